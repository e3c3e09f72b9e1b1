//! Criterion bench: record two executions and recompute `conf` for 6000 reference samples
//! in a mid-study state (about half the samples still low-confidence, each execution
//! supervising ~3000 samples). Target: ≤ 1 ms. The state is produced by replaying 40
//! study iterations; `warm` keeps the evaluation cache those iterations filled,
//! `cold_cache` is the same state as just restored from a file.

use criterion::{BatchSize, BenchmarkId, Criterion};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tandem_confidence::{Confidence, ConfidenceParams, Observations};

/// Kind of reference sample in the synthetic sanding-like task.
#[derive(Clone, Copy, PartialEq)]
enum Kind {
    /// Demonstrations agree (σ²_D ≤ 0.001): high confidence from the prior.
    Steady,
    /// Moderate variance (σ²_D in 0.01–0.05): latches after 25–67 clean executions.
    Moderate,
    /// Large variance, corrected only by mistake (1 %): latches after ≥ 90 executions.
    Quiet,
    /// Painted about half the time: corrected in half the executions, never latches.
    Painted,
}

impl Kind {
    fn sigma2_d(self, rng: &mut ChaCha8Rng) -> f64 {
        match self {
            Kind::Steady => rng.random_range(0.0..0.001),
            Kind::Moderate => rng.random_range(0.01..0.05),
            Kind::Quiet => rng.random_range(0.2..2.0),
            Kind::Painted => rng.random_range(0.3..1.0),
        }
    }
    fn p_correction(self) -> f64 {
        if self == Kind::Painted { 0.5 } else { 0.01 }
    }
}

/// One study iteration's inputs, built outside the timed closure.
struct Setup {
    conf: Confidence,
    obs: Observations,
    sigma2_d: Vec<f64>,
    /// Per execution: supervised reference times and whether each was corrected.
    executions: Vec<(Vec<f64>, Vec<bool>)>,
}

/// One execution: every low-confidence sample is supervised, visited at fractional
/// reference times (local speed 0.8–1.25 reference samples per control tick).
fn execution(rng: &mut ChaCha8Rng, conf: &Confidence, kind: &[Kind]) -> (Vec<f64>, Vec<bool>) {
    let mut times = Vec::new();
    let mut corrected = Vec::new();
    for region in conf.low_regions() {
        let mut t = region.start as f64 + rng.random_range(0.0..0.5);
        while t <= (region.end - 1) as f64 {
            times.push(t);
            corrected.push(rng.random_bool(kind[t as usize].p_correction()));
            t += rng.random_range(0.8..1.25);
        }
    }
    (times, corrected)
}

fn setup(n_ref: usize, seed: u64, warm: bool) -> Setup {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    // Regions of 100–400 samples cycling through the kinds: ~30 % steady, ~20 % moderate,
    // ~20 % quiet, ~30 % painted.
    let cycle = [
        Kind::Steady,
        Kind::Painted,
        Kind::Moderate,
        Kind::Quiet,
        Kind::Steady,
        Kind::Painted,
        Kind::Moderate,
        Kind::Painted,
        Kind::Quiet,
        Kind::Steady,
    ];
    let mut kind = Vec::with_capacity(n_ref);
    for &k in cycle.iter().cycle() {
        if kind.len() == n_ref {
            break;
        }
        let len = rng.random_range(100..400).min(n_ref - kind.len());
        kind.extend(std::iter::repeat_n(k, len));
    }
    let base: Vec<f64> = kind.iter().map(|k| k.sigma2_d(&mut rng)).collect();
    // Each iteration's executions enter Eq. 6, so the variance moves a little.
    let jitter = |rng: &mut ChaCha8Rng| -> Vec<f64> {
        base.iter()
            .map(|s| s * rng.random_range(0.95..1.05))
            .collect()
    };
    let params = ConfidenceParams::default();
    let mut conf = Confidence::from_prior(&jitter(&mut rng), params).expect("valid");
    let mut obs = Observations::new(n_ref).expect("n_ref > 0");
    // Replay 40 iterations of the study loop (two executions each).
    for _ in 0..40 {
        for _ in 0..2 {
            let (times, corrected) = execution(&mut rng, &conf, &kind);
            obs.record(&times, &corrected).expect("valid times");
        }
        conf.update(&jitter(&mut rng), &obs).expect("valid inputs");
    }
    if !warm {
        let params = conf.params().clone();
        conf = Confidence::from_parts(params, conf.conf().to_vec()).expect("valid state");
    }
    let executions = (0..2).map(|_| execution(&mut rng, &conf, &kind)).collect();
    Setup {
        sigma2_d: jitter(&mut rng),
        conf,
        obs,
        executions,
    }
}

fn bench(c: &mut Criterion) {
    let n_ref = 6000;
    let mut group = c.benchmark_group("update_conf");
    for warm in [true, false] {
        let s = setup(n_ref, 7, warm);
        let supervised: usize = s.executions.iter().map(|e| e.0.len()).sum();
        let low = 100.0 * (1.0 - s.conf.high_share());
        let name = format!(
            "record2_update_{}/low{low:.0}%_supervised{supervised}",
            if warm { "warm" } else { "cold_cache" }
        );
        group.bench_function(BenchmarkId::new(name, n_ref), |b| {
            b.iter_batched(
                || (s.conf.clone(), s.obs.clone()),
                |(mut conf, mut obs)| {
                    for (times, corrected) in &s.executions {
                        obs.record(times, corrected).expect("valid times");
                    }
                    conf.update(&s.sigma2_d, &obs).expect("valid inputs")
                },
                BatchSize::SmallInput,
            );
        });
    }
    group.finish();
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    bench(&mut c);
    c.final_summary();
}
