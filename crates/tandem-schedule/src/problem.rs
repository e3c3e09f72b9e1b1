//! The scheduling problem: confidence and warp-gradient bounds per reference sample (Eq. 12, 14).

use serde::{Deserialize, Serialize};
use tandem_confidence::Run;

use crate::schedule::Schedule;
use crate::{Error, Result};

/// The scheduling problem of Eq. 13–20 for two robots doing the same task.
///
/// Everything is indexed by reference sample `n ∈ 0..T_ref` (period `dt_s`). Gradients are
/// warp gradients `ψ̇` in execution samples per reference sample (2.0 = half speed):
/// `grad_mean` is the mean demonstration gradient `ψ̇̄_D` (followed on low-confidence samples,
/// Eq. 20 constraint 4), `grad_min`/`grad_max` are `ψ̇min`/`ψ̇max` (Eq. 14). Build it with
/// [`Problem::new`], which checks `0 < ψ̇min ≤ ψ̇̄ ≤ ψ̇max` everywhere.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ProblemData", into = "ProblemData")]
pub struct Problem {
    conf: Vec<bool>,
    grad_mean: Vec<f64>,
    grad_min: Vec<f64>,
    grad_max: Vec<f64>,
    dt_s: f64,
    runs: Vec<Run>,
    holds: Vec<usize>,
}

/// Serialized form of [`Problem`]; deserialization goes through [`Problem::new`].
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ProblemData {
    conf: Vec<bool>,
    grad_mean: Vec<f64>,
    grad_min: Vec<f64>,
    grad_max: Vec<f64>,
    dt_s: f64,
    /// Absent in problems written before hold points existed: no holds.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    holds: Vec<usize>,
}

impl TryFrom<ProblemData> for Problem {
    type Error = Error;
    fn try_from(d: ProblemData) -> Result<Self> {
        Problem::new(d.conf, d.grad_mean, d.grad_min, d.grad_max, d.dt_s)?.with_holds(d.holds)
    }
}

impl From<Problem> for ProblemData {
    fn from(p: Problem) -> Self {
        ProblemData {
            conf: p.conf,
            grad_mean: p.grad_mean,
            grad_min: p.grad_min,
            grad_max: p.grad_max,
            dt_s: p.dt_s,
            holds: p.holds,
        }
    }
}

impl Problem {
    /// Checks and builds a problem.
    ///
    /// - `conf[n]`: `true` = high confidence at reference sample `n` (Eq. 12).
    /// - `grad_mean[n]`, `grad_min[n]`, `grad_max[n]`: `ψ̇̄`, `ψ̇min`, `ψ̇max` (Eq. 14), execution
    ///   samples per reference sample; must be finite with `0 < ψ̇min ≤ ψ̇̄ ≤ ψ̇max`.
    /// - `dt_s`: reference sample period `Δt_s` (s), finite and > 0.
    ///
    /// All vectors must have the same length `T_ref ≥ 1`.
    ///
    /// # Errors
    /// [`Error::Empty`], [`Error::LengthMismatch`], [`Error::NonFinite`], [`Error::BadBounds`]
    /// (naming the first offending reference sample) or [`Error::BadParam`] for `dt_s`.
    pub fn new(
        conf: Vec<bool>,
        grad_mean: Vec<f64>,
        grad_min: Vec<f64>,
        grad_max: Vec<f64>,
        dt_s: f64,
    ) -> Result<Self> {
        if !(dt_s.is_finite() && dt_s > 0.0) {
            return Err(Error::BadParam {
                name: "dt_s",
                why: "must be finite and > 0",
            });
        }
        let n_ref = conf.len();
        if n_ref == 0 {
            return Err(Error::Empty);
        }
        for (name, v) in [
            ("grad_mean", &grad_mean),
            ("grad_min", &grad_min),
            ("grad_max", &grad_max),
        ] {
            if v.len() != n_ref {
                return Err(Error::LengthMismatch {
                    name,
                    len: v.len(),
                    expected: n_ref,
                });
            }
            if let Some(ref_idx) = v.iter().position(|x| !x.is_finite()) {
                return Err(Error::NonFinite { name, ref_idx });
            }
        }
        for ref_idx in 0..n_ref {
            let (min, mean, max) = (grad_min[ref_idx], grad_mean[ref_idx], grad_max[ref_idx]);
            if !(min > 0.0 && min <= mean && mean <= max) {
                return Err(Error::BadBounds {
                    ref_idx,
                    min,
                    mean,
                    max,
                });
            }
        }
        let runs = tandem_confidence::runs(&conf);
        Ok(Problem {
            conf,
            grad_mean,
            grad_min,
            grad_max,
            dt_s,
            runs,
            holds: Vec::new(),
        })
    }

    /// The same problem with hold points: reference samples `n` at which a robot may dwell
    /// for any time (its execution clock stopped at sample `n`) without harm, e.g. where the
    /// tool is lifted between passes (§II-C: "stop certain robots"). The task start is always
    /// one and is not listed: it is the start offset `τ_i`.
    ///
    /// `holds` must be strictly increasing reference-sample indices `< T_ref`. A hold on a
    /// low-confidence sample is kept but inactive while that sample is low-confidence: a
    /// robot that needs the operator is never stopped there. An empty list is the problem
    /// without holds, bit for bit.
    ///
    /// # Errors
    /// [`Error::BadHold`] naming the first hold out of range or out of order.
    pub fn with_holds(mut self, holds: Vec<usize>) -> Result<Self> {
        let n_ref = self.n_ref();
        for (i, &h) in holds.iter().enumerate() {
            if h >= n_ref {
                return Err(Error::BadHold {
                    ref_idx: h,
                    why: "is past the last reference sample",
                });
            }
            if i > 0 && holds[i - 1] >= h {
                return Err(Error::BadHold {
                    ref_idx: h,
                    why: "is not after the hold before it (holds must be strictly increasing)",
                });
            }
        }
        self.holds = holds;
        Ok(self)
    }

    /// Hold points (reference samples, strictly increasing, `< T_ref`; see
    /// [`Problem::with_holds`]); empty for a problem without holds.
    pub fn holds(&self) -> &[usize] {
        &self.holds
    }

    /// The hold points at which a robot may dwell now: those on high-confidence samples
    /// (reference samples, increasing).
    pub fn active_holds(&self) -> impl Iterator<Item = usize> + '_ {
        self.holds.iter().copied().filter(|&h| self.conf[h])
    }

    /// The active holds a schedule can use ([`Schedule::holds`]): those whose sample before is
    /// high-confidence too (`tandem_realtime::holds::usable_holds`), increasing.
    pub fn usable_holds(&self) -> Vec<usize> {
        tandem_realtime::holds::usable_holds(&self.conf, &self.holds)
    }

    /// `schedule` with release rules from its order of low-confidence stretches on the usable
    /// holds of this problem (`tandem_realtime::holds::release_rules`), keeping its own holds
    /// and dwells; unchanged when the problem has no usable hold or no pair of stretches gets
    /// a rule.
    ///
    /// # Errors
    /// As [`Schedule::timelines`].
    pub fn with_release_rules(&self, schedule: &Schedule) -> Result<Schedule> {
        let usable = self.usable_holds();
        if usable.is_empty() {
            return Ok(schedule.clone());
        }
        let robots = schedule.timelines(self)?;
        let holds = tandem_realtime::holds::release_rules(
            &robots,
            &schedule.holds,
            &vec![usable; schedule.n_robots()],
        );
        Ok(Schedule {
            holds,
            ..schedule.clone()
        })
    }

    /// Number of reference samples `T_ref` (≥ 1).
    pub fn n_ref(&self) -> usize {
        self.conf.len()
    }

    /// Confidence per reference sample: `true` = high (Eq. 12).
    pub fn conf(&self) -> &[bool] {
        &self.conf
    }

    /// Mean demonstration warp gradient `ψ̇̄` per reference sample.
    pub fn grad_mean(&self) -> &[f64] {
        &self.grad_mean
    }

    /// `ψ̇min` per reference sample (Eq. 14): the fastest permitted gradient.
    pub fn grad_min(&self) -> &[f64] {
        &self.grad_min
    }

    /// `ψ̇max` per reference sample (Eq. 14): the slowest permitted gradient.
    pub fn grad_max(&self) -> &[f64] {
        &self.grad_max
    }

    /// Reference sample period `Δt_s` (s).
    pub fn dt_s(&self) -> f64 {
        self.dt_s
    }

    /// Maximal runs of equal confidence ([`tandem_confidence::runs`]), in reference order,
    /// covering `0..T_ref`.
    pub fn runs(&self) -> &[Run] {
        &self.runs
    }

    /// The fastest admissible execution warp: `ψ̇min` on high-confidence samples, `ψ̇̄` on
    /// low-confidence ones (Eq. 20 constraints 1 and 4).
    pub fn fastest_warp(&self) -> Vec<f64> {
        (0..self.n_ref())
            .map(|n| {
                if self.conf[n] {
                    self.grad_min[n]
                } else {
                    self.grad_mean[n]
                }
            })
            .collect()
    }

    /// The fastest serial schedule of two robots (§II-C fallback) for control tick `tick_s`
    /// (real s): [`Problem::serial_schedule_n`] with `N = 2`. Its `T_total` is twice the
    /// fastest single execution.
    ///
    /// # Errors
    /// [`Error::BadParam`] for a `tick_s` that is not finite and > 0.
    pub fn serial_schedule(&self, tick_s: f64) -> Result<Schedule> {
        self.serial_schedule_n(2, tick_s)
    }

    /// The fastest serial schedule of `n_robots` robots for control tick `tick_s` (real s):
    /// every robot on [`Problem::fastest_warp`], robot `i + 1` starting when robot `i` ends
    /// (`τ_{i+1} = τ_i + |ψ_E|`). Its `T_total` is `N` times the fastest single execution. It
    /// satisfies every constraint of Eq. 20 at any tick: no low-confidence overlap is
    /// possible, since each robot starts only once the one before it has finished.
    ///
    /// # Errors
    /// [`Error::BadParam`] for a `tick_s` that is not finite and > 0; [`Error::Realtime`]
    /// (`RobotCount`) for `n_robots` not in `1..=MAX_ROBOTS`.
    pub fn serial_schedule_n(&self, n_robots: usize, tick_s: f64) -> Result<Schedule> {
        if !(tick_s.is_finite() && tick_s > 0.0) {
            return Err(Error::BadParam {
                name: "tick_s",
                why: "must be finite and > 0",
            });
        }
        check_robot_count(n_robots)?;
        let warp = self.fastest_warp();
        // Each start must not precede the previous robot's end on the clock the coordinator
        // and the margin check run (`clock_end_s`, summed sample by sample). It is the later
        // of that end and the closed form `τ + Σ ψ̇·Δt` of Eq. 13, which differ by rounding
        // only: a robot starts at the previous robot's end or a few ulps after it, never
        // before. (Taking the clock end alone moves robot 2's first tick in some serial
        // schedules and with it every later pair of the study; this keeps the study's
        // executions bit-identical to the closed form used before the clock had one owner.)
        let duration_s = warp.iter().sum::<f64>() * self.dt_s;
        let mut offsets_s = Vec::with_capacity(n_robots - 1);
        let mut start_s = 0.0;
        for _ in 1..n_robots {
            start_s =
                tandem_realtime::clock_end_s(&warp, start_s, self.dt_s).max(start_s + duration_s);
            offsets_s.push(start_s);
        }
        Ok(Schedule {
            grad_exec: vec![warp; n_robots],
            offsets_s,
            tick_s,
            holds: Vec::new(),
        })
    }
}

/// Checks a robot count `N` where it enters the crate: [`tandem_realtime::RobotCount::new`],
/// the one check and the one error of a robot count (`1 ≤ N ≤ MAX_ROBOTS`).
///
/// # Errors
/// [`Error::Realtime`] with `tandem_realtime::Error::RobotCount`.
pub(crate) fn check_robot_count(n_robots: usize) -> Result<()> {
    tandem_realtime::RobotCount::new(n_robots)?;
    Ok(())
}

/// Unit-test problem shared by this crate's modules: confidence `conf` (`true` = high), every
/// demonstrated gradient 1 within `[lo, hi]`, reference period `dt_s` (s).
#[cfg(test)]
pub(crate) fn unit_gradients(conf: Vec<bool>, (lo, hi): (f64, f64), dt_s: f64) -> Problem {
    let n = conf.len();
    Problem::new(conf, vec![1.0; n], vec![lo; n], vec![hi; n], dt_s).expect("valid by construction")
}

/// Unit-test problem shared by this crate's modules: `[HC, LC, LC, HC]`, gradients 1 within
/// `[0.5, 2]`, reference period `dt_s`.
#[cfg(test)]
pub(crate) fn hllh(dt_s: f64) -> Problem {
    unit_gradients(vec![true, false, false, true], (0.5, 2.0), dt_s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ok() -> Problem {
        hllh(0.01)
    }

    #[test]
    fn holds_are_checked_kept_through_serde_and_inactive_on_low_confidence() {
        // hllh: samples 0 and 3 high-confidence, 1 and 2 low.
        let p = ok().with_holds(vec![0, 2, 3]).unwrap();
        assert_eq!(p.holds(), &[0, 2, 3]);
        assert_eq!(p.active_holds().collect::<Vec<_>>(), vec![0, 3]);
        let back: Problem = serde_json::from_str(&serde_json::to_string(&p).unwrap()).unwrap();
        assert_eq!(back.holds(), &[0, 2, 3]);
        // Without holds the serialized form is the one written before holds existed.
        let json = serde_json::to_string(&ok()).unwrap();
        assert!(!json.contains("holds"), "{json}");
        assert!(matches!(
            ok().with_holds(vec![4]),
            Err(Error::BadHold { ref_idx: 4, .. })
        ));
        assert!(matches!(
            ok().with_holds(vec![2, 2]),
            Err(Error::BadHold { ref_idx: 2, .. })
        ));
    }

    #[test]
    fn runs_cover_the_reference() {
        let p = ok();
        assert_eq!(
            p.runs(),
            &[
                Run {
                    start: 0,
                    end: 1,
                    high_conf: true
                },
                Run {
                    start: 1,
                    end: 3,
                    high_conf: false
                },
                Run {
                    start: 3,
                    end: 4,
                    high_conf: true
                },
            ]
        );
    }

    #[test]
    fn serial_schedule_by_hand() {
        // HC at 0.5, LC at 1.0: |ψ_E| = (0.5 + 1 + 1 + 0.5)·0.01 = 0.03 s.
        let s = ok().serial_schedule(0.005).unwrap();
        assert_eq!(s.grad_exec[0], vec![0.5, 1.0, 1.0, 0.5]);
        assert_eq!(s.tick_s, 0.005);
        assert!((s.offsets_s[0] - 0.03).abs() < 1e-12);
        // Robot 2 starts where robot 1's clock ends (or an ulp later).
        assert!(s.offsets_s[0] >= s.ends_s(0.01)[0] && s.offsets_s[0] - s.ends_s(0.01)[0] < 1e-15);
        assert_eq!(s.t_total_s(0.01), s.ends_s(0.01)[1]);
        assert!((s.t_total_s(0.01) - 0.06).abs() < 1e-12);
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                ok().serial_schedule(bad),
                Err(Error::BadParam { name: "tick_s", .. })
            ));
        }
    }

    #[test]
    fn serial_schedule_of_n_robots_by_hand() {
        // Each robot takes 0.03 s and starts when the one before ends: T_total = N·0.03 s.
        for n in 1..=tandem_realtime::MAX_ROBOTS {
            let s = ok().serial_schedule_n(n, 0.01).unwrap();
            assert_eq!((s.n_robots(), s.offsets_s.len()), (n, n - 1));
            let ends = s.ends_s(0.01);
            for i in 1..n {
                assert!(s.start_s(i) >= ends[i - 1] && s.start_s(i) - ends[i - 1] < 1e-15);
            }
            assert!((s.t_total_s(0.01) - 0.03 * n as f64).abs() < 1e-12);
        }
        assert_eq!(
            ok().serial_schedule_n(2, 0.01).unwrap(),
            ok().serial_schedule(0.01).unwrap()
        );
        for bad in [0, tandem_realtime::MAX_ROBOTS + 1] {
            assert!(matches!(
                ok().serial_schedule_n(bad, 0.01),
                Err(Error::Realtime(tandem_realtime::Error::RobotCount { n, .. })) if n == bad
            ));
        }
    }

    #[test]
    fn rejects_bad_input() {
        let mk = |conf: Vec<bool>, mean: Vec<f64>, min: Vec<f64>, max: Vec<f64>, dt: f64| {
            Problem::new(conf, mean, min, max, dt)
        };
        assert!(matches!(
            mk(vec![], vec![], vec![], vec![], 0.01),
            Err(Error::Empty)
        ));
        assert!(matches!(
            mk(vec![true], vec![1.0], vec![1.0], vec![1.0], 0.0),
            Err(Error::BadParam { name: "dt_s", .. })
        ));
        assert!(matches!(
            mk(vec![true], vec![1.0, 1.0], vec![1.0], vec![1.0], 0.01),
            Err(Error::LengthMismatch {
                name: "grad_mean",
                len: 2,
                expected: 1
            })
        ));
        assert!(matches!(
            mk(
                vec![true; 2],
                vec![1.0; 2],
                vec![1.0, f64::NAN],
                vec![1.0; 2],
                0.01
            ),
            Err(Error::NonFinite {
                name: "grad_min",
                ref_idx: 1
            })
        ));
        assert!(matches!(
            mk(
                vec![true; 2],
                vec![1.0, 0.4],
                vec![0.5; 2],
                vec![2.0; 2],
                0.01
            ),
            Err(Error::BadBounds { ref_idx: 1, .. })
        ));
        assert!(matches!(
            mk(vec![true], vec![1.0], vec![0.0], vec![2.0], 0.01),
            Err(Error::BadBounds { ref_idx: 0, .. })
        ));
    }

    #[test]
    fn serde_goes_through_the_checks() {
        let p = ok();
        let json = serde_json::to_string(&p).unwrap();
        let back: Problem = serde_json::from_str(&json).unwrap();
        assert_eq!(back, p);
        let bad = json.replace("\"dt_s\":0.01", "\"dt_s\":-1.0");
        assert!(serde_json::from_str::<Problem>(&bad).is_err());
    }
}
