//! `cargo xtask test`: every test of the project, Rust and Python, in one command (the
//! README's test command, which `.ci/run` calls).
//!
//! 1. `cargo test --workspace --no-fail-fast`; the steps below run even if it fails, and the
//!    command fails at the end if any step did.
//! 2. `cargo build -p tandem-cli`: the Python tests compare the bindings with the command line
//!    (`TANDEM_CLI` points them at this binary).
//! 3. A virtual environment under the target folder (`<target>/py-venv`, never committed),
//!    created with `python3 -m venv` (`$PYTHON` overrides the interpreter), with the pinned
//!    packages of `python/requirements-dev.txt` from PyPI (installed again only when that
//!    file changes).
//! 4. The wheel, built by maturin from `python/pyproject.toml` (release, abi3) into
//!    `<target>/wheels` and installed into the environment: what a user installs.
//! 5. `pytest python/tests`. Its exit code 5 ("no tests collected") is a failure too.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, bail};

use crate::workspace_root;

/// Options of `cargo xtask test`.
#[derive(clap::Args)]
pub(crate) struct TestArgs {
    /// Skip `cargo test --workspace` (run only the Python tests).
    #[arg(long)]
    python_only: bool,
    /// Extra arguments for pytest (after `--`), e.g. `-- -k coordinator -x`.
    #[arg(last = true)]
    pytest_args: Vec<String>,
}

/// Runs `cmd`, failing with `what` when it cannot start or exits non-zero.
fn run(cmd: &mut Command, what: &str) -> anyhow::Result<()> {
    println!("== {what}");
    let status = cmd
        .status()
        .with_context(|| format!("{what}: cannot start {:?}", cmd.get_program()))?;
    if !status.success() {
        bail!("{what} failed ({status})");
    }
    Ok(())
}

/// The Python interpreter inside the environment `venv`.
fn venv_python(venv: &Path) -> PathBuf {
    venv.join("bin").join("python")
}

/// `pip install` (quiet) of the environment `venv`, to be given what to install.
fn pip_install(venv: &Path) -> Command {
    let mut cmd = Command::new(venv_python(venv));
    cmd.args([
        "-m",
        "pip",
        "install",
        "--disable-pip-version-check",
        "--quiet",
    ]);
    cmd
}

/// Creates the virtual environment if needed and installs the pinned requirements when they
/// changed since the last install.
fn prepare_venv(root: &Path, venv: &Path) -> anyhow::Result<()> {
    let python = std::env::var("PYTHON").unwrap_or_else(|_| "python3".into());
    if !venv_python(venv).exists() {
        run(
            Command::new(&python).args(["-m", "venv"]).arg(venv),
            &format!("create the virtual environment {}", venv.display()),
        )
        .context(
            "Python 3.9 or newer with its `venv` module is needed (Debian: apt-get install \
             python3-venv); set $PYTHON to use another interpreter",
        )?;
    }
    let requirements = root.join("python").join("requirements-dev.txt");
    let wanted = std::fs::read_to_string(&requirements)
        .with_context(|| format!("reading {}", requirements.display()))?;
    let stamp = venv.join(".tandem-requirements");
    if std::fs::read_to_string(&stamp).ok().as_deref() == Some(wanted.as_str()) {
        return Ok(());
    }
    run(
        pip_install(venv).arg("-r").arg(&requirements),
        "install the pinned Python packages (python/requirements-dev.txt)",
    )?;
    std::fs::write(&stamp, wanted).with_context(|| format!("writing {}", stamp.display()))?;
    Ok(())
}

/// Builds the wheel with maturin and installs it into the environment.
fn install_wheel(root: &Path, venv: &Path, target: &Path) -> anyhow::Result<()> {
    let wheels = target.join("wheels");
    if wheels.exists() {
        std::fs::remove_dir_all(&wheels)
            .with_context(|| format!("clearing {}", wheels.display()))?;
    }
    run(
        Command::new(venv.join("bin").join("maturin"))
            .current_dir(root.join("python"))
            .args(["build", "--release", "--quiet", "--out"])
            .arg(&wheels)
            .arg("--interpreter")
            .arg(venv_python(venv)),
        "build the wheel (maturin, python/pyproject.toml)",
    )?;
    let wheel = std::fs::read_dir(&wheels)
        .with_context(|| format!("listing {}", wheels.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| p.extension().is_some_and(|e| e == "whl"))
        .with_context(|| format!("maturin wrote no wheel into {}", wheels.display()))?;
    run(
        pip_install(venv)
            .args(["--force-reinstall", "--no-deps"])
            .arg(&wheel),
        &format!("install {}", wheel.display()),
    )
}

/// Runs the command.
pub(crate) fn run_all(args: &TestArgs) -> anyhow::Result<()> {
    let root = workspace_root();
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target"));
    // Every test binary runs even if one fails, and the Python tests run after failing Rust
    // tests too: one run reports every failure; the command fails if any did.
    let rust = if args.python_only {
        Ok(())
    } else {
        run(
            Command::new(&cargo)
                .current_dir(&root)
                .args(["test", "--workspace", "--no-fail-fast"]),
            "cargo test --workspace --no-fail-fast",
        )
    };
    run(
        Command::new(&cargo)
            .current_dir(&root)
            .args(["build", "--quiet", "-p", "tandem-cli"]),
        "build the command line for the Python tests",
    )?;
    let venv = target.join("py-venv");
    prepare_venv(&root, &venv)?;
    install_wheel(&root, &venv, &target)?;
    println!("== pytest python/tests");
    let status = Command::new(venv_python(&venv))
        .current_dir(&root)
        .env("TANDEM_CLI", target.join("debug").join("tandem"))
        .args(["-m", "pytest", "python/tests"])
        .args(&args.pytest_args)
        .status()
        .context("cannot start pytest")?;
    let python = match status.code() {
        Some(0) => Ok(()),
        Some(5) => Err(anyhow::anyhow!(
            "pytest collected no tests in python/tests (exit code 5)"
        )),
        _ => Err(anyhow::anyhow!("pytest failed ({status})")),
    };
    match (rust, python) {
        (Err(r), Err(p)) => bail!("{r:#}; {p:#}"),
        (r, p) => r.and(p),
    }
}
