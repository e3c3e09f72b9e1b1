//! Need profiles: per reference sample, the probability that a workpiece needs the operator
//! there, and the regions that share one draw (the input of `tandem simulate --need`, and of
//! `tandem.sim.needs` in Python).
//!
//! A profile is built from reference-time intervals ([`NeedProfile::from_regions`]), from
//! per-sample levels ([`NeedProfile::from_levels`], e.g. a label column), or read from a need
//! file ([`NeedProfile::parse_csv`], the format of docs/formats.md); [`NeedProfile::to_csv`]
//! writes that format and reading it back gives the same profile.
//! [`NeedProfile::draw`] draws which samples need the operator on `N` workpieces, one draw
//! per region and workpiece, in the order `tandem simulate` uses.
//!
//! Reference time: sample `n` of the reference demonstration is at `n·Δt_s` seconds.
//! A region `[start_s, end_s)` covers the samples with `start_s ≤ n·Δt_s < end_s` (half
//! open, so adjacent regions `a-b` and `b-c` share no sample), compared with a tolerance
//! of `10⁻⁹·Δt_s` so that printed decimals (`0.3` at 100 Hz) hit the sample they name.

use std::collections::BTreeMap;

use rand::Rng;
use tandem_lfd::CsvTable;

use crate::{Error, Result};

/// One reference-time interval needing the operator with probability `level`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NeedRegion {
    /// Start, reference seconds (inclusive).
    pub start_s: f64,
    /// End, reference seconds (exclusive).
    pub end_s: f64,
    /// Probability in `[0, 1]` that a workpiece needs the operator over the whole region.
    pub level: f64,
}

/// Per reference sample, the need probability and its region (see the module docs).
///
/// Invariants (checked by every constructor): `p` and `region` have the same length ≥ 1;
/// every `p` is in `[0, 1]`; regions are numbered densely from 0 in order of first
/// appearance and all samples of a region have the same probability.
#[derive(Clone, Debug, PartialEq)]
pub struct NeedProfile {
    p: Vec<f64>,
    region: Vec<usize>,
}

/// Tolerance of the reference-time comparisons, in reference samples.
const SAMPLE_EPS: f64 = 1e-9;

/// First sample `n` with `n·Δt_s ≥ t_s` (up to [`SAMPLE_EPS`]).
fn first_sample_at(t_s: f64, dt_s: f64) -> usize {
    (t_s / dt_s - SAMPLE_EPS).ceil().max(0.0) as usize
}

/// `Error::Need` at `at`.
fn need_err(at: impl Into<String>, why: impl Into<String>) -> Error {
    Error::Need {
        at: at.into(),
        why: why.into(),
    }
}

impl NeedProfile {
    /// Regions in reference seconds over a reference of `n_ref` samples `dt_s` apart.
    /// Samples outside every region have need 0 and form region 0; given region `k`
    /// (0-based) is region `k + 1`.
    ///
    /// # Errors
    /// [`Error::Need`] (naming the region, 1-based, as `--region K`) for a level outside
    /// `[0, 1]`, a non-finite bound, `start_s ≥ end_s`, a region covering no sample, one
    /// ending after the reference (`n_ref·Δt_s`), or two regions sharing a sample;
    /// [`Error::BadParam`] for `n_ref = 0` or `dt_s` not finite > 0.
    pub fn from_regions(regions: &[NeedRegion], n_ref: usize, dt_s: f64) -> Result<Self> {
        if n_ref == 0 {
            return Err(Error::BadParam {
                name: "n_ref",
                why: "must be at least 1",
            });
        }
        if !(dt_s.is_finite() && dt_s > 0.0) {
            return Err(Error::BadParam {
                name: "dt_s",
                why: "must be finite and > 0",
            });
        }
        let duration = n_ref as f64 * dt_s;
        let mut p = vec![0.0; n_ref];
        let mut region = vec![0usize; n_ref];
        let mut owner: Vec<Option<usize>> = vec![None; n_ref];
        for (k, r) in regions.iter().enumerate() {
            let at = format!("region {} ({}-{}={})", k + 1, r.start_s, r.end_s, r.level);
            if !(r.start_s.is_finite() && r.end_s.is_finite()) {
                return Err(need_err(at, "start and end must be finite seconds"));
            }
            if !(0.0..=1.0).contains(&r.level) {
                return Err(need_err(
                    at,
                    format!("level {} is not a probability in [0, 1]", r.level),
                ));
            }
            if r.start_s < 0.0 || r.start_s >= r.end_s {
                return Err(need_err(
                    at,
                    "needs 0 ≤ START < END (reference seconds, END exclusive)",
                ));
            }
            if r.end_s > duration * (1.0 + SAMPLE_EPS) {
                return Err(need_err(
                    at,
                    format!(
                        "ends after the reference, which lasts {} s ({n_ref} samples × {dt_s} s; \
                         `tandem inspect` prints it)",
                        (duration * 1e9).round() / 1e9
                    ),
                ));
            }
            let (lo, hi) = (
                first_sample_at(r.start_s, dt_s),
                first_sample_at(r.end_s, dt_s).min(n_ref),
            );
            if lo >= hi {
                return Err(need_err(
                    at,
                    format!("covers no reference sample (samples are {dt_s} s apart)"),
                ));
            }
            for n in lo..hi {
                if let Some(other) = owner[n] {
                    return Err(need_err(
                        at,
                        format!(
                            "overlaps region {} at {} s (reference sample {n}); regions must \
                             not share a sample",
                            other + 1,
                            (n as f64 * dt_s * 1e9).round() / 1e9
                        ),
                    ));
                }
                owner[n] = Some(k);
                p[n] = r.level;
                region[n] = k + 1;
            }
        }
        Ok(Self::densify(p, &region))
    }

    /// Per-sample levels in `[0, 1]` (one per reference sample): every maximal run of
    /// consecutive equal values is one region.
    ///
    /// # Errors
    /// [`Error::Need`] naming the 0-based sample of a level outside `[0, 1]` (or of an
    /// empty slice).
    pub fn from_levels(levels: &[f64]) -> Result<Self> {
        if levels.is_empty() {
            return Err(need_err("levels", "no reference samples"));
        }
        if let Some(n) = levels.iter().position(|v| !(0.0..=1.0).contains(v)) {
            return Err(need_err(
                format!("sample {n}"),
                format!("level {} is not a probability in [0, 1]", levels[n]),
            ));
        }
        let mut region = Vec::with_capacity(levels.len());
        let mut id = 0;
        for n in 0..levels.len() {
            if n > 0 && levels[n] != levels[n - 1] {
                id += 1;
            }
            region.push(id);
        }
        Ok(Self {
            p: levels.to_vec(),
            region,
        })
    }

    /// Renumbers `region` densely in order of first appearance.
    fn densify(p: Vec<f64>, region: &[usize]) -> Self {
        let mut ids: BTreeMap<usize, usize> = BTreeMap::new();
        let region = region
            .iter()
            .map(|&r| {
                let next = ids.len();
                *ids.entry(r).or_insert(next)
            })
            .collect();
        Self { p, region }
    }

    /// Parses a need file (docs/formats.md): column `need` in `[0, 1]`, one row per reference
    /// sample (`n_ref` rows), optional whole-number column `region` (≥ 0) grouping samples
    /// into one draw; without it every maximal run of consecutive equal values is a region.
    /// `file` names the text in errors.
    ///
    /// # Errors
    /// The tokenizer's errors ([`Error::Lfd`]); [`Error::Need`] with the file, the 1-based
    /// line and column for a header without rows, an unknown or missing column, a row count
    /// other than `n_ref`, a value outside `[0, 1]`, a region id that is not a whole number,
    /// or a region with two probabilities.
    pub fn parse_csv(text: &str, file: &str, n_ref: usize) -> Result<Self> {
        let t = CsvTable::parse(text, file)?;
        let hl = t.header_line();
        if t.rows().is_empty() {
            return Err(need_err(
                format!("{file}:{}", t.end_line()),
                "header only, no data rows",
            ));
        }
        for (j, n) in t.names().iter().enumerate() {
            if n != "need" && n != "region" {
                return Err(need_err(
                    format!("{file}:{hl}:{}", j + 1),
                    format!("unexpected column `{n}` (allowed: need, region)"),
                ));
            }
        }
        let Some(jn) = t.column("need") else {
            return Err(need_err(
                format!("{file}:{hl}"),
                format!("no column `need` in the header {:?}", t.names()),
            ));
        };
        let p: Vec<f64> = (0..t.rows().len())
            .map(|r| t.number(r, jn))
            .collect::<tandem_lfd::Result<_>>()?;
        let line = |k: usize| t.rows()[k].line;
        if p.len() != n_ref {
            return Err(need_err(
                file,
                format!(
                    "{} rows, the model has {n_ref} reference samples (one row per reference \
                     sample; `tandem need` writes one)",
                    p.len()
                ),
            ));
        }
        if let Some(k) = p.iter().position(|v| !(0.0..=1.0).contains(v)) {
            return Err(need_err(
                format!("{file}:{}:{}", line(k), jn + 1),
                format!("`need` = {} is not a probability in [0, 1]", p[k]),
            ));
        }
        let Some(jr) = t.column("region") else {
            return Self::from_levels(&p);
        };
        let mut region = Vec::with_capacity(p.len());
        // User id → (dense index, first line, probability).
        let mut seen: BTreeMap<u64, (usize, usize, f64)> = BTreeMap::new();
        for (k, &pk) in p.iter().enumerate() {
            let v = t.number(k, jr)?;
            if !(v >= 0.0 && v.fract() == 0.0 && v < 1e15) {
                return Err(need_err(
                    format!("{file}:{}:{}", line(k), jr + 1),
                    format!("`region` = {v} is not a whole number ≥ 0"),
                ));
            }
            let id = v as u64;
            let next = seen.len();
            let (dense, line0, p0) = *seen.entry(id).or_insert((next, line(k), pk));
            if p0 != pk {
                return Err(need_err(
                    format!("{file}:{}", line(k)),
                    format!(
                        "region {id} has need {pk} here but {p0} on line {line0} (one \
                         probability per region)"
                    ),
                ));
            }
            region.push(dense);
        }
        Ok(Self { p, region })
    }

    /// The need file of this profile (`need,region`, one row per reference sample, numbers in
    /// shortest round-trip form): [`NeedProfile::parse_csv`] reads it back unchanged.
    pub fn to_csv(&self) -> String {
        let mut out = String::with_capacity(16 * self.p.len() + 12);
        out.push_str("need,region\n");
        for (p, r) in self.p.iter().zip(&self.region) {
            out.push_str(&format!("{p},{r}\n"));
        }
        out
    }

    /// Probability per reference sample.
    pub fn p(&self) -> &[f64] {
        &self.p
    }

    /// Region of each reference sample (dense, from 0).
    pub fn region(&self) -> &[usize] {
        &self.region
    }

    /// Number of reference samples `T_ref`.
    pub fn n_ref(&self) -> usize {
        self.p.len()
    }

    /// Number of regions.
    pub fn n_regions(&self) -> usize {
        self.region.iter().copied().max().map_or(0, |m| m + 1)
    }

    /// Probability of each region (index = region).
    pub fn region_levels(&self) -> Vec<f64> {
        let mut out = vec![0.0; self.n_regions()];
        for (&r, &p) in self.region.iter().zip(&self.p) {
            out[r] = p;
        }
        out
    }

    /// Which reference samples need the operator on each of `robots` workpieces:
    /// `out[i][n]`. Per workpiece (robot 1 first), one uniform draw per region in region
    /// order; the region is needed when the draw is below its probability.
    pub fn draw(&self, robots: usize, rng: &mut impl Rng) -> Vec<Vec<bool>> {
        let levels = self.region_levels();
        (0..robots)
            .map(|_| {
                let hit: Vec<bool> = levels.iter().map(|&p| rng.random::<f64>() < p).collect();
                self.region.iter().map(|&r| hit[r]).collect()
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn region(start_s: f64, end_s: f64, level: f64) -> NeedRegion {
        NeedRegion {
            start_s,
            end_s,
            level,
        }
    }

    #[test]
    fn regions_cover_half_open_reference_intervals() {
        // 10 samples 0.1 s apart: 0.0, 0.1, …, 0.9 s.
        let p = NeedProfile::from_regions(&[region(0.2, 0.5, 0.5), region(0.5, 0.7, 1.0)], 10, 0.1)
            .unwrap();
        assert_eq!(p.p(), [0.0, 0.0, 0.5, 0.5, 0.5, 1.0, 1.0, 0.0, 0.0, 0.0]);
        assert_eq!(p.region(), [0, 0, 1, 1, 1, 2, 2, 0, 0, 0]);
        assert_eq!(p.n_regions(), 3);
        // The whole reference: 0 to n_ref·Δt.
        let all = NeedProfile::from_regions(&[region(0.0, 1.0, 0.25)], 10, 0.1).unwrap();
        assert_eq!(all.p(), [0.25; 10]);
        assert_eq!(all.n_regions(), 1);
    }

    #[test]
    fn printed_decimals_hit_the_sample_they_name() {
        // 0.3 / 0.01 = 29.999999999999996 in floating point: sample 30 starts the region.
        let p = NeedProfile::from_regions(&[region(0.3, 0.31, 1.0)], 100, 0.01).unwrap();
        let hit: Vec<usize> = (0..100).filter(|&n| p.p()[n] > 0.0).collect();
        assert_eq!(hit, [30]);
    }

    #[test]
    fn bad_regions_are_named() {
        for (r, want) in [
            (region(0.2, 0.2, 0.5), "START < END"),
            (region(0.5, 0.2, 0.5), "START < END"),
            (region(-0.1, 0.2, 0.5), "START < END"),
            (region(0.2, 0.5, 1.5), "not a probability"),
            (region(0.2, 0.5, f64::NAN), "not a probability"),
            (region(0.2, f64::INFINITY, 0.5), "finite"),
            (
                region(0.2, 1.2, 0.5),
                "ends after the reference, which lasts 1 s",
            ),
            (region(0.21, 0.29, 0.5), "covers no reference sample"),
        ] {
            let e = NeedProfile::from_regions(&[r], 10, 0.1)
                .unwrap_err()
                .to_string();
            assert!(e.contains("region 1") && e.contains(want), "{e}");
        }
        let e = NeedProfile::from_regions(&[region(0.1, 0.5, 0.5), region(0.4, 0.6, 0.5)], 10, 0.1)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("region 2") && e.contains("overlaps region 1 at 0.4 s"),
            "{e}"
        );
    }

    #[test]
    fn the_written_file_reads_back_unchanged() {
        let p = NeedProfile::from_regions(
            &[region(0.05, 0.3, 0.1 + 0.2), region(0.6, 0.8, 0.5)],
            10,
            0.1,
        )
        .unwrap();
        let text = p.to_csv();
        assert!(
            text.starts_with("need,region\n0,0\n0.30000000000000004,1\n"),
            "{text}"
        );
        assert_eq!(NeedProfile::parse_csv(&text, "need.csv", 10).unwrap(), p);
        let e = NeedProfile::parse_csv(&text, "need.csv", 11)
            .unwrap_err()
            .to_string();
        assert!(e.contains("need.csv: 10 rows, the model has 11"), "{e}");
    }

    #[test]
    fn need_files_are_checked_with_their_lines() {
        for (text, want) in [
            (
                "need\n0.5\n2\n",
                "need.csv:3:1: `need` = 2 is not a probability",
            ),
            (
                "need,region\n0.5,1\n0.4,1\n",
                "need.csv:3: region 1 has need 0.4 here but 0.5 on line 2",
            ),
            (
                "need,region\n0.5,1.5\n0.5,1\n",
                "need.csv:2:2: `region` = 1.5",
            ),
            (
                "need,what\n0.5,1\n0.5,1\n",
                "need.csv:1:2: unexpected column `what`",
            ),
            ("region\n1\n1\n", "need.csv:1: no column `need`"),
            ("need\n", "need.csv:2: header only"),
        ] {
            let e = NeedProfile::parse_csv(text, "need.csv", 2)
                .unwrap_err()
                .to_string();
            assert!(e.contains(want), "{e} / {want}");
        }
        // Without `region`, runs of equal values are regions; ids in the file are renumbered.
        let p = NeedProfile::parse_csv("need\n0\n0.5\n0.5\n0\n", "n", 4).unwrap();
        assert_eq!(p.region(), [0, 1, 1, 2]);
        let p = NeedProfile::parse_csv(
            "need,region\n0.5,900000000000\n0,3\n0.5,900000000000\n",
            "n",
            3,
        )
        .unwrap();
        assert_eq!(p.region(), [0, 1, 0]);
    }

    #[test]
    fn a_region_is_needed_on_the_whole_workpiece_or_not_at_all() {
        let p = NeedProfile::from_regions(&[region(0.0, 0.5, 0.5), region(0.5, 1.0, 1.0)], 10, 0.1)
            .unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let mut first_hits = 0;
        for _ in 0..200 {
            for w in p.draw(3, &mut rng) {
                assert_eq!(w.len(), 10);
                assert!(w[..5].iter().all(|&b| b == w[0]), "one draw per region");
                assert!(w[5..].iter().all(|&b| b), "level 1 is always needed");
                first_hits += usize::from(w[0]);
            }
        }
        // 600 draws at p = 0.5: far inside [200, 400] (≈ 8 standard deviations).
        assert!((200..=400).contains(&first_hits), "{first_hits}");
    }
}
