//! The tangent layout: which channels are scalars and which form quaternion blocks, the
//! coordinate names, and everything that reads a demonstration through the layout
//! (ranges, alignment weights, sign-aligned signals, orientations at fractional times).

use serde::{Deserialize, Serialize};

use super::bracket;
use crate::demo::{ChannelSchema, Demonstration};
use crate::quat::{self, Quat};
use crate::{Error, Result};

/// One item of the tangent layout.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub(super) enum Item {
    /// A scalar channel (its column).
    Scalar(usize),
    /// A quaternion block (columns of x, y, z, w; index among the model's blocks).
    Quat([usize; 4], usize),
}

/// The tangent layout of a channel set: items in column order, coordinate names (rate
/// last) and the number of quaternion blocks.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub(super) struct Layout {
    pub(super) items: Vec<Item>,
    pub(super) names: Vec<String>,
    pub(super) n_quat: usize,
}

/// Name of the derived rate coordinate (the warp gradient `ψ̇`), last in every layout.
const RATE: &str = "rate";

impl Layout {
    /// The layout of `demo`'s channels under `schema`: scalars in column order, each
    /// complete quaternion block at the position of its first channel, the rate last.
    ///
    /// Errors name `demo`'s source: a block with some but not all of its channels, or a
    /// channel named like a derived coordinate.
    pub(super) fn new(demo: &Demonstration, schema: &ChannelSchema) -> Result<Self> {
        let channels = demo.channel_names();
        let mut in_block = vec![None; channels.len()];
        let mut blocks = Vec::new();
        for block in &schema.quaternions {
            let cols = block.channels.clone().map(|c| demo.channel_index(&c));
            let (present, missing): (Vec<_>, Vec<_>) =
                (0..4).partition(|&axis| cols[axis].is_some());
            if present.is_empty() {
                continue;
            }
            if !missing.is_empty() {
                let names =
                    |axes: Vec<usize>| axes.iter().map(|&a| block.channels[a].clone()).collect();
                let (line, _) = demo.header_at(None);
                return Err(Error::PartialQuaternionBlock {
                    file: demo.source().into(),
                    line,
                    block: block.name.clone(),
                    present: names(present),
                    missing: names(missing),
                });
            }
            let cols = cols.map(|c| c.expect("every channel of the block is present"));
            for &c in &cols {
                in_block[c] = Some(blocks.len());
            }
            blocks.push((block.name.clone(), cols));
        }
        let derived = |name: &str| -> Option<String> {
            if name == RATE {
                return Some("the warp gradient (speed)".into());
            }
            blocks.iter().find_map(|(block, _)| {
                let axis = name.strip_prefix(block.as_str())?.strip_prefix('.')?;
                ["rx", "ry", "rz"]
                    .contains(&axis)
                    .then(|| format!("a rotation-vector coordinate of quaternion block `{block}`"))
            })
        };
        if let Some(channel) = channels.iter().find(|n| crate::checks::time_like(n)) {
            let (line, column) = demo.header_at(Some(channel));
            return Err(Error::TimeLikeChannel {
                file: demo.source().into(),
                line,
                column,
                channel: channel.clone(),
            });
        }
        if let Some((channel, why)) = channels
            .iter()
            .find_map(|name| derived(name).map(|why| (name, why)))
        {
            let (line, column) = demo.header_at(Some(channel));
            return Err(Error::ReservedChannelName {
                file: demo.source().into(),
                line,
                column,
                channel: channel.clone(),
                derived: why,
            });
        }
        let mut items = Vec::new();
        let mut names = Vec::new();
        let mut emitted = vec![false; blocks.len()];
        for (j, name) in channels.iter().enumerate() {
            match in_block[j] {
                None => {
                    items.push(Item::Scalar(j));
                    names.push(name.clone());
                }
                Some(b) if !emitted[b] => {
                    emitted[b] = true;
                    items.push(Item::Quat(blocks[b].1, b));
                    for axis in ["rx", "ry", "rz"] {
                        names.push(format!("{}.{axis}", blocks[b].0));
                    }
                }
                Some(_) => {}
            }
        }
        names.push(RATE.into());
        Ok(Self {
            items,
            names,
            n_quat: blocks.len(),
        })
    }

    /// Tangent dimension `d` including the rate.
    pub(super) fn dim(&self) -> usize {
        self.names.len()
    }

    /// Whether every item refers to a column below `m` and a block below `n_quat`.
    pub(super) fn fits(&self, m: usize) -> bool {
        self.items.iter().all(|it| match it {
            Item::Scalar(j) => *j < m,
            Item::Quat(cols, b) => cols.iter().all(|c| *c < m) && *b < self.n_quat,
        })
    }

    /// Rejects a demonstration with a (near-)zero quaternion in any block.
    pub(super) fn check_quaternion_norms(&self, demo: &Demonstration) -> Result<()> {
        for item in &self.items {
            if let Item::Quat(cols, _) = item {
                for t in 0..demo.n_samples() {
                    let s = demo.sample(t);
                    let q = cols.map(|c| s[c]);
                    if quat::norm(&q) < 1e-6 {
                        let names = cols.map(|c| demo.channel_names()[c].as_str());
                        return Err(Error::BadData {
                            what: demo.locate(t),
                            why: format!(
                                "quaternion block ({}) has norm {:e} (≈ 0), which is no \
                                 orientation: check the export of these columns",
                                names.join(", "),
                                quat::norm(&q)
                            ),
                        });
                    }
                }
            }
        }
        Ok(())
    }

    /// The first orientation of `demo` in each quaternion block, normalized.
    pub(super) fn first_orientations(&self, demo: &Demonstration) -> Vec<Quat> {
        self.items
            .iter()
            .filter_map(|it| match it {
                Item::Quat(cols, _) => Some(quat::normalize(&cols.map(|c| demo.sample(0)[c]))),
                Item::Scalar(_) => None,
            })
            .collect()
    }

    /// Default ranges of the non-rate tangent coordinates (`d − 1` values, see
    /// [`FitParams::ranges`](super::FitParams::ranges)) over every sample of `demos`; the
    /// first orientation of `reference` is the origin of the quaternion blocks' rotation
    /// vectors. The result does not depend on the order of `demos`.
    pub(super) fn channel_ranges(
        &self,
        reference: &Demonstration,
        demos: &[Demonstration],
        min_range: f64,
    ) -> Vec<f64> {
        let mut ranges = Vec::with_capacity(self.dim());
        let guard = |r: f64| {
            if r < min_range || !r.is_finite() {
                1.0
            } else {
                r
            }
        };
        for item in &self.items {
            match item {
                Item::Scalar(j) => {
                    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
                    for demo in demos {
                        for t in 0..demo.n_samples() {
                            let v = demo.sample(t)[*j];
                            lo = lo.min(v);
                            hi = hi.max(v);
                        }
                    }
                    ranges.push(guard(hi - lo));
                }
                Item::Quat(cols, _) => {
                    let origin = quat::normalize(&cols.map(|c| reference.sample(0)[c]));
                    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
                    for demo in demos {
                        for t in 0..demo.n_samples() {
                            let q = quat::normalize(&cols.map(|c| demo.sample(t)[c]));
                            let r = quat::log_relative(&origin, &q);
                            for axis in 0..3 {
                                lo[axis] = lo[axis].min(r[axis]);
                                hi[axis] = hi[axis].max(r[axis]);
                            }
                        }
                    }
                    let r = (0..3).map(|axis| hi[axis] - lo[axis]).fold(0.0, f64::max);
                    ranges.extend([guard(r); 3]);
                }
            }
        }
        ranges
    }

    /// Alignment weights per channel (`m` values) derived from the non-rate ranges.
    pub(super) fn warp_weights(&self, ranges: &[f64], m: usize) -> Vec<f64> {
        let mut w = vec![0.0; m];
        let mut coord = 0;
        for item in &self.items {
            match item {
                Item::Scalar(j) => {
                    w[*j] = 1.0 / (ranges[coord] * ranges[coord]);
                    coord += 1;
                }
                Item::Quat(cols, _) => {
                    let r = ranges[coord..coord + 3].iter().copied().fold(0.0, f64::max);
                    for &c in cols {
                        w[c] = 4.0 / (r * r);
                    }
                    coord += 3;
                }
            }
        }
        w
    }

    /// A copy of the samples with every quaternion block sign-continuous in time and in the
    /// hemisphere of `reference_orientations` (the reference's first orientation per block),
    /// for alignment.
    pub(super) fn sign_aligned(
        &self,
        demo: &Demonstration,
        reference_orientations: &[Quat],
    ) -> Vec<f64> {
        let m = demo.n_channels();
        let mut data = demo.samples().to_vec();
        for item in &self.items {
            if let Item::Quat(cols, blk) = item {
                let mut prev = reference_orientations[*blk];
                for row in data.chunks_exact_mut(m) {
                    let q = cols.map(|c| row[c]);
                    if quat::dot(&q, &prev) < 0.0 {
                        for &c in cols {
                            row[c] = -row[c];
                        }
                    }
                    prev = cols.map(|c| row[c]);
                }
            }
        }
        data
    }
}

impl Demonstration {
    /// Names of the `d` tangent coordinates of a model fitted on demonstrations with this
    /// one first (the model's channel order is the first demonstration's), under `schema`:
    /// scalar channels by name in column order, each quaternion block as
    /// `<block>.rx/.ry/.rz` at the position of its first channel, then `rate` (the warp
    /// gradient). [`crate::TaskModel::tangent_names`] of the fitted model returns the same
    /// list; [`crate::FitParams::ranges`] is indexed by it.
    ///
    /// # Errors
    /// [`Error::PartialQuaternionBlock`] for a block of `schema` with some but not all of
    /// its four channels; [`Error::ReservedChannelName`] for a channel named `rate`, or
    /// `<block>.rx|ry|rz` of a block that is present. Both name this demonstration's source.
    pub fn tangent_names(&self, schema: &ChannelSchema) -> Result<Vec<String>> {
        Ok(Layout::new(self, schema)?.names)
    }
}

/// Quaternion of block `cols` at fractional demo time `demo_t` (nlerp between neighbours).
pub(super) fn quat_at(demo: &Demonstration, cols: &[usize; 4], demo_t: f64) -> Quat {
    let (lo, hi, alpha) = bracket(demo_t, demo.n_samples());
    let a = quat::normalize(&cols.map(|c| demo.sample(lo)[c]));
    if alpha == 0.0 {
        return a;
    }
    let b = quat::normalize(&cols.map(|c| demo.sample(hi)[c]));
    quat::nlerp(&a, &b, alpha)
}
