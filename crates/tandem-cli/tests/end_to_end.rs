//! End to end through the binary: fit on the six sanding fixtures, simulate two pairs and
//! write them, record them with `tandem record`, re-schedule; plus the documented examples
//! under `fixtures/examples/`, `--help`, `params` and `plot`.

mod common;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use common::*;
use tandem::Planner;
use tandem::realtime::tol;
use tandem::schedule::{Schedule, solve_exact, validate};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn s(p: &Path) -> String {
    p.display().to_string()
}

/// A need file for the fixtures' reference demonstration: sanding in passes 1–3 needs the
/// operator on half the workpieces, one region per (pass, section); nothing else does
/// (the study of §III).
fn sanding_need(dir: &Path) -> PathBuf {
    let labels = std::fs::read_to_string(repo().join("fixtures/sanding/demo_0.labels.csv"))
        .expect("read labels");
    let mut need = String::from("need,region\n");
    for row in labels.lines().skip(1) {
        let f: Vec<&str> = row.split(',').collect();
        let (pass, section) = (f[0].parse::<u32>().unwrap(), f[1].parse::<u32>().unwrap());
        if f[3] == "sanding" && pass < 4 {
            writeln!(need, "0.5,{}", pass * 100 + section + 1).unwrap();
        } else {
            need.push_str("0,0\n");
        }
    }
    write(dir, "need.csv", &need)
}

/// The round-`k` files `tandem simulate --write` produced, as `record` arguments.
fn round_files(dir: &Path, k: usize) -> [[PathBuf; 3]; 2] {
    files_named(dir, "round", k)
}

/// The files `{prefix}_{k}_robot_{1,2}` (`.csv`, `.reflog.csv`, `.corr.csv`) in `dir`, as
/// `record` arguments (`fixtures/examples/` keeps its committed names `pair_1_robot_*`).
fn files_named(dir: &Path, prefix: &str, k: usize) -> [[PathBuf; 3]; 2] {
    std::array::from_fn(|i| {
        let stem = format!("{prefix}_{k}_robot_{}", i + 1);
        [
            dir.join(format!("{stem}.csv")),
            dir.join(format!("{stem}.reflog.csv")),
            dir.join(format!("{stem}.corr.csv")),
        ]
    })
}

/// The last column (next T_total, s) of each pair row of `simulate`'s table.
fn simulated_t_totals(stdout: &str) -> Vec<f64> {
    stdout
        .lines()
        .filter(|l| l.trim_start().starts_with(|c: char| c.is_ascii_digit()))
        .map(|l| l.split_whitespace().last().unwrap().parse().unwrap())
        .collect()
}

#[test]
fn fixtures_fit_simulate_record_schedule() {
    let dir = scratch("e2e");
    let state = dir.join("cell.tandem");
    // Demo 0 is the reference (`--reference first`): the fixtures' labels are on its axis.
    let mut fit = vec!["fit".to_string()];
    fit.extend((0..6).map(|i| s(&repo().join(format!("fixtures/sanding/demo_{i}.csv")))));
    fit.extend(["--reference", "first", "--samples", "200", "-o"].map(String::from));
    fit.push(s(&state));
    let stdout = ok(&tandem(&fit));
    assert!(stdout.contains("fitted 6 demonstrations"), "{stdout}");
    let fitted = Planner::load(&state).unwrap();
    assert_eq!(fitted.params().sampler.samples, 200);
    let n_ref = fitted.model().n_ref();
    assert_eq!(n_ref, 9873, "demo_0.csv has 9873 samples");

    // Simulate two rounds: a what-if that leaves the state alone.
    let need = sanding_need(&dir);
    let before = std::fs::read(&state).unwrap();
    let sim_dir = dir.join("sim");
    let stdout = ok(&tandem([
        "simulate",
        &s(&state),
        "--need",
        &s(&need),
        "--rounds",
        "2",
        "--seed",
        "7",
        "--write",
        &s(&sim_dir),
    ]));
    assert_eq!(
        std::fs::read(&state).unwrap(),
        before,
        "simulate is read-only"
    );
    let predicted = simulated_t_totals(&stdout);
    assert_eq!(predicted.len(), 2, "{stdout}");
    let stdout_sim = stdout.clone();
    // Each round's row reports 0 ticks with both robots low-confidence.
    for line in stdout
        .lines()
        .filter(|l| l.trim_start().starts_with(['1', '2']))
    {
        let cols: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(cols[5], "0", "overlap ticks: {line}");
    }

    // Record both rounds from the written files.
    for k in 1..=2 {
        let [a, b] = round_files(&sim_dir, k);
        let stdout = ok(&tandem(record_args(&state, &a, &b)));
        assert!(stdout.contains(&format!("recorded round {k}")), "{stdout}");
        // What became of the schedule the round ran: kept, re-timed or invalidated.
        assert!(
            stdout
                .lines()
                .any(|l| l.starts_with("previous schedule: the previous schedule")),
            "{stdout}"
        );
    }
    // The simulation says how far the rounds ran from their plans, and why.
    assert!(
        stdout_sim.contains("realized against planned over 2 round(s)"),
        "{stdout_sim}"
    );
    assert!(
        stdout_sim.contains("needed but unsupervised: "),
        "{stdout_sim}"
    );
    let recorded = Planner::load(&state).unwrap();
    assert_eq!(recorded.rounds_recorded(), 2);
    assert_eq!(recorded.model().count(), 6 + 4);
    assert!(recorded.observations().total_supervised() > 0.0);
    // The files round-trip exactly: `record` reproduces the simulation's own updates.
    assert!(
        (recorded.outcome().t_total_s - predicted[1]).abs() < 0.006,
        "recorded T_total {} vs simulated {}",
        recorded.outcome().t_total_s,
        predicted[1]
    );

    // Re-schedule: valid for the state's problem and never longer than the saved schedule.
    let out = tandem([
        "schedule",
        &s(&state),
        "--json",
        "--samples",
        "300",
        "--seed",
        "5",
    ]);
    let doc: serde_json::Value = serde_json::from_str(&ok(&out)).unwrap();
    let schedule: Schedule = serde_json::from_value(doc["schedule"].clone()).unwrap();
    validate(recorded.problem(), &schedule).expect("the JSON schedule satisfies Eq. 20");
    let t_total = doc["t_total_s"].as_f64().unwrap();
    assert!((t_total - schedule.t_total_s(recorded.model().dt_s())).abs() < 1e-9);
    assert!(t_total <= recorded.outcome().t_total_s + 1e-9);
    assert!(t_total <= doc["serial_t_total_s"].as_f64().unwrap() + 1e-9);
    // The certificate: the margin-free optimum `T*₀` of the state's problem (solved here
    // again, independently of the command) and the gap to it. The bound is reported
    // unclamped, so it may exceed `T_total` by the rounding `tol::BOUND_REL` (2e-9 relative)
    // allows a valid schedule, never by more.
    let bound = doc["lower_bound_s"].as_f64().unwrap();
    let exact = solve_exact(recorded.problem(), &recorded.params().sampler.exact).unwrap();
    assert!(exact.proven_optimal);
    assert_eq!(doc["bound_is_optimum"], true);
    assert!(
        (bound - exact.lower_bound_s).abs() <= 1e-12 * exact.lower_bound_s,
        "reported bound {bound} vs T*₀ {}",
        exact.lower_bound_s
    );
    assert!(
        bound <= t_total * (1.0 + tol::BOUND_REL),
        "{bound} vs {t_total}"
    );
    assert!((doc["gap"].as_f64().unwrap() - (t_total - bound) / bound).abs() < 1e-9);
    assert_eq!(doc["offset_s"].as_f64().unwrap(), schedule.offsets_s[0]);
    // Low-confidence intervals of the two robots never overlap in global time.
    let iv = doc["lc_intervals"].as_array().unwrap();
    for a in iv.iter().filter(|x| x["robot"] == 1) {
        for b in iv.iter().filter(|x| x["robot"] == 2) {
            let (a0, a1) = (a["start_s"].as_f64().unwrap(), a["end_s"].as_f64().unwrap());
            let (b0, b1) = (b["start_s"].as_f64().unwrap(), b["end_s"].as_f64().unwrap());
            assert!(a1 <= b0 + 1e-9 || b1 <= a0 + 1e-9, "{a} overlaps {b}");
        }
    }
    assert_eq!(doc["saved"], false);

    // --save keeps exactly that schedule, and the state still loads.
    let before = std::fs::read(&state).unwrap();
    ok(&tandem([
        "schedule",
        &s(&state),
        "--samples",
        "300",
        "--seed",
        "5",
        "--save",
    ]));
    assert_ne!(std::fs::read(&state).unwrap(), before);
    let saved = Planner::load(&state).unwrap();
    // serde_json reads floats to within an ulp, not bit for bit.
    assert!((saved.schedule().offsets_s[0] - schedule.offsets_s[0]).abs() < 1e-12);
    for (a, b) in saved.schedule().grad_exec.iter().zip(&schedule.grad_exec) {
        assert_eq!(a.len(), b.len());
        let worst = a
            .iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        assert!(
            worst < 1e-12,
            "saved schedule differs from the JSON by {worst}"
        );
    }
    assert_eq!(saved.rounds_recorded(), 2);
    assert_eq!(saved.model().count(), recorded.model().count());

    // Plot the recorded state: SVG and PNG of each figure.
    let plots = dir.join("plots");
    ok(&tandem(["plot", &s(&state), "-o", &s(&plots)]));
    for name in ["model", "confidence", "schedule"] {
        let svg = std::fs::read_to_string(plots.join(format!("{name}.svg"))).unwrap();
        assert!(svg.contains("<svg"), "{name}.svg");
        let png = std::fs::read(plots.join(format!("{name}.png"))).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "{name}.png");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The tiny files of `fixtures/examples/` (docs/formats.md) work as documented.
#[test]
fn documented_examples_work() {
    let dir = scratch("examples");
    let ex = repo().join("fixtures/examples");
    let state = dir.join("ex.tandem");
    let demos: Vec<String> = (0..3)
        .map(|i| s(&ex.join(format!("demo_{i}.csv"))))
        .collect();
    let mut fit = vec!["fit".to_string()];
    fit.extend(demos);
    fit.extend([
        "--params".into(),
        s(&ex.join("params.toml")),
        "-o".into(),
        s(&state),
    ]);
    let stdout = ok(&tandem(&fit));
    // demo_0.csv: 40 samples at 10 ms.
    assert!(stdout.contains("40 samples × 0.01 s = 0.40 s"), "{stdout}");
    let p = Planner::load(&state).unwrap();
    assert_eq!(p.params().sampler.samples, 2000, "params.toml sets 2000");
    assert_eq!(p.params().fit.k_max, 2);
    let [a, b] = files_named(&ex, "pair", 1);
    ok(&tandem(record_args(&state, &a, &b)));
    // The walk-through writes exactly the committed golden state file (`cargo xtask fixtures`).
    assert!(
        std::fs::read(&state).unwrap()
            == std::fs::read(repo().join("fixtures/state/example.tandem")).unwrap(),
        "tandem fit + record on fixtures/examples/ differ from fixtures/state/example.tandem"
    );
    let p = Planner::load(&state).unwrap();
    assert_eq!(p.rounds_recorded(), 1);
    // 42 samples per execution, all supervised before the first update; with one vote per
    // execution (the default) each execution counts once on each of the 40 reference samples.
    assert_eq!(p.observations().total_supervised(), 80.0);
    ok(&tandem([
        "simulate",
        &s(&state),
        "--need",
        &s(&ex.join("need.csv")),
        "--rounds",
        "1",
    ]));
    // `--pairs` is the deprecated alias of `--rounds` (kept one release): the same run, and a
    // deprecation line on stderr; the two together are refused.
    let sim_with = |flag: &str| {
        tandem([
            "simulate",
            &s(&state),
            "--need",
            &s(&ex.join("need.csv")),
            flag,
            "1",
        ])
    };
    let (new, old) = (sim_with("--rounds"), sim_with("--pairs"));
    assert_eq!(ok(&old), ok(&new));
    let warned = String::from_utf8_lossy(&old.stderr);
    assert!(
        warned.contains("deprecated") && warned.contains("--rounds"),
        "{warned}"
    );
    assert!(!String::from_utf8_lossy(&new.stderr).contains("deprecated"));
    let both = tandem([
        "simulate",
        &s(&state),
        "--need",
        &s(&ex.join("need.csv")),
        "--rounds",
        "1",
        "--pairs",
        "1",
    ]);
    assert!(!both.status.success());
    // The text views print the certificate.
    let text = ok(&tandem(["inspect", &s(&state)]));
    assert!(
        text.contains("lower bound") && text.contains("without margins"),
        "{text}"
    );
    let text = ok(&tandem(["schedule", &s(&state), "--samples", "50"]));
    assert!(text.starts_with("T_total "), "{text}");
    assert!(text.contains("without margins") && text.contains("fastest serial"));
    let inspect: serde_json::Value =
        serde_json::from_str(&ok(&tandem(["inspect", &s(&state), "--json"]))).unwrap();
    // `inspect` reports the stored certificate as stored (bit for bit through JSON), within
    // the rounding `tol::BOUND_REL` allows of `T_total`.
    let stored = Planner::load(&state).unwrap();
    let bound = inspect["schedule"]["lower_bound_s"].as_f64().unwrap();
    assert_eq!(bound, stored.outcome().lower_bound_s);
    assert_eq!(
        inspect["schedule"]["gap"].as_f64().unwrap(),
        stored.outcome().gap
    );
    assert!(bound <= inspect["schedule"]["t_total_s"].as_f64().unwrap() * (1.0 + tol::BOUND_REL));
    assert_eq!(inspect["rounds_recorded"], 1);
    // The deprecated duplicate key (kept one release) says the same.
    assert_eq!(inspect["pairs_recorded"], inspect["rounds_recorded"]);
    assert_eq!(inspect["model"]["count"], 5);
    assert_eq!(inspect["model"]["n_ref"], 40);
    // Every low-confidence region says why it is low and where, in reference time.
    let regions = inspect["confidence"]["low_regions"].as_array().unwrap();
    assert!(!regions.is_empty());
    for r in regions {
        let (a, b) = (r["start_s"].as_f64().unwrap(), r["end_s"].as_f64().unwrap());
        assert!(a < b && b <= 0.4 + 1e-9, "{r}");
        let cause = r["cause"].as_str().unwrap();
        assert!(cause == "variance" || cause == "corrections", "{r}");
        assert!(r["channels"].as_array().is_some_and(|c| c.len() <= 3));
    }
    let f = inspect["confidence"]["error_rates"]["false_correction_rate"]
        .as_f64()
        .unwrap();
    assert!((0.0..0.5).contains(&f));
    assert!(text_inspect_explains(&ok(&tandem(["inspect", &s(&state)]))));
    let _ = std::fs::remove_dir_all(&dir);
}

/// The text view gives each low-confidence region its cause and what would change it.
fn text_inspect_explains(text: &str) -> bool {
    text.contains("why: ") && text.contains("would change it: ")
}

#[test]
fn every_subcommand_has_help_with_an_example() {
    for sub in [
        "fit", "schedule", "record", "inspect", "plot", "simulate", "params", "console",
    ] {
        let stdout = ok(&tandem([sub, "--help"]));
        assert!(stdout.contains("Example"), "{sub} --help:\n{stdout}");
        assert!(
            stdout.contains(&format!("tandem {sub}")),
            "{sub} --help:\n{stdout}"
        );
    }
    let top = ok(&tandem(["--help"]));
    for sub in ["fit", "schedule", "record", "inspect", "plot", "simulate"] {
        assert!(top.contains(sub), "{top}");
    }
    // A usage error is a user error too: exit code 2.
    assert_eq!(tandem(["fit"]).status.code(), Some(2));
    assert_eq!(tandem(["frobnicate"]).status.code(), Some(2));
}

/// `tandem params` prints a parameter file that `fit --params` reads back as the defaults.
#[test]
fn printed_default_parameters_read_back() {
    let dir = scratch("params");
    let text = ok(&tandem(["params"]));
    let p = write(&dir, "params.toml", &text);
    let state = small_state_with(&dir, &["--params", &s(&p)]);
    let loaded = Planner::load(&state).unwrap();
    assert_eq!(loaded.params(), &tandem::PlannerParams::default());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Fits the small task with extra `fit` arguments.
fn small_state_with(dir: &Path, extra: &[&str]) -> PathBuf {
    let demos = small_demos(dir);
    let state = dir.join("cell.tandem");
    let mut args: Vec<String> = vec!["fit".into()];
    args.extend(demos.iter().map(|p| s(p)));
    args.extend(extra.iter().map(|x| x.to_string()));
    args.extend(["-o".into(), s(&state)]);
    ok(&tandem(&args));
    state
}

/// `--ranges` sets the named ranges and keeps the automatic ones for the rest.
#[test]
fn ranges_override_only_the_named_coordinates() {
    let dir = scratch("ranges");
    let auto = Planner::load(small_state_with(&dir, &["--samples", "50"])).unwrap();
    let names = auto.model().tangent_names().to_vec();
    assert_eq!(names, ["x", "force", "rate"]);
    // Force spans 5..17 N over the demonstrations, x spans 0..1.
    assert!((auto.model().ranges()[1] - 12.0).abs() < 1e-9);
    assert!((auto.model().ranges()[0] - 1.0).abs() < 1e-9);
    let set = Planner::load(small_state_with(
        &dir,
        &["--samples", "50", "--ranges", "force=24"],
    ))
    .unwrap();
    assert_eq!(set.model().ranges()[1], 24.0);
    assert_eq!(set.model().ranges()[0], auto.model().ranges()[0]);
    assert_eq!(set.model().ranges()[2], auto.model().ranges()[2]);
    // Doubling the force range quarters its weight: σ²_D falls where only force varies.
    let mid = SMALL_N_REF / 2;
    assert!(set.model().sigma2_d()[mid] < auto.model().sigma2_d()[mid]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--reference medoid` makes the model independent of the order of the files: the same
/// reference file, the same statistics and the same first schedule; `first` follows the
/// order. The parameter file's `[fit] reference` does the same as the flag.
#[test]
fn medoid_reference_does_not_depend_on_the_order_of_the_files() {
    let dir = scratch("reference");
    let demos: Vec<String> = small_demos(&dir).iter().map(|p| s(p)).collect();
    let fit = |order: &[usize], extra: &[&str], name: &str| -> (String, Planner) {
        let state = dir.join(name);
        let mut args: Vec<String> = vec!["fit".into()];
        args.extend(order.iter().map(|&i| demos[i].clone()));
        args.extend(["--samples", "50"].map(String::from));
        args.extend(extra.iter().map(|x| x.to_string()));
        args.extend(["-o".into(), s(&state)]);
        let stdout = ok(&tandem(&args));
        (stdout, Planner::load(&state).unwrap())
    };
    let (out_a, a) = fit(&[0, 1, 2], &["--reference", "medoid"], "a.tandem");
    let (out_b, b) = fit(&[2, 0, 1], &["--reference", "medoid"], "b.tandem");
    let medoid = &demos[a.model().reference_idx()];
    assert_eq!(
        &[2, 0, 1].map(|i| &demos[i])[b.model().reference_idx()],
        &medoid
    );
    for out in [&out_a, &out_b] {
        assert!(
            out.contains(&format!("reference: {medoid}, the medoid")),
            "{out}"
        );
    }
    assert_eq!(a.model().sigma2_d(), b.model().sigma2_d());
    assert_eq!(a.model().grad_min(), b.model().grad_min());
    assert_eq!(a.schedule(), b.schedule());
    // The same choice from the parameter file.
    let p = write(&dir, "medoid.toml", "[fit]\nreference = \"medoid\"\n");
    let (_, c) = fit(&[1, 2, 0], &["--params", &s(&p)], "c.tandem");
    assert_eq!(c.model().sigma2_d(), a.model().sigma2_d());
    // The default is the medoid (docs/decisions.md, "The medoid reference by default: labels
    // follow the reference"): the same model as asked for by name, in any order.
    let (out_e, e) = fit(&[1, 2, 0], &[], "e.tandem");
    assert_eq!(
        &[1, 2, 0].map(|i| &demos[i])[e.model().reference_idx()],
        &medoid
    );
    assert!(
        out_e.contains(&format!("reference: {medoid}, the medoid")),
        "{out_e}"
    );
    assert_eq!(e.model().sigma2_d(), a.model().sigma2_d());
    // `first` takes the first file.
    let (out_d, d) = fit(&[1, 2, 0], &["--reference", "first"], "d.tandem");
    assert_eq!(d.model().reference_idx(), 0);
    assert!(out_d.contains(&format!("reference: {}, the first file", demos[1])));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Three robots through the binary: `fit --robots 3` on the documented example, the schedule
/// JSON of docs/formats.md (three warps, two offsets, no two robots low-confidence at once),
/// `simulate --write` writes three executions per round, `record` takes exactly three and
/// refuses two, and `--robots 17` is a user error.
#[test]
fn three_robots_fit_schedule_simulate_record() {
    let dir = scratch("three");
    let ex = repo().join("fixtures/examples");
    let state = dir.join("cell3.tandem");
    let mut fit = vec!["fit".to_string()];
    fit.extend((0..3).map(|i| s(&ex.join(format!("demo_{i}.csv")))));
    fit.extend(["--params".into(), s(&ex.join("params.toml"))]);
    fit.extend(["--robots", "3", "-o"].map(String::from));
    fit.push(s(&state));
    let stdout = ok(&tandem(&fit));
    assert!(stdout.contains("schedule: τ = "), "{stdout}");
    assert_eq!(Planner::load(&state).unwrap().n_robots(), 3);

    let doc: serde_json::Value =
        serde_json::from_str(&ok(&tandem(["schedule", &s(&state), "--json"]))).unwrap();
    assert_eq!(doc["n_robots"], 3);
    let offsets = doc["offsets_s"].as_array().unwrap();
    assert_eq!(offsets.len(), 2);
    assert_eq!(doc["offset_s"], offsets[0]);
    assert_eq!(doc["durations_s"].as_array().unwrap().len(), 3);
    let schedule: Schedule = serde_json::from_value(doc["schedule"].clone()).unwrap();
    assert_eq!(schedule.n_robots(), 3);
    let p = Planner::load(&state).unwrap();
    validate(p.problem(), &schedule).unwrap();
    // The robots overlap (faster than serial), yet their low-confidence intervals never do.
    let t_total = doc["t_total_s"].as_f64().unwrap();
    assert!(t_total < doc["serial_t_total_s"].as_f64().unwrap());
    let mut lc: Vec<(f64, f64)> = doc["lc_intervals"]
        .as_array()
        .unwrap()
        .iter()
        .map(|iv| {
            (
                iv["start_s"].as_f64().unwrap(),
                iv["end_s"].as_f64().unwrap(),
            )
        })
        .collect();
    lc.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert!(lc.windows(2).all(|w| w[0].1 <= w[1].0), "{lc:?}");
    let text = ok(&tandem(["schedule", &s(&state)]));
    assert!(
        text.contains("robot 3  |") && text.contains("lower bound"),
        "{text}"
    );

    let sim = dir.join("sim");
    let stdout = ok(&tandem([
        "simulate",
        &s(&state),
        "--need",
        &s(&ex.join("need.csv")),
        "--rounds",
        "1",
        "--write",
        &s(&sim),
    ]));
    assert!(stdout.contains("wrote 9 files"), "{stdout}");
    let files = |robot: usize| {
        let stem = format!("round_1_robot_{robot}");
        [
            sim.join(format!("{stem}.csv")),
            sim.join(format!("{stem}.reflog.csv")),
            sim.join(format!("{stem}.corr.csv")),
        ]
    };
    // Two executions for a three-robot state: refused, the state unchanged.
    let before = std::fs::read(&state).unwrap();
    let out = tandem(record_args(&state, &files(1), &files(2)));
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("3 robots") && err.contains("exactly 3"),
        "{err}"
    );
    assert_eq!(std::fs::read(&state).unwrap(), before);
    let mut args = vec![PathBuf::from("record"), state.clone()];
    for robot in 1..=3 {
        let [e, l, c] = files(robot);
        args.extend([
            "--execution".into(),
            e,
            "--log".into(),
            l,
            "--corrections".into(),
            c,
        ]);
    }
    let stdout = ok(&tandem(args));
    assert!(stdout.contains("recorded round 1"), "{stdout}");
    let p = Planner::load(&state).unwrap();
    assert_eq!((p.n_robots(), p.rounds_recorded()), (3, 1));

    let mut bad = fit.clone();
    let k = bad.iter().position(|a| a == "3").unwrap();
    bad[k] = "17".into();
    let out = tandem(&bad);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--robots 17") && err.contains("1 to 16 robots"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
