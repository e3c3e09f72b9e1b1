//! A cell of different tasks on different robots (issue 45) through the command line: `fit
//! --task NAME=FILE,… --robots NAME=K,…`, `inspect` and `record` of its format 12 state, a
//! one-task cell written exactly as `fit DEMO…`, and bad input exiting 2 with the fix.

mod common;

use std::path::{Path, PathBuf};

use common::*;

fn examples(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/examples")
        .join(name)
}

fn task_arg(name: &str, demos: &[&str]) -> String {
    let files: Vec<String> = demos
        .iter()
        .map(|d| examples(d).display().to_string())
        .collect();
    format!("{name}={}", files.join(","))
}

fn version(path: &Path) -> u32 {
    let bytes = std::fs::read(path).unwrap();
    u32::from_le_bytes(bytes[8..12].try_into().unwrap())
}

fn fails_with(out: &std::process::Output, want: &[&str]) {
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    for w in want {
        assert!(err.contains(w), "`{w}` missing in: {err}");
    }
}

/// `fit` of the example task on two robots (`a`, demos 0, 1, 2) and another model of it on
/// one robot (`b`, demos 0 and 2 only: the same reference, other statistics).
fn fit_mixed(dir: &Path) -> PathBuf {
    let state = dir.join("mixed.tandem");
    let params = examples("params.toml");
    let out = ok(&tandem([
        "fit",
        "--task",
        &task_arg("a", &["demo_0.csv", "demo_1.csv", "demo_2.csv"]),
        "--task",
        &task_arg("b", &["demo_0.csv", "demo_2.csv"]),
        "--robots",
        "a=2,b=1",
        "--params",
        &params.display().to_string(),
        "-o",
        &state.display().to_string(),
    ]));
    for want in [
        "fitted a cell of 2 task(s), 3 robots",
        "task a: robots 1, 2; reference 40 samples × 0.01 s",
        "task b: robot 3; reference",
        "schedule (rounds, every robot its own task): T_total",
    ] {
        assert!(out.contains(want), "`{want}` missing in:\n{out}");
    }
    assert_eq!(version(&state), 12);
    state
}

#[test]
fn a_mixed_cell_is_fitted_inspected_and_recorded_per_robot_task() {
    let dir = scratch("cells-mixed");
    let state = fit_mixed(&dir);
    let s = state.display().to_string();
    let out = ok(&tandem(["inspect", &s]));
    assert!(
        out.contains("a cell of 2 tasks, 3 robots, 0 round(s) recorded"),
        "{out}"
    );
    // Robots 1 and 2 run task a, robot 3 task b; the example pair is logged on demo 0, the
    // reference of both tasks, so robot 3 records robot 1's execution into task b.
    let p = |n: &str| examples(n).display().to_string();
    let args = [
        "record",
        &s,
        "--execution",
        &p("pair_1_robot_1.csv"),
        "--log",
        &p("pair_1_robot_1.reflog.csv"),
        "--corrections",
        &p("pair_1_robot_1.corr.csv"),
        "--execution",
        &p("pair_1_robot_2.csv"),
        "--log",
        &p("pair_1_robot_2.reflog.csv"),
        "--corrections",
        &p("pair_1_robot_2.corr.csv"),
        "--execution",
        &p("pair_1_robot_1.csv"),
        "--log",
        &p("pair_1_robot_1.reflog.csv"),
        "--corrections",
        &p("pair_1_robot_1.corr.csv"),
    ];
    let out = ok(&tandem(args));
    for want in ["recorded round 1 into", "task a: ", "task b: ", "T_total: "] {
        assert!(out.contains(want), "`{want}` missing in:\n{out}");
    }
    assert_eq!(version(&state), 12);
    let out = ok(&tandem(["inspect", &s]));
    assert!(out.contains("1 round(s) recorded"), "{out}");
    // The same round again is refused, and the file is unchanged.
    let before = std::fs::read(&state).unwrap();
    fails_with(&tandem(args), &["task `a`", "already recorded as round 1"]);
    assert_eq!(std::fs::read(&state).unwrap(), before);
    // A round of two executions for three robots.
    fails_with(
        &tandem(&args[..14]),
        &[
            "--execution given 2 time(s)",
            "a round needs exactly 3",
            "robot 3 b",
        ],
    );
    // `schedule` shows the cell's schedule, each robot named with its task.
    let out = ok(&tandem(["schedule", &s]));
    for want in [
        "robot 1 (a) starts at 0.00 s",
        "robot 3 (b) starts at",
        "robot 1 (a) |",
        "robot 3 (b) |",
        "operator    |",
        "low-confidence intervals (global time; reference samples):",
    ] {
        assert!(out.contains(want), "`{want}` missing in:\n{out}");
    }
    // The margin check accepted the schedule, so no column has two robots supervised.
    let operator_row = out.lines().find(|l| l.starts_with("operator")).unwrap();
    assert!(!operator_row.contains('!'), "{out}");
    // Its JSON, from `schedule` and from `inspect`, is one document.
    let doc: serde_json::Value =
        serde_json::from_str(&ok(&tandem(["schedule", &s, "--json"]))).expect("schedule --json");
    let inspected: serde_json::Value =
        serde_json::from_str(&ok(&tandem(["inspect", &s, "--json"]))).expect("inspect --json");
    assert_eq!(doc, inspected);
    assert_eq!(doc["robot_tasks"], serde_json::json!(["a", "a", "b"]));
    assert_eq!(doc["tasks"][0]["robots"], serde_json::json!([1, 2]));
    assert_eq!(doc["tasks"][1]["robots"], serde_json::json!([3]));
    assert_eq!(doc["rounds_recorded"], 1);
    let sch = &doc["schedule"];
    let t_total = sch["t_total_s"].as_f64().unwrap();
    assert!(
        sch["lower_bound_s"].as_f64().unwrap() <= t_total + 1e-9,
        "{sch}"
    );
    // T_total is the last robot's planned end; robot 1 starts at 0.
    let ends: Vec<f64> = sch["robots"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["end_s"].as_f64().unwrap())
        .collect();
    assert_eq!(ends.len(), 3);
    assert!((ends.iter().cloned().fold(f64::MIN, f64::max) - t_total).abs() < 1e-9);
    assert_eq!(sch["robots"][0]["start_s"], 0.0);
    // The planned low-confidence intervals of different robots never overlap, and each
    // names its robot's task.
    let lc = sch["lc_intervals"].as_array().unwrap();
    assert!(!lc.is_empty());
    for (k, a) in lc.iter().enumerate() {
        let robot = a["robot"].as_u64().unwrap() as usize;
        assert_eq!(a["task"], doc["robot_tasks"][robot - 1]);
        for b in &lc[k + 1..] {
            if a["robot"] != b["robot"] {
                assert!(
                    a["end_s"].as_f64().unwrap() <= b["start_s"].as_f64().unwrap() + 1e-9,
                    "{a} overlaps {b}"
                );
            }
        }
    }
    // Nothing to save or re-sample: refused, the file unchanged.
    fails_with(
        &tandem(["schedule", &s, "--save"]),
        &["re-scheduled when a round is recorded", "Leave out --save"],
    );
    fails_with(
        &tandem(["schedule", &s, "--samples", "10"]),
        &["Leave out --save, --samples"],
    );
    assert_eq!(std::fs::read(&state).unwrap(), before);
    // A single-task command refuses the cell, naming its tasks and the fix.
    fails_with(
        &tandem(["plot", &s, "-o", &dir.join("p.svg").display().to_string()]),
        &[
            "holds a cell of 2 tasks (a, b)",
            "load it as a cell",
            "tandem schedule",
        ],
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_one_task_cell_writes_the_bytes_of_a_plain_fit() {
    let dir = scratch("cells-one");
    let params = examples("params.toml").display().to_string();
    let one = dir.join("one.tandem").display().to_string();
    let plain = dir.join("plain.tandem").display().to_string();
    ok(&tandem([
        "fit",
        "--task",
        &task_arg("sanding", &["demo_0.csv", "demo_1.csv", "demo_2.csv"]),
        "--robots",
        "sanding=3",
        "--params",
        &params,
        "-o",
        &one,
    ]));
    let demos: Vec<String> = ["demo_0.csv", "demo_1.csv", "demo_2.csv"]
        .iter()
        .map(|d| examples(d).display().to_string())
        .collect();
    let mut args: Vec<String> = vec!["fit".into()];
    args.extend(demos);
    args.extend(["--robots", "3", "--params", &params, "-o", &plain].map(String::from));
    ok(&tandem(&args));
    assert_eq!(version(Path::new(&one)), 11);
    assert_eq!(std::fs::read(&one).unwrap(), std::fs::read(&plain).unwrap());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_cell_input_exits_2_naming_the_fix() {
    let dir = scratch("cells-bad");
    let out = dir.join("x.tandem").display().to_string();
    let a = task_arg("a", &["demo_0.csv", "demo_1.csv"]);
    let cases: Vec<(Vec<String>, Vec<&str>)> = vec![
        (
            vec![
                "--task".into(),
                a.clone(),
                "--robots".into(),
                "a=2,c=1".into(),
            ],
            vec!["--robots c=…: no task `c` (the tasks: a)"],
        ),
        (
            vec!["--task".into(), task_arg("a", &["demo_0.csv"])],
            vec!["1 demonstration file(s)", "at least 2"],
        ),
        (
            vec!["--task".into(), "demo_0.csv".into()],
            vec!["give NAME=FILE,…"],
        ),
        (
            vec!["--task".into(), a.clone(), "--robots".into(), "2".into()],
            vec!["with --task give each task's robots as NAME=K"],
        ),
        (
            vec!["--task".into(), a.clone(), "--robots".into(), "a=0".into()],
            vec!["K must be a whole number of robots ≥ 1"],
        ),
        (
            vec![
                "--task".into(),
                a.clone(),
                "--task".into(),
                task_arg("a", &["demo_1.csv", "demo_2.csv"]),
            ],
            vec!["task name `a`: given twice"],
        ),
        (
            vec![
                "--task".into(),
                task_arg("a b", &["demo_0.csv", "demo_1.csv"]),
            ],
            vec!["a task name is 1 to 64 letters"],
        ),
        (
            vec![
                examples("demo_0.csv").display().to_string(),
                examples("demo_1.csv").display().to_string(),
                "--robots".into(),
                "a=2".into(),
            ],
            vec!["robot counts per task are for a cell of tasks"],
        ),
    ];
    for (extra, want) in cases {
        let mut args: Vec<String> = vec!["fit".into()];
        args.extend(extra);
        args.extend(["-o".to_string(), out.clone()]);
        fails_with(&tandem(&args), &want);
        assert!(!Path::new(&out).exists(), "{args:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
