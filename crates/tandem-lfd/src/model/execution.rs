//! Executions recorded by the system and the incremental update with them (Eq. 21).

use std::sync::OnceLock;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::stats::{derive_at, observe_at, packed_len, welford_add};
use super::{PAR_MIN_LEN, TaskModel, check_dt};
use crate::demo::Demonstration;
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

impl TaskModel {
    /// Adds one execution recorded by the system (Eq. 21) without re-alignment: its warp
    /// is the inverse of its reference-time log, its gradient per reference sample follows.
    /// Updates the per-reference-sample count, mean and scatter (Welford) and the gradient
    /// bounds in `O(n_ref · d²)`; the ranges, anchors and `k_max` stay as fitted; the
    /// correction directions are recomputed on next use.
    ///
    /// # Errors
    /// The model is unchanged on error: different channel set or sample period, log length
    /// ≠ sample count, non-finite, decreasing or outside `[0, n_ref − 1]` log, zero
    /// quaternion.
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
        data.count += 1;
        self.corrections = OnceLock::new();
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
        check_dt(demo, self.data.dt_s)?;
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
