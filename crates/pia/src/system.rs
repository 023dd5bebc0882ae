//! The linear system behind progressive interpolation, restricted to the moving vertices.
//!
//! With `B` the limit-position matrix of the scheme (row `i`: the limit of vertex `i` as a
//! combination of control vertices), targets `p`, moving set `P` and fixed set `Q` (which
//! keep `v_Q = p_Q`), the moving vertices must satisfy
//!
//! ```text
//! M̄ x = b,   M̄ = B[P, P],   b = p_P − B[P, Q] p_Q,
//! ```
//!
//! and the residual `b − M̄ x` is exactly the paper's difference vector `D_P = p_P − v∞_P`.

use std::borrow::Cow;
use std::sync::{Arc, OnceLock};

use glam::DVec3;
use rayon::prelude::*;
use subd_mesh::memory;
use subd_schemes::StencilTable;

use crate::checkerboard::{self, Preconditioned};
use crate::matrix::{CHUNK, Matrix, positive, row_stats};

/// Entries below this magnitude are rounding noise of stencil composition, not couplings.
const DROP: f64 = 1e-15;

/// The whole limit matrix in the solvers' form (rounding noise dropped, columns sorted), and
/// its symmetric form once asked for: built once per [`crate::Pia`] and shared by every
/// solve, so a second solve on the same mesh (new targets, another moving set) starts at
/// once.
#[derive(Debug)]
pub(crate) struct FullSystem {
    pub matrix: Arc<Matrix>,
    symmetrizer: OnceLock<Option<Vec<f64>>>,
    /// The checkerboard preconditioner's scaling `T = S Δ⁻¹` (signs over the diagonal
    /// of `M̄`, [`crate::checkerboard`]), where the scheme and mesh have the signs and
    /// every diagonal entry is positive.
    conjugation: Option<Arc<Vec<f64>>>,
    /// The explicitly preconditioned operator and its spectral interval, computed on first
    /// request.
    preconditioned: OnceLock<Option<Preconditioned>>,
}

impl FullSystem {
    /// The solvers' form of `limit`. `classical_row_len`, where the caller knows every row
    /// to be a classical smooth limit mask (see [`crate::Pia::new`]), gives the number of
    /// entries that mask has at each vertex: rows of exactly that length have each ring
    /// vertex once, so their largest off-diagonal weight is the symmetrizer's entry and
    /// the symmetric form is known without the pairwise check. `signs` are the vertices'
    /// checkerboard signs, where the scheme and mesh have them.
    pub fn new(
        limit: &StencilTable,
        signs: Option<Vec<f64>>,
        classical_row_len: Option<&(dyn Fn(usize) -> usize + Sync)>,
    ) -> FullSystem {
        let all = vec![true; limit.num_rows()];
        let (matrix, _, _) = restrict(limit.num_rows(), |i| limit.row(i), None, &all);
        let symmetrizer = OnceLock::new();
        if let Some(len) = classical_row_len
            && (0..matrix.len())
                .into_par_iter()
                .with_min_len(CHUNK)
                .all(|i| {
                    matrix.row(i).0.len() == len(i)
                        && positive(matrix.diag[i])
                        && positive(matrix.off_diag_max[i])
                })
        {
            symmetrizer
                .set(Some(matrix.off_diag_max.clone()))
                .expect("a fresh cell");
        }
        let conjugation = signs.and_then(|s| checkerboard::conjugation(&s, &matrix.diag));
        FullSystem {
            matrix: Arc::new(matrix),
            symmetrizer,
            conjugation: conjugation.map(Arc::new),
            preconditioned: OnceLock::new(),
        }
    }

    /// `K = T M̄ T M̄` of the whole matrix with its spectral interval, when the scheme has
    /// the checkerboard scaling `T` and the matrix a symmetric form; computed on first
    /// request.
    pub fn preconditioned(&self) -> Option<&Preconditioned> {
        self.preconditioned
            .get_or_init(|| {
                let t = self.conjugation.as_ref()?;
                let c = self.symmetrizer()?;
                Preconditioned::new(&self.matrix, c, t)
            })
            .as_ref()
    }

    /// Whether the symmetric form was known at construction (classical masks).
    #[cfg(test)]
    pub fn symmetric_form_known(&self) -> bool {
        self.symmetrizer.get().is_some()
    }

    /// `C` of the whole matrix, computed on first request.
    pub fn symmetrizer(&self) -> Option<&[f64]> {
        self.symmetrizer
            .get_or_init(|| self.matrix.symmetrizer())
            .as_deref()
    }
}

/// `M̄` over the moving vertices (renumbered `0..n` in increasing vertex order) and the
/// right side `b`.
#[derive(Debug, Clone)]
pub(crate) struct ReducedSystem {
    pub matrix: Arc<Matrix>,
    pub rhs: Vec<DVec3>,
    /// Base vertex of each unknown.
    pub moving: Vec<u32>,
    /// The whole system this one was cut from, whose symmetric form restricts to this one.
    full: Option<Arc<FullSystem>>,
}

/// Restricts a square `limit` to the moving vertices: the matrix (rounding noise dropped,
/// columns renumbered and sorted), the right side when `targets` are given (empty
/// otherwise) and the moving vertices. One parallel pass counts each row's entries, a
/// second writes the rows straight into arrays of the final size (no per-block buffers
/// copied together afterwards).
fn restrict<'a>(
    nv: usize,
    limit_row: impl Fn(usize) -> (&'a [u32], &'a [f64]) + Sync,
    targets: Option<&[DVec3]>,
    is_moving: &[bool],
) -> (Matrix, Vec<DVec3>, Vec<u32>) {
    let mut index = vec![u32::MAX; nv];
    let moving: Vec<u32> = (0..nv as u32).filter(|&v| is_moving[v as usize]).collect();
    for (k, &v) in moving.iter().enumerate() {
        index[v as usize] = k as u32;
    }
    let n = moving.len();
    // The row's entries that stay: couplings between moving vertices, renumbered.
    let kept = |v: u32| {
        let (c, w) = limit_row(v as usize);
        c.iter()
            .zip(w)
            .filter(|e| e.1.abs() >= DROP)
            .filter_map(|(&j, &x)| match index[j as usize] {
                u32::MAX => None,
                k => Some((k, x)),
            })
    };
    let counts: Vec<u32> = moving
        .par_iter()
        .with_min_len(CHUNK)
        .map(|&v| kept(v).count() as u32)
        .collect();
    let offsets: Vec<u32> = std::iter::once(0)
        .chain(counts.iter().scan(0u32, |end, &c| {
            *end += c;
            Some(*end)
        }))
        .collect();
    let nnz = offsets[n] as usize;
    let mut cols: Vec<u32> = memory::zeroed(nnz);
    let mut weights: Vec<f64> = memory::zeroed(nnz);
    let (mut diag, mut off_diag_max) = (vec![0.0; n], vec![0.0; n]);
    // Each block of CHUNK rows gets its own part of the entry arrays.
    let mut parts = Vec::with_capacity(n.div_ceil(CHUNK));
    let (mut cols_rest, mut weights_rest) = (&mut cols[..], &mut weights[..]);
    for first in (0..n).step_by(CHUNK) {
        let len = (offsets[(first + CHUNK).min(n)] - offsets[first]) as usize;
        let (c, c_rest) = std::mem::take(&mut cols_rest).split_at_mut(len);
        let (w, w_rest) = std::mem::take(&mut weights_rest).split_at_mut(len);
        parts.push((c, w));
        (cols_rest, weights_rest) = (c_rest, w_rest);
    }
    parts
        .into_par_iter()
        .zip(diag.par_chunks_mut(CHUNK))
        .zip(off_diag_max.par_chunks_mut(CHUNK))
        .enumerate()
        .for_each(|(b, (((cols, weights), diag), off))| {
            let first = b * CHUNK;
            let mut row: Vec<(u32, f64)> = Vec::with_capacity(32);
            let mut at = 0;
            for (r, &v) in moving[first..first + diag.len()].iter().enumerate() {
                row.clear();
                row.extend(kept(v));
                row.sort_unstable_by_key(|e| e.0);
                (diag[r], off[r]) = row_stats((first + r) as u32, &row);
                for &(j, x) in &row {
                    cols[at] = j;
                    weights[at] = x;
                    at += 1;
                }
            }
        });
    let rhs = match targets {
        Some(targets) => moving
            .par_iter()
            .with_min_len(CHUNK)
            .map(|&v| {
                let (c, w) = limit_row(v as usize);
                let mut b = targets[v as usize];
                for (&j, &x) in c.iter().zip(w) {
                    if x.abs() >= DROP && index[j as usize] == u32::MAX {
                        b -= x * targets[j as usize];
                    }
                }
                b
            })
            .collect(),
        None => Vec::new(),
    };
    let matrix = Matrix {
        offsets,
        cols,
        weights,
        diag,
        off_diag_max,
    };
    (matrix, rhs, moving)
}

impl ReducedSystem {
    /// Restricts `limit` (square, one row per base vertex) to the moving vertices.
    #[cfg(test)]
    pub fn new(limit: &StencilTable, targets: &[DVec3], is_moving: &[bool]) -> ReducedSystem {
        let (matrix, rhs, moving) =
            restrict(limit.num_rows(), |i| limit.row(i), Some(targets), is_moving);
        ReducedSystem {
            matrix: Arc::new(matrix),
            rhs,
            moving,
            full: None,
        }
    }

    /// The system of `full` restricted to the moving vertices. With every vertex moving the
    /// matrix is shared, not copied; otherwise the cut is taken from the full matrix, whose
    /// rows are already clean and sorted.
    pub fn from_full(
        full: &Arc<FullSystem>,
        targets: &[DVec3],
        is_moving: &[bool],
    ) -> ReducedSystem {
        let m = &full.matrix;
        if is_moving.iter().all(|&b| b) {
            return ReducedSystem {
                matrix: Arc::clone(m),
                rhs: targets.to_vec(),
                moving: (0..targets.len() as u32).collect(),
                full: Some(Arc::clone(full)),
            };
        }
        let (matrix, rhs, moving) = restrict(targets.len(), |i| m.row(i), Some(targets), is_moving);
        ReducedSystem {
            matrix: Arc::new(matrix),
            rhs,
            moving,
            full: Some(Arc::clone(full)),
        }
    }

    /// `C` with `M̄ = C D`, `D` symmetric: cut from the whole system's when that has one,
    /// else found for this system alone.
    pub fn symmetrizer(&self) -> Option<Cow<'_, [f64]>> {
        if let Some(c) = self.full.as_ref().and_then(|f| f.symmetrizer()) {
            return Some(self.cut(c));
        }
        self.matrix.symmetrizer().map(Cow::Owned)
    }

    /// A per-vertex array of the whole system restricted to the unknowns: borrowed when
    /// every vertex is one.
    fn cut<'a>(&self, whole: &'a [f64]) -> Cow<'a, [f64]> {
        if self.moving.len() == whole.len() {
            Cow::Borrowed(whole)
        } else {
            Cow::Owned(self.moving.iter().map(|&v| whole[v as usize]).collect())
        }
    }

    /// The whole system's preconditioned operator, when this system is the whole system
    /// (every vertex moving) and it has one: built now if `build`, else only if it was
    /// built before.
    pub fn whole_preconditioned(&self, build: bool) -> Option<&Preconditioned> {
        let full = self.full.as_ref()?;
        if !Arc::ptr_eq(&full.matrix, &self.matrix) {
            return None;
        }
        if build {
            full.preconditioned()
        } else {
            full.preconditioned.get()?.as_ref()
        }
    }

    /// The checkerboard preconditioner's scaling `T = S Δ⁻¹` of the unknowns, when the
    /// whole system has it (a cut keeps its rows, so its diagonal is the whole one's).
    pub fn conjugation(&self) -> Option<Cow<'_, [f64]>> {
        let t = self.full.as_ref()?.conjugation.as_ref()?;
        Some(self.cut(t))
    }

    /// Diagonal of `M̄`.
    pub fn diag(&self) -> &[f64] {
        &self.matrix.diag
    }

    /// Number of unknowns.
    pub fn len(&self) -> usize {
        self.moving.len()
    }

    /// Row `i`: (columns, weights).
    #[inline]
    pub fn row(&self, i: usize) -> (&[u32], &[f64]) {
        self.matrix.row(i)
    }

    /// `y = M̄ x`, in parallel.
    pub fn apply(&self, x: &[DVec3], y: &mut [DVec3]) {
        y.par_chunks_mut(CHUNK).enumerate().for_each(|(c, out)| {
            for (k, o) in out.iter_mut().enumerate() {
                *o = self.gather(c * CHUNK + k, |j| x[j]);
            }
        });
    }

    /// `r = b − M̄ x`; returns `max |r_i|`.
    pub fn residual(&self, x: &[DVec3], r: &mut [DVec3]) -> f64 {
        self.residual_into(x, r, |_, ri| ri)
    }

    /// One pass of the weighted iteration: `next = x + ω (b − M̄ x)`; returns
    /// `max |b − M̄ x|` (the error of `x`).
    pub fn step(&self, x: &[DVec3], omega: f64, next: &mut [DVec3]) -> f64 {
        self.residual_into(x, next, |i, ri| x[i] + omega * ri)
    }

    /// `(b − M̄ x)_i`.
    #[inline]
    fn row_residual(&self, i: usize, x: &[DVec3]) -> DVec3 {
        let (cols, w) = self.row(i);
        let mut acc = self.rhs[i];
        for (&j, &x_w) in cols.iter().zip(w) {
            acc -= x_w * x[j as usize];
        }
        acc
    }

    /// `max |b − M̄ x|_i` without storing the residual.
    pub fn residual_max(&self, x: &[DVec3]) -> f64 {
        (0..self.len().div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let mut m = 0.0f64;
                for i in c * CHUNK..((c + 1) * CHUNK).min(self.len()) {
                    m = m.max(finite_or_inf(self.row_residual(i, x).length()));
                }
                m
            })
            .reduce(|| 0.0, f64::max)
    }

    /// `y = T M̄ T x` for the diagonal `T` of `t`, in one pass.
    pub fn apply_conjugated(&self, t: &[f64], x: &[DVec3], y: &mut [DVec3]) {
        y.par_chunks_mut(CHUNK).enumerate().for_each(|(c, out)| {
            for (k, o) in out.iter_mut().enumerate() {
                let i = c * CHUNK + k;
                *o = t[i] * self.gather(i, |j| t[j] * x[j]);
            }
        });
    }

    /// Writes `f(i, r_i)` for the residual `r = b − M̄ x`, in parallel; returns `max |r_i|`.
    fn residual_into(
        &self,
        x: &[DVec3],
        out: &mut [DVec3],
        f: impl Fn(usize, DVec3) -> DVec3 + Sync,
    ) -> f64 {
        out.par_chunks_mut(CHUNK)
            .enumerate()
            .map(|(c, out)| {
                let mut m = 0.0f64;
                for (k, o) in out.iter_mut().enumerate() {
                    let i = c * CHUNK + k;
                    let acc = self.row_residual(i, x);
                    *o = f(i, acc);
                    m = m.max(finite_or_inf(acc.length()));
                }
                m
            })
            .reduce(|| 0.0, f64::max)
    }

    /// `(M̄ x)_i` for `x_j = input(j)`.
    #[inline]
    fn gather(&self, i: usize, input: impl Fn(usize) -> DVec3) -> DVec3 {
        let (cols, w) = self.row(i);
        let mut acc = DVec3::ZERO;
        for (&j, &x_w) in cols.iter().zip(w) {
            acc += x_w * input(j as usize);
        }
        acc
    }

    /// `r̃ = T (b − M̄ x)` for the diagonal `T` of `t` (the identity when `None`); returns
    /// `max |r_i|` of the unscaled residual.
    pub fn scaled_residual(&self, t: Option<&[f64]>, x: &[DVec3], r: &mut [DVec3]) -> f64 {
        match t {
            Some(t) => self.residual_into(x, r, |i, ri| t[i] * ri),
            None => self.residual(x, r),
        }
    }

    /// The checkerboard preconditioner applied to the scaled residual `r̃ = T r`:
    /// `u = M̄ r̃`, written as `z = T u` (so `z = T M̄ T r`); returns
    /// `⟨r, z⟩ = Σ w_i r̃_i ⊙ u_i` per coordinate, blocks summed in order. One pass,
    /// gathering plain `r̃`.
    pub fn precondition_pass(
        &self,
        w: &[f64],
        t: &[f64],
        r_scaled: &[DVec3],
        z: &mut [DVec3],
    ) -> DVec3 {
        let partial: Vec<DVec3> = z
            .par_chunks_mut(CHUNK)
            .enumerate()
            .map(|(c, out)| {
                let mut d = DVec3::ZERO;
                for (k, o) in out.iter_mut().enumerate() {
                    let i = c * CHUNK + k;
                    let u = self.gather(i, |j| r_scaled[j]);
                    *o = t[i] * u;
                    d += w[i] * (r_scaled[i] * u);
                }
                d
            })
            .collect();
        partial.into_iter().fold(DVec3::ZERO, |s, x| s + x)
    }

    /// CG's new direction and its product in one pass: `p ← z + β ⊙ p` and
    /// `q ← M̄ z + β ⊙ q`, which is `M̄ p` by linearity when `q` held `M̄ p` (`β = None`:
    /// the first direction, `p = z`); returns `⟨p, q⟩ = Σ w_i p_i ⊙ q_i` per coordinate,
    /// blocks summed in order.
    pub fn direction_pass(
        &self,
        w: &[f64],
        z: &[DVec3],
        beta: Option<DVec3>,
        p: &mut [DVec3],
        q: &mut [DVec3],
    ) -> DVec3 {
        let partial: Vec<DVec3> = p
            .par_chunks_mut(CHUNK)
            .zip(q.par_chunks_mut(CHUNK))
            .enumerate()
            .map(|(c, (p, q))| {
                let mut d = DVec3::ZERO;
                for (k, (p, q)) in p.iter_mut().zip(q).enumerate() {
                    let i = c * CHUNK + k;
                    let mz = self.gather(i, |j| z[j]);
                    (*p, *q) = match beta {
                        Some(b) => (z[i] + b * *p, mz + b * *q),
                        None => (z[i], mz),
                    };
                    d += w[i] * (*p * *q);
                }
                d
            })
            .collect();
        partial.into_iter().fold(DVec3::ZERO, |s, x| s + x)
    }

    /// Largest absolute row sum (an upper bound of the spectral radius).
    pub fn inf_norm(&self) -> f64 {
        (0..self.len())
            .map(|i| self.row(i).1.iter().map(|w| w.abs()).sum::<f64>())
            .fold(0.0, f64::max)
    }
}

/// `Σ_i a_i ⊙ b_i` per component, in fixed-size blocks summed in order (the same value with
/// any number of threads).
pub(crate) fn dot(a: &[DVec3], b: &[DVec3]) -> DVec3 {
    let partial: Vec<DVec3> = a
        .par_chunks(CHUNK)
        .zip(b.par_chunks(CHUNK))
        .map(|(x, y)| x.iter().zip(y).fold(DVec3::ZERO, |s, (p, q)| s + *p * *q))
        .collect();
    partial.into_iter().fold(DVec3::ZERO, |s, x| s + x)
}

/// `max_i |a_i|`.
pub(crate) fn max_norm(a: &[DVec3]) -> f64 {
    a.par_chunks(CHUNK)
        .map(|x| {
            x.iter()
                .fold(0.0f64, |m, p| m.max(finite_or_inf(p.length())))
        })
        .reduce(|| 0.0, f64::max)
}

/// A NaN norm counts as infinitely large (`f64::max` would skip it and report convergence).
#[inline]
pub(crate) fn finite_or_inf(x: f64) -> f64 {
    if x.is_nan() { f64::INFINITY } else { x }
}

/// Componentwise `a / b`, 0 where `b` is 0 (a column that has already converged exactly).
#[inline]
pub(crate) fn safe_div(a: DVec3, b: DVec3) -> DVec3 {
    let d = |x: f64, y: f64| if y != 0.0 { x / y } else { 0.0 };
    DVec3::new(d(a.x, b.x), d(a.y, b.y), d(a.z, b.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A system straight from dense rows (all vertices moving, zero targets).
    fn system(rows: &[&[f64]]) -> ReducedSystem {
        let n = rows.len();
        let dense: Vec<Vec<(u32, f64)>> = rows
            .iter()
            .map(|r| {
                r.iter()
                    .enumerate()
                    .filter(|e| *e.1 != 0.0)
                    .map(|(j, &w)| (j as u32, w))
                    .collect()
            })
            .collect();
        let table = StencilTable::from_rows(n, &dense);
        ReducedSystem::new(&table, &vec![DVec3::ZERO; n], &vec![true; n])
    }

    #[test]
    fn symmetrizer_recovers_c_of_c_times_d() {
        // D symmetric positive definite, C = diag(1, 2, 4): M̄ = C D.
        let d = [[4.0, 1.0, 0.5], [1.0, 3.0, 1.0], [0.5, 1.0, 5.0]];
        let c = [1.0, 2.0, 4.0];
        let rows: Vec<Vec<f64>> = (0..3)
            .map(|i| (0..3).map(|j| c[i] * d[i][j]).collect())
            .collect();
        let refs: Vec<&[f64]> = rows.iter().map(|r| r.as_slice()).collect();
        let s = system(&refs);
        let found = s.symmetrizer().expect("symmetrisable");
        // Unique up to one scale.
        for i in 0..3 {
            assert!((found[i] / found[0] - c[i] / c[0]).abs() < 1e-14);
        }
        // A one-way coupling has no symmetric form.
        let s = system(&[&[1.0, 0.5, 0.0], &[0.0, 1.0, 0.0], &[0.0, 0.2, 0.8]]);
        assert!(s.symmetrizer().is_none());
        // Nor do ratios that disagree around a cycle.
        let s = system(&[&[2.0, 1.0, 1.0], &[1.0, 2.0, 2.0], &[1.0, 1.0, 2.0]]);
        assert!(s.symmetrizer().is_none());
    }

    #[test]
    fn classical_masks_have_the_symmetric_form_the_pairwise_check_finds() {
        use crate::Pia;
        use subd_mesh::TopologyBuilder;
        use subd_schemes::{Options, Refinement, Scheme, TwoPhase};

        // Quads with valence 3, 4 and 6 vertices.
        let base = subd_mesh::primitives::torus_with_hexagons(8, 12, 4, 3.0, 1.0);
        let quads = Refinement::new(&base.topology, Scheme::CatmullClark, &Options::default(), 1)
            .unwrap()
            .into_topology(1);
        let nv = quads.num_vertices();
        let lambda = (0..nv).map(|v| 0.36 + 0.64 * ((v * 37) % 101) as f64 / 101.0);
        let two_phase = Scheme::TwoPhase(TwoPhase::new(lambda.collect()).unwrap());
        // Triangles: a torus grid split along one diagonal (valence 6) and an octahedron
        // (valence 4).
        let (m, n) = (6u32, 8u32);
        let id = |i: u32, j: u32| (i % m) * n + j % n;
        let mut tris = Vec::new();
        for i in 0..m {
            for j in 0..n {
                tris.extend([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                tris.extend([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let torus_tris = TopologyBuilder::new((m * n) as usize)
            .build(&vec![3; tris.len() / 3], &tris)
            .unwrap();
        let octahedron = TopologyBuilder::new(6)
            .build(
                &[3; 8],
                &[
                    0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5,
                ],
            )
            .unwrap();
        let cases = [
            (&quads, Scheme::CatmullClark),
            (&quads, two_phase),
            (&torus_tris, Scheme::Loop),
            (&octahedron, Scheme::Loop),
        ];
        for (t, scheme) in &cases {
            let pia = Pia::new(t, scheme, &Options::default()).unwrap();
            assert!(pia.full.symmetric_form_known(), "{scheme:?}");
            let c = pia.full.symmetrizer().unwrap();
            assert!(pia.full.matrix.symmetrizes(c), "{scheme:?}");
        }
        // Hexagons (not classical): found by the check when first asked for.
        let pia = Pia::new(&base.topology, &Scheme::CatmullClark, &Options::default()).unwrap();
        assert!(!pia.full.symmetric_form_known());
        assert!(pia.full.symmetrizer().is_some());
    }

    #[test]
    fn fixed_vertices_move_to_the_right_side() {
        // Vertex 1 fixed: b_0 = p_0 − M̄_01 p_1.
        let rows: Vec<Vec<(u32, f64)>> = vec![vec![(0, 0.5), (1, 0.5)], vec![(0, 0.25), (1, 0.75)]];
        let table = StencilTable::from_rows(2, &rows);
        let p = [DVec3::X, DVec3::Y];
        let s = ReducedSystem::new(&table, &p, &[true, false]);
        assert_eq!(s.len(), 1);
        assert_eq!(s.moving, [0]);
        assert_eq!(s.rhs[0], DVec3::X - 0.5 * DVec3::Y);
        assert_eq!(s.diag(), [0.5]);
    }

    #[test]
    fn dot_sums_blocks_in_order() {
        let a: Vec<DVec3> = (0..10_000)
            .map(|i| DVec3::splat((i as f64).sin()))
            .collect();
        let want = a
            .chunks(CHUNK)
            .map(|c| c.iter().map(|x| *x * *x).fold(DVec3::ZERO, |s, x| s + x))
            .fold(DVec3::ZERO, |s, x| s + x);
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        assert_eq!(one.install(|| dot(&a, &a)), want);
        assert_eq!(dot(&a, &a), want);
    }
}
