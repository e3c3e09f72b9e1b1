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

use std::collections::BTreeMap;

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

/// One candidate operator sequence: the coordinator it leads to and what it has done.
#[derive(Clone)]
struct Candidate {
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
}

/// The lesser of two shortest switches (`None`: none measured).
fn min_gap(a: Option<u64>, b: Option<u64>) -> Option<u64> {
    a.into_iter().chain(b).min()
}

/// The run of a sequence that overlapped at tick `first`: continued without corrections to the
/// end (or to `max_ticks`), counting every overlapping tick; `gaps` the sequence's switches so
/// far, `least_gap` the shortest switch of the other sequences expanded.
fn finish(
    mut coordinator: Coordinator,
    (mut ticks, first, max_ticks): (u64, u64, u64),
    mut backward_steps: u64,
    mut gaps: SwitchGaps,
    least_gap: Option<u64>,
) -> Result<AdversaryRun> {
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
    Ok(AdversaryRun {
        ticks,
        overlap_ticks,
        first_overlap: Some(first),
        finished: coordinator.is_finished(),
        backward_steps,
        min_tasks: u64::from(coordinator.is_finished()),
        min_switch_gap_ticks: min_gap(gaps.min_gap_ticks(), least_gap),
    })
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
    let width = width.max(1);
    // One cell per nominal tick of progress: every robot one tick on schedule.
    let cell_s = coordinator.tick_s() * coordinator.n_robots() as f64;
    let progress = |c: &Coordinator| (c.rule_clock_s().iter().sum::<f64>() / cell_s).floor() as i64;
    let mut cells: BTreeMap<i64, Vec<Candidate>> = BTreeMap::new();
    let clearance = min_clearance_s(&coordinator);
    let start = Candidate {
        now_s: clearance,
        worst_s: clearance,
        coordinator,
        ticks: 0,
        backward_steps: 0,
        gaps: SwitchGaps::default(),
    };
    // The shortest switch over every sequence expanded so far.
    let mut least_gap: Option<u64> = None;
    cells
        .entry(progress(&start.coordinator))
        .or_default()
        .push(start);
    let mut best_finished: Option<Candidate> = None;
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
                if tick.overlap() {
                    return finish(
                        next.coordinator,
                        (next.ticks, cand.ticks, max_ticks),
                        next.backward_steps,
                        next.gaps,
                        least_gap,
                    );
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
    Ok(
        best_finished.map_or(AdversaryRun::default(), |b| AdversaryRun {
            ticks: b.ticks,
            overlap_ticks: 0,
            first_overlap: None,
            finished: b.coordinator.is_finished(),
            backward_steps: b.backward_steps,
            min_tasks: u64::from(b.coordinator.is_finished()),
            min_switch_gap_ticks: least_gap,
        }),
    )
}
