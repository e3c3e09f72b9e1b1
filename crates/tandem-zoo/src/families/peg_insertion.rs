//! Peg insertion with a search spiral (see the crate docs, "peg_insertion").

use rand::Rng;

use crate::Result;
use crate::engine::pose::*;
use crate::engine::{
    Channel, Feature, FeatureKind, Interp::*, Script, pick, render, rng_for, seg, to, uniform,
};
use crate::task::ZooTask;

/// The family's name.
pub(crate) const NAME: &str = "peg_insertion";

const FX: usize = 7;
const FY: usize = 8;
const FZ: usize = 9;

/// How unsteady the demonstrator's pace is ([`Script::wobble_scale`]): an ordinary hand (±15 % within a free move).
const WOBBLE: f64 = 0.5;

/// Generates the task for `seed`.
pub(crate) fn generate(seed: u64) -> Result<ZooTask> {
    let mut rng = rng_for(NAME, seed);
    let n_demos = rng.random_range(3..=8);
    let rate_hz = pick(&mut rng, &[250.0, 500.0]);
    let jitter = uniform(&mut rng, 0.0, 0.12);
    let length_var = uniform(&mut rng, 0.05, 0.085);
    let spiral_p = pick(&mut rng, &[0.8, 1.0]);
    let insert_p = pick(&mut rng, &[0.4, 0.6]);
    let turns = pick(&mut rng, &[2.0, 3.0]);

    let force = |name| Channel::real(name, 3, 0.03, 0.05);
    let channels = Channel::pose_then(
        6,
        (0.000_1, 0.000_3),
        (0.000_2, 0.001),
        [force("fx"), force("fy"), Channel::real("fz", 3, 0.15, 0.2)],
    );
    let start = vec![0.0, 0.0, 0.12, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let segments = vec![
        seg(
            "transport to the hole",
            2.5,
            0.08,
            0.3,
            vec![
                to(X, 0.20, MinJerk),
                to(Y, 0.10, MinJerk),
                to(Z, 0.03, MinJerk),
                to(QX, 0.04, MinJerk),
                to(QZ, 0.6, MinJerk),
            ],
        ),
        seg("descend", 1.5, 0.1, 0.25, vec![to(Z, 0.006, MinJerk)]),
        seg(
            "contact",
            0.6,
            0.15,
            0.2,
            vec![to(Z, 0.004, Linear), to(FZ, -8.0, Ease)],
        ),
        seg("search spiral", 2.5, 0.35, 0.1, vec![]),
        seg(
            "insert",
            1.2,
            0.2,
            0.2,
            vec![
                to(Z, -0.02, Linear),
                to(QX, 0.0, MinJerk),
                to(FZ, -4.0, Ease),
            ],
        ),
        seg(
            "release and retract",
            1.2,
            0.08,
            0.25,
            vec![
                to(Z, 0.05, MinJerk),
                to(FZ, 0.0, Ease),
                to(QZ, 0.0, MinJerk),
            ],
        ),
    ];
    let features = vec![
        // Where the hole is found differs: the spiral's phase and radius, and the friction
        // force that follows its direction.
        Feature {
            seg: 3,
            need_p: spiral_p,
            kind: FeatureKind::Spiral {
                cx: X,
                cy: Y,
                r_max: 0.004,
                turns,
                friction: Some((FX, FY, 3.0)),
            },
        },
        // The peg jams once on the way in, at a depth and with a force that differ.
        Feature {
            seg: 4,
            need_p: insert_p,
            kind: FeatureKind::Spike {
                ch: FZ,
                peak: -10.0,
                peak_var: 5.0,
                at: (0.12, 0.7),
                width: 0.12,
            },
        },
    ];
    let script = Script {
        family: NAME,
        seed,
        channels,
        quat: Some(QX),
        start,
        segments,
        variations: vec![],
        features,
        agreed: vec![],
        holds: vec!["z>0.02".into()],
        n_demos,
        rate_hz,
        jitter,
        length_var,
        wobble_scale: WOBBLE,
    };
    render(&script, &mut rng)
}
