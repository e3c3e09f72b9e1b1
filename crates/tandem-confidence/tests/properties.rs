//! Property tests: observation mass is conserved by the fractional split, the latch only
//! ever adds high-confidence samples, every latched decision equals a direct statrs
//! evaluation of Eq. 12, `conf` is the latch less the prior's trust that yields to a need on
//! both sides evaluated on the totals, and every order of the same rounds gives the same
//! confidence on every sample.

use proptest::prelude::*;
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tandem_confidence::{
    Confidence, ConfidenceParams, MIN_VOTES, Observations, estimate_error_rates, evaluate,
    posterior, prob_need_below_mu_c,
};

/// Rests on its prior alone: no correction and fewer than `MIN_VOTES` votes.
fn on_prior(obs: &Observations, n: usize) -> bool {
    obs.corrections()[n] == 0.0 && obs.supervised()[n] < MIN_VOTES
}

/// `conf` as the `Confidence` type docs define it from a latch and the totals, written out
/// again here: the latch less every maximal run of latched samples resting on their prior
/// alone whose neighbours on both sides are not latched and are needed by their totals (a
/// correction and `P(π < μ_c | data) < 1 − γ_c`).
fn latch_less_yield(
    latch: &[bool],
    sigma2_d: &[f64],
    obs: &Observations,
    params: &ConfidenceParams,
) -> Vec<bool> {
    let mut conf = latch.to_vec();
    if !params.one_vote_per_execution {
        return conf;
    }
    let below = prob_need_below_mu_c(sigma2_d, obs, params).unwrap();
    let needed =
        |m: usize| !latch[m] && obs.corrections()[m] > 0.0 && below[m] < 1.0 - params.gamma_c;
    let trusted = |n: usize| latch[n] && on_prior(obs, n);
    let mut n = 0;
    while n < latch.len() {
        if !trusted(n) {
            n += 1;
            continue;
        }
        let start = n;
        while n < latch.len() && trusted(n) {
            n += 1;
        }
        if start > 0 && n < latch.len() && needed(start - 1) && needed(n) {
            conf[start..n].fill(false);
        }
    }
    conf
}

/// Whether some sample high in `conf` rests on its prior alone between two needed samples:
/// what the yield leaves none of (fails with the yield removed).
fn trusted_between_needs(
    conf: &[bool],
    sigma2_d: &[f64],
    obs: &Observations,
    params: &ConfidenceParams,
) -> bool {
    latch_less_yield(conf, sigma2_d, obs, params) != conf
}

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
            // The paper's counting has no yield: `conf` is the latch.
            prop_assert_eq!(conf.conf(), conf.latched());
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
            let before = conf.latched().to_vec();
            conf.update(&sigma2_d, &obs).unwrap();
            let post = posterior(&sigma2_d, &obs, &params).unwrap();
            let unlatched = evaluate(&sigma2_d, &obs, &params).unwrap();
            for n in 0..n_ref {
                // Eq. 12 at mu'_c, on MIN_VOTES votes at least once a sample was supervised.
                let s = obs.supervised()[n];
                let fresh = post[n].is_high_confidence(&shifted).unwrap()
                    && (s == 0.0 || s >= MIN_VOTES);
                prop_assert_eq!(unlatched[n], fresh, "sample {}", n);
                prop_assert_eq!(conf.latched()[n], before[n] || fresh, "sample {}", n);
            }
            // `conf` is the latch less the yield on these totals, and a state restored from
            // its latch is refreshed to the same `conf`.
            let view = latch_less_yield(conf.latched(), &sigma2_d, &obs, &params);
            prop_assert_eq!(conf.conf(), view.as_slice());
            if votes {
                prop_assert!(!trusted_between_needs(conf.conf(), &sigma2_d, &obs, &params));
            }
            let mut restored = Confidence::from_parts(params.clone(), conf.latched().to_vec()).unwrap();
            restored.refresh(&sigma2_d, &obs).unwrap();
            prop_assert_eq!(&restored, &conf);
        }
    }

    /// The same executions, each its own round, in any order: with a fixed prior and fixed
    /// error rates the latch that yields to corrections ends at the totals' decision, which
    /// no order changes (Eq. 12 rises with clean mass at fixed corrections, so a sample
    /// latched before its last correction is decided again on the totals, and one latched
    /// after it passes on the totals too). `conf`, the latch less the prior's trust that
    /// yields to a need on both sides, is a function of that latch and the totals, so every
    /// order gives the same confidence on every sample.
    #[test]
    fn with_a_fixed_prior_and_rates_any_order_ends_at_the_totals_decision(
        n_ref in 1_usize..8,
        n_exec in 1_usize..40,
        p_corr in prop_oneof![Just(0.05), Just(0.2), Just(0.5)],
        votes in any::<bool>(),
        seed in any::<u64>(),
    ) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let params = ConfidenceParams {
            mu_c: 0.3,
            gamma_c: 0.5,
            estimate_error_rates: false,
            ..ConfidenceParams::default()
        };
        let sigma2_d: Vec<f64> = (0..n_ref).map(|_| rng.random_range(0.0..1.0)).collect();
        let executions: Vec<_> = (0..n_exec)
            .map(|_| execution(&mut rng, n_ref, p_corr))
            .collect();
        let record = |obs: &mut Observations, (t, c): &(Vec<f64>, Vec<bool>)| {
            if votes { obs.record_votes(t, c) } else { obs.record(t, c) }
        };
        let mut order: Vec<usize> = (0..n_exec).collect();
        let mut finals = Vec::new();
        let from_prior = Confidence::from_prior(&sigma2_d, params.clone()).unwrap().conf().to_vec();
        for _ in 0..20 {
            let mut conf = Confidence::from_prior(&sigma2_d, params.clone()).unwrap();
            let mut obs = Observations::new(n_ref).unwrap();
            for &k in &order {
                let before = obs.clone();
                record(&mut obs, &executions[k]).unwrap();
                conf.update_round(&sigma2_d, &before, &obs).unwrap();
            }
            // Sums in another order differ in the last bits only: the decision is the
            // totals' whichever order summed them, except that a sample trusted from its
            // prior and never corrected keeps the latch although it has fewer than
            // MIN_VOTES votes (they are asked of samples that earn their trust).
            let totals = evaluate(&sigma2_d, &obs, &params).unwrap();
            let expected: Vec<bool> = (0..n_ref)
                .map(|n| totals[n] || (from_prior[n] && obs.corrections()[n] == 0.0))
                .collect();
            prop_assert_eq!(conf.latched(), expected.as_slice(), "order {:?}", order);
            let view = latch_less_yield(&expected, &sigma2_d, &obs, &params);
            prop_assert_eq!(conf.conf(), view.as_slice(), "order {:?}", order);
            finals.push(conf.clone());
            order.shuffle(&mut rng);
        }
        // Every order: the same latch and the same confidence on every sample.
        for other in &finals[1..] {
            prop_assert_eq!(other, &finals[0]);
        }
    }

    /// The order test where the yield happens: a stretch trusted from its prior (the
    /// demonstrations agree there) inside a need that the operator corrects on both sides,
    /// with rounds that supervise the stretch a few times and rounds that are clean
    /// everywhere, in many orders. Every order gives the same confidence on every sample.
    #[test]
    fn every_order_of_rounds_around_a_prior_trusted_need_gives_one_confidence(
        n_ref in 6_usize..14,
        n_rounds in 2_usize..12,
        seed in any::<u64>(),
    ) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let params = ConfidenceParams { estimate_error_rates: rng.random_bool(0.5), ..ConfidenceParams::default() };
        // Varying at the borders of a stretch [a, b) that agrees.
        let a = rng.random_range(1..n_ref - 3);
        let b = rng.random_range(a + 1..n_ref - 1);
        let sigma2_d: Vec<f64> = (0..n_ref)
            .map(|n| if n == a - 1 || n == b { 10.0 } else { 0.0 })
            .collect();
        let rounds: Vec<(Vec<f64>, Vec<bool>)> = (0..n_rounds)
            .map(|_| {
                let samples: Vec<usize> = match rng.random_range(0..3) {
                    // The borders, corrected (the need the prior cannot see).
                    0 => vec![a - 1, b],
                    // Some of the stretch, mostly clean.
                    1 => (a..b).filter(|_| rng.random_bool(0.5)).collect(),
                    // Everything, clean or corrected at random.
                    _ => (0..n_ref).collect(),
                };
                let corrected = samples
                    .iter()
                    .map(|&n| if n == a - 1 || n == b { rng.random_bool(0.8) } else { rng.random_bool(0.05) })
                    .collect();
                (samples.iter().map(|&n| n as f64).collect(), corrected)
            })
            .collect();
        let mut order: Vec<usize> = (0..n_rounds).collect();
        let mut finals: Vec<Confidence> = Vec::new();
        for _ in 0..12 {
            let mut conf = Confidence::from_prior(&sigma2_d, params.clone()).unwrap();
            let mut obs = Observations::new(n_ref).unwrap();
            for &k in &order {
                let before = obs.clone();
                obs.record_votes(&rounds[k].0, &rounds[k].1).unwrap();
                conf.update_round(&sigma2_d, &before, &obs).unwrap();
                prop_assert!(!trusted_between_needs(conf.conf(), &sigma2_d, &obs, &params));
            }
            if let Some(first) = finals.first() {
                prop_assert_eq!(&conf, first, "order {:?}", order);
            }
            finals.push(conf);
            order.shuffle(&mut rng);
        }
    }

    #[test]
    fn update_round_without_new_observations_is_update(
        n_ref in 1_usize..10,
        seed in any::<u64>(),
    ) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let params = ConfidenceParams::default();
        let sigma2_d: Vec<f64> = (0..n_ref).map(|_| rng.random_range(0.0..2.0)).collect();
        let mut obs = Observations::new(n_ref).unwrap();
        for _ in 0..rng.random_range(0..60) {
            let (t, c) = execution(&mut rng, n_ref, 0.1);
            obs.record_votes(&t, &c).unwrap();
        }
        let mut a = Confidence::from_prior(&sigma2_d, params.clone()).unwrap();
        let mut b = a.clone();
        let prior = a.conf().to_vec();
        let newly = a.update(&sigma2_d, &obs).unwrap();
        let round = b.update_round(&sigma2_d, &obs, &obs).unwrap();
        prop_assert_eq!(&a, &b);
        prop_assert_eq!(round.newly_high, newly);
        // Nothing latched is reopened without new corrections; what turns low is the prior's
        // trust yielding to a need on both sides (latched, resting on its prior).
        let turned_low: Vec<usize> = (0..n_ref).filter(|&n| prior[n] && !b.conf()[n]).collect();
        prop_assert_eq!(round.reopened, turned_low.len());
        for &n in &turned_low {
            prop_assert!(b.latched()[n] && on_prior(&obs, n), "sample {}", n);
        }
        // `before` that is not an earlier state is refused, naming the sample.
        if obs.total_supervised() > 0.0 {
            let empty = Observations::new(n_ref).unwrap();
            let err = b.update_round(&sigma2_d, &obs, &empty).unwrap_err();
            prop_assert!(err.to_string().contains("pass the observations as they were before"), "{}", err);
        }
    }
}
