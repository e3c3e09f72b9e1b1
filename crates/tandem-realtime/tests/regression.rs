//! The margin check is not vacuous: schedules it rejects (and the printed Alg. 2, or for three
//! robots the two-robot check applied per pair, accepts) really do overlap under some admissible
//! operator.

use rand::SeedableRng;
use tandem_realtime::Operator::{Fastest as FAST, Slowest as SLOW};
use tandem_realtime::adversary::{adversary_set, run_adversary};
use tandem_realtime::margins::baseline;
use tandem_realtime::testkit::{Case, Family, find_overlap, rng};
use tandem_realtime::{Coordinator, Timeline, sufficient_margins, sufficient_margins_per_pair};

/// The smallest case of docs/decisions.md, "Alg. 2 as printed is not sound on a tick grid":
/// [HC, LC, HC], gradients 1, bounds [½, 2] (F = 2, S = ½),
/// Δt_s = 1, tick = 1 sample, τ = 3/2.
fn three_sample() -> [Timeline; 2] {
    let conf = [true, false, true];
    let (g, lo, hi) = ([1.0; 3], [0.5; 3], [2.0; 3]);
    [
        Timeline::new(&conf, &g, &lo, &hi, 0.0, 1.0).unwrap(),
        Timeline::new(&conf, &g, &lo, &hi, 1.5, 1.0).unwrap(),
    ]
}

#[test]
fn three_sample_case_printed_accepts_overlaps_conservative_rejects() {
    let robots = three_sample();
    assert!(baseline::printed(&robots, 1.0).unwrap());
    assert!(!sufficient_margins(&robots, 1.0).unwrap());
    assert!(!sufficient_margins_per_pair(&robots, 1.0).unwrap());
    // The operator drags the previous robot for one tick (setting the tick phase), then rushes
    // it: the responder matches the rushed step and enters its LC sample in the same tick.
    let mut c = Coordinator::new_unchecked(robots, 1.0).unwrap();
    let ticks: Vec<_> = [FAST, SLOW, FAST]
        .iter()
        .map(|&g| c.tick(g).unwrap())
        .collect();
    assert_eq!(ticks[2].low_conf, [true, true]);
    assert!(ticks[..2].iter().all(|t| !(t.low_conf[0] && t.low_conf[1])));
    // Moving robot 2 later by two maximal steps is accepted, and the same operator is harmless.
    let later = [three_sample()[0].clone(), {
        let conf = [true, false, true];
        Timeline::new(&conf, &[1.0; 3], &[0.5; 3], &[2.0; 3], 3.0, 1.0).unwrap()
    }];
    assert!(sufficient_margins(&later, 1.0).unwrap());
    let mut c = Coordinator::new(later, 1.0).unwrap();
    for g in [FAST, SLOW, FAST, FAST, SLOW, FAST, FAST, FAST] {
        let t = c.tick(g).unwrap();
        assert!(!(t.low_conf[0] && t.low_conf[1]));
    }
}

/// Random problems where the printed check accepts the tightest offset it allows but the
/// conservative check rejects it: simple operator policies find real overlaps in many of them.
#[test]
fn printed_check_accepts_schedules_that_overlap() {
    let (mut cases, mut overlaps) = (0, 0);
    for seed in 0..150u64 {
        let mut r = rng(0xA11CE + seed);
        let case = Case::random(Family::Uniform, 2, &mut r);
        let e1 = case.plans[0].timeline(0.0).end_s();
        let tick_s = case.tick_s;
        let robots_at = |tau: f64| case.robots_at(&[0.0, tau]);
        // Tightest offset the printed check accepts (bisection, accepted end kept).
        let (mut lo, mut hi) = (0.0, e1);
        if baseline::printed(&robots_at(0.0), tick_s).unwrap() {
            hi = 0.0;
        }
        for _ in 0..30 {
            let m = 0.5 * (lo + hi);
            if baseline::printed(&robots_at(m), tick_s).unwrap() {
                hi = m;
            } else {
                lo = m;
            }
        }
        let robots = robots_at(hi);
        if !baseline::printed(&robots, tick_s).unwrap()
            || sufficient_margins(&robots, tick_s).unwrap()
        {
            continue;
        }
        cases += 1;
        let set = case.adversaries(&robots, &mut r);
        if find_overlap(&robots, tick_s, &set, &mut r).is_some() {
            overlaps += 1;
        }
    }
    // `cargo test -p tandem-realtime --test regression -- --nocapture` shows the counts
    // (docs/decisions.md, "Alg. 2 as printed is not sound on a tick grid").
    eprintln!("printed-only cases: {cases}, overlapped under the adversary set: {overlaps}");
    assert!(cases >= 100, "only {cases} printed-only cases");
    assert!(
        overlaps >= 40,
        "only {overlaps} of {cases} printed-only cases overlapped"
    );
}

/// The smallest three-robot case found where a robot that is neither `p` nor `c` breaks the
/// pair's two-robot worst case: 32 reference samples [HC×16, LC×8, HC×8], Δt_s = 1, bounds
/// `[½, 2]`, tick ¼ s. Robot 0 (gradients 1) starts at 0, robot 1 (gradients 1) at 12, robot 2
/// at `tau_c` with gradient 2 on its HC samples, i.e. at `ψ̇max`: `S = 1`, it cannot slow down.
/// Regions: robot 0 `[16, 24)`, robot 1 `[28, 36)`, robot 2 `[tau_c + 32, tau_c + 40)`.
fn third_robot_case(tau_c: f64) -> Vec<Timeline> {
    let conf: Vec<bool> = (0..32).map(|k| !(16..24).contains(&k)).collect();
    let (lo, hi, ones) = ([0.5; 32], [2.0; 32], [1.0; 32]);
    let slow_hc: Vec<f64> = conf.iter().map(|&hc| if hc { 2.0 } else { 1.0 }).collect();
    vec![
        Timeline::new(&conf, &ones, &lo, &hi, 0.0, 1.0).unwrap(),
        Timeline::new(&conf, &ones, &lo, &hi, 12.0, 1.0).unwrap(),
        Timeline::new(&conf, &slow_hc, &lo, &hi, tau_c, 1.0).unwrap(),
    ]
}

#[test]
fn a_dragged_third_robot_breaks_the_two_robot_worst_case() {
    let tick_s = 0.25;
    // τ_c = 16: robot 2's region starts 12 s after robot 1's ends. Each pair on its own is
    // safe, so the per-pair check accepts; the N-robot check rejects.
    let robots = third_robot_case(16.0);
    assert!(baseline::pairwise(&robots, tick_s).unwrap());
    assert!(!sufficient_margins(&robots, tick_s).unwrap());
    assert!(!sufficient_margins_per_pair(&robots, tick_s).unwrap());
    // The operator drags every low-confidence robot. While robot 0 is dragged (step ⅛ s),
    // robot 1 follows it but robot 2 cannot go below ¼ s per tick and gains 8 s; robot 1's own
    // dragged region adds 8 s more, and robot 2 enters its region while robot 1 is in its own.
    let mut c = Coordinator::new_unchecked(robots, tick_s).unwrap();
    let mut first = None;
    for k in 0.. {
        if c.is_finished() {
            break;
        }
        let t = c.tick(SLOW).unwrap();
        if t.overlap() {
            first = Some((k, t.low_conf));
            break;
        }
    }
    let (k, low_conf) = first.expect("the dragged third robot makes robots 1 and 2 overlap");
    assert_eq!(low_conf, [false, true, true], "tick {k}");
    // Six seconds later the N-robot check accepts (from 21 s on, on a 1 s grid), and the full
    // adversary set finds nothing.
    let later = third_robot_case(22.0);
    assert!(sufficient_margins(&later, tick_s).unwrap());
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    for a in adversary_set(3, [0.5, 2.0], 400, &mut rng) {
        let c = Coordinator::new(later.clone(), tick_s).unwrap();
        let run = run_adversary(c, a, &mut rng, 100_000).unwrap();
        assert!(run.finished && run.first_overlap.is_none(), "{a:?}");
    }
}

/// Executions shorter than one tick (found by the N-robot schedule property test): one
/// low-confidence sample, ψ̇_E = 0.801 (8.0 ms per execution), a 9.36 ms tick, three robots
/// serial (each starting where the one before it ends). Robot 1 finishing within a tick once
/// carried both waiting robots past their starts in the same tick, and they were low-confidence
/// together under `Periodic { period: 1, phase: 7 }`, although the check accepts the schedule.
/// Robots now start one start time at a time (strategy rule 3), as the check assumes.
#[test]
fn executions_shorter_than_a_tick_start_one_at_a_time() {
    let conf = [false];
    let (g, lo, hi) = (
        [0.801_036_476_389_653_6],
        [0.617_476_277_615_212_2],
        [1.078_909_833_189_365],
    );
    let tick_s = 0.009_360_638_873_002_192;
    let mut robots: Vec<Timeline> = Vec::new();
    for _ in 0..3 {
        let start = robots.last().map_or(0.0, Timeline::end_s);
        robots.push(Timeline::new(&conf, &g, &lo, &hi, start, 0.01).unwrap());
    }
    assert!(sufficient_margins(&robots, tick_s).unwrap());
    let periodic = tandem_realtime::adversary::Adversary::Periodic {
        period: 1,
        phase: 7,
    };
    let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let mut set = adversary_set(3, [lo[0], hi[0]], 4, &mut r);
    set.push(periodic);
    for a in set {
        let c = Coordinator::new(robots.clone(), tick_s).unwrap();
        let run = run_adversary(c, a, &mut r, 1000).unwrap();
        assert!(run.finished, "{a:?}");
        assert_eq!(
            run.overlap_ticks, 0,
            "{a:?}: first at {:?}",
            run.first_overlap
        );
    }
}
