//! `tandem need`: writes a need file (`tandem simulate --need`) for the state's reference from
//! reference-time regions, a label column, or the current low-confidence regions
//! (`tandem::sim::needs::NeedProfile`).

use std::io::Write as _;
use std::path::Path;

use anyhow::{Context, Result, anyhow, bail};
use tandem::lfd::CsvTable;
use tandem::sim::needs::{NeedProfile, NeedRegion};

use crate::cli::NeedArgs;
use crate::cmd::{out, secs};
use crate::state_io;

/// Parses `START-END=LEVEL` (reference seconds, END exclusive, LEVEL in [0, 1]).
pub(crate) fn parse_region(item: &str) -> Result<NeedRegion> {
    let usage = || {
        anyhow!(
            "--region `{item}`: expected START-END=LEVEL in reference seconds, e.g. --region \
             21.3-27.6=0.5"
        )
    };
    let (range, level) = item.split_once('=').ok_or_else(usage)?;
    let (start, end) = range.trim().split_once('-').ok_or_else(usage)?;
    let num = |s: &str| s.trim().parse::<f64>().map_err(|_| usage());
    Ok(NeedRegion {
        start_s: num(start)?,
        end_s: num(end)?,
        level: num(level)?,
    })
}

/// Per-sample levels from column `column` of a label file with one row per reference sample:
/// the values themselves (each in [0, 1]), or with `level` that level wherever the value is
/// not 0.
fn label_levels(path: &Path, column: &str, level: Option<f64>, n_ref: usize) -> Result<Vec<f64>> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).with_context(|| format!("{file}: cannot read"))?;
    let t = CsvTable::parse(&text, &file)?;
    let j = t.column(column).ok_or_else(|| {
        anyhow!(
            "{file}:{}: --column {column}: no such column in the header {:?}",
            t.header_line(),
            t.names()
        )
    })?;
    if t.rows().len() != n_ref {
        bail!(
            "{file}: {} rows, the state's reference has {n_ref} samples (the label file must \
             have one row per sample of the reference demonstration)",
            t.rows().len()
        );
    }
    let mut out = Vec::with_capacity(n_ref);
    for r in 0..n_ref {
        let v = t.number(r, j)?;
        let p = match level {
            Some(p) => {
                if v != 0.0 {
                    p
                } else {
                    0.0
                }
            }
            None => v,
        };
        if !(0.0..=1.0).contains(&p) {
            bail!(
                "{file}:{}:{}: `{column}` = {v} is not a probability in [0, 1] (give --level P \
                 to mark every non-zero value with P)",
                t.rows()[r].line,
                j + 1
            );
        }
        out.push(p);
    }
    Ok(out)
}

/// Writes `text` to `path`: a new file, or (with `force`) replacing an existing file
/// atomically (written beside it under a temporary name, then renamed).
fn write_new(path: &Path, text: &str, force: bool) -> Result<()> {
    let shown = path.display();
    state_io::check_writable(path)?;
    if !force {
        let mut f = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(path)
            .map_err(|e| {
                if e.kind() == std::io::ErrorKind::AlreadyExists {
                    anyhow!("{shown}: exists; tandem need does not replace a file (give --force to replace it)")
                } else {
                    anyhow!("{shown}: cannot create: {e}")
                }
            })?;
        return f
            .write_all(text.as_bytes())
            .with_context(|| format!("{shown}: cannot write"));
    }
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(path.file_name().unwrap_or_default());
    tmp_name.push(format!(".tmp{}", std::process::id()));
    let tmp = state_io::parent_dir(path).join(tmp_name);
    std::fs::write(&tmp, text).with_context(|| format!("{}: cannot write", tmp.display()))?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        anyhow!("{shown}: cannot replace: {e}")
    })
}

/// `tandem need`.
pub(crate) fn need(a: &NeedArgs) -> Result<()> {
    let planner = state_io::load(&a.state)?;
    let model = planner.model();
    let (n_ref, dt) = (model.n_ref(), model.dt_s());
    let profile = if !a.region.is_empty() {
        let regions = a
            .region
            .iter()
            .map(|r| parse_region(r))
            .collect::<Result<Vec<_>>>()?;
        NeedProfile::from_regions(&regions, n_ref, secs(dt)).context("--region")?
    } else if let Some(labels) = &a.from_labels {
        let Some(column) = &a.column else {
            bail!("--from-labels needs --column NAME (the label column to read)");
        };
        NeedProfile::from_levels(&label_levels(labels, column, a.level, n_ref)?)?
    } else if let Some(level) = a.low_confidence {
        let regions: Vec<NeedRegion> = planner
            .confidence()
            .low_regions()
            .iter()
            .map(|r| NeedRegion {
                start_s: r.start as f64 * secs(dt),
                end_s: r.end as f64 * secs(dt),
                level,
            })
            .collect();
        if regions.is_empty() {
            bail!(
                "--low-confidence: {} has no low-confidence sample (every sample is trusted): \
                 nothing for the operator to do",
                a.state.display()
            );
        }
        NeedProfile::from_regions(&regions, n_ref, secs(dt)).context("--low-confidence")?
    } else {
        bail!(
            "give --region START-END=LEVEL (repeatable), --from-labels FILE --column NAME, or --low-confidence LEVEL"
        );
    };
    write_new(&a.output, &profile.to_csv(), a.force)?;
    let needed = profile.p().iter().filter(|&&p| p > 0.0).count();
    let levels = profile.region_levels();
    let busy = levels.iter().filter(|&&p| p > 0.0).count();
    out(&format!(
        "wrote {}: {n_ref} reference samples × {} s, {busy} region(s) with need > 0 covering \
         {needed} samples ({:.2} s of {:.2} s)",
        a.output.display(),
        secs(dt),
        needed as f64 * dt,
        n_ref as f64 * dt
    ));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regions_parse_as_start_end_level() {
        let r = parse_region("21.3-27.6=0.5").unwrap();
        assert_eq!((r.start_s, r.end_s, r.level), (21.3, 27.6, 0.5));
        let r = parse_region(" 0 - 1.5 = 1 ").unwrap();
        assert_eq!((r.start_s, r.end_s, r.level), (0.0, 1.5, 1.0));
        for bad in ["21.3-27.6", "21.3=0.5", "a-b=0.5", "1-2=x", ""] {
            let e = parse_region(bad).unwrap_err().to_string();
            assert!(e.contains("START-END=LEVEL"), "{bad}: {e}");
        }
    }
}
