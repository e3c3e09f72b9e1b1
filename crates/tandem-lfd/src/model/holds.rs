//! Hold points declared by the user: reference times and channel rules ([`HoldSpec`]),
//! resolved on a [`TaskModel`] to reference-sample indices.
//!
//! A hold point is a reference sample at which a robot may dwell for any time, its execution
//! clock stopped (the paper's §II-C names stopping robots as the way beyond the demonstrated
//! speeds). The task start is always one and is never listed: a declaration that resolves to
//! reference sample 0 adds nothing. What a hold means for the schedule and the run time is
//! `tandem-schedule`'s and `tandem-realtime`'s; this module only turns what the user wrote
//! into reference samples.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::TaskModel;
use super::layout::Item;
use crate::{Error, Result};

/// The comparison of a [`HoldRule`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[non_exhaustive]
pub enum Comparison {
    /// `<`
    Less,
    /// `<=`
    LessEq,
    /// `>`
    Greater,
    /// `>=`
    GreaterEq,
}

impl Comparison {
    /// Whether `lhs <op> rhs` holds (false for a NaN operand).
    pub fn holds(self, lhs: f64, rhs: f64) -> bool {
        match self {
            Comparison::Less => lhs < rhs,
            Comparison::LessEq => lhs <= rhs,
            Comparison::Greater => lhs > rhs,
            Comparison::GreaterEq => lhs >= rhs,
        }
    }

    /// The operator as written: `<`, `<=`, `>` or `>=`.
    pub fn symbol(self) -> &'static str {
        match self {
            Comparison::Less => "<",
            Comparison::LessEq => "<=",
            Comparison::Greater => ">",
            Comparison::GreaterEq => ">=",
        }
    }
}

/// A channel rule for hold points: every reference sample where the model's mean trajectory
/// `μ̂(n)` of `channel` satisfies `μ̂(n) <comparison> value` is a hold point.
///
/// Written and parsed as `<channel><op><value>`, e.g. `tool<0.5` or `gripper >= 0.8`
/// (spaces around the operator allowed; `op` one of `<`, `<=`, `>`, `>=`). Serialized as that
/// string (in TOML: `rules = ["tool<0.5"]`).
///
/// ```
/// use tandem_lfd::{Comparison, HoldRule};
/// let rule: HoldRule = "gripper >= 0.8".parse()?;
/// assert_eq!(rule.channel, "gripper");
/// assert_eq!(rule.comparison, Comparison::GreaterEq);
/// assert_eq!(rule.value, 0.8);
/// assert_eq!(rule.to_string(), "gripper>=0.8");
/// assert!("gripper = 0.8".parse::<HoldRule>().is_err());
/// # Ok::<(), tandem_lfd::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct HoldRule {
    /// The channel's name (a scalar channel of the model, not a quaternion component).
    pub channel: String,
    /// How the channel's mean is compared with `value`.
    pub comparison: Comparison,
    /// The threshold, in the channel's unit; finite.
    pub value: f64,
}

impl fmt::Display for HoldRule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}{}{}",
            self.channel,
            self.comparison.symbol(),
            self.value
        )
    }
}

impl FromStr for HoldRule {
    type Err = Error;

    fn from_str(text: &str) -> Result<Self> {
        let bad = |why: String| Error::BadHoldRule {
            rule: text.to_owned(),
            why,
        };
        let Some(at) = text.find(['<', '>']) else {
            let why = if text.contains('=') {
                "`=` is not a comparison here: write `<`, `<=`, `>` or `>=` (e.g. `tool<0.5`)"
            } else {
                "no comparison: write `<channel><op><value>` with `<`, `<=`, `>` or `>=` \
                 (e.g. `tool<0.5`)"
            };
            return Err(bad(why.into()));
        };
        let channel = text[..at].trim();
        let rest = &text[at..];
        let (comparison, value_text) = if let Some(v) = rest.strip_prefix("<=") {
            (Comparison::LessEq, v)
        } else if let Some(v) = rest.strip_prefix(">=") {
            (Comparison::GreaterEq, v)
        } else if let Some(v) = rest.strip_prefix('<') {
            (Comparison::Less, v)
        } else {
            (Comparison::Greater, &rest[1..])
        };
        if channel.is_empty() {
            return Err(bad(
                "no channel name before the comparison (e.g. `tool<0.5`)".into(),
            ));
        }
        if channel.contains('=') {
            return Err(bad(format!(
                "`=` before the comparison: write `{}<=…` or `>=`, not `=<` or `=>`",
                channel.trim_end_matches('=').trim()
            )));
        }
        let value_text = value_text.trim();
        if value_text.is_empty() {
            return Err(bad("no value after the comparison (e.g. `tool<0.5`)".into()));
        }
        if value_text.contains(['<', '>', '=']) {
            return Err(bad(format!(
                "more than one comparison (`{}`); a rule compares one channel with one value",
                rest.trim()
            )));
        }
        let value: f64 = value_text
            .parse()
            .map_err(|_| bad(format!("`{value_text}` is not a number")))?;
        if !value.is_finite() {
            return Err(bad(format!(
                "`{value_text}` is not a finite number (a threshold must be finite)"
            )));
        }
        Ok(HoldRule {
            channel: channel.to_owned(),
            comparison,
            value,
        })
    }
}

impl TryFrom<String> for HoldRule {
    type Error = Error;
    fn try_from(text: String) -> Result<Self> {
        text.parse()
    }
}

impl From<HoldRule> for String {
    fn from(rule: HoldRule) -> Self {
        rule.to_string()
    }
}

/// The hold points a user declares for a task: reference times and channel rules. The
/// default (both empty) declares none, and a planner without holds behaves as before hold
/// points existed.
///
/// [`HoldSpec::resolve`] turns it into reference-sample indices on a model. Serialized with
/// both fields optional (`#[serde(default)]`), e.g. in TOML:
///
/// ```toml
/// [holds]
/// at_s = [2.5, 7.0]
/// rules = ["tool<0.5"]
/// ```
///
/// ```
/// use tandem_lfd::{Demonstration, FitParams, HoldSpec, TaskModel};
/// // A gripper that closes (1) in the middle of the task.
/// let names = vec!["gripper".to_string()];
/// let a = Demonstration::new(names.clone(), vec![0.0, 0.0, 1.0, 1.0, 0.0], 0.5)?;
/// let b = Demonstration::new(names, vec![0.0, 0.2, 1.0, 0.8, 0.0], 0.5)?;
/// let id: Vec<f64> = (0..5).map(f64::from).collect();
/// let model = TaskModel::fit_aligned(&[a, b], &[id.clone(), id], &FitParams::default())?;
/// let spec = HoldSpec { at_s: vec![2.0], rules: vec!["gripper>0.5".parse()?] };
/// // 2.0 s is sample 4 (Δt = 0.5 s); the mean gripper is 1.0 and 0.9 at samples 2 and 3.
/// assert_eq!(spec.resolve(&model)?, [2, 3, 4]);
/// assert!(HoldSpec { at_s: vec![2.5], rules: vec![] }.resolve(&model).is_err());
/// # Ok::<(), tandem_lfd::Error>(())
/// ```
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HoldSpec {
    /// Hold points at these reference times (s, reference time `n·Δt_s`), each at the
    /// nearest reference sample; each in `[0, (T_ref − 1)·Δt_s]`. Default: none.
    pub at_s: Vec<f64>,
    /// Hold points at every reference sample where a rule holds on the mean trajectory.
    /// Default: none.
    pub rules: Vec<HoldRule>,
}

/// Reference times may exceed the task's last sample by this share of a period (rounding of a
/// time printed in seconds).
const END_SLACK: f64 = 1e-6;

impl HoldSpec {
    /// Whether it declares no hold point.
    pub fn is_empty(&self) -> bool {
        self.at_s.is_empty() && self.rules.is_empty()
    }

    /// Checks what can be checked without a model: every reference time finite and
    /// non-negative, every rule's value finite.
    ///
    /// # Errors
    /// [`Error::BadHoldTime`] or [`Error::BadHoldRule`] naming the first bad entry.
    pub fn validate(&self) -> Result<()> {
        for &t in &self.at_s {
            if !t.is_finite() || t < 0.0 {
                return Err(Error::BadHoldTime {
                    at_s: t,
                    why: "a hold's reference time must be a finite number of seconds ≥ 0".into(),
                });
            }
        }
        for rule in &self.rules {
            if !rule.value.is_finite() || rule.channel.is_empty() {
                return Err(Error::BadHoldRule {
                    rule: rule.to_string(),
                    why: "needs a channel name and a finite value".into(),
                });
            }
        }
        Ok(())
    }

    /// The reference sample nearest to the reference time `at_s` on `model`.
    ///
    /// # Errors
    /// [`Error::BadHoldTime`] for a non-finite time or one outside the task's reference time
    /// `[0, (T_ref − 1)·Δt_s]`.
    pub fn sample_at(model: &TaskModel, at_s: f64) -> Result<usize> {
        let dt = model.dt_s();
        let last = model.n_ref() - 1;
        let end_s = last as f64 * dt;
        if !at_s.is_finite() || at_s < 0.0 || at_s > end_s + END_SLACK * dt {
            return Err(Error::BadHoldTime {
                at_s,
                why: format!(
                    "outside the task: its reference time runs from 0 to {end_s} s \
                     ({} samples {dt} s apart)",
                    model.n_ref()
                ),
            });
        }
        Ok(((at_s / dt).round() as usize).min(last))
    }

    /// The reference samples where `rule` holds on `model`'s mean trajectory, increasing
    /// (possibly none, and possibly sample 0).
    ///
    /// # Errors
    /// [`Error::BadHoldRule`] for a channel the model does not have (naming the ones it has)
    /// or a quaternion component (whose mean alone says nothing: the orientation is the
    /// block).
    pub fn rule_samples(model: &TaskModel, rule: &HoldRule) -> Result<Vec<usize>> {
        let names = model.channel_names();
        let bad = |why: String| Error::BadHoldRule {
            rule: rule.to_string(),
            why,
        };
        let Some(col) = names.iter().position(|n| *n == rule.channel) else {
            return Err(bad(format!(
                "the model has no channel `{}`; its scalar channels are {:?}",
                rule.channel,
                model.scalar_channels()
            )));
        };
        if let Some(block) = model.quaternion_block_of(col) {
            return Err(bad(format!(
                "`{}` is a component of the quaternion block `{block}`: a component of a unit \
                 quaternion alone does not describe the orientation; use a scalar channel \
                 (one of {:?}) or --hold-at",
                rule.channel,
                model.scalar_channels()
            )));
        }
        let m = names.len();
        Ok(model
            .mean()
            .chunks_exact(m)
            .enumerate()
            .filter(|(_, mean_n)| rule.comparison.holds(mean_n[col], rule.value))
            .map(|(n, _)| n)
            .collect())
    }

    /// The hold points on `model`: reference-sample indices, strictly increasing, without
    /// sample 0 (the task start, always a hold): each reference time at its nearest sample
    /// ([`HoldSpec::sample_at`]), each rule at every sample where it holds
    /// ([`HoldSpec::rule_samples`]), merged. A rule that holds nowhere adds nothing (the
    /// planner's declaration check refuses it when the task is learnt).
    ///
    /// # Errors
    /// As [`HoldSpec::sample_at`] and [`HoldSpec::rule_samples`].
    pub fn resolve(&self, model: &TaskModel) -> Result<Vec<usize>> {
        let mut holds = Vec::new();
        for &t in &self.at_s {
            holds.push(Self::sample_at(model, t)?);
        }
        for rule in &self.rules {
            holds.extend(Self::rule_samples(model, rule)?);
        }
        holds.sort_unstable();
        holds.dedup();
        holds.retain(|&n| n > 0);
        Ok(holds)
    }
}

impl TaskModel {
    /// Names of the scalar channels (those a [`HoldRule`] may name), in column order.
    pub fn scalar_channels(&self) -> Vec<&str> {
        self.data
            .layout
            .items
            .iter()
            .filter_map(|item| match item {
                Item::Scalar(j) => Some(self.data.channel_names[*j].as_str()),
                Item::Quat(..) => None,
            })
            .collect()
    }

    /// The name of the quaternion block channel column `col` belongs to, if any.
    fn quaternion_block_of(&self, col: usize) -> Option<String> {
        let mut coord = 0;
        for item in &self.data.layout.items {
            match item {
                Item::Scalar(_) => coord += 1,
                Item::Quat(cols, _) => {
                    if cols.contains(&col) {
                        let name = &self.data.layout.names[coord];
                        return Some(name.strip_suffix(".rx").unwrap_or(name).to_owned());
                    }
                    coord += 3;
                }
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Demonstration, FitParams};

    /// Channels `gripper` and a quaternion block `q` (identity), 5 samples 0.5 s apart, the
    /// gripper's mean `[0, 0.1, 1, 0.9, 0]`.
    fn gripper_model() -> TaskModel {
        let names: Vec<String> = ["gripper", "qx", "qy", "qz", "qw"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let rows =
            |g: [f64; 5]| -> Vec<f64> { g.iter().flat_map(|&v| [v, 0.0, 0.0, 0.0, 1.0]).collect() };
        let a = Demonstration::new(names.clone(), rows([0.0, 0.0, 1.0, 1.0, 0.0]), 0.5).unwrap();
        let b = Demonstration::new(names, rows([0.0, 0.2, 1.0, 0.8, 0.0]), 0.5).unwrap();
        let id: Vec<f64> = (0..5).map(f64::from).collect();
        TaskModel::fit_aligned(&[a, b], &[id.clone(), id], &FitParams::default()).unwrap()
    }

    fn rule(text: &str) -> HoldRule {
        text.parse().unwrap()
    }

    #[test]
    fn rules_parse_with_every_comparison_and_print_back() {
        for (text, cmp, printed) in [
            ("tool<0.5", Comparison::Less, "tool<0.5"),
            (" tool <= 0.5 ", Comparison::LessEq, "tool<=0.5"),
            ("tool>-1e-3", Comparison::Greater, "tool>-0.001"),
            ("tool >= 2", Comparison::GreaterEq, "tool>=2"),
        ] {
            let r = rule(text);
            assert_eq!((r.channel.as_str(), r.comparison), ("tool", cmp), "{text}");
            assert_eq!(r.to_string(), printed);
            assert_eq!(rule(printed), r);
        }
    }

    #[test]
    fn malformed_rules_are_refused_saying_why() {
        for (text, says) in [
            ("tool", "no comparison"),
            ("tool=0.5", "`=` is not a comparison"),
            ("tool==0.5", "`=` is not a comparison"),
            ("<0.5", "no channel name"),
            ("tool<", "no value"),
            ("tool<abc", "`abc` is not a number"),
            ("tool<NaN", "not a finite number"),
            ("tool<inf", "not a finite number"),
            ("tool=<0.5", "`=` before the comparison"),
            ("0<tool<1", "more than one comparison"),
            ("tool<>1", "more than one comparison"),
        ] {
            let e = text.parse::<HoldRule>().unwrap_err().to_string();
            assert!(e.contains(says) && e.contains(text), "{text}: {e}");
        }
    }

    #[test]
    fn rules_and_times_resolve_to_increasing_samples_without_the_start() {
        let model = gripper_model();
        let spec = |at_s: Vec<f64>, rules: &[&str]| HoldSpec {
            at_s,
            rules: rules.iter().map(|r| rule(r)).collect(),
        };
        assert_eq!(
            spec(vec![], &["gripper>0.5"]).resolve(&model).unwrap(),
            [2, 3]
        );
        assert_eq!(
            spec(vec![], &["gripper>=0.9"]).resolve(&model).unwrap(),
            [2, 3]
        );
        assert_eq!(spec(vec![], &["gripper>0.9"]).resolve(&model).unwrap(), [2]);
        // `gripper<0.5` holds at 0, 1 and 4; the start is never listed.
        assert_eq!(
            spec(vec![], &["gripper<0.5"]).resolve(&model).unwrap(),
            [1, 4]
        );
        // Times round to the nearest sample (0.74 s → 1, 0.76 s → 2), merged with the rules.
        assert_eq!(
            spec(vec![0.76, 0.74, 2.0], &["gripper>0.5"])
                .resolve(&model)
                .unwrap(),
            [1, 2, 3, 4]
        );
        assert_eq!(
            spec(vec![0.0, 0.2], &[]).resolve(&model).unwrap(),
            [] as [usize; 0]
        );
        assert_eq!(
            spec(vec![], &["gripper>5"]).resolve(&model).unwrap(),
            [] as [usize; 0]
        );
        assert!(HoldSpec::default().resolve(&model).unwrap().is_empty());
    }

    #[test]
    fn times_outside_the_task_and_nan_are_refused() {
        let model = gripper_model();
        for t in [-0.1, 2.01, 100.0, f64::NAN, f64::INFINITY] {
            let spec = HoldSpec {
                at_s: vec![t],
                rules: vec![],
            };
            let e = spec.resolve(&model).unwrap_err().to_string();
            assert!(e.contains("hold"), "{t}: {e}");
            if t.is_finite() {
                assert!(
                    e.contains("outside the task") && e.contains("0 to 2 s"),
                    "{e}"
                );
            }
        }
        assert!(
            HoldSpec {
                at_s: vec![f64::NAN],
                rules: vec![]
            }
            .validate()
            .is_err()
        );
    }

    #[test]
    fn unknown_channels_and_quaternion_components_are_refused_naming_the_known_ones() {
        let model = gripper_model();
        let e = HoldSpec::rule_samples(&model, &rule("tool<0.5"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("no channel `tool`") && e.contains("[\"gripper\"]"),
            "{e}"
        );
        let e = HoldSpec::rule_samples(&model, &rule("qw>0.5"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("quaternion block `q`"), "{e}");
        assert_eq!(model.scalar_channels(), ["gripper"]);
    }

    #[test]
    fn specs_round_trip_through_serde_with_rules_as_strings() {
        let spec = HoldSpec {
            at_s: vec![1.5],
            rules: vec![rule("gripper >= 0.5")],
        };
        let json = serde_json::to_string(&spec).unwrap();
        assert_eq!(json, r#"{"at_s":[1.5],"rules":["gripper>=0.5"]}"#);
        assert_eq!(serde_json::from_str::<HoldSpec>(&json).unwrap(), spec);
        assert_eq!(
            serde_json::from_str::<HoldSpec>("{}").unwrap(),
            HoldSpec::default()
        );
        let e = serde_json::from_str::<HoldSpec>(r#"{"rules":["gripper"]}"#).unwrap_err();
        assert!(e.to_string().contains("no comparison"), "{e}");
    }
}
