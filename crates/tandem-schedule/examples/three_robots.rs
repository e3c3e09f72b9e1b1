//! The three-robot margin-free search (`margin_free_bound` with `N = 3`, no switch time) on the
//! test kit's random problems `testkit::random_problem(400..=1500, 10 ms)`, ChaCha8 seeds
//! `0..SEEDS` (default 40): per seed the LC runs per robot, the search's nodes, whether it
//! proved its optimum, whether it reached a leaf (an order, so a margin-free schedule: an upper
//! bound on `T*₀` and a start for the completions), the best margin-free `T_total` found, the
//! certificate's bound `B(3)` beside the two-robot bound `B(2)` and the operator bound, and the
//! wall time; then the counts (docs/decisions.md, "The three-robot search: a dive that reaches a
//! leaf and the open nodes' bound (issue 38)").
//!
//! ```text
//! cargo run --release -p tandem-schedule --example three_robots [-- SEEDS]
//! ```
#![allow(clippy::print_stdout, reason = "an example reports to the terminal")]

use std::time::Instant;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tandem_schedule::{ExactParams, margin_free_bound, operator_bound_s, testkit};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let seeds: u64 = match std::env::args().nth(1) {
        Some(s) => s
            .parse()
            .map_err(|e| format!("SEEDS must be a whole number (got {s:?}: {e})"))?,
        None => 40,
    };
    let params = ExactParams::default();
    println!("seed lc_runs nodes proven leaf best_s bound3_s bound2_s operator_s wall_ms");
    let (mut proven, mut leaves, mut nodes) = (0usize, 0usize, 0usize);
    let mut above_b2 = 0usize;
    let mut gap_sum = 0.0;
    for seed in 0..seeds {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let problem = testkit::random_problem(&mut rng, 400..=1500, 0.01)?;
        let start = Instant::now();
        let three = margin_free_bound(&problem, 3, &params, 0.0)?;
        let wall_ms = start.elapsed().as_secs_f64() * 1e3;
        let two = margin_free_bound(&problem, 2, &params, 0.0)?;
        let op = operator_bound_s(&problem, 3)?;
        let best = three.schedule.as_ref().map(|s| s.t_total_s(problem.dt_s()));
        proven += usize::from(three.proven_optimal);
        leaves += usize::from(best.is_some());
        nodes += three.stats.states;
        above_b2 += usize::from(three.lower_bound_s > two.lower_bound_s);
        if let Some(b) = best {
            gap_sum += (b - three.lower_bound_s) / three.lower_bound_s;
        }
        println!(
            "{seed} {} {} {} {} {} {:.3} {:.3} {:.3} {wall_ms:.0}",
            three.stats.lc_runs,
            three.stats.states,
            three.proven_optimal,
            best.is_some(),
            best.map_or("-".to_string(), |b| format!("{b:.3}")),
            three.lower_bound_s,
            two.lower_bound_s,
            op,
        );
    }
    println!(
        "# {seeds} problems: {proven} proven, {leaves} with a leaf, bound above B(2) on \
         {above_b2}, {nodes} nodes, mean search gap (best − bound)/bound over the leaves {:.2} %",
        if leaves > 0 {
            100.0 * gap_sum / leaves as f64
        } else {
            0.0
        }
    );
    Ok(())
}
