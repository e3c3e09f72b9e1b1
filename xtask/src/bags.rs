//! `cargo xtask bags`: the measurements behind ROS 2 bag support (docs/decisions.md, "ROS 2
//! bags"), in one run.
//!
//! 1. **The fixtures as bags fit to the same model.** Each of the six sanding demonstrations
//!    (`fixtures/sanding/demo_{i}.csv`, 100 Hz) is written as a ROS 2 recording of three
//!    topics at their own rates and phases: `/pose` (`PoseStamped`, 100 Hz, from 0 ms),
//!    `/wrench` (`WrenchStamped`, 250 Hz, from 2 ms; the normal force as `fz`) and `/tool`
//!    (`Bool`, 50 Hz, from 5 ms), by `tandem::bag::write_demonstration`. The bags are read
//!    back (at 100 Hz, and at the default rate, the pose's 100 Hz: the slowest topic that is
//!    interpolated, the `Bool` being held) and fitted with
//!    the planner's defaults, and the first schedule's `T_total`, the high-confidence share
//!    and the model's durations and `σ²_D` are compared with the fit of the CSV files; a
//!    second parameter set (`mu_c = 0.25`, which trusts the least variable samples from the
//!    prior alone) makes the high-confidence share non-trivial.
//! 2. **Reading speed.** Six synthetic demonstrations of 60 s with five topics at 100–500 Hz
//!    (`/pose` 100 Hz, `/wrench` 500 Hz, `/twist` 200 Hz, `/joints` 7 joints at 250 Hz,
//!    `/tool` 100 Hz) are written as bags, read once onto the 100 Hz grid and written as the
//!    same data in CSV (one row per grid sample, shortest round-trip numbers). Then, in the same
//!    run: the time to read the six bags and the six CSV files (median of 5 reads each), and to
//!    read and fit (`TaskModel::fit`, defaults) each set once. The ratios bag / CSV are printed.
//!
//! Everything is written under `--out` (default `target/bags/`), which is scratch.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tandem::bag::{
    BagOptions, Existing, MsgType, Recording, TopicSpec, extend_schema, read_bag,
    write_demonstration,
};
use tandem::lfd::{Demonstration, FitParams, TaskModel};
use tandem::{Planner, PlannerParams};

use crate::workspace_root;

/// Flags of `cargo xtask bags`.
#[derive(clap::Args, Debug)]
pub(crate) struct BagsArgs {
    /// Scratch folder for the bags and CSV files. Default: target/bags/ in the workspace.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Seed of the synthetic demonstrations of the speed measurement.
    #[arg(long, default_value_t = 23)]
    seed: u64,
    /// Skip the speed measurement.
    #[arg(long)]
    no_speed: bool,
}

fn spec(topic: &str, t: MsgType, channels: &[&str], rate_hz: f64, start_ms: i64) -> TopicSpec {
    TopicSpec {
        topic: topic.into(),
        msg_type: t,
        channels: channels
            .iter()
            .map(|c| (!c.is_empty()).then(|| (*c).to_owned()))
            .collect(),
        joints: Vec::new(),
        rate_hz,
        start_ns: start_ms * 1_000_000,
    }
}

/// The topics of a fixture demonstration's bag.
fn fixture_topics() -> Vec<TopicSpec> {
    vec![
        spec(
            "/pose",
            MsgType::PoseStamped,
            &["x", "y", "z", "qx", "qy", "qz", "qw"],
            100.0,
            0,
        ),
        spec(
            "/wrench",
            MsgType::WrenchStamped,
            &["", "", "force", "", "", ""],
            250.0,
            2,
        ),
        spec("/tool", MsgType::Bool, &["tool"], 50.0, 5),
    ]
}

/// What the comparison reports of one fit.
struct FitFigures {
    n_ref: usize,
    dt_s: f64,
    t_total_s: f64,
    high_pct: f64,
    mean_s: f64,
    fastest_s: f64,
    slowest_s: f64,
    sigma2_median: f64,
}

fn figures(planner: &Planner) -> FitFigures {
    let m = planner.model();
    let dt = m.dt_s();
    let mut s2 = m.sigma2_d().to_vec();
    s2.sort_by(f64::total_cmp);
    FitFigures {
        n_ref: m.n_ref(),
        dt_s: dt,
        t_total_s: planner.outcome().t_total_s,
        high_pct: 100.0 * planner.confidence().high_share(),
        mean_s: m.grad_mean().iter().sum::<f64>() * dt,
        fastest_s: m.grad_min().iter().sum::<f64>() * dt,
        slowest_s: m.grad_max().iter().sum::<f64>() * dt,
        sigma2_median: s2[s2.len() / 2],
    }
}

fn print_row(label: &str, f: &FitFigures, csv: &FitFigures) {
    println!(
        "  {label:<22} n_ref {:>5} × {:.3} s  T_total {:>8.2} s ({:+.2} %)  high-conf {:>5.1} % ({:+.1} pp)  \
         durations mean/fastest/slowest {:.2}/{:.2}/{:.2} s  median σ²_D {:.4}",
        f.n_ref,
        f.dt_s,
        f.t_total_s,
        100.0 * (f.t_total_s / csv.t_total_s - 1.0),
        f.high_pct,
        f.high_pct - csv.high_pct,
        f.mean_s,
        f.fastest_s,
        f.slowest_s,
        f.sigma2_median
    );
}

/// Part 1 (see the module docs).
fn fixtures_as_bags(out: &Path) -> anyhow::Result<()> {
    let dir = workspace_root().join("fixtures/sanding");
    let bag_dir = out.join("fixtures");
    std::fs::create_dir_all(&bag_dir).with_context(|| format!("creating {}", bag_dir.display()))?;
    let csv: Vec<Demonstration> = (0..6)
        .map(|i| Demonstration::from_csv_path(dir.join(format!("demo_{i}.csv")), None))
        .collect::<Result<_, _>>()?;
    let mut paths = Vec::new();
    for (i, d) in csv.iter().enumerate() {
        let p = bag_dir.join(format!("demo_{i}.mcap"));
        write_demonstration(&p, d, &fixture_topics(), true, Existing::Replace)?;
        paths.push(p);
    }
    let size: u64 = paths
        .iter()
        .map(|p| std::fs::metadata(p).map(|m| m.len()).unwrap_or(0))
        .sum();
    println!(
        "fixtures as bags: 6 demonstrations, /pose 100 Hz, /wrench 250 Hz (+2 ms), /tool 50 Hz \
         (+5 ms); {:.1} MB zstd in {}",
        size as f64 / 1e6,
        bag_dir.display()
    );
    let mu_c = PlannerParams {
        confidence: tandem::confidence::ConfidenceParams {
            mu_c: 0.25,
            ..Default::default()
        },
        ..PlannerParams::default()
    };
    for (name, params) in [
        ("defaults", PlannerParams::default()),
        ("mu_c = 0.25", mu_c),
    ] {
        let t = Instant::now();
        let from_csv = figures(&Planner::new(&csv, params.clone())?);
        let csv_s = t.elapsed().as_secs_f64();
        println!("parameters: {name}");
        print_row("CSV (100 Hz)", &from_csv, &from_csv);
        for rate in [Some(100.0), None] {
            let options = BagOptions {
                rate_hz: rate,
                ..BagOptions::default()
            };
            let recs: Vec<Recording> = paths
                .iter()
                .map(|p| read_bag(p, &options))
                .collect::<Result<_, _>>()?;
            let demos: Vec<Demonstration> = recs
                .iter()
                .map(Recording::demonstration)
                .collect::<Result<_, _>>()?;
            let mut p = params.clone();
            extend_schema(&mut p.fit.schema, &recs);
            let t = Instant::now();
            let from_bags = figures(&Planner::new(&demos, p)?);
            let label = match rate {
                Some(r) => format!("bags, --rate {r}"),
                None => "bags, default rate".to_owned(),
            };
            print_row(&label, &from_bags, &from_csv);
            println!(
                "    (fit {:.1} s; the CSV fit {csv_s:.1} s; channels {})",
                t.elapsed().as_secs_f64(),
                recs[0].channel_names.join(", ")
            );
        }
    }
    Ok(())
}

/// A synthetic demonstration of part 2 at 1 kHz: a pose moving and turning, a wrench,
/// a twist, seven joints and a tool flag, each demonstration at its own speed.
fn synthetic(rng: &mut ChaCha8Rng) -> anyhow::Result<Demonstration> {
    let mut names: Vec<String> = ["x", "y", "z", "qx", "qy", "qz", "qw"]
        .iter()
        .map(|s| (*s).to_owned())
        .collect();
    names.extend(["fx", "fy", "fz", "tx", "ty", "tz"].map(String::from));
    names.extend(["vx", "vy", "vz", "wx", "wy", "wz"].map(String::from));
    names.extend((1..=7).map(|j| format!("j{j}")));
    names.push("tool".into());
    let speed = 1.0 + rng.random_range(-0.1..0.1);
    let phase: Vec<f64> = (0..names.len())
        .map(|_| rng.random_range(0.0..0.2))
        .collect();
    let n = 60_001;
    let mut v = Vec::with_capacity(n * names.len());
    for k in 0..n {
        let t = k as f64 / 1000.0;
        let s = (t * speed / 60.0).min(1.0) * std::f64::consts::TAU;
        let angle = 0.3 * (s + phase[3]).sin();
        let (sn, cs) = (angle / 2.0).sin_cos();
        v.extend_from_slice(&[
            0.3 * s.sin(),
            0.2 * (2.0 * s).sin(),
            0.05 * s.cos(),
            0.0,
            0.0,
            sn,
            cs,
        ]);
        for (c, p) in phase.iter().enumerate().take(names.len() - 1).skip(7) {
            v.push((c as f64 * 0.1) * ((c as f64 * 0.37 + 1.0) * s + p).sin());
        }
        v.push(f64::from(u8::from(s.sin() > 0.0)));
    }
    Ok(Demonstration::new(names, v, 0.001)?)
}

fn speed_topics() -> Vec<TopicSpec> {
    let mut joints = spec(
        "/joints",
        MsgType::JointState,
        &["j1", "j2", "j3", "j4", "j5", "j6", "j7"],
        250.0,
        0,
    );
    joints.joints = (1..=7).map(|j| format!("joint_{j}")).collect();
    vec![
        spec(
            "/pose",
            MsgType::PoseStamped,
            &["x", "y", "z", "qx", "qy", "qz", "qw"],
            100.0,
            0,
        ),
        spec(
            "/wrench",
            MsgType::WrenchStamped,
            &["fx", "fy", "fz", "tx", "ty", "tz"],
            500.0,
            0,
        ),
        spec(
            "/twist",
            MsgType::TwistStamped,
            &["vx", "vy", "vz", "wx", "wy", "wz"],
            200.0,
            0,
        ),
        joints,
        spec("/tool", MsgType::Bool, &["tool"], 100.0, 0),
    ]
}

/// `rec` as a CSV demonstration file: a `t` column and the channels, one row per sample.
fn csv_text(rec: &Recording) -> String {
    use std::fmt::Write as _;
    let m = rec.channel_names.len();
    let mut s = String::from("t,");
    s.push_str(&rec.channel_names.join(","));
    s.push('\n');
    for (k, row) in rec.samples.chunks_exact(m).enumerate() {
        let _ = write!(s, "{}", k as f64 * rec.dt_s);
        for v in row {
            let _ = write!(s, ",{v}");
        }
        s.push('\n');
    }
    s
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Part 2 (see the module docs).
fn speed(out: &Path, seed: u64) -> anyhow::Result<()> {
    let dir = out.join("speed");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (mut bags, mut csvs) = (Vec::new(), Vec::new());
    let mut messages = 0usize;
    for d in 0..6 {
        let demo = synthetic(&mut rng)?;
        let bag = dir.join(format!("demo_{d}.mcap"));
        write_demonstration(&bag, &demo, &speed_topics(), true, Existing::Replace)?;
        let rec = read_bag(&bag, &BagOptions::default())?;
        messages += rec.topics.iter().map(|t| t.messages).sum::<usize>();
        let csv = dir.join(format!("demo_{d}.csv"));
        std::fs::write(&csv, csv_text(&rec))
            .with_context(|| format!("writing {}", csv.display()))?;
        bags.push(bag);
        csvs.push(csv);
    }
    let bytes = |v: &[PathBuf]| -> u64 {
        v.iter()
            .map(|p| std::fs::metadata(p).map(|m| m.len()).unwrap_or(0))
            .sum()
    };
    println!(
        "reading speed: 6 demonstrations × 60 s, 5 topics at 100–500 Hz ({messages} messages, \
         {:.1} MB of zstd MCAP) vs the same data as CSV at 100 Hz ({:.1} MB)",
        bytes(&bags) as f64 / 1e6,
        bytes(&csvs) as f64 / 1e6
    );
    let read_bags = || -> anyhow::Result<(Vec<Demonstration>, Vec<Recording>)> {
        let recs: Vec<Recording> = bags
            .iter()
            .map(|p| read_bag(p, &BagOptions::default()))
            .collect::<Result<_, _>>()?;
        let demos = recs
            .iter()
            .map(Recording::demonstration)
            .collect::<Result<_, _>>()?;
        Ok((demos, recs))
    };
    let read_csvs = || -> anyhow::Result<Vec<Demonstration>> {
        Ok(csvs
            .iter()
            .map(|p| Demonstration::from_csv_path(p, None))
            .collect::<Result<_, _>>()?)
    };
    let (mut t_bag, mut t_csv) = (Vec::new(), Vec::new());
    for _ in 0..5 {
        let t = Instant::now();
        read_bags()?;
        t_bag.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        read_csvs()?;
        t_csv.push(t.elapsed().as_secs_f64());
    }
    let (rb, rc) = (median(t_bag), median(t_csv));
    println!(
        "  read (median of 5): bags {rb:.3} s, CSV {rc:.3} s: ratio {:.2}",
        rb / rc
    );
    // The same schema for both fits (the pose's orientation as a quaternion block).
    let (_, recs) = read_bags()?;
    let mut params = FitParams::default();
    extend_schema(&mut params.schema, &recs);
    let t = Instant::now();
    let (demos, _) = read_bags()?;
    let model_bag = TaskModel::fit(&demos, &params)?;
    let fb = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let demos = read_csvs()?;
    let model_csv = TaskModel::fit(&demos, &params)?;
    let fc = t.elapsed().as_secs_f64();
    println!(
        "  read and fit (once each): bags {fb:.2} s, CSV {fc:.2} s: ratio {:.2} (the models are \
         {})",
        fb / fc,
        if model_bag.sigma2_d() == model_csv.sigma2_d() {
            "identical"
        } else {
            "different"
        }
    );
    Ok(())
}

/// Runs `cargo xtask bags`.
pub(crate) fn run(args: &BagsArgs) -> anyhow::Result<()> {
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| workspace_root().join("target/bags"));
    fixtures_as_bags(&out)?;
    if !args.no_speed {
        speed(&out, args.seed)?;
    }
    Ok(())
}
