//! [`FitParams`]: the parameters of a fit, [`Reference`]: which demonstration's time
//! axis the model lives on, and [`RateTerm`]: how the demonstrations' speeds enter `σ²_D`.

use serde::{Deserialize, Serialize};

use crate::demo::ChannelSchema;
use crate::{Error, Result};

/// Which demonstration is the *reference*: the model's time axis is its sample index
/// (`n_ref = T_ref`), every other demonstration is aligned to it (GDTW, Eq. 2–3), and every
/// per-time array (mean, `σ²_D`, gradient bounds, confidence, schedule) is read on it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Reference {
    /// The first demonstration given (the model then depends on which file the user names
    /// first, by 5.8 pp of high confidence on the task zoo's selection seeds,
    /// docs/decisions.md, "Fit defaults on the task zoo").
    First,
    /// The medoid (default): every demonstration is tried as the reference (all the others
    /// aligned to it with the weights it would have as the reference, and the statistics
    /// fitted), and the one whose model has the least median `σ²_D` (Eq. 6) over its
    /// reference samples wins: the time axis on which the demonstrations agree best at a
    /// typical instant. Costs `n_demos` alignment passes instead of one. Ties go to the
    /// demonstration first in a fixed order of their content, and the others enter the
    /// statistics in that order, so the fitted model is bit-identical for any order in which
    /// the demonstrations are given (docs/decisions.md, "Fit defaults on the task zoo"; the
    /// default since "The medoid reference by default: labels follow the reference").
    #[default]
    Medoid,
}

impl std::fmt::Display for Reference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Reference::First => "first",
            Reference::Medoid => "medoid",
        })
    }
}

/// How the rate coordinate (the warp gradient `ψ̇`, demo samples per reference sample)
/// enters `σ²_D` (Eq. 6). Spelled the same in a parameter file (`[fit] rate_term`), on the
/// command line (`tandem fit --rate-term`) and in Python (`rate_term=`): `absolute`,
/// `relative` (the default widths), or `relative:opening=13,window=49` (either width may be
/// left out and keeps its default). A fitted model keeps the form it was fitted with
/// ([`TaskModel::rate_term`](crate::TaskModel::rate_term)), also through a state file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RateTerm {
    /// `var_n(ψ̇) / r_rate²` per reference sample: the term of the paper's Eq. 6 and of the
    /// models fitted before the relative term (docs/decisions.md, "Fit defaults on the task
    /// zoo").
    Absolute,
    /// Relative speed differences: at reference sample `n` the variance of the warp gradients
    /// over `(r_rate · ψ̄̇(n)/ψ̄̇₀)²` (`ψ̄̇₀` the mean pace over the reference), so a 10 %
    /// speed difference weighs the same wherever the reference was fast or slow; opened
    /// (running minimum, then running maximum) over `opening` reference samples. With
    /// `window > 0`, the larger of that and the *duration term*: the same relative variance
    /// of the time each demonstration spent on the `window` reference samples centred on `n`
    /// (`ψ_i(n + h) − ψ_i(n − h)`, `h = window/2`), which sees a stretch whose duration varies
    /// across demonstrations wherever in it the alignment placed the extra time
    /// (docs/decisions.md, "Timing-only variable sections: the duration term").
    Relative {
        /// Width of the opening, reference samples, odd ≥ 1 (1: no opening). Default 13
        /// ([`RateTerm::DEFAULT_OPENING`]).
        opening: usize,
        /// Width of the duration window, reference samples, 0 (no duration term) or odd
        /// ≥ 3. Default [`RateTerm::DEFAULT_WINDOW`].
        window: usize,
    },
}

impl RateTerm {
    /// The opening's default width, reference samples: three node spacings of the
    /// alignment's default grid ([`tandem_warp::DEFAULT_NODE_SPACING`]) and one, the stretch
    /// over which two warps may place one change of speed at different nodes.
    pub const DEFAULT_OPENING: usize = 3 * tandem_warp::DEFAULT_NODE_SPACING + 1;
    /// The duration window's default width, reference samples: 97 (24 node spacings of the
    /// alignment's default grid and one), chosen on the task zoo's selection seeds among 25, 49,
    /// 97 and 193 (docs/decisions.md, "Timing-only variable sections: the duration term").
    pub const DEFAULT_WINDOW: usize = 97;

    /// The relative form with the default widths.
    pub const DEFAULT: RateTerm = RateTerm::Relative {
        opening: Self::DEFAULT_OPENING,
        window: Self::DEFAULT_WINDOW,
    };

    /// The relative form of the models saved before the duration term existed (a state
    /// file's model whose rate term carries no duration window).
    pub const RELATIVE_WITHOUT_WINDOW: RateTerm = RateTerm::Relative {
        opening: Self::DEFAULT_OPENING,
        window: 0,
    };

    /// Checks the widths.
    ///
    /// # Errors
    /// [`Error::BadParam`] naming `rate_term` and the width.
    pub fn validate(&self) -> Result<()> {
        if let RateTerm::Relative { opening, window } = *self {
            if opening == 0 || opening % 2 == 0 {
                return Err(Error::BadParam {
                    name: "rate_term",
                    why: format!("the opening must be an odd number of samples ≥ 1, got {opening}"),
                });
            }
            if window != 0 && (window < 3 || window % 2 == 0) {
                return Err(Error::BadParam {
                    name: "rate_term",
                    why: format!(
                        "the duration window must be 0 (none) or an odd number of samples ≥ 3, \
                         got {window}"
                    ),
                });
            }
        }
        Ok(())
    }
}

impl Default for RateTerm {
    fn default() -> Self {
        Self::DEFAULT
    }
}

impl std::fmt::Display for RateTerm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RateTerm::Absolute => f.write_str("absolute"),
            RateTerm::Relative { opening, window } => {
                write!(f, "relative:opening={opening},window={window}")
            }
        }
    }
}

impl std::str::FromStr for RateTerm {
    type Err = Error;

    /// Parses `absolute`, `relative` or `relative:opening=N,window=M` (either width may be
    /// left out); the widths are checked ([`RateTerm::validate`]).
    fn from_str(s: &str) -> Result<Self> {
        let bad = |why: String| Error::BadParam {
            name: "rate_term",
            why: format!(
                "{why}; the choices are `absolute`, `relative` or \
                 `relative:opening=N,window=M` (e.g. `{}`)",
                RateTerm::DEFAULT
            ),
        };
        let s = s.trim();
        let (form, widths) = match s.split_once(':') {
            Some((form, widths)) => (form.trim(), Some(widths)),
            None => (s, None),
        };
        let term = match (form, widths) {
            ("absolute", None) => RateTerm::Absolute,
            ("absolute", Some(_)) => return Err(bad("`absolute` takes no widths".into())),
            ("relative", widths) => {
                let (mut opening, mut window) = (Self::DEFAULT_OPENING, Self::DEFAULT_WINDOW);
                for part in widths.into_iter().flat_map(|w| w.split(',')) {
                    let (key, value) = part
                        .split_once('=')
                        .ok_or_else(|| bad(format!("`{part}` is not NAME=VALUE")))?;
                    let value: usize = value.trim().parse().map_err(|_| {
                        bad(format!("`{}` is not a number of samples", value.trim()))
                    })?;
                    match key.trim() {
                        "opening" => opening = value,
                        "window" => window = value,
                        other => {
                            return Err(bad(format!(
                                "unknown width `{other}` (the widths are `opening` and `window`)"
                            )));
                        }
                    }
                }
                RateTerm::Relative { opening, window }
            }
            _ => return Err(bad(format!("`{s}` is not a rate term"))),
        };
        term.validate()?;
        Ok(term)
    }
}

impl Serialize for RateTerm {
    fn serialize<S: serde::Serializer>(
        &self,
        serializer: S,
    ) -> std::result::Result<S::Ok, S::Error> {
        serializer.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for RateTerm {
    fn deserialize<D: serde::Deserializer<'de>>(
        deserializer: D,
    ) -> std::result::Result<Self, D::Error> {
        let s = String::deserialize(deserializer)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

/// Parameters of [`TaskModel::fit`](crate::TaskModel::fit) and
/// [`TaskModel::fit_aligned`](crate::TaskModel::fit_aligned).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FitParams {
    /// GDTW parameters for aligning every demonstration to the reference (Eq. 2–3).
    /// When `warp.weights` is `None` (default), the weights are derived from the ranges:
    /// `1/r_j²` per scalar channel and `4/r_q²` per quaternion component (a small rotation
    /// `δr` moves a unit quaternion by `|δr|/2`), so the alignment uses the same `W` as
    /// the statistics. Default: `WarpParams::default()` with `lambda_inst = 0.02` (four times
    /// the alignment crate's default): the model reads the warps' gradients too (the rate
    /// channel of `σ²_D`, the speed bounds), and a weaker slope penalty makes them follow
    /// every speed wobble, so that on the fixtures the variance contrast between the sanding
    /// passes and pass 4 falls from 3.13 to 2.84 (docs/decisions.md, "tandem-warp defaults");
    /// `smooth_width = 1` (no smoothing before alignment, the crate's default smooths over
    /// 7 samples) and `fill_length = 0` (flat stretches keep the straight line of the slope
    /// penalty, the crate's default fills them): the model's gradients and statistics were
    /// measured without either.
    pub warp: tandem_warp::WarpParams,
    /// Per tangent-coordinate ranges `r_j` (length `d`, warp gradient last; physical units:
    /// channel units, radians for rotation vectors, demo samples per reference sample for
    /// the rate); `W⁺ = diag(1/r_j²)` (Eq. 6). `None` (default): each scalar channel's
    /// range over all demonstrations' samples; for a quaternion block, the largest
    /// component range of the rotation vectors relative to the reference's first
    /// orientation; for the rate, the largest speed-up the alignment admits at the
    /// demonstrations' mean pace, `(warp.slope_max − 1) · ψ̄̇₀` (`ψ̄̇₀` the mean warp gradient).
    /// The rate's term of `σ²_D` divides its range by the local mean pace over `ψ̄̇₀`, so it
    /// weighs relative speed differences, and is opened over 13 reference samples (a rise
    /// narrower than the alignment can place a change of speed is removed; docs/decisions.md,
    /// "Fit defaults on the task zoo"), as [`FitParams::rate_term`] says.
    pub ranges: Option<Vec<f64>>,
    /// How the demonstrations' speeds enter `σ²_D` ([`RateTerm`]). Default:
    /// [`RateTerm::DEFAULT`], relative, opened over 13 samples, with the duration term over
    /// [`RateTerm::DEFAULT_WINDOW`] samples.
    pub rate_term: RateTerm,
    /// Ranges below this are replaced by 1 (constant channels). Default: 1e-9.
    pub min_range: f64,
    /// Maximum number of correction components `k_max`; `K = min(n − 1, k_max, d)`.
    /// Must be ≥ 1. Default: 3.
    pub k_max: usize,
    /// Channel kinds and quaternion blocks. Default: [`ChannelSchema::default`].
    pub schema: ChannelSchema,
    /// Which demonstration is the reference (its samples are the model's time axis).
    /// Default: [`Reference::Medoid`] (the model does not depend on the order of the files;
    /// docs/decisions.md, "The medoid reference by default: labels follow the reference").
    /// [`TaskModel::fit_aligned`](crate::TaskModel::fit_aligned)
    /// takes warps onto demo 0, whose samples are then the time axis whatever this says.
    pub reference: Reference,
}

impl Default for FitParams {
    fn default() -> Self {
        Self {
            warp: tandem_warp::WarpParams {
                lambda_inst: 0.02,
                smooth_width: 1,
                fill_length: 0.0,
                ..tandem_warp::WarpParams::default()
            },
            ranges: None,
            rate_term: RateTerm::DEFAULT,
            min_range: 1e-9,
            k_max: 3,
            schema: ChannelSchema::default(),
            reference: Reference::Medoid,
        }
    }
}

impl FitParams {
    /// Checks every field (the warp parameters are checked by `tandem-warp`).
    ///
    /// # Errors
    /// [`Error::BadParam`] naming the field, or the schema's error.
    pub fn validate(&self) -> Result<()> {
        if self.k_max == 0 {
            return Err(Error::BadParam {
                name: "k_max",
                why: "must be ≥ 1".into(),
            });
        }
        if !(self.min_range.is_finite() && self.min_range >= 0.0) {
            return Err(Error::BadParam {
                name: "min_range",
                why: format!("must be finite ≥ 0, got {}", self.min_range),
            });
        }
        let bad_range = self
            .ranges
            .iter()
            .flatten()
            .find(|v| !(v.is_finite() && **v > 0.0));
        if let Some(v) = bad_range {
            return Err(Error::BadParam {
                name: "ranges",
                why: format!("every range must be finite > 0, got {v}"),
            });
        }
        self.rate_term.validate()?;
        self.schema.validate()
    }

    /// Checks that explicit [`FitParams::ranges`] has one entry per tangent coordinate
    /// (`d`, rate included).
    pub(super) fn check_ranges_len(&self, d: usize) -> Result<()> {
        match &self.ranges {
            Some(r) if r.len() != d => Err(Error::BadParam {
                name: "ranges",
                why: format!("has {} entries, the tangent layout has {d}", r.len()),
            }),
            _ => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rate_term_is_spelled_one_way_everywhere() {
        for (text, term) in [
            ("absolute", RateTerm::Absolute),
            ("relative", RateTerm::DEFAULT),
            (
                "relative:window=49",
                RateTerm::Relative {
                    opening: 13,
                    window: 49,
                },
            ),
            (
                "relative:opening=7",
                RateTerm::Relative {
                    opening: 7,
                    window: 97,
                },
            ),
            (
                " relative: opening = 7 , window = 0 ",
                RateTerm::Relative {
                    opening: 7,
                    window: 0,
                },
            ),
        ] {
            let parsed: RateTerm = text.parse().unwrap();
            assert_eq!(parsed, term, "{text}");
            // Display writes every width; it parses back to the same form.
            assert_eq!(parsed.to_string().parse::<RateTerm>().unwrap(), term);
        }
        assert_eq!(
            RateTerm::Relative {
                opening: 13,
                window: 49
            }
            .to_string(),
            "relative:opening=13,window=49"
        );
        // In a parameter file, as a string.
        let p: FitParams =
            serde_json::from_str(r#"{"rate_term": "relative:opening=5,window=25"}"#).unwrap();
        assert_eq!(
            p.rate_term,
            RateTerm::Relative {
                opening: 5,
                window: 25
            }
        );
        assert_eq!(FitParams::default().rate_term, RateTerm::DEFAULT);
    }

    #[test]
    fn a_bad_rate_term_names_the_parameter_and_the_choices() {
        for (text, why) in [
            ("relativ", "`relativ` is not a rate term"),
            ("absolute:window=3", "`absolute` takes no widths"),
            ("relative:width=3", "unknown width `width`"),
            ("relative:window", "`window` is not NAME=VALUE"),
            ("relative:window=-3", "`-3` is not a number of samples"),
            ("relative:window=4", "odd number of samples ≥ 3, got 4"),
            ("relative:window=1", "odd number of samples ≥ 3, got 1"),
            ("relative:opening=0", "odd number of samples ≥ 1, got 0"),
        ] {
            let err = text.parse::<RateTerm>().unwrap_err().to_string();
            assert!(
                err.contains("rate_term") && err.contains(why),
                "{text}: {err}"
            );
        }
        let err = "relativ".parse::<RateTerm>().unwrap_err().to_string();
        assert!(
            err.contains("`absolute`, `relative` or `relative:opening=N,window=M`"),
            "{err}"
        );
        let err = serde_json::from_str::<FitParams>(r#"{"rate_term": "quadratic"}"#)
            .unwrap_err()
            .to_string();
        assert!(err.contains("`quadratic` is not a rate term"), "{err}");
        let bad = FitParams {
            rate_term: RateTerm::Relative {
                opening: 2,
                window: 0,
            },
            ..FitParams::default()
        };
        assert!(matches!(
            bad.validate(),
            Err(Error::BadParam {
                name: "rate_term",
                ..
            })
        ));
    }
}
