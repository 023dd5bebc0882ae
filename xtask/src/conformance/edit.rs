//! The edit checks: a random edit solved by subd-editing must be met by OpenSubdiv's
//! `Limit` of the edited control mesh.

use subd_editing::{Constraint, Edit, Editor, Goal, Location, Method};
use subd_mesh::DVec3;
use subd_schemes::{Refinement, Scheme};

use super::{Case, MAX_LIMIT_FACE_VERTICES, Row, osd_limit};
use crate::oracles::osd;

/// Which method an `edit` row checks.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum EditCheck {
    LeastSquares,
    Energy,
}

/// Tolerance of the edit check (relative to the bounding-box diagonal; normals: |n · t| / |t|).
const EDIT_TOLERANCE: f64 = 1e-9;

/// The directions of the point constraints' displacements, in turn.
const DIRS: [DVec3; 4] = [
    DVec3::new(0.0, 0.0, 1.0),
    DVec3::new(0.6, 0.8, 0.0),
    DVec3::new(-0.48, 0.6, 0.64),
    DVec3::new(0.0, -1.0, 0.0),
];

/// The displacement of the `k`-th point constraint: 5 % of the diagonal.
fn displacement(k: usize, diag: f64) -> DVec3 {
    0.05 * diag * DIRS[k % 4]
}

/// The normal the normal constraint asks for.
fn target_normal() -> DVec3 {
    DVec3::new(0.3, -0.2, 0.93).normalize()
}

/// A random edit (seeded by the mesh name): point constraints at the limits of up to four
/// vertices (spread over the vertex list from a seeded start), displaced by 5 % of the
/// diagonal in varied directions, and (Catmull-Clark) a normal constraint at a smooth
/// interior vertex; solved by subd-editing, then OpenSubdiv's `Limit` of the edited control
/// mesh must meet them to 1e-9 of the diagonal (points) and with both limit tangents
/// perpendicular to the target normal. Vertices where OpenSubdiv's limit is inexact (darts,
/// interior valence 2, see OPENSUBDIV.md) are not used.
pub fn compare(case: &Case, method: EditCheck) -> Row {
    let check = match method {
        EditCheck::LeastSquares => "edit",
        EditCheck::Energy => "edit-e",
    };
    let mut row = Row::pending(case.name, check, 0);
    let level = subd_limit::levels_for_exact_limit(case.topo, case.scheme)
        .0
        .max(1);
    if case.topo.num_face_vertices() << (2 * level) > MAX_LIMIT_FACE_VERTICES {
        return Stop::NotChecked("too deep for OpenSubdiv's limit, not checked".into())
            .into_row(row);
    }
    row.level = level;
    match edit_and_measure(case, level, method) {
        Ok(m) => m.into_row(row),
        Err(stop) => stop.into_row(row),
    }
}

/// Why an edit row ends before the comparison: a failure, or a mesh the check cannot judge.
enum Stop {
    Problem(String),
    NotChecked(String),
}

impl Stop {
    fn into_row(self, mut row: Row) -> Row {
        match self {
            Stop::Problem(p) => row.problem = Some(p),
            Stop::NotChecked(note) => {
                row.error = 0.0;
                row.note = Some(note);
            }
        }
        row
    }
}

/// Picks the constraints, solves the edit, and measures OpenSubdiv's limit before and after.
fn edit_and_measure(case: &Case, level: usize, method: EditCheck) -> Result<Measured, Stop> {
    let picks = Picks::new(case, level)?;
    let cs = picks.constraints(case.diag);
    if cs.is_empty() {
        return Err(Stop::NotChecked(
            "no vertex on the surface (off holes) with an exact OpenSubdiv limit, not checked"
                .into(),
        ));
    }
    let (rank_deficient, edit) = solve(case, &cs, method)?;
    let encode = |positions: &[DVec3]| {
        osd::encode(
            case.topo,
            positions,
            case.scheme,
            case.options,
            level as u32,
        )
    };
    let opensubdiv = |e: String| Stop::Problem(format!("OpenSubdiv: {e}"));
    let (before, _) = osd_limit(case.exe, &encode(case.positions), false).map_err(opensubdiv)?;
    // Tangents for the normal check; where OpenSubdiv's tangent masks crash (see the limit
    // check), positions only.
    let (after, with_tangents) =
        osd_limit(case.exe, &encode(&edit.positions), picks.normal.is_some())
            .map_err(opensubdiv)?;
    let mut err = 0.0f64;
    for (k, &v) in picks.points.iter().enumerate() {
        let moved = after.positions[v] - before.positions[v];
        err = err.max((moved - displacement(k, case.diag)).length() / case.diag);
    }
    let mut normal_err = None;
    if let Some(v) = picks.normal.filter(|_| with_tangents) {
        let (a, b) = (after.tangent1[v], after.tangent2[v]);
        let n = target_normal();
        normal_err = Some((n.dot(a).abs() / a.length()).max(n.dot(b).abs() / b.length()));
    }
    Ok(Measured {
        moved: edit.moved.len(),
        picks,
        rank_deficient,
        err,
        normal_err,
    })
}

/// The vertices an edit constrains: the points, and the normal's vertex.
struct Picks {
    points: Vec<usize>,
    normal: Option<usize>,
}

impl Picks {
    /// Up to four vertices on the surface (off holes) with an exact OpenSubdiv limit, spread
    /// from a start seeded by the mesh name, and (Catmull-Clark) a smooth interior vertex of
    /// valence 3 or more for the normal.
    fn new(case: &Case, level: usize) -> Result<Picks, Stop> {
        let (topo, scheme) = (case.topo, case.scheme);
        let prepared = Refinement::new(topo, scheme.clone(), case.options, level)
            .map_err(|e| Stop::Problem(format!("subd: {e}")))?;
        let inexact = subd_limit::eigen_limit_vertices(&prepared, level);
        let (t0, rules0) = (prepared.topology(0), prepared.vertex_rules(0));
        // Holes as the evaluator sees them (boundary faces too under boundary "none").
        let surface = subd_limit::eval::LimitEvaluator::new(topo, scheme, case.options)
            .map(|ev| ev.topology().clone())
            .map_err(|e| Stop::NotChecked(format!("subd-limit: {e}; not checked")))?;
        let nv = topo.num_vertices();
        let seed = case
            .name
            .bytes()
            .fold(7u64, |h, b| h.wrapping_mul(31).wrapping_add(b as u64));
        let usable = |v: usize| {
            v < nv
                && !inexact.contains(&v)
                && surface
                    .vertex_faces(v)
                    .iter()
                    .any(|&f| !surface.is_hole(f as usize))
        };
        let start = ((seed >> 7) % nv as u64) as usize;
        let stride = (nv / 4).max(1);
        let mut points: Vec<usize> = Vec::new();
        for k in 0..nv {
            let v = (start + k * stride + k / 4) % nv;
            if points.len() == 4 {
                break;
            }
            if usable(v) && !points.contains(&v) {
                points.push(v);
            }
        }
        let normal = (0..nv).map(|k| (k + seed as usize) % nv).find(|&v| {
            usable(v)
                && !points.contains(&v)
                && *scheme == Scheme::CatmullClark
                && !t0.is_boundary_vertex(v)
                && rules0[v] == subd_schemes::Rule::Smooth
                && t0.vertex_faces(v).len() >= 3
        });
        Ok(Picks { points, normal })
    }

    /// The point constraints, then the normal constraint.
    fn constraints(&self, diag: f64) -> Vec<Constraint> {
        let mut cs: Vec<Constraint> = self
            .points
            .iter()
            .enumerate()
            .map(|(k, &v)| Constraint::Point {
                at: Location::Vertex(v),
                goal: Goal::Displacement(displacement(k, diag)),
            })
            .collect();
        if let Some(v) = self.normal {
            cs.push(Constraint::Normal {
                at: Location::Vertex(v),
                normal: target_normal(),
            });
        }
        cs
    }
}

/// subd-editing's solution of the constraints `cs`, and whether its system was
/// rank-deficient.
fn solve(case: &Case, cs: &[Constraint], method: EditCheck) -> Result<(bool, Edit), Stop> {
    let m = match method {
        EditCheck::LeastSquares => Method::LeastSquares,
        EditCheck::Energy => Method::Energy {
            penalty: None,
            region_rings: Some(2),
            energy: Default::default(),
        },
    };
    Editor::new(case.topo, case.positions, case.scheme, case.options, cs, m)
        .and_then(|ed| ed.solve(cs).map(|e| (ed.rank_deficient, e)))
        .map_err(|e| Stop::NotChecked(format!("subd-editing: {e}; not checked")))
}

/// How well OpenSubdiv's limit of the edited mesh meets the constraints.
struct Measured {
    picks: Picks,
    /// Control vertices the edit moved.
    moved: usize,
    /// A rank-deficient system is solved in the least-squares sense: nothing to hold it to.
    rank_deficient: bool,
    /// Max distance of a moved limit point from its target, over the diagonal.
    err: f64,
    /// max |n · t| / |t| over both limit tangents at the normal's vertex.
    normal_err: Option<f64>,
}

impl Measured {
    fn into_row(self, mut row: Row) -> Row {
        let (err, normal_err) = (self.err, self.normal_err);
        row.vertices = self.picks.points.len() + usize::from(self.picks.normal.is_some());
        row.error = err;
        row.normal_error = normal_err;
        row.note = Some(format!(
            "{} points{}, {} vertices moved{}",
            self.picks.points.len(),
            if self.picks.normal.is_some() {
                " + 1 normal"
            } else {
                ""
            },
            self.moved,
            if self.rank_deficient {
                ", rank-deficient: least-squares solution"
            } else {
                ""
            }
        ));
        let bad_normal = normal_err.is_some_and(|e| e.is_nan() || e > EDIT_TOLERANCE);
        if !self.rank_deficient && (err.is_nan() || err > EDIT_TOLERANCE || bad_normal) {
            row.problem = Some(format!(
                "constraints not met by OpenSubdiv's limit (points {err:e}, normal {normal_err:?})"
            ));
        }
        row
    }
}
