//! One edit of a mesh from start to finish, as `subd edit` and the Python package's
//! `subd.edit` run it: the [`Editor`] prepared and solved, the dependent constraints put
//! into words, and (when asked) the result measured afresh: a new limit evaluator on the
//! edited positions, so the residuals check the solve rather than repeat it.

use std::time::Instant;

use glam::DVec3;
use subd_limit::eval::LimitEvaluator;
use subd_mesh::Mesh;
use subd_schemes::{Options, Scheme};

use crate::EditError;
use crate::constraint::{Constraint, Location};
use crate::dependency::DependentGroup;
use crate::energy::{EnergyMatrix, EnergyOptions, surface_energy_before_after};
use crate::isoline::Axis;
use crate::solve::{Edit, Editor, Method, Timings, faces_touching};

/// What [`edit_mesh`] did.
#[derive(Clone, Debug)]
pub struct MeshEdit {
    /// The new control vertices, the vertices that moved and the dependent constraints.
    pub edit: Edit,
    /// Constraint rows.
    pub rows: usize,
    /// Their rank.
    pub rank: usize,
    /// Whether the rows were dependent or conflicting (a least-squares solution).
    pub rank_deficient: bool,
    /// Vertices allowed to move (the constraints' support, or the energy's region).
    pub free_vertices: usize,
    /// One sentence per group of dependent constraints: redundant or conflicting, naming
    /// them as the constraint list gives them.
    pub warnings: Vec<String>,
    /// The editor's time per phase.
    pub timings: Timings,
    /// The result measured afresh, when asked for.
    pub measured: Option<Measured>,
}

/// An edit's result measured with a limit evaluator built afresh.
#[derive(Clone, Debug)]
pub struct Measured {
    /// Per constraint, as [`crate::check::residuals`] defines it: a distance (points,
    /// iso-lines; model units) or the sine of the angle to the target normal.
    pub residuals: Vec<f64>,
    /// The largest point or iso-line residual over the bounding-box diagonal of the input.
    pub max_residual_relative: f64,
    /// Thin-plate energies (Catmull-Clark only).
    pub energies: Option<Energies>,
    /// Seconds spent measuring.
    pub seconds: f64,
}

/// The energies of an edit (Catmull-Clark).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Energies {
    /// Thin-plate energy of the whole limit surface before the edit, one definition for
    /// every method ([`surface_energy_before_after`], no membrane term).
    pub before: f64,
    /// The same after.
    pub after: f64,
    /// The displacement's energy over the faces the free vertices touch (the method's own
    /// energy, membrane included, where it assembled one).
    pub displacement: f64,
}

/// Moves the control vertices of `mesh` so that its limit surface under `scheme` meets
/// `constraints` (see [`Editor`]); with `measure`, also measures the result afresh
/// ([`Measured`]).
///
/// # Errors
/// As [`Editor::new`]: a constraint that cannot be built ([`EditError::Constraint`], named
/// by its index), a mesh the limit evaluator rejects, the energy method on Loop, a failed
/// factorisation.
pub fn edit_mesh(
    mesh: &Mesh,
    scheme: &Scheme,
    options: &Options,
    constraints: &[Constraint],
    method: Method,
    measure: bool,
) -> Result<MeshEdit, EditError> {
    let x0 = &mesh.positions;
    let mut editor = Editor::new(&mesh.topology, x0, scheme, options, constraints, method)?;
    let edit = editor.solve_timed(constraints)?;
    let rows = editor.rows().rows.len();
    let warnings = dependency_warnings(constraints, &edit.dependencies, editor.rank, rows);
    let measured = measure
        .then(|| measure_edit(mesh, scheme, options, constraints, &mut editor, &edit))
        .transpose()?;
    Ok(MeshEdit {
        rows,
        rank: editor.rank,
        rank_deficient: editor.rank_deficient,
        free_vertices: editor.free_vertices().len(),
        warnings,
        timings: editor.timings,
        measured,
        edit,
    })
}

/// Residuals and energies of `edit` from a new evaluator on its positions.
fn measure_edit(
    mesh: &Mesh,
    scheme: &Scheme,
    options: &Options,
    constraints: &[Constraint],
    editor: &mut Editor,
    edit: &Edit,
) -> Result<Measured, EditError> {
    let started = Instant::now();
    let (topo, x0, x1) = (&mesh.topology, &mesh.positions, &edit.positions);
    let ev = LimitEvaluator::new(topo, scheme, options)?;
    let residuals = crate::check::residuals(&ev, topo, scheme, constraints, x0, x1)?;
    let max_residual_relative = largest_relative_distance(constraints, &residuals, x0);
    let energies = (*scheme == Scheme::CatmullClark)
        .then(|| energies(&ev, editor, x0, x1))
        .transpose()?;
    Ok(Measured {
        residuals,
        max_residual_relative,
        energies,
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// The largest residual of a point or iso-line over the bounding-box diagonal of `x0`.
fn largest_relative_distance(constraints: &[Constraint], res: &[f64], x0: &[DVec3]) -> f64 {
    let diagonal =
        subd_mesh::bounding_box(x0.iter().copied()).map_or(0.0, |(lo, hi)| (hi - lo).length());
    let diagonal = diagonal.max(f64::MIN_POSITIVE);
    constraints
        .iter()
        .zip(res)
        .filter(|(c, _)| !matches!(c, Constraint::Normal { .. }))
        .map(|(_, r)| r / diagonal)
        .fold(0.0, f64::max)
}

/// The energies of moving `x0` to `x1`: the displacement's with the method's own energy
/// matrix where it built one, else the thin plate's over the faces the free vertices touch.
fn energies(
    ev: &LimitEvaluator,
    editor: &mut Editor,
    x0: &[DVec3],
    x1: &[DVec3],
) -> Result<Energies, EditError> {
    let topo = ev.topology();
    let q = match editor.energy.take() {
        Some(q) => q,
        None => {
            let faces = faces_touching(topo, editor.free_vertices());
            EnergyMatrix::new(ev, topo.num_vertices(), &faces, &EnergyOptions::default())?
        }
    };
    let d: Vec<DVec3> = x1.iter().zip(x0).map(|(a, b)| *a - *b).collect();
    let (before, after) = surface_energy_before_after(ev, x0, x1, &EnergyOptions::default())?;
    Ok(Energies {
        before,
        after,
        displacement: q.energy(&d),
    })
}

/// Where a point or normal constraint is, as a constraint list says it.
fn location(at: &Location) -> String {
    match at {
        Location::Vertex(v) => format!("vertex {v}"),
        Location::Face(p) if p.sub == 0 => format!("face {} uv ({}, {})", p.face, p.u, p.v),
        Location::Face(p) => format!("face {} sub {} uv ({}, {})", p.face, p.sub, p.u, p.v),
    }
}

/// A constraint as the user wrote it: its index in the list, kind and place.
fn describe(index: usize, c: &Constraint) -> String {
    match c {
        Constraint::Point { at, .. } => format!("{index} (point at {})", location(at)),
        Constraint::Normal { at, .. } => format!("{index} (normal at {})", location(at)),
        Constraint::Isoline { line, .. } => {
            let along = match line.along {
                Axis::U => "u",
                Axis::V => "v",
            };
            format!(
                "{index} (isoline from face {} along {along} at {})",
                line.face, line.at
            )
        }
    }
}

/// "constraint 2 (…)", "constraints 0 (…) and 1 (…)", "constraints 0 (…), 1 (…) and 3 (…)".
fn name_constraints(indices: &[usize], constraints: &[Constraint]) -> String {
    let names: Vec<String> = indices
        .iter()
        .map(|&i| describe(i, &constraints[i]))
        .collect();
    match names.as_slice() {
        [one] => format!("constraint {one}"),
        [init @ .., last] => format!("constraints {} and {last}", init.join(", ")),
        [] => "no constraint".into(),
    }
}

/// One sentence per dependent group: redundant when its targets agree, else conflicting
/// with what the least-squares compromise leaves unmet. A rank deficiency the groups do not
/// explain (a solver's test looser than theirs) gets one sentence of its own.
fn dependency_warnings(
    constraints: &[Constraint],
    groups: &[DependentGroup],
    rank: usize,
    rows: usize,
) -> Vec<String> {
    let mut lines: Vec<String> = groups
        .iter()
        .map(|g| group_warning(constraints, g))
        .collect();
    if groups.is_empty() && rank < rows {
        lines.push(format!(
            "the constraint rows are dependent (rank {rank} of {rows} rows): the \
             least-squares solution"
        ));
    }
    lines
}

/// The sentence for one dependent group.
fn group_warning(constraints: &[Constraint], g: &DependentGroup) -> String {
    let names = name_constraints(&g.constraints, constraints);
    let single = g.constraints.len() == 1;
    if g.consistent {
        format!(
            "{names} {} redundant: {} dependent but consistent, every one met",
            if single { "is" } else { "are" },
            if single {
                "its rows are"
            } else {
                "their rows are"
            },
        )
    } else {
        format!(
            "{names} conflict{}: no surface meets {} ({} dependent rows); the \
             least-squares compromise leaves {:.4e} unmet",
            if single { "s with itself" } else { "" },
            if single { "all its rows" } else { "them all" },
            g.dependent_rows,
            g.residual
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Goal;

    fn torus_edit(constraints: &[Constraint], measure: bool) -> MeshEdit {
        let mesh = subd_mesh::primitives::torus(12, 8, 2.0, 0.5);
        let options = Options::default();
        edit_mesh(
            &mesh,
            &Scheme::CatmullClark,
            &options,
            constraints,
            Method::LeastSquares,
            measure,
        )
        .unwrap()
    }

    fn lift(v: usize, dz: f64) -> Constraint {
        Constraint::Point {
            at: Location::Vertex(v),
            goal: Goal::Displacement(DVec3::new(0.0, 0.0, dz)),
        }
    }

    #[test]
    fn a_measured_edit_meets_its_constraint() {
        let e = torus_edit(&[lift(0, 0.1)], true);
        let m = e.measured.expect("measured");
        assert!(m.residuals[0] < 1e-12, "{:?}", m.residuals);
        assert!(m.energies.is_some());
        assert!(e.warnings.is_empty() && !e.rank_deficient);
        assert!(torus_edit(&[lift(0, 0.1)], false).measured.is_none());
    }

    #[test]
    fn conflicting_constraints_are_named() {
        let e = torus_edit(&[lift(3, 0.1), lift(3, 0.3)], false);
        assert_eq!(e.warnings.len(), 1);
        assert!(
            e.warnings[0].starts_with(
                "constraints 0 (point at vertex 3) and 1 (point at vertex 3) conflict"
            ),
            "{}",
            e.warnings[0]
        );
    }
}
