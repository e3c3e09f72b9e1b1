#!/usr/bin/env python3
"""Golden CDR bytes of every message type tandem-ros2 sends or receives (issue 43, item 4).

Writes one example of each type, serialized by the `rosbags` type store (an implementation of
ROS 2's CDR independent of tandem's), to crates/tandem-ros2/tests/golden/<name>.bin: the
4-byte encapsulation header (CDR little-endian) and the payload, as a ROS 2 publisher puts them
on the wire. The Rust test `cargo test -p tandem-ros2 --test golden` serializes the same values
with the library the node publishes through and compares the bytes, and decodes these files;
it does not need Python. The values here and in tests/golden.rs must stay the same.

Run once (the files are committed): a venv with `pip install rosbags==0.11.9`, then
    python scripts/ros2_golden.py
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

OUT = Path(__file__).resolve().parent.parent / "crates" / "tandem-ros2" / "tests" / "golden"


def main() -> int:
    ts = get_typestore(Stores.ROS2_HUMBLE)
    # std_srvs/Trigger's request and response as DDS carries them (ROS 2's IDL of an empty
    # request gets the member `structure_needs_at_least_one_member`); the store has no
    # services, so they are registered from their definitions (rosbags files a parsed type
    # under `<pkg>/srv/msg/<name>`; the CDR bytes carry no type name).
    trigger = {}
    for name, definition in (
        ("Trigger_Request", "uint8 structure_needs_at_least_one_member"),
        ("Trigger_Response", "bool success\nstring message"),
    ):
        types = get_types_from_msg(definition, f"std_srvs/srv/{name}")
        ts.register(types)
        (trigger[name],) = types.keys()
    t = ts.types
    time = t["builtin_interfaces/msg/Time"](sec=1_765_000_000, nanosec=123_456_789)
    dim = t["std_msgs/msg/MultiArrayDimension"]
    layout = t["std_msgs/msg/MultiArrayLayout"]
    examples = {
        # A robot's progress (reference samples).
        "float64": ("std_msgs/msg/Float64", t["std_msgs/msg/Float64"](data=123.25)),
        # needs_operator.
        "bool": ("std_msgs/msg/Bool", t["std_msgs/msg/Bool"](data=True)),
        # The fault (non-ASCII text: the encoding is UTF-8 bytes plus a NUL).
        "string": (
            "std_msgs/msg/String",
            t["std_msgs/msg/String"](data="robot 2 stalled: no progress for 0.260 s — hold"),
        ),
        # A robot's command.
        "float64_multi_array": (
            "std_msgs/msg/Float64MultiArray",
            t["std_msgs/msg/Float64MultiArray"](
                layout=layout(
                    dim=[dim(label="ref_time,speed_scale,tick,stamp_s", size=4, stride=4)],
                    data_offset=0,
                ),
                data=np.array([12.5, 0.75, 42.0, 1765000000.125], dtype=np.float64),
            ),
        ),
        # The next handover while no robot has a stretch ahead: an empty array.
        "float64_multi_array_empty": (
            "std_msgs/msg/Float64MultiArray",
            t["std_msgs/msg/Float64MultiArray"](
                layout=layout(
                    dim=[dim(label="robot,earliest_s,latest_s", size=0, stride=0)],
                    data_offset=0,
                ),
                data=np.array([], dtype=np.float64),
            ),
        ),
        # The operator's input.
        "joy": (
            "sensor_msgs/msg/Joy",
            t["sensor_msgs/msg/Joy"](
                header=t["std_msgs/msg/Header"](stamp=time, frame_id="joy"),
                axes=np.array([-0.5, 0.25, 1.0], dtype=np.float32),
                buttons=np.array([1, 0], dtype=np.int32),
            ),
        ),
        # The setpoint as a pose.
        "pose_stamped": (
            "geometry_msgs/msg/PoseStamped",
            t["geometry_msgs/msg/PoseStamped"](
                header=t["std_msgs/msg/Header"](stamp=time, frame_id="world"),
                pose=t["geometry_msgs/msg/Pose"](
                    position=t["geometry_msgs/msg/Point"](x=0.5, y=-0.25, z=1.125),
                    orientation=t["geometry_msgs/msg/Quaternion"](
                        x=0.0, y=0.0, z=0.6, w=0.8
                    ),
                ),
            ),
        ),
        "trigger_request": (
            trigger["Trigger_Request"],
            t[trigger["Trigger_Request"]](structure_needs_at_least_one_member=0),
        ),
        "trigger_response": (
            trigger["Trigger_Response"],
            t[trigger["Trigger_Response"]](success=True, message="recorded round 3"),
        ),
    }
    OUT.mkdir(parents=True, exist_ok=True)
    for name, (ty, msg) in examples.items():
        raw = bytes(ts.serialize_cdr(msg, ty))
        (OUT / f"{name}.bin").write_bytes(raw)
        print(f"{name}.bin: {ty}, {len(raw)} bytes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
