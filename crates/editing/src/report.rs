//! What an edit did, as `subd edit --json` and `subd.edit`'s report show it: one
//! serialisable record made by the library, so both fronts report the same fields.

use serde::Serialize;
use subd_schemes::Scheme;

use crate::constraint::Constraint;
use crate::dependency::DependentGroup;
use crate::mesh_edit::MeshEdit;
use crate::solve::Method;

/// One constraint's residual, measured on the edited surface with a fresh evaluator.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ConstraintResidual {
    /// Its index in the constraint list.
    pub constraint: usize,
    /// `point`, `normal` or `isoline`.
    pub kind: &'static str,
    /// A distance (points, iso-lines; model units) or the sine of the angle to the target
    /// normal.
    pub residual: f64,
}

/// An edit's report: the solve's shape, what moved and, where the edit was measured, the
/// residuals and energies. Times are in [`EditSeconds`], apart, so a front can add its own.
#[derive(Clone, Debug, Serialize)]
pub struct EditReport {
    /// The scheme of the limit surface.
    pub scheme: Scheme,
    /// [`Method::report_name`].
    pub method: &'static str,
    /// Vertices of the mesh.
    pub vertices: usize,
    /// Constraints given.
    pub constraints: usize,
    /// Constraint rows.
    pub rows: usize,
    /// Their rank.
    pub rank: usize,
    /// Whether the constraints were dependent or conflicting (least-squares solution).
    pub rank_deficient: bool,
    /// The groups of dependent constraints: which, how many dependent rows, whether they
    /// agree (`consistent`) and what no change can meet (`residual`).
    pub dependencies: Vec<DependentGroup>,
    /// Vertices allowed to move (the constraints' support, or the energy's region).
    pub free_vertices: usize,
    /// The vertices that moved.
    pub moved_vertices: Vec<u32>,
    /// Per constraint, measured afresh (`None` when the edit was not measured).
    pub residuals: Option<Vec<ConstraintResidual>>,
    /// The largest point or iso-line residual over the bounding-box diagonal.
    pub max_residual_relative: Option<f64>,
    /// Thin-plate energy `∬ S_uu² + 2 S_uv² + S_vv²` of the whole limit surface before the
    /// edit (Catmull-Clark; no membrane term whatever the method's options).
    pub energy_before: Option<f64>,
    /// The same after.
    pub energy_after: Option<f64>,
    /// The displacement's energy over the faces the free vertices touch, with the energy
    /// method's membrane term (what that method minimises).
    pub displacement_energy: Option<f64>,
}

/// Seconds spent in each phase of an edit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct EditSeconds {
    /// The limit evaluator.
    pub evaluator: f64,
    /// The constraint rows.
    pub constraints: f64,
    /// Energy matrix assembly (0 for least squares).
    pub assemble: f64,
    /// Factorisation and the solution map.
    pub factor: f64,
    /// The solve.
    pub solve: f64,
    /// The fresh measurement (0 when not measured).
    pub check: f64,
}

impl MeshEdit {
    /// The report of this edit of a mesh of `vertices` vertices under `scheme` and
    /// `method`, with `constraints` as given.
    pub fn report(
        &self,
        scheme: &Scheme,
        method: &Method,
        vertices: usize,
        constraints: &[Constraint],
    ) -> EditReport {
        let measured = self.measured.as_ref();
        let energies = measured.and_then(|m| m.energies);
        let residuals = measured.map(|m| {
            let each = constraints.iter().zip(&m.residuals).enumerate();
            each.map(|(i, (c, &r))| ConstraintResidual {
                constraint: i,
                kind: c.kind(),
                residual: r,
            })
            .collect()
        });
        EditReport {
            scheme: scheme.clone(),
            method: method.report_name(),
            vertices,
            constraints: constraints.len(),
            rows: self.rows,
            rank: self.rank,
            rank_deficient: self.rank_deficient,
            dependencies: self.edit.dependencies.clone(),
            free_vertices: self.free_vertices,
            moved_vertices: self.edit.moved.clone(),
            residuals,
            max_residual_relative: measured.map(|m| m.max_residual_relative),
            energy_before: energies.map(|e| e.before),
            energy_after: energies.map(|e| e.after),
            displacement_energy: energies.map(|e| e.displacement),
        }
    }

    /// The time of each phase.
    pub fn seconds(&self) -> EditSeconds {
        let t = self.timings;
        EditSeconds {
            evaluator: t.evaluator,
            constraints: t.constraints,
            assemble: t.assemble,
            factor: t.factor,
            solve: t.solve,
            check: self.measured.as_ref().map_or(0.0, |m| m.seconds),
        }
    }
}

impl Constraint {
    /// The constraint's kind as reports name it: `point`, `normal` or `isoline`.
    pub fn kind(&self) -> &'static str {
        match self {
            Constraint::Point { .. } => "point",
            Constraint::Normal { .. } => "normal",
            Constraint::Isoline { .. } => "isoline",
        }
    }
}
