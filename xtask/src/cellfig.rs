//! The continuous study's figure (`cargo xtask study --cell continuous` writes `cell.svg` and
//! `cell.png` next to `study.json`): how the cell's throughput and confidence evolve as it
//! learns, against the number of tasks completed.
//!
//! Left axis (tasks per hour per operator): the throughput measured over a moving window of
//! tasks (mean over trials at the same task count; the window is [`window`] tasks), the
//! planned throughput `3600·N / P` of each plan, and its certificate's bound
//! `3600·N / P_lower` (both mean over trials at the same re-plan; a trial re-plans every `N`
//! tasks, so the `k`-th plans of all trials follow the same number of recorded tasks). Right
//! axis: the percent of high-confidence reference samples of each plan (mean over trials) and
//! the ground truth.

use std::path::Path;

use anyhow::{Context, anyhow, bail};
use plotters::prelude::*;
use tandem::sim::study::{CellStudyResult, mean_std};
use tandem_plot::{FONT_FAMILY, GROUND_TRUTH, HIGH_CONFIDENCE, MEAN, OPERATOR};

/// Image size (pixels; SVG user units).
const SIZE_PX: (u32, u32) = (1200, 640);

/// The moving window of measured throughput for a trial of `tasks` tasks of `n_robots`
/// robots: a twentieth of the tasks, rounded up to whole periods (a multiple of `N`, as the
/// study's steady window: the robots complete their tasks in bunches, and a window of a
/// fraction of a period zig-zags with where the bunches fall).
#[must_use]
pub(crate) fn window(tasks: usize, n_robots: usize) -> usize {
    let n = n_robots.max(1);
    (tasks / 20).max(1).div_ceil(n) * n
}

/// What the figure draws, one value per point.
#[derive(Debug, PartialEq)]
pub(crate) struct CellFigData {
    /// Tasks recorded at each plan (x of the plan series).
    pub plan_tasks: Vec<f64>,
    /// Mean planned throughput of the plans (tasks/h).
    pub plan_per_h: Vec<f64>,
    /// Mean certificate bound of the plans (tasks/h).
    pub bound_per_h: Vec<f64>,
    /// Mean high-confidence percent of the plans.
    pub high_conf_pct: Vec<f64>,
    /// Tasks completed at each measured point (x of the measured series).
    pub measured_tasks: Vec<f64>,
    /// Mean measured throughput over the window ending there (tasks/h).
    pub measured_per_h: Vec<f64>,
    /// Ground truth: percent of reference samples that need no help.
    pub ground_truth_pct: f64,
    /// The window of the measured series (tasks).
    pub window: usize,
}

impl CellFigData {
    /// The figure's data of a continuous study.
    ///
    /// # Errors
    /// A study without trials, or trials without plans or completions.
    pub(crate) fn of(result: &CellStudyResult) -> anyhow::Result<CellFigData> {
        let trials = &result.trials;
        if trials.is_empty() {
            bail!("the continuous study has no trials to draw");
        }
        let n = result.config.robots;
        let plans = trials.iter().map(|t| t.iterations.len()).min().unwrap_or(0);
        let completed = trials
            .iter()
            .map(|t| t.completions.len())
            .min()
            .unwrap_or(0);
        if plans == 0 || completed == 0 {
            bail!("the continuous study has a trial without plans or completed tasks");
        }
        let at = |k: usize, f: &dyn Fn(&tandem::sim::study::CellIteration) -> f64| {
            mean_std(trials.iter().map(|t| f(&t.iterations[k]))).0
        };
        let nf = n as f64;
        let w = window(completed, n);
        let measured: Vec<(f64, f64)> = (w..=completed)
            .step_by((w / 4).max(1))
            .map(|j| {
                let per_h = mean_std(trials.iter().map(|t| {
                    let c = &t.completions;
                    let t0 = if j > w { c[j - w - 1].tick } else { 0 };
                    let ticks = (c[j - 1].tick - t0).max(1) as f64;
                    w as f64 * 3600.0 / (ticks * result.dt_s)
                }))
                .0;
                (j as f64, per_h)
            })
            .collect();
        Ok(CellFigData {
            plan_tasks: (0..plans)
                .map(|k| at(k, &|i| i.tasks_recorded as f64))
                .collect(),
            plan_per_h: (0..plans).map(|k| at(k, &|i| i.tasks_per_hour)).collect(),
            bound_per_h: (0..plans)
                .map(|k| at(k, &|i| 3600.0 * nf / i.lower_bound_s))
                .collect(),
            high_conf_pct: (0..plans).map(|k| at(k, &|i| i.high_conf_pct)).collect(),
            measured_tasks: measured.iter().map(|p| p.0).collect(),
            measured_per_h: measured.iter().map(|p| p.1).collect(),
            ground_truth_pct: result.ground_truth_pct,
            window: w,
        })
    }
}

/// Draws the continuous study's figure (module docs) as SVG and PNG.
///
/// # Errors
/// Data that [`CellFigData::of`] rejects, or a failure to render or write a file.
pub(crate) fn draw_cell_study(
    result: &CellStudyResult,
    svg: &Path,
    png: &Path,
) -> anyhow::Result<()> {
    let data = CellFigData::of(result)?;
    tandem_plot::register_font()?;
    let mut svg_text = String::new();
    {
        let root = SVGBackend::with_string(&mut svg_text, SIZE_PX).into_drawing_area();
        draw_on(&root, &data)?;
        root.present()
            .map_err(|e| anyhow!("finishing the continuous study's SVG: {e}"))?;
    }
    {
        let root = BitMapBackend::new(png, SIZE_PX).into_drawing_area();
        draw_on(&root, &data)?;
        root.present()
            .map_err(|e| anyhow!("writing {}: {e}", png.display()))?;
    }
    std::fs::write(svg, svg_text).with_context(|| format!("writing {}", svg.display()))?;
    Ok(())
}

fn draw_on<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    d: &CellFigData,
) -> anyhow::Result<()> {
    let err = |what: &'static str| {
        move |e: DrawingAreaErrorKind<DB::ErrorType>| {
            anyhow!("drawing the continuous study's figure ({what}): {e}")
        }
    };
    root.fill(&WHITE).map_err(err("background"))?;
    let x_max = d
        .measured_tasks
        .iter()
        .chain(&d.plan_tasks)
        .copied()
        .fold(1.0, f64::max);
    let top = d
        .plan_per_h
        .iter()
        .chain(&d.bound_per_h)
        .chain(&d.measured_per_h)
        .copied()
        .fold(1.0, f64::max);
    let y_max = crate::fig5::nice_ceiling(top * 1.4);
    let mut chart = ChartBuilder::on(root)
        .margin(20)
        .x_label_area_size(60)
        .y_label_area_size(80)
        .right_y_label_area_size(80)
        .build_cartesian_2d(0.0..x_max, 0.0..y_max)
        .map_err(err("axes"))?
        .set_secondary_coord(0.0..x_max, 0.0..140.0);
    mesh_style!(
        chart
            .configure_mesh()
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_label_formatter(&|v| format!("{v:.0}"))
            .x_desc("tasks completed (all robots)")
            .y_desc("throughput (tasks per hour per operator)")
    )
    .draw()
    .map_err(err("mesh"))?;
    chart
        .configure_secondary_axes()
        .y_labels(8)
        .y_label_formatter(&crate::legend::percent_label)
        .y_desc("high-confidence samples (%)")
        .label_style((FONT_FAMILY, 18))
        .axis_desc_style((FONT_FAMILY, 20))
        .draw()
        .map_err(err("secondary axis"))?;
    let zip = |x: &[f64], y: &[f64]| -> Vec<(f64, f64)> {
        x.iter().copied().zip(y.iter().copied()).collect()
    };
    chart
        .draw_series(LineSeries::new(
            zip(&d.measured_tasks, &d.measured_per_h),
            MEAN.stroke_width(3),
        ))
        .map_err(err("measured"))?
        .label(format!("measured (window of {} tasks)", d.window))
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], MEAN.stroke_width(3)));
    chart
        .draw_series(LineSeries::new(
            zip(&d.plan_tasks, &d.plan_per_h),
            OPERATOR.stroke_width(2),
        ))
        .map_err(err("planned"))?
        .label("planned 3600·N / P")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], OPERATOR.stroke_width(2)));
    chart
        .draw_series(DashedLineSeries::new(
            zip(&d.plan_tasks, &d.bound_per_h),
            8,
            6,
            GROUND_TRUTH.stroke_width(3),
        ))
        .map_err(err("bound"))?
        .label("certificate bound 3600·N / P_lower")
        .legend(dashed_mark!(GROUND_TRUTH));
    chart
        .draw_secondary_series(LineSeries::new(
            zip(&d.plan_tasks, &d.high_conf_pct),
            HIGH_CONFIDENCE.stroke_width(2),
        ))
        .map_err(err("high confidence"))?
        .label("high confidence (right axis)")
        .legend(|(x, y)| {
            PathElement::new(vec![(x, y), (x + 24, y)], HIGH_CONFIDENCE.stroke_width(2))
        });
    chart
        .draw_secondary_series(DashedLineSeries::new(
            [(0.0, d.ground_truth_pct), (x_max, d.ground_truth_pct)],
            3,
            5,
            HIGH_CONFIDENCE.stroke_width(2),
        ))
        .map_err(err("ground truth"))?
        .label("ground truth (right axis)")
        .legend(|(x, y)| {
            EmptyElement::at((x, y))
                + PathElement::new(vec![(0, 0), (3, 0)], HIGH_CONFIDENCE.stroke_width(2))
                + PathElement::new(vec![(8, 0), (11, 0)], HIGH_CONFIDENCE.stroke_width(2))
                + PathElement::new(vec![(16, 0), (19, 0)], HIGH_CONFIDENCE.stroke_width(2))
        });
    draw_legend!(chart, SeriesLabelPosition::UpperLeft, 17, err("legend"))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use tandem::sim::study::{CellCompletion, CellIteration, CellTrialResult, Steady, StudyConfig};
    use tandem::sim::workcell::CellStats;

    /// Two robots, 40 tasks per trial, a task every 100 ticks of 10 ms (one per second: 3600
    /// per hour), two plans of 60 and 90 tasks/h.
    fn result() -> CellStudyResult {
        let plan = |tasks_recorded: usize, per_h: f64| CellIteration {
            tasks_recorded,
            tick: 0,
            period_s: 7200.0 / per_h,
            tasks_per_hour: per_h,
            operator_share: 0.5,
            lower_bound_s: 7200.0 / (per_h + 10.0),
            gap: 0.1,
            order_exhaustive: true,
            high_conf_pct: per_h / 2.0,
            lc_stretches: 3,
            lc_ref: Vec::new(),
            holds: Vec::new(),
            falsely_trusted_samples: 0,
            fleet: None,
        };
        let trial = |k: usize| CellTrialResult {
            trial: k,
            seed: k as u64,
            iterations: vec![plan(0, 60.0), plan(20, 90.0)],
            completions: (1..=40)
                .map(|j| CellCompletion {
                    robot: j % 2,
                    tick: 100 * j as u64,
                    busy_ticks: 0,
                    gate_ticks: 0,
                    plan_gap: tandem::sim::workcell::PlanGap::default(),
                    needed_unsupervised: 0,
                    switch_missed: 0,
                })
                .collect(),
            stats: CellStats::default(),
            steady: Steady {
                tasks: 4,
                duration_s: 4.0,
                throughput_per_h: 3600.0,
                operator_busy_share: 0.0,
                robot_wait_share: 0.0,
                plan_gap: tandem::sim::workcell::PlanGap::default(),
                needed_unsupervised: 0,
            },
        };
        CellStudyResult {
            config: StudyConfig {
                executions: 40,
                ..StudyConfig::default()
            },
            n_ref: 100,
            dt_s: 0.01,
            ground_truth_pct: 66.0,
            trials: vec![trial(0), trial(1)],
        }
    }

    #[test]
    fn the_data_averages_plans_by_index_and_measures_a_moving_window() {
        let d = CellFigData::of(&result()).unwrap();
        assert_eq!(d.plan_tasks, vec![0.0, 20.0]);
        assert_eq!(d.plan_per_h, vec![60.0, 90.0]);
        assert_eq!(d.bound_per_h, vec![70.0, 100.0]);
        assert_eq!(d.high_conf_pct, vec![30.0, 45.0]);
        // 40 tasks of 2 robots: a window of 2 tasks, a point every task from the second.
        assert_eq!(d.window, 2);
        // 300 tasks of 2 robots: 15 rounded up to 16; of 3 robots, 15.
        assert_eq!((window(300, 2), window(300, 3), window(10, 4)), (16, 15, 4));
        assert_eq!(d.measured_tasks.first(), Some(&2.0));
        assert_eq!(d.measured_tasks.last(), Some(&40.0));
        // One task per second, whatever the window.
        assert!(d.measured_per_h.iter().all(|&v| (v - 3600.0).abs() < 1e-9));
        let mut empty = result();
        empty.trials[1].completions.clear();
        assert!(CellFigData::of(&empty).is_err());
        empty.trials.clear();
        assert!(CellFigData::of(&empty).is_err());
    }

    #[test]
    fn the_figure_renders_with_its_labels() {
        let dir = crate::fig5::tests::scratch_dir("cellfig");
        let (svg, png) = (dir.join("cell.svg"), dir.join("cell.png"));
        draw_cell_study(&result(), &svg, &png).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        for label in [
            "tasks completed (all robots)",
            "measured (window of 2 tasks)",
            "certificate bound",
            "high-confidence samples (%)",
        ] {
            assert!(text.contains(label), "{label}");
        }
        assert_eq!(
            crate::fig5::tests::png_size(&std::fs::read(&png).unwrap()),
            SIZE_PX
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
