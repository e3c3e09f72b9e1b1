//! The rounds scheduler with the operator's switch time `δ` on zoo families (issue 41;
//! docs/decisions.md, "Rounds schedules with the switch time and the load cap (issue 41)"):
//! the problem of a run in rounds after `ROUNDS` rounds of two robots, re-scheduled for
//! `N = 2, 3` robots at `δ ∈ {0, 0.5, 2, 7}` s: `T_total`, its source and the certificate's
//! `δ`-bound.
//!
//! `cargo run -p tandem-zoo --example switch_rounds -- SEED ROUNDS FAMILY...`

#![allow(clippy::print_stdout, reason = "an example reports to the terminal")]

use std::sync::Mutex;

use tandem_planner::{PlannerParams, derive_seed};
use tandem_schedule::{Problem, SamplerParams, sample_schedule_n, validate_with_switch};
use tandem_sim::study::{Cell, RoundView, StudyConfig, run_trial_on};
use tandem_zoo::eval::prepare;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [seed, rounds, families @ ..] = &args[..] else {
        return Err("usage: switch_rounds SEED ROUNDS FAMILY...".into());
    };
    let (seed, rounds): (u64, usize) = (seed.parse()?, rounds.parse()?);
    for name in families {
        let fam = tandem_zoo::family(name)?;
        let prep = prepare(fam, seed, &PlannerParams::default(), false)?;
        let config = StudyConfig {
            trials: 1,
            executions: rounds * 2,
            robots: 2,
            samples: prep.planner.sampler.samples,
            seed: derive_seed(prep.seed, 2),
            example_iterations: Vec::new(),
            planner: prep.planner.clone(),
            cell: Cell::Rounds,
            ..StudyConfig::default()
        };
        let last: Mutex<Option<(Problem, f64)>> = Mutex::new(None);
        let observe = |view: RoundView<'_>| {
            let p = view.planner;
            *last
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner) =
                Some((p.problem().clone(), p.outcome().schedule.tick_s));
        };
        run_trial_on(
            &config,
            &prep.model,
            prep.truth.as_ref(),
            0,
            &|_| {},
            &observe,
        )?;
        let Some((problem, tick_s)) = last.into_inner()? else {
            return Err("no round ran".into());
        };
        println!(
            "{name}: T_ref {}, {} LC samples, tick {tick_s} s",
            problem.n_ref(),
            problem.conf().iter().filter(|c| !**c).count()
        );
        for n in [2usize, 3] {
            for switch_s in [0.0, 0.5, 2.0, 7.0] {
                let params = SamplerParams {
                    tick_s: Some(tick_s),
                    switch_s,
                    ..prep.planner.sampler.clone()
                };
                match sample_schedule_n(&problem, n, &params, None) {
                    Ok(o) => println!(
                        "  N = {n}, δ = {switch_s} s: T_total {:.3} s ({}), bound {:.3} s{}, gap {:.2} %, valid {}",
                        o.t_total_s,
                        o.source.name(),
                        o.lower_bound_s,
                        if o.bound_is_optimum { " (proven)" } else { "" },
                        100.0 * o.gap,
                        validate_with_switch(&problem, &o.schedule, switch_s).is_ok()
                    ),
                    Err(e) => println!("  N = {n}, δ = {switch_s} s: {e}"),
                }
            }
        }
    }
    Ok(())
}
