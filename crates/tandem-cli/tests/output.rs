//! Output a person reads: what grows with the task or the number of files is summarized
//! (hold-point stretches, period notes, bag grid notes), `--verbose` lists it all; the rate
//! error names the odd file out; a rosbag2 folder is read through its `.mcap` file.

mod common;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use common::{ok, scratch, small_demo, small_demos, tandem, write};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn s(p: &Path) -> String {
    p.display().to_string()
}

/// stderr of a run.
fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// `small_demo(n, bump)` with every time moved by `shift(row)` seconds (rows from 0).
fn shifted(n: usize, bump: f64, shift: impl Fn(usize) -> f64) -> String {
    small_demo(n, bump)
        .lines()
        .enumerate()
        .map(|(k, l)| match k {
            0 => format!("{l}\n"),
            _ => {
                let (t, rest) = l.split_once(',').expect("t,x,force rows");
                let t: f64 = t.parse().expect("a time");
                format!("{:.4},{rest}\n", t + shift(k - 1))
            }
        })
        .collect()
}

#[test]
fn period_notes_are_one_line_for_all_files_unless_verbose() {
    let dir = scratch("out-notes");
    // Three files whose `t` jitters by 1–2 ms at one row each (10–20 % of a period).
    let files: Vec<PathBuf> = [(60, 0.0, 0.001), (66, 6.0, 0.002), (56, 12.0, 0.0015)]
        .iter()
        .enumerate()
        .map(|(i, &(n, bump, dev))| {
            let text = shifted(n, bump, |row| if row == 20 { dev } else { 0.0 });
            write(&dir, &format!("j{i}.csv"), &text)
        })
        .collect();
    let state = dir.join("cell.tandem");
    let mut args: Vec<String> = vec!["fit".into()];
    args.extend(files.iter().map(|p| s(p)));
    args.extend(["--samples", "50", "-o"].map(String::from));
    args.push(s(&state));
    let out = tandem(&args);
    ok(&out);
    let err = stderr(&out);
    let timing = |l: &&str| l.starts_with("note: ") && l.contains("time column `t`");
    let notes: Vec<&str> = err.lines().filter(timing).collect();
    assert_eq!(notes.len(), 1, "{err}");
    // The worst deviation (2 ms, 20 % of a period) and where it is.
    for part in [
        "3 files (",
        "deviate from each file's even grid by up to 2.000 ms (20.0 % of a period, at ",
        &format!("{}:22;", s(&files[1])),
        "(--verbose: one note per file)",
    ] {
        assert!(notes[0].contains(part), "`{part}` missing: {err}");
    }
    std::fs::remove_file(&state).expect("remove");
    args.insert(1, "--verbose".into());
    let out = tandem(&args);
    ok(&out);
    let err = stderr(&out);
    assert_eq!(err.lines().filter(timing).count(), 3, "{err}");
    // `record` of two executions without a time column: one note for both.
    let ex = repo().join("fixtures/examples");
    let cell = dir.join("example.tandem");
    let demos: Vec<String> = (0..3)
        .map(|i| s(&ex.join(format!("demo_{i}.csv"))))
        .collect();
    // Demo 0 is the reference: the example executions are logged on its axis.
    let mut fit = vec!["fit".to_string()];
    fit.extend(demos);
    fit.extend(["--reference", "first", "--samples", "50", "-o"].map(String::from));
    fit.push(s(&cell));
    ok(&tandem(&fit));
    let mut rec = vec!["record".to_string(), s(&cell)];
    for i in 1..=2 {
        for (flag, kind) in [
            ("--execution", ""),
            ("--log", ".reflog"),
            ("--corrections", ".corr"),
        ] {
            rec.push(flag.into());
            rec.push(s(&ex.join(format!("pair_1_robot_{i}{kind}.csv"))));
        }
    }
    let out = tandem(&rec);
    ok(&out);
    let err = stderr(&out);
    let notes: Vec<&str> = err.lines().filter(timing).collect();
    assert_eq!(notes.len(), 1, "{err}");
    assert!(
        notes[0].contains("2 files (")
            && notes[0].contains("no time column `t`: their samples are taken to be 0.01 s apart")
            && notes[0].contains("the control tick of the schedule it ran"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn many_hold_stretches_are_summarized_and_verbose_lists_them() {
    let dir = scratch("out-holds");
    // Three demonstrations of 120 samples whose `gripper` opens and closes every 10 samples:
    // six stretches where it is open (gripper < 0.5); the force differs over the middle.
    let demo = |bump: f64| {
        let mut text = String::from("t,x,force,gripper\n");
        for k in 0..120 {
            let u = k as f64 / 119.0;
            let force = if (40..80).contains(&k) {
                5.0 + bump
            } else {
                5.0
            };
            let gripper = u8::from((k / 10) % 2 == 1);
            writeln!(text, "{:.2},{u:.6},{force:.4},{gripper}", k as f64 * 0.01).expect("text");
        }
        text
    };
    let files: Vec<String> = [0.0, 4.0, 8.0]
        .iter()
        .enumerate()
        .map(|(i, &b)| s(&write(&dir, &format!("g{i}.csv"), &demo(b))))
        .collect();
    let state = s(&dir.join("cell.tandem"));
    let mut args: Vec<&str> = vec!["fit"];
    args.extend(files.iter().map(String::as_str));
    args.extend([
        "--hold-where",
        "gripper<0.5",
        "--samples",
        "50",
        "-o",
        &state,
    ]);
    let text = ok(&tandem(&args));
    let line = text
        .lines()
        .find(|l| l.starts_with("hold points (where gripper<0.5): "))
        .unwrap_or_else(|| panic!("no hold line:\n{text}"));
    let stretches: usize = line
        .split(" samples in ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no stretch count: {line}"));
    assert!(stretches > 5, "{text}");
    let listed = |text: &str| {
        text.lines()
            .filter(|l| l.starts_with("  ") && l.contains(" (sample"))
            .count()
    };
    assert_eq!(listed(&text), 0, "{text}");
    assert!(
        text.contains("longest: ") && text.contains("(--verbose lists every stretch"),
        "{text}"
    );
    // `inspect` summarizes the same way; `--verbose` lists every stretch.
    let inspect = ok(&tandem(["inspect", &state]));
    assert_eq!(listed(&inspect), 0, "{inspect}");
    let verbose = ok(&tandem(["inspect", &state, "--verbose"]));
    assert_eq!(listed(&verbose), stretches, "{verbose}");
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn a_rate_mismatch_names_the_odd_file_even_when_it_comes_first() {
    let dir = scratch("out-rate");
    let demos = small_demos(&dir);
    // The first file logged at 1 kHz: 60 rows 1 ms apart.
    let khz = write(
        &dir,
        "khz.csv",
        &shifted(60, 0.0, |row| -0.009 * row as f64),
    );
    let out = tandem([
        "fit",
        &s(&khz),
        &s(&demos[1]),
        &s(&demos[2]),
        "-o",
        &s(&dir.join("out.tandem")),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(
        err.contains(&format!(
            "{}:1:1: sample period 0.001 s differs from 0.01 s, the period of 2 of the 3 \
             demonstrations ({}, {})",
            s(&khz),
            s(&demos[1]),
            s(&demos[2])
        )),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn a_rosbag2_folder_is_read_through_its_mcap_and_the_grid_note_is_said_once() {
    let dir = scratch("out-folder");
    let ros2 = repo().join("fixtures/examples/ros2");
    let folders: Vec<PathBuf> = (0..3)
        .map(|i| {
            let f = dir.join(format!("demo_{i}"));
            std::fs::create_dir_all(&f).expect("folder");
            std::fs::write(f.join("metadata.yaml"), "rosbag2_bagfile_information: {}\n")
                .expect("metadata");
            std::fs::copy(
                ros2.join(format!("demo_{i}.mcap")),
                f.join(format!("demo_{i}_0.mcap")),
            )
            .expect("copy the bag");
            f
        })
        .collect();
    let state = s(&dir.join("cell.tandem"));
    let mut args: Vec<String> = vec!["fit".into()];
    args.extend(folders.iter().map(|p| s(p)));
    args.extend(["--reference", "first", "--samples", "50", "-o"].map(String::from));
    args.push(state.clone());
    let out = tandem(&args);
    let text = ok(&out);
    // Named as given (the folder).
    assert!(
        text.contains(&format!("(reference: {}, the first file)", s(&folders[0]))),
        "{text}"
    );
    // The grid note: once for the three bags, naming the topic that set it.
    let err = stderr(&out);
    let notes: Vec<&str> = err
        .lines()
        .filter(|l| l.starts_with("note: ") && l.contains("grid of"))
        .collect();
    assert_eq!(notes.len(), 1, "{err}");
    assert!(
        notes[0].contains("3 files (")
            && notes[0].contains(": grid of 100 Hz (0.01 s), the rate of /tool_pose")
            && notes[0].contains("--rate HZ"),
        "{err}"
    );
    ok(&tandem(["inspect", &s(&folders[0])]));
    // A folder without an .mcap file, and one with two: refused with what they hold.
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).expect("folder");
    std::fs::write(empty.join("metadata.yaml"), "x: 1\n").expect("metadata");
    let two = &folders[1];
    std::fs::copy(ros2.join("demo_2.mcap"), two.join("demo_1_1.mcap")).expect("copy");
    for (folder, part) in [
        (
            &empty,
            "a folder (a rosbag2 recording: metadata.yaml), without an .mcap file",
        ),
        (two, "a folder with 2 .mcap files"),
    ] {
        let out = tandem([
            "fit",
            &s(folder),
            &s(&folders[0]),
            "-o",
            &s(&dir.join("other.tandem")),
        ]);
        assert_eq!(out.status.code(), Some(2));
        let err = stderr(&out);
        assert!(
            err.contains(&format!("error: {}: {part}", s(folder))),
            "{err}"
        );
        assert!(!err.contains("Is a directory"), "{err}");
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn a_dt_that_agrees_with_every_file_is_one_note() {
    let dir = scratch("out-dt");
    let demos = small_demos(&dir);
    let mut args: Vec<String> = vec!["fit".into()];
    args.extend(demos.iter().map(|p| s(p)));
    args.extend(["--dt", "0.01", "--samples", "50", "-o"].map(String::from));
    args.push(s(&dir.join("cell.tandem")));
    let out = tandem(&args);
    ok(&out);
    let err = stderr(&out);
    let notes: Vec<&str> = err
        .lines()
        .filter(|l| l.contains("its own time gives"))
        .collect();
    assert_eq!(notes.len(), 1, "{err}");
    assert!(
        notes[0].starts_with("note: 3 files (")
            && notes[0].ends_with(
                "): its own time gives 0.01 s; --dt (the period of files without a time column) \
                 agrees and is not used for it"
            ),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).expect("clean up");
}

/// A reaching task of six strokes between waypoints of `x` and `y` (smooth cosine ramps,
/// 100 Hz), each demonstration with its own stroke durations (`scale[k]` times the nominal):
/// the speeds differ by up to 15 % per stroke, so the warps' gradients change at every
/// stroke boundary.
fn strokes(scale: &[f64]) -> String {
    const WAY: [(f64, f64); 7] = [
        (0.0, 0.0),
        (0.4, 0.1),
        (0.5, 0.5),
        (0.1, 0.6),
        (0.2, 0.9),
        (0.7, 0.8),
        (0.9, 0.2),
    ];
    const NOMINAL: [f64; 6] = [80.0, 60.0, 100.0, 70.0, 90.0, 50.0];
    let mut text = String::from("t,x,y\n");
    let mut k = 0usize;
    for (stroke, (&len, &f)) in NOMINAL.iter().zip(scale).enumerate() {
        let n = (len * f).round() as usize;
        let ((x0, y0), (x1, y1)) = (WAY[stroke], WAY[stroke + 1]);
        for j in 0..n {
            let u = 0.5 - 0.5 * (std::f64::consts::PI * j as f64 / n as f64).cos();
            writeln!(
                text,
                "{:.2},{:.6},{:.6}",
                k as f64 * 0.01,
                x0 + u * (x1 - x0),
                y0 + u * (y1 - y0)
            )
            .expect("write to string");
            k += 1;
        }
    }
    let (x, y) = WAY[6];
    writeln!(text, "{:.2},{x:.6},{y:.6}", k as f64 * 0.01).expect("write to string");
    text
}

/// The `(high, total, regions)` of the first `high confidence: …` line of `text`.
fn confidence_counts(text: &str) -> (usize, usize, usize) {
    let line = text
        .lines()
        .find(|l| l.starts_with("high confidence: "))
        .unwrap_or_else(|| panic!("no confidence line:\n{text}"));
    let inner = line.split_once('(').expect("`(h of n)`").1;
    let (h, rest) = inner.split_once(" of ").expect("`h of n`");
    let (n, rest) = rest.split_once("), ").expect("`n), k regions`");
    let k = rest.split_once(' ').expect("`k low-confidence regions`").0;
    let num = |x: &str| x.parse::<usize>().unwrap_or_else(|_| panic!("{x}: {line}"));
    (num(h), num(n), num(k))
}

/// The stroke task's five demonstrations (`strokes`), written into `dir`: each stroke's speed
/// scaled by up to ±15 % per demonstration (the first at the nominal speed); their paths.
fn stroke_demos(dir: &std::path::Path) -> Vec<String> {
    let scales: [[f64; 6]; 5] = [
        [1.0, 1.0, 1.0, 1.0, 1.0, 1.0],
        [1.12, 0.9, 1.05, 0.87, 1.1, 0.95],
        [0.88, 1.1, 0.93, 1.14, 0.9, 1.08],
        [1.06, 0.86, 1.13, 0.95, 0.88, 1.15],
        [0.94, 1.13, 0.89, 1.07, 1.12, 0.86],
    ];
    scales
        .iter()
        .enumerate()
        .map(|(i, sc)| s(&write(dir, &format!("demo_{i}.csv"), &strokes(sc))))
        .collect()
}

#[test]
fn fit_says_once_which_rate_range_would_merge_its_short_islands() {
    // The stroke task with a rate range of 2.3 (the default, 3 × the mean pace, trusts every
    // sample): the speeds' part of `σ²_D` peaks just above `σ²_MAX` over a few samples, so the
    // prior's only low-confidence region is an island narrower than the opening (13 samples)
    // with the position channels alone high-confidence. `fit` names the range from which it
    // is high-confidence; fitted with that range the task is all high-confidence and the
    // note is gone.
    let dir = scratch("range-advice-positive");
    let demos = stroke_demos(&dir);
    let fit = |rate: &str| {
        let mut args = vec!["fit".to_string()];
        args.extend(demos.iter().cloned());
        args.extend(["--samples", "50", "--force", "-o"].map(String::from));
        args.push(s(&dir.join("cell.tandem")));
        args.extend(["--ranges".to_string(), format!("rate={rate}")]);
        ok(&tandem(&args))
    };
    let text = fit("2.3");
    let notes: Vec<&str> = text.lines().filter(|l| l.starts_with("range: ")).collect();
    assert_eq!(notes.len(), 1, "one range note:\n{text}");
    let note = notes[0];
    // One low-confidence region, and it is shorter than the opening: the island.
    let (high, n_ref, regions) = confidence_counts(&text);
    assert_eq!(regions, 1, "{text}");
    assert!(n_ref - high < 13, "{text}");
    for part in [
        "range: channel `rate`: 1 low-confidence island shorter than 13 samples from the \
         demonstrations' speeds alone; `--ranges rate=",
        "(now 2.30) would make it high-confidence (",
        "→ 100.0 % of the task, 1 → 0 low-confidence regions)",
    ] {
        assert!(note.contains(part), "`{part}` missing: {note}");
    }
    let advised = note
        .split_once("`--ranges rate=")
        .and_then(|(_, r)| r.split_once('`'))
        .expect("the advised range")
        .0;
    let value: f64 = advised.parse().expect("a number");
    // Larger than the range in force, rounded up to three significant digits.
    assert!(value > 2.3 && value < 2.4, "{note}");
    assert_eq!(advised.len(), 4, "three significant digits: {note}");
    // The note's prediction (`1 → 0` regions, every sample high) is the refit's summary.
    let predicted: usize = note
        .rsplit_once("→ ")
        .and_then(|(_, r)| r.split_once(' '))
        .expect("`→ y low-confidence regions`")
        .0
        .parse()
        .expect("a count");
    let refit = fit(advised);
    let (high, n_ref_after, regions) = confidence_counts(&refit);
    assert_eq!(n_ref_after, n_ref, "the same reference:\n{refit}");
    assert_eq!((high, regions), (n_ref, predicted), "{refit}");
    assert!(
        !refit.lines().any(|l| l.starts_with("range: ")),
        "no note once the islands are gone:\n{refit}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn fit_gives_no_range_note_without_short_islands_from_the_speeds() {
    // The stroke task's speeds differ by up to 15 % per stroke: under the defaults its prior
    // trusts every sample, and with a small rate range its low-confidence regions are long
    // stretches, not islands narrower than the opening: no range is advisable either way.
    let dir = scratch("range-advice");
    let demos = stroke_demos(&dir);
    let fit = |extra: &[&str]| {
        let mut args = vec!["fit".to_string()];
        args.extend(demos.iter().cloned());
        args.extend(["--reference", "first", "--samples", "50", "--force", "-o"].map(String::from));
        args.push(s(&dir.join("cell.tandem")));
        args.extend(extra.iter().map(|x| x.to_string()));
        ok(&tandem(&args))
    };
    for extra in [&[][..], &["--ranges", "rate=1.3"][..]] {
        let text = fit(extra);
        assert!(text.contains("high confidence: "), "{text}");
        assert!(
            !text.lines().any(|l| l.starts_with("range: ")),
            "{extra:?}: no range note:\n{text}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
