//! Hold points of a planner: the user's declaration ([`tandem_lfd::HoldSpec`] in
//! [`crate::PlannerParams::holds`]) resolved on the current model, and the checks of a
//! declaration.
//!
//! # Which holds are refused
//!
//! A hold is a place where waiting is harmless, so a hold inside a stretch where the operator
//! is needed is a declaration error. What says the operator is needed there? Not the
//! confidence at fit time: before any supervised execution the posterior is the prior
//! (Eq. 10–11), and in the sanding task the prior leaves every sample low-confidence; nor the
//! demonstrations' variance: on the sanding fixture `σ²_D` is at least 0.19 in the transitions
//! between passes (`tool<0.5`), where waiting is harmless, far above any level that would
//! separate them from the passes by the prior (docs/decisions.md, "Hold points"). The
//! evidence is the operator's corrections: a hold is refused ([`Error::HoldInLowConfidence`],
//! naming the hold's reference time and the stretch) when it lies in a low-confidence stretch
//! that the recorded corrections show needs the operator (more corrections than the
//! operator's false-correction rate explains: [`crate::LowCause::Corrections`]). A hold on a
//! stretch that is low-confidence only for lack of executions ([`crate::LowCause::Variance`])
//! is kept, *inactive* ([`tandem_schedule::Problem::active_holds`]) until the confidence
//! trusts its sample. At fit time nothing is recorded, so a declaration is refused only when
//! it is malformed, outside the task, names a channel the model does not have, or holds
//! nowhere; [`crate::Planner::set_holds`] declares holds on a planner with recorded rounds,
//! and there the evidence refuses. After a later round a declared hold is never refused (that
//! would refuse the round): a hold whose stretch the operator corrects stays inactive, as
//! every hold on a low-confidence sample.

use tandem_lfd::{HoldSpec, TaskModel};

use crate::{Error, LowCause, LowRegion, Result};

/// The hold points of `spec` on `model` ([`HoldSpec::resolve`]); empty without a
/// declaration.
pub(crate) fn resolve(spec: &HoldSpec, model: &TaskModel) -> Result<Vec<usize>> {
    if spec.is_empty() {
        return Ok(Vec::new());
    }
    Ok(spec.resolve(model)?)
}

/// Refuses a declaration that cannot mean what it says on `model`: a bad reference time or
/// rule ([`HoldSpec::resolve`]'s errors) and a rule that holds on no reference sample after
/// the start.
///
/// # Errors
/// [`Error::HoldMatchesNothing`], and the model crate's errors for a bad time or rule.
pub(crate) fn check_declared(spec: &HoldSpec, model: &TaskModel) -> Result<()> {
    if spec.is_empty() {
        return Ok(());
    }
    spec.validate()?;
    for &t in &spec.at_s {
        HoldSpec::sample_at(model, t)?;
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
    }
    Ok(())
}

/// Refuses `spec` when one of its hold points lies in a low-confidence region that the
/// recorded corrections show needs the operator (`regions`: the planner's
/// `explain_low_confidence`).
///
/// # Errors
/// [`Error::HoldInLowConfidence`] naming the first such hold and its region.
pub(crate) fn check_evidence(
    spec: &HoldSpec,
    model: &TaskModel,
    regions: &[LowRegion],
) -> Result<()> {
    let needed = |n: usize| {
        regions
            .iter()
            .find(|r| r.cause == LowCause::Corrections && (r.ref_start..r.ref_end).contains(&n))
    };
    let dt = model.dt_s();
    let refuse = |hold: String, n: usize, r: &LowRegion| Error::HoldInLowConfidence {
        hold,
        at_s: n as f64 * dt,
        start_s: r.start_s,
        end_s: r.end_s,
        corrections: r.corrections,
        supervised: r.supervised,
    };
    for &t in &spec.at_s {
        let n = HoldSpec::sample_at(model, t)?;
        if let Some(r) = needed(n) {
            return Err(refuse(format!("the hold at {t} s"), n, r));
        }
    }
    for rule in &spec.rules {
        for n in HoldSpec::rule_samples(model, rule)? {
            if let Some(r) = needed(n) {
                return Err(refuse(format!("the hold rule `{rule}`"), n, r));
            }
        }
    }
    Ok(())
}
