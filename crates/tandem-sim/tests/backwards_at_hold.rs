//! "A robot never moves backwards" (docs/decisions.md) on a witness of a user's own task.
//!
//! `tests/data/backwards_at_hold.tandem` is the state file of the issue-38 witness
//! (`reproducers/backwards_at_hold.tandem` of the shared reproducers, found at 41c66dc): a
//! two-robot dispensing task of a user's own (8 demonstrations at 200 Hz,
//! `x,y,z,qx,qy,qz,qw,flow,valve`, holds declared with `--hold-where "valve<0.5"`, sampler 1000
//! samples, seed 1, re-scheduled at a 5 ms tick). Its schedule has five holds per robot, with
//! planned dwells of up to 2.6 s and release rules. Before the fix, ticking its coordinator to
//! the end with a constant operator input moved a robot's clock backwards 8 times (up to
//! 0.42 s, 73 reference samples read through the robot's plan), and the reference time a control
//! loop read from the clock and the robot's plan was off by the planned dwells (234 samples).

use tandem_planner::Planner;
use tandem_realtime::Operator;

fn witness() -> Planner {
    Planner::load(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/backwards_at_hold.tandem"
    ))
    .expect("the witness state file loads")
}

/// Cause 1: at a hold the robot's next leg takes the clock of the legs not started, which
/// follows the robots behind and was below where its previous leg ended; the clock the
/// coordinator reported went back with it. Cause 2: the reference time read from that clock
/// through the robot's plan (`robots()[i]`, a plan without the planned dwells) was off by the
/// dwells and went back too. Now the clock never decreases, and `ref_time_now` (the legs'
/// reference time) is what every tick reports, never decreasing, at the hold's sample while
/// the robot waits there.
#[test]
fn the_witness_never_moves_a_robot_backwards_for_constant_operators() {
    let planner = witness();
    let n_ref = planner.model().n_ref();
    let holds = planner.schedule().holds.clone();
    assert_eq!(planner.n_robots(), 2);
    assert!(holds.iter().all(|h| h.len() == 5), "{holds:?}");
    for op in [Operator::Scheduled, Operator::Slowest, Operator::Fastest] {
        let mut c = planner.coordinator().unwrap();
        let n = c.n_robots();
        let mut ref_before = c.ref_time_now();
        let mut clock_before = c.clock_s().to_vec();
        let (mut ticks, mut waits, mut dwelt_ahead) = (0, 0, 0);
        while !c.is_finished() {
            let tick = c.tick(op).unwrap();
            ticks += 1;
            assert!(ticks < 100_000, "{op:?}: does not finish");
            let now = c.ref_time_now();
            let samples = c.sample_now();
            let running = c.running_now();
            for i in 0..n {
                let at = format!("{op:?}, tick {ticks}, robot {i}");
                assert_eq!(tick.ref_time[i], now[i], "{at}");
                assert!(
                    now[i] >= ref_before[i],
                    "{at}: {} -> {}",
                    ref_before[i],
                    now[i]
                );
                assert!(c.clock_s()[i] >= clock_before[i], "{at}: clock goes back");
                assert_eq!(samples[i], (now[i].floor() as usize).min(n_ref - 1), "{at}");
                if c.at_hold(i) {
                    waits += 1;
                    assert!(!running[i], "{at}: a robot at a hold does not run");
                    // It stands at its hold's sample (the first sample of its current leg).
                    assert!(
                        holds[i].iter().any(|h| h.ref_idx as f64 == now[i]),
                        "{at}: at {} is not at a hold",
                        now[i]
                    );
                    // The plan without dwells puts it elsewhere: the trap of cause 2.
                    let through_plan = c.robots()[i].ref_time_at(c.clock_s()[i]);
                    dwelt_ahead += usize::from(through_plan != now[i]);
                }
            }
            ref_before = now;
            clock_before = c.clock_s().to_vec();
        }
        assert_eq!(c.ref_time_now(), [n_ref as f64; 2], "{op:?}");
        // Not vacuous: robots wait at holds, and reading their position through the plan
        // without dwells would place them elsewhere.
        assert!(waits > 100, "{op:?}: {waits} waiting robot-ticks");
        assert!(dwelt_ahead > 0, "{op:?}");
    }
}
