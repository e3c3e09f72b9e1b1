//! `cargo xtask capacity --operators M,…` (issue 44): a fleet of `N` robots and `M`
//! operators in a continuous cell on the sanding task, pooled against sectored, against the
//! ceiling `min(r·N, o·M)` with both constants measured in the same run.
//!
//! - *Pooled*: one continuous cell of `N` robots with `M` tokens (`[operator] operators = M`:
//!   the planner's `SamplerParams::operators`, `M` simulated operators, one per operator index
//!   of `Tick::operator`), measured like every capacity row (steady throughput over the last
//!   [`END_SHARE`](crate::capacity::END_SHARE) of the tasks, mean over trials).
//! - *Sectored*: the best fixed partition of the `N` robots into at most `M` one-operator
//!   cells, each cell's throughput the *measured* one-operator row of its size from the same
//!   run (so the one-operator rows `N = 1..=max_robots` must run), the partition chosen by
//!   dynamic programming over those measurements ([`best_sectors`]).
//! - *Ceiling*: `min(r·N, o·M)` with `r` the measured throughput of one robot alone (the
//!   one-operator row `N = 1`: `3600/T₁`) and `o` the measured throughput of the saturated
//!   operator (the largest one-operator row: `3600/I`, the 53.5 and 93.7).
//!
//! Writes `fleet.json`, `fleet.svg` and `fleet.png` beside `capacity.json`.

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, anyhow, bail};
use plotters::prelude::*;
use serde::Serialize;
use tandem::sim::study::{Cell, StudyConfig, StudyInputs, run_cell_study};
use tandem_plot::{FONT_FAMILY, GROUND_TRUTH, MEAN, OPERATOR};

use crate::capacity::{CellRow, cell_row};
use crate::study::TrialBar;

/// One `(N, M)` of the fleet table.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub(crate) struct FleetRow {
    /// Robots `N`.
    pub robots: usize,
    /// Operators `M`.
    pub operators: usize,
    /// The pooled cell's measured row (`M` tokens).
    pub pooled: CellRow,
    /// The best sectors' throughput: the sum of the measured one-operator rows of their sizes
    /// (tasks per hour).
    pub sectored_per_h: f64,
    /// The sizes of the best sectors (one per operator used, largest first).
    pub sectors: Vec<usize>,
    /// The ceiling `min(r·N, o·M)` (tasks per hour).
    pub ceiling_per_h: f64,
    /// The pooled cell's share of the ceiling (in [0, 1]).
    pub pooled_share: f64,
}

/// What `fleet.json` holds.
#[derive(Serialize)]
struct FleetFile<'a> {
    trials: usize,
    seed: u64,
    /// `r`: the one robot's measured throughput (tasks per hour; the one-operator row `N = 1`).
    robot_per_h: f64,
    /// `o`: the saturated operator's measured throughput (tasks per hour; the largest
    /// one-operator row).
    operator_per_h: f64,
    /// The one-operator rows the constants and the sectors are taken from.
    one_operator: &'a [CellRow],
    rows: &'a [FleetRow],
}

/// The best partition of `n` robots into at most `m` one-operator cells, given the measured
/// throughput `one[k − 1]` of a one-operator cell of `k` robots (`k = 1..=n`): the largest sum
/// and the sizes (largest first). Dynamic programming over (robots left, cells left); a cell
/// of no robots is no cell.
pub(crate) fn best_sectors(one: &[f64], n: usize, m: usize) -> (f64, Vec<usize>) {
    assert!(one.len() >= n, "one-operator rows for every size up to n");
    // best[j][r]: the best sum of r robots in at most j cells, and the first cell's size.
    let mut best = vec![vec![(f64::NEG_INFINITY, 0_usize); n + 1]; m + 1];
    for row in &mut best {
        row[0] = (0.0, 0);
    }
    for j in 1..=m {
        for r in 1..=n {
            for k in 1..=r {
                let v = one[k - 1] + best[j - 1][r - k].0;
                if v > best[j][r].0 {
                    best[j][r] = (v, k);
                }
            }
        }
    }
    let mut sizes = Vec::new();
    let (mut j, mut r) = (m, n);
    while r > 0 {
        let k = best[j][r].1;
        sizes.push(k);
        r -= k;
        j -= 1;
    }
    sizes.sort_unstable_by(|a, b| b.cmp(a));
    (best[m][n].0, sizes)
}

/// Runs the pooled cells of every `(N, M)` with `N` in `robots`, `M` in `operators`, `M < N`,
/// after the one-operator rows `one` (continuous, `N = 1..=max`, same configuration; the
/// steady state measured as `capacity --steady-tasks` says), prints
/// the table and writes `fleet.json`, `fleet.svg` and `fleet.png` in `out`. Returns the pooled
/// cells' ticks with more than `M` robots low-confidence plus their faults (must be 0).
pub(crate) fn run(
    base: &StudyConfig,
    inputs: &StudyInputs,
    one: &[CellRow],
    robots: &[usize],
    operators: &[usize],
    steady_tasks: Option<usize>,
    out: &Path,
) -> anyhow::Result<u64> {
    let one_tp: Vec<f64> = one.iter().map(|r| r.steady_throughput_per_h).collect();
    if one.iter().enumerate().any(|(i, r)| r.robots != i + 1) {
        bail!("--operators needs the one-operator continuous rows N = 1, 2, … (--min-robots 1)");
    }
    let robot_per_h = *one_tp
        .first()
        .ok_or_else(|| anyhow!("no one-operator rows"))?;
    let operator_per_h = one_tp.iter().copied().fold(0.0, f64::max);
    let mut rows = Vec::new();
    for &n in robots {
        if n > one.len() {
            bail!(
                "--fleet-robots {n}: above --max-robots ({}), whose one-operator rows the \
                 sectors need",
                one.len()
            );
        }
        for &m in operators.iter().filter(|&&m| m < n) {
            let mut config = StudyConfig {
                executions: base.executions / n * n,
                robots: n,
                cell: Cell::Continuous,
                ..base.clone()
            };
            config.operator.operators = m;
            config
                .validate()
                .with_context(|| format!("the fleet of N = {n}, M = {m}"))?;
            let t = Instant::now();
            let bar = TrialBar::new(&config, &format!("re-plans of N = {n}, M = {m} (pooled)"))?;
            let (result, _) = run_cell_study(&config, inputs, &|p| bar.step(p))
                .with_context(|| format!("the pooled cell of N = {n}, M = {m}"))?;
            bar.clear();
            let pooled = cell_row(&result, t.elapsed().as_secs_f64(), steady_tasks)?;
            let (sectored_per_h, sectors) = best_sectors(&one_tp, n, m);
            let ceiling_per_h = (robot_per_h * n as f64).min(operator_per_h * m as f64);
            let row = FleetRow {
                robots: n,
                operators: m,
                pooled_share: pooled.steady_throughput_per_h / ceiling_per_h,
                pooled,
                sectored_per_h,
                sectors,
                ceiling_per_h,
            };
            println!(
                "N = {n}, M = {m}: pooled {:.1} ± {:.1} tasks/h ({:.1} % of the ceiling {:.1}), \
                 best sectors {:.1} ({:?}), {} ticks over M, {} faults ({:.1} s)",
                row.pooled.steady_throughput_per_h,
                row.pooled.steady_throughput_std_per_h,
                100.0 * row.pooled_share,
                row.ceiling_per_h,
                row.sectored_per_h,
                row.sectors,
                row.pooled.overlap_ticks,
                row.pooled.faults,
                row.pooled.wall_s
            );
            rows.push(row);
        }
    }
    println!(
        "\nfleet (continuous cell; r = {robot_per_h:.1} tasks/h per robot, o = \
         {operator_per_h:.1} per operator, measured in this run):"
    );
    print!("{}", fleet_table(&rows));
    let file = FleetFile {
        trials: base.trials,
        seed: base.seed,
        robot_per_h,
        operator_per_h,
        one_operator: one,
        rows: &rows,
    };
    let json = out.join("fleet.json");
    std::fs::write(&json, serde_json::to_string_pretty(&file)? + "\n")
        .with_context(|| format!("writing {}", json.display()))?;
    draw_fleet(&rows, &out.join("fleet.svg"), &out.join("fleet.png"))?;
    println!(
        "wrote fleet.json, fleet.svg, fleet.png in {}",
        out.display()
    );
    Ok(rows
        .iter()
        .map(|r| r.pooled.overlap_ticks + r.pooled.faults)
        .sum())
}

/// The fleet table as Markdown (docs/study.md).
pub(crate) fn fleet_table(rows: &[FleetRow]) -> String {
    let mut out = String::from(
        "| (N, M) | pooled (tasks/h) | ceiling min(r·N, o·M) | share | best sectors (tasks/h) | \
         sectors | operators busy | ticks > M | faults |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        out += &format!(
            "| ({}, {}) | {:.1} ± {:.1} | {:.1} | {:.1} % | {:.1} | {} | {:.0} % | {} | {} |\n",
            r.robots,
            r.operators,
            r.pooled.steady_throughput_per_h,
            r.pooled.steady_throughput_std_per_h,
            r.ceiling_per_h,
            100.0 * r.pooled_share,
            r.sectored_per_h,
            r.sectors
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(" + "),
            100.0 * r.pooled.operator_busy_share,
            r.pooled.overlap_ticks,
            r.pooled.faults
        );
    }
    out
}

/// Image size (pixels; SVG user units).
const SIZE_PX: (u32, u32) = (900, 600);

/// Draws per `(N, M)` the pooled cell's measured throughput, the best sectors' and the
/// ceiling, as SVG and PNG.
///
/// # Errors
/// No rows, or a failure to render or write a file.
pub(crate) fn draw_fleet(rows: &[FleetRow], svg: &Path, png: &Path) -> anyhow::Result<()> {
    if rows.is_empty() {
        bail!("fleet figure: no (N, M) to draw (give --operators M below some --fleet-robots N)");
    }
    tandem_plot::register_font()?;
    let mut svg_text = String::new();
    {
        let root = SVGBackend::with_string(&mut svg_text, SIZE_PX).into_drawing_area();
        draw_on(&root, rows)?;
        root.present()
            .map_err(|e| anyhow!("finishing the fleet SVG: {e}"))?;
    }
    {
        let root = BitMapBackend::new(png, SIZE_PX).into_drawing_area();
        draw_on(&root, rows)?;
        root.present()
            .map_err(|e| anyhow!("writing {}: {e}", png.display()))?;
    }
    std::fs::write(svg, svg_text).with_context(|| format!("writing {}", svg.display()))?;
    Ok(())
}

fn draw_on<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    rows: &[FleetRow],
) -> anyhow::Result<()> {
    let err = |what: &'static str| {
        move |e: DrawingAreaErrorKind<DB::ErrorType>| {
            anyhow!("drawing the fleet figure ({what}): {e}")
        }
    };
    root.fill(&WHITE).map_err(err("background"))?;
    let top = rows
        .iter()
        .flat_map(|r| {
            [
                r.pooled.steady_throughput_per_h,
                r.sectored_per_h,
                r.ceiling_per_h,
            ]
        })
        .fold(0.0, f64::max);
    let y_max = crate::fig5::nice_ceiling(top * 1.3);
    let labels: Vec<String> = rows
        .iter()
        .map(|r| format!("N = {}, M = {}", r.robots, r.operators))
        .collect();
    let k = rows.len() as f64;
    let mut chart = ChartBuilder::on(root)
        .margin(20)
        .caption(
            "a fleet: N robots, M operators (continuous cell)",
            (FONT_FAMILY, 24),
        )
        .x_label_area_size(60)
        .y_label_area_size(80)
        .build_cartesian_2d(-0.5..k - 0.5, 0.0..y_max)
        .map_err(err("axes"))?;
    mesh_style!(
        chart
            .configure_mesh()
            .x_labels(rows.len())
            .x_label_formatter(&|v| {
                let i = v.round();
                if (v - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < labels.len() {
                    labels[i as usize].clone()
                } else {
                    String::new()
                }
            })
            .y_label_formatter(&|v| format!("{v:.0}"))
            .x_desc("robots N and operators M")
            .y_desc("throughput (tasks per hour)")
    )
    .draw()
    .map_err(err("mesh"))?;
    let at = |i: usize, dx: f64| i as f64 + dx;
    for (dx, colour, label, value) in [
        (
            -0.15,
            OPERATOR,
            "pooled: M tokens (measured, last 10 %)",
            (|r: &FleetRow| r.pooled.steady_throughput_per_h) as fn(&FleetRow) -> f64,
        ),
        (
            0.15,
            MEAN,
            "best sectors: one-operator cells (measured)",
            |r: &FleetRow| r.sectored_per_h,
        ),
    ] {
        chart
            .draw_series(rows.iter().enumerate().map(|(i, r)| {
                Rectangle::new(
                    [(at(i, dx - 0.12), 0.0), (at(i, dx + 0.12), value(r))],
                    colour.filled(),
                )
            }))
            .map_err(err("bars"))?
            .label(label)
            .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 24, y + 6)], colour.filled()));
    }
    chart
        .draw_series(rows.iter().enumerate().map(|(i, r)| {
            PathElement::new(
                vec![
                    (at(i, -0.35), r.ceiling_per_h),
                    (at(i, 0.35), r.ceiling_per_h),
                ],
                GROUND_TRUTH.stroke_width(3),
            )
        }))
        .map_err(err("ceiling"))?
        .label("ceiling min(r·N, o·M), r and o measured")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], GROUND_TRUTH.stroke_width(3)));
    draw_legend!(chart, SeriesLabelPosition::UpperLeft, 18, err("legend"))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_best_sectors_split_where_the_one_operator_cell_saturates() {
        // A one-operator cell gains 50 per robot up to 2 robots, then 10 for the third and
        // nothing after: 8 robots under 2 operators are best 4 + 4 (or any split with ≥ 3
        // each): 110 + 110 = 220; by hand.
        let one = [50.0, 100.0, 110.0, 110.0, 110.0, 110.0, 110.0, 110.0];
        let (v, sizes) = best_sectors(&one, 8, 2);
        assert_eq!(v, 220.0);
        assert_eq!(sizes.len(), 2);
        assert!(sizes.iter().all(|&k| k >= 3), "{sizes:?}");
        // 3 robots, 2 operators: 2 + 1 (150) beats 3 alone (110).
        assert_eq!(best_sectors(&one, 3, 2), (150.0, vec![2, 1]));
        // One operator: the whole cell.
        assert_eq!(best_sectors(&one, 5, 1), (110.0, vec![5]));
        // More operators than robots: one robot each.
        assert_eq!(best_sectors(&one, 2, 4), (100.0, vec![1, 1]));
    }

    #[test]
    fn the_fleet_table_names_the_sectors() {
        let cell = CellRow {
            robots: 4,
            switch_s: 0.0,
            tasks: 240,
            steady_throughput_per_h: 180.0,
            steady_throughput_std_per_h: 1.0,
            operator_busy_share: 0.9,
            robot_wait_share: 0.1,
            lc_s_per_task: 19.0,
            plan_per_h: 185.0,
            bound_per_h: 188.0,
            lc_stretches: 4.0,
            overlap_ticks: 0,
            faults: 0,
            high_conf_pct: 60.0,
            wall_s: 1.0,
            steady_tasks: 24,
            plan_gap_per_task: tandem::sim::workcell::PlanGap::default(),
        };
        let row = FleetRow {
            robots: 4,
            operators: 2,
            pooled: cell,
            sectored_per_h: 178.0,
            sectors: vec![2, 2],
            ceiling_per_h: 187.4,
            pooled_share: 180.0 / 187.4,
        };
        let t = fleet_table(std::slice::from_ref(&row));
        assert!(
            t.contains("| (4, 2) | 180.0 ± 1.0 | 187.4 | 96.1 % | 178.0 | 2 + 2 |"),
            "{t}"
        );
        let dir = std::env::temp_dir().join(format!("tandem_fleet_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        draw_fleet(&[row], &dir.join("f.svg"), &dir.join("f.png")).unwrap();
        let svg = std::fs::read_to_string(dir.join("f.svg")).unwrap();
        assert!(
            svg.contains("pooled") && svg.contains("N = 4, M = 2"),
            "missing labels"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
