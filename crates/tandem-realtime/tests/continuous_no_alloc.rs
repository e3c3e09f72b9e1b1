//! `ContinuousCoordinator::tick` and `run_cell` never allocate: long runs of a continuous cell
//! (N = 1, 2, 4 and `MAX_ROBOTS`, with holds, under every kind of operator input, the
//! rejected NaN included, and the policy loop of `run_cell`) measured with the counting global
//! allocator of `allocation-counter` (as `tests/tick_no_alloc.rs`).

use std::hint::black_box;

use allocation_counter::measure;
use rand::SeedableRng;
use tandem_realtime::adversary::adversary_set;
use tandem_realtime::continuous::{ContinuousCoordinator, run_cell};
use tandem_realtime::{MAX_ROBOTS, Operator, Timeline};

/// 600 samples at 10 ms: three LC runs of 40 samples, holds in the middle of each HC run
/// between them, none in the head; round robin by stretch.
fn cell(n: usize) -> ContinuousCoordinator {
    let conf: Vec<bool> = (0..600)
        .map(|k| !(k % 200 >= 80 && k % 200 < 120))
        .collect();
    let mean: Vec<f64> = (0..600)
        .map(|k| 1.0 + 0.2 * (k as f64 * 0.05).sin())
        .collect();
    let lo: Vec<f64> = mean.iter().map(|m| 0.6 * m).collect();
    let hi: Vec<f64> = mean.iter().map(|m| 1.7 * m).collect();
    let task = Timeline::new(&conf, &mean, &lo, &hi, 0.0, 0.01).expect("valid task");
    let order: Vec<(usize, usize)> = (0..3).flat_map(|lc| (0..n).map(move |r| (r, lc))).collect();
    ContinuousCoordinator::new(task, &[160, 360], &order, n, 0.01).expect("runnable")
}

#[test]
fn ticks_and_the_policy_loop_allocate_nothing() {
    let boxed = measure(|| {
        black_box(Box::new(7_u64));
    });
    assert_eq!(boxed.count_total, 1, "the counting allocator is not active");
    for n in [1, 2, 4, MAX_ROBOTS] {
        let mut c = cell(n);
        let ops = [
            Operator::Fastest,
            Operator::Slowest,
            Operator::Scheduled,
            Operator::Gradient(0.9),
            Operator::Gradient(f64::NAN),
        ];
        let (mut lc_ticks, mut errors) = (0_u64, 0_u64);
        let info = measure(|| {
            for k in 0..60_000 {
                black_box(c.low_conf_now());
                match c.tick(ops[k % ops.len()]) {
                    Ok(t) => lc_ticks += u64::from(t.low_conf.count() > 0),
                    Err(e) => {
                        black_box(&e);
                        errors += 1;
                    }
                }
            }
            c.reset();
        });
        assert_eq!(info.count_total, 0, "{n} robots: {info:?}");
        assert!(
            lc_ticks > 5_000 && errors == 12_000,
            "{n}: {lc_ticks} {errors}"
        );
        // The policy loop.
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let set = adversary_set(n, [0.5, 2.0], 4000, &mut rng);
        let mut done = 0;
        let info = measure(|| {
            for &a in &set {
                // Cloning shares the plan (reference counts), it allocates nothing either.
                let mut run_c = c.clone();
                let run = run_cell(&mut run_c, a, &mut rng, 3, 10_000_000).expect("admissible");
                done += u64::from(run.finished);
            }
        });
        assert_eq!(info.count_total, 0, "{n} robots, policies: {info:?}");
        assert_eq!(done, set.len() as u64);
    }
}
