//! `tandem simulate`: a what-if run of rounds (one execution per robot of the state's
//! schedule) with a simulated operator on the user's model.
//!
//! Per round `k` (seed `derive_seed(seed, k)`):
//!
//! 1. Each robot's workpiece draws, per need region `r`, whether the region needs the
//!    operator (probability `need[r]`, one draw per region and workpiece).
//! 2. Every robot runs the state's current schedule with the study's simulated operator,
//!    `tandem::sim::workcell::run_round_with` (the real-time coordinator, Eq. 17–18, Alg. 1,
//!    one control tick per reference sample period, exactly as on the robots), told by
//!    step 1 which reference samples of which robot need the operator.
//! 3. The robot on a low-confidence sample is *supervised*. The operator corrects it where
//!    its workpiece needs it (missing a needed correction with `--miss-rate`) and, where it
//!    does not, with `--false-rate`. A correction is the joystick input `u_k = ±gain` along
//!    the model's correction components with the sign that raises `--channel` (components
//!    that would speed the robot up are dropped when the combined input would), with the
//!    study's `gain` (`OperatorParams::default()`: 1/3, about one standard deviation). The
//!    command `x_f⁺ = μ̂⁺ + δx⁺(u)` (Eq. 7) is logged and its rate (clamped to the
//!    demonstrated bounds) is the operator's gradient for the tick. Every flag's default is
//!    the study's (`OperatorParams::default()`).
//! 4. Every running robot logs its command, its reference time (Eq. 21) and its
//!    supervised/corrected flags; the round is then recorded in memory with
//!    `Planner::record_round`, exactly as `tandem record` does with the written files.
//!
//! The state file is never modified.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tandem::lfd::Execution;
use tandem::sim::workcell::{
    OperatorParams, PlanGap, RobotRun, RoundRun, correction_channel, run_round_with,
};
use tandem::{ExecutionRecord, Planner, derive_seed};

use crate::cli::SimulateArgs;
use crate::cmd::{deprecated, note, out, verbose};
use crate::{bag, input, state_io};

/// Runs one round (see the module docs). `needed[i][n]`: robot `i`'s workpiece needs the
/// operator at reference sample `n`; one entry per robot.
fn run_round(
    planner: &Planner,
    needed: &[Vec<bool>],
    op: &OperatorParams,
    rng: &mut impl Rng,
) -> Result<RoundRun> {
    Ok(run_round_with(
        planner,
        |robot, n| needed[robot][n],
        op,
        rng,
    )?)
}

/// File stem of robot `robot`'s execution in round `round` (both 1-based).
fn stem(round: usize, robot: usize) -> String {
    format!("round_{round}_robot_{robot}")
}

/// `record` with its demonstration named like the file `--write` gives it, so that an error
/// names the execution.
fn named(record: ExecutionRecord, round: usize, robot: usize) -> ExecutionRecord {
    let demonstration = record
        .execution
        .demonstration
        .with_source(format!("{}.csv", stem(round, robot)));
    ExecutionRecord {
        execution: Execution {
            demonstration,
            ..record.execution
        },
        ..record
    }
}

/// The three files of one execution, as `tandem record` reads them (numbers printed in
/// shortest round-trip form, so reading them back gives the same bits).
fn execution_files(log: &RobotRun, channels: &[String]) -> [String; 3] {
    let m = channels.len();
    let mut exec = channels.join(",");
    exec.push('\n');
    for row in log.samples.chunks_exact(m) {
        let fields: Vec<String> = row.iter().map(|v| format!("{v}")).collect();
        exec.push_str(&fields.join(","));
        exec.push('\n');
    }
    let mut reflog = String::from("ref_sample\n");
    for v in &log.ref_time_log {
        let _ = writeln!(reflog, "{v}");
    }
    let mut corr = String::from("supervised,corrected\n");
    for (s, c) in log.supervised.iter().zip(&log.corrected) {
        let _ = writeln!(corr, "{},{}", u8::from(*s), u8::from(*c));
    }
    [exec, reflog, corr]
}

/// The channel the simulated operator corrects along: `--channel NAME` checked against the
/// model, or the model's default ([`correction_channel`]), said in a note when it is not
/// `force` (the sanding task's, the operator's default before).
pub(crate) fn operator_channel(channel: Option<&str>, planner: &Planner) -> Result<String> {
    let model = planner.model();
    match channel {
        Some(name) => {
            if !model.tangent_names().iter().any(|n| n == name) {
                bail!(
                    "--channel {name}: the model has no such channel (channels: {})",
                    model.tangent_names().join(", ")
                );
            }
            Ok(name.to_owned())
        }
        None => {
            let name = correction_channel(model);
            if name != OperatorParams::default().force_channel {
                note(&format!(
                    "the simulated operator's corrections raise channel `{name}` (the model has \
                     no `force`; --channel NAME chooses another)"
                ));
            }
            Ok(name)
        }
    }
}

/// `tandem simulate`.
pub(crate) fn simulate(a: &SimulateArgs) -> Result<()> {
    let rounds = match (a.rounds, a.pairs) {
        (Some(n), _) => n,
        (None, Some(n)) => {
            deprecated("--pairs is --rounds (a round is one execution of each robot)");
            n
        }
        (None, None) => bail!("--rounds N is required"),
    };
    if rounds == 0 {
        bail!("--rounds 0: simulate at least one round");
    }
    // The study's operator with the flags' values; its own checks name the flag.
    let op = OperatorParams {
        miss_rate: a.miss_rate,
        false_correction_rate: a.false_rate,
        false_correction_s: a.false_episode,
        ..OperatorParams::default()
    };
    if let Err(e) = op.validate() {
        let flag = match e {
            tandem::sim::Error::BadParam {
                name: "miss_rate", ..
            } => "--miss-rate",
            tandem::sim::Error::BadParam {
                name: "false_correction_rate",
                ..
            } => "--false-rate",
            tandem::sim::Error::BadParam {
                name: "false_correction_s",
                ..
            } => "--false-episode",
            _ => "simulate",
        };
        bail!("{flag}: {e}");
    }
    let mut planner = state_io::load(&a.state)?;
    let need = input::read_need(&a.need, planner.model().n_ref())?;
    let op = OperatorParams {
        force_channel: operator_channel(a.channel.as_deref(), &planner)?,
        ..op
    };
    if let Some(dir) = &a.write {
        state_io::prepare_dir(dir)?;
    }
    let mut run_bag = match &a.bag {
        Some(path) => Some(bag::RunBag::create(path, &planner)?),
        None => None,
    };
    let mut files: Vec<(PathBuf, String)> = Vec::new();
    let mut gaps: Vec<PlanGap> = Vec::with_capacity(rounds);
    let mut unsupervised_needed = 0;
    out(
        "round  T_total ran (s)  actual (s)  supervised  corrected  overlap  → high-conf %  next T_total (s)",
    );
    for k in 0..rounds {
        let mut rng = ChaCha8Rng::seed_from_u64(derive_seed(a.seed, k as u64));
        let needed = need.draw(planner.n_robots(), &mut rng);
        let t_ran = planner.outcome().t_total_s;
        let round = run_round(&planner, &needed, &op, &mut rng)
            .with_context(|| format!("simulating round {}", k + 1))?;
        let channels = planner.model().channel_names().to_vec();
        let dt = planner.model().dt_s();
        if let Some(dir) = &a.write {
            for (i, log) in round.robots.iter().enumerate() {
                let stem = stem(k + 1, i + 1);
                let [e, l, c] = execution_files(log, &channels);
                files.push((dir.join(format!("{stem}.csv")), e));
                files.push((dir.join(format!("{stem}.reflog.csv")), l));
                files.push((dir.join(format!("{stem}.corr.csv")), c));
            }
        }
        if let Some(b) = &mut run_bag {
            b.write_round(&planner, &round)?;
        }
        let records: Vec<ExecutionRecord> = round
            .records(planner.model())?
            .into_iter()
            .enumerate()
            .map(|(i, r)| named(r, k + 1, i + 1))
            .collect();
        let supervised: usize = round
            .robots
            .iter()
            .map(|r| r.supervised.iter().filter(|s| **s).count())
            .sum();
        let corrected: usize = round
            .robots
            .iter()
            .map(|r| r.corrected.iter().filter(|s| **s).count())
            .sum();
        unsupervised_needed += round.needed_unsupervised(|robot, n| needed[robot][n]);
        gaps.push(round.plan_gap);
        let report = planner
            .record_round(&records)
            .with_context(|| format!("recording simulated round {}", k + 1))?;
        out(&format!(
            "{:>5}  {:>15.2}  {:>10.2}  {:>10}  {:>9}  {:>7}  {:>14.1}  {:>16.2}",
            k + 1,
            t_ran,
            round.ticks as f64 * dt,
            supervised,
            corrected,
            round.overlap_ticks,
            100.0 * planner.confidence().high_share(),
            report.t_total_s
        ));
        if verbose() {
            out(&format!("       gap: {}", describe_gap(&round.plan_gap)));
        }
        if round.rest_ticks > 0 {
            // The load cap at run time (issue 41): the next round starts after the rest.
            out(&format!(
                "       rest {:.2} s before the next round (load cap {})",
                round.rest_ticks as f64 * round.tick_s,
                planner.params().sampler.max_busy_share
            ));
        }
    }
    for line in realization_summary(&gaps, planner.n_robots(), unsupervised_needed) {
        out(&line);
    }
    if let Some(dir) = &a.write {
        write_all(&files)?;
        out(&format!(
            "wrote {} files into {} (tandem record reads them; round_K_robot_1 first)",
            files.len(),
            dir.display()
        ));
    }
    if let Some(b) = run_bag {
        b.finish()?;
    }
    out(&format!("what-if only: {} is unchanged", a.state.display()));
    Ok(())
}

/// One round's (or several rounds') realized against planned time and its causes, on one
/// line: `+1.23 s over plan (+4.5 %): corrections +0.80, holds +0.30, strategy +0.10,
/// grid +0.03 s` (causes of 0 left out).
fn describe_gap(gap: &PlanGap) -> String {
    let total = gap.total_s();
    let pct = if gap.planned_s > 0.0 {
        100.0 * total / gap.planned_s
    } else {
        0.0
    };
    let word = if total >= 0.0 { "over" } else { "under" };
    let parts: Vec<String> = gap
        .parts()
        .iter()
        .filter(|(_, s)| s.abs() >= 0.005)
        .map(|(name, s)| format!("{name} {s:+.2}"))
        .collect();
    let causes = if parts.is_empty() {
        String::new()
    } else {
        format!(": {} s", parts.join(", "))
    };
    format!("{:.2} s {word} plan ({pct:+.1} %){causes}", total.abs())
}

/// The summary lines of `simulate` after its table: realized against planned time and
/// throughput over all rounds, the share of the difference each cause explains
/// ([`PlanGap`]), and the samples that needed the operator but ran unsupervised.
fn realization_summary(
    gaps: &[PlanGap],
    n_robots: usize,
    unsupervised_needed: usize,
) -> Vec<String> {
    if gaps.is_empty() {
        return Vec::new();
    }
    let sum = PlanGap::sum(gaps);
    let per_h = |t_s: f64| {
        if t_s > 0.0 {
            n_robots as f64 * 3600.0 * gaps.len() as f64 / t_s
        } else {
            0.0
        }
    };
    vec![
        format!(
            "realized against planned over {} round(s): {:.2} s against {:.2} s, {}",
            gaps.len(),
            sum.realized_s,
            sum.planned_s,
            describe_gap(&sum)
        ),
        format!(
            "throughput: {:.1} tasks/h planned, {:.1} realized; needed but unsupervised: {} \
             sample(s) (high confidence where the need says the operator is needed)",
            per_h(sum.planned_s),
            per_h(sum.realized_s),
            unsupervised_needed
        ),
    ]
}

/// Writes every file (after the whole simulation succeeded).
fn write_all(files: &[(PathBuf, String)]) -> Result<()> {
    for (p, text) in files {
        write_file(p, text)?;
    }
    Ok(())
}

fn write_file(p: &Path, text: &str) -> Result<()> {
    std::fs::write(p, text).with_context(|| format!("{}: cannot write", p.display()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use tandem::PlannerParams;
    use tandem::lfd::{Demonstration, FitParams, TaskModel};
    use tandem::schedule::SamplerParams;

    /// Three one-channel demonstrations aligned by known warps: demos 0 and 2 press 1 N
    /// everywhere; demo 1 presses 9 N over reference samples 10..20 and takes two samples per
    /// reference sample there (the expert slows down where pressing hard).
    fn model() -> TaskModel {
        let names = vec!["force".to_string()];
        let light = Demonstration::new(names.clone(), vec![1.0; 40], 0.01).unwrap();
        let hard: Vec<f64> = (0..50)
            .map(|q| if (10..30).contains(&q) { 9.0 } else { 1.0 })
            .collect();
        let hard = Demonstration::new(names, hard, 0.01).unwrap();
        let id: Vec<f64> = (0..40).map(f64::from).collect();
        let slow: Vec<f64> = (0..40)
            .map(|n| match n {
                0..10 => f64::from(n),
                10..20 => 10.0 + 2.0 * f64::from(n - 10),
                _ => 30.0 + f64::from(n - 20),
            })
            .collect();
        TaskModel::fit_aligned(
            &[light.clone(), hard, light],
            &[id.clone(), slow, id],
            &FitParams::default(),
        )
        .unwrap()
    }

    #[test]
    fn the_summary_says_how_far_over_plan_and_why() {
        let gap = PlanGap {
            realized_s: 11.0,
            planned_s: 10.0,
            critical_robot: 1,
            corrections_s: 0.75,
            holds_s: 0.0,
            strategy_s: 0.3,
            grid_s: -0.05,
            faults_s: 0.0,
            critical_path_s: 0.0,
        };
        assert_eq!(
            describe_gap(&gap),
            "1.00 s over plan (+10.0 %): corrections +0.75, strategy +0.30, grid -0.05 s"
        );
        let lines = realization_summary(&[gap, gap], 2, 7);
        assert_eq!(
            lines[0],
            "realized against planned over 2 round(s): 22.00 s against 20.00 s, 2.00 s over \
             plan (+10.0 %): corrections +1.50, strategy +0.60, grid -0.10 s"
        );
        // Two robots, one task each per round: 2 · 3600 · 2 / 20 = 720 planned, / 22 realized.
        assert!(lines[1].starts_with("throughput: 720.0 tasks/h planned, 654.5 realized"));
        assert!(lines[1].contains("needed but unsupervised: 7 sample(s)"));
        assert!(realization_summary(&[], 2, 0).is_empty());
    }

    #[test]
    fn a_perfect_operator_corrects_exactly_the_supervised_needed_samples() {
        let params = PlannerParams {
            sampler: SamplerParams {
                samples: 50,
                ..SamplerParams::default()
            },
            ..PlannerParams::default()
        };
        let planner = Planner::from_model(model(), params).unwrap();
        let op = OperatorParams {
            miss_rate: 0.0,
            false_correction_rate: 0.0,
            false_correction_s: 0.0,
            ..OperatorParams::default()
        };
        let needed = [vec![true; 40], vec![false; 40]];
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let round = run_round(&planner, &needed, &op, &mut rng).unwrap();
        assert_eq!(round.overlap_ticks, 0);
        let [r1, r2] = &round.robots[..] else {
            panic!("{} robots", round.robots.len())
        };
        assert!(
            r1.supervised.iter().any(|s| *s),
            "robot 1 is supervised somewhere"
        );
        assert_eq!(
            r1.corrected, r1.supervised,
            "robot 1 needs every supervised sample"
        );
        assert!(r2.corrected.iter().all(|c| !c), "robot 2 needs none");
        for r in [r1, r2] {
            assert_eq!(r.samples.len(), r.ref_time_log.len());
            assert!(r.ref_time_log.windows(2).all(|w| w[0] <= w[1]));
            assert!(r.ref_time_log.iter().all(|t| (0.0..=39.0).contains(t)));
        }
        // Corrections slow robot 1 down: it runs longer than robot 2.
        assert!(r1.samples.len() > r2.samples.len());
    }
}
