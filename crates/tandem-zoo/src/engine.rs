//! The one generator behind every family: a task is a [`Script`] — channels, a sequence of
//! [`Segment`]s over task progress, what varies between demonstrations ([`Variation`]s and
//! [`Feature`]s) and where the operator is needed although the demonstrations agree
//! ([`Agreed`]) — and [`render`] turns a script into demonstrations with their true progress.
//!
//! # Progress and time
//!
//! Segment `k` covers the progress span `[P_k, P_{k+1})` with `P` the cumulative *nominal*
//! durations over the nominal total, so progress is the task's own clock, the same for every
//! demonstration. Demonstration `i` gives segment `k` the duration `d_ik`: the nominal one
//! times `1 ± dur_var` (independent per segment and demonstration: a pause of independent
//! length is a segment with a large `dur_var`), all rescaled so the demonstration's total is
//! the nominal total times `1 ± length_var` (stratified over the demonstrations, so the set
//! always spans the range). Inside a segment local time `τ ∈ [0, 1]` becomes local phase
//! `u = τ + a·sin(2πmτ)/(2πm)` with `|a| ≤ wobble < 1`: a monotone speed profile that speeds
//! up and slows down within the segment. Progress is then `P_k + (P_{k+1} − P_k)·u`,
//! strictly increasing in time: the ground-truth warp.
//!
//! # Values
//!
//! A channel's value is its mean path at `(k, u)` — the segment's [`Target`]s interpolated
//! from the value the previous segments left — plus the variations (an offset or a wave per
//! demonstration, under an envelope in progress that is 1 inside the variable span, ½ at its
//! ends and 0 a ramp beyond them), plus the features (spikes, search spirals), plus sensor
//! noise: white noise and a smooth tremor (first-order autoregressive, correlation time
//! `tremor_tau_s`). Binary channels carry no noise. A quaternion block is generated as a
//! rotation vector in the slots of `qx, qy, qz` and written as a unit quaternion with `qw > 0`.
//!
//! # Samples
//!
//! Rows are sampled at `rate_hz`: the first at 0 s, the last exactly at the end, the others
//! at `i·Δt` plus a jitter uniform in `±jitter·Δt` (`jitter ≤ 0.12`, inside the loader's 25 %
//! of a period around the even grid through the first and last times, docs/decisions.md,
//! "Timestamps: the mean period, jitter within 25 %"). Values are taken at the jittered time.
//! For half the seeds the stamps are the controller's clock: each demonstration's `t` starts
//! at its own offset of 1–60 min (whole milliseconds), as a log cut from a longer recording
//! does; for the others `t` starts at 0.

use std::f64::consts::TAU;
use std::fmt::Write as _;

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use crate::task::{NeedSpan, ZooTask};
use crate::{Error, Result};

/// How a channel's value is written and disturbed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Kind {
    /// Any real value.
    Real,
    /// An on/off signal written as `0` or `1`; no noise.
    Binary,
    /// A real value clipped at 0 after noise (a flow meter reads no negative flow).
    NonNeg,
}

/// One channel of a task.
#[derive(Clone, Debug)]
pub(crate) struct Channel {
    /// Column name in the CSV header.
    pub(crate) name: &'static str,
    /// Decimals written.
    pub(crate) decimals: usize,
    /// Kind.
    pub(crate) kind: Kind,
    /// Standard deviation of white sensor noise, channel units.
    pub(crate) white_sd: f64,
    /// Standard deviation of the smooth tremor, channel units.
    pub(crate) tremor_sd: f64,
    /// Correlation time of the tremor, seconds.
    pub(crate) tremor_tau_s: f64,
}

/// The columns of the pose block [`Channel::pose_then`] puts first: `x, y, z, qx, qy, qz, qw`.
pub(crate) mod pose {
    /// Column of `x` (m).
    pub(crate) const X: usize = 0;
    /// Column of `y` (m).
    pub(crate) const Y: usize = 1;
    /// Column of `z` (m).
    pub(crate) const Z: usize = 2;
    /// Column of the quaternion's `qx`.
    pub(crate) const QX: usize = 3;
    /// Column of the quaternion's `qy`.
    pub(crate) const QY: usize = 4;
    /// Column of the quaternion's `qz`.
    pub(crate) const QZ: usize = 5;
}

impl Channel {
    /// A pose as a recorder logs it, `x, y, z` (m, `pos_decimals` decimals) and the quaternion
    /// `qx, qy, qz` (6 decimals) with `qw` (noise-free, the generator normalizes), each with
    /// its `(white, tremor)` noise, followed by the family's own `rest` channels.
    pub(crate) fn pose_then<const K: usize>(
        pos_decimals: usize,
        (pos_white, pos_tremor): (f64, f64),
        (rot_white, rot_tremor): (f64, f64),
        rest: [Channel; K],
    ) -> Vec<Channel> {
        let pos = |name| Channel::real(name, pos_decimals, pos_white, pos_tremor);
        let rot = |name| Channel::real(name, 6, rot_white, rot_tremor);
        let mut out = vec![
            pos("x"),
            pos("y"),
            pos("z"),
            rot("qx"),
            rot("qy"),
            rot("qz"),
            Channel::real("qw", 6, 0.0, 0.0),
        ];
        out.extend(rest);
        out
    }

    /// A real channel.
    pub(crate) fn real(name: &'static str, decimals: usize, white_sd: f64, tremor_sd: f64) -> Self {
        Self {
            name,
            decimals,
            kind: Kind::Real,
            white_sd,
            tremor_sd,
            tremor_tau_s: 0.5,
        }
    }

    /// A non-negative channel (clipped at 0 after noise).
    pub(crate) fn non_neg(name: &'static str, decimals: usize, white_sd: f64) -> Self {
        Self {
            kind: Kind::NonNeg,
            ..Self::real(name, decimals, white_sd, 0.0)
        }
    }

    /// A binary channel.
    pub(crate) fn binary(name: &'static str) -> Self {
        Self {
            kind: Kind::Binary,
            ..Self::real(name, 0, 0.0, 0.0)
        }
    }
}

/// How a target is approached within its segment, as a function of local phase `u ∈ [0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Interp {
    /// Minimum-jerk: `10u³ − 15u⁴ + 6u⁵` (a point-to-point move, at rest at both ends).
    MinJerk,
    /// Constant speed along the segment (a bead, a stroke, an edge).
    Linear,
    /// The new value from local phase `at` on (a switch).
    Step(f64),
    /// A first-order lag, 63 % at `u = 0.12` (a force building up on contact).
    Ease,
}

impl Interp {
    /// The share `s(u) ∈ [0, 1]` of the way from the start value to the target.
    fn share(self, u: f64) -> f64 {
        match self {
            Interp::MinJerk => u * u * u * (10.0 - 15.0 * u + 6.0 * u * u),
            Interp::Linear => u,
            Interp::Step(at) => {
                if u >= at {
                    1.0
                } else {
                    0.0
                }
            }
            Interp::Ease => (1.0 - (-u / 0.12).exp()) / (1.0 - (-1.0 / 0.12_f64).exp()),
        }
    }
}

/// The value channel `ch` reaches at the end of a segment, and how.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Target {
    /// Channel index.
    pub(crate) ch: usize,
    /// Value at the segment's end (rotation-vector component for a quaternion slot).
    pub(crate) value: f64,
    /// How it gets there.
    pub(crate) interp: Interp,
}

/// Shorthand for a [`Target`].
pub(crate) fn to(ch: usize, value: f64, interp: Interp) -> Target {
    Target { ch, value, interp }
}

/// One stretch of the task.
#[derive(Clone, Debug)]
pub(crate) struct Segment {
    /// What the segment is (documentation, error messages).
    pub(crate) name: &'static str,
    /// Nominal duration, seconds.
    pub(crate) nominal_s: f64,
    /// Independent duration spread per demonstration, fraction (`d = nominal·(1 ± dur_var)`).
    pub(crate) dur_var: f64,
    /// Largest speed wobble `a` inside the segment (`< 1`).
    pub(crate) wobble: f64,
    /// Channels that change in this segment.
    pub(crate) targets: Vec<Target>,
}

/// Shorthand for a [`Segment`].
pub(crate) fn seg(
    name: &'static str,
    nominal_s: f64,
    dur_var: f64,
    wobble: f64,
    targets: Vec<Target>,
) -> Segment {
    Segment {
        name,
        nominal_s,
        dur_var,
        wobble,
        targets,
    }
}

/// The form of a variation along its span.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Shape {
    /// A constant offset per demonstration and channel (a part placed elsewhere).
    Offset,
    /// `0.4·c + 0.6·sin(2π·cycles·v + φ)` with `v` the position in the span and `c`, `φ` per
    /// demonstration and channel (a cable lying differently, a seam that wanders).
    Wavy {
        /// Periods of the wave over the span.
        cycles: f64,
    },
}

/// Channels that differ between demonstrations over segments `first..=last`: there the
/// operator is needed with probability `need_p` (the demonstrations say the task varies).
#[derive(Clone, Debug)]
pub(crate) struct Variation {
    /// First segment of the span.
    pub(crate) first: usize,
    /// Last segment of the span (inclusive).
    pub(crate) last: usize,
    /// Half-width of the envelope's ramp at each end of the span, seconds of nominal time.
    pub(crate) ramp_s: f64,
    /// p(need) over the span.
    pub(crate) need_p: f64,
    /// `(channel, amplitude)`: the largest deviation, channel units.
    pub(crate) amps: Vec<(usize, f64)>,
    /// Its form.
    pub(crate) shape: Shape,
}

/// A local event of one segment that differs between demonstrations; the operator is needed
/// with probability `need_p` over the part of the segment where it can happen.
#[derive(Clone, Debug)]
pub(crate) struct Feature {
    /// The segment.
    pub(crate) seg: usize,
    /// p(need) where the event can happen.
    pub(crate) need_p: f64,
    /// What happens.
    pub(crate) kind: FeatureKind,
}

/// The events of [`Feature`].
#[derive(Clone, Copy, Debug)]
pub(crate) enum FeatureKind {
    /// A raised-cosine spike added to `ch`: peak `peak ± peak_var` and centre in local phase
    /// `at.0..at.1`, both stratified over the demonstrations; half-width `width` (local phase).
    Spike {
        /// Channel.
        ch: usize,
        /// Mean peak, channel units.
        peak: f64,
        /// Spread of the peak, channel units.
        peak_var: f64,
        /// Range of the centre, local phase.
        at: (f64, f64),
        /// Half-width, local phase.
        width: f64,
    },
    /// An Archimedean search spiral added to channels `cx, cy` (`turns` turns, radius growing
    /// linearly to `r_max·[0.5, 1]`, starting angle in `[0, 2π)`, both stratified), with a
    /// friction force of magnitude `friction` against the motion on channels `fx, fy`.
    Spiral {
        /// Channel of the first coordinate.
        cx: usize,
        /// Channel of the second coordinate.
        cy: usize,
        /// Largest final radius, channel units.
        r_max: f64,
        /// Turns over the segment.
        turns: f64,
        /// Force channels and friction magnitude (N).
        friction: Option<(usize, usize, f64)>,
    },
}

impl FeatureKind {
    /// The local phase over which the event can differ between demonstrations: a spike's
    /// possible centres widened by its half-width, the whole segment for a spiral (its
    /// direction, so its friction force, differs throughout).
    fn span_u(self) -> (f64, f64) {
        match self {
            FeatureKind::Spike { at, width, .. } => {
                ((at.0 - width).max(0.0), (at.1 + width).min(1.0))
            }
            FeatureKind::Spiral { .. } => (0.0, 1.0),
        }
    }

    /// The local phase over which the demonstrations drawn (`draws`, one per demonstration)
    /// actually differ: for a spike, the union of every demonstration's support (its centre
    /// ± the half-width; outside every support no demonstration has the spike, so they all
    /// agree there although the operator can be needed); for a spiral, the whole segment as in
    /// [`FeatureKind::span_u`]. Sorted, merged.
    fn varies_u(self, draws: &[FeatureDraw]) -> Vec<(f64, f64)> {
        match self {
            FeatureKind::Spike { at, width, .. } => {
                let mut supports: Vec<(f64, f64)> = draws
                    .iter()
                    .map(|&(_, d1)| {
                        let centre = at.0 + (at.1 - at.0) * d1;
                        ((centre - width).max(0.0), (centre + width).min(1.0))
                    })
                    .collect();
                supports.sort_by(|a, b| a.0.total_cmp(&b.0));
                merge_spans(supports)
            }
            FeatureKind::Spiral { .. } => vec![self.span_u()],
        }
    }
}

/// Sorted spans `(a, b)` merged where they overlap or touch.
fn merge_spans(sorted: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    let mut merged: Vec<(f64, f64)> = Vec::new();
    for (a, b) in sorted {
        match merged.last_mut() {
            Some(last) if a <= last.1 => last.1 = last.1.max(b),
            _ => merged.push((a, b)),
        }
    }
    merged
}

/// The operator is needed with probability `p` over local phase `from_u..to_u` of segment
/// `seg`, although every demonstration does the same there (unlearnable from
/// demonstrations).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Agreed {
    /// The segment.
    pub(crate) seg: usize,
    /// Start, local phase.
    pub(crate) from_u: f64,
    /// End, local phase.
    pub(crate) to_u: f64,
    /// p(need).
    pub(crate) p: f64,
}

/// A whole task, ready to render.
#[derive(Clone, Debug)]
pub(crate) struct Script {
    /// The family's name.
    pub(crate) family: &'static str,
    /// The seed it was drawn with.
    pub(crate) seed: u64,
    /// Channels in column order (after `t`).
    pub(crate) channels: Vec<Channel>,
    /// Index of `qx` when the channels hold a quaternion block `qx, qy, qz, qw`.
    pub(crate) quat: Option<usize>,
    /// Value of every channel at the start (rotation vector in the quaternion's first three
    /// slots).
    pub(crate) start: Vec<f64>,
    /// The segments in order.
    pub(crate) segments: Vec<Segment>,
    /// Variable sections.
    pub(crate) variations: Vec<Variation>,
    /// Local events that vary.
    pub(crate) features: Vec<Feature>,
    /// Need where the demonstrations agree.
    pub(crate) agreed: Vec<Agreed>,
    /// Hold rules.
    pub(crate) holds: Vec<String>,
    /// Number of demonstrations.
    pub(crate) n_demos: usize,
    /// Sample rate, Hz.
    pub(crate) rate_hz: f64,
    /// Time-stamp jitter, fraction of a period.
    pub(crate) jitter: f64,
    /// Total length spread, fraction (`T_i = T_nominal·(1 ± length_var)`).
    pub(crate) length_var: f64,
    /// How unsteady the demonstrator's pace is: every segment's `wobble` is multiplied by it
    /// (0.5: a steady hand, ±15 % speed within a free move; 1: ±30 %).
    pub(crate) wobble_scale: f64,
}

/// Draws the family's per-seed choices: a ChaCha8 stream from the seed and the family's name
/// (FNV-1a), so families with the same seed are independent.
pub(crate) fn rng_for(family: &str, seed: u64) -> ChaCha8Rng {
    use rand::SeedableRng;
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in family.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    ChaCha8Rng::seed_from_u64(seed ^ h)
}

/// Uniform in `[lo, hi)`.
pub(crate) fn uniform(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * rng.random::<f64>()
}

/// One of `choices`, uniformly.
pub(crate) fn pick<T: Copy>(rng: &mut ChaCha8Rng, choices: &[T]) -> T {
    choices[rng.random_range(0..choices.len())]
}

/// A standard normal draw (Box–Muller).
fn normal(rng: &mut ChaCha8Rng) -> f64 {
    let u1 = 1.0 - rng.random::<f64>(); // (0, 1]
    let u2 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (TAU * u2).cos()
}

/// `n` values in `[0, 1)`, one in each stratum `[j/n, (j+1)/n)`, in random order: a set of
/// demonstrations always spans the range (no seed where every demonstration happens to agree).
fn stratified(rng: &mut ChaCha8Rng, n: usize) -> Vec<f64> {
    let mut order: Vec<usize> = (0..n).collect();
    for i in (1..n).rev() {
        order.swap(i, rng.random_range(0..=i));
    }
    order
        .into_iter()
        .map(|j| (j as f64 + rng.random::<f64>()) / n as f64)
        .collect()
}

/// `3x² − 2x³` on `[0, 1]`, clamped outside.
fn smoothstep(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// Progress boundaries `P_0 = 0 … P_K = 1` of the segments.
pub(crate) fn boundaries(segments: &[Segment]) -> Vec<f64> {
    let total: f64 = segments.iter().map(|s| s.nominal_s).sum();
    let mut p = Vec::with_capacity(segments.len() + 1);
    let mut acc = 0.0;
    p.push(0.0);
    for s in segments {
        acc += s.nominal_s;
        p.push(acc / total);
    }
    // Exactly 1 at the end whatever the rounding of the sum.
    if let Some(last) = p.last_mut() {
        *last = 1.0;
    }
    p
}

/// Envelope of a variable span `[p0, p1]` with ramp half-width `w`: 1 inside (from `w` in),
/// ½ at the ends, 0 beyond `w` outside; an end at 0 or 1 is not ramped.
fn envelope(p: f64, p0: f64, p1: f64, w: f64) -> f64 {
    let rise = if p0 <= 0.0 {
        1.0
    } else {
        smoothstep((p - (p0 - w)) / (2.0 * w))
    };
    let fall = if p1 >= 1.0 {
        1.0
    } else {
        1.0 - smoothstep((p - (p1 - w)) / (2.0 * w))
    };
    rise * fall
}

/// Per-demonstration draws of one variation: per amplitude, `(c, φ)`.
type VariationDraw = Vec<(f64, f64)>;

/// Per-demonstration draws of one feature: two stratified values in `[0, 1)`.
type FeatureDraw = (f64, f64);

impl Script {
    fn bad(&self, why: String) -> Error {
        Error::BadFamily {
            family: self.family,
            why,
        }
    }

    /// Checks the script's own consistency (indices, ranges), so a family's mistake is an
    /// error naming it rather than a panic or a silent wrong truth.
    fn check(&self) -> Result<()> {
        let m = self.channels.len();
        let k = self.segments.len();
        if self.start.len() != m {
            return Err(self.bad(format!(
                "{} start values for {m} channels",
                self.start.len()
            )));
        }
        if k == 0 || !(3..=12).contains(&self.n_demos) {
            return Err(self.bad(format!("{k} segments, {} demonstrations", self.n_demos)));
        }
        if !(1.0..=10_000.0).contains(&self.rate_hz) || !(0.0..=0.12).contains(&self.jitter) {
            return Err(self.bad(format!("rate {} Hz, jitter {}", self.rate_hz, self.jitter)));
        }
        if !(0.0..0.5).contains(&self.length_var) || !(0.0..=1.0).contains(&self.wobble_scale) {
            return Err(self.bad(format!(
                "length_var {}, wobble_scale {}",
                self.length_var, self.wobble_scale
            )));
        }
        if let Some(q) = self.quat
            && (q + 4 > m
                || ["qx", "qy", "qz", "qw"]
                    .iter()
                    .enumerate()
                    .any(|(j, n)| self.channels[q + j].name != *n))
        {
            return Err(self.bad("the quaternion block must be qx, qy, qz, qw".into()));
        }
        for s in &self.segments {
            let ok = s.nominal_s > 0.0
                && (0.0..1.0).contains(&s.dur_var)
                && (0.0..0.9).contains(&s.wobble)
                && s.targets.iter().all(|t| t.ch < m && t.value.is_finite());
            if !ok {
                return Err(self.bad(format!("segment `{}` is malformed", s.name)));
            }
        }
        for v in &self.variations {
            let ok = v.first <= v.last
                && v.last < k
                && v.ramp_s > 0.0
                && v.need_p > 0.0
                && v.need_p <= 1.0
                && v.amps.iter().all(|&(c, a)| c < m && a > 0.0);
            if !ok {
                return Err(self.bad(format!(
                    "variation over segments {}..={} is malformed",
                    v.first, v.last
                )));
            }
        }
        for f in &self.features {
            let chans_ok = match f.kind {
                FeatureKind::Spike { ch, width, at, .. } => {
                    ch < m && width > 0.0 && 0.0 <= at.0 && at.0 <= at.1 && at.1 <= 1.0
                }
                FeatureKind::Spiral {
                    cx, cy, friction, ..
                } => cx < m && cy < m && friction.is_none_or(|(a, b, _)| a < m && b < m),
            };
            if !(f.seg < k && f.need_p > 0.0 && f.need_p <= 1.0 && chans_ok) {
                return Err(self.bad(format!("feature in segment {} is malformed", f.seg)));
            }
        }
        for a in &self.agreed {
            let ok = a.seg < k
                && 0.0 <= a.from_u
                && a.from_u < a.to_u
                && a.to_u <= 1.0
                && a.p > 0.0
                && a.p <= 1.0;
            if !ok {
                return Err(self.bad(format!("agreed need in segment {} is malformed", a.seg)));
            }
        }
        Ok(())
    }

    /// Value of every channel at the start of every segment (and at the end, index `K`).
    fn segment_starts(&self) -> Vec<Vec<f64>> {
        let mut starts = vec![self.start.clone()];
        for s in &self.segments {
            let mut v = starts.last().expect("starts holds the start").clone();
            for t in &s.targets {
                v[t.ch] = t.value;
            }
            starts.push(v);
        }
        starts
    }

    /// Need spans (disjoint, sorted, merged) and variable spans (merged): a feature is needed
    /// over [`FeatureKind::span_u`] (wherever its event can happen in an execution) and
    /// variable only where the demonstrations drawn (`feat_draws`, per feature and
    /// demonstration) differ ([`FeatureKind::varies_u`]).
    fn truth(
        &self,
        p: &[f64],
        feat_draws: &[Vec<FeatureDraw>],
    ) -> (Vec<NeedSpan>, Vec<(f64, f64)>) {
        // (from, to, p, learnable) contributions.
        let mut parts: Vec<(f64, f64, f64, bool)> = Vec::new();
        let mut variable: Vec<(f64, f64)> = Vec::new();
        for v in &self.variations {
            parts.push((p[v.first], p[v.last + 1], v.need_p, true));
            variable.push((p[v.first], p[v.last + 1]));
        }
        for (f, draws) in self.features.iter().zip(feat_draws) {
            let (u0, u1) = f.kind.span_u();
            let w = p[f.seg + 1] - p[f.seg];
            let at = |u: f64| p[f.seg] + w * u;
            parts.push((at(u0), at(u1), f.need_p, true));
            variable.extend(
                f.kind
                    .varies_u(draws)
                    .into_iter()
                    .map(|(a, b)| (at(a), at(b))),
            );
        }
        for a in &self.agreed {
            let w = p[a.seg + 1] - p[a.seg];
            parts.push((p[a.seg] + w * a.from_u, p[a.seg] + w * a.to_u, a.p, false));
        }
        let mut cuts: Vec<f64> = parts.iter().flat_map(|&(a, b, _, _)| [a, b]).collect();
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        let mut need: Vec<NeedSpan> = Vec::new();
        for w in cuts.windows(2) {
            let mid = 0.5 * (w[0] + w[1]);
            let covering = parts.iter().filter(|&&(a, b, _, _)| a <= mid && mid < b);
            let (mut pmax, mut learnable, mut any) = (0.0_f64, false, false);
            for &(_, _, pp, l) in covering {
                pmax = pmax.max(pp);
                learnable |= l;
                any = true;
            }
            if !any {
                continue;
            }
            match need.last_mut() {
                Some(last) if last.to == w[0] && last.p == pmax && last.learnable == learnable => {
                    last.to = w[1];
                }
                _ => need.push(NeedSpan {
                    from: w[0],
                    to: w[1],
                    p: pmax,
                    learnable,
                }),
            }
        }
        variable.sort_by(|a, b| a.0.total_cmp(&b.0));
        (need, merge_spans(variable))
    }
}

/// Renders `script`: its demonstrations as CSV text, their true progress, and the truth.
///
/// # Errors
/// [`Error::BadFamily`] when the script is inconsistent.
pub(crate) fn render(script: &Script, rng: &mut ChaCha8Rng) -> Result<ZooTask> {
    script.check()?;
    let n = script.n_demos;
    let m = script.channels.len();
    let p_bounds = boundaries(&script.segments);
    let starts = script.segment_starts();
    let nominal_total: f64 = script.segments.iter().map(|s| s.nominal_s).sum();
    let dt = 1.0 / script.rate_hz;

    // Per-set stratified draws, in a fixed order.
    let lengths = stratified(rng, n);
    let var_draws: Vec<Vec<VariationDraw>> = script
        .variations
        .iter()
        .map(|v| {
            let cols: Vec<(Vec<f64>, Vec<f64>)> = v
                .amps
                .iter()
                .map(|_| (stratified(rng, n), stratified(rng, n)))
                .collect();
            (0..n)
                .map(|i| {
                    cols.iter()
                        .map(|(c, f)| (2.0 * c[i] - 1.0, TAU * f[i]))
                        .collect()
                })
                .collect()
        })
        .collect();
    let feat_draws: Vec<Vec<FeatureDraw>> = script
        .features
        .iter()
        .map(|_| {
            let (a, b) = (stratified(rng, n), stratified(rng, n));
            (0..n).map(|i| (a[i], b[i])).collect()
        })
        .collect();

    let clock_offsets_s: Vec<f64> = if rng.random::<bool>() {
        (0..n)
            .map(|_| (uniform(rng, 60.0, 3600.0) * 1000.0).round() / 1000.0)
            .collect()
    } else {
        vec![0.0; n]
    };

    let header = {
        let mut h = String::from("t");
        for c in &script.channels {
            h.push(',');
            h.push_str(c.name);
        }
        h
    };

    let mut files = Vec::with_capacity(n);
    let mut progress = Vec::with_capacity(n);
    for i in 0..n {
        // Segment durations: independent spreads, rescaled to the drawn total, then to a whole
        // number of periods.
        let total_s = nominal_total * (1.0 + script.length_var * (2.0 * lengths[i] - 1.0));
        let mut dur: Vec<f64> = script
            .segments
            .iter()
            .map(|s| s.nominal_s * (1.0 + s.dur_var * uniform(rng, -1.0, 1.0)))
            .collect();
        let n_rows = (total_s / dt).round() as usize + 1;
        let end_s = (n_rows - 1) as f64 * dt;
        let sum: f64 = dur.iter().sum();
        for d in &mut dur {
            *d *= end_s / sum;
        }
        let wobble: Vec<(f64, f64)> = script
            .segments
            .iter()
            .map(|s| {
                let a = s.wobble * script.wobble_scale * uniform(rng, -1.0, 1.0);
                let m = if rng.random::<bool>() { 1.0 } else { 2.0 };
                (a, m)
            })
            .collect();
        let mut cum = Vec::with_capacity(dur.len() + 1);
        cum.push(0.0);
        for d in &dur {
            cum.push(cum.last().copied().unwrap_or(0.0) + d);
        }

        let mut tremor: Vec<f64> = script
            .channels
            .iter()
            .map(|c| c.tremor_sd * normal(rng))
            .collect();
        let rho: Vec<f64> = script
            .channels
            .iter()
            .map(|c| (-dt / c.tremor_tau_s).exp())
            .collect();

        let mut text = String::with_capacity(n_rows * (10 + 10 * m));
        text.push_str(&header);
        text.push('\n');
        let mut prog = Vec::with_capacity(n_rows);
        let mut values = vec![0.0; m];
        let mut k = 0;
        for r in 0..n_rows {
            let t = if r == 0 {
                0.0
            } else if r == n_rows - 1 {
                end_s
            } else {
                r as f64 * dt + script.jitter * dt * uniform(rng, -1.0, 1.0)
            };
            while k + 1 < dur.len() && t >= cum[k + 1] {
                k += 1;
            }
            let tau = ((t - cum[k]) / dur[k]).clamp(0.0, 1.0);
            let (a, mm) = wobble[k];
            let u = (tau + a * (TAU * mm * tau).sin() / (TAU * mm)).clamp(0.0, 1.0);
            let p = if r == n_rows - 1 {
                1.0
            } else {
                p_bounds[k] + (p_bounds[k + 1] - p_bounds[k]) * u
            };
            prog.push(p);

            // Mean path.
            values.copy_from_slice(&starts[k]);
            for tg in &script.segments[k].targets {
                let from = starts[k][tg.ch];
                values[tg.ch] = from + (tg.value - from) * tg.interp.share(u);
            }
            // Variable sections.
            for (v, draws) in script.variations.iter().zip(&var_draws) {
                let (p0, p1) = (p_bounds[v.first], p_bounds[v.last + 1]);
                let w = (v.ramp_s / nominal_total).min(0.25 * (p1 - p0));
                let env = envelope(p, p0, p1, w);
                if env == 0.0 {
                    continue;
                }
                let pos = ((p - p0) / (p1 - p0)).clamp(0.0, 1.0);
                for (&(ch, amp), &(c, phi)) in v.amps.iter().zip(&draws[i]) {
                    let shape = match v.shape {
                        Shape::Offset => c,
                        Shape::Wavy { cycles } => 0.4 * c + 0.6 * (TAU * cycles * pos + phi).sin(),
                    };
                    values[ch] += amp * env * shape;
                }
            }
            // Local events.
            for (f, draws) in script.features.iter().zip(&feat_draws) {
                if f.seg != k {
                    continue;
                }
                let (d0, d1) = draws[i];
                match f.kind {
                    FeatureKind::Spike {
                        ch,
                        peak,
                        peak_var,
                        at,
                        width,
                    } => {
                        let centre = at.0 + (at.1 - at.0) * d1;
                        let x = (u - centre) / width;
                        if x.abs() < 1.0 {
                            let height = peak + peak_var * (2.0 * d0 - 1.0);
                            values[ch] += height * 0.5 * (1.0 + (std::f64::consts::PI * x).cos());
                        }
                    }
                    FeatureKind::Spiral {
                        cx,
                        cy,
                        r_max,
                        turns,
                        friction,
                    } => {
                        let r_end = r_max * (0.5 + 0.5 * d0);
                        let phi0 = TAU * d1;
                        let ang = phi0 + TAU * turns * u;
                        // The spiral closes onto the hole: out and back, radius r_end·sin(πu).
                        let rad = r_end * (std::f64::consts::PI * u).sin();
                        values[cx] += rad * ang.cos();
                        values[cy] += rad * ang.sin();
                        if let Some((fx, fy, mag)) = friction {
                            let drad =
                                r_end * std::f64::consts::PI * (std::f64::consts::PI * u).cos();
                            let dang = TAU * turns;
                            let vx = drad * ang.cos() - rad * dang * ang.sin();
                            let vy = drad * ang.sin() + rad * dang * ang.cos();
                            let speed = vx.hypot(vy);
                            if speed > 0.0 {
                                values[fx] -= mag * vx / speed;
                                values[fy] -= mag * vy / speed;
                            }
                        }
                    }
                }
            }
            // Noise.
            for (j, c) in script.channels.iter().enumerate() {
                if c.kind == Kind::Binary {
                    continue;
                }
                if c.tremor_sd > 0.0 {
                    tremor[j] = rho[j] * tremor[j]
                        + (1.0 - rho[j] * rho[j]).sqrt() * c.tremor_sd * normal(rng);
                    values[j] += tremor[j];
                }
                if c.white_sd > 0.0 {
                    values[j] += c.white_sd * normal(rng);
                }
            }

            write_row(&mut text, clock_offsets_s[i] + t, &values, script);
        }
        files.push((format!("demo_{i}.csv"), text));
        progress.push(prog);
    }

    let (need, variable) = script.truth(&p_bounds, &feat_draws);
    Ok(ZooTask {
        family: script.family,
        seed: script.seed,
        rate_hz: script.rate_hz,
        files,
        progress,
        need,
        holds: script.holds.clone(),
        variable,
    })
}

/// Appends one CSV row: the stamp `t` (s) with 6 decimals (microseconds), then every channel.
fn write_row(text: &mut String, t: f64, values: &[f64], script: &Script) {
    let _ = write!(text, "{t:.6}");
    let quat = script.quat.map(|q| {
        let (rx, ry, rz) = (values[q], values[q + 1], values[q + 2]);
        let angle = (rx * rx + ry * ry + rz * rz).sqrt();
        let (s, c) = (0.5 * angle).sin_cos();
        let k = if angle > 0.0 { s / angle } else { 0.5 };
        (q, [k * rx, k * ry, k * rz, c])
    });
    for (j, c) in script.channels.iter().enumerate() {
        let v = match quat {
            Some((q, qv)) if (q..q + 4).contains(&j) => qv[j - q],
            _ => values[j],
        };
        match c.kind {
            Kind::Binary => {
                text.push_str(if v >= 0.5 { ",1" } else { ",0" });
            }
            Kind::NonNeg => {
                let _ = write!(text, ",{:.*}", c.decimals, v.max(0.0));
            }
            Kind::Real => {
                let _ = write!(text, ",{:.*}", c.decimals, v);
            }
        }
    }
    text.push('\n');
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolations_run_from_0_to_1() {
        for i in [
            Interp::MinJerk,
            Interp::Linear,
            Interp::Step(0.3),
            Interp::Ease,
        ] {
            assert!(
                i.share(0.0).abs() < 1e-12 || i == Interp::Step(0.0),
                "{i:?}"
            );
            assert!((i.share(1.0) - 1.0).abs() < 1e-12, "{i:?}");
        }
        // Minimum jerk is symmetric: half way at half time.
        assert!((Interp::MinJerk.share(0.5) - 0.5).abs() < 1e-12);
        assert_eq!(Interp::Step(0.3).share(0.29), 0.0);
        assert_eq!(Interp::Step(0.3).share(0.3), 1.0);
    }

    #[test]
    fn envelope_is_half_at_the_span_ends() {
        let (p0, p1, w) = (0.2, 0.5, 0.02);
        assert!((envelope(p0, p0, p1, w) - 0.5).abs() < 1e-12);
        assert!((envelope(p1, p0, p1, w) - 0.5).abs() < 1e-12);
        assert_eq!(envelope(0.35, p0, p1, w), 1.0);
        assert_eq!(envelope(p0 - w, p0, p1, w), 0.0);
        assert_eq!(envelope(p1 + w, p0, p1, w), 0.0);
        // A span at the task's start is not ramped there.
        assert_eq!(envelope(0.0, 0.0, 0.3, w), 1.0);
    }

    #[test]
    fn stratified_draws_cover_every_stratum() {
        let mut rng = rng_for("test", 1);
        let mut v = stratified(&mut rng, 5);
        v.sort_by(f64::total_cmp);
        for (j, x) in v.iter().enumerate() {
            assert!((j as f64 / 5.0..(j + 1) as f64 / 5.0).contains(x), "{v:?}");
        }
    }

    #[test]
    fn a_spike_varies_only_around_the_spikes_drawn() {
        let spike = FeatureKind::Spike {
            ch: 0,
            peak: 1.0,
            peak_var: 0.0,
            at: (0.1, 0.9),
            width: 0.1,
        };
        // Its need covers every centre it can have, widened by its half-width.
        assert_eq!(spike.span_u(), (0.0, 1.0));
        // Centres 0.1 + 0.8·d1 = 0.2, 0.3 (overlapping supports) and 0.7: two spans, and
        // 0.4..0.6 (no spike there in any demonstration) is not variable.
        let v = spike.varies_u(&[(0.0, 0.125), (0.0, 0.75), (0.0, 0.25)]);
        assert_eq!(v.len(), 2, "{v:?}");
        for ((a, b), (x, y)) in v.iter().zip([(0.1, 0.4), (0.6, 0.8)]) {
            assert!((a - x).abs() < 1e-12 && (b - y).abs() < 1e-12, "{v:?}");
        }
        // Clipped to the segment.
        let v = spike.varies_u(&[(0.0, 0.0)]);
        assert!(v.len() == 1 && v[0].0 == 0.0 && (v[0].1 - 0.2).abs() < 1e-12);
        // A spiral's direction differs throughout: the whole segment.
        let spiral = FeatureKind::Spiral {
            cx: 0,
            cy: 1,
            r_max: 0.01,
            turns: 2.0,
            friction: None,
        };
        assert_eq!(spiral.varies_u(&[(0.3, 0.6)]), [(0.0, 1.0)]);
    }

    #[test]
    fn boundaries_are_cumulative_nominal_shares() {
        let segs = vec![
            seg("a", 1.0, 0.0, 0.0, vec![]),
            seg("b", 3.0, 0.0, 0.0, vec![]),
        ];
        assert_eq!(boundaries(&segs), [0.0, 0.25, 1.0]);
    }
}
