//! Hold points through the planner on a task that is not sanding: a pick-and-place with a
//! gripper channel, whose grasp and place vary between demonstrations (the operator is
//! needed there) and whose carry does not (a robot may wait there with the part).

use tandem_lfd::{Demonstration, HoldSpec};
use tandem_planner::{Error, Planner, PlannerParams, demonstrated_need_level};
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
fn the_task_varies_at_grasp_and_place_and_not_while_carrying() {
    let p = Planner::new(&demos(), params(HoldSpec::default())).unwrap();
    let level = demonstrated_need_level(&p.params().confidence).unwrap();
    let s2 = p.model().sigma2_d();
    let at = |t: f64| s2[(t / DT_S).round() as usize];
    for t in [0.5, 0.75, 1.45, 4.0, 4.5, 4.95] {
        assert!(at(t) > level, "contact at {t} s: {} vs {level}", at(t));
    }
    // (The alignment moves the edges of the contact by a sample or two.)
    for t in [0.0, 0.3, 1.6, 2.0, 3.0, 3.9, 5.1, 5.95] {
        assert!(at(t) < level, "carry at {t} s: {} vs {level}", at(t));
    }
    // The prior alone trusts the carry and not the grasp.
    let conf = p.confidence().conf();
    assert!(!conf[15] && !conf[90] && conf[50]);
}

#[test]
fn a_gripper_rule_holds_the_robot_while_it_carries() {
    let p = Planner::new(&demos(), params(spec(&[], &["gripper>0.5"]))).unwrap();
    let holds = p.problem().holds();
    // The mean gripper is closed from 1 s in the grasp to 4.5 s in the place; only the carry
    // (1.5–4 s) does not vary, so its samples are the holds.
    let level = demonstrated_need_level(&p.params().confidence).unwrap();
    let s2 = p.model().sigma2_d();
    assert!(!holds.is_empty());
    let (first, last) = (holds[0], *holds.last().unwrap());
    assert!(
        (29..=32).contains(&first) && (77..=80).contains(&last),
        "{first}–{last}"
    );
    assert_eq!(holds.len(), last - first + 1);
    assert!(holds.iter().all(|&n| s2[n] < level));
    let closed = p.model().mean().chunks(4).filter(|m| m[3] > 0.5).count();
    assert!(closed > holds.len() + 15, "{closed}");
    // `gripper<0.5` holds on the approach and the retreat, not in contact.
    let open = Planner::new(&demos(), params(spec(&[], &["gripper<0.5"]))).unwrap();
    let open = open.problem().holds();
    assert!(open.iter().all(|&n| n <= 10 || n >= 98), "{open:?}");
    assert!(open.contains(&1) && open.contains(&6) && open.contains(&110) && open.contains(&119));
    // The prior trusts the carry, so its holds are active at once.
    assert!(p.problem().active_holds().count() > 0);
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
fn holds_where_the_demonstrations_vary_are_refused_naming_the_stretch() {
    let err = refusal(spec(&[0.75], &[]));
    let Error::HoldInLowConfidence {
        at_s,
        start_s,
        end_s,
        ..
    } = err
    else {
        panic!("{err}");
    };
    // The grasp's contact, 0.5–1.5 s.
    assert!((at_s - 0.75).abs() < 1e-9, "{at_s}");
    assert!((start_s - 0.5).abs() <= 0.1 + 1e-9, "{start_s}");
    assert!((end_s - 1.5).abs() <= 0.1 + 1e-9, "{end_s}");
    let msg = err_msg(spec(&[0.75], &[]));
    assert!(
        msg.contains("the hold at 0.75 s") && msg.contains("low-confidence stretch"),
        "{msg}"
    );
    // A rule that holds only where the demonstrations vary (in contact) adds no hold and is
    // refused.
    let msg = err_msg(spec(&[], &["force>1"]));
    assert!(
        msg.contains("hold rule `force>1` holds only inside"),
        "{msg}"
    );
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
