"""ROS 2 bags both ways, checked by Foxglove's own Python MCAP reader and ROS 2 CDR codec
(``mcap`` and ``mcap-ros2-support``): a run ``tandem simulate --bag`` writes opens there with
every topic and the message counts the run's CSV files give, and bags that Python writes are
what ``tandem.read_bag`` and ``tandem.fit`` read."""

from __future__ import annotations

import json
import subprocess
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from mcap_ros2.writer import Writer as Ros2Writer

import tandem
from conftest import ROOT, cli

EXAMPLES = ROOT / "fixtures" / "examples"
BAGS = [EXAMPLES / "ros2" / f"demo_{i}.mcap" for i in range(3)]

SEP = "=" * 80 + "\n"
HEADER = "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n"
TIME = "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"
VECTOR3 = "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n"
POSE_STAMPED = SEP.join(
    [
        "std_msgs/Header header\ngeometry_msgs/Pose pose\n",
        HEADER,
        TIME,
        "MSG: geometry_msgs/Pose\ngeometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n",
        "MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n",
        "MSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w\n",
    ]
)
WRENCH_STAMPED = SEP.join(
    [
        "std_msgs/Header header\ngeometry_msgs/Wrench wrench\n",
        HEADER,
        TIME,
        "MSG: geometry_msgs/Wrench\ngeometry_msgs/Vector3 force\ngeometry_msgs/Vector3 torque\n",
        VECTOR3,
    ]
)
BOOL = "bool data\n"


def run_cli(*args: object) -> str:
    out = subprocess.run(
        [str(cli()), *map(str, args)], capture_output=True, text=True, check=False
    )
    assert out.returncode == 0, out.stderr
    return out.stdout


def decoded(path: Path):
    """Every message of a bag decoded by mcap-ros2-support: ``(topic, schema, log_time, msg)``;
    JSON messages parsed."""
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for schema, channel, message in reader.iter_messages():
            if channel.message_encoding == "json":
                yield channel.topic, schema.name, message.log_time, json.loads(message.data)
            else:
                yield channel.topic, schema.name, message.log_time, reader_decode(
                    reader, schema, channel, message
                )


_DECODER = DecoderFactory()
_DECODERS: dict = {}


def reader_decode(reader, schema, channel, message):
    key = schema.id
    if key not in _DECODERS:
        _DECODERS[key] = _DECODER.decoder_for(channel.message_encoding, schema)
    return _DECODERS[key](message.data)


@pytest.fixture(scope="module")
def run_20(tmp_path_factory) -> dict:
    """A 20-round ``tandem simulate --bag`` run of the example bags, with the same run's CSV
    files (``--write``)."""
    tmp = tmp_path_factory.mktemp("run20")
    state = tmp / "cell.tandem"
    run_cli("fit", *BAGS, "--params", EXAMPLES / "params.toml", "-o", state)
    bag = tmp / "run.mcap"
    run_cli(
        "simulate", state, "--need", EXAMPLES / "need.csv", "--rounds", 20,
        "--channel", "wrench.fz", "--bag", bag, "--write", tmp / "csv", "--seed", 3,
    )
    return {"bag": bag, "csv": tmp / "csv", "state": state}


def test_a_20_round_run_opens_in_the_python_reader_with_every_topic_and_count(run_20) -> None:
    messages = list(decoded(run_20["bag"]))
    counts = Counter(topic for topic, *_ in messages)
    types = {topic: schema for topic, schema, *_ in messages}
    channels = ["wrench/fx", "wrench/fy", "wrench/fz", "wrench/tx", "wrench/ty", "wrench/tz"]
    schedules = [m for t, _, _, m in messages if t == "/tandem/schedule"]
    assert len(schedules) == 20
    assert [s["round"] for s in schedules] == list(range(1, 21))
    ticks = sum(s["ticks"] for s in schedules)
    expected_topics = {"/tandem/schedule"}
    for robot in (1, 2):
        # Samples per round from the run's own CSV files: one message per sample and topic.
        samples = sum(
            len((run_20["csv"] / f"round_{k}_robot_{robot}.reflog.csv").read_text().split()) - 1
            for k in range(1, 21)
        )
        ns = f"/robot_{robot}"
        per_sample = ["tool_pose", *channels, "ref_sample", "supervised", "corrected"]
        for t in per_sample:
            assert counts[f"{ns}/{t}"] == samples, (t, counts[f"{ns}/{t}"], samples)
        for t in ("schedule_clock", "waiting"):
            assert counts[f"{ns}/{t}"] == ticks
        assert types[f"{ns}/tool_pose"] == "geometry_msgs/msg/PoseStamped"
        assert types[f"{ns}/supervised"] == "std_msgs/msg/Bool"
        assert types[f"{ns}/ref_sample"] == "std_msgs/msg/Float64"
        expected_topics |= {f"{ns}/{t}" for t in [*per_sample, "schedule_clock", "waiting"]}
    assert set(counts) == expected_topics


def test_the_decoded_run_is_the_runs_csv_files(run_20) -> None:
    """Round 1, robot 1: the pose's x, the force, the log and the flags as mcap-ros2-support
    decodes them equal the execution files of the same run."""
    first = [m for m in decoded(run_20["bag"]) if m[0] != "/tandem/schedule"]
    end = next(
        m[2] for m in decoded(run_20["bag"]) if m[0] == "/tandem/schedule" and m[3]["round"] == 2
    )
    pick = lambda topic: [m[3] for m in first if m[0] == topic and m[2] < end]  # noqa: E731
    csv = run_20["csv"]
    exe = np.loadtxt(csv / "round_1_robot_1.csv", delimiter=",", skiprows=1)
    header = (csv / "round_1_robot_1.csv").read_text().split("\n", 1)[0].split(",")
    log = np.loadtxt(csv / "round_1_robot_1.reflog.csv", skiprows=1)
    flags = np.loadtxt(csv / "round_1_robot_1.corr.csv", delimiter=",", skiprows=1)
    poses = pick("/robot_1/tool_pose")
    assert [p.pose.position.x for p in poses] == list(exe[:, header.index("tool_pose.x")])
    assert [p.pose.orientation.w for p in poses] == list(exe[:, header.index("tool_pose.qw")])
    stamps = [p.header.stamp.sec * 10**9 + p.header.stamp.nanosec for p in poses]
    assert stamps == sorted(stamps) and len(set(np.diff(stamps))) <= 2  # 10 ms ± 1 ns
    assert [m.data for m in pick("/robot_1/wrench/fz")] == list(exe[:, header.index("wrench.fz")])
    assert [m.data for m in pick("/robot_1/ref_sample")] == list(log)
    assert [m.data for m in pick("/robot_1/supervised")] == [bool(v) for v in flags[:, 0]]
    assert [m.data for m in pick("/robot_1/corrected")] == [bool(v) for v in flags[:, 1]]


def test_record_from_the_bag_equals_record_from_the_csv_files(run_20, tmp_path: Path) -> None:
    a, b = tmp_path / "a.tandem", tmp_path / "b.tandem"
    for p in (a, b):
        p.write_bytes(run_20["state"].read_bytes())
    run_cli("record", a, run_20["bag"], "--round", 1)
    csv = run_20["csv"]
    args = []
    for r in (1, 2):
        stem = csv / f"round_1_robot_{r}"
        args += ["--execution", f"{stem}.csv", "--log", f"{stem}.reflog.csv",
                 "--corrections", f"{stem}.corr.csv"]
    run_cli("record", b, *args)
    assert a.read_bytes() == b.read_bytes()


def write_python_bag(path: Path, demo_csv: Path, tool_rate_hz: float = 50.0) -> None:
    """The example demonstration ``demo_csv`` (columns t, x, force at 100 Hz) as a ROS 2 bag
    written by mcap-ros2-support: ``/pose`` at 100 Hz, ``/wrench`` at 200 Hz (linear
    interpolation of the force), ``/tool`` (Bool, always on) at ``tool_rate_hz``."""
    data = np.loadtxt(demo_csv, delimiter=",", skiprows=1)
    t, x, force = data[:, 0], data[:, 1], data[:, 2]
    with open(path, "wb") as f:
        w = Ros2Writer(f)
        pose = w.register_msgdef("geometry_msgs/msg/PoseStamped", POSE_STAMPED)
        wrench = w.register_msgdef("geometry_msgs/msg/WrenchStamped", WRENCH_STAMPED)
        tool = w.register_msgdef("std_msgs/msg/Bool", BOOL)
        stamp = lambda ns: {"sec": ns // 10**9, "nanosec": ns % 10**9}  # noqa: E731
        for k, tk in enumerate(t):
            ns = round(tk * 1e9)
            msg = {
                "header": {"stamp": stamp(ns), "frame_id": "plate"},
                "pose": {"position": {"x": x[k], "y": 0.1, "z": 0.0},
                         "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}},
            }
            w.write_message("/pose", pose, msg, log_time=ns, publish_time=ns)
        for tw in np.arange(0.0, t[-1] + 1e-9, 0.005):
            ns = round(tw * 1e9)
            fz = float(np.interp(tw, t, force))
            msg = {
                "header": {"stamp": stamp(ns), "frame_id": "tool"},
                "wrench": {"force": {"x": 0.0, "y": 0.0, "z": fz},
                           "torque": {"x": 0.0, "y": 0.0, "z": 0.0}},
            }
            w.write_message("/wrench", wrench, msg, log_time=ns, publish_time=ns)
        for tb in np.arange(0.0, t[-1] + 1e-9, 1.0 / tool_rate_hz):
            ns = round(tb * 1e9)
            w.write_message("/tool", tool, {"data": True}, log_time=ns, publish_time=ns)
        w.finish()


def test_tandem_reads_a_bag_python_wrote(tmp_path: Path) -> None:
    bag = tmp_path / "demo_0.mcap"
    write_python_bag(bag, EXAMPLES / "demo_0.csv")
    rec = tandem.read_bag(bag)
    assert rec["channels"][:3] == ["pose.x", "pose.y", "pose.z"]
    assert "wrench.fz" in rec["channels"] and rec["channels"][-1] == "tool"
    # The slowest topic that is interpolated (/pose, 100 Hz) sets the default grid: the 50 Hz
    # /tool flag is held, so it does not halve the pose's rate; there the pose is exact.
    assert rec["dt_s"] == 0.01
    rec = tandem.read_bag(bag, rate=100.0)
    csv = np.loadtxt(EXAMPLES / "demo_0.csv", delimiter=",", skiprows=1)
    n = rec["samples"].shape[0]
    x = rec["samples"][:, rec["channels"].index("pose.x")]
    fz = rec["samples"][:, rec["channels"].index("wrench.fz")]
    np.testing.assert_array_equal(x, csv[:n, 1])
    np.testing.assert_allclose(fz, csv[:n, 2], rtol=0, atol=1e-12)
    assert np.all(rec["samples"][:, -1] == 1.0)
    assert rec["quaternions"] == [("pose.q", ["pose.qx", "pose.qy", "pose.qz", "pose.qw"])]
    topics = {t["topic"]: t for t in rec["topics"]}
    assert topics["/tool"]["log_time"] and not topics["/pose"]["log_time"]
    # Only some topics, in the order given.
    rec = tandem.read_bag(bag, topics=["/wrench", "/pose"], rate=100.0)
    assert rec["channels"][0] == "wrench.fx" and rec["channels"][6] == "pose.x"


def test_fit_takes_python_bags_and_gives_the_csv_model(tmp_path: Path) -> None:
    bags = []
    for i in range(3):
        bag = tmp_path / f"demo_{i}.mcap"
        write_python_bag(bag, EXAMPLES / f"demo_{i}.csv", tool_rate_hz=100.0)
        bags.append(bag)
    params = str(EXAMPLES / "params.toml")
    from_bags = tandem.fit(bags, params=params)
    from_csv = tandem.fit([EXAMPLES / f"demo_{i}.csv" for i in range(3)], params=params)
    assert from_bags.model.n_ref == from_csv.model.n_ref
    # The wrench's force is the CSV's force; zero channels add no variance.
    np.testing.assert_allclose(from_bags.model.sigma2_d, from_csv.model.sigma2_d, atol=1e-9)


def test_a_bad_bag_is_an_input_error_naming_the_file(tmp_path: Path) -> None:
    bag = tmp_path / "cut.mcap"
    write_python_bag(bag, EXAMPLES / "demo_0.csv")
    data = bag.read_bytes()
    bag.write_bytes(data[: len(data) // 2])
    with pytest.raises(tandem.InputError, match="truncated MCAP file") as e:
        tandem.read_bag(bag)
    assert e.value.file == str(bag)
    with pytest.raises(tandem.InputError, match="truncated"):
        tandem.fit([bag, bag])
    with pytest.raises(tandem.ParamError):
        tandem.read_bag(BAGS[0], rate=-1.0)
