//! The documented JSON outputs (docs/formats.md) keep their shape: every key path and the
//! JSON type of its values, for `schedule --json`, `inspect --json` and `schedule --cell
//! continuous --json`, on the guide's example task (two robots, three robots, and with hold
//! points and a hold rule), and for `inspect BAG --json` on an example bag, against the
//! committed golden shapes in `tests/data/json/`.
//!
//! A library field renamed or added cannot change an output silently: the outputs are the
//! command line's own types (`src/json.rs`), and a change of a shape fails here. The numbers
//! are the scheduler's and the model's, tested where they are made; the shapes pin what a
//! reader of the documents relies on. After a deliberate change of an output, regenerate the
//! shapes with `TANDEM_BLESS=1 cargo test -p tandem-cli --test json_outputs`, review the diff,
//! and update docs/formats.md.

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use common::*;
use serde_json::Value;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn examples(name: &str) -> String {
    repo()
        .join("fixtures/examples")
        .join(name)
        .display()
        .to_string()
}

/// The JSON type of a value (`number`, `string`, …; an empty array is `[]`).
fn type_name(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "bool",
        Value::Number(_) => "number",
        Value::String(_) => "string",
        Value::Array(a) if a.is_empty() => "[]",
        Value::Array(_) => "array",
        Value::Object(_) => "object",
    }
}

/// Collects every leaf path of `v` under `path` (`a.b[].c`: the elements of an array share
/// one path) with the set of types seen there.
fn walk(v: &Value, path: &str, out: &mut BTreeMap<String, Vec<&'static str>>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                let p = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                walk(x, &p, out);
            }
        }
        Value::Array(a) if !a.is_empty() => {
            for x in a {
                walk(x, &format!("{path}[]"), out);
            }
        }
        leaf => {
            let types = out.entry(path.to_owned()).or_default();
            let t = type_name(leaf);
            if !types.contains(&t) {
                types.push(t);
                types.sort_unstable();
            }
        }
    }
}

/// The shape of a JSON document: one line `path: type|type` per leaf path, sorted.
fn shape(doc: &str) -> String {
    let v: Value = serde_json::from_str(doc).expect("the output is JSON");
    let mut paths = BTreeMap::new();
    walk(&v, "", &mut paths);
    paths
        .iter()
        .map(|(p, t)| format!("{p}: {}\n", t.join("|")))
        .collect()
}

/// Compares the shape of `doc` with `tests/data/json/<name>.shape` (writes it when
/// `TANDEM_BLESS` is set).
fn check_shape(name: &str, doc: &str) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/json")
        .join(format!("{name}.shape"));
    let got = shape(doc);
    if std::env::var_os("TANDEM_BLESS").is_some() {
        std::fs::write(&path, &got).unwrap();
        return;
    }
    let want = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        got == want,
        "the shape of {name} changed (a documented output): got\n{got}\nwant ({}):\n{want}\n\
         If deliberate: TANDEM_BLESS=1 cargo test -p tandem-cli --test json_outputs, review the \
         diff and update docs/formats.md",
        path.display()
    );
}

/// The guide's example task fitted with `extra` arguments into `dir/name`.
fn fit(dir: &Path, name: &str, extra: &[&str]) -> String {
    let out = dir.join(name).display().to_string();
    let mut args: Vec<String> = vec!["fit".into(), "--params".into(), examples("params.toml")];
    args.extend((0..3).map(|i| examples(&format!("demo_{i}.csv"))));
    args.extend(extra.iter().map(|s| (*s).to_owned()));
    args.extend(["-o".into(), out.clone()]);
    ok(&tandem(&args));
    out
}

fn run(args: &[&str]) -> String {
    ok(&tandem(args))
}

#[test]
fn two_robots_after_one_round() {
    // The golden state file: fitted, one round recorded.
    let dir = scratch("json-two");
    let state = dir.join("example.tandem");
    std::fs::copy(repo().join("fixtures/state/example.tandem"), &state).unwrap();
    let s = state.display().to_string();
    check_shape(
        "schedule",
        &run(&["schedule", &s, "--json", "--samples", "200"]),
    );
    let inspect = run(&["inspect", &s, "--json"]);
    check_shape("inspect", &inspect);
    // Spot checks of what the shape cannot say.
    let doc: Value = serde_json::from_str(&inspect).unwrap();
    assert_eq!(doc["rounds_recorded"], 1);
    assert_eq!(doc["confidence"]["params"]["gamma_p"], 10.0);
    assert!(doc["schedule"]["schedule"].get("holds").is_none());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn three_robots_in_a_continuous_cell() {
    let dir = scratch("json-cell");
    let s = fit(&dir, "cell3.tandem", &["--robots", "3"]);
    let plan = run(&["schedule", &s, "--cell", "continuous", "--json"]);
    check_shape("cyclic_plan", &plan);
    // Printed in the documented order of its keys (not alphabetical).
    let keys: Vec<&str> = plan
        .lines()
        .filter(|l| l.starts_with("  \"") && !l.starts_with("   "))
        .map(|l| l.trim().split('"').nth(1).unwrap())
        .collect();
    assert_eq!(
        keys,
        [
            "n_robots",
            "order",
            "period_s",
            "lc_s",
            "robots",
            "tasks_per_hour",
            "operator_share",
            "lower_bound_s",
            "gap",
            "order_exhaustive",
            "orders_evaluated"
        ]
    );
    let doc: Value = serde_json::from_str(&plan).unwrap();
    assert_eq!(doc["n_robots"], 3);
    assert_eq!(doc["robots"].as_array().unwrap().len(), 3);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn hold_points_and_a_hold_rule() {
    let dir = scratch("json-holds");
    let s = fit(
        &dir,
        "holds.tandem",
        &["--hold-at", "0.05,0.35", "--hold-where", "x<0.05"],
    );
    let schedule = run(&["schedule", &s, "--json", "--samples", "200"]);
    check_shape("schedule_holds", &schedule);
    check_shape("inspect_holds", &run(&["inspect", &s, "--json"]));
    check_shape(
        "cyclic_plan_holds",
        &run(&["schedule", &s, "--cell", "continuous", "--json"]),
    );
    let doc: Value = serde_json::from_str(&run(&["inspect", &s, "--json"])).unwrap();
    assert_eq!(
        doc["holds"]["declared"]["at_s"],
        serde_json::json!([0.05, 0.35])
    );
    assert_eq!(
        doc["holds"]["declared"]["rules"],
        serde_json::json!(["x<0.05"])
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_bag() {
    let bag = repo().join("fixtures/examples/ros2/demo_0.mcap");
    let doc = run(&["inspect", &bag.display().to_string(), "--json"]);
    check_shape("inspect_bag", &doc);
    let v: Value = serde_json::from_str(&doc).unwrap();
    assert_eq!(v["rounds"], 0);
    assert_eq!(v["topics"][0]["role"], "channel");
}
