//! Exact evaluation of a Catmull-Clark patch with one extraordinary corner: Stam's eigenbasis
//! method (Stam 1998, "Exact evaluation of Catmull-Clark subdivision surfaces at arbitrary
//! parameter values"; Li et al. 2008 §2.1).
//!
//! Around an extraordinary vertex of valence n the patch has 2n + 8 control points
//! ([`crate::patch`] gives their order). One subdivision step maps them to the 2n + 8 control
//! points of the quarter patch at the same corner (matrix `A`) and to the 16 B-spline control
//! points of each of the three other quarters (matrices `Ā_k`, k = 1, 2, 3), which are
//! regular. A point at (s, t) with `max(s, t)` in `[2^-m, 2^(1-m))` lies in quarter k of the
//! corner patch after `m − 1` steps, so
//!
//! `P(s, t) = b(s', t')ᵀ · Ā_k · A^(m−1) · C = Σ_i λ_i^(m−1) · (b(s', t')ᵀ Ā_k v_i) · ĉ_i`
//!
//! with `A = V Λ V⁻¹` and `ĉ = V⁻¹ C` — a sum over eigenvalues, not m matrix products.
//!
//! The matrices are read off one step of the refinement code on a synthetic neighbourhood
//! (no hand-written matrix, no data file), decomposed with `faer`, and cached per valence.
//! Where the eigenvectors are ill-conditioned (a defective `A`) the evaluator applies `A`
//! directly `m − 1` times instead, which is the same value computed another way.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use faer::linalg::solvers::Solve;
use faer::{Mat, c64};
use glam::DVec3;
use subd_mesh::TopologyBuilder;
use subd_schemes::{Options, Refinement, Scheme};

use crate::LimitError;
use crate::evaluation::patch::{
    Derivatives, REGULAR_GRID, SurfacePoint, bicubic_weights, corner_patch,
};

/// Subdivision matrices of the corner patch of valence `n`, and their eigen decomposition.
#[derive(Debug)]
pub struct CornerPatchMatrices {
    /// Valence.
    pub n: usize,
    /// `A`, (2n + 8) × (2n + 8) (the corner quarter's control points from the patch's), the
    /// three `Ā_k`, 16 × (2n + 8) (the B-spline control points of quarters k = 1, 2, 3, rows
    /// in grid order), and their eigenbasis.
    pub sub: SubpatchSubdivision<16>,
}

/// One subdivision step of a patch with an extraordinary corner: `A` maps its K control
/// points to those of the corner sub-patch, `Ā_k` (k = 1, 2, 3) to the G control points of
/// the three regular sub-patches; with the eigenbasis of `A` when it reproduces `A`. Shared
/// by Catmull-Clark (G = 16) and Loop (G = 12).
#[derive(Debug)]
pub struct SubpatchSubdivision<const G: usize> {
    /// `A`, K × K.
    pub a: Mat<f64>,
    /// `Ā_k`, G × K, for k = 1, 2, 3 (index k − 1).
    pub abar: [Mat<f64>; 3],
    eigen: Option<Eigenbasis<G>>,
}

#[derive(Debug)]
struct Eigenbasis<const G: usize> {
    /// Eigenvalues λ_i.
    values: Vec<c64>,
    /// `Ā_k V` per sub-patch: for each eigenvector i, its G control weights.
    phi: [Vec<[c64; G]>; 3],
    /// `V⁻¹`, K × K.
    v_inv: Mat<c64>,
}

/// The synthetic neighbourhood: the 1-ring of a quad whose corner 0 has valence n, vertices
/// numbered as the corner-patch control points.
fn synthetic_faces(n: usize) -> Vec<u32> {
    let e = |i: usize| (1 + 2 * (i % n)) as u32;
    let f = |i: usize| (2 + 2 * (i % n)) as u32;
    let x = |k: usize| (2 * n + 1 + k) as u32;
    let mut faces = Vec::with_capacity(4 * (n + 5));
    // Face 0 is the patch's own face (0, e0, f0, e1).
    for i in 0..n {
        faces.extend([0, e(i), f(i), e(i + 1)]);
    }
    faces.extend([f(n - 1), x(0), x(1), e(0)]); // below-right
    faces.extend([e(0), x(1), x(2), f(0)]); // right
    faces.extend([f(0), x(2), x(3), x(4)]); // corner
    faces.extend([e(1), f(0), x(4), x(5)]); // top
    faces.extend([f(1), e(1), x(5), x(6)]); // top-left
    faces
}

impl CornerPatchMatrices {
    /// Builds the matrices for valence `n ≥ 2` by refining the synthetic neighbourhood once.
    pub fn new(n: usize) -> Result<CornerPatchMatrices, LimitError> {
        if n < 2 {
            return Err(LimitError::Analysis(format!(
                "corner patches need valence ≥ 2, not {n}"
            )));
        }
        let k = 2 * n + 8;
        let faces = synthetic_faces(n);
        let topo = TopologyBuilder::new(k)
            .build(&vec![4; faces.len() / 4], &faces)
            .map_err(|e| LimitError::Analysis(format!("synthetic patch of valence {n}: {e}")))?;
        let r = Refinement::new(&topo, Scheme::CatmullClark, &Options::default(), 1)?;
        let child = r.topology(1);
        let st = r.stencils(1);
        let rows = |ids: &[u32]| -> Result<Mat<f64>, LimitError> {
            let mut m = Mat::<f64>::zeros(ids.len(), k);
            for (row, &id) in ids.iter().enumerate() {
                let (idx, w) = st.row(id as usize);
                for (&j, &wj) in idx.iter().zip(w) {
                    m[(row, j as usize)] += wj;
                }
            }
            Ok(m)
        };
        // Children of face 0 are child faces 0..4, child j holding parent corner j.
        let bad = || LimitError::Analysis(format!("synthetic patch of valence {n} is not regular"));
        let a = rows(&corner_patch(child, 0, 0).ok_or_else(bad)?)?;
        let quarter = |j: usize| -> Result<Mat<f64>, LimitError> {
            let cp = corner_patch(child, j, 0).ok_or_else(bad)?;
            let grid: Vec<u32> = REGULAR_GRID.iter().map(|&g| cp[g]).collect();
            rows(&grid)
        };
        let abar = [quarter(1)?, quarter(2)?, quarter(3)?];
        Ok(CornerPatchMatrices {
            n,
            sub: SubpatchSubdivision::new(a, abar),
        })
    }

    /// Whether evaluation uses the eigenbasis (`false`: repeated application of `A`).
    pub fn uses_eigenbasis(&self) -> bool {
        self.sub.uses_eigenbasis()
    }

    /// Eigenvalues of `A`, largest modulus first (empty when the decomposition was rejected).
    pub fn eigenvalues(&self) -> Vec<c64> {
        self.sub.eigenvalues()
    }

    /// The surface point at corner-patch parameters (s, t) ∈ [0, 1]², (0, 0) at the
    /// extraordinary vertex, from the 2n + 8 control points `cp`. `(0, 0)` itself is not a
    /// patch point of any level; the caller takes the limit mask there.
    pub fn evaluate(&self, cp: &[DVec3], s: f64, t: f64) -> SurfacePoint {
        self.evaluate_with(cp, s, t, true)
    }

    /// [`Self::evaluate`] choosing the method: the eigenbasis or `A` applied `m − 1` times.
    pub fn evaluate_with(&self, cp: &[DVec3], s: f64, t: f64, eigen: bool) -> SurfacePoint {
        self.evaluate_projected(&self.sub.project(cp, eigen), s, t)
    }

    /// The control points prepared for evaluation: projected on the eigenbasis
    /// (`ĉ = V⁻¹ C`) when there is one. Do this once per patch, then evaluate many points.
    pub fn project(&self, cp: &[DVec3]) -> Projected {
        self.sub.project(cp, true)
    }

    /// [`Self::evaluate`] from [`Self::project`]ed control points.
    pub fn evaluate_projected(&self, c: &Projected, s: f64, t: f64) -> SurfacePoint {
        self.evaluate_projected_to(c, s, t, Derivatives::Second)
    }

    /// [`Self::evaluate_projected`] up to the derivatives `d` (the others zero).
    pub(crate) fn evaluate_projected_to(
        &self,
        c: &Projected,
        s: f64,
        t: f64,
        d: Derivatives,
    ) -> SurfacePoint {
        debug_assert!(s > 0.0 || t > 0.0);
        let (steps, scale) = steps_to_regular(s.max(t));
        let (s1, t1) = (s * scale, t * scale);
        let (quarter, u, v) = if t1 < 0.5 {
            (0, 2.0 * s1 - 1.0, 2.0 * t1)
        } else if s1 >= 0.5 {
            (1, 2.0 * s1 - 1.0, 2.0 * t1 - 1.0)
        } else {
            (2, 2.0 * s1, 2.0 * t1 - 1.0)
        };
        let w = bicubic_weights(u, v);
        let out = self.sub.combine(c, steps, quarter, &w[..d.rows()]);
        SurfacePoint {
            position: out[0],
            du: out[1],
            dv: out[2],
            duu: out[3],
            duv: out[4],
            dvv: out[5],
        }
        .scaled(2.0 * scale)
    }
}

/// The number of steps m − 1 after which a point at "distance" `p` from the extraordinary
/// corner (max(s, t) for quads, u + v for triangles) lies in a regular sub-patch, i.e.
/// `p · 2^(m−1)` ∈ [1/2, 1], and that power of two.
pub(crate) fn steps_to_regular(p: f64) -> (i32, f64) {
    let mut steps = (-p.log2()).floor().max(0.0) as i32;
    let mut scale = 2f64.powi(steps);
    if p * scale > 1.0 {
        steps -= 1;
        scale *= 0.5;
    } else if p * scale < 0.5 {
        steps += 1;
        scale *= 2.0;
    }
    (steps, scale)
}

impl<const G: usize> SubpatchSubdivision<G> {
    /// Stores `A` and `Ā_k` and decomposes `A`.
    pub fn new(a: Mat<f64>, abar: [Mat<f64>; 3]) -> Self {
        let eigen = Eigenbasis::new(&a, &abar);
        SubpatchSubdivision { a, abar, eigen }
    }

    /// Whether evaluation uses the eigenbasis (`false`: repeated application of `A`).
    pub fn uses_eigenbasis(&self) -> bool {
        self.eigen.is_some()
    }

    /// Eigenvalues of `A`, largest modulus first (empty when the decomposition was rejected).
    pub fn eigenvalues(&self) -> Vec<c64> {
        let mut v = self
            .eigen
            .as_ref()
            .map_or_else(Vec::new, |e| e.values.clone());
        v.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
        v
    }

    /// Control points prepared for evaluation: projected on the eigenbasis when there is one
    /// and `eigen` asks for it, else kept for repeated subdivision.
    pub fn project(&self, cp: &[DVec3], eigen: bool) -> Projected {
        match (&self.eigen, eigen) {
            (Some(e), true) => Projected::Eigen(
                (0..cp.len())
                    .map(|i| {
                        cp.iter()
                            .enumerate()
                            .fold([c64::new(0.0, 0.0); 3], |mut acc, (j, p)| {
                                let z = e.v_inv[(i, j)];
                                acc[0] += z * p.x;
                                acc[1] += z * p.y;
                                acc[2] += z * p.z;
                                acc
                            })
                    })
                    .collect(),
            ),
            _ => Projected::Points(cp.to_vec()),
        }
    }

    /// Position and derivatives (in sub-patch parameters) after `steps` subdivisions, in
    /// regular sub-patch `sub` (0..3 for k = 1..3), from its control weights `w`: one output
    /// per row of `w` (position, ∂u, ∂v, then the second derivatives), the rest zero.
    pub fn combine(&self, c: &Projected, steps: i32, sub: usize, w: &[[f64; G]]) -> [DVec3; 6] {
        let mut out = [DVec3::ZERO; 6];
        match c {
            Projected::Eigen(chat) => {
                let e = self
                    .eigen
                    .as_ref()
                    .expect("eigen projections come from this eigenbasis");
                let one = c64::new(1.0, 0.0);
                for ((lam, phi), ch) in e.values.iter().zip(&e.phi[sub]).zip(chat) {
                    let lp = lam.powi(steps);
                    // The eigenvalue-1 term is the constant (the limit point): derivatives
                    // of a constant are exactly zero, and leaving it out keeps derivatives
                    // near the vertex to full relative precision (its round-off would be
                    // scaled up by 2^m).
                    let outputs = if *lam == one { 1 } else { w.len() };
                    for (o, wd) in out.iter_mut().zip(w).take(outputs) {
                        let b = phi
                            .iter()
                            .zip(wd)
                            .fold(c64::new(0.0, 0.0), |acc, (f, &x)| acc + *f * x);
                        let f = lp * b;
                        *o += DVec3::new((f * ch[0]).re, (f * ch[1]).re, (f * ch[2]).re);
                    }
                }
            }
            Projected::Points(cp) => {
                let mut c = cp.clone();
                let mut next = vec![DVec3::ZERO; c.len()];
                for _ in 0..steps {
                    for (i, o) in next.iter_mut().enumerate() {
                        *o = (0..c.len()).fold(DVec3::ZERO, |acc, j| acc + self.a[(i, j)] * c[j]);
                    }
                    std::mem::swap(&mut c, &mut next);
                }
                let ab = &self.abar[sub];
                for g in 0..G {
                    let q = (0..c.len()).fold(DVec3::ZERO, |acc, j| acc + ab[(g, j)] * c[j]);
                    for (o, wd) in out.iter_mut().zip(w) {
                        *o += wd[g] * q;
                    }
                }
            }
        }
        out
    }
}

/// Control points of a corner patch prepared for evaluation ([`CornerPatchMatrices::project`]).
#[derive(Clone, Debug)]
pub enum Projected {
    /// Coordinates in the eigenbasis, `ĉ = V⁻¹ C` (x, y, z).
    Eigen(Vec<[c64; 3]>),
    /// The control points themselves (no usable eigenbasis).
    Points(Vec<DVec3>),
}

impl<const G: usize> Eigenbasis<G> {
    /// `A = V Λ V⁻¹`, kept only when it reproduces `A` and `V` is well conditioned.
    fn new(a: &Mat<f64>, abar: &[Mat<f64>; 3]) -> Option<Eigenbasis<G>> {
        let k = a.nrows();
        let evd = a.eigen().ok()?;
        // The dominant eigenvalue is exactly 1 (affine invariance); the solver's 1 ± ε raised
        // to the m-th power would drift at deep levels.
        let values: Vec<c64> = (0..k)
            .map(|i| evd.S()[i])
            .map(|z| {
                if (z - c64::new(1.0, 0.0)).norm() < 1e-9 {
                    c64::new(1.0, 0.0)
                } else {
                    z
                }
            })
            .collect();
        let v: Mat<c64> = evd.U().to_owned();
        let id = Mat::<c64>::from_fn(k, k, |i, j| {
            if i == j {
                c64::new(1.0, 0.0)
            } else {
                c64::new(0.0, 0.0)
            }
        });
        let v_inv = v.full_piv_lu().solve(&id);
        // Check V⁻¹ V = I and V Λ V⁻¹ = A; a defective A fails here.
        let mut err = 0.0f64;
        for i in 0..k {
            for j in 0..k {
                let mut vv = c64::new(0.0, 0.0);
                let mut rec = c64::new(0.0, 0.0);
                for l in 0..k {
                    vv += v_inv[(i, l)] * v[(l, j)];
                    rec += v[(i, l)] * values[l] * v_inv[(l, j)];
                }
                let target = if i == j { 1.0 } else { 0.0 };
                err = err.max((vv - c64::new(target, 0.0)).norm());
                err = err.max((rec - c64::new(a[(i, j)], 0.0)).norm());
            }
        }
        if err.is_nan() || err >= 1e-10 {
            return None;
        }
        let phi = std::array::from_fn(|q| {
            (0..k)
                .map(|i| {
                    std::array::from_fn(|g| {
                        (0..k).fold(c64::new(0.0, 0.0), |acc, j| {
                            acc + v[(j, i)] * abar[q][(g, j)]
                        })
                    })
                })
                .collect()
        });
        Some(Eigenbasis { values, phi, v_inv })
    }
}

/// Corner-patch matrices per valence, built on first use and shared.
pub fn corner_patch_matrices(n: usize) -> Result<Arc<CornerPatchMatrices>, LimitError> {
    static CACHE: PerValence<CornerPatchMatrices> = OnceLock::new();
    cached(&CACHE, n, CornerPatchMatrices::new)
}

/// A cache of per-valence matrices.
pub(crate) type PerValence<T> = OnceLock<Mutex<HashMap<usize, Arc<T>>>>;

/// The entry of `cache` for valence `n`, built with `build` on first use.
pub(crate) fn cached<T>(
    cache: &PerValence<T>,
    n: usize,
    build: impl FnOnce(usize) -> Result<T, LimitError>,
) -> Result<Arc<T>, LimitError> {
    let cache = cache.get_or_init(|| Mutex::new(HashMap::new()));
    let poisoned = || LimitError::Analysis("matrix cache poisoned by a panic".into());
    if let Some(m) = cache.lock().map_err(|_| poisoned())?.get(&n) {
        return Ok(m.clone());
    }
    let m = Arc::new(build(n)?);
    Ok(cache
        .lock()
        .map_err(|_| poisoned())?
        .entry(n)
        .or_insert(m)
        .clone())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::evaluation::patch::eval_bicubic;
    use crate::limit_masks::masks;

    /// Some control points.
    fn points(k: usize) -> Vec<DVec3> {
        (0..k)
            .map(|i| {
                let x = i as f64;
                DVec3::new((0.7 * x).sin(), (1.3 * x).cos(), 0.1 * x + (2.1 * x).sin())
            })
            .collect()
    }

    #[test]
    fn valence_four_is_the_bicubic_b_spline() {
        let m = CornerPatchMatrices::new(4).unwrap();
        let cp = points(16);
        let grid: [DVec3; 16] = std::array::from_fn(|g| cp[REGULAR_GRID[g]]);
        for &(s, t) in &[
            (0.3, 0.7),
            (0.01, 0.02),
            (1.0, 1.0),
            (0.9, 0.001),
            (1e-7, 3e-8),
        ] {
            let a = m.evaluate(&cp, s, t);
            let b = eval_bicubic(&grid, s, t);
            // Going down m levels scales derivatives by 2^m, and their round-off with it.
            let p = f64::max(s, t);
            let (tol1, tol2) = (1e-14 / p, 1e-14 / (p * p));
            assert!((a.position - b.position).length() < 1e-12, "{s} {t}");
            assert!(
                (a.du - b.du).length() < tol1 * (1.0 + b.du.length()),
                "{s} {t}"
            );
            assert!(
                (a.dv - b.dv).length() < tol1 * (1.0 + b.dv.length()),
                "{s} {t}"
            );
            assert!(
                (a.duv - b.duv).length() < tol2 * (1.0 + b.duv.length()),
                "{s} {t}"
            );
            assert!(
                (a.duu - b.duu).length() < tol2 * (1.0 + b.duu.length()),
                "{s} {t}"
            );
        }
    }

    #[test]
    fn eigenbasis_equals_repeated_subdivision() {
        for n in [3, 5, 6, 7, 8, 12, 20, 50] {
            let m = CornerPatchMatrices::new(n).unwrap();
            assert!(m.uses_eigenbasis(), "valence {n}: eigenbasis rejected");
            let cp = points(2 * n + 8);
            for &(s, t) in &[(0.6, 0.2), (0.1, 0.3), (0.01, 0.004), (3e-5, 1e-5)] {
                let a = m.evaluate_with(&cp, s, t, true);
                let b = m.evaluate_with(&cp, s, t, false);
                assert!(
                    (a.position - b.position).length() < 1e-12,
                    "n={n} ({s},{t})"
                );
                let scale = 1.0 + b.du.length();
                assert!((a.du - b.du).length() < 1e-10 * scale, "n={n} ({s},{t})");
            }
        }
    }

    #[test]
    fn corner_values_converge_to_the_limit_mask() {
        for n in [3, 5, 9] {
            let m = CornerPatchMatrices::new(n).unwrap();
            let cp = points(2 * n + 8);
            let mask = masks::catmark_smooth(n).position;
            let mut limit = mask.vertex * cp[0];
            for i in 0..n {
                limit += mask.edges[i] * cp[1 + 2 * i] + mask.faces[i] * cp[2 + 2 * i];
            }
            let near = m.evaluate(&cp, 1e-100, 1e-100).position;
            assert!((near - limit).length() < 1e-13, "n={n}: {near} vs {limit}");
        }
    }

    #[test]
    fn subdominant_eigenvalue_matches_closed_form() {
        for n in [3, 5, 6, 10] {
            let m = CornerPatchMatrices::new(n).unwrap();
            let ev = m.eigenvalues();
            assert!((ev[0].re - 1.0).abs() < 1e-12);
            let lam = masks::catmark_subdominant(n);
            assert!((ev[1].norm() - lam).abs() < 1e-10, "n={n}: {:?}", &ev[..4]);
            assert!((ev[2].norm() - lam).abs() < 1e-10, "n={n}");
        }
    }

    #[test]
    fn extended_spectrum_contains_the_ring_spectrum() {
        // The 2n + 8 matrix is block lower-triangular over (ring, 7 extras): its spectrum is
        // the 2n + 1 ring matrix's plus that of the regular 7 × 7 block.
        for n in [3, 5, 8] {
            let m = CornerPatchMatrices::new(n).unwrap();
            let big = m.eigenvalues();
            let ring = crate::limit_masks::eigen::ring_matrix(
                &Scheme::CatmullClark,
                n,
                crate::limit_masks::eigen::RingFeature::Smooth,
            )
            .unwrap();
            let small = crate::limit_masks::eigen::eigenvalues(&ring).unwrap();
            let mut used = vec![false; big.len()];
            for z in &small {
                let hit = (0..big.len())
                    .find(|&i| !used[i] && (big[i] - *z).norm() < 1e-9)
                    .unwrap_or_else(|| panic!("n={n}: ring eigenvalue {z} missing from {big:?}"));
                used[hit] = true;
            }
            assert_eq!(big.len() - small.len(), 7);
        }
    }
}
