//! `cargo xtask bench --tess-only`: uniform tessellation of the limit surface, subd's
//! `tessellate` against OpenSubdiv's `Bfr::RefinerSurfaceFactory` + `Bfr::Tessellation`, on
//! the bench torus (Catmull-Clark) and its triangulation (Loop).
//!
//! Both sides do the same work per run: set up (subd: the evaluator and its patch points;
//! Bfr: the factory), then every face's samples with positions and first derivatives. Bfr's
//! time is measured inside its harness (the topology refiner it starts from is not timed);
//! subd's in this process, on one thread (`tessellate` is serial).

use std::time::Instant;

use subd_limit::eval::LimitEvaluator;
use subd_limit::tessellation::tessellate;
use subd_schemes::{Options, Scheme};

use crate::bench::{json_number, median, quad_bench_mesh, tri_bench_mesh};
use crate::osd;

/// Runs the comparison and prints the table.
pub fn run(repeats: usize) -> Result<(), String> {
    let exe = osd::build_harness()?;
    println!(
        "uniform limit tessellation: subd tessellate (1 thread) vs OpenSubdiv 3.5 Bfr (approximation level 10); medians of {repeats} runs"
    );
    println!(
        "{:<14} {:>7} {:>5} {:>10} {:>10} {:>10} {:>12} {:>7}",
        "scheme", "faces", "rate", "samples", "bfr s", "subd s", "(setup s)", "ratio"
    );
    for (scheme, mesh) in [
        (Scheme::CatmullClark, quad_bench_mesh()),
        (Scheme::Loop, tri_bench_mesh()),
    ] {
        let options = Options::default();
        let input = osd::encode(&mesh.topology, &mesh.positions, &scheme, &options, 0);
        for rate in [4usize, 8] {
            let out = osd::run(
                &exe,
                &input,
                &["--bfr-bench", &rate.to_string(), &repeats.to_string()],
            )?;
            let line = String::from_utf8_lossy(&out);
            let bfr = json_number(&line, "seconds").ok_or("Bfr bench: no seconds")?;
            let mut times = Vec::new();
            let mut setups = Vec::new();
            let mut samples = 0;
            for _ in 0..repeats {
                let t = Instant::now();
                let ev = LimitEvaluator::new(&mesh.topology, &scheme, &options)
                    .map_err(|e| e.to_string())?;
                let pts = ev.prepare(&mesh.positions);
                setups.push(t.elapsed().as_secs_f64());
                let tess = tessellate(&ev, &pts, rate).map_err(|e| e.to_string())?;
                times.push(t.elapsed().as_secs_f64());
                samples = tess.positions.len();
            }
            let ours = median(times);
            println!(
                "{:<14} {:>7} {:>5} {:>10} {:>10.3} {:>10.3} {:>12.3} {:>7.2}",
                format!("{scheme:?}"),
                mesh.topology.num_faces(),
                rate,
                samples,
                bfr,
                ours,
                median(setups),
                ours / bfr
            );
        }
    }
    Ok(())
}
