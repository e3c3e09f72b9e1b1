//! `tandem.read_bag`: a ROS 2 bag (rosbag2 MCAP) on one grid, as `tandem fit` reads it
//! (`tandem_bag::read_bag`).

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::arrays::{out_matrix, out_vector};
use crate::errors::guard;
use crate::facade::{BagOptions, read_bag as read};

/// Reads a ROS 2 bag (rosbag2 MCAP file) onto one grid, exactly as ``tandem fit`` and
/// :func:`fit` read it: the selected topics (default: every topic of a supported type:
/// ``geometry_msgs/msg/PoseStamped``, ``WrenchStamped``, ``TwistStamped``,
/// ``sensor_msgs/msg/JointState``, ``std_msgs/msg/Float64``, ``Bool``) resampled from their
/// own rates onto one grid (linear interpolation, slerp for orientations, flags held), times
/// from the header stamps (log times without a header).
///
/// Args:
///     path: the ``.mcap`` file.
///     topics: topic names to read (full names, e.g. ``["/pose", "/wrench"]``), in channel
///         order; ``None``: every topic of a supported type.
///     rate: grid rate in Hz; ``None``: the slowest selected topic's median message rate.
///     namespace: read only the topics under it (``"/robot_1"``), channels named relative to it.
///
/// Returns:
///     A dict: ``samples`` (float array ``(T, C)``, channel units), ``channels`` (``C`` names,
///     ``<topic>.<field>``: e.g. ``pose.x … pose.qw``, ``wrench.fz``, a Float64 or Bool topic by
///     its name), ``t`` (``(T,)`` bag time of every sample, s), ``dt_s`` (grid period, s),
///     ``topics`` (one dict per topic read: ``topic``, ``type``, ``messages``, ``channels``,
///     ``median_period_s``, ``log_time``) and ``quaternions`` (``[(block, [qx, qy, qz, qw])]``,
///     the orientation channels :func:`fit` averages on the rotation manifold).
///
/// Raises:
///     InputError: the file is not MCAP, is truncated or corrupt, or a topic is missing, of an
///         unknown type, without schema or messages, has a bad value, times that do not
///         increase, a gap or a late start; ``file`` is the bag, the message names topic and
///         message.
///     ParamError: a bad ``rate`` or ``topics``.
#[pyfunction]
#[pyo3(signature = (path, topics=None, rate=None, namespace=None))]
pub(crate) fn read_bag<'py>(
    py: Python<'py>,
    path: PathBuf,
    topics: Option<Vec<String>>,
    rate: Option<f64>,
    namespace: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let options = BagOptions {
        topics,
        rate_hz: rate,
        namespace,
    };
    let rec = py.detach(|| guard(|| Ok(read(&path, &options)?)))?;
    let d = PyDict::new(py);
    let n = rec.n_samples();
    let m = rec.channel_names.len();
    let t: Vec<f64> = (0..n).map(|k| rec.start_s + k as f64 * rec.dt_s).collect();
    d.set_item(
        "samples",
        out_matrix(py, rec.samples.clone(), m).map_err(PyErr::from)?,
    )?;
    d.set_item("channels", rec.channel_names.clone())?;
    d.set_item("t", out_vector(py, t))?;
    d.set_item("dt_s", rec.dt_s)?;
    let topics = PyList::empty(py);
    for info in &rec.topics {
        let td = PyDict::new(py);
        td.set_item("topic", &info.topic)?;
        td.set_item("type", &info.schema)?;
        td.set_item("messages", info.messages)?;
        td.set_item("channels", &info.channels)?;
        td.set_item("median_period_s", info.median_period_s)?;
        td.set_item("log_time", info.log_time)?;
        topics.append(td)?;
    }
    d.set_item("topics", topics)?;
    let blocks: Vec<(String, Vec<String>)> = rec
        .quaternions
        .iter()
        .map(|b| (b.name.clone(), b.channels.to_vec()))
        .collect();
    d.set_item("quaternions", blocks)?;
    Ok(d)
}
