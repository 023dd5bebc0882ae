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

use glam::DVec3;
use rayon::prelude::*;
use subd_schemes::StencilTable;

/// Rows per parallel task; also the block size of the fixed-order reductions, so sums do
/// not depend on the number of threads.
pub(crate) const CHUNK: usize = 2048;

/// Entries below this magnitude are rounding noise of stencil composition, not couplings.
const DROP: f64 = 1e-15;

/// `M̄` in CSR form over the moving vertices (renumbered `0..n` in increasing vertex order),
/// columns sorted within each row, and the right side `b`.
#[derive(Debug, Clone)]
pub(crate) struct ReducedSystem {
    pub offsets: Vec<u32>,
    pub cols: Vec<u32>,
    pub weights: Vec<f64>,
    pub rhs: Vec<DVec3>,
    /// Base vertex of each unknown.
    pub moving: Vec<u32>,
    /// Diagonal of `M̄`.
    pub diag: Vec<f64>,
}

impl ReducedSystem {
    /// Restricts `limit` (square, one row per base vertex) to the moving vertices.
    pub fn new(limit: &StencilTable, targets: &[DVec3], is_moving: &[bool]) -> ReducedSystem {
        let nv = limit.num_rows();
        let mut index = vec![u32::MAX; nv];
        let moving: Vec<u32> = (0..nv as u32).filter(|&v| is_moving[v as usize]).collect();
        for (k, &v) in moving.iter().enumerate() {
            index[v as usize] = k as u32;
        }
        let rows: Vec<(Vec<(u32, f64)>, DVec3)> = moving
            .par_iter()
            .map(|&v| {
                let (c, w) = limit.row(v as usize);
                let mut row = Vec::with_capacity(c.len());
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
                (row, b)
            })
            .collect();
        let mut offsets = Vec::with_capacity(moving.len() + 1);
        offsets.push(0u32);
        let nnz: usize = rows.iter().map(|r| r.0.len()).sum();
        let mut cols = Vec::with_capacity(nnz);
        let mut weights = Vec::with_capacity(nnz);
        let mut rhs = Vec::with_capacity(moving.len());
        let mut diag = vec![0.0; moving.len()];
        for (i, (row, b)) in rows.into_iter().enumerate() {
            for (j, x) in row {
                if j as usize == i {
                    diag[i] = x;
                }
                cols.push(j);
                weights.push(x);
            }
            offsets.push(cols.len() as u32);
            rhs.push(b);
        }
        ReducedSystem {
            offsets,
            cols,
            weights,
            rhs,
            moving,
            diag,
        }
    }

    /// Number of unknowns.
    pub fn len(&self) -> usize {
        self.moving.len()
    }

    /// Row `i`: (columns, weights).
    #[inline]
    pub fn row(&self, i: usize) -> (&[u32], &[f64]) {
        let (a, b) = (self.offsets[i] as usize, self.offsets[i + 1] as usize);
        (&self.cols[a..b], &self.weights[a..b])
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
        r.par_chunks_mut(CHUNK)
            .enumerate()
            .map(|(c, out)| {
                let mut m = 0.0f64;
                for (k, o) in out.iter_mut().enumerate() {
                    let i = c * CHUNK + k;
                    let (cols, w) = self.row(i);
                    let mut acc = self.rhs[i];
                    for (&j, &x_w) in cols.iter().zip(w) {
                        acc -= x_w * x[j as usize];
                    }
                    *o = acc;
                    m = m.max(finite_or_inf(acc.length()));
                }
                m
            })
            .reduce(|| 0.0, f64::max)
    }

    /// Largest absolute row sum (an upper bound of the spectral radius).
    pub fn inf_norm(&self) -> f64 {
        (0..self.len())
            .map(|i| self.row(i).1.iter().map(|w| w.abs()).sum::<f64>())
            .fold(0.0, f64::max)
    }

    /// The positive diagonal `C` with `M̄ = C D`, `D` symmetric, when there is one
    /// (seed 000 eqs. 17–18 for the two-phase scheme; the plain Catmull-Clark and Loop
    /// limit masks have the same structure on closed meshes). Found by propagating
    /// `c_j = c_i · M̄_ji / M̄_ij` over the coupling graph and checking every pair.
    pub fn symmetrizer(&self) -> Option<Vec<f64>> {
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
