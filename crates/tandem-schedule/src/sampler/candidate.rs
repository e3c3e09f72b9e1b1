//! Candidate `k`: its draws from ChaCha8 stream `(seed, k)`, its cheap check (`T_total` below
//! the bound, no low-confidence overlap) and its materialized schedule under every
//! constraint of Eq. 20.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tandem_realtime::LcInterval;

use super::offsets::{feasible_offset, overlaps};
use super::params::{Distribution, DrawnOffset, OffsetSampling, SamplerBaselines, SamplerParams};
use super::pieces::{lc_of_warp, pieces};
use super::{Sampler, Scratch, WARM_WIDEN, Warm};
use crate::choose::repair;
use crate::problem::Problem;
use crate::schedule::Schedule;
use crate::validate::{validate_full, validate_with_switch};

impl<'a> Sampler<'a> {
    /// The pieces, their suffix sums and, for fitted robot 2 with a previous
    /// schedule, the warm start (robot 1 of its repair).
    pub(super) fn new(
        problem: &'a Problem,
        n_robots: usize,
        params: &'a SamplerParams,
        baselines: &SamplerBaselines,
        tick_s: f64,
        previous: Option<&Schedule>,
    ) -> Self {
        let distribution = if baselines.per_sample {
            Distribution::PerSample
        } else {
            Distribution::PerRun {
                pieces: params.pieces,
            }
        };
        let offset = match baselines.drawn_offset {
            Some(drawn) => OffsetSampling::Drawn(drawn),
            None => OffsetSampling::Fitted {
                widen_max: params.widen_max,
            },
        };
        let pieces = pieces(problem, distribution);
        let mut suffix_min_s = vec![0.0; pieces.len() + 1];
        for (p, piece) in pieces.iter().enumerate().rev() {
            suffix_min_s[p] = suffix_min_s[p + 1] + piece.min_s;
        }
        let warm = match (
            offset,
            previous
                .and_then(|prev| repair(problem, prev, tick_s))
                .and_then(|fixed| fixed.grad_exec.into_iter().next()),
        ) {
            (OffsetSampling::Fitted { .. }, Some(warp)) => {
                let (lc, dur_s) = lc_of_warp(problem, &warp);
                Some(Warm { warp, lc, dur_s })
            }
            _ => None,
        };
        Sampler {
            problem,
            params,
            n_robots,
            offset,
            margin_check: baselines.margin_check,
            pieces,
            suffix_min_s,
            tick_s,
            warm,
            has_holds: !problem.usable_holds().is_empty(),
            switch_room_s: if params.switch_s > 0.0 {
                [
                    params.switch_s * crate::choose::max_step_s(problem, 1.0),
                    params.switch_s,
                ]
            } else {
                [0.0; 2]
            },
        }
    }
}

impl Sampler<'_> {
    pub(super) fn rng(&self, k: u64) -> ChaCha8Rng {
        let mut rng = ChaCha8Rng::seed_from_u64(self.params.seed);
        rng.set_stream(k);
        rng
    }

    pub(super) fn factor(&self, rng: &mut ChaCha8Rng) -> f64 {
        if rng.random_bool(self.params.p_fastest) {
            0.0
        } else {
            rng.random::<f64>()
        }
    }

    /// Draws one robot's factors into `factors` and its low-confidence intervals (relative to
    /// its start, from the piece sums) into `lc`; returns its duration `|ψ_E|` (s).
    pub(super) fn draw_robot(
        &self,
        rng: &mut ChaCha8Rng,
        factors: &mut Vec<f64>,
        lc: &mut Vec<LcInterval>,
    ) -> f64 {
        factors.clear();
        self.walk(0.0, lc, || {
            let u = self.factor(rng);
            factors.push(u);
            u
        })
    }

    /// One robot's pass over the pieces from `start_s` (s): each high-confidence piece takes
    /// the factor `next_factor()` (its duration `min_s + u·span_s`), each low-confidence piece
    /// its mean duration, pushed into `lc` (cleared first) as an interval; returns the end
    /// (s), from the piece sums.
    pub(super) fn walk(
        &self,
        start_s: f64,
        lc: &mut Vec<LcInterval>,
        mut next_factor: impl FnMut() -> f64,
    ) -> f64 {
        lc.clear();
        let mut t = start_s;
        for p in &self.pieces {
            if p.high_conf {
                t += p.min_s + next_factor() * p.span_s;
            } else {
                lc.push(LcInterval {
                    ref_start: p.start,
                    ref_end: p.end,
                    start_s: t,
                    end_s: t + p.min_s,
                });
                t += p.min_s;
            }
        }
        t
    }

    /// Draws candidate `k`: factors (into `scratch.factors`), durations (into
    /// `scratch.durs_s`) and offsets (into `scratch.offsets_s`); returns its `T_total` (s,
    /// from the piece sums), or `None` when no admissible offset avoids a low-confidence
    /// overlap. With fitted robots, candidates whose robots cannot all finish before
    /// `bound_s` get `None` (the same draws otherwise, whatever `bound_s`).
    pub(super) fn draw(&self, scratch: &mut Scratch, k: u64, bound_s: f64) -> Option<f64> {
        let mut rng = self.rng(k);
        scratch.offsets_s.clear();
        scratch.durs_s.clear();
        if let OffsetSampling::Fitted { widen_max } = self.offset {
            let (dur0, w) = match (&self.warm, k.checked_sub(self.params.samples as u64)) {
                (Some(warm), Some(j)) => {
                    scratch.factors[0].clear();
                    scratch.lc[0].clear();
                    scratch.lc[0].extend_from_slice(&warm.lc);
                    (warm.dur_s, widen_max * WARM_WIDEN[j as usize])
                }
                _ => {
                    let (f0, lc0) = (&mut scratch.factors[0], &mut scratch.lc[0]);
                    let dur0 = self.draw_robot(&mut rng, f0, lc0);
                    (dur0, rng.random::<f64>() * widen_max)
                }
            };
            // Robots 2..N in turn, each fitted against every earlier robot (the latest end
            // so far bounds its offset, Eq. 20 constraint 2); `T_total` is the latest end.
            scratch.durs_s.push(dur0);
            let mut t_total = dur0;
            for robot in 1..self.n_robots {
                let room_s = self.switch_room_s[(k % 2) as usize];
                let (offset_s, dur) = self.fit_next(scratch, robot, t_total, w, bound_s, room_s)?;
                scratch.offsets_s.push(offset_s);
                scratch.durs_s.push(dur);
                t_total = t_total.max(offset_s + dur);
                if robot + 1 < self.n_robots {
                    self.lc_of_factors(scratch, robot, offset_s);
                }
            }
            return Some(t_total);
        }
        let (f0, f1) = scratch.factors.split_at_mut(1);
        let (lc0, lc1) = scratch.lc.split_at_mut(1);
        let dur = [
            self.draw_robot(&mut rng, &mut f0[0], &mut lc0[0]),
            self.draw_robot(&mut rng, &mut f1[0], &mut lc1[0]),
        ];
        let v = rng.random::<f64>();
        let offset_s = match self.offset {
            OffsetSampling::Drawn(DrawnOffset::Uniform) => {
                let offset_s = v * dur[0];
                (!overlaps(&scratch.lc[0], &scratch.lc[1], offset_s)).then_some(offset_s)
            }
            OffsetSampling::Drawn(DrawnOffset::UniformFeasible) => {
                feasible_offset(scratch, dur[0], v)
            }
            OffsetSampling::Fitted { .. } => unreachable!("fitted candidates returned above"),
        }?;
        scratch.durs_s.extend(dur);
        scratch.offsets_s.push(offset_s);
        Some(dur[0].max(offset_s + dur[1]))
    }

    /// Writes robot `robot`'s low-confidence intervals in global time (it starts at
    /// `offset_s`) into `scratch.lc[robot]`, from its factors and the piece sums.
    pub(super) fn lc_of_factors(&self, scratch: &mut Scratch, robot: usize, offset_s: f64) {
        let mut factors = scratch.factors[robot].iter();
        self.walk(offset_s, &mut scratch.lc[robot], || {
            factors.next().copied().unwrap_or(0.0)
        });
    }

    /// Cheap evaluation of candidate `k`: `Some(T_total)` if it beats `bound_s` and has no
    /// low-confidence overlap.
    pub(super) fn cheap(&self, scratch: &mut Scratch, k: u64, bound_s: f64) -> Option<f64> {
        let t_total = self.draw(scratch, k, bound_s)?;
        (t_total < bound_s).then_some(t_total)
    }

    /// The full schedule of candidate `k` (same draws as [`Sampler::cheap`]).
    pub(super) fn materialize(&self, k: u64) -> Option<Schedule> {
        let mut scratch = Scratch::for_robots(self.n_robots);
        self.draw(&mut scratch, k, f64::INFINITY)?;
        let (gmin, gmax, gmean) = (
            self.problem.grad_min(),
            self.problem.grad_max(),
            self.problem.grad_mean(),
        );
        let n_ref = self.problem.n_ref();
        let mut warps = vec![Vec::with_capacity(n_ref); self.n_robots];
        for (robot, (warp, factors)) in warps.iter_mut().zip(&scratch.factors).enumerate() {
            if robot == 0
                && k >= self.params.samples as u64
                && let Some(warm) = &self.warm
            {
                warp.extend_from_slice(&warm.warp);
                continue;
            }
            let mut factors = factors.iter();
            for p in &self.pieces {
                if p.high_conf {
                    let u = *factors.next().expect("one factor was drawn per HC piece");
                    // `ψ̇min + u·(ψ̇max − ψ̇min)` can round one ulp above `ψ̇max` at `u = 1`:
                    // capped, so every stored gradient meets constraint 1 exactly.
                    warp.extend(
                        (p.start..p.end).map(|n| (gmin[n] + u * (gmax[n] - gmin[n])).min(gmax[n])),
                    );
                } else {
                    warp.extend_from_slice(&gmean[p.start..p.end]);
                }
            }
        }
        Some(Schedule {
            grad_exec: warps,
            offsets_s: scratch.offsets_s,
            tick_s: self.tick_s,
            holds: Vec::new(),
        })
    }

    /// Every constraint of Eq. 20 on `s`, with the operator's switch time when
    /// [`crate::SamplerParams::switch_s`] is not 0 ([`validate_with_switch`], whose margin
    /// check has one implementation), else with the baselines' margin check.
    fn passes(&self, s: &Schedule) -> bool {
        let switch_s = self.params.switch_s;
        if switch_s > 0.0 {
            validate_with_switch(self.problem, s, switch_s).is_ok()
        } else {
            validate_full(self.problem, s, self.margin_check).is_ok()
        }
    }

    /// Full constraints of candidate `k`: the schedule and its `T_total` if feasible.
    pub(super) fn full(&self, k: u64) -> Option<(Schedule, f64)> {
        let mut s = self.materialize(k)?;
        let mut ok = self.passes(&s);
        if !ok && self.has_holds {
            // With hold points the order of the stretches can be enforced at run time: the
            // same candidate with release rules. For two robots only when their planned waits
            // leave its T_total as it was (half a tick of rounding): a candidate the rules make
            // longer would win out of its place in the `T_total` order the candidates are
            // checked in, ahead of shorter ones (zoo deburring: 33.4 s where 29.1 s passed),
            // and the held completion plans such waits (docs/decisions.md, "Two robots with
            // holds near their bound").
            if let Ok(held) = self.problem.with_release_rules(&s)
                && held.has_holds()
                && (self.n_robots != 2
                    || held.t_total_s(self.problem.dt_s())
                        <= s.t_total_s(self.problem.dt_s()) + 0.5 * self.tick_s)
            {
                ok = self.passes(&held);
                s = held;
            }
        }
        ok.then(|| {
            let t = s.t_total_s(self.problem.dt_s());
            (s, t)
        })
    }
}
