//! Control points of one Catmull-Clark face's limit patch, and the bicubic B-spline.
//!
//! **Corner patch.** For a quad face `f` seen from its corner `c` (the corner at local
//! parameter (0, 0), `u` towards the next corner), when the other three corners are smooth
//! interior vertices of valence 4 with quads around them and the corner vertex `x0` is a
//! smooth interior vertex of valence `n` with quads around it, the limit surface over `f`
//! depends on 2n + 8 control points, in this order (grid coordinates as in a 4 × 4
//! B-spline patch whose face is the square (1,1)–(2,2)):
//!
//! * 0: `x0`, at (1, 1);
//! * 1 + 2i: the far end of the i-th edge of `x0` counter-clockwise from the edge to `f`'s
//!   next corner (e_0 at (2, 1), e_1 at (1, 2));
//! * 2 + 2i: the vertex opposite `x0` in the face between edges i and i + 1 (f_0 at (2, 2));
//! * 2n + 1 … 2n + 7: (3,0), (3,1), (3,2), (3,3), (2,3), (1,3), (0,3).
//!
//! This is Stam's 2n + 8 neighbourhood (Stam 1998, "Exact evaluation of Catmull-Clark
//! subdivision surfaces at arbitrary parameter values", §3) in an order of our own. With
//! n = 4 it is the regular 16-point patch, reordered by [`REGULAR_GRID`].

use glam::DVec3;
use subd_mesh::Topology;
use subd_mesh::neighbourhood::face_ring;
use subd_schemes::Rule;

/// For n = 4: the corner-patch index of grid point (i, j) at `REGULAR_GRID[4 j + i]`.
pub const REGULAR_GRID: [usize; 16] = [6, 7, 8, 9, 5, 0, 1, 10, 4, 3, 2, 11, 15, 14, 13, 12];

/// Uniform cubic B-spline basis at `t` and its first two derivatives.
#[inline]
pub fn bspline_basis(t: f64) -> ([f64; 4], [f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    let (t2, t3) = (t * t, t * t * t);
    let b = [
        s * s * s / 6.0,
        (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0,
        (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0,
        t3 / 6.0,
    ];
    let d = [
        -0.5 * s * s,
        1.5 * t2 - 2.0 * t,
        -1.5 * t2 + t + 0.5,
        0.5 * t2,
    ];
    let dd = [s, 3.0 * t - 2.0, -3.0 * t + 1.0, t];
    (b, d, dd)
}

/// How many derivatives an evaluation computes: positions and first derivatives only (what
/// a tessellation needs: half of an eigenbasis evaluation's work), or second ones too.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Derivatives {
    First,
    Second,
}

impl Derivatives {
    /// Rows of a weight table: position, ∂u, ∂v (then ∂uu, ∂uv, ∂vv).
    pub(crate) fn rows(self) -> usize {
        match self {
            Derivatives::First => 3,
            Derivatives::Second => 6,
        }
    }
}

/// Position and derivatives of a surface point with respect to the face parameters.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SurfacePoint {
    /// Position.
    pub position: DVec3,
    /// ∂/∂u.
    pub du: DVec3,
    /// ∂/∂v.
    pub dv: DVec3,
    /// ∂²/∂u².
    pub duu: DVec3,
    /// ∂²/∂u∂v.
    pub duv: DVec3,
    /// ∂²/∂v².
    pub dvv: DVec3,
}

impl SurfacePoint {
    /// Unit normal `normalize(du × dv)` (zero where the derivatives are parallel).
    pub fn normal(&self) -> DVec3 {
        self.du.cross(self.dv).normalize_or_zero()
    }

    /// The same point with derivatives scaled for a parameter map `u' = s u + …`,
    /// `v' = s v + …` (first derivatives by `s`, second by `s²`).
    pub(crate) fn scaled(mut self, s: f64) -> SurfacePoint {
        self.du *= s;
        self.dv *= s;
        self.duu *= s * s;
        self.duv *= s * s;
        self.dvv *= s * s;
        self
    }
}

/// The 16 tensor-product weights (grid order `4 j + i`) of position and derivatives.
pub(crate) fn bicubic_weights(u: f64, v: f64) -> [[f64; 16]; 6] {
    let (bu, du, ddu) = bspline_basis(u);
    let (bv, dv, ddv) = bspline_basis(v);
    let mut w = [[0.0; 16]; 6];
    for j in 0..4 {
        for i in 0..4 {
            let k = 4 * j + i;
            w[0][k] = bu[i] * bv[j];
            w[1][k] = du[i] * bv[j];
            w[2][k] = bu[i] * dv[j];
            w[3][k] = ddu[i] * bv[j];
            w[4][k] = du[i] * dv[j];
            w[5][k] = bu[i] * ddv[j];
        }
    }
    w
}

/// The bicubic B-spline patch over grid control points `grid[4 j + i]` at (u, v).
pub fn eval_bicubic(grid: &[DVec3; 16], u: f64, v: f64) -> SurfacePoint {
    let w = bicubic_weights(u, v);
    let sum = |k: usize| {
        grid.iter()
            .zip(&w[k])
            .fold(DVec3::ZERO, |acc, (p, &x)| acc + x * *p)
    };
    SurfacePoint {
        position: sum(0),
        du: sum(1),
        dv: sum(2),
        duu: sum(3),
        duv: sum(4),
        dvv: sum(5),
    }
}

/// Position and first derivatives of the bicubic B-spline patch over `grid[4 j + i]` at
/// (u, v), summed row by row (the tensor product split in two): a third of
/// [`eval_bicubic`]'s work, for callers that need no second derivatives.
pub fn eval_bicubic_first(grid: &[DVec3; 16], u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
    let (bu, du, _) = bspline_basis(u);
    let (bv, dv, _) = bspline_basis(v);
    let (mut p, mut pu, mut pv) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
    for j in 0..4 {
        let row = &grid[4 * j..4 * j + 4];
        let r = bu[0] * row[0] + bu[1] * row[1] + bu[2] * row[2] + bu[3] * row[3];
        let ru = du[0] * row[0] + du[1] * row[1] + du[2] * row[2] + du[3] * row[3];
        p += bv[j] * r;
        pu += bv[j] * ru;
        pv += dv[j] * r;
    }
    (p, pu, pv)
}

/// [`face_ring`] of quads: (next, opposite, previous) per face.
fn quad_ring(t: &Topology, v: usize, f: usize) -> Option<Vec<[u32; 3]>> {
    face_ring::<3>(t, v, f)
}

/// The 2n + 8 control points of quad `f` seen from its corner `c` (see the module docs), or
/// `None` when the neighbourhood is not of that form.
pub fn corner_patch(t: &Topology, f: usize, c: usize) -> Option<Vec<u32>> {
    let fv = t.face_vertices(f);
    if fv.len() != 4 {
        return None;
    }
    let x = |k: usize| fv[(c + k) % 4] as usize;
    let r0 = quad_ring(t, x(0), f)?;
    let n = r0.len();
    let mut out = Vec::with_capacity(2 * n + 8);
    out.push(x(0) as u32);
    for r in &r0 {
        out.push(r[0]);
        out.push(r[1]);
    }
    let (r1, r2, r3) = (
        quad_ring(t, x(1), f)?,
        quad_ring(t, x(2), f)?,
        quad_ring(t, x(3), f)?,
    );
    if r1.len() != 4 || r2.len() != 4 || r3.len() != 4 {
        return None;
    }
    out.extend_from_slice(&[
        r1[2][1], r1[3][0], r1[3][1], r2[2][1], r2[3][0], r2[3][1], r3[2][1],
    ]);
    Some(out)
}

/// `true` when nothing in the 1-ring of face `f` is sharp: every vertex of `f` has the smooth
/// rule and no vertex sharpness, and no edge at those vertices is sharp, and no face around
/// them is a hole.
pub fn smooth_neighbourhood(t: &Topology, rules: &[Rule], f: usize) -> bool {
    t.face_vertices(f).iter().all(|&v| {
        let v = v as usize;
        rules[v] == Rule::Smooth
            && t.vertex_sharpness(v) == 0.0
            && t.vertex_edges(v)
                .iter()
                .all(|&e| t.edge_sharpness(e as usize) == 0.0)
            && t.vertex_faces(v).iter().all(|&g| !t.is_hole(g as usize))
    })
}

/// A grid control point as a combination of mesh vertices (a real vertex, or a phantom point
/// reflected across a sharp edge or boundary).
pub type GridPoint = Vec<(u32, f64)>;

/// The corner of face `f` at local index `k` is regular for a B-spline patch with phantom
/// points: a smooth interior vertex of valence 4; a crease vertex whose two infinitely sharp
/// edges run straight through it (interior valence 4, or a boundary vertex with two faces);
/// or a sharp corner with one face. Returns `false` for anything else (darts, semi-sharp
/// features, irregular valences).
pub fn regular_sharp_corner(t: &Topology, rules: &[Rule], v: usize) -> bool {
    let vs = t.vertex_sharpness(v);
    let Some(sharp) = infinitely_sharp_edges(t, v, 4) else {
        return false;
    };
    let (ne, nf) = (t.vertex_edges(v).len(), t.vertex_faces(v).len());
    match (rules[v], ne, nf, sharp.as_slice()) {
        (Rule::Smooth, 4, 4, []) => vs == 0.0,
        (Rule::Crease, 4, 4, [a, b]) => b - a == 2 && vs == 0.0,
        (Rule::Crease, 3, 2, [0, 2]) => vs == 0.0,
        (Rule::Corner, 2, 1, [0, 1]) => true,
        _ => false,
    }
}

/// The positions (in vertex-edge order) of the sharp edges at `v`, when they are all
/// infinitely sharp, `v` is manifold with no semi-sharp vertex sharpness, and every face
/// around it has `size` vertices and is not a hole; `None` otherwise.
pub(crate) fn infinitely_sharp_edges(t: &Topology, v: usize, size: usize) -> Option<Vec<usize>> {
    use subd_mesh::tags::is_infinite;
    let (ve, vf) = (t.vertex_edges(v), t.vertex_faces(v));
    let vs = t.vertex_sharpness(v);
    if t.is_non_manifold_vertex(v)
        || (vs != 0.0 && !is_infinite(vs))
        || vf
            .iter()
            .any(|&g| t.face_size(g as usize) != size || t.is_hole(g as usize))
    {
        return None;
    }
    let sharp: Vec<usize> = (0..ve.len())
        .filter(|&i| t.edge_sharpness(ve[i] as usize) > 0.0)
        .collect();
    sharp
        .iter()
        .all(|&i| is_infinite(t.edge_sharpness(ve[i] as usize)))
        .then_some(sharp)
}

/// The 16 B-spline control points (grid order `4 j + i`) of quad `f` whose corners are all
/// regular in the sense of [`regular_sharp_corner`], with phantom points `2 p − q` across
/// infinitely sharp edges and boundaries (the reflection that turns the B-spline rules into
/// the crease rules: midpoint on the edge, (1, 6, 1)/8 at crease vertices, interpolation at
/// corners). `None` when the neighbourhood is not of that form.
pub fn sharp_regular_grid(t: &Topology, rules: &[Rule], f: usize) -> Option<[GridPoint; 16]> {
    let fv = t.face_vertices(f);
    if fv.len() != 4
        || t.is_hole(f)
        || fv
            .iter()
            .any(|&v| !regular_sharp_corner(t, rules, v as usize))
    {
        return None;
    }
    let fe = t.face_edges(f);
    let sharp = |k: usize| t.edge_sharpness(fe[k] as usize) > 0.0;
    let mut g: [GridPoint; 16] = std::array::from_fn(|_| Vec::new());
    let at = |i: usize, j: usize| 4 * j + i;
    // The face itself: corners k at (1,1), (2,1), (2,2), (1,2).
    let inner = [(1, 1), (2, 1), (2, 2), (1, 2)];
    for k in 0..4 {
        g[at(inner[k].0, inner[k].1)] = vec![(fv[k], 1.0)];
    }
    // Outer rows/columns beside edge k (corner k to k + 1): the points beyond corner k and
    // beyond corner k + 1, and the grid step pointing out of the face across that edge.
    let beside = [
        [(1, 0), (2, 0)],
        [(3, 1), (3, 2)],
        [(2, 3), (1, 3)],
        [(0, 2), (0, 1)],
    ];
    let inward = [(0i32, 1i32), (-1, 0), (0, -1), (1, 0)];
    let comb = |a: &GridPoint, wa: f64, b: &GridPoint, wb: f64| -> GridPoint {
        a.iter()
            .map(|&(v, w)| (v, w * wa))
            .chain(b.iter().map(|&(v, w)| (v, w * wb)))
            .collect()
    };
    for k in 0..4 {
        let across = t
            .edge_faces(fe[k] as usize)
            .iter()
            .map(|&x| x as usize)
            .find(|&x| x != f);
        match (sharp(k), across) {
            (false, Some(h)) => {
                let hv = t.face_vertices(h);
                if hv.len() != 4 {
                    return None;
                }
                // h runs (x_{k+1}, x_k, beyond x_k, beyond x_{k+1}).
                let s = hv.iter().position(|&x| x == fv[(k + 1) % 4])?;
                if hv[(s + 1) % 4] != fv[k] {
                    return None;
                }
                g[at(beside[k][0].0, beside[k][0].1)] = vec![(hv[(s + 2) % 4], 1.0)];
                g[at(beside[k][1].0, beside[k][1].1)] = vec![(hv[(s + 3) % 4], 1.0)];
            }
            (false, None) => return None,
            (true, _) => {
                for &(i, j) in &beside[k] {
                    let (di, dj) = inward[k];
                    let on = (i as i32 + di) as usize;
                    let oj = (j as i32 + dj) as usize;
                    let (ii, ij) = ((on as i32 + di) as usize, (oj as i32 + dj) as usize);
                    g[at(i, j)] = comb(&g[at(on, oj)].clone(), 2.0, &g[at(ii, ij)].clone(), -1.0);
                }
            }
        }
    }
    // Diagonal corners at corner k, between edge k − 1 (before) and edge k (after).
    let diag = [(0, 0), (3, 0), (3, 3), (0, 3)];
    for k in 0..4 {
        let (before, after) = ((k + 3) % 4, k);
        let (i, j) = diag[k];
        g[at(i, j)] = match (sharp(before), sharp(after)) {
            (false, false) => {
                let ring = quad_ring(t, fv[k] as usize, f)?;
                if ring.len() != 4 {
                    return None;
                }
                vec![(ring[2][1], 1.0)]
            }
            // Reflect across the sharp edge after corner k: step inward[after].
            (_, true) => {
                let (di, dj) = inward[after];
                let (a, b) = ((i as i32 + di) as usize, (j as i32 + dj) as usize);
                let (c, d) = ((a as i32 + di) as usize, (b as i32 + dj) as usize);
                comb(&g[at(a, b)].clone(), 2.0, &g[at(c, d)].clone(), -1.0)
            }
            (true, false) => {
                let (di, dj) = inward[before];
                let (a, b) = ((i as i32 + di) as usize, (j as i32 + dj) as usize);
                let (c, d) = ((a as i32 + di) as usize, (b as i32 + dj) as usize);
                comb(&g[at(a, b)].clone(), 2.0, &g[at(c, d)].clone(), -1.0)
            }
        };
    }
    Some(g)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_is_a_partition_of_unity_with_matching_derivatives() {
        for k in 0..=10 {
            let t = k as f64 / 10.0;
            let (b, d, dd) = bspline_basis(t);
            assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-15);
            assert!(d.iter().sum::<f64>().abs() < 1e-15);
            assert!(dd.iter().sum::<f64>().abs() < 1e-15);
            // Linear precision: Σ B_i(t)·(i − 1) = t.
            let x: f64 = b
                .iter()
                .enumerate()
                .map(|(i, w)| w * (i as f64 - 1.0))
                .sum();
            assert!((x - t).abs() < 1e-15);
            // Central differences of the basis match the derivatives.
            let h = 1e-6;
            let (bp, dp, _) = bspline_basis(t + h);
            let (bm, dm, _) = bspline_basis(t - h);
            for i in 0..4 {
                assert!(((bp[i] - bm[i]) / (2.0 * h) - d[i]).abs() < 1e-8);
                assert!(((dp[i] - dm[i]) / (2.0 * h) - dd[i]).abs() < 1e-8);
            }
        }
    }

    #[test]
    fn regular_grid_is_a_permutation() {
        let mut seen = [false; 16];
        for &k in &REGULAR_GRID {
            assert!(!seen[k]);
            seen[k] = true;
        }
        // The face corners: (1,1) = x0, (2,1) = e0, (2,2) = f0, (1,2) = e1.
        assert_eq!(
            [
                REGULAR_GRID[5],
                REGULAR_GRID[6],
                REGULAR_GRID[10],
                REGULAR_GRID[9]
            ],
            [0, 1, 2, 3]
        );
    }
}

#[cfg(test)]
mod first_derivative_tests {
    use super::*;

    #[test]
    fn row_by_row_equals_the_full_tensor_product() {
        let grid: [DVec3; 16] = std::array::from_fn(|k| {
            let x = k as f64;
            DVec3::new((1.3 * x).sin(), (0.7 * x).cos() * 2.0, x * x * 0.01)
        });
        for &(u, v) in &[(0.0, 0.0), (0.3, 0.8), (1.0, 0.25), (0.5, 1.0)] {
            let full = eval_bicubic(&grid, u, v);
            let (p, du, dv) = eval_bicubic_first(&grid, u, v);
            assert!((p - full.position).length() < 1e-14);
            assert!((du - full.du).length() < 1e-13);
            assert!((dv - full.dv).length() < 1e-13);
        }
    }
}
