//! One recording, one set of samples: the same messages written as a ROS 2 bag and as a CSV
//! log with a `t` column give the same samples on the same grid, because the bag reader and
//! the CSV reader resample by the one policy of `tandem_lfd::resample` (a quaternion by
//! slerp, a flag held, the rest linear). Before it, the CSV reader interpolated the
//! quaternion's channels linearly and the bag slerped them: 3.5e-3 apart on this recording.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::PathBuf;

use tandem_bag::{BagOptions, BagWriter, Existing, Message, MsgType, extend_schema, read_bag};
use tandem_lfd::{ChannelSchema, Demonstration};

fn scratch() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tandem-bag-one-policy-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Message `k` of 101: 10 ms apart with ±3 ms of jitter on every other message (the first and
/// last on time), so every grid time but the ends falls between two messages.
fn time_ns(k: i64) -> i64 {
    let jitter = if k % 2 == 1 && k < 100 { 3_000_000 } else { 0 };
    k * 10_000_000 + jitter
}

/// The pose at message `k`: x = sin, a turn of 0.4 rad per message about an axis tilted off
/// z (large steps, where slerp and linear interpolation differ), and a valve open from
/// message 40 to 69.
fn pose(k: i64) -> ([f64; 3], [f64; 4], bool) {
    let angle = 0.4 * k as f64;
    let axis = [0.6, 0.0, 0.8];
    let (s, c) = ((0.5 * angle).sin(), (0.5 * angle).cos());
    (
        [(0.1 * k as f64).sin(), 0.02 * k as f64, 1.0],
        [s * axis[0], s * axis[1], s * axis[2], c],
        (40..70).contains(&k),
    )
}

#[test]
fn one_recording_as_a_bag_and_as_a_csv_log_gives_the_same_samples() {
    let dir = scratch();
    let path = dir.join("rec.mcap");
    let mut bag = BagWriter::create(&path, false, Existing::Replace).unwrap();
    let none = BTreeMap::new();
    let pose_id = bag.add_topic("/pose", MsgType::PoseStamped, &none).unwrap();
    let valve_id = bag.add_topic("/valve", MsgType::Bool, &none).unwrap();
    for k in 0..=100 {
        let (position, orientation, open) = pose(k);
        let t = time_ns(k);
        bag.write(
            pose_id,
            t,
            &Message::Pose {
                position,
                orientation,
            },
        )
        .unwrap();
        bag.write(valve_id, t, &Message::Bool(open)).unwrap();
    }
    bag.finish().unwrap();
    let rec = read_bag(&path, &BagOptions::default()).unwrap();
    assert_eq!((rec.dt_s, rec.n_samples()), (0.01, 101));

    // The same messages as a CSV log, in the bag's channel order, at full precision.
    let names = &rec.channel_names;
    let mut csv = format!("t,{}\n", names.join(","));
    for k in 0..=100 {
        let (p, q, open) = pose(k);
        let by_name = |name: &str| -> f64 {
            match name {
                "pose.x" => p[0],
                "pose.y" => p[1],
                "pose.z" => p[2],
                "pose.qx" => q[0],
                "pose.qy" => q[1],
                "pose.qz" => q[2],
                "pose.qw" => q[3],
                "valve" => f64::from(u8::from(open)),
                other => panic!("unexpected channel {other}"),
            }
        };
        write!(csv, "{:?}", time_ns(k) as f64 / 1e9).unwrap();
        for name in names {
            write!(csv, ",{:?}", by_name(name)).unwrap();
        }
        csv.push('\n');
    }
    let mut schema = ChannelSchema::default();
    extend_schema(&mut schema, std::slice::from_ref(&rec));
    let grid = Demonstration::regrid_csv_str_with(&csv, "rec.csv", Some(rec.dt_s), &schema)
        .unwrap()
        .demonstration;
    assert_eq!(grid.channel_names(), names.as_slice());
    assert_eq!(grid.n_samples(), rec.n_samples());
    let m = names.len();
    let mut worst = 0.0_f64;
    for j in 0..rec.n_samples() {
        for (c, (x, y)) in grid.sample(j).iter().zip(&rec.samples[j * m..]).enumerate() {
            assert!(
                (x - y).abs() <= 1e-9,
                "sample {j}, {}: {x} vs {y}",
                names[c]
            );
            worst = worst.max((x - y).abs());
        }
    }
    eprintln!("largest difference between the CSV and the bag: {worst:e}");
    // The old CSV policy (no quaternion block: every channel linear) is far from the bag.
    let no_blocks = ChannelSchema {
        quaternions: Vec::new(),
        ..ChannelSchema::default()
    };
    let linear = Demonstration::regrid_csv_str_with(&csv, "rec.csv", Some(rec.dt_s), &no_blocks)
        .unwrap()
        .demonstration;
    let old = (0..rec.n_samples() * m)
        .map(|i| (linear.sample(i / m)[i % m] - rec.samples[i]).abs())
        .fold(0.0, f64::max);
    eprintln!("with the quaternion's channels interpolated linearly: {old:e}");
    assert!(old > 1e-3, "{old}");

    // Not vacuous: at sample 1 (10 ms, 7/13 of the way from message 0 to message 1 at 13 ms)
    // the quaternion is the slerp, not the linear blend, and the valve is held.
    let col = |name: &str| names.iter().position(|n| n == name).unwrap();
    let u: f64 = 10.0 / 13.0;
    let (_, q1, _) = pose(1);
    let (_, q0, _) = pose(0);
    let qz = grid.sample(1)[col("pose.qz")];
    let slerp_qz = (0.5 * 0.4 * u).sin() * 0.8;
    let linear_qz = q0[2] + u * (q1[2] - q0[2]);
    assert!((qz - slerp_qz).abs() < 1e-12, "{qz} vs {slerp_qz}");
    assert!((qz - linear_qz).abs() > 1e-4, "{qz} vs {linear_qz}");
    // The valve opens at message 40 (400 ms) and closes at message 70 (700 ms): the samples
    // at 390 ms (between messages 38 and 39, both closed) and 700 ms closed, those at 400 ms
    // and 690 ms (between messages 68 and 69, both open) open.
    let v = col("valve");
    let at = |j: usize| grid.sample(j)[v];
    assert_eq!([at(39), at(40), at(69), at(70)], [0.0, 1.0, 1.0, 0.0]);
}
