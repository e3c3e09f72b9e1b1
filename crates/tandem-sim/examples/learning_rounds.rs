//! Rounds of `N` robots with the simulated operator on a state file's model, and what each
//! re-schedule did with the previous schedule (docs/decisions.md, "Learning never makes the
//! plan worse"): per round `T_total` before and after, the source, the certificate and its
//! split, and the fate of the previous schedule; then the largest round-to-round increase.
//!
//! ```text
//! cargo run --release -p tandem-sim --example learning_rounds -- STATE NEED.csv \
//!     [--robots N] [--no-holds] [--rounds K] [--seed S] [--channel NAME] [--quiet]
//! ```
//!
//! The planner is rebuilt from the state's model and parameters for `N` robots (without its
//! holds with `--no-holds`); round `k` draws its workpieces from `derive_seed(seed, k)` as
//! `tandem simulate` does.

#![expect(clippy::print_stdout, reason = "an example prints its table")]

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tandem_planner::{Planner, derive_seed};
use tandem_schedule::PreviousFate;
use tandem_sim::needs::NeedProfile;
use tandem_sim::workcell::{OperatorParams, run_round_with};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let flag = |name: &str| args.iter().any(|a| a == name);
    let value = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let [state, need_path] = [0, 1].map(|i| args.get(i).cloned());
    let (Some(state), Some(need_path)) = (state, need_path) else {
        return Err("usage: learning_rounds STATE NEED.csv [--robots N] [--no-holds] [--rounds K] [--seed S] [--channel NAME] [--quiet]".into());
    };
    let n_robots: usize = value("--robots").map_or(Ok(2), |v| v.parse())?;
    let rounds: usize = value("--rounds").map_or(Ok(12), |v| v.parse())?;
    let seed: u64 = value("--seed").map_or(Ok(0), |v| v.parse())?;
    let channel = value("--channel").unwrap_or_else(|| "force".into());
    let base = Planner::load(&state)?;
    let mut params = base.params().clone();
    if flag("--no-holds") {
        params.holds = Default::default();
    }
    let mut planner = Planner::from_model_with_robots(base.model().clone(), params, n_robots)?;
    let need = NeedProfile::parse_csv(
        &std::fs::read_to_string(&need_path)?,
        &need_path,
        planner.model().n_ref(),
    )?;
    let op = OperatorParams {
        force_channel: channel,
        ..OperatorParams::default()
    };
    let tick_s = planner.schedule().tick_s;
    let o = planner.outcome();
    println!(
        "start: T_total {:.3} s ({}), bound {:.3} s{}",
        o.t_total_s,
        o.source.name(),
        o.lower_bound_s,
        if o.bound_is_optimum { " (T*0)" } else { "" }
    );
    println!("round  ran (s)  next (s)  source     bound (s)  gap     search  margins  previous");
    let (mut max_up, mut invalid, mut unexplained) = (f64::NEG_INFINITY, 0, 0);
    for k in 0..rounds {
        let mut rng = ChaCha8Rng::seed_from_u64(derive_seed(seed, k as u64));
        let needed = need.draw(planner.n_robots(), &mut rng);
        let round = run_round_with(&planner, |r, n| needed[r][n], &op, &mut rng)?;
        let records = round.records(planner.model())?;
        let report = planner.record_round(&records)?;
        let o = planner.outcome();
        let up = report.t_total_s - report.previous_t_total_s;
        max_up = max_up.max(up);
        let fate = match &report.previous {
            PreviousFate::Valid { .. } => "valid",
            PreviousFate::Repaired { .. } => "re-timed",
            PreviousFate::Invalid { .. } => {
                invalid += 1;
                "INVALID"
            }
            PreviousFate::NotGiven => "-",
        };
        if up > tick_s && !matches!(report.previous, PreviousFate::Invalid { .. }) {
            unexplained += 1;
        }
        let split = o.gap_split();
        if !flag("--quiet") {
            println!(
                "{:>5}  {:>7.3}  {:>8.3}  {:<9}  {:>9.3}  {:>5.1}%  {:>5.1}%  {:>6.1}%  {fate}",
                k + 1,
                report.previous_t_total_s,
                report.t_total_s,
                report.source.name(),
                o.lower_bound_s,
                100.0 * o.gap,
                100.0 * split.map_or(f64::NAN, |s| s.search),
                100.0 * split.map_or(f64::NAN, |s| s.margins),
            );
            if let PreviousFate::Invalid { .. } = report.previous {
                println!("       {}", report.previous.describe().unwrap_or_default());
            }
        }
    }
    let o = planner.outcome();
    println!(
        "N = {n_robots}: final {:.3} s, bound {:.3} s (gap {:.1} %), largest round-to-round change {:+.3} s, previous schedule invalid in {invalid} of {rounds} rounds, increases above a tick with the previous schedule valid or re-timed: {unexplained}",
        o.t_total_s,
        o.lower_bound_s,
        100.0 * o.gap,
        max_up
    );
    Ok(())
}
