//! `tandem fit -o` onto a state file holding recorded rounds: refused without consent,
//! `--keep-rounds` replays them onto the new fit, `--force` discards them and says so
//! (docs/decisions.md, "A refit keeps the recorded rounds").

mod common;

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use common::*;

fn fit_args(demos: &[PathBuf], out: &Path, extra: &[&str]) -> Vec<OsString> {
    let mut v: Vec<OsString> = vec!["fit".into()];
    v.extend(demos.iter().map(|p| p.clone().into_os_string()));
    // The first file is the reference, as in `small_state` (the medoid is the default).
    v.extend(["--reference", "first", "--samples", "200"].map(OsString::from));
    v.extend(extra.iter().map(OsString::from));
    v.push("-o".into());
    v.push(out.as_os_str().to_owned());
    v
}

fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn a_fit_over_recorded_rounds_needs_consent() {
    let dir = scratch("refit-consent");
    let state = small_state(&dir);
    let a = small_execution(&dir, "r1");
    let mut b = small_execution(&dir, "r2");
    // Robot 2's flags differ (a correction), so the round is not two equal executions.
    b[2] = write(&dir, "r2.corr.csv", &{
        let mut s = String::from("supervised,corrected\n");
        for k in 0..SMALL_N_REF {
            s.push_str(if (25..30).contains(&k) {
                "1,1\n"
            } else {
                "1,0\n"
            });
        }
        s
    });
    ok(&tandem(record_args(&state, &a, &b)));
    let before = std::fs::read(&state).unwrap();
    let demos: Vec<PathBuf> = (0..3).map(|i| dir.join(format!("demo_{i}.csv"))).collect();

    // Without consent: exit 2, the count and both ways on named, the file unchanged.
    let out = tandem(fit_args(&demos, &state, &[]));
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let msg = stderr(&out);
    for part in [
        "cell.tandem",
        "holds 1 recorded round(s)",
        "--keep-rounds",
        "--force",
    ] {
        assert!(msg.contains(part), "`{part}` missing: {msg}");
    }
    assert_eq!(std::fs::read(&state).unwrap(), before);
    let out = tandem(fit_args(&demos, &state, &["--keep-rounds", "--force"]));
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert_eq!(std::fs::read(&state).unwrap(), before);

    // --keep-rounds on the same reference: the round is kept as recorded, and the same round
    // given again is still refused.
    let text = ok(&tandem(fit_args(&demos, &state, &["--keep-rounds"])));
    assert!(text.contains("kept 1 recorded round(s)"), "{text}");
    assert!(text.contains("on the same reference"), "{text}");
    let out = tandem(record_args(&state, &a, &b));
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("already recorded as round 1"),
        "{}",
        stderr(&out)
    );
    // With another first demonstration (another reference): the round is replayed by alignment.
    let reordered = [demos[1].clone(), demos[0].clone(), demos[2].clone()];
    let text = ok(&tandem(fit_args(&reordered, &state, &["--keep-rounds"])));
    assert!(text.contains("kept 1 recorded round(s)"), "{text}");
    assert!(text.contains("aligned to the new reference"), "{text}");
    let inspect = ok(&tandem([OsString::from("inspect"), state.clone().into()]));
    assert!(
        inspect.contains("5 demonstrations and executions, 1 rounds recorded"),
        "{inspect}"
    );

    // --force replaces it and says what went.
    let text = ok(&tandem(fit_args(&demos, &state, &["--force"])));
    assert!(text.contains("discarded its 1 recorded round(s)"), "{text}");
    // Now it holds none: a plain fit over it is allowed again.
    ok(&tandem(fit_args(&demos, &state, &[])));
    std::fs::remove_dir_all(&dir).unwrap();
}
