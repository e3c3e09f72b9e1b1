//! Executions recorded by the system and the incremental update with them (Eq. 21).

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::corrections::CorrectionCache;
use super::stats::{derive_at, observe_at, packed_len, welford_add};
use super::{PAR_MIN_LEN, TaskModel, check_dt};
use crate::demo::{DT_TOLERANCE, Demonstration};
use crate::resample::{self, Interpolation};
use crate::{Error, Result};

/// An execution recorded by the system (Eq. 21): its samples and, per sample, the
/// fractional reference time (reference samples) it executed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Execution {
    /// The executed samples (same channels as the model, any order; same `Δt_s` within 1 %).
    pub demonstration: Demonstration,
    /// Reference time of each sample, reference samples, monotone non-decreasing, inside
    /// `[0, T_ref − 1]`, one per sample.
    pub ref_time_log: Vec<f64>,
}

/// Execution samples per reference sample over the first step `[a, b]` of `steps` (pairs
/// of consecutive reference-time log entries) that moves; 1 if none does.
fn pace<'a>(mut steps: impl Iterator<Item = &'a [f64]>) -> f64 {
    steps
        .find(|w| w[1] > w[0])
        .map_or(1.0, |w| 1.0 / (w[1] - w[0]))
}

/// Reference samples of the first step of `steps` that moves; 0 if none does.
fn step<'a>(mut steps: impl Iterator<Item = &'a [f64]>) -> f64 {
    steps.find(|w| w[1] > w[0]).map_or(0.0, |w| w[1] - w[0])
}

/// An execution outside `[fastest / EXECUTION_DURATION_RATIO, EXECUTION_DURATION_RATIO ·
/// slowest]` of the demonstrated speeds is refused ([`Error::ExecutionDuration`]): 2.
pub const EXECUTION_DURATION_RATIO: f64 = 2.0;

/// An execution at the model's sample period ([`TaskModel::resample_execution`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Resampled {
    /// The execution, its samples `Δt_s` (the model's period) apart.
    pub execution: Execution,
    /// For every sample `k` of the original execution, the sample of `execution` whose
    /// period it falls in (`round(k·Δt_E/Δt_s)`): per-sample events are merged through it.
    pub bin_of: Vec<usize>,
    /// For every sample `j` of `execution`, the original sample nearest to it in time:
    /// per-sample states are read through it.
    pub nearest: Vec<usize>,
}

impl TaskModel {
    /// Adds one execution recorded by the system (Eq. 21) without re-alignment: its warp
    /// is the inverse of its reference-time log, its gradient per reference sample follows.
    /// Updates the per-reference-sample count, mean and scatter (Welford) and the gradient
    /// bounds in `O(n_ref · d²)`; the ranges, anchors and `k_max` stay as fitted; the
    /// correction directions are recomputed on next use.
    ///
    /// # Errors
    /// The model is unchanged on error: different channel set or sample period (resample it
    /// first: [`TaskModel::resample_execution`]), log length ≠ sample count, non-finite,
    /// decreasing or outside `[0, n_ref − 1]` log, a log that does not cover the whole task
    /// ([`Error::TruncatedExecution`]), a duration outside half the fastest to twice the
    /// slowest admissible execution ([`Error::ExecutionDuration`]), zero quaternion.
    pub fn update(&mut self, execution: &Execution) -> Result<()> {
        let warp = self.execution_warp(execution)?;
        let demo = execution
            .demonstration
            .conform_to(&self.data.channel_names)?;
        let inv_w = self.inverse_weights();
        let data = &mut self.data;
        let d = data.layout.dim();
        let pl = packed_len(d);
        let (layout, anchors, count) = (&data.layout, &data.anchors, data.count);
        let (m, n_quat) = (data.channel_names.len(), layout.n_quat);
        let denom = count as f64; // (count + 1) − 1
        data.tangent_mean
            .par_chunks_mut(d)
            .zip(data.scatter.par_chunks_mut(pl))
            .zip(
                data.grad_min
                    .par_iter_mut()
                    .zip(data.grad_max.par_iter_mut()),
            )
            .zip(
                self.mean.par_chunks_mut(m).zip(
                    self.grad_mean
                        .par_iter_mut()
                        .zip(self.sigma2_d.par_iter_mut()),
                ),
            )
            .enumerate()
            .with_min_len(PAR_MIN_LEN)
            .for_each_init(
                || (vec![0.0; d], vec![0.0; d]),
                |(x, delta), (n, (((mean_n, scatter_n), (gmin, gmax)), (out, (g, s2))))| {
                    let anchors_n = &anchors[n * n_quat..(n + 1) * n_quat];
                    observe_at(layout, anchors_n, &demo, &warp, n, x);
                    welford_add(x, count, mean_n, scatter_n, delta);
                    *gmin = gmin.min(x[d - 1]);
                    *gmax = gmax.max(x[d - 1]);
                    (*g, *s2) = derive_at(layout, anchors_n, &inv_w, denom, mean_n, scatter_n, out);
                },
            );
        if let super::RateTerm::Relative { window, .. } = data.rate_term
            && window > 0
        {
            // The Welford step of the window durations, as for the tangent statistics.
            let durations = super::stats::window_durations(&warp, window);
            let new_count = count as f64 + 1.0;
            for ((mean, scatter), x) in data
                .duration_mean
                .iter_mut()
                .zip(data.duration_scatter.iter_mut())
                .zip(durations)
            {
                let delta = x - *mean;
                *mean += delta / new_count;
                *scatter += delta * delta * (count as f64 / new_count);
            }
        }
        data.count += 1;
        self.add_rate_terms();
        self.corrections = CorrectionCache::new(self.data.n_ref);
        Ok(())
    }

    /// The warp (reference → execution samples) of an execution: the inverse of its
    /// reference-time log, `ψ_E(n) = min{q : log(q) ≥ n}` with linear interpolation of the
    /// log between samples. Reference samples before the log's first entry or after its
    /// last are extrapolated at the execution's first or last pace (execution samples per
    /// reference sample, from the nearest pair of distinct log entries; 1 if there is
    /// none), so the warp gradient stays that of the execution at both ends — an execution
    /// ends once its last step passes `T_ref − 1`, so its log may stop a step short of it.
    /// The warp may thus leave `[0, T_E − 1]` by less than a step at either end.
    ///
    /// # Errors
    /// As [`TaskModel::update`] (this validates the execution).
    pub fn execution_warp(&self, execution: &Execution) -> Result<Vec<f64>> {
        let demo = &execution.demonstration;
        let log = &execution.ref_time_log;
        demo.conform_to(&self.data.channel_names)?;
        check_dt(demo, self.data.dt_s, &|| "the model".into())?;
        self.data.layout.check_quaternion_norms(demo)?;
        let bad = |why: String| Error::BadLog {
            file: demo.source().into(),
            why,
        };
        if log.len() != demo.n_samples() {
            return Err(bad(format!(
                "{} entries for {} samples",
                log.len(),
                demo.n_samples()
            )));
        }
        let last_ref = (self.data.n_ref - 1) as f64;
        for (k, &v) in log.iter().enumerate() {
            if !v.is_finite() || !(0.0..=last_ref).contains(&v) {
                return Err(bad(format!("entry {k} = {v} is outside [0, {last_ref}]")));
            }
            if k > 0 && v < log[k - 1] {
                return Err(bad(format!(
                    "entry {k} = {v} decreases from {}",
                    log[k - 1]
                )));
            }
        }
        self.check_coverage(demo.source(), log)?;
        self.check_duration(demo)?;
        let t_e = log.len();
        // Execution samples per reference sample over the first and last distinct steps.
        let first_pace = pace(log.windows(2));
        let last_pace = pace(log.windows(2).rev());
        let mut warp = Vec::with_capacity(self.data.n_ref);
        let mut k = 0;
        for n in 0..self.data.n_ref {
            let nf = n as f64;
            let exec_t = if nf <= log[0] {
                -(log[0] - nf) * first_pace
            } else if nf > log[t_e - 1] {
                (t_e - 1) as f64 + (nf - log[t_e - 1]) * last_pace
            } else {
                while log[k + 1] < nf {
                    k += 1;
                }
                k as f64 + (nf - log[k]) / (log[k + 1] - log[k])
            };
            warp.push(exec_t);
        }
        Ok(warp)
    }
}

impl TaskModel {
    /// Refuses a log that does not cover the task: it must start within one step of the
    /// first reference sample (`log[0] < max(1, first step)`) and end within one step of
    /// the last (`T_ref − 1 − log[last] ≤ max(1, last step)`), a step being the log's first
    /// or last move in reference samples. An execution ends once its last step passes
    /// `T_ref − 1` (the coordinator's clock), so its log may stop up to one step short.
    fn check_coverage(&self, file: &str, log: &[f64]) -> Result<()> {
        let last_ref = (self.data.n_ref - 1) as f64;
        let (first, last) = (log[0], log[log.len() - 1]);
        let start_gap = step(log.windows(2)).max(1.0);
        let end_gap = step(log.windows(2).rev()).max(1.0);
        let bad = |why: String| Error::TruncatedExecution {
            file: file.into(),
            why,
        };
        // Reference samples in messages to a thousandth (`within 1.206`, not
        // `1.205509816341646`).
        let r = |v: f64| (v * 1e3).round() / 1e3;
        if first >= start_gap {
            return Err(bad(format!(
                "starts at reference sample {} (expected below {}, one step from the \
                 beginning)",
                r(first),
                r(start_gap)
            )));
        }
        if last_ref - last > end_gap {
            return Err(bad(format!(
                "ends at reference sample {} (expected within {} of the end of the task, \
                 reference sample {last_ref})",
                r(last),
                r(end_gap)
            )));
        }
        Ok(())
    }

    /// Refuses an execution whose duration `T_E·Δt_E` is below half the fastest or
    /// above twice the slowest admissible execution (`Σ_n ψ̇min/max(n)·Δt_s`, Eq. 14): the
    /// coordinator keeps every robot inside those speeds, so such a log was most likely
    /// taken at another rate than the one assumed for it ([`EXECUTION_DURATION_RATIO`]).
    fn check_duration(&self, demo: &Demonstration) -> Result<()> {
        let dt = self.data.dt_s;
        let fastest_s = self.data.grad_min.iter().sum::<f64>() * dt;
        let slowest_s = self.data.grad_max.iter().sum::<f64>() * dt;
        let duration_s = demo.n_samples() as f64 * demo.dt_s();
        if duration_s < fastest_s / EXECUTION_DURATION_RATIO
            || duration_s > slowest_s * EXECUTION_DURATION_RATIO
        {
            return Err(Error::ExecutionDuration {
                file: demo.source().into(),
                duration_s,
                n_samples: demo.n_samples(),
                dt_s: crate::demo::round_s(demo.dt_s()),
                fastest_s,
                slowest_s,
            });
        }
        Ok(())
    }

    /// `execution` at the model's sample period `Δt_s`: unchanged (up to the channel order)
    /// when its period is within 1 % of `Δt_s`; otherwise, for a finer log (a control loop
    /// faster than the demonstrations), sample `j` is the execution at time `j·Δt_s`
    /// (clamped to its last sample, which is kept): scalar channels and the reference-time
    /// log interpolated linearly, quaternion blocks by slerp, 0/1 channels held (the one
    /// resampling policy, [`crate::resample`]). [`Resampled::bin_of`] maps
    /// every original sample to the new sample nearest in time, for per-sample flags.
    ///
    /// # Errors
    /// [`Error::CoarseExecution`] for a period more than 1 % above `Δt_s` (resampling
    /// would invent samples), and the channel errors of [`TaskModel::update`].
    pub fn resample_execution(&self, execution: &Execution) -> Result<Resampled> {
        let demo = execution
            .demonstration
            .conform_to(&self.data.channel_names)?;
        let (dt_e, dt_m) = (demo.dt_s(), self.data.dt_s);
        let t_e = demo.n_samples();
        if (dt_e - dt_m).abs() <= DT_TOLERANCE * dt_m {
            return Ok(Resampled {
                execution: Execution {
                    demonstration: demo.into_owned(),
                    ref_time_log: execution.ref_time_log.clone(),
                },
                bin_of: (0..t_e).collect(),
                nearest: (0..t_e).collect(),
            });
        }
        if dt_e > dt_m {
            return Err(Error::CoarseExecution {
                file: demo.source().into(),
                found_s: crate::demo::round_s(dt_e),
                model_s: crate::demo::round_s(dt_m),
            });
        }
        let log = &execution.ref_time_log;
        if log.len() != t_e {
            return Err(Error::BadLog {
                file: demo.source().into(),
                why: format!("{} entries for {t_e} samples", log.len()),
            });
        }
        // Original samples per new sample (> 1).
        let ratio = dt_m / dt_e;
        let last = (t_e - 1) as f64;
        let n_new = (last / ratio - 1e-9).ceil().max(1.0) as usize + 1;
        let m = demo.n_channels();
        // The one resampling policy (`crate::resample`): the model's quaternion blocks by
        // slerp, 0/1 channels held, the rest linear.
        let quats: Vec<[usize; 4]> = self
            .data
            .layout
            .items
            .iter()
            .filter_map(|item| match item {
                super::layout::Item::Quat(cols, _) => Some(*cols),
                super::layout::Item::Scalar(_) => None,
            })
            .collect();
        let flags: Vec<usize> = (0..m)
            .filter(|&c| {
                !quats.iter().flatten().any(|&d| d == c)
                    && resample::is_flag((0..t_e).map(|k| demo.sample(k)[c]))
            })
            .collect();
        let policy = Interpolation::new(m, &flags, &quats)?;
        let mut samples = vec![0.0; n_new * m];
        let mut new_log = Vec::with_capacity(n_new);
        for j in 0..n_new {
            let pos = (j as f64 * ratio).min(last);
            let lo = (pos.floor() as usize).min(t_e - 1);
            let hi = (lo + 1).min(t_e - 1);
            let alpha = pos - lo as f64;
            let (a, b) = (demo.sample(lo), demo.sample(hi));
            policy.row(a, b, alpha, &mut samples[j * m..(j + 1) * m]);
            new_log.push(log[lo] + alpha * (log[hi] - log[lo]));
        }
        let bin_of = (0..t_e)
            .map(|k| ((k as f64 / ratio).round() as usize).min(n_new - 1))
            .collect();
        let nearest = (0..n_new)
            .map(|j| ((j as f64 * ratio).round() as usize).min(t_e - 1))
            .collect();
        let demonstration = Demonstration::new(self.data.channel_names.clone(), samples, dt_m)?
            .with_source(demo.source());
        Ok(Resampled {
            execution: Execution {
                demonstration,
                ref_time_log: new_log,
            },
            bin_of,
            nearest,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{demo, three_demo_model};
    use super::*;

    #[test]
    fn execution_warp_inverts_the_log() {
        let model = three_demo_model();
        // 5 samples at half speed: ref times 0, 0.5, …, 2 → warp 0, 2, 4.
        let exec = Execution {
            demonstration: demo(&["force"], vec![0.0, 5.0, 10.0, 15.0, 20.0]),
            ref_time_log: vec![0.0, 0.5, 1.0, 1.5, 2.0],
        };
        assert_eq!(model.execution_warp(&exec).unwrap(), [0.0, 2.0, 4.0]);
        // A pause (flat log) maps to its first sample; a late start is extrapolated at the
        // first pace (2 samples per reference sample): 0.5 reference samples early → −1.
        let exec = Execution {
            demonstration: demo(&["force"], vec![0.0; 5]),
            ref_time_log: vec![0.5, 1.0, 1.0, 1.0, 2.0],
        };
        assert_eq!(model.execution_warp(&exec).unwrap(), [-1.0, 1.0, 4.0]);
        // A log that stops short of the last reference sample (its last step went past it)
        // is extrapolated from its last sample (4) at the last moving pace (2 samples per
        // reference sample): 4 + 0.5·2 = 5, so the gradient there is 3, not 0.
        let exec = Execution {
            demonstration: demo(&["force"], vec![0.0; 5]),
            ref_time_log: vec![0.0, 0.5, 1.0, 1.5, 1.5],
        };
        assert_eq!(model.execution_warp(&exec).unwrap(), [0.0, 2.0, 5.0]);
    }

    /// Two 21-sample demonstrations of `force` at 10 ms, identity warps: every speed bound is
    /// 1 sample per reference sample, so every admissible execution takes 0.2 s.
    fn model21() -> TaskModel {
        let d = |f: f64| demo(&["force"], (0..21).map(|k| f + k as f64).collect());
        let id: Vec<f64> = (0..21).map(f64::from).collect();
        TaskModel::fit_aligned(&[d(0.0), d(2.0)], &[id.clone(), id], &Default::default()).unwrap()
    }

    /// `n` samples of `force = 3·ref_time` at period `dt_s` whose log runs from `first` to
    /// `last` evenly.
    fn run(n: usize, dt_s: f64, first: f64, last: f64) -> Execution {
        let log: Vec<f64> = (0..n)
            .map(|k| first + (last - first) * k as f64 / (n - 1) as f64)
            .collect();
        Execution {
            demonstration: Demonstration::new(
                vec!["force".into()],
                log.iter().map(|r| 3.0 * r).collect(),
                dt_s,
            )
            .unwrap()
            .with_source("run.csv"),
            ref_time_log: log,
        }
    }

    #[test]
    fn an_execution_must_cover_the_whole_task() {
        let model = model21();
        model.execution_warp(&run(21, 0.01, 0.0, 20.0)).unwrap();
        // Within one step of either end (the last step passed the end) is complete.
        model.execution_warp(&run(21, 0.01, 0.0, 19.0)).unwrap();
        model.execution_warp(&run(21, 0.01, 0.5, 20.0)).unwrap();
        for (exec, part) in [
            (run(16, 0.01, 5.0, 20.0), "starts at reference sample 5"),
            (run(11, 0.01, 0.0, 10.0), "ends at reference sample 10"),
            // A step of 12/7 reference samples is printed to a thousandth.
            (
                run(8, 0.01, 0.0, 12.0),
                "ends at reference sample 12 (expected within 1.714 of the end",
            ),
        ] {
            let err = model.execution_warp(&exec).unwrap_err();
            assert!(matches!(err, Error::TruncatedExecution { .. }), "{err}");
            let msg = err.to_string();
            assert!(msg.contains(part) && msg.contains("run.csv"), "{msg}");
            assert!(msg.contains("whole task"), "{msg}");
        }
        // The update refuses it too and leaves the model.
        let mut m = model.clone();
        assert!(m.update(&run(11, 0.01, 0.0, 10.0)).is_err());
        assert_eq!(m.count(), 2);
    }

    #[test]
    fn an_execution_logged_at_another_rate_is_refused_or_resampled() {
        let model = model21();
        // 0.2 s logged at 1 kHz: 201 samples. Taken for 10 ms samples it would last 2.01 s,
        // ten times the only admissible duration (21 samples × 10 ms): refused, naming the fix.
        let fast = run(201, 0.01, 0.0, 20.0);
        let err = model.execution_warp(&fast).unwrap_err();
        assert!(matches!(err, Error::ExecutionDuration { .. }), "{err}");
        let msg = err.to_string();
        for part in [
            "2.01 s long",
            "201 samples",
            "0.21 to 0.21 s",
            "column `t`",
            "dt_s=",
        ] {
            assert!(msg.contains(part), "`{part}` missing: {msg}");
        }
        // With its period stated it is resampled to the model's: 21 samples at 10 ms, the
        // values (linear in time) and the log exactly those of a 10 ms log.
        let at_1khz = run(201, 0.001, 0.0, 20.0);
        let r = model.resample_execution(&at_1khz).unwrap();
        let want = run(21, 0.01, 0.0, 20.0);
        assert_eq!(r.execution.demonstration.dt_s(), 0.01);
        assert_eq!(r.execution.demonstration.n_samples(), 21);
        for (a, b) in r.execution.ref_time_log.iter().zip(&want.ref_time_log) {
            assert!((a - b).abs() < 1e-9, "{a} vs {b}");
        }
        for (a, b) in r
            .execution
            .demonstration
            .samples()
            .iter()
            .zip(want.demonstration.samples())
        {
            assert!((a - b).abs() < 1e-9, "{a} vs {b}");
        }
        // Original samples 0..4 fall in new sample 0, 5..14 in 1, …, 195..200 in 20.
        assert_eq!(&r.bin_of[..6], &[0, 0, 0, 0, 0, 1]);
        assert_eq!(r.bin_of[14], 1);
        assert_eq!(r.bin_of[15], 2);
        assert_eq!(r.bin_of[200], 20);
        assert_eq!(r.nearest, (0..21).map(|j| 10 * j).collect::<Vec<_>>());
        let mut m = model.clone();
        m.update(&r.execution).unwrap();
        assert_eq!(m.count(), 3);
        // A period that does not divide the model's: the last sample is kept.
        let odd = model
            .resample_execution(&run(61, 0.003, 0.0, 20.0))
            .unwrap();
        assert_eq!(odd.execution.demonstration.n_samples(), 19);
        assert_eq!(odd.execution.ref_time_log.last(), Some(&20.0));
        model.execution_warp(&odd.execution).unwrap();
        // At the model's period (within 1 %) nothing changes.
        let same = model.resample_execution(&want).unwrap();
        assert_eq!(same.execution, want);
        assert_eq!(same.bin_of, (0..21).collect::<Vec<_>>());
        // A coarser log would need invented samples: refused.
        let err = model
            .resample_execution(&run(11, 0.02, 0.0, 20.0))
            .unwrap_err();
        assert!(matches!(err, Error::CoarseExecution { .. }), "{err}");
        assert!(err.to_string().contains("0.02 s is coarser"), "{err}");
    }

    #[test]
    fn resampled_quaternions_stay_unit() {
        let q = |angle: f64| {
            let (s, c) = (0.5 * angle).sin_cos();
            [0.0, 0.0, s, c]
        };
        let names: Vec<String> = ["qx", "qy", "qz", "qw"].map(String::from).to_vec();
        let d = |scale: f64| {
            let s = (0..21).flat_map(|k| q(scale * k as f64 * 0.05)).collect();
            Demonstration::new(names.clone(), s, 0.01).unwrap()
        };
        let id: Vec<f64> = (0..21).map(f64::from).collect();
        let model =
            TaskModel::fit_aligned(&[d(1.0), d(1.2)], &[id.clone(), id], &Default::default())
                .unwrap();
        let n = 81;
        let exec = Execution {
            demonstration: Demonstration::new(
                names.clone(),
                (0..n).flat_map(|k| q(k as f64 * 0.0125)).collect(),
                0.0025,
            )
            .unwrap(),
            ref_time_log: (0..n).map(|k| k as f64 * 0.25).collect(),
        };
        let r = model.resample_execution(&exec).unwrap();
        assert_eq!(r.execution.demonstration.n_samples(), 21);
        for j in 0..21 {
            let s = r.execution.demonstration.sample(j);
            let norm = s.iter().map(|v| v * v).sum::<f64>().sqrt();
            assert!((norm - 1.0).abs() < 1e-12, "sample {j}: norm {norm}");
            let want = q(j as f64 * 0.05);
            assert!((s[2] - want[2]).abs() < 1e-12 && (s[3] - want[3]).abs() < 1e-12);
        }
    }

    #[test]
    fn bad_executions_are_errors_and_leave_the_model() {
        let mut model = three_demo_model();
        let exec = Execution {
            demonstration: demo(&["force"], vec![0.0; 3]),
            ref_time_log: vec![0.0, 2.0, 1.0],
        };
        assert!(matches!(model.update(&exec), Err(Error::BadLog { .. })));
        let exec = Execution {
            demonstration: demo(&["force"], vec![0.0; 3]),
            ref_time_log: vec![0.0, 2.0],
        };
        assert!(matches!(model.update(&exec), Err(Error::BadLog { .. })));
        let exec = Execution {
            demonstration: demo(&["torque"], vec![0.0; 3]),
            ref_time_log: vec![0.0, 1.0, 2.0],
        };
        assert!(matches!(
            model.update(&exec),
            Err(Error::ChannelMismatch { .. })
        ));
        assert_eq!(model.count(), 3);
    }
}
