//! `cargo xtask conformance`: subd's uniform refinement against OpenSubdiv's, level by level,
//! on every shape of `../shared/meshes/osd` and on random meshes.

use std::path::{Path, PathBuf};

use subd_mesh::{DVec3, Topology};
use subd_schemes::{Options, Refinement, Scheme};

use crate::osd;

/// Tolerance on max |Δ| / bounding-box diagonal.
const TOLERANCE: f64 = 1e-12;
/// Levels are capped where the mesh would pass this many vertices.
const MAX_VERTICES: usize = 2_000_000;

/// Outcome of one mesh at one level.
pub struct Row {
    pub mesh: String,
    pub level: usize,
    pub vertices: usize,
    pub error: f64,
    pub problem: Option<String>,
}

/// Levels to check: up to 3, fewer where the mesh would grow past [`MAX_VERTICES`].
fn levels_for(topo: &Topology, scheme: Scheme) -> usize {
    let mut faces = topo.num_face_vertices() as f64;
    let mut levels = 0;
    while levels < 3 {
        // Each level multiplies face-vertices by ~4; vertices are about face-vertices / 4·2.
        faces *= 4.0;
        let est_vertices = match scheme {
            Scheme::Loop => faces / 6.0,
            _ => faces / 4.0,
        };
        if est_vertices > MAX_VERTICES as f64 {
            break;
        }
        levels += 1;
    }
    levels.max(1)
}

/// Compares subd and OpenSubdiv on one mesh, returning one row per level.
pub fn compare(
    exe: &Path,
    name: &str,
    topo: &Topology,
    positions: &[DVec3],
    scheme: Scheme,
    options: &Options,
) -> Vec<Row> {
    let levels = levels_for(topo, scheme);
    let fail = |level: usize, msg: String| Row {
        mesh: name.to_string(),
        level,
        vertices: 0,
        error: f64::INFINITY,
        problem: Some(msg),
    };
    let input = osd::encode(topo, positions, scheme, options, levels as u32);
    let osd_levels = match osd::run(exe, &input, &[]).and_then(|b| osd::decode(&b, levels)) {
        Ok(l) => l,
        Err(e) => return vec![fail(0, format!("OpenSubdiv: {e}"))],
    };
    let refinement = match Refinement::new(topo, scheme, options, levels) {
        Ok(r) => r,
        Err(e) => return vec![fail(0, format!("subd: {e}"))],
    };
    let ours = refinement.refine_points(positions);
    let (lo, hi) = subd_mesh::bounding_box(positions.iter().copied()).unwrap_or_default();
    let diag = (hi - lo).length().max(f64::MIN_POSITIVE);
    let mut rows = Vec::new();
    for (l, o) in osd_levels.iter().enumerate() {
        let level = l + 1;
        let t = refinement.topology(level);
        let mut problem = None;
        if t.num_vertices() != o.positions.len() {
            problem = Some(format!(
                "{} vertices, OpenSubdiv {}",
                t.num_vertices(),
                o.positions.len()
            ));
        } else if t.num_faces() != o.face_sizes.len() {
            problem = Some(format!(
                "{} faces, OpenSubdiv {}",
                t.num_faces(),
                o.face_sizes.len()
            ));
        } else if t.all_face_vertices() != o.face_vertices.as_slice() {
            let f = (0..t.num_faces())
                .find(|&f| {
                    let a = t.face_offsets()[f] as usize;
                    let b = t.face_offsets()[f + 1] as usize;
                    t.all_face_vertices()[a..b]
                        != o.face_vertices
                            [a.min(o.face_vertices.len())..b.min(o.face_vertices.len())]
                })
                .unwrap_or(0);
            problem = Some(format!("face-vertex lists differ (first at face {f})"));
        }
        let error = if problem.is_none() {
            ours[level]
                .iter()
                .zip(&o.positions)
                .map(|(a, b)| (*a - *b).abs().max_element())
                .fold(0.0, f64::max)
                / diag
        } else {
            f64::INFINITY
        };
        if problem.is_none() && (error.is_nan() || error > TOLERANCE) {
            let v = ours[level]
                .iter()
                .zip(&o.positions)
                .enumerate()
                .max_by(|a, b| {
                    let da = (*a.1.0 - *a.1.1).abs().max_element();
                    let db = (*b.1.0 - *b.1.1).abs().max_element();
                    da.total_cmp(&db)
                })
                .map(|x| x.0)
                .unwrap_or(0);
            problem = Some(format!("worst vertex {v}"));
        }
        rows.push(Row {
            mesh: name.to_string(),
            level,
            vertices: t.num_vertices(),
            error,
            problem,
        });
    }
    rows
}

fn scheme_of(name: &str) -> Option<Scheme> {
    if name.starts_with("catmark_") {
        Some(Scheme::CatmullClark)
    } else if name.starts_with("loop_") {
        Some(Scheme::Loop)
    } else if name.starts_with("bilinear_") {
        Some(Scheme::Bilinear)
    } else {
        None
    }
}

/// Every shape of the OpenSubdiv directory.
pub fn shapes(exe: &Path, dir: &Path) -> Result<Vec<Row>, String> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "obj"))
        .collect();
    paths.sort();
    let mut rows = Vec::new();
    let opts = subd_io::ReadOptions {
        accept_inconsistent_orientation: true,
    };
    for p in paths {
        let name = p.file_stem().unwrap().to_string_lossy().to_string();
        let Some(scheme) = scheme_of(&name) else {
            continue;
        };
        let file = subd_io::read_mesh(&p, &opts).map_err(|e| e.to_string())?;
        let options = Options::from_hints(&file.mesh.hints);
        rows.extend(compare(
            exe,
            &name,
            &file.mesh.topology,
            &file.mesh.positions,
            scheme,
            &options,
        ));
    }
    Ok(rows)
}

/// `count` random meshes (see `random_mesh`).
pub fn random(exe: &Path, count: u64) -> Vec<Row> {
    let mut rows = Vec::new();
    for seed in 0..count {
        let c = crate::random_mesh::case(seed);
        rows.extend(compare(
            exe,
            &c.name,
            &c.topology,
            &c.positions,
            c.scheme,
            &c.options,
        ));
    }
    rows
}

/// Prints the table and returns whether every row passed.
pub fn report(rows: &[Row]) -> bool {
    println!(
        "{:<36} {:>5} {:>9} {:>12}  status",
        "mesh", "level", "vertices", "max|Δ|/diag"
    );
    let mut ok = true;
    for r in rows {
        let pass = r.problem.is_none();
        ok &= pass;
        println!(
            "{:<36} {:>5} {:>9} {:>12.3e}  {}",
            r.mesh,
            r.level,
            r.vertices,
            r.error,
            r.problem.as_deref().unwrap_or("ok")
        );
    }
    let failed = rows.iter().filter(|r| r.problem.is_some()).count();
    println!("{} passed, {} failed", rows.len() - failed, failed);
    ok
}
