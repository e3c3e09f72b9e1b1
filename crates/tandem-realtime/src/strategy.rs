//! The real-time timing strategy of §II-B5: the response of Eq. 18 and `HIGH-CONF` (Alg. 1).
//!
//! All quantities are schedule-clock seconds (the global time at which the schedule planned a
//! robot's current reference position). A robot's step `δt` is how far its schedule clock
//! advances during one control tick of `tick_s` real seconds; a rate `r` gives `δt = r·tick_s`.

use crate::timeline::Rates;

/// Eq. 18, `δt_resp(ΔT, ·)`: the step (schedule-clock s) of a responding robot whose lead over
/// the other robot, measured *after* the other robot's step, is `lead_s = s_self − s_other`.
///
/// - `−ΔT < S·tick`: even the slowest step keeps it level or ahead → go slowest, `S·tick`;
/// - `S·tick ≤ −ΔT < F·tick`: match the other robot exactly, `−ΔT`;
/// - otherwise it cannot catch up → go fastest, `F·tick`.
pub fn response_step(lead_s: f64, rates: Rates, tick_s: f64) -> f64 {
    let slow = rates.slow * tick_s;
    let fast = rates.fast * tick_s;
    let gap = -lead_s;
    if gap < slow {
        slow
    } else if gap < fast {
        gap
    } else {
        fast
    }
}

/// Alg. 1, `HIGH-CONF`: steps `(δt_a, δt_b)` (schedule-clock s) of two high-confidence robots,
/// `a` ahead and `b` behind with `lead_s = s_a − s_b ≥ 0` (either may be `a` when level).
///
/// If the behind robot can reach the ahead robot's fastest step (`F_b·tick ≥ F_a·tick + ΔT`),
/// `a` goes fastest and `b` lands level with it. Otherwise `b` goes at its *own* fastest rate
/// (line 9 prints `ψ̇^F_{i_a}(t_b)`, read as `b`'s own `F`: docs/decisions.md, "Typos of
/// Eq. 17 and Alg. 1") and `a` responds with Eq. 18 to the lead left after `b`'s step.
pub fn high_conf_steps(lead_s: f64, rates_a: Rates, rates_b: Rates, tick_s: f64) -> (f64, f64) {
    let fast_a = rates_a.fast * tick_s;
    let fast_b = rates_b.fast * tick_s;
    if fast_b >= fast_a + lead_s {
        (fast_a, fast_a + lead_s)
    } else {
        let step_b = fast_b;
        (response_step(lead_s - step_b, rates_a, tick_s), step_b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const R: Rates = Rates {
        fast: 2.0,
        slow: 0.5,
    };

    #[test]
    fn eq18_three_branches() {
        // tick 1 s: slowest step 0.5, fastest 2.
        // Ahead by 1 → slowest.
        assert_eq!(response_step(1.0, R, 1.0), 0.5);
        // Level → -ΔT = 0 < 0.5 → slowest.
        assert_eq!(response_step(0.0, R, 1.0), 0.5);
        // Behind by 0.5 → exactly S·tick is matched (second branch, same value).
        assert_eq!(response_step(-0.5, R, 1.0), 0.5);
        // Behind by 1.25 → match exactly.
        assert_eq!(response_step(-1.25, R, 1.0), 1.25);
        // Behind by exactly 2 → fastest.
        assert_eq!(response_step(-2.0, R, 1.0), 2.0);
        // Behind by 5 → fastest.
        assert_eq!(response_step(-5.0, R, 1.0), 2.0);
        // Tick 0.1 s scales the thresholds: behind by 0.1 → match.
        assert!((response_step(-0.1, R, 0.1) - 0.1).abs() < 1e-15);
    }

    #[test]
    fn alg1_behind_robot_can_catch_up() {
        // a: F = 2; b: F = 3; a ahead by 0.5, tick 1: 3 ≥ 2 + 0.5 → a goes 2, b goes 2.5 (level).
        let b = Rates {
            fast: 3.0,
            slow: 0.5,
        };
        assert_eq!(high_conf_steps(0.5, R, b, 1.0), (2.0, 2.5));
        // Level and equal rates: both fastest.
        assert_eq!(high_conf_steps(0.0, R, R, 1.0), (2.0, 2.0));
    }

    #[test]
    fn alg1_behind_robot_cannot_catch_up_uses_own_f() {
        // a ahead by 3, both F = 2: b goes its own F = 2; lead after b's step 1 > 0 → a slowest.
        assert_eq!(high_conf_steps(3.0, R, R, 1.0), (0.5, 2.0));
        // a: F = 4, S = 0.25; b: F = 1.5 (≠ a's F, line-9 fix matters), level:
        // 1.5 < 4 → b goes 1.5; a's lead after b's step is -1.5 → a matches, 1.5.
        let a = Rates {
            fast: 4.0,
            slow: 0.25,
        };
        let b = Rates {
            fast: 1.5,
            slow: 0.5,
        };
        assert_eq!(high_conf_steps(0.0, a, b, 1.0), (1.5, 1.5));
        // Same, a ahead by 1: b goes 1.5, a's lead after is -0.5 → a matches 0.5 (≥ S = 0.25).
        assert_eq!(high_conf_steps(1.0, a, b, 1.0), (0.5, 1.5));
        // a ahead by 1.4: b goes 1.5, a's lead after -0.1 < S·tick → a goes slowest 0.25.
        assert_eq!(high_conf_steps(1.4, a, b, 1.0), (0.25, 1.5));
    }
}
