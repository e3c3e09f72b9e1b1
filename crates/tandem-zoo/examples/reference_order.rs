//! The fit's dependence on the order of the files, on the zoo (issue 38): for every task of
//! the given families and seeds, (a) the default fit (the medoid) on every rotation of the
//! files (`r, r + 1, …, r − 1`): its reference, its high confidence from the prior, and
//! whether its `σ²_D` is bit-identical to the unrotated fit's; (b) every single first file
//! (`Reference::First` on rotation `r`, what the zoo's spread measures): its high confidence
//! from the prior, the truth on its axis, the medoid's criterion (median `σ²_D`) and the
//! samples it trusts from the prior where the operator can be needed (where the
//! demonstrations vary / agree, `ZooTask::is_variable`).
//!
//! `cargo run --release -p tandem-zoo --example reference_order -- FAMILY[,FAMILY…] [SEEDS]`
//! (`SEEDS` like `0-7` or `0,3`; default the selection seeds 0–7). One line per task and
//! candidate, then per family: the spread of the single files, the spread of the default
//! over the rotations, and the default against the best single file.

#![allow(
    clippy::print_stdout,
    clippy::needless_range_loop,
    reason = "a measurement example that reports to the terminal"
)]
use rayon::prelude::*;
use tandem_confidence::{Confidence, ConfidenceParams};
use tandem_lfd::{Demonstration, FitParams, Reference, TaskModel};

/// What one fit shows.
struct View {
    reference: usize,
    high_pct: f64,
    truth_pct: f64,
    median_s2: f64,
    vary: usize,
    agree: usize,
    s2: Vec<f64>,
}

fn view(task: &tandem_zoo::ZooTask, model: &TaskModel, order: &[usize]) -> View {
    let conf = Confidence::from_prior(model.sigma2_d(), ConfidenceParams::default()).unwrap();
    let reference = order[model.reference_idx()];
    let progress = &task.progress[reference];
    let (mut vary, mut agree) = (0, 0);
    for (n, &h) in conf.conf().iter().enumerate() {
        if h && task.need_at(progress[n]) > 0.0 {
            if task.is_variable(progress[n]) {
                vary += 1;
            } else {
                agree += 1;
            }
        }
    }
    let mut s2 = model.sigma2_d().to_vec();
    s2.sort_by(f64::total_cmp);
    View {
        reference,
        high_pct: 100.0 * conf.high_share(),
        truth_pct: 100.0 * task.true_high_share(reference),
        median_s2: s2[s2.len() / 2],
        vary,
        agree,
        s2: model.sigma2_d().to_vec(),
    }
}

fn parse_seeds(s: &str) -> Vec<u64> {
    s.split(',')
        .flat_map(|part| match part.split_once('-') {
            Some((a, b)) => (a.parse().unwrap()..=b.parse().unwrap()).collect::<Vec<u64>>(),
            None => vec![part.parse().unwrap()],
        })
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let families: Vec<&str> = args[1].split(',').collect();
    let seeds = args
        .get(2)
        .map_or_else(|| (0..8).collect(), |s| parse_seeds(s));
    for fam_name in families {
        let fam = tandem_zoo::family(fam_name).unwrap();
        let rows: Vec<(u64, Vec<View>, Vec<View>)> = seeds
            .par_iter()
            .map(|&seed| {
                let task = (fam.generate)(seed).unwrap();
                let demos = task.demos().unwrap();
                let n = demos.len();
                let rotated = |r: usize| -> (Vec<Demonstration>, Vec<usize>) {
                    let order: Vec<usize> = (0..n).map(|k| (r + k) % n).collect();
                    (order.iter().map(|&i| demos[i].clone()).collect(), order)
                };
                let fits = |params: FitParams| -> Vec<View> {
                    (0..n)
                        .into_par_iter()
                        .map(|r| {
                            let (given, order) = rotated(r);
                            let model = TaskModel::fit(&given, &params).unwrap();
                            view(&task, &model, &order)
                        })
                        .collect()
                };
                let first = fits(FitParams {
                    reference: Reference::First,
                    ..FitParams::default()
                });
                let default = fits(FitParams::default());
                (seed, first, default)
            })
            .collect();
        let mut sums = [0.0f64; 4];
        for (seed, first, default) in &rows {
            let best = first.iter().map(|v| v.high_pct).fold(f64::MIN, f64::max);
            let worst = first.iter().map(|v| v.high_pct).fold(f64::MAX, f64::min);
            let dmax = default.iter().map(|v| v.high_pct).fold(f64::MIN, f64::max);
            let dmin = default.iter().map(|v| v.high_pct).fold(f64::MAX, f64::min);
            let identical = default.iter().all(|v| v.s2 == default[0].s2);
            let refs: Vec<usize> = default.iter().map(|v| v.reference).collect();
            println!(
                "{fam_name} seed {seed}: default over {} rotations: refs {refs:?}, HC {dmin:.2}..{dmax:.2} % (spread {:.2} pp), σ²_D bit-identical {identical}; single files {worst:.2}..{best:.2} % (spread {:.2}); default − best {:.2} pp",
                default.len(),
                dmax - dmin,
                best - worst,
                default[0].high_pct - best
            );
            for v in first {
                println!(
                    "    first {}: HC {:.2} truth {:.2} HC−truth {:+.2} median σ²_D {:.3e} prior-trusted needed: vary {} agree {}{}",
                    v.reference,
                    v.high_pct,
                    v.truth_pct,
                    v.high_pct - v.truth_pct,
                    v.median_s2,
                    v.vary,
                    v.agree,
                    if v.reference == default[0].reference {
                        "  <- medoid"
                    } else {
                        ""
                    }
                );
            }
            sums[0] += best - worst;
            sums[1] += dmax - dmin;
            sums[2] += default[0].high_pct - best;
            sums[3] += 1.0;
        }
        println!(
            "SUMMARY {fam_name}: seeds {} single-file spread {:.2} pp, default spread over rotations {:.2} pp, default − best {:.2} pp",
            sums[3],
            sums[0] / sums[3],
            sums[1] / sums[3],
            sums[2] / sums[3]
        );
    }
}
