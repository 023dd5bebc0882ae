//! Eigenvalue bounds from a Lanczos run: the extreme Ritz values.

use faer::{Mat, Side};

/// Smallest and largest eigenvalue of the Lanczos tridiagonal matrix (diagonal `alphas`,
/// off-diagonal `betas`), when the smallest is positive.
pub(crate) fn ritz_extremes(alphas: &[f64], betas: &[f64]) -> Option<(f64, f64)> {
    let m = alphas.len();
    let t = Mat::<f64>::from_fn(m, m, |i, j| {
        if i == j {
            alphas[i]
        } else if i == j + 1 {
            betas[j]
        } else if j == i + 1 {
            betas[i]
        } else {
            0.0
        }
    });
    let ev = t.self_adjoint_eigenvalues(Side::Lower).ok()?;
    match (ev.first(), ev.last()) {
        (Some(&lo), Some(&hi)) if lo > 0.0 => Some((lo, hi)),
        _ => None,
    }
}
