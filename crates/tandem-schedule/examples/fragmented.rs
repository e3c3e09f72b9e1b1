//! Mid-study-like problems with fragmented confidence, built from the fixture problem: the
//! exact search (`solve_exact`), the margin-aware completion alone
//! (`SamplerBaselines::completion_only`) and the sampler alone
//! (`SamplerBaselines::sampler_only`) on each.
//!
//! ```text
//! cargo run --release -p tandem-schedule --example fragmented [-- --write DIR]
//! ```
//!
//! The gradients are those of `fixtures/sanding/problem.csv`; `fixture` is that problem itself
//! (all sanding of passes 1–3 low-confidence). The other confidences mimic a study
//! half-way through (docs/study.md: 15–257 LC runs per robot between iterations 10 and 75):
//! the painted sections of passes 1–3 (labels of the reference demonstration,
//! `fixtures/sanding/demo_0.labels.csv`) stay low-confidence, and each other sample of passes
//! 1–3 (probability `p_sanding`) or of the transitions (`p_transition`) is a one-sample LC
//! island, drawn from a ChaCha8 stream of the seed. `--write DIR` also writes every problem
//! as `DIR/<name>.csv` (`grad_mean,grad_min,grad_max,conf`, the input of the `certify`
//! example and of `bench/peers/exact_compare.py`).
//!
//! Prints one row per problem: LC runs per robot, `T*₀` and whether it is proven, the search's
//! pieces and wall time; the completion's `T_total` (with where it came from: `completed`, or
//! `serial` when the completion found nothing shorter), its gap to `T*₀`, margin checks and
//! wall time; the sampler's `T_total`, gap and wall time (5000 samples, seed 0); and the
//! scheduler's (`sample_schedule`: both, the completion also refining the sampler's winner).
//!
//! Then the same for `RANDOM` random problems (`random_<k>`, ChaCha8 seed `k`): 2000–4000
//! samples at 10 ms in alternating runs (LC runs of 20–400 samples, HC runs of 50–800), a
//! smooth random mean gradient and per-run bound factors `ψ̇min/ψ̇̄ ∈ [0.3, 0.9]`,
//! `ψ̇max/ψ̇̄ ∈ [1.1, 2.5]`; and a last row with the means over them.
#![allow(clippy::print_stdout, reason = "an example reports to the terminal")]

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tandem_schedule::testkit::{ProblemShape, random_problem_shaped};
use tandem_schedule::{
    ExactParams, Problem, SamplerBaselines, SamplerParams, Source, sample_schedule,
    sample_schedule_with_baselines, solve_exact,
};

/// Reference sample period of the fixtures (s).
const DT_S: f64 = 0.01;

/// The problems: name, `p_sanding`, `p_transition`, seed.
const CASES: [(&str, f64, f64, u64); 9] = [
    ("fixture", 1.0, 0.0, 0),
    ("painted", 0.0, 0.0, 1),
    ("islands_1pct", 0.01, 0.0, 2),
    ("islands_3pct", 0.03, 0.002, 3),
    ("islands_5pct", 0.05, 0.005, 4),
    ("islands_10pct", 0.1, 0.01, 5),
    ("islands_20pct", 0.2, 0.02, 6),
    ("islands_40pct", 0.4, 0.0, 7),
    ("transition_islands", 0.0, 0.01, 8),
];

/// Number of random problems.
const RANDOM: u64 = 12;

/// Random problem `k` (see the module docs): the test kit's generator in this shape.
fn random_problem(k: u64) -> Problem {
    let shape = ProblemShape {
        hc_run: 50..=800,
        lc_run: 20..=400,
        freq: 0.001..0.02,
        lo: 0.3..0.9,
        hi: 1.1..2.5,
    };
    let mut rng = ChaCha8Rng::seed_from_u64(k);
    random_problem_shaped(&mut rng, 2000..=4000, DT_S, &shape)
        .expect("bounds around a positive mean")
}

/// One row's numbers: `T*₀`, completion `T_total` and gap and wall time, sampler `T_total` and
/// gap and wall time.
struct Row {
    completion_gap: f64,
    completion_ms: f64,
    sampler_gap: f64,
    sampler_ms: f64,
    scheduler_gap: f64,
    scheduler_ms: f64,
}

/// Runs the search, the completion alone and the sampler alone on `p` and prints the row.
fn row(name: &str, p: &Problem) -> Result<Row, String> {
    let (completion_only, sampler_only) = (
        SamplerBaselines::COMPLETION_ONLY,
        SamplerBaselines::SAMPLER_ONLY,
    );
    let t = Instant::now();
    let free = solve_exact(p, &ExactParams::default()).map_err(|e| e.to_string())?;
    let search_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    let done = sample_schedule_with_baselines(p, &SamplerParams::default(), &completion_only, None)
        .map_err(|e| e.to_string())?;
    let completion_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    let sampled = sample_schedule_with_baselines(p, &SamplerParams::default(), &sampler_only, None)
        .map_err(|e| e.to_string())?;
    let sampler_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    let both = sample_schedule(p, &SamplerParams::default(), None).map_err(|e| e.to_string())?;
    let scheduler_ms = t.elapsed().as_secs_f64() * 1e3;
    let from = if done.source == Source::Completed {
        "completed"
    } else {
        "serial"
    };
    let chosen = match both.source {
        Source::Completed => "completed",
        Source::Sampled { .. } => "sampled",
        _ => "serial",
    };
    println!(
        "| {name} | {} | {:.6} | {} | {} | {search_ms:.1} | {:.3} | {from} | {:.2} % | {} | {completion_ms:.1} | {:.3} | {:.2} % | {sampler_ms:.1} | {:.3} | {chosen} | {:.2} % | {scheduler_ms:.1} |",
        free.stats.lc_runs,
        free.lower_bound_s,
        if free.proven_optimal { "yes" } else { "no" },
        free.stats.pieces,
        done.t_total_s,
        100.0 * done.gap,
        done.stats.completion_margin_checks,
        sampled.t_total_s,
        100.0 * sampled.gap,
        both.t_total_s,
        100.0 * both.gap,
    );
    Ok(Row {
        completion_gap: done.gap,
        completion_ms,
        sampler_gap: sampled.gap,
        sampler_ms,
        scheduler_gap: both.gap,
        scheduler_ms,
    })
}

/// Per reference sample: mean, min, max gradient, pass, phase is sanding, painted.
struct Fixture {
    grads: Vec<[f64; 3]>,
    pass: Vec<u32>,
    sanding: Vec<bool>,
    painted: Vec<bool>,
}

fn read_fixture(dir: &Path) -> Result<Fixture, String> {
    let read = |name: &str| {
        let p = dir.join(name);
        std::fs::read_to_string(&p).map_err(|e| format!("{}: {e}", p.display()))
    };
    let problem = read("problem.csv")?;
    let labels = read("demo_0.labels.csv")?;
    let mut fx = Fixture {
        grads: vec![],
        pass: vec![],
        sanding: vec![],
        painted: vec![],
    };
    for (i, line) in problem.lines().enumerate().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let num = |k: usize| {
            f.get(k)
                .and_then(|s| s.parse::<f64>().ok())
                .ok_or(format!("problem.csv:{}: bad field {k}", i + 1))
        };
        fx.grads.push([num(1)?, num(2)?, num(3)?]);
        fx.pass.push(num(4)? as u32);
        fx.sanding.push(f.get(5) == Some(&"sanding"));
    }
    for line in labels.lines().skip(1) {
        fx.painted.push(line.split(',').nth(2) == Some("true"));
    }
    if fx.painted.len() != fx.grads.len() {
        return Err("demo_0.labels.csv and problem.csv differ in length".into());
    }
    Ok(fx)
}

fn build(fx: &Fixture, p_sanding: f64, p_transition: f64, seed: u64) -> Problem {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let conf: Vec<bool> = (0..fx.grads.len())
        .map(|n| {
            let in_passes = (1..=3).contains(&fx.pass[n]);
            let lc = if fx.sanding[n] && in_passes {
                fx.painted[n] || rng.random_bool(p_sanding)
            } else if !fx.sanding[n] {
                rng.random_bool(p_transition)
            } else {
                false
            };
            !lc
        })
        .collect();
    let col = |k: usize| fx.grads.iter().map(|g| g[k]).collect::<Vec<f64>>();
    Problem::new(conf, col(0), col(1), col(2), DT_S).expect("fixture gradients are ordered")
}

fn write_csv(path: &Path, p: &Problem) -> Result<(), String> {
    let mut s = String::from("grad_mean,grad_min,grad_max,conf\n");
    for n in 0..p.n_ref() {
        let _ = writeln!(
            s,
            "{},{},{},{}",
            p.grad_mean()[n],
            p.grad_min()[n],
            p.grad_max()[n],
            u8::from(p.conf()[n])
        );
    }
    std::fs::write(path, s).map_err(|e| format!("{}: {e}", path.display()))
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let write_dir = match args.as_slice() {
        [] => None,
        [flag, dir] if flag == "--write" => Some(PathBuf::from(dir)),
        _ => return Err("usage: fragmented [--write DIR]".into()),
    };
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/sanding");
    let fx = read_fixture(&dir)?;
    if let Some(d) = &write_dir {
        std::fs::create_dir_all(d).map_err(|e| format!("{}: {e}", d.display()))?;
    }
    let header = "| problem | LC runs | T*0 (s) | proven | pieces | search (ms) | completion (s) | from | gap | checks | completion (ms) | sampler (s) | gap | sampler (ms) | scheduler (s) | from | gap | scheduler (ms) |";
    let rule = "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|";
    println!("{header}");
    println!("{rule}");
    for (name, p_sanding, p_transition, seed) in CASES {
        let p = build(&fx, p_sanding, p_transition, seed);
        if let Some(d) = &write_dir {
            write_csv(&d.join(format!("{name}.csv")), &p)?;
        }
        row(name, &p)?;
    }
    println!();
    println!("{header}");
    println!("{rule}");
    let rows: Vec<Row> = (0..RANDOM)
        .map(|k| row(&format!("random_{k}"), &random_problem(k)))
        .collect::<Result<_, _>>()?;
    let mean = |f: fn(&Row) -> f64| rows.iter().map(f).sum::<f64>() / rows.len() as f64;
    println!(
        "| mean of {RANDOM} | | | | | | | | {:.2} % | | {:.1} | | {:.2} % | {:.1} | | | {:.2} % | {:.1} |",
        100.0 * mean(|r| r.completion_gap),
        mean(|r| r.completion_ms),
        100.0 * mean(|r| r.sampler_gap),
        mean(|r| r.sampler_ms),
        100.0 * mean(|r| r.scheduler_gap),
        mean(|r| r.scheduler_ms),
    );
    Ok(())
}
