//! Why each stretch is low-confidence, and what would change it.
//!
//! A low-confidence region (a maximal run of low-confidence reference samples,
//! `tandem_confidence::runs`) is low for one of two reasons:
//!
//! * **the demonstrations' variance**: `σ²_D` (Eq. 6) lies above the level at which the
//!   prior (Eq. 10–11) turns low-confidence ([`tandem_confidence::prior_low_threshold`]) and
//!   the supervised executions have not yet shown that corrections are rare there. The
//!   tangent coordinates whose part of `σ²_D` (a channel's weighted variance
//!   `cov_jj / r_j²`, the rate's term as the model computes it) adds most over the region
//!   are named; more clean supervised executions, or a wider range `r_j` for
//!   those coordinates (if their variation there does not matter), would change it;
//! * **the corrections recorded**: the operator corrected more of the region's supervised
//!   time than their false-correction rate explains. The task needs the operator there;
//!   nothing but a different task changes that.

use serde::{Deserialize, Serialize};
use tandem_confidence::{ErrorRates, low_regions, prior_low_threshold};

use crate::{Planner, Result};

/// One tangent coordinate's share of `σ²_D` over a region.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ChannelShare {
    /// Tangent coordinate name (`TaskModel::tangent_names`: a channel, `<block>.rx/ry/rz` of a
    /// quaternion block, or `rate`).
    pub name: String,
    /// Its mean part of `σ²_D` over the region (dimensionless): `cov_jj / r_j²` for a
    /// channel, the model's rate term (`TaskModel::sigma2_d_rate`) for `rate`.
    pub sigma2: f64,
    /// Its share of the region's mean `σ²_D`, in `[0, 1]`.
    pub share: f64,
    /// Its range `r_j` (the coordinate's unit; `W = diag(1/r_j²)`).
    pub range: f64,
    /// The range for this coordinate alone that would bring the region's largest `σ²_D`
    /// to the prior's threshold, if one does (`None` when the other coordinates alone
    /// exceed it, or the region is low for its corrections).
    pub range_for_prior: Option<f64>,
}

/// Why a region is low-confidence.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LowCause {
    /// The demonstrations vary more than the prior trusts and the supervised evidence is not
    /// yet enough.
    Variance,
    /// The operator corrected it more often than their false-correction rate explains.
    Corrections,
}

/// One low-confidence region, explained.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LowRegion {
    /// First reference sample of the region.
    pub ref_start: usize,
    /// One past its last reference sample.
    pub ref_end: usize,
    /// Its reference-time interval `[start_s, end_s)` (s, reference time `n·Δt_s`).
    pub start_s: f64,
    /// End of the interval (s, reference time).
    pub end_s: f64,
    /// Why it is low.
    pub cause: LowCause,
    /// Largest `σ²_D` in the region (dimensionless).
    pub sigma2_d_max: f64,
    /// The `σ²_D` at which the prior turns low-confidence (`None`: even 0 is low).
    pub sigma2_d_prior_threshold: Option<f64>,
    /// The tangent coordinates adding most to `σ²_D` there, largest first (at most three).
    pub channels: Vec<ChannelShare>,
    /// Supervised observation mass in the region (control samples, summed over samples).
    pub supervised: f64,
    /// Corrected observation mass in the region (control samples).
    pub corrections: f64,
    /// The corrections the operator's false-correction rate explains: `f·supervised`.
    pub expected_false_corrections: f64,
    /// Clean (uncorrected) supervised executions more that would make every sample of the
    /// region high-confidence, at the current variance and error rates (estimated rates
    /// move with the new data, so this is a guide, exact for fixed rates; `None` beyond
    /// 10 000 or for a region low for its corrections).
    pub clean_executions_needed: Option<usize>,
}

/// Largest number of clean executions [`LowRegion::clean_executions_needed`] searches.
const MAX_CLEAN: usize = 10_000;

impl Planner {
    /// Every low-confidence region of the current confidence with its cause and what would
    /// change it (see the module docs of `explain`), in reference order.
    ///
    /// # Errors
    /// The confidence crate's error for invalid parameters (a loaded planner has valid ones).
    pub fn explain_low_confidence(&self) -> Result<Vec<LowRegion>> {
        let model = self.model();
        let params = &self.params().confidence;
        let obs = self.observations();
        let rates: ErrorRates = self.error_rates()?;
        let threshold = prior_low_threshold(params)?;
        let posts = tandem_confidence::posterior(model.sigma2_d(), obs, params)?;
        let mu = rates.shifted_mu_c(params.mu_c);
        let names = model.tangent_names();
        let ranges = model.ranges();
        let d = names.len();
        let dt = model.dt_s();
        let mut out = Vec::new();
        // The rate's part of `σ²_D` is not its covariance over `r²` (the relative term
        // weighs the local pace and is opened over the alignment's resolution): it is
        // read from the model, which owns the term.
        let rate_part = model.sigma2_d_rate();
        let part_at = |cov: &[f64], n: usize, j: usize| {
            if j + 1 == d {
                rate_part[n]
            } else {
                cov[j * d + j] / (ranges[j] * ranges[j])
            }
        };
        for r in low_regions(self.confidence().conf()) {
            let len = r.len() as f64;
            let mut per = vec![0.0; d];
            let mut s2_max = 0.0_f64;
            let mut s2_max_at = r.start;
            for n in r.clone() {
                let cov = model.covariance(n);
                for (j, p) in per.iter_mut().enumerate() {
                    *p += part_at(&cov, n, j) / len;
                }
                if model.sigma2_d()[n] > s2_max {
                    s2_max = model.sigma2_d()[n];
                    s2_max_at = n;
                }
            }
            let supervised: f64 = obs.supervised()[r.clone()].iter().sum();
            let corrections: f64 = obs.corrections()[r.clone()].iter().sum();
            let expected = rates.false_correction_rate * supervised;
            // More corrections than the operator's slips explain, by more than their
            // binomial spread (two standard deviations) and at least one.
            let spread = 2.0 * (expected * (1.0 - rates.false_correction_rate)).sqrt();
            let cause = if corrections > expected + spread.max(1.0) {
                LowCause::Corrections
            } else {
                LowCause::Variance
            };
            let total: f64 = per.iter().sum();
            let cov_max = model.covariance(s2_max_at);
            let mut order: Vec<usize> = (0..d).collect();
            order.sort_by(|&a, &b| per[b].total_cmp(&per[a]));
            let channels = order
                .iter()
                .take(3)
                .filter(|&&j| per[j] > 0.0)
                .map(|&j| {
                    // sigma2_d at the worst sample without coordinate j, and j's variance
                    // there: scaling r_j by k divides j's part by k².
                    let part = part_at(&cov_max, s2_max_at, j);
                    let rest = s2_max - part;
                    let range_for_prior = match (cause, threshold) {
                        (LowCause::Variance, Some(t)) if rest < t && part > 0.0 => {
                            Some(ranges[j] * (part / (t - rest)).sqrt())
                        }
                        _ => None,
                    };
                    ChannelShare {
                        name: names[j].clone(),
                        sigma2: per[j],
                        share: if total > 0.0 { per[j] / total } else { 0.0 },
                        range: ranges[j],
                        range_for_prior,
                    }
                })
                .collect();
            let clean_executions_needed = match cause {
                LowCause::Corrections => None,
                LowCause::Variance => r
                    .clone()
                    .map(|n| {
                        let (a, b) = (posts[n].alpha(), posts[n].beta());
                        let high = |k: usize| statrs_high(a, b + k as f64, mu, params.gamma_c);
                        first_true(MAX_CLEAN, high)
                    })
                    .try_fold(0, |acc, k| k.map(|k| acc.max(k))),
            };
            out.push(LowRegion {
                ref_start: r.start,
                ref_end: r.end,
                start_s: r.start as f64 * dt,
                end_s: r.end as f64 * dt,
                cause,
                sigma2_d_max: s2_max,
                sigma2_d_prior_threshold: threshold,
                channels,
                supervised,
                corrections,
                expected_false_corrections: expected,
                clean_executions_needed,
            });
        }
        Ok(out)
    }
}

/// The smallest `k ≤ max` with `pred(k)` for a predicate that stays true once true
/// (`I_μ(α, β + k)` rises with `k`), by bisection; `None` if `pred(max)` is false.
fn first_true(max: usize, pred: impl Fn(usize) -> bool) -> Option<usize> {
    if !pred(max) {
        return None;
    }
    let (mut lo, mut hi) = (0, max);
    if pred(0) {
        return Some(0);
    }
    // pred(lo) false, pred(hi) true.
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if pred(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

/// `I_mu(a, b) > gamma` (Eq. 12 at the shifted threshold); low where statrs fails.
fn statrs_high(a: f64, b: f64, mu: f64, gamma: f64) -> bool {
    tandem_confidence::BetaParams::new(a, b)
        .and_then(|p| p.cdf(mu))
        .is_ok_and(|v| v > gamma)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PlannerParams;
    use tandem_confidence::{Confidence, Observations};
    use tandem_lfd::{Demonstration, FitParams, TaskModel};
    use tandem_schedule::SamplerParams;

    /// Three demonstrations of two channels aligned by the identity: `x` always agrees,
    /// `force` differs on reference samples 10..20 only.
    fn planner(confidence: tandem_confidence::ConfidenceParams) -> Planner {
        let n = 40;
        let names = vec!["x".to_string(), "force".to_string()];
        let demo = |bump: f64| {
            let v = (0..n)
                .flat_map(|i| {
                    let f = if (10..20).contains(&i) { bump } else { 1.0 };
                    [i as f64 / 40.0, f]
                })
                .collect();
            Demonstration::new(names.clone(), v, 0.01).unwrap()
        };
        let identity: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let model = TaskModel::fit_aligned(
            &[demo(1.0), demo(5.0), demo(9.0)],
            &[identity.clone(), identity.clone(), identity],
            &FitParams::default(),
        )
        .unwrap();
        let params = PlannerParams {
            sampler: SamplerParams {
                samples: 20,
                ..SamplerParams::default()
            },
            confidence,
            ..PlannerParams::default()
        };
        Planner::from_model(model, params).unwrap()
    }

    #[test]
    fn a_region_low_for_its_variance_names_the_channel_and_the_executions_needed() {
        // Fixed error rates (1 %): the executions needed do not move the rates.
        let fixed = tandem_confidence::ConfidenceParams {
            estimate_error_rates: false,
            ..Default::default()
        };
        let p = planner(fixed);
        let regions = p.explain_low_confidence().unwrap();
        assert_eq!(regions.len(), 1);
        let r = &regions[0];
        assert_eq!((r.ref_start, r.ref_end), (10, 20));
        assert!((r.start_s - 0.1).abs() < 1e-12 && (r.end_s - 0.2).abs() < 1e-12);
        assert_eq!(r.cause, LowCause::Variance);
        assert_eq!(r.channels[0].name, "force");
        assert!(r.channels[0].share > 0.99, "{:?}", r.channels);
        let t = r.sigma2_d_prior_threshold.unwrap();
        assert!(r.sigma2_d_max > t);
        // A wide enough force range brings sigma2_d to the prior's threshold: scaling r by k
        // divides force's part by k².
        let wider = r.channels[0].range_for_prior.unwrap();
        let k = wider / r.channels[0].range;
        assert!((r.sigma2_d_max / (k * k) - t).abs() < 1e-9 * t.max(1e-12));
        assert_eq!((r.supervised, r.corrections), (0.0, 0.0));
        // The executions needed are exactly what the confidence itself needs: record them
        // clean and the whole region latches, one fewer leaves it low.
        let need = r.clean_executions_needed.unwrap();
        let sigma2_d = p.model().sigma2_d();
        let run = |k: usize| {
            let mut obs = Observations::new(40).unwrap();
            let times: Vec<f64> = (10..20).map(f64::from).collect();
            for _ in 0..k {
                obs.record(&times, &[false; 10]).unwrap();
            }
            let mut conf = Confidence::from_prior(sigma2_d, p.params().confidence.clone()).unwrap();
            conf.update(sigma2_d, &obs).unwrap();
            conf.low_regions().is_empty()
        };
        assert!(run(need) && !run(need - 1), "{need}");
    }

    /// The coordinates' parts add up to `σ²_D`: a channel's `cov_jj / r_j²` plus the rate's
    /// term as the model computes it (relative to the pace, opened over the alignment's
    /// resolution), not the warp gradients' variance over `r²`, which the model never adds.
    /// Three demonstrations whose middle dwell lasts 10, 14 and 18 samples with a different
    /// force there, aligned by the fit itself: the listed parts (every coordinate: `x`,
    /// `force`, `rate`) sum to the region's mean `σ²_D`, and the rate's part is the model's.
    #[test]
    fn the_parts_of_a_region_add_up_to_its_sigma2_d() {
        let names = vec!["x".to_string(), "force".to_string()];
        let demo = |dwell: usize, force: f64| {
            let mut v = Vec::new();
            for i in 0..20 {
                v.extend([0.5 * f64::from(i) / 20.0, 1.0]);
            }
            for _ in 0..dwell {
                v.extend([0.5, force]);
            }
            for i in 0..20 {
                v.extend([0.5 + 0.5 * f64::from(i) / 20.0, 1.0]);
            }
            Demonstration::new(names.clone(), v, 0.01).unwrap()
        };
        let demos = [demo(10, 3.0), demo(14, 6.0), demo(18, 9.0)];
        let model = TaskModel::fit(&demos, &FitParams::default()).unwrap();
        let params = PlannerParams {
            sampler: SamplerParams {
                samples: 20,
                ..SamplerParams::default()
            },
            ..PlannerParams::default()
        };
        let p = Planner::from_model(model, params).unwrap();
        let regions = p.explain_low_confidence().unwrap();
        assert!(!regions.is_empty());
        let sigma2_d = p.model().sigma2_d();
        let rate = p.model().sigma2_d_rate();
        for r in &regions {
            let len = r.ref_end - r.ref_start;
            let mean = |v: &[f64]| v[r.ref_start..r.ref_end].iter().sum::<f64>() / len as f64;
            let listed: f64 = r.channels.iter().map(|c| c.sigma2).sum();
            let want = mean(sigma2_d);
            assert!(
                (listed - want).abs() <= 1e-9 * want,
                "{listed} against {want}: {r:?}"
            );
            if let Some(c) = r.channels.iter().find(|c| c.name == "rate") {
                assert!((c.sigma2 - mean(&rate)).abs() <= 1e-12 * want.max(1e-300));
            }
        }
    }

    #[test]
    fn bisection_finds_the_first_true() {
        for k in [0, 1, 7, 100] {
            assert_eq!(first_true(100, |x| x >= k), Some(k));
        }
        assert_eq!(first_true(100, |_| false), None);
    }
}
