//! Every family, a few seeds each: the generated files read through the CSV loader, the truth
//! is consistent with the data, generation is deterministic, and a default fit succeeds.

use proptest::prelude::*;
use tandem_lfd::{FitParams, HoldRule, HoldSpec, TaskModel};
use tandem_zoo::{HELD_OUT_SEEDS, SELECTION_SEEDS, ZooTask, families, family};

/// Seeds every structural test runs on: selection seeds and held-out ones.
const SEEDS: [u64; 4] = [0, 1, 5, HELD_OUT_SEEDS.start];

fn tasks() -> impl Iterator<Item = ZooTask> {
    families().iter().flat_map(|f| {
        SEEDS
            .iter()
            .map(move |&s| (f.generate)(s).unwrap_or_else(|e| panic!("{} seed {s}: {e}", f.name)))
    })
}

#[test]
fn at_least_eight_families_with_unique_names() {
    let names: Vec<&str> = families().iter().map(|f| f.name).collect();
    assert!(names.len() >= 8, "{names:?}");
    let mut sorted = names.clone();
    sorted.sort_unstable();
    sorted.dedup();
    assert_eq!(sorted.len(), names.len(), "duplicate names in {names:?}");
    for f in families() {
        assert_eq!(family(f.name).unwrap().name, f.name);
        assert!(!f.summary.is_empty());
    }
    assert_eq!(SELECTION_SEEDS, 0..8);
    assert_eq!(HELD_OUT_SEEDS, 1000..1008);
}

#[test]
fn an_unknown_family_is_an_error_listing_the_names() {
    let e = family("welding").unwrap_err().to_string();
    assert!(e.contains("welding"), "{e}");
    for f in families() {
        assert!(e.contains(f.name), "{e}");
    }
}

#[test]
fn every_task_reads_through_the_csv_loader_with_its_rate() {
    tasks().for_each(|t| check_loader(&t));
}

#[test]
fn progress_is_monotone_and_spans_zero_to_one() {
    tasks().for_each(|t| check_progress(&t));
}

#[test]
fn need_and_variable_spans_are_sorted_in_range_and_consistent() {
    tasks().for_each(|t| check_spans(&t));
}

#[test]
fn lengths_are_within_20_percent_of_each_other() {
    tasks().for_each(|t| check_lengths(&t));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]
    /// Any seed, not only the ones above, gives a task with every structural property.
    #[test]
    fn any_seed_gives_a_valid_task(seed in any::<u64>(), f in 0..8_usize) {
        let family = &families()[f % families().len()];
        let task = (family.generate)(seed).unwrap();
        check_loader(&task);
        check_progress(&task);
        check_spans(&task);
        check_lengths(&task);
    }
}

/// The files read through the CSV loader at the task's rate, with at most 6000 rows, 3–12
/// demonstrations named `demo_<i>.csv` with the same channels.
fn check_loader(task: &ZooTask) {
    let what = format!("{} seed {}", task.family, task.seed);
    let demos = task.demos().unwrap_or_else(|e| panic!("{what}: {e}"));
    assert!(
        (3..=12).contains(&demos.len()),
        "{what}: {} demos",
        demos.len()
    );
    assert!((50.0..=1000.0).contains(&task.rate_hz), "{what}");
    assert_eq!(demos.len(), task.progress.len(), "{what}");
    for (i, d) in demos.iter().enumerate() {
        assert_eq!(task.files[i].0, format!("demo_{i}.csv"), "{what}");
        assert_eq!(d.n_samples(), task.progress[i].len(), "{what} demo {i}");
        assert!(
            d.n_samples() <= 6000,
            "{what} demo {i}: {} rows",
            d.n_samples()
        );
        assert!(
            (d.dt_s() - 1.0 / task.rate_hz).abs() < 1e-12,
            "{what} demo {i}: period {} at {} Hz",
            d.dt_s(),
            task.rate_hz
        );
        assert_eq!(d.channel_names(), demos[0].channel_names(), "{what}");
    }
}

/// Progress strictly increasing from exactly 0 to exactly 1.
fn check_progress(task: &ZooTask) {
    for (i, p) in task.progress.iter().enumerate() {
        let what = format!("{} seed {} demo {i}", task.family, task.seed);
        assert_eq!(p[0], 0.0, "{what}");
        assert_eq!(*p.last().unwrap(), 1.0, "{what}");
        assert!(p.windows(2).all(|w| w[0] < w[1]), "{what}: not increasing");
    }
}

/// Need spans sorted, disjoint, in range, `p ∈ (0, 1]`; variable spans disjoint and covered
/// by learnable need spans; a true high share strictly between 0.2 and 0.95.
fn check_spans(task: &ZooTask) {
    let what = format!("{} seed {}", task.family, task.seed);
    assert!(!task.need.is_empty() && !task.variable.is_empty(), "{what}");
    for s in &task.need {
        assert!(
            0.0 <= s.from && s.from < s.to && s.to <= 1.0,
            "{what}: {s:?}"
        );
        assert!(s.p > 0.0 && s.p <= 1.0, "{what}: {s:?}");
    }
    for w in task.need.windows(2) {
        assert!(
            w[0].to <= w[1].from,
            "{what}: {:?} overlaps {:?}",
            w[0],
            w[1]
        );
    }
    for w in task.variable.windows(2) {
        assert!(w[0].1 < w[1].0, "{what}: variable spans not disjoint");
    }
    for &(a, b) in &task.variable {
        assert!(0.0 <= a && a < b && b <= 1.0, "{what}");
        // Covered by learnable need spans from end to end.
        let mut at = a;
        while at < b {
            let s = task
                .need
                .iter()
                .find(|s| s.from <= at && at < s.to)
                .unwrap_or_else(|| panic!("{what}: {at} varies but needs nothing"));
            assert!(s.learnable, "{what}: variable span {a}..{b} in {s:?}");
            at = s.to;
        }
    }
    for i in 0..task.progress.len() {
        let share = task.true_high_share(i);
        assert!(
            share > 0.2 && share < 0.95,
            "{what} demo {i}: share {share}"
        );
    }
}

/// The longest demonstration at most 1.2 times the shortest, and not all the same.
fn check_lengths(task: &ZooTask) {
    let lens: Vec<f64> = task.progress.iter().map(|p| (p.len() - 1) as f64).collect();
    let max = lens.iter().copied().fold(0.0, f64::max);
    let min = lens.iter().copied().fold(f64::INFINITY, f64::min);
    assert!(
        max <= 1.2 * min,
        "{} seed {}: {lens:?}",
        task.family,
        task.seed
    );
    assert!(
        max > min,
        "{} seed {}: all the same length",
        task.family,
        task.seed
    );
}

#[test]
fn the_same_seed_gives_the_same_bytes_and_seeds_differ() {
    for f in families() {
        let a = (f.generate)(3).unwrap();
        let b = (f.generate)(3).unwrap();
        assert_eq!(a, b, "{}", f.name);
        let c = (f.generate)(4).unwrap();
        assert_ne!(a.files, c.files, "{}", f.name);
    }
}

/// Between-demonstration variance at equal true progress, `Σ_c var_c / r_c²` per point of a
/// grid (`r_c` each channel's range over all samples, as the fit weighs channels): the
/// quantity the fit's `σ²_D` estimates when the alignment is perfect.
fn variance_on_grid(task: &ZooTask, grid: &[f64]) -> Vec<f64> {
    let demos = task.demos().unwrap();
    let m = demos[0].n_channels();
    let names = demos[0].channel_names();
    let mut ranges: Vec<f64> = (0..m)
        .map(|c| {
            let (lo, hi) = demos
                .iter()
                .flat_map(|d| (0..d.n_samples()).map(move |t| d.sample(t)[c]))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(v), hi.max(v))
                });
            if hi - lo > 1e-9 { hi - lo } else { 1.0 }
        })
        .collect();
    // A quaternion block is one orientation: its vector part gets the largest component
    // range (as the fit's rotation vectors do) and `qw`, second order in the angle, is left
    // out.
    let quat: Vec<usize> = ["qx", "qy", "qz"]
        .iter()
        .filter_map(|q| names.iter().position(|n| n == q))
        .collect();
    let qrange = quat.iter().map(|&c| ranges[c]).fold(0.0, f64::max);
    let skip = names.iter().position(|n| n == "qw");
    for &c in &quat {
        ranges[c] = qrange;
    }
    let at = |d: &tandem_lfd::Demonstration, p: &[f64], q: f64, c: usize| {
        let j = p.partition_point(|&x| x <= q).clamp(1, p.len() - 1);
        let f = ((q - p[j - 1]) / (p[j] - p[j - 1])).clamp(0.0, 1.0);
        d.sample(j - 1)[c] * (1.0 - f) + d.sample(j)[c] * f
    };
    grid.iter()
        .map(|&q| {
            (0..m)
                .filter(|&c| Some(c) != skip)
                .map(|c| {
                    let v: Vec<f64> = demos
                        .iter()
                        .zip(&task.progress)
                        .map(|(d, p)| at(d, p, q, c))
                        .collect();
                    let mean = v.iter().sum::<f64>() / v.len() as f64;
                    let var =
                        v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (v.len() - 1) as f64;
                    var / (ranges[c] * ranges[c])
                })
                .sum()
        })
        .collect()
}

#[test]
fn demonstrations_vary_where_the_truth_says_and_agree_elsewhere() {
    // Aligned by the true progress, the demonstrations' variance is well above the prior's
    // high-confidence level (σ²_D ≈ 0.002 with the default confidence parameters) on
    // average over every variable span, and below it at 95 % of the points away from them.
    let grid: Vec<f64> = (0..2000).map(|g| (g as f64 + 0.5) / 2000.0).collect();
    for task in tasks() {
        let what = format!("{} seed {}", task.family, task.seed);
        let v = variance_on_grid(&task, &grid);
        for &(a, b) in &task.variable {
            let inside: Vec<f64> = grid
                .iter()
                .zip(&v)
                .filter(|(q, _)| a <= **q && **q < b)
                .map(|(_, v)| *v)
                .collect();
            let mean = inside.iter().sum::<f64>() / inside.len() as f64;
            eprintln!("{what}: span {a:.3}..{b:.3} mean {mean:.5}");
            assert!(
                mean > 0.01,
                "{what}: variable span {a:.3}..{b:.3} has mean variance {mean:.5}"
            );
        }
        let margin = 0.02;
        let mut outside: Vec<f64> = grid
            .iter()
            .zip(&v)
            .filter(|(q, _)| {
                task.variable
                    .iter()
                    .all(|&(a, b)| **q < a - margin || **q > b + margin)
            })
            .map(|(_, v)| *v)
            .collect();
        outside.sort_by(f64::total_cmp);
        let p95 = outside[outside.len() * 95 / 100];
        eprintln!(
            "{what}: p95 elsewhere {p95:.5}, max {:.5}",
            outside.last().unwrap()
        );
        assert!(
            p95 < 0.002,
            "{what}: 95th percentile of the variance elsewhere {p95:.5}"
        );
    }
}

#[test]
fn a_default_fit_succeeds_and_the_hold_rules_hit() {
    for f in families() {
        let task = (f.generate)(0).unwrap();
        let demos = task.demos().unwrap();
        let model = TaskModel::fit(&demos, &FitParams::default())
            .unwrap_or_else(|e| panic!("{}: {e}", f.name));
        let rules: Vec<HoldRule> = task
            .holds
            .iter()
            .map(|h| h.parse().unwrap_or_else(|e| panic!("{}: {h}: {e}", f.name)))
            .collect();
        for rule in rules {
            let hits = HoldSpec::rule_samples(&model, &rule).unwrap();
            assert!(!hits.is_empty(), "{}: {rule} holds nowhere", f.name);
            let spec = HoldSpec {
                at_s: vec![],
                rules: vec![rule],
            };
            assert!(!spec.resolve(&model).unwrap().is_empty(), "{}", f.name);
        }
    }
}

#[test]
fn write_dir_writes_the_files_and_the_truth() {
    let dir = std::env::temp_dir().join(format!("tandem-zoo-test-{}", std::process::id()));
    for f in families() {
        let task = (f.generate)(1).unwrap();
        let sub = dir.join(f.name);
        task.write_dir(&sub).unwrap();
        for (name, text) in &task.files {
            assert_eq!(&std::fs::read_to_string(sub.join(name)).unwrap(), text);
        }
        let truth: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(sub.join("truth.json")).unwrap())
                .unwrap();
        assert_eq!(truth["family"], f.name);
        assert_eq!(truth["need"].as_array().unwrap().len(), task.need.len());
        assert_eq!(
            truth["progress"][0].as_array().unwrap().len(),
            task.progress[0].len()
        );
        assert_eq!(sub.join("holds.txt").exists(), !task.holds.is_empty());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_zoo_covers_what_users_vary() {
    // Over every family and selection seed: rates, demonstration counts, channels, need
    // levels, where the variable sections fall, and families with and without holds.
    let tasks: Vec<ZooTask> = families()
        .iter()
        .flat_map(|f| SELECTION_SEEDS.map(move |s| (f.generate)(s).unwrap()))
        .collect();
    let mut rates: Vec<u64> = tasks.iter().map(|t| t.rate_hz as u64).collect();
    rates.sort_unstable();
    rates.dedup();
    assert_eq!(rates.first(), Some(&50), "{rates:?}");
    assert_eq!(rates.last(), Some(&1000), "{rates:?}");
    assert!(rates.len() >= 6, "{rates:?}");
    let counts: Vec<usize> = tasks.iter().map(ZooTask::n_demos).collect();
    assert_eq!(counts.iter().min(), Some(&3));
    assert!(counts.iter().max().is_some_and(|&n| n >= 11), "{counts:?}");
    let headers: Vec<&str> = tasks
        .iter()
        .map(|t| t.files[0].1.lines().next().unwrap())
        .collect();
    for needle in [
        "qx,qy,qz,qw",
        "force",
        "torque",
        "flow",
        "valve",
        "gripper",
        "fz",
    ] {
        assert!(headers.iter().any(|h| h.contains(needle)), "no `{needle}`");
    }
    assert!(
        headers.iter().any(|h| !h.contains("qw")),
        "every task has a pose"
    );
    let ps: Vec<f64> = tasks
        .iter()
        .flat_map(|t| t.need.iter().map(|s| s.p))
        .collect();
    assert!(ps.iter().any(|&p| p <= 0.2) && ps.contains(&1.0), "{ps:?}");
    let mut levels: Vec<u64> = ps.iter().map(|p| (p * 100.0).round() as u64).collect();
    levels.sort_unstable();
    levels.dedup();
    assert!(levels.len() >= 6, "need levels {levels:?}");
    let spans: Vec<(f64, f64)> = tasks.iter().flat_map(|t| t.variable.clone()).collect();
    assert!(spans.iter().any(|&(a, _)| a == 0.0), "none at the start");
    assert!(spans.iter().any(|&(_, b)| b > 0.9), "none at the end");
    assert!(
        spans.iter().any(|&(a, b)| a > 0.3 && b < 0.7),
        "none in the middle"
    );
    assert!(
        spans.iter().any(|&(a, b)| b - a > 0.4),
        "no long variable section"
    );
    // Back to back: two learnable need spans of different p that touch.
    assert!(
        tasks.iter().any(|t| t
            .need
            .windows(2)
            .any(|w| w[0].to == w[1].from && w[0].learnable && w[1].learnable)),
        "no variable sections back to back"
    );
    assert!(
        tasks.iter().any(|t| t.need.iter().any(|s| !s.learnable)),
        "no need where the demonstrations agree"
    );
    let with_holds = families()
        .iter()
        .filter(|f| !(f.generate)(0).unwrap().holds.is_empty())
        .count();
    assert!(
        with_holds >= 4 && with_holds < families().len(),
        "{with_holds} with holds"
    );
}

#[test]
fn the_crate_docs_table_is_true() {
    // (family, channels, rates, demonstration counts, nominal duration in s per rate)
    type Row = (
        &'static str,
        &'static str,
        &'static [f64],
        (usize, usize),
        fn(f64) -> f64,
    );
    let table: [Row; 8] = [
        (
            "dispensing",
            "x,y,z,qx,qy,qz,qw,flow,valve",
            &[100.0, 125.0, 200.0],
            (4, 10),
            |_| 22.8,
        ),
        (
            "peg_insertion",
            "x,y,z,qx,qy,qz,qw,fx,fy,fz",
            &[250.0, 500.0],
            (3, 8),
            |_| 9.5,
        ),
        (
            "screw_driving",
            "x,y,z,torque,fz,spindle",
            &[500.0, 1000.0],
            (3, 8),
            |r| {
                if r == 1000.0 { 5.1 } else { 7.4 }
            },
        ),
        (
            "polishing",
            "x,y,z,qx,qy,qz,qw,force,tool",
            &[100.0, 200.0],
            (3, 12),
            |_| 23.7,
        ),
        (
            "pick_and_place",
            "x,y,z,qx,qy,qz,qw,gripper",
            &[50.0, 100.0],
            (3, 12),
            |_| 26.4,
        ),
        (
            "painting",
            "x,y,z,qx,qy,qz,qw,flow,spray",
            &[50.0, 100.0],
            (3, 12),
            |_| 28.2,
        ),
        (
            "deburring",
            "x,y,z,qx,qy,qz,qw,fx,fy,fz,spindle",
            &[200.0, 250.0],
            (3, 10),
            |_| 20.4,
        ),
        (
            "cable_routing",
            "x,y,z,qx,qy,qz,qw,gripper,tension",
            &[50.0],
            (3, 12),
            |_| 36.0,
        ),
    ];
    let names: Vec<&str> = families().iter().map(|f| f.name).collect();
    assert_eq!(
        names,
        table.map(|r| r.0),
        "the docs list the families in this order"
    );
    for (name, channels, rates, (lo, hi), nominal_s) in table {
        for seed in SELECTION_SEEDS {
            let task = (family(name).unwrap().generate)(seed).unwrap();
            let what = format!("{name} seed {seed}");
            let header = task.files[0].1.lines().next().unwrap();
            assert_eq!(header, format!("t,{channels}"), "{what}");
            assert!(rates.contains(&task.rate_hz), "{what}: {} Hz", task.rate_hz);
            assert!(
                (lo..=hi).contains(&task.n_demos()),
                "{what}: {}",
                task.n_demos()
            );
            let nominal = nominal_s(task.rate_hz);
            for p in &task.progress {
                let duration_s = (p.len() - 1) as f64 / task.rate_hz;
                let ratio = duration_s / nominal;
                assert!((0.91..=1.09).contains(&ratio), "{what}: {duration_s} s");
            }
        }
    }
}

#[test]
fn some_logs_start_at_the_controllers_clock() {
    // Seeds where every file's first stamp is 0 and seeds where none is: both occur, and the
    // loader reads both at the task's rate (checked with every task above).
    let first_stamps = |seed| {
        let task = (families()[0].generate)(seed).unwrap();
        task.files
            .iter()
            .map(|(_, text)| {
                let row = text.lines().nth(1).unwrap();
                row.split(',').next().unwrap().parse::<f64>().unwrap()
            })
            .collect::<Vec<f64>>()
    };
    let stamps: Vec<Vec<f64>> = SELECTION_SEEDS.map(first_stamps).collect();
    assert!(
        stamps.iter().any(|s| s.iter().all(|&t| t == 0.0)),
        "{stamps:?}"
    );
    assert!(
        stamps
            .iter()
            .any(|s| s.iter().all(|&t| (60.0..=3600.0).contains(&t))),
        "{stamps:?}"
    );
}
