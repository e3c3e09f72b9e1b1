//! What the switches between two robots' low-confidence runs cost on a planned problem, and
//! whether the scheduler leaves time on the table: the bounds (margin-free `T*₀`, the bound
//! that charges every switch its least margin), the room the plan keeps at each switch, and
//! the scheduler re-run from scratch with its default budget, with eight times the
//! completion's margin checks, and with 50 000 sampled candidates.
//!
//! ```text
//! cargo run --release -p tandem-schedule --example switch_cost -- PLAN.json [PLAN.json …]
//! ```
//!
//! `PLAN.json`: an object with the fields `problem` (a serialized `Problem`) and `schedule`
//! (a serialized two-robot `Schedule` of it, e.g. a planner's current schedule). Prints one
//! JSON object per file. Bad input: a message naming the file on stderr, exit code 2.
#![allow(clippy::print_stdout, reason = "an example reports to the terminal")]

use std::process::ExitCode;

use serde::Deserialize;
use tandem_schedule::{
    ExactParams, Outcome, Problem, SamplerParams, Schedule, drag_charged_bound, sample_schedule,
    switch_charged_bound, validate,
};

/// The fields read from a plan file.
#[derive(Deserialize)]
struct Plan {
    problem: Problem,
    schedule: Schedule,
}

/// The room (s) at every switch of `s`: consecutive low-confidence intervals (by start) of
/// different robots, the later's start minus the earlier's end.
fn switches(p: &Problem, s: &Schedule) -> Vec<f64> {
    let Ok(lc) = s.lc_intervals(p) else {
        return Vec::new();
    };
    let mut all: Vec<(f64, f64, usize)> = lc
        .iter()
        .enumerate()
        .flat_map(|(r, iv)| iv.iter().map(move |i| (i.start_s, i.end_s, r)))
        .collect();
    all.sort_by(|a, b| a.0.total_cmp(&b.0));
    all.windows(2)
        .filter(|w| w[0].2 != w[1].2)
        .map(|w| w[1].0 - w[0].1)
        .collect()
}

/// `T_total`, source and the rooms at its switches of one outcome, as JSON.
fn summary(p: &Problem, out: &Outcome) -> serde_json::Value {
    let rooms = switches(p, &out.schedule);
    serde_json::json!({
        "t_total_s": out.t_total_s,
        "source": format!("{:?}", out.source),
        "switches": rooms.len(),
        "room_s": rooms,
    })
}

fn one(path: &str) -> Result<serde_json::Value, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{path}: {e}"))?;
    let plan: Plan = serde_json::from_str(&text).map_err(|e| format!("{path}: {e}"))?;
    let (p, s) = (&plan.problem, &plan.schedule);
    let tick_s = s.tick_s;
    let exact = ExactParams::default();
    let bound = switch_charged_bound(p, &exact, tick_s).map_err(|e| format!("{path}: {e}"))?;
    let drag = drag_charged_bound(p, &exact, tick_s).map_err(|e| format!("{path}: {e}"))?;
    let plan_rooms = switches(p, s);
    let run = |params: SamplerParams| {
        sample_schedule(p, &params, None).map_err(|e| format!("{path}: {e}"))
    };
    let base = SamplerParams {
        tick_s: Some(tick_s),
        seed: 0,
        ..SamplerParams::default()
    };
    let default = run(base.clone())?;
    let more_checks = run(SamplerParams {
        exact: ExactParams {
            max_margin_checks: 8 * exact.max_margin_checks,
            ..exact.clone()
        },
        ..base.clone()
    })?;
    let sampled = run(SamplerParams {
        samples: 50_000,
        ..base
    })?;
    Ok(serde_json::json!({
        "file": path,
        "holds": !p.usable_holds().is_empty(),
        "lc_runs": p.runs().iter().filter(|r| !r.high_conf).count(),
        "tick_s": tick_s,
        "plan_t_total_s": s.t_total_s(p.dt_s()),
        "plan_valid": validate(p, s).is_ok(),
        "plan_switches": plan_rooms.len(),
        "plan_room_s": plan_rooms,
        "margin_free_s": bound.margin_free_s,
        "switch_charged_s": bound.lower_bound_s,
        "charged": bound.charged,
        "charge_s": bound.charge_s,
        "drag_charged_s": drag.lower_bound_s,
        "drag_max_charge_s": drag.max_charge_s,
        "scratch": summary(p, &default),
        "checks_x8": summary(p, &more_checks),
        "samples_50000": summary(p, &sampled),
    }))
}

fn main() -> ExitCode {
    let paths: Vec<String> = std::env::args().skip(1).collect();
    if paths.is_empty() {
        eprintln!("usage: switch_cost PLAN.json [PLAN.json …]");
        return ExitCode::from(2);
    }
    for path in &paths {
        match one(path) {
            Ok(v) => println!("{v}"),
            Err(e) => {
                eprintln!("{e}");
                return ExitCode::from(2);
            }
        }
    }
    ExitCode::SUCCESS
}
