//! Hold points through the planner on a task that is not sanding: a pick-and-place with a
//! gripper channel, whose grasp and place vary between demonstrations (the operator is
//! needed there) and whose carry does not (a robot may wait there with the part).

use tandem_lfd::{Demonstration, HoldSpec};
use tandem_planner::{Error, Planner, PlannerParams};
use tandem_schedule::SamplerParams;

/// Reference period of the demonstrations, s.
const DT_S: f64 = 0.05;
/// Samples per demonstration (6 s): 0–0.5 s approach, 0.5–1.5 s grasp (contact), 1.5–4 s
/// carry with the gripper closed, 4–5 s place (contact; the gripper opens at 4.5 s), 5–6 s
/// retreat.
const N: usize = 120;

/// Demonstration `i` of four: channels `x` (m), `z` (m), `force` (N) and `gripper` (0 open,
/// 1 closed). The demonstrations move alike; the contact force differs from one to the next
/// while grasping and placing, so the operator is needed there, and nowhere else.
fn demo(i: usize) -> Demonstration {
    let grasp_n = [5.0, 8.0, 11.0, 14.0][i];
    let place_n = [12.0, 6.0, 9.0, 3.0][i];
    let mut samples = Vec::with_capacity(4 * N);
    for k in 0..N {
        let t = k as f64 * DT_S;
        let down = |s: f64| 0.2 * (1.0 - (std::f64::consts::PI * s.clamp(0.0, 1.0)).sin());
        let row = if t < 0.5 {
            [0.3 * t / 0.5, down(t), 0.0, 0.0]
        } else if t < 1.5 {
            [0.3, 0.0, grasp_n, if t < 1.0 { 0.0 } else { 1.0 }]
        } else if t < 4.0 {
            [
                0.3 + 0.5 * (t - 1.5) / 2.5,
                down(0.5 + 0.5 * (t - 1.5) / 2.5),
                0.0,
                1.0,
            ]
        } else if t < 5.0 {
            [0.8, 0.0, place_n, if t < 4.5 { 1.0 } else { 0.0 }]
        } else {
            [0.8, down(0.5 * (t - 5.0)), 0.0, 0.0]
        };
        samples.extend(row);
    }
    let names = ["x", "z", "force", "gripper"].map(String::from).to_vec();
    Demonstration::new(names, samples, DT_S)
        .unwrap()
        .with_source(format!("pick_{i}.csv"))
}

fn demos() -> Vec<Demonstration> {
    (0..4).map(demo).collect()
}

fn params(holds: HoldSpec) -> PlannerParams {
    PlannerParams {
        sampler: SamplerParams {
            samples: 300,
            ..SamplerParams::default()
        },
        holds,
        ..PlannerParams::default()
    }
}

fn spec(at_s: &[f64], rules: &[&str]) -> HoldSpec {
    HoldSpec {
        at_s: at_s.to_vec(),
        rules: rules.iter().map(|r| r.parse().unwrap()).collect(),
    }
}

#[test]
fn the_prior_trusts_the_carry_and_not_the_contacts() {
    let p = Planner::new(&demos(), params(HoldSpec::default())).unwrap();
    let conf = p.confidence().conf();
    let at = |t: f64| conf[(t / DT_S).round() as usize];
    for t in [0.75, 1.25, 4.25, 4.75] {
        assert!(!at(t), "contact at {t} s is low-confidence");
    }
    for t in [2.0, 2.5, 3.0, 3.5] {
        assert!(at(t), "carry at {t} s is high-confidence");
    }
}

#[test]
fn a_gripper_rule_holds_the_robot_while_it_carries() {
    let p = Planner::new(&demos(), params(spec(&[], &["gripper>0.5"]))).unwrap();
    let holds = p.problem().holds();
    // The mean gripper is closed from 1 s in the grasp to 4.5 s in the place: every such
    // sample is a hold; those in contact are low-confidence, so inactive.
    let closed: Vec<usize> = p
        .model()
        .mean()
        .chunks(4)
        .enumerate()
        .filter(|(_, m)| m[3] > 0.5)
        .map(|(n, _)| n)
        .collect();
    assert_eq!(holds, closed);
    assert!((19..=21).contains(&holds[0]) && (88..=91).contains(holds.last().unwrap()));
    let conf = p.problem().conf();
    let active: Vec<usize> = p.problem().active_holds().collect();
    assert_eq!(
        active,
        holds
            .iter()
            .copied()
            .filter(|&n| conf[n])
            .collect::<Vec<_>>()
    );
    // Most of the carry (2–3.95 s) is trusted by the prior, so its holds are active at once.
    assert!((42..=78).all(|n| active.contains(&n)), "{active:?}");
    assert!(!active.contains(&25) && !active.contains(&85));
    // `gripper<0.5` holds on the approach and the retreat (and the open half of the grasp).
    let open = Planner::new(&demos(), params(spec(&[], &["gripper<0.5"]))).unwrap();
    let open = open.problem().holds();
    assert!(open.contains(&1) && open.contains(&110) && open.contains(&119));
    assert!(!open.contains(&50));
}

#[test]
fn a_hold_at_a_time_is_the_nearest_sample_and_survives_save_and_load() {
    let p = Planner::new(&demos(), params(spec(&[2.0, 3.01], &[]))).unwrap();
    assert_eq!(p.problem().holds(), &[40, 60]);
    let dir = std::env::temp_dir().join(format!("tandem-holds-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("pick.tandem");
    p.save(&path).unwrap();
    let back = Planner::load(&path).unwrap();
    assert_eq!(back.params().holds, p.params().holds);
    assert_eq!(back.problem().holds(), &[40, 60]);
    assert_eq!(back.outcome(), p.outcome());
    assert!(back.load_notice().is_none());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_schedule_with_holds_survives_save_and_load() {
    // Three robots with the carry as hold points: the scheduler plans holds (dwells and
    // release rules), which the state file keeps field for field, empty ones included.
    let p = Planner::with_robots(&demos(), params(spec(&[], &["gripper>0.5"])), 3).unwrap();
    assert!(p.schedule().has_holds(), "{:?}", p.schedule().holds);
    let dir = std::env::temp_dir().join(format!("tandem-holds-3-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("pick3.tandem");
    p.save(&path).unwrap();
    let back = Planner::load(&path).unwrap();
    assert_eq!(back.outcome(), p.outcome());
    assert!(back.load_notice().is_none());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn holds_where_nothing_is_known_yet_are_kept_inactive() {
    // The grasp is low-confidence for lack of executions only: a hold there is kept, and
    // waits to be trusted (a hold is refused only where recorded corrections show the need,
    // `Planner::set_holds`, tested in the crate).
    let p = Planner::new(&demos(), params(spec(&[0.75], &["force>1"]))).unwrap();
    assert!(p.problem().holds().contains(&15));
    assert_eq!(p.problem().active_holds().count(), 0);
}

fn refusal(holds: HoldSpec) -> Error {
    match Planner::new(&demos(), params(holds.clone())) {
        Ok(_) => panic!("{holds:?} was accepted"),
        Err(e) => e,
    }
}

fn err_msg(holds: HoldSpec) -> String {
    refusal(holds).to_string()
}

#[test]
fn bad_declarations_are_refused_with_what_and_where() {
    for (holds, says) in [
        (spec(&[6.5], &[]), "outside the task"),
        (spec(&[-1.0], &[]), "finite number of seconds"),
        (spec(&[f64::NAN], &[]), "finite number of seconds"),
        (spec(&[], &["tool<0.5"]), "no channel `tool`"),
        (spec(&[], &["gripper>2"]), "holds nowhere"),
    ] {
        let msg = err_msg(holds.clone());
        assert!(msg.contains(says), "{holds:?}: {msg}");
    }
    let msg = err_msg(spec(&[], &["tool<0.5"]));
    assert!(msg.contains(r#"["x", "z", "force", "gripper"]"#), "{msg}");
}

#[test]
fn a_planner_without_holds_is_the_planner_of_before() {
    // An empty declaration and none at all give the same problem and schedule, bit for bit;
    // a declaration changes the problem only by its holds.
    let a = Planner::new(&demos(), params(HoldSpec::default())).unwrap();
    let b = Planner::new(&demos(), params(spec(&[2.0], &[]))).unwrap();
    assert!(a.problem().holds().is_empty());
    assert_eq!(b.problem().holds(), &[40]);
    assert_eq!(a.problem().conf(), b.problem().conf());
    assert_eq!(a.problem().grad_min(), b.problem().grad_min());
}
