//! `cargo xtask bench --batch-only`: `subd refine` in batch mode against a shell loop of
//! single runs, on two corpora: 1,000 small meshes (OpenSubdiv's shapes, repeated) and 10
//! large ones (the ~100k-face quad bench mesh). Batch mode is also timed with `--jobs 1`
//! (files one after another, each using every thread), which is how the split between
//! per-file and per-mesh threads was chosen.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use crate::bench::median;
use crate::meshes::quad_bench_mesh;
use crate::system::{cargo, run};

/// Small meshes in the small corpus.
const SMALL_FILES: usize = 1000;
/// Large meshes in the large corpus.
const LARGE_FILES: usize = 10;

struct Corpus {
    name: &'static str,
    dir: PathBuf,
    files: usize,
    levels: usize,
}

/// Builds `subd` in release mode and returns its path.
pub(crate) fn subd_binary() -> Result<PathBuf, String> {
    run(cargo().args(["build", "--release", "-p", "subd-cli"]))?;
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target"));
    Ok(target.join("release/subd"))
}

/// The two corpora under `root`, written once.
fn corpora(root: &Path, shapes: &Path) -> Result<Vec<Corpus>, String> {
    let io = |e: std::io::Error| e.to_string();
    let small = root.join("small");
    let large = root.join("large");
    if !small.join("done").exists() {
        let _ = std::fs::remove_dir_all(&small);
        std::fs::create_dir_all(&small).map_err(io)?;
        let mut shape_files: Vec<PathBuf> = std::fs::read_dir(shapes)
            .map_err(|e| format!("{}: {e}", shapes.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "obj"))
            .collect();
        shape_files.sort();
        if shape_files.is_empty() {
            return Err(format!("{}: no .obj shapes", shapes.display()));
        }
        for i in 0..SMALL_FILES {
            let src = &shape_files[i % shape_files.len()];
            let stem = src.file_stem().unwrap().to_string_lossy();
            std::fs::copy(src, small.join(format!("{i:04}_{stem}.obj"))).map_err(io)?;
        }
        std::fs::write(small.join("done"), "").map_err(io)?;
    }
    if !large.join("done").exists() {
        let _ = std::fs::remove_dir_all(&large);
        std::fs::create_dir_all(&large).map_err(io)?;
        let mesh = quad_bench_mesh();
        let first = large.join("large_00.obj");
        subd_io::write_mesh(&first, &mesh, &subd_io::WriteOptions::default())
            .map_err(|e| e.to_string())?;
        for i in 1..LARGE_FILES {
            std::fs::copy(&first, large.join(format!("large_{i:02}.obj"))).map_err(io)?;
        }
        std::fs::write(large.join("done"), "").map_err(io)?;
    }
    Ok(vec![
        Corpus {
            name: "1000 OpenSubdiv shapes",
            dir: small,
            files: SMALL_FILES,
            levels: 2,
        },
        Corpus {
            name: "10 × 100k-face quads",
            dir: large,
            files: LARGE_FILES,
            levels: 1,
        },
    ])
}

/// Seconds of one run of `cmd`, which must succeed.
fn seconds(cmd: &mut Command) -> Result<f64, String> {
    let t = Instant::now();
    let out = cmd.output().map_err(|e| format!("{cmd:?}: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "{cmd:?} failed: {}",
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    Ok(t.elapsed().as_secs_f64())
}

/// Runs the comparison and prints the table (times are medians of `rounds`).
pub fn run_batch(rounds: usize, shapes: &Path) -> Result<(), String> {
    let subd = subd_binary()?;
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/xtask/bench/batch");
    let corpora = corpora(&root, shapes)?;
    let out = root.join("out");
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!(
        "subd refine --scheme catmull-clark, batch mode against a shell loop of single runs; OBJ in, binary PLY out; {threads} threads; medians of {rounds} rounds"
    );
    println!(
        "{:<24} {:>5} {:>6} {:>10} {:>14} {:>11} {:>10} {:>13}",
        "corpus",
        "files",
        "level",
        "loop s",
        "batch jobs=1 s",
        "batch s",
        "loop/batch",
        "jobs=1/batch"
    );
    for corpus in &corpora {
        let common = [
            "refine".to_string(),
            "--scheme".into(),
            "catmull-clark".into(),
            "--levels".into(),
            corpus.levels.to_string(),
            "--accept-inconsistent-orientation".into(),
        ];
        let fresh = || {
            let _ = std::fs::remove_dir_all(&out);
            std::fs::create_dir_all(&out).map_err(|e| e.to_string())
        };
        let (mut shell, mut one, mut batch) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..rounds {
            fresh()?;
            // What a user without batch mode writes: one process per file.
            let script = format!(
                "for f in \"$1\"/*.obj; do b=$(basename \"$f\" .obj); \"$2\" {} \"$f\" \"$3/$b.ply\" || exit 1; done",
                common.join(" ")
            );
            shell.push(seconds(
                Command::new("bash")
                    .args(["-c", &script, "loop"])
                    .arg(&corpus.dir)
                    .arg(&subd)
                    .arg(&out),
            )?);
            for (jobs, times) in [(Some(1), &mut one), (None, &mut batch)] {
                fresh()?;
                let mut cmd = Command::new(&subd);
                cmd.args(&common)
                    .arg(&corpus.dir)
                    .arg("--out-dir")
                    .arg(&out)
                    .args(["--format", "ply"]);
                if let Some(j) = jobs {
                    cmd.args(["--jobs", &j.to_string()]);
                }
                times.push(seconds(&mut cmd)?);
            }
        }
        let written = std::fs::read_dir(&out).map_err(|e| e.to_string())?.count();
        if written != corpus.files {
            return Err(format!(
                "{}: batch wrote {written} files, expected {}",
                corpus.name, corpus.files
            ));
        }
        let ratio = |a: &[f64], b: &[f64]| median(a.iter().zip(b).map(|(x, y)| x / y).collect());
        println!(
            "{:<24} {:>5} {:>6} {:>10.3} {:>14.3} {:>11.3} {:>10.2} {:>13.2}",
            corpus.name,
            corpus.files,
            corpus.levels,
            median(shell.clone()),
            median(one.clone()),
            median(batch.clone()),
            ratio(&shell, &batch),
            ratio(&one, &batch),
        );
    }
    let _ = std::fs::remove_dir_all(&out);
    Ok(())
}
