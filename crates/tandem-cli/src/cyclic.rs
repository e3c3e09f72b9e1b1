//! `tandem schedule --cell continuous`: the cyclic plan of a continuous cell (issue 21;
//! `tandem::schedule::cyclic`, docs/decisions.md "A continuous cell: the cyclic plan and its
//! exact period") as text with a Gantt of two periods, or as JSON.

use std::fmt::Write as _;

use anyhow::{Context, Result, bail};
use tandem::planner::Cell;
use tandem::schedule::CheckedCyclicPlan;
use tandem::schedule::Problem;
use tandem::schedule::cyclic::{CyclicPlan, RobotCycle, TaskShape};

use crate::cli::ScheduleArgs;
use crate::cmd::out;
use crate::gantt::gap_text;

/// Columns of the cyclic Gantt per period (two periods are drawn).
pub(crate) const COLUMNS_PER_PERIOD: usize = 36;

/// `tandem schedule STATE --cell continuous`: loads the state, computes the cyclic plan of
/// its problem for its robot count (`Planner::plan`: the default `CyclicParams`, at the
/// schedule's tick) and prints it.
/// Nothing is saved; the rounds sampler's flags are refused (they would do nothing).
pub(crate) fn schedule_continuous(a: &ScheduleArgs) -> Result<()> {
    let file = a.state.display();
    if a.save {
        bail!(
            "{file}: --save with --cell continuous: the cyclic plan is shown, never saved (the \
             state file keeps the rounds schedule that `tandem record` learns from)"
        );
    }
    if a.sampler.samples.is_some() || a.sampler.seed.is_some() {
        bail!(
            "{file}: --samples/--seed set the rounds sampler; --cell continuous samples \
             nothing (its period is computed exactly for every operator order it searches)"
        );
    }
    let mut planner = crate::state_io::load(&a.state)?;
    // --switch-s/--max-busy/--operators plan this cell with them (shown, not saved: --save is
    // refused).
    let sp = crate::cmd::apply_sampler(planner.params().sampler.clone(), &a.sampler)?;
    planner
        .set_operator(sp.switch_s, sp.max_busy_share)
        .context("--switch-s/--max-busy")?;
    planner.set_operators(sp.operators).context("--operators")?;
    let problem = planner.problem();
    // The planner's plan of the cell, at the schedule's control tick (its hand-overs counted
    // at it, so its period is what the cell does with the planned operator).
    let checked = planner
        .plan(Cell::Continuous)
        .with_context(|| format!("{file}: cannot compute the cyclic plan"))?;
    let Some(plan) = checked.as_continuous().map(CheckedCyclicPlan::plan) else {
        bail!("{file}: the planner gave no cyclic plan for a continuous cell (a bug)");
    };
    if a.json {
        out(&serde_json::to_string_pretty(
            &tandem::planner::json::CyclicPlanJson::from(plan),
        )?);
    } else {
        let sp = &planner.params().sampler;
        out(&plan_text(
            problem,
            plan,
            (sp.switch_s, sp.max_busy_share),
            crate::cmd::verbose(),
        )?);
        if sp.operators > 1 {
            // Which cell the M operators run (issue 44): the pooled cell unless the even
            // sectors measure strictly faster with the planned operator.
            let c = planner.fleet_cell().context("--operators")?;
            let cyclic = checked.as_continuous().expect("checked above");
            let (_, pick) = planner
                .fleet_coordinator(cyclic, tandem::planner::FleetCell::Auto)
                .context("--operators")?;
            if let Some(p) = pick {
                let sizes: Vec<String> = p.sectors.iter().map(usize::to_string).collect();
                let rate = |r: Option<f64>| r.map_or("-".to_string(), |r| format!("{r:.1}"));
                out(&format!(
                    "{} operators run the {} cell: measured with the planned operator, pooled ({} tokens) {} tasks/h, sectors of {} robots {} (planned {}); ceilings {:.1} and {:.1}",
                    sp.operators,
                    p.cell,
                    sp.operators,
                    rate(p.pooled_tasks_per_hour),
                    sizes.join(" + "),
                    rate(p.sectored_tasks_per_hour),
                    rate(p.sectored_planned_tasks_per_hour),
                    c.pooled_bound_tasks_per_hour,
                    c.sectored_bound_tasks_per_hour
                ));
            }
        }
    }
    Ok(())
}

/// A duration (s) as text with two decimals, more below 1 s (three significant digits at
/// least: `76.80`, `0.373`, `0.0912`; zero is `0.00`), and never `-0.00`.
pub(crate) fn secs_text(v: f64) -> String {
    let decimals = if v.abs() >= 1.0 || v == 0.0 {
        2
    } else if v.abs() >= 0.1 {
        3
    } else {
        4
    };
    // `+ 0.0` turns −0 (an empty sum) into 0.
    format!("{:.*}", decimals, v + 0.0)
}

/// A stretch's name in the text: `r2s1` is robot 2's first low-confidence stretch (1-based).
fn stretch_name(robot: usize, lc: usize) -> String {
    format!("r{}s{}", robot + 1, lc + 1)
}

/// The operator's order as turns, `r1s1`, `r2s1`, `r1s2–4`, …: a run of one robot's
/// consecutive stretches is one turn.
fn order_turns(plan: &CyclicPlan) -> Vec<String> {
    let mut parts: Vec<String> = Vec::new();
    let mut k = 0;
    while k < plan.order.len() {
        let first = plan.order[k];
        let mut last = first;
        while let Some(next) = plan.order.get(k + 1) {
            if next.robot == last.robot && next.lc == last.lc + 1 {
                last = *next;
                k += 1;
            } else {
                break;
            }
        }
        let name = stretch_name(first.robot, first.lc);
        parts.push(if last.lc == first.lc {
            name
        } else {
            format!("{name}–{}", last.lc + 1)
        });
        k += 1;
    }
    parts
}

/// Turns of the operator's order printed in full; a longer order is shown by its first
/// [`ORDER_HEAD`] turns and its last one (`--verbose` prints all, `--json` has it).
const ORDER_TURNS_SHOWN: usize = 12;

/// Turns shown at the head of a long order.
const ORDER_HEAD: usize = 8;

/// Stretch durations printed one by one; beyond, their count, total and the longest few.
const DURATIONS_SHOWN: usize = 8;

/// The operator's order as text (`r1s1 → r2s1 → r1s2–4 → …`), whole when short or `all`.
fn order_text(turns: &[String], all: bool) -> String {
    if all || turns.len() <= ORDER_TURNS_SHOWN {
        return turns.join(" → ");
    }
    format!(
        "{} → … ({} turns in all) → {}",
        turns[..ORDER_HEAD].join(" → "),
        turns.len(),
        turns[turns.len() - 1]
    )
}

/// The stretch durations (s, at the mean speed) as text: each one when few or `all`,
/// otherwise the count, the total, the longest few (`s5 3.21 s`: stretch 5 of the task)
/// and how many are shorter than a second.
fn durations_text(lc_s: &[f64], all: bool) -> String {
    if all || lc_s.len() <= DURATIONS_SHOWN {
        let lc: Vec<String> = lc_s.iter().map(|&d| secs_text(d)).collect();
        return format!("{} s", lc.join(", "));
    }
    let mut order: Vec<usize> = (0..lc_s.len()).collect();
    order.sort_by(|&a, &b| lc_s[b].total_cmp(&lc_s[a]).then(a.cmp(&b)));
    let longest: Vec<String> = order
        .iter()
        .take(3)
        .map(|&k| format!("s{} {} s", k + 1, secs_text(lc_s[k])))
        .collect();
    let short = lc_s.iter().filter(|&&d| d < 1.0).count();
    format!(
        "{} stretches per task, {} s in all; longest {}; {short} shorter than 1 s",
        lc_s.len(),
        secs_text(lc_s.iter().sum()),
        longest.join(", ")
    )
}

/// Stretch start times listed per robot in the text; `--json` has all of them.
const STRETCHES_SHOWN: usize = 8;

/// The plan as text: period, throughput and busy share, the certificate, how the order was
/// found, the operator's order, what the plan assumes, the Gantt of two periods and each
/// robot's times. A long order and many stretch durations are summarized unless `all`
/// (`--verbose`). `operator` is the switch time `δ` (s) and load cap `u_max` the plan was
/// made with (`(0.0, 1.0)`: neither): when either is not its default the busy share with the
/// switches and the δ-bound's terms are printed too.
pub(crate) fn plan_text(
    problem: &Problem,
    plan: &CyclicPlan,
    operator: (f64, f64),
    all: bool,
) -> Result<String> {
    let shape = TaskShape::new(problem);
    let n = plan.n_robots;
    let m = plan.lc_s.len();
    let mut out = String::new();
    writeln!(
        out,
        "continuous cell: {n} robot{} repeating the task, one operator, no rounds",
        if n == 1 { "" } else { "s" }
    )?;
    let t = secs_text;
    writeln!(
        out,
        "period P {} s: {:.2} tasks/h (each robot one task per period); operator busy {:.1} % \
         of the time",
        t(plan.period_s),
        plan.tasks_per_hour,
        100.0 * plan.operator_share
    )?;
    let (switch_s, max_busy_share) = operator;
    if switch_s == 0.0 && max_busy_share == 1.0 {
        writeln!(
            out,
            "certificate: P ≥ {} s = max(N·(L + I) = {n} × ({} + {}) s, fastest task D_min {} \
             s); gap {}",
            t(plan.lower_bound_s),
            t(shape.lc_total_s()),
            t(shape.idle_s()),
            t(shape.fastest_s()),
            gap_text(plan.gap)
        )?;
    } else {
        let (busy, changes) = busy_with_switches(plan, shape.lc_total_s(), switch_s);
        writeln!(
            out,
            "operator: switch time δ {} s per change of robot ({changes} per period), load cap \
             u_max {max_busy_share}: busy {:.1} % of the time with the switches",
            t(switch_s),
            100.0 * busy
        )?;
        // For N ≥ 2 robots every cyclic order changes robot at least N times.
        let c = if n >= 2 && m > 0 { n as f64 } else { 0.0 };
        let delta = if c > 0.0 { switch_s } else { 0.0 };
        writeln!(
            out,
            "certificate: P ≥ {} s, the δ-bound: at least N·(L + I + δ) = {n} × ({} + {} + {}) \
             s, (N·L + N·δ)/u_max = {} s and the fastest task D_min {} s; gap {}",
            t(plan.lower_bound_s),
            t(shape.lc_total_s()),
            t(shape.idle_s()),
            t(delta),
            t((n as f64 * shape.lc_total_s() + c * switch_s) / max_busy_share),
            t(shape.fastest_s()),
            gap_text(plan.gap)
        )?;
    }
    writeln!(
        out,
        "             (L: the operator's supervised time per task; I: its forced idle time per \
         task, in gaps without a hold too short for any stretch)"
    )?;
    let orders = plan.orders_evaluated;
    let plural = if orders == 1 { "" } else { "s" };
    if plan.order_exhaustive {
        writeln!(
            out,
            "order search: exhaustive ({orders} operator order{plural}, all evaluated): no \
             1-periodic plan has a shorter period"
        )?;
    } else {
        writeln!(
            out,
            "order search: local search ({orders} operator order{plural} evaluated, too many to \
             enumerate): not proven the best order; the lower bound holds for every order"
        )?;
    }
    if m == 0 {
        writeln!(
            out,
            "operator's order: none (the task has no low-confidence stretch: nothing to supervise)"
        )?;
    } else {
        let turns = order_turns(plan);
        writeln!(
            out,
            "operator's order per period: {} (rRsK: robot R's low-confidence stretch K of {m}, in \
             task order; rRsJ–K: its stretches J to K in a row; then again)",
            order_text(&turns, all)
        )?;
        writeln!(
            out,
            "stretch durations at ψ̇̄: {}",
            durations_text(&plan.lc_s, all)
        )?;
        if !all && (turns.len() > ORDER_TURNS_SHOWN || m > DURATIONS_SHOWN) {
            writeln!(
                out,
                "             (--verbose prints the whole order and every duration; --json has \
                 them all)"
            )?;
        }
    }
    writeln!(out)?;
    writeln!(
        out,
        "This is a plan: it assumes the operator supervises every low-confidence stretch at the \
         demonstrated mean speed ψ̇̄ and the robots run at their planned rates. At run time \
         (Rust: CyclicPlan::coordinator) a robot waits at the hold before its low-confidence \
         stretch until the operator's previous stretch has ended, so no two robots need the \
         operator at once whatever the operator does; the throughput then depends on where the \
         holds are. `tandem record` learns from rounds (--cell rounds, the default)."
    )?;
    writeln!(out)?;
    out.push_str(&gantt(problem, plan));
    writeln!(out)?;
    writeln!(
        out,
        "per robot (the task it starts in period 0; times in s from the period's start):"
    )?;
    for (r, cycle) in plan.robots.iter().enumerate() {
        out.push_str(&robot_line(problem, r, cycle));
    }
    Ok(out)
}

/// The operator's busy share of `plan` with the switches, `(N·L + c·δ)/P`, and the number `c`
/// of changes of robot around its cyclic order (`lc_total_s` = `L`, `switch_s` = `δ`).
pub(crate) fn busy_with_switches(
    plan: &CyclicPlan,
    lc_total_s: f64,
    switch_s: f64,
) -> (f64, usize) {
    let len = plan.order.len();
    let changes = (0..len)
        .filter(|&q| plan.order[q].robot != plan.order[(q + 1) % len].robot)
        .count();
    let busy = (plan.n_robots as f64 * lc_total_s + changes as f64 * switch_s) / plan.period_s;
    (busy, changes)
}

/// One robot's times: its start, its stretches, its waits at holds and at the task start.
fn robot_line(problem: &Problem, robot: usize, cycle: &RobotCycle) -> String {
    let t = secs_text;
    let mut s = format!("  robot {}  starts {}", robot + 1, t(cycle.start_s));
    let starts: Vec<String> = cycle
        .lc_start_s
        .iter()
        .enumerate()
        .map(|(k, &at)| format!("{} {}", stretch_name(robot, k), t(at)))
        .collect();
    if !starts.is_empty() {
        let _ = write!(
            s,
            "; {}",
            starts[..starts.len().min(STRETCHES_SHOWN)].join(", ")
        );
        if starts.len() > STRETCHES_SHOWN {
            let _ = write!(
                s,
                ", … {} more (--json lists all)",
                starts.len() - STRETCHES_SHOWN
            );
        }
    }
    for g in &cycle.gaps {
        if let (Some(h), true) = (g.hold, g.wait_s > 0.0) {
            let _ = write!(
                s,
                "; waits {} at the hold at ref {h} ({} s)",
                t(g.wait_s),
                t(h as f64 * problem.dt_s())
            );
        }
    }
    let _ = writeln!(s, "; waits {} at its start", t(cycle.start_wait_s));
    s
}

/// What a robot does at one instant of the cyclic Gantt.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Activity {
    /// Running high-confidence (unsupervised).
    High,
    /// Running low-confidence: robot's stretch, the operator supervises it.
    Low,
    /// Waiting at a hold point, the task start included.
    Wait,
}

/// One robot's task as intervals `[from, to)` (s) relative to its start `start_s`, covering
/// `[0, P)`: the gaps (with the planned wait at their hold, after the part of the gap before
/// the hold at `ψ̇max`: the robot slows to `ψ̇max` first), the stretches, the wait at the
/// start.
fn robot_segments(
    problem: &Problem,
    shape: &TaskShape,
    plan: &CyclicPlan,
    cycle: &RobotCycle,
) -> Vec<(f64, f64, Activity)> {
    let m = plan.lc_s.len();
    let mut segs = Vec::with_capacity(3 * (m + 1) + 1);
    let mut pos = 0.0;
    for k in 0..=m {
        let end = if k < m {
            cycle.lc_start_s[k] - cycle.start_s
        } else {
            pos + cycle.gaps.get(k).map_or(0.0, |g| g.duration_s)
        };
        let plan_gap = cycle.gaps.get(k);
        let task_gap = shape.gaps.get(k);
        match (plan_gap, task_gap) {
            (Some(g), Some(tg)) if g.wait_s > 0.0 && g.hold.is_some() => {
                let h = g.hold.unwrap_or(tg.ref_start);
                let before: f64 = problem
                    .grad_max()
                    .get(tg.ref_start..h)
                    .map_or(0.0, |s| s.iter().sum::<f64>() * problem.dt_s());
                let before = before.clamp(0.0, (end - pos - g.wait_s).max(0.0));
                segs.push((pos, pos + before, Activity::High));
                segs.push((pos + before, pos + before + g.wait_s, Activity::Wait));
                segs.push((pos + before + g.wait_s, end, Activity::High));
            }
            _ => segs.push((pos, end, Activity::High)),
        }
        pos = end;
        if k < m {
            segs.push((pos, pos + plan.lc_s[k], Activity::Low));
            pos += plan.lc_s[k];
        }
    }
    segs.push((pos, plan.period_s, Activity::Wait));
    segs
}

/// What the robot with `segs` (from [`robot_segments`]) does at time `t` (s) of a plan of
/// period `period_s` in which it starts at `start_s`: the task repeats every period.
fn activity_at(segs: &[(f64, f64, Activity)], start_s: f64, period_s: f64, t: f64) -> Activity {
    let u = (t - start_s).rem_euclid(period_s);
    segs.iter()
        .find(|(from, to, _)| u >= *from && u < *to)
        .map_or(Activity::Wait, |s| s.2)
}

/// The text Gantt of two periods `[0, 2P)`: one row per robot (`=` running high-confidence,
/// `#` low-confidence, `h` waiting at a hold, the task start included) and the operator's
/// row (`1`…`9`, then `a`…`g` for robots 10–16: whose stretch it supervises, `.` idle, `!`
/// two at once: never in a valid plan), [`COLUMNS_PER_PERIOD`] columns per period, each showing its middle instant.
pub(crate) fn gantt(problem: &Problem, plan: &CyclicPlan) -> String {
    let shape = TaskShape::new(problem);
    let n = plan.n_robots;
    let p = plan.period_s;
    let columns = 2 * COLUMNS_PER_PERIOD;
    let segs: Vec<_> = plan
        .robots
        .iter()
        .map(|c| robot_segments(problem, &shape, plan, c))
        .collect();
    let mut rows = vec![String::new(); n + 1];
    for c in 0..columns {
        let t = (c as f64 + 0.5) / COLUMNS_PER_PERIOD as f64 * p;
        let mut supervised = Vec::new();
        for (r, row) in rows.iter_mut().take(n).enumerate() {
            row.push(match activity_at(&segs[r], plan.robots[r].start_s, p, t) {
                Activity::High => '=',
                Activity::Wait => 'h',
                Activity::Low => {
                    supervised.push(r);
                    '#'
                }
            });
        }
        rows[n].push(match supervised.as_slice() {
            [] => '.',
            [r] => char::from_digit(*r as u32 + 1, 36).unwrap_or('?'),
            _ => '!',
        });
    }
    let mut out = String::new();
    let mid = format!("P = {} s", secs_text(p));
    let end = format!("2P = {} s", secs_text(2.0 * p));
    // "0 s" under the first column, `mid` starting at the second period's first column,
    // `end` ending under the last column.
    let mut header = format!("{:10}0 s", "");
    let mid_at = 10 + 1 + COLUMNS_PER_PERIOD;
    let pad = mid_at.saturating_sub(header.chars().count()).max(1);
    header.push_str(&" ".repeat(pad));
    header.push_str(&mid);
    let end_at = 10 + 1 + columns;
    let pad = end_at
        .saturating_sub(header.chars().count() + end.chars().count())
        .max(1);
    header.push_str(&" ".repeat(pad));
    header.push_str(&end);
    let _ = writeln!(out, "{header}");
    for (r, row) in rows[..n].iter().enumerate() {
        let _ = writeln!(out, "robot {}  |{row}|", r + 1);
    }
    let _ = writeln!(out, "operator |{}|", rows[n]);
    let _ = writeln!(
        out,
        "          = high confidence (unsupervised)   # low confidence (operator supervises)"
    );
    let _ = writeln!(
        out,
        "          h waiting at a hold point or at the task start for the next task (planned)"
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use tandem::schedule::cyclic::{CyclicParams, cyclic_plan};

    /// The doc example of `tandem_schedule::cyclic`: 1 s high (0.5 s at the fastest), 1 s low,
    /// 1 s high, at 10 ms.
    fn doc_problem() -> Problem {
        let conf: Vec<bool> = (0..300).map(|n| !(100..200).contains(&n)).collect();
        Problem::new(conf, vec![1.0; 300], vec![0.5; 300], vec![2.0; 300], 0.01)
            .expect("a valid problem")
    }

    #[test]
    fn runs_of_one_robot_in_the_order_are_written_once() {
        use tandem::schedule::Stretch;
        let st = |robot, lc| Stretch { robot, lc };
        let plan = CyclicPlan {
            n_robots: 2,
            order: vec![st(0, 0), st(1, 2), st(0, 1), st(0, 2), st(1, 0), st(1, 1)],
            period_s: 1.0,
            lc_s: vec![0.1; 3],
            robots: Vec::new(),
            tasks_per_hour: 7200.0,
            operator_share: 0.6,
            lower_bound_s: 1.0,
            gap: 0.0,
            order_exhaustive: true,
            orders_evaluated: 1,
        };
        assert_eq!(
            order_text(&order_turns(&plan), false),
            "r1s1 → r2s3 → r1s2–3 → r2s1–2"
        );
    }

    #[test]
    fn a_long_order_and_many_stretches_are_summarized_unless_verbose() {
        // 40 turns: robots alternating stretch by stretch over 20 stretches per task.
        let turns: Vec<String> = (0..40).map(|k| stretch_name(k % 2, k / 2)).collect();
        assert_eq!(
            order_text(&turns, false),
            "r1s1 → r2s1 → r1s2 → r2s2 → r1s3 → r2s3 → r1s4 → r2s4 → … (40 turns in all) → r2s20"
        );
        assert_eq!(order_text(&turns, true).matches(" → ").count(), 39);
        // 23 durations: the count, the total, the three longest, the short ones.
        let mut lc = vec![0.5; 20];
        lc.extend([3.21, 2.5, 7.0]);
        assert_eq!(
            durations_text(&lc, false),
            "23 stretches per task, 22.71 s in all; longest s23 7.00 s, s21 3.21 s, s22 2.50 s; \
             20 shorter than 1 s"
        );
        assert_eq!(durations_text(&lc, true).matches(", ").count(), 22);
        assert_eq!(durations_text(&lc[..3], false), "0.500, 0.500, 0.500 s");
    }

    #[test]
    fn three_robots_keep_the_operator_busy_and_one_robot_waits_for_nothing() {
        let problem = doc_problem();
        let plan = cyclic_plan(&problem, 3, &CyclicParams::default()).expect("plan");
        let g = gantt(&problem, &plan);
        let rows: Vec<&str> = g.lines().filter(|l| l.contains('|')).collect();
        let operator = rows[3].split('|').nth(1).expect("operator row");
        assert_eq!(operator.chars().count(), 2 * COLUMNS_PER_PERIOD);
        // P = 3 s, the operator supervises one stretch of 1 s after another: never idle,
        // each robot a third of the time.
        assert!(!operator.contains('.') && !operator.contains('!'), "{g}");
        for d in ['1', '2', '3'] {
            assert_eq!(operator.chars().filter(|&c| c == d).count(), 24, "{g}");
        }
        assert!(g.contains("P = 3.00 s") && g.contains("2P = 6.00 s"), "{g}");
        // One robot: the fastest task 0.5 + 1 + 0.5 s, no wait.
        let one = cyclic_plan(&problem, 1, &CyclicParams::default()).expect("plan");
        let g = gantt(&problem, &one);
        let robot = g
            .lines()
            .nth(1)
            .and_then(|l| l.split('|').nth(1))
            .expect("row");
        assert!(!robot.contains('h'), "{g}");
        assert_eq!(robot.chars().filter(|&c| c == '#').count(), 36, "{g}");
    }
}
