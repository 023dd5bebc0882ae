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
use subd_schemes::{Options, Refinement, Scheme};

use crate::LimitError;
use crate::patch::{SurfacePoint, face_ring};
use crate::stam::{PerValence, Projected, SubpatchSubdivision, cached, steps_to_regular};
use crate::table::LimitStencilTable;

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
    let mut m = [[0.0; 15]; 6];
    let pw = |x: f64, k: i32| if k < 0 { 0.0 } else { x.powi(k) };
    let mut k = 0;
    for d in 0..=4i32 {
        for b in 0..=d {
            let a = d - b;
            let (af, bf) = (f64::from(a), f64::from(b));
            m[0][k] = pw(u, a) * pw(v, b);
            m[1][k] = af * pw(u, a - 1) * pw(v, b);
            m[2][k] = bf * pw(u, a) * pw(v, b - 1);
            m[3][k] = af * (af - 1.0) * pw(u, a - 2) * pw(v, b);
            m[4][k] = af * bf * pw(u, a - 1) * pw(v, b - 1);
            m[5][k] = bf * (bf - 1.0) * pw(u, a) * pw(v, b - 2);
            k += 1;
        }
    }
    m
}

/// The 12 quartic box-spline basis functions of the regular patch (monomial coefficients).
#[derive(Debug)]
pub struct BoxSpline {
    coeffs: [[f64; 15]; 12],
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
        let coeffs = std::array::from_fn(|k| std::array::from_fn(|m| sol[(m, k)]));
        Ok(BoxSpline { coeffs })
    }

    /// Weights of the 12 control points for position and the five derivatives at (u, v).
    pub fn weights(&self, u: f64, v: f64) -> [[f64; 12]; 6] {
        let m = monomials(u, v);
        let mut w = [[0.0; 12]; 6];
        for d in 0..6 {
            for k in 0..12 {
                w[d][k] = self.coeffs[k].iter().zip(&m[d]).map(|(c, x)| c * x).sum();
            }
        }
        w
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
        let out = self.sub.combine(c, steps, sub, &basis.weights(s, t));
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

#[cfg(test)]
mod tests {
    use super::*;

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
            let mask = crate::masks::loop_smooth(n).position;
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
