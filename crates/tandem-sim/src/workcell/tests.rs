//! Tests of the workcell on a hand-made one-channel task (low confidence exactly where the
//! demonstrations differ).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tandem_lfd::{Demonstration, FitParams, TaskModel};
use tandem_planner::Planner;
use tandem_schedule::{Problem, Schedule};

use super::run::{run_coordinator, run_schedule};
use super::*;
use crate::Error;
use crate::task::{Label, N_PASSES, Phase, Workpiece};

const N_REF: usize = 60;

/// Three demonstrations of a one-channel "force" task aligned by known warps: demo 0
/// (the reference) and demo 2 press lightly (1 N) everywhere; demo 1 presses hard (9 N)
/// over reference samples 10..20 and takes two samples per reference sample there.
/// So samples 10..20 vary (low confidence), force rising with the warp gradient.
fn model() -> TaskModel {
    let names = vec!["force".to_string()];
    let light = Demonstration::new(names.clone(), vec![1.0; N_REF], 0.01).unwrap();
    let mut hard = Vec::new();
    let mut warp1 = Vec::new();
    for n in 0..N_REF {
        warp1.push(hard.len() as f64);
        let reps = if (10..20).contains(&n) { 2 } else { 1 };
        for _ in 0..reps {
            hard.push(if (10..20).contains(&n) { 9.0 } else { 1.0 });
        }
    }
    let hard = Demonstration::new(names, hard, 0.01).unwrap();
    let identity: Vec<f64> = (0..N_REF).map(|n| n as f64).collect();
    TaskModel::fit_aligned(
        &[light.clone(), hard, light],
        &[identity.clone(), warp1, identity],
        &FitParams::default(),
    )
    .unwrap()
}

fn problem(model: &TaskModel) -> Problem {
    let conf = (0..N_REF).map(|n| !(10..20).contains(&n)).collect();
    let (gmin, gmax) = (model.grad_min().to_vec(), model.grad_max().to_vec());
    let gmean = model
        .grad_mean()
        .iter()
        .zip(gmin.iter().zip(&gmax))
        .map(|(g, (lo, hi))| g.clamp(*lo, *hi))
        .collect();
    Problem::new(conf, gmean, gmin, gmax, model.dt_s()).unwrap()
}

fn painted_labels() -> Vec<Label> {
    vec![
        Label {
            pass: 1,
            section: 0,
            painted: true,
            phase: Phase::Sanding,
        };
        N_REF
    ]
}

fn all_painted() -> Workpiece {
    Workpiece {
        painted: vec![vec![true; 8]; N_PASSES],
    }
}

/// An operator who never misses a needed correction and never gives an unneeded one.
fn perfect() -> OperatorParams {
    OperatorParams {
        miss_rate: 0.0,
        false_correction_rate: 0.0,
        ..OperatorParams::default()
    }
}

/// Whether robot `robot` needs the operator at reference sample `ref_idx` on the
/// painted labels and workpieces ([`run_round`]'s rule).
fn painted_needs(robot: usize, ref_idx: usize) -> bool {
    needs_correction(
        &painted_labels()[ref_idx],
        &[all_painted(), all_painted()][robot],
    )
}

/// The serial schedule of the hand-made problem, run with `params`: the round and its
/// planned `T_total` (s).
fn run(params: &OperatorParams, seed: u64) -> (RoundRun, f64) {
    let model = model();
    let problem = problem(&model);
    let schedule = problem.serial_schedule(problem.dt_s()).unwrap();
    let planned_s = schedule.t_total_s(problem.dt_s());
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let run = run_schedule(&model, &problem, &schedule, painted_needs, params, &mut rng).unwrap();
    (run, planned_s)
}

/// A planner on the hand-made model: low confidence exactly where the demonstrations
/// differ (samples 10..20), a sampled schedule at the workcell's tick.
fn planner() -> Planner {
    let params = tandem_planner::PlannerParams {
        sampler: tandem_schedule::SamplerParams {
            samples: 50,
            seed: 3,
            ..Default::default()
        },
        ..Default::default()
    };
    Planner::from_model(model(), params).unwrap()
}

#[test]
fn only_painted_sanding_of_passes_one_to_three_needs_a_correction() {
    let mut wp = all_painted();
    wp.painted[1][3] = false;
    let label = |pass, section, phase| Label {
        pass,
        section,
        painted: true,
        phase,
    };
    assert!(needs_correction(&label(1, 0, Phase::Sanding), &wp));
    assert!(needs_correction(&label(3, 7, Phase::Sanding), &wp));
    assert!(
        !needs_correction(&label(2, 3, Phase::Sanding), &wp),
        "unpainted"
    );
    assert!(
        !needs_correction(&label(4, 0, Phase::Sanding), &wp),
        "pass 4"
    );
    assert!(!needs_correction(&label(1, 0, Phase::Transition), &wp));
}

#[test]
fn bad_rates_are_rejected() {
    let p = OperatorParams {
        miss_rate: 1.5,
        ..OperatorParams::default()
    };
    assert!(matches!(
        p.validate(),
        Err(Error::BadParam {
            name: "miss_rate",
            ..
        })
    ));
}

#[test]
fn a_perfect_operator_corrects_every_needed_sample_and_slows_the_robots() {
    let perfect = perfect();
    let (run, planned_s) = run(&perfect, 1);
    assert_eq!(run.overlap_ticks, 0);
    let model = model();
    for r in &run.robots {
        let n = r.ref_time_log.len();
        assert_eq!(r.samples.len(), n);
        assert!(r.ref_time_log.windows(2).all(|w| w[0] <= w[1]));
        assert!(
            r.ref_time_log
                .iter()
                .all(|t| (0.0..=(N_REF - 1) as f64).contains(t))
        );
        assert_eq!(r.missed + r.false_corrections, 0);
        for k in 0..n {
            let t = r.ref_time_log[k];
            assert_eq!(r.supervised[k], (10..20).contains(&(t as usize)), "t = {t}");
            assert_eq!(r.corrected[k], r.supervised[k]);
            // A correction presses harder than the mean. By hand, inside 10..19: one
            // component c = 2·(8, 1)/√2 (±3σ of the normalised residuals, ranges 8 N
            // and 1), admissible scale (4/3 − 1)/√2, u = 1/3: δforce = 8/9 N.
            let mean = model.command(&[0.0, 0.0], t).unwrap()[0];
            if r.corrected[k] {
                if (10.0..=19.0).contains(&t) {
                    assert!((r.samples[k] - mean - 8.0 / 9.0).abs() < 1e-9, "t = {t}");
                }
                assert!(r.samples[k] > mean + 0.1, "{} vs {mean}", r.samples[k]);
            } else {
                assert!((r.samples[k] - mean).abs() < 1e-9);
            }
        }
        assert_eq!(r.needed, r.supervised.iter().filter(|s| **s).count());
    }
    // Slower than planned: the corrected gradient is 4/3 + 1/9 instead of 4/3 on the 10
    // low-confidence samples, 10/9 samples (11 ms) more per robot, 22 ms in series.
    assert!(
        run.duration_s() > planned_s + 0.01,
        "{} vs {planned_s}",
        run.duration_s()
    );
    // The operator is idle while both robots are high-confidence.
    assert!(run.idle_ticks > 0 && run.operator_idle_share() < 1.0);
}

#[test]
fn without_corrections_the_round_runs_on_schedule() {
    let never = OperatorParams {
        miss_rate: 1.0,
        false_correction_rate: 0.0,
        ..OperatorParams::default()
    };
    let (run, planned_s) = run(&never, 2);
    assert_eq!(run.overlap_ticks, 0);
    assert!(run.robots.iter().all(|r| r.corrected.iter().all(|c| !c)));
    assert!(
        run.robots
            .iter()
            .all(|r| r.missed == r.needed && r.needed > 0)
    );
    assert!(
        (run.duration_s() - planned_s).abs() <= 2.0 * run.tick_s,
        "{} vs {planned_s}",
        run.duration_s()
    );
}

#[test]
fn a_round_of_three_robots_runs_each_once_and_busies_the_operator_for_each() {
    let model = model();
    let problem = problem(&model);
    let schedule = problem.serial_schedule_n(3, problem.dt_s()).unwrap();
    let perfect = perfect();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let run = run_schedule(
        &model,
        &problem,
        &schedule,
        painted_needs_n,
        &perfect,
        &mut rng,
    )
    .unwrap();
    assert_eq!(run.robots.len(), 3);
    assert_eq!(run.overlap_ticks, 0);
    for r in &run.robots {
        assert!(r.needed > 0 && r.corrected == r.supervised);
    }
    // Serial: the operator is busy exactly while one robot is supervised, so the busy
    // ticks are the three robots' supervised ticks, up to one tick at each end of each
    // robot's one low-confidence stretch (a tick that enters or leaves it is busy).
    let supervised: usize = run
        .robots
        .iter()
        .map(|r| r.supervised.iter().filter(|s| **s).count())
        .sum();
    let busy = run.ticks - run.idle_ticks;
    assert!(busy.abs_diff(supervised) <= 6, "{busy} vs {supervised}");
    assert!(
        (run.operator_busy_share() - busy as f64 / run.ticks as f64).abs() < 1e-15
            && (run.operator_busy_share() + run.operator_idle_share() - 1.0).abs() < 1e-15
    );
    assert_eq!(run.records(&model).unwrap().len(), 3);
}

#[test]
fn every_robot_logs_its_clock_every_tick_and_runs_from_its_start_tick() {
    let model = model();
    let problem = problem(&model);
    let schedule = problem.serial_schedule_n(3, problem.dt_s()).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let params = OperatorParams::default();
    let run = run_schedule(
        &model,
        &problem,
        &schedule,
        painted_needs_n,
        &params,
        &mut rng,
    )
    .unwrap();
    let starts: Vec<f64> = std::iter::once(0.0)
        .chain(schedule.offsets_s.iter().copied())
        .collect();
    for (i, r) in run.robots.iter().enumerate() {
        assert_eq!(r.clock_s.len(), run.ticks, "robot {i}: one clock per tick");
        assert!(r.clock_s.windows(2).all(|w| w[0] <= w[1]), "robot {i}");
        let n = r.ref_time_log.len();
        assert!(n > 0 && r.start_tick + n <= run.ticks, "robot {i}");
        // Waiting before its start tick (clock short of its start τ_i), running from it.
        let tau = starts[i];
        assert!(
            r.clock_s[..r.start_tick].iter().all(|&c| c < tau),
            "robot {i}"
        );
        assert!(r.clock_s[r.start_tick] >= tau, "robot {i}");
    }
    assert_eq!(run.robots[0].start_tick, 0);
    // Serial: each robot starts once the one before it has finished.
    for w in run.robots.windows(2) {
        assert!(w[1].start_tick >= w[0].start_tick + w[0].ref_time_log.len());
    }
    // So the round lasts at least the three robots' running ticks, and each robot waits
    // for the other two: at least 2/3 of the robots' time is waiting.
    let moving: usize = run.robots.iter().map(|r| r.ref_time_log.len()).sum();
    assert!(run.ticks >= moving);
    let wait = run.robot_wait_share();
    assert!((wait - (1.0 - moving as f64 / (3 * run.ticks) as f64)).abs() < 1e-15);
    assert!((2.0 / 3.0 - 1e-15..1.0).contains(&wait), "{wait}");
}

/// [`painted_needs`] for any robot index (every workpiece painted).
fn painted_needs_n(_robot: usize, ref_idx: usize) -> bool {
    needs_correction(&painted_labels()[ref_idx], &all_painted())
}

#[test]
fn run_round_reads_everything_from_the_planner() {
    let planner = planner();
    let conf = planner.confidence().conf();
    assert!(
        (0..N_REF).all(|n| conf[n] != (10..20).contains(&n)),
        "{conf:?}"
    );
    let p = OperatorParams::default();
    let (labels, wp) = (painted_labels(), [all_painted(), all_painted()]);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let by_labels = run_round(&planner, &labels, &wp, &p, &mut rng).unwrap();
    assert_eq!(by_labels.overlap_ticks, 0);
    assert_eq!(by_labels.tick_s, planner.schedule().tick_s);
    // The same as the caller's rule, and as the planner's parts run by hand.
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let by_rule = run_round_with(&planner, painted_needs, &p, &mut rng).unwrap();
    assert_eq!(by_rule, by_labels);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let by_parts = run_schedule(
        planner.model(),
        planner.problem(),
        planner.schedule(),
        painted_needs,
        &p,
        &mut rng,
    )
    .unwrap();
    assert_eq!(by_parts, by_labels);
    // Its records are what the planner takes (Eq. 21): one per robot, flags per sample.
    let records = by_labels.records(planner.model()).unwrap();
    for (record, robot) in records.iter().zip(&by_labels.robots) {
        assert_eq!(record.execution.ref_time_log, robot.ref_time_log);
        assert_eq!(record.execution.demonstration.samples(), &robot.samples[..]);
        assert_eq!(record.supervised, robot.supervised);
        assert_eq!(record.corrected, robot.corrected);
    }
    let mut next = planner.clone();
    next.record_round(&records).unwrap();
    assert_eq!(next.model().count(), planner.model().count() + 2);
}

/// The deprecated two-robot names at the public edge run the very same round.
#[test]
#[expect(
    deprecated,
    reason = "the deprecated public-edge names are what is tested"
)]
fn the_deprecated_pair_names_run_the_same_round() {
    let planner = planner();
    let p = OperatorParams::default();
    let (labels, wp) = (painted_labels(), [all_painted(), all_painted()]);
    let round = run_round(
        &planner,
        &labels,
        &wp,
        &p,
        &mut ChaCha8Rng::seed_from_u64(7),
    )
    .unwrap();
    let pair: PairRun = run_pair(
        &planner,
        &labels,
        &wp,
        &p,
        &mut ChaCha8Rng::seed_from_u64(7),
    )
    .unwrap();
    assert_eq!(pair, round);
    let with = run_pair_with(
        &planner,
        painted_needs,
        &p,
        &mut ChaCha8Rng::seed_from_u64(7),
    )
    .unwrap();
    assert_eq!(with, round);
}

#[test]
fn run_round_with_asks_the_caller_only_about_supervised_samples() {
    let model = model();
    let problem = problem(&model);
    let schedule = problem.serial_schedule(problem.dt_s()).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    // Only robot 1 needs the operator; a perfect operator corrects exactly its
    // supervised samples, and is asked about nothing but low-confidence samples.
    let perfect = perfect();
    let mut asked = Vec::new();
    let run = run_schedule(
        &model,
        &problem,
        &schedule,
        |i, n| {
            asked.push((i, n));
            i == 0
        },
        &perfect,
        &mut rng,
    )
    .unwrap();
    let [r1, r2] = &run.robots[..] else {
        panic!("{} robots", run.robots.len())
    };
    assert!(r1.supervised.iter().any(|s| *s));
    assert_eq!(r1.corrected, r1.supervised);
    assert!(r2.supervised.iter().any(|s| *s));
    assert!(r2.corrected.iter().all(|c| !c));
    assert_eq!(r1.needed, r1.supervised.iter().filter(|s| **s).count());
    assert_eq!(r2.needed, 0);
    let supervised: usize = run
        .robots
        .iter()
        .map(|r| r.supervised.iter().filter(|s| **s).count())
        .sum();
    assert_eq!(asked.len(), supervised);
    assert!(
        asked.iter().all(|&(_, n)| (10..=20).contains(&n)),
        "{asked:?}"
    );
}

#[test]
fn a_schedule_checked_at_another_tick_is_rejected() {
    let mut planner = planner();
    let dt_s = planner.problem().dt_s();
    // Re-scheduled at half the workcell's period: its margins say nothing about 10 ms ticks.
    let half = tandem_schedule::SamplerParams {
        tick_s: Some(dt_s / 2.0),
        ..planner.params().sampler.clone()
    };
    planner.reschedule(&half).unwrap();
    assert_eq!(planner.schedule().tick_s, dt_s / 2.0);
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let p = OperatorParams::default();
    let wp = [all_painted(), all_painted()];
    let err = run_round(&planner, &painted_labels(), &wp, &p, &mut rng).unwrap_err();
    assert!(
        matches!(
            err,
            Error::TickMismatch {
                schedule_tick_s,
                workcell_tick_s,
            } if schedule_tick_s == dt_s / 2.0 && workcell_tick_s == dt_s
        ),
        "{err}"
    );
    let msg = err.to_string();
    assert!(msg.contains("0.005 s") && msg.contains("0.01 s"), "{msg}");
    let err = run_round_with(&planner, |_, _| true, &p, &mut rng);
    assert!(matches!(err, Err(Error::TickMismatch { .. })));
    // Re-scheduled at the workcell's own tick it runs (`tick_s: None` would keep the
    // schedule's half tick: a re-schedule keeps the tick a user chose).
    let own = tandem_schedule::SamplerParams {
        tick_s: Some(dt_s),
        ..half
    };
    planner.reschedule(&own).unwrap();
    assert!(run_round_with(&planner, |_, _| true, &p, &mut rng).is_ok());
}

#[test]
fn same_seed_same_run_and_mismatches_are_errors() {
    let p = OperatorParams::default();
    assert_eq!(run(&p, 7).0, run(&p, 7).0);
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let err = run_round(
        &planner(),
        &painted_labels()[..5],
        &[all_painted(), all_painted()],
        &p,
        &mut rng,
    )
    .unwrap_err();
    assert!(matches!(
        err,
        Error::Mismatch {
            what: "reference labels",
            expected: N_REF,
            found: 5,
        }
    ));
}

#[test]
fn an_unsafe_plan_latches_a_fault_that_the_operator_releases_and_the_round_finishes() {
    let model = model();
    let problem = problem(&model);
    // Both robots start together: both reach the low-confidence samples 10..20 in the same
    // ticks, which the margin check rejects.
    let mut schedule = problem.serial_schedule(problem.dt_s()).unwrap();
    schedule.offsets_s = vec![0.0];
    let perfect = perfect();
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let refused = run_schedule(
        &model,
        &problem,
        &schedule,
        painted_needs,
        &perfect,
        &mut rng,
    );
    assert!(
        matches!(
            refused,
            Err(Error::Schedule(_) | Error::Realtime(tandem_realtime::Error::Unsafe { .. }))
        ),
        "{refused:?}"
    );
    let unchecked = tandem_realtime::Coordinator::new_unchecked(
        schedule.timelines(&problem).unwrap(),
        schedule.tick_s,
    )
    .unwrap();
    let run = run_coordinator(
        &model,
        &problem,
        unchecked,
        painted_needs,
        &perfect,
        &mut rng,
    )
    .unwrap();
    // The first overlap latches the fault and holds robot 2 (its stretch began in the same
    // tick: the higher index on a tie) at once, so there is no second overlap tick; released
    // once robot 1 has left its stretch, robot 2 runs to the end.
    assert_eq!((run.overlap_ticks, run.faults), (1, 1));
    for (i, r) in run.robots.iter().enumerate() {
        let last = *r.ref_time_log.last().unwrap();
        assert!(last > (N_REF - 2) as f64, "robot {i} ended at {last}");
        assert!(r.ref_time_log.windows(2).all(|w| w[0] <= w[1]), "robot {i}");
        assert_eq!(r.clock_s.len(), run.ticks, "robot {i}");
    }
    let [r1, r2] = &run.robots[..] else {
        panic!("{} robots", run.robots.len())
    };
    // Held, robot 2's clock stood still and it logged no sample; it finished last, so it
    // logged a sample in every other tick of the round.
    let held = r2.clock_s.windows(2).filter(|w| w[0] == w[1]).count();
    assert!(held > 0);
    assert_eq!(r2.start_tick, 0);
    assert_eq!(r2.ref_time_log.len() + held, run.ticks);
    assert!(r1.start_tick + r1.ref_time_log.len() < run.ticks);
    assert!(r2.supervised.iter().any(|s| *s));
    // The safe plan of the same problem never faults.
    let on_time = run_schedule(
        &model,
        &problem,
        &problem.serial_schedule(problem.dt_s()).unwrap(),
        painted_needs,
        &perfect,
        &mut ChaCha8Rng::seed_from_u64(9),
    )
    .unwrap();
    assert_eq!((on_time.faults, on_time.overlap_ticks), (0, 0));
}

#[test]
fn a_robot_waits_at_its_hold_while_the_operator_drags_the_other_and_never_overlaps() {
    // The hand-made problem with a hold at sample 5 (before the LC run 10..20). Robot 2
    // starts so that its LC run begins exactly when robot 1's ends on schedule: no margin at
    // all, rejected without holds; with the rule "robot 2 leaves its hold at 5 once robot 1
    // has passed sample 20" it is accepted, and a perfect operator (whose corrections slow
    // the LC robot down) makes robot 2 wait there instead of overlapping.
    let model = model();
    let problem = problem(&model).with_holds(vec![5]).unwrap();
    let dt_s = problem.dt_s();
    let serial = problem.serial_schedule(dt_s).unwrap();
    let clock = |n: usize| tandem_realtime::clock_end_s(&serial.grad_exec[0][..n], 0.0, dt_s);
    let plain = Schedule {
        offsets_s: vec![clock(20) - clock(10)],
        ..serial
    };
    assert!(tandem_schedule::validate(&problem, &plain).is_err());
    let held = problem.with_release_rules(&plain).unwrap();
    assert_eq!(held.holds_of(1)[0].ref_idx, 5);
    tandem_schedule::validate(&problem, &held).unwrap();
    let perfect = perfect();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let run = run_schedule(&model, &problem, &held, painted_needs, &perfect, &mut rng).unwrap();
    assert_eq!(run.overlap_ticks, 0);
    assert_eq!(run.faults, 0);
    assert_eq!(run.robots[0].hold_ticks, 0);
    assert!(run.robots[1].hold_ticks > 0, "{}", run.robots[1].hold_ticks);
    assert_eq!(
        run.robots[1].hold_wait_s(run.tick_s),
        run.robots[1].hold_ticks as f64 * run.tick_s
    );
    // Every robot ran its whole task, one sample per running tick.
    for r in &run.robots {
        assert!(r.needed > 0 && r.corrected == r.supervised);
        assert_eq!(r.ref_time_log.len(), r.supervised.len());
    }
    // Where the time went: the parts add up to realized − planned, and the corrections
    // (which slow the LC robot, so that robot 2 waits at its hold) explain a positive share.
    let gap = &run.plan_gap;
    assert!(
        (gap.parts_sum_s() - run.over_plan_s()).abs() < 1e-9,
        "{gap:?} against {}",
        run.over_plan_s()
    );
    assert_eq!(gap.faults_s, 0.0);
    assert!(gap.corrections_s + gap.holds_s > 0.0, "{gap:?}");
    // Every sample needs the operator on the painted workpieces, but only 10..20 is
    // low-confidence: each robot runs the 50 high-confidence samples (one tick each at
    // ψ̇ = 1) unsupervised where the truth needs it.
    assert_eq!(run.needed_unsupervised(painted_needs), 2 * 50);
    assert_eq!(run.needed_unsupervised(|_, n| (10..20).contains(&n)), 0);
}

#[test]
fn a_round_gap_adds_up_for_any_operator_with_and_without_a_hold() {
    // The hand-made problem, serial and with a hold at 5 and its release rule, under
    // operators who miss and correct by mistake: the parts always sum to realized − planned,
    // the grid stays within a tick per leg, and only corrections and holds make the round
    // longer than planned by more than the grid.
    let model = model();
    let plain_problem = problem(&model);
    let held_problem = plain_problem.clone().with_holds(vec![5]).unwrap();
    let dt_s = plain_problem.dt_s();
    let serial = plain_problem.serial_schedule(dt_s).unwrap();
    let clock = |n: usize| tandem_realtime::clock_end_s(&serial.grad_exec[0][..n], 0.0, dt_s);
    let overlapping = Schedule {
        offsets_s: vec![clock(20) - clock(10)],
        ..serial.clone()
    };
    let held = held_problem.with_release_rules(&overlapping).unwrap();
    let cases = [(&plain_problem, &serial, 1), (&held_problem, &held, 2)];
    for (problem, schedule, legs) in cases {
        for seed in 0..6_u64 {
            let op = OperatorParams {
                miss_rate: 0.3,
                false_correction_rate: 0.2,
                ..OperatorParams::default()
            };
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let run =
                run_schedule(&model, problem, schedule, painted_needs, &op, &mut rng).unwrap();
            let gap = &run.plan_gap;
            assert!(
                (gap.parts_sum_s() - run.over_plan_s()).abs() < 1e-9,
                "seed {seed}: {gap:?} against {}",
                run.over_plan_s()
            );
            assert_eq!((gap.faults_s, run.faults), (0.0, 0));
            let tick = run.tick_s;
            assert!(
                gap.grid_s >= -tick && gap.grid_s <= legs as f64 * tick + 1e-9,
                "seed {seed}, {legs} leg(s): {gap:?}"
            );
            let corrected: usize = run
                .robots
                .iter()
                .map(|r| r.corrected.iter().filter(|&&c| c).count())
                .sum();
            assert!(corrected > 0, "seed {seed}: the operator corrected");
            assert_ne!(gap.corrections_s, 0.0, "seed {seed}: {gap:?}");
        }
    }
}

#[test]
fn a_round_gap_splits_realized_minus_planned_into_its_causes_exactly() {
    // A hand-built round, τ = 1 s, T_ref = 4, every sample planned at 1 s. Robot 1 starts at
    // 0 and runs its four samples on plan. Robot 2 is planned to start at 2 and to dwell 1 s
    // at a hold after sample 2: planned end 2 + 4 + 1 = 7 = T_total. It ran:
    //   k0 waiting, the operator correcting robot 1: its clock advanced 0.5 (0.5 s lost);
    //   k1, k2 waiting at full pace (clock 0.5 → 2.5); k3 running 0.5 → 1.5 (on plan);
    //   k4 running 1.5 → 2 and reaching the hold half-way (0.5 s grid);
    //   k5, k6 at the hold (2 s, planned 1 s: 1 s holds);
    //   k7 running 2 → 2.5 corrected (0.5 s corrections); k8 running 2.5 → 3.7 ahead of the
    //   warp (−0.2 s strategy); k9 running 3.7 → 4 and finishing (0.7 s grid).
    // Realized 10 s, planned 7 s: 3 s = 1 (corrections) + 1 (holds) − 0.2 (strategy) +
    // 1.2 (grid).
    use TickPhase::{AtHold, Finished, Running, Waiting};
    let robot = |phases: Vec<TickPhase>, ref_time_log: Vec<f64>, clock_s: Vec<f64>| {
        let n = ref_time_log.len();
        RobotRun {
            samples: vec![0.0; n],
            supervised: vec![false; n],
            corrected: vec![false; n],
            ref_time_log,
            needed: 0,
            missed: 0,
            switch_missed: 0,
            false_corrections: 0,
            clock_s,
            start_tick: phases.iter().position(|&p| p == Running).unwrap(),
            hold_ticks: phases.iter().filter(|&&p| p == AtHold).count(),
            phases,
        }
    };
    let r1 = robot(
        [vec![Running; 4], vec![Finished; 6]].concat(),
        vec![0.0, 1.0, 2.0, 3.0],
        (0..10).map(f64::from).collect(),
    );
    let r2 = robot(
        vec![
            Waiting, Waiting, Waiting, Running, Running, AtHold, AtHold, Running, Running, Running,
        ],
        vec![0.5, 1.5, 2.0, 2.5, 3.7],
        vec![0.0, 0.5, 1.5, 2.5, 3.5, 4.0, 4.0, 5.0, 5.5, 6.7],
    );
    let mut round = RoundRun {
        robots: vec![r1, r2],
        ticks: 10,
        tick_s: 1.0,
        overlap_ticks: 0,
        idle_ticks: 10,
        faults: 0,
        planned_t_total_s: 7.0,
        planned_ends_s: vec![4.0, 7.0],
        plan_gap: PlanGap::default(),
        rest_ticks: 0,
    };
    let plan = |start_s: f64, end_s: f64| RobotPlan {
        start_s,
        end_s,
        sample_clock_s: (0..5).map(|n| start_s + f64::from(n)).collect(),
    };
    let mut plans = vec![plan(0.0, 4.0), plan(2.0, 7.0)];
    let mut corrected_tick = vec![false; 10];
    corrected_tick[0] = true;
    corrected_tick[7] = true;
    let gap = plan_gap(&round, &plans, &corrected_tick);
    let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
    assert_eq!(gap.critical_robot, 1);
    assert_eq!((gap.realized_s, gap.planned_s), (10.0, 7.0));
    assert!(close(gap.corrections_s, 1.0), "{gap:?}");
    assert!(close(gap.holds_s, 1.0), "{gap:?}");
    assert!(close(gap.strategy_s, -0.2), "{gap:?}");
    assert!(close(gap.grid_s, 1.2), "{gap:?}");
    assert_eq!((gap.faults_s, gap.critical_path_s), (0.0, 0.0));
    assert!(close(gap.parts_sum_s(), 3.0));
    assert_eq!(gap.dominant().0, "grid");
    assert_eq!(
        gap.describe(),
        "3.00 s over plan (+42.9 %): corrections +1.00 s (33 %), holds +1.00 s (33 %), \
         strategy -0.20 s (-7 %), grid +1.20 s (40 %)"
    );
    // Robot 1 planned to end last (at 7.5, its plan padded with a 3.5 s dwell it never
    // needed), robot 2 planned at 6.5 (a 0.5 s dwell): robot 2 still ended the round, its
    // hold took 1.5 s more than planned, and the plan's critical path was 0.5 s longer.
    plans[0].end_s = 7.5;
    plans[1].end_s = 6.5;
    round.planned_t_total_s = 7.5;
    let gap = plan_gap(&round, &plans, &corrected_tick);
    assert_eq!(gap.critical_robot, 1);
    assert!(close(gap.holds_s, 1.5), "{gap:?}");
    assert!(close(gap.critical_path_s, -1.0), "{gap:?}");
    assert!(close(gap.parts_sum_s(), gap.total_s()), "{gap:?}");
    assert!(close(gap.total_s(), 2.5));
    // Needed but unsupervised: robot 2 needs the operator at reference samples 2 and 4
    // (round(t)): its samples at 1.5 and 2.0 round to 2, at 3.7 to 4; nothing supervised.
    let needs = |robot: usize, idx: usize| robot == 1 && (idx == 2 || idx == 4);
    assert_eq!(round.needed_unsupervised(needs), 3);
    round.robots[1].supervised[1] = true;
    assert_eq!(round.needed_unsupervised(needs), 2);
}

#[test]
fn a_nominal_round_with_a_hold_ends_on_plan_and_records_where_its_time_went() {
    // The schedule of the test above (robot 2 leaves its hold at 5 once robot 1 has passed
    // sample 20, its LC run 10..20 planned right after robot 1's): the rule's wait is planned
    // as a dwell, so an operator who never corrects (nothing needed, no false corrections)
    // ends the round on plan. Before the wait was planned the round ran the travel from the
    // hold to the LC run (samples 5..10) over its plan.
    let model = model();
    let problem = problem(&model).with_holds(vec![5]).unwrap();
    let dt_s = problem.dt_s();
    let serial = problem.serial_schedule(dt_s).unwrap();
    let grad = serial.grad_exec[0].clone();
    let clock = |n: usize| tandem_realtime::clock_end_s(&grad[..n], 0.0, dt_s);
    let plain = Schedule {
        offsets_s: vec![clock(20) - clock(10)],
        ..serial
    };
    let held = problem.with_release_rules(&plain).unwrap();
    // The dwell: robot 2 arrives at its hold at τ + c_5 and robot 1 passes sample 20 at c_20.
    let tau = plain.offsets_s[0];
    let dwell = held.holds_of(1)[0].dwell_s;
    assert!(
        (dwell - (clock(20) - (tau + clock(5)))).abs() < 1e-12,
        "{dwell}"
    );
    assert!((held.t_total_s(dt_s) - (plain.t_total_s(dt_s) + dwell)).abs() < 1e-12);
    let nominal = perfect();
    let never = |_: usize, _: usize| false;
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let run = run_schedule(&model, &problem, &held, never, &nominal, &mut rng).unwrap();
    assert_eq!((run.overlap_ticks, run.faults), (0, 0));
    assert_eq!(run.planned_t_total_s, held.t_total_s(dt_s));
    assert_eq!(run.planned_ends_s, held.ends_s(dt_s));
    // On plan to the tick grid (an 82-tick round: 1 % is less than a tick): the round ends
    // at a tick boundary, and robot 2 leaves its hold at the first tick start after robot 1
    // passed sample 20 (both at most a tick later than planned).
    let grid_s = 2.0 * run.tick_s;
    assert!(
        run.over_plan_s().abs() <= grid_s,
        "realized {} s against planned {} s",
        run.duration_s(),
        run.planned_t_total_s
    );
    // Every tick of every robot is accounted for: waiting for its start, running (one logged
    // sample each), at its hold, finished.
    for (i, r) in run.robots.iter().enumerate() {
        assert_eq!(r.phases.len(), run.ticks, "robot {i}");
        assert_eq!(r.ticks_in(TickPhase::Running), r.ref_time_log.len());
        assert_eq!(r.ticks_in(TickPhase::AtHold), r.hold_ticks);
        assert_eq!(r.ticks_in(TickPhase::Waiting), r.start_tick);
        assert_eq!(r.ticks_in(TickPhase::Held), 0);
        let end_s = r.end_tick() as f64 * run.tick_s;
        assert!(
            (end_s - run.planned_ends_s[i]).abs() <= grid_s,
            "robot {i}: {end_s}"
        );
    }
    // The gap's parts add up to realized − planned; no correction was given, so none is
    // charged to corrections, and the rest is within the tick grid.
    let gap = &run.plan_gap;
    assert!(
        (gap.parts_sum_s() - run.over_plan_s()).abs() < 1e-9,
        "{gap:?}"
    );
    assert_eq!((gap.corrections_s, gap.faults_s), (0.0, 0.0), "{gap:?}");
    for (name, s) in gap.parts() {
        assert!(s.abs() <= grid_s, "{name}: {s} s ({gap:?})");
    }
    // Robot 2 stands at its hold for its planned dwell (to within a tick).
    let waited_s = run.robots[1].hold_wait_s(run.tick_s);
    assert!(
        (waited_s - dwell).abs() <= run.tick_s,
        "{waited_s} vs {dwell}"
    );
}

#[test]
fn a_fast_robot_crossing_a_one_sample_island_in_one_tick_gets_it_supervised() {
    // High confidence everywhere but a one-sample island at 30; every sample is planned at
    // ψ̇ = 0.35 (the fastest), so a robot sweeps 1/0.35 ≈ 2.86 reference samples per tick and
    // crosses the island inside the tick from 28.57 to 31.43: no tick starts on it. The
    // coordinator reports that tick low-confidence; the record must supervise it and the
    // island must get its vote (issue 22), else it never clears.
    let model = model();
    let island = 30;
    let conf: Vec<bool> = (0..N_REF).map(|n| n != island).collect();
    let problem = Problem::new(
        conf,
        vec![0.35; N_REF],
        vec![0.35; N_REF],
        vec![2.0; N_REF],
        model.dt_s(),
    )
    .unwrap();
    let schedule = problem.serial_schedule(problem.dt_s()).unwrap();
    let perfect = perfect();
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let run = run_schedule(
        &model,
        &problem,
        &schedule,
        painted_needs,
        &perfect,
        &mut rng,
    )
    .unwrap();
    assert_eq!(run.overlap_ticks, 0);
    for r in &run.robots {
        // The robot never starts a tick on the island: it jumps it.
        assert!(
            r.ref_time_log.iter().all(|t| t.floor() as usize != island),
            "{:?}",
            r.ref_time_log
        );
        // The tick that crossed it is supervised, and the operator (needed: painted) corrected.
        let k = r
            .ref_time_log
            .windows(2)
            .position(|w| w[0] < island as f64 && w[1] >= (island + 1) as f64)
            .unwrap();
        assert!(r.supervised[k] && r.corrected[k], "row {k}");
        assert_eq!(r.supervised.iter().filter(|s| **s).count(), 1);
        assert_eq!((r.needed, r.missed), (1, 0));
        // The planner's vote reaches the island.
        let (times, swept_to, corrected) = r.record(&model).unwrap().observation_spans().unwrap();
        let mut obs = tandem_confidence::Observations::new(N_REF).unwrap();
        obs.record_votes_swept(&times, &swept_to, &corrected)
            .unwrap();
        assert_eq!(obs.supervised()[island], 1.0);
        assert_eq!(obs.corrections()[island], 1.0);
        // The split of the tick's sample alone (at 28.57: samples 28 and 29) would not.
        let mut split = tandem_confidence::Observations::new(N_REF).unwrap();
        split.record_votes(&times, &corrected).unwrap();
        assert_eq!(split.supervised()[island], 0.0);
    }
}

/// The ticks (of the round) in which `run` logged a supervised sample.
fn supervised_ticks(run: &RobotRun) -> Vec<usize> {
    run.phases
        .iter()
        .enumerate()
        .filter(|(_, p)| **p == TickPhase::Running)
        .map(|(t, _)| t)
        .zip(&run.supervised)
        .filter(|(_, s)| **s)
        .map(|(t, _)| t)
        .collect()
}

/// An operator with a switch time `δ_true` (issue 41) misses exactly the needed corrections of
/// the second robot's stretch that come less than `δ_true` (in whole ticks) after the first
/// robot's stretch ended; the first robot, and an operator without a switch time, miss none.
#[test]
fn an_operator_with_a_switch_time_misses_the_corrections_right_after_another_robots_stretch() {
    let perfect = perfect();
    let (base, _) = run(&perfect, 11);
    for r in &base.robots {
        assert_eq!((r.missed, r.switch_missed), (0, 0));
        assert!(r.needed > 0);
    }
    // 0.6 s at 10 ms ticks: 60 ticks, more than the serial schedule's 50 ticks between the
    // two robots' stretches.
    let switch_s = 0.6;
    let k = tandem_realtime::switch_ticks(switch_s, 0.01).unwrap() as usize;
    assert_eq!(k, 60);
    let slow = OperatorParams {
        switch_true_s: switch_s,
        ..perfect.clone()
    };
    let (round, _) = run(&slow, 11);
    let ticks: Vec<Vec<usize>> = round.robots.iter().map(supervised_ticks).collect();
    // The serial schedule: one robot's stretch, then the other's.
    let (first, second) = if ticks[0][0] < ticks[1][0] {
        (0, 1)
    } else {
        (1, 0)
    };
    let last = *ticks[first].last().unwrap();
    assert!(last < ticks[second][0]);
    let expected = ticks[second].iter().filter(|&&t| t < last + 1 + k).count();
    assert!(
        expected > 0,
        "the stretches are {} ticks apart",
        ticks[second][0] - last - 1
    );
    assert_eq!(round.robots[first].switch_missed, 0);
    assert_eq!(round.robots[first].missed, 0);
    // Every low-confidence sample needs a correction (all painted): each one in the switch is
    // missed, none after it.
    assert_eq!(round.robots[second].switch_missed, expected);
    assert_eq!(round.robots[second].missed, expected);
    let corrected: Vec<bool> = round.robots[second]
        .corrected
        .iter()
        .zip(&round.robots[second].supervised)
        .filter(|(_, s)| **s)
        .map(|(c, _)| *c)
        .collect();
    assert!(corrected[..expected].iter().all(|c| !c));
    assert!(corrected[expected..].iter().all(|c| *c));
    // A switch time no longer than the gap between the stretches costs nothing.
    let gap_ticks = ticks[second][0] - last - 1;
    if gap_ticks > 0 {
        let short = OperatorParams {
            switch_true_s: gap_ticks as f64 * 0.01,
            ..perfect.clone()
        };
        let (round, _) = run(&short, 11);
        assert!(round.robots.iter().all(|r| r.switch_missed == 0));
    }
    // A bad switch time is refused by name.
    let bad = OperatorParams {
        switch_true_s: -1.0,
        ..perfect
    };
    assert!(matches!(
        bad.validate(),
        Err(Error::BadParam {
            name: "switch_true_s",
            ..
        })
    ));
}

/// The console's tick-by-tick round is the workcell's round: same seed, same ticks, same
/// executions (samples and reference-time logs), and after `restart` the same round again.
#[test]
fn a_round_sim_ticks_the_same_round_as_run_round_with() {
    let planner = planner();
    let params = OperatorParams::default();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let want = run_round_with(&planner, painted_needs, &params, &mut rng).unwrap();
    let coord = planner.coordinator().unwrap();
    let mut sim = RoundSim::new(planner.model(), planner.problem(), coord, &params).unwrap();
    for _ in 0..2 {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut ticks = 0;
        while !tandem_realtime::Controller::is_finished(sim.coordinator()) {
            let t = sim.tick(planner.model(), painted_needs, &mut rng).unwrap();
            assert!(!t.overlap());
            ticks += 1;
            assert!(
                ticks <= want.ticks,
                "the round runs longer than run_round_with's"
            );
        }
        assert_eq!(ticks, want.ticks);
        sim.restart();
        assert_eq!(sim.coordinator().ticks(), 0);
    }
    // A model of another size is an error, not a panic.
    let other = Demonstration::new(vec!["force".into()], vec![1.0; 30], 0.01).unwrap();
    let small = TaskModel::fit(&[other.clone(), other], &FitParams::default());
    if let Ok(small) = small {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        assert!(matches!(
            sim.tick(&small, painted_needs, &mut rng),
            Err(Error::Mismatch { .. })
        ));
    }
}

/// The load cap at run time (issue 41; docs/decisions.md, "The load cap in rounds at run time:
/// the rest after a round (issue 41)"): a planner with `max_busy_share = u` runs its round by
/// [`run_round_with`] with the coordinator's rest; with no switch time the busy ticks are the
/// ticks with a low-confidence robot (`ticks − idle_ticks`), and over the round and its rest
/// they are at most `u`, with the least such rest. Without a cap: no rest, none in the JSON.
#[test]
fn a_round_under_the_load_cap_reports_the_rest_that_keeps_it() {
    for u in [0.3, 1.0] {
        let params = tandem_planner::PlannerParams {
            sampler: tandem_schedule::SamplerParams {
                samples: 50,
                seed: 3,
                max_busy_share: u,
                ..Default::default()
            },
            ..Default::default()
        };
        let planner = Planner::from_model(model(), params).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let round = run_round_with(
            &planner,
            painted_needs,
            &OperatorParams::default(),
            &mut rng,
        )
        .unwrap();
        let (busy, ticks, rest) = (
            (round.ticks - round.idle_ticks) as f64,
            round.ticks,
            round.rest_ticks,
        );
        let json = serde_json::to_string(&round).unwrap();
        if u < 1.0 {
            assert!(busy > 0.0);
            assert!(
                busy <= u * (ticks + rest) as f64,
                "{busy} in {ticks} + {rest}"
            );
            assert!(rest == 0 || busy > u * (ticks + rest - 1) as f64);
            assert_eq!(json.contains("rest_ticks"), rest > 0);
        } else {
            assert_eq!(rest, 0);
            assert!(!json.contains("rest_ticks"));
        }
    }
}
