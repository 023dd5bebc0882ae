//! `cargo xtask bench --patches-only`: building a patch table and evaluating it at random
//! points, subd's `PatchTable` against OpenSubdiv's `RefineAdaptive` +
//! `PatchTableFactory::Create` (+ the refined and local points) and its `PatchMap::FindPatch`
//! + `EvaluateBasis` loop, same options, OpenSubdiv on its one thread, subd on 1 and 2.

use std::time::Instant;

use subd_limit::eval::FaceParam;
use subd_limit::patches::{EndCaps, PatchOptions, PatchTable};
use subd_mesh::Mesh;
use subd_schemes::{Options, Scheme};

use crate::bench::{json_number, median};
use crate::conformance::patches::harness_args;
use crate::meshes::{quad_bench_mesh, tri_bench_mesh};
use crate::oracles::osd;

/// Random evaluation points, one root face at a time uniformly: (base face, sub-face, u, v)
/// and the harness's ptex face.
fn random_points(mesh: &Mesh, scheme: &Scheme, count: usize) -> Vec<(FaceParam, u32)> {
    let t = &mesh.topology;
    let mut roots = Vec::new();
    for f in 0..t.num_faces() {
        let n = t.face_size(f);
        let subs = if *scheme == Scheme::Loop || n == 4 {
            1
        } else {
            n
        };
        for sub in 0..subs {
            roots.push((f, sub));
        }
    }
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    (0..count)
        .map(|_| {
            let r = (next() % roots.len() as u64) as usize;
            let (face, sub) = roots[r];
            let unit = |x: u64| (x >> 11) as f64 / (1u64 << 53) as f64;
            let (mut u, mut v) = (unit(next()), unit(next()));
            if *scheme == Scheme::Loop && u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            (FaceParam { face, sub, u, v }, r as u32)
        })
        .collect()
}

/// Median seconds of `work` over `repeats` runs on a pool of `threads`.
fn timed<T: Send>(
    threads: usize,
    repeats: usize,
    mut work: impl FnMut() -> T + Send,
) -> Result<f64, String> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| e.to_string())?;
    let mut times = Vec::with_capacity(repeats);
    for _ in 0..repeats {
        let t = Instant::now();
        std::hint::black_box(pool.install(&mut work));
        times.push(t.elapsed().as_secs_f64());
    }
    Ok(median(times))
}

/// Runs the comparison and prints the table.
pub fn run(repeats: usize) -> Result<(), String> {
    let exe = osd::build_harness()?;
    const POINTS: usize = 1_000_000;
    println!(
        "patch tables: subd PatchTable (1 and 2 threads) vs OpenSubdiv 3.5 (1 thread); medians of {repeats} runs"
    );
    println!(
        "{:<14} {:>7} {:>4} {:<9} {:>8} {:>9} {:>9} {:>9} {:>6} {:>6} | {:>8} {:>8} {:>8} {:>6} {:>6}",
        "scheme",
        "faces",
        "iso",
        "caps",
        "patches",
        "osd s",
        "subd 1t",
        "subd 2t",
        "ratio",
        "1t/2t",
        "osd 1M",
        "subd 1t",
        "subd 2t",
        "ratio",
        "1t/2t"
    );
    for (scheme, mesh, caps) in [
        (
            Scheme::CatmullClark,
            quad_bench_mesh(),
            EndCaps::GregoryBasis,
        ),
        (Scheme::Loop, tri_bench_mesh(), EndCaps::GregoryBasis),
    ] {
        let rules = Options::default();
        let points = random_points(&mesh, &scheme, POINTS);
        for isolation in [2u8, 6] {
            let po = PatchOptions {
                isolation,
                end_caps: caps,
                inf_sharp: true,
                legacy_sharp_corners: false,
                single_crease: false,
            };
            let input = osd::encode(
                &mesh.topology,
                &mesh.positions,
                &scheme,
                &rules,
                isolation.into(),
            );
            let harness: Vec<(u32, f64, f64)> =
                points.iter().map(|(p, r)| (*r, p.u, p.v)).collect();
            let input = osd::encode_eval_points(input, &harness);
            let mut args = harness_args(&po);
            args[0] = "--patches-bench".into();
            args.push(repeats.to_string());
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            let line = String::from_utf8_lossy(&osd::run(&exe, &input, &args)?).to_string();
            let osd_build = json_number(&line, "build_seconds").ok_or("no build_seconds")?;
            let osd_eval = json_number(&line, "eval_seconds").ok_or("no eval_seconds")?;
            let build = |threads| {
                timed(threads, repeats, || {
                    PatchTable::new(&mesh.topology, &mesh.positions, &scheme, &rules, &po)
                        .map(|t| t.census().patches)
                })
            };
            let (b1, b2) = (build(1)?, build(2)?);
            let table = PatchTable::new(&mesh.topology, &mesh.positions, &scheme, &rules, &po)
                .map_err(|e| e.to_string())?;
            let params: Vec<FaceParam> = points.iter().map(|(p, _)| *p).collect();
            let mut out = vec![[subd_mesh::DVec3::ZERO; 3]; params.len()];
            let mut eval = |threads| {
                timed(threads, repeats, || {
                    table.evaluate_first_into(&params, &mut out).is_ok()
                })
            };
            let e1 = eval(1)?;
            let e2 = eval(2)?;
            println!(
                "{:<14} {:>7} {:>4} {:<9} {:>8} {:>9.3} {:>9.3} {:>9.3} {:>6.2} {:>6.2} | {:>8.3} {:>8.3} {:>8.3} {:>6.2} {:>6.2}",
                format!("{scheme:?}"),
                mesh.topology.num_faces(),
                isolation,
                caps.name(),
                table.census().patches,
                osd_build,
                b1,
                b2,
                b1 / osd_build,
                b1 / b2,
                osd_eval,
                e1,
                e2,
                e1 / osd_eval,
                e1 / e2
            );
        }
    }
    Ok(())
}
