//! The pre-alert of every tick (`Tick::next`, `tandem_realtime::prealert`, issue 41): the
//! earliest start it announces for a robot's next low-confidence stretch is never later than
//! the start observed, and the latest, when bounded, never earlier — in rounds (random problems
//! of the test kit's families, N = 2…4, with and without holds and release rules, switch times
//! of 0 and 3 ticks) and in continuous cells (random tasks, N = 2…4, random runnable orders),
//! under every operator policy of the adversary set and, in rounds, the beam search (its
//! sequence, `adversary::search::beam_search_run`, replayed tick by tick; a continuous cell has
//! no beam search: it runs as its policy fallback there).

use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tandem_realtime::adversary::search::beam_search_run;
use tandem_realtime::adversary::{Adversary, AdversaryRun, adversary_set, run_adversary_on};
use tandem_realtime::continuous::{ContinuousCoordinator, groups};
use tandem_realtime::testkit::{CellHolds, Family, HeldRound, random_cell_task, random_order};
use tandem_realtime::{Controller, Fault, Operator, PerRobot, RobotFlags, Tick, Timeline};

/// A controller that records every tick it runs.
struct Watch<C> {
    inner: C,
    ticks: Vec<Tick>,
}

impl<C: Controller> Controller for Watch<C> {
    fn n_robots(&self) -> usize {
        self.inner.n_robots()
    }
    fn tick_s(&self) -> f64 {
        self.inner.tick_s()
    }
    fn tick(&mut self, operator: Operator) -> tandem_realtime::Result<Tick> {
        let t = self.inner.tick(operator)?;
        self.ticks.push(t);
        Ok(t)
    }
    fn reset(&mut self) {
        self.inner.reset();
        self.ticks.clear();
    }
    fn fault(&self) -> Option<Fault> {
        self.inner.fault()
    }
    fn clear_fault(&mut self) {
        self.inner.clear_fault();
    }
    fn low_conf_now(&self) -> RobotFlags {
        self.inner.low_conf_now()
    }
    fn running_now(&self) -> RobotFlags {
        self.inner.running_now()
    }
    fn waiting_now(&self) -> RobotFlags {
        self.inner.waiting_now()
    }
    fn pre_alert(&self) -> Option<tandem_realtime::PreAlert> {
        self.inner.pre_alert()
    }
    fn ref_time_now(&self) -> PerRobot<f64> {
        self.inner.ref_time_now()
    }
    fn tasks_now(&self) -> PerRobot<u64> {
        self.inner.tasks_now()
    }
    fn clock_s(&self) -> &[f64] {
        self.inner.clock_s()
    }
    fn is_finished(&self) -> bool {
        self.inner.is_finished()
    }
    fn ticks(&self) -> u64 {
        self.inner.ticks()
    }
}

/// Checks every announcement of a recorded run at tick `h`: the robot's next stretch starts
/// in the first tick after the announcement that reports it low-confidence (when it was not
/// low-confidence in the announcing tick; else in the first such tick after a tick without,
/// a later stretch, which only the earliest bound must respect). `finished`: the run ended
/// with every robot done (rounds), so a bounded announced stretch must have been observed.
/// Returns (announcements checked, of them with a finite latest, the least slack of the
/// earliest in ticks).
fn check_run(ticks: &[Tick], h: f64, finished: bool, faults: bool) -> (u64, u64, f64) {
    let (mut checked, mut bounded, mut least) = (0, 0, f64::INFINITY);
    for (t0, tick) in ticks.iter().enumerate() {
        let Some(a) = tick.next else { continue };
        let r = a.robot;
        let lc_now = tick.low_conf[r];
        let mut it = ticks.iter().enumerate().skip(t0 + 1);
        if lc_now {
            // Past the current stretch first.
            if it.by_ref().find(|(_, t)| !t.low_conf[r]).is_none() {
                continue;
            }
        }
        let Some((t1, _)) = it.find(|(_, t)| t.low_conf[r]) else {
            // Never observed: the latest must have been unbounded (or the run cut short).
            assert!(
                !finished || faults || a.latest_s.is_infinite() || lc_now,
                "tick {t0}: {a:?} announced, the stretch never started"
            );
            continue;
        };
        let start_s = (t1 - t0 - 1) as f64 * h;
        assert!(
            a.earliest_s <= start_s + 1e-9 * h,
            "tick {t0}: {a:?} announced, started after {start_s} s (tick {t1}); ref times {:?}",
            ticks[t0..=t1]
                .iter()
                .map(|t| (t.ref_time[r], t.low_conf[r], t.waiting[r]))
                .collect::<Vec<_>>()
        );
        least = least.min((start_s - a.earliest_s) / h);
        checked += 1;
        if a.latest_s.is_finite() && !lc_now && !faults {
            bounded += 1;
            assert!(
                start_s <= a.latest_s + 1e-9 * h,
                "tick {t0}: {a:?} announced, started only after {start_s} s (tick {t1})"
            );
        }
    }
    (checked, bounded, least)
}

/// Runs the beam search from `w`'s coordinator and gives its sequence's inputs to `w` tick by
/// tick (after an overlap the fault cleared before each tick, as the search runs it); the
/// replay ends where the search's sequence ended. Returns the search's run.
fn replay_beam(
    w: &mut Watch<tandem_realtime::Coordinator>,
    width: u32,
    budget: u64,
) -> AdversaryRun {
    let end = beam_search_run(w.inner.clone(), width as usize, budget).unwrap();
    for (i, &op) in end.operators.iter().enumerate() {
        if end.run.first_overlap.is_some_and(|f| i as u64 > f) {
            w.clear_fault();
        }
        w.tick(op).unwrap();
    }
    assert_eq!(
        (w.inner.ticks(), w.inner.clock_s(), w.inner.is_finished()),
        (
            end.coordinator.ticks(),
            end.coordinator.clock_s(),
            end.coordinator.is_finished()
        )
    );
    end.run
}

/// Announcements checked, of them bounded, of them in the beam search's sequence.
fn rounds_case(seed: u64, n: usize, holds: bool, switch_ticks: f64) -> (u64, u64, u64) {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    let round = HeldRound::random(Family::of_seed(seed), n, holds, &mut r);
    let tick_s = round.case.tick_s;
    let c = round
        .coordinator()
        .with_switch_s(switch_ticks * tick_s)
        .unwrap();
    let budget = round.budget();
    let set = round.case.adversaries(&round.robots, &mut r);
    let (mut checked, mut bounded, mut beam) = (0, 0, 0);
    for a in set {
        let mut w = Watch {
            inner: c.clone(),
            ticks: Vec::new(),
        };
        let run = match a {
            // The search's sequence, replayed tick by tick from the same start.
            Adversary::Beam { width } => replay_beam(&mut w, width, budget),
            _ => run_adversary_on(&mut w, a, &mut r, 1, budget).unwrap(),
        };
        let faults = run.overlap_ticks > 0;
        let (k, b, _) = check_run(&w.ticks, tick_s, run.finished, faults);
        checked += k;
        bounded += b;
        if matches!(a, Adversary::Beam { .. }) {
            beam += k;
        }
    }
    (checked, bounded, beam)
}

fn cell_case(seed: u64, n: usize, switch_ticks: f64) -> (u64, u64) {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    let (task, holds) = random_cell_task(&mut r, 40, CellHolds::Uniform);

    let order = random_order(&groups(task.conf(), &holds).unwrap(), n, &mut r);
    let tick_s = 0.05 * r.random_range(0.2..2.0);
    let c = ContinuousCoordinator::new(task, &holds, &order, n, tick_s)
        .unwrap()
        .with_switch_s(switch_ticks * tick_s)
        .unwrap();
    let set = adversary_set(n, [0.3, 3.0], 4000, &mut r);
    let (mut checked, mut bounded) = (0, 0);
    for a in set {
        let mut w = Watch {
            inner: c.clone(),
            ticks: Vec::new(),
        };
        let run = run_adversary_on(&mut w, a, &mut r, 4, 4000).unwrap();
        let (k, b, _) = check_run(&w.ticks, tick_s, false, run.overlap_ticks > 0);
        checked += k;
        bounded += b;
    }
    (checked, bounded)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn rounds_never_start_a_stretch_before_its_announced_earliest(
        seed in 0u64..1_000_000,
        n in 2usize..=4,
        holds in any::<bool>(),
        switch in prop_oneof![Just(0.0), Just(3.0)],
    ) {
        let (checked, _, _) = rounds_case(seed, n, holds, switch);
        prop_assert!(checked > 0, "no announcement checked");
    }

    #[test]
    fn a_cell_never_starts_a_stretch_before_its_announced_earliest(
        seed in 0u64..1_000_000,
        n in 2usize..=4,
        switch in prop_oneof![Just(0.0), Just(3.0)],
    ) {
        let (checked, _) = cell_case(seed, n, switch);
        prop_assert!(checked > 0, "no announcement checked");
    }
}

/// Not vacuous: over fixed seeds the latest is bounded in many announcements, in both cells.
#[test]
fn announcements_are_checked_and_latest_is_often_bounded() {
    let (mut rk, mut rb, mut ck, mut cb, mut beam) = (0, 0, 0, 0, 0);
    for seed in 0..8 {
        let (k, b, kb) = rounds_case(seed, 2 + (seed as usize % 3), seed % 2 == 0, 0.0);
        rk += k;
        rb += b;
        beam += kb;
        let (k, b) = cell_case(seed, 2 + (seed as usize % 3), 2.0);
        ck += k;
        cb += b;
    }
    eprintln!(
        "rounds: {rk} announcements checked ({beam} in the beam search's sequences), {rb} \
         bounded; cell: {ck}, {cb}"
    );
    assert!(beam > 0, "the beam search's sequences announce nothing");
    assert!(rb * 20 >= rk && rb > 0, "rounds: {rb} of {rk} bounded");
    assert!(cb * 20 >= ck && cb > 0, "cell: {cb} of {ck} bounded");
}

/// By hand: [HC, LC, HC] of 1 s, ψ̇ = 1, bounds [½, 2] (F = 2, S = ½), tick ½ s, two robots
/// of a continuous cell, robot 0's stretch first, a switch time of 1 s. On high confidence a
/// cell's robot runs on plan (½ s of clock a tick), so robot 0's stretch at 1 s of clock is
/// reported by its 2nd tick, which starts ½ s from now, whatever the operator does.
#[test]
fn the_first_announcement_by_hand() {
    let task = Timeline::new(
        &[true, false, true],
        &[1.0; 3],
        &[0.5; 3],
        &[2.0; 3],
        0.0,
        1.0,
    )
    .unwrap();
    let mut cell = ContinuousCoordinator::new(task.clone(), &[], &[(0, 0), (1, 0)], 2, 0.5)
        .unwrap()
        .with_switch_s(1.0)
        .unwrap();
    // Before any tick: robot 0 holds the token at clock 0, its stretch at 1 s of clock (HC
    // runs on plan: 2 ticks; the 2nd reports it, starting ½ s from now).
    let a = cell.pre_alert().unwrap();
    assert_eq!(a.robot, 0);
    assert_eq!(a.earliest_s, 0.5);
    assert_eq!(a.latest_s, 0.5);
    let t = cell.tick(Operator::Scheduled).unwrap();
    assert!(!t.low_conf[0]);
    let a = t.next.unwrap();
    assert_eq!((a.robot, a.earliest_s, a.latest_s), (0, 0.0, 0.0));
    // Robot 0 in its stretch: the next is robot 1's, waiting for the token: unbounded.
    let t = cell.tick(Operator::Slowest).unwrap();
    assert!(t.low_conf[0]);
    let a = t.next.unwrap();
    assert_eq!(a.robot, 1);
    assert!(a.latest_s.is_infinite());
}

/// The continuous cell names the robot the token passes to next, not the lowest-numbered
/// robot waiting at a gate. By hand: [HC, LC, HC] of 1 s, bounds [½, 2], tick ½ s, three robots
/// in the serial order 0, 1, 2, no switch time. After robot 0's stretch starts (clock 1 s), the
/// token moves on no sooner than the end of the next tick (robot 0 through its second of
/// low confidence at rate 2), so robot 1 passes its gate in the tick after and reports its
/// stretch (1 s of clock on plan: two ticks) in the tick starting 2 ticks = 1 s from now;
/// robot 2 waits as long but gets the token after robot 1. Then, whichever robot is in its
/// stretch, the one named is the next in the order, never a robot waiting behind it (robot 0
/// back at its gate while robot 1 has the token was named before: it is the lowest index).
#[test]
fn a_cell_names_the_robot_the_token_passes_to_next() {
    let task = Timeline::new(
        &[true, false, true],
        &[1.0; 3],
        &[0.5; 3],
        &[2.0; 3],
        0.0,
        1.0,
    )
    .unwrap();
    let mut cell = ContinuousCoordinator::new(task, &[], &[(0, 0), (1, 0), (2, 0)], 3, 0.5)
        .unwrap()
        .with_switch_s(0.0)
        .unwrap();
    let t = cell.tick(Operator::Scheduled).unwrap();
    assert!(!t.low_conf[0]);
    let t = cell.tick(Operator::Slowest).unwrap();
    assert!(t.low_conf[0]);
    let a = t.next.unwrap();
    assert_eq!((a.robot, a.earliest_s), (1, 1.0));
    assert!(a.latest_s.is_infinite());
    let mut named = [0u32; 3];
    for _ in 0..200 {
        let t = cell.tick(Operator::Slowest).unwrap();
        let Some(r) = (0..3).find(|&r| t.low_conf[r]) else {
            continue;
        };
        let a = t.next.unwrap();
        assert_eq!(
            a.robot,
            (r + 1) % 3,
            "robot {r} in its stretch: {a:?}; {:?} {:?} {:?}",
            t.ref_time,
            t.waiting,
            cell.token()
        );
        // The token must move on first: at least one tick.
        assert!(a.earliest_s >= 0.5, "{a:?}");
        named[a.robot] += 1;
    }
    assert!(
        named.iter().all(|&k| k > 0),
        "every robot named in turn: {named:?}"
    );
}

/// Regression (issue 42, the three-robot cell's 100 late pre-alerts): the robot named is the
/// next TURN of the token order, not the robot whose own bound is smallest. Task of 8 samples
/// of 1 s, `[HC, LC, HC, HC, HC, HC, LC, HC]`, bounds [½, 2], a usable hold at sample 5 (the
/// gate of group 1; group 0's gate is the task start), tick ½ s, no switch time, three
/// robots (0-based here) in the order `0 1 0 2 1 2`, stretches `(0,0) (1,0) (0,1) (2,0) (1,1)
/// (2,1)`: each stretch is its own group, so this is the token sequence.
///
/// By hand, at the end of the tick in which robot 1 enters its second stretch (tick 21 at the
/// scheduled pace: robot 1's clock 6.0 s): robot 2, whose turn `(2,1)` is next, is at 3.5 s
/// on high confidence, where a cell's robot runs on plan (½ s of clock a tick): it reaches
/// the stretch at 6 s in 5 ticks, the 5th starting 4 ticks = 2.0 s from now. Robot 0 waits at
/// its next task's start (gate 0): its own bound is the token moving on (robot 1 may leave
/// sample 6 within this next tick at rate 2: 0 ticks before it), one tick, then 1 s of high
/// confidence from the gate to the stretch (2 ticks, the second starting 1 tick later):
/// 2 ticks = 1.0 s. The old rule (the smallest earliest start) named robot 0 at 1.0 s,
/// although its turn `(0,0)` comes after robot 2's; the rule now raises robot 0 to one tick
/// past robot 2's earliest and names robot 2 at 2.0 s, and robot 2's stretch does start in
/// tick 26, exactly 4 ticks after tick 21 ends. Over the whole run, during every robot's
/// stretch the robot named is the next entry of the order.
#[test]
fn a_cell_names_the_next_turn_not_the_smallest_own_bound() {
    let task = Timeline::new(
        &[true, false, true, true, true, true, false, true],
        &[1.0; 8],
        &[0.5; 8],
        &[2.0; 8],
        0.0,
        1.0,
    )
    .unwrap();
    let order = [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (2, 1)];
    let mut cell = ContinuousCoordinator::new(task, &[5], &order, 3, 0.5)
        .unwrap()
        .with_switch_s(0.0)
        .unwrap();
    let ticks: Vec<Tick> = (0..400)
        .map(|_| cell.tick(Operator::Scheduled).unwrap())
        .collect();
    let at = ticks
        .iter()
        .position(|t| t.low_conf[1] && t.ref_time[1] >= 6.0)
        .unwrap();
    assert_eq!(at, 21);
    let t = &ticks[at];
    assert_eq!(t.ref_time, [0.0, 6.0, 3.5]);
    assert!(t.waiting[0]);
    let a = t.next.unwrap();
    assert_eq!((a.robot, a.earliest_s), (2, 2.0), "{a:?}");
    let starts = ticks
        .iter()
        .position(|t| t.low_conf[2] && t.ref_time[2] >= 6.0)
        .unwrap();
    assert_eq!(starts, 26);
    // Every stretch in order: during the k-th, the robot named is the (k+1)-th entry's.
    let mut k = 0usize;
    let mut inside = None;
    let mut checked = 0;
    for t in &ticks {
        let Some(r) = (0..3).find(|&r| t.low_conf[r]) else {
            inside = None;
            continue;
        };
        if inside != Some(r) {
            assert_eq!(r, order[k % order.len()].0, "stretch {k} out of order");
            inside = Some(r);
            k += 1;
        }
        let want = order[k % order.len()].0;
        assert_eq!(
            t.next.map(|a| a.robot),
            Some(want),
            "stretch {}: {t:?}",
            k - 1
        );
        checked += 1;
    }
    assert!(k >= 24 && checked >= 48, "{k} stretches, {checked} ticks");
}

/// Regression (issue 42, the three-robot study's rounds: 3 of 8 stretches pre-alerted under
/// 1 s ahead): a robot waiting for its start (rule 3: it follows the running robot furthest
/// behind) cannot start before every running robot has reached its start or stopped. Two
/// robots of 30 samples of 1 s, rates [½, 2]; robot 1 (0-based 0) starts at 0 and is
/// low-confidence on samples 20–21, robot 2 (0-based 1) starts at 40 and is low-confidence
/// on its first samples 0–1; tick ½ s. Robot 2 can start only once robot 1 has finished
/// (30 s of clock, at least 15 s at rate 2), so robot 1's stretch (20 s of clock, at least
/// 10 s: named at 9.5 s, the tick rounding) is next. The old rule took the wait for a start as 0 and named robot 2 at 0 s.
#[test]
fn rounds_do_not_name_a_robot_whose_start_is_far_off() {
    let conf0: Vec<bool> = (0..30).map(|n| !(20..22).contains(&n)).collect();
    let conf1: Vec<bool> = (0..30).map(|n| n >= 2).collect();
    let (g, lo, hi) = (vec![1.0; 30], vec![0.5; 30], vec![2.0; 30]);
    let robots = vec![
        Timeline::new(&conf0, &g, &lo, &hi, 0.0, 1.0).unwrap(),
        Timeline::new(&conf1, &g, &lo, &hi, 40.0, 1.0).unwrap(),
    ];
    let mut c = tandem_realtime::Coordinator::new(robots, 0.5).unwrap();
    let t = c.tick(Operator::Scheduled).unwrap();
    let a = t.next.unwrap();
    // 20 s of clock at rate 2 take 10 s: the tick that reaches the stretch is the 20th,
    // starting 19 ticks = 9.5 s from now.
    assert_eq!((a.robot, a.earliest_s), (0, 9.5), "{a:?}");
    let mut first = [None; 2];
    for k in 1..400u32 {
        let t = c.tick(Operator::Fastest).unwrap();
        for (r, f) in first.iter_mut().enumerate() {
            if t.low_conf[r] && f.is_none() {
                *f = Some(k);
            }
        }
        if let (Some(a), None) = (t.next, first[0]) {
            assert_eq!(a.robot, 0, "tick {k}: {a:?}");
        }
    }
    assert!(first[0].unwrap() < first[1].unwrap(), "{first:?}");
}
