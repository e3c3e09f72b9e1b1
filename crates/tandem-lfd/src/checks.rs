//! Plausibility rules for the data that enters a model: channels named like a time column,
//! and demonstrations whose length is an outlier of the set (docs/decisions.md, "Data is
//! checked where it enters"). The rules for executions (coverage of the task, duration,
//! sample period) are in `model/execution.rs`, next to the update they protect.

use crate::demo::Demonstration;
use crate::{Error, Result};

/// A demonstration shorter than `1 / LENGTH_REFUSE_RATIO` or longer than `LENGTH_REFUSE_RATIO`
/// times the median demonstration is refused ([`Error::DemonstrationLength`]): 2.
pub const LENGTH_REFUSE_RATIO: f64 = 2.0;

/// A demonstration shorter than `1 / LENGTH_WARN_RATIO` or longer than `LENGTH_WARN_RATIO`
/// times the median (but inside the refusal band) is warned about ([`length_warnings`]): 1.5.
pub const LENGTH_WARN_RATIO: f64 = 1.5;

/// A demonstration whose alignment to the reference ends with a run of the lower slope bound
/// (`WarpParams::slope_min`, within [`END_RUN_SLOPE_TOLERANCE`]) longer than this share of the
/// reference is refused as not reaching the end of the task
/// ([`Error::TruncatedDemonstration`]): 0.05 (docs/decisions.md, "A demonstration must reach
/// the end of the task").
pub const END_RUN_REFUSE_SHARE: f64 = 0.05;

/// Over the final run, the signal whose part is missing must move: some channel must vary by
/// more than this share of its range over the whole demonstration (a run over a stretch
/// where both signals rest, a final pause of independent length, is not a missing part):
/// 0.05, the run's own threshold ([`END_RUN_REFUSE_SHARE`]), so that on a task moving at an
/// even pace the two agree. A resting channel varies by its noise, far below it (the
/// alignment's flat stretches: 1 % of the range, `tandem_warp::FLAT_RANGE_FRACTION`).
pub const END_RUN_MOTION_SHARE: f64 = 0.05;

/// How close to a slope bound a warp's slope counts as "at the bound": within 5 % of it.
pub const END_RUN_SLOPE_TOLERANCE: f64 = 0.05;

/// Units a time column is given in, as a last name token (`t_ms`, `stamp.sec`).
const TIME_UNITS: [&str; 13] = [
    "s", "sec", "secs", "second", "seconds", "ms", "msec", "us", "usec", "ns", "nsec", "nsecs",
    "nanosec",
];

/// Whether a column name looks like a time column other than tandem's `t`: `time`, `stamp`,
/// `timestamp`, `elapsed` or a bare time unit (`seconds`, `ms`, …), alone or followed by a
/// unit (`t_ms`, `time_s`, `stamp.sec`), or ending in `stamp`/`timestamp` (`header.stamp`,
/// `ros_timestamp`). Case and the separators `_ . - /` and spaces are ignored. A time column
/// read as a channel is aligned and averaged like a force and grows without bound, so the
/// readers and the fit refuse it ([`Error::TimeLikeChannel`]).
pub fn time_like(name: &str) -> bool {
    let lower = name.to_lowercase();
    let tokens: Vec<&str> = lower
        .split(|c: char| !c.is_alphanumeric())
        .filter(|t| !t.is_empty())
        .collect();
    let Some(&last) = tokens.last() else {
        return false;
    };
    if tokens.len() == 1 && (TIME_UNITS.contains(&last) && last != "s" || last == "elapsed") {
        return true;
    }
    let with_unit = tokens.len() > 1 && TIME_UNITS.contains(&last);
    let base = if with_unit {
        &tokens[..tokens.len() - 1]
    } else {
        &tokens[..]
    };
    match base {
        [] => false,
        // `t` alone is tandem's time column (or, as `T`, a channel); `t_ms` is a time.
        ["t"] => with_unit,
        [one] => ["time", "times", "stamp", "timestamp", "elapsed"].contains(one),
        [.., end] => ["stamp", "timestamp"].contains(end),
    }
}

/// Durations `T_i − 1` (samples) of `demos` and their median.
fn lengths(demos: &[Demonstration]) -> (Vec<f64>, f64) {
    let lens: Vec<f64> = demos.iter().map(|d| (d.n_samples() - 1) as f64).collect();
    let mut sorted = lens.clone();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    let median = if n % 2 == 1 {
        sorted[n / 2]
    } else {
        0.5 * (sorted[n / 2 - 1] + sorted[n / 2])
    };
    (lens, median)
}

/// Refuses a demonstration whose length is outside `[1/2, 2]` times the median length of
/// `demos` ([`LENGTH_REFUSE_RATIO`]): a partial task, a recording that kept running, or a
/// long pause widen the model's speed bounds `[ψ̇min, ψ̇max]` (Eq. 14) and its variance
/// everywhere. Lengths are compared in samples (every demonstration of a fit has the same
/// period within 1 %). Called by [`crate::TaskModel::fit`] and `fit_aligned`.
///
/// # Errors
/// [`Error::DemonstrationLength`] for the first demonstration outside the band, naming it,
/// both durations and the fix.
pub fn check_lengths(demos: &[Demonstration]) -> Result<()> {
    if demos.len() < 2 {
        return Ok(());
    }
    let (lens, median) = lengths(demos);
    for (demo, &len) in demos.iter().zip(&lens) {
        let ratio = len / median;
        if !(1.0 / LENGTH_REFUSE_RATIO..=LENGTH_REFUSE_RATIO).contains(&ratio) {
            return Err(Error::DemonstrationLength {
                file: demo.source().into(),
                duration_s: len * demo.dt_s(),
                median_s: median * demo.dt_s(),
                ratio,
            });
        }
    }
    Ok(())
}

/// Length of the final run of `warp` (reference sample → demo sample, `n_ref` values ending at
/// `t_i − 1`) whose slope in normalized time (`ψ̇·(n_ref − 1)/(t_i − 1)`) is at a bound:
/// `at_min` for the lower bound `slope_min`, else the upper `slope_max`; as a share of the
/// reference's span `n_ref − 1`.
fn end_run_share(warp: &[f64], t_i: usize, slope: f64, at_min: bool) -> f64 {
    let n_ref = warp.len();
    if n_ref < 2 || t_i < 2 {
        return 0.0;
    }
    let scale = (n_ref - 1) as f64 / (t_i - 1) as f64;
    let run = warp
        .windows(2)
        .rev()
        .take_while(|w| {
            let s = (w[1] - w[0]) * scale;
            if at_min {
                s <= slope * (1.0 + END_RUN_SLOPE_TOLERANCE)
            } else {
                s >= slope / (1.0 + END_RUN_SLOPE_TOLERANCE)
            }
        })
        .count();
    run as f64 / (n_ref - 1) as f64
}

/// Whether some channel of `demo` varies over its samples `from..` by more than
/// [`END_RUN_MOTION_SHARE`] of its range over the whole demonstration.
fn moves_after(demo: &Demonstration, from: usize) -> bool {
    let m = demo.n_channels();
    let spread = |rows: &[f64], c: usize| {
        let (lo, hi) = rows
            .chunks_exact(m)
            .map(|r| r[c])
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
        hi - lo
    };
    let all = demo.samples();
    let tail = &all[from.min(demo.n_samples() - 1) * m..];
    (0..m).any(|c| {
        let range = spread(all, c);
        range > 0.0 && spread(tail, c) > END_RUN_MOTION_SHARE * range
    })
}

/// The reference sample from which motion over a final run of `run` (share of the reference)
/// counts: the run's start plus a tenth of its length, so that the last feature both signals
/// share, where the run begins, is not taken for motion inside it.
fn inner_start(n_ref: usize, run: f64) -> usize {
    let len = (run * (n_ref - 1) as f64).round() as usize;
    (n_ref - 1 - len + len / 10).min(n_ref - 1)
}

/// Refuses a demonstration that does not reach the end of the task, the check executions
/// get from their reference-time log (`TaskModel::update`), made on the alignment: a
/// demonstration cut off before the end is aligned to the reference with its last samples
/// spread over the rest of the task at the slowest slope the alignment allows
/// (`slope_min`, pinned at the end), so its warp ends with a long run at that bound; a
/// complete one, faster, slower or pausing, does not (the sanding fixtures: none; cut at
/// 55 %, 80 % and 90 %: 39 %, 17 % and 11 % of the task). A run over
/// [`END_RUN_REFUSE_SHARE`] of the reference over which the reference moves
/// ([`END_RUN_MOTION_SHARE`], after the run's first tenth, where the last shared feature
/// sits) is refused: where the reference rests over the run (both end at rest, for lengths
/// of their own) nothing is missing. When the reference itself is the
/// short one, every other demonstration's warp ends with a run at the upper bound
/// (`slope_max`: the rest of their task squeezed into its last sample) over which they
/// move; that is refused naming the reference. `demos` and `warps` are in model order, the reference first
/// (its warp is the identity and is not checked). Called by [`crate::TaskModel::fit`].
///
/// # Errors
/// [`Error::TruncatedDemonstration`] for the first demonstration (or the reference) that
/// stops short, naming it, where it ends on the reference and the fix.
pub(crate) fn check_reaches_end(
    demos: &[&Demonstration],
    warps: &[Vec<f64>],
    slope_min: f64,
    slope_max: f64,
) -> Result<()> {
    match reaches_end_failure(demos, warps, slope_min, slope_max) {
        Some((_, e)) => Err(e),
        None => Ok(()),
    }
}

/// [`check_reaches_end`]'s refusal with the position in `demos` of the demonstration it
/// refuses (0: the reference itself), or `None`.
pub(crate) fn reaches_end_failure(
    demos: &[&Demonstration],
    warps: &[Vec<f64>],
    slope_min: f64,
    slope_max: f64,
) -> Option<(usize, Error)> {
    let reference = demos[0].source();
    for (k, (demo, warp)) in demos.iter().zip(warps).enumerate().skip(1) {
        let run = end_run_share(warp, demo.n_samples(), slope_min, true);
        if run > END_RUN_REFUSE_SHARE && moves_after(demos[0], inner_start(warp.len(), run)) {
            return Some((
                k,
                Error::TruncatedDemonstration {
                    file: demo.source().into(),
                    ends_at_pct: 100.0 * (1.0 - run),
                    why: format!(
                        "aligned to the reference ({reference}), its last samples are spread over \
                     the last {:.0} % of the task at the slowest pace the alignment allows",
                        100.0 * run
                    ),
                },
            ));
        }
    }
    let others: Vec<f64> = demos
        .iter()
        .zip(warps)
        .skip(1)
        .map(|(demo, warp)| {
            let run = end_run_share(warp, demo.n_samples(), slope_max, false);
            // The other's samples squeezed into the run.
            let from = warp[inner_start(warp.len(), run)].floor().max(0.0) as usize;
            if moves_after(demo, from) { run } else { 0.0 }
        })
        .collect();
    let shortest = others.iter().copied().fold(f64::INFINITY, f64::min);
    if !others.is_empty() && shortest > END_RUN_REFUSE_SHARE {
        return Some((
            0,
            Error::TruncatedDemonstration {
                file: reference.into(),
                ends_at_pct: 100.0 * (1.0 - shortest),
                why: format!(
                    "it is the reference, and every other demonstration's alignment to it ends with \
                 at least the last {:.0} % of the task squeezed into its last sample (make \
                 another demonstration the reference if this one is kept: give it first, or \
                 `--reference medoid`)",
                    100.0 * shortest
                ),
            },
        ));
    }
    None
}

/// One sentence per demonstration whose length is outside `[2/3, 3/2]` times the median
/// ([`LENGTH_WARN_RATIO`]) but not refused by [`check_lengths`]: it may stop before the end
/// of the task or hold a pause. The command line prints them, the Python package raises them
/// as warnings; the fit itself does not need them.
pub fn length_warnings(demos: &[Demonstration]) -> Vec<String> {
    if demos.len() < 2 {
        return Vec::new();
    }
    let (lens, median) = lengths(demos);
    demos
        .iter()
        .zip(&lens)
        .filter_map(|(demo, &len)| {
            let ratio = len / median;
            let warn = !(1.0 / LENGTH_WARN_RATIO..=LENGTH_WARN_RATIO).contains(&ratio);
            let refused = !(1.0 / LENGTH_REFUSE_RATIO..=LENGTH_REFUSE_RATIO).contains(&ratio);
            (warn && !refused).then(|| {
                format!(
                    "{}: {:.2} s long, {ratio:.2}× the median demonstration ({:.2} s): if it stops \
                     before the end of the task or holds a pause, trim it or leave it out",
                    demo.source(),
                    len * demo.dt_s(),
                    median * demo.dt_s()
                )
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_like_names() {
        for name in [
            "time",
            "Time",
            "TIME_S",
            "timestamp",
            "stamp",
            "t_ms",
            "t_s",
            "t.us",
            "time_ms",
            "header.stamp",
            "header.stamp.sec",
            "field.header.stamp.nanosec",
            "ros_timestamp",
            "seconds",
            "elapsed",
            "elapsed_s",
            "ms",
        ] {
            assert!(time_like(name), "{name}");
        }
        for name in [
            "t",
            "T",
            "x",
            "force",
            "qx",
            "tool",
            "s",
            "stamping_force",
            "time_to_contact",
            "tx",
            "rate_s",
            "temperature",
        ] {
            assert!(!time_like(name), "{name}");
        }
    }

    fn demo(n: usize) -> Demonstration {
        Demonstration::new(vec!["a".into()], vec![0.0; n], 0.01)
            .unwrap()
            .with_source(format!("d{n}"))
    }

    /// A demonstration of `n` samples moving all along (a ramp), labelled `d<n>`.
    fn ramp(n: usize) -> Demonstration {
        Demonstration::new(vec!["a".into()], (0..n).map(|k| k as f64).collect(), 0.01)
            .unwrap()
            .with_source(format!("d{n}"))
    }

    /// A warp of `n_ref` values onto `t_i` samples: the identity pace up to share `cut` of
    /// the reference, then the rest at normalized slope `end_slope`.
    fn warp_with_end(n_ref: usize, t_i: usize, cut: f64, end_slope: f64) -> Vec<f64> {
        let scale = (t_i - 1) as f64 / (n_ref - 1) as f64;
        let knee = (cut * (n_ref - 1) as f64).round() as usize;
        let end_len = (n_ref - 1 - knee) as f64 * end_slope * scale;
        let head = (t_i - 1) as f64 - end_len;
        (0..n_ref)
            .map(|n| {
                if n <= knee {
                    head * n as f64 / knee as f64
                } else {
                    head + (n - knee) as f64 * end_slope * scale
                }
            })
            .collect()
    }

    #[test]
    fn a_warp_ending_at_the_slope_bound_is_a_demonstration_that_stops_short() {
        let (n_ref, t_i) = (201, 121);
        let d = ramp(t_i);
        let r = ramp(n_ref);
        let identity: Vec<f64> = (0..n_ref).map(|n| n as f64).collect();
        // Cut at 55 %: the last 45 % at s_min = 0.25 → run 0.45 > 0.05, ends at 55 %.
        let cut = warp_with_end(n_ref, t_i, 0.55, 0.25);
        assert!((end_run_share(&cut, t_i, 0.25, true) - 0.45).abs() < 1e-9);
        let err = check_reaches_end(&[&r, &d], &[identity.clone(), cut], 0.25, 4.0).unwrap_err();
        let Error::TruncatedDemonstration {
            ref file,
            ends_at_pct,
            ..
        } = err
        else {
            panic!("{err}");
        };
        assert_eq!(file, "d121");
        assert!((ends_at_pct - 55.0).abs() < 1e-9);
        let msg = err.to_string();
        for part in [
            "d121",
            "55 %",
            "d201",
            "last 45 %",
            "demonstrate the whole task",
        ] {
            assert!(msg.contains(part), "`{part}` missing: {msg}");
        }
        // A run of 5 % exactly is accepted, 6 % refused.
        let five = warp_with_end(n_ref, t_i, 0.95, 0.25);
        check_reaches_end(&[&r, &d], &[identity.clone(), five], 0.25, 4.0).unwrap();
        let six = warp_with_end(n_ref, t_i, 0.94, 0.25);
        assert!(check_reaches_end(&[&r, &d], &[identity.clone(), six], 0.25, 4.0).is_err());
        // A slow but not bound-pinned end (slope 0.3, 1.2× the bound) is accepted.
        let slow = warp_with_end(n_ref, t_i, 0.5, 0.3);
        check_reaches_end(&[&r, &d], &[identity.clone(), slow], 0.25, 4.0).unwrap();
        // Every other demonstration ending at s_max: the reference stops short.
        let fast = warp_with_end(n_ref, t_i, 0.9, 4.0);
        let err = check_reaches_end(
            &[&r, &d, &d],
            &[identity.clone(), fast.clone(), fast.clone()],
            0.25,
            4.0,
        )
        .unwrap_err();
        assert!(
            matches!(err, Error::TruncatedDemonstration { ref file, .. } if file == "d201"),
            "{err}"
        );
        assert!(err.to_string().contains("reference"), "{err}");
        // One of two at s_max is not enough to blame the reference.
        let plain = warp_with_end(n_ref, t_i, 0.5, 1.0);
        check_reaches_end(&[&r, &d, &d], &[identity.clone(), fast, plain], 0.25, 4.0).unwrap();
        // Where both rest over the run (the reference flat from 50 %: a final pause of a
        // length of its own), the run at the bound misses nothing: accepted.
        let resting = Demonstration::new(
            vec!["a".into()],
            (0..n_ref).map(|k| (k.min(100)) as f64).collect(),
            0.01,
        )
        .unwrap();
        let cut = warp_with_end(n_ref, t_i, 0.55, 0.25);
        check_reaches_end(&[&resting, &d], &[identity, cut], 0.25, 4.0).unwrap();
    }

    #[test]
    fn lengths_outside_half_to_twice_the_median_are_refused() {
        // Median length 100 samples (99 steps).
        let ok = [demo(100), demo(100), demo(100)];
        check_lengths(&ok).unwrap();
        assert!(length_warnings(&ok).is_empty());
        // 50 steps of 99: 0.505× — inside the refusal band, outside the warning band.
        let half = [demo(100), demo(51), demo(100)];
        check_lengths(&half).unwrap();
        let w = length_warnings(&half);
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(w[0].starts_with("d51: 0.50 s long, 0.51×"), "{}", w[0]);
        // 40 steps: 0.40× — refused, naming the file, both durations and the fix.
        let short = [demo(100), demo(41), demo(100)];
        let err = check_lengths(&short).unwrap_err();
        assert!(
            matches!(err, Error::DemonstrationLength { ref file, ratio, .. } if file == "d41" && (ratio - 40.0 / 99.0).abs() < 1e-12),
            "{err}"
        );
        let msg = err.to_string();
        for part in ["d41", "0.40 s", "0.99 s", "leave it out"] {
            assert!(msg.contains(part), "`{part}` missing: {msg}");
        }
        // Exactly twice the median is accepted; above it is refused.
        check_lengths(&[demo(100), demo(199), demo(100)]).unwrap();
        assert!(check_lengths(&[demo(100), demo(200), demo(100)]).is_err());
        // Two demonstrations: the median is their mean.
        check_lengths(&[demo(101), demo(301)]).unwrap();
        assert!(check_lengths(&[demo(101), demo(302)]).is_err());
    }
}
