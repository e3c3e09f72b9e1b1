//! Fig. 5 of the paper (§III, "Scheduling solution evolution"), drawn from plain numbers.
//!
//! Top panel: the mean task length `T_total` (Eq. 13) per study iteration as a dark blue
//! line with a shaded ±1 standard deviation band over trials, and at a few iterations an
//! example schedule as a vertical bar from 0 to its `T_total`, and the mean certificate lower
//! bound `T*₀` (the margin-free optimum, a bound on every admissible schedule) as a dashed
//! line under the `T_total` curve; each bar is coloured along global time:
//! blue where robot 1 is low-confidence, red where robot 2 is, gray where neither is.
//! Bottom panel: the percentage of high-confidence reference samples (mean line and band)
//! and the ground-truth percentage as a gray dotted line, on the same iteration axis.
//!
//! The figure is written as SVG and PNG. Text uses the bundled DejaVu Sans and the colours
//! are the palette of `tandem_plot` (shared with `tandem plot`), through plotters' pure-Rust
//! `ab_glyph` text renderer, so rendering needs no system font, fontconfig or freetype.
//! The figure's tests draw a synthetic dataset (module `demo`, compiled for tests only).

#[cfg(test)]
mod demo;

use std::path::Path;

use anyhow::{Context, anyhow, bail, ensure};
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use tandem_plot::{BOTH_LC, FONT_FAMILY, GROUND_TRUTH, MEAN, NEITHER_LC, ROBOT_LC_N};

/// Width of both output images, in pixels (SVG user units for the SVG).
pub(crate) const WIDTH_PX: u32 = 1200;
/// Height of both output images, in pixels (SVG user units for the SVG).
pub(crate) const HEIGHT_PX: u32 = 900;

/// Everything Fig. 5 shows, as plain numbers (global schedule time in seconds).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Fig5Data {
    /// Study iteration index: 0 = before the first pair of executions, then one per
    /// executed pair. Strictly increasing; every per-iteration vector below has this length.
    pub iterations: Vec<usize>,
    /// Mean over trials of the task length `T_total` (Eq. 13) of the schedule in force at
    /// each iteration, in seconds of global schedule time.
    pub t_total_mean_s: Vec<f64>,
    /// Standard deviation over trials of `T_total` per iteration, in seconds (≥ 0).
    pub t_total_std_s: Vec<f64>,
    /// Mean over trials of the schedule's certificate lower bound (`T*₀` where proven), in
    /// seconds of global schedule time (≥ 0; drawn dashed under the `T_total` curve).
    pub lower_bound_mean_s: Vec<f64>,
    /// Mean over trials of the percentage (0–100) of reference samples that are
    /// high-confidence (Eq. 12) per iteration.
    pub high_conf_pct_mean: Vec<f64>,
    /// Standard deviation over trials of that percentage, in percentage points (≥ 0).
    pub high_conf_pct_std: Vec<f64>,
    /// Ground-truth percentage (0–100) of reference samples that never need a correction
    /// (the paper's gray dotted line).
    pub ground_truth_pct: f64,
    /// Robots per round (`N ≥ 1`; the paper's 2): names the iterations (pairs or rounds of
    /// `N`) and the bound (`T*₀` for two robots, the operator-limited bound otherwise).
    pub n_robots: usize,
    /// Example schedules drawn as coloured bars at a few iterations (may be empty).
    pub examples: Vec<ExampleSchedule>,
}

/// One example schedule, drawn as a bar from global time 0 to `t_total_s`.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct ExampleSchedule {
    /// Study iteration the schedule belongs to; within the range of [`Fig5Data::iterations`].
    pub iteration: usize,
    /// The schedule's task length `T_total` (Eq. 13), in seconds of global time.
    pub t_total_s: f64,
    /// Per robot (robot 1 first; 1 to 16 robots), the global-time intervals
    /// `(start_s, end_s)` in which it is low-confidence; each within `[0, t_total_s]`.
    pub lc: Vec<Vec<(f64, f64)>>,
}

/// Who is low-confidence during a stretch of an example schedule's global time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Occupancy {
    /// No robot (gray).
    Neither,
    /// Robot `i` (0-based) only: blue for robot 1, red for robot 2, then
    /// [`ROBOT_LC_N`]'s colours.
    Robot(usize),
    /// Two or more robots: a schedule violating the one-low-confidence-robot constraint
    /// (purple).
    Both,
}

impl Occupancy {
    fn colour(self) -> RGBColor {
        match self {
            Self::Neither => NEITHER_LC,
            Self::Robot(i) => ROBOT_LC_N[i % ROBOT_LC_N.len()],
            Self::Both => BOTH_LC,
        }
    }
}

/// Relative slack allowed when an interval ends just past `t_total_s` through rounding.
const INTERVAL_SLACK: f64 = 1e-9;

impl Fig5Data {
    /// Checks the data can be drawn: equal non-empty lengths, strictly increasing
    /// iterations, finite values, non-negative spreads, percentages in `[0, 100]`, and
    /// example schedules inside the plotted range with intervals inside `[0, T_total]`.
    ///
    /// # Errors
    /// A message naming the offending field and index.
    pub(crate) fn validate(&self) -> anyhow::Result<()> {
        let n = self.iterations.len();
        ensure!(n > 0, "Fig. 5 data: `iterations` is empty");
        for (name, len) in [
            ("t_total_mean_s", self.t_total_mean_s.len()),
            ("t_total_std_s", self.t_total_std_s.len()),
            ("lower_bound_mean_s", self.lower_bound_mean_s.len()),
            ("high_conf_pct_mean", self.high_conf_pct_mean.len()),
            ("high_conf_pct_std", self.high_conf_pct_std.len()),
        ] {
            ensure!(
                len == n,
                "Fig. 5 data: `{name}` has {len} values but `iterations` has {n}"
            );
        }
        for (i, pair) in self.iterations.windows(2).enumerate() {
            ensure!(
                pair[0] < pair[1],
                "Fig. 5 data: `iterations` must be strictly increasing, but iterations[{i}] = {} \
                 and iterations[{}] = {}",
                pair[0],
                i + 1,
                pair[1]
            );
        }
        check_values("t_total_mean_s", &self.t_total_mean_s, 0.0, f64::INFINITY)?;
        check_values("t_total_std_s", &self.t_total_std_s, 0.0, f64::INFINITY)?;
        check_values(
            "lower_bound_mean_s",
            &self.lower_bound_mean_s,
            0.0,
            f64::INFINITY,
        )?;
        check_values("high_conf_pct_mean", &self.high_conf_pct_mean, 0.0, 100.0)?;
        check_values(
            "high_conf_pct_std",
            &self.high_conf_pct_std,
            0.0,
            f64::INFINITY,
        )?;
        check_values("ground_truth_pct", &[self.ground_truth_pct], 0.0, 100.0)?;

        let (first, last) = (self.iterations[0], self.iterations[n - 1]);
        for (k, ex) in self.examples.iter().enumerate() {
            ensure!(
                (first..=last).contains(&ex.iteration),
                "Fig. 5 data: examples[{k}].iteration = {} lies outside the plotted iterations \
                 {first}..={last}",
                ex.iteration
            );
            ensure!(
                ex.t_total_s.is_finite() && ex.t_total_s >= 0.0,
                "Fig. 5 data: examples[{k}].t_total_s = {} must be finite and >= 0",
                ex.t_total_s
            );
            let limit = ex.t_total_s * (1.0 + INTERVAL_SLACK) + INTERVAL_SLACK;
            ensure!(
                (1..=ROBOT_LC_N.len()).contains(&ex.lc.len()),
                "Fig. 5 data: examples[{k}] has {} robots, must have 1 to {}",
                ex.lc.len(),
                ROBOT_LC_N.len()
            );
            for (robot, intervals) in ex.lc.iter().enumerate() {
                let robot = format!("robot {}", robot + 1);
                for (j, &(start, end)) in intervals.iter().enumerate() {
                    ensure!(
                        start.is_finite()
                            && end.is_finite()
                            && 0.0 <= start
                            && start <= end
                            && end <= limit,
                        "Fig. 5 data: examples[{k}], {robot}, interval {j} = ({start}, {end}) s must satisfy \
                         0 <= start <= end <= t_total_s = {}",
                        ex.t_total_s
                    );
                }
            }
            if let Some(other) = self.examples[..k]
                .iter()
                .position(|e| e.iteration == ex.iteration)
            {
                bail!(
                    "Fig. 5 data: examples[{other}] and examples[{k}] are both at iteration {}",
                    ex.iteration
                );
            }
        }
        Ok(())
    }
}

/// Errs unless every value is finite and within `[lo, hi]`.
fn check_values(name: &str, values: &[f64], lo: f64, hi: f64) -> anyhow::Result<()> {
    for (i, &v) in values.iter().enumerate() {
        ensure!(
            v.is_finite() && lo <= v && v <= hi,
            "Fig. 5 data: `{name}`[{i}] = {v} must be finite and within [{lo}, {hi}]"
        );
    }
    Ok(())
}

/// Splits `[0, t_total_s]` of an example schedule into maximal stretches of constant
/// [`Occupancy`], in global time order. Intervals are clipped to `[0, t_total_s]`; a
/// zero-length schedule gives no stretches.
fn occupancy_segments(ex: &ExampleSchedule) -> Vec<(f64, f64, Occupancy)> {
    let t_end = ex.t_total_s;
    let clip = |t: f64| t.clamp(0.0, t_end);
    let mut cuts: Vec<f64> = vec![0.0, t_end];
    for &(s, e) in ex.lc.iter().flatten() {
        cuts.push(clip(s));
        cuts.push(clip(e));
    }
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    let covers = |intervals: &[(f64, f64)], t: f64| intervals.iter().any(|&(s, e)| s < t && t < e);
    let mut segments: Vec<(f64, f64, Occupancy)> = Vec::new();
    for pair in cuts.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        if b <= a {
            continue;
        }
        let mid = 0.5 * (a + b);
        let mut covering = ex.lc.iter().enumerate().filter(|(_, v)| covers(v, mid));
        let occupancy = match (covering.next(), covering.next()) {
            (None, _) => Occupancy::Neither,
            (Some((i, _)), None) => Occupancy::Robot(i),
            (Some(_), Some(_)) => Occupancy::Both,
        };
        match segments.last_mut() {
            Some(last) if last.2 == occupancy => last.1 = b,
            _ => segments.push((a, b, occupancy)),
        }
    }
    segments
}

/// Draws Fig. 5 from `data` and writes it to `svg` and `png` ([`WIDTH_PX`] × [`HEIGHT_PX`]).
///
/// The data is validated before anything is written; the parent directories must exist.
///
/// # Errors
/// Invalid data (see [`Fig5Data::validate`]), or a failure to render or write a file.
pub(crate) fn draw_fig5(data: &Fig5Data, svg: &Path, png: &Path) -> anyhow::Result<()> {
    data.validate()?;
    tandem_plot::register_font()?;
    let mut svg_text = String::new();
    {
        let root =
            SVGBackend::with_string(&mut svg_text, (WIDTH_PX, HEIGHT_PX)).into_drawing_area();
        draw_on(&root, data)?;
        root.present()
            .map_err(|e| anyhow!("finishing the SVG of Fig. 5: {e}"))?;
    }
    {
        let root = BitMapBackend::new(png, (WIDTH_PX, HEIGHT_PX)).into_drawing_area();
        draw_on(&root, data)?;
        root.present()
            .map_err(|e| anyhow!("writing the PNG of Fig. 5 to {}: {e}", png.display()))?;
    }
    std::fs::write(svg, svg_text)
        .with_context(|| format!("writing the SVG of Fig. 5 to {}", svg.display()))?;
    Ok(())
}

/// Share of the x axis, from the right, that the legends cover.
const LEGEND_X_SHARE: f64 = 0.3;
/// Share of the top panel's y axis, from the top, that its legend covers.
const TOP_LEGEND_Y_SHARE: f64 = 0.43;
/// Share of the bottom panel's y axis, from the top or bottom, that its legend covers.
const BOTTOM_LEGEND_Y_SHARE: f64 = 0.5;

/// Axis ranges, bar geometry and legend placement shared by both panels.
struct Layout {
    /// Plotted iteration range (padded so edge bars are fully visible).
    x_min: f64,
    x_max: f64,
    /// Width of an example bar, in iterations.
    bar_width: f64,
    /// Top of the task-length axis, in seconds (leaves the top-right corner to the legend).
    t_max_s: f64,
    /// Top of the percentage axis, in percent.
    pct_max: f64,
    /// Corner of the bottom panel's legend: the lower right unless data is there.
    pct_legend: SeriesLabelPosition,
}

impl Layout {
    fn new(data: &Fig5Data) -> Self {
        let first = data.iterations[0] as f64;
        let last = data.iterations[data.iterations.len() - 1] as f64;
        let span = (last - first).max(1.0);
        let mut example_its: Vec<f64> = data.examples.iter().map(|e| e.iteration as f64).collect();
        example_its.sort_by(f64::total_cmp);
        let min_spacing = example_its
            .windows(2)
            .map(|p| p[1] - p[0])
            .fold(f64::INFINITY, f64::min);
        // 60 % of the spacing between examples, but never wider than 4 % of the axis
        // (so a few examples far apart stay bars, not blocks).
        let bar_width = (0.6 * min_spacing).min(0.04 * span);
        let half_bar = if data.examples.is_empty() {
            0.0
        } else {
            0.5 * bar_width
        };
        let pad = (0.02 * span).max(0.5) + half_bar;
        let (x_min, x_max) = (first - pad, last + pad);
        let legend_x = x_max - LEGEND_X_SHARE * (x_max - x_min);
        let in_legend_x = |x: f64| x >= legend_x;

        // Task length: everything must fit, and what lies under the legend must stay below it.
        let t_points = data
            .iterations
            .iter()
            .zip(data.t_total_mean_s.iter().zip(&data.t_total_std_s))
            .map(|(&i, (m, s))| (i as f64, m + s))
            .chain(
                data.examples
                    .iter()
                    .map(|e| (e.iteration as f64, e.t_total_s)),
            );
        let (mut t_top, mut t_top_right) = (0.0_f64, 0.0_f64);
        for (x, t) in t_points {
            t_top = t_top.max(t);
            if in_legend_x(x) {
                t_top_right = t_top_right.max(t);
            }
        }
        let t_needed = (t_top * 1.06).max(t_top_right / (1.0 - TOP_LEGEND_Y_SHARE));
        let t_max_s = if t_needed > 0.0 {
            nice_ceiling(t_needed)
        } else {
            1.0
        };

        // High-confidence share: the legend goes to the lower right when the data there is
        // high, else to the upper right with the axis raised (up to 100 %) to make room.
        let mut pct_top = data.ground_truth_pct;
        let (mut right_lo, mut right_hi) = (f64::INFINITY, data.ground_truth_pct);
        for ((&i, m), s) in data
            .iterations
            .iter()
            .zip(&data.high_conf_pct_mean)
            .zip(&data.high_conf_pct_std)
        {
            let (lo, hi) = ((m - s).max(0.0), (m + s).min(100.0));
            pct_top = pct_top.max(hi);
            if in_legend_x(i as f64) {
                right_lo = right_lo.min(lo);
                right_hi = right_hi.max(hi);
            }
        }
        let round_up_10 = |v: f64| ((v / 10.0).ceil() * 10.0).clamp(10.0, 100.0);
        let mut pct_max = round_up_10(pct_top * 1.12);
        let pct_legend = if right_lo >= BOTTOM_LEGEND_Y_SHARE * pct_max {
            SeriesLabelPosition::LowerRight
        } else {
            pct_max = pct_max.max(round_up_10(right_hi / (1.0 - BOTTOM_LEGEND_Y_SHARE)));
            SeriesLabelPosition::UpperRight
        };
        Self {
            x_min,
            x_max,
            bar_width,
            t_max_s,
            pct_max,
            pct_legend,
        }
    }
}

/// Rounds `v > 0` up to a round number: 1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6 or 8 times a power
/// of ten.
pub(crate) fn nice_ceiling(v: f64) -> f64 {
    let magnitude = 10f64.powf(v.log10().floor());
    let step = [1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0]
        .into_iter()
        .find(|&m| m * magnitude >= v * (1.0 - 1e-12))
        .unwrap_or(10.0);
    step * magnitude
}

/// Tick label for an iteration axis value: integers only (fractional ticks stay unlabelled).
fn iteration_label(v: &f64) -> String {
    if (v - v.round()).abs() < 1e-9 {
        format!("{}", v.round())
    } else {
        String::new()
    }
}

fn draw_err<E: std::error::Error + Send + Sync>(
    what: &str,
) -> impl FnOnce(DrawingAreaErrorKind<E>) -> anyhow::Error + '_ {
    move |e| anyhow!("drawing Fig. 5 ({what}): {e}")
}

/// Font sizes in pixels.
const TICK_FONT: u32 = 20;
const AXIS_FONT: u32 = 24;
const LEGEND_FONT: u32 = 19;
/// Width of the y label area of both panels, so their plot areas line up.
const Y_LABEL_AREA_PX: u32 = 95;

fn draw_on<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    data: &Fig5Data,
) -> anyhow::Result<()> {
    root.fill(&WHITE).map_err(draw_err("background"))?;
    let top_height = root.dim_in_pixel().1 * 62 / 100;
    let (top, bottom) = root.split_vertically(top_height);
    let layout = Layout::new(data);
    draw_task_length_panel(&top, data, &layout)?;
    draw_high_conf_panel(&bottom, data, &layout)?;
    Ok(())
}

/// A panel's chart: iterations on x, seconds or percent on y.
type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Draws the closed polygon `band` (a ±1 std band, [`std_band`]) with its legend entry;
/// `what` names it in errors.
fn draw_band<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    band: Vec<(f64, f64)>,
    what: &str,
) -> anyhow::Result<()> {
    chart
        .draw_series(std::iter::once(Polygon::new(band, MEAN.mix(0.22).filled())))
        .map_err(draw_err(what))?
        .label("±1 std over trials")
        .legend(|(x, y)| Rectangle::new([(x, y - 7), (x + 24, y + 7)], MEAN.mix(0.22).filled()));
    Ok(())
}

/// Draws the mean line through `(xs, mean)` with legend entry `label` (a single iteration
/// is no line: it gets a dot); `what` names it in errors.
fn draw_mean<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    xs: &[f64],
    mean: &[f64],
    label: &str,
    what: &str,
) -> anyhow::Result<()> {
    chart
        .draw_series(LineSeries::new(
            xs.iter().copied().zip(mean.iter().copied()),
            MEAN.stroke_width(3),
        ))
        .map_err(draw_err(what))?
        .label(label)
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], MEAN.stroke_width(3)));
    if let ([x], [m]) = (xs, mean) {
        chart
            .draw_series(std::iter::once(Circle::new((*x, *m), 5, MEAN.filled())))
            .map_err(draw_err(what))?;
    }
    Ok(())
}

/// Draws the legend of the series labelled so far at `position`; `what` names it in errors.
fn draw_legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    position: SeriesLabelPosition,
    what: &str,
) -> anyhow::Result<()> {
    draw_legend!(chart, position, LEGEND_FONT, draw_err(what))?;
    Ok(())
}

/// Top panel: mean ± std `T_total` and the example schedule bars.
fn draw_task_length_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    data: &Fig5Data,
    layout: &Layout,
) -> anyhow::Result<()> {
    let mut chart = ChartBuilder::on(area)
        .margin_top(20)
        .margin_right(28)
        .margin_left(8)
        .x_label_area_size(12)
        .y_label_area_size(Y_LABEL_AREA_PX)
        .build_cartesian_2d(layout.x_min..layout.x_max, 0.0..layout.t_max_s)
        .map_err(draw_err("top panel axes"))?;
    chart
        .configure_mesh()
        .x_label_formatter(&|_| String::new())
        .y_label_formatter(&|v| format!("{v:.0}"))
        .y_desc("task length T_total (s)")
        .label_style((FONT_FAMILY, TICK_FONT))
        .axis_desc_style((FONT_FAMILY, AXIS_FONT))
        .light_line_style(WHITE.mix(0.0))
        .bold_line_style(BLACK.mix(0.12))
        .draw()
        .map_err(draw_err("top panel mesh"))?;

    let xs: Vec<f64> = data.iterations.iter().map(|&i| i as f64).collect();
    let band = std_band(
        &xs,
        &data.t_total_mean_s,
        &data.t_total_std_s,
        f64::INFINITY,
    );
    draw_band(&mut chart, band, "task length band")?;

    let half = 0.5 * layout.bar_width;
    let mut bars: Vec<Rectangle<(f64, f64)>> = Vec::new();
    let mut any_both = false;
    for ex in &data.examples {
        let x = ex.iteration as f64;
        for (start, end, occupancy) in occupancy_segments(ex) {
            any_both |= occupancy == Occupancy::Both;
            bars.push(Rectangle::new(
                [(x - half, start), (x + half, end)],
                occupancy.colour().filled(),
            ));
        }
        bars.push(Rectangle::new(
            [(x - half, 0.0), (x + half, ex.t_total_s)],
            BLACK.mix(0.7).stroke_width(1),
        ));
    }
    chart
        .draw_series(bars)
        .map_err(draw_err("example schedules"))?;
    let n_robots = data.examples.iter().map(|e| e.lc.len()).max().unwrap_or(0);
    // Two robots: one swatch each, as in the paper; more: one swatch striped in the robots'
    // colours, so the legend keeps its size.
    let mut swatches: Vec<(String, Vec<Occupancy>)> = if n_robots <= 2 {
        (0..n_robots)
            .map(|i| {
                (
                    format!("robot {} low-confidence", i + 1),
                    vec![Occupancy::Robot(i)],
                )
            })
            .collect()
    } else {
        vec![(
            format!("robots 1–{n_robots} low-confidence"),
            (0..n_robots).map(Occupancy::Robot).collect(),
        )]
    };
    let none = if n_robots <= 2 { "neither" } else { "none" };
    swatches.push((format!("{none} low-confidence"), vec![Occupancy::Neither]));
    if any_both {
        let two = if n_robots <= 2 { "both" } else { "two or more" };
        swatches.push((
            format!("{two} low-confidence (invalid)"),
            vec![Occupancy::Both],
        ));
    }
    if !data.examples.is_empty() {
        for (label, colours) in swatches {
            chart
                .draw_series(std::iter::empty::<Rectangle<(f64, f64)>>())
                .map_err(draw_err("legend"))?
                .label(label)
                .legend(move |(x, y)| {
                    // Eight 3 px stripes, robot colours in turn (one colour: a plain swatch).
                    let stripe = |j: usize| {
                        let x0 = 3 * j as i32;
                        let colour = colours[j * colours.len() / 8].colour();
                        Rectangle::new([(x0, -7), (x0 + 3, 7)], colour.filled())
                    };
                    EmptyElement::at((x, y))
                        + stripe(0)
                        + stripe(1)
                        + stripe(2)
                        + stripe(3)
                        + stripe(4)
                        + stripe(5)
                        + stripe(6)
                        + stripe(7)
                });
        }
    }

    draw_mean(
        &mut chart,
        &xs,
        &data.t_total_mean_s,
        "mean task length",
        "task length mean",
    )?;
    chart
        .draw_series(DashedLineSeries::new(
            xs.iter()
                .copied()
                .zip(data.lower_bound_mean_s.iter().copied()),
            6,
            5,
            MEAN.stroke_width(2),
        ))
        .map_err(draw_err("lower bound"))?
        .label(if data.n_robots == 2 {
            "mean lower bound T*₀ (no margins)".to_string()
        } else {
            "mean lower bound (operator-limited)".to_string()
        })
        .legend(|(x, y)| {
            EmptyElement::at((x, y))
                + PathElement::new(vec![(0, 0), (6, 0)], MEAN.stroke_width(2))
                + PathElement::new(vec![(11, 0), (17, 0)], MEAN.stroke_width(2))
                + PathElement::new(vec![(22, 0), (24, 0)], MEAN.stroke_width(2))
        });

    draw_legend(
        &mut chart,
        SeriesLabelPosition::UpperRight,
        "top panel legend",
    )
}

/// Bottom panel: % high-confidence samples and the ground-truth line.
fn draw_high_conf_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    data: &Fig5Data,
    layout: &Layout,
) -> anyhow::Result<()> {
    let mut chart = ChartBuilder::on(area)
        .margin_top(10)
        .margin_right(28)
        .margin_left(8)
        .margin_bottom(8)
        .x_label_area_size(70)
        .y_label_area_size(Y_LABEL_AREA_PX)
        .build_cartesian_2d(layout.x_min..layout.x_max, 0.0..layout.pct_max)
        .map_err(draw_err("bottom panel axes"))?;
    chart
        .configure_mesh()
        .x_label_formatter(&iteration_label)
        .y_label_formatter(&|v| format!("{v:.0}"))
        .x_desc(format!(
            "iteration (rounds of {} executions)",
            data.n_robots
        ))
        .y_desc("high-confidence samples (%)")
        .label_style((FONT_FAMILY, TICK_FONT))
        .axis_desc_style((FONT_FAMILY, AXIS_FONT))
        .light_line_style(WHITE.mix(0.0))
        .bold_line_style(BLACK.mix(0.12))
        .draw()
        .map_err(draw_err("bottom panel mesh"))?;

    let xs: Vec<f64> = data.iterations.iter().map(|&i| i as f64).collect();
    if data.high_conf_pct_std.iter().any(|&s| s > 0.0) {
        let band = std_band(
            &xs,
            &data.high_conf_pct_mean,
            &data.high_conf_pct_std,
            100.0,
        );
        draw_band(&mut chart, band, "high-confidence band")?;
    }
    draw_mean(
        &mut chart,
        &xs,
        &data.high_conf_pct_mean,
        "mean high-confidence share",
        "high-confidence mean",
    )?;
    let gt = data.ground_truth_pct;
    chart
        .draw_series(DashedLineSeries::new(
            [(layout.x_min, gt), (layout.x_max, gt)],
            3,
            5,
            GROUND_TRUTH.stroke_width(3),
        ))
        .map_err(draw_err("ground truth"))?
        .label("ground truth")
        .legend(|(x, y)| {
            EmptyElement::at((x, y))
                + PathElement::new(vec![(0, 0), (4, 0)], GROUND_TRUTH.stroke_width(3))
                + PathElement::new(vec![(10, 0), (14, 0)], GROUND_TRUTH.stroke_width(3))
                + PathElement::new(vec![(20, 0), (24, 0)], GROUND_TRUTH.stroke_width(3))
        });

    draw_legend(&mut chart, layout.pct_legend.clone(), "bottom panel legend")
}

/// The closed polygon of a ±1 std band: `mean + std` (capped at `cap`) along `xs`, then
/// `mean − std` (floored at 0) back.
fn std_band(xs: &[f64], mean: &[f64], std: &[f64], cap: f64) -> Vec<(f64, f64)> {
    let hi = mean.iter().zip(std).map(|(m, s)| (m + s).min(cap));
    let lo = mean.iter().zip(std).map(|(m, s)| (m - s).max(0.0));
    xs.iter()
        .copied()
        .zip(hi)
        .chain(xs.iter().copied().zip(lo).rev())
        .collect()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::path::PathBuf;

    /// Damages a valid dataset in one way.
    type Corruption = fn(&mut Fig5Data);

    /// A fresh, empty per-test directory under the system temp dir.
    pub(crate) fn scratch_dir(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("tandem-xtask-fig5-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("temp dir is writable");
        dir
    }

    fn small_data() -> Fig5Data {
        Fig5Data {
            iterations: vec![0, 1, 2, 3, 4],
            t_total_mean_s: vec![100.0, 90.0, 80.0, 70.0, 65.0],
            t_total_std_s: vec![0.0, 5.0, 4.0, 3.0, 2.0],
            lower_bound_mean_s: vec![100.0, 80.0, 70.0, 60.0, 60.0],
            high_conf_pct_mean: vec![0.0, 20.0, 35.0, 45.0, 50.0],
            high_conf_pct_std: vec![0.0, 3.0, 2.0, 1.0, 1.0],
            ground_truth_pct: 55.0,
            n_robots: 2,
            examples: vec![
                ExampleSchedule {
                    iteration: 0,
                    t_total_s: 100.0,
                    lc: vec![vec![(0.0, 50.0)], vec![(50.0, 100.0)]],
                },
                ExampleSchedule {
                    iteration: 4,
                    t_total_s: 65.0,
                    lc: vec![
                        vec![(5.0, 15.0), (25.0, 35.0)],
                        vec![(15.0, 25.0), (35.0, 45.0)],
                    ],
                },
            ],
        }
    }

    /// Width and height from a PNG's IHDR chunk, after checking the signature.
    pub(crate) fn png_size(bytes: &[u8]) -> (u32, u32) {
        assert!(bytes.len() > 24, "PNG too short: {} bytes", bytes.len());
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "PNG signature");
        assert_eq!(&bytes[12..16], b"IHDR", "first chunk is IHDR");
        let be = |b: &[u8]| u32::from_be_bytes([b[0], b[1], b[2], b[3]]);
        (be(&bytes[16..20]), be(&bytes[20..24]))
    }

    #[test]
    fn draws_svg_and_png_with_labels_and_size() {
        let dir = scratch_dir("draw");
        let (svg, png) = (dir.join("fig5.svg"), dir.join("fig5.png"));
        draw_fig5(&small_data(), &svg, &png).unwrap();

        let svg_text = std::fs::read_to_string(&svg).unwrap();
        assert!(svg_text.starts_with("<svg"), "SVG starts with <svg");
        for label in [
            "task length T_total (s)",
            "high-confidence samples (%)",
            "iteration (rounds of 2 executions)",
            "robot 1 low-confidence",
            "robot 2 low-confidence",
            "neither low-confidence",
            "mean task length",
            "mean lower bound T*₀ (no margins)",
            "ground truth",
        ] {
            assert!(svg_text.contains(label), "SVG lacks the label {label:?}");
        }
        assert!(
            !svg_text.contains("both low-confidence"),
            "valid schedules need no violation swatch"
        );
        assert!(!svg_text.contains("SYNTHETIC"), "no note unless asked");
        // The example bars are drawn in the robots' colours.
        assert!(svg_text.contains("#4285F4"), "robot 1 blue bar segment");
        assert!(svg_text.contains("#D62728"), "robot 2 red bar segment");

        let png_bytes = std::fs::read(&png).unwrap();
        assert_eq!(png_size(&png_bytes), (WIDTH_PX, HEIGHT_PX));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn overlapping_low_confidence_gets_the_violation_swatch() {
        let dir = scratch_dir("overlap");
        let mut data = small_data();
        data.examples[0].lc[1] = vec![(40.0, 100.0)];
        draw_fig5(&data, &dir.join("a.svg"), &dir.join("a.png")).unwrap();
        let svg_text = std::fs::read_to_string(dir.join("a.svg")).unwrap();
        assert!(svg_text.contains("both low-confidence (invalid)"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn three_robots_get_their_own_colours_and_one_striped_swatch() {
        let dir = scratch_dir("three");
        let mut data = small_data();
        data.examples[1].lc.push(vec![(50.0, 60.0)]);
        assert_eq!(
            occupancy_segments(&data.examples[1]).last(),
            Some(&(60.0, 65.0, Occupancy::Neither))
        );
        assert!(occupancy_segments(&data.examples[1]).contains(&(50.0, 60.0, Occupancy::Robot(2))));
        data.n_robots = 3;
        draw_fig5(&data, &dir.join("a.svg"), &dir.join("a.png")).unwrap();
        let svg_text = std::fs::read_to_string(dir.join("a.svg")).unwrap();
        assert!(svg_text.contains("robots 1–3 low-confidence"));
        assert!(svg_text.contains("iteration (rounds of 3 executions)"));
        assert!(svg_text.contains("mean lower bound (operator-limited)"));
        assert!(svg_text.contains("none low-confidence"));
        assert!(svg_text.contains("#FF7F0E"), "robot 3 orange bar segment");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn mismatched_lengths_are_errors_and_write_nothing() {
        let dir = scratch_dir("mismatch");
        let (svg, png) = (dir.join("f.svg"), dir.join("f.png"));
        let mut data = small_data();
        data.t_total_std_s.pop();
        let err = draw_fig5(&data, &svg, &png).unwrap_err().to_string();
        assert!(
            err.contains("t_total_std_s") && err.contains("4") && err.contains("5"),
            "{err}"
        );

        let mut data = small_data();
        data.high_conf_pct_mean.push(1.0);
        let err = draw_fig5(&data, &svg, &png).unwrap_err().to_string();
        assert!(err.contains("high_conf_pct_mean"), "{err}");
        assert!(!svg.exists() && !png.exists(), "no partial output");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn bad_values_are_errors_naming_the_field() {
        let cases: Vec<(&str, Corruption)> = vec![
            ("is empty", |d| {
                d.examples.clear();
                d.iterations.clear();
                d.t_total_mean_s.clear();
                d.t_total_std_s.clear();
                d.lower_bound_mean_s.clear();
                d.high_conf_pct_mean.clear();
                d.high_conf_pct_std.clear();
            }),
            ("t_total_mean_s`[2] = NaN", |d| {
                d.t_total_mean_s[2] = f64::NAN
            }),
            ("t_total_std_s`[1] = -1", |d| d.t_total_std_s[1] = -1.0),
            ("lower_bound_mean_s`[0] = NaN", |d| {
                d.lower_bound_mean_s[0] = f64::NAN
            }),
            ("high_conf_pct_mean`[3] = 101", |d| {
                d.high_conf_pct_mean[3] = 101.0
            }),
            ("ground_truth_pct", |d| d.ground_truth_pct = f64::INFINITY),
            ("strictly increasing", |d| d.iterations[2] = 1),
            ("examples[1].iteration = 9", |d| d.examples[1].iteration = 9),
            ("examples[1].t_total_s", |d| {
                d.examples[1].t_total_s = f64::NAN
            }),
            ("examples[1], robot 2, interval 1", |d| {
                d.examples[1].lc[1][1] = (35.0, 66.0)
            }),
            ("examples[0], robot 1, interval 0", |d| {
                d.examples[0].lc[0][0] = (20.0, 10.0)
            }),
            ("both at iteration 0", |d| d.examples[1].iteration = 0),
        ];
        let dir = scratch_dir("bad");
        for (needle, corrupt) in cases {
            let mut data = small_data();
            corrupt(&mut data);
            let err = draw_fig5(&data, &dir.join("f.svg"), &dir.join("f.png"))
                .unwrap_err()
                .to_string();
            assert!(err.contains(needle), "expected {needle:?} in {err:?}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn interval_ending_at_t_total_within_rounding_is_accepted() {
        let mut data = small_data();
        data.examples[1].lc[1][1] = (35.0, 65.0 + 1e-12);
        data.validate().unwrap();
    }

    #[test]
    fn segments_partition_the_schedule_in_time_order() {
        let ex = ExampleSchedule {
            iteration: 0,
            t_total_s: 10.0,
            lc: vec![vec![(0.0, 3.0), (3.0, 4.0)], vec![(5.0, 7.0)]],
        };
        assert_eq!(
            occupancy_segments(&ex),
            vec![
                (0.0, 4.0, Occupancy::Robot(0)),
                (4.0, 5.0, Occupancy::Neither),
                (5.0, 7.0, Occupancy::Robot(1)),
                (7.0, 10.0, Occupancy::Neither),
            ]
        );
        let clash = ExampleSchedule {
            iteration: 0,
            t_total_s: 6.0,
            lc: vec![vec![(1.0, 4.0)], vec![(3.0, 6.0)]],
        };
        assert_eq!(
            occupancy_segments(&clash),
            vec![
                (0.0, 1.0, Occupancy::Neither),
                (1.0, 3.0, Occupancy::Robot(0)),
                (3.0, 4.0, Occupancy::Both),
                (4.0, 6.0, Occupancy::Robot(1)),
            ]
        );
        let empty = ExampleSchedule {
            iteration: 0,
            t_total_s: 0.0,
            lc: vec![vec![], vec![]],
        };
        assert!(occupancy_segments(&empty).is_empty());
    }

    #[test]
    fn legends_keep_clear_of_the_data_beneath_them() {
        let d = small_data();
        let layout = Layout::new(&d);
        // x range [-0.5 - 0.08, 4.5 + 0.08] (pad 0.5 plus half a 0.16-wide bar); the legends
        // cover the right 30 %, x >= 4.58 - 0.3 · 5.16 = 3.032, i.e. iteration 4, where
        // T_total + std = 67 s (bar 65 s) and the high-confidence band is [49, 51] %.
        assert!((layout.x_min + 0.58).abs() < 1e-12 && (layout.x_max - 4.58).abs() < 1e-12);
        // 100 s overall needs 106 s -> 120 s; 67 s under the legend needs 67 / 0.57 = 118 s.
        assert_eq!(layout.t_max_s, 120.0);
        // 55 % · 1.12 -> 70 %; the band under the legend starts at 49 % >= 0.5 · 70 %.
        assert_eq!(layout.pct_max, 70.0);
        assert_eq!(layout.pct_legend, SeriesLabelPosition::LowerRight);

        // High-confidence share stuck low at the right: the legend moves up and the axis
        // grows so the ground-truth line (55 %) stays below the legend: 55 / 0.5 -> 100 %.
        let mut low = small_data();
        low.high_conf_pct_mean = vec![0.0, 5.0, 5.0, 5.0, 5.0];
        let layout = Layout::new(&low);
        assert_eq!(layout.pct_legend, SeriesLabelPosition::UpperRight);
        assert_eq!(layout.pct_max, 100.0);

        // A task length that does not fall: the axis doubles so the legend has room.
        let mut flat = small_data();
        flat.t_total_mean_s = vec![100.0; 5];
        flat.t_total_std_s = vec![0.0; 5];
        flat.lower_bound_mean_s = vec![90.0; 5];
        flat.examples.clear();
        // 100 / 0.57 = 175.4 -> 200.
        assert_eq!(Layout::new(&flat).t_max_s, 200.0);
    }

    #[test]
    fn nice_ceiling_rounds_up_to_round_numbers() {
        assert_eq!(nice_ceiling(169.6), 200.0);
        assert_eq!(nice_ceiling(106.0), 120.0);
        assert_eq!(nice_ceiling(95.4), 100.0);
        assert_eq!(nice_ceiling(2.1), 2.5);
        assert_eq!(nice_ceiling(0.7), 0.8);
        assert_eq!(nice_ceiling(40.0), 40.0);
        assert_eq!(nice_ceiling(0.031), 0.04);
    }
}
