//! The operator's load cap at run time in the continuous cell (issue 41): the token's pace.
//!
//! **Episodes and passes.** The ticks of a run split into the operator's *episodes*, one per
//! token: episode `i` runs from its start `A_i` (tick index; `A_0 = 0`) to `A_{i+1}`. Its token's
//! robot passes its gate no sooner than `A_i + s_i`, where `s_i = k` (the switch time in ticks)
//! when the robot differs from the one that left the previous group, else 0; it leaves its group
//! at the end of tick `l_i`, where the token moves. Consecutive episodes form *segments*: one
//! per pass through the token sequence (the plan's cycle), the segment `j` from its start `C_j`
//! (`C_0 = 0`) to the start of the episode after the pass's last token. With `B` the segment's
//! busy count so far, `β_i = s_i + (ticks in [A_i, l_i] with a low-confidence robot)` added at
//! each token move, the next episode starts at `A_{i+1} = max(l_i + 1, C_j + n(B))`, `n(B)` the
//! least whole number with `B ≤ u·n` (`u` the cap, [`ticks_for_share`]): the pause
//! `A_{i+1} − (l_i + 1)`, when positive, is the operator's rest. So idle time earlier in a pass
//! (robots travelling between their stretches) pays for busier episodes later in it, never
//! across passes.
//!
//! **Why the share is at most `u` over every window of whole passes.** In `[A_i, A_i + s_i)`
//! nobody is low-confidence: the token's robot has not passed its gate, the previous one has
//! left its group (the token rule and the switch wait of docs/decisions.md, "The switch time at
//! run time (issue 41)"). In `[l_i + 1, A_{i+1})` nobody is either: the next token's robot may
//! not pass its gate before `A_{i+1}`. So the busy ticks (the low-confidence ticks and the `s_i`
//! switch ticks, disjoint) of `[C_j, A_{i+1})` number exactly `B` after episode `i`'s move, and
//! `A_{i+1} − C_j ≥ n(B)` gives `B ≤ u·(A_{i+1} − C_j)`: the share of every prefix of a segment
//! that ends at an episode start, in particular of the whole segment, is at most `u`, for any
//! operator (the pause is set after the episode, from what the operator did). Summed over
//! consecutive segments: the same over every window of whole segments. A window of `W`
//! arbitrary ticks exceeds `u·W` by at most `(1 − u)` times the busy ticks of the two segments
//! it cuts.

use crate::error::{Error, Result};

/// The token's pace of a cell with a load cap `u < 1`: the current segment's start and busy
/// count, and the current episode's start (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Pace {
    /// `u`: the operator's load cap, in `(0, 1)`.
    cap: f64,
    /// `C_j`: the first tick of the current segment (tick index: ticks run since the start).
    segment: u64,
    /// `B`: the busy ticks of the segment counted so far (its episodes' low-confidence ticks,
    /// and their switch ticks from each token move on).
    busy: u64,
    /// `A_i`: the first tick of the current episode.
    start: u64,
}

impl Pace {
    /// A pace at `cap` in `(0, 1)` (checked by the caller), at the start of a run.
    pub(super) fn new(cap: f64) -> Pace {
        Pace {
            cap,
            segment: 0,
            busy: 0,
            start: 0,
        }
    }

    /// The load cap `u`.
    pub(super) fn cap(&self) -> f64 {
        self.cap
    }

    /// `A_i`: the first tick of the current episode.
    pub(super) fn start(&self) -> u64 {
        self.start
    }

    /// `C_j`: the first tick of the current segment.
    pub(super) fn segment(&self) -> u64 {
        self.segment
    }

    /// Back to the start of a run.
    pub(super) fn reset(&mut self) {
        *self = Pace::new(self.cap);
    }

    /// The state of `old` (a hand-over keeps the segment and the episode running), at this
    /// pace's cap.
    pub(super) fn carry_over(&mut self, old: &Pace) {
        *self = Pace {
            cap: self.cap,
            ..*old
        };
    }

    /// Counts one tick: busy when a robot was low-confidence in it.
    pub(super) fn observe(&mut self, low_conf: bool) {
        self.busy += u64::from(low_conf);
    }

    /// The token moved after a robot left its group at the end of tick `left − 1`; `switch`:
    /// the switch ticks `s_i` its gate waited (`k` when it was not the robot that left the
    /// group before, else 0); `pass_ended`: the token wrapped around its sequence. Starts the
    /// next episode at `max(left, C_j + n(B))`, and with it the next segment when the pass
    /// ended.
    pub(super) fn end_episode(&mut self, left: u64, switch: u64, pass_ended: bool) {
        self.busy += switch;
        self.start = self
            .segment
            .saturating_add(ticks_for_share(self.busy, self.cap))
            .max(left);
        if pass_ended {
            self.segment = self.start;
            self.busy = 0;
        }
    }

    /// Ticks robot `i` must still wait at tick index `tick` before it may pass its gate with
    /// the token: until the episode's start, plus the switch ticks `k` when `last_left` (the
    /// robot that last left a group, and the tick after) is another robot, less `early` (at
    /// most the switch ticks: the ticks the robot surely travels from its gate before it is
    /// low-confidence, so `[A_i, A_i + s_i)` still has no low-confidence tick; never before
    /// the episode's start).
    pub(super) fn wait(
        &self,
        last_left: Option<(usize, u64)>,
        i: usize,
        k: u64,
        early: u64,
        tick: u64,
    ) -> u64 {
        let (from, switch) = match last_left {
            Some((r, left)) => (left.max(self.start), if r == i { 0 } else { k }),
            None => (self.start, 0),
        };
        (from + switch - early.min(switch)).saturating_sub(tick)
    }
}

/// Checks the operator's load cap `u_max` (`max_busy_share`, a share of ticks): it must lie in
/// `(0, 1]` (1: no cap). The one check of both coordinators' `with_max_busy_share`.
///
/// # Errors
/// [`Error::BadParam`] naming `max_busy_share` otherwise.
pub(crate) fn check_max_busy_share(max_busy_share: f64) -> Result<()> {
    if max_busy_share > 0.0 && max_busy_share <= 1.0 {
        Ok(())
    } else {
        Err(Error::BadParam {
            name: "max_busy_share",
            why: "must be in (0, 1]: the operator's busy share cap (1: no cap)",
        })
    }
}

/// `n(β)`: the least whole number of ticks `n` with `β ≤ u·n` as computed in floating point
/// (`u = cap` in `(0, 1]`), so that `β` busy ticks in `n` are a share of at most `u` as a run
/// measures it. 0 for `β = 0`.
pub(crate) fn ticks_for_share(busy: u64, cap: f64) -> u64 {
    let b = busy as f64;
    // The quotient rounded up, then corrected by whole ticks either way if the product says so
    // (the division may round across an integer).
    let mut n = (b / cap).ceil() as u64;
    while (n as f64) * cap < b {
        n += 1;
    }
    while n > 0 && ((n - 1) as f64) * cap >= b {
        n -= 1;
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_least_ticks_for_a_share_by_hand() {
        // 7 busy ticks at 0.7 need 10 (7/0.7 = 10.000000000000002 in floating point).
        assert_eq!(ticks_for_share(7, 0.7), 10);
        assert_eq!(ticks_for_share(0, 0.7), 0);
        assert_eq!(ticks_for_share(1, 0.5), 2);
        assert_eq!(ticks_for_share(3, 0.5), 6);
        assert_eq!(ticks_for_share(5, 1.0), 5);
        for busy in 0..2000u64 {
            for cap in [0.05, 0.1, 0.3, 0.6, 0.7, 0.9, 0.999] {
                let n = ticks_for_share(busy, cap);
                assert!(busy as f64 <= cap * n as f64, "{busy} at {cap}: {n}");
                assert!(n == 0 || busy as f64 > cap * (n - 1) as f64);
            }
        }
    }

    #[test]
    fn a_pass_pauses_to_its_share() {
        // Cap ½, switch 3 ticks. Episode 0 from tick 0: its robot (0) low-confidence 4 ticks,
        // left at the end of tick 9 (`left = 10`): B = 4, n = 8 ≤ 10, no pause.
        let mut p = Pace::new(0.5);
        for t in 0..10 {
            p.observe((5..9).contains(&t));
        }
        assert_eq!(p.wait(None, 1, 3, 0, 0), 0);
        p.end_episode(10, 0, false);
        assert_eq!(p.start(), 10);
        // Episode 1 of robot 1 (switch 3) busy 6 ticks, left at the end of tick 19: B = 4 +
        // 6 + 3 = 13, n = 26: the next episode starts at 26, the pass ends there.
        for t in 10..20 {
            p.observe((13..19).contains(&t));
        }
        p.end_episode(20, 3, true);
        assert_eq!(p.start(), 26);
        assert_eq!(p.wait(Some((1, 20)), 2, 3, 0, 20), 9);
        assert_eq!(p.wait(Some((1, 20)), 1, 3, 0, 20), 6);
        assert_eq!(p.wait(Some((1, 20)), 1, 3, 0, 26), 0);
        // A robot 2 ticks of travel from its stretch passes its gate 2 ticks early; the
        // credit is at most the switch ticks (never before the episode's start, 26).
        assert_eq!(p.wait(Some((1, 20)), 2, 3, 2, 20), 7);
        assert_eq!(p.wait(Some((1, 20)), 2, 3, 50, 20), 6);
        assert_eq!(p.wait(Some((1, 20)), 1, 3, 50, 20), 6);
        // A new segment from 26: an episode already longer than its share goes on at once.
        for t in 20..60 {
            p.observe(t == 50);
        }
        p.end_episode(60, 0, false);
        assert_eq!(p.start(), 60);
    }
}
