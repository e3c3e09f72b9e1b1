//! The search adversary: a beam search over the operator's per-tick choices that drives the
//! robots towards the smallest clearance between low-confidence regions, comparing candidate
//! sequences at equal progress rather than at equal tick counts.
//!
//! Comparing at equal ticks is the flaw of a per-tick maximum (docs/decisions.md, "The N-robot
//! margin check: a lead bound per unit of progress"): dragging gains less lead per tick than
//! rushing but more per unit of progress, so after `k` ticks a dragging sequence looks safer
//! than a rushing one although it ends closer to an overlap. Here every state is filed under its
//! progress (the sum of all robots' schedule clocks, in cells of one nominal tick of every robot), the cells are
//! expanded in order of progress, and each cell keeps the `width` states with the smallest
//! clearance now (then the smallest along the way, then the fewest ticks).
//!
//! Every sequence the search runs is an admissible operator's execution (a prefix of one), so
//! the switches it traverses are measured as in a policy's run ([`SwitchGaps`], issue 41): the
//! search reports the shortest switch over *all* the sequences it expanded, pruned ones
//! included, not only over the one it returns.
//!
//! [`beam_search_run`] is the same search that also hands back the sequence it returns: its
//! operator inputs, tick by tick, and the coordinator they lead to (for counts read from the
//! coordinator at the end of a round, such as the operator's busy ticks and the rest of the
//! load cap, issue 41). [`beam_search`] keeps no sequence: its cost is as before.

use std::collections::BTreeMap;
use std::rc::Rc;

use super::{AdversaryRun, Backward, SwitchGaps};
use crate::{Coordinator, Operator, Result, Timeline};

/// The operator inputs the search tries at every tick.
const CHOICES: [Operator; 3] = [Operator::Fastest, Operator::Slowest, Operator::Scheduled];

/// The smallest clearance (schedule-clock s) between two robots' low-confidence regions in the
/// state of `coordinator`, over ordered pairs `(i, j)` where `i`'s current-or-next region `R_i`
/// starts no later than `j`'s next region `R_j`: `(R_j.start − s_j) − (R_i.end − s_i)`, how far
/// `j` still is from entering `R_j` minus how far `i` still is from leaving `R_i`. Negative when,
/// at equal speeds, `j` would enter before `i` leaves; `+∞` without such a pair.
#[must_use]
pub fn min_clearance_s(coordinator: &Coordinator) -> f64 {
    // With holds, each robot's current leg (without, its timeline).
    let robots: Vec<&Timeline> = (0..coordinator.n_robots())
        .map(|i| coordinator.current_plan(i))
        .collect();
    let clocks = coordinator.rule_clock_s();
    // Regions are in time order: binary searches.
    let current = |r: &Timeline, s: f64| {
        let ivs = r.lc_intervals();
        ivs.get(ivs.partition_point(|iv| iv.end_s <= s)).copied()
    };
    let upcoming = |r: &Timeline, s: f64| {
        let ivs = r.lc_intervals();
        ivs.get(ivs.partition_point(|iv| iv.start_s <= s)).copied()
    };
    let mut best = f64::INFINITY;
    for (i, (&ri, &si)) in robots.iter().zip(clocks).enumerate() {
        let Some(a) = current(ri, si) else { continue };
        for (j, (&rj, &sj)) in robots.iter().zip(clocks).enumerate() {
            if i == j || sj >= rj.end_s() {
                continue;
            }
            let Some(b) = upcoming(rj, sj) else { continue };
            if a.start_s <= b.start_s {
                best = best.min((b.start_s - sj) - (a.end_s - si));
            }
        }
    }
    best
}

/// What a candidate keeps of its operator sequence: nothing ([`beam_search`]) or its inputs as a
/// shared list from the last back to the first ([`beam_search_run`]; a clone is one pointer).
trait Trail: Clone + Default {
    /// The trail with `op` appended.
    fn then(&self, op: Operator) -> Self;
}

impl Trail for () {
    fn then(&self, _: Operator) -> Self {}
}

/// One input of a kept sequence and the inputs before it.
struct Step {
    op: Operator,
    before: Option<Rc<Step>>,
}

impl Drop for Step {
    /// Drops the list from this node back without recursion (a sequence has up to a round's
    /// ticks): each earlier node no other candidate shares is taken apart in turn.
    fn drop(&mut self) {
        let mut before = self.before.take();
        while let Some(node) = before {
            match Rc::try_unwrap(node) {
                Ok(mut step) => before = step.before.take(),
                Err(_) => break,
            }
        }
    }
}

/// The inputs of a sequence, last first (`None`: no tick yet).
#[derive(Clone, Default)]
struct Inputs(Option<Rc<Step>>);

impl Trail for Inputs {
    fn then(&self, op: Operator) -> Self {
        Self(Some(Rc::new(Step {
            op,
            before: self.0.clone(),
        })))
    }
}

impl Inputs {
    /// The inputs first to last.
    fn to_vec(&self) -> Vec<Operator> {
        let mut ops = Vec::new();
        let mut at = self.0.as_deref();
        while let Some(step) = at {
            ops.push(step.op);
            at = step.before.as_deref();
        }
        ops.reverse();
        ops
    }
}

/// One candidate operator sequence: the coordinator it leads to and what it has done.
#[derive(Clone)]
struct Candidate<T> {
    coordinator: Coordinator,
    ticks: u64,
    /// [`min_clearance_s`] now.
    now_s: f64,
    /// The smallest [`min_clearance_s`] along the sequence so far.
    worst_s: f64,
    /// Ticks of the sequence in which a robot moved backwards ([`super::Backward`]).
    backward_steps: u64,
    /// The switches of the sequence so far, on the ticks it traversed.
    gaps: SwitchGaps,
    /// Its operator inputs, if kept.
    trail: T,
}

/// The lesser of two shortest switches (`None`: none measured).
fn min_gap(a: Option<u64>, b: Option<u64>) -> Option<u64> {
    a.into_iter().chain(b).min()
}

/// The run of a sequence that overlapped at tick `first`: continued without corrections to the
/// end (or to `max_ticks`), counting every overlapping tick; `gaps` the sequence's switches so
/// far, `least_gap` the shortest switch of the other sequences expanded. Returns the run and the
/// coordinator at its end.
fn finish(
    mut coordinator: Coordinator,
    (mut ticks, first, max_ticks): (u64, u64, u64),
    mut backward_steps: u64,
    mut gaps: SwitchGaps,
    least_gap: Option<u64>,
) -> Result<(AdversaryRun, Coordinator)> {
    let mut overlap_ticks = 1;
    let mut backward = Backward::new(&coordinator);
    while !coordinator.is_finished() && ticks < max_ticks {
        coordinator.clear_fault();
        let tick = coordinator.tick(Operator::Scheduled)?;
        overlap_ticks += u64::from(tick.overlap());
        backward_steps += u64::from(backward.step(&coordinator, &tick));
        gaps.record(ticks, &tick.low_conf);
        ticks += 1;
    }
    let run = AdversaryRun {
        ticks,
        overlap_ticks,
        first_overlap: Some(first),
        finished: coordinator.is_finished(),
        backward_steps,
        min_tasks: u64::from(coordinator.is_finished()),
        min_switch_gap_ticks: min_gap(gaps.min_gap_ticks(), least_gap),
    };
    Ok((run, coordinator))
}

/// Runs the beam search of the [module docs](self) with `width` states per progress cell from
/// the coordinator's current state, for at most `max_ticks` ticks along any sequence. Returns
/// the first sequence that makes two robots low-confidence in one tick (`overlap_ticks = 1`,
/// `first_overlap` its tick), or else the run of the sequence with the smallest clearance that
/// finished. Its `min_switch_gap_ticks` is the shortest switch over every sequence expanded
/// (each an admissible operator's execution), measured on the ticks it traversed.
///
/// # Errors
/// None in practice (the choices are always admissible); a coordinator error is passed on.
pub fn beam_search(coordinator: Coordinator, width: usize, max_ticks: u64) -> Result<AdversaryRun> {
    Ok(search::<()>(coordinator, width, max_ticks)?.0)
}

/// The sequence [`beam_search_run`] returns: the run [`beam_search`] reports, the operator
/// inputs of its sequence and the coordinator they lead to.
#[derive(Clone)]
pub struct BeamEnd {
    /// What [`beam_search`] reports for the same arguments.
    pub run: AdversaryRun,
    /// The operator input of each tick of the returned sequence, first to last (`run.ticks`
    /// of them). Given, tick by tick, to a clone of the coordinator the search started from,
    /// they reproduce `coordinator`; after an overlap (`run.first_overlap`) the sequence goes
    /// on with [`Operator::Scheduled`], the fault cleared before each tick
    /// ([`Coordinator::clear_fault`]), as the search runs it.
    pub operators: Vec<Operator>,
    /// The coordinator at the end of the sequence (its counts of the round: ticks, the
    /// operator's busy ticks and the rest of the load cap, [`Coordinator::rest_ticks`]).
    pub coordinator: Coordinator,
}

/// [`beam_search`] that also returns the sequence it reports ([`BeamEnd`]): the same search,
/// the same candidates kept and the same [`AdversaryRun`], with every candidate keeping its
/// inputs (one shared list node per tick; [`beam_search`] keeps none). Used where a count of
/// the sequence is read from its coordinator or from its ticks (tests of the load cap's rest
/// and of the pre-alert, issue 41).
///
/// # Errors
/// As [`beam_search`].
pub fn beam_search_run(coordinator: Coordinator, width: usize, max_ticks: u64) -> Result<BeamEnd> {
    let start = coordinator.clone();
    let (run, end) = search::<Inputs>(coordinator, width, max_ticks)?;
    Ok(match end {
        Some((coordinator, inputs, after)) => {
            let mut operators = inputs.to_vec();
            operators.extend(std::iter::repeat_n(Operator::Scheduled, after));
            BeamEnd {
                run,
                operators,
                coordinator,
            }
        }
        // No sequence kept (not reached: every expanded sequence ends finished or at
        // `max_ticks`): the start, no tick.
        None => BeamEnd {
            run,
            operators: Vec::new(),
            coordinator: start,
        },
    })
}

/// The search of [`beam_search`], each candidate keeping the trail `T` of its inputs. Returns
/// the run and, for the sequence reported, its end coordinator, its trail and the number of
/// [`Operator::Scheduled`] ticks run after its first overlap (0 without one).
#[allow(
    clippy::type_complexity,
    reason = "one private function's result, named in its doc comment"
)]
fn search<T: Trail>(
    coordinator: Coordinator,
    width: usize,
    max_ticks: u64,
) -> Result<(AdversaryRun, Option<(Coordinator, T, usize)>)> {
    let width = width.max(1);
    // One cell per nominal tick of progress: every robot one tick on schedule.
    let cell_s = coordinator.tick_s() * coordinator.n_robots() as f64;
    let progress = |c: &Coordinator| (c.rule_clock_s().iter().sum::<f64>() / cell_s).floor() as i64;
    let mut cells: BTreeMap<i64, Vec<Candidate<T>>> = BTreeMap::new();
    let clearance = min_clearance_s(&coordinator);
    let start = Candidate {
        now_s: clearance,
        worst_s: clearance,
        coordinator,
        ticks: 0,
        backward_steps: 0,
        gaps: SwitchGaps::default(),
        trail: T::default(),
    };
    // The shortest switch over every sequence expanded so far.
    let mut least_gap: Option<u64> = None;
    cells
        .entry(progress(&start.coordinator))
        .or_default()
        .push(start);
    let mut best_finished: Option<Candidate<T>> = None;
    while let Some((_, mut cell)) = cells.pop_first() {
        cell.sort_by(|a, b| {
            (a.now_s.total_cmp(&b.now_s))
                .then(a.worst_s.total_cmp(&b.worst_s))
                .then(a.ticks.cmp(&b.ticks))
        });
        cell.truncate(width);
        for cand in cell {
            if cand.coordinator.is_finished() || cand.ticks >= max_ticks {
                if best_finished
                    .as_ref()
                    .is_none_or(|b| cand.worst_s < b.worst_s)
                {
                    best_finished = Some(cand);
                }
                continue;
            }
            for op in CHOICES {
                let mut next = cand.clone();
                let mut backward = Backward::new(&next.coordinator);
                let tick = next.coordinator.tick(op)?;
                next.ticks += 1;
                next.backward_steps += u64::from(backward.step(&next.coordinator, &tick));
                next.gaps.record(cand.ticks, &tick.low_conf);
                next.trail = next.trail.then(op);
                if tick.overlap() {
                    let ticks = next.ticks;
                    let (run, end) = finish(
                        next.coordinator,
                        (next.ticks, cand.ticks, max_ticks),
                        next.backward_steps,
                        next.gaps,
                        least_gap,
                    )?;
                    // The ticks `finish` ran after the overlapping one.
                    let after = usize::try_from(run.ticks - ticks).unwrap_or(usize::MAX);
                    return Ok((run, Some((end, next.trail, after))));
                }
                least_gap = min_gap(least_gap, next.gaps.min_gap_ticks());
                next.now_s = min_clearance_s(&next.coordinator);
                next.worst_s = next.worst_s.min(next.now_s);
                cells
                    .entry(progress(&next.coordinator))
                    .or_default()
                    .push(next);
            }
        }
    }
    Ok(match best_finished {
        Some(b) => (
            AdversaryRun {
                ticks: b.ticks,
                overlap_ticks: 0,
                first_overlap: None,
                finished: b.coordinator.is_finished(),
                backward_steps: b.backward_steps,
                min_tasks: u64::from(b.coordinator.is_finished()),
                min_switch_gap_ticks: least_gap,
            },
            Some((b.coordinator, b.trail, 0)),
        ),
        None => (AdversaryRun::default(), None),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two robots of [HC, LC, LC, HC, HC, HC] at 1 s per sample, bounds [0.8, 1.25], the second
    /// starting `offset_s` after the first, tick 0.05 s.
    fn round(offset_s: f64) -> Coordinator {
        let conf = [true, false, false, true, true, true];
        let (mean, lo, hi) = ([1.0; 6], [0.8; 6], [1.25; 6]);
        let robots = vec![
            Timeline::new(&conf, &mean, &lo, &hi, 0.0, 0.1).unwrap(),
            Timeline::new(&conf, &mean, &lo, &hi, offset_s, 0.1).unwrap(),
        ];
        Coordinator::new_unchecked(robots, 0.05).unwrap()
    }

    /// `beam_search_run` reports exactly `beam_search`'s run, and its operator inputs, given to
    /// a clone of the start, lead to its end coordinator: the same ticks, clocks, end, busy
    /// ticks and rest (a safe round with a load cap of ½, where the search finishes), and the
    /// same after an overlap (both robots starting together: the search stops at the first
    /// overlapping tick and runs on without corrections, the fault cleared before each tick).
    #[test]
    fn the_run_variant_reports_the_search_and_its_inputs_replay_it() {
        for (offset_s, overlaps) in [(0.45, false), (0.0, true)] {
            let start = round(offset_s).with_max_busy_share(0.5).unwrap();
            for width in [1, 4] {
                let run = beam_search(start.clone(), width, 5_000).unwrap();
                let end = beam_search_run(start.clone(), width, 5_000).unwrap();
                assert_eq!(end.run, run);
                assert_eq!(run.overlap_ticks > 0, overlaps, "{run:?}");
                assert_eq!(run.finished, !overlaps || end.coordinator.is_finished());
                assert_eq!(end.operators.len() as u64, run.ticks);
                let mut replay = start.clone();
                let mut overlap_ticks = 0;
                for (i, &op) in end.operators.iter().enumerate() {
                    if run.first_overlap.is_some_and(|f| i as u64 > f) {
                        replay.clear_fault();
                    }
                    overlap_ticks += u64::from(replay.tick(op).unwrap().overlap());
                }
                assert_eq!(overlap_ticks, run.overlap_ticks);
                let c = &end.coordinator;
                assert_eq!(replay.ticks(), c.ticks());
                assert_eq!(replay.clock_s(), c.clock_s());
                assert_eq!(replay.is_finished(), c.is_finished());
                assert_eq!(replay.busy_ticks(0), c.busy_ticks(0));
                assert_eq!(replay.rest_ticks(), c.rest_ticks());
                assert!(c.busy_ticks(0).is_some_and(|b| b > 0));
                if !overlaps {
                    // The sequence is not all one input: the search mixes its choices.
                    assert!(end.operators.iter().any(|&o| o != end.operators[0]));
                }
            }
        }
    }
}
