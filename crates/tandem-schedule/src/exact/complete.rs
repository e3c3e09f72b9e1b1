//! Margin-aware completion: clearances between the robots' LC runs found with the margin check
//! as the oracle (see "Margin-aware completion" in the module docs of [`super`]).

use rayon::prelude::*;
use tandem_realtime::{Timeline, sufficient_margins};

use super::chain::Chain;
use super::search::{self, Clearance, Robot};
use super::shape::{Shaping, shaped_schedule};
use super::stn::{self, Times};
use crate::problem::Problem;
use crate::schedule::Schedule;
use crate::validate::validate;

/// Growth factor of the uniform clearance between tries, in units of the maximal step `M`.
const GROWTH: f64 = 1.5;
/// First uniform clearance tried, in units of `M`.
const FIRST_CLEARANCE_M: f64 = 2.0;
/// Bisection steps on the uniform clearance once a passing one is known.
const UNIFORM_STEPS: usize = 3;
/// Bisection rounds of the per-pair clearances.
const PAIR_ROUNDS: usize = 4;

/// A schedule the margin check accepted, with its `T_total` (s).
#[derive(Clone, Debug)]
pub(crate) struct Completed {
    pub(crate) schedule: Schedule,
    pub(crate) t_total_s: f64,
}

/// One candidate: clearances, machine order, times and shaped schedule.
#[derive(Clone, Debug)]
struct Candidate {
    clear: Clearance,
    order: Vec<Robot>,
    times: Times,
    schedule: Schedule,
}

/// The completion's context.
pub(crate) struct Completion<'a> {
    problem: &'a Problem,
    chain: &'a Chain,
    tick_s: f64,
    /// `M`: the largest step (schedule-clock s) of any robot in one tick, with HC samples kept
    /// at `F ≤ f_cap`.
    max_step_s: f64,
    knobs: Shaping,
    /// `ε` of the "robot 2 starts after robot 1's run ended" exception (s).
    after_start_s: f64,
    /// Piece budget of each search.
    max_pieces: usize,
    /// Margin checks spent.
    pub(crate) checks: usize,
}

impl<'a> Completion<'a> {
    /// The completion of `problem` (whose chain is `chain`) for the margin check at `tick_s`
    /// (s). `M = tick_s·F*` with `F*` the largest `F = ψ̇̄/ψ̇min` of an LC sample, which the
    /// shaping keeps as the largest `F` of any sample unless a run's duration needs more; the
    /// shaping's knobs are multiples of `M` (tuned on the fixture problem, docs/decisions.md).
    pub(crate) fn new(
        problem: &'a Problem,
        chain: &'a Chain,
        tick_s: f64,
        max_pieces: usize,
    ) -> Self {
        let (gmean, gmin) = (problem.grad_mean(), problem.grad_min());
        let f_cap = (0..problem.n_ref())
            .filter(|&n| !problem.conf()[n])
            .map(|n| gmean[n] / gmin[n])
            .fold(1.0, f64::max);
        let max_step_s = tick_s * f_cap;
        let scale = 2.0 * chain.slowest_s().max(1.0);
        Completion {
            problem,
            chain,
            tick_s,
            max_step_s,
            knobs: Shaping {
                window_s: 2.0 * max_step_s,
                zone_s: 20.0 * max_step_s,
                edge_s: 2.0 * max_step_s,
                f_cap,
            },
            after_start_s: 1e-6 * scale,
            max_pieces,
            checks: 0,
        }
    }

    /// Uniform clearance `delta_s` before every LC run that follows the other robot's.
    fn uniform(&self, delta_s: f64) -> Clearance {
        let m = self.chain.n_lc();
        Clearance {
            before: [vec![delta_s; m], vec![delta_s; m]],
            after_start: Some(self.after_start_s),
        }
    }

    /// The candidate for clearances `clear`: the best order found by the search (below
    /// `cap_s`) when `order` is `None`, its earliest times and shaped speeds.
    fn candidate(
        &self,
        clear: Clearance,
        order: Option<&[Robot]>,
        cap_s: f64,
    ) -> Option<Candidate> {
        self.candidate_upto(clear, order, cap_s, None)
    }

    /// [`Completion::candidate`]; with `keep = Some(((r, k), base))`, only the HC runs entered
    /// before robot `r`'s LC run `k` starts (plus the shaping window) are shaped, the later ones
    /// keep `base`'s gradients (enough for the margin check of the LC runs up to that one).
    fn candidate_upto(
        &self,
        clear: Clearance,
        order: Option<&[Robot]>,
        cap_s: f64,
        keep: Option<((usize, usize), &Schedule)>,
    ) -> Option<Candidate> {
        let order = match order {
            Some(o) => o.to_vec(),
            None => match search::search(self.chain, &clear, cap_s, self.max_pieces).0 {
                search::Outcome::Done(Some(found)) => found.order,
                _ => return None,
            },
        };
        let times = stn::earliest(self.chain, &order, &clear)?;
        let keep = keep.map(|((r, k), base)| (times.lc_start_s[r][k] + self.knobs.window_s, base));
        let schedule = shaped_schedule(
            self.problem,
            self.chain,
            &times,
            &self.knobs,
            keep,
            self.tick_s,
        );
        Some(Candidate {
            clear,
            order,
            times,
            schedule,
        })
    }

    /// The margin check on the candidate's LC runs up to machine position `upto` (later LC
    /// runs count as HC; all of them when `None`).
    fn margins_pass(&self, c: &Candidate, upto: Option<usize>) -> bool {
        let p = self.problem;
        let mut conf = [p.conf().to_vec(), p.conf().to_vec()];
        if let Some(q) = upto {
            let mut seen = [0usize; 2];
            for (pos, &r) in c.order.iter().enumerate() {
                let r = usize::from(r);
                let k = seen[r];
                seen[r] += 1;
                if pos > q {
                    let (a, b) = self.chain.lc_ref[k];
                    conf[r][a..b].fill(true);
                }
            }
        }
        let starts = c.schedule.starts_s();
        let build = |r: usize| {
            Timeline::new(
                &conf[r],
                &c.schedule.grad_exec[r],
                p.grad_min(),
                p.grad_max(),
                starts[r],
                p.dt_s(),
            )
        };
        match (build(0), build(1)) {
            (Ok(a), Ok(b)) => sufficient_margins(&[a, b], self.tick_s).unwrap_or(false),
            _ => false,
        }
    }

    /// The full constraints of Eq. 20 at the completion's tick.
    fn valid(&self, c: &Candidate) -> bool {
        validate(self.problem, &c.schedule).is_ok()
    }

    /// The least-`T_total` schedule this completion finds that passes every constraint of
    /// Eq. 20 and beats `cap_s`, spending at most `budget` margin checks.
    pub(crate) fn run(&mut self, cap_s: f64, budget: usize) -> Option<Completed> {
        let dt = self.problem.dt_s();
        let m_step = self.max_step_s;
        // Phase 1: a uniform clearance, grown geometrically (two tries at a time) until one
        // passes; if the clearances grow too large for any order to beat the cap first, the
        // stretch between the last failure and that size is bisected instead.
        let mut fail = 0.0;
        let mut pass: Option<(f64, Candidate)> = None;
        let mut too_big: Option<f64> = None;
        let mut delta = FIRST_CLEARANCE_M * m_step;
        while pass.is_none() && too_big.is_none() && self.checks + 2 <= budget {
            let deltas = [delta, delta * GROWTH];
            let tried: Vec<Option<(Candidate, bool)>> = deltas
                .par_iter()
                .map(|&d| {
                    let c = self.candidate(self.uniform(d), None, cap_s)?;
                    let ok = self.margins_pass(&c, None);
                    Some((c, ok))
                })
                .collect();
            self.checks += tried.iter().filter(|t| t.is_some()).count();
            for (d, t) in deltas.iter().zip(tried) {
                match t {
                    Some((c, true)) => {
                        pass = Some((*d, c));
                        break;
                    }
                    Some((_, false)) => fail = *d,
                    None => {
                        too_big = Some(*d);
                        break;
                    }
                }
            }
            delta *= GROWTH * GROWTH;
        }
        if let (None, Some(mut hi)) = (&pass, too_big) {
            for _ in 0..UNIFORM_STEPS {
                if self.checks >= budget {
                    break;
                }
                let mid = 0.5 * (fail + hi);
                match self.candidate(self.uniform(mid), None, cap_s) {
                    Some(c) => {
                        self.checks += 1;
                        if self.margins_pass(&c, None) {
                            pass = Some((mid, c));
                            break;
                        }
                        fail = mid;
                    }
                    None => hi = mid,
                }
            }
        }
        let (mut pass_delta, mut best) = pass?;
        // Per-pair refinement follows when the budget allows it: it starts from the passing
        // uniform clearance, so the uniform bisection is skipped then.
        let pairs = self.cross_pairs(&best);
        let refine = !pairs.is_empty() && self.checks + PAIR_ROUNDS * pairs.len() < budget;
        for _ in 0..if refine { 0 } else { UNIFORM_STEPS } {
            if self.checks >= budget {
                break;
            }
            let mid = 0.5 * (fail + pass_delta);
            self.checks += 1;
            match self.candidate(self.uniform(mid), None, cap_s) {
                Some(c) if self.margins_pass(&c, None) => {
                    pass_delta = mid;
                    best = c;
                }
                _ => fail = mid,
            }
        }
        // Phase 2: per-pair clearances on the winner's order, every pair bisected at once
        // (each on the margin check of the LC runs up to its own), while the budget lasts.
        if refine && let Some(better) = self.refine(&best, &pairs, m_step, budget) {
            best = better;
        }
        // Constraints 1–4 hold by construction (earliest times, gradients in bounds, the mean
        // on LC samples); the full check confirms it, and the margins.
        if !self.valid(&best) {
            return None;
        }
        let t = best.schedule.t_total_s(dt);
        (t < cap_s).then_some(Completed {
            schedule: best.schedule,
            t_total_s: t,
        })
    }

    /// Machine positions `q` whose LC run follows the other robot's and needs a clearance:
    /// `(q, robot, run index)`. Robot 2's first run is left out when robot 2 starts after the
    /// previous run ended (the margin check accepts such pairs without simulating them).
    fn cross_pairs(&self, c: &Candidate) -> Vec<(usize, usize, usize)> {
        let mut out = Vec::new();
        let mut seen = [0usize; 2];
        let mut prev: Option<(usize, usize)> = None;
        for (q, &r) in c.order.iter().enumerate() {
            let r = usize::from(r);
            let k = seen[r];
            seen[r] += 1;
            if let Some((pr, pk)) = prev
                && pr != r
            {
                let prev_end = c.times.lc_start_s[pr][pk] + self.chain.lc_s[pk];
                let exempt = r == 1 && k == 0 && c.times.tau_s >= prev_end + self.after_start_s;
                if !exempt {
                    out.push((q, r, k));
                }
            }
            prev = Some((r, k));
        }
        out
    }

    /// Bisects every pair's clearance between `M` (the margin check's own step: never enough)
    /// and its current value, all pairs at once per round; keeps the result if the full check
    /// accepts it (after one widening by the last bisection step if needed).
    fn refine(
        &mut self,
        best: &Candidate,
        pairs: &[(usize, usize, usize)],
        m_step: f64,
        budget: usize,
    ) -> Option<Candidate> {
        let mut hi: Vec<f64> = pairs
            .iter()
            .map(|&(_, r, k)| best.clear.before[r][k])
            .collect();
        let mut lo: Vec<f64> = hi.iter().map(|&h| m_step.min(h)).collect();
        let with = |vals: &[f64]| {
            let mut clear = best.clear.clone();
            for (&(_, r, k), &v) in pairs.iter().zip(vals) {
                clear.before[r][k] = v;
            }
            clear
        };
        for _ in 0..PAIR_ROUNDS {
            if self.checks + pairs.len() > budget {
                break;
            }
            let results: Vec<bool> = (0..pairs.len())
                .into_par_iter()
                .map(|i| {
                    let mut vals = hi.clone();
                    vals[i] = 0.5 * (lo[i] + hi[i]);
                    let (q, r, k) = pairs[i];
                    let keep = Some(((r, k), &best.schedule));
                    self.candidate_upto(with(&vals), Some(&best.order), f64::INFINITY, keep)
                        .is_some_and(|c| self.margins_pass(&c, Some(q)))
                })
                .collect();
            self.checks += pairs.len();
            for (i, ok) in results.into_iter().enumerate() {
                let mid = 0.5 * (lo[i] + hi[i]);
                if ok {
                    hi[i] = mid;
                } else {
                    lo[i] = mid;
                }
            }
        }
        for widen in [0.0, 1.0] {
            if self.checks >= budget {
                break;
            }
            let vals: Vec<f64> = hi
                .iter()
                .zip(&lo)
                .map(|(&h, &l)| h + widen * (h - l))
                .collect();
            self.checks += 1;
            if let Some(c) = self.candidate(with(&vals), Some(&best.order), f64::INFINITY)
                && self.valid(&c)
            {
                return Some(c);
            }
        }
        None
    }
}
