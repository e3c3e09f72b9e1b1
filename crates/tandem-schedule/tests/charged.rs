//! The bound that charges every switch its least margin (`switch_charged_bound`): by hand on a
//! three-run problem, and as a lower bound on every schedule the scheduler returns (which
//! passes the margin check) and on the fastest serial schedule, on random problems; the lemma
//! it rests on (every switch of a schedule the check accepts keeps at least `M`, but robot 2's
//! first run after a robot-1 run that ended by robot 2's start) on the same schedules.

mod common;

use proptest::prelude::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tandem_schedule::testkit;
use tandem_schedule::{
    ExactParams, Problem, SamplerParams, Schedule, drag_charged_bound, sample_schedule,
    switch_charged_bound, validate,
};

/// `tol::BOUND_REL`: how far a correct bound may lie above a valid schedule's `T_total`.
const BOUND_REL: f64 = 2e-9;

/// The least clearance (s) over the switches of `s` that the lemma charges: consecutive LC
/// intervals (by start) of different robots, except robot 2's first interval right after a
/// robot-1 interval that ended by robot 2's start. `None` without such a switch.
fn least_charged_switch(p: &Problem, s: &Schedule) -> Option<f64> {
    let lc = s.lc_intervals(p).unwrap();
    let tau = s.offsets_s.first().copied().unwrap_or(0.0);
    let mut all: Vec<(f64, f64, usize, usize)> = lc
        .iter()
        .enumerate()
        .flat_map(|(r, iv)| {
            iv.iter()
                .enumerate()
                .map(move |(k, i)| (i.start_s, i.end_s, r, k))
        })
        .collect();
    all.sort_by(|a, b| a.0.total_cmp(&b.0));
    all.windows(2)
        .filter(|w| w[0].2 != w[1].2)
        .filter(|w| !(w[0].2 == 0 && w[1].2 == 1 && w[1].3 == 0 && w[0].1 <= tau + 1e-9))
        .map(|w| w[1].0 - w[0].1)
        .reduce(f64::min)
}

/// `bound` is at most the `T_total` of the valid schedule `s` at `tick_s`, and every charged
/// switch of `s` keeps the charge.
fn holds_for(p: &Problem, s: &Schedule, tick_s: f64) -> Result<(), TestCaseError> {
    prop_assert_eq!(validate(p, s), Ok(()));
    let b = switch_charged_bound(p, &ExactParams::default(), tick_s).unwrap();
    let t = s.t_total_s(p.dt_s());
    prop_assert!(
        b.lower_bound_s <= t * (1.0 + BOUND_REL),
        "bound {} above a valid schedule's T_total {t} ({b:?})",
        b.lower_bound_s
    );
    prop_assert!(b.lower_bound_s >= b.margin_free_s);
    // The drag-lead bound: below the valid schedule too, never below the step-only bound.
    let d = drag_charged_bound(p, &ExactParams::default(), tick_s).unwrap();
    prop_assert!(
        d.lower_bound_s <= t * (1.0 + BOUND_REL),
        "drag bound {} above a valid schedule's T_total {t} ({d:?})",
        d.lower_bound_s
    );
    prop_assert!(d.lower_bound_s >= b.lower_bound_s, "{d:?} below {b:?}");
    prop_assert!(d.max_charge_s >= d.charge_s && d.charged == b.charged);
    if b.charged
        && let Some(least) = least_charged_switch(p, s)
    {
        prop_assert!(
            least >= b.charge_s,
            "a switch of {least} s against the charge {} s",
            b.charge_s
        );
    }
    Ok(())
}

/// [LC, HC, LC] with gradients 1 in [0.5, 2], 10 samples each at 10 ms: LC runs of 0.1 s, an
/// HC gap of [0.05, 0.2] s. Margin-free: robot 1, robot 2, robot 1, robot 2 back to back,
/// 0.4 s. At a 10 ms tick `M = 0.01 · 1/0.5 = 0.02 s`. Robot 2's first run may follow robot
/// 1's without it (robot 2 starts at 0.1 s, when that run ends); robot 1's second run then
/// starts at 0.2 + 0.02 (its gap, 0.12 s, within [0.05, 0.2]), robot 2's second at
/// 0.32 + 0.02, ending at 0.44 s. Robot 1 twice first: robot 2 starts at 0.25 s and ends at
/// 0.5 s; robot 2's two runs between robot 1's: robot 1 would wait 0.27 s > 0.2 s. So 0.44 s.
#[test]
fn three_runs_by_hand() {
    let conf: Vec<bool> = (0..30).map(|n| (10..20).contains(&n)).collect();
    let p = Problem::new(conf, vec![1.0; 30], vec![0.5; 30], vec![2.0; 30], 0.01).unwrap();
    let b = switch_charged_bound(&p, &ExactParams::default(), 0.01).unwrap();
    assert!(b.charged);
    assert!((b.margin_free_s - 0.4).abs() < 1e-9, "{b:?}");
    assert!((b.charge_s - 0.02).abs() < 1e-9, "{b:?}");
    assert!((b.lower_bound_s - 0.44).abs() < 1e-9, "{b:?}");
    // Half the tick, half the charge: 0.4 + 2 · 0.01.
    let half = switch_charged_bound(&p, &ExactParams::default(), 0.005).unwrap();
    assert!((half.lower_bound_s - 0.42).abs() < 1e-9, "{half:?}");
    // The scheduler's schedule (valid) is not below it.
    let out = sample_schedule(&p, &SamplerParams::default(), None).unwrap();
    holds_for(&p, &out.schedule, 0.01).unwrap();
    // Bad input: a clear error, no panic.
    for bad in [0.0, -0.01, f64::NAN, f64::INFINITY] {
        assert!(switch_charged_bound(&p, &ExactParams::default(), bad).is_err());
    }
}

/// One LC run between a long head and tail: the drag lead by hand. Head and tail 40 HC
/// samples with `ψ̇min, ψ̇̄, ψ̇max = 0.9, 0.95, 1.0` (a robot there can hardly slow down), the
/// run 10 LC samples with `0.5, 1, 4` (its slow rate `S = 1/4`: the operator may drag it to a
/// quarter of its pace), 10 ms samples and tick. Margin-free: head 0.36 s, run 0.1 s, robot
/// 2's run right after robot 1's, `T*₀ = 0.46 + 0.1 + 0.36 = 0.92 s`; the step `M = 0.02 s`
/// gives 0.94 s. Drag: while `p` drags its whole run (slow time `10·0.04 = 0.4 s`) `c` crosses
/// at least 0.4 s of slow time, i.e. its whole head, planned at least `0.36 s`, plus `M`
/// before its run: room `0.36 + 0.02 − 0.1 − h = 0.27 s` (entry at the run's start, the
/// largest). Robot 2 starting inside the run: its head's 0.36 s less what is left of the run
/// when it starts, least on the first cell, `0.36 − 0.1 − h = 0.25 s`. The pair's room is
/// 0.25 s: robot 2's run starts at `0.46 + 0.25`, `T = 0.71 + 0.1 + 0.36 = 1.17 s` (waiting
/// for the exception instead costs `0.46 + 0.82 = 1.28 s`). The check agrees that it is
/// below every valid schedule: robot 2 starting `δ` before robot 1's exit crosses `4δ` of slow
/// time, `3.6δ` of planned head, and needs `3.6δ + M < 0.36`, so its room `0.36 − δ` is at
/// least 0.266 s; the scheduler's schedule is not below the bound.
#[test]
fn one_run_drag_by_hand() {
    let n = 90;
    let lc = |i: usize| (40..50).contains(&i);
    let conf: Vec<bool> = (0..n).map(|i| !lc(i)).collect();
    let pick = |i: usize, h: f64, l: f64| if lc(i) { l } else { h };
    let p = Problem::new(
        conf,
        (0..n).map(|i| pick(i, 0.95, 1.0)).collect(),
        (0..n).map(|i| pick(i, 0.9, 0.5)).collect(),
        (0..n).map(|i| pick(i, 1.0, 4.0)).collect(),
        0.01,
    )
    .unwrap();
    let step = switch_charged_bound(&p, &ExactParams::default(), 0.01).unwrap();
    assert!((step.margin_free_s - 0.92).abs() < 1e-6, "{step:?}");
    assert!((step.lower_bound_s - 0.94).abs() < 1e-6, "{step:?}");
    let d = drag_charged_bound(&p, &ExactParams::default(), 0.01).unwrap();
    assert!(d.charged);
    assert!((d.max_charge_s - 0.25).abs() < 1e-6, "{d:?}");
    assert!((d.lower_bound_s - 1.17).abs() < 1e-6, "{d:?}");
    let out = sample_schedule(&p, &SamplerParams::default(), None).unwrap();
    holds_for(&p, &out.schedule, 0.01).unwrap();
    assert!(out.schedule.t_total_s(p.dt_s()) >= 1.186 - 1e-6);
    for bad in [0.0, f64::NAN] {
        assert!(drag_charged_bound(&p, &ExactParams::default(), bad).is_err());
    }
}

/// With usable hold points the switches are not charged (the lead bound on legs checks those
/// schedules): the bound is the margin-free one.
#[test]
fn holds_are_not_charged() {
    let conf: Vec<bool> = (0..30).map(|n| (10..20).contains(&n)).collect();
    let p = Problem::new(conf, vec![1.0; 30], vec![0.5; 30], vec![2.0; 30], 0.01)
        .unwrap()
        .with_holds(vec![15])
        .unwrap();
    let b = switch_charged_bound(&p, &ExactParams::default(), 0.01).unwrap();
    assert!(!b.charged && b.charge_s == 0.0 && b.lower_bound_s == b.margin_free_s);
    let d = drag_charged_bound(&p, &ExactParams::default(), 0.01).unwrap();
    assert_eq!(d, b);
}

/// Random small problems: 1–6 runs of 1–9 samples, high confidence with probability 0.65.
fn small_problem() -> impl Strategy<Value = Problem> {
    proptest::collection::vec((1usize..10, prop::bool::weighted(0.65)), 1..7)
        .prop_flat_map(|blocks| {
            let conf: Vec<bool> = blocks
                .iter()
                .flat_map(|&(len, hc)| std::iter::repeat_n(hc, len))
                .collect();
            let n = conf.len();
            (Just(conf), common::gradients(n))
        })
        .prop_map(|(conf, g)| common::problem(conf, &g))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Small random problems (1–6 runs of 1–9 samples): the scheduler's schedule (sampler,
    /// completion, serial fallback; all pass the margin check) and the fastest serial schedule
    /// are never below the bound, and keep the charge at every charged switch.
    #[test]
    fn the_bound_is_below_every_checked_schedule_small(
        p in small_problem(),
        seed in any::<u64>(),
    ) {
        let params = SamplerParams { samples: 2000, seed, ..SamplerParams::default() };
        let out = sample_schedule(&p, &params, None).unwrap();
        holds_for(&p, &out.schedule, p.dt_s())?;
        holds_for(&p, &p.serial_schedule(p.dt_s()).unwrap(), p.dt_s())?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(40))]

    /// Larger random problems (`testkit::random_problem`, 200–1200 samples), at the problem's
    /// sample time and at a tick twice as long.
    #[test]
    fn the_bound_is_below_every_checked_schedule(seed in any::<u64>(), long in any::<bool>()) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let p = testkit::random_problem(&mut rng, 200..=1200, 0.01).unwrap();
        let tick_s = if long { 0.02 } else { 0.01 };
        let params = SamplerParams { samples: 500, seed, tick_s: Some(tick_s), ..SamplerParams::default() };
        let out = sample_schedule(&p, &params, None).unwrap();
        holds_for(&p, &out.schedule, tick_s)?;
    }
}

/// The zoo's painting task (selection seed 3 after 30 rounds, one LC run of 7.78 s): the
/// drag-lead bound lies between the step-only bound and the best valid schedule known
/// (35.258 s, the fastest warps at the least offset the check accepts,
/// `tests/single_switch.rs`).
#[test]
fn zoo_painting_drag_bound() {
    #[derive(serde::Deserialize)]
    struct Data {
        problem: Problem,
        tick_s: f64,
    }
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/zoo_painting_select3_round30.json"
    ))
    .unwrap();
    let Data { problem: p, tick_s } = serde_json::from_str(&text).unwrap();
    let step = switch_charged_bound(&p, &ExactParams::default(), tick_s).unwrap();
    let d = drag_charged_bound(&p, &ExactParams::default(), tick_s).unwrap();
    eprintln!("step {step:?}\ndrag {d:?}");
    assert!(d.lower_bound_s >= step.lower_bound_s);
    assert!(d.lower_bound_s <= 35.258);
}
