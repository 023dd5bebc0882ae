//! `cargo xtask bench --tess-only`: uniform tessellation of the limit surface at rate 8, subd's
//! `tessellate_mesh` against OpenSubdiv's `Bfr::RefinerSurfaceFactory` + `Bfr::Tessellation`,
//! on the three kinds of mesh of issue 49: a torus of 8,192 regular quads (Catmull-Clark),
//! an open scan with boundaries (the bunny, 99,785 triangles, Loop) and a CAD-like part with
//! creases (a gear of 13,000 triangles and 2,600 infinitely sharp edges, Loop).
//!
//! Both sides do the same work per run: set up (subd: the exact-limit patch table inside
//! `tessellate_mesh`; Bfr: the factory), then every face's samples with positions and normals
//! (Bfr: first derivatives). Bfr's time is measured inside its harness (the topology refiner
//! it starts from is not timed); subd's in this process, on 1 thread (the ratio to Bfr's one
//! thread) and on 2 (the speed-up). subd's time includes writing its output mesh (shared
//! samples numbered, faces and grids), which Bfr's harness does not make.

use std::time::Instant;

use subd_limit::patches::PatchTable;
use subd_limit::tessellation::tessellate_mesh;
use subd_mesh::Mesh;
use subd_schemes::{Options, Scheme};

use crate::bench::{json_number, median};
use crate::oracles::osd;

/// The rate of the comparison (the issue's).
const RATE: usize = 8;

/// The three meshes: name, scheme, mesh.
fn meshes() -> Result<Vec<(&'static str, Scheme, Mesh)>, String> {
    Ok(vec![
        (
            "torus (regular quads)",
            Scheme::CatmullClark,
            subd_mesh::primitives::torus(128, 64, 3.0, 1.0),
        ),
        ("scan (bunny)", Scheme::Loop, crate::meshes::scan_mesh()?),
        (
            "CAD part (gear)",
            Scheme::Loop,
            subd_mesh::primitives::gear(65, 5, 9),
        ),
    ])
}

/// Runs the comparison and prints the table.
pub fn run(repeats: usize) -> Result<(), String> {
    let exe = osd::build_harness()?;
    println!(
        "uniform limit tessellation at rate {RATE}: subd tessellate_mesh (1 and 2 threads) vs OpenSubdiv 3.5 Bfr (approximation level 10, 1 thread); medians of {repeats} runs"
    );
    println!(
        "{:<22} {:>7} {:>9} {:>8} {:>9} {:>9} {:>9} {:>7} {:>7}",
        "mesh", "faces", "samples", "bfr s", "table s", "subd 1t", "subd 2t", "ratio", "1t/2t"
    );
    for (name, scheme, mesh) in meshes()? {
        let options = Options::default();
        let input = osd::encode(&mesh.topology, &mesh.positions, &scheme, &options, 0);
        let out = osd::run(
            &exe,
            &input,
            &["--bfr-bench", &RATE.to_string(), &repeats.to_string()],
        )?;
        let line = String::from_utf8_lossy(&out);
        let bfr = json_number(&line, "seconds").ok_or("Bfr bench: no seconds")?;
        let mut samples = 0;
        let mut time_on = |threads: usize, table_only: bool| -> Result<f64, String> {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .map_err(|e| e.to_string())?;
            let mut times = Vec::new();
            for _ in 0..repeats {
                let t = Instant::now();
                if table_only {
                    pool.install(|| {
                        PatchTable::exact_limit(&mesh.topology, &mesh.positions, &scheme, &options)
                    })
                    .map_err(|e| e.to_string())?;
                    times.push(t.elapsed().as_secs_f64());
                    continue;
                }
                let tess = pool.install(|| {
                    tessellate_mesh(&mesh.topology, &scheme, &options, &mesh.positions, RATE)
                });
                times.push(t.elapsed().as_secs_f64());
                samples = tess.map_err(|e| e.to_string())?.positions.len();
            }
            Ok(median(times))
        };
        let (table, one, two) = (time_on(1, true)?, time_on(1, false)?, time_on(2, false)?);
        println!(
            "{:<22} {:>7} {:>9} {:>8.3} {:>9.3} {:>9.3} {:>9.3} {:>7.2} {:>7.2}",
            name,
            mesh.topology.num_faces(),
            samples,
            bfr,
            table,
            one,
            two,
            one / bfr,
            one / two
        );
    }
    Ok(())
}
