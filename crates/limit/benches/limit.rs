//! Criterion benches: limit stencil tables (build and application) and exact evaluation
//! throughput, on a regular 25.6k-quad torus and on a cube refined three levels (eight
//! valence-3 vertices, so a third of its faces take Stam's evaluation).

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use subd_limit::LimitStencilTable;
use subd_limit::eval::{FaceParam, LimitEvaluator};
use subd_mesh::{DVec3, Topology, TopologyBuilder};
use subd_schemes::{Options, Refinement, Scheme};

/// A cube refined `levels` times, as a base mesh.
fn cube(levels: usize) -> (Topology, Vec<DVec3>) {
    let faces = [
        0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4,
    ];
    let topo = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
    let s = [
        (-1., -1., 1.),
        (1., -1., 1.),
        (-1., 1., 1.),
        (1., 1., 1.),
        (-1., 1., -1.),
        (1., 1., -1.),
        (-1., -1., -1.),
        (1., -1., -1.),
    ];
    let p: Vec<DVec3> = s.iter().map(|&(x, y, z)| DVec3::new(x, y, z)).collect();
    let r = Refinement::new(&topo, Scheme::CatmullClark, &Options::default(), levels).unwrap();
    let pts = r.refine_points(&p).pop().unwrap();
    (r.into_topology(levels), pts)
}

/// `count` pseudo-random points on a quad mesh of `faces` faces.
fn params(faces: usize, count: usize) -> Vec<FaceParam> {
    let mut x: u64 = 12345;
    let mut next = || {
        x = x
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (x >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..count)
        .map(|_| FaceParam {
            face: ((next() * faces as f64) as usize).min(faces - 1),
            sub: 0,
            u: next(),
            v: next(),
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let torus = subd_mesh::primitives::torus(160, 160, 3.0, 1.0);
    let opts = Options::default();
    let mut g = c.benchmark_group("limit");
    g.sample_size(10);
    let r = Refinement::new(&torus.topology, Scheme::CatmullClark, &opts, 0).unwrap();
    g.throughput(Throughput::Elements(torus.topology.num_vertices() as u64));
    g.bench_function("stencils_build_torus_25k", |b| {
        b.iter(|| LimitStencilTable::at_level(black_box(&r), 0).unwrap())
    });
    let table = LimitStencilTable::at_level(&r, 0).unwrap();
    g.bench_function("stencils_apply_torus_25k", |b| {
        b.iter(|| table.apply(black_box(&torus.positions)))
    });
    for (name, topo, pts) in [
        ("torus_25k", torus.topology.clone(), torus.positions.clone()),
        ("cube_level3", cube(3).0, cube(3).1),
    ] {
        let ev = LimitEvaluator::new(&topo, &Scheme::CatmullClark, &opts).unwrap();
        let pp = ev.prepare(&pts);
        let at = params(topo.num_faces(), 10_000);
        g.throughput(Throughput::Elements(at.len() as u64));
        g.bench_function(format!("evaluate_{name}"), |b| {
            b.iter(|| {
                at.iter()
                    .map(|&p| ev.evaluate(&pp, p).unwrap().position.x)
                    .sum::<f64>()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
