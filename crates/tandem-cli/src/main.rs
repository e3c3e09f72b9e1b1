//! `tandem`: the command line of the tandem workspace (Hagenow et al., RA-L 2023, §II).
//!
//! It takes a robotics researcher from their own recorded demonstrations to a schedule for
//! two robots and one operator, without writing Rust:
//!
//! - `tandem fit` learns the task model (alignment, statistics, corrections, confidence
//!   prior; §II-B1–3) and the first schedule (§II-B4–6, §II-C) and saves a state file;
//! - `tandem schedule` re-optimizes and shows the schedule (text Gantt or JSON); with
//!   `--cell continuous` it shows the cyclic plan of a continuous cell instead (`cyclic`);
//! - `tandem record` adds an executed pair (Eq. 21), updates the confidence, re-schedules;
//! - `tandem inspect` and `tandem plot` show the model, the confidence and the schedule;
//! - `tandem simulate` runs a simulated operator on the model (what-if) and can write the
//!   executions in the formats `tandem record` reads;
//! - `tandem need` writes a need file (the simulated operator's input) from reference-time
//!   intervals;
//! - `tandem params` prints the default parameter file;
//! - `tandem console STATE --simulate` serves the operator's console on a simulated cell.
//!
//! File formats: `docs/formats.md`. Walk-through: `docs/guide.md`.
//! Every user error prints `error: …` naming the file and the problem, and exits with code 2;
//! nothing is written when a command fails.

mod bag;
mod cells;
mod cli;
mod cmd;
mod console;
mod cyclic;
mod gantt;
mod input;
mod json;
mod need;
#[cfg(feature = "ros2")]
mod node;
mod plot;
mod sim;
mod state_io;

use clap::Parser;

fn main() {
    let args = cli::Cli::parse();
    if let Err(e) = cmd::run(args) {
        eprintln!("error: {}", message(&e));
        std::process::exit(2);
    }
}

/// The error and its causes joined by `: ` (as `{:#}` does), skipping a cause whose text the
/// message already holds (the lower crates' errors print their own source).
fn message(e: &anyhow::Error) -> String {
    let mut msg = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if msg.contains(&text) {
            continue;
        }
        if !msg.is_empty() {
            msg.push_str(": ");
        }
        msg.push_str(&text);
    }
    msg
}
