//! A simulated cell in real time (`tandem console STATE --simulate`): the planner's controller
//! for the chosen kind of cell with tandem-sim's simulated operator
//! ([`RoundSim`] / [`CellSim`]), ticked every `tick_s / speed` real seconds, publishing every
//! tick through the same [`ConsoleHandle`] a user's loop uses and taking the operator's
//! controls at tick boundaries ([`Driver`]). Rounds run one after the other; under the
//! operator's load cap (`max_busy_share` of the state file, issue 41) the next round starts
//! only after the rest the finished round asks (`Coordinator::rest_ticks`): that many idle
//! ticks between the round's last tick and the next round's first, as the ROS 2 node keeps
//! it, the page's notice saying `rest: N s before the next round` meanwhile ([`rest_notice`]).

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tandem_planner::{AnyController, Cell, Planner};
use tandem_realtime::{Controller, Tick};
use tandem_sim::workcell::{CellSim, OperatorParams, RoundSim};

use crate::error::{Error, Result};
use crate::handle::{ConsoleCell, ConsoleHandle, Driver};
use crate::replay::Recorder;

/// How the simulated cell runs.
#[derive(Clone, Debug)]
pub struct SimParams {
    /// Rounds or a continuous cell. Default: rounds.
    pub cell: Cell,
    /// Real-time factor: 1 runs the cell at the robots' speed, 2 twice as fast. In
    /// (0, 1000]. Default: 1.
    pub speed: f64,
    /// Seed of the simulated operator. Default: 0.
    pub seed: u64,
    /// The simulated operator (the study's). Default: `OperatorParams::default()`.
    pub operator: OperatorParams,
}

impl Default for SimParams {
    fn default() -> Self {
        SimParams {
            cell: Cell::Rounds,
            speed: 1.0,
            seed: 0,
            operator: OperatorParams::default(),
        }
    }
}

impl SimParams {
    /// Checks `speed` (finite, in (0, 1000]) and the operator.
    ///
    /// # Errors
    /// [`Error::BadParam`] naming `speed`; the operator's own errors.
    pub fn validate(&self) -> Result<()> {
        if !(self.speed > 0.0 && self.speed <= 1000.0) {
            return Err(Error::BadParam {
                name: "speed",
                why: "must be in (0, 1000]",
            });
        }
        self.operator.validate()?;
        Ok(())
    }
}

/// The simulated cell of either kind, behind [`ConsoleCell`].
#[derive(Debug)]
enum SimCell {
    Rounds(Box<RoundSim>),
    Continuous(Box<CellSim>),
}

impl ConsoleCell for SimCell {
    fn controller(&self) -> &dyn Controller {
        match self {
            SimCell::Rounds(s) => s.coordinator(),
            SimCell::Continuous(s) => s.coordinator(),
        }
    }
    fn clear_fault(&mut self) {
        match self {
            SimCell::Rounds(s) => s.clear_fault(),
            SimCell::Continuous(s) => s.clear_fault(),
        }
    }
}

/// The [`Tick`] that describes `ctl` now (its `*_now` readers; `low_conf` is the robots
/// supervised now): for a loop whose tick function returns something else.
#[must_use]
pub fn tick_now<C: Controller + ?Sized>(ctl: &C) -> Tick {
    Tick {
        ref_time: ctl.ref_time_now(),
        tasks: ctl.tasks_now(),
        low_conf: ctl.low_conf_now(),
        operator: ctl.operator_now(),
        running: ctl.running_now(),
        waiting: ctl.waiting_now(),
        fault: ctl.fault(),
        next: ctl.pre_alert(),
    }
}

/// A simulated cell stepped one tick at a time: what [`simulate`] runs in real time and
/// [`record_sim`] as fast as it can.
#[derive(Debug)]
pub(crate) struct SimRun<'p> {
    planner: &'p Planner,
    cell: SimCell,
    needed: Vec<Vec<bool>>,
    rng: ChaCha8Rng,
    rounds_done: u64,
    /// Idle ticks of the operator's rest still to run before the next round's first tick
    /// (rounds under a load cap; set when a round finishes).
    rest_left: u64,
    /// Whether the last [`step`](Self::step) was a tick of the rest.
    resting: bool,
}

impl<'p> SimRun<'p> {
    pub(crate) fn new(
        planner: &'p Planner,
        ctl: AnyController,
        params: &SimParams,
        needed: Option<Vec<Vec<bool>>>,
    ) -> Result<SimRun<'p>> {
        params.validate()?;
        let model = planner.model();
        let n_ref = model.n_ref();
        let n = ctl.n_robots();
        let needed = match needed {
            Some(t) => {
                if t.len() != n || t.iter().any(|r| r.len() != n_ref) {
                    return Err(Error::BadParam {
                        name: "needed",
                        why: "must hold one row of T_ref samples per robot",
                    });
                }
                t
            }
            None => {
                let lc: Vec<bool> = planner.problem().conf().iter().map(|c| !c).collect();
                vec![lc; n]
            }
        };
        let cell = match ctl {
            AnyController::Rounds(c) => SimCell::Rounds(Box::new(RoundSim::new(
                model,
                planner.problem(),
                c,
                &params.operator,
            )?)),
            AnyController::Continuous(c) => {
                SimCell::Continuous(Box::new(CellSim::new(model, c, &params.operator)?))
            }
        };
        Ok(SimRun {
            planner,
            cell,
            needed,
            rng: ChaCha8Rng::seed_from_u64(params.seed),
            rounds_done: 0,
            rest_left: 0,
            resting: false,
        })
    }

    pub(crate) fn controller(&self) -> &dyn Controller {
        self.cell.controller()
    }

    pub(crate) fn is_rounds(&self) -> bool {
        matches!(self.cell, SimCell::Rounds(_))
    }

    pub(crate) fn rounds_done(&self) -> u64 {
        self.rounds_done
    }

    /// Ticks of the operator's rest still to run before the next round's first tick (0 while
    /// a round runs, without a load cap, and in a continuous cell).
    pub(crate) fn rest_left_ticks(&self) -> u64 {
        self.rest_left
    }

    /// Whether the simulated operator's input in the last [`step`](Self::step) was a
    /// correction.
    pub(crate) fn corrected(&self) -> bool {
        if self.resting {
            return false;
        }
        match &self.cell {
            SimCell::Rounds(s) => s.corrected(),
            SimCell::Continuous(s) => s.corrected(),
        }
    }

    /// One tick; returns the tick and whether a round was completed before it. After a
    /// finished round, first the rest it asks
    /// ([`Coordinator::rest_ticks`](tandem_realtime::Coordinator::rest_ticks), read at its
    /// last tick): that many idle ticks, in which nothing moves (the tick describes the
    /// finished round, no correction); then the round restarts.
    pub(crate) fn step(&mut self) -> Result<(Tick, bool)> {
        let model = self.planner.model();
        let needed = &self.needed;
        self.resting = false;
        match &mut self.cell {
            SimCell::Rounds(s) => {
                let mut new_round = false;
                if s.coordinator().is_finished() {
                    if self.rest_left > 0 {
                        self.rest_left -= 1;
                        self.resting = true;
                        return Ok((tick_now(s.coordinator()), false));
                    }
                    s.restart();
                    self.rounds_done += 1;
                    new_round = true;
                }
                let tick = s.tick(model, |i, k| needed[i][k], &mut self.rng)?;
                if s.coordinator().is_finished() {
                    self.rest_left = s.coordinator().rest_ticks();
                }
                Ok((tick, new_round))
            }
            SimCell::Continuous(s) => {
                s.tick(model, |i, k| needed[i][k], &mut self.rng)?;
                Ok((tick_now(s.coordinator()), false))
            }
        }
    }
}

/// Runs the simulated cell of `planner` (its controller `ctl` for `params.cell`, as
/// [`Planner::controller`] makes it) in real time until `stop` is set, publishing into
/// `handle`. `needed[i][n]`: robot `i` needs the operator at reference sample `n` (`None`:
/// every low-confidence sample of the plan needs the operator).
///
/// # Errors
/// Bad parameters, a needs table that is not one row of `T_ref` per robot, or the simulated
/// cell's errors.
pub fn simulate(
    planner: &Planner,
    ctl: AnyController,
    params: &SimParams,
    needed: Option<Vec<Vec<bool>>>,
    handle: ConsoleHandle,
    stop: &AtomicBool,
) -> Result<()> {
    simulate_recorded(planner, ctl, params, needed, handle, None, stop)
}

/// [`simulate`] writing every tick into `recorder` as well (`tandem console --simulate
/// --record FILE`; a recording [`crate::replay`] plays back).
///
/// # Errors
/// As [`simulate`], and the recorder's write errors.
pub fn simulate_recorded(
    planner: &Planner,
    ctl: AnyController,
    params: &SimParams,
    needed: Option<Vec<Vec<bool>>>,
    mut handle: ConsoleHandle,
    mut recorder: Option<&mut Recorder>,
    stop: &AtomicBool,
) -> Result<()> {
    let mut run = SimRun::new(planner, ctl, params, needed)?;
    let rounds = run.is_rounds();
    let tick_s = run.controller().tick_s();
    let period_s = tick_s / params.speed;
    let first = tick_now(run.controller());
    handle.publish_corrected(&first, run.controller(), false);
    if let Some(r) = recorder.as_deref_mut() {
        r.record(&first, run.controller(), rounds, run.rounds_done())?;
    }
    // The rest's notice shown (whole seconds left; `None`: no notice of ours).
    let mut shown_rest: Option<u64> = None;
    // Ticks are due at `base + k · period_s`; the base moves on every pause.
    let mut base = Instant::now();
    let mut done_since_base: u64 = 0;
    let mut was_paused = false;
    while !stop.load(Ordering::Relaxed) {
        let due = (base.elapsed().as_secs_f64() / period_s) as u64;
        // At most half a second of ticks at once: a slow machine lags, it does not race.
        let mut budget = ((0.5 / period_s) as u64).max(1);
        loop {
            if !Driver::apply(&mut handle, &mut run.cell) {
                let t = tick_now(run.controller());
                handle.publish_corrected(&t, run.controller(), false);
                was_paused = true;
                break;
            }
            if was_paused {
                // Resumed: a frame saying so now, not at the next tick (which may be a long
                // period away at a low speed).
                was_paused = false;
                base = Instant::now();
                done_since_base = 0;
                let t = tick_now(run.controller());
                handle.publish_corrected(&t, run.controller(), false);
                break;
            }
            if done_since_base >= due || budget == 0 {
                break;
            }
            let (tick, new_round) = run.step()?;
            if new_round {
                handle.round_done();
            }
            let rest = rest_left_s(run.rest_left_ticks(), tick_s);
            // A full queue of updates: given again at the next tick.
            if rest != shown_rest && handle.set_notice(rest.map(rest_notice)) {
                shown_rest = rest;
            }
            handle.publish_corrected(&tick, run.controller(), run.corrected());
            if let Some(r) = recorder.as_deref_mut() {
                r.record(&tick, run.controller(), rounds, run.rounds_done())?;
            }
            done_since_base += 1;
            budget -= 1;
        }
        if due > done_since_base + ((0.5 / period_s) as u64).max(1) {
            // Behind by more than half a second: start the clock again rather than race.
            base = Instant::now();
            done_since_base = 0;
        }
        std::thread::sleep(Duration::from_secs_f64(period_s.clamp(0.001, 0.02)));
    }
    if let Some(r) = recorder {
        r.flush()?;
    }
    Ok(())
}

/// The rest left in whole seconds, rounded up (never less than is left), of `ticks` ticks of
/// `tick_s`; `None` without a rest.
fn rest_left_s(ticks: u64, tick_s: f64) -> Option<u64> {
    (ticks > 0).then(|| (ticks as f64 * tick_s).ceil() as u64)
}

/// The page's notice while the simulated operator rests after a round under the load cap
/// (issue 41): `rest: N s before the next round (the operator's load cap)`, `N` whole seconds
/// rounded up, as the ROS 2 node's notice (`tandem_ros2::rest_notice`) begins; the simulated
/// cell then starts the next round by itself.
#[must_use]
pub fn rest_notice(left_s: u64) -> String {
    format!(
        "rest: {left_s} s before the next round (the operator's load cap) — the simulated cell \
         starts it when the rest has passed"
    )
}

/// When [`record_sim`] stops.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Until {
    /// After this many ticks.
    Ticks(u64),
    /// When this many rounds are complete (rounds cells).
    Rounds(u64),
    /// When the robots completed this many tasks together (continuous cells).
    Tasks(u64),
}

/// Runs the simulated cell as fast as it can (not in real time, no server) until `until`,
/// writing every tick into `recorder`; returns the ticks run. The recording of a run of
/// `tandem console --simulate` without waiting for it.
///
/// # Errors
/// As [`simulate`], the recorder's write errors, and [`Error::BadParam`] for an `until` the
/// cell cannot reach (rounds of a continuous cell, tasks of rounds) or of more than
/// 10⁸ ticks.
pub fn record_sim(
    planner: &Planner,
    ctl: AnyController,
    params: &SimParams,
    needed: Option<Vec<Vec<bool>>>,
    until: Until,
    recorder: &mut Recorder,
) -> Result<u64> {
    const MAX_TICKS: u64 = 100_000_000;
    let mut run = SimRun::new(planner, ctl, params, needed)?;
    let rounds = run.is_rounds();
    match (until, rounds) {
        (Until::Rounds(_), false) => {
            return Err(Error::BadParam {
                name: "until",
                why: "counts rounds, and a continuous cell has none: use tasks",
            });
        }
        (Until::Tasks(_), true) => {
            return Err(Error::BadParam {
                name: "until",
                why: "counts tasks, and a rounds cell counts rounds: use rounds",
            });
        }
        _ => {}
    }
    recorder.record(&tick_now(run.controller()), run.controller(), rounds, 0)?;
    let mut ticks = 0u64;
    loop {
        let done = match until {
            Until::Ticks(k) => ticks >= k,
            Until::Rounds(k) => run.rounds_done() + u64::from(run.controller().is_finished()) >= k,
            Until::Tasks(k) => {
                run.controller()
                    .tasks_now()
                    .iter()
                    .take(run.controller().n_robots())
                    .sum::<u64>()
                    >= k
            }
        };
        if done {
            break;
        }
        if ticks >= MAX_TICKS {
            return Err(Error::BadParam {
                name: "until",
                why: "not reached within 10^8 ticks",
            });
        }
        let (tick, _) = run.step()?;
        recorder.record(&tick, run.controller(), rounds, run.rounds_done())?;
        ticks += 1;
    }
    recorder.flush()?;
    Ok(ticks)
}

#[cfg(test)]
mod tests {
    use tandem_lfd::{Demonstration, FitParams, TaskModel};
    use tandem_planner::PlannerParams;

    use super::*;

    /// The hand-made one-channel task of the node's tests (low confidence where the
    /// demonstrations differ, reference samples 10..20 of 60 at 10 ms), planned for two robots,
    /// with the operator's load cap `u`.
    fn planner(u: f64) -> Planner {
        let names = vec!["force".to_string()];
        let light = Demonstration::new(names.clone(), vec![1.0; 60], 0.01).unwrap();
        let (mut hard, mut warp) = (Vec::new(), Vec::new());
        for n in 0..60 {
            warp.push(hard.len() as f64);
            let reps = if (10..20).contains(&n) { 2 } else { 1 };
            for _ in 0..reps {
                hard.push(if (10..20).contains(&n) { 9.0 } else { 1.0 });
            }
        }
        let hard = Demonstration::new(names, hard, 0.01).unwrap();
        let identity: Vec<f64> = (0..60).map(f64::from).collect();
        let model = TaskModel::fit_aligned(
            &[light.clone(), hard, light],
            &[identity.clone(), warp, identity],
            &FitParams::default(),
        )
        .unwrap();
        let mut params = PlannerParams::default();
        params.sampler.samples = 50;
        params.sampler.seed = 3;
        let mut planner = Planner::from_model_with_robots(model, params, 2).unwrap();
        planner.set_operator(0.0, u).unwrap();
        planner
    }

    /// The rest by hand: the least whole `n` with `busy ≤ u·n` (floating point, from below
    /// the quotient), less the round's ticks.
    fn rest_by_hand(busy: u64, ticks: u64, u: f64) -> u64 {
        let mut n = ((busy as f64 / u).floor() as u64).saturating_sub(2);
        while (n as f64) * u < busy as f64 {
            n += 1;
        }
        n.saturating_sub(ticks)
    }

    /// Runs the current round of `run` to its end; returns (its ticks, its busy ticks: with a
    /// robot low-confidence, one operator, no switch time) and whether its first step started
    /// a new round.
    fn run_round(run: &mut SimRun<'_>) -> (u64, u64, bool) {
        let (mut ticks, mut busy, mut started) = (0, 0, false);
        loop {
            let (tick, new_round) = run.step().unwrap();
            assert!(!run.resting);
            assert!(!new_round || ticks == 0, "a round starts at its first tick");
            started |= new_round;
            ticks += 1;
            busy += u64::from(tick.low_conf.first().is_some());
            if run.controller().is_finished() {
                return (ticks, busy, started);
            }
        }
    }

    /// Under a load cap of 0.1 the simulated cell starts the next round exactly the round's
    /// rest after its last tick (this test's own count of the busy ticks and its own least
    /// `n`): that many idle ticks in which nothing moves, no correction is counted and the
    /// rest left counts down; the next step restarts. Three rounds in a row, each with its own
    /// rest. Without a cap the next step restarts at once.
    #[test]
    fn a_simulated_round_after_a_capped_round_starts_exactly_its_rest_later() {
        let u = 0.1;
        let planner = planner(u);
        let ctl = planner.controller(Cell::Rounds).unwrap();
        let tick_s = ctl.tick_s();
        let mut run = SimRun::new(&planner, ctl, &SimParams::default(), None).unwrap();
        for round in 0..3 {
            let (ticks, busy, started) = run_round(&mut run);
            assert_eq!(started, round > 0);
            assert_eq!(run.rounds_done(), round);
            let rest = rest_by_hand(busy, ticks, u);
            assert!(rest > 0, "the cap binds: {busy} busy ticks of {ticks}");
            let SimCell::Rounds(s) = &run.cell else {
                panic!("a rounds cell")
            };
            assert_eq!(s.coordinator().rest_ticks(), rest);
            assert_eq!(run.rest_left_ticks(), rest);
            assert!(busy as f64 <= u * (ticks + rest) as f64);
            assert!(
                busy as f64 > u * (ticks + rest - 1) as f64,
                "the least rest"
            );
            let at_end = (run.controller().ticks(), run.controller().ref_time_now());
            for left in (0..rest).rev() {
                let (tick, new_round) = run.step().unwrap();
                assert!(!new_round && run.resting && !run.corrected());
                assert_eq!(run.rest_left_ticks(), left);
                assert_eq!((run.controller().ticks(), tick.ref_time), at_end);
                assert!(run.controller().is_finished());
            }
            assert_eq!(
                rest_left_s(rest, tick_s),
                Some((rest as f64 * tick_s).ceil() as u64)
            );
        }
        assert_eq!(rest_left_s(0, tick_s), None);
        // The next round's first tick: one step after the rest.
        let (_, new_round) = run.step().unwrap();
        assert!(new_round && !run.resting && run.rest_left_ticks() == 0);
        assert_eq!(run.rounds_done(), 3);

        let planner = planner_uncapped();
        let ctl = planner.controller(Cell::Rounds).unwrap();
        let mut run = SimRun::new(&planner, ctl, &SimParams::default(), None).unwrap();
        run_round(&mut run);
        assert_eq!(run.rest_left_ticks(), 0);
        let (_, new_round) = run.step().unwrap();
        assert!(new_round);
    }

    fn planner_uncapped() -> Planner {
        planner(1.0)
    }

    /// The notice begins as the node's does (`tandem_ros2::rest_notice`).
    #[test]
    fn the_rest_notice_says_the_seconds_left_as_the_node_does() {
        assert!(
            rest_notice(3)
                .starts_with("rest: 3 s before the next round (the operator's load cap) — ")
        );
        assert_eq!(rest_left_s(1, 0.01), Some(1));
        assert_eq!(rest_left_s(100, 0.01), Some(1));
        assert_eq!(rest_left_s(101, 0.01), Some(2));
    }
}
