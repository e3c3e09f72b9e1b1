//! The fixture problem for benches and examples: `fixtures/sanding/problem.csv` when it exists,
//! else a synthetic problem shaped like it.

use std::path::PathBuf;

use tandem_schedule::Problem;

/// Reference sample period of the fixtures (s).
const DT_S: f64 = 0.01;

/// Loads `fixtures/sanding/problem.csv` (header
/// `ref_sample,grad_mean,grad_min,grad_max,pass,phase`) with the mid-study confidence pattern:
/// sanding of passes 1–3 low-confidence, everything else high-confidence. Falls back to
/// [`synthetic`]. Returns the problem and a label saying which one it is.
pub(crate) fn mid_study_problem() -> (Problem, String) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/sanding/problem.csv");
    match std::fs::read_to_string(&path) {
        Ok(text) => match parse(&text) {
            Ok(p) => (p, format!("fixture {}", path.display())),
            Err(e) => panic!("{}: {e}", path.display()),
        },
        Err(_) => (synthetic(), "synthetic fixture-like problem".to_string()),
    }
}

/// [`mid_study_problem`] with every sample of the fixture's transitions between passes (its
/// `phase` column) a hold point (the tool is off and lifted); the synthetic fallback's
/// transitions (its high-confidence samples between passes) likewise. Returns the problem,
/// the label and the number of hold points.
#[allow(dead_code, reason = "not every bench or example plans with holds")]
pub(crate) fn mid_study_problem_with_holds() -> (Problem, String, usize) {
    let (problem, label) = mid_study_problem();
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/sanding/problem.csv");
    let holds: Vec<usize> = match std::fs::read_to_string(&path) {
        Ok(text) => text
            .lines()
            .skip(1)
            .filter(|l| !l.trim().is_empty())
            .enumerate()
            .filter(|(_, l)| l.trim().ends_with(",transition"))
            .map(|(n, _)| n)
            .collect(),
        Err(_) => (900..1600).chain(2500..3200).chain(4100..4800).collect(),
    };
    let n = holds.len();
    let problem = problem
        .with_holds(holds)
        .expect("the transitions are high-confidence samples");
    (problem, label, n)
}

/// The problem in the fixture format at `path` with the mid-study confidence pattern of
/// [`mid_study_problem`] (panics naming the file on a read or parse error: test data).
#[allow(dead_code, reason = "only the tests pin a problem file")]
pub(crate) fn mid_study_problem_at(path: &std::path::Path) -> Problem {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    parse(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn parse(text: &str) -> Result<Problem, String> {
    let mut lines = text.lines();
    let header = lines.next().ok_or("empty file")?.trim();
    if header != "ref_sample,grad_mean,grad_min,grad_max,pass,phase" {
        return Err(format!("unexpected header `{header}`"));
    }
    let (mut conf, mut mean, mut min, mut max) = (vec![], vec![], vec![], vec![]);
    for (i, line) in lines.enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let f: Vec<&str> = line.trim().split(',').collect();
        if f.len() != 6 {
            return Err(format!("line {}: expected 6 fields", i + 2));
        }
        let num = |s: &str| s.parse::<f64>().map_err(|e| format!("line {}: {e}", i + 2));
        mean.push(num(f[1])?);
        min.push(num(f[2])?);
        max.push(num(f[3])?);
        let pass: u32 = f[4].parse().map_err(|e| format!("line {}: {e}", i + 2))?;
        conf.push(!(f[5] == "sanding" && (1..=3).contains(&pass)));
    }
    Problem::new(conf, mean, min, max, DT_S).map_err(|e| e.to_string())
}

/// ≈6000 samples at 10 ms: 4 sanding passes of 900 samples (bounds [0.8, 1.3]×mean; passes
/// 1–3 low-confidence) joined by 3 transitions of 700 samples (bounds [0.5, 2]×mean,
/// high-confidence). The mean gradient wobbles smoothly around 1.
pub(crate) fn synthetic() -> Problem {
    let (mut conf, mut mean, mut min, mut max) = (vec![], vec![], vec![], vec![]);
    for pass in 1..=4 {
        for _ in 0..900 {
            let n = mean.len() as f64;
            let m = 1.0 + 0.1 * (n / 150.0).sin();
            conf.push(pass == 4);
            mean.push(m);
            min.push(0.8 * m);
            max.push(1.3 * m);
        }
        if pass < 4 {
            for _ in 0..700 {
                let n = mean.len() as f64;
                let m = 1.2 + 0.2 * (n / 100.0).cos();
                conf.push(true);
                mean.push(m);
                min.push(0.5 * m);
                max.push(2.0 * m);
            }
        }
    }
    Problem::new(conf, mean, min, max, DT_S).expect("synthetic bounds are ordered and finite")
}
