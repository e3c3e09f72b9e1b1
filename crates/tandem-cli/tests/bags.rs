//! ROS 2 bags through the binary: every bad bag of the catalogue ends `fit` and `record` with
//! exit code 2, a message naming the file and the topic, and an untouched state file; a run
//! `simulate --bag` writes records back exactly as its CSV files do; an existing file is
//! never overwritten.

mod common;

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use common::*;
use tandem::bag;

#[path = "../../tandem-bag/tests/support/bad.rs"]
mod bad;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn examples() -> PathBuf {
    repo().join("fixtures/examples")
}

fn example_bags() -> Vec<PathBuf> {
    (0..3)
        .map(|i| examples().join(format!("ros2/demo_{i}.mcap")))
        .collect()
}

/// `args`, expecting exit code 2, `needles` in stderr and `state` unchanged.
fn refused(args: &[OsString], needles: &[&str], state: &Path) {
    let before = std::fs::read(state).unwrap();
    let out = tandem(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}\n{stderr}");
    assert!(
        stderr.lines().any(|l| l.starts_with("error: ")),
        "{args:?}\n{stderr}"
    );
    for n in needles {
        assert!(
            stderr.contains(n),
            "{args:?}: stderr lacks `{n}`:\n{stderr}"
        );
    }
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(
        std::fs::read(state).unwrap(),
        before,
        "{args:?}: the state changed"
    );
}

fn os(v: &[&dyn AsRef<std::ffi::OsStr>]) -> Vec<OsString> {
    v.iter().map(|s| s.as_ref().to_os_string()).collect()
}

/// A state fitted on the example bags, and a copy of the state bytes.
fn bag_state(dir: &Path) -> PathBuf {
    let state = dir.join("cell.tandem");
    let mut args = os(&[&"fit"]);
    args.extend(example_bags().into_iter().map(OsString::from));
    args.extend(os(&[
        &"--params",
        &examples().join("params.toml"),
        &"--samples",
        &"200",
        &"-o",
        &state,
    ]));
    ok(&tandem(&args));
    state
}

#[test]
fn every_bad_bag_is_refused_by_fit_and_record_and_leaves_the_state() {
    let dir = scratch("bad-bags");
    let state = bag_state(&dir);
    for case in bad::catalogue(&dir.join("bags")) {
        eprintln!("bad bag: {}", case.name);
        let file = case.path.display().to_string();
        let mut needles = vec![file.as_str()];
        needles.extend(case.needles.iter().copied());
        // fit: the bad bag with two good ones, the existing state file as the output.
        let mut args = os(&[&"fit", &case.path]);
        args.extend(example_bags()[1..].iter().map(OsString::from));
        if let Some(t) = &case.topics {
            args.extend(os(&[&"--topics", &t.join(",")]));
        }
        args.extend(os(&[&"-o", &state]));
        refused(&args, &needles, &state);
        // record: the bad bag as the round.
        let mut args = os(&[&"record", &state, &case.path]);
        if let Some(t) = &case.topics {
            args.extend(os(&[&"--topics", &t.join(",")]));
        }
        refused(&args, &[file.as_str()], &state);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_simulated_run_bag_records_like_its_csv_files_and_is_never_overwritten() {
    let dir = scratch("run-bag");
    let state = bag_state(&dir);
    let run = dir.join("run.mcap");
    let sim = |extra: &[&dyn AsRef<std::ffi::OsStr>]| {
        let mut args = os(&[
            &"simulate",
            &state,
            &"--need",
            &examples().join("need.csv"),
            &"--rounds",
            &"3",
            &"--channel",
            &"wrench.fz",
            &"--seed",
            &"4",
        ]);
        args.extend(os(extra));
        tandem(&args)
    };
    let text = ok(&sim(&[&"--bag", &run, &"--write", &dir.join("csv")]));
    assert!(
        text.contains("wrote") && text.contains("3 round(s)"),
        "{text}"
    );
    assert_eq!(bag::count_rounds(&run).unwrap(), 3);
    // The same run again onto the same file: refused, the file kept.
    let before = std::fs::read(&run).unwrap();
    refused(
        &os(&[
            &"simulate",
            &state,
            &"--need",
            &examples().join("need.csv"),
            &"--rounds",
            &"1",
            &"--channel",
            &"wrench.fz",
            &"--bag",
            &run,
        ]),
        &["the file exists", "does not overwrite"],
        &state,
    );
    assert_eq!(std::fs::read(&run).unwrap(), before);
    // Round 2 from the bag and from the CSV files give the same state file, byte for byte.
    let (a, b) = (dir.join("a.tandem"), dir.join("b.tandem"));
    for round in 1..=2 {
        for p in [&a, &b] {
            if round == 1 {
                std::fs::copy(&state, p).unwrap();
            }
        }
        ok(&tandem(os(&[
            &"record",
            &a,
            &run,
            &"--round",
            &round.to_string(),
        ])));
        let mut args = os(&[&"record", &b]);
        for r in 1..=2 {
            let stem = dir.join("csv").join(format!("round_{round}_robot_{r}"));
            let with = |ext: &str| PathBuf::from(format!("{}{ext}", stem.display()));
            args.extend(os(&[
                &"--execution",
                &with(".csv"),
                &"--log",
                &with(".reflog.csv"),
                &"--corrections",
                &with(".corr.csv"),
            ]));
        }
        ok(&tandem(&args));
        assert_eq!(
            std::fs::read(&a).unwrap(),
            std::fs::read(&b).unwrap(),
            "round {round}"
        );
    }
    // Without --round the run is refused; inspect lists its topics and rounds.
    refused(
        &os(&[&"record", &a, &run]),
        &["holds 3 rounds", "--round"],
        &a,
    );
    let text = ok(&tandem(os(&[&"inspect", &run])));
    assert!(
        text.contains("3 round(s)") && text.contains("/robot_2/supervised"),
        "{text}"
    );
    let json = ok(&tandem(os(&[&"inspect", &run, &"--json"])));
    let doc: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(doc["rounds"], 3);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bag_flags_are_checked() {
    let dir = scratch("bag-flags");
    let state = bag_state(&dir);
    let csvs = small_demos(&dir);
    refused(
        &os(&[&"fit", &csvs[0], &csvs[1], &"--rate", &"100", &"-o", &state]),
        &["--rate and --topics apply to ROS 2 bags"],
        &state,
    );
    let b = example_bags();
    refused(
        &os(&[&"fit", &b[0], &b[1], &"--rate", &"0", &"-o", &state]),
        &["--rate 0: the grid rate must be finite and > 0"],
        &state,
    );
    refused(
        &os(&[&"fit", &b[0], &b[1], &"--topics", &"/nope", &"-o", &state]),
        &[
            "no topic `/nope`",
            "/tool_pose (geometry_msgs/msg/PoseStamped)",
        ],
        &state,
    );
    // A bag and CSV files: the channel names differ, and the error says so.
    refused(
        &os(&[&"fit", &b[0], &csvs[0], &csvs[1], &"-o", &state]),
        &["channels"],
        &state,
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
