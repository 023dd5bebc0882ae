//! Criterion benches of adaptive refinement: the hierarchy plus the conforming mesh on a
//! 25.6k-quad torus with hexagons (Catmull-Clark, flatness) and on its triangulation (Loop),
//! beside uniform refinement of the same mesh to the same level.

use criterion::{Criterion, criterion_group, criterion_main};
use subd_adaptive::{AdaptiveRefinement, Flatness, Positions};
use subd_mesh::{Mesh, TopologyBuilder};
use subd_schemes::{Options, Refinement, Scheme};

fn triangulated(m: &Mesh) -> Mesh {
    let t = &m.topology;
    let mut idx = Vec::new();
    let mut sizes = Vec::new();
    for f in 0..t.num_faces() {
        let v = t.face_vertices(f);
        for i in 1..v.len() - 1 {
            idx.extend_from_slice(&[v[0], v[i], v[i + 1]]);
            sizes.push(3);
        }
    }
    let topo = TopologyBuilder::new(t.num_vertices())
        .build(&sizes, &idx)
        .expect("valid");
    Mesh::new(topo, m.positions.clone()).expect("finite")
}

fn bench(c: &mut Criterion) {
    let quads = subd_mesh::primitives::torus_with_hexagons(160, 160, 8, 3.0, 1.0);
    let tris = triangulated(&quads);
    let o = Options::default();
    let flat = Flatness::new(2.0).expect("threshold");
    let mut g = c.benchmark_group("adaptive");
    g.sample_size(10);
    for (name, scheme, m) in [
        ("catmark", Scheme::CatmullClark, &quads),
        ("loop", Scheme::Loop, &tris),
    ] {
        g.bench_function(format!("{name}_flatness_level3"), |b| {
            b.iter(|| {
                let a =
                    AdaptiveRefinement::new(&m.topology, &m.positions, &scheme, &o, &[&flat], 3)
                        .expect("adaptive");
                a.mesh(Positions::Refined).expect("mesh").num_faces()
            })
        });
        g.bench_function(format!("{name}_uniform_level3"), |b| {
            b.iter(|| {
                let r = Refinement::new(&m.topology, scheme.clone(), &o, 3).expect("refine");
                r.refine_points(&m.positions).len()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
