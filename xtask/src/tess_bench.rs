//! `cargo xtask bench --tess-only`: uniform tessellation of the limit surface, subd's
//! `tessellate` against OpenSubdiv's `Bfr::RefinerSurfaceFactory` + `Bfr::Tessellation`, on
//! the bench torus (Catmull-Clark) and its triangulation (Loop).
//!
//! Both sides do the same work per run: set up (subd: the refinement or the evaluator,
//! inside `tessellate_mesh`; Bfr: the factory), then every face's samples with positions
//! and normals (Bfr: first derivatives). Bfr's time is measured inside its harness (the
//! topology refiner it starts from is not timed); subd's in this process, on 1 thread (the
//! ratio to Bfr's one thread) and on 2 (the speed-up).

use std::time::Instant;

use subd_limit::tessellation::tessellate_mesh;
use subd_schemes::{Options, Scheme};

use crate::bench::{json_number, median, quad_bench_mesh, tri_bench_mesh};
use crate::osd;

/// Runs the comparison and prints the table.
pub fn run(repeats: usize) -> Result<(), String> {
    let exe = osd::build_harness()?;
    println!(
        "uniform limit tessellation: subd tessellate_mesh (1 and 2 threads) vs OpenSubdiv 3.5 Bfr (approximation level 10); medians of {repeats} runs"
    );
    println!(
        "{:<14} {:>7} {:>5} {:>10} {:>10} {:>10} {:>10} {:>7} {:>7}",
        "scheme", "faces", "rate", "samples", "bfr s", "subd 1t s", "subd 2t s", "ratio", "1t/2t"
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
            let mut samples = 0;
            let mut time_on = |threads: usize| -> Result<f64, String> {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .map_err(|e| e.to_string())?;
                let mut times = Vec::new();
                for _ in 0..repeats {
                    let t = Instant::now();
                    let tess = pool.install(|| {
                        tessellate_mesh(&mesh.topology, &scheme, &options, &mesh.positions, rate)
                    });
                    times.push(t.elapsed().as_secs_f64());
                    samples = tess.map_err(|e| e.to_string())?.positions.len();
                }
                Ok(median(times))
            };
            let (one, two) = (time_on(1)?, time_on(2)?);
            println!(
                "{:<14} {:>7} {:>5} {:>10} {:>10.3} {:>10.3} {:>10.3} {:>7.2} {:>7.2}",
                format!("{scheme:?}"),
                mesh.topology.num_faces(),
                rate,
                samples,
                bfr,
                one,
                two,
                one / bfr,
                one / two
            );
        }
    }
    Ok(())
}
