//! Criterion benches of subd-editing: least squares, the exact energy method over a region,
//! and the editor's re-solve, on a closed 40 × 40 torus with 8 constraints.

use std::sync::Arc;

use criterion::{Criterion, criterion_group, criterion_main};
use subd_editing::{Constraint, Editor, EnergyOptions, Goal, Location, Method};
use subd_limit::eval::{FaceParam, LimitEvaluator};
use subd_mesh::DVec3;
use subd_schemes::{Options, Scheme};

fn constraints(nf: usize) -> Vec<Constraint> {
    (0..8)
        .map(|k| {
            let at = Location::Face(FaceParam {
                face: (k * 197) % nf,
                sub: 0,
                u: 0.4,
                v: 0.6,
            });
            if k % 4 == 3 {
                Constraint::Normal {
                    at,
                    normal: DVec3::new(0.1, 0.2, 1.0),
                }
            } else {
                Constraint::Point {
                    at,
                    goal: Goal::Displacement(DVec3::new(0.0, 0.0, 0.05)),
                }
            }
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let m = subd_mesh::primitives::torus(40, 40, 3.0, 1.0);
    let ev = Arc::new(
        LimitEvaluator::new(&m.topology, &Scheme::CatmullClark, &Options::default()).unwrap(),
    );
    let cs = constraints(m.topology.num_faces());
    let energy = Method::Energy {
        penalty: None,
        region_rings: Some(3),
        energy: EnergyOptions::default(),
    };
    let mut g = c.benchmark_group("editing");
    for (name, method) in [
        ("least_squares", Method::LeastSquares),
        ("energy_3_rings", energy),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| {
                let ed = Editor::with_evaluator(
                    ev.clone(),
                    &m.topology,
                    &m.positions,
                    &Scheme::CatmullClark,
                    &cs,
                    method,
                )
                .unwrap();
                ed.solve(&cs).unwrap()
            })
        });
    }
    let ed = Editor::with_evaluator(
        ev.clone(),
        &m.topology,
        &m.positions,
        &Scheme::CatmullClark,
        &cs,
        energy,
    )
    .unwrap();
    g.bench_function("editor_resolve", |b| b.iter(|| ed.solve(&cs).unwrap()));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
