//! A run bag replayed with its state file (`tandem console STATE --replay RUN.mcap`): the
//! frames rebuilt from the bag's per-tick logs (tandem-bag's run layout, [`read_run`]: each
//! robot's reference time, supervised flag and schedule clock at every tick of every round)
//! against the plan geometry of the state file's planner, as a [`Recording`] that [`replay`]
//! and [`check_recording`] take like any other.
//!
//! What such a replay can show (docs/decisions.md, "The console replays a run bag with its
//! state file"): each robot's state per tick — `lc` where the bag's `supervised` flag is set
//! (the page's `lc` robot is the one the run logged as supervised, so "two `lc`" counts the
//! ticks the run logged two supervised robots), `wait` before its start, `hold` where its next
//! tick does not advance it (a hold point: a running robot advances at least at `ψ̇min`
//! otherwise),
//! `done` after its last logged tick, `hc` otherwise —, its schedule clock and reference time;
//! the timeline, the queue and the banner's time left from the state's plan. What it cannot:
//! the coordinator's pre-alert (a run bag records none, so the page shows no countdown and the
//! check counts no pre-alert), faults, the operator's input, and the plan of a round whose
//! schedule is not the state's (a state recorded into since: the note says so).
//!
//! [`replay`]: crate::replay
//! [`check_recording`]: crate::check_recording

use std::path::Path;

use tandem_bag::{RunRoundLog, read_run};

use crate::error::{Error, Result};
use crate::frame::{Geometry, RobotState};
use crate::replay::{RecordedRobot, RecordedTick, Recording};

/// Reads the run bag at `path` (a `.mcap` file, or a folder holding one) for the rounds plan
/// `geometry` of the state file's planner (`schedule`: its description for the page's
/// health) and rebuilds every tick of every round as a [`Recording`] (see the module docs).
///
/// # Errors
/// [`Error::Recording`] naming the bag: a continuous `geometry` (a run bag holds rounds), an
/// unreadable, truncated or damaged bag, a bag of another robot count than the plan's, logs
/// that do not fill their rounds.
pub fn read_run_bag(
    path: impl AsRef<Path>,
    geometry: &Geometry,
    schedule: Option<&str>,
) -> Result<Recording> {
    let path = path.as_ref();
    let err = |why: String| Error::Recording {
        path: path.display().to_string(),
        why,
    };
    if !geometry.is_rounds() {
        return Err(err(
            "a run bag holds rounds (`tandem simulate --bag`): replay it with the rounds plan \
             of its state file (without --cell continuous)"
                .into(),
        ));
    }
    let file = tandem_bag::bag_file(path).map_err(|e| err(e.to_string()))?;
    let rounds = read_run(&file, geometry.n_robots()).map_err(|e| Error::Recording {
        path: file.display().to_string(),
        why: format!("cannot replay this run bag: {e}"),
    })?;
    Ok(recording_from_rounds(&file, geometry, schedule, &rounds))
}

/// The [`Recording`] of the rounds `rounds` read from `path` against `geometry` (see the
/// module docs): one recorded tick per control tick of every round, rounds one after the other
/// on one clock, no pre-alert.
#[must_use]
pub fn recording_from_rounds(
    path: &Path,
    geometry: &Geometry,
    schedule: Option<&str>,
    rounds: &[RunRoundLog],
) -> Recording {
    let tick_s = rounds.first().map_or(0.01, |r| r.dt_s);
    let mut ticks = Vec::with_capacity(rounds.iter().map(|r| r.ticks).sum());
    let mut t_s = 0.0f64;
    for (done, round) in rounds.iter().enumerate() {
        for k in 0..round.ticks {
            let robots: Vec<RecordedRobot> = round
                .robots
                .iter()
                .map(|r| {
                    // The first sample logged at or after tick `k` (samples are stamped at
                    // the ticks they ran in: none while the robot stood at a hold).
                    let j = r.sample_ticks.partition_point(|&t| t < k);
                    let (state, ref_time, tasks) = if k < r.start_tick {
                        (RobotState::Wait, 0.0, 0)
                    } else if j >= r.ref_time.len() {
                        (
                            RobotState::Done,
                            r.ref_time.last().copied().unwrap_or(0.0),
                            1,
                        )
                    } else if r.sample_ticks[j] != k {
                        // Between two samples: it stood (a hold point, or held) where its
                        // next sample starts.
                        (RobotState::Hold, r.ref_time[j], 0)
                    } else {
                        let state = if r.supervised[j] {
                            RobotState::Lc
                        } else if r.ref_time.get(j + 1).is_some_and(|&n| n <= r.ref_time[j]) {
                            RobotState::Hold
                        } else {
                            RobotState::Hc
                        };
                        (state, r.ref_time[j], 0)
                    };
                    RecordedRobot {
                        state,
                        clock_s: r.clock_s.get(k).copied().unwrap_or(0.0),
                        ref_time,
                        tasks,
                    }
                })
                .collect();
            let coordinator_lc = robots
                .iter()
                .position(|r| r.state == RobotState::Lc)
                .map(|i| i + 1);
            ticks.push(RecordedTick {
                t_s,
                tick: k as u64,
                rounds_done: done as u64,
                fault: false,
                robots,
                coordinator_lc,
                next: None,
            });
            t_s += round.dt_s;
        }
    }
    Recording {
        path: path.to_path_buf(),
        geometry: geometry.clone(),
        tick_s,
        schedule: schedule.map(str::to_string),
        ticks,
        problem: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::build_frame;
    use tandem_bag::RunRobotLog;
    use tandem_planner::AnyController;
    use tandem_realtime::{Coordinator, Timeline};

    /// Two robots 4 s apart on a 10 s task (Δt_s = 0.1 s), low-confidence on samples 40..60.
    fn geometry() -> Geometry {
        let conf: Vec<bool> = (0..100).map(|k| !(40..60).contains(&k)).collect();
        let (g, lo, hi) = (vec![1.0; 100], vec![0.5; 100], vec![2.0; 100]);
        let robots: Vec<Timeline> = (0..2)
            .map(|i| Timeline::new(&conf, &g, &lo, &hi, 4.0 * i as f64, 0.1).unwrap())
            .collect();
        Geometry::new(&AnyController::Rounds(
            Coordinator::new(robots, 0.1).unwrap(),
        ))
    }

    /// Robot 1 runs ticks 0..6 (supervised in 1..3, held at tick 4: its reference time does
    /// not advance from tick 4 to 5), robot 2 waits two ticks, runs 2..4, stands at a hold in
    /// tick 4 (no sample logged: the next is stamped at tick 5) and runs 5..8 (supervised in
    /// 5..7); a round of 8 ticks.
    #[test]
    fn each_tick_shows_the_logged_states_and_the_logged_supervised_robot() {
        let round = RunRoundLog {
            round: 1,
            ticks: 8,
            dt_s: 0.1,
            t_total_s: 0.8,
            robots: vec![
                RunRobotLog {
                    start_tick: 0,
                    sample_ticks: (0..6).collect(),
                    ref_time: vec![0.0, 1.0, 2.0, 3.0, 4.0, 4.0],
                    supervised: vec![false, true, true, false, false, false],
                    clock_s: (0..8).map(|k| 0.1 * f64::from(k)).collect(),
                },
                RunRobotLog {
                    start_tick: 2,
                    sample_ticks: vec![2, 3, 5, 6, 7],
                    ref_time: vec![0.0, 1.0, 2.0, 3.0, 4.0],
                    supervised: vec![false, false, true, true, false],
                    clock_s: vec![0.0; 8],
                },
            ],
        };
        let g = geometry();
        let rec = recording_from_rounds(Path::new("r.mcap"), &g, None, &[round.clone(), round]);
        assert_eq!(rec.ticks.len(), 16);
        use RobotState::{Done, Hc, Hold, Lc, Wait};
        let want = [
            (Hc, Wait),
            (Lc, Wait),
            (Lc, Hc),
            (Hc, Hc),
            (Hold, Hold),
            (Hc, Lc),
            (Done, Lc),
            (Done, Hc),
        ];
        for (k, t) in rec.ticks.iter().enumerate() {
            let (a, b) = want[k % 8];
            assert_eq!((t.robots[0].state, t.robots[1].state), (a, b), "tick {k}");
            let lc = [a, b].iter().position(|s| *s == Lc).map(|i| i + 1);
            assert_eq!(t.coordinator_lc, lc, "tick {k}");
            assert_eq!(t.rounds_done, (k / 8) as u64);
            assert_eq!(t.tick, (k % 8) as u64);
            assert!((t.t_s - 0.1 * k as f64).abs() < 1e-9);
            assert_eq!(t.next, None);
            // The page's frame shows the same `lc` robot, and its banner names it.
            let f = build_frame(&g, &t.raw(rec.tick_s));
            let page: Vec<usize> = f
                .robots
                .iter()
                .filter(|r| r.state == Lc)
                .map(|r| r.robot)
                .collect();
            assert_eq!(page.first().copied(), lc, "tick {k}");
            assert_eq!(f.attention.map(|a| a.robot), lc, "tick {k}");
        }
        assert!((rec.ticks[3].robots[0].clock_s - 0.3).abs() < 1e-12);
        assert_eq!(rec.ticks[6].robots[0].ref_time, 4.0);
        assert_eq!(rec.ticks[6].robots[0].tasks, 1);
        // At the hold, robot 2 stands where its next sample starts.
        assert_eq!(rec.ticks[4].robots[1].ref_time, 2.0);
        assert_eq!(rec.ticks[7].robots[1].ref_time, 4.0);
        let c = crate::check_recording(&rec, 7.0);
        assert_eq!((c.frames, c.two_lc, c.lc_differs), (16, 0, 0));
        // Robot 1 at ticks 1 and 9, robot 2 at ticks 5 and 13.
        assert_eq!(c.stretches, 4);
    }

    #[test]
    fn a_continuous_plan_is_refused_naming_the_fix() {
        let e = read_run_bag("r.mcap", &Geometry::empty(false), None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("without --cell continuous"), "{e}");
    }
}
