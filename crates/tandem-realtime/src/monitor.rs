//! THE run-time fault monitor of every controller (rounds and the continuous cell): after each
//! tick it keeps when each robot's run of low-confidence ticks began and latches a [`Fault`] in
//! a tick with more robots low-confidence than the cell has operators (one operator: two or
//! more), holding the robot whose run began last.
//!
//! The fault policy lives here and nowhere else: the rounds [`Coordinator`](crate::Coordinator)
//! and the [`ContinuousCoordinator`](crate::ContinuousCoordinator) both own a [`Monitor`], feed
//! it each tick's low-confidence flags and hold the robot it names
//! (docs/decisions.md, "One run-time contract").

use crate::robots::{MAX_ROBOTS, RobotFlags};

/// A latched fault of the run-time monitor: in tick `tick` more robots than the cell has
/// operators (one operator: two or more) traversed a
/// low-confidence sample (`low_conf`), a state [`sufficient_margins`](crate::sufficient_margins)
/// (rounds) and the token rule (the continuous cell) exclude. The controller fails safe instead
/// of carrying on: it holds `stopped`, the robot whose low-confidence stretch began last (the
/// highest index on a tie), where it is — its schedule clock no longer advances — until the
/// caller clears the fault, so that the operator has one robot to help. The fault is reported
/// in every later [`Tick`](crate::Tick).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fault {
    /// Index of the tick (counted from the controller's start or last reset) in which it
    /// happened.
    pub tick: u64,
    /// The robots low-confidence in that tick.
    pub low_conf: RobotFlags,
    /// The robot held (index `0..N`).
    pub stopped: usize,
}

/// Whether two or more robots are flagged in `low_conf`: the operator was needed by two robots
/// at once. The one overlap test of the crate ([`Tick::overlap`](crate::Tick::overlap), the
/// monitor).
#[must_use]
pub(crate) fn overlap(low_conf: &RobotFlags) -> bool {
    low_conf.count() >= 2
}

/// The run-time monitor of `N` robots: the ticks run, when each robot's current run of
/// low-confidence ticks began, and the latched [`Fault`]. O(N) per tick, no allocation.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Monitor {
    /// Number of robots.
    n: usize,
    /// Number of operators `M`: a tick with more than `M` robots low-confidence is the fault
    /// (`M = 1`: two or more, an overlap).
    operators: usize,
    /// Ticks observed since the start or the last reset.
    ticks: u64,
    /// Per robot, the tick at which its current run of low-confidence ticks began.
    lc_since: [u64; MAX_ROBOTS],
    /// Whether each robot was low-confidence in the previous tick.
    lc_last: RobotFlags,
    /// The latched fault.
    fault: Option<Fault>,
    /// Sectors (a rounds cell of `M` one-operator sectors, issue 44): each robot's operator;
    /// a tick with two robots of one sector low-confidence is the fault (which a tick with
    /// more than `M` always has). `None`: the count rule above.
    sector_of: Option<[u8; MAX_ROBOTS]>,
}

impl Monitor {
    /// A monitor of `n` robots that has seen no tick.
    pub(crate) fn new(n: usize) -> Monitor {
        Monitor {
            n,
            operators: 1,
            ticks: 0,
            lc_since: [0; MAX_ROBOTS],
            lc_last: RobotFlags::new(n),
            fault: None,
            sector_of: None,
        }
    }

    /// The same monitor for `m ≥ 1` operators each serving one fixed sector of robots
    /// (`sector_of[i] < m` robot `i`'s operator): a tick with two robots of one sector
    /// low-confidence is the fault — the sector's operator was needed twice at once (with
    /// more than `m` robots low-confidence some sector has two, so it includes the count rule).
    pub(crate) fn with_sectors(self, m: usize, sector_of: [u8; MAX_ROBOTS]) -> Monitor {
        Monitor {
            sector_of: Some(sector_of),
            ..self.with_operators(m)
        }
    }

    /// The same monitor for `m ≥ 1` operators: a tick with more than `m` robots
    /// low-confidence is the fault.
    pub(crate) fn with_operators(self, m: usize) -> Monitor {
        Monitor {
            operators: m.max(1),
            ..self
        }
    }

    /// Back to [`Monitor::new`] (the operators kept): no tick seen, no fault.
    pub(crate) fn reset(&mut self) {
        *self = Monitor {
            sector_of: self.sector_of,
            ..Monitor::new(self.n).with_operators(self.operators)
        };
    }

    /// Whether the robots flagged in `low_conf` are more than the cell's operators can
    /// serve: more than `M`, or with sectors two of one sector.
    fn too_many(&self, low_conf: &RobotFlags) -> bool {
        match &self.sector_of {
            None => low_conf.count() > self.operators,
            Some(of) => {
                let mut seen = [false; MAX_ROBOTS];
                for i in (0..self.n).filter(|&i| low_conf[i]) {
                    let o = usize::from(of[i]);
                    if seen[o] {
                        return true;
                    }
                    seen[o] = true;
                }
                false
            }
        }
    }

    /// A fresh monitor of `m` operators whose tick count goes on from `ticks` (a hand-over to
    /// a new plan: the runs of low-confidence ticks and the fault start afresh, the tick index
    /// does not).
    pub(crate) fn resumed_at(n: usize, m: usize, ticks: u64) -> Monitor {
        Monitor {
            ticks,
            ..Monitor::new(n).with_operators(m)
        }
    }

    /// Ticks observed since the start or the last reset: the index of the next tick.
    pub(crate) fn ticks(&self) -> u64 {
        self.ticks
    }

    /// The latched fault.
    pub(crate) fn fault(&self) -> Option<Fault> {
        self.fault
    }

    /// The robot the latched fault holds: it must not move until [`Monitor::clear`].
    pub(crate) fn held(&self) -> Option<usize> {
        self.fault.map(|f| f.stopped)
    }

    /// Clears the latched fault.
    pub(crate) fn clear(&mut self) {
        self.fault = None;
    }

    /// After each tick, with the robots low-confidence in it: keeps when each robot's run of
    /// low-confidence ticks began and, in a tick with more than `M` (one operator: two or
    /// more), latches a [`Fault`] holding
    /// the robot whose run began last (the highest index on a tie), unless a fault is already
    /// latched; counts the tick. Returns the latched fault (this tick's or an earlier one's).
    pub(crate) fn observe(&mut self, low_conf: RobotFlags) -> Option<Fault> {
        for i in 0..self.n {
            if low_conf[i] && !self.lc_last[i] {
                self.lc_since[i] = self.ticks;
            }
        }
        self.lc_last = low_conf;
        if self.fault.is_none() && self.too_many(&low_conf) {
            let stopped = (0..self.n)
                .filter(|&i| low_conf[i])
                .max_by_key(|&i| (self.lc_since[i], policy::tie_rank(i, self.n)))
                .expect("an overlap has low-confidence robots");
            self.fault = Some(Fault {
                tick: self.ticks,
                low_conf,
                stopped,
            });
        }
        self.ticks += 1;
        self.fault
    }
}

/// The tie rule of the fault policy: among robots whose low-confidence runs began in the same
/// tick, the one with the largest rank is held. In tests a hook can reverse it, to show that
/// the monitor is the only code that decides which robot is held.
mod policy {
    /// Rank of robot `i` of `n` on a tie: its index (the highest index is held).
    #[cfg(not(test))]
    pub(super) fn tie_rank(i: usize, _n: usize) -> usize {
        i
    }

    #[cfg(test)]
    thread_local! {
        /// Test hook: hold the lowest index on a tie instead of the highest.
        static LOWEST_ON_TIE: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    }

    /// Rank of robot `i` of `n` on a tie: its index, or with the test hook set, `n − i`.
    #[cfg(test)]
    pub(super) fn tie_rank(i: usize, n: usize) -> usize {
        if LOWEST_ON_TIE.get() { n - i } else { i }
    }

    /// Test hook: sets, on this thread, whether a tie holds the lowest index.
    #[cfg(test)]
    pub(crate) fn hold_lowest_on_tie(on: bool) {
        LOWEST_ON_TIE.set(on);
    }
}

#[cfg(test)]
pub(crate) use policy::hold_lowest_on_tie;

#[cfg(test)]
mod tests {
    use super::*;

    fn flags(v: &[bool]) -> RobotFlags {
        RobotFlags::from_slice(v)
    }

    #[test]
    fn latches_the_robot_whose_run_began_last_and_holds_it_until_cleared() {
        let mut m = Monitor::new(3);
        // Tick 0: robot 0 LC alone. Tick 1: robot 2 joins — robot 2's run began later.
        assert_eq!(m.observe(flags(&[true, false, false])), None);
        let f = Fault {
            tick: 1,
            low_conf: flags(&[true, false, true]),
            stopped: 2,
        };
        assert_eq!(m.observe(flags(&[true, false, true])), Some(f));
        assert_eq!(m.held(), Some(2));
        // Latched: a later overlap does not replace it; a tick without one keeps it.
        assert_eq!(m.observe(flags(&[true, true, false])), Some(f));
        assert_eq!(m.observe(flags(&[false; 3])), Some(f));
        m.clear();
        assert_eq!((m.fault(), m.held(), m.ticks()), (None, None, 4));
        // Tick 4: robots 0 and 1 both begin a run: the tie holds the higher index.
        assert_eq!(
            m.observe(flags(&[true, true, false])).map(|f| f.stopped),
            Some(1)
        );
        m.reset();
        assert_eq!((m.fault(), m.ticks()), (None, 0));
        let r = Monitor::resumed_at(3, 1, 17);
        assert_eq!((r.fault(), r.ticks()), (None, 17));
    }

    #[test]
    fn with_m_operators_the_fault_is_more_than_m() {
        let mut m = Monitor::new(4).with_operators(2);
        assert_eq!(m.observe(flags(&[true, true, false, false])), None);
        let f = m.observe(flags(&[true, true, true, false])).expect("3 > 2");
        assert_eq!((f.tick, f.stopped), (1, 2));
        m.reset();
        // The operators survive a reset.
        assert_eq!(m.observe(flags(&[false, true, true, false])), None);
    }

    #[test]
    fn with_sectors_the_fault_is_two_of_one_sector() {
        // Robots 0, 1 under operator 0; robots 2, 3 under operator 1.
        let mut of = [0_u8; MAX_ROBOTS];
        of[2] = 1;
        of[3] = 1;
        let mut m = Monitor::new(4).with_sectors(2, of);
        // One of each sector: two robots, two operators, no fault.
        assert_eq!(m.observe(flags(&[true, false, true, false])), None);
        // Two of sector 1 (robots 2 and 3), though only two robots in all: the fault.
        let f = m
            .observe(flags(&[false, false, true, true]))
            .expect("sector 1 twice");
        assert_eq!((f.tick, f.stopped), (1, 3));
        m.reset();
        // The sectors survive a reset.
        assert_eq!(m.observe(flags(&[false, true, true, false])), None);
        assert!(m.observe(flags(&[true, true, false, false])).is_some());
    }

    #[test]
    fn the_tie_hook_reverses_the_tie_only() {
        hold_lowest_on_tie(true);
        let mut m = Monitor::new(3);
        let tie = m.observe(flags(&[false, true, true])).map(|f| f.stopped);
        // Not a tie: robot 0's run began a tick after robot 1's — still the later one.
        let mut later = Monitor::new(3);
        later.observe(flags(&[false, true, false]));
        let not_tie = later
            .observe(flags(&[true, true, false]))
            .map(|f| f.stopped);
        hold_lowest_on_tie(false);
        assert_eq!((tie, not_tie), (Some(1), Some(0)));
    }
}
