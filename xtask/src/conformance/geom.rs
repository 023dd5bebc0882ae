//! The second and third opinions in `cargo xtask conformance`: subd's Doo-Sabin, √3 and
//! modified butterfly against CGAL and OpenMesh, and its Loop and Catmull-Clark against both
//! as well, on every fitting OpenSubdiv shape and on random meshes, levels 1–3.
//!
//! The libraries number vertices their own way, so a level is compared by its vertex and face
//! counts and by matching positions (nearest vertex, both ways) to 1e-12 × the bounding-box
//! diagonal. Neither library reads crease tags: shapes are compared with their tags taken
//! off.

use rayon::prelude::*;
use std::path::Path;

use subd_mesh::{DVec3, Topology, TopologyBuilder};
use subd_schemes::{Options, Refinement, Scheme};

use crate::conformance::Row;
use crate::oracles::geom::{self, Library, RefOutcome};

/// Tolerance on the matched distance / bounding-box diagonal.
const TOLERANCE: f64 = 1e-12;
/// Levels stop before a mesh passes this many vertices.
const MAX_VERTICES: usize = 400_000;
/// OpenMesh's Loop and √3 weight tables stop at this valence (entries 0–49; above, they are
/// read past their end). The harness enlarges them with OpenMesh's own `init_weights`, so
/// such meshes are compared rather than skipped, and their rows say so.
const OPENMESH_MAX_VALENCE: usize = 50;

/// One comparison: which library, its name for the scheme, ours, and on which meshes.
struct Pairing {
    check: &'static str,
    library: Library,
    harness_scheme: &'static str,
    ours: Scheme,
    triangles: bool,
    /// Open meshes too (the library implements the boundary rule subd does).
    open: bool,
    /// OpenMesh's weight tables have to be enlarged for valences of 50 and more.
    valence_limit: bool,
}

const PAIRINGS: &[Pairing] = &[
    Pairing {
        check: "cgal-sqrt3",
        library: Library::Cgal,
        harness_scheme: "sqrt3",
        ours: Scheme::Sqrt3,
        triangles: true,
        open: true,
        valence_limit: false,
    },
    Pairing {
        check: "om-sqrt3",
        library: Library::OpenMesh,
        harness_scheme: "sqrt3",
        ours: Scheme::Sqrt3,
        triangles: true,
        open: true,
        valence_limit: true,
    },
    Pairing {
        check: "cgal-doo-sabin",
        library: Library::Cgal,
        harness_scheme: "doo-sabin",
        ours: Scheme::DooSabin,
        triangles: false,
        open: false,
        valence_limit: false,
    },
    Pairing {
        check: "om-mod-butterfly",
        library: Library::OpenMesh,
        harness_scheme: "modified-butterfly",
        ours: Scheme::ModifiedButterfly,
        triangles: true,
        open: true,
        valence_limit: false,
    },
    Pairing {
        check: "cgal-loop",
        library: Library::Cgal,
        harness_scheme: "loop",
        ours: Scheme::Loop,
        triangles: true,
        open: false,
        valence_limit: false,
    },
    Pairing {
        check: "om-loop",
        library: Library::OpenMesh,
        harness_scheme: "loop",
        ours: Scheme::Loop,
        triangles: true,
        open: false,
        valence_limit: true,
    },
    Pairing {
        check: "cgal-catmull-clark",
        library: Library::Cgal,
        harness_scheme: "catmull-clark",
        ours: Scheme::CatmullClark,
        triangles: false,
        open: false,
        valence_limit: false,
    },
    Pairing {
        check: "om-catmull-clark",
        library: Library::OpenMesh,
        harness_scheme: "catmull-clark",
        ours: Scheme::CatmullClark,
        triangles: false,
        open: false,
        valence_limit: false,
    },
];

/// The topology without its tags (creases, corners, holes), or `None` when it is not a
/// manifold mesh (neither library takes one).
fn untagged(topo: &Topology) -> Option<Topology> {
    let manifold = (0..topo.num_edges()).all(|e| !topo.is_non_manifold_edge(e))
        && (0..topo.num_vertices()).all(|v| !topo.is_non_manifold_vertex(v));
    if !manifold {
        return None;
    }
    let sizes: Vec<u32> = topo.face_sizes().collect();
    TopologyBuilder::new(topo.num_vertices())
        .build(&sizes, topo.all_face_vertices())
        .ok()
}

/// Positions of every level of ours, level 0 included.
fn our_levels(
    ours: Scheme,
    topo: &Topology,
    positions: &[DVec3],
    levels: usize,
) -> Result<Vec<(Vec<DVec3>, usize)>, String> {
    let r = Refinement::new(topo, ours, &Options::default(), levels).map_err(|e| e.to_string())?;
    Ok(r.refine_points(positions)
        .into_iter()
        .enumerate()
        .map(|(l, p)| (p, r.faces(l).0.len() - 1))
        .collect())
}

/// Levels to compare: up to 3, fewer where a level would pass [`MAX_VERTICES`].
fn levels_for(topo: &Topology) -> usize {
    let mut n = topo.num_face_vertices().max(topo.num_vertices());
    let mut levels = 0;
    while levels < 3 && 4 * n <= MAX_VERTICES {
        n *= 4;
        levels += 1;
    }
    levels
}

/// Every pairing that fits `topo`, levels 1–3.
fn compare(exe: &Path, name: &str, topo: &Topology, positions: &[DVec3]) -> Vec<Row> {
    let mut rows = Vec::new();
    let Some(t) = untagged(topo) else {
        return rows;
    };
    if t.num_faces() == 0 {
        return rows;
    }
    let triangles = (0..t.num_faces()).all(|f| t.face_size(f) == 3);
    let closed = (0..t.num_edges()).all(|e| !t.is_boundary_edge(e));
    let max_valence = (0..t.num_vertices())
        .map(|v| t.valence(v))
        .max()
        .unwrap_or(0);
    let diag = subd_mesh::bounding_box(positions.iter().copied())
        .map_or(1.0, |(lo, hi)| (hi - lo).length())
        .max(f64::MIN_POSITIVE);
    let levels = levels_for(&t);
    // Interior vertices with two faces: CGAL's Doo-Sabin keeps their 2-gon vertex faces, subd
    // collapses each into an edge (a face needs three vertices), so past level 1 the meshes
    // differ by design.
    let two_gons = (0..t.num_vertices())
        .filter(|&v| !t.is_boundary_vertex(v) && t.vertex_faces(v).len() == 2)
        .count();
    for p in PAIRINGS {
        if (p.triangles && !triangles) || (!p.open && !closed) {
            continue;
        }
        let enlarged = (p.valence_limit && max_valence >= OPENMESH_MAX_VALENCE).then(|| {
            format!(
                "valence {max_valence}: OpenMesh's tables (valences < {OPENMESH_MAX_VALENCE}) enlarged with its init_weights"
            )
        });
        let ours = match our_levels(p.ours.clone(), &t, positions, levels) {
            Ok(o) => o,
            Err(e) => {
                let mut row = Row::pending(name, p.check, 1);
                row.problem = Some(format!("subd refused: {e}"));
                rows.push(row);
                continue;
            }
        };
        let collapsed = if p.check == "cgal-doo-sabin" {
            two_gons
        } else {
            0
        };
        for (level, (pos, faces)) in ours.iter().enumerate().skip(1) {
            if collapsed > 0 && level > 1 {
                break;
            }
            let faces = &(faces + collapsed);
            let mut row = Row::pending(name, p.check, level);
            row.note = enlarged.clone();
            if collapsed > 0 {
                row.note = Some(format!(
                    "level 1 only: {collapsed} interior valence-2 vertices, whose 2-gon faces CGAL keeps and subd collapses"
                ));
            }
            row.vertices = pos.len();
            match geom::refine(exe, p.library, p.harness_scheme, level, &t, positions) {
                Err(e) => row.problem = Some(e),
                Ok(RefOutcome::Refused(why)) => {
                    row.problem = Some(format!(
                        "{} refused a mesh subd took: {why}",
                        p.library.name()
                    ))
                }
                Ok(RefOutcome::Mesh(m)) => {
                    if m.positions.len() != pos.len() || m.num_faces != *faces {
                        row.problem = Some(format!(
                            "counts differ: subd {} vertices {} faces, {} {} and {}",
                            pos.len(),
                            faces,
                            p.library.name(),
                            m.positions.len(),
                            m.num_faces
                        ));
                    } else {
                        row.error = geom::matched_error(pos, &m.positions, diag);
                        if row.error.is_nan() || row.error > TOLERANCE {
                            row.problem = Some(format!("matched |Δ|/diag {:.3e}", row.error));
                        }
                    }
                }
            }
            rows.push(row);
        }
    }
    rows
}

/// Every fitting shape of the OpenSubdiv directory.
pub fn shapes(exe: &Path, dir: &Path) -> Result<Vec<Row>, String> {
    let paths = crate::conformance::shape_paths(dir)?;
    let opts = subd_io::ReadOptions {
        accept_inconsistent_orientation: true,
        ..Default::default()
    };
    // Shapes in parallel (each mostly waits on its harness process), rows in order.
    let per_shape = paths
        .par_iter()
        .map(|p| -> Result<Vec<Row>, String> {
            let name = p.file_stem().unwrap().to_string_lossy().to_string();
            let file = subd_io::read_mesh(p, &opts).map_err(|e| e.to_string())?;
            Ok(compare(
                exe,
                &name,
                &file.mesh.topology,
                &file.mesh.positions,
            ))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(per_shape.into_iter().flatten().collect())
}

/// A closed bipyramid whose two apices have valence `n` (an n-gon equator, wobbled).
fn bipyramid(n: u32) -> (Topology, Vec<DVec3>) {
    let mut positions = vec![DVec3::new(0.0, 0.0, 1.3), DVec3::new(0.1, -0.05, -0.9)];
    for i in 0..n {
        let t = std::f64::consts::TAU * f64::from(i) / f64::from(n);
        let r = 1.0 + 0.15 * (3.0 * t).sin();
        positions.push(DVec3::new(r * t.cos(), r * t.sin(), 0.1 * (5.0 * t).cos()));
    }
    let ring = |i: u32| 2 + i % n;
    let faces: Vec<u32> = (0..n)
        .flat_map(|i| [0, ring(i), ring(i + 1), 1, ring(i + 1), ring(i)])
        .collect();
    let topo = TopologyBuilder::new(positions.len())
        .build(&vec![3; 2 * n as usize], &faces)
        .expect("bipyramid is valid");
    (topo, positions)
}

/// `count` random meshes (those of `random_mesh`, tags taken off, non-manifold ones left
/// out), and closed bipyramids of apex valence 60 and 64 (above OpenMesh's tables).
pub fn random(exe: &Path, count: u64) -> Vec<Row> {
    let mut rows = Vec::new();
    for n in [60, 64] {
        let (t, p) = bipyramid(n);
        rows.extend(compare(exe, &format!("bipyramid_valence_{n}"), &t, &p));
    }
    rows.par_extend((0..count).into_par_iter().flat_map_iter(|seed| {
        let c = crate::meshes::random::case(seed);
        compare(exe, &c.name, &c.topology, &c.positions)
    }));
    rows
}
