//! Loading and saving state files, and checking output locations before any work is done.

use std::fs::File;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use tandem::Planner;
use tandem::planner::state::{self, DEFAULT_LOCK_TIMEOUT, StateLock};

/// Locks the state file `path` for a read–modify–write, waiting up to
/// [`DEFAULT_LOCK_TIMEOUT`] for another `tandem` command that holds it.
pub(crate) fn lock(path: &Path) -> Result<StateLock> {
    if !path.is_file() {
        // A missing file or a folder: the error load gives, and no lock file beside it.
        load(path)?;
    }
    Ok(StateLock::acquire(path, DEFAULT_LOCK_TIMEOUT)?)
}

/// Locks the state file `path` for a write that does not read it first (the file may be
/// missing), waiting up to [`DEFAULT_LOCK_TIMEOUT`].
pub(crate) fn lock_new(path: &Path) -> Result<StateLock> {
    Ok(StateLock::acquire(path, DEFAULT_LOCK_TIMEOUT)?)
}

/// Loads a planner, naming the file in every error.
pub(crate) fn load(path: &Path) -> Result<Planner> {
    if path.is_dir() {
        bail!("{}: is a folder, not a state file", path.display());
    }
    let planner = Planner::load(path).context("cannot load the state")?;
    if let Some(notice) = planner.load_notice() {
        eprintln!("notice: {}: {notice}", path.display());
    }
    Ok(planner)
}

/// Checks that a state file can be written at `path` (as [`check_writable`], and an existing
/// file there is a state file: [`state::check_target`]), without touching `path` itself.
pub(crate) fn check_file_target(path: &Path) -> Result<()> {
    check_writable(path)?;
    state::check_target(path)?;
    Ok(())
}

/// Checks that a file can be created at `path`: its folder exists and accepts a new file, and
/// `path` is not a folder. Touches nothing at `path` itself; whether an existing file may be
/// replaced is the caller's rule.
pub(crate) fn check_writable(path: &Path) -> Result<()> {
    let shown = path.display();
    if path.is_dir() {
        bail!("{shown}: is a folder; give a file name for the output");
    }
    let Some(name) = path.file_name() else {
        bail!("{shown}: has no file name");
    };
    let dir = parent_dir(path);
    if !dir.is_dir() {
        bail!(
            "{shown}: cannot write: folder {} does not exist or is not a folder",
            dir.display()
        );
    }
    let mut probe_name = std::ffi::OsString::from(".");
    probe_name.push(name);
    probe_name.push(format!(".probe{}", std::process::id()));
    let probe = dir.join(probe_name);
    File::create(&probe)
        .with_context(|| format!("{shown}: cannot write into folder {}", dir.display()))?;
    std::fs::remove_file(&probe)
        .with_context(|| format!("cannot remove probe file {}", probe.display()))?;
    Ok(())
}

/// Creates `dir` if needed and checks that files can be created in it.
pub(crate) fn prepare_dir(dir: &Path) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        bail!("{}: exists and is not a folder", dir.display());
    }
    std::fs::create_dir_all(dir)
        .with_context(|| format!("{}: cannot create output folder", dir.display()))?;
    let probe = dir.join(format!(".tandem-probe{}", std::process::id()));
    File::create(&probe)
        .with_context(|| format!("{}: cannot write into output folder", dir.display()))?;
    std::fs::remove_file(&probe)
        .with_context(|| format!("cannot remove probe file {}", probe.display()))?;
    Ok(())
}

/// The folder of `path` (`.` for a bare file name).
pub(crate) fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}
