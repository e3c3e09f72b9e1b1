//! `cargo xtask reference-order`: how much the fitted model, and the confidence after a
//! reduced study, change when the same demonstrations are given in another order, with
//! each reference choice (`tandem::lfd::Reference`).
//!
//! The six sanding fixtures are given in their six rotations (`0 1 2 3 4 5`,
//! `1 2 3 4 5 0`, …: each demonstration first once). For each rotation and each choice
//! (`first`, `medoid`) the task model is fitted with the study's parameters
//! (`fixtures/study.toml`) and summarized on its own time axis by numbers that do not
//! depend on that axis' length: the time average and median of `σ²_D` (Eq. 6), and the
//! durations `Σ_n ψ̇(n)·Δt` of the fastest, mean and slowest demonstrated executions
//! (Eq. 14). Then a reduced study (§III; trials, executions and samples by flag) runs on
//! the model with the ground-truth labels of whichever demonstration is the reference,
//! and the final share of high-confidence samples and `T_total` are reported.
//! Per choice the spread (largest minus smallest over the rotations) says how much the
//! order matters. Prints the medoid's criterion per demonstration
//! (`TaskModel::reference_costs`), a Markdown table, and writes `reference_order.json` into
//! the output folder.

use std::path::PathBuf;

use anyhow::{Context, bail};
use serde::Serialize;
use tandem::lfd::{Demonstration, Reference, TaskModel};
use tandem::sim::study::{StudyConfig, read_labels, run_trials};

use crate::study::read_config;
use crate::workspace_root;

/// Flags of `cargo xtask reference-order`.
#[derive(clap::Args, Debug)]
pub(crate) struct ReferenceOrderArgs {
    /// Study configuration (fit, confidence, sampler and operator parameters).
    /// Default: fixtures/study.toml in the workspace.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Trials of each reduced study.
    #[arg(long, default_value_t = 2)]
    trials: usize,
    /// Executions per trial of each reduced study (even).
    #[arg(long, default_value_t = 200)]
    executions: usize,
    /// Sampler iterations per re-schedule in each reduced study.
    #[arg(long, default_value_t = 1000)]
    samples: usize,
    /// Master seed (default: the configuration's).
    #[arg(long)]
    seed: Option<u64>,
    /// Output folder (created if missing). Default: results/ in the workspace.
    #[arg(long)]
    out: Option<PathBuf>,
}

/// One fit and reduced study.
#[derive(Clone, Debug, Serialize)]
struct Row {
    /// The reference choice.
    reference: String,
    /// The order the fixtures were given in (fixture indices).
    order: Vec<usize>,
    /// The fixture that became the reference.
    reference_demo: usize,
    /// Reference samples `T_ref`.
    n_ref: usize,
    /// Time average of `σ²_D` over the reference samples.
    sigma2_d_mean: f64,
    /// Median of `σ²_D` over the reference samples.
    sigma2_d_median: f64,
    /// `Σ_n ψ̇min(n)·Δt`: the fastest demonstrated execution, seconds.
    t_fastest_s: f64,
    /// `Σ_n ψ̄̇(n)·Δt`: the mean demonstrated execution, seconds.
    t_mean_s: f64,
    /// `Σ_n ψ̇max(n)·Δt`: the slowest demonstrated execution, seconds.
    t_slowest_s: f64,
    /// High-confidence share after the reduced study (mean over trials), percent.
    high_conf_pct: f64,
    /// Ground truth of the reference's labels, percent.
    ground_truth_pct: f64,
    /// Planned `T_total` after the reduced study (mean over trials), seconds.
    t_total_s: f64,
    /// Ticks with both robots low-confidence in the reduced study (must be 0).
    overlap_ticks: usize,
}

/// The numbers a row reports, in table order, with their decimals.
fn metrics(r: &Row) -> [(f64, usize); 10] {
    [
        (r.n_ref as f64, 0),
        (r.sigma2_d_mean, 5),
        (r.sigma2_d_median, 5),
        (r.t_fastest_s, 2),
        (r.t_mean_s, 2),
        (r.t_slowest_s, 2),
        (r.high_conf_pct, 2),
        (r.ground_truth_pct, 2),
        (r.high_conf_pct - r.ground_truth_pct, 2),
        (r.t_total_s, 2),
    ]
}

/// The table's header (Markdown).
const HEADER: &str = "| reference | order | ref demo | n_ref | mean σ²_D | median σ²_D | fastest (s) \
    | mean (s) | slowest (s) | HC % after | ground truth % | HC − truth (pp) | T_total after (s) |\n\
    |---|---|---|---|---|---|---|---|---|---|---|---|---|";

/// One Markdown table line: three label cells, then the values.
fn line(labels: [&str; 3], values: &[(f64, usize)]) -> String {
    let cells: Vec<String> = values
        .iter()
        .map(|&(v, decimals)| format!("{v:.decimals$}"))
        .collect();
    format!("| {} | {} |", labels.join(" | "), cells.join(" | "))
}

fn median(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    let k = v.len() / 2;
    if v.len() % 2 == 0 {
        0.5 * (v[k - 1] + v[k])
    } else {
        v[k]
    }
}

/// Fits on the fixtures in `order` with `reference`, runs the reduced study, reports.
fn run_one(
    config: &StudyConfig,
    demos: &[Demonstration],
    labels_path: &dyn Fn(usize) -> PathBuf,
    order: Vec<usize>,
    reference: Reference,
) -> anyhow::Result<Row> {
    let given: Vec<Demonstration> = order.iter().map(|&i| demos[i].clone()).collect();
    let mut fit = config.planner.fit.clone();
    fit.reference = reference;
    let model = TaskModel::fit(&given, &fit).context("fitting the fixtures")?;
    model.prepare_corrections();
    let reference_demo = order[model.reference_idx()];
    let labels = read_labels(&labels_path(reference_demo))?;
    let (result, _) = run_trials(config, &model, &labels, &|_| {})?;
    let summary = result.summary();
    let last = summary.last().context("a study has iterations")?;
    let dt = model.dt_s();
    let n_ref = model.n_ref();
    let duration = |g: &[f64]| g.iter().sum::<f64>() * dt;
    Ok(Row {
        reference: reference.to_string(),
        order,
        reference_demo,
        n_ref,
        sigma2_d_mean: model.sigma2_d().iter().sum::<f64>() / n_ref as f64,
        sigma2_d_median: median(model.sigma2_d()),
        t_fastest_s: duration(model.grad_min()),
        t_mean_s: duration(model.grad_mean()),
        t_slowest_s: duration(model.grad_max()),
        high_conf_pct: last.high_conf_pct_mean,
        ground_truth_pct: result.ground_truth_pct,
        t_total_s: last.t_total_mean_s,
        overlap_ticks: result.total_overlap_ticks(),
    })
}

/// Runs `cargo xtask reference-order`.
pub(crate) fn run(args: &ReferenceOrderArgs) -> anyhow::Result<()> {
    let root = workspace_root();
    let (mut config, path) = read_config(args.config.as_deref())?;
    config.trials = args.trials;
    config.executions = args.executions;
    config.samples = args.samples;
    if let Some(seed) = args.seed {
        config.seed = seed;
    }
    config
        .validate()
        .with_context(|| format!("study configuration {} with flags", path.display()))?;
    let fixtures = root.join("fixtures/sanding");
    let n_demos = 6;
    let demos = (0..n_demos)
        .map(|i| Demonstration::from_csv_path(fixtures.join(format!("demo_{i}.csv")), None))
        .collect::<Result<Vec<_>, _>>()?;
    let labels_path = |i: usize| fixtures.join(format!("demo_{i}.labels.csv"));

    let costs = TaskModel::reference_costs(&demos, &config.planner.fit)?;
    let costs: Vec<String> = costs
        .iter()
        .enumerate()
        .map(|(i, c)| format!("demo {i} {c:.4}"))
        .collect();
    println!(
        "medoid criterion (total alignment objective with each demo as the reference): {}",
        costs.join(", ")
    );
    println!(
        "reduced study: {} trials × {} executions, {} samples per schedule, seed {}",
        config.trials, config.executions, config.samples, config.seed
    );
    println!();
    println!("{HEADER}");
    let mut rows = Vec::new();
    for reference in [Reference::First, Reference::Medoid] {
        let mut group = Vec::new();
        for first in 0..n_demos {
            let order: Vec<usize> = (0..n_demos).map(|k| (first + k) % n_demos).collect();
            let row = run_one(&config, &demos, &labels_path, order, reference)?;
            let order_text: Vec<String> = row.order.iter().map(ToString::to_string).collect();
            println!(
                "{}",
                line(
                    [
                        &row.reference,
                        &order_text.join(" "),
                        &row.reference_demo.to_string()
                    ],
                    &metrics(&row)
                )
            );
            group.push(row);
        }
        // Largest minus smallest over the orders, per column.
        let spread: Vec<(f64, usize)> = (0..metrics(&group[0]).len())
            .map(|k| {
                let values = group.iter().map(|r| metrics(r)[k].0);
                let hi = values.clone().fold(f64::NEG_INFINITY, f64::max);
                let lo = values.fold(f64::INFINITY, f64::min);
                (hi - lo, metrics(&group[0])[k].1)
            })
            .collect();
        let name = reference.to_string();
        println!("{}", line([&name, "**spread**", "–"], &spread));
        rows.extend(group);
    }
    let overlaps: usize = rows.iter().map(|r| r.overlap_ticks).sum();
    println!();
    println!("overlapping low-confidence ticks over all reduced studies: {overlaps}");
    let out = args.out.clone().unwrap_or_else(|| root.join("results"));
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let file = out.join("reference_order.json");
    std::fs::write(&file, serde_json::to_string_pretty(&rows)? + "\n")
        .with_context(|| format!("writing {}", file.display()))?;
    println!("wrote {}", file.display());
    if overlaps > 0 {
        bail!("both robots were low-confidence in the same tick: the schedule is unsafe");
    }
    Ok(())
}
