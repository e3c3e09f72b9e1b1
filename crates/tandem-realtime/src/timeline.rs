//! One robot's plan in schedule-clock time (Eq. 15–16) and its rates (Eq. 17).
//!
//! [`clock_s`] is the one computation of the Eq. 15 clock: a [`Timeline`] stores its
//! breakpoints, and every duration, end and `T_total` of a schedule is read from it.

use crate::error::{Error, Result};
use crate::tol;

/// The Eq. 15 clock of one robot: the schedule-clock breakpoints `c_0, …, c_{T_ref}` (s,
/// global/schedule-clock frame) of execution gradients `grad_exec` (`ψ̇_E[n]`, execution
/// samples per reference sample) started at `start_s` (`τ_i`, s) with reference period
/// `dt_s` (`Δt_s`, s): `c_0 = τ_i`, `c_{n+1} = c_n + ψ̇_E[n]·Δt_s`, summed in this order.
///
/// This is the only place schedule-clock time is summed: [`Timeline`], the coordinator, the
/// margin check and the schedule's durations and `T_total` all read it, so they agree to
/// the last bit. `|ψ_E| = Σ_n ψ̇_E[n]·Δt_s` is the last breakpoint of the clock started at 0.
///
/// ```
/// let c: Vec<f64> = tandem_realtime::clock_s(&[1.0, 2.0, 0.5], 10.0, 0.5).collect();
/// assert_eq!(c, [10.0, 10.5, 11.5, 11.75]);
/// ```
pub fn clock_s(grad_exec: &[f64], start_s: f64, dt_s: f64) -> impl Iterator<Item = f64> + '_ {
    std::iter::once(start_s).chain(grad_exec.iter().scan(start_s, move |c, &e| {
        *c += e * dt_s;
        Some(*c)
    }))
}

/// The last breakpoint of [`clock_s`]: the schedule-clock time (s) at which a robot started
/// at `start_s` ends on schedule, `τ_i + |ψ_E|`. With `start_s = 0` it is the execution's
/// duration `|ψ_E|` (s).
#[must_use]
pub fn clock_end_s(grad_exec: &[f64], start_s: f64, dt_s: f64) -> f64 {
    clock_s(grad_exec, start_s, dt_s)
        .last()
        .expect("the clock yields at least its start")
}

/// A scheduled low-confidence interval of one robot (Eq. 19): the maximal low-confidence run
/// of reference samples `ref_start..ref_end` occupies schedule-clock (global) time
/// `[start_s, end_s)`, in seconds.
///
/// Which robot it belongs to is where it is stored (robot 0 first, robot 1 second).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LcInterval {
    /// First reference sample of the low-confidence run.
    pub ref_start: usize,
    /// One past the last reference sample of the run.
    pub ref_end: usize,
    /// Schedule-clock time (s) at which the robot enters the run.
    pub start_s: f64,
    /// Schedule-clock time (s) at which the robot leaves the run (end exclusive).
    pub end_s: f64,
}

impl LcInterval {
    /// Length of the intersection with `other` (s); zero or negative when they do not
    /// overlap (touching half-open intervals give 0).
    #[must_use]
    pub fn overlap_s(&self, other: &LcInterval) -> f64 {
        self.end_s.min(other.end_s) - self.start_s.max(other.start_s)
    }

    /// The same interval `by_s` seconds later.
    #[must_use]
    pub fn shifted(self, by_s: f64) -> LcInterval {
        LcInterval {
            start_s: self.start_s + by_s,
            end_s: self.end_s + by_s,
            ..self
        }
    }
}

/// One robot's plan in schedule-clock time (Eq. 15–16), built from its execution warp
/// (one gradient `ψ̇_E[n]` per reference sample) and its start offset `τ_i`.
///
/// Reference sample `n` occupies the schedule-clock interval `[c_n, c_{n+1})` (seconds,
/// global/schedule-clock frame) with `c_0 = τ_i` and `c_{n+1} = c_n + ψ̇_E[n]·Δt_s`, so the
/// robot ends at `τ_i + |ψ_E|` with `|ψ_E| = Σ_n ψ̇_E[n]·Δt_s`. Between breakpoints the
/// reference time (in reference samples) is linear in the schedule clock: this is the inverse
/// warp of Eq. 15. The breakpoints ([`clock_s`]), the low-confidence intervals and prefix
/// counts of the low-confidence samples are computed once here, so lookups by the
/// coordinator are O(1) amortized.
#[derive(Clone, Debug)]
pub struct Timeline {
    /// Eq. 12 per reference sample: `true` = high confidence.
    conf: Vec<bool>,
    /// ψ̇_E[n], execution samples per reference sample.
    grad_exec: Vec<f64>,
    /// ψ̇min[n] (Eq. 14).
    grad_min: Vec<f64>,
    /// ψ̇max[n] (Eq. 14).
    grad_max: Vec<f64>,
    /// Breakpoints `c_n`, `n ∈ 0..=T_ref` (schedule clock, s).
    clock_s: Vec<f64>,
    /// `lc_prefix[n]` = number of low-confidence samples among `0..n`.
    lc_prefix: Vec<usize>,
    /// Maximal low-confidence runs in schedule-clock time, in order.
    lc_intervals: Vec<LcInterval>,
    /// Reference sample period Δt_s (s).
    dt_s: f64,
}

impl Timeline {
    /// Builds a timeline.
    ///
    /// - `conf[n]`: high confidence at reference sample `n` (Eq. 12); `false` = low confidence (LC).
    /// - `grad_exec[n]`: scheduled execution gradient `ψ̇_E[n]` (execution samples per reference
    ///   sample, > 0).
    /// - `grad_min`, `grad_max`: `ψ̇min`, `ψ̇max` (Eq. 14) with `0 < ψ̇min ≤ ψ̇_E ≤ ψ̇max`
    ///   (up to [`tol::GRADIENT_REL`] of the bounds, for floating-point means).
    /// - `start_s`: `τ_i`, global time (s) at which the robot starts.
    /// - `dt_s`: reference sample period `Δt_s` (s), > 0.
    ///
    /// All slices have the same length `T_ref ≥ 1`.
    ///
    /// # Errors
    /// [`Error::EmptyTimeline`], [`Error::LengthMismatch`], [`Error::NonFinite`],
    /// [`Error::BadGradient`] or [`Error::BadParam`] (for `dt_s`) naming the offending input.
    pub fn new(
        conf: &[bool],
        grad_exec: &[f64],
        grad_min: &[f64],
        grad_max: &[f64],
        start_s: f64,
        dt_s: f64,
    ) -> Result<Timeline> {
        let n_ref = conf.len();
        if n_ref == 0 {
            return Err(Error::EmptyTimeline);
        }
        for (what, v) in [
            ("grad_exec", grad_exec),
            ("grad_min", grad_min),
            ("grad_max", grad_max),
        ] {
            if v.len() != n_ref {
                return Err(Error::LengthMismatch {
                    what,
                    expected: n_ref,
                    found: v.len(),
                });
            }
            if let Some(index) = v.iter().position(|x| !x.is_finite()) {
                return Err(Error::NonFinite { what, index });
            }
        }
        if !start_s.is_finite() {
            return Err(Error::NonFinite {
                what: "start_s",
                index: 0,
            });
        }
        if !(dt_s.is_finite() && dt_s > 0.0) {
            return Err(Error::BadParam {
                name: "dt_s",
                why: "must be finite and > 0",
            });
        }
        for n in 0..n_ref {
            let (e, lo, hi) = (grad_exec[n], grad_min[n], grad_max[n]);
            if lo <= 0.0 {
                return Err(Error::BadGradient {
                    index: n,
                    why: "grad_min must be > 0",
                });
            }
            if lo > hi {
                return Err(Error::BadGradient {
                    index: n,
                    why: "grad_min exceeds grad_max",
                });
            }
            if !tol::within_bounds(e, lo, hi) {
                return Err(Error::BadGradient {
                    index: n,
                    why: if e < lo {
                        "grad_exec below grad_min"
                    } else {
                        "grad_exec above grad_max"
                    },
                });
            }
        }
        let mut clock = Vec::with_capacity(n_ref + 1);
        clock.extend(clock_s(grad_exec, start_s, dt_s));
        if !clock[n_ref].is_finite() {
            return Err(Error::NonFinite {
                what: "end_s",
                index: n_ref,
            });
        }
        let mut lc_prefix = Vec::with_capacity(n_ref + 1);
        let mut count = 0;
        lc_prefix.push(0);
        for &hc in conf {
            count += usize::from(!hc);
            lc_prefix.push(count);
        }
        let lc_intervals = tandem_confidence::runs(conf)
            .into_iter()
            .filter(|r| !r.high_conf)
            .map(|r| LcInterval {
                ref_start: r.start,
                ref_end: r.end,
                start_s: clock[r.start],
                end_s: clock[r.end],
            })
            .collect();
        Ok(Timeline {
            conf: conf.to_vec(),
            grad_exec: grad_exec.to_vec(),
            grad_min: grad_min.to_vec(),
            grad_max: grad_max.to_vec(),
            clock_s: clock,
            lc_prefix,
            lc_intervals,
            dt_s,
        })
    }

    /// The plan of reference samples `from..to` (`from < to ≤ T_ref`) alone, started at
    /// `start_s` (s): the leg of a plan with holds (`crate::holds::legs`). Its reference
    /// samples are numbered from 0 (sample `from` of this plan is its sample 0). Started at
    /// this plan's `c_from` it has this plan's breakpoints `c_from..=c_to` bit for bit (the
    /// clock is summed in the same order).
    ///
    /// # Errors
    /// [`Error::BadParam`] for an empty or out-of-range `from..to`, [`Error::NonFinite`] for a
    /// start or end that is not finite.
    pub fn sub(&self, from: usize, to: usize, start_s: f64) -> Result<Timeline> {
        if !(from < to && to <= self.n_ref()) {
            return Err(Error::BadParam {
                name: "from..to",
                why: "must be a non-empty range of reference samples",
            });
        }
        Timeline::new(
            &self.conf[from..to],
            &self.grad_exec[from..to],
            &self.grad_min[from..to],
            &self.grad_max[from..to],
            start_s,
            self.dt_s,
        )
    }

    /// `τ_i`: global time (s) at which the robot starts.
    pub fn start_s(&self) -> f64 {
        self.clock_s[0]
    }

    /// `τ_i + |ψ_E|`: global time (s) at which the robot ends on schedule.
    pub fn end_s(&self) -> f64 {
        self.clock_s[self.clock_s.len() - 1]
    }

    /// `T_ref`: number of reference samples.
    pub fn n_ref(&self) -> usize {
        self.conf.len()
    }

    /// Reference sample period `Δt_s` (s).
    pub fn dt_s(&self) -> f64 {
        self.dt_s
    }

    /// Confidence per reference sample (Eq. 12): `true` = high confidence.
    pub fn conf(&self) -> &[bool] {
        &self.conf
    }

    /// Scheduled execution gradients `ψ̇_E[n]` (execution samples per reference sample).
    pub fn grad_exec(&self) -> &[f64] {
        &self.grad_exec
    }

    /// Minimum gradients `ψ̇min[n]` (Eq. 14).
    pub fn grad_min(&self) -> &[f64] {
        &self.grad_min
    }

    /// Maximum gradients `ψ̇max[n]` (Eq. 14).
    pub fn grad_max(&self) -> &[f64] {
        &self.grad_max
    }

    /// Schedule-clock breakpoints `c_n` (s), `n ∈ 0..=T_ref`: sample `n` is scheduled on
    /// `[c_n, c_{n+1})`.
    pub fn sample_clock_s(&self) -> &[f64] {
        &self.clock_s
    }

    /// Eq. 17, fast rate `F = ψ̇_E[n]/ψ̇min[n]`: how many seconds of schedule clock the robot can
    /// cover per second of real time at reference sample `n` when it goes as fast as the
    /// demonstrations allow (e.g. `ψ̇_E = 3`, `ψ̇min = 0.5` → `F = 6`).
    ///
    /// # Panics
    /// If `n ≥ T_ref`.
    pub fn rate_fast(&self, n: usize) -> f64 {
        self.grad_exec[n] / self.grad_min[n]
    }

    /// Eq. 17, slow rate `S = ψ̇_E[n]/ψ̇max[n]` (the paper prints the symbol `S` for both rates):
    /// schedule-clock seconds per real second when the robot goes as slowly as the
    /// demonstrations allow.
    ///
    /// # Panics
    /// If `n ≥ T_ref`.
    pub fn rate_slow(&self, n: usize) -> f64 {
        self.grad_exec[n] / self.grad_max[n]
    }

    /// Both rates of Eq. 17 at reference sample `n`.
    ///
    /// # Panics
    /// If `n ≥ T_ref`.
    pub fn rates(&self, n: usize) -> Rates {
        Rates {
            fast: self.rate_fast(n),
            slow: self.rate_slow(n),
        }
    }

    /// Reference sample scheduled at schedule-clock time `clock_s` (s): the largest `n` with
    /// `c_n ≤ clock_s`, clamped to `0..T_ref` (so times before the start map to 0 and times at
    /// or after the end to `T_ref − 1`).
    pub fn sample_at(&self, clock_s: f64) -> usize {
        let n_ref = self.n_ref();
        self.clock_s[1..n_ref].partition_point(|&c| c <= clock_s)
    }

    /// Eq. 15: fractional reference time (reference samples, in `[0, T_ref]`) scheduled at
    /// schedule-clock time `clock_s` (s). 0 before the start, `T_ref` at and after the end.
    pub fn ref_time_at(&self, clock_s: f64) -> f64 {
        self.ref_time_in(self.sample_at(clock_s), clock_s)
    }

    /// Eq. 16 for one robot: confidence at global time `t_s` (s) on schedule; `true` (high)
    /// when the robot is not running.
    pub fn conf_at(&self, t_s: f64) -> bool {
        if t_s < self.start_s() || t_s >= self.end_s() {
            return true;
        }
        self.conf[self.sample_at(t_s)]
    }

    /// Low-confidence intervals (Eq. 19): each maximal run of low-confidence reference samples
    /// `n0..n1` as the schedule-clock interval `[c_{n0}, c_{n1})` (s), in time order.
    pub fn lc_intervals(&self) -> &[LcInterval] {
        &self.lc_intervals
    }

    /// Whether any reference sample in `lo..=hi` is low confidence (O(1), prefix counts).
    pub(crate) fn any_low_conf(&self, lo: usize, hi: usize) -> bool {
        self.lc_prefix[hi + 1] > self.lc_prefix[lo]
    }

    /// Whether any reference sample in `lo..=hi` is high confidence (O(1), prefix counts).
    pub(crate) fn any_high_conf(&self, lo: usize, hi: usize) -> bool {
        self.lc_prefix[hi + 1] - self.lc_prefix[lo] < hi + 1 - lo
    }

    /// Advances a monotone cursor to `sample_at(clock_s)`; amortized O(1) when `clock_s` never
    /// decreases between calls with the same cursor.
    pub(crate) fn advance_cursor(&self, cursor: &mut usize, clock_s: f64) -> usize {
        let last = self.n_ref() - 1;
        while *cursor < last && self.clock_s[*cursor + 1] <= clock_s {
            *cursor += 1;
        }
        *cursor
    }

    /// Reference time at `clock_s` given the sample `n` that contains it.
    pub(crate) fn ref_time_in(&self, n: usize, clock_s: f64) -> f64 {
        if clock_s <= self.start_s() {
            return 0.0;
        }
        if clock_s >= self.end_s() {
            return self.n_ref() as f64;
        }
        let (c0, c1) = (self.clock_s[n], self.clock_s[n + 1]);
        let frac = ((clock_s - c0) / (c1 - c0)).clamp(0.0, 1.0);
        n as f64 + frac
    }

    /// Largest fast rate over all samples (at least 1, the nominal rate).
    pub(crate) fn max_rate_fast(&self) -> f64 {
        (0..self.n_ref())
            .map(|n| self.rate_fast(n))
            .fold(1.0, f64::max)
    }

    /// Largest slow rate `S` over all samples.
    pub(crate) fn max_rate_slow(&self) -> f64 {
        (0..self.n_ref())
            .map(|n| self.rate_slow(n))
            .fold(0.0, f64::max)
    }

    /// Smallest fast rate `F` over all samples.
    pub(crate) fn min_rate_fast(&self) -> f64 {
        (0..self.n_ref())
            .map(|n| self.rate_fast(n))
            .fold(f64::INFINITY, f64::min)
    }

    /// Smallest slow rate over all samples (at most 1).
    pub(crate) fn min_rate_slow(&self) -> f64 {
        (0..self.n_ref())
            .map(|n| self.rate_slow(n))
            .fold(1.0, f64::min)
    }

    /// An upper bound on the ticks of `tick_s` (s) a clock spends in `[from_s, to_s]`
    /// (schedule clock, s) if every tick moves it by at least `tick_s · S_n` for some sample `n`
    /// of this timeline within `pad_s` (s) of it: `Σ_n ((|I_n ∩ [from_s, to_s]| + 2·pad_s) /
    /// (tick_s·S_n) + 1)` over the samples whose interval `I_n = [c_n, c_{n+1})` (the last one
    /// open to the right) comes within `pad_s` of `[from_s, to_s]`. Unlike
    /// `(to_s − from_s)/(tick_s·S_min)` it charges a sample with a tiny `S` (a dwell in a
    /// demonstration, `ψ̇max ≫ ψ̇_E`) only for the clock time near that sample.
    pub(crate) fn slow_crossing_ticks(
        &self,
        from_s: f64,
        to_s: f64,
        pad_s: f64,
        tick_s: f64,
    ) -> f64 {
        let n_ref = self.n_ref();
        let mut ticks = 0.0;
        for n in 0..n_ref {
            let lo = self.clock_s[n];
            let hi = if n + 1 == n_ref {
                f64::INFINITY
            } else {
                self.clock_s[n + 1]
            };
            if hi < from_s - pad_s || lo > to_s + pad_s {
                continue;
            }
            let inside = (hi.min(to_s) - lo.max(from_s)).max(0.0);
            ticks += (inside + 2.0 * pad_s) / (tick_s * self.rate_slow(n)) + 1.0;
        }
        ticks
    }
}

/// The two rates of Eq. 17 at one reference sample: schedule-clock seconds covered per real
/// second when going as fast (`fast`, `F = ψ̇_E/ψ̇min ≥ 1`) or as slowly (`slow`,
/// `S = ψ̇_E/ψ̇max ≤ 1`) as the demonstrations allow.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rates {
    /// `F = ψ̇_E/ψ̇min` (dimensionless, schedule-clock s per real s).
    pub fast: f64,
    /// `S = ψ̇_E/ψ̇max` (dimensionless, schedule-clock s per real s).
    pub slow: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tl(conf: &[bool], exec: &[f64], lo: &[f64], hi: &[f64], start: f64) -> Timeline {
        Timeline::new(conf, exec, lo, hi, start, 0.5).unwrap()
    }

    #[test]
    fn eq17_example_of_section_ii_b5() {
        // ψ̇_E = 3, ψ̇min = 0.5 → F = 6; ψ̇max = 4 → S = 3/4.
        let t = tl(&[true], &[3.0], &[0.5], &[4.0], 0.0);
        assert_eq!(t.rate_fast(0), 6.0);
        assert_eq!(t.rate_slow(0), 0.75);
        assert_eq!(
            t.rates(0),
            Rates {
                fast: 6.0,
                slow: 0.75
            }
        );
    }

    #[test]
    fn breakpoints_end_and_ref_time() {
        // dt = 0.5: sample 0 lasts 1·0.5, sample 1 lasts 2·0.5, sample 2 lasts 0.5·0.5.
        let t = tl(
            &[true, false, true],
            &[1.0, 2.0, 0.5],
            &[0.5, 2.0, 0.5],
            &[2.0, 2.0, 1.0],
            10.0,
        );
        assert_eq!(t.sample_clock_s(), &[10.0, 10.5, 11.5, 11.75]);
        assert_eq!(t.end_s(), 11.75);
        assert_eq!(t.sample_at(9.0), 0);
        assert_eq!(t.sample_at(10.5), 1);
        assert_eq!(t.sample_at(11.0), 1);
        assert_eq!(t.sample_at(99.0), 2);
        assert_eq!(t.ref_time_at(9.0), 0.0);
        assert_eq!(t.ref_time_at(11.0), 1.5);
        assert_eq!(t.ref_time_at(11.625), 2.5);
        assert_eq!(t.ref_time_at(12.0), 3.0);
        assert!(t.conf_at(9.0) && !t.conf_at(11.0) && t.conf_at(11.6) && t.conf_at(11.75));
        assert_eq!(
            t.lc_intervals(),
            [LcInterval {
                ref_start: 1,
                ref_end: 2,
                start_s: 10.5,
                end_s: 11.5
            }]
        );
        assert_eq!(clock_end_s(&[1.0, 2.0, 0.5], 10.0, 0.5), t.end_s());
        assert_eq!(clock_end_s(&[1.0, 2.0, 0.5], 0.0, 0.5), 1.75);
        assert!(t.any_low_conf(0, 1) && !t.any_low_conf(2, 2));
        let mut cur = 0;
        assert_eq!(t.advance_cursor(&mut cur, 11.5), 2);
    }

    #[test]
    fn rejects_bad_input() {
        let ok = [1.0];
        assert_eq!(
            Timeline::new(&[], &[], &[], &[], 0.0, 1.0).unwrap_err(),
            Error::EmptyTimeline
        );
        assert!(matches!(
            Timeline::new(&[true, true], &ok, &ok, &ok, 0.0, 1.0),
            Err(Error::LengthMismatch {
                what: "grad_exec",
                ..
            })
        ));
        assert!(matches!(
            Timeline::new(&[true], &[f64::NAN], &ok, &ok, 0.0, 1.0),
            Err(Error::NonFinite {
                what: "grad_exec",
                index: 0
            })
        ));
        assert!(matches!(
            Timeline::new(&[true], &[3.0], &ok, &[2.0], 0.0, 1.0),
            Err(Error::BadGradient { index: 0, .. })
        ));
        assert!(matches!(
            Timeline::new(&[true], &[0.0], &[0.0], &ok, 0.0, 1.0),
            Err(Error::BadGradient { index: 0, .. })
        ));
        assert!(matches!(
            Timeline::new(&[true], &ok, &ok, &ok, 0.0, 0.0),
            Err(Error::BadParam { name: "dt_s", .. })
        ));
        assert!(matches!(
            Timeline::new(&[true], &ok, &ok, &ok, f64::INFINITY, 1.0),
            Err(Error::NonFinite {
                what: "start_s",
                ..
            })
        ));
        // A mean one ulp above identical bounds is accepted.
        let m = f64::from_bits(1.0_f64.to_bits() + 1);
        assert!(Timeline::new(&[false], &[m], &ok, &ok, 0.0, 1.0).is_ok());
    }
}
