//! Python bindings of tandem: the extension module `tandem._tandem` of the Python package
//! `tandem` (python/tandem/, built with maturin; docs/python.md).
//!
//! What Python gets, NumPy arrays in and out, with shapes and units in every docstring:
//!
//! - `planner`: `tandem.fit` (demonstrations as arrays or the command line's CSV/JSON
//!   files → the Fig. 2 loop), `tandem.Planner` (`record_round`, `reschedule`, `save`/`load`
//!   with the command line's state file, `command` of Eq. 7) and the per-sample arrays of
//!   the model (`tandem.Model`: `μ̂`, `σ²_D`, `ψ̇min/ψ̇max`) and of the confidence
//!   (`tandem.Confidence`: latched `conf`, Beta posterior, observations).
//! - `cell`: `tandem.fit_cell` and `tandem.CellPlanner`, a cell of different tasks on
//!   different robots (issue 45) with the command line's state file.
//! - `schedule`: `tandem.Problem` and `tandem.Schedule` (offsets, gradients,
//!   low-confidence intervals, `T_total`, tick; `validate` against Eq. 20).
//! - `cyclic`: `tandem.CyclicPlan`, the plan of a continuous cell (no rounds: its period,
//!   throughput, the operator's order and busy share, a lower bound), from
//!   `Planner.cyclic_plan` or `tandem.cyclic_plan`.
//! - `coordinator`: `tandem.Coordinator`, the Rust real-time coordinator itself (not a
//!   re-implementation), one control tick per `tick(operator)`.
//! - `continuous`: `tandem.ContinuousCoordinator`, the Rust coordinator of a continuous cell
//!   (the token rule), from `CyclicPlan.coordinator` or `Planner.continuous_coordinator`,
//!   one control tick per `tick(operator)`.
//! - `console`: `tandem.Console`, the operator's console (a local web page, issue 42) fed by
//!   a user's own control loop: `apply` the operator's controls at each tick boundary,
//!   `publish` each tick.
//! - `study` and `sim`: the simulated study of §III and its workcell.
//! - `warp`: `tandem.align`, GDTW (Eq. 2–3).
//! - `bag`: `tandem.read_bag`, a ROS 2 bag (rosbag2 MCAP) on one grid; `tandem.fit` takes
//!   `.mcap` paths too.
//!
//! Errors become subclasses of `tandem.TandemError` (`errors`); a panic is caught at the
//! boundary and raised as `tandem.InternalError`. The GIL is released around every long call
//! (fit, record, reschedule, study, align, load, save). The per-robot arrays are shaped for
//! `N` robots (`(N,)`, `(N, T_ref)`, `N − 1` offsets); this build coordinates two.
//!
//! Every path into the `tandem` facade is in `facade`, so moving the planner into its own
//! crate changes one file here. The crate has no Rust test harness and no doctest (either
//! would need libpython at link time): it is tested from Python (`python/tests/`, run by
//! `cargo xtask test`), and its examples are `examples/python/`.

mod arrays;
mod bag;
mod cell;
mod console;
mod continuous;
mod coordinator;
mod cyclic;
mod errors;
mod facade;
mod params;
mod planner;
mod schedule;
mod sim;
mod study;
mod warp;

use pyo3::prelude::*;

/// tandem: coordinated multi-robot shared autonomy (Hagenow et al., RA-L 2023), the Rust
/// extension module. Import ``tandem``, not this module.
#[pymodule]
mod _tandem {
    #[pymodule_export]
    use crate::bag::read_bag;
    #[pymodule_export]
    use crate::cell::{PyCellPlanner, fit_cell};
    #[pymodule_export]
    use crate::console::PyConsole;
    #[pymodule_export]
    use crate::continuous::{PyCellTick, PyContinuousCoordinator};
    #[pymodule_export]
    use crate::coordinator::{PyCoordinator, PyTick};
    #[pymodule_export]
    use crate::cyclic::{PyCyclicPlan, cyclic_plan};
    #[pymodule_export]
    use crate::errors::{
        DataWarning, InputError, InternalError, ParamError, ScheduleError, StateFileError,
        TandemError,
    };
    #[pymodule_export]
    use crate::planner::{
        PyConfidence, PyModel, PyObservations, PyPlanner, PyStateEdit, default_params, fit,
        fit_model,
    };
    #[pymodule_export]
    use crate::schedule::{PyProblem, PySchedule};
    #[pymodule_export]
    use crate::sim::{sim_correction_input, sim_needs, sim_run_round, sim_sanding_needs};
    #[pymodule_export]
    use crate::study::{
        PyStudyTask, study_config, study_prepare, study_run, study_run_cell_trial, study_run_trial,
    };
    #[pymodule_export]
    use crate::warp::{PyWarp, align};

    use pyo3::prelude::*;

    /// Module constants: the number of robots this build coordinates and the version.
    #[pymodule_init]
    fn init(m: &Bound<'_, PyModule>) -> PyResult<()> {
        m.add("N_ROBOTS", crate::planner::N_ROBOTS)?;
        m.add("MAX_ROBOTS", crate::facade::MAX_ROBOTS)?;
        m.add("__version__", env!("CARGO_PKG_VERSION"))?;
        Ok(())
    }
}
