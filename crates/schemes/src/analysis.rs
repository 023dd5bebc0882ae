//! Convergence and smoothness of univariate subdivision masks by Laurent polynomials
//! (seed 001 §7; Dyn 1992).
//!
//! A stationary scheme of arity `m` refines `p'_i = Σ_k a_{i − m k} p_k`; its symbol is
//! `a(z) = Σ_j a_j z^j`. With `σ(z) = 1 + z + … + z^{m−1}`:
//!
//! 1. The sum rules — every residue class of the coefficients mod `m` sums to 1 — are
//!    necessary for convergence; they say that `σ` divides `a`.
//! 2. The differences of the refined points obey the scheme with symbol `q = a / σ`
//!    (`(1 − z) a(z) = (1 − z^m) q(z)`). The scheme converges (to a continuous limit) iff some
//!    power of the difference scheme contracts: `‖S_q^L‖∞ < 1` for some `L`, where
//!    `S_q^L` has symbol `q(z) q(z^m) … q(z^{m^{L−1}})` and its norm is the largest sum of
//!    absolute coefficients over the `m^L` residue classes.
//! 3. `S_a` is `C^k` if `a = (σ/m)^k a_k` and `S_{a_k}` converges (a sufficient test; the
//!    largest `k` for which it succeeds within the level limit is reported).
//!
//! ```
//! use subd_schemes::analysis::analyze;
//!
//! // The 4-point scheme (ω = 1/16): C¹, not shown C².
//! let w = 1.0 / 16.0;
//! let v = analyze(&[-w, 0.0, 0.5 + w, 1.0, 0.5 + w, 0.0, -w], 2, 8).unwrap();
//! assert!(v.converges);
//! assert_eq!(v.smoothness, Some(1));
//! ```

use thiserror::Error;

/// Why a mask cannot be analysed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum AnalysisError {
    /// Arity other than 2 or 3.
    #[error("arity {0}: only binary (2) and ternary (3) masks are analysed")]
    Arity(usize),
    /// No coefficients, or one that is not finite.
    #[error("{0}")]
    Mask(String),
}

/// The outcome of [`analyze`].
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Verdict {
    /// Arity of the mask.
    pub arity: usize,
    /// Whether the scheme converges to a continuous limit (shown within the level limit).
    pub converges: bool,
    /// The largest `k` for which `C^k` was shown (`None` when convergence was not shown).
    pub smoothness: Option<usize>,
    /// For `k = 0, 1, …` (while the factorisation exists): the smallest `L` with
    /// `‖S_{q_k}^L‖∞ < 1`, if any within the limit.
    pub levels_used: Vec<Option<usize>>,
    /// For `k = 0, 1, …`: `‖S_{q_k}^L‖∞` for `L = 1, 2, …` (up to the first below 1).
    pub norms: Vec<Vec<f64>>,
    /// Why the analysis stopped where it did.
    pub note: String,
}

/// Decides convergence and smoothness of the mask `coeffs` (`a_j` in order of increasing
/// power of `z`; they must sum to the arity), trying `L = 1..=max_levels`.
///
/// # Errors
/// [`AnalysisError`] for an arity other than 2 or 3, an empty mask or a coefficient that is
/// not finite.
pub fn analyze(coeffs: &[f64], arity: usize, max_levels: usize) -> Result<Verdict, AnalysisError> {
    if !(2..=3).contains(&arity) {
        return Err(AnalysisError::Arity(arity));
    }
    if coeffs.is_empty() {
        return Err(AnalysisError::Mask("the mask has no coefficients".into()));
    }
    if let Some(i) = coeffs.iter().position(|c| !c.is_finite()) {
        return Err(AnalysisError::Mask(format!(
            "coefficient {i} is not a finite number"
        )));
    }
    let scale = coeffs.iter().fold(0.0f64, |m, c| m.max(c.abs()));
    let tol = 1e-10 * scale.max(1.0);
    let mut verdict = Verdict {
        arity,
        converges: false,
        smoothness: None,
        levels_used: Vec::new(),
        norms: Vec::new(),
        note: String::new(),
    };
    let mut a = trim(coeffs.to_vec(), tol);
    for k in 0.. {
        // Sum rules: each residue class sums to 1 (a(1) = m and σ | a).
        if let Some(r) = (0..arity).find(|&r| {
            let s: f64 = a.iter().skip(r).step_by(arity).sum();
            (s - 1.0).abs() > tol
        }) {
            let s: f64 = a.iter().skip(r).step_by(arity).sum();
            verdict.note = if k == 0 {
                format!(
                    "sum rule fails: the coefficients of residue class {r} (mod {arity}) sum to {s}, not 1; the scheme does not converge"
                )
            } else {
                format!(
                    "C^{k} not shown: the derived mask of order {k} fails the sum rule (class {r} sums to {s})"
                )
            };
            break;
        }
        let Some(q) = divide_by_sigma(&a, arity, tol) else {
            verdict.note = format!(
                "derived mask of order {k} is not divisible by 1 + z{}",
                if arity == 3 { " + z²" } else { "" }
            );
            break;
        };
        let mut norms = Vec::new();
        let mut used = None;
        let mut power = q.clone();
        for l in 1..=max_levels {
            if l > 1 {
                power = multiply(&power, &upsample(&q, arity.pow(l as u32 - 1)));
            }
            let n = class_norm(&power, arity.pow(l as u32));
            norms.push(n);
            if n < 1.0 - 1e-12 {
                used = Some(l);
                break;
            }
            if power.len() > 1 << 22 {
                break;
            }
        }
        verdict.norms.push(norms);
        verdict.levels_used.push(used);
        if used.is_none() {
            verdict.note = if k == 0 {
                format!("‖S_q^L‖∞ ≥ 1 for L = 1..{max_levels}: convergence not shown")
            } else {
                format!(
                    "C^{k} not shown: ‖S_q^L‖∞ ≥ 1 for L = 1..{max_levels} for the derived mask of order {k}"
                )
            };
            break;
        }
        verdict.converges = true;
        verdict.smoothness = Some(k);
        // Next derived mask: a_{k+1} = m a_k / σ = m q.
        a = trim(q.iter().map(|x| x * arity as f64).collect(), tol);
        if k >= 16 {
            verdict.note = "stopped at C^16".into();
            break;
        }
    }
    Ok(verdict)
}

/// Drops leading and trailing coefficients below `tol`.
fn trim(mut a: Vec<f64>, tol: f64) -> Vec<f64> {
    while a.len() > 1 && a.last().is_some_and(|x| x.abs() <= tol) {
        a.pop();
    }
    let lead = a.iter().position(|x| x.abs() > tol).unwrap_or(0);
    a.drain(..lead);
    a
}

/// `a / (1 + z + … + z^{m−1})` when it divides exactly (remainder within `tol`).
fn divide_by_sigma(a: &[f64], m: usize, tol: f64) -> Option<Vec<f64>> {
    if a.len() < m {
        return None;
    }
    // a(z) = σ(z) q(z): q_i = a_i − (q_{i−1} + … + q_{i−m+1}).
    let n = a.len() - (m - 1);
    let mut q = vec![0.0; n];
    for i in 0..n {
        let mut x = a[i];
        for d in 1..m {
            if i >= d {
                x -= q[i - d];
            }
        }
        q[i] = x;
    }
    // The remaining top coefficients must match.
    for i in n..a.len() {
        let s: f64 = (1..m)
            .filter(|&d| i >= d && i - d < n)
            .map(|d| q[i - d])
            .sum();
        if (a[i] - s).abs() > tol {
            return None;
        }
    }
    Some(q)
}

/// `q(z^s)`.
fn upsample(q: &[f64], s: usize) -> Vec<f64> {
    let mut out = vec![0.0; (q.len() - 1) * s + 1];
    for (i, &x) in q.iter().enumerate() {
        out[i * s] = x;
    }
    out
}

fn multiply(a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; a.len() + b.len() - 1];
    for (i, &x) in a.iter().enumerate() {
        if x == 0.0 {
            continue;
        }
        for (j, &y) in b.iter().enumerate() {
            out[i + j] += x * y;
        }
    }
    out
}

/// `max_r Σ_k |c_{r + s k}|`.
fn class_norm(c: &[f64], s: usize) -> f64 {
    (0..s)
        .map(|r| c.iter().skip(r).step_by(s).map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn four_point(w: f64) -> Vec<f64> {
        vec![-w, 0.0, 0.5 + w, 1.0, 0.5 + w, 0.0, -w]
    }

    fn bspline(order: usize) -> Vec<f64> {
        let mut c = vec![2.0];
        for _ in 0..order {
            let mut n = vec![0.0; c.len() + 1];
            for (i, &x) in c.iter().enumerate() {
                n[i] += 0.5 * x;
                n[i + 1] += 0.5 * x;
            }
            c = n;
        }
        c
    }

    #[test]
    fn bspline_of_order_m_is_c_m_minus_2_with_norm_one_half() {
        for m in 2..=8 {
            let v = analyze(&bspline(m), 2, 6).unwrap();
            assert!(v.converges, "order {m}");
            assert_eq!(v.norms[0][0], 0.5, "order {m}");
            assert_eq!(v.smoothness, Some(m - 2), "order {m}: {v:?}");
        }
    }

    #[test]
    fn four_point_norms_and_ranges() {
        // ‖S_q‖ = 1/2 + 2|ω|.
        for w in [-0.3, -0.1, 0.0, 1.0 / 16.0, 0.1, 0.2] {
            let v = analyze(&four_point(w), 2, 1).unwrap();
            assert!(
                (v.norms[0][0] - (0.5 + 2.0 * f64::abs(w))).abs() < 1e-15,
                "ω = {w}"
            );
        }
        // Convergent on (−3/8, (−1 + √13)/8) with L = 2.
        let hi = (-1.0 + 13f64.sqrt()) / 8.0;
        for w in [-0.37, -0.2, 0.1, 0.3, hi - 1e-3] {
            let v = analyze(&four_point(w), 2, 2).unwrap();
            assert!(
                v.converges && v.levels_used[0].is_some_and(|l| l <= 2),
                "ω = {w}: {v:?}"
            );
        }
        for w in [-0.38, hi + 1e-3] {
            assert!(!analyze(&four_point(w), 2, 2).unwrap().converges, "ω = {w}");
        }
        // C¹ on (0, (−1 + √5)/8) with L = 2; ω = 1/16 is not shown C².
        let c1 = (-1.0 + 5f64.sqrt()) / 8.0;
        for w in [0.01, 1.0 / 16.0, 0.1, c1 - 1e-3] {
            let v = analyze(&four_point(w), 2, 2).unwrap();
            assert!(
                v.smoothness >= Some(1) && v.levels_used[1].is_some_and(|l| l <= 2),
                "ω = {w}: {v:?}"
            );
        }
        assert_eq!(
            analyze(&four_point(1.0 / 16.0), 2, 10).unwrap().smoothness,
            Some(1)
        );
    }

    #[test]
    fn sum_rule_failure_is_not_convergent() {
        let v = analyze(&[0.5, 1.0, 0.5, 0.0], 2, 4).unwrap();
        assert!(v.converges);
        let v = analyze(&[0.5, 1.5, 0.0], 2, 4).unwrap();
        assert!(!v.converges && v.note.contains("sum rule"));
        assert!(analyze(&[], 2, 4).is_err());
        assert!(analyze(&[1.0, 1.0], 4, 4).is_err());
    }
}
