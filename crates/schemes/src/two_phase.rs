//! The two-phase modified Catmull-Clark scheme of Lin et al. (Lin, Pan et al., "Local
//! progressive interpolation for Catmull-Clark subdivision surfaces with shape control").
//!
//! **Phase 1** is one Catmull-Clark step with the same topology, face points and edge points,
//! and a modified vertex point with a shape parameter `λ` per vertex (Lin et al. §1, eq. (1)):
//!
//! ```text
//! v' = λ v + (1 − λ) [ α E + (1 − α) F ],   α = 10/13,
//! ```
//!
//! where `E` is the mean of the vertex's edge neighbours and `F` the mean of the vertices
//! diagonally opposite it in its quads. **Phase 2** is ordinary Catmull-Clark from then on.
//! `λ ∈ (7/20, 1]` is the range in which the paper proves that progressive interpolation
//! converges (its Theorem 1); `λ = 1` freezes the vertex (`v' = v`), which is *not* ordinary
//! Catmull-Clark (that is `α = 6/7`, `λ = 1 − 7/(4n)`, outside this family).
//!
//! # Boundaries and creases (not in the paper)
//!
//! The paper treats closed quad meshes only. Catmull-Clark's own boundary rule
//! `v' = 3/4 v + 1/8 (e₀ + e₁)` is its regular interior rule restricted to data that is
//! constant across the boundary: on a regular grid with `p(i, j) = c_i`, the interior rule
//! gives `E = c_i / 2 + (c_{i−1} + c_{i+1}) / 4` and `F = (c_{i−1} + c_{i+1}) / 2`, and
//! `λ = 9/16, α = 6/7` give exactly `3/4 c_i + 1/8 (c_{i−1} + c_{i+1})`. Doing the same with the
//! modified rule gives the phase-1 rule used here at boundary and crease vertices, with the
//! two crease neighbours `e₀`, `e₁`:
//!
//! ```text
//! v' = μ v + (1 − μ) (e₀ + e₁) / 2,   μ = λ + (1 − λ) α / 2 = (5 + 8λ) / 13.
//! ```
//!
//! The limit of a boundary vertex is then the cubic B-spline limit of the phase-1 boundary
//! polygon, `[(1 + 4μ) v + (5/2 − 2μ)(e₀ + e₁)] / 6`, a symmetric tridiagonal (along each
//! boundary curve) matrix whose eigenvalues are `[(1 + 4μ) + (5 − 4μ) cos θ] / 6 ≥ (8μ − 4)/6`.
//! For `λ ∈ (7/20, 1]`, `μ ∈ (3/5, 1]`, so they lie in `(2/15, 1]`: progressive interpolation
//! of boundary vertices converges for the whole range of the paper (and the boundary rows do
//! not depend on interior vertices, so the whole matrix is block triangular and its spectrum
//! is that of the boundary block together with that of the interior block). Corners keep
//! `v' = v`; semi-sharp vertices blend the modified smooth and crease rules with OpenSubdiv's
//! fractional weight, as ordinary Catmull-Clark does. Faces must all be quads.

use crate::RefineError;
use crate::facts::{Capability, FaceKind, OPENSUBDIV_TAGS, SchemeFacts, Split};

/// `α` of the modified vertex rule (Lin et al.).
pub const ALPHA: f64 = 10.0 / 13.0;

/// The exclusive lower end of the `λ` range in which the paper proves convergence.
pub const LAMBDA_MIN: f64 = 7.0 / 20.0;

/// The inclusive upper end of the `λ` range.
pub const LAMBDA_MAX: f64 = 1.0;

/// The shape parameters of the two-phase scheme: one `λ` for every vertex, one per vertex,
/// or none yet (a scheme named without its `λ`, which a refinement refuses until it is
/// given).
///
/// ```
/// use subd_schemes::two_phase::TwoPhase;
///
/// let tp = TwoPhase::uniform(0.5).unwrap();
/// assert_eq!(tp.lambda_for(8).unwrap().len(), 8);
/// assert!(TwoPhase::uniform(0.3).is_err()); // below 7/20
/// assert!(TwoPhase::with_any_lambda(vec![0.3; 8]).is_ok());
/// assert!(TwoPhase::unset().lambda_for(8).is_err());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct TwoPhase {
    lambda: Lambda,
}

/// Where a [`TwoPhase`]'s `λ` comes from.
#[derive(Debug, Clone, PartialEq)]
enum Lambda {
    Unset,
    Uniform(f64),
    PerVertex(std::sync::Arc<[f64]>),
}

/// The first value outside `(7/20, 1]` (or not finite), as an error.
fn check_range(lambda: &[f64]) -> Result<(), RefineError> {
    match lambda
        .iter()
        .enumerate()
        .find(|&(_, &x)| !(x > LAMBDA_MIN && x <= LAMBDA_MAX))
    {
        Some((v, &x)) => Err(RefineError::Lambda {
            vertex: v,
            value: x,
            reason: "outside (7/20, 1], where interpolation is proven to converge",
        }),
        None => Ok(()),
    }
}

impl TwoPhase {
    /// One `λ` per base vertex, each in `(7/20, 1]`.
    ///
    /// # Errors
    /// [`RefineError::Lambda`] naming the first vertex whose `λ` is out of range or not finite.
    pub fn new(lambda: Vec<f64>) -> Result<TwoPhase, RefineError> {
        check_range(&lambda)?;
        Ok(TwoPhase {
            lambda: Lambda::PerVertex(lambda.into()),
        })
    }

    /// One `λ` per base vertex, any finite value (the scheme is defined for every `λ`; only
    /// the convergence proof needs the range).
    ///
    /// # Errors
    /// [`RefineError::Lambda`] for a value that is not finite.
    pub fn with_any_lambda(lambda: Vec<f64>) -> Result<TwoPhase, RefineError> {
        if let Some((v, &x)) = lambda.iter().enumerate().find(|&(_, x)| !x.is_finite()) {
            return Err(RefineError::Lambda {
                vertex: v,
                value: x,
                reason: "not a finite number",
            });
        }
        Ok(TwoPhase {
            lambda: Lambda::PerVertex(lambda.into()),
        })
    }

    /// The same `λ` for every vertex, checked as by [`Self::new`].
    ///
    /// # Errors
    /// As [`Self::new`] (the error names vertex 0).
    pub fn uniform(lambda: f64) -> Result<TwoPhase, RefineError> {
        check_range(&[lambda])?;
        Ok(TwoPhase {
            lambda: Lambda::Uniform(lambda),
        })
    }

    /// No `λ` yet: what `"two-phase".parse::<Scheme>()` gives. A refinement with it fails
    /// with [`RefineError::MissingLambda`].
    pub fn unset() -> TwoPhase {
        TwoPhase {
            lambda: Lambda::Unset,
        }
    }

    /// Whether a `λ` was given.
    pub fn is_set(&self) -> bool {
        self.lambda != Lambda::Unset
    }

    /// The one `λ` of every vertex, when it was given that way.
    pub fn uniform_lambda(&self) -> Option<f64> {
        match self.lambda {
            Lambda::Uniform(l) => Some(l),
            _ => None,
        }
    }

    /// `λ` of every vertex of a base mesh of `num_vertices` vertices.
    ///
    /// # Errors
    /// [`RefineError::LambdaCount`] when one `λ` per vertex was given for another number of
    /// vertices; [`RefineError::MissingLambda`] when none was given.
    pub fn lambda_for(&self, num_vertices: usize) -> Result<Vec<f64>, RefineError> {
        match &self.lambda {
            Lambda::Unset => Err(RefineError::MissingLambda),
            Lambda::Uniform(l) => Ok(vec![*l; num_vertices]),
            Lambda::PerVertex(l) if l.len() == num_vertices => Ok(l.to_vec()),
            Lambda::PerVertex(l) => Err(RefineError::LambdaCount {
                given: l.len(),
                vertices: num_vertices,
            }),
        }
    }
}

/// The weight `μ` of the vertex itself in the phase-1 crease and boundary rule
/// `v' = μ v + (1 − μ)(e₀ + e₁)/2`: `λ + (1 − λ) α / 2` (derivation in the module docs).
#[inline]
pub fn crease_vertex_weight(lambda: f64) -> f64 {
    lambda + (1.0 - lambda) * ALPHA * 0.5
}

/// The two-phase scheme's facts: Catmull-Clark's topology and rules after its first step,
/// quads only (phase 1 is defined on quads), no exact evaluation of its own.
pub const FACTS: SchemeFacts = SchemeFacts {
    name: "two-phase",
    summary: "Lin et al.'s two-phase modified Catmull-Clark, quads; shape parameter λ (two-phase:λ)",
    input_faces: FaceKind::Quads,
    split: Split::Quad,
    interpolating: false,
    opensubdiv_family: true,
    tags: OPENSUBDIV_TAGS,
    peak_bytes_per_vertex: (105, Some(70)),
    capabilities: &[
        Capability::Refine,
        Capability::Limit,
        Capability::Interpolate,
    ],
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ordinary_boundary_rule_is_the_restricted_interior_rule() {
        // The same restriction applied to ordinary Catmull-Clark (λ = 9/16, α = 6/7 at
        // valence 4) must give the cubic B-spline's 3/4.
        let (lambda, alpha): (f64, f64) = (9.0 / 16.0, 6.0 / 7.0);
        assert!((lambda + (1.0 - lambda) * alpha / 2.0 - 0.75).abs() < 1e-15);
        // The modified family maps (7/20, 1] onto (3/5, 1].
        assert!((crease_vertex_weight(LAMBDA_MIN) - 0.6).abs() < 1e-15);
        assert_eq!(crease_vertex_weight(1.0), 1.0);
    }

    #[test]
    fn lambda_checks() {
        assert!(TwoPhase::new(vec![0.36, 1.0]).is_ok());
        let e = TwoPhase::new(vec![0.5, 0.35]).unwrap_err();
        assert!(TwoPhase::uniform(0.35).is_err() && TwoPhase::uniform(1.0).is_ok());
        assert_eq!(
            TwoPhase::new(vec![0.5; 3]).unwrap().lambda_for(4),
            Err(RefineError::LambdaCount {
                given: 3,
                vertices: 4
            })
        );
        assert!(matches!(e, RefineError::Lambda { vertex: 1, .. }));
        assert!(TwoPhase::new(vec![1.0 + 1e-12]).is_err());
        assert!(TwoPhase::with_any_lambda(vec![f64::NAN]).is_err());
        assert!(TwoPhase::with_any_lambda(vec![-3.0, 2.0]).is_ok());
    }
}
