//! `cargo xtask bench --usd-only`: a 1M-face mesh read and written as `.usdc` against the
//! same mesh as binary PLY (both through `subd-io`, in this run), and Pixar's USD reading the
//! `.usdc` from Python (`usd-core` in `target/python-env`: `Usd.Stage.Open` and the mesh's
//! three arrays, as a Python pipeline reads them).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use subd_io::{ReadOptions, WriteOptions};

use crate::bench::median;

/// Quads per side of the benchmark torus: 1000 × 1000 = 1M faces.
const SIDE: usize = 1000;

/// Median seconds of `repeats` runs of `f`.
fn timed(repeats: usize, mut f: impl FnMut() -> Result<(), String>) -> Result<f64, String> {
    let mut t = Vec::with_capacity(repeats);
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        f()?;
        t.push(start.elapsed().as_secs_f64());
    }
    Ok(median(t))
}

/// Pixar's USD reading `path` from Python: median seconds of `repeats` opens, each reading
/// the points, counts and indices into `Vt` arrays.
fn pxr_read(root: &Path, path: &Path, repeats: usize) -> Result<f64, String> {
    let script = r#"
import gc, statistics, sys, time
from pxr import Usd, UsdGeom
path, repeats = sys.argv[1], int(sys.argv[2])
times = []
for _ in range(repeats):
    start = time.perf_counter()
    stage = Usd.Stage.Open(path)
    mesh = UsdGeom.Mesh(next(p for p in stage.Traverse() if p.IsA(UsdGeom.Mesh)))
    arrays = (mesh.GetPointsAttr().Get(), mesh.GetFaceVertexCountsAttr().Get(),
              mesh.GetFaceVertexIndicesAttr().Get())
    assert len(arrays[1]) == 1000000
    times.append(time.perf_counter() - start)
    del stage, mesh, arrays
    gc.collect()
print(statistics.median(times))
"#;
    let python = crate::system::env_python(root);
    let out = Command::new(&python)
        .args(["-c", script])
        .arg(path)
        .arg(repeats.max(1).to_string())
        .output()
        .map_err(|e| format!("{}: {e}", python.display()))?;
    if !out.status.success() {
        return Err(format!(
            "pxr read failed (is usd-core installed in target/python-env? `cargo xtask test` installs it): {}",
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    String::from_utf8_lossy(&out.stdout)
        .trim()
        .parse()
        .map_err(|e| format!("pxr read: {e}"))
}

pub(crate) fn run(root: &Path, repeats: usize) -> Result<(), String> {
    let mesh = subd_mesh::primitives::torus(SIDE as u32, SIDE as u32, 3.0, 1.0);
    let dir: PathBuf = root.join("target/xtask/bench/usd");
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    println!(
        "1M-face torus ({} vertices), medians of {repeats} runs",
        mesh.positions.len()
    );
    println!(
        "{:<12} {:>9} {:>9} {:>10}",
        "format", "write s", "read s", "MB"
    );
    let mut rows = Vec::new();
    for ext in ["ply", "usdc"] {
        let path = dir.join(format!("torus.{ext}"));
        let write = timed(repeats, || {
            subd_io::write_mesh(&path, &mesh, &WriteOptions::default()).map_err(|e| e.to_string())
        })?;
        let read = timed(repeats, || {
            let file =
                subd_io::read_mesh(&path, &ReadOptions::default()).map_err(|e| e.to_string())?;
            assert_eq!(file.mesh.topology.num_faces(), SIDE * SIDE);
            Ok(())
        })?;
        let mb = std::fs::metadata(&path).map_or(0.0, |m| m.len() as f64 / 1e6);
        println!("{ext:<12} {write:>9.3} {read:>9.3} {mb:>10.1}");
        rows.push((write, read));
    }
    let (ply, usd) = (rows[0], rows[1]);
    println!(
        "usdc / ply: write {:.2}×, read {:.2}× (target ≤ 2×)",
        usd.0 / ply.0,
        usd.1 / ply.1
    );
    // Without usd-core the table above still stands: the line says what is missing.
    match pxr_read(root, &dir.join("torus.usdc"), repeats) {
        Ok(pxr) => println!(
            "pxr reads the .usdc in {pxr:.3} s; subd {:.3} s ({:.2}× pxr's time; target ≤ 1×)",
            usd.1,
            usd.1 / pxr
        ),
        Err(e) => println!("pxr not timed: {e}"),
    }
    Ok(())
}
