//! The Python side of `cargo xtask test`: the package `subd` (`crates/python`) installed
//! with pip into a virtual environment under `target/`, as a user installs it, then its
//! pytest suite, which compares the bindings with the `subd` binary the Rust tests built.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::system::env_python;
use crate::system::run;

/// What the tests import besides `subd` (from PyPI): the runner, property tests, SciPy
/// (the stencil matrices come back as its CSR matrices), libigl (an independent Loop),
/// trimesh (the benchmark's other Loop, and `Mesh.to_trimesh`'s other side), PyVista (with
/// VTK: `Mesh.to_pyvista`'s other side) and Dask's distributed scheduler (the batch
/// example).
pub(crate) const TEST_PACKAGES: &[&str] = &[
    "maturin",
    "numpy",
    "pytest",
    "hypothesis",
    "scipy",
    "libigl",
    "trimesh",
    "pyvista",
    "dask[distributed]",
    // Pixar's USD: the reference the USD tests hold subd's reader and writer to.
    "usd-core",
];

/// Builds and installs the package in `target/python-env`, then runs its tests.
pub(crate) fn run_python_tests(root: &Path) -> Result<(), String> {
    let python = python_env(root, &[])?;
    let package = root.join("crates/python");
    let subd_bin: PathBuf = root.join("target/release/subd");
    run(Command::new(&python)
        // The slowest tests are listed, to see where the CI budget goes.
        .args(["-m", "pytest", "-q", "--durations=25"])
        .arg(package.join("tests"))
        .env("SUBD_BIN", subd_bin))
}

/// `cargo xtask bench --python-only`: Loop level 3 with the package against trimesh,
/// libigl and PyMeshLab (when it installs), on a ~100k-triangle torus and the bunny scan
/// (`crates/python/bench/loop_bench.py`, which prints the table).
pub(crate) fn run_python_bench(root: &Path, repeats: usize) -> Result<(), String> {
    // PyMeshLab ships wheels for few platforms: the table says so where it is missing.
    let python = python_env(root, &["pymeshlab"])?;
    let scan = crate::meshes::bunny()?;
    let json = root.join("target/xtask/bench/python_loop.json");
    run(Command::new(&python)
        .arg(root.join("crates/python/bench/loop_bench.py"))
        .arg("--scan")
        .arg(scan)
        .args(["--repeats", &repeats.max(1).to_string(), "--json"])
        .arg(json))
}

/// The environment `target/python-env` with the test packages, `optional` ones where they
/// install, and the package built and installed as a user installs it: its interpreter.
fn python_env(root: &Path, optional: &[&str]) -> Result<PathBuf, String> {
    let env = root.join("target/python-env");
    let python = env_python(root);
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
    for package in optional {
        if let Err(e) = pip(&[package]) {
            eprintln!("xtask: {package} not installed ({e}); left out");
        }
    }
    // pip builds the wheel with maturin (its build backend), in release, sharing the
    // workspace's target directory.
    let package = root.join("crates/python");
    pip(&[package.to_str().ok_or("non-UTF-8 path")?])?;
    Ok(python)
}

/// The Python interpreter to make the environment with: `$PYTHON`, else `python3`.
fn python3() -> String {
    std::env::var("PYTHON").unwrap_or_else(|_| "python3".into())
}
