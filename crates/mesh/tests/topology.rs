//! Hand-checked topologies: each expectation below is worked out on paper from the face
//! lists, not taken from the code's output.

use subd_mesh::{BuildWarning, TopologyBuilder, TopologyError, TopologySummary};

fn build(nv: usize, faces: &[&[u32]]) -> subd_mesh::Topology {
    let sizes: Vec<u32> = faces.iter().map(|f| f.len() as u32).collect();
    let idx: Vec<u32> = faces.iter().flat_map(|f| f.iter().copied()).collect();
    TopologyBuilder::new(nv).build(&sizes, &idx).unwrap()
}

/// 3x3 vertex grid, 2x2 quads, counter-clockwise in the xy plane:
/// 6 7 8 / 3 4 5 / 0 1 2.
fn grid() -> subd_mesh::Topology {
    build(
        9,
        &[&[0, 1, 4, 3], &[1, 2, 5, 4], &[3, 4, 7, 6], &[4, 5, 8, 7]],
    )
}

#[test]
fn edges_are_numbered_by_first_appearance() {
    let t = grid();
    // Face 0 creates (0,1) (1,4) (4,3) (3,0); face 1 creates (1,2) (2,5) (5,4), reuses (4,1);
    // face 2 creates (4,7) (7,6) (6,3), reuses (3,4); face 3 creates (5,8) (8,7).
    let expected = [
        [0, 1],
        [1, 4],
        [4, 3],
        [3, 0],
        [1, 2],
        [2, 5],
        [5, 4],
        [4, 7],
        [7, 6],
        [6, 3],
        [5, 8],
        [8, 7],
    ];
    assert_eq!(t.num_edges(), expected.len());
    for (e, ev) in expected.iter().enumerate() {
        assert_eq!(&t.edge_vertices(e), ev, "edge {e}");
    }
    assert_eq!(t.face_edges(1), &[4, 5, 6, 1]);
    assert_eq!(t.edge_faces(1), &[0, 1]);
    assert_eq!(t.edge_face_local_indices(1), &[1, 3]);
}

#[test]
fn interior_vertex_ring_is_counter_clockwise() {
    let t = grid();
    // Around 4 counter-clockwise starting in face 0 at its outgoing edge (4,3):
    // neighbours 3, 1, 5, 7 and faces 0, 1, 3, 2.
    assert_eq!(t.vertex_ring(4).collect::<Vec<_>>(), vec![3, 1, 5, 7]);
    assert_eq!(t.vertex_faces(4), &[0, 1, 3, 2]);
    assert_eq!(t.vertex_face_local_indices(4), &[2, 3, 0, 1]);
    assert_eq!(t.valence(4), 4);
    assert!(!t.is_extraordinary(4, 4));
    assert_eq!(
        t.vertex_quad_diagonals(4).collect::<Vec<_>>(),
        vec![Some(0), Some(2), Some(8), Some(6)]
    );
}

#[test]
fn boundary_vertex_ring_starts_at_leading_boundary_edge() {
    let t = grid();
    // Vertex 1: faces 0 and 1. Its leading boundary edge is (1,2) (outgoing in face 1);
    // counter-clockwise: 2, 4, 0.
    assert_eq!(t.vertex_ring(1).collect::<Vec<_>>(), vec![2, 4, 0]);
    assert_eq!(t.vertex_faces(1), &[1, 0]);
    assert!(t.is_boundary_vertex(1));
    assert!(!t.is_extraordinary(1, 4));
    // Corner 0 has one face: extraordinary by face count, a corner for OpenSubdiv.
    assert!(t.is_extraordinary(0, 4));
    assert_eq!(subd_mesh::analysis::count_irregular(&t, 4), 0);
    let s = TopologySummary::new(&t);
    assert_eq!(
        (s.boundary_edges, s.boundary_loops, s.euler, s.genus),
        (8, 1, 1, None)
    );
}

#[test]
fn edge_with_three_faces_is_non_manifold() {
    // Three triangles sharing edge (0,1).
    let t = build(5, &[&[0, 1, 2], &[1, 0, 3], &[0, 1, 4]]);
    let e = t.find_edge(0, 1).unwrap() as usize;
    assert_eq!(t.edge_faces(e), &[0, 1, 2]);
    assert!(t.is_non_manifold_edge(e));
    assert!(t.is_non_manifold_vertex(0) && t.is_non_manifold_vertex(1));
    assert!(!t.is_non_manifold_vertex(2));
}

#[test]
fn bowtie_vertex_is_non_manifold() {
    // Two triangles touching only at vertex 0.
    let t = build(5, &[&[0, 1, 2], &[0, 3, 4]]);
    assert!(t.is_non_manifold_vertex(0));
    assert!((0..t.num_edges()).all(|e| !t.is_non_manifold_edge(e)));
    assert_eq!(TopologySummary::new(&t).components, 1);
}

#[test]
fn repeated_vertex_gives_degenerate_non_manifold_edge_and_warning() {
    // The quad repeats vertex 3 (like `f 41 42 52 52` in the non-manifold shapes).
    let (t, warnings) = TopologyBuilder::new(4)
        .build_with_warnings(&[4], &[0, 1, 3, 3])
        .unwrap();
    assert_eq!(
        warnings,
        vec![BuildWarning::RepeatedVertex { face: 0, vertex: 3 }]
    );
    // Edges (0,1) (1,3) (3,3) (3,0): the degenerate one is a separate non-manifold edge.
    assert_eq!(t.num_edges(), 4);
    assert!(t.is_degenerate_edge(2) && t.is_non_manifold_edge(2));
    assert_eq!(t.edge_vertices(2), [3, 3]);
    assert!(t.is_isolated_vertex(2));
}

#[test]
fn edge_repeated_within_a_face_gets_a_second_instance() {
    // Face 0 walks 0->1->2->1: edge {1,2} appears twice in it.
    let (t, _) = TopologyBuilder::new(3)
        .build_with_warnings(&[4], &[0, 1, 2, 1])
        .unwrap();
    // (0,1) (1,2) then (2,1) is a new instance, then (1,0) is yet another (0,1) use in the
    // same face, so it is a new instance too.
    assert_eq!(t.num_edges(), 4);
    assert_eq!(t.edge_vertices(2), [2, 1]);
    assert!((0..4).all(|e| t.is_non_manifold_edge(e)));
    assert_eq!(t.find_edge(1, 2), Some(1));
}

#[test]
fn orientation_conflict_is_an_error_unless_accepted() {
    let sizes = [3, 3];
    let idx = [0, 1, 2, 0, 1, 3];
    let err = TopologyBuilder::new(4).build(&sizes, &idx).unwrap_err();
    assert_eq!(
        err,
        TopologyError::InconsistentOrientation {
            first_face: 0,
            second_face: 1,
            v0: 0,
            v1: 1
        }
    );
    assert!(err.to_string().contains("faces 0 and 1"));
    let (t, w) = TopologyBuilder::new(4)
        .accept_inconsistent_orientation(true)
        .build_with_warnings(&sizes, &idx)
        .unwrap();
    assert_eq!(w.len(), 1);
    assert!(t.is_non_manifold_edge(0));
}

#[test]
fn invalid_input_is_rejected_with_the_element_named() {
    assert_eq!(
        TopologyBuilder::new(3).build(&[2], &[0, 1]).unwrap_err(),
        TopologyError::FaceTooSmall { face: 0, size: 2 }
    );
    // One face beyond the 16-bit local-index limit, after a valid triangle.
    let big = subd_mesh::MAX_FACE_SIZE + 1;
    let mut verts = vec![0u32, 1, 2];
    verts.extend(0..big as u32);
    assert_eq!(
        TopologyBuilder::new(big)
            .build(&[3, big as u32], &verts)
            .unwrap_err(),
        TopologyError::FaceTooLarge {
            face: 1,
            size: big,
            max: 65535
        }
    );
    assert_eq!(
        TopologyBuilder::new(3)
            .build(&[3, 3], &[0, 1, 2, 0, 2, 7])
            .unwrap_err(),
        TopologyError::VertexIndexOutOfRange {
            face: 1,
            corner: 2,
            index: 7,
            num_vertices: 3
        }
    );
    assert!(matches!(
        TopologyBuilder::new(3).build(&[3], &[0, 1]).unwrap_err(),
        TopologyError::FaceVertexCountMismatch { .. }
    ));
    let nan = [
        subd_mesh::DVec3::ZERO,
        subd_mesh::DVec3::new(0.0, f64::NAN, 0.0),
    ];
    assert!(matches!(
        subd_mesh::validate_positions(&nan).unwrap_err(),
        TopologyError::NonFiniteCoordinate { vertex: 1, .. }
    ));
}

#[test]
fn tags_are_checked() {
    let mut t = grid();
    assert_eq!(t.set_crease(4, 5, 2.5).unwrap(), Some(6));
    assert_eq!(t.edge_sharpness(6), 2.5);
    assert_eq!(t.set_crease(0, 8, 1.0).unwrap(), None);
    assert!(t.set_crease(0, 9, 1.0).is_err());
    assert!(t.set_corner(3, -1.0).is_err());
    assert!(t.set_hole_checked(4).is_err());
    t.set_corner(3, 7.9).unwrap();
    // Sharpness is kept in f32, as OpenSubdiv keeps it.
    assert_eq!(t.vertex_sharpness(3), 7.9f32);
    // Huge but finite sharpness (found by fuzzing) saturates instead of becoming inf.
    t.set_corner(4, 3.4e79).unwrap();
    assert_eq!(t.vertex_sharpness(4), f32::MAX);
    t.set_corner(4, 0.0).unwrap();
    t.set_hole_checked(3).unwrap();
    assert_eq!(
        (
            t.tags().num_holes(),
            t.tags().num_corners(),
            t.tags().num_creased_edges()
        ),
        (1, 1, 1)
    );
}

#[test]
fn cube_and_torus_genus() {
    let cube: [&[u32]; 6] = [
        &[0, 1, 3, 2],
        &[2, 3, 5, 4],
        &[4, 5, 7, 6],
        &[6, 7, 1, 0],
        &[1, 7, 5, 3],
        &[6, 0, 2, 4],
    ];
    let s = TopologySummary::new(&build(8, &cube));
    assert_eq!((s.edges, s.euler, s.genus), (12, 2, Some(0)));
    // 3x3 torus grid.
    let n = 3u32;
    let id = |i: u32, j: u32| (i % n) * n + (j % n);
    let faces: Vec<Vec<u32>> = (0..n)
        .flat_map(|i| {
            (0..n).map(move |j| vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
        })
        .collect();
    let refs: Vec<&[u32]> = faces.iter().map(|f| f.as_slice()).collect();
    let s = TopologySummary::new(&build(9, &refs));
    assert_eq!(
        (s.edges, s.euler, s.genus, s.components),
        (18, 0, Some(1), 1)
    );
    // Two disjoint cubes: genus adds up, components count.
    let mut two: Vec<Vec<u32>> = cube.iter().map(|f| f.to_vec()).collect();
    two.extend(
        cube.iter()
            .map(|f| f.iter().map(|v| v + 8).collect::<Vec<_>>()),
    );
    let refs: Vec<&[u32]> = two.iter().map(|f| f.as_slice()).collect();
    let s = TopologySummary::new(&build(16, &refs));
    assert_eq!((s.components, s.euler, s.genus), (2, 4, Some(0)));
}
