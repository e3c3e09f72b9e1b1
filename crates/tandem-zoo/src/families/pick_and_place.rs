//! Pick-and-place with gripper steps and pauses of independent length (see the crate docs,
//! "pick_and_place").

use rand::Rng;

use crate::Result;
use crate::engine::pose::*;
use crate::engine::{
    Channel, Interp::*, Script, Segment, Shape, Variation, pick, render, rng_for, seg, to, uniform,
};
use crate::task::ZooTask;

/// The family's name.
pub(crate) const NAME: &str = "pick_and_place";

const GRIPPER: usize = 7;

/// Segments per object.
const PER_OBJECT: usize = 8;

/// How unsteady the demonstrator's pace is ([`Script::wobble_scale`]): a quick, uneven hand (±21 % within a free move).
const WOBBLE: f64 = 0.7;

/// Generates the task for `seed`.
pub(crate) fn generate(seed: u64) -> Result<ZooTask> {
    let mut rng = rng_for(NAME, seed);
    let n_demos = rng.random_range(3..=12);
    let rate_hz = pick(&mut rng, &[50.0, 100.0]);
    let jitter = uniform(&mut rng, 0.0, 0.12);
    let length_var = uniform(&mut rng, 0.05, 0.085);
    // Which of the three objects a person puts down by hand (the others come in a fixture).
    let loose: &[usize] = pick(&mut rng, &[&[0][..], &[0, 2], &[2], &[1]]);

    let channels = Channel::pose_then(
        6,
        (0.000_2, 0.000_5),
        (0.000_5, 0.003),
        [Channel::binary("gripper")],
    );
    let start = vec![0.3, 0.15, 0.2, 0.0, 0.0, 0.0, 0.0, 0.0];
    let mut segments: Vec<Segment> = Vec::new();
    for j in 0..3 {
        let (px, py) = (0.05 + 0.10 * j as f64, 0.30);
        let (qx, qy) = (0.40 + 0.05 * j as f64, 0.05);
        segments.extend([
            seg(
                "reach",
                1.8,
                0.08,
                0.3,
                vec![
                    to(X, px, MinJerk),
                    to(Y, py, MinJerk),
                    to(Z, 0.12, MinJerk),
                    to(QZ, 0.3, MinJerk),
                ],
            ),
            seg("descend", 0.8, 0.1, 0.2, vec![to(Z, 0.02, MinJerk)]),
            seg("grasp", 0.7, 0.6, 0.0, vec![to(GRIPPER, 1.0, Step(0.4))]),
            seg("lift", 0.8, 0.1, 0.2, vec![to(Z, 0.12, MinJerk)]),
            seg(
                "transport",
                2.0,
                0.08,
                0.3,
                vec![
                    to(X, qx, MinJerk),
                    to(Y, qy, MinJerk),
                    to(QZ, 0.0, MinJerk),
                    to(QX, 0.05 * j as f64, MinJerk),
                ],
            ),
            seg("lower", 0.8, 0.1, 0.2, vec![to(Z, 0.03, MinJerk)]),
            seg("release", 0.6, 0.6, 0.0, vec![to(GRIPPER, 0.0, Step(0.3))]),
            seg("retreat", 0.7, 0.1, 0.2, vec![to(Z, 0.12, MinJerk)]),
        ]);
    }
    segments.push(seg(
        "home",
        1.8,
        0.08,
        0.3,
        vec![
            to(X, 0.3, MinJerk),
            to(Y, 0.15, MinJerk),
            to(Z, 0.2, MinJerk),
            to(QX, 0.0, MinJerk),
        ],
    ));
    // A loose object lies elsewhere each time: the reach, the grasp and the lift follow it
    // (±6 cm, ±0.35 rad of yaw).
    let variations = loose
        .iter()
        .map(|&j| Variation {
            first: j * PER_OBJECT,
            last: j * PER_OBJECT + 3,
            ramp_s: 0.3,
            need_p: pick(&mut rng, &[0.2, 0.5, 0.8, 1.0]),
            amps: vec![(X, 0.06), (Y, 0.06), (QZ, 0.35)],
            shape: Shape::Offset,
        })
        .collect();
    let script = Script {
        family: NAME,
        seed,
        channels,
        quat: Some(QX),
        start,
        segments,
        variations,
        features: vec![],
        agreed: vec![],
        holds: vec!["gripper<0.5".into()],
        n_demos,
        rate_hz,
        jitter,
        length_var,
        wobble_scale: WOBBLE,
    };
    render(&script, &mut rng)
}
