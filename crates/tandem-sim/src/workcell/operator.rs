//! The simulated operator (§III): its parameters, which samples need a correction, unneeded
//! corrections as episodes, and the joystick input of a correction (module docs of
//! [`crate::workcell`], steps 2–3).

use rand::Rng;
use serde::{Deserialize, Serialize};
use tandem_lfd::TaskModel;

use crate::task::{Label, N_PASSES, Phase, Workpiece};
use crate::{Error, Result};

/// The simulated operator (§III).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OperatorParams {
    /// Probability of missing a needed correction, in `[0, 1]`. Default: 0.01 (§III).
    pub miss_rate: f64,
    /// Share of the supervised samples that need no correction on which the operator
    /// corrects anyway, in `[0, 1)`. Default: 0.01 (§III: "1 % of the time").
    pub false_correction_rate: f64,
    /// Mean duration (s) of one unneeded correction: a person who corrects by mistake
    /// holds the joystick for a while, so unneeded corrections come as episodes of
    /// geometric length with this mean, started at the rate that makes them cover
    /// `false_correction_rate` of the time. `0` (or anything up to one control tick) draws
    /// every tick independently. Finite and `≥ 0`. Default: 0.5 s.
    pub false_correction_s: f64,
    /// Channel whose increase a correction aims at. Default: `"force"` (the sanding
    /// task's normal force, N).
    pub force_channel: String,
    /// Joystick deflection `|u_k|` of a correction, in `(0, 1]`. The model's components
    /// span ±3σ at `|u_k| = 1`, so the default 1/3 moves the command about one standard
    /// deviation along each component: from the mean towards how the experts sanded over
    /// paint, not to the edge of what they ever did. Default: 1/3.
    pub gain: f64,
    /// The operator's own switch time `δ_true` (real s, finite and ≥ 0; issue 41): a person
    /// needs this long after the end of one robot's supervision before corrections on
    /// *another* robot are effective (docs/decisions.md, "The simulated operator's switch
    /// time (issue 41)"); a correction needed earlier is missed
    /// ([`crate::workcell::RobotRun::switch_missed`]). Independent of the switch time the
    /// schedule was planned with (`tandem_schedule::SamplerParams::switch_s`), so a study can
    /// run a plan that ignores it. Default 0: no switch time, the operator of before (the
    /// same draws, bit for bit); not serialized when 0.
    #[serde(skip_serializing_if = "is_zero_s")]
    pub switch_true_s: f64,
}

/// Whether a duration is 0 (for `skip_serializing_if`).
#[expect(
    clippy::trivially_copy_pass_by_ref,
    reason = "serde passes the field by reference"
)]
fn is_zero_s(v: &f64) -> bool {
    *v == 0.0
}

impl Default for OperatorParams {
    fn default() -> Self {
        Self {
            miss_rate: 0.01,
            false_correction_rate: 0.01,
            false_correction_s: 0.5,
            force_channel: "force".into(),
            gain: 1.0 / 3.0,
            switch_true_s: 0.0,
        }
    }
}

/// Channels a simulated operator's correction aims at by default, in order of preference: the
/// task's contact or process quantity when it has one.
const CORRECTION_CHANNELS: [&str; 8] = [
    "force", "fz", "torque", "tz", "flow", "pressure", "depth", "width",
];

/// Position channels, never the default correction channel when another scalar channel exists.
const POSITION_CHANNELS: [&str; 3] = ["x", "y", "z"];

/// The channel a simulated operator's corrections raise on `model` when the user names none
/// ([`OperatorParams::force_channel`]): the first of `force`, `fz`, `torque`, `tz`, `flow`,
/// `pressure`, `depth`, `width` the model has, else its first scalar channel that is not a
/// position (`x`, `y`, `z`), a quaternion's tangent coordinate or `rate`, else its first
/// tangent coordinate. On the sanding task: `force` (the default of [`OperatorParams`]).
///
/// ```
/// use tandem_lfd::{Demonstration, FitParams, TaskModel};
/// use tandem_sim::workcell::correction_channel;
///
/// // A welding task: a position, the arc current and the wire feed, two demonstrations.
/// let names: Vec<String> = ["x", "current", "wire_feed"].map(String::from).into();
/// let rows = |k: f64| (0..40).flat_map(|n| [n as f64 * 0.01, 150.0 + k, 5.0]).collect();
/// let demos = [
///     Demonstration::new(names.clone(), rows(0.0), 0.01)?,
///     Demonstration::new(names, rows(2.0), 0.01)?,
/// ];
/// let model = TaskModel::fit(&demos, &FitParams::default())?;
/// // No `force` or other known process channel: the first scalar that is not a position.
/// assert_eq!(correction_channel(&model), "current");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[must_use]
pub fn correction_channel(model: &TaskModel) -> String {
    let names = model.tangent_names();
    CORRECTION_CHANNELS
        .iter()
        .find_map(|c| names.iter().find(|n| n.as_str() == *c))
        .or_else(|| {
            names.iter().find(|n| {
                !n.contains('.') && n.as_str() != "rate" && !POSITION_CHANNELS.contains(&n.as_str())
            })
        })
        .or_else(|| names.first())
        .cloned()
        .unwrap_or_default()
}

impl OperatorParams {
    /// Index of [`OperatorParams::force_channel`] among `model`'s tangent coordinates
    /// ([`TaskModel::tangent_names`]).
    ///
    /// # Errors
    /// [`Error::NoForceChannel`] naming the channel, the model's channels and the fix.
    pub fn channel_index(&self, model: &TaskModel) -> Result<usize> {
        let names = model.tangent_names();
        names
            .iter()
            .position(|n| *n == self.force_channel)
            .ok_or_else(|| Error::NoForceChannel {
                name: self.force_channel.clone(),
                channels: names.join(", "),
            })
    }

    /// Checks the rates.
    ///
    /// # Errors
    /// [`Error::BadParam`] naming the field.
    pub fn validate(&self) -> Result<()> {
        for (name, p) in [
            ("miss_rate", self.miss_rate),
            ("false_correction_rate", self.false_correction_rate),
        ] {
            if !(0.0..=1.0).contains(&p) {
                return Err(Error::BadParam {
                    name,
                    why: "must be a probability in [0, 1]",
                });
            }
        }
        if !(0.0..1.0).contains(&self.false_correction_rate) {
            return Err(Error::BadParam {
                name: "false_correction_rate",
                why: "must be in [0, 1)",
            });
        }
        if !(self.false_correction_s.is_finite() && self.false_correction_s >= 0.0) {
            return Err(Error::BadParam {
                name: "false_correction_s",
                why: "must be finite and ≥ 0",
            });
        }
        if !(self.gain > 0.0 && self.gain <= 1.0) {
            return Err(Error::BadParam {
                name: "gain",
                why: "must be in (0, 1]",
            });
        }
        if !(self.switch_true_s.is_finite() && self.switch_true_s >= 0.0) {
            return Err(Error::BadParam {
                name: "switch_true_s",
                why: "must be finite and ≥ 0 (the operator's own switch time in seconds; 0: none)",
            });
        }
        Ok(())
    }
}

/// Where the simulated operator's attention is (issue 41): the robot it supervised last, the
/// last control tick it did, and the first tick from which its corrections on that robot are
/// effective. With a switch time of `k` ticks (`δ_true` rounded up to whole ticks,
/// [`tandem_realtime::switch_ticks`]): when robot `j` is supervised in tick `t` and the
/// attention was on another robot `i`, last supervised in tick `L` (its stretch ended at the
/// end of tick `L`), the operator is ready for `j` from tick `L + 1 + k` on, `k·Δt ≥ δ_true`
/// after `i`'s stretch ended: a needed correction in a tick before that is missed. The
/// operator turns to the next robot as soon as the previous one leaves its stretch (a display
/// tells it which robot comes next), so a schedule that leaves at least `δ_true` between two
/// robots' stretches loses nothing; back-to-back stretches lose the first `δ_true` of the
/// second. The first robot a fresh operator supervises (a round's first, a cell's first) is
/// no switch. Supervising the same robot again, after a pause or not, is no switch either.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Attention {
    /// `(robot, last supervised tick, first effective tick)`, `None` before the first.
    on: Option<(usize, usize, usize)>,
}

impl Attention {
    /// Robot `robot` is supervised in tick `tick` by an operator with a switch time of
    /// `switch_ticks` ticks: returns whether the operator is still switching to it (its
    /// corrections in this tick are not effective). Ticks must not decrease.
    pub(super) fn supervise(&mut self, robot: usize, tick: usize, switch_ticks: usize) -> bool {
        let ready = match self.on {
            Some((r, _, ready)) if r == robot => ready,
            Some((_, last, _)) => last + 1 + switch_ticks,
            None => tick,
        };
        self.on = Some((robot, tick, ready));
        tick < ready
    }
}

/// Whether a reference sample with this label needs a correction on `workpiece`: sanding
/// in passes 1–3 over a painted section (pass 4 is always painted and never needs one).
#[must_use]
pub fn needs_correction(label: &Label, workpiece: &Workpiece) -> bool {
    label.phase == Phase::Sanding
        && (1..N_PASSES).contains(&usize::from(label.pass))
        && workpiece.painted_at(label)
}

/// Unneeded corrections as episodes of geometric length with mean `l ≥ 1` ticks: outside
/// one, a tick starts one with probability `p_start`; each tick of an episode is followed
/// by another with probability `1 − 1/l`. Off runs last `(1 − p_start)/p_start` ticks on
/// average, so episodes cover `l·p_start / (l·p_start + 1 − p_start)` of the time, which
/// `p_start = rate / (l·(1 − rate) + rate)` makes equal to `rate`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Episodes {
    p_start: f64,
    p_end: f64,
    /// `l > 1`: episodes last more than one tick (else every tick is drawn alone).
    lasting: bool,
}

impl Episodes {
    /// `rate` in `[0, 1)`, mean length `ticks` (values below 1 mean 1).
    pub(super) fn new(rate: f64, ticks: f64) -> Self {
        let l = ticks.max(1.0);
        Episodes {
            p_start: rate / (l * (1.0 - rate) + rate),
            p_end: 1.0 / l,
            lasting: l > 1.0,
        }
    }

    /// One supervised tick that needs no correction: `(corrected, in an episode after it)`
    /// from the state before it, the tick's draw `draw ∈ [0, 1)` and, for the length of an
    /// episode, one more draw from `rng`.
    pub(super) fn tick(&self, in_episode: bool, draw: f64, rng: &mut impl Rng) -> (bool, bool) {
        let corrected = in_episode || draw < self.p_start;
        let goes_on = corrected && self.lasting && rng.random::<f64>() >= self.p_end;
        (corrected, goes_on)
    }
}

/// The simulated operator's joystick input for a force-raising, slowing correction at
/// fractional reference time `ref_time` (see the module docs, step 3): fills `u` (one entry
/// per correction component, [`TaskModel::n_components`]) with `±gain` or 0 and returns
/// whether any entry is non-zero. `force_idx` is the force channel's index in
/// [`TaskModel::tangent_names`]. `u` is along the components of
/// [`TaskModel::corrections_at`], for [`TaskModel::command_into`] (Eq. 7); the workcell itself
/// chooses the same input in the frame of [`TaskModel::local_corrections_at`] and passes it
/// to [`TaskModel::local_command_into`], which gives the same command. Public so that a
/// replay of a run can recompute the operator's input.
///
/// # Errors
/// The model crate's error for `ref_time` outside `[0, T_ref − 1]`.
pub fn correction_input(
    model: &TaskModel,
    force_idx: usize,
    gain: f64,
    ref_time: f64,
    u: &mut [f64],
) -> Result<bool> {
    let corr = model.corrections_at(ref_time)?;
    Ok(input_along(&corr.components, force_idx, gain, u))
}

/// [`correction_input`] along the components of [`TaskModel::local_corrections_at`], for
/// [`TaskModel::local_command_into`]: only the two reference samples around `ref_time` are
/// decomposed.
///
/// # Errors
/// As [`correction_input`].
pub(super) fn local_correction_input(
    model: &TaskModel,
    force_idx: usize,
    gain: f64,
    ref_time: f64,
    u: &mut [f64],
) -> Result<bool> {
    let corr = model.local_corrections_at(ref_time)?;
    Ok(input_along(&corr.components, force_idx, gain, u))
}

/// The operator's rule of [`correction_input`] on the given components (`d` values each,
/// the rate last): `u_k = ±gain` with the sign of component `k`'s force entry, then, if the
/// combined input would speed the robot up, only the components that slow it down (or leave
/// its rate alone). Odd in each component: negating component `k` negates `u_k` alone, so
/// every product `u_k·c_k` is unchanged.
fn input_along(components: &[Vec<f64>], force_idx: usize, gain: f64, u: &mut [f64]) -> bool {
    let mut rate_change = 0.0;
    let mut any = false;
    for (k, c) in components.iter().enumerate() {
        let rate_idx = c.len() - 1;
        u[k] = if c[force_idx] > 0.0 {
            gain
        } else if c[force_idx] < 0.0 {
            -gain
        } else {
            0.0
        };
        any |= u[k] != 0.0;
        rate_change += u[k] * c[rate_idx];
    }
    if rate_change < 0.0 {
        // Keep only the components that slow the robot down (or leave its rate alone).
        for (k, c) in components.iter().enumerate() {
            if u[k] * c[c.len() - 1] < 0.0 {
                u[k] = 0.0;
            }
        }
        any = u.iter().any(|&x| x != 0.0);
    }
    any
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;

    use super::*;

    /// A model of two demonstrations with these channels: the first a ramp both share, the
    /// others constant and apart by 0.5.
    fn model_of(names: &[&str]) -> TaskModel {
        let names: Vec<String> = names.iter().map(|n| (*n).to_string()).collect();
        let rows = |k: f64| -> Vec<f64> {
            (0..30)
                .flat_map(|n| {
                    (0..names.len()).map(move |c| {
                        if c == 0 {
                            n as f64 * 0.01
                        } else {
                            c as f64 + k
                        }
                    })
                })
                .collect()
        };
        let demos = [
            tandem_lfd::Demonstration::new(names.clone(), rows(0.0), 0.01).unwrap(),
            tandem_lfd::Demonstration::new(names.clone(), rows(0.5), 0.01).unwrap(),
        ];
        TaskModel::fit(&demos, &tandem_lfd::FitParams::default()).unwrap()
    }

    #[test]
    fn the_default_correction_channel_prefers_a_process_quantity_then_a_non_position() {
        // A known process quantity wins wherever it stands.
        assert_eq!(
            correction_channel(&model_of(&["x", "valve", "flow"])),
            "flow"
        );
        assert_eq!(correction_channel(&model_of(&["force", "torque"])), "force");
        // None known: the first scalar that is not a position.
        assert_eq!(
            correction_channel(&model_of(&["x", "y", "current", "feed"])),
            "current"
        );
        // Only positions: the first coordinate.
        assert_eq!(correction_channel(&model_of(&["y", "x"])), "y");
    }

    #[test]
    fn a_missing_correction_channel_names_the_models_channels_and_the_fix() {
        let model = model_of(&["x", "current"]);
        let e = OperatorParams::default().channel_index(&model).unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("`force`") && text.contains("x, current"),
            "{text}"
        );
        assert!(text.contains("--channel"), "{text}");
        let ok = OperatorParams {
            force_channel: "current".into(),
            ..OperatorParams::default()
        };
        assert_eq!(ok.channel_index(&model).unwrap(), 1);
    }

    #[test]
    fn attention_needs_the_switch_time_after_another_robots_stretch() {
        // A switch time of 3 ticks.
        let mut a = Attention::default();
        // The first robot is no switch; robot 0 supervised in ticks 0..=4.
        for t in 0..5 {
            assert!(!a.supervise(0, t, 3), "tick {t}");
        }
        // Robot 1 right after (tick 5): its stretch ended at the end of tick 4, so the
        // operator is ready from tick 4 + 1 + 3 = 8 on.
        let switching: Vec<bool> = (5..10).map(|t| a.supervise(1, t, 3)).collect();
        assert_eq!(switching, [true, true, true, false, false]);
        // Back to robot 0 after a pause of 3 ticks (10, 11, 12 unsupervised): ready at
        // 9 + 1 + 3 = 13, the tick it starts.
        assert!(!a.supervise(0, 13, 3));
        // Robot 1 again after a pause of 2 ticks: one tick of switching left.
        assert!(a.supervise(1, 16, 3));
        assert!(!a.supervise(1, 17, 3));
        // The same robot after any pause: no switch.
        assert!(!a.supervise(1, 40, 3));
        // No switch time: never switching.
        let mut b = Attention::default();
        assert!(!b.supervise(0, 0, 0));
        assert!(!b.supervise(1, 1, 0));
    }

    #[test]
    fn unneeded_corrections_cover_the_rate_in_episodes_of_the_mean_length() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for (rate, ticks) in [(0.01, 50.0), (0.01, 1.0), (0.2, 10.0)] {
            let e = Episodes::new(rate, ticks);
            let (mut state, mut on, mut starts) = (false, 0usize, 0usize);
            let n = 2_000_000;
            for _ in 0..n {
                let before = state;
                let draw: f64 = rng.random();
                let (corrected, next) = e.tick(state, draw, &mut rng);
                on += usize::from(corrected);
                starts += usize::from(corrected && !before);
                state = next;
            }
            let share = on as f64 / n as f64;
            let mean_len = on as f64 / starts as f64;
            assert!(
                (share - rate).abs() < 0.1 * rate,
                "{rate} {ticks}: share {share}"
            );
            assert!(
                (mean_len - ticks).abs() < 0.1 * ticks,
                "{rate} {ticks}: {mean_len}"
            );
        }
    }
}
