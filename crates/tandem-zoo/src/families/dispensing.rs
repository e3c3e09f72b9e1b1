//! Dispensing: a glue bead along three edges of a part (see the crate docs, "dispensing").

use rand::Rng;

use crate::Result;
use crate::engine::pose::*;
use crate::engine::{
    Channel, Interp::*, Script, Shape, Variation, pick, render, rng_for, seg, to, uniform,
};
use crate::task::ZooTask;

/// The family's name.
pub(crate) const NAME: &str = "dispensing";

const FLOW: usize = 7;
const VALVE: usize = 8;

/// Segment indices of the three beads (A along +x, B along +y, C along −x).
const BEADS: [usize; 3] = [4, 6, 8];

/// How unsteady the demonstrator's pace is ([`Script::wobble_scale`]): an ordinary hand (±15 % within a free move).
const WOBBLE: f64 = 0.5;

/// Generates the task for `seed`.
pub(crate) fn generate(seed: u64) -> Result<ZooTask> {
    let mut rng = rng_for(NAME, seed);
    let n_demos = rng.random_range(4..=10);
    let rate_hz = pick(&mut rng, &[100.0, 125.0, 200.0]);
    let jitter = uniform(&mut rng, 0.0, 0.12);
    let length_var = uniform(&mut rng, 0.05, 0.085);
    let seam_bead = pick(&mut rng, &BEADS);
    let start_p = pick(&mut rng, &[0.2, 0.3, 0.4]);
    let seam_p = pick(&mut rng, &[0.6, 0.8, 1.0]);
    let seam_shape = pick(&mut rng, &[Shape::Offset, Shape::Wavy { cycles: 1.0 }]);
    // Across the bead's travel: y for the beads along x, x for the bead along y.
    let across = if seam_bead == 6 { X } else { Y };

    let channels = Channel::pose_then(
        6,
        (0.000_2, 0.000_6),
        (0.000_5, 0.003),
        [Channel::non_neg("flow", 4, 0.02), Channel::binary("valve")],
    );
    let start = vec![0.0, 0.0, 0.15, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let segments = vec![
        seg(
            "approach the purge station",
            2.0,
            0.08,
            0.3,
            vec![
                to(X, -0.05, MinJerk),
                to(Y, 0.05, MinJerk),
                to(Z, 0.03, MinJerk),
            ],
        ),
        seg(
            "purge dwell",
            2.0,
            0.45,
            0.0,
            vec![to(VALVE, 1.0, Step(0.05)), to(FLOW, 2.0, Ease)],
        ),
        seg(
            "transfer to the part",
            2.2,
            0.08,
            0.3,
            vec![
                to(VALVE, 0.0, Step(0.0)),
                to(FLOW, 0.0, Ease),
                to(X, 0.10, MinJerk),
                to(Y, 0.05, MinJerk),
                to(Z, 0.005, MinJerk),
                to(QY, 0.2, MinJerk),
            ],
        ),
        seg(
            "bead start",
            0.8,
            0.1,
            0.2,
            vec![
                to(VALVE, 1.0, Step(0.0)),
                to(FLOW, 1.2, Ease),
                to(X, 0.12, Linear),
            ],
        ),
        seg("bead A", 3.0, 0.08, 0.25, vec![to(X, 0.30, Linear)]),
        seg(
            "corner 1",
            1.2,
            0.1,
            0.2,
            vec![
                to(X, 0.31, MinJerk),
                to(Y, 0.06, MinJerk),
                to(QY, 0.0, MinJerk),
                to(QX, -0.2, MinJerk),
                to(FLOW, 0.8, Ease),
            ],
        ),
        seg(
            "bead B",
            3.0,
            0.08,
            0.25,
            vec![to(Y, 0.20, Linear), to(FLOW, 1.2, Ease)],
        ),
        seg(
            "corner 2",
            1.2,
            0.1,
            0.2,
            vec![
                to(X, 0.30, MinJerk),
                to(Y, 0.21, MinJerk),
                to(QX, 0.0, MinJerk),
                to(QY, -0.2, MinJerk),
                to(FLOW, 0.8, Ease),
            ],
        ),
        seg(
            "bead C",
            3.0,
            0.08,
            0.25,
            vec![to(X, 0.12, Linear), to(FLOW, 1.2, Ease)],
        ),
        seg(
            "lift off",
            0.8,
            0.1,
            0.2,
            vec![
                to(VALVE, 0.0, Step(0.0)),
                to(FLOW, 0.0, Ease),
                to(Z, 0.06, MinJerk),
                to(QY, 0.0, MinJerk),
            ],
        ),
        seg("inspection hover", 1.6, 0.4, 0.0, vec![to(X, 0.14, Linear)]),
        seg(
            "retreat",
            2.0,
            0.08,
            0.3,
            vec![
                to(X, 0.0, MinJerk),
                to(Y, 0.0, MinJerk),
                to(Z, 0.15, MinJerk),
            ],
        ),
    ];
    let variations = vec![
        // The bead's start: how much glue the first touch needs differs part to part.
        Variation {
            first: 3,
            last: 3,
            ramp_s: 0.15,
            need_p: start_p,
            amps: vec![(FLOW, 0.6), (Z, 0.002)],
            shape: Shape::Offset,
        },
        // The seam under one bead is where a hand-placed insert put it.
        Variation {
            first: seam_bead,
            last: seam_bead,
            ramp_s: 0.2,
            need_p: seam_p,
            amps: vec![(across, 0.05), (Z, 0.004), (FLOW, 0.4)],
            shape: seam_shape,
        },
    ];
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
        holds: vec!["valve<0.5".into()],
        n_demos,
        rate_hz,
        jitter,
        length_var,
        wobble_scale: WOBBLE,
    };
    render(&script, &mut rng)
}
