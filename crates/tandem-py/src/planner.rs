//! `tandem.fit`, `tandem.Planner` (the Fig. 2 loop and its state file), `tandem.Model`,
//! `tandem.Confidence` and `tandem.Observations`.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use crate::arrays::{flags, matrix, out_flags, out_matrix, out_vector, repr_list, vector};
use crate::errors::{Error, Result, deprecated, guard, warn};
use crate::facade::{
    AnyController, BetaParams, Cell, DEFAULT_DT_S, DEFAULT_LOCK_TIMEOUT, DT_TOLERANCE,
    Demonstration, Execution, ExecutionRecord, HoldRule, HoldSpec, Observations, PeriodSource,
    Plan, Planner, PlannerParams, RateTerm, RecordReport, Regridded, StateLock, TaskModel,
    drifting_majority, errors, length_warnings, posterior, prior, prior_low_threshold,
    prob_need_below_mu_c, reschedule_seed,
};
use crate::facade::{BagOptions, Recording, extend_bag_schema, is_bag, read_bag};
use crate::params::{from_py, serialize_to_py};
use crate::schedule::PyProblem;
use crate::schedule::PySchedule;

/// The default robot count (the paper's two robots): `tandem.fit(robots=...)`'s default.
pub(crate) const N_ROBOTS: usize = 2;

/// `e` with the in-memory source label replaced by `label` (the Python argument).
fn relabel(e: errors::Lfd, label: &str) -> errors::Lfd {
    match e {
        errors::Lfd::BadData { why, .. } => errors::Lfd::BadData {
            what: label.to_owned(),
            why,
        },
        errors::Lfd::TooFewSamples { found, .. } => errors::Lfd::TooFewSamples {
            at: label.to_owned(),
            found,
        },
        other => other,
    }
}

/// The channel names that go with a demonstration argument.
#[derive(Clone, Copy)]
pub(crate) struct Channels<'a> {
    /// The names of an array's columns (required for arrays).
    pub(crate) array: Option<&'a [String]>,
    /// Names a file's header must have, in order, if any.
    pub(crate) file: Option<&'a [String]>,
}

/// One demonstration or execution from a Python value: a CSV or JSON path (the command
/// line's formats; JSON by extension), a ROS 2 bag (`.mcap`, read like `tandem fit` reads it,
/// its recording pushed to `recordings` when given), or a `(T, C)` array with
/// `channels.array` naming its columns, sample period `dt_s` (s). `label` names it in errors
/// (`demos[2]`).
fn demonstration(
    x: &Bound<'_, PyAny>,
    label: &str,
    channels: Channels<'_>,
    dt_s: Option<f64>,
    recordings: Option<&mut Vec<Recording>>,
) -> Result<Demonstration> {
    if x.is_instance_of::<PyString>() || x.hasattr("__fspath__").unwrap_or(false) {
        let path: PathBuf = x
            .extract()
            .map_err(|e| Error::input(label, format!("not a path: {e}")))?;
        let is_json = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"));
        let demo = if is_bag(&path) {
            let rec = read_bag(&path, &BagOptions::default())?;
            let demo = rec.demonstration()?;
            if let Some(r) = recordings {
                r.push(rec);
            }
            demo
        } else if is_json {
            Demonstration::from_json_path(&path, dt_s)?
        } else {
            Demonstration::from_csv_path(&path, dt_s)?
        };
        if let Some(names) = channels.file
            && names != demo.channel_names()
        {
            return Err(Error::Input {
                what: label.to_owned(),
                why: format!(
                    "{}: columns {} differ from channels={}",
                    path.display(),
                    repr_list(demo.channel_names()),
                    repr_list(names)
                ),
                file: Some(path.display().to_string()),
            });
        }
        return Ok(demo);
    }
    let (values, cols) = matrix(x, label, "samples × channels")?;
    let names = channels.array.ok_or_else(|| {
        Error::input(
            "channels",
            format!("{label} is an array: give channels=[...], one name per column"),
        )
    })?;
    if names.len() != cols {
        return Err(Error::input(
            label,
            format!(
                "{cols} columns, but channels names {}: {}",
                names.len(),
                repr_list(names)
            ),
        ));
    }
    let demo = Demonstration::new(names.to_vec(), values, dt_s.unwrap_or(DEFAULT_DT_S))
        .map_err(|e| relabel(e, label))?;
    Ok(demo.with_source(label))
}

/// A CSV with its own times put on an even grid (`record_round(resample=True)`,
/// `fit(resample=True)`; `Demonstration::regrid_csv_str`): the period `dt_s`, or its logger's
/// period, keeping how its rows map onto the grid for the log and flags given beside it.
/// Arrays (no times), JSON and bags are refused; `channels.file`, when given, must match the
/// header.
fn regridded_execution(
    x: &Bound<'_, PyAny>,
    label: &str,
    channels: Channels<'_>,
    dt_s: Option<f64>,
) -> Result<Regridded> {
    let is_path = x.is_instance_of::<PyString>() || x.hasattr("__fspath__").unwrap_or(false);
    if !is_path {
        return Err(Error::input(
            label,
            "resample=True needs the time of every row: give a CSV file with a `t` column \
             (an array has no times; give it at dt_s instead)",
        ));
    }
    let path: PathBuf = x
        .extract()
        .map_err(|e| Error::input(label, format!("not a path: {e}")))?;
    let other = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json") || e.eq_ignore_ascii_case("mcap"));
    if other {
        return Err(Error::Input {
            what: label.to_owned(),
            why: format!(
                "{}: resample=True applies to CSV files with a `t` column; a JSON file or a \
                 bag is already on an even grid",
                path.display()
            ),
            file: Some(path.display().to_string()),
        });
    }
    let grid = Demonstration::regrid_csv_path(&path, dt_s)?;
    if let Some(names) = channels.file
        && names != grid.demonstration.channel_names()
    {
        return Err(Error::Input {
            what: label.to_owned(),
            why: format!(
                "{}: columns {} differ from channels={}",
                path.display(),
                repr_list(grid.demonstration.channel_names()),
                repr_list(names)
            ),
            file: Some(path.display().to_string()),
        });
    }
    Ok(grid)
}

/// The items of a Python sequence argument (not a string or a single array).
pub(crate) fn items<'py>(x: &Bound<'py, PyAny>, what: &str) -> Result<Vec<Bound<'py, PyAny>>> {
    let single = x.is_instance_of::<PyString>()
        || x.hasattr("__fspath__").unwrap_or(false)
        || x.hasattr("__array_interface__").unwrap_or(false)
        || x.is_instance_of::<PyDict>();
    if single {
        return Err(Error::input(
            what,
            "expected a list (one entry per demonstration or robot), got a single value",
        ));
    }
    let iter = x
        .try_iter()
        .map_err(|_| Error::input(what, "expected a list"))?;
    iter.map(|item| item.map_err(|e| Error::input(what, e.to_string())))
        .collect()
}

/// Demonstrations from `demos` (paths or arrays, see [`demonstration`]), with the bags'
/// orientations added to `params`' channel schema as quaternion blocks, and the labels of
/// the arrays that took the default period because `dt_s` was not given.
pub(crate) fn demonstrations(
    demos: &Bound<'_, PyAny>,
    channels: Option<&[String]>,
    dt_s: Option<f64>,
    resample: bool,
    params: &mut PlannerParams,
) -> Result<Loaded> {
    let list = items(demos, "demos")?;
    if list.len() < 2 {
        return Err(Error::input(
            "demos",
            format!(
                "{} demonstration(s); the variability of the task needs at least 2",
                list.len()
            ),
        ));
    }
    let mut recordings = Vec::new();
    let mut assumed = Vec::new();
    let mut resampled = Vec::new();
    let out = list
        .iter()
        .enumerate()
        .map(|(k, d)| {
            let both = Channels {
                array: channels,
                file: channels,
            };
            let label = format!("demos[{k}]");
            let is_path =
                d.is_instance_of::<PyString>() || d.hasattr("__fspath__").unwrap_or(false);
            if dt_s.is_none() && !is_path {
                assumed.push(label.clone());
            }
            let demo = if resample {
                let grid = regridded_execution(d, &label, both, dt_s)?;
                resampled.push(grid.note.clone());
                grid.demonstration
            } else {
                demonstration(d, &label, both, dt_s, Some(&mut recordings))?
            };
            // A file's own time wins over dt_s; a dt_s that contradicts it is refused.
            if let Some(dt) = dt_s
                && demo.period_source() == PeriodSource::File
                && (demo.dt_s() - dt).abs() > DT_TOLERANCE * dt
            {
                return Err(Error::param(
                    "dt_s",
                    format!(
                        "{dt} s, but {} has its own time (`t` column or `dt_s`) giving {} s: \
                         leave dt_s out (it is for arrays and files without a time column) or \
                         fix the file",
                        demo.source(),
                        (demo.dt_s() * 1e9).round() / 1e9
                    ),
                ));
            }
            Ok(demo)
        })
        .collect::<Result<Vec<_>>>()?;
    // resample=True without dt_s: loggers whose clocks merely drift apart go onto the period
    // most of them share, said once (as `tandem fit --resample` without `--dt`).
    let mut out = out;
    if resample && dt_s.is_none() {
        let periods: Vec<f64> = out.iter().map(Demonstration::dt_s).collect();
        if let Some((dt, count)) = drifting_majority(&periods) {
            for (k, d) in list.iter().enumerate() {
                if (out[k].dt_s() - dt).abs() > 1e-12 * dt {
                    let both = Channels {
                        array: channels,
                        file: channels,
                    };
                    let grid = regridded_execution(d, &format!("demos[{k}]"), both, Some(dt))?;
                    resampled[k] = grid.note;
                    out[k] = grid.demonstration;
                }
            }
            let nano = |p: f64| (p * 1e9).round() / 1e9;
            let (lo, hi) = periods
                .iter()
                .fold((f64::INFINITY, 0.0_f64), |(lo, hi), &p| {
                    (lo.min(p), hi.max(p))
                });
            resampled.insert(
                0,
                format!(
                    "the {} files' logger periods differ by up to {:.1} % ({} – {} s, clocks \
                     that drift): every file resampled onto {} s, the period of {count} of \
                     them (dt_s for another grid)",
                    out.len(),
                    100.0 * (hi - lo) / dt,
                    nano(lo),
                    nano(hi),
                    nano(dt)
                ),
            );
        }
    }
    extend_bag_schema(&mut params.fit.schema, &recordings);
    params.validate()?;
    Ok(Loaded {
        demos: out,
        assumed,
        resampled,
    })
}

/// Demonstrations as [`demonstrations`] loaded them.
pub(crate) struct Loaded {
    /// The demonstrations, in the order given.
    demos: Vec<Demonstration>,
    /// Labels of arrays given without `dt_s` (the default period was assumed).
    assumed: Vec<String>,
    /// One note per file put on an even grid (`resample=True`), naming the file
    /// (`Regridded::note`).
    resampled: Vec<String>,
}

impl Loaded {
    /// Raises the loading's `DataWarning`s (assumed periods, resampled files, the
    /// demonstrations' own) and hands the demonstrations out.
    pub(crate) fn warned(self, py: Python<'_>) -> PyResult<Vec<Demonstration>> {
        if !self.assumed.is_empty() {
            warn(py, &assumed_period_warning(&self.assumed))?;
        }
        for note in &self.resampled {
            warn(py, note)?;
        }
        warn_demonstrations(py, &self.demos)?;
        Ok(self.demos)
    }
}

/// The `DataWarning` for arrays given without `dt_s` (`labels`, non-empty): an array carries
/// no time, so the default period was assumed; relying on it is deprecated (docs/decisions.md,
/// "Arrays without a period: a warning now, an error later").
fn assumed_period_warning(labels: &[String]) -> String {
    let which = match labels {
        [one] => format!("{one} is an array"),
        [a, b] => format!("{a} and {b} are arrays"),
        [a, b, rest @ ..] => format!("{a}, {b} and {} more are arrays", rest.len()),
        [] => "no array".to_owned(),
    };
    let hz = (1.0 / DEFAULT_DT_S).round();
    format!(
        "{which} without dt_s: an array carries no time, so its samples were taken to be \
         {DEFAULT_DT_S} s apart ({hz} Hz), the default; if they were logged at another rate, \
         every duration and speed of the model is off by the ratio. Pass dt_s= (the sample \
         period in seconds, e.g. dt_s=0.005 for 200 Hz). Relying on the default is deprecated: \
         a later release refuses arrays without dt_s"
    )
}

/// Raises the `DataWarning`s of a set of demonstrations: the period assumed for a file
/// without a time column, and lengths far from the median (`tandem_lfd::length_warnings`).
fn warn_demonstrations(py: Python<'_>, demos: &[Demonstration]) -> PyResult<()> {
    for d in demos {
        if let Some(note) = d.period_note() {
            warn(py, &note)?;
        }
    }
    for w in length_warnings(demos) {
        warn(py, &w)?;
    }
    Ok(())
}

/// The timeout of a lock wait given in seconds from Python (`None`: the default, 60 s).
pub(crate) fn lock_timeout(timeout_s: Option<f64>) -> Result<Duration> {
    match timeout_s {
        None => Ok(DEFAULT_LOCK_TIMEOUT),
        Some(t) if t.is_finite() && t >= 0.0 => Ok(Duration::from_secs_f64(t)),
        Some(t) => Err(Error::param(
            "timeout_s",
            format!("{t} is not a finite number ≥ 0"),
        )),
    }
}

/// Planner parameters from `params` (None, a dict or a TOML path), checked.
pub(crate) fn planner_params(params: Option<&Bound<'_, PyAny>>) -> Result<PlannerParams> {
    let p: PlannerParams = from_py(params, "params")?;
    p.validate()?;
    Ok(p)
}

/// The hold points `holds` of `fit` (see its docs): `None` keeps `params`' declaration, a
/// dict is a `HoldSpec` (`{"at_s": [...], "rules": [...]}`), a list mixes reference times
/// (numbers, s) and rules (strings such as `"gripper>0.5"`); an empty list declares none.
fn hold_spec(holds: &Bound<'_, PyAny>) -> Result<HoldSpec> {
    if holds.is_instance_of::<pyo3::types::PyDict>() {
        return from_py(Some(holds), "holds");
    }
    if holds.extract::<String>().is_ok() {
        return Err(Error::param(
            "holds",
            "expected a list of reference times (s) and rules (e.g. [2.5, \"gripper>0.5\"]) or \
             a dict {\"at_s\": [...], \"rules\": [...]}, got a single string",
        ));
    }
    let mut spec = HoldSpec::default();
    for (k, item) in items(holds, "holds")?.iter().enumerate() {
        if let Ok(rule) = item.extract::<String>() {
            let rule: HoldRule = rule
                .parse()
                .map_err(|e: errors::Lfd| Error::param(format!("holds[{k}]"), e.to_string()))?;
            spec.rules.push(rule);
        } else if let Ok(t) = item.extract::<f64>() {
            spec.at_s.push(t);
        } else {
            return Err(Error::param(
                format!("holds[{k}]"),
                "expected a reference time (a number of seconds) or a rule (a string such as \
                 \"gripper>0.5\")",
            ));
        }
    }
    Ok(spec)
}

/// Learns the task from demonstrations and makes the first schedule (paper Fig. 2).
///
/// Aligns every demonstration to the reference (GDTW, Eq. 2–3; demo 0, or the medoid with
/// ``params["fit"]["reference"] = "medoid"``), fits the model (mean ``μ̂``, ``σ²_D`` of
/// Eq. 6, gradient bounds of Eq. 14, correction directions), sets the confidence from the
/// prior (Eq. 10–12) and samples a schedule (§II-C). Exactly what ``tandem fit`` does: the
/// same inputs and parameters give the same state file.
///
/// Args:
///     demos: at least two demonstrations, each a path to a CSV or JSON file (the command
///         line's formats, a ``t`` column sets the period), a ROS 2 bag (``.mcap``: every
///         topic of a supported type on one grid at the slowest topic's rate, as
///         ``tandem fit`` reads it; :func:`read_bag` shows what it reads) or a float array of
///         shape ``(T_i, C)`` (samples × channels, channel units).
///     channels: the ``C`` channel names of array demonstrations (required for arrays;
///         checked against a file's header if given).
///     params: ``None`` (defaults), a nested dict ``{"fit": …, "confidence": …,
///         "sampler": …}`` or the path of a TOML file (``tandem params`` prints the
///         defaults).
///     dt_s: sample period (s) of arrays and of files without a ``t`` column. Give it for
///         arrays: without it they are taken to be 0.01 s apart with a ``DataWarning`` naming
///         them (deprecated: a later release refuses arrays without ``dt_s``).
///     robots: robots ``N`` run by the one operator, 1 to 16 (default 2, the paper's): every
///         schedule has ``N`` warps and :meth:`Planner.record_round` takes ``N`` executions.
///     holds: hold points, places where a robot may wait as long as needed (``tandem fit
///         --hold-at``/``--hold-where``): a list of reference times (numbers, s, each at its
///         nearest reference sample) and rules (strings ``"<channel><op><value>"`` with
///         ``<``, ``<=``, ``>``, ``>=``, every sample where the channel's mean satisfies it,
///         e.g. ``[2.5, "gripper>0.5"]``), or a dict ``{"at_s": […], "rules": […]}``.
///         ``None`` (default) keeps ``params["holds"]``; ``[]`` declares none (the
///         schedule of before hold points, as ``--no-holds``). A hold on a low-confidence
///         sample is inactive until the sample is trusted.
///     switch_s: the operator's switch time ``δ`` (s, finite and ≥ 0; issue 41): at least
///         this long between the end of one robot's low-confidence stretch and the start of
///         another robot's, in the worst case (``tandem fit --switch-s``). ``None`` (default)
///         keeps ``params["sampler"]["switch_s"]`` (0: none). Stored in the state file.
///     max_busy_share: the operator's load cap ``u_max`` in ``(0, 1]``: its busy share,
///         supervised time plus ``switch_s`` per change of robot, may not exceed it
///         (``tandem fit --max-busy``). ``None`` (default) keeps
///         ``params["sampler"]["max_busy_share"]`` (1: no cap). Stored in the state file.
///     operators: the cell's operators ``M``, 1 to 16 (issue 44; ``tandem fit --operators``):
///         at most ``M`` robots low-confidence at once, each under its own operator — a
///         continuous cell runs ``M`` tokens, rounds run ``M`` sectors
///         (:meth:`Planner.sectored_rounds`). ``None`` (default) keeps
///         ``params["sampler"]["operators"]`` (1). Stored in the state file.
///     resample: put demonstrations given as CSV files with an irregular ``t`` column (a
///         logger's own jittered clock) on an even grid of their mean period first, as
///         ``tandem fit --resample`` does (channels interpolated linearly, quaternions by
///         slerp, 0/1 channels held); a ``DataWarning`` per file says what was done. Arrays,
///         JSON files and bags are refused with it (they carry no row times or are on a
///         grid already). Default ``False``: such a file is an ``InputError`` naming the row.
///
/// Raises:
///     InputError: a bad demonstration (with ``file``/``line`` for files).
///     ParamError: a bad parameter or robot count, a malformed hold, a hold outside the task
///         a rule on an unknown channel or one that holds nowhere, a ``switch_s``,
///         ``max_busy_share`` or ``operators`` out of range (``name`` names it).
#[pyfunction]
#[pyo3(signature = (demos, channels=None, params=None, dt_s=None, robots=N_ROBOTS, holds=None, rate_term=None, switch_s=None, max_busy_share=None, resample=false, operators=None))]
#[expect(
    clippy::too_many_arguments,
    reason = "the keyword arguments of the Python function, each documented above"
)]
pub(crate) fn fit(
    py: Python<'_>,
    demos: &Bound<'_, PyAny>,
    channels: Option<Vec<String>>,
    params: Option<&Bound<'_, PyAny>>,
    dt_s: Option<f64>,
    robots: usize,
    holds: Option<&Bound<'_, PyAny>>,
    rate_term: Option<String>,
    switch_s: Option<f64>,
    max_busy_share: Option<f64>,
    resample: bool,
    operators: Option<usize>,
) -> PyResult<PyPlanner> {
    let mut params = planner_params(params)?;
    apply_rate_term(&mut params, rate_term.as_deref())?;
    apply_operator(&mut params, switch_s, max_busy_share, operators)?;
    if let Some(holds) = holds.filter(|h| !h.is_none()) {
        params.holds = hold_spec(holds)?;
        params.validate().map_err(Error::from)?;
    }
    let demos =
        demonstrations(demos, channels.as_deref(), dt_s, resample, &mut params)?.warned(py)?;
    let planner = py.detach(|| guard(|| Ok(Planner::with_robots(&demos, params, robots)?)))?;
    Ok(PyPlanner { inner: planner })
}

/// ``switch_s=``, ``max_busy_share=`` and ``operators=`` of :func:`fit`: the operator's switch
/// time and load cap and the cell's operators `M`
/// (`tandem_schedule::SamplerParams::{switch_s, max_busy_share, operators}`, the one source of
/// all three), checked: a `ParamError` naming the one out of range.
fn apply_operator(
    params: &mut PlannerParams,
    switch_s: Option<f64>,
    max_busy_share: Option<f64>,
    operators: Option<usize>,
) -> Result<()> {
    if let Some(d) = switch_s {
        params.sampler.switch_s = d;
    }
    if let Some(u) = max_busy_share {
        params.sampler.max_busy_share = u;
    }
    if let Some(m) = operators {
        params.sampler.operators = m;
    }
    params.sampler.validate()?;
    Ok(())
}

/// ``rate_term=`` of :func:`fit` and :func:`fit_model`: the fit's rate term
/// (`tandem_lfd::RateTerm`'s spelling), a `ParamError` naming `rate_term` and the choices.
fn apply_rate_term(params: &mut PlannerParams, rate_term: Option<&str>) -> Result<()> {
    if let Some(text) = rate_term {
        params.fit.rate_term = text.parse::<RateTerm>().map_err(|e| Error::Param {
            what: "rate_term".into(),
            why: match e {
                errors::Lfd::BadParam { why, .. } => why,
                other => other.to_string(),
            },
        })?;
    }
    Ok(())
}

/// The task model alone (alignment and statistics, §II-B1/2), without confidence or
/// schedule: as :func:`fit` but returns a :class:`Model`. ``params`` takes the same form as
/// :func:`fit`'s; only its ``"fit"`` block is used; ``rate_term`` and ``resample`` as
/// :func:`fit`'s.
#[pyfunction]
#[pyo3(signature = (demos, channels=None, params=None, dt_s=None, rate_term=None, resample=false))]
pub(crate) fn fit_model(
    py: Python<'_>,
    demos: &Bound<'_, PyAny>,
    channels: Option<Vec<String>>,
    params: Option<&Bound<'_, PyAny>>,
    dt_s: Option<f64>,
    rate_term: Option<String>,
    resample: bool,
) -> PyResult<PyModel> {
    let mut params = planner_params(params)?;
    apply_rate_term(&mut params, rate_term.as_deref())?;
    let demos =
        demonstrations(demos, channels.as_deref(), dt_s, resample, &mut params)?.warned(py)?;
    let model = py.detach(|| guard(|| Ok(TaskModel::fit(&demos, &params.fit)?)))?;
    Ok(PyModel {
        source: ModelSource::Owned(Arc::new(model)),
    })
}

/// The default parameters as a nested dict (``{"fit": …, "confidence": …, "sampler": …}``,
/// the command line's ``tandem params``).
#[pyfunction]
pub(crate) fn default_params(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    serialize_to_py(py, &PlannerParams::default())
}

/// The loop of the paper's Fig. 2: the task model, the correction observations, the
/// latched confidence and the current schedule, updated after every round of executions
/// (one execution of each robot).
///
/// Make one with :func:`fit` or :meth:`Planner.load`. The state file is the command line's:
/// a file saved here opens with ``tandem inspect``/``record``/``schedule`` and vice versa.
#[pyclass(module = "tandem", name = "Planner")]
pub(crate) struct PyPlanner {
    pub(crate) inner: Planner,
}

/// Robot `i`'s execution record of a round from its four Python arguments (the execution as
/// a path or array with `names`, its reference-time log, its `supervised` and `corrected`
/// flags), at sample period `dt_s` (s) when the execution carries none; with `resample` an
/// irregular `t` column is put on an even grid first, the log and flags with it (a
/// `DataWarning` says so). Shared by `Planner.record_round` and `CellPlanner.record_round`.
pub(crate) fn execution_record(
    py: Python<'_>,
    i: usize,
    [exec, log, sup, cor]: [&Bound<'_, PyAny>; 4],
    names: Channels<'_>,
    dt_s: f64,
    resample: bool,
) -> PyResult<ExecutionRecord> {
    if resample {
        let label = format!("executions[{i}]");
        let grid = regridded_execution(exec, &label, names, None)?;
        warn(
            py,
            &format!(
                "{}; its log and flags put on the same grid (log interpolated, a sample \
                 supervised where the nearest row was, corrected where any row of its \
                 period was)",
                grid.note
            ),
        )?;
        let per_row = "one entry per row of the execution file";
        let log = vector(log, &format!("ref_time_logs[{i}]"), per_row)?;
        let sup = flags(sup, &format!("supervised[{i}]"), per_row)?;
        let cor = flags(cor, &format!("corrected[{i}]"), per_row)?;
        return Ok(ExecutionRecord::from_regridded(grid, &log, &sup, &cor).map_err(Error::from)?);
    }
    let demonstration = demonstration(exec, &format!("executions[{i}]"), names, Some(dt_s), None)?;
    if let Some(note) = demonstration.period_note() {
        warn(py, &note)?;
    }
    let ref_time_log = vector(
        log,
        &format!("ref_time_logs[{i}]"),
        "one reference time per executed sample",
    )?;
    Ok(ExecutionRecord {
        execution: Execution {
            demonstration,
            ref_time_log,
        },
        supervised: flags(
            sup,
            &format!("supervised[{i}]"),
            "one flag per executed sample",
        )?,
        corrected: flags(
            cor,
            &format!("corrected[{i}]"),
            "one flag per executed sample",
        )?,
    })
}

/// Per-robot arguments of `record_round`, checked to have one entry per robot (`n`).
pub(crate) fn per_robot<'py>(
    x: &Bound<'py, PyAny>,
    what: &str,
    n: usize,
) -> Result<Vec<Bound<'py, PyAny>>> {
    let v = items(x, what)?;
    if v.len() != n {
        return Err(Error::input(
            what,
            format!(
                "{} entries; give one per robot ({n} robots: robot 1 first)",
                v.len()
            ),
        ));
    }
    Ok(v)
}

/// The report of a recorded round as a dict.
pub(crate) fn report_dict<'py>(py: Python<'py>, r: &RecordReport) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("newly_high", r.newly_high)?;
    d.set_item("reopened", r.reopened)?;
    d.set_item("source", crate::schedule::source_name(r.source))?;
    d.set_item("t_total_s", r.t_total_s)?;
    d.set_item("model_update_s", r.model_update.as_secs_f64())?;
    d.set_item("confidence_s", r.confidence.as_secs_f64())?;
    d.set_item("scheduling_s", r.scheduling.as_secs_f64())?;
    d.set_item("notices", r.notices.clone())?;
    Ok(d)
}

#[pymethods]
impl PyPlanner {
    /// Loads a planner from a state file written by :meth:`save` or by the command line.
    /// Reading takes no lock (saves are atomic); the planner remembers the file's content,
    /// so :meth:`save` into the same file refuses to overwrite what another process saved
    /// into it meanwhile.
    ///
    /// A stored schedule that fails this build's check (every constraint of Eq. 20 with the
    /// margin check) is never run: it is replaced by a fresh schedule, with a ``DataWarning``
    /// that says why (the file changes only when the planner is saved).
    ///
    /// Raises:
    ///     StateFileError: the file is missing, not a state file, of another format version,
    ///         truncated or corrupt (``path`` names it).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<PyPlanner> {
        let inner = py.detach(|| guard(|| Ok(Planner::load(&path)?)))?;
        warn_load_notice(py, &path, &inner)?;
        Ok(PyPlanner { inner })
    }

    /// A read–modify–write of the state file ``path`` under its lock (the lock
    /// ``tandem record`` takes): ``with tandem.Planner.locked(path) as planner: ...`` waits
    /// up to ``timeout_s`` seconds (default 60) for another writer, loads the planner, and
    /// saves it when the block ends without an exception (nothing is saved otherwise); the
    /// lock is held throughout, so no other writer can record in between.
    ///
    /// Raises:
    ///     StateFileError: the lock is still held by another writer after ``timeout_s``, or
    ///         the file cannot be loaded or saved (``path`` names it).
    #[staticmethod]
    #[pyo3(signature = (path, timeout_s=None))]
    fn locked(path: PathBuf, timeout_s: Option<f64>) -> PyResult<PyStateEdit> {
        Ok(PyStateEdit {
            path,
            timeout: lock_timeout(timeout_s)?,
            lock: None,
            planner: None,
        })
    }

    /// Saves the planner to ``path`` atomically (temporary file with a name of its own,
    /// fsync, rename) under the file's lock, waiting up to ``timeout_s`` seconds (default
    /// 60) for another writer: on error or a crash the previous file at ``path`` is intact.
    /// Refuses to replace a file that is not a state file, and, when this planner was loaded
    /// from (or saved to) ``path``, a file another process saved into since.
    ///
    /// Recorded rounds are never discarded without consent: a state file at ``path`` that
    /// holds rounds this planner does not hold (a fresh :func:`fit` saved over a cell's
    /// state, or a planner loaded from another file) is refused unless ``force=True``, which
    /// replaces it and warns (``DataWarning``) how many rounds went; to keep them, refit with
    /// :meth:`refit` on the planner loaded from it.
    ///
    /// Raises:
    ///     StateFileError: the file cannot be written, is not a state file, changed since the
    ///         load, holds rounds this planner does not (without ``force``), or stays locked
    ///         (``path`` names it).
    #[pyo3(signature = (path, timeout_s=None, force=false))]
    fn save(
        &self,
        py: Python<'_>,
        path: PathBuf,
        timeout_s: Option<f64>,
        force: bool,
    ) -> PyResult<()> {
        let timeout = lock_timeout(timeout_s)?;
        let inner = &self.inner;
        let discarded = py.detach(|| {
            guard(|| {
                let lock = StateLock::acquire(&path, timeout)?;
                if force {
                    Ok(inner.save_locked_discarding(&lock)?)
                } else {
                    inner.save_locked(&lock)?;
                    Ok(Some(0))
                }
            })
        })?;
        match discarded {
            Some(0) => Ok(()),
            Some(n) => crate::errors::warn(
                py,
                &format!(
                    "{}: replaced, discarding its {n} recorded round(s) (force=True)",
                    path.display()
                ),
            ),
            None => crate::errors::warn(
                py,
                &format!(
                    "{}: replaced a state file this build cannot read (force=True)",
                    path.display()
                ),
            ),
        }
    }

    /// Fits the task again from ``demos`` (as :func:`fit`, for this planner's robot count)
    /// and replays every round this planner recorded onto the new fit, in their order: the
    /// operator's corrections are kept. Each execution keeps its samples and flags; its
    /// reference-time log is carried onto the new reference (kept as recorded when the
    /// reference is the same, else through the alignment of the old reference to the new
    /// one), then the rounds are recorded as :meth:`record_round` would. Returns the new
    /// planner; this one is unchanged. The new planner saves into the file this one was
    /// loaded from (``save(path)``, no ``force`` needed). ``resample`` as :func:`fit`'s.
    ///
    /// Raises:
    ///     InputError: a bad demonstration.
    ///     ParamError: a bad parameter or hold.
    ///     StateFileError: the rounds cannot be replayed (recorded by a tandem older than
    ///         state format 11, which did not keep the executions, or refused by the new
    ///         model's checks): keep the old state, or fit and ``save(..., force=True)``.
    #[pyo3(signature = (demos, channels=None, params=None, dt_s=None, holds=None, resample=false))]
    #[expect(
        clippy::too_many_arguments,
        reason = "the keyword arguments of the Python method, documented above"
    )]
    fn refit(
        &self,
        py: Python<'_>,
        demos: &Bound<'_, PyAny>,
        channels: Option<Vec<String>>,
        params: Option<&Bound<'_, PyAny>>,
        dt_s: Option<f64>,
        holds: Option<&Bound<'_, PyAny>>,
        resample: bool,
    ) -> PyResult<PyPlanner> {
        let mut params = planner_params(params)?;
        if let Some(holds) = holds.filter(|h| !h.is_none()) {
            params.holds = hold_spec(holds)?;
            params.validate().map_err(Error::from)?;
        }
        let demos =
            demonstrations(demos, channels.as_deref(), dt_s, resample, &mut params)?.warned(py)?;
        let old = &self.inner;
        let (planner, _) = py.detach(|| guard(|| Ok(old.refit(&demos, params)?)))?;
        Ok(PyPlanner { inner: planner })
    }

    /// Records a round of executions, one per robot (robot 1 first), and re-schedules (Eq. 21,
    /// Eq. 9–12, §II-C).
    ///
    /// Adds every execution to the model with their reference-time logs (no re-alignment),
    /// their supervised samples to the observations, updates the latched confidence and
    /// samples a new schedule warm-started by the current one. Everything is checked first:
    /// on error the planner is as before.
    ///
    /// Args:
    ///     executions: per robot, the executed samples: a ``(T_k, C)`` float array in the
    ///         model's channels (or ``channels``) or a CSV/JSON path.
    ///     ref_time_logs: per robot, a ``(T_k,)`` float array: the fractional reference
    ///         sample of each executed sample (monotone, in ``[0, T_ref − 1]``).
    ///     supervised: per robot, a ``(T_k,)`` bool array: the sample ran low-confidence,
    ///         with the operator watching.
    ///     corrected: per robot, a ``(T_k,)`` bool array: the operator corrected the sample
    ///         (only read where supervised).
    ///     channels: column names of the arrays (default: the model's channels).
    ///     dt_s: sample period (s) of the arrays and of files without a ``t`` column
    ///         (default: the control tick of the current schedule, ``schedule.tick_s``: one
    ///         sample per tick of the schedule the round ran). A log finer than the model's
    ///         ``Δt_s`` is resampled to it (a ``DataWarning`` says so); a coarser one is
    ///         refused.
    ///     resample: put executions given as CSV files with an irregular ``t`` column
    ///         (jitter beyond a quarter period, dropped samples) on the even grid of their
    ///         logger's period first, as ``tandem record --resample`` does: the log and flags
    ///         (one entry per row of the file) follow, the log interpolated, a sample
    ///         supervised where the nearest row was, corrected where any row of its period
    ///         was; a ``DataWarning`` says what was done. Arrays have no times and are
    ///         refused with it. Default: ``False``.
    ///
    /// Every execution must cover the whole task and last no less than half the fastest and
    /// no more than twice the slowest demonstrated execution (a log taken at another rate
    /// than ``dt_s`` says fails this); the same round recorded twice is refused; a sample
    /// flagged ``corrected`` must be ``supervised`` (the operator corrects only what they
    /// supervise), as ``tandem record`` checks: otherwise ``InputError``.
    ///
    /// Returns:
    ///     dict: ``newly_high`` (samples latched high-confidence), ``reopened`` (latched
    ///     samples this round's corrections turned low-confidence again, e.g. rounds recorded
    ///     out of order), ``source`` of the new
    ///     schedule, its ``t_total_s`` (Eq. 13, s), wall times ``model_update_s``,
    ///     ``confidence_s``, ``scheduling_s``, and ``notices`` (what was resampled).
    #[pyo3(signature = (executions, ref_time_logs, supervised, corrected, channels=None, dt_s=None, resample=false))]
    #[expect(
        clippy::too_many_arguments,
        reason = "the Python signature: one list per robot and three keywords"
    )]
    fn record_round<'py>(
        &mut self,
        py: Python<'py>,
        executions: &Bound<'py, PyAny>,
        ref_time_logs: &Bound<'py, PyAny>,
        supervised: &Bound<'py, PyAny>,
        corrected: &Bound<'py, PyAny>,
        channels: Option<Vec<String>>,
        dt_s: Option<f64>,
        resample: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        if let Some(dt) = dt_s
            && !(dt.is_finite() && dt > 0.0)
        {
            return Err(Error::param("dt_s", format!("{dt} s is not a finite period > 0")).into());
        }
        let dt_s = dt_s.unwrap_or(self.inner.schedule().tick_s);
        let model = self.inner.model();
        let n = self.inner.n_robots();
        // Arrays default to the model's channel order; a file's header may list the
        // channels in any order (the model matches them by name, as `tandem record` does).
        let names = Channels {
            array: Some(channels.as_deref().unwrap_or(model.channel_names())),
            file: channels.as_deref(),
        };
        let (execs, logs, sups, cors) = (
            per_robot(executions, "executions", n)?,
            per_robot(ref_time_logs, "ref_time_logs", n)?,
            per_robot(supervised, "supervised", n)?,
            per_robot(corrected, "corrected", n)?,
        );
        let records = (0..n)
            .map(|i| {
                execution_record(
                    py,
                    i,
                    [&execs[i], &logs[i], &sups[i], &cors[i]],
                    names,
                    dt_s,
                    resample,
                )
            })
            .collect::<PyResult<Vec<_>>>()?;
        let inner = &mut self.inner;
        let report = py.detach(|| guard(|| Ok(inner.record_round(&records)?)))?;
        for note in &report.notices {
            warn(py, note)?;
        }
        report_dict(py, &report)
    }

    /// Deprecated: :meth:`record_round` under its two-robot name (the same arguments, one
    /// entry per robot); emits a ``DeprecationWarning``. Kept for one release.
    #[pyo3(signature = (executions, ref_time_logs, supervised, corrected, channels=None, dt_s=None))]
    #[expect(
        clippy::too_many_arguments,
        reason = "the Python signature: one list per robot and two keywords"
    )]
    fn record_pair<'py>(
        &mut self,
        py: Python<'py>,
        executions: &Bound<'py, PyAny>,
        ref_time_logs: &Bound<'py, PyAny>,
        supervised: &Bound<'py, PyAny>,
        corrected: &Bound<'py, PyAny>,
        channels: Option<Vec<String>>,
        dt_s: Option<f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        deprecated(
            py,
            "Planner.record_pair is deprecated: use Planner.record_round (a round is one \
             execution of each robot)",
        )?;
        self.record_round(
            py,
            executions,
            ref_time_logs,
            supervised,
            corrected,
            channels,
            dt_s,
            false,
        )
    }

    /// Re-runs the anytime sampler (§II-C) on the current problem, warm-started by the
    /// current schedule, and keeps the result (``T_total`` never increases at the same
    /// tick). Model, observations, confidence and parameters are unchanged, but for the
    /// operator's ``switch_s`` and ``max_busy_share`` and the cell's ``operators`` when given
    /// (``tandem schedule --switch-s/--max-busy/--operators --save``): they become the
    /// planner's (``params()["sampler"]``, stored by :meth:`save`, honoured by every later
    /// schedule).
    ///
    /// Args:
    ///     samples: candidates to sample (default: the parameters').
    ///     seed: the sampler's seed (default: the stream ``tandem schedule`` uses without
    ///         ``--seed``, so both give the same schedule for the same state).
    ///     tick_s: control tick (real s) the margins are checked at and the schedule runs at
    ///         (default: the current schedule's tick). Later :meth:`record_round` calls keep
    ///         the tick chosen here.
    ///     switch_s: the operator's switch time ``δ`` (s, finite and ≥ 0) from now on
    ///         (default: the planner's, ``params()["sampler"]["switch_s"]``).
    ///     max_busy_share: the operator's load cap ``u_max`` in ``(0, 1]`` from now on
    ///         (default: the planner's).
    ///     operators: the cell's operators ``M``, 1 to 16, from now on (issue 44; default: the
    ///         planner's): rounds then run :meth:`sectored_rounds`, a continuous cell ``M``
    ///         tokens (:meth:`controller`). The schedule itself is the one-operator schedule of
    ///         all robots (the state file's).
    ///
    /// Returns:
    ///     Schedule: the new current schedule.
    ///
    /// Raises:
    ///     ParamError: a ``switch_s``, ``max_busy_share`` or ``operators`` out of range
    ///         (``name`` names it; the planner is unchanged).
    #[pyo3(signature = (samples=None, seed=None, tick_s=None, switch_s=None, max_busy_share=None, operators=None))]
    #[expect(
        clippy::too_many_arguments,
        reason = "the keyword arguments of the Python method, each documented above"
    )]
    fn reschedule(
        &mut self,
        py: Python<'_>,
        samples: Option<usize>,
        seed: Option<u64>,
        tick_s: Option<f64>,
        switch_s: Option<f64>,
        max_busy_share: Option<f64>,
        operators: Option<usize>,
    ) -> PyResult<PySchedule> {
        let now = &self.inner.params().sampler;
        let before = (now.switch_s, now.max_busy_share, now.operators);
        if switch_s.is_some() || max_busy_share.is_some() {
            let (d, u) = (
                switch_s.unwrap_or(before.0),
                max_busy_share.unwrap_or(before.1),
            );
            self.inner.set_operator(d, u).map_err(Error::from)?;
        }
        if let Some(m) = operators
            && let Err(e) = self.inner.set_operators(m)
        {
            self.inner
                .set_operator(before.0, before.1)
                .map_err(Error::from)?;
            return Err(Error::from(e).into());
        }
        let mut sp = self.inner.params().sampler.clone();
        sp.seed = match seed {
            Some(s) => s,
            // The stream of `tandem schedule` without `--seed` (the planner's one rule).
            None => reschedule_seed(sp.seed, self.inner.rounds_recorded()),
        };
        if let Some(n) = samples {
            sp.samples = n;
        }
        // `None` keeps the current schedule's tick (the planner's rule).
        sp.tick_s = tick_s;
        let inner = &mut self.inner;
        let done = py.detach(|| guard(|| Ok(inner.reschedule(&sp).map(|_| ())?)));
        if done.is_err() {
            // A failed re-schedule leaves the planner as it was: its operator parameters too.
            self.inner
                .set_operator(before.0, before.1)
                .map_err(Error::from)?;
            self.inner.set_operators(before.2).map_err(Error::from)?;
        }
        done?;
        Ok(self.current_schedule())
    }

    /// Declares hold points on this planner in place of its own and re-schedules (Rust
    /// ``Planner::set_holds``): ``holds`` as :func:`fit` takes it (a list of reference times
    /// and rules, or a dict; ``[]`` none). A hold inside a low-confidence stretch that the
    /// recorded corrections show needs the operator is refused, naming the stretch; on error
    /// the planner is unchanged.
    ///
    /// Returns:
    ///     Schedule: the new current schedule.
    ///
    /// Raises:
    ///     ParamError: a malformed hold, a time outside the task, an unknown channel, a rule
    ///         that holds nowhere, or a hold where the operator corrected.
    fn set_holds(&mut self, py: Python<'_>, holds: &Bound<'_, PyAny>) -> PyResult<PySchedule> {
        let spec = hold_spec(holds)?;
        let inner = &mut self.inner;
        py.detach(|| guard(|| Ok(inner.set_holds(spec).map(|_| ())?)))?;
        Ok(self.current_schedule())
    }

    /// The plan of this planner's ``cell`` on the current problem (Rust ``Planner::plan``):
    /// ``"rounds"`` (default) the current :class:`Schedule` (checked on the problem), or
    /// ``"continuous"`` the :class:`CyclicPlan` of a continuous cell (no rounds: each robot
    /// repeating the task, one period per task), the token rule's hand-overs counted at the
    /// current schedule's control tick, the cell's tick (:attr:`CyclicPlan.tick_s`), so its
    /// period is what the cell does with the planned operator. Both kinds of cell run at that
    /// one tick. A snapshot, computed now (``tandem schedule --cell continuous`` shows the same
    /// plan); it does not change the planner, whose schedule stays the rounds one it records
    /// from.
    ///
    /// Raises:
    ///     ParamError: a ``cell`` other than ``"rounds"`` or ``"continuous"`` (``name`` is
    ///         ``"cell"``).
    ///     ScheduleError: a current schedule that fails this build's check (never for a
    ///         planner made by :func:`fit` or :meth:`load`).
    #[pyo3(signature = (cell="rounds"))]
    fn plan(&self, py: Python<'_>, cell: &str) -> PyResult<Py<PyAny>> {
        let cell = parse_cell(cell)?;
        let inner = &self.inner;
        let plan = py.detach(|| guard(|| Ok(inner.plan(cell)?)))?;
        Ok(match plan {
            Plan::Rounds(_) => Py::new(py, self.current_schedule())?.into_any(),
            Plan::Continuous(c) => Py::new(py, crate::cyclic::PyCyclicPlan::checked(c))?.into_any(),
        })
    }

    /// The run-time coordinator of :meth:`plan` (Rust ``Planner::controller``): for
    /// ``"rounds"`` (default) a :class:`Coordinator` of the current schedule, for
    /// ``"continuous"`` a :class:`ContinuousCoordinator` of the cyclic plan; both at the
    /// current schedule's control tick, every robot at its start. A snapshot: it does not
    /// follow the planner. With ``params()["sampler"]["operators"] = M > 1`` (issue 44) the
    /// rounds coordinator runs :meth:`sectored_rounds` and the continuous one ``M`` tokens;
    /// either takes a list of ``M`` inputs per tick.
    ///
    /// Raises:
    ///     ParamError: a ``cell`` other than ``"rounds"`` or ``"continuous"``.
    #[pyo3(signature = (cell="rounds"))]
    fn controller(&self, py: Python<'_>, cell: &str) -> PyResult<Py<PyAny>> {
        let cell = parse_cell(cell)?;
        let inner = &self.inner;
        let controller = py.detach(|| guard(|| Ok(inner.controller(cell)?)))?;
        Ok(match controller {
            AnyController::Rounds(c) => {
                Py::new(py, crate::coordinator::PyCoordinator::from_inner(c))?.into_any()
            }
            AnyController::Continuous(c) => Py::new(
                py,
                crate::continuous::PyContinuousCoordinator::from_inner(c),
            )?
            .into_any(),
        })
    }

    /// The plan of a continuous cell on the current problem for this planner's robots:
    /// :meth:`plan` ``(cell="continuous")``, with ``max_enumerated`` (default 100 000):
    /// search every operator order while there are at most this many.
    ///
    /// Raises:
    ///     ParamError: ``max_enumerated`` 0.
    #[pyo3(signature = (max_enumerated=None))]
    fn cyclic_plan(
        &self,
        py: Python<'_>,
        max_enumerated: Option<u64>,
    ) -> PyResult<crate::cyclic::PyCyclicPlan> {
        let params = crate::cyclic::params(max_enumerated, true, None);
        let inner = &self.inner;
        let plan = py.detach(|| guard(|| Ok(inner.cyclic_plan(&params, None)?)))?;
        Ok(crate::cyclic::PyCyclicPlan::checked(plan))
    }

    /// The continuous coordinator of this planner's cell: :meth:`cyclic_plan` (with
    /// ``max_enumerated``) run on the current problem at a control tick of ``tick_s`` real
    /// seconds (default: the current schedule's ``tick_s``, the cell's control tick; the
    /// plan's hand-overs are counted at it): :meth:`controller` ``(cell="continuous")`` when
    /// both are left to their defaults. A snapshot: it does not change the planner and does
    /// not follow it.
    ///
    /// Raises:
    ///     ParamError: ``max_enumerated`` 0, or ``tick_s`` not finite and > 0.
    #[pyo3(signature = (max_enumerated=None, tick_s=None))]
    fn continuous_coordinator(
        &self,
        py: Python<'_>,
        max_enumerated: Option<u64>,
        tick_s: Option<f64>,
    ) -> PyResult<crate::continuous::PyContinuousCoordinator> {
        let params = crate::cyclic::params(max_enumerated, true, None);
        let inner = &self.inner;
        let plan = py.detach(|| guard(|| Ok(inner.cyclic_plan(&params, tick_s)?)))?;
        Ok(crate::continuous::PyContinuousCoordinator::from_inner(
            plan.coordinator(),
        ))
    }

    /// The round of ``M = params()["sampler"]["operators"]`` operators (issue 44; Rust
    /// ``Planner::sectored_rounds``, what :meth:`controller` runs in rounds with ``M > 1``):
    /// the robots in contiguous sectors, each sector a one-operator round of its own schedule
    /// run by its own operator. A dict ``{"sizes": [int], "sector_of": [int],
    /// "t_total_s": float, "lower_bound_s": float}``: robots per sector, each robot's sector
    /// (its operator), the round's ``T_total`` (s, Eq. 13: the slowest sector's) and the bound
    /// no round of ``M`` operators beats (s, ``max(a_0 + N·ΣL/M + a_m, D_min)``). A snapshot,
    /// computed now; the planner keeps its one-operator schedule.
    ///
    /// Raises:
    ///     ScheduleError: a current schedule that fails this build's check.
    fn sectored_rounds<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let inner = &self.inner;
        let (s, _) = py.detach(|| guard(|| Ok(inner.sectored_rounds()?)))?;
        let d = PyDict::new(py);
        d.set_item("sizes", s.sizes.clone())?;
        d.set_item("sector_of", s.sector_of())?;
        d.set_item("t_total_s", s.t_total_s)?;
        d.set_item("lower_bound_s", s.lower_bound_s)?;
        Ok(d)
    }

    /// The current schedule (a snapshot: it does not change when the planner does).
    #[getter]
    fn schedule(&self) -> PySchedule {
        self.current_schedule()
    }

    /// The current scheduling problem (confidence and gradient bounds per reference sample).
    #[getter]
    fn problem(&self) -> PyProblem {
        PyProblem::new(Arc::new(self.inner.problem().clone()))
    }

    /// The task model (a live view: it follows the planner).
    #[getter]
    fn model(slf: Py<Self>) -> PyModel {
        PyModel {
            source: ModelSource::Planner(slf),
        }
    }

    /// The latched confidence and the observations (a live view).
    #[getter]
    fn confidence(slf: Py<Self>) -> PyConfidence {
        PyConfidence { planner: slf }
    }

    /// The parameters as a nested dict.
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let params = serialize_to_py(py, self.inner.params())?;
        // `sampler.operators` is left out of the serialized parameters when it is 1 (so that
        // files and reports of one operator stay as they were); Python always shows it.
        let sampler = params.get_item("sampler")?;
        if !sampler.contains("operators")? {
            sampler.set_item("operators", self.inner.params().sampler.operators)?;
        }
        Ok(params)
    }

    /// Rounds recorded so far (a round is one execution of each robot).
    #[getter]
    fn rounds_recorded(&self) -> usize {
        self.inner.rounds_recorded()
    }

    /// Deprecated: :attr:`rounds_recorded` under its two-robot name; emits a
    /// ``DeprecationWarning``. Kept for one release.
    #[getter]
    fn pairs_recorded(&self, py: Python<'_>) -> PyResult<usize> {
        deprecated(
            py,
            "Planner.pairs_recorded is deprecated: use Planner.rounds_recorded",
        )?;
        Ok(self.inner.rounds_recorded())
    }

    /// Number of robots the planner schedules.
    #[getter]
    fn n_robots(&self) -> usize {
        self.inner.n_robots()
    }

    /// The command ``x_f⁺(u, t) = μ̂⁺(t) + δx⁺(u, t)`` (Eq. 7) at fractional reference time
    /// ``ref_time`` (reference samples) for joystick input ``u`` in ``[−1, 1]^K``
    /// (``None``: no correction). Returns a ``(C + 1,)`` array: the ``C`` channel values
    /// (channel units) then the rate, the warp gradient in ``[ψ̇min, ψ̇max]`` (demo samples
    /// per reference sample) that the coordinator takes as the operator's gradient.
    #[pyo3(signature = (ref_time, u=None))]
    fn command<'py>(
        &self,
        py: Python<'py>,
        ref_time: f64,
        u: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        command(py, self.inner.model(), ref_time, u)
    }

    fn __repr__(&self) -> String {
        let m = self.inner.model();
        format!(
            "Planner(n_ref={}, channels={}, rounds_recorded={}, high_share={:.3}, t_total_s={:.3})",
            m.n_ref(),
            repr_list(m.channel_names()),
            self.inner.rounds_recorded(),
            self.inner.confidence().high_share(),
            self.inner.outcome().t_total_s
        )
    }
}

/// Warns (``DataWarning``) when loading replaced the stored schedule because it failed this
/// build's check (see `Planner::load_notice`).
fn warn_load_notice(py: Python<'_>, path: &std::path::Path, planner: &Planner) -> PyResult<()> {
    match planner.load_notice() {
        Some(notice) => crate::errors::warn(py, &format!("{}: {notice}", path.display())),
        None => Ok(()),
    }
}

/// A read–modify–write of a state file under its lock: what :meth:`Planner.locked`
/// returns, a context manager (``with ... as planner:``).
#[pyclass(module = "tandem", name = "StateEdit")]
pub(crate) struct PyStateEdit {
    path: PathBuf,
    timeout: Duration,
    lock: Option<StateLock>,
    planner: Option<Py<PyPlanner>>,
}

#[pymethods]
impl PyStateEdit {
    /// Takes the lock (waiting up to the timeout) and loads the planner.
    fn __enter__(&mut self, py: Python<'_>) -> PyResult<Py<PyPlanner>> {
        if self.lock.is_some() {
            return Err(Error::input("locked", "this block is already open").into());
        }
        let (path, timeout) = (self.path.clone(), self.timeout);
        let (lock, inner) = py.detach(|| {
            guard(|| {
                let lock = StateLock::acquire(&path, timeout)?;
                let inner = Planner::load(&path)?;
                Ok((lock, inner))
            })
        })?;
        warn_load_notice(py, &path, &inner)?;
        let planner = Py::new(py, PyPlanner { inner })?;
        self.lock = Some(lock);
        self.planner = Some(planner.clone_ref(py));
        Ok(planner)
    }

    /// Saves the planner if the block raised nothing, then releases the lock. Never
    /// swallows the block's exception.
    fn __exit__(
        &mut self,
        py: Python<'_>,
        exc_type: Option<&Bound<'_, PyAny>>,
        _exc: Option<&Bound<'_, PyAny>>,
        _tb: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<bool> {
        let (lock, planner) = (self.lock.take(), self.planner.take());
        if let (Some(lock), Some(planner), None) = (&lock, &planner, exc_type) {
            let p = planner.bind(py).try_borrow()?;
            let inner = &p.inner;
            py.detach(|| guard(|| Ok(inner.save_locked(lock)?)))?;
        }
        drop(lock);
        Ok(false)
    }

    fn __repr__(&self) -> String {
        format!(
            "StateEdit(path={:?}, locked={})",
            self.path.display().to_string(),
            self.lock.is_some()
        )
    }
}

impl PyPlanner {
    fn current_schedule(&self) -> PySchedule {
        let sp = &self.inner.params().sampler;
        PySchedule::from_outcome(Arc::new(self.inner.problem().clone()), self.inner.outcome())
            .with_operator(sp.switch_s, sp.max_busy_share)
    }
}

/// A cell kind from Python (`"rounds"` or `"continuous"`, the planner's `Cell` names); a
/// `ParamError` naming `cell` otherwise.
fn parse_cell(cell: &str) -> Result<Cell> {
    Ok(cell.parse::<Cell>()?)
}

/// Eq. 7 on `model`; `u = None` is no correction.
fn command<'py>(
    py: Python<'py>,
    model: &TaskModel,
    ref_time: f64,
    u: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let u = match u.filter(|u| !u.is_none()) {
        Some(u) => vector(u, "u", "one input per correction component")?,
        None => vec![0.0; model.n_components()],
    };
    let cmd = guard(|| Ok(model.command(&u, ref_time)?))?;
    Ok(out_vector(py, cmd))
}

/// Where a [`PyModel`] reads its model.
enum ModelSource {
    /// The planner's current model.
    Planner(Py<PyPlanner>),
    /// A model of its own (from `fit_model`).
    Owned(Arc<TaskModel>),
}

/// The task model (§II-B1/2): per reference sample ``n`` (period ``dt_s``) the mean
/// behaviour, the demonstration variance, the warp-gradient bounds and the correction
/// directions.
#[pyclass(module = "tandem", name = "Model", frozen)]
pub(crate) struct PyModel {
    source: ModelSource,
}

impl PyModel {
    fn with<R>(&self, py: Python<'_>, f: impl FnOnce(&TaskModel) -> R) -> PyResult<R> {
        match &self.source {
            ModelSource::Planner(p) => Ok(f(p.bind(py).try_borrow()?.inner.model())),
            ModelSource::Owned(m) => Ok(f(m)),
        }
    }
}

#[pymethods]
impl PyModel {
    /// Channel names ``C``, in column order.
    #[getter]
    fn channels(&self, py: Python<'_>) -> PyResult<Vec<String>> {
        self.with(py, |m| m.channel_names().to_vec())
    }

    /// Names of the ``d`` tangent coordinates (scalar channels, ``<block>.rx/ry/rz`` per
    /// quaternion block, then ``rate``): the columns of :meth:`corrections_at`.
    #[getter]
    fn tangent_names(&self, py: Python<'_>) -> PyResult<Vec<String>> {
        self.with(py, |m| m.tangent_names().to_vec())
    }

    /// ``T_ref``: reference samples (the length of every per-sample array).
    #[getter]
    fn n_ref(&self, py: Python<'_>) -> PyResult<usize> {
        self.with(py, TaskModel::n_ref)
    }

    /// Reference sample period ``Δt_s`` (s).
    #[getter]
    fn dt_s(&self, py: Python<'_>) -> PyResult<f64> {
        self.with(py, TaskModel::dt_s)
    }

    /// Index of the reference demonstration among those given to the fit.
    #[getter]
    fn reference_idx(&self, py: Python<'_>) -> PyResult<usize> {
        self.with(py, TaskModel::reference_idx)
    }

    /// Demonstrations and executions in the statistics.
    #[getter]
    fn count(&self, py: Python<'_>) -> PyResult<usize> {
        self.with(py, TaskModel::count)
    }

    /// Correction components ``K = min(n − 1, k_max, d)``: the length of ``u``.
    #[getter]
    fn n_components(&self, py: Python<'_>) -> PyResult<usize> {
        self.with(py, TaskModel::n_components)
    }

    /// Mean behaviour ``μ̂(n)``, shape ``(T_ref, C)``, channel units (quaternions unit-norm).
    #[getter]
    fn mean<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (v, c) = self.with(py, |m| (m.mean().to_vec(), m.channel_names().len()))?;
        Ok(out_matrix(py, v, c)?)
    }

    /// Demonstration variance ``σ²_D(n)`` (Eq. 6), shape ``(T_ref,)``, dimensionless
    /// (weighted by ``W⁺ = diag(1/r²)``).
    #[getter]
    fn sigma2_d<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(out_vector(py, self.with(py, |m| m.sigma2_d().to_vec())?))
    }

    /// Mean warp gradient ``ψ̄̇_D(n)`` (Eq. 5), shape ``(T_ref,)``, demo samples per
    /// reference sample.
    #[getter]
    fn grad_mean<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(out_vector(py, self.with(py, |m| m.grad_mean().to_vec())?))
    }

    /// Minimum warp gradient ``ψ̇min(n)`` (Eq. 14, the fastest), shape ``(T_ref,)``.
    #[getter]
    fn grad_min<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(out_vector(py, self.with(py, |m| m.grad_min().to_vec())?))
    }

    /// Maximum warp gradient ``ψ̇max(n)`` (Eq. 14, the slowest), shape ``(T_ref,)``.
    #[getter]
    fn grad_max<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(out_vector(py, self.with(py, |m| m.grad_max().to_vec())?))
    }

    /// Ranges ``r_j`` of the tangent coordinates, shape ``(d,)``; ``W⁺ = diag(1/r²)``.
    #[getter]
    fn ranges<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(out_vector(py, self.with(py, |m| m.ranges().to_vec())?))
    }

    /// The admissible corrections at fractional reference time ``ref_time``: ``(scale,
    /// components)`` with ``components`` of shape ``(K, d)`` (±3σ displacements in the
    /// tangent coordinates) and ``scale`` in ``[0, 1]`` keeping the rate within bounds for
    /// every ``u`` in ``[−1, 1]^K`` (§II-B2).
    fn corrections_at<'py>(
        &self,
        py: Python<'py>,
        ref_time: f64,
    ) -> PyResult<(f64, Bound<'py, PyArray2<f64>>)> {
        let (c, d) = self.with(py, |m| {
            (
                guard(|| Ok(m.corrections_at(ref_time)?)),
                m.tangent_names().len(),
            )
        })?;
        let c = c?;
        let flat: Vec<f64> = c.components.concat();
        Ok((c.scale, out_matrix(py, flat, d)?))
    }

    /// The command of Eq. 7 (see :meth:`Planner.command`).
    #[pyo3(signature = (ref_time, u=None))]
    fn command<'py>(
        &self,
        py: Python<'py>,
        ref_time: f64,
        u: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        match &self.source {
            ModelSource::Planner(p) => {
                command(py, p.bind(py).try_borrow()?.inner.model(), ref_time, u)
            }
            ModelSource::Owned(m) => command(py, m, ref_time, u),
        }
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        self.with(py, |m| {
            format!(
                "Model(n_ref={}, dt_s={}, channels={}, count={})",
                m.n_ref(),
                m.dt_s(),
                repr_list(m.channel_names()),
                m.count()
            )
        })
    }
}

/// The latched confidence (Eq. 9–12) of a planner and its observations, per reference
/// sample (a live view of the planner).
#[pyclass(module = "tandem", name = "Confidence", frozen)]
pub(crate) struct PyConfidence {
    planner: Py<PyPlanner>,
}

impl PyConfidence {
    fn with<R>(&self, py: Python<'_>, f: impl FnOnce(&Planner) -> R) -> PyResult<R> {
        Ok(f(&self.planner.bind(py).try_borrow()?.inner))
    }

    /// Prior (Eq. 10–11) or posterior (Eq. 9) Beta parameters per reference sample.
    fn betas(&self, py: Python<'_>, posterior_too: bool) -> PyResult<Vec<BetaParams>> {
        Ok(self.with(py, |p| {
            let (s2, params) = (p.model().sigma2_d(), p.confidence().params());
            guard(|| {
                Ok(if posterior_too {
                    posterior(s2, p.observations(), params)?
                } else {
                    prior(s2, params)?
                })
            })
        })??)
    }

    /// One parameter of [`PyConfidence::betas`] per reference sample, as an array.
    fn beta_column<'py>(
        &self,
        py: Python<'py>,
        posterior_too: bool,
        pick: fn(&BetaParams) -> f64,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let betas = self.betas(py, posterior_too)?;
        Ok(out_vector(py, betas.iter().map(pick).collect()))
    }
}

#[pymethods]
impl PyConfidence {
    /// ``conf(n)`` (Eq. 12, latched), shape ``(T_ref,)`` bool: ``True`` = high confidence
    /// (no supervision needed). A sample that became high-confidence stays so.
    #[getter]
    fn high<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<bool>>> {
        Ok(out_flags(
            py,
            self.with(py, |p| p.confidence().conf().to_vec())?,
        ))
    }

    /// High-confidence reference samples.
    #[getter]
    fn n_high(&self, py: Python<'_>) -> PyResult<usize> {
        self.with(py, |p| p.confidence().n_high())
    }

    /// Share of high-confidence reference samples, in ``[0, 1]``.
    #[getter]
    fn high_share(&self, py: Python<'_>) -> PyResult<f64> {
        self.with(py, |p| p.confidence().high_share())
    }

    /// Maximal low-confidence runs of reference samples, shape ``(k, 2)`` int64,
    /// ``[start, end)``.
    #[getter]
    fn low_regions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let flat: Vec<i64> = self.with(py, |p| {
            p.confidence()
                .low_regions()
                .iter()
                .flat_map(|r| [r.start as i64, r.end as i64])
                .collect()
        })?;
        Ok(out_matrix(py, flat, 2)?)
    }

    /// The confidence parameters (``gamma_p``, ``sigma2_max``, ``epsilon``, ``mu_c``,
    /// ``gamma_c``) as a dict.
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let params = self.with(py, |p| p.confidence().params().clone())?;
        serialize_to_py(py, &params)
    }

    /// Prior ``α₀`` per reference sample (Eq. 10–11 from the current ``σ²_D``), ``(T_ref,)``.
    #[getter]
    fn prior_alpha<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.beta_column(py, false, BetaParams::alpha)
    }

    /// Prior ``β₀`` per reference sample (Eq. 10–11), ``(T_ref,)``.
    #[getter]
    fn prior_beta<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.beta_column(py, false, BetaParams::beta)
    }

    /// Posterior ``α = α₀ + corrections`` per reference sample (Eq. 9), ``(T_ref,)``.
    #[getter]
    fn posterior_alpha<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.beta_column(py, true, BetaParams::alpha)
    }

    /// Posterior ``β = β₀ + supervised − corrections`` per reference sample (Eq. 9),
    /// ``(T_ref,)``.
    #[getter]
    fn posterior_beta<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.beta_column(py, true, BetaParams::beta)
    }

    /// ``P(π < μ_c | data)`` per reference sample, the left side of Eq. 12 for the
    /// posterior, ``(T_ref,)``: ``I_μ'c(α, β)`` at ``μ'_c = f + (1 − f − m)·μ_c`` with the
    /// operator's error rates ``f``, ``m`` (``I_μc(α, β)``, the paper's, when both are 0).
    /// A sample is newly high-confidence when it exceeds ``γ_c``; latched samples stay high
    /// whatever it says now.
    #[getter]
    fn p_below_mu_c<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let values = self.with(py, |p| {
            guard(|| {
                Ok(prob_need_below_mu_c(
                    p.model().sigma2_d(),
                    p.observations(),
                    p.confidence().params(),
                )?)
            })
        })??;
        Ok(out_vector(py, values))
    }

    /// The operator's error rates the confidence decides with, a dict
    /// ``{"false_correction_rate": f, "miss_rate": m}`` (per control sample): estimated
    /// from the executions when ``params["estimate_error_rates"]``, else as configured.
    #[getter]
    fn error_rates<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let rates = self.with(py, |p| guard(|| Ok(p.error_rates()?)))??;
        serialize_to_py(py, &rates)
    }

    /// The ``σ²_D`` above which the prior alone is low-confidence, or ``None`` when even 0
    /// is (dimensionless).
    #[getter]
    fn sigma2_d_prior_threshold(&self, py: Python<'_>) -> PyResult<Option<f64>> {
        Ok(self.with(py, |p| {
            guard(|| Ok(prior_low_threshold(p.confidence().params())?))
        })??)
    }

    /// Every low-confidence region with why it is low and what would change it, a list of
    /// dicts in reference order (the records of ``tandem inspect --json``'s
    /// ``confidence.low_regions``): ``ref_start``, ``ref_end``, ``start_s``, ``end_s``,
    /// ``cause`` (``"variance"`` or ``"corrections"``), ``sigma2_d_max``,
    /// ``sigma2_d_prior_threshold``, ``channels`` (name, sigma2, share, range,
    /// range_for_prior), ``supervised``, ``corrections``, ``expected_false_corrections``,
    /// ``clean_executions_needed``.
    fn explain_low_confidence<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let regions = self.with(py, |p| guard(|| Ok(p.explain_low_confidence()?)))??;
        serialize_to_py(py, &regions)
    }

    /// The correction observations (Eq. 9's counts per reference sample).
    #[getter]
    fn observations(&self, py: Python<'_>) -> PyResult<PyObservations> {
        Ok(PyObservations {
            inner: self.with(py, |p| p.observations().clone())?,
        })
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        self.with(py, |p| {
            let c = p.confidence();
            format!(
                "Confidence(n_ref={}, n_high={}, high_share={:.3})",
                c.n_ref(),
                c.n_high(),
                c.high_share()
            )
        })
    }
}

/// Correction observations per reference sample (Eq. 9): fractional counts, each
/// supervised execution sample split linearly between its two neighbouring reference
/// samples. A snapshot.
#[pyclass(module = "tandem", name = "Observations", frozen)]
pub(crate) struct PyObservations {
    inner: Observations,
}

#[pymethods]
impl PyObservations {
    /// Supervised (low-confidence) observations per reference sample, ``(T_ref,)``.
    #[getter]
    fn supervised<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out_vector(py, self.inner.supervised().to_vec())
    }

    /// Corrected observations per reference sample, ``(T_ref,)``, ``≤ supervised``.
    #[getter]
    fn corrections<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out_vector(py, self.inner.corrections().to_vec())
    }

    /// Sum of :attr:`supervised`.
    #[getter]
    fn total_supervised(&self) -> f64 {
        self.inner.total_supervised()
    }

    /// Sum of :attr:`corrections`.
    #[getter]
    fn total_corrections(&self) -> f64 {
        self.inner.total_corrections()
    }

    fn __repr__(&self) -> String {
        format!(
            "Observations(n_ref={}, total_supervised={}, total_corrections={})",
            self.inner.n_ref(),
            self.inner.total_supervised(),
            self.inner.total_corrections()
        )
    }
}
