//! What a study records: per iteration, per trial and for the whole study, with the
//! summary across trials (Fig. 5) and the CSV rows.

use std::fmt::Write as _;

use serde::{Deserialize, Serialize};
use tandem_confidence::ErrorRates;
use tandem_schedule::Source;

use super::config::StudyConfig;
use crate::workcell::PlanGap;

/// What happened when a round (one execution of each robot) ran under one schedule.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RoundStats {
    /// Control ticks in which two or more robots traversed a low-confidence sample (must be 0).
    pub overlap_ticks: usize,
    /// Share of the round's duration (ticks) in which no robot was low-confidence, in [0, 1].
    pub operator_idle_share: f64,
    /// Actual duration of the round (s, global time), from the start until every robot
    /// finished.
    pub duration_s: f64,
    /// Ticks in which a robot was low-confidence (supervised), all robots together.
    pub supervised_ticks: usize,
    /// Supervised ticks in which the operator corrected, all robots together.
    pub corrected_ticks: usize,
    /// Operator busy share, in [0, 1]: the share of the round's control ticks (from the
    /// first robot's start until the last robot finished) in which at least one robot
    /// traversed a low-confidence sample, so that the operator was needed
    /// (`1 − operator_idle_share`; docs/study.md).
    pub operator_busy_share: f64,
    /// Faults of the coordinator's run-time monitor in the round
    /// ([`RoundRun::faults`](crate::workcell::RoundRun::faults); must be 0). Left out of the
    /// JSON when 0, as it always is for the checked schedules a study runs.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub faults: usize,
    /// Share of the robots' time in the round spent waiting (start offsets, holds, done
    /// before the last robot), in `[0, 1]`
    /// ([`RoundRun::robot_wait_share`](crate::workcell::RoundRun::robot_wait_share)); 0 in
    /// files written before it was recorded.
    #[serde(default)]
    pub robot_wait_share: f64,
    /// Control ticks the robots stood at hold points, summed over robots (0 without holds,
    /// and then left out of the JSON).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub hold_ticks: usize,
    /// Where the round's time went against its plan: realized minus planned `T_total` split
    /// into corrections, holds, response strategy, tick grid, faults and critical path
    /// ([`RoundRun::plan_gap`](crate::workcell::RoundRun::plan_gap); all 0 in files written
    /// before it was recorded).
    #[serde(default)]
    pub plan_gap: PlanGap,
    /// Samples the robots ran at high confidence (unsupervised) where the truth says the
    /// operator is needed ([`RoundRun::needed_unsupervised`](crate::workcell::RoundRun::needed_unsupervised)).
    #[serde(default)]
    pub needed_unsupervised: usize,
    /// Needed corrections the simulated operator missed because it was still switching its
    /// attention from another robot (its switch time `δ_true`, issue 41), summed over the
    /// round's executions ([`RobotRun::switch_missed`](crate::workcell::RobotRun::switch_missed)).
    /// Left out of the JSON when 0, as it always is without a switch time.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub switch_missed: usize,
    /// The operator's rest after the round (s) under the load cap `u_max < 1` (issue 41;
    /// [`RoundRun::rest_ticks`](crate::workcell::RoundRun::rest_ticks) times the tick): the
    /// next round starts that long after this one ended. The operator's busy share over the
    /// round and its rest is at most `u_max`. Left out of the JSON when 0, as it always is
    /// without a cap.
    #[serde(default, skip_serializing_if = "is_zero_s")]
    pub rest_s: f64,
}

/// Deprecated: [`RoundStats`] under its two-robot name. Kept for one release at the crate's
/// public edge.
#[deprecated(note = "use `RoundStats` (a round is one execution of each robot)")]
pub type PairStats = RoundStats;

/// Whether a count is 0 (for `skip_serializing_if`).
#[expect(
    clippy::trivially_copy_pass_by_ref,
    reason = "serde passes the field by reference"
)]
fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// Whether a time is 0 (for `skip_serializing_if`).
#[expect(
    clippy::trivially_copy_pass_by_ref,
    reason = "serde passes the field by reference"
)]
fn is_zero_s(s: &f64) -> bool {
    *s == 0.0
}

/// One iteration of a trial: a schedule and what running it gave.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IterationRecord {
    /// Rounds recorded before this schedule was made (0 = demonstrations only).
    pub iteration: usize,
    /// Planned `T_total` (Eq. 13, s).
    pub t_total_s: f64,
    /// Planned offset `τ` of robot 2 (s, global time; 0 for a single robot).
    pub offset_s: f64,
    /// Share of reference samples that are high-confidence (Eq. 12), in percent.
    pub high_conf_pct: f64,
    /// Where the schedule came from.
    pub source: ScheduleSource,
    /// Planned low-confidence intervals `[start_s, end_s)` of each robot, robot 1 first
    /// (global time, s).
    pub lc_intervals_s: Vec<Vec<[f64; 2]>>,
    /// The outcome of running the next round under this schedule (`None` for the last one;
    /// `pair` in the JSON, the name of the files written so far).
    #[serde(rename = "pair")]
    pub round: Option<RoundStats>,
    /// The schedule's certificate ([`tandem_schedule::Outcome::lower_bound_s`]): a lower
    /// bound (s, global time) on the `T_total` of every schedule of Eq. 20 for this
    /// iteration's problem, the margin-free optimum `T*₀` when
    /// [`IterationRecord::bound_is_optimum`].
    pub lower_bound_s: f64,
    /// Whether [`IterationRecord::lower_bound_s`] is the proven margin-free optimum `T*₀`.
    pub bound_is_optimum: bool,
    /// `(T_total − lower_bound_s) / lower_bound_s` (dimensionless; the bound is unclamped, so
    /// ≥ 0 up to rounding: never below `−realtime::tol::BOUND_REL`, e.g. `−2.4e-16` when the
    /// schedule is the optimum).
    pub gap: f64,
    /// The search's share of [`IterationRecord::gap`] ([`tandem_schedule::GapSplit::search`]:
    /// `(margin_free_s − lower_bound_s) / lower_bound_s`, dimensionless, 0 when the bound is
    /// proven): what the margin-free search left open; the rest of the gap is the margins'
    /// (and release waits') cost above the best margin-free schedule known. `None` when the
    /// outcome does not know its margin-free schedule.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gap_search: Option<f64>,
    /// Planned throughput: tasks per hour per operator, `N·3600 / T_total` (`N` robots each
    /// finish one task per `T_total` seconds of the schedule).
    pub throughput_per_h: f64,
    /// Planned start offsets `τ_2, …, τ_N` of robots 2..N (s, global time; `N − 1` values,
    /// `[offset_s]` for two robots).
    pub offsets_s: Vec<f64>,
    /// Reference samples that truly need help ([`crate::truth::needs_help`]) but are
    /// high-confidence in this iteration's confidence: sanded unsupervised.
    #[serde(default)]
    pub falsely_trusted_samples: usize,
    /// Low-confidence runs of each robot's schedule, robot 1 first (the lengths of
    /// [`IterationRecord::lc_intervals_s`]).
    #[serde(default)]
    pub lc_runs: Vec<usize>,
    /// The operator's error rates this iteration's confidence was decided with (estimated
    /// from the rounds recorded so far, or the configured ones; per control sample).
    #[serde(default)]
    pub error_rates: ErrorRates,
    /// The simulated operator's actual rates over the rounds recorded so far
    /// ([`OperatorTally::rates`](crate::truth::OperatorTally::rates)); `None` before any round.
    #[serde(default)]
    pub simulated_rates: Option<ErrorRates>,
}

/// Where a study iteration's schedule came from: the kind of [`tandem_schedule::Source`]
/// without the candidate index, under the name the study's JSON and CSV give it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ScheduleSource {
    /// A candidate of the anytime sampler (`Source::Sampled`): `sampled`.
    Sampled,
    /// The margin-aware completion of the exact margin-free optimum (`Source::Completed`):
    /// `completed`.
    Completed,
    /// The previous schedule, unchanged (`Source::Previous`): `previous`.
    Previous,
    /// The previous schedule re-projected onto the new problem (`Source::RepairedPrevious`):
    /// `repaired`.
    Repaired,
    /// The fastest serial schedule (`Source::Serial`): `serial`.
    Serial,
    /// The exact optimum with hold points and release rules (`Source::Held`): `held`.
    Held,
    /// `N ≥ 3` robots staggered at the least starts the check accepts
    /// (`Source::Staggered`): `staggered`.
    Staggered,
}

impl ScheduleSource {
    /// The name in the study's JSON and CSV.
    pub fn name(self) -> &'static str {
        match self {
            Self::Sampled => "sampled",
            Self::Completed => "completed",
            Self::Previous => "previous",
            Self::Repaired => "repaired",
            Self::Serial => "serial",
            Self::Held => "held",
            Self::Staggered => "staggered",
        }
    }
}

impl From<Source> for ScheduleSource {
    fn from(source: Source) -> Self {
        match source {
            Source::Sampled { .. } => Self::Sampled,
            Source::Completed => Self::Completed,
            Source::Previous => Self::Previous,
            Source::RepairedPrevious => Self::Repaired,
            Source::Serial => Self::Serial,
            Source::Held => Self::Held,
            Source::Staggered => Self::Staggered,
        }
    }
}

impl std::fmt::Display for ScheduleSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One trial: its seed and every iteration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrialResult {
    /// Trial index `k`.
    pub trial: usize,
    /// Seed of the trial, derived from `(seed, k)` by [`trial_seed`](super::trial_seed).
    pub seed: u64,
    /// Iterations `0..=n_rounds`: the schedule before each round, and the last one.
    pub iterations: Vec<IterationRecord>,
}

/// The whole study: everything the JSON output holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StudyResult {
    /// The configuration it ran with.
    pub config: StudyConfig,
    /// Reference samples of the task (`T_ref`).
    pub n_ref: usize,
    /// Reference sample period `Δt_s` (s).
    pub dt_s: f64,
    /// Ground truth (§III): percent of reference samples outside the sanding of passes 1–3.
    pub ground_truth_pct: f64,
    /// The trials, in trial order.
    pub trials: Vec<TrialResult>,
}

/// Per-iteration statistics across trials.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IterationSummary {
    /// Iteration index (rounds recorded).
    pub iteration: usize,
    /// Mean planned `T_total` across trials (s).
    pub t_total_mean_s: f64,
    /// Sample standard deviation of `T_total` across trials (s); 0 for a single trial.
    pub t_total_std_s: f64,
    /// Mean percent of high-confidence reference samples across trials.
    pub high_conf_pct_mean: f64,
    /// Sample standard deviation of that percent across trials (percentage points).
    pub high_conf_pct_std: f64,
    /// Overlap ticks summed across trials (must be 0).
    pub overlap_ticks: usize,
    /// Mean certificate lower bound `T*₀` across trials (s; [`IterationRecord::lower_bound_s`]).
    pub lower_bound_mean_s: f64,
    /// Share of trials, in [0, 1], whose lower bound is the proven margin-free optimum.
    pub bound_proven_share: f64,
    /// Mean relative gap of `T_total` to the lower bound across trials (dimensionless).
    pub gap_mean: f64,
    /// Mean across trials of the search's share of the gap ([`IterationRecord::gap_search`];
    /// `gap_mean` minus it is the margins' share); `None` unless every trial records it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gap_search_mean: Option<f64>,
    /// Mean planned throughput across trials (tasks per hour per operator,
    /// [`IterationRecord::throughput_per_h`]).
    pub throughput_mean_per_h: f64,
    /// Mean operator busy share across trials of the round run under this iteration's
    /// schedule ([`RoundStats::operator_busy_share`], in [0, 1]); `None` for the last
    /// iteration, after which no round runs.
    pub operator_busy_share_mean: Option<f64>,
    /// Mean across trials of the round's [`RoundStats::plan_gap`] (realized against planned
    /// `T_total` and its causes, s); `None` for the last iteration.
    #[serde(default)]
    pub plan_gap_mean: Option<PlanGap>,
    /// Mean across trials of the round's [`RoundStats::needed_unsupervised`]; `None` for the
    /// last iteration.
    #[serde(default)]
    pub needed_unsupervised_mean: Option<f64>,
}

impl StudyResult {
    /// Mean and standard deviation of each iteration across trials (Fig. 5 top and bottom).
    pub fn summary(&self) -> Vec<IterationSummary> {
        let n_iter = self
            .trials
            .iter()
            .map(|t| t.iterations.len())
            .min()
            .unwrap_or(0);
        (0..n_iter)
            .map(|k| {
                let recs: Vec<&IterationRecord> =
                    self.trials.iter().map(|t| &t.iterations[k]).collect();
                let (mean, std) = mean_std(recs.iter().map(|r| r.t_total_s));
                let (hc, hc_std) = mean_std(recs.iter().map(|r| r.high_conf_pct));
                IterationSummary {
                    iteration: recs[0].iteration,
                    t_total_mean_s: mean,
                    t_total_std_s: std,
                    high_conf_pct_mean: hc,
                    high_conf_pct_std: hc_std,
                    overlap_ticks: recs
                        .iter()
                        .filter_map(|r| r.round.as_ref())
                        .map(|p| p.overlap_ticks)
                        .sum(),
                    lower_bound_mean_s: mean_std(recs.iter().map(|r| r.lower_bound_s)).0,
                    bound_proven_share: recs.iter().filter(|r| r.bound_is_optimum).count() as f64
                        / recs.len() as f64,
                    gap_mean: mean_std(recs.iter().map(|r| r.gap)).0,
                    gap_search_mean: recs
                        .iter()
                        .map(|r| r.gap_search)
                        .collect::<Option<Vec<f64>>>()
                        .map(|v| mean_std(v.into_iter()).0),
                    throughput_mean_per_h: mean_std(recs.iter().map(|r| r.throughput_per_h)).0,
                    operator_busy_share_mean: {
                        let busy: Vec<f64> = recs
                            .iter()
                            .filter_map(|r| r.round.as_ref())
                            .map(|p| p.operator_busy_share)
                            .collect();
                        (!busy.is_empty()).then(|| mean_std(busy.into_iter()).0)
                    },
                    plan_gap_mean: PlanGap::mean(
                        recs.iter()
                            .filter_map(|r| r.round.as_ref())
                            .map(|p| &p.plan_gap),
                    ),
                    needed_unsupervised_mean: {
                        let n: Vec<f64> = recs
                            .iter()
                            .filter_map(|r| r.round.as_ref())
                            .map(|p| p.needed_unsupervised as f64)
                            .collect();
                        (!n.is_empty()).then(|| mean_std(n.into_iter()).0)
                    },
                }
            })
            .collect()
    }

    /// The gaps of every round of every trial from iteration `from` on, summed cause by
    /// cause ([`RoundStats::plan_gap`]), and the needed-but-unsupervised samples summed over
    /// the same rounds: how optimistic the plans were, and why.
    pub fn plan_gap_total(&self, from: usize) -> (PlanGap, usize) {
        let rounds: Vec<&RoundStats> = self
            .trials
            .iter()
            .flat_map(|t| &t.iterations)
            .filter(|r| r.iteration >= from)
            .filter_map(|r| r.round.as_ref())
            .collect();
        (
            PlanGap::sum(rounds.iter().map(|p| &p.plan_gap)),
            rounds.iter().map(|p| p.needed_unsupervised).sum(),
        )
    }

    /// Needed corrections missed while the simulated operator was switching its attention
    /// (issue 41), summed over every round of every trial
    /// ([`RoundStats::switch_missed`]; 0 without a switch time), and the rounds run.
    pub fn switch_missed_total(&self) -> (usize, usize) {
        let rounds: Vec<&RoundStats> = self
            .trials
            .iter()
            .flat_map(|t| &t.iterations)
            .filter_map(|r| r.round.as_ref())
            .collect();
        (rounds.iter().map(|p| p.switch_missed).sum(), rounds.len())
    }

    /// Total overlap ticks over every round of every trial (must be 0).
    pub fn total_overlap_ticks(&self) -> usize {
        self.trials
            .iter()
            .flat_map(|t| &t.iterations)
            .filter_map(|r| r.round.as_ref())
            .map(|p| p.overlap_ticks)
            .sum()
    }

    /// One CSV row per trial and iteration. Columns: `trial, iteration, t_total_s, offset_s,
    /// high_conf_pct, source, overlap_ticks, operator_idle_share, duration_s, supervised_ticks,
    /// corrected_ticks, operator_busy_share, lower_bound_s, bound_is_optimum, gap,
    /// throughput_per_h`, then one `lc_intervals_robot<i>_s` column per robot; round columns
    /// (`overlap_ticks` to `operator_busy_share`) are empty for the last iteration;
    /// intervals are `start-end` pairs (s) joined by `;`.
    pub fn to_csv(&self) -> String {
        let n_robots = self
            .trials
            .iter()
            .flat_map(|t| &t.iterations)
            .map(|r| r.lc_intervals_s.len())
            .max()
            .unwrap_or(0);
        let mut out = String::from(
            "trial,iteration,t_total_s,offset_s,high_conf_pct,source,overlap_ticks,\
             operator_idle_share,duration_s,supervised_ticks,corrected_ticks,\
             operator_busy_share,lower_bound_s,bound_is_optimum,gap,throughput_per_h",
        );
        for i in 1..=n_robots {
            let _ = write!(out, ",lc_intervals_robot{i}_s");
        }
        out.push('\n');
        for t in &self.trials {
            for r in &t.iterations {
                let round = match &r.round {
                    Some(p) => format!(
                        "{},{},{},{},{},{}",
                        p.overlap_ticks,
                        p.operator_idle_share,
                        p.duration_s,
                        p.supervised_ticks,
                        p.corrected_ticks,
                        p.operator_busy_share,
                    ),
                    None => ",,,,,".to_string(),
                };
                // Writing to a String cannot fail.
                let _ = write!(
                    out,
                    "{},{},{},{},{},{},{},{},{},{},{}",
                    t.trial,
                    r.iteration,
                    r.t_total_s,
                    r.offset_s,
                    r.high_conf_pct,
                    r.source,
                    round,
                    r.lower_bound_s,
                    r.bound_is_optimum,
                    r.gap,
                    r.throughput_per_h,
                );
                for i in 0..n_robots {
                    let intervals = r.lc_intervals_s.get(i).map_or_else(String::new, |v| {
                        v.iter()
                            .map(|[a, b]| format!("{a:.3}-{b:.3}"))
                            .collect::<Vec<_>>()
                            .join(";")
                    });
                    let _ = write!(out, ",{intervals}");
                }
                out.push('\n');
            }
        }
        out
    }
}

/// Tasks per hour per operator when `n_robots` robots each finish one task every
/// `t_total_s` seconds: `N·3600 / T_total`.
#[must_use]
pub fn throughput_per_h(n_robots: usize, t_total_s: f64) -> f64 {
    n_robots as f64 * 3600.0 / t_total_s
}

/// Mean and sample standard deviation (n − 1 denominator; 0 for one value, NaN for none).
pub fn mean_std(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let v: Vec<f64> = values.collect();
    if v.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    if v.len() < 2 {
        return (mean, 0.0);
    }
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, var.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::trial_seed;

    fn record(iteration: usize, t_total_s: f64, round: bool) -> IterationRecord {
        IterationRecord {
            iteration,
            t_total_s,
            offset_s: 1.0,
            high_conf_pct: 10.0 * iteration as f64,
            source: ScheduleSource::Sampled,
            lc_intervals_s: vec![vec![[0.0, 1.5]], vec![[2.0, 2.25], [3.0, 4.0]]],
            round: round.then_some(RoundStats {
                overlap_ticks: 0,
                operator_idle_share: 0.5,
                duration_s: t_total_s,
                supervised_ticks: 10,
                corrected_ticks: 4,
                operator_busy_share: 0.5,
                faults: 0,
                robot_wait_share: 0.25,
                hold_ticks: 0,
                plan_gap: PlanGap {
                    realized_s: t_total_s + 1.0,
                    planned_s: t_total_s,
                    corrections_s: 0.75,
                    strategy_s: 0.25,
                    ..PlanGap::default()
                },
                needed_unsupervised: iteration + 3,
                switch_missed: 0,
                rest_s: 0.0,
            }),
            lower_bound_s: t_total_s - 1.0,
            bound_is_optimum: iteration == 0,
            gap: 1.0 / (t_total_s - 1.0),
            gap_search: None,
            throughput_per_h: throughput_per_h(2, t_total_s),
            offsets_s: vec![1.0],
            falsely_trusted_samples: 0,
            lc_runs: vec![1, 2],
            error_rates: ErrorRates::default(),
            simulated_rates: None,
        }
    }

    fn result() -> StudyResult {
        let trial = |k: usize, a: f64, b: f64| TrialResult {
            trial: k,
            seed: trial_seed(1, k),
            iterations: vec![record(0, a, true), record(1, b, false)],
        };
        StudyResult {
            config: StudyConfig::default(),
            n_ref: 100,
            dt_s: 0.01,
            ground_truth_pct: 50.0,
            trials: vec![trial(0, 10.0, 8.0), trial(1, 12.0, 8.0)],
        }
    }

    /// The summary's search share of the gap is the trials' mean when every trial records
    /// one, and `None` (left out of the JSON) when one does not.
    #[test]
    fn the_gap_search_share_is_averaged_only_when_every_trial_has_it() {
        let mut r = result();
        assert_eq!(r.summary()[1].gap_search_mean, None);
        r.trials[0].iterations[1].gap_search = Some(0.1);
        assert_eq!(r.summary()[1].gap_search_mean, None);
        r.trials[1].iterations[1].gap_search = Some(0.3);
        let mean = r.summary()[1].gap_search_mean.unwrap();
        assert!((mean - 0.2).abs() < 1e-12, "{mean}");
        let json = serde_json::to_string(&r.summary()[0]).unwrap();
        assert!(!json.contains("gap_search"), "{json}");
    }

    #[test]
    fn schedule_sources_keep_their_names_in_json_csv_and_display() {
        let cases = [
            (
                Source::Sampled { candidate: 41 },
                ScheduleSource::Sampled,
                "sampled",
            ),
            (Source::Previous, ScheduleSource::Previous, "previous"),
            (
                Source::RepairedPrevious,
                ScheduleSource::Repaired,
                "repaired",
            ),
            (Source::Serial, ScheduleSource::Serial, "serial"),
        ];
        for (source, kind, name) in cases {
            assert_eq!(ScheduleSource::from(source), kind);
            assert_eq!(kind.to_string(), name);
            let json = serde_json::to_string(&kind).unwrap();
            assert_eq!(json, format!("\"{name}\""));
            assert_eq!(serde_json::from_str::<ScheduleSource>(&json).unwrap(), kind);
        }
    }

    #[test]
    fn summary_is_mean_and_sample_std_across_trials() {
        let s = result().summary();
        assert_eq!(s.len(), 2);
        // Trials give 10 and 12: mean 11, sample std sqrt(2).
        assert_eq!(s[0].t_total_mean_s, 11.0);
        assert!((s[0].t_total_std_s - 2f64.sqrt()).abs() < 1e-12);
        assert_eq!((s[1].t_total_mean_s, s[1].t_total_std_s), (8.0, 0.0));
        assert_eq!(s[1].high_conf_pct_mean, 10.0);
        // The certificate: bounds 9 and 11 (mean 10), both proven at iteration 0, neither
        // at 1; gaps 1/9 and 1/11.
        assert_eq!(s[0].lower_bound_mean_s, 10.0);
        assert_eq!(
            (s[0].bound_proven_share, s[1].bound_proven_share),
            (1.0, 0.0)
        );
        assert!((s[0].gap_mean - (1.0 / 9.0 + 1.0 / 11.0) / 2.0).abs() < 1e-15);
        // Two robots at 8 s: 900 tasks per hour; 10 s and 12 s: (720 + 600) / 2.
        assert_eq!(s[1].throughput_mean_per_h, 900.0);
        assert_eq!(s[0].throughput_mean_per_h, 660.0);
        // A round ran at iteration 0 only.
        assert_eq!(s[0].operator_busy_share_mean, Some(0.5));
        assert_eq!(s[1].operator_busy_share_mean, None);
        // The plans' optimism: each round ran 1 s over (0.75 s corrections, 0.25 s
        // strategy); planned 10 and 12 s, mean 11.
        let gap = s[0].plan_gap_mean.as_ref().unwrap();
        assert_eq!((gap.planned_s, gap.realized_s), (11.0, 12.0));
        assert_eq!((gap.corrections_s, gap.strategy_s), (0.75, 0.25));
        assert_eq!(s[0].needed_unsupervised_mean, Some(3.0));
        assert_eq!(
            (s[1].plan_gap_mean.as_ref(), s[1].needed_unsupervised_mean),
            (None, None)
        );
        let (total, unsupervised) = result().plan_gap_total(0);
        assert_eq!((total.planned_s, total.realized_s), (22.0, 24.0));
        assert!((total.parts_sum_s() - total.total_s()).abs() < 1e-12);
        assert_eq!(unsupervised, 6);
        assert_eq!(result().plan_gap_total(1).0, PlanGap::default());
    }

    #[test]
    fn throughput_is_tasks_per_hour_per_operator() {
        assert_eq!(throughput_per_h(2, 120.0), 60.0);
        assert_eq!(throughput_per_h(1, 3600.0), 1.0);
        assert_eq!(throughput_per_h(8, 90.0), 320.0);
    }

    #[test]
    fn csv_has_one_row_per_trial_and_iteration() {
        let csv = result().to_csv();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 1 + 4);
        let n_cols = lines[0].split(',').count();
        assert_eq!(n_cols, 18);
        assert!(lines[0].ends_with(",lc_intervals_robot1_s,lc_intervals_robot2_s"));
        for l in &lines[1..] {
            assert_eq!(l.split(',').count(), n_cols, "{l}");
        }
        assert_eq!(
            lines[1],
            "0,0,10,1,0,sampled,0,0.5,10,10,4,0.5,9,true,0.1111111111111111,720,\
             0.000-1.500,2.000-2.250;3.000-4.000"
        );
        assert!(lines[2].starts_with("0,1,8,1,10,sampled,,,,,,,7,false,"));
    }
}
