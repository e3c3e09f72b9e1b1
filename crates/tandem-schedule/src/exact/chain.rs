//! The margin-free model: the run structure both robots traverse (Eq. 20 constraints 1, 4).

use crate::problem::Problem;

/// What a robot's execution looks like to the margin-free problem: its low-confidence (LC) runs
/// with their fixed durations and the high-confidence (HC) gaps around them with their duration
/// ranges. Both robots traverse the same chain.
///
/// With `m` LC runs, gap `g ∈ 0..=m` is the HC run before LC run `g` (gap 0: the head before
/// the first LC run; gap `m`: the tail after the last); a missing HC run is the range `[0, 0]`.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Chain {
    /// `L_k = Σ ψ̇̄[n]·Δt_s` over LC run `k` (s), `k ∈ 0..m` (Eq. 20 constraint 4).
    pub(crate) lc_s: Vec<f64>,
    /// `[a_g, b_g] = [Σ ψ̇min·Δt_s, Σ ψ̇max·Δt_s]` over HC gap `g` (s), `g ∈ 0..=m`
    /// (Eq. 20 constraint 1).
    pub(crate) gap_s: Vec<(f64, f64)>,
    /// Reference samples `start..end` of LC run `k`.
    pub(crate) lc_ref: Vec<(usize, usize)>,
    /// Reference samples of HC gap `g` (empty range for a missing run).
    pub(crate) gap_ref: Vec<(usize, usize)>,
    /// Per HC gap, the latest usable hold point inside it (`Problem::usable_holds`) when the
    /// chain was built with holds ([`Chain::with_holds`]): the gap has no upper duration
    /// bound, a robot may dwell there. `None` everywhere for [`Chain::new`].
    pub(crate) gap_hold: Vec<Option<usize>>,
}

impl Chain {
    /// The chain of `problem`'s runs ([`Problem::runs`]).
    pub(crate) fn new(problem: &Problem) -> Chain {
        let dt = problem.dt_s();
        let sum = |v: &[f64], a: usize, b: usize| v[a..b].iter().sum::<f64>() * dt;
        let (gmean, gmin, gmax) = (problem.grad_mean(), problem.grad_min(), problem.grad_max());
        let mut chain = Chain {
            lc_s: Vec::new(),
            gap_s: Vec::new(),
            lc_ref: Vec::new(),
            gap_ref: Vec::new(),
            gap_hold: Vec::new(),
        };
        let mut pending_gap: Option<(usize, usize)> = None;
        for run in problem.runs() {
            if run.high_conf {
                pending_gap = Some((run.start, run.end));
                continue;
            }
            let (a, b) = pending_gap.take().unwrap_or((run.start, run.start));
            chain.gap_ref.push((a, b));
            chain.gap_s.push((sum(gmin, a, b), sum(gmax, a, b)));
            chain.lc_ref.push((run.start, run.end));
            chain.lc_s.push(sum(gmean, run.start, run.end));
        }
        let n_ref = problem.n_ref();
        let (a, b) = pending_gap.unwrap_or((n_ref, n_ref));
        chain.gap_ref.push((a, b));
        chain.gap_s.push((sum(gmin, a, b), sum(gmax, a, b)));
        chain.gap_hold = vec![None; chain.gap_s.len()];
        chain
    }

    /// The chain of `problem` with its hold points: an HC gap that contains a usable hold
    /// (`Problem::usable_holds`, at a sample after the gap's first) may last any time, which
    /// the search sees as the upper bound `max(b_g, max_gap_s)` (`max_gap_s`, s: at least the
    /// incumbent's `T_total`, beyond which no gap of a better schedule lasts). The latest such
    /// hold of each gap is where the schedule plans the dwell. Without usable holds it is
    /// [`Chain::new`].
    pub(crate) fn with_holds(problem: &Problem, max_gap_s: f64) -> Chain {
        let mut chain = Chain::new(problem);
        let usable = problem.usable_holds();
        for (g, &(a, b)) in chain.gap_ref.iter().enumerate() {
            if let Some(&h) = usable.iter().rev().find(|&&h| h > a && h < b) {
                chain.gap_hold[g] = Some(h);
                chain.gap_s[g].1 = chain.gap_s[g].1.max(max_gap_s);
            }
        }
        chain
    }

    /// Number of LC runs `m`.
    pub(crate) fn n_lc(&self) -> usize {
        self.lc_s.len()
    }

    /// Fastest execution of one robot (s): `Σ L_k + Σ a_g`.
    pub(crate) fn fastest_s(&self) -> f64 {
        self.lc_s.iter().sum::<f64>() + self.gap_s.iter().map(|g| g.0).sum::<f64>()
    }

    /// Slowest execution of one robot (s): `Σ L_k + Σ b_g`.
    pub(crate) fn slowest_s(&self) -> f64 {
        self.lc_s.iter().sum::<f64>() + self.gap_s.iter().map(|g| g.1).sum::<f64>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chain_of_hllh_by_hand() {
        // [HC, LC, LC, HC], gradients 1 in [0.5, 2], dt 0.5 s: one LC run of 1 s, head and tail
        // [0.25, 1] s.
        let c = Chain::new(&crate::problem::hllh(0.5));
        assert_eq!(c.lc_s, vec![1.0]);
        assert_eq!(c.gap_s, vec![(0.25, 1.0), (0.25, 1.0)]);
        assert_eq!(c.lc_ref, vec![(1, 3)]);
        assert_eq!(c.gap_ref, vec![(0, 1), (3, 4)]);
        assert_eq!((c.fastest_s(), c.slowest_s()), (1.5, 3.0));
    }

    #[test]
    fn missing_head_and_tail_are_empty_gaps() {
        let c = Chain::new(&crate::problem::unit_gradients(
            vec![false, true, false],
            (0.5, 2.0),
            1.0,
        ));
        assert_eq!(c.lc_s, vec![1.0, 1.0]);
        assert_eq!(c.gap_s, vec![(0.0, 0.0), (0.5, 2.0), (0.0, 0.0)]);
        assert_eq!(c.gap_ref, vec![(0, 0), (1, 2), (3, 3)]);
    }
}
