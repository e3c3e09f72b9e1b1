//! Cable routing with a long variable section (see the crate docs, "cable_routing").

use rand::Rng;

use crate::Result;
use crate::engine::pose::*;
use crate::engine::{
    Agreed, Channel, Feature, FeatureKind, Interp::*, Script, Shape, Variation, pick, render,
    rng_for, seg, to, uniform,
};
use crate::task::ZooTask;

/// The family's name.
pub(crate) const NAME: &str = "cable_routing";

const GRIPPER: usize = 7;
const TENSION: usize = 8;

/// How unsteady the demonstrator's pace is ([`Script::wobble_scale`]): a hand pulling a cable, uneven (±24 % within a free move).
const WOBBLE: f64 = 0.8;

/// Generates the task for `seed`.
pub(crate) fn generate(seed: u64) -> Result<ZooTask> {
    let mut rng = rng_for(NAME, seed);
    let n_demos = rng.random_range(3..=12);
    let rate_hz = 50.0;
    let jitter = uniform(&mut rng, 0.0, 0.12);
    let length_var = uniform(&mut rng, 0.05, 0.085);
    // The long variable section: the route, from clip 1 or from the route's start, to the
    // route's end or through clip 2.
    let first = pick(&mut rng, &[3, 4]);
    let last = pick(&mut rng, &[4, 5]);
    let route_p = pick(&mut rng, &[0.4, 0.6, 0.8, 1.0]);
    let connector_p = pick(&mut rng, &[0.5, 0.7]);

    let channels = Channel::pose_then(
        5,
        (0.000_2, 0.000_6),
        (0.000_5, 0.003),
        [
            Channel::binary("gripper"),
            Channel::real("tension", 3, 0.05, 0.08),
        ],
    );
    let start = vec![0.3, 0.3, 0.2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let segments = vec![
        seg(
            "reach the cable end",
            3.0,
            0.08,
            0.3,
            vec![
                to(X, 0.05, MinJerk),
                to(Y, 0.05, MinJerk),
                to(Z, 0.02, MinJerk),
            ],
        ),
        seg("grasp", 1.0, 0.5, 0.0, vec![to(GRIPPER, 1.0, Step(0.5))]),
        seg(
            "pull to clip 1",
            4.0,
            0.08,
            0.3,
            vec![
                to(X, 0.20, MinJerk),
                to(Y, 0.10, MinJerk),
                to(Z, 0.05, MinJerk),
                to(QZ, 0.5, MinJerk),
                to(TENSION, 5.0, Ease),
            ],
        ),
        seg(
            "seat in clip 1",
            2.0,
            0.15,
            0.2,
            vec![to(Z, 0.02, MinJerk), to(TENSION, 3.0, Ease)],
        ),
        seg(
            "route along the channel",
            14.0,
            0.1,
            0.3,
            vec![
                to(X, 0.60, Linear),
                to(Y, 0.30, Linear),
                to(Z, 0.05, MinJerk),
                to(TENSION, 4.0, Ease),
            ],
        ),
        seg("seat in clip 2", 2.0, 0.15, 0.2, vec![to(Z, 0.02, MinJerk)]),
        seg(
            "to the connector",
            4.0,
            0.08,
            0.3,
            vec![
                to(X, 0.70, MinJerk),
                to(Y, 0.40, MinJerk),
                to(Z, 0.06, MinJerk),
                to(QZ, 0.9, MinJerk),
                to(TENSION, 2.0, Ease),
            ],
        ),
        seg(
            "insert the connector",
            2.0,
            0.15,
            0.2,
            vec![to(Z, 0.03, MinJerk)],
        ),
        seg(
            "release",
            1.0,
            0.5,
            0.0,
            vec![to(GRIPPER, 0.0, Step(0.5)), to(TENSION, 0.0, Ease)],
        ),
        seg(
            "retreat",
            3.0,
            0.08,
            0.3,
            vec![
                to(X, 0.4, MinJerk),
                to(Y, 0.2, MinJerk),
                to(Z, 0.2, MinJerk),
                to(QZ, 0.0, MinJerk),
            ],
        ),
    ];
    // The cable's slack lies differently every time: the path and the pull wander.
    let variations = vec![Variation {
        first,
        last,
        ramp_s: 0.4,
        need_p: route_p,
        amps: vec![(Y, 0.04), (Z, 0.02), (TENSION, 2.5), (QX, 0.15)],
        shape: Shape::Wavy { cycles: 1.5 },
    }];
    // The connector seats with a push whose force and moment differ.
    let features = vec![Feature {
        seg: 7,
        need_p: connector_p,
        kind: FeatureKind::Spike {
            ch: TENSION,
            peak: 8.0,
            peak_var: 3.0,
            at: (0.3, 0.7),
            width: 0.2,
        },
    }];
    // Clip 2 may not latch although every demonstration latched it: watched, p = 0.25.
    let agreed = vec![Agreed {
        seg: 5,
        from_u: 0.3,
        to_u: 0.8,
        p: 0.25,
    }];
    let script = Script {
        family: NAME,
        seed,
        channels,
        quat: Some(QX),
        start,
        segments,
        variations,
        features,
        agreed,
        // No safe wait: a cable under tension slips out of the last clip.
        holds: vec![],
        n_demos,
        rate_hz,
        jitter,
        length_var,
        wobble_scale: WOBBLE,
    };
    render(&script, &mut rng)
}
