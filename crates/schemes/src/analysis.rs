//! Convergence and smoothness of univariate subdivision masks by Laurent polynomials
//! (the subdivision lecture notes §7; Dyn 1992).
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
//! [`analyze_bivariate`] does the same for factorable bivariate binary masks on quad and
//! three-direction grids (the subdivision lecture notes §7.2), up to C¹.
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

use subd_mesh::choice::Choice;
use thiserror::Error;

/// Why a mask cannot be analysed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum AnalysisError {
    /// Arity other than 2 or 3.
    #[error("arity {0}: only binary (2) and ternary (3) masks are analysed")]
    Arity(usize),
    /// No coefficients, one that is not finite, or sums other than the arity's.
    #[error("{0}")]
    Mask(String),
    /// A level limit outside [`LEVEL_RANGE`].
    #[error("{0} levels: the analysis tries 1 to 20")]
    Levels(usize),
}

/// The levels `L` of the difference schemes a checked analysis may try
/// ([`analyze_mask`], [`analyze_mask2`]).
pub const LEVEL_RANGE: std::ops::RangeInclusive<usize> = 1..=20;

/// The analysis `subd analyze --mask` and `subd.analyze(mask=…)` run: the level limit and
/// the mask's total checked ([`check_total`]), then [`analyze`].
///
/// # Errors
/// [`AnalysisError::Levels`], [`AnalysisError::Arity`], or [`AnalysisError::Mask`] for an
/// empty mask, a coefficient that is not finite or coefficients that do not sum to the
/// arity.
pub fn analyze_mask(
    coeffs: &[f64],
    arity: usize,
    max_levels: usize,
) -> Result<Verdict, AnalysisError> {
    if !LEVEL_RANGE.contains(&max_levels) {
        return Err(AnalysisError::Levels(max_levels));
    }
    if !(2..=3).contains(&arity) {
        return Err(AnalysisError::Arity(arity));
    }
    if coeffs.is_empty() {
        return Err(AnalysisError::Mask("the mask has no coefficients".into()));
    }
    check_total(coeffs, arity as f64, &format!("a mask of arity {arity}"))?;
    analyze(coeffs, arity, max_levels)
}

/// The analysis `subd analyze --mask2` and `subd.analyze(mask2=…)` run: the level limit
/// and the mask's total (4) checked, then [`analyze_bivariate`].
///
/// # Errors
/// [`AnalysisError::Levels`], or [`AnalysisError::Mask`] for a mask that is empty, ragged,
/// not finite or does not sum to 4.
pub fn analyze_mask2(
    rows: &[Vec<f64>],
    lattice: Lattice,
    max_levels: usize,
) -> Result<BivariateVerdict, AnalysisError> {
    if !LEVEL_RANGE.contains(&max_levels) {
        return Err(AnalysisError::Levels(max_levels));
    }
    let all: Vec<f64> = rows.iter().flatten().copied().collect();
    check_total(&all, 4.0, "a bivariate binary mask")?;
    analyze_bivariate(rows, lattice, max_levels)
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

/// Refuses a mask whose coefficients do not sum to `total` (the arity of a univariate mask,
/// 4 for a bivariate binary one), `what` naming it in the message: the front ends' check
/// before [`analyze`] or [`analyze_bivariate`], which themselves report such a mask as not
/// convergent rather than refuse it.
///
/// # Errors
/// [`AnalysisError::Mask`] with the sum found.
pub fn check_total(coeffs: &[f64], total: f64, what: &str) -> Result<(), AnalysisError> {
    let sum: f64 = coeffs.iter().sum();
    if (sum - total).abs() > 1e-9 * coeffs.len().max(1) as f64 {
        return Err(AnalysisError::Mask(format!(
            "the coefficients sum to {sum}; {what} must sum to {total} (each old point's weights in the new points)"
        )));
    }
    Ok(())
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

/// The lattice of a bivariate binary mask.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Lattice {
    /// Quad (tensor) grids: difference directions `z1`, `z2`.
    Quad,
    /// Three-direction (triangle) grids: directions `z1`, `z2`, `z1 z2`.
    ThreeDirection,
}

impl Choice for Lattice {
    const OPTION: &'static str = "lattice";
    const VALUES: &'static [(Self, &'static str, &'static str)] = &[
        (
            Lattice::Quad,
            "quad",
            "Quad (tensor) grids: directions z1, z2",
        ),
        (
            Lattice::ThreeDirection,
            "three-direction",
            "Three-direction (triangle) grids: directions z1, z2, z1 z2",
        ),
    ];
}

subd_mesh::choice_by_name!(Lattice);

/// The outcome of [`analyze_bivariate`].
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct BivariateVerdict {
    /// The lattice.
    pub lattice: Lattice,
    /// Whether convergence (C⁰) was shown.
    pub converges: bool,
    /// `Some(1)` when C¹ was shown, `Some(0)` when only C⁰, `None` when neither.
    pub smoothness: Option<usize>,
    /// For C⁰ and (when the mask factors far enough) C¹: per level `L = 1, 2, …`, the largest
    /// `‖S_{q_k}^L‖∞` over the difference directions `k`.
    pub norms: Vec<Vec<f64>>,
    /// Why the analysis stopped where it did.
    pub note: String,
}

/// A bivariate polynomial: `c[j][i]` is the coefficient of `z1^i z2^j`.
type Poly2 = Vec<Vec<f64>>;

/// Convergence and C¹ of a factorable bivariate binary mask (the subdivision lecture notes §7.2):
/// `coeffs[j][i]` is `a_{ij}`, the weight of `z1^i z2^j` (rows are powers of `z2`); the four
/// residue classes mod 2 must each sum to 1.
///
/// * **C⁰:** `a` must factor as `(1 + z1)(1 + z2) b` (quad) or `(1 + z1)(1 + z2)(1 + z1 z2) b`
///   (three-direction). Differences along direction `k` (`w_k` = `z1`, `z2`, `z1 z2`) obey the
///   scheme `q_k = a / (1 + w_k)`; the scheme converges if all of them contract:
///   `max_k ‖S_{q_k}^L‖∞ < 1` for some `L`.
/// * **C¹:** each directional derivative scheme `2 a / (1 + w_k)` must itself pass the C⁰
///   test, which needs a second factor of every `(1 + w)`; where it is missing (the
///   butterfly scheme, whose C¹ proof needs matrix-valued differences) C¹ is not shown.
///
/// ```
/// use subd_schemes::analysis::{Lattice, analyze_bivariate};
///
/// // The tensor-product cubic B-spline: C¹ shown (it is C²).
/// let b = [1.0, 4.0, 6.0, 4.0, 1.0];
/// let rows: Vec<Vec<f64>> = b.iter().map(|&y| b.iter().map(|&x| x * y / 64.0).collect()).collect();
/// let v = analyze_bivariate(&rows, Lattice::Quad, 6).unwrap();
/// assert!(v.converges);
/// assert_eq!(v.smoothness, Some(1));
/// ```
///
/// # Errors
/// [`AnalysisError::Mask`] for an empty mask, ragged rows or a coefficient that is not finite.
pub fn analyze_bivariate(
    coeffs: &[Vec<f64>],
    lattice: Lattice,
    max_levels: usize,
) -> Result<BivariateVerdict, AnalysisError> {
    let width = coeffs.first().map_or(0, Vec::len);
    if width == 0 || coeffs.iter().any(|r| r.len() != width) {
        return Err(AnalysisError::Mask(
            "the mask must be a non-empty rectangle of coefficients (rows of equal length)".into(),
        ));
    }
    if coeffs.iter().flatten().any(|c| !c.is_finite()) {
        return Err(AnalysisError::Mask(
            "a coefficient is not a finite number".into(),
        ));
    }
    let scale = coeffs.iter().flatten().fold(0.0f64, |m, c| m.max(c.abs()));
    let tol = 1e-10 * scale.max(1.0);
    let mut v = BivariateVerdict {
        lattice,
        converges: false,
        smoothness: None,
        norms: Vec::new(),
        note: String::new(),
    };
    let a: Poly2 = coeffs.to_vec();
    for (r1, r2) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
        let s: f64 = a
            .iter()
            .skip(r2)
            .step_by(2)
            .flat_map(|row| row.iter().skip(r1).step_by(2))
            .sum();
        if (s - 1.0).abs() > tol {
            v.note = format!(
                "sum rule fails: residue class ({r1}, {r2}) sums to {s}, not 1; the scheme does not converge"
            );
            return Ok(v);
        }
    }
    let directions: &[Dir] = match lattice {
        Lattice::Quad => &[Dir::X, Dir::Y],
        Lattice::ThreeDirection => &[Dir::X, Dir::Y, Dir::Diagonal],
    };
    // C⁰: the difference schemes along every direction.
    let Some(diffs) = directions
        .iter()
        .map(|&d| divide2(&a, d, tol))
        .collect::<Option<Vec<_>>>()
    else {
        v.note = format!(
            "the mask does not factor as {}: not analysed",
            lattice_factor(lattice)
        );
        return Ok(v);
    };
    let (norms, ok) = contract(&diffs, max_levels);
    v.norms.push(norms);
    if !ok {
        v.note = format!("max_k ‖S_q^L‖∞ ≥ 1 for L = 1..{max_levels}: convergence not shown");
        return Ok(v);
    }
    v.converges = true;
    v.smoothness = Some(0);
    // C¹: each derivative scheme 2a/(1 + w_k) = 2 q_k must pass the C⁰ test.
    let mut second = Vec::new();
    for q in &diffs {
        let dq: Poly2 = q
            .iter()
            .map(|r| r.iter().map(|x| 2.0 * x).collect())
            .collect();
        match directions
            .iter()
            .map(|&d| divide2(&dq, d, tol))
            .collect::<Option<Vec<_>>>()
        {
            Some(d) => second.extend(d),
            None => {
                v.note = format!(
                    "C¹ not shown: the derivative schemes do not factor as {} again",
                    lattice_factor(lattice)
                );
                return Ok(v);
            }
        }
    }
    let (norms, ok) = contract(&second, max_levels);
    v.norms.push(norms);
    if ok {
        v.smoothness = Some(1);
    } else {
        v.note = format!(
            "C¹ not shown: max_k ‖S_q^L‖∞ ≥ 1 for L = 1..{max_levels} for the derivative schemes"
        );
    }
    Ok(v)
}

fn lattice_factor(l: Lattice) -> &'static str {
    match l {
        Lattice::Quad => "(1 + z1)(1 + z2) b",
        Lattice::ThreeDirection => "(1 + z1)(1 + z2)(1 + z1 z2) b",
    }
}

/// A difference direction.
#[derive(Debug, Clone, Copy)]
enum Dir {
    X,
    Y,
    Diagonal,
}

/// `p / (1 + w)` for `w = z1`, `z2` or `z1 z2`, when exact within `tol`.
fn divide2(p: &Poly2, d: Dir, tol: f64) -> Option<Poly2> {
    let (h, w) = (p.len(), p[0].len());
    // Each line along the direction is a univariate polynomial to divide by (1 + t).
    let lines: Vec<Vec<(usize, usize)>> = match d {
        Dir::X => (0..h).map(|j| (0..w).map(|i| (j, i)).collect()).collect(),
        Dir::Y => (0..w).map(|i| (0..h).map(|j| (j, i)).collect()).collect(),
        Dir::Diagonal => {
            let mut l = Vec::new();
            for start in (0..h).rev().map(|j| (j, 0)).chain((1..w).map(|i| (0, i))) {
                let mut line = Vec::new();
                let (mut j, mut i) = start;
                while j < h && i < w {
                    line.push((j, i));
                    j += 1;
                    i += 1;
                }
                l.push(line);
            }
            l
        }
    };
    let (nh, nw) = match d {
        Dir::X => (h, w.checked_sub(1)?),
        Dir::Y => (h.checked_sub(1)?, w),
        Dir::Diagonal => (h.checked_sub(1)?, w.checked_sub(1)?),
    };
    if nh == 0 || nw == 0 {
        return None;
    }
    let mut out = vec![vec![0.0; nw]; nh];
    for line in lines {
        let vals: Vec<f64> = line.iter().map(|&(j, i)| p[j][i]).collect();
        let q = divide_by_sigma(&vals, 2, tol).or_else(|| {
            vals.iter()
                .all(|x| x.abs() <= tol)
                .then(|| vec![0.0; vals.len().saturating_sub(1)])
        })?;
        for (k, &x) in q.iter().enumerate() {
            let (j, i) = line[k];
            if j < nh && i < nw {
                out[j][i] = x;
            } else if x.abs() > tol {
                return None;
            }
        }
    }
    Some(out)
}

/// `max_k ‖S_{q_k}^L‖∞` for `L = 1..=max_levels` until it drops below 1; whether it did.
fn contract(qs: &[Poly2], max_levels: usize) -> (Vec<f64>, bool) {
    let mut powers: Vec<Poly2> = qs.to_vec();
    let mut norms = Vec::new();
    for l in 1..=max_levels {
        if l > 1 {
            for (p, q) in powers.iter_mut().zip(qs) {
                *p = multiply2(p, &upsample2(q, 1 << (l - 1)));
            }
        }
        let n = powers
            .iter()
            .map(|p| class_norm2(p, 1 << l))
            .fold(0.0, f64::max);
        norms.push(n);
        if n < 1.0 - 1e-12 {
            return (norms, true);
        }
        if powers.iter().any(|p| p.len() * p[0].len() > 1 << 22) {
            break;
        }
    }
    (norms, false)
}

fn upsample2(q: &Poly2, s: usize) -> Poly2 {
    let (h, w) = (q.len(), q[0].len());
    let mut out = vec![vec![0.0; (w - 1) * s + 1]; (h - 1) * s + 1];
    for j in 0..h {
        for i in 0..w {
            out[j * s][i * s] = q[j][i];
        }
    }
    out
}

fn multiply2(a: &Poly2, b: &Poly2) -> Poly2 {
    let (ha, wa, hb, wb) = (a.len(), a[0].len(), b.len(), b[0].len());
    let mut out = vec![vec![0.0; wa + wb - 1]; ha + hb - 1];
    for j in 0..ha {
        for i in 0..wa {
            let x = a[j][i];
            if x == 0.0 {
                continue;
            }
            for (l, row) in b.iter().enumerate() {
                for (k, &y) in row.iter().enumerate() {
                    if y != 0.0 {
                        out[j + l][i + k] += x * y;
                    }
                }
            }
        }
    }
    out
}

/// `max_{(r1, r2)} Σ |c_{r1 + s i, r2 + s j}|`.
fn class_norm2(c: &Poly2, s: usize) -> f64 {
    let mut sums = vec![0.0; s * s];
    for (j, row) in c.iter().enumerate() {
        for (i, &x) in row.iter().enumerate() {
            sums[(j % s) * s + i % s] += x.abs();
        }
    }
    sums.into_iter().fold(0.0, f64::max)
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

    /// `(1 + z)^k / 2^(k − 1)` coefficients, as a row.
    fn box1(k: usize) -> Vec<f64> {
        bspline(k)
    }

    #[test]
    fn bivariate_box_splines_and_butterfly() {
        // Tensor-product B-splines: linear (C⁰ only by this test), cubic (C¹ shown).
        let tensor = |k: usize| -> Vec<Vec<f64>> {
            let b = box1(k);
            b.iter()
                .map(|&y| b.iter().map(|&x| x * y).collect())
                .collect()
        };
        let v = analyze_bivariate(&tensor(2), Lattice::Quad, 6).unwrap();
        assert!(v.converges && v.smoothness == Some(0), "{v:?}");
        let v = analyze_bivariate(&tensor(4), Lattice::Quad, 6).unwrap();
        assert_eq!(v.smoothness, Some(1), "{v:?}");
        // Loop's regular mask is the three-direction quartic box spline
        // (1 + z1)²(1 + z2)²(1 + z1 z2)² / 16: C¹ shown (it is C²).
        let f = |p: &Poly2, d: (usize, usize)| {
            let mut f = vec![vec![0.0; d.0 + 1]; d.1 + 1];
            f[0][0] = 1.0;
            f[d.1][d.0] = 1.0;
            multiply2(p, &f)
        };
        let mut loop_mask: Poly2 = vec![vec![1.0 / 16.0]];
        for _ in 0..2 {
            loop_mask = f(&loop_mask, (1, 0));
            loop_mask = f(&loop_mask, (0, 1));
            loop_mask = f(&loop_mask, (1, 1));
        }
        let v = analyze_bivariate(&loop_mask, Lattice::ThreeDirection, 6).unwrap();
        assert_eq!(v.smoothness, Some(1), "{v:?}");
        // The butterfly scheme (w = 1/16): C⁰ shown; C¹ needs matrix differences.
        let w = 1.0 / 16.0;
        // Stencil of one old point's weights on the three-direction grid, centred at (3, 3):
        // 1 at the centre, 1/2 + 2w... written out from the refinement rules.
        let mut b = vec![vec![0.0; 7]; 7];
        let mut put = |i: i32, j: i32, x: f64| b[(j + 3) as usize][(i + 3) as usize] += x;
        put(0, 0, 1.0);
        for (i, j) in [(1, 0), (0, 1), (1, 1), (-1, 0), (0, -1), (-1, -1)] {
            put(i, j, 0.5);
        }
        for (i, j) in [(2, 1), (1, 2), (-1, 1), (-2, -1), (-1, -2), (1, -1)] {
            put(i, j, 2.0 * w);
        }
        for (i, j) in [
            (3, 1),
            (3, 2),
            (2, 3),
            (1, 3),
            (-1, 2),
            (-2, 1),
            (-3, -1),
            (-3, -2),
            (-2, -3),
            (-1, -3),
            (1, -2),
            (2, -1),
        ] {
            put(i, j, -w);
        }
        let v = analyze_bivariate(&b, Lattice::ThreeDirection, 6).unwrap();
        assert!(v.converges, "{v:?}");
        assert_eq!(v.smoothness, Some(0), "{v:?}");
        // Not factorable: refused politely.
        let v = analyze_bivariate(
            &[vec![1.0, 1.0], vec![1.0, 1.0]],
            Lattice::ThreeDirection,
            4,
        )
        .unwrap();
        assert!(!v.converges);
        assert!(analyze_bivariate(&[vec![1.0], vec![1.0, 2.0]], Lattice::Quad, 2).is_err());
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

    #[test]
    fn the_checked_analyses_refuse_what_the_fronts_refused() {
        // The cubic B-spline (1, 4, 6, 4, 1) / 8: C² by the closed form of its difference
        // masks, the same verdict checked or not.
        let cubic = [0.125, 0.5, 0.75, 0.5, 0.125];
        assert_eq!(analyze_mask(&cubic, 2, 10), analyze(&cubic, 2, 10));
        assert_eq!(analyze_mask(&cubic, 2, 10).unwrap().smoothness, Some(2));
        assert_eq!(analyze_mask(&cubic, 2, 0), Err(AnalysisError::Levels(0)));
        assert_eq!(analyze_mask(&cubic, 2, 21), Err(AnalysisError::Levels(21)));
        assert_eq!(analyze_mask(&cubic, 4, 10), Err(AnalysisError::Arity(4)));
        let e = analyze_mask(&[0.5, 1.0], 2, 10).unwrap_err().to_string();
        assert!(
            e.contains("sum to 1.5; a mask of arity 2 must sum to 2"),
            "{e}"
        );
        let half = vec![vec![0.5, 0.5], vec![0.5, 0.5]];
        let e = analyze_mask2(&half, Lattice::Quad, 5)
            .unwrap_err()
            .to_string();
        assert!(e.contains("a bivariate binary mask must sum to 4"), "{e}");
    }
}
