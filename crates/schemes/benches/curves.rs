//! Criterion benches: 8 levels of every curve scheme on a 10,000-point closed curve (for the
//! ternary schemes that is 65.6 M points), reported as output points per second.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::{DVec2, DVec3};
use subd_schemes::curve::{CircleScheme, CurveScheme, PointNormal};

fn bench(c: &mut Criterion) {
    let n = 10_000;
    let pts: Vec<DVec3> = (0..n)
        .map(|i| {
            let t = i as f64 / n as f64 * std::f64::consts::TAU;
            let r = 1.0 + 0.2 * (7.0 * t).sin();
            DVec3::new(r * t.cos(), r * t.sin(), 0.0)
        })
        .collect();
    let mut g = c.benchmark_group("curve_10k_closed");
    g.sample_size(10);
    let linear = [
        ("chaikin", CurveScheme::Chaikin, 8),
        ("bspline4", CurveScheme::BSpline { order: 4 }, 8),
        (
            "four_point",
            CurveScheme::FourPoint { omega: 1.0 / 16.0 },
            8,
        ),
        (
            "four_point_2p",
            CurveScheme::FourPoint2 {
                omega: 1.0 / 16.0,
                mu: 0.05,
            },
            8,
        ),
        ("ternary_3pt", CurveScheme::Ternary3 { omega: 0.25 }, 8),
        ("tension", CurveScheme::Tension { alpha0: 0.5 }, 8),
        ("circle_preserving", CurveScheme::CirclePreserving, 8),
        ("variational", CurveScheme::Variational, 8),
    ];
    for (name, scheme, levels) in linear {
        let out = scheme
            .subdivide(&pts, true, levels)
            .expect("subdivide")
            .len();
        g.throughput(Throughput::Elements(out as u64));
        g.bench_function(format!("{name}_{levels}_levels"), |b| {
            b.iter(|| scheme.subdivide(&pts, true, levels).expect("subdivide"))
        });
    }
    let pn: Vec<PointNormal> = pts
        .iter()
        .map(|p| PointNormal {
            p: p.truncate(),
            n: p.truncate().normalize_or(DVec2::X),
        })
        .collect();
    for (name, scheme, levels) in [
        (
            "circle_four_point",
            CircleScheme::FourPoint {
                omega: 1.0 / 16.0,
                mu: 0.0,
            },
            8,
        ),
        ("circle_ternary", CircleScheme::Ternary { omega: 0.25 }, 8),
    ] {
        let out = scheme
            .subdivide(&pn, true, levels)
            .expect("subdivide")
            .len();
        g.throughput(Throughput::Elements(out as u64));
        g.bench_function(format!("{name}_{levels}_levels"), |b| {
            b.iter(|| scheme.subdivide(&pn, true, levels).expect("subdivide"))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
