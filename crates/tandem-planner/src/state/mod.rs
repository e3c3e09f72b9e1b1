//! The versioned binary state file and its atomic write (why postcard: docs/decisions.md,
//! "postcard, not bincode, for the state file").
//!
//! # Format (version [`FORMAT_VERSION`])
//!
//! | bytes | content |
//! |---|---|
//! | 0..8 | magic [`MAGIC`] = `b"TANDEMST"` |
//! | 8..12 | format version, `u32` little endian |
//! | 12..20 | payload length in bytes, `u64` little endian |
//! | 20..24 | CRC-32 (IEEE) of the payload, `u32` little endian |
//! | 24.. | payload: the state encoded with `postcard` ([`v11::Payload`]), then, only when a planner uses a parameter added after format 11, the list of such parameters by name ([`Extras`]) |
//!
//! A cell of two or more tasks (issue 45, `crate::CellPlanner`) is written as format
//! [`CELL_FORMAT_VERSION`] (12): the same header, then [`v12::CellPayload`], which nests each
//! task's complete format 11 payload as bytes. A planner, and a one-task cell, still write
//! format 11, byte for byte as before; [`crate::Planner::load`] of a format 12 file fails with
//! [`Error::CellFile`] naming its tasks, and a build older than format 12 with its
//! [`Error::UnsupportedVersion`] ("written by a newer build").
//!
//! Reading checks, in this order: the file can be read, it is at least a header long and
//! starts with the magic bytes, the version is one this build reads
//! ([`OLDEST_READABLE_VERSION`]`..=`[`FORMAT_VERSION`]), the payload has
//! exactly the announced length (shorter = truncated, longer = trailing garbage), the
//! checksum matches, and `postcard` decodes the payload using every byte (in format 11, the
//! bytes after the [`v11::Payload`] must decode as an [`Extras`] list using every byte).
//!
//! # Wire types apart from library types
//!
//! The payload is its own set of plain types, never a library type's serde form (postcard is
//! positional: a library field renamed, reordered or added would silently change the
//! format):
//!
//! - [`v11`]: the current payload, [`v11::Payload`], one wire type per stored library type
//!   with explicit conversions both ways (`From`/`TryFrom`; a library field added fails to
//!   compile there until it is decided on). The one library type stored in its own serde form
//!   is the fitted `TaskModel` (statistics only `tandem-lfd` can build, no parameters).
//! - `legacy`: the payloads of formats 4 to 10, each converted into [`v11::Payload`] on
//!   load; nothing writes them.
//! - [`extras`]: parameters added to the library after the format, stored by name.
//!
//! A planner is saved as `Planner` → library state → [`v11::Payload`] (+ [`Extras`]) →
//! bytes, and loaded the other way, every version through [`v11::Payload`].
//! [`load_payload`] and [`save_payload`] give tools and tests the wire types of a file.
//!
//! # Adding a library parameter
//!
//! A parameter added to `PlannerParams`, `FitParams`, `WarpParams`, `ConfidenceParams` or
//! `SamplerParams` with a default does **not** change the format. The build fails in
//! [`v11`] (the conversion from the library type names every field): there
//!
//! 1. in the library → wire conversion, ignore the field (`new_field: _`) and in
//!    `v11::Payload::from_state` store it by name: `extras.put("fit.warp.new_field",
//!    &params.fit.warp.new_field, &ABSENT)?`, where `ABSENT` is the value that reproduces
//!    what builds before it did (usually its default);
//! 2. in the wire → library conversion, set it to `ABSENT`, and in `v11::Payload::into_state`
//!    read it: `params.fit.warp.new_field = extras.take("fit.warp.new_field", ABSENT)?`
//!    before `extras.finish()`.
//!
//! A planner at `ABSENT` then saves the very bytes of a build without the parameter; every
//! older file loads with `ABSENT`; a planner off it writes one entry after the payload
//! (still format 11), which this build reads back and a build without the parameter
//! refuses, naming it (never drops it). The test `a_new_parameter_at_its_default_does_not_
//! change_the_format` in [`v11`] does exactly this with a test-only parameter.
//! A new format version is needed only when the shape of what is stored changes otherwise
//! (a new kind of data, a changed meaning): then `v11.rs` moves to `legacy` with a
//! conversion into the new `v12.rs`, and only then does the golden file change.
//! Each failure is its own [`Error`] variant naming the file.
//! A file of another version is refused ([`Error::UnsupportedVersion`] says whether it is
//! older or newer than the build). A file of an older readable version is decoded with that
//! version's payload shape and converted (`Planner::load`); saving it again writes the
//! current version.
//!
//! # The golden file
//!
//! `fixtures/state/example.tandem` is a committed file of the current version: the planner of
//! the guide's walk-through on `fixtures/examples/` (fit on `demo_{0,1,2}.csv` with
//! `params.toml`, then the pair `pair_1_robot_{1,2}` recorded). `tests/state_file.rs` loads it
//! and checks its values against those inputs, so a change of the payload's shape, or a new
//! [`FORMAT_VERSION`] without a new file, fails the tests. The file is written only by
//! `cargo xtask fixtures`; CI runs `cargo xtask fixtures --check`, which fails on any byte
//! that differs, so every change of the format or of a number in the file is a reviewed diff.
//! The command line writes the same bytes for the same inputs (`tandem fit` + `tandem
//! record`, checked by `tandem-cli`'s end-to-end test).
//!
//! # Atomic write
//!
//! The bytes go to a temporary file in the same directory with a name no other writer uses
//! (`.<name>.<process id>-<counter>.tmp`), which is flushed to disk (`fsync`), then renamed
//! over the target, then the directory itself is flushed so the rename survives a power cut.
//! A crash at any point leaves either the old file or the new one, never a mix: the previous
//! state is never lost. Temporary files a crashed writer left are removed by the next save.
//! An existing file that is not a state file is never replaced ([`check_target`]).
//!
//! # Locking
//!
//! Every writer holds a [`StateLock`] for its whole read–modify–write: an advisory exclusive
//! lock (`flock` on Unix, through the `fs4` crate) on the lock file `.<name>.lock` beside the
//! state file, which is never renamed or removed (locking the state file itself would lock
//! the inode that the rename replaces). A second writer waits for the first, at most
//! [`DEFAULT_LOCK_TIMEOUT`] unless told otherwise, then fails with [`Error::Locked`]; it never
//! overwrites the first one's round. Readers need no lock: the rename is atomic. The lock is
//! released when the [`StateLock`] is dropped, and by the operating system when its process
//! dies, so a crashed writer never leaves a stale lock.

use std::fs::{self, File, OpenOptions};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::{Error, Result};

pub mod extras;
mod legacy;
pub mod v11;
pub mod v12;

pub use extras::Extras;

use tandem_confidence::{Confidence, Observations};
use tandem_lfd::{Demonstration, TaskModel};
use tandem_schedule::Outcome;

use crate::PlannerParams;
use crate::planner::ExecutionRecord;

/// The serialized part of a [`crate::Planner`] in library types (its problem is rebuilt on
/// load): what [`v11::Payload`] converts from and to.
#[derive(Clone, Debug)]
pub(crate) struct PlannerState {
    pub(crate) params: PlannerParams,
    pub(crate) model: TaskModel,
    pub(crate) observations: Observations,
    pub(crate) confidence: Confidence,
    pub(crate) outcome: Outcome,
    pub(crate) rounds_recorded: usize,
    pub(crate) rounds: Vec<u64>,
    pub(crate) reference: Option<Demonstration>,
    pub(crate) records: Vec<Vec<ExecutionRecord>>,
}

/// Magic bytes at the start of every state file.
pub const MAGIC: [u8; 8] = *b"TANDEMST";

/// The state format version this build writes and reads.
/// Bump it whenever the serialized payload changes shape, and regenerate the golden file
/// (`cargo xtask fixtures`, see the module docs). A library parameter added with a default
/// does not change the shape (module docs, "Adding a library parameter").
///
/// - 1: first format.
/// - 2: the sampler parameters gained `OffsetSampling::Fitted` and `max_margin_checks`.
/// - 3: the schedule stores the control tick it was checked with (`Schedule::tick_s`), and
///   the sampler parameters keep only what a user tunes (`pieces` and `widen_max` replace
///   `distribution` and `offset`; the benchmark-only `margin_check` and
///   `exhaustive_margins` moved to `SamplerBaselines`, which is never stored); the fit
///   parameters gained `reference` and the model `reference_idx`.
/// - 4: the outcome carries its certificate (`lower_bound_s`, `bound_is_optimum`, `gap`), its
///   counts the completion's and the search's, `Source` gained `Completed`, and the sampler
///   parameters the exact search's and completion's (`exact`).
/// - 5: the schedule holds `N` robots (`Schedule::grad_exec` a list of warps, `offsets_s` the
///   `N − 1` start offsets instead of the one `offset_s`). Version 4 files still load, as
///   two-robot schedules with `offsets_s = [offset_s]`.
/// - 6: the planner keeps a fingerprint of every round it recorded, so that the same round
///   recorded twice is refused. Version 4 and 5 files still load, with no fingerprints for
///   the rounds they hold.
/// - 7: the confidence parameters gained the operator's error rates
///   (`false_correction_rate`, `miss_rate`, `estimate_error_rates`) and
///   `one_vote_per_execution`, and the observations
///   their evidence of misses (`MissEvidence`). Version 4 to 6 files still load, with the
///   paper's model (`ConfidenceParams::paper()`: the decisions they were saved with) and no
///   evidence of misses.
/// - 8: the planner parameters gained the hold points the user declared
///   (`PlannerParams::holds`: reference times and channel rules) and the schedule its holds
///   (`Schedule::holds`: per robot the hold, its planned dwell and release rules; every field
///   written, also when empty). Version 4 to 7 files still load, with no hold points.
/// - 9: the fit's warp parameters gained `smooth_width` (`tandem_warp::WarpParams`: the
///   signals are smoothed before they are aligned). Version 4 to 8 files still load, with
///   `smooth_width = 1`: unsmoothed, the alignment they were fitted with.
/// - 10: the fit's warp parameters gained `fill_length` (`tandem_warp::WarpParams`: flat
///   stretches filled by the smoothest continuation of the warp). Version 4 to 9 files still
///   load, with `fill_length = 0`: unfilled, the alignment they were fitted with.
/// - 11: the planner keeps its reference demonstration and every recorded round's executions
///   (samples, reference-time log, supervised and corrected flags, as taken in), so that a
///   refit can replay them (`Planner::refit`). Version 4 to 10 files still load, without
///   them: their rounds cannot be replayed.
pub const FORMAT_VERSION: u32 = 11;

/// The format version of a cell of two or more tasks (issue 45, [`crate::CellPlanner`]): the
/// header as in every version, then [`v12::CellPayload`] (each task's complete format 11
/// payload, the robot → task map, the cell's parameters by name). A one-task cell is written
/// as [`FORMAT_VERSION`], byte for byte its planner's file (docs/decisions.md, "Different
/// tasks on different robots: the cell of task models (issue 45)").
pub const CELL_FORMAT_VERSION: u32 = 12;

/// The newest state format version this build reads: [`CELL_FORMAT_VERSION`].
pub const NEWEST_READABLE_VERSION: u32 = CELL_FORMAT_VERSION;

/// The oldest state format version this build reads (converting it on load).
pub const OLDEST_READABLE_VERSION: u32 = 4;

/// Header length in bytes: magic (8) + version (4) + payload length (8) + CRC-32 (4).
pub const HEADER_LEN: usize = 24;

/// Encode `value` as a complete state file image (header + payload).
pub(crate) fn encode<T: Serialize>(value: &T) -> Result<Vec<u8>> {
    let payload = postcard::to_allocvec(value).map_err(|source| Error::Encode { source })?;
    Ok(with_header(&payload))
}

/// The state file image of `payload`: the header of the current version, then the payload.
fn with_header(payload: &[u8]) -> Vec<u8> {
    with_header_version(payload, FORMAT_VERSION)
}

/// The state file image of `payload` under a header of `version`.
pub(crate) fn with_header_version(payload: &[u8], version: u32) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(HEADER_LEN + payload.len());
    bytes.extend_from_slice(&MAGIC);
    bytes.extend_from_slice(&version.to_le_bytes());
    bytes.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&crc32fast::hash(payload).to_le_bytes());
    bytes.extend_from_slice(payload);
    bytes
}

/// Decode a state file image of the current version read from `path` (used only in error
/// messages).
pub(crate) fn decode<T: DeserializeOwned>(bytes: &[u8], path: &Path) -> Result<T> {
    let (version, payload) = checked_payload(bytes, path)?;
    if version != FORMAT_VERSION {
        return Err(unsupported(path, version));
    }
    decode_payload(payload, path)
}

/// The [`Error::UnsupportedVersion`] of a file of version `found` at `path`.
fn unsupported(path: &Path, found: u32) -> Error {
    Error::UnsupportedVersion {
        path: path.to_path_buf(),
        found,
        expected: NEWEST_READABLE_VERSION,
    }
}

/// The version and the payload of a state file image read from `path`, after every check of
/// the module docs but the decoding: magic, a readable version
/// ([`OLDEST_READABLE_VERSION`]`..=`[`NEWEST_READABLE_VERSION`]), length and checksum.
pub(crate) fn checked_payload<'a>(bytes: &'a [u8], path: &Path) -> Result<(u32, &'a [u8])> {
    let path_buf = || path.to_path_buf();
    if bytes.len() < MAGIC.len() || bytes[..MAGIC.len()] != MAGIC {
        return Err(Error::NotAStateFile { path: path_buf() });
    }
    if bytes.len() < HEADER_LEN {
        return Err(Error::Truncated {
            path: path_buf(),
            expected_bytes: HEADER_LEN as u64,
            found_bytes: bytes.len() as u64,
        });
    }
    let word = |range: std::ops::Range<usize>| -> &[u8] { &bytes[range] };
    let version = u32::from_le_bytes(word(8..12).try_into().expect("4-byte slice"));
    if !(OLDEST_READABLE_VERSION..=NEWEST_READABLE_VERSION).contains(&version) {
        return Err(unsupported(path, version));
    }
    let payload_len = u64::from_le_bytes(word(12..20).try_into().expect("8-byte slice"));
    let crc = u32::from_le_bytes(word(20..24).try_into().expect("4-byte slice"));
    let payload = &bytes[HEADER_LEN..];
    let found = payload.len() as u64;
    if found < payload_len {
        return Err(Error::Truncated {
            path: path_buf(),
            expected_bytes: HEADER_LEN as u64 + payload_len,
            found_bytes: bytes.len() as u64,
        });
    }
    if found > payload_len {
        return Err(Error::Corrupt {
            path: path_buf(),
            why: format!(
                "{} bytes after the {payload_len}-byte payload",
                found - payload_len
            ),
        });
    }
    let actual_crc = crc32fast::hash(payload);
    if actual_crc != crc {
        return Err(Error::Corrupt {
            path: path_buf(),
            why: format!("payload checksum {actual_crc:#010x} differs from header {crc:#010x}"),
        });
    }
    Ok((version, payload))
}

/// Decodes a checked payload ([`checked_payload`]) of a file read from `path` as `T`, using
/// every byte.
pub(crate) fn decode_payload<T: DeserializeOwned>(payload: &[u8], path: &Path) -> Result<T> {
    let path_buf = || path.to_path_buf();
    let (value, rest) = postcard::take_from_bytes::<T>(payload).map_err(|e| Error::Corrupt {
        path: path_buf(),
        why: format!("payload does not decode: {e}"),
    })?;
    if !rest.is_empty() {
        return Err(Error::Corrupt {
            path: path_buf(),
            why: format!("{} undecoded payload bytes", rest.len()),
        });
    }
    Ok(value)
}

/// The payload bytes of `payload` and the parameters stored by name after it: postcard of
/// the payload, then, only when there is any, postcard of the [`Extras`] list.
pub(crate) fn payload_bytes(payload: &v11::Payload, extras: &Extras) -> Result<Vec<u8>> {
    let mut bytes = postcard::to_allocvec(payload).map_err(|source| Error::Encode { source })?;
    if !extras.is_empty() {
        bytes.extend(postcard::to_allocvec(extras).map_err(|source| Error::Encode { source })?);
    }
    Ok(bytes)
}

/// A complete state file image (header + payload) of `payload` and `extras`.
fn encode_payload(payload: &v11::Payload, extras: &Extras) -> Result<Vec<u8>> {
    Ok(with_header(&payload_bytes(payload, extras)?))
}

/// The complete state file image of a planner's state: [`v11::Payload::from_state`], then
/// the current format.
pub(crate) fn encode_state(state: &PlannerState) -> Result<Vec<u8>> {
    let (payload, extras) = v11::Payload::from_state(state)?;
    encode_payload(&payload, &extras)
}

/// The payload of a state file image read from `path` (only for error messages), of any
/// readable version: a current one with the parameters stored by name after it, an older
/// one converted (`legacy::upgrade`, no parameters by name).
///
/// # Errors
/// As [`load`].
pub(crate) fn decode_any(bytes: &[u8], path: &Path) -> Result<(v11::Payload, Extras)> {
    let (version, payload) = checked_payload(bytes, path)?;
    if version < FORMAT_VERSION {
        return Ok((legacy::upgrade(version, payload, path)?, Extras::default()));
    }
    if version == CELL_FORMAT_VERSION {
        let cell: v12::CellPayload = decode_payload(payload, path)?;
        return Err(Error::CellFile {
            path: path.to_path_buf(),
            tasks: cell.tasks.into_iter().map(|t| t.name).collect(),
        });
    }
    decode_task_payload(payload, path)
}

/// A format 11 payload (the bytes after the header) read from `path`: [`v11::Payload`] and
/// the parameters stored by name after it.
///
/// # Errors
/// [`Error::Corrupt`] naming `path` when the bytes do not decode.
pub(crate) fn decode_task_payload(payload: &[u8], path: &Path) -> Result<(v11::Payload, Extras)> {
    let (value, rest) =
        postcard::take_from_bytes::<v11::Payload>(payload).map_err(|e| Error::Corrupt {
            path: path.to_path_buf(),
            why: format!("payload does not decode: {e}"),
        })?;
    let extras = if rest.is_empty() {
        Extras::default()
    } else {
        decode_payload::<Extras>(rest, path)?
    };
    Ok((value, extras))
}

/// The planner state in a state file image read from `path`, of any readable version.
///
/// # Errors
/// As [`load`]; [`Error::Corrupt`] naming `path` when the parts do not convert into the
/// library's types (counts, flags, a demonstration, a parameter stored by name that this
/// build does not know).
pub(crate) fn decode_state(bytes: &[u8], path: &Path) -> Result<PlannerState> {
    let (payload, extras) = decode_any(bytes, path)?;
    payload.into_state(extras).map_err(|e| Error::Corrupt {
        path: path.to_path_buf(),
        why: e.to_string(),
    })
}

/// What a state file image holds: one task's planner (formats 4 to 11) or a cell of tasks
/// (format 12).
pub(crate) enum Stored {
    /// One task's planner state, an older format converted.
    Task(Box<PlannerState>),
    /// A cell of two or more tasks.
    Cell(v12::CellPayload),
}

/// The content of a state file image read from `path`, of any readable version.
///
/// # Errors
/// As [`decode_state`] for formats 4 to 11; for format 12 as [`load`].
pub(crate) fn decode_stored(bytes: &[u8], path: &Path) -> Result<Stored> {
    let (version, payload) = checked_payload(bytes, path)?;
    if version == CELL_FORMAT_VERSION {
        return Ok(Stored::Cell(decode_payload(payload, path)?));
    }
    decode_state(bytes, path).map(|s| Stored::Task(Box::new(s)))
}

/// The complete state file image of a cell of tasks: the header of
/// [`CELL_FORMAT_VERSION`], then postcard of `cell`.
///
/// # Errors
/// [`Error::Encode`].
pub(crate) fn encode_cell(cell: &v12::CellPayload) -> Result<Vec<u8>> {
    let payload = postcard::to_allocvec(cell).map_err(|source| Error::Encode { source })?;
    Ok(with_header_version(&payload, CELL_FORMAT_VERSION))
}

/// The payload of the planner's state file at `path` as wire types ([`v11::Payload`], an
/// older version converted) and the parameters stored after it by name: for tools and tests
/// that read or edit a state file below the [`crate::Planner`] (which checks what it loads).
///
/// # Errors
/// As [`load`].
pub fn load_payload(path: &Path) -> Result<(v11::Payload, Extras)> {
    decode_any(&read(path)?, path)
}

/// Saves a payload and the parameters stored by name after it ([`load_payload`]) to `path`
/// as a current-version state file, atomically and under the file's lock, as [`save`]. The
/// payload is not checked: [`crate::Planner::load`] checks it when it is read.
///
/// # Errors
/// As [`save`].
pub fn save_payload(path: &Path, payload: &v11::Payload, extras: &Extras) -> Result<()> {
    let bytes = encode_payload(payload, extras)?;
    let _lock = StateLock::acquire(path, DEFAULT_LOCK_TIMEOUT)?;
    check_target(path)?;
    write_atomic(path, &bytes)
}

/// Where a simulated crash interrupts [`write_atomic_with`] (tests only).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum CrashPoint {
    /// Finish normally.
    None,
    /// Stop after the temporary file has been written and flushed, before the rename.
    BeforeRename,
    /// Stop after writing only half of the bytes to the temporary file (no flush).
    MidWrite,
}

/// How long a writer waits for another one's lock by default: 60 s, far above one `record`
/// on the sanding fixtures (docs/decisions.md, "State files are locked").
pub const DEFAULT_LOCK_TIMEOUT: Duration = Duration::from_secs(60);

/// How often a waiting writer tries the lock again: 10 ms.
const LOCK_POLL: Duration = Duration::from_millis(10);

/// `.<name><suffix>` beside `path`.
fn sibling(path: &Path, suffix: &str) -> Result<PathBuf> {
    let name = path.file_name().ok_or_else(|| Error::Io {
        path: path.to_path_buf(),
        op: "use as a state file (the path has no file name)",
        source: std::io::Error::from(std::io::ErrorKind::InvalidInput),
    })?;
    let mut sibling_name = std::ffi::OsString::from(".");
    sibling_name.push(name);
    sibling_name.push(suffix);
    Ok(path.with_file_name(sibling_name))
}

/// The lock file of the state file `path`: `.<name>.lock` in the same directory.
pub fn lock_path(path: &Path) -> Result<PathBuf> {
    sibling(path, ".lock")
}

/// Saves made by this process so far: the counter of the unique temporary names.
static SAVES: AtomicU64 = AtomicU64::new(0);

/// A temporary file for saving `path` that no other save uses:
/// `.<name>.<process id>-<counter>.tmp` in the same directory.
pub(crate) fn temp_path(path: &Path) -> Result<PathBuf> {
    let k = SAVES.fetch_add(1, Ordering::Relaxed);
    sibling(path, &format!(".{}-{k}.tmp", std::process::id()))
}

/// Whether `name` is a temporary file of [`temp_path`] for the state file named `state_name`.
fn is_temp_of(name: &str, state_name: &str) -> bool {
    name.strip_prefix('.')
        .and_then(|n| n.strip_prefix(state_name))
        .and_then(|n| n.strip_prefix('.'))
        .and_then(|n| n.strip_suffix(".tmp"))
        .and_then(|n| n.split_once('-'))
        .is_some_and(|(pid, k)| {
            !pid.is_empty()
                && !k.is_empty()
                && pid.bytes().all(|b| b.is_ascii_digit())
                && k.bytes().all(|b| b.is_ascii_digit())
        })
}

/// Removes the temporary files of `path` that crashed writers left (best effort: a file that
/// cannot be listed or removed stays). Call it only while holding the lock of `path`.
fn remove_stale_temps(path: &Path) {
    let (Some(dir), Some(name)) = (parent_dir(path), path.file_name().and_then(|n| n.to_str()))
    else {
        return;
    };
    let Ok(entries) = fs::read_dir(&dir) else {
        return;
    };
    for entry in entries.flatten() {
        if entry
            .file_name()
            .to_str()
            .is_some_and(|n| is_temp_of(n, name))
        {
            let _ = fs::remove_file(entry.path());
        }
    }
}

/// The directory holding `path` (`.` for a bare file name).
fn parent_dir(path: &Path) -> Option<PathBuf> {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => Some(d.to_path_buf()),
        _ => Some(PathBuf::from(".")),
    }
}

/// An advisory exclusive lock on a state file, held for a whole read–modify–write (see the
/// module docs): at most one `StateLock` of a path exists at a time, across processes and
/// threads. Dropping it releases the lock.
#[derive(Debug)]
pub struct StateLock {
    file: File,
    state_path: PathBuf,
    lock_path: PathBuf,
}

impl StateLock {
    /// Locks the state file `path` (which need not exist yet), waiting up to `timeout` for a
    /// writer that holds it (polling every 10 ms).
    ///
    /// # Errors
    /// [`Error::Locked`] when the lock is still held after `timeout`; [`Error::Io`] when the
    /// lock file cannot be created or locked (e.g. the folder does not exist).
    pub fn acquire(path: &Path, timeout: Duration) -> Result<Self> {
        // The lock file lives beside the state file: a folder that is not there is named
        // with the fix, not as the operating system's error on the lock file.
        check_folder(path)?;
        let lock_path = lock_path(path)?;
        let file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&lock_path)
            .map_err(|source| Error::Io {
                path: lock_path.clone(),
                op: "create the lock file of the state file",
                source,
            })?;
        let start = Instant::now();
        loop {
            match fs4::FileExt::try_lock(&file) {
                Ok(()) => {
                    return Ok(Self {
                        file,
                        state_path: path.to_path_buf(),
                        lock_path,
                    });
                }
                Err(fs4::TryLockError::WouldBlock) => {}
                Err(fs4::TryLockError::Error(source)) => {
                    return Err(Error::Io {
                        path: lock_path,
                        op: "lock",
                        source,
                    });
                }
            }
            let waited = start.elapsed();
            if waited >= timeout {
                return Err(Error::Locked {
                    path: path.to_path_buf(),
                    lock_path,
                    waited_s: waited.as_secs_f64(),
                });
            }
            std::thread::sleep(LOCK_POLL.min(timeout - waited));
        }
    }

    /// The state file this lock protects.
    pub fn state_path(&self) -> &Path {
        &self.state_path
    }

    /// The lock file (`.<name>.lock` beside the state file).
    pub fn lock_path(&self) -> &Path {
        &self.lock_path
    }
}

impl Drop for StateLock {
    fn drop(&mut self) {
        // Closing the file releases the lock too; unlocking first says so explicitly.
        let _ = fs4::FileExt::unlock(&self.file);
    }
}

/// Refuses to replace `path` unless it is missing, empty or a tandem state file (it starts
/// with [`MAGIC`]): a save never overwrites a demonstration, a log or any other file by
/// accident.
///
/// # Errors
/// [`Error::WouldOverwrite`] for a folder or a file of other content; [`Error::Io`] when an
/// existing file cannot be read, or when the folder to save into does not exist or is a
/// file (naming that folder and the fix).
pub fn check_target(path: &Path) -> Result<()> {
    let meta = match fs::metadata(path) {
        Ok(m) => m,
        Err(e)
            if matches!(
                e.kind(),
                std::io::ErrorKind::NotFound | std::io::ErrorKind::NotADirectory
            ) =>
        {
            return check_folder(path);
        }
        Err(source) => {
            return Err(Error::Io {
                path: path.to_path_buf(),
                op: "inspect the file to be replaced",
                source,
            });
        }
    };
    if meta.is_dir() {
        return Err(Error::WouldOverwrite {
            path: path.to_path_buf(),
            why: "it is a folder".into(),
        });
    }
    let mut head = Vec::with_capacity(MAGIC.len());
    File::open(path)
        .and_then(|f| f.take(MAGIC.len() as u64).read_to_end(&mut head))
        .map_err(|source| Error::Io {
            path: path.to_path_buf(),
            op: "read the file to be replaced",
            source,
        })?;
    if !head.is_empty() && head != MAGIC {
        return Err(Error::WouldOverwrite {
            path: path.to_path_buf(),
            why: "it is not a tandem state file (it does not start with \"TANDEMST\")".into(),
        });
    }
    Ok(())
}

/// The folder `path` would be saved into exists and is a folder; else [`Error::Io`] naming
/// it and the fix (instead of the operating system's error on the lock file).
fn check_folder(path: &Path) -> Result<()> {
    let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) else {
        return Ok(());
    };
    let why = match fs::metadata(parent) {
        Ok(m) if m.is_dir() => return Ok(()),
        Ok(_) => "it is a file, not a folder: give a path in an existing folder",
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            "the folder does not exist: create it first or give a path in an existing folder"
        }
        // Anything else (permissions, say) is reported where the save meets it.
        Err(_) => return Ok(()),
    };
    Err(Error::Io {
        path: parent.to_path_buf(),
        op: "save the state file there",
        source: std::io::Error::other(why),
    })
}

/// What identifies the content of a state file: its payload length and checksum (header
/// bytes 12..24).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Stamp {
    payload_len: u64,
    crc: u32,
}

/// The [`Stamp`] of a state file image, if it has a whole header.
pub(crate) fn stamp_of(bytes: &[u8]) -> Option<Stamp> {
    let header = bytes.get(..HEADER_LEN)?;
    Some(Stamp {
        payload_len: u64::from_le_bytes(header[12..20].try_into().expect("8-byte slice")),
        crc: u32::from_le_bytes(header[20..24].try_into().expect("4-byte slice")),
    })
}

/// The [`Stamp`] of the file at `path` (`None` when it is missing or shorter than a header).
pub(crate) fn stamp_at(path: &Path) -> Result<Option<Stamp>> {
    let mut header = Vec::with_capacity(HEADER_LEN);
    match File::open(path) {
        Ok(f) => f
            .take(HEADER_LEN as u64)
            .read_to_end(&mut header)
            .map_err(|source| Error::Io {
                path: path.to_path_buf(),
                op: "read the header of state file",
                source,
            })?,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(source) => {
            return Err(Error::Io {
                path: path.to_path_buf(),
                op: "read the header of state file",
                source,
            });
        }
    };
    Ok(stamp_of(&header))
}

/// `path` with its folder resolved (symbolic links, `.`/`..`), whether or not the file
/// exists: what decides that two paths name the same state file.
pub(crate) fn resolved(path: &Path) -> PathBuf {
    if let Ok(p) = fs::canonicalize(path) {
        return p;
    }
    match (parent_dir(path), path.file_name()) {
        (Some(dir), Some(name)) => fs::canonicalize(&dir)
            .map(|d| d.join(name))
            .unwrap_or_else(|_| path.to_path_buf()),
        _ => path.to_path_buf(),
    }
}

/// Write `bytes` to `path` atomically (see the module docs). The caller holds the lock.
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    remove_stale_temps(path);
    write_atomic_with(path, bytes, CrashPoint::None).map(|_| ())
}

/// [`write_atomic`] with a simulated crash point for tests; returns the temporary file used.
pub(crate) fn write_atomic_with(path: &Path, bytes: &[u8], crash: CrashPoint) -> Result<PathBuf> {
    let tmp = temp_path(path)?;
    let io = |p: &Path, op: &'static str| {
        let p = p.to_path_buf();
        move |source| Error::Io {
            path: p,
            op,
            source,
        }
    };
    let mut file = OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(true)
        .open(&tmp)
        .map_err(io(&tmp, "create temporary state file"))?;
    if crash == CrashPoint::MidWrite {
        file.write_all(&bytes[..bytes.len() / 2])
            .map_err(io(&tmp, "write temporary state file"))?;
        return Ok(tmp);
    }
    let written = file
        .write_all(bytes)
        .map_err(io(&tmp, "write temporary state file"))
        .and_then(|()| {
            file.sync_all()
                .map_err(io(&tmp, "flush temporary state file to disk"))
        });
    drop(file);
    if let Err(e) = written {
        let _ = fs::remove_file(&tmp);
        return Err(e);
    }
    if crash == CrashPoint::BeforeRename {
        return Ok(tmp);
    }
    if let Err(e) = fs::rename(&tmp, path) {
        let _ = fs::remove_file(&tmp);
        return Err(io(path, "rename the temporary state file onto")(e));
    }
    sync_parent_dir(path)?;
    Ok(tmp)
}

/// Flush the directory holding `path`, so that a rename in it is durable.
#[cfg(unix)]
fn sync_parent_dir(path: &Path) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    File::open(dir)
        .and_then(|d| d.sync_all())
        .map_err(|source| Error::Io {
            path: dir.to_path_buf(),
            op: "flush directory of the state file",
            source,
        })
}

/// Directories cannot be flushed portably off Unix; the rename alone is atomic there.
#[cfg(not(unix))]
fn sync_parent_dir(_path: &Path) -> Result<()> {
    Ok(())
}

/// Read a state file image from `path`.
pub(crate) fn read(path: &Path) -> Result<Vec<u8>> {
    if path.is_dir() {
        return Err(Error::Io {
            path: path.to_path_buf(),
            op: "read state file",
            source: std::io::Error::other("it is a folder, not a state file: give the file's path"),
        });
    }
    fs::read(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        op: "read state file",
        source,
    })
}

/// Save `value` to `path` as a versioned state file (see the module docs), atomically and
/// under the file's lock (waiting up to [`DEFAULT_LOCK_TIMEOUT`]): on any error, or a crash,
/// the file previously at `path` is untouched.
///
/// # Errors
/// [`Error::Locked`], [`Error::WouldOverwrite`] for an existing file that is not a state
/// file, [`Error::Encode`] if `value` cannot be serialized, [`Error::Io`] naming the file or
/// directory whose creation, write, flush or rename failed.
pub fn save<T: Serialize>(path: &Path, value: &T) -> Result<()> {
    let bytes = encode(value)?;
    let _lock = StateLock::acquire(path, DEFAULT_LOCK_TIMEOUT)?;
    check_target(path)?;
    write_atomic(path, &bytes)
}

/// Load a versioned state file from `path`.
///
/// # Errors
/// [`Error::Io`] if the file cannot be read, [`Error::NotAStateFile`] without the magic
/// bytes, [`Error::UnsupportedVersion`] for another format version, [`Error::Truncated`]
/// if it is shorter than announced, [`Error::Corrupt`] for a checksum mismatch, trailing
/// bytes or a payload that does not decode as `T`. Every variant names `path`.
pub fn load<T: DeserializeOwned>(path: &Path) -> Result<T> {
    decode(&read(path)?, path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct Payload {
        name: String,
        values: Vec<f64>,
        flags: Vec<bool>,
    }

    fn payload(n: usize) -> Payload {
        Payload {
            name: format!("state {n}"),
            values: (0..n).map(|i| i as f64 * 0.5).collect(),
            flags: (0..n).map(|i| i % 3 == 0).collect(),
        }
    }

    #[test]
    fn a_missing_folder_a_file_as_folder_and_a_folder_as_file_are_named_with_the_fix() {
        let dir = tmp_dir("folders");
        let missing = dir.join("no/such/folder/cell.tandem");
        let err = check_target(&missing).unwrap_err().to_string();
        assert_eq!(
            err,
            format!(
                "{}: cannot save the state file there: the folder does not exist: create it first or give a path in an existing folder",
                dir.join("no/such/folder").display()
            )
        );
        // Taking the lock (before any save) says the same, not the lock file's OS error.
        let Err(err) = StateLock::acquire(&missing, Duration::from_millis(10)) else {
            panic!("a lock in a missing folder");
        };
        let err = err.to_string();
        assert!(err.contains("the folder does not exist"), "{err}");
        let file = dir.join("demo.csv");
        fs::write(&file, "t,x\n").unwrap();
        let err = check_target(&file.join("cell.tandem"))
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with(&format!(
                "{}: cannot save the state file there: it is a file",
                file.display()
            )),
            "{err}"
        );
        let err = read(&dir).unwrap_err().to_string();
        assert_eq!(
            err,
            format!(
                "{}: cannot read state file: it is a folder, not a state file: give the file's path",
                dir.display()
            )
        );
        // A bare file name saves into the working folder: nothing to check.
        assert!(check_target(Path::new("cell-that-does-not-exist.tandem")).is_ok());
        assert!(!dir.join("no").exists());
        let _ = fs::remove_dir_all(&dir);
    }

    fn tmp_dir(tag: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("tandem-state-{tag}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn header_layout_is_as_documented() {
        let bytes = encode(&payload(4)).unwrap();
        assert_eq!(&bytes[..8], b"TANDEMST");
        assert_eq!(u32::from_le_bytes(bytes[8..12].try_into().unwrap()), 11);
        let len = u64::from_le_bytes(bytes[12..20].try_into().unwrap());
        assert_eq!(len as usize, bytes.len() - HEADER_LEN);
        let crc = u32::from_le_bytes(bytes[20..24].try_into().unwrap());
        assert_eq!(crc, crc32fast::hash(&bytes[HEADER_LEN..]));
    }

    #[test]
    fn round_trip_through_a_file() {
        let dir = tmp_dir("roundtrip");
        let path = dir.join("state.tandem");
        let value = payload(50);
        save(&path, &value).unwrap();
        assert_eq!(load::<Payload>(&path).unwrap(), value);
        // Overwriting replaces the content and leaves no temporary file behind: only the
        // state file and its lock file.
        save(&path, &payload(7)).unwrap();
        assert_eq!(load::<Payload>(&path).unwrap(), payload(7));
        let mut names: Vec<String> = fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        assert_eq!(names, [".state.tandem.lock", "state.tandem"]);
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn every_truncation_is_a_clear_error() {
        let path = Path::new("some/dir/state.tandem");
        let bytes = encode(&payload(20)).unwrap();
        for cut in 0..bytes.len() {
            let err = decode::<Payload>(&bytes[..cut], path).unwrap_err();
            let msg = err.to_string();
            assert!(msg.contains("some/dir/state.tandem"), "{msg}");
            match err {
                Error::NotAStateFile { .. } => assert!(cut < MAGIC.len()),
                Error::Truncated { found_bytes, .. } => assert_eq!(found_bytes, cut as u64),
                other => panic!("cut at {cut}: unexpected {other:?}"),
            }
        }
    }

    #[test]
    fn random_bytes_and_flipped_bits_are_rejected() {
        let path = Path::new("x.tandem");
        // Deterministic pseudo-random bytes (xorshift), no magic.
        let mut x = 0x9E37_79B9_7F4A_7C15_u64;
        let noise: Vec<u8> = (0..300)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                (x >> 24) as u8
            })
            .collect();
        assert!(matches!(
            decode::<Payload>(&noise, path),
            Err(Error::NotAStateFile { .. })
        ));
        assert!(matches!(
            decode::<Payload>(&[], path),
            Err(Error::NotAStateFile { .. })
        ));
        // Any single flipped bit in the payload is caught by the checksum.
        let good = encode(&payload(10)).unwrap();
        for i in HEADER_LEN..good.len() {
            let mut bad = good.clone();
            bad[i] ^= 0x10;
            let err = decode::<Payload>(&bad, path).unwrap_err();
            assert!(matches!(err, Error::Corrupt { .. }), "byte {i}: {err:?}");
            assert!(err.to_string().contains("checksum"), "{err}");
        }
        // Trailing garbage after the payload.
        let mut long = good.clone();
        long.push(0);
        assert!(matches!(
            decode::<Payload>(&long, path),
            Err(Error::Corrupt { .. })
        ));
    }

    #[test]
    fn other_version_is_rejected_with_both_numbers() {
        let mut bytes = encode(&payload(3)).unwrap();
        bytes[8..12].copy_from_slice(&13u32.to_le_bytes());
        let err = decode::<Payload>(&bytes, Path::new("v.tandem")).unwrap_err();
        assert!(matches!(
            err,
            Error::UnsupportedVersion {
                found: 13,
                expected: NEWEST_READABLE_VERSION,
                ..
            }
        ));
        let msg = err.to_string();
        assert!(msg.contains("v.tandem") && msg.contains("13") && msg.contains("4 to 12"));
    }

    #[test]
    fn a_crash_while_saving_keeps_the_old_file() {
        let dir = tmp_dir("crash");
        let path = dir.join("state.tandem");
        let old = payload(30);
        save(&path, &old).unwrap();
        let new_bytes = encode(&payload(40)).unwrap();
        let mut stale = Vec::new();
        for crash in [CrashPoint::MidWrite, CrashPoint::BeforeRename] {
            let tmp = write_atomic_with(&path, &new_bytes, crash).unwrap();
            assert!(tmp.exists());
            assert_eq!(load::<Payload>(&path).unwrap(), old, "{crash:?}");
            stale.push(tmp);
        }
        assert_ne!(
            stale[0], stale[1],
            "every save has a temporary file of its own"
        );
        // The next save succeeds and removes the crashed writers' temporary files.
        save(&path, &payload(40)).unwrap();
        assert_eq!(load::<Payload>(&path).unwrap(), payload(40));
        assert!(stale.iter().all(|t| !t.exists()));
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn temporary_names_are_recognised_exactly() {
        assert!(is_temp_of(".cell.tandem.123-0.tmp", "cell.tandem"));
        for other in [
            ".cell.tandem.tmp",
            ".cell.tandem.lock",
            ".cell.tandem.x-1.tmp",
            ".cell.tandem.1-.tmp",
            ".other.tandem.1-2.tmp",
            "cell.tandem.1-2.tmp",
        ] {
            assert!(!is_temp_of(other, "cell.tandem"), "{other}");
        }
    }

    #[test]
    fn a_save_never_replaces_a_file_of_other_content() {
        let dir = tmp_dir("target");
        let csv = dir.join("demo_3.csv");
        fs::write(&csv, "t,x\n0,1\n").unwrap();
        let err = save(&csv, &payload(3)).unwrap_err();
        assert!(matches!(err, Error::WouldOverwrite { .. }), "{err}");
        let msg = err.to_string();
        assert!(
            msg.contains("demo_3.csv") && msg.contains("not a tandem state file"),
            "{msg}"
        );
        assert_eq!(fs::read_to_string(&csv).unwrap(), "t,x\n0,1\n");
        let err = save(&dir, &payload(3)).unwrap_err();
        assert!(err.to_string().contains("is a folder"), "{err}");
        // Missing, empty and state files may be replaced.
        let empty = dir.join("empty.tandem");
        fs::write(&empty, b"").unwrap();
        save(&empty, &payload(3)).unwrap();
        save(&empty, &payload(4)).unwrap();
        assert_eq!(load::<Payload>(&empty).unwrap(), payload(4));
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_second_writer_waits_for_the_lock_then_gives_up_with_a_clear_error() {
        let dir = tmp_dir("lock");
        let path = dir.join("cell.tandem");
        let held = StateLock::acquire(&path, Duration::ZERO).unwrap();
        assert_eq!(held.lock_path(), dir.join(".cell.tandem.lock"));
        let start = Instant::now();
        let err = StateLock::acquire(&path, Duration::from_millis(50)).unwrap_err();
        assert!(start.elapsed() >= Duration::from_millis(50));
        assert!(matches!(err, Error::Locked { .. }), "{err}");
        assert!(err.to_string().contains("another process"), "{err}");
        // Another thread's save waits while the lock is held and goes through once it is
        // released.
        let p2 = path.clone();
        let writer = std::thread::spawn(move || save(&p2, &payload(5)));
        std::thread::sleep(Duration::from_millis(100));
        assert!(!path.exists(), "the save waited for the lock");
        drop(held);
        writer.join().unwrap().unwrap();
        assert_eq!(load::<Payload>(&path).unwrap(), payload(5));
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn missing_file_names_the_path() {
        let err = load::<Payload>(Path::new("/nonexistent/dir/s.tandem")).unwrap_err();
        assert!(matches!(err, Error::Io { .. }));
        assert!(err.to_string().contains("/nonexistent/dir/s.tandem"));
    }
}
