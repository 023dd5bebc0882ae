//! The `subd` binary as a user runs it: exit codes, one-line errors, JSON output, one module a
//! command.

use std::path::{Path, PathBuf};
use std::process::Command;

mod adaptive;
mod analyze;
mod batch;
mod budget;
mod curve;
mod depth_first;
mod edit;
mod eval;
mod input;
mod limit;
mod patches;
mod pia;
mod refine;
mod render;
mod tessellate;
mod usd;
mod uv;

fn subd(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_subd"))
        .args(args)
        .env("RUST_BACKTRACE", "1")
        .output()
        .expect("run subd");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn meshes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/meshes/osd")
}

struct Scratch(PathBuf);

impl Scratch {
    fn new(tag: &str) -> Self {
        let d = std::env::temp_dir().join(format!("subd-cli-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        Scratch(d)
    }
    fn file(&self, name: &str, bytes: &[u8]) -> PathBuf {
        let p = self.0.join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Runs `subd info` on a bad input and checks the user-facing contract: exit 2, exactly one
/// line on stderr starting with `subd: <file>`, containing `expect`, no panic or backtrace.
fn assert_bad_input(path: &Path, expect: &str) {
    let p = path.to_str().unwrap();
    let (code, out, err) = subd(&["info", p]);
    assert_eq!(code, 2, "{p}: stderr {err:?}");
    assert!(out.is_empty(), "{p}: stdout {out:?}");
    let lines: Vec<&str> = err
        .lines()
        .filter(|l| !l.starts_with("subd: warning:"))
        .collect();
    assert_eq!(lines.len(), 1, "{p}: stderr {err:?}");
    assert!(lines[0].starts_with(&format!("subd: {p}")), "{p}: {err:?}");
    assert!(
        lines[0].contains(expect),
        "{p}: expected {expect:?} in {err:?}"
    );
    assert!(
        !err.contains("panicked") && !err.contains("backtrace"),
        "{err}"
    );
}

/// Reads the vertex positions of an OBJ file (`v x y z` lines).
fn obj_vertices(path: &Path) -> Vec<[f64; 3]> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

/// The regular files of `dir`, by name.
fn file_names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}
