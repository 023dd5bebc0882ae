//! Property tests of the topology builder on random meshes: closed manifolds of random
//! polygons and valences, vertex relabelling, and ring order checked against geometry.

use proptest::prelude::*;
use subd_mesh::TopologySummary;
use subd_tests::{build, mesh_strategy};

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn closed_manifolds_have_half_as_many_edges_as_face_vertices(mesh in mesh_strategy()) {
        let t = build(mesh.num_vertices, &mesh.faces);
        let s = TopologySummary::new(&t);
        if let Some(genus) = mesh.genus {
            prop_assert_eq!(s.boundary_edges, 0);
            prop_assert_eq!(2 * t.num_edges(), t.num_face_vertices());
            prop_assert_eq!(s.genus, Some(genus));
            prop_assert_eq!(s.euler, 2 - 2 * genus);
        } else {
            // A disc: Euler characteristic 1, one boundary loop.
            prop_assert_eq!((s.euler, s.boundary_loops, s.genus), (1, 1, None));
        }
        prop_assert_eq!(s.nonmanifold_edges + s.nonmanifold_vertices, 0);
    }

    #[test]
    fn relabelling_vertices_preserves_invariants(mesh in mesh_strategy(), seed in any::<u64>()) {
        let t = build(mesh.num_vertices, &mesh.faces);
        // A permutation from a seeded Fisher-Yates shuffle.
        let mut perm: Vec<u32> = (0..mesh.num_vertices as u32).collect();
        let mut state = seed | 1;
        for i in (1..perm.len()).rev() {
            state ^= state << 13; state ^= state >> 7; state ^= state << 17;
            perm.swap(i, (state % (i as u64 + 1)) as usize);
        }
        let relabelled: Vec<Vec<u32>> = mesh.faces.iter().map(|f| f.iter().map(|&v| perm[v as usize]).collect()).collect();
        let r = build(mesh.num_vertices, &relabelled);
        let (s, q) = (TopologySummary::new(&t), TopologySummary::new(&r));
        prop_assert_eq!((s.edges, s.euler, s.genus, s.components), (q.edges, q.euler, q.genus, q.components));
        prop_assert_eq!(&s.valences, &q.valences);
        for v in 0..t.num_vertices() {
            let w = perm[v] as usize;
            prop_assert_eq!(t.valence(v), r.valence(w));
            prop_assert_eq!(t.is_boundary_vertex(v), r.is_boundary_vertex(w));
            // The ordered ring maps onto the relabelled ring up to rotation.
            let a: Vec<u32> = t.vertex_ring(v).map(|x| perm[x as usize]).collect();
            let b: Vec<u32> = r.vertex_ring(w).collect();
            let rotated = (0..b.len().max(1)).any(|k| a.iter().enumerate().all(|(i, x)| b[(i + k) % b.len()] == *x));
            prop_assert!(rotated, "ring of {} not a rotation: {:?} vs {:?}", v, a, b);
        }
    }

    #[test]
    fn rings_turn_counter_clockwise_with_the_faces(mesh in mesh_strategy()) {
        let t = build(mesh.num_vertices, &mesh.faces);
        for v in 0..t.num_vertices() {
            // Combinatorial: face i's outgoing edge at v is ring edge i; its incoming edge is
            // ring edge i+1, shared with face i+1.
            let faces = t.vertex_faces(v);
            let corners = t.vertex_face_local_indices(v);
            let edges = t.vertex_edges(v);
            for i in 0..faces.len() {
                let (f, c) = (faces[i] as usize, corners[i] as usize);
                let fe = t.face_edges(f);
                prop_assert_eq!(t.face_vertices(f)[c], v as u32);
                prop_assert_eq!(fe[c], edges[i]);
                prop_assert_eq!(fe[(c + fe.len() - 1) % fe.len()], edges[(i + 1) % edges.len()]);
            }
        }
        // Geometric, on the planar grids: ring neighbours sweep counter-clockwise, i.e. the
        // angle steps are positive and add up to one turn (interior) or less (boundary).
        if let Some(pos) = &mesh.planar {
            for v in 0..t.num_vertices() {
                let p = pos[v];
                let ang: Vec<f64> = t.vertex_ring(v).map(|w| {
                    let q = pos[w as usize];
                    (q[1] - p[1]).atan2(q[0] - p[0])
                }).collect();
                let k = ang.len();
                let steps = if t.is_boundary_vertex(v) { k - 1 } else { k };
                let mut total = 0.0;
                for i in 0..steps {
                    let mut d = ang[(i + 1) % k] - ang[i];
                    while d <= 0.0 { d += std::f64::consts::TAU; }
                    while d > std::f64::consts::TAU { d -= std::f64::consts::TAU; }
                    prop_assert!(d < std::f64::consts::PI, "vertex {} step {} turns clockwise", v, i);
                    total += d;
                }
                if t.is_boundary_vertex(v) {
                    prop_assert!(total < std::f64::consts::TAU);
                } else {
                    prop_assert!((total - std::f64::consts::TAU).abs() < 1e-9, "vertex {} turns {}", v, total);
                }
            }
        }
    }
}
