//! Adaptive refinement on every OpenSubdiv shape, checked against uniform refinement: every
//! vertex of every level of the hierarchy is the uniform level's vertex of the same index
//! (positions to 1e-15 of the bounding box), selecting every face gives the uniform faces,
//! the conforming mesh is conforming with level differences ≤ 1, and `Positions::Limit`
//! gives the limit masks of a uniform refinement deep enough for every vertex.

use std::collections::HashSet;

use glam::DVec3;
use subd_adaptive::{AdaptiveRefinement, Positions, RandomSelection};
use subd_limit::{LimitStencilTable, levels_for_exact_limit};
use subd_schemes::LevelCounts;
use subd_schemes::{Refinement, Rule};
use subd_tests::{SurfaceShape, surface_shapes};

fn shapes() -> Vec<SurfaceShape> {
    surface_shapes()
}

fn diagonal(p: &[DVec3]) -> f64 {
    subd_pia::bbox_diagonal(p).max(1e-300)
}

/// Every vertex of every level equals uniform refinement's, and the mesh is conforming.
fn check_exact(s: &SurfaceShape, a: &AdaptiveRefinement, uniform: &[Vec<DVec3>]) {
    let d = diagonal(&s.mesh.positions);
    for (l, level) in uniform.iter().enumerate().take(a.depth() + 1) {
        for (k, p) in a.level_vertices(l) {
            let q = level[k as usize];
            assert!(
                (p - q).length() <= 1e-15 * d,
                "{}: level {l} vertex {k}: {p} vs uniform {q}",
                s.name
            );
        }
    }
    let mesh = a.mesh(Positions::Refined).unwrap();
    let c = mesh.conformity();
    assert_eq!(
        edge_measures(&mesh),
        (
            c.boundary_edges,
            c.nonmanifold_edges,
            c.max_level_difference_edge,
            c.max_level_difference_vertex
        ),
        "{}",
        s.name
    );
    assert!(c.conforming, "{}: {c:?}", s.name);
    assert!(c.max_level_difference_vertex <= 1, "{}: {c:?}", s.name);
    assert!(c.max_level_difference_edge <= 1, "{}: {c:?}", s.name);
    for (v, (&l, &k)) in mesh
        .vertex_levels
        .iter()
        .zip(&mesh.vertex_uniform)
        .enumerate()
    {
        assert_eq!(
            mesh.positions[v], uniform[l as usize][k as usize],
            "{}",
            s.name
        );
    }
}

/// Boundary and non-manifold edges and the largest level differences across edges and
/// vertices, read from the output's full topology (the report computes them from its edges
/// alone).
fn edge_measures(mesh: &subd_adaptive::AdaptiveMesh) -> (usize, usize, u8, u8) {
    let sizes: Vec<u32> = mesh.face_offsets.windows(2).map(|w| w[1] - w[0]).collect();
    let t = subd_mesh::TopologyBuilder::new(mesh.positions.len())
        .accept_inconsistent_orientation(true)
        .build(&sizes, &mesh.face_vertices)
        .unwrap();
    let spread = |faces: &[u32]| {
        let levels = faces.iter().map(|&f| mesh.face_levels[f as usize]);
        levels.clone().max().unwrap_or(0) - levels.min().unwrap_or(0)
    };
    let edges = 0..t.num_edges();
    (
        edges.clone().filter(|&e| t.is_boundary_edge(e)).count(),
        edges.clone().filter(|&e| t.is_non_manifold_edge(e)).count(),
        edges.map(|e| spread(t.edge_faces(e))).max().unwrap_or(0),
        (0..t.num_vertices())
            .map(|v| spread(t.vertex_faces(v)))
            .max()
            .unwrap_or(0),
    )
}

#[test]
fn scattered_selections_give_uniform_vertices_on_every_shape() {
    let levels = 3;
    let mut checked = 0;
    for s in shapes() {
        let r = Refinement::new(&s.mesh.topology, s.scheme.clone(), &s.options, levels).unwrap();
        let uniform = r.refine_points(&s.mesh.positions);
        for seed in 0..2 {
            let pick = RandomSelection::new(seed, 0.35).unwrap();
            let a = AdaptiveRefinement::new(
                &s.mesh.topology,
                &s.mesh.positions,
                &s.scheme,
                &s.options,
                &[&pick],
                levels,
            )
            .unwrap_or_else(|e| panic!("{}: {e}", s.name));
            check_exact(&s, &a, &uniform);
            checked += 1;
        }
    }
    assert!(checked > 100, "{checked} runs");
}

#[test]
fn selecting_every_face_is_uniform_refinement() {
    let levels = 2;
    for s in shapes() {
        let r = Refinement::new(&s.mesh.topology, s.scheme.clone(), &s.options, levels).unwrap();
        let a = AdaptiveRefinement::new(
            &s.mesh.topology,
            &s.mesh.positions,
            &s.scheme,
            &s.options,
            &[],
            levels,
        )
        .unwrap();
        let mesh = a.mesh(Positions::Refined).unwrap();
        let LevelCounts {
            faces, vertices, ..
        } = a.uniform_counts(levels);
        assert_eq!(mesh.num_faces() as u64, faces, "{}", s.name);
        assert_eq!(
            mesh.positions.len() as u64,
            vertices - isolated(&r, levels),
            "{}",
            s.name
        );
        // The same faces: compare them as lists of uniform vertex indices.
        let (off, fv) = r.faces(levels);
        let want: HashSet<Vec<u32>> = (0..off.len() - 1)
            .map(|f| fv[off[f] as usize..off[f + 1] as usize].to_vec())
            .collect();
        let got: HashSet<Vec<u32>> = (0..mesh.num_faces())
            .map(|f| {
                mesh.face(f)
                    .iter()
                    .map(|&v| mesh.vertex_uniform[v as usize] as u32)
                    .collect()
            })
            .collect();
        assert_eq!(got, want, "{}", s.name);
        assert!(mesh.vertex_levels.iter().all(|&l| l as usize == levels));
        assert!(!mesh.transition.iter().any(|&t| t));
    }
}

/// Vertices of `level` that no face uses (isolated base vertices keep their children).
fn isolated(r: &Refinement, level: usize) -> u64 {
    let t = r.topology(level);
    (0..t.num_vertices())
        .filter(|&v| t.vertex_faces(v).is_empty())
        .count() as u64
}

/// `Positions::Limit` against the limit masks of a uniform refinement deep enough for every
/// vertex (semi-sharp decay included): positions to 1e-12 of the bounding box, normals of
/// smooth vertices to 1e-9.
#[test]
fn limit_positions_are_the_uniform_limit() {
    let levels = 2;
    let mut checked = 0;
    for s in shapes() {
        let (decay, _) = levels_for_exact_limit(&s.mesh.topology, &s.scheme);
        let deep = levels + decay.max(1);
        if s.mesh.topology.num_face_vertices() << (2 * deep) > 4_000_000 {
            continue;
        }
        let pick = RandomSelection::new(7, 0.4).unwrap();
        let a = AdaptiveRefinement::new(
            &s.mesh.topology,
            &s.mesh.positions,
            &s.scheme,
            &s.options,
            &[&pick],
            levels,
        )
        .unwrap();
        let mesh = match a.mesh(Positions::Limit) {
            Ok(m) => m,
            Err(e) => panic!("{}: {e}", s.name),
        };
        let r = Refinement::new(&s.mesh.topology, s.scheme.clone(), &s.options, deep).unwrap();
        let pts = r.refine_points(&s.mesh.positions).pop().unwrap();
        let limit = LimitStencilTable::at_level(&r, deep).unwrap().apply(&pts);
        let rules = r.vertex_rules(deep);
        let d = diagonal(&s.mesh.positions);
        let counts: Vec<u64> = (0..=levels).map(|l| a.uniform_counts(l).vertices).collect();
        for v in 0..mesh.positions.len() {
            let (l, k) = (
                mesh.vertex_levels[v] as usize,
                mesh.vertex_uniform[v] as usize,
            );
            // Vertex k of level l keeps index k at every deeper level.
            assert!((k as u64) < counts[l]);
            let want = limit.positions[k];
            assert!(
                (mesh.positions[v] - want).length() <= 1e-12 * d,
                "{}: level {l} vertex {k}: {} vs {want}",
                s.name,
                mesh.positions[v]
            );
            // Skip vertices whose tangents are parallel (no normal to compare).
            let (t1, t2) = (limit.tangent1[k], limit.tangent2[k]);
            let scale = t1.length().max(t2.length());
            let spans = t1.cross(t2).length() > 1e-6 * scale * scale;
            let manifold = !r.topology(deep).is_non_manifold_vertex(k);
            if manifold && spans && rules[k] == Rule::Smooth {
                assert!(
                    (mesh.normals[v] - limit.normals[k]).length() <= 1e-9,
                    "{}: normal of level {l} vertex {k}: {} vs {}",
                    s.name,
                    mesh.normals[v],
                    limit.normals[k]
                );
            }
        }
        checked += 1;
    }
    assert!(checked > 50, "{checked} shapes");
}

/// The parameters the mesh records for each corner put it where the exact evaluator puts the
/// limit surface: with `Positions::Limit`, every corner of every face is the evaluator's
/// point at the corner's (face, sub-face, u, v), to 1e-12 of the bounding box.
#[test]
fn corner_parameters_locate_the_limit_surface() {
    let mut checked = 0;
    for s in shapes() {
        let Ok(surface) = subd_adaptive::LimitSurface::new(
            &s.mesh.topology,
            &s.mesh.positions,
            &s.scheme,
            &s.options,
        ) else {
            continue;
        };
        let pick = RandomSelection::new(3, 0.5).unwrap();
        let a = AdaptiveRefinement::new(
            &s.mesh.topology,
            &s.mesh.positions,
            &s.scheme,
            &s.options,
            &[&pick],
            2,
        )
        .unwrap();
        let mesh = a.mesh(Positions::Limit).unwrap();
        let d = diagonal(&s.mesh.positions);
        let mut all = true;
        // Every seventh face: the evaluator refines locally next to irregular sharp
        // features, which is slow point by point.
        for f in (0..mesh.num_faces()).filter(|&f| !mesh.holes[f] && f % 7 == 0) {
            let (face, sub) = mesh.face_domains[f];
            let first = mesh.face_offsets[f] as usize;
            for (i, &v) in mesh.face(f).iter().enumerate() {
                let uv = mesh.corner_params[first + i];
                let sub = if sub == u16::MAX { i } else { sub as usize };
                let (u, w) = if uv[0].is_nan() {
                    (0.0, 0.0)
                } else {
                    (uv[0], uv[1])
                };
                match surface.position(face as usize, sub, u, w) {
                    Ok(p) => assert!(
                        (p - mesh.positions[v as usize]).length() <= 1e-12 * d,
                        "{}: face {f} corner {i}: evaluator {p} vs {}",
                        s.name,
                        mesh.positions[v as usize]
                    ),
                    Err(_) => all = false,
                }
            }
        }
        checked += usize::from(all);
    }
    assert!(checked > 40, "{checked} shapes");
}

/// UVs on the adaptive mesh: with every face selected the mesh is uniform refinement, and each
/// corner's UV, evaluated on the channel's patches at the corner's parameter, is the exact
/// limit of uniform refinement's value at that face corner, taken with limit masks
/// (`subd_limit::fvar::limit_at_level`), in every mode: an independent computation.
#[test]
fn adaptive_uvs_are_the_limits_of_uniform_refinement_values() {
    use subd_limit::eval::LimitEvaluator;
    use subd_mesh::fvar::FVarLinearInterpolation;
    use subd_schemes::FaceVaryingRefinement;
    let names = [
        "catmark_cube",
        "catmark_pyramid",
        "catmark_fvar_bound1",
        "catmark_cube_creases1",
        "loop_cube",
    ];
    let mut checked = 0;
    for s in shapes().iter().filter(|s| names.contains(&s.name.as_str())) {
        let uv = s.mesh.uv().expect("these shapes have UVs");
        let every = subd_adaptive::EveryFace;
        let (t, p) = (&s.mesh.topology, &s.mesh.positions);
        let a = AdaptiveRefinement::new(t, p, &s.scheme, &s.options, &[&every], 2).unwrap();
        let mesh = a.mesh(Positions::Limit).unwrap();
        // Limits are taken where semi-sharp creases have decayed; a level-2 corner's vertex
        // is the vertex at the same corner of its corner child at every deeper level.
        let deepest = 2.max(levels_for_exact_limit(t, &s.scheme).0);
        let r = Refinement::new(t, s.scheme.clone(), &s.options, deepest).unwrap();
        let at_deepest = |mut g: usize, k: usize| {
            for l in 2..deepest {
                g = if s.scheme == subd_schemes::Scheme::Loop {
                    4 * g + k
                } else {
                    r.topology(l).face_offsets()[g] as usize + k
                };
            }
            g
        };
        let ev = LimitEvaluator::new(t, &s.scheme, &s.options).unwrap();
        for mode in FVarLinearInterpolation::ALL_MODES {
            let fr = FaceVaryingRefinement::new(&r, uv, mode).unwrap();
            let refined = fr.refine_values(&r, uv.values(), 2).pop().unwrap();
            let mut limits = vec![0.0; refined.len()];
            subd_limit::fvar::limit_at_level(&r, &fr, deepest)
                .unwrap()
                .apply(&refined, 2, &mut limits);
            let corner_values = fr.face_values(deepest);
            let offsets = r.topology(deepest).face_offsets();
            let uv_eval = ev.face_varying(uv, mode).unwrap();
            let values = uv_eval.prepare(uv.values()).unwrap();
            let got = mesh.face_varying_limit(&uv_eval, &values).unwrap();
            assert_eq!(got.indices.len(), mesh.face_vertices.len());
            for f in 0..mesh.num_faces() {
                assert_eq!(mesh.face_levels[f], 2, "{}: every face selected", s.name);
                for k in 0..mesh.face(f).len() {
                    let g = at_deepest(mesh.face_uniform[f] as usize, k);
                    let i = corner_values[offsets[g] as usize + k] as usize;
                    let j = got.indices[mesh.face_offsets[f] as usize + k] as usize;
                    for c in 0..2 {
                        let (x, want) = (got.values[2 * j + c], limits[2 * i + c]);
                        assert!(
                            (x - want).abs() < 1e-12,
                            "{} {mode:?} face {f} corner {k}: {x} vs {want}",
                            s.name
                        );
                    }
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 5000, "only {checked} corners checked");
}

/// The crack count of `mesh` computed another way: a hash map of each uniform edge's
/// face sides against the faces it has, and of each diagonal's (unordered vertex pair)
/// sides, which must be two.
fn mismatches_by_hashing(mesh: &subd_adaptive::AdaptiveMesh) -> usize {
    use std::collections::HashMap;
    use subd_adaptive::EdgeOrigin;
    let mut uniform: HashMap<(u8, u64), (usize, u32)> = HashMap::new();
    let mut diagonals: HashMap<(u32, u32), usize> = HashMap::new();
    for f in 0..mesh.num_faces() {
        let face = mesh.face(f);
        for (i, &a) in face.iter().enumerate() {
            let b = face[(i + 1) % face.len()];
            match mesh.edge_origins[mesh.face_offsets[f] as usize + i] {
                EdgeOrigin::Uniform {
                    level,
                    index,
                    faces,
                } => uniform.entry((level, index)).or_insert((0, faces)).0 += 1,
                EdgeOrigin::Diagonal => *diagonals.entry((a.min(b), a.max(b))).or_insert(0) += 1,
            }
        }
    }
    uniform
        .values()
        .filter(|(n, faces)| *n != *faces as usize)
        .count()
        + diagonals.values().filter(|&&n| n % 2 != 0).count()
}

/// The conformity check finds cracks: with the last face of an adaptive mesh dropped, its
/// inner sides are each one side short; with one side's uniform edge index moved past what
/// the packed sort holds (so the check takes its unpacked path), that side and its
/// partner are off. Both counts equal a hash map's, on every shape.
#[test]
fn the_conformity_check_counts_cracks() {
    let (mut cracked, mut unpacked) = (0, 0);
    for s in shapes() {
        let pick = RandomSelection::new(5, 0.35).unwrap();
        let Ok(a) = AdaptiveRefinement::new(
            &s.mesh.topology,
            &s.mesh.positions,
            &s.scheme,
            &s.options,
            &[&pick],
            2,
        ) else {
            continue;
        };
        let mut mesh = a.mesh(Positions::Refined).unwrap();
        assert_eq!(mesh.conformity().mismatched_edges, 0, "{}", s.name);
        // The last face dropped.
        let mut dropped = mesh.clone();
        dropped.face_offsets.pop();
        let end = *dropped.face_offsets.last().unwrap() as usize;
        dropped.face_vertices.truncate(end);
        dropped.edge_origins.truncate(end);
        dropped.face_levels.pop();
        let expected = mismatches_by_hashing(&dropped);
        assert_eq!(
            dropped.conformity().mismatched_edges,
            expected,
            "{}",
            s.name
        );
        cracked += usize::from(expected > 0);
        // One uniform side moved out of the packed range.
        if let Some(subd_adaptive::EdgeOrigin::Uniform { index, .. }) = mesh
            .edge_origins
            .iter_mut()
            .find(|o| matches!(o, subd_adaptive::EdgeOrigin::Uniform { faces: 2, .. }))
        {
            *index += 1 << 53;
            let expected = mismatches_by_hashing(&mesh);
            assert_eq!(mesh.conformity().mismatched_edges, expected, "{}", s.name);
            assert_eq!(expected, 2, "{}", s.name);
            unpacked += 1;
        }
    }
    assert!(
        cracked > 30 && unpacked > 30,
        "{cracked} cracked, {unpacked} unpacked"
    );
}
