//! Helpers shared by the CLI's integration tests: run the binary, make small inputs.

#![allow(dead_code, reason = "each test binary uses a subset of the helpers")]

use std::ffi::OsStr;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs `tandem` with `args`.
pub(crate) fn tandem<I, S>(args: I) -> Output
where
    I: IntoIterator<Item = S>,
    S: AsRef<OsStr>,
{
    Command::new(env!("CARGO_BIN_EXE_tandem"))
        .args(args)
        .env("RUST_BACKTRACE", "1")
        .output()
        .expect("the tandem binary runs")
}

/// Asserts a successful run and returns its stdout.
pub(crate) fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "expected success, got {:?}\nstdout:\n{}\nstderr:\n{}",
        out.status.code(),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout.clone()).expect("utf-8 stdout")
}

/// A fresh, empty folder for one test.
pub(crate) fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tandem-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create scratch folder");
    dir
}

/// Writes `text` to `dir/name` and returns the path.
pub(crate) fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write test file");
    p
}

/// Number of reference samples of the small task (demo 0).
pub(crate) const SMALL_N_REF: usize = 60;

/// A small demonstration: time `t` (s, 10 ms), position `x` and `force`; `n` samples; a force
/// bump of height `bump` over the middle third (where the demonstrations disagree).
pub(crate) fn small_demo(n: usize, bump: f64) -> String {
    let mut s = String::from("t,x,force\n");
    for k in 0..n {
        let u = k as f64 / (n - 1) as f64;
        let f = if (1.0 / 3.0..2.0 / 3.0).contains(&u) {
            5.0 + bump
        } else {
            5.0
        };
        writeln!(s, "{:.2},{:.6},{:.4}", k as f64 * 0.01, u, f).expect("write to string");
    }
    s
}

/// Three small demonstrations in `dir`; returns their paths (demo 0 has [`SMALL_N_REF`] samples).
pub(crate) fn small_demos(dir: &Path) -> Vec<PathBuf> {
    [(SMALL_N_REF, 0.0), (66, 6.0), (56, 12.0)]
        .iter()
        .enumerate()
        .map(|(i, &(n, bump))| write(dir, &format!("demo_{i}.csv"), &small_demo(n, bump)))
        .collect()
}

/// Fits the small task into `dir/cell.tandem` (200 sampler candidates) with demo 0 as the
/// reference (`--reference first`: the executions and need files of these tests are on its
/// time axis) and returns its path.
pub(crate) fn small_state(dir: &Path) -> PathBuf {
    let demos = small_demos(dir);
    let state = dir.join("cell.tandem");
    let mut args: Vec<&OsStr> = vec![OsStr::new("fit")];
    args.extend(demos.iter().map(|p| p.as_os_str()));
    args.extend(["--reference", "first", "--samples", "200", "-o"].map(OsStr::new));
    args.push(state.as_os_str());
    ok(&tandem(args));
    state
}

/// A valid execution of the small task for `tandem record`: demo 0 replayed at reference
/// speed (identity log), every sample supervised, none corrected. Returns (execution, log,
/// corrections) paths named `<stem>.csv`, `<stem>.reflog.csv`, `<stem>.corr.csv`.
pub(crate) fn small_execution(dir: &Path, stem: &str) -> [PathBuf; 3] {
    let exec = write(dir, &format!("{stem}.csv"), &small_demo(SMALL_N_REF, 0.0));
    let mut log = String::from("ref_sample\n");
    let mut corr = String::from("supervised,corrected\n");
    for k in 0..SMALL_N_REF {
        writeln!(log, "{k}").expect("write to string");
        corr.push_str("1,0\n");
    }
    let log = write(dir, &format!("{stem}.reflog.csv"), &log);
    let corr = write(dir, &format!("{stem}.corr.csv"), &corr);
    [exec, log, corr]
}

/// `record` arguments for a pair.
pub(crate) fn record_args(state: &Path, a: &[PathBuf; 3], b: &[PathBuf; 3]) -> Vec<PathBuf> {
    let mut v = vec![PathBuf::from("record"), state.to_path_buf()];
    for e in [a, b] {
        for (flag, p) in ["--execution", "--log", "--corrections"].iter().zip(e) {
            v.push(PathBuf::from(flag));
            v.push(p.clone());
        }
    }
    v
}
