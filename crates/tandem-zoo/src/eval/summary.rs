//! Per family, the mean over seeds ([`FamilyRow`], [`FitRow`]), and the acceptance limits
//! ([`Thresholds`], [`check`]).

use serde::{Deserialize, Serialize};
use tandem_sim::study::Cell;

use super::ZooReport;
use super::prepare::min_max;
use super::run::{FateIncreases, RunReport};

/// One family, robot count and cell, over its seeds (means unless said otherwise).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FamilyRow {
    /// The family.
    pub family: String,
    /// Robots `N`.
    pub robots: usize,
    /// Rounds or continuous.
    pub cell: Cell,
    /// Seeds averaged.
    pub seeds: usize,
    /// Final `T_total` (continuous: period), s.
    pub t_total_s: f64,
    /// Its margin-free bound, s.
    pub bound_s: f64,
    /// Mean of `T_total / bound − 1` over seeds, percent.
    pub gap_pct: f64,
    /// Largest `T_total / bound − 1` of a seed, percent.
    pub gap_max_pct: f64,
    /// Where the gap goes (rounds): the mean over seeds of the margin-free search's open
    /// share and of the margins' share (`RunReport::gap_split_pct`, percent of the bound;
    /// their sum is [`FamilyRow::gap_pct`]); `None` when no seed measured it (a cell, an old
    /// report).
    #[serde(default)]
    pub gap_split_pct: Option<(f64, f64)>,
    /// Of the margins' share, what no valid schedule avoids: the mean over the seeds that
    /// measured it of `RunReport::unavoidable_pct` (percent of the bound), with their number;
    /// `None` when none did (a cell, three or more robots, an old report).
    #[serde(default)]
    pub unavoidable_pct: Option<(f64, usize)>,
    /// Seeds whose bound is the proven margin-free optimum (rounds).
    #[serde(default)]
    pub bound_proven: usize,
    /// Mean of `T_total / serial`.
    pub over_serial: f64,
    /// Final high confidence, percent.
    pub high_pct: f64,
    /// Truth, percent.
    pub truth_pct: f64,
    /// Mean of `high − truth`, percentage points.
    pub high_minus_truth_pp: f64,
    /// Largest `|high − truth|` of a seed, percentage points.
    pub high_minus_truth_max_pp: f64,
    /// Samples falsely trusted where the demonstrations vary (mean).
    pub falsely_trusted: f64,
    /// Samples falsely trusted where every demonstration agrees (mean).
    pub falsely_trusted_agreeing: f64,
    /// Mean rounds until the robots first overlap, over the seeds where they did.
    pub first_overlap_round: Option<f64>,
    /// Seeds in which the robots never overlapped (rounds only).
    pub never_overlapped: usize,
    /// Largest round-to-round increase of `T_total` over every seed, s.
    pub max_increase_s: f64,
    /// The same in control ticks.
    pub max_increase_ticks: f64,
    /// Round-to-round changes of `T_total` by the previous schedule's fate, over every seed
    /// (`RunReport::by_fate` merged: counts added, the largest increase); all empty for a cell
    /// and an old report.
    #[serde(default)]
    pub by_fate: FateIncreases,
    /// Realized over planned time (mean over rounds and seeds).
    pub realized_over_planned: f64,
    /// Planned throughput of the last round (tasks/h per operator).
    pub planned_per_h: f64,
    /// Realized throughput of the last round (continuous: steady), tasks/h per operator.
    pub realized_per_h: f64,
    /// Realized minus planned time as a percent of planned (mean over seeds of
    /// `100·(realized − planned) / planned` of every round summed; continuous: the steady
    /// window's tasks against the plan's period): the sum of the cause columns below.
    #[serde(default)]
    pub over_plan_pct: f64,
    /// The causes' shares of planned time, percent, in the order of
    /// `PlanGap::parts` (corrections, holds (continuous: gates), strategy, grid, faults,
    /// critical path); they add up to [`FamilyRow::over_plan_pct`].
    #[serde(default)]
    pub cause_pct: [f64; 6],
    /// Samples run at high confidence where the truth needed the operator (mean over seeds;
    /// rounds: summed over every round; continuous: the steady window).
    #[serde(default)]
    pub needed_unsupervised: f64,
    /// Backward steps of reference time, summed over seeds (must be 0).
    pub backward_steps: usize,
    /// Largest backward step (reference samples).
    pub max_backward_samples: f64,
    /// Overlapping ticks, summed over seeds (must be 0).
    pub overlap_ticks: u64,
    /// Monitor faults, summed over seeds (must be 0).
    pub faults: u64,
}

/// One family's fits over its seeds (means).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FitRow {
    /// The family.
    pub family: String,
    /// Seeds averaged.
    pub seeds: usize,
    /// Truth, percent.
    pub truth_pct: f64,
    /// High confidence after the fit, percent.
    pub fit_high_pct: f64,
    /// Low-confidence runs after the fit.
    pub fit_lc_runs: f64,
    /// Mean reference-choice spread (largest − smallest high confidence over the choices of
    /// first file), pp; `None` when not measured.
    pub spread_pp: Option<f64>,
    /// Largest spread of a seed, pp.
    pub spread_max_pp: Option<f64>,
    /// Mean of the medoid's high confidence minus the best single file's, pp.
    pub medoid_vs_best_pp: Option<f64>,
    /// The alignment's error against the known warps (`WarpError::mean_samples`), mean over
    /// the seeds that measured it, reference samples; `None` when none did.
    #[serde(default)]
    pub warp_mean_samples: Option<f64>,
    /// The largest `WarpError::max_samples` of a seed, reference samples.
    #[serde(default)]
    pub warp_max_samples: Option<f64>,
}

fn mean(v: impl IntoIterator<Item = f64>) -> f64 {
    let (s, n) = v
        .into_iter()
        .fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    if n == 0 { f64::NAN } else { s / n as f64 }
}

/// The rows of every family, robot count and cell present in `report`, in its order.
#[must_use]
pub fn family_rows(report: &ZooReport) -> Vec<FamilyRow> {
    let mut keys: Vec<(String, usize, Cell)> = Vec::new();
    for r in &report.runs {
        let key = (r.family.clone(), r.robots, r.cell);
        if !keys.contains(&key) {
            keys.push(key);
        }
    }
    keys.into_iter()
        .map(|(family, robots, cell)| {
            let runs: Vec<&RunReport> = report
                .runs
                .iter()
                .filter(|r| r.family == family && r.robots == robots && r.cell == cell)
                .collect();
            row(family, robots, cell, &runs)
        })
        .collect()
}

fn row(family: String, robots: usize, cell: Cell, runs: &[&RunReport]) -> FamilyRow {
    let m = |f: &dyn Fn(&RunReport) -> f64| mean(runs.iter().map(|r| f(r)));
    let overlapped: Vec<f64> = runs
        .iter()
        .filter_map(|r| r.first_overlap_round.map(|k| k as f64))
        .collect();
    let (max_increase_s, max_increase_ticks) = runs
        .iter()
        .map(|r| (r.max_increase_s, r.max_increase_s / r.tick_s))
        .fold((f64::NEG_INFINITY, f64::NEG_INFINITY), |a, b| {
            (a.0.max(b.0), a.1.max(b.1))
        });
    FamilyRow {
        family,
        robots,
        cell,
        seeds: runs.len(),
        t_total_s: m(&RunReport::final_t_s),
        bound_s: m(&|r| r.bound_s),
        gap_pct: m(&RunReport::gap_pct),
        gap_max_pct: min_max(&runs.iter().map(|r| r.gap_pct()).collect::<Vec<_>>()).1,
        gap_split_pct: {
            let split: Vec<(f64, f64)> = runs.iter().filter_map(|r| r.gap_split_pct()).collect();
            (!split.is_empty()).then(|| {
                (
                    mean(split.iter().map(|s| s.0)),
                    mean(split.iter().map(|s| s.1)),
                )
            })
        },
        unavoidable_pct: {
            let u: Vec<f64> = runs.iter().filter_map(|r| r.unavoidable_pct()).collect();
            (!u.is_empty()).then(|| (mean(u.iter().copied()), u.len()))
        },
        bound_proven: runs.iter().filter(|r| r.bound_is_optimum).count(),
        over_serial: m(&|r| r.final_t_s() / r.serial_s),
        high_pct: m(&RunReport::final_high_pct),
        truth_pct: m(&|r| r.truth_high_pct),
        high_minus_truth_pp: m(&|r| r.final_high_pct() - r.truth_high_pct),
        high_minus_truth_max_pp: runs
            .iter()
            .map(|r| (r.final_high_pct() - r.truth_high_pct).abs())
            .fold(0.0, f64::max),
        falsely_trusted: m(&|r| r.falsely_trusted as f64),
        falsely_trusted_agreeing: m(&|r| r.falsely_trusted_agreeing as f64),
        first_overlap_round: (!overlapped.is_empty()).then(|| mean(overlapped.iter().copied())),
        never_overlapped: if cell == Cell::Rounds {
            runs.len() - overlapped.len()
        } else {
            0
        },
        max_increase_s,
        max_increase_ticks,
        by_fate: runs
            .iter()
            .fold(FateIncreases::default(), |a, r| a.merged(r.by_fate)),
        realized_over_planned: m(&|r| r.realized_over_planned),
        planned_per_h: m(&|r| r.planned_per_h),
        realized_per_h: m(&|r| r.realized_per_h),
        over_plan_pct: m(&|r| pct_of_plan(r, r.plan_gap.total_s())),
        cause_pct: std::array::from_fn(|k| m(&|r| pct_of_plan(r, r.plan_gap.parts()[k].1))),
        needed_unsupervised: m(&|r| r.needed_unsupervised as f64),
        backward_steps: runs.iter().map(|r| r.backward_steps).sum(),
        max_backward_samples: runs
            .iter()
            .map(|r| r.max_backward_samples)
            .fold(0.0, f64::max),
        overlap_ticks: runs.iter().map(|r| r.overlap_ticks).sum(),
        faults: runs.iter().map(|r| r.faults).sum(),
    }
}

/// `s` as a percent of the run's planned time (0 when nothing was planned).
fn pct_of_plan(r: &RunReport, s: f64) -> f64 {
    if r.plan_gap.planned_s > 0.0 {
        100.0 * s / r.plan_gap.planned_s
    } else {
        0.0
    }
}

/// The fit rows of every family in `report`, in its order.
#[must_use]
pub fn fit_rows(report: &ZooReport) -> Vec<FitRow> {
    report
        .families
        .iter()
        .filter_map(|family| {
            let fits: Vec<_> = report.fits.iter().filter(|f| &f.family == family).collect();
            if fits.is_empty() {
                return None;
            }
            let spreads: Vec<_> = fits.iter().filter_map(|f| f.spread.as_ref()).collect();
            let measured = !spreads.is_empty();
            let warps: Vec<_> = fits.iter().filter_map(|f| f.warp_error.as_ref()).collect();
            let aligned = !warps.is_empty();
            Some(FitRow {
                family: family.clone(),
                seeds: fits.len(),
                truth_pct: mean(fits.iter().map(|f| f.truth_high_pct)),
                fit_high_pct: mean(fits.iter().map(|f| f.fit_high_pct)),
                fit_lc_runs: mean(fits.iter().map(|f| f.fit_lc_runs as f64)),
                spread_pp: measured.then(|| mean(spreads.iter().map(|s| s.spread_pp()))),
                spread_max_pp: measured
                    .then(|| spreads.iter().map(|s| s.spread_pp()).fold(0.0, f64::max)),
                medoid_vs_best_pp: measured
                    .then(|| mean(spreads.iter().map(|s| s.medoid_vs_best_pp()))),
                warp_mean_samples: aligned.then(|| mean(warps.iter().map(|w| w.mean_samples))),
                warp_max_samples: aligned
                    .then(|| warps.iter().map(|w| w.max_samples).fold(0.0, f64::max)),
            })
        })
        .collect()
}

/// The acceptance limits of `cargo xtask zoo --check`, applied to every [`FamilyRow`] (the
/// mean over a family's seeds) of the rounds cell, and the safety limits to every run.
///
/// The one place they live: [`Thresholds::CI`] is what today's code meets on the held-out
/// seeds with a margin (docs/zoo.md, docs/decisions.md "The task zoo"), to be tightened
/// towards [`Thresholds::TARGET`] (issue 38's "Must show") as the fixes land.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Thresholds {
    /// Backward steps of reference time in a run. Always 0.
    pub max_backward_steps: usize,
    /// Overlapping ticks (and faults) in a run. Always 0.
    pub max_overlap_ticks: u64,
    /// Largest mean `T_total / bound − 1` of a family with two robots, percent.
    pub max_gap_pct_n2: f64,
    /// The same with three robots, percent.
    pub max_gap_pct_n3: f64,
    /// The same with four or more robots, percent.
    pub max_gap_pct_n4: f64,
    /// Largest mean `|high confidence − truth|` of a family, percentage points.
    pub max_high_vs_truth_pp: f64,
}

impl Thresholds {
    /// What CI checks today: limits every held-out seed met alone (CI runs one seed, so a
    /// family's "mean" there is one seed's value), with a margin. Measured at commit f67bc36
    /// (docs/zoo.md, rounds, 30 rounds): the worst seed of any family 58.2 % above its bound
    /// with two robots (polishing), family means up to 50.0 % with three and 123.5 % with
    /// four robots (screw driving), high confidence at most 16.4 pp from the truth (peg
    /// insertion).
    pub const CI: Thresholds = Thresholds {
        max_backward_steps: 0,
        max_overlap_ticks: 0,
        max_gap_pct_n2: 75.0,
        max_gap_pct_n3: 100.0,
        max_gap_pct_n4: 200.0,
        max_high_vs_truth_pp: 25.0,
    };

    /// Issue 38's targets: within 5 % of the bound for two robots, 10 % for three, high
    /// confidence within 2 pp of the truth; never a backward step or an overlap.
    pub const TARGET: Thresholds = Thresholds {
        max_backward_steps: 0,
        max_overlap_ticks: 0,
        max_gap_pct_n2: 5.0,
        max_gap_pct_n3: 10.0,
        max_gap_pct_n4: 10.0,
        max_high_vs_truth_pp: 2.0,
    };

    /// The gap limit for `robots` robots (percent; no limit for one robot).
    #[must_use]
    pub fn max_gap_pct(&self, robots: usize) -> f64 {
        match robots {
            0 | 1 => f64::INFINITY,
            2 => self.max_gap_pct_n2,
            3 => self.max_gap_pct_n3,
            _ => self.max_gap_pct_n4,
        }
    }
}

impl Default for Thresholds {
    fn default() -> Self {
        Self::CI
    }
}

/// A limit a report breaks.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Breach {
    /// The family (and seed, for a safety limit).
    pub at: String,
    /// What, with the value and the limit.
    pub what: String,
}

/// Every limit of `limits` that `report` breaks: backward steps and overlaps per run (any
/// cell), the gap and the high confidence per family row of the rounds cell.
#[must_use]
pub fn check(report: &ZooReport, limits: &Thresholds) -> Vec<Breach> {
    let mut out = Vec::new();
    for r in &report.runs {
        let at = format!("{} seed {} N={} {:?}", r.family, r.seed, r.robots, r.cell);
        if r.backward_steps > limits.max_backward_steps {
            out.push(Breach {
                at: at.clone(),
                what: format!(
                    "{} backward steps of reference time (largest {:.3} samples; limit {})",
                    r.backward_steps, r.max_backward_samples, limits.max_backward_steps
                ),
            });
        }
        if r.overlap_ticks + r.faults > limits.max_overlap_ticks {
            out.push(Breach {
                at,
                what: format!(
                    "{} overlapping ticks, {} faults (limit {})",
                    r.overlap_ticks, r.faults, limits.max_overlap_ticks
                ),
            });
        }
    }
    for row in family_rows(report)
        .iter()
        .filter(|r| r.cell == Cell::Rounds)
    {
        let at = format!(
            "{} N={} (mean of {} seeds)",
            row.family, row.robots, row.seeds
        );
        let gap_limit = limits.max_gap_pct(row.robots);
        if row.gap_pct > gap_limit {
            out.push(Breach {
                at: at.clone(),
                what: format!(
                    "T_total {:.1} % above its bound (limit {gap_limit} %)",
                    row.gap_pct
                ),
            });
        }
        if row.high_minus_truth_pp.abs() > limits.max_high_vs_truth_pp {
            out.push(Breach {
                at,
                what: format!(
                    "high confidence {:+.1} pp from the truth (limit ±{} pp)",
                    row.high_minus_truth_pp, limits.max_high_vs_truth_pp
                ),
            });
        }
    }
    out
}
