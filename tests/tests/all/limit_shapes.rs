//! Limit positions and normals on every OpenSubdiv shape, checked against the refinement
//! itself: the limit of a vertex must not change when the mesh is refined first (that is
//! what makes a mask a limit mask — a left eigenvector of the subdivision), and refined
//! points must converge to it.

// Vertices index several parallel arrays.
#![allow(clippy::needless_range_loop)]

use glam::DVec3;
use subd_limit::{LimitError, LimitStencilTable, base_limit, levels_for_exact_limit, masks};
use subd_schemes::{Options, Refinement, Rule, Scheme};
use subd_tests::{SurfaceShape, surface_shapes};

fn bbox_diagonal(p: &[DVec3]) -> f64 {
    let (lo, hi) = p.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(a, b), &q| (a.min(q), b.max(q)),
    );
    (hi - lo).length().max(1e-300)
}

fn shapes() -> Vec<SurfaceShape> {
    surface_shapes()
}

/// The limit from the base mesh equals the limit taken two levels further down, for every
/// vertex of every shape (positions to 1e-12 of the bounding box; normals of smooth and dart
/// vertices to 1e-9 — corner tangents follow the edges of the level by convention, and
/// crease cross-tangents are OpenSubdiv's approximations).
#[test]
fn limit_is_invariant_under_refinement() {
    let mut checked = 0;
    for s in shapes() {
        let base = match base_limit(&s.mesh.topology, &s.scheme, &s.options) {
            Ok(t) => t,
            Err(LimitError::TooDeep { .. }) => continue,
            Err(e) => panic!("{}: {e}", s.name),
        };
        let (levels, _) = levels_for_exact_limit(&s.mesh.topology, &s.scheme);
        let deeper = levels + 2;
        if s.mesh.topology.num_face_vertices() << (2 * deeper) > 4_000_000 {
            continue;
        }
        let r = Refinement::new(&s.mesh.topology, s.scheme.clone(), &s.options, deeper).unwrap();
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
        let r = Refinement::new(&s.mesh.topology, s.scheme.clone(), &s.options, 0).unwrap();
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
        let exact = base_limit(&s.mesh.topology, &s.scheme, &s.options)
            .unwrap()
            .apply(&s.mesh.positions);
        let r = Refinement::new(&s.mesh.topology, s.scheme.clone(), &s.options, 7).unwrap();
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

/// Refining only around the semi-sharp features (what `base_limit` does on meshes too large
/// to refine whole) gives the limits of refining the whole mesh, on every shape with a
/// semi-sharp feature or (Catmull-Clark) a face that is not a quad: positions and normals.
#[test]
fn local_decay_refinement_equals_global() {
    let mut checked = 0;
    for s in shapes() {
        let (levels, _) = levels_for_exact_limit(&s.mesh.topology, &s.scheme);
        // Keep the global refinement this compares with small enough for a test.
        if levels == 0 || s.mesh.topology.num_face_vertices() << (2 * levels) > 1 << 20 {
            continue;
        }
        let global = match base_limit(&s.mesh.topology, &s.scheme, &s.options) {
            Ok(t) => t.apply(&s.mesh.positions),
            Err(LimitError::TooDeep { .. }) => continue,
            Err(e) => panic!("{}: {e}", s.name),
        };
        let local = match subd_limit::local::base_limit(&s.mesh.topology, &s.scheme, &s.options) {
            Ok(t) => t.apply(&s.mesh.positions),
            // A non-manifold neighbourhood a cut cannot reproduce is refused, not guessed.
            Err(LimitError::Unsupported { .. }) => continue,
            Err(e) => panic!("{}: {e}", s.name),
        };
        let diag = bbox_diagonal(&s.mesh.positions);
        let r0 = Refinement::new(&s.mesh.topology, s.scheme.clone(), &s.options, 0).unwrap();
        for v in 0..s.mesh.topology.num_vertices() {
            let d = (global.positions[v] - local.positions[v]).length() / diag;
            assert!(d < 1e-13, "{} vertex {v}: {d:e}", s.name);
            // A corner has no limit normal (its conventional one, from its first two edges,
            // depends on the level the masks are taken at).
            // Nor has an interior valence-2 vertex a tangent plane (three eigenvalues of
            // modulus 1/4).
            let t0 = r0.topology(0);
            let valence2 = t0.vertex_faces(v).len() == 2 && !t0.is_boundary_vertex(v);
            // At crease and boundary vertices the cross-tangent masks (OpenSubdiv's, which
            // subd matches) are not eigenvectors of the crease rules except at regular
            // vertices, so the normal they give depends on the level they are taken at; and
            // at an interior crease the side they take follows where the vertex's edge
            // order starts, which a cut need not keep.
            let sharp = t0
                .vertex_edges(v)
                .iter()
                .any(|&e| t0.edge_sharpness(e as usize) > 0.0 || t0.is_boundary_edge(e as usize));
            if r0.vertex_rules(0)[v] == Rule::Corner || valence2 || sharp {
                continue;
            }
            // Tangent lengths depend on the level the masks are taken at (a subdominant
            // eigenvalue per level); their plane does not.
            let dn = (global.normals[v] - local.normals[v]).length();
            assert!(dn < 1e-10, "{} vertex {v} normal: {dn:e}", s.name);
        }
        checked += 1;
    }
    assert!(checked >= 15, "only {checked} shapes");
    eprintln!("local decay refinement: {checked} shapes equal to global refinement");
}

/// A mesh too large to refine whole until a sharpness-7 crease decays (160,000 face-vertices
/// × 4^7) still gets its exact limits: only the crease's neighbourhood is refined, and a
/// vertex far from the crease keeps the plain limit mask of its level.
#[test]
fn large_mesh_with_a_semi_sharp_crease_gets_exact_limits() {
    let n = 200u32;
    let mut faces = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let v = j * (n + 1) + i;
            faces.extend([v, v + 1, v + n + 2, v + n + 1]);
        }
    }
    let mut topo = subd_mesh::TopologyBuilder::new(((n + 1) * (n + 1)) as usize)
        .build(&vec![4; (n * n) as usize], &faces)
        .unwrap();
    let row = n / 2;
    for i in 0..n {
        let a = u64::from(row * (n + 1) + i);
        topo.set_crease(a, a + 1, 7.0).unwrap();
    }
    let pts: Vec<DVec3> = (0..(n + 1) * (n + 1))
        .map(|k| {
            let (x, y) = (f64::from(k % (n + 1)), f64::from(k / (n + 1)));
            DVec3::new(x, y, (0.1 * x).sin() * (0.13 * y).cos())
        })
        .collect();
    let (levels, _) = levels_for_exact_limit(&topo, &Scheme::CatmullClark);
    assert_eq!(levels, 7);
    assert!(topo.num_face_vertices() << (2 * levels) > subd_limit::MAX_DECAY_FACE_VERTICES);
    let limit = base_limit(&topo, &Scheme::CatmullClark, &Options::default())
        .unwrap()
        .apply(&pts);
    let r0 = Refinement::new(&topo, Scheme::CatmullClark, &Options::default(), 0).unwrap();
    let plain = LimitStencilTable::at_level(&r0, 0).unwrap().apply(&pts);
    let far = (10 * (n + 1) + 10) as usize;
    assert!((limit.positions[far] - plain.positions[far]).length() < 1e-15);
    // On the crease the semi-sharp rules pull the limit away from the smooth one.
    let on = (row * (n + 1) + n / 2) as usize;
    assert!((limit.positions[on] - plain.positions[on]).length() > 1e-6);
    assert!(limit.positions.iter().all(|p| p.is_finite()));
}

/// The positions-only tables ([`subd_limit::base_limit_positions`],
/// [`subd_limit::two_phase_base_limit_positions`]) are the position tables of the full ones
/// on every shape: bit for bit, except where two-phase takes the closed form on a closed
/// smooth quad mesh (then to rounding); two-phase on the all-quad shapes, with a `λ` that
/// varies by vertex.
#[test]
fn positions_alone_equal_the_full_tables() {
    let (mut checked, mut two_phase, mut classical) = (0, 0, 0);
    for s in shapes() {
        let t = &s.mesh.topology;
        // Deep semi-sharp decay only repeats the same composition at more levels.
        if levels_for_exact_limit(t, &s.scheme).0 > 2 {
            continue;
        }
        let full = match base_limit(t, &s.scheme, &s.options) {
            Ok(f) => f,
            Err(LimitError::TooDeep { .. }) => continue,
            Err(e) => panic!("{}: {e}", s.name),
        };
        let positions = subd_limit::base_limit_positions(t, &s.scheme, &s.options).unwrap();
        // Closed smooth meshes take the classical masks directly, bit for bit the same.
        assert_eq!(positions, full.position, "{}", s.name);
        checked += 1;
        let face_size = if s.scheme == Scheme::Loop { 3 } else { 4 };
        if s.scheme != Scheme::Bilinear && t.is_closed_smooth_uniform(face_size) {
            classical += 1;
        }
        if s.scheme == Scheme::CatmullClark && (0..t.num_faces()).all(|f| t.face_size(f) == 4) {
            let lambda: Vec<f64> = (0..t.num_vertices())
                .map(|v| 0.4 + 0.6 * ((v * 7) % 10) as f64 / 10.0)
                .collect();
            let tp = subd_schemes::TwoPhase::new(lambda).unwrap();
            let full = match subd_limit::two_phase_base_limit(t, &tp, &s.options) {
                Ok(f) => f,
                Err(LimitError::TooDeep { .. }) => continue,
                Err(e) => panic!("{} two-phase: {e}", s.name),
            };
            let positions = subd_limit::two_phase_base_limit_positions(t, &tp, &s.options).unwrap();
            // Closed smooth meshes take the paper's formula (2) directly: the same weights up
            // to rounding, possibly merged in another order.
            for v in 0..t.num_vertices() {
                let sorted = |table: &subd_schemes::StencilTable| {
                    let (c, w) = table.row(v);
                    let mut row: Vec<(u32, f64)> =
                        c.iter().copied().zip(w.iter().copied()).collect();
                    row.sort_by_key(|e| e.0);
                    row
                };
                let (a, b) = (sorted(&positions), sorted(&full.position));
                assert_eq!(a.len(), b.len(), "{} two-phase vertex {v}", s.name);
                for (x, y) in a.iter().zip(&b) {
                    assert!(
                        x.0 == y.0 && (x.1 - y.1).abs() < 1e-15,
                        "{} two-phase vertex {v}: {x:?} vs {y:?}",
                        s.name
                    );
                }
            }
            two_phase += 1;
        }
    }
    assert!(
        checked >= 40 && two_phase >= 10 && classical >= 3,
        "{checked} shapes, {two_phase} two-phase, {classical} with the classical masks"
    );
}
