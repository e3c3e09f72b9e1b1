//! `tandem console STATE --simulate`: the operator's console (issue 42) on a simulated cell in
//! real time. The state file's planner makes the cell's plan and controller
//! (`Planner::controller`), tandem-sim's simulated operator supervises the low-confidence
//! robot, and the page at the URL printed as the first line of standard output shows it
//! (tandem-console). Runs until interrupted; the state file is never modified.

use std::net::IpAddr;
use std::sync::atomic::AtomicBool;

use anyhow::{Context, Result, bail};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tandem::{Planner, derive_seed};
use tandem_console::{Console, ConsoleConfig, Geometry, SimParams, simulate};

use crate::cli::ConsoleArgs;
use crate::cmd::{note, out};
use crate::{input, state_io};

/// Runs `tandem console`.
pub(crate) fn console(a: &ConsoleArgs) -> Result<()> {
    if !a.simulate {
        bail!(
            "tandem console needs a source: --simulate (a simulated cell from the state file); \
             a live control loop feeds a console through tandem_console::ConsoleHandle"
        );
    }
    let planner = state_io::load(&a.state)?;
    let planner = with_robots(planner, a.robots, &a.state)?;
    let params = SimParams {
        cell: a.cell,
        speed: a.speed,
        seed: a.seed,
        ..SimParams::default()
    };
    params
        .validate()
        .map_err(|e| anyhow::anyhow!("--speed {}: {e}", a.speed))?;
    let needed = match &a.need {
        Some(path) => {
            let need = input::read_need(path, planner.model().n_ref())?;
            let mut rng = ChaCha8Rng::seed_from_u64(derive_seed(a.seed, 1));
            Some(need.draw(planner.n_robots(), &mut rng))
        }
        None => None,
    };
    let ctl = planner
        .controller(a.cell)
        .with_context(|| format!("{}: the {} cell's plan", a.state.display(), a.cell))?;
    let config = ConsoleConfig {
        host: a.host,
        port: a.port,
        lead_s: a.lead.unwrap_or_else(|| {
            tandem_console::DEFAULT_LEAD_S.max(planner.params().sampler.switch_s)
        }),
        ..ConsoleConfig::default()
    };
    let (console, handle) = Console::start(&config, Geometry::new(&ctl)).map_err(|e| match e {
        tandem_console::Error::BadParam { name: "lead_s", .. } => {
            anyhow::anyhow!("--lead {}: {e}", config.lead_s)
        }
        e => e.into(),
    })?;
    out(console.url());
    note(&format!(
        "console: {} robots, {} cell, speed ×{}; open {} (Ctrl-C stops)",
        planner.n_robots(),
        a.cell,
        a.speed,
        console.url()
    ));
    let stop = AtomicBool::new(false);
    simulate(&planner, ctl, &params, needed, handle, &stop)?;
    console.stop();
    Ok(())
}

/// The planner for `robots` robots: the state's own when it has that many (or `robots` is not
/// given); otherwise, for a state with no recorded round, the same model and parameters planned
/// for `robots` robots (exactly what `tandem fit --robots N` makes from the same files). A
/// state with recorded rounds keeps what it learned for its own robot count.
fn with_robots(planner: Planner, robots: Option<usize>, path: &std::path::Path) -> Result<Planner> {
    let Some(n) = robots else {
        return Ok(planner);
    };
    if n == planner.n_robots() {
        return Ok(planner);
    }
    if planner.rounds_recorded() > 0 {
        bail!(
            "--robots {n}: {} plans {} robots and holds {} recorded round(s) of them; \
             omit --robots, or fit a state with `tandem fit --robots {n}`",
            path.display(),
            planner.n_robots(),
            planner.rounds_recorded()
        );
    }
    Planner::from_model_with_robots(planner.model().clone(), planner.params().clone(), n)
        .with_context(|| format!("--robots {n}"))
}

/// The default bind address: this machine only.
pub(crate) fn localhost() -> IpAddr {
    IpAddr::V4(std::net::Ipv4Addr::LOCALHOST)
}
