//! tandem: coordinated multi-robot shared autonomy (Hagenow et al., RA-L 2023).
//!
//! The facade of the workspace. It re-exports the crates, and holds the glue of the
//! paper's Fig. 2 loop, persisted as a versioned, atomically written state file
//! ([`state`]).
//!
//! ```
//! let path = std::env::temp_dir().join(format!("tandem-doc-{}.state", std::process::id()));
//! tandem::state::save(&path, &vec![1.0_f64, 2.5])?;
//! assert_eq!(tandem::state::load::<Vec<f64>>(&path)?, vec![1.0, 2.5]);
//! std::fs::write(&path, b"not a state file")?;
//! assert!(matches!(
//!     tandem::state::load::<Vec<f64>>(&path),
//!     Err(tandem::Error::NotAStateFile { .. })
//! ));
//! # std::fs::remove_file(&path)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod error;
pub mod state;
pub mod study;

pub use error::{Error, Result};
