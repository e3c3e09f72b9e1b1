//! Property tests: every returned warp is monotone, pinned at both ends, within the slope bounds,
//! and reports the objective of its own values.

use proptest::prelude::*;
use tandem_warp::{SignalRef, WarpParams, align, objective_of};

fn signal(max_len: usize) -> impl Strategy<Value = (Vec<f64>, usize)> {
    (1usize..=3, 2usize..=max_len)
        .prop_flat_map(|(nc, len)| (prop::collection::vec(-10.0f64..10.0, nc * len), Just(nc)))
}

fn params() -> impl Strategy<Value = WarpParams> {
    (
        0.05f64..=1.0,
        1.0f64..6.0,
        0.0f64..2.0,
        0.0f64..2.0,
        3usize..25,
        0usize..4,
        prop::option::of(2usize..80),
        prop::option::of(0usize..6),
        2usize..40,
    )
        .prop_map(
            |(s_min, s_max, li, lc, m, refinements, n_nodes, max_jump, coarse)| WarpParams {
                n_nodes,
                n_candidates: m,
                lambda_inst: li,
                lambda_cum: lc,
                slope_min: s_min,
                slope_max: s_max,
                refinements,
                max_jump,
                coarse_nodes: coarse,
                coarse_candidates: m + 2,
                ..Default::default()
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]
    #[test]
    fn warps_are_monotone_pinned_and_slope_bounded(
        (r, nc) in signal(70),
        qlen in 2usize..90,
        qseed in prop::collection::vec(-10.0f64..10.0, 3 * 90),
        p in params(),
    ) {
        let q = &qseed[..qlen * nc];
        let rs = SignalRef::new(&r, nc).unwrap();
        let qs = SignalRef::new(q, nc).unwrap();
        let w = align(rs, qs, &p).unwrap();
        let v = w.values();
        let (nr, nq) = (rs.n_samples(), qs.n_samples());
        prop_assert_eq!(v.len(), nr);
        prop_assert_eq!(v[0], 0.0);
        prop_assert_eq!(v[nr - 1], (nq - 1) as f64);
        let g = (nq - 1) as f64 / (nr - 1) as f64;
        for (n, d) in v.windows(2).map(|x| x[1] - x[0]).enumerate() {
            let slope = d / g; // normalized φ'
            prop_assert!(d > 0.0, "not increasing at {}: {:?}", n, &v[n..n + 2]);
            prop_assert!(slope >= p.slope_min * (1.0 - 1e-7), "slope {} < s_min {} at {}", slope, p.slope_min, n);
            prop_assert!(slope <= p.slope_max * (1.0 + 1e-7), "slope {} > s_max {} at {}", slope, p.slope_max, n);
        }
        let direct = objective_of(rs, qs, v, &p).unwrap();
        prop_assert!((direct - w.objective()).abs() <= 1e-9 * direct.abs().max(1e-12));
        prop_assert!(w.gradient().iter().all(|&x| x > 0.0));
    }
}
