//! Where the samples falsely trusted after the loop came from: one zoo run of two robots in
//! rounds (the study seed of `cargo xtask zoo --seeds SEED --families FAMILY --robots 2
//! --cell rounds --no-spread`), and for every run of reference samples that can need the
//! operator and are high-confidence at the end: its need, whether the demonstrations vary
//! there, the round it became trusted (0: from the prior) with the votes `c/s`, the error
//! rates and `σ²_D` of then, and its neighbours. The last line sorts the samples where the
//! demonstrations vary: trusted from the prior, latched after fewer than 10 votes, latched
//! while `f̂` was above 3 %, other (docs/decisions.md, "Graded needs: the error rate's
//! estimate and the latch's evidence").
//!
//! `cargo run --release -p tandem-zoo --example trust_trace -- FAMILY SEED [ROUNDS]`

#![allow(
    clippy::print_stdout,
    clippy::type_complexity,
    clippy::needless_range_loop,
    reason = "a diagnosis example that reports to the terminal"
)]
use std::sync::Mutex;
use tandem_planner::{PlannerParams, derive_seed};
use tandem_sim::study::{Cell, RoundView, StudyConfig, run_trial_on};
use tandem_zoo::eval::prepare;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let fam = tandem_zoo::family(&args[1]).unwrap();
    let seed: u64 = args[2].parse().unwrap();
    let rounds: usize = args.get(3).map_or(30, |s| s.parse().unwrap());
    let params = PlannerParams::default();
    let prep = prepare(fam, seed, &params, false).unwrap();
    let task = (fam.generate)(seed).unwrap();
    let r = prep.model.reference_idx();
    let prog = &task.progress[r];
    let level: Vec<f64> = prog.iter().map(|&p| task.need_at(p)).collect();
    let n_ref = prep.model.n_ref();
    let s2 = prep.model.sigma2_d().to_vec();
    let conf0 = tandem_confidence::Confidence::from_prior(&s2, params.confidence.clone()).unwrap();
    println!(
        "n_ref {n_ref} ref {r} need spans {:?} variable {:?}",
        task.need, task.variable
    );
    let became: Mutex<Vec<Option<(usize, f64, f64, f64, f64, f64)>>> = Mutex::new(
        conf0
            .conf()
            .iter()
            .map(|&h| h.then_some((0, 0.0, 0.0, 0.0, 0.0, 0.0)))
            .collect(),
    );
    let sup_counts: Mutex<Vec<(usize, usize)>> = Mutex::new(vec![(0, 0); n_ref]);
    let observe = |view: RoundView<'_>| {
        let pl = view.planner;
        let conf = pl.confidence().conf();
        let obs = pl.observations();
        let rates = pl.error_rates().unwrap();
        let mut b = became.lock().unwrap();
        for n in 0..n_ref {
            if conf[n] && b[n].is_none() {
                b[n] = Some((
                    view.round - 1,
                    obs.corrections()[n],
                    obs.supervised()[n],
                    rates.false_correction_rate,
                    rates.miss_rate,
                    pl.model().sigma2_d()[n],
                ));
            }
            if !conf[n] {
                b[n] = None;
            }
        }
        if view.round % 5 == 1 {
            println!(
                "round {} f {:.4} m {:.4} high {:.1}%",
                view.round,
                rates.false_correction_rate,
                rates.miss_rate,
                100.0 * pl.confidence().high_share()
            );
        }
        let mut sc = sup_counts.lock().unwrap();
        for rob in &view.run.robots {
            for (k, &t) in rob.ref_time_log.iter().enumerate() {
                let n = (t.round() as usize).min(n_ref - 1);
                if rob.supervised[k] {
                    sc[n].0 += 1;
                    if rob.corrected[k] {
                        sc[n].1 += 1;
                    }
                }
            }
        }
    };
    let config = StudyConfig {
        trials: 1,
        executions: rounds * 2,
        robots: 2,
        samples: prep.planner.sampler.samples,
        seed: {
            let h = prep.family.bytes().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| {
                (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
            });
            derive_seed(derive_seed(h, prep.seed), 2u64 << 1)
        },
        example_iterations: Vec::new(),
        planner: prep.planner.clone(),
        cell: Cell::Rounds,
        ..StudyConfig::default()
    };
    let run = run_trial_on(
        &config,
        &prep.model,
        prep.truth.as_ref(),
        0,
        &|_| {},
        &observe,
    )
    .unwrap();
    let pl = &run.planner;
    let conf = pl.confidence().conf();
    let obs = pl.observations();
    let rates = pl.error_rates().unwrap();
    println!(
        "final f {:.4} m {:.4} mu' {:.4}",
        rates.false_correction_rate,
        rates.miss_rate,
        rates.shifted_mu_c(params.confidence.mu_c)
    );
    let b = became.lock().unwrap();
    let sc = sup_counts.lock().unwrap();
    let mut last: Option<usize> = None;
    let mut start = 0;
    let flush = |a: usize, e: usize| {
        println!(
            "  run {a}..{e} ({} samples) need {:.2} var {:?} became {:?} | final c/s at start {:.2}/{:.2}, s2 {:.4}, ticks sup/corr {:?}",
            e - a,
            level[a],
            prep.need_kind[a],
            b[a],
            obs.corrections()[a],
            obs.supervised()[a],
            pl.model().sigma2_d()[a],
            sc[a]
        );
        let lo = a.saturating_sub(1);
        let hi = e.min(n_ref - 1);
        println!(
            "     before {lo}: high {} need {:.2} c/s {:.2}/{:.2} | after {hi}: high {} need {:.2} c/s {:.2}/{:.2}",
            conf[lo],
            level[lo],
            obs.corrections()[lo],
            obs.supervised()[lo],
            conf[hi],
            level[hi],
            obs.corrections()[hi],
            obs.supervised()[hi]
        );
        let mid = (a + e) / 2;
        println!(
            "     mid {mid}: became {:?} c/s {:.2}/{:.2} ticks {:?}",
            b[mid],
            obs.corrections()[mid],
            obs.supervised()[mid],
            sc[mid]
        );
    };
    for n in 0..=n_ref {
        let ft = n < n_ref && conf[n] && prep.need_kind[n].is_some();
        match (ft, last) {
            (true, None) => {
                last = Some(n);
                start = n;
            }
            (false, Some(_)) => {
                flush(start, n);
                last = None;
            }
            _ => {}
        }
    }
    let vary = (0..n_ref)
        .filter(|&n| conf[n] && prep.need_kind[n] == Some(true))
        .count();
    let agree = (0..n_ref)
        .filter(|&n| conf[n] && prep.need_kind[n] == Some(false))
        .count();
    println!("falsely trusted vary {vary} agree {agree}");
    let (mut prior, mut few, mut inflated, mut other) = (0, 0, 0, 0);
    for n in 0..n_ref {
        if !(conf[n] && prep.need_kind[n] == Some(true)) {
            continue;
        }
        match b[n] {
            Some((0, ..)) => prior += 1,
            Some((_, _, _, f, ..)) if f > 0.03 => inflated += 1,
            Some((_, _, s, ..)) if s < 10.0 => few += 1,
            _ => other += 1,
        }
    }
    println!(
        "SUMMARY vary: prior {prior} latched-after-few-votes(<10) {few} latched-with-f>3% {inflated} other {other}"
    );
}
