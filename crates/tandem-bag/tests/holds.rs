//! A run with hold points written as a bag: each robot's samples are stamped at the ticks it
//! ran in (not at its start tick plus their count), so a robot that stood at a hold is not
//! logged early and the bag never shows two robots supervised in one tick where the
//! simulation had none (issue 42: a replay of such a bag showed 6 frames with two `lc`
//! robots while the simulation counted 0 overlapping ticks).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tandem_bag::{ExecutionOptions, Existing, RunWriter, read_executions, read_run};
use tandem_lfd::{Demonstration, HoldSpec};
use tandem_planner::{Planner, PlannerParams};
use tandem_schedule::SamplerParams;
use tandem_sim::workcell::{OperatorParams, TickPhase, run_round_with};

/// Reference period of the demonstrations, s.
const DT_S: f64 = 0.05;
/// Samples per demonstration (6 s).
const N: usize = 120;

/// A pick-and-place (as tandem-planner's tests/holds.rs): approach, grasp (contact, varies),
/// carry with the gripper closed (trusted: the hold points), place (contact, varies), retreat.
fn demo(i: usize) -> Demonstration {
    let grasp_n = [5.0, 8.0, 11.0, 14.0][i];
    let place_n = [12.0, 6.0, 9.0, 3.0][i];
    let mut samples = Vec::with_capacity(4 * N);
    for k in 0..N {
        let t = k as f64 * DT_S;
        let down = |s: f64| 0.2 * (1.0 - (std::f64::consts::PI * s.clamp(0.0, 1.0)).sin());
        let row = if t < 0.5 {
            [0.3 * t / 0.5, down(t), 0.0, 0.0]
        } else if t < 1.5 {
            [0.3, 0.0, grasp_n, if t < 1.0 { 0.0 } else { 1.0 }]
        } else if t < 4.0 {
            let s = (t - 1.5) / 2.5;
            [0.3 + 0.5 * s, down(0.5 + 0.5 * s), 0.0, 1.0]
        } else if t < 5.0 {
            [0.8, 0.0, place_n, if t < 4.5 { 1.0 } else { 0.0 }]
        } else {
            [0.8, down(0.5 * (t - 5.0)), 0.0, 0.0]
        };
        samples.extend(row);
    }
    let names = ["x", "z", "force", "gripper"].map(String::from).to_vec();
    Demonstration::new(names, samples, DT_S).unwrap()
}

#[test]
fn samples_after_a_hold_are_stamped_at_the_ticks_they_ran() {
    let demos: Vec<Demonstration> = (0..4).map(demo).collect();
    let params = PlannerParams {
        sampler: SamplerParams {
            samples: 300,
            ..SamplerParams::default()
        },
        holds: HoldSpec {
            at_s: Vec::new(),
            rules: vec!["gripper>0.5".parse().unwrap()],
        },
        ..PlannerParams::default()
    };
    let planner = Planner::with_robots(&demos, params, 3).unwrap();
    assert!(planner.schedule().has_holds(), "the plan uses its holds");
    let dir = std::env::temp_dir().join(format!("tandem-bag-holds-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("run.mcap");
    let mut writer = RunWriter::create(&path, &planner, Existing::Refuse).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let needs = |_: usize, n: usize| (20..30).contains(&n);
    let run = run_round_with(&planner, needs, &OperatorParams::default(), &mut rng).unwrap();
    writer.write_round(&planner, &run).unwrap();
    writer.finish().unwrap();
    assert_eq!(
        run.overlap_ticks, 0,
        "the simulation never had two robots supervised"
    );
    assert!(
        run.robots.iter().any(|r| r.hold_ticks > 0),
        "some robot stood at a hold (else the stamps could not go wrong)"
    );

    let rounds = read_run(&path, 3).unwrap();
    assert_eq!(rounds.len(), 1);
    let r = &rounds[0];
    assert_eq!(r.ticks, run.ticks);
    // Each sample at the tick it ran in: the robot's running ticks, holds skipped.
    let mut supervised_at = vec![0usize; run.ticks];
    let mut early = vec![0usize; run.ticks];
    for (i, (got, sim)) in r.robots.iter().zip(&run.robots).enumerate() {
        let ran: Vec<usize> = (0..run.ticks)
            .filter(|&k| sim.phases[k] == TickPhase::Running)
            .collect();
        assert_eq!(got.sample_ticks, ran, "robot {}", i + 1);
        assert_eq!(got.start_tick, sim.start_tick, "robot {}", i + 1);
        assert_eq!(got.ref_time, sim.ref_time_log, "robot {}", i + 1);
        assert_eq!(got.supervised, sim.supervised, "robot {}", i + 1);
        for (j, &s) in got.supervised.iter().enumerate() {
            if s {
                supervised_at[got.sample_ticks[j]] += 1;
                // Where the former stamps (start tick + k) put it.
                early[got.start_tick + j] += 1;
            }
        }
    }
    assert_eq!(
        supervised_at.iter().filter(|&&c| c > 1).count(),
        0,
        "ticks of the bag with two robots supervised"
    );
    // The former stamps put supervised samples of a robot that stood at a hold on another
    // robot's stretch (9 ticks here): the test can see the fault it guards against.
    let before = early.iter().filter(|&&c| c > 1).count();
    assert!(before > 0, "the former stamps were wrong on this run");

    // The executions read back across the gaps, sample for sample.
    let options = ExecutionOptions {
        dt_s: planner.model().dt_s(),
        robots: vec![1, 2, 3],
        round: Some(1),
        topics: None,
    };
    let read = read_executions(&path, &options).unwrap();
    let records = run.records(planner.model()).unwrap();
    assert_eq!(read.len(), 3);
    for (i, (a, b)) in read.iter().zip(&records).enumerate() {
        let what = format!("robot {}", i + 1);
        assert_eq!(
            a.execution.demonstration.n_samples(),
            b.execution.demonstration.n_samples(),
            "{what}"
        );
        assert_eq!(a.execution.ref_time_log, b.execution.ref_time_log, "{what}");
        assert_eq!(a.supervised, b.supervised, "{what}");
        assert_eq!(a.corrected, b.corrected, "{what}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
