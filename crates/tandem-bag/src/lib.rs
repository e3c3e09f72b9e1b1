//! ROS 2 bags for tandem: rosbag2 MCAP recordings in, simulated runs out.
//!
//! - **Reading** ([`read_bag`], [`read_executions`], [`inspect`]). A bag's topics of the six
//!   supported types ([`MsgType`]: `PoseStamped`, `WrenchStamped`, `TwistStamped`,
//!   `JointState`, `Float64`, `Bool`, all ROS 2 CDR) become the same plain data the CSV
//!   readers give: a [`tandem_lfd::Demonstration`] (paper Eq. 1) or the planner's
//!   [`tandem_planner::ExecutionRecord`]s (samples, reference-time log of Eq. 21, supervised
//!   and corrected flags). Channel names come from the topic and the field
//!   (`/tool_pose` → `tool_pose.x … tool_pose.qw`, `/wrench` → `wrench.fx … wrench.tz`,
//!   `/joints` → `joints.<joint>.position`, a `Float64` or `Bool` topic → its name), or from
//!   the channel record's [`FIELDS_KEY`] metadata that tandem writes.
//! - **Resampling.** Every topic keeps its own rate in the bag; the reader lays one grid over
//!   the span all selected topics cover (from the latest first message to the earliest last
//!   one) at a chosen rate (default: the rate of the slowest topic that is interpolated,
//!   every type but `Bool`, its period snapped as for a CSV `t` column, and
//!   [`Recording::grid_note`] says which topic that was; an execution: the model's `Δt_s`)
//!   and interpolates each topic onto it by the one resampling policy of
//!   `tandem_lfd::resample` (as CSV logs and executions): linearly, orientations by slerp,
//!   flags (`Bool`, any channel whose every value is 0 or 1) held. Times are header stamps (log times where there is no header). A gap
//!   or a late start or early end of more than [`GAP_FACTOR`] × a topic's median period is an
//!   error, not interpolated across.
//! - **Writing** ([`RunWriter`], [`BagWriter`], [`write_demonstration`]). A simulated run
//!   (`tandem simulate --bag`, `cargo xtask study --bag`) as MCAP that Foxglove shows without
//!   plugins: poses as `geometry_msgs/msg/PoseStamped` and every other per-tick series as
//!   `std_msgs` `Float64`/`Bool`, all ROS 2 CDR with their `ros2msg` schemas, and the schedule
//!   of every round as JSON with a JSON Schema. It reads back through [`read_executions`] to
//!   the same executions, bit for bit.
//!
//! Every error ([`Error`]) names the file, the topic and, for a bad message, its 1-based index
//! in the topic.
//!
//! ```
//! use tandem_bag::{BagOptions, BagWriter, Existing, Message, MsgType, read_bag};
//! # let dir = std::env::temp_dir().join(format!("tandem-bag-doc-{}", std::process::id()));
//! # std::fs::create_dir_all(&dir)?;
//! let path = dir.join("demo.mcap");
//! // A force topic at 100 Hz and a tool flag at 10 Hz, both over 1 s.
//! let mut bag = BagWriter::create(&path, true, Existing::Replace)?;
//! let force = bag.add_topic("/force", MsgType::Float64, &Default::default())?;
//! let tool = bag.add_topic("/tool", MsgType::Bool, &Default::default())?;
//! for k in 0..=100 {
//!     bag.write(force, k * 10_000_000, &Message::Float64(k as f64))?;
//! }
//! for k in 0..=10 {
//!     bag.write(tool, k * 100_000_000, &Message::Bool(k >= 5))?;
//! }
//! bag.finish()?;
//! // The default grid is the rate of the slowest topic that is interpolated: the force's
//! // 100 Hz (the 10 Hz flag is held between its messages): 101 samples.
//! let rec = read_bag(&path, &BagOptions::default())?;
//! assert_eq!(rec.channel_names, ["force", "tool"]);
//! assert_eq!((rec.n_samples(), rec.dt_s), (101, 0.01));
//! assert_eq!(rec.grid_topic.as_deref(), Some("/force"));
//! assert_eq!(&rec.samples[2 * 50..2 * 51], &[50.0, 1.0]); // t = 0.5 s
//! assert_eq!(&rec.samples[2 * 49..2 * 50], &[49.0, 0.0]); // t = 0.49 s: the flag held
//! // At 40 Hz the force is interpolated and the flag held.
//! let rec = read_bag(&path, &BagOptions { rate_hz: Some(40.0), ..Default::default() })?;
//! assert_eq!(rec.n_samples(), 41);
//! assert_eq!(&rec.samples[2 * 19..2 * 20], &[47.5, 0.0]); // t = 0.475 s
//! # std::fs::remove_dir_all(&dir)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod error;
mod msg;
mod read;
mod recording;
mod resample;
mod run;
mod write;

pub use error::{Error, Result};
pub use msg::{ALL_TYPES, MsgType, joint_columns};
pub use read::{FIELDS_KEY, QUAT_NORM_TOL, ROLE_KEY, Role, SCHEDULE_TOPIC};
pub use recording::{
    BagOptions, ExecutionOptions, Recording, TopicInfo, count_rounds, extend_schema, inspect,
    read_bag, read_executions, robot_namespace,
};
pub use resample::SNAP_NS;
pub use run::{RunRobotLog, RunRoundLog, RunWriter, SCHEDULE_SCHEMA, read_run};
pub use write::{BagWriter, Existing, Message, TopicId, TopicSpec, write_demonstration};

/// Largest accepted gap between consecutive messages of a topic, and largest late start or
/// early end of a topic against the others, as a multiple of the topic's median message
/// period: 3. One or two dropped messages (a gap of 2–3 periods) are interpolated across; a
/// longer silence is a recording problem that interpolation would paper over.
pub const GAP_FACTOR: f64 = 3.0;

/// Whether `path` names a bag: the extension `.mcap` (any case).
#[must_use]
pub fn is_bag(path: &std::path::Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mcap"))
}

/// The MCAP file `path` names: `path` itself unless it is a folder; for a folder (a rosbag2
/// recording: `ros2 bag record -s mcap -o demo_0` writes `demo_0/metadata.yaml` and
/// `demo_0/demo_0_0.mcap`) the one `.mcap` file in it.
///
/// # Errors
/// [`Error::Layout`] for a folder with no `.mcap` file, or with several (a recording split
/// into parts), naming what it holds and the fix; [`Error::Io`] when it cannot be listed.
pub fn bag_file(path: &std::path::Path) -> Result<std::path::PathBuf> {
    if !path.is_dir() {
        return Ok(path.to_path_buf());
    }
    let file = path.display().to_string();
    let entries = std::fs::read_dir(path).map_err(|source| Error::Io {
        file: file.clone(),
        what: "cannot list the folder",
        source,
    })?;
    let mut mcaps: Vec<std::path::PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file() && is_bag(p))
        .collect();
    mcaps.sort();
    let rosbag2 = path.join("metadata.yaml").is_file();
    match &mcaps[..] {
        [one] => Ok(one.clone()),
        [] => Err(Error::Layout {
            file,
            why: format!(
                "a folder{}, without an .mcap file in it: give a file (a demonstration is a \
                 CSV, .json or .mcap file; tandem reads rosbag2 recordings made with `ros2 bag \
                 record -s mcap`)",
                if rosbag2 {
                    " (a rosbag2 recording: metadata.yaml)"
                } else {
                    ""
                }
            ),
        }),
        several => Err(Error::Layout {
            file,
            why: format!(
                "a folder with {} .mcap files ({}): a recording split into parts, or several \
                 recordings; give one .mcap file per demonstration (`ros2 bag convert` merges \
                 the parts of one recording into one file)",
                several.len(),
                several
                    .iter()
                    .map(|p| p.display().to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        }),
    }
}
