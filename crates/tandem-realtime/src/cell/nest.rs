//! Nested groups (issue 45): the two tick counts behind
//! [`ContinuousCoordinator::with_nesting`](super::ContinuousCoordinator::with_nesting), which
//! lets the next robot of the token sequence go through its whole group inside a
//! high-confidence gap of the group the token's robot is in.
//!
//! **The rule.** At the end of tick `T` (the next tick is `T + 1`), robot `i` holds the token
//! for its group `G`, has not left it, and is on high-confidence ground (every sample from its
//! clock less the tolerance to its clock is high-confidence), `a` the clock of its next
//! low-confidence sample (in `G`: it has not left `G`). The next entry of the sequence is
//! robot `j ≠ i`'s group `G'`, and `j` waits at `G'`'s gate. Then `j` may pass its gate from
//! tick `T + 1` when
//! 1. (*back in time*) `n_i ≥ W_j + k + 1`, `n_i` = [`ticks_before_lc`] (no tick before
//!    `T + n_i` is low-confidence for `i`), `W_j` = [`span_ticks`] of `G'` (`j` has left
//!    `G'` by the end of tick `T + W_j`, so its last low-confidence tick is at most that),
//!    `k` the switch time in ticks;
//! 2. (*the switch to `j`*) `T + 1 + e_j ≥ L + k + 1` for the last low-confidence tick `L` of
//!    every robot other than `j`, `e_j` the whole ticks `j` surely travels from its gate
//!    before its first low-confidence tick in `G'` (as the token rule's switch wait counts
//!    them).
//!
//! *Why no two robots are low-confidence in one tick, for any operator.* Outside the nested
//! span the token rule's argument holds unchanged: `i` and `j` are the only robots that may
//! pass a gate (every other robot is before its gate or waits there, on high-confidence
//! samples). `j`'s low-confidence ticks lie in `[T + 1 + e_j, T + W_j]`; `i`'s ticks from
//! `T + 1` to `T + n_i − 1` are high-confidence (1), so `i` and `j` are never low-confidence
//! together, and between `j`'s last and `i`'s next at least `k` ticks pass; (2) gives the `k`
//! ticks before `j`'s first. `j` leaves `G'` before `i` reaches its next stretch, so when `i`
//! leaves `G` the token moves on as before (`j`'s entry already granted). Both bounds hold for
//! every admissible operator: on high-confidence samples a robot's clock advances exactly one
//! tick per tick (less at a cap), so `i` moves at most `h` per tick (a *least* duration of the
//! gap); on low-confidence samples at least `S·h` per tick (`S = ψ̇_E/ψ̇max`, the slowest
//! input, Eq. 17), so `j` needs at most the ticks of [`span_ticks`] (a *largest* span).
//! Each rounding errs on the safe side: `n_i` is rounded down (and its distance shortened by
//! twice the clock tolerance), every segment of `W_j` rounded up with one tick added for the
//! cap that may end it short and the summing of steps.

use crate::timeline::Timeline;

use super::groups::Group;

/// `W`: an upper bound on the ticks of `h = tick_s` a robot needs, from the tick start at
/// which it stands at the gate of its group `g` of `task` and may pass it, to the end of the
/// tick at which it has left `g` (clock at least the start of sample `g.ref_end` plus `tol_s`),
/// under every operator input.
///
/// The samples from the gate to `g.ref_end` split into maximal runs of one confidence. A
/// high-confidence run of clock length `ℓ` takes at most `⌈ℓ/h⌉ + 1` ticks (a tick advances
/// the clock by `h`, a cap at the next low-confidence sample may end one short); a
/// low-confidence run at most `⌈ℓ/(S_min·h)⌉ + 1` (every tick that starts on it advances by at
/// least `S·h`, `S = ψ̇_E/ψ̇max` of its sample, Eq. 17; `S_min` the least over the run). Each run
/// starts no later than its first sample's clock, so the sum bounds the whole; one tick more
/// covers the tolerance past the last low-confidence sample (`tol_s < h`). O(samples of `g`).
pub(crate) fn span_ticks(task: &Timeline, g: &Group, tick_s: f64, tol_s: f64) -> u64 {
    let (c, conf) = (task.sample_clock_s(), task.conf());
    let mut ticks: u64 = 1 + u64::from(tol_s >= tick_s);
    let mut k = g.gate;
    while k < g.ref_end {
        let start = k;
        let hc = conf[k];
        let mut rate = 1.0_f64;
        while k < g.ref_end && conf[k] == hc {
            if !hc {
                rate = rate.min(task.rate_slow(k));
            }
            k += 1;
        }
        let len = (c[k] - c[start]).max(0.0);
        let per_tick = if hc { tick_s } else { rate * tick_s };
        let q = (len / per_tick).ceil();
        if !q.is_finite() || q >= (u64::MAX / 4) as f64 {
            return u64::MAX / 4;
        }
        ticks += q as u64 + 1;
    }
    ticks
}

/// `n`: the ticks of `h = tick_s` after which a robot at clock `clock_s` on high-confidence
/// ground, whose next low-confidence sample starts at clock `next_lc_s`, may first be
/// low-confidence: no tick before the `n`-th from now (1-based) is. A tick is low-confidence
/// when the interval it traverses, widened by `tol_s`, reaches a low-confidence sample; on
/// high-confidence ground the `m`-th tick ends at clock at most `clock_s + m·h`, so it is
/// high-confidence while `clock_s + m·h + tol_s < next_lc_s`. Rounded down, the distance
/// shortened by `2·tol_s` (the sum of `m` steps may exceed `m·h` by rounding). At least 1.
pub(crate) fn ticks_before_lc(clock_s: f64, next_lc_s: f64, tick_s: f64, tol_s: f64) -> u64 {
    let x = (next_lc_s - clock_s - 2.0 * tol_s) / tick_s;
    if !x.is_finite() || x <= 1.0 {
        return 1;
    }
    let n = (x * (1.0 - 1e-12)).ceil();
    if n >= (u64::MAX / 4) as f64 {
        u64::MAX / 4
    } else {
        (n as u64).max(1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::groups;

    /// `conf` at Δt_s = 1 s, ψ̇ = 1, bounds [½, 2] (`S = ½`).
    fn task(conf: &[bool]) -> Timeline {
        let n = conf.len();
        Timeline::new(conf, &vec![1.0; n], &vec![0.5; n], &vec![2.0; n], 0.0, 1.0).unwrap()
    }

    #[test]
    fn the_span_by_hand() {
        // [HC, LC, LC, HC, LC, HC]: one group (no hold), gate 0. At h = 1 s: the HC run of
        // 1 s: 1 + 1; LC 2 s at S = ½: 4 + 1; HC 1 s: 1 + 1; LC 1 s: 2 + 1; one for the
        // tolerance: 13. The slowest run really takes 1 + 4 + 1 + 2 + 1 = 9 ticks.
        let t = task(&[true, false, false, true, false, true]);
        let g = groups(t.conf(), &[]).unwrap();
        assert_eq!(g.len(), 1);
        assert_eq!(span_ticks(&t, &g[0], 1.0, 1e-9), 13);
        // At h = ½ s every run doubles its whole ticks: 2+1, 8+1, 2+1, 4+1, 1 = 21.
        assert_eq!(span_ticks(&t, &g[0], 0.5, 1e-9), 21);
    }

    #[test]
    fn the_least_gap_by_hand() {
        // At clock 2 s, the next low-confidence sample at 5 s, h = 1 s: ticks 1 and 2 end at
        // 3 and 4 s (high-confidence), tick 3 may reach 5 s: n = 3.
        assert_eq!(ticks_before_lc(2.0, 5.0, 1.0, 1e-9), 3);
        // Half a tick further on: tick 3 ends at 5.5 s at most, n = 3 still (⌈2.5⌉).
        assert_eq!(ticks_before_lc(2.5, 5.0, 1.0, 1e-9), 3);
        // Adjacent: the next tick may be low-confidence.
        assert_eq!(ticks_before_lc(4.9, 5.0, 1.0, 1e-9), 1);
        assert_eq!(ticks_before_lc(5.0, 5.0, 1.0, 1e-9), 1);
    }
}
