//! The alignment against the truth: how far the fit's warp of every demonstration onto the
//! reference is from the family's known warp, and the same data exported for a peer aligner
//! (`bench/peers/zoo_gdtw.py` runs `gdtw` on it).
//!
//! # The error, on one time axis
//!
//! The fit aligns demonstration `i` to the reference `r`: `ψ̂_i(n)` is the (fractional) row of
//! demo `i` at reference sample `n` (`TaskModel::align_demonstration`, the warp the fit
//! computed). The truth knows every row's task progress ([`ZooTask::progress`], strictly
//! increasing), so the row `ψ̂_i(n)` of demo `i` is truly at the reference's row
//! `τ_i(ψ̂_i(n)) = P_r⁻¹(P_i(ψ̂_i(n)))`, with `P_i` demo `i`'s progress interpolated linearly
//! between rows and `P_r⁻¹` its inverse on the reference. The error at `n` is
//! `|τ_i(ψ̂_i(n)) − n|`, in reference samples: zero exactly when the warp pairs reference
//! sample `n` with the row of demo `i` at the same progress. Reference samples are the axis of
//! every per-time array of the model (the statistics are read through the warp there), and the
//! same for every demonstration of a task, so errors of demonstrations of different lengths
//! add up. [`WarpError`] gives the mean over every reference sample of every non-reference
//! demonstration, and the largest.

use std::io::Write as _;
use std::path::Path;

use serde::{Deserialize, Serialize};
use tandem_lfd::{Demonstration, FitParams, TaskModel};

use crate::{Error, Result, ZooTask};

/// The alignment's error against the truth over a task's demonstrations (module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WarpError {
    /// Demonstrations scored (every one but the reference).
    pub pairs: usize,
    /// Mean `|τ_i(ψ̂_i(n)) − n|` over every reference sample of every scored demonstration,
    /// reference samples.
    pub mean_samples: f64,
    /// The largest, reference samples.
    pub max_samples: f64,
}

/// Linear interpolation of `v` (one value per row) at the fractional row `t`, clamped to the
/// rows.
fn lerp_at(v: &[f64], t: f64) -> f64 {
    let last = v.len() - 1;
    let t = t.clamp(0.0, last as f64);
    let lo = (t.floor() as usize).min(last);
    let hi = (lo + 1).min(last);
    v[lo] + (t - lo as f64) * (v[hi] - v[lo])
}

/// The fractional row at which the increasing `v` takes the value `x` (linear between rows,
/// clamped to the first and last row).
fn inverse_at(v: &[f64], x: f64) -> f64 {
    let last = v.len() - 1;
    if x <= v[0] {
        return 0.0;
    }
    if x >= v[last] {
        return last as f64;
    }
    // v[j] <= x < v[j + 1]
    let j = v.partition_point(|&p| p <= x) - 1;
    let (a, b) = (v[j], v[j + 1]);
    if b > a {
        j as f64 + (x - a) / (b - a)
    } else {
        j as f64
    }
}

/// Per reference sample `n`, the error `|P_r⁻¹(P_i(ψ̂(n))) − n|` (module docs) of the warp
/// `fitted` (rows of demo `i` per reference sample) given the true progress of demo `i`
/// (`progress_demo`) and of the reference (`progress_ref`).
#[must_use]
pub fn warp_errors(fitted: &[f64], progress_demo: &[f64], progress_ref: &[f64]) -> Vec<f64> {
    fitted
        .iter()
        .enumerate()
        .map(|(n, &row)| (inverse_at(progress_ref, lerp_at(progress_demo, row)) - n as f64).abs())
        .collect()
}

/// The fit's warps of every demonstration but the reference onto it (`None` for the
/// reference), as `model` (fitted on `demos` with `fit`) aligns them.
///
/// # Errors
/// The alignment's errors (as the fit's).
pub fn fitted_warps(
    model: &TaskModel,
    demos: &[Demonstration],
    fit: &FitParams,
) -> Result<Vec<Option<Vec<f64>>>> {
    let r = model.reference_idx();
    demos
        .iter()
        .enumerate()
        .map(|(i, demo)| {
            if i == r {
                Ok(None)
            } else {
                Ok(Some(model.align_demonstration(&demos[r], demo, fit)?))
            }
        })
        .collect()
}

/// The error of `warps` (from [`fitted_warps`]) against `task`'s truth (module docs).
///
/// # Errors
/// [`Error::Eval`] when a warp or the reference's progress does not fit the task (a bug).
pub fn warp_error(
    task: &ZooTask,
    reference: usize,
    warps: &[Option<Vec<f64>>],
) -> Result<WarpError> {
    let bad = |why: String| Error::Eval {
        what: format!("{} seed {} alignment", task.family, task.seed),
        why,
    };
    let progress_ref = task.progress.get(reference).ok_or_else(|| {
        bad(format!(
            "no true progress for the reference, demo {reference}"
        ))
    })?;
    let (mut sum, mut count, mut max, mut pairs) = (0.0, 0usize, 0.0_f64, 0);
    for (i, warp) in warps.iter().enumerate() {
        let Some(warp) = warp else { continue };
        let progress = &task.progress[i];
        if warp.len() != progress_ref.len() || progress.len() < 2 {
            return Err(bad(format!(
                "demo {i}: a warp of {} values for a reference of {} rows",
                warp.len(),
                progress_ref.len()
            )));
        }
        for e in warp_errors(warp, progress, progress_ref) {
            sum += e;
            max = max.max(e);
            count += 1;
        }
        pairs += 1;
    }
    Ok(WarpError {
        pairs,
        mean_samples: if count == 0 { 0.0 } else { sum / count as f64 },
        max_samples: max,
    })
}

/// Quaternion columns of a zoo task (`engine::pose`'s channel names).
const QUAT_CHANNELS: [&str; 4] = ["qx", "qy", "qz", "qw"];

/// Demo `demo`'s samples as the alignment sees them: channels in the model's order, the
/// quaternion block sign-continuous and in the hemisphere of the reference's first
/// orientation (as the fit's alignment does), every channel multiplied by `√W_jj`
/// (`TaskModel::warp_weights`), so that an unweighted squared distance between two rows is
/// the fit's weighted one. Row-major, `n_samples × channels`.
fn weighted_signal(
    model: &TaskModel,
    demo: &Demonstration,
    reference_q: Option<[f64; 4]>,
) -> Result<Vec<f64>> {
    let names = model.channel_names();
    let demo = demo.conform_to(names)?;
    let m = names.len();
    let quat: Option<[usize; 4]> = QUAT_CHANNELS
        .iter()
        .map(|q| names.iter().position(|n| n == q))
        .collect::<Option<Vec<usize>>>()
        .map(|v| [v[0], v[1], v[2], v[3]]);
    let scale: Vec<f64> = model.warp_weights().iter().map(|w| w.sqrt()).collect();
    let mut data = demo.samples().to_vec();
    if let (Some(cols), Some(mut prev)) = (quat, reference_q) {
        for row in data.chunks_exact_mut(m) {
            let dot: f64 = cols.iter().zip(prev).map(|(&c, p)| row[c] * p).sum();
            if dot < 0.0 {
                for &c in &cols {
                    row[c] = -row[c];
                }
            }
            prev = cols.map(|c| row[c]);
        }
    }
    for row in data.chunks_exact_mut(m) {
        for (v, s) in row.iter_mut().zip(&scale) {
            *v *= s;
        }
    }
    Ok(data)
}

/// Writes `data` (row-major, `shape`) as a NumPy `.npy` file (format 1.0, little-endian
/// `f64`).
fn write_npy(path: &Path, data: &[f64], shape: &[usize]) -> Result<()> {
    let shape_text = match shape {
        [a] => format!("({a},)"),
        dims => format!(
            "({})",
            dims.iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let mut header = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': {shape_text}, }}");
    // magic (6) + version (2) + header length (2) + header + '\n': a multiple of 64.
    let pad = (64 - (10 + header.len() + 1) % 64) % 64;
    header.push_str(&" ".repeat(pad));
    header.push('\n');
    let mut bytes = Vec::with_capacity(10 + header.len() + 8 * data.len());
    bytes.extend_from_slice(b"\x93NUMPY\x01\x00");
    let len = u16::try_from(header.len()).map_err(|_| Error::Eval {
        what: path.display().to_string(),
        why: "npy header too long".into(),
    })?;
    bytes.extend_from_slice(&len.to_le_bytes());
    bytes.extend_from_slice(header.as_bytes());
    for v in data {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    let io = |source| Error::Io {
        path: path.display().to_string(),
        source,
    };
    let mut file = std::fs::File::create(path).map_err(io)?;
    file.write_all(&bytes).map_err(io)
}

/// What `meta.json` of an exported task holds ([`export_alignment`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ExportMeta {
    /// The family.
    pub family: String,
    /// The seed.
    pub seed: u64,
    /// Demonstrations.
    pub n_demos: usize,
    /// The reference demonstration (the fit's).
    pub reference_idx: usize,
    /// Channel names, the columns of every `signal_<i>.npy`.
    pub channels: Vec<String>,
    /// The weights `W_jj` the signals were multiplied by the square root of.
    pub weights: Vec<f64>,
    /// The fit's warp parameters' slope bounds `[min, max]` (tandem-warp's; informational).
    pub slope_bounds: [f64; 2],
    /// The fit's alignment error ([`warp_error`]), for the peer script to check that it
    /// scores the exported warps the same way.
    pub tandem: WarpError,
}

/// Writes what a peer aligner needs to align `task`'s demonstrations exactly as the fit did,
/// into `dir` (created if missing): `signal_<i>.npy` per demonstration (rows × channels,
/// weighted as `weighted_signal` says: unweighted squared distances are the fit's weighted
/// ones), `progress_<i>.npy` (the true progress per row), `tandem_<i>.npy` (the fit's warp
/// `ψ̂_i`, one value per reference sample, for every demo but the reference) and `meta.json`
/// ([`ExportMeta`]). Returns the meta.
///
/// # Errors
/// The alignment's errors; [`Error::Io`] naming a file that could not be written.
pub fn export_alignment(
    task: &ZooTask,
    demos: &[Demonstration],
    model: &TaskModel,
    fit: &FitParams,
    dir: &Path,
) -> Result<ExportMeta> {
    let io = |path: &Path| {
        let path = path.display().to_string();
        move |source| Error::Io { path, source }
    };
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let r = model.reference_idx();
    let warps = fitted_warps(model, demos, fit)?;
    let tandem = warp_error(task, r, &warps)?;
    let names = model.channel_names();
    let m = names.len();
    let reference_q = {
        let reference = demos[r].conform_to(names)?;
        let idx: Option<Vec<usize>> = QUAT_CHANNELS
            .iter()
            .map(|q| names.iter().position(|n| n == q))
            .collect();
        idx.map(|c| [0, 1, 2, 3].map(|k| reference.sample(0)[c[k]]))
    };
    for (i, demo) in demos.iter().enumerate() {
        let signal = weighted_signal(model, demo, reference_q)?;
        write_npy(
            &dir.join(format!("signal_{i}.npy")),
            &signal,
            &[signal.len() / m, m],
        )?;
        let progress = &task.progress[i];
        write_npy(
            &dir.join(format!("progress_{i}.npy")),
            progress,
            &[progress.len()],
        )?;
        if let Some(w) = &warps[i] {
            write_npy(&dir.join(format!("tandem_{i}.npy")), w, &[w.len()])?;
        }
    }
    let meta = ExportMeta {
        family: task.family.to_string(),
        seed: task.seed,
        n_demos: demos.len(),
        reference_idx: r,
        channels: names.to_vec(),
        weights: model.warp_weights(),
        slope_bounds: [fit.warp.slope_min, fit.warp.slope_max],
        tandem,
    };
    let path = dir.join("meta.json");
    std::fs::write(&path, serde_json::to_string_pretty(&meta)? + "\n").map_err(io(&path))?;
    Ok(meta)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_and_its_inverse() {
        let v = [0.0, 0.1, 0.4, 1.0];
        assert!((lerp_at(&v, 1.5) - 0.25).abs() < 1e-15);
        assert_eq!(lerp_at(&v, -1.0), 0.0);
        assert_eq!(lerp_at(&v, 9.0), 1.0);
        assert!((inverse_at(&v, 0.25) - 1.5).abs() < 1e-12);
        assert!((inverse_at(&v, 0.7) - 2.5).abs() < 1e-12);
        assert_eq!(inverse_at(&v, -0.5), 0.0);
        assert_eq!(inverse_at(&v, 2.0), 3.0);
        assert_eq!(inverse_at(&v, 0.4), 2.0);
    }

    #[test]
    fn errors_in_reference_samples() {
        // The reference moves at constant speed (progress n/4); the demo spends its first
        // half-progress in 1 row and the second in 3 (progress 0, 0.5, 2/3, 5/6, 1).
        let progress_ref = [0.0, 0.25, 0.5, 0.75, 1.0];
        let progress_demo = [0.0, 0.5, 2.0 / 3.0, 5.0 / 6.0, 1.0];
        // The true warp: ref row n ↔ demo row at the same progress.
        let truth = [0.0, 0.5, 1.0, 2.5, 4.0];
        let e = warp_errors(&truth, &progress_demo, &progress_ref);
        assert!(e.iter().all(|&x| x < 1e-12), "{e:?}");
        // The identity warp: ref row 1 ↔ demo row 1 (progress 0.5 = ref row 2): 1 sample off;
        // ref row 3 ↔ demo row 3 (progress 5/6 = ref row 10/3): 1/3 off.
        let e = warp_errors(&[0.0, 1.0, 2.0, 3.0, 4.0], &progress_demo, &progress_ref);
        let want = [0.0, 1.0, 2.0 / 3.0, 1.0 / 3.0, 0.0];
        for (a, b) in e.iter().zip(want) {
            assert!((a - b).abs() < 1e-12, "{e:?}");
        }
    }

    #[test]
    fn npy_header_is_aligned() {
        let dir = std::env::temp_dir().join(format!("tandem-zoo-npy-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("a.npy");
        write_npy(&path, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0], &[3, 2]).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
        let hlen = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        assert_eq!((10 + hlen) % 64, 0);
        let header = std::str::from_utf8(&bytes[10..10 + hlen]).unwrap();
        assert!(
            header.contains("'shape': (3, 2)") && header.ends_with('\n'),
            "{header}"
        );
        assert_eq!(bytes.len(), 10 + hlen + 48);
        assert_eq!(&bytes[10 + hlen..10 + hlen + 8], &1.0_f64.to_le_bytes());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
