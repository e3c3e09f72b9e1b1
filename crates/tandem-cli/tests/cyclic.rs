//! `tandem schedule --cell continuous`: the cyclic plan of a continuous cell through the
//! binary, against `tandem::schedule::cyclic_plan` on the same state, its Gantt of two
//! periods, and its errors.

mod common;

use std::path::{Path, PathBuf};

use common::{ok, scratch, small_demos, tandem, write};
use tandem::Planner;
use tandem::planner::Cell;
use tandem::schedule::{CyclicParams, CyclicPlan, cyclic_plan};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn s(p: &Path) -> String {
    p.display().to_string()
}

/// The plan `cyclic_plan` computes for the state file's problem and robot count.
/// The plan `tandem schedule --cell continuous` shows: the token rule's hand-overs counted
/// at the schedule's control tick, the tick the cell runs at.
fn plan_of(state: &Path) -> CyclicPlan {
    let p = Planner::load(state).expect("the state loads");
    let params = CyclicParams {
        handover_tick_s: Some(p.schedule().tick_s),
        ..CyclicParams::default()
    };
    cyclic_plan(p.problem(), p.n_robots(), &params).expect("a cyclic plan")
}

/// The number after `prefix` in `text` (up to the next space), and how many decimals it has.
fn number_after(text: &str, prefix: &str) -> (f64, usize) {
    let at = text
        .find(prefix)
        .unwrap_or_else(|| panic!("no {prefix:?} in\n{text}"))
        + prefix.len();
    let word = text[at..].split_whitespace().next().expect("a number");
    let decimals = word.split_once('.').map_or(0, |(_, d)| d.len());
    (word.parse().expect("a number"), decimals)
}

/// The Gantt's bars by row name (`robot 1`, …, `operator`): the text between the `|`s.
fn gantt_rows(text: &str) -> Vec<(String, Vec<char>)> {
    text.lines()
        .filter_map(|l| {
            let (name, rest) = l.split_once('|')?;
            let bar = rest.strip_suffix('|')?;
            Some((name.trim().to_string(), bar.chars().collect()))
        })
        .collect()
}

/// Checks the text output of `plan` on the state: the printed period is the plan's, the
/// Gantt spans two periods with one row per robot and the operator's, each robot's bar
/// repeats after one period, and the operator row names exactly the one robot running
/// low-confidence (never two at once).
fn check_text(text: &str, plan: &CyclicPlan) {
    let (period, decimals) = number_after(text, "period P ");
    assert!(
        (period - plan.period_s).abs() <= 0.5 * 10f64.powi(-(decimals as i32)) + 1e-12,
        "printed P {period} vs {}\n{text}",
        plan.period_s
    );
    let (per_hour, _) = number_after(text, "s: ");
    assert!(
        (per_hour - plan.tasks_per_hour).abs() <= 0.005 + 1e-9,
        "{text}"
    );
    let (end, decimals) = number_after(text, "2P = ");
    assert!(
        (end - 2.0 * plan.period_s).abs() <= 0.5 * 10f64.powi(-(decimals as i32)) + 1e-12,
        "{text}"
    );
    assert!(text.contains("demonstrated mean speed"), "{text}");
    assert!(
        text.contains("`tandem record` learns from rounds"),
        "{text}"
    );
    let rows = gantt_rows(text);
    let n = plan.n_robots;
    assert_eq!(rows.len(), n + 1, "{text}");
    for (i, (name, _)) in rows[..n].iter().enumerate() {
        assert_eq!(name, &format!("robot {}", i + 1));
    }
    assert_eq!(rows[n].0, "operator");
    let width = rows[0].1.len();
    assert_eq!(width % 2, 0);
    let half = width / 2;
    for (name, bar) in &rows {
        assert_eq!(bar.len(), width, "{name}: {text}");
        // Two periods: the second repeats the first.
        assert_eq!(
            bar[..half],
            bar[half..],
            "{name} does not repeat after P:\n{text}"
        );
    }
    let operator = &rows[n].1;
    assert!(!operator.contains(&'!'), "two robots at once:\n{text}");
    for (c, &supervised) in operator.iter().enumerate() {
        let low: Vec<usize> = (0..n).filter(|&r| rows[r].1[c] == '#').collect();
        let expected = match low.as_slice() {
            [] => '.',
            [r] => char::from_digit(*r as u32 + 1, 10).expect("a digit"),
            _ => panic!("column {c}: robots {low:?} low-confidence at once:\n{text}"),
        };
        assert_eq!(supervised, expected, "column {c}:\n{text}");
    }
    // The operator row's busy columns match the busy share, within one column per stretch
    // edge.
    let busy = operator.iter().filter(|&&c| c != '.').count() as f64 / width as f64;
    let edges = 2.0 * plan.order.len() as f64 / half as f64;
    assert!(
        (busy - plan.operator_share).abs() <= edges + 1e-9,
        "busy {busy} vs share {}\n{text}",
        plan.operator_share
    );
}

#[test]
fn continuous_cell_on_the_golden_state_prints_the_plan_of_cyclic_plan() {
    let state = repo().join("fixtures/state/example.tandem");
    let plan = plan_of(&state);
    let json = ok(&tandem([
        "schedule",
        &s(&state),
        "--cell",
        "continuous",
        "--json",
    ]));
    // Exactly the plan's serde form.
    assert_eq!(
        json.trim_end(),
        serde_json::to_string_pretty(&plan).unwrap()
    );
    let back: CyclicPlan = serde_json::from_str(&json).unwrap();
    assert_eq!(back.order, plan.order);
    assert!(plan.order_exhaustive && plan.gap.abs() < 1e-9);
    let text = ok(&tandem(["schedule", &s(&state), "--cell", "continuous"]));
    check_text(&text, &plan);
    assert!(text.contains("order search: exhaustive"), "{text}");
    assert!(text.contains("r1s1 → r2s1"), "{text}");
    // The default is the rounds schedule, as before.
    let rounds = ok(&tandem(["schedule", &s(&state), "--samples", "50"]));
    assert!(rounds.starts_with("T_total "), "{rounds}");
    assert_eq!(
        rounds,
        ok(&tandem([
            "schedule",
            &s(&state),
            "--samples",
            "50",
            "--cell",
            "rounds"
        ]))
    );
}

/// Three robots and a hold point on a task of its own (the small task of `common`, fitted
/// here): the plan's waits at the hold show as `h`, and the text is the plan's.
#[test]
fn three_robots_with_a_hold_wait_there_in_the_gantt() {
    let dir = scratch("cyclic-hold");
    let demos = small_demos(&dir);
    let state = dir.join("cell.tandem");
    let mut args: Vec<String> = vec!["fit".into()];
    args.extend(demos.iter().map(|p| s(p)));
    args.extend(
        [
            "--robots",
            "3",
            "--hold-at",
            "0.1,0.5",
            "--samples",
            "200",
            "-o",
        ]
        .map(String::from),
    );
    args.push(s(&state));
    ok(&tandem(&args));
    let plan = plan_of(&state);
    assert_eq!(plan.n_robots, 3);
    let text = ok(&tandem(["schedule", &s(&state), "--cell", "continuous"]));
    check_text(&text, &plan);
    let waits = plan
        .robots
        .iter()
        .flat_map(|r| &r.gaps)
        .filter(|g| g.wait_s > 0.0)
        .count();
    let h_rows = gantt_rows(&text)[..3]
        .iter()
        .filter(|(_, bar)| bar.contains(&'h'))
        .count();
    let start_waits = plan.robots.iter().filter(|r| r.start_wait_s > 0.0).count();
    if waits + start_waits == 0 {
        assert_eq!(h_rows, 0, "no planned wait, no `h`:\n{text}");
    } else {
        assert!(h_rows > 0, "planned waits without `h`:\n{text}");
    }
    let json = ok(&tandem([
        "schedule",
        &s(&state),
        "--cell",
        "continuous",
        "--json",
    ]));
    assert_eq!(
        json.trim_end(),
        serde_json::to_string_pretty(&plan).unwrap()
    );
}

#[test]
fn continuous_cell_errors_name_the_file_and_exit_2() {
    let dir = scratch("cyclic-errors");
    let missing = dir.join("missing.tandem");
    let not_state = write(&dir, "notes.tandem", "not a state file\n");
    let golden = repo().join("fixtures/state/example.tandem");
    for (args, names) in [
        (
            vec![s(&missing), "--cell".into(), "continuous".into()],
            s(&missing),
        ),
        (
            vec![s(&not_state), "--cell".into(), "continuous".into()],
            s(&not_state),
        ),
        (
            vec![
                s(&golden),
                "--cell".into(),
                "continuous".into(),
                "--save".into(),
            ],
            s(&golden),
        ),
        (
            vec![
                s(&golden),
                "--cell".into(),
                "continuous".into(),
                "--samples".into(),
                "10".into(),
            ],
            "--samples".into(),
        ),
        (
            vec![s(&golden), "--cell".into(), "circular".into()],
            "circular".into(),
        ),
    ] {
        let mut full = vec!["schedule".to_string()];
        full.extend(args);
        let out = tandem(&full);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{full:?}: {stderr}");
        assert!(stderr.contains(&names), "{full:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert!(out.stdout.is_empty(), "{full:?}");
    }
}

/// The tick default is the planner's for the command line too: a state whose schedule ticks
/// at 20 ms (`[sampler] tick_s`, not `Δt_s`) shows `Planner::plan(Cell::Continuous)`, the
/// plan with its hand-overs counted at 20 ms, which differs from the one at `Δt_s`.
#[test]
fn continuous_cell_plans_at_the_schedules_tick_as_the_planner_does() {
    let dir = scratch("cyclic-tick");
    let demos = small_demos(&dir);
    let params = write(&dir, "params.toml", "[sampler]\ntick_s = 0.02\n");
    let state = dir.join("cell.tandem");
    let mut args: Vec<String> = vec!["fit".into()];
    args.extend(demos.iter().map(|p| s(p)));
    args.extend(["--samples", "200", "--params"].map(String::from));
    args.push(s(&params));
    args.push("-o".into());
    args.push(s(&state));
    ok(&tandem(&args));
    let planner = Planner::load(&state).expect("the state loads");
    let tick_s = planner.schedule().tick_s;
    assert_eq!(tick_s, 0.02);
    assert!(planner.problem().dt_s() < tick_s);
    let planned = planner.plan(Cell::Continuous).expect("a plan");
    assert_eq!(planned.tick_s(), tick_s);
    let plan = planned.as_continuous().expect("a cyclic plan").plan();
    assert_eq!(plan, &plan_of(&state));
    let json = ok(&tandem([
        "schedule",
        &s(&state),
        "--cell",
        "continuous",
        "--json",
    ]));
    assert_eq!(json.trim_end(), serde_json::to_string_pretty(plan).unwrap());
    // At Δt_s the hand-overs cost less: another period, so the tick matters.
    let at_dt = CyclicParams {
        handover_tick_s: Some(planner.problem().dt_s()),
        ..CyclicParams::default()
    };
    let other = cyclic_plan(planner.problem(), planner.n_robots(), &at_dt).expect("a plan");
    assert!(
        other.period_s < plan.period_s,
        "{} vs {}",
        other.period_s,
        plan.period_s
    );
}
