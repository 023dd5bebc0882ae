//! The child topologies a refinement derives directly (no search) agree with what the
//! generic builder makes of the same faces, and keep the ring invariants, on every shape.

use subd_io::{ReadOptions, read_mesh};
use subd_mesh::{TopologyBuilder, TopologySummary};
use subd_schemes::{Options, Refinement, Scheme};
use subd_tests::osd_meshes;

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
    let opts = ReadOptions {
        accept_inconsistent_orientation: true,
        ..Default::default()
    };
    let (mut sharp, mut smooth, mut explicit) = (0, 0, 0);
    for path in osd_meshes() {
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        let file = read_mesh(&path, &opts).unwrap();
        let base = &file.mesh.topology;
        let schemes: &[Scheme] = if (0..base.num_faces()).all(|f| base.face_size(f) == 3) {
            &[Scheme::Loop, Scheme::CatmullClark, Scheme::Bilinear]
        } else {
            &[Scheme::CatmullClark, Scheme::Bilinear]
        };
        for &scheme in schemes {
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
                    let r = Refinement::new(base, scheme, &options, levels).unwrap();
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
                    assert_eq!(edges, t.num_edges(), "{name} {scheme:?} L{levels} edges");
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
    let opts = ReadOptions {
        accept_inconsistent_orientation: true,
        ..Default::default()
    };
    let mut fused = Vec::new();
    for path in osd_meshes() {
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        let file = read_mesh(&path, &opts).unwrap();
        let base = &file.mesh.topology;
        if base.num_face_vertices() > 8000 {
            continue;
        }
        let schemes: &[Scheme] = if (0..base.num_faces()).all(|f| base.face_size(f) == 3) {
            &[Scheme::CatmullClark, Scheme::Loop]
        } else {
            &[Scheme::CatmullClark]
        };
        for (&scheme, smooth_triangles) in schemes.iter().flat_map(|s| [(s, false), (s, true)]) {
            let mut options = Options::from_hints(&file.mesh.hints);
            if smooth_triangles {
                options.triangle_subdivision = subd_mesh::TriangleSubdivision::Smooth;
            }
            for levels in 2..=3 {
                let r = Refinement::new(base, scheme, &options, levels).unwrap();
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
                assert_eq!(edges, t.num_edges(), "{name} L{levels} edges");
                assert_eq!(tags, r.explicit_tags(levels), "{name} L{levels} tags");
                let built = r.refine_points(&file.mesh.positions);
                assert_eq!(points, built, "{name} L{levels} points");
                // A refinement one level deeper builds level `levels` and derives its rules
                // from the built level above.
                let deeper = Refinement::new(base, scheme, &options, levels + 1).unwrap();
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
