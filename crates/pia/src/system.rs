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

use std::sync::{Arc, OnceLock};

use glam::DVec3;
use rayon::prelude::*;
use subd_schemes::StencilTable;

use crate::checkerboard::Preconditioned;

/// Rows per parallel task; also the block size of the fixed-order reductions, so sums do
/// not depend on the number of threads.
pub(crate) const CHUNK: usize = 2048;

/// Entries below this magnitude are rounding noise of stencil composition, not couplings.
const DROP: f64 = 1e-15;

/// A square sparse matrix in CSR form, columns sorted within each row (except in the
/// checkerboard operator `K`, which only takes part in products), with its diagonal.
#[derive(Debug, Clone)]
pub(crate) struct Matrix {
    pub offsets: Vec<u32>,
    pub cols: Vec<u32>,
    pub weights: Vec<f64>,
    pub diag: Vec<f64>,
}

/// The whole limit matrix in the solvers' form (rounding noise dropped, columns sorted), and
/// its symmetric form once asked for: built once per [`crate::Pia`] and shared by every
/// solve, so a second solve on the same mesh (new targets, another moving set) starts at
/// once.
#[derive(Debug)]
pub(crate) struct FullSystem {
    pub matrix: Arc<Matrix>,
    symmetrizer: OnceLock<Option<Vec<f64>>>,
    /// Checkerboard signs of the vertices for the preconditioner
    /// ([`crate::checkerboard`]), where the scheme and mesh have them.
    signs: Option<Arc<Vec<f64>>>,
    /// The explicitly preconditioned operator and its spectral interval, computed on first
    /// request.
    preconditioned: OnceLock<Option<Preconditioned>>,
}

impl FullSystem {
    pub fn new(limit: &StencilTable, signs: Option<Arc<Vec<f64>>>) -> FullSystem {
        let all = vec![true; limit.num_rows()];
        let zero = vec![DVec3::ZERO; limit.num_rows()];
        let (matrix, _, _) = restrict(limit.num_rows(), |i| limit.row(i), &zero, &all);
        FullSystem {
            matrix: Arc::new(matrix),
            symmetrizer: OnceLock::new(),
            signs,
            preconditioned: OnceLock::new(),
        }
    }

    /// `K = S M̄ S M̄` of the whole matrix with its spectral interval, when the scheme has
    /// checkerboard signs and the matrix a symmetric form; computed on first request.
    pub fn preconditioned(&self) -> Option<&Preconditioned> {
        self.preconditioned
            .get_or_init(|| {
                let signs = self.signs.as_ref()?;
                let c = self.symmetrizer()?;
                Preconditioned::new(&self.matrix, c, signs)
            })
            .as_ref()
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

/// Restricts a square `limit` to the moving vertices: the matrix, the right side and the
/// moving vertices. Rows are taken in parallel blocks (one scratch row per block), then
/// concatenated in order.
fn restrict<'a>(
    nv: usize,
    limit_row: impl Fn(usize) -> (&'a [u32], &'a [f64]) + Sync,
    targets: &[DVec3],
    is_moving: &[bool],
) -> (Matrix, Vec<DVec3>, Vec<u32>) {
    let mut index = vec![u32::MAX; nv];
    let moving: Vec<u32> = (0..nv as u32).filter(|&v| is_moving[v as usize]).collect();
    for (k, &v) in moving.iter().enumerate() {
        index[v as usize] = k as u32;
    }
    struct Block {
        rows: RowBlock,
        rhs: Vec<DVec3>,
    }
    let blocks: Vec<Block> = moving
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(k, rows)| {
            let first = k * CHUNK;
            let mut blk = Block {
                rows: RowBlock::with_rows(rows.len()),
                rhs: Vec::with_capacity(rows.len()),
            };
            let mut row: Vec<(u32, f64)> = Vec::with_capacity(32);
            for &v in rows {
                let (c, w) = limit_row(v as usize);
                row.clear();
                let mut b = targets[v as usize];
                for (&j, &x) in c.iter().zip(w) {
                    if x.abs() < DROP {
                        continue;
                    }
                    match index[j as usize] {
                        u32::MAX => b -= x * targets[j as usize],
                        k => row.push((k, x)),
                    }
                }
                row.sort_unstable_by_key(|e| e.0);
                blk.rows.push_row(first, &row);
                blk.rhs.push(b);
            }
            blk
        })
        .collect();
    let mut rhs = Vec::with_capacity(moving.len());
    let mut rows = Vec::with_capacity(blocks.len());
    for blk in blocks {
        rhs.extend_from_slice(&blk.rhs);
        rows.push(blk.rows);
    }
    (Matrix::from_blocks(rows), rhs, moving)
}

/// Consecutive rows of a [`Matrix`] built by one parallel task.
pub(crate) struct RowBlock {
    counts: Vec<u32>,
    cols: Vec<u32>,
    weights: Vec<f64>,
    diag: Vec<f64>,
}

impl RowBlock {
    /// An empty block for about `rows` rows.
    pub fn with_rows(rows: usize) -> RowBlock {
        RowBlock {
            counts: Vec::with_capacity(rows),
            cols: Vec::with_capacity(rows * 10),
            weights: Vec::with_capacity(rows * 10),
            diag: Vec::with_capacity(rows),
        }
    }

    /// Appends the next row (sorted `(column, weight)` pairs); `first` is the global index
    /// of the block's first row, to pick out the diagonal.
    pub fn push_row(&mut self, first: usize, row: &[(u32, f64)]) {
        let i = (first + self.counts.len()) as u32;
        let mut d = 0.0;
        for &(j, x) in row {
            if j == i {
                d = x;
            }
            self.cols.push(j);
            self.weights.push(x);
        }
        self.diag.push(d);
        self.counts.push(row.len() as u32);
    }
}

impl ReducedSystem {
    /// Restricts `limit` (square, one row per base vertex) to the moving vertices.
    #[cfg(test)]
    pub fn new(limit: &StencilTable, targets: &[DVec3], is_moving: &[bool]) -> ReducedSystem {
        let (matrix, rhs, moving) =
            restrict(limit.num_rows(), |i| limit.row(i), targets, is_moving);
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
        let (matrix, rhs, moving) = restrict(targets.len(), |i| m.row(i), targets, is_moving);
        ReducedSystem {
            matrix: Arc::new(matrix),
            rhs,
            moving,
            full: Some(Arc::clone(full)),
        }
    }

    /// `C` with `M̄ = C D`, `D` symmetric: cut from the whole system's when that has one,
    /// else found for this system alone.
    pub fn symmetrizer(&self) -> Option<Vec<f64>> {
        if let Some(c) = self.full.as_ref().and_then(|f| f.symmetrizer()) {
            return Some(self.moving.iter().map(|&v| c[v as usize]).collect());
        }
        self.matrix.symmetrizer()
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

    /// Checkerboard signs of the unknowns, when the whole system has them.
    pub fn signs(&self) -> Option<Vec<f64>> {
        let signs = self.full.as_ref()?.signs.as_ref()?;
        Some(self.moving.iter().map(|&v| signs[v as usize]).collect())
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
                let (cols, w) = self.row(c * CHUNK + k);
                let mut acc = DVec3::ZERO;
                for (&j, &x_w) in cols.iter().zip(w) {
                    acc += x_w * x[j as usize];
                }
                *o = acc;
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

    /// `y = S M̄ S x` for the diagonal of signs `S`, in one pass.
    pub fn apply_conjugated(&self, signs: &[f64], x: &[DVec3], y: &mut [DVec3]) {
        y.par_chunks_mut(CHUNK).enumerate().for_each(|(c, out)| {
            for (k, o) in out.iter_mut().enumerate() {
                let i = c * CHUNK + k;
                let (cols, w) = self.row(i);
                let mut acc = DVec3::ZERO;
                for (&j, &x_w) in cols.iter().zip(w) {
                    acc += (x_w * signs[j as usize]) * x[j as usize];
                }
                *o = signs[i] * acc;
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

    /// `q = M̄ p`; returns `Σ w_i p_i ⊙ q_i` per coordinate, blocks summed in order.
    pub fn apply_weighted_dot(&self, w: &[f64], p: &[DVec3], q: &mut [DVec3]) -> DVec3 {
        self.weighted_dot_pass(w, |j| p[j], q)
    }

    /// `q = M̄ S r` for the diagonal of signs `S`; returns `Σ w_i (S r)_i ⊙ q_i` per
    /// coordinate, blocks summed in order: [`ReducedSystem::apply_weighted_dot`] of `S r`
    /// without forming it (signs are `±1`, so the products are the same to the bit).
    pub fn apply_signed_weighted_dot(
        &self,
        w: &[f64],
        signs: &[f64],
        r: &[DVec3],
        q: &mut [DVec3],
    ) -> DVec3 {
        self.weighted_dot_pass(w, |j| signs[j] * r[j], q)
    }

    /// `q = M̄ p` for `p_j = input(j)`, with `Σ w_i p_i ⊙ q_i` per coordinate.
    #[inline]
    fn weighted_dot_pass(
        &self,
        w: &[f64],
        input: impl Fn(usize) -> DVec3 + Sync,
        q: &mut [DVec3],
    ) -> DVec3 {
        let partial: Vec<DVec3> = q
            .par_chunks_mut(CHUNK)
            .enumerate()
            .map(|(c, out)| {
                let mut d = DVec3::ZERO;
                for (k, o) in out.iter_mut().enumerate() {
                    let i = c * CHUNK + k;
                    let (cols, wt) = self.row(i);
                    let mut acc = DVec3::ZERO;
                    for (&j, &x_w) in cols.iter().zip(wt) {
                        acc += x_w * input(j as usize);
                    }
                    *o = acc;
                    d += w[i] * (input(i) * acc);
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

impl Matrix {
    /// Concatenates consecutive blocks of rows.
    pub fn from_blocks(blocks: Vec<RowBlock>) -> Matrix {
        let nnz: usize = blocks.iter().map(|b| b.cols.len()).sum();
        let rows: usize = blocks.iter().map(|b| b.counts.len()).sum();
        let mut offsets = Vec::with_capacity(rows + 1);
        offsets.push(0u32);
        let mut cols = Vec::with_capacity(nnz);
        let mut weights = Vec::with_capacity(nnz);
        let mut diag = Vec::with_capacity(rows);
        let mut end = 0u32;
        for blk in blocks {
            for c in blk.counts {
                end += c;
                offsets.push(end);
            }
            cols.extend_from_slice(&blk.cols);
            weights.extend_from_slice(&blk.weights);
            diag.extend_from_slice(&blk.diag);
        }
        Matrix {
            offsets,
            cols,
            weights,
            diag,
        }
    }

    /// `y = A x` for one scalar column, in parallel.
    pub fn apply_scalar(&self, x: &[f64], y: &mut [f64]) {
        y.par_chunks_mut(CHUNK).enumerate().for_each(|(c, out)| {
            for (k, o) in out.iter_mut().enumerate() {
                let (cols, w) = self.row(c * CHUNK + k);
                *o = cols.iter().zip(w).map(|(&j, &w)| w * x[j as usize]).sum();
            }
        });
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.diag.len()
    }

    /// Row `i`: (columns, weights).
    #[inline]
    pub fn row(&self, i: usize) -> (&[u32], &[f64]) {
        let (a, b) = (self.offsets[i] as usize, self.offsets[i + 1] as usize);
        (&self.cols[a..b], &self.weights[a..b])
    }

    /// The positive diagonal `C` with `M̄ = C D`, `D` symmetric, when there is one
    /// (seed 000 eqs. 17–18 for the two-phase scheme; the plain Catmull-Clark and Loop
    /// limit masks have the same structure on closed meshes). Found by propagating
    /// `c_j = c_i · M̄_ji / M̄_ij` over the coupling graph and checking every pair.
    pub fn symmetrizer(&self) -> Option<Vec<f64>> {
        // The masks of subd's schemes weigh every edge neighbour alike up to the row's scale
        // (D's largest off-diagonal entries are equal), so the row's largest off-diagonal
        // weight is the candidate; checked in parallel, propagated only if that fails.
        let candidate: Vec<f64> = (0..self.len())
            .into_par_iter()
            .with_min_len(CHUNK)
            .map(|i| {
                let (c, w) = self.row(i);
                c.iter()
                    .zip(w)
                    .filter(|e| *e.0 as usize != i)
                    .map(|e| e.1.abs())
                    .fold(0.0, f64::max)
            })
            .collect();
        if candidate.iter().all(|&c| c > 0.0) && self.symmetrizes(&candidate) {
            return Some(candidate);
        }
        self.propagated_symmetrizer()
    }

    /// Whether `C⁻¹ M̄` is symmetric (relative 1e-11) with a positive diagonal. Each entry
    /// above the diagonal is matched with its transpose (rows are sorted, so a binary
    /// search); equal counts above and below then leave no unmatched entry below.
    fn symmetrizes(&self, c: &[f64]) -> bool {
        let counts = (0..self.len())
            .into_par_iter()
            .with_min_len(CHUNK)
            .map(|i| {
                let (cols, w) = self.row(i);
                if !positive(self.diag[i]) {
                    return None;
                }
                let (mut above, mut below) = (0usize, 0usize);
                for (&j, &mij) in cols.iter().zip(w) {
                    let j = j as usize;
                    if j < i {
                        below += 1;
                        continue;
                    }
                    if j == i {
                        continue;
                    }
                    above += 1;
                    let (cj, wj) = self.row(j);
                    let k = cj.binary_search(&(i as u32)).ok()?;
                    let (a, b) = (mij / c[i], wj[k] / c[j]);
                    if (a - b).abs() > 1e-11 * a.abs().max(b.abs()) {
                        return None;
                    }
                }
                Some((above, below))
            })
            .try_reduce(|| (0, 0), |a, b| Some((a.0 + b.0, a.1 + b.1)));
        matches!(counts, Some((above, below)) if above == below)
    }

    /// The symmetrizer by propagation over the coupling graph (any consistent scales).
    fn propagated_symmetrizer(&self) -> Option<Vec<f64>> {
        let n = self.len();
        let transpose = |i: usize, j: usize| -> Option<f64> {
            let (c, w) = self.row(j);
            c.binary_search(&(i as u32)).ok().map(|k| w[k])
        };
        let mut c = vec![0.0f64; n];
        let mut stack = Vec::new();
        for root in 0..n {
            if c[root] != 0.0 {
                continue;
            }
            if !positive(self.diag[root]) {
                return None;
            }
            c[root] = 1.0;
            stack.push(root);
            while let Some(i) = stack.pop() {
                let (cols, w) = self.row(i);
                for (&j, &mij) in cols.iter().zip(w) {
                    let j = j as usize;
                    if j == i {
                        continue;
                    }
                    let mji = transpose(i, j)?;
                    if !positive(mij / mji) {
                        return None;
                    }
                    let cj = c[i] * mji / mij;
                    if c[j] == 0.0 {
                        if !positive(self.diag[j]) {
                            return None;
                        }
                        c[j] = cj;
                        stack.push(j);
                    } else if (c[j] - cj).abs() > 1e-11 * c[j].abs().max(cj.abs()) {
                        return None;
                    }
                }
            }
        }
        Some(c)
    }
}

/// `x > 0` (false for NaN).
#[inline]
fn positive(x: f64) -> bool {
    x > 0.0
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
