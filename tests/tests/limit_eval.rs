//! Exact evaluation against independent computations: at dyadic parameters the surface point
//! is the limit of a refined vertex (refinement + closed-form limit masks); near an
//! extraordinary vertex refined positions converge to it at the rate the eigenvalues
//! predict; normals are continuous across faces.

// Vertices and faces index several parallel arrays.
#![allow(clippy::needless_range_loop)]

use glam::DVec3;
use subd_io::{ReadOptions, read_mesh};
use subd_limit::LimitStencilTable;
use subd_limit::eval::{FaceParam, LimitEvaluator};
use subd_mesh::Topology;
use subd_schemes::{Options, Refinement, Scheme};
use subd_tests::osd_meshes;

/// Catmull-Clark shapes the evaluator covers entirely (closed and smooth).
fn smooth_shapes() -> Vec<(String, subd_mesh::Mesh, Options, LimitEvaluator)> {
    let opts = ReadOptions {
        accept_inconsistent_orientation: true,
    };
    let mut out = Vec::new();
    for path in osd_meshes() {
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        if !name.starts_with("catmark_") {
            continue;
        }
        let mesh = read_mesh(&path, &opts).unwrap().mesh;
        let options = Options::from_hints(&mesh.hints);
        let Ok(ev) = LimitEvaluator::new(&mesh.topology, Scheme::CatmullClark, &options) else {
            continue;
        };
        let pts = ev.prepare(&mesh.positions);
        let covered = (0..mesh.topology.num_faces()).all(|f| {
            ev.evaluate(
                &pts,
                FaceParam {
                    face: f,
                    sub: 0,
                    u: 0.5,
                    v: 0.5,
                },
            )
            .is_ok()
        });
        if covered {
            out.push((name, mesh, options, ev));
        }
    }
    out
}

/// The level-`level` vertex at dyadic parameter `at` (a multiple of 2^-level, of the
/// sub-face for a non-quad), found by descending through the child faces.
fn vertex_at(r: &Refinement, level: usize, at: FaceParam) -> usize {
    let quadrant = |u: f64, v: f64| match (u >= 0.5, v >= 0.5) {
        (false, false) => (0, 2.0 * u, 2.0 * v),
        (true, false) => (1, 2.0 * u - 1.0, 2.0 * v),
        (true, true) => (2, 2.0 * u - 1.0, 2.0 * v - 1.0),
        (false, true) => (3, 2.0 * u, 2.0 * v - 1.0),
    };
    let base = r.topology(0);
    let off = base.face_offsets()[at.face] as usize;
    let (mut face, mut u, mut v, mut l) = if base.face_size(at.face) == 4 {
        (at.face, at.u, at.v, 0)
    } else {
        (off + at.sub, at.u, at.v, 1)
    };
    while l < level {
        let t: &Topology = r.topology(l);
        let (j, s, w) = if u == 1.0 && v == 1.0 {
            (2, 1.0, 1.0)
        } else {
            quadrant(u, v)
        };
        face = t.face_offsets()[face] as usize + j;
        (u, v) = (s, w);
        l += 1;
    }
    let corner = match (u, v) {
        (0.0, 0.0) => 0,
        (1.0, 0.0) => 1,
        (1.0, 1.0) => 2,
        (0.0, 1.0) => 3,
        _ => panic!("({u}, {v}) is not a corner at level {level}"),
    };
    r.topology(level).face_vertices(face)[corner] as usize
}

#[test]
fn dyadic_points_are_limits_of_refined_vertices() {
    let shapes = smooth_shapes();
    assert!(shapes.len() >= 8, "only {} smooth shapes", shapes.len());
    let level = 4;
    let mut checked = 0;
    for (name, mesh, options, ev) in &shapes {
        if mesh.topology.num_face_vertices() > 5000 {
            continue;
        }
        let pts = ev.prepare(&mesh.positions);
        let r = Refinement::new(&mesh.topology, Scheme::CatmullClark, options, level).unwrap();
        let refined = r.refine_points(&mesh.positions);
        let limit = LimitStencilTable::at_level(&r, level)
            .unwrap()
            .apply(&refined[level]);
        let diag = {
            let (lo, hi) = subd_mesh::bounding_box(mesh.positions.iter().copied()).unwrap();
            (hi - lo).length()
        };
        let params = [
            (0.0, 0.0),
            (1.0 / 16.0, 0.0),
            (1.0 / 16.0, 1.0 / 16.0),
            (0.25, 0.75),
            (0.5, 0.5),
            (1.0, 0.0),
            (0.0, 1.0),
            (1.0, 1.0),
            (0.8125, 0.1875),
        ];
        for f in 0..mesh.topology.num_faces() {
            let subs = match mesh.topology.face_size(f) {
                4 => 1,
                n => n,
            };
            for sub in 0..subs {
                for &(u, v) in &params {
                    // A sub-face starts one level down: its dyadic grid is one level coarser.
                    if subs > 1 && ((u * 8.0f64).fract() != 0.0 || (v * 8.0f64).fract() != 0.0) {
                        continue;
                    }
                    let at = FaceParam { face: f, sub, u, v };
                    let p = ev.evaluate(&pts, at).unwrap();
                    let vtx = vertex_at(&r, level, at);
                    let d = (p.position - limit.positions[vtx]).length() / diag;
                    assert!(d < 1e-12, "{name} face {f}.{sub} ({u}, {v}): {d:e}");
                    // No tangent plane at an interior valence-2 vertex (three eigenvalues of
                    // modulus 1/4), so no normal to compare there; and catmark_val2_back2back
                    // is pairs of coincident faces glued back to back, a surface folded flat
                    // along every edge.
                    let valence2 = r.topology(level).vertex_faces(vtx).len() == 2;
                    let folded = name == "catmark_val2_back2back";
                    if !valence2
                        && !folded
                        && limit.normals[vtx] != DVec3::ZERO
                        && p.normal() != DVec3::ZERO
                    {
                        let dn = (p.normal() - limit.normals[vtx]).length();
                        assert!(
                            dn < 1e-9,
                            "{name} face {f}.{sub} ({u}, {v}): normal off by {dn:e}"
                        );
                    }
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 1000, "{checked}");
}
