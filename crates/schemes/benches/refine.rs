//! Criterion benches: topology refinement (levels 1-2 of a 25k-face quad torus), stencil
//! table construction, stencil application and direct point evaluation.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use subd_schemes::{Options, Refinement, Scheme};

fn bench(c: &mut Criterion) {
    let mesh = subd_mesh::primitives::torus(160, 160, 3.0, 1.0);
    let (t, pos) = (mesh.topology, mesh.positions);
    let opts = Options::default();
    let mut g = c.benchmark_group("catmull_clark_25k_faces");
    g.sample_size(10);
    for levels in [1usize, 2] {
        g.throughput(Throughput::Elements(
            (t.num_faces() * 4usize.pow(levels as u32)) as u64,
        ));
        g.bench_function(format!("topology_level{levels}"), |b| {
            b.iter(|| Refinement::new(black_box(&t), Scheme::CatmullClark, &opts, levels).unwrap())
        });
    }
    let r = Refinement::new(&t, Scheme::CatmullClark, &opts, 2).unwrap();
    g.throughput(Throughput::Elements(r.num_vertices(2) as u64));
    g.bench_function("points_level2", |b| {
        b.iter(|| r.refine_points(black_box(&pos)))
    });
    g.bench_function("stencils_level2", |b| {
        b.iter(|| {
            Refinement::new(&t, Scheme::CatmullClark, &opts, 2)
                .unwrap()
                .composed(2)
        })
    });
    let table = r.composed(2);
    let src: Vec<f64> = pos.iter().flat_map(|p| p.to_array()).collect();
    let mut dst = vec![0.0; 3 * table.num_rows()];
    g.bench_function("apply_composed_level2", |b| {
        b.iter(|| table.apply(black_box(&src), 3, &mut dst))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
