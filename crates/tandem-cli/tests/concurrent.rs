//! Two writers on one state file: `tandem record` holds the file's lock from the load to the
//! save, so a second `record` waits for the first instead of overwriting its round.

mod common;

use std::path::{Path, PathBuf};

use common::*;

/// Rounds each of the two writers records: 50, or more with `TANDEM_CONCURRENT_ROUNDS`
/// (docs/decisions.md, "State files are locked…", runs it by hand with 200).
fn rounds_per_writer() -> usize {
    std::env::var("TANDEM_CONCURRENT_ROUNDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .map_or(50, |n: usize| n.max(50))
}

/// Round `i`'s two executions of the small task (as `small_execution`, every sample
/// supervised), each with a force of its own so that no two rounds are the same.
fn distinct_round(dir: &Path, i: usize) -> [[PathBuf; 3]; 2] {
    std::array::from_fn(|robot| {
        let stem = format!("round_{i}_robot_{robot}");
        let [_, log, corr] = small_execution(dir, &stem);
        let bump = 1e-3 * (2 * i + robot + 1) as f64;
        let exec = write(dir, &format!("{stem}.csv"), &small_demo(SMALL_N_REF, bump));
        [exec, log, corr]
    })
}

#[test]
fn two_concurrent_writers_lose_no_round() {
    let rounds_each = rounds_per_writer();
    let dir = scratch("two-writers");
    let state = small_state(&dir);
    let rounds: Vec<[[PathBuf; 3]; 2]> = (0..2 * rounds_each)
        .map(|i| distinct_round(&dir, i))
        .collect();
    let writer = |w: usize| {
        let (state, mine) = (
            state.clone(),
            rounds[w * rounds_each..(w + 1) * rounds_each].to_vec(),
        );
        std::thread::spawn(move || {
            mine.iter()
                .map(|[a, b]| tandem(record_args(&state, a, b)))
                .collect::<Vec<_>>()
        })
    };
    let (a, b) = (writer(0), writer(1));
    let outputs = [a.join().expect("writer 0"), b.join().expect("writer 1")].concat();
    // Every command succeeded (a writer that found the lock taken waited for it) and said
    // which round it recorded: 1 to 100, each once.
    let mut numbers: Vec<usize> = outputs
        .iter()
        .map(|out| {
            let stdout = ok(out);
            let line = stdout.lines().next().expect("first line");
            line.strip_prefix("recorded round ")
                .and_then(|r| r.split_whitespace().next())
                .and_then(|k| k.parse().ok())
                .unwrap_or_else(|| panic!("unexpected output: {stdout}"))
        })
        .collect();
    numbers.sort_unstable();
    assert_eq!(numbers, (1..=2 * rounds_each).collect::<Vec<_>>());
    // Every round is in the file: 100 rounds, the 3 demonstrations and 200 executions in the
    // model, and all 200 × 60 supervised samples in the observations.
    let doc: serde_json::Value = serde_json::from_str(&ok(&tandem([
        "inspect".to_string(),
        state.display().to_string(),
        "--json".into(),
    ])))
    .expect("JSON document");
    assert_eq!(doc["rounds_recorded"], 2 * rounds_each);
    assert_eq!(doc["model"]["count"], 3 + 4 * rounds_each);
    let supervised = doc["confidence"]["total_supervised"]
        .as_f64()
        .expect("a number");
    assert!(
        (supervised - (4 * rounds_each * SMALL_N_REF) as f64).abs() < 1e-6,
        "{supervised}"
    );
    // No temporary file is left; the lock file stays beside the state file.
    let mut leftovers: Vec<String> = std::fs::read_dir(&dir)
        .expect("list the folder")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".cell.tandem"))
        .collect();
    leftovers.sort();
    assert_eq!(leftovers, [".cell.tandem.lock"]);
}
