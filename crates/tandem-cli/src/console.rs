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
use tandem::realtime::Controller;
use tandem::sim::workcell::OperatorParams;
use tandem::{Planner, derive_seed};
use tandem_console::{
    Console, ConsoleConfig, Geometry, Recorder, SimParams, Until, check_recording, read_recording,
    record_sim, simulate_recorded,
};

use crate::cli::ConsoleArgs;
use crate::cmd::{note, out};
use crate::{input, state_io};

/// Runs `tandem console`.
pub(crate) fn console(a: &ConsoleArgs) -> Result<()> {
    if let Some(path) = &a.replay {
        return replay(a, path);
    }
    let Some(state) = a.state.as_ref().filter(|_| a.simulate) else {
        bail!(
            "tandem console needs a source: STATE --simulate (a simulated cell from the state \
             file) or --replay FILE|DIR (a console recording); a live control loop feeds a \
             console through tandem_console::ConsoleHandle"
        );
    };
    let until = a.until.as_deref().map(parse_until).transpose()?;
    let planner = state_io::load(state)?;
    let planner = with_robots(planner, a.robots, state)?;
    let params = SimParams {
        cell: a.cell,
        speed: a.speed,
        seed: a.seed,
        operator: OperatorParams {
            force_channel: crate::sim::operator_channel(a.channel.as_deref(), &planner)?,
            ..OperatorParams::default()
        },
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
        .with_context(|| format!("{}: the {} cell's plan", state.display(), a.cell))?;
    let schedule = schedule_text(&planner, a.cell)?;
    let mut recorder = match &a.record {
        Some(path) => Some(
            Recorder::create(path, &Geometry::new(&ctl), ctl.tick_s(), Some(&schedule))
                .map_err(|e| anyhow::anyhow!("--record: {e}"))?,
        ),
        None => None,
    };
    if let (Some(until), Some(rec), Some(path)) = (until, recorder.as_mut(), a.record.as_ref()) {
        let ticks = record_sim(&planner, ctl, &params, needed, until, rec).map_err(|e| {
            // A failed batch recording is not a run: remove the file this command created,
            // so that a retry with the same name works and nothing half-written is replayed.
            let _ = std::fs::remove_file(path);
            match e {
                tandem_console::Error::BadParam { name: "until", why } => {
                    anyhow::anyhow!("--until {}: {why}", a.until.as_deref().unwrap_or_default())
                }
                e => anyhow::Error::from(e),
            }
        })?;
        note(&format!(
            "console: recorded {ticks} ticks into {}",
            a.record
                .as_ref()
                .map_or(String::new(), |p| p.display().to_string())
        ));
        return Ok(());
    }
    let config = ConsoleConfig {
        host: a.host,
        port: a.port,
        lead_s: a.lead.unwrap_or_else(|| {
            tandem_console::DEFAULT_LEAD_S.max(planner.params().sampler.switch_s)
        }),
        schedule: Some(schedule),
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
    simulate_recorded(
        &planner,
        ctl,
        &params,
        needed,
        handle,
        recorder.as_mut(),
        &stop,
    )?;
    console.stop();
    Ok(())
}

/// The schedule the cell runs and its certificate in words (the page's health): rounds, the
/// planner's schedule, its source (certified search or a fallback) and certificate line; the
/// continuous cell, its cyclic plan.
fn schedule_text(planner: &Planner, cell: tandem::planner::Cell) -> Result<String> {
    Ok(match cell {
        tandem::planner::Cell::Rounds => format!(
            "{}; {}",
            crate::gantt::outcome_source_name(planner.problem(), planner.outcome()),
            crate::gantt::certificate_line(planner.problem(), planner.outcome())?
        ),
        tandem::planner::Cell::Continuous => {
            "the continuous cell's cyclic plan (gate order and token rule)".to_string()
        }
    })
}

/// `--until WHAT:N`.
fn parse_until(text: &str) -> Result<Until> {
    let bad = || {
        anyhow::anyhow!(
            "--until {text}: expected ticks:N, rounds:N or tasks:N with N a whole number > 0"
        )
    };
    let (what, n) = text.split_once(':').ok_or_else(bad)?;
    let n: u64 = n.trim().parse().map_err(|_| bad())?;
    if n == 0 {
        return Err(bad());
    }
    match what.trim() {
        "ticks" => Ok(Until::Ticks(n)),
        "rounds" => Ok(Until::Rounds(n)),
        "tasks" => Ok(Until::Tasks(n)),
        _ => Err(bad()),
    }
}

/// `tandem console --replay FILE|DIR [--check]`.
fn replay(a: &ConsoleArgs, path: &std::path::Path) -> Result<()> {
    if !(a.speed > 0.0 && a.speed <= 1000.0) {
        bail!("--speed {}: must be in (0, 1000]", a.speed);
    }
    let bag = tandem_console::looks_like_bag(path);
    let rec = match (&a.state, bag) {
        (Some(state), true) => run_bag(state, path)?,
        (Some(state), false) => bail!(
            "--replay {}: a console recording carries its own plan; {} is only for a run bag \
             (RUN.mcap): omit it",
            path.display(),
            state.display()
        ),
        (None, _) => read_recording(path),
    };
    let lead_s = a.lead.unwrap_or(tandem_console::DEFAULT_LEAD_S);
    if a.check {
        let rec = rec.map_err(|e| anyhow::anyhow!("--replay: {e}"))?;
        if let Some(p) = &rec.problem {
            note(&format!(
                "console: recording {} is damaged: {p}; checked the {} frames before it",
                rec.path.display(),
                rec.ticks.len()
            ));
        }
        if bag {
            note(
                "console: a run bag records no pre-alert: the page showed no countdown, so the \
                 pre-alert counts are 0; the stretches and the notice the schedule allowed are \
                 the run's",
            );
        }
        let check = check_recording(&rec, lead_s);
        out(&serde_json::to_string_pretty(&check)?);
        return Ok(());
    }
    // An unreadable recording still serves the page, which says what is wrong.
    let (geometry, rec, failure) = match rec {
        Ok(r) => (r.geometry.clone(), Some(r), None),
        Err(e) => (Geometry::empty(true), None, Some(e.to_string())),
    };
    let config = ConsoleConfig {
        host: a.host,
        port: a.port,
        lead_s,
        schedule: rec
            .as_ref()
            .and_then(|r| r.schedule.as_ref())
            .map(|s| format!("{s} (recorded)")),
        ..ConsoleConfig::default()
    };
    let (console, handle) = Console::start(&config, geometry)?;
    out(console.url());
    let stop = AtomicBool::new(false);
    match (rec, failure) {
        (Some(rec), _) => {
            note(&format!(
                "console: replaying {} ({} frames, {} robots) at ×{}; open {} (Ctrl-C stops)",
                rec.path.display(),
                rec.ticks.len(),
                rec.geometry.n_robots(),
                a.speed,
                console.url()
            ));
            tandem_console::replay(&rec, a.speed, &console, handle, &stop)?;
        }
        (None, failure) => {
            note(&format!("console: open {} (Ctrl-C stops)", console.url()));
            let empty = tandem_console::Recording {
                path: path.to_path_buf(),
                geometry: Geometry::empty(true),
                tick_s: 0.1,
                schedule: None,
                ticks: Vec::new(),
                problem: Some(failure.unwrap_or_else(|| "no recording".to_string())),
            };
            tandem_console::replay(&empty, 1.0, &console, handle, &stop)?;
        }
    }
    console.stop();
    Ok(())
}

/// The run bag at `path` rebuilt against the rounds plan of the state file `state`
/// (`tandem console STATE --replay RUN.mcap`); a note when the state's schedule is not the one
/// the bag's rounds ran (a state recorded into since: the page's plan is the state's).
fn run_bag(
    state: &std::path::Path,
    path: &std::path::Path,
) -> Result<tandem_console::Result<tandem_console::Recording>> {
    let planner = state_io::load(state)?;
    let ctl = planner
        .controller(tandem::planner::Cell::Rounds)
        .with_context(|| format!("{}: the rounds plan", state.display()))?;
    let schedule = schedule_text(&planner, tandem::planner::Cell::Rounds)?;
    let geometry = Geometry::new(&ctl);
    let rec = tandem_console::read_run_bag(path, &geometry, Some(&schedule));
    if let Ok(file) = tandem::bag::bag_file(path)
        && let Ok(rounds) = tandem::bag::read_run(&file, planner.n_robots())
    {
        let planned = planner.outcome().t_total_s;
        if let Some(r) = rounds
            .iter()
            .find(|r| (r.t_total_s - planned).abs() > 1e-6 * planned.max(1.0))
        {
            note(&format!(
                "console: round {} of {} ran a schedule of T_total {:.2} s, {} plans {:.2} s \
                 (recorded into since?): the page's timeline and time left are the state's plan",
                r.round,
                path.display(),
                r.t_total_s,
                state.display(),
                planned
            ));
        }
    }
    Ok(rec)
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
