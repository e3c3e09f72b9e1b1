//! Integration tests of the sanding task generator (public API only).

use proptest::prelude::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tandem_sim::Error;
use tandem_sim::task::{
    self, CHANNEL_FORCE, CHANNEL_TOOL, CHANNELS, FIXTURE_SEED, Label, N_PASSES, Phase, TaskDemo,
    TaskParams, Workpiece,
};

fn demo_for_seed(params: &TaskParams, seed: u64) -> (Workpiece, TaskDemo) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let workpiece = Workpiece::random(params, &mut rng).unwrap();
    let demo = task::demonstrate(params, &workpiece, &mut rng).unwrap();
    (workpiece, demo)
}

/// Planar speed (m/s) from sample `i` to `i + 1`.
fn speed_m_s(demo: &TaskDemo, i: usize) -> f64 {
    let (a, b) = (demo.samples[i], demo.samples[i + 1]);
    ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt() / demo.dt_s
}

/// Mean force (N) and mean speed (m/s) over the samples whose label satisfies `pick` (and whose
/// successor has the same label phase and pass, so the speed is within one stretch).
fn means(demo: &TaskDemo, pick: impl Fn(&Label) -> bool) -> (f64, f64) {
    let (mut force, mut speed, mut n) = (0.0, 0.0, 0usize);
    for i in 0..demo.samples.len() - 1 {
        let (l, next) = (demo.labels[i], demo.labels[i + 1]);
        if pick(&l) && l.phase == next.phase && l.pass == next.pass {
            force += demo.samples[i][CHANNEL_FORCE];
            speed += speed_m_s(demo, i);
            n += 1;
        }
    }
    assert!(n > 0, "no samples picked");
    (force / n as f64, speed / n as f64)
}

fn sanding_p123(painted: bool) -> impl Fn(&Label) -> bool {
    move |l: &Label| l.phase == Phase::Sanding && l.pass < 4 && l.painted == painted
}

#[test]
fn same_seed_same_demo_different_seed_different_demo() {
    let params = TaskParams::default();
    let (wa, a) = demo_for_seed(&params, 11);
    let (wb, b) = demo_for_seed(&params, 11);
    assert_eq!(wa, wb);
    assert_eq!(a, b);
    let (_, c) = demo_for_seed(&params, 12);
    assert_ne!(a.samples, c.samples);
    // `demonstrations` draws workpiece then demo from one stream, like the calls above.
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let set = task::demonstrations(&params, 2, &mut rng).unwrap();
    assert_eq!(set.len(), 2);
    assert_eq!(set[0], (wa, a));
    assert_ne!(set[1].1, set[0].1);
}

#[test]
fn workpieces_paint_exactly_half_of_passes_1_to_3_and_all_of_pass_4() {
    let params = TaskParams::default();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut painted_count = [[0usize; 6]; 3];
    for _ in 0..300 {
        let w = Workpiece::random(&params, &mut rng).unwrap();
        assert_eq!(w.painted.len(), N_PASSES);
        for (p, row) in w.painted.iter().enumerate() {
            assert_eq!(row.len(), params.n_sections);
            let n = row.iter().filter(|&&b| b).count();
            if p < 3 {
                assert_eq!(n, params.n_sections / 2, "pass {}", p + 1);
                for (j, &b) in row.iter().enumerate() {
                    painted_count[p][j] += usize::from(b);
                }
            } else {
                assert_eq!(n, params.n_sections, "pass 4 is fully painted");
            }
        }
    }
    // Uniform random choice: each section is painted in about half of 300 workpieces.
    for row in painted_count {
        for c in row {
            assert!((100..=200).contains(&c), "section painted {c} times of 300");
        }
    }
}

#[test]
fn labels_match_samples_and_workpiece() {
    let params = TaskParams::default();
    for seed in 0..5 {
        let (workpiece, demo) = demo_for_seed(&params, seed);
        assert_eq!(demo.samples.len(), demo.labels.len());
        assert!((demo.dt_s - 0.01).abs() < 1e-15);
        // Order of stretches: pass 1, transition 1, pass 2, transition 2, pass 3, transition 3,
        // pass 4.
        let mut stretches: Vec<(Phase, u8)> = Vec::new();
        for l in &demo.labels {
            if stretches.last() != Some(&(l.phase, l.pass)) {
                stretches.push((l.phase, l.pass));
            }
        }
        use Phase::{Sanding as S, Transition as T};
        assert_eq!(
            stretches,
            [(S, 1), (T, 1), (S, 2), (T, 2), (S, 3), (T, 3), (S, 4)]
        );
        for (s, l) in demo.samples.iter().zip(&demo.labels) {
            match l.phase {
                Phase::Sanding => {
                    assert_eq!(s[CHANNEL_TOOL], 1.0);
                    assert_eq!(s[2], 0.0, "in contact while sanding");
                    assert!((0.0..params.plate_length_m).contains(&s[0]));
                    assert_eq!(usize::from(l.section), params.section_at(s[0]));
                    assert!((s[1] - params.pass_y_m(usize::from(l.pass))).abs() < 0.01);
                    assert_eq!(l.painted, workpiece.painted_at(l));
                }
                Phase::Transition => {
                    assert_eq!(s[CHANNEL_TOOL], 0.0);
                    assert!(s[2] >= 0.0);
                    assert_eq!((l.section, l.painted), (0, false));
                    assert!(!workpiece.painted_at(l));
                }
            }
            assert!(s[CHANNEL_FORCE] >= 0.0);
            assert!(s.iter().all(|v| v.is_finite()));
        }
        // Starts at the left edge of pass 1; the path is continuous (no jump over 1 cm).
        assert_eq!(demo.samples[0][0], 0.0);
        for i in 0..demo.samples.len() - 1 {
            assert!(speed_m_s(&demo, i) * demo.dt_s < 0.01, "jump at sample {i}");
        }
    }
}

#[test]
fn quaternions_are_unit_with_positive_w_and_small_tilt() {
    let params = TaskParams::default();
    let (_, demo) = demo_for_seed(&params, 5);
    for s in &demo.samples {
        let q = &s[3..7];
        let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!((norm - 1.0).abs() < 1e-12);
        // qw > cos(15°): the disc stays roughly parallel to the plate.
        assert!(q[3] > (7.5f64.to_radians()).cos());
    }
}

#[test]
fn expert_presses_harder_and_moves_slower_over_paint() {
    let params = TaskParams::default();
    for seed in 0..10 {
        let (_, demo) = demo_for_seed(&params, seed);
        let (force_p, speed_p) = means(&demo, sanding_p123(true));
        let (force_u, speed_u) = means(&demo, sanding_p123(false));
        // Nominal 20 N vs 3.5 N; lags at section boundaries blur the means a little.
        assert!((16.0..=21.0).contains(&force_p), "painted force {force_p}");
        assert!((2.5..=7.0).contains(&force_u), "unpainted force {force_u}");
        // Nominal 0.04 vs 0.08 m/s (×0.9–1.1 per demo): about half the speed over paint.
        let ratio = speed_p / speed_u;
        assert!((0.4..=0.7).contains(&ratio), "speed ratio {ratio}");
        assert!((0.03..=0.05).contains(&speed_p), "painted speed {speed_p}");
    }
}

#[test]
fn pass_4_is_consistent_across_demos_and_transitions_are_not() {
    let params = TaskParams::default();
    let demos: Vec<TaskDemo> = (0..6).map(|s| demo_for_seed(&params, 100 + s).1).collect();
    let mut pass4_speeds = Vec::new();
    let mut apex_heights_m = Vec::new();
    let mut bulges_m = Vec::new();
    for demo in &demos {
        // Pass 4 after the initial 1 s of loading: force within noise of 20 N everywhere.
        let start = demo.labels.iter().position(|l| l.pass == 4).unwrap();
        for s in &demo.samples[start + 100..] {
            assert!(
                (s[CHANNEL_FORCE] - 20.0).abs() < 1.5,
                "pass-4 force {}",
                s[CHANNEL_FORCE]
            );
        }
        pass4_speeds.push(means(demo, |l| l.pass == 4).1);
        for pass in 1..=3u8 {
            let stretch: Vec<&[f64; 9]> = demo
                .samples
                .iter()
                .zip(&demo.labels)
                .filter(|(_, l)| l.phase == Phase::Transition && l.pass == pass)
                .map(|(s, _)| s)
                .collect();
            apex_heights_m.push(stretch.iter().map(|s| s[2]).fold(0.0, f64::max));
            // Largest lateral departure from the straight line between the two passes.
            let (y0, y1) = (stretch[0][1], params.pass_y_m(usize::from(pass) + 1));
            let x_len = params.plate_length_m;
            let bulge = stretch
                .iter()
                .map(|s| s[1] - (y0 + (y1 - y0) * (1.0 - s[0] / x_len)))
                .fold(0.0f64, |m, d| if d.abs() > m.abs() { d } else { m });
            bulges_m.push(bulge);
        }
    }
    let spread = |v: &[f64]| {
        v.iter().copied().fold(f64::MIN, f64::max) - v.iter().copied().fold(f64::MAX, f64::min)
    };
    // Mild global variability only: the per-demo speed factor is within ±10 %.
    let mean4 = pass4_speeds.iter().sum::<f64>() / 6.0;
    assert!(
        pass4_speeds.iter().all(|v| (v / mean4 - 1.0).abs() < 0.2),
        "{pass4_speeds:?}"
    );
    // The lift-off arc varies by several centimetres in height and bulge.
    assert!(spread(&apex_heights_m) > 0.03, "{apex_heights_m:?}");
    assert!(
        apex_heights_m
            .iter()
            .all(|&h| (0.04..=0.12 + 1e-9).contains(&h))
    );
    assert!(spread(&bulges_m) > 0.03, "{bulges_m:?}");
}

#[test]
fn demonstrations_last_60_to_140_seconds() {
    let params = TaskParams::default();
    for seed in 0..50 {
        let (_, demo) = demo_for_seed(&params, seed);
        let t = demo.duration_s();
        // Four sanding passes of 11–15 s and three slow transitions of 16 s ± 45 %.
        assert!((60.0..=140.0).contains(&t), "seed {seed}: {t} s");
        assert!((6000..=14000).contains(&demo.samples.len()));
    }
}

#[test]
fn ground_truth_share_counts_transitions_and_pass_4() {
    let l = |pass, phase| Label {
        pass,
        section: 0,
        painted: false,
        phase,
    };
    let labels = [
        l(1, Phase::Sanding),
        l(3, Phase::Sanding),
        l(1, Phase::Transition),
        l(4, Phase::Sanding),
    ];
    assert_eq!(task::ground_truth_share(&labels), 0.5);
    assert_eq!(task::ground_truth_share(&[]), 0.0);
    let (_, demo) = demo_for_seed(&TaskParams::default(), 9);
    let share = task::ground_truth_share(&demo.labels);
    let n_free = demo
        .labels
        .iter()
        .filter(|l| l.phase == Phase::Transition || l.pass == 4)
        .count();
    assert_eq!(share, n_free as f64 / demo.labels.len() as f64);
    assert!((0.45..=0.8).contains(&share), "{share}");
}

#[test]
fn painted_at_reads_pass_and_section() {
    let params = TaskParams::default();
    let mut rng = ChaCha8Rng::seed_from_u64(FIXTURE_SEED);
    let w = Workpiece::random(&params, &mut rng).unwrap();
    for pass in 1..=4u8 {
        for section in 0..6u8 {
            let label = Label {
                pass,
                section,
                painted: false,
                phase: Phase::Sanding,
            };
            let expected = w.painted[usize::from(pass) - 1][usize::from(section)];
            assert_eq!(w.painted_at(&label), expected);
            let transition = Label {
                phase: Phase::Transition,
                ..label
            };
            assert!(!w.painted_at(&transition));
        }
    }
    let outside = |pass, section| Label {
        pass,
        section,
        painted: true,
        phase: Phase::Sanding,
    };
    assert!(!w.painted_at(&outside(0, 0)));
    assert!(!w.painted_at(&outside(5, 0)));
    assert!(!w.painted_at(&outside(4, 6)));
}

#[test]
fn invalid_params_are_rejected_by_name() {
    let bad = |edit: fn(&mut TaskParams)| {
        let mut p = TaskParams::default();
        edit(&mut p);
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        let w = Workpiece {
            painted: vec![vec![true; 6]; 4],
        };
        let via_demo = task::demonstrate(&p, &w, &mut rng).unwrap_err();
        let via_random = Workpiece::random(&p, &mut rng).unwrap_err();
        assert_eq!(via_demo.to_string(), via_random.to_string());
        match p.validate().unwrap_err() {
            Error::BadParam { name, .. } => name,
            other => panic!("unexpected {other:?}"),
        }
    };
    assert_eq!(bad(|p| p.n_sections = 5), "n_sections");
    assert_eq!(bad(|p| p.n_sections = 0), "n_sections");
    assert_eq!(bad(|p| p.n_sections = 256), "n_sections");
    assert_eq!(bad(|p| p.plate_length_m = f64::NAN), "plate_length_m");
    assert_eq!(bad(|p| p.plate_width_m = -1.0), "plate_width_m");
    assert_eq!(bad(|p| p.speed_painted_m_s = 0.0), "speed_painted_m_s");
    assert_eq!(
        bad(|p| p.force_painted_n = f64::INFINITY),
        "force_painted_n"
    );
    assert_eq!(bad(|p| p.force_unpainted_n = -0.1), "force_unpainted_n");
    assert_eq!(bad(|p| p.lift_height_max_m = 0.01), "lift_height_max_m");
    assert_eq!(
        bad(|p| p.transition_duration_var = 1.0),
        "transition_duration_var"
    );
    assert_eq!(
        bad(|p| p.transition_duration_s = 0.015),
        "transition_duration_s"
    );
    assert_eq!(bad(|p| p.speed_global_var = 0.9), "speed_global_var");
    assert_eq!(
        bad(|p| p.tilt_noise_std_rad = f64::NAN),
        "tilt_noise_std_rad"
    );
    assert_eq!(bad(|p| p.sample_rate_hz = 0.0), "sample_rate_hz");
    assert_eq!(bad(|p| p.end_speed_m_s = 0.0), "end_speed_m_s");
    assert_eq!(bad(|p| p.force_noise_tau_s = -1.0), "force_noise_tau_s");
    // Valid fields, but a demonstration could run past MAX_SAMPLES.
    assert_eq!(bad(|p| p.end_speed_m_s = 1e-9), "speed_painted_m_s");
    assert!(TaskParams::default().validate().is_ok());
}

#[test]
fn workpiece_shape_must_match_params() {
    let params = TaskParams::default();
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let three_passes = Workpiece {
        painted: vec![vec![true; 6]; 3],
    };
    assert!(matches!(
        task::demonstrate(&params, &three_passes, &mut rng),
        Err(Error::BadWorkpiece {
            pass: 0,
            expected: 4,
            found: 3,
            ..
        })
    ));
    let mut short = Workpiece {
        painted: vec![vec![true; 6]; 4],
    };
    short.painted[2].pop();
    assert!(matches!(
        task::demonstrate(&params, &short, &mut rng),
        Err(Error::BadWorkpiece {
            pass: 3,
            expected: 6,
            found: 5,
            ..
        })
    ));
}

#[test]
fn params_round_trip_through_serde_and_reject_unknown_fields() {
    let params = TaskParams {
        n_sections: 8,
        ..TaskParams::default()
    };
    let json = serde_json::to_string(&params).unwrap();
    let back: TaskParams = serde_json::from_str(&json).unwrap();
    assert_eq!(back, params);
    // Missing fields take their defaults.
    let partial: TaskParams = serde_json::from_str(r#"{"n_sections": 4}"#).unwrap();
    assert_eq!(partial.n_sections, 4);
    assert_eq!(partial.force_painted_n, 20.0);
    assert!(serde_json::from_str::<TaskParams>(r#"{"n_section": 4}"#).is_err());
    let label = Label {
        pass: 2,
        section: 3,
        painted: true,
        phase: Phase::Transition,
    };
    let json = serde_json::to_string(&label).unwrap();
    assert!(json.contains(r#""phase":"transition""#), "{json}");
    assert_eq!(serde_json::from_str::<Label>(&json).unwrap(), label);
    assert_eq!(CHANNELS.len(), 9);
}

#[test]
fn other_geometries_and_rates_work() {
    let params = TaskParams {
        n_sections: 10,
        sample_rate_hz: 50.0,
        ..TaskParams::default()
    };
    let (w, demo) = demo_for_seed(&params, 1);
    assert!(
        w.painted[..3]
            .iter()
            .all(|r| r.iter().filter(|&&b| b).count() == 5)
    );
    assert!((demo.dt_s - 0.02).abs() < 1e-15);
    assert!((60.0..=140.0).contains(&demo.duration_s()));
    assert!(demo.labels.iter().any(|l| l.section == 9));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]

    #[test]
    fn any_seed_gives_well_formed_demos(seed in any::<u64>()) {
        let params = TaskParams::default();
        let (workpiece, demo) = demo_for_seed(&params, seed);
        prop_assert_eq!(demo.samples.len(), demo.labels.len());
        prop_assert!((60.0..=140.0).contains(&demo.duration_s()));
        for (s, l) in demo.samples.iter().zip(&demo.labels) {
            prop_assert!((1..=4).contains(&l.pass));
            prop_assert_eq!(l.painted, workpiece.painted_at(l));
            let norm = s[3..7].iter().map(|v| v * v).sum::<f64>().sqrt();
            prop_assert!((norm - 1.0).abs() < 1e-12 && s[6] > 0.0);
        }
    }
}
