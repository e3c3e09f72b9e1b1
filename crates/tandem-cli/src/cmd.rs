//! The subcommands.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use tandem::lfd::{Demonstration, Execution, HoldSpec, PeriodSource, Reference, TaskModel};
use tandem::planner::{Cell, reschedule_seed};
use tandem::schedule::SamplerParams;
use tandem::{ExecutionRecord, Planner, PlannerParams};

use crate::cli::{
    Cli, Command, FitArgs, InspectArgs, PlotArgs, RecordArgs, RobotsArg, SamplerArgs, ScheduleArgs,
};
use crate::gantt::{certificate_line, gantt_text, offsets_text, outcome_source_name, schedule_doc};
use crate::json;
use crate::{bag, cyclic, input, need, plot, sim, state_io};

/// Whether `--verbose` was given: the full lists instead of their summaries. Set once by
/// [`run`] before any command runs; read by the printing code of every command.
static VERBOSE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();

/// Whether `--verbose` was given (see [`VERBOSE`]).
pub(crate) fn verbose() -> bool {
    VERBOSE.get().copied().unwrap_or(false)
}

/// Runs one command.
pub(crate) fn run(cli: Cli) -> Result<()> {
    let _ = VERBOSE.set(cli.verbose);
    match cli.command {
        Command::Fit(a) => fit(&a),
        Command::Schedule(a) => schedule(&a),
        Command::Record(a) => record(&a),
        Command::Inspect(a) => inspect(&a),
        Command::Plot(a) => plot_cmd(&a),
        Command::Simulate(a) => sim::simulate(&a),
        Command::Need(a) => need::need(&a),
        Command::Params => params(),
        Command::Console(a) => crate::console::console(&a),
        #[cfg(feature = "ros2")]
        Command::Node(a) => crate::node::node(&a),
    }
}

/// Prints a line to stdout (the CLI's output channel). A closed pipe (`tandem … | head`)
/// ends the process quietly instead of panicking.
pub(crate) fn out(text: &str) {
    use std::io::Write as _;
    let mut stdout = std::io::stdout().lock();
    if writeln!(stdout, "{text}").is_err() {
        std::process::exit(0);
    }
}

/// Prints a note about the user's data on stderr (the output channel stays clean for
/// `--json`): how a file was read, or something that looks wrong but is not refused.
pub(crate) fn note(text: &str) {
    eprintln!("note: {text}");
}

/// Prints one note per group of files that share it: `what` maps each file to the rest of
/// its note; a note several files share is printed once, naming them (the first
/// [`FILES_NAMED`] and how many more), unless `--verbose` asks for one note per file.
pub(crate) fn grouped_notes(what: &[(String, String)]) {
    let mut groups: Vec<(&str, Vec<&str>)> = Vec::new();
    for (file, rest) in what {
        match groups.iter_mut().find(|(r, _)| *r == rest.as_str()) {
            Some((_, files)) if !verbose() => files.push(file.as_str()),
            _ => groups.push((rest.as_str(), vec![file.as_str()])),
        }
    }
    for (rest, files) in groups {
        note(&format!("{}: {rest}", files_text(&files)));
    }
}

/// Files named in one note before `… and K more`.
pub(crate) const FILES_NAMED: usize = 3;

/// `a.csv`, or `3 files (a.csv, b.csv, c.csv)`, or `6 files (a.csv, b.csv, c.csv and 3
/// more)`.
pub(crate) fn files_text(files: &[&str]) -> String {
    match files {
        [one] => (*one).to_owned(),
        _ => {
            let named = files[..files.len().min(FILES_NAMED)].join(", ");
            let more = files.len().saturating_sub(FILES_NAMED);
            if more == 0 {
                format!("{} files ({named})", files.len())
            } else {
                format!("{} files ({named} and {more} more)", files.len())
            }
        }
    }
}

/// The period notes of files read (demonstrations, executions): one line per kind for all
/// files (the files without a time column, the files whose `t` jitters), or with
/// `--verbose` each file's own note ([`Demonstration::period_note`]). `assumed_suffix` is
/// added to the note of files without a time column (why that period).
pub(crate) fn period_notes(demos: &[&Demonstration], assumed_suffix: &str) {
    let with_note: Vec<&Demonstration> = demos
        .iter()
        .copied()
        .filter(|d| d.period_note().is_some())
        .collect();
    let assumed: Vec<&Demonstration> = with_note
        .iter()
        .copied()
        .filter(|d| d.period_source() == PeriodSource::Assumed)
        .collect();
    let jittered: Vec<&Demonstration> = with_note
        .iter()
        .copied()
        .filter(|d| d.period_source() == PeriodSource::File && d.jitter().is_some())
        .collect();
    let own = |d: &Demonstration| {
        let n = d.period_note().unwrap_or_default();
        if d.period_source() == PeriodSource::Assumed {
            format!("{n}{assumed_suffix}")
        } else {
            n
        }
    };
    if verbose() || with_note.len() == 1 {
        for d in with_note {
            note(&own(d));
        }
        return;
    }
    match assumed[..] {
        [] => {}
        [one] => note(&own(one)),
        _ => {
            let files: Vec<&str> = assumed.iter().map(|d| d.source()).collect();
            let periods: Vec<f64> = assumed.iter().map(|d| secs(d.dt_s())).collect();
            let same = periods.iter().all(|p| *p == periods[0]);
            let apart = if same {
                format!("{} s apart ({} Hz)", periods[0], secs(1.0 / periods[0]))
            } else {
                "the period given for them apart".into()
            };
            note(&format!(
                "{}: no time column `t`: their samples are taken to be {apart}; if they were \
                 logged at another rate, add a column `t` (seconds){assumed_suffix} (--verbose: \
                 one note per file)",
                files_text(&files)
            ));
        }
    }
    match jittered[..] {
        [] => {}
        [one] => note(&own(one)),
        _ => {
            let files: Vec<&str> = jittered.iter().map(|d| d.source()).collect();
            let share = |d: &Demonstration| d.jitter().map_or(0.0, |(dev, _)| dev / d.dt_s());
            let worst: &Demonstration = jittered
                .iter()
                .copied()
                .max_by(|a, b| share(a).total_cmp(&share(b)))
                .expect("at least two files");
            let (dev, line) = worst.jitter().expect("a jittered file");
            note(&format!(
                "{}: time column `t`: times deviate from each file's even grid by up to {:.3} \
                 ms ({:.1} % of a period, at {}:{line}; tandem accepts up to {} %): the samples \
                 are taken to be evenly spaced (--verbose: one note per file)",
                files_text(&files),
                dev * 1e3,
                100.0 * share(worst),
                worst.source(),
                100.0 * tandem::lfd::JITTER_TOLERANCE
            ));
        }
    }
}

/// Prints a deprecation line on stderr: an old flag or name, kept one release, and what
/// replaces it.
pub(crate) fn deprecated(text: &str) {
    eprintln!("warning: deprecated: {text}");
}

/// A period or time in seconds without floating-point noise (`0.01`, not `0.009999…`).
pub(crate) fn secs(v: f64) -> f64 {
    (v * 1e9).round() / 1e9
}

/// Applies `--samples`/`--seed`/`--switch-s`/`--max-busy` to sampler parameters and checks
/// them: a bad operator parameter is refused naming its flag and the valid range.
pub(crate) fn apply_sampler(mut p: SamplerParams, a: &SamplerArgs) -> Result<SamplerParams> {
    if let Some(n) = a.samples {
        p.samples = n;
    }
    if let Some(s) = a.seed {
        p.seed = s;
    }
    if let Some(d) = a.switch_s {
        if !(d.is_finite() && d >= 0.0) {
            bail!(
                "--switch-s {d}: the operator's switch time must be a finite number of seconds \
                 ≥ 0 (0: no switch time)"
            );
        }
        p.switch_s = d;
    }
    if let Some(u) = a.max_busy {
        if !(u > 0.0 && u <= 1.0) {
            bail!(
                "--max-busy {u}: the operator's load cap is a share of the time in (0, 1] \
                 (0.7: busy at most 70 % of the time; 1: no cap)"
            );
        }
        p.max_busy_share = u;
    }
    if let Some(m) = a.operators {
        if !(1..=tandem::realtime::MAX_ROBOTS).contains(&m) {
            bail!(
                "--operators {m}: a cell has 1 to {} operators (1: one operator)",
                tandem::realtime::MAX_ROBOTS
            );
        }
        p.operators = m;
    }
    p.validate()
        .context("--samples/--seed/--switch-s/--max-busy/--operators")?;
    Ok(p)
}

/// The operator's line of the summaries (`fit`, `record`, `inspect`, `schedule`): the switch
/// time and load cap the schedules honour, when either is not its default (`None` otherwise:
/// the output of a planner without them is unchanged).
pub(crate) fn operator_line(p: &SamplerParams) -> Option<String> {
    if p.switch_s == 0.0 && p.max_busy_share == 1.0 && p.operators == 1 {
        return None;
    }
    let cap = if p.max_busy_share == 1.0 {
        "no load cap".to_owned()
    } else {
        format!(
            "load cap u_max {} (busy at most {} % of the time, switches included)",
            p.max_busy_share,
            secs(100.0 * p.max_busy_share)
        )
    };
    let fleet = if p.operators == 1 {
        String::new()
    } else {
        format!(
            "; {} operators (at most {} robots low-confidence at once: a continuous cell's \
             tokens, or rounds in sectors)",
            p.operators, p.operators
        )
    };
    Some(format!(
        "operator: switch time δ {} s (at least δ between one robot's low-confidence stretch \
         and another's); {cap}{fleet}",
        secs(p.switch_s)
    ))
}

/// With `M > 1` operators, the round the robots run (issue 44): the planner's sectored round
/// (`Planner::sectored_rounds`), its sectors, `T_total` and the bound of every round of `M`
/// operators; `None` with one operator (the output of before).
pub(crate) fn sectors_line(planner: &Planner) -> Result<Option<String>> {
    let m = planner.params().sampler.operators;
    if m == 1 {
        return Ok(None);
    }
    let (s, _) = planner
        .sectored_rounds()
        .context("cannot plan the sectored round")?;
    let sizes: Vec<String> = s.sizes.iter().map(ToString::to_string).collect();
    Ok(Some(format!(
        "rounds with {m} operators: sectors of {} robots (one operator each), T_total {:.2} s \
         (no round of {m} operators is shorter than {:.2} s)",
        sizes.join(" + "),
        s.t_total_s,
        s.lower_bound_s
    )))
}

/// `fit`'s parameters: the parameter file, then the flags over it, checked.
pub(crate) fn fit_params(a: &FitArgs) -> Result<PlannerParams> {
    let mut params = match &a.params {
        Some(p) => input::read_params(p)?,
        None => PlannerParams::default(),
    };
    params.sampler = apply_sampler(params.sampler, &a.sampler)?;
    if let Some(reference) = a.reference {
        params.fit.reference = reference.into();
    }
    if let Some(rate_term) = a.rate_term {
        params.fit.rate_term = rate_term;
    }
    if a.no_holds {
        params.holds = HoldSpec::default();
    }
    if !a.hold_at.is_empty() {
        params.holds.at_s = a.hold_at.clone();
    }
    if !a.hold_where.is_empty() {
        params.holds.rules = a.hold_where.clone();
    }
    if let Some(t) = params
        .holds
        .at_s
        .iter()
        .find(|t| !t.is_finite() || **t < 0.0)
    {
        bail!("--hold-at {t}: a hold's reference time must be a finite number of seconds ≥ 0");
    }
    if let Some(dt) = a.dt
        && !(dt.is_finite() && dt > 0.0)
    {
        bail!("--dt {dt}: the sample period must be finite and > 0 seconds");
    }
    Ok(params)
}

fn fit(a: &FitArgs) -> Result<()> {
    let mut params = fit_params(a)?;
    if !a.task.is_empty() {
        return crate::cells::fit_cell(a, params);
    }
    let robots_given = match &a.robots {
        None => None,
        Some(RobotsArg::Count(r)) => Some(*r),
        Some(RobotsArg::PerTask(_)) => bail!(
            "--robots NAME=K: robot counts per task are for a cell of tasks (--task \
             NAME=FILE,…); with DEMO files give one count N"
        ),
    };
    if let Some(r) = robots_given
        && let Err(e) = tandem::realtime::RobotCount::new(r)
    {
        bail!("--robots {r}: {e}");
    }
    state_io::check_file_target(&a.output)?;
    // Recorded rounds are never discarded without consent; decided before any work.
    let held = if a.force {
        0
    } else {
        Planner::rounds_at(&a.output).with_context(|| {
            format!(
                "{}: cannot tell whether it holds recorded rounds; write to another file, or \
                 replace it with --force",
                a.output.display()
            )
        })?
    };
    if held > 0 && !a.keep_rounds {
        bail!(
            "{}: holds {held} recorded round(s) (the operator's corrections), which a new fit \
             would discard; nothing was written. Keep them: add --keep-rounds (they are \
             replayed onto the new fit); discard them: add --force; or write the new fit to \
             another file (-o)",
            a.output.display()
        );
    }
    // With --keep-rounds: a read–modify–write of the state under its lock, as `record`.
    let kept = if a.keep_rounds && a.output.is_file() {
        let lock = state_io::lock(&a.output)?;
        let old = state_io::load(&a.output)?;
        if let Some(r) = robots_given
            && r != old.n_robots()
        {
            bail!(
                "--robots {r}: the rounds recorded in {} are of {} robots; with --keep-rounds \
                 the new fit has the state's robot count (leave --robots out)",
                a.output.display(),
                old.n_robots()
            );
        }
        Some((lock, old))
    } else {
        None
    };
    let robots = match &kept {
        Some((_, old)) => old.n_robots(),
        None => robots_given.unwrap_or(2),
    };
    let demos: Vec<Demonstration> = bag::read_demos(
        &a.demos,
        a.dt,
        a.rate,
        &a.topics,
        &mut params.fit.schema,
        a.resample,
    )?;
    period_notes(&demos.iter().collect::<Vec<_>>(), "");
    let mut dt_notes: Vec<(String, String)> = Vec::new();
    for d in &demos {
        // The file's own time wins over --dt; a --dt that contradicts it is refused.
        if let Some(dt) = a.dt
            && d.period_source() == PeriodSource::File
            && !a.resample
        {
            if (d.dt_s() - dt).abs() > tandem::lfd::DT_TOLERANCE * dt {
                bail!(
                    "{}: --dt {dt} s, but its own time (`t` column or `dt_s`) gives {} s: \
                     remove --dt (it is only for files without a time column) or fix the file",
                    d.source(),
                    secs(d.dt_s())
                );
            }
            dt_notes.push((
                d.source().to_owned(),
                format!(
                    "its own time gives {} s; --dt (the period of files without a time column) \
                     agrees and is not used for it",
                    secs(d.dt_s())
                ),
            ));
        }
    }
    grouped_notes(&dt_notes);
    for w in tandem::lfd::length_warnings(&demos) {
        note(&w);
    }
    if demos.len() < 2 {
        bail!(
            "{}: only one demonstration; the variability of the task needs at least 2 \
             (give every demonstration file)",
            a.demos[0].display()
        );
    }
    if !a.ranges.is_empty() {
        let names = demos[0].tangent_names(&params.fit.schema)?;
        let given = input::parse_ranges(&a.ranges, &names)?;
        let mut ranges = if given.len() == names.len() {
            vec![0.0; names.len()]
        } else {
            // The automatic ranges of the coordinates not given (quaternion and rate ranges
            // need the alignment): one fit with the defaults.
            let model = TaskModel::fit(&demos, &params.fit).context("cannot fit the task model")?;
            model.ranges().to_vec()
        };
        for (j, v) in given {
            ranges[j] = v;
        }
        params.fit.ranges = Some(ranges);
    }
    let fit_context = || match &a.params {
        Some(p) => format!(
            "cannot fit the task model (parameters from {})",
            p.display()
        ),
        None => "cannot fit the task model".into(),
    };
    let mut kept_line = None;
    let planner = if let Some((lock, old)) = &kept {
        let (planner, report) = old.refit(&demos, params).with_context(fit_context)?;
        planner.save_locked(lock)?;
        kept_line = Some(format!(
            "kept {} recorded round(s): replayed onto the new fit in their order{} (high \
             confidence before the refit: {:.1} %)",
            report.rounds,
            if report.reference_changed {
                ", each execution aligned to the new reference for its reference times"
            } else {
                " on the same reference"
            },
            100.0 * report.high_share_before
        ));
        planner
    } else {
        let planner = Planner::with_robots(&demos, params, robots).with_context(fit_context)?;
        if a.force {
            let lock = state_io::lock_new(&a.output)?;
            kept_line = match planner.save_locked_discarding(&lock)? {
                Some(0) => None,
                Some(n) => Some(format!(
                    "replaced {}: discarded its {n} recorded round(s) (--force)",
                    a.output.display()
                )),
                None => Some(format!(
                    "replaced {}, a state file this build cannot read (--force)",
                    a.output.display()
                )),
            };
        } else {
            planner.save(&a.output)?;
        }
        planner
    };
    let model = planner.model();
    let files: Vec<String> = a.demos.iter().map(|p| p.display().to_string()).collect();
    out(&format!(
        "fitted {} demonstrations (reference: {}, {})",
        demos.len(),
        files[model.reference_idx()],
        match planner.params().fit.reference {
            Reference::First => "the first file",
            Reference::Medoid => "the medoid",
        }
    ));
    out(&format!(
        "reference: {} samples × {} s = {:.2} s; channels: {}",
        model.n_ref(),
        secs(model.dt_s()),
        model.n_ref() as f64 * model.dt_s(),
        model.channel_names().join(", ")
    ));
    summary_lines(&planner)?;
    if let Some(line) = range_advice(&planner)? {
        out(&line);
    }
    if let Some(line) = kept_line {
        out(&line);
    }
    out(&format!("saved {}", a.output.display()));
    Ok(())
}

/// A low-confidence region of the prior shorter than this many reference samples is a short
/// island (the rate term's opening: a region narrower than the alignment can place a change
/// of speed).
const SHORT_ISLAND: usize = tandem::lfd::RateTerm::DEFAULT_OPENING;

/// `fit`'s note when a range is still advisable: the short low-confidence islands of the
/// prior that the demonstrations' speeds alone make (high confidence without the rate's part
/// of `σ²_D`), and the rate range from which every one of them is high-confidence. The rate's
/// part scales as `1/r²` with the range `r` and the alignment does not depend on it, so the
/// prior with `--ranges rate=r` is computed here exactly, for the same reference
/// (docs/decisions.md, "Timing-only variable sections: the duration term").
fn range_advice(planner: &Planner) -> Result<Option<String>> {
    use tandem::confidence::Confidence;
    let model = planner.model();
    let params = planner.params().confidence.clone();
    let sigma2 = model.sigma2_d();
    let rate = model.sigma2_d_rate();
    let channels: Vec<f64> = sigma2
        .iter()
        .zip(&rate)
        .map(|(s, r)| (s - r).max(0.0))
        .collect();
    let prior = Confidence::from_prior(sigma2, params.clone())?;
    let without_rate = Confidence::from_prior(&channels, params.clone())?;
    let islands: Vec<std::ops::Range<usize>> = prior
        .low_regions()
        .into_iter()
        .filter(|r| r.len() < SHORT_ISLAND && r.clone().all(|n| without_rate.conf()[n]))
        .collect();
    if islands.is_empty() {
        return Ok(None);
    }
    let samples: Vec<usize> = islands.iter().flat_map(Clone::clone).collect();
    // High confidence on every island sample with the rate's part scaled by `s`.
    let all_high = |s: f64| -> Result<bool> {
        let v: Vec<f64> = samples.iter().map(|&n| channels[n] + s * rate[n]).collect();
        Ok(Confidence::from_prior(&v, params.clone())?
            .conf()
            .iter()
            .all(|&h| h))
    };
    // Bisection on the scale (1: the model's range, 0: no rate term, where all are high).
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if all_high(mid)? {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let d = model.ranges().len();
    let now = model.ranges()[d - 1];
    // The range for the scale `lo`, rounded up to three significant digits (a larger range
    // only lowers the rate's part).
    let needed = now / lo.max(f64::MIN_POSITIVE).sqrt();
    let digits = 10f64.powi(needed.log10().floor() as i32 - 2);
    let advised = (needed / digits).ceil() * digits;
    let scale = (now / advised).powi(2);
    if !all_high(scale)? {
        return Ok(None);
    }
    let with: Vec<f64> = channels
        .iter()
        .zip(&rate)
        .map(|(c, r)| c + scale * r)
        .collect();
    let after = Confidence::from_prior(&with, params)?;
    Ok(Some(format!(
        "range: channel `rate`: {} low-confidence island{} shorter than {SHORT_ISLAND} samples \
         from the demonstrations' speeds alone; `--ranges rate={}` (now {}) would make {} \
         high-confidence ({:.1} % → {:.1} % of the task, {} → {} low-confidence regions)",
        islands.len(),
        if islands.len() == 1 { "" } else { "s" },
        fmt_range(advised),
        fmt_range(now),
        if islands.len() == 1 { "it" } else { "them" },
        100.0 * prior.high_share(),
        100.0 * after.high_share(),
        prior.low_regions().len(),
        after.low_regions().len(),
    )))
}

/// A range with three significant digits and no floating-point noise.
fn fmt_range(v: f64) -> String {
    let digits = (2 - v.log10().floor() as i32).max(0) as usize;
    format!("{v:.digits$}")
}

/// One stretch of consecutive hold points of the same activity.
struct HoldRun {
    /// First reference sample.
    start: usize,
    /// Last reference sample (inclusive).
    last: usize,
    /// Whether its samples are high-confidence, so a robot may dwell there now.
    active: bool,
}

impl HoldRun {
    /// Its number of reference samples.
    fn len(&self) -> usize {
        self.last + 1 - self.start
    }
}

/// The planner's hold points (`Problem::holds`) as stretches of consecutive samples with the
/// same activity, in reference order.
fn hold_runs(planner: &Planner) -> Vec<HoldRun> {
    let conf = planner.problem().conf();
    let mut runs: Vec<HoldRun> = Vec::new();
    for &n in planner.problem().holds() {
        match runs.last_mut() {
            Some(r) if r.last + 1 == n && r.active == conf[n] => r.last = n,
            _ => runs.push(HoldRun {
                start: n,
                last: n,
                active: conf[n],
            }),
        }
    }
    runs
}

/// `1.50–3.95 s (samples 30–79, active)` or `2.00 s (sample 40, inactive)`.
fn hold_run_text(r: &HoldRun, dt: f64) -> String {
    let state = if r.active { "active" } else { "inactive" };
    if r.start == r.last {
        format!("{:.2} s (sample {}, {state})", r.start as f64 * dt, r.start)
    } else {
        format!(
            "{:.2}–{:.2} s (samples {}–{}, {state})",
            r.start as f64 * dt,
            r.last as f64 * dt,
            r.start,
            r.last
        )
    }
}

/// `tandem inspect --json`'s `holds`: the declaration, the resolved samples and their
/// stretches.
fn holds_out(planner: &Planner) -> json::HoldsOut {
    let dt = planner.model().dt_s();
    let conf = planner.problem().conf();
    let holds = planner.problem().holds();
    json::HoldsOut {
        declared: json::HoldSpecOut::from(&planner.params().holds),
        samples: holds.to_vec(),
        active_samples: holds.iter().filter(|&&n| conf[n]).count(),
        stretches: hold_runs(planner)
            .iter()
            .map(|r| json::HoldStretchOut {
                ref_start: r.start,
                ref_last: r.last,
                start_s: r.start as f64 * dt,
                last_s: r.last as f64 * dt,
                active: r.active,
            })
            .collect(),
    }
}

/// The hold-point lines of `fit`, `record` and `inspect`; nothing without a declaration.
fn hold_lines(planner: &Planner) {
    let spec = &planner.params().holds;
    if spec.is_empty() {
        return;
    }
    let holds = planner.problem().holds();
    let active = planner.problem().active_holds().count();
    let runs = hold_runs(planner);
    let mut declared: Vec<String> = spec.at_s.iter().map(|t| format!("at {t} s")).collect();
    declared.extend(spec.rules.iter().map(|r| format!("where {r}")));
    out(&format!(
        "hold points ({}): {} samples in {} stretch{}, {active} active (high-confidence: a \
         robot may wait there)",
        declared.join(", "),
        holds.len(),
        runs.len(),
        if runs.len() == 1 { "" } else { "es" }
    ));
    for line in hold_run_lines(&runs, planner.model().dt_s(), verbose()) {
        out(&line);
    }
}

/// Hold-point stretches listed one per line before a summary takes over (`--verbose` lists
/// them all).
const HOLD_RUNS_LISTED: usize = 5;

/// Longest stretches named in a summary.
const HOLD_RUNS_LONGEST: usize = 3;

/// Inactive stretches of at most this many samples are counted as slivers in a summary:
/// they sit at the edges of low-confidence regions, where the mean of the channel crosses
/// the rule's value while the confidence is still low.
const HOLD_SLIVER_SAMPLES: usize = 4;

/// The lines under the hold-point line: every stretch when there are few (or `all`),
/// otherwise per activity the count, the samples, the longest few and what makes an
/// inactive one active.
fn hold_run_lines(runs: &[HoldRun], dt: f64, all: bool) -> Vec<String> {
    if all || runs.len() <= HOLD_RUNS_LISTED {
        return runs
            .iter()
            .map(|r| format!("  {}", hold_run_text(r, dt)))
            .collect();
    }
    let mut lines = Vec::new();
    for active in [true, false] {
        let mut mine: Vec<&HoldRun> = runs.iter().filter(|r| r.active == active).collect();
        if mine.is_empty() {
            continue;
        }
        let samples: usize = mine.iter().map(|r| r.len()).sum();
        let slivers = mine
            .iter()
            .filter(|r| r.len() <= HOLD_SLIVER_SAMPLES)
            .count();
        // Longest first; ties in reference order.
        mine.sort_by(|a, b| b.len().cmp(&a.len()).then(a.start.cmp(&b.start)));
        let longest: Vec<String> = mine
            .iter()
            .take(HOLD_RUNS_LONGEST)
            .map(|r| hold_run_span(r, dt))
            .collect();
        let (state, what) = if active {
            ("active", "a robot may wait there now")
        } else {
            (
                "inactive",
                "low-confidence: each becomes active once recorded rounds make its samples \
                 trusted",
            )
        };
        let sliver_text = if !active && slivers > 0 {
            format!(
                "; {slivers} of them {HOLD_SLIVER_SAMPLES} samples or shorter, at the edges of \
                 low-confidence regions"
            )
        } else {
            String::new()
        };
        lines.push(format!(
            "  {state}: {} stretch{}, {samples} samples ({what}); longest: {}{sliver_text}",
            mine.len(),
            if mine.len() == 1 { "" } else { "es" },
            longest.join(", ")
        ));
    }
    lines.push("  (--verbose lists every stretch; inspect --json has them all)".into());
    lines
}

/// `11.02–32.07 s (2106 samples)` or `2.00 s (1 sample)`.
fn hold_run_span(r: &HoldRun, dt: f64) -> String {
    let n = r.len();
    if n == 1 {
        format!("{:.2} s (1 sample)", r.start as f64 * dt)
    } else {
        format!(
            "{:.2}–{:.2} s ({n} samples)",
            r.start as f64 * dt,
            r.last as f64 * dt
        )
    }
}

/// Confidence and schedule lines shared by `fit`, `record` and `inspect`.
fn summary_lines(planner: &Planner) -> Result<()> {
    let conf = planner.confidence();
    out(&format!(
        "high confidence: {:.1} % of reference samples ({} of {}), {} low-confidence regions",
        100.0 * conf.high_share(),
        conf.n_high(),
        conf.n_ref(),
        conf.low_regions().len()
    ));
    hold_lines(planner);
    if let Some(line) = operator_line(&planner.params().sampler) {
        out(&line);
    }
    if let Some(line) = sectors_line(planner)? {
        out(&line);
    }
    out(&format!(
        "schedule: {}",
        certificate_line(planner.problem(), planner.outcome())?
    ));
    // Two robots: `τ = 12.65 s`; N robots: `τ = 0.29, 0.58 s` (robots 2..N); one: no offset.
    let offsets =
        offsets_text(planner.schedule()).map_or("one robot".into(), |t| format!("τ = {t} s"));
    out(&format!(
        "schedule: {offsets}; {}",
        outcome_source_name(planner.problem(), planner.outcome())
    ));
    Ok(())
}

fn schedule(a: &ScheduleArgs) -> Result<()> {
    if crate::cells::is_cell(&a.state) {
        return crate::cells::schedule_cell(a);
    }
    if a.cell == Cell::Continuous {
        return cyclic::schedule_continuous(a);
    }
    // With --save this is a read–modify–write: hold the state file's lock throughout.
    let lock = a.save.then(|| state_io::lock(&a.state)).transpose()?;
    let mut planner = state_io::load(&a.state)?;
    let mut sp = planner.params().sampler.clone();
    // The schedule's own control tick is kept (the planner's rule for `tick_s = None`).
    sp.tick_s = None;
    if a.sampler.seed.is_none() {
        // A plain re-run draws new, still deterministic, candidates (the planner's rule,
        // shared with Python's `Planner.reschedule`).
        sp.seed = reschedule_seed(sp.seed, planner.rounds_recorded());
    }
    let sp = apply_sampler(sp, &a.sampler)?;
    // The operator's parameters are the planner's own (later rounds honour them): set, and
    // stored with --save.
    planner
        .set_operator(sp.switch_s, sp.max_busy_share)
        .context("--switch-s/--max-busy")?;
    planner.set_operators(sp.operators).context("--operators")?;
    let previous_t_total_s = planner.outcome().t_total_s;
    planner.reschedule(&sp).context("cannot schedule")?;
    if let Some(lock) = &lock {
        // Atomic: on error the previous state file is intact.
        planner
            .save_locked(lock)
            .with_context(|| format!("cannot save the schedule into {}", a.state.display()))?;
    }
    if a.json {
        let doc = json::ScheduleDoc {
            saved: Some(a.save),
            previous_t_total_s: Some(previous_t_total_s),
            ..schedule_doc(planner.problem(), planner.outcome())?
        };
        out(&serde_json::to_string_pretty(&json::value(&doc)?)?);
    } else {
        out(&gantt_text(planner.problem(), planner.outcome())?);
        if let Some(line) = operator_line(&planner.params().sampler) {
            out(&line);
        }
        if let Some(line) = sectors_line(&planner)? {
            out(&line);
        }
        out(&format!(
            "saved schedule: T_total {:.2} s; {}",
            previous_t_total_s,
            if a.save {
                format!("replaced by this one in {}", a.state.display())
            } else {
                "unchanged (use --save to keep this one)".into()
            }
        ));
    }
    Ok(())
}

/// One robot's three files, read and checked as the planner takes them in
/// ([`Planner::check_execution`]: resampled to the model's period if logged finer, the whole
/// task covered, a plausible duration). An execution without a `t` column is taken to be
/// logged once per control tick of the schedule it ran (`record` says so on stderr for the
/// whole round, [`period_notes`]). With `resample`
/// (`--resample`) an irregular `t` column is first put on an even grid, the log and flags
/// with it ([`ExecutionRecord::from_regridded`]).
pub(crate) fn read_execution(
    planner: &Planner,
    robot: usize,
    exec: &Path,
    log: &Path,
    corr: &Path,
    resample: bool,
) -> Result<ExecutionRecord> {
    let (demonstration, grid) = if resample {
        let grid = input::regrid_execution(exec)?;
        (grid.demonstration.clone(), Some(grid))
    } else {
        (
            input::read_demo(exec, Some(planner.schedule().tick_s))?,
            None,
        )
    };
    let ref_time_log = input::read_log(log)?;
    let (supervised, corrected) = input::read_corrections(corr)?;
    let n = grid
        .as_ref()
        .map_or(demonstration.n_samples(), |g| g.n_rows());
    if ref_time_log.len() != n {
        bail!(
            "{}: {} rows, but execution {} has {n} samples (one log row per sample)",
            log.display(),
            ref_time_log.len(),
            exec.display()
        );
    }
    if supervised.len() != n {
        bail!(
            "{}: {} rows, but execution {} has {n} samples (one row per sample)",
            corr.display(),
            supervised.len(),
            exec.display()
        );
    }
    let record = match grid {
        Some(g) => ExecutionRecord::from_regridded(g, &ref_time_log, &supervised, &corrected)?,
        None => ExecutionRecord {
            execution: Execution {
                demonstration,
                ref_time_log,
            },
            supervised,
            corrected,
        },
    };
    planner.check_execution(&record).with_context(|| {
        format!(
            "robot {robot}: execution {} with log {} does not fit the model",
            exec.display(),
            log.display()
        )
    })?;
    Ok(record)
}

fn record(a: &RecordArgs) -> Result<()> {
    if crate::cells::is_cell(&a.state) {
        return crate::cells::record_cell(a);
    }
    // A read–modify–write: hold the state file's lock from the load to the save, so that a
    // concurrent `record` waits for this one instead of overwriting its round.
    let lock = state_io::lock(&a.state)?;
    let mut planner = state_io::load(&a.state)?;
    let n = planner.n_robots();
    for (flag, v) in [
        ("--execution", &a.execution),
        ("--log", &a.log),
        ("--corrections", &a.corrections),
    ] {
        if v.len() != n && a.bags.is_empty() {
            bail!(
                "{flag} given {} time(s); {} has {n} robots, so a round needs exactly {n} \
                 (robot 1 first)",
                v.len(),
                a.state.display()
            );
        }
    }
    let before_t = planner.outcome().t_total_s;
    let before_high = planner.confidence().high_share();
    let r = |i: usize| {
        read_execution(
            &planner,
            i + 1,
            &a.execution[i],
            &a.log[i],
            &a.corrections[i],
            a.resample,
        )
    };
    let round = if a.bags.is_empty() {
        let round = (0..n).map(r).collect::<Result<Vec<_>>>()?;
        let demos: Vec<&Demonstration> = round.iter().map(|r| &r.execution.demonstration).collect();
        period_notes(
            &demos,
            " (the assumed period is the control tick of the schedule it ran)",
        );
        round
    } else {
        bag::read_round(&planner, &a.bags, a.round, &a.topics)?
    };
    let report = planner
        .record_round(&round)
        .context("cannot record the round")?;
    planner.save_locked(&lock)?;
    drop(lock);
    for n in &report.notices {
        note(n);
    }
    out(&format!(
        "recorded round {} into {}",
        planner.rounds_recorded(),
        a.state.display()
    ));
    out(&format!(
        "confidence: {} reference samples became high-confidence; {:.1} % → {:.1} %",
        report.newly_high,
        100.0 * before_high,
        100.0 * planner.confidence().high_share()
    ));
    if report.reopened > 0 {
        out(&format!(
            "reopened: {} latched reference samples are low-confidence again (this round's \
             corrections reached them)",
            report.reopened
        ));
    }
    out(&format!(
        "T_total: {before_t:.2} s → {:.2} s",
        report.t_total_s
    ));
    if let Some(fate) = report.previous.describe() {
        out(&format!("previous schedule: {fate}"));
    }
    summary_lines(&planner)?;
    Ok(())
}

fn inspect(a: &InspectArgs) -> Result<()> {
    // A folder can only be a rosbag2 recording (or is refused as one, with what it holds).
    if tandem::bag::is_bag(&a.state) || a.state.is_dir() {
        return bag::inspect_bag(&a.state, a.json);
    }
    if crate::cells::is_cell(&a.state) {
        return crate::cells::inspect_cell(a);
    }
    let planner = state_io::load(&a.state)?;
    let model = planner.model();
    let conf = planner.confidence();
    let obs = planner.observations();
    let s2 = model.sigma2_d();
    let mut sorted = s2.to_vec();
    sorted.sort_by(f64::total_cmp);
    let q = |p: f64| sorted[((sorted.len() - 1) as f64 * p).round() as usize];
    let dt = model.dt_s();
    let explained = planner
        .explain_low_confidence()
        .context("cannot explain the low-confidence regions")?;
    let rates = planner.error_rates()?;
    let prior_threshold = tandem::confidence::prior_low_threshold(conf.params())?;
    let ranges = model
        .tangent_names()
        .iter()
        .zip(model.ranges())
        .map(|(n, &r)| (n.clone(), r))
        .collect();
    let doc = json::InspectDoc {
        state: a.state.display().to_string(),
        rounds_recorded: planner.rounds_recorded(),
        pairs_recorded: planner.rounds_recorded(),
        model: json::ModelOut {
            channels: model.channel_names().to_vec(),
            reference: json::ReferenceOut {
                choice: planner.params().fit.reference.to_string(),
                demo_idx: model.reference_idx(),
            },
            n_ref: model.n_ref(),
            dt_s: dt,
            reference_duration_s: model.n_ref() as f64 * dt,
            count: model.count(),
            correction_components: model.n_components(),
            ranges,
            sigma2_d: json::QuantilesOut {
                min: q(0.0),
                median: q(0.5),
                p90: q(0.9),
                max: q(1.0),
            },
            mean_duration_s: model.grad_mean().iter().sum::<f64>() * dt,
            fastest_duration_s: model.grad_min().iter().sum::<f64>() * dt,
            slowest_duration_s: model.grad_max().iter().sum::<f64>() * dt,
        },
        confidence: json::ConfidenceOut {
            params: json::ConfidenceParamsOut::from(conf.params()),
            high_share: conf.high_share(),
            n_high: conf.n_high(),
            low_regions: explained.iter().map(json::LowRegionOut::from).collect(),
            error_rates: json::ErrorRatesOut::from(rates),
            sigma2_d_prior_threshold: prior_threshold,
            total_supervised: obs.total_supervised(),
            total_corrections: obs.total_corrections(),
        },
        schedule: schedule_doc(planner.problem(), planner.outcome())?,
        holds: holds_out(&planner),
    };
    if a.json {
        out(&serde_json::to_string_pretty(&json::value(&doc)?)?);
        return Ok(());
    }
    out(&format!("state file {}", a.state.display()));
    out(&format!(
        "model: {} demonstrations and executions, {} rounds recorded",
        model.count(),
        planner.rounds_recorded()
    ));
    out(&format!(
        "  reference: demonstration {} of the fit ({}), {} samples × {} s = {:.2} s; channels: {}",
        model.reference_idx() + 1,
        planner.params().fit.reference,
        model.n_ref(),
        secs(dt),
        model.n_ref() as f64 * dt,
        model.channel_names().join(", ")
    ));
    out(&format!(
        "  execution length: mean {:.2} s, fastest {:.2} s, slowest {:.2} s (demonstrated speed bounds)",
        doc.model.mean_duration_s, doc.model.fastest_duration_s, doc.model.slowest_duration_s,
    ));
    let ranges_txt: Vec<String> = model
        .tangent_names()
        .iter()
        .zip(model.ranges())
        .map(|(n, r)| format!("{n}={r:.4}"))
        .collect();
    out(&format!(
        "  ranges (W = diag(1/r²)): {}",
        ranges_txt.join(", ")
    ));
    out(&format!(
        "  σ²_D (dimensionless): min {:.2e}, median {:.2e}, 90 % {:.2e}, max {:.2e}",
        q(0.0),
        q(0.5),
        q(0.9),
        q(1.0)
    ));
    out(&format!(
        "  correction directions per sample: {}",
        model.n_components()
    ));
    let p = conf.params();
    out(&format!(
        "confidence: γ_p {}, σ²_MAX {}, ε {}, μ_c {}, γ_c {}",
        p.gamma_p, p.sigma2_max, p.epsilon, p.mu_c, p.gamma_c
    ));
    out(&format!(
        "  operator error rates: false corrections {:.3} %, misses {:.3} % ({})",
        100.0 * rates.false_correction_rate,
        100.0 * rates.miss_rate,
        if p.estimate_error_rates {
            "estimated from the executions"
        } else {
            "as configured"
        }
    ));
    if let Some(t) = prior_threshold {
        out(&format!(
            "  the prior alone is low-confidence where σ²_D > {t:.3e}"
        ));
    }
    out(&format!(
        "  observations: {:.0} supervised samples, {:.0} corrected",
        obs.total_supervised(),
        obs.total_corrections()
    ));
    summary_lines(&planner)?;
    let lows = &explained;
    const SHOWN: usize = 20;
    out(&format!(
        "low-confidence regions (reference time): {}",
        lows.len()
    ));
    for r in lows.iter().take(SHOWN) {
        out(&format!(
            "  {:>9.2} – {:>9.2} s   samples {:>6} – {:>6}",
            r.start_s, r.end_s, r.ref_start, r.ref_end
        ));
        out(&format!("      why: {}", why_text(r)));
        out(&format!("      would change it: {}", remedy_text(r)));
    }
    if lows.len() > SHOWN {
        out(&format!(
            "  … {} more (tandem inspect --json lists all)",
            lows.len() - SHOWN
        ));
    }
    Ok(())
}

/// The cause of a low-confidence region in words (`tandem inspect`).
fn why_text(r: &tandem::planner::LowRegion) -> String {
    use tandem::planner::LowCause;
    let channels: Vec<String> = r
        .channels
        .iter()
        .map(|c| format!("{} {:.0} %", c.name, 100.0 * c.share))
        .collect();
    match r.cause {
        LowCause::Corrections => format!(
            "corrections: {:.0} of {:.0} supervised samples corrected, the operator's false \
             corrections explain {:.1}",
            r.corrections, r.supervised, r.expected_false_corrections
        ),
        LowCause::Variance => format!(
            "demonstration variance: σ²_D up to {:.3e}{} ({}); {:.0} supervised samples, \
             {:.0} corrected",
            r.sigma2_d_max,
            r.sigma2_d_prior_threshold
                .map_or(String::new(), |t| format!(" against the prior's {t:.3e}")),
            channels.join(", "),
            r.supervised,
            r.corrections
        ),
    }
}

/// What would change a low-confidence region, in words (`tandem inspect`).
fn remedy_text(r: &tandem::planner::LowRegion) -> String {
    use tandem::planner::LowCause;
    if r.cause == LowCause::Corrections {
        return "nothing but the task: the operator is needed here".into();
    }
    let mut parts = Vec::new();
    if let Some(k) = r.clean_executions_needed {
        parts.push(format!(
            "{k} more supervised executions without a correction"
        ));
    }
    for c in &r.channels {
        if let Some(range) = c.range_for_prior {
            parts.push(format!(
                "a range of {range:.4} for {} (now {:.4}) if its variation there does not matter",
                c.name, c.range
            ));
        }
    }
    if parts.is_empty() {
        "more supervised executions without a correction".into()
    } else {
        parts.join("; or ")
    }
}

fn plot_cmd(a: &PlotArgs) -> Result<()> {
    let planner = state_io::load(&a.state)?;
    state_io::prepare_dir(&a.output)?;
    let written: Vec<PathBuf> = plot::plot_all(&planner, &a.output)?;
    for p in written {
        out(&format!("wrote {}", p.display()));
    }
    Ok(())
}

fn params() -> Result<()> {
    let text = toml::to_string_pretty(&PlannerParams::default())
        .context("cannot print the default parameters")?;
    out("# tandem parameters (defaults). Use with: tandem fit --params FILE …");
    out("# Sections: [fit] alignment and model, [confidence] Eq. 10–12, [sampler] §II-C.");
    out(
        "# [sampler] switch_s: the operator's switch time δ in seconds (≥ 0; 0: none); \
         max_busy_share: the operator's load cap u_max, a share of the time in (0, 1] (1: no cap).",
    );
    out(&text);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(start: usize, len: usize, active: bool) -> HoldRun {
        HoldRun {
            start,
            last: start + len - 1,
            active,
        }
    }

    #[test]
    fn many_hold_stretches_are_summarized_and_few_are_listed() {
        // 23 stretches as on a partly trusted task: 9 active (lengths 10..=90), 14 inactive of
        // which 10 are slivers of 2–4 samples and 4 longer (100, 200, 300, 5 samples).
        let mut runs = Vec::new();
        let mut at = 0;
        let mut push = |len: usize, active: bool| {
            runs.push(run(at, len, active));
            at += len + 10;
        };
        for k in 1..=9 {
            push(10 * k, true);
        }
        for k in 0..10 {
            push(2 + k % 3, false);
        }
        for len in [100, 200, 300, 5] {
            push(len, false);
        }
        let lines = hold_run_lines(&runs, 0.01, false);
        assert_eq!(lines.len(), 3, "{lines:#?}");
        // Active: 9 stretches, 10 + 20 + … + 90 = 450 samples, the longest three first.
        assert!(
            lines[0].starts_with(
                "  active: 9 stretches, 450 samples (a robot may wait there now); longest: "
            ),
            "{}",
            lines[0]
        );
        assert!(lines[0].contains("(90 samples), "), "{}", lines[0]);
        // Inactive: 14 stretches; slivers 4×2 + 3×3 + 3×4 = 29 samples, plus 605.
        assert!(
            lines[1].starts_with("  inactive: 14 stretches, 634 samples (low-confidence"),
            "{}",
            lines[1]
        );
        assert!(lines[1].contains("(300 samples), "), "{}", lines[1]);
        assert!(
            lines[1].ends_with(
                "; 10 of them 4 samples or shorter, at the edges of low-confidence regions"
            ),
            "{}",
            lines[1]
        );
        assert!(lines[2].contains("--verbose"));
        // --verbose, or five stretches or fewer: one line each.
        assert_eq!(hold_run_lines(&runs, 0.01, true).len(), 23);
        let few = hold_run_lines(&runs[..5], 0.01, false);
        assert_eq!(few.len(), 5);
        assert_eq!(few[0], "  0.00–0.09 s (samples 0–9, active)");
    }
}
