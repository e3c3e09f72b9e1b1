//! Dumps the last plan of a zoo run in rounds of two robots (the problem, the planner's
//! schedule and its `T_total`), for `tandem-schedule`'s `switch_cost` example.
//!
//! `cargo run --release -p tandem-zoo --example plans_dump -- OUT_DIR ROUNDS SEED FAMILY...`
//! writes `OUT_DIR/FAMILY-SEED.json` with the fields `problem`, `schedule`, `t_total_s`,
//! `previous` (the schedule before the last re-schedule) and `params` (the sampler's).

#![allow(clippy::print_stdout, reason = "an example reports to the terminal")]

use std::sync::Mutex;

use tandem_planner::{PlannerParams, derive_seed};
use tandem_sim::study::{Cell, RoundView, StudyConfig, run_trial_on};
use tandem_zoo::eval::prepare;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [out, rounds, seed, families @ ..] = &args[..] else {
        return Err("usage: plans_dump OUT_DIR ROUNDS SEED FAMILY...".into());
    };
    let (seed, rounds): (u64, usize) = (seed.parse()?, rounds.parse()?);
    for name in families {
        let fam = tandem_zoo::family(name)?;
        let prep = prepare(fam, seed, &PlannerParams::default(), false)?;
        let family = prep.family.bytes().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
        });
        let config = StudyConfig {
            trials: 1,
            executions: rounds * 2,
            robots: 2,
            samples: prep.planner.sampler.samples,
            seed: derive_seed(derive_seed(family, prep.seed), 2 << 1),
            example_iterations: Vec::new(),
            planner: prep.planner.clone(),
            cell: Cell::Rounds,
            ..StudyConfig::default()
        };
        let plans: Mutex<Vec<serde_json::Value>> = Mutex::new(Vec::new());
        let observe = |view: RoundView<'_>| {
            let p = view.planner;
            let v = serde_json::json!({
                "problem": p.problem(),
                "schedule": p.outcome().schedule,
                "t_total_s": p.outcome().t_total_s,
                "params": p.params().sampler,
            });
            plans
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
                .push(v);
        };
        let run = run_trial_on(
            &config,
            &prep.model,
            prep.truth.as_ref(),
            0,
            &|_| {},
            &observe,
        )?;
        let mut plans = plans.into_inner()?;
        let last = serde_json::json!({
            "problem": run.planner.problem(),
            "schedule": run.planner.outcome().schedule,
            "t_total_s": run.planner.outcome().t_total_s,
            "previous": plans.last().map(|p| p["schedule"].clone()),
            "params": run.planner.params().sampler,
        });
        plans.clear();
        let path = format!("{out}/{name}-{seed}.json");
        std::fs::write(&path, serde_json::to_string(&last)?)?;
        println!("{path}: T_total {:.3}", run.planner.outcome().t_total_s);
    }
    Ok(())
}
