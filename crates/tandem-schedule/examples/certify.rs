//! A certified schedule for a problem file: the margin-free lower bound `T*₀` (exact search),
//! the margin-aware completion and, with `--seed`, the sampler beside it (the scheduler the
//! planner runs, `sample_schedule`).
//!
//! ```text
//! cargo run --release -p tandem-schedule --example certify -- PROBLEM.csv [--dt 0.01] [--seed S]
//! ```
//!
//! `PROBLEM.csv`: a header, then one row per reference sample with the columns
//! `grad_mean,grad_min,grad_max,conf` in any order (`conf` 1 = high confidence, 0 = low; other
//! columns are ignored). Without a `conf` column, the columns `pass,phase` of
//! `fixtures/sanding/problem.csv` are read instead (low confidence = sanding in passes 1–3).
//! `--dt`: the reference sample period `Δt_s` (s), default 0.01; the margin check runs at a
//! control tick of `Δt_s`. `--seed S`: also run the sampler (5000 samples, seed `S`) and keep
//! its schedule if it is better; without it, no candidate is sampled
//! (`SamplerBaselines::completion_only`).
//!
//! Prints one JSON object `{"t_total_s", "lower_bound_s", "gap", "wall_ms", "accepted"}` for the
//! schedule it returns (`accepted`: it passes `validate` at tick `Δt_s`; `wall_ms`: the time of
//! the whole re-schedule: search, completion and sampler). Bad input: a message naming the file and the
//! line on stderr, exit code 2.
#![allow(clippy::print_stdout, reason = "an example reports to the terminal")]

use std::process::ExitCode;
use std::time::Instant;

use tandem_schedule::{
    Problem, SamplerBaselines, SamplerParams, sample_schedule_with_baselines, validate,
};

/// Command-line arguments.
struct Args {
    path: String,
    dt_s: f64,
    seed: Option<u64>,
}

fn parse_args() -> Result<Args, String> {
    let mut args = std::env::args().skip(1);
    let mut path = None;
    let mut dt_s = 0.01;
    let mut seed = None;
    while let Some(a) = args.next() {
        match a.as_str() {
            "--dt" => {
                let v = args.next().ok_or("--dt needs a value (s)")?;
                dt_s = v
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite() && *x > 0.0)
                    .ok_or_else(|| format!("--dt: `{v}` is not a finite period > 0 (s)"))?;
            }
            "--seed" => {
                let v = args.next().ok_or("--seed needs a value")?;
                seed = Some(
                    v.parse::<u64>()
                        .map_err(|_| format!("--seed: `{v}` is not an unsigned integer"))?,
                );
            }
            _ if a.starts_with("--") => return Err(format!("unknown option `{a}`")),
            _ if path.is_none() => path = Some(a),
            _ => return Err(format!("unexpected argument `{a}`")),
        }
    }
    let path = path.ok_or("usage: certify PROBLEM.csv [--dt 0.01] [--seed S]")?;
    Ok(Args { path, dt_s, seed })
}

/// Reads a problem file (see the module docs); errors name the file and the line.
fn read_problem(path: &str, dt_s: f64) -> Result<Problem, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{path}: cannot read: {e}"))?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let (_, header) = lines
        .next()
        .ok_or_else(|| format!("{path}:1: empty file, expected a header"))?;
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let col = |name: &str| names.iter().position(|n| *n == name);
    let need = |name: &str| col(name).ok_or_else(|| format!("{path}:1: missing column `{name}`"));
    let (i_mean, i_min, i_max) = (need("grad_mean")?, need("grad_min")?, need("grad_max")?);
    let conf_col = match col("conf") {
        Some(i) => ConfColumn::Conf(i),
        None => match (col("pass"), col("phase")) {
            (Some(p), Some(h)) => ConfColumn::PassPhase(p, h),
            _ => {
                return Err(format!(
                    "{path}:1: missing column `conf` (or `pass` and `phase`)"
                ));
            }
        },
    };
    let (mut conf, mut mean, mut min, mut max, mut line_of) =
        (vec![], vec![], vec![], vec![], vec![]);
    for (i, line) in lines {
        let lineno = i + 1;
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        if f.len() != names.len() {
            return Err(format!(
                "{path}:{lineno}: {} fields, the header has {}",
                f.len(),
                names.len()
            ));
        }
        let num = |k: usize| {
            f[k].parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| {
                    format!(
                        "{path}:{lineno}: `{}` = `{}` is not a finite number",
                        names[k], f[k]
                    )
                })
        };
        mean.push(num(i_mean)?);
        min.push(num(i_min)?);
        max.push(num(i_max)?);
        conf.push(match conf_col {
            ConfColumn::Conf(k) => match f[k] {
                "1" | "true" => true,
                "0" | "false" => false,
                v => return Err(format!("{path}:{lineno}: `conf` = `{v}`, expected 1 or 0")),
            },
            ConfColumn::PassPhase(p, h) => {
                let pass: u32 = f[p].parse().map_err(|_| {
                    format!("{path}:{lineno}: `pass` = `{}` is not a pass number", f[p])
                })?;
                !(f[h] == "sanding" && (1..=3).contains(&pass))
            }
        });
        line_of.push(lineno);
    }
    if mean.is_empty() {
        return Err(format!("{path}:2: no data rows after the header"));
    }
    Problem::new(conf, mean, min, max, dt_s).map_err(|e| match e {
        tandem_schedule::Error::BadBounds { ref_idx, .. }
        | tandem_schedule::Error::NonFinite { ref_idx, .. } => {
            format!("{path}:{}: {e}", line_of[ref_idx])
        }
        _ => format!("{path}: {e}"),
    })
}

/// The printed object, in this field order.
#[derive(serde::Serialize)]
struct Report {
    t_total_s: f64,
    lower_bound_s: f64,
    gap: f64,
    wall_ms: f64,
    accepted: bool,
}

/// Where the confidence comes from.
#[derive(Clone, Copy)]
enum ConfColumn {
    /// A `conf` column (1 = high).
    Conf(usize),
    /// The fixture's `pass` and `phase` columns.
    PassPhase(usize, usize),
}

fn run() -> Result<String, String> {
    let args = parse_args()?;
    let problem = read_problem(&args.path, args.dt_s)?;
    let params = SamplerParams {
        seed: args.seed.unwrap_or(0),
        ..SamplerParams::default()
    };
    let baselines = SamplerBaselines {
        completion_only: args.seed.is_none(),
        ..SamplerBaselines::default()
    };
    let start = Instant::now();
    let out = sample_schedule_with_baselines(&problem, &params, &baselines, None)
        .map_err(|e| format!("{}: {e}", args.path))?;
    let wall_ms = start.elapsed().as_secs_f64() * 1e3;
    let accepted = validate(&problem, &out.schedule).is_ok();
    let report = Report {
        t_total_s: out.t_total_s,
        lower_bound_s: out.lower_bound_s,
        gap: out.gap,
        wall_ms,
        accepted,
    };
    serde_json::to_string(&report).map_err(|e| format!("cannot write JSON: {e}"))
}

fn main() -> ExitCode {
    match run() {
        Ok(json) => {
            println!("{json}");
            ExitCode::SUCCESS
        }
        Err(msg) => {
            eprintln!("certify: {msg}");
            ExitCode::from(2)
        }
    }
}
