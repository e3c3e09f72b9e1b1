//! Hold points of a planner: the user's declaration ([`tandem_lfd::HoldSpec`] in
//! [`crate::PlannerParams::holds`]) resolved on the current model, and the check that refuses
//! a hold declared where the demonstrations themselves say the operator is needed.
//!
//! # Which holds are refused
//!
//! A hold is a place where waiting is harmless; a hold inside a low-confidence stretch is a
//! declaration error. But confidence at fit time cannot be the test: before any supervised
//! execution the posterior is the prior (Eq. 10–11), and in a task like the sanding fixture
//! the prior leaves every sample low-confidence, so "refuse a hold on a low-confidence sample"
//! would refuse every hold there. The prior has two parts, and they tell the two reasons for
//! low confidence apart:
//!
//! - its **mean** `μ = g/2`, `g = 1 − exp(−γ_p(σ²_D + ε))`, is the correction probability the
//!   demonstrations predict. Where `μ ≥ μ'_c` (the acceptable correction probability of
//!   Eq. 12, shifted by the configured false-correction and miss rates as the decision is) the
//!   demonstrations themselves predict the operator will be needed more often than
//!   acceptable: the sample belongs to a *demonstrated* low-confidence stretch. Equivalently
//!   `σ²_D ≥ σ²_hold = −ln(1 − 2μ'_c)/γ_p − ε` ([`demonstrated_need_level`]).
//! - its **spread** (`σ²_MAX·g`) is what keeps a sample with `μ < μ'_c` low-confidence until
//!   supervised executions confirm it: low only for lack of evidence.
//!
//! A hold declared at a reference time on a sample of the first kind is refused at
//! declaration ([`Error::HoldInLowConfidence`], naming the hold's reference time and the
//! stretch). A rule names a kind of place ("wherever the gripper is closed"), and its samples
//! of the first kind are not holds (a pick-and-place keeps the gripper closed while it lowers
//! the part to a place that varies); a rule left with no sample is refused. A hold of the
//! second kind is kept; it is *inactive* while its sample is low-confidence
//! ([`tandem_schedule::Problem::active_holds`]) and becomes active once the sample is trusted.
//! The check runs when a planner is made from demonstrations or a model; a hold that a later
//! model update moves into a high-variance stretch is kept (refusing it there would refuse the
//! round being recorded) and stays inactive while its sample is low-confidence.

use tandem_confidence::{ConfidenceParams, ErrorRates};
use tandem_lfd::{HoldSpec, TaskModel};

use crate::{Error, Result};

/// The `σ²_D` (dimensionless, Eq. 6) from which the prior's mean correction probability
/// `g/2` (Eq. 10–11) reaches the acceptable correction probability `μ'_c` (Eq. 12 with the
/// configured error rates): `σ²_hold = −ln(1 − 2μ'_c)/γ_p − ε`, `+∞` when `2μ'_c ≥ 1`. A hold
/// on a sample with `σ²_D ≥ σ²_hold` is refused (see the module docs).
///
/// ```
/// use tandem_confidence::ConfidenceParams;
/// let p = ConfidenceParams::paper(); // γ_p = 10, ε = 1e-6, μ_c = 0.05, no error rates
/// let level = tandem_planner::demonstrated_need_level(&p)?;
/// assert!((level - (-(0.9f64).ln() / 10.0 - 1e-6)).abs() < 1e-15);
/// # Ok::<(), tandem_planner::Error>(())
/// ```
///
/// # Errors
/// The confidence crate's error for invalid `params`.
pub fn demonstrated_need_level(params: &ConfidenceParams) -> Result<f64> {
    params.validate()?;
    let mu = ErrorRates::configured(params).shifted_mu_c(params.mu_c);
    if 2.0 * mu >= 1.0 {
        return Ok(f64::INFINITY);
    }
    Ok(-(-2.0 * mu).ln_1p() / params.gamma_p - params.epsilon)
}

/// The hold points of `spec` on `model` for a planner deciding with `confidence`:
/// reference-sample indices, strictly increasing, without the task start. Each reference time
/// at its nearest sample ([`HoldSpec::sample_at`]); each rule at every sample where it holds
/// ([`HoldSpec::rule_samples`]) *and* `σ²_D <` [`demonstrated_need_level`] on the current
/// model (a rule names a kind of place, "wherever the gripper is closed"; where the
/// demonstrations vary there the operator is needed and waiting is not harmless, see the
/// module docs). Empty without a declaration.
pub(crate) fn resolve(
    spec: &HoldSpec,
    model: &TaskModel,
    confidence: &ConfidenceParams,
) -> Result<Vec<usize>> {
    if spec.is_empty() {
        return Ok(Vec::new());
    }
    let level = demonstrated_need_level(confidence)?;
    let s2 = model.sigma2_d();
    let mut holds = Vec::new();
    for &t in &spec.at_s {
        holds.push(HoldSpec::sample_at(model, t)?);
    }
    for rule in &spec.rules {
        holds.extend(
            HoldSpec::rule_samples(model, rule)?
                .into_iter()
                .filter(|&n| s2[n] < level),
        );
    }
    holds.sort_unstable();
    holds.dedup();
    holds.retain(|&n| n > 0);
    Ok(holds)
}

/// Refuses a declaration that cannot mean what it says on `model`: a reference time on a
/// sample of a demonstrated low-confidence stretch (`σ²_D ≥` [`demonstrated_need_level`], see
/// the module docs), a rule that holds on no reference sample after the start, and a rule
/// that holds only inside such stretches (so it would add no hold).
///
/// # Errors
/// [`Error::HoldMatchesNothing`], [`Error::HoldInLowConfidence`], and the model crate's
/// errors for a bad time or rule.
pub(crate) fn check_declared(
    spec: &HoldSpec,
    model: &TaskModel,
    confidence: &ConfidenceParams,
) -> Result<()> {
    if spec.is_empty() {
        return Ok(());
    }
    let level = demonstrated_need_level(confidence)?;
    let s2 = model.sigma2_d();
    let dt = model.dt_s();
    let refuse = |hold: String, n: usize| {
        let (mut start, mut end) = (n, n + 1);
        while start > 0 && s2[start - 1] >= level {
            start -= 1;
        }
        while end < s2.len() && s2[end] >= level {
            end += 1;
        }
        Error::HoldInLowConfidence {
            hold,
            at_s: n as f64 * dt,
            start_s: start as f64 * dt,
            end_s: end as f64 * dt,
            sigma2_d: s2[n],
            level,
        }
    };
    for &t in &spec.at_s {
        let n = HoldSpec::sample_at(model, t)?;
        if n > 0 && s2[n] >= level {
            return Err(refuse(format!("the hold at {t} s"), n));
        }
    }
    for rule in &spec.rules {
        let samples = HoldSpec::rule_samples(model, rule)?;
        if samples.iter().all(|&n| n == 0) {
            let m = model.channel_names().len();
            let col = model
                .channel_names()
                .iter()
                .position(|c| *c == rule.channel)
                .expect("rule_samples accepted the channel");
            let (lo, hi) = model
                .mean()
                .iter()
                .skip(col)
                .step_by(m)
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                    (lo.min(v), hi.max(v))
                });
            return Err(Error::HoldMatchesNothing {
                rule: rule.to_string(),
                why: format!(
                    "the mean of `{}` runs from {lo} to {hi} over the task",
                    rule.channel
                ),
            });
        }
        if samples.iter().all(|&n| n == 0 || s2[n] >= level) {
            let n = *samples.iter().find(|&&n| n > 0).expect("checked above");
            return Err(refuse(
                format!("the hold rule `{rule}` holds only inside stretches like this; it"),
                n,
            ));
        }
    }
    Ok(())
}
