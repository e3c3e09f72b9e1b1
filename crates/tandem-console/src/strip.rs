//! The page's strips (issue 42): per robot ([`RobotStrip`]: warp rate within its bounds,
//! confidence at the current sample, supervision this execution, fault) and for the operator
//! ([`OperatorStrip`]: busy share, switches per hour, longest busy stretch, time on shift),
//! derived by [`Tracker`] from the snapshots the server reads, one after the other.
//!
//! The server sees the newest snapshot at most `max_hz` times a second, not every tick: the
//! tracker weighs each snapshot by the ticks since the one before (`RawFrame::tick`), so the
//! shares and durations are in cell time and do not depend on the page's frame rate; a
//! low-confidence stretch shorter than one server period between two reads can be missed in
//! the switch count (at 30 Hz: under 33 ms, far below any planned stretch). A replay feeds
//! every tick of its recording, so its strips are exact.

use serde::{Deserialize, Serialize};
use tandem_realtime::MAX_ROBOTS;

use crate::frame::{Geometry, RawFrame, RobotState};

/// Cell time (s) over which the warp rate is measured.
const RATE_WINDOW_S: f64 = 1.0;
/// Relative slack of "within its bounds" (the window's ticks quantize the rate).
const RATE_SLACK: f64 = 0.05;

/// One robot's strip on the page.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RobotStrip {
    /// Its warp rate over the last second of cell time it ran: execution samples per reference
    /// sample (1: the reference demonstration's pace; larger is slower). `None` while it
    /// does not move (waits, holds, done, fault) or before a second has passed.
    pub rate: Option<f64>,
    /// The rate's bounds `[ψ̇min, ψ̇max]` at its current sample (the demonstrations' speed
    /// range), if the plan carries them.
    pub rate_bounds: Option<(f64, f64)>,
    /// Whether `rate` is within `rate_bounds` (5 % slack for the tick grid); true when either
    /// is unknown.
    pub rate_ok: bool,
    /// Whether its current reference sample is high-confidence (outside its planned
    /// low-confidence runs).
    pub confident: bool,
    /// Cell time (s) it was supervised (`lc`) in its current execution (task).
    pub supervised_s: f64,
    /// Low-confidence stretches the operator supervised in its current execution.
    pub stretches: u64,
    /// Corrections the operator gave it in its current execution (runs of consecutive
    /// corrected ticks; [`RawRobot::corrections`](crate::RawRobot::corrections)); `None`
    /// when the source does not report the operator's input (a replay, a loop that calls
    /// [`ConsoleHandle::publish`](crate::ConsoleHandle::publish)).
    #[serde(default)]
    pub corrections: Option<u64>,
    /// Whether the fault monitor holds it.
    pub fault: bool,
}

/// The operator's strip on the page.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct OperatorStrip {
    /// Share of the time on shift some robot was supervised (`lc`), in `[0, 1]`.
    pub busy_share: f64,
    /// Switches (a stretch of another robot than the one supervised before) per hour of shift.
    pub switches_per_h: f64,
    /// Switches so far.
    pub switches: u64,
    /// The longest time (s) the operator was needed without a break (stretches back to back
    /// count as one).
    pub longest_busy_s: f64,
    /// The current busy stretch (s), 0 when no robot needs the operator.
    pub busy_now_s: f64,
    /// Cell time (s) since the console's first snapshot.
    pub shift_s: f64,
}

/// Where a robot's warp rate is measured from.
#[derive(Clone, Copy, Debug, Default)]
struct Anchor {
    t_s: f64,
    ref_time: f64,
    tasks: u64,
    valid: bool,
}

/// Per-robot memory of the tracker.
#[derive(Clone, Copy, Debug, Default)]
struct RobotMemory {
    anchor: Anchor,
    rate: Option<f64>,
    tasks: u64,
    supervised_s: f64,
    stretches: u64,
    was_lc: bool,
}

/// Derives the strips from successive snapshots ([`Tracker::update`]).
#[derive(Clone, Debug, Default)]
pub struct Tracker {
    started: bool,
    last_tick: u64,
    last_rounds_done: u64,
    shift_s: f64,
    busy_s: f64,
    busy_now_s: f64,
    longest_busy_s: f64,
    switches: u64,
    last_supervised: Option<usize>,
    robots: [RobotMemory; MAX_ROBOTS],
    last: Option<(Vec<RobotStrip>, OperatorStrip)>,
}

impl Tracker {
    /// A tracker that has seen nothing.
    #[must_use]
    pub fn new() -> Tracker {
        Tracker::default()
    }

    /// Takes the next snapshot `raw` of the cell of `geometry`; returns each robot's strip
    /// (robot 1 first) and the operator's.
    pub fn update(
        &mut self,
        geometry: &Geometry,
        raw: &RawFrame,
    ) -> (Vec<RobotStrip>, OperatorStrip) {
        let n = raw.n.min(MAX_ROBOTS);
        let new_round = raw.rounds_done != self.last_rounds_done;
        // Ticks since the snapshot before (a new round restarts the controller's count).
        let ticks = if !self.started {
            0
        } else if raw.tick >= self.last_tick && !new_round {
            raw.tick - self.last_tick
        } else {
            raw.tick
        };
        let dt = ticks as f64 * raw.tick_s;
        self.started = true;
        self.last_tick = raw.tick;
        self.last_rounds_done = raw.rounds_done;
        self.shift_s += dt;
        let t_s = self.shift_s;
        let supervised = (0..n).find(|&i| raw.robots[i].state == RobotState::Lc);
        if let Some(k) = supervised {
            self.busy_s += dt;
            self.busy_now_s += dt;
            if self.last_supervised.is_some_and(|j| j != k) {
                self.switches += 1;
            }
            self.last_supervised = Some(k);
        } else {
            self.busy_now_s = 0.0;
        }
        self.longest_busy_s = self.longest_busy_s.max(self.busy_now_s);
        let mut strips = Vec::with_capacity(n);
        for i in 0..n {
            let r = &raw.robots[i];
            let m = &mut self.robots[i];
            // A new execution: the robot's task count moved, or a new round began.
            if r.tasks != m.tasks || new_round {
                m.tasks = r.tasks;
                m.supervised_s = 0.0;
                m.stretches = 0;
                m.anchor.valid = false;
                m.rate = None;
            }
            let lc = r.state == RobotState::Lc;
            if lc {
                m.supervised_s += dt;
                if !m.was_lc {
                    m.stretches += 1;
                }
            }
            m.was_lc = lc;
            let moving = matches!(r.state, RobotState::Lc | RobotState::Hc);
            if !moving {
                m.anchor.valid = false;
                m.rate = None;
            } else if !m.anchor.valid || m.anchor.tasks != r.tasks {
                m.anchor = Anchor {
                    t_s,
                    ref_time: r.ref_time,
                    tasks: r.tasks,
                    valid: true,
                };
            } else if t_s - m.anchor.t_s >= RATE_WINDOW_S {
                let d_ref = r.ref_time - m.anchor.ref_time;
                m.rate = match geometry.dt_s(i) {
                    Some(dt_ref) if d_ref > 1e-9 => Some((t_s - m.anchor.t_s) / dt_ref / d_ref),
                    _ => None,
                };
                m.anchor = Anchor {
                    t_s,
                    ref_time: r.ref_time,
                    tasks: r.tasks,
                    valid: true,
                };
            }
            let rate_bounds = geometry.rate_bounds_at(i, r.ref_time);
            let rate_ok = match (m.rate, rate_bounds) {
                (Some(v), Some((lo, hi))) => {
                    v >= lo * (1.0 - RATE_SLACK) && v <= hi * (1.0 + RATE_SLACK)
                }
                _ => true,
            };
            strips.push(RobotStrip {
                rate: m.rate,
                rate_bounds,
                rate_ok,
                confident: geometry.confident_at(i, r.ref_time),
                supervised_s: m.supervised_s,
                stretches: m.stretches,
                corrections: raw.corrections_known.then_some(r.corrections),
                fault: r.state == RobotState::Fault,
            });
        }
        let op = OperatorStrip {
            busy_share: if self.shift_s > 0.0 {
                (self.busy_s / self.shift_s).clamp(0.0, 1.0)
            } else {
                0.0
            },
            switches_per_h: if self.shift_s > 0.0 {
                self.switches as f64 * 3600.0 / self.shift_s
            } else {
                0.0
            },
            switches: self.switches,
            longest_busy_s: self.longest_busy_s,
            busy_now_s: self.busy_now_s,
            shift_s: self.shift_s,
        };
        (strips, op)
    }

    /// [`Tracker::update`] writing the strips into `frame` (built from the same `raw`).
    pub fn fill(&mut self, geometry: &Geometry, raw: &RawFrame, frame: &mut crate::Frame) {
        let (robots, op) = self.update(geometry, raw);
        for (f, s) in frame.robots.iter_mut().zip(&robots) {
            f.strip = s.clone();
        }
        frame.operator = op.clone();
        self.last = Some((robots, op));
    }

    /// Writes the strips of the last [`Tracker::fill`] into `frame` (a frame of the same
    /// snapshot, pushed again).
    pub fn fill_again(&self, frame: &mut crate::Frame) {
        if let Some((robots, op)) = &self.last {
            for (f, s) in frame.robots.iter_mut().zip(robots) {
                f.strip = s.clone();
            }
            frame.operator = op.clone();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::RawRobot;

    fn raw(tick: u64, states: &[RobotState], ref_time: &[f64]) -> RawFrame {
        let mut r = RawFrame {
            n: states.len(),
            tick,
            tick_s: 0.1,
            ..RawFrame::default()
        };
        for (i, (&s, &t)) in states.iter().zip(ref_time).enumerate() {
            r.robots[i] = RawRobot {
                state: s,
                ref_time: t,
                ..RawRobot::default()
            };
        }
        r
    }

    #[test]
    fn operator_strip_by_hand() {
        use RobotState::{Hc, Lc};
        let g = Geometry::empty(true);
        let mut tr = Tracker::new();
        // 10 ticks of 0.1 s per snapshot: idle 1 s, robot 1 lc 2 s, robot 2 lc 1 s (back to
        // back: one busy stretch of 3 s), idle 1 s, robot 2 lc 1 s.
        let seq = [[Hc, Hc], [Lc, Hc], [Lc, Hc], [Hc, Lc], [Hc, Hc], [Hc, Lc]];
        tr.update(&g, &raw(0, &[Hc, Hc], &[0.0, 0.0]));
        let mut op = OperatorStrip::default();
        for (k, s) in seq.iter().enumerate() {
            op = tr.update(&g, &raw(10 * (k as u64 + 1), s, &[0.0, 0.0])).1;
        }
        assert!((op.shift_s - 6.0).abs() < 1e-9, "{op:?}");
        assert!((op.busy_share - 4.0 / 6.0).abs() < 1e-9, "{op:?}");
        // Robot 1 → robot 2 is a switch; robot 2 → (idle) → robot 2 is not.
        assert_eq!(op.switches, 1);
        assert!((op.switches_per_h - 600.0).abs() < 1e-9, "{op:?}");
        assert!((op.longest_busy_s - 3.0).abs() < 1e-9, "{op:?}");
        assert!((op.busy_now_s - 1.0).abs() < 1e-9, "{op:?}");
    }

    #[test]
    fn robot_strip_counts_supervision_per_execution() {
        use RobotState::{Hc, Lc, Wait};
        let g = Geometry::empty(false);
        let mut tr = Tracker::new();
        let mut f = |tick, s, tasks| {
            let mut r = raw(tick, &[s], &[0.0]);
            r.robots[0].tasks = tasks;
            tr.update(&g, &r).0.remove(0)
        };
        f(0, Hc, 0);
        f(5, Lc, 0);
        f(10, Lc, 0);
        f(15, Hc, 0);
        let s = f(20, Lc, 0);
        assert_eq!(s.stretches, 2);
        assert!((s.supervised_s - 1.5).abs() < 1e-9, "{s:?}");
        // The next task starts afresh; a waiting robot has no rate.
        let s = f(25, Wait, 1);
        assert_eq!((s.stretches, s.supervised_s, s.rate), (0, 0.0, None));
        assert!(s.confident, "no plan: confident");
    }

    #[test]
    fn warp_rate_by_hand() {
        use tandem_planner::AnyController;
        use tandem_realtime::{Coordinator, Timeline};
        // One robot, 100 samples of 0.1 s, bounds ψ̇ ∈ [½, 2], confident everywhere.
        let t = Timeline::new(
            &[true; 100],
            &[1.0; 100],
            &[0.5; 100],
            &[2.0; 100],
            0.0,
            0.1,
        )
        .unwrap();
        let g = Geometry::new(&AnyController::Rounds(
            Coordinator::new(vec![t], 0.1).unwrap(),
        ));
        let mut tr = Tracker::new();
        let mut at = |tick: u64, r: f64| {
            tr.update(&g, &raw(tick, &[RobotState::Hc], &[r]))
                .0
                .remove(0)
        };
        // Half a sample per 0.1 s tick: 1 s of cell time per 5 samples of 0.1 s, ψ̇ = 2.
        at(0, 0.0);
        let s = at(10, 5.0);
        assert!((s.rate.unwrap() - 2.0).abs() < 1e-9, "{s:?}");
        assert_eq!(s.rate_bounds, Some((0.5, 2.0)));
        assert!(s.rate_ok && s.confident);
        // A quarter sample per tick: ψ̇ = 4, out of bounds.
        let s = at(20, 7.5);
        assert!((s.rate.unwrap() - 4.0).abs() < 1e-9, "{s:?}");
        assert!(!s.rate_ok);
    }
}
