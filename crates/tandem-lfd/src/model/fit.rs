//! Fitting: checks of the demonstration set, the choice of the reference and the alignment
//! to it (GDTW), and the batch statistics from the warps.

use std::borrow::Cow;
use std::cmp::Ordering;

use rayon::prelude::*;

#[cfg(test)]
use super::RateTerm;
use super::layout::{Item, Layout, quat_at};
use super::stats::{batch_statistics, observe};
use super::{FitParams, ModelData, Reference, TaskModel, check_dt};
use crate::demo::{DT_TOLERANCE, Demonstration};
use crate::{Error, Result};

/// Checks the demonstration set; returns it with every channel order equal to demo 0's
/// (borrowed when it already is).
fn check_demos(demos: &[Demonstration]) -> Result<Cow<'_, [Demonstration]>> {
    if demos.len() < 2 {
        return Err(Error::TooFewDemonstrations { found: demos.len() });
    }
    let names = demos[0].channel_names();
    // The period most demonstrations share decides which one is the odd one out (a 1 kHz
    // file given first is named, not the good file after it); ties go to the earlier file.
    let agree = |a: &Demonstration, b: &Demonstration| {
        (a.dt_s() - b.dt_s()).abs() <= DT_TOLERANCE * b.dt_s()
    };
    let shared = |d: &Demonstration| demos.iter().filter(|o| agree(o, d)).count();
    let majority = demos
        .iter()
        .enumerate()
        .max_by(|(i, a), (j, b)| shared(a).cmp(&shared(b)).then(j.cmp(i)))
        .map_or(0, |(i, _)| i);
    let dt = demos[majority].dt_s();
    let whose = || {
        let with: Vec<&str> = demos
            .iter()
            .filter(|o| agree(o, &demos[majority]))
            .map(Demonstration::source)
            .collect();
        match with[..] {
            [one] => one.to_owned(),
            _ => format!(
                "{} of the {} demonstrations ({})",
                with.len(),
                demos.len(),
                with.join(", ")
            ),
        }
    };
    let mut reordered = false;
    for demo in demos {
        check_dt(demo, dt, &whose)?;
        reordered |= matches!(demo.conform_to(names)?, Cow::Owned(_));
    }
    if !reordered {
        return Ok(Cow::Borrowed(demos));
    }
    demos
        .iter()
        .map(|demo| Ok(demo.conform_to(names)?.into_owned()))
        .collect::<Result<Vec<_>>>()
        .map(Cow::Owned)
}

/// Checks warp `demo_idx` (`n_ref` values, monotone, inside `[0, T_i − 1]`).
fn check_warp(demo_idx: usize, warp: &[f64], n_ref: usize, t_i: usize) -> Result<()> {
    let bad = |why: String| Error::BadWarp { demo_idx, why };
    if warp.len() != n_ref {
        return Err(bad(format!(
            "{} values for {n_ref} reference samples",
            warp.len()
        )));
    }
    let last = (t_i - 1) as f64;
    let tol = 1e-9 * last.max(1.0);
    for (n, &v) in warp.iter().enumerate() {
        if !v.is_finite() || v < -tol || v > last + tol {
            return Err(bad(format!(
                "value {v} at reference sample {n} is outside [0, {last}]"
            )));
        }
        if n > 0 && v < warp[n - 1] {
            return Err(bad(format!("decreases at reference sample {n}")));
        }
    }
    Ok(())
}

/// Every demonstration aligned to one reference (the alignment stage of a fit).
struct Alignment {
    /// Demonstration indices (into the caller's list) in model order, the reference first.
    order: Vec<usize>,
    /// The ranges of the non-rate coordinates the weights came from.
    non_rate_ranges: Vec<f64>,
    /// One warp per demonstration in model order (the reference's is the identity).
    warps: Vec<Vec<f64>>,
}

/// Aligns every demonstration of `demos` to `demos[order[0]]` with the weights the fit
/// would derive with that reference; `order` lists the others in the order they enter the
/// statistics.
fn align_to(
    demos: &[Demonstration],
    order: Vec<usize>,
    layout: &Layout,
    params: &FitParams,
) -> Result<Alignment> {
    let reference = &demos[order[0]];
    let d = layout.dim();
    let non_rate_ranges = match &params.ranges {
        Some(r) => r[..d - 1].to_vec(),
        None => layout.channel_ranges(reference, demos, params.min_range),
    };
    let m = reference.n_channels();
    let mut warp_params = params.warp.clone();
    if warp_params.weights.is_none() {
        warp_params.weights = Some(layout.warp_weights(&non_rate_ranges, m));
    }
    let reference_orientations = layout.first_orientations(reference);
    let signals: Vec<Vec<f64>> = order
        .par_iter()
        .map(|&i| layout.sign_aligned(&demos[i], &reference_orientations))
        .collect();
    let refs = signals
        .iter()
        .map(|s| tandem_warp::SignalRef::new(s, m))
        .collect::<std::result::Result<Vec<_>, _>>()?;
    let aligned = tandem_warp::align_many(refs[0], &refs[1..], &warp_params)?;
    let mut warps: Vec<Vec<f64>> = Vec::with_capacity(order.len());
    warps.push((0..reference.n_samples()).map(|n| n as f64).collect());
    warps.extend(aligned.iter().map(|w| w.values().to_vec()));
    Ok(Alignment {
        order,
        non_rate_ranges,
        warps,
    })
}

/// A fixed order of demonstrations by content (length, then samples, then period), for
/// statistics that must not depend on the order the caller gave them in.
fn content_order(a: &Demonstration, b: &Demonstration) -> Ordering {
    a.n_samples()
        .cmp(&b.n_samples())
        .then_with(|| {
            a.samples()
                .iter()
                .zip(b.samples())
                .map(|(x, y)| x.total_cmp(y))
                .find(|o| o.is_ne())
                .unwrap_or(Ordering::Equal)
        })
        .then_with(|| a.dt_s().total_cmp(&b.dt_s()))
}

/// Every demonstration tried as the reference, in input order (the medoid's candidates).
fn all_candidates(
    demos: &[Demonstration],
    layout: &Layout,
    params: &FitParams,
) -> Result<Vec<Alignment>> {
    (0..demos.len())
        .into_par_iter()
        .map(|r| {
            let mut others: Vec<usize> = (0..demos.len()).filter(|&i| i != r).collect();
            others.sort_by(|&a, &b| content_order(&demos[a], &demos[b]));
            let order = std::iter::once(r).chain(others).collect();
            align_to(demos, order, layout, params)
        })
        .collect()
}

/// The medoid's criterion of a model fitted on a candidate reference: the median of `σ²_D`
/// (Eq. 6) over its reference samples (the upper one of an even count), how much the
/// demonstrations disagree at a typical instant of the candidate's time axis
/// (docs/decisions.md, "The reference demonstration: the medoid by default").
fn medoid_criterion(model: &TaskModel) -> f64 {
    let mut s2 = model.sigma2_d().to_vec();
    let mid = s2.len() / 2;
    *s2.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// One candidate reference of the medoid: its model and [`medoid_criterion`], or the
/// demonstration (input index) that looks cut off on its time axis and the error saying so.
type Candidate = std::result::Result<(TaskModel, f64), (usize, Error)>;

/// Every demonstration tried as the reference ([`all_candidates`]), each fitted, in input
/// order; an error other than a demonstration looking cut off ends the fit.
fn candidate_models(
    demos: &[Demonstration],
    layout: &Layout,
    params: &FitParams,
) -> Result<Vec<Candidate>> {
    all_candidates(demos, layout, params)?
        .into_par_iter()
        .map(|alignment| {
            let ordered: Vec<&Demonstration> = alignment.order.iter().map(|&i| &demos[i]).collect();
            if let Some((k, e)) = crate::checks::reaches_end_failure(
                &ordered,
                &alignment.warps,
                params.warp.slope_min,
                params.warp.slope_max,
            ) {
                return Ok(Err((alignment.order[k], e)));
            }
            let model = TaskModel::from_alignment(demos, alignment, params, layout.clone())?;
            let criterion = medoid_criterion(&model);
            Ok(Ok((model, criterion)))
        })
        .collect()
}

/// The medoid ([`Reference::Medoid`]): of the candidates of [`candidate_models`] (in input
/// order) on whose axis every demonstration reaches the end, the one with the least
/// criterion, a tie going to the demonstration first in content order (so that the choice
/// does not depend on the order of the input either).
///
/// A demonstration is refused as cut off when it looks so on the time axes of more than
/// half of the other demonstrations (the error of the candidate first in content order that
/// refuses it): one that does not reach the end looks cut off on every other axis, while on
/// a legitimate set one odd candidate (a long pause of its own at the end) may make another
/// look cut off (`tests/demo_coverage.rs`).
fn medoid(demos: &[Demonstration], candidates: Vec<Candidate>) -> Result<TaskModel> {
    let n = demos.len();
    let by_content = |a: usize, b: usize| content_order(&demos[a], &demos[b]);
    let mut votes = vec![0usize; n];
    let mut refusal: Option<(usize, usize, Error)> = None;
    let mut best: Option<(TaskModel, f64)> = None;
    for (i, c) in candidates.into_iter().enumerate() {
        match c {
            Err((refused, e)) => {
                votes[refused] += 1;
                if 2 * votes[refused] > n - 1
                    && refusal
                        .as_ref()
                        .is_none_or(|(j, ..)| by_content(i, *j).is_lt())
                {
                    refusal = Some((i, refused, e));
                }
            }
            Ok(c) => {
                best = Some(match best {
                    None => c,
                    Some(b) => {
                        let closer =
                            c.1.total_cmp(&b.1)
                                .then_with(|| by_content(c.0.reference_idx(), b.0.reference_idx()));
                        if closer.is_lt() { c } else { b }
                    }
                });
            }
        }
    }
    match (refusal, best) {
        (Some((.., e)), _) => Err(e),
        (None, Some((model, _))) => Ok(model),
        (None, None) => Err(Error::BadData {
            what: "demonstrations".into(),
            why: "on the time axis of each of them another looks cut off: give the one that \
                  reaches the end of the task first and fit with `--reference first`"
                .into(),
        }),
    }
}

/// The checks every fit starts with: parameters, the demonstration set (returned with
/// demo 0's channel order), its tangent layout, quaternion norms, explicit ranges' length.
fn checked<'a>(
    demos: &'a [Demonstration],
    params: &FitParams,
) -> Result<(Cow<'a, [Demonstration]>, Layout)> {
    params.validate()?;
    let demos = check_demos(demos)?;
    let layout = Layout::new(&demos[0], &params.schema)?;
    for demo in demos.iter() {
        layout.check_quaternion_norms(demo)?;
    }
    params.check_ranges_len(layout.dim())?;
    Ok((demos, layout))
}

impl TaskModel {
    /// Fits the model: chooses the reference ([`FitParams::reference`]: the medoid by
    /// default, or demo 0), aligns every demonstration to it with GDTW
    /// (`tandem_warp::align_many`, in parallel), then computes the statistics as
    /// [`TaskModel::fit_aligned`] does. `n_ref() = T_ref`, the reference's sample count;
    /// [`TaskModel::reference_idx`] says which demonstration it was. The model's channel
    /// order is demo 0's.
    ///
    /// # Errors
    /// Fewer than 2 demonstrations, different channel sets or sample periods, a partial
    /// quaternion block, a channel named like a derived coordinate, a zero quaternion, bad
    /// parameters, alignment failure.
    pub fn fit(demos: &[Demonstration], params: &FitParams) -> Result<Self> {
        let (demos, layout) = checked(demos, params)?;
        crate::checks::check_lengths(&demos)?;
        match params.reference {
            Reference::First => {
                let alignment = align_to(&demos, (0..demos.len()).collect(), &layout, params)?;
                Self::from_alignment(&demos, alignment, params, layout)
            }
            Reference::Medoid => medoid(&demos, candidate_models(&demos, &layout, params)?),
        }
    }

    /// The model of one alignment: its statistics, its reference's index.
    fn from_alignment(
        demos: &[Demonstration],
        alignment: Alignment,
        params: &FitParams,
        layout: Layout,
    ) -> Result<Self> {
        let ordered: Vec<&Demonstration> = alignment.order.iter().map(|&i| &demos[i]).collect();
        crate::checks::check_reaches_end(
            &ordered,
            &alignment.warps,
            params.warp.slope_min,
            params.warp.slope_max,
        )?;
        let mut model = Self::fit_from_warps(
            &ordered,
            &alignment.warps,
            params,
            layout,
            alignment.non_rate_ranges,
        )?;
        model.data.reference_idx = alignment.order[0];
        Ok(model)
    }

    /// Fits the model from known warps: `warps[i][n]` is demo `i`'s time (demo samples,
    /// fractional) at reference sample `n`. Demo 0 is the reference (`warps[0]` is normally
    /// the identity `0, 1, …, T_0 − 1`) whatever [`FitParams::reference`] says: the warps
    /// chose it.
    ///
    /// Per reference sample it computes the mean `μ̂(n)`, the mean warp gradient and the
    /// augmented mean `μ̂⁺` (Eq. 5), the weighted variance `σ²_D(n)` (Eq. 6) and the gradient
    /// bounds (Eq. 14); the correction directions are computed on first use.
    ///
    /// # Errors
    /// As [`TaskModel::fit`], plus a warp of the wrong length, non-finite, decreasing, or
    /// outside `[0, T_i − 1]`.
    pub fn fit_aligned(
        demos: &[Demonstration],
        warps: &[Vec<f64>],
        params: &FitParams,
    ) -> Result<Self> {
        let (demos, layout) = checked(demos, params)?;
        let non_rate_ranges = match &params.ranges {
            Some(r) => r[..r.len() - 1].to_vec(),
            None => layout.channel_ranges(&demos[0], &demos, params.min_range),
        };
        let ordered: Vec<&Demonstration> = demos.iter().collect();
        Self::fit_from_warps(&ordered, warps, params, layout, non_rate_ranges)
    }

    /// The medoid's criterion for every demonstration, in input order: the median of
    /// `σ²_D` (Eq. 6) of the model fitted with it as the reference (all the others aligned
    /// to it with the weights it would have as the reference); infinite for a candidate on
    /// whose time axis another demonstration looks cut off (refused as the medoid refuses). [`Reference::Medoid`] picks the
    /// smallest; how far apart the values are says how clear that choice is. Ignores
    /// [`FitParams::reference`].
    ///
    /// # Errors
    /// As [`TaskModel::fit`] (a demonstration cut off whatever the reference included).
    pub fn reference_costs(demos: &[Demonstration], params: &FitParams) -> Result<Vec<f64>> {
        let (demos, layout) = checked(demos, params)?;
        let candidates = candidate_models(&demos, &layout, params)?;
        let costs = candidates
            .iter()
            .map(|c| {
                c.as_ref()
                    .map_or(f64::INFINITY, |(_, criterion)| *criterion)
            })
            .collect();
        // The medoid's refusals are the costs' too.
        medoid(&demos, candidates)?;
        Ok(costs)
    }

    /// The warp (reference sample → sample of `demo`, `n_ref()` values) with which a fit with
    /// `params` whose reference was `reference` aligns `demo`: the same signals (quaternion
    /// blocks sign-aligned to the reference's first orientation), the model's ranges as the
    /// channel weights (unless `params.warp.weights` gives them) and `params.warp`. Used to
    /// carry reference times from another reference onto this model's (the planner's refit
    /// that keeps recorded rounds).
    ///
    /// # Errors
    /// `reference` is not `n_ref()` samples long or either has other channels or another
    /// sample period than the model; bad warp parameters; alignment failure.
    pub fn align_demonstration(
        &self,
        reference: &Demonstration,
        demo: &Demonstration,
        params: &FitParams,
    ) -> Result<Vec<f64>> {
        let names = &self.data.channel_names;
        let reference = reference.conform_to(names)?;
        let demo = demo.conform_to(names)?;
        check_dt(&reference, self.data.dt_s, &|| "the model".into())?;
        check_dt(&demo, self.data.dt_s, &|| "the model".into())?;
        if reference.n_samples() != self.data.n_ref {
            return Err(Error::BadData {
                what: "reference".into(),
                why: format!(
                    "{} samples for a model of {} reference samples",
                    reference.n_samples(),
                    self.data.n_ref
                ),
            });
        }
        let layout = &self.data.layout;
        let d = layout.dim();
        let m = names.len();
        let mut warp_params = params.warp.clone();
        if warp_params.weights.is_none() {
            warp_params.weights = Some(layout.warp_weights(&self.data.ranges[..d - 1], m));
        }
        let orientations = layout.first_orientations(&reference);
        let a = layout.sign_aligned(&reference, &orientations);
        let b = layout.sign_aligned(&demo, &orientations);
        let aligned = tandem_warp::align_many(
            tandem_warp::SignalRef::new(&a, m)?,
            &[tandem_warp::SignalRef::new(&b, m)?],
            &warp_params,
        )?;
        Ok(aligned[0].values().to_vec())
    }

    /// The statistics of checked demonstrations, reference first, from their warps.
    /// `non_rate_ranges`: the ranges of the non-rate coordinates (explicit or default).
    fn fit_from_warps(
        demos: &[&Demonstration],
        warps: &[Vec<f64>],
        params: &FitParams,
        layout: Layout,
        non_rate_ranges: Vec<f64>,
    ) -> Result<Self> {
        let n_ref = demos[0].n_samples();
        if warps.len() != demos.len() {
            return Err(Error::BadData {
                what: "warps".into(),
                why: format!("{} warps for {} demonstrations", warps.len(), demos.len()),
            });
        }
        for (demo_idx, (warp, demo)) in warps.iter().zip(demos).enumerate() {
            check_warp(demo_idx, warp, n_ref, demo.n_samples())?;
        }
        let d = layout.dim();
        // Anchors: the reference's orientation at its aligned time, `n_ref × n_quat`.
        let mut anchors = Vec::with_capacity(n_ref * layout.n_quat);
        for &demo_t in &warps[0] {
            for item in &layout.items {
                if let Item::Quat(cols, _) = item {
                    anchors.push(quat_at(demos[0], cols, demo_t));
                }
            }
        }
        let obs: Vec<Vec<f64>> = demos
            .par_iter()
            .zip(warps.par_iter())
            .map(|(demo, warp)| observe(&layout, &anchors, demo, warp))
            .collect();
        let ranges = match &params.ranges {
            Some(r) => r.clone(),
            None => {
                let mut r = non_rate_ranges;
                let rate_range = super::stats::default_rate_range(&obs, d, &params.warp);
                r.push(
                    if rate_range < params.min_range || !rate_range.is_finite() {
                        1.0
                    } else {
                        rate_range
                    },
                );
                r
            }
        };
        let stats = batch_statistics(&obs, n_ref, d);
        let (duration_mean, duration_scatter) = match params.rate_term {
            super::RateTerm::Relative { window, .. } if window > 0 => {
                super::stats::duration_statistics(warps, window)
            }
            _ => (Vec::new(), Vec::new()),
        };
        let data = ModelData {
            channel_names: demos[0].channel_names().to_vec(),
            layout,
            dt_s: demos[0].dt_s(),
            n_ref,
            reference_idx: 0,
            k_max: params.k_max,
            ranges,
            anchors,
            count: obs.len(),
            tangent_mean: stats.tangent_mean,
            scatter: stats.scatter,
            grad_min: stats.grad_min,
            grad_max: stats.grad_max,
            rate_term: params.rate_term,
            duration_mean,
            duration_scatter,
        };
        Ok(Self::from_data(data))
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{close, demo, three_demo_model, three_demos};
    use super::*;

    #[test]
    fn hand_derived_statistics() {
        let model = three_demo_model();
        assert_eq!(model.n_ref(), 3);
        assert_eq!(model.tangent_names(), ["force", "rate"]);
        // Force range 20 N. Gradients per demonstration 1, 1, 1 | 1.5, 2.5, 2.5 | 1, 1, 1:
        // mean pace 12.5/9 = 25/18, rate range (s_max − 1)·25/18 = 3·25/18 = 25/6.
        assert_eq!(model.ranges()[0], 20.0);
        assert!(close(model.ranges()[1], 25.0 / 6.0));
        // n = 1: forces 10, 7.5, 10 (demo 1 at its time 1.5); gradients 1, 2.5, 1.
        assert!(close(model.mean()[1], 55.0 / 6.0));
        assert!(close(model.grad_mean()[1], 1.5));
        assert_eq!((model.grad_min()[1], model.grad_max()[1]), (1.0, 2.5));
        // The rate's range at sample n is 25/6 · ψ̄̇(n)/(25/18) = 3·ψ̄̇(n), so its raw term is
        // var(n)/(9·ψ̄̇(n)²): n = 0: gradients 1, 1.5, 1, mean 7/6, var 1/12 → 1/147;
        // n = 1 and 2: gradients 1, 2.5, 1, var 0.75 → 1/27. The opening over 13 samples
        // takes the least of the three everywhere: 1/147.
        assert!(close(model.grad_mean()[0], 7.0 / 6.0));
        // The duration window (97 samples) covers the whole reference at every sample: the
        // durations are 2, 4, 2 (mean 8/3, var 4/3), a term of (4/3)/(3·8/3)² = 1/48, larger
        // than the opened rate term, so the rate's part is 1/48 everywhere.
        assert!(close(model.sigma2_d()[0], 1.0 / 48.0));
        // σ²_D(1) = (25+100+25)/36 / 20² / 2 + 1/48 = 1/192 + 1/48.
        assert!(close(model.sigma2_d()[1], 1.0 / 192.0 + 1.0 / 48.0));
        // Without the duration term, the opened rate term alone.
        let (demos, warps) = three_demos();
        let without = TaskModel::fit_aligned(
            &demos,
            &warps,
            &FitParams {
                rate_term: RateTerm::RELATIVE_WITHOUT_WINDOW,
                ..FitParams::default()
            },
        )
        .unwrap();
        assert!(close(without.sigma2_d()[0], 1.0 / 147.0));
        assert!(close(without.sigma2_d()[1], 1.0 / 192.0 + 1.0 / 147.0));
        // n = 2: last gradient repeats the previous: 1, 2.5, 1.
        assert_eq!(model.grad_max()[2], 2.5);
        assert_eq!(model.n_components(), 2);
    }

    #[test]
    fn bad_fits_are_errors() {
        let (demos, warps) = three_demos();
        let p = FitParams::default();
        assert!(matches!(
            TaskModel::fit_aligned(&demos[..1], &warps[..1], &p),
            Err(Error::TooFewDemonstrations { found: 1 })
        ));
        let mut w = warps.clone();
        w[1] = vec![0.0, 3.0, 2.0];
        assert!(matches!(
            TaskModel::fit_aligned(&demos, &w, &p),
            Err(Error::BadWarp { demo_idx: 1, .. })
        ));
        w[1] = vec![0.0, 1.0, 4.5];
        assert!(matches!(
            TaskModel::fit_aligned(&demos, &w, &p),
            Err(Error::BadWarp { demo_idx: 1, .. })
        ));
        let bad = FitParams {
            k_max: 0,
            ..FitParams::default()
        };
        assert!(matches!(
            TaskModel::fit_aligned(&demos, &warps, &bad),
            Err(Error::BadParam { name: "k_max", .. })
        ));
        // A partial quaternion block is rejected.
        let q = demo(&["qx", "qy", "qz"], vec![0.0; 6]);
        let id = vec![0.0, 1.0];
        assert!(TaskModel::fit_aligned(&[q.clone(), q], &[id.clone(), id], &p).is_err());
    }
}
