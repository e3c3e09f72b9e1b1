//! What a study learns from: the demonstrations and the reference's ground-truth labels.

use std::path::Path;

use tandem_lfd::Demonstration;

use crate::task::{self, Label};
use crate::{Error, Result};

/// What a study learns from: demonstrations (demo 0 is the reference) and the ground-truth
/// labels of the reference demonstration, one per sample.
#[derive(Clone, Debug, PartialEq)]
pub struct StudyInputs {
    /// The demonstrations, demo 0 first.
    pub demos: Vec<Demonstration>,
    /// Labels of demo 0's samples (pass, section, painted, phase).
    pub reference_labels: Vec<Label>,
}

impl StudyInputs {
    /// Reads `demo_0.csv`, `demo_1.csv`, … (until the first missing index) and
    /// `demo_0.labels.csv` from `dir` (the layout of `fixtures/sanding/`).
    ///
    /// # Errors
    /// [`Error::BadInput`] naming the file for a missing or unreadable labels file, fewer
    /// than two demonstrations, or labels that do not match demo 0's samples; the model
    /// crate's error (naming file and line) for a bad demonstration.
    pub fn from_dir(dir: &Path) -> Result<Self> {
        let mut demos = Vec::new();
        loop {
            let path = dir.join(format!("demo_{}.csv", demos.len()));
            if !path.exists() {
                break;
            }
            demos.push(Demonstration::from_csv_path(&path, None)?);
        }
        if demos.len() < 2 {
            return Err(Error::BadInput {
                path: dir.to_path_buf(),
                why: format!(
                    "found {} demonstrations demo_0.csv, demo_1.csv, …; need at least 2",
                    demos.len()
                ),
            });
        }
        let path = dir.join("demo_0.labels.csv");
        let inputs = Self {
            demos,
            reference_labels: read_labels(&path)?,
        };
        inputs
            .check()
            .map_err(|why| Error::BadInput { path, why })?;
        Ok(inputs)
    }

    /// From demonstrations made by the task generator ([`crate::task`]), demo 0 the
    /// reference: channels [`task::CHANNELS`], each demo's own `Δt_s`.
    ///
    /// # Errors
    /// The model crate's error if a demonstration is invalid, [`Error::BadInput`] for
    /// fewer than two.
    pub fn from_task_demos(demos: &[task::TaskDemo]) -> Result<Self> {
        let names: Vec<String> = task::CHANNELS.iter().map(|c| (*c).to_string()).collect();
        let converted = demos
            .iter()
            .map(|d| {
                let flat: Vec<f64> = d.samples.iter().flatten().copied().collect();
                Demonstration::new(names.clone(), flat, d.dt_s)
            })
            .collect::<std::result::Result<Vec<_>, _>>()?;
        let inputs = Self {
            demos: converted,
            reference_labels: demos.first().map(|d| d.labels.clone()).unwrap_or_default(),
        };
        inputs.check().map_err(|why| Error::BadInput {
            path: "<generated demonstrations>".into(),
            why,
        })?;
        Ok(inputs)
    }

    pub(super) fn check(&self) -> std::result::Result<(), String> {
        if self.demos.len() < 2 {
            return Err(format!(
                "{} demonstrations, need at least 2",
                self.demos.len()
            ));
        }
        let n = self.demos[0].n_samples();
        if self.reference_labels.len() != n {
            return Err(format!(
                "{} labels for the {n} samples of the reference demonstration",
                self.reference_labels.len()
            ));
        }
        Ok(())
    }
}

/// Reads a labels file of the fixtures (`demo_<i>.labels.csv`: columns `pass, section,
/// painted, phase`, one row per sample of demo `i`).
///
/// # Errors
/// [`Error::BadInput`] naming the file (and the row) when it cannot be read or parsed.
pub fn read_labels(path: &Path) -> Result<Vec<Label>> {
    let bad = |why: String| Error::BadInput {
        path: path.to_path_buf(),
        why,
    };
    let mut reader = csv::Reader::from_path(path).map_err(|e| bad(e.to_string()))?;
    reader
        .deserialize::<Label>()
        .enumerate()
        .map(|(k, r)| r.map_err(|e| bad(format!("row {}: {e}", k + 1))))
        .collect()
}
