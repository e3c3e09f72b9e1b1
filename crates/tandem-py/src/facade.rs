//! Every item this crate uses from the `tandem` facade, in one place.

pub(crate) use tandem::confidence::{
    BetaParams, Observations, posterior, prior, prior_low_threshold, prob_need_below_mu_c,
};
pub(crate) use tandem::lfd::{
    DEFAULT_DT_S, DT_TOLERANCE, Demonstration, Execution, HoldRule, HoldSpec, PeriodSource,
    RateTerm, Regridded, TaskModel, drifting_majority, length_warnings,
};
pub(crate) use tandem::planner::state::{DEFAULT_LOCK_TIMEOUT, StateLock};
pub(crate) use tandem::planner::{
    AnyController, Cell, CellPlanner, CellSchedule, Error as TandemError, ExecutionRecord, Plan,
    Planner, PlannerParams, RecordReport, TaskSpec, reschedule_seed,
};
pub(crate) use tandem::realtime::continuous::{ContinuousCoordinator, Group, Token};
pub(crate) use tandem::realtime::{
    Controller, Coordinator, Fault, MAX_ROBOTS, Operator, RobotCount, Tick, Timeline,
};
pub(crate) use tandem::schedule::cyclic::{GapPlan, Stretch};
pub(crate) use tandem::schedule::{
    CheckedCyclicPlan, CheckedSchedule, CyclicParams, CyclicPlan, GlobalTimeline, LcInterval,
    Outcome, Problem, SamplerParams, Schedule, Source, Violation, cyclic_plan,
    cyclic_plan_for_order, sample_schedule_n,
};
pub(crate) use tandem::sim::needs::{NeedProfile, NeedRegion};
pub(crate) use tandem::sim::study::{
    PhaseTimes, StudyConfig, StudyInputs, read_labels, reference_labels, run_cell_trial, run_trial,
    run_trials,
};
pub(crate) use tandem::sim::task::{
    FIXTURE_SEED, Label, N_FIXTURE_DEMOS, TaskDemo, TaskParams, Workpiece, demonstrations,
};
pub(crate) use tandem::sim::workcell::{
    OperatorParams, RoundRun, correction_input, needs_correction, run_round_with,
};
pub(crate) use tandem::warp::{SignalRef, Warp, WarpParams, align};
/// The operator's console (not in the facade: a server, as the command line uses it).
pub(crate) use tandem_console::{
    Console, ConsoleConfig, ConsoleHandle, DEFAULT_HORIZON_S, DEFAULT_LEAD_S, Driver,
    Error as ConsoleError, Geometry,
};

pub(crate) use tandem::bag::{
    BagOptions, Recording, extend_schema as extend_bag_schema, is_bag, read_bag,
};

/// The crates' own error types, for classifying them into Python exceptions.
pub(crate) mod errors {
    pub(crate) use tandem::bag::Error as Bag;
    pub(crate) use tandem::confidence::Error as Confidence;
    pub(crate) use tandem::lfd::Error as Lfd;
    pub(crate) use tandem::realtime::Error as Realtime;
    pub(crate) use tandem::schedule::Error as Schedule;
    pub(crate) use tandem::sim::Error as Sim;
    pub(crate) use tandem::warp::Error as Warp;
}
