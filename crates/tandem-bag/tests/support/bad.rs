//! The catalogue of bad bags: every way a recording can be broken that the reader must
//! refuse, each with the topic selection to read it with and what the error must say.
//! Shared by `tandem-bag`'s tests and the command line's (`#[path]` include); the including
//! file names the bag crate `bag` (`use tandem_bag as bag;` or `use tandem::bag;`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::bag::{BagWriter, Existing, Message, MsgType};

/// One bad bag.
pub(crate) struct BadBag {
    /// What is wrong, for messages.
    pub(crate) name: &'static str,
    /// The file.
    pub(crate) path: PathBuf,
    /// `--topics`, if the case needs a selection.
    pub(crate) topics: Option<Vec<String>>,
    /// Fragments the error message must contain (besides the file name).
    pub(crate) needles: Vec<&'static str>,
}

const MS: i64 = 1_000_000;

fn pose(x: f64) -> Message<'static> {
    Message::Pose {
        position: [x, 0.0, 0.0],
        orientation: [0.0, 0.0, 0.0, 1.0],
    }
}

/// A good two-topic recording: `/pose` at 100 Hz and `/force` (Float64) at 100 Hz for 1 s,
/// through `edit(k, message)` which may change message `k` (0-based) of `/force`
/// (returning its time in ns and value) or drop it (`None`).
fn write_good(path: &Path, edit: impl Fn(usize) -> Option<(i64, f64)>) {
    let mut bag = BagWriter::create(path, true, Existing::Replace).unwrap();
    let p = bag
        .add_topic("/pose", MsgType::PoseStamped, &BTreeMap::new())
        .unwrap();
    let f = bag
        .add_topic("/force", MsgType::Float64, &BTreeMap::new())
        .unwrap();
    for k in 0..=100 {
        bag.write(p, k as i64 * 10 * MS, &pose(k as f64 * 0.01))
            .unwrap();
        if let Some((t, v)) = edit(k) {
            bag.write(f, t, &Message::Float64(v)).unwrap();
        }
    }
    bag.finish().unwrap();
}

fn normal(k: usize) -> Option<(i64, f64)> {
    Some((k as i64 * 10 * MS, k as f64))
}

/// Writes every bad bag into `dir` and returns the catalogue.
pub(crate) fn catalogue(dir: &Path) -> Vec<BadBag> {
    std::fs::create_dir_all(dir).unwrap();
    let mut out = Vec::new();
    let mut case = |name: &'static str, topics: Option<Vec<String>>, needles: Vec<&'static str>| {
        let path = dir.join(format!("{}.mcap", name.replace(' ', "_")));
        out.push(BadBag {
            name,
            path,
            topics,
            needles,
        });
        out.last().unwrap().path.clone()
    };
    let good = dir.join("good.mcap");
    write_good(&good, normal);
    let good_bytes = std::fs::read(&good).unwrap();

    let p = case("truncated", None, vec!["truncated MCAP file"]);
    std::fs::write(&p, &good_bytes[..good_bytes.len() / 2]).unwrap();

    let p = case("wrong magic", None, vec!["not an MCAP file"]);
    let mut bytes = good_bytes.clone();
    bytes[1] = b'X';
    std::fs::write(&p, bytes).unwrap();

    let p = case("a csv named mcap", None, vec!["not an MCAP file"]);
    std::fs::write(&p, "t,x\n0,1\n0.01,2\n").unwrap();

    let p = case("empty", None, vec!["truncated MCAP file"]);
    std::fs::write(&p, b"").unwrap();

    let p = case(
        "unknown schema",
        Some(vec!["/pose".into(), "/tf".into()]),
        vec!["topic `/tf`", "unknown schema `tf2_msgs/msg/TFMessage`"],
    );
    {
        let mut w =
            mcap::Writer::new(std::io::BufWriter::new(std::fs::File::create(&p).unwrap())).unwrap();
        let s = w
            .add_schema(
                "tf2_msgs/msg/TFMessage",
                "ros2msg",
                b"geometry_msgs/TransformStamped[] transforms\n",
            )
            .unwrap();
        let c = w.add_channel(s, "/tf", "cdr", &BTreeMap::new()).unwrap();
        let ps = w
            .add_schema(
                "geometry_msgs/msg/PoseStamped",
                "ros2msg",
                MsgType::PoseStamped.schema_text().as_bytes(),
            )
            .unwrap();
        let pc = w.add_channel(ps, "/pose", "cdr", &BTreeMap::new()).unwrap();
        for k in 0..10u64 {
            let header = |channel_id| mcap::records::MessageHeader {
                channel_id,
                sequence: k as u32,
                log_time: k * 10_000_000,
                publish_time: k * 10_000_000,
            };
            w.write_to_known_channel(&header(c), &[0, 1, 0, 0, 0, 0, 0, 0])
                .unwrap();
            let mut pose_bytes = vec![0, 1, 0, 0];
            pose_bytes.extend_from_slice(&(k as i32).to_le_bytes()); // sec
            pose_bytes.extend_from_slice(&0u32.to_le_bytes()); // nanosec
            pose_bytes.extend_from_slice(&1u32.to_le_bytes()); // frame_id ""
            pose_bytes.extend_from_slice(&[0, 0, 0, 0]); // NUL + padding to 16
            for v in [0.0f64, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0] {
                pose_bytes.extend_from_slice(&v.to_le_bytes());
            }
            w.write_to_known_channel(&header(pc), &pose_bytes).unwrap();
        }
        w.finish().unwrap();
    }

    let p = case(
        "missing schema",
        None,
        vec!["topic `/force`", "missing schema"],
    );
    {
        let mut w =
            mcap::Writer::new(std::io::BufWriter::new(std::fs::File::create(&p).unwrap())).unwrap();
        let c = w.add_channel(0, "/force", "cdr", &BTreeMap::new()).unwrap();
        for k in 0..10u64 {
            let header = mcap::records::MessageHeader {
                channel_id: c,
                sequence: k as u32,
                log_time: k * 10_000_000,
                publish_time: k * 10_000_000,
            };
            w.write_to_known_channel(&header, &[0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 240, 63])
                .unwrap();
        }
        w.finish().unwrap();
    }

    let p = case("no messages", None, vec!["topic `/force`", "0 message(s)"]);
    write_good(&p, |_| None);

    let p = case("one message", None, vec!["topic `/force`", "1 message(s)"]);
    write_good(&p, |k| if k == 0 { normal(k) } else { None });

    let p = case(
        "two topics give one channel",
        None,
        vec!["channel `pose.x` comes from both `/pose` and `/pose.x`"],
    );
    {
        let mut bag = BagWriter::create(&p, false, Existing::Replace).unwrap();
        let a = bag
            .add_topic("/pose", MsgType::PoseStamped, &BTreeMap::new())
            .unwrap();
        let b = bag
            .add_topic("/pose.x", MsgType::Float64, &BTreeMap::new())
            .unwrap();
        for k in 0..10 {
            bag.write(a, k * 10 * MS, &pose(0.0)).unwrap();
            bag.write(b, k * 10 * MS, &Message::Float64(0.0)).unwrap();
        }
        bag.finish().unwrap();
    }

    let p = case(
        "non-finite value",
        None,
        vec![
            "topic `/force`",
            "message 6",
            "field `data`",
            "non-finite value NaN",
        ],
    );
    write_good(&p, |k| {
        normal(k).map(|(t, v)| (t, if k == 5 { f64::NAN } else { v }))
    });

    let p = case(
        "infinite position",
        None,
        vec![
            "topic `/pose`",
            "message 4",
            "field `x`",
            "non-finite value inf",
        ],
    );
    {
        let mut bag = BagWriter::create(&p, false, Existing::Replace).unwrap();
        let t = bag
            .add_topic("/pose", MsgType::PoseStamped, &BTreeMap::new())
            .unwrap();
        for k in 0..10 {
            let x = if k == 3 { f64::INFINITY } else { 0.0 };
            bag.write(t, k * 10 * MS, &pose(x)).unwrap();
        }
        bag.finish().unwrap();
    }

    let p = case(
        "header stamps going backwards",
        None,
        vec![
            "topic `/pose`",
            "message 8",
            "header stamp",
            "does not increase",
        ],
    );
    {
        let mut bag = BagWriter::create(&p, false, Existing::Replace).unwrap();
        let t = bag
            .add_topic("/pose", MsgType::PoseStamped, &BTreeMap::new())
            .unwrap();
        for k in 0..20i64 {
            let time = if k == 7 { 5 * 10 * MS } else { k * 10 * MS };
            bag.write(t, time, &pose(0.0)).unwrap();
        }
        bag.finish().unwrap();
    }

    let p = case(
        "log times going backwards",
        None,
        vec![
            "topic `/force`",
            "message 31",
            "log time",
            "does not increase",
        ],
    );
    write_good(&p, |k| {
        normal(k).map(|(t, v)| (if k == 30 { t - 25 * MS } else { t }, v))
    });

    let p = case(
        "gap",
        None,
        vec![
            "topic `/force`",
            "message 46",
            "a gap of 0.06 s",
            "median period is 0.01 s",
        ],
    );
    write_good(&p, |k| {
        if (45..50).contains(&k) {
            None
        } else {
            normal(k)
        }
    });

    let p = case(
        "late start",
        None,
        vec!["topic `/force` starts 0.5 s after topic `/pose`"],
    );
    write_good(&p, |k| if k < 50 { None } else { normal(k) });

    let p = case(
        "unset orientation",
        None,
        vec![
            "topic `/pose`",
            "message 1",
            "field `orientation`",
            "norm 0",
        ],
    );
    {
        let mut bag = BagWriter::create(&p, false, Existing::Replace).unwrap();
        let t = bag
            .add_topic("/pose", MsgType::PoseStamped, &BTreeMap::new())
            .unwrap();
        for k in 0..10 {
            let m = Message::Pose {
                position: [0.0; 3],
                orientation: [0.0; 4],
            };
            bag.write(t, k * 10 * MS, &m).unwrap();
        }
        bag.finish().unwrap();
    }

    let p = case(
        "joint names change",
        None,
        vec!["topic `/joints`", "message 3", "joint names or arrays"],
    );
    {
        let mut bag = BagWriter::create(&p, false, Existing::Replace).unwrap();
        let t = bag
            .add_topic("/joints", MsgType::JointState, &BTreeMap::new())
            .unwrap();
        let (ab, ac) = (
            vec!["a".to_owned(), "b".to_owned()],
            vec!["a".to_owned(), "c".to_owned()],
        );
        for k in 0..10 {
            let names = if k == 2 { &ac } else { &ab };
            let m = Message::Joints {
                names,
                position: &[0.1, 0.2],
                velocity: &[],
                effort: &[],
            };
            bag.write(t, k * 10 * MS, &m).unwrap();
        }
        bag.finish().unwrap();
    }

    let p = case(
        "undecodable message",
        None,
        vec![
            "topic `/pose`",
            "message 1",
            "not a valid geometry_msgs/msg/PoseStamped",
        ],
    );
    {
        let mut w =
            mcap::Writer::new(std::io::BufWriter::new(std::fs::File::create(&p).unwrap())).unwrap();
        let s = w
            .add_schema(
                "geometry_msgs/msg/PoseStamped",
                "ros2msg",
                MsgType::PoseStamped.schema_text().as_bytes(),
            )
            .unwrap();
        let c = w.add_channel(s, "/pose", "cdr", &BTreeMap::new()).unwrap();
        for k in 0..10u64 {
            let header = mcap::records::MessageHeader {
                channel_id: c,
                sequence: k as u32,
                log_time: k * 10_000_000,
                publish_time: k * 10_000_000,
            };
            w.write_to_known_channel(&header, &[0, 1, 0, 0, 9, 9])
                .unwrap();
        }
        w.finish().unwrap();
    }

    let p = case("corrupt chunk", None, vec!["corrupt MCAP file"]);
    {
        // A chunk's compressed bytes changed in the middle: its CRC (or zstd) fails.
        let mut bytes = good_bytes.clone();
        let mid = bytes.len() / 3;
        for b in &mut bytes[mid..mid + 8] {
            *b ^= 0x5a;
        }
        std::fs::write(&p, bytes).unwrap();
    }

    let p = case(
        "no supported topic",
        None,
        vec![
            "no topic of a supported type",
            "/tf (tf2_msgs/msg/TFMessage)",
        ],
    );
    {
        let mut w =
            mcap::Writer::new(std::io::BufWriter::new(std::fs::File::create(&p).unwrap())).unwrap();
        let s = w
            .add_schema(
                "tf2_msgs/msg/TFMessage",
                "ros2msg",
                b"geometry_msgs/TransformStamped[] transforms\n",
            )
            .unwrap();
        let c = w.add_channel(s, "/tf", "cdr", &BTreeMap::new()).unwrap();
        let header = mcap::records::MessageHeader {
            channel_id: c,
            sequence: 0,
            log_time: 0,
            publish_time: 0,
        };
        w.write_to_known_channel(&header, &[0, 1, 0, 0, 0, 0, 0, 0])
            .unwrap();
        w.finish().unwrap();
    }

    let p = case(
        "topic not in the bag",
        Some(vec!["/pose".into(), "/wrench".into()]),
        vec![
            "no topic `/wrench`",
            "/pose (geometry_msgs/msg/PoseStamped)",
        ],
    );
    write_good(&p, normal);
    out
}
