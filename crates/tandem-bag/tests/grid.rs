//! The default grid of a bag: the slowest topic that is interpolated sets it (a `Bool` flag
//! is held, so a 50 Hz valve does not coarsen a 100 Hz pose), its period is snapped as for a
//! CSV `t` column, and the recording says which topic set it and how to choose another rate.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use tandem_bag::{BagOptions, BagWriter, Existing, Message, MsgType, inspect, read_bag};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tandem-bag-grid-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A valve whose logger runs 0.07 % slow: 50 Hz nominal, a message every 20.01408 ms (the
/// period an unsnapped median gave before).
const VALVE_NS: i64 = 20_014_080;

/// 1 s of `/pose` (`PoseStamped`, 100 Hz, its x = time in s), `/wrench` (250 Hz, fz = 2·t)
/// and `/valve` (`Bool`, [`VALVE_NS`], open from 0.5 s), when `with_pose`; else the valve
/// alone.
fn write(path: &Path, with_pose: bool) {
    let mut bag = BagWriter::create(path, false, Existing::Replace).unwrap();
    let none = BTreeMap::new();
    if with_pose {
        let pose = bag.add_topic("/pose", MsgType::PoseStamped, &none).unwrap();
        let wrench = bag
            .add_topic("/wrench", MsgType::WrenchStamped, &none)
            .unwrap();
        for k in 0..=100 {
            let t = k as f64 * 0.01;
            let message = Message::Pose {
                position: [t, 0.0, 0.0],
                orientation: [0.0, 0.0, 0.0, 1.0],
            };
            bag.write(pose, k * 10_000_000, &message).unwrap();
        }
        for k in 0..=250 {
            let t = k as f64 * 0.004;
            let message = Message::Wrench {
                force: [0.0, 0.0, 2.0 * t],
                torque: [0.0; 3],
            };
            bag.write(wrench, k * 4_000_000, &message).unwrap();
        }
    }
    let valve = bag.add_topic("/valve", MsgType::Bool, &none).unwrap();
    for k in 0..=50 {
        let t = k * VALVE_NS;
        bag.write(valve, t, &Message::Bool(t >= 500_000_000))
            .unwrap();
    }
    bag.finish().unwrap();
}

#[test]
fn the_slowest_interpolated_topic_sets_the_grid_and_the_note_names_it() {
    let dir = scratch("pose");
    let path = dir.join("demo.mcap");
    write(&path, true);
    let rec = read_bag(&path, &BagOptions::default()).unwrap();
    // The pose's 100 Hz, not the valve's 50 Hz: 101 samples over 1 s.
    assert_eq!(rec.dt_s, 0.01);
    assert_eq!(rec.n_samples(), 101);
    assert_eq!(rec.grid_topic.as_deref(), Some("/pose"));
    let x = rec
        .channel_names
        .iter()
        .position(|c| c == "pose.x")
        .unwrap();
    let valve = rec.channel_names.iter().position(|c| c == "valve").unwrap();
    let m = rec.channel_names.len();
    assert_eq!(rec.samples[37 * m + x], 37.0 * 0.01);
    // The valve is held between its messages: closed up to its last message before 0.5 s
    // (at 0.48 s), open from its message at 0.50035 s, so still closed at the 0.50 s sample.
    assert_eq!(rec.samples[50 * m + valve], 0.0);
    assert_eq!(rec.samples[51 * m + valve], 1.0);
    let note = rec.grid_note().unwrap();
    assert_eq!(
        note,
        format!(
            "{}: grid of 100 Hz (0.01 s), the rate of /pose (PoseStamped, 100 Hz), the slowest \
             topic that is interpolated; /valve (Bool, 50 Hz) held between messages, not \
             interpolated, so not setting it; for another grid give --rate HZ (Python: rate=)",
            path.display()
        )
    );
    // The valve's period is snapped to 20 ms, as a CSV `t` column's would be.
    let info = inspect(&path).unwrap();
    let period = |name: &str| {
        info.iter()
            .find(|t| t.topic == name)
            .unwrap()
            .period_s
            .unwrap()
    };
    assert_eq!(
        (period("/pose"), period("/wrench"), period("/valve")),
        (0.01, 0.004, 0.02)
    );
    // A rate given is used as it is, and there is nothing to note.
    let given = read_bag(
        &path,
        &BagOptions {
            rate_hz: Some(50.0),
            ..BagOptions::default()
        },
    )
    .unwrap();
    assert_eq!((given.dt_s, given.n_samples()), (0.02, 51));
    assert_eq!(
        (given.grid_topic.as_deref(), given.grid_note()),
        (None, None)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn flags_alone_set_a_snapped_grid() {
    let dir = scratch("valve");
    let path = dir.join("valve.mcap");
    write(&path, false);
    let rec = read_bag(&path, &BagOptions::default()).unwrap();
    // 20.01408 ms stamps: 50 Hz within 0.1 %, so exactly 0.02 s, not 0.02001408 s.
    assert_eq!(rec.dt_s, 0.02);
    assert_eq!(rec.grid_topic.as_deref(), Some("/valve"));
    let note = rec.grid_reason().unwrap();
    assert!(
        note.starts_with("grid of 50 Hz (0.02 s), the rate of /valve (Bool, 50 Hz), the slowest topic (every topic is a Bool)"),
        "{note}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_rosbag2_folder_is_read_through_its_one_mcap_file() {
    let dir = scratch("folder");
    let rec = dir.join("demo_0");
    std::fs::create_dir_all(&rec).unwrap();
    std::fs::write(
        rec.join("metadata.yaml"),
        "rosbag2_bagfile_information: {}\n",
    )
    .unwrap();
    // No .mcap yet: the folder is named with the fix.
    let e = tandem_bag::bag_file(&rec).unwrap_err().to_string();
    assert!(
        e.starts_with(&format!(
            "{}: a folder (a rosbag2 recording: metadata.yaml), without an .mcap file",
            rec.display()
        )),
        "{e}"
    );
    write(&rec.join("demo_0_0.mcap"), true);
    assert_eq!(
        tandem_bag::bag_file(&rec).unwrap(),
        rec.join("demo_0_0.mcap")
    );
    // A file is itself.
    let file = rec.join("demo_0_0.mcap");
    assert_eq!(tandem_bag::bag_file(&file).unwrap(), file);
    // Two parts: which one is ambiguous, so both are named.
    write(&rec.join("demo_0_1.mcap"), false);
    let e = tandem_bag::bag_file(&rec).unwrap_err().to_string();
    assert!(
        e.contains("a folder with 2 .mcap files") && e.contains("demo_0_1.mcap"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
