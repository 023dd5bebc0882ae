//! OBJ read + topology build throughput on a 1M-face mesh (a 1000 x 1000 quad torus with
//! full-precision coordinates), reported in bytes/s and faces/s; and the topology build alone.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use subd_io::{Format, ReadOptions, WriteOptions, encode_mesh, parse_mesh};
use subd_mesh::{DVec3, Mesh, TopologyBuilder};

const N: u32 = 1000;

fn torus() -> (Vec<u32>, Vec<u32>, Vec<DVec3>) {
    let id = |i: u32, j: u32| (i % N) * N + (j % N);
    let mut idx = Vec::with_capacity((4 * N * N) as usize);
    for i in 0..N {
        for j in 0..N {
            idx.extend_from_slice(&[id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let tau = std::f64::consts::TAU;
    let pos = (0..N * N)
        .map(|k| {
            let (u, v) = (
                (k / N) as f64 * tau / N as f64,
                (k % N) as f64 * tau / N as f64,
            );
            DVec3::new(
                (3.0 + v.cos()) * u.cos(),
                (3.0 + v.cos()) * u.sin(),
                v.sin(),
            )
        })
        .collect();
    (vec![4; (N * N) as usize], idx, pos)
}

fn bench(c: &mut Criterion) {
    let (sizes, idx, pos) = torus();
    let faces = sizes.len() as u64;
    let topo = TopologyBuilder::new(pos.len()).build(&sizes, &idx).unwrap();
    let mesh = Mesh::new(topo, pos.clone()).unwrap();
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
