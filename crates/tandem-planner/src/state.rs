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
//! | 24.. | payload: the state encoded with `postcard` |
//!
//! Reading checks, in this order: the file can be read, it is at least a header long and
//! starts with the magic bytes, the version is one this build reads
//! ([`OLDEST_READABLE_VERSION`]`..=`[`FORMAT_VERSION`]), the payload has
//! exactly the announced length (shorter = truncated, longer = trailing garbage), the
//! checksum matches, and `postcard` decodes the payload using every byte.
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
//! The bytes go to a temporary file in the same directory (`.<name>.tmp`), which is
//! flushed to disk (`fsync`), then renamed over the target, then the directory itself is
//! flushed so the rename survives a power cut. A crash at any point leaves either the old
//! file or the new one, never a mix: the previous state is never lost.

use std::fs::{self, File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::{Error, Result};

/// Magic bytes at the start of every state file.
pub const MAGIC: [u8; 8] = *b"TANDEMST";

/// The state format version this build writes and reads.
/// Bump it whenever the serialized payload changes shape, and regenerate the golden file
/// (`cargo xtask fixtures`, see the module docs).
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
pub const FORMAT_VERSION: u32 = 5;

/// The oldest state format version this build reads (converting it on load).
pub const OLDEST_READABLE_VERSION: u32 = 4;

/// Header length in bytes: magic (8) + version (4) + payload length (8) + CRC-32 (4).
pub const HEADER_LEN: usize = 24;

/// Encode `value` as a complete state file image (header + payload).
pub(crate) fn encode<T: Serialize>(value: &T) -> Result<Vec<u8>> {
    let payload = postcard::to_allocvec(value).map_err(|source| Error::Encode { source })?;
    let mut bytes = Vec::with_capacity(HEADER_LEN + payload.len());
    bytes.extend_from_slice(&MAGIC);
    bytes.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    bytes.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
    bytes.extend_from_slice(&payload);
    Ok(bytes)
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
        expected: FORMAT_VERSION,
    }
}

/// The version and the payload of a state file image read from `path`, after every check of
/// the module docs but the decoding: magic, a readable version
/// ([`OLDEST_READABLE_VERSION`]`..=`[`FORMAT_VERSION`]), length and checksum.
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
    if !(OLDEST_READABLE_VERSION..=FORMAT_VERSION).contains(&version) {
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

/// The temporary file used while saving `path`: `.<name>.tmp` in the same directory.
pub(crate) fn temp_path(path: &Path) -> Result<PathBuf> {
    let name = path.file_name().ok_or_else(|| Error::Io {
        path: path.to_path_buf(),
        op: "save state to (the path has no file name)",
        source: std::io::Error::from(std::io::ErrorKind::InvalidInput),
    })?;
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(".tmp");
    Ok(path.with_file_name(tmp_name))
}

/// Write `bytes` to `path` atomically (see the module docs).
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic_with(path, bytes, CrashPoint::None)
}

/// [`write_atomic`] with a simulated crash point for tests.
pub(crate) fn write_atomic_with(path: &Path, bytes: &[u8], crash: CrashPoint) -> Result<()> {
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
        return Ok(());
    }
    file.write_all(bytes)
        .map_err(io(&tmp, "write temporary state file"))?;
    file.sync_all()
        .map_err(io(&tmp, "flush temporary state file to disk"))?;
    drop(file);
    if crash == CrashPoint::BeforeRename {
        return Ok(());
    }
    fs::rename(&tmp, path).map_err(io(path, "rename the temporary state file onto"))?;
    sync_parent_dir(path)?;
    Ok(())
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
    fs::read(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        op: "read state file",
        source,
    })
}

/// Save `value` to `path` as a versioned state file (see the module docs), atomically:
/// on any error, or a crash, the file previously at `path` is untouched.
///
/// # Errors
/// [`Error::Encode`] if `value` cannot be serialized, [`Error::Io`] naming the file or
/// directory whose creation, write, flush or rename failed.
pub fn save<T: Serialize>(path: &Path, value: &T) -> Result<()> {
    write_atomic(path, &encode(value)?)
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
        assert_eq!(u32::from_le_bytes(bytes[8..12].try_into().unwrap()), 5);
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
        // Overwriting replaces the content and leaves no temporary file behind.
        save(&path, &payload(7)).unwrap();
        assert_eq!(load::<Payload>(&path).unwrap(), payload(7));
        assert!(!temp_path(&path).unwrap().exists());
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
        bytes[8..12].copy_from_slice(&7u32.to_le_bytes());
        let err = decode::<Payload>(&bytes, Path::new("v.tandem")).unwrap_err();
        assert!(matches!(
            err,
            Error::UnsupportedVersion {
                found: 7,
                expected: FORMAT_VERSION,
                ..
            }
        ));
        let msg = err.to_string();
        assert!(msg.contains("v.tandem") && msg.contains('7') && msg.contains('5'));
    }

    #[test]
    fn a_crash_while_saving_keeps_the_old_file() {
        let dir = tmp_dir("crash");
        let path = dir.join("state.tandem");
        let old = payload(30);
        save(&path, &old).unwrap();
        let new_bytes = encode(&payload(40)).unwrap();
        for crash in [CrashPoint::MidWrite, CrashPoint::BeforeRename] {
            write_atomic_with(&path, &new_bytes, crash).unwrap();
            assert!(temp_path(&path).unwrap().exists());
            assert_eq!(load::<Payload>(&path).unwrap(), old, "{crash:?}");
        }
        // The next save overwrites the stale temporary file and succeeds.
        save(&path, &payload(40)).unwrap();
        assert_eq!(load::<Payload>(&path).unwrap(), payload(40));
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn missing_file_names_the_path() {
        let err = load::<Payload>(Path::new("/nonexistent/dir/s.tandem")).unwrap_err();
        assert!(matches!(err, Error::Io { .. }));
        assert!(err.to_string().contains("/nonexistent/dir/s.tandem"));
    }
}
