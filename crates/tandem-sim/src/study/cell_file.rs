//! The cell file of a study with different tasks on different robots (issue 45,
//! `cargo xtask study --cell-file`; the format is in docs/formats.md, "Cell file"): each
//! task's name, demonstrations, robots, hold rules and the ground truth of the simulated
//! operator. [`CellFile::tasks`] fits every task and gives the study's [`MixedTask`]s.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use tandem_lfd::{Demonstration, HoldRule, TaskModel};

use super::config::StudyConfig;
use super::inputs::StudyInputs;
use super::mixed::MixedTask;
use crate::needs::NeedProfile;
use crate::truth::{ProfileTruth, SandingTruth, TaskTruth};
use crate::{Error, Result};

/// A cell file: the tasks of the cell, in the cell's order (the robots are numbered task by
/// task, the first task's first).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellFile {
    /// The tasks (`[[task]]` tables), at least one.
    pub task: Vec<CellFileTask>,
}

/// One `[[task]]` of a cell file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellFileTask {
    /// The task's name (letters, digits, `_`, `-`; unique in the cell).
    pub name: String,
    /// Folder of its demonstrations `demo_0.csv`, `demo_1.csv`, … (until the first missing
    /// index), relative to the cell file.
    pub demos: PathBuf,
    /// How many robots do it (≥ 1).
    pub robots: usize,
    /// Its hold rules (`CHANNEL<VALUE`, as `[planner.holds] rules`). In a cell of two or
    /// more tasks the continuous cell waits at their usable holds; the rounds placement does
    /// not wait at them. Default: none.
    #[serde(default)]
    pub holds: Vec<String>,
    /// Where its workpieces need the simulated operator.
    pub truth: CellTruth,
}

/// The ground truth of a task of a cell file (`truth = { kind = "labels" }` or
/// `truth = { kind = "need", file = "…", channel = "…" }`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum CellTruth {
    /// The sanding task's: every demonstration's `demo_<i>.labels.csv` beside it; the truth
    /// is the labels of the fit's reference ([`SandingTruth`], the study's own truth).
    Labels,
    /// A need file (docs/formats.md, "Need file": one row per reference sample of the task's
    /// fit with the study's parameters), relative to the cell file, and the channel whose
    /// increase the operator's corrections aim at ([`ProfileTruth`]).
    Need {
        /// The need file.
        file: PathBuf,
        /// The correction channel (a channel of the task's demonstrations).
        channel: String,
    },
}

impl CellFile {
    /// Robots of the cell (every task's together).
    #[must_use]
    pub fn n_robots(&self) -> usize {
        self.task.iter().map(|t| t.robots).sum()
    }

    /// Fits every task with `config`'s planner parameters and the task's hold rules, and
    /// reads its truth; paths are relative to `dir` (the cell file's folder).
    ///
    /// # Errors
    /// [`Error::BadInput`] naming the task and file for no task, missing or too few
    /// demonstrations, a bad hold rule, an unreadable need file; the model crate's errors
    /// for a bad demonstration or fit; [`Error::Need`] for a need file that does not fit the
    /// task's reference.
    pub fn tasks(&self, dir: &Path, config: &StudyConfig) -> Result<Vec<MixedTask>> {
        if self.task.is_empty() {
            return Err(Error::BadInput {
                path: dir.to_path_buf(),
                why: "a cell file with no [[task]]: give at least one".into(),
            });
        }
        self.task.iter().map(|t| t.fit(dir, config)).collect()
    }
}

impl CellFileTask {
    /// The params of this task: `config`'s with its hold rules.
    fn params(&self, dir: &Path, config: &StudyConfig) -> Result<tandem_planner::PlannerParams> {
        let mut params = config.planner_params();
        params.holds.at_s.clear();
        params.holds.rules = self
            .holds
            .iter()
            .map(|r| {
                r.parse::<HoldRule>().map_err(|e| Error::BadInput {
                    path: dir.to_path_buf(),
                    why: format!("task `{}`: hold rule `{r}`: {e}", self.name),
                })
            })
            .collect::<Result<_>>()?;
        Ok(params)
    }

    /// Fits the task and reads its truth (see [`CellFile::tasks`]).
    fn fit(&self, dir: &Path, config: &StudyConfig) -> Result<MixedTask> {
        let params = self.params(dir, config)?;
        let demos_dir = dir.join(&self.demos);
        let in_task = |e: Error| Error::BadInput {
            path: demos_dir.clone(),
            why: format!("task `{}`: {e}", self.name),
        };
        let (model, truth): (TaskModel, Box<dyn TaskTruth>) = match &self.truth {
            CellTruth::Labels => {
                let inputs = StudyInputs::from_dir(&demos_dir).map_err(in_task)?;
                let model = TaskModel::fit(&inputs.demos, &params.fit)?;
                let labels = inputs.reference_labels(&model).map_err(in_task)?;
                (
                    model,
                    Box::new(SandingTruth::new(labels, config.task.clone())),
                )
            }
            CellTruth::Need { file, channel } => {
                let demos = read_demos(&demos_dir).map_err(in_task)?;
                let model = TaskModel::fit(&demos, &params.fit)?;
                let path = dir.join(file);
                let text = std::fs::read_to_string(&path).map_err(|e| Error::BadInput {
                    path: path.clone(),
                    why: format!("task `{}`: need file: {e}", self.name),
                })?;
                let profile =
                    NeedProfile::parse_csv(&text, &path.display().to_string(), model.n_ref())?;
                if !model.tangent_names().iter().any(|n| n == channel) {
                    return Err(Error::BadInput {
                        path,
                        why: format!(
                            "task `{}`: correction channel `{channel}` is not one of the \
                             model's {:?}: name one of them",
                            self.name,
                            model.tangent_names()
                        ),
                    });
                }
                (
                    model,
                    Box::new(ProfileTruth::new(profile, channel.clone())?),
                )
            }
        };
        model.prepare_corrections();
        Ok(MixedTask {
            name: self.name.clone(),
            model,
            params,
            truth,
            robots: self.robots,
        })
    }
}

/// Reads `demo_0.csv`, `demo_1.csv`, … from `dir` until the first missing index.
///
/// # Errors
/// [`Error::BadInput`] for fewer than two; the model crate's error for a bad file.
fn read_demos(dir: &Path) -> Result<Vec<Demonstration>> {
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
    Ok(demos)
}
