//! Writing MCAP files: [`BagWriter`] (topics of the six ROS 2 types in CDR and JSON topics
//! with a JSON Schema), and [`write_demonstration`], a demonstration as a bag of topics at
//! their own rates.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use mcap::records::MessageHeader;
use mcap::{Compression, WriteOptions, Writer};
use tandem_lfd::Demonstration;

use crate::msg::{
    self, Bool, Float64, Header, JointState, MsgType, PoseStamped, Quaternion, Time,
    TwoVectorsStamped, Vector3,
};
use crate::read::{FIELDS_KEY, ROLE_KEY, Role};
use crate::resample::{Grid, Interp, resample_into};
use crate::{Error, Result};

/// One message to write.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Message<'a> {
    /// `geometry_msgs/msg/PoseStamped`: position `[x, y, z]` (m), orientation
    /// `[x, y, z, w]` (unit quaternion).
    Pose {
        /// Position (m).
        position: [f64; 3],
        /// Orientation `[x, y, z, w]`.
        orientation: [f64; 4],
    },
    /// `geometry_msgs/msg/WrenchStamped`: force (N) and torque (N·m).
    Wrench {
        /// Force `[x, y, z]` (N).
        force: [f64; 3],
        /// Torque `[x, y, z]` (N·m).
        torque: [f64; 3],
    },
    /// `geometry_msgs/msg/TwistStamped`: linear (m/s) and angular (rad/s) velocity.
    Twist {
        /// Linear velocity (m/s).
        linear: [f64; 3],
        /// Angular velocity (rad/s).
        angular: [f64; 3],
    },
    /// `sensor_msgs/msg/JointState`.
    Joints {
        /// Joint names.
        names: &'a [String],
        /// Positions (rad or m), one per joint.
        position: &'a [f64],
        /// Velocities, one per joint or none.
        velocity: &'a [f64],
        /// Efforts, one per joint or none.
        effort: &'a [f64],
    },
    /// `std_msgs/msg/Float64`.
    Float64(f64),
    /// `std_msgs/msg/Bool`.
    Bool(bool),
}

impl Message<'_> {
    /// Its type.
    #[must_use]
    pub fn msg_type(&self) -> MsgType {
        match self {
            Message::Pose { .. } => MsgType::PoseStamped,
            Message::Wrench { .. } => MsgType::WrenchStamped,
            Message::Twist { .. } => MsgType::TwistStamped,
            Message::Joints { .. } => MsgType::JointState,
            Message::Float64(_) => MsgType::Float64,
            Message::Bool(_) => MsgType::Bool,
        }
    }

    /// Its CDR payload, header stamp `stamp_ns` (ns), frame `frame_id`.
    fn payload(&self, stamp_ns: i64, frame_id: &str) -> Vec<u8> {
        let header = Header {
            stamp: Time::from_ns(stamp_ns),
            frame_id: frame_id.to_owned(),
        };
        let v3 = |v: [f64; 3]| Vector3 {
            x: v[0],
            y: v[1],
            z: v[2],
        };
        match *self {
            Message::Pose {
                position,
                orientation: [x, y, z, w],
            } => msg::encode(&PoseStamped {
                header,
                position: v3(position),
                orientation: Quaternion { x, y, z, w },
            }),
            Message::Wrench { force, torque } => msg::encode(&TwoVectorsStamped {
                header,
                a: v3(force),
                b: v3(torque),
            }),
            Message::Twist { linear, angular } => msg::encode(&TwoVectorsStamped {
                header,
                a: v3(linear),
                b: v3(angular),
            }),
            Message::Joints {
                names,
                position,
                velocity,
                effort,
            } => msg::encode(&JointState {
                header,
                name: names.to_vec(),
                position: position.to_vec(),
                velocity: velocity.to_vec(),
                effort: effort.to_vec(),
            }),
            Message::Float64(data) => msg::encode(&Float64 { data }),
            Message::Bool(data) => msg::encode(&Bool { data }),
        }
    }
}

/// A topic added to a [`BagWriter`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TopicId {
    channel: u16,
    msg_type: Option<MsgType>,
}

/// How a [`BagWriter`] treats an existing file at its path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Existing {
    /// Refuse to write (a file the user did not ask tandem to replace is never overwritten).
    Refuse,
    /// Replace it (outputs the caller owns: `cargo xtask` results and fixtures).
    Replace,
}

/// Writes an MCAP file: ROS 2 topics (`ros2msg` schemas, CDR messages: what rosbag2
/// writes) and JSON topics (`jsonschema` schemas), chunked, zstd-compressed or not.
///
/// The file appears only when [`BagWriter::finish`] succeeds: the messages go to a temporary
/// file beside it, which is then linked into place (refusing an existing file with
/// [`Existing::Refuse`]) or renamed over it ([`Existing::Replace`]).
pub struct BagWriter {
    /// `None` once finished.
    writer: Option<Writer<BufWriter<File>>>,
    path: PathBuf,
    tmp: PathBuf,
    existing: Existing,
    schemas: BTreeMap<MsgType, u16>,
    sequence: u32,
}

impl std::fmt::Debug for BagWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BagWriter")
            .field("path", &self.path)
            .finish_non_exhaustive()
    }
}

impl BagWriter {
    /// Starts a bag at `path`; `compress` chooses zstd chunks (else uncompressed chunks,
    /// byte for byte the same with any zstd version: the committed fixtures).
    ///
    /// # Errors
    /// [`Error::Write`] when `path` exists and `existing` is [`Existing::Refuse`], or is a
    /// folder; [`Error::Io`] when the temporary file cannot be created.
    pub fn create(path: impl AsRef<Path>, compress: bool, existing: Existing) -> Result<Self> {
        let path = path.as_ref().to_path_buf();
        let file = path.display().to_string();
        if path.is_dir() {
            return Err(Error::Write {
                file,
                why: "is a folder; give a file name (e.g. run.mcap)".into(),
            });
        }
        if existing == Existing::Refuse && path.exists() {
            return Err(Error::Write {
                file,
                why: "the file exists; tandem does not overwrite a file it was not asked to \
                      replace (remove it or choose another name)"
                    .into(),
            });
        }
        let name = path
            .file_name()
            .map_or_else(|| "bag.mcap".into(), |n| n.to_string_lossy().into_owned());
        let tmp = path.with_file_name(format!(".{name}.tmp{}", std::process::id()));
        let out = File::create(&tmp).map_err(|source| Error::Io {
            file: tmp.display().to_string(),
            what: "cannot create",
            source,
        })?;
        let options = WriteOptions::new()
            .compression(compress.then_some(Compression::Zstd))
            .profile("ros2")
            .library(concat!("tandem-bag ", env!("CARGO_PKG_VERSION")));
        let writer = options
            .create(BufWriter::new(out))
            .map_err(|e| Error::Write {
                file,
                why: e.to_string(),
            })?;
        Ok(Self {
            writer: Some(writer),
            path,
            tmp,
            existing,
            schemas: BTreeMap::new(),
            sequence: 0,
        })
    }

    fn writer(&mut self) -> &mut Writer<BufWriter<File>> {
        self.writer
            .as_mut()
            .expect("the writer is taken only by `finish`, which consumes self")
    }

    fn err(&self, e: impl std::fmt::Display) -> Error {
        Error::Write {
            file: self.path.display().to_string(),
            why: e.to_string(),
        }
    }

    /// Adds a ROS 2 topic of type `msg_type`; `metadata` goes into its channel record (tandem
    /// writes [`crate::FIELDS_KEY`] and [`crate::ROLE_KEY`] there).
    ///
    /// # Errors
    /// [`Error::Write`] when the MCAP writer fails.
    pub fn add_topic(
        &mut self,
        topic: &str,
        msg_type: MsgType,
        metadata: &BTreeMap<String, String>,
    ) -> Result<TopicId> {
        let schema = match self.schemas.get(&msg_type) {
            Some(&id) => id,
            None => {
                let id = self
                    .writer()
                    .add_schema(
                        msg_type.ros_name(),
                        "ros2msg",
                        msg_type.schema_text().as_bytes(),
                    )
                    .map_err(|e| self.err(e))?;
                self.schemas.insert(msg_type, id);
                id
            }
        };
        let channel = self
            .writer()
            .add_channel(schema, topic, "cdr", metadata)
            .map_err(|e| self.err(e))?;
        Ok(TopicId {
            channel,
            msg_type: Some(msg_type),
        })
    }

    /// Adds a JSON topic whose messages follow the JSON Schema `json_schema` (schema name
    /// `schema_name`).
    ///
    /// # Errors
    /// [`Error::Write`] when the MCAP writer fails.
    pub fn add_json_topic(
        &mut self,
        topic: &str,
        schema_name: &str,
        json_schema: &str,
        metadata: &BTreeMap<String, String>,
    ) -> Result<TopicId> {
        let schema = self
            .writer()
            .add_schema(schema_name, "jsonschema", json_schema.as_bytes())
            .map_err(|e| self.err(e))?;
        let channel = self
            .writer()
            .add_channel(schema, topic, "json", metadata)
            .map_err(|e| self.err(e))?;
        Ok(TopicId {
            channel,
            msg_type: None,
        })
    }

    /// Writes `message` on `topic` at bag time `time_ns` (ns ≥ 0): log, publish and header
    /// time alike; poses in frame `world`.
    ///
    /// # Errors
    /// [`Error::Write`] for a message of another type than the topic's, a negative time, or a
    /// failing writer.
    pub fn write(&mut self, topic: TopicId, time_ns: i64, message: &Message<'_>) -> Result<()> {
        if topic.msg_type != Some(message.msg_type()) {
            return Err(self.err(format!(
                "a {} message on a topic of type {:?}",
                message.msg_type().ros_name(),
                topic.msg_type.map(MsgType::ros_name)
            )));
        }
        let data = message.payload(time_ns, "world");
        self.raw(topic, time_ns, &data)
    }

    /// Writes a JSON document on a JSON topic at bag time `time_ns` (ns ≥ 0).
    ///
    /// # Errors
    /// [`Error::Write`] for a ROS topic, a negative time, or a failing writer.
    pub fn write_json(&mut self, topic: TopicId, time_ns: i64, json: &str) -> Result<()> {
        if topic.msg_type.is_some() {
            return Err(self.err("a JSON message on a ROS 2 topic"));
        }
        self.raw(topic, time_ns, json.as_bytes())
    }

    fn raw(&mut self, topic: TopicId, time_ns: i64, data: &[u8]) -> Result<()> {
        let t = u64::try_from(time_ns).map_err(|_| self.err(format!("time {time_ns} ns < 0")))?;
        self.sequence = self.sequence.wrapping_add(1);
        let header = MessageHeader {
            channel_id: topic.channel,
            sequence: self.sequence,
            log_time: t,
            publish_time: t,
        };
        let r = self.writer().write_to_known_channel(&header, data);
        r.map_err(|e| self.err(e))
    }

    /// Finishes the file (summary, index, footer) and puts it at its path.
    ///
    /// # Errors
    /// [`Error::Write`] when the writer fails or the path was taken meanwhile
    /// ([`Existing::Refuse`]); [`Error::Io`] when the file cannot be moved into place. The
    /// temporary file is removed on error.
    pub fn finish(mut self) -> Result<()> {
        let result = self.finish_inner();
        if result.is_err() {
            let _ = std::fs::remove_file(&self.tmp);
        }
        result
    }

    fn finish_inner(&mut self) -> Result<()> {
        let mut writer = self.writer.take().expect("finish runs once");
        writer.finish().map_err(|e| self.err(e))?;
        let file = self.path.display().to_string();
        let io = |what, source| Error::Io {
            file: file.clone(),
            what,
            source,
        };
        let out = writer
            .into_inner()
            .into_inner()
            .map_err(|e| io("cannot write", e.into_error()))?;
        out.sync_all().map_err(|e| io("cannot write", e))?;
        drop(out);
        match self.existing {
            Existing::Replace => {
                std::fs::rename(&self.tmp, &self.path).map_err(|e| io("cannot write", e))?;
            }
            Existing::Refuse => {
                std::fs::hard_link(&self.tmp, &self.path).map_err(|e| {
                    if e.kind() == std::io::ErrorKind::AlreadyExists {
                        self.err("the file was created meanwhile; not overwritten")
                    } else {
                        io("cannot write", e)
                    }
                })?;
                std::fs::remove_file(&self.tmp).map_err(|e| io("cannot remove temporary", e))?;
            }
        }
        Ok(())
    }
}

impl Drop for BagWriter {
    fn drop(&mut self) {
        // An unfinished writer (an error on the way) leaves no file behind.
        if self.writer.take().is_some() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// What one topic of [`write_demonstration`] carries.
#[derive(Clone, Debug, PartialEq)]
pub struct TopicSpec {
    /// Topic name (`/pose`).
    pub topic: String,
    /// Its type.
    pub msg_type: MsgType,
    /// The demonstration channel of every value column of the type, in its column order
    /// (`x, y, z, qx, qy, qz, qw` for a pose, `fx … tz` for a wrench); `None` writes 0 (and
    /// `w = 1` for an orientation). `JointState` takes its joint names from `joints`.
    pub channels: Vec<Option<String>>,
    /// Joint names of a `JointState` (its columns are their positions).
    pub joints: Vec<String>,
    /// Message rate (Hz, finite > 0).
    pub rate_hz: f64,
    /// Bag time of the first message (ns ≥ 0).
    pub start_ns: i64,
}

/// Writes `demo` as a ROS 2 recording would hold it (no tandem metadata, so the reader names
/// the channels from the topics): each topic's messages on its own
/// period from its start, its values resampled from the demonstration (sample `t` at
/// `t·Δt_s` from the demonstration's start at bag time 0) by the reader's interpolation
/// (linear, slerp for a pose's orientation, held for a `Bool`), over the demonstration's
/// span. A `Bool` is true where its channel is at least 0.5.
///
/// # Errors
/// A channel the demonstration lacks or a bad spec ([`Error::BadParam`]), and the writer's
/// errors.
pub fn write_demonstration(
    path: impl AsRef<Path>,
    demo: &Demonstration,
    topics: &[TopicSpec],
    compress: bool,
    existing: Existing,
) -> Result<()> {
    let mut bag = BagWriter::create(path, compress, existing)?;
    let n = demo.n_samples();
    let m = demo.n_channels();
    let dt_ns = demo.dt_s() * 1e9;
    let span_ns = ((n - 1) as f64 * dt_ns).round() as i64;
    // The demonstration as a series at its own sample times.
    let demo_series = crate::read::Series {
        times_ns: (0..n).map(|t| (t as f64 * dt_ns).round() as i64).collect(),
        log_time: true,
        values: demo.samples().to_vec(),
        median_ns: dt_ns.round() as i64,
        period_ns: dt_ns,
    };
    for spec in topics {
        if !(spec.rate_hz.is_finite() && spec.rate_hz > 0.0) || spec.start_ns < 0 {
            return Err(Error::BadParam {
                name: "topics",
                why: format!(
                    "{}: rate {} Hz, start {} ns",
                    spec.topic, spec.rate_hz, spec.start_ns
                ),
            });
        }
        let width = match spec.msg_type {
            MsgType::JointState => spec.joints.len(),
            t => t.fixed_columns().len(),
        };
        if spec.channels.len() != width {
            return Err(Error::BadParam {
                name: "topics",
                why: format!(
                    "{}: {} channels for {width} columns",
                    spec.topic,
                    spec.channels.len()
                ),
            });
        }
        let cols: Vec<Option<usize>> = spec
            .channels
            .iter()
            .map(|c| match c {
                None => Ok(None),
                Some(name) => demo
                    .channel_index(name)
                    .map(Some)
                    .ok_or_else(|| Error::BadParam {
                        name: "topics",
                        why: format!("{}: the demonstration has no channel `{name}`", spec.topic),
                    }),
            })
            .collect::<Result<_>>()?;
        let period_ns = 1e9 / spec.rate_hz;
        let grid = Grid {
            t0_ns: spec.start_ns,
            period_ns,
            n: if spec.start_ns > span_ns {
                0
            } else {
                ((span_ns - spec.start_ns) as f64 / period_ns).floor() as usize + 1
            },
        };
        let mut all = vec![0.0; grid.n * m];
        // Orientation channels of a pose are slerped as a block when they are consecutive in
        // the demonstration; otherwise linearly and renormalized below.
        let plan = slerp_plan(vec![Interp::Linear; m], spec, &cols);
        resample_into(&demo_series, m, &plan, &grid, &mut all, m, 0);
        // No tandem metadata: the bag looks like any rosbag2 recording, and its channels are
        // named from the topics.
        let id = bag.add_topic(&spec.topic, spec.msg_type, &BTreeMap::new())?;
        let zeros = vec![0.0; spec.joints.len()];
        for j in 0..grid.n {
            let row = &all[j * m..(j + 1) * m];
            let v = |c: usize, default: f64| cols[c].map_or(default, |k| row[k]);
            let t = grid.time(j);
            let positions: Vec<f64>;
            let message = match spec.msg_type {
                MsgType::PoseStamped => {
                    let q = [v(3, 0.0), v(4, 0.0), v(5, 0.0), v(6, 1.0)];
                    let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
                    Message::Pose {
                        position: [v(0, 0.0), v(1, 0.0), v(2, 0.0)],
                        orientation: q.map(|x| x / norm),
                    }
                }
                MsgType::WrenchStamped => Message::Wrench {
                    force: [v(0, 0.0), v(1, 0.0), v(2, 0.0)],
                    torque: [v(3, 0.0), v(4, 0.0), v(5, 0.0)],
                },
                MsgType::TwistStamped => Message::Twist {
                    linear: [v(0, 0.0), v(1, 0.0), v(2, 0.0)],
                    angular: [v(3, 0.0), v(4, 0.0), v(5, 0.0)],
                },
                MsgType::JointState => {
                    positions = (0..spec.joints.len()).map(|c| v(c, 0.0)).collect();
                    Message::Joints {
                        names: &spec.joints,
                        position: &positions,
                        velocity: &zeros[..0],
                        effort: &zeros[..0],
                    }
                }
                MsgType::Float64 => Message::Float64(v(0, 0.0)),
                MsgType::Bool => Message::Bool(v(0, 0.0) >= 0.5),
            };
            bag.write(id, t, &message)?;
        }
    }
    bag.finish()
}

/// `plan` (one linear entry per demonstration channel) with the four orientation channels of
/// a pose spec replaced by one slerp entry when they are consecutive `x, y, z, w` channels.
fn slerp_plan(plan: Vec<Interp>, spec: &TopicSpec, cols: &[Option<usize>]) -> Vec<Interp> {
    if spec.msg_type != MsgType::PoseStamped {
        return plan;
    }
    let (Some(a), Some(b), Some(c), Some(d)) = (cols[3], cols[4], cols[5], cols[6]) else {
        return plan;
    };
    if !(b == a + 1 && c == a + 2 && d == a + 3) {
        return plan;
    }
    let mut out = Vec::with_capacity(plan.len() - 3);
    out.extend_from_slice(&plan[..a]);
    out.push(Interp::Slerp);
    out.extend_from_slice(&plan[a + 4..]);
    out
}

/// The metadata of a tandem-written topic: its channel names and its role.
pub(crate) fn metadata(fields: &[String], role: Role) -> BTreeMap<String, String> {
    let mut m = BTreeMap::new();
    m.insert(FIELDS_KEY.to_owned(), fields.join(","));
    m.insert(ROLE_KEY.to_owned(), role.name().to_owned());
    m
}
