//! Spray painting with overlapping strokes (see the crate docs, "painting").

use rand::Rng;

use crate::Result;
use crate::engine::pose::*;
use crate::engine::{
    Channel, Interp::*, Script, Segment, Shape, Variation, pick, render, rng_for, seg, to, uniform,
};
use crate::task::ZooTask;

/// The family's name.
pub(crate) const NAME: &str = "painting";

const FLOW: usize = 7;
const SPRAY: usize = 8;

/// Number of strokes; stroke `k` is segment `1 + 2k`.
const N_STROKES: usize = 6;

/// How unsteady the demonstrator's pace is ([`Script::wobble_scale`]): an ordinary hand (±15 % within a free move).
const WOBBLE: f64 = 0.5;

/// Generates the task for `seed`.
pub(crate) fn generate(seed: u64) -> Result<ZooTask> {
    let mut rng = rng_for(NAME, seed);
    let n_demos = rng.random_range(3..=12);
    let rate_hz = pick(&mut rng, &[50.0, 100.0]);
    let jitter = uniform(&mut rng, 0.0, 0.12);
    let length_var = uniform(&mut rng, 0.05, 0.085);
    // Which strokes a painter adapts to the coat they see: the first, two in the middle
    // (back to back), or the last two (touch-up).
    let (first, last) = pick(&mut rng, &[(0, 0), (2, 3), (4, 5)]);
    let need_p = pick(&mut rng, &[0.4, 0.6, 0.8, 1.0]);

    let channels = Channel::pose_then(
        5,
        (0.000_2, 0.000_5),
        (0.000_3, 0.0015),
        [Channel::non_neg("flow", 3, 0.015), Channel::binary("spray")],
    );
    let start = vec![0.3, -0.1, 0.4, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let mut segments: Vec<Segment> = vec![seg(
        "approach",
        2.0,
        0.08,
        0.3,
        vec![
            to(X, -0.1, MinJerk),
            to(Y, 0.05, MinJerk),
            to(Z, 0.25, MinJerk),
            to(QY, 0.1, MinJerk),
        ],
    )];
    for k in 0..N_STROKES {
        // Strokes start and end off the panel (x in [0, 0.6]) so the fan's edges overlap.
        let x_end = if k % 2 == 0 { 0.7 } else { -0.1 };
        segments.push(seg(
            "stroke",
            3.2,
            0.08,
            0.25,
            vec![
                to(X, x_end, Linear),
                to(SPRAY, 1.0, Step(0.06)),
                to(FLOW, 1.5, Ease),
            ],
        ));
        if k + 1 < N_STROKES {
            // Rows 8 cm apart under a 12 cm fan: each stroke overlaps the last by a third.
            let tilt = if k % 2 == 0 { -0.1 } else { 0.1 };
            segments.push(seg(
                "turnaround",
                1.0,
                0.1,
                0.2,
                vec![
                    to(SPRAY, 0.0, Step(0.0)),
                    to(FLOW, 0.0, Ease),
                    to(Y, 0.05 + 0.08 * (k + 1) as f64, MinJerk),
                    to(QY, tilt, MinJerk),
                ],
            ));
        }
    }
    segments.push(seg(
        "retreat",
        2.0,
        0.08,
        0.3,
        vec![
            to(SPRAY, 0.0, Step(0.0)),
            to(FLOW, 0.0, Ease),
            to(X, 0.3, MinJerk),
            to(Y, -0.1, MinJerk),
            to(Z, 0.4, MinJerk),
            to(QY, 0.0, MinJerk),
        ],
    ));
    // The painter sprays more or less, closer or farther, as the coat asks.
    let variations = vec![Variation {
        first: 1 + 2 * first,
        last: 1 + 2 * last,
        ramp_s: 0.2,
        need_p,
        amps: vec![(FLOW, 0.6), (Z, 0.04), (Y, 0.02), (QX, 0.08)],
        shape: Shape::Wavy { cycles: 1.0 },
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
        // No safe wait: a stop mid-panel leaves a run or a dry edge.
        holds: vec![],
        n_demos,
        rate_hz,
        jitter,
        length_var,
        wobble_scale: WOBBLE,
    };
    render(&script, &mut rng)
}
