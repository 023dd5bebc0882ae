//! `subd._subd._CoreMesh`: a [`Mesh`] (topology, tags, positions) and, after a refinement
//! to the limit, its normals. The Python class `subd.Mesh` wraps one.

use numpy::ndarray::Array2;
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use subd_mesh::{DVec3, Mesh, TopologyBuilder};

use crate::errors::{io_error, mesh_error};
use crate::pool;

/// A mesh held by the library: what `subd.Mesh` stands on.
#[pyclass(name = "_CoreMesh", module = "subd._subd", frozen)]
pub(crate) struct CoreMesh {
    pub(crate) mesh: Mesh,
    /// Unit limit normals, one per vertex, where a refinement to the limit gave them.
    pub(crate) normals: Option<Vec<DVec3>>,
}

/// The arrays a mesh is made of, as the Python layer passes them (C-contiguous, exact
/// dtypes; shapes and lengths checked there and again here).
struct Arrays<'a> {
    vertices: &'a [f64],
    face_sizes: &'a [i64],
    face_vertices: &'a [i64],
    crease_edges: &'a [i64],
    crease_sharpness: &'a [f64],
    corner_vertices: &'a [i64],
    corner_sharpness: &'a [f64],
    holes: &'a [i64],
}

impl Arrays<'_> {
    /// The mesh, every index and value checked, each problem named by its element.
    fn build(&self) -> Result<Mesh, String> {
        let nv = self.vertices.len() / 3;
        let sizes = self.face_sizes()?;
        let corners = self.corners(&sizes, nv)?;
        let mut topology = TopologyBuilder::new(nv)
            .build(&sizes, &corners)
            .map_err(|e| e.to_string())?;
        for (k, (pair, &s)) in self
            .crease_edges
            .chunks_exact(2)
            .zip(self.crease_sharpness)
            .enumerate()
        {
            let a = index(pair[0]).map_err(|e| format!("crease {k}: {e}"))?;
            let b = index(pair[1]).map_err(|e| format!("crease {k}: {e}"))?;
            match topology.set_crease(a, b, s) {
                Ok(Some(_)) => {}
                Ok(None) => {
                    return Err(format!("crease {k}: no edge joins vertices {a} and {b}"));
                }
                Err(e) => return Err(format!("crease {k}: {e}")),
            }
        }
        for (k, (&v, &s)) in self
            .corner_vertices
            .iter()
            .zip(self.corner_sharpness)
            .enumerate()
        {
            let v = index(v).map_err(|e| format!("corner {k}: {e}"))?;
            topology
                .set_corner(v, s)
                .map_err(|e| format!("corner {k}: {e}"))?;
        }
        for (k, &f) in self.holes.iter().enumerate() {
            let f = index(f).map_err(|e| format!("hole {k}: {e}"))?;
            topology
                .set_hole_checked(f)
                .map_err(|e| format!("hole {k}: {e}"))?;
        }
        let positions = self
            .vertices
            .chunks_exact(3)
            .map(|c| DVec3::new(c[0], c[1], c[2]))
            .collect();
        Mesh::new(topology, positions).map_err(|e| e.to_string())
    }

    /// Face sizes as `u32`, each from 3 to the largest size a face may have.
    fn face_sizes(&self) -> Result<Vec<u32>, String> {
        let total: i128 = self.face_sizes.iter().map(|&s| i128::from(s)).sum();
        if total != self.face_vertices.len() as i128 {
            return Err(format!(
                "the face sizes add up to {total}, but {} face-vertex indices were given",
                self.face_vertices.len()
            ));
        }
        self.face_sizes
            .iter()
            .enumerate()
            .map(|(f, &s)| {
                u32::try_from(s)
                    .ok()
                    .filter(|&s| (3..=subd_mesh::MAX_FACE_SIZE as u32).contains(&s))
                    .ok_or_else(|| {
                        format!(
                            "face {f} has {s} corners (3 to {} allowed)",
                            subd_mesh::MAX_FACE_SIZE
                        )
                    })
            })
            .collect()
    }

    /// Face-vertex indices as `u32`, each checked against the `nv` vertices.
    fn corners(&self, sizes: &[u32], nv: usize) -> Result<Vec<u32>, String> {
        let mut out = Vec::with_capacity(self.face_vertices.len());
        let mut next = self.face_vertices.iter();
        for (f, &size) in sizes.iter().enumerate() {
            for c in 0..size {
                let &i = next
                    .next()
                    .ok_or("fewer face-vertex indices than corners")?;
                match u32::try_from(i) {
                    Ok(v) if (v as usize) < nv => out.push(v),
                    _ => {
                        return Err(format!(
                            "face {f} corner {c}: vertex index {i} out of range (the mesh has {nv} vertices)"
                        ));
                    }
                }
            }
        }
        Ok(out)
    }
}

/// A tag's index, refused (named) when negative; the library checks the upper bound.
fn index(i: i64) -> Result<u64, String> {
    u64::try_from(i).map_err(|_| format!("index {i} is negative"))
}

/// `values` as a C-contiguous numpy array of `n` rows of `K` numbers, owned by numpy.
pub(crate) fn rows<'py, const K: usize, T: numpy::Element + Copy>(
    py: Python<'py>,
    values: impl Iterator<Item = [T; K]>,
) -> PyResult<Bound<'py, PyArray2<T>>> {
    let flat: Vec<T> = values.flat_map(|r| r.into_iter()).collect();
    let n = flat.len() / K;
    Array2::from_shape_vec((n, K), flat)
        .map(|a| a.into_pyarray(py))
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Points as an `(n, 3)` float64 array.
pub(crate) fn points<'py>(py: Python<'py>, p: &[DVec3]) -> PyResult<Bound<'py, PyArray2<f64>>> {
    rows(py, p.iter().map(|v| v.to_array()))
}

/// A slice of a contiguous array, or a `ValueError` naming the argument.
fn slice<'a, T: numpy::Element>(a: &'a PyReadonlyArray1<'_, T>, what: &str) -> PyResult<&'a [T]> {
    a.as_slice()
        .map_err(|_| PyValueError::new_err(format!("{what}: a C-contiguous array is needed")))
}

/// A slice of a contiguous 2-D array of `k` columns.
fn slice2<'a, T: numpy::Element>(
    a: &'a PyReadonlyArray2<'_, T>,
    k: usize,
    what: &str,
) -> PyResult<&'a [T]> {
    if a.shape()[1] != k {
        return Err(PyValueError::new_err(format!(
            "{what}: shape {:?}, expected (n, {k})",
            a.shape()
        )));
    }
    a.as_slice()
        .map_err(|_| PyValueError::new_err(format!("{what}: a C-contiguous array is needed")))
}

#[pymethods]
impl CoreMesh {
    /// A mesh from flat arrays (see `subd.Mesh`, which builds them from what a user has).
    #[new]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        vertices: PyReadonlyArray2<'_, f64>,
        face_sizes: PyReadonlyArray1<'_, i64>,
        face_vertices: PyReadonlyArray1<'_, i64>,
        crease_edges: PyReadonlyArray2<'_, i64>,
        crease_sharpness: PyReadonlyArray1<'_, f64>,
        corner_vertices: PyReadonlyArray1<'_, i64>,
        corner_sharpness: PyReadonlyArray1<'_, f64>,
        holes: PyReadonlyArray1<'_, i64>,
    ) -> PyResult<CoreMesh> {
        let arrays = Arrays {
            vertices: slice2(&vertices, 3, "vertices")?,
            face_sizes: slice(&face_sizes, "face sizes")?,
            face_vertices: slice(&face_vertices, "face vertices")?,
            crease_edges: slice2(&crease_edges, 2, "crease edges")?,
            crease_sharpness: slice(&crease_sharpness, "crease sharpness")?,
            corner_vertices: slice(&corner_vertices, "corner vertices")?,
            corner_sharpness: slice(&corner_sharpness, "corner sharpness")?,
            holes: slice(&holes, "holes")?,
        };
        if arrays.crease_edges.len() / 2 != arrays.crease_sharpness.len()
            || arrays.corner_vertices.len() != arrays.corner_sharpness.len()
        {
            return Err(mesh_error(
                "each crease and each corner needs one sharpness",
            ));
        }
        let mesh = pool::run(py, || arrays.build())?.map_err(mesh_error)?;
        Ok(CoreMesh {
            mesh,
            normals: None,
        })
    }

    /// Vertex positions, `(n, 3)` float64.
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        points(py, &self.mesh.positions)
    }

    /// Unit limit normals, `(n, 3)` float64, or `None`.
    #[getter]
    fn normals<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
        self.normals.as_deref().map(|n| points(py, n)).transpose()
    }

    /// Number of corners of every face, `(m,)` int64.
    #[getter]
    fn face_sizes<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let t = &self.mesh.topology;
        let sizes: Vec<i64> = t.face_sizes().map(i64::from).collect();
        sizes.into_pyarray(py)
    }

    /// Vertex indices of every face, one face after the other, int64.
    #[getter]
    fn face_vertices<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let fv = self.mesh.topology.all_face_vertices();
        let v: Vec<i64> = fv.iter().map(|&i| i64::from(i)).collect();
        v.into_pyarray(py)
    }

    /// Creases: `(edges (k, 2) int64, sharpness (k,) float64)`, edges with sharpness > 0.
    #[getter]
    #[allow(clippy::type_complexity)]
    fn creases<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyArray2<i64>>, Bound<'py, PyArray1<f64>>)> {
        let t = &self.mesh.topology;
        let creased: Vec<usize> = (0..t.num_edges())
            .filter(|&e| t.edge_sharpness(e) > 0.0)
            .collect();
        let edges = rows(
            py,
            creased.iter().map(|&e| t.edge_vertices(e).map(i64::from)),
        )?;
        let s: Vec<f64> = creased
            .iter()
            .map(|&e| f64::from(t.edge_sharpness(e)))
            .collect();
        Ok((edges, s.into_pyarray(py)))
    }

    /// Corners: `(vertices (c,) int64, sharpness (c,) float64)`, vertices with sharpness > 0.
    #[getter]
    fn corners<'py>(
        &self,
        py: Python<'py>,
    ) -> (Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<f64>>) {
        let t = &self.mesh.topology;
        let tagged: Vec<usize> = (0..t.num_vertices())
            .filter(|&v| t.vertex_sharpness(v) > 0.0)
            .collect();
        let v: Vec<i64> = tagged.iter().map(|&v| v as i64).collect();
        let s: Vec<f64> = tagged
            .iter()
            .map(|&v| f64::from(t.vertex_sharpness(v)))
            .collect();
        (v.into_pyarray(py), s.into_pyarray(py))
    }

    /// Indices of the faces that are holes, int64.
    #[getter]
    fn holes<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let t = &self.mesh.topology;
        let h: Vec<i64> = (0..t.num_faces())
            .filter(|&f| t.is_hole(f))
            .map(|f| f as i64)
            .collect();
        h.into_pyarray(py)
    }

    /// Number of vertices.
    #[getter]
    fn num_vertices(&self) -> usize {
        self.mesh.topology.num_vertices()
    }

    /// Number of faces.
    #[getter]
    fn num_faces(&self) -> usize {
        self.mesh.topology.num_faces()
    }

    /// Number of edges.
    #[getter]
    fn num_edges(&self) -> usize {
        self.mesh.topology.num_edges()
    }

    /// Writes the mesh (OBJ with crease tags, PLY, glTF binary by the extension), with its
    /// normals where it has them. The file appears whole or not at all.
    fn write(&self, py: Python<'_>, path: std::path::PathBuf) -> PyResult<()> {
        let options = subd_io::WriteOptions::default();
        pool::run(py, || match &self.normals {
            None => subd_io::write_mesh(&path, &self.mesh, &options),
            Some(n) => {
                let view = subd_io::MeshView::from_mesh(&self.mesh)
                    .with_normals(n)
                    .map_err(|e| subd_io::IoError::Invalid {
                        path: path.clone(),
                        message: e.to_string(),
                    })?;
                subd_io::write_view(&path, &view, &options)
            }
        })?
        .map_err(io_error)
    }
}
