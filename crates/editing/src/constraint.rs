//! Constraints on the limit surface and their rows over the control vertices (Li et al. 2008 §3).
//!
//! Every constraint becomes one or more linear equations in the *changes* ΔX of the control
//! vertices (Li et al. 2008 §3.4). A point constraint at a limit point with stencil weights `w_v`
//! gives three equations `Σ_v w_v ΔX_v[c] = b_c`, one per coordinate. A normal constraint
//! asks both limit tangents `t = Σ_v w'_v X_v` to be perpendicular to the target normal n:
//! `Σ_v w'_v (n · ΔX_v) = −n · t(X₀)` couples x, y and z, the Kronecker form `(Bᵀ ⊗ A) vec X`
//! of Li et al. written row by row. So one row here is a list of (vertex, weight) with a
//! [`Coupling`]: one coordinate, or a direction dotted with the vertex's change.

use glam::DVec3;
use subd_limit::PointStencil;
use subd_limit::eval::{FaceParam, LimitEvaluator};
use subd_limit::point_stencil::{ControlRow, DU, DV, POSITION};
use subd_mesh::Topology;
use subd_schemes::Scheme;

use crate::EditError;
use crate::isoline::{
    Isoline, SAMPLES_PER_FACE, along_rows, bspline_point, control_triple, is_regular, strip,
};

/// Where on the limit surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Location {
    /// The limit point of a base vertex.
    Vertex(usize),
    /// A (face, sub-face, u, v) in `subd eval`'s parameterisation.
    Face(FaceParam),
}

/// What a point (or curve control point) should become.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Goal {
    /// An absolute position.
    Position(DVec3),
    /// A displacement from where it is now.
    Displacement(DVec3),
}

/// One constraint on the limit surface.
#[derive(Clone, Debug, PartialEq)]
pub enum Constraint {
    /// The limit surface passes through a point.
    Point {
        /// Where.
        at: Location,
        /// To where.
        goal: Goal,
    },
    /// The limit normal at a point is `normal` (both tangents perpendicular to it).
    Normal {
        /// Where.
        at: Location,
        /// The target normal (any non-zero length).
        normal: DVec3,
    },
    /// An iso-parameter line follows a uniform cubic B-spline curve.
    Isoline {
        /// Which line.
        line: Isoline,
        /// Its target: the curve's control points (`faces + 3` of them), absolute or as
        /// displacements of the line's current control points.
        goals: Vec<Goal>,
    },
}

/// How a row's weights act on a vertex's change ΔX_v.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Coupling {
    /// On one coordinate (0, 1, 2).
    Coordinate(usize),
    /// On `direction · ΔX_v`.
    Along(DVec3),
}

/// One linear equation `Σ_v weight_v · coupling(ΔX_v) = value`.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// (vertex, weight), vertices ascending.
    pub entries: Vec<(u32, f64)>,
    /// How the weights act.
    pub coupling: Coupling,
    /// The constraint it comes from (index in the list given).
    pub constraint: usize,
}

impl Row {
    /// The row's value at positions `x`.
    pub fn value(&self, x: &[DVec3]) -> f64 {
        let s: DVec3 = self.entries.iter().map(|&(v, w)| w * x[v as usize]).sum();
        match self.coupling {
            Coupling::Coordinate(c) => s[c],
            Coupling::Along(d) => d.dot(s),
        }
    }

    /// The coefficient of unknown `3 v + c` for entry weight `w`.
    pub fn coefficient(&self, w: f64, c: usize) -> f64 {
        match self.coupling {
            Coupling::Coordinate(k) => {
                if k == c {
                    w
                } else {
                    0.0
                }
            }
            Coupling::Along(d) => w * d[c],
        }
    }

    /// The dot product of the two rows' coefficient vectors (an entry of `A Aᵀ`).
    pub fn dot(&self, other: &Row) -> f64 {
        let (a, b) = (self, other);
        let (mut i, mut j, mut s) = (0, 0, 0.0);
        while i < a.entries.len() && j < b.entries.len() {
            let (va, wa) = a.entries[i];
            let (vb, wb) = b.entries[j];
            match va.cmp(&vb) {
                std::cmp::Ordering::Less => i += 1,
                std::cmp::Ordering::Greater => j += 1,
                std::cmp::Ordering::Equal => {
                    for c in 0..3 {
                        s += a.coefficient(wa, c) * b.coefficient(wb, c);
                    }
                    i += 1;
                    j += 1;
                }
            }
        }
        s
    }
}

/// What a row asks of the positions: a value, or a change of its current value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum RowGoal {
    Value(f64),
    Change(f64),
}

/// The rows of a list of constraints and what they ask.
#[derive(Clone, Debug)]
pub struct ConstraintRows {
    /// The rows.
    pub rows: Vec<Row>,
    pub(crate) goals: Vec<RowGoal>,
}

impl ConstraintRows {
    /// Builds the rows of `constraints` on `ev`'s mesh.
    ///
    /// # Errors
    /// [`EditError::Constraint`] naming the constraint: a vertex or face out of range,
    /// parameters outside the face, a non-finite number, a zero normal, an iso-line that
    /// leaves the mesh or has the wrong number of control points.
    pub fn new(
        ev: &LimitEvaluator,
        topology: &Topology,
        scheme: &Scheme,
        constraints: &[Constraint],
    ) -> Result<ConstraintRows, EditError> {
        let mut out = ConstraintRows {
            rows: Vec::new(),
            goals: Vec::new(),
        };
        for (i, c) in constraints.iter().enumerate() {
            let bad = |message: String| EditError::Constraint { index: i, message };
            match c {
                Constraint::Point { at, goal } => {
                    let st = stencil_at(ev, scheme, at).map_err(bad)?;
                    let target = check_goal(goal).map_err(bad)?;
                    out.push_point(&st.indices, &st.weights[POSITION], target, i);
                }
                Constraint::Normal { at, normal } => {
                    if !normal.is_finite() {
                        return Err(bad("the normal is not finite".into()));
                    }
                    if normal.length_squared() == 0.0 {
                        return Err(bad("the normal is zero".into()));
                    }
                    let n = normal.normalize();
                    let st = stencil_at(ev, scheme, at).map_err(bad)?;
                    for k in [DU, DV] {
                        out.rows.push(Row {
                            entries: pairs(&st.indices, &st.weights[k]),
                            coupling: Coupling::Along(n),
                            constraint: i,
                        });
                        out.goals.push(RowGoal::Value(0.0));
                    }
                }
                Constraint::Isoline { line, goals } => {
                    let targets: Vec<Goal> = goals
                        .iter()
                        .map(|g| check_goal(g).map(|_| *g))
                        .collect::<Result<_, _>>()
                        .map_err(bad)?;
                    for (entries, goal) in strip_rows(ev, topology, line, &targets).map_err(bad)? {
                        out.push_point_row(entries, goal, i);
                    }
                }
            }
        }
        Ok(out)
    }

    fn push_point(&mut self, idx: &[u32], w: &[f64], goal: Goal, constraint: usize) {
        self.push_point_row(pairs(idx, w), goal, constraint);
    }

    fn push_point_row(&mut self, entries: Vec<(u32, f64)>, goal: Goal, constraint: usize) {
        for c in 0..3 {
            self.rows.push(Row {
                entries: entries.clone(),
                coupling: Coupling::Coordinate(c),
                constraint,
            });
            self.goals.push(match goal {
                Goal::Position(p) => RowGoal::Value(p[c]),
                Goal::Displacement(d) => RowGoal::Change(d[c]),
            });
        }
    }

    /// The right-hand side `b − A X₀` for positions `x0`: what each row must change by.
    pub fn residual(&self, x0: &[DVec3]) -> Vec<f64> {
        self.rows
            .iter()
            .zip(&self.goals)
            .map(|(r, g)| match *g {
                RowGoal::Value(b) => b - r.value(x0),
                RowGoal::Change(d) => d,
            })
            .collect()
    }

    /// The vertices the rows involve, ascending.
    pub fn support(&self) -> Vec<u32> {
        let mut s: Vec<u32> = self
            .rows
            .iter()
            .flat_map(|r| r.entries.iter().map(|e| e.0))
            .collect();
        s.sort_unstable();
        s.dedup();
        s
    }
}

fn pairs(idx: &[u32], w: &[f64]) -> Vec<(u32, f64)> {
    idx.iter().copied().zip(w.iter().copied()).collect()
}

fn check_goal(g: &Goal) -> Result<Goal, String> {
    let (Goal::Position(p) | Goal::Displacement(p)) = g;
    if !p.is_finite() {
        return Err("the target is not finite".into());
    }
    Ok(*g)
}

/// The rows (over base vertices, one position each) and goals of an iso-line constraint:
/// the curve's control points on a regular strip, samples otherwise.
pub(crate) fn strip_rows(
    ev: &LimitEvaluator,
    topology: &Topology,
    line: &Isoline,
    goals: &[Goal],
) -> Result<Vec<(ControlRow, Goal)>, String> {
    let faces = strip(topology, line)?;
    let m = faces.len();
    if goals.len() != m + 3 {
        return Err(format!(
            "an iso-line over {m} faces needs {} control points, not {}",
            m + 3,
            goals.len()
        ));
    }
    let mut out = Vec::new();
    if is_regular(ev, &faces) {
        for (j, f) in faces.iter().enumerate() {
            let [c0, c1, c2] = control_triple(&along_rows(ev, f, 0.0)?);
            if j == 0 {
                out.push((c0, goals[0]));
                out.push((c1, goals[1]));
            }
            out.push((c2, goals[j + 2]));
        }
        let [_, _, last] = control_triple(&along_rows(ev, &faces[m - 1], 1.0)?);
        out.push((last, goals[m + 2]));
        return Ok(out);
    }
    // Sampled: each sample's goal is the target curve (or the displacement curve) there.
    let all_positions = goals.iter().all(|g| matches!(g, Goal::Position(_)));
    let all_changes = goals.iter().all(|g| matches!(g, Goal::Displacement(_)));
    if !all_positions && !all_changes {
        return Err("an iso-line's control points are all targets or all displacements".into());
    }
    let cps: Vec<DVec3> = goals
        .iter()
        .map(|g| match g {
            Goal::Position(p) | Goal::Displacement(p) => *p,
        })
        .collect();
    for (j, f) in faces.iter().enumerate() {
        for k in 0..SAMPLES_PER_FACE {
            let s = (k as f64 + 0.5) / SAMPLES_PER_FACE as f64;
            let st = ev.stencil(f.param(s)).map_err(|e| e.to_string())?;
            let p = bspline_point(&cps, j as f64 + s);
            let goal = if all_positions {
                Goal::Position(p)
            } else {
                Goal::Displacement(p)
            };
            out.push((
                st.indices
                    .iter()
                    .copied()
                    .zip(st.weights[POSITION].iter().copied())
                    .collect(),
                goal,
            ));
        }
    }
    Ok(out)
}

/// The parameter of a base vertex as a corner of its first face.
pub(crate) fn vertex_param(
    topology: &Topology,
    scheme: &Scheme,
    v: usize,
) -> Result<FaceParam, String> {
    if v >= topology.num_vertices() {
        return Err(format!(
            "vertex {v} out of range (the mesh has {} vertices)",
            topology.num_vertices()
        ));
    }
    let faces = topology.vertex_faces(v);
    let (face, corner) = faces
        .iter()
        .zip(topology.vertex_face_local_indices(v))
        .find(|&(&f, _)| !topology.is_hole(f as usize))
        .map(|(&f, &c)| (f as usize, c as usize))
        .ok_or_else(|| format!("vertex {v} is on no face of the surface"))?;
    let size = topology.face_size(face);
    let (sub, u, v) = match (scheme, size) {
        (Scheme::Loop, _) => {
            let (u, v) = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)][corner];
            (0, u, v)
        }
        (_, 4) => {
            let (u, v) = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)][corner];
            (0, u, v)
        }
        _ => (corner, 0.0, 0.0),
    };
    Ok(FaceParam { face, sub, u, v })
}

/// The stencil of a location, with a one-line reason when it is not on the surface.
pub(crate) fn stencil_at(
    ev: &LimitEvaluator,
    scheme: &Scheme,
    at: &Location,
) -> Result<PointStencil, String> {
    let p = match at {
        Location::Vertex(v) => vertex_param(ev.topology(), scheme, *v)?,
        Location::Face(p) => {
            if !p.u.is_finite() || !p.v.is_finite() {
                return Err("the parameters are not finite".into());
            }
            *p
        }
    };
    ev.stencil(p).map_err(|e| e.to_string())
}
