//! The guide's glossary claims to explain every term `tandem` prints: this test runs the
//! command line on the example fixtures (fit with hold points, inspect, schedule, the
//! continuous plan, simulate, record, a bag's topics and a fit from bags) and fails on a term
//! of [`TERMS`] that the output contains and the glossary (docs/guide.md, "### Glossary")
//! does not. The schedule sources are checked one by one in `src/gantt.rs`.

mod common;
#[path = "support/glossary.rs"]
mod glossary;

use std::path::{Path, PathBuf};

use common::{ok, scratch, tandem};

/// The terms a reader of `tandem`'s output needs explained: what the output says (matched
/// case-sensitively in stdout and stderr) and the glossary's words for it (matched
/// case-insensitively in the glossary). A new term the command line prints belongs here and
/// in the glossary.
const TERMS: &[(&str, &str)] = &[
    ("reference:", "reference sample"),
    ("reference samples", "reference sample"),
    ("high confidence", "high / low confidence"),
    ("low-confidence", "high / low confidence"),
    ("σ²_D", "σ²_D"),
    ("ranges (W = diag(1/r²))", "W = diag(1/r²)"),
    ("rate=", "`rate`"),
    ("correction directions", "correction directions"),
    ("demonstrated speed bounds", "demonstrated speed bounds"),
    ("observations", "observations, supervised, corrected"),
    ("supervised", "supervised"),
    ("corrected", "corrected"),
    ("rounds recorded", "round"),
    ("T_total", "T_total"),
    ("τ =", "`τ`, offset"),
    ("lower bound", "lower bound"),
    ("without margins", "margins"),
    ("margin-aware", "margin-aware"),
    (
        "operator-limited lower bound",
        "operator-limited lower bound",
    ),
    ("fastest serial", "fastest serial schedule (fallback)"),
    ("hold points", "hold points"),
    ("active", "active / inactive"),
    ("inactive", "active / inactive"),
    ("release rules", "release rules"),
    ("continuous cell", "continuous cell"),
    ("period P", "period `P`"),
    ("tasks/h", "tasks/h"),
    ("operator busy", "operator busy"),
    ("certificate", "certificate"),
    ("D_min", "D_min"),
    ("operator's order", "operator's order"),
    ("order search", "order search"),
    ("exhaustive", "exhaustive"),
    ("local search", "local search"),
    ("stretch durations at ψ̇̄", "stretch durations"),
    ("the prior alone", "prior"),
    ("operator error rates", "operator error rates"),
    ("false corrections", "false corrections"),
    ("misses", "misses"),
    ("latched", "latched"),
    ("tick", "tick"),
    ("overlap", "overlap"),
    ("over plan", "over / under plan"),
    ("needed but unsupervised", "needed but unsupervised"),
    ("reopened:", "reopened"),
    ("previous schedule: ", "previous schedule: …"),
    ("high-conf %", "high / low confidence"),
    ("grid of", "grid (of a bag)"),
    ("jitter", "jitter"),
    ("time column `t`", "jitter"),
];

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// stdout and stderr of a successful run.
fn run(args: &[&str]) -> String {
    let out = tandem(args);
    let stdout = ok(&out);
    format!("{stdout}{}", String::from_utf8_lossy(&out.stderr))
}

fn s(p: &Path) -> String {
    p.display().to_string()
}

#[test]
fn every_term_the_command_line_prints_is_in_the_glossary() {
    let dir = scratch("glossary");
    let ex = repo().join("fixtures/examples");
    let state = s(&dir.join("cell.tandem"));
    let demos: Vec<String> = (0..3)
        .map(|i| s(&ex.join(format!("demo_{i}.csv"))))
        .collect();
    let params = s(&ex.join("params.toml"));
    let mut printed = String::new();
    let mut fit = vec!["fit"];
    fit.extend(demos.iter().map(String::as_str));
    fit.extend(["--params", &params, "--hold-where", "force<6", "-o", &state]);
    printed += &run(&fit);
    printed += &run(&["inspect", &state]);
    printed += &run(&["schedule", &state]);
    printed += &run(&["schedule", &state, "--cell", "continuous"]);
    let need = s(&ex.join("need.csv"));
    printed += &run(&["simulate", &state, "--need", &need, "--rounds", "2"]);
    let pair = |i: usize, kind: &str| s(&ex.join(format!("pair_1_robot_{i}{kind}.csv")));
    let (e1, l1, c1) = (pair(1, ""), pair(1, ".reflog"), pair(1, ".corr"));
    let (e2, l2, c2) = (pair(2, ""), pair(2, ".reflog"), pair(2, ".corr"));
    printed += &run(&[
        "record",
        &state,
        "--execution",
        &e1,
        "--log",
        &l1,
        "--corrections",
        &c1,
        "--execution",
        &e2,
        "--log",
        &l2,
        "--corrections",
        &c2,
    ]);
    // Three robots: the operator-limited bound and the N-robot schedule lines.
    let three = s(&dir.join("three.tandem"));
    let mut fit3 = vec!["fit"];
    fit3.extend(demos.iter().map(String::as_str));
    fit3.extend(["--params", &params, "--robots", "3", "-o", &three]);
    printed += &run(&fit3);
    // Bags: a bag's topics, the grid note of a fit from bags.
    let bags: Vec<String> = (0..3)
        .map(|i| s(&ex.join(format!("ros2/demo_{i}.mcap"))))
        .collect();
    printed += &run(&["inspect", &bags[0]]);
    let from_bags = s(&dir.join("bags.tandem"));
    let mut fitb = vec!["fit"];
    fitb.extend(bags.iter().map(String::as_str));
    fitb.extend(["--params", &params, "-o", &from_bags]);
    printed += &run(&fitb);
    // A file whose `t` column jitters: the jitter note.
    let jittered = dir.join("jittered.csv");
    let text = std::fs::read_to_string(&demos[1]).expect("demo_1.csv");
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    let fields: Vec<&str> = lines[5].split(',').collect();
    let t: f64 = fields[0].parse().expect("a time");
    lines[5] = format!("{:.3},{}", t + 0.001, fields[1..].join(","));
    std::fs::write(&jittered, lines.join("\n") + "\n").expect("write");
    let jitter_state = s(&dir.join("jitter.tandem"));
    printed += &run(&[
        "fit",
        &demos[0],
        &s(&jittered),
        "--params",
        &params,
        "-o",
        &jitter_state,
    ]);

    let glossary = glossary::glossary().to_lowercase();
    let mut seen = 0;
    let mut missing = Vec::new();
    for &(term, entry) in TERMS {
        if !printed.contains(term) {
            continue;
        }
        seen += 1;
        if !glossary.contains(&entry.to_lowercase()) {
            missing.push(format!("`{term}` (glossary words: `{entry}`)"));
        }
    }
    assert!(
        missing.is_empty(),
        "printed but not in docs/guide.md's glossary: {}\n\noutput:\n{printed}",
        missing.join(", ")
    );
    // Not vacuous: most of the terms were printed by these runs.
    assert!(
        seen >= TERMS.len() - 6,
        "only {seen} of {} terms printed:\n{printed}",
        TERMS.len()
    );
    std::fs::remove_dir_all(&dir).expect("clean up");
}
