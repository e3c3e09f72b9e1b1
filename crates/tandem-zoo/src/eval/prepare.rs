//! One task made ready for the loop: generated, fitted with the defaults (the user's first
//! try), its truth mapped onto the model's reference samples, and what the fit alone shows
//! ([`FitReport`]: high confidence against the truth, and how it depends on which file comes
//! first).

use serde::{Deserialize, Serialize};
use tandem_confidence::{Confidence, ConfidenceParams};
use tandem_lfd::{Demonstration, FitParams, HoldRule, HoldSpec, Reference, TaskModel};
use tandem_planner::PlannerParams;
use tandem_sim::needs::NeedProfile;
use tandem_sim::study::StudyInputs;
use tandem_sim::task::{TaskParams, ground_truth_share};
use tandem_sim::truth::{ProfileTruth, SandingTruth, TaskTruth, needs_help};

use super::warps::{WarpError, fitted_warps, warp_error};
use crate::{Error, Family, Result, ZooTask};

/// High confidence after the fit for each choice of first file, and with the medoid
/// (`Reference::Medoid`), percent of reference samples.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReferenceSpread {
    /// Per demonstration `r`: high confidence (%) of the fit whose first file is demo `r`
    /// (the files rotated, `r, r + 1, …, r − 1`; the default `Reference::First` makes demo `r`
    /// the reference).
    pub first_high_pct: Vec<f64>,
    /// Per demonstration `r`: the truth (%) on demo `r`'s time axis
    /// ([`ZooTask::true_high_share`]).
    pub first_truth_pct: Vec<f64>,
    /// High confidence (%) with `Reference::Medoid` (any order gives the same model).
    pub medoid_high_pct: f64,
    /// The demonstration the medoid chose.
    pub medoid_idx: usize,
    /// The truth (%) on the medoid's time axis.
    pub medoid_truth_pct: f64,
}

impl ReferenceSpread {
    /// Largest minus smallest high confidence over the choices of first file (pp).
    #[must_use]
    pub fn spread_pp(&self) -> f64 {
        let (lo, hi) = min_max(&self.first_high_pct);
        hi - lo
    }

    /// The medoid's high confidence minus the best single-file choice's (pp; ≤ 0).
    #[must_use]
    pub fn medoid_vs_best_pp(&self) -> f64 {
        self.medoid_high_pct - min_max(&self.first_high_pct).1
    }
}

/// Smallest and largest value (`(+∞, −∞)` for none).
pub(super) fn min_max(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        })
}

/// What the fit with the defaults shows, before any round.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FitReport {
    /// The family.
    pub family: String,
    /// The seed.
    pub seed: u64,
    /// Demonstrations.
    pub n_demos: usize,
    /// Sample rate (Hz).
    pub rate_hz: f64,
    /// Reference samples `T_ref`.
    pub n_ref: usize,
    /// The reference demonstration (`TaskModel::reference_idx`).
    pub reference_idx: usize,
    /// The hold rules declared (`--hold-where`), as the family gives them.
    pub holds: Vec<String>,
    /// The channel the simulated operator's corrections raise.
    pub correction_channel: String,
    /// Truth: percent of the reference's duration that never needs the operator
    /// ([`ZooTask::true_high_share`] of the reference).
    pub truth_high_pct: f64,
    /// High confidence after the fit (the prior alone, Eq. 10–12), percent.
    pub fit_high_pct: f64,
    /// Low-confidence runs after the fit.
    pub fit_lc_runs: usize,
    /// Reference samples that need the operator (need > 0) and are high-confidence after the
    /// fit, where the demonstrations vary (a variable section, [`ZooTask::is_variable`]).
    pub fit_falsely_trusted: usize,
    /// The same where every demonstration agrees (no variance can reveal the need there: only
    /// corrections can).
    pub fit_falsely_trusted_agreeing: usize,
    /// The reference-choice spread (`None` when not measured).
    pub spread: Option<ReferenceSpread>,
    /// The fit's alignment against the family's known warps (`eval::warps`; `None` for
    /// the sanding fixture, whose true warps are not known, and in reports written before it
    /// was measured).
    #[serde(default)]
    pub warp_error: Option<WarpError>,
}

/// A task ready for the loop.
pub struct Prepared {
    /// The family's name.
    pub family: &'static str,
    /// The seed.
    pub seed: u64,
    /// The model fitted with the defaults (corrections prepared).
    pub model: TaskModel,
    /// The planner parameters: the defaults with the family's hold rules declared.
    pub planner: PlannerParams,
    /// The truth on the model's reference samples.
    pub truth: Box<dyn TaskTruth + Send + Sync>,
    /// Per reference sample: where the operator can be needed (need > 0), `Some(varies)`:
    /// whether the demonstrations vary there ([`ZooTask::is_variable`]); `None` elsewhere.
    pub need_kind: Vec<Option<bool>>,
    /// What the fit shows.
    pub report: FitReport,
}

/// The channel the simulated operator's corrections raise on `model`
/// ([`tandem_sim::workcell::correction_channel`], what `tandem simulate` uses by default).
#[must_use]
pub fn correction_channel(model: &TaskModel) -> String {
    tandem_sim::workcell::correction_channel(model)
}

/// High confidence (%) after a fit: the prior alone with the default confidence parameters.
fn prior_high_pct(model: &TaskModel, params: &ConfidenceParams) -> Result<f64> {
    let conf = Confidence::from_prior(model.sigma2_d(), params.clone())
        .map_err(tandem_planner::Error::from)?;
    Ok(100.0 * conf.high_share())
}

/// The reference-choice spread of `demos` (module docs): one fit per choice of first file
/// and one with the medoid, each with `fit` otherwise.
fn reference_spread(
    task: &ZooTask,
    demos: &[Demonstration],
    fit: &FitParams,
    confidence: &ConfidenceParams,
    first_fit: &TaskModel,
) -> Result<ReferenceSpread> {
    let n = demos.len();
    let mut first_high_pct = Vec::with_capacity(n);
    for r in 0..n {
        let pct = if r == 0 && fit.reference == Reference::First {
            prior_high_pct(first_fit, confidence)?
        } else {
            let rotated: Vec<Demonstration> =
                demos[r..].iter().chain(&demos[..r]).cloned().collect();
            let params = FitParams {
                reference: Reference::First,
                ..fit.clone()
            };
            prior_high_pct(&TaskModel::fit(&rotated, &params)?, confidence)?
        };
        first_high_pct.push(pct);
    }
    let medoid = if fit.reference == Reference::Medoid {
        // The default fit is the medoid's (any order gives the same model).
        first_fit.clone()
    } else {
        TaskModel::fit(
            demos,
            &FitParams {
                reference: Reference::Medoid,
                ..fit.clone()
            },
        )?
    };
    let medoid_idx = medoid.reference_idx();
    Ok(ReferenceSpread {
        first_high_pct,
        first_truth_pct: (0..n).map(|r| 100.0 * task.true_high_share(r)).collect(),
        medoid_high_pct: prior_high_pct(&medoid, confidence)?,
        medoid_idx,
        medoid_truth_pct: 100.0 * task.true_high_share(medoid_idx),
    })
}

/// The hold rules `rules` as the planner takes them (`--hold-where`).
fn hold_spec(rules: &[String]) -> Result<HoldSpec> {
    Ok(HoldSpec {
        at_s: Vec::new(),
        rules: rules
            .iter()
            .map(|r| r.parse::<HoldRule>())
            .collect::<std::result::Result<_, _>>()?,
    })
}

/// The name the sanding fixture has among the families of a report.
pub const SANDING: &str = "sanding";

/// The sanding fixture (`inputs`: its demonstrations and each one's labels) made ready for
/// the same loop: fitted with `params` and the hold rules `holds` (the study's `tool<0.5`),
/// its truth the study's ([`SandingTruth`] on the labels of the fit's reference,
/// `StudyInputs::reference_labels`: a random half of the sections of passes 1–3 painted per
/// workpiece; every sample that can need the operator varies between demonstrations). No
/// reference-choice spread here (`cargo xtask reference-order` measures it on the fixture).
///
/// # Errors
/// The fit's or the planner's errors; [`Error::Eval`] when the labels are not one per sample
/// of the reference.
pub fn prepare_sanding(
    inputs: &StudyInputs,
    holds: &[String],
    params: &PlannerParams,
) -> Result<Prepared> {
    let mut planner = params.clone();
    planner.holds = hold_spec(holds)?;
    let model = TaskModel::fit(&inputs.demos, &planner.fit)?;
    model.prepare_corrections();
    // The truth is the labels of whichever demonstration the fit chose as the reference.
    let labels = &inputs.reference_labels(&model).map_err(|e| Error::Eval {
        what: SANDING.into(),
        why: e.to_string(),
    })?;
    let need_kind: Vec<Option<bool>> = labels
        .iter()
        .map(|l| needs_help(l).then_some(true))
        .collect();
    let conf = Confidence::from_prior(model.sigma2_d(), planner.confidence.clone())
        .map_err(tandem_planner::Error::from)?;
    let (fit_falsely_trusted, fit_falsely_trusted_agreeing) =
        falsely_trusted_split(conf.conf(), &need_kind);
    let dt_s = model.dt_s();
    let report = FitReport {
        family: SANDING.into(),
        seed: 0,
        n_demos: inputs.demos.len(),
        rate_hz: 1.0 / dt_s,
        n_ref: model.n_ref(),
        reference_idx: model.reference_idx(),
        holds: holds.to_vec(),
        correction_channel: "force".into(),
        truth_high_pct: 100.0 * ground_truth_share(labels),
        fit_high_pct: 100.0 * conf.high_share(),
        fit_lc_runs: tandem_confidence::runs(conf.conf())
            .iter()
            .filter(|run| !run.high_conf)
            .count(),
        fit_falsely_trusted,
        fit_falsely_trusted_agreeing,
        spread: None,
        warp_error: None,
    };
    Ok(Prepared {
        family: SANDING,
        seed: 0,
        model,
        planner,
        truth: Box::new(SandingTruth::new(labels.clone(), TaskParams::default())),
        need_kind,
        report,
    })
}

/// Generates `family` at `seed`, fits it with `params` (the defaults plus the family's hold
/// rules) and maps the truth onto the reference; with `spread`, also measures the
/// reference-choice spread.
///
/// # Errors
/// The generator's, the fit's or the planner's errors; [`Error::Eval`] when the reference's
/// truth does not have one value per reference sample, or a hold rule does not parse.
pub fn prepare(
    family: &Family,
    seed: u64,
    params: &PlannerParams,
    spread: bool,
) -> Result<Prepared> {
    let task = (family.generate)(seed)?;
    let demos = task.demos()?;
    let mut planner = params.clone();
    planner.holds = hold_spec(&task.holds)?;
    let model = TaskModel::fit(&demos, &planner.fit)?;
    model.prepare_corrections();
    let r = model.reference_idx();
    let progress = task.progress.get(r).ok_or_else(|| Error::Eval {
        what: format!("{} seed {seed}", family.name),
        why: format!("no true progress for the reference, demo {r}"),
    })?;
    if progress.len() != model.n_ref() {
        return Err(Error::Eval {
            what: format!("{} seed {seed}", family.name),
            why: format!(
                "the reference (demo {r}) has {} rows of true progress but {} reference samples",
                progress.len(),
                model.n_ref()
            ),
        });
    }
    let levels: Vec<f64> = progress.iter().map(|&p| task.need_at(p)).collect();
    let need_kind: Vec<Option<bool>> = progress
        .iter()
        .map(|&p| (task.need_at(p) > 0.0).then(|| task.is_variable(p)))
        .collect();
    let channel = correction_channel(&model);
    let truth = Box::new(ProfileTruth::new(
        NeedProfile::from_levels(&levels)?,
        channel.clone(),
    )?);
    let conf = Confidence::from_prior(model.sigma2_d(), planner.confidence.clone())
        .map_err(tandem_planner::Error::from)?;
    let (fit_falsely_trusted, fit_falsely_trusted_agreeing) =
        falsely_trusted_split(conf.conf(), &need_kind);
    let spread = if spread {
        Some(reference_spread(
            &task,
            &demos,
            &planner.fit,
            &planner.confidence,
            &model,
        )?)
    } else {
        None
    };
    let warps = fitted_warps(&model, &demos, &planner.fit)?;
    let warp_error = Some(warp_error(&task, r, &warps)?);
    let report = FitReport {
        family: family.name.to_string(),
        seed,
        n_demos: demos.len(),
        rate_hz: task.rate_hz,
        n_ref: model.n_ref(),
        reference_idx: r,
        holds: task.holds.clone(),
        correction_channel: channel,
        truth_high_pct: 100.0 * task.true_high_share(r),
        fit_high_pct: 100.0 * conf.high_share(),
        fit_lc_runs: tandem_confidence::runs(conf.conf())
            .iter()
            .filter(|run| !run.high_conf)
            .count(),
        fit_falsely_trusted,
        fit_falsely_trusted_agreeing,
        spread,
        warp_error,
    };
    Ok(Prepared {
        family: family.name,
        seed,
        model,
        planner,
        truth,
        need_kind,
        report,
    })
}

/// High-confidence samples where the operator can be needed: `(varying, agreeing)` (where
/// the demonstrations vary, where they all agree), from [`Prepared::need_kind`].
#[must_use]
pub fn falsely_trusted_split(conf: &[bool], need_kind: &[Option<bool>]) -> (usize, usize) {
    conf.iter()
        .zip(need_kind)
        .fold((0, 0), |(l, u), (high, kind)| match (high, kind) {
            (true, Some(true)) => (l + 1, u),
            (true, Some(false)) => (l, u + 1),
            _ => (l, u),
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn falsely_trusted_splits_by_learnability() {
        let conf = [true, true, false, true, true];
        let kind = [Some(true), Some(false), Some(true), None, Some(true)];
        assert_eq!(falsely_trusted_split(&conf, &kind), (2, 1));
        assert_eq!(falsely_trusted_split(&[false; 5], &kind), (0, 0));
    }

    #[test]
    fn min_max_of_values() {
        assert_eq!(min_max(&[3.0, -1.0, 2.0]), (-1.0, 3.0));
        let s = ReferenceSpread {
            first_high_pct: vec![60.0, 66.5, 62.0],
            first_truth_pct: vec![70.0; 3],
            medoid_high_pct: 61.0,
            medoid_idx: 2,
            medoid_truth_pct: 70.0,
        };
        assert_eq!(s.spread_pp(), 6.5);
        assert_eq!(s.medoid_vs_best_pp(), -5.5);
    }
}
