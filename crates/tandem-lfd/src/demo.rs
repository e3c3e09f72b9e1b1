//! Demonstrations (paper Eq. 1): channel names, sample-major data, sample period; CSV and
//! JSON readers with located errors; the channel-kind schema.

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::csv::CsvTable;
use crate::resample::{self, Interpolation};
use crate::{Error, Result};

/// Sample period used when a file carries neither a `t` column nor a `dt_s` field and the
/// caller gives none: 0.01 s (100 Hz, the fixtures' rate).
pub const DEFAULT_DT_S: f64 = 0.01;

/// Largest magnitude of a demonstration value, `1e100` (the alignment's
/// `tandem_warp::MAX_ABS_VALUE`): alignment and statistics square differences of values,
/// which overflow `f64` near `1e154`; physical task data never comes near this.
pub const MAX_ABS_VALUE: f64 = tandem_warp::MAX_ABS_VALUE;

/// Relative tolerance on sample periods (even spacing of a `t` column; equal periods
/// across demonstrations): 1 %.
pub const DT_TOLERANCE: f64 = 0.01;

/// Largest deviation of a `t` column's time from the file's even grid (first time plus
/// multiples of the mean period), relative to the period, that a file may have: 25 % (a
/// ±1.5 ms jitter at 100 Hz is 15 %; a dropped or repeated sample is at least 50 %).
/// docs/decisions.md, "Timestamps: the mean period, jitter within 25 %".
pub const JITTER_TOLERANCE: f64 = 0.25;

/// Longest gap between two rows of a log that [`Demonstration::from_csv_str_resampled`]
/// interpolates over, in grid periods: 3.
pub const MAX_RESAMPLE_GAP: f64 = 3.0;

/// Deviation from the even grid (relative to the period) above which the reader reports the
/// worst one in [`Demonstration::period_note`]: 1 %.
pub const JITTER_NOTE: f64 = 0.01;

/// One demonstration `X_i ∈ R^{m × T_i}` (Eq. 1) in its own demo time.
///
/// Samples are stored sample-major: sample `t` (demo samples), channel `j` at
/// `samples()[t * n_channels() + j]`, so a `tandem_warp::SignalRef` can borrow them.
/// Every value is finite and there are at least 2 samples.
///
/// Serde form: the JSON document of [`Demonstration::from_json_str`]
/// (`{"channels", "dt_s", "samples"}`); deserializing validates like
/// [`Demonstration::new`] (the source label is not persisted).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(try_from = "DemoJson", into = "DemoJson")]
pub struct Demonstration {
    source: String,
    channel_names: Vec<String>,
    samples: Vec<f64>,
    dt_s: f64,
    period: PeriodSource,
    /// 1-based file line of each sample, for a demonstration read from CSV (errors about a
    /// sample name its line, [`Demonstration::locate`]); `None` otherwise.
    lines: Option<std::sync::Arc<[usize]>>,
    /// The `t` column's worst step deviation from the period (s) and its 1-based line, when
    /// it exceeds [`JITTER_NOTE`] of the period (reported by [`Demonstration::period_note`]).
    jitter: Option<(f64, usize)>,
    /// Where the header is, for a demonstration read from CSV (errors about its channel set
    /// or period name the header's line and the column, [`Demonstration::header_at`]).
    header: Option<Header>,
}

/// The header of a CSV demonstration: its 1-based line, the 1-based column (field number)
/// of each channel in channel order, and of the `t` column if there is one.
#[derive(Clone, Debug)]
struct Header {
    line: usize,
    columns: std::sync::Arc<[usize]>,
    t_column: Option<usize>,
}

/// A log with its own times put on an even grid ([`Demonstration::regrid_csv_str`], what
/// `tandem fit --resample` and `tandem record --resample` do), with the map from the file's
/// rows to the grid's samples: a series logged one value per row beside the file is put on
/// the same grid through it ([`Regridded::interpolate`] for a quantity, [`Regridded::bin_of`]
/// for events, [`Regridded::nearest`] for states), as the model's own
/// [`crate::TaskModel::resample_execution`] does for a log finer than the model.
#[derive(Clone, Debug, PartialEq)]
pub struct Regridded {
    /// The demonstration on the grid `t_0 + k·Δt_s`.
    pub demonstration: Demonstration,
    /// One sentence saying what was done (rows, step range, grid), for a note.
    pub note: String,
    /// For every row `r` of the file, the grid sample nearest to its time
    /// (`round((t_r − t_0)/Δt_s)`): per-row events are merged through it.
    pub bin_of: Vec<usize>,
    /// For every grid sample `k`, the row nearest to it in time: per-row states are read
    /// through it.
    pub nearest: Vec<usize>,
    /// For every grid sample, the row at or before it and the fraction `u ∈ [0, 1]` of the
    /// way to the next row (the linear interpolation of the channels).
    segments: Vec<(usize, f64)>,
}

impl Regridded {
    /// Number of rows of the file that was regridded.
    #[must_use]
    pub fn n_rows(&self) -> usize {
        self.bin_of.len()
    }

    /// A series logged one value per row of the file (an execution's reference-time log),
    /// interpolated linearly at the grid times, as the channels are.
    ///
    /// # Errors
    /// [`Error::BadData`] when `per_row` does not have one value per row.
    pub fn interpolate(&self, what: &str, per_row: &[f64]) -> Result<Vec<f64>> {
        if per_row.len() != self.n_rows() {
            return Err(Error::BadData {
                what: what.into(),
                why: format!(
                    "{} values, but {} has {} rows (one value per row)",
                    per_row.len(),
                    self.demonstration.source(),
                    self.n_rows()
                ),
            });
        }
        Ok(self
            .segments
            .iter()
            .map(|&(a, u)| {
                let b = (a + 1).min(per_row.len() - 1);
                per_row[a] + u * (per_row[b] - per_row[a])
            })
            .collect())
    }
}

/// Equal channels, samples, period and source label; where the period came from
/// ([`Demonstration::period_source`]) is not compared.
impl PartialEq for Demonstration {
    fn eq(&self, other: &Self) -> bool {
        self.source == other.source
            && self.channel_names == other.channel_names
            && self.samples == other.samples
            && self.dt_s == other.dt_s
    }
}

/// Where a demonstration's sample period `Δt_s` came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PeriodSource {
    /// The file's own time: a CSV `t` column or a JSON `dt_s` key.
    File,
    /// The caller gave it ([`Demonstration::new`], or deserialized from a document with `dt_s`).
    Given,
    /// The file has no time of its own: the reader's `dt_s` argument, or [`DEFAULT_DT_S`]
    /// without one, was assumed. [`Demonstration::period_note`] says so in words.
    Assumed,
}

/// The text of `path` and the name errors use for it.
fn read_text(path: &Path) -> Result<(String, String)> {
    let file = path.display().to_string();
    match std::fs::read_to_string(path) {
        Ok(text) => Ok((text, file)),
        Err(source) => Err(Error::Io { file, source }),
    }
}

impl Demonstration {
    /// Builds a demonstration from channel names, sample-major samples and the sample
    /// period `dt_s` (seconds). The source label (used in error messages) is `<memory>`.
    ///
    /// Errors: no channels, empty or duplicated names, `samples.len()` not a multiple of
    /// the channel count, fewer than 2 samples, a non-finite value or one beyond
    /// `±`[`MAX_ABS_VALUE`], `dt_s` not finite > 0.
    pub fn new(channel_names: Vec<String>, samples: Vec<f64>, dt_s: f64) -> Result<Self> {
        let demo = Self {
            source: "<memory>".to_owned(),
            channel_names,
            samples,
            dt_s,
            period: PeriodSource::Given,
            lines: None,
            jitter: None,
            header: None,
        };
        demo.check()?;
        Ok(demo)
    }

    /// Where sample `t` (0-based) is, for error messages: `file:line` when read from a CSV
    /// file (1-based line), else `source, sample t (0-based)`.
    pub fn locate(&self, t: usize) -> String {
        match self.lines.as_deref().and_then(|l| l.get(t)) {
            Some(line) => format!("{}:{line}", self.source),
            None => format!("{}, sample {t} (0-based)", self.source),
        }
    }

    /// Where the header of a demonstration read from CSV is, for errors about its channels
    /// or its period: the 1-based line of the header and the 1-based column of `channel`
    /// (`Some(name)`), of the `t` column (`None`), or `None` when there is no such column.
    /// `(None, None)` for a demonstration not read from CSV.
    pub fn header_at(&self, channel: Option<&str>) -> (Option<usize>, Option<usize>) {
        let Some(h) = &self.header else {
            return (None, None);
        };
        let column = match channel {
            Some(name) => self
                .channel_index(name)
                .and_then(|j| h.columns.get(j).copied()),
            None => h.t_column,
        };
        (Some(h.line), column)
    }

    /// Where [`Demonstration::dt_s`] came from (the file, the caller, or an assumption).
    pub fn period_source(&self) -> PeriodSource {
        self.period
    }

    /// A sentence saying which sample period was assumed for a file without a time of its
    /// own ([`PeriodSource::Assumed`]), and how to state the real one; `None` otherwise.
    /// The command line prints it, the Python package raises it as a warning.
    ///
    /// For a `t` column whose times deviate from the even grid by more than [`JITTER_NOTE`]
    /// of a period (but within [`JITTER_TOLERANCE`], else the file is refused), the sentence
    /// gives the worst deviation and its line, and says that the samples are taken as evenly
    /// spaced.
    pub fn period_note(&self) -> Option<String> {
        if let (PeriodSource::File, Some((dev, line))) = (self.period, self.jitter) {
            return Some(format!(
                "{}:{line}: time column `t`: times deviate from the even grid of period {} s \
                 ({} Hz) by up to {:.3} ms here ({:.1} % of a period; tandem accepts up to {} \
                 %): the samples are taken to be evenly spaced",
                self.source,
                round_s(self.dt_s),
                round_s(1.0 / self.dt_s),
                dev * 1e3,
                100.0 * dev / self.dt_s,
                100.0 * JITTER_TOLERANCE
            ));
        }
        (self.period == PeriodSource::Assumed).then(|| {
            format!(
                "{}: no time column `t`: its samples are taken to be {} s apart ({} Hz); \
                 if it was logged at another rate, add a column `t` (seconds)",
                self.source,
                round_s(self.dt_s),
                round_s(1.0 / self.dt_s)
            )
        })
    }

    /// The `t` column's worst deviation from its even grid (s) and the 1-based line where it
    /// is, when it exceeds [`JITTER_NOTE`] of a period (what [`Demonstration::period_note`]
    /// reports); `None` otherwise.
    pub fn jitter(&self) -> Option<(f64, usize)> {
        self.jitter
    }

    fn with_period_source(mut self, period: PeriodSource) -> Self {
        self.period = period;
        self
    }

    /// Replaces the source label that error messages use to name this demonstration.
    #[must_use]
    pub fn with_source(mut self, source: impl Into<String>) -> Self {
        self.source = source.into();
        self
    }

    fn check(&self) -> Result<()> {
        let bad = |why: String| Error::BadData {
            what: self.source.clone(),
            why,
        };
        if self.channel_names.is_empty() {
            return Err(bad("no channels".into()));
        }
        let mut seen = BTreeMap::new();
        for (j, name) in self.channel_names.iter().enumerate() {
            if name.is_empty() {
                return Err(bad(format!("channel {j} has an empty name")));
            }
            if let Some(k) = seen.insert(name.as_str(), j) {
                return Err(bad(format!("channel `{name}` appears twice ({k} and {j})")));
            }
        }
        let m = self.channel_names.len();
        if self.samples.len() % m != 0 {
            return Err(bad(format!(
                "{} values are not a whole number of {m}-channel samples",
                self.samples.len()
            )));
        }
        if self.samples.len() / m < 2 {
            return Err(Error::TooFewSamples {
                at: self.source.clone(),
                found: self.samples.len() / m,
            });
        }
        if let Some(k) = self.samples.iter().position(|v| !v.is_finite()) {
            return Err(bad(format!(
                "sample {}, channel `{}`: non-finite value {}",
                k / m,
                self.channel_names[k % m],
                self.samples[k]
            )));
        }
        if let Some(k) = first_too_large(&self.samples) {
            return Err(bad(format!(
                "sample {}, channel `{}`: {}",
                k / m,
                self.channel_names[k % m],
                too_large_why(self.samples[k])
            )));
        }
        if !(self.dt_s.is_finite() && self.dt_s > 0.0) {
            return Err(bad(format!(
                "sample period {} s is not finite > 0",
                self.dt_s
            )));
        }
        Ok(())
    }

    /// The source label (file path, or `<memory>`).
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Channel names, in column order.
    pub fn channel_names(&self) -> &[String] {
        &self.channel_names
    }

    /// Number of channels `m`.
    pub fn n_channels(&self) -> usize {
        self.channel_names.len()
    }

    /// Number of samples `T_i` (demo samples).
    pub fn n_samples(&self) -> usize {
        self.samples.len() / self.channel_names.len()
    }

    /// Sample period `Δt_s`, seconds.
    pub fn dt_s(&self) -> f64 {
        self.dt_s
    }

    /// All samples, sample-major (`T_i × m`).
    pub fn samples(&self) -> &[f64] {
        &self.samples
    }

    /// Sample `t` (demo time, samples) as `m` values. Panics if `t ≥ n_samples()`.
    pub fn sample(&self, t: usize) -> &[f64] {
        let m = self.n_channels();
        &self.samples[t * m..(t + 1) * m]
    }

    /// Index of channel `name`, if present.
    pub fn channel_index(&self, name: &str) -> Option<usize> {
        self.channel_names.iter().position(|c| c == name)
    }

    /// This demonstration with its channels in the order of `names`.
    ///
    /// Errors with [`Error::ChannelMismatch`] when the channel sets differ.
    pub fn conform_to(&self, names: &[String]) -> Result<Cow<'_, Self>> {
        if self.channel_names == names {
            return Ok(Cow::Borrowed(self));
        }
        // The header's first column whose name the reference does not have, if any.
        let stranger = self
            .channel_names
            .iter()
            .find(|c| !names.contains(c))
            .map(String::as_str);
        let (line, column) = self.header_at(stranger);
        let mismatch = || Error::ChannelMismatch {
            file: self.source.clone(),
            line,
            column: stranger.and(column),
            expected: names.to_vec(),
            found: self.channel_names.clone(),
        };
        if names.len() != self.channel_names.len() {
            return Err(mismatch());
        }
        let map = names
            .iter()
            .map(|n| self.channel_index(n).ok_or_else(mismatch))
            .collect::<Result<Vec<_>>>()?;
        let m = names.len();
        let mut samples = Vec::with_capacity(self.samples.len());
        for row in self.samples.chunks_exact(m) {
            samples.extend(map.iter().map(|&j| row[j]));
        }
        Ok(Cow::Owned(Self {
            source: self.source.clone(),
            channel_names: names.to_vec(),
            samples,
            dt_s: self.dt_s,
            period: self.period,
            lines: self.lines.clone(),
            jitter: self.jitter,
            header: self.header.as_ref().map(|h| Header {
                columns: map.iter().map(|&j| h.columns[j]).collect(),
                ..h.clone()
            }),
        }))
    }

    /// Reads a CSV file: see [`Demonstration::from_csv_str`].
    pub fn from_csv_path(path: impl AsRef<Path>, dt_s: Option<f64>) -> Result<Self> {
        let (text, file) = read_text(path.as_ref())?;
        Self::from_csv_str(&text, &file, dt_s)
    }

    /// Parses CSV text: a header row of channel names, then one row of numbers per sample.
    ///
    /// A column named `t` (seconds) is optional; when present it is removed from the
    /// channels, must be strictly increasing with every time within [`JITTER_TOLERANCE`]
    /// (25 %) of a period of the even grid of its mean spacing, and sets `Δt_s` to that
    /// spacing, snapped to a whole rate in Hz within 0.1 % ([`period_from_times`]); `dt_s`
    /// is then not used (the command line refuses a `--dt` that disagrees). Otherwise
    /// `Δt_s` is `dt_s`, or [`DEFAULT_DT_S`] when `None`.
    /// The text is split by [`CsvTable`] (blank lines skipped, header names may be
    /// double-quoted); a value beyond `±`[`MAX_ABS_VALUE`] is rejected.
    /// `file` names the input in errors, which carry the 1-based line and field number.
    pub fn from_csv_str(text: &str, file: &str, dt_s: Option<f64>) -> Result<Self> {
        let table = CsvTable::parse(text, file)?;
        let names = table.names();
        let t_col = table.column("t");
        if let Some(j) = names.iter().position(|n| crate::checks::time_like(n)) {
            return Err(Error::TimeLikeChannel {
                file: file.into(),
                line: Some(table.header_line()),
                column: Some(j + 1),
                channel: names[j].clone(),
            });
        }
        if names.len() == usize::from(t_col.is_some()) {
            return Err(Error::BadHeader {
                file: file.into(),
                line: table.header_line(),
                column: 1,
                why: "no data channels".into(),
            });
        }
        let mut samples = Vec::with_capacity(table.rows().len() * names.len());
        let mut times: Vec<(usize, f64)> = Vec::new();
        for (r, row) in table.rows().iter().enumerate() {
            for (j, (name, text)) in names.iter().zip(&row.fields).enumerate() {
                let value = table.number(r, j)?;
                if Some(j) == t_col {
                    times.push((row.line, value));
                    continue;
                }
                if value.abs() > MAX_ABS_VALUE {
                    return Err(Error::TooLarge {
                        file: file.into(),
                        line: row.line,
                        column: j + 1,
                        channel: name.clone(),
                        text: (*text).into(),
                    });
                }
                samples.push(value);
            }
        }
        let n = table.rows().len();
        if n < 2 {
            // The last line the file has: its only data row, or the header.
            let last = table.rows().last().map_or(table.header_line(), |r| r.line);
            return Err(Error::TooFewSamples {
                at: format!("{file}:{last}:1"),
                found: n,
            });
        }
        let rows = table.rows();
        if let (Some(col), Some(k)) = (
            t_col,
            (1..n).find(|&k| rows[k].fields == rows[k - 1].fields),
        ) {
            return Err(repeated_row(file, rows[k].line, rows[k - 1].line, col + 1));
        }
        let ((dt_s, jitter), period) = match t_col {
            Some(col) => (
                time_column_period(&times, file, col + 1)?,
                PeriodSource::File,
            ),
            None => ((dt_s.unwrap_or(DEFAULT_DT_S), None), PeriodSource::Assumed),
        };
        let channel_names = names
            .iter()
            .enumerate()
            .filter(|(j, _)| Some(*j) != t_col)
            .map(|(_, n)| n.clone())
            .collect();
        let mut demo = Self::new(channel_names, samples, dt_s)?
            .with_source(file)
            .with_period_source(period);
        demo.jitter = jitter;
        demo.lines = Some(table.rows().iter().map(|r| r.line).collect());
        demo.header = Some(Header {
            line: table.header_line(),
            columns: (0..names.len())
                .filter(|&j| Some(j) != t_col)
                .map(|j| j + 1)
                .collect(),
            t_column: t_col.map(|j| j + 1),
        });
        Ok(demo)
    }

    /// Reads a CSV file resampled onto an even grid: see
    /// [`Demonstration::from_csv_str_resampled`].
    pub fn from_csv_path_resampled(
        path: impl AsRef<Path>,
        dt_s: Option<f64>,
    ) -> Result<(Self, String)> {
        let (text, file) = read_text(path.as_ref())?;
        Self::from_csv_str_resampled(&text, &file, dt_s)
    }

    /// Parses CSV text with an irregular time column `t` (seconds) and resamples it onto the
    /// even grid `t_0 + k·Δt_s` (`k = 0, 1, …` up to the last time): `Δt_s` is `dt_s`, or
    /// the logger's period: the span `t_last − t_0` over the number of periods it holds
    /// (each step counted as its whole number of median steps, at least one, so a dropped
    /// sample counts two and jitter averages out), snapped like [`period_from_times`].
    /// Every channel is interpolated
    /// linearly between the two neighbouring rows, except a quaternion block of the default
    /// [`ChannelSchema`] (`qx, qy, qz, qw`), interpolated by slerp, and a channel whose every
    /// value is 0 or 1 (an on/off signal), which holds the earlier row's value: the one
    /// resampling policy ([`crate::resample`]; a row within 1e-9 of a step from a grid time
    /// is taken as it is). Returns the
    /// demonstration and a sentence saying what was done (for a note).
    ///
    /// Errors: as [`Demonstration::from_csv_str`] for the table and values; no `t` column;
    /// times not strictly increasing; a gap longer than [`MAX_RESAMPLE_GAP`] grid periods
    /// (resampling would invent the samples of a whole stretch).
    pub fn from_csv_str_resampled(
        text: &str,
        file: &str,
        dt_s: Option<f64>,
    ) -> Result<(Self, String)> {
        let r = Self::regrid_csv_str(text, file, dt_s)?;
        Ok((r.demonstration, r.note))
    }

    /// Reads a CSV file onto an even grid with the row mapping: see
    /// [`Demonstration::regrid_csv_str`].
    pub fn regrid_csv_path(path: impl AsRef<Path>, dt_s: Option<f64>) -> Result<Regridded> {
        let (text, file) = read_text(path.as_ref())?;
        Self::regrid_csv_str(&text, &file, dt_s)
    }

    /// [`Demonstration::from_csv_str_resampled`], keeping how the file's rows map onto the
    /// grid ([`Regridded`]), so that series logged beside the file, one value per row (an
    /// execution's reference-time log and correction flags), can be put on the same grid.
    ///
    /// # Errors
    /// As [`Demonstration::from_csv_str_resampled`].
    pub fn regrid_csv_str(text: &str, file: &str, dt_s: Option<f64>) -> Result<Regridded> {
        Self::regrid_csv_str_with(text, file, dt_s, &ChannelSchema::default())
    }

    /// [`Demonstration::regrid_csv_str`] with the quaternion blocks of `schema` (the
    /// default's is `qx, qy, qz, qw`) interpolated by slerp: the one resampling policy
    /// ([`crate::resample`]), as for executions and bags.
    ///
    /// # Errors
    /// As [`Demonstration::from_csv_str_resampled`].
    pub fn regrid_csv_str_with(
        text: &str,
        file: &str,
        dt_s: Option<f64>,
        schema: &ChannelSchema,
    ) -> Result<Regridded> {
        let table = CsvTable::parse(text, file)?;
        if let Some(j) = table
            .names()
            .iter()
            .position(|n| crate::checks::time_like(n))
        {
            return Err(Error::TimeLikeChannel {
                file: file.into(),
                line: Some(table.header_line()),
                column: Some(j + 1),
                channel: table.names()[j].clone(),
            });
        }
        let Some(tc) = table.column("t") else {
            return Err(Error::BadHeader {
                file: file.into(),
                line: table.header_line(),
                column: 1,
                why: "no time column `t`: resampling needs the time of every row".into(),
            });
        };
        let n = table.rows().len();
        let mut times = Vec::with_capacity(n);
        for r in 0..n {
            times.push(table.number(r, tc)?);
        }
        if n < 2 {
            return Err(Error::TooFewSamples {
                at: format!(
                    "{file}:{}:1",
                    table.rows().last().map_or(table.header_line(), |r| r.line)
                ),
                found: n,
            });
        }
        let line = |k: usize| table.rows()[k].line;
        for k in 1..n {
            if table.rows()[k].fields == table.rows()[k - 1].fields {
                return Err(repeated_row(file, line(k), line(k - 1), tc + 1));
            }
            if times[k] <= times[k - 1] {
                return Err(Error::BadTime {
                    file: file.into(),
                    line: line(k),
                    column: tc + 1,
                    why: format!(
                        "{} does not increase after {} (times must be strictly increasing; \
                         sort the log or remove repeated rows)",
                        times[k],
                        times[k - 1]
                    ),
                });
            }
        }
        let mut steps: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
        steps.sort_by(f64::total_cmp);
        let period = match dt_s {
            Some(p) => p,
            // The logger's period (`logger_period`: the span over the steps counted in
            // median steps, snapped); the grid is never coarser than the mean step.
            None => logger_period(&times).expect("at least 2 strictly increasing times"),
        };
        if !(period.is_finite() && period > 0.0) {
            return Err(Error::BadParam {
                name: "dt_s",
                why: format!("{period} s is not a finite period > 0"),
            });
        }
        for k in 1..n {
            let gap = times[k] - times[k - 1];
            if gap > MAX_RESAMPLE_GAP * period {
                return Err(Error::BadTime {
                    file: file.into(),
                    line: line(k),
                    column: tc + 1,
                    why: format!(
                        "a gap of {} s after {} s ({:.1} periods of {} s): resampling would \
                         invent more than {MAX_RESAMPLE_GAP} missing samples; record the task \
                         again or cut the file there",
                        round_s(gap),
                        times[k - 1],
                        gap / period,
                        round_s(period)
                    ),
                });
            }
        }
        let names: Vec<String> = table
            .names()
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != tc)
            .map(|(_, n)| n.clone())
            .collect();
        let cols: Vec<usize> = (0..table.names().len()).filter(|&j| j != tc).collect();
        let mut values: Vec<Vec<f64>> = Vec::with_capacity(cols.len());
        for &j in &cols {
            let mut v = Vec::with_capacity(n);
            for r in 0..n {
                let x = table.number(r, j)?;
                if x.abs() > MAX_ABS_VALUE {
                    return Err(Error::TooLarge {
                        file: file.into(),
                        line: line(r),
                        column: j + 1,
                        channel: table.names()[j].clone(),
                        text: table.rows()[r].fields[j].into(),
                    });
                }
                v.push(x);
            }
            values.push(v);
        }
        // The one resampling policy: quaternion blocks of the schema by slerp, 0/1 channels
        // held, the rest linear (`crate::resample`).
        let policy = Interpolation::for_channels(&names, schema, |c| {
            resample::is_flag(values[c].iter().copied())
        });
        let width = cols.len();
        let (mut ra, mut rb, mut row) = (vec![0.0; width], vec![0.0; width], vec![0.0; width]);
        let t0 = times[0];
        let count = ((times[n - 1] - t0) / period + 1e-9).floor() as usize + 1;
        let mut samples = Vec::with_capacity(count * cols.len());
        let mut segments = Vec::with_capacity(count);
        let mut nearest = Vec::with_capacity(count);
        let mut seg = 0;
        for k in 0..count {
            let t = t0 + k as f64 * period;
            while seg + 2 < n && times[seg + 1] <= t {
                seg += 1;
            }
            let (ta, tb) = (times[seg], times[seg + 1]);
            let u = ((t - ta) / (tb - ta)).clamp(0.0, 1.0);
            segments.push((seg, u));
            nearest.push(if u < 0.5 { seg } else { seg + 1 });
            for (c, v) in values.iter().enumerate() {
                (ra[c], rb[c]) = (v[seg], v[seg + 1]);
            }
            policy.row(&ra, &rb, u, &mut row);
            samples.extend_from_slice(&row);
        }
        let mut demo = Self::new(names, samples, period)?
            .with_source(file)
            .with_period_source(PeriodSource::File);
        demo.header = Some(Header {
            line: table.header_line(),
            columns: cols.iter().map(|&j| j + 1).collect(),
            t_column: Some(tc + 1),
        });
        let note = format!(
            "{file}: resampled {n} rows (steps {} – {} s) onto {count} samples {} s apart ({} \
             Hz), channels interpolated linearly, quaternions by slerp, 0/1 channels held",
            round_s(steps[0]),
            round_s(steps[steps.len() - 1]),
            round_s(period),
            round_s(1.0 / period)
        );
        let bin_of = times
            .iter()
            .map(|&t| (((t - t0) / period).round() as usize).min(count - 1))
            .collect();
        Ok(Regridded {
            demonstration: demo,
            note,
            bin_of,
            nearest,
            segments,
        })
    }

    /// Reads a JSON file: see [`Demonstration::from_json_str`].
    pub fn from_json_path(path: impl AsRef<Path>, dt_s: Option<f64>) -> Result<Self> {
        let (text, file) = read_text(path.as_ref())?;
        Self::from_json_str(&text, &file, dt_s)
    }

    /// Parses a JSON document `{"channels": [names], "dt_s": seconds, "samples": [[row], …]}`
    /// (one row of `m` numbers per sample; `dt_s` optional, defaulting to `dt_s` then
    /// [`DEFAULT_DT_S`]; no other keys). Errors carry the 1-based line and character column.
    pub fn from_json_str(text: &str, file: &str, dt_s: Option<f64>) -> Result<Self> {
        if text.trim().is_empty() {
            return Err(Error::EmptyFile { file: file.into() });
        }
        let doc: DemoJson = serde_json::from_str(text).map_err(|e| Error::Json {
            file: file.into(),
            line: e.line(),
            column: e.column(),
            why: e.to_string(),
        })?;
        let m = doc.channels.len();
        let json_err = |row: Option<usize>, why: String| {
            let (line, column) = row
                .and_then(|r| json_row_position(text, Some(r)))
                .unwrap_or((1, 1));
            Error::Json {
                file: file.into(),
                line,
                column,
                why,
            }
        };
        if m == 0 {
            return Err(json_err(None, "`channels` is empty".into()));
        }
        for (r, row) in doc.samples.iter().enumerate() {
            if row.len() != m {
                return Err(json_err(
                    Some(r),
                    format!(
                        "ragged row: sample {r} has {} values, expected {m}",
                        row.len()
                    ),
                ));
            }
        }
        if let Some((r, j)) = doc.samples.iter().enumerate().find_map(|(r, row)| {
            let j = first_too_large(row)?;
            Some((r, j))
        }) {
            return Err(json_err(
                Some(r),
                format!(
                    "sample {r}, channel `{}`: {}",
                    doc.channels[j],
                    too_large_why(doc.samples[r][j])
                ),
            ));
        }
        if doc.samples.len() < 2 {
            let (line, column) = json_row_position(text, None).unwrap_or((1, 1));
            return Err(Error::TooFewSamples {
                at: format!("{file}:{line}:{column}"),
                found: doc.samples.len(),
            });
        }
        let source = if doc.dt_s.is_some() {
            PeriodSource::File
        } else {
            PeriodSource::Assumed
        };
        let period = doc.dt_s.or(dt_s).unwrap_or(DEFAULT_DT_S);
        if !(period.is_finite() && period > 0.0) {
            return Err(json_err(
                None,
                format!("`dt_s` = {period} is not finite > 0"),
            ));
        }
        let samples = doc.samples.into_iter().flatten().collect();
        Demonstration::new(doc.channels, samples, period)
            .map(|d| d.with_source(file).with_period_source(source))
            .map_err(|e| match e {
                Error::BadData { why, .. } => json_err(None, why),
                other => other,
            })
    }

    /// Serializes to the JSON document [`Demonstration::from_json_str`] reads.
    pub fn to_json_string(&self) -> String {
        let doc = DemoJsonRef {
            channels: &self.channel_names,
            dt_s: self.dt_s,
            samples: self.samples.chunks_exact(self.n_channels()).collect(),
        };
        serde_json::to_string(&doc).expect("serializing numbers and strings cannot fail")
    }
}

/// A period or rate without floating-point noise (`0.01`, not `0.009999…`).
pub(crate) fn round_s(v: f64) -> f64 {
    (v * 1e9).round() / 1e9
}

/// Index of the first value beyond `±`[`MAX_ABS_VALUE`].
fn first_too_large(values: &[f64]) -> Option<usize> {
    values.iter().position(|v| v.abs() > MAX_ABS_VALUE)
}

/// Why a value beyond `±`[`MAX_ABS_VALUE`] is rejected.
fn too_large_why(value: f64) -> String {
    format!(
        "value {value:e} is beyond ±{MAX_ABS_VALUE:e} (squared differences would overflow; \
         check the units)"
    )
}

/// The sample period (s) of evenly spaced times `t_0 … t_{n−1}` (s): the mean spacing
/// `(t_{n−1} − t_0)/(n − 1)`, snapped to `1/f` when it is within 0.1 % of the period of a
/// whole rate `f ≥ 1` Hz (a 100 Hz log with jitter gives exactly 0.01 s), else rounded to
/// the nanosecond. `None` for fewer than 2 times or a spacing that is not finite > 0.
#[must_use]
pub fn period_from_times(times: &[f64]) -> Option<f64> {
    let n = times.len();
    if n < 2 {
        return None;
    }
    let mean = (times[n - 1] - times[0]) / (n - 1) as f64;
    if !(mean.is_finite() && mean > 0.0) {
        return None;
    }
    let rate = (1.0 / mean).round();
    if rate >= 1.0 && (1.0 / rate - mean).abs() <= 1e-3 * mean {
        return Some(1.0 / rate);
    }
    Some(round_s(mean))
}

/// The error for a row that repeats the row before it field for field (a logger that wrote
/// one sample twice), at line `line` (the earlier at `previous`), column `column` (`t`).
fn repeated_row(file: &str, line: usize, previous: usize, column: usize) -> Error {
    Error::BadTime {
        file: file.into(),
        line,
        column,
        why: format!(
            "line {line} repeats line {previous} exactly (the logger wrote one sample twice): \
             remove the repeated line (`uniq FILE > FIXED` drops repeated consecutive lines; \
             remove the same row of any file logged beside it)"
        ),
    }
}

/// How far (relative) the loggers' periods of resampled files may lie from the period most
/// of them share for every file to be put onto that one grid without a period given
/// (`tandem fit --resample` without `--dt`, Python `fit(resample=True)` without `dt_s`):
/// clocks that drift (a few per cent at most), not files logged at other rates or in other
/// units, which stay the fit's error naming the odd file and the period to give
/// (docs/decisions.md, "Resampling puts drifting loggers onto one grid").
pub const DRIFT_TOLERANCE: f64 = 0.10;

/// The period (s) most of `periods` (s, one per file) share (each within [`DT_TOLERANCE`]
/// of it; ties: the earlier file) and how many share it, when they do not all share it but every one lies within
/// [`DRIFT_TOLERANCE`] of it; `None` otherwise (all agree, or one is another rate).
#[must_use]
pub fn drifting_majority(periods: &[f64]) -> Option<(f64, usize)> {
    let agree = |a: f64, b: f64| (a - b).abs() <= DT_TOLERANCE * b;
    let shared = |p: f64| periods.iter().filter(|&&o| agree(o, p)).count();
    let (best, count) = periods
        .iter()
        .map(|&p| (p, shared(p)))
        .reduce(|a, b| if b.1 > a.1 { b } else { a })?;
    let drifting = count < periods.len()
        && periods
            .iter()
            .all(|&p| p.is_finite() && (p - best).abs() <= DRIFT_TOLERANCE * best);
    drifting.then_some((best, count))
}

/// The period (s) of a logger whose stamps `times` (s, strictly increasing) may jitter and
/// miss samples: the span `t_last − t_0` over the number of periods it holds, each step
/// counted as its whole number of median steps (at least one, so a dropped sample counts
/// two), snapped like [`period_from_times`]. Jitter averages out over the log (the median
/// step alone is off by a fraction of the jitter); the count is exact while every stamp is
/// within a quarter period of its grid, and beyond that it can only grow, so the period is
/// never longer than the mean step. `None` for fewer than 2 times or times that do not
/// increase. Used by [`Demonstration::regrid_csv_str`] and for the topics of a ROS 2 bag.
#[must_use]
pub fn logger_period(times: &[f64]) -> Option<f64> {
    if times.len() < 2
        || times
            .windows(2)
            .any(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
    {
        return None;
    }
    let mut steps: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    steps.sort_by(f64::total_cmp);
    let median = steps[steps.len() / 2];
    let periods: f64 = times
        .windows(2)
        .map(|w| ((w[1] - w[0]) / median).round().max(1.0))
        .sum();
    period_from_times(&[0.0, (times[times.len() - 1] - times[0]) / periods])
}

/// Checks a `t` column and returns its period ([`period_from_times`]) and, when some time
/// deviates from the even grid by more than [`JITTER_NOTE`] of a period, the worst deviation
/// (s) and its line. The grid is `t_0 + i·p` with `p` the mean spacing (exactly the line
/// through the first and the last time); every time must lie within [`JITTER_TOLERANCE`] of
/// a period of it, which refuses a dropped or repeated sample (at least half a period off).
fn time_column_period(
    times: &[(usize, f64)],
    file: &str,
    column: usize,
) -> Result<(f64, Option<(f64, usize)>)> {
    let bad = |line: usize, why: String| Error::BadTime {
        file: file.into(),
        line,
        column,
        why,
    };
    for w in times.windows(2) {
        if w[1].1 <= w[0].1 {
            return Err(bad(
                w[1].0,
                format!(
                    "{} does not increase after {} (times must be strictly increasing; sort \
                     the log or remove repeated rows)",
                    w[1].1, w[0].1
                ),
            ));
        }
    }
    let n = times.len();
    let (t0, mean) = (times[0].1, (times[n - 1].1 - times[0].1) / (n - 1) as f64);
    let (dev, line) = times
        .iter()
        .enumerate()
        .map(|(i, &(line, t))| ((t - (t0 + i as f64 * mean)).abs(), line))
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .expect("at least 2 times");
    if dev > JITTER_TOLERANCE * mean {
        return Err(bad(
            line,
            format!(
                "this time is {:.3} ms off the even grid of the file's mean period {} s \
                 ({:.1} % of a period; tandem accepts up to {} %: a dropped or repeated \
                 sample, or an irregular log): resample the log onto an even grid (`--resample` \
                 of `tandem fit` or `tandem record`, `resample=True` of Python's `fit` or \
                 `record_round`), or remove the `t` column and give the period (`tandem fit \
                 --dt`)",
                dev * 1e3,
                (mean * 1e6).round() / 1e6,
                100.0 * dev / mean,
                100.0 * JITTER_TOLERANCE
            ),
        ));
    }
    let values: Vec<f64> = times.iter().map(|&(_, t)| t).collect();
    let period = period_from_times(&values).expect("strictly increasing, at least 2 times");
    Ok((period, (dev > JITTER_NOTE * mean).then_some((dev, line))))
}

/// 1-based (line, column) of the start of row `row` of the top-level `samples` array, or
/// of the array itself when `row` is `None`.
fn json_row_position(text: &str, row: Option<usize>) -> Option<(usize, usize)> {
    let position = |pos: usize| {
        let before = &text[..pos];
        let line = before.matches('\n').count() + 1;
        let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        (line, col)
    };
    let (mut depth, mut in_string, mut escape) = (0usize, false, false);
    let mut string_start = 0;
    let mut last_key: Option<&str> = None;
    let mut in_samples = false;
    let mut count = 0;
    for (pos, ch) in text.char_indices() {
        if in_string {
            if escape {
                escape = false;
            } else if ch == '\\' {
                escape = true;
            } else if ch == '"' {
                in_string = false;
                if depth == 1 {
                    last_key = Some(&text[string_start..pos]);
                }
            }
            continue;
        }
        match ch {
            '"' => {
                in_string = true;
                string_start = pos + 1;
            }
            '[' | '{' => {
                if in_samples && depth == 2 && ch == '[' {
                    if Some(count) == row {
                        return Some(position(pos));
                    }
                    count += 1;
                }
                if depth == 1 && ch == '[' && last_key == Some("samples") {
                    if row.is_none() {
                        return Some(position(pos));
                    }
                    in_samples = true;
                }
                depth += 1;
            }
            ']' | '}' => {
                depth = depth.saturating_sub(1);
                if depth == 1 {
                    in_samples = false;
                }
            }
            _ => {}
        }
    }
    None
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct DemoJson {
    channels: Vec<String>,
    #[serde(default)]
    dt_s: Option<f64>,
    samples: Vec<Vec<f64>>,
}

impl TryFrom<DemoJson> for Demonstration {
    type Error = Error;
    fn try_from(doc: DemoJson) -> Result<Self> {
        let m = doc.channels.len();
        if let Some(r) = doc.samples.iter().position(|row| row.len() != m) {
            return Err(Error::BadData {
                what: "demonstration".into(),
                why: format!("ragged row: sample {r} does not have {m} values"),
            });
        }
        let samples = doc.samples.into_iter().flatten().collect();
        let period = match doc.dt_s {
            Some(_) => PeriodSource::Given,
            None => PeriodSource::Assumed,
        };
        Ok(
            Self::new(doc.channels, samples, doc.dt_s.unwrap_or(DEFAULT_DT_S))?
                .with_period_source(period),
        )
    }
}

impl From<Demonstration> for DemoJson {
    fn from(d: Demonstration) -> Self {
        let m = d.n_channels();
        Self {
            samples: d.samples.chunks_exact(m).map(<[f64]>::to_vec).collect(),
            channels: d.channel_names,
            dt_s: Some(d.dt_s),
        }
    }
}

#[derive(Serialize)]
struct DemoJsonRef<'a> {
    channels: &'a [String],
    dt_s: f64,
    samples: Vec<&'a [f64]>,
}

/// What a scalar channel measures. Only quaternion blocks change the statistics
/// (they are handled on the rotation manifold); the other kinds are documentation for
/// users of the model and are all averaged as numbers (binary channels may be fractional
/// in the mean: docs/decisions.md, "Channel weights and kinds").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ChannelKind {
    /// A Cartesian position coordinate (fixtures: metres).
    Position,
    /// A force (fixtures: newtons).
    Force,
    /// An on/off signal stored as 0/1.
    Binary,
    /// A rate or speed recorded as a channel (under any name but `rate`, which is the
    /// model's derived warp gradient).
    Rate,
    /// Anything else, averaged as a number.
    Scalar,
}

/// Four channels that together hold one unit quaternion, named in `[x, y, z, w]` order.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QuaternionBlock {
    /// Block name, used for its rotation-vector coordinates (`<name>.rx`, `.ry`, `.rz`).
    pub name: String,
    /// The channel names of the `x, y, z, w` components.
    pub channels: [String; 4],
}

/// Channel kinds by name: which channels are quaternion blocks and what the scalars are.
///
/// Default: `x, y, z` position; block `q` = `qx, qy, qz, qw`; `force` force; `tool`
/// binary; any other channel [`ChannelKind::Scalar`].
/// A quaternion block applies only when all four of its channels are present; a block with
/// some but not all channels present is an error at fit time
/// ([`Error::PartialQuaternionBlock`], see [`Demonstration::tangent_names`]). No channel may
/// be named like a coordinate the model derives: `rate`, or `<block>.rx|ry|rz` of a block
/// that is present ([`Error::ReservedChannelName`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ChannelSchema {
    /// Scalar channel kinds by channel name.
    pub kinds: BTreeMap<String, ChannelKind>,
    /// Quaternion blocks.
    pub quaternions: Vec<QuaternionBlock>,
}

impl Default for ChannelSchema {
    fn default() -> Self {
        let kinds = [
            ("x", ChannelKind::Position),
            ("y", ChannelKind::Position),
            ("z", ChannelKind::Position),
            ("force", ChannelKind::Force),
            ("tool", ChannelKind::Binary),
        ]
        .into_iter()
        .map(|(n, k)| (n.to_owned(), k))
        .collect();
        Self {
            kinds,
            quaternions: vec![QuaternionBlock {
                name: "q".into(),
                channels: ["qx", "qy", "qz", "qw"].map(String::from),
            }],
        }
    }
}

impl ChannelSchema {
    /// Kind of scalar channel `name` ([`ChannelKind::Scalar`] when not listed).
    pub fn kind(&self, name: &str) -> ChannelKind {
        self.kinds.get(name).copied().unwrap_or(ChannelKind::Scalar)
    }

    /// Checks that no channel belongs to two quaternion blocks and block names are unique.
    pub fn validate(&self) -> Result<()> {
        let mut seen = BTreeMap::new();
        for (b, block) in self.quaternions.iter().enumerate() {
            if block.name.is_empty() {
                return Err(Error::BadParam {
                    name: "schema.quaternions",
                    why: format!("block {b} has an empty name"),
                });
            }
            for c in &block.channels {
                if seen.insert(c.as_str(), b).is_some() {
                    return Err(Error::BadParam {
                        name: "schema.quaternions",
                        why: format!("channel `{c}` appears in more than one block slot"),
                    });
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drifting_loggers_share_the_majoritys_period() {
        // Agreeing within 1 %: nothing to do.
        assert_eq!(drifting_majority(&[0.01, 0.01005, 0.00996]), None);
        // 7 loggers around 125 Hz (±2 %): 0.007874 s is within 1 % of itself, 0.00787,
        // 0.00790 and 0.00785 (4 files); 0.00787 and 0.00785 share as many and come later.
        let p = [
            0.00800, 0.007874, 0.00787, 0.00790, 0.00808, 0.00809, 0.00785,
        ];
        let (dt, count) = drifting_majority(&p).unwrap();
        assert_eq!(count, 4);
        assert_eq!(dt, 0.007874);
        // One file at another rate (twice the period) or in other units: not drift.
        assert_eq!(drifting_majority(&[0.01, 0.01, 0.02]), None);
        assert_eq!(drifting_majority(&[0.01, 0.0101, 10.0]), None);
        assert_eq!(drifting_majority(&[0.01, 0.0105, f64::NAN]), None);
        // Within 10 % is drift; beyond it is not.
        assert_eq!(drifting_majority(&[0.01, 0.01, 0.0109]), Some((0.01, 2)));
        assert_eq!(drifting_majority(&[0.01, 0.01, 0.0111]), None);
        assert_eq!(drifting_majority(&[]), None);
    }

    #[test]
    fn csv_with_time_column_sets_dt() {
        let d = Demonstration::from_csv_str("t,a,b\n0.0,1,2\n0.02,3,4\n0.04,5,6\n", "f.csv", None)
            .unwrap();
        assert_eq!(d.channel_names(), ["a", "b"]);
        assert_eq!(d.samples(), [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        assert!((d.dt_s() - 0.02).abs() < 1e-15);
        assert_eq!(d.source(), "f.csv");
    }

    /// `n` rows `t,a` at 100 Hz with the times moved by `jitter(i)` seconds.
    fn jittered(n: usize, jitter: impl Fn(usize) -> f64) -> String {
        let mut text = String::from("t,a\n");
        for i in 0..n {
            text.push_str(&format!("{},{i}\n", i as f64 * 0.01 + jitter(i)));
        }
        text
    }

    #[test]
    fn a_jittered_100_hz_log_is_read_at_exactly_0_01_s_with_a_note() {
        // ±1.5 ms of deterministic jitter (15 % of a period), the last time on the grid.
        let text = jittered(500, |i| {
            if i == 0 || i == 499 {
                0.0
            } else {
                0.0015 * (i as f64 * 2.4).sin()
            }
        });
        let d = Demonstration::from_csv_str(&text, "j.csv", None).unwrap();
        assert_eq!(d.dt_s(), 0.01, "snapped to 100 Hz");
        let note = d.period_note().expect("a jitter note");
        assert!(note.starts_with("j.csv:"), "{note}");
        assert!(
            note.contains("period 0.01 s (100 Hz)") && note.contains("up to 25 %"),
            "{note}"
        );
        // Exactly even times: no note, and the period is 0.01 exactly, not 0.009999….
        let even = Demonstration::from_csv_str(&jittered(300, |_| 0.0), "e.csv", None).unwrap();
        assert_eq!(even.dt_s(), 0.01);
        assert_eq!(even.period_note(), None);
    }

    #[test]
    fn a_dropped_sample_or_an_irregular_log_is_refused_with_the_fix() {
        // Sample 100 is missing: every later time is one period late.
        let text = jittered(300, |i| if i >= 100 { 0.01 } else { 0.0 });
        let e = Demonstration::from_csv_str(&text, "d.csv", None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("d.csv:") && e.contains("time column `t`"), "{e}");
        assert!(e.contains("resample the log") && e.contains("--dt"), "{e}");
        // 30 % of a period off at one time.
        let text = jittered(50, |i| if i == 20 { 0.003 } else { 0.0 });
        let e = Demonstration::from_csv_str(&text, "j.csv", None)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("j.csv:22:1:") && e.contains("30.0 % of a period"),
            "{e}"
        );
    }

    #[test]
    fn an_irregular_log_is_resampled_onto_its_median_grid() {
        // 0.01 s steps with sample 3 (t = 0.03) missing; `a` a ramp, `on` a 0/1 signal.
        let text = "t,a,on\n0,0,0\n0.01,1,0\n0.02,2,1\n0.04,4,1\n0.05,5,0\n";
        let (d, note) = Demonstration::from_csv_str_resampled(text, "r.csv", None).unwrap();
        assert_eq!(d.dt_s(), 0.01);
        assert_eq!(d.n_samples(), 6);
        let a: Vec<f64> = (0..6).map(|k| d.sample(k)[0]).collect();
        for (k, v) in a.iter().enumerate() {
            assert!((v - k as f64).abs() < 1e-9, "a[{k}] = {v}");
        }
        let on: Vec<f64> = (0..6).map(|k| d.sample(k)[1]).collect();
        assert_eq!(on, [0.0, 0.0, 1.0, 1.0, 1.0, 0.0], "held, not interpolated");
        assert!(
            note.contains("resampled 5 rows") && note.contains("6 samples 0.01 s apart"),
            "{note}"
        );
        // A gap of 5 periods is not papered over.
        let gap = "t,a\n0,0\n0.01,1\n0.06,6\n0.07,7\n";
        let e = Demonstration::from_csv_str_resampled(gap, "g.csv", None)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("g.csv:4:1:") && e.contains("a gap of 0.05 s"),
            "{e}"
        );
        let none = Demonstration::from_csv_str_resampled("a\n1\n2\n", "n.csv", None);
        assert!(none.unwrap_err().to_string().contains("no time column `t`"));
    }

    #[test]
    fn the_period_of_a_jittered_log_with_dropped_rows_is_the_loggers_rate() {
        // 100 Hz for 10 s, ±1.5 ms jitter (a fixed pseudo-random sequence), rows 200 and
        // 700 dropped: the median step alone is off by a fraction of the jitter,
        // the span over the counted periods is 0.01 s.
        let jitter = |k: u64, amp: f64| {
            let mut h = k.wrapping_add(0x9E37_79B9_7F4A_7C15);
            h = (h ^ (h >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            h = (h ^ (h >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            h ^= h >> 31;
            2.0 * amp * ((h % 1001) as f64 / 1000.0 - 0.5)
        };
        let log = |amp: f64| {
            let mut text = String::from("t,a\n");
            for k in 0..=1000u64 {
                if [200, 700].contains(&k) {
                    continue;
                }
                let j = if k == 0 || k == 1000 {
                    0.0
                } else {
                    jitter(k, amp)
                };
                text.push_str(&format!("{},{}\n", 0.01 * k as f64 + j, k));
            }
            text
        };
        let (d, note) = Demonstration::from_csv_str_resampled(&log(0.0015), "j.csv", None).unwrap();
        assert_eq!(d.dt_s(), 0.01, "{note}");
        assert_eq!(d.n_samples(), 1001);
        assert!(note.contains("999 rows") && note.contains("1001 samples 0.01 s apart (100 Hz)"));
        // Jitter beyond a quarter period blurs a drop and a late row: the count can only
        // grow, so the grid is finer than the mean step, never coarser.
        let (d, _) = Demonstration::from_csv_str_resampled(&log(0.004), "h.csv", None).unwrap();
        assert!(d.dt_s() <= 10.0 / 997.0, "{}", d.dt_s());
    }

    #[test]
    fn a_repeated_row_is_named_with_its_twin_and_the_fix() {
        // Line 4 repeats line 3 field for field (a logger that wrote a sample twice): named,
        // with the fix, read plainly and with --resample alike.
        let text = "t,a\n0,0\n0.01,1\n0.01,1\n0.02,2\n0.03,3\n";
        let plain = Demonstration::from_csv_str(text, "r.csv", None).unwrap_err();
        let resampled = Demonstration::from_csv_str_resampled(text, "r.csv", None).unwrap_err();
        for e in [plain, resampled] {
            let msg = e.to_string();
            assert!(
                msg.starts_with("r.csv:4:1: ") && msg.contains("line 4 repeats line 3 exactly"),
                "{msg}"
            );
            assert!(msg.contains("uniq FILE > FIXED"), "{msg}");
        }
        // Without a time column equal rows are data (the robot held still).
        let still = Demonstration::from_csv_str("a\n0\n1\n1\n2\n", "s.csv", None).unwrap();
        assert_eq!(still.n_samples(), 4);
    }

    #[test]
    fn the_logger_period_counts_dropped_steps_and_snaps() {
        // 50 Hz stamps with one dropped message and a 0.07 % slow clock: 0.02 s exactly.
        let times: Vec<f64> = (0..100)
            .filter(|&k| k != 40)
            .map(|k| k as f64 * 0.020_014)
            .collect();
        assert_eq!(logger_period(&times), Some(0.02));
        assert_eq!(logger_period(&[0.0]), None);
        assert_eq!(logger_period(&[0.0, 0.0]), None);
    }

    #[test]
    fn a_regridded_log_maps_its_rows_for_series_logged_beside_it() {
        // Rows at 0, 0.012, 0.018, 0.03 s (jitter) onto the 0.01 s grid (median step 0.012
        // would snap to 0.012; give the grid): grid times 0, 0.01, 0.02, 0.03.
        let text = "t,a\n0,0\n0.012,12\n0.018,18\n0.03,30\n";
        let r = Demonstration::regrid_csv_str(text, "j.csv", Some(0.01)).unwrap();
        assert_eq!(r.n_rows(), 4);
        assert_eq!(r.demonstration.n_samples(), 4);
        // Each row's nearest grid sample: 0 → 0, 0.012 → 1, 0.018 → 2, 0.03 → 3.
        assert_eq!(r.bin_of, [0, 1, 2, 3]);
        // Each grid sample's nearest row: 0.01 is 0.002 from row 1, 0.02 is 0.002 from row 2.
        assert_eq!(r.nearest, [0, 1, 2, 3]);
        // A ramp logged beside the file is interpolated as the channel `a` is (a = 1000·t).
        let log = r.interpolate("log", &[0.0, 1.2, 1.8, 3.0]).unwrap();
        for (k, v) in log.iter().enumerate() {
            assert!((v - k as f64).abs() < 1e-9, "log[{k}] = {v}");
            assert!((r.demonstration.sample(k)[0] - 10.0 * k as f64).abs() < 1e-9);
        }
        let short = r.interpolate("j.reflog.csv", &[0.0, 1.0]).unwrap_err();
        assert!(
            short.to_string().contains("2 values, but j.csv has 4 rows"),
            "{short}"
        );
        // Two rows in one grid period share its bin: an event on either is kept.
        let dense = "t,a\n0,0\n0.004,0\n0.006,0\n0.01,0\n";
        let r = Demonstration::regrid_csv_str(dense, "d.csv", Some(0.01)).unwrap();
        assert_eq!(r.bin_of, [0, 0, 1, 1]);
        assert_eq!(r.nearest, [0, 3]);
    }

    #[test]
    fn periods_snap_to_whole_rates_only_when_close() {
        assert_eq!(period_from_times(&[0.0, 0.0100004, 0.0200008]), Some(0.01));
        assert_eq!(period_from_times(&[0.0, 1.0 / 3.0]), Some(1.0 / 3.0));
        // 0.0123 s is 81.3 Hz, 0.4 % from 81 Hz: rounded to the nanosecond, not snapped.
        assert_eq!(period_from_times(&[0.0, 0.0123]), Some(0.0123));
        assert_eq!(period_from_times(&[0.0, 2.5]), Some(2.5));
        assert_eq!(period_from_times(&[1.0]), None);
        assert_eq!(period_from_times(&[1.0, 1.0]), None);
    }

    #[test]
    fn csv_without_time_uses_given_or_default_dt() {
        let d = Demonstration::from_csv_str("a\n1\n2\n", "f", Some(0.5)).unwrap();
        assert_eq!(d.dt_s(), 0.5);
        let d = Demonstration::from_csv_str("a\r\n1\r\n2\r\n\r\n", "f", None).unwrap();
        assert_eq!(d.dt_s(), DEFAULT_DT_S);
        assert_eq!(d.n_samples(), 2);
    }

    #[test]
    fn a_time_like_column_is_refused_where_it_stands() {
        for (header, at) in [
            ("x,time,force", "f.csv:2:2"),
            ("t_ms,x", "f.csv:2:1"),
            ("x,header.stamp", "f.csv:2:2"),
        ] {
            let width = header.split(',').count();
            let row = vec!["1"; width].join(",");
            let text = format!("\n{header}\n{row}\n{row}\n");
            let err = Demonstration::from_csv_str(&text, "f.csv", None).unwrap_err();
            assert!(matches!(err, Error::TimeLikeChannel { .. }), "{err}");
            let msg = err.to_string();
            assert!(msg.starts_with(at), "{msg}");
            assert!(msg.contains("rename it to `t`"), "{msg}");
        }
        // In memory the fit refuses it (naming the source).
        let d = Demonstration::new(vec!["x".into(), "Time".into()], vec![0.0; 4], 0.01)
            .unwrap()
            .with_source("demos[1]");
        let err = d.tangent_names(&ChannelSchema::default()).unwrap_err();
        assert!(
            err.to_string().starts_with("demos[1]: column `Time`"),
            "{err}"
        );
    }

    #[test]
    fn the_assumed_period_is_said() {
        let with_t = Demonstration::from_csv_str("t,a\n0,1\n0.01,2\n", "a.csv", None).unwrap();
        assert_eq!(with_t.period_source(), PeriodSource::File);
        assert_eq!(with_t.period_note(), None);
        let without = Demonstration::from_csv_str("a\n1\n2\n", "b.csv", Some(0.001)).unwrap();
        assert_eq!(without.period_source(), PeriodSource::Assumed);
        assert_eq!(
            without.period_note().unwrap(),
            "b.csv: no time column `t`: its samples are taken to be 0.001 s apart (1000 Hz); \
             if it was logged at another rate, add a column `t` (seconds)"
        );
        let json = Demonstration::from_json_str(
            r#"{"channels":["a"],"samples":[[1],[2]]}"#,
            "c.json",
            None,
        )
        .unwrap();
        assert_eq!(json.period_source(), PeriodSource::Assumed);
        assert!(
            json.period_note()
                .unwrap()
                .contains("0.01 s apart (100 Hz)")
        );
        let given = Demonstration::new(vec!["a".into()], vec![1.0, 2.0], 0.01).unwrap();
        assert_eq!(given.period_source(), PeriodSource::Given);
        // Where the period came from does not make two demonstrations different.
        assert_eq!(
            Demonstration::from_csv_str("a\n1\n2\n", "<memory>", None).unwrap(),
            given
        );
    }

    #[test]
    fn json_row_positions() {
        let text = "{\"channels\": [\"a\"],\n \"samples\": [[1],\n   [2, 3]]}";
        assert_eq!(json_row_position(text, None), Some((2, 13)));
        assert_eq!(json_row_position(text, Some(0)), Some((2, 14)));
        assert_eq!(json_row_position(text, Some(1)), Some((3, 4)));
        assert_eq!(json_row_position(text, Some(2)), None);
    }

    #[test]
    fn json_round_trip() {
        let d = Demonstration::new(vec!["a".into(), "b".into()], vec![1.0, 2.0, 3.5, -4.0], 0.1)
            .unwrap();
        let back = Demonstration::from_json_str(&d.to_json_string(), "<memory>", None).unwrap();
        assert_eq!(back, d);
    }

    #[test]
    fn conform_reorders_and_rejects_other_sets() {
        let d = Demonstration::new(vec!["b".into(), "a".into()], vec![1.0, 2.0, 3.0, 4.0], 0.1)
            .unwrap();
        let names = vec!["a".to_owned(), "b".to_owned()];
        assert_eq!(
            d.conform_to(&names).unwrap().samples(),
            [2.0, 1.0, 4.0, 3.0]
        );
        let other = vec!["a".to_owned(), "c".to_owned()];
        assert!(matches!(
            d.conform_to(&other),
            Err(Error::ChannelMismatch { .. })
        ));
    }

    #[test]
    fn new_rejects_bad_shapes() {
        let names = || vec!["a".to_owned(), "b".to_owned()];
        assert!(Demonstration::new(names(), vec![1.0, 2.0, 3.0], 0.1).is_err());
        assert!(matches!(
            Demonstration::new(names(), vec![1.0, 2.0], 0.1),
            Err(Error::TooFewSamples { found: 1, .. })
        ));
        assert!(Demonstration::new(names(), vec![1.0, f64::NAN, 3.0, 4.0], 0.1).is_err());
        assert!(Demonstration::new(names(), vec![1.0, 2.0, 3.0, 4.0], 0.0).is_err());
        assert!(Demonstration::new(vec!["a".into(), "a".into()], vec![0.0; 4], 0.1).is_err());
    }
}
