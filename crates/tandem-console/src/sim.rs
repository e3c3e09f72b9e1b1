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
        running: ctl.running_now(),
        waiting: ctl.waiting_now(),
        fault: ctl.fault(),
        next: ctl.pre_alert(),
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
    mut handle: ConsoleHandle,
    stop: &AtomicBool,
) -> Result<()> {
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
    let mut cell = match ctl {
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
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    let tick_s = cell.controller().tick_s();
    let period_s = tick_s / params.speed;
    let first = tick_now(cell.controller());
    handle.publish(&first, cell.controller());
    // Ticks are due at `base + k · period_s`; the base moves on every pause.
    let mut base = Instant::now();
    let mut done_since_base: u64 = 0;
    let mut was_paused = false;
    while !stop.load(Ordering::Relaxed) {
        let due = (base.elapsed().as_secs_f64() / period_s) as u64;
        // At most half a second of ticks at once: a slow machine lags, it does not race.
        let mut budget = ((0.5 / period_s) as u64).max(1);
        loop {
            if !Driver::apply(&mut handle, &mut cell) {
                let t = tick_now(cell.controller());
                handle.publish(&t, cell.controller());
                was_paused = true;
                break;
            }
            if was_paused {
                was_paused = false;
                base = Instant::now();
                done_since_base = 0;
                break;
            }
            if done_since_base >= due || budget == 0 {
                break;
            }
            let tick = match &mut cell {
                SimCell::Rounds(s) => {
                    if s.coordinator().is_finished() {
                        s.restart();
                        handle.round_done();
                    }
                    s.tick(model, |i, k| needed[i][k], &mut rng)?
                }
                SimCell::Continuous(s) => {
                    s.tick(model, |i, k| needed[i][k], &mut rng)?;
                    tick_now(s.coordinator())
                }
            };
            handle.publish(&tick, cell.controller());
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
    Ok(())
}
