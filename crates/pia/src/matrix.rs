//! The sparse matrices the solvers work with (CSR rows with their diagonal), built in
//! parallel blocks of rows.

use rayon::prelude::*;

/// Rows per parallel task; also the block size of the fixed-order reductions, so sums do
/// not depend on the number of threads.
pub(crate) const CHUNK: usize = 2048;

/// A square sparse matrix in CSR form, columns sorted within each row (except in the
/// checkerboard operator `K`, which only takes part in products), with its diagonal.
#[derive(Debug, Clone)]
pub(crate) struct Matrix {
    pub offsets: Vec<u32>,
    pub cols: Vec<u32>,
    pub weights: Vec<f64>,
    pub diag: Vec<f64>,
    /// Largest off-diagonal `|weight|` of each row (0 for a row without one): the
    /// candidate symmetrizer ([`Matrix::symmetrizer`]).
    pub off_diag_max: Vec<f64>,
}

/// The diagonal entry and the largest off-diagonal `|weight|` of row `i`.
pub(crate) fn row_stats(i: u32, row: &[(u32, f64)]) -> (f64, f64) {
    row.iter().fold((0.0, 0.0f64), |(d, off), &(j, x)| {
        if j == i {
            (x, off)
        } else {
            (d, off.max(x.abs()))
        }
    })
}

/// Consecutive rows of a [`Matrix`] built by one parallel task.
pub(crate) struct RowBlock {
    counts: Vec<u32>,
    cols: Vec<u32>,
    weights: Vec<f64>,
    diag: Vec<f64>,
    off_diag_max: Vec<f64>,
}

impl RowBlock {
    /// An empty block for about `rows` rows.
    pub fn with_rows(rows: usize) -> RowBlock {
        RowBlock {
            counts: Vec::with_capacity(rows),
            cols: Vec::with_capacity(rows * 10),
            weights: Vec::with_capacity(rows * 10),
            diag: Vec::with_capacity(rows),
            off_diag_max: Vec::with_capacity(rows),
        }
    }

    /// Appends the next row (sorted `(column, weight)` pairs); `first` is the global index
    /// of the block's first row, to pick out the diagonal.
    pub fn push_row(&mut self, first: usize, row: &[(u32, f64)]) {
        let i = (first + self.counts.len()) as u32;
        let (d, off) = row_stats(i, row);
        for &(j, x) in row {
            self.cols.push(j);
            self.weights.push(x);
        }
        self.diag.push(d);
        self.off_diag_max.push(off);
        self.counts.push(row.len() as u32);
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
        let mut off_diag_max = Vec::with_capacity(rows);
        let mut end = 0u32;
        for blk in blocks {
            for c in blk.counts {
                end += c;
                offsets.push(end);
            }
            cols.extend_from_slice(&blk.cols);
            weights.extend_from_slice(&blk.weights);
            diag.extend_from_slice(&blk.diag);
            off_diag_max.extend_from_slice(&blk.off_diag_max);
        }
        Matrix {
            offsets,
            cols,
            weights,
            diag,
            off_diag_max,
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
    /// (Lin et al. eqs. 17–18 for the two-phase scheme; the plain Catmull-Clark and Loop
    /// limit masks have the same structure on closed meshes). Found by propagating
    /// `c_j = c_i · M̄_ji / M̄_ij` over the coupling graph and checking every pair.
    pub fn symmetrizer(&self) -> Option<Vec<f64>> {
        // The masks of subd's schemes weigh every edge neighbour alike up to the row's scale
        // (D's largest off-diagonal entries are equal), so the row's largest off-diagonal
        // weight is the candidate; checked in parallel, propagated only if that fails.
        let candidate = &self.off_diag_max;
        if candidate.iter().all(|&c| c > 0.0) && self.symmetrizes(candidate) {
            return Some(candidate.clone());
        }
        self.propagated_symmetrizer()
    }

    /// Whether `C⁻¹ M̄` is symmetric (relative 1e-11) with a positive diagonal. Each entry
    /// above the diagonal is matched with its transpose (a scan of the short sorted row);
    /// equal counts above and below then leave no unmatched entry below.
    pub(crate) fn symmetrizes(&self, c: &[f64]) -> bool {
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
                    let k = cj.iter().position(|&c| c == i as u32)?;
                    // M̄_ij / c_i = M̄_ji / c_j, scaled by c_i c_j > 0 (no divisions).
                    let (a, b) = (mij * c[j], wj[k] * c[i]);
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
pub(crate) fn positive(x: f64) -> bool {
    x > 0.0
}
