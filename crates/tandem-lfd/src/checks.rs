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
