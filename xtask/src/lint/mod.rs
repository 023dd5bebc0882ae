//! `cargo xtask lint`: the house rules that rustfmt and clippy do not check. A function
//! over 100 lines in `crates/*/src` or `xtask/src`, a file over 1,000 lines in
//! `crates/*/src`, or a circle of modules inside one crate fails the run, each one line
//! naming the file, the item and the count.

mod circles;
mod lengths;

use std::path::{Path, PathBuf};

/// The longest function the house allows, in lines from `fn` to its closing brace.
pub const MAX_FUNCTION_LINES: usize = 100;
/// The longest source file the house allows in the library crates.
pub const MAX_FILE_LINES: usize = 1000;

/// One broken rule, as a line for the terminal.
pub type Finding = String;

/// Runs every rule over the workspace at `root`; `Err` lists what broke them.
pub fn run(root: &Path) -> Result<(), String> {
    let mut findings = Vec::new();
    let crates = crate_sources(root)?;
    for source_root in crates.iter().chain([&root.join("xtask/src")]) {
        let files = rust_files(source_root)?;
        for file in &files {
            let text = std::fs::read_to_string(file)
                .map_err(|e| format!("{}: cannot read: {e}", file.display()))?;
            let shown = file.strip_prefix(root).unwrap_or(file);
            findings.extend(lengths::long_functions(shown, &text)?);
            if source_root.starts_with(root.join("crates")) {
                findings.extend(lengths::long_file(shown, &text));
            }
        }
        findings.extend(circles::module_circles(root, source_root, &files)?);
    }
    if findings.is_empty() {
        eprintln!(
            "xtask lint: no function over {MAX_FUNCTION_LINES} lines, no file over {MAX_FILE_LINES} lines, no module circle"
        );
        return Ok(());
    }
    for finding in &findings {
        eprintln!("{finding}");
    }
    Err(format!("lint: {} finding(s)", findings.len()))
}

/// The `src` folder of each crate under `crates/`.
fn crate_sources(root: &Path) -> Result<Vec<PathBuf>, String> {
    let crates = root.join("crates");
    let mut out: Vec<PathBuf> = std::fs::read_dir(&crates)
        .map_err(|e| format!("{}: cannot list: {e}", crates.display()))?
        .filter_map(|e| e.ok().map(|e| e.path().join("src")))
        .filter(|p| p.is_dir())
        .collect();
    out.sort();
    Ok(out)
}

/// Every `.rs` file under `dir`, sorted.
fn rust_files(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let mut out = Vec::new();
    let mut pending = vec![dir.to_path_buf()];
    while let Some(d) = pending.pop() {
        let entries =
            std::fs::read_dir(&d).map_err(|e| format!("{}: cannot list: {e}", d.display()))?;
        for entry in entries {
            let path = entry.map_err(|e| format!("{}: {e}", d.display()))?.path();
            if path.is_dir() {
                pending.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }
    out.sort();
    Ok(out)
}
