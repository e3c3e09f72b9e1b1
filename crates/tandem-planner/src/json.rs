//! The documented JSON outputs of the planner's plans (docs/formats.md), as types of their
//! own apart from the library types they show, so that renaming or adding a field of a
//! library type changes no documented output: each conversion names every field of the
//! library type, so a field added fails to compile here until it is decided on. One owner
//! for every front end: the command line prints them, Python returns them (issue 40, "State
//! wire types apart from library types").
//!
//! [`CyclicPlanJson`]: the cyclic plan of a continuous cell.

use serde::Serialize;
use tandem_schedule::cyclic::{CyclicPlan, GapPlan, RobotCycle, Stretch};

/// The documented JSON form of a continuous cell's cyclic plan (`CyclicPlan`): what `tandem
/// schedule --cell continuous --json` prints and Python's `CyclicPlan.to_json()` returns, both
/// `serde_json::to_string_pretty` of this (meaning of every field, times in seconds of the
/// cell's period, robots and stretches 0-based: docs/formats.md, "Cyclic plan JSON").
/// Fields in the documented key order; made with `CyclicPlanJson::from(&plan)`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CyclicPlanJson {
    n_robots: usize,
    order: Vec<StretchJson>,
    period_s: f64,
    lc_s: Vec<f64>,
    robots: Vec<RobotCycleJson>,
    tasks_per_hour: f64,
    operator_share: f64,
    lower_bound_s: f64,
    gap: f64,
    order_exhaustive: bool,
    orders_evaluated: usize,
}

/// One of [`CyclicPlanJson::order`]: robot and low-confidence stretch, both 0-based.
#[derive(Clone, Debug, PartialEq, Serialize)]
struct StretchJson {
    robot: usize,
    lc: usize,
}

/// One of [`CyclicPlanJson::robots`].
#[derive(Clone, Debug, PartialEq, Serialize)]
struct RobotCycleJson {
    start_s: f64,
    lc_start_s: Vec<f64>,
    gaps: Vec<GapJson>,
    start_wait_s: f64,
}

/// One of [`RobotCycleJson::gaps`].
#[derive(Clone, Debug, PartialEq, Serialize)]
struct GapJson {
    duration_s: f64,
    wait_s: f64,
    hold: Option<usize>,
}

impl From<&CyclicPlan> for CyclicPlanJson {
    fn from(p: &CyclicPlan) -> Self {
        let CyclicPlan {
            n_robots,
            order,
            period_s,
            lc_s,
            robots,
            tasks_per_hour,
            operator_share,
            lower_bound_s,
            gap,
            order_exhaustive,
            orders_evaluated,
        } = p;
        CyclicPlanJson {
            n_robots: *n_robots,
            order: order
                .iter()
                .map(|&Stretch { robot, lc }| StretchJson { robot, lc })
                .collect(),
            period_s: *period_s,
            lc_s: lc_s.clone(),
            robots: robots
                .iter()
                .map(|r| {
                    let RobotCycle {
                        start_s,
                        lc_start_s,
                        gaps,
                        start_wait_s,
                    } = r;
                    RobotCycleJson {
                        start_s: *start_s,
                        lc_start_s: lc_start_s.clone(),
                        gaps: gaps
                            .iter()
                            .map(
                                |&GapPlan {
                                     duration_s,
                                     wait_s,
                                     hold,
                                 }| GapJson {
                                    duration_s,
                                    wait_s,
                                    hold,
                                },
                            )
                            .collect(),
                        start_wait_s: *start_wait_s,
                    }
                })
                .collect(),
            tasks_per_hour: *tasks_per_hour,
            operator_share: *operator_share,
            lower_bound_s: *lower_bound_s,
            gap: *gap,
            order_exhaustive: *order_exhaustive,
            orders_evaluated: *orders_evaluated,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A one-robot plan with one stretch, every field a distinct number.
    fn plan() -> CyclicPlan {
        CyclicPlan {
            n_robots: 1,
            order: vec![Stretch { robot: 0, lc: 0 }],
            period_s: 2.5,
            lc_s: vec![0.5],
            robots: vec![RobotCycle {
                start_s: 0.0,
                lc_start_s: vec![1.0],
                gaps: vec![
                    GapPlan {
                        duration_s: 1.0,
                        wait_s: 0.25,
                        hold: Some(7),
                    },
                    GapPlan {
                        duration_s: 0.75,
                        wait_s: 0.0,
                        hold: None,
                    },
                ],
                start_wait_s: 0.25,
            }],
            tasks_per_hour: 1440.0,
            operator_share: 0.2,
            lower_bound_s: 2.0,
            gap: 0.25,
            order_exhaustive: true,
            orders_evaluated: 1,
        }
    }

    #[test]
    fn the_cyclic_plan_json_is_the_documented_form() {
        // docs/formats.md, "Cyclic plan JSON": these keys, in this order, at every level.
        let text = serde_json::to_string(&CyclicPlanJson::from(&plan())).unwrap();
        assert_eq!(
            text,
            "{\"n_robots\":1,\"order\":[{\"robot\":0,\"lc\":0}],\"period_s\":2.5,\
             \"lc_s\":[0.5],\"robots\":[{\"start_s\":0.0,\"lc_start_s\":[1.0],\"gaps\":\
             [{\"duration_s\":1.0,\"wait_s\":0.25,\"hold\":7},{\"duration_s\":0.75,\
             \"wait_s\":0.0,\"hold\":null}],\"start_wait_s\":0.25}],\"tasks_per_hour\":1440.0,\
             \"operator_share\":0.2,\"lower_bound_s\":2.0,\"gap\":0.25,\
             \"order_exhaustive\":true,\"orders_evaluated\":1}"
        );
    }
}
