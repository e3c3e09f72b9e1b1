//! The adversary driver of `M ≥ 1` operators (issue 44): every operator runs its own copy of
//! one [`Adversary`] policy on the robot it supervises, and every tick is checked against the
//! `M`-operator invariant (docs/decisions.md, "M operators: the invariant and the continuous
//! cell (issue 44)"): at most `M` robots low-confidence, each low-confidence robot with an
//! operator, no operator on two robots in one tick, and no stretch handed over mid-way.
//!
//! With one operator it drives the same policy as [`run_adversary_on`](super::run_adversary_on)
//! (the robot the operator supervises is the low-confidence one) and checks more: it is the
//! stress driver of `cargo xtask stress --operators M`.

use rand::Rng;

use super::{Adversary, Backward, PolicyState};
use crate::{Controller, MAX_ROBOTS, Operator, Result};

/// What one execution of `M` operators did ([`run_operators_on`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OperatorsRun {
    /// Control ticks run.
    pub ticks: u64,
    /// Ticks with more than `M` robots low-confidence ([`Tick::over`](crate::Tick::over);
    /// 0 for a sound controller).
    pub over_ticks: u64,
    /// The most robots low-confidence in one tick (at most `M`; `M` shows that the run used
    /// every operator).
    pub most_low_conf: usize,
    /// Ticks in which a robot low-confidence in this tick and the one before, in the same
    /// task ([`Controller::tasks_now`] at both tick starts), had another operator than in the
    /// one before: a stretch handed over mid-way (0 for a sound controller). A stretch is
    /// the robot's consecutive low-confidence ticks within one task.
    pub handed_over: u64,
    /// Ticks in which a robot low-confidence in this tick and the one before had another
    /// operator, the two ticks in two tasks: its task's last stretch ran into the next task's
    /// first one (a task that ends and starts on low confidence), and the cell granted the
    /// next task's stretch on its own. Two stretches, no hand-over (not a fault; counted to
    /// show how often it happens).
    pub changed_at_task_end: u64,
    /// The first of [`handed_over`](Self::handed_over): `(tick, robot)`, the tick's index
    /// (ticks since the start) and the robot, to replay it (run again with `max_ticks` = the
    /// tick to see the state before it).
    pub first_handed_over: Option<(u64, usize)>,
    /// Ticks in which one operator was reported on two or more low-confidence robots, or a
    /// low-confidence robot had no operator or one outside `0..M` (0 for a sound controller).
    pub misassigned: u64,
    /// Faults the controller latched (each cleared at once so that the run goes on).
    pub faults: u64,
    /// Ticks in which some robot moved backwards ([`Backward`]).
    pub backward_steps: u64,
    /// Whether the run reached its goal within the tick budget.
    pub finished: bool,
    /// The fewest tasks any robot completed at the end ([`Controller::tasks_now`]).
    pub min_tasks: u64,
    /// The shortest switch of any operator: the fewest ticks between a tick in which it
    /// supervised one robot low-confidence and a later tick in which it supervised another,
    /// in which it supervised no low-confidence robot (`None`: no operator changed robot). A
    /// controller with switch time `δ` keeps it `≥ switch_ticks(δ, tick_s)`.
    pub min_switch_gap_ticks: Option<u64>,
}

/// Runs `controller` (its [`Controller::operators`] = `M` operators) until it has finished or
/// every robot has completed `min_tasks` tasks, or for at most `max_ticks` ticks. Operator `o`
/// gives the inputs of its own copy of the policy `adversary`, seeing the robot it supervises
/// at the tick start ([`Controller::operator_now`]) as the low-confidence one; the `M` inputs
/// go to [`Controller::tick_many`]. [`Adversary::Beam`] searches one operator's sequence and
/// runs here as [`Adversary::SwitchFavourite`] with holds up to 50 ticks (per operator). A
/// fault is counted and cleared. Allocates nothing; `O(N + M)` per tick.
///
/// # Errors
/// [`crate::Error::BadOperator`] when the adversary produces an inadmissible gradient; those of
/// [`Controller::tick_many`].
pub fn run_operators_on<C: Controller + ?Sized>(
    controller: &mut C,
    adversary: Adversary,
    rng: &mut impl Rng,
    min_tasks: u64,
    max_ticks: u64,
) -> Result<OperatorsRun> {
    let (n, m) = (
        controller.n_robots(),
        controller.operators().min(MAX_ROBOTS),
    );
    let mut run = OperatorsRun::default();
    let policy = match adversary {
        Adversary::Beam { .. } => Adversary::SwitchFavourite { max_hold: 50 },
        other => other,
    };
    let mut states: [PolicyState; MAX_ROBOTS] = std::array::from_fn(|_| PolicyState::new(n));
    let mut inputs = [Operator::Scheduled; MAX_ROBOTS];
    // Per robot: its operator in the previous tick and its task count at that tick's start,
    // if it was low-confidence then.
    let mut prev = [None::<(u8, u64)>; MAX_ROBOTS];
    // Per operator: the robot and tick of its last low-confidence tick.
    let mut last = [None::<(usize, u64)>; MAX_ROBOTS];
    let mut backward = Backward::new(controller);
    let fewest = |c: &C| c.tasks_now().iter().copied().min().unwrap_or(0);
    while !(controller.is_finished() || fewest(controller) >= min_tasks) {
        if run.ticks >= max_ticks {
            run.min_tasks = fewest(controller);
            return Ok(run);
        }
        let now = controller.operator_now();
        let tasks = controller.tasks_now();
        for (o, (input, state)) in inputs.iter_mut().zip(&mut states).take(m).enumerate() {
            let robot = now.iter().position(|&x| x == Some(o as u8));
            *input = state.next(policy, run.ticks, robot, rng);
        }
        let tick = controller.tick_many(&inputs[..m])?;
        run.backward_steps += u64::from(backward.step(controller, &tick));
        run.over_ticks += u64::from(tick.over(m));
        run.most_low_conf = run.most_low_conf.max(tick.low_conf.count());
        let mut busy = [false; MAX_ROBOTS];
        let mut wrong = false;
        for (i, prev_i) in prev.iter_mut().enumerate().take(n) {
            if !tick.low_conf[i] {
                *prev_i = None;
                continue;
            }
            let Some(o) = tick.operator[i].filter(|&o| usize::from(o) < m) else {
                wrong = true;
                *prev_i = None;
                continue;
            };
            let ou = usize::from(o);
            wrong |= busy[ou];
            busy[ou] = true;
            match *prev_i {
                Some((p, task)) if p != o && task == tasks[i] => {
                    run.handed_over += 1;
                    run.first_handed_over.get_or_insert((run.ticks, i));
                }
                Some((p, _)) if p != o => run.changed_at_task_end += 1,
                _ => {}
            }
            *prev_i = Some((o, tasks[i]));
            // An operator on two robots in this tick is `misassigned`, not a switch.
            if let Some((j, at)) = last[ou]
                && j != i
                && at < run.ticks
            {
                let gap = run.ticks - at - 1;
                run.min_switch_gap_ticks =
                    Some(run.min_switch_gap_ticks.map_or(gap, |g| g.min(gap)));
            }
            last[ou] = Some((i, run.ticks));
        }
        run.misassigned += u64::from(wrong);
        if tick.fault.is_some() {
            run.faults += 1;
            controller.clear_fault();
        }
        run.ticks += 1;
    }
    run.min_tasks = fewest(controller);
    run.finished = true;
    Ok(run)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{OperatorCount, Timeline};
    use rand::SeedableRng;

    /// Three robots of [HC, HC, LC, LC, HC × 6], gradient 1 and bounds [1, 1] (they always
    /// run on schedule), one sample a second, started together, ticked at 1 s: their
    /// stretches coincide whatever the inputs.
    fn three_together() -> Vec<Timeline> {
        let conf: Vec<bool> = (0..10).map(|k| !(2..4).contains(&k)).collect();
        let one = vec![1.0; 10];
        (0..3)
            .map(|_| Timeline::new(&conf, &one, &one, &one, 0.0, 1.0).unwrap())
            .collect()
    }

    #[test]
    fn three_operators_on_three_coinciding_stretches_count_nothing_wrong() {
        let c = crate::Coordinator::new_unchecked(three_together(), 1.0).unwrap();
        let mut c = c.with_operators(OperatorCount::new(3).unwrap()).unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let r = run_operators_on(&mut c, Adversary::RandomExtreme, &mut rng, 1, 100).unwrap();
        assert_eq!((r.most_low_conf, r.over_ticks, r.handed_over), (3, 0, 0));
        assert_eq!((r.misassigned, r.faults, r.finished), (0, 0, true));
        assert_eq!(r.min_switch_gap_ticks, None);
    }

    /// The case the stress found (issue 44, docs/decisions.md "Up to 16 robots: what limits
    /// N"): a task that ends and starts on low confidence, [LC, LC, HC × 4, LC, LC] with a
    /// hold at 3 (two groups, the first gated at the task start), one sample a second,
    /// gradient 1 in [0.5, 2], ticked at 0.5 s, four robots and two operators. A robot that
    /// finishes its task on its last stretch is at once on the next task's first, which the
    /// cell grants on its own: when another robot's entry comes first, the robot's operator
    /// goes to it and the robot gets the other one. Two stretches, so `handed_over` stays 0
    /// and `changed_at_task_end` counts it (some policy shows it: the test is not vacuous).
    #[test]
    fn a_new_operator_at_the_task_end_is_two_stretches_not_a_hand_over() {
        let conf = [false, false, true, true, true, true, false, false];
        let task = Timeline::new(&conf, &[1.0; 8], &[0.5; 8], &[2.0; 8], 0.0, 1.0).unwrap();
        let order: Vec<(usize, usize)> =
            (0..2).flat_map(|lc| (0..4).map(move |r| (r, lc))).collect();
        let cell = crate::ContinuousCoordinator::new(task, &[3], &order, 4, 0.5)
            .unwrap()
            .with_operators(OperatorCount::new(2).unwrap());
        let mut changed = 0;
        for (k, adversary) in [
            Adversary::Nominal,
            Adversary::RandomExtreme,
            Adversary::RushRobot { rush: 1 },
            Adversary::SwitchFavourite { max_hold: 5 },
        ]
        .into_iter()
        .enumerate()
        {
            let mut c = cell.clone();
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(k as u64);
            let r = run_operators_on(&mut c, adversary, &mut rng, 20, 100_000).unwrap();
            assert!(r.finished && r.most_low_conf == 2, "{adversary:?}: {r:?}");
            assert_eq!(
                (r.over_ticks, r.handed_over, r.misassigned, r.faults),
                (0, 0, 0, 0),
                "{adversary:?}: {r:?}"
            );
            changed += r.changed_at_task_end;
        }
        assert!(changed > 0);
    }

    /// A round of 16 robots and 4 operators (`MAX_ROBOTS`): four waves of four robots of
    /// [HC, HC, LC, LC, HC × 6], gradient 1 in [0.5, 2], the waves 30 s apart, ticked at
    /// 0.25 s. `Coordinator::with_operators(4)` accepts it
    /// (`margins::operators::tests::four_waves_of_four_robots_need_four_operators`: it was
    /// refused before the lower envelope left out finished robots), and under every policy
    /// per operator no tick has more than 4 robots low-confidence, no stretch is handed over,
    /// no operator is on two robots, no fault; some tick has all 4 operators busy.
    #[test]
    fn sixteen_robots_in_four_waves_run_with_four_operators() {
        let conf: Vec<bool> = (0..10).map(|k| !(2..4).contains(&k)).collect();
        let robots: Vec<Timeline> = (0..16)
            .map(|i| {
                let start = 30.0 * (i / 4) as f64;
                Timeline::new(&conf, &[1.0; 10], &[0.5; 10], &[2.0; 10], start, 1.0).unwrap()
            })
            .collect();
        let c = crate::Coordinator::new_unchecked(robots, 0.25)
            .unwrap()
            .with_operators(OperatorCount::new(4).unwrap())
            .unwrap();
        assert_eq!(c.operators(), 4);
        for (k, adversary) in [
            Adversary::Nominal,
            Adversary::RandomExtreme,
            Adversary::RushRobot { rush: 1 },
            Adversary::SwitchFavourite { max_hold: 5 },
        ]
        .into_iter()
        .enumerate()
        {
            let mut c = c.clone();
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(k as u64);
            let r = run_operators_on(&mut c, adversary, &mut rng, 1, 100_000).unwrap();
            assert!(r.finished && r.most_low_conf == 4, "{adversary:?}: {r:?}");
            assert_eq!(
                (r.over_ticks, r.handed_over, r.misassigned, r.faults),
                (0, 0, 0, 0),
                "{adversary:?}: {r:?}"
            );
        }
    }

    #[test]
    fn one_operator_on_coinciding_stretches_counts_the_ticks_over() {
        // Unchecked, one operator: the three stretches coincide; the monitor latches a fault
        // (cleared), and every low-confidence robot reports operator 0 (misassigned).
        let mut c = crate::Coordinator::new_unchecked(three_together(), 1.0).unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let r = run_operators_on(&mut c, Adversary::Nominal, &mut rng, 1, 100).unwrap();
        assert_eq!(r.most_low_conf, 3);
        assert!(
            r.over_ticks >= 1 && r.faults >= 1 && r.misassigned >= 1,
            "{r:?}"
        );
    }
}
