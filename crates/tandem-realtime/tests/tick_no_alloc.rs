//! `Coordinator::tick` never allocates (docs/ARCHITECTURE.md): a whole run of ticks, under every
//! kind of operator input and through the adversary loop, for 2, 4 and `MAX_ROBOTS` robots, is
//! measured with a counting global allocator.
//!
//! The allocator is the `allocation-counter` crate's: linking it installs a
//! `#[global_allocator]` that counts per thread, so this file needs no `unsafe` of its own
//! (the workspace forbids it) and the test harness's other threads cannot disturb the count.
//! Only this test binary uses it.

use std::hint::black_box;

use allocation_counter::measure;
use rand::SeedableRng;
use tandem_realtime::adversary::{Adversary, adversary_set, run_adversary};
use tandem_realtime::holds::release_rules;
use tandem_realtime::{Coordinator, Hold, MAX_ROBOTS, Operator, Timeline};

/// `n_robots` robots on 3000 reference samples at 10 ms with 12 low-confidence runs; robot `i`
/// starts `i` quarter-periods plus half a run after robot 0, so they run together, one
/// low-confidence while the others are not (for two robots: robot 2 a quarter of the way
/// through robot 1).
fn robots(n_robots: usize) -> Vec<Timeline> {
    let n = 3000;
    let conf: Vec<bool> = (0..n).map(|k| k % 250 >= 40).collect();
    let mean: Vec<f64> = (0..n)
        .map(|k| 1.0 + 0.2 * (k as f64 * 0.01).sin())
        .collect();
    let lo: Vec<f64> = mean.iter().map(|m| 0.6 * m).collect();
    let hi: Vec<f64> = mean.iter().map(|m| 1.7 * m).collect();
    let r0 = Timeline::new(&conf, &mean, &lo, &hi, 0.0, 0.01).expect("valid timeline");
    let starts: Vec<f64> = (0..n_robots)
        .map(|i| {
            if i == 0 {
                0.0
            } else {
                r0.sample_clock_s()[(i * (n / 4 + 125)) % n]
            }
        })
        .collect();
    starts
        .iter()
        .map(|&s| Timeline::new(&conf, &mean, &lo, &hi, s, 0.01).expect("valid timeline"))
        .collect()
}

#[test]
fn a_whole_run_of_ticks_allocates_nothing() {
    // Non-vacuity: the counting allocator is the one in use.
    let boxed = measure(|| {
        black_box(Box::new(7_u64));
    });
    assert_eq!(boxed.count_total, 1, "the counting allocator is not active");

    for n_robots in [2, 4, MAX_ROBOTS] {
        whole_run_allocates_nothing(n_robots, false);
    }
    // With hold points: every robot's plan split into legs at holds in its HC runs (one with a
    // planned dwell), release rules from the order of the stretches; N = 1…MAX_ROBOTS.
    for n_robots in 1..=MAX_ROBOTS {
        whole_run_allocates_nothing(n_robots, true);
    }
}

/// Holds in the middle of every HC run (samples `k·250 + 145`), release rules derived from
/// the order of the low-confidence stretches, and a dwell of 0.3 s at robot 0's first hold.
fn holds(robots: &[Timeline]) -> Vec<Vec<Hold>> {
    let usable: Vec<usize> = (0..12).map(|k| k * 250 + 145).collect();
    let mut base = vec![Vec::new(); robots.len()];
    base[0].push(Hold {
        dwell_s: 0.3,
        ..Hold::at(usable[0])
    });
    let mut holds = release_rules(robots, &base, &vec![usable.clone(); robots.len()]);
    if holds.iter().all(|h| h.len() <= 1) {
        holds = vec![usable.iter().map(|&h| Hold::at(h)).collect(); robots.len()];
    }
    holds
}

fn whole_run_allocates_nothing(n_robots: usize, with_holds: bool) {
    let robots = robots(n_robots);
    let holds = if with_holds {
        holds(&robots)
    } else {
        Vec::new()
    };
    assert!(!with_holds || holds.iter().map(Vec::len).sum::<usize>() >= n_robots);
    let mut c = Coordinator::with_holds_unchecked(robots, &holds, 0.01).expect("valid tick");
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
                        low_conf_ticks += u64::from(t.low_conf.count() > 0);
                        // Releasing a robot the monitor holds allocates nothing either.
                        if t.fault.is_some() {
                            c.clear_fault();
                        }
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
    assert_eq!(info.count_total, 0, "{n_robots} robots: {info:?}");
    // The run was real: thousands of ticks, many low-confidence, every NaN rejected.
    assert!(
        ticks > 5000 && low_conf_ticks > 500,
        "{n_robots} robots: {ticks} {low_conf_ticks}"
    );
    assert!(errors > 1000, "{n_robots} robots: {errors}");
}

#[test]
fn the_adversary_loop_allocates_nothing() {
    for n_robots in [2, 4] {
        adversary_loop_allocates_nothing(n_robots);
    }
}

fn adversary_loop_allocates_nothing(n_robots: usize) {
    let robots = robots(n_robots);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    // The policies, not the beam search: a search keeps its candidates on the heap by nature.
    let set: Vec<Adversary> = adversary_set(n_robots, [0.5, 2.0], 4000, &mut rng)
        .into_iter()
        .filter(|a| !matches!(a, Adversary::Beam { .. }))
        .collect();
    // Coordinators are cloned (allocated) outside the measurement.
    let coordinators: Vec<Coordinator> = set
        .iter()
        .map(|_| Coordinator::new_unchecked(robots.clone(), 0.01).expect("valid tick"))
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
    assert_eq!(info.count_total, 0, "{n_robots} robots: {info:?}");
    assert!(total_ticks > set.len() as u64 * 3000, "{total_ticks}");
}
