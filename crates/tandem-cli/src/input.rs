//! Readers for the user's files: demonstrations, executions, reference-time logs,
//! correction flags, need probabilities, parameter files and `--ranges`.
//!
//! Every error names the file and, where there is one, the 1-based line and column.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, Result, anyhow, bail};
use tandem::PlannerParams;
use tandem::lfd::{CsvTable, Demonstration, drifting_majority};
use tandem::sim::needs::NeedProfile;

/// Reads a demonstration or execution: JSON when the extension is `.json`, CSV otherwise.
/// `dt_s` is the sample period for files without a time column (CSV) or `dt_s` key (JSON).
/// The model crate checks every value (finite, within its magnitude limit) and names the
/// file, line and column of a bad one.
pub(crate) fn read_demo(path: &Path, dt_s: Option<f64>) -> Result<Demonstration> {
    let is_json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    Ok(if is_json {
        Demonstration::from_json_path(path, dt_s)?
    } else {
        Demonstration::from_csv_path(path, dt_s)?
    })
}

/// Reads a CSV demonstration with an irregular `t` column resampled onto an even grid
/// (`tandem fit --resample`, `Demonstration::from_csv_str_resampled`: period `dt_s` or the
/// median step), printing what was done as a note. JSON files have no time column to
/// resample and are refused.
pub(crate) fn read_demo_resampled(path: &Path, dt_s: Option<f64>) -> Result<Demonstration> {
    refuse_json(path)?;
    let (demo, what) = Demonstration::from_csv_path_resampled(path, dt_s)?;
    crate::cmd::note(&what);
    Ok(demo)
}

/// `--resample` of a JSON demonstration, refused: it has no time column to resample.
fn refuse_json(path: &Path) -> Result<()> {
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
    {
        bail!(
            "{}: --resample applies to CSV files with a `t` column; a JSON demonstration is \
             already on an even grid (`dt_s`)",
            path.display()
        );
    }
    Ok(())
}

/// Reads `--resample`d CSV demonstrations without `--dt` (`tandem fit --resample`): each onto
/// its logger's period, unless the periods differ only as drifting clocks do
/// (`tandem_lfd::drifting_majority`), in which case every file goes onto the period most of them share,
/// said once in a note. Notes as [`read_demo_resampled`].
pub(crate) fn read_demos_resampled(paths: &[&Path]) -> Result<Vec<Demonstration>> {
    let mut read = Vec::with_capacity(paths.len());
    for &path in paths {
        refuse_json(path)?;
        read.push(Demonstration::from_csv_path_resampled(path, None)?);
    }
    let periods: Vec<f64> = read.iter().map(|(d, _)| d.dt_s()).collect();
    if let Some((dt, count)) = drifting_majority(&periods) {
        for (slot, &path) in read.iter_mut().zip(paths) {
            if !agree_exactly(slot.0.dt_s(), dt) {
                *slot = Demonstration::from_csv_path_resampled(path, Some(dt))?;
            }
        }
        let nano = |p: f64| (p * 1e9).round() / 1e9;
        let (lo, hi) = periods
            .iter()
            .fold((f64::INFINITY, 0.0_f64), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        crate::cmd::note(&format!(
            "the {} files' logger periods differ by up to {:.1} % ({} – {} s, clocks that \
             drift): every file resampled onto {} s, the period of {count} of them (`--dt` \
             for another grid)",
            paths.len(),
            100.0 * (hi - lo) / dt,
            nano(lo),
            nano(hi),
            nano(dt),
        ));
    }
    Ok(read
        .into_iter()
        .map(|(demo, what)| {
            crate::cmd::note(&what);
            demo
        })
        .collect())
}

/// Two periods equal up to float noise.
fn agree_exactly(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b
}

/// Reads an execution CSV with an irregular `t` column onto the even grid of its logger's
/// period (`tandem record --resample`, `Demonstration::regrid_csv_str`), keeping how its rows
/// map onto the grid for the log and flags beside it, and prints what was done as a note.
/// JSON files have no time column to resample and are refused.
pub(crate) fn regrid_execution(path: &Path) -> Result<tandem::lfd::Regridded> {
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
    {
        bail!(
            "{}: --resample applies to CSV files with a `t` column; a JSON execution is \
             already on an even grid (`dt_s`)",
            path.display()
        );
    }
    let grid = Demonstration::regrid_csv_path(path, None)?;
    crate::cmd::note(&format!(
        "{}; its log and flags put on the same grid (log interpolated, a sample supervised \
         where the nearest row was, corrected where any row of its period was)",
        grid.note
    ));
    Ok(grid)
}

/// The text of `path` and the name errors use for it.
fn read_text(path: &Path) -> Result<(String, String)> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).with_context(|| format!("{file}: cannot read"))?;
    Ok((text, file))
}

/// A small CSV table, split by the model crate's tokenizer ([`CsvTable`]: header, rows of
/// trimmed fields with their 1-based line, ragged rows rejected), with at least one row.
struct Table<'a> {
    csv: CsvTable<'a>,
}

impl<'a> Table<'a> {
    /// Splits `text` (of `file`); a header without rows is an error.
    fn new(text: &'a str, file: &str) -> Result<Self> {
        let csv = CsvTable::parse(text, file)?;
        if csv.rows().is_empty() {
            bail!("{file}: header only, no data rows");
        }
        Ok(Self { csv })
    }

    fn file(&self) -> &str {
        self.csv.file()
    }

    /// 1-based line of row `k`.
    fn line(&self, k: usize) -> usize {
        self.csv.rows()[k].line
    }

    /// Column index of `name`, or an error listing the header.
    fn column(&self, name: &str) -> Result<usize> {
        self.csv.column(name).ok_or_else(|| {
            anyhow!(
                "{}:{}: no column `{name}` in the header {:?}",
                self.file(),
                self.csv.header_line(),
                self.csv.names()
            )
        })
    }

    /// Rejects header names other than `allowed`.
    fn only(&self, allowed: &[&str]) -> Result<()> {
        for (j, n) in self.csv.names().iter().enumerate() {
            if !allowed.contains(&n.as_str()) {
                bail!(
                    "{}:{}:{}: unexpected column `{n}` (allowed: {})",
                    self.file(),
                    self.csv.header_line(),
                    j + 1,
                    allowed.join(", ")
                );
            }
        }
        Ok(())
    }

    /// The finite numbers of column `j`.
    fn numbers(&self, j: usize) -> Result<Vec<f64>> {
        (0..self.csv.rows().len())
            .map(|r| Ok(self.csv.number(r, j)?))
            .collect()
    }

    /// The 0/1 flags of column `j` (`true`/`false` accepted too).
    fn flags(&self, j: usize) -> Result<Vec<bool>> {
        self.csv
            .rows()
            .iter()
            .map(|row| match row.fields[j] {
                "0" | "false" => Ok(false),
                "1" | "true" => Ok(true),
                other => bail!(
                    "{}:{}:{}: column `{}`: expected 0 or 1, found `{other}`",
                    self.file(),
                    row.line,
                    j + 1,
                    self.csv.names()[j]
                ),
            })
            .collect()
    }
}

/// Reads a reference-time log: one column `ref_sample`, one row per execution sample, the
/// fractional reference sample the execution was at (monotone non-decreasing, in
/// `[0, T_ref − 1]`; the model checks the range).
pub(crate) fn read_log(path: &Path) -> Result<Vec<f64>> {
    let (text, file) = read_text(path)?;
    let t = Table::new(&text, &file)?;
    t.only(&["ref_sample"])?;
    let j = t.column("ref_sample")?;
    let v = t.numbers(j)?;
    for k in 1..v.len() {
        if v[k] < v[k - 1] {
            bail!(
                "{}:{}:1: `ref_sample` decreases from {} to {} (the log must be monotone)",
                t.file(),
                t.line(k),
                v[k - 1],
                v[k]
            );
        }
    }
    Ok(v)
}

/// Reads correction flags: columns `supervised,corrected` (0/1), one row per execution
/// sample. `corrected` may be 1 only where `supervised` is 1.
pub(crate) fn read_corrections(path: &Path) -> Result<(Vec<bool>, Vec<bool>)> {
    let (text, file) = read_text(path)?;
    let t = Table::new(&text, &file)?;
    t.only(&["supervised", "corrected"])?;
    let supervised = t.flags(t.column("supervised")?)?;
    let corrected = t.flags(t.column("corrected")?)?;
    if let Some(k) = (0..supervised.len()).find(|&k| corrected[k] && !supervised[k]) {
        bail!(
            "{}:{}: `corrected` is 1 but `supervised` is 0 (only a supervised, low-confidence \
             sample can be corrected)",
            t.file(),
            t.line(k)
        );
    }
    Ok((supervised, corrected))
}

/// Reads a need file (docs/formats.md; `tandem::sim::needs::NeedProfile::parse_csv`): column
/// `need` in `[0, 1]` per reference sample (`n_ref` rows), optional whole-number column
/// `region` grouping samples into one draw.
pub(crate) fn read_need(path: &Path, n_ref: usize) -> Result<NeedProfile> {
    let (text, file) = read_text(path)?;
    Ok(NeedProfile::parse_csv(&text, &file, n_ref)?)
}

/// Reads a parameter file (TOML with sections `[fit]`, `[confidence]`, `[sampler]`) and
/// validates it.
pub(crate) fn read_params(path: &Path) -> Result<PlannerParams> {
    let file = path.display();
    let text = std::fs::read_to_string(path).with_context(|| format!("{file}: cannot read"))?;
    let params: PlannerParams = toml::from_str(&text).map_err(|e| {
        let at = e
            .span()
            .map(|s| {
                let line = text[..s.start].matches('\n').count() + 1;
                format!(":{line}")
            })
            .unwrap_or_default();
        anyhow!("{file}{at}: {}", e.message())
    })?;
    params
        .validate()
        .with_context(|| format!("{file}: invalid parameter"))?;
    Ok(params)
}

/// Parses `--ranges NAME=VALUE` items against the tangent names; each value finite > 0.
pub(crate) fn parse_ranges(items: &[String], names: &[String]) -> Result<BTreeMap<usize, f64>> {
    let mut out = BTreeMap::new();
    for item in items {
        let (name, value) = item.split_once('=').ok_or_else(|| {
            anyhow!("--ranges: `{item}` is not NAME=VALUE (e.g. --ranges force=20,x=0.5)")
        })?;
        let (name, value) = (name.trim(), value.trim());
        let j = names.iter().position(|n| n == name).ok_or_else(|| {
            anyhow!(
                "--ranges: `{name}` is not a coordinate of these demonstrations (known: {})",
                names.join(", ")
            )
        })?;
        let v: f64 = value
            .parse()
            .map_err(|_| anyhow!("--ranges: `{name}`: not a number: `{value}`"))?;
        if !(v.is_finite() && v > 0.0) {
            bail!("--ranges: `{name}` = {value}: a range must be finite and > 0");
        }
        if out.insert(j, v).is_some() {
            bail!("--ranges: `{name}` is given twice");
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn ranges_are_parsed_by_name_and_checked() {
        let n = names(&["x", "force", "rate"]);
        let r = parse_ranges(&["force=20".into(), " x = 0.5".into()], &n).unwrap();
        assert_eq!(r.into_iter().collect::<Vec<_>>(), vec![(0, 0.5), (1, 20.0)]);
        for bad in ["force", "torque=1", "force=abc", "force=-1", "force=inf"] {
            assert!(parse_ranges(&[bad.into()], &n).is_err(), "{bad}");
        }
        assert!(parse_ranges(&["x=1".into(), "x=2".into()], &n).is_err());
    }
}
