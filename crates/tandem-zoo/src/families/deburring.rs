//! Deburring along an edge with a variable section in the middle (see the crate docs,
//! "deburring").

use rand::Rng;

use crate::Result;
use crate::engine::pose::*;
use crate::engine::{
    Channel, Interp::*, Script, Shape, Variation, pick, render, rng_for, seg, to, uniform,
};
use crate::task::ZooTask;

/// The family's name.
pub(crate) const NAME: &str = "deburring";

const FX: usize = 7;
const FY: usize = 8;
const FZ: usize = 9;
const SPINDLE: usize = 10;

/// How unsteady the demonstrator's pace is ([`Script::wobble_scale`]): a steady, careful pace (±10 % within a free move).
const WOBBLE: f64 = 0.35;

/// Generates the task for `seed`.
pub(crate) fn generate(seed: u64) -> Result<ZooTask> {
    let mut rng = rng_for(NAME, seed);
    let n_demos = rng.random_range(3..=10);
    let rate_hz = pick(&mut rng, &[200.0, 250.0]);
    let jitter = uniform(&mut rng, 0.0, 0.12);
    let length_var = uniform(&mut rng, 0.05, 0.085);
    let need_p = pick(&mut rng, &[0.6, 0.8, 1.0]);
    let shape = pick(&mut rng, &[Shape::Offset, Shape::Wavy { cycles: 2.0 }]);

    let force = |name| Channel::real(name, 3, 0.04, 0.05);
    let channels = Channel::pose_then(
        6,
        (0.000_05, 0.000_2),
        (0.000_3, 0.002),
        [
            force("fx"),
            force("fy"),
            force("fz"),
            Channel::binary("spindle"),
        ],
    );
    let start = vec![0.3, 0.2, 0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let segments = vec![
        seg(
            "approach",
            2.0,
            0.08,
            0.3,
            vec![
                to(X, 0.0, MinJerk),
                to(Y, 0.105, MinJerk),
                to(Z, 0.01, MinJerk),
                to(QX, 0.3, MinJerk),
            ],
        ),
        seg(
            "spindle run-up",
            1.0,
            0.3,
            0.0,
            vec![to(SPINDLE, 1.0, Step(0.1))],
        ),
        seg(
            "engage the edge",
            0.8,
            0.1,
            0.2,
            vec![
                to(Y, 0.1, MinJerk),
                to(FY, -10.0, Ease),
                to(FX, -2.0, Ease),
                to(FZ, -5.0, Ease),
            ],
        ),
        seg("edge, first part", 4.0, 0.08, 0.2, vec![to(X, 0.2, Linear)]),
        seg("burr section", 5.0, 0.1, 0.2, vec![to(X, 0.4, Linear)]),
        seg("edge, last part", 4.0, 0.08, 0.2, vec![to(X, 0.6, Linear)]),
        seg(
            "disengage",
            0.8,
            0.1,
            0.2,
            vec![
                to(Y, 0.12, MinJerk),
                to(FY, 0.0, Ease),
                to(FX, 0.0, Ease),
                to(FZ, 0.0, Ease),
            ],
        ),
        seg(
            "spindle run-down",
            0.8,
            0.4,
            0.0,
            vec![to(SPINDLE, 0.0, Step(0.0))],
        ),
        seg(
            "retreat",
            2.0,
            0.08,
            0.3,
            vec![
                to(X, 0.3, MinJerk),
                to(Y, 0.2, MinJerk),
                to(Z, 0.1, MinJerk),
                to(QX, 0.0, MinJerk),
            ],
        ),
    ];
    // The burr: its height along the middle of the edge differs part to part, so the
    // normal and cutting forces and the tool's give do.
    let variations = vec![Variation {
        first: 4,
        last: 4,
        ramp_s: 0.2,
        need_p,
        amps: vec![(FY, 5.0), (FX, 3.0), (Y, 0.002)],
        shape,
    }];
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
        holds: vec!["spindle<0.5".into()],
        n_demos,
        rate_hz,
        jitter,
        length_var,
        wobble_scale: WOBBLE,
    };
    render(&script, &mut rng)
}
