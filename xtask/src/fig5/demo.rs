//! Synthetic Fig. 5 data for the figure's tests: a closed-form toy shaped like the paper's
//! study, NOT output of the tandem pipeline and not study results. It exercises the figure
//! end to end (150 iterations, five "trials", example schedules that alternate the robots'
//! sanding passes) with numbers that can be checked by hand.

use super::tests::{png_size, scratch_dir};
use super::{
    ExampleSchedule, Fig5Data, HEIGHT_PX, Occupancy, WIDTH_PX, draw_fig5, occupancy_segments,
};

/// Duration of one robot's execution in the demo model, in seconds of its own time.
const DEMO_EXEC_S: f64 = 84.0;
/// Sanding passes of the demo model, `(start_s, end_s)` in execution time: 10 s of
/// sanding, then 12 s of slow transit to the next pass (as in the paper's demonstrations,
/// slow enough for the other robot to sand a pass meanwhile).
const DEMO_PASSES: [(f64, f64); 4] = [(4.0, 14.0), (26.0, 36.0), (48.0, 58.0), (70.0, 80.0)];
/// Decay constants (in iterations) of the five synthetic "trials".
const DEMO_TAUS: [f64; 5] = [20.0, 22.5, 25.0, 27.5, 30.0];
/// Number of executed pairs in the demo (the paper's 300 executions).
const DEMO_PAIRS: usize = 150;
/// Step of the demo's offset search, in seconds.
const DEMO_OFFSET_STEP_S: f64 = 0.5;

/// Low-confidence intervals of one execution (execution time, sorted, disjoint) after
/// `k` pairs in a synthetic trial with decay constant `tau`: everything before the first
/// pair; then passes 1–3 widened by a margin that shrinks as `10 s · exp(-k/tau)`, and
/// pass 4 (never corrected) fading out faster.
fn demo_lc_intervals(k: usize, tau: f64) -> Vec<(f64, f64)> {
    if k == 0 {
        return vec![(0.0, DEMO_EXEC_S)];
    }
    let kf = k as f64;
    let margin = 10.0 * (-kf / tau).exp();
    let mut raw: Vec<(f64, f64)> = DEMO_PASSES[..3]
        .iter()
        .map(|&(s, e)| ((s - margin).max(0.0), (e + margin).min(DEMO_EXEC_S)))
        .collect();
    let (s4, e4) = DEMO_PASSES[3];
    let half4 = (0.5 * (e4 - s4) + margin) * (-kf / (0.4 * tau)).exp();
    if half4 >= 0.5 {
        let mid = 0.5 * (s4 + e4);
        raw.push(((mid - half4).max(0.0), (mid + half4).min(DEMO_EXEC_S)));
    }
    let mut merged: Vec<(f64, f64)> = Vec::new();
    for (s, e) in raw {
        match merged.last_mut() {
            Some(last) if s <= last.1 => last.1 = last.1.max(e),
            _ => merged.push((s, e)),
        }
    }
    merged
}

/// Smallest offset (multiple of [`DEMO_OFFSET_STEP_S`]) of robot 2's start such that the
/// two robots' low-confidence intervals never overlap (touching is allowed).
fn demo_offset_s(lc: &[(f64, f64)]) -> f64 {
    let overlaps = |o: f64| {
        lc.iter()
            .any(|&(s1, e1)| lc.iter().any(|&(s2, e2)| s1 < e2 + o && s2 + o < e1))
    };
    let steps = (DEMO_EXEC_S / DEMO_OFFSET_STEP_S).ceil() as usize;
    (0..=steps)
        .map(|i| i as f64 * DEMO_OFFSET_STEP_S)
        .find(|&o| !overlaps(o))
        .unwrap_or(DEMO_EXEC_S)
}

/// Share (0–100) of the execution that is high-confidence.
fn demo_high_conf_pct(lc: &[(f64, f64)]) -> f64 {
    let lc_s: f64 = lc.iter().map(|(s, e)| e - s).sum();
    100.0 * (1.0 - lc_s / DEMO_EXEC_S)
}

/// A synthetic, deterministic dataset shaped like the paper's study (two robots, one
/// 84 s sanding execution each, 150 pairs, five "trials" that differ only in how fast
/// their low-confidence margins shrink). It exercises the figure end to end; it is a
/// closed-form toy, not output of the tandem pipeline.
fn demo_data() -> Fig5Data {
    let iterations: Vec<usize> = (0..=DEMO_PAIRS).collect();
    let mut fig = Fig5Data {
        iterations: iterations.clone(),
        t_total_mean_s: Vec::with_capacity(iterations.len()),
        t_total_std_s: Vec::with_capacity(iterations.len()),
        // Robot 2 cannot sand its first pass (10 s) before robot 1's ends: T ≥ 84 + 10 s.
        lower_bound_mean_s: vec![DEMO_EXEC_S + 10.0; iterations.len()],
        high_conf_pct_mean: Vec::with_capacity(iterations.len()),
        high_conf_pct_std: Vec::with_capacity(iterations.len()),
        ground_truth_pct: 100.0 * (1.0 - 30.0 / DEMO_EXEC_S),
        n_robots: 2,
        examples: Vec::new(),
    };
    for &k in &iterations {
        let (t_totals, pcts): (Vec<f64>, Vec<f64>) = DEMO_TAUS
            .iter()
            .map(|&tau| {
                let lc = demo_lc_intervals(k, tau);
                (DEMO_EXEC_S + demo_offset_s(&lc), demo_high_conf_pct(&lc))
            })
            .unzip();
        let (t_mean, t_std) = tandem::sim::study::mean_std(t_totals.iter().copied());
        let (p_mean, p_std) = tandem::sim::study::mean_std(pcts.iter().copied());
        fig.t_total_mean_s.push(t_mean);
        fig.t_total_std_s.push(t_std);
        fig.high_conf_pct_mean.push(p_mean);
        fig.high_conf_pct_std.push(p_std);
    }
    let tau = DEMO_TAUS[2];
    fig.examples = (0..=DEMO_PAIRS)
        .step_by(25)
        .map(|k| {
            let lc = demo_lc_intervals(k, tau);
            let offset = demo_offset_s(&lc);
            ExampleSchedule {
                iteration: k,
                t_total_s: DEMO_EXEC_S + offset,
                lc: vec![
                    lc.clone(),
                    lc.iter().map(|&(s, e)| (s + offset, e + offset)).collect(),
                ],
            }
        })
        .collect();
    fig
}

#[test]
fn demo_data_is_valid_and_has_the_papers_shape() {
    let d = demo_data();
    d.validate().unwrap();
    let last = d.iterations.len() - 1;
    // Before any pair everything is low-confidence: the robots run one after the other
    // (T_total = 2 · 84 s) with no high-confidence samples, identically in every trial.
    assert_eq!((d.t_total_mean_s[0], d.t_total_std_s[0]), (168.0, 0.0));
    assert_eq!(
        (d.high_conf_pct_mean[0], d.high_conf_pct_std[0]),
        (0.0, 0.0)
    );
    // At the end only the 10 s sanding of passes 1–3 plus margins m <= 10 s · exp(-150/30)
    // = 0.067 s per side is low-confidence. Any offset in [10 + 2m, 12 - 2m] s lets robot 2
    // sand each pass while robot 1 is in transit; the first 0.5 s step in it is 10.5 s, so
    // T_total = 84 + 10.5 s in every trial, and the high-confidence share is below the
    // ground truth by at most 6 · 0.067 s / 84 s = 0.48 percentage points.
    assert_eq!((d.t_total_mean_s[last], d.t_total_std_s[last]), (94.5, 0.0));
    let gap = d.ground_truth_pct - d.high_conf_pct_mean[last];
    assert!(0.0 < gap && gap < 0.48, "gap {gap}");
    assert!((d.ground_truth_pct - 100.0 * 54.0 / 84.0).abs() < 1e-12);
    for ex in &d.examples {
        assert!(
            occupancy_segments(ex)
                .iter()
                .all(|s| s.2 != Occupancy::Both),
            "demo schedule at iteration {} overlaps",
            ex.iteration
        );
    }
}

#[test]
fn the_demo_figure_renders_in_both_formats() {
    let dir = scratch_dir("demo");
    let (svg, png) = (dir.join("fig5-demo.svg"), dir.join("fig5-demo.png"));
    draw_fig5(&demo_data(), &svg, &png).unwrap();
    let svg_text = std::fs::read_to_string(&svg).unwrap();
    assert!(svg_text.contains("iteration (rounds of 2 executions)"));
    assert_eq!(
        png_size(&std::fs::read(&png).unwrap()),
        (WIDTH_PX, HEIGHT_PX)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
