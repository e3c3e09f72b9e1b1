//! `Coordinator::tick` never allocates (docs/ARCHITECTURE.md): a whole run of ticks, under every
//! kind of operator input and through the adversary loop, is measured with a counting global
//! allocator.
//!
//! The allocator is the `allocation-counter` crate's: linking it installs a
//! `#[global_allocator]` that counts per thread, so this file needs no `unsafe` of its own
//! (the workspace forbids it) and the test harness's other threads cannot disturb the count.
//! Only this test binary uses it.

use std::hint::black_box;

use allocation_counter::measure;
use rand::SeedableRng;
use tandem_realtime::adversary::{adversary_set, run_adversary};
use tandem_realtime::{Coordinator, Operator, Timeline};

/// 3000 reference samples at 10 ms with 12 low-confidence runs; robot 2 starts a quarter of
/// the way through robot 1, so both run together, one low-confidence while the other is not.
fn robots() -> [Timeline; 2] {
    let n = 3000;
    let conf: Vec<bool> = (0..n).map(|k| k % 250 >= 40).collect();
    let mean: Vec<f64> = (0..n)
        .map(|k| 1.0 + 0.2 * (k as f64 * 0.01).sin())
        .collect();
    let lo: Vec<f64> = mean.iter().map(|m| 0.6 * m).collect();
    let hi: Vec<f64> = mean.iter().map(|m| 1.7 * m).collect();
    let r0 = Timeline::new(&conf, &mean, &lo, &hi, 0.0, 0.01).expect("valid timeline");
    let tau = r0.sample_clock_s()[n / 4 + 125];
    let r1 = Timeline::new(&conf, &mean, &lo, &hi, tau, 0.01).expect("valid timeline");
    [r0, r1]
}

#[test]
fn a_whole_run_of_ticks_allocates_nothing() {
    // Non-vacuity: the counting allocator is the one in use.
    let boxed = measure(|| {
        black_box(Box::new(7_u64));
    });
    assert_eq!(boxed.count_total, 1, "the counting allocator is not active");

    let mut c = Coordinator::new(robots(), 0.01).expect("valid tick");
    let ops = [
        Operator::Fastest,
        Operator::Slowest,
        Operator::Scheduled,
        Operator::Gradient(0.9),
        Operator::Gradient(f64::NAN), // rejected: the error path must not allocate either
    ];
    let (mut ticks, mut low_conf_ticks, mut errors) = (0_u64, 0_u64, 0_u64);
    let info = measure(|| {
        for _ in 0..2 {
            let mut k = 0;
            while !c.is_finished() {
                black_box(c.low_conf_now());
                match c.tick(ops[k % ops.len()]) {
                    Ok(t) => {
                        ticks += 1;
                        low_conf_ticks += u64::from(t.low_conf[0] || t.low_conf[1]);
                    }
                    Err(e) => {
                        black_box(&e);
                        errors += 1;
                    }
                }
                k += 1;
            }
            c.reset();
        }
    });
    assert_eq!(info.count_total, 0, "{info:?}");
    // The run was real: thousands of ticks, many low-confidence, every NaN rejected.
    assert!(
        ticks > 5000 && low_conf_ticks > 1000,
        "{ticks} {low_conf_ticks}"
    );
    assert!(errors > 1000, "{errors}");
}

#[test]
fn the_adversary_loop_allocates_nothing() {
    let robots = robots();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let set = adversary_set([0.5, 2.0], 4000, &mut rng);
    // Coordinators are cloned (allocated) outside the measurement.
    let coordinators: Vec<Coordinator> = set
        .iter()
        .map(|_| Coordinator::new(robots.clone(), 0.01).expect("valid tick"))
        .collect();
    let mut total_ticks = 0;
    let mut coordinators = coordinators.into_iter();
    let info = measure(|| {
        for &adversary in &set {
            let c = coordinators.next().expect("one coordinator per adversary");
            let run = run_adversary(c, adversary, &mut rng, 1_000_000).expect("admissible");
            assert!(run.finished);
            total_ticks += run.ticks;
        }
    });
    assert_eq!(info.count_total, 0, "{info:?}");
    assert!(total_ticks > 13 * 3000, "{total_ticks}");
}
