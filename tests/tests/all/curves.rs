//! Subdivision curves and mask analysis: the numbers of seeds 001 and 004, each checked
//! against a closed form (polynomials, circles, the papers' norm formulas).

use glam::{DVec2, DVec3};
use std::f64::consts::TAU;
use subd_schemes::analysis::analyze;
use subd_schemes::curve::{CircleScheme, CurveScheme, PointNormal, circle_average};

/// Samples of `f` at the integers 0..n as an open polyline (y = f(x)).
fn graph(n: usize, f: impl Fn(f64) -> f64) -> Vec<DVec3> {
    (0..n)
        .map(|i| DVec3::new(i as f64, f(i as f64), 0.0))
        .collect()
}

/// Largest |y − f(x)| over the points with x in [lo, hi].
fn deviation(points: &[DVec3], f: impl Fn(f64) -> f64, lo: f64, hi: f64) -> f64 {
    points
        .iter()
        .filter(|p| p.x >= lo && p.x <= hi)
        .map(|p| (p.y - f(p.x)).abs())
        .fold(0.0, f64::max)
}

#[test]
fn linear_schemes_reproduce_the_polynomials_they_should() {
    let cubic = |x: f64| 0.01 * x * x * x - 0.2 * x * x + x;
    let quad = |x: f64| 0.05 * x * x - x;
    let line = |x: f64| 0.5 * x + 2.0;
    let (n, lo, hi) = (24, 6.0, 17.0);
    let case = |s: CurveScheme, f: &dyn Fn(f64) -> f64, levels: usize| {
        let out = s.subdivide(&graph(n, f), false, levels).unwrap();
        deviation(&out, f, lo, hi)
    };
    // Every scheme reproduces straight lines everywhere, ends included.
    for s in [
        CurveScheme::Chaikin,
        CurveScheme::BSpline { order: 5 },
        CurveScheme::FourPoint { omega: 0.1 },
        CurveScheme::FourPoint2 {
            omega: 0.05,
            mu: 0.1,
        },
        CurveScheme::Ternary3 { omega: 0.3 },
        CurveScheme::Tension { alpha0: 0.3 },
        CurveScheme::Variational,
    ] {
        let out = s.subdivide(&graph(n, line), false, 3).unwrap();
        assert!(deviation(&out, line, -1.0, 100.0) < 1e-12, "{s:?}");
        // Open curves keep their end points.
        assert_eq!(out[0], DVec3::new(0.0, line(0.0), 0.0), "{s:?}");
        assert!(
            (out[out.len() - 1] - DVec3::new((n - 1) as f64, line((n - 1) as f64), 0.0)).length()
                < 1e-12,
            "{s:?}"
        );
    }
    // Interpolatory 4-point (ω = 1/16), variational: cubics; other ω: not quadratics.
    assert!(case(CurveScheme::FourPoint { omega: 1.0 / 16.0 }, &cubic, 3) < 1e-12);
    // The variational scheme's end rows reach into the curve with weights decaying like
    // (3 − 2√2)^k: check well inside a longer polygon.
    let out = CurveScheme::Variational
        .subdivide(&graph(80, cubic), false, 3)
        .unwrap();
    assert!(deviation(&out, cubic, 30.0, 50.0) < 1e-9 * cubic(80.0).abs());
    assert!(case(CurveScheme::FourPoint { omega: 0.1 }, &quad, 1) > 1e-3);
    // Ternary: quadratics exactly at ω = 2/9, not elsewhere.
    assert!(case(CurveScheme::Ternary3 { omega: 2.0 / 9.0 }, &quad, 3) < 1e-12);
    assert!(case(CurveScheme::Ternary3 { omega: 0.3 }, &quad, 1) > 1e-3);
    // B-splines and the displaced 4-point reproduce no more than lines.
    assert!(case(CurveScheme::BSpline { order: 4 }, &quad, 1) > 1e-3);
    assert!(
        case(
            CurveScheme::FourPoint2 {
                omega: 1.0 / 16.0,
                mu: 0.05
            },
            &quad,
            1
        ) > 1e-3
    );
}

#[test]
fn lane_riesenfeld_masks_and_chaikin() {
    // Order k: 2^{-(k-1)} C(k, j), one old point's weights summing to 2.
    let m = CurveScheme::BSpline { order: 4 }.mask(1).unwrap();
    assert_eq!(m.coeffs, [0.125, 0.5, 0.75, 0.5, 0.125]);
    // Chaikin: the quarter points of every edge of a closed square.
    let sq = [DVec3::ZERO, DVec3::X, DVec3::X + DVec3::Y, DVec3::Y];
    let out = CurveScheme::Chaikin.subdivide(&sq, true, 1).unwrap();
    assert_eq!(out.len(), 8);
    for (a, b) in sq.iter().zip(sq.iter().cycle().skip(1)) {
        for t in [0.25, 0.75] {
            let q = *a + t * (*b - *a);
            assert!(out.iter().any(|p| (*p - q).length() < 1e-15), "{q}");
        }
    }
    // The tension scheme with α₀ = 1 is the cubic B-spline.
    let pts: Vec<DVec3> = (0..7)
        .map(|i| DVec3::new(i as f64, ((i * i) % 5) as f64, 0.0))
        .collect();
    let a = CurveScheme::Tension { alpha0: 1.0 }
        .subdivide(&pts, true, 3)
        .unwrap();
    let b = CurveScheme::BSpline { order: 4 }
        .subdivide(&pts, true, 3)
        .unwrap();
    assert_eq!(a.len(), b.len());
    for (p, q) in a.iter().zip(&b) {
        assert!((*p - *q).length() < 1e-14);
    }
}

fn ngon(n: usize) -> Vec<DVec3> {
    (0..n)
        .map(|i| {
            let a = i as f64 * TAU / n as f64;
            DVec3::new(a.cos(), a.sin(), 0.0)
        })
        .collect()
}

fn radius_spread(points: &[DVec3]) -> f64 {
    let (lo, hi) = points.iter().fold((f64::MAX, 0.0f64), |(lo, hi), p| {
        let r = p.truncate().length();
        (lo.min(r), hi.max(r))
    });
    hi - lo
}

#[test]
fn tension_scheme_keeps_a_regular_polygon_on_a_circle() {
    // On z^j (z = e^{iθ}) the rules give a copy of e^{ijθ/2} scaled by
    // (2cos θ + 2 + 4α)/(4 + 4α) (even) and cos(θ/2) (odd): equal iff α = cos(θ/2). With
    // α₀ = cos(2π/N) the first step's α₁ = sqrt((1 + α₀)/2) = cos(π/N) is exactly that.
    for n in [3, 5, 6, 12] {
        let out = CurveScheme::Tension {
            alpha0: (TAU / n as f64).cos(),
        }
        .subdivide(&ngon(n), true, 8)
        .unwrap();
        assert_eq!(out.len(), n << 8);
        assert!(
            radius_spread(&out) < 1e-12,
            "N = {n}: {}",
            radius_spread(&out)
        );
        // The cubic B-spline does not.
        let bs = CurveScheme::BSpline { order: 4 }
            .subdivide(&ngon(n), true, 8)
            .unwrap();
        assert!(radius_spread(&bs) > 1e-4);
    }
}

fn circle_samples(n: usize, r: f64, c: DVec2, arc: f64) -> Vec<PointNormal> {
    (0..n)
        .map(|i| {
            let a = 0.3 + i as f64 * arc / n as f64;
            let d = DVec2::new(a.cos(), a.sin());
            PointNormal { p: c + r * d, n: d }
        })
        .collect()
}

#[test]
fn circle_average_schemes_reproduce_circles_and_linear_ones_do_not() {
    let (r, c) = (2.5, DVec2::new(1.0, -3.0));
    let on_circle = |pts: &[PointNormal]| {
        pts.iter()
            .map(|q| {
                ((q.p - c).length() - r)
                    .abs()
                    .max((q.n - (q.p - c) / r).length())
            })
            .fold(0.0, f64::max)
    };
    let closed = circle_samples(7, r, c, TAU);
    for scheme in [
        CircleScheme::FourPoint {
            omega: 1.0 / 16.0,
            mu: 0.0,
        },
        CircleScheme::FourPoint {
            omega: 0.1,
            mu: 0.08,
        },
        CircleScheme::Ternary { omega: 0.25 },
    ] {
        // 8 levels: 1,792 points (4-point), 45,927 (ternary).
        let out = scheme.subdivide(&closed, true, 8).unwrap();
        assert!(on_circle(&out) < 1e-12, "{scheme:?}: {}", on_circle(&out));
        // An open arc too (mirrored continuation at the ends).
        let arc = circle_samples(6, r, c, 2.0);
        let out = scheme.subdivide(&arc, false, 5).unwrap();
        assert!(
            on_circle(&out) < 1e-12,
            "{scheme:?} open: {}",
            on_circle(&out)
        );
    }
    // Interpolation: μ = 0 and the ternary scheme keep the old points.
    let out = CircleScheme::FourPoint {
        omega: 1.0 / 16.0,
        mu: 0.0,
    }
    .subdivide(&closed, true, 1)
    .unwrap();
    for (i, q) in closed.iter().enumerate() {
        assert_eq!(out[2 * i].p, q.p);
    }
    let out = CircleScheme::Ternary { omega: 0.25 }
        .subdivide(&closed, true, 1)
        .unwrap();
    for (i, q) in closed.iter().enumerate() {
        assert_eq!(out[3 * i].p, q.p);
    }
    // The linear schemes with the same masks shrink the circle.
    let pts: Vec<DVec3> = closed.iter().map(|q| q.p.extend(0.0)).collect();
    for s in [
        CurveScheme::FourPoint2 {
            omega: 1.0 / 16.0,
            mu: 0.0,
        },
        CurveScheme::Ternary3 { omega: 0.25 },
    ] {
        let out = s.subdivide(&pts, true, 6).unwrap();
        let worst = out
            .iter()
            .map(|p| ((p.truncate() - c).length() - r).abs())
            .fold(0.0, f64::max);
        assert!(worst > 1e-3, "{s:?}: {worst}");
    }
}

#[test]
fn circle_average_is_the_linear_average_on_straight_data_and_stays_on_the_circle() {
    let n = DVec2::Y;
    let a = PointNormal {
        p: DVec2::new(0.0, 0.0),
        n,
    };
    let b = PointNormal {
        p: DVec2::new(2.0, 0.0),
        n,
    };
    for w in [-0.5, 0.0, 0.3, 1.0, 1.5] {
        let m = circle_average(a, b, w);
        assert!((m.p - DVec2::new(2.0 * w, 0.0)).length() < 1e-15);
        assert!((m.n - n).length() < 1e-15);
    }
    // Midpoint of a quarter circle: the chord midpoint pushed out by (|p1 − p0|/2)·tan(θ/4).
    let a = PointNormal {
        p: DVec2::X,
        n: DVec2::X,
    };
    let b = PointNormal {
        p: DVec2::Y,
        n: DVec2::Y,
    };
    let m = circle_average(a, b, 0.5);
    let s = std::f64::consts::FRAC_1_SQRT_2;
    assert!((m.p - DVec2::new(s, s)).length() < 1e-15);
    let chord = 2f64.sqrt();
    let push = (m.p - DVec2::splat(0.5)).length();
    assert!((push - chord / 2.0 * (std::f64::consts::FRAC_PI_2 / 4.0).tan()).abs() < 1e-15);
}

fn ternary_mask(w: f64) -> Vec<f64> {
    let (a, b) = (w - 1.0 / 3.0, 4.0 / 3.0 - 2.0 * w);
    vec![a, 0.0, w, b, 1.0, b, w, 0.0, a]
}

#[test]
fn ternary_scheme_is_c1_exactly_on_two_ninths_to_one_third() {
    for (w, c1) in [
        (0.18, false),
        (0.2, false),
        (0.22, false),
        (0.23, true),
        (0.25, true),
        (0.3, true),
        (0.33, true),
    ] {
        let v = analyze(&ternary_mask(w), 3, 1).unwrap();
        assert!(v.converges, "ω = {w}: {v:?}");
        assert_eq!(v.smoothness >= Some(1), c1, "ω = {w}: {v:?}");
    }
    // Not shown convergent below 1/6.
    for w in [0.1, 0.16] {
        assert!(
            !analyze(&ternary_mask(w), 3, 1).unwrap().converges,
            "ω = {w}"
        );
    }
}

#[test]
fn two_parameter_four_point_c1_norm_is_the_papers_formula() {
    for (w, mu) in [
        (1.0 / 16.0, 0.0),
        (0.05, 0.02),
        (0.1, -0.05),
        (0.02, 0.1),
        (-0.03, 0.2),
    ] {
        let h = 0.5 + w;
        let mask = [-w, mu, h, 1.0 - 2.0 * mu, h, mu, -w];
        let v = analyze(&mask, 2, 1).unwrap();
        let want = f64::max(
            4.0 * (mu + 2.0 * w).abs(),
            4.0 * w + (1.0 - 4.0 * mu - 4.0 * w).abs(),
        );
        assert!(v.norms.len() >= 2, "ω = {w}, μ = {mu}: {v:?}");
        assert!(
            (v.norms[1][0] - want).abs() < 1e-14,
            "ω = {w}, μ = {mu}: {} vs {want}",
            v.norms[1][0]
        );
    }
}

#[test]
fn bad_parameters_are_typed_errors() {
    let p = ngon(5);
    assert!(
        CurveScheme::BSpline { order: 1 }
            .subdivide(&p, true, 1)
            .is_err()
    );
    assert!(
        CurveScheme::FourPoint { omega: f64::NAN }
            .subdivide(&p, true, 1)
            .is_err()
    );
    assert!(
        CurveScheme::Tension { alpha0: -2.0 }
            .subdivide(&p, true, 1)
            .is_err()
    );
    assert!(CurveScheme::Chaikin.subdivide(&p[..2], true, 1).is_err());
    assert!(CurveScheme::Chaikin.subdivide(&p[..1], false, 1).is_err());
    assert!(CurveScheme::Chaikin.subdivide(&p, true, 40).is_err());
    let mut q = p.clone();
    q[2].x = f64::INFINITY;
    assert!(CurveScheme::Chaikin.subdivide(&q, true, 1).is_err());
    let pn = circle_samples(4, 1.0, DVec2::ZERO, TAU);
    assert!(
        CircleScheme::Ternary { omega: 1.0 }
            .subdivide(&pn, true, 1)
            .is_err()
    );
}

#[test]
fn sabin_dodgson_preserves_circles_and_matches_an_independent_implementation() {
    // Uneven samples of a circle, closed and open: every new point stays on it.
    let (r, c) = (1.7, DVec3::new(0.5, -1.0, 0.0));
    let angles = [0.0, 0.4, 1.1, 1.5, 2.6, 3.0, 4.1, 5.2];
    let pts: Vec<DVec3> = angles
        .iter()
        .map(|&a| c + r * DVec3::new(f64::cos(a), f64::sin(a), 0.0))
        .collect();
    for closed in [true, false] {
        let out = CurveScheme::CirclePreserving
            .subdivide(&pts, closed, 6)
            .unwrap();
        let worst = out
            .iter()
            .map(|p| ((*p - c).length() - r).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-12, "closed {closed}: {worst}");
        // Interpolatory.
        for (i, p) in pts.iter().enumerate() {
            assert_eq!(out[64 * i], *p);
        }
    }
    // Clockwise order too.
    let rev: Vec<DVec3> = pts.iter().rev().copied().collect();
    let out = CurveScheme::CirclePreserving
        .subdivide(&rev, true, 4)
        .unwrap();
    assert!(out.iter().all(|p| ((*p - c).length() - r).abs() < 1e-12));
    // The new point between b and c of four crafted points, as the `sophus` library's
    // implementation of the same paper computes it (DodgsonSabinHelperTest).
    let q = [(1.0, 1.1), (2.2, 0.5), (3.0, 1.5), (3.5, 2.9)].map(|(x, y)| DVec3::new(x, y, 0.0));
    let out = CurveScheme::CirclePreserving
        .subdivide(&q, false, 1)
        .unwrap();
    assert!(
        (out[3] - DVec3::new(2.64619661516195, 0.8388990046231528, 0.0)).length() < 1e-13,
        "{}",
        out[3]
    );
    // Straight data stays straight; 3D data is refused.
    let line: Vec<DVec3> = (0..5)
        .map(|i| DVec3::new(i as f64, 2.0 * i as f64, 0.0))
        .collect();
    let out = CurveScheme::CirclePreserving
        .subdivide(&line, false, 3)
        .unwrap();
    assert!(out.iter().all(|p| (p.y - 2.0 * p.x).abs() < 1e-12));
    assert!(
        CurveScheme::CirclePreserving
            .subdivide(&[DVec3::Z, DVec3::X, DVec3::Y], false, 1)
            .is_err()
    );
}
