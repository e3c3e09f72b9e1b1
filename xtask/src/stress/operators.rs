//! `cargo xtask stress --operators M` (issue 44): the `M`-operator invariant under load, in
//! rounds and in the continuous cell.
//!
//! Every execution runs `M` operators, each with its own copy of the execution's policy of the
//! adversary set on the robot it supervises
//! (`tandem::realtime::adversary::operators::run_operators_on`; the beam search searches one
//! operator's sequence and runs as a switching favourite per operator), and counts the ticks
//! with more than `M` robots low-confidence, the stretches handed over mid-way (a robot
//! low-confidence in two consecutive ticks of one task under two operators; a new operator
//! where a task's last stretch runs into the next task's first is two stretches, counted
//! apart), the ticks in which an operator
//! is on two robots or a low-confidence robot has none, the faults, the backward steps and,
//! with `--switch-s`, each operator's switches shorter than `k` ticks. Every one of them must
//! be 0; every number depends only on the flags and the seed.
//!
//! - *Rounds*: the sectored round the planner runs with `M > 1` (`Coordinator::sectored`;
//!   docs/decisions.md, "M operators in rounds: sectors end to end"): the `N` robots split
//!   evenly into `M` sectors of consecutive robots (the first `N mod M` one robot larger, as
//!   `tandem_schedule::sectors`), one test kit case of every family per problem
//!   (`testkit::Case::random`), each sector's robots made tight at an edge of the one-operator
//!   check at the case's tick and switch time (`check_margins`; `testkit::tight_starts`, robot
//!   0 of every sector at 0, so the sectors' stretches meet), run by `Coordinator::sectored`
//!   (which checks every sector again). [`Adversary::Beam`] runs as the beam search of every
//!   sector's own one-operator round (`Coordinator::with_margins` of the sector's robots, which
//!   the sectored coordinator ticks exactly, `tests/sectors.rs`) and, on the sectored round,
//!   as the switching favourite per operator. Holds are refused with `M > 1`.
//! - *Continuous*: the problems of the one-operator continuous stress ([`super::make_cell_case`]:
//!   this task's random problems with and without hold points, the test kit's shared-mask
//!   families), each planned by `cyclic_plan` and run with `M` tokens
//!   (`ContinuousCoordinator::with_operators`) until every robot has completed `--tasks`.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use anyhow::{Context, bail};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use tandem::realtime::adversary::Adversary;
use tandem::realtime::adversary::operators::{OperatorsRun, run_operators_on};
use tandem::realtime::adversary::run_adversary;
use tandem::realtime::testkit::{self, Family};
use tandem::realtime::{
    Controller, Coordinator, MarginParams, OperatorCount, Timeline, check_margins,
};

/// Draws of a test kit case per problem before giving up (a case some sector of which has no
/// accepted start, not even the serial one, is drawn again).
const MAX_DRAWS: u64 = 50;

/// One case of the run: a controller (cloned per execution), its policies and budget.
struct OpCase<C> {
    controller: C,
    adversaries: Vec<Adversary>,
    max_ticks: u64,
    family: &'static str,
    /// Whether some robot starts before the robots placed before it have ended (rounds: in
    /// some sector).
    overlapping: bool,
    /// `k`, the switch time in ticks.
    switch_ticks: u64,
    /// Rounds: every sector's own one-operator round, for the beam search per sector.
    sectors: Vec<Coordinator>,
}

/// The sizes of `m` sectors of `n` robots: as even as possible, the larger first.
fn sector_sizes(n: usize, m: usize) -> Vec<usize> {
    (0..m).map(|o| n / m + usize::from(o < n % m)).collect()
}

/// A sectored rounds case of `n` robots and `m` operators at switch time `switch_s`: the first
/// of up to [`MAX_DRAWS`] test kit draws whose every sector has starts `tight_starts` finds at
/// the one-operator check.
fn rounds_case(
    seed: u64,
    index: u64,
    n: usize,
    m: OperatorCount,
    switch_s: f64,
) -> anyhow::Result<OpCase<Coordinator>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x0044_0044);
    rng.set_stream(index);
    let sizes = sector_sizes(n, m.get());
    'draw: for attempt in 0..MAX_DRAWS {
        let family = Family::ALL[((index + attempt) % Family::ALL.len() as u64) as usize];
        let case = testkit::Case::random(family, sizes[0], &mut rng);
        let params = MarginParams {
            tick_s: case.tick_s,
            switch_s,
        };
        let k = params.switch_ticks()?;
        let check = |robots: &[Timeline], _: f64| check_margins(robots, &[], &params);
        let (mut robots, mut sector_of, mut sectors) = (Vec::new(), Vec::new(), Vec::new());
        let mut overlapping = false;
        for (o, &g) in sizes.iter().enumerate() {
            let mut sub = case.clone();
            sub.plans.truncate(g);
            let Some((starts, over)) = testkit::tight_starts(&sub, check, &mut rng) else {
                continue 'draw;
            };
            overlapping |= over;
            let own = sub.robots_at(&starts);
            sectors.push(Coordinator::with_margins(own.clone(), &[], &params)?);
            robots.extend(own);
            sector_of.extend(std::iter::repeat_n(o, g));
        }
        let budget = testkit::adversary_budget(&robots, &[], case.tick_s);
        let controller = Coordinator::sectored(robots.clone(), &[], &sector_of, m, &params)?;
        return Ok(OpCase {
            adversaries: case.adversaries(&robots, &mut rng),
            controller,
            max_ticks: budget,
            family: family.name(),
            overlapping,
            switch_ticks: k,
            sectors,
        });
    }
    bail!(
        "no test kit case of {MAX_DRAWS} draws has starts the one-operator check accepts in every sector"
    )
}

/// A continuous case: [`super::make_cell_case`]'s cell with `m` tokens.
fn cell_case(
    seed: u64,
    index: u64,
    n: usize,
    m: OperatorCount,
    tasks: u64,
    switch_s: f64,
) -> anyhow::Result<OpCase<tandem::realtime::continuous::ContinuousCoordinator>> {
    let c = super::make_cell_case(seed, index, n, tasks, switch_s, 1.0)?;
    let k = c.run.cell.switch_ticks();
    Ok(OpCase {
        controller: c.run.cell.with_operators(m),
        adversaries: c.run.adversaries,
        max_ticks: c.run.max_ticks,
        family: c.family,
        overlapping: true,
        switch_ticks: k,
        sectors: Vec::new(),
    })
}

/// What the executions add up to, from worker threads.
#[derive(Default)]
struct OpTally {
    ticks: AtomicU64,
    over_ticks: AtomicU64,
    handed_over: AtomicU64,
    /// The first execution with a stretch handed over: `(execution, tick, robot)`.
    first_handed_over: std::sync::Mutex<Option<(u64, u64, usize)>>,
    changed_at_task_end: AtomicU64,
    misassigned: AtomicU64,
    faults: AtomicU64,
    backward: AtomicU64,
    unfinished: AtomicU64,
    short_switches: AtomicU64,
    /// Executions with `M` robots low-confidence in some tick (every operator busy at once).
    full: AtomicU64,
    /// Executions in which some operator changed robot (its switch measured).
    switches_measured: AtomicU64,
    tasks: AtomicU64,
    /// Beam searches run on a sector's own round, and the ticks with two robots of one sector
    /// low-confidence they found (expected 0).
    beam_searches: AtomicU64,
    beam_overlaps: AtomicU64,
}

impl OpTally {
    fn add(&self, r: &OperatorsRun, m: usize, k: u64, tasks: u64) {
        let add = |a: &AtomicU64, v: u64| {
            a.fetch_add(v, Ordering::Relaxed);
        };
        add(&self.ticks, r.ticks);
        add(&self.over_ticks, r.over_ticks);
        add(&self.handed_over, r.handed_over);
        add(&self.changed_at_task_end, r.changed_at_task_end);
        add(&self.misassigned, r.misassigned);
        add(&self.faults, r.faults);
        add(&self.backward, r.backward_steps);
        add(&self.unfinished, u64::from(!r.finished));
        add(&self.full, u64::from(r.most_low_conf >= m));
        add(&self.tasks, tasks);
        if let Some(g) = r.min_switch_gap_ticks {
            add(&self.switches_measured, 1);
            add(&self.short_switches, u64::from(g < k));
        }
    }
}

/// `cargo xtask stress --operators M [--cell continuous]`: `executions` executions of `n`
/// robots and `m` operators; fails on any broken invariant (module docs).
#[allow(clippy::too_many_arguments)]
pub(crate) fn run(
    continuous: bool,
    executions: u64,
    seed: u64,
    n: usize,
    m: usize,
    holds: bool,
    tasks: u64,
    switch_s: f64,
    problems: Option<u64>,
) -> anyhow::Result<()> {
    if executions == 0 || tasks == 0 {
        bail!("--executions and --tasks must be ≥ 1");
    }
    tandem::realtime::RobotCount::new(n).map_err(|e| anyhow::anyhow!("--robots: {e}"))?;
    let om = OperatorCount::new(m).map_err(|e| anyhow::anyhow!("--operators: {e}"))?;
    if m > n {
        bail!("--operators {m}: more operators than the {n} robots (give at most --robots)");
    }
    if holds && !continuous {
        bail!(
            "--holds with --operators {m}: rounds with holds run one operator (the hold rules of \
             M > 1 operators are not built); drop --holds or use --cell continuous"
        );
    }
    let n_problems = super::n_problems(executions, problems)?;
    let start = Instant::now();
    if continuous {
        let cases = (0..n_problems)
            .into_par_iter()
            .map(|i| {
                cell_case(seed, i, n, om, tasks, switch_s)
                    .with_context(|| format!("planning problem {i}"))
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        report(
            "continuous",
            &cases,
            executions,
            seed,
            n,
            m,
            switch_s,
            tasks,
            start,
        )
    } else {
        let cases = (0..n_problems)
            .into_par_iter()
            .map(|i| {
                rounds_case(seed, i, n, om, switch_s)
                    .with_context(|| format!("scheduling problem {i}"))
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        report("rounds", &cases, executions, seed, n, m, switch_s, 1, start)
    }
}

/// Runs the executions over `cases` and prints the report; fails on any broken invariant.
#[allow(clippy::too_many_arguments)]
fn report<C: Controller + Clone + Sync>(
    cell: &str,
    cases: &[OpCase<C>],
    executions: u64,
    seed: u64,
    n: usize,
    m: usize,
    switch_s: f64,
    tasks: u64,
    start: Instant,
) -> anyhow::Result<()> {
    let n_problems = cases.len() as u64;
    let mut families: Vec<&str> = cases.iter().map(|c| c.family).collect();
    families.sort_unstable();
    families.dedup();
    let overlapping = cases.iter().filter(|c| c.overlapping).count();
    println!(
        "stress --operators {m} --cell {cell}: {n} robots, {n_problems} problems ({}; {overlapping} \
         with overlapping executions); setting up took {:.1} s",
        families.join(", "),
        start.elapsed().as_secs_f64()
    );
    let set_size = cases[0].adversaries.len() as u64;
    let tally = OpTally::default();
    let run_start = Instant::now();
    let mut done = 0;
    let batch = if tasks > 1 { 1_000 } else { 50_000 };
    while done < executions {
        let end = (done + batch).min(executions);
        (done..end).into_par_iter().try_for_each(|e| {
            let case = &cases[(e % n_problems) as usize];
            let op = case.adversaries[((e / n_problems) % set_size) as usize];
            let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_add(0x9e37_79b9_7f4a_7c15));
            rng.set_stream(e);
            let mut c = case.controller.clone();
            if let Adversary::Beam { .. } = op {
                for sector in &case.sectors {
                    let b = run_adversary(sector.clone(), op, &mut rng, case.max_ticks)?;
                    tally.beam_searches.fetch_add(1, Ordering::Relaxed);
                    tally
                        .beam_overlaps
                        .fetch_add(b.overlap_ticks, Ordering::Relaxed);
                }
            }
            let r = run_operators_on(&mut c, op, &mut rng, tasks, case.max_ticks)?;
            let done_tasks: u64 = c.tasks_now().iter().sum();
            tally.add(&r, m, case.switch_ticks, done_tasks);
            if let Some((tick, robot)) = r.first_handed_over {
                let mut first = tally.first_handed_over.lock().expect("not poisoned");
                if first.is_none_or(|(f, _, _)| e < f) {
                    *first = Some((e, tick, robot));
                }
            }
            anyhow::Ok(())
        })?;
        done = end;
    }
    let secs = run_start.elapsed().as_secs_f64();
    let get = |a: &AtomicU64| a.load(Ordering::Relaxed);
    let beam_overlaps = get(&tally.beam_overlaps);
    let (over, handed, mis, faults, back, unfinished, short) = (
        get(&tally.over_ticks),
        get(&tally.handed_over),
        get(&tally.misassigned),
        get(&tally.faults),
        get(&tally.backward),
        get(&tally.unfinished),
        get(&tally.short_switches),
    );
    println!(
        "stress --operators {m} --cell {cell}: {executions} executions of {n} robots ({set_size} \
         policies per operator, seed {seed}), {} ticks: {over} ticks with more than {m} robots \
         low-confidence, {handed} stretches handed over mid-way, {mis} ticks with an operator on \
         two robots or a robot without one, {faults} faults, {back} backward steps, {unfinished} \
         unfinished (all expected 0); {} executions with {m} robots low-confidence at once; {} \
         new operators where a task's last stretch ran into the next task's first (two \
         stretches); {:.1} tasks per robot per execution; {secs:.1} s",
        get(&tally.ticks),
        get(&tally.full),
        get(&tally.changed_at_task_end),
        get(&tally.tasks) as f64 / (executions * n as u64) as f64,
    );
    if cases.iter().any(|c| !c.sectors.is_empty()) {
        println!(
            "  beam search per sector: {} searches of a sector's own round, {beam_overlaps} ticks \
             with two robots of one sector low-confidence (expected 0)",
            get(&tally.beam_searches)
        );
    }
    if switch_s > 0.0 {
        let ks: Vec<u64> = cases.iter().map(|c| c.switch_ticks).collect();
        println!(
            "  switch time {switch_s} s (k = {}…{} ticks): {short} executions with an operator's \
             switch shorter than k (expected 0) of {} in which an operator changed robot",
            ks.iter().min().unwrap_or(&0),
            ks.iter().max().unwrap_or(&0),
            get(&tally.switches_measured)
        );
    }
    if let Some((e, tick, robot)) = *tally.first_handed_over.lock().expect("not poisoned") {
        println!(
            "  the first stretch handed over: execution {e} (problem {}), tick {tick}, robot {robot} \
             (run_operators_on with max_ticks = {tick} gives the state before it)",
            e % n_problems
        );
    }
    if over + handed + mis + faults + back + unfinished + short + beam_overlaps > 0 {
        bail!(
            "the {m}-operator invariant is broken: {over} ticks over {m}, {handed} handed over, \
             {mis} misassigned, {faults} faults, {back} backward steps, {unfinished} unfinished, \
             {short} short switches, {beam_overlaps} beam overlaps in a sector"
        );
    }
    Ok(())
}
