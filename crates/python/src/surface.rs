//! Functions on the limit surface itself: exact evaluation at (face, u, v) and watertight
//! tessellation.

use numpy::{PyArray2, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;
use subd_limit::eval::FaceParam;
use subd_limit::patches::PatchTable;
use subd_limit::tessellation::tessellate_mesh;
use subd_mesh::{DVec3, Mesh, TopologyBuilder};
use subd_schemes::Options;

use crate::arrays::{contiguous, points};
use crate::errors::mesh_error;
use crate::mesh::CoreMesh;
use crate::ops::scheme;
use crate::pool;

/// Points on the limit surface: `[position, normal]`, then `[du, dv, duu, duv, dvv]` with
/// `derivatives`, each `(m, 3)`.
type Evaluated<'py> = Vec<Bound<'py, PyArray2<f64>>>;

/// The limit surface of `mesh` at `(faces[i], subs[i], u[i], v[i])` for every `i`.
#[pyfunction]
#[pyo3(signature = (mesh, scheme_name, faces, subs, u, v, derivatives = false))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn evaluate<'py>(
    py: Python<'py>,
    mesh: &CoreMesh,
    scheme_name: &str,
    faces: PyReadonlyArray1<'_, i64>,
    subs: PyReadonlyArray1<'_, i64>,
    u: PyReadonlyArray1<'_, f64>,
    v: PyReadonlyArray1<'_, f64>,
    derivatives: bool,
) -> PyResult<Evaluated<'py>> {
    let scheme = scheme(scheme_name)?;
    let (faces, subs) = (contiguous(&faces, "faces")?, contiguous(&subs, "sub")?);
    let (u, v) = (contiguous(&u, "u")?, contiguous(&v, "v")?);
    if [subs.len(), u.len(), v.len()]
        .iter()
        .any(|&n| n != faces.len())
    {
        return Err(PyValueError::new_err(
            "faces, sub, u and v need the same length",
        ));
    }
    let m = mesh.mesh(py)?;
    let options = Options::from_hints(&m.hints);
    let samples = pool::run(py, || -> Result<Vec<[DVec3; 7]>, String> {
        // The exact limit's patch table, as `subd eval` evaluates it.
        let table = PatchTable::exact_limit(&m.topology, &m.positions, &scheme, &options)
            .map_err(|e| e.to_string())?;
        // Points evaluated side by side; the first error in point order is the one named.
        let evaluated: Vec<Result<[DVec3; 7], String>> = (0..faces.len())
            .into_par_iter()
            .with_min_len(256)
            .map(|i| {
                let whole = |x: i64, what: &str| {
                    usize::try_from(x).map_err(|_| format!("point {i}: {what} {x} is negative"))
                };
                let at = FaceParam {
                    face: whole(faces[i], "face")?,
                    sub: whole(subs[i], "sub-face")?,
                    u: u[i],
                    v: v[i],
                };
                let p = table.evaluate(at).map_err(|e| format!("point {i}: {e}"))?;
                Ok([p.position, p.normal(), p.du, p.dv, p.duu, p.duv, p.dvv])
            })
            .collect();
        evaluated.into_iter().collect()
    })?
    .map_err(mesh_error)?;
    let kept = if derivatives { 7 } else { 2 };
    (0..kept)
        .map(|k| {
            let column: Vec<DVec3> = samples.iter().map(|s| s[k]).collect();
            points(py, &column)
        })
        .collect()
}

/// The limit surface of `mesh` sampled `rate` times along every edge, watertight, with
/// unit normals.
#[pyfunction]
#[pyo3(signature = (mesh, scheme_name, rate))]
pub(crate) fn tessellate(
    py: Python<'_>,
    mesh: &CoreMesh,
    scheme_name: &str,
    rate: usize,
) -> PyResult<CoreMesh> {
    let scheme = scheme(scheme_name)?;
    let m = mesh.mesh(py)?;
    let options = Options::from_hints(&m.hints);
    let (out, normals) = pool::run(py, || -> Result<(Mesh, Vec<DVec3>), String> {
        let t = tessellate_mesh(&m.topology, &scheme, &options, &m.positions, rate)
            .map_err(|e| e.to_string())?;
        let sizes: Vec<u32> = t.face_offsets.windows(2).map(|w| w[1] - w[0]).collect();
        // As watertight as the input: a non-manifold input gives non-manifold samples.
        let topology = TopologyBuilder::new(t.positions.len())
            .accept_inconsistent_orientation(true)
            .build(&sizes, &t.face_vertices)
            .map_err(|e| e.to_string())?;
        let out = Mesh::new(topology, t.positions).map_err(|e| e.to_string())?;
        Ok((out, t.normals))
    })?
    .map_err(mesh_error)?;
    let mut core = CoreMesh::plain(out).made_from(mesh);
    core.normals = Some(normals);
    Ok(core)
}
