//! `subd._subd._CorePatchTable`: a mesh's feature-adaptive patch table (OpenSubdiv's
//! `PatchTable`), its arrays, its local-point stencils, vectorised evaluation and `update`,
//! the evaluation optionally on the GPU.

use std::sync::Arc;

use subd_gpu::{Gpu, GpuPatchTable, GpuPatchValues};

use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyList;
use subd_limit::eval::FaceParam;
use subd_limit::patches::{EndCaps, PatchOptions, PatchTable};
use subd_mesh::DVec3;

use crate::arrays::{contiguous, copied1, filled1, points, view2};
use crate::device::{choose, device_error, fallback_warning};
use crate::errors::{mesh_error, warn};
use crate::mesh::CoreMesh;
use crate::ops::{RuleNames, named, scheme};
use crate::pool;

/// A patch table of one mesh, with the points of its current positions.
#[pyclass(name = "_CorePatchTable", module = "subd._subd")]
pub(crate) struct CorePatchTable {
    table: PatchTable,
    /// The table on the GPU, where it is evaluated there.
    device: Option<(Arc<Gpu>, GpuPatchTable)>,
    /// Why `device="auto"` evaluates on the CPU, if it does.
    device_warning: Option<String>,
    /// `device="auto"`: a failure on the GPU falls back to the CPU with a warning.
    auto: bool,
}

/// One array's parts: type name, control points `(n, k)`, parameters `(n, 2)` (OpenSubdiv's
/// two packed words), single-crease sharpness `(n,)`.
type ArrayParts<'py> = (
    &'static str,
    Bound<'py, PyArray2<u32>>,
    Bound<'py, PyArray2<u32>>,
    Bound<'py, PyArray2<f32>>,
);

#[pymethods]
impl CorePatchTable {
    /// Builds the table of `mesh` with `scheme_name` and the options.
    #[new]
    /// Texture coordinates of the mesh become face-varying channel 0, refined with
    /// `fvar_interpolation` (else the mesh's own mode, else corners-plus1).
    /// `evaluate` runs on `device` ("cpu", "gpu" or "auto").
    #[pyo3(signature = (mesh, scheme_name, isolation, end_caps, single_crease, inf_sharp, legacy_sharp_corners, boundary = None, crease_method = None, triangles = None, fvar_interpolation = None, device = "cpu"))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        mesh: &CoreMesh,
        scheme_name: &str,
        isolation: u8,
        end_caps: &str,
        single_crease: bool,
        inf_sharp: bool,
        legacy_sharp_corners: bool,
        boundary: Option<&str>,
        crease_method: Option<&str>,
        triangles: Option<&str>,
        fvar_interpolation: Option<&str>,
        device: &str,
    ) -> PyResult<CorePatchTable> {
        let (gpu, mut device_warning) = choose(device)?;
        let scheme = scheme(scheme_name)?;
        let end_caps: EndCaps = named("end_caps", end_caps)?;
        let base = mesh.mesh(py)?;
        let names = RuleNames {
            boundary,
            crease_method,
            triangles,
            fvar_interpolation,
        };
        let rules = names.options(&base.hints)?;
        let mode = names.fvar_mode(&base.hints)?;
        let options = PatchOptions {
            isolation,
            end_caps,
            single_crease,
            inf_sharp,
            legacy_sharp_corners,
        };
        let table = pool::run(py, || {
            let mut table =
                PatchTable::new(&base.topology, &base.positions, &scheme, &rules, &options)?;
            if let Some(uv) = base.uv() {
                table.add_face_varying(uv, mode)?;
            }
            Ok::<_, subd_limit::LimitError>(table)
        })?
        .map_err(mesh_error)?;
        let on_device = match gpu {
            None => None,
            Some(gpu) => match py.detach(|| GpuPatchTable::new(&gpu, &table)) {
                Ok(t) => Some((gpu, t)),
                Err(e) if device == "auto" => {
                    device_warning = Some(fallback_warning(&e));
                    None
                }
                Err(e) => return Err(device_error(e)),
            },
        };
        Ok(CorePatchTable {
            table,
            device: on_device,
            device_warning,
            auto: device == "auto",
        })
    }

    /// Where `evaluate` runs: "gpu" or "cpu".
    #[getter]
    fn device(&self) -> &'static str {
        if self.device.is_some() { "gpu" } else { "cpu" }
    }

    /// Why `device="auto"` evaluates on the CPU, if it does.
    #[getter]
    fn device_warning(&self) -> Option<String> {
        self.device_warning.clone()
    }

    /// The census as JSON text (the Python layer makes it a dict).
    fn census(&self) -> PyResult<String> {
        serde_json::to_string(&self.table.census())
            .map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// Every array's parts, in table order, as read-only views of the table's memory.
    #[allow(unsafe_code)] // views without copies: see each SAFETY note
    fn arrays<'py>(slf: Bound<'py, Self>) -> PyResult<Bound<'py, PyList>> {
        let py = slf.py();
        let this = slf.borrow();
        let parts: Vec<ArrayParts<'py>> = this
            .table
            .arrays()
            .iter()
            .map(|a| {
                let k = a.kind().num_control_points().unwrap_or(0).max(1);
                let params = a.params();
                // SAFETY: `PatchParam` is `#[repr(C)]`, two `u32` words.
                let words = unsafe {
                    std::slice::from_raw_parts(params.as_ptr().cast::<u32>(), 2 * params.len())
                };
                let owner = || slf.clone().into_any();
                // SAFETY: the arrays are built once and never change; `slf` owns them.
                Ok(unsafe {
                    (
                        a.kind().name(),
                        view2(a.control_points(), k, owner())?,
                        view2(words, 2, owner())?,
                        view2(a.sharpness(), 1, owner())?,
                    )
                })
            })
            .collect::<PyResult<_>>()?;
        PyList::new(py, parts)
    }

    /// Refined vertices of all levels, then local points, `(n, 3)`: a read-only view of the
    /// table's points (`update` overwrites them in place, so the view follows).
    #[allow(unsafe_code)] // a view without a copy: see the SAFETY note
    fn points<'py>(slf: Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let this = slf.borrow();
        let p = this.table.points();
        // SAFETY: `DVec3` is `#[repr(C)]`, three `f64`; the table keeps this buffer where it
        // is for its life (`set_points` copies into it), and `slf` owns the table.
        unsafe {
            let flat = std::slice::from_raw_parts(p.as_ptr().cast::<f64>(), 3 * p.len());
            view2(flat, 3, slf.clone().into_any())
        }
    }

    /// Vertices of each refined level.
    fn level_vertex_counts(&self) -> Vec<usize> {
        self.table.level_vertex_counts()
    }

    /// The local points' stencils over the refined vertices of all levels, as CSR arrays:
    /// `(indptr, indices, weights, shape)`.
    #[allow(clippy::type_complexity)]
    fn local_point_stencils<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(
        Bound<'py, PyArray1<i64>>,
        Bound<'py, PyArray1<i64>>,
        Bound<'py, PyArray1<f64>>,
        (usize, usize),
    )> {
        let s = self.table.local_point_stencils();
        let (offsets, indices) = (s.offsets(), s.indices());
        Ok((
            filled1(py, offsets.len(), |i| i64::from(offsets[i]))?,
            filled1(py, indices.len(), |i| i64::from(indices[i]))?,
            copied1(py, s.weights())?,
            (s.num_rows(), s.num_sources()),
        ))
    }

    /// The surface at `(faces[i], subs[i], u[i], v[i])`: positions, du, dv and, with
    /// `derivatives`, duu, duv, dvv, each `(m, 3)`.
    #[pyo3(signature = (faces, subs, u, v, derivatives = false))]
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        faces: PyReadonlyArray1<'_, i64>,
        subs: PyReadonlyArray1<'_, i64>,
        u: PyReadonlyArray1<'_, f64>,
        v: PyReadonlyArray1<'_, f64>,
        derivatives: bool,
    ) -> PyResult<Vec<Bound<'py, PyArray2<f64>>>> {
        let at = places(&faces, &subs, &u, &v)?;
        if let Some((gpu, on_device)) = self.device.as_ref().filter(|_| !(derivatives && self.auto))
        {
            if derivatives {
                return Err(PyValueError::new_err(
                    "derivatives=True: second derivatives are evaluated on the CPU (build the table with device=\"cpu\" or \"auto\")",
                ));
            }
            let table = &self.table;
            match py.detach(|| evaluate_on_device(gpu, on_device, table, &at)) {
                Ok(columns) => return columns.iter().map(|c| points(py, c)).collect(),
                Err(subd_gpu::GpuError::Limit(e)) => return Err(mesh_error(e)),
                Err(e) if self.auto => warn(py, &fallback_warning(&e))?,
                Err(e) => return Err(device_error(e)),
            }
        }
        let table = &self.table;
        let columns: Vec<Vec<DVec3>> = pool::run(py, || -> Result<Vec<Vec<DVec3>>, String> {
            use rayon::prelude::*;
            let rows: Vec<[DVec3; 6]> = at
                .par_iter()
                .enumerate()
                .with_min_len(1024)
                .map(|(i, p)| {
                    table
                        .evaluate(*p)
                        .map(|s| [s.position, s.du, s.dv, s.duu, s.duv, s.dvv])
                        .map_err(|e| format!("point {i}: {e}"))
                })
                .collect::<Result<_, _>>()?;
            let kept = if derivatives { 6 } else { 3 };
            Ok((0..kept)
                .map(|k| rows.iter().map(|r| r[k]).collect())
                .collect())
        })?
        .map_err(mesh_error)?;
        columns.iter().map(|c| points(py, c)).collect()
    }

    /// The texture coordinates' face-varying patches, or `None` without them: the mode's
    /// name, the values of each level, per array the values of each patch `(n, k)` and the
    /// values of all levels `(m, 2)`, read-only views of the table's memory.
    #[allow(unsafe_code)] // views without copies: see the SAFETY note
    #[allow(clippy::type_complexity)]
    fn face_varying<'py>(
        slf: Bound<'py, Self>,
    ) -> PyResult<
        Option<(
            &'static str,
            Vec<usize>,
            Vec<Bound<'py, PyArray2<u32>>>,
            Bound<'py, PyArray2<f64>>,
        )>,
    > {
        let this = slf.borrow();
        let Some(fvar) = this.table.face_varying().first() else {
            return Ok(None);
        };
        let owner = || slf.clone().into_any();
        let k = fvar.values_per_patch();
        // SAFETY: the patch values never change after the build; the values are overwritten
        // in place by `update_uv` (never moved); `slf` owns the table.
        unsafe {
            let patches = (0..this.table.arrays().len())
                .map(|a| view2(fvar.array_values(a), k, owner()))
                .collect::<PyResult<Vec<_>>>()?;
            let values = view2(fvar.values(), fvar.components(), owner())?;
            Ok(Some((
                fvar.mode().name(),
                fvar.level_value_counts().to_vec(),
                patches,
                values,
            )))
        }
    }

    /// The texture coordinates at `(faces[i], subs[i], u[i], v[i])` on the face-varying
    /// patches: values, du, dv, each `(m, 2)`.
    fn evaluate_uv<'py>(
        &self,
        py: Python<'py>,
        faces: PyReadonlyArray1<'_, i64>,
        subs: PyReadonlyArray1<'_, i64>,
        u: PyReadonlyArray1<'_, f64>,
        v: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<Vec<Bound<'py, PyArray2<f64>>>> {
        if self.table.face_varying().is_empty() {
            return Err(PyValueError::new_err(
                "the mesh has no texture coordinates: the table has no face-varying patches",
            ));
        }
        let at = places(&faces, &subs, &u, &v)?;
        let table = &self.table;
        let rows: Vec<[f64; 6]> = pool::run(py, || -> Result<Vec<[f64; 6]>, String> {
            use rayon::prelude::*;
            at.par_iter()
                .enumerate()
                .with_min_len(1024)
                .map(|(i, p)| {
                    let t = table
                        .evaluate_face_varying(0, *p)
                        .map_err(|e| format!("point {i}: {e}"))?;
                    Ok([t.value[0], t.value[1], t.du[0], t.du[1], t.dv[0], t.dv[1]])
                })
                .collect()
        })?
        .map_err(mesh_error)?;
        (0..3)
            .map(|k| {
                let flat: Vec<f64> = rows.iter().flat_map(|r| [r[2 * k], r[2 * k + 1]]).collect();
                crate::arrays::flat_rows(py, &flat, 2)
            })
            .collect()
    }

    /// New texture coordinates `(n, 2)` for the same layout: the refined values follow.
    fn update_uv(&mut self, py: Python<'_>, uvs: PyReadonlyArray2<'_, f64>) -> PyResult<()> {
        let Some(fvar) = self.table.face_varying().first() else {
            return Err(PyValueError::new_err(
                "the mesh has no texture coordinates: the table has no face-varying patches",
            ));
        };
        if uvs.shape()[1] != fvar.components() {
            return Err(PyValueError::new_err(format!(
                "uvs: expected an (n, {}) array, got {} columns",
                fvar.components(),
                uvs.shape()[1]
            )));
        }
        let flat = contiguous(&uvs, "uvs")?;
        if let Some(i) = flat.iter().position(|x| !x.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "uvs: row {} is not finite",
                i / fvar.components()
            )));
        }
        // Computed with the GIL released, put in place with it held (see `update`).
        let next = pool::run(py, || fvar.values_for(flat))?.map_err(mesh_error)?;
        self.table
            .set_face_varying_values(0, &next)
            .map_err(mesh_error)
    }

    /// Moves the base vertices: recomputes the refined and local points.
    fn update(&mut self, py: Python<'_>, vertices: PyReadonlyArray2<'_, f64>) -> PyResult<()> {
        if vertices.shape()[1] != 3 {
            return Err(PyValueError::new_err(format!(
                "vertices: expected an (n, 3) array, got {} columns",
                vertices.shape()[1]
            )));
        }
        let flat = contiguous(&vertices, "vertices")?;
        let base: Vec<DVec3> = flat.chunks_exact(3).map(DVec3::from_slice).collect();
        if let Some(i) = base.iter().position(|p| !p.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "vertices: row {i} is not finite"
            )));
        }
        // The points are computed with the GIL released and put in place with it held, so
        // no Python thread reads a view of them while they change.
        let table = &self.table;
        let next = pool::run(py, || table.points_for(&base))?.map_err(mesh_error)?;
        // The device first: where it fails with device="gpu" neither copy has moved.
        if let Some((gpu, on_device)) = &self.device {
            match py.detach(|| on_device.update_points(gpu, &base)) {
                Ok(()) => {}
                Err(e) if self.auto => {
                    warn(py, &fallback_warning(&e))?;
                    self.device = None;
                }
                Err(e) => return Err(device_error(e)),
            }
        }
        self.table.set_points(next);
        Ok(())
    }
}

/// Positions, du and dv at `at` on the device: the places located on the host by the
/// table's patch map, evaluated there, read back as f64.
fn evaluate_on_device(
    gpu: &Gpu,
    on_device: &GpuPatchTable,
    table: &PatchTable,
    at: &[FaceParam],
) -> Result<Vec<Vec<DVec3>>, subd_gpu::GpuError> {
    let coords = on_device.coords(gpu, table, at)?;
    let out = GpuPatchValues::new(gpu, at.len())?;
    on_device.evaluate(gpu, &coords, &out)?;
    [&out.positions, &out.du, &out.dv]
        .into_iter()
        .map(|c| gpu.read_points(c))
        .collect()
}

/// The evaluation places `(faces[i], subs[i], u[i], v[i])`, checked for equal lengths and
/// non-negative indices.
fn places(
    faces: &PyReadonlyArray1<'_, i64>,
    subs: &PyReadonlyArray1<'_, i64>,
    u: &PyReadonlyArray1<'_, f64>,
    v: &PyReadonlyArray1<'_, f64>,
) -> PyResult<Vec<FaceParam>> {
    let (faces, subs) = (contiguous(faces, "faces")?, contiguous(subs, "sub")?);
    let (u, v) = (contiguous(u, "u")?, contiguous(v, "v")?);
    if [subs.len(), u.len(), v.len()]
        .iter()
        .any(|&n| n != faces.len())
    {
        return Err(PyValueError::new_err(
            "faces, sub, u and v need the same length",
        ));
    }
    (0..faces.len())
        .map(|i| {
            let whole = |x: i64, what: &str| {
                usize::try_from(x).map_err(|_| {
                    PyValueError::new_err(format!("point {i}: {what} {x} is negative"))
                })
            };
            Ok(FaceParam {
                face: whole(faces[i], "face")?,
                sub: whole(subs[i], "sub-face")?,
                u: u[i],
                v: v[i],
            })
        })
        .collect::<PyResult<Vec<_>>>()
}
