//! Schedules of three robots that the N-robot worst-case simulation (fixes 5–6, kept as
//! `margins::baseline::greedy_pace`) accepted and that overlap at run time under a constant
//! slowest operator, found by an independent adversarial check; and their minimal forms. The
//! lead bound that replaced the simulation for `N ≥ 3` rejects every one of them
//! (docs/decisions.md, "The N-robot margin check: a lead bound per unit of progress").
//!
//! The plans are written as runs `(value, samples)`; they reproduce the independent check's
//! files sample for sample (Δt_s = 1 s, tick ¼ s), and the overlap ticks it reported.

use tandem_realtime::margins::baseline;
use tandem_realtime::{
    Coordinator, Operator, Timeline, pair_slacks, sufficient_margins, sufficient_margins_per_pair,
};

/// The values of `runs`, each repeated its count.
fn rle<T: Copy>(runs: &[(T, usize)]) -> Vec<T> {
    runs.iter()
        .flat_map(|&(v, n)| std::iter::repeat_n(v, n))
        .collect()
}

/// `ψ̇min` and `ψ̇max` of the stiff class (`F` 5 % above, `S` 20 % above the flexible class's on
/// the same gradient): 0.25/1.05 and 2/1.2.
const STIFF: (f64, f64) = (0.238_095_238_095_238_08, 1.666_666_666_666_666_7);
/// The flexible class.
const FLEX: (f64, f64) = (0.25, 2.0);

/// The shared-mask reproducer: three robots with one mask and one set of bounds (a valid
/// `tandem-schedule` problem, constraint 3 holds), offsets `tau2` and `tau3`; `tail` is the
/// length of the last high-confidence run (40 in the original, 1 in the minimal form).
///
/// Mask: LC×60 (flexible), HC×95 (stiff), LC×1, HC×77, LC×1, HC×`tail` (flexible). Robot 1's
/// gradient on the stiff run is 0.8, robot 2's 1.0, robot 3's 1.2; 1.0 everywhere else.
fn shared_mask(tau2: f64, tau3: f64, tail: usize) -> Vec<Timeline> {
    let conf = rle(&[
        (false, 60),
        (true, 95),
        (false, 1),
        (true, 77),
        (false, 1),
        (true, tail),
    ]);
    let rest = 79 + tail;
    let lo = rle(&[(FLEX.0, 60), (STIFF.0, 95), (FLEX.0, rest)]);
    let hi = rle(&[(FLEX.1, 60), (STIFF.1, 95), (FLEX.1, rest)]);
    let exec = |g: f64| rle(&[(1.0, 60), (g, 95), (1.0, rest)]);
    [(0.8, 0.0), (1.0, tau2), (1.2, tau3)]
        .iter()
        .map(|&(g, start)| Timeline::new(&conf, &exec(g), &lo, &hi, start, 1.0).unwrap())
        .collect()
}

/// The per-robot-bounds reproducer, and its minimal form: all three robots start at 0, every
/// gradient is 1. Robot 1 (flexible) is low-confidence at sample `k_p` only, robot 2 (stiff) at
/// `k_c` only, robot 3 (flexible) for its first `long` samples; `n` samples each. The original
/// is `(long, k_p, k_c, n) = (60, 62, 68, 100)`, the minimal `(24, 26, 30, 32)`.
fn per_robot_bounds(long: usize, k_p: usize, k_c: usize, n: usize) -> Vec<Timeline> {
    let single = |k: usize| -> Vec<bool> { (0..n).map(|i| i != k).collect() };
    let third: Vec<bool> = (0..n).map(|i| i >= long).collect();
    let ones = vec![1.0; n];
    let plan = |conf: &[bool], (lo, hi): (f64, f64)| {
        Timeline::new(conf, &ones, &vec![lo; n], &vec![hi; n], 0.0, 1.0).unwrap()
    };
    vec![
        plan(&single(k_p), FLEX),
        plan(&single(k_c), STIFF),
        plan(&third, FLEX),
    ]
}

/// The first tick (index) with two robots low-confidence under a constant `op`, and which.
fn first_overlap(robots: Vec<Timeline>, op: Operator) -> Option<(u64, Vec<bool>)> {
    let n = robots.len();
    let mut c = Coordinator::new_unchecked(robots, 0.25).unwrap();
    let mut k = 0;
    while !c.is_finished() {
        let t = c.tick(op).unwrap();
        if t.overlap() {
            return Some((k, (0..n).map(|i| t.low_conf[i]).collect()));
        }
        k += 1;
    }
    None
}

/// Both checks of this crate reject, the unsafe simulation accepts, and a constant slowest
/// operator makes the robots flagged in `low_conf` low-confidence together in tick
/// `overlap_tick`.
fn assert_reproduces(robots: &[Timeline], overlap_tick: u64, low_conf: [bool; 3]) {
    assert!(baseline::greedy_pace(robots, 0.25).unwrap());
    assert!(!sufficient_margins(robots, 0.25).unwrap());
    assert!(!sufficient_margins_per_pair(robots, 0.25).unwrap());
    assert!(
        pair_slacks(robots, 0.25)
            .unwrap()
            .iter()
            .any(|s| s.slack_s <= 0.0)
    );
    assert_eq!(
        first_overlap(robots.to_vec(), Operator::Slowest),
        Some((overlap_tick, low_conf.to_vec()))
    );
}

#[test]
fn shared_mask_reproducer_is_rejected() {
    assert_reproduces(&shared_mask(65.0, 150.5, 40), 1469, [false, true, true]);
}

#[test]
fn per_robot_bounds_reproducer_is_rejected() {
    // Robot 2 enters its sample while robot 3 is still dragged through its stretch.
    assert_reproduces(&per_robot_bounds(60, 62, 68, 100), 453, [false, true, true]);
}

#[test]
fn minimal_forms_are_rejected() {
    // The shared mask with its tail cut to one sample: the same overlap.
    assert_reproduces(&shared_mask(65.0, 150.5, 1), 1469, [false, true, true]);
    // A third of the samples: robot 3 low-confidence for 24 s, robot 1's region at 26 s, robot
    // 2's 4 s later; robot 2 enters its region while robot 1 is in its own.
    assert_reproduces(&per_robot_bounds(24, 26, 30, 32), 199, [true, true, false]);
}

/// Why the simulation was fooled, by hand: on the stiff run robot 2 paces `F = 4.2`, `S = 0.6`,
/// robot 1 `F = 4`, `S = 0.5` (gradient 1 on bounds 0.25/1.05, 2/1.2 and 0.25, 2). Rushing the
/// third robot moves robot 1 a full step of `4·¼ = 1 s` per tick and robot 2 `1.05 s`: 0.05 s of
/// lead per tick, 0.05 s per second of robot 1's progress. Dragging moves robot 1 `0.125 s` and
/// robot 2 `0.15 s`: 0.025 s per tick, but 0.2 s per second of robot 1's progress. A per-tick
/// maximum picks the rush; over the 60 s of the third robot's stretch the drag gives 12 s.
#[test]
fn dragging_gains_more_per_unit_of_progress_than_rushing() {
    let robots = per_robot_bounds(60, 62, 68, 100);
    let (p, c) = (&robots[0], &robots[1]);
    let tick = 0.25;
    let (rush_p, rush_c) = (p.rate_fast(0) * tick, c.rate_fast(0) * tick);
    let (drag_p, drag_c) = (p.rate_slow(0) * tick, c.rate_slow(0) * tick);
    assert!((rush_p - 1.0).abs() < 1e-12 && (rush_c - 1.05).abs() < 1e-12);
    assert!((drag_p - 0.125).abs() < 1e-12 && (drag_c - 0.15).abs() < 1e-12);
    // Per tick the rush gains more, per unit of p's progress the drag does, four times as much.
    assert!(rush_c - rush_p > drag_c - drag_p);
    let per_progress = |dp: f64, dc: f64| (dc - dp) / dp;
    let ratio = per_progress(drag_p, drag_c) / per_progress(rush_p, rush_c);
    assert!((ratio - 4.0).abs() < 1e-9, "{ratio}");
    // Under a constant slowest operator, 400 ticks move robot 1 (level with the dragged robot 3)
    // by 50 s and robot 2 by 60 s: 0.2 s of lead per second of progress (both started at 0).
    let mut co = Coordinator::new_unchecked(robots, tick).unwrap();
    for _ in 0..400 {
        assert!(!co.tick(Operator::Slowest).unwrap().overlap());
    }
    let [p_s, c_s, t_s] = [co.clock_s()[0], co.clock_s()[1], co.clock_s()[2]];
    assert!(
        (p_s - 50.0).abs() < 1e-9 && (t_s - 50.0).abs() < 1e-9,
        "{p_s} {t_s}"
    );
    assert!((c_s - 60.0).abs() < 1e-9, "{c_s}");
}

/// The acceptance edge of the lead bound on the shared-mask reproducer: robot 3's first region
/// must come after robot 2's single-sample region at 220 s (the window the simulation accepted,
/// 150.5 s to 154 s, is gone), and from there the full adversary set, the beam search included,
/// finds nothing.
#[test]
fn shared_mask_is_accepted_once_robot_3_follows_robot_2() {
    use rand::SeedableRng;
    use tandem_realtime::adversary::{adversary_set, run_adversary};
    let accepted = |tau3: f64| sufficient_margins(&shared_mask(65.0, tau3, 40), 0.25).unwrap();
    assert!((1500..=2200).all(|t| !accepted(f64::from(t) / 10.0)));
    let tau3 = 221.5;
    assert!(accepted(tau3));
    let robots = shared_mask(65.0, tau3, 40);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(18);
    for a in adversary_set(3, [STIFF.0, FLEX.1], 1600, &mut rng) {
        let c = Coordinator::new(robots.clone(), 0.25).unwrap();
        let run = run_adversary(c, a, &mut rng, 200_000).unwrap();
        assert!(run.finished && run.first_overlap.is_none(), "{a:?}");
    }
}
