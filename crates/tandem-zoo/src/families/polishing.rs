//! Polishing with a contact-force channel and a pad change (see the crate docs, "polishing").

use rand::Rng;

use crate::Result;
use crate::engine::pose::*;
use crate::engine::{
    Agreed, Channel, Interp::*, Script, Shape, Variation, pick, render, rng_for, seg, to, uniform,
};
use crate::task::ZooTask;

/// The family's name.
pub(crate) const NAME: &str = "polishing";

const FORCE: usize = 7;
const TOOL: usize = 8;

/// Index of stroke 1 (the first contact) and stroke 5 (the part's far edge).
const FIRST_STROKE: usize = 2;
const LAST_STROKE: usize = 12;

/// How unsteady the demonstrator's pace is ([`Script::wobble_scale`]): an ordinary hand (±15 % within a free move).
const WOBBLE: f64 = 0.5;

/// Generates the task for `seed`.
pub(crate) fn generate(seed: u64) -> Result<ZooTask> {
    let mut rng = rng_for(NAME, seed);
    let n_demos = rng.random_range(3..=12);
    let rate_hz = pick(&mut rng, &[100.0, 200.0]);
    let jitter = uniform(&mut rng, 0.0, 0.12);
    let length_var = uniform(&mut rng, 0.05, 0.085);
    let where_ = pick(&mut rng, &["start", "end", "both"]);

    let channels = Channel::pose_then(
        6,
        (0.000_1, 0.000_4),
        (0.000_2, 0.001),
        [Channel::real("force", 3, 0.2, 0.3), Channel::binary("tool")],
    );
    let start = vec![0.0, 0.0, 0.10, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let stroke = |x: f64| seg("stroke", 2.6, 0.08, 0.25, vec![to(X, x, Linear)]);
    let turn = |y: f64, tilt: f64| {
        seg(
            "turn",
            0.6,
            0.1,
            0.2,
            vec![to(Y, y, MinJerk), to(QY, tilt, MinJerk)],
        )
    };
    let segments = vec![
        seg(
            "approach",
            2.0,
            0.08,
            0.3,
            vec![
                to(X, 0.05, MinJerk),
                to(Y, 0.05, MinJerk),
                to(Z, 0.01, MinJerk),
                to(QY, 0.05, MinJerk),
            ],
        ),
        seg(
            "touch down",
            0.8,
            0.1,
            0.2,
            vec![
                to(Z, 0.0, MinJerk),
                to(TOOL, 1.0, Step(0.0)),
                to(FORCE, 15.0, Ease),
            ],
        ),
        stroke(0.35),
        turn(0.08, -0.05),
        stroke(0.05),
        turn(0.11, 0.05),
        stroke(0.35),
        seg(
            "lift for the pad change",
            0.8,
            0.1,
            0.2,
            vec![
                to(TOOL, 0.0, Step(0.0)),
                to(FORCE, 0.0, Ease),
                to(Z, 0.08, MinJerk),
                to(QX, 0.5, MinJerk),
            ],
        ),
        seg("pad change", 2.5, 0.5, 0.0, vec![]),
        seg(
            "touch down again",
            0.8,
            0.1,
            0.2,
            vec![
                to(Y, 0.14, MinJerk),
                to(Z, 0.0, MinJerk),
                to(QX, 0.0, MinJerk),
                to(QY, -0.05, MinJerk),
                to(TOOL, 1.0, Step(0.0)),
                to(FORCE, 15.0, Ease),
            ],
        ),
        stroke(0.05),
        turn(0.17, 0.05),
        stroke(0.35),
        seg(
            "lift and retreat",
            2.0,
            0.08,
            0.3,
            vec![
                to(TOOL, 0.0, Step(0.0)),
                to(FORCE, 0.0, Ease),
                to(X, 0.0, MinJerk),
                to(Y, 0.0, MinJerk),
                to(Z, 0.10, MinJerk),
                to(QY, 0.0, MinJerk),
            ],
        ),
    ];
    let mut variations = Vec::new();
    if where_ != "end" {
        // First contact: how hard the pad bites before the force settles differs part to part.
        variations.push(Variation {
            first: 1,
            last: FIRST_STROKE,
            ramp_s: 0.2,
            need_p: pick(&mut rng, &[0.4, 0.6, 0.8]),
            amps: vec![(FORCE, 6.0), (Z, 0.001)],
            shape: Shape::Wavy { cycles: 1.5 },
        });
    }
    if where_ != "start" {
        // The part's far edge: where it is and how it takes the pad differ.
        variations.push(Variation {
            first: LAST_STROKE,
            last: LAST_STROKE,
            ramp_s: 0.2,
            need_p: pick(&mut rng, &[0.6, 0.8, 1.0]),
            amps: vec![(FORCE, 6.0), (Y, 0.02)],
            shape: Shape::Offset,
        });
    }
    // A fragile feature (a label, a thin wall) in the middle of stroke 3: every
    // demonstration polished it the same way, but it needs watching.
    let agreed = vec![Agreed {
        seg: 6,
        from_u: 0.4,
        to_u: 0.7,
        p: 0.3,
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
        agreed,
        holds: vec!["tool<0.5".into()],
        n_demos,
        rate_hz,
        jitter,
        length_var,
        wobble_scale: WOBBLE,
    };
    render(&script, &mut rng)
}
