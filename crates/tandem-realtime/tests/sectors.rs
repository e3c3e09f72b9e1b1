//! Rounds of `M` operators in fixed sectors (issue 44; docs/decisions.md, "M operators in
//! rounds: sectors end to end (issue 44)"): `Coordinator::sectored` is the sectors' one-operator
//! coordinators run side by side, tick for tick; each sector's plans checked for one operator
//! keep at most one robot of the sector low-confidence under every operator input (the test
//! kit's adversaries of one operator, per sector, and the per-operator policies), so at most
//! `M` in all, each under its sector's operator, no stretch handed over, no fault.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use tandem_realtime::holds::release_rules;
use tandem_realtime::margins::operators::assign_operators;
use tandem_realtime::testkit::{
    Case, Family, adversary_budget, random_usable, rng, tight_starts, with_random_dwells,
};
use tandem_realtime::{
    After, Coordinator, Error, Hold, MarginParams, Operator, OperatorCount, PreAlert, Timeline,
    check_margins,
};

/// `m` sectors of `g` robots of one random case, each made tight at the edge of the
/// one-operator check with a switch time of `k` ticks (robot 0 of each at 0); `None` when a
/// sector has no accepted start.
fn sectors(seed: u64, g: usize, m: usize, k: u64) -> Option<(Case, Vec<Timeline>, Vec<usize>)> {
    let mut r = rng(seed);
    let case = Case::random(Family::of_seed(seed), g, &mut r);
    let params = MarginParams {
        tick_s: case.tick_s,
        switch_s: k as f64 * case.tick_s,
    };
    let check = |robots: &[Timeline], _: f64| check_margins(robots, &[], &params);
    let mut robots = Vec::new();
    let mut sector_of = Vec::new();
    for o in 0..m {
        let (starts, _) = tight_starts(&case, check, &mut r)?;
        robots.extend(case.robots_at(&starts));
        sector_of.extend(std::iter::repeat_n(o, g));
    }
    Some((case, robots, sector_of))
}

fn pick(r: &mut ChaCha8Rng, policy: usize, o: usize, tick: u64) -> Operator {
    match policy {
        0 => Operator::Fastest,
        1 => Operator::Slowest,
        2 if (tick / 5 + o as u64) % 2 == 0 => Operator::Fastest,
        2 => Operator::Slowest,
        _ if r.random_bool(0.5) => Operator::Fastest,
        _ => Operator::Gradient(r.random_range(0.1..6.0)),
    }
}

/// `m` sectors of `g` robots of one random case with hold points: per sector robots at
/// interleaved starts (robot 0 at 0), a random quarter of their usable holds, their release
/// rules and random dwells, redrawn until the one-operator check at a switch time of `k`
/// ticks accepts them with at least one release rule (`g ≥ 2`); the holds renumbered to the
/// round's robots. `None` when a sector finds none in 30 draws.
fn held_sectors(seed: u64, g: usize, m: usize, k: u64) -> Option<Sectored> {
    let mut r = rng(seed ^ 0x401d);
    let case = Case::random(Family::of_seed(seed), g, &mut r);
    let params = MarginParams {
        tick_s: case.tick_s,
        switch_s: k as f64 * case.tick_s,
    };
    let mut robots = Vec::new();
    let mut holds = Vec::new();
    let mut sector_of = Vec::new();
    for o in 0..m {
        let (sub, sub_holds) = (0..30).find_map(|_| {
            let starts = case.interleaved_starts(g, &mut r);
            let sub = case.robots_at(&starts);
            let usable = random_usable(&sub, &mut r);
            let rules = release_rules(&sub, &[], &usable);
            let held = with_random_dwells(&sub, rules, case.tick_s, &mut r);
            let ruled = held.iter().flatten().any(|h| !h.after.is_empty());
            (ruled && check_margins(&sub, &held, &params).unwrap()).then_some((sub, held))
        })?;
        robots.extend(sub);
        holds.extend(sub_holds.into_iter().map(|mut list| {
            for h in &mut list {
                for a in &mut h.after {
                    a.robot += o * g;
                }
            }
            list
        }));
        sector_of.extend(std::iter::repeat_n(o, g));
    }
    Some((case, robots, holds, sector_of))
}

/// A case, the round's robots, their holds (empty: none) and each robot's sector.
type Sectored = (Case, Vec<Timeline>, Vec<Vec<Hold>>, Vec<usize>);

/// What [`side_by_side`] saw: the most robots low-confidence in one tick, and the ticks in
/// which some robot stood at a hold.
struct Seen {
    most: usize,
    waiting_ticks: u64,
}

/// Runs the sectored coordinator of `round` (sectors of `g` robots, `m` operators, switch time
/// `k` ticks) and each sector's own [`Coordinator::with_margins`] side by side under four
/// input policies per operator, asserting tick for tick the same reference times, clocks,
/// low-confidence, running and waiting flags, each low-confidence robot under its sector's
/// operator, at most one per sector, the pre-alert the sectors' soonest, no fault, every
/// robot finished within its budget.
fn side_by_side(seed: u64, round: &Sectored, g: usize, m: usize, k: u64) -> Seen {
    let (case, robots, holds, sector_of) = round;
    let params = MarginParams {
        tick_s: case.tick_s,
        switch_s: k as f64 * case.tick_s,
    };
    let om = OperatorCount::new(m).unwrap();
    let c = Coordinator::sectored(robots.clone(), holds, sector_of, om, &params).unwrap();
    assert_eq!((c.operators(), c.switch_ticks()), (m, k));
    assert_eq!(c.has_holds(), !holds.is_empty());
    let budget = adversary_budget(robots, holds, case.tick_s);
    let mut r = rng(seed ^ 0x5ec);
    let mut seen = Seen {
        most: 0,
        waiting_ticks: 0,
    };
    for policy in 0..4 {
        let mut all = c.clone();
        let mut own: Vec<Coordinator> = (0..m)
            .map(|o| {
                let sub: Vec<Timeline> = robots[o * g..(o + 1) * g].to_vec();
                let sub_holds: Vec<Vec<Hold>> = holds
                    .iter()
                    .skip(o * g)
                    .take(g)
                    .map(|list| {
                        let mut list = list.clone();
                        for h in &mut list {
                            for a in &mut h.after {
                                a.robot -= o * g;
                            }
                        }
                        list
                    })
                    .collect();
                Coordinator::with_margins(sub, &sub_holds, &params).unwrap()
            })
            .collect();
        let mut tick = 0;
        while !all.is_finished() {
            assert!(tick < budget, "seed {seed}: not finished in {budget} ticks");
            let inputs: Vec<Operator> = (0..m).map(|o| pick(&mut r, policy, o, tick)).collect();
            let t = all.tick_many(&inputs).unwrap();
            assert!(
                t.fault.is_none() && !t.over(m),
                "seed {seed} tick {tick}: {t:?}"
            );
            let mut per = vec![0; m];
            // The pre-alert is the sectors' soonest (the first sector's on a tie).
            let mut soonest: Option<PreAlert> = None;
            for (o, c1) in own.iter_mut().enumerate() {
                let t1 = c1.tick(inputs[o]).unwrap();
                if let Some(a) = t1.next
                    && soonest.is_none_or(|b| a.earliest_s < b.earliest_s)
                {
                    soonest = Some(PreAlert {
                        robot: a.robot + o * g,
                        ..a
                    });
                }
                for j in 0..g {
                    let i = o * g + j;
                    assert_eq!(t.ref_time[i], t1.ref_time[j], "seed {seed} robot {i}");
                    assert_eq!(t.low_conf[i], t1.low_conf[j], "seed {seed} robot {i}");
                    assert_eq!(t.running[i], t1.running[j]);
                    assert_eq!(t.waiting[i], t1.waiting[j], "seed {seed} robot {i}");
                    assert_eq!(all.clock_s()[i], c1.clock_s()[j]);
                    if t.low_conf[i] {
                        per[o] += 1;
                        assert_eq!(t.operator[i], Some(o as u8));
                    } else {
                        assert_eq!(t.operator[i], None);
                    }
                }
            }
            assert!(
                per.iter().all(|&x| x <= 1),
                "seed {seed} tick {tick}: {per:?}"
            );
            assert_eq!(t.next, soonest, "seed {seed} tick {tick}");
            seen.most = seen.most.max(t.low_conf.count());
            seen.waiting_ticks += u64::from(t.waiting.count() > 0);
            tick += 1;
        }
        assert!(own.iter().all(Coordinator::is_finished));
    }
    seen
}

/// The sectored coordinator ticks exactly as its sectors' own coordinators side by side (the
/// same clocks, reference times, low-confidence flags), reports each low-confidence robot under
/// its sector's operator, never has two robots of one sector low-confidence (so never more than
/// `M`) and never latches a fault, under rush, drag, alternating and random inputs per operator.
#[test]
fn sectors_run_as_their_one_operator_rounds_side_by_side() {
    let mut checked = 0;
    let mut most = 0;
    for seed in 0..16_u64 {
        let (g, m) = [(2, 2), (2, 4), (3, 2), (1, 3)][(seed % 4) as usize];
        let k = seed % 3;
        let Some((case, robots, sector_of)) = sectors(seed, g, m, k) else {
            continue;
        };
        let seen = side_by_side(seed, &(case, robots, Vec::new(), sector_of), g, m, k);
        most = most.max(seen.most);
        checked += 1;
    }
    assert!(checked >= 12, "{checked}");
    // Not vacuous: some tick has several robots low-confidence, one per sector.
    assert!(most >= 2, "{most}");
}

/// The same with hold points (one wait clock per sector): sectors of 2–3 robots with release
/// rules, random dwells and a switch time of 0–2 ticks, each sector accepted by the
/// one-operator check with its holds, tick for tick its own `with_margins` coordinator — the
/// proof that each sector keeps the one-operator guarantee with holds. Not vacuous: robots
/// stand at holds, several are low-confidence in one tick.
#[test]
fn sectors_with_holds_run_as_their_one_operator_rounds_side_by_side() {
    let mut checked = 0;
    let mut most = 0;
    let mut waiting_ticks = 0;
    for seed in 0..16_u64 {
        let (g, m) = [(2, 2), (2, 3), (3, 2), (2, 4)][(seed % 4) as usize];
        let k = seed % 3;
        let Some(round) = held_sectors(seed, g, m, k) else {
            continue;
        };
        let seen = side_by_side(seed, &round, g, m, k);
        most = most.max(seen.most);
        waiting_ticks += seen.waiting_ticks;
        checked += 1;
    }
    assert!(checked >= 12, "{checked}");
    assert!(most >= 2, "{most}");
    eprintln!("holds: checked {checked} most {most} waiting {waiting_ticks}");
    assert!(waiting_ticks > 0, "no robot ever stood at a hold");
}

/// A release rule across sectors is refused by name: a sector runs as its own round.
#[test]
fn a_release_rule_across_sectors_is_refused() {
    let robots = [0.0, 5.0].map(rigid);
    let holds = vec![
        vec![],
        vec![Hold {
            after: vec![After {
                robot: 0,
                ref_idx: 4,
            }],
            ..Hold::at(0)
        }],
    ];
    let p = MarginParams::new(1.0);
    let two = OperatorCount::new(2).unwrap();
    assert!(matches!(
        Coordinator::sectored(robots.to_vec(), &holds, &[0, 1], two, &p),
        Err(Error::BadHold { robot: 1, .. })
    ));
    // In one sector the rule is the one-operator round's.
    let c = Coordinator::sectored(robots.to_vec(), &holds, &[0, 0], two, &p).unwrap();
    assert!(c.has_holds());
    assert!(matches!(
        Coordinator::sectored(robots.to_vec(), &holds[..1], &[0, 0], two, &p),
        Err(Error::LengthMismatch { what: "holds", .. })
    ));
}

/// [HC, HC, LC, LC, HC × 6] with gradient 1 and bounds [1, 1], one sample a second.
fn rigid(start_s: f64) -> Timeline {
    let conf: Vec<bool> = (0..10).map(|k| !(2..4).contains(&k)).collect();
    let one = vec![1.0; 10];
    Timeline::new(&conf, &one, &one, &one, start_s, 1.0).unwrap()
}

/// The regression test of the sectors' rule: three rigid robots whose stretches coincide. In
/// sectors `[0, 0, 1]` the first sector's two robots would share operator 0: refused
/// (`Unsafe`), as a rule that let `M + 1 = 3` robots in would not be. In sectors `[0, 1, 2]`
/// of three operators they run, three low-confidence at once under operators 0, 1, 2. One input
/// is refused with `M > 1`; a sector outside `0..M` and a wrong length are refused by name.
#[test]
fn two_coinciding_robots_in_one_sector_are_refused() {
    let robots = [0.0; 3].map(rigid);
    let p = MarginParams::new(1.0);
    let two = OperatorCount::new(2).unwrap();
    assert!(matches!(
        Coordinator::sectored(robots.clone(), &[], &[0, 0, 1], two, &p),
        Err(Error::Unsafe { .. })
    ));
    assert!(matches!(
        Coordinator::sectored(robots.clone(), &[], &[0, 2, 1], two, &p),
        Err(Error::BadParam {
            name: "sector_of",
            ..
        })
    ));
    assert!(matches!(
        Coordinator::sectored(robots.clone(), &[], &[0, 1], two, &p),
        Err(Error::LengthMismatch { .. })
    ));
    let mut c =
        Coordinator::sectored(robots, &[], &[0, 1, 2], OperatorCount::new(3).unwrap(), &p).unwrap();
    assert!(matches!(
        c.tick(Operator::Scheduled),
        Err(Error::OperatorInputs { got: 1, want: 3 })
    ));
    let mut most = 0;
    while !c.is_finished() {
        let t = c.tick_many(&[Operator::Scheduled; 3]).unwrap();
        assert!(t.fault.is_none());
        if t.low_conf.count() == 3 {
            assert_eq!(t.operator, [Some(0), Some(1), Some(2)], "{t:?}");
        }
        most = most.max(t.low_conf.count());
    }
    assert_eq!(most, 3);
    // Robot 2 six seconds later in sector 0 with robot 0: clear of it, two operators suffice.
    let robots = [0.0, 0.0, 6.0].map(rigid);
    let mut c = Coordinator::sectored(robots, &[], &[0, 1, 0], two, &p).unwrap();
    let mut seen = Vec::new();
    while !c.is_finished() {
        let t = c
            .tick_many(&[Operator::Fastest, Operator::Slowest])
            .unwrap();
        assert!(t.fault.is_none());
        seen.push(t.operator.to_vec());
    }
    assert!(seen.iter().any(|o| o == &[Some(0), Some(1), None]));
    assert!(seen.iter().any(|o| o == &[None, None, Some(0)]));
}

/// Samples of 1 s `[HC, LC, LC, HC, LC, LC, HC]` (head `a` = 1 s, two stretches of `L` = 2 s
/// with `G` = 1 s of high confidence between, tail `b` = 1 s, `D` = 7 s), gradient 1 in
/// `[1 − w, 1 + w]`, robot at `start_s`.
fn two_stretches(start_s: f64, w: f64) -> Timeline {
    let conf = [true, false, false, true, false, false, true];
    let (g, lo, hi) = ([1.0; 7], [1.0 - w; 7], [1.0 + w; 7]);
    Timeline::new(&conf, &g, &lo, &hi, start_s, 1.0).unwrap()
}

/// The least `T_total` (s) of three robots of [`two_stretches`] under two operators on a grid
/// of starts (multiples of `step` up to `max_s`, robot 0 at 0): pooled
/// ([`assign_operators`], the windows' colouring) and the best sectored plan (a sector of two
/// robots checked by [`check_margins`] beside a sector of one; the robots are alike, so every
/// partition is this one). `None` where nothing on the grid is accepted.
fn pooled_and_sectored(w: f64, tick_s: f64, step: f64, max_s: f64) -> (Option<f64>, Option<f64>) {
    let two = OperatorCount::new(2).unwrap();
    let grid: Vec<f64> = (0..=(max_s / step).round() as usize)
        .map(|k| k as f64 * step)
        .collect();
    let end = |starts: &[f64]| starts.iter().fold(0.0_f64, |a, &s| a.max(s)) + 7.0;
    let mut pooled: Option<f64> = None;
    for &x in &grid {
        for &y in grid.iter().filter(|&&y| y >= x) {
            let t = end(&[0.0, x, y]);
            if pooled.is_some_and(|p| p <= t) {
                continue;
            }
            let robots = [0.0, x, y].map(|s| two_stretches(s, w));
            if assign_operators(&robots, tick_s, two, 0).unwrap().is_some() {
                pooled = Some(t);
            }
        }
    }
    let p = MarginParams::new(tick_s);
    let sectored = grid
        .iter()
        .find(|&&d| check_margins(&[0.0, d].map(|s| two_stretches(s, w)), &[], &p).unwrap())
        .map(|&d| end(&[0.0, d]));
    (pooled, sectored)
}

/// Pooled against sectored where three robots do not divide among two operators (issue 44,
/// docs/decisions.md "M operators in rounds: sectors with hold points"). A sector of two
/// robots needs their four stretches of `L` = 2 s disjoint: offset `d ≥ 2L + G` = 5 s when
/// `G < L` (d = 2, 3, 4 overlap a stretch of the other robot), so the best sectored round is
/// at least `D + 5` = 12 s (the one-operator check takes `d` = 5.75 s: 12.75 s). Pooled,
/// starts 0, 2, 4 s would put every pair of robots in low confidence at some time but never
/// three (stretches [1, 3] ∪ [4, 6], [3, 5] ∪ [6, 8], [5, 7] ∪ [8, 10]): 11 s; the windows'
/// check needs room at the two touching ends and takes 0, 2.5, 5 s: 12 s. With rigid robots
/// (bounds [1, 1]) the windows are the stretches themselves (plus the tolerance): pooling wins.
/// With bounds of ±10 % the windows widen with the accumulated drift and pooling loses
/// (printed: 13.25 s pooled against 12.5 s sectored).
#[test]
fn pooling_beats_sectors_where_three_robots_overlap_pairwise_on_rigid_timing() {
    let (pooled, sectored) = pooled_and_sectored(0.0, 0.25, 0.25, 12.0);
    eprintln!("rigid: pooled {pooled:?} sectored {sectored:?}");
    let (pooled, sectored) = (pooled.unwrap(), sectored.unwrap());
    assert!(sectored >= 12.0, "{sectored}");
    // Never below the fleet bound a + N·ΣL/M + b = 1 + 3·4/2 + 1 = 8 s.
    assert!((8.0..sectored).contains(&pooled), "{pooled} {sectored}");
    let (pooled10, sectored10) = pooled_and_sectored(0.1, 0.25, 0.25, 12.0);
    eprintln!("±10 %: pooled {pooled10:?} sectored {sectored10:?}");
    assert!(sectored10.is_some() && pooled10.is_some());
}
