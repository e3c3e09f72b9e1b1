//! The committed sanding fixtures, loaded and fitted once per test binary.

use std::path::PathBuf;
use std::sync::OnceLock;

use tandem_lfd::{FitParams, TaskModel};
use tandem_sim::study::StudyInputs;
use tandem_sim::task::Label;

/// `fixtures/sanding/` as study inputs, and the task model fitted on them with the defaults
/// (the reference is the medoid).
pub(crate) fn fixtures() -> &'static (StudyInputs, TaskModel) {
    static CELL: OnceLock<(StudyInputs, TaskModel)> = OnceLock::new();
    CELL.get_or_init(|| {
        let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/sanding");
        let inputs = StudyInputs::from_dir(&dir).expect("the committed fixtures load");
        let model = TaskModel::fit(&inputs.demos, &FitParams::default()).expect("fit");
        (inputs, model)
    })
}

/// The ground-truth labels on the time axis of [`fixtures`]' model: its reference's.
#[allow(dead_code, reason = "not every test binary reads the labels")]
pub(crate) fn labels() -> &'static [Label] {
    static LABELS: OnceLock<Vec<Label>> = OnceLock::new();
    LABELS.get_or_init(|| {
        let (inputs, model) = fixtures();
        inputs
            .reference_labels(model)
            .expect("every fixture has its labels")
    })
}
