//! Exact evaluation of Loop surfaces: the regular triangle is a quartic box-spline patch,
//! and a triangle with one extraordinary corner is evaluated with Stam's eigenbasis method
//! for Loop (Stam 1998, "Evaluation of Loop subdivision surfaces").
//!
//! **Corner patch** of triangle `(x0, x1, x2)` at its corner `x0` of valence n, when `x1`
//! and `x2` are smooth interior vertices of valence 6: n + 6 control points,
//! `[x0, e_0 … e_{n−1}, A, B, C, D, E]` — `e_i` the neighbours of `x0` counter-clockwise
//! from `e_0 = x1` (so `e_1 = x2`), then the three further neighbours of `x1` and the two
//! further neighbours of `x2`, counter-clockwise. With n = 6 this is the 12-point regular
//! patch.
//!
//! **Box-spline basis.** Rather than transcribing the 12 quartic polynomials, the code
//! derives them from the scheme: on a regular synthetic mesh, the limit of every refined
//! vertex at the 15 dyadic points `(i/4, j/4)` of the triangle is computed with the
//! refinement stencils and the closed-form limit masks, and the quartic through those 15
//! values is solved for, control point by control point (`faer` LU). A test checks the
//! result against the limit at other dyadic points.
//!
//! Parameters: `(0,0) = x0`, `(1,0) = x1`, `(0,1) = x2`, barycentric `(1 − u − v, u, v)`.

// Basis functions and derivatives index several parallel arrays.
#![allow(clippy::needless_range_loop)]

use std::sync::{Arc, OnceLock};

use faer::Mat;
use faer::linalg::solvers::Solve;
use glam::DVec3;
use subd_mesh::{Topology, TopologyBuilder};
use subd_schemes::{Options, Refinement, Rule, Scheme};

use crate::LimitError;
use subd_mesh::neighbourhood::face_ring;

use crate::evaluation::patch::{Derivatives, GridPoint, SurfacePoint};
use crate::evaluation::stam::{
    PerValence, Projected, SubpatchSubdivision, cached, steps_to_regular,
};
use crate::limit_masks::table::LimitStencilTable;

/// The ring of `v` from face `f`: per incident triangle counter-clockwise, (next, previous).
fn tri_ring(t: &Topology, v: usize, f: usize) -> Option<Vec<[u32; 2]>> {
    face_ring::<2>(t, v, f)
}

/// The n + 6 control points of triangle `f` from its corner `c` (module docs), or `None`.
pub fn tri_corner_patch(t: &Topology, f: usize, c: usize) -> Option<Vec<u32>> {
    let fv = t.face_vertices(f);
    if fv.len() != 3 {
        return None;
    }
    let x = |k: usize| fv[(c + k) % 3] as usize;
    let r0 = tri_ring(t, x(0), f)?;
    let (r1, r2) = (tri_ring(t, x(1), f)?, tri_ring(t, x(2), f)?);
    if r1.len() != 6 || r2.len() != 6 {
        return None;
    }
    let mut out = Vec::with_capacity(r0.len() + 6);
    out.push(x(0) as u32);
    out.extend(r0.iter().map(|r| r[0]));
    // x1's ring from f: (x2, x0), (x0, e_{n−1}), (e_{n−1}, A), (A, B), (B, C), (C, x2).
    out.extend_from_slice(&[r1[2][1], r1[3][1], r1[4][1]]);
    // x2's ring from f: (x0, x1), (x1, C), (C, D), (D, E), (E, e_2), (e_2, x0).
    out.extend_from_slice(&[r2[2][1], r2[3][1]]);
    Some(out)
}

/// Monomials u^a v^b of total degree ≤ 4, and their first and second derivatives.
fn monomials(u: f64, v: f64) -> [[f64; 15]; 6] {
    monomial_rows::<6>(u, v)
}

/// The first `R` rows of [`monomials`] (3: the monomials and their first derivatives), each
/// computed as there.
fn monomial_rows<const R: usize>(u: f64, v: f64) -> [[f64; 15]; R] {
    // x^k for k ≤ 4 by the products `powi` forms (square and multiply: x·x², (x²)²), so
    // the same bits without a library call per term.
    let powers = |x: f64| {
        let x2 = x * x;
        [1.0, x, x2, x * x2, x2 * x2]
    };
    let (pu, pv) = (powers(u), powers(v));
    let pw = |p: &[f64; 5], k: i32| if k < 0 { 0.0 } else { p[k as usize] };
    let mut m = [[0.0; 15]; R];
    let mut k = 0;
    for d in 0..=4i32 {
        for b in 0..=d {
            let a = d - b;
            let (af, bf) = (f64::from(a), f64::from(b));
            let row = |r: usize| match r {
                0 => pw(&pu, a) * pw(&pv, b),
                1 => af * pw(&pu, a - 1) * pw(&pv, b),
                2 => bf * pw(&pu, a) * pw(&pv, b - 1),
                3 => af * (af - 1.0) * pw(&pu, a - 2) * pw(&pv, b),
                4 => af * bf * pw(&pu, a - 1) * pw(&pv, b - 1),
                _ => bf * (bf - 1.0) * pw(&pu, a) * pw(&pv, b - 2),
            };
            for (r, mr) in m.iter_mut().enumerate() {
                mr[k] = row(r);
            }
            k += 1;
        }
    }
    m
}

/// The 12 quartic box-spline basis functions of the regular patch (monomial coefficients).
#[derive(Debug)]
pub struct BoxSpline {
    coeffs: [[f64; 12]; 15],
}

/// A regular triangle grid of `(2r + 1)²` vertices around the origin: every interior vertex
/// has valence 6.
fn regular_grid(r: i32) -> (Topology, impl Fn(i32, i32) -> u32) {
    let w = 2 * r + 1;
    let id = move |i: i32, j: i32| ((j + r) * w + (i + r)) as u32;
    // Directions (1,0), (0,1) and (1,−1), so that (0,0), (1,0), (0,1) is a triangle.
    let mut faces = Vec::new();
    for j in -r..r {
        for i in -r..r {
            faces.extend([id(i, j), id(i + 1, j), id(i, j + 1)]);
            faces.extend([id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let topo = TopologyBuilder::new((w * w) as usize)
        .build(&vec![3; faces.len() / 3], &faces)
        .expect("a triangle grid is a valid mesh");
    (topo, id)
}

impl BoxSpline {
    /// Derives the basis from Loop refinement and limit masks (module docs).
    pub fn derive() -> Result<BoxSpline, LimitError> {
        let (grid, id) = regular_grid(5);
        // The patch triangle (0,0), (1,0), (0,1): x0 = (0,0), x1 = (1,0), x2 = (0,1).
        let f = (0..grid.num_faces())
            .find(|&f| grid.face_vertices(f) == [id(0, 0), id(1, 0), id(0, 1)])
            .or_else(|| {
                (0..grid.num_faces()).find(|&f| {
                    let fv = grid.face_vertices(f);
                    fv.contains(&id(0, 0)) && fv.contains(&id(1, 0)) && fv.contains(&id(0, 1))
                })
            })
            .ok_or_else(|| LimitError::Analysis("no patch triangle in the grid".into()))?;
        let fv = grid.face_vertices(f);
        let c = fv
            .iter()
            .position(|&v| v == id(0, 0))
            .expect("the triangle has the origin");
        // The triangle must run x0 → x1 → x2 counter-clockwise for the parameterisation.
        if fv[(c + 1) % 3] != id(1, 0) {
            return Err(LimitError::Analysis(
                "patch triangle is mis-oriented".into(),
            ));
        }
        let cp = tri_corner_patch(&grid, f, c)
            .ok_or_else(|| LimitError::Analysis("grid patch is not regular".into()))?;
        let level = 2;
        let r = Refinement::new(&grid, Scheme::Loop, &Options::default(), level)?;
        let limit = LimitStencilTable::at_level(&r, level)?.position;
        let composed = r.composed(level);
        let table = composed.then(&limit);
        // The dyadic point (i/4, j/4) of the patch is the level-2 vertex reached by halving
        // twice; find it by position on the grid's own (planar) coordinates.
        let planar: Vec<DVec3> = (0..grid.num_vertices())
            .map(|k| {
                let w = 11;
                DVec3::new((k % w) as f64 - 5.0, (k / w) as f64 - 5.0, 0.0)
            })
            .collect();
        let refined = r.refine_points(&planar).pop().expect("level 2");
        let mut samples = Vec::new();
        for j in 0..=4 {
            for i in 0..=(4 - j) {
                let (u, v) = (i as f64 / 4.0, j as f64 / 4.0);
                let k = refined
                    .iter()
                    .position(|p| (p.x - u).abs() < 1e-12 && (p.y - v).abs() < 1e-12)
                    .ok_or_else(|| LimitError::Analysis("dyadic point not found".into()))?;
                samples.push((u, v, k));
            }
        }
        // A[s][m] = monomial m at sample s; rhs[s][k] = weight of control point k there.
        let a = Mat::<f64>::from_fn(15, 15, |s, m| monomials(samples[s].0, samples[s].1)[0][m]);
        let mut rhs = Mat::<f64>::zeros(15, 12);
        for (s, &(_, _, row)) in samples.iter().enumerate() {
            let (idx, w) = table.row(row);
            for (&src, &x) in idx.iter().zip(w) {
                match cp.iter().position(|&q| q == src) {
                    Some(k) => rhs[(s, k)] += x,
                    None if x.abs() > 1e-12 => {
                        return Err(LimitError::Analysis(format!(
                            "the limit inside the patch depends on vertex {src} outside it ({x})"
                        )));
                    }
                    None => {}
                }
            }
        }
        let sol = a.full_piv_lu().solve(&rhs);
        let coeffs = std::array::from_fn(|m| std::array::from_fn(|k| sol[(m, k)]));
        Ok(BoxSpline { coeffs })
    }

    /// Weights of the 12 control points for position and the five derivatives at (u, v).
    pub fn weights(&self, u: f64, v: f64) -> [[f64; 12]; 6] {
        self.weights_to(u, v, Derivatives::Second)
    }

    /// [`Self::weights`] up to the derivatives `d` (the other rows zero).
    pub(crate) fn weights_to(&self, u: f64, v: f64, d: Derivatives) -> [[f64; 12]; 6] {
        let mut m = [[0.0; 15]; 6];
        match d {
            Derivatives::First => m[..3].copy_from_slice(&monomial_rows::<3>(u, v)),
            Derivatives::Second => m = monomials(u, v),
        }
        let mut w = [[0.0; 12]; 6];
        for (wd, md) in w.iter_mut().zip(&m).take(d.rows()) {
            *wd = self.row_weights(md);
        }
        w
    }

    /// The 12 weights `Σ_j coeffs[j][k] · m[j]` of one row of monomials: each sum in the
    /// order of `j` from `-0.0` (as `Iterator::sum` takes it), the twelve side by side so
    /// that they do not wait on one another.
    #[inline]
    fn row_weights(&self, m: &[f64; 15]) -> [f64; 12] {
        let mut w = [-0.0; 12];
        for (&x, cj) in m.iter().zip(&self.coeffs) {
            for (wk, c) in w.iter_mut().zip(cj) {
                *wk += c * x;
            }
        }
        w
    }

    /// Position and first derivatives of the regular patch over `cp` at (u, v): half of
    /// [`Self::evaluate`]'s work, for callers that need no second derivatives.
    pub fn evaluate_first(&self, cp: &[DVec3; 12], u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
        let m = monomial_rows::<3>(u, v);
        let w = [
            self.row_weights(&m[0]),
            self.row_weights(&m[1]),
            self.row_weights(&m[2]),
        ];
        let mut out = [DVec3::ZERO; 3];
        for (k, p) in cp.iter().enumerate() {
            for (o, wd) in out.iter_mut().zip(&w) {
                *o += wd[k] * *p;
            }
        }
        (out[0], out[1], out[2])
    }

    /// The regular patch over control points `cp` (corner-patch order, n = 6) at (u, v).
    pub fn evaluate(&self, cp: &[DVec3], u: f64, v: f64) -> SurfacePoint {
        let w = self.weights(u, v);
        let sum = |d: usize| {
            cp.iter()
                .zip(&w[d])
                .fold(DVec3::ZERO, |a, (p, &x)| a + x * *p)
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
}

/// The box-spline basis, derived once.
pub fn box_spline() -> Result<&'static BoxSpline, LimitError> {
    static BASIS: OnceLock<Result<BoxSpline, String>> = OnceLock::new();
    BASIS
        .get_or_init(|| BoxSpline::derive().map_err(|e| e.to_string()))
        .as_ref()
        .map_err(|e| LimitError::Analysis(e.clone()))
}

/// Subdivision matrices of a Loop corner patch of valence n (K = n + 6 control points; the
/// regular sub-triangles 1, 2, 3 have 12 each) and their eigenbasis.
#[derive(Debug)]
pub struct LoopCornerMatrices {
    sub: SubpatchSubdivision<12>,
}

impl LoopCornerMatrices {
    /// Builds the matrices by refining a synthetic neighbourhood once.
    pub fn new(n: usize) -> Result<LoopCornerMatrices, LimitError> {
        if n < 3 {
            return Err(LimitError::Analysis(format!(
                "Loop corner patches need valence ≥ 3, not {n}"
            )));
        }
        let k = n + 6;
        // Vertices: 0 = x0, 1..=n = e_i (e_0 = x1, e_1 = x2), then A B C (n+1..n+3), D E.
        let e = |i: usize| (1 + i % n) as u32;
        let (a_, b_, c_, d_, e_) = (
            (n + 1) as u32,
            (n + 2) as u32,
            (n + 3) as u32,
            (n + 4) as u32,
            (n + 5) as u32,
        );
        let mut faces: Vec<u32> = Vec::new();
        for i in 0..n {
            faces.extend([0, e(i), e(i + 1)]);
        }
        let (x1, x2, em1, e2) = (e(0), e(1), e(n - 1), e(2));
        // Around x1: (x1, x2, x0) is ring face 0; (x1, x0, e_{n−1}) is x0's last face.
        faces.extend([x1, em1, a_]);
        faces.extend([x1, a_, b_]);
        faces.extend([x1, b_, c_]);
        faces.extend([x1, c_, x2]);
        // Around x2: (x2, x0, x1), (x2, x1, C), then C D, D E, E e_2; (x2, e_2, x0) is x0's.
        faces.extend([x2, c_, d_]);
        faces.extend([x2, d_, e_]);
        faces.extend([x2, e_, e2]);
        let topo = TopologyBuilder::new(k)
            .build(&vec![3; faces.len() / 3], &faces)
            .map_err(|err| {
                LimitError::Analysis(format!("synthetic Loop patch of valence {n}: {err}"))
            })?;
        let r = Refinement::new(&topo, Scheme::Loop, &Options::default(), 1)?;
        let child = r.topology(1);
        let st = r.stencils(1);
        let rows = |ids: &[u32]| -> Mat<f64> {
            let mut m = Mat::<f64>::zeros(ids.len(), k);
            for (row, &id) in ids.iter().enumerate() {
                let (idx, w) = st.row(id as usize);
                for (&j, &wj) in idx.iter().zip(w) {
                    m[(row, j as usize)] += wj;
                }
            }
            m
        };
        let bad = || {
            LimitError::Analysis(format!(
                "synthetic Loop patch of valence {n} is not regular"
            ))
        };
        // Face 0 = (x0, x1, x2); its children are 0..4: (V0,E0,E2), (E0,V1,E1), (E2,E1,V2),
        // (E1,E2,E0), each seen from its first corner.
        let a = rows(&tri_corner_patch(child, 0, 0).ok_or_else(bad)?);
        let sub = |j: usize| -> Result<Mat<f64>, LimitError> {
            Ok(rows(&tri_corner_patch(child, j, 0).ok_or_else(bad)?))
        };
        let abar = [sub(1)?, sub(2)?, sub(3)?];
        Ok(LoopCornerMatrices {
            sub: SubpatchSubdivision::new(a, abar),
        })
    }

    /// Whether evaluation uses the eigenbasis.
    pub fn uses_eigenbasis(&self) -> bool {
        self.sub.uses_eigenbasis()
    }

    /// Control points prepared for evaluation.
    pub fn project(&self, cp: &[DVec3]) -> Projected {
        self.sub.project(cp, true)
    }

    /// The surface at (u, v) ≠ (0, 0) of the corner patch (parameters of the module docs).
    pub fn evaluate(&self, c: &Projected, u: f64, v: f64) -> Result<SurfacePoint, LimitError> {
        self.evaluate_to(c, u, v, Derivatives::Second)
    }

    /// [`Self::evaluate`] up to the derivatives `d` (the others zero).
    pub(crate) fn evaluate_to(
        &self,
        c: &Projected,
        u: f64,
        v: f64,
        d: Derivatives,
    ) -> Result<SurfacePoint, LimitError> {
        let basis = box_spline()?;
        let (steps, scale) = steps_to_regular(u + v);
        let (u1, v1) = (u * scale, v * scale);
        // Sub-triangle and its parameters (s, t) with Jacobian ∂(s,t)/∂(u1,v1).
        let (sub, s, t, j) = if u1 >= 0.5 {
            (0, 2.0 * u1 - 1.0, 2.0 * v1, [[2.0, 0.0], [0.0, 2.0]])
        } else if v1 >= 0.5 {
            (1, 2.0 * u1, 2.0 * v1 - 1.0, [[2.0, 0.0], [0.0, 2.0]])
        } else {
            (
                2,
                1.0 - 2.0 * u1,
                1.0 - 2.0 * v1,
                [[-2.0, 0.0], [0.0, -2.0]],
            )
        };
        let w = basis.weights_to(s, t, d);
        let out = self.sub.combine(c, steps, sub, &w[..d.rows()]);
        // Chain rule: (s, t) = J (u1, v1) + const, (u1, v1) = scale (u, v).
        let (js, jt) = (j[0][0] * scale, j[1][1] * scale);
        Ok(SurfacePoint {
            position: out[0],
            du: js * out[1],
            dv: jt * out[2],
            duu: js * js * out[3],
            duv: js * jt * out[4],
            dvv: jt * jt * out[5],
        })
    }
}

/// Loop corner-patch matrices per valence, built on first use and shared.
pub fn loop_corner_matrices(n: usize) -> Result<Arc<LoopCornerMatrices>, LimitError> {
    static CACHE: PerValence<LoopCornerMatrices> = OnceLock::new();
    cached(&CACHE, n, LoopCornerMatrices::new)
}

/// Lattice coordinates of the 12 control points of the regular patch in corner-patch order
/// (module docs), on the triangle lattice with directions (1, 0), (0, 1), (−1, 1):
/// x0, e_0 = x1, e_1 = x2, e_2 … e_5, A, B, C, D, E.
const LATTICE: [(i32, i32); 12] = [
    (0, 0),
    (1, 0),
    (0, 1),
    (-1, 1),
    (-1, 0),
    (0, -1),
    (1, -1),
    (2, -1),
    (2, 0),
    (1, 1),
    (0, 2),
    (-1, 2),
];

/// The six lattice neighbours of a point, counter-clockwise.
const LATTICE_RING: [(i32, i32); 6] = [(1, 0), (0, 1), (-1, 1), (-1, 0), (0, -1), (1, -1)];

/// A vertex of triangle `f` is regular for a box-spline patch with phantom points: a smooth
/// interior vertex of valence 6, or a crease vertex whose two infinitely sharp edges run
/// straight through it (interior valence 6, edges opposite; or a boundary vertex with three
/// faces). No semi-sharp edge, no vertex sharpness, no hole, only triangles.
fn loop_regular_vertex(t: &Topology, rules: &[Rule], v: usize) -> bool {
    let Some(sharp) = crate::evaluation::patch::infinitely_sharp_edges(t, v, 3) else {
        return false;
    };
    let (ne, nf) = (t.vertex_edges(v).len(), t.vertex_faces(v).len());
    t.vertex_sharpness(v) == 0.0
        && match (rules[v], ne, nf, sharp.as_slice()) {
            (Rule::Smooth, 6, 6, []) => true,
            (Rule::Crease, 6, 6, [a, b]) => b - a == 3,
            (Rule::Crease, 4, 3, [0, 3]) => true,
            _ => false,
        }
}

/// The edge joining `a` and `b`, if any.
fn edge_between(t: &Topology, a: u32, b: u32) -> Option<usize> {
    t.vertex_edges(a as usize)
        .iter()
        .map(|&e| e as usize)
        .find(|&e| {
            let [p, q] = t.edge_vertices(e);
            (p == a && q == b) || (p == b && q == a)
        })
}

/// The 12 box-spline control points (corner-patch order) of Loop triangle `f` whose corners
/// are regular (smooth interior vertices of valence 6, or straight infinitely sharp crease
/// and regular boundary vertices), with phantom points across
/// infinitely sharp edges and boundaries, or `None` when the neighbourhood is not of that
/// form.
///
/// The faces around the corners are laid out on the triangle lattice by crossing smooth
/// edges only (each new triangle the parallelogram image of its neighbour); a lattice point
/// on the far side of a sharp edge `(a, b)` from the triangle `(a, b, c)` is the phantom
/// `a + b − c`. With it the box-spline rules reproduce Loop's crease rules: the edge point
/// `3/8 (a + b) + 1/8 (c + a + b − c) = (a + b)/2`, and at a crease vertex the smooth
/// valence-6 rule `5/8 x + 1/16 Σ` becomes `3/4 x + 1/8 (b₀ + b₁)`. The dyadic-point tests
/// check the patches against refinement.
pub fn loop_sharp_regular(t: &Topology, rules: &[Rule], f: usize) -> Option<[GridPoint; 12]> {
    let fv = t.face_vertices(f);
    if fv.len() != 3
        || t.is_hole(f)
        || fv
            .iter()
            .any(|&v| !loop_regular_vertex(t, rules, v as usize))
    {
        return None;
    }
    let region: Vec<u32> = fv
        .iter()
        .flat_map(|&v| t.vertex_faces(v as usize).iter().copied())
        .collect();
    let mut coords: Vec<(u32, (i32, i32))> =
        vec![(fv[0], (0, 0)), (fv[1], (1, 0)), (fv[2], (0, 1))];
    let mut visited = vec![f as u32];
    let mut queue = vec![f];
    let add = |coords: &mut Vec<(u32, (i32, i32))>, v: u32, c: (i32, i32)| -> bool {
        match coords.iter().find(|&&(w, d)| w == v || d == c) {
            Some(&(w, d)) => w == v && d == c,
            None => {
                coords.push((v, c));
                true
            }
        }
    };
    let coord = |coords: &[(u32, (i32, i32))], v: u32| {
        coords.iter().find(|&&(w, _)| w == v).map(|&(_, c)| c)
    };
    while let Some(g) = queue.pop() {
        let gv = t.face_vertices(g);
        let ge = t.face_edges(g);
        for k in 0..3 {
            let e = ge[k] as usize;
            if t.edge_sharpness(e) > 0.0 {
                continue;
            }
            let (a, b, c) = (gv[k], gv[(k + 1) % 3], gv[(k + 2) % 3]);
            let ef = t.edge_faces(e);
            if ef.len() != 2 {
                return None;
            }
            let h = if ef[0] as usize == g { ef[1] } else { ef[0] };
            if visited.contains(&h) || !region.contains(&h) {
                continue;
            }
            let hv = t.face_vertices(h as usize);
            // Consistent orientation: h runs b → a.
            let i = hv.iter().position(|&x| x == b)?;
            if hv[(i + 1) % 3] != a {
                return None;
            }
            let d = hv[(i + 2) % 3];
            let (ca, cb, cc) = (coord(&coords, a)?, coord(&coords, b)?, coord(&coords, c)?);
            if !add(&mut coords, d, (ca.0 + cb.0 - cc.0, ca.1 + cb.1 - cc.1)) {
                return None;
            }
            visited.push(h);
            queue.push(h as usize);
        }
    }
    let at = |c: (i32, i32)| coords.iter().find(|&&(_, d)| d == c).map(|&(v, _)| v);
    let mut out: [GridPoint; 12] = std::array::from_fn(|_| Vec::new());
    for (slot, &q) in out.iter_mut().zip(&LATTICE) {
        if let Some(v) = at(q) {
            *slot = vec![(v, 1.0)];
            continue;
        }
        // A lattice triangle (q, a, b) across a sharp edge (a, b) from the real (a, b, c).
        let phantom = (0..6).find_map(|k| {
            let (d0, d1) = (LATTICE_RING[k], LATTICE_RING[(k + 1) % 6]);
            let pa = (q.0 + d0.0, q.1 + d0.1);
            let pb = (q.0 + d1.0, q.1 + d1.1);
            let pc = (pa.0 + pb.0 - q.0, pa.1 + pb.1 - q.1);
            let (a, b, c) = (at(pa)?, at(pb)?, at(pc)?);
            let e = edge_between(t, a, b)?;
            (t.edge_sharpness(e) > 0.0).then(|| vec![(a, 1.0), (b, 1.0), (c, -1.0)])
        })?;
        *slot = phantom;
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a boundary triangle of a regular grid the phantom-point patch follows the Loop
    /// boundary curve, the uniform cubic B-spline of the boundary vertices: at the middle of
    /// the boundary edge b1 b2 it is (b0 + 23 b1 + 23 b2 + b3) / 48.
    #[test]
    fn boundary_patch_follows_the_cubic_b_spline_boundary() {
        let (grid, id) = regular_grid(3);
        let r = Refinement::new(&grid, Scheme::Loop, &Options::default(), 0).unwrap();
        let (t, rules) = (r.topology(0), r.vertex_rules(0));
        let f = (0..t.num_faces())
            .find(|&f| t.face_vertices(f) == [id(0, -3), id(1, -3), id(0, -2)])
            .unwrap();
        let grid_points = loop_sharp_regular(t, rules, f).expect("a regular boundary patch");
        assert!(grid_points.iter().any(|g| g.len() == 3), "no phantom point");
        // A curved surface over the grid: z = x² − x y³ + 0.3 y.
        let pos = |i: i32, j: i32| {
            let (x, y) = (f64::from(i), f64::from(j));
            DVec3::new(x, y, x * x - x * y * y * y + 0.3 * y)
        };
        let pts: Vec<DVec3> = (0..grid.num_vertices())
            .map(|k| pos((k % 7) as i32 - 3, (k / 7) as i32 - 3))
            .collect();
        let cp: Vec<DVec3> = grid_points
            .iter()
            .map(|g| {
                g.iter()
                    .fold(DVec3::ZERO, |a, &(v, w)| a + w * pts[v as usize])
            })
            .collect();
        let p = box_spline().unwrap().evaluate(&cp, 0.5, 0.0);
        let expected = (pos(-1, -3) + 23.0 * pos(0, -3) + 23.0 * pos(1, -3) + pos(2, -3)) / 48.0;
        assert!(
            (p.position - expected).length() < 1e-13,
            "{p:?} vs {expected}"
        );
    }

    #[test]
    fn box_spline_is_a_partition_of_unity_and_reproduces_linears() {
        let b = box_spline().unwrap();
        for &(u, v) in &[
            (0.0, 0.0),
            (0.3, 0.2),
            (1.0, 0.0),
            (0.1, 0.85),
            (1.0 / 3.0, 1.0 / 3.0),
        ] {
            let w = b.weights(u, v);
            assert!((w[0].iter().sum::<f64>() - 1.0).abs() < 1e-12);
            for d in 1..6 {
                assert!(w[d].iter().sum::<f64>().abs() < 1e-10, "derivative {d}");
            }
        }
    }

    fn points(k: usize) -> Vec<DVec3> {
        (0..k)
            .map(|i| {
                let x = i as f64;
                DVec3::new((0.7 * x).sin(), (1.3 * x).cos(), 0.1 * x + (2.1 * x).sin())
            })
            .collect()
    }

    #[test]
    fn eigenbasis_equals_repeated_subdivision_and_reaches_the_limit_mask() {
        for n in [3, 4, 5, 7, 9, 12] {
            let m = LoopCornerMatrices::new(n).unwrap();
            // At valence 3 the matrix has a Jordan block (Stam 1998 notes it for Loop), so
            // its eigenvectors do not reproduce it and evaluation subdivides instead.
            assert_eq!(m.uses_eigenbasis(), n != 3, "valence {n}");
            let cp = points(n + 6);
            let eig = m.project(&cp);
            let pts = Projected::Points(cp.clone());
            for &(u, v) in &[(0.6, 0.2), (0.1, 0.3), (0.01, 0.004), (3e-5, 1e-5)] {
                let a = m.evaluate(&eig, u, v).unwrap();
                let b = m.evaluate(&pts, u, v).unwrap();
                assert!(
                    (a.position - b.position).length() < 1e-12,
                    "n={n} ({u},{v})"
                );
                assert!(
                    (a.du - b.du).length() < 1e-9 * (1.0 + b.du.length()) / (u + v),
                    "n={n}"
                );
            }
            let mask = crate::limit_masks::masks::loop_smooth(n).position;
            let mut limit = mask.vertex * cp[0];
            for i in 0..n {
                limit += mask.edges[i] * cp[1 + i];
            }
            let near = m.evaluate(&eig, 1e-100, 1e-100).unwrap().position;
            assert!((near - limit).length() < 1e-13, "n={n}: {near} vs {limit}");
        }
    }

    #[test]
    fn valence_six_corner_patch_is_the_box_spline() {
        let m = LoopCornerMatrices::new(6).unwrap();
        let cp = points(12);
        let b = box_spline().unwrap();
        for &(u, v) in &[(0.3, 0.2), (0.05, 0.01), (0.5, 0.5), (0.9, 0.05)] {
            let a = m.evaluate(&m.project(&cp), u, v).unwrap();
            let e = b.evaluate(&cp, u, v);
            assert!((a.position - e.position).length() < 1e-12, "({u},{v})");
            assert!((a.du - e.du).length() < 1e-9, "({u},{v})");
        }
    }
}

#[cfg(test)]
mod first_derivative_tests {
    use super::*;

    #[test]
    fn first_derivatives_equal_the_full_evaluation() {
        let basis = box_spline().unwrap();
        let cp: [DVec3; 12] = std::array::from_fn(|k| {
            let x = k as f64;
            DVec3::new((0.9 * x).sin(), (1.7 * x).cos(), 0.05 * x * x)
        });
        for &(u, v) in &[(0.0, 0.0), (0.2, 0.3), (1.0, 0.0), (0.4, 0.6)] {
            let full = basis.evaluate(&cp, u, v);
            let (p, du, dv) = basis.evaluate_first(&cp, u, v);
            assert!((p - full.position).length() < 1e-14);
            assert!((du - full.du).length() < 1e-13);
            assert!((dv - full.dv).length() < 1e-13);
        }
    }
}
