//! `cargo xtask <cmd>`: repeatable project tasks (see README.md and docs/ARCHITECTURE.md).
//!
//! Each subcommand lives in its own module; this file only parses the command line and
//! dispatches, so that tasks added by different issues do not touch each other's code.
#![allow(clippy::print_stdout, reason = "xtask reports to the terminal")]

use clap::{Parser, Subcommand};

/// Command line of `cargo xtask`.
#[derive(Parser)]
#[command(name = "cargo xtask", about = "tandem's repeatable tasks")]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

/// The tasks.
#[derive(Subcommand)]
enum Cmd {}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.cmd {}
}
