//! The operator's switch time and load cap on the command line (issue 41): `--switch-s` and
//! `--max-busy` of `fit` and `schedule`, stored in the state file, printed by the summaries
//! and `tandem params`, and refused with the flag and its range when out of range.

mod common;

use std::path::{Path, PathBuf};

use common::{ok, scratch, small_demos, tandem};
use tandem::Planner;
use tandem::planner::Cell;
use tandem::schedule::cyclic::period_lower_bound_with_switch_s;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn s(p: &Path) -> String {
    p.display().to_string()
}

/// Fits the small task into `dir/cell.tandem` with `extra` flags; returns the state and stdout.
fn fit(dir: &Path, extra: &[&str]) -> (PathBuf, String) {
    let demos = small_demos(dir);
    let state = dir.join("cell.tandem");
    let mut args: Vec<String> = vec!["fit".into()];
    args.extend(demos.iter().map(|p| s(p)));
    args.extend(["--samples", "100"].map(String::from));
    args.extend(extra.iter().map(|x| x.to_string()));
    args.extend(["-o".into(), s(&state), "--force".into()]);
    let text = ok(&tandem(&args));
    (state, text)
}

#[test]
fn fit_stores_the_switch_time_and_load_cap_and_the_summaries_print_them() {
    let dir = scratch("operator-fit");
    // The small task's robots are about 1 s long: a switch time its serial schedule can keep
    // (0.38 s between the stretches when the worst case runs the rest at its fastest).
    let (state, text) = fit(&dir, &["--switch-s", "0.25", "--max-busy", "0.8"]);
    let p = Planner::load(&state).expect("the state loads");
    assert_eq!(p.params().sampler.switch_s, 0.25);
    assert_eq!(p.params().sampler.max_busy_share, 0.8);
    let line = "operator: switch time δ 0.25 s (at least δ between one robot's low-confidence \
                stretch and another's); load cap u_max 0.8 (busy at most 80 % of the time, \
                switches included)";
    assert!(text.contains(line), "{text}");
    let inspect = ok(&tandem(["inspect", &s(&state)]));
    assert!(inspect.contains(line), "{inspect}");
    // Without the flags nothing is stored and no operator line is printed (today's output).
    let (state, text) = fit(&dir, &[]);
    let p = Planner::load(&state).expect("the state loads");
    assert_eq!(
        (
            p.params().sampler.switch_s,
            p.params().sampler.max_busy_share
        ),
        (0.0, 1.0)
    );
    assert!(!text.contains("operator:"), "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn schedule_sets_them_and_saves_them_only_with_save() {
    let dir = scratch("operator-schedule");
    let (state, _) = fit(&dir, &[]);
    let text = ok(&tandem([
        "schedule",
        &s(&state),
        "--samples",
        "50",
        "--switch-s",
        "0.2",
    ]));
    assert!(text.contains("operator: switch time δ 0.2 s"), "{text}");
    assert!(text.contains("no load cap"), "{text}");
    // Shown, not saved.
    assert_eq!(
        Planner::load(&state).unwrap().params().sampler.switch_s,
        0.0
    );
    ok(&tandem([
        "schedule",
        &s(&state),
        "--samples",
        "50",
        "--switch-s",
        "0.2",
        "--max-busy",
        "0.9",
        "--save",
    ]));
    let p = Planner::load(&state).unwrap();
    assert_eq!(
        (
            p.params().sampler.switch_s,
            p.params().sampler.max_busy_share
        ),
        (0.2, 0.9)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The continuous cell's plan with a switch time is the planner's with it, and its text names
/// the δ-bound: `N·(L + I + δ)` for the golden state's two robots.
#[test]
fn continuous_cell_with_a_switch_time_prints_the_delta_bound() {
    let state = repo().join("fixtures/state/example.tandem");
    let mut planner = Planner::load(&state).unwrap();
    let without = planner.plan(Cell::Continuous).unwrap();
    let without = without.as_continuous().unwrap().plan().clone();
    planner.set_operator(2.0, 1.0).unwrap();
    let with = planner.plan(Cell::Continuous).unwrap();
    let with = with.as_continuous().unwrap().plan().clone();
    // Each change of robot costs the operator 2 s: the period can only grow.
    assert!(with.period_s >= without.period_s, "{with:?} {without:?}");
    let bound = period_lower_bound_with_switch_s(planner.problem(), 2, 2.0).unwrap();
    assert!(with.lower_bound_s >= bound - 1e-9);
    let json = ok(&tandem([
        "schedule",
        &s(&state),
        "--cell",
        "continuous",
        "--switch-s",
        "2",
        "--json",
    ]));
    let back: tandem::schedule::CyclicPlan = serde_json::from_str(&json).unwrap();
    assert_eq!(back, with);
    let text = ok(&tandem([
        "schedule",
        &s(&state),
        "--cell",
        "continuous",
        "--switch-s",
        "2",
    ]));
    assert!(text.contains("the δ-bound"), "{text}");
    assert!(
        text.contains("operator: switch time δ 2.00 s per change of robot"),
        "{text}"
    );
    // Two robots of one stretch each (the golden task) change robot twice per period.
    let changes = with
        .order
        .iter()
        .zip(with.order.iter().cycle().skip(1))
        .filter(|(a, b)| a.robot != b.robot)
        .count();
    assert!(
        text.contains(&format!("({changes} per period)")),
        "{changes}: {text}"
    );
    let plain = ok(&tandem(["schedule", &s(&state), "--cell", "continuous"]));
    assert!(!plain.contains("δ-bound"), "{plain}");
}

#[test]
fn out_of_range_values_name_the_flag_and_the_range() {
    let dir = scratch("operator-bad");
    let golden = repo().join("fixtures/state/example.tandem");
    let demos = small_demos(&dir);
    for (flag, value, range) in [
        ("--switch-s", "-1", "≥ 0"),
        ("--switch-s", "NaN", "≥ 0"),
        ("--switch-s", "inf", "≥ 0"),
        ("--max-busy", "0", "(0, 1]"),
        ("--max-busy", "1.5", "(0, 1]"),
    ] {
        let mut fit: Vec<String> = vec!["fit".into()];
        fit.extend(demos.iter().map(|p| s(p)));
        fit.extend([flag, value, "-o"].map(String::from));
        fit.push(s(&dir.join("never.tandem")));
        let sched: Vec<String> = vec!["schedule".into(), s(&golden), flag.into(), value.into()];
        for args in [fit, sched] {
            let out = tandem(&args);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
            assert!(
                stderr.contains(&format!("{flag} ")) && stderr.contains(range),
                "{args:?}: {stderr}"
            );
            assert!(!stderr.contains("panicked"), "{stderr}");
        }
    }
    assert!(!dir.join("never.tandem").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn params_names_them_with_their_units() {
    let text = ok(&tandem(["params"]));
    assert!(text.contains("switch_s = 0.0"), "{text}");
    assert!(text.contains("max_busy_share = 1.0"), "{text}");
    assert!(
        text.contains("switch_s: the operator's switch time δ in seconds"),
        "{text}"
    );
    assert!(
        text.contains("max_busy_share: the operator's load cap u_max, a share of the time"),
        "{text}"
    );
}

/// Rounds with two operators (issue 44): `tandem schedule --operators 2` on a rounds state of
/// four robots prints the sectored round — two sectors of two robots, its `T_total` and the
/// fleet bound — as the library's `Planner::sectored_rounds` gives them; one operator prints
/// no such line, and the state is not changed without `--save`.
#[test]
fn schedule_with_two_operators_prints_the_sectors_of_the_round() {
    let dir = scratch("operator-sectors");
    let (state, text) = fit(&dir, &["--robots", "4"]);
    assert!(!text.contains("rounds with"), "{text}");
    let text = ok(&tandem([
        "schedule",
        &s(&state),
        "--samples",
        "50",
        "--operators",
        "2",
    ]));
    let mut p = Planner::load(&state).expect("the state loads");
    assert_eq!(p.params().sampler.operators, 1, "not saved");
    p.set_operators(2).unwrap();
    let (sectors, _) = p.sectored_rounds().unwrap();
    assert_eq!(sectors.sizes, vec![2, 2]);
    let bound = tandem::schedule::fleet_operator_bound_s(p.problem(), 4, 2).unwrap();
    assert_eq!(sectors.lower_bound_s, bound);
    assert!(sectors.t_total_s >= bound);
    let line = format!(
        "rounds with 2 operators: sectors of 2 + 2 robots (one operator each), T_total {:.2} s \
         (no round of 2 operators is shorter than {bound:.2} s)",
        sectors.t_total_s
    );
    assert!(text.contains(&line), "{line}\n{text}");
    assert!(text.contains("2 operators (at most 2 robots"), "{text}");
    let plain = ok(&tandem(["schedule", &s(&state), "--samples", "50"]));
    assert!(!plain.contains("rounds with"), "{plain}");
    let _ = std::fs::remove_dir_all(&dir);
}
