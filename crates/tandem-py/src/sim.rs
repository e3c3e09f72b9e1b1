//! The simulated workcell of §III for `tandem.sim`: a round of executions, one per robot, run
//! through the schedule's coordinator with a simulated operator (`tandem_sim::workcell`).

use std::path::PathBuf;

use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::arrays::{flag_matrix, out_flags, out_matrix, out_vector};
use crate::errors::{Error, Result, guard};
use crate::facade::{
    NeedProfile, NeedRegion, OperatorParams, RobotCount, RoundRun, TaskParams, Workpiece,
    correction_input, needs_correction, read_labels, reference_labels, run_round_with,
};
use crate::params::from_py;
use crate::planner::{N_ROBOTS, PyPlanner};

/// The run of a round as a dict of arrays (see `sim_run_round`).
fn run_dict<'py>(py: Python<'py>, run: RoundRun, channels: usize) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("ticks", run.ticks)?;
    d.set_item("tick_s", run.tick_s)?;
    d.set_item("overlap_ticks", run.overlap_ticks)?;
    d.set_item("idle_ticks", run.idle_ticks)?;
    d.set_item("duration_s", run.duration_s())?;
    d.set_item("operator_idle_share", run.operator_idle_share())?;
    d.set_item("operator_busy_share", run.operator_busy_share())?;
    d.set_item("robot_wait_share", run.robot_wait_share())?;
    let robots = PyList::empty(py);
    for r in run.robots {
        let rd = PyDict::new(py);
        rd.set_item("samples", out_matrix(py, r.samples, channels)?)?;
        rd.set_item("ref_time_log", out_vector(py, r.ref_time_log))?;
        rd.set_item("supervised", out_flags(py, r.supervised))?;
        rd.set_item("corrected", out_flags(py, r.corrected))?;
        rd.set_item("needed", r.needed)?;
        rd.set_item("missed", r.missed)?;
        rd.set_item("false_corrections", r.false_corrections)?;
        rd.set_item("hold_ticks", r.hold_ticks)?;
        robots.append(rd)?;
    }
    d.set_item("robots", robots)?;
    Ok(d)
}

/// Runs the planner's current schedule once in the simulated workcell (§III): every robot
/// through the Rust coordinator at the schedule's tick, a simulated operator supervising the
/// low-confidence robot. `needs[i, n]`: robot `i` needs a correction at reference sample `n`
/// (shape `(N, T_ref)`); `operator` the operator's parameters (dict). Deterministic for
/// `seed` (a ChaCha8 stream).
#[pyfunction]
#[pyo3(signature = (planner, needs, seed, operator=None))]
pub(crate) fn sim_run_round<'py>(
    py: Python<'py>,
    planner: PyRef<'py, PyPlanner>,
    needs: &Bound<'py, PyAny>,
    seed: u64,
    operator: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let p = &planner.inner;
    let (n_ref, n_robots) = (p.model().n_ref(), p.n_robots());
    let (needs, cols) = flag_matrix(needs, "needs", "robots × reference samples")?;
    if cols != n_ref || needs.len() != n_robots * n_ref {
        return Err(Error::input(
            "needs",
            format!(
                "shape ({}, {cols}), expected ({n_robots}, {n_ref}) (robots × reference samples)",
                needs.len().checked_div(cols).unwrap_or(0)
            ),
        )
        .into());
    }
    let params: OperatorParams = from_py(operator, "operator")?;
    let run = py.detach(|| {
        guard(|| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            Ok(run_round_with(
                p,
                |robot, ref_idx| needs[robot * n_ref + ref_idx],
                &params,
                &mut rng,
            )?)
        })
    })?;
    run_dict(py, run, p.model().channel_names().len())
}

/// Which reference samples need a correction on each of `N` random sanding workpieces
/// (§III: sanding in passes 1–3 over a painted section): a `(N, T_ref)` bool array. `labels`
/// is one labels file, one folder with `demo_<i>.labels.csv` (the fixtures' layout), or one
/// labels file per demonstration in the fit's order. With `planner`, the labels of its
/// reference demonstration (`tandem::sim::study::reference_labels`, the one owner of that
/// choice), checked to be one per reference sample; without, `labels` must be one file.
/// `task` holds the task parameters (dict; only `n_sections` matters); `robots` is `N` (1 to
/// 8, default 2). Deterministic for `seed`.
#[pyfunction]
#[pyo3(signature = (labels, seed, task=None, robots=N_ROBOTS, planner=None))]
pub(crate) fn sim_sanding_needs<'py>(
    py: Python<'py>,
    labels: Vec<PathBuf>,
    seed: u64,
    task: Option<&Bound<'py, PyAny>>,
    robots: usize,
    planner: Option<PyRef<'py, PyPlanner>>,
) -> PyResult<Bound<'py, PyArray2<bool>>> {
    let params: TaskParams = from_py(task, "task")?;
    RobotCount::new(robots).map_err(|e| Error::param("robots", e.to_string()))?;
    let folder = match labels.as_slice() {
        [one] if one.is_dir() => Some(one.clone()),
        _ => None,
    };
    let labels = guard(|| {
        let Some(planner) = planner.as_ref() else {
            return match (labels.as_slice(), &folder) {
                ([file], None) => Ok(read_labels(file)?),
                _ => Err(Error::param(
                    "labels",
                    "a folder or a list of labels files needs planner=…, whose reference \
                     demonstration's labels are taken",
                )),
            };
        };
        // The file of demonstration `k`: in the folder, the `k`-th of the list, or the one
        // file given (which must then be the reference's: its length is checked).
        let file_of = |k: usize| -> Result<PathBuf> {
            match (&folder, labels.as_slice()) {
                (Some(dir), _) => Ok(dir.join(format!("demo_{k}.labels.csv"))),
                (None, [one]) => Ok(one.clone()),
                (None, many) => many.get(k).cloned().ok_or_else(|| {
                    Error::input(
                        "labels",
                        format!(
                            "{} labels files, but the planner's reference is demonstration \
                             {k} of the fit (counted from 0): give one file per \
                             demonstration, in the order given to the fit",
                            many.len()
                        ),
                    )
                }),
            }
        };
        let model = planner.inner.model();
        let path = file_of(model.reference_idx())?;
        Ok(reference_labels(model, |_| {
            Ok((path.clone(), read_labels(&path)?))
        })?)
    })?;
    let flat = guard(|| {
        params.validate()?;
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut out = Vec::with_capacity(robots * labels.len());
        for _ in 0..robots {
            let wp = Workpiece::random(&params, &mut rng)?;
            out.extend(labels.iter().map(|l| needs_correction(l, &wp)));
        }
        Ok(out)
    })?;
    Ok(out_matrix(py, flat, labels.len())?)
}

/// Which reference samples need the operator on `robots` workpieces (`tandem.sim.needs`):
/// a `(robots, n_ref)` bool array drawn from a need profile (`tandem_sim::needs`), one draw
/// per region and workpiece (ChaCha8 seeded with `seed`; robot 1 first, regions in order, as
/// `tandem simulate` draws each round). The profile comes from exactly one of `regions`
/// (`(start_s, end_s, level)` in reference seconds, end exclusive), `levels` (one
/// probability per reference sample; runs of equal values are regions) or `need_file` (the
/// CSV `tandem simulate --need` reads).
#[pyfunction]
#[pyo3(signature = (n_ref, dt_s, robots, seed, regions=None, levels=None, need_file=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn sim_needs<'py>(
    py: Python<'py>,
    n_ref: usize,
    dt_s: f64,
    robots: usize,
    seed: u64,
    regions: Option<Vec<(f64, f64, f64)>>,
    levels: Option<Vec<f64>>,
    need_file: Option<PathBuf>,
) -> PyResult<Bound<'py, PyArray2<bool>>> {
    RobotCount::new(robots).map_err(|e| Error::param("robots", e.to_string()))?;
    let given = usize::from(regions.is_some())
        + usize::from(levels.is_some())
        + usize::from(need_file.is_some());
    if given != 1 {
        return Err(Error::param(
            "needs",
            "give exactly one of regions=[(start_s, end_s, level), …], levels=…, need_file=…",
        )
        .into());
    }
    let flat = guard(|| {
        let profile = if let Some(regions) = regions {
            let regions: Vec<NeedRegion> = regions
                .into_iter()
                .map(|(start_s, end_s, level)| NeedRegion {
                    start_s,
                    end_s,
                    level,
                })
                .collect();
            NeedProfile::from_regions(&regions, n_ref, dt_s)?
        } else if let Some(levels) = levels {
            if levels.len() != n_ref {
                return Err(Error::input(
                    "levels",
                    format!(
                        "{} values, expected one per reference sample ({n_ref})",
                        levels.len()
                    ),
                ));
            }
            NeedProfile::from_levels(&levels)?
        } else {
            let path = need_file.expect("exactly one source is given (checked above)");
            let file = path.display().to_string();
            let text = std::fs::read_to_string(&path)
                .map_err(|e| Error::input(file.clone(), format!("cannot read: {e}")))?;
            NeedProfile::parse_csv(&text, &file, n_ref)?
        };
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        Ok(profile.draw(robots, &mut rng).concat())
    })?;
    Ok(out_matrix(py, flat, n_ref)?)
}

/// The simulated operator's joystick input `u` (shape `(K,)`) for a correction at
/// fractional reference time `ref_time`: `±gain` along each correction component, the sign
/// that raises `force_channel`, leaving out components that would speed the robot up
/// (`tandem_sim::workcell::correction_input`). `None` when no component moves the force (the
/// workcell then commands `u = 0`).
#[pyfunction]
#[pyo3(signature = (planner, ref_time, force_channel="force", gain=1.0 / 3.0))]
pub(crate) fn sim_correction_input<'py>(
    py: Python<'py>,
    planner: PyRef<'py, PyPlanner>,
    ref_time: f64,
    force_channel: &str,
    gain: f64,
) -> PyResult<Option<Bound<'py, PyArray1<f64>>>> {
    let model = planner.inner.model();
    let params = OperatorParams {
        force_channel: force_channel.to_owned(),
        gain,
        ..OperatorParams::default()
    };
    let u = guard(|| -> Result<Option<Vec<f64>>> {
        params.validate()?;
        let force_idx = model
            .tangent_names()
            .iter()
            .position(|n| *n == params.force_channel)
            .ok_or_else(|| {
                Error::input(
                    "force_channel",
                    format!(
                        "'{force_channel}' is not a coordinate of the model ({})",
                        crate::arrays::repr_list(model.tangent_names())
                    ),
                )
            })?;
        let mut u = vec![0.0; model.n_components()];
        let any = correction_input(model, force_idx, params.gain, ref_time, &mut u)?;
        Ok(any.then_some(u))
    })?;
    Ok(u.map(|u| out_vector(py, u)))
}
