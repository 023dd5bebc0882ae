//! Criterion benches: global PIA to 1e-10 of the bounding-box diagonal on the 101,600-quad
//! closed torus of `cargo xtask bench` (valence-3 and valence-6 vertices), each solver on a
//! prepared `Pia`, and the default solver cold (a fresh `Pia` per solve).

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use subd_mesh::{DVec3, Topology, TopologyBuilder};
use subd_pia::{Moving, Pia, PiaOptions, PiaScheme, Solver};
use subd_schemes::{Options, Refinement, Scheme};

/// A 160 × 160 torus grid in which every 8th quad pair is merged into a hexagon, refined
/// once with Catmull-Clark: 101,600 quads, 800 valence-3 and 400 valence-6 vertices (the
/// construction of `xtask/src/bench.rs`).
fn torus() -> (Topology, Vec<DVec3>) {
    let (m, n) = (160u32, 160u32);
    let id = |i: u32, j: u32| (i % m) * n + (j % n);
    let positions = subd_mesh::primitives::torus(m, n, 3.0, 1.0).positions;
    let (mut sizes, mut idx) = (Vec::new(), Vec::new());
    for i in 0..m {
        let mut j = 0;
        while j < n {
            if i % 8 == 0 && j % 8 == 0 {
                idx.extend([
                    id(i, j),
                    id(i + 1, j),
                    id(i + 1, j + 1),
                    id(i + 1, j + 2),
                    id(i, j + 2),
                    id(i, j + 1),
                ]);
                sizes.push(6);
                j += 2;
            } else {
                idx.extend([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
                sizes.push(4);
                j += 1;
            }
        }
    }
    let base = TopologyBuilder::new(positions.len())
        .build(&sizes, &idx)
        .expect("a torus");
    let r = Refinement::new(&base, Scheme::CatmullClark, &Options::default(), 1).expect("refine");
    let points = r.refine_points(&positions).pop().expect("level 1");
    (r.into_topology(1), points)
}

fn bench(c: &mut Criterion) {
    let (topo, targets) = torus();
    let new = || Pia::new(&topo, &PiaScheme::CatmullClark, &Options::default()).expect("limit");
    let pia = new();
    assert!(pia.prepare(), "the torus has the Chebyshev operator");
    let mut g = c.benchmark_group("pia_torus_101k");
    g.sample_size(10);
    for (name, solver) in [
        ("iterate", Solver::Iterate),
        ("weighted", Solver::Weighted),
        ("cg", Solver::Cg),
        ("chebyshev", Solver::Chebyshev),
        ("direct", Solver::Direct),
        ("auto", Solver::Auto),
    ] {
        let options = PiaOptions {
            solver,
            ..PiaOptions::default()
        };
        g.bench_function(name, |b| {
            b.iter(|| pia.solve(&targets, &Moving::All, &options).expect("solve"))
        });
    }
    // One solve on a fresh `Pia` (its limit stencils built outside the timing): what
    // `subd pia` does.
    g.bench_function("auto_cold", |b| {
        b.iter_batched(
            new,
            |pia| {
                pia.solve(&targets, &Moving::All, &PiaOptions::default())
                    .expect("solve")
            },
            BatchSize::PerIteration,
        )
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
