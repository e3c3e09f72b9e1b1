//! A state file whose stored schedule fails this build's check is never run: every command
//! that loads it re-schedules, says so on stderr, and leaves the file as it was unless the
//! command writes the state anyway.

mod common;

use common::*;
use tandem::planner::state;
use tandem::schedule::{Schedule, validate};

fn s(p: &std::path::Path) -> String {
    p.display().to_string()
}

#[test]
fn an_edited_schedule_that_fails_the_check_is_replaced_with_a_notice() {
    let dir = scratch("recheck");
    let state_path = small_state(&dir);
    // Unedited: no notice.
    let out = tandem(["inspect", &s(&state_path), "--json"]);
    ok(&out);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("notice"));
    // Robot 2 starts with robot 1: both low-confidence at once (Eq. 20, constraint 3).
    // Edited through the planner's wire types of the state file (`state::v11`).
    let (mut payload, extras) = state::load_payload(&state_path).unwrap();
    let problem = tandem::Planner::load(&state_path)
        .unwrap()
        .problem()
        .clone();
    payload.outcome.schedule.offsets_s = vec![0.0];
    let edited_schedule = Schedule::from(payload.outcome.schedule.clone());
    assert!(validate(&problem, &edited_schedule).is_err());
    state::save_payload(&state_path, &payload, &extras).unwrap();
    let edited = std::fs::read(&state_path).unwrap();

    // A read-only command runs the replacement and says why; the file is unchanged.
    let out = tandem(["inspect", &s(&state_path), "--json"]);
    let doc: serde_json::Value = serde_json::from_str(&ok(&out)).unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("notice: ") && stderr.contains("fails this build's check"),
        "{stderr}"
    );
    assert!(stderr.contains(&*s(&state_path)), "{stderr}");
    assert!(
        doc["schedule"]["offsets_s"][0].as_f64().unwrap() > 0.0,
        "{doc}"
    );
    assert_eq!(std::fs::read(&state_path).unwrap(), edited);

    // A command that writes the state saves the replacement: no notice afterwards.
    let out = tandem(["schedule", &s(&state_path), "--samples", "100", "--save"]);
    ok(&out);
    let replaced = tandem::Planner::load(&state_path).unwrap();
    assert_eq!(replaced.load_notice(), None);
    assert!(validate(replaced.problem(), replaced.schedule()).is_ok());
    std::fs::remove_dir_all(&dir).unwrap();
}
