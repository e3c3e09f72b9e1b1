//! Format 12: a cell of two or more tasks ([`crate::CellPlanner`], issue 45).
//!
//! | bytes | content |
//! |---|---|
//! | 0..24 | the header of every version ([`super`]), version [`super::CELL_FORMAT_VERSION`] |
//! | 24.. | postcard of [`CellPayload`], using every byte |
//!
//! Each task's state is its complete format 11 payload ([`super::v11::Payload`], then its
//! parameters stored by name, [`super::Extras`]) nested as bytes: every rule of format 11 (the
//! wire types, the parameters added later, the checks on load) applies to each task
//! unchanged, and a task's bytes are exactly those its planner would write after a format 11
//! header. A one-task cell is never written in this format (it is its planner's format 11
//! file), so a format 12 file holds at least two tasks.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::{Extras, PlannerState, decode_task_payload, payload_bytes, v11};
use crate::{Error, Result};

/// The payload of a format 12 state file: the cell's tasks, its robots, its parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CellPayload {
    /// The tasks, in the cell's order (at least two).
    pub tasks: Vec<TaskPayload>,
    /// Robot `i` does task `robot_task[i]` (an index into `tasks`); every task has a robot.
    pub robot_task: Vec<u32>,
    /// Parameters of the cell added after format 12, stored by name (none yet): the same
    /// mechanism as format 11's ([`super::extras`]).
    pub extras: Extras,
}

/// One task of a [`CellPayload`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TaskPayload {
    /// The task's name (letters, digits, `_`, `-`; unique in the cell).
    pub name: String,
    /// The task's planner as a format 11 payload: postcard of [`v11::Payload`], then, only
    /// when there is any, postcard of its [`Extras`].
    pub state: Vec<u8>,
}

impl TaskPayload {
    /// The task named `name` holding the planner state `state`.
    ///
    /// # Errors
    /// [`Error::Encode`], or the conversion's error for a parameter stored by name.
    pub(crate) fn from_state(name: &str, state: &PlannerState) -> Result<Self> {
        let (payload, extras) = v11::Payload::from_state(state)?;
        Ok(TaskPayload {
            name: name.to_string(),
            state: payload_bytes(&payload, &extras)?,
        })
    }

    /// The planner state of this task, read from the file at `path` (for error messages).
    ///
    /// # Errors
    /// [`Error::Corrupt`] naming `path` and the task when its bytes do not decode or do not
    /// convert into the library's types.
    pub(crate) fn into_state(self, path: &Path) -> Result<PlannerState> {
        let corrupt = |why: String| Error::Corrupt {
            path: path.to_path_buf(),
            why: format!("task `{}`: {why}", self.name),
        };
        let (payload, extras) =
            decode_task_payload(&self.state, path).map_err(|e| corrupt(e.to_string()))?;
        payload
            .into_state(extras)
            .map_err(|e| corrupt(e.to_string()))
    }

    /// The wire form of this task's planner ([`v11::Payload`] and its parameters by name).
    ///
    /// # Errors
    /// [`Error::Corrupt`] naming `path` when the bytes do not decode.
    pub fn payload(&self, path: &Path) -> Result<(v11::Payload, Extras)> {
        decode_task_payload(&self.state, path)
    }
}
