//! Property tests: every returned warp is monotone, pinned at both ends, within the slope bounds,
//! and reports the objective of its own values, with and without the fill of flat stretches
//! (also on signals made of plateaus, where most samples are flat).

use proptest::prelude::*;
use tandem_warp::{SignalRef, WarpParams, align, objective_of};

fn signal(max_len: usize) -> impl Strategy<Value = (Vec<f64>, usize)> {
    (1usize..=3, 2usize..=max_len)
        .prop_flat_map(|(nc, len)| (prop::collection::vec(-10.0f64..10.0, nc * len), Just(nc)))
}

/// Plateaus of random levels and lengths, joined by ramps of a few samples, with a little noise:
/// long flat stretches that the fill replaces.
fn plateaus(max_len: usize) -> impl Strategy<Value = (Vec<f64>, usize)> {
    (
        1usize..=3,
        20usize..=max_len,
        prop::collection::vec((-5.0f64..5.0, 5usize..60, 1usize..6), 2..8),
        prop::collection::vec(-0.01f64..0.01, 3 * max_len),
    )
        .prop_map(|(nc, len, pieces, noise)| {
            let mut x = Vec::with_capacity(nc * len);
            let mut level = 0.0;
            'fill: for (to, hold, ramp) in pieces.iter().cycle() {
                for k in 1..=*ramp {
                    if x.len() == nc * len {
                        break 'fill;
                    }
                    let v = level + (to - level) * k as f64 / *ramp as f64;
                    x.extend((0..nc).map(|c| v * (c + 1) as f64));
                }
                for _ in 0..*hold {
                    if x.len() == nc * len {
                        break 'fill;
                    }
                    x.extend((0..nc).map(|c| to * (c + 1) as f64));
                }
                level = *to;
            }
            for (v, e) in x.iter_mut().zip(&noise) {
                *v += e;
            }
            (x, nc)
        })
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
        prop_oneof![Just(0.0), 0.001f64..1.0],
    )
        .prop_map(
            |(s_min, s_max, li, lc, m, refinements, n_nodes, max_jump, coarse, fill)| WarpParams {
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
                fill_length: fill,
                ..Default::default()
            },
        )
}

/// The invariants of every warp `align` returns.
fn check(r: &[f64], q: &[f64], nc: usize, p: &WarpParams) -> Result<(), TestCaseError> {
    let rs = SignalRef::new(r, nc).unwrap();
    let qs = SignalRef::new(q, nc).unwrap();
    let w = align(rs, qs, p).unwrap();
    let v = w.values();
    let (nr, nq) = (rs.n_samples(), qs.n_samples());
    prop_assert_eq!(v.len(), nr);
    prop_assert_eq!(v[0], 0.0);
    prop_assert_eq!(v[nr - 1], (nq - 1) as f64);
    let g = (nq - 1) as f64 / (nr - 1) as f64;
    for (n, d) in v.windows(2).map(|x| x[1] - x[0]).enumerate() {
        let slope = d / g; // normalized φ'
        prop_assert!(d > 0.0, "not increasing at {}: {:?}", n, &v[n..n + 2]);
        prop_assert!(
            slope >= p.slope_min * (1.0 - 1e-7),
            "slope {} < s_min {} at {}",
            slope,
            p.slope_min,
            n
        );
        prop_assert!(
            slope <= p.slope_max * (1.0 + 1e-7),
            "slope {} > s_max {} at {}",
            slope,
            p.slope_max,
            n
        );
    }
    let direct = objective_of(rs, qs, v, p).unwrap();
    prop_assert!((direct - w.objective()).abs() <= 1e-9 * direct.abs().max(1e-12));
    prop_assert!(w.gradient().iter().all(|&x| x > 0.0));
    Ok(())
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
        check(&r, &qseed[..qlen * nc], nc, &p)?;
    }

    #[test]
    fn filled_warps_of_plateaus_are_monotone_pinned_and_slope_bounded(
        (r, nc) in plateaus(200),
        (q, nq_c) in plateaus(260),
        p in params(),
    ) {
        // the query with the reference's channel count
        let q: Vec<f64> = q.chunks(nq_c).flat_map(|s| (0..nc).map(move |c| s[c % s.len()])).collect();
        check(&r, &q, nc, &p)?;
    }
}
