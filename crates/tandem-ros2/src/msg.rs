//! The standard ROS 2 message and service types the node speaks, as serde structs whose field
//! order is their ROS IDL's (the CDR encoding is positional), with their ROS type names.
//!
//! Only `std_msgs`, `sensor_msgs` and `std_srvs` types: any ROS 2 install has them, `ros2 topic
//! echo` shows them without a tandem package, and every DDS implementation that speaks the ROS
//! 2 type names (Cyclone, Fast DDS, RustDDS) can read them (docs/decisions.md, "tandem in a
//! live ROS 2 graph").

use serde::{Deserialize, Serialize};

/// A ROS type name: package and type (`std_msgs`, `Float64`), as in `std_msgs/msg/Float64`.
pub type TypeName = (&'static str, &'static str);

/// `std_msgs/msg/Float64`: one number. A robot's progress (the reference time it has reached,
/// reference samples).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Float64 {
    /// The value.
    pub data: f64,
}

/// `std_msgs/msg/Bool`: one flag. `needs_operator` per robot.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Bool {
    /// The value.
    pub data: bool,
}

/// `std_msgs/msg/String`: one text. The fault topic (empty text: no fault).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Text {
    /// The text (UTF-8).
    pub data: String,
}

/// `builtin_interfaces/msg/Time`: seconds and nanoseconds since the UNIX epoch (ROS time).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Time {
    /// Whole seconds.
    pub sec: i32,
    /// Nanoseconds in `[0, 10⁹)`.
    pub nanosec: u32,
}

/// `std_msgs/msg/Header`: a stamp and a frame.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// When the data was taken.
    pub stamp: Time,
    /// The coordinate frame (empty: none).
    pub frame_id: String,
}

/// `std_msgs/msg/MultiArrayDimension`: one dimension of a multi-array.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MultiArrayDimension {
    /// What the dimension holds (the node lists the entries' names, comma-separated).
    pub label: String,
    /// Entries along it.
    pub size: u32,
    /// Stride (entries).
    pub stride: u32,
}

/// `std_msgs/msg/MultiArrayLayout`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MultiArrayLayout {
    /// The dimensions.
    pub dim: Vec<MultiArrayDimension>,
    /// Entries before the first one.
    pub data_offset: u32,
}

/// `std_msgs/msg/Float64MultiArray`: numbers with their labels. A robot's command, its
/// setpoint and the next handover.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Float64MultiArray {
    /// The layout: one dimension whose label names the entries.
    pub layout: MultiArrayLayout,
    /// The numbers.
    pub data: Vec<f64>,
}

impl Float64MultiArray {
    /// One dimension labelled `label` (the entries' names, comma-separated) holding `data`.
    #[must_use]
    pub fn labelled(label: &str, data: Vec<f64>) -> Self {
        let n = u32::try_from(data.len()).unwrap_or(u32::MAX);
        Float64MultiArray {
            layout: MultiArrayLayout {
                dim: vec![MultiArrayDimension {
                    label: label.to_owned(),
                    size: n,
                    stride: n,
                }],
                data_offset: 0,
            },
            data,
        }
    }
}

/// `geometry_msgs/msg/Point`: a position (m, in the header's frame).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Point {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

/// `geometry_msgs/msg/Quaternion`: an orientation (`x, y, z, w`, unit norm).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w (the scalar part).
    pub w: f64,
}

impl Default for Quaternion {
    /// The identity (ROS's default: `w = 1`).
    fn default() -> Self {
        Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 1.0,
        }
    }
}

/// `geometry_msgs/msg/Pose`: a position and an orientation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// The position.
    pub position: Point,
    /// The orientation.
    pub orientation: Quaternion,
}

/// `geometry_msgs/msg/PoseStamped`: a pose in a frame at a time. A robot's setpoint when the
/// model's channels name a pose (`setpoint_pose`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseStamped {
    /// Stamp and frame.
    pub header: Header,
    /// The pose.
    pub pose: Pose,
}

/// `sensor_msgs/msg/Joy`: the operator's input device.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Joy {
    /// Stamp and frame.
    pub header: Header,
    /// Axes in `[−1, 1]`.
    pub axes: Vec<f32>,
    /// Buttons (1 pressed, 0 not).
    pub buttons: Vec<i32>,
}

/// `std_srvs/srv/Trigger` request: empty in ROS IDL, which DDS encodes as one byte
/// (`structure_needs_at_least_one_member`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TriggerRequest {
    structure_needs_at_least_one_member: u8,
}

/// `std_srvs/srv/Trigger` response.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TriggerResponse {
    /// Whether the service did what was asked.
    pub success: bool,
    /// What it did, or why not and the fix.
    pub message: String,
}

macro_rules! message {
    ($($t:ty),*) => { $(impl ros2_client::Message for $t {})* };
}
message!(
    Float64,
    Bool,
    Text,
    Float64MultiArray,
    Joy,
    PoseStamped,
    TriggerRequest,
    TriggerResponse
);

/// `std_msgs/Float64`.
pub const FLOAT64: TypeName = ("std_msgs", "Float64");
/// `std_msgs/Bool`.
pub const BOOL: TypeName = ("std_msgs", "Bool");
/// `std_msgs/String`.
pub const STRING: TypeName = ("std_msgs", "String");
/// `std_msgs/Float64MultiArray`.
pub const FLOAT64_MULTI_ARRAY: TypeName = ("std_msgs", "Float64MultiArray");
/// `sensor_msgs/Joy`.
pub const JOY: TypeName = ("sensor_msgs", "Joy");
/// `geometry_msgs/PoseStamped`.
pub const POSE_STAMPED: TypeName = ("geometry_msgs", "PoseStamped");
/// `std_srvs/Trigger`.
pub const TRIGGER: TypeName = ("std_srvs", "Trigger");

/// ROS time now (the system clock; the UNIX epoch if the clock is before it).
#[must_use]
pub fn now() -> Time {
    let d = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap_or_default();
    Time {
        sec: i32::try_from(d.as_secs()).unwrap_or(i32::MAX),
        nanosec: d.subsec_nanos(),
    }
}

/// Seconds since the UNIX epoch of a [`Time`].
#[must_use]
pub fn seconds(t: Time) -> f64 {
    f64::from(t.sec) + f64::from(t.nanosec) * 1e-9
}
