//! The machine the tasks run on: system packages (installed when run as root), commands
//! run and timed, the workspace's paths, the Python test environment's interpreter.

use std::path::{Path, PathBuf};
use std::process::Command;

/// System packages the reference harnesses (OpenSubdiv, CGAL, OpenMesh) need: (file that proves it is there, Debian
/// package). The unit and integration tests need none.
pub const REFERENCE_PACKAGES: &[(&str, &str)] = &[
    (
        "/usr/include/opensubdiv/far/topologyRefinerFactory.h",
        "libosd-dev",
    ),
    ("/usr/bin/g++", "g++"),
    (
        "/usr/include/CGAL/Subdivision_method_3/subdivision_methods_3.h",
        "libcgal-dev",
    ),
    (
        "/usr/include/OpenMesh/Tools/Subdivider/Uniform/Sqrt3T.hh",
        "libopenmesh-dev",
    ),
];

/// System packages the tests need: a Vulkan adapter for subd-gpu's tests (Mesa's software
/// driver, lavapipe, where the machine has no GPU).
pub const TEST_PACKAGES: &[(&str, &str)] = &[(
    "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json",
    "mesa-vulkan-drivers",
)];

pub fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
        .unwrap_or(false)
}

pub fn ensure_system_packages(packages: &[(&str, &str)]) -> Result<(), String> {
    let missing: Vec<&str> = packages
        .iter()
        .filter(|(probe, _)| !std::path::Path::new(probe).exists())
        .map(|(_, pkg)| *pkg)
        .collect();
    if missing.is_empty() {
        return Ok(());
    }
    if !is_root() {
        return Err(format!(
            "missing system packages: {}; install them with: sudo apt-get install -y {}",
            missing.join(" "),
            missing.join(" ")
        ));
    }
    run(Command::new("apt-get").arg("update"))?;
    run(Command::new("apt-get")
        .args(["install", "-y"])
        .args(&missing))
}

pub fn run(cmd: &mut Command) -> Result<(), String> {
    eprintln!("xtask: running {cmd:?}");
    let start = std::time::Instant::now();
    let status = cmd
        .status()
        .map_err(|e| format!("cannot run {cmd:?}: {e}"))?;
    // Where CI's time goes, step by step.
    eprintln!(
        "xtask: {:?} took {:.0} s",
        cmd.get_program(),
        start.elapsed().as_secs_f64()
    );
    if status.success() {
        Ok(())
    } else {
        Err(format!("{cmd:?} failed with {status}"))
    }
}

/// The USD stages Pixar's USD wrote for the conformance rows (`tests/data/usd`).
pub fn usd_stages() -> std::path::PathBuf {
    workspace_root().join("tests/data/usd")
}

/// The workspace's root directory.
pub fn workspace_root() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(std::path::Path::to_path_buf)
        .unwrap_or_default()
}

pub fn cargo() -> Command {
    Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
}

/// The interpreter of the test environment `target/python-env` (there once `cargo xtask
/// test` has made it).
pub fn env_python(root: &Path) -> PathBuf {
    root.join("target/python-env/bin/python")
}
