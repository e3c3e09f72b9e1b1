//! The reading API: a bag's topics on one grid as a demonstration ([`read_bag`]), an
//! executed round's executions ([`read_executions`]), and what a bag holds ([`inspect`]).

use std::collections::BTreeMap;
use std::path::Path;

use tandem_lfd::{ChannelKind, ChannelSchema, Demonstration, Execution, QuaternionBlock};
use tandem_planner::ExecutionRecord;

use crate::msg::MsgType;
use crate::read::{RawTopic, Role, SCHEDULE_TOPIC, Selection, Series, read_topics, series, under};
use crate::resample::{Grid, grid, resample_into};
use crate::{Error, Result};
use tandem_lfd::resample::{Interpolation, is_flag};

/// How to read a bag as a demonstration.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BagOptions {
    /// The topics to read (full names, `/pose`), in this channel order; `None`: every topic of
    /// a supported type, in the file's order (topics tandem wrote for viewing only, such as a
    /// run's schedule clock, are left out).
    pub topics: Option<Vec<String>>,
    /// Rate of the common grid (Hz, finite > 0); `None`: the rate of the slowest selected
    /// topic that is interpolated (every type but `Bool`, whose flags are held; when every
    /// topic is a `Bool`, the slowest one), its period estimated and snapped as for a CSV
    /// `t` column ([`tandem_lfd::logger_period`]). [`Recording::grid_topic`] names it.
    pub rate_hz: Option<f64>,
    /// Read only the topics under this namespace (`/robot_1`) and name the channels relative
    /// to it; `None`: every topic, named from the root.
    pub namespace: Option<String>,
}

impl BagOptions {
    fn validate(&self) -> Result<()> {
        if let Some(r) = self.rate_hz
            && !(r.is_finite() && r > 0.0)
        {
            return Err(Error::BadParam {
                name: "rate",
                why: format!("{r} Hz: the grid rate must be finite and > 0"),
            });
        }
        if let Some(t) = &self.topics {
            if t.is_empty() {
                return Err(Error::BadParam {
                    name: "topics",
                    why: "an empty list; name at least one topic".into(),
                });
            }
            for (k, name) in t.iter().enumerate() {
                if t[..k].contains(name) {
                    return Err(Error::BadParam {
                        name: "topics",
                        why: format!("`{name}` is given twice"),
                    });
                }
            }
        }
        Ok(())
    }
}

/// One topic of a bag, as [`inspect`] and [`Recording::topics`] describe it.
#[derive(Clone, Debug, PartialEq)]
pub struct TopicInfo {
    /// Full topic name.
    pub topic: String,
    /// Schema name (the ROS type, e.g. `geometry_msgs/msg/PoseStamped`), or `None` without a
    /// schema.
    pub schema: Option<String>,
    /// The supported type, or `None` (the topic is never read).
    pub msg_type: Option<MsgType>,
    /// Messages in the file.
    pub messages: usize,
    /// Channel names its columns give (empty when the topic is not read).
    pub channels: Vec<String>,
    /// Median message period (s), when read with at least 2 messages.
    pub median_period_s: Option<f64>,
    /// Message period (s) as the grid would use it, when read: the span over the steps
    /// counted in median periods, snapped to a whole rate within 0.1 %
    /// ([`tandem_lfd::logger_period`]; 0.02 s for 50 Hz stamps that run 0.07 % slow).
    pub period_s: Option<f64>,
    /// Bag time (s) of its first and last message, when read.
    pub span_s: Option<(f64, f64)>,
    /// Whether its times are log times (no header, or all header stamps zero) rather than
    /// header stamps.
    pub log_time: bool,
    /// Its role (data channel, an execution's log or flags, or viewing only).
    pub role: Role,
}

/// A bag read onto one grid: channels, samples and period, and where they came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Recording {
    /// The file.
    pub source: String,
    /// Channel names, in column order: each selected topic's columns in turn.
    pub channel_names: Vec<String>,
    /// Samples, sample-major (`n_samples × channel_names.len()`), channel units.
    pub samples: Vec<f64>,
    /// Grid period `Δt_s` (s).
    pub dt_s: f64,
    /// The topic whose rate set the grid (`None`: the rate was given,
    /// [`BagOptions::rate_hz`]); see [`Recording::grid_note`].
    pub grid_topic: Option<String>,
    /// Bag time (s) of sample 0: the latest first message of the selected topics.
    pub start_s: f64,
    /// The topics read, in column order.
    pub topics: Vec<TopicInfo>,
    /// The orientation of every `PoseStamped` topic as a quaternion block (name `<stem>q`
    /// for channels `<stem>qx … <stem>qw`), for the fit's channel schema
    /// ([`extend_schema`]).
    pub quaternions: Vec<QuaternionBlock>,
}

impl Recording {
    /// Number of samples.
    #[must_use]
    pub fn n_samples(&self) -> usize {
        self.samples.len() / self.channel_names.len().max(1)
    }

    /// Why the grid has its rate, in one sentence without the file name (for a note; the
    /// command line prints it once for every bag it applies to): the topic whose rate set
    /// it, the `Bool` topics held rather than interpolated, and how to choose another rate.
    /// `None` when the rate was given.
    #[must_use]
    pub fn grid_reason(&self) -> Option<String> {
        let topic = self.grid_topic.as_deref()?;
        let rate = |p: f64| round_hz(1.0 / p);
        let of = |t: &TopicInfo| {
            let short = t
                .schema
                .as_deref()
                .unwrap_or("?")
                .rsplit('/')
                .next()
                .unwrap_or("?");
            match t.period_s {
                Some(p) => format!("{} ({short}, {} Hz)", t.topic, rate(p)),
                None => format!("{} ({short})", t.topic),
            }
        };
        let chosen = self.topics.iter().find(|t| t.topic == topic)?;
        let flags: Vec<String> = self
            .topics
            .iter()
            .filter(|t| t.msg_type == Some(MsgType::Bool) && t.topic != topic)
            .map(of)
            .collect();
        let held = if flags.is_empty() {
            String::new()
        } else {
            format!(
                "; {} held between messages, not interpolated, so not setting it",
                flags.join(", ")
            )
        };
        let why = if chosen.msg_type == Some(MsgType::Bool) {
            "the slowest topic (every topic is a Bool)"
        } else {
            "the slowest topic that is interpolated"
        };
        Some(format!(
            "grid of {} Hz ({} s), the rate of {}, {why}{held}; for another grid give --rate HZ \
             (Python: rate=)",
            rate(self.dt_s),
            (self.dt_s * 1e9).round() / 1e9,
            of(chosen),
        ))
    }

    /// [`Recording::grid_reason`] with the file in front.
    #[must_use]
    pub fn grid_note(&self) -> Option<String> {
        self.grid_reason().map(|r| format!("{}: {r}", self.source))
    }

    /// The recording as a demonstration (named by its file).
    ///
    /// # Errors
    /// The model crate's checks ([`Demonstration::new`]).
    pub fn demonstration(&self) -> Result<Demonstration> {
        Ok(
            Demonstration::new(self.channel_names.clone(), self.samples.clone(), self.dt_s)?
                .with_source(self.source.clone()),
        )
    }
}

/// The channel kinds and quaternion blocks of bag recordings added to `schema`: every
/// recording's quaternion blocks not yet in it (so a `PoseStamped`'s orientation is averaged
/// on the rotation manifold, as the CSV channels `qx, qy, qz, qw` are), its position channels
/// as positions, its wrench forces as forces and its `Bool` channels as binary. Kinds and
/// blocks already in `schema` are kept.
pub fn extend_schema(schema: &mut ChannelSchema, recordings: &[Recording]) {
    for r in recordings {
        for b in &r.quaternions {
            let known = schema
                .quaternions
                .iter()
                .any(|q| q.name == b.name || q.channels == b.channels);
            if !known {
                schema.quaternions.push(b.clone());
            }
        }
        for t in &r.topics {
            let kinds: Vec<(usize, ChannelKind)> = match t.msg_type {
                Some(MsgType::PoseStamped) => (0..3).map(|c| (c, ChannelKind::Position)).collect(),
                Some(MsgType::WrenchStamped) => (0..3).map(|c| (c, ChannelKind::Force)).collect(),
                Some(MsgType::Bool) => vec![(0, ChannelKind::Binary)],
                _ => Vec::new(),
            };
            for (c, kind) in kinds {
                if let Some(name) = t.channels.get(c) {
                    schema.kinds.entry(name.clone()).or_insert(kind);
                }
            }
        }
    }
}

/// How a topic's columns are resampled (series `s` of topic `t`): the one policy of
/// [`tandem_lfd::resample`], a pose's orientation as its quaternion block, a column whose
/// every value is 0 or 1 (a `Bool`, say) held.
fn plan(t: &RawTopic, s: &Series) -> Interpolation {
    let w = t.width();
    let quats: &[[usize; 4]] = match t.msg_type {
        Some(MsgType::PoseStamped) => &[[3, 4, 5, 6]],
        _ => &[],
    };
    let flags: Vec<usize> = (0..w)
        .filter(|&c| {
            !quats.iter().flatten().any(|&d| d == c)
                && is_flag(s.values.iter().skip(c).step_by(w).copied())
        })
        .collect();
    Interpolation::new(w, &flags, quats).expect("a topic's columns")
}

/// The description of topic `t` read as `s` (or not read).
fn info(t: &RawTopic, s: Option<&Series>, namespace: Option<&str>) -> TopicInfo {
    TopicInfo {
        topic: t.topic.clone(),
        schema: t.schema.clone(),
        msg_type: t.msg_type,
        messages: t.count,
        channels: if t.msg_type.is_some() {
            t.channel_names(namespace).into_iter().flatten().collect()
        } else {
            Vec::new()
        },
        median_period_s: s.map(|s| s.median_ns as f64 / 1e9),
        period_s: s.map(|s| s.period_ns / 1e9),
        span_s: s.map(|s| {
            (
                s.times_ns[0] as f64 / 1e9,
                s.times_ns[s.times_ns.len() - 1] as f64 / 1e9,
            )
        }),
        log_time: s.is_some_and(|s| s.log_time),
        role: t.role(namespace),
    }
}

/// Topics of one grid: their series, resampled together.
struct Gridded {
    grid: Grid,
    /// Per topic (index into the file's topics): its column block in `values`.
    blocks: Vec<(usize, usize)>,
    /// All topics' full columns on the grid, row-major.
    values: Vec<f64>,
    width: usize,
}

/// Which of the series sets the default grid: the slowest (longest [`Series::period_ns`],
/// the earlier on a tie) of those that are interpolated, every type but `Bool` (a flag is
/// held between its messages, so a 50 Hz valve need not coarsen a 100 Hz pose); the
/// slowest of all when every one is a `Bool`.
fn grid_setter(topics: &[RawTopic], chosen: &[usize], series: &[Series]) -> usize {
    let interpolated: Vec<usize> = (0..chosen.len())
        .filter(|&b| topics[chosen[b]].msg_type != Some(MsgType::Bool))
        .collect();
    let candidates = if interpolated.is_empty() {
        (0..chosen.len()).collect()
    } else {
        interpolated
    };
    candidates
        .into_iter()
        .rev()
        .max_by(|&a, &b| series[a].period_ns.total_cmp(&series[b].period_ns))
        .expect("at least one topic")
}

/// Resamples the `chosen` topics (indices into `topics`) onto one grid of period `period_ns`
/// (`None`: the period of the topic [`grid_setter`] picks) within `window`. Returns the
/// grid, the series and, when the period was not given, the block of the topic that set it.
fn grid_topics(
    topics: &[RawTopic],
    chosen: &[usize],
    file: &str,
    window: Option<(i64, i64)>,
    period_ns: Option<f64>,
) -> Result<(Gridded, Vec<Series>, Option<usize>)> {
    let series: Vec<Series> = chosen
        .iter()
        .map(|&k| series(&topics[k], file, window, false))
        .collect::<Result<_>>()?;
    let setter = period_ns
        .is_none()
        .then(|| grid_setter(topics, chosen, &series));
    let period_ns = period_ns.unwrap_or_else(|| series[setter.expect("no period given")].period_ns);
    let refs: Vec<&Series> = series.iter().collect();
    let names: Vec<&str> = chosen.iter().map(|&k| topics[k].topic.as_str()).collect();
    let g = grid(&refs, &names, file, period_ns)?;
    let width: usize = chosen.iter().map(|&k| topics[k].width()).sum();
    let mut values = vec![0.0; g.n * width];
    let mut blocks = Vec::with_capacity(chosen.len());
    let mut offset = 0;
    for (s, &k) in series.iter().zip(chosen) {
        let w = topics[k].width();
        resample_into(s, w, &plan(&topics[k], s), &g, &mut values, width, offset);
        blocks.push((offset, w));
        offset += w;
    }
    Ok((
        Gridded {
            grid: g,
            blocks,
            values,
            width,
        },
        series,
        setter,
    ))
}

impl Gridded {
    /// Column `c` of topic block `b`, every grid row.
    fn column(&self, b: usize, c: usize) -> Vec<f64> {
        let (off, _) = self.blocks[b];
        (0..self.grid.n)
            .map(|j| self.values[j * self.width + off + c])
            .collect()
    }
}

/// The channel columns of `chosen` topics (their kept columns, in order) as one sample-major
/// matrix, with their names; a name given twice is an error.
fn channels(
    topics: &[RawTopic],
    chosen: &[usize],
    g: &Gridded,
    file: &str,
    namespace: Option<&str>,
) -> Result<(Vec<String>, Vec<f64>)> {
    let mut names: Vec<String> = Vec::new();
    let mut from: BTreeMap<String, usize> = BTreeMap::new();
    let mut cols: Vec<(usize, usize)> = Vec::new();
    for (b, &k) in chosen.iter().enumerate() {
        for (c, name) in topics[k].channel_names(namespace).into_iter().enumerate() {
            let Some(name) = name else { continue };
            if let Some(&other) = from.get(&name) {
                return Err(Error::ChannelClash {
                    file: file.into(),
                    channel: name,
                    first: topics[other].topic.clone(),
                    second: topics[k].topic.clone(),
                });
            }
            from.insert(name.clone(), k);
            names.push(name);
            cols.push((b, c));
        }
    }
    let m = cols.len();
    let mut samples = Vec::with_capacity(g.grid.n * m);
    for j in 0..g.grid.n {
        let row = &g.values[j * g.width..(j + 1) * g.width];
        samples.extend(cols.iter().map(|&(b, c)| row[g.blocks[b].0 + c]));
    }
    Ok((names, samples))
}

/// The quaternion blocks of the chosen `PoseStamped` topics whose four orientation columns
/// are kept and named `<stem>qx … <stem>qw`.
fn quaternion_blocks(
    topics: &[RawTopic],
    chosen: &[usize],
    namespace: Option<&str>,
) -> Vec<QuaternionBlock> {
    chosen
        .iter()
        .filter(|&&k| topics[k].msg_type == Some(MsgType::PoseStamped))
        .filter_map(|&k| {
            let names = topics[k].channel_names(namespace);
            let q: Vec<&String> = names[3..7].iter().flatten().collect();
            let stem = q.first()?.strip_suffix("qx")?;
            let expected = ["qx", "qy", "qz", "qw"].map(|s| format!("{stem}{s}"));
            (q.len() == 4 && q.iter().zip(&expected).all(|(a, b)| *a == b)).then(|| {
                QuaternionBlock {
                    name: format!("{stem}q"),
                    channels: expected,
                }
            })
        })
        .collect()
}

/// A rate in Hz without floating-point noise (`50`, `33.333`).
fn round_hz(hz: f64) -> f64 {
    (hz * 1e3).round() / 1e3
}

/// Reads a rosbag2 MCAP file as one demonstration: the selected topics (by default every
/// topic of a supported type) resampled onto one grid, channel names from the topic and the
/// field (docs/formats.md, "ROS 2 bags").
///
/// Times are the header stamps (log times for `Float64`, `Bool` and topics whose stamps are
/// all zero). The grid runs from the latest first message to the earliest last one at
/// `rate_hz` (default: the rate of the slowest topic that is interpolated, see
/// [`BagOptions::rate_hz`] and [`Recording::grid_note`]); values are interpolated linearly,
/// orientations by slerp, flags (`Bool`, any channel whose every value is 0 or 1) held: the
/// one resampling policy of [`tandem_lfd::resample`], as for CSV logs.
///
/// # Errors
/// The file cannot be read or is not MCAP ([`Error::NotMcap`]), is truncated or corrupt; a
/// selected topic is missing, has no or an unknown schema, fewer than 2 messages, a message
/// that does not decode, a non-finite or too large value, times that do not increase, a gap
/// or a late start or early end ([`crate::GAP_FACTOR`] × its median period); two topics give
/// the same channel name. Every error names the file, the topic and the message.
pub fn read_bag(path: impl AsRef<Path>, options: &BagOptions) -> Result<Recording> {
    options.validate()?;
    let path = path.as_ref();
    let file = path.display().to_string();
    let namespace = options.namespace.as_deref();
    let sel = Selection {
        topics: options.topics.as_deref(),
        namespace,
        views: false,
    };
    let topics = read_topics(path, &sel)?;
    let chosen = chosen_topics(&topics, options.topics.as_deref(), |t| {
        t.selected && t.msg_type.is_some()
    });
    let period = options.rate_hz.map(|r| 1e9 / r);
    let (g, series, setter) = grid_topics(&topics, &chosen, &file, None, period)?;
    let (channel_names, samples) = channels(&topics, &chosen, &g, &file, namespace)?;
    let topics_info = chosen
        .iter()
        .zip(&series)
        .map(|(&k, s)| info(&topics[k], Some(s), namespace))
        .collect();
    Ok(Recording {
        source: file,
        channel_names,
        samples,
        dt_s: g.grid.period_ns / 1e9,
        grid_topic: setter.map(|b| topics[chosen[b]].topic.clone()),
        start_s: g.grid.t0_ns as f64 / 1e9,
        topics: topics_info,
        quaternions: quaternion_blocks(&topics, &chosen, namespace),
    })
}

/// Indices of the topics to read: in the order of `explicit` when given, else file order.
fn chosen_topics(
    topics: &[RawTopic],
    explicit: Option<&[String]>,
    keep: impl Fn(&RawTopic) -> bool,
) -> Vec<usize> {
    match explicit {
        Some(list) => list
            .iter()
            .filter_map(|name| topics.iter().position(|t| t.topic == *name))
            .filter(|&k| keep(&topics[k]))
            .collect(),
        None => (0..topics.len()).filter(|&k| keep(&topics[k])).collect(),
    }
}

/// Every topic of a bag: type, message count, the channels it gives, its rate and span (for
/// `tandem inspect`). Topics of a supported type are decoded and checked as [`read_bag`]
/// would (in a run of several rounds, without the gap check: a robot idles between rounds);
/// the error of a damaged one is the result.
///
/// # Errors
/// As [`read_bag`] (for every topic of a supported type).
pub fn inspect(path: impl AsRef<Path>) -> Result<Vec<TopicInfo>> {
    let path = path.as_ref();
    let file = path.display().to_string();
    let sel = Selection {
        topics: None,
        namespace: None,
        views: true,
    };
    let topics = read_topics(path, &sel)?;
    // A run of several rounds: robots idle between rounds, so gaps are expected there.
    let rounds = round_starts(&topics).len() > 1;
    topics
        .iter()
        .map(|t| {
            if t.selected && t.msg_type.is_some() {
                let s = series(t, &file, None, rounds)?;
                Ok(info(t, Some(&s), None))
            } else {
                Ok(info(t, None, None))
            }
        })
        .collect()
}

/// How to read executions from a bag (`tandem record`).
#[derive(Clone, Debug, PartialEq)]
pub struct ExecutionOptions {
    /// The model's sample period `Δt_s` (s): one execution sample per control tick.
    pub dt_s: f64,
    /// Which robots this bag holds (1-based, in order): robot `i`'s topics are those under
    /// `/robot_<i>` when the bag has any, else (one robot) every topic.
    pub robots: Vec<usize>,
    /// The round to read from a bag of several rounds (1-based; a run tandem wrote has one
    /// schedule message per round); `None` for a bag of one round.
    pub round: Option<usize>,
    /// Topics to read (full names); `None`: every topic of a supported type under the robot's
    /// namespace.
    pub topics: Option<Vec<String>>,
}

/// The namespace of robot `i` (1-based).
#[must_use]
pub fn robot_namespace(robot: usize) -> String {
    format!("/robot_{robot}")
}

/// The rounds of a run: the log times (ns) of its schedule messages, in order.
fn round_starts(topics: &[RawTopic]) -> Vec<i64> {
    let mut v: Vec<i64> = topics
        .iter()
        .find(|t| t.topic == SCHEDULE_TOPIC)
        .map(|t| t.log_ns.clone())
        .unwrap_or_default();
    v.sort_unstable();
    v
}

/// Closes the gaps a run tandem wrote leaves in a robot's per-sample topics where it stood at a
/// hold point (or was held) in the round starting at bag time `start` (ns, its schedule
/// message) and ending before `end`: such a run stamps each sample at the tick it ran in
/// (`"sample_stamps": "tick"` in the schedule message, [`crate::SCHEDULE_SCHEMA`]), and an
/// execution is its samples one after the other (the time at a hold is not part of it). The
/// `j`-th sample of a robot whose first ran at tick `s` is moved to tick `s + j`, exactly
/// where a run without holds stamps it, so the executions read back sample for sample. The
/// per-tick topics (`schedule_clock`, `waiting`) and bags of other writers are left alone.
fn close_hold_gaps(topics: &mut [RawTopic], start: i64, end: i64) {
    let Some(schedule) = topics.iter().find(|t| t.topic == SCHEDULE_TOPIC) else {
        return;
    };
    let Some(doc) = schedule
        .log_ns
        .iter()
        .position(|&t| t == start)
        .and_then(|m| schedule.json.get(m))
        .and_then(|j| serde_json::from_slice::<serde_json::Value>(j).ok())
    else {
        return;
    };
    let by_tick = doc.get("sample_stamps").and_then(|v| v.as_str()) == Some("tick");
    let Some(dt_ns) = doc
        .get("dt_s")
        .and_then(serde_json::Value::as_f64)
        .filter(|d| by_tick && d.is_finite() && *d > 0.0)
        .map(|d| d * 1e9)
    else {
        return;
    };
    let at = |tick: i64| start + (tick as f64 * dt_ns).round() as i64;
    for t in topics.iter_mut() {
        if !t.topic.starts_with("/robot_")
            || t.topic.ends_with("/schedule_clock")
            || t.topic.ends_with("/waiting")
        {
            continue;
        }
        let mut mine: Vec<usize> = (0..t.log_ns.len())
            .filter(|&k| t.log_ns[k] >= start && t.log_ns[k] < end)
            .collect();
        mine.sort_by_key(|&k| t.log_ns[k]);
        let Some(&first) = mine.first() else {
            continue;
        };
        let s = ((t.log_ns[first] - start) as f64 / dt_ns).round() as i64;
        for (j, &k) in mine.iter().enumerate() {
            let new = at(s + j as i64);
            if t.stamp_ns.get(k) == Some(&t.log_ns[k]) {
                t.stamp_ns[k] = new;
            }
            t.log_ns[k] = new;
        }
    }
}

/// Number of rounds of a run tandem wrote (its schedule messages), 0 for any other bag.
///
/// # Errors
/// As [`read_bag`] for an unreadable or damaged file.
pub fn count_rounds(path: impl AsRef<Path>) -> Result<usize> {
    let sel = Selection {
        topics: None,
        namespace: None,
        views: false,
    };
    Ok(round_starts(&read_topics(path.as_ref(), &sel)?).len())
}

/// Reads the executions of one round from a bag, one per robot of `options.robots`: for each
/// robot its channel topics, its reference-time log (a `Float64` topic `ref_sample`, in
/// reference samples) and its flags (`Bool` topics `supervised` and `corrected`), resampled
/// onto the model's period `dt_s` from the robot's first message (docs/formats.md, "ROS 2
/// bags").
///
/// # Errors
/// As [`read_bag`]; [`Error::Layout`] for a robot without topics, without exactly one log
/// and two flag topics, a round that does not exist, or a `corrected` sample that is not
/// supervised.
pub fn read_executions(
    path: impl AsRef<Path>,
    options: &ExecutionOptions,
) -> Result<Vec<ExecutionRecord>> {
    let path = path.as_ref();
    let file = path.display().to_string();
    if !(options.dt_s.is_finite() && options.dt_s > 0.0) {
        return Err(Error::BadParam {
            name: "dt_s",
            why: format!("{} s: the period must be finite and > 0", options.dt_s),
        });
    }
    let sel = Selection {
        topics: options.topics.as_deref(),
        namespace: None,
        views: false,
    };
    let mut topics = read_topics(path, &sel)?;
    let layout = |why: String| Error::Layout {
        file: file.clone(),
        why,
    };
    let starts = round_starts(&topics);
    let window = match (options.round, starts.len()) {
        (None, 0 | 1) => None,
        (None, n) => {
            return Err(layout(format!(
                "holds {n} rounds (schedule messages on {SCHEDULE_TOPIC}); choose one (--round K)"
            )));
        }
        (Some(k), n) if k == 0 || k > n => {
            return Err(layout(format!(
                "round {k} requested, but the bag holds {n} round(s) (1 to {n})"
            )));
        }
        (Some(k), _) => Some((starts[k - 1], starts.get(k).copied().unwrap_or(i64::MAX))),
    };
    if let Some((start, end)) = window.or_else(|| starts.first().map(|&s| (s, i64::MAX))) {
        close_hold_gaps(&mut topics, start, end);
    }
    let namespaced = topics.iter().any(|t| t.topic.starts_with("/robot_"));
    options
        .robots
        .iter()
        .map(|&robot| {
            let ns = robot_namespace(robot);
            let namespace = namespaced.then_some(ns.as_str());
            if !namespaced && options.robots.len() > 1 {
                return Err(layout(format!(
                    "holds no /robot_<i> namespaces, so it cannot hold the executions of robots {:?}",
                    options.robots
                )));
            }
            read_robot(&topics, &file, namespace, window, options, robot)
        })
        .collect()
}

/// One robot's execution (see [`read_executions`]).
fn read_robot(
    topics: &[RawTopic],
    file: &str,
    namespace: Option<&str>,
    window: Option<(i64, i64)>,
    options: &ExecutionOptions,
    robot: usize,
) -> Result<ExecutionRecord> {
    let layout = |why: String| Error::Layout {
        file: file.into(),
        why,
    };
    let mine = |t: &RawTopic| {
        t.selected
            && t.msg_type.is_some()
            && namespace.is_none_or(|ns| under(&t.topic, ns))
            && t.role(namespace) != Role::View
    };
    let chosen = chosen_topics(topics, options.topics.as_deref(), mine);
    let where_ = namespace.map_or("the bag".to_owned(), |ns| format!("{ns}/"));
    if chosen.is_empty() {
        return Err(layout(format!(
            "robot {robot}: no topics of a supported type under {where_}"
        )));
    }
    let role_topic = |role: Role| -> Result<usize> {
        let found: Vec<usize> = chosen
            .iter()
            .copied()
            .filter(|&k| topics[k].role(namespace) == role)
            .collect();
        match found[..] {
            [k] => Ok(k),
            _ => Err(layout(format!(
                "robot {robot}: {} topic(s) `{}` under {where_} ({}); an execution needs exactly \
                 one (a {} topic `{}`)",
                found.len(),
                role.name(),
                found
                    .iter()
                    .map(|&k| topics[k].topic.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
                if role == Role::RefSample {
                    "Float64"
                } else {
                    "Bool"
                },
                role.name()
            ))),
        }
    };
    let (log_k, sup_k, cor_k) = (
        role_topic(Role::RefSample)?,
        role_topic(Role::Supervised)?,
        role_topic(Role::Corrected)?,
    );
    let (g, _, _) = grid_topics(topics, &chosen, file, window, Some(options.dt_s * 1e9))?;
    let block = |k: usize| chosen.iter().position(|&c| c == k).expect("chosen");
    let ref_time_log = g.column(block(log_k), 0);
    let supervised: Vec<bool> = g
        .column(block(sup_k), 0)
        .iter()
        .map(|&v| v != 0.0)
        .collect();
    let corrected: Vec<bool> = g
        .column(block(cor_k), 0)
        .iter()
        .map(|&v| v != 0.0)
        .collect();
    if let Some(j) = (0..supervised.len()).find(|&j| corrected[j] && !supervised[j]) {
        return Err(layout(format!(
            "robot {robot}: sample {j} (bag time {:.6} s): `corrected` is true but `supervised` \
             is false (only a supervised, low-confidence sample can be corrected)",
            g.grid.time(j) as f64 / 1e9
        )));
    }
    let data: Vec<usize> = chosen
        .iter()
        .copied()
        .filter(|&k| topics[k].role(namespace) == Role::Channel)
        .collect();
    if data.is_empty() {
        return Err(layout(format!(
            "robot {robot}: no channel topics under {where_} (only the log and the flags)"
        )));
    }
    // The channel topics' blocks, in `data`'s order, over the same grid values.
    let blocks = data.iter().map(|&k| g.blocks[block(k)]).collect();
    let data_grid = Gridded { blocks, ..g };
    let (names, samples) = channels(topics, &data, &data_grid, file, namespace)?;
    let source = match namespace {
        Some(ns) => format!("{file} ({ns})"),
        None => file.to_owned(),
    };
    let demonstration = Demonstration::new(names, samples, options.dt_s)?.with_source(source);
    Ok(ExecutionRecord {
        execution: Execution {
            demonstration,
            ref_time_log,
        },
        supervised,
        corrected,
    })
}
