//! The study's configuration (`fixtures/study.toml`).

use serde::{Deserialize, Serialize};
use tandem_planner::{FleetCell, PlannerParams};

use crate::task::TaskParams;
use crate::workcell::OperatorParams;
use crate::{Error, Result};

/// Study configuration (`fixtures/study.toml`, §III).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StudyConfig {
    /// Independent trials (paper: 5). Default: 5.
    pub trials: usize,
    /// Executions per trial, run in rounds of [`StudyConfig::robots`] (one execution per
    /// robot), so a positive multiple of `robots` (paper: 300, in pairs). Default: 300.
    pub executions: usize,
    /// Robots `N` run by the one operator, `1 ≤ N ≤` [`tandem_realtime::MAX_ROBOTS`]
    /// (paper: 2). Default: 2.
    pub robots: usize,
    /// Sampler iterations per re-schedule (paper: 5000). Default: 5000.
    pub samples: usize,
    /// Master seed; trial `k` is seeded from `(seed, k)` only. Default: 2023.
    pub seed: u64,
    /// Probability that the simulated operator misses a needed correction (§III: 1 %).
    /// Default: 0.01.
    pub miss_rate: f64,
    /// Probability that the operator corrects a sample that needs none (§III: 1 %).
    /// Default: 0.01.
    pub false_correction_rate: f64,
    /// Mean duration (s) of one unneeded correction episode (see
    /// [`OperatorParams::false_correction_s`]). Default: 0.5 s.
    pub false_correction_s: f64,
    /// Iterations whose schedules Fig. 5 draws as examples (trial 0). Default: 0, 25, 50, 100, 150.
    pub example_iterations: Vec<usize>,
    /// Model, confidence and sampler parameters. The sampler's `samples` and `seed` are
    /// replaced by [`StudyConfig::samples`] and the trial's seed. Default: `PlannerParams::default()`
    /// (the fit's reference is the medoid; the truth is its own labels,
    /// [`super::StudyInputs::reference_labels`]).
    pub planner: PlannerParams,
    /// Task parameters for drawing each execution's workpiece (only `n_sections` matters);
    /// must match the demonstrations'. Default: `TaskParams::default()` (the fixtures').
    pub task: TaskParams,
    /// How the robots run: in rounds (the paper; `run_study`) or as a continuous cell
    /// (`run_cell_study`). Default: rounds (not written when it is).
    #[serde(skip_serializing_if = "Cell::is_rounds")]
    pub cell: Cell,
    /// The operator as a person (issue 41), `[operator]`: the switch time and load cap the
    /// schedules are planned with, and the simulated operator's own switch time. Default:
    /// none of them (not written when so, so a study without them records as before).
    #[serde(skip_serializing_if = "StudyOperator::is_default")]
    pub operator: StudyOperator,
}

/// The `[operator]` table of the study's configuration (issue 41): what the schedules plan
/// for and what the simulated operator needs, set apart so that a study can run a plan that
/// ignores the operator's switch time (`switch_s = 0`) with an operator who has one
/// (`switch_true_s = 2`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StudyOperator {
    /// The switch time `δ` (real s, finite and ≥ 0) the schedules are planned with: the
    /// planner's [`tandem_schedule::SamplerParams::switch_s`] (set here, not in
    /// `[planner.sampler]`). Default: 0.
    pub switch_s: f64,
    /// The load cap `u_max` in `(0, 1]` the schedules are planned with: the planner's
    /// [`tandem_schedule::SamplerParams::max_busy_share`] (set here, not in
    /// `[planner.sampler]`). Default: 1 (no cap).
    pub max_busy_share: f64,
    /// The simulated operator's own switch time `δ_true` (real s, finite and ≥ 0):
    /// [`OperatorParams::switch_true_s`]; needed corrections in its first `δ_true` after
    /// another robot's stretch ended are missed and counted. Default: 0 (the operator of §III).
    pub switch_true_s: f64,
    /// The number of operators `M` of the cell (issue 44), `1 ≤ M ≤`
    /// [`tandem_realtime::MAX_ROBOTS`]: the planner's
    /// [`tandem_schedule::SamplerParams::operators`] (set here, not in `[planner.sampler]`),
    /// and `M` simulated operators, one per operator index of `Tick::operator`, each with the
    /// error rates and switch time above. Rounds with `M > 1` run the planner's sectored round
    /// (`Planner::sectored_rounds`), the continuous cell `M` tokens. Default: 1 (not written
    /// when so).
    #[serde(skip_serializing_if = "is_one")]
    pub operators: usize,
    /// Which continuous cell `M > 1` operators run (issue 44): `auto` (the default, not
    /// written: the pooled cell unless the even sectors measure strictly faster,
    /// `Planner::fleet_coordinator`), `pooled` or `sectored` (forced, to compare the two in
    /// one study). Rounds and one operator ignore it.
    #[serde(skip_serializing_if = "FleetCell::is_auto")]
    pub fleet_cell: FleetCell,
    /// Whether the continuous cell of different tasks (issue 45) nests groups: the next
    /// robot's whole group run inside a high-confidence gap of the token robot's group when
    /// the gap's least duration covers the group's largest span and the switch time
    /// (`ContinuousCoordinator::with_nesting`). `false`: the token rule alone. Single-task
    /// cells ignore it. Default: `true` (not written when so).
    #[serde(skip_serializing_if = "is_true")]
    pub nested_groups: bool,
}

/// Whether `b` is true (serde's `skip_serializing_if` of [`StudyOperator::nested_groups`]).
#[expect(
    clippy::trivially_copy_pass_by_ref,
    reason = "serde's skip_serializing_if passes a reference"
)]
fn is_true(b: &bool) -> bool {
    *b
}

/// Whether `m` is 1 (serde's `skip_serializing_if` of [`StudyOperator::operators`]).
#[expect(
    clippy::trivially_copy_pass_by_ref,
    reason = "serde's skip_serializing_if passes a reference"
)]
fn is_one(m: &usize) -> bool {
    *m == 1
}

impl Default for StudyOperator {
    fn default() -> Self {
        StudyOperator {
            switch_s: 0.0,
            max_busy_share: 1.0,
            switch_true_s: 0.0,
            operators: 1,
            fleet_cell: FleetCell::Auto,
            nested_groups: true,
        }
    }
}

impl StudyOperator {
    /// Whether every field is its default (then the table is not written).
    pub fn is_default(&self) -> bool {
        *self == StudyOperator::default()
    }
}

/// How the robots of a study run: the planner's one cell type (`rounds` or `continuous`),
/// re-exported where the study's configuration names it.
pub use tandem_planner::Cell;

impl Default for StudyConfig {
    fn default() -> Self {
        Self {
            trials: 5,
            executions: 300,
            robots: 2,
            samples: 5000,
            seed: 2023,
            miss_rate: 0.01,
            false_correction_rate: 0.01,
            false_correction_s: 0.5,
            example_iterations: vec![0, 25, 50, 100, 150],
            planner: PlannerParams::default(),
            task: TaskParams::default(),
            cell: Cell::Rounds,
            operator: StudyOperator::default(),
        }
    }
}

impl StudyConfig {
    /// Number of rounds per trial (`executions / robots`; pairs for two robots).
    pub fn n_rounds(&self) -> usize {
        self.executions / self.robots.max(1)
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`Error::BadParam`] naming the first invalid field.
    pub fn validate(&self) -> Result<()> {
        let bad = |name: &'static str, why: &'static str| Err(Error::BadParam { name, why });
        if self.trials == 0 {
            return bad("trials", "must be at least 1");
        }
        if !(1..=tandem_realtime::MAX_ROBOTS).contains(&self.robots) {
            return bad(
                "robots",
                "must be between 1 and 16 (tandem_realtime::MAX_ROBOTS)",
            );
        }
        if self.executions == 0 || self.executions % self.robots != 0 {
            return bad(
                "executions",
                if self.robots == 2 {
                    "must be a positive even number (executions run in pairs)"
                } else {
                    "must be a positive multiple of `robots` (executions run in rounds of one \
                     execution per robot)"
                },
            );
        }
        if self.samples == 0 {
            return bad("samples", "must be at least 1");
        }
        for (name, p) in [
            ("miss_rate", self.miss_rate),
            ("false_correction_rate", self.false_correction_rate),
        ] {
            if !(0.0..=1.0).contains(&p) {
                return bad(name, "must be a probability in [0, 1]");
            }
        }
        if self.false_correction_rate >= 1.0 {
            return bad("false_correction_rate", "must be below 1");
        }
        if !(self.false_correction_s.is_finite() && self.false_correction_s >= 0.0) {
            return bad("false_correction_s", "must be finite and ≥ 0");
        }
        let op = &self.operator;
        if !(op.switch_s.is_finite() && op.switch_s >= 0.0) {
            return bad(
                "operator.switch_s",
                "must be finite and ≥ 0 (the planned switch time in seconds; 0: none)",
            );
        }
        if !(op.max_busy_share > 0.0 && op.max_busy_share <= 1.0) {
            return bad(
                "operator.max_busy_share",
                "must be in (0, 1] (the operator's load cap; 1: no cap)",
            );
        }
        if !(op.switch_true_s.is_finite() && op.switch_true_s >= 0.0) {
            return bad(
                "operator.switch_true_s",
                "must be finite and ≥ 0 (the simulated operator's switch time in seconds; 0: none)",
            );
        }
        if !(1..=tandem_realtime::MAX_ROBOTS).contains(&op.operators) {
            return bad(
                "operator.operators",
                "must be between 1 and 16 (tandem_realtime::MAX_ROBOTS): the cell's operators",
            );
        }
        let sampler = &self.planner.sampler;
        if sampler.switch_s != 0.0 || sampler.max_busy_share != 1.0 || sampler.operators != 1 {
            return bad(
                "planner.sampler",
                "sets switch_s, max_busy_share or operators: a study sets them in its \
                 [operator] table (one place for the operator), leave them out of \
                 [planner.sampler]",
            );
        }
        self.planner.validate()?;
        self.task.validate()?;
        Ok(())
    }

    /// The planner's parameters of every trial: [`StudyConfig::planner`] with the planned
    /// switch time and load cap of [`StudyConfig::operator`] (the sampler's `samples` and
    /// `seed` are set per trial).
    pub fn planner_params(&self) -> PlannerParams {
        let mut params = self.planner.clone();
        params.sampler.switch_s = self.operator.switch_s;
        params.sampler.max_busy_share = self.operator.max_busy_share;
        params.sampler.operators = self.operator.operators;
        params
    }

    /// The operator of the workcell.
    pub fn operator(&self) -> OperatorParams {
        OperatorParams {
            miss_rate: self.miss_rate,
            false_correction_rate: self.false_correction_rate,
            false_correction_s: self.false_correction_s,
            switch_true_s: self.operator.switch_true_s,
            ..OperatorParams::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_papers_study() {
        let c = StudyConfig::default();
        assert_eq!((c.trials, c.executions, c.samples), (5, 300, 5000));
        assert_eq!((c.robots, c.n_rounds()), (2, 150));
        assert_eq!((c.miss_rate, c.false_correction_rate), (0.01, 0.01));
        c.validate().unwrap();
    }

    #[test]
    fn bad_configs_name_the_field() {
        let cases: [(StudyConfig, &str); 7] = [
            (
                StudyConfig {
                    robots: 0,
                    ..Default::default()
                },
                "robots",
            ),
            (
                StudyConfig {
                    robots: 17,
                    ..Default::default()
                },
                "robots",
            ),
            (
                StudyConfig {
                    robots: 7,
                    ..Default::default()
                },
                "executions",
            ),
            (
                StudyConfig {
                    trials: 0,
                    ..Default::default()
                },
                "trials",
            ),
            (
                StudyConfig {
                    executions: 7,
                    ..Default::default()
                },
                "executions",
            ),
            (
                StudyConfig {
                    samples: 0,
                    ..Default::default()
                },
                "samples",
            ),
            (
                StudyConfig {
                    miss_rate: f64::NAN,
                    ..Default::default()
                },
                "miss_rate",
            ),
        ];
        // Rounds of N robots: 300 executions are 100 rounds of 3.
        let three = StudyConfig {
            robots: 3,
            ..Default::default()
        };
        three.validate().unwrap();
        assert_eq!(three.n_rounds(), 100);
        for (c, name) in cases {
            let err = c.validate().unwrap_err();
            assert!(
                matches!(err, Error::BadParam { name: n, .. } if n == name),
                "{err}"
            );
        }
    }

    #[test]
    fn config_reads_from_toml_with_defaults_and_rejects_unknown_keys() {
        let c: StudyConfig = toml::from_str("trials = 2\nseed = 7\n").unwrap();
        assert_eq!((c.trials, c.seed, c.executions), (2, 7, 300));
        assert!(toml::from_str::<StudyConfig>("trails = 2\n").is_err());
        let nested: StudyConfig = toml::from_str(
            "[planner.sampler]\np_fastest = 0.5\n[planner.confidence]\ngamma_c = 0.9\n",
        )
        .unwrap();
        assert_eq!(nested.planner.sampler.p_fastest, 0.5);
        assert_eq!(nested.planner.confidence.gamma_c, 0.9);
        assert!(toml::from_str::<StudyConfig>("[planner.sampler]\nbogus = 1\n").is_err());
        // The committed configuration is the paper's study with the sanding task's hold
        // points (the tool off between passes) declared; nothing else differs from the default.
        let committed = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../fixtures/study.toml"
        ))
        .unwrap();
        let mut c: StudyConfig = toml::from_str(&committed).unwrap();
        let rules: Vec<String> = c
            .planner
            .holds
            .rules
            .iter()
            .map(|r| r.to_string())
            .collect();
        assert_eq!(rules, ["tool<0.5"]);
        assert!(c.planner.holds.at_s.is_empty());
        c.planner.holds = Default::default();
        assert_eq!(c, StudyConfig::default());
    }

    #[test]
    fn the_operator_table_sets_the_planner_and_the_simulated_operator() {
        let c: StudyConfig = toml::from_str(
            "[operator]\nswitch_s = 2.0\nmax_busy_share = 0.7\nswitch_true_s = 1.5\n",
        )
        .unwrap();
        c.validate().unwrap();
        let p = c.planner_params();
        assert_eq!((p.sampler.switch_s, p.sampler.max_busy_share), (2.0, 0.7));
        assert_eq!(c.operator().switch_true_s, 1.5);
        // Written back only when set.
        let text = toml::to_string(&c).unwrap();
        assert!(text.contains("[operator]"), "{text}");
        assert!(
            !toml::to_string(&StudyConfig::default())
                .unwrap()
                .contains("[operator]")
        );
        assert!(toml::from_str::<StudyConfig>("[operator]\nswitch = 1\n").is_err());
        // M operators (issue 44): the planner's count; written only when not 1.
        let m: StudyConfig =
            toml::from_str("cell = \"continuous\"\n[operator]\noperators = 2\n").unwrap();
        m.validate().unwrap();
        // Rounds with two operators too (issue 44: the sectored round).
        let r: StudyConfig = toml::from_str("[operator]\noperators = 2\n").unwrap();
        r.validate().unwrap();
        assert_eq!(m.planner_params().sampler.operators, 2);
        assert!(toml::to_string(&m).unwrap().contains("operators = 2"));
        assert!(!text.contains("operators"), "{text}");
        for (text, name) in [
            ("[operator]\nswitch_s = -1.0\n", "operator.switch_s"),
            (
                "[operator]\nmax_busy_share = 0.0\n",
                "operator.max_busy_share",
            ),
            (
                "[operator]\nswitch_true_s = inf\n",
                "operator.switch_true_s",
            ),
            ("[planner.sampler]\nswitch_s = 2.0\n", "planner.sampler"),
            ("[operator]\noperators = 0\n", "operator.operators"),
            (
                "cell = \"continuous\"\n[operator]\noperators = 17\n",
                "operator.operators",
            ),
            ("[planner.sampler]\noperators = 2\n", "planner.sampler"),
        ] {
            let c: StudyConfig = toml::from_str(text).unwrap();
            let err = c.validate().unwrap_err();
            assert!(
                matches!(err, Error::BadParam { name: n, .. } if n == name),
                "{text}: {err}"
            );
        }
    }
}
