//! Align a query CSV signal to a reference CSV signal and print the warp as CSV.
//!
//! ```text
//! cargo run --release -p tandem-warp --example align -- REF.csv QUERY.csv \
//!     [--weights w0,w1,...] [--params '<WarpParams as JSON>'] [--report]
//! ```
//!
//! Input files: a header row, then one row of numbers per sample; a column named `t` is ignored.
//! Output (stdout): `ref_sample,query_time`, one row per reference sample (query samples).
//! `--report` also prints `objective=<J> wall_s=<seconds of align()>` to stderr;
//! `--repeat K` runs the alignment K times and reports the mean wall time.
//! Bad input: a message naming file, line and problem on stderr, exit code 2.
#![allow(
    clippy::print_stdout,
    reason = "a command-line example writes its result to stdout"
)]
#![allow(
    clippy::print_stderr,
    reason = "a command-line example reports errors on stderr"
)]

use std::fmt::Write as _;
use std::process::ExitCode;
use std::time::Instant;

use tandem_warp::{SignalRef, WarpParams, align};

/// A parsed CSV signal: channel names (without `t`) and sample-major data.
struct Csv {
    names: Vec<String>,
    data: Vec<f64>,
}

fn parse_csv(path: &str) -> Result<Csv, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{path}: cannot read: {e}"))?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        return Err(format!("{path}: empty file (expected a header row)"));
    };
    let header: Vec<String> = header.split(',').map(|s| s.trim().to_string()).collect();
    let keep: Vec<usize> = (0..header.len()).filter(|&i| header[i] != "t").collect();
    if keep.is_empty() {
        return Err(format!("{path}:1: no data columns besides `t`"));
    }
    let mut data = Vec::new();
    let mut rows = 0usize;
    for (idx, line) in lines {
        let line_no = idx + 1;
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        if cells.len() != header.len() {
            return Err(format!(
                "{path}:{line_no}: ragged row: {} cells, header has {}",
                cells.len(),
                header.len()
            ));
        }
        for &i in &keep {
            let v: f64 = cells[i].parse().map_err(|_| {
                format!(
                    "{path}:{line_no}: column `{}`: not a number: {:?}",
                    header[i], cells[i]
                )
            })?;
            if !v.is_finite() {
                return Err(format!(
                    "{path}:{line_no}: column `{}`: non-finite value {v}",
                    header[i]
                ));
            }
            data.push(v);
        }
        rows += 1;
    }
    if rows < 2 {
        return Err(format!("{path}: {rows} data rows; at least 2 are required"));
    }
    Ok(Csv {
        names: keep.iter().map(|&i| header[i].clone()).collect(),
        data,
    })
}

fn parse_weights(s: &str, n: usize) -> Result<Vec<f64>, String> {
    let w: Vec<f64> = s
        .split(',')
        .map(|x| {
            x.trim()
                .parse::<f64>()
                .map_err(|_| format!("--weights: not a number: {x:?}"))
        })
        .collect::<Result<_, _>>()?;
    if w.len() != n {
        return Err(format!(
            "--weights: {} values given, the signals have {n} channels",
            w.len()
        ));
    }
    if let Some((i, v)) = w
        .iter()
        .enumerate()
        .find(|(_, v)| !(v.is_finite() && **v >= 0.0))
    {
        return Err(format!(
            "--weights: weight {i} must be finite and >= 0 (got {v})"
        ));
    }
    Ok(w)
}

fn run() -> Result<String, String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: align REF.csv QUERY.csv [--weights w0,w1,...] [--params JSON] [--report] [--repeat K]";
    let mut files = Vec::new();
    let (mut weights, mut params_json, mut report) = (None, None, false);
    let mut repeat = 1usize;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--weights" => weights = Some(it.next().ok_or("--weights needs a value")?.clone()),
            "--params" => params_json = Some(it.next().ok_or("--params needs a value")?.clone()),
            "--report" => report = true,
            "--repeat" => {
                let v = it.next().ok_or("--repeat needs a value")?;
                repeat = v
                    .parse()
                    .map_err(|_| format!("--repeat: not a count: {v:?}"))?;
                repeat = repeat.max(1);
            }
            s if s.starts_with("--") => return Err(format!("unknown option {s}\n{usage}")),
            _ => files.push(a.clone()),
        }
    }
    let [ref_path, query_path] = files.as_slice() else {
        return Err(usage.to_string());
    };
    let reference = parse_csv(ref_path)?;
    let query = parse_csv(query_path)?;
    if reference.names != query.names {
        return Err(format!(
            "channel mismatch: {ref_path} has columns {:?}, {query_path} has {:?}",
            reference.names, query.names
        ));
    }
    let nc = reference.names.len();
    let mut params: WarpParams = match params_json {
        Some(j) => serde_json::from_str(&j).map_err(|e| format!("--params: {e}"))?,
        None => WarpParams::default(),
    };
    if let Some(w) = weights {
        params.weights = Some(parse_weights(&w, nc)?);
    }
    let rs = SignalRef::new(&reference.data, nc).map_err(|e| format!("{ref_path}: {e}"))?;
    let qs = SignalRef::new(&query.data, nc).map_err(|e| format!("{query_path}: {e}"))?;
    let start = Instant::now();
    let mut warp = align(rs, qs, &params).map_err(|e| e.to_string())?;
    for _ in 1..repeat {
        warp = align(rs, qs, &params).map_err(|e| e.to_string())?;
    }
    let wall_s = start.elapsed().as_secs_f64() / repeat as f64;
    if report {
        eprintln!("objective={:.12e} wall_s={wall_s:.6}", warp.objective());
    }
    let mut out = String::from("ref_sample,query_time\n");
    for (n, v) in warp.values().iter().enumerate() {
        writeln!(out, "{n},{v}").expect("writing to a String cannot fail");
    }
    Ok(out)
}

fn main() -> ExitCode {
    match run() {
        Ok(out) => {
            print!("{out}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
