//! tandem: coordinated multi-robot shared autonomy (Hagenow et al., RA-L 2023).
//!
//! The facade of the workspace. It re-exports the crates (`tandem::warp`, `lfd`,
//! `confidence`, `realtime`, `schedule`, `sim`) and holds the glue of the paper's Fig. 2
//! loop (§II-C, Eq. 21): [`Planner`] keeps the task model, the correction observations,
//! the latched confidence and the current schedule, and updates all four after every
//! pair of executions ([`Planner::record_pair`]). Its state is saved as a versioned,
//! checksummed, atomically written file ([`state`]). [`study`] is the simulated study of
//! §III (Fig. 5).
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
pub mod planner;
pub mod state;
pub mod study;

pub use error::{Error, Result};
pub use planner::{ExecutionRecord, Planner, PlannerParams, RecordReport};

pub use tandem_confidence as confidence;
pub use tandem_lfd as lfd;
pub use tandem_realtime as realtime;
pub use tandem_schedule as schedule;
pub use tandem_sim as sim;
pub use tandem_warp as warp;

/// A seed for item `index` of a seeded family (trial `k` of a study, the schedule after
/// `k` recorded pairs): SplitMix64 of both, so items are independent of each other and of
/// the order in which threads process them.
pub fn derive_seed(seed: u64, index: u64) -> u64 {
    splitmix64(seed ^ splitmix64(index.wrapping_add(1)))
}

/// One SplitMix64 output for state `x` (Steele, Lea & Flood 2014).
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}
