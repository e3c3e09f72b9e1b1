//! Property tests: observation mass is conserved by the fractional split, the latch only
//! ever adds high-confidence samples, and every latched decision equals a direct statrs
//! evaluation of Eq. 12.

use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tandem_confidence::{
    Confidence, ConfidenceParams, Observations, estimate_error_rates, evaluate, posterior,
};

/// One execution over `n_ref` samples: supervised times (fractional) and corrections.
fn execution(rng: &mut ChaCha8Rng, n_ref: usize, p_corr: f64) -> (Vec<f64>, Vec<bool>) {
    let t_max = (n_ref - 1) as f64;
    let mut times = Vec::new();
    let mut t = rng.random_range(0.0..0.5);
    while t <= t_max {
        times.push(t);
        t += rng.random_range(0.5..1.5);
    }
    // Hit both ends exactly sometimes.
    if rng.random_bool(0.3) {
        times.push(t_max);
        times.push(0.0);
    }
    let corrected = times.iter().map(|_| rng.random_bool(p_corr)).collect();
    (times, corrected)
}

proptest! {
    #[test]
    fn split_conserves_mass(n_ref in 1_usize..40, n_exec in 0_usize..20, seed in any::<u64>()) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut obs = Observations::new(n_ref).unwrap();
        let (mut n_obs, mut n_corr) = (0_usize, 0_usize);
        for _ in 0..n_exec {
            let (times, corrected) = execution(&mut rng, n_ref, 0.3);
            n_obs += times.len();
            n_corr += corrected.iter().filter(|&&c| c).count();
            obs.record(&times, &corrected).unwrap();
        }
        let tol = 1e-12 * (n_obs.max(1) as f64);
        prop_assert!((obs.total_supervised() - n_obs as f64).abs() <= tol);
        prop_assert!((obs.total_corrections() - n_corr as f64).abs() <= tol);
        for (n, (&c, &s)) in obs.corrections().iter().zip(obs.supervised()).enumerate() {
            prop_assert!(c >= 0.0 && c <= s, "sample {}: {} > {}", n, c, s);
        }
    }

    #[test]
    fn latch_is_monotone_and_decisions_equal_statrs(
        n_ref in 1_usize..10,
        steps in 1_usize..8,
        p_corr in prop_oneof![Just(0.0), Just(0.01), Just(0.3)],
        seed in any::<u64>(),
    ) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let params = ConfidenceParams::paper();
        let mut conf = Confidence::new(n_ref, params.clone()).unwrap();
        let mut obs = Observations::new(n_ref).unwrap();
        for _ in 0..steps {
            // Variances that may jump up or down between updates.
            let sigma2_d: Vec<f64> = (0..n_ref)
                .map(|_| match rng.random_range(0..4) {
                    0 => 0.0,
                    1 => rng.random_range(0.0..0.02),
                    2 => rng.random_range(0.0..0.2),
                    _ => rng.random_range(0.0..20.0),
                })
                .collect();
            for _ in 0..rng.random_range(0..40) {
                let (times, corrected) = execution(&mut rng, n_ref, p_corr);
                obs.record(&times, &corrected).unwrap();
            }
            let before = conf.conf().to_vec();
            let newly = conf.update(&sigma2_d, &obs).unwrap();
            let post = posterior(&sigma2_d, &obs, &params).unwrap();
            let mut count = 0;
            for n in 0..n_ref {
                let fresh = post[n].is_high_confidence(&params).unwrap();
                // Latched samples stay; the others take exactly statrs' decision.
                prop_assert_eq!(conf.conf()[n], before[n] || fresh, "sample {}", n);
                count += usize::from(!before[n] && fresh);
            }
            prop_assert_eq!(newly, count);
        }
    }

    #[test]
    fn with_error_rates_the_latch_is_monotone_and_decisions_are_eq_12_at_the_shifted_mu(
        n_ref in 1_usize..10,
        steps in 1_usize..8,
        p_corr in prop_oneof![Just(0.0), Just(0.01), Just(0.05), Just(0.3)],
        votes in any::<bool>(),
        seed in any::<u64>(),
    ) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let params = ConfidenceParams::default();
        let mut conf = Confidence::new(n_ref, params.clone()).unwrap();
        let mut obs = Observations::new(n_ref).unwrap();
        for _ in 0..steps {
            let sigma2_d: Vec<f64> = (0..n_ref)
                .map(|_| match rng.random_range(0..3) {
                    0 => 0.0,
                    1 => rng.random_range(0.0..0.2),
                    _ => rng.random_range(0.0..20.0),
                })
                .collect();
            for _ in 0..rng.random_range(0..40) {
                let (times, corrected) = execution(&mut rng, n_ref, p_corr);
                if votes {
                    obs.record_votes(&times, &corrected).unwrap();
                } else {
                    obs.record(&times, &corrected).unwrap();
                }
            }
            let rates = estimate_error_rates(&obs, &params).unwrap();
            prop_assert!((0.0..0.5).contains(&rates.false_correction_rate));
            prop_assert!((0.0..0.5).contains(&rates.miss_rate));
            // Eq. 12 with mu_c replaced by mu'_c = f + (1 - f - m) mu_c, evaluated directly.
            let shifted = ConfidenceParams { mu_c: rates.shifted_mu_c(params.mu_c), ..ConfidenceParams::paper() };
            let before = conf.conf().to_vec();
            conf.update(&sigma2_d, &obs).unwrap();
            let post = posterior(&sigma2_d, &obs, &params).unwrap();
            let unlatched = evaluate(&sigma2_d, &obs, &params).unwrap();
            for n in 0..n_ref {
                let fresh = post[n].is_high_confidence(&shifted).unwrap();
                prop_assert_eq!(unlatched[n], fresh, "sample {}", n);
                prop_assert_eq!(conf.conf()[n], before[n] || fresh, "sample {}", n);
            }
        }
    }
}
