//! The committed sanding fixtures, loaded and fitted once per test binary.

use std::path::PathBuf;
use std::sync::OnceLock;

use tandem_lfd::{FitParams, TaskModel};
use tandem_sim::study::StudyInputs;

/// `fixtures/sanding/` as study inputs, and the task model fitted on them with the defaults.
pub(crate) fn fixtures() -> &'static (StudyInputs, TaskModel) {
    static CELL: OnceLock<(StudyInputs, TaskModel)> = OnceLock::new();
    CELL.get_or_init(|| {
        let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/sanding");
        let inputs = StudyInputs::from_dir(&dir).expect("the committed fixtures load");
        // The labels are demo 0's: demo 0 is the reference (the fit's default is the medoid).
        let params = FitParams {
            reference: tandem_lfd::Reference::First,
            ..FitParams::default()
        };
        let model = TaskModel::fit(&inputs.demos, &params).expect("fit");
        (inputs, model)
    })
}
