//! Basis functions of the regular patches and their boundary forms: the weight of each
//! control point for the position and the five derivatives (∂u, ∂v, ∂uu, ∂uv, ∂vv) at
//! `(s, t)` in the patch's own unit domain.
//!
//! **Boundaries.** A regular patch on a boundary (or, with infinitely sharp patches, along
//! a sharp edge) has no points beyond the edge; the table fills those slots with any point
//! and the basis gives them weight zero, after moving their weight onto *phantom points*
//! extrapolated from the points inside: beyond a B-spline edge row `B` with inner row `I`,
//! `P = 2B − I` (the cubic end condition that interpolates the boundary curve, OpenSubdiv's
//! `adjustBSplineBoundaryWeights`); beyond a box-spline edge, the parallelogram completion
//! `P = B₁ + B₂ − I` of the two nearest boundary points and the inner point across from them
//! (`adjustBoxSplineTriBoundaryWeights`).

use crate::evaluation::loop_patch::BoxSpline;
use crate::evaluation::patch::bspline_basis;

/// Weights for position, ∂s, ∂t, ∂ss, ∂st, ∂tt.
pub(crate) type Weights<const N: usize> = [[f64; N]; 6];

/// Bicubic B-spline weights of the 16 points (rows bottom to top) at `(s, t)`, with the
/// boundary mask's phantom points folded in (bit 0: the bottom row is missing, 1: right
/// column, 2: top row, 3: left column).
pub(crate) fn bspline(s: f64, t: f64, boundary: u8) -> Weights<16> {
    let (bs, ds, dss) = bspline_basis(s);
    let (bt, dt, dtt) = bspline_basis(t);
    let tensor =
        |a: &[f64; 4], b: &[f64; 4]| -> [f64; 16] { std::array::from_fn(|k| a[k % 4] * b[k / 4]) };
    let mut w = [
        tensor(&bs, &bt),
        tensor(&ds, &bt),
        tensor(&bs, &dt),
        tensor(&dss, &bt),
        tensor(&ds, &dt),
        tensor(&bs, &dtt),
    ];
    if boundary != 0 {
        for row in &mut w {
            fold_bspline_boundary(row, boundary);
        }
    }
    w
}

/// The (missing, boundary, inner) points, among the 16 of a B-spline patch, of the k-th
/// place along boundary side `side` (bit `side` of the boundary mask): the phantom point
/// `missing` is `2 boundary − inner`.
pub(super) fn bspline_side(side: usize, k: usize) -> (usize, usize, usize) {
    match side {
        0 => (k, k + 4, k + 8),
        1 => (4 * k + 3, 4 * k + 2, 4 * k + 1),
        2 => (k + 12, k + 8, k + 4),
        _ => (4 * k, 4 * k + 1, 4 * k + 2),
    }
}

/// Moves the weight of the missing rows and columns onto `2B − I`.
fn fold_bspline_boundary(w: &mut [f64; 16], boundary: u8) {
    for bit in 0..4 {
        if boundary & (1 << bit) == 0 {
            continue;
        }
        for k in 0..4 {
            let (m, b, i) = bspline_side(bit, k);
            let x = w[m];
            w[b] += 2.0 * x;
            w[i] -= x;
            w[m] = 0.0;
        }
    }
}

/// The corner-patch order of [`BoxSpline`] (the corner `x0`, its six neighbours
/// counter-clockwise from `x1`, three further neighbours of `x1`, two of `x2`) for each
/// point of OpenSubdiv's 12-point layout (rows {0,1,2}, {3,4,5,6}, {7,8,9}, {10,11}; the
/// triangle is 4, 5, 8).
const BOX_SPLINE_ORDER: [usize; 12] = [5, 6, 7, 4, 0, 1, 8, 3, 2, 9, 11, 10];

/// Quartic box-spline weights of the 12 points at `(s, t)` (barycentric `(1 − s − t, s, t)`),
/// with OpenSubdiv's five-bit boundary mask folded in.
pub(crate) fn box_spline(basis: &BoxSpline, s: f64, t: f64, boundary: u8) -> Weights<12> {
    let derived = basis.weights(s, t);
    let mut w = derived.map(|row| std::array::from_fn(|k| row[BOX_SPLINE_ORDER[k]]));
    if boundary != 0 {
        let (edges, vertices) = phantom_sides(boundary);
        for row in &mut w {
            fold_box_spline_boundary(row, edges, vertices);
        }
    }
    w
}

/// The boundary edges and the lone boundary vertices a five-bit triangle mask asks the
/// basis to extrapolate across: edges only (their vertices follow from them), vertices only,
/// or one edge and the vertex opposite it.
fn phantom_sides(mask: u8) -> (u8, u8) {
    let lower = mask & 7;
    match mask >> 3 {
        1 => (0, lower),
        // Edge i's opposite vertex is i + 2.
        2 => (lower, ((lower & 1) << 2) | (lower >> 1)),
        _ => (lower, 0),
    }
}

/// An interior box-spline patch's position and first derivatives at `(s, t)` from its 12
/// control points (indices into `points`, OpenSubdiv's order).
pub(crate) fn box_spline_first(
    cps: &[u32],
    points: &[glam::DVec3],
    s: f64,
    t: f64,
) -> [glam::DVec3; 3] {
    let basis = crate::evaluation::loop_patch::box_spline()
        .expect("the box-spline basis derives on a fixed grid");
    let mut corner = [glam::DVec3::ZERO; 12];
    for (k, &cp) in cps.iter().enumerate() {
        corner[BOX_SPLINE_ORDER[k]] = points[cp as usize];
    }
    let (p, du, dv) = basis.evaluate_first(&corner, s, t);
    [p, du, dv]
}

/// One phantom point: `phantom = a + b − inner`.
#[derive(Clone, Copy)]
struct Phantom {
    phantom: usize,
    a: usize,
    b: usize,
    inner: usize,
}

const fn ph(phantom: usize, a: usize, b: usize, inner: usize) -> Phantom {
    Phantom {
        phantom,
        a,
        b,
        inner,
    }
}

/// Per boundary edge of the triangle (4, 5, 8): its three phantom points, the first and
/// last in two forms, for when the neighbouring edge (previous, next) is a boundary too
/// (the phantom then mirrors through the shared corner).
struct EdgePhantoms {
    first: (Phantom, Phantom),
    middle: Phantom,
    last: (Phantom, Phantom),
    /// The edges before and after this one around the triangle.
    prev: usize,
    next: usize,
}

const EDGE_PHANTOMS: [EdgePhantoms; 3] = [
    EdgePhantoms {
        first: (ph(0, 4, 3, 7), ph(0, 4, 4, 8)),
        middle: ph(1, 4, 5, 8),
        last: (ph(2, 5, 6, 9), ph(2, 5, 5, 8)),
        prev: 2,
        next: 1,
    },
    EdgePhantoms {
        first: (ph(6, 5, 2, 1), ph(6, 5, 5, 4)),
        middle: ph(9, 5, 8, 4),
        last: (ph(11, 8, 10, 7), ph(11, 8, 8, 4)),
        prev: 0,
        next: 2,
    },
    EdgePhantoms {
        first: (ph(10, 8, 11, 9), ph(10, 8, 8, 5)),
        middle: ph(7, 8, 4, 5),
        last: (ph(3, 4, 0, 1), ph(3, 4, 4, 5)),
        prev: 1,
        next: 0,
    },
];

/// The two phantom points beyond a boundary vertex whose edges in the triangle are interior.
const VERTEX_PHANTOMS: [[Phantom; 2]; 3] = [
    [ph(3, 4, 7, 8), ph(0, 4, 1, 5)],
    [ph(2, 5, 1, 4), ph(6, 5, 9, 8)],
    [ph(11, 8, 9, 5), ph(10, 8, 7, 4)],
];

fn fold(w: &mut [f64; 12], p: Phantom) {
    let x = w[p.phantom];
    w[p.a] += x;
    w[p.b] += x;
    w[p.inner] -= x;
    w[p.phantom] = 0.0;
}

/// Moves the weight of the phantom points beyond boundary edges and vertices onto the
/// points they are extrapolated from (edges first, each edge's points in order).
fn fold_box_spline_boundary(w: &mut [f64; 12], edges: u8, vertices: u8) {
    for (e, ep) in EDGE_PHANTOMS.iter().enumerate() {
        if edges & (1 << e) == 0 {
            continue;
        }
        let prev_boundary = edges & (1 << ep.prev) != 0;
        let next_boundary = edges & (1 << ep.next) != 0;
        fold(
            w,
            if prev_boundary {
                ep.first.1
            } else {
                ep.first.0
            },
        );
        fold(w, ep.middle);
        fold(w, if next_boundary { ep.last.1 } else { ep.last.0 });
    }
    for (v, pair) in VERTEX_PHANTOMS.iter().enumerate() {
        if vertices & (1 << v) != 0 {
            fold(w, pair[0]);
            fold(w, pair[1]);
        }
    }
}

/// Bilinear weights of a quad's corners (v0 v1 v2 v3) at `(s, t)`.
pub(crate) fn bilinear(s: f64, t: f64) -> Weights<4> {
    let (a, b) = (1.0 - s, 1.0 - t);
    [
        [a * b, s * b, s * t, a * t],
        [-b, b, t, -t],
        [-a, -s, s, a],
        [0.0; 4],
        [1.0, -1.0, 1.0, -1.0],
        [0.0; 4],
    ]
}

/// Linear weights of a triangle's corners at `(s, t)`.
pub(crate) fn linear(s: f64, t: f64) -> Weights<3> {
    [
        [1.0 - s - t, s, t],
        [-1.0, 1.0, 0.0],
        [-1.0, 0.0, 1.0],
        [0.0; 3],
        [0.0; 3],
        [0.0; 3],
    ]
}

/// Cubic Bernstein polynomials at `t` and their first two derivatives.
fn bernstein(t: f64) -> ([f64; 4], [f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    (
        [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t],
        [
            -3.0 * s * s,
            9.0 * t * t - 12.0 * t + 3.0,
            -9.0 * t * t + 6.0 * t,
            3.0 * t * t,
        ],
        [6.0 * s, 18.0 * t - 12.0, -18.0 * t + 6.0, 6.0 * t],
    )
}

/// Where each of the 20 Gregory points sits in the 4 × 4 Bézier net (column, row), the
/// interior pairs `Fp`, `Fm` sharing a place; per corner `P, Ep, Em, Fp, Fm`.
const GREGORY_NET: [(usize, usize); 20] = [
    (0, 0),
    (1, 0),
    (0, 1),
    (1, 1),
    (1, 1),
    (3, 0),
    (3, 1),
    (2, 0),
    (2, 1),
    (2, 1),
    (3, 3),
    (2, 3),
    (3, 2),
    (2, 2),
    (2, 2),
    (0, 3),
    (0, 2),
    (1, 3),
    (1, 2),
    (1, 2),
];

/// The share of each corner's `Fp` point in its interior Bézier point at `(s, t)` of a
/// Gregory quad (`Fm` has the rest); a corner's own sum is 0 exactly there, where `Fp`'s
/// share is 0.
pub(crate) fn gregory_fp_shares(s: f64, t: f64) -> [f64; 4] {
    let recip = |x: f64| if x <= 0.0 { 1.0 } else { 1.0 / x };
    [
        s * recip(s + t),
        t * recip((1.0 - s) + t),
        (1.0 - s) * recip((1.0 - s) + (1.0 - t)),
        (1.0 - t) * recip(s + (1.0 - t)),
    ]
}

/// Gregory patch weights of the 20 points at `(s, t)` with every blend 1: the Bézier net's
/// Bernstein products, each interior pair weighted as its shared net point.
pub(crate) fn gregory_net(s: f64, t: f64) -> Weights<20> {
    let (bs, ds, dss) = bernstein(s);
    let (bt, dt, dtt) = bernstein(t);
    let mut w = [[0.0; 20]; 6];
    for (k, &(col, row)) in GREGORY_NET.iter().enumerate() {
        w[0][k] = bs[col] * bt[row];
        w[1][k] = ds[col] * bt[row];
        w[2][k] = bs[col] * dt[row];
        w[3][k] = dss[col] * bt[row];
        w[4][k] = ds[col] * dt[row];
        w[5][k] = bs[col] * dtt[row];
    }
    w
}

/// Gregory patch weights of the 20 points at `(s, t)`: the Bézier net whose interior
/// points blend each corner's `Fp` and `Fm` rationally (`Fp` towards the corner's `Ep`
/// edge). Derivatives hold the blend constant, as OpenSubdiv's evaluation does (the
/// Bézier net at `(s, t)` differentiated).
pub(crate) fn gregory(s: f64, t: f64) -> Weights<20> {
    let fp = gregory_fp_shares(s, t);
    let mut w = gregory_net(s, t);
    for k in 0..20 {
        let blend = match k % 5 {
            3 => fp[k / 5],
            4 => 1.0 - fp[k / 5],
            _ => continue,
        };
        for row in &mut w {
            row[k] *= blend;
        }
    }
    w
}

/// `u^i v^j w^k` differentiated `di`, `dj`, `dk` times in `u`, `v`, `w`.
fn barycentric_monomial(uvw: [f64; 3], ijk: [i32; 3], d: [i32; 3]) -> f64 {
    let mut x = 1.0;
    for a in 0..3 {
        // Falling factorial: the derivative's coefficient; zero past the power.
        for r in 0..d[a] {
            x *= f64::from(ijk[a] - r);
        }
        if ijk[a] >= d[a] {
            x *= uvw[a].powi(ijk[a] - d[a]);
        }
    }
    x
}

/// Quartic Bernstein weights of the 15 points of a Bézier triangle, row by row from corner
/// 0 (`p004, p103, p202, p301, p400, p013, …, p040`; `p_{ijk}` weighs `u^i v^j w^k` with
/// `u = s`, `v = t`, `w = 1 − s − t`), and their derivatives by the chain rule
/// `∂s = ∂u − ∂w`, `∂t = ∂v − ∂w`.
pub(crate) fn bezier_triangle(s: f64, t: f64) -> Weights<15> {
    let uvw = [s, t, 1.0 - s - t];
    // Each derivative as a sum of barycentric derivative orders (du, dv, dw) with signs.
    const PARTIALS: [&[(f64, [i32; 3])]; 6] = [
        &[(1.0, [0, 0, 0])],
        &[(1.0, [1, 0, 0]), (-1.0, [0, 0, 1])],
        &[(1.0, [0, 1, 0]), (-1.0, [0, 0, 1])],
        &[(1.0, [2, 0, 0]), (-2.0, [1, 0, 1]), (1.0, [0, 0, 2])],
        &[
            (1.0, [1, 1, 0]),
            (-1.0, [1, 0, 1]),
            (-1.0, [0, 1, 1]),
            (1.0, [0, 0, 2]),
        ],
        &[(1.0, [0, 2, 0]), (-2.0, [0, 1, 1]), (1.0, [0, 0, 2])],
    ];
    let factorial = [1.0, 1.0, 2.0, 6.0, 24.0];
    let mut w = [[0.0; 15]; 6];
    let mut q = 0;
    for j in 0..=4i32 {
        for i in 0..=(4 - j) {
            let k = 4 - i - j;
            let multinomial =
                24.0 / (factorial[i as usize] * factorial[j as usize] * factorial[k as usize]);
            for (row, terms) in w.iter_mut().zip(PARTIALS) {
                row[q] = multinomial
                    * terms
                        .iter()
                        .map(|&(sign, d)| sign * barycentric_monomial(uvw, [i, j, k], d))
                        .sum::<f64>();
            }
            q += 1;
        }
    }
    w
}

/// The Bézier point (index into [`bezier_triangle`]'s order) of each of the 18 Gregory
/// triangle points (per corner `P, Ep, Em, Fp, Fm`, then `M_0, M_1, M_2`), with the pair
/// at an interior point sharing it.
const GREGORY_TRIANGLE_NET: [usize; 18] =
    [0, 1, 5, 6, 6, 4, 8, 3, 7, 7, 14, 12, 13, 10, 10, 2, 11, 9];

/// Gregory triangle weights of the 18 points at `(s, t)`: the quartic Bézier triangle whose
/// interior point next to each corner blends that corner's `Fp` and `Fm` by the
/// barycentric distances to the two edges (the `Fp` share `u/(u + v)`, `v/(v + w)`,
/// `w/(w + u)` at corners 0, 1, 2; all `Fp` where the sum vanishes, as OpenSubdiv chooses).
/// Derivatives hold the blend constant, as OpenSubdiv's evaluation does.
pub(crate) fn gregory_triangle(s: f64, t: f64) -> Weights<18> {
    let pairs = gregory_triangle_shares(s, t);
    let mut out = gregory_triangle_net(s, t);
    for k in 0..15 {
        let blend = match k % 5 {
            3 => pairs[k / 5][0],
            4 => pairs[k / 5][1],
            _ => continue,
        };
        for row in &mut out {
            row[k] *= blend;
        }
    }
    out
}

/// The (`Fp`, `Fm`) shares of each corner's interior point of a Gregory triangle at
/// `(s, t)`: `u/(u + v)`, `v/(v + w)`, `w/(w + u)` for `Fp` at corners 0, 1, 2, and all
/// `Fp` where the sum vanishes.
pub(crate) fn gregory_triangle_shares(s: f64, t: f64) -> [[f64; 2]; 3] {
    let (u, v, w) = (s, t, 1.0 - s - t);
    let shares = |x: f64, y: f64| {
        if x + y > 0.0 {
            [x / (x + y), y / (x + y)]
        } else {
            [1.0, 0.0]
        }
    };
    [shares(u, v), shares(v, w), shares(w, u)]
}

/// Gregory triangle weights of the 18 points at `(s, t)` with every blend 1.
pub(crate) fn gregory_triangle_net(s: f64, t: f64) -> Weights<18> {
    let b = bezier_triangle(s, t);
    let mut out = [[0.0; 18]; 6];
    for (k, &q) in GREGORY_TRIANGLE_NET.iter().enumerate() {
        for (o, row) in out.iter_mut().zip(&b) {
            o[k] = row[q];
        }
    }
    out
}

/// Widens `N` weights to the 20 slots every patch type fits in.
fn widen<const N: usize>(w: Weights<N>) -> Weights<20> {
    w.map(|row| std::array::from_fn(|k| if k < N { row[k] } else { 0.0 }))
}

/// The weights of a patch of type `kind` at `(s, t)` of its own domain, `boundary` the
/// mask of a regular patch (0 for end caps).
pub(crate) fn weights(kind: super::PatchType, s: f64, t: f64, boundary: u8) -> Weights<20> {
    use super::PatchType as T;
    match kind {
        T::Regular => widen(bspline(s, t, boundary)),
        T::Loop => {
            let basis = crate::evaluation::loop_patch::box_spline()
                .expect("the box-spline basis derives on a fixed grid");
            widen(box_spline(basis, s, t, boundary))
        }
        T::GregoryBasis => gregory(s, t),
        T::GregoryTriangle => widen(gregory_triangle(s, t)),
        T::Quads => widen(bilinear(s, t)),
        T::Triangles => widen(linear(s, t)),
        T::Exact => unreachable!("{kind} patches are evaluated elsewhere"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const POINTS: [(f64, f64); 6] = [
        (0.2, 0.3),
        (0.0, 0.0),
        (1.0, 0.0),
        (0.0, 1.0),
        (0.61, 0.05),
        (0.25, 0.74),
    ];

    /// `x (x − 1) … (x − n + 1)`.
    fn falling(x: i32, n: i32) -> f64 {
        (0..n).map(|r| f64::from(x - r)).product()
    }

    /// Every barycentric monomial `u^a v^b w^c` of degree ≤ 4 is reproduced, with its
    /// derivatives: its quartic Bézier coefficients are the blossom values
    /// `i^(a) j^(b) k^(c) (4 − a − b − c)! / 4!` (falling factorials).
    #[test]
    fn the_bezier_triangle_reproduces_quartic_polynomials() {
        for a in 0..=4 {
            for b in 0..=(4 - a) {
                for c in 0..=(4 - a - b) {
                    let scale = falling(4 - a - b - c, 4 - a - b - c) / 24.0;
                    let mut coeffs = Vec::new();
                    for j in 0..=4i32 {
                        for i in 0..=(4 - j) {
                            let k = 4 - i - j;
                            coeffs.push(falling(i, a) * falling(j, b) * falling(k, c) * scale);
                        }
                    }
                    for &(s, t) in &POINTS {
                        let w = bezier_triangle(s, t);
                        let uvw = [s, t, 1.0 - s - t];
                        let exact = |d: [i32; 3]| barycentric_monomial(uvw, [a, b, c], d);
                        let want = [
                            exact([0, 0, 0]),
                            exact([1, 0, 0]) - exact([0, 0, 1]),
                            exact([0, 1, 0]) - exact([0, 0, 1]),
                            exact([2, 0, 0]) - 2.0 * exact([1, 0, 1]) + exact([0, 0, 2]),
                            exact([1, 1, 0]) - exact([1, 0, 1]) - exact([0, 1, 1])
                                + exact([0, 0, 2]),
                            exact([0, 2, 0]) - 2.0 * exact([0, 1, 1]) + exact([0, 0, 2]),
                        ];
                        for d in 0..6 {
                            let got: f64 = w[d].iter().zip(&coeffs).map(|(x, y)| x * y).sum();
                            assert!(
                                (got - want[d]).abs() < 1e-12,
                                "u^{a} v^{b} w^{c} at ({s}, {t}), derivative {d}: {got} vs {}",
                                want[d]
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn bezier_triangle_derivatives_are_those_of_the_position() {
        let h = 1e-6;
        for &(s, t) in &POINTS[..1] {
            let at = |s, t| bezier_triangle(s, t);
            let (ps, ms, pt, mt) = (at(s + h, t), at(s - h, t), at(s, t + h), at(s, t - h));
            let w = at(s, t);
            for q in 0..15 {
                let ds = (ps[0][q] - ms[0][q]) / (2.0 * h);
                let dt = (pt[0][q] - mt[0][q]) / (2.0 * h);
                let dss = (ps[1][q] - ms[1][q]) / (2.0 * h);
                let dst = (pt[1][q] - mt[1][q]) / (2.0 * h);
                let dtt = (pt[2][q] - mt[2][q]) / (2.0 * h);
                for (got, want) in [
                    (w[1][q], ds),
                    (w[2][q], dt),
                    (w[3][q], dss),
                    (w[4][q], dst),
                    (w[5][q], dtt),
                ] {
                    assert!((got - want).abs() < 1e-6, "point {q}: {got} vs {want}");
                }
            }
        }
    }

    /// With each corner's `Fp` and `Fm` the same point, the Gregory triangle is the Bézier
    /// triangle: the blends are a partition of unity.
    #[test]
    fn the_gregory_triangle_with_equal_pairs_is_the_bezier_triangle() {
        for &(s, t) in &POINTS {
            let g = gregory_triangle(s, t);
            let b = bezier_triangle(s, t);
            for d in 0..6 {
                let mut folded = [0.0; 15];
                for (k, &q) in GREGORY_TRIANGLE_NET.iter().enumerate() {
                    folded[q] += g[d][k];
                }
                for q in 0..15 {
                    assert!((folded[q] - b[d][q]).abs() < 1e-14, "({s}, {t}) {d} {q}");
                }
            }
            let total: f64 = g[0].iter().sum();
            assert!((total - 1.0).abs() < 1e-14);
        }
    }

    #[test]
    fn gregory_triangle_pairs_blend_by_distance_to_the_edges() {
        // On edge 0 (t = 0) the cross derivative sees only Fp0, the point paired with that
        // edge; on edge 2 (s = 0) only Fm0; at the corner itself OpenSubdiv picks Fp.
        let g = gregory_triangle(0.3, 0.0);
        assert!(g[2][3] > 0.0 && g[2][4] == 0.0);
        let g = gregory_triangle(0.0, 0.3);
        assert!(g[1][4] > 0.0 && g[1][3] == 0.0);
        let g = gregory_triangle(0.0, 0.0);
        assert!(g[4][3] == 12.0 && g[4][4] == 0.0);
    }
}
