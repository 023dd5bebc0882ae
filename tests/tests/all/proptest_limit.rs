//! Property tests of limit stencils and exact evaluation on random meshes: limit position
//! rows sum to one and tangent rows to zero; limits and evaluated points commute with affine
//! maps.

use proptest::prelude::*;
use subd_limit::LimitStencilTable;
use subd_limit::eval::{FaceParam, LimitEvaluator};
use subd_mesh::DVec3;
use subd_schemes::{Options, Refinement, Scheme};
use subd_tests::{RandomMesh, build, mesh_strategy};

fn positions(mesh: &RandomMesh, seed: u64) -> Vec<DVec3> {
    let mut x = seed | 1;
    let mut next = || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    (0..mesh.num_vertices)
        .map(|_| DVec3::new(next(), next(), next()))
        .collect()
}

fn affine(p: DVec3) -> DVec3 {
    DVec3::new(
        1.3 * p.x - 0.4 * p.y + 0.2 * p.z + 0.7,
        0.1 * p.x + 0.9 * p.y - 0.5 * p.z - 1.1,
        -0.3 * p.x + 0.6 * p.y + 1.7 * p.z + 2.5,
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn limit_rows_sum_to_one_and_commute_with_affine_maps(
        mesh in mesh_strategy(), loop_scheme in any::<bool>(), seed in any::<u64>()
    ) {
        let mut mesh = mesh;
        let scheme = if loop_scheme {
            mesh.faces = mesh
                .faces
                .iter()
                .flat_map(|f| (1..f.len() - 1).map(move |i| vec![f[0], f[i], f[i + 1]]))
                .collect();
            Scheme::Loop
        } else {
            Scheme::CatmullClark
        };
        let topo = build(mesh.num_vertices, &mesh.faces);
        let p = positions(&mesh, seed);
        let r = Refinement::new(&topo, scheme.clone(), &Options::default(), 1).unwrap();
        let table = LimitStencilTable::at_level(&r, 1).unwrap();
        for row in 0..table.num_rows() {
            let sum = |t: &subd_schemes::StencilTable| t.row(row).1.iter().sum::<f64>();
            prop_assert!((sum(&table.position) - 1.0).abs() < 1e-12);
            prop_assert!(sum(&table.tangent1).abs() < 1e-10);
            prop_assert!(sum(&table.tangent2).abs() < 1e-10);
        }
        let level1 = r.refine_points(&p).pop().unwrap();
        let a = table.apply(&level1);
        let mapped: Vec<DVec3> = level1.iter().map(|&x| affine(x)).collect();
        let b = table.apply(&mapped);
        for (x, y) in a.positions.iter().zip(&b.positions) {
            prop_assert!((affine(*x) - *y).length() < 1e-11);
        }
        // Exact evaluation commutes with the same map, wherever it is covered.
        let ev = LimitEvaluator::new(&topo, &scheme, &Options::default()).unwrap();
        let (pa, pb) = (ev.prepare(&p), ev.prepare(&p.iter().map(|&x| affine(x)).collect::<Vec<_>>()));
        for f in 0..topo.num_faces() {
            for (u, v) in [(0.3, 0.2), (0.05, 0.01), (0.0, 0.0)] {
                let at = FaceParam { face: f, sub: 0, u, v };
                if let (Ok(x), Ok(y)) = (ev.evaluate(&pa, at), ev.evaluate(&pb, at)) {
                    prop_assert!((affine(x.position) - y.position).length() < 1e-11);
                }
            }
        }
    }
}
