//! The sectored continuous cell (issue 44; docs/decisions.md, "The continuous cell of M
//! operators: one hand-over per sector, pooled or sectored by measurement (issue 44)"):
//! operator `o` serves only sector `o`'s robots by the one-operator rule, so each sector ticks exactly as its own one-operator
//! cell — checked here tick for tick, bit for bit, from the start and across a hand-over — and
//! at most `M` robots are low-confidence in any tick, each under its sector's operator, under
//! every operator policy.

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tandem_realtime::cell::{ContinuousCoordinator, SectorOrder, groups};
use tandem_realtime::testkit::{CellHolds, random_cell_task, random_order};
use tandem_realtime::{Controller, Error, Operator, OperatorCount, Timeline};

/// Each operator's policy.
#[derive(Clone, Copy, Debug)]
enum Policy {
    Rush,
    Drag,
    RandomExtreme,
    RandomGradient,
    /// Per operator: rush for 7 ticks, drag for 7, shifted by the operator's index.
    Mixed,
}

fn input(policy: Policy, o: usize, tick: u64, rng: &mut ChaCha8Rng) -> Operator {
    match policy {
        Policy::Rush => Operator::Fastest,
        Policy::Drag => Operator::Slowest,
        Policy::RandomExtreme if rng.random_bool(0.5) => Operator::Fastest,
        Policy::RandomExtreme => Operator::Slowest,
        Policy::RandomGradient => Operator::Gradient(rng.random_range(0.1..6.0)),
        Policy::Mixed if (tick / 7 + o as u64) % 2 == 0 => Operator::Fastest,
        Policy::Mixed => Operator::Slowest,
    }
}

/// A random sectored cell of `n` robots in `m` sectors (robot `r` in sector `r mod m`, so a
/// sector's robots are not contiguous), each sector a random one-operator order; with each
/// sector's own one-operator cell of the same orders beside it.
struct Case {
    cell: ContinuousCoordinator,
    own: Vec<ContinuousCoordinator>,
    members: Vec<Vec<usize>>,
    task: Timeline,
    holds: Vec<usize>,
    tick_s: f64,
    switch_s: f64,
}

fn case(seed: u64, n: usize, m: usize, switch: bool) -> Case {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (task, holds) = random_cell_task(&mut rng, 60, CellHolds::Uniform);
    let gs = groups(task.conf(), &holds).unwrap();
    let members: Vec<Vec<usize>> = (0..m)
        .map(|o| (0..n).filter(|r| r % m == o).collect())
        .collect();
    let sectors: Vec<SectorOrder> = members
        .iter()
        .map(|r| (r.clone(), random_order(&gs, r.len(), &mut rng)))
        .collect();
    let tick_s = 0.05 * rng.random_range(0.2..2.0);
    let switch_s = if switch {
        rng.random_range(0.0..0.5)
    } else {
        0.0
    };
    let cell = ContinuousCoordinator::sectored(task.clone(), &holds, &sectors, n, tick_s)
        .unwrap()
        .with_switch_s(switch_s)
        .unwrap();
    let own = sectors
        .iter()
        .map(|(r, order)| {
            ContinuousCoordinator::new(task.clone(), &holds, order, r.len(), tick_s)
                .unwrap()
                .with_switch_s(switch_s)
                .unwrap()
        })
        .collect();
    Case {
        cell,
        own,
        members,
        task,
        holds,
        tick_s,
        switch_s,
    }
}

/// Ticks the sectored cell and every sector's own cell `ticks` times with the same inputs
/// (operator `o`'s to sector `o`), asserting that every robot's clock, tasks, low confidence,
/// operator, waiting and running flags are its own cell's, bit for bit. Returns the most
/// robots low-confidence in one tick.
fn tick_alike(c: &mut Case, policy: Policy, ticks: u64, rng: &mut ChaCha8Rng) -> usize {
    let m = c.own.len();
    let mut most = 0;
    for tick in 0..ticks {
        let inputs: Vec<Operator> = (0..m).map(|o| input(policy, o, tick, rng)).collect();
        let t = c.cell.tick_many(&inputs).unwrap();
        assert!(t.fault.is_none() && !t.over(m), "tick {tick}: {t:?}");
        most = most.max(t.low_conf.count());
        for (o, own) in c.own.iter_mut().enumerate() {
            let u = own.tick(inputs[o]).unwrap();
            for (j, &r) in c.members[o].iter().enumerate() {
                assert_eq!(
                    c.cell.clock_s()[r].to_bits(),
                    own.clock_s()[j].to_bits(),
                    "tick {tick}: robot {r} (sector {o}, robot {j} there)"
                );
                assert_eq!(t.tasks[r], u.tasks[j], "tick {tick}: robot {r}");
                assert_eq!(t.low_conf[r], u.low_conf[j], "tick {tick}: robot {r}");
                assert_eq!(t.waiting[r], u.waiting[j], "tick {tick}: robot {r}");
                assert_eq!(t.running[r], u.running[j], "tick {tick}: robot {r}");
                assert_eq!(
                    t.operator[r],
                    u.operator[j].map(|_| o as u8),
                    "tick {tick}: robot {r}"
                );
                assert_eq!(t.ref_time[r].to_bits(), u.ref_time[j].to_bits());
            }
        }
    }
    most
}

#[test]
fn each_sector_ticks_as_its_own_one_operator_cell() {
    let mut several = 0;
    for seed in 0..16_u64 {
        for &(n, m) in &[(4, 2), (5, 2), (8, 4), (16, 4)] {
            let policy = [
                Policy::Rush,
                Policy::Drag,
                Policy::RandomExtreme,
                Policy::RandomGradient,
                Policy::Mixed,
            ][seed as usize % 5];
            let mut c = case(seed, n, m, seed % 2 == 1);
            let mut rng = ChaCha8Rng::seed_from_u64(seed + 100);
            let most = tick_alike(&mut c, policy, 1500, &mut rng);
            several += usize::from(most >= 2);
            // Every robot progressed (the sectors run their own cells, which are live).
            assert!(c.cell.tasks_completed().iter().all(|&k| k >= 1), "{seed}");
        }
    }
    // Not vacuous: sectors do run at once.
    assert!(
        several >= 32,
        "{several} of 64 runs had two robots low-confidence at once"
    );
}

#[test]
fn a_sectored_hand_over_is_each_sectors_own_hand_over() {
    let mut handed = 0;
    for seed in 0..8_u64 {
        let (n, m) = [(4, 2), (8, 4)][seed as usize % 2];
        let mut c = case(seed, n, m, seed % 2 == 0);
        let mut rng = ChaCha8Rng::seed_from_u64(seed + 200);
        tick_alike(&mut c, Policy::RandomExtreme, 300, &mut rng);
        // A new plan: other random orders for the same sectors.
        let gs = groups(c.task.conf(), &c.holds).unwrap();
        let orders: Vec<Vec<(usize, usize)>> = c
            .members
            .iter()
            .map(|r| random_order(&gs, r.len(), &mut rng))
            .collect();
        let sectors: Vec<SectorOrder> = c.members.iter().cloned().zip(orders.clone()).collect();
        let fresh =
            ContinuousCoordinator::sectored(c.task.clone(), &c.holds, &sectors, n, c.tick_s)
                .unwrap()
                .with_switch_s(c.switch_s)
                .unwrap();
        // A hand-over point needs every robot of every sector outside its groups at once.
        for _ in 0..20_000 {
            let mut next = fresh.clone();
            if next.take_over(&c.cell).is_ok() {
                // Then every sector is at a hand-over point of its own new cell.
                let mut own_next = Vec::new();
                for (o, own) in c.own.iter().enumerate() {
                    let mut x = ContinuousCoordinator::new(
                        c.task.clone(),
                        &c.holds,
                        &orders[o],
                        c.members[o].len(),
                        c.tick_s,
                    )
                    .unwrap()
                    .with_switch_s(c.switch_s)
                    .unwrap();
                    x.take_over(own).unwrap();
                    own_next.push(x);
                }
                c.cell = next;
                c.own = own_next;
                handed += 1;
                break;
            }
            tick_alike(&mut c, Policy::RandomExtreme, 1, &mut rng);
        }
        tick_alike(&mut c, Policy::Mixed, 1500, &mut rng);
    }
    eprintln!("handed over in {handed} of 8 cases");
    assert!(handed >= 4, "handed over in {handed} of 8 cases");
}

/// One hand-over per sector (`take_over_sector`): each sector takes the new plan when its own
/// robots are at a hand-over point, while the others run on — also while a robot of another
/// sector is in the middle of a stretch — and takes it exactly as its own one-operator cell's
/// `take_over` does (the same ticks succeed, and the cells stay equal tick for tick, bit for
/// bit, across every sector's hand-over and for 1500 ticks after the last).
#[test]
fn each_sector_hands_over_on_its_own() {
    let (mut all, mut mid_stretch) = (0, 0);
    for seed in 0..8_u64 {
        let (n, m) = [(4, 2), (8, 4)][seed as usize % 2];
        let mut c = case(seed, n, m, seed % 2 == 0);
        let mut rng = ChaCha8Rng::seed_from_u64(seed + 300);
        tick_alike(&mut c, Policy::RandomExtreme, 300, &mut rng);
        let gs = groups(c.task.conf(), &c.holds).unwrap();
        let orders: Vec<Vec<(usize, usize)>> = c
            .members
            .iter()
            .map(|r| random_order(&gs, r.len(), &mut rng))
            .collect();
        let sectors: Vec<SectorOrder> = c.members.iter().cloned().zip(orders.clone()).collect();
        let fresh =
            ContinuousCoordinator::sectored(c.task.clone(), &c.holds, &sectors, n, c.tick_s)
                .unwrap()
                .with_switch_s(c.switch_s)
                .unwrap();
        let own_fresh: Vec<ContinuousCoordinator> = (0..m)
            .map(|o| {
                ContinuousCoordinator::new(
                    c.task.clone(),
                    &c.holds,
                    &orders[o],
                    c.members[o].len(),
                    c.tick_s,
                )
                .unwrap()
                .with_switch_s(c.switch_s)
                .unwrap()
            })
            .collect();
        let mut taken = vec![false; m];
        for _ in 0..20_000 {
            for o in 0..m {
                if taken[o] {
                    continue;
                }
                let others_lc = c.cell.low_conf_now();
                let busy_elsewhere =
                    (0..m).any(|q| q != o && c.members[q].iter().any(|&r| others_lc[r]));
                let ok = c.cell.take_over_sector(&fresh, o).is_ok();
                let mut own = own_fresh[o].clone();
                assert_eq!(
                    own.take_over(&c.own[o]).is_ok(),
                    ok,
                    "seed {seed}: sector {o} hands over where its own cell does"
                );
                if ok {
                    c.own[o] = own;
                    taken[o] = true;
                    mid_stretch += usize::from(busy_elsewhere);
                }
            }
            if taken.iter().all(|&t| t) {
                all += 1;
                break;
            }
            tick_alike(&mut c, Policy::RandomExtreme, 1, &mut rng);
        }
        tick_alike(&mut c, Policy::Mixed, 1500, &mut rng);
    }
    eprintln!("every sector handed over in {all} of 8 cases, {mid_stretch} hand-overs mid-stretch");
    assert_eq!(all, 8, "every sector handed over in {all} of 8 cases");
    // Not vacuous: sectors took their plans while another sector's robot was low-confidence.
    assert!(
        mid_stretch >= 4,
        "{mid_stretch} hand-overs mid-stretch elsewhere"
    );
    // Refused by name: a pooled cell, other sectors, a sector without robots.
    let c = case(1, 4, 2, false);
    let pooled = ContinuousCoordinator::new(c.task.clone(), &c.holds, &[], 4, c.tick_s);
    if let Ok(p) = pooled {
        assert!(matches!(
            c.cell.clone().take_over_sector(&p, 0),
            Err(Error::HandOver { .. })
        ));
    }
    let other = case(1, 4, 4, false).cell;
    assert!(matches!(
        c.cell.clone().take_over_sector(&other, 0),
        Err(Error::HandOver { .. })
    ));
    assert!(matches!(
        c.cell.clone().take_over_sector(&c.cell, 2),
        Err(Error::HandOver { .. })
    ));
}

/// Runs a random sectored cell until every robot has done 20 tasks under `policy`, checking
/// the invariant at every tick: at most `M` robots low-confidence, at most one per sector and
/// under its sector's operator, no fault, each operator's stretches of different robots more
/// than `k` ticks apart, no deadlock within a generous bound.
fn sectors_sound(
    seed: u64,
    n: usize,
    m: usize,
    policy: Policy,
    switch: bool,
    replan: bool,
) -> Result<(), TestCaseError> {
    let mut c = case(seed, n, m, switch);
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5ec7);
    let k = c.cell.switch_ticks();
    prop_assert_eq!(Controller::operators(&c.cell), m);
    let mut sector = vec![0usize; n];
    for (o, r) in c.members.iter().enumerate() {
        for &i in r {
            sector[i] = o;
        }
    }
    let slow_s: f64 = (0..c.task.n_ref())
        .map(|q| {
            if c.task.conf()[q] {
                c.task.grad_exec()[q]
            } else {
                c.task.grad_max()[q]
            }
        })
        .sum::<f64>()
        * c.task.dt_s();
    let per_task = (slow_s + c.switch_s) / c.tick_s + (c.task.n_ref() + 40) as f64;
    let bound = (25.0 * n as f64 * per_task) as u64 + 1000;
    let mut last_lc: Vec<Option<(usize, u64)>> = vec![None; m];
    let mut ticks = 0_u64;
    // With `replan`, a new plan (new random orders) every 150 ticks, taken sector by sector
    // (`take_over_sector`), each sector when its own robots are at a hand-over point.
    let gs = groups(c.task.conf(), &c.holds).unwrap();
    let mut pending: Option<(ContinuousCoordinator, Vec<bool>)> = None;
    let mut sector_hand_overs = 0_u64;
    while c.cell.tasks_completed().iter().any(|&t| t < 20) {
        prop_assert!(ticks < bound, "deadlock? {:?}", c.cell.tasks_completed());
        if replan && ticks % 150 == 50 {
            let sectors: Vec<SectorOrder> = c
                .members
                .iter()
                .map(|r| (r.clone(), random_order(&gs, r.len(), &mut rng)))
                .collect();
            let next =
                ContinuousCoordinator::sectored(c.task.clone(), &c.holds, &sectors, n, c.tick_s)
                    .unwrap()
                    .with_switch_s(c.switch_s)
                    .unwrap();
            pending = Some((next, vec![false; m]));
        }
        if let Some((next, taken)) = &mut pending {
            for (o, t) in taken.iter_mut().enumerate() {
                if !*t && c.cell.take_over_sector(next, o).is_ok() {
                    *t = true;
                    sector_hand_overs += 1;
                }
            }
            if taken.iter().all(|&t| t) {
                pending = None;
            }
        }
        let inputs: Vec<Operator> = (0..m).map(|o| input(policy, o, ticks, &mut rng)).collect();
        let t = c.cell.tick_many(&inputs).unwrap();
        prop_assert!(!t.over(m) && t.fault.is_none(), "tick {ticks}: {t:?}");
        let mut seen = vec![false; m];
        for (i, &home) in sector.iter().enumerate() {
            if !t.low_conf[i] {
                continue;
            }
            let o = usize::from(t.operator[i].expect("an operator"));
            prop_assert_eq!(
                o,
                home,
                "tick {}: robot {} under another sector's",
                ticks,
                i
            );
            prop_assert!(!seen[o], "tick {ticks}: two robots of sector {o}");
            seen[o] = true;
            if let Some((r, at)) = last_lc[o] {
                prop_assert!(r == i || ticks - at > k, "tick {ticks}: switch of {o}");
            }
            last_lc[o] = Some((i, ticks));
        }
        ticks += 1;
    }
    prop_assert!(
        !replan || ticks < 1000 || sector_hand_overs > 0,
        "no sector took a new plan in {} ticks",
        ticks
    );
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 48,
        rng_seed: RngSeed::Fixed(44),
        ..ProptestConfig::default()
    })]

    #[test]
    fn sectors_keep_at_most_m_low_confidence_under_every_operator(
        seed in any::<u64>(),
        (n, m) in prop_oneof![
            Just((4_usize, 2_usize)),
            Just((8, 2)),
            Just((8, 4)),
            Just((16, 4)),
        ],
        policy in prop_oneof![
            Just(Policy::Rush),
            Just(Policy::Drag),
            Just(Policy::RandomExtreme),
            Just(Policy::RandomGradient),
            Just(Policy::Mixed),
        ],
        switch in any::<bool>(),
        replan in any::<bool>(),
    ) {
        sectors_sound(seed, n, m, policy, switch, replan)?;
    }
}

#[test]
fn bad_sectors_are_refused_by_name() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let (task, holds) = random_cell_task(&mut rng, 30, CellHolds::Uniform);
    let gs = groups(task.conf(), &holds).unwrap();
    let order = random_order(&gs, 2, &mut rng);
    let refused = |sectors: Vec<SectorOrder>, n| {
        matches!(
            ContinuousCoordinator::sectored(task.clone(), &holds, &sectors, n, 0.05),
            Err(Error::BadParam {
                name: "sectors",
                ..
            })
        )
    };
    // Robot 3 twice, robot 2 missing; a robot out of range; descending; empty; none.
    assert!(refused(
        vec![(vec![0, 1], order.clone()), (vec![3, 3], order.clone())],
        4
    ));
    assert!(refused(
        vec![(vec![0, 1], order.clone()), (vec![2, 4], order.clone())],
        4
    ));
    assert!(refused(
        vec![(vec![1, 0], order.clone()), (vec![2, 3], order.clone())],
        4
    ));
    assert!(refused(
        vec![(vec![], vec![]), (vec![0, 1], order.clone())],
        2
    ));
    assert!(refused(vec![], 2));
    // With more operators than sectors, the extra operators have no robots; never fewer.
    let c = ContinuousCoordinator::sectored(task.clone(), &holds, &[(vec![0, 1], order)], 2, 0.05)
        .unwrap();
    assert_eq!(c.operators(), 1);
    let c = c.with_operators(OperatorCount::new(3).unwrap());
    assert_eq!(c.operators(), 3);
    assert_eq!(c.sector_of().unwrap(), [0, 0]);
    assert!(c.with_max_busy_share(0.9).is_err());
}
