//! Golden bytes of every message type the node sends or receives (issue 43, item 4): the files
//! in tests/golden/ were written once by the Python `rosbags` type store (an implementation of
//! ROS 2's CDR independent of tandem's; scripts/ros2_golden.py, the same values as here). Each
//! value serialized by the library the node publishes through (RustDDS's CDR, little-endian)
//! must give the file's payload byte for byte, and the file must decode to the value. No Python
//! needed.

use std::path::Path;

use ros2_client::dds::rustdds::RepresentationIdentifier;
use ros2_client::dds::rustdds::serialization::{
    deserialize_from_cdr_with_rep_id, to_writer_with_rep_id,
};
use serde::Serialize;
use serde::de::DeserializeOwned;
use tandem_ros2::msg::{
    Bool, Float64, Float64MultiArray, Header, Joy, Point, Pose, PoseStamped, Quaternion, Text,
    Time, TriggerRequest, TriggerResponse,
};

/// The CDR little-endian encapsulation header every ROS 2 sample starts with.
const CDR_LE: [u8; 4] = [0, 1, 0, 0];

fn golden(name: &str) -> Vec<u8> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden")
        .join(format!("{name}.bin"));
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Serializes `value` as the node's publishers do and compares with the golden file `name`;
/// decodes the file and compares with `value`.
fn check<M: Serialize + DeserializeOwned + PartialEq + std::fmt::Debug>(name: &str, value: &M) {
    let file = golden(name);
    assert_eq!(file[..4], CDR_LE, "{name}: the encapsulation header");
    let mut ours = Vec::new();
    to_writer_with_rep_id(&mut ours, value, RepresentationIdentifier::CDR_LE).unwrap();
    // rosbags pads a sample to a multiple of 4 bytes (DDS's alignment of the next sample);
    // the payload proper is the first `ours.len()` bytes and the rest is zeros.
    let payload = &file[4..];
    assert!(
        payload.len() >= ours.len() && payload.len() - ours.len() < 4,
        "{name}: {} bytes from rosbags, {} from RustDDS",
        payload.len(),
        ours.len()
    );
    assert_eq!(&payload[..ours.len()], &ours[..], "{name}: the payload");
    assert!(
        payload[ours.len()..].iter().all(|&b| b == 0),
        "{name}: padding"
    );
    let (decoded, _) =
        deserialize_from_cdr_with_rep_id::<M>(payload, RepresentationIdentifier::CDR_LE).unwrap();
    assert_eq!(&decoded, value, "{name}: decoded");
}

const STAMP: Time = Time {
    sec: 1_765_000_000,
    nanosec: 123_456_789,
};

#[test]
fn std_msgs_match_rosbags_bytes() {
    check("float64", &Float64 { data: 123.25 });
    check("bool", &Bool { data: true });
    check(
        "string",
        &Text {
            data: "robot 2 stalled: no progress for 0.260 s — hold".into(),
        },
    );
    check(
        "float64_multi_array",
        &Float64MultiArray::labelled(
            "ref_time,speed_scale,tick,stamp_s",
            vec![12.5, 0.75, 42.0, 1_765_000_000.125],
        ),
    );
    check(
        "float64_multi_array_empty",
        &Float64MultiArray::labelled("robot,earliest_s,latest_s", Vec::new()),
    );
}

#[test]
fn joy_and_pose_stamped_match_rosbags_bytes() {
    check(
        "joy",
        &Joy {
            header: Header {
                stamp: STAMP,
                frame_id: "joy".into(),
            },
            axes: vec![-0.5, 0.25, 1.0],
            buttons: vec![1, 0],
        },
    );
    check(
        "pose_stamped",
        &PoseStamped {
            header: Header {
                stamp: STAMP,
                frame_id: "world".into(),
            },
            pose: Pose {
                position: Point {
                    x: 0.5,
                    y: -0.25,
                    z: 1.125,
                },
                orientation: Quaternion {
                    x: 0.0,
                    y: 0.0,
                    z: 0.6,
                    w: 0.8,
                },
            },
        },
    );
}

#[test]
fn trigger_service_matches_rosbags_bytes() {
    check("trigger_request", &TriggerRequest::default());
    check(
        "trigger_response",
        &TriggerResponse {
            success: true,
            message: "recorded round 3".into(),
        },
    );
}

#[test]
fn a_changed_byte_is_caught() {
    // The comparison can fail: the command's golden bytes with one number changed differ.
    let file = golden("float64_multi_array");
    let mut ours = Vec::new();
    let other = Float64MultiArray::labelled(
        "ref_time,speed_scale,tick,stamp_s",
        vec![12.5, 0.75, 43.0, 1_765_000_000.125],
    );
    to_writer_with_rep_id(&mut ours, &other, RepresentationIdentifier::CDR_LE).unwrap();
    assert_ne!(&file[4..4 + ours.len()], &ours[..]);
}
