//! Eigen analysis of the local subdivision matrix around one vertex (the subdivision lecture notes
//! §5).
//!
//! The matrix is not written down by hand: it is read off the refinement itself. A small
//! mesh made of the vertex's 1-ring is refined once with `subd-schemes`, and the stencil rows
//! of the children that form the child's 1-ring (the vertex's child, the children of its
//! edges and, for Catmull-Clark, of its faces) give the matrix `S` with
//! `ring_{k+1} = S · ring_k`. Its spectrum is computed with `faer`'s general (non-symmetric)
//! eigen solver. The dominant left eigenvector (eigenvalue 1) is the limit-position mask; the
//! left eigenvectors of the two subdominant eigenvalues span the tangent masks.
//!
//! Ring order: `[v, e_0 … e_{n−1}, f_0 … f_{n−1}]` for Catmull-Clark (size 2n + 1; `f_i` is
//! the vertex opposite `v` in the quad between `e_i` and `e_{i+1}`) and `[v, e_0 … e_{n−1}]`
//! for Loop (size n + 1).

use std::f64::consts::PI;

use faer::linalg::solvers::Solve;
use faer::{Mat, c64};
use subd_mesh::{Topology, TopologyBuilder};
use subd_schemes::{Options, Refinement, Scheme};

use crate::LimitError;
use crate::limit_masks::masks::{LimitMask, RingMask};

/// Features of the centre vertex of a local ring.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RingFeature {
    /// A smooth interior vertex.
    Smooth,
    /// An interior vertex with one infinitely sharp edge (edge 0).
    Dart,
}

/// The 1-ring mesh around a centre of valence `n`: quads (Catmull-Clark) or triangles (Loop).
fn ring_mesh(scheme: &Scheme, n: usize, feature: RingFeature) -> Result<Topology, LimitError> {
    let (sizes, verts, nv): (Vec<u32>, Vec<u32>, usize) = match scheme {
        Scheme::Loop => {
            let f = (0..n).flat_map(|i| [0, 1 + i as u32, 1 + ((i + 1) % n) as u32]);
            (vec![3; n], f.collect(), n + 1)
        }
        _ => {
            let f = (0..n).flat_map(|i| {
                [
                    0,
                    1 + i as u32,
                    (n + 1 + i) as u32,
                    1 + ((i + 1) % n) as u32,
                ]
            });
            (vec![4; n], f.collect(), 2 * n + 1)
        }
    };
    let mut t = TopologyBuilder::new(nv)
        .build(&sizes, &verts)
        .map_err(|e| LimitError::Analysis(format!("ring mesh of valence {n}: {e}")))?;
    if feature == RingFeature::Dart {
        let e = t
            .find_edge(0, 1)
            .ok_or_else(|| LimitError::Analysis("ring mesh has no spoke edge".into()))?;
        t.set_edge_sharpness(e as usize, subd_mesh::tags::SHARPNESS_INFINITE);
    }
    Ok(t)
}

/// The local subdivision matrix `S` (ring order as in the module docs) of a centre of
/// valence `n ≥ 2` under `scheme` (Catmull-Clark or Loop), read off one refinement step.
pub fn ring_matrix(
    scheme: &Scheme,
    n: usize,
    feature: RingFeature,
) -> Result<Mat<f64>, LimitError> {
    if n < 2 || *scheme == Scheme::Bilinear {
        return Err(LimitError::Analysis(format!(
            "no local subdivision matrix for {scheme:?} at valence {n}"
        )));
    }
    let t = ring_mesh(scheme, n, feature)?;
    let r = Refinement::new(&t, scheme.clone(), &Options::default(), 1)
        .map_err(|e| LimitError::Analysis(e.to_string()))?;
    let st = r.stencils(1);
    let nv = t.num_vertices();
    let size = if *scheme == Scheme::Loop {
        n + 1
    } else {
        2 * n + 1
    };
    // Child of each ring position: the centre stays 0; spoke e_i's child is the child of
    // edge (0, 1+i); f_i's is the child of face i.
    let edge_child_base = if *scheme == Scheme::Loop {
        nv
    } else {
        nv + t.num_faces()
    };
    let mut child = vec![0usize; size];
    for i in 0..n {
        let e = t
            .find_edge(0, 1 + i as u32)
            .ok_or_else(|| LimitError::Analysis("ring mesh has no spoke edge".into()))?;
        child[1 + i] = edge_child_base + e as usize;
        if *scheme != Scheme::Loop {
            child[1 + n + i] = nv + i;
        }
    }
    let mut s = Mat::<f64>::zeros(size, size);
    for (row, &c) in child.iter().enumerate() {
        let (idx, w) = st.row(c);
        for (&j, &wj) in idx.iter().zip(w) {
            let j = j as usize;
            if j >= size {
                return Err(LimitError::Analysis(format!(
                    "ring child {c} reaches outside the ring (vertex {j})"
                )));
            }
            s[(row, j)] += wj;
        }
    }
    Ok(s)
}

/// Eigenvalues of `s`, largest modulus first.
pub fn eigenvalues(s: &Mat<f64>) -> Result<Vec<c64>, LimitError> {
    let mut v = s
        .eigenvalues()
        .map_err(|e| LimitError::Analysis(format!("eigenvalues: {e:?}")))?;
    v.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    Ok(v)
}

/// The left eigenvector of `s` for eigenvalue 1, scaled to sum 1: the limit-position mask
/// (solved as `(Sᵀ − I) l = 0` with the last equation replaced by `Σ l = 1`).
pub fn dominant_left_eigenvector(s: &Mat<f64>) -> Result<Vec<f64>, LimitError> {
    let m = s.nrows();
    let mut a = Mat::<f64>::from_fn(m, m, |i, j| s[(j, i)] - if i == j { 1.0 } else { 0.0 });
    for j in 0..m {
        a[(m - 1, j)] = 1.0;
    }
    let mut rhs = Mat::<f64>::zeros(m, 1);
    rhs[(m - 1, 0)] = 1.0;
    let x = a.full_piv_lu().solve(&rhs);
    let l: Vec<f64> = (0..m).map(|i| x[(i, 0)]).collect();
    if l.iter().any(|v| !v.is_finite()) {
        return Err(LimitError::Analysis(
            "singular dominant eigenproblem".into(),
        ));
    }
    Ok(l)
}

/// Real left eigenvectors of `s` other than the dominant one, grouped by the modulus of their
/// eigenvalue, largest first (a complex pair gives its real and imaginary parts): the
/// candidates for the tangent functionals.
fn left_vectors_by_modulus(s: &Mat<f64>) -> Result<Vec<Vec<Vec<f64>>>, LimitError> {
    let m = s.nrows();
    let st = Mat::<f64>::from_fn(m, m, |i, j| s[(j, i)]);
    let evd = st
        .eigen()
        .map_err(|e| LimitError::Analysis(format!("eigen decomposition: {e:?}")))?;
    let vals = evd.S();
    let vecs = evd.U();
    let mut rest: Vec<usize> = (0..m)
        .filter(|&k| (vals[k] - c64::new(1.0, 0.0)).norm() > 1e-9)
        .collect();
    rest.sort_by(|&a, &b| vals[b].norm().total_cmp(&vals[a].norm()));
    let col = |k: usize, imag: bool| -> Vec<f64> {
        (0..m)
            .map(|i| {
                let z = vecs[(i, k)];
                if imag { z.im } else { z.re }
            })
            .collect()
    };
    let mut groups: Vec<(f64, Vec<Vec<f64>>)> = Vec::new();
    for &k in &rest {
        let r = vals[k].norm();
        if groups.last().is_none_or(|g| r < g.0 * (1.0 - 1e-9)) {
            groups.push((r, Vec::new()));
        }
        let g = &mut groups.last_mut().expect("just pushed").1;
        g.push(col(k, false));
        if vals[k].im.abs() > 1e-12 {
            g.push(col(k, true));
        }
    }
    Ok(groups.into_iter().map(|g| g.1).collect())
}

/// A planar embedding of the ring (the spoke ends on the unit circle, the diagonal vertices
/// at the sum of their neighbours), used to orient numerically computed tangent masks.
fn planar_ring(scheme: &Scheme, n: usize) -> Vec<[f64; 2]> {
    let dir = |i: usize| {
        let t = 2.0 * PI * (i % n) as f64 / n as f64;
        [t.cos(), t.sin()]
    };
    let mut p = vec![[0.0, 0.0]];
    p.extend((0..n).map(dir));
    if *scheme != Scheme::Loop {
        p.extend((0..n).map(|i| {
            let (a, b) = (dir(i), dir(i + 1));
            // For valence 2 the two spoke directions cancel: push the diagonal off the line.
            let off = if n == 2 {
                [0.0, if i == 0 { 1.0 } else { -1.0 }]
            } else {
                [0.0, 0.0]
            };
            [a[0] + b[0] + off[0], a[1] + b[1] + off[1]]
        }));
    }
    p
}

/// Limit masks of a ring by eigen analysis: position from the dominant left eigenvector,
/// tangents from the subdominant pair, combined so that on the planar ring they give the
/// x and y directions (tangent 1 along edge 0, tangent 2 counter-clockwise from it).
pub fn ring_limit_mask(
    scheme: &Scheme,
    n: usize,
    feature: RingFeature,
) -> Result<LimitMask, LimitError> {
    let s = ring_matrix(scheme, n, feature)?;
    let pos = dominant_left_eigenvector(&s)?;
    let groups = left_vectors_by_modulus(&s)?;
    let plane = planar_ring(scheme, n);
    let apply = |w: &[f64]| {
        w.iter().zip(&plane).fold([0.0, 0.0], |acc, (wi, p)| {
            [acc[0] + wi * p[0], acc[1] + wi * p[1]]
        })
    };
    // The tangent functionals: the eigenvectors of the largest moduli after 1 that span the
    // plane. A double subdominant eigenvalue (smooth) or two distinct ones (darts) give them
    // at once; at valence 2 the subdominant modulus is shared with a symmetric vector that
    // does not move the centre in the plane, and at a valence-2 dart the two largest both
    // move it along the crease, so smaller moduli are taken in until a pair spans the plane.
    let mut candidates: Vec<Vec<f64>> = Vec::new();
    let mut best = (0.0f64, 0, 0);
    let mut responses: Vec<[f64; 2]> = Vec::new();
    for g in groups {
        candidates.extend(g);
        responses = candidates.iter().map(|c| apply(c)).collect();
        for i in 0..candidates.len() {
            for j in i + 1..candidates.len() {
                let (p, q) = (responses[i], responses[j]);
                // Eigenvectors come normalised, so the raw determinant compares fairly.
                let det = (p[0] * q[1] - p[1] * q[0]).abs();
                if det > best.0 {
                    best = (det, i, j);
                }
            }
        }
        if best.0 >= 1e-9 {
            break;
        }
    }
    if best.0 < 1e-9 {
        return Err(LimitError::Analysis(format!(
            "degenerate tangent plane at valence {n}"
        )));
    }
    let (a, b) = (&candidates[best.1], &candidates[best.2]);
    let (pa, pb) = (responses[best.1], responses[best.2]);
    // [t1; t2] = M⁻¹ [a; b] with M = [[pa.x, pa.y], [pb.x, pb.y]]ᵀ so that t1 ↦ x, t2 ↦ y.
    let det = pa[0] * pb[1] - pa[1] * pb[0];
    let inv = [[pb[1] / det, -pb[0] / det], [-pa[1] / det, pa[0] / det]];
    let combine = |c: [f64; 2]| -> Vec<f64> {
        a.iter()
            .zip(b.iter())
            .map(|(x, y)| c[0] * x + c[1] * y)
            .collect()
    };
    // Rows of inv: t1 = inv[0][0]·a + inv[1][0]·b gives x; t2 the same with column 1.
    let t1 = combine([inv[0][0], inv[1][0]]);
    let t2 = combine([inv[0][1], inv[1][1]]);
    let split = |mut w: Vec<f64>| -> RingMask {
        // Round-off from the eigen solver on weights that are zero by symmetry.
        let big = w.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        w.iter_mut()
            .filter(|x| x.abs() < 1e-14 * big)
            .for_each(|x| *x = 0.0);
        let faces = if *scheme == Scheme::Loop {
            Vec::new()
        } else {
            w[1 + n..].to_vec()
        };
        RingMask {
            vertex: w[0],
            edges: w[1..=n].to_vec(),
            faces,
        }
    };
    Ok(LimitMask {
        position: split(pos),
        tangent1: split(t1),
        tangent2: split(t2),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::limit_masks::masks;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn catmark_subdominant_matches_closed_form() {
        for n in 3..=16 {
            let s = ring_matrix(&Scheme::CatmullClark, n, RingFeature::Smooth).unwrap();
            let ev = eigenvalues(&s).unwrap();
            assert!(close(ev[0].re, 1.0, 1e-12), "n={n} {:?}", ev[0]);
            let lam = masks::catmark_subdominant(n);
            assert!(close(ev[1].norm(), lam, 1e-10), "n={n}: {} vs {lam}", ev[1]);
            assert!(close(ev[2].norm(), lam, 1e-10), "n={n}: {} vs {lam}", ev[2]);
        }
    }

    #[test]
    fn catmark_valence_four_spectrum() {
        let s = ring_matrix(&Scheme::CatmullClark, 4, RingFeature::Smooth).unwrap();
        let ev: Vec<f64> = eigenvalues(&s).unwrap().iter().map(|z| z.re).collect();
        let expect = [1.0, 0.5, 0.5, 0.25];
        for (k, e) in expect.iter().enumerate() {
            assert!(close(ev[k], *e, 1e-12), "{ev:?}");
        }
    }

    #[test]
    fn loop_subdominant_matches_closed_form() {
        for n in 3..=16 {
            let s = ring_matrix(&Scheme::Loop, n, RingFeature::Smooth).unwrap();
            let ev = eigenvalues(&s).unwrap();
            assert!(close(ev[0].re, 1.0, 1e-12));
            let lam = masks::loop_subdominant(n);
            assert!(close(ev[1].norm(), lam, 1e-10), "n={n}: {} vs {lam}", ev[1]);
        }
    }

    #[test]
    fn dominant_left_eigenvector_is_the_closed_form_limit_mask() {
        for n in 3..=12 {
            let s = ring_matrix(&Scheme::CatmullClark, n, RingFeature::Smooth).unwrap();
            let l = dominant_left_eigenvector(&s).unwrap();
            let m = masks::catmark_smooth(n).position;
            assert!(close(l[0], m.vertex, 1e-13), "n={n}");
            for i in 0..n {
                assert!(close(l[1 + i], m.edges[i], 1e-13));
                assert!(close(l[1 + n + i], m.faces[i], 1e-13));
            }
            let s = ring_matrix(&Scheme::Loop, n, RingFeature::Smooth).unwrap();
            let l = dominant_left_eigenvector(&s).unwrap();
            let m = masks::loop_smooth(n).position;
            assert!(close(l[0], m.vertex, 1e-13), "loop n={n}");
            for i in 0..n {
                assert!(close(l[1 + i], m.edges[i], 1e-13));
            }
        }
    }

    #[test]
    fn numeric_tangents_span_the_closed_form_tangent_plane() {
        // On a non-planar ring, the normal from the eigen tangents equals the closed-form one.
        for n in 3..=9 {
            let num = ring_limit_mask(&Scheme::CatmullClark, n, RingFeature::Smooth).unwrap();
            let cf = masks::catmark_smooth(n);
            let pts: Vec<[f64; 3]> = (0..2 * n + 1)
                .map(|i| {
                    let x = i as f64;
                    [
                        x.sin() * 1.3 + 0.1 * x,
                        (0.7 * x).cos(),
                        (1.9 * x).sin() * 0.4,
                    ]
                })
                .collect();
            let ap = |m: &RingMask| -> [f64; 3] {
                let mut acc = [0.0; 3];
                let mut add = |w: f64, p: [f64; 3]| {
                    for k in 0..3 {
                        acc[k] += w * p[k];
                    }
                };
                add(m.vertex, pts[0]);
                for i in 0..n {
                    add(m.edges[i], pts[1 + i]);
                    add(m.faces[i], pts[1 + n + i]);
                }
                acc
            };
            let normal = |m: &LimitMask| {
                let (a, b) = (ap(&m.tangent1), ap(&m.tangent2));
                let c = [
                    a[1] * b[2] - a[2] * b[1],
                    a[2] * b[0] - a[0] * b[2],
                    a[0] * b[1] - a[1] * b[0],
                ];
                let l = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
                [c[0] / l, c[1] / l, c[2] / l]
            };
            let (x, y) = (normal(&num), normal(&cf));
            for k in 0..3 {
                assert!(close(x[k], y[k], 1e-10), "n={n}: {x:?} vs {y:?}");
            }
        }
    }
}
