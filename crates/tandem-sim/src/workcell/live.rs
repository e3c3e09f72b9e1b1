//! A round of the simulated workcell one control tick at a time ([`RoundSim`]), for a caller
//! that drives the cell in real time (the operator's console, issue 42) and may pause it,
//! clear a fault or start the next round between ticks. The tick is the workcell's one
//! [`step`] (module docs of [`crate::workcell`]). It is also the one round loop of
//! [`run_round_with`](super::run_round_with): that is a `RoundSim` ticked to the end, which
//! additionally records each robot's clock and phase before every tick
//! (`RoundSim::record_phases`) and releases a held robot itself; here a latched fault stays
//! latched until the caller clears it ([`RoundSim::clear_fault`]): the person at the console
//! releases the held robot.

use rand::Rng;
use tandem_lfd::TaskModel;
use tandem_realtime::{Coordinator, Tick};

use super::record::{RobotRun, TickPhase};
use tandem_schedule::Problem;

use super::operator::OperatorParams;
use super::run::{Operate, Robots, check_n_ref, check_tick, step};
use crate::{Error, Result};

/// A simulated round driven tick by tick: the coordinator of a checked schedule, the
/// simulated operator, each robot's execution in progress (dropped at each new round: the
/// caller shows the cell, it does not record it).
#[derive(Debug)]
pub struct RoundSim {
    coord: Coordinator,
    op: Operate,
    robots: Robots,
    conf: Vec<bool>,
    grad_min: Vec<f64>,
    grad_max: Vec<f64>,
    n_ref: usize,
    round_ticks: usize,
    /// Whether the operator's input in the last tick was a correction.
    corrected: bool,
}

impl RoundSim {
    /// A round of `coord` (every robot at its start) with the operator `params` on `model`'s
    /// task; `problem` is the one `coord`'s schedule was checked on.
    ///
    /// # Errors
    /// Invalid parameters; a model without the force channel; a problem or coordinator of
    /// another number of reference samples than the model ([`Error::Mismatch`]); a coordinator
    /// at another control tick than the model's `Δt_s` ([`Error::TickMismatch`]).
    pub fn new(
        model: &TaskModel,
        problem: &Problem,
        coord: Coordinator,
        params: &OperatorParams,
    ) -> Result<RoundSim> {
        params.validate()?;
        let n_ref = model.n_ref();
        let sizes = std::iter::once(("problem reference samples", problem.n_ref())).chain(
            coord
                .robots()
                .iter()
                .map(|t| ("a robot's plan reference samples", t.n_ref())),
        );
        check_n_ref(n_ref, sizes)?;
        check_tick(coord.tick_s(), model.dt_s())?;
        let op = Operate::new(model, params, coord.tick_s())?;
        let n = coord.n_robots();
        Ok(RoundSim {
            robots: Robots {
                runs: (0..n).map(|_| op.empty_run(n_ref)).collect(),
                in_episode: vec![false; n],
                ref_now: coord.ref_time_now().to_vec(),
            },
            op,
            conf: problem.conf().to_vec(),
            grad_min: problem.grad_min().to_vec(),
            grad_max: problem.grad_max().to_vec(),
            n_ref,
            round_ticks: 0,
            corrected: false,
            coord,
        })
    }

    /// The coordinator running the round.
    pub fn coordinator(&self) -> &Coordinator {
        &self.coord
    }

    /// Releases the robot held by a latched fault ([`Coordinator::clear_fault`]).
    pub fn clear_fault(&mut self) {
        self.coord.clear_fault();
    }

    /// Starts the next round: every robot back at its start ([`Coordinator::reset`]), the
    /// executions in progress dropped.
    pub fn restart(&mut self) {
        self.coord.reset();
        for (run, ep) in self.robots.runs.iter_mut().zip(&mut self.robots.in_episode) {
            *run = self.op.empty_run(self.n_ref);
            *ep = false;
        }
        self.robots.ref_now = self.coord.ref_time_now().to_vec();
        self.round_ticks = 0;
    }

    /// One control tick of the workcell (module docs of [`crate::workcell`]):
    /// `needs(robot, ref_idx)` says whether robot `robot` needs the operator at reference
    /// sample `ref_idx`, asked once per supervised sample before the operator's draw from
    /// `rng`. A finished round does not move (the tick changes nothing but the tick count);
    /// [`restart`](Self::restart) starts the next.
    ///
    /// # Errors
    /// A model of another size than the round's, or a degenerate command.
    pub fn tick(
        &mut self,
        model: &TaskModel,
        mut needs: impl FnMut(usize, usize) -> bool,
        rng: &mut impl Rng,
    ) -> Result<Tick> {
        if model.n_ref() != self.n_ref {
            return Err(Error::Mismatch {
                what: "model reference samples",
                expected: self.n_ref,
                found: model.n_ref(),
            });
        }
        Ok(self.step(model, &mut needs, rng)?.0)
    }

    /// One control tick on a model of the round's size (checked by the caller): the workcell's
    /// [`step`] with the round's bounds and confidence. Returns the tick and whether the
    /// operator's input was a correction.
    pub(super) fn step(
        &mut self,
        model: &TaskModel,
        needs: &mut impl FnMut(usize, usize) -> bool,
        rng: &mut impl Rng,
    ) -> Result<(Tick, bool)> {
        let (grad_min, grad_max) = (&self.grad_min, &self.grad_max);
        let out = step(
            &mut self.coord,
            model,
            &mut self.op,
            |_, _, n| (grad_min[n], grad_max[n]),
            Some(&self.conf),
            &mut self.robots,
            self.round_ticks,
            needs,
            rng,
        )?;
        self.round_ticks += 1;
        self.corrected = out.1;
        Ok(out)
    }

    /// Whether the operator's input in the last [`tick`](Self::tick) was a correction (the
    /// console's per-robot count of corrections).
    #[must_use]
    pub fn corrected(&self) -> bool {
        self.corrected
    }

    /// Records, before a tick, each robot's clock (s), whether it is at a hold, and its phase
    /// ([`TickPhase`]) into its execution in progress: what a recorded round
    /// ([`run_round_with`](super::run_round_with)) keeps and the console does not need.
    pub(super) fn record_phases(&mut self) {
        let held = self.coord.fault().map(|f| f.stopped);
        let clocks = self.coord.clock_s();
        let running = self.coord.running_now();
        for (i, run) in self.robots.runs.iter_mut().enumerate() {
            run.clock_s.push(clocks[i]);
            let at_hold = self.coord.at_hold(i);
            run.hold_ticks += usize::from(at_hold);
            run.phases.push(if held == Some(i) {
                TickPhase::Held
            } else if at_hold {
                TickPhase::AtHold
            } else if running[i] {
                TickPhase::Running
            } else if self.robots.ref_now[i] >= self.n_ref as f64 {
                TickPhase::Finished
            } else {
                TickPhase::Waiting
            });
        }
    }

    /// The coordinator and each robot's execution (the end of a recorded round).
    pub(super) fn into_parts(self) -> (Coordinator, Vec<RobotRun>) {
        (self.coord, self.robots.runs)
    }
}
