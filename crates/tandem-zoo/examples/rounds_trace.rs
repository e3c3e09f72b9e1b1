//! One zoo run in rounds, traced: per round the schedule's `T_total`, source, certificate and
//! what became of the previous schedule, and beside it what a re-schedule of the same problem
//! would give without the previous schedule (`--fresh`).
//!
//! `cargo run --release -p tandem-zoo --example rounds_trace -- FAMILY SEED ROBOTS ROUNDS
//! [--fresh] [--dump ROUND PATH]` (the run of `cargo xtask zoo --seeds SEED --families FAMILY
//! --robots ROBOTS --cell rounds --rounds ROUNDS --no-spread`, the same study seed). `--dump`
//! writes the problem of round `ROUND` as JSON to `PATH` (fields `problem`, `schedule`,
//! `t_total_s`, `tick_s`, `seed`: the seed of the round's re-schedule, and `previous`: the round before's
//! schedule), the input of a scheduler test.

#![allow(clippy::print_stdout, reason = "an example reports to the terminal")]

use std::sync::Mutex;

use tandem_planner::{PlannerParams, derive_seed};
use tandem_schedule::sample_schedule_n;
use tandem_sim::study::{Cell, RoundView, StudyConfig, run_trial_on};
use tandem_zoo::eval::prepare;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [family, seed, robots, rounds, rest @ ..] = &args[..] else {
        return Err(
            "usage: rounds_trace FAMILY SEED ROBOTS ROUNDS [--fresh] [--dump ROUND PATH]".into(),
        );
    };
    let fresh = rest.iter().any(|a| a == "--fresh");
    let dump: Option<(usize, String)> = match rest.iter().position(|a| a == "--dump") {
        Some(i) => match (rest.get(i + 1), rest.get(i + 2)) {
            (Some(r), Some(path)) => Some((r.parse()?, path.clone())),
            _ => return Err("--dump needs ROUND and PATH".into()),
        },
        None => None,
    };
    let previous = Mutex::new(None::<tandem_schedule::Schedule>);
    let (seed, robots, rounds): (u64, usize, usize) =
        (seed.parse()?, robots.parse()?, rounds.parse()?);
    let fam = tandem_zoo::family(family)?;
    let prep = prepare(fam, seed, &PlannerParams::default(), false)?;
    // The zoo's study seed of a run in rounds (tandem_zoo::eval::run, `run_seed`).
    let name_hash = prep.family.bytes().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    });
    let config = StudyConfig {
        trials: 1,
        executions: rounds * robots,
        robots,
        samples: prep.planner.sampler.samples,
        seed: derive_seed(derive_seed(name_hash, prep.seed), (robots as u64) << 1),
        example_iterations: Vec::new(),
        planner: prep.planner.clone(),
        cell: Cell::Rounds,
        ..StudyConfig::default()
    };
    let lines = Mutex::new(Vec::new());
    let observe = |view: RoundView<'_>| {
        let p = view.planner;
        let o = p.outcome();
        let split = o.gap_split();
        let mut line = format!(
            "round {:>2}: T {:>8.3} s  {:<9}  bound {:>7.3}{}  gap {:>6.1} % (search {:>5.1}, margins {:>5.1})  hc {:>5.1} %  fate: {}",
            view.round,
            o.t_total_s,
            o.source.name(),
            o.lower_bound_s,
            if o.bound_is_optimum { "*" } else { " " },
            100.0 * o.gap,
            split.map_or(f64::NAN, |s| 100.0 * s.search),
            split.map_or(f64::NAN, |s| 100.0 * s.margins),
            100.0 * p.confidence().high_share(),
            o.previous.describe().unwrap_or_default(),
        );
        line += &format!("\n          offsets {:?}", o.schedule.offsets_s);
        let mut prev = previous
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Some((round, path)) = &dump
            && *round == view.round
        {
            let v = serde_json::json!({
                "problem": p.problem(),
                "schedule": o.schedule,
                "t_total_s": o.t_total_s,
                "tick_s": o.schedule.tick_s,
                "seed": derive_seed(p.params().sampler.seed, p.rounds_recorded() as u64),
                "previous": *prev,
            });
            match serde_json::to_string(&v).map(|t| std::fs::write(path, t)) {
                Ok(Ok(())) => line += &format!("\n          dumped to {path}"),
                Ok(Err(e)) => line += &format!("\n          dump: {e}"),
                Err(e) => line += &format!("\n          dump: {e}"),
            }
        }
        *prev = Some(o.schedule.clone());
        drop(prev);
        if fresh {
            let params = tandem_schedule::SamplerParams {
                tick_s: Some(o.schedule.tick_s),
                ..p.params().sampler.clone()
            };
            match sample_schedule_n(p.problem(), robots, &params, None) {
                Ok(f) => {
                    line += &format!(
                        "\n          fresh: T {:.3} s {} (checks {})",
                        f.t_total_s,
                        f.source.name(),
                        f.stats.margin_checks
                    );
                }
                Err(e) => line += &format!("\n          fresh: {e}"),
            }
        }
        lines
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .push(line);
    };
    let run = run_trial_on(
        &config,
        &prep.model,
        prep.truth.as_ref(),
        0,
        &|_| {},
        &observe,
    )?;
    for l in lines.into_inner()? {
        println!("{l}");
    }
    let o = run.planner.outcome();
    println!(
        "final: T {:.3} s {} bound {:.3} fate: {}",
        o.t_total_s,
        o.source.name(),
        o.lower_bound_s,
        o.previous.describe().unwrap_or_default()
    );
    Ok(())
}
