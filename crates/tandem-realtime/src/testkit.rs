//! Test kit (feature `testkit`, for tests, benchmarks and `cargo xtask stress`; never for
//! production): random problem families for the safety invariant, tight schedules bisected to
//! the acceptance edge of a margin check, and the search for an operator that makes two robots
//! low-confidence in one tick.
//!
//! The families differ in what makes the margins hard, because a check can only be trusted on
//! the structures it was attacked with (docs/decisions.md, "The N-robot margin check: a lead
//! bound per unit of progress"):
//!
//! - [`Family::Uniform`]: one mask and one set of bounds, many short regions, zero-flexibility
//!   stretches, gradients uniform in the bounds per sample;
//! - [`Family::Styled`]: the same with per-robot gradient styles (fastest, slowest, uniform per
//!   sample or per run);
//! - [`Family::Structured`]: one mask, a few long regions, one bound-factor pair everywhere,
//!   per-run gradient fractions;
//! - [`Family::FlexibleRuns`]: one mask whose high-confidence runs each have their own bound
//!   ratios (so `S_c/S_p` and `F_c/F_p` differ between robots at different places), long regions;
//! - [`Family::PerRobot`]: every robot its own mask, length, bounds and gradients (what
//!   [`Timeline`] allows, e.g. robots doing different tasks);
//! - [`Family::LongThird`]: per-robot plans where one robot has a long low-confidence stretch
//!   while the others have short regions with their own bound ratios;
//! - [`Family::DraggedThird`]: the structure of a dragged third robot made on purpose: robot `t`
//!   low-confidence for a long stretch, then robot `p`'s short region and, a few samples later,
//!   robot `c`'s, with `p` more flexible than `c` (`ψ̇max/ψ̇min` larger), so that dragging `t`
//!   gains `c` more lead per unit of `p`'s progress than rushing it although it gains less per
//!   tick (the per-robot-bounds reproducer of tests/regression.rs is one of these);
//! - [`Family::SharedDrag`]: the same on one mask and one set of bounds: a long first region,
//!   then high-confidence runs of two flexibility classes with single-sample regions between,
//!   robots on different gradient fractions (the shared-mask reproducer is one of these).
//!
//! ```
//! use tandem_realtime::sufficient_margins;
//! use tandem_realtime::testkit::{Case, Family, tight_starts};
//!
//! let mut rng = tandem_realtime::testkit::rng(7);
//! let case = Case::random(Family::LongThird, 3, &mut rng);
//! let (starts, _overlapping) = tight_starts(&case, sufficient_margins, &mut rng).unwrap();
//! assert!(sufficient_margins(&case.robots_at(&starts), case.tick_s)?);
//! # Ok::<(), tandem_realtime::Error>(())
//! ```

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::adversary::{Adversary, adversary_set, run_adversary};
use crate::{Coordinator, Result, Timeline};

/// The seeded generator every random process of the kit takes.
#[must_use]
pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// One robot's plan without its start: per reference sample the confidence (`true` = high),
/// the scheduled gradient `ψ̇_E` and the bounds `ψ̇min`, `ψ̇max` (execution samples per
/// reference sample), and the reference period `dt_s` (s).
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// Confidence per reference sample (Eq. 12).
    pub conf: Vec<bool>,
    /// Scheduled gradient `ψ̇_E[n]`.
    pub exec: Vec<f64>,
    /// `ψ̇min[n]`.
    pub lo: Vec<f64>,
    /// `ψ̇max[n]`.
    pub hi: Vec<f64>,
    /// Reference sample period `Δt_s` (s).
    pub dt_s: f64,
}

impl Plan {
    /// The plan's timeline started at `start_s` (schedule clock, s).
    ///
    /// # Panics
    /// If the plan is not a valid timeline (the generators only make valid ones).
    #[must_use]
    pub fn timeline(&self, start_s: f64) -> Timeline {
        Timeline::new(
            &self.conf, &self.exec, &self.lo, &self.hi, start_s, self.dt_s,
        )
        .expect("generated plans are valid timelines")
    }
}

/// The shared mask of a case ([`Case::shared_mask`]): per reference sample the confidence, a
/// mean gradient, `ψ̇min` and `ψ̇max`, and the period `Δt_s` (s).
#[derive(Clone, Debug, PartialEq)]
pub struct SharedMask {
    /// Confidence per reference sample.
    pub conf: Vec<bool>,
    /// Mean gradient `ψ̇̄[n]` (the plans' gradient on low-confidence samples).
    pub mean: Vec<f64>,
    /// `ψ̇min[n]`.
    pub lo: Vec<f64>,
    /// `ψ̇max[n]`.
    pub hi: Vec<f64>,
    /// Reference sample period (s).
    pub dt_s: f64,
}

/// A problem family (see the [module docs](self)).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// One mask and bounds, many short regions, gradients uniform per sample.
    Uniform,
    /// One mask and bounds, many short regions, per-robot gradient styles.
    Styled,
    /// One mask, a few long regions, one bound-factor pair.
    Structured,
    /// One mask, per-run bound ratios, long regions.
    FlexibleRuns,
    /// Every robot its own mask, length, bounds and gradients.
    PerRobot,
    /// Per-robot plans, one robot with a long low-confidence stretch.
    LongThird,
    /// Per-robot plans built to fool a per-tick worst case: a dragged third robot.
    DraggedThird,
    /// One mask and bounds built to fool a per-tick worst case.
    SharedDrag,
}

impl Family {
    /// Every family, in the order [`Family::of_seed`] cycles through them.
    pub const ALL: [Family; 8] = [
        Family::Uniform,
        Family::Styled,
        Family::Structured,
        Family::FlexibleRuns,
        Family::PerRobot,
        Family::LongThird,
        Family::DraggedThird,
        Family::SharedDrag,
    ];

    /// The family of case `seed` when a test cycles through [`Family::ALL`].
    #[must_use]
    pub fn of_seed(seed: u64) -> Family {
        Family::ALL[(seed % Family::ALL.len() as u64) as usize]
    }

    /// The family's name in reports (kebab case).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Family::Uniform => "uniform",
            Family::Styled => "styled",
            Family::Structured => "structured",
            Family::FlexibleRuns => "flexible-runs",
            Family::PerRobot => "per-robot",
            Family::LongThird => "long-third",
            Family::DraggedThird => "dragged-third",
            Family::SharedDrag => "shared-drag",
        }
    }

    /// Whether every robot of the family shares one mask and one set of bounds (a
    /// `tandem-schedule` problem).
    #[must_use]
    pub fn shared_mask(self) -> bool {
        matches!(
            self,
            Family::Uniform
                | Family::Styled
                | Family::Structured
                | Family::FlexibleRuns
                | Family::SharedDrag
        )
    }
}

/// A random case: one plan per robot and a control tick (s).
#[derive(Clone, Debug)]
pub struct Case {
    /// The family it was drawn from.
    pub family: Family,
    /// One plan per robot (robot `i` at index `i`).
    pub plans: Vec<Plan>,
    /// Control tick (real s): ¼ to 1½ reference samples of the first plan (0.2 to 0.6 in the
    /// built families).
    pub tick_s: f64,
}

/// A reference period drawn from 0.01, 0.1 and 1 s.
fn draw_dt(rng: &mut ChaCha8Rng) -> f64 {
    [0.01, 0.1, 1.0][rng.random_range(0..3)]
}

/// A mask of `regions` LC runs of `lc_len` samples, each after an HC run of `hc_len` samples,
/// and an HC tail of `0..=tail_max` samples.
fn runs_mask(
    rng: &mut ChaCha8Rng,
    regions: usize,
    lc_len: std::ops::RangeInclusive<usize>,
    hc_len: std::ops::RangeInclusive<usize>,
    tail_max: usize,
) -> Vec<bool> {
    let mut conf = Vec::new();
    for _ in 0..regions {
        conf.extend(std::iter::repeat_n(true, rng.random_range(hc_len.clone())));
        conf.extend(std::iter::repeat_n(false, rng.random_range(lc_len.clone())));
    }
    conf.extend(std::iter::repeat_n(true, rng.random_range(0..=tail_max)));
    conf
}

/// Gradients in `[lo, hi]` per sample: the mean `mean` on LC samples (constraint 4) and, on HC
/// samples, a fraction of the bounds held per HC run and redrawn (fastest, slowest or uniform)
/// at a run boundary with probability ½.
fn run_styled_exec(
    rng: &mut ChaCha8Rng,
    conf: &[bool],
    mean: &[f64],
    lo: &[f64],
    hi: &[f64],
) -> Vec<f64> {
    let mut frac: f64 = rng.random();
    (0..conf.len())
        .map(|i| {
            if i > 0 && conf[i] != conf[i - 1] && rng.random_bool(0.5) {
                frac = [0.0, 1.0, rng.random()][rng.random_range(0..3)];
            }
            if conf[i] {
                lo[i] + frac * (hi[i] - lo[i])
            } else {
                mean[i]
            }
        })
        .collect()
}

impl Case {
    /// A random case of `family` with `n_robots` plans (see the [module docs](self)).
    pub fn random(family: Family, n_robots: usize, rng: &mut ChaCha8Rng) -> Case {
        let plans = match family {
            Family::Uniform => styled(rng, n_robots, false),
            Family::Styled => styled(rng, n_robots, true),
            Family::Structured => structured(rng, n_robots),
            Family::FlexibleRuns => flexible_runs(rng, n_robots),
            Family::PerRobot => (0..n_robots).map(|_| own_plan(rng, None)).collect(),
            Family::LongThird => {
                let long = rng.random_range(0..n_robots);
                let dt_s = draw_dt(rng);
                (0..n_robots)
                    .map(|i| own_plan(rng, Some((dt_s, i == long))))
                    .collect()
            }
            Family::DraggedThird => dragged_third(rng, n_robots),
            Family::SharedDrag => shared_drag(rng, n_robots),
        };
        let dt_s = plans[0].dt_s;
        // The built families need short ticks: with long ones the margins of one maximal step
        // swamp the lead a dragged third robot adds.
        let ticks_per_sample = match family {
            Family::DraggedThird | Family::SharedDrag => 0.2..=0.6,
            _ => 0.25..=1.5,
        };
        let tick_s = dt_s * rng.random_range(ticks_per_sample);
        Case {
            family,
            plans,
            tick_s,
        }
    }

    /// Start offsets (schedule clock, s) that interleave the `n` robots: robot 0 at 0, each
    /// later robot at a uniform random point of the span of the robots before it.
    pub fn interleaved_starts(&self, n: usize, r: &mut ChaCha8Rng) -> Vec<f64> {
        let mut starts = vec![0.0];
        for _ in 1..n {
            let end = self
                .robots_at(&starts)
                .iter()
                .map(Timeline::end_s)
                .fold(0.0, f64::max);
            starts.push(end * r.random::<f64>());
        }
        starts
    }

    /// Every robot's timeline, robot `i` starting at `starts_s[i]` (schedule clock, s).
    #[must_use]
    pub fn robots_at(&self, starts_s: &[f64]) -> Vec<Timeline> {
        starts_s
            .iter()
            .zip(&self.plans)
            .map(|(&s, plan)| plan.timeline(s))
            .collect()
    }

    /// For a case whose plans share one mask, one set of bounds and one period (the shared-mask
    /// families): the mask, a mean gradient (the plans' gradient on low-confidence samples, where
    /// every plan runs the mean, and the middle of the bounds elsewhere), `ψ̇min`, `ψ̇max` and
    /// `Δt_s` — the inputs of a `tandem-schedule` problem. `None` otherwise.
    #[must_use]
    pub fn shared_mask(&self) -> Option<SharedMask> {
        let first = &self.plans[0];
        let same = self.plans.iter().all(|p| {
            p.conf == first.conf && p.lo == first.lo && p.hi == first.hi && p.dt_s == first.dt_s
        });
        same.then(|| SharedMask {
            conf: first.conf.clone(),
            mean: (0..first.conf.len())
                .map(|i| {
                    if first.conf[i] {
                        0.5 * (first.lo[i] + first.hi[i])
                    } else {
                        first.exec[i]
                    }
                })
                .collect(),
            lo: first.lo.clone(),
            hi: first.hi.clone(),
            dt_s: first.dt_s,
        })
    }

    /// `[min ψ̇min, max ψ̇max]` over every plan: the range random adversaries draw from.
    #[must_use]
    pub fn grad_range(&self) -> [f64; 2] {
        let lo = self
            .plans
            .iter()
            .flat_map(|p| p.lo.iter().copied())
            .fold(f64::INFINITY, f64::min);
        let hi = self
            .plans
            .iter()
            .flat_map(|p| p.hi.iter().copied())
            .fold(0.0, f64::max);
        [lo, hi]
    }

    /// The full adversary set of [`adversary_set`] for these
    /// robots (random parameters from `rng`).
    pub fn adversaries(&self, robots: &[Timeline], rng: &mut ChaCha8Rng) -> Vec<Adversary> {
        let ticks = (last_end_s(robots) / self.tick_s).ceil() as u64;
        adversary_set(robots.len(), self.grad_range(), ticks, rng)
    }
}

/// [`Family::Styled`] (and, without `styles`, [`Family::Uniform`]): `T_ref` in 20..=300, 1–8
/// LC regions, per-sample bounds with zero-flexibility stretches, each robot's HC gradients in a
/// style of its own (or uniform per sample).
fn styled(rng: &mut ChaCha8Rng, n_robots: usize, styles: bool) -> Vec<Plan> {
    let n = rng.random_range(20..=300usize);
    let dt_s = draw_dt(rng);
    let mut conf = vec![true; n];
    let k = rng.random_range(1..=8usize);
    let max_len = (n / (2 * k)).max(1);
    for _ in 0..k {
        let len = rng.random_range(1..=max_len);
        let start = rng.random_range(0..n);
        for c in conf.iter_mut().skip(start).take(len) {
            *c = false;
        }
    }
    let (mut mean, mut lo, mut hi) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..n {
        let m: f64 = rng.random_range(0.5..2.0);
        mean.push(m);
        lo.push(m * rng.random_range(0.25..=1.0));
        hi.push(m * rng.random_range(1.0..=3.0));
    }
    for _ in 0..rng.random_range(0..=3usize) {
        let len = rng.random_range(1..=(n / 4).max(1));
        let start = rng.random_range(0..n);
        let end = (start + len).min(n);
        lo[start..end].copy_from_slice(&mean[start..end]);
        hi[start..end].copy_from_slice(&mean[start..end]);
    }
    (0..n_robots)
        .map(|_| {
            let style = if styles { rng.random_range(0..4u8) } else { 0 };
            let mut run_frac: f64 = if styles { rng.random() } else { 0.0 };
            let exec = (0..n)
                .map(|i| {
                    if i > 0 && conf[i] != conf[i - 1] && styles {
                        run_frac = rng.random();
                    }
                    if !(conf[i] && lo[i] < hi[i]) {
                        mean[i]
                    } else {
                        match style {
                            1 => lo[i],
                            2 => hi[i],
                            3 => lo[i] + run_frac * (hi[i] - lo[i]),
                            _ => rng.random_range(lo[i]..=hi[i]),
                        }
                    }
                })
                .collect();
            Plan {
                conf: conf.clone(),
                exec,
                lo: lo.clone(),
                hi: hi.clone(),
                dt_s,
            }
        })
        .collect()
}

/// [`Family::Structured`]: 1–4 LC regions of 1–30 samples between HC runs of 3–60, one
/// bound-factor pair `[¼…1, 1…3]` of a mean in `[0.8, 1.25]`, per-run gradient fractions.
fn structured(rng: &mut ChaCha8Rng, n_robots: usize) -> Vec<Plan> {
    let dt_s = draw_dt(rng);
    let regions = rng.random_range(1..=4);
    let conf = runs_mask(rng, regions, 1..=30, 3..=60, 30);
    let n = conf.len();
    let (lo_f, hi_f) = (rng.random_range(0.25..=1.0), rng.random_range(1.0..=3.0));
    let mean: Vec<f64> = (0..n).map(|_| rng.random_range(0.8..1.25)).collect();
    let lo: Vec<f64> = mean.iter().map(|m| m * lo_f).collect();
    let hi: Vec<f64> = mean.iter().map(|m| m * hi_f).collect();
    (0..n_robots)
        .map(|_| Plan {
            exec: run_styled_exec(rng, &conf, &mean, &lo, &hi),
            conf: conf.clone(),
            lo: lo.clone(),
            hi: hi.clone(),
            dt_s,
        })
        .collect()
}

/// Per-run bound factors `[lo, hi]` of a mask: one pair drawn per run of equal confidence.
fn per_run_factors(rng: &mut ChaCha8Rng, conf: &[bool]) -> Vec<(f64, f64)> {
    let mut pair = (rng.random_range(0.2..=1.0), rng.random_range(1.0..=3.0));
    (0..conf.len())
        .map(|i| {
            if i > 0 && conf[i] != conf[i - 1] {
                pair = (rng.random_range(0.2..=1.0), rng.random_range(1.0..=3.0));
            }
            pair
        })
        .collect()
}

/// [`Family::FlexibleRuns`]: one mask of 1–4 long LC regions (5–80 samples) between HC runs of
/// 5–100, bound factors drawn per run, gradients per robot and run (fastest, slowest, nominal or
/// uniform).
fn flexible_runs(rng: &mut ChaCha8Rng, n_robots: usize) -> Vec<Plan> {
    let dt_s = draw_dt(rng);
    let regions = rng.random_range(1..=4);
    let conf = runs_mask(rng, regions, 5..=80, 5..=100, 100);
    let factors = per_run_factors(rng, &conf);
    let mean: Vec<f64> = (0..conf.len())
        .map(|_| rng.random_range(0.8..1.25))
        .collect();
    let lo: Vec<f64> = mean.iter().zip(&factors).map(|(m, f)| m * f.0).collect();
    let hi: Vec<f64> = mean.iter().zip(&factors).map(|(m, f)| m * f.1).collect();
    (0..n_robots)
        .map(|_| Plan {
            exec: run_styled_exec(rng, &conf, &mean, &lo, &hi),
            conf: conf.clone(),
            lo: lo.clone(),
            hi: hi.clone(),
            dt_s,
        })
        .collect()
}

/// One robot's own plan ([`Family::PerRobot`]): length 20–200 samples, 1–4 LC regions of
/// 1–20 samples, its own bound factors (per run with probability ½), its own gradient styles.
/// With `Some((dt_s, long))` the period is given and, if `long`, the robot gets one long LC
/// stretch of 30–100 samples ([`Family::LongThird`]).
fn own_plan(rng: &mut ChaCha8Rng, long: Option<(f64, bool)>) -> Plan {
    let dt_s = long.map_or_else(|| draw_dt(rng), |(dt, _)| dt);
    let conf = if long.is_some_and(|(_, l)| l) {
        let mut c = runs_mask(rng, 1, 30..=100, 0..=20, 20);
        let more = rng.random_range(0..=2);
        c.extend(runs_mask(rng, more, 1..=10, 5..=40, 40));
        c
    } else {
        let regions = rng.random_range(1..=4);
        runs_mask(rng, regions, 1..=20, 3..=60, 60)
    };
    let factors = if rng.random_bool(0.5) {
        per_run_factors(rng, &conf)
    } else {
        let f = (rng.random_range(0.2..=1.0), rng.random_range(1.0..=3.0));
        vec![f; conf.len()]
    };
    let mean: Vec<f64> = (0..conf.len())
        .map(|_| rng.random_range(0.6..1.6))
        .collect();
    let lo: Vec<f64> = mean.iter().zip(&factors).map(|(m, f)| m * f.0).collect();
    let hi: Vec<f64> = mean.iter().zip(&factors).map(|(m, f)| m * f.1).collect();
    Plan {
        exec: run_styled_exec(rng, &conf, &mean, &lo, &hi),
        conf,
        lo,
        hi,
        dt_s,
    }
}

/// `len` samples of confidence `hc` with bounds `[lo_f, hi_f]·mean` and gradient `mean·frac`
/// between them (`mean` itself on LC samples), appended to `plan`.
fn push_run(plan: &mut Plan, len: usize, hc: bool, (lo_f, hi_f): (f64, f64), frac: f64) {
    for _ in 0..len {
        plan.conf.push(hc);
        plan.lo.push(lo_f);
        plan.hi.push(hi_f);
        plan.exec
            .push(if hc { lo_f + frac * (hi_f - lo_f) } else { 1.0 });
    }
}

/// An empty plan of period `dt_s`.
fn empty_plan(dt_s: f64) -> Plan {
    Plan {
        conf: Vec::new(),
        exec: Vec::new(),
        lo: Vec::new(),
        hi: Vec::new(),
        dt_s,
    }
}

/// A flexible bound pair `(ψ̇min, ψ̇max)` and a stiff one that can go a little faster but slow
/// down much less: on the mean gradient the stiff robot's `F` is up to 18 % larger and its `S`
/// 10–65 % larger, so a common pace set by a third robot moves it ahead of the flexible robot
/// by more per tick when rushed but by more per unit of progress when dragged.
fn flexible_and_stiff(rng: &mut ChaCha8Rng) -> ((f64, f64), (f64, f64)) {
    let flexible = (rng.random_range(0.2..0.3), rng.random_range(1.8..2.6));
    let stiff = (
        flexible.0 * rng.random_range(0.85..0.99),
        flexible.1 * rng.random_range(0.6..0.9),
    );
    (flexible, stiff)
}

/// [`Family::DraggedThird`]: robots `t`, `p`, `c` (robots 0, 1, 2, or random distinct indices;
/// the others get
/// [`Family::PerRobot`] plans); `t` low-confidence for 30–120 samples from (nearly) the start;
/// `p` high-confidence with the flexible bounds up to a 1–4-sample region placed 0–10 samples
/// after `t`'s stretch; `c` with the stiff bounds up to its 1–4-sample region 1–20 samples
/// later; gradients at the mean or a held fraction of the bounds.
fn dragged_third(rng: &mut ChaCha8Rng, n_robots: usize) -> Vec<Plan> {
    let dt_s = draw_dt(rng);
    let mut plans: Vec<Plan> = (0..n_robots)
        .map(|_| own_plan(rng, Some((dt_s, false))))
        .collect();
    if n_robots < 3 {
        return plans;
    }
    // Half the cases in placement order (t, p, c = robots 0, 1, 2: `tight_starts` then keeps t
    // and p at 0 and moves c to the acceptance edge), half at random indices.
    let mut roles: Vec<usize> = (0..n_robots).collect();
    if rng.random_bool(0.5) {
        for i in 0..3 {
            let j = rng.random_range(i..n_robots);
            roles.swap(i, j);
        }
    }
    let (t, p, c) = (roles[0], roles[1], roles[2]);
    let (flexible, stiff) = flexible_and_stiff(rng);
    let long = rng.random_range(30..=120usize);
    let head = rng.random_range(0..=5usize);
    let frac = |rng: &mut ChaCha8Rng| [0.5, rng.random(), 0.0, 1.0][rng.random_range(0..4)];
    let mut third = empty_plan(dt_s);
    push_run(&mut third, head, true, flexible, 0.5);
    push_run(&mut third, long, false, flexible, 0.5);
    push_run(
        &mut third,
        rng.random_range(10..=60),
        true,
        flexible,
        frac(rng),
    );
    let p_at = head + long + rng.random_range(0..=10usize);
    let c_at = p_at + rng.random_range(1..=20usize);
    let mut prev = empty_plan(dt_s);
    push_run(&mut prev, p_at, true, flexible, frac(rng));
    push_run(&mut prev, rng.random_range(1..=4), false, flexible, 0.5);
    push_run(
        &mut prev,
        rng.random_range(10..=60),
        true,
        flexible,
        frac(rng),
    );
    let mut cur = empty_plan(dt_s);
    push_run(&mut cur, c_at, true, stiff, frac(rng));
    push_run(&mut cur, rng.random_range(1..=4), false, stiff, 0.5);
    push_run(&mut cur, rng.random_range(10..=60), true, stiff, frac(rng));
    (plans[t], plans[p], plans[c]) = (third, prev, cur);
    plans
}

/// [`Family::SharedDrag`]: one mask — a first region of 30–90 samples, an HC run of 40–120
/// samples with the stiff bounds, a single-sample region, an HC run of 30–100 with the flexible
/// bounds, a single-sample region, a tail — and one set of bounds (the first region and the
/// later runs flexible); robot `i`'s gradients on the stiff run a fraction of the bounds drawn
/// per robot.
fn shared_drag(rng: &mut ChaCha8Rng, n_robots: usize) -> Vec<Plan> {
    let dt_s = draw_dt(rng);
    let (flexible, stiff) = flexible_and_stiff(rng);
    let (first, stiff_len, flex_len, tail) = (
        rng.random_range(30..=90),
        rng.random_range(40..=120),
        rng.random_range(30..=100),
        rng.random_range(1..=40),
    );
    (0..n_robots)
        .map(|_| {
            let f: f64 = rng.random();
            let mut plan = empty_plan(dt_s);
            push_run(&mut plan, first, false, flexible, 0.5);
            push_run(&mut plan, stiff_len, true, stiff, f);
            push_run(&mut plan, 1, false, flexible, 0.5);
            push_run(&mut plan, flex_len, true, flexible, 0.5);
            push_run(&mut plan, 1, false, flexible, 0.5);
            push_run(&mut plan, tail, true, flexible, 0.5);
            plan
        })
        .collect()
}

/// Latest end (s) of any robot.
fn last_end_s(robots: &[Timeline]) -> f64 {
    robots.iter().map(Timeline::end_s).fold(0.0, f64::max)
}

/// A margin check of this crate (the conservative one or a baseline).
pub type Check = fn(&[Timeline], f64) -> Result<bool>;

/// `starts_s` followed by serial starts for the remaining robots of `case` (each where the
/// robots before it have all ended).
fn with_serial_tail(case: &Case, starts_s: &[f64]) -> Vec<f64> {
    let mut all = starts_s.to_vec();
    while all.len() < case.plans.len() {
        let latest_end = last_end_s(&case.robots_at(&all));
        all.push(latest_end);
    }
    all
}

/// Offsets tried per robot by [`tight_starts`] besides 0 and the serial start.
const GRID: usize = 24;
/// Bisection steps towards an acceptance edge per robot.
const BISECTIONS: usize = 12;

/// A tight schedule of the case's robots accepted by `check` (a [`Check`], or any closure, e.g.
/// one with a switch time), at an edge of its acceptance:
/// robot 0 at 0; for robot `i`, offsets `0`, `E_i·(k + u_k)/24` (`k = 0..24`, `u_k` uniform) and
/// `E_i` (the latest end of the robots before it: a serial start) are checked with robots
/// `0..=i` and the robots after `i` started serially behind them (so every decision is the
/// `N`-robot check's); among the neighbouring offsets of which one is accepted and the other not
/// — the lower *and* upper edges of every window of accepted offsets — one is drawn and bisected
/// 12 times towards the rejected one, keeping the accepted end. Returns the starts (s) and
/// whether some robot starts before its `E_i` (executions overlap), or `None` if no offset is
/// accepted, not even the serial one.
///
/// # Panics
/// If `check` returns an error (the case's tick is valid).
pub fn tight_starts(
    case: &Case,
    check: impl Fn(&[Timeline], f64) -> Result<bool>,
    r: &mut ChaCha8Rng,
) -> Option<(Vec<f64>, bool)> {
    let n = case.plans.len();
    let mut starts = vec![0.0];
    let mut overlapping = false;
    for _ in 1..n {
        let latest_end = last_end_s(&case.robots_at(&starts));
        let accepts = |t: f64, starts: &mut Vec<f64>| {
            starts.push(t);
            let all = with_serial_tail(case, starts);
            let ok = check(&case.robots_at(&all), case.tick_s).expect("valid tick");
            starts.pop();
            ok
        };
        let mut taus = vec![0.0];
        taus.extend((0..GRID).map(|k| latest_end * (k as f64 + r.random::<f64>()) / GRID as f64));
        taus.push(latest_end);
        let ok: Vec<bool> = taus.iter().map(|&t| accepts(t, &mut starts)).collect();
        let edges: Vec<usize> = (1..taus.len()).filter(|&k| ok[k] != ok[k - 1]).collect();
        let tau = if edges.is_empty() {
            *taus.iter().zip(&ok).find(|(_, a)| **a)?.0
        } else {
            let k = edges[r.random_range(0..edges.len())];
            let (mut good, mut bad) = if ok[k] {
                (taus[k], taus[k - 1])
            } else {
                (taus[k - 1], taus[k])
            };
            for _ in 0..BISECTIONS {
                let m = 0.5 * (good + bad);
                if accepts(m, &mut starts) {
                    good = m;
                } else {
                    bad = m;
                }
            }
            good
        };
        overlapping |= tau < latest_end;
        starts.push(tau);
    }
    Some((starts, overlapping))
}

/// Runs every adversary to the end; the first `(adversary, tick)` at which two robots were
/// low-confidence, or `None`.
///
/// # Panics
/// If an execution does not finish within a generous budget (40 times the ticks of the
/// schedule at its nominal pace).
pub fn find_overlap(
    robots: &[Timeline],
    tick_s: f64,
    adversaries: &[Adversary],
    rng: &mut ChaCha8Rng,
) -> Option<(Adversary, u64)> {
    find_overlap_with_holds(robots, &[], tick_s, adversaries, rng)
}

/// [`find_overlap`] for plans with holds (`crate::holds`; `holds` empty: no holds), run by
/// [`Coordinator::with_holds_unchecked`]; the budget counts the planned dwells too.
///
/// # Panics
/// As [`find_overlap`], and for holds the coordinator rejects.
pub fn find_overlap_with_holds(
    robots: &[Timeline],
    holds: &[Vec<crate::Hold>],
    tick_s: f64,
    adversaries: &[Adversary],
    rng: &mut ChaCha8Rng,
) -> Option<(Adversary, u64)> {
    let budget = adversary_budget(robots, holds, tick_s);
    for &a in adversaries {
        let c = Coordinator::with_holds_unchecked(robots.to_vec(), holds, tick_s)
            .expect("valid tick and holds");
        let run = run_adversary(c, a, rng, budget).expect("admissible adversaries");
        assert!(run.finished, "coordinator did not finish under {a:?}");
        if let Some(k) = run.first_overlap {
            return Some((a, k));
        }
    }
    None
}

/// The tick budget of a run of an adversary on `robots` with `holds` at `tick_s` (s): 40
/// times the ticks from the first start to the latest end plus the planned dwells, plus 100
/// (a generous cap: every admissible operator finishes well within it).
#[must_use]
pub fn adversary_budget(robots: &[Timeline], holds: &[Vec<crate::Hold>], tick_s: f64) -> u64 {
    let first_start = robots
        .iter()
        .map(Timeline::start_s)
        .fold(f64::INFINITY, f64::min);
    let dwell: f64 = holds.iter().flatten().map(|h| h.dwell_s).sum();
    let total = last_end_s(robots) + dwell - first_start;
    (total / tick_s * 40.0).ceil() as u64 + 100
}

/// A random round with hold points, as the property tests with holds draw it: a [`Case`] of
/// the given family, its robots at [`Case::interleaved_starts`], and with holds a random
/// quarter of each robot's usable holds ([`random_usable`]), their release rules
/// ([`crate::holds::release_rules`]) and random planned dwells ([`with_random_dwells`]).
#[derive(Clone, Debug)]
pub struct HeldRound {
    /// The case the robots' plans come from.
    pub case: Case,
    /// Every robot's timeline at its start.
    pub robots: Vec<Timeline>,
    /// Each robot's holds with their release rules and dwells (empty without holds).
    pub holds: Vec<Vec<crate::Hold>>,
}

impl HeldRound {
    /// Draws a round of `n` robots of `family` from `r` (see the type docs); with
    /// `holds = false` no holds are drawn (nor anything after the starts).
    #[must_use]
    pub fn random(family: Family, n: usize, holds: bool, r: &mut ChaCha8Rng) -> HeldRound {
        let case = Case::random(family, n, r);
        let starts = case.interleaved_starts(n, r);
        let robots = case.robots_at(&starts);
        let holds = if holds {
            let usable = random_usable(&robots, r);
            let rules = crate::holds::release_rules(&robots, &[], &usable);
            with_random_dwells(&robots, rules, case.tick_s, r)
        } else {
            Vec::new()
        };
        HeldRound {
            case,
            robots,
            holds,
        }
    }

    /// Whether some robot has a hold with a release rule.
    #[must_use]
    pub fn has_holds(&self) -> bool {
        self.holds.iter().any(|h| !h.is_empty())
    }

    /// The round's coordinator without the margin check
    /// ([`Coordinator::with_holds_unchecked`]).
    ///
    /// # Panics
    /// Never for a drawn round (its holds are ones the coordinator accepts).
    #[must_use]
    pub fn coordinator(&self) -> Coordinator {
        Coordinator::with_holds_unchecked(self.robots.clone(), &self.holds, self.case.tick_s)
            .expect("drawn holds are accepted")
    }

    /// [`adversary_budget`] of the round.
    #[must_use]
    pub fn budget(&self) -> u64 {
        adversary_budget(&self.robots, &self.holds, self.case.tick_s)
    }
}

/// A random runnable order of a continuous cell of `n` robots over the task's `groups`
/// ([`crate::cell::groups`]): each robot's groups in task order from a random first group,
/// interleaved at random as whole groups, flattened to `(robot, stretch)` entries.
///
/// # Panics
/// If `groups` is empty while `n > 0` (a task with low confidence has a group).
pub fn random_order(
    groups: &[crate::cell::Group],
    n: usize,
    rng: &mut ChaCha8Rng,
) -> Vec<(usize, usize)> {
    let g = groups.len();
    let first: Vec<usize> = (0..n).map(|_| rng.random_range(0..g)).collect();
    let mut taken = vec![0; n];
    let mut out = Vec::new();
    while taken.iter().any(|&k| k < g) {
        let r = loop {
            let r = rng.random_range(0..n);
            if taken[r] < g {
                break r;
            }
        };
        let gr = groups[(first[r] + taken[r]) % g];
        out.extend((gr.first_lc..gr.end_lc).map(|lc| (r, lc)));
        taken[r] += 1;
    }
    out
}

/// A random runnable order of a continuous cell of different tasks
/// ([`crate::cell::ContinuousCoordinator::mixed`]): robot `k` has the groups `groups[k]` of
/// its own task and `ratios[k]` tasks per pass; each robot's `r_k·G_k` groups in task order
/// from a random first one, interleaved at random as whole groups, flattened to
/// `(robot, lc)` entries with `lc` counting over the robot's `r_k` tasks. Robots without
/// groups have no entries.
#[must_use]
pub fn random_mixed_order(
    groups: &[&[crate::cell::Group]],
    ratios: &[usize],
    rng: &mut ChaCha8Rng,
) -> Vec<(usize, usize)> {
    let n = groups.len();
    // Per robot its blocks (copy, group) in task order, from a random first one.
    let blocks: Vec<usize> = (0..n).map(|k| groups[k].len() * ratios[k]).collect();
    let first: Vec<usize> = blocks
        .iter()
        .map(|&b| if b == 0 { 0 } else { rng.random_range(0..b) })
        .collect();
    let mut taken = vec![0; n];
    let mut out = Vec::new();
    while (0..n).any(|k| taken[k] < blocks[k]) {
        let r = loop {
            let r = rng.random_range(0..n);
            if taken[r] < blocks[r] {
                break r;
            }
        };
        let b = (first[r] + taken[r]) % blocks[r];
        let (copy, g) = (b / groups[r].len(), b % groups[r].len());
        let m = groups[r].last().map_or(0, |g| g.end_lc);
        let gr = groups[r][g];
        out.extend((gr.first_lc..gr.end_lc).map(|lc| (r, copy * m + lc)));
        taken[r] += 1;
    }
    out
}

/// How [`random_cell_task`] draws its hold points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CellHolds {
    /// Each sample after the first a candidate with one probability `p ~ U[0, 1)` per task.
    Uniform,
    /// As [`CellHolds::Uniform`], but with probability ⅓ no hold at all (`p = 0`).
    NoneOneThird,
}

/// A random task for a continuous cell: `6..=max_len` samples in runs of alternating
/// confidence (high 1–8 samples, low 1–5, at least one low sample), `ψ̇̄` per sample in
/// `[0.5, 2]`, bound factors in `[0.3, 1]` and `[1, 3]`, high confidence planned at its fastest
/// (`ψ̇min`) and low confidence at `ψ̇̄`, `Δt_s` 0.05 s; and its usable holds
/// ([`crate::holds::usable_holds`]) on a random subset of the samples, drawn as `holds` says.
///
/// # Panics
/// Never for `max_len ≥ 6` (the timeline it builds is valid by construction).
pub fn random_cell_task(
    rng: &mut ChaCha8Rng,
    max_len: usize,
    holds: CellHolds,
) -> (Timeline, Vec<usize>) {
    let mut conf = Vec::new();
    let mut hc = rng.random_bool(0.5);
    let len = rng.random_range(6..=max_len);
    while conf.len() < len {
        let run = if hc {
            rng.random_range(1..=8)
        } else {
            rng.random_range(1..=5)
        };
        conf.extend(std::iter::repeat_n(hc, run));
        hc = !hc;
    }
    if conf.iter().all(|&c| c) {
        conf[0] = false;
    }
    let n = conf.len();
    let mean: Vec<f64> = (0..n).map(|_| rng.random_range(0.5..2.0)).collect();
    let lo: Vec<f64> = mean
        .iter()
        .map(|m| m * rng.random_range(0.3..1.0))
        .collect();
    let hi: Vec<f64> = mean
        .iter()
        .map(|m| m * rng.random_range(1.0..3.0))
        .collect();
    let p = match holds {
        CellHolds::NoneOneThird if rng.random_bool(1.0 / 3.0) => 0.0,
        _ => rng.random_range(0.0..1.0),
    };
    let candidates: Vec<usize> = (1..n).filter(|_| rng.random_bool(p)).collect();
    let holds = crate::holds::usable_holds(&conf, &candidates);
    let exec: Vec<f64> = (0..n)
        .map(|k| if conf[k] { lo[k] } else { mean[k] })
        .collect();
    (
        Timeline::new(&conf, &exec, &lo, &hi, 0.0, 0.05).expect("a valid random timeline"),
        holds,
    )
}

/// A random quarter of each robot's usable hold points (`holds::usable_holds` over every
/// reference sample but the first), each kept with probability 0.25 in sample order: the
/// hold points of the property tests with holds.
pub fn random_usable(robots: &[Timeline], r: &mut impl Rng) -> Vec<Vec<usize>> {
    robots
        .iter()
        .map(|tl| {
            let all: Vec<usize> = (1..tl.n_ref()).collect();
            crate::holds::usable_holds(tl.conf(), &all)
                .into_iter()
                .filter(|_| r.random_bool(0.25))
                .collect()
        })
        .collect()
}

/// `rules` (release rules per robot) with planned dwells on some holds: each hold after the
/// first sample gets, with probability 1/2, a dwell of up to 0.2 × the latest robot's end (s);
/// the dwelt plan when a coordinator at `tick_s` accepts it (its legs still start in order),
/// else `rules` unchanged. The draws are made in robot, then hold order.
pub fn with_random_dwells(
    robots: &[Timeline],
    rules: Vec<Vec<crate::Hold>>,
    tick_s: f64,
    r: &mut impl Rng,
) -> Vec<Vec<crate::Hold>> {
    let span = robots.iter().map(Timeline::end_s).fold(0.0, f64::max);
    let dwelt: Vec<Vec<crate::Hold>> = rules
        .iter()
        .map(|l| {
            l.iter()
                .map(|h| crate::Hold {
                    dwell_s: if h.ref_idx > 0 && r.random_bool(0.5) {
                        r.random_range(0.0..0.2) * span
                    } else {
                        0.0
                    },
                    ..h.clone()
                })
                .collect()
        })
        .collect();
    if Coordinator::with_holds_unchecked(robots.to_vec(), &dwelt, tick_s).is_ok() {
        dwelt
    } else {
        rules
    }
}
