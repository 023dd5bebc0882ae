//! Simple constrained deformation (Borrel & Moreau 1994, "Scodef"; Sun et al. 2012 §3 with its
//! equation corrected, see SEEDS.md): points Q move by `d(Q) = Σ_i M_i B(‖Q − C_i‖ / R_i)`.
//!
//! The blend is Wendland's `B(r) = (1 − r)⁴ (4r + 1)` for r < 1 and 0 beyond: B(0) = 1,
//! and B, B' and B'' vanish at r = 1 (so the deformation is C² across every radius), and
//! the matrix `B(‖C_j − C_i‖ / R)` of distinct points with one radius is positive definite
//! (Wendland 1995), so equal radii never make the system singular. The vectors M_i solve
//! `Σ_i M_i B(‖C_j − C_i‖ / R_i) = D_j` so that every constraint point C_j moves by exactly
//! D_j. A point outside every radius keeps its coordinates bit for bit.

use faer::Mat;
use faer::linalg::solvers::Solve;
use glam::DVec3;

use crate::EditError;

/// One constraint point of a deformation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeformConstraint {
    /// The point C_i.
    pub center: DVec3,
    /// Its radius of influence R_i (> 0).
    pub radius: f64,
    /// Its displacement D_i.
    pub displacement: DVec3,
}

/// The radial blend: `(1 − r)⁴ (4r + 1)` on [0, 1), 0 beyond.
pub fn blend(r: f64) -> f64 {
    if r >= 1.0 {
        0.0
    } else {
        let s = 1.0 - r;
        s * s * s * s * (4.0 * r + 1.0)
    }
}

/// A solved deformation.
///
/// ```
/// use subd_editing::deform::{DeformConstraint, Deformation};
/// use subd_mesh::DVec3;
///
/// let d = Deformation::new(&[DeformConstraint {
///     center: DVec3::ZERO,
///     radius: 1.0,
///     displacement: DVec3::new(0.0, 0.0, 0.5),
/// }]).unwrap();
/// let mut points = vec![DVec3::ZERO, DVec3::new(0.5, 0.0, 0.0), DVec3::new(2.0, 0.0, 0.0)];
/// d.apply(&mut points);
/// assert_eq!(points[0], DVec3::new(0.0, 0.0, 0.5)); // the constraint point, exactly
/// assert!(points[1].z > 0.0 && points[1].z < 0.5); // blended
/// assert_eq!(points[2], DVec3::new(2.0, 0.0, 0.0)); // outside: untouched
/// ```
#[derive(Clone, Debug)]
pub struct Deformation {
    constraints: Vec<DeformConstraint>,
    /// The solved M_i.
    pub m: Vec<DVec3>,
}

impl Deformation {
    /// Solves for the M_i.
    ///
    /// # Errors
    /// [`EditError::Deform`] naming the constraint: a non-finite value, a radius ≤ 0, or a
    /// system that is singular (constraint points that coincide).
    pub fn new(constraints: &[DeformConstraint]) -> Result<Deformation, EditError> {
        for (i, c) in constraints.iter().enumerate() {
            let bad = |m: &str| EditError::Deform {
                index: i,
                message: m.into(),
            };
            if !c.center.is_finite() || !c.displacement.is_finite() || !c.radius.is_finite() {
                return Err(bad("a value is not finite"));
            }
            if c.radius <= 0.0 {
                return Err(bad("the radius must be positive"));
            }
            if let Some(j) = constraints[..i].iter().position(|d| d.center == c.center) {
                return Err(bad(&format!("its centre coincides with constraint {j}'s")));
            }
        }
        let n = constraints.len();
        if n == 0 {
            return Ok(Deformation {
                constraints: Vec::new(),
                m: Vec::new(),
            });
        }
        let f = Mat::from_fn(n, n, |j, i| {
            let c = &constraints[i];
            blend((constraints[j].center - c.center).length() / c.radius)
        });
        let rhs = Mat::from_fn(n, 3, |j, k| constraints[j].displacement[k]);
        let lu = f.partial_piv_lu();
        let m = lu.solve(&rhs);
        let out: Vec<DVec3> = (0..n)
            .map(|i| DVec3::new(m[(i, 0)], m[(i, 1)], m[(i, 2)]))
            .collect();
        // A singular system shows as non-finite or non-reproducing M.
        for (j, c) in constraints.iter().enumerate() {
            let d = displacement_at(constraints, &out, c.center);
            let scale = c.displacement.length().max(1e-300);
            if !d.is_finite() || (d - c.displacement).length() > 1e-9 * scale.max(1.0) {
                return Err(EditError::Deform {
                    index: j,
                    message: "the system is singular (constraint points too close for their radii)"
                        .into(),
                });
            }
        }
        Ok(Deformation {
            constraints: constraints.to_vec(),
            m: out,
        })
    }

    /// `d(q)`.
    pub fn displacement(&self, q: DVec3) -> DVec3 {
        displacement_at(&self.constraints, &self.m, q)
    }

    /// The largest distance between a constraint point's solved displacement and the one
    /// it asked for (rounding of the solve only).
    pub fn max_constraint_error(&self) -> f64 {
        self.constraints
            .iter()
            .map(|c| (self.displacement(c.center) - c.displacement).length())
            .fold(0.0, f64::max)
    }

    /// Moves `points` in place; returns how many moved. Constraint centres among them move
    /// by their displacement exactly (to rounding of the solve).
    pub fn apply(&self, points: &mut [DVec3]) -> usize {
        let mut moved = 0;
        for p in points.iter_mut() {
            if let Some(i) = self.constraints.iter().position(|c| c.center == *p) {
                // Exactly D_i at the constraint point itself.
                *p += self.constraints[i].displacement;
                moved += 1;
                continue;
            }
            if self
                .constraints
                .iter()
                .any(|c| (*p - c.center).length() < c.radius)
            {
                *p += self.displacement(*p);
                moved += 1;
            }
        }
        moved
    }
}

fn displacement_at(cs: &[DeformConstraint], m: &[DVec3], q: DVec3) -> DVec3 {
    cs.iter()
        .zip(m)
        .map(|(c, &mi)| mi * blend((q - c.center).length() / c.radius))
        .sum()
}
