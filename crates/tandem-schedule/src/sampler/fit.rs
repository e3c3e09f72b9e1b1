//! Fitting robots 2..N: the exact sweep over a robot's pieces that finds its earliest finish
//! clear of the earlier robots' widened low-confidence intervals.

use super::offsets::sort_and_merge;
use super::{Sampler, Scratch};

impl Sampler<'_> {
    /// Fitted robot `robot` (≥ 1; robot 2 for two robots): its earliest finish given the
    /// low-confidence intervals of robots `0..robot` in `scratch.lc` (global time; robot 1
    /// starts at 0), each widened by `δ = w·length + 2·tick_s` (plus the operator's switch
    /// time's room `switch_room_s`, s, 0 without one), over `τ ∈ [0, latest_end_s]`
    /// (the latest end of the earlier robots, s; `|ψ_E1|` for robot 2) and the robot's
    /// per-piece durations. Writes its factors into `scratch.factors[robot]`; returns
    /// `(τ, |ψ_E|)`, or `None` when it cannot finish before `bound_s` clear of the earlier
    /// robots.
    ///
    /// The sweep keeps, for each piece, the set of its feasible start times as sorted
    /// disjoint intervals: a high-confidence piece of durations `[d_min, d_max]` maps `[x, y]`
    /// to `[x + d_min, y + d_max]`; a low-confidence piece of duration `L` keeps the starts
    /// `s` with `[s, s + L]` inside a gap between forbidden intervals, shifted by `L`. Starts
    /// from which even the fastest rest of robot 2 would end at or after `bound_s` are cut.
    /// The earliest end is then traced back, each high-confidence piece taking its shortest
    /// duration that still meets the start set before it (the fastest speeds: the most room
    /// for the coordinator to slow that robot down while the other is dragged).
    pub(super) fn fit_next(
        &self,
        scratch: &mut Scratch,
        robot: usize,
        latest_end_s: f64,
        w: f64,
        bound_s: f64,
        switch_room_s: f64,
    ) -> Option<(f64, f64)> {
        let dur0 = latest_end_s;
        let margin = 2.0 * self.tick_s;
        let forbidden = &mut scratch.forbidden;
        forbidden.clear();
        // With the operator's switch time `δ` the fitted robot's runs keep `switch_room_s` (`δ`
        // or `δ·F`, `Sampler::switch_room_s`) more on both sides of every earlier robot's run:
        // (3δ) of `validate_with_switch` on schedule, and room for the margin check's `k·M_c`.
        let switch_s = switch_room_s;
        if switch_s > 0.0 {
            forbidden.extend(scratch.lc[..robot].iter().flatten().map(|iv| {
                let d = w * (iv.end_s - iv.start_s) + margin + switch_s;
                (iv.start_s - d, iv.end_s + d)
            }));
        } else {
            forbidden.extend(scratch.lc[..robot].iter().flatten().map(|iv| {
                let d = w * (iv.end_s - iv.start_s) + margin;
                (iv.start_s - d, iv.end_s + d)
            }));
        }
        sort_and_merge(forbidden);
        let forbidden = &scratch.forbidden;
        // Gap g lies between forbidden[g − 1] and forbidden[g] (unbounded at both ends).
        // Starts of a piece of length `len` inside gap g, `w·len` clear of both ends.
        let gap = |g: usize, len: f64| -> (f64, f64) {
            let pad = w * len;
            let lo = if g == 0 {
                f64::NEG_INFINITY
            } else {
                forbidden[g - 1].1 + pad
            };
            let hi = forbidden.get(g).map_or(f64::INFINITY, |f| f.0 - len - pad);
            (lo, hi)
        };

        let sets = &mut scratch.sets;
        let starts = &mut scratch.set_starts;
        sets.clear();
        starts.clear();
        let n_pieces = self.pieces.len();
        let hi0 = dur0.min(bound_s - self.suffix_min_s[0]);
        if hi0 < 0.0 {
            return None;
        }
        starts.push(0);
        sets.push((0.0, hi0));
        for (p, piece) in self.pieces.iter().enumerate() {
            let (from, to) = (starts[p], sets.len());
            let cap = bound_s - self.suffix_min_s[p + 1];
            starts.push(to);
            let push = |sets: &mut Vec<(f64, f64)>, lo: f64, hi: f64| {
                let hi = hi.min(cap);
                if lo > hi {
                    return;
                }
                let fresh = sets.len() == to;
                match sets.last_mut() {
                    Some(last) if !fresh && lo <= last.1 => last.1 = last.1.max(hi),
                    _ => sets.push((lo, hi)),
                }
            };
            if piece.high_conf {
                let (d_min, d_max) = (piece.min_s, piece.min_s + piece.span_s);
                for i in from..to {
                    let (x, y) = sets[i];
                    push(sets, x + d_min, y + d_max);
                }
            } else {
                let len = piece.min_s;
                let x_min = sets[from].0;
                let mut g = forbidden.partition_point(|f| f.0 - len - w * len < x_min);
                let mut i = from;
                while i < to && g <= forbidden.len() {
                    let (x, y) = sets[i];
                    let (glo, ghi) = gap(g, len);
                    let (lo, hi) = (x.max(glo), y.min(ghi));
                    if lo <= hi {
                        push(sets, lo + len, hi + len);
                    }
                    if y < ghi {
                        i += 1;
                    } else {
                        g += 1;
                    }
                }
            }
            if sets.len() == starts[p + 1] {
                return None;
            }
        }

        // Trace the earliest end back.
        let factors = &mut scratch.factors[robot];
        factors.clear();
        let mut e = sets[starts[n_pieces]].0;
        if e >= bound_s {
            return None;
        }
        for (p, piece) in self.pieces.iter().enumerate().rev() {
            if !piece.high_conf {
                e -= piece.min_s;
                continue;
            }
            let set = &sets[starts[p]..starts[p + 1]];
            let (d_min, d_max) = (piece.min_s, piece.min_s + piece.span_s);
            let latest = e - d_min;
            let idx = set.partition_point(|iv| iv.0 <= latest).max(1) - 1;
            let s = set[idx].1.min(latest).max(e - d_max);
            let u = if piece.span_s > 0.0 {
                ((e - s - d_min) / piece.span_s).clamp(0.0, 1.0)
            } else {
                0.0
            };
            factors.push(u);
            e = s;
        }
        factors.reverse();
        let tau = e.clamp(0.0, dur0);
        let mut dur1 = 0.0;
        let mut f = factors.iter();
        for p in &self.pieces {
            dur1 += if p.high_conf {
                p.min_s + f.next().copied().unwrap_or(0.0) * p.span_s
            } else {
                p.min_s
            };
        }
        Some((tau, dur1))
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::scratch;
    use super::*;
    use crate::problem::Problem;
    use crate::sampler::{SamplerBaselines, SamplerParams};

    /// [LC ×10, HC ×20, LC ×10] at 0.1 s per sample, gradients 1 in [0.5, 2]: pieces LC
    /// 1 s, HC 1–4 s, LC 1 s.
    fn three_runs() -> Problem {
        let conf: Vec<bool> = (0..40).map(|n| (10..30).contains(&n)).collect();
        crate::problem::unit_gradients(conf, (0.5, 2.0), 0.1)
    }

    #[test]
    fn fitted_robot_2_by_hand() {
        let p = three_runs();
        let params = SamplerParams::default();
        let sampler = Sampler::new(&p, 2, &params, &SamplerBaselines::default(), 0.1, None);
        // Robot 1 runs its HC piece at the slowest (4 s): LC [0, 1) and [5, 6), 6 s long.
        let mut s = scratch(&[(0.0, 1.0), (5.0, 6.0)], &[]);
        // w = 0: forbidden [−0.2, 1.2] and [4.8, 6.2] (two ticks of 0.1 s). Robot 2's first
        // LC starts in [1.2, 3.8] and ends in [2.2, 4.8]; its HC piece (1–4 s) reaches
        // [3.2, 8.8]; its last LC must start in [3.2, 3.8] or from 6.2: earliest end 4.2,
        // traced back with the HC piece at its shortest (u = 0) and τ = 1.2.
        let (tau, dur) = sampler
            .fit_next(&mut s, 1, 6.0, 0.0, f64::INFINITY, 0.0)
            .unwrap();
        assert!(
            (tau - 1.2).abs() < 1e-9 && (dur - 3.0).abs() < 1e-9,
            "{tau} {dur}"
        );
        assert_eq!(s.factors[1], [0.0]);
        // w = 0.1: robot 1's regions grow by 0.1·1 + 0.2 s and robot 2's LC keeps 0.1 s
        // clear: starts [1.4, 3.6] → earliest end 4.4 with τ = 1.4.
        let (tau, dur) = sampler
            .fit_next(&mut s, 1, 6.0, 0.1, f64::INFINITY, 0.0)
            .unwrap();
        assert!(
            (tau - 1.4).abs() < 1e-9 && (dur - 3.0).abs() < 1e-9,
            "{tau} {dur}"
        );
        // An incumbent of 4 s cuts every start: robot 2 needs 3 s and cannot start before 1.2.
        assert_eq!(sampler.fit_next(&mut s, 1, 6.0, 0.0, 4.0, 0.0), None);
        // Robot 1 at its fastest (LC [0, 1) and [2, 3)): no gap holds a 1 s region before
        // τ's upper end |ψ_E1| = 3 s, so robot 2 cannot be fitted.
        let mut s = scratch(&[(0.0, 1.0), (2.0, 3.0)], &[]);
        assert_eq!(
            sampler.fit_next(&mut s, 1, 3.0, 0.0, f64::INFINITY, 0.0),
            None
        );
    }
}
