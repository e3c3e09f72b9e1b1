//! Task-model invariants through the public API: gradient bounds, admissible commands,
//! incremental updates equal to a refit, alignment with `tandem-warp`.

use proptest::prelude::*;
use tandem_lfd::{Demonstration, Execution, FitParams, RateTerm, Reference, TaskModel};

const NAMES: [&str; 7] = ["x", "qx", "qy", "qz", "qw", "force", "tool"];

/// A smooth synthetic demonstration of `t_len` samples: `shape` shifts the force and the
/// tilt so demonstrations differ; the quaternion sign flips every 7 samples (q ≡ −q).
fn synthetic(t_len: usize, shape: f64) -> Demonstration {
    let mut s = Vec::with_capacity(t_len * NAMES.len());
    for t in 0..t_len {
        let p = t as f64 / (t_len - 1) as f64;
        let angle = 0.1 * shape * (3.0 * p).sin() + 0.05 * p;
        let (sin, cos) = (0.5 * angle).sin_cos();
        let sign = if (t / 7) % 2 == 0 { 1.0 } else { -1.0 };
        s.extend([
            0.6 * p,
            sign * sin * 0.6,
            sign * sin * 0.8,
            0.0,
            sign * cos,
            10.0 + 5.0 * shape * (6.0 * p).cos(),
            if p > 0.2 + 0.1 * shape { 1.0 } else { 0.0 },
        ]);
    }
    let names = NAMES.iter().map(|n| n.to_string()).collect();
    Demonstration::new(names, s, 0.01).unwrap()
}

/// A monotone warp from reference samples `0..n_ref` onto `0..t_len` with a bump of size
/// `bend ∈ (−1, 1)` (0 = linear).
fn warp(n_ref: usize, t_len: usize, bend: f64) -> Vec<f64> {
    (0..n_ref)
        .map(|n| {
            let p = n as f64 / (n_ref - 1) as f64;
            let q = p + bend * p * (1.0 - p) * 0.9;
            q * (t_len - 1) as f64
        })
        .collect()
}

fn data(shapes: &[f64], lens: &[usize], bends: &[f64]) -> (Vec<Demonstration>, Vec<Vec<f64>>) {
    let n_ref = lens[0];
    let demos = shapes
        .iter()
        .zip(lens)
        .map(|(&s, &l)| synthetic(l, s))
        .collect();
    let warps = lens
        .iter()
        .zip(bends)
        .map(|(&l, &b)| warp(n_ref, l, b))
        .collect();
    (demos, warps)
}

fn interp(v: &[f64], t: f64) -> f64 {
    let lo = (t.floor() as usize).min(v.len() - 1);
    let hi = (lo + 1).min(v.len() - 1);
    v[lo] + (t - lo as f64) * (v[hi] - v[lo])
}

#[test]
fn bounds_contain_every_demonstration_gradient() {
    let (demos, warps) = data(&[0.0, 1.0, -0.5], &[40, 55, 31], &[0.0, 0.6, -0.4]);
    let m = TaskModel::fit_aligned(&demos, &warps, &FitParams::default()).unwrap();
    for w in &warps {
        for n in 0..m.n_ref() {
            let g = if n + 1 < w.len() {
                w[n + 1] - w[n]
            } else {
                w[n] - w[n - 1]
            };
            assert!(m.grad_min()[n] <= g && g <= m.grad_max()[n], "n = {n}: {g}");
        }
    }
    assert_eq!(m.n_components(), 2);
    assert_eq!(m.channel_names(), NAMES);
    assert_eq!(m.mean().len(), 40 * NAMES.len());
}

fn assert_same_statistics(a: &TaskModel, b: &TaskModel) {
    assert_eq!(a.count(), b.count());
    assert_eq!(a.n_components(), b.n_components());
    let near = |x: f64, y: f64| (x - y).abs() <= 1e-9 * (1.0 + y.abs());
    for n in 0..a.n_ref() {
        assert!(near(a.sigma2_d()[n], b.sigma2_d()[n]), "sigma2 at {n}");
        assert!(near(a.grad_mean()[n], b.grad_mean()[n]));
        assert_eq!(a.grad_min()[n], b.grad_min()[n]);
        assert_eq!(a.grad_max()[n], b.grad_max()[n]);
        for (x, y) in a.tangent_mean(n).iter().zip(b.tangent_mean(n)) {
            assert!(near(*x, *y), "mean at {n}");
        }
        for (x, y) in a.covariance(n).iter().zip(&b.covariance(n)) {
            assert!(near(*x, *y), "covariance at {n}");
        }
    }
    for (x, y) in a.mean().iter().zip(b.mean()) {
        assert!(near(*x, *y));
    }
}

/// An execution made from a demonstration and its known warp: each sample's reference
/// time is the inverse warp at that sample.
fn execution_from(demo: &Demonstration, warp: &[f64]) -> Execution {
    let log = (0..demo.n_samples())
        .map(|q| {
            let q = q as f64;
            let k = warp.partition_point(|&v| v < q);
            if k == 0 {
                0.0
            } else if k >= warp.len() {
                (warp.len() - 1) as f64
            } else {
                (k - 1) as f64 + (q - warp[k - 1]) / (warp[k] - warp[k - 1])
            }
        })
        .collect();
    Execution {
        demonstration: demo.clone(),
        ref_time_log: log,
    }
}

#[test]
fn update_equals_refit() {
    // Every form of the rate term: the window durations are sufficient statistics too.
    for rate_term in [
        RateTerm::DEFAULT,
        RateTerm::Absolute,
        RateTerm::Relative {
            opening: 5,
            window: 9,
        },
    ] {
        update_equals_refit_with(rate_term);
    }
}

fn update_equals_refit_with(rate_term: RateTerm) {
    let (demos, warps) = data(&[0.0, 1.0, -0.5], &[40, 55, 31], &[0.0, 0.6, -0.4]);
    let fit_params = FitParams {
        rate_term,
        ..FitParams::default()
    };
    let mut model = TaskModel::fit_aligned(&demos, &warps, &fit_params).unwrap();
    assert_eq!(model.rate_term(), rate_term);
    let params = FitParams {
        ranges: Some(model.ranges().to_vec()),
        ..fit_params
    };
    let mut all_demos = demos.clone();
    let mut all_warps = warps.clone();
    for (shape, len, bend) in [(0.7, 47, 0.3), (-1.2, 36, -0.7)] {
        let exec = execution_from(&synthetic(len, shape), &warp(40, len, bend));
        let values = model.execution_warp(&exec).unwrap();
        // The execution's warp recovered from its log is the warp it was made from, up to
        // the log's piecewise-linear sampling.
        for (v, w) in values.iter().zip(warp(40, len, bend)) {
            assert!((v - w).abs() < 0.05, "{v} vs {w}");
        }
        model.prepare_corrections();
        model.update(&exec).unwrap();
        all_demos.push(exec.demonstration.clone());
        all_warps.push(values);
        let refit = TaskModel::fit_aligned(&all_demos, &all_warps, &params).unwrap();
        assert_same_statistics(&model, &refit);
        // And the same model through its serde form (the window durations included).
        let back: TaskModel =
            serde_json::from_str(&serde_json::to_string(&model).unwrap()).unwrap();
        assert_eq!(back.rate_term(), rate_term);
        assert_eq!(back.sigma2_d(), model.sigma2_d());
        assert_eq!(
            model.command(&[0.3, -0.2, 0.9], 17.5).unwrap().len(),
            NAMES.len() + 1
        );
        let c = model.corrections_at(17.5).unwrap();
        let r = refit.corrections_at(17.5).unwrap();
        assert!((c.scale - r.scale).abs() < 1e-9);
    }
    assert_eq!(model.count(), 5);
}

#[test]
fn fit_with_alignment_recovers_known_timing() {
    // Demo 1 is demo 0 played 1.5× slower (same shape over 90 instead of 60 samples):
    // its warp gradient is 89/59 ≈ 1.51 everywhere.
    let d0 = synthetic(60, 1.0);
    let d1 = synthetic(90, 1.0);
    let m = TaskModel::fit(&[d0.clone(), d1, d0], &FitParams::default()).unwrap();
    let mid: Vec<f64> = m.grad_max()[5..55].to_vec();
    let avg = mid.iter().sum::<f64>() / mid.len() as f64;
    assert!((avg - 89.0 / 59.0).abs() < 0.1, "mean max gradient {avg}");
    assert!(m.grad_min()[5..55].iter().all(|&g| (g - 1.0).abs() < 0.05));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn commanded_rate_stays_inside_the_bounds(
        shapes in prop::collection::vec(-1.5f64..1.5, 2..5),
        bends in prop::collection::vec(-0.9f64..0.9, 4),
        lens in prop::collection::vec(12usize..40, 4),
        u in prop::collection::vec(-1.0f64..=1.0, 3),
        t_frac in 0.0f64..=1.0,
        k_max in 1usize..4,
    ) {
        let n_d = shapes.len();
        let (demos, warps) = data(&shapes, &lens[..n_d], &bends[..n_d]);
        let params = FitParams { k_max, ..FitParams::default() };
        let m = TaskModel::fit_aligned(&demos, &warps, &params).unwrap();
        let k = m.n_components();
        prop_assert_eq!(k, k_max.min(n_d - 1));
        let t = t_frac * (m.n_ref() - 1) as f64;
        let cmd = m.command(&u[..k], t).unwrap();
        let rate = cmd[NAMES.len()];
        let (lo, hi) = (interp(m.grad_min(), t), interp(m.grad_max(), t));
        prop_assert!(lo - 1e-12 <= rate && rate <= hi + 1e-12, "{} not in [{}, {}]", rate, lo, hi);
        // The admissible scale alone (no clamping needed) keeps the rate inside.
        let c = m.corrections_at(t).unwrap();
        let reach: f64 = c.components.iter().map(|v| v[v.len() - 1].abs()).sum::<f64>() * c.scale;
        let g = interp(m.grad_mean(), t);
        prop_assert!(g + reach <= hi + 1e-9 && g - reach >= lo - 1e-9);
        let q = &cmd[1..5];
        prop_assert!((q.iter().map(|v| v * v).sum::<f64>().sqrt() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn update_equals_refit_for_any_execution(
        shape in -1.5f64..1.5,
        // From about the fastest demonstrated speed to well past the slowest: an execution
        // faster than half the fastest is refused (`EXECUTION_DURATION_RATIO`).
        len in 20usize..60,
        bend in -0.9f64..0.9,
        window in prop::sample::select(vec![0usize, 3, 7, 13]),
    ) {
        let (demos, warps) = data(&[0.0, 1.0], &[30, 44], &[0.0, 0.5]);
        let fit_params = FitParams {
            rate_term: RateTerm::Relative { opening: RateTerm::DEFAULT_OPENING, window },
            ..FitParams::default()
        };
        let mut model = TaskModel::fit_aligned(&demos, &warps, &fit_params).unwrap();
        let exec = execution_from(&synthetic(len, shape), &warp(30, len, bend));
        let values = model.execution_warp(&exec).unwrap();
        model.update(&exec).unwrap();
        let params = FitParams { ranges: Some(model.ranges().to_vec()), ..fit_params };
        let refit = TaskModel::fit_aligned(
            &[demos[0].clone(), demos[1].clone(), exec.demonstration.clone()],
            &[warps[0].clone(), warps[1].clone(), values],
            &params,
        ).unwrap();
        assert_same_statistics(&model, &refit);
    }
}

#[test]
fn correction_components_are_sign_continuous() {
    let (demos, warps) = data(
        &[0.0, 1.0, -0.5, 0.8],
        &[50, 61, 44, 57],
        &[0.0, 0.6, -0.4, 0.2],
    );
    let m = TaskModel::fit_aligned(&demos, &warps, &FitParams::default()).unwrap();
    assert_eq!(m.n_components(), 3);
    let r = m.ranges().to_vec();
    let scaled = |t: usize, k: usize| -> Vec<f64> {
        let c = m.corrections_at(t as f64).unwrap();
        c.components[k].iter().zip(&r).map(|(c, r)| c / r).collect()
    };
    for n in 1..m.n_ref() {
        for k in 0..3 {
            let (a, b) = (scaled(n - 1, k), scaled(n, k));
            let dot: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
            assert!(dot >= 0.0, "component {k} flips between {} and {n}", n - 1);
        }
    }
}

#[test]
fn results_do_not_depend_on_thread_count() {
    let (demos, _) = data(&[0.0, 1.0, -0.5], &[40, 55, 31], &[0.0, 0.6, -0.4]);
    for reference in [Reference::First, Reference::Medoid] {
        let params = FitParams {
            reference,
            ..FitParams::default()
        };
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let m = TaskModel::fit(&demos, &params).unwrap();
                let c = m.corrections_at(12.25).unwrap();
                (serde_json::to_string(&m).unwrap(), c)
            })
        };
        let (a, ca) = run(1);
        let (b, cb) = run(3);
        assert_eq!(a, b, "{reference}");
        assert_eq!(ca, cb, "{reference}");
    }
}

/// One force channel: a plateau of height 10 N starting at `start` (fraction of the length)
/// and lasting a quarter of it, on `len` samples.
fn plateau(len: usize, start: f64) -> Demonstration {
    let s: Vec<f64> = (0..len)
        .map(|t| {
            let p = t as f64 / (len - 1) as f64;
            if (start..start + 0.25).contains(&p) {
                10.0
            } else {
                0.0
            }
        })
        .collect();
    Demonstration::new(vec!["force".into()], s, 0.01).unwrap()
}

/// Four plateau demonstrations of different lengths and timings.
fn plateaus() -> Vec<Demonstration> {
    vec![
        plateau(60, 0.10),
        plateau(70, 0.45),
        plateau(64, 0.30),
        plateau(58, 0.60),
    ]
}

fn medoid_params() -> FitParams {
    FitParams {
        reference: Reference::Medoid,
        // Explicit weights, so the test can recompute every candidate's cost with tandem-warp.
        warp: tandem_warp::WarpParams {
            weights: Some(vec![1.0]),
            ..tandem_warp::WarpParams::default()
        },
        ..FitParams::default()
    }
}

#[test]
fn medoid_is_the_reference_with_the_least_median_variance() {
    let demos = plateaus();
    let params = medoid_params();
    let model = TaskModel::fit(&demos, &params).unwrap();
    // Each candidate fitted as the first demonstration given (the others in any order give
    // the same statistics up to rounding): the median of its σ²_D.
    let median_of = |r: usize| -> f64 {
        let mut given = vec![demos[r].clone()];
        given.extend(
            (0..demos.len())
                .filter(|&j| j != r)
                .map(|j| demos[j].clone()),
        );
        let first = FitParams {
            reference: Reference::First,
            ..params.clone()
        };
        let mut s2 = TaskModel::fit(&given, &first).unwrap().sigma2_d().to_vec();
        s2.sort_by(f64::total_cmp);
        s2[s2.len() / 2]
    };
    let medians: Vec<f64> = (0..demos.len()).map(median_of).collect();
    let argmin = (0..demos.len())
        .min_by(|&a, &b| medians[a].total_cmp(&medians[b]))
        .unwrap();
    assert_eq!(model.reference_idx(), argmin, "medians {medians:?}");
    assert_eq!(model.n_ref(), demos[argmin].n_samples());
    let reported = TaskModel::reference_costs(&demos, &params).unwrap();
    for (a, b) in reported.iter().zip(&medians) {
        assert!(
            (a - b).abs() <= 1e-9 * b.abs(),
            "{reported:?} vs {medians:?}"
        );
    }
    // The chosen model's own median is the least reported.
    let mut own = model.sigma2_d().to_vec();
    own.sort_by(f64::total_cmp);
    assert_eq!(own[own.len() / 2], reported[argmin]);
    // First: demo 0, whatever the criterion.
    let first = FitParams {
        reference: Reference::First,
        ..params.clone()
    };
    assert_eq!(TaskModel::fit(&demos, &first).unwrap().reference_idx(), 0);
}

#[test]
fn medoid_model_does_not_depend_on_the_order_of_the_demonstrations() {
    let demos = plateaus();
    let params = medoid_params();
    let model = TaskModel::fit(&demos, &params).unwrap();
    let json = serde_json::to_string(&model).unwrap();
    let reference = &demos[model.reference_idx()];
    for order in [[3, 2, 1, 0], [2, 0, 3, 1], [1, 3, 0, 2]] {
        let shuffled: Vec<Demonstration> = order.iter().map(|&i| demos[i].clone()).collect();
        let other = TaskModel::fit(&shuffled, &params).unwrap();
        assert_eq!(&shuffled[other.reference_idx()], reference);
        // Bit-identical statistics (the reference index itself is where it was given).
        let same = serde_json::to_string(&other).unwrap().replace(
            &format!("\"reference_idx\":{}", other.reference_idx()),
            &format!("\"reference_idx\":{}", model.reference_idx()),
        );
        assert_eq!(same, json, "order {order:?}");
    }
    // First depends on the order: another first demonstration, another time axis.
    let first = FitParams {
        reference: Reference::First,
        ..params
    };
    let a = TaskModel::fit(&demos, &first).unwrap();
    let b = TaskModel::fit(&[demos[3].clone(), demos[0].clone()], &first).unwrap();
    assert_ne!(a.n_ref(), b.n_ref());
}

#[test]
fn fit_aligned_takes_demo_0_as_the_reference_whatever_the_choice() {
    let (demos, warps) = data(&[0.0, 1.0], &[30, 44], &[0.0, 0.5]);
    let medoid = TaskModel::fit_aligned(&demos, &warps, &medoid_params()).unwrap();
    let first = FitParams {
        reference: Reference::First,
        ..medoid_params()
    };
    let m = TaskModel::fit_aligned(&demos, &warps, &first).unwrap();
    assert_eq!((m.reference_idx(), medoid.reference_idx()), (0, 0));
    assert_eq!(m.sigma2_d(), medoid.sigma2_d());
    assert_eq!(m.n_ref(), 30);
}
