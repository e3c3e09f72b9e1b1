//! [`ZooTask`]: one generated task — demonstrations as CSV text and the ground truth.

use std::path::Path;

use serde::{Deserialize, Serialize};
use tandem_lfd::Demonstration;

use crate::{Error, Result};

/// Where the operator is needed: `p(need)` over the progress span `[from, to)` (the span that
/// ends the task includes progress 1).
///
/// `p` is the probability that an execution needs the operator in the span, graded from 0.2
/// (rarely) to 1 (always): an operator who follows the truth draws once per execution and
/// span, and when the draw says so, corrects the robot over the span; elsewhere never.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct NeedSpan {
    /// Start, progress in `[0, 1)`.
    pub from: f64,
    /// End, progress in `(from, 1]`.
    pub to: f64,
    /// p(need), in `(0, 1]`.
    pub p: f64,
    /// Whether the demonstrations vary over the span, so that their variance can reveal the
    /// need (`true`), or all demonstrations agree there although the operator is needed
    /// (`false`: unlearnable from demonstrations, only corrections can reveal it; reported
    /// apart).
    pub learnable: bool,
}

/// One task of a family at one seed: the demonstrations a user would record and the truth of
/// where, and how much, the operator is needed.
///
/// Progress is the task's own clock in `[0, 1]`: every demonstration goes through the same
/// sequence of task phases, and `progress[i][r]` says where in that sequence row `r` of
/// demonstration `i` is. Two rows of two demonstrations with the same progress are at the same
/// point of the task, so the progress arrays are the ground-truth time warps between the
/// demonstrations ([`ZooTask::true_warp`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ZooTask {
    /// The family's name ([`crate::Family::name`]).
    pub family: &'static str,
    /// The seed it was generated with.
    pub seed: u64,
    /// Sample rate of every demonstration, Hz (the files' `t` columns say so too).
    pub rate_hz: f64,
    /// Each demonstration as the CSV text a user's recorder writes (header, `t` column in
    /// seconds with jitter, channels), and its file name `demo_<i>.csv`.
    pub files: Vec<(String, String)>,
    /// Per demonstration, per CSV row: the true task progress (phase in [0, 1], non-decreasing):
    /// the ground-truth warp of that demonstration.
    pub progress: Vec<Vec<f64>>,
    /// Where the operator is needed: p(need) per span of progress (disjoint, sorted; 0
    /// elsewhere).
    pub need: Vec<NeedSpan>,
    /// Hold rules a user would declare where the task has a natural safe wait (e.g.
    /// "valve<0.5"), in the syntax of `tandem_lfd::HoldSpec`/`tandem fit --hold-where`; empty
    /// if none.
    pub holds: Vec<String>,
    /// Which spans vary between these demonstrations (variable sections, and the supports of
    /// the local events they drew), for "falsely trusted" counts: sorted, disjoint, in
    /// progress units. Each lies inside a learnable need span; a learnable need span may hold
    /// stretches where no demonstration drew its event, which count as agreeing.
    pub variable: Vec<(f64, f64)>,
}

/// What `truth.json` holds (written by [`ZooTask::write_dir`]).
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct TruthFile {
    family: String,
    seed: u64,
    rate_hz: f64,
    files: Vec<String>,
    need: Vec<NeedSpan>,
    variable: Vec<(f64, f64)>,
    holds: Vec<String>,
    true_high_share: Vec<f64>,
    progress: Vec<Vec<f64>>,
}

impl ZooTask {
    /// Number of demonstrations.
    #[must_use]
    pub fn n_demos(&self) -> usize {
        self.files.len()
    }

    /// The demonstrations parsed exactly as the CLI parses CSV files (tandem_lfd's CSV path:
    /// `Demonstration::from_csv_str`, period from the `t` column).
    ///
    /// # Errors
    /// The loader's error, naming the file, line and column (a generator bug).
    pub fn demos(&self) -> Result<Vec<Demonstration>> {
        self.files
            .iter()
            .map(|(name, text)| Ok(Demonstration::from_csv_str(text, name, None)?))
            .collect()
    }

    /// p(need) at a progress value (0 outside every need span).
    #[must_use]
    pub fn need_at(&self, progress: f64) -> f64 {
        self.need
            .iter()
            .find(|s| s.from <= progress && (progress < s.to || s.to >= 1.0 && progress <= 1.0))
            .map_or(0.0, |s| s.p)
    }

    /// Whether `progress` lies in a variable section ([`ZooTask::variable`]): the
    /// demonstrations differ there, so a sample the model trusts there is falsely trusted.
    #[must_use]
    pub fn is_variable(&self, progress: f64) -> bool {
        self.variable
            .iter()
            .any(|&(a, b)| a <= progress && (progress < b || b >= 1.0 && progress <= 1.0))
    }

    /// The need per row of demonstration `i`.
    ///
    /// # Panics
    /// If `i ≥ n_demos()`, like indexing a slice.
    #[must_use]
    pub fn need_of_demo(&self, i: usize) -> Vec<f64> {
        self.progress[i].iter().map(|&p| self.need_at(p)).collect()
    }

    /// Truth: share of demonstration `i`'s duration (time-weighted, its rows are evenly
    /// spaced) that never needs the operator: the share of its sampling intervals whose
    /// midpoint progress has no need. In `[0, 1]`.
    ///
    /// # Panics
    /// If `i ≥ n_demos()`, like indexing a slice.
    #[must_use]
    pub fn true_high_share(&self, i: usize) -> f64 {
        let p = &self.progress[i];
        if p.len() < 2 {
            return 0.0;
        }
        let free = p
            .windows(2)
            .filter(|w| self.need_at(0.5 * (w[0] + w[1])) == 0.0)
            .count();
        free as f64 / (p.len() - 1) as f64
    }

    /// The ground-truth warp from demonstration `reference` onto demonstration `demo`: for
    /// every row `n` of the reference, the (fractional) row of `demo` at the same progress.
    /// Monotone, `0` at the first row and `T_demo − 1` at the last: the warp an alignment of
    /// `demo` to `reference` should find (in the time frames of `tandem_lfd`'s warps).
    ///
    /// # Errors
    /// [`Error::DemoIndex`] for an index past the demonstrations.
    pub fn true_warp(&self, reference: usize, demo: usize) -> Result<Vec<f64>> {
        let n_demos = self.n_demos();
        for index in [reference, demo] {
            if index >= n_demos {
                return Err(Error::DemoIndex { index, n_demos });
            }
        }
        let (pr, pd) = (&self.progress[reference], &self.progress[demo]);
        if pd.len() < 2 {
            return Ok(vec![0.0; pr.len()]);
        }
        let mut j = 0;
        let last = pd.len() - 1;
        Ok(pr
            .iter()
            .map(|&p| {
                while j + 1 < last && pd[j + 1] <= p {
                    j += 1;
                }
                let (a, b) = (pd[j], pd[j + 1]);
                let f = if b > a {
                    ((p - a) / (b - a)).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                j as f64 + f
            })
            .collect())
    }

    /// Writes the task into `dir` (created if missing): `demo_<i>.csv` per demonstration,
    /// `truth.json` (family, seed, rate, need and variable spans, holds, each demonstration's
    /// true high share and progress per row) and, when the task declares holds,
    /// `holds.txt` (one rule per line, for `tandem fit --hold-where`). Existing files of
    /// these names are replaced.
    ///
    /// # Errors
    /// [`Error::Io`] naming the file that could not be written.
    pub fn write_dir(&self, dir: &Path) -> Result<()> {
        let io = |path: &Path| {
            let path = path.display().to_string();
            move |source| Error::Io { path, source }
        };
        std::fs::create_dir_all(dir).map_err(io(dir))?;
        for (name, text) in &self.files {
            let path = dir.join(name);
            std::fs::write(&path, text).map_err(io(&path))?;
        }
        let truth = TruthFile {
            family: self.family.to_owned(),
            seed: self.seed,
            rate_hz: self.rate_hz,
            files: self.files.iter().map(|(n, _)| n.clone()).collect(),
            need: self.need.clone(),
            variable: self.variable.clone(),
            holds: self.holds.clone(),
            true_high_share: (0..self.n_demos())
                .map(|i| self.true_high_share(i))
                .collect(),
            progress: self.progress.clone(),
        };
        let path = dir.join("truth.json");
        std::fs::write(&path, serde_json::to_string(&truth)?).map_err(io(&path))?;
        if !self.holds.is_empty() {
            let path = dir.join("holds.txt");
            let mut text = self.holds.join("\n");
            text.push('\n');
            std::fs::write(&path, text).map_err(io(&path))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hand-made task: two demonstrations of 5 rows, need 0.5 on [0.25, 0.5), 1 on [0.75, 1].
    fn small() -> ZooTask {
        ZooTask {
            family: "hand",
            seed: 0,
            rate_hz: 10.0,
            files: vec![
                (
                    "demo_0.csv".into(),
                    "t,a\n0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n".into(),
                ),
                ("demo_1.csv".into(), "t,a\n0,0\n0.1,2\n0.2,4\n".into()),
            ],
            progress: vec![vec![0.0, 0.25, 0.5, 0.75, 1.0], vec![0.0, 0.5, 1.0]],
            need: vec![
                NeedSpan {
                    from: 0.25,
                    to: 0.5,
                    p: 0.5,
                    learnable: true,
                },
                NeedSpan {
                    from: 0.75,
                    to: 1.0,
                    p: 1.0,
                    learnable: false,
                },
            ],
            holds: vec![],
            variable: vec![(0.25, 0.5)],
        }
    }

    #[test]
    fn need_is_read_per_span_with_the_last_one_closed() {
        let t = small();
        assert_eq!(t.need_at(0.1), 0.0);
        assert_eq!(t.need_at(0.25), 0.5);
        assert_eq!(t.need_at(0.5), 0.0);
        assert_eq!(t.need_at(1.0), 1.0);
        assert_eq!(t.need_of_demo(0), [0.0, 0.5, 0.0, 1.0, 1.0]);
        // Intervals of demo 0 have midpoints 0.125, 0.375, 0.625, 0.875: two are free.
        assert_eq!(t.true_high_share(0), 0.5);
        // Demo 1: midpoints 0.25 (need) and 0.75 (need).
        assert_eq!(t.true_high_share(1), 0.0);
        assert!(t.is_variable(0.25) && t.is_variable(0.49) && !t.is_variable(0.5));
    }

    #[test]
    fn the_true_warp_maps_equal_progress() {
        let t = small();
        // Reference demo 0 (progress 0, .25, .5, .75, 1) onto demo 1 (0, .5, 1).
        assert_eq!(t.true_warp(0, 1).unwrap(), [0.0, 0.5, 1.0, 1.5, 2.0]);
        assert_eq!(t.true_warp(1, 0).unwrap(), [0.0, 2.0, 4.0]);
        assert!(matches!(
            t.true_warp(0, 2),
            Err(Error::DemoIndex {
                index: 2,
                n_demos: 2
            })
        ));
    }

    #[test]
    fn demos_parse_through_the_loader() {
        let demos = small().demos().unwrap();
        assert_eq!(demos[0].n_samples(), 5);
        assert!((demos[0].dt_s() - 0.1).abs() < 1e-12);
    }
}
