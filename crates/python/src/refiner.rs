//! `subd._subd._CoreRefiner`: a mesh's topology refined once, applied to any number of
//! position sets (animation frames) or other per-vertex columns, on the CPU or the GPU,
//! and its stencils as a sparse matrix.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use subd_gpu::{Gpu, GpuError, GpuRefiner, LevelTables};

use numpy::{PyArray1, PyArray2, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use subd_mesh::DVec3;
use subd_schemes::Refinement;

use crate::arrays::{contiguous, copied1, filled1, flat_rows, points};
use crate::device::{choose, device_error, fallback_warning};
use crate::errors::{mesh_error, warn};
use crate::mesh::CoreMesh;
use crate::ops::{RuleNames, request};
use crate::pool;

/// A refinement of one mesh's topology, `levels` deep.
#[pyclass(name = "_CoreRefiner", module = "subd._subd", frozen)]
pub(crate) struct CoreRefiner {
    refinement: Refinement,
    levels: usize,
    /// The GPU and its refiners by column count, where the refiner runs there.
    device: Option<DeviceRefiners>,
    /// Why `device="auto"` runs on the CPU.
    device_warning: Option<String>,
    /// `device="auto"`: a failure on the GPU falls back to the CPU with a warning.
    auto: bool,
}

/// The level stencils on the device, one refiner per column count (made on first use),
/// each used by one call at a time: its buffers hold that call's values until read back.
struct DeviceRefiners {
    gpu: Arc<Gpu>,
    by_width: Mutex<HashMap<usize, Arc<Mutex<GpuRefiner>>>>,
}

impl DeviceRefiners {
    /// `values` (rows of `k`) refined to the last level on the device, as f64.
    fn apply(
        &self,
        refinement: &Refinement,
        values: &[f64],
        k: usize,
    ) -> Result<Vec<f64>, GpuError> {
        let refiner = {
            let mut held = self.by_width.lock().unwrap_or_else(|e| e.into_inner());
            match held.get(&k) {
                Some(r) => Arc::clone(r),
                None => {
                    let r = GpuRefiner::new(&self.gpu, refinement, k, LevelTables::PerLevel)?;
                    Arc::clone(held.entry(k).or_insert(Arc::new(Mutex::new(r))))
                }
            }
        };
        let as_f32: Vec<f32> = values.iter().map(|&x| x as f32).collect();
        // Held from the write to the read-back: another thread's values would overwrite them.
        let refiner = refiner.lock().unwrap_or_else(|e| e.into_inner());
        refiner.update(&self.gpu, &as_f32)?;
        let out = self.gpu.read_columns(refiner.last())?;
        Ok(out.into_iter().map(f64::from).collect())
    }
}

#[pymethods]
impl CoreRefiner {
    /// Refines `mesh`'s topology `levels` times with `scheme_name` and the rule options;
    /// `apply` runs on `device` ("cpu", "gpu" or "auto").
    #[new]
    #[pyo3(signature = (mesh, scheme_name, levels, boundary = None, crease_method = None, triangles = None, device = "cpu"))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        mesh: &CoreMesh,
        scheme_name: &str,
        levels: usize,
        boundary: Option<&str>,
        crease_method: Option<&str>,
        triangles: Option<&str>,
        device: &str,
    ) -> PyResult<CoreRefiner> {
        let device_name = device;
        let (gpu, device_warning) = choose(device)?;
        let rules = RuleNames {
            boundary,
            crease_method,
            triangles,
            fvar_interpolation: None,
        };
        let base = mesh.mesh(py)?;
        let (scheme, options) = request(base, scheme_name, levels, &rules)?;
        let topology = &base.topology;
        let refinement = pool::run(py, || Refinement::new(topology, scheme, &options, levels))?
            .map_err(mesh_error)?;
        let device = gpu.map(|gpu| DeviceRefiners {
            gpu,
            by_width: Mutex::new(HashMap::new()),
        });
        Ok(CoreRefiner {
            refinement,
            levels,
            device,
            device_warning,
            auto: device_name == "auto",
        })
    }

    /// Where `apply` runs: "gpu" or "cpu".
    #[getter]
    fn device(&self) -> &'static str {
        if self.device.is_some() { "gpu" } else { "cpu" }
    }

    /// Why `device="auto"` runs on the CPU, if it does.
    #[getter]
    fn device_warning(&self) -> Option<String> {
        self.device_warning.clone()
    }

    /// Number of vertices of the base level.
    #[getter]
    fn num_base_vertices(&self) -> usize {
        self.refinement.num_vertices(0)
    }

    /// Number of vertices of the last level.
    #[getter]
    fn num_vertices(&self) -> usize {
        self.refinement.num_vertices(self.levels)
    }

    /// Per-vertex values of the base level, `(n, k)` float64, refined to the last level:
    /// `(n_L, k)`. Three columns take the positions' own path (`subd.refine`'s numbers).
    fn apply<'py>(
        &self,
        py: Python<'py>,
        values: PyReadonlyArray2<'_, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (n, k) = (values.shape()[0], values.shape()[1]);
        if n != self.refinement.num_vertices(0) {
            return Err(PyValueError::new_err(format!(
                "{n} rows given; the base mesh has {} vertices",
                self.refinement.num_vertices(0)
            )));
        }
        let src = contiguous(&values, "values")?;
        if let Some(device) = &self.device {
            let refinement = &self.refinement;
            match py.detach(|| device.apply(refinement, src, k)) {
                Ok(out) => return flat_rows(py, &out, k),
                Err(e) if self.auto => warn(py, &fallback_warning(&e))?,
                Err(e) => return Err(device_error(e)),
            }
        }
        if k == 3 {
            let base: Vec<DVec3> = src.chunks_exact(3).map(DVec3::from_slice).collect();
            let out = pool::run(py, || self.refinement.points_at(&base, self.levels))?;
            return points(py, &out);
        }
        let out = pool::run(py, || {
            let mut level = src.to_vec();
            for l in 1..=self.levels {
                let table = self.refinement.stencils(l);
                let mut next = vec![0.0; table.num_rows() * k];
                table.apply(&level, k, &mut next);
                level = next;
            }
            level
        })?;
        flat_rows(py, &out, k)
    }

    /// The stencils from the base vertices to the vertices of `level` (the last when
    /// `None`) as CSR arrays: `(indptr, indices, weights, shape)`.
    #[pyo3(signature = (level = None))]
    #[allow(clippy::type_complexity)]
    fn stencil_matrix<'py>(
        &self,
        py: Python<'py>,
        level: Option<usize>,
    ) -> PyResult<(
        Bound<'py, PyArray1<i64>>,
        Bound<'py, PyArray1<i64>>,
        Bound<'py, PyArray1<f64>>,
        (usize, usize),
    )> {
        let level = level.unwrap_or(self.levels);
        if level > self.levels {
            return Err(PyValueError::new_err(format!(
                "level {level}: the refiner has levels 0 to {}",
                self.levels
            )));
        }
        let table = pool::run(py, || self.refinement.composed(level))?;
        let (offsets, indices) = (table.offsets(), table.indices());
        let shape = (table.num_rows(), self.refinement.num_vertices(0));
        Ok((
            filled1(py, offsets.len(), |i| i64::from(offsets[i]))?,
            filled1(py, indices.len(), |i| i64::from(indices[i]))?,
            copied1(py, table.weights())?,
            shape,
        ))
    }
}
