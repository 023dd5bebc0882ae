//! `cargo xtask bench --split-only`: Doo-Sabin, √3 and the butterflies against CGAL and
//! OpenMesh on ~100k-face meshes, levels 1–3, in one run.
//!
//! Every measurement runs in its own process (the CGAL/OpenMesh harness in bench mode, or
//! `xtask bench-split-run` for subd), so its peak memory is its own. Both sides are timed
//! from face lists in memory to the refined positions: building the library's mesh (subd's
//! `TopologyBuilder::build`) plus the subdivision. Times are medians of `repeats` runs; each
//! configuration runs `rounds` times back to back and the table shows medians over rounds.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use subd_mesh::{Mesh, TopologyBuilder};

use subd_schemes::{Options, Refinement, Scheme};

use crate::bench::{json_number, median, peak_rss_bytes};
use crate::meshes::{quad_bench_mesh, split_quads};
use crate::oracles::geom::{self, Library};

/// The triangle bench mesh: a 112 × 112 torus with hexagons, refined once by Catmull-Clark
/// (extraordinary vertices of valence 3 and 6) and every quad split along a diagonal: about
/// 100k triangles, valences 3 to 12.
pub fn tri_100k_mesh() -> Mesh {
    let base = subd_mesh::primitives::torus_with_hexagons(112, 112, 8, 3.0, 1.0);
    let r = Refinement::new(&base.topology, Scheme::CatmullClark, &Options::default(), 1)
        .expect("refine");
    let pts = r.refine_points(&base.positions).pop().expect("level 1");
    split_quads(&Mesh::new(r.into_topology(1), pts).expect("finite"))
}

fn scheme_named(name: &str) -> Option<Scheme> {
    name.parse::<Scheme>().ok().filter(|s| !s.is_opensubdiv())
}

/// The subd side, in a child process: from the face lists of `mesh`, build the topology and
/// refine it `levels` levels with positions, `repeats` times; one JSON line.
pub fn run_subd(
    mesh: &Path,
    scheme: &str,
    levels: usize,
    threads: usize,
    repeats: usize,
) -> Result<(), String> {
    let scheme = scheme_named(scheme).ok_or_else(|| format!("unknown scheme {scheme}"))?;
    let file =
        subd_io::read_mesh(mesh, &subd_io::ReadOptions::default()).map_err(|e| e.to_string())?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| e.to_string())?;
    let (base, pos) = (&file.mesh.topology, &file.mesh.positions);
    let sizes: Vec<u32> = base.face_sizes().collect();
    let mut times = Vec::new();
    let mut vertices = 0;
    for _ in 0..repeats {
        pool.install(|| {
            let t0 = Instant::now();
            let topo = TopologyBuilder::new(base.num_vertices())
                .build(&sizes, base.all_face_vertices())
                .expect("valid base");
            let r = Refinement::new(&topo, scheme.clone(), &Options::default(), levels)
                .expect("refine");
            let p = r.refine_points(pos);
            times.push(t0.elapsed().as_secs_f64());
            vertices = p[levels].len();
        });
    }
    println!(
        "{{\"seconds\": {:.9}, \"peak_rss_bytes\": {}, \"vertices\": {}}}",
        median(times),
        peak_rss_bytes(),
        vertices
    );
    Ok(())
}

#[derive(Clone, Copy)]
struct Measure {
    seconds: f64,
    peak_mib: f64,
    vertices: f64,
}

fn measure(cmd: &mut Command) -> Result<Measure, String> {
    let out = cmd.output().map_err(|e| e.to_string())?;
    if !out.status.success() {
        return Err(format!(
            "{cmd:?}: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    let line = String::from_utf8_lossy(&out.stdout).to_string();
    Ok(Measure {
        seconds: json_number(&line, "seconds").ok_or("no seconds")?,
        peak_mib: json_number(&line, "peak_rss_bytes").ok_or("no peak")? / (1024.0 * 1024.0),
        vertices: json_number(&line, "vertices").ok_or("no vertices")?,
    })
}

/// One round of a configuration: the references (CGAL, OpenMesh) that have the scheme, then
/// subd on one thread and on all.
type Round = (Vec<Option<Measure>>, Measure, Measure);

/// One row of the table: a scheme, its mesh and the references that have it.
struct Case {
    scheme: &'static str,
    mesh: &'static str,
    /// (library, the harness's scheme name).
    references: &'static [(Library, &'static str)],
}

const CASES: &[Case] = &[
    Case {
        scheme: "doo-sabin",
        mesh: "quad",
        references: &[(Library::Cgal, "doo-sabin")],
    },
    Case {
        scheme: "sqrt3",
        mesh: "tri",
        references: &[(Library::Cgal, "sqrt3"), (Library::OpenMesh, "sqrt3")],
    },
    Case {
        scheme: "modified-butterfly",
        mesh: "tri",
        references: &[(Library::OpenMesh, "modified-butterfly")],
    },
    // No library ships the classic butterfly: OpenMesh's modified one is the nearest (the
    // same split, stencils of the same size).
    Case {
        scheme: "butterfly",
        mesh: "tri",
        references: &[(Library::OpenMesh, "modified-butterfly")],
    },
];

/// Runs the comparison and prints the table.
pub fn run(levels: usize, repeats: usize, rounds: usize) -> Result<(), String> {
    let harness = geom::build_harness()?;
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/xtask/bench");
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let me = std::env::current_exe().map_err(|e| e.to_string())?;
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let files = write_meshes(&dir)?;
    print_header(rounds, repeats, threads);
    for case in CASES {
        let (_, obj, off, faces) = files.iter().find(|f| f.0 == case.mesh).expect("bench mesh");
        for level in 1..=levels {
            let reference = |lib: Library, name: &str| {
                measure(
                    Command::new(&harness)
                        .args(["bench", lib.name(), name, &level.to_string()])
                        .arg(off)
                        .arg(repeats.to_string()),
                )
            };
            let subd = |t: usize| {
                measure(Command::new(&me).args([
                    "bench-split-run",
                    "--mesh",
                    obj.to_str().unwrap(),
                    "--scheme",
                    case.scheme,
                    "--levels",
                    &level.to_string(),
                    "--threads",
                    &t.to_string(),
                    "--repeats",
                    &repeats.to_string(),
                ]))
            };
            let mut runs: Vec<Round> = Vec::new();
            for _ in 0..rounds {
                let mut refs = vec![None, None];
                for &(lib, name) in case.references {
                    refs[usize::from(lib == Library::OpenMesh)] = Some(reference(lib, name)?);
                }
                runs.push((refs, subd(1)?, subd(threads)?));
            }
            print_row(case, *faces, level, &runs);
        }
    }
    Ok(())
}

/// Writes the quad and triangle bench meshes into `dir`, as OBJ for subd and OFF for the
/// references; (name, OBJ path, OFF path, faces) of each.
fn write_meshes(dir: &Path) -> Result<Vec<(&'static str, PathBuf, PathBuf, usize)>, String> {
    let mut files = Vec::new();
    for (name, mesh) in [("quad", quad_bench_mesh()), ("tri", tri_100k_mesh())] {
        let obj = dir.join(format!("split_{name}.obj"));
        let off = dir.join(format!("split_{name}.off"));
        subd_io::write_mesh(&obj, &mesh, &subd_io::WriteOptions::default())
            .map_err(|e| e.to_string())?;
        geom::write_off(&off, &mesh.topology, &mesh.positions)?;
        files.push((name, obj, off, mesh.topology.num_faces()));
    }
    Ok(files)
}

/// The table's opening line and column names.
fn print_header(rounds: usize, repeats: usize, threads: usize) {
    println!(
        "subd split schemes vs CGAL 5.5 and OpenMesh 9.0 (double), from face lists to refined positions; {rounds} rounds, each the median of {repeats} runs; ratio = subd 1 thread / the faster reference"
    );
    println!(
        "{:<19} {:>7} {:>5} {:>9} {:>10} {:>10} {:>10} {:>10} {:>7} {:>8} {:>8} {:>8}",
        "scheme",
        "faces",
        "level",
        "out verts",
        "cgal s",
        "openmesh s",
        "subd 1T s",
        format!("subd {threads}T s"),
        "ratio",
        "cgal MB",
        "om MB",
        "subd MB"
    );
}

/// One row: medians over the rounds `runs`, "-" where no reference has the scheme; the
/// ratio against the faster reference of each round; peak memories over the rounds.
fn print_row(case: &Case, faces: usize, level: usize, runs: &[Round]) {
    let med = |f: &dyn Fn(&Round) -> Option<f64>| {
        let v: Vec<f64> = runs.iter().filter_map(f).collect();
        (!v.is_empty()).then(|| median(v))
    };
    let show =
        |x: Option<f64>, prec: usize| x.map_or_else(|| "-".to_string(), |x| format!("{x:.prec$}"));
    let cgal = med(&|r| r.0[0].map(|m| m.seconds));
    let om = med(&|r| r.0[1].map(|m| m.seconds));
    let ratio = med(&|r| {
        let faster =
            r.0.iter()
                .flatten()
                .map(|m| m.seconds)
                .fold(f64::INFINITY, f64::min);
        faster.is_finite().then(|| r.1.seconds / faster)
    });
    let peak = |f: &dyn Fn(&Round) -> Option<f64>| runs.iter().filter_map(f).reduce(f64::max);
    println!(
        "{:<19} {:>7} {:>5} {:>9} {:>10} {:>10} {:>10.4} {:>10.4} {:>7} {:>8} {:>8} {:>8.0}",
        case.scheme,
        faces,
        level,
        runs[0].1.vertices,
        show(cgal, 4),
        show(om, 4),
        med(&|r| Some(r.1.seconds)).unwrap_or(f64::NAN),
        med(&|r| Some(r.2.seconds)).unwrap_or(f64::NAN),
        show(ratio, 3),
        show(peak(&|r| r.0[0].map(|m| m.peak_mib)), 0),
        show(peak(&|r| r.0[1].map(|m| m.peak_mib)), 0),
        peak(&|r| Some(r.1.peak_mib.max(r.2.peak_mib))).unwrap_or(f64::NAN)
    );
}
