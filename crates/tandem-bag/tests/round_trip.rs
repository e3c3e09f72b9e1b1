//! A simulated run written as a bag reads back, round by round and robot by robot, to the
//! very executions the simulation recorded (bit for bit), for 1, 2 and 3 robots; and the
//! bag holds every topic with the expected message counts.

use std::path::PathBuf;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tandem_bag::{
    BagOptions, ExecutionOptions, Existing, MsgType, Role, RunWriter, SCHEDULE_TOPIC, count_rounds,
    inspect, read_bag, read_executions,
};
use tandem_lfd::Demonstration;
use tandem_planner::{ExecutionRecord, Planner, PlannerParams};
use tandem_schedule::SamplerParams;
use tandem_sim::workcell::{OperatorParams, run_round_with};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tandem-bag-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Three demonstrations of a 60-sample task with a pose (moving along x, turning about z),
/// a force and a tool flag; they differ in force and speed over samples 20..40.
fn demos() -> Vec<Demonstration> {
    let names: Vec<String> = ["x", "y", "z", "qx", "qy", "qz", "qw", "force", "tool"]
        .map(String::from)
        .to_vec();
    [2.0, 5.0, 8.0]
        .iter()
        .enumerate()
        .map(|(d, &press)| {
            let mut v = Vec::new();
            let n = 60 + 5 * d;
            for t in 0..n {
                let s = t as f64 / (n - 1) as f64;
                let angle = 0.3 * s + 0.02 * d as f64;
                let (sin, cos) = (angle / 2.0).sin_cos();
                let middle = (0.33..0.66).contains(&s);
                v.extend_from_slice(&[
                    0.6 * s,
                    0.1 + 0.001 * d as f64,
                    0.0,
                    0.0,
                    0.0,
                    sin,
                    cos,
                    if middle { press } else { 1.0 },
                    f64::from(u8::from(middle)),
                ]);
            }
            Demonstration::new(names.clone(), v, 0.01).unwrap()
        })
        .collect()
}

fn planner(robots: usize) -> Planner {
    let params = PlannerParams {
        sampler: SamplerParams {
            samples: 100,
            seed: 5,
            ..SamplerParams::default()
        },
        ..PlannerParams::default()
    };
    Planner::with_robots(&demos(), params, robots).unwrap()
}

/// Runs `rounds` rounds of `robots` robots into a bag; returns the bag and every round's
/// records as the simulation made them.
fn simulate(robots: usize, rounds: usize, path: &std::path::Path) -> Vec<Vec<ExecutionRecord>> {
    let mut planner = planner(robots);
    let mut writer = RunWriter::create(path, &planner, Existing::Refuse).unwrap();
    let mut all = Vec::new();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for _ in 0..rounds {
        let needs = |robot: usize, n: usize| robot == 0 && (20..40).contains(&n);
        let run = run_round_with(&planner, needs, &OperatorParams::default(), &mut rng).unwrap();
        writer.write_round(&planner, &run).unwrap();
        let records = run.records(planner.model()).unwrap();
        planner.record_round(&records).unwrap();
        all.push(records);
    }
    writer.finish().unwrap();
    all
}

fn assert_same(read: &ExecutionRecord, sim: &ExecutionRecord, what: &str) {
    let (a, b) = (&read.execution.demonstration, &sim.execution.demonstration);
    assert_eq!(a.channel_names(), b.channel_names(), "{what}");
    assert_eq!(a.dt_s().to_bits(), b.dt_s().to_bits(), "{what}");
    assert_eq!(a.n_samples(), b.n_samples(), "{what}");
    // The binary channel `tool` goes out as a `std_msgs/Bool`, true where the command is at
    // least 0.5 (as a valve is driven); every other value bit for bit.
    let tool = b.channel_index("tool").expect("a tool channel");
    let m = b.n_channels();
    for (k, (x, y)) in a.samples().iter().zip(b.samples()).enumerate() {
        let y = if k % m == tool {
            f64::from(u8::from(*y >= 0.5))
        } else {
            *y
        };
        assert_eq!(x.to_bits(), y.to_bits(), "{what}: value {k}: {x} vs {y}");
    }
    assert_eq!(
        read.execution.ref_time_log, sim.execution.ref_time_log,
        "{what}"
    );
    assert_eq!(read.supervised, sim.supervised, "{what}");
    assert_eq!(read.corrected, sim.corrected, "{what}");
}

#[test]
fn a_run_reads_back_to_the_same_executions_for_one_two_and_three_robots() {
    let dir = scratch("round-trip");
    for robots in 1..=3 {
        let path = dir.join(format!("run{robots}.mcap"));
        let rounds = 3;
        let sim = simulate(robots, rounds, &path);
        assert_eq!(count_rounds(&path).unwrap(), rounds);
        let dt_s = planner(robots).model().dt_s();
        for (k, sim_round) in sim.iter().enumerate() {
            let options = ExecutionOptions {
                dt_s,
                robots: (1..=robots).collect(),
                round: Some(k + 1),
                topics: None,
            };
            let read = read_executions(&path, &options).unwrap();
            assert_eq!(read.len(), robots);
            for (i, (r, s)) in read.iter().zip(sim_round).enumerate() {
                assert_same(
                    r,
                    s,
                    &format!("{robots} robots, round {}, robot {}", k + 1, i + 1),
                );
            }
            // One robot at a time gives the same.
            for i in 1..=robots {
                let one = ExecutionOptions {
                    robots: vec![i],
                    ..options.clone()
                };
                let r = read_executions(&path, &one).unwrap();
                assert_same(&r[0], &sim_round[i - 1], "one robot");
            }
        }
        // Every topic with its message count: samples per robot for the channel, log and
        // flag topics; every tick for the clock and the waiting flag; one schedule per round.
        let topics = inspect(&path).unwrap();
        let count = |name: &str| {
            topics
                .iter()
                .find(|t| t.topic == name)
                .unwrap_or_else(|| panic!("no topic {name}"))
                .messages
        };
        assert_eq!(count(SCHEDULE_TOPIC), rounds);
        for i in 1..=robots {
            let samples: usize = sim
                .iter()
                .map(|r| r[i - 1].execution.ref_time_log.len())
                .sum();
            for t in [
                "tool_pose",
                "force",
                "tool",
                "ref_sample",
                "supervised",
                "corrected",
            ] {
                assert_eq!(count(&format!("/robot_{i}/{t}")), samples, "robot {i} {t}");
            }
            let clock = count(&format!("/robot_{i}/schedule_clock"));
            assert_eq!(count(&format!("/robot_{i}/waiting")), clock);
            assert!(clock >= samples);
        }
        let n_topics = robots * 8 + 1;
        assert_eq!(topics.len(), n_topics, "{topics:#?}");
        let pose = topics
            .iter()
            .find(|t| t.topic == "/robot_1/tool_pose")
            .unwrap();
        assert_eq!(pose.msg_type, Some(MsgType::PoseStamped));
        assert_eq!(pose.channels, ["x", "y", "z", "qx", "qy", "qz", "qw"]);
        // A binary channel is a Bool topic, a scalar one a Float64.
        let ty = |name: &str| topics.iter().find(|t| t.topic == name).unwrap().msg_type;
        assert_eq!(ty("/robot_1/tool"), Some(MsgType::Bool));
        assert_eq!(ty("/robot_1/force"), Some(MsgType::Float64));
        assert!(
            topics
                .iter()
                .filter(|t| t.topic.ends_with("schedule_clock") || t.topic.ends_with("waiting"))
                .all(|t| t.role == Role::View)
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_round_must_be_chosen_and_exist_and_robot_1_reads_as_a_demonstration() {
    let dir = scratch("rounds");
    let path = dir.join("run.mcap");
    simulate(2, 2, &path);
    let dt_s = 0.01;
    let options = |round| ExecutionOptions {
        dt_s,
        robots: vec![1, 2],
        round,
        topics: None,
    };
    let e = read_executions(&path, &options(None))
        .unwrap_err()
        .to_string();
    assert!(e.contains("holds 2 rounds") && e.contains("--round"), "{e}");
    let e = read_executions(&path, &options(Some(3)))
        .unwrap_err()
        .to_string();
    assert!(e.contains("round 3 requested, but the bag holds 2"), "{e}");
    // A robot's data topics of the whole run read as one recording:
    let topics: Vec<String> = ["tool_pose", "force", "tool"]
        .iter()
        .map(|t| format!("/robot_1/{t}"))
        .collect();
    let e = read_bag(
        &path,
        &BagOptions {
            topics: Some(topics),
            namespace: Some("/robot_1".into()),
            ..BagOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    // Robot 1 idles while robot 2 finishes a round: a gap, refused rather than interpolated.
    assert!(e.contains("a gap of"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_existing_file_is_never_overwritten_and_a_failed_write_leaves_nothing() {
    let dir = scratch("no-overwrite");
    let path = dir.join("run.mcap");
    std::fs::write(&path, "precious").unwrap();
    let e = RunWriter::create(&path, &planner(2), Existing::Refuse).unwrap_err();
    assert!(e.to_string().contains("does not overwrite"), "{e}");
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "precious");
    // A writer dropped before `finish` (an error on the way) leaves no file and no temporary.
    let other = dir.join("other.mcap");
    let w = RunWriter::create(&other, &planner(2), Existing::Refuse).unwrap();
    drop(w);
    let names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["run.mcap"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `read_run` gives back, tick by tick, what the workcell ran: every robot's start tick,
/// reference-time log and supervised flags bit for bit, its schedule clock at every tick of
/// the round, and each round's tick count and `T_total` (the console's replay of a run bag
/// rests on it). A truncated bag is an error naming it, and so is a robot count the bag does
/// not hold.
#[test]
fn a_run_reads_back_tick_by_tick() {
    let dir = scratch("run-ticks");
    let path = dir.join("run.mcap");
    let mut planner = planner(2);
    let mut writer = RunWriter::create(&path, &planner, Existing::Refuse).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut runs = Vec::new();
    for _ in 0..2 {
        let needs = |robot: usize, n: usize| robot == 1 && (25..35).contains(&n);
        let run = run_round_with(&planner, needs, &OperatorParams::default(), &mut rng).unwrap();
        writer.write_round(&planner, &run).unwrap();
        let t_total = planner.outcome().t_total_s;
        planner
            .record_round(&run.records(planner.model()).unwrap())
            .unwrap();
        runs.push((run, t_total));
    }
    writer.finish().unwrap();
    let rounds = tandem_bag::read_run(&path, 2).unwrap();
    assert_eq!(rounds.len(), 2);
    for (k, (r, (run, t_total))) in rounds.iter().zip(&runs).enumerate() {
        assert_eq!(r.round, k + 1);
        assert_eq!(r.ticks, run.ticks);
        assert_eq!(r.t_total_s.to_bits(), t_total.to_bits());
        assert_eq!(r.robots.len(), 2);
        for (got, sim) in r.robots.iter().zip(&run.robots) {
            assert_eq!(got.start_tick, sim.start_tick, "round {}", k + 1);
            assert_eq!(got.ref_time, sim.ref_time_log, "round {}", k + 1);
            assert_eq!(got.supervised, sim.supervised, "round {}", k + 1);
            assert_eq!(got.clock_s, sim.clock_s, "round {}", k + 1);
        }
    }
    // Someone was supervised, and robot 2 started later than robot 1 in some round: the
    // comparison above is not between empty or aligned logs.
    assert!(
        runs.iter()
            .any(|(r, _)| r.robots.iter().any(|x| x.supervised.contains(&true)))
    );
    assert!(runs.iter().any(|(r, _)| r.robots[1].start_tick > 0));

    let e = tandem_bag::read_run(&path, 3).unwrap_err().to_string();
    assert!(e.contains("/robot_3/"), "{e}");
    let bytes = std::fs::read(&path).unwrap();
    let cut = dir.join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let e = tandem_bag::read_run(&cut, 2).unwrap_err();
    assert!(
        matches!(
            e,
            tandem_bag::Error::Truncated { .. } | tandem_bag::Error::Corrupt { .. }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("cut.mcap"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}
