//! Sanding task generator (paper §III; why its transitions last 16 s ± 45 %:
//! docs/decisions.md, "The fixtures' transitions: 16 s ± 45 %").
//!
//! # The task
//!
//! A rectangular plate lies in the *plate frame*: origin at a plate corner, `x` along the plate
//! length (the sanding direction), `y` across it, `z` up along the plate normal, the plate
//! surface at `z = 0`.
//! The task has [`N_PASSES`] = 4 sanding passes.
//! Pass `k` (1-based) runs at the fixed lateral position `y_k = (k − ½)·plate_width_m / 4`, always
//! from `x = 0` to `x = plate_length_m` (left to right, as the paper's alignment assumption asks).
//! Each pass is cut along `x` into `n_sections` equal sections; section `j` (0-based) covers
//! `x ∈ [j·ℓ, (j+1)·ℓ)` with `ℓ = plate_length_m / n_sections`.
//! A [`Workpiece`] says which sections are painted: in passes 1–3 exactly half of them, chosen at
//! random for every workpiece; in pass 4 all of them.
//!
//! # The simulated expert
//!
//! * **Sanding.** The tool is on (`tool = 1`) and in contact (`z = 0`).
//!   Over paint the expert presses with `force_painted_n` and moves at `speed_painted_m_s`;
//!   elsewhere with `force_unpainted_n` at `speed_unpainted_m_s`.
//!   Speed and force follow these section targets through first-order lags (`speed_tau_s`,
//!   `force_tau_s`): a hand does not jump.
//!   Each pass starts from rest and brakes towards its end (`brake_tau_s`, `end_speed_m_s`).
//! * **Transitions.** After passes 1–3 the tool is switched off (`tool = 0`), lifted off along an
//!   arc and put down at the start of the next pass, slowly (`transition_duration_s`).
//!   The arc varies from transition to transition: its height, its lateral bulge, when the tool
//!   starts and stops moving sideways, when it is highest, and how the hand tilts.
//! * **Human variability.** A global speed factor per demonstration (`speed_global_var`), a slow
//!   speed drift, smooth force noise, a small lateral wobble of the path and a small tilt of the
//!   tool, each smooth Gaussian noise (white noise low-pass filtered twice) with a given standard
//!   deviation and correlation time.
//!
//! Consequently, once demonstrations are time-warped onto each other, their per-sample variance
//! is high over the sanding of passes 1–3 (the paint pattern differs, so force differs by about
//! 15 N and speed by a factor of 2), high over the transitions (the arc differs by centimetres)
//! and low over pass 4 (always painted: the same force up to ±0.5 N of noise and the same path).
//!
//! # Samples and labels
//!
//! A demonstration ([`TaskDemo`]) is a sequence of samples in *demo time*: sample `i` is at
//! `t = i·dt_s` seconds from the start (default `dt_s` = 0.01 s).
//! Each sample has the 9 channels of [`CHANNELS`] and one ground-truth [`Label`].
//! The first sample is the tool touching down at the start of pass 1; the last is the end of
//! pass 4.

use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::{Error, Result};

/// Number of sanding passes of the task (paper §III: four passes).
pub const N_PASSES: usize = 4;

/// Number of channels of a sample.
pub const N_CHANNELS: usize = 9;

/// Channel names, in sample order.
///
/// * `x`, `y`, `z`: tool contact point in the plate frame, metres.
/// * `qx`, `qy`, `qz`, `qw`: unit quaternion (vector part first) rotating the plate frame into the
///   tool frame. The tool frame is defined so that the identity means the sanding disc lies flat
///   on the plate (disc normal = plate `+z`); the generator keeps `qw > 0`.
/// * `force`: normal force of the disc on the plate, newtons, `≥ 0`.
/// * `tool`: tool state, `1.0` = on (sanding), `0.0` = off.
pub const CHANNELS: [&str; N_CHANNELS] = ["x", "y", "z", "qx", "qy", "qz", "qw", "force", "tool"];

/// Index of the `x` channel in a sample (position channels are `0..3`).
pub const CHANNEL_X: usize = 0;
/// Index of the `qx` channel in a sample (quaternion channels are `3..7`, `qw` last).
pub const CHANNEL_QX: usize = 3;
/// Index of the `force` channel in a sample.
pub const CHANNEL_FORCE: usize = 7;
/// Index of the `tool` channel in a sample.
pub const CHANNEL_TOOL: usize = 8;

/// Hard limit on the length of one demonstration, in samples (10⁶ = 10 000 s at 100 Hz).
///
/// [`TaskParams::validate`] rejects parameters whose worst case exceeds it and [`demonstrate`]
/// returns [`Error::TooLong`] rather than run away.
pub const MAX_SAMPLES: usize = 1_000_000;

/// Seed of the committed fixtures (`fixtures/sanding/`): they are
/// `demonstrations(&TaskParams::default(), N_FIXTURE_DEMOS, &mut ChaCha8Rng::seed_from_u64(FIXTURE_SEED))`.
pub const FIXTURE_SEED: u64 = 2023;

/// Number of committed fixture demonstrations (paper §III: six demonstrations).
pub const N_FIXTURE_DEMOS: usize = 6;

/// Parameters of the sanding task and of the simulated expert.
///
/// Lengths in metres, speeds in m/s, forces in newtons, times in seconds of demo time, angles in
/// radians. Variabilities marked "fraction" are relative (0.1 = ±10 %).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TaskParams {
    /// Plate length along `x` = length of every pass. Must be > 0. Default: 0.6 m.
    pub plate_length_m: f64,
    /// Plate width along `y`; pass `k` runs at `y = (k − ½)·plate_width_m / 4`. Must be > 0.
    /// Default: 0.4 m.
    pub plate_width_m: f64,
    /// Sections per pass. Must be even (passes 1–3 are painted in exactly half of them) and in
    /// `2..=254`. Default: 6.
    pub n_sections: usize,
    /// Nominal sanding speed over paint. Must be > 0. Default: 0.04 m/s.
    pub speed_painted_m_s: f64,
    /// Nominal sanding speed where there is no paint. Must be > 0. Default: 0.08 m/s.
    pub speed_unpainted_m_s: f64,
    /// Nominal normal force over paint. Must be ≥ 0. Default: 20 N.
    pub force_painted_n: f64,
    /// Nominal normal force where there is no paint. Must be ≥ 0. Default: 3.5 N.
    pub force_unpainted_n: f64,
    /// Time constant of the first-order lag of the speed towards its target. Must be > 0.
    /// Default: 0.3 s.
    pub speed_tau_s: f64,
    /// Time constant of the first-order lag of the force towards its target (also the unloading
    /// at lift-off). Must be > 0. Default: 0.25 s.
    pub force_tau_s: f64,
    /// Braking near the end of a pass: the target speed is capped at
    /// `end_speed_m_s + (plate_length_m − x) / brake_tau_s`. Must be > 0. Default: 0.5 s.
    pub brake_tau_s: f64,
    /// Speed at which the tool arrives at the end of a pass. Must be > 0. Default: 0.01 m/s.
    pub end_speed_m_s: f64,
    /// Nominal duration of a transition between passes. Must be > 0. Default: 16 s.
    ///
    /// Paper §III: "the tool was moved slowly between passes as a simple way to ensure the
    /// task was amenable to a highly-parallel execution (i.e., one robot sanding while the
    /// other moved between passes)". So a transition must be able to last as long as a
    /// sanding pass (11–12 s at the mean pace) plus the worst-case margins of Alg. 2: with
    /// 7 s ± 20 % transitions (at most ~10 s even at the slowest demonstrated pace) no
    /// schedule could put one robot's pass inside the other's transition, and the best
    /// schedule of the mid-study problem overlapped the robots only from pass 4 on
    /// (measured at commit `0c9ae47`; docs/decisions.md).
    pub transition_duration_s: f64,
    /// Variability of the transition duration, fraction: uniform in
    /// `transition_duration_s·(1 ± transition_duration_var)`. Must be in `[0, 1)`.
    /// Default: 0.45.
    ///
    /// The spread across demonstrations sets `[ψ̇min, ψ̇max]` over the transitions, i.e.
    /// how much the coordinator may speed up or slow down the robot in transition while
    /// the operator rushes or drags the other one's pass; Alg. 2's worst-case check needs
    /// that room (with ± 20 % no alternating schedule of the mid-study problem passed it;
    /// measured at commit `0c9ae47`).
    pub transition_duration_var: f64,
    /// Lowest apex height of the lift-off arc above the plate. Must be ≥ 0. Default: 0.04 m.
    pub lift_height_min_m: f64,
    /// Highest apex height of the lift-off arc (uniform between min and max). Must be
    /// ≥ `lift_height_min_m`. Default: 0.12 m.
    pub lift_height_max_m: f64,
    /// Largest lateral (`y`) bulge of the transition path, uniform in `±transition_bulge_m`.
    /// Must be ≥ 0. Default: 0.05 m.
    pub transition_bulge_m: f64,
    /// Largest extra tilt of the tool about `x` and about `y` during a transition, uniform in
    /// `±transition_tilt_rad` each. Must be in `[0, 0.5]`. Default: 0.1 rad.
    pub transition_tilt_rad: f64,
    /// Global speed factor of a demonstration, fraction: uniform in `1 ± speed_global_var`.
    /// Must be in `[0, 0.5]`. Default: 0.1.
    pub speed_global_var: f64,
    /// Standard deviation of the slow relative speed drift, fraction (the drift factor is clamped
    /// to `[0.5, 1.5]`). Must be ≥ 0. Default: 0.05.
    pub speed_drift_std: f64,
    /// Correlation time of the speed drift. Must be > 0. Default: 2 s.
    pub speed_drift_tau_s: f64,
    /// Standard deviation of the smooth force noise while sanding. Must be ≥ 0. Default: 0.3 N.
    pub force_noise_std_n: f64,
    /// Correlation time of the force noise. Must be > 0. Default: 0.5 s.
    pub force_noise_tau_s: f64,
    /// Standard deviation of the lateral (`y`) path wobble while sanding. Must be ≥ 0.
    /// Default: 0.002 m.
    pub lateral_noise_std_m: f64,
    /// Correlation time of the lateral wobble. Must be > 0. Default: 1 s.
    pub lateral_noise_tau_s: f64,
    /// Standard deviation of the tool tilt about each plate axis. Must be in `[0, 0.2]`.
    /// Default: 0.015 rad (≈ 0.9°).
    pub tilt_noise_std_rad: f64,
    /// Correlation time of the tilt noise. Must be > 0. Default: 1 s.
    pub tilt_noise_tau_s: f64,
    /// Sample rate; `dt_s = 1 / sample_rate_hz`. Must be in `[1, 10 000]`. Default: 100 Hz.
    pub sample_rate_hz: f64,
}

impl Default for TaskParams {
    fn default() -> Self {
        Self {
            plate_length_m: 0.6,
            plate_width_m: 0.4,
            n_sections: 6,
            speed_painted_m_s: 0.04,
            speed_unpainted_m_s: 0.08,
            force_painted_n: 20.0,
            force_unpainted_n: 3.5,
            speed_tau_s: 0.3,
            force_tau_s: 0.25,
            brake_tau_s: 0.5,
            end_speed_m_s: 0.01,
            transition_duration_s: 16.0,
            transition_duration_var: 0.45,
            lift_height_min_m: 0.04,
            lift_height_max_m: 0.12,
            transition_bulge_m: 0.05,
            transition_tilt_rad: 0.1,
            speed_global_var: 0.1,
            speed_drift_std: 0.05,
            speed_drift_tau_s: 2.0,
            force_noise_std_n: 0.3,
            force_noise_tau_s: 0.5,
            lateral_noise_std_m: 0.002,
            lateral_noise_tau_s: 1.0,
            tilt_noise_std_rad: 0.015,
            tilt_noise_tau_s: 1.0,
            sample_rate_hz: 100.0,
        }
    }
}

/// `Err(BadParam)` unless `ok`.
fn check(ok: bool, name: &'static str, why: &'static str) -> Result<()> {
    if ok {
        Ok(())
    } else {
        Err(Error::BadParam { name, why })
    }
}

impl TaskParams {
    /// Checks every field against its documented range (non-finite values are rejected) and that
    /// the slowest possible demonstration stays below [`MAX_SAMPLES`].
    ///
    /// # Errors
    /// [`Error::BadParam`] naming the first offending field.
    pub fn validate(&self) -> Result<()> {
        let positive: [(&'static str, f64); 11] = [
            ("plate_length_m", self.plate_length_m),
            ("plate_width_m", self.plate_width_m),
            ("speed_painted_m_s", self.speed_painted_m_s),
            ("speed_unpainted_m_s", self.speed_unpainted_m_s),
            ("speed_tau_s", self.speed_tau_s),
            ("force_tau_s", self.force_tau_s),
            ("brake_tau_s", self.brake_tau_s),
            ("end_speed_m_s", self.end_speed_m_s),
            ("transition_duration_s", self.transition_duration_s),
            ("speed_drift_tau_s", self.speed_drift_tau_s),
            ("force_noise_tau_s", self.force_noise_tau_s),
        ];
        for (name, value) in positive {
            check(
                value.is_finite() && value > 0.0,
                name,
                "must be finite and > 0",
            )?;
        }
        for (name, value) in [
            ("lateral_noise_tau_s", self.lateral_noise_tau_s),
            ("tilt_noise_tau_s", self.tilt_noise_tau_s),
        ] {
            check(
                value.is_finite() && value > 0.0,
                name,
                "must be finite and > 0",
            )?;
        }
        let non_negative: [(&'static str, f64); 7] = [
            ("force_painted_n", self.force_painted_n),
            ("force_unpainted_n", self.force_unpainted_n),
            ("lift_height_min_m", self.lift_height_min_m),
            ("transition_bulge_m", self.transition_bulge_m),
            ("speed_drift_std", self.speed_drift_std),
            ("force_noise_std_n", self.force_noise_std_n),
            ("lateral_noise_std_m", self.lateral_noise_std_m),
        ];
        for (name, value) in non_negative {
            check(
                value.is_finite() && value >= 0.0,
                name,
                "must be finite and ≥ 0",
            )?;
        }
        check(
            self.n_sections >= 2 && self.n_sections <= 254 && self.n_sections % 2 == 0,
            "n_sections",
            "must be even and in 2..=254",
        )?;
        check(
            self.lift_height_max_m.is_finite() && self.lift_height_max_m >= self.lift_height_min_m,
            "lift_height_max_m",
            "must be finite and ≥ lift_height_min_m",
        )?;
        check(
            (0.0..1.0).contains(&self.transition_duration_var),
            "transition_duration_var",
            "must be in [0, 1)",
        )?;
        check(
            (0.0..=0.5).contains(&self.transition_tilt_rad),
            "transition_tilt_rad",
            "must be in [0, 0.5]",
        )?;
        check(
            (0.0..=0.5).contains(&self.speed_global_var),
            "speed_global_var",
            "must be in [0, 0.5]",
        )?;
        check(
            (0.0..=0.2).contains(&self.tilt_noise_std_rad),
            "tilt_noise_std_rad",
            "must be in [0, 0.2]",
        )?;
        check(
            (1.0..=10_000.0).contains(&self.sample_rate_hz),
            "sample_rate_hz",
            "must be in [1, 10000]",
        )?;
        let dt_s = self.dt_s();
        check(
            self.transition_duration_s * (1.0 - self.transition_duration_var) >= 2.0 * dt_s,
            "transition_duration_s",
            "shortest transition must last at least two samples",
        )?;
        // Worst case: every pass at the slowest possible cruise speed (global factor and drift at
        // their lower limits) or at the end speed, plus ramp-up, plus the longest transitions.
        let slowest_m_s = (self.speed_painted_m_s.min(self.speed_unpainted_m_s)
            * (1.0 - self.speed_global_var)
            * 0.5)
            .min(self.end_speed_m_s);
        let worst_s = N_PASSES as f64
            * (self.plate_length_m / slowest_m_s + 10.0 * self.speed_tau_s)
            + (N_PASSES - 1) as f64
                * self.transition_duration_s
                * (1.0 + self.transition_duration_var);
        check(
            worst_s / dt_s < MAX_SAMPLES as f64,
            "speed_painted_m_s",
            "speeds are too low for the plate length: a demonstration could exceed MAX_SAMPLES",
        )?;
        Ok(())
    }

    /// Sample period `Δt_s = 1 / sample_rate_hz`, seconds of demo time.
    #[must_use]
    pub fn dt_s(&self) -> f64 {
        1.0 / self.sample_rate_hz
    }

    /// Nominal lateral position `y_k` of pass `pass` (1-based) in the plate frame, metres.
    #[must_use]
    pub fn pass_y_m(&self, pass: usize) -> f64 {
        (pass as f64 - 0.5) * self.plate_width_m / N_PASSES as f64
    }

    /// The 0-based section containing position `x_m` along a pass (clamped to the plate).
    #[must_use]
    pub fn section_at(&self, x_m: f64) -> usize {
        let section_len_m = self.plate_length_m / self.n_sections as f64;
        let j = (x_m / section_len_m).floor();
        if j.is_nan() || j < 0.0 {
            0
        } else {
            (j as usize).min(self.n_sections - 1)
        }
    }
}

/// Which sections of a plate are painted.
///
/// `painted[p][j]` is section `j` (0-based, along `x`) of pass `p + 1` (the outer index is
/// 0-based: `painted[0]` is pass 1). A [`Label`] of a sanding sample indexes it as
/// `painted[label.pass − 1][label.section]`; see [`Workpiece::painted_at`].
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Workpiece {
    /// `painted[pass − 1][section]`: [`N_PASSES`] rows of `n_sections` flags.
    pub painted: Vec<Vec<bool>>,
}

impl Workpiece {
    /// Draws a new workpiece (paper §III): in passes 1–3 exactly `n_sections / 2` sections,
    /// chosen uniformly at random, are painted; pass 4 is painted everywhere.
    ///
    /// # Errors
    /// [`Error::BadParam`] if `params` is invalid.
    pub fn random(params: &TaskParams, rng: &mut impl Rng) -> Result<Self> {
        params.validate()?;
        let n = params.n_sections;
        let mut painted = Vec::with_capacity(N_PASSES);
        for _ in 0..N_PASSES - 1 {
            // Partial Fisher–Yates shuffle: the first n/2 entries are a uniform random subset.
            let mut order: Vec<usize> = (0..n).collect();
            for i in 0..n / 2 {
                let j = rng.random_range(i..n);
                order.swap(i, j);
            }
            let mut row = vec![false; n];
            for &j in &order[..n / 2] {
                row[j] = true;
            }
            painted.push(row);
        }
        painted.push(vec![true; n]);
        Ok(Self { painted })
    }

    /// Checks the shape against `params`: [`N_PASSES`] passes of `n_sections` sections each.
    ///
    /// # Errors
    /// [`Error::BadWorkpiece`] naming the pass and the counts.
    pub fn validate(&self, params: &TaskParams) -> Result<()> {
        if self.painted.len() != N_PASSES {
            return Err(Error::BadWorkpiece {
                why: "wrong number of passes",
                pass: 0,
                expected: N_PASSES,
                found: self.painted.len(),
            });
        }
        for (p, row) in self.painted.iter().enumerate() {
            if row.len() != params.n_sections {
                return Err(Error::BadWorkpiece {
                    why: "wrong number of sections",
                    pass: p + 1,
                    expected: params.n_sections,
                    found: row.len(),
                });
            }
        }
        Ok(())
    }

    /// Whether the sample with this label is over paint on *this* workpiece: the flag of
    /// `(label.pass, label.section)` for a sanding sample, `false` for a transition (the tool is
    /// off the plate) or for a pass/section outside the workpiece.
    ///
    /// The simulated study uses it with the labels of the reference demonstration to decide
    /// which reference samples need a correction on a freshly drawn workpiece.
    #[must_use]
    pub fn painted_at(&self, label: &Label) -> bool {
        if label.phase != Phase::Sanding || label.pass == 0 {
            return false;
        }
        self.painted
            .get(usize::from(label.pass) - 1)
            .and_then(|row| row.get(usize::from(label.section)))
            .copied()
            .unwrap_or(false)
    }
}

/// What the expert is doing at a sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Phase {
    /// Tool on and in contact, moving along a pass.
    Sanding,
    /// Tool off, moving from the end of one pass to the start of the next.
    Transition,
}

/// Ground truth of one sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Label {
    /// Sanding: the pass being sanded, `1..=4`. Transition: the pass just finished, `1..=3`.
    pub pass: u8,
    /// Sanding: the 0-based section under the tool (from its `x` position). Transition: 0.
    pub section: u8,
    /// Sanding: whether that section is painted on the demonstration's workpiece.
    /// Transition: `false`.
    pub painted: bool,
    /// Sanding or transition.
    pub phase: Phase,
}

/// One simulated expert demonstration of the sanding task.
#[derive(Clone, Debug, PartialEq)]
pub struct TaskDemo {
    /// Samples in demo time, sample-major: `samples[i]` is at `t = i·dt_s`, channels as in
    /// [`CHANNELS`].
    pub samples: Vec<[f64; N_CHANNELS]>,
    /// Ground truth, one label per sample (same length as `samples`).
    pub labels: Vec<Label>,
    /// Sample period `Δt_s`, seconds.
    pub dt_s: f64,
}

impl TaskDemo {
    /// Duration `T_i·Δt_s` in seconds (number of samples times the sample period).
    #[must_use]
    pub fn duration_s(&self) -> f64 {
        self.samples.len() as f64 * self.dt_s
    }
}

/// Share of samples (in `[0, 1]`) that are *not* sanding in passes 1–3, i.e. the transitions and
/// pass 4: the samples that never need a correction. Over the reference demonstration this is the
/// paper's "ground-truth percentage" of high-confidence samples (Fig. 5, bottom), as a fraction.
/// Returns 0 for no labels.
#[must_use]
pub fn ground_truth_share(labels: &[Label]) -> f64 {
    if labels.is_empty() {
        return 0.0;
    }
    let n_free = labels
        .iter()
        .filter(|l| !(l.phase == Phase::Sanding && usize::from(l.pass) < N_PASSES))
        .count();
    n_free as f64 / labels.len() as f64
}

/// Standard normal draw (Box–Muller).
fn std_normal(rng: &mut impl Rng) -> f64 {
    let u1: f64 = 1.0 - rng.random::<f64>(); // (0, 1]
    let u2: f64 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// Uniform draw in `[lo, hi]` (returns `lo` when the interval is empty).
fn uniform(rng: &mut impl Rng, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * rng.random::<f64>()
}

/// Smooth Gaussian noise sampled every `dt_s`: white noise through two cascaded first-order
/// low-pass filters with time constant `tau_s`, scaled to the stationary standard deviation `std`
/// and started from its stationary distribution. Unlike a plain Ornstein–Uhlenbeck process it
/// has a finite rate of change (about `std / tau_s`), as a hand does.
struct SmoothNoise {
    /// First filter stage.
    inner: f64,
    /// Output (second stage).
    value: f64,
    /// Per-sample decay `a = exp(−dt_s / tau_s)`.
    decay: f64,
    /// Standard deviation of the white-noise kick of the first stage.
    kick: f64,
}

impl SmoothNoise {
    fn new(std: f64, tau_s: f64, dt_s: f64, rng: &mut impl Rng) -> Self {
        let a = (-dt_s / tau_s).exp();
        // Stationary variances: inner σ₁², output σ₁²(1 + a²)/(1 + a)²; covariance σ₁²/(1 + a).
        let inner_std = std * (1.0 + a) / (1.0 + a * a).sqrt();
        let inner = inner_std * std_normal(rng);
        let value = inner / (1.0 + a) + inner_std * a / (1.0 + a) * std_normal(rng);
        Self {
            inner,
            value,
            decay: a,
            kick: inner_std * (1.0 - a * a).sqrt(),
        }
    }

    fn step(&mut self, rng: &mut impl Rng) {
        self.inner = self.decay * self.inner + self.kick * std_normal(rng);
        self.value = self.decay * self.value + (1.0 - self.decay) * self.inner;
    }
}

/// Unit quaternion `[qx, qy, qz, qw]` of the rotation vector `r` (axis × angle, radians), `qw ≥ 0`
/// for angles up to π.
fn quat_from_rotvec(r: [f64; 3]) -> [f64; 4] {
    let angle = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
    let half = 0.5 * angle;
    // sin(half)/angle, with its limit 1/2 at zero.
    let s = if angle < 1e-9 {
        0.5
    } else {
        half.sin() / angle
    };
    let q = [r[0] * s, r[1] * s, r[2] * s, half.cos()];
    let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    [q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm]
}

/// Minimum-jerk time law `10s³ − 15s⁴ + 6s⁵` on `[0, 1]` (zero speed and acceleration at both
/// ends).
fn min_jerk(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    s * s * s * (10.0 + s * (-15.0 + 6.0 * s))
}

/// The expert's hand: the smooth noises that persist across the whole demonstration.
struct Hand {
    speed_factor: f64,
    drift: SmoothNoise,
    force_noise: SmoothNoise,
    lateral: SmoothNoise,
    tilt: [SmoothNoise; 3],
}

impl Hand {
    fn new(params: &TaskParams, rng: &mut impl Rng) -> Self {
        let dt_s = params.dt_s();
        let g = params.speed_global_var;
        Self {
            speed_factor: uniform(rng, 1.0 - g, 1.0 + g),
            drift: SmoothNoise::new(params.speed_drift_std, params.speed_drift_tau_s, dt_s, rng),
            force_noise: SmoothNoise::new(
                params.force_noise_std_n,
                params.force_noise_tau_s,
                dt_s,
                rng,
            ),
            lateral: SmoothNoise::new(
                params.lateral_noise_std_m,
                params.lateral_noise_tau_s,
                dt_s,
                rng,
            ),
            tilt: [
                SmoothNoise::new(
                    params.tilt_noise_std_rad,
                    params.tilt_noise_tau_s,
                    dt_s,
                    rng,
                ),
                SmoothNoise::new(
                    params.tilt_noise_std_rad,
                    params.tilt_noise_tau_s,
                    dt_s,
                    rng,
                ),
                SmoothNoise::new(
                    params.tilt_noise_std_rad,
                    params.tilt_noise_tau_s,
                    dt_s,
                    rng,
                ),
            ],
        }
    }

    fn step_tilt(&mut self, rng: &mut impl Rng) {
        for t in &mut self.tilt {
            t.step(rng);
        }
    }
}

/// Appends one sample and its label, failing past [`MAX_SAMPLES`].
fn push(demo: &mut TaskDemo, sample: [f64; N_CHANNELS], label: Label) -> Result<()> {
    if demo.samples.len() >= MAX_SAMPLES {
        return Err(Error::TooLong { limit: MAX_SAMPLES });
    }
    demo.samples.push(sample);
    demo.labels.push(label);
    Ok(())
}

/// Simulates one expert demonstration of the sanding task on `workpiece` (see the module docs
/// for the model). The random stream of `rng` is consumed in a fixed order, so the same `rng`
/// state gives the same demonstration, bit for bit.
///
/// # Errors
/// [`Error::BadParam`] if `params` is invalid, [`Error::BadWorkpiece`] if `workpiece` does not
/// have [`N_PASSES`] passes of `params.n_sections` sections, [`Error::TooLong`] if the
/// demonstration would exceed [`MAX_SAMPLES`] samples.
pub fn demonstrate(
    params: &TaskParams,
    workpiece: &Workpiece,
    rng: &mut impl Rng,
) -> Result<TaskDemo> {
    params.validate()?;
    workpiece.validate(params)?;
    let dt_s = params.dt_s();
    let length_m = params.plate_length_m;
    let speed_gain = 1.0 - (-dt_s / params.speed_tau_s).exp();
    let force_gain = 1.0 - (-dt_s / params.force_tau_s).exp();

    let mut hand = Hand::new(params, rng);
    let mut demo = TaskDemo {
        samples: Vec::with_capacity(8000),
        labels: Vec::with_capacity(8000),
        dt_s,
    };
    // Force state (before noise); carried across phases so that unloading and loading are smooth.
    let mut force_n = 0.0;

    for pass in 1..=N_PASSES {
        let y_m = params.pass_y_m(pass);
        let row = &workpiece.painted[pass - 1];
        let pass_u8 = u8::try_from(pass).expect("N_PASSES = 4 fits in u8");

        // --- Sanding: from rest at x = 0 to x = plate_length_m.
        let mut x_m = 0.0;
        let mut speed_m_s = 0.0;
        loop {
            let section = params.section_at(x_m);
            let painted = row[section];
            let tilt = [hand.tilt[0].value, hand.tilt[1].value, hand.tilt[2].value];
            let q = quat_from_rotvec(tilt);
            let force_out = (force_n + hand.force_noise.value).max(0.0);
            push(
                &mut demo,
                [
                    x_m,
                    y_m + hand.lateral.value,
                    0.0,
                    q[0],
                    q[1],
                    q[2],
                    q[3],
                    force_out,
                    1.0,
                ],
                Label {
                    pass: pass_u8,
                    section: u8::try_from(section).expect("n_sections ≤ 254 (validated)"),
                    painted,
                    phase: Phase::Sanding,
                },
            )?;

            let (cruise_m_s, target_n) = if painted {
                (params.speed_painted_m_s, params.force_painted_n)
            } else {
                (params.speed_unpainted_m_s, params.force_unpainted_n)
            };
            let drift = (1.0 + hand.drift.value).clamp(0.5, 1.5);
            let brake_m_s = params.end_speed_m_s + (length_m - x_m) / params.brake_tau_s;
            let target_m_s = (cruise_m_s * hand.speed_factor * drift).min(brake_m_s);
            speed_m_s += (target_m_s - speed_m_s) * speed_gain;
            x_m += speed_m_s * dt_s;
            force_n += (target_n - force_n) * force_gain;
            hand.drift.step(rng);
            hand.force_noise.step(rng);
            hand.lateral.step(rng);
            hand.step_tilt(rng);
            if x_m >= length_m {
                break;
            }
        }

        if pass == N_PASSES {
            break;
        }

        // --- Transition: tool off, lift-off arc from the end of this pass to the start of the
        // next. The lateral wobble is frozen meanwhile, so the arc ends where the next pass
        // starts.
        let y_start_m = y_m + hand.lateral.value;
        let y_end_m = params.pass_y_m(pass + 1) + hand.lateral.value;
        let var = params.transition_duration_var;
        let duration_s = params.transition_duration_s * uniform(rng, 1.0 - var, 1.0 + var);
        let n_samples = ((duration_s / dt_s).round() as usize).max(2);
        let height_m = uniform(rng, params.lift_height_min_m, params.lift_height_max_m);
        let bulge_m = uniform(rng, -params.transition_bulge_m, params.transition_bulge_m);
        // Exponent of the lift timing: < 1 peaks early, > 1 late (apex at u = 0.5^(1/γ)).
        let lift_gamma = uniform(rng, 0.75f64.ln(), (1.0f64 / 0.75).ln()).exp();
        // Fractions of the transition spent lifting before / lowering after moving sideways.
        let lead = uniform(rng, 0.05, 0.25);
        let lag = uniform(rng, 0.05, 0.25);
        let extra_tilt = [
            uniform(rng, -params.transition_tilt_rad, params.transition_tilt_rad),
            uniform(rng, -params.transition_tilt_rad, params.transition_tilt_rad),
        ];
        let label = Label {
            pass: pass_u8,
            section: 0,
            painted: false,
            phase: Phase::Transition,
        };
        for i in 0..n_samples {
            let u = i as f64 / n_samples as f64;
            let s = min_jerk((u - lead) / (1.0 - lead - lag));
            let x = length_m * (1.0 - s);
            let y =
                y_start_m + (y_end_m - y_start_m) * s + bulge_m * (std::f64::consts::PI * s).sin();
            let z = height_m * (std::f64::consts::PI * u.powf(lift_gamma)).sin().powi(2);
            let bump = (std::f64::consts::PI * u).sin().powi(2);
            let q = quat_from_rotvec([
                hand.tilt[0].value + extra_tilt[0] * bump,
                hand.tilt[1].value + extra_tilt[1] * bump,
                hand.tilt[2].value,
            ]);
            push(
                &mut demo,
                [x, y, z, q[0], q[1], q[2], q[3], force_n.max(0.0), 0.0],
                label,
            )?;
            force_n -= force_n * force_gain;
            hand.step_tilt(rng);
        }
    }
    Ok(demo)
}

/// Draws `n_demos` workpieces and one demonstration on each, in the order
/// workpiece 0, demo 0, workpiece 1, demo 1, … from the same `rng`.
///
/// The committed fixtures are `demonstrations(&TaskParams::default(), N_FIXTURE_DEMOS,
/// &mut ChaCha8Rng::seed_from_u64(FIXTURE_SEED))`.
///
/// # Errors
/// As [`Workpiece::random`] and [`demonstrate`].
pub fn demonstrations(
    params: &TaskParams,
    n_demos: usize,
    rng: &mut impl Rng,
) -> Result<Vec<(Workpiece, TaskDemo)>> {
    params.validate()?;
    (0..n_demos)
        .map(|_| {
            let workpiece = Workpiece::random(params, rng)?;
            let demo = demonstrate(params, &workpiece, rng)?;
            Ok((workpiece, demo))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn quaternion_of_rotation_vector() {
        assert_eq!(quat_from_rotvec([0.0; 3]), [0.0, 0.0, 0.0, 1.0]);
        // 90° about x: (sin 45°, 0, 0, cos 45°).
        let q = quat_from_rotvec([std::f64::consts::FRAC_PI_2, 0.0, 0.0]);
        let h = std::f64::consts::FRAC_1_SQRT_2;
        for (a, b) in q.iter().zip([h, 0.0, 0.0, h]) {
            assert!((a - b).abs() < 1e-15);
        }
        let q = quat_from_rotvec([0.01, -0.02, 0.005]);
        assert!((q.iter().map(|v| v * v).sum::<f64>() - 1.0).abs() < 1e-15);
        assert!(q[3] > 0.0 && q[1] < 0.0);
    }

    #[test]
    fn min_jerk_is_a_smooth_step() {
        assert_eq!(min_jerk(-1.0), 0.0);
        assert_eq!(min_jerk(0.0), 0.0);
        assert_eq!(min_jerk(0.5), 0.5);
        assert_eq!(min_jerk(1.0), 1.0);
        assert_eq!(min_jerk(2.0), 1.0);
        // Zero slope at the ends: f(h) ≈ 10h³.
        assert!(min_jerk(1e-3) < 1.1e-8);
    }

    #[test]
    fn smooth_noise_has_its_stationary_std_and_bounded_rate() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let (std, tau_s, dt_s) = (2.0, 0.5, 0.01);
        let (mut sum2, mut max_step, n) = (0.0, 0.0f64, 200_000);
        let mut noise = SmoothNoise::new(std, tau_s, dt_s, &mut rng);
        for _ in 0..n {
            let before = noise.value;
            noise.step(&mut rng);
            sum2 += noise.value * noise.value;
            max_step = max_step.max((noise.value - before).abs());
        }
        let measured = (sum2 / f64::from(n)).sqrt();
        // 200 000 samples ≈ 2000 correlation times: a few % of sampling error.
        assert!((measured / std - 1.0).abs() < 0.1, "{measured}");
        // Rate ≈ std / tau per second, i.e. ≈ std·dt/tau per sample: far below white noise.
        assert!(max_step < 5.0 * std * dt_s / tau_s, "{max_step}");
    }

    #[test]
    fn sections_are_clamped_to_the_plate() {
        let p = TaskParams::default();
        assert_eq!(p.section_at(-0.1), 0);
        assert_eq!(p.section_at(0.0), 0);
        assert_eq!(p.section_at(0.1 + 1e-12), 1);
        assert_eq!(p.section_at(0.599), 5);
        assert_eq!(p.section_at(0.7), 5);
        assert_eq!(p.section_at(f64::NAN), 0);
        assert!((p.pass_y_m(1) - 0.05).abs() < 1e-15);
        assert!((p.pass_y_m(4) - 0.35).abs() < 1e-15);
    }

    #[test]
    fn two_sections_paint_one_at_random() {
        let p = TaskParams {
            n_sections: 2,
            ..TaskParams::default()
        };
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let mut first = 0;
        for _ in 0..100 {
            let w = Workpiece::random(&p, &mut rng).unwrap();
            for row in &w.painted[..3] {
                assert!(row[0] != row[1]);
                first += usize::from(row[0]);
            }
            assert_eq!(w.painted[3], [true, true]);
        }
        assert!((100..=200).contains(&first), "{first}");
    }
}
