//! Property tests of refinement on random meshes with random tags: stencil rows sum to one,
//! refinement commutes with affine maps, relabelling input vertices only permutes the
//! result, the stencil tables and the direct evaluation agree, and thread count does not
//! change a bit.

use proptest::prelude::*;
use subd_mesh::{DVec3, Topology, TopologyBuilder};
use subd_schemes::{Options, Refinement, Scheme};
use subd_tests::{
    TaggedCase as Case, build, creased_torus, random_mesh, relabelled, tagged_case_strategy,
};

fn case_strategy() -> impl Strategy<Value = Case> {
    tagged_case_strategy(&[Scheme::CatmullClark, Scheme::Loop, Scheme::Bilinear])
}

fn topology(c: &Case, faces: &[Vec<u32>]) -> Topology {
    c.topology(faces)
}

fn options(c: &Case) -> Options {
    c.options()
}

fn max_diff(a: &[DVec3], b: &[DVec3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (*x - *y).abs().max_element())
        .fold(0.0, f64::max)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn stencil_rows_sum_to_one(c in case_strategy()) {
        let t = topology(&c, &c.mesh.faces);
        let r = Refinement::new(&t, c.scheme.clone(), &options(&c), 2).unwrap();
        for table in [r.stencils(1).clone(), r.stencils(2).clone(), r.composed(2)] {
            for row in 0..table.num_rows() {
                let (_, w) = table.row(row);
                let sum: f64 = w.iter().sum();
                prop_assert!((sum - 1.0).abs() < 1e-12, "row {} sums to {}", row, sum);
            }
        }
    }

    #[test]
    fn refinement_commutes_with_affine_maps(c in case_strategy(), a in prop::array::uniform9(-2.0f64..2.0), b in prop::array::uniform3(-5.0f64..5.0)) {
        let t = topology(&c, &c.mesh.faces);
        let r = Refinement::new(&t, c.scheme.clone(), &options(&c), 2).unwrap();
        let m = glam::DMat3::from_cols_array(&a);
        let shift = DVec3::from_array(b);
        let map = |p: DVec3| m * p + shift;
        let moved: Vec<DVec3> = c.positions.iter().map(|&p| map(p)).collect();
        let direct = r.refine_points(&moved).pop().unwrap();
        let mapped: Vec<DVec3> = r.refine_points(&c.positions).pop().unwrap().into_iter().map(map).collect();
        prop_assert!(max_diff(&direct, &mapped) < 1e-12 * 10.0, "{}", max_diff(&direct, &mapped));
    }

    #[test]
    fn relabelling_vertices_permutes_the_result(c in case_strategy(), seed in any::<u64>()) {
        let nv = c.mesh.num_vertices;
        let (perm, t, u, pos) = relabelled(&c, seed);
        let a = Refinement::new(&t, c.scheme.clone(), &options(&c), 2).unwrap().refine_points(&c.positions);
        let b = Refinement::new(&u, c.scheme.clone(), &options(&c), 2).unwrap().refine_points(&pos);
        // Edges are numbered by first appearance in face order, which relabelling keeps, so
        // only the base-vertex block of each level is permuted.
        for level in 1..=2 {
            let (x, y) = (&a[level], &b[level]);
            prop_assert_eq!(x.len(), y.len());
            for i in 0..x.len() {
                let j = if i < nv { perm[i] as usize } else { i };
                prop_assert!((x[i] - y[j]).abs().max_element() < 1e-12, "level {} vertex {}", level, i);
            }
        }
    }

    #[test]
    fn stencil_tables_agree_with_direct_evaluation(c in case_strategy()) {
        let t = topology(&c, &c.mesh.faces);
        let r = Refinement::new(&t, c.scheme.clone(), &options(&c), 3).unwrap();
        let direct = r.refine_points(&c.positions);
        let composed = r.composed(3).apply_points(&c.positions);
        prop_assert!(max_diff(&direct[3], &composed) < 1e-12);
        let mut flat = vec![0.0; 3 * r.num_vertices(3)];
        let src: Vec<f64> = direct[2].iter().flat_map(|p| p.to_array()).collect();
        r.stencils(3).apply(&src, 3, &mut flat);
        let per_level: Vec<DVec3> = flat.chunks_exact(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect();
        prop_assert!(max_diff(&direct[3], &per_level) < 1e-12);
    }
}

/// One thread and many threads give bit-identical points and stencil tables on a mesh large
/// enough to be split across threads.
#[test]
fn one_thread_equals_many_threads() {
    let (t, positions) = creased_torus(60, 70);
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                let r = Refinement::new(&t, Scheme::CatmullClark, &Options::default(), 3).unwrap();
                (r.refine_points(&positions), r.composed(3))
            })
    };
    let (p1, s1) = run(1);
    let (p4, s4) = run(4);
    assert!(s1.num_rows() > 50_000);
    let bits = |v: &[DVec3]| {
        v.iter()
            .map(|p| p.to_array().map(f64::to_bits))
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(&p1[3]), bits(&p4[3]));
    assert_eq!(s1, s4);
}

/// Two triangles become eight after one Loop level; a closed torus keeps V − E + F = 0.
#[test]
fn counts_grow_as_expected() {
    let t = TopologyBuilder::new(4)
        .build(&[3, 3], &[0, 1, 2, 0, 2, 3])
        .unwrap();
    let r = Refinement::new(&t, Scheme::Loop, &Options::default(), 1).unwrap();
    assert_eq!((r.topology(1).num_faces(), r.num_vertices(1)), (8, 9));
    let mesh = random_mesh(0, 5, 6, &[0], &[(0.0, 0.0)]);
    let t = build(mesh.num_vertices, &mesh.faces);
    let r = Refinement::new(&t, Scheme::CatmullClark, &Options::default(), 2).unwrap();
    let l2 = r.topology(2);
    assert_eq!(
        l2.num_vertices() as i64 - l2.num_edges() as i64 + l2.num_faces() as i64,
        0
    );
}
