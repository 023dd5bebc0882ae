//! The functions of `subd._subd`: each parses its arguments, calls the library once (the
//! GIL released, on the package's pool) and hands back arrays or a `_CoreMesh`.

use std::path::PathBuf;

use numpy::PyArray2;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use subd_mesh::{DVec3, Mesh};
use subd_schemes::{Options, Refinement, Scheme};

use crate::errors::{io_error, mesh_error};
use crate::mesh::{CoreMesh, points};
use crate::pool;

/// The scheme names `subd.refine` takes (the CLI's `--scheme` values).
pub(crate) const SCHEME_NAMES: [&str; 8] = Scheme::NAMES;

/// `name` (optionally `name:parameter`, the butterfly's tension or the two-phase scheme's
/// `λ`) as a scheme, or a `ValueError` listing the names.
fn scheme(name: &str) -> PyResult<Scheme> {
    name.parse::<Scheme>()
        .map_err(|e| PyValueError::new_err(format!("{e} (schemes: {})", SCHEME_NAMES.join(", "))))
}

/// Reads a mesh file (OBJ with OpenSubdiv's tags, PLY, glTF): the mesh and the reader's
/// warnings.
#[pyfunction]
#[pyo3(signature = (path, accept_inconsistent_orientation = false))]
pub(crate) fn read(
    py: Python<'_>,
    path: PathBuf,
    accept_inconsistent_orientation: bool,
) -> PyResult<(CoreMesh, Vec<String>)> {
    let options = subd_io::ReadOptions {
        accept_inconsistent_orientation,
        ..Default::default()
    };
    let file = pool::run(py, || subd_io::read_mesh(&path, &options))?.map_err(io_error)?;
    Ok((
        CoreMesh {
            mesh: file.mesh,
            normals: None,
        },
        file.warnings,
    ))
}

/// The mesh refined `levels` times with `scheme` (the mesh's own boundary and crease
/// options), its vertices moved to the limit surface with unit normals when `limit`.
#[pyfunction]
#[pyo3(signature = (mesh, scheme_name, levels, limit = false))]
pub(crate) fn refine(
    py: Python<'_>,
    mesh: &CoreMesh,
    scheme_name: &str,
    levels: usize,
    limit: bool,
) -> PyResult<CoreMesh> {
    let scheme = scheme(scheme_name)?;
    check_size(&mesh.mesh, &scheme, levels)?;
    let (refined, normals) =
        pool::run(py, || refined(&mesh.mesh, scheme, levels, limit))?.map_err(mesh_error)?;
    Ok(CoreMesh {
        mesh: refined,
        normals,
    })
}

/// Refuses a refinement whose output would not fit the library's 32-bit indices, before
/// any of it is allocated.
fn check_size(mesh: &Mesh, scheme: &Scheme, levels: usize) -> PyResult<()> {
    if levels > subd_schemes::MAX_LEVELS {
        return Err(mesh_error(format!(
            "{levels} levels asked for; at most {} are supported",
            subd_schemes::MAX_LEVELS
        )));
    }
    let counts = subd_schemes::refined_counts(&mesh.topology, scheme, levels);
    let too_many = counts.last().is_some_and(|c| {
        c.face_vertices >= u64::from(u32::MAX) || c.vertices >= u64::from(u32::MAX)
    });
    if too_many {
        return Err(mesh_error(format!(
            "level {levels} of this mesh would have more than 2^32 face-vertices or vertices"
        )));
    }
    Ok(())
}

/// The refined mesh (and its limit normals).
fn refined(
    mesh: &Mesh,
    scheme: Scheme,
    levels: usize,
    limit: bool,
) -> Result<(Mesh, Option<Vec<DVec3>>), String> {
    let options = Options::from_hints(&mesh.hints);
    let r = Refinement::new(&mesh.topology, scheme, &options, levels).map_err(|e| e.to_string())?;
    let mut positions = r.points_at(&mesh.positions, levels);
    let mut normals = None;
    if limit {
        let l = subd_limit::level_limit_points(
            &r,
            levels,
            &options,
            &positions,
            subd_limit::Tangents::Dropped,
        )
        .map_err(|e| e.to_string())?;
        positions = l.positions;
        normals = Some(l.normals);
    }
    let topology = r.into_topology(levels);
    let mut out = Mesh::new(topology, positions).map_err(|e| e.to_string())?;
    out.hints = mesh.hints;
    Ok((out, normals))
}

/// The exact limit position and unit normal of every vertex of `mesh`.
#[pyfunction]
#[pyo3(signature = (mesh, scheme_name))]
#[allow(clippy::type_complexity)]
pub(crate) fn limit<'py>(
    py: Python<'py>,
    mesh: &CoreMesh,
    scheme_name: &str,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
    let scheme = scheme(scheme_name)?;
    let m = &mesh.mesh;
    let options = Options::from_hints(&m.hints);
    let l = pool::run(py, || {
        subd_limit::limit_points(&m.topology, &scheme, &options, &m.positions)
    })?
    .map_err(mesh_error)?;
    Ok((points(py, &l.positions)?, points(py, &l.normals)?))
}
