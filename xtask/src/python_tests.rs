//! The Python side of `cargo xtask test`: the package `subd` (`crates/python`) installed
//! with pip into a virtual environment under `target/`, as a user installs it, then its
//! pytest suite, which compares the bindings with the `subd` binary the Rust tests built.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::run;

/// What the tests import besides `subd` (from PyPI): the runner, property tests, SciPy
/// (the stencil matrices come back as its CSR matrices) and libigl (an independent Loop).
const TEST_PACKAGES: &[&str] = &["numpy", "pytest", "hypothesis", "scipy", "libigl"];

/// Builds and installs the package in `target/python-env`, then runs its tests.
pub(crate) fn run_python_tests(root: &Path) -> Result<(), String> {
    let env = root.join("target/python-env");
    let python = env.join("bin/python");
    if !python.exists() {
        run(Command::new(python3()).args(["-m", "venv"]).arg(&env))?;
    }
    let pip = |args: &[&str]| {
        run(Command::new(&python)
            .args([
                "-m",
                "pip",
                "install",
                "--quiet",
                "--disable-pip-version-check",
            ])
            .args(args))
    };
    pip(TEST_PACKAGES)?;
    // Installed as a user installs it: pip builds the wheel with maturin (its build
    // backend), in release, sharing the workspace's target directory.
    let package = root.join("crates/python");
    pip(&[package.to_str().ok_or("non-UTF-8 path")?])?;
    let subd_bin: PathBuf = root.join("target/release/subd");
    run(Command::new(&python)
        .args(["-m", "pytest", "-q"])
        .arg(package.join("tests"))
        .env("SUBD_BIN", subd_bin))
}

/// The Python interpreter to make the environment with: `$PYTHON`, else `python3`.
fn python3() -> String {
    std::env::var("PYTHON").unwrap_or_else(|_| "python3".into())
}
