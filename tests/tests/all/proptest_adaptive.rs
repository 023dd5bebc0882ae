//! Property tests of adaptive refinement on random meshes with random tags (Catmull-Clark and
//! Loop, uniform and Chaikin creases): the hierarchy's vertices are uniform refinement's,
//! the conforming mesh is conforming with level differences of at most one, selecting every
//! face is uniform refinement, relabelling the input only relabels the result, and one
//! thread gives what many threads give, bit for bit.

use std::collections::BTreeSet;

use proptest::prelude::*;
use subd_adaptive::{
    AdaptiveMesh, AdaptiveRefinement, Criterion, FaceSelection, Flatness, Positions,
    RandomSelection,
};
use subd_mesh::DVec3;
use subd_schemes::{Refinement, Scheme};
use subd_tests::{TaggedCase, creased_torus, relabelled, tagged_case_strategy};

fn cases() -> impl Strategy<Value = TaggedCase> {
    tagged_case_strategy(&[Scheme::CatmullClark, Scheme::Loop])
}

fn adaptive(c: &TaggedCase, criteria: &[&dyn Criterion], levels: usize) -> AdaptiveRefinement {
    let t = c.topology(&c.mesh.faces);
    AdaptiveRefinement::new(&t, &c.positions, &c.scheme, &c.options(), criteria, levels).unwrap()
}

/// Faces as lists of corner positions (bits), each rotated to start at its smallest corner.
fn face_set(m: &AdaptiveMesh) -> BTreeSet<Vec<[u64; 3]>> {
    (0..m.num_faces())
        .map(|f| {
            let c: Vec<[u64; 3]> = m
                .face(f)
                .iter()
                .map(|&v| m.positions[v as usize].to_array().map(f64::to_bits))
                .collect();
            let k = (0..c.len()).min_by_key(|&i| c[i]).unwrap_or(0);
            (0..c.len()).map(|i| c[(k + i) % c.len()]).collect()
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn hierarchy_is_exact_and_the_mesh_conforming(c in cases(), seed in any::<u64>()) {
        let levels = 3;
        let t = c.topology(&c.mesh.faces);
        let uniform = Refinement::new(&t, c.scheme.clone(), &c.options(), levels)
            .unwrap()
            .refine_points(&c.positions);
        let a = adaptive(&c, &[&RandomSelection::new(seed, 0.4).unwrap()], levels);
        for (l, level) in uniform.iter().enumerate().take(a.depth() + 1) {
            for (k, p) in a.level_vertices(l) {
                prop_assert_eq!(p, level[k as usize], "level {} vertex {}", l, k);
            }
        }
        let mesh = a.mesh(Positions::Refined).unwrap();
        let report = mesh.conformity();
        prop_assert!(report.conforming, "{:?}", report);
        prop_assert!(report.max_level_difference_vertex <= 1, "{:?}", report);
        prop_assert!(report.max_level_difference_edge <= 1, "{:?}", report);
        if c.mesh.genus.is_some() {
            prop_assert_eq!(report.boundary_edges, 0);
        }
    }

    #[test]
    fn selecting_every_face_gives_uniform_faces(c in cases()) {
        let levels = 2;
        let t = c.topology(&c.mesh.faces);
        let r = Refinement::new(&t, c.scheme.clone(), &c.options(), levels).unwrap();
        let a = adaptive(&c, &[], levels);
        let mesh = a.mesh(Positions::Refined).unwrap();
        let (off, fv) = r.faces(levels);
        let want: BTreeSet<Vec<u32>> = (0..off.len() - 1)
            .map(|f| fv[off[f] as usize..off[f + 1] as usize].to_vec())
            .collect();
        let got: BTreeSet<Vec<u32>> = (0..mesh.num_faces())
            .map(|f| mesh.face(f).iter().map(|&v| mesh.vertex_uniform[v as usize] as u32).collect())
            .collect();
        prop_assert_eq!(got, want);
    }

    #[test]
    fn relabelling_vertices_relabels_the_result(c in cases(), seed in any::<u64>(), flat in 5.0f64..40.0) {
        let (_, t, u, pos) = relabelled(&c, seed);
        // Geometric criteria and face selections do not depend on labels.
        let flatness = Flatness::new(flat).unwrap();
        let picked: Vec<u64> = (0..t.num_faces() as u64).filter(|f| (f ^ seed) % 3 == 0).collect();
        let select = FaceSelection::from_faces(t.num_faces(), &picked).unwrap();
        let o = c.options();
        let a = AdaptiveRefinement::new(&t, &c.positions, &c.scheme, &o, &[&flatness, &select], 3).unwrap();
        let b = AdaptiveRefinement::new(&u, &pos, &c.scheme, &o, &[&flatness, &select], 3).unwrap();
        let (ma, mb) = (a.mesh(Positions::Refined).unwrap(), b.mesh(Positions::Refined).unwrap());
        prop_assert_eq!(ma.faces_per_level(), mb.faces_per_level());
        prop_assert_eq!(face_set(&ma), face_set(&mb));
    }
}

/// One thread and four threads give the same hierarchy and mesh, bit for bit, on a mesh
/// large enough to be split across threads.
#[test]
fn one_thread_equals_many_threads() {
    let (t, positions) = creased_torus(50, 60);
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                let flat = Flatness::new(20.0).unwrap();
                let o = subd_schemes::Options::default();
                let a =
                    AdaptiveRefinement::new(&t, &positions, &Scheme::CatmullClark, &o, &[&flat], 3)
                        .unwrap();
                let m = a.mesh(Positions::Limit).unwrap();
                let bits = |v: &[DVec3]| {
                    v.iter()
                        .map(|p| p.to_array().map(f64::to_bits))
                        .collect::<Vec<_>>()
                };
                (
                    bits(&m.positions),
                    bits(&m.normals),
                    m.face_vertices,
                    m.face_levels,
                )
            })
    };
    let one = run(1);
    let four = run(4);
    assert!(one.2.len() > 20_000, "{} face-vertices", one.2.len());
    assert!(one == four);
}
