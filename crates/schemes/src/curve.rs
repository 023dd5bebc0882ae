//! Subdivision curves: linear schemes on open and closed polylines in 2D or 3D (the subdivision
//! lecture notes §2–6), and the nonlinear circle-average schemes on planar point–normal pairs (Liu
//! et al.).
//!
//! # Linear schemes
//!
//! A stationary scheme of arity `m` (2 binary, 3 ternary) is a mask `a_j`: the new point `i`
//! is `p'_i = Σ_k a_{i − m k} p_k`. [`CurveScheme`] covers Chaikin, Lane–Riesenfeld B-splines of
//! any order, the 4-point scheme with tension `ω`, the two-parameter 4-point scheme (Liu et al.),
//! the 3-point ternary interpolatory scheme (Liu et al.), the non-stationary tension scheme that
//! reproduces circles (a new mask each level), Sabin & Dodgson's circle-preserving 4-point
//! scheme (nonlinear, planar) and the variational interpolatory scheme (a banded solve each
//! level).
//!
//! **Open curves.** The polygon is continued past each end by point reflection through the
//! end point, `p_{−k} = 2 p_0 − p_k` — for interpolatory schemes this is the linear
//! extrapolation of the missing neighbours (`p_{−1} = 2 p_0 − p_1`). A symmetric scheme maps
//! such data to data with the same symmetry, and a continuous curve symmetric under the
//! reflection through `p_0` passes through `p_0`: **every scheme here interpolates the end
//! points of an open curve**, and reproduces straight lines there. For dual schemes
//! (Chaikin, odd B-spline orders) the centre of symmetry falls between two new points; it is
//! carried along level by level and the end points are written as the first and last points
//! of the result.
//!
//! # Circle-average schemes
//!
//! [`circle_average`] is Lipovetsky & Dyn's (2016) average of two point–normal pairs: the
//! point on the circle arc through both points whose normals are the pairs' normals, with the
//! normal the weighted geodesic average. [`CircleScheme`] rewrites the two-parameter 4-point
//! and the 3-point ternary schemes as repeated binary averages `A_w(a, b) = (1 − w) a + w b`
//! and replaces each by the circle average (Liu et al.):
//!
//! * 4-point, odd: `A_{1/2}(A_{1+2ω}(p_{i−1}, p_i), A_{1+2ω}(p_{i+2}, p_{i+1}))`;
//!   even: `A_{2μ}(p_i, A_{1/2}(p_{i−1}, p_{i+1}))`.
//! * ternary: `p_{3i} = p_i`, `p_{3i+1} = A_ω(A_s(p_{i−1}, p_i), p_{i+1})`,
//!   `p_{3i+2} = A_ω(A_s(p_{i+2}, p_{i+1}), p_i)` with `s = (4/3 − 2ω)/(1 − ω)`.
//!
//! Linearly these are exactly the masks of [`CurveScheme::FourPoint2`] and
//! [`CurveScheme::Ternary3`]; on points of a circle with radial normals every average stays on
//! the circle, so the schemes reproduce circles.

use glam::{DVec2, DVec3};
use rayon::prelude::*;
use thiserror::Error;

/// Why a curve cannot be subdivided.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum CurveError {
    /// Too few points for the scheme.
    #[error("{given} points; this scheme needs at least {needed}")]
    TooFewPoints {
        /// Points given.
        given: usize,
        /// Points needed.
        needed: usize,
    },
    /// A parameter out of its range.
    #[error("{0}")]
    Parameter(String),
    /// A point or normal that is not finite.
    #[error("point {0} is not finite")]
    NotFinite(usize),
    /// The result would be too large.
    #[error("{levels} levels of {points} points would make more than 2^28 points")]
    TooLarge {
        /// Levels asked for.
        levels: usize,
        /// Input points.
        points: usize,
    },
    /// The variational scheme's banded system could not be solved.
    #[error("variational scheme: {0}")]
    Solve(String),
}

/// A linear curve scheme.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CurveScheme {
    /// Chaikin's corner cutting (the quadratic B-spline, order 3).
    Chaikin,
    /// Uniform B-spline of order `k ≥ 2` (degree `k − 1`) by Lane–Riesenfeld: mask
    /// `2^{-(k−1)} C(k, j)` (the subdivision lecture notes §2).
    BSpline {
        /// Order (2 = linear, 3 = Chaikin, 4 = cubic).
        order: usize,
    },
    /// The interpolatory 4-point scheme, odd rule `−ω p_{i−1} + (1/2 + ω)(p_i + p_{i+1}) −
    /// ω p_{i+2}` (`ω = 1/16`: Dubuc–Deslauriers).
    FourPoint {
        /// Tension.
        omega: f64,
    },
    /// The two-parameter 4-point binary scheme of Liu et al.: even rule
    /// `μ p_{i−1} + (1 − 2μ) p_i + μ p_{i+1}`, odd rule as [`CurveScheme::FourPoint`].
    FourPoint2 {
        /// Tension.
        omega: f64,
        /// Displacement of the old points (0: interpolatory).
        mu: f64,
    },
    /// The 3-point ternary interpolatory scheme of Liu et al.: `p_{3i} = p_i`,
    /// `p_{3i+1} = (ω − 1/3) p_{i−1} + (4/3 − 2ω) p_i + ω p_{i+1}`, and its mirror image.
    Ternary3 {
        /// The parameter (convergent for 1/6 < ω < 1/3, C¹ for 2/9 < ω < 1/3).
        omega: f64,
    },
    /// The non-stationary tension scheme (the subdivision lecture notes §5): at level `k`,
    /// `α_k = sqrt((1 + α_{k−1})/2)`, `p_{2i} = (p_{i−1} + (2 + 4α_k) p_i + p_{i+1})/(4 + 4α_k)`,
    /// `p_{2i+1} = (p_i + p_{i+1})/2`. `α_0 = 1` is the cubic B-spline; on a regular N-gon,
    /// `α_0 = cos(2π/N)` keeps every level on a circle. (The first step uses `α_1`, not `α_0`:
    /// the rules map `z^j`, `z = e^{iθ}`, to a scaled copy of `e^{ijθ/2}` exactly when
    /// `α = cos(θ/2)` — derivation in the test `tension_scheme_keeps_a_regular_polygon_on_a_circle`.)
    Tension {
        /// `α_0 ≥ −1`.
        alpha0: f64,
    },
    /// Sabin & Dodgson's circle-preserving variant of the 4-point scheme (2005), planar
    /// points only: old points stay; the new point between `b` and `c` (neighbours `a`, `d`)
    /// lies on the circle through `b` and `c` with curvature
    /// `κ = (κ_abc |bd| + κ_bcd |ac|)/(|bd| + |ac|)`, above the chord point
    /// `(b + c)/2 + (λ/2)(c − b)`, where `λ = ((μ − 1)/(μ + 1)) / (1 − 2 h μ/(μ + 1)²)`,
    /// `μ = |ac|/|bd|` and `h = s/(1 + sqrt(1 − s))`, `s = κ² |bc|²/4` (λ shifts the point
    /// toward the longer side when the spacing is uneven; uniform spacing gives the arc
    /// midpoint). Four points on a circle give a point on it, so circles are reproduced. Open
    /// curves: the end intervals use the one triangle they have and `λ = 0`.
    CirclePreserving,
    /// Variational interpolatory subdivision (Kobbelt; the subdivision lecture notes §6(a)): old
    /// points stay, new points minimise the sum of squared second differences of the refined
    /// polygon, i.e. solve `u_{i−1} + 6 u_i + u_{i+1} = 4 (p_i + p_{i+1})` (a banded system, faer).
    Variational,
}

/// Refinement of one level by a stationary mask.
#[derive(Debug, Clone, PartialEq)]
pub struct Mask {
    /// Arity `m` (2 or 3).
    pub arity: usize,
    /// Coefficients `a_j` for `j = first, first + 1, …`.
    pub coeffs: Vec<f64>,
    /// Index of the first coefficient.
    pub first: i64,
}

impl Mask {
    /// Offset `d` with new index `i` ↔ old parameter `(i − d)/m` (the weighted centre of every
    /// rule; the same for all of them in a symmetric scheme).
    fn shift(&self) -> f64 {
        // Centre of the rule of new point 0: Σ_k k a_{−m k} over its k, i.e. −Σ j a_j / m
        // over the j ≡ 0 (mod m).
        let m = self.arity as i64;
        let mut c = 0.0;
        for (k, &a) in self.coeffs.iter().enumerate() {
            let j = self.first + k as i64;
            if j.rem_euclid(m) == 0 {
                c += a * j as f64;
            }
        }
        c
    }
}

impl CurveScheme {
    /// The mask of level `level` (1-based), or `None` for the variational scheme.
    pub fn mask(&self, level: usize) -> Option<Mask> {
        let binary = |coeffs: Vec<f64>, first: i64| {
            Some(Mask {
                arity: 2,
                coeffs,
                first,
            })
        };
        match *self {
            CurveScheme::Chaikin => CurveScheme::BSpline { order: 3 }.mask(level),
            CurveScheme::BSpline { order } => {
                let mut c = vec![1.0f64];
                for _ in 0..order {
                    let mut n = vec![0.0; c.len() + 1];
                    for (i, &x) in c.iter().enumerate() {
                        n[i] += x * 0.5;
                        n[i + 1] += x * 0.5;
                    }
                    c = n;
                }
                c.iter_mut().for_each(|x| *x *= 2.0);
                // Centred: a_j for j = −⌊k/2⌋…
                binary(c, -(order as i64 / 2))
            }
            CurveScheme::FourPoint { omega } => {
                CurveScheme::FourPoint2 { omega, mu: 0.0 }.mask(level)
            }
            CurveScheme::FourPoint2 { omega, mu } => {
                let h = 0.5 + omega;
                // j = −3 … 3: odd j from the odd rule, even j from the even rule.
                binary(vec![-omega, mu, h, 1.0 - 2.0 * mu, h, mu, -omega], -3)
            }
            CurveScheme::Ternary3 { omega } => {
                let (a, b) = (omega - 1.0 / 3.0, 4.0 / 3.0 - 2.0 * omega);
                // p_{3i+r} = Σ_k a_{3i + r − 3k} p_k: j = 3(i − k) + r.
                // r = 1: k = i−1 → j = 4: a; k = i → 1: b; k = i+1 → −2: ω.
                // r = 2: k = i → 2: ω; k = i+1 → −1: b; k = i+2 → −4: a. r = 0: j = 0: 1.
                Some(Mask {
                    arity: 3,
                    coeffs: vec![a, 0.0, omega, b, 1.0, b, omega, 0.0, a],
                    first: -4,
                })
            }
            CurveScheme::Tension { alpha0 } => {
                let mut alpha = alpha0;
                for _ in 0..level {
                    alpha = ((1.0 + alpha) / 2.0).sqrt();
                }
                let d = 4.0 + 4.0 * alpha;
                binary(
                    vec![1.0 / d, 0.5, (2.0 + 4.0 * alpha) / d, 0.5, 1.0 / d],
                    -2,
                )
            }
            CurveScheme::Variational | CurveScheme::CirclePreserving => None,
        }
    }

    /// Whether old points stay (interpolatory schemes).
    pub fn is_interpolatory(&self) -> bool {
        match *self {
            CurveScheme::FourPoint { .. }
            | CurveScheme::Ternary3 { .. }
            | CurveScheme::Variational => true,
            CurveScheme::FourPoint2 { mu, .. } => mu == 0.0,
            CurveScheme::BSpline { order } => order == 2,
            _ => false,
        }
    }

    /// Checks the parameters.
    ///
    /// # Errors
    /// [`CurveError::Parameter`] naming the parameter and its range.
    pub fn check(&self) -> Result<(), CurveError> {
        let finite = |name: &str, x: f64| {
            if x.is_finite() {
                Ok(())
            } else {
                Err(CurveError::Parameter(format!(
                    "{name} = {x} is not a finite number"
                )))
            }
        };
        match *self {
            CurveScheme::BSpline { order } if !(2..=32).contains(&order) => Err(
                CurveError::Parameter(format!("order {order}: a B-spline order must be 2 to 32")),
            ),
            CurveScheme::FourPoint { omega } => finite("omega", omega),
            CurveScheme::FourPoint2 { omega, mu } => finite("omega", omega).and(finite("mu", mu)),
            CurveScheme::Ternary3 { omega } => finite("omega", omega),
            CurveScheme::Tension { alpha0 } if !(alpha0 >= -1.0 && alpha0.is_finite()) => Err(
                CurveError::Parameter(format!("alpha0 = {alpha0}: must be a number ≥ −1")),
            ),
            _ => Ok(()),
        }
    }

    /// Subdivides `points` `levels` times (a closed polygon when `closed`).
    ///
    /// ```
    /// use subd_schemes::curve::CurveScheme;
    /// use glam::DVec3;
    ///
    /// // The 4-point scheme keeps the old points and reproduces cubics.
    /// let p: Vec<DVec3> = (0..6).map(|i| DVec3::new(i as f64, (i as f64).powi(3), 0.0)).collect();
    /// let out = CurveScheme::FourPoint { omega: 1.0 / 16.0 }.subdivide(&p, false, 1).unwrap();
    /// assert_eq!(out.len(), 11);
    /// assert_eq!(out[4], p[2]);
    /// assert!((out[5].y - 2.5f64.powi(3)).abs() < 1e-12);
    /// ```
    ///
    /// # Errors
    /// [`CurveError`] for bad parameters, too few or non-finite points, or a result of
    /// more than 2^28 points.
    pub fn subdivide(
        &self,
        points: &[DVec3],
        closed: bool,
        levels: usize,
    ) -> Result<Vec<DVec3>, CurveError> {
        self.check()?;
        check_points(points.iter().map(|p| p.is_finite()), points.len(), closed)?;
        let arity = self.mask(1).map_or(2, |m| m.arity);
        check_size(points.len(), arity, levels)?;
        if *self == CurveScheme::CirclePreserving && points.iter().any(|p| p.z != 0.0) {
            return Err(CurveError::Parameter(
                "the circle-preserving scheme works on planar points (z = 0)".into(),
            ));
        }
        let mut cur = Polyline::new(points.to_vec(), closed);
        for level in 1..=levels {
            cur = match self.mask(level) {
                Some(mask) => cur.refine(&mask),
                None if *self == CurveScheme::Variational => cur.variational()?,
                None => cur.circle_preserving(),
            };
        }
        Ok(cur.into_points())
    }
}

fn check_points(
    finite: impl Iterator<Item = bool>,
    n: usize,
    closed: bool,
) -> Result<(), CurveError> {
    let needed = if closed { 3 } else { 2 };
    if n < needed {
        return Err(CurveError::TooFewPoints { given: n, needed });
    }
    for (i, ok) in finite.enumerate() {
        if !ok {
            return Err(CurveError::NotFinite(i));
        }
    }
    Ok(())
}

fn check_size(n: usize, arity: usize, levels: usize) -> Result<(), CurveError> {
    let mut size = n as u128;
    for _ in 0..levels {
        size *= arity as u128;
        if size > 1 << 28 {
            return Err(CurveError::TooLarge { levels, points: n });
        }
    }
    Ok(())
}

/// A polyline at some level. Open ones carry their two centres of reflection: the position
/// `s` (in index units of `points`) and the point there.
#[derive(Debug, Clone)]
struct Polyline {
    points: Vec<DVec3>,
    closed: bool,
    left: (f64, DVec3),
    right: (f64, DVec3),
}

impl Polyline {
    fn new(points: Vec<DVec3>, closed: bool) -> Polyline {
        let n = points.len();
        Polyline {
            left: (0.0, points[0]),
            right: ((n - 1) as f64, points[n - 1]),
            points,
            closed,
        }
    }

    /// Point `k` of the infinite continuation: wrapped for closed curves, reflected through
    /// the end centres (as often as needed) for open ones.
    #[inline]
    fn at(&self, k: i64) -> DVec3 {
        let n = self.points.len() as i64;
        if self.closed {
            return self.points[k.rem_euclid(n) as usize];
        }
        // Index k reflects to 2s − k; the value v to 2c − v. Track the value as
        // sign · p + offset through as many reflections as a short polygon needs.
        let (l2, r2) = (
            (2.0 * self.left.0).round() as i64,
            (2.0 * self.right.0).round() as i64,
        );
        let (mut k, mut sign, mut offset) = (k, 1.0, DVec3::ZERO);
        for _ in 0..64 {
            let c = if k < 0 {
                k = l2 - k;
                self.left.1
            } else if k > n - 1 {
                k = r2 - k;
                self.right.1
            } else {
                break;
            };
            offset += 2.0 * sign * c;
            sign = -sign;
        }
        sign * self.points[k.clamp(0, n - 1) as usize] + offset
    }

    fn refine(&self, mask: &Mask) -> Polyline {
        let m = mask.arity as i64;
        let len = mask.coeffs.len() as i64;
        let d = mask.shift();
        let point = |i: i64| {
            // k with first ≤ i − m k < first + len.
            let k_hi = (i - mask.first).div_euclid(m);
            let k_lo = (i - mask.first - len + 1 + m - 1).div_euclid(m);
            let mut acc = DVec3::ZERO;
            for k in k_lo..=k_hi {
                let a = mask.coeffs[(i - m * k - mask.first) as usize];
                if a != 0.0 {
                    acc += a * self.at(k);
                }
            }
            acc
        };
        if self.closed {
            let n = self.points.len() as i64;
            // New index i ↔ old parameter (i − d)/m; start at the point nearest parameter 0.
            let start = d.round() as i64;
            let points = (0..m * n)
                .into_par_iter()
                .map(|i| point(start + i))
                .collect();
            return Polyline {
                points,
                closed: true,
                left: self.left,
                right: self.right,
            };
        }
        let (sl, sr) = (m as f64 * self.left.0 + d, m as f64 * self.right.0 + d);
        let (lo, hi) = (sl.ceil() as i64, sr.floor() as i64);
        let points = (lo..=hi).into_par_iter().map(point).collect();
        Polyline {
            points,
            closed: false,
            left: (sl - lo as f64, self.left.1),
            right: (sr - lo as f64, self.right.1),
        }
    }

    /// One level of Kobbelt's variational scheme: old points stay at even positions, the new
    /// ones solve `u_{i−1} + 6 u_i + u_{i+1} = 4 (p_i + p_{i+1})` (cyclic for closed curves;
    /// for open ones the reflected neighbour `u_{−1} = 2 p_0 − u_0` turns the first row into
    /// `5 u_0 + u_1 = 2 p_0 + 4 p_1`, and likewise at the end).
    fn variational(&self) -> Result<Polyline, CurveError> {
        use faer::linalg::solvers::Solve;
        use faer::sparse::{SparseColMat, Triplet};
        let p = &self.points;
        let n = p.len();
        let u = if self.closed { n } else { n - 1 };
        let mut t = Vec::with_capacity(3 * u);
        let mut rhs = faer::Mat::<f64>::zeros(u, 3);
        for i in 0..u {
            let (a, b) = (p[i], p[(i + 1) % n]);
            let mut diag = 6.0;
            let mut r = 4.0 * (a + b);
            if self.closed {
                t.push(Triplet::new(i, (i + u - 1) % u, 1.0));
                t.push(Triplet::new(i, (i + 1) % u, 1.0));
            } else {
                if i > 0 {
                    t.push(Triplet::new(i, i - 1, 1.0));
                } else {
                    diag -= 1.0;
                    r -= 2.0 * p[0];
                }
                if i + 1 < u {
                    t.push(Triplet::new(i, i + 1, 1.0));
                } else {
                    diag -= 1.0;
                    r -= 2.0 * p[n - 1];
                }
            }
            t.push(Triplet::new(i, i, diag));
            for k in 0..3 {
                rhs[(i, k)] = r[k];
            }
        }
        let a = SparseColMat::<usize, f64>::try_new_from_triplets(u, u, &t)
            .map_err(|e| CurveError::Solve(format!("{e:?}")))?;
        let lu = a.sp_lu().map_err(|e| CurveError::Solve(format!("{e:?}")))?;
        lu.solve_in_place(rhs.as_mut());
        let mut out = Vec::with_capacity(n + u);
        for i in 0..n {
            out.push(p[i]);
            if i < u {
                out.push(DVec3::new(rhs[(i, 0)], rhs[(i, 1)], rhs[(i, 2)]));
            }
        }
        let len = out.len();
        Ok(Polyline {
            left: (0.0, out[0]),
            right: ((len - 1) as f64, out[len - 1]),
            points: out,
            closed: self.closed,
        })
    }

    /// One level of Sabin & Dodgson's circle-preserving 4-point scheme (see
    /// [`CurveScheme::CirclePreserving`]).
    fn circle_preserving(&self) -> Polyline {
        let p: Vec<DVec2> = self.points.iter().map(|q| q.truncate()).collect();
        let n = p.len();
        let count = if self.closed { n } else { n - 1 };
        let out: Vec<DVec3> = (0..n)
            .into_par_iter()
            .flat_map_iter(|i| {
                let new = (i < count).then(|| {
                    let (b, c) = (p[i], p[(i + 1) % n]);
                    let prev = (self.closed || i > 0).then(|| p[(i + n - 1) % n]);
                    let next = (self.closed || i + 2 < n).then(|| p[(i + 2) % n]);
                    let m = match (prev, next) {
                        (Some(a), Some(d)) => sabin_dodgson(a, b, c, d),
                        (None, Some(d)) => arc_point(b, c, signed_curvature(b, c, d), 0.0),
                        (Some(a), None) => arc_point(b, c, signed_curvature(a, b, c), 0.0),
                        (None, None) => 0.5 * (b + c),
                    };
                    m.extend(0.0)
                });
                std::iter::once(self.points[i]).chain(new)
            })
            .collect();
        let len = out.len();
        Polyline {
            left: (0.0, out[0]),
            right: ((len - 1) as f64, out[len - 1]),
            points: out,
            closed: self.closed,
        }
    }

    /// The points, with the end points of an open curve first and last.
    fn into_points(self) -> Vec<DVec3> {
        if self.closed {
            return self.points;
        }
        let mut out = Vec::with_capacity(self.points.len() + 2);
        if self.left.0 != 0.0 {
            out.push(self.left.1);
        }
        let last_is_centre = self.right.0 == (self.points.len() - 1) as f64;
        out.extend(self.points);
        if !last_is_centre {
            out.push(self.right.1);
        }
        out
    }
}

/// Signed curvature of the circle through `a`, `b`, `c` (positive for a left turn).
fn signed_curvature(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    let den = (b - a).length() * (c - b).length() * (c - a).length();
    if den == 0.0 {
        return 0.0;
    }
    2.0 * (b - a).perp_dot(c - b) / den
}

/// The point of the circle of signed curvature `k` through `b` and `c` (its arc between
/// them) above the chord point `(b + c)/2 + (λ/2)(c − b)`.
fn arc_point(b: DVec2, c: DVec2, k: f64, lambda: f64) -> DVec2 {
    let d = c - b;
    let dd = d.length_squared();
    if dd == 0.0 {
        return b;
    }
    // Sagitta at chord offset x = λ|d|/2: (1/k)(sqrt(1 − k²x²) − sqrt(1 − k²|d|²/4)),
    // written without cancellation as (k|d|²/4)(f(1) − λ² f(λ)), f(t) = 1/(1 + sqrt(1 − t²s)).
    let s = k * k * dd / 4.0;
    let f = |t: f64| 1.0 / (1.0 + (1.0 - t * t * s).max(0.0).sqrt());
    let height = k * dd / 4.0 * (f(1.0) - lambda * lambda * f(lambda));
    // A left turn (k > 0) has its centre on the left: the arc bulges to the right.
    0.5 * (b + c) + 0.5 * lambda * d - (height / dd.sqrt()) * d.perp()
}

/// Sabin & Dodgson's new point between `b` and `c`.
fn sabin_dodgson(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> DVec2 {
    let (ac, bd) = ((c - a).length(), (d - b).length());
    if ac + bd == 0.0 {
        return 0.5 * (b + c);
    }
    let k = (signed_curvature(a, b, c) * bd + signed_curvature(b, c, d) * ac) / (bd + ac);
    let mu = if bd > 0.0 { ac / bd } else { 1.0 };
    let s = k * k * (c - b).length_squared() / 4.0;
    let h = s / (1.0 + (1.0 - s).max(0.0).sqrt());
    let lambda = ((mu - 1.0) / (mu + 1.0)) / (1.0 - 2.0 * h * mu / ((mu + 1.0) * (mu + 1.0)));
    arc_point(b, c, k, lambda)
}

/// A planar point with a unit normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointNormal {
    /// Position.
    pub p: DVec2,
    /// Unit normal.
    pub n: DVec2,
}

/// Lipovetsky & Dyn's circle average `A_w((p0, n0), (p1, n1))` with weights `1 − w`, `w`
/// (`w` outside `[0, 1]` extrapolates along the same circle).
///
/// The normal is the weighted geodesic average of the normals (angle
/// `(1 − w) ang(n0) + w ang(n1)` along the shorter arc). With `θ` the angle from `n0` to `n1`,
/// the point lies on the circle through `p0` and `p1` whose chord subtends `θ`, centred on the
/// side the normals point away from, at the angle `(1 − w) β0 + w β1` (`β_i` the angles of
/// `p_i` seen from the centre). When `θ` is 0 (or the normals are opposite, where no such
/// circle is defined) the point is the linear average.
pub fn circle_average(a: PointNormal, b: PointNormal, w: f64) -> PointNormal {
    let (ang0, ang1) = (a.n.y.atan2(a.n.x), b.n.y.atan2(b.n.x));
    let theta = wrap(ang1 - ang0);
    let ang = ang0 + w * theta;
    let n = DVec2::new(ang.cos(), ang.sin());
    let chord = b.p - a.p;
    let len = chord.length();
    if theta.abs() < 1e-14 || len == 0.0 || std::f64::consts::PI - theta.abs() < 1e-12 {
        return PointNormal {
            p: a.p + w * chord,
            n,
        };
    }
    let t = chord / len;
    let perp = DVec2::new(-t.y, t.x);
    let mid = 0.5 * (a.p + b.p);
    let h = len / (2.0 * (0.5 * theta.abs()).tan());
    // The centre is where the normals point away from.
    let side = if (a.n + b.n).dot(perp) >= 0.0 {
        -1.0
    } else {
        1.0
    };
    let c = mid + side * h * perp;
    let (va, vb) = (a.p - c, b.p - c);
    let r = 0.5 * (va.length() + vb.length());
    let beta0 = va.y.atan2(va.x);
    let dbeta = wrap(vb.y.atan2(vb.x) - beta0);
    let phi = beta0 + w * dbeta;
    PointNormal {
        p: c + r * DVec2::new(phi.cos(), phi.sin()),
        n,
    }
}

/// `x` wrapped into `(−π, π]`.
fn wrap(x: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let y = (x + PI).rem_euclid(TAU) - PI;
    if y == -PI { PI } else { y }
}

/// A circle-average curve scheme (Liu et al.).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CircleScheme {
    /// The two-parameter 4-point binary scheme with circle averages.
    FourPoint {
        /// Tension.
        omega: f64,
        /// Displacement (0: interpolatory).
        mu: f64,
    },
    /// The 3-point ternary interpolatory scheme with circle averages (`ω ≠ 1`).
    Ternary {
        /// The parameter.
        omega: f64,
    },
}

impl CircleScheme {
    /// Subdivides point–normal pairs `levels` times. Open curves keep their end points and
    /// are continued by mirroring in the normal line at each end (which maps a circle
    /// through the end point, with radial normals, onto itself; for a straight line it is
    /// the point reflection the linear schemes use).
    ///
    /// ```
    /// use glam::DVec2;
    /// use subd_schemes::curve::{CircleScheme, PointNormal};
    ///
    /// // Six points of the unit circle with radial normals stay on it.
    /// let pts: Vec<PointNormal> = (0..6)
    ///     .map(|i| {
    ///         let a = i as f64 * std::f64::consts::TAU / 6.0;
    ///         PointNormal { p: DVec2::new(a.cos(), a.sin()), n: DVec2::new(a.cos(), a.sin()) }
    ///     })
    ///     .collect();
    /// let out = CircleScheme::FourPoint { omega: 1.0 / 16.0, mu: 0.0 }.subdivide(&pts, true, 4).unwrap();
    /// assert_eq!(out.len(), 96);
    /// assert!(out.iter().all(|q| (q.p.length() - 1.0).abs() < 1e-12));
    /// ```
    ///
    /// # Errors
    /// As [`CurveScheme::subdivide`]; a zero normal is not finite.
    pub fn subdivide(
        &self,
        points: &[PointNormal],
        closed: bool,
        levels: usize,
    ) -> Result<Vec<PointNormal>, CurveError> {
        match *self {
            CircleScheme::FourPoint { omega, mu } => {
                if !omega.is_finite() || !mu.is_finite() {
                    return Err(CurveError::Parameter("omega and mu must be finite".into()));
                }
            }
            CircleScheme::Ternary { omega } => {
                if !omega.is_finite() || omega == 1.0 {
                    return Err(CurveError::Parameter(format!(
                        "omega = {omega}: must be finite and not 1"
                    )));
                }
            }
        }
        check_points(
            points
                .iter()
                .map(|q| q.p.is_finite() && q.n.is_finite() && q.n.length() > 0.0),
            points.len(),
            closed,
        )?;
        let arity = match self {
            CircleScheme::FourPoint { .. } => 2,
            CircleScheme::Ternary { .. } => 3,
        };
        check_size(points.len(), arity, levels)?;
        let mut cur: Vec<PointNormal> = points
            .iter()
            .map(|q| PointNormal {
                p: q.p,
                n: q.n.normalize(),
            })
            .collect();
        for _ in 0..levels {
            cur = self.step(&cur, closed);
        }
        Ok(cur)
    }

    fn step(&self, p: &[PointNormal], closed: bool) -> Vec<PointNormal> {
        let n = p.len() as i64;
        // Continuation: wrap, or reflect through the end points (point and normal).
        let at = |k: i64| -> PointNormal {
            if closed {
                return p[k.rem_euclid(n) as usize];
            }
            // The mirror image in the normal line of the end point: a circle through the
            // end point with its radial normal there is mapped onto itself.
            let reflect = |c: PointNormal, q: PointNormal| PointNormal {
                p: c.p + (q.p - c.p).reflect_about(c.n),
                n: q.n.reflect_about(c.n),
            };
            if k < 0 {
                reflect(p[0], p[(-k).min(n - 1) as usize])
            } else if k >= n {
                reflect(p[(n - 1) as usize], p[(2 * (n - 1) - k).max(0) as usize])
            } else {
                p[k as usize]
            }
        };
        let a = circle_average;
        match *self {
            CircleScheme::FourPoint { omega, mu } => {
                let count = if closed { n } else { n - 1 };
                (0..n)
                    .into_par_iter()
                    .flat_map_iter(|i| {
                        let end = !closed && (i == 0 || i == n - 1);
                        let even = if mu == 0.0 || end {
                            p[i as usize]
                        } else {
                            a(p[i as usize], a(at(i - 1), at(i + 1), 0.5), 2.0 * mu)
                        };
                        let odd = (i < count).then(|| {
                            let l = a(at(i - 1), at(i), 1.0 + 2.0 * omega);
                            let r = a(at(i + 2), at(i + 1), 1.0 + 2.0 * omega);
                            a(l, r, 0.5)
                        });
                        std::iter::once(even).chain(odd)
                    })
                    .collect()
            }
            CircleScheme::Ternary { omega } => {
                let s = (4.0 / 3.0 - 2.0 * omega) / (1.0 - omega);
                let count = if closed { n } else { n - 1 };
                (0..n)
                    .into_par_iter()
                    .flat_map_iter(|i| {
                        let new = (i < count).then(|| {
                            [
                                a(a(at(i - 1), at(i), s), at(i + 1), omega),
                                a(a(at(i + 2), at(i + 1), s), at(i), omega),
                            ]
                        });
                        std::iter::once(p[i as usize]).chain(new.into_iter().flatten())
                    })
                    .collect()
            }
        }
    }
}

/// A `DVec2` helper: the reflection of a normal about the line spanned by `axis`.
trait ReflectAbout {
    fn reflect_about(self, axis: DVec2) -> DVec2;
}

impl ReflectAbout for DVec2 {
    fn reflect_about(self, axis: DVec2) -> DVec2 {
        let a = axis.normalize_or_zero();
        2.0 * self.dot(a) * a - self
    }
}
