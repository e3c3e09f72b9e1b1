// The peg-in-hole problem shared by the scheduler's tests with hold points (a task of our own
// making, not the sanding fixture), `include!`d where `Problem` is in scope: by
// `tests/common/mod.rs` and by `src/retime.rs`'s unit tests.

/// 20 s at 20 Hz: approach (3 s), insert peg 1 (2 s, low confidence), transfer (8 s), insert
/// peg 2 (2 s, low confidence), retract (5 s). High-confidence speeds within
/// `[0.8, 1.25]` of the mean, the inserts at their mean (bounds `[0.7, 1.4]`). With
/// `with_holds`, holds in the approach, twice in the transfer and in the retract (gripper
/// open, arm in free space).
#[allow(dead_code, reason = "test files without hold points include it too")]
pub(crate) fn pegs(with_holds: bool) -> Problem {
    let n = 400;
    let conf: Vec<bool> = (0..n)
        .map(|k| !((60..100).contains(&k) || (260..300).contains(&k)))
        .collect();
    let mean: Vec<f64> = (0..n)
        .map(|k| 1.0 + 0.1 * (k as f64 * 0.03).sin())
        .collect();
    let (lo, hi): (Vec<f64>, Vec<f64>) = mean
        .iter()
        .zip(&conf)
        .map(|(&m, &hc)| {
            if hc {
                (0.8 * m, 1.25 * m)
            } else {
                (0.7 * m, 1.4 * m)
            }
        })
        .unzip();
    let p = Problem::new(conf, mean, lo, hi, 0.05).unwrap();
    if with_holds {
        p.with_holds(vec![30, 150, 200, 340]).unwrap()
    } else {
        p
    }
}
