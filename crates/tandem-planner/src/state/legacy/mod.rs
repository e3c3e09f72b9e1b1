//! The payloads of state formats 4 to 10, as those formats wrote them, each converted into
//! the current payload ([`super::v11::Payload`]) on load. Nothing writes them.
//!
//! Each old payload is written with the wire types of [`super::v11`] wherever its bytes are
//! the same (postcard writes a nested struct as its fields in order), and its own types where
//! they differ. The conversions fill what a format lacked with the value that reproduces
//! what the file was made with (no smoothing, no filling, the paper's confidence model, no
//! hold points, no fingerprints, no stored executions): see [`super::FORMAT_VERSION`].
//!
//! - `v8_to_v10`: formats 8 to 10 (the fit's warp parameters of 8 and 9; no reference
//!   demonstration, no stored executions).
//! - `v7`: format 7 (no hold points).
//! - `v4_to_v6`: formats 4 to 6 (the paper's confidence model, no evidence of misses; 4
//!   and 5 without round fingerprints, 4 with a two-robot schedule).

mod v4_to_v6;
mod v7;
mod v8_to_v10;

use std::path::Path;

use super::v11::Payload;
use super::{OLDEST_READABLE_VERSION, decode_payload};
use crate::Result;

/// The payload of a file of the old `version` (`4..=10`), read from `path`, converted into
/// the current payload.
///
/// # Errors
/// [`crate::Error::Corrupt`] naming `path` when the payload does not decode.
pub(crate) fn upgrade(version: u32, payload: &[u8], path: &Path) -> Result<Payload> {
    debug_assert!((OLDEST_READABLE_VERSION..=10).contains(&version));
    Ok(match version {
        4 => decode_payload::<v4_to_v6::V4>(payload, path)?.into(),
        5 => decode_payload::<v4_to_v6::V5>(payload, path)?.into(),
        6 => decode_payload::<v4_to_v6::V6>(payload, path)?.into(),
        7 => decode_payload::<v7::V7>(payload, path)?.into(),
        8 => decode_payload::<v8_to_v10::V8>(payload, path)?.into(),
        9 => decode_payload::<v8_to_v10::V9>(payload, path)?.into(),
        _ => decode_payload::<v8_to_v10::V10>(payload, path)?.into(),
    })
}
