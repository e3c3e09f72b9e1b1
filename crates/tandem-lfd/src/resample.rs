//! The one resampling policy (docs/decisions.md, "One resampling policy"): how a value
//! between two recorded samples is made when a log is put onto a grid. CSV logs
//! ([`crate::Demonstration::regrid_csv_str`]), executions finer than the model
//! ([`crate::TaskModel::resample_execution`]) and ROS 2 bags (tandem-bag) all use
//! [`Interpolation`], so one recording gives the same samples in every format:
//! - a quaternion block (four columns `x, y, z, w`): slerp on the shorter arc, normalized, in
//!   the earlier sample's hemisphere;
//! - a flag (a channel whose every value is 0 or 1: a valve, a tool switch): held, the
//!   earlier sample's value until the later sample's time;
//! - every other channel: linear.
//!
//! A grid time within [`SNAP`] of a sample (as a fraction of the step between the two
//! samples) takes that sample's values unchanged, so a log already on the grid is copied bit
//! for bit (a quaternion is not renormalized, a value not perturbed by rounding).

use crate::demo::ChannelSchema;
use crate::error::{Error, Result};
use crate::quat;

/// A grid time whose fraction of the way between two samples is within this of 0 or 1
/// takes the nearer sample's values as they are: 1e-9.
pub const SNAP: f64 = 1e-9;

/// How the columns of one table are interpolated between two of its rows ([module
/// docs](self)).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Interpolation {
    /// Per column: held (a flag).
    held: Vec<bool>,
    /// Per column: in a quaternion block (interpolated by [`quat_blocks`](Self::quat_blocks)).
    in_quat: Vec<bool>,
    /// The quaternion blocks: the columns of `x, y, z, w`.
    quats: Vec<[usize; 4]>,
}

/// Whether a channel with these values is a flag: every value is 0 or 1.
pub fn is_flag(values: impl IntoIterator<Item = f64>) -> bool {
    values.into_iter().all(|x| x == 0.0 || x == 1.0)
}

impl Interpolation {
    /// `width` columns: the quaternion blocks `quats` (columns of `x, y, z, w`) slerped, the
    /// columns `flags` held, the others linear.
    ///
    /// # Errors
    /// [`Error::BadParam`] for a column `≥ width`, a column in two blocks, or a column both a
    /// flag and in a block.
    pub fn new(width: usize, flags: &[usize], quats: &[[usize; 4]]) -> Result<Interpolation> {
        let bad = |why: String| {
            Err(Error::BadParam {
                name: "interpolation",
                why,
            })
        };
        let mut held = vec![false; width];
        let mut in_quat = vec![false; width];
        for block in quats {
            for &c in block {
                if c >= width {
                    return bad(format!("quaternion column {c} of {width} columns"));
                }
                if std::mem::replace(&mut in_quat[c], true) {
                    return bad(format!("column {c} is in two quaternion blocks"));
                }
            }
        }
        for &c in flags {
            if c >= width {
                return bad(format!("flag column {c} of {width} columns"));
            }
            if in_quat[c] {
                return bad(format!(
                    "column {c} is both a flag and in a quaternion block"
                ));
            }
            held[c] = true;
        }
        Ok(Interpolation {
            held,
            in_quat,
            quats: quats.to_vec(),
        })
    }

    /// The policy for channels `names` under `schema`: each quaternion block of the schema
    /// whose four channels are all present is slerped (a partial block is linear here; the
    /// fit refuses it), each other channel for which `flag(column)` holds (use [`is_flag`] on
    /// its values) is held, the rest are linear.
    pub fn for_channels(
        names: &[String],
        schema: &ChannelSchema,
        flag: impl Fn(usize) -> bool,
    ) -> Interpolation {
        let col = |name: &String| names.iter().position(|n| n == name);
        let mut quats: Vec<[usize; 4]> = Vec::new();
        for block in &schema.quaternions {
            let cols = block.channels.clone().map(|c| col(&c));
            if let [Some(x), Some(y), Some(z), Some(w)] = cols {
                let b = [x, y, z, w];
                if !b.iter().any(|c| quats.iter().flatten().any(|d| d == c)) {
                    quats.push(b);
                }
            }
        }
        let in_quat = |c: usize| quats.iter().flatten().any(|&d| d == c);
        let flags: Vec<usize> = (0..names.len())
            .filter(|&c| !in_quat(c) && flag(c))
            .collect();
        Interpolation::new(names.len(), &flags, &quats).expect("columns checked above")
    }

    /// Number of columns.
    pub fn width(&self) -> usize {
        self.held.len()
    }

    /// The quaternion blocks (columns of `x, y, z, w`).
    pub fn quat_blocks(&self) -> &[[usize; 4]] {
        &self.quats
    }

    /// Whether column `c` is held (a flag).
    pub fn is_held(&self, c: usize) -> bool {
        self.held.get(c).copied().unwrap_or(false)
    }

    /// Writes into `out` the row a fraction `u ∈ [0, 1]` of the way from row `a` (`u = 0`) to
    /// row `b` (`u = 1`), all three [`width`](Self::width) long: `a` itself for `u ≤ SNAP`,
    /// `b` itself for `u ≥ 1 − SNAP`, else linear, held (`a`'s value) and slerped columns as
    /// the policy says.
    ///
    /// # Panics
    /// If a row is not [`width`](Self::width) long (a caller's bug, not input).
    pub fn row(&self, a: &[f64], b: &[f64], u: f64, out: &mut [f64]) {
        let m = self.width();
        assert!(
            a.len() == m && b.len() == m && out.len() == m,
            "rows of {}, {} and {} values for {m} columns",
            a.len(),
            b.len(),
            out.len()
        );
        if u <= SNAP {
            out.copy_from_slice(a);
            return;
        }
        if u >= 1.0 - SNAP {
            out.copy_from_slice(b);
            return;
        }
        for c in 0..m {
            out[c] = if self.held[c] {
                a[c]
            } else {
                a[c] + u * (b[c] - a[c])
            };
        }
        for cols in &self.quats {
            let q = quat::slerp(&cols.map(|c| a[c]), &cols.map(|c| b[c]), u);
            for (axis, &c) in cols.iter().enumerate() {
                out[c] = q[axis];
            }
        }
        debug_assert!(self.in_quat.len() == m);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_held_slerped_and_snapped_by_hand() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        // Columns: a value, a flag, then identity → 90° about z.
        let p = Interpolation::new(6, &[1], &[[2, 3, 4, 5]]).unwrap();
        let a = [0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
        let b = [10.0, 1.0, 0.0, 0.0, h, h];
        let mut out = [0.0; 6];
        p.row(&a, &b, 0.5, &mut out);
        // Halfway: 5; the flag still 0; 45° about z (sin, cos of 22.5°).
        let (s, c) = (
            std::f64::consts::FRAC_PI_8.sin(),
            std::f64::consts::FRAC_PI_8.cos(),
        );
        assert_eq!(out[..2], [5.0, 0.0]);
        assert!(
            (out[4] - s).abs() < 1e-12 && (out[5] - c).abs() < 1e-12,
            "{out:?}"
        );
        // Linear would give (0.354, 0.854), norm 0.924: the slerp is unit and on the arc.
        // At the later sample the flag has switched; within SNAP of a sample, that sample
        // verbatim (here a quaternion of norm 1.001 stays as it is).
        let b2 = [10.0, 1.0, 0.0, 0.0, 0.0, 1.001];
        p.row(&a, &b2, 1.0 - 1e-12, &mut out);
        assert_eq!(out, b2);
        p.row(&a, &b2, 1e-12, &mut out);
        assert_eq!(out, a);
        // The short arc: b given as −b.
        let mb = [10.0, 1.0, 0.0, 0.0, -h, -h];
        p.row(&a, &mb, 0.5, &mut out);
        assert!(
            (out[4] - s).abs() < 1e-12 && (out[5] - c).abs() < 1e-12,
            "{out:?}"
        );
    }

    #[test]
    fn channels_by_schema_and_flags_by_values() {
        let names: Vec<String> = ["x", "qx", "qy", "qz", "qw", "tool", "force"]
            .map(String::from)
            .into();
        let columns = [
            vec![0.1, 0.2],
            vec![0.0, 0.0],
            vec![0.0, 0.0],
            vec![0.0, 0.0],
            vec![1.0, 1.0],
            vec![0.0, 1.0],
            vec![0.0, 0.5],
        ];
        let p = Interpolation::for_channels(&names, &ChannelSchema::default(), |c| {
            is_flag(columns[c].iter().copied())
        });
        assert_eq!(p.quat_blocks(), [[1, 2, 3, 4]]);
        // The identity quaternion's 0/1 values do not make its channels flags.
        let held: Vec<bool> = (0..7).map(|c| p.is_held(c)).collect();
        assert_eq!(held, [false, false, false, false, false, true, false]);
        assert!(Interpolation::new(3, &[3], &[]).is_err());
        assert!(Interpolation::new(5, &[0], &[[0, 1, 2, 3]]).is_err());
        assert!(Interpolation::new(8, &[], &[[0, 1, 2, 3], [3, 4, 5, 6]]).is_err());
    }
}
