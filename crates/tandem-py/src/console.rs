//! `tandem.Console`: the operator's console (issue 42) fed by a user's own Python control
//! loop. It starts the console's server (`tandem_console::Console`, the page at
//! :attr:`Console.url`) and wraps the loop's handle: `apply(coordinator)` at each tick boundary
//! (the operator's controls), `publish(tick, coordinator)` after each tick.

use std::net::IpAddr;
use std::sync::{Mutex, MutexGuard, PoisonError};

use pyo3::prelude::*;

use crate::continuous::{PyCellTick, PyContinuousCoordinator};
use crate::coordinator::{PyCoordinator, PyTick};
use crate::errors::{Error, Result};
use crate::facade::{
    AnyController, Console, ConsoleConfig, ConsoleError, ConsoleHandle, Controller,
    DEFAULT_HORIZON_S, DEFAULT_LEAD_S, Driver, Geometry, Tick,
};

/// The operator's console of a cell driven by your own control loop: a local web page
/// (:attr:`url`) that shows which robot needs the operator now (the red indicator of the
/// paper's Fig. 1), the coordinator's pre-alert of the next handover as a countdown, the
/// queue of upcoming low-confidence stretches, and takes the operator's controls (pause,
/// resume, hold, clear a fault, acknowledge).
///
/// The loop hands each tick over with :meth:`publish` (lock-free on the Rust side, never
/// blocking: a slow page drops frames, the robots are never delayed) and applies the
/// operator's controls at each tick boundary with :meth:`apply`::
///
///     coord = planner.controller()
///     with tandem.Console(coord, port=0) as console:
///         print(console.url)
///         while not coord.is_finished:
///             if console.apply(coord):      # False while the operator paused the cell
///                 console.publish(coord.tick(), coord)
///
/// Args:
///     controller: the cell's :class:`Coordinator` (rounds) or
///         :class:`ContinuousCoordinator`, as it is before the loop starts (its plan is read
///         once: the timeline, the queue).
///     port: the TCP port; 0 (the default) picks a free one.
///     host: the address to bind, ``"127.0.0.1"`` by default (this machine only).
///     lead_s: the pre-alert's lead in seconds (default 7; never below the controller's
///         switch time).
///     max_hz: frames per second sent to a page at most (default 30, in (0, 240]).
///     horizon_s: the timeline's horizon in seconds (default 90, in (0, 3600]).
///
/// Raises:
///     InputError: ``controller`` is not a coordinator, or ``host`` is not an IP address.
///     ParamError: a parameter out of range, or the port is taken.
#[pyclass(module = "tandem", name = "Console")]
pub(crate) struct PyConsole {
    /// The server; `None` once closed.
    server: Option<Console>,
    /// The loop's end (a `Mutex` only to make the class `Sync`; the loop is its one user).
    handle: Mutex<ConsoleHandle>,
    rounds: bool,
    n_robots: usize,
    url: String,
    port: u16,
}

/// The controller behind a Python coordinator, as the console's cell kind.
fn controller_of(controller: &Bound<'_, PyAny>) -> Result<AnyController> {
    if let Ok(c) = controller.cast::<PyCoordinator>() {
        return Ok(AnyController::Rounds(c.borrow().inner.clone()));
    }
    if let Ok(c) = controller.cast::<PyContinuousCoordinator>() {
        return Ok(AnyController::Continuous(c.borrow().inner.clone()));
    }
    Err(not_a_controller())
}

fn not_a_controller() -> Error {
    Error::input(
        "controller",
        "expected a tandem.Coordinator or tandem.ContinuousCoordinator (Planner.controller())",
    )
}

fn console_error(e: &ConsoleError) -> Error {
    Error::param("console", e.to_string())
}

impl PyConsole {
    fn handle(&self) -> MutexGuard<'_, ConsoleHandle> {
        self.handle.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Checks that `controller` is of the kind and size the console was started for.
    fn check_kind(&self, rounds: bool, n_robots: usize) -> Result<()> {
        let kind = |r: bool| if r { "a rounds" } else { "a continuous" };
        if rounds != self.rounds || n_robots != self.n_robots {
            return Err(Error::input(
                "controller",
                format!(
                    "this console shows {} cell of {} robots, not {} cell of {n_robots}: \
                     pass the coordinator the console was started with",
                    kind(self.rounds),
                    self.n_robots,
                    kind(rounds)
                ),
            ));
        }
        Ok(())
    }
}

#[pymethods]
impl PyConsole {
    #[new]
    #[pyo3(signature = (controller, port=0, host="127.0.0.1", lead_s=None, max_hz=30.0, horizon_s=DEFAULT_HORIZON_S))]
    fn py_new(
        controller: &Bound<'_, PyAny>,
        port: u16,
        host: &str,
        lead_s: Option<f64>,
        max_hz: f64,
        horizon_s: f64,
    ) -> PyResult<Self> {
        let ctl = controller_of(controller)?;
        let host: IpAddr = host.parse().map_err(|_| {
            Error::input(
                "host",
                format!("'{host}' is not an IP address (e.g. \"127.0.0.1\")"),
            )
        })?;
        let config = ConsoleConfig {
            host,
            port,
            max_hz,
            lead_s: lead_s.unwrap_or(DEFAULT_LEAD_S),
            horizon_s,
            // A coordinator does not say which schedule it runs: the page's health shows none.
            schedule: None,
        };
        let geometry = Geometry::new(&ctl);
        let (rounds, n_robots) = (geometry.is_rounds(), geometry.n_robots());
        let (server, handle) = Console::start(&config, geometry).map_err(|e| console_error(&e))?;
        Ok(Self {
            url: server.url().to_string(),
            port: server.addr().port(),
            server: Some(server),
            handle: Mutex::new(handle),
            rounds,
            n_robots,
        })
    }

    /// The page's URL, ``http://127.0.0.1:PORT/`` (``/frame``: the newest frame as JSON;
    /// ``/events``: the frames as server-sent events; docs/formats.md).
    #[getter]
    fn url(&self) -> &str {
        &self.url
    }

    /// The TCP port the server listens on.
    #[getter]
    fn port(&self) -> u16 {
        self.port
    }

    /// Applies the operator's controls waiting since the last call to ``controller`` and
    /// confirms each on the page; call it at each tick boundary, before the tick.
    ///
    /// Returns:
    ///     bool: whether the loop may tick now (``False`` while the operator paused the cell,
    ///     or a hold took effect). Publish ticks anyway (e.g. the same tick again) so the page
    ///     sees the pause.
    ///
    /// Raises:
    ///     InputError: a controller of another kind or size than the console's.
    fn apply(&self, controller: &Bound<'_, PyAny>) -> PyResult<bool> {
        let mut handle = self.handle();
        if let Ok(c) = controller.cast::<PyCoordinator>() {
            let mut c = c.borrow_mut();
            self.check_kind(true, c.inner.robots().len())?;
            return Ok(Driver::apply(&mut handle, &mut c.inner));
        }
        if let Ok(c) = controller.cast::<PyContinuousCoordinator>() {
            let mut c = c.borrow_mut();
            self.check_kind(false, Controller::n_robots(&c.inner))?;
            return Ok(Driver::apply(&mut handle, &mut c.inner));
        }
        Err(not_a_controller().into())
    }

    /// Hands the state after ``tick`` to the page. Cheap (a counter, unless the server asked
    /// for a frame since the last call), never blocks; frames a slow page does not take are
    /// dropped.
    ///
    /// Args:
    ///     tick: the :class:`Tick` (or :class:`CellTick`) ``controller.tick()`` returned.
    ///     controller: the coordinator that returned it.
    ///     corrected: whether the operator's input of this tick was a correction (anything
    ///         but the scheduled pace); once given, the page's per-robot strip counts the
    ///         corrections of each robot's current execution (consecutive corrected ticks
    ///         count once). ``None`` (default): not reported, the strip shows no count.
    ///
    /// Raises:
    ///     InputError: a tick or controller of another kind or size than the console's.
    #[pyo3(signature = (tick, controller, corrected=None))]
    fn publish(
        &self,
        tick: &Bound<'_, PyAny>,
        controller: &Bound<'_, PyAny>,
        corrected: Option<bool>,
    ) -> PyResult<()> {
        let tick: Tick = if let Ok(t) = tick.cast::<PyTick>() {
            t.get().inner
        } else if let Ok(t) = tick.cast::<PyCellTick>() {
            t.get().inner
        } else {
            return Err(Error::input(
                "tick",
                "expected the tandem.Tick or tandem.CellTick that controller.tick() returned",
            )
            .into());
        };
        let mut handle = self.handle();
        if let Ok(c) = controller.cast::<PyCoordinator>() {
            let c = c.borrow();
            self.check_kind(true, c.inner.robots().len())?;
            match corrected {
                Some(k) => handle.publish_corrected(&tick, &c.inner, k),
                None => handle.publish(&tick, &c.inner),
            }
        } else if let Ok(c) = controller.cast::<PyContinuousCoordinator>() {
            let c = c.borrow();
            self.check_kind(false, Controller::n_robots(&c.inner))?;
            match corrected {
                Some(k) => handle.publish_corrected(&tick, &c.inner, k),
                None => handle.publish(&tick, &c.inner),
            }
        } else {
            return Err(not_a_controller().into());
        }
        Ok(())
    }

    /// Counts a finished round (a rounds cell run round after round: call it before
    /// ``controller.reset()``); the page shows the count.
    fn round_done(&self) {
        self.handle().round_done();
    }

    /// Whether the operator paused the cell (the loop should not tick).
    #[getter]
    fn paused(&self) -> bool {
        self.handle().is_paused()
    }

    /// Ticks handed to :meth:`publish` so far.
    #[getter]
    fn published(&self) -> u64 {
        self.handle().published()
    }

    /// Whether the server runs (``False`` after :meth:`close`).
    #[getter]
    fn running(&self) -> bool {
        self.server.is_some()
    }

    /// Stops the server (open pages lose their connection and retry); idempotent. A closed
    /// console's :meth:`publish` and :meth:`apply` still work and show nobody anything.
    fn close(&mut self, py: Python<'_>) {
        if let Some(s) = self.server.take() {
            py.detach(|| s.stop());
        }
    }

    fn __enter__(slf: Py<Self>) -> Py<Self> {
        slf
    }

    #[pyo3(signature = (*_args))]
    fn __exit__(&mut self, py: Python<'_>, _args: &Bound<'_, pyo3::types::PyTuple>) -> bool {
        self.close(py);
        false
    }

    fn __repr__(&self) -> String {
        format!(
            "Console(url={:?}, {} cell of {} robots, running={})",
            self.url,
            if self.rounds { "rounds" } else { "continuous" },
            self.n_robots,
            if self.server.is_some() {
                "True"
            } else {
                "False"
            }
        )
    }
}
