//! How well positions meet constraints, measured by evaluating the limit surface directly
//! (not through the constraint rows the solver used).

use glam::DVec3;
use subd_limit::eval::{FaceParam, LimitEvaluator, PatchPoints};
use subd_mesh::Topology;
use subd_schemes::Scheme;

use crate::EditError;
use crate::constraint::{Constraint, Goal, Location, vertex_param};
use crate::isoline::{SAMPLES_PER_FACE, bspline_point, is_regular, strip};

/// Per constraint: a point's distance to its target; a normal's `|n × n_target|` (the sine
/// of the angle between the lines); an iso-line's largest distance to the target curve
/// (9 points per face on a regular strip, the constrained samples elsewhere).
///
/// # Errors
/// A constraint that cannot be evaluated (as [`crate::Editor::new`] reports it).
pub fn residuals(
    ev: &LimitEvaluator,
    topology: &Topology,
    scheme: &Scheme,
    constraints: &[Constraint],
    before: &[DVec3],
    after: &[DVec3],
) -> Result<Vec<f64>, EditError> {
    let p0 = ev.prepare(before);
    let p1 = ev.prepare(after);
    constraints
        .iter()
        .enumerate()
        .map(|(i, c)| {
            residual(ev, topology, scheme, c, &p0, &p1)
                .map_err(|message| EditError::Constraint { index: i, message })
        })
        .collect()
}

fn residual(
    ev: &LimitEvaluator,
    topology: &Topology,
    scheme: &Scheme,
    c: &Constraint,
    p0: &PatchPoints,
    p1: &PatchPoints,
) -> Result<f64, String> {
    let param = |l: &Location| match l {
        Location::Vertex(v) => vertex_param(ev.topology(), scheme, *v),
        Location::Face(p) => Ok(*p),
    };
    let eval = |p: &PatchPoints, q: FaceParam| ev.evaluate(p, q).map_err(|e| e.to_string());
    match c {
        Constraint::Point { at, goal } => {
            let q = param(at)?;
            let now = eval(p1, q)?.position;
            let want = match goal {
                Goal::Position(t) => *t,
                Goal::Displacement(d) => eval(p0, q)?.position + *d,
            };
            Ok((now - want).length())
        }
        Constraint::Normal { at, normal } => {
            let n = eval(p1, param(at)?)?.normal();
            Ok(n.cross(normal.normalize()).length())
        }
        Constraint::Isoline { line, goals } => {
            let faces = strip(topology, line)?;
            if goals.len() != faces.len() + 3 {
                return Err(format!(
                    "an iso-line over {} faces needs {} control points, not {}",
                    faces.len(),
                    faces.len() + 3,
                    goals.len()
                ));
            }
            let cps: Vec<DVec3> = goals
                .iter()
                .map(|g| match g {
                    Goal::Position(p) | Goal::Displacement(p) => *p,
                })
                .collect();
            let absolute = matches!(goals.first(), Some(Goal::Position(_)));
            let samples: Vec<f64> = if is_regular(ev, &faces) {
                (0..=8).map(|k| k as f64 / 8.0).collect()
            } else {
                (0..SAMPLES_PER_FACE)
                    .map(|k| (k as f64 + 0.5) / SAMPLES_PER_FACE as f64)
                    .collect()
            };
            let mut worst = 0.0f64;
            for (j, f) in faces.iter().enumerate() {
                for &s in &samples {
                    let q = f.param(s);
                    let target = bspline_point(&cps, j as f64 + s);
                    let want = if absolute {
                        target
                    } else {
                        eval(p0, q)?.position + target
                    };
                    worst = worst.max((eval(p1, q)?.position - want).length());
                }
            }
            Ok(worst)
        }
    }
}
