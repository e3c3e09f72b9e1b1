//! Screw driving with torque spikes at seating (see the crate docs, "screw_driving").

use rand::Rng;

use crate::Result;
use crate::engine::{
    Agreed, Channel, Feature, FeatureKind, Interp::*, Script, Segment, pick, render, rng_for, seg,
    to, uniform,
};
use crate::task::ZooTask;

/// The family's name.
pub(crate) const NAME: &str = "screw_driving";

const X: usize = 0;
const Y: usize = 1;
const Z: usize = 2;
const TORQUE: usize = 3;
const FZ: usize = 4;
const SPINDLE: usize = 5;

/// How unsteady the demonstrator's pace is ([`Script::wobble_scale`]): a steady, careful pace (±10 % within a free move).
const WOBBLE: f64 = 0.35;

/// Generates the task for `seed`.
pub(crate) fn generate(seed: u64) -> Result<ZooTask> {
    let mut rng = rng_for(NAME, seed);
    let n_screws = pick(&mut rng, &[2, 3]);
    // A short task logged fast: 1 kHz for two screws, 500 Hz for three.
    let rate_hz = if n_screws == 2 { 1000.0 } else { 500.0 };
    let n_demos = rng.random_range(3..=8);
    let jitter = uniform(&mut rng, 0.0, 0.12);
    let length_var = uniform(&mut rng, 0.05, 0.085);

    let channels = vec![
        Channel::real("x", 6, 0.000_05, 0.000_1),
        Channel::real("y", 6, 0.000_05, 0.000_1),
        Channel::real("z", 6, 0.000_05, 0.000_1),
        Channel::real("torque", 4, 0.01, 0.01),
        Channel::real("fz", 3, 0.2, 0.2),
        Channel::binary("spindle"),
    ];
    let start = vec![0.0, 0.0, 0.06, 0.0, 0.0, 0.0];
    let mut segments: Vec<Segment> = Vec::new();
    let mut features = Vec::new();
    for j in 0..n_screws {
        // Screws on a diagonal row: every axis moves (an axis that only carries noise is a
        // different trap, left out of this family).
        let (x, y) = (0.05 * (j + 1) as f64, 0.05 + 0.04 * j as f64);
        segments.push(seg(
            "move to the screw",
            0.6,
            0.08,
            0.3,
            vec![to(X, x, MinJerk), to(Y, y, MinJerk), to(Z, 0.02, MinJerk)],
        ));
        segments.push(seg(
            "engage",
            0.25,
            0.1,
            0.2,
            vec![
                to(Z, 0.0, MinJerk),
                to(FZ, -15.0, Ease),
                to(SPINDLE, 1.0, Step(0.5)),
                to(TORQUE, 0.15, Ease),
            ],
        ));
        segments.push(seg(
            "run down",
            0.8,
            0.2,
            0.2,
            vec![to(Z, -0.008, Linear), to(TORQUE, 0.35, Linear)],
        ));
        segments.push(seg("seat", 0.35, 0.2, 0.1, vec![]));
        // The head seats: a torque spike whose height and moment differ screw to screw.
        features.push(Feature {
            seg: segments.len() - 1,
            need_p: pick(&mut rng, &[0.3, 0.5, 0.8]),
            kind: FeatureKind::Spike {
                ch: TORQUE,
                peak: 1.6,
                peak_var: 0.5,
                at: (0.3, 0.7),
                width: 0.25,
            },
        });
        segments.push(seg(
            "release",
            0.3,
            0.1,
            0.2,
            vec![
                to(SPINDLE, 0.0, Step(0.0)),
                to(TORQUE, 0.0, Ease),
                to(FZ, 0.0, Ease),
                to(Z, 0.02, MinJerk),
            ],
        ));
    }
    segments.push(seg(
        "retract",
        0.5,
        0.08,
        0.3,
        vec![
            to(X, 0.0, MinJerk),
            to(Y, 0.0, MinJerk),
            to(Z, 0.06, MinJerk),
        ],
    ));
    // Cross-threading on the first screw's engagement: every demonstration engaged it
    // cleanly, yet the operator must watch it.
    let agreed = vec![Agreed {
        seg: 1,
        from_u: 0.0,
        to_u: 1.0,
        p: 0.2,
    }];
    let script = Script {
        family: NAME,
        seed,
        channels,
        quat: None,
        start,
        segments,
        variations: vec![],
        features,
        agreed,
        holds: vec!["spindle<0.5".into()],
        n_demos,
        rate_hz,
        jitter,
        length_var,
        wobble_scale: WOBBLE,
    };
    render(&script, &mut rng)
}
