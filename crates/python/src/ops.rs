//! The functions of `subd._subd`: each parses its arguments, calls the library once (the
//! GIL released, on the package's pool) and hands back arrays or a `_CoreMesh`.

use std::path::PathBuf;

use numpy::PyArray2;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use subd_limit::refined_mesh::{MeshRefinement, RefinedMesh, refine_mesh};
use subd_mesh::Mesh;
use subd_mesh::choice::Choice;
use subd_mesh::fvar::FVarLinearInterpolation;
use subd_mesh::report::MeshReport;
use subd_schemes::{Options, Scheme};

use crate::arrays::{IndexType, points};
use crate::errors::{io_error, mesh_error};
use crate::mesh::CoreMesh;
use crate::pool;

/// The scheme names `subd.refine` takes (the CLI's `--scheme` values).
pub(crate) const SCHEME_NAMES: [&str; 8] = Scheme::NAMES;

/// `name` (optionally `name:parameter`, the butterfly's tension or the two-phase scheme's
/// `λ`) as a scheme, or a `ValueError` listing the names.
pub(crate) fn scheme(name: &str) -> PyResult<Scheme> {
    name.parse::<Scheme>()
        .map_err(|e| PyValueError::new_err(format!("{e} (schemes: {})", SCHEME_NAMES.join(", "))))
}

/// The rule options by the CLI's names (`None`: the mesh's own, from its file's tags, else
/// OpenSubdiv's defaults).
pub(crate) struct RuleNames<'a> {
    pub(crate) boundary: Option<&'a str>,
    pub(crate) crease_method: Option<&'a str>,
    pub(crate) triangles: Option<&'a str>,
    pub(crate) fvar_interpolation: Option<&'a str>,
}

impl RuleNames<'_> {
    /// The options for a mesh with `hints`, or a `ValueError` listing the names.
    pub(crate) fn options(&self, hints: &subd_mesh::SchemeHints) -> PyResult<Options> {
        let mut o = Options::from_hints(hints);
        if let Some(b) = self.boundary {
            o.boundary_interpolation = named("boundary", b)?;
        }
        if let Some(c) = self.crease_method {
            o.crease_method = named("crease_method", c)?;
        }
        if let Some(t) = self.triangles {
            o.triangle_subdivision = named("triangles", t)?;
        }
        Ok(o)
    }

    /// How texture coordinates interpolate: the name given, else the mesh's own, else
    /// `corners-plus1` (the CLI's default).
    pub(crate) fn fvar_mode(
        &self,
        hints: &subd_mesh::SchemeHints,
    ) -> PyResult<FVarLinearInterpolation> {
        let given = self.fvar_interpolation;
        Ok(
            match given.map(|n| named("fvar_interpolation", n)).transpose()? {
                Some(mode) => mode,
                None => hints
                    .fvar_interpolation
                    .unwrap_or(FVarLinearInterpolation::CornersPlus1),
            },
        )
    }
}

/// `value` as one of the option `T`'s names, or a `ValueError` naming the argument `arg` and
/// listing the names.
pub(crate) fn named<T: Choice>(arg: &str, value: &str) -> PyResult<T> {
    T::from_name(value).map_err(|e| PyValueError::new_err(format!("{arg}: {e}")))
}

/// Reads a mesh file (OBJ with OpenSubdiv's tags, PLY, glTF, USD): the mesh and the
/// reader's warnings.
#[pyfunction]
#[pyo3(signature = (path, accept_inconsistent_orientation = false, no_transform = false, weld_tolerance = None, prim = None, time = None))]
pub(crate) fn read(
    py: Python<'_>,
    path: PathBuf,
    accept_inconsistent_orientation: bool,
    no_transform: bool,
    weld_tolerance: Option<f64>,
    prim: Option<String>,
    time: Option<f64>,
) -> PyResult<(CoreMesh, Vec<String>)> {
    if time.is_some_and(|t| !t.is_finite()) {
        return Err(PyValueError::new_err("time: expected a finite time code"));
    }
    if weld_tolerance.is_some_and(|w| !(w.is_finite() && w >= 0.0)) {
        return Err(PyValueError::new_err(
            "weld_tolerance: expected a finite distance ≥ 0",
        ));
    }
    let options = subd_io::ReadOptions {
        accept_inconsistent_orientation,
        ignore_transforms: no_transform,
        weld_tolerance,
        prim,
        time,
    };
    let file = pool::run(py, || subd_io::read_mesh(&path, &options))?.map_err(io_error)?;
    let mut core = CoreMesh::plain(file.mesh);
    core.orientation_conflicts = file.orientation_conflicts;
    core.stage = file.stage;
    Ok((core, file.warnings))
}

/// The mesh prims of the USD stage at `path` (composed, in traversal order): each one's
/// path, faces, points and `subdivisionScheme` token.
#[pyfunction]
pub(crate) fn mesh_prims(
    py: Python<'_>,
    path: PathBuf,
) -> PyResult<Vec<(String, usize, usize, String)>> {
    let prims = pool::run(py, || subd_io::usd::mesh_prims(&path))?.map_err(io_error)?;
    Ok(prims
        .into_iter()
        .map(|p| (p.path, p.faces, p.points, p.scheme))
        .collect())
}

/// The mesh refined `levels` times with `scheme` (the mesh's own rule options unless
/// named), its vertices and texture coordinates moved to the limit surface, with unit
/// normals, when `limit`: the mesh and what was left out (warnings).
#[pyfunction]
#[pyo3(signature = (mesh, scheme_name, levels, limit = false, boundary = None, crease_method = None, triangles = None, fvar_interpolation = None, index_dtype = "int64"))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn refine<'py>(
    py: Python<'py>,
    mesh: &CoreMesh,
    scheme_name: &str,
    levels: usize,
    limit: bool,
    boundary: Option<&str>,
    crease_method: Option<&str>,
    triangles: Option<&str>,
    fvar_interpolation: Option<&str>,
    index_dtype: &str,
) -> PyResult<(CoreMesh, Vec<String>, Option<Bound<'py, PyAny>>)> {
    let index_type = IndexType::named(index_dtype)?;
    let rules = RuleNames {
        boundary,
        crease_method,
        triangles,
        fvar_interpolation,
    };
    let base = mesh.mesh(py)?;
    let (scheme, options) = request(base, scheme_name, levels, &rules)?;
    let request = MeshRefinement {
        scheme,
        options,
        levels,
        limit,
        fvar_interpolation: rules.fvar_mode(&base.hints)?,
    };
    let mut refined = pool::run(py, || refine_mesh(base, &request))?.map_err(mesh_error)?;
    let warnings = std::mem::take(&mut refined.warnings);
    let faces = last_faces(py, &refined, index_type)?;
    Ok((CoreMesh::refined(refined).made_from(mesh), warnings, faces))
}

/// The face-vertex indices of a refinement's last level written once, straight into the
/// array Python keeps (`index_type`), from the level above: no `u32` face list is made
/// unless something else asks for one. `None` where the scheme does not stream its faces.
fn last_faces<'py>(
    py: Python<'py>,
    refined: &RefinedMesh,
    index_type: IndexType,
) -> PyResult<Option<Bound<'py, PyAny>>> {
    let Some(stream) = refined.face_stream() else {
        return Ok(None);
    };
    index_type.check_holds(refined.positions().len())?;
    index_type.faces(py, &stream).map(Some)
}

/// A refinement request checked: the scheme, the options for `mesh` and the output's size.
pub(crate) fn request(
    mesh: &Mesh,
    scheme_name: &str,
    levels: usize,
    rules: &RuleNames<'_>,
) -> PyResult<(Scheme, Options)> {
    let scheme = scheme(scheme_name)?;
    let options = rules.options(&mesh.hints)?;
    check_size(mesh, &scheme, levels)?;
    Ok((scheme, options))
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
    let m = mesh.mesh(py)?;
    let options = Options::from_hints(&m.hints);
    let l = pool::run(py, || {
        subd_limit::limit_points(&m.topology, &scheme, &options, &m.positions)
    })?
    .map_err(mesh_error)?;
    Ok((points(py, &l.positions)?, points(py, &l.normals)?))
}

/// What `subd info --json` reports of the mesh (its topology summary, irregular vertices,
/// tags and texture-coordinate seams), as a JSON text the Python layer turns into a dict.
#[pyfunction]
pub(crate) fn info(py: Python<'_>, mesh: &CoreMesh) -> PyResult<String> {
    let m = mesh.mesh(py)?;
    let report = pool::run(py, || MeshReport::of(m, mesh.orientation_conflicts))?;
    serde_json::to_string(&report).map_err(|e| PyValueError::new_err(e.to_string()))
}
