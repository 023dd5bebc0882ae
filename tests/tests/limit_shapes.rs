//! Limit positions and normals on every OpenSubdiv shape, checked against the refinement
//! itself: the limit of a vertex must not change when the mesh is refined first (that is
//! what makes a mask a limit mask — a left eigenvector of the subdivision), and refined
//! points must converge to it.

// Vertices index several parallel arrays.
#![allow(clippy::needless_range_loop)]

use glam::DVec3;
use subd_io::{ReadOptions, read_mesh};
use subd_limit::{LimitError, LimitStencilTable, base_limit, levels_for_exact_limit, masks};
use subd_schemes::{Options, Refinement, Rule, Scheme};
use subd_tests::osd_meshes;

fn bbox_diagonal(p: &[DVec3]) -> f64 {
    let (lo, hi) = p.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(a, b), &q| (a.min(q), b.max(q)),
    );
    (hi - lo).length().max(1e-300)
}

struct Shape {
    name: String,
    scheme: Scheme,
    options: Options,
    mesh: subd_mesh::Mesh,
}

fn shapes() -> Vec<Shape> {
    let opts = ReadOptions {
        accept_inconsistent_orientation: true,
    };
    osd_meshes()
        .into_iter()
        .filter_map(|path| {
            let name = path.file_stem()?.to_string_lossy().to_string();
            let scheme = if name.starts_with("loop_") {
                Scheme::Loop
            } else if name.starts_with("catmark_") {
                Scheme::CatmullClark
            } else {
                return None;
            };
            let file = read_mesh(&path, &opts).ok()?;
            Some(Shape {
                name,
                scheme,
                options: Options::from_hints(&file.mesh.hints),
                mesh: file.mesh,
            })
        })
        .collect()
}

/// The limit from the base mesh equals the limit taken two levels further down, for every
/// vertex of every shape (positions to 1e-12 of the bounding box; normals of smooth and dart
/// vertices to 1e-9 — corner tangents follow the edges of the level by convention, and
/// crease cross-tangents are OpenSubdiv's approximations).
#[test]
fn limit_is_invariant_under_refinement() {
    let mut checked = 0;
    for s in shapes() {
        let base = match base_limit(&s.mesh.topology, s.scheme, &s.options) {
            Ok(t) => t,
            Err(LimitError::TooDeep { .. }) => continue,
            Err(e) => panic!("{}: {e}", s.name),
        };
        let (levels, _) = levels_for_exact_limit(&s.mesh.topology, s.scheme);
        let deeper = levels + 2;
        if s.mesh.topology.num_face_vertices() << (2 * deeper) > 4_000_000 {
            continue;
        }
        let r = Refinement::new(&s.mesh.topology, s.scheme, &s.options, deeper).unwrap();
        let pts = r.refine_points(&s.mesh.positions);
        let at = LimitStencilTable::at_level(&r, deeper)
            .unwrap()
            .apply(&pts[deeper]);
        let ours = base.apply(&s.mesh.positions);
        let diag = bbox_diagonal(&s.mesh.positions);
        let rules = r.vertex_rules(deeper);
        for v in 0..s.mesh.topology.num_vertices() {
            let d = (ours.positions[v] - at.positions[v]).length() / diag;
            assert!(d < 1e-12, "{} vertex {v}: limit moves by {d:e}", s.name);
            if matches!(rules[v], Rule::Smooth | Rule::Dart) && ours.normals[v] != DVec3::ZERO {
                let dn = (ours.normals[v] - at.normals[v]).length();
                assert!(
                    dn < 1e-9,
                    "{} vertex {v} ({:?}): normal moves by {dn:e}",
                    s.name,
                    rules[v]
                );
            }
        }
        checked += 1;
    }
    assert!(checked > 80, "only {checked} shapes checked");
}

/// Where OpenSubdiv takes the smooth mask at a dart, or the corner mask at an interior
/// valence-2 vertex, its value depends on the level it is applied at and only converges to
/// the limit; subd's value (from the eigen analysis) is the value that sequence converges to.
#[test]
fn darts_and_valence_two_converge_to_the_eigen_limit() {
    let all = shapes();
    let mut cases = Vec::new();
    for name in [
        "catmark_inf_crease0",
        "catmark_val2_interior",
        "catmark_val2_back2back",
    ] {
        let s = all.iter().find(|s| s.name == name).unwrap();
        let r = Refinement::new(&s.mesh.topology, s.scheme, &s.options, 0).unwrap();
        let t = r.topology(0);
        for v in 0..t.num_vertices() {
            let rule = r.vertex_rules(0)[v];
            let interior =
                !t.is_boundary_vertex(v) && t.vertex_edges(v).len() == t.vertex_faces(v).len();
            if interior
                && ((rule == Rule::Smooth && t.vertex_faces(v).len() == 2) || rule == Rule::Dart)
            {
                cases.push((s, v));
            }
        }
    }
    assert!(cases.len() >= 3, "{} cases", cases.len());
    for (s, v) in cases {
        let name = &s.name;
        let exact = base_limit(&s.mesh.topology, s.scheme, &s.options)
            .unwrap()
            .apply(&s.mesh.positions);
        let r = Refinement::new(&s.mesh.topology, s.scheme, &s.options, 7).unwrap();
        let pts = r.refine_points(&s.mesh.positions);
        let mut errors = Vec::new();
        for level in 1..=7 {
            let t = r.topology(level);
            // OpenSubdiv's value: the smooth closed form (valence ≥ 3) or the vertex itself.
            let n = t.vertex_faces(v).len();
            let osd_like = if n == 2 {
                pts[level][v]
            } else {
                let m = masks::catmark_smooth(n).position;
                let local = t.vertex_face_local_indices(v);
                let mut p = DVec3::ZERO;
                for (i, &f) in t.vertex_faces(v).iter().enumerate() {
                    let fv = t.face_vertices(f as usize);
                    p += m.faces[i] * pts[level][fv[(local[i] as usize + 2) % 4] as usize];
                }
                for (i, &e) in t.vertex_edges(v).iter().enumerate() {
                    p +=
                        m.edges[i] * pts[level][t.edge_other_vertex(e as usize, v as u32) as usize];
                }
                p + m.vertex * pts[level][v]
            };
            errors.push((osd_like - exact.positions[v]).length());
        }
        assert!(
            errors[0] > 1e-6,
            "{name}: the level-1 approximation should differ: {errors:?}"
        );
        for w in errors.windows(2) {
            assert!(w[1] < w[0], "{name}: errors must shrink: {errors:?}");
        }
        assert!(errors[6] < errors[0] * 1e-2, "{name}: {errors:?}");
    }
}
