//! Reading an MCAP file into per-topic time series: schemas, channels and messages, every
//! message of a selected topic decoded, its time taken and checked.

use std::collections::BTreeMap;
use std::path::Path;

use mcap::read::parse_record;
use mcap::records::{Record, op};
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};

use crate::msg::{self, ALL_TYPES, MsgType, joint_columns};
use crate::{Error, GAP_FACTOR, Result};

/// MCAP channel metadata key: the channel name of every value column, comma-separated, in
/// the column order of the message type (an empty entry drops that column). Written by
/// tandem so that a run reads back with the model's own channel names.
pub const FIELDS_KEY: &str = "tandem.fields";
/// MCAP channel metadata key: what a topic is to tandem (see [`Role`]).
pub const ROLE_KEY: &str = "tandem.role";
/// The topic of the schedule messages of a run (one per round, at its start; JSON).
pub const SCHEDULE_TOPIC: &str = "/tandem/schedule";

/// What a topic is to tandem.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// Channels of a demonstration or execution (the default).
    Channel,
    /// An execution's reference-time log (`Float64`, reference samples).
    RefSample,
    /// An execution's `supervised` flag (`Bool`: the robot was low-confidence).
    Supervised,
    /// An execution's `corrected` flag (`Bool`: the operator corrected it).
    Corrected,
    /// Written for viewing only (schedule clock, waiting flag); never read as data.
    View,
}

impl Role {
    /// The metadata value (and the derived channel name that implies the role).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Role::Channel => "channel",
            Role::RefSample => "ref_sample",
            Role::Supervised => "supervised",
            Role::Corrected => "corrected",
            Role::View => "view",
        }
    }

    fn parse(s: &str) -> Option<Role> {
        [
            Role::Channel,
            Role::RefSample,
            Role::Supervised,
            Role::Corrected,
            Role::View,
        ]
        .into_iter()
        .find(|r| r.name() == s)
    }
}

/// The supported types, for messages.
pub(crate) fn supported_list() -> String {
    ALL_TYPES
        .iter()
        .map(|t| t.ros_name())
        .collect::<Vec<_>>()
        .join(", ")
}

/// A channel record as read.
#[derive(Clone, Debug)]
struct ChannelRec {
    topic: String,
    schema_id: u16,
    message_encoding: String,
    metadata: BTreeMap<String, String>,
}

/// Which topics to decode.
#[derive(Clone, Debug, Default)]
pub(crate) struct Selection<'a> {
    /// Explicit topics (full names); `None`: every topic of a supported type.
    pub(crate) topics: Option<&'a [String]>,
    /// Only topics under this namespace (`/robot_1`), named relative to it.
    pub(crate) namespace: Option<&'a str>,
    /// Also decode [`Role::View`] topics (inspection).
    pub(crate) views: bool,
}

/// One topic of the file.
#[derive(Clone, Debug)]
pub(crate) struct RawTopic {
    /// Full topic name.
    pub(crate) topic: String,
    /// Schema name (`geometry_msgs/msg/PoseStamped`), or `None` without a schema.
    pub(crate) schema: Option<String>,
    /// Schema encoding.
    pub(crate) schema_encoding: String,
    /// Message encoding (`cdr`, `json`).
    pub(crate) message_encoding: String,
    /// The supported type, if any.
    pub(crate) msg_type: Option<MsgType>,
    /// Channel metadata.
    pub(crate) metadata: BTreeMap<String, String>,
    /// Whether its messages are decoded.
    pub(crate) selected: bool,
    /// Messages seen.
    pub(crate) count: usize,
    /// Log time (ns) of every decoded message.
    pub(crate) log_ns: Vec<i64>,
    /// Header stamp (ns) of every decoded message (types with a header).
    pub(crate) stamp_ns: Vec<i64>,
    /// Value columns of every decoded message, message-major.
    pub(crate) values: Vec<f64>,
    /// Column suffixes ([`MsgType::fixed_columns`] or the joint columns).
    pub(crate) columns: Vec<String>,
    /// JSON payloads (the schedule topic).
    pub(crate) json: Vec<Vec<u8>>,
    /// A `JointState`'s joint names and whether it has velocities and efforts (from its first
    /// message; every message must have the same).
    pub(crate) joints: (Vec<String>, (bool, bool)),
}

impl RawTopic {
    /// Number of value columns.
    pub(crate) fn width(&self) -> usize {
        self.columns.len()
    }

    /// Its role: metadata, else implied by a one-column topic's relative name.
    pub(crate) fn role(&self, namespace: Option<&str>) -> Role {
        if let Some(r) = self.metadata.get(ROLE_KEY).and_then(|s| Role::parse(s)) {
            return r;
        }
        if self.columns.len() == 1 {
            let stem = relative_name(&self.topic, namespace);
            return match (stem.as_str(), self.msg_type) {
                ("ref_sample", Some(MsgType::Float64)) => Role::RefSample,
                ("supervised", Some(MsgType::Bool)) => Role::Supervised,
                ("corrected", Some(MsgType::Bool)) => Role::Corrected,
                _ => Role::Channel,
            };
        }
        Role::Channel
    }

    /// The channel name of every column (`None`: dropped by the metadata), from the
    /// metadata when the channel has [`FIELDS_KEY`], else derived from the topic name
    /// relative to `namespace` and the column suffix.
    pub(crate) fn channel_names(&self, namespace: Option<&str>) -> Vec<Option<String>> {
        if let Some(fields) = self.metadata.get(FIELDS_KEY) {
            let names: Vec<&str> = fields.split(',').map(str::trim).collect();
            if names.len() == self.width() {
                return names
                    .into_iter()
                    .map(|n| (!n.is_empty()).then(|| n.to_owned()))
                    .collect();
            }
        }
        let stem = relative_name(&self.topic, namespace);
        self.columns
            .iter()
            .map(|c| {
                Some(if c.is_empty() {
                    stem.clone()
                } else {
                    format!("{stem}.{c}")
                })
            })
            .collect()
    }
}

/// A topic's name relative to `namespace`, without the leading `/` (`/robot_1/force` under
/// `/robot_1` is `force`; `/pose` is `pose`).
pub(crate) fn relative_name(topic: &str, namespace: Option<&str>) -> String {
    let rest = match namespace {
        Some(ns) => topic
            .strip_prefix(ns.trim_end_matches('/'))
            .and_then(|r| r.strip_prefix('/'))
            .unwrap_or(topic),
        None => topic,
    };
    rest.trim_start_matches('/').to_owned()
}

/// Whether `topic` lies under `namespace`.
pub(crate) fn under(topic: &str, namespace: &str) -> bool {
    let ns = namespace.trim_end_matches('/');
    topic.strip_prefix(ns).is_some_and(|r| r.starts_with('/'))
}

/// The MCAP reader's error as this crate's, naming the file.
fn mcap_error(file: &str, e: mcap::McapError) -> Error {
    use mcap::McapError as E;
    match e {
        E::BadMagic => Error::NotMcap { file: file.into() },
        E::UnexpectedEof | E::UnexpectedEoc | E::BadFooter => Error::Truncated {
            file: file.into(),
            why: e.to_string(),
        },
        other => Error::Corrupt {
            file: file.into(),
            why: other.to_string(),
        },
    }
}

/// Every topic of the MCAP file at `path`, the selected ones decoded (file order of their
/// channel records). Decoding errors, bad values and unknown or missing schemas of selected
/// topics are errors here; times are checked later, per window.
pub(crate) fn read_topics(path: &Path, sel: &Selection<'_>) -> Result<Vec<RawTopic>> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| Error::Io {
        file: file.clone(),
        what: "cannot read",
        source,
    })?;
    if !bytes.starts_with(mcap::MAGIC) {
        if mcap::MAGIC.starts_with(&bytes) {
            return Err(Error::Truncated {
                file,
                why: format!("{} bytes, shorter than the magic", bytes.len()),
            });
        }
        return Err(Error::NotMcap { file });
    }
    read_bytes(&bytes, &file, sel)
}

/// Largest record the reader accepts beyond the file's own length: 256 MiB (a decompressed
/// chunk's record may exceed the compressed file; a corrupt length must not make the reader
/// allocate without bound).
const RECORD_LIMIT: usize = 256 << 20;

fn read_bytes(bytes: &[u8], file: &str, sel: &Selection<'_>) -> Result<Vec<RawTopic>> {
    // The sans-io reader yields every record borrowed from its buffer (chunks decompressed
    // and their CRCs checked), so a message's payload is decoded where it lies, not copied.
    let options = LinearReaderOptions::default()
        .with_validate_chunk_crcs(true)
        .with_record_length_limit(bytes.len() + RECORD_LIMIT);
    let mut reader = LinearReader::new_with_options(options);
    let mut rest = bytes;
    let mut schemas: BTreeMap<u16, (String, String)> = BTreeMap::new();
    let mut channels: BTreeMap<u16, usize> = BTreeMap::new();
    let mut topics: Vec<RawTopic> = Vec::new();
    let mut by_name: BTreeMap<String, usize> = BTreeMap::new();
    while let Some(event) = reader.next_event() {
        let (opcode, data) = match event.map_err(|e| mcap_error(file, e))? {
            LinearReadEvent::ReadRequest(need) => {
                let len = need.min(rest.len());
                reader.insert(len).copy_from_slice(&rest[..len]);
                reader.notify_read(len);
                rest = &rest[len..];
                continue;
            }
            LinearReadEvent::Record { opcode, data } => (opcode, data),
        };
        if opcode == op::MESSAGE {
            let (channel_id, log_time, payload) =
                message_parts(data).ok_or_else(|| Error::Corrupt {
                    file: file.into(),
                    why: format!(
                        "a message record of {} bytes is shorter than its header",
                        data.len()
                    ),
                })?;
            let Some(&idx) = channels.get(&channel_id) else {
                return Err(Error::Corrupt {
                    file: file.into(),
                    why: format!(
                        "a message refers to channel {channel_id}, which has no channel record"
                    ),
                });
            };
            let t = &mut topics[idx];
            t.count += 1;
            if t.selected {
                add_message(t, file, log_time, payload)?;
            }
            continue;
        }
        if opcode != op::SCHEMA && opcode != op::CHANNEL {
            continue;
        }
        match parse_record(opcode, data).map_err(|e| mcap_error(file, e))? {
            Record::Schema { header, .. } => {
                schemas
                    .entry(header.id)
                    .or_insert((header.name, header.encoding));
            }
            Record::Channel(c) => {
                if channels.contains_key(&c.id) {
                    continue;
                }
                let rec = ChannelRec {
                    topic: c.topic,
                    schema_id: c.schema_id,
                    message_encoding: c.message_encoding,
                    metadata: c.metadata,
                };
                let idx = match by_name.get(&rec.topic) {
                    Some(&k) => k,
                    None => {
                        let t = new_topic(&rec, &schemas, sel);
                        topics.push(t);
                        by_name.insert(rec.topic.clone(), topics.len() - 1);
                        topics.len() - 1
                    }
                };
                channels.insert(c.id, idx);
            }
            _ => {}
        }
    }
    check_selection(&topics, file, sel)?;
    Ok(topics)
}

/// A message record's channel ID, log time and payload (its header is channel ID `u16`,
/// sequence `u32`, log and publish time `u64`, little-endian).
fn message_parts(data: &[u8]) -> Option<(u16, u64, &[u8])> {
    let channel = u16::from_le_bytes(data.get(0..2)?.try_into().ok()?);
    let log_time = u64::from_le_bytes(data.get(6..14)?.try_into().ok()?);
    Some((channel, log_time, data.get(22..)?))
}

/// A topic for a new channel record: its type, whether it is selected.
fn new_topic(
    rec: &ChannelRec,
    schemas: &BTreeMap<u16, (String, String)>,
    sel: &Selection<'_>,
) -> RawTopic {
    let schema = schemas.get(&rec.schema_id);
    let msg_type = schema.and_then(|(name, encoding)| {
        (encoding == "ros2msg" && rec.message_encoding == "cdr")
            .then(|| MsgType::from_ros_name(name))
            .flatten()
    });
    let in_namespace = sel.namespace.is_none_or(|ns| under(&rec.topic, ns));
    let mut t = RawTopic {
        topic: rec.topic.clone(),
        schema: schema.map(|s| s.0.clone()),
        schema_encoding: schema.map(|s| s.1.clone()).unwrap_or_default(),
        message_encoding: rec.message_encoding.clone(),
        msg_type,
        metadata: rec.metadata.clone(),
        selected: false,
        count: 0,
        log_ns: Vec::new(),
        stamp_ns: Vec::new(),
        values: Vec::new(),
        columns: msg_type
            .map(|m| m.fixed_columns().iter().map(|c| (*c).to_owned()).collect())
            .unwrap_or_default(),
        json: Vec::new(),
        joints: (Vec::new(), (false, false)),
    };
    let explicit = sel.topics.is_some_and(|l| l.contains(&t.topic));
    let is_view = t.role(sel.namespace) == Role::View;
    t.selected = if rec.topic == SCHEDULE_TOPIC {
        t.message_encoding == "json"
    } else if sel.topics.is_some() {
        explicit
    } else {
        in_namespace && (schema.is_none() || msg_type.is_some()) && (sel.views || !is_view)
    };
    t
}

/// Appends one message of a selected topic.
fn add_message(t: &mut RawTopic, file: &str, log_time: u64, data: &[u8]) -> Result<()> {
    let index = t.count;
    let Some(msg_type) = t.msg_type else {
        if t.topic == SCHEDULE_TOPIC {
            t.log_ns.push(log_time as i64);
            t.json.push(data.to_vec());
        }
        // A selected topic without a supported type is reported by `check_selection`.
        return Ok(());
    };
    let bad = |why: String| Error::BadMessage {
        file: file.into(),
        topic: t.topic.clone(),
        index,
        why,
    };
    let log_ns = i64::try_from(log_time).map_err(|_| bad(format!("log time {log_time} ns")))?;
    let start = t.values.len();
    let d = msg::decode(msg_type, data, &mut t.values).map_err(bad)?;
    if msg_type == MsgType::JointState {
        if t.log_ns.is_empty() {
            t.columns = joint_columns(&d.joint_names, d.joint_arrays.0, d.joint_arrays.1);
            t.joints = (d.joint_names, d.joint_arrays);
        } else if (&d.joint_names, d.joint_arrays) != (&t.joints.0, t.joints.1) {
            t.values.truncate(start);
            let cols = joint_columns(&d.joint_names, d.joint_arrays.0, d.joint_arrays.1);
            return Err(Error::BadMessage {
                file: file.into(),
                topic: t.topic.clone(),
                index,
                why: format!(
                    "joint names or arrays {:?} differ from the first message's {:?}",
                    cols, t.columns
                ),
            });
        }
    }
    let row = &t.values[start..];
    if let Some(j) = row
        .iter()
        .position(|v| !v.is_finite() || v.abs() > tandem_lfd::MAX_ABS_VALUE)
    {
        let v = row[j];
        let why = if v.is_finite() {
            format!(
                "value {v:e} is beyond ±{:e} (check the units)",
                tandem_lfd::MAX_ABS_VALUE
            )
        } else {
            format!("non-finite value {v}")
        };
        let field = match t.columns[j].as_str() {
            "" => "data".to_owned(),
            c => c.to_owned(),
        };
        return Err(Error::BadValue {
            file: file.into(),
            topic: t.topic.clone(),
            index,
            field,
            why,
        });
    }
    if msg_type == MsgType::PoseStamped {
        let q = &row[3..7];
        let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        if (norm - 1.0).abs() > QUAT_NORM_TOL {
            return Err(Error::BadValue {
                file: file.into(),
                topic: t.topic.clone(),
                index,
                field: "orientation".into(),
                why: format!(
                    "quaternion ({}, {}, {}, {}) has norm {norm}, not 1 (within {QUAT_NORM_TOL})",
                    q[0], q[1], q[2], q[3]
                ),
            });
        }
    }
    t.log_ns.push(log_ns);
    if let Some(s) = d.stamp_ns {
        t.stamp_ns.push(s);
    }
    Ok(())
}

/// Largest accepted deviation of an orientation's norm from 1: 1e-3 (a quaternion written
/// as floats and renormalized by its publisher is within 1e-6; an unset orientation,
/// all zeros, is not a rotation).
pub const QUAT_NORM_TOL: f64 = 1e-3;

/// Checks that every explicitly selected topic exists and has a supported type, that every
/// selected topic has a schema, and that something was selected.
fn check_selection(topics: &[RawTopic], file: &str, sel: &Selection<'_>) -> Result<()> {
    let list = || {
        topics
            .iter()
            .map(|t| {
                format!(
                    "{} ({})",
                    t.topic,
                    t.schema.as_deref().unwrap_or("no schema")
                )
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    if let Some(wanted) = sel.topics {
        for w in wanted {
            if !topics.iter().any(|t| t.topic == *w) {
                return Err(Error::TopicNotFound {
                    file: file.into(),
                    topic: w.clone(),
                    available: list(),
                });
            }
        }
    }
    for t in topics
        .iter()
        .filter(|t| t.selected && t.topic != SCHEDULE_TOPIC)
    {
        let Some(schema) = &t.schema else {
            return Err(Error::MissingSchema {
                file: file.into(),
                topic: t.topic.clone(),
            });
        };
        if t.msg_type.is_none() {
            return Err(Error::UnknownSchema {
                file: file.into(),
                topic: t.topic.clone(),
                schema: schema.clone(),
                encoding: format!("{}/{}", t.schema_encoding, t.message_encoding),
            });
        }
    }
    if !topics.iter().any(|t| t.selected && t.msg_type.is_some()) {
        return Err(Error::NoSupportedTopics {
            file: file.into(),
            found: if topics.is_empty() {
                "no topics".into()
            } else {
                list()
            },
        });
    }
    Ok(())
}

/// A selected topic's messages inside a window, with their times checked.
#[derive(Clone, Debug)]
pub(crate) struct Series {
    /// Message times (ns, bag time): header stamps, or log times for types without a header
    /// and for topics whose stamps are all zero.
    pub(crate) times_ns: Vec<i64>,
    /// Whether `times_ns` are log times.
    pub(crate) log_time: bool,
    /// The window's values, message-major ([`RawTopic::width`] per message).
    pub(crate) values: Vec<f64>,
    /// The topic's median message period (ns).
    pub(crate) median_ns: i64,
    /// The topic's message period (ns) as for a CSV `t` column: the span over the steps
    /// counted in median periods, snapped to a whole rate within 0.1 %
    /// ([`tandem_lfd::logger_period`]), so a 50 Hz topic whose stamps run 0.07 % slow has a
    /// period of exactly 20 ms.
    pub(crate) period_ns: f64,
}

/// The messages of topic `t` with log time in `window` (`[start, end)`
/// ns; all when `None`), with times checked: at least 2 messages, strictly increasing, no
/// gap over [`GAP_FACTOR`] × the median period (unless `gaps_allowed`: the whole of a run of
/// several rounds, between which a robot is idle).
pub(crate) fn series(
    t: &RawTopic,
    file: &str,
    window: Option<(i64, i64)>,
    gaps_allowed: bool,
) -> Result<Series> {
    let use_log = t.stamp_ns.len() != t.log_ns.len() || t.stamp_ns.iter().all(|&s| s == 0);
    let keep: Vec<usize> = (0..t.log_ns.len())
        .filter(|&k| window.is_none_or(|(a, b)| (a..b).contains(&t.log_ns[k])))
        .collect();
    if keep.len() < 2 {
        return Err(Error::TooFewMessages {
            file: file.into(),
            topic: t.topic.clone(),
            found: keep.len(),
        });
    }
    let w = t.width();
    let src = if use_log { &t.log_ns } else { &t.stamp_ns };
    let times_ns: Vec<i64> = keep.iter().map(|&k| src[k]).collect();
    let values: Vec<f64> = if keep.len() == t.log_ns.len() {
        t.values.clone()
    } else {
        keep.iter()
            .flat_map(|&k| t.values[k * w..(k + 1) * w].iter().copied())
            .collect()
    };
    let first_index = keep[0] + 1;
    let clock = if use_log { "log time" } else { "header stamp" };
    for k in 1..times_ns.len() {
        if times_ns[k] <= times_ns[k - 1] {
            return Err(Error::TimeNotIncreasing {
                file: file.into(),
                topic: t.topic.clone(),
                index: first_index + k,
                clock,
                this_s: times_ns[k] as f64 / 1e9,
                previous_s: times_ns[k - 1] as f64 / 1e9,
            });
        }
    }
    let mut periods: Vec<i64> = times_ns.windows(2).map(|p| p[1] - p[0]).collect();
    periods.sort_unstable();
    let median_ns = periods[(periods.len() - 1) / 2];
    for k in (1..times_ns.len()).filter(|_| !gaps_allowed) {
        let gap = times_ns[k] - times_ns[k - 1];
        if gap as f64 > GAP_FACTOR * median_ns as f64 {
            return Err(Error::Gap {
                file: file.into(),
                topic: t.topic.clone(),
                index: first_index + k,
                gap_s: gap as f64 / 1e9,
                median_s: median_ns as f64 / 1e9,
            });
        }
    }
    let secs: Vec<f64> = times_ns.iter().map(|&t| t as f64 / 1e9).collect();
    let period_ns = tandem_lfd::logger_period(&secs)
        .map_or(median_ns as f64, |p| (p * 1e9 * 1e3).round() / 1e3);
    Ok(Series {
        times_ns,
        log_time: use_log,
        values,
        median_ns,
        period_ns,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_relative_to_a_namespace() {
        assert_eq!(relative_name("/robot_1/force", Some("/robot_1")), "force");
        assert_eq!(relative_name("/robot_1/force", Some("/robot_1/")), "force");
        assert_eq!(relative_name("/pose", None), "pose");
        assert_eq!(relative_name("/robot_10/x", Some("/robot_1")), "robot_10/x");
        assert!(under("/robot_1/x", "/robot_1"));
        assert!(!under("/robot_10/x", "/robot_1"));
    }
}
