//! Shared by the console's tests and bench: a hand-made cell.

#![allow(dead_code)]

use tandem_planner::AnyController;
use tandem_realtime::{ContinuousCoordinator, Coordinator, Timeline};

/// `n` robots of a task of 100 samples at Δt_s = 0.1 s (10 s), low-confidence on 40..60 (2 s
/// at the mean pace, gradient 1, bounds [½, 2]); in rounds robot `i` starts at `i · 4` s, so
/// the stretches follow each other; the continuous cell lets the token rule order them.
pub(crate) fn task(start_s: f64) -> Timeline {
    let conf: Vec<bool> = (0..100).map(|k| !(40..60).contains(&k)).collect();
    let g = vec![1.0; 100];
    let (lo, hi) = (vec![0.5; 100], vec![2.0; 100]);
    Timeline::new(&conf, &g, &lo, &hi, start_s, 0.1).expect("a valid timeline")
}

/// The rounds cell of [`task`] for `n` robots.
pub(crate) fn rounds(n: usize) -> AnyController {
    let robots: Vec<Timeline> = (0..n).map(|i| task(4.0 * i as f64)).collect();
    AnyController::Rounds(Coordinator::new(robots, 0.1).expect("stretches 4 s apart pass"))
}

/// The continuous cell of [`task`] for `n` robots.
pub(crate) fn continuous(n: usize) -> AnyController {
    let slots: Vec<(usize, usize)> = (0..n).map(|i| (i, 0)).collect();
    AnyController::Continuous(
        ContinuousCoordinator::new(task(0.0), &[], &slots, n, 0.1).expect("a runnable order"),
    )
}
