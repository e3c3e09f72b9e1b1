//! A simulated cell in real time (`tandem console STATE --simulate`): the planner's controller
//! for the chosen kind of cell with tandem-sim's simulated operator
//! ([`RoundSim`] / [`CellSim`]), ticked every `tick_s / speed` real seconds, publishing every
//! tick through the same [`ConsoleHandle`] a user's loop uses and taking the operator's
//! controls at tick boundaries ([`Driver`]). Rounds run one after the other.

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

    /// Whether the simulated operator's input in the last [`step`](Self::step) was a
    /// correction.
    pub(crate) fn corrected(&self) -> bool {
        match &self.cell {
            SimCell::Rounds(s) => s.corrected(),
            SimCell::Continuous(s) => s.corrected(),
        }
    }

    /// One tick (a finished round restarts first); returns the tick and whether a round
    /// was completed before it.
    pub(crate) fn step(&mut self) -> Result<(Tick, bool)> {
        let model = self.planner.model();
        let needed = &self.needed;
        match &mut self.cell {
            SimCell::Rounds(s) => {
                let mut new_round = false;
                if s.coordinator().is_finished() {
                    s.restart();
                    self.rounds_done += 1;
                    new_round = true;
                }
                Ok((
                    s.tick(model, |i, k| needed[i][k], &mut self.rng)?,
                    new_round,
                ))
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
