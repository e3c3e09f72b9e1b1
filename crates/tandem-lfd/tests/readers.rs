//! CSV and JSON readers: every malformed case is an error naming file, line and column.

use tandem_lfd::{ChannelSchema, Demonstration, Error, FitParams, TaskModel};

fn csv_err(text: &str) -> String {
    let e = Demonstration::from_csv_str(text, "demo.csv", None).unwrap_err();
    e.to_string()
}

fn json_err(text: &str) -> String {
    Demonstration::from_json_str(text, "demo.json", None)
        .unwrap_err()
        .to_string()
}

#[test]
fn csv_empty_file() {
    assert_eq!(csv_err(""), "demo.csv:1:1: empty file");
    assert_eq!(csv_err("\n  \n"), "demo.csv:1:1: empty file");
}

#[test]
fn csv_ragged_rows() {
    let short = "t,a,b\n0,1,2\n0.01,3\n";
    assert_eq!(
        csv_err(short),
        "demo.csv:3:3: ragged row: expected 3 fields, found 2"
    );
    let long = "a,b\n1,2\n3,4,5\n";
    assert_eq!(
        csv_err(long),
        "demo.csv:3:3: ragged row: expected 2 fields, found 3"
    );
}

#[test]
fn csv_non_numeric_and_non_finite() {
    let text = "a,b\n1,2\n3,x4\n";
    assert_eq!(
        csv_err(text),
        "demo.csv:3:2: column `b`: not a number: `x4`"
    );
    let text = "a,b\n1,2\nNaN,4\n";
    assert_eq!(
        csv_err(text),
        "demo.csv:3:1: column `a`: non-finite value `NaN`"
    );
    let text = "a,b\n1,inf\n3,4\n";
    assert_eq!(
        csv_err(text),
        "demo.csv:2:2: column `b`: non-finite value `inf`"
    );
    let text = "a,b\n1,2\n3,\n";
    assert_eq!(csv_err(text), "demo.csv:3:2: column `b`: not a number: ``");
}

#[test]
fn values_beyond_the_magnitude_limit_are_rejected_where_they_are() {
    // CSV: line, column and channel; the `t` column is not a channel but counts as a column.
    assert_eq!(
        csv_err("t,a,b\n0,1,2\n0.01,3,-1e101\n"),
        "demo.csv:3:3: channel `b`: value `-1e101` is beyond ±1e100 (squared differences \
         would overflow; check the units)"
    );
    // 1e100 itself is accepted.
    assert!(Demonstration::from_csv_str("a\n1e100\n2\n", "f", None).is_ok());
    // JSON: the row of the value.
    let text = "{\"channels\": [\"a\"],\n \"samples\": [[1],\n [2e150]]}";
    let e = json_err(text);
    assert!(
        e.starts_with("demo.json:3:2: sample 1, channel `a`: value 2e150 is beyond"),
        "{e}"
    );
    // In memory (a library caller of `Demonstration::new`, e.g. before `fit_aligned`).
    let e = Demonstration::new(vec!["a".into()], vec![0.0, 1e300], 0.01).unwrap_err();
    assert!(matches!(e, Error::BadData { .. }));
    assert_eq!(
        e.to_string(),
        "<memory>: sample 1, channel `a`: value 1e300 is beyond ±1e100 (squared differences \
         would overflow; check the units)"
    );
}

#[test]
fn tangent_names_follow_the_channels_and_the_schema() {
    let schema = ChannelSchema::default();
    let d = Demonstration::from_csv_str(
        "t0,qx,qy,qz,qw,force\n0,0,0,0,1,1\n1,0,0,0,1,2\n",
        "d.csv",
        None,
    )
    .unwrap();
    assert_eq!(
        d.tangent_names(&schema).unwrap(),
        ["t0", "q.rx", "q.ry", "q.rz", "force", "rate"]
    );
    // The fitted model reports the same names.
    let id = vec![0.0, 1.0];
    let model = TaskModel::fit_aligned(
        &[d.clone(), d.clone()],
        &[id.clone(), id],
        &FitParams::default(),
    )
    .unwrap();
    assert_eq!(model.tangent_names(), d.tangent_names(&schema).unwrap());
}

#[test]
fn a_partial_quaternion_block_is_an_error_naming_the_file() {
    let d = Demonstration::from_csv_str("a,qx,qz\n0,0,0\n1,0,0\n", "part.csv", None).unwrap();
    let e = d.tangent_names(&ChannelSchema::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "part.csv:1: quaternion block `q` is incomplete: [\"qy\", \"qw\"] missing, [\"qx\", \
         \"qz\"] present (give all four channels, or none, or change `schema.quaternions`)"
    );
    // The fit reports the same error.
    let id = vec![0.0, 1.0];
    let fit = TaskModel::fit_aligned(&[d.clone(), d], &[id.clone(), id], &FitParams::default());
    assert!(matches!(fit, Err(Error::PartialQuaternionBlock { .. })));
}

#[test]
fn channels_named_like_derived_coordinates_are_rejected() {
    let schema = ChannelSchema::default();
    let rate = Demonstration::from_csv_str("t,x,rate\n0,0,1\n0.01,1,1\n", "r.csv", None).unwrap();
    assert_eq!(
        rate.tangent_names(&schema).unwrap_err().to_string(),
        "r.csv:1:3: channel `rate` has the name of a coordinate the model derives: the warp \
         gradient (speed); rename the channel"
    );
    let id = vec![0.0, 1.0];
    let fit = TaskModel::fit_aligned(
        &[rate.clone(), rate],
        &[id.clone(), id.clone()],
        &FitParams::default(),
    );
    assert!(matches!(fit, Err(Error::ReservedChannelName { .. })));
    // `q.rx` collides only when block `q` is present.
    let text = "qx,qy,qz,qw,q.rx\n0,0,0,1,5\n0,0,0,1,6\n";
    let clash = Demonstration::from_csv_str(text, "c.csv", None).unwrap();
    let e = clash.tangent_names(&schema).unwrap_err().to_string();
    assert!(e.contains("`q.rx`") && e.contains("block `q`"), "{e}");
    let alone = Demonstration::from_csv_str("x,q.rx\n0,5\n1,6\n", "a.csv", None).unwrap();
    assert_eq!(alone.tangent_names(&schema).unwrap(), ["x", "q.rx", "rate"]);
}

#[test]
fn csv_too_few_samples() {
    assert_eq!(
        csv_err("a,b\n1,2\n"),
        "demo.csv:2:1: 1 sample(s); at least 2 are required"
    );
    assert_eq!(
        csv_err("a,b\n"),
        "demo.csv:1:1: 0 sample(s); at least 2 are required"
    );
}

#[test]
fn csv_bad_header() {
    assert_eq!(
        csv_err("a,,b\n1,2,3\n"),
        "demo.csv:1:2: bad header: empty column name"
    );
    assert_eq!(
        csv_err("a,b,a\n1,2,3\n"),
        "demo.csv:1:3: bad header: column `a` repeats column 1"
    );
    assert_eq!(
        csv_err("t\n0\n1\n"),
        "demo.csv:1:1: bad header: no data channels"
    );
}

#[test]
fn csv_bad_time_column() {
    let text = "a,t\n1,0.00\n2,0.01\n3,0.01\n";
    assert_eq!(
        csv_err(text),
        "demo.csv:4:2: time column `t`: 0.01 does not increase after 0.01 (times must be \
         strictly increasing; sort the log or remove repeated rows)"
    );
    let text = "t,a\n0.00,1\n0.01,2\n0.025,3\n0.03,4\n";
    assert!(
        csv_err(text).starts_with("demo.csv:4:1: time column `t`: this time is 5.000 ms off"),
        "{}",
        csv_err(text)
    );
    // Within 25 % of a period of the even grid: accepted, Δt_s = the mean step (snapped to a
    // whole rate only within 0.1 %: 0.010025 s is 99.75 Hz, 0.25 % from 100 Hz).
    let d = Demonstration::from_csv_str("t,a\n0,1\n0.01,2\n0.02005,3\n", "f", None).unwrap();
    assert_eq!(d.dt_s(), 0.010025);
}

#[test]
fn json_malformed_cases() {
    assert_eq!(json_err(""), "demo.json:1:1: empty file");
    let ragged = "{\"channels\": [\"a\", \"b\"],\n \"samples\": [[1, 2],\n   [3]]}";
    assert_eq!(
        json_err(ragged),
        "demo.json:3:4: ragged row: sample 1 has 1 values, expected 2"
    );
    let text = "{\"channels\": [\"a\"],\n \"samples\": [[1], [\"x\"]]}";
    assert!(
        json_err(text).starts_with("demo.json:2:"),
        "{}",
        json_err(text)
    );
    assert!(
        json_err(text).contains("invalid type: string"),
        "{}",
        json_err(text)
    );
    let text = "{\"channels\": [\"a\"],\n \"samples\": [[1],\n [NaN]]}";
    assert!(
        json_err(text).starts_with("demo.json:3:3:"),
        "{}",
        json_err(text)
    );
    let text = "{\"channels\": [\"a\"], \"samples\": [[1], [1e999]]}";
    assert!(
        json_err(text).starts_with("demo.json:1:"),
        "{}",
        json_err(text)
    );
    let text = "{\"channels\": [\"a\"], \"samples\": [[1]]}";
    assert_eq!(
        json_err(text),
        "demo.json:1:32: 1 sample(s); at least 2 are required"
    );
    let text = "{\"channels\": [\"a\"], \"samples\": [[1], [2]], \"extra\": 1}";
    assert!(
        json_err(text).contains("unknown field `extra`"),
        "{}",
        json_err(text)
    );
    let text = "{\"channels\": [\"a\", \"a\"], \"samples\": [[1, 2], [2, 3]]}";
    assert!(
        json_err(text).contains("appears twice"),
        "{}",
        json_err(text)
    );
}

#[test]
fn json_reads_dt_and_round_trips() {
    let text = "{\"channels\": [\"a\", \"b\"], \"dt_s\": 0.02, \"samples\": [[1, 2], [3, 4]]}";
    let d = Demonstration::from_json_str(text, "d.json", None).unwrap();
    assert_eq!(d.dt_s(), 0.02);
    assert_eq!(d.samples(), [1.0, 2.0, 3.0, 4.0]);
    let via_serde: Demonstration = serde_json::from_str(&d.to_json_string()).unwrap();
    assert_eq!(via_serde.samples(), d.samples());
    let without_dt = "{\"channels\": [\"a\"], \"samples\": [[1], [2]]}";
    assert_eq!(
        Demonstration::from_json_str(without_dt, "d", Some(0.5))
            .unwrap()
            .dt_s(),
        0.5
    );
}

#[test]
fn missing_file_names_the_path() {
    let e = Demonstration::from_csv_path("/nonexistent/demo_9.csv", None).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("/nonexistent/demo_9.csv: cannot read"),
        "{e}"
    );
}

#[test]
fn demonstration_sets_are_checked() {
    let a = Demonstration::from_csv_str("a,b\n1,2\n3,4\n", "a.csv", None).unwrap();
    let b = Demonstration::from_csv_str("a,c\n1,2\n3,4\n", "b.csv", None).unwrap();
    let id = vec![0.0, 1.0];
    let e = TaskModel::fit_aligned(
        &[a.clone(), b],
        &[id.clone(), id.clone()],
        &FitParams::default(),
    )
    .unwrap_err();
    assert!(matches!(e, Error::ChannelMismatch { .. }));
    assert!(
        e.to_string()
            .starts_with("b.csv:1:2: channels [\"a\", \"c\"] differ"),
        "{e}"
    );
    let e = TaskModel::fit_aligned(
        std::slice::from_ref(&a),
        std::slice::from_ref(&id),
        &FitParams::default(),
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "1 demonstration(s); at least 2 are required for a variance"
    );
    // Same set in another order is reordered, not rejected.
    let c = Demonstration::from_csv_str("b,a\n2,1\n4,3\n", "c.csv", None).unwrap();
    let m = TaskModel::fit_aligned(&[a, c], &[id.clone(), id], &FitParams::default()).unwrap();
    assert!(m.sigma2_d().iter().all(|&s| s == 0.0));
    let slow = Demonstration::from_csv_str("t,a,b\n0,1,2\n0.1,3,4\n", "slow.csv", None).unwrap();
    let fast = Demonstration::from_csv_str("a,b\n1,2\n3,4\n", "fast.csv", None).unwrap();
    let e = TaskModel::fit_aligned(
        &[fast, slow],
        &[vec![0.0, 1.0], vec![0.0, 1.0]],
        &FitParams::default(),
    )
    .unwrap_err();
    assert!(matches!(e, Error::SamplePeriodMismatch { .. }), "{e}");
    // Named at its header's `t` column, where the period came from.
    assert!(
        e.to_string()
            .starts_with("slow.csv:1:1: sample period 0.1 s"),
        "{e}"
    );
    // Two files against one: the majority's period decides, so a 1 kHz file given first is
    // the one named (not the good file after it), and the message says whose period it is.
    let khz = Demonstration::from_csv_str("t,a,b\n0,1,2\n0.001,3,4\n", "khz.csv", None).unwrap();
    let b = Demonstration::from_csv_str("t,a,b\n0,1,2\n0.01,3,4\n", "b.csv", None).unwrap();
    let c = Demonstration::from_csv_str("t,a,b\n0,1,2\n0.01,3,4\n", "c.csv", None).unwrap();
    let e = TaskModel::fit_aligned(
        &[khz.clone(), b.clone(), c],
        &[vec![0.0, 1.0], vec![0.0, 1.0], vec![0.0, 1.0]],
        &FitParams::default(),
    )
    .unwrap_err();
    assert!(
        e.to_string().starts_with(
            "khz.csv:1:1: sample period 0.001 s differs from 0.01 s, the period of 2 of the 3 \
             demonstrations (b.csv, c.csv), by more than 1 %"
        ),
        "{e}"
    );
    // One against one: the first file's period is kept and both files are named.
    let e = TaskModel::fit_aligned(
        &[khz, b],
        &[vec![0.0, 1.0], vec![0.0, 1.0]],
        &FitParams::default(),
    )
    .unwrap_err();
    assert!(
        e.to_string().starts_with(
            "b.csv:1:1: sample period 0.01 s differs from 0.001 s, the period of khz.csv"
        ),
        "{e}"
    );
    // A header after a blank line: its own line; a channel missing (no stranger column):
    // the header line alone.
    let d = Demonstration::from_csv_str("\nt,a\n0,1\n0.01,3\n", "d.csv", None).unwrap();
    let e = d.conform_to(&["a".into(), "b".into()]).unwrap_err();
    assert!(
        e.to_string().starts_with("d.csv:2: channels [\"a\"]"),
        "{e}"
    );
    assert_eq!(d.header_at(Some("a")), (Some(2), Some(2)));
    // In memory there is no header to point at.
    let m = Demonstration::new(vec!["a".into()], vec![1.0, 2.0], 0.01).unwrap();
    assert_eq!(m.header_at(Some("a")), (None, None));
    let e = m.conform_to(&["b".into()]).unwrap_err();
    assert!(e.to_string().starts_with("<memory>: channels"), "{e}");
}
