//! `cargo xtask bench --fvar-only`: face-varying refinement of a UV channel with seams on the
//! quad bench torus, subd against OpenSubdiv's `InterpolateFaceVarying` (double precision),
//! levels 1..L.

use std::path::Path;
use std::time::Instant;

use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};
use subd_mesh::{Mesh, Topology};
use subd_schemes::{FaceVaryingRefinement, Options, Refinement, Scheme};

use crate::bench::{json_number, median};
use crate::meshes::quad_bench_mesh;
use crate::oracles::osd;

/// The torus's own UV layout: u around the ring, v around the tube, each in [0, 1], cut
/// where they wrap (one seam loop each way), so vertices on the cuts have two or four
/// values.
pub fn torus_uv(mesh: &Mesh) -> FVarChannel {
    let t: &Topology = &mesh.topology;
    let angle = |p: subd_mesh::DVec3| {
        let u = p.y.atan2(p.x) / std::f64::consts::TAU;
        let ring = (p.x * p.x + p.y * p.y).sqrt() - 3.0;
        let v = p.z.atan2(ring) / std::f64::consts::TAU;
        [u.rem_euclid(1.0), v.rem_euclid(1.0)]
    };
    let base: Vec<[f64; 2]> = mesh.positions.iter().map(|&p| angle(p)).collect();
    // Value index: vertex × 4 + (u wrapped?) + 2 × (v wrapped?).
    let mut indices = Vec::with_capacity(t.num_face_vertices());
    for f in 0..t.num_faces() {
        let fv = t.face_vertices(f);
        let span = |k: usize| {
            let lo = fv.iter().map(|&v| base[v as usize][k]).fold(1.0, f64::min);
            let hi = fv.iter().map(|&v| base[v as usize][k]).fold(0.0, f64::max);
            hi - lo > 0.5
        };
        let (wrap_u, wrap_v) = (span(0), span(1));
        for &v in fv {
            let [u, w] = base[v as usize];
            let bump = u32::from(wrap_u && u < 0.5) + 2 * u32::from(wrap_v && w < 0.5);
            indices.push(4 * v + bump);
        }
    }
    let values = base
        .iter()
        .flat_map(|&[u, v]| [u, v, u + 1.0, v, u, v + 1.0, u + 1.0, v + 1.0])
        .collect();
    FVarChannel::new(t, 2, values, indices).expect("indices made for the topology")
}

/// Runs the benchmark and prints a table: setup (topology refinement with the channel),
/// values (the refinement of the UVs, allocating each level's output) and values again into
/// those outputs, medians of `repeats` runs. Each level is measured in
/// `rounds` back-to-back rounds of (OpenSubdiv, subd on one thread, subd on all threads);
/// times are medians over the rounds and each ratio the median of the rounds' ratios, so a
/// slow spell of the shared machine hits both sides of a ratio.
pub fn run(levels: usize, repeats: usize, rounds: usize) -> Result<(), String> {
    let mesh = quad_bench_mesh();
    let uv = torus_uv(&mesh);
    let exe = osd::build_harness()?;
    let threads = rayon::current_num_threads();
    print_header(&mesh, &uv, rounds, repeats);
    for mode in [
        FVarLinearInterpolation::CornersPlus1,
        FVarLinearInterpolation::All,
    ] {
        for l in 1..=levels {
            let input = osd::encode_fvar(
                osd::encode(
                    &mesh.topology,
                    &mesh.positions,
                    &Scheme::CatmullClark,
                    &Options::default(),
                    l as u32,
                ),
                uv.values(),
                uv.indices(),
            );
            // Per round: OpenSubdiv topology, values and values into its buffers; subd
            // setup, values and values into its buffers on one thread, and values on all
            // threads.
            let mut runs: Vec<[f64; 8]> = Vec::with_capacity(rounds);
            for _ in 0..rounds {
                let [osd_topo, osd_values, osd_into] = measure_osd(&exe, &input, mode, repeats)?;
                let [setup1, values1, into1] = measure_subd(&mesh, &uv, mode, l, repeats, 1)?;
                let [_, values_n, into_n] = measure_subd(&mesh, &uv, mode, l, repeats, threads)?;
                runs.push([
                    osd_topo, osd_values, setup1, values1, values_n, osd_into, into1, into_n,
                ]);
            }
            print_row(mode, l, &runs);
        }
    }
    println!(
        "osd topo: Create + RefineUniform with the channel; subd setup: Refinement + FaceVaryingRefinement (1 thread);"
    );
    println!(
        "values×: subd's UV refinement (1 thread) over InterpolateFaceVarying's through every level, each allocating its outputs; values×N: on {threads} threads"
    );
    println!(
        "into×: the same again into those outputs (refine_level_into; InterpolateFaceVarying into the caller's vectors), 1 thread; into×N: on {threads} threads"
    );
    Ok(())
}

/// The table's opening line and column names.
fn print_header(mesh: &Mesh, uv: &FVarChannel, rounds: usize, repeats: usize) {
    println!(
        "face-varying refinement: {} quads, {} UV values, seams on both wrap loops; {rounds} rounds of (OpenSubdiv, subd 1 thread, subd all threads), each the median of {repeats} runs",
        mesh.topology.num_faces(),
        uv.num_values()
    );
    println!(
        "{:<14} {:>5} {:>11} {:>11} {:>11} {:>11} {:>9} {:>9} {:>11} {:>11} {:>9} {:>9}",
        "mode",
        "level",
        "osd topo",
        "osd values",
        "subd setup",
        "subd values",
        "values×",
        "values×N",
        "osd into",
        "subd into",
        "into×",
        "into×N"
    );
}

/// One OpenSubdiv run on `input` (the harness's own medians of `repeats`): topology,
/// values, and values into its buffers.
fn measure_osd(
    exe: &Path,
    input: &[u8],
    mode: FVarLinearInterpolation,
    repeats: usize,
) -> Result<[f64; 3], String> {
    let out = osd::run(
        exe,
        input,
        &[
            "--fvar-bench",
            &mode.to_shape_tag().to_string(),
            &repeats.to_string(),
        ],
    )?;
    let line = String::from_utf8_lossy(&out);
    let osd_topo = json_number(&line, "topology_seconds").ok_or("no topology time")?;
    let osd_values = json_number(&line, "fvar_seconds").ok_or("no fvar time")?;
    let osd_into = json_number(&line, "fvar_into_seconds").ok_or("no fvar into time")?;
    Ok([osd_topo, osd_values, osd_into])
}

/// subd on `n` threads, medians of `repeats` runs to level `l`: setup, values, and values
/// again into the same buffers.
fn measure_subd(
    mesh: &Mesh,
    uv: &FVarChannel,
    mode: FVarLinearInterpolation,
    l: usize,
    repeats: usize,
    n: usize,
) -> Result<[f64; 3], String> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build()
        .map_err(|e| e.to_string())?;
    let (mut setup, mut values, mut into) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..repeats {
        pool.install(|| {
            let t0 = Instant::now();
            let r = Refinement::new(&mesh.topology, Scheme::CatmullClark, &Options::default(), l)
                .expect("refine");
            let fr = FaceVaryingRefinement::new(&r, uv, mode).expect("channel");
            let t1 = Instant::now();
            let mut out = fr.refine_values(&r, uv.values(), 2);
            let t2 = Instant::now();
            // Again into the same buffers, as the OpenSubdiv side does.
            for level in 1..=l {
                let (done, rest) = out.split_at_mut(level);
                fr.refine_level_into(&r, level, &done[level - 1], &mut rest[0], 2);
            }
            let t3 = Instant::now();
            std::hint::black_box(out);
            setup.push((t1 - t0).as_secs_f64());
            values.push((t2 - t1).as_secs_f64());
            into.push((t3 - t2).as_secs_f64());
        });
    }
    Ok([median(setup), median(values), median(into)])
}

/// One row: medians over the rounds of each column of `runs`, and the medians of the
/// rounds' ratios.
fn print_row(mode: FVarLinearInterpolation, l: usize, runs: &[[f64; 8]]) {
    let col = |i: usize| median(runs.iter().map(|r| r[i]).collect());
    let ratio = |i: usize, of: usize| median(runs.iter().map(|r| r[i] / r[of]).collect());
    println!(
        "{:<14} {:>5} {:>10.2}ms {:>10.2}ms {:>10.2}ms {:>10.2}ms {:>9.2} {:>9.2} {:>10.2}ms {:>10.2}ms {:>9.2} {:>9.2}",
        mode.name(),
        l,
        1e3 * col(0),
        1e3 * col(1),
        1e3 * col(2),
        1e3 * col(3),
        ratio(3, 1),
        ratio(4, 1),
        1e3 * col(5),
        1e3 * col(6),
        ratio(6, 5),
        ratio(7, 5)
    );
}
