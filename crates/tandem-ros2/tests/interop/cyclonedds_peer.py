"""An independent DDS implementation against tandem's node: Eclipse Cyclone DDS (the DDS of
ROS 2's Cyclone RMW), through its Python binding, with the ROS 2 type and topic names.

Subscribes to robot 1's `needs_operator` (std_msgs/Bool) and `command`
(std_msgs/Float64MultiArray) and publishes the operator's input (sensor_msgs/Joy, axis 0 at
-1: the slowest the demonstrations allow) while a round runs (the Rust test drives the round).
Prints one JSON line: what it received, and robot 1's speed scale in the ticks it needed the
operator. Exits 1 when it received nothing.

Usage: cyclonedds_peer.py DOMAIN SECONDS
"""

import json
import sys
import time
from dataclasses import dataclass

import cyclonedds.idl.annotations as annotate
from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import float32, float64, int32, sequence, uint32
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration


@dataclass
@annotate.final
class Bool(IdlStruct, typename="std_msgs::msg::dds_::Bool_"):
    data: bool


@dataclass
@annotate.final
class MultiArrayDimension(IdlStruct, typename="std_msgs::msg::dds_::MultiArrayDimension_"):
    label: str
    size: uint32
    stride: uint32


@dataclass
@annotate.final
class MultiArrayLayout(IdlStruct, typename="std_msgs::msg::dds_::MultiArrayLayout_"):
    dim: sequence[MultiArrayDimension]
    data_offset: uint32


@dataclass
@annotate.final
class Float64MultiArray(IdlStruct, typename="std_msgs::msg::dds_::Float64MultiArray_"):
    layout: MultiArrayLayout
    data: sequence[float64]


@dataclass
@annotate.final
class Time(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: int32
    nanosec: uint32


@dataclass
@annotate.final
class Header(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time
    frame_id: str


@dataclass
@annotate.final
class Joy(IdlStruct, typename="sensor_msgs::msg::dds_::Joy_"):
    header: Header
    axes: sequence[float32]
    buttons: sequence[int32]


def main() -> int:
    domain, seconds = int(sys.argv[1]), float(sys.argv[2])
    # ROS 2's default profile, as the node's; classic CDR (XCDR1), which RustDDS speaks.
    qos = Qos(
        Policy.Reliability.Reliable(duration(milliseconds=100)),
        Policy.Durability.Volatile,
        Policy.History.KeepLast(16),
        Policy.DataRepresentation(use_cdrv0_representation=True),
    )
    dp = DomainParticipant(domain)
    needs = DataReader(dp, Topic(dp, "rt/tandem/robot1/needs_operator", Bool), qos=qos)
    command = DataReader(dp, Topic(dp, "rt/tandem/robot1/command", Float64MultiArray), qos=qos)
    joy = DataWriter(dp, Topic(dp, "rt/tandem/operator", Joy), qos=qos)
    got_needs = got_true = got_cmd = 0
    label = ""
    supervised_speeds = []
    needed = False
    end = time.time() + seconds
    while time.time() < end:
        now = time.time()
        joy.write(Joy(Header(Time(int(now), int((now % 1) * 1e9)), ""), [-1.0], [1]))
        for s in needs.take(N=64):
            if isinstance(s, Bool):
                got_needs += 1
                got_true += int(s.data)
                needed = s.data
        for s in command.take(N=256):
            if isinstance(s, Float64MultiArray) and len(s.data) >= 2:
                got_cmd += 1
                label = s.layout.dim[0].label if s.layout.dim else ""
                if needed and s.data[1] > 0:
                    supervised_speeds.append(s.data[1])
        time.sleep(0.005)
    print(
        json.dumps(
            {
                "needs": got_needs,
                "needs_true": got_true,
                "commands": got_cmd,
                "label": label,
                "supervised_speeds": supervised_speeds,
            }
        ),
        flush=True,
    )
    return 0 if got_needs and got_cmd else 1


if __name__ == "__main__":
    sys.exit(main())
