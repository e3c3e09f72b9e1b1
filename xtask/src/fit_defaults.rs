//! `cargo xtask fit-defaults`: what a user sees right after `fit` on the task zoo, for every
//! choice of the first file and for the fit's default reference (issue 38).
//!
//! For every family of `tandem_zoo` and every seed of the chosen split (the selection seeds
//! by default; `--held-out` for the one confirmation run), the demonstrations are fitted with
//! the default `FitParams` once per choice of first file (the files rotated so that file `i`
//! comes first, `reference = first`), once with `reference = medoid` and once with the
//! default reference. Each fit is read the way the planner reads it first: the confidence
//! from the prior alone (`Confidence::from_prior` on `σ²_D` with the default
//! `ConfidenceParams`, which is what `Planner::new` computes before it schedules). Reported
//! per fit: the high-confidence share of the reference samples, the number of low-confidence
//! regions and of short islands among them (fewer than [`SHORT_ISLAND`] samples), the
//! high-confidence samples on the task's variable spans (where the demonstrations differ,
//! so trusting them is wrong), the truth (`ZooTask::true_high_share` of the reference demo)
//! and the fit's notes. Per family the table gives means over the seeds; the gap is the best
//! single-file choice's high-confidence share minus the default's, per seed.
//!
//! Writes `fit_defaults.json` (every fit) into the output folder; `--detail FAMILY:SEED`
//! also writes `fit_defaults_<family>_<seed>.csv`, the default fit's per-sample `σ²_D`, its
//! rate term and confidence against the reference's true progress.

use std::path::PathBuf;

use anyhow::Context;
use rayon::prelude::*;
use serde::Serialize;
use tandem::confidence::{Confidence, ConfidenceParams, runs};
use tandem::lfd::{Demonstration, FitParams, RateTerm, Reference, TaskModel};
use tandem::sim::study::read_labels;
use tandem::sim::task::Label;
use tandem::sim::truth::needs_help;
use tandem_zoo::ZooTask;

use crate::study::read_config;
use crate::workspace_root;

/// A low-confidence region shorter than this many reference samples is a short island.
const SHORT_ISLAND: usize = 13;

/// Flags of `cargo xtask fit-defaults`.
#[derive(clap::Args, Debug)]
pub(crate) struct FitDefaultsArgs {
    /// Run on the held-out seeds (the one confirmation run; never tune on it).
    #[arg(long)]
    held_out: bool,
    /// Only this family (default: all eight).
    #[arg(long)]
    family: Option<String>,
    /// Write the default fit's per-sample detail of one task, `FAMILY:SEED`, or of every task
    /// measured, `all`.
    #[arg(long)]
    detail: Option<String>,
    /// Output folder (created if missing). Default: results/ in the workspace.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Fit with this rate term instead of the default (`absolute`, `relative`,
    /// `relative:opening=N,window=M`), the sanding row too: a variant to compare.
    #[arg(long, value_name = "FORM")]
    rate_term: Option<RateTerm>,
}

/// What one fit shows the user.
#[derive(Clone, Debug, Serialize)]
struct FitView {
    /// Which reference choice: `first:<i>` (file `i` given first), `medoid`, `default`.
    choice: String,
    /// The demonstration that became the reference (index into the task's files).
    reference_demo: usize,
    /// Reference samples.
    n_ref: usize,
    /// High-confidence share from the prior, percent.
    high_pct: f64,
    /// High-confidence share from the prior with the rate term taken out of `σ²_D`, percent
    /// (how much of the low confidence is the demonstrations' speed alone).
    high_without_rate_pct: f64,
    /// The truth: share of the reference demonstration that never needs the operator, percent.
    truth_pct: f64,
    /// Low-confidence regions (maximal runs).
    lc_regions: usize,
    /// Low-confidence regions shorter than [`SHORT_ISLAND`] samples.
    short_islands: usize,
    /// High-confidence reference samples on the task's variable spans.
    variable_high: usize,
    /// Reference samples on the task's variable spans.
    variable_samples: usize,
    /// Time average of `σ²_D` over the reference samples.
    sigma2_mean: f64,
    /// Median of `σ²_D` over the reference samples.
    sigma2_median: f64,
    /// Percentiles 1–99 of `σ²_D` over the reference samples (reference criteria compared
    /// offline, `scripts/reference_criteria.py`).
    sigma2_percentiles: Vec<f64>,
    /// The rate coordinate's range the fit used (demo samples per reference sample).
    rate_range: f64,
    /// The fit's notes.
    notes: Vec<String>,
}

/// Every fit of one task.
#[derive(Clone, Debug, Serialize)]
struct TaskRow {
    family: String,
    seed: u64,
    n_demos: usize,
    rate_hz: f64,
    /// One per choice of first file, in file order.
    first: Vec<FitView>,
    medoid: FitView,
    default: FitView,
}

impl TaskRow {
    fn best_first(&self) -> f64 {
        self.first
            .iter()
            .map(|f| f.high_pct)
            .fold(f64::NEG_INFINITY, f64::max)
    }
    fn worst_first(&self) -> f64 {
        self.first
            .iter()
            .map(|f| f.high_pct)
            .fold(f64::INFINITY, f64::min)
    }
}

/// Whether progress `p` lies in one of the task's variable spans.
fn in_variable(task: &ZooTask, p: f64) -> bool {
    task.variable.iter().any(|&(a, b)| a <= p && p < b)
}

/// The truth of a task on the axis of one of its demonstrations.
trait Truth: Sync {
    /// What the fit is called in errors.
    fn name(&self) -> String;
    /// Share of demonstration `i` that never needs the operator, in `[0, 1]`.
    fn high_share(&self, i: usize) -> f64;
    /// Per sample of demonstration `i`: whether it lies where the demonstrations vary and
    /// the operator is needed (trusting it from the prior is wrong).
    fn variable(&self, i: usize) -> Vec<bool>;
}

impl Truth for ZooTask {
    fn name(&self) -> String {
        format!("{} seed {}", self.family, self.seed)
    }
    fn high_share(&self, i: usize) -> f64 {
        self.true_high_share(i)
    }
    fn variable(&self, i: usize) -> Vec<bool> {
        self.progress[i]
            .iter()
            .map(|&p| in_variable(self, p))
            .collect()
    }
}

/// The sanding fixtures with every demonstration's labels.
struct Sanding {
    labels: Vec<Vec<Label>>,
}

impl Truth for Sanding {
    fn name(&self) -> String {
        "sanding fixtures".into()
    }
    fn high_share(&self, i: usize) -> f64 {
        let free = self.labels[i].iter().filter(|l| !needs_help(l)).count();
        free as f64 / self.labels[i].len() as f64
    }
    fn variable(&self, i: usize) -> Vec<bool> {
        self.labels[i].iter().map(needs_help).collect()
    }
}

/// Fits `demos` (already in the order to give) with `fit` and reads the result.
/// `order[k]` is the task's file index of `demos[k]`.
fn view(
    truth: &dyn Truth,
    demos: &[Demonstration],
    order: &[usize],
    fit: &FitParams,
    choice: String,
) -> anyhow::Result<(FitView, TaskModel, Confidence)> {
    let model =
        TaskModel::fit(demos, fit).with_context(|| format!("{}: fit ({choice})", truth.name()))?;
    let conf = Confidence::from_prior(model.sigma2_d(), ConfidenceParams::default())?;
    let reference_demo = order[model.reference_idx()];
    let high = conf.conf();
    let lc: Vec<_> = runs(high).into_iter().filter(|r| !r.high_conf).collect();
    let on_variable = truth.variable(reference_demo);
    let d = model.tangent_names().len();
    let rate_range = model.ranges()[d - 1];
    let without_rate: Vec<f64> = (0..model.n_ref())
        .map(|n| {
            let rate_term = model.covariance(n)[d * d - 1] / (rate_range * rate_range);
            (model.sigma2_d()[n] - rate_term).max(0.0)
        })
        .collect();
    let conf_without_rate = Confidence::from_prior(&without_rate, ConfidenceParams::default())?;
    let view = FitView {
        choice,
        reference_demo,
        n_ref: model.n_ref(),
        high_pct: 100.0 * conf.high_share(),
        high_without_rate_pct: 100.0 * conf_without_rate.high_share(),
        truth_pct: 100.0 * truth.high_share(reference_demo),
        lc_regions: lc.len(),
        short_islands: lc.iter().filter(|r| r.end - r.start < SHORT_ISLAND).count(),
        variable_high: high
            .iter()
            .zip(&on_variable)
            .filter(|(h, v)| **h && **v)
            .count(),
        variable_samples: on_variable.iter().filter(|v| **v).count(),
        sigma2_mean: model.sigma2_d().iter().sum::<f64>() / model.n_ref() as f64,
        sigma2_median: {
            let mut v = model.sigma2_d().to_vec();
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        },
        sigma2_percentiles: {
            let mut v = model.sigma2_d().to_vec();
            v.sort_by(f64::total_cmp);
            (1..100).map(|q| v[(q * (v.len() - 1)) / 100]).collect()
        },
        rate_range,
        notes: Vec::new(),
    };
    Ok((view, model, conf))
}

/// Writes the per-sample detail of the default fit.
type WriteDetail<'a> = dyn Fn(&FitView, &TaskModel, &Confidence) -> anyhow::Result<()> + 'a;

/// Every fit of one task (the first-file choices in parallel), with `base` as the fit
/// parameters (their reference replaced for the first-file choices and the medoid).
fn measure(
    truth: &dyn Truth,
    demos: &[Demonstration],
    base: &FitParams,
    detail: Option<&WriteDetail<'_>>,
) -> anyhow::Result<(Vec<FitView>, FitView, FitView)> {
    let n = demos.len();
    let rotated = |first: usize| -> (Vec<Demonstration>, Vec<usize>) {
        let order: Vec<usize> = (0..n).map(|k| (first + k) % n).collect();
        (order.iter().map(|&i| demos[i].clone()).collect(), order)
    };
    let first = (0..n)
        .into_par_iter()
        .map(|i| {
            let (given, order) = rotated(i);
            let fit = FitParams {
                reference: Reference::First,
                ..base.clone()
            };
            Ok(view(truth, &given, &order, &fit, format!("first:{i}"))?.0)
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let identity: Vec<usize> = (0..n).collect();
    let medoid_fit = FitParams {
        reference: Reference::Medoid,
        ..base.clone()
    };
    let (medoid, medoid_model, medoid_conf) =
        view(truth, demos, &identity, &medoid_fit, "medoid".into())?;
    let (default, model, conf) = if base.reference == Reference::Medoid {
        // The default fit is the medoid's: the same model, not fitted twice.
        let default = FitView {
            choice: "default".into(),
            ..medoid.clone()
        };
        (default, medoid_model, medoid_conf)
    } else {
        view(truth, demos, &identity, base, "default".into())?
    };
    if let Some(write) = detail {
        write(&default, &model, &conf)?;
    }
    Ok((first, medoid, default))
}

/// Every fit of one zoo task.
fn measure_task(
    task: &ZooTask,
    detail: Option<&PathBuf>,
    rate_term: Option<RateTerm>,
) -> anyhow::Result<TaskRow> {
    let demos = task.demos()?;
    let write = |view: &FitView, model: &TaskModel, conf: &Confidence| {
        let progress = &task.progress[view.reference_demo];
        let need: Vec<f64> = progress.iter().map(|&p| task.need_at(p)).collect();
        let variable = task.variable(view.reference_demo);
        let name = format!("{}_{}", task.family, task.seed);
        write_detail(
            detail.expect("called with a folder"),
            &name,
            progress,
            &need,
            &variable,
            model,
            conf,
        )
    };
    let (first, medoid, default) = measure(
        task,
        &demos,
        &FitParams {
            rate_term: rate_term.unwrap_or_default(),
            ..FitParams::default()
        },
        detail.is_some().then_some(&write as _),
    )?;
    Ok(TaskRow {
        family: task.family.to_owned(),
        seed: task.seed,
        n_demos: demos.len(),
        rate_hz: task.rate_hz,
        first,
        medoid,
        default,
    })
}

/// Every fit of the sanding fixtures with the study's fit parameters.
fn measure_sanding(
    detail: Option<&PathBuf>,
    rate_term: Option<RateTerm>,
) -> anyhow::Result<TaskRow> {
    let root = workspace_root();
    let (mut config, _) = read_config(None)?;
    if let Some(rate_term) = rate_term {
        config.planner.fit.rate_term = rate_term;
    }
    let dir = root.join("fixtures/sanding");
    let n_demos = 6;
    let demos = (0..n_demos)
        .map(|i| Demonstration::from_csv_path(dir.join(format!("demo_{i}.csv")), None))
        .collect::<Result<Vec<_>, _>>()?;
    let labels = (0..n_demos)
        .map(|i| read_labels(&dir.join(format!("demo_{i}.labels.csv"))))
        .collect::<Result<Vec<_>, _>>()?;
    let truth = Sanding { labels };
    let write = |view: &FitView, model: &TaskModel, conf: &Confidence| {
        let labels = &truth.labels[view.reference_demo];
        let progress: Vec<f64> = (0..labels.len())
            .map(|n| n as f64 / (labels.len() - 1) as f64)
            .collect();
        let need: Vec<f64> = labels
            .iter()
            .map(|l| f64::from(u8::from(needs_help(l))))
            .collect();
        let variable = truth.variable(view.reference_demo);
        write_detail(
            detail.expect("called with a folder"),
            "sanding",
            &progress,
            &need,
            &variable,
            model,
            conf,
        )
    };
    let (first, medoid, default) = measure(
        &truth,
        &demos,
        &config.planner.fit,
        detail.is_some().then_some(&write as _),
    )?;
    Ok(TaskRow {
        family: "sanding (study.toml)".into(),
        seed: config.seed,
        n_demos,
        rate_hz: 1.0 / demos[0].dt_s(),
        first,
        medoid,
        default,
    })
}

/// The default fit's per-sample detail: reference progress, need, whether the sample lies on a
/// variable span, `σ²_D`, its rate term (the gradients' variance over the squared rate range,
/// before the local pace and the filter) and the confidence.
fn write_detail(
    dir: &std::path::Path,
    name: &str,
    progress: &[f64],
    need: &[f64],
    variable: &[bool],
    model: &TaskModel,
    conf: &Confidence,
) -> anyhow::Result<()> {
    let d = model.tangent_names().len();
    let rate_range = model.ranges()[d - 1];
    let mut text = String::from("n,progress,need,variable,sigma2_d,rate_term,grad_mean,high\n");
    for n in 0..model.n_ref() {
        let cov = model.covariance(n);
        let rate_term = cov[d * d - 1] / (rate_range * rate_range);
        text.push_str(&format!(
            "{n},{:.6},{},{},{:.6e},{:.6e},{:.4},{}\n",
            progress[n],
            need[n],
            u8::from(variable[n]),
            model.sigma2_d()[n],
            rate_term,
            model.grad_mean()[n],
            u8::from(conf.conf()[n])
        ));
    }
    let file = dir.join(format!("fit_defaults_{name}.csv"));
    std::fs::write(&file, text).with_context(|| format!("writing {}", file.display()))?;
    println!("wrote {}", file.display());
    Ok(())
}

/// Mean of `f` over `rows`.
fn mean(rows: &[TaskRow], f: impl Fn(&TaskRow) -> f64) -> f64 {
    rows.iter().map(f).sum::<f64>() / rows.len() as f64
}

/// The Markdown table's header.
const HEADER: &str = "| family | seeds | demos | HC first: worst / mean / best % | HC medoid % | \
    HC default % | best − default pp (mean / worst seed) | truth % (default's ref) | \
    LC regions first (mean) / default | short islands first (mean) / default | \
    variable HC default / samples | rate range |\n\
    |---|---|---|---|---|---|---|---|---|---|---|---|";

/// One table line over the seeds of one family (or all).
fn table_line(name: &str, rows: &[TaskRow]) -> String {
    let first_mean = |r: &TaskRow, f: &dyn Fn(&FitView) -> f64| {
        r.first.iter().map(f).sum::<f64>() / r.first.len() as f64
    };
    let gaps: Vec<f64> = rows
        .iter()
        .map(|r| r.best_first() - r.default.high_pct)
        .collect();
    let worst_gap = gaps.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let (dmin, dmax) = rows.iter().fold((usize::MAX, 0), |(lo, hi), r| {
        (lo.min(r.n_demos), hi.max(r.n_demos))
    });
    format!(
        "| {name} | {} | {dmin}–{dmax} | {:.1} / {:.1} / {:.1} | {:.1} | {:.1} | {:.2} / {:.2} | \
         {:.1} | {:.1} / {:.1} | {:.1} / {:.1} | {:.0} / {:.0} | {:.3} |",
        rows.len(),
        mean(rows, TaskRow::worst_first),
        mean(rows, |r| first_mean(r, &|f| f.high_pct)),
        mean(rows, TaskRow::best_first),
        mean(rows, |r| r.medoid.high_pct),
        mean(rows, |r| r.default.high_pct),
        gaps.iter().sum::<f64>() / gaps.len() as f64,
        worst_gap,
        mean(rows, |r| r.default.truth_pct),
        mean(rows, |r| first_mean(r, &|f| f.lc_regions as f64)),
        mean(rows, |r| r.default.lc_regions as f64),
        mean(rows, |r| first_mean(r, &|f| f.short_islands as f64)),
        mean(rows, |r| r.default.short_islands as f64),
        mean(rows, |r| r.default.variable_high as f64),
        mean(rows, |r| r.default.variable_samples as f64),
        mean(rows, |r| r.default.rate_range),
    )
}

/// Runs `cargo xtask fit-defaults`.
pub(crate) fn run(args: &FitDefaultsArgs) -> anyhow::Result<()> {
    let root = workspace_root();
    let out = args.out.clone().unwrap_or_else(|| root.join("results"));
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let seeds = if args.held_out {
        tandem_zoo::HELD_OUT_SEEDS
    } else {
        tandem_zoo::SELECTION_SEEDS
    };
    let families: Vec<&tandem_zoo::Family> = match &args.family {
        Some(name) => vec![tandem_zoo::family(name)?],
        None => tandem_zoo::families().iter().collect(),
    };
    let detail: Option<(String, u64)> = match &args.detail {
        Some(spec) if spec == "all" => None,
        Some(spec) => {
            let (family, seed) = spec
                .split_once(':')
                .context("--detail takes FAMILY:SEED, e.g. dispensing:3")?;
            Some((family.to_owned(), seed.parse().context("--detail's seed")?))
        }
        None => None,
    };
    if let Some(rate_term) = args.rate_term {
        println!("rate term: {rate_term}");
    }
    println!(
        "seeds {}..{} ({}), short island < {SHORT_ISLAND} samples",
        seeds.start,
        seeds.end,
        if args.held_out {
            "held out"
        } else {
            "selection"
        }
    );
    let started = std::time::Instant::now();
    let mut all = Vec::new();
    let mut lines = Vec::new();
    for family in families {
        let mut rows = Vec::new();
        for seed in seeds.clone() {
            let task = (family.generate)(seed)?;
            let want_detail = args.detail.as_deref() == Some("all")
                || detail
                    .as_ref()
                    .is_some_and(|(f, s)| f == family.name && *s == seed);
            let row = measure_task(&task, want_detail.then_some(&out), args.rate_term)?;
            eprintln!(
                "{} seed {seed}: {} demos, HC first {:.1}–{:.1} %, medoid {:.1} %, default {:.1} % \
                 (truth {:.1} %), LC regions {} ({} short){}",
                family.name,
                row.n_demos,
                row.worst_first(),
                row.best_first(),
                row.medoid.high_pct,
                row.default.high_pct,
                row.default.truth_pct,
                row.default.lc_regions,
                row.default.short_islands,
                if row.default.notes.is_empty() {
                    String::new()
                } else {
                    format!("; notes: {}", row.default.notes.join(" | "))
                }
            );
            rows.push(row);
        }
        lines.push(table_line(family.name, &rows));
        all.extend(rows);
    }
    let sanding_detail = detail.as_ref().is_some_and(|(f, _)| f == "sanding");
    let sanding = measure_sanding(sanding_detail.then_some(&out), args.rate_term)?;
    eprintln!(
        "sanding: HC first {:.1}–{:.1} %, medoid {:.1} %, default {:.1} % (truth {:.1} %), \
         LC regions {} ({} short), falsely trusted {}",
        sanding.worst_first(),
        sanding.best_first(),
        sanding.medoid.high_pct,
        sanding.default.high_pct,
        sanding.default.truth_pct,
        sanding.default.lc_regions,
        sanding.default.short_islands,
        sanding.default.variable_high,
    );
    println!();
    println!("{HEADER}");
    for line in &lines {
        println!("{line}");
    }
    if lines.len() > 1 {
        println!("{}", table_line("**all**", &all));
    }
    println!(
        "{}",
        table_line("sanding (study.toml)", std::slice::from_ref(&sanding))
    );
    all.push(sanding);
    println!();
    println!("{:.1} s", started.elapsed().as_secs_f64());
    let file = out.join(if args.held_out {
        "fit_defaults_held_out.json"
    } else {
        "fit_defaults.json"
    });
    std::fs::write(&file, serde_json::to_string_pretty(&all)? + "\n")
        .with_context(|| format!("writing {}", file.display()))?;
    println!("wrote {}", file.display());
    Ok(())
}
