//! `tandem plot`: the model, the confidence and the schedule as SVG and PNG.
//!
//! Pure Rust (plotters' SVG and bitmap backends, text through `ab_glyph` with the font and
//! colours of `tandem_plot`, shared with `cargo xtask study`'s Fig. 5), so plotting needs
//! nothing but a Rust toolchain. Every file is rendered to a
//! temporary name in the output folder first and renamed only when all of them succeeded,
//! so a failure leaves no partial figure set.

use std::path::{Path, PathBuf};

use anyhow::{Result, anyhow};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use tandem::Planner;
use tandem::lfd::ChannelKind;
use tandem_plot::{FONT_FAMILY, HIGH_CONFIDENCE, MEAN, NEITHER_LC, ROBOT_LC_N};
/// Figure width (px, SVG user units).
const WIDTH: u32 = 1200;
/// Height of one panel (px).
const PANEL_H: u32 = 170;

/// Turns a plotters error into an `anyhow` error.
fn de<E: std::fmt::Debug>(e: E) -> anyhow::Error {
    anyhow!("drawing failed: {e:?}")
}

/// A figure that can be drawn on any backend.
trait Figure {
    /// File stem (`model`, `confidence`, `schedule`).
    fn name(&self) -> &'static str;
    /// Height in px.
    fn height(&self) -> u32;
    /// Draws the figure.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>;
}

/// Renders `fig` to `<dir>/.<name>.svg.tmp` and `.png.tmp`; returns (temp, final) paths.
fn render<F: Figure>(fig: &F, dir: &Path) -> Result<Vec<(PathBuf, PathBuf)>> {
    let size = (WIDTH, fig.height());
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        fig.draw(&root)?;
        root.present().map_err(de)?;
    }
    let svg_final = dir.join(format!("{}.svg", fig.name()));
    let svg_tmp = dir.join(format!(".{}.tmp.svg", fig.name()));
    std::fs::write(&svg_tmp, svg)
        .map_err(|e| anyhow!("{}: cannot write: {e}", svg_tmp.display()))?;
    let png_final = dir.join(format!("{}.png", fig.name()));
    let png_tmp = dir.join(format!(".{}.tmp.png", fig.name()));
    {
        let root = BitMapBackend::new(&png_tmp, size).into_drawing_area();
        fig.draw(&root)?;
        root.present()
            .map_err(|e| anyhow!("{}: cannot write PNG: {e:?}", png_tmp.display()))?;
    }
    Ok(vec![(svg_tmp, svg_final), (png_tmp, png_final)])
}

/// Draws the three figures into `dir` (which must exist); returns the files written.
pub(crate) fn plot_all(planner: &Planner, dir: &Path) -> Result<Vec<PathBuf>> {
    tandem_plot::register_font()?;
    let mut pending = Vec::new();
    let result = (|| -> Result<()> {
        pending.extend(render(&ModelFigure::new(planner), dir)?);
        pending.extend(render(&ConfidenceFigure { planner }, dir)?);
        pending.extend(render(&ScheduleFigure::new(planner)?, dir)?);
        Ok(())
    })();
    if let Err(e) = result {
        for (tmp, _) in &pending {
            let _ = std::fs::remove_file(tmp);
        }
        // A PNG that failed half-way may exist under its temporary name too.
        for name in ["model", "confidence", "schedule"] {
            for ext in ["svg", "png"] {
                let _ = std::fs::remove_file(dir.join(format!(".{name}.tmp.{ext}")));
            }
        }
        return Err(e);
    }
    let mut written = Vec::new();
    for (tmp, fin) in pending {
        std::fs::rename(&tmp, &fin).map_err(|e| anyhow!("{}: cannot write: {e}", fin.display()))?;
        written.push(fin);
    }
    Ok(written)
}

/// Points kept per drawn series (files stay small; bands keep each stride's extremes).
const MAX_POINTS: usize = 2400;

/// Stride that keeps at most [`MAX_POINTS`] of `n` samples.
fn stride(n: usize) -> usize {
    n.div_ceil(MAX_POINTS).max(1)
}

/// Largest of `v[n..n + step]`.
fn band_max(v: &[f64], n: usize, step: usize) -> f64 {
    v[n..(n + step).min(v.len())]
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max)
}

/// Smallest of `v[n..n + step]`.
fn band_min(v: &[f64], n: usize, step: usize) -> f64 {
    v[n..(n + step).min(v.len())]
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min)
}

/// Value range of `values` with 5 % padding (a unit range around a constant).
fn padded(lo: f64, hi: f64) -> (f64, f64) {
    if !(lo.is_finite() && hi.is_finite()) {
        return (0.0, 1.0);
    }
    let span = hi - lo;
    if span <= 1e-12 * hi.abs().max(1.0) {
        return (lo - 0.5, hi + 0.5);
    }
    (lo - 0.05 * span, hi + 0.05 * span)
}

/// The y-axis unit of a channel of kind `kind`: metres and newtons as ROS and the fixtures
/// record them; a plain channel is drawn in the units it was recorded in.
fn unit_of(kind: ChannelKind) -> &'static str {
    match kind {
        ChannelKind::Position => "m",
        ChannelKind::Force => "N",
        ChannelKind::Binary => "0 = off, 1 = on",
        _ => "as recorded",
    }
}

/// One panel: a band and a line over reference time (s).
struct Panel {
    title: String,
    unit: String,
    line: Vec<f64>,
    lo: Vec<f64>,
    hi: Vec<f64>,
}

/// Mean ± one standard deviation of every coordinate over reference time, and the speed.
struct ModelFigure {
    dt_s: f64,
    panels: Vec<Panel>,
}

impl ModelFigure {
    fn new(planner: &Planner) -> Self {
        let model = planner.model();
        let names = model.tangent_names();
        let d = names.len();
        let n_ref = model.n_ref();
        let mut panels: Vec<Panel> = names[..d - 1]
            .iter()
            .map(|n| {
                let rot = n.ends_with(".rx") || n.ends_with(".ry") || n.ends_with(".rz");
                Panel {
                    title: if rot {
                        format!("{n}: orientation relative to the reference demonstration")
                    } else {
                        n.clone()
                    },
                    unit: if rot {
                        "deg".into()
                    } else {
                        unit_of(planner.params().fit.schema.kind(n)).into()
                    },
                    line: Vec::with_capacity(n_ref),
                    lo: Vec::with_capacity(n_ref),
                    hi: Vec::with_capacity(n_ref),
                }
            })
            .collect();
        for n in 0..n_ref {
            let mean = model.tangent_mean(n);
            let cov = model.covariance(n);
            for (j, p) in panels.iter_mut().enumerate() {
                let k = if p.unit == "deg" {
                    180.0 / std::f64::consts::PI
                } else {
                    1.0
                };
                let sd = cov[j * d + j].max(0.0).sqrt();
                p.line.push(k * mean[j]);
                p.lo.push(k * (mean[j] - sd));
                p.hi.push(k * (mean[j] + sd));
            }
        }
        panels.push(Panel {
            title: "speed: warp gradient dψ/dn (mean; band = demonstrated min..max)".into(),
            unit: "samples/ref. sample".into(),
            line: model.grad_mean().to_vec(),
            lo: model.grad_min().to_vec(),
            hi: model.grad_max().to_vec(),
        });
        Self {
            dt_s: model.dt_s(),
            panels,
        }
    }
}

impl Figure for ModelFigure {
    fn name(&self) -> &'static str {
        "model"
    }
    fn height(&self) -> u32 {
        PANEL_H * self.panels.len() as u32 + 40
    }
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        root.fill(&WHITE).map_err(de)?;
        let (top, body) = root.split_vertically(40);
        top.titled(
            "task model: mean ± 1 standard deviation over reference time (s)",
            (FONT_FAMILY, 20),
        )
        .map_err(de)?;
        let areas = body.split_evenly((self.panels.len(), 1));
        let t_end = self.panels[0].line.len().saturating_sub(1).max(1) as f64 * self.dt_s;
        let last = self.panels.len() - 1;
        for (k, (p, area)) in self.panels.iter().zip(&areas).enumerate() {
            let lo = p.lo.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = p.hi.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let (y0, y1) = padded(lo, hi);
            // Tick labels on every panel; the axis description only under the last one,
            // with room below its tick labels (it was drawn over them).
            let mut chart = ChartBuilder::on(area)
                .caption(&p.title, (FONT_FAMILY, 14))
                // Room on the right for the last tick label (it was cut off at the edge).
                .margin(5)
                .margin_right(20)
                .x_label_area_size(if k == last { 40 } else { 22 })
                .y_label_area_size(70)
                .build_cartesian_2d(0.0..t_end, y0..y1)
                .map_err(de)?;
            chart
                .configure_mesh()
                .light_line_style(WHITE)
                .x_desc(if k == last { "reference time (s)" } else { "" })
                .y_desc(p.unit.as_str())
                .label_style((FONT_FAMILY, 11))
                .draw()
                .map_err(de)?;
            let step = stride(p.line.len());
            let mut band: Vec<(f64, f64)> = (0..p.hi.len())
                .step_by(step)
                .map(|n| (n as f64 * self.dt_s, band_max(&p.hi, n, step)))
                .collect();
            band.extend(
                (0..p.lo.len())
                    .step_by(step)
                    .rev()
                    .map(|n| (n as f64 * self.dt_s, band_min(&p.lo, n, step))),
            );
            chart
                .draw_series(std::iter::once(Polygon::new(band, MEAN.mix(0.25))))
                .map_err(de)?;
            chart
                .draw_series(LineSeries::new(
                    (0..p.line.len())
                        .step_by(step)
                        .map(|n| (n as f64 * self.dt_s, p.line[n])),
                    MEAN.stroke_width(1),
                ))
                .map_err(de)?;
        }
        Ok(())
    }
}

/// σ²_D(t), the latched confidence map and the observed correction frequency.
struct ConfidenceFigure<'a> {
    planner: &'a Planner,
}

impl Figure for ConfidenceFigure<'_> {
    fn name(&self) -> &'static str {
        "confidence"
    }
    fn height(&self) -> u32 {
        2 * PANEL_H + 100
    }
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        let model = self.planner.model();
        let conf = self.planner.confidence();
        let obs = self.planner.observations();
        let dt = model.dt_s();
        let n_ref = model.n_ref();
        let t_end = n_ref.saturating_sub(1).max(1) as f64 * dt;
        root.fill(&WHITE).map_err(de)?;
        let (top, body) = root.split_vertically(40);
        top.titled(
            &format!(
                "confidence: {:.1} % of reference samples high-confidence after {} recorded {}",
                100.0 * conf.high_share(),
                self.planner.rounds_recorded(),
                if self.planner.rounds_recorded() == 1 {
                    "round"
                } else {
                    "rounds"
                }
            ),
            (FONT_FAMILY, 20),
        )
        .map_err(de)?;
        let areas = body.split_evenly((2, 1));
        // σ²_D on a log axis.
        let floor = 1e-9;
        let s2: Vec<f64> = model.sigma2_d().iter().map(|v| v.max(floor)).collect();
        // The level above which the prior alone (no executions) is low-confidence.
        let threshold = tandem::confidence::prior_low_threshold(conf.params())?
            .filter(|t| t.is_finite())
            .map(|t| t.max(floor));
        let hi = s2
            .iter()
            .copied()
            .chain(threshold)
            .fold(floor * 10.0, f64::max)
            * 2.0;
        let lo = s2
            .iter()
            .copied()
            .chain(threshold)
            .fold(f64::INFINITY, f64::min)
            .max(floor)
            / 2.0;
        let caption = match threshold {
            Some(t) => format!(
                "demonstration variance σ²_D(t) (Eq. 6, dimensionless); dashed: {t:.2e}, above \
                 which the prior alone is low-confidence"
            ),
            None => "demonstration variance σ²_D(t) (Eq. 6, dimensionless); the prior alone is \
                     low-confidence everywhere"
                .to_owned(),
        };
        let mut chart = ChartBuilder::on(&areas[0])
            .caption(caption, (FONT_FAMILY, 14))
            .margin(5)
            .margin_right(20)
            .x_label_area_size(30)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..t_end, (lo..hi).log_scale())
            .map_err(de)?;
        chart
            .configure_mesh()
            .light_line_style(WHITE)
            .x_desc("reference time (s)")
            .y_desc("σ²_D")
            .label_style((FONT_FAMILY, 11))
            .draw()
            .map_err(de)?;
        chart
            .draw_series(LineSeries::new(
                (0..n_ref)
                    .step_by(stride(n_ref))
                    .map(|n| (n as f64 * dt, band_max(&s2, n, stride(n_ref)))),
                MEAN.stroke_width(1),
            ))
            .map_err(de)?;
        if let Some(t) = threshold {
            chart
                .draw_series(DashedLineSeries::new(
                    [(0.0, t), (t_end, t)],
                    6,
                    4,
                    BLACK.stroke_width(1),
                ))
                .map_err(de)?;
        }
        // Confidence map and observed correction frequency.
        let mut chart = ChartBuilder::on(&areas[1])
            .caption(
                "high confidence (green area, Eq. 12, latched); dots: corrections / supervised executions",
                (FONT_FAMILY, 14),
            )
            .margin(5)
            .margin_right(20)
            .x_label_area_size(30)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..t_end, -0.05..1.05)
            .map_err(de)?;
        chart
            .configure_mesh()
            .light_line_style(WHITE)
            .x_desc("reference time (s)")
            .y_desc("share")
            .label_style((FONT_FAMILY, 11))
            .draw()
            .map_err(de)?;
        let c = conf.conf();
        let mut n = 0;
        while n < n_ref {
            let start = n;
            while n < n_ref && c[n] == c[start] {
                n += 1;
            }
            if c[start] {
                chart
                    .draw_series(std::iter::once(Rectangle::new(
                        [(start as f64 * dt, 0.0), (n as f64 * dt, 1.0)],
                        HIGH_CONFIDENCE.mix(0.3).filled(),
                    )))
                    .map_err(de)?;
            }
        }
        let (corr, sup) = (obs.corrections(), obs.supervised());
        chart
            .draw_series(
                (0..n_ref)
                    .filter(|&n| sup[n] >= 0.5)
                    .step_by(1.max(n_ref / 2000))
                    .map(|n| Circle::new((n as f64 * dt, corr[n] / sup[n]), 2, MEAN.filled())),
            )
            .map_err(de)?;
        Ok(())
    }
}

/// Every robot in global time: gray running high-confidence, each robot's colour
/// (`ROBOT_LC_N`: robot 1 blue, robot 2 red, …, repeated from robot 9 on) low-confidence.
struct ScheduleFigure {
    t_total_s: f64,
    spans: Vec<(f64, f64)>,
    lc: Vec<Vec<(f64, f64)>>,
    /// Per robot, its holds in global time: where it reaches the hold and where it leaves on
    /// schedule (equal for a hold without planned dwell).
    dwells: Vec<Vec<(f64, f64)>>,
    title: String,
}

impl ScheduleFigure {
    fn new(planner: &Planner) -> Result<Self> {
        let layout = crate::gantt::Layout::new(planner.problem(), planner.schedule())?;
        let lc = layout
            .legs
            .iter()
            .map(|legs| {
                legs.iter()
                    .flat_map(|l| l.lc_intervals().iter().map(|iv| (iv.start_s, iv.end_s)))
                    .collect()
            })
            .collect();
        let spans: Vec<(f64, f64)> = layout
            .legs
            .iter()
            .map(|legs| {
                let first = legs.first().map_or(0.0, |l| l.start_s());
                (first, legs.last().map_or(first, |l| l.end_s()))
            })
            .collect();
        let t_total_s = spans.iter().map(|s| s.1).fold(f64::NEG_INFINITY, f64::max);
        let mut dwells = vec![Vec::new(); spans.len()];
        for d in &layout.dwells {
            if d.ref_idx > 0 {
                dwells[d.robot].push((d.start_s, d.end_s));
            }
        }
        let schedule = planner.schedule();
        let serial = crate::gantt::serial_t_total_s(
            planner.problem(),
            schedule.n_robots(),
            schedule.tick_s,
        )?;
        let n = schedule.n_robots();
        let starts = match crate::gantt::offsets_text(schedule) {
            None => String::new(),
            Some(t) if n == 2 => format!(", robot 2 starts at τ = {t} s"),
            Some(t) => format!(", robots 2–{n} start at τ = {t} s"),
        };
        let holds = if schedule.has_holds() {
            let waits: f64 = (0..n).map(|i| schedule.dwell_s(i)).sum();
            format!(
                "; {} holds (black ticks), {waits:.2} s planned waiting (white)",
                dwells.iter().map(Vec::len).sum::<usize>()
            )
        } else {
            String::new()
        };
        Ok(Self {
            t_total_s,
            spans,
            lc,
            dwells,
            title: format!(
                "schedule: T_total {t_total_s:.2} s (fastest serial {serial:.2} s){starts}{holds}"
            ),
        })
    }
}

impl Figure for ScheduleFigure {
    fn name(&self) -> &'static str {
        "schedule"
    }
    fn height(&self) -> u32 {
        60 + 100 * (self.spans.len() as u32 + 1)
    }
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        root.fill(&WHITE).map_err(de)?;
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FONT_FAMILY, 18))
            .margin(10)
            .margin_right(20)
            .x_label_area_size(40)
            .y_label_area_size(10)
            .build_cartesian_2d(
                0.0..self.t_total_s.max(1e-9),
                0.0..(self.spans.len() + 1) as f64,
            )
            .map_err(de)?;
        // An interval narrower than two pixels is drawn two pixels wide, so that a
        // one-sample low-confidence island is visible at the committed size.
        let min_w = 2.0 * self.t_total_s.max(1e-9) / f64::from(WIDTH);
        let widened = |(s, e): (f64, f64)| {
            let pad = ((min_w - (e - s)) / 2.0).max(0.0);
            (s - pad, e + pad)
        };
        chart
            .configure_mesh()
            .disable_y_mesh()
            .light_line_style(WHITE)
            .y_labels(0)
            .x_desc(if self.spans.len() <= 2 {
                "global time (s); blue = robot 1 low-confidence, red = robot 2 low-confidence, gray = high-confidence"
            } else {
                "global time (s); coloured = low-confidence (robot 1 blue, robot 2 red, 3 orange, …), gray = high-confidence"
            })
            .label_style((FONT_FAMILY, 12))
            .draw()
            .map_err(de)?;
        let n = self.spans.len();
        // The operator row (bottom): whom the operator supervises, in that robot's colour.
        chart
            .draw_series(std::iter::once(Text::new(
                "operator: supervises the robot of that colour (white = nobody)",
                (0.0, 0.83),
                (FONT_FAMILY, 13)
                    .into_font()
                    .color(&BLACK)
                    .pos(Pos::new(HPos::Left, VPos::Bottom)),
            )))
            .map_err(de)?;
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(0.0, 0.2), (self.t_total_s, 0.8)],
                BLACK.stroke_width(1),
            )))
            .map_err(de)?;
        for (i, colour) in ROBOT_LC_N.iter().cycle().take(n).enumerate() {
            chart
                .draw_series(self.lc[i].iter().map(|&iv| {
                    let (s, e) = widened(iv);
                    Rectangle::new([(s, 0.2), (e, 0.8)], colour.filled())
                }))
                .map_err(de)?;
        }
        for (i, colour) in ROBOT_LC_N.iter().cycle().take(n).enumerate() {
            let y = (n + 1 - i) as f64 - 0.5;
            let (a, b) = self.spans[i];
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(a, y - 0.3), (b, y + 0.3)],
                    NEITHER_LC.filled(),
                )))
                .map_err(de)?;
            let label = format!(
                "robot {}: {:.2} – {:.2} s",
                i + 1,
                self.spans[i].0,
                self.spans[i].1
            );
            chart
                .draw_series(std::iter::once(Text::new(
                    label,
                    (a, y + 0.33),
                    (FONT_FAMILY, 13)
                        .into_font()
                        .color(&BLACK)
                        .pos(Pos::new(HPos::Left, VPos::Bottom)),
                )))
                .map_err(de)?;
            chart
                .draw_series(self.lc[i].iter().map(|&iv| {
                    let (s, e) = widened(iv);
                    Rectangle::new([(s, y - 0.3), (e, y + 0.3)], colour.filled())
                }))
                .map_err(de)?;
            // Planned waits at hold points: white inside a black outline; every hold a
            // black tick where the robot reaches it.
            chart
                .draw_series(
                    self.dwells[i].iter().filter(|d| d.1 > d.0).map(|&(s, e)| {
                        Rectangle::new([(s, y - 0.3), (e, y + 0.3)], WHITE.filled())
                    }),
                )
                .map_err(de)?;
            chart
                .draw_series(self.dwells[i].iter().filter(|d| d.1 > d.0).map(|&(s, e)| {
                    Rectangle::new([(s, y - 0.3), (e, y + 0.3)], BLACK.stroke_width(1))
                }))
                .map_err(de)?;
            chart
                .draw_series(self.dwells[i].iter().map(|&(s, _)| {
                    PathElement::new(vec![(s, y - 0.38), (s, y + 0.38)], BLACK.stroke_width(2))
                }))
                .map_err(de)?;
        }
        Ok(())
    }
}
