//! `cargo xtask capacity`: how many robots can one operator run on this task?
//!
//! Runs the study of §III (`tandem::sim::study`) once per robot count `N = 1..=max_robots`
//! with reduced sizes (defaults: 3 trials, 240 executions per trial rounded down to a
//! multiple of `N`, 2000 sampler candidates per re-schedule, the configuration file's seed;
//! see [`CapacityArgs`]), and reports at the end of learning, per `N`:
//!
//! - `T_total` of the final schedule (mean ± std over trials, s);
//! - the planned throughput `N·3600 / T_total` (tasks per hour per operator), mean over trials;
//! - the operator busy share (share of a round's control ticks in which some robot was
//!   low-confidence) and the supervised seconds per task, both averaged over the rounds of
//!   the last [`END_SHARE`] of each trial (at least one round) and over trials;
//! - overlapping low-confidence ticks over every round of every trial (must be 0).
//!
//! The operator-limited bound is `3600 / E[low-confidence seconds per task]`: one operator
//! supervising one robot at a time can support at most that many tasks per hour, however many
//! robots run. `E[·]` pools the end-of-learning supervised seconds per task of every `N`.
//!
//! Writes `capacity.json`, `capacity.svg` and `capacity.png` under the output folder
//! (default `results/capacity/`) and prints the table (docs/study.md quotes it).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, anyhow, bail};
use plotters::prelude::*;
use serde::Serialize;
use tandem::realtime::MAX_ROBOTS;
use tandem::sim::study::{
    StudyConfig, StudyInputs, StudyResult, mean_std, run_study, throughput_per_h,
};
use tandem_plot::{FONT_FAMILY, GROUND_TRUTH, MEAN, OPERATOR};

use crate::study::read_config;
use crate::workspace_root;

/// Share of a trial's rounds, at its end, over which the busy share and the supervised time
/// per task are averaged ("the end of learning").
pub(crate) const END_SHARE: f64 = 0.1;

/// Flags of `cargo xtask capacity`.
#[derive(clap::Args, Debug)]
pub(crate) struct CapacityArgs {
    /// Largest robot count (runs N = 1..=this).
    #[arg(long, default_value_t = MAX_ROBOTS)]
    max_robots: usize,
    /// Trials per robot count.
    #[arg(long, default_value_t = 3)]
    trials: usize,
    /// Executions per trial, rounded down to a multiple of N for each N.
    #[arg(long, default_value_t = 240)]
    executions: usize,
    /// Sampler candidates per re-schedule.
    #[arg(long, default_value_t = 2000)]
    samples: usize,
    /// Master seed (default: the configuration file's).
    #[arg(long)]
    seed: Option<u64>,
    /// Study configuration (default: fixtures/study.toml).
    #[arg(long)]
    config: Option<PathBuf>,
    /// Output folder. Default: results/capacity/ in the workspace.
    #[arg(long)]
    out: Option<PathBuf>,
}

/// One robot count's result at the end of learning.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub(crate) struct CapacityRow {
    /// Robots `N`.
    pub robots: usize,
    /// Executions per trial actually run (a multiple of `N`).
    pub executions: usize,
    /// Rounds per trial.
    pub rounds: usize,
    /// Mean `T_total` of the final schedules (s).
    pub t_total_mean_s: f64,
    /// Sample standard deviation of that `T_total` across trials (s).
    pub t_total_std_s: f64,
    /// Mean planned throughput of the final schedules, `N·3600 / T_total` (tasks per hour per
    /// operator).
    pub throughput_per_h: f64,
    /// Mean operator busy share over the last rounds (in [0, 1]).
    pub operator_busy_share: f64,
    /// Mean supervised (low-confidence) seconds per task over the last rounds (s).
    pub lc_s_per_task: f64,
    /// Overlapping low-confidence ticks over every round of every trial (must be 0).
    pub overlap_ticks: usize,
    /// Mean percent of high-confidence reference samples at the end.
    pub high_conf_pct: f64,
    /// Wall time of this robot count's study (s).
    pub wall_s: f64,
}

/// What `capacity.json` holds.
#[derive(Serialize)]
struct CapacityFile<'a> {
    trials: usize,
    samples: usize,
    seed: u64,
    end_share: f64,
    /// `3600 / E[low-confidence seconds per task]` (tasks per hour per operator).
    operator_limited_per_h: f64,
    rows: &'a [CapacityRow],
}

/// The end-of-learning row of one study.
pub(crate) fn row(result: &StudyResult, wall_s: f64) -> anyhow::Result<CapacityRow> {
    let config = &result.config;
    let n = config.robots;
    let finals: Vec<_> = result
        .trials
        .iter()
        .map(|t| {
            t.iterations
                .last()
                .ok_or_else(|| anyhow!("a trial without iterations"))
        })
        .collect::<anyhow::Result<_>>()?;
    let (t_mean, t_std) = mean_std(finals.iter().map(|r| r.t_total_s));
    let rounds = config.n_rounds();
    let last = ((END_SHARE * rounds as f64).ceil() as usize).clamp(1, rounds);
    let end_rounds: Vec<_> = result
        .trials
        .iter()
        .flat_map(|t| {
            t.iterations
                .iter()
                .filter_map(|r| r.pair.as_ref())
                .skip(rounds - last)
        })
        .collect();
    let tick_s = result.dt_s;
    Ok(CapacityRow {
        robots: n,
        executions: config.executions,
        rounds,
        t_total_mean_s: t_mean,
        t_total_std_s: t_std,
        throughput_per_h: mean_std(finals.iter().map(|r| r.throughput_per_h)).0,
        operator_busy_share: mean_std(end_rounds.iter().map(|p| p.operator_busy_share)).0,
        lc_s_per_task: mean_std(
            end_rounds
                .iter()
                .map(|p| p.supervised_ticks as f64 * tick_s / n as f64),
        )
        .0,
        overlap_ticks: result.total_overlap_ticks(),
        high_conf_pct: mean_std(finals.iter().map(|r| r.high_conf_pct)).0,
        wall_s,
    })
}

/// `3600 / E[low-confidence seconds per task]` pooled over the rows (tasks per hour): the
/// throughput of one operator busy all the time, each task taking its low-confidence seconds.
pub(crate) fn operator_limited_per_h(rows: &[CapacityRow]) -> f64 {
    throughput_per_h(1, mean_std(rows.iter().map(|r| r.lc_s_per_task)).0)
}

/// The table as Markdown (docs/study.md).
pub(crate) fn table(rows: &[CapacityRow]) -> String {
    let mut out = String::from(
        "| N | executions (rounds) | `T_total` (s) | throughput (tasks/h) | operator busy | \
         LC s per task | high confidence (%) | overlaps |\n|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        out += &format!(
            "| {} | {} ({}) | {:.1} ± {:.1} | {:.1} | {:.0} % | {:.1} | {:.1} | {} |\n",
            r.robots,
            r.executions,
            r.rounds,
            r.t_total_mean_s,
            r.t_total_std_s,
            r.throughput_per_h,
            100.0 * r.operator_busy_share,
            r.lc_s_per_task,
            r.high_conf_pct,
            r.overlap_ticks
        );
    }
    out
}

/// Runs `cargo xtask capacity`.
pub(crate) fn run(args: &CapacityArgs) -> anyhow::Result<()> {
    if !(1..=MAX_ROBOTS).contains(&args.max_robots) {
        bail!("--max-robots must be between 1 and {MAX_ROBOTS}");
    }
    let root = workspace_root();
    let (base, path) = read_config(args.config.as_deref())?;
    let inputs = StudyInputs::from_dir(&root.join("fixtures/sanding"))
        .context("reading the sanding fixtures")?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| root.join("results/capacity"));
    let seed = args.seed.unwrap_or(base.seed);
    println!(
        "capacity: N = 1..={} robots, {} trials × up to {} executions (rounded down to a \
         multiple of N), {} samples per schedule, seed {seed}; end of learning = final \
         schedule, busy share over the last {:.0} % of rounds",
        args.max_robots,
        args.trials,
        args.executions,
        args.samples,
        100.0 * END_SHARE
    );
    let wall = Instant::now();
    let mut rows = Vec::new();
    for n in 1..=args.max_robots {
        let config = StudyConfig {
            trials: args.trials,
            executions: args.executions / n * n,
            robots: n,
            samples: args.samples,
            seed,
            ..base.clone()
        };
        config
            .validate()
            .with_context(|| format!("{} with N = {n}", path.display()))?;
        let t = Instant::now();
        let (result, _) = run_study(&config, &inputs, &|_| {})
            .with_context(|| format!("the study with N = {n} robots"))?;
        let r = row(&result, t.elapsed().as_secs_f64())?;
        println!(
            "N = {n}: T_total {:.1} ± {:.1} s, {:.1} tasks/h, operator busy {:.0} %, \
             {} overlapping ticks ({:.1} s)",
            r.t_total_mean_s,
            r.t_total_std_s,
            r.throughput_per_h,
            100.0 * r.operator_busy_share,
            r.overlap_ticks,
            r.wall_s
        );
        rows.push(r);
    }
    let bound = operator_limited_per_h(&rows);
    println!();
    print!("{}", table(&rows));
    println!(
        "operator-limited bound: {bound:.1} tasks per hour (3600 / {:.1} s low-confidence \
         per task)",
        3600.0 / bound
    );
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let file = CapacityFile {
        trials: args.trials,
        samples: args.samples,
        seed,
        end_share: END_SHARE,
        operator_limited_per_h: bound,
        rows: &rows,
    };
    let json_path = out.join("capacity.json");
    std::fs::write(&json_path, serde_json::to_string_pretty(&file)? + "\n")
        .with_context(|| format!("writing {}", json_path.display()))?;
    draw_capacity(
        &rows,
        bound,
        &out.join("capacity.svg"),
        &out.join("capacity.png"),
    )?;
    println!(
        "wrote capacity.json, capacity.svg, capacity.png in {} ({:.1} s wall)",
        out.display(),
        wall.elapsed().as_secs_f64()
    );
    let overlaps: usize = rows.iter().map(|r| r.overlap_ticks).sum();
    if overlaps > 0 {
        bail!("{overlaps} ticks had two or more robots low-confidence: a schedule is unsafe");
    }
    Ok(())
}

/// Image size (pixels; SVG user units).
const SIZE_PX: (u32, u32) = (1000, 620);

/// Draws throughput (left axis) and operator busy share (right axis) against `N`, with the
/// operator-limited bound as a dashed line, as SVG and PNG.
///
/// # Errors
/// No rows, or a failure to render or write a file.
pub(crate) fn draw_capacity(
    rows: &[CapacityRow],
    bound_per_h: f64,
    svg: &Path,
    png: &Path,
) -> anyhow::Result<()> {
    if rows.is_empty() {
        bail!("capacity figure: no robot counts to draw");
    }
    tandem_plot::register_font()?;
    let mut svg_text = String::new();
    {
        let root = SVGBackend::with_string(&mut svg_text, SIZE_PX).into_drawing_area();
        draw_on(&root, rows, bound_per_h)?;
        root.present()
            .map_err(|e| anyhow!("finishing the capacity SVG: {e}"))?;
    }
    {
        let root = BitMapBackend::new(png, SIZE_PX).into_drawing_area();
        draw_on(&root, rows, bound_per_h)?;
        root.present()
            .map_err(|e| anyhow!("writing {}: {e}", png.display()))?;
    }
    std::fs::write(svg, svg_text).with_context(|| format!("writing {}", svg.display()))?;
    Ok(())
}

fn draw_on<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    rows: &[CapacityRow],
    bound_per_h: f64,
) -> anyhow::Result<()> {
    let err = |what: &'static str| {
        move |e: DrawingAreaErrorKind<DB::ErrorType>| {
            anyhow!("drawing the capacity figure ({what}): {e}")
        }
    };
    root.fill(&WHITE).map_err(err("background"))?;
    let n_max = rows.iter().map(|r| r.robots).max().unwrap_or(1) as f64;
    let top = rows
        .iter()
        .map(|r| r.throughput_per_h)
        .fold(bound_per_h, f64::max);
    let y_max = crate::fig5::nice_ceiling(top * 1.35);
    let mut chart = ChartBuilder::on(root)
        .margin(20)
        .x_label_area_size(60)
        .y_label_area_size(80)
        .right_y_label_area_size(80)
        .build_cartesian_2d(0.5..n_max + 0.5, 0.0..y_max)
        .map_err(err("axes"))?
        .set_secondary_coord(0.5..n_max + 0.5, 0.0..100.0);
    chart
        .configure_mesh()
        .x_labels(rows.len())
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .x_desc("robots N run by one operator")
        .y_desc("throughput (tasks per hour per operator)")
        .label_style((FONT_FAMILY, 18))
        .axis_desc_style((FONT_FAMILY, 20))
        .light_line_style(WHITE.mix(0.0))
        .bold_line_style(BLACK.mix(0.12))
        .draw()
        .map_err(err("mesh"))?;
    chart
        .configure_secondary_axes()
        .y_label_formatter(&|v| format!("{v:.0}"))
        .y_desc("operator busy share (%)")
        .label_style((FONT_FAMILY, 18))
        .axis_desc_style((FONT_FAMILY, 20))
        .draw()
        .map_err(err("secondary axis"))?;

    let throughput: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (r.robots as f64, r.throughput_per_h))
        .collect();
    chart
        .draw_series(LineSeries::new(throughput.clone(), MEAN.stroke_width(3)))
        .map_err(err("throughput"))?
        .label("throughput N·3600 / T_total")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], MEAN.stroke_width(3)));
    chart
        .draw_series(throughput.iter().map(|&p| Circle::new(p, 5, MEAN.filled())))
        .map_err(err("throughput points"))?;
    chart
        .draw_series(DashedLineSeries::new(
            [(0.5, bound_per_h), (n_max + 0.5, bound_per_h)],
            8,
            6,
            GROUND_TRUTH.stroke_width(3),
        ))
        .map_err(err("bound"))?
        .label("operator-limited bound 3600 / E[LC s per task]")
        .legend(|(x, y)| {
            EmptyElement::at((x, y))
                + PathElement::new(vec![(0, 0), (8, 0)], GROUND_TRUTH.stroke_width(3))
                + PathElement::new(vec![(14, 0), (22, 0)], GROUND_TRUTH.stroke_width(3))
        });
    let busy: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (r.robots as f64, 100.0 * r.operator_busy_share))
        .collect();
    // Not a robot's colour: the busy share is the operator's.
    let busy_colour = OPERATOR;
    chart
        .draw_secondary_series(LineSeries::new(busy.clone(), busy_colour.stroke_width(3)))
        .map_err(err("busy share"))?
        .label("operator busy share (right axis)")
        .legend(move |(x, y)| {
            PathElement::new(vec![(x, y), (x + 24, y)], busy_colour.stroke_width(3))
        });
    chart
        .draw_secondary_series(
            busy.iter()
                .map(|&p| TriangleMarker::new(p, 7, busy_colour.filled())),
        )
        .map_err(err("busy share points"))?;
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .margin(12)
        .legend_area_size(30)
        .label_font((FONT_FAMILY, 18))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK.mix(0.5))
        .draw()
        .map_err(err("legend"))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn r(robots: usize, t: f64, busy: f64, lc: f64) -> CapacityRow {
        CapacityRow {
            robots,
            executions: 12 / robots * robots,
            rounds: 12 / robots,
            t_total_mean_s: t,
            t_total_std_s: 0.0,
            throughput_per_h: robots as f64 * 3600.0 / t,
            operator_busy_share: busy,
            lc_s_per_task: lc,
            overlap_ticks: 0,
            high_conf_pct: 60.0,
            wall_s: 1.0,
        }
    }

    #[test]
    fn the_operator_limited_bound_is_3600_over_the_mean_lc_time_per_task() {
        // 30 s and 50 s of supervision per task: 40 s on average, 90 tasks per hour.
        let rows = [r(1, 100.0, 0.3, 30.0), r(2, 120.0, 0.6, 50.0)];
        assert_eq!(operator_limited_per_h(&rows), 90.0);
        let t = table(&rows);
        assert!(
            t.contains("| 1 | 12 (12) | 100.0 ± 0.0 | 36.0 | 30 % | 30.0 | 60.0 | 0 |"),
            "{t}"
        );
        assert!(
            t.contains("| 2 | 12 (6) | 120.0 ± 0.0 | 60.0 | 60 % | 50.0 | 60.0 | 0 |"),
            "{t}"
        );
    }

    #[test]
    fn the_row_takes_the_final_schedule_and_the_last_tenth_of_the_rounds() {
        use tandem::sim::study::{
            IterationRecord, PairStats, ScheduleSource, StudyConfig, StudyResult, TrialResult,
        };
        // Three robots, 30 executions: 10 rounds, the last 10 % is round 9 alone. Round k
        // keeps the operator busy k/10 of the time and supervises 300·k ticks (10 ms) over the
        // three robots: k s per task.
        let record = |k: usize, t_total_s: f64| IterationRecord {
            iteration: k,
            t_total_s,
            offset_s: 1.0,
            high_conf_pct: 60.0,
            source: ScheduleSource::Sampled,
            lc_intervals_s: vec![vec![]; 3],
            pair: (k < 10).then(|| PairStats {
                overlap_ticks: 0,
                operator_idle_share: 1.0 - k as f64 / 10.0,
                duration_s: t_total_s,
                supervised_ticks: 300 * k,
                corrected_ticks: 0,
                operator_busy_share: k as f64 / 10.0,
                faults: 0,
            }),
            lower_bound_s: t_total_s,
            bound_is_optimum: false,
            gap: 0.0,
            throughput_per_h: 3.0 * 3600.0 / t_total_s,
            offsets_s: vec![1.0, 2.0],
            falsely_trusted_samples: 0,
            lc_runs: vec![0; 3],
            error_rates: Default::default(),
            simulated_rates: None,
        };
        let trial = |k: usize, last_s: f64| TrialResult {
            trial: k,
            seed: k as u64,
            iterations: (0..=10)
                .map(|i| record(i, if i == 10 { last_s } else { 500.0 }))
                .collect(),
        };
        let result = StudyResult {
            config: StudyConfig {
                executions: 30,
                robots: 3,
                ..StudyConfig::default()
            },
            n_ref: 100,
            dt_s: 0.01,
            ground_truth_pct: 66.0,
            trials: vec![trial(0, 100.0), trial(1, 200.0)],
        };
        let row = row(&result, 1.0).unwrap();
        assert_eq!((row.robots, row.executions, row.rounds), (3, 30, 10));
        assert_eq!(row.t_total_mean_s, 150.0);
        assert!((row.t_total_std_s - 50.0 * 2f64.sqrt()).abs() < 1e-12);
        // 3·3600/100 = 108 and 3·3600/200 = 54 tasks per hour: mean 81.
        assert_eq!(row.throughput_per_h, 81.0);
        assert!((row.operator_busy_share - 0.9).abs() < 1e-15);
        assert!((row.lc_s_per_task - 9.0).abs() < 1e-12);
        assert_eq!(row.overlap_ticks, 0);
    }

    #[test]
    fn the_figure_renders_with_its_labels() {
        let dir = crate::fig5::tests::scratch_dir("capacity");
        let rows: Vec<CapacityRow> = (1..=4)
            .map(|n| r(n, 90.0 + 20.0 * n as f64, 0.2 * n as f64, 30.0))
            .collect();
        let (svg, png) = (dir.join("c.svg"), dir.join("c.png"));
        draw_capacity(&rows, 120.0, &svg, &png).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        for label in [
            "robots N run by one operator",
            "throughput (tasks per hour per operator)",
            "operator busy share (%)",
            "operator-limited bound",
        ] {
            assert!(text.contains(label), "{label}");
        }
        assert_eq!(
            crate::fig5::tests::png_size(&std::fs::read(&png).unwrap()),
            SIZE_PX
        );
        assert!(draw_capacity(&[], 1.0, &svg, &png).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
