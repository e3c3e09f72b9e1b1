//! Simulated runs as MCAP: per robot the commanded pose and channels, the low-confidence
//! (`supervised`) and `corrected` flags, the reference-time log, the schedule clock and
//! whether it waits for its start, and per round the schedule; what [`read_executions`]
//! reads back.
//!
//! [`read_executions`]: crate::read_executions

use std::collections::BTreeMap;
use std::path::Path;

use serde_json::json;
use tandem_lfd::ChannelKind;
use tandem_planner::Planner;
use tandem_schedule::GlobalTimeline;
use tandem_sim::workcell::RoundRun;

use crate::msg::MsgType;
use crate::read::{Role, SCHEDULE_TOPIC};
use crate::recording::robot_namespace;
use crate::write::{BagWriter, Existing, Message, TopicId, metadata};
use crate::{Error, Result};

/// The JSON Schema of the schedule messages (one per round on [`SCHEDULE_TOPIC`]).
pub const SCHEDULE_SCHEMA: &str = r#"{
  "title": "tandem.Schedule",
  "description": "The schedule a round of a tandem run ran under (global time of the round: robot 1 starts at 0 s).",
  "type": "object",
  "properties": {
    "round": {"type": "integer", "description": "1-based round of the run"},
    "start_time_s": {"type": "number", "description": "bag time of the round's first tick (s)"},
    "n_robots": {"type": "integer"},
    "t_total_s": {"type": "number", "description": "T_total of the schedule (Eq. 13), s"},
    "lower_bound_s": {"type": "number", "description": "certified lower bound on T_total (s)"},
    "offsets_s": {"type": "array", "items": {"type": "number"}, "description": "start offsets of robots 2..N (s)"},
    "durations_s": {"type": "array", "items": {"type": "number"}, "description": "scheduled execution durations (s)"},
    "dt_s": {"type": "number", "description": "reference sample period (s)"},
    "tick_s": {"type": "number", "description": "control tick the schedule was checked at (s)"},
    "n_ref": {"type": "integer", "description": "reference samples"},
    "ticks": {"type": "integer", "description": "control ticks the round took"},
    "sample_stamps": {"type": "string", "description": "\"tick\": each logged sample is stamped at the tick it ran in (a robot at a hold or held logs nothing in those ticks); absent in bags of older builds, which stamped the k-th sample at start_tick + k"},
    "lc_intervals": {"type": "array", "items": {"type": "object", "properties": {
      "robot": {"type": "integer"}, "ref_start": {"type": "integer"}, "ref_end": {"type": "integer"},
      "start_s": {"type": "number"}, "end_s": {"type": "number"}}}},
    "schedule": {"type": "object", "description": "tandem::schedule::Schedule: grad_exec (per robot, execution samples per reference sample), offsets_s, tick_s"}
  }
}"#;

/// One channel or flag topic of a robot.
#[derive(Clone, Debug)]
enum Slot {
    /// A `PoseStamped` from model channels `cols` (`x, y, z, qx, qy, qz, qw`; `None`: 0).
    Pose(TopicId, [Option<usize>; 7]),
    /// A `Float64` of model channel `c`.
    Channel(TopicId, usize),
    /// A `Bool` of model channel `c`, a binary channel ([`ChannelKind::Binary`]): true where
    /// the commanded value is at least 0.5.
    Flag(TopicId, usize),
}

/// A robot's topics.
#[derive(Clone, Debug)]
struct RobotTopics {
    slots: Vec<Slot>,
    ref_sample: TopicId,
    supervised: TopicId,
    corrected: TopicId,
    clock: TopicId,
    waiting: TopicId,
}

/// A ROS 2 topic name token for a channel name: letters, digits and `_` kept, a `.` becomes
/// `/`, anything else `_`; a token starting with a digit gets a `c` in front.
fn topic_token(name: &str) -> String {
    let mapped: String = name
        .chars()
        .map(|c| match c {
            'a'..='z' | 'A'..='Z' | '0'..='9' | '_' => c,
            '.' | '/' => '/',
            _ => '_',
        })
        .collect();
    mapped
        .split('/')
        .filter(|t| !t.is_empty())
        .map(|t| {
            if t.starts_with(|c: char| c.is_ascii_digit()) {
                format!("c{t}")
            } else {
                t.to_owned()
            }
        })
        .collect::<Vec<_>>()
        .join("/")
}

/// Writes a simulated run round by round ([`RunWriter::write_round`]); the file appears at
/// [`RunWriter::finish`].
///
/// Layout (docs/formats.md, "Runs as bags"), for robot `i` under `/robot_<i>`:
/// one `geometry_msgs/msg/PoseStamped` per quaternion block of the model whose four channels
/// it has (`tool_pose` for the block `q`; position from the channels `x, y, z` beside it,
/// 0 where missing), a `std_msgs/msg/Bool` per binary channel of the fit's channel schema
/// ([`ChannelKind::Binary`]: a bag's `Bool` topics, a CSV's `tool`; true where the command is
/// at least 0.5, as a valve is driven, so such a channel reads back as 0 or 1), a
/// `std_msgs/msg/Float64` per other channel, `ref_sample` (`Float64`,
/// reference samples), `supervised` and `corrected` (`std_msgs/msg/Bool`), one message each
/// per control tick the robot ran; `schedule_clock` (`Float64`, s) and `waiting` (`Bool`)
/// at every tick of the round. `/tandem/schedule` holds one JSON message per round at its
/// first tick ([`SCHEDULE_SCHEMA`]). Rounds follow each other on one clock; tick `k` of a
/// round is at bag time `start + k·Δt_s`, and each sample is stamped at the tick it ran in
/// ([`RobotRun::phases`](tandem_sim::workcell::RobotRun::phases)' running ticks: a robot
/// standing at a hold point or held by the fault monitor logs no sample, so its later
/// samples are not stamped early). Each channel record names its model channels
/// ([`crate::FIELDS_KEY`]) and role ([`crate::ROLE_KEY`]), so the executions read back with
/// the model's names.
#[derive(Debug)]
pub struct RunWriter {
    bag: BagWriter,
    robots: Vec<RobotTopics>,
    schedule: TopicId,
    n_channels: usize,
    next_start_ns: i64,
    rounds: usize,
}

impl RunWriter {
    /// Starts a run of `planner`'s robots and channels at `path`, zstd-compressed.
    ///
    /// # Errors
    /// As [`BagWriter::create`] and [`BagWriter::add_topic`].
    pub fn create(path: impl AsRef<Path>, planner: &Planner, existing: Existing) -> Result<Self> {
        let mut bag = BagWriter::create(path, true, existing)?;
        let model = planner.model();
        let names = model.channel_names();
        let schema = &planner.params().fit.schema;
        let index = |n: &str| names.iter().position(|c| c == n);
        // Pose topics from the quaternion blocks, the rest as Float64 channels.
        let mut poses: Vec<(String, [Option<usize>; 7])> = Vec::new();
        let mut used = vec![false; names.len()];
        for block in &schema.quaternions {
            let q: Vec<Option<usize>> = block.channels.iter().map(|c| index(c)).collect();
            if q.iter().any(Option::is_none) {
                continue;
            }
            let stem = block.name.strip_suffix('q').unwrap_or("");
            let pos = ["x", "y", "z"].map(|a| index(&format!("{stem}{a}")));
            let cols = [pos[0], pos[1], pos[2], q[0], q[1], q[2], q[3]];
            for c in cols.iter().flatten() {
                used[*c] = true;
            }
            let topic = match topic_token(stem.trim_end_matches(['.', '_'])) {
                t if t.is_empty() => "tool_pose".to_owned(),
                t => t,
            };
            poses.push((topic, cols));
        }
        let mut robots = Vec::with_capacity(planner.n_robots());
        for i in 1..=planner.n_robots() {
            let ns = robot_namespace(i);
            let mut taken: Vec<String> = Vec::new();
            let mut unique = |token: String| {
                let mut name = token.clone();
                let mut k = 2;
                while taken.contains(&name) {
                    name = format!("{token}_{k}");
                    k += 1;
                }
                taken.push(name.clone());
                format!("{ns}/{name}")
            };
            let mut slots = Vec::new();
            for (topic, cols) in &poses {
                let fields: Vec<String> = cols
                    .iter()
                    .map(|c| c.map(|k| names[k].clone()).unwrap_or_default())
                    .collect();
                let id = bag.add_topic(
                    &unique(topic.clone()),
                    MsgType::PoseStamped,
                    &metadata(&fields, Role::Channel),
                )?;
                slots.push(Slot::Pose(id, *cols));
            }
            for (c, name) in names.iter().enumerate().filter(|(c, _)| !used[*c]) {
                let token = match topic_token(name) {
                    t if t.is_empty() => format!("channel_{c}"),
                    t => t,
                };
                let binary = schema.kind(name) == ChannelKind::Binary;
                let id = bag.add_topic(
                    &unique(token),
                    if binary {
                        MsgType::Bool
                    } else {
                        MsgType::Float64
                    },
                    &metadata(std::slice::from_ref(name), Role::Channel),
                )?;
                slots.push(if binary {
                    Slot::Flag(id, c)
                } else {
                    Slot::Channel(id, c)
                });
            }
            let mut flag = |name: &str, t: MsgType, role: Role| {
                let topic = unique(name.to_owned());
                bag.add_topic(&topic, t, &metadata(&[name.to_owned()], role))
            };
            let ref_sample = flag("ref_sample", MsgType::Float64, Role::RefSample)?;
            let supervised = flag("supervised", MsgType::Bool, Role::Supervised)?;
            let corrected = flag("corrected", MsgType::Bool, Role::Corrected)?;
            let clock = flag("schedule_clock", MsgType::Float64, Role::View)?;
            let waiting = flag("waiting", MsgType::Bool, Role::View)?;
            robots.push(RobotTopics {
                slots,
                ref_sample,
                supervised,
                corrected,
                clock,
                waiting,
            });
        }
        let mut meta = BTreeMap::new();
        meta.insert(crate::ROLE_KEY.to_owned(), Role::View.name().to_owned());
        let schedule =
            bag.add_json_topic(SCHEDULE_TOPIC, "tandem.Schedule", SCHEDULE_SCHEMA, &meta)?;
        Ok(Self {
            bag,
            robots,
            schedule,
            n_channels: names.len(),
            next_start_ns: 0,
            rounds: 0,
        })
    }

    /// Rounds written so far.
    #[must_use]
    pub fn rounds(&self) -> usize {
        self.rounds
    }

    /// Writes one round: `run` as run by `planner` (the planner *before* the round is
    /// recorded into it, whose schedule the round ran).
    ///
    /// # Errors
    /// [`Error::Layout`] when the run does not fit the writer's robots and channels, and the
    /// writer's errors.
    pub fn write_round(&mut self, planner: &Planner, run: &RoundRun) -> Result<()> {
        let file = "<run>".to_owned();
        if run.robots.len() != self.robots.len() {
            return Err(Error::Layout {
                file,
                why: format!(
                    "a round of {} robots for a run of {}",
                    run.robots.len(),
                    self.robots.len()
                ),
            });
        }
        let dt_ns = planner.model().dt_s() * 1e9;
        let start = self.next_start_ns;
        let at = |tick: usize| start + (tick as f64 * dt_ns).round() as i64;
        self.rounds += 1;
        let doc = schedule_doc(planner, self.rounds, start, run.ticks)?;
        self.bag.write_json(self.schedule, start, &doc)?;
        let m = self.n_channels;
        for (robot, topics) in run.robots.iter().zip(&self.robots) {
            let n = robot.ref_time_log.len();
            if robot.samples.len() != n * m || robot.clock_s.len() != run.ticks {
                return Err(Error::Layout {
                    file,
                    why: format!(
                        "a robot's run has {} values for {n} samples of {m} channels and {} \
                         clocks for {} ticks",
                        robot.samples.len(),
                        robot.clock_s.len(),
                        run.ticks
                    ),
                });
            }
            let stamps = sample_ticks(robot, run.ticks).map_err(|why| Error::Layout {
                file: file.clone(),
                why,
            })?;
            for (k, &tick) in stamps.iter().enumerate() {
                let t = at(tick);
                let row = &robot.samples[k * m..(k + 1) * m];
                for slot in &topics.slots {
                    match slot {
                        Slot::Pose(id, cols) => {
                            let v = |i: usize, d: f64| cols[i].map_or(d, |c| row[c]);
                            let message = Message::Pose {
                                position: [v(0, 0.0), v(1, 0.0), v(2, 0.0)],
                                orientation: [v(3, 0.0), v(4, 0.0), v(5, 0.0), v(6, 1.0)],
                            };
                            self.bag.write(*id, t, &message)?;
                        }
                        Slot::Channel(id, c) => {
                            self.bag.write(*id, t, &Message::Float64(row[*c]))?;
                        }
                        Slot::Flag(id, c) => {
                            self.bag.write(*id, t, &Message::Bool(row[*c] >= 0.5))?;
                        }
                    }
                }
                self.bag.write(
                    topics.ref_sample,
                    t,
                    &Message::Float64(robot.ref_time_log[k]),
                )?;
                self.bag
                    .write(topics.supervised, t, &Message::Bool(robot.supervised[k]))?;
                self.bag
                    .write(topics.corrected, t, &Message::Bool(robot.corrected[k]))?;
            }
            for (tick, &clock) in robot.clock_s.iter().enumerate() {
                let t = at(tick);
                self.bag.write(topics.clock, t, &Message::Float64(clock))?;
                self.bag
                    .write(topics.waiting, t, &Message::Bool(tick < robot.start_tick))?;
            }
        }
        self.next_start_ns = at(run.ticks);
        Ok(())
    }

    /// Finishes the file and puts it at its path.
    ///
    /// # Errors
    /// As [`BagWriter::finish`].
    pub fn finish(self) -> Result<()> {
        self.bag.finish()
    }
}

/// The round's tick (0-based) of each of `robot`'s logged samples: the ticks its
/// [`RobotRun::phases`](tandem_sim::workcell::RobotRun::phases) say it ran (one sample per
/// running tick); without phases (a run built by hand) `start_tick + k`, which is exact only
/// without hold ticks. An error (the reason) when they do not account for its samples.
fn sample_ticks(
    robot: &tandem_sim::workcell::RobotRun,
    ticks: usize,
) -> std::result::Result<Vec<usize>, String> {
    use tandem_sim::workcell::TickPhase;
    let n = robot.ref_time_log.len();
    if robot.phases.is_empty() {
        if robot.hold_ticks > 0 {
            return Err(format!(
                "a robot's run has {} ticks at holds but no phases to stamp its samples by",
                robot.hold_ticks
            ));
        }
        return Ok((robot.start_tick..robot.start_tick + n).collect());
    }
    let running: Vec<usize> = (0..robot.phases.len())
        .filter(|&k| robot.phases[k] == TickPhase::Running)
        .collect();
    if robot.phases.len() != ticks || running.len() != n {
        return Err(format!(
            "a robot's run has {} phases for {ticks} ticks and {} running ticks for {n} \
             samples",
            robot.phases.len(),
            running.len()
        ));
    }
    Ok(running)
}

/// One robot of a round read back from a run ([`read_run`]), tick by tick of the round.
#[derive(Clone, Debug, PartialEq)]
pub struct RunRobotLog {
    /// The round's tick (0-based) at which the robot started (its ticks before it waited).
    pub start_tick: usize,
    /// The round's tick (0-based) of each logged sample, strictly increasing from
    /// `start_tick`: consecutive while the robot runs, with a gap for each tick it stood at a
    /// hold point or was held by the fault monitor.
    pub sample_ticks: Vec<usize>,
    /// Its reference time (reference samples) at each tick it ran (`sample_ticks`).
    pub ref_time: Vec<f64>,
    /// Whether the operator supervised it in each tick it ran (`supervised`).
    pub supervised: Vec<bool>,
    /// Its schedule clock (s) at every tick of the round.
    pub clock_s: Vec<f64>,
}

/// One round of a run read back ([`read_run`]).
#[derive(Clone, Debug, PartialEq)]
pub struct RunRoundLog {
    /// The round (1-based).
    pub round: usize,
    /// Control ticks the round took.
    pub ticks: usize,
    /// The period between ticks (s): the model's `Δt_s`, the bag's tick spacing.
    pub dt_s: f64,
    /// `T_total` (s) of the schedule the round ran (Eq. 13).
    pub t_total_s: f64,
    /// Every robot, robot 1 first.
    pub robots: Vec<RunRobotLog>,
}

/// Reads back, tick by tick, every round of a run [`RunWriter`] wrote for `n_robots` robots:
/// each robot's reference-time log, supervised flags and schedule clock, at the ticks the
/// round's schedule message and the messages' log times give (tick `k` of a round at its
/// start plus `k·Δt_s`; a robot's samples at the ticks it ran, across the ticks it stood at
/// a hold). A bag of an older build (no `sample_stamps` in its schedule messages) reads as
/// before where its schedule has no holds, and is refused where it has: that build stamped
/// the samples after a hold early.
///
/// # Errors
/// As [`read_bag`](crate::read_bag) for an unreadable, truncated or damaged file
/// ([`Error::Truncated`], [`Error::Corrupt`]); [`Error::TopicNotFound`] for a robot the bag
/// does not hold; [`Error::Layout`] for a bag without schedule messages (not a run tandem
/// wrote), a round of another robot count than `n_robots`, logs that do not fill the round's
/// ticks, or a round with holds from an older build (see above).
pub fn read_run(path: impl AsRef<Path>, n_robots: usize) -> Result<Vec<RunRoundLog>> {
    let path = path.as_ref();
    let file = path.display().to_string();
    let layout = |why: String| Error::Layout {
        file: file.clone(),
        why,
    };
    let names = ["ref_sample", "supervised", "schedule_clock"];
    let wanted: Vec<String> = (1..=n_robots)
        .flat_map(|i| names.map(|n| format!("{}/{n}", robot_namespace(i))))
        .collect();
    let sel = crate::read::Selection {
        topics: Some(&wanted),
        namespace: None,
        views: true,
    };
    let topics = crate::read::read_topics(path, &sel)?;
    let topic = |name: &str| {
        topics
            .iter()
            .find(|t| t.topic == name)
            .ok_or_else(|| layout(format!("no topic {name}")))
    };
    let schedule = topics
        .iter()
        .find(|t| t.topic == SCHEDULE_TOPIC && !t.json.is_empty())
        .ok_or_else(|| {
            layout(format!(
                "no schedule messages on {SCHEDULE_TOPIC}: not a run tandem wrote \
                 (`tandem simulate --bag`, `cargo xtask study --bag`)"
            ))
        })?;
    let mut rounds = Vec::with_capacity(schedule.json.len());
    let mut order: Vec<usize> = (0..schedule.json.len()).collect();
    order.sort_by_key(|&k| schedule.log_ns[k]);
    for (k, &m) in order.iter().enumerate() {
        let doc: serde_json::Value = serde_json::from_slice(&schedule.json[m])
            .map_err(|e| layout(format!("schedule message {}: {e}", k + 1)))?;
        let field = |name: &str| {
            doc.get(name).ok_or_else(|| {
                layout(format!(
                    "schedule message {} has no `{name}` (see SCHEDULE_SCHEMA)",
                    k + 1
                ))
            })
        };
        let ticks = field("ticks")?.as_u64().ok_or_else(|| {
            layout(format!(
                "schedule message {}: `ticks` is not a count",
                k + 1
            ))
        })? as usize;
        let dt_s = field("dt_s")?
            .as_f64()
            .filter(|d| *d > 0.0)
            .ok_or_else(|| {
                layout(format!(
                    "schedule message {}: `dt_s` is not a period",
                    k + 1
                ))
            })?;
        let t_total_s = field("t_total_s")?.as_f64().unwrap_or(f64::NAN);
        let n = field("n_robots")?.as_u64().unwrap_or(0) as usize;
        if n != n_robots {
            return Err(layout(format!(
                "round {} ran {n} robots, not {n_robots}: pass the state file of the planner \
                 the run was simulated from",
                k + 1
            )));
        }
        let by_tick = doc.get("sample_stamps").and_then(|v| v.as_str()) == Some("tick");
        let has_holds = doc
            .get("schedule")
            .and_then(|s| s.get("holds"))
            .and_then(|h| h.as_array())
            .is_some_and(|h| {
                h.iter()
                    .any(|r| r.as_array().is_some_and(|r| !r.is_empty()))
            });
        if !by_tick && has_holds {
            return Err(layout(format!(
                "round {}: its schedule has hold points and the bag was written by an older \
                 tandem that stamped each robot's samples after a hold early (at its start \
                 tick plus their count); write it again with this build (`tandem simulate \
                 --bag`)",
                k + 1
            )));
        }
        let start_ns = schedule.log_ns[m];
        let end_ns = order
            .get(k + 1)
            .map_or(i64::MAX, |&next| schedule.log_ns[next]);
        let dt_ns = dt_s * 1e9;
        let tick_of = |t_ns: i64| ((t_ns - start_ns) as f64 / dt_ns).round() as usize;
        let mut robots = Vec::with_capacity(n_robots);
        for i in 1..=n_robots {
            let ns = robot_namespace(i);
            let window = |name: &str| -> Result<Vec<(usize, f64)>> {
                let t = topic(&format!("{ns}/{name}"))?;
                Ok(t.log_ns
                    .iter()
                    .zip(&t.values)
                    .filter(|(l, _)| **l >= start_ns && **l < end_ns)
                    .map(|(l, v)| (tick_of(*l), *v))
                    .collect())
            };
            let refs = window("ref_sample")?;
            let sup = window("supervised")?;
            let clock = window("schedule_clock")?;
            let start_tick = refs.first().map_or(ticks, |r| r.0);
            let consecutive = |v: &[(usize, f64)], from: usize| {
                v.iter().enumerate().all(|(j, (tick, _))| *tick == from + j)
            };
            let increasing = refs.windows(2).all(|w| w[0].0 < w[1].0);
            if refs.len() != sup.len()
                || !increasing
                || refs.iter().zip(&sup).any(|(r, s)| r.0 != s.0)
                || refs.last().is_some_and(|r| r.0 >= ticks)
                || clock.len() != ticks
                || !consecutive(&clock, 0)
            {
                return Err(layout(format!(
                    "round {}: robot {i}'s logs do not fill the round's {ticks} ticks (one \
                     ref_sample and supervised message per tick it ran, one schedule_clock \
                     per tick); a bag cut short or edited?",
                    k + 1
                )));
            }
            robots.push(RunRobotLog {
                start_tick,
                sample_ticks: refs.iter().map(|r| r.0).collect(),
                ref_time: refs.iter().map(|r| r.1).collect(),
                supervised: sup.iter().map(|r| r.1 >= 0.5).collect(),
                clock_s: clock.iter().map(|r| r.1).collect(),
            });
        }
        rounds.push(RunRoundLog {
            round: k + 1,
            ticks,
            dt_s,
            t_total_s,
            robots,
        });
    }
    Ok(rounds)
}

/// The schedule message of round `round` (JSON).
fn schedule_doc(planner: &Planner, round: usize, start_ns: i64, ticks: usize) -> Result<String> {
    let problem = planner.problem();
    let outcome = planner.outcome();
    let s = &outcome.schedule;
    let tl = GlobalTimeline::new(problem, s)?;
    let mut intervals = Vec::new();
    for (robot, ivs) in tl.lc_intervals().iter().enumerate() {
        for iv in ivs {
            intervals.push(json!({
                "robot": robot + 1,
                "ref_start": iv.ref_start,
                "ref_end": iv.ref_end,
                "start_s": iv.start_s,
                "end_s": iv.end_s,
            }));
        }
    }
    let dt = problem.dt_s();
    let doc = json!({
        "round": round,
        "start_time_s": start_ns as f64 / 1e9,
        "n_robots": s.n_robots(),
        "t_total_s": outcome.t_total_s,
        "lower_bound_s": outcome.lower_bound_s,
        "offsets_s": s.offsets_s,
        "durations_s": s.durations_s(dt),
        "dt_s": dt,
        "tick_s": s.tick_s,
        "n_ref": problem.n_ref(),
        "ticks": ticks,
        "sample_stamps": "tick",
        "lc_intervals": intervals,
        "schedule": serde_json::to_value(s).map_err(|e| Error::Write {
            file: "<run>".into(),
            why: e.to_string(),
        })?,
    });
    Ok(doc.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn topic_tokens_are_ros_names() {
        assert_eq!(topic_token("force"), "force");
        assert_eq!(topic_token("wrench.fx"), "wrench/fx");
        assert_eq!(topic_token("joints.3.position"), "joints/c3/position");
        assert_eq!(topic_token("a-b c"), "a_b_c");
        assert_eq!(topic_token("."), "");
    }
}
