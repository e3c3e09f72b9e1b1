//! The stuck incumbent (docs/decisions.md, "The stuck incumbent: N ≥ 3 robots with holds"):
//! three robots on pick-and-place, selection seed 7, ten rounds of the zoo's loop. Learning made
//! a stretch high-confidence in round 8 and the margin-free optimum dropped from 42.8 s to
//! 38.0 s and then 33.8 s, but the optimum with its release rules failed the margin check, no
//! other `N ≥ 3` candidate was built from it, and the re-timed incumbent (whose events never
//! move earlier) stayed at 43.1 s, 27 % above the bound, to the end. With the optimum re-timed
//! at growing clearances (and the lead bound's finished-robot pass) the run ends at its bound.

use tandem_planner::PlannerParams;
use tandem_zoo::eval::{prepare, run_rounds};

#[test]
fn three_robots_on_pick_and_place_seed_7_end_at_their_bound() {
    let family = tandem_zoo::family("pick_and_place").unwrap();
    let prep = prepare(family, 7, &PlannerParams::default(), false).unwrap();
    let run = run_rounds(&prep, 3, 10, &|| {}).unwrap();
    assert_eq!((run.overlap_ticks, run.backward_steps), (0, 0));
    // Was 43.07 s against a proven bound of 33.80 s (27.4 %).
    assert!(
        run.bound_is_optimum && run.gap_pct() < 2.0,
        "final {:.3} s against the bound {:.3} s ({:.1} %): {:?}",
        run.final_t_s(),
        run.bound_s,
        run.gap_pct(),
        run.t_total_s
    );
}
