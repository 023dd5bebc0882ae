//! Every patch basis as data: per control point, a polynomial in the patch's own `(s, t)`
//! and a blend factor. An evaluator outside this crate (a GPU shader, a renderer's own
//! code) then needs one routine for every kind of patch instead of one per kind, and
//! evaluates exactly what [`super::PatchTable::evaluate`] does.
//!
//! A control point's weight at `(s, t)` is `blend(s, t) · Σ c[i + 5j] sⁱ tʲ` (`i, j ≤ 4`),
//! and its derivatives are the polynomial's times the same blend: only the Gregory kinds
//! have blends other than 1, and their derivatives hold the blend constant, as OpenSubdiv's
//! evaluation does.
//!
//! The coefficients are found by interpolation: each basis function (B-spline, box-spline,
//! bilinear, linear, the Gregory nets' Bernstein products, boundary folds included) is a
//! polynomial of degree at most 3 in each of `s` and `t` (quads) or at most 4 in all
//! (triangles), so its values on a grid unisolvent for that space (`{0, ⅓, ⅔, 1}²`, or the
//! 15 points `(a/4, b/4)`, `a + b ≤ 4`) determine it.

use faer::Mat;
use faer::linalg::solvers::Solve;

use super::PatchType;
use super::basis;
use crate::LimitError;

/// Monomial slots of a basis polynomial: `sⁱ tʲ` at `i + 5j`, `i, j ≤ 4`.
pub const MONOMIALS: usize = 25;

/// The factor a control point's polynomial is multiplied by.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BasisBlend {
    /// 1.
    One,
    /// Gregory quad, corner `c`: the share of its `Fp` point,
    /// `[s/(s+t), t/((1−s)+t), (1−s)/((1−s)+(1−t)), (1−t)/(s+(1−t))][c]`, each denominator
    /// read as 1 where it is 0.
    QuadFp(u8),
    /// Gregory quad, corner `c`: 1 minus [`BasisBlend::QuadFp`]'s share.
    QuadFm(u8),
    /// Gregory triangle, corner `c` (`u = s`, `v = t`, `w = 1 − s − t`): `x/(x + y)` with
    /// `(x, y)` = `(u, v)`, `(v, w)`, `(w, u)`; 1 where `x + y` is 0.
    TriangleFp(u8),
    /// Gregory triangle, corner `c`: `y/(x + y)`; 0 where `x + y` is 0.
    TriangleFm(u8),
}

impl BasisBlend {
    /// The factor at `(s, t)`.
    pub fn at(self, s: f64, t: f64) -> f64 {
        match self {
            BasisBlend::One => 1.0,
            BasisBlend::QuadFp(c) => basis::gregory_fp_shares(s, t)[c as usize],
            BasisBlend::QuadFm(c) => 1.0 - basis::gregory_fp_shares(s, t)[c as usize],
            BasisBlend::TriangleFp(c) => basis::gregory_triangle_shares(s, t)[c as usize][0],
            BasisBlend::TriangleFm(c) => basis::gregory_triangle_shares(s, t)[c as usize][1],
        }
    }
}

/// One kind of patch's basis (with its boundary mask) as polynomials and blends.
#[derive(Debug, Clone, PartialEq)]
pub struct PatchBasisPolynomials {
    /// The kind of patch.
    pub kind: PatchType,
    /// The boundary mask the basis folds (that of [`super::PatchParam::basis_boundary`]).
    pub boundary: u8,
    /// Per control point, its polynomial's coefficients (`sⁱ tʲ` at `i + 5j`).
    pub coefficients: Vec<[f64; MONOMIALS]>,
    /// Per control point, its blend.
    pub blends: Vec<BasisBlend>,
}

impl PatchBasisPolynomials {
    /// The basis of patches of `kind` whose boundary mask is `boundary`.
    ///
    /// # Errors
    /// [`LimitError::Unsupported`] for [`PatchType::Exact`], which has no fixed basis.
    pub fn new(kind: PatchType, boundary: u8) -> Result<PatchBasisPolynomials, LimitError> {
        let Some(n) = kind.num_control_points() else {
            return Err(LimitError::Unsupported {
                face: 0,
                reason: "an exact end cap has no fixed basis",
            });
        };
        let samples = sample_points(is_triangle(kind));
        let monomials = monomials(is_triangle(kind));
        let a = Mat::<f64>::from_fn(samples.len(), monomials.len(), |r, m| {
            let (s, t) = samples[r];
            let (i, j) = monomials[m];
            s.powi(i as i32) * t.powi(j as i32)
        });
        let values: Vec<[f64; 20]> = samples
            .iter()
            .map(|&(s, t)| unblended_position(kind, boundary, s, t))
            .collect();
        let rhs = Mat::<f64>::from_fn(samples.len(), n, |r, k| values[r][k]);
        let x = a.full_piv_lu().solve(&rhs);
        let coefficients = (0..n)
            .map(|k| {
                let mut c = [0.0; MONOMIALS];
                for (m, &(i, j)) in monomials.iter().enumerate() {
                    c[i + 5 * j] = x[(m, k)];
                }
                c
            })
            .collect();
        Ok(PatchBasisPolynomials {
            kind,
            boundary,
            coefficients,
            blends: (0..n).map(|k| blend(kind, k)).collect(),
        })
    }

    /// Whether the patch is a triangle (its domain `s, t ≥ 0`, `s + t ≤ 1`).
    pub fn is_triangle(&self) -> bool {
        is_triangle(self.kind)
    }

    /// The weights of the control points at `(s, t)`: position, ∂s, ∂t, as an evaluator
    /// using this form computes them.
    pub fn weights(&self, s: f64, t: f64) -> [Vec<f64>; 3] {
        let mut out = [Vec::new(), Vec::new(), Vec::new()];
        for (c, blend) in self.coefficients.iter().zip(&self.blends) {
            let (mut p, mut ds, mut dt) = (0.0, 0.0, 0.0);
            for j in 0..5 {
                for i in 0..5 {
                    let x = c[i + 5 * j];
                    p += x * power(s, i) * power(t, j);
                    ds += x * i as f64 * power(s, i.saturating_sub(1)) * power(t, j);
                    dt += x * j as f64 * power(s, i) * power(t, j.saturating_sub(1));
                }
            }
            let b = blend.at(s, t);
            out[0].push(b * p);
            out[1].push(b * ds);
            out[2].push(b * dt);
        }
        out
    }
}

/// `x^n` with `0^0 = 1`.
fn power(x: f64, n: usize) -> f64 {
    x.powi(n as i32)
}

fn is_triangle(kind: PatchType) -> bool {
    matches!(
        kind,
        PatchType::Loop | PatchType::Triangles | PatchType::GregoryTriangle
    )
}

/// A grid on which polynomials of the kind's space are determined by their values.
fn sample_points(triangle: bool) -> Vec<(f64, f64)> {
    if triangle {
        (0..=4)
            .flat_map(|b| (0..=4 - b).map(move |a| (a as f64 / 4.0, b as f64 / 4.0)))
            .collect()
    } else {
        (0..4)
            .flat_map(|b| (0..4).map(move |a| (a as f64 / 3.0, b as f64 / 3.0)))
            .collect()
    }
}

/// The monomials `(i, j)` of the kind's space: bicubic or quartic.
fn monomials(triangle: bool) -> Vec<(usize, usize)> {
    if triangle {
        (0..=4)
            .flat_map(|j| (0..=4 - j).map(move |i| (i, j)))
            .collect()
    } else {
        (0..4).flat_map(|j| (0..4).map(move |i| (i, j))).collect()
    }
}

/// The position weights at `(s, t)` with every blend 1.
fn unblended_position(kind: PatchType, boundary: u8, s: f64, t: f64) -> [f64; 20] {
    match kind {
        PatchType::GregoryBasis => basis::gregory_net(s, t)[0],
        PatchType::GregoryTriangle => {
            let w = basis::gregory_triangle_net(s, t)[0];
            std::array::from_fn(|k| if k < 18 { w[k] } else { 0.0 })
        }
        _ => basis::weights(kind, s, t, boundary)[0],
    }
}

/// The blend of control point `k` of `kind` (per corner `P, Ep, Em, Fp, Fm`).
fn blend(kind: PatchType, k: usize) -> BasisBlend {
    let corner = (k / 5) as u8;
    match (kind, k % 5) {
        (PatchType::GregoryBasis, 3) => BasisBlend::QuadFp(corner),
        (PatchType::GregoryBasis, 4) => BasisBlend::QuadFm(corner),
        (PatchType::GregoryTriangle, 3) if k < 15 => BasisBlend::TriangleFp(corner),
        (PatchType::GregoryTriangle, 4) if k < 15 => BasisBlend::TriangleFm(corner),
        _ => BasisBlend::One,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Places inside, on the edges and at the corners of both domains.
    const PLACES: [(f64, f64); 8] = [
        (0.2, 0.3),
        (0.0, 0.0),
        (1.0, 0.0),
        (0.0, 1.0),
        (0.61, 0.05),
        (0.25, 0.74),
        (0.5, 0.0),
        (0.0, 0.37),
    ];

    /// The polynomial form gives the weights the table evaluates with (position and
    /// first derivatives) for every kind and every boundary mask, to 1e-12.
    #[test]
    fn the_polynomials_are_the_bases() {
        for kind in PatchType::ALL {
            if kind == PatchType::Exact {
                assert!(PatchBasisPolynomials::new(kind, 0).is_err());
                continue;
            }
            let masks: u8 = match kind {
                PatchType::Regular => 16,
                PatchType::Loop => 32,
                _ => 1,
            };
            for boundary in 0..masks {
                let poly = PatchBasisPolynomials::new(kind, boundary).unwrap();
                for &(s, t) in &PLACES {
                    if poly.is_triangle() && s + t > 1.0 {
                        continue;
                    }
                    let want = basis::weights(kind, s, t, boundary);
                    let got = poly.weights(s, t);
                    for (d, row) in got.iter().enumerate() {
                        for (k, w) in row.iter().enumerate() {
                            assert!(
                                (w - want[d][k]).abs() < 1e-12,
                                "{kind} mask {boundary} at ({s}, {t}): row {d} point {k}: {w} vs {}",
                                want[d][k]
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn a_bspline_point_is_a_tensor_product_of_cubics() {
        // The corner point 0 of an interior B-spline patch: (1 − s)³ (1 − t)³ / 36.
        let poly = PatchBasisPolynomials::new(PatchType::Regular, 0).unwrap();
        let c = &poly.coefficients[0];
        let cubic = [1.0, -3.0, 3.0, -1.0];
        for j in 0..4 {
            for i in 0..4 {
                let want = cubic[i] * cubic[j] / 36.0;
                assert!((c[i + 5 * j] - want).abs() < 1e-14, "{i} {j}");
            }
        }
    }
}
