//! Criterion benches: PIA on a closed quad torus with extraordinary vertices, each solver
//! to 1e-10 of the bounding-box diagonal.

use criterion::{Criterion, criterion_group, criterion_main};
use subd_mesh::{DVec3, Topology, TopologyBuilder};
use subd_pia::{Moving, Pia, PiaOptions, PiaScheme, Solver};
use subd_schemes::Options;

/// An `nu × nv` quad torus, bumped so the targets are not a trivial surface.
fn torus(nu: u32, nv: u32) -> (Topology, Vec<DVec3>) {
    let mut faces = Vec::new();
    for j in 0..nv {
        for i in 0..nu {
            let v = |a: u32, b: u32| (b % nv) * nu + (a % nu);
            faces.extend([v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    let topo = TopologyBuilder::new((nu * nv) as usize)
        .build(&vec![4; (nu * nv) as usize], &faces)
        .expect("a torus");
    let points = (0..nu * nv)
        .map(|k| {
            let (a, b) = ((k % nu) as f64, (k / nu) as f64);
            let (u, v) = (
                a / nu as f64 * std::f64::consts::TAU,
                b / nv as f64 * std::f64::consts::TAU,
            );
            let r = 1.0 + 0.05 * (7.0 * u).sin() * (5.0 * v).cos();
            DVec3::new(
                (3.0 + r * v.cos()) * u.cos(),
                (3.0 + r * v.cos()) * u.sin(),
                r * v.sin(),
            )
        })
        .collect();
    (topo, points)
}

fn bench(c: &mut Criterion) {
    let (topo, targets) = torus(200, 100);
    let pia = Pia::new(&topo, &PiaScheme::CatmullClark, &Options::default()).expect("limit");
    let mut g = c.benchmark_group("pia_torus_20k");
    g.sample_size(10);
    for (name, solver) in [
        ("iterate", Solver::Iterate),
        ("weighted", Solver::Weighted),
        ("cg", Solver::Cg),
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
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
