//! The continuous cell's static half: the task's groups ([`groups`]) and the operator's cyclic
//! token sequence ([`token_sequence`]); the rule that uses them is in
//! [the cell's docs](crate::cell).

use crate::error::{Error, Result};

/// Consecutive stretches of the task with no usable hold between them: a robot passes them
/// without stopping, so one robot at a time is in a group ([cell docs](crate::cell)).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Group {
    /// The gate: the reference sample at whose start a robot waits for the group's token (the
    /// last usable hold before the group's first stretch, or 0, the task start).
    pub gate: usize,
    /// The group's stretches are `first_lc..end_lc` (indices of the task's low-confidence
    /// runs, in reference order).
    pub first_lc: usize,
    /// One past the group's last stretch.
    pub end_lc: usize,
    /// First reference sample of the group's first stretch.
    pub ref_start: usize,
    /// One past the group's last low-confidence sample: a robot has left the group once its
    /// clock is past the start of this sample.
    pub ref_end: usize,
}

/// One entry of the token sequence: robot `robot` may go through its group `group`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Token {
    /// The robot (0-based).
    pub robot: usize,
    /// Its group (index into [`groups`]' result).
    pub group: usize,
}

/// The groups of a task of confidence `conf` (`true` = high) with usable holds `holds`
/// (reference samples, strictly increasing, each in `1..T_ref` with samples `h − 1` and `h`
/// high-confidence, as [`crate::holds::usable_holds`] returns them). Empty for a task without
/// low confidence.
///
/// # Errors
/// [`Error::BadGate`] for a hold out of range, out of order, or inside or next to a stretch.
pub fn groups(conf: &[bool], holds: &[usize]) -> Result<Vec<Group>> {
    for (k, &h) in holds.iter().enumerate() {
        let bad = |why| Err(Error::BadGate { ref_idx: h, why });
        if h == 0 || h >= conf.len() {
            return bad("is outside 1..T_ref");
        }
        if k > 0 && holds[k - 1] >= h {
            return bad("is not after the hold before it");
        }
        if !(conf[h - 1] && conf[h]) {
            return bad("is inside or next to a low-confidence stretch");
        }
    }
    // The stretches (start, end) in reference order.
    let stretches: Vec<(usize, usize)> = tandem_confidence::low_regions(conf)
        .into_iter()
        .map(|r| (r.start, r.end))
        .collect();
    let mut out: Vec<Group> = Vec::new();
    for (k, &(start, end)) in stretches.iter().enumerate() {
        let after = if k == 0 { 0 } else { stretches[k - 1].1 };
        let hold = holds
            .iter()
            .copied()
            .rfind(|&h| (k == 0 || h > after) && h < start);
        match (k, hold) {
            (0, _) | (_, Some(_)) => out.push(Group {
                gate: hold.unwrap_or(0),
                first_lc: k,
                end_lc: k + 1,
                ref_start: start,
                ref_end: end,
            }),
            (_, None) => {
                let g = out.last_mut().expect("stretch 0 opened a group");
                g.end_lc = k + 1;
                g.ref_end = end;
            }
        }
    }
    Ok(out)
}

/// The group of each stretch.
fn group_of(groups: &[Group]) -> Vec<usize> {
    groups
        .iter()
        .enumerate()
        .flat_map(|(g, gr)| std::iter::repeat_n(g, gr.end_lc - gr.first_lc))
        .collect()
}

/// Whether the operator's cyclic `order` of stretches `(robot, lc)` of `n_robots` robots can
/// run under the token rule on a task with `groups`: every robot's every stretch once, each
/// robot's in task order around the cycle, and every group contiguous (no other robot's
/// stretch between two stretches of one robot with no usable hold between them:
/// [`first_split_group`]).
#[must_use]
pub fn is_runnable(order: &[(usize, usize)], groups: &[Group], n_robots: usize) -> bool {
    token_sequence(order, groups, n_robots).is_ok()
}

/// The first position of the cyclic `order` of stretches `(robot, lc)` that splits one of
/// `groups`, or `None` when every group is contiguous: the contiguity rule of
/// [`is_runnable`], and its one implementation (`tandem-schedule`'s order search and
/// `cyclic::is_runnable` use it). Entry `q`, stretch `(r, lc)`, splits its group when it is
/// not the group's first (no usable hold lies between stretches `lc − 1` and `lc`: the robot
/// cannot wait there) and the entry before it, cyclically, is not `(r, lc − 1)`. Checks only
/// this condition, not that `order` is well formed (a stretch outside the groups splits
/// nothing; [`token_sequence`] checks the rest, and this rule with the same code).
/// O(len·log(groups)), no allocation: the check of an order search, which visits
/// well-formed orders only.
#[must_use]
pub fn first_split_group<T: Copy + Into<(usize, usize)>>(
    order: &[T],
    groups: &[Group],
) -> Option<usize> {
    (0..order.len()).find(|&q| splits_group(order, q, groups))
}

/// Whether entry `q` of `order` splits its group ([`first_split_group`]).
fn splits_group<T: Copy + Into<(usize, usize)>>(order: &[T], q: usize, groups: &[Group]) -> bool {
    let len = order.len();
    let (r, lc) = order[q].into();
    let m = groups.last().map_or(0, |g| g.end_lc);
    // A group's first stretch (stretch 0 always), or one outside the groups, splits nothing.
    if lc == 0 || lc >= m || groups.binary_search_by_key(&lc, |g| g.first_lc).is_ok() {
        return false;
    }
    let prev: (usize, usize) = order[(q + len - 1) % len].into();
    prev != (r, lc - 1)
}

/// The cyclic token sequence of a runnable `order` ([`is_runnable`]): the order cut into its
/// groups, one [`Token`] per group, starting at the first entry of `order` that opens a group;
/// and, per token, whether the first pass skips it (it precedes its robot's group 0: it
/// belongs to the task before the robot's first).
///
/// # Errors
/// [`Error::BadOrder`] naming the position in `order` and what is wrong.
pub fn token_sequence(
    order: &[(usize, usize)],
    groups: &[Group],
    n_robots: usize,
) -> Result<(Vec<Token>, Vec<bool>)> {
    let m = groups.last().map_or(0, |g| g.end_lc);
    let len = order.len();
    if len != n_robots * m {
        return Err(Error::BadOrder {
            position: len.min(n_robots * m),
            why: "does not list each robot's each stretch exactly once (length N·m)",
        });
    }
    if m == 0 || n_robots == 0 {
        return Ok((Vec::new(), Vec::new()));
    }
    let gof = group_of(groups);
    let mut seen = vec![false; n_robots * m];
    let mut last: Vec<Option<usize>> = vec![None; n_robots];
    for (q, &(r, lc)) in order.iter().enumerate() {
        let bad = |why| Err(Error::BadOrder { position: q, why });
        if r >= n_robots || lc >= m {
            return bad("names a robot or a stretch that does not exist");
        }
        if std::mem::replace(&mut seen[r * m + lc], true) {
            return bad("repeats a stretch");
        }
        if last[r].is_some_and(|l| (l + 1) % m != lc) {
            return bad("breaks its robot's task order around the cycle");
        }
        last[r] = Some(lc);
        if splits_group(order, q, groups) {
            return bad(
                "is not runnable: another robot's stretch comes between it and the stretch \
                 before it, with no usable hold between them",
            );
        }
    }
    let opens = |q: usize| {
        let (_, lc) = order[q];
        groups[gof[lc]].first_lc == lc
    };
    let start = (0..len)
        .find(|&q| opens(q))
        .expect("stretch 0 opens a group");
    let tokens: Vec<Token> = (0..len)
        .map(|k| (start + k) % len)
        .filter(|&q| opens(q))
        .map(|q| Token {
            robot: order[q].0,
            group: gof[order[q].1],
        })
        .collect();
    let first_zero: Vec<usize> = (0..n_robots)
        .map(|r| {
            tokens
                .iter()
                .position(|t| t.robot == r && t.group == 0)
                .expect("every robot has a group 0")
        })
        .collect();
    let skip = tokens
        .iter()
        .enumerate()
        .map(|(k, t)| k < first_zero[t.robot])
        .collect();
    Ok((tokens, skip))
}

/// The token sequence of a cell of different tasks (issue 45): robot `k` runs its own task,
/// whose groups are `groups[k]` ([`groups`] of its confidence and holds, `m_k` stretches per
/// task), `ratios[k]` (`r_k ≥ 1`) times per pass, and the operator's cyclic `order` lists
/// every `(robot, lc)` with `lc` counting the robot's stretches over its `r_k` tasks
/// (`lc = copy·m_k + j`, as `tandem_schedule::cyclic::MixedCyclicPlan::order`). Each robot's
/// stretches must come in task order around the cycle and each group (of each copy) be
/// contiguous ([`token_sequence`]'s rules per robot). The tokens are `(robot, group)` with
/// `group` the index in `groups[robot]`, so robot `k`'s tokens are its groups `r_k` times per
/// pass, each time in task order. In the first pass a robot's entries before its first
/// group 0 are skipped. With one task for every robot and `r_k = 1` it is
/// [`token_sequence`]'s sequence.
///
/// # Errors
/// [`Error::BadParam`] when `groups` and `ratios` do not have one entry per robot or a ratio
/// is 0; [`Error::BadOrder`] as [`token_sequence`].
pub fn mixed_token_sequence(
    order: &[(usize, usize)],
    groups: &[&[Group]],
    ratios: &[usize],
) -> Result<(Vec<Token>, Vec<bool>)> {
    let n = groups.len();
    if ratios.len() != n || ratios.contains(&0) {
        return Err(Error::BadParam {
            name: "ratios",
            why: "must give each robot its tasks per pass (r_k ≥ 1), one per robot",
        });
    }
    let m: Vec<usize> = groups
        .iter()
        .map(|g| g.last().map_or(0, |g| g.end_lc))
        .collect();
    let total: Vec<usize> = m.iter().zip(ratios).map(|(&m, &r)| m * r).collect();
    let len = order.len();
    let want: usize = total.iter().sum();
    if len != want {
        return Err(Error::BadOrder {
            position: len.min(want),
            why: "does not list each robot's each stretch of its r_k tasks exactly once",
        });
    }
    let gof: Vec<Vec<usize>> = groups.iter().map(|g| group_of(g)).collect();
    // Whether robot `r`'s stretch `lc` (over its `r_k` tasks) opens a group of its copy.
    let opens = |r: usize, lc: usize| {
        let j = lc % m[r];
        groups[r][gof[r][j]].first_lc == j
    };
    let mut seen: Vec<Vec<bool>> = total.iter().map(|&t| vec![false; t]).collect();
    let mut last: Vec<Option<usize>> = vec![None; n];
    for (q, &(r, lc)) in order.iter().enumerate() {
        let bad = |why| Err(Error::BadOrder { position: q, why });
        if r >= n || lc >= total[r] {
            return bad("names a robot or a stretch that does not exist");
        }
        if std::mem::replace(&mut seen[r][lc], true) {
            return bad("repeats a stretch");
        }
        if last[r].is_some_and(|l| (l + 1) % total[r] != lc) {
            return bad("breaks its robot's task order around the cycle");
        }
        last[r] = Some(lc);
        if !opens(r, lc) && order[(q + len - 1) % len] != (r, lc - 1) {
            return bad(
                "is not runnable: another robot's stretch comes between it and the stretch \
                 before it, with no usable hold between them",
            );
        }
    }
    if len == 0 {
        return Ok((Vec::new(), Vec::new()));
    }
    let start = (0..len)
        .find(|&q| opens(order[q].0, order[q].1))
        .expect("a robot's stretch 0 opens a group");
    let tokens: Vec<Token> = (0..len)
        .map(|k| (start + k) % len)
        .filter(|&q| opens(order[q].0, order[q].1))
        .map(|q| Token {
            robot: order[q].0,
            group: gof[order[q].0][order[q].1 % m[order[q].0]],
        })
        .collect();
    let first_zero: Vec<usize> = (0..n)
        .map(|r| {
            tokens
                .iter()
                .position(|t| t.robot == r && t.group == 0)
                .unwrap_or(usize::MAX)
        })
        .collect();
    let skip = tokens
        .iter()
        .enumerate()
        .map(|(k, t)| k < first_zero[t.robot])
        .collect();
    Ok((tokens, skip))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_by_hand() {
        // HC HC LC HC HC HC LC LC HC LC HC HC: stretches (2,3), (6,8), (9,10).
        let conf = [
            true, true, false, true, true, true, false, false, true, false, true, true,
        ];
        // No holds: one group of three stretches, gated at the start.
        let g = groups(&conf, &[]).unwrap();
        assert_eq!(g.len(), 1);
        assert_eq!((g[0].gate, g[0].first_lc, g[0].end_lc), (0, 0, 3));
        assert_eq!((g[0].ref_start, g[0].ref_end), (2, 10));
        // A hold at 1 (before stretch 0) and at 5 (between stretches 0 and 1).
        let g = groups(&conf, &[1, 5]).unwrap();
        assert_eq!(g.len(), 2);
        assert_eq!((g[0].gate, g[0].end_lc, g[0].ref_end), (1, 1, 3));
        assert_eq!((g[1].gate, g[1].first_lc, g[1].end_lc), (5, 1, 3));
        assert!(matches!(
            groups(&conf, &[3]),
            Err(Error::BadGate { ref_idx: 3, .. })
        ));
        assert!(groups(&conf, &[5, 4]).is_err() && groups(&conf, &[12]).is_err());
        assert!(groups(&[true; 4], &[]).unwrap().is_empty());
    }

    #[test]
    fn token_sequences_by_hand() {
        // Two groups per task: {0}, {1, 2}.
        let g = [
            Group {
                gate: 0,
                first_lc: 0,
                end_lc: 1,
                ref_start: 2,
                ref_end: 3,
            },
            Group {
                gate: 5,
                first_lc: 1,
                end_lc: 3,
                ref_start: 6,
                ref_end: 10,
            },
        ];
        // Robot 1 starts at its stretch 1 and its group {1, 2} straddles the wrap.
        let order = [(1, 2), (0, 0), (1, 0), (0, 1), (0, 2), (1, 1)];
        let (tokens, skip) = token_sequence(&order, &g, 2).unwrap();
        let t = |robot, group| Token { robot, group };
        assert_eq!(tokens, [t(0, 0), t(1, 0), t(0, 1), t(1, 1)]);
        assert_eq!(skip, [false; 4]);
        // Robot 1 first in its group 1: skipped in the first pass.
        let order = [(1, 1), (1, 2), (0, 0), (1, 0), (0, 1), (0, 2)];
        let (tokens, skip) = token_sequence(&order, &g, 2).unwrap();
        assert_eq!(tokens, [t(1, 1), t(0, 0), t(1, 0), t(0, 1)]);
        assert_eq!(skip, [true, false, false, false]);
        // Robot 0 between robot 1's stretches 1 and 2: not runnable.
        let bad = [(1, 1), (0, 0), (1, 2), (1, 0), (0, 1), (0, 2)];
        assert!(matches!(
            token_sequence(&bad, &g, 2),
            Err(Error::BadOrder { position: 2, .. })
        ));
        assert!(!is_runnable(&bad, &g, 2));
        assert_eq!(first_split_group(&bad, &g), Some(2));
        assert_eq!(first_split_group(&order, &g), None);
        // No robots: the empty order, nothing to run.
        assert!(is_runnable(&[], &g, 0));
        // Out of task order, repeated, wrong length, unknown robot.
        let cases: [&[(usize, usize)]; 4] = [
            &[(0, 0), (1, 0), (1, 1), (1, 2), (0, 2), (0, 1)],
            &[(0, 0), (0, 0), (1, 0), (1, 1), (1, 2), (0, 1)],
            &[(0, 0), (0, 1), (0, 2)],
            &[(0, 0), (2, 0), (1, 1), (1, 2), (0, 1), (0, 2)],
        ];
        for c in cases {
            assert!(!is_runnable(c, &g, 2), "{c:?}");
        }
    }

    #[test]
    fn mixed_token_sequences_by_hand() {
        // Robot 0: groups {0}, {1, 2} (as above); robot 1: one group {0}, twice per pass.
        let a = [
            Group {
                gate: 0,
                first_lc: 0,
                end_lc: 1,
                ref_start: 2,
                ref_end: 3,
            },
            Group {
                gate: 5,
                first_lc: 1,
                end_lc: 3,
                ref_start: 6,
                ref_end: 10,
            },
        ];
        let b = [Group {
            gate: 0,
            first_lc: 0,
            end_lc: 1,
            ref_start: 1,
            ref_end: 2,
        }];
        let t = |robot, group| Token { robot, group };
        let order = [(0, 0), (1, 0), (0, 1), (0, 2), (1, 1)];
        let (tokens, skip) = mixed_token_sequence(&order, &[&a, &b], &[1, 2]).unwrap();
        assert_eq!(tokens, [t(0, 0), t(1, 0), t(0, 1), t(1, 0)]);
        assert_eq!(skip, [false; 4]);
        // Robot 1's second task first: its tokens are both group 0, none skipped.
        let order = [(1, 1), (0, 0), (1, 0), (0, 1), (0, 2)];
        let (tokens, skip) = mixed_token_sequence(&order, &[&a, &b], &[1, 2]).unwrap();
        assert_eq!(tokens, [t(1, 0), t(0, 0), t(1, 0), t(0, 1)]);
        assert_eq!(skip, [false; 4]);
        // Robot 0 first in its group 1: skipped in the first pass.
        let order = [(0, 1), (0, 2), (1, 0), (0, 0), (1, 1)];
        let (_, skip) = mixed_token_sequence(&order, &[&a, &b], &[1, 2]).unwrap();
        assert_eq!(skip, [true, false, false, false]);
        // Robot 1 between robot 0's stretches 1 and 2: not runnable, at position 3.
        let bad = [(0, 0), (1, 0), (0, 1), (1, 1), (0, 2)];
        assert!(matches!(
            mixed_token_sequence(&bad, &[&a, &b], &[1, 2]),
            Err(Error::BadOrder { position: 4, .. })
        ));
        // Robot 1's second task missing; out of order; a zero ratio.
        let short = [(0, 0), (1, 0), (0, 1), (0, 2)];
        assert!(mixed_token_sequence(&short, &[&a, &b], &[1, 2]).is_err());
        let swapped = [(0, 0), (1, 1), (0, 1), (0, 2), (1, 0)];
        assert!(mixed_token_sequence(&swapped, &[&a, &b], &[1, 2]).is_ok());
        let out_of_order = [(0, 0), (0, 2), (0, 1), (1, 0), (1, 1)];
        assert!(mixed_token_sequence(&out_of_order, &[&a, &b], &[1, 2]).is_err());
        assert!(mixed_token_sequence(&order, &[&a, &b], &[1, 0]).is_err());
        // One task, ratios 1: token_sequence's sequence.
        let order = [(1, 2), (0, 0), (1, 0), (0, 1), (0, 2), (1, 1)];
        assert_eq!(
            mixed_token_sequence(&order, &[&a, &a], &[1, 1]).unwrap(),
            token_sequence(&order, &a, 2).unwrap()
        );
    }
}
