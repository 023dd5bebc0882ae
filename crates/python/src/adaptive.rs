//! `subd._subd.adaptive`: selective refinement, crack-free (`subd_adaptive::request`).

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use subd_adaptive::AdaptiveMesh;
use subd_adaptive::request::{AdaptedMesh, AdaptiveRequest, adapt_mesh};
use subd_mesh::fvar::FVarChannel;
use subd_mesh::{Mesh, SchemeHints, TopologyBuilder};

use crate::arrays::index;
use crate::errors::mesh_error;
use crate::mesh::CoreMesh;
use crate::ops::{RuleNames, scheme};
use crate::pool;

/// The thresholds of the criteria (`None`: not used), a dict keyed as the CLI's flags are
/// named.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub(crate) struct Thresholds {
    flatness: Option<f64>,
    max_distance: Option<f64>,
    curvature: Option<f64>,
    dihedral: Option<f64>,
}

/// `mesh` refined where the criteria ask, up to `levels`: the mesh (its `face_levels`
/// set) and what was left out (warnings).
#[pyfunction]
#[pyo3(signature = (mesh, scheme_name, levels, limit, thresholds, select_faces = None, select_vertices = None, boundary = None, crease_method = None, triangles = None, fvar_interpolation = None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn adaptive(
    py: Python<'_>,
    mesh: &CoreMesh,
    scheme_name: &str,
    levels: usize,
    limit: bool,
    thresholds: Thresholds,
    select_faces: Option<PyReadonlyArray1<'_, i64>>,
    select_vertices: Option<PyReadonlyArray1<'_, i64>>,
    boundary: Option<&str>,
    crease_method: Option<&str>,
    triangles: Option<&str>,
    fvar_interpolation: Option<&str>,
) -> PyResult<(CoreMesh, Vec<String>)> {
    let base = mesh.mesh(py)?;
    let rules = RuleNames {
        boundary,
        crease_method,
        triangles,
        fvar_interpolation,
    };
    let request = AdaptiveRequest {
        scheme: scheme(scheme_name)?,
        options: rules.options(&base.hints)?,
        levels,
        limit,
        flatness: thresholds.flatness,
        max_distance: thresholds.max_distance,
        curvature: thresholds.curvature,
        dihedral: thresholds.dihedral,
        select_faces: select_faces
            .map(|a| indices(&a, "select_faces"))
            .transpose()?,
        select_vertices: select_vertices
            .map(|a| indices(&a, "select_vertices"))
            .transpose()?,
        fvar_interpolation: rules.fvar_mode(&base.hints)?,
    };
    let adapted = pool::run(py, || {
        adapt_mesh(base, &request)
            .map_err(|e| e.to_string())
            .and_then(|a| assembled(a, &request))
    })?
    .map_err(mesh_error)?;
    Ok((adapted.0.made_from(mesh), adapted.1))
}

/// Indices as the criteria take them, a negative one named.
fn indices(a: &PyReadonlyArray1<'_, i64>, what: &str) -> PyResult<Vec<u64>> {
    a.as_array()
        .iter()
        .map(|&i| index(i).map_err(|e| mesh_error(format!("{what}: {e}"))))
        .collect()
}

/// The adaptive result as a mesh: its faces, holes, the rule options it was refined with,
/// its texture coordinates, normals (with `limit`) and the level of every face.
fn assembled(
    adapted: AdaptedMesh,
    request: &AdaptiveRequest,
) -> Result<(CoreMesh, Vec<String>), String> {
    let AdaptedMesh {
        mesh: a,
        uv,
        warnings,
        ..
    } = adapted;
    let AdaptiveMesh {
        positions,
        normals,
        face_offsets,
        face_vertices,
        face_levels,
        holes,
        ..
    } = a;
    let mut mesh = mesh_of(positions, &face_offsets, &face_vertices, &holes)?;
    mesh.hints = SchemeHints {
        boundary_interpolation: Some(request.options.boundary_interpolation),
        crease_method: Some(request.options.crease_method),
        triangle_subdivision: Some(request.options.triangle_subdivision),
        fvar_interpolation: uv.as_ref().map(|_| request.fvar_interpolation),
        scheme: None,
    };
    if let Some(uv) = uv {
        let channel = FVarChannel::new(&mesh.topology, uv.components, uv.values, uv.indices)
            .map_err(|e| e.to_string())?;
        mesh.fvar.push(channel);
    }
    let mut core = CoreMesh::plain(mesh);
    core.normals = (!normals.is_empty()).then_some(normals);
    core.face_levels = Some(face_levels);
    Ok((core, warnings))
}

/// Faces and positions as a [`Mesh`], its holes tagged.
fn mesh_of(
    positions: Vec<subd_mesh::DVec3>,
    offsets: &[u32],
    face_vertices: &[u32],
    holes: &[bool],
) -> Result<Mesh, String> {
    let sizes: Vec<u32> = offsets.windows(2).map(|w| w[1] - w[0]).collect();
    let mut topology = TopologyBuilder::new(positions.len())
        .build(&sizes, face_vertices)
        .map_err(|e| e.to_string())?;
    for (f, &hole) in holes.iter().enumerate() {
        topology.set_hole(f, hole);
    }
    Mesh::new(topology, positions).map_err(|e| e.to_string())
}
