//! OBJ read + topology build throughput on a 1M-face mesh (a 1000 x 1000 quad torus with
//! full-precision coordinates), reported in bytes/s and faces/s; and the topology build alone.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use subd_io::{Format, ReadOptions, WriteOptions, encode_mesh, parse_mesh};
use subd_mesh::TopologyBuilder;

const N: u32 = 1000;

fn bench(c: &mut Criterion) {
    let mesh = subd_mesh::primitives::torus(N, N, 3.0, 1.0);
    let faces = mesh.topology.num_faces() as u64;
    let sizes: Vec<u32> = mesh.topology.face_sizes().collect();
    let idx = mesh.topology.all_face_vertices().to_vec();
    let pos = mesh.positions.clone();
    let mut obj = Vec::new();
    encode_mesh(&mut obj, &mesh, Format::Obj, &WriteOptions::default()).unwrap();
    let opts = ReadOptions::default();

    let mut g = c.benchmark_group("obj_read_build_1M_faces");
    g.sample_size(10);
    g.throughput(Throughput::Bytes(obj.len() as u64));
    g.bench_function("bytes", |b| {
        b.iter(|| parse_mesh(black_box(&obj), Format::Obj, &opts).unwrap())
    });
    g.throughput(Throughput::Elements(faces));
    g.bench_function("faces", |b| {
        b.iter(|| parse_mesh(black_box(&obj), Format::Obj, &opts).unwrap())
    });
    g.finish();

    let mut g = c.benchmark_group("topology_build_1M_faces");
    g.sample_size(10);
    g.throughput(Throughput::Elements(faces));
    g.bench_function("faces", |b| {
        b.iter(|| {
            TopologyBuilder::new(pos.len())
                .build(black_box(&sizes), black_box(&idx))
                .unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
