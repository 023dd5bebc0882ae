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
}

impl RuleNames<'_> {
    /// The options for a mesh with `hints`, or a `ValueError` listing the names.
    pub(crate) fn options(&self, hints: &subd_mesh::SchemeHints) -> PyResult<Options> {
        use subd_mesh::{BoundaryInterpolation as B, CreaseMethod as C, TriangleSubdivision as T};
        let mut o = Options::from_hints(hints);
        let bad = |what: &str, got: &str, names: &str| {
            PyValueError::new_err(format!("{what}: unknown value {got:?} (one of {names})"))
        };
        if let Some(b) = self.boundary {
            o.boundary_interpolation = match b {
                "none" => B::None,
                "edge-only" => B::EdgeOnly,
                "edge-and-corner" => B::EdgeAndCorner,
                _ => return Err(bad("boundary", b, "none, edge-only, edge-and-corner")),
            };
        }
        if let Some(c) = self.crease_method {
            o.crease_method = match c {
                "uniform" => C::Uniform,
                "chaikin" => C::Chaikin,
                _ => return Err(bad("crease_method", c, "uniform, chaikin")),
            };
        }
        if let Some(t) = self.triangles {
            o.triangle_subdivision = match t {
                "catmark" => T::Catmark,
                "smooth" => T::Smooth,
                _ => return Err(bad("triangles", t, "catmark, smooth")),
            };
        }
        Ok(o)
    }
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
#[pyo3(signature = (mesh, scheme_name, levels, limit = false, boundary = None, crease_method = None, triangles = None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn refine(
    py: Python<'_>,
    mesh: &CoreMesh,
    scheme_name: &str,
    levels: usize,
    limit: bool,
    boundary: Option<&str>,
    crease_method: Option<&str>,
    triangles: Option<&str>,
) -> PyResult<CoreMesh> {
    let rules = RuleNames {
        boundary,
        crease_method,
        triangles,
    };
    let (scheme, options) = request(&mesh.mesh, scheme_name, levels, &rules)?;
    let (refined, normals) =
        pool::run(py, || refined(&mesh.mesh, scheme, &options, levels, limit))?
            .map_err(mesh_error)?;
    Ok(CoreMesh {
        mesh: refined,
        normals,
    })
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

/// The refined mesh (and its limit normals).
fn refined(
    mesh: &Mesh,
    scheme: Scheme,
    options: &Options,
    levels: usize,
    limit: bool,
) -> Result<(Mesh, Option<Vec<DVec3>>), String> {
    let r = Refinement::new(&mesh.topology, scheme, options, levels).map_err(|e| e.to_string())?;
    let mut positions = r.points_at(&mesh.positions, levels);
    let mut normals = None;
    if limit {
        let l = subd_limit::level_limit_points(
            &r,
            levels,
            options,
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
