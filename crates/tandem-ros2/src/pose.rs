//! The setpoint as a `geometry_msgs/PoseStamped` (issue 43: "the task model's setpoint as
//! `geometry_msgs/PoseStamped` plus the model's other channels"). A model's channels are named
//! by the user, so which of them form a pose is an option ([`PoseChannels`]): by default the
//! channels named `x`, `y`, `z` (and `qx`, `qy`, `qz`, `qw` when all four exist, in any order
//! in the model) when the model has them. The pose's channels then leave the setpoint's
//! `Float64MultiArray`, which keeps the others.

use crate::error::{Error, Result};
use crate::msg::{Header, Point, Pose, PoseStamped, Quaternion, Time};

/// Which of the model's channels the node publishes as a pose (`/tandem/robotK/setpoint_pose`).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum PoseChannels {
    /// The channels named `x`, `y`, `z` (position, m) and, when the model has all four,
    /// `qx`, `qy`, `qz`, `qw` (orientation); no pose when the model lacks one of `x`, `y`, `z`.
    #[default]
    Auto,
    /// No pose topic: every channel in the setpoint's `Float64MultiArray`.
    Off,
    /// The named channels: three (position; the orientation is the identity) or seven
    /// (position, then the orientation's `x`, `y`, `z`, `w`).
    Named(Vec<String>),
}

/// The channels of a pose, by index into the model's channels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PoseMap {
    /// Position `x`, `y`, `z`.
    pub position: [usize; 3],
    /// Orientation `x`, `y`, `z`, `w`; `None`: the identity.
    pub orientation: Option<[usize; 4]>,
}

impl PoseChannels {
    /// The pose's channels among `channels` (the model's names), or `None` for no pose.
    ///
    /// # Errors
    /// [`Error::BadParam`] (`pose_channels`) for a named list of another length than 3 or 7, a
    /// name the model does not have (the message lists the model's), or a name given twice.
    pub fn resolve(&self, channels: &[String]) -> Result<Option<PoseMap>> {
        let find = |name: &str| channels.iter().position(|c| c == name);
        match self {
            PoseChannels::Off => Ok(None),
            PoseChannels::Auto => {
                let (Some(x), Some(y), Some(z)) = (find("x"), find("y"), find("z")) else {
                    return Ok(None);
                };
                let orientation = match (find("qx"), find("qy"), find("qz"), find("qw")) {
                    (Some(a), Some(b), Some(c), Some(d)) => Some([a, b, c, d]),
                    _ => None,
                };
                Ok(Some(PoseMap {
                    position: [x, y, z],
                    orientation,
                }))
            }
            PoseChannels::Named(names) => {
                let bad = |why: String| {
                    Err(Error::BadParam {
                        name: "pose_channels",
                        why,
                    })
                };
                if names.len() != 3 && names.len() != 7 {
                    return bad(format!(
                        "names {} channels; give 3 (x,y,z) or 7 (x,y,z,qx,qy,qz,qw)",
                        names.len()
                    ));
                }
                let mut idx = Vec::with_capacity(names.len());
                for (i, n) in names.iter().enumerate() {
                    if names[..i].contains(n) {
                        return bad(format!("names channel `{n}` twice; each once"));
                    }
                    match find(n) {
                        Some(k) => idx.push(k),
                        None => {
                            return bad(format!(
                                "names `{n}`, which the model has not; its channels are {}",
                                channels.join(",")
                            ));
                        }
                    }
                }
                Ok(Some(PoseMap {
                    position: [idx[0], idx[1], idx[2]],
                    orientation: (idx.len() == 7).then(|| [idx[3], idx[4], idx[5], idx[6]]),
                }))
            }
        }
    }
}

impl PoseMap {
    /// Whether channel `k` is one of the pose's.
    #[must_use]
    pub fn contains(&self, k: usize) -> bool {
        self.position.contains(&k) || self.orientation.is_some_and(|o| o.contains(&k))
    }

    /// The pose of a setpoint `values` (the model's channels) in `frame_id` at `stamp`. The
    /// orientation is normalized (the model's mean of quaternions is not a unit one); a zero
    /// or non-finite quaternion is the identity.
    #[must_use]
    pub fn pose(&self, values: &[f64], frame_id: &str, stamp: Time) -> PoseStamped {
        let v = |k: usize| values.get(k).copied().unwrap_or(0.0);
        let [x, y, z] = self.position.map(v);
        let orientation = self
            .orientation
            .map(|q| q.map(v))
            .and_then(|[qx, qy, qz, qw]| {
                let norm = (qx * qx + qy * qy + qz * qz + qw * qw).sqrt();
                (norm.is_finite() && norm > 1e-12).then(|| Quaternion {
                    x: qx / norm,
                    y: qy / norm,
                    z: qz / norm,
                    w: qw / norm,
                })
            })
            .unwrap_or_default();
        PoseStamped {
            header: Header {
                stamp,
                frame_id: frame_id.to_owned(),
            },
            pose: Pose {
                position: Point { x, y, z },
                orientation,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(s: &str) -> Vec<String> {
        s.split(',').map(str::to_owned).collect()
    }

    #[test]
    fn auto_finds_position_and_orientation_in_any_order() {
        let ch = names("force,qw,x,qx,y,qy,z,qz");
        let m = PoseChannels::Auto.resolve(&ch).unwrap().unwrap();
        assert_eq!(m.position, [2, 4, 6]);
        assert_eq!(m.orientation, Some([3, 5, 7, 1]));
        assert!(!m.contains(0) && (1..8).all(|k| m.contains(k)));
        // Position only; no pose without all of x, y, z.
        let m = PoseChannels::Auto
            .resolve(&names("x,y,z,qw"))
            .unwrap()
            .unwrap();
        assert_eq!(m.orientation, None);
        assert_eq!(
            PoseChannels::Auto.resolve(&names("x,y,force")).unwrap(),
            None
        );
        assert_eq!(PoseChannels::Off.resolve(&ch).unwrap(), None);
    }

    #[test]
    fn named_channels_are_checked() {
        let ch = names("a,b,c,force");
        let m = PoseChannels::Named(names("c,b,a")).resolve(&ch).unwrap();
        assert_eq!(m.unwrap().position, [2, 1, 0]);
        let e = PoseChannels::Named(names("a,b,d"))
            .resolve(&ch)
            .unwrap_err();
        assert!(
            e.to_string().contains("`d`") && e.to_string().contains("a,b,c,force"),
            "{e}"
        );
        let e = PoseChannels::Named(names("a,b")).resolve(&ch).unwrap_err();
        assert!(e.to_string().contains("give 3"), "{e}");
        let e = PoseChannels::Named(names("a,a,b"))
            .resolve(&ch)
            .unwrap_err();
        assert!(e.to_string().contains("twice"), "{e}");
    }

    #[test]
    fn the_pose_is_normalized() {
        let m = PoseMap {
            position: [0, 1, 2],
            orientation: Some([3, 4, 5, 6]),
        };
        let p = m.pose(
            &[1.0, 2.0, 3.0, 0.0, 0.0, 1.2, 1.6],
            "world",
            Time::default(),
        );
        assert_eq!(p.header.frame_id, "world");
        assert_eq!(
            (p.pose.position.x, p.pose.position.y, p.pose.position.z),
            (1.0, 2.0, 3.0)
        );
        let q = p.pose.orientation;
        assert!((q.z - 0.6).abs() < 1e-12 && (q.w - 0.8).abs() < 1e-12 && q.x == 0.0);
        let p = m.pose(&[0.0; 7], "w", Time::default());
        assert_eq!(p.pose.orientation, Quaternion::default());
    }
}
