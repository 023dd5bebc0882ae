//! The child topologies a refinement derives directly (no search) agree with what the
//! generic builder makes of the same faces, and keep the ring invariants, on every shape.

use subd_io::{ReadOptions, read_mesh};
use subd_mesh::{TopologyBuilder, TopologySummary};
use subd_schemes::{Options, Refinement, Scheme};
use subd_tests::{all_faces_of_size, osd_meshes, small_shapes};

#[test]
fn derived_child_topology_matches_the_builder() {
    let opts = ReadOptions {
        accept_inconsistent_orientation: true,
        ..Default::default()
    };
    for path in osd_meshes() {
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        let scheme = if name.starts_with("loop_") {
            Scheme::Loop
        } else {
            Scheme::CatmullClark
        };
        let file = read_mesh(&path, &opts).unwrap();
        let r = Refinement::new(
            &file.mesh.topology,
            scheme,
            &Options::from_hints(&file.mesh.hints),
            2,
        )
        .unwrap();
        for level in 1..=2 {
            let t = r.topology(level);
            t.check_relations()
                .unwrap_or_else(|e| panic!("{name} level {level}: {e}"));
            // Manifold rings: edge i leaves the vertex in face i, edge i+1 arrives in it.
            for v in 0..t.num_vertices() {
                if t.is_non_manifold_vertex(v) || t.is_isolated_vertex(v) {
                    continue;
                }
                let (vf, vl, ve) = (
                    t.vertex_faces(v),
                    t.vertex_face_local_indices(v),
                    t.vertex_edges(v),
                );
                for i in 0..vf.len() {
                    let fe = t.face_edges(vf[i] as usize);
                    let c = vl[i] as usize;
                    assert_eq!(fe[c], ve[i], "{name} L{level} v{v} leading edge {i}");
                    assert_eq!(
                        fe[(c + fe.len() - 1) % fe.len()],
                        ve[(i + 1) % ve.len()],
                        "{name} L{level} v{v} trailing {i}"
                    );
                }
            }
            // On a manifold base the generic builder, given the same faces, finds the same
            // edges and flags. (Around non-manifold features a refinement keeps edges that
            // join the same two vertices apart — the two halves of a degenerate edge, the
            // interior edges of two faces with the same vertices — exactly as OpenSubdiv
            // does, and a rebuild from faces alone would merge them; the OpenSubdiv
            // conformance run checks those cases.)
            let base = &file.mesh.topology;
            if (0..base.num_edges()).any(|e| base.is_non_manifold_edge(e))
                || (0..base.num_vertices()).any(|v| base.is_non_manifold_vertex(v))
            {
                continue;
            }
            let rebuilt = TopologyBuilder::new(t.num_vertices())
                .accept_inconsistent_orientation(true)
                .build(&t.face_sizes().collect::<Vec<_>>(), t.all_face_vertices())
                .unwrap();
            let (a, b) = (TopologySummary::new(t), TopologySummary::new(&rebuilt));
            assert_eq!(
                (
                    a.edges,
                    a.boundary_edges,
                    a.nonmanifold_edges,
                    a.nonmanifold_vertices,
                    a.euler,
                    &a.valences
                ),
                (
                    b.edges,
                    b.boundary_edges,
                    b.nonmanifold_edges,
                    b.nonmanifold_vertices,
                    b.euler,
                    &b.valences
                ),
                "{name} level {level}"
            );
            for e in 0..t.num_edges() {
                let [x, y] = t.edge_vertices(e);
                assert!(
                    rebuilt.find_edge(x, y).is_some(),
                    "{name} L{level} edge {e}"
                );
            }
        }
    }
}

/// What a refinement says of its last level without building the level's topology (the
/// edge count, whether anything is sharp, the tags a file must carry) is what the built
/// topology shows, on every shape with every scheme that applies, and with Chaikin creases.
#[test]
fn last_level_counts_and_sharpness_without_its_topology() {
    let (mut sharp, mut smooth, mut explicit) = (0, 0, 0);
    for (name, file) in small_shapes(usize::MAX) {
        let base = &file.mesh.topology;
        let schemes: &[Scheme] = if all_faces_of_size(base, 3) {
            &[Scheme::Loop, Scheme::CatmullClark, Scheme::Bilinear]
        } else {
            &[Scheme::CatmullClark, Scheme::Bilinear]
        };
        for scheme in schemes {
            for chaikin in [false, true] {
                let mut options = Options::from_hints(&file.mesh.hints);
                if chaikin {
                    options.crease_method = subd_mesh::CreaseMethod::Chaikin;
                }
                // Three levels decay the semi-sharp creases of most shapes away.
                let deepest = if base.num_face_vertices() > 8000 {
                    2
                } else {
                    3
                };
                for levels in 1..=deepest {
                    let r = Refinement::new(base, scheme.clone(), &options, levels).unwrap();
                    let (edges, has) = (r.num_edges(levels), r.has_sharpness(levels));
                    let tags = r.explicit_tags(levels);
                    let t = r.topology(levels);
                    // From the built level: every sharp edge and vertex but the implied.
                    assert_eq!(
                        tags,
                        r.explicit_tags(levels),
                        "{name} {scheme:?} L{levels} explicit tags"
                    );
                    let implied_vertex = |v: usize| {
                        t.is_non_manifold_vertex(v)
                            || t.is_isolated_vertex(v)
                            || (t.vertex_faces(v).len() == 1
                                && t.valence(v) == 2
                                && options.boundary_interpolation
                                    == subd_mesh::BoundaryInterpolation::EdgeAndCorner)
                    };
                    let explicit_edges = (0..t.num_edges())
                        .filter(|&e| t.edge_sharpness(e) > 0.0)
                        .filter(|&e| !t.is_boundary_edge(e) && !t.is_non_manifold_edge(e))
                        .count();
                    let explicit_vertices = (0..t.num_vertices())
                        .filter(|&v| t.vertex_sharpness(v) > 0.0 && !implied_vertex(v))
                        .count();
                    assert_eq!(tags.creases.len(), explicit_edges, "{name} L{levels}");
                    assert_eq!(tags.corners.len(), explicit_vertices, "{name} L{levels}");
                    explicit += tags.creases.len() + tags.corners.len();
                    assert_eq!(
                        edges,
                        Some(t.num_edges()),
                        "{name} {scheme:?} L{levels} edges"
                    );
                    let built = (0..t.num_edges()).any(|e| t.edge_sharpness(e) > 0.0)
                        || (0..t.num_vertices()).any(|v| t.vertex_sharpness(v) > 0.0);
                    assert_eq!(has, built, "{name} {scheme:?} L{levels} sharpness");
                    assert_eq!(r.has_sharpness(levels), built, "{name} built, asked again");
                    if built {
                        sharp += 1;
                    } else {
                        smooth += 1;
                    }
                }
            }
        }
    }
    // The shapes cover both answers.
    assert!(sharp > 0 && smooth > 0, "sharp {sharp}, smooth {smooth}");
    assert!(explicit > 1000, "{explicit} explicit tags");
}

/// On closed, smooth meshes the last Catmull-Clark (all quads) or Loop level is derived from
/// the level two above, without building the level in between. Its faces, rules and points equal,
/// bit for bit, those of the path through the built level (forced afterwards on the same
/// refinement), and the deeper refinement that builds it.
#[test]
fn last_level_from_its_grandparent_equals_the_built_path() {
    let mut fused = Vec::new();
    for (name, file) in small_shapes(8000) {
        let base = &file.mesh.topology;
        let schemes: &[Scheme] = if all_faces_of_size(base, 3) {
            &[Scheme::CatmullClark, Scheme::Loop]
        } else {
            &[Scheme::CatmullClark]
        };
        for (scheme, smooth_triangles) in schemes
            .iter()
            .flat_map(|s| [(s.clone(), false), (s.clone(), true)])
        {
            let mut options = Options::from_hints(&file.mesh.hints);
            if smooth_triangles {
                options.triangle_subdivision = subd_mesh::TriangleSubdivision::Smooth;
            }
            for levels in 2..=3 {
                let r = Refinement::new(base, scheme.clone(), &options, levels).unwrap();
                if r.has_topology(levels - 1) {
                    continue;
                }
                fused.push(format!("{name} {scheme:?} L{levels}"));
                let (edges, tags) = (r.num_edges(levels), r.explicit_tags(levels));
                let points = r.refine_points(&file.mesh.positions);
                assert!(
                    !r.has_topology(levels - 1),
                    "{name}: points need no level {}",
                    levels - 1
                );
                // The same refinement through the built levels.
                let t = r.topology(levels);
                assert!(r.has_topology(levels - 1));
                let (offsets, vertices) = r.faces(levels);
                assert_eq!(offsets, t.face_offsets(), "{name} L{levels} offsets");
                assert_eq!(vertices, t.all_face_vertices(), "{name} L{levels} faces");
                assert!(r.holes(levels).iter().all(|&h| !h));
                assert_eq!(edges, Some(t.num_edges()), "{name} L{levels} edges");
                assert_eq!(tags, r.explicit_tags(levels), "{name} L{levels} tags");
                let built = r.refine_points(&file.mesh.positions);
                assert_eq!(points, built, "{name} L{levels} points");
                // A refinement one level deeper builds level `levels` and derives its rules
                // from the built level above.
                let deeper = Refinement::new(base, scheme.clone(), &options, levels + 1).unwrap();
                assert!(deeper.has_topology(levels - 1));
                assert_eq!(
                    r.vertex_rules(levels),
                    deeper.vertex_rules(levels),
                    "{name} L{levels} rules"
                );
                assert_eq!(
                    r.topology(levels),
                    deeper.topology(levels),
                    "{name} L{levels} topology"
                );
                assert_eq!(
                    points,
                    deeper.refine_points(&file.mesh.positions)[..=levels],
                    "{name} L{levels} deeper points"
                );
                // Stencils go through the built level too, and agree.
                let via_stencils = r.composed(levels).apply_points(&file.mesh.positions);
                for (a, b) in via_stencils.iter().zip(&points[levels]) {
                    assert!((*a - *b).length() <= 1e-12 * (1.0 + b.length()), "{name}");
                }
            }
        }
    }
    // Closed smooth quad shapes exist among OpenSubdiv's, at level 2 from an all-quad base
    // and at level 3 from any closed smooth base.
    assert!(fused.len() >= 6, "fused cases: {fused:?}");
    assert!(
        fused.iter().any(|c| c.contains("Loop")),
        "no Loop case: {fused:?}"
    );
}

/// The last level streamed a range at a time (faces from the level above or its
/// grandparent, points from the level above) is, bit for bit, the level held whole, on
/// every shape with every scheme that applies and the two-phase scheme, in windows that
/// split parent faces.
#[test]
fn last_level_streams_equal_the_held_level() {
    use subd_mesh::DVec3;
    let (mut cases, mut from_grandparent, mut with_holes) = (0, 0, 0);
    for (name, file) in small_shapes(8000) {
        let base = &file.mesh.topology;
        let triangles = all_faces_of_size(base, 3);
        let quads = all_faces_of_size(base, 4);
        let schemes: &[Scheme] = if triangles {
            &[Scheme::Loop, Scheme::CatmullClark, Scheme::Bilinear]
        } else {
            &[Scheme::CatmullClark, Scheme::Bilinear]
        };
        let options = Options::from_hints(&file.mesh.hints);
        let mut runs: Vec<(Scheme, bool)> = schemes.iter().map(|s| (s.clone(), false)).collect();
        if quads {
            runs.push((Scheme::CatmullClark, true));
        }
        for (scheme, two_phase) in runs {
            for levels in 1..=3 {
                let refine = || match two_phase {
                    true => {
                        let tp = subd_schemes::TwoPhase::uniform(0.6).unwrap();
                        Refinement::new(
                            base,
                            subd_schemes::Scheme::TwoPhase(tp.clone()),
                            &options,
                            levels,
                        )
                        .unwrap()
                    }
                    false => Refinement::new(base, scheme.clone(), &options, levels).unwrap(),
                };
                let (streamed, held) = (refine(), refine());
                let what = format!("{name} {scheme:?} two-phase {two_phase} L{levels}");
                from_grandparent += usize::from(!streamed.has_topology(levels - 1));
                let faces = streamed.face_stream().unwrap();
                let above = streamed.points_at(&file.mesh.positions, levels - 1);
                let points = streamed.point_stream(&above).unwrap();
                // Windows of 7 faces and 5 points cut through the children of parent faces.
                let mut got_faces = Vec::new();
                let n = faces.num_faces();
                for start in (0..n).step_by(7) {
                    faces.fill(start..(start + 7).min(n), &mut got_faces);
                }
                let mut got_points = vec![DVec3::ZERO; points.len()];
                for (i, chunk) in got_points.chunks_mut(5).enumerate() {
                    points.fill(5 * i, chunk);
                }
                let (offsets, vertices) = held.faces(levels);
                assert_eq!(n, offsets.len() - 1, "{what} face count");
                assert!(
                    offsets
                        .windows(2)
                        .all(|w| (w[1] - w[0]) as usize == faces.face_size()),
                    "{what} face size"
                );
                assert_eq!(got_faces, vertices, "{what} faces");
                // The whole level written at once into a buffer of another index type.
                let mut wide = vec![-1i64; vertices.len()];
                faces.write_all(&mut wide, i64::from);
                assert!(
                    wide.iter().zip(vertices).all(|(&w, &v)| w == i64::from(v)),
                    "{what} faces written whole"
                );
                let holes: Vec<usize> = (0..n).filter(|&f| held.holes(levels)[f]).collect();
                with_holes += usize::from(!holes.is_empty());
                assert_eq!(faces.hole_faces(), holes, "{what} holes");
                let all = held.refine_points(&file.mesh.positions);
                assert_eq!(above, all[levels - 1], "{what} level above");
                assert_eq!(got_points, all[levels], "{what} points");
                // Streaming built no level the held path did not.
                assert!(
                    !streamed.has_topology(levels),
                    "{what}: the streamed level stays unbuilt"
                );
                cases += 1;
            }
        }
    }
    assert!(cases > 300, "{cases} cases");
    assert!(
        from_grandparent > 10,
        "{from_grandparent} from the grandparent"
    );
    assert!(with_holes > 3, "{with_holes} with holes");
}

/// `refine_mesh`'s result hands its faces out whole in another index type equal to the
/// built mesh's, and building the topology moves its positions rather than copying them
/// (the Python binding's views of them stay valid).
#[test]
fn refined_mesh_streams_faces_and_moves_positions() {
    use subd_limit::refined_mesh::{MeshRefinement, refine_mesh};
    for (name, file) in small_shapes(400) {
        let scheme = if all_faces_of_size(&file.mesh.topology, 3) {
            Scheme::Loop
        } else {
            Scheme::CatmullClark
        };
        for levels in 1..=2 {
            let request = MeshRefinement::new(scheme.clone(), &file.mesh, levels);
            let refined = refine_mesh(&file.mesh, &request).unwrap();
            let stream = refined.face_stream().expect("an OpenSubdiv scheme streams");
            let mut wide = vec![0i32; refined.faces().1.len()];
            stream.write_all(&mut wide, |v| i32::try_from(v).unwrap());
            let before = refined.positions().as_ptr();
            let (mesh, _) = refined.into_mesh().unwrap();
            assert_eq!(mesh.positions.as_ptr(), before, "{name} L{levels}");
            let built = mesh.topology.all_face_vertices();
            assert!(
                wide.iter().zip(built).all(|(&w, &b)| w as u32 == b) && wide.len() == built.len(),
                "{name} L{levels} faces"
            );
        }
    }
}
