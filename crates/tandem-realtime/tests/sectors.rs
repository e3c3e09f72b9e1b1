//! Rounds of `M` operators in fixed sectors (issue 44; docs/decisions.md, "M operators in
//! rounds: sectors end to end (issue 44)"): `Coordinator::sectored` is the sectors' one-operator
//! coordinators run side by side, tick for tick; each sector's plans checked for one operator
//! keep at most one robot of the sector low-confidence under every operator input (the test
//! kit's adversaries of one operator, per sector, and the per-operator policies), so at most
//! `M` in all, each under its sector's operator, no stretch handed over, no fault.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use tandem_realtime::testkit::{Case, Family, adversary_budget, rng, tight_starts};
use tandem_realtime::{
    Coordinator, Error, MarginParams, Operator, OperatorCount, Timeline, check_margins,
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
        let params = MarginParams {
            tick_s: case.tick_s,
            switch_s: k as f64 * case.tick_s,
        };
        let om = OperatorCount::new(m).unwrap();
        let c = Coordinator::sectored(robots.clone(), &sector_of, om, &params).unwrap();
        assert_eq!((c.operators(), c.switch_ticks()), (m, k));
        let budget = adversary_budget(&robots, &[], case.tick_s);
        let mut r = rng(seed ^ 0x5ec);
        for policy in 0..4 {
            let mut all = c.clone();
            let mut own: Vec<Coordinator> = (0..m)
                .map(|o| {
                    let sub: Vec<Timeline> = robots[o * g..(o + 1) * g].to_vec();
                    Coordinator::with_margins(sub, &[], &params).unwrap()
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
                for (o, c1) in own.iter_mut().enumerate() {
                    let t1 = c1.tick(inputs[o]).unwrap();
                    for j in 0..g {
                        let i = o * g + j;
                        assert_eq!(t.ref_time[i], t1.ref_time[j], "seed {seed} robot {i}");
                        assert_eq!(t.low_conf[i], t1.low_conf[j], "seed {seed} robot {i}");
                        assert_eq!(t.running[i], t1.running[j]);
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
                most = most.max(t.low_conf.count());
                tick += 1;
            }
            assert!(own.iter().all(Coordinator::is_finished));
        }
        checked += 1;
    }
    assert!(checked >= 12, "{checked}");
    // Not vacuous: some tick has several robots low-confidence, one per sector.
    assert!(most >= 2, "{most}");
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
        Coordinator::sectored(robots.clone(), &[0, 0, 1], two, &p),
        Err(Error::Unsafe { .. })
    ));
    assert!(matches!(
        Coordinator::sectored(robots.clone(), &[0, 2, 1], two, &p),
        Err(Error::BadParam {
            name: "sector_of",
            ..
        })
    ));
    assert!(matches!(
        Coordinator::sectored(robots.clone(), &[0, 1], two, &p),
        Err(Error::LengthMismatch { .. })
    ));
    let mut c =
        Coordinator::sectored(robots, &[0, 1, 2], OperatorCount::new(3).unwrap(), &p).unwrap();
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
    let mut c = Coordinator::sectored(robots, &[0, 1, 0], two, &p).unwrap();
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
