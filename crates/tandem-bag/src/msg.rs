//! The six ROS 2 message types tandem reads and writes: hand-written serde structs in their
//! CDR layout, their `ros2msg` schema texts (what rosbag2 stores in an MCAP schema record),
//! and the value columns each one gives.
//!
//! A ROS 2 CDR payload is a 4-byte encapsulation header (representation identifier
//! `0x0001` little-endian or `0x0000` big-endian, then two option bytes) followed by the
//! message body in plain (XCDR1) CDR, aligned from the first body byte.

use cdr_encoding::{from_bytes, to_vec};
use serde::{Deserialize, Serialize};

/// A supported ROS 2 message type.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum MsgType {
    /// `geometry_msgs/msg/PoseStamped`: position (m) and orientation (unit quaternion).
    PoseStamped,
    /// `geometry_msgs/msg/WrenchStamped`: force (N) and torque (N·m).
    WrenchStamped,
    /// `geometry_msgs/msg/TwistStamped`: linear (m/s) and angular (rad/s) velocity.
    TwistStamped,
    /// `sensor_msgs/msg/JointState`: per named joint position, velocity, effort.
    JointState,
    /// `std_msgs/msg/Float64`: one number, no header (log time).
    Float64,
    /// `std_msgs/msg/Bool`: one flag as 0/1, no header (log time), held between messages.
    Bool,
}

/// Every supported type, in the order of the docs.
pub const ALL_TYPES: [MsgType; 6] = [
    MsgType::PoseStamped,
    MsgType::WrenchStamped,
    MsgType::TwistStamped,
    MsgType::JointState,
    MsgType::Float64,
    MsgType::Bool,
];

const SEPARATOR: &str =
    "================================================================================\n";

impl MsgType {
    /// The ROS 2 type name, as rosbag2 writes it into the schema record
    /// (`geometry_msgs/msg/PoseStamped`).
    #[must_use]
    pub fn ros_name(self) -> &'static str {
        match self {
            MsgType::PoseStamped => "geometry_msgs/msg/PoseStamped",
            MsgType::WrenchStamped => "geometry_msgs/msg/WrenchStamped",
            MsgType::TwistStamped => "geometry_msgs/msg/TwistStamped",
            MsgType::JointState => "sensor_msgs/msg/JointState",
            MsgType::Float64 => "std_msgs/msg/Float64",
            MsgType::Bool => "std_msgs/msg/Bool",
        }
    }

    /// The type of a schema name, if supported.
    #[must_use]
    pub fn from_ros_name(name: &str) -> Option<MsgType> {
        ALL_TYPES.into_iter().find(|t| t.ros_name() == name)
    }

    /// Whether messages of this type carry a `std_msgs/Header` (whose stamp is their time).
    #[must_use]
    pub fn has_header(self) -> bool {
        !matches!(self, MsgType::Float64 | MsgType::Bool)
    }

    /// The channel-name suffixes of the fixed value columns (`x … qw` for a pose; one empty
    /// suffix for `Float64` and `Bool`, whose channel is the topic itself). `JointState`'s
    /// columns depend on its joint names: [`joint_columns`].
    #[must_use]
    pub fn fixed_columns(self) -> &'static [&'static str] {
        match self {
            MsgType::PoseStamped => &["x", "y", "z", "qx", "qy", "qz", "qw"],
            MsgType::WrenchStamped => &["fx", "fy", "fz", "tx", "ty", "tz"],
            MsgType::TwistStamped => &["vx", "vy", "vz", "wx", "wy", "wz"],
            MsgType::JointState => &[],
            MsgType::Float64 | MsgType::Bool => &[""],
        }
    }

    /// The `ros2msg` schema text: the message definition, then every nested definition after a
    /// separator line and `MSG: <type>` (rosbag2's layout, which Foxglove and
    /// `mcap-ros2-support` parse).
    #[must_use]
    pub fn schema_text(self) -> String {
        const HEADER: &str =
            "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n";
        const TIME: &str = "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n";
        const VECTOR3: &str = "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n";
        let parts: Vec<&str> = match self {
            MsgType::PoseStamped => vec![
                "std_msgs/Header header\ngeometry_msgs/Pose pose\n",
                HEADER,
                TIME,
                "MSG: geometry_msgs/Pose\ngeometry_msgs/Point position\n\
                 geometry_msgs/Quaternion orientation\n",
                "MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n",
                "MSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w\n",
            ],
            MsgType::WrenchStamped => vec![
                "std_msgs/Header header\ngeometry_msgs/Wrench wrench\n",
                HEADER,
                TIME,
                "MSG: geometry_msgs/Wrench\ngeometry_msgs/Vector3 force\n\
                 geometry_msgs/Vector3 torque\n",
                VECTOR3,
            ],
            MsgType::TwistStamped => vec![
                "std_msgs/Header header\ngeometry_msgs/Twist twist\n",
                HEADER,
                TIME,
                "MSG: geometry_msgs/Twist\ngeometry_msgs/Vector3 linear\n\
                 geometry_msgs/Vector3 angular\n",
                VECTOR3,
            ],
            MsgType::JointState => vec![
                "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\n\
                 float64[] effort\n",
                HEADER,
                TIME,
            ],
            MsgType::Float64 => vec!["float64 data\n"],
            MsgType::Bool => vec!["bool data\n"],
        };
        parts.join(SEPARATOR)
    }
}

/// The channel-name suffixes of a `JointState` with these joint names and these non-empty
/// arrays: `<joint>.position` for every joint, then `<joint>.velocity`, then `<joint>.effort`
/// (each group only when that array is filled).
#[must_use]
pub fn joint_columns(names: &[String], velocity: bool, effort: bool) -> Vec<String> {
    let mut out: Vec<String> = names.iter().map(|n| format!("{n}.position")).collect();
    if velocity {
        out.extend(names.iter().map(|n| format!("{n}.velocity")));
    }
    if effort {
        out.extend(names.iter().map(|n| format!("{n}.effort")));
    }
    out
}

/// `builtin_interfaces/Time`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct Time {
    pub(crate) sec: i32,
    pub(crate) nanosec: u32,
}

impl Time {
    /// Nanoseconds since the epoch.
    pub(crate) fn ns(self) -> i64 {
        i64::from(self.sec) * 1_000_000_000 + i64::from(self.nanosec)
    }

    /// The stamp of `ns` nanoseconds (`ns` within the `i32` seconds of ROS time).
    pub(crate) fn from_ns(ns: i64) -> Time {
        Time {
            sec: ns.div_euclid(1_000_000_000) as i32,
            nanosec: ns.rem_euclid(1_000_000_000) as u32,
        }
    }
}

/// `std_msgs/Header`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct Header {
    pub(crate) stamp: Time,
    pub(crate) frame_id: String,
}

/// `geometry_msgs/Vector3` (and `Point`: the same layout).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct Vector3 {
    pub(crate) x: f64,
    pub(crate) y: f64,
    pub(crate) z: f64,
}

/// `geometry_msgs/Quaternion`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct Quaternion {
    pub(crate) x: f64,
    pub(crate) y: f64,
    pub(crate) z: f64,
    pub(crate) w: f64,
}

/// `geometry_msgs/PoseStamped` (`Pose` inlined: position, orientation).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct PoseStamped {
    pub(crate) header: Header,
    pub(crate) position: Vector3,
    pub(crate) orientation: Quaternion,
}

/// `geometry_msgs/WrenchStamped` and `TwistStamped` (two `Vector3` after the header).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct TwoVectorsStamped {
    pub(crate) header: Header,
    pub(crate) a: Vector3,
    pub(crate) b: Vector3,
}

/// `sensor_msgs/JointState`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct JointState {
    pub(crate) header: Header,
    pub(crate) name: Vec<String>,
    pub(crate) position: Vec<f64>,
    pub(crate) velocity: Vec<f64>,
    pub(crate) effort: Vec<f64>,
}

/// `std_msgs/Float64`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct Float64 {
    pub(crate) data: f64,
}

/// `std_msgs/Bool`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct Bool {
    pub(crate) data: bool,
}

/// One message's content as tandem reads it.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Decoded {
    /// The header stamp (ns), for types with a header.
    pub(crate) stamp_ns: Option<i64>,
    /// The joint names of a `JointState` (empty for other types).
    pub(crate) joint_names: Vec<String>,
    /// Whether a `JointState` has velocities and efforts.
    pub(crate) joint_arrays: (bool, bool),
}

/// Decodes a CDR payload of type `t`, appending its value columns to `values` (see
/// [`MsgType::fixed_columns`], [`joint_columns`]). Errors describe what is malformed.
pub(crate) fn decode(t: MsgType, payload: &[u8], values: &mut Vec<f64>) -> Result<Decoded, String> {
    let (little, body) = encapsulation(payload)?;
    macro_rules! body {
        ($ty:ty) => {{
            let r = if little {
                from_bytes::<$ty, byteorder::LittleEndian>(body)
            } else {
                from_bytes::<$ty, byteorder::BigEndian>(body)
            };
            r.map_err(|e| format!("not a valid {} (CDR): {e}", t.ros_name()))?
                .0
        }};
    }
    let plain = |stamp: Option<i64>| Decoded {
        stamp_ns: stamp,
        joint_names: Vec::new(),
        joint_arrays: (false, false),
    };
    Ok(match t {
        MsgType::PoseStamped => {
            let m: PoseStamped = body!(PoseStamped);
            let (p, q) = (m.position, m.orientation);
            values.extend_from_slice(&[p.x, p.y, p.z, q.x, q.y, q.z, q.w]);
            plain(Some(m.header.stamp.ns()))
        }
        MsgType::WrenchStamped | MsgType::TwistStamped => {
            let m: TwoVectorsStamped = body!(TwoVectorsStamped);
            let (a, b) = (m.a, m.b);
            values.extend_from_slice(&[a.x, a.y, a.z, b.x, b.y, b.z]);
            plain(Some(m.header.stamp.ns()))
        }
        MsgType::JointState => {
            let m: JointState = body!(JointState);
            let n = m.name.len();
            for (what, v) in [
                ("position", &m.position),
                ("velocity", &m.velocity),
                ("effort", &m.effort),
            ] {
                if !(v.is_empty() || v.len() == n) {
                    return Err(format!(
                        "`{what}` has {} entries for {n} joint names (give one per joint, or none)",
                        v.len()
                    ));
                }
            }
            if m.position.is_empty() {
                return Err("`position` is empty (tandem reads joint positions)".into());
            }
            values.extend_from_slice(&m.position);
            values.extend_from_slice(&m.velocity);
            values.extend_from_slice(&m.effort);
            Decoded {
                stamp_ns: Some(m.header.stamp.ns()),
                joint_arrays: (!m.velocity.is_empty(), !m.effort.is_empty()),
                joint_names: m.name,
            }
        }
        MsgType::Float64 => {
            let m: Float64 = body!(Float64);
            values.push(m.data);
            plain(None)
        }
        MsgType::Bool => {
            let m: Bool = body!(Bool);
            values.push(f64::from(u8::from(m.data)));
            plain(None)
        }
    })
}

/// The byte order and the body of a CDR payload.
fn encapsulation(payload: &[u8]) -> Result<(bool, &[u8]), String> {
    match payload {
        [0x00, 0x01, _, _, body @ ..] => Ok((true, body)),
        [0x00, 0x00, _, _, body @ ..] => Ok((false, body)),
        [a, b, _, _, ..] => Err(format!(
            "CDR representation {a:#04x}{b:02x} is not plain CDR (0x0000 or 0x0001; XCDR2 and \
             parameter lists are not supported)"
        )),
        _ => Err(format!(
            "{} bytes: shorter than the 4-byte CDR encapsulation header",
            payload.len()
        )),
    }
}

/// A little-endian CDR payload (with its encapsulation header) of `value`.
pub(crate) fn encode<T: Serialize>(value: &T) -> Vec<u8> {
    let body = to_vec::<T, byteorder::LittleEndian>(value)
        .expect("serializing numbers, flags and strings into memory cannot fail");
    let mut out = Vec::with_capacity(body.len() + 4);
    out.extend_from_slice(&[0x00, 0x01, 0x00, 0x00]);
    out.extend_from_slice(&body);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn float64_payload_is_ros2_cdr() {
        // Header 00 01 00 00, then the double aligned at body offset 0.
        let bytes = encode(&Float64 { data: 1.5 });
        assert_eq!(&bytes[..4], &[0, 1, 0, 0]);
        assert_eq!(&bytes[4..], &1.5f64.to_le_bytes());
        let mut v = Vec::new();
        decode(MsgType::Float64, &bytes, &mut v).unwrap();
        assert_eq!(v, [1.5]);
    }

    #[test]
    fn pose_layout_pads_the_doubles_after_the_frame_id() {
        let m = PoseStamped {
            header: Header {
                stamp: Time { sec: 3, nanosec: 7 },
                frame_id: "ab".into(),
            },
            position: Vector3 {
                x: 1.0,
                y: 2.0,
                z: 3.0,
            },
            orientation: Quaternion {
                x: 0.0,
                y: 0.0,
                z: 0.0,
                w: 1.0,
            },
        };
        let bytes = encode(&m);
        // sec(4) nanosec(4) len(4) "ab\0"(3) pad(1): the doubles start at body offset 16,
        // aligned to 8 from the body's start (not the encapsulation header's).
        assert_eq!(bytes.len(), 4 + 16 + 7 * 8);
        assert_eq!(&bytes[4 + 12..4 + 15], b"ab\0");
        assert_eq!(&bytes[4 + 16..4 + 24], &1.0f64.to_le_bytes());
        let mut v = Vec::new();
        let d = decode(MsgType::PoseStamped, &bytes, &mut v).unwrap();
        assert_eq!(d.stamp_ns, Some(3_000_000_007));
        assert_eq!(v, [1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 1.0]);
    }

    #[test]
    fn big_endian_and_bad_headers() {
        let body =
            cdr_encoding::to_vec::<Float64, byteorder::BigEndian>(&Float64 { data: -2.0 }).unwrap();
        let mut be = vec![0, 0, 0, 0];
        be.extend(body);
        let mut v = Vec::new();
        decode(MsgType::Float64, &be, &mut v).unwrap();
        assert_eq!(v, [-2.0]);
        assert!(decode(MsgType::Float64, &[0, 7, 0, 0, 1], &mut v).is_err());
        assert!(decode(MsgType::Float64, &[0, 1], &mut v).is_err());
        // A body too short for its type.
        assert!(decode(MsgType::PoseStamped, &[0, 1, 0, 0, 1, 2, 3], &mut v).is_err());
    }

    #[test]
    fn joint_state_arrays_must_match_the_names() {
        let m = JointState {
            name: vec!["a".into(), "b".into()],
            position: vec![1.0, 2.0],
            velocity: vec![0.5],
            ..JointState::default()
        };
        let mut v = Vec::new();
        let e = decode(MsgType::JointState, &encode(&m), &mut v).unwrap_err();
        assert!(e.contains("`velocity` has 1 entries for 2"), "{e}");
        assert_eq!(
            joint_columns(&m.name, true, false),
            ["a.position", "b.position", "a.velocity", "b.velocity"]
        );
    }

    #[test]
    fn stamps_convert_both_ways() {
        for ns in [0, 1, 999_999_999, 1_000_000_000, 1_700_000_000_123_456_789] {
            assert_eq!(Time::from_ns(ns).ns(), ns);
        }
    }
}
