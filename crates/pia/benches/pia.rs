//! Criterion benches: global PIA to 1e-10 of the bounding-box diagonal on the 101,600-quad
//! closed torus of `cargo xtask bench` (valence-3 and valence-6 vertices), each solver on a
//! prepared `Pia`, and the default solver cold (a fresh `Pia` per solve).

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use subd_mesh::{DVec3, Topology};
use subd_pia::{Moving, Pia, PiaOptions, Solver};
use subd_schemes::{Options, Refinement, Scheme};

/// A 160 × 160 torus grid in which every 8th quad pair is merged into a hexagon, refined
/// once with Catmull-Clark: 101,600 quads, 800 valence-3 and 400 valence-6 vertices (the
/// construction of `xtask/src/meshes/mod.rs`).
fn torus() -> (Topology, Vec<DVec3>) {
    let base = subd_mesh::primitives::torus_with_hexagons(160, 160, 8, 3.0, 1.0);
    let r = Refinement::new(&base.topology, Scheme::CatmullClark, &Options::default(), 1)
        .expect("refine");
    let points = r.refine_points(&base.positions).pop().expect("level 1");
    (r.into_topology(1), points)
}

fn bench(c: &mut Criterion) {
    let (topo, targets) = torus();
    let new = || Pia::new(&topo, &Scheme::CatmullClark, &Options::default()).expect("limit");
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
            // Returned with the result, so that freeing them is not timed (as for the
            // other solvers, whose `Pia` lives on).
            |pia| {
                let r = pia
                    .solve(&targets, &Moving::All, &PiaOptions::default())
                    .expect("solve");
                (pia, r)
            },
            BatchSize::PerIteration,
        )
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
