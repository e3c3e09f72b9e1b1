//! What a study learns from: the demonstrations and their ground-truth labels, and the one
//! function that puts the labels on a model's time axis ([`reference_labels`]).

use std::path::{Path, PathBuf};

use tandem_lfd::{Demonstration, TaskModel};

use crate::task::{self, Label};
use crate::{Error, Result};

/// What a study learns from: demonstrations and the ground-truth labels of every one of them,
/// one per sample. Whichever demonstration the fit chooses as the reference
/// ([`tandem_lfd::FitParams::reference`]; the default is the medoid), its own labels are the
/// truth on the model's time axis ([`StudyInputs::reference_labels`]).
#[derive(Clone, Debug, PartialEq)]
pub struct StudyInputs {
    /// The demonstrations, in the order they are given to the fit.
    pub demos: Vec<Demonstration>,
    /// Per demonstration (same order), the labels of its samples (pass, section, painted,
    /// phase).
    pub labels: Vec<Vec<Label>>,
}

impl StudyInputs {
    /// Reads `demo_0.csv`, `demo_1.csv`, … (until the first missing index) and each one's
    /// `demo_<i>.labels.csv` from `dir` (the layout of `fixtures/sanding/`).
    ///
    /// # Errors
    /// [`Error::BadInput`] naming the file for a missing or unreadable labels file, fewer
    /// than two demonstrations, or labels that do not match their demonstration's samples;
    /// the model crate's error (naming file and line) for a bad demonstration.
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
        let mut labels = Vec::with_capacity(demos.len());
        for (i, demo) in demos.iter().enumerate() {
            let path = dir.join(format!("demo_{i}.labels.csv"));
            if !path.exists() {
                return Err(Error::BadInput {
                    path,
                    why: format!(
                        "missing: every demonstration needs its ground-truth labels (the fit's \
                         reference, whose labels are the truth, may be any of them), and \
                         demo_{i}.csv has none"
                    ),
                });
            }
            let l = read_labels(&path)?;
            if l.len() != demo.n_samples() {
                return Err(Error::BadInput {
                    path,
                    why: format!(
                        "{} labels for the {} samples of demo_{i}.csv: give one row per sample",
                        l.len(),
                        demo.n_samples()
                    ),
                });
            }
            labels.push(l);
        }
        let inputs = Self { demos, labels };
        inputs.check().map_err(|why| Error::BadInput {
            path: dir.to_path_buf(),
            why,
        })?;
        Ok(inputs)
    }

    /// From demonstrations made by the task generator ([`crate::task`]), in their order, each
    /// with its own labels: channels [`task::CHANNELS`], each demo's own `Δt_s`.
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
            labels: demos.iter().map(|d| d.labels.clone()).collect(),
        };
        inputs.check().map_err(|why| Error::BadInput {
            path: "<generated demonstrations>".into(),
            why,
        })?;
        Ok(inputs)
    }

    /// The ground-truth labels on `model`'s time axis: the labels of the demonstration its
    /// fit chose as the reference ([`reference_labels`]). `model` must be fitted on
    /// [`StudyInputs::demos`] in their order.
    ///
    /// # Errors
    /// As [`reference_labels`].
    pub fn reference_labels(&self, model: &TaskModel) -> Result<Vec<Label>> {
        reference_labels(model, |k| {
            let where_ = PathBuf::from(format!("<labels of demonstration {k}>"));
            match self.labels.get(k) {
                Some(l) => Ok((where_, l.clone())),
                None => Err(Error::BadInput {
                    path: where_,
                    why: format!(
                        "the model's reference is demonstration {k} (counted from 0) but the \
                         study has {} demonstrations: fit the model on the study's own \
                         demonstrations",
                        self.labels.len()
                    ),
                }),
            }
        })
    }

    pub(super) fn check(&self) -> std::result::Result<(), String> {
        if self.demos.len() < 2 {
            return Err(format!(
                "{} demonstrations, need at least 2",
                self.demos.len()
            ));
        }
        if self.labels.len() != self.demos.len() {
            return Err(format!(
                "labels for {} of the {} demonstrations: every demonstration needs its own",
                self.labels.len(),
                self.demos.len()
            ));
        }
        for (i, (demo, labels)) in self.demos.iter().zip(&self.labels).enumerate() {
            if labels.len() != demo.n_samples() {
                return Err(format!(
                    "{} labels for the {} samples of demonstration {i}",
                    labels.len(),
                    demo.n_samples()
                ));
            }
        }
        Ok(())
    }
}

/// The ground-truth labels on `model`'s time axis, one per reference sample: those of the
/// demonstration its fit chose as the reference ([`TaskModel::reference_idx`], counted from 0
/// in the order the demonstrations were given to the fit). `labels_of(k)` gives demonstration
/// `k`'s labels and where they came from (a file, or a description), for the error.
///
/// Every demonstration of the sanding task has its own labels (the fixtures'
/// `demo_<i>.labels.csv`, the generator's [`task::TaskDemo::labels`]), so every reference
/// choice has its exact truth: nothing is mapped through a fitted warp, which would shift
/// the boundaries of the needed sections by the alignment's error. This is the one place the
/// study, the zoo's sanding row and Python's `tandem.sim.sanding_needs` choose the labels.
///
/// # Errors
/// `labels_of`'s error, or [`Error::BadInput`] naming where the labels came from when they
/// are not one per reference sample (labels of another demonstration than the reference).
pub fn reference_labels(
    model: &TaskModel,
    labels_of: impl FnOnce(usize) -> Result<(PathBuf, Vec<Label>)>,
) -> Result<Vec<Label>> {
    let k = model.reference_idx();
    let (path, labels) = labels_of(k)?;
    if labels.len() != model.n_ref() {
        return Err(Error::BadInput {
            path,
            why: format!(
                "{} labels, but the model's reference (demonstration {k} of the fit, counted \
                 from 0) has {} samples: give that demonstration's labels (the fit's default \
                 reference is the medoid, which need not be the first file)",
                labels.len(),
                model.n_ref()
            ),
        });
    }
    Ok(labels)
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
