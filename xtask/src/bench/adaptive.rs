//! The adaptive lines of `cargo xtask bench`:
//!
//! * Sun et al.'s Table 1 side by side — faces after 1 and 2 Loop levels, uniform and adaptive
//!   (flatness), with each result's largest sampled distance to the limit surface — on a
//!   ~5k-face organic scan (the Stanford bunny of `pymeshfix`, decimated to the paper's
//!   4801 faces with the `fast-simplification` package from PyPI) and a 2000-face
//!   mechanical part (`subd_mesh::primitives::gear`, the paper's count);
//! * the fair comparison: the faces adaptive refinement needs for the accuracy of uniform
//!   levels 2 and 3 (both with limit positions);
//! * speed: output faces per second of adaptive refinement against subd's and OpenSubdiv's
//!   uniform refinement of the same mesh and level.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use subd_adaptive::{
    AdaptiveRefinement, Criterion, Flatness, LimitDistance, LimitSurface, Positions,
};
use subd_mesh::{Mesh, TopologyBuilder};
use subd_schemes::{Options, Refinement, Scheme};

use crate::bench::median;
use crate::meshes::{quad_bench_mesh, tri_bench_mesh};
use crate::oracles::osd;

/// Sun et al. 2012 gives no flatness threshold; the table shows these.
const TABLE_FLATNESS_DEGREES: [f64; 3] = [10.0, 20.0, 30.0];

fn bench_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/xtask/bench")
}

fn diagonal(m: &Mesh) -> f64 {
    m.bounding_box().map_or(1.0, |(lo, hi)| (hi - lo).length())
}

/// The bunny decimated to `faces` triangles (cached under `target/`).
fn decimated_scan(faces: usize) -> Result<Mesh, String> {
    let dir = bench_dir();
    let out = dir.join(format!("bunny_{faces}.obj"));
    if !out.exists() {
        let scan = crate::meshes::scan_mesh()?;
        let full = dir.join("bunny_full.obj");
        subd_io::write_mesh(&full, &scan, &subd_io::WriteOptions::default())
            .map_err(|e| e.to_string())?;
        let have = Command::new("python3")
            .args(["-c", "import fast_simplification"])
            .status()
            .is_ok_and(|s| s.success());
        if !have {
            let ok = Command::new("python3")
                .args([
                    "-m",
                    "pip",
                    "install",
                    "--quiet",
                    "fast-simplification==0.2.0",
                ])
                .status()
                .is_ok_and(|s| s.success());
            if !ok {
                return Err("pip install fast-simplification failed".into());
            }
        }
        let script = "import sys, numpy as np, fast_simplification as fs\n\
                      v, f = [], []\n\
                      for line in open(sys.argv[1]):\n\
                      \x20   p = line.split()\n\
                      \x20   if p and p[0] == 'v': v.append([float(x) for x in p[1:4]])\n\
                      \x20   elif p and p[0] == 'f': f.append([int(x.split('/')[0]) - 1 for x in p[1:4]])\n\
                      pv, pf = fs.simplify(np.array(v), np.array(f, dtype=np.int64), target_count=int(sys.argv[3]))\n\
                      with open(sys.argv[2], 'w') as o:\n\
                      \x20   o.writelines('v %.17g %.17g %.17g\\n' % tuple(p) for p in pv)\n\
                      \x20   o.writelines('f %d %d %d\\n' % tuple(t + 1) for t in pf)\n";
        let ok = Command::new("python3")
            .args(["-c", script])
            .arg(&full)
            .arg(&out)
            .arg(faces.to_string())
            .status()
            .is_ok_and(|s| s.success());
        if !ok {
            return Err("decimating the scan failed".into());
        }
    }
    read(&out)
}

fn read(path: &Path) -> Result<Mesh, String> {
    let opts = subd_io::ReadOptions {
        accept_inconsistent_orientation: true,
        ..Default::default()
    };
    Ok(subd_io::read_mesh(path, &opts)
        .map_err(|e| e.to_string())?
        .mesh)
}

/// Faces, largest sampled distance to the limit (relative to the diagonal) and seconds of
/// one adaptive run.
struct Outcome {
    faces: usize,
    distance: f64,
    seconds: f64,
}

fn adaptive(
    m: &Mesh,
    scheme: &Scheme,
    criteria: &[&dyn Criterion],
    levels: usize,
    positions: Positions,
    surface: &LimitSurface,
) -> Result<Outcome, String> {
    let o = Options::from_hints(&m.hints);
    let t = Instant::now();
    let a = AdaptiveRefinement::new(&m.topology, &m.positions, scheme, &o, criteria, levels)
        .map_err(|e| e.to_string())?;
    let mesh = a.mesh(positions).map_err(|e| e.to_string())?;
    let seconds = t.elapsed().as_secs_f64();
    let distance = mesh
        .max_limit_distance(surface)
        .map_err(|e| e.to_string())?
        / diagonal(m);
    Ok(Outcome {
        faces: mesh.num_faces(),
        distance,
        seconds,
    })
}

/// Sun et al.'s Table 1 and the fair comparison on the scan and the gear.
fn table_one() -> Result<(), String> {
    let meshes: Vec<(&str, usize, Mesh)> = vec![
        ("scan (bunny)", 4801, decimated_scan(4801)?),
        ("gear", 2000, subd_mesh::primitives::gear(20, 5, 4)),
    ];
    println!();
    println!(
        "Sun et al. 2012 Table 1 side by side (Loop): faces after 1 and 2 levels, uniform and adaptive (flatness, the paper's rule; the paper gives no ε_T), with each result's largest sampled distance to the limit surface / diagonal (vertices at their refined positions); paper: head 4801 → 19204 / 76816 uniform, 13442 / 30151 adaptive; gear 2000 → 8000 / 32000, 5963 / 11357"
    );
    println!(
        "{:<14} {:>6} {:>5} {:>10} {:>11} {:>5} {:>10} {:>11} {:>7} {:>12}",
        "mesh",
        "faces",
        "level",
        "uniform",
        "dist",
        "ε_T",
        "adaptive",
        "dist",
        "ratio",
        "paper ratio"
    );
    let paper = [[0.70, 0.39], [0.75, 0.35]];
    for (k, (name, _, m)) in meshes.iter().enumerate() {
        let o = Options::from_hints(&m.hints);
        let surface = LimitSurface::new(&m.topology, &m.positions, &Scheme::Loop, &o)
            .map_err(|e| e.to_string())?;
        for level in 1..=2 {
            let u = adaptive(m, &Scheme::Loop, &[], level, Positions::Refined, &surface)?;
            for eps in TABLE_FLATNESS_DEGREES {
                let flat = Flatness::new(eps).map_err(|e| e.to_string())?;
                let a = adaptive(
                    m,
                    &Scheme::Loop,
                    &[&flat],
                    level,
                    Positions::Refined,
                    &surface,
                )?;
                println!(
                    "{:<14} {:>6} {:>5} {:>10} {:>11.3e} {:>5} {:>10} {:>11.3e} {:>7.2} {:>12.2}",
                    name,
                    m.topology.num_faces(),
                    level,
                    u.faces,
                    u.distance,
                    eps,
                    a.faces,
                    a.distance,
                    a.faces as f64 / u.faces as f64,
                    paper[k][level - 1]
                );
            }
        }
    }
    println!();
    println!(
        "Faces for a given accuracy (Loop, limit positions): D = the largest sampled distance to the limit of uniform level L; adaptive --max-distance D --limit (level cap L + 3); targets: ratio ≤ 0.30 at L = 2, ≤ 0.15 at L = 3"
    );
    println!(
        "{:<14} {:>3} {:>10} {:>11} {:>10} {:>11} {:>7} {:>9}",
        "mesh", "L", "uniform", "D / diag", "adaptive", "dist", "ratio", "adapt s"
    );
    for (name, _, m) in &meshes {
        let o = Options::from_hints(&m.hints);
        let surface = LimitSurface::new(&m.topology, &m.positions, &Scheme::Loop, &o)
            .map_err(|e| e.to_string())?;
        for level in 2..=3 {
            let u = adaptive(m, &Scheme::Loop, &[], level, Positions::Limit, &surface)?;
            let d = u.distance * diagonal(m);
            let s2 = LimitSurface::new(&m.topology, &m.positions, &Scheme::Loop, &o)
                .map_err(|e| e.to_string())?;
            let c = LimitDistance::new(s2, d, true).map_err(|e| e.to_string())?;
            let a = adaptive(
                m,
                &Scheme::Loop,
                &[&c],
                level + 3,
                Positions::Limit,
                &surface,
            )?;
            println!(
                "{:<14} {:>3} {:>10} {:>11.3e} {:>10} {:>11.3e} {:>7.3} {:>9.3}",
                name,
                level,
                u.faces,
                u.distance,
                a.faces,
                a.distance,
                a.faces as f64 / u.faces as f64,
                a.seconds
            );
        }
    }
    Ok(())
}

/// Median seconds of subd's uniform refinement (topology from the face lists, positions).
fn subd_uniform(m: &Mesh, scheme: &Scheme, level: usize, repeats: usize) -> (f64, usize) {
    let t = &m.topology;
    let sizes: Vec<u32> = (0..t.num_faces()).map(|f| t.face_size(f) as u32).collect();
    let mut faces = 0;
    let times = (0..repeats)
        .map(|_| {
            let t0 = Instant::now();
            let topo = TopologyBuilder::new(t.num_vertices())
                .accept_inconsistent_orientation(true)
                .build(&sizes, t.all_face_vertices())
                .expect("valid");
            let r =
                Refinement::new(&topo, scheme.clone(), &Options::default(), level).expect("refine");
            let p = r.refine_points(&m.positions);
            faces = r.faces(level).0.len() - 1;
            std::hint::black_box(p);
            t0.elapsed().as_secs_f64()
        })
        .collect();
    (median(times), faces)
}

/// Median seconds of OpenSubdiv's uniform refinement (its harness, own process).
fn osd_uniform(
    exe: &Path,
    m: &Mesh,
    scheme: &Scheme,
    level: usize,
    repeats: usize,
) -> Result<f64, String> {
    let input = osd::encode(
        &m.topology,
        &m.positions,
        scheme,
        &Options::default(),
        level as u32,
    );
    let path = bench_dir().join("adaptive_osd.bin");
    std::fs::write(&path, &input).map_err(|e| e.to_string())?;
    let out = Command::new(exe)
        .args(["--bench", &repeats.to_string()])
        .stdin(std::fs::File::open(&path).map_err(|e| e.to_string())?)
        .output()
        .map_err(|e| e.to_string())?;
    if !out.status.success() {
        return Err(String::from_utf8_lossy(&out.stderr).to_string());
    }
    let line = String::from_utf8_lossy(&out.stdout).to_string();
    crate::bench::json_number(&line, "seconds").ok_or_else(|| "no seconds".into())
}

/// Output faces per second: adaptive (flatness) against uniform refinement of subd and
/// OpenSubdiv, on the bench torus and the scan.
fn speed(exe: &Path, repeats: usize) -> Result<(), String> {
    let threads = rayon::current_num_threads();
    println!();
    println!(
        "Speed: output faces per second (median of {repeats}, {threads} threads); adaptive = AdaptiveRefinement::new + mesh (refined positions), flatness ε_T as given; uniform = topology from the face lists + positions; targets: adaptive rate ≥ 0.5 × subd uniform, ≥ OpenSubdiv uniform"
    );
    println!(
        "{:<14} {:>7} {:>5} {:>6} {:>10} {:>9} {:>11} {:>11} {:>11} {:>8} {:>8}",
        "mesh",
        "faces",
        "level",
        "ε_T",
        "adaptive",
        "adapt s",
        "adapt f/s",
        "subd f/s",
        "osd f/s",
        "/subd",
        "/osd"
    );
    let scan = crate::meshes::scan_mesh()?;
    let cases: Vec<(&str, Scheme, Mesh, f64)> = vec![
        (
            "torus catmark",
            Scheme::CatmullClark,
            quad_bench_mesh(),
            2.0,
        ),
        ("torus loop", Scheme::Loop, tri_bench_mesh(), 2.0),
        ("scan loop", Scheme::Loop, scan, 10.0),
    ];
    for (name, scheme, m, eps) in &cases {
        let flat = Flatness::new(*eps).map_err(|e| e.to_string())?;
        let o = Options::from_hints(&m.hints);
        for level in 2..=3 {
            let mut faces = 0;
            let times: Vec<f64> = (0..repeats)
                .map(|_| {
                    let t0 = Instant::now();
                    let a = AdaptiveRefinement::new(
                        &m.topology,
                        &m.positions,
                        &*scheme,
                        &o,
                        &[&flat],
                        level,
                    )
                    .expect("adaptive");
                    let mesh = a.mesh(Positions::Refined).expect("mesh");
                    faces = mesh.num_faces();
                    t0.elapsed().as_secs_f64()
                })
                .collect();
            let at = median(times);
            let (ut, uf) = subd_uniform(m, scheme, level, repeats);
            let osd = osd_uniform(exe, m, scheme, level, repeats).ok();
            let ar = faces as f64 / at;
            let ur = uf as f64 / ut;
            let or = osd.map(|s| uf as f64 / s);
            println!(
                "{:<14} {:>7} {:>5} {:>6} {:>10} {:>9.3} {:>11.3e} {:>11.3e} {:>11} {:>8.3} {:>8}",
                name,
                m.topology.num_faces(),
                level,
                eps,
                faces,
                at,
                ar,
                ur,
                or.map_or_else(|| "-".into(), |r| format!("{r:.3e}")),
                ar / ur,
                or.map_or_else(|| "-".into(), |r| format!("{:.3}", ar / r))
            );
        }
    }
    Ok(())
}

/// Every adaptive line of the benchmark.
pub fn run(repeats: usize) -> Result<(), String> {
    std::fs::create_dir_all(bench_dir()).map_err(|e| e.to_string())?;
    table_one()?;
    let exe = osd::build_harness()?;
    speed(&exe, repeats)
}
