//! The state file through the public API: the committed golden file of the current format
//! (`fixtures/state/example.tandem`, regenerated only by `cargo xtask fixtures`) loads with
//! the values its inputs give, and damaged or other-version files give clear errors.

use std::path::{Path, PathBuf};

use tandem_confidence::{Confidence, ConfidenceParams, MissEvidence};
use tandem_lfd::{Demonstration, RateTerm, TaskModel};
use tandem_planner::state::{
    self, FORMAT_VERSION, NEWEST_READABLE_VERSION, OLDEST_READABLE_VERSION,
};
use tandem_planner::{Error, Planner, PlannerParams};
use tandem_schedule::validate;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The golden state file: `tandem fit --params params.toml demo_0.csv demo_1.csv demo_2.csv`
/// then `tandem record` of `pair_1_robot_{1,2}`, all from `fixtures/examples/`.
fn golden_path() -> PathBuf {
    repo().join("fixtures/state/example.tandem")
}

fn examples(name: &str) -> PathBuf {
    repo().join("fixtures/examples").join(name)
}

/// Rows of a correction-flag file (`supervised,corrected`) whose line starts with `prefix`.
fn flag_rows(file: &str, prefix: &str) -> usize {
    let text = std::fs::read_to_string(examples(file)).unwrap();
    text.lines()
        .skip(1)
        .filter(|l| l.starts_with(prefix))
        .count()
}

fn tmp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tandem-state-file-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn the_golden_state_file_loads_with_the_values_of_its_inputs() {
    let bytes = std::fs::read(golden_path()).unwrap();
    assert_eq!(
        u32::from_le_bytes(bytes[8..12].try_into().unwrap()),
        FORMAT_VERSION,
        "fixtures/state/example.tandem is not of the current format: run `cargo xtask fixtures` \
         and review the diff"
    );
    let p = Planner::load(golden_path()).unwrap();
    assert_eq!(p.params().fit.rate_term, p.model().rate_term());

    // The parameters are fixtures/examples/params.toml's.
    let text = std::fs::read_to_string(examples("params.toml")).unwrap();
    let params: PlannerParams = toml::from_str(&text).unwrap();
    assert_eq!(p.params(), &params);
    assert_eq!(
        (p.params().fit.k_max, p.params().sampler.samples),
        (2, 2000)
    );
    assert_eq!(p.params().sampler.seed, 1);

    // The model: demo_0.csv's 40 samples at 10 ms are the reference; three demonstrations
    // and the pair's two executions (Eq. 21).
    let model = p.model();
    assert_eq!(model.n_ref(), 40);
    assert!((model.dt_s() - 0.01).abs() < 1e-12, "{}", model.dt_s());
    assert_eq!(model.channel_names(), ["x", "force"]);
    assert_eq!(model.count(), 5);
    assert_eq!(p.rounds_recorded(), 1);
    // Every demonstration and execution starts at x = 0 m with 5 N and ends at x = 1 m with
    // 5 N; warps and reference-time logs are pinned at both ends, so the mean is exactly that.
    assert_eq!(&model.mean()[..2], &[0.0, 5.0]);
    assert_eq!(&model.mean()[2 * 39..], &[1.0, 5.0]);

    // The observations: every supervised row of the two correction files is one unit of
    // supervised mass (Eq. 9, split between neighbouring reference samples), every corrected
    // row one unit of corrections.
    let supervised =
        flag_rows("pair_1_robot_1.corr.csv", "1,") + flag_rows("pair_1_robot_2.corr.csv", "1,");
    let corrected =
        flag_rows("pair_1_robot_1.corr.csv", "1,1") + flag_rows("pair_1_robot_2.corr.csv", "1,1");
    assert_eq!((supervised, corrected), (84, 33));
    let obs = p.observations();
    // With one vote per execution (the default) each of the two executions adds exactly one
    // unit to every reference sample it touched (all 40: every sample was supervised before
    // the update); the paper's model adds one unit per row (the version 6 file of the same
    // inputs holds exactly 84 and 33).
    assert!(p.params().confidence.one_vote_per_execution);
    assert!(obs.supervised().iter().all(|&s| s == 2.0));
    assert!(obs.total_corrections() < corrected as f64);
    let paper = Planner::load(v6_path()).unwrap();
    let paper_obs = paper.observations();
    assert!((paper_obs.total_supervised() - supervised as f64).abs() < 1e-9);
    assert!((paper_obs.total_corrections() - corrected as f64).abs() < 1e-9);
    // The share of corrections per sample is the paper's split within each execution, so a
    // sample is uncorrected with votes exactly where it is uncorrected in the paper's counts.
    for (c, pc) in obs.corrections().iter().zip(paper_obs.corrections()) {
        assert_eq!(*c == 0.0, *pc == 0.0);
    }

    // The confidence is the prior of the three demonstrations, updated once with the new
    // model's variance and the observations (Eq. 9–12, latched).
    let demos: Vec<Demonstration> = (0..3)
        .map(|i| Demonstration::from_csv_path(examples(&format!("demo_{i}.csv")), None).unwrap())
        .collect();
    let fitted = TaskModel::fit(&demos, &params.fit).unwrap();
    let mut conf = Confidence::from_prior(fitted.sigma2_d(), params.confidence.clone()).unwrap();
    conf.update(model.sigma2_d(), obs).unwrap();
    assert_eq!(p.confidence(), &conf);
    assert!(
        p.confidence().n_high() < 40,
        "the corrected stretch stays low-confidence"
    );

    // The schedule: checked at the default tick Δt_s, valid for the loaded problem, its
    // T_total the clock's, and never slower than the serial schedule.
    let s = p.schedule();
    assert_eq!(s.tick_s, model.dt_s());
    assert_eq!((s.n_robots(), s.offsets_s.len()), (2, 1));
    assert_eq!([s.grad_exec[0].len(), s.grad_exec[1].len()], [40, 40]);
    validate(p.problem(), s).unwrap();
    assert_eq!(p.outcome().t_total_s, s.t_total_s(model.dt_s()));
    let serial = p.problem().serial_schedule(s.tick_s).unwrap();
    assert!(p.outcome().t_total_s <= serial.t_total_s(model.dt_s()));
    assert_eq!(p.coordinator().unwrap().tick_s(), s.tick_s);

    // Saving what was loaded gives the same bytes.
    let dir = tmp_dir("golden");
    let again = dir.join("again.tandem");
    p.save(&again).unwrap();
    assert!(
        std::fs::read(&again).unwrap() == bytes,
        "load + save changed the bytes"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `tests/fixtures/example_v4.tandem`: the golden state file as format version 4 wrote it
/// (two warps and one offset `offset_s`), copied before the format became version 5.
/// The parameters with the default rate term (an old file's parameters carry the form of its
/// model, `tandem_planner::state::v11::FIT_RATE_TERM`).
fn but_rate_term(p: &PlannerParams) -> PlannerParams {
    let mut p = p.clone();
    p.fit.rate_term = RateTerm::DEFAULT;
    p
}

fn v4_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/example_v4.tandem")
}

#[test]
fn a_version_4_file_loads_as_the_same_two_robot_schedule() {
    let bytes = std::fs::read(v4_path()).unwrap();
    assert_eq!(u32::from_le_bytes(bytes[8..12].try_into().unwrap()), 4);
    let old = Planner::load(v4_path()).unwrap();
    let new = Planner::load(v6_path()).unwrap();
    // The same planner: the version 6 file is the same inputs written as version 6.
    assert_eq!(old.params(), new.params());
    assert_eq!(old.model().mean(), new.model().mean());
    assert_eq!(old.model().count(), new.model().count());
    assert_eq!(old.confidence(), new.confidence());
    assert_eq!(old.rounds_recorded(), new.rounds_recorded());
    // The schedule: offset_s became offsets_s = [offset_s], the rest field for field.
    assert_eq!(old.schedule().offsets_s.len(), 1);
    assert_eq!(old.outcome(), new.outcome());
    validate(old.problem(), old.schedule()).unwrap();
    // Saving it writes the current version: byte for byte the version 5 file saved again
    // (neither knows the fingerprint of the round it holds).
    let dir = tmp_dir("v4");
    let again = dir.join("again.tandem");
    old.save(&again).unwrap();
    let v5_again = dir.join("v5_again.tandem");
    Planner::load(v5_path()).unwrap().save(&v5_again).unwrap();
    assert!(
        std::fs::read(&again).unwrap() == std::fs::read(&v5_again).unwrap(),
        "a version 4 file saved again is not the version 5 file saved again"
    );
    // A version 4 header on a version 7 payload does not decode: a clear error, no panic.
    let mut wrong = std::fs::read(golden_path()).unwrap();
    wrong[8..12].copy_from_slice(&4u32.to_le_bytes());
    let path = dir.join("wrong.tandem");
    std::fs::write(&path, &wrong).unwrap();
    let err = Planner::load(&path).unwrap_err();
    assert!(matches!(err, Error::Corrupt { .. }), "{err}");
    assert_names(&err, &path);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `tests/fixtures/example_v5.tandem`: the golden state file as format version 5 wrote it
/// (no round fingerprints), copied before the format became version 6.
fn v5_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/example_v5.tandem")
}

#[test]
fn a_version_5_file_loads_as_the_same_planner_without_round_fingerprints() {
    let v5 = std::fs::read(v5_path()).unwrap();
    assert_eq!(u32::from_le_bytes(v5[8..12].try_into().unwrap()), 5);
    let old = Planner::load(v5_path()).unwrap();
    let new = Planner::load(v6_path()).unwrap();
    assert_eq!(old.params(), new.params());
    assert_eq!(old.model().mean(), new.model().mean());
    assert_eq!(old.confidence(), new.confidence());
    assert_eq!(old.outcome(), new.outcome());
    assert_eq!(old.rounds_recorded(), new.rounds_recorded());
    // Version 6 only appends the fingerprints to version 5's payload: the version 6 payload
    // starts with the version 5 payload, then the list of one round fingerprint.
    let golden = std::fs::read(v6_path()).unwrap();
    let (v5_payload, v6_payload) = (&v5[24..], &golden[24..]);
    assert!(v6_payload.starts_with(v5_payload));
    assert_eq!(v6_payload[v5_payload.len()], 1, "one round fingerprint");
    // Saved again, it is version 6 with no fingerprint (an empty list).
    let dir = tmp_dir("v5");
    let again = dir.join("again.tandem");
    old.save(&again).unwrap();
    let bytes = std::fs::read(&again).unwrap();
    assert_eq!(
        u32::from_le_bytes(bytes[8..12].try_into().unwrap()),
        FORMAT_VERSION
    );
    let again = Planner::load(&again).unwrap();
    assert_eq!(again.params(), old.params());
    assert_eq!(again.confidence(), old.confidence());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `tests/fixtures/example_v6.tandem`: the golden state file as format version 6 wrote it
/// (the paper's confidence parameters, no evidence of misses), copied before the format
/// became version 7.
fn v6_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/example_v6.tandem")
}

#[test]
fn a_version_6_file_loads_with_the_papers_confidence_model() {
    let v6 = std::fs::read(v6_path()).unwrap();
    assert_eq!(u32::from_le_bytes(v6[8..12].try_into().unwrap()), 6);
    let old = Planner::load(v6_path()).unwrap();
    let new = Planner::load(golden_path()).unwrap();
    // The same inputs: the parameters differ only in the confidence's error rates, which a
    // version 6 file did not have (it was decided with the paper's model and keeps it).
    let paper = ConfidenceParams {
        false_correction_rate: 0.0,
        miss_rate: 0.0,
        estimate_error_rates: false,
        one_vote_per_execution: false,
        ..new.params().confidence.clone()
    };
    assert_eq!(paper, ConfidenceParams::paper());
    assert_eq!(old.params().confidence, paper);
    // Its fit parameters keep the rate term its model was fitted with (a refit reproduces
    // it): the absolute one; the rest are the golden file's.
    assert_eq!(old.params().fit.rate_term, RateTerm::Absolute);
    assert_eq!(old.model().rate_term(), RateTerm::Absolute);
    assert_eq!(
        but_rate_term(old.params()).fit,
        but_rate_term(new.params()).fit
    );
    assert_eq!(old.params().sampler, new.params().sampler);
    assert_eq!(old.model().mean(), new.model().mean());
    // The observations: the paper's one unit per control sample (the golden file holds one
    // vote per execution, checked in the golden test).
    assert!((old.observations().total_supervised() - 84.0).abs() < 1e-9);
    assert_eq!(old.observations().miss_evidence(), MissEvidence::default());
    assert_eq!(old.rounds_recorded(), new.rounds_recorded());
    // Its confidence is the paper's decision on the same data, recomputed here.
    let demos: Vec<Demonstration> = (0..3)
        .map(|i| Demonstration::from_csv_path(examples(&format!("demo_{i}.csv")), None).unwrap())
        .collect();
    // The file's model keeps the rate term it was fitted with: the absolute one,
    // `σ²_D(n) = Σ_j cov_jj(n) / r_j²` with the stored ranges (its rate range the range of the
    // warp gradients), not this build's relative one (docs/decisions.md, "Fit defaults on the
    // task zoo"). So is the prior of its decision: the three demonstrations' statistics
    // (today's fit) with the stored ranges.
    let absolute = |m: &TaskModel, ranges: &[f64]| -> Vec<f64> {
        let d = ranges.len();
        (0..m.n_ref())
            .map(|n| {
                let cov = m.covariance(n);
                (0..d)
                    .map(|j| cov[j * d + j] / (ranges[j] * ranges[j]))
                    .sum()
            })
            .collect()
    };
    let stored = old.model().ranges();
    let close = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .all(|(x, y)| (x - y).abs() <= 1e-12 * (1.0 + y.abs()))
    };
    assert!(close(
        old.model().sigma2_d(),
        &absolute(old.model(), stored)
    ));
    assert!(!close(
        new.model().sigma2_d(),
        &absolute(new.model(), new.model().ranges())
    ));
    let fitted = TaskModel::fit(&demos, &old.params().fit).unwrap();
    assert_eq!(
        &fitted.ranges()[..1],
        &stored[..1],
        "the channel's range is the data's"
    );
    let mut conf = Confidence::from_prior(&absolute(&fitted, stored), paper).unwrap();
    conf.update(old.model().sigma2_d(), old.observations())
        .unwrap();
    assert_eq!(old.confidence(), &conf);
    validate(old.problem(), old.schedule()).unwrap();
    // Saved again, it is the current version and loads as the same planner.
    let dir = tmp_dir("v6");
    let again = dir.join("again.tandem");
    old.save(&again).unwrap();
    let bytes = std::fs::read(&again).unwrap();
    assert_eq!(
        u32::from_le_bytes(bytes[8..12].try_into().unwrap()),
        FORMAT_VERSION
    );
    let back = Planner::load(&again).unwrap();
    assert_eq!(back.params(), old.params());
    assert_eq!(back.confidence(), old.confidence());
    assert_eq!(back.outcome(), old.outcome());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `tests/fixtures/example_v<version>.tandem`: the golden state file as that format version
/// wrote it, copied before the format changed.
fn old_golden_path(version: u32) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/fixtures/example_v{version}.tandem"))
}

/// The bytes of the version 10 golden file (`tests/fixtures/example_v10.tandem`) loaded and
/// saved again: the current format without a reference demonstration or stored executions
/// (the version 10 payload followed by `None` and an empty list, one byte each).
/// `tag` names the scratch folder (tests run in parallel).
fn v10_saved_again(tag: &str) -> Vec<u8> {
    let dir = tmp_dir(&format!("v10-again-{tag}"));
    let again = dir.join("again.tandem");
    Planner::load(old_golden_path(10))
        .unwrap()
        .save(&again)
        .unwrap();
    let bytes = std::fs::read(&again).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    bytes
}

/// Loads the old golden file of `version`, checks that it is of that version, loads with the
/// parameters of the current golden file and as the planner of the version 10 file of the
/// same inputs (same parameters, model and outcome: the current golden file's model has this
/// build's relative rate term, the old files keep the absolute one they were fitted with), is
/// `added` bytes shorter than the version 10 golden file, and saves as that file saved again
/// ([`v10_saved_again`]); returns the loaded planner.
fn old_golden_loads_and_saves_as_the_golden_file(version: u32, added: usize) -> Planner {
    let old_bytes = std::fs::read(old_golden_path(version)).unwrap();
    assert_eq!(
        u32::from_le_bytes(old_bytes[8..12].try_into().unwrap()),
        version
    );
    let old = Planner::load(old_golden_path(version)).unwrap();
    let new = Planner::load(golden_path()).unwrap();
    let v10_planner = Planner::load(old_golden_path(10)).unwrap();
    // The rate term of the parameters is the one the file's model was fitted with.
    assert_eq!(old.params().fit.rate_term, old.model().rate_term());
    assert_eq!(but_rate_term(old.params()), but_rate_term(new.params()));
    assert_eq!(old.params(), v10_planner.params());
    assert_eq!(old.model().sigma2_d(), v10_planner.model().sigma2_d());
    assert_eq!(old.outcome(), v10_planner.outcome());
    let v10 = std::fs::read(old_golden_path(10)).unwrap();
    assert_eq!(v10.len(), old_bytes.len() + added);
    let dir = tmp_dir(&format!("v{version}"));
    let again = dir.join("again.tandem");
    old.save(&again).unwrap();
    assert!(
        std::fs::read(&again).unwrap() == v10_saved_again(&format!("v{version}")),
        "a version {version} file saved again differs from the version 10 file of the same inputs"
    );
    std::fs::remove_dir_all(&dir).unwrap();
    old
}

#[test]
fn a_version_10_file_loads_without_stored_rounds_and_saves_as_its_payload_extended() {
    // Format 11 appends the reference demonstration and the recorded executions: the version
    // 10 file saved again is its payload followed by `None` and an empty list. (Its payload no
    // longer leads the golden file's: the golden model's ranges carry the relative rate
    // term's marker and its rate range, `tandem_lfd`'s `RateTerm`.)
    let v10 = std::fs::read(old_golden_path(10)).unwrap();
    const HEADER: usize = tandem_planner::state::HEADER_LEN;
    let again = v10_saved_again("v10");
    assert_eq!(&again[HEADER..again.len() - 2], &v10[HEADER..]);
    assert_eq!(&again[again.len() - 2..], &[0, 0]);
    // Its round cannot be replayed (its executions were not kept); the golden file's can.
    let old = Planner::load(old_golden_path(10)).unwrap();
    assert_eq!(old.rounds_recorded(), 1);
    let demos: Vec<Demonstration> = (0..3)
        .map(|i| Demonstration::from_csv_path(examples(&format!("demo_{i}.csv")), None).unwrap())
        .collect();
    let err = old.refit(&demos, old.params().clone()).unwrap_err();
    assert!(matches!(err, Error::CannotReplay { .. }), "{err}");
    assert!(
        err.to_string().contains("older than state format 11"),
        "{err}"
    );
    let p = Planner::load(golden_path()).unwrap();
    let (refit, report) = p.refit(&demos, p.params().clone()).unwrap();
    assert_eq!((report.rounds, report.reference_changed), (1, false));
    assert_eq!(refit.confidence(), p.confidence());
    assert_eq!(refit.model().mean(), p.model().mean());
}

#[test]
fn a_version_7_file_loads_without_holds_and_saves_as_the_golden_file() {
    // No hold points (format 7 had none). The same inputs without holds: version 8 adds only
    // the empty declaration (two empty lists) and the schedule's empty holds (one list), one
    // byte each, version 9 the fit's `smooth_width` (1, one byte), version 10 its
    // `fill_length` (0.0, eight bytes), and saving the old file writes the golden file's
    // bytes, so a planner without holds is the planner of before, bit for bit.
    let old = old_golden_loads_and_saves_as_the_golden_file(7, 12);
    assert!(old.params().holds.is_empty());
    assert!(old.problem().holds().is_empty());
}

#[test]
fn a_version_8_file_loads_unsmoothed_and_saves_as_the_golden_file() {
    // Fitted before smoothing existed: loaded as unsmoothed, which is also what the golden
    // file's fit (the default `FitParams`) uses. Version 9 adds one byte (`smooth_width = 1`),
    // version 10 eight (`fill_length = 0.0`).
    let old = old_golden_loads_and_saves_as_the_golden_file(8, 9);
    assert_eq!(old.params().fit.warp.smooth_width, 1);
}

#[test]
fn a_version_9_file_loads_unfilled_and_saves_as_the_golden_file() {
    // Fitted before the fill of flat stretches existed: loaded without it, which is also what
    // the golden file's fit (the default `FitParams`) uses. Version 10 adds eight bytes
    // (`fill_length = 0.0`, an f64).
    let old = old_golden_loads_and_saves_as_the_golden_file(9, 8);
    assert_eq!(old.params().fit.warp.fill_length, 0.0);
}

#[test]
fn older_and_newer_files_say_which_version_they_are() {
    let dir = tmp_dir("version");
    let golden = std::fs::read(golden_path()).unwrap();
    for (found, age) in [
        (OLDEST_READABLE_VERSION - 1, "an older"),
        (NEWEST_READABLE_VERSION + 1, "a newer"),
    ] {
        let path = dir.join(format!("v{found}.tandem"));
        let mut bytes = golden.clone();
        bytes[8..12].copy_from_slice(&found.to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        let err = Planner::load(&path).unwrap_err();
        assert!(
            matches!(err, Error::UnsupportedVersion { found: f, expected: NEWEST_READABLE_VERSION, .. } if f == found),
            "{err}"
        );
        let msg = err.to_string();
        for part in [
            path.display().to_string(),
            format!("state format version {found}"),
            format!("reads versions {OLDEST_READABLE_VERSION} to {NEWEST_READABLE_VERSION} only"),
            format!("written by {age} build"),
        ] {
            assert!(msg.contains(&part), "`{part}` missing in: {msg}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

fn assert_names(err: &Error, path: &Path) {
    assert!(
        err.to_string().contains(&path.display().to_string()),
        "error does not name the file: {err}"
    );
}

#[test]
fn damaged_state_files_give_clear_errors() {
    let dir = tmp_dir("damaged");
    let bytes = std::fs::read(golden_path()).unwrap();

    let truncated = dir.join("truncated.tandem");
    std::fs::write(&truncated, &bytes[..bytes.len() - 17]).unwrap();
    let err = Planner::load(&truncated).unwrap_err();
    assert!(matches!(err, Error::Truncated { .. }), "{err}");
    assert_names(&err, &truncated);

    // Not a state file: the golden file's bytes in reverse order.
    let noise = dir.join("noise.tandem");
    let junk: Vec<u8> = bytes.iter().rev().copied().collect();
    std::fs::write(&noise, &junk).unwrap();
    let err = Planner::load(&noise).unwrap_err();
    assert!(matches!(err, Error::NotAStateFile { .. }), "{err}");
    assert_names(&err, &noise);

    let flipped = dir.join("flipped.tandem");
    let mut bad = bytes.clone();
    let mid = bad.len() / 2;
    bad[mid] ^= 0x01;
    std::fs::write(&flipped, &bad).unwrap();
    let err = Planner::load(&flipped).unwrap_err();
    assert!(matches!(err, Error::Corrupt { .. }), "{err}");
    assert_names(&err, &flipped);

    let missing = dir.join("missing.tandem");
    let err = Planner::load(&missing).unwrap_err();
    assert!(matches!(err, Error::Io { .. }), "{err}");
    assert_names(&err, &missing);

    // None of this touched the committed file.
    assert!(std::fs::read(golden_path()).unwrap() == bytes);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_golden_state_file_saves_again_byte_for_byte() {
    let dir = tmp_dir("golden-again");
    let golden = std::fs::read(golden_path()).unwrap();
    // Through the planner.
    let again = dir.join("again.tandem");
    Planner::load(golden_path()).unwrap().save(&again).unwrap();
    assert!(std::fs::read(&again).unwrap() == golden);
    // Through the wire types alone.
    let wire = dir.join("wire.tandem");
    let (payload, extras) = state::load_payload(&golden_path()).unwrap();
    assert!(extras.is_empty());
    state::save_payload(&wire, &payload, &extras).unwrap();
    assert!(std::fs::read(&wire).unwrap() == golden);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn old_payloads_convert_into_the_current_wire_types_with_what_they_were_made_with() {
    use tandem_planner::state::v11;
    let wire = |v: u32| state::load_payload(&old_golden_path(v)).unwrap();
    let (golden, _) = state::load_payload(&golden_path()).unwrap();
    for v in OLDEST_READABLE_VERSION..FORMAT_VERSION {
        let (p, extras) = wire(v);
        assert!(extras.is_empty(), "version {v}");
        // No format before 11 kept the reference demonstration or the executions.
        assert!(p.reference.is_none() && p.records.is_empty(), "version {v}");
        assert_eq!(p.rounds_recorded, 1, "version {v}");
        // Formats before 6 kept no round fingerprints.
        assert_eq!(p.rounds.len(), usize::from(v >= 6), "version {v}");
        assert_eq!(p.outcome.schedule.offsets_s.len(), 1, "version {v}");
        // Formats before 8 had no hold points.
        assert_eq!(
            p.outcome.schedule.holds, golden.outcome.schedule.holds,
            "version {v}"
        );
    }
    // Formats 4 to 6: the paper's confidence model, no evidence of misses.
    let paper = v11::ConfidenceParams::from(&ConfidenceParams::paper());
    for v in 4..=6 {
        let (p, _) = wire(v);
        assert_eq!(p.confidence.params, paper, "version {v}");
        assert_eq!(
            p.observations.miss,
            v11::MissEvidence::default(),
            "version {v}"
        );
    }
    // Formats 4 to 8: unsmoothed and unfilled; 9: unfilled.
    for v in 4..=9 {
        let (p, _) = wire(v);
        let w = &p.params.fit.warp;
        let smooth = if v <= 8 { 1 } else { w.smooth_width };
        assert_eq!(
            (w.smooth_width, w.fill_length),
            (smooth, 0.0),
            "version {v}"
        );
    }
    // Format 10 is format 11 without the reference and the executions: the same parameters.
    // (Not the same outcome: the golden file's model has this build's relative rate term, the
    // version 10 file keeps the absolute one it was fitted with, and so its confidence and
    // schedule; `a_version_6_file_loads_with_the_papers_confidence_model` checks that.)
    let (p10, _) = wire(10);
    assert_eq!(p10.params, golden.params);
}

/// The golden file of a cell of two tasks (format 12, issue 45): the example task on two
/// robots and another model of it (demos 2 and 0, `params.toml`) on one, no round.
#[test]
fn the_golden_cell_file_loads_as_its_two_tasks() {
    let path = repo().join("fixtures/state/mixed.tandem");
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(
        u32::from_le_bytes(bytes[8..12].try_into().unwrap()),
        state::CELL_FORMAT_VERSION,
        "fixtures/state/mixed.tandem is not of the cell format: run `cargo xtask fixtures`"
    );
    let cell = tandem_planner::CellPlanner::load(&path).unwrap();
    let names: Vec<&str> = cell.tasks().iter().map(|t| t.name()).collect();
    assert_eq!(names, ["example", "example-b"]);
    assert_eq!(cell.robot_task(), [0, 0, 1]);
    assert_eq!(cell.rounds_recorded(), 0);
    let text = std::fs::read_to_string(examples("params.toml")).unwrap();
    let params: PlannerParams = toml::from_str(&text).unwrap();
    let demo = |i: usize| Demonstration::from_csv_path(examples(&format!("demo_{i}.csv")), None);
    let demos = [demo(0).unwrap(), demo(1).unwrap(), demo(2).unwrap()];
    let a = Planner::new(&demos, params.clone()).unwrap();
    let b = Planner::with_robots(&[demos[2].clone(), demos[0].clone()], params, 1).unwrap();
    for (task, fresh) in cell.tasks().iter().zip([&a, &b]) {
        assert_eq!(task.planner().params(), fresh.params());
        assert_eq!(task.planner().confidence(), fresh.confidence());
        assert_eq!(task.planner().n_robots(), fresh.n_robots());
    }
    // Task example-b's reference is demo 2 (36 samples), example's demo 0 (40).
    assert_eq!(cell.tasks()[0].planner().model().n_ref(), 40);
    assert_eq!(cell.tasks()[1].planner().model().n_ref(), 36);
    let s = cell.schedule().unwrap();
    assert!(s.t_total_s >= s.lower_bound_s);
    assert!(cell.coordinator().is_ok());
    // One task's planner refuses it, naming the tasks.
    let err = Planner::load(&path).unwrap_err();
    assert!(
        err.to_string()
            .contains("holds a cell of 2 tasks (example, example-b)"),
        "{err}"
    );
}
