//! A test client of the node over DDS: it plays the robots (reads each robot's command,
//! reports progress), the operator's input device, and calls the services. The tests' other
//! process, and a smoke test for a user's graph.

use std::sync::Mutex;
use std::time::{Duration, Instant};

use ros2_client::dds::rustdds::mio1::{Events, Interest, Poll, Token};
use ros2_client::{Client, Node as RosNode, Publisher, ServiceTypeName, Subscription};

use crate::error::{Error, Result, dds};
use crate::msg::{
    BOOL, Bool, FLOAT64, FLOAT64_MULTI_ARRAY, Float64, Float64MultiArray, Header, JOY, Joy,
    POSE_STAMPED, PoseStamped, STRING, TRIGGER, Text, TriggerRequest, TriggerResponse, now,
};
use crate::node::{
    SERVICE_MAPPING, SERVICES, cell_topic, publisher, qos, robot_topic, ros_node, subscription,
};

/// One command as a robot receives it (`/tandem/robotK/command`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Command {
    /// Reference time to follow (reference samples).
    pub ref_time: f64,
    /// Speed scale over the last tick.
    pub speed: f64,
    /// The node's tick count.
    pub tick: u64,
    /// The node's wall-clock stamp of the tick (UNIX s).
    pub stamp_s: f64,
    /// The probe's wall clock when it took the message (UNIX s).
    pub received_s: f64,
}

/// The probe: one ROS 2 node with the counterparts of the node's topics and services.
pub struct Probe {
    _node: RosNode,
    commands: Vec<Subscription<Float64MultiArray>>,
    needs: Vec<Subscription<Bool>>,
    setpoints: Vec<Subscription<Float64MultiArray>>,
    poses: Vec<Subscription<PoseStamped>>,
    progress: Vec<Publisher<Float64>>,
    fault: Subscription<Text>,
    operator: Publisher<Joy>,
    clients: Vec<Client<TriggerRequest, TriggerResponse>>,
    /// The robots' command readers registered for their data events
    /// ([`Probe::wait_commands`]).
    wake: Mutex<(Poll, Events)>,
}

impl std::fmt::Debug for Probe {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Probe")
            .field("robots", &self.commands.len())
            .finish_non_exhaustive()
    }
}

impl Probe {
    /// A probe of `n` robots' topics on DDS domain `domain`.
    ///
    /// # Errors
    /// [`Error::Dds`].
    pub fn new(domain: u16, n: usize) -> Result<Probe> {
        let mut node = ros_node(domain, "tandem_probe")?;
        let mut commands = Vec::new();
        let mut needs = Vec::new();
        let mut setpoints = Vec::new();
        let mut poses = Vec::new();
        let mut progress = Vec::new();
        for k in 0..n {
            commands.push(subscription(
                &mut node,
                &robot_topic(k, "command")?,
                FLOAT64_MULTI_ARRAY,
            )?);
            needs.push(subscription(
                &mut node,
                &robot_topic(k, "needs_operator")?,
                BOOL,
            )?);
            setpoints.push(subscription(
                &mut node,
                &robot_topic(k, "setpoint")?,
                FLOAT64_MULTI_ARRAY,
            )?);
            poses.push(subscription(
                &mut node,
                &robot_topic(k, "setpoint_pose")?,
                POSE_STAMPED,
            )?);
            progress.push(publisher(&mut node, &robot_topic(k, "progress")?, FLOAT64)?);
        }
        let poll = Poll::new().map_err(|e| dds("create a poll of the command readers", e))?;
        for (k, c) in commands.iter_mut().enumerate() {
            poll.registry()
                .register(c, Token(k), Interest::READABLE)
                .map_err(|e| dds(format!("register robot {}'s command reader", k + 1), e))?;
        }
        let fault = subscription(&mut node, &cell_topic("fault")?, STRING)?;
        let operator = publisher(&mut node, &cell_topic("operator")?, JOY)?;
        let clients = SERVICES
            .iter()
            .map(|(name, _)| {
                node.create_client::<TriggerRequest, TriggerResponse>(
                    SERVICE_MAPPING,
                    &cell_topic(name)?,
                    &ServiceTypeName::new(TRIGGER.0, TRIGGER.1),
                    qos(),
                    qos(),
                )
                .map_err(|e| dds(format!("call {name}"), e))
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Probe {
            _node: node,
            commands,
            needs,
            setpoints,
            poses,
            progress,
            fault,
            operator,
            clients,
            wake: Mutex::new((poll, Events::with_capacity(16))),
        })
    }

    /// Waits until a command of any robot has arrived since the last [`Probe::commands`]
    /// (the reader's data event: RustDDS signals each sample it stores), or `timeout` passes;
    /// `true` when woken by data (it may be data already taken). What a robot driver's thread
    /// that follows the commands does instead of polling on a timer: the command is taken as it
    /// arrives, not up to a poll period later.
    pub fn wait_commands(&self, timeout: Duration) -> bool {
        let mut guard = match self.wake.lock() {
            Ok(g) => g,
            Err(poisoned) => poisoned.into_inner(),
        };
        let (poll, events) = &mut *guard;
        match poll.poll(events, Some(timeout)) {
            Ok(()) => !events.is_empty(),
            // An interrupted wait is a spurious wake-up: the caller takes and waits again.
            Err(_) => false,
        }
    }

    /// Every command of robot `k` that arrived since the last call, oldest first.
    pub fn commands(&self, k: usize) -> Vec<Command> {
        let mut out = Vec::new();
        while let Ok(Some((m, _))) = self.commands[k].take() {
            if let [ref_time, speed, tick, stamp_s, ..] = m.data[..] {
                out.push(Command {
                    ref_time,
                    speed,
                    tick: tick as u64,
                    stamp_s,
                    received_s: crate::msg::seconds(now()),
                });
            }
        }
        out
    }

    /// The last `needs_operator` of robot `k` that arrived since the last call.
    pub fn needs(&self, k: usize) -> Option<bool> {
        let mut last = None;
        while let Ok(Some((m, _))) = self.needs[k].take() {
            last = Some(m.data);
        }
        last
    }

    /// The last setpoint (`Float64MultiArray`) of robot `k` that arrived since the last call.
    pub fn setpoint(&self, k: usize) -> Option<Float64MultiArray> {
        let mut last = None;
        while let Ok(Some((m, _))) = self.setpoints[k].take() {
            last = Some(m);
        }
        last
    }

    /// The last `setpoint_pose` of robot `k` that arrived since the last call.
    pub fn setpoint_pose(&self, k: usize) -> Option<PoseStamped> {
        let mut last = None;
        while let Ok(Some((m, _))) = self.poses[k].take() {
            last = Some(m);
        }
        last
    }

    /// The last fault text that arrived since the last call.
    pub fn fault(&self) -> Option<String> {
        let mut last = None;
        while let Ok(Some((m, _))) = self.fault.take() {
            last = Some(m.data);
        }
        last
    }

    /// Robot `k` reports reaching `ref_time`.
    ///
    /// # Errors
    /// [`Error::Dds`].
    pub fn report(&self, k: usize, ref_time: f64) -> Result<()> {
        self.progress[k]
            .publish(Float64 { data: ref_time })
            .map_err(|e| dds("publish progress", e))
    }

    /// The operator's device: timing axis `axis`, button 0 `correcting`.
    ///
    /// # Errors
    /// [`Error::Dds`].
    pub fn operate(&self, axis: f32, correcting: bool) -> Result<()> {
        let joy = Joy {
            header: Header {
                stamp: now(),
                frame_id: String::new(),
            },
            axes: vec![axis],
            buttons: vec![i32::from(correcting)],
        };
        self.operator
            .publish(joy)
            .map_err(|e| dds("publish the operator's input", e))
    }

    /// Calls service `name` (one of `start_round`, `stop_round`, `clear_fault`,
    /// `record_round`) and waits up to `timeout` for the answer, calling `between` while it
    /// waits (to keep the robots reporting).
    ///
    /// # Errors
    /// [`Error::BadParam`] for another name; [`Error::Dds`] when the request cannot be sent
    /// or no answer came in time.
    pub fn call(
        &self,
        name: &str,
        timeout: Duration,
        mut between: impl FnMut(),
    ) -> Result<TriggerResponse> {
        let i = SERVICES
            .iter()
            .position(|(s, _)| *s == name)
            .ok_or_else(|| Error::BadParam {
                name: "service",
                why: format!(
                    "`{name}` is none of start_round, stop_round, clear_fault, record_round"
                ),
            })?;
        let client = &self.clients[i];
        let id = client
            .send_request(TriggerRequest::default())
            .map_err(|e| dds(format!("call {name}"), e))?;
        let end = Instant::now() + timeout;
        while Instant::now() < end {
            while let Ok(Some((got, r))) = client.receive_response() {
                if got == id {
                    return Ok(r);
                }
            }
            between();
            std::thread::sleep(Duration::from_millis(1));
        }
        Err(dds(format!("call {name}"), "no answer in time"))
    }
}
