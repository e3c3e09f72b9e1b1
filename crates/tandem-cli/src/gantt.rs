//! The schedule as the user sees it: a text Gantt chart and a JSON document.

use std::fmt::Write as _;

use anyhow::Result;

use crate::json::{AfterOut, LcIntervalOut, ScheduleDoc, ScheduleHoldOut, ScheduleOut};
use tandem::realtime::{After, Timeline, tol};
use tandem::schedule::{LcInterval, Outcome, Problem, Schedule, SerialForm, Source};

/// Columns of the text Gantt's bars.
const GANTT_COLUMNS: usize = 72;

/// Human-readable name of where a schedule came from.
pub(crate) fn source_name(source: &Source) -> String {
    match source {
        Source::Sampled { candidate } => format!("sampled (candidate {candidate})"),
        Source::Completed => "margin-aware completion of the exact optimum".into(),
        Source::Previous => "previous schedule (still valid, nothing better found)".into(),
        Source::RepairedPrevious => "previous schedule, repaired for the new model".into(),
        Source::Serial => "fastest serial schedule (fallback)".into(),
        Source::Held => "exact optimum with hold points and release rules".into(),
        Source::Staggered => "staggered (fastest warps, least starts the check accepts)".into(),
    }
}

/// Human-readable name of where `outcome`'s schedule came from: [`source_name`], except that a
/// serial fallback is named by its form ([`SerialForm::of`]: the fastest serial schedule, or
/// one slowed or idling for the operator's switch time or load cap), which the state file's
/// source alone does not tell.
pub(crate) fn outcome_source_name(problem: &Problem, outcome: &Outcome) -> String {
    match outcome.source {
        Source::Serial => SerialForm::of(&outcome.schedule, problem).label().into(),
        ref other => source_name(other),
    }
}

/// `T_total` (s) of the fastest serial schedule of `n_robots` robots on `problem` (each robot
/// starts when the one before it ends) at control tick `tick_s` (s; `T_total` does not depend
/// on it, the schedule does).
pub(crate) fn serial_t_total_s(problem: &Problem, n_robots: usize, tick_s: f64) -> Result<f64> {
    Ok(problem
        .serial_schedule_n(n_robots, tick_s)?
        .t_total_s(problem.dt_s()))
}

/// The start offsets `τ_2, …, τ_N` of a schedule as text, `"12.65"` for two robots,
/// `"0.29, 0.58"` for three (s, two decimals); `None` for a single robot.
pub(crate) fn offsets_text(schedule: &Schedule) -> Option<String> {
    (!schedule.offsets_s.is_empty()).then(|| {
        schedule
            .offsets_s
            .iter()
            .map(|t| format!("{t:.2}"))
            .collect::<Vec<_>>()
            .join(", ")
    })
}

/// The certificate of a schedule in one line: its `T_total`, the margin-free lower bound
/// `T*₀` with the gap to it, and the fastest serial schedule's `T_total` (all s), e.g.
/// `T_total 90.34 s — lower bound 89.91 s without margins (+0.49 %), fastest serial 145.75 s`.
pub(crate) fn certificate_line(problem: &Problem, outcome: &Outcome) -> Result<String> {
    let s = &outcome.schedule;
    let serial = serial_t_total_s(problem, s.n_robots(), s.tick_s)?;
    let bound = if outcome.bound_is_optimum {
        "lower bound"
    } else if s.n_robots() == 2 {
        "lower bound (search budget spent: not the optimum)"
    } else {
        "operator-limited lower bound (every robot's low-confidence time in turn)"
    };
    Ok(format!(
        "T_total {:.2} s — {bound} {:.2} s without margins ({}), fastest serial {serial:.2} s",
        outcome.t_total_s,
        outcome.lower_bound_s,
        gap_text(outcome.gap),
    ))
}

/// A certificate's relative gap as a signed percentage with two decimals, `"+0.49 %"`.
/// A gap of magnitude at most `tol::BOUND_REL` is the bound equal to `T_total` up to the
/// rounding a valid schedule is allowed (the bound is reported unclamped, so such a gap may
/// be `−5.7e-15`): it prints `"+0.00 %"`. A gap below `−tol::BOUND_REL` is a wrong bound and
/// prints with its minus sign, never hidden.
pub(crate) fn gap_text(gap: f64) -> String {
    let pct = if gap.abs() <= tol::BOUND_REL {
        0.0
    } else {
        100.0 * gap
    };
    format!("{pct:+.2} %")
}

/// One planned wait of a robot at a hold point, in global time.
pub(crate) struct Dwell {
    /// The robot (0-based).
    pub(crate) robot: usize,
    /// The hold's reference sample (the robot has done samples `0..ref_idx`).
    pub(crate) ref_idx: usize,
    /// Global time (s) the robot reaches the hold on schedule.
    pub(crate) start_s: f64,
    /// Global time (s) it leaves on schedule (`start_s` plus the planned dwell).
    pub(crate) end_s: f64,
    /// Its release rules (robot `robot` 0-based has passed reference sample `ref_idx`).
    pub(crate) after: Vec<After>,
}

/// A schedule laid out in global time with its holds: every robot's legs
/// (`Schedule::legs`: one leg per robot without holds, its timeline) and planned dwells.
pub(crate) struct Layout {
    /// Per robot, its legs in order.
    pub(crate) legs: Vec<Vec<Timeline>>,
    /// Per robot, the first reference sample of each leg (a leg's own reference samples
    /// count from its start: add this to them).
    pub(crate) leg_from: Vec<Vec<usize>>,
    /// Every hold of the schedule with its planned wait, by robot then reference sample
    /// (a hold at the task start waits from `τ_i` to `τ_i`: the offset is its dwell).
    pub(crate) dwells: Vec<Dwell>,
}

impl Layout {
    pub(crate) fn new(problem: &Problem, schedule: &Schedule) -> Result<Self> {
        let legs = schedule.legs(problem)?;
        let leg_from = (0..legs.len())
            .map(|robot| {
                std::iter::once(0)
                    .chain(
                        schedule
                            .holds_of(robot)
                            .iter()
                            .map(|h| h.ref_idx)
                            .filter(|&n| n > 0),
                    )
                    .collect()
            })
            .collect();
        let mut dwells = Vec::new();
        for (robot, robot_legs) in legs.iter().enumerate() {
            let mut k = 0;
            for h in schedule.holds_of(robot) {
                let (start_s, end_s) = if h.ref_idx == 0 {
                    let t = schedule.start_s(robot);
                    (t, t)
                } else {
                    // Hold k (of those after the start) joins leg k and leg k + 1.
                    let s = (robot_legs[k].end_s(), robot_legs[k + 1].start_s());
                    k += 1;
                    s
                };
                dwells.push(Dwell {
                    robot,
                    ref_idx: h.ref_idx,
                    start_s,
                    end_s,
                    after: h.after.clone(),
                });
            }
        }
        Ok(Layout {
            legs,
            leg_from,
            dwells,
        })
    }

    /// One leg per robot and no holds: the timelines of a cell of different tasks (each
    /// robot's own task, global time; `CellPlanner::timelines`).
    pub(crate) fn of_timelines(timelines: Vec<Timeline>) -> Self {
        let n = timelines.len();
        Layout {
            legs: timelines.into_iter().map(|t| vec![t]).collect(),
            leg_from: vec![vec![0]; n],
            dwells: Vec::new(),
        }
    }

    /// `T_total` (s, global time): the latest end of a leg.
    fn t_total_s(&self) -> f64 {
        self.legs
            .iter()
            .flatten()
            .map(Timeline::end_s)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// What robot `robot` does at global time `t` (s): `Some(true)` running high-confidence,
    /// `Some(false)` running low-confidence, `None` not running (before its start, waiting
    /// at a hold, or done).
    fn running_conf(&self, robot: usize, t: f64) -> Option<bool> {
        self.legs[robot]
            .iter()
            .find(|l| t >= l.start_s() && t < l.end_s())
            .map(|l| l.conf_at(t))
    }

    /// Whether robot `robot` waits at a hold at global time `t` (s).
    fn waiting(&self, robot: usize, t: f64) -> bool {
        self.dwells
            .iter()
            .any(|d| d.robot == robot && t >= d.start_s && t < d.end_s)
    }
}

/// Every robot's low-confidence intervals with their robot index (0-based), sorted by start
/// (the lower robot first on a tie).
fn sorted_intervals(layout: &Layout) -> Vec<(usize, LcInterval)> {
    let mut out: Vec<(usize, LcInterval)> = layout
        .legs
        .iter()
        .zip(&layout.leg_from)
        .enumerate()
        .flat_map(|(robot, (legs, from))| {
            legs.iter().zip(from).flat_map(move |(l, &from)| {
                l.lc_intervals().iter().map(move |iv| {
                    let mut iv = *iv;
                    iv.ref_start += from;
                    iv.ref_end += from;
                    (robot, iv)
                })
            })
        })
        .collect();
    out.sort_by(|a, b| a.1.start_s.total_cmp(&b.1.start_s));
    out
}

/// The schedule's holds for JSON (robots 1-based, times in global s).
fn holds_out(layout: &Layout, dt_s: f64) -> Vec<ScheduleHoldOut> {
    layout
        .dwells
        .iter()
        .map(|d| ScheduleHoldOut {
            robot: d.robot + 1,
            ref_idx: d.ref_idx,
            ref_s: d.ref_idx as f64 * dt_s,
            start_s: d.start_s,
            end_s: d.end_s,
            dwell_s: d.end_s - d.start_s,
            after: d
                .after
                .iter()
                .map(|a| AfterOut {
                    robot: a.robot + 1,
                    ref_idx: a.ref_idx,
                })
                .collect(),
        })
        .collect()
}

/// The schedule as JSON ([`ScheduleDoc`]): robot count, offsets, per-robot gradients and
/// durations, low-confidence intervals in global time, `T_total` and its certificate (the
/// margin-free lower bound, whether it is the proven optimum, the gap) (all times in seconds
/// of global time; gradients in execution samples per reference sample).
pub(crate) fn schedule_doc(problem: &Problem, outcome: &Outcome) -> Result<ScheduleDoc> {
    let layout = Layout::new(problem, &outcome.schedule)?;
    let dt = problem.dt_s();
    let s = &outcome.schedule;
    let lc_intervals = sorted_intervals(&layout)
        .iter()
        .map(|(robot, iv)| LcIntervalOut {
            robot: robot + 1,
            ref_start: iv.ref_start,
            ref_end: iv.ref_end,
            start_s: iv.start_s,
            end_s: iv.end_s,
        })
        .collect();
    // Holds and dwells only with holds, so that a schedule without them prints as before
    // hold points.
    let with_holds = s.has_holds();
    Ok(ScheduleDoc {
        t_total_s: outcome.t_total_s,
        lower_bound_s: outcome.lower_bound_s,
        bound_is_optimum: outcome.bound_is_optimum,
        gap: outcome.gap,
        serial_t_total_s: serial_t_total_s(problem, s.n_robots(), s.tick_s)?,
        n_robots: s.n_robots(),
        offset_s: s.offsets_s.first().copied(),
        offsets_s: s.offsets_s.clone(),
        durations_s: s.durations_s(dt),
        dt_s: dt,
        tick_s: s.tick_s,
        n_ref: problem.n_ref(),
        source: outcome_source_name(problem, outcome),
        lc_intervals,
        schedule: ScheduleOut::from(s),
        holds: with_holds.then(|| holds_out(&layout, dt)),
        dwells_s: with_holds.then(|| (0..s.n_robots()).map(|i| s.dwell_s(i)).collect()),
        saved: None,
        previous_t_total_s: None,
    })
}

/// The chart of a [`Layout`]: its time axis, one bar per robot over `[0, T_total]` (`=`
/// running high-confidence, `#` running low-confidence, `h` waiting at a hold, blank not
/// running), the operator's row (`1`…`9`, then `a`…`g` for robots 10–16: which robot is
/// supervised, `.` idle, `!` two or more), the legend, and every low-confidence interval in global time. `labels[i]` names
/// robot `i` (`robot 1`, or `robot 1 (sanding)` in a cell of tasks); the bars start after the
/// longest label.
fn write_chart(out: &mut String, layout: &Layout, labels: &[String], holds: bool) -> Result<()> {
    let t_total = layout.t_total_s();
    let n = labels.len();
    let width = labels
        .iter()
        .map(|l| l.chars().count())
        .chain(std::iter::once("operator".len()))
        .max()
        .unwrap_or(0);
    let mut rows = vec![String::new(); n + 1];
    for c in 0..GANTT_COLUMNS {
        let t = (c as f64 + 0.5) / GANTT_COLUMNS as f64 * t_total;
        let mut supervised = Vec::new();
        for (i, row) in rows.iter_mut().take(n).enumerate() {
            row.push(match layout.running_conf(i, t) {
                None if layout.waiting(i, t) => 'h',
                None => ' ',
                Some(true) => '=',
                Some(false) => {
                    supervised.push(i);
                    '#'
                }
            });
        }
        rows[n].push(match supervised.as_slice() {
            [] => '.',
            [i] => char::from_digit(*i as u32 + 1, 36).unwrap_or('?'),
            _ => '!',
        });
    }
    let label_w = labels.iter().map(|l| l.chars().count()).max().unwrap_or(0);
    let pad = " ".repeat(width + 2);
    writeln!(out)?;
    writeln!(
        out,
        "{pad}0 s{:>w$}",
        format!("{t_total:.1} s"),
        w = GANTT_COLUMNS - 3
    )?;
    for (label, row) in labels.iter().zip(&rows[..n]) {
        writeln!(out, "{label:<w$}|{row}|", w = width + 1)?;
    }
    writeln!(out, "{:<w$}|{}|", "operator", rows[n], w = width + 1)?;
    writeln!(
        out,
        "{pad}= high confidence (unsupervised)   # low confidence (operator supervises)"
    )?;
    if holds {
        writeln!(
            out,
            "{pad}h waiting at a hold point (planned; at run time until its release rule holds)"
        )?;
    }
    let intervals = sorted_intervals(layout);
    writeln!(out)?;
    writeln!(
        out,
        "{} low-confidence intervals (global time; reference samples):",
        intervals.len()
    )?;
    for (robot, iv) in intervals.iter().take(SHOWN) {
        writeln!(
            out,
            "  {:<w$}  {:>9.2} – {:>9.2} s   ref {:>6} – {:>6}",
            labels[*robot],
            iv.start_s,
            iv.end_s,
            iv.ref_start,
            iv.ref_end,
            w = label_w
        )?;
    }
    if intervals.len() > SHOWN {
        writeln!(
            out,
            "  … {} more (tandem schedule --json lists all)",
            intervals.len() - SHOWN
        )?;
    }
    Ok(())
}

/// The chart ([`write_chart`]) of a cell of different tasks: one timeline per robot (global
/// time, each on its own task's reference samples) and its label (`robot 1 (sanding)`).
pub(crate) fn cell_chart(timelines: Vec<Timeline>, labels: &[String]) -> Result<String> {
    let mut out = String::new();
    write_chart(&mut out, &Layout::of_timelines(timelines), labels, false)?;
    Ok(out)
}

/// Every robot's low-confidence intervals of a cell's timelines, sorted by start (robot
/// 0-based; reference samples of the robot's own task; global s).
pub(crate) fn cell_intervals(timelines: Vec<Timeline>) -> Vec<(usize, LcInterval)> {
    sorted_intervals(&Layout::of_timelines(timelines))
}

/// Lines of a long list the text output shows (the JSON lists all).
const SHOWN: usize = 40;

/// The text Gantt chart of a one-task schedule: its certificate, the robots' starts and
/// durations, and [`write_chart`] (robots named `robot 1`…), followed by its holds.
pub(crate) fn gantt_text(problem: &Problem, outcome: &Outcome) -> Result<String> {
    let layout = Layout::new(problem, &outcome.schedule)?;
    let n = outcome.schedule.n_robots();
    let mut out = String::new();
    let dt = problem.dt_s();
    let d = outcome.schedule.durations_s(dt);
    writeln!(out, "{}", certificate_line(problem, outcome)?)?;
    let starts: Vec<String> = (1..n)
        .map(|i| {
            format!(
                "robot {} starts at τ = {:.2} s",
                i + 1,
                outcome.schedule.start_s(i)
            )
        })
        .collect();
    let runs: Vec<String> = d
        .iter()
        .enumerate()
        .map(|(i, d)| format!("robot {} runs {d:.2} s", i + 1))
        .collect();
    let starts = if starts.is_empty() {
        String::new()
    } else {
        starts.join(", ") + "; "
    };
    writeln!(
        out,
        "{starts}{}; schedule: {}",
        runs.join(", "),
        outcome_source_name(problem, outcome)
    )?;
    let labels: Vec<String> = (1..=n).map(|i| format!("robot {i}")).collect();
    write_chart(&mut out, &layout, &labels, outcome.schedule.has_holds())?;
    if outcome.schedule.has_holds() {
        let dt = problem.dt_s();
        writeln!(out)?;
        writeln!(
            out,
            "{} holds (global time; reference sample; the robot leaves once):",
            layout.dwells.len()
        )?;
        for d in layout.dwells.iter().take(SHOWN) {
            let after: Vec<String> = d
                .after
                .iter()
                .map(|a| format!("robot {} passed ref {}", a.robot + 1, a.ref_idx))
                .collect();
            writeln!(
                out,
                "  robot {}  {:>9.2} – {:>9.2} s   ref {:>6} ({:.2} s)   {}",
                d.robot + 1,
                d.start_s,
                d.end_s,
                d.ref_idx,
                d.ref_idx as f64 * dt,
                if after.is_empty() {
                    "the others reach their leg's start".to_string()
                } else {
                    after.join(", ")
                }
            )?;
        }
        if layout.dwells.len() > SHOWN {
            writeln!(out, "  … {} more", layout.dwells.len() - SHOWN)?;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {

    mod glossary {
        include!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/support/glossary.rs"
        ));
    }

    /// One of every schedule source. The match fails to compile when a source is added, until
    /// it is handled there (and then listed here, and explained in the glossary).
    fn every_source() -> Vec<Source> {
        let all = vec![
            Source::Sampled { candidate: 0 },
            Source::Completed,
            Source::Previous,
            Source::RepairedPrevious,
            Source::Serial,
            Source::Held,
            Source::Staggered,
        ];
        for s in &all {
            match s {
                Source::Sampled { .. }
                | Source::Completed
                | Source::Previous
                | Source::RepairedPrevious
                | Source::Serial
                | Source::Held
                | Source::Staggered => {}
            }
        }
        all
    }

    #[test]
    fn every_schedule_source_is_explained_in_the_glossary() {
        let glossary = glossary::glossary();
        for s in every_source() {
            // The phrase `schedule:` lines print, in bold, followed by the short name records
            // use (`Source::name`, the study's JSON and CSV, Python).
            let label = source_name(&s).replace("candidate 0", "candidate k");
            let entry = format!("**{label}** (`{}`)", s.name());
            assert!(
                glossary.contains(&entry),
                "docs/guide.md's glossary lacks `{entry}`"
            );
        }
        // A serial fallback is named by its form (`outcome_source_name`).
        for form in [SerialForm::Fastest, SerialForm::Slowed, SerialForm::Idling] {
            let entry = format!("**{}** (`serial`)", form.label());
            assert!(
                glossary.contains(&entry),
                "docs/guide.md's glossary lacks `{entry}`"
            );
        }
        assert_eq!(
            source_name(&Source::Serial),
            SerialForm::Fastest.label(),
            "the plain serial source reads as the fastest serial schedule"
        );
    }
    use super::*;

    #[test]
    fn a_gap_prints_signed_and_rounding_prints_as_zero() {
        assert_eq!(gap_text(0.0049), "+0.49 %");
        assert_eq!(gap_text(0.25), "+25.00 %");
        // The bound as computed can sit a rounding above T_total: zero, not "+-0.00 %".
        assert_eq!(gap_text(-5.7e-15), "+0.00 %");
        assert_eq!(gap_text(-tol::BOUND_REL), "+0.00 %");
        assert_eq!(gap_text(1e-12), "+0.00 %");
        // Beyond the rounding allowance a negative gap (a wrong bound) keeps its sign.
        assert_eq!(gap_text(-1e-3), "-0.10 %");
        assert_eq!(gap_text(-3.0 * tol::BOUND_REL), "-0.00 %");
    }
}
