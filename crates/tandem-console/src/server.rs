//! The HTTP server: one static page (`/`), the frames as server-sent events (`/events`), the
//! newest frame as JSON (`/frame`), the operator's controls by POST (`/control`). It runs on
//! its own thread with a one-thread tokio runtime; a poller reads the loop's newest snapshot at
//! most `max_hz` times a second and pushes one frame to every page (a page that is slower
//! skips frames; nothing queues up).

use std::collections::{HashMap, VecDeque};
use std::convert::Infallible;
use std::net::{IpAddr, Ipv4Addr, SocketAddr, TcpListener};
use std::sync::atomic::Ordering;
use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use axum::Router;
use axum::body::Bytes;
use axum::extract::{Query, State};
use axum::http::{StatusCode, header};
use axum::response::sse::{Event, KeepAlive, Sse};
use axum::response::{Html, IntoResponse, Response};
use axum::routing::{get, post};
use futures_util::Stream;
use serde::Deserialize;
use serde_json::json;
use tokio::sync::{oneshot, watch};

use crate::error::{Error, Result};
use crate::frame::{Ack, Geometry, build_frame};
use crate::handle::{ConsoleHandle, ControlMsg, Op, Shared};
use crate::strip::Tracker;

/// The page: HTML, CSS and JavaScript in one file, no external resource.
pub const PAGE: &str = include_str!("page.html");

/// Controls waiting for the loop at most (a full queue answers 503).
const CONTROL_QUEUE: usize = 64;
/// Confirmations waiting for the server at most.
const ACK_QUEUE: usize = 64;
/// Confirmations every frame repeats (the newest).
const ACKS_KEPT: usize = 16;

/// Where and how fast the console serves.
#[derive(Clone, Debug)]
pub struct ConsoleConfig {
    /// Address to bind. Default: 127.0.0.1 (this machine only).
    pub host: IpAddr,
    /// Port; 0 picks a free one. Default: 0.
    pub port: u16,
    /// Frames per second pushed to a page at most. Default: 30.
    pub max_hz: f64,
    /// The pre-alert's lead (s): the page alerts once the next handover can start within it.
    /// The console uses the larger of this and the controller's switch time
    /// ([`Geometry::switch_s`]). Default: [`crate::DEFAULT_LEAD_S`] (7 s).
    pub lead_s: f64,
    /// The timeline's horizon (s). Default: [`crate::DEFAULT_HORIZON_S`] (90 s).
    pub horizon_s: f64,
    /// The schedule the cell runs and its certificate, in words (health: certified plan or
    /// fallback), if the source knows it. Default: `None`.
    pub schedule: Option<String>,
}

impl Default for ConsoleConfig {
    fn default() -> Self {
        ConsoleConfig {
            host: IpAddr::V4(Ipv4Addr::LOCALHOST),
            port: 0,
            max_hz: 30.0,
            lead_s: crate::DEFAULT_LEAD_S,
            horizon_s: crate::DEFAULT_HORIZON_S,
            schedule: None,
        }
    }
}

impl ConsoleConfig {
    /// Checks the numbers: `max_hz` in (0, 240], `lead_s` ≥ 0, `horizon_s` in (0, 3600].
    ///
    /// # Errors
    /// [`Error::BadParam`] naming the first bad one.
    pub fn validate(&self) -> Result<()> {
        let bad = |name, why| Err(Error::BadParam { name, why });
        if !(self.max_hz > 0.0 && self.max_hz <= 240.0) {
            return bad("max_hz", "must be in (0, 240]");
        }
        if !(self.lead_s >= 0.0 && self.lead_s.is_finite()) {
            return bad("lead_s", "must be finite and >= 0");
        }
        if !(self.horizon_s > 0.0 && self.horizon_s <= 3600.0) {
            return bad("horizon_s", "must be in (0, 3600]");
        }
        Ok(())
    }
}

/// Who may control the cell, and the ids seen.
#[derive(Debug, Default)]
struct Clients {
    controller: Option<String>,
    last_id: HashMap<String, u64>,
    acks: VecDeque<Ack>,
    version: u64,
}

impl Clients {
    fn push_ack(&mut self, ack: Ack) {
        if self.acks.len() == ACKS_KEPT {
            self.acks.pop_front();
        }
        self.acks.push_back(ack);
        self.version += 1;
    }
}

#[derive(Debug)]
struct App {
    frames: watch::Receiver<Arc<str>>,
    controls: SyncSender<ControlMsg>,
    clients: Mutex<Clients>,
    n_robots: usize,
    shared: Arc<Shared>,
    /// What the page must be told about the source ([`Console::set_notice`]).
    notice: Mutex<Option<String>>,
}

impl App {
    fn clients(&self) -> std::sync::MutexGuard<'_, Clients> {
        self.clients.lock().unwrap_or_else(PoisonError::into_inner)
    }

    fn set_notice(&self, notice: Option<String>) {
        *self.notice.lock().unwrap_or_else(PoisonError::into_inner) = notice;
    }

    fn notice(&self) -> Option<String> {
        self.notice
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .clone()
    }
}

/// The plan the server reads, the configuration's lead and horizon to apply to a new one, and
/// the loop's updates ([`ConsoleHandle::set_plan`], [`ConsoleHandle::set_notice`]).
struct Plan {
    geometry: Geometry,
    config: (f64, f64),
    updates: Receiver<Update>,
}

/// What the control loop's handle sends the server besides snapshots: rare, queued, in order.
#[derive(Debug)]
pub(crate) enum Update {
    /// The cell's plan changed (a controller re-planned after a recorded round).
    Plan(Box<Geometry>),
    /// The notice every frame carries from now on ([`Console::set_notice`]).
    Notice(Option<String>),
}

/// Queued updates the server has not taken yet (a handful between two server periods).
const UPDATE_QUEUE: usize = 16;

/// A running console: the server thread and its address. Dropping it stops the server.
#[derive(Debug)]
pub struct Console {
    app: Arc<App>,
    url: String,
    addr: SocketAddr,
    stop: Option<oneshot::Sender<()>>,
    thread: Option<JoinHandle<()>>,
}

impl Console {
    /// Starts a console for the cell of `geometry` on `config`'s address; returns it and the
    /// control loop's handle. The page is at [`Console::url`] once this returns.
    ///
    /// # Errors
    /// [`Error::BadParam`] for a bad `config`, [`Error::Bind`] when the address is taken or not
    /// local, [`Error::Runtime`] when the server's runtime cannot start.
    pub fn start(
        config: &ConsoleConfig,
        mut geometry: Geometry,
    ) -> Result<(Console, ConsoleHandle)> {
        config.validate()?;
        geometry.lead_s = config.lead_s.max(geometry.switch_s());
        geometry.horizon_s = config.horizon_s;
        let addr = SocketAddr::new(config.host, config.port);
        let listener = TcpListener::bind(addr).map_err(|source| Error::Bind {
            addr: addr.to_string(),
            source,
        })?;
        listener.set_nonblocking(true).map_err(Error::Runtime)?;
        let addr = listener.local_addr().map_err(Error::Runtime)?;
        let shared = Arc::new(Shared::new());
        let (controls_tx, controls_rx) = sync_channel(CONTROL_QUEUE);
        let (acks_tx, acks_rx) = sync_channel(ACK_QUEUE);
        let (updates_tx, updates_rx) = sync_channel(UPDATE_QUEUE);
        let handle = ConsoleHandle::new(
            shared.clone(),
            controls_rx,
            acks_tx,
            updates_tx,
            geometry.is_rounds(),
            geometry.n_robots(),
            geometry.can_hold(),
        );
        let (frames_tx, frames_rx) = watch::channel::<Arc<str>>(Arc::from(""));
        let app = Arc::new(App {
            frames: frames_rx,
            controls: controls_tx,
            clients: Mutex::new(Clients::default()),
            n_robots: geometry.n_robots(),
            shared: shared.clone(),
            notice: Mutex::new(None),
        });
        let app_kept = app.clone();
        let rt = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .map_err(Error::Runtime)?;
        let (stop_tx, stop_rx) = oneshot::channel::<()>();
        let period = Duration::from_secs_f64(1.0 / config.max_hz);
        let schedule = config.schedule.clone();
        let plan_config = (config.lead_s, config.horizon_s);
        let thread = std::thread::Builder::new()
            .name("tandem-console".into())
            .spawn(move || {
                rt.block_on(serve(
                    listener,
                    app,
                    shared,
                    Plan {
                        geometry,
                        config: plan_config,
                        updates: updates_rx,
                    },
                    schedule,
                    frames_tx,
                    acks_rx,
                    period,
                    stop_rx,
                ));
                rt.shutdown_timeout(Duration::from_millis(200));
            })
            .map_err(Error::Runtime)?;
        Ok((
            Console {
                app: app_kept,
                url: format!("http://{addr}/"),
                addr,
                stop: Some(stop_tx),
                thread: Some(thread),
            },
            handle,
        ))
    }

    /// The page's URL (`http://127.0.0.1:PORT/`).
    #[must_use]
    pub fn url(&self) -> &str {
        &self.url
    }

    /// Sets (or clears, `None`) the notice every frame carries to the page from now on (a
    /// replay's damaged file, its end); it is pushed at the next server period.
    pub fn set_notice(&self, notice: Option<String>) {
        self.app.set_notice(notice);
    }

    /// The address the server listens on.
    #[must_use]
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// Stops the server (open pages lose their connection and retry) and waits for its thread.
    pub fn stop(mut self) {
        self.shutdown();
    }

    fn shutdown(&mut self) {
        if let Some(tx) = self.stop.take() {
            let _ = tx.send(());
        }
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Drop for Console {
    fn drop(&mut self) {
        self.shutdown();
    }
}

#[allow(clippy::too_many_arguments)]
async fn serve(
    listener: TcpListener,
    app: Arc<App>,
    shared: Arc<Shared>,
    plan: Plan,
    schedule: Option<String>,
    frames_tx: watch::Sender<Arc<str>>,
    acks_rx: Receiver<Ack>,
    period: Duration,
    stop: oneshot::Receiver<()>,
) {
    let listener = match tokio::net::TcpListener::from_std(listener) {
        Ok(l) => l,
        Err(e) => {
            eprintln!("console: cannot serve: {e}");
            return;
        }
    };
    let router = Router::new()
        .route("/", get(page))
        .route("/events", get(events))
        .route("/frame", get(latest))
        .route("/control", post(control))
        .with_state(app.clone());
    let poll = poller(app, shared, plan, schedule, frames_tx, acks_rx, period);
    let server = axum::serve(listener, router);
    tokio::select! {
        r = server => if let Err(e) = r { eprintln!("console: server stopped: {e}") },
        () = poll => {}
        _ = stop => {}
    }
}

/// Reads the newest snapshot every `period` and pushes a frame when anything changed (or once
/// a second, so the page sees the source's age grow when the loop stops publishing).
async fn poller(
    app: Arc<App>,
    shared: Arc<Shared>,
    plan: Plan,
    schedule: Option<String>,
    frames_tx: watch::Sender<Arc<str>>,
    acks_rx: Receiver<Ack>,
    period: Duration,
) {
    let mut interval = tokio::time::interval(period);
    interval.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Skip);
    let (mut last_written, mut sent_new, mut seq) = (0u64, 0u64, 0u64);
    let mut last_version = u64::MAX;
    let mut last_controller: Option<String> = None;
    let mut last_notice: Option<String> = None;
    let mut tracker = Tracker::new();
    let mut last_push = Instant::now();
    let Plan {
        mut geometry,
        config: (lead_s, horizon_s),
        updates,
    } = plan;
    loop {
        interval.tick().await;
        // Ask the loop for its next snapshot and wait for it (at most one period: a loop that
        // stopped publishing leaves the newest snapshot, whose age the page shows).
        let before = shared.slot.written();
        shared.want.store(true, Ordering::Relaxed);
        let asked = Instant::now();
        while shared.slot.written() == before && asked.elapsed() < period {
            tokio::time::sleep(Duration::from_millis(1)).await;
        }
        // The loop's updates (`ConsoleHandle::set_plan`, `set_notice`), in their order, after the
        // snapshot: the loop sends a new plan before the first snapshot on it, so a snapshot of
        // the new controller is not read on the old plan (unless the loop answered later than
        // a period, and then for one frame).
        while let Ok(u) = updates.try_recv() {
            match u {
                Update::Plan(g) => {
                    geometry = *g;
                    geometry.lead_s = lead_s.max(geometry.switch_s());
                    geometry.horizon_s = horizon_s;
                    // The strips follow the new plan's executions from its first snapshot.
                    tracker = Tracker::new();
                    last_version = u64::MAX;
                }
                Update::Notice(n) => app.set_notice(n),
            }
        }
        let (acks, version, controller) = {
            let mut c = app.clients();
            while let Ok(ack) = acks_rx.try_recv() {
                c.push_ack(ack);
            }
            (
                c.acks.iter().cloned().collect::<Vec<_>>(),
                c.version,
                c.controller.clone(),
            )
        };
        let notice = app.notice();
        let Some((written, raw)) = shared.slot.read() else {
            continue;
        };
        let fresh = written != last_written;
        if !fresh
            && version == last_version
            && controller == last_controller
            && notice == last_notice
            && last_push.elapsed() < Duration::from_secs(1)
        {
            continue;
        }
        if fresh {
            sent_new += 1;
        }
        last_written = written;
        last_version = version;
        last_controller.clone_from(&controller);
        last_notice.clone_from(&notice);
        last_push = Instant::now();
        seq += 1;
        let mut frame = build_frame(&geometry, &raw);
        frame.seq = seq;
        if fresh {
            tracker.fill(&geometry, &raw, &mut frame);
        } else {
            tracker.fill_again(&mut frame);
        }
        frame.notice = notice;
        frame.controller = controller;
        frame.acks = acks;
        frame.health.published = raw.published;
        frame.health.schedule.clone_from(&schedule);
        frame.health.dropped = raw.published.saturating_sub(sent_new);
        frame.health.acks_lost = shared.acks_lost.load(Ordering::Relaxed);
        frame.health.source_age_s = (unix_ms() - raw.published_unix_ms).max(0.0) / 1e3;
        match serde_json::to_string(&frame) {
            Ok(s) => {
                if frames_tx.send(Arc::from(s)).is_err() {
                    // No receiver left: the server is gone.
                    return;
                }
            }
            Err(e) => eprintln!("console: cannot encode a frame: {e}"),
        }
    }
}

fn unix_ms() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64() * 1e3)
}

async fn page() -> Html<&'static str> {
    Html(PAGE)
}

async fn latest(State(app): State<Arc<App>>) -> Response {
    let f = app.frames.borrow().clone();
    if f.is_empty() {
        return (
            StatusCode::SERVICE_UNAVAILABLE,
            "no frame yet: the loop has not published",
        )
            .into_response();
    }
    ([(header::CONTENT_TYPE, "application/json")], f.to_string()).into_response()
}

/// `?client=ID` of `/events`: a controlling client whose stream closes gives control up.
#[derive(Debug, Deserialize)]
struct EventsQuery {
    client: Option<String>,
}

/// Releases control when the controlling client's event stream closes.
#[derive(Debug)]
struct StreamGuard {
    app: Arc<App>,
    client: Option<String>,
}

impl Drop for StreamGuard {
    fn drop(&mut self) {
        if let Some(client) = &self.client {
            let mut c = self.app.clients();
            if c.controller.as_deref() == Some(client) {
                c.controller = None;
                c.version += 1;
                eprintln!("console: client {client} disconnected; control released");
            }
        }
    }
}

async fn events(
    State(app): State<Arc<App>>,
    Query(q): Query<EventsQuery>,
) -> Sse<impl Stream<Item = std::result::Result<Event, Infallible>>> {
    let mut rx = app.frames.clone();
    rx.mark_changed();
    let guard = StreamGuard {
        app: app.clone(),
        client: q.client,
    };
    let stream =
        futures_util::stream::unfold((rx, guard, true), |(mut rx, guard, first)| async move {
            loop {
                rx.changed().await.ok()?;
                let data = rx.borrow_and_update().clone();
                if data.is_empty() {
                    continue;
                }
                let mut ev = Event::default().event("frame").data(&*data);
                if first {
                    ev = ev.retry(Duration::from_millis(500));
                }
                return Some((Ok(ev), (rx, guard, false)));
            }
        });
    Sse::new(stream).keep_alive(KeepAlive::default())
}

/// A control message as the page sends it (docs/formats.md, "Console controls").
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ControlRequest {
    client: String,
    id: u64,
    op: Op,
    #[serde(default)]
    robot: Option<usize>,
}

fn reply(status: StatusCode, body: serde_json::Value) -> Response {
    (status, axum::Json(body)).into_response()
}

fn reject(status: StatusCode, client: &str, why: String) -> Response {
    eprintln!("console: control rejected ({client}): {why}");
    reply(status, json!({ "ok": false, "error": why }))
}

async fn control(State(app): State<Arc<App>>, body: Bytes) -> Response {
    let req: ControlRequest = match serde_json::from_slice(&body) {
        Ok(r) => r,
        Err(e) => {
            return reject(
                StatusCode::BAD_REQUEST,
                "?",
                format!(
                    "malformed control message: {e}; expected {{\"client\": \"ID\", \"id\": N, \"op\": \
                     \"claim|release|acknowledge|hold|clear_fault|pause|resume\", \"robot\": K}}"
                ),
            );
        }
    };
    let client = req.client.as_str();
    if client.is_empty() || client.len() > 64 {
        return reject(
            StatusCode::BAD_REQUEST,
            "?",
            "`client` must be 1 to 64 characters".to_string(),
        );
    }
    let mut c = app.clients();
    if let Some(&last) = c.last_id.get(client) {
        if req.id <= last {
            return reject(
                StatusCode::CONFLICT,
                client,
                format!(
                    "out-of-order message: id {} after id {last}; ids must increase",
                    req.id
                ),
            );
        }
    }
    c.last_id.insert(client.to_string(), req.id);
    let ack = |ok: bool, message: String| Ack {
        client: client.to_string(),
        id: req.id,
        op: req.op.name().to_string(),
        ok,
        message,
    };
    match req.op {
        Op::Claim => match c.controller.clone() {
            Some(other) if other != client => reject(
                StatusCode::CONFLICT,
                client,
                format!(
                    "read-only: client {other} controls the cell; it must release control first"
                ),
            ),
            _ => {
                c.controller = Some(client.to_string());
                c.push_ack(ack(true, "you control the cell".to_string()));
                reply(
                    StatusCode::OK,
                    json!({ "ok": true, "id": req.id, "controller": client }),
                )
            }
        },
        Op::Release => {
            if c.controller.as_deref() == Some(client) {
                c.controller = None;
                c.push_ack(ack(true, "control released".to_string()));
                reply(StatusCode::OK, json!({ "ok": true, "id": req.id }))
            } else {
                reject(
                    StatusCode::CONFLICT,
                    client,
                    "this client does not control the cell".to_string(),
                )
            }
        }
        op => {
            match c.controller.as_deref() {
                Some(owner) if owner == client => {}
                Some(owner) => {
                    let why = format!("read-only: client {owner} controls the cell");
                    return reject(StatusCode::FORBIDDEN, client, why);
                }
                None => {
                    return reject(
                        StatusCode::FORBIDDEN,
                        client,
                        "no client controls the cell: claim control first".to_string(),
                    );
                }
            }
            let robot = match (op, req.robot) {
                (Op::Hold, Some(k)) if (1..=app.n_robots).contains(&k) => Some(k - 1),
                (Op::Hold, _) => {
                    return reject(
                        StatusCode::BAD_REQUEST,
                        client,
                        format!("`hold` needs `robot` in 1..={}", app.n_robots),
                    );
                }
                (_, Some(_)) => {
                    return reject(
                        StatusCode::BAD_REQUEST,
                        client,
                        format!("`{}` takes no `robot`", op.name()),
                    );
                }
                (_, None) => None,
            };
            drop(c);
            let msg = ControlMsg {
                client: client.to_string(),
                id: req.id,
                op,
                robot,
            };
            match app.controls.try_send(msg) {
                Ok(()) => {
                    app.shared.controls_sent.fetch_add(1, Ordering::Release);
                    reply(
                        StatusCode::ACCEPTED,
                        json!({ "ok": true, "id": req.id, "pending": true }),
                    )
                }
                Err(TrySendError::Full(_)) => reject(
                    StatusCode::SERVICE_UNAVAILABLE,
                    client,
                    "the cell's control queue is full; retry".to_string(),
                ),
                Err(TrySendError::Disconnected(_)) => reject(
                    StatusCode::SERVICE_UNAVAILABLE,
                    client,
                    "the control loop has stopped".to_string(),
                ),
            }
        }
    }
}
