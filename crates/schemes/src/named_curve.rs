//! Curve schemes by name: [`NamedCurve`] makes one of [`crate::curve`]'s schemes from the
//! name and parameters `subd curve` and `subd.curve` take (with the same defaults), and
//! [`subdivide_curve`] runs it on points (with normals for Liu et al.'s circle-average
//! schemes, estimated from the polygon when none are given).

use glam::{DVec2, DVec3};

use subd_mesh::choice::Choice;

use crate::curve::{CircleScheme, CurveError, CurveScheme, PointNormal};

/// The curve schemes by name, as the CLI and the Python package spell them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CurveName {
    /// `chaikin`.
    Chaikin,
    /// `bspline`.
    BSpline,
    /// `four-point`.
    FourPoint,
    /// `four-point-2p`.
    FourPoint2p,
    /// `ternary-3pt`.
    Ternary3pt,
    /// `tension`.
    Tension,
    /// `circle-preserving`.
    CirclePreserving,
    /// `variational`.
    Variational,
    /// `circle-four-point`.
    CircleFourPoint,
    /// `circle-ternary`.
    CircleTernary,
}

impl Choice for CurveName {
    const OPTION: &'static str = "curve scheme";
    const VALUES: &'static [(Self, &'static str, &'static str)] = &[
        (
            CurveName::Chaikin,
            "chaikin",
            "Chaikin corner cutting (quadratic B-spline)",
        ),
        (
            CurveName::BSpline,
            "bspline",
            "Uniform B-spline of order --order (default 4, cubic)",
        ),
        (
            CurveName::FourPoint,
            "four-point",
            "Interpolatory 4-point scheme, tension --omega (default 1/16)",
        ),
        (
            CurveName::FourPoint2p,
            "four-point-2p",
            "Two-parameter 4-point scheme, --omega (default 1/16) and --mu (default 0)",
        ),
        (
            CurveName::Ternary3pt,
            "ternary-3pt",
            "3-point ternary interpolatory scheme, --omega (default 1/4)",
        ),
        (
            CurveName::Tension,
            "tension",
            "Non-stationary tension scheme, --alpha0 (default 1: cubic B-spline)",
        ),
        (
            CurveName::CirclePreserving,
            "circle-preserving",
            "Sabin–Dodgson circle-preserving 4-point scheme (planar points)",
        ),
        (
            CurveName::Variational,
            "variational",
            "Variational interpolatory scheme (Kobbelt)",
        ),
        (
            CurveName::CircleFourPoint,
            "circle-four-point",
            "Circle-average two-parameter 4-point scheme on point–normal pairs, --omega, --mu",
        ),
        (
            CurveName::CircleTernary,
            "circle-ternary",
            "Circle-average 3-point ternary scheme on point–normal pairs, --omega",
        ),
    ];
    // Earlier spellings of the command line's.
    const ALIASES: &'static [(&'static str, Self)] = &[
        ("four-point2p", CurveName::FourPoint2p),
        ("ternary3pt", CurveName::Ternary3pt),
    ];
}

subd_mesh::choice_by_name!(CurveName);

impl CurveName {
    /// Whether the scheme takes `parameter` (`omega`, `mu`, `order`, `alpha0`).
    pub fn takes(self, parameter: &str) -> bool {
        use CurveName as C;
        match parameter {
            "omega" => matches!(
                self,
                C::FourPoint
                    | C::FourPoint2p
                    | C::Ternary3pt
                    | C::CircleFourPoint
                    | C::CircleTernary
            ),
            "mu" => matches!(self, C::FourPoint2p | C::CircleFourPoint),
            "order" => self == C::BSpline,
            "alpha0" => self == C::Tension,
            _ => false,
        }
    }
}

/// The curve schemes' names, in [`CurveName`]'s order.
pub const CURVE_SCHEMES: [&str; 10] = {
    let values = <CurveName as Choice>::VALUES;
    assert!(values.len() == 10);
    let mut names = [""; 10];
    let mut i = 0;
    while i < names.len() {
        names[i] = values[i].1;
        i += 1;
    }
    names
};

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
        let name = CurveName::from_name(name).map_err(|e| CurveError::Parameter(e.to_string()))?;
        Self::of(name, parameters)
    }

    /// The scheme `name` with `parameters` ([`NamedCurve::new`] by value).
    ///
    /// # Errors
    /// [`CurveError::Parameter`] for a parameter the scheme does not take.
    pub fn of(name: CurveName, parameters: &CurveParameters) -> Result<NamedCurve, CurveError> {
        let p = parameters;
        for (parameter, given) in [
            ("omega", p.omega.is_some()),
            ("mu", p.mu.is_some()),
            ("order", p.order.is_some()),
            ("alpha0", p.alpha0.is_some()),
        ] {
            if given && !name.takes(parameter) {
                return Err(CurveError::Parameter(format!(
                    "{parameter} does not apply to the {name} scheme"
                )));
            }
        }
        let ternary = matches!(name, CurveName::Ternary3pt | CurveName::CircleTernary);
        let omega = p.omega.unwrap_or(if ternary { 0.25 } else { 1.0 / 16.0 });
        let mu = p.mu.unwrap_or(0.0);
        let linear = |scheme| Ok(NamedCurve::Linear(scheme));
        match name {
            CurveName::CircleFourPoint => {
                Ok(NamedCurve::Circle(CircleScheme::FourPoint { omega, mu }))
            }
            CurveName::CircleTernary => Ok(NamedCurve::Circle(CircleScheme::Ternary { omega })),
            CurveName::Chaikin => linear(CurveScheme::Chaikin),
            CurveName::BSpline => linear(CurveScheme::BSpline {
                order: p.order.unwrap_or(4),
            }),
            CurveName::FourPoint => linear(CurveScheme::FourPoint { omega }),
            CurveName::FourPoint2p => linear(CurveScheme::FourPoint2 { omega, mu }),
            CurveName::Ternary3pt => linear(CurveScheme::Ternary3 { omega }),
            CurveName::Tension => linear(CurveScheme::Tension {
                alpha0: p.alpha0.unwrap_or(1.0),
            }),
            CurveName::CirclePreserving => linear(CurveScheme::CirclePreserving),
            CurveName::Variational => linear(CurveScheme::Variational),
        }
    }

    /// Whether the scheme `name` takes `parameter` (`omega`, `mu`, `order`, `alpha0`);
    /// `false` for a name that is no curve scheme.
    pub fn takes(name: &str, parameter: &str) -> bool {
        CurveName::from_name(name).is_ok_and(|n| n.takes(parameter))
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_makes_its_scheme_and_the_old_spellings_still_work() {
        assert_eq!(CURVE_SCHEMES.len(), CurveName::VALUES.len());
        for (name, &(value, listed, _)) in CURVE_SCHEMES.iter().zip(CurveName::VALUES) {
            assert_eq!(*name, listed);
            let by_name = NamedCurve::new(name, &CurveParameters::default()).unwrap();
            assert_eq!(
                by_name,
                NamedCurve::of(value, &CurveParameters::default()).unwrap()
            );
        }
        assert_eq!("four-point2p".parse(), Ok(CurveName::FourPoint2p));
        assert_eq!("ternary3pt".parse(), Ok(CurveName::Ternary3pt));
        // The closed forms of the defaults: the classic 4-point tension, the ternary ¼.
        let four = NamedCurve::new("four-point", &CurveParameters::default()).unwrap();
        assert_eq!(
            four,
            NamedCurve::Linear(CurveScheme::FourPoint { omega: 1.0 / 16.0 })
        );
        let ternary = NamedCurve::new("ternary-3pt", &CurveParameters::default()).unwrap();
        assert_eq!(
            ternary,
            NamedCurve::Linear(CurveScheme::Ternary3 { omega: 0.25 })
        );
    }

    #[test]
    fn a_parameter_the_scheme_does_not_take_is_refused() {
        let p = CurveParameters {
            mu: Some(0.1),
            ..Default::default()
        };
        let e = NamedCurve::new("chaikin", &p).unwrap_err().to_string();
        assert!(e.contains("mu does not apply to the chaikin scheme"), "{e}");
        let e = NamedCurve::new("cubic", &p).unwrap_err().to_string();
        assert!(
            e.contains("unknown curve scheme \"cubic\" (one of chaikin, bspline"),
            "{e}"
        );
    }
}
