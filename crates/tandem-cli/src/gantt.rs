//! The schedule as the user sees it: a text Gantt chart and a JSON document.

use std::fmt::Write as _;

use anyhow::Result;
use serde_json::{Value, json};
use tandem::realtime::tol;
use tandem::schedule::{GlobalTimeline, LcInterval, Outcome, Problem, Schedule, Source};

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

/// Every robot's low-confidence intervals with their robot index (0-based), sorted by start
/// (the lower robot first on a tie).
fn sorted_intervals(tl: &GlobalTimeline) -> Vec<(usize, LcInterval)> {
    let mut out: Vec<(usize, LcInterval)> = tl
        .lc_intervals()
        .iter()
        .enumerate()
        .flat_map(|(robot, ivs)| ivs.iter().map(move |iv| (robot, *iv)))
        .collect();
    out.sort_by(|a, b| a.1.start_s.total_cmp(&b.1.start_s));
    out
}

/// The schedule as JSON: robot count, offsets, per-robot gradients and durations,
/// low-confidence intervals in global time, `T_total` and its certificate (the margin-free lower bound, whether it is the proven
/// optimum, the gap) (all times in seconds of global time; gradients in execution samples per
/// reference sample). `schedule` is exactly `tandem::schedule::Schedule`'s serde form.
pub(crate) fn schedule_json(problem: &Problem, outcome: &Outcome) -> Result<Value> {
    let tl = GlobalTimeline::new(problem, &outcome.schedule)?;
    let dt = problem.dt_s();
    let intervals: Vec<Value> = sorted_intervals(&tl)
        .iter()
        .map(|(robot, iv)| {
            json!({
                "robot": robot + 1,
                "ref_start": iv.ref_start,
                "ref_end": iv.ref_end,
                "start_s": iv.start_s,
                "end_s": iv.end_s,
            })
        })
        .collect();
    let s = &outcome.schedule;
    Ok(json!({
        "t_total_s": outcome.t_total_s,
        "lower_bound_s": outcome.lower_bound_s,
        "bound_is_optimum": outcome.bound_is_optimum,
        "gap": outcome.gap,
        "serial_t_total_s": serial_t_total_s(problem, s.n_robots(), s.tick_s)?,
        "n_robots": s.n_robots(),
        "offset_s": s.offsets_s.first(),
        "offsets_s": s.offsets_s,
        "durations_s": s.durations_s(dt),
        "dt_s": dt,
        "tick_s": s.tick_s,
        "n_ref": problem.n_ref(),
        "source": source_name(&outcome.source),
        "lc_intervals": intervals,
        "schedule": serde_json::to_value(s)?,
    }))
}

/// The text Gantt chart: one bar per robot over `[0, T_total]` (`=` running high-confidence,
/// `#` running low-confidence, blank not running) and the operator's row (`1`…`8`: which
/// robot is supervised, `.` idle, `!` two or more), followed by the low-confidence intervals.
pub(crate) fn gantt_text(problem: &Problem, outcome: &Outcome) -> Result<String> {
    let tl = GlobalTimeline::new(problem, &outcome.schedule)?;
    let t_total = tl.t_total_s();
    let spans = tl.spans_s();
    let n = outcome.schedule.n_robots();
    let mut rows = vec![String::new(); n + 1];
    for c in 0..GANTT_COLUMNS {
        let t = (c as f64 + 0.5) / GANTT_COLUMNS as f64 * t_total;
        let conf = tl.conf_at(t);
        let mut supervised = Vec::new();
        for i in 0..n {
            let running = t >= spans[i].0 && t < spans[i].1;
            rows[i].push(match (running, conf[i]) {
                (false, _) => ' ',
                (true, true) => '=',
                (true, false) => {
                    supervised.push(i);
                    '#'
                }
            });
        }
        rows[n].push(match supervised.as_slice() {
            [] => '.',
            [i] => char::from_digit(*i as u32 + 1, 10).unwrap_or('?'),
            _ => '!',
        });
    }
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
        source_name(&outcome.source)
    )?;
    writeln!(out)?;
    writeln!(
        out,
        "          0 s{:>w$}",
        format!("{t_total:.1} s"),
        w = GANTT_COLUMNS - 3
    )?;
    for (i, row) in rows[..n].iter().enumerate() {
        writeln!(out, "robot {}  |{row}|", i + 1)?;
    }
    writeln!(out, "operator |{}|", rows[n])?;
    writeln!(
        out,
        "          = high confidence (unsupervised)   # low confidence (operator supervises)"
    )?;
    let intervals = sorted_intervals(&tl);
    writeln!(out)?;
    writeln!(
        out,
        "{} low-confidence intervals (global time; reference samples):",
        intervals.len()
    )?;
    const SHOWN: usize = 40;
    for (robot, iv) in intervals.iter().take(SHOWN) {
        writeln!(
            out,
            "  robot {}  {:>9.2} – {:>9.2} s   ref {:>6} – {:>6}",
            robot + 1,
            iv.start_s,
            iv.end_s,
            iv.ref_start,
            iv.ref_end
        )?;
    }
    if intervals.len() > SHOWN {
        writeln!(
            out,
            "  … {} more (tandem schedule --json lists all)",
            intervals.len() - SHOWN
        )?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
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
