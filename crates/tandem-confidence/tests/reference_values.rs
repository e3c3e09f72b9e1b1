//! Prior, posterior and Eq. 12 decisions against values computed independently at high
//! precision.
//!
//! Source of every reference number: Python mpmath 1.3.0 at `mp.dps = 30`, with
//! `g = -expm1(-gamma_p*(s2d+eps))`, `mu = g/2`, `var = sigma2_max*g`,
//! `k = mu*(1-mu)/var - 1`, `alpha0 = mu*k`, `beta0 = (1-mu)*k` (Eq. 10–11 literally) and
//! `I_x(a, b) = mp.betainc(a, b, 0, x, regularized=True)`; printed to 20–25 digits and
//! rounded to the 17 significant digits written here.

use tandem_confidence::{
    BetaParams, Confidence, ConfidenceParams, Observations, evaluate, posterior, prior,
};

fn assert_rel(got: f64, want: f64, rel: f64, what: &str) {
    assert!(
        (got - want).abs() <= rel * want.abs(),
        "{what}: got {got:e}, want {want:e}"
    );
}

#[test]
fn prior_matches_mpmath() {
    let p = ConfidenceParams::paper();
    // (sigma2_d, alpha0, beta0, mean, variance)
    let cases = [
        (
            0.0,
            4.499_952_500_324_998e-5,
            8.999_905_000_724_996,
            4.999_975_000_083_333e-6,
            4.999_975_000_083_333e-7,
        ),
        (
            0.001,
            0.044_572_292_826_847_46,
            8.905_627_373_674_817,
            0.004_980_033_349_833_555,
            4.980_033_349_833_555e-4,
        ),
        (
            0.01,
            0.405_628_238_286_847_1,
            8.118_513_610_248_258,
            0.047_585_815_146_489_53,
            0.004_758_581_514_648_953,
        ),
        (
            0.05,
            1.383_582_088_077_695_6,
            5.649_040_884_104_118,
            0.196_737_702_781_818_64,
            0.019_673_770_278_181_864,
        ),
        (
            0.1,
            1.845_606_439_802_675_2,
            3.993_772_372_174_447_4,
            0.316_062_118_802_287_74,
            0.031_606_211_880_228_774,
        ),
        (
            0.5,
            2.003_255_442_255_544,
            2.030_433_955_844_218,
            0.496_631_060_190_023_8,
            0.049_663_106_019_002_38,
        ),
        (10.0, 2.0, 2.0, 0.5, 0.05),
    ];
    let s2: Vec<f64> = cases.iter().map(|c| c.0).collect();
    let priors = prior(&s2, &p).unwrap();
    for (b, &(s, alpha, beta, mean, var)) in priors.iter().zip(&cases) {
        let what = format!("sigma2_d = {s}");
        assert_rel(b.alpha(), alpha, 1e-12, &what);
        assert_rel(b.beta(), beta, 1e-12, &what);
        // Eq. 11: the prior's own mean and variance are mu_t and sigma_t^2.
        assert_rel(b.mean(), mean, 1e-12, &what);
        assert_rel(b.variance(), var, 1e-11, &what);
    }
}

#[test]
fn incomplete_beta_matches_mpmath() {
    let cases = [
        (2.0, 2.0, 0.00725),
        (2.0, 91.0, 0.947_863_597_068_323),
        (2.0, 92.0, 0.950_024_204_757_383_5),
        (2.5, 37.25, 0.435_715_233_612_651_65),
        (3.0, 100.0, 0.889_730_143_271_278_8),
        (0.5, 10.0, 0.682_848_424_534_454_7),
        (12.75, 40.5, 2.074_717_177_607_167e-6),
    ];
    for (a, b, want) in cases {
        let got = BetaParams::new(a, b).unwrap().cdf(0.05).unwrap();
        assert_rel(got, want, 1e-10, &format!("I_0.05({a}, {b})"));
    }
}

/// Number of clean supervised executions after which a sample with variance `s2` first
/// becomes high-confidence, through the public state machine.
fn executions_to_high(s2: f64) -> usize {
    let sigma2_d = [s2];
    let mut conf = Confidence::from_prior(&sigma2_d, ConfidenceParams::paper()).unwrap();
    let mut obs = Observations::new(1).unwrap();
    let mut n = 0;
    while !conf.conf()[0] {
        obs.record(&[0.0], &[false]).unwrap();
        n += 1;
        conf.update(&sigma2_d, &obs).unwrap();
        assert!(n < 1000, "never became high-confidence");
    }
    n
}

#[test]
fn conf_flips_where_the_cdf_crosses_gamma_c() {
    // mpmath: smallest n with I_0.05(alpha0, beta0 + n) > 0.95, and the CDF on both sides.
    // (sigma2_d, n, I at n - 1, I at n)
    let cases = [
        (0.001, 0, f64::NAN, 0.970_485_993_835_987_3),
        (0.01, 25, 0.947_091_804_232_469_3, 0.950_401_551_349_213_7),
        (0.05, 67, 0.949_139_208_718_405_2, 0.951_475_421_694_195),
        (0.1, 84, 0.949_678_417_129_163_2, 0.951_814_999_648_747_6),
        (0.5, 91, 0.949_874_055_353_369_2, 0.951_953_945_922_395),
        (10.0, 90, 0.947_863_597_068_323, 0.950_024_204_757_383_5),
    ];
    let p = ConfidenceParams::paper();
    for (s2, n, before, after) in cases {
        assert_eq!(executions_to_high(s2), n, "sigma2_d = {s2}");
        let b0 = prior(&[s2], &p).unwrap()[0];
        let at = |k: usize| b0.posterior(0.0, k as f64).unwrap();
        assert_rel(
            at(n).cdf(0.05).unwrap(),
            after,
            1e-10,
            &format!("{s2} after"),
        );
        assert!(at(n).is_high_confidence(&p).unwrap());
        if n > 0 {
            assert_rel(
                at(n - 1).cdf(0.05).unwrap(),
                before,
                1e-10,
                &format!("{s2} before"),
            );
            assert!(!at(n - 1).is_high_confidence(&p).unwrap());
        }
    }
}

#[test]
fn corrections_delay_confidence() {
    // mpmath: with one correction (Beta(3, 2 + m)) the crossing is at m = 120
    // (I = 0.94857918021338741 at 119, 0.95047022232131288 at 120); two: m = 148.
    let p = ConfidenceParams::paper();
    for (corrections, m, before, after) in [
        (1.0, 120.0, 0.948_579_180_213_387_4, 0.950_470_222_321_312_8),
        (2.0, 148.0, 0.948_835_481_928_303_9, 0.950_555_201_956_979_7),
    ] {
        let b0 = prior(&[10.0], &p).unwrap()[0];
        let lo = b0.posterior(corrections, corrections + m - 1.0).unwrap();
        let hi = b0.posterior(corrections, corrections + m).unwrap();
        assert_rel(lo.cdf(0.05).unwrap(), before, 1e-10, "before");
        assert_rel(hi.cdf(0.05).unwrap(), after, 1e-10, "after");
        assert!(!lo.is_high_confidence(&p).unwrap() && hi.is_high_confidence(&p).unwrap());
    }
}

#[test]
fn posterior_after_known_observation_sequence() {
    let p = ConfidenceParams::paper();
    let sigma2_d = [10.0, 10.0, 10.0, 10.0];
    let mut obs = Observations::new(4).unwrap();
    // Execution 1 supervises reference times 0.5 (corrected) and 2.25 (not).
    obs.record(&[0.5, 2.25], &[true, false]).unwrap();
    // Execution 2 supervises 1.0 (corrected), 2.25 (corrected) and 3.0 (not).
    obs.record(&[1.0, 2.25, 3.0], &[true, true, false]).unwrap();
    // Per-sample (corrections, supervised):
    // 0: (0.5, 0.5); 1: (0.5 + 1, 0.5 + 1); 2: (0.75, 0.75 + 0.75); 3: (0.25, 0.25 + 0.25 + 1).
    let post = posterior(&sigma2_d, &obs, &p).unwrap();
    let want = [(2.5, 2.0), (3.5, 2.0), (2.75, 2.75), (2.25, 3.25)];
    for (n, (b, (alpha, beta))) in post.iter().zip(want).enumerate() {
        assert!(
            (b.alpha() - alpha).abs() < 1e-12 && (b.beta() - beta).abs() < 1e-12,
            "sample {n}: {b:?}, want ({alpha}, {beta})"
        );
    }
    assert_eq!(evaluate(&sigma2_d, &obs, &p).unwrap(), vec![false; 4]);
}
