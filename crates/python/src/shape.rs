//! Functions that move a mesh's control points (`subd pia`, `subd edit`, `subd deform`):
//! each takes a `_CoreMesh` and the CLI's options, runs the library once with the GIL
//! released, and gives back a `_CoreMesh` with the input's topology, tags and texture
//! coordinates and the new positions, with a JSON report the Python layer turns into a
//! dict (as `info` does). Constraints come as the JSON text the CLI reads from its files,
//! parsed by the same parser, so both accept the same lists and name the same problems.

use numpy::PyReadonlyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use serde_json::json;
use subd_editing::{Deformation, MeshEdit, MethodRequest};
use subd_mesh::{DVec3, Mesh};
use subd_pia::{InterpolationRequest, Moving, PiaOptions};
use subd_schemes::{Capability, Options, Scheme, TwoPhase};

use crate::arrays::contiguous;
use crate::errors::mesh_error;
use crate::mesh::CoreMesh;
use crate::ops::{RuleNames, named, scheme};
use crate::pool;

/// `base`'s topology, tags and texture coordinates with `positions` (checked finite).
fn reshaped(base: &Mesh, positions: Vec<DVec3>) -> Result<Mesh, String> {
    let mut mesh = Mesh::new(base.topology.clone(), positions).map_err(|e| e.to_string())?;
    mesh.hints = base.hints;
    // Only control points move: texture coordinates stay as given.
    mesh.fvar = base.fvar.clone();
    Ok(mesh)
}

/// The control cage of `scheme` with the base's topology at `positions`: it names the scheme
/// (as `subd pia` and `subd edit` do), so that a USD output is subdivided by a renderer into
/// the same limit surface; a scheme USD cannot name leaves the cage plain polygons.
fn cage(base: &Mesh, positions: Vec<DVec3>, scheme: &Scheme) -> Result<Mesh, String> {
    let mut mesh = reshaped(base, positions)?;
    mesh.hints.scheme = scheme.file_scheme();
    Ok(mesh)
}

/// Vertex indices as `u32`, each named when negative or past the mesh's `nv` vertices.
fn vertex_list(indices: &[i64], nv: usize, what: &str) -> PyResult<Vec<u32>> {
    indices
        .iter()
        .map(|&i| match u32::try_from(i) {
            Ok(v) if (v as usize) < nv => Ok(v),
            _ if i < 0 => Err(mesh_error(format!("{what}: vertex index {i} is negative"))),
            _ => Err(mesh_error(format!(
                "{what}: vertex {i} does not exist (the mesh has {nv} vertices)"
            ))),
        })
        .collect()
}

/// The vertices that move: `moving` only, all but `fixed`, or all.
fn moving_vertices(moving: Option<&[i64]>, fixed: Option<&[i64]>, nv: usize) -> PyResult<Moving> {
    match (moving, fixed) {
        (Some(_), Some(_)) => Err(PyValueError::new_err(
            "moving and fixed: give one of them (the other vertices are the rest)",
        )),
        (Some(m), None) => Ok(Moving::Only(vertex_list(m, nv, "moving")?)),
        (None, Some(f)) => Ok(Moving::AllBut(vertex_list(f, nv, "fixed")?)),
        (None, None) => Ok(Moving::All),
    }
}

/// `scheme` with the two-phase scheme's `λ` from `lam` (one value for every vertex, or one
/// per vertex): the CLI's `--lambda` / `--lambda-file` and `--allow-any-lambda`.
fn with_lambda(
    scheme: Scheme,
    lam: Option<&[f64]>,
    allow_any_lambda: bool,
    nv: usize,
) -> PyResult<Scheme> {
    let values = match (&scheme, lam) {
        (Scheme::TwoPhase(tp), Some(_)) if tp.is_set() => {
            return Err(mesh_error(
                "lam: the scheme name (two-phase:λ) gives λ already",
            ));
        }
        (Scheme::TwoPhase(tp), None) if !tp.is_set() => {
            return Err(mesh_error(
                "the two-phase scheme needs lam (one λ, or one per vertex)",
            ));
        }
        (Scheme::TwoPhase(_), Some(&[one])) => vec![one; nv],
        (Scheme::TwoPhase(_), Some(l)) if l.len() == nv => l.to_vec(),
        (Scheme::TwoPhase(_), Some(l)) => {
            return Err(mesh_error(format!(
                "lam: {} values for {nv} vertices (one, or one per vertex)",
                l.len()
            )));
        }
        (_, Some(_)) => return Err(mesh_error("lam applies to the two-phase scheme only")),
        (_, None) => return Ok(scheme),
    };
    let checked = if allow_any_lambda {
        TwoPhase::with_any_lambda(values)
    } else {
        TwoPhase::new(values)
    };
    checked.map(Scheme::TwoPhase).map_err(|e| {
        let hint = if allow_any_lambda {
            ""
        } else {
            " (allow_any_lambda=True accepts it)"
        };
        mesh_error(format!("lam: {e}{hint}"))
    })
}

/// An interpolation's request, checked.
struct PiaRequest {
    scheme: Scheme,
    options: Options,
    moving: Moving,
    solve: PiaOptions,
}

/// An interpolation's result: the control points where it converged, and its report.
type Solved = (Option<CoreMesh>, String);

/// Control points whose limit surface under `scheme_name` passes through the mesh's
/// vertices (the moving ones): the new mesh when the solve reached `tol`, else `None`, and
/// the report as JSON.
#[pyfunction]
#[pyo3(signature = (mesh, scheme_name, lam, allow_any_lambda, moving, fixed, solver, tol, max_iter, boundary = None, crease_method = None, triangles = None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn pia(
    py: Python<'_>,
    mesh: &CoreMesh,
    scheme_name: &str,
    lam: Option<PyReadonlyArray1<'_, f64>>,
    allow_any_lambda: bool,
    moving: Option<PyReadonlyArray1<'_, i64>>,
    fixed: Option<PyReadonlyArray1<'_, i64>>,
    solver: &str,
    tol: f64,
    max_iter: usize,
    boundary: Option<&str>,
    crease_method: Option<&str>,
    triangles: Option<&str>,
) -> PyResult<Solved> {
    let base = mesh.mesh(py)?;
    let nv = base.topology.num_vertices();
    let lam = lam.as_ref().map(|l| contiguous(l, "lam")).transpose()?;
    let moving = moving
        .as_ref()
        .map(|m| contiguous(m, "moving"))
        .transpose()?;
    let fixed = fixed.as_ref().map(|f| contiguous(f, "fixed")).transpose()?;
    if tol.is_nan() || tol <= 0.0 {
        return Err(mesh_error(format!("tol {tol}: must be a positive number")));
    }
    let rules = RuleNames {
        boundary,
        crease_method,
        triangles,
        fvar_interpolation: None,
    };
    let request = PiaRequest {
        scheme: with_lambda(scheme(scheme_name)?, lam, allow_any_lambda, nv)?,
        options: rules.options(&base.hints)?,
        moving: moving_vertices(moving, fixed, nv)?,
        solve: PiaOptions {
            solver: named("solver", solver)?,
            tol,
            max_iter,
        },
    };
    let (solved, report) = pool::run(py, || interpolate(base, &request))?.map_err(mesh_error)?;
    let cage_of = |m| CoreMesh::plain(m).made_from(mesh).cage_of(&request.scheme);
    Ok((solved.map(cage_of), report))
}

/// The library's interpolation workflow (as `subd pia` runs it): the fitted mesh where the
/// fresh measurement meets the tolerance, and the report as JSON.
fn interpolate(base: &Mesh, r: &PiaRequest) -> Result<(Option<Mesh>, String), String> {
    let request = InterpolationRequest {
        scheme: &r.scheme,
        options: &r.options,
        moving: &r.moving,
        solve: r.solve,
    };
    let fitted = subd_pia::interpolate(&base.topology, &base.positions, &request)
        .map_err(|e| e.to_string())?;
    let mut report = serde_json::to_value(&fitted.report).map_err(|e| e.to_string())?;
    report["seconds"] = json!(fitted.seconds);
    // A solve that did not converge may hold points that are not finite: no mesh of them.
    let mesh = fitted
        .report
        .converged
        .then(|| cage(base, fitted.points, &r.scheme))
        .transpose()?;
    Ok((mesh, report.to_string()))
}

/// `method` and its energy options as the CLI's `subd edit` takes them.
fn edit_method(
    method: &str,
    penalty: Option<f64>,
    exact: bool,
    membrane: f64,
    region_rings: Option<usize>,
) -> PyResult<subd_editing::Method> {
    MethodRequest {
        kind: named("method", method)?,
        penalty,
        exact,
        membrane,
        region_rings,
    }
    .method()
    .map_err(mesh_error)
}

/// The schemes whose limit surface the editor evaluates at any point.
fn edited_scheme(name: &str) -> PyResult<Scheme> {
    let s = scheme(name)?;
    if s.supports(Capability::Edit) {
        Ok(s)
    } else {
        Err(PyValueError::new_err(format!(
            "scheme {name:?}: {} needs {}",
            Capability::Edit,
            Scheme::list_with(Capability::Edit)
        )))
    }
}

/// An edit's result: the mesh, the dependency warnings and the report as JSON.
type Edited = (CoreMesh, Vec<String>, String);

/// The mesh with its control points moved so that the limit surface meets the constraints
/// of `constraints_json` (the CLI's constraint file), the warnings about dependent
/// constraints, and the report (measured afresh with `measure`).
#[pyfunction]
#[pyo3(signature = (mesh, constraints_json, scheme_name, method, penalty, exact, membrane, region_rings, measure, boundary = None, crease_method = None, triangles = None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn edit(
    py: Python<'_>,
    mesh: &CoreMesh,
    constraints_json: &str,
    scheme_name: &str,
    method: &str,
    penalty: Option<f64>,
    exact: bool,
    membrane: f64,
    region_rings: Option<usize>,
    measure: bool,
    boundary: Option<&str>,
    crease_method: Option<&str>,
    triangles: Option<&str>,
) -> PyResult<Edited> {
    let scheme = edited_scheme(scheme_name)?;
    let method = edit_method(method, penalty, exact, membrane, region_rings)?;
    let constraints =
        subd_editing::spec::parse_constraints(constraints_json).map_err(mesh_error)?;
    if constraints.is_empty() {
        return Err(mesh_error("no constraints"));
    }
    let base = mesh.mesh(py)?;
    let rules = RuleNames {
        boundary,
        crease_method,
        triangles,
        fvar_interpolation: None,
    };
    let options = rules.options(&base.hints)?;
    let (edited, moved) = pool::run(py, || -> Result<(MeshEdit, Mesh), String> {
        let e = subd_editing::edit_mesh(base, &scheme, &options, &constraints, method, measure)
            .map_err(|e| e.to_string())?;
        let moved = cage(base, e.edit.positions.clone(), &scheme)?;
        Ok((e, moved))
    })?
    .map_err(mesh_error)?;
    let mut report = serde_json::to_value(edited.report(
        &scheme,
        &method,
        base.topology.num_vertices(),
        &constraints,
    ))
    .map_err(|e| mesh_error(e.to_string()))?;
    report["seconds"] = json!(edited.seconds());
    Ok((
        CoreMesh::plain(moved).made_from(mesh).cage_of(&scheme),
        edited.warnings,
        report.to_string(),
    ))
}

/// The mesh with its vertices moved by the deformation of `constraints_json` (the CLI's
/// deformation file), and the report as JSON.
#[pyfunction]
pub(crate) fn deform(
    py: Python<'_>,
    mesh: &CoreMesh,
    constraints_json: &str,
) -> PyResult<(CoreMesh, String)> {
    let constraints =
        subd_editing::spec::parse_deformation(constraints_json).map_err(mesh_error)?;
    let deformation = Deformation::new(&constraints).map_err(mesh_error)?;
    let base = mesh.mesh(py)?;
    let (moved, count) = pool::run(py, || -> Result<(Mesh, usize), String> {
        let mut positions = base.positions.clone();
        let count = deformation.apply(&mut positions);
        Ok((reshaped(base, positions)?, count))
    })?
    .map_err(mesh_error)?;
    let report = json!({
        "vertices": base.topology.num_vertices(),
        "constraints": constraints.len(),
        "moved": count,
        "max_constraint_error": deformation.max_constraint_error(),
    });
    Ok((CoreMesh::plain(moved).made_from(mesh), report.to_string()))
}
