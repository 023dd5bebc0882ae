//! Curve schemes by name: [`NamedCurve`] makes one of [`crate::curve`]'s schemes from the
//! name and parameters `subd curve` and `subd.curve` take (with the same defaults), and
//! [`subdivide_curve`] runs it on points (with normals for Liu et al.'s circle-average
//! schemes, estimated from the polygon when none are given).

use glam::{DVec2, DVec3};

use crate::curve::{CircleScheme, CurveError, CurveScheme, PointNormal};

/// The curve schemes' names, as the CLI and the Python package spell them.
pub const CURVE_SCHEMES: [&str; 10] = [
    "chaikin",
    "bspline",
    "four-point",
    "four-point-2p",
    "ternary-3pt",
    "tension",
    "circle-preserving",
    "variational",
    "circle-four-point",
    "circle-ternary",
];

/// The parameters a curve scheme may take (`None`: the scheme's default).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CurveParameters {
    /// Tension of the 4-point and ternary schemes (default 1/16; 1/4 for the ternary ones).
    pub omega: Option<f64>,
    /// Displacement of old points of the two-parameter 4-point schemes (default 0).
    pub mu: Option<f64>,
    /// Order of the B-spline (default 4, cubic).
    pub order: Option<usize>,
    /// `α_0` of the tension scheme (default 1, the cubic B-spline).
    pub alpha0: Option<f64>,
}

/// A curve scheme: a linear one, or a circle-average one (points with normals).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NamedCurve {
    /// A scheme on points alone.
    Linear(CurveScheme),
    /// Liu et al.'s circle-average schemes, on planar points with normals.
    Circle(CircleScheme),
}

impl NamedCurve {
    /// The scheme `name` (one of [`CURVE_SCHEMES`]) with `parameters`.
    ///
    /// ```
    /// use subd_schemes::curve::CurveScheme;
    /// use subd_schemes::named_curve::{CurveParameters, NamedCurve};
    ///
    /// let s = NamedCurve::new("four-point", &CurveParameters::default()).unwrap();
    /// assert_eq!(s, NamedCurve::Linear(CurveScheme::FourPoint { omega: 1.0 / 16.0 }));
    /// ```
    ///
    /// # Errors
    /// [`CurveError::Parameter`] for an unknown name, or a parameter the scheme does not
    /// take (refused rather than ignored).
    pub fn new(name: &str, parameters: &CurveParameters) -> Result<NamedCurve, CurveError> {
        if !CURVE_SCHEMES.contains(&name) {
            return Err(CurveError::Parameter(format!(
                "unknown curve scheme {name:?} (one of {})",
                CURVE_SCHEMES.join(", ")
            )));
        }
        let p = parameters;
        for (parameter, given) in [
            ("omega", p.omega.is_some()),
            ("mu", p.mu.is_some()),
            ("order", p.order.is_some()),
            ("alpha0", p.alpha0.is_some()),
        ] {
            if given && !Self::takes(name, parameter) {
                return Err(CurveError::Parameter(format!(
                    "{parameter} does not apply to the {name} scheme"
                )));
            }
        }
        let ternary = matches!(name, "ternary-3pt" | "circle-ternary");
        let omega = p.omega.unwrap_or(if ternary { 0.25 } else { 1.0 / 16.0 });
        let mu = p.mu.unwrap_or(0.0);
        Ok(match name {
            "circle-four-point" => NamedCurve::Circle(CircleScheme::FourPoint { omega, mu }),
            "circle-ternary" => NamedCurve::Circle(CircleScheme::Ternary { omega }),
            _ => NamedCurve::Linear(match name {
                "chaikin" => CurveScheme::Chaikin,
                "bspline" => CurveScheme::BSpline {
                    order: p.order.unwrap_or(4),
                },
                "four-point" => CurveScheme::FourPoint { omega },
                "four-point-2p" => CurveScheme::FourPoint2 { omega, mu },
                "ternary-3pt" => CurveScheme::Ternary3 { omega },
                "tension" => CurveScheme::Tension {
                    alpha0: p.alpha0.unwrap_or(1.0),
                },
                "circle-preserving" => CurveScheme::CirclePreserving,
                _ => CurveScheme::Variational,
            }),
        })
    }

    /// Whether the scheme `name` takes `parameter` (`omega`, `mu`, `order`, `alpha0`).
    pub fn takes(name: &str, parameter: &str) -> bool {
        match parameter {
            "omega" => matches!(
                name,
                "four-point"
                    | "four-point-2p"
                    | "ternary-3pt"
                    | "circle-four-point"
                    | "circle-ternary"
            ),
            "mu" => matches!(name, "four-point-2p" | "circle-four-point"),
            "order" => name == "bspline",
            "alpha0" => name == "tension",
            _ => false,
        }
    }
}

/// A subdivided curve: its points, and their unit normals under a circle-average scheme.
#[derive(Debug, Clone, PartialEq)]
pub struct SubdividedCurve {
    /// The points of the last level.
    pub points: Vec<DVec3>,
    /// Their normals (circle-average schemes).
    pub normals: Option<Vec<DVec2>>,
    /// Whether the input's normals were estimated from the polygon.
    pub normals_estimated: bool,
}

/// `points` (and, for a circle-average scheme, their `normals`, estimated with
/// [`estimate_normals`] when `None`) subdivided `levels` times with `scheme`.
///
/// # Errors
/// The scheme's [`CurveError`]; for a circle-average scheme also points off the plane
/// `z = 0`, normals not one per point, or a zero normal.
pub fn subdivide_curve(
    scheme: &NamedCurve,
    points: &[DVec3],
    normals: Option<&[DVec2]>,
    closed: bool,
    levels: usize,
) -> Result<SubdividedCurve, CurveError> {
    let circle = match scheme {
        NamedCurve::Linear(s) => {
            return Ok(SubdividedCurve {
                points: s.subdivide(points, closed, levels)?,
                normals: None,
                normals_estimated: false,
            });
        }
        NamedCurve::Circle(c) => c,
    };
    if points.iter().any(|p| p.z != 0.0) {
        return Err(CurveError::Parameter(
            "the circle-average schemes work on planar points (z = 0)".into(),
        ));
    }
    let estimated = normals.is_none();
    let normals = match normals {
        Some(n) => unit_normals(n, points.len())?,
        None => estimate_normals(points, closed),
    };
    let pn: Vec<PointNormal> = points
        .iter()
        .zip(&normals)
        .map(|(p, n)| PointNormal {
            p: p.truncate(),
            n: *n,
        })
        .collect();
    let r = circle.subdivide(&pn, closed, levels)?;
    Ok(SubdividedCurve {
        points: r.iter().map(|q| q.p.extend(0.0)).collect(),
        normals: Some(r.iter().map(|q| q.n).collect()),
        normals_estimated: estimated,
    })
}

/// Given normals, one per point, scaled to unit length.
fn unit_normals(normals: &[DVec2], points: usize) -> Result<Vec<DVec2>, CurveError> {
    if normals.len() != points {
        return Err(CurveError::Parameter(format!(
            "{} normals for {points} points",
            normals.len()
        )));
    }
    normals
        .iter()
        .enumerate()
        .map(|(i, n)| {
            if !n.is_finite() {
                Err(CurveError::NotFinite(i))
            } else if n.length() == 0.0 {
                Err(CurveError::Parameter(format!("normal {i} is zero")))
            } else {
                Ok(n.normalize())
            }
        })
        .collect()
}

/// Unit normals of a planar polygon: the perpendicular of the central difference (one-sided
/// at open ends), on the outer side of a closed polygon (the right of a counter-clockwise
/// one) and on the right of an open one.
pub fn estimate_normals(p: &[DVec3], closed: bool) -> Vec<DVec2> {
    let n = p.len();
    let area: f64 = (0..n)
        .map(|i| {
            let (a, b) = (p[i], p[(i + 1) % n]);
            a.x * b.y - b.x * a.y
        })
        .sum();
    let flip = if closed && area < 0.0 { -1.0 } else { 1.0 };
    (0..n)
        .map(|i| {
            let (prev, next) = if closed {
                (p[(i + n - 1) % n], p[(i + 1) % n])
            } else {
                (p[i.saturating_sub(1)], p[(i + 1).min(n - 1)])
            };
            let t = (next - prev).truncate();
            flip * DVec2::new(t.y, -t.x).normalize_or_zero()
        })
        .collect()
}
