//! `subd._subd._CoreMesh`: a [`Mesh`] (topology, tags, positions) and, after a refinement
//! to the limit, its normals. The Python class `subd.Mesh` wraps one.

use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use std::sync::{Mutex, MutexGuard, OnceLock, PoisonError, TryLockError};

use pyo3::prelude::*;
use subd_limit::refined_mesh::RefinedMesh;
use subd_mesh::fvar::FVarChannel;
use subd_mesh::{DVec3, Mesh, TopologyBuilder};
use subd_schemes::Scheme;

use crate::arrays::{
    IndexType, columns, contiguous, copied1, filled1, filled2, flat_rows, index, view2,
};
use crate::errors::{io_error, mesh_error};
use crate::pool;

/// A mesh held by the library: what `subd.Mesh` stands on. A refinement's result keeps
/// its last level as faces and positions until something needs the full topology (tags,
/// edges, writing, refining it again): [`CoreMesh::mesh`] builds it then, once.
#[pyclass(name = "_CoreMesh", module = "subd._subd", frozen)]
pub(crate) struct CoreMesh {
    built: OnceLock<Mesh>,
    /// A refinement's result whose topology is not built yet.
    pending: Mutex<Option<RefinedMesh>>,
    /// Unit limit normals, one per vertex, where a refinement to the limit gave them.
    pub(crate) normals: Option<Vec<DVec3>>,
    /// The refinement level of every face of an adaptive result.
    pub(crate) face_levels: Option<Vec<u8>>,
    /// Edges used in the same direction by two faces, as the reader counted them.
    pub(crate) orientation_conflicts: usize,
    /// The USD prim it was read from and its stage's units (kept by what is made from it,
    /// and written back by a USD output).
    pub(crate) stage: Option<subd_io::usd::StageInfo>,
    /// The scheme this mesh is the control cage of, where USD cannot name it (two-phase,
    /// Doo-Sabin, √3, the butterflies): a USD output holds the cage refined instead.
    pub(crate) unnamed_cage: Option<Scheme>,
}

/// The face offsets and texture coordinates of a mesh, built or not.
pub(crate) struct Faces<'a> {
    pub(crate) offsets: &'a [u32],
    /// Texture coordinates: values (two numbers each) and one index per face-vertex.
    pub(crate) uv: Option<(&'a [f64], &'a [u32])>,
}

impl CoreMesh {
    /// A mesh with nothing besides its own data.
    pub(crate) fn plain(mesh: Mesh) -> CoreMesh {
        CoreMesh {
            built: OnceLock::from(mesh),
            pending: Mutex::new(None),
            normals: None,
            face_levels: None,
            orientation_conflicts: 0,
            stage: None,
            unnamed_cage: None,
        }
    }

    /// This mesh, made from `source`: it keeps the USD prim and units `source` was read with.
    pub(crate) fn made_from(mut self, source: &CoreMesh) -> CoreMesh {
        self.stage = source.stage.clone();
        self
    }

    /// This mesh as the control cage of `scheme` (its hints name the scheme where a file can).
    pub(crate) fn cage_of(mut self, scheme: &Scheme) -> CoreMesh {
        self.unnamed_cage = scheme.file_scheme().is_none().then(|| scheme.clone());
        self
    }

    /// A refinement's result, its topology left for later.
    pub(crate) fn refined(mut refined: RefinedMesh) -> CoreMesh {
        CoreMesh {
            built: OnceLock::new(),
            normals: refined.normals.take(),
            pending: Mutex::new(Some(refined)),
            face_levels: None,
            orientation_conflicts: 0,
            stage: None,
            unnamed_cage: None,
        }
    }

    /// The mesh with its full topology, built now (the GIL released) if it is not yet.
    pub(crate) fn mesh(&self, py: Python<'_>) -> PyResult<&Mesh> {
        if let Some(m) = self.built.get() {
            return Ok(m);
        }
        // The lock is taken on this thread, not on the pool: a pool thread waiting for it
        // could starve the pool work of the thread that holds it.
        py.detach(|| -> PyResult<()> {
            let mut pending = self.pending.lock().unwrap_or_else(PoisonError::into_inner);
            // Checked before the result is consumed: a failure inside `into_mesh` would free
            // the positions that `vertices` views may point at (a refinement's faces and
            // texture coordinates are consistent by construction; only its values can fail).
            if let Some(r) = pending.as_ref() {
                subd_mesh::validate_positions(r.positions()).map_err(mesh_error)?;
            }
            if let Some(r) = pending.take() {
                let (mesh, _normals) = pool::install(|| r.into_mesh())?.map_err(mesh_error)?;
                // Set before the lock is released: a reader that finds nothing pending
                // finds the mesh.
                let _ = self.built.set(mesh);
            }
            Ok(())
        })?;
        self.built
            .get()
            .ok_or_else(|| mesh_error("the refined mesh could not be assembled"))
    }

    /// The pending refinement's lock, waited for with the GIL released: a thread holding
    /// the lock may need the GIL (to make an array) before it lets go, so no thread may wait
    /// for the lock while holding the GIL.
    fn lock_pending(&self, py: Python<'_>) -> MutexGuard<'_, Option<RefinedMesh>> {
        loop {
            match self.pending.try_lock() {
                Ok(guard) => return guard,
                Err(TryLockError::Poisoned(p)) => return p.into_inner(),
                Err(TryLockError::WouldBlock) => {
                    py.detach(|| std::thread::sleep(std::time::Duration::from_micros(200)));
                }
            }
        }
    }

    /// `read` applied to what the mesh holds now: the refinement's result where its
    /// topology is not built, else the mesh.
    fn with_held<T>(&self, py: Python<'_>, read: impl FnOnce(Held<'_>) -> T) -> T {
        if let Some(m) = self.built.get() {
            return read(Held::Built(m));
        }
        let pending = self.lock_pending(py);
        match pending.as_ref() {
            Some(r) => read(Held::Pending(r)),
            // Taken by `mesh`, which set the mesh before letting go of the lock.
            None => read(Held::Built(
                self.built
                    .get()
                    .expect("built before the lock was released"),
            )),
        }
    }

    /// `read` applied to the mesh's face offsets and texture coordinates, from the
    /// refinement's result where its topology is not built.
    pub(crate) fn with_faces<T>(&self, py: Python<'_>, read: impl FnOnce(Faces<'_>) -> T) -> T {
        self.with_held(py, |held| match held {
            Held::Pending(r) => read(Faces {
                offsets: r.faces().0,
                uv: r.uv().map(|u| (&u.values[..], &u.indices[..])),
            }),
            Held::Built(m) => read(Faces {
                offsets: m.topology.face_offsets(),
                uv: m.uv().map(|c| (c.values(), c.indices())),
            }),
        })
    }

    /// `read` applied to the positions alone (a refinement's result makes no face list for
    /// them).
    fn with_positions<T>(&self, py: Python<'_>, read: impl FnOnce(&[DVec3]) -> T) -> T {
        self.with_held(py, |held| match held {
            Held::Pending(r) => read(r.positions()),
            Held::Built(m) => read(&m.positions),
        })
    }

    /// Number of faces and, when they all have the same number of corners, that number
    /// (from a refinement's face stream where it has one, without a face list).
    fn face_counts(&self, py: Python<'_>) -> (usize, Option<usize>) {
        fn of_offsets(offsets: &[u32]) -> (usize, Option<usize>) {
            let mut sizes = offsets.windows(2).map(|w| w[1] - w[0]);
            let k = sizes.next().unwrap_or(3);
            let uniform = sizes.all(|s| s == k).then_some(k as usize);
            (offsets.len() - 1, uniform)
        }
        self.with_held(py, |held| match held {
            Held::Pending(r) => match r.face_stream() {
                Some(s) => (s.num_faces(), Some(s.face_size())),
                None => of_offsets(r.faces().0),
            },
            Held::Built(m) => of_offsets(m.topology.face_offsets()),
        })
    }
}

/// What a mesh holds: a refinement's result whose topology is not built yet, or the mesh.
enum Held<'a> {
    Pending(&'a RefinedMesh),
    Built(&'a Mesh),
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
    /// Texture coordinates (two numbers each) and one index per face-vertex, if given.
    uv: Option<(&'a [f64], &'a [i64])>,
    /// Whether an edge two faces use in the same direction is taken (as OpenSubdiv does,
    /// making it non-manifold) rather than refused.
    accept_inconsistent_orientation: bool,
}

impl Arrays<'_> {
    /// The mesh, every index and value checked, each problem named by its element.
    fn build(&self) -> Result<Mesh, String> {
        let nv = self.vertices.len() / 3;
        let sizes = self.face_sizes()?;
        let corners = self.corners(&sizes, nv)?;
        let mut topology = TopologyBuilder::new(nv)
            .accept_inconsistent_orientation(self.accept_inconsistent_orientation)
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
        let mut mesh = Mesh::new(topology, positions).map_err(|e| e.to_string())?;
        if let Some((values, indices)) = self.uv {
            mesh.fvar.push(uv_channel(&mesh, values, indices)?);
        }
        Ok(mesh)
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

/// Texture coordinates as the mesh's face-varying channel: every value finite, one index
/// per face-vertex, each naming a value.
fn uv_channel(mesh: &Mesh, values: &[f64], indices: &[i64]) -> Result<FVarChannel, String> {
    let t = &mesh.topology;
    if indices.len() != t.num_face_vertices() {
        return Err(format!(
            "uv_indices: {} given, one per face corner ({}) needed",
            indices.len(),
            t.num_face_vertices()
        ));
    }
    if let Some(i) = values.iter().position(|x| !x.is_finite()) {
        return Err(format!("uv {}: non-finite coordinate", i / 2));
    }
    let nuv = values.len() / 2;
    let mut checked = Vec::with_capacity(indices.len());
    for f in 0..t.num_faces() {
        let start = t.face_offsets()[f] as usize;
        for (c, &i) in indices[start..start + t.face_size(f)].iter().enumerate() {
            match u32::try_from(i) {
                Ok(x) if (x as usize) < nuv => checked.push(x),
                _ => {
                    return Err(format!(
                        "face {f} corner {c}: uv index {i} out of range (there are {nuv} uvs)"
                    ));
                }
            }
        }
    }
    FVarChannel::new(t, 2, values.to_vec(), checked).map_err(|e| e.to_string())
}

#[pymethods]
impl CoreMesh {
    /// A mesh from flat arrays (see `subd.Mesh`, which builds them from what a user has).
    #[new]
    #[pyo3(signature = (vertices, face_sizes, face_vertices, crease_edges, crease_sharpness, corner_vertices, corner_sharpness, holes, uvs = None, uv_indices = None, accept_inconsistent_orientation = false))]
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
        uvs: Option<PyReadonlyArray2<'_, f64>>,
        uv_indices: Option<PyReadonlyArray1<'_, i64>>,
        accept_inconsistent_orientation: bool,
    ) -> PyResult<CoreMesh> {
        let uv = match (&uvs, &uv_indices) {
            (Some(u), Some(i)) => Some((columns(u, 2, "uvs")?, contiguous(i, "uv_indices")?)),
            (None, None) => None,
            _ => return Err(mesh_error("uvs and uv_indices come together")),
        };
        let arrays = Arrays {
            vertices: columns(&vertices, 3, "vertices")?,
            face_sizes: contiguous(&face_sizes, "face sizes")?,
            face_vertices: contiguous(&face_vertices, "face vertices")?,
            crease_edges: columns(&crease_edges, 2, "crease edges")?,
            crease_sharpness: contiguous(&crease_sharpness, "crease sharpness")?,
            corner_vertices: contiguous(&corner_vertices, "corner vertices")?,
            corner_sharpness: contiguous(&corner_sharpness, "corner sharpness")?,
            holes: contiguous(&holes, "holes")?,
            uv,
            accept_inconsistent_orientation,
        };
        if arrays.crease_edges.len() / 2 != arrays.crease_sharpness.len()
            || arrays.corner_vertices.len() != arrays.corner_sharpness.len()
        {
            return Err(mesh_error(
                "each crease and each corner needs one sharpness",
            ));
        }
        let mesh = pool::run(py, || arrays.build())?.map_err(mesh_error)?;
        Ok(CoreMesh::plain(mesh))
    }

    /// Vertex positions, `(n, 3)` float64: a read-only view of the mesh's own buffer (no
    /// copy; the array keeps the mesh alive).
    #[getter]
    fn vertices<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let owner = slf.clone().into_any();
        slf.get().with_positions(slf.py(), |positions| {
            // SAFETY: the positions are this mesh's, never changed nor freed while it lives:
            // a built mesh is never changed (the class is frozen) and building a pending one
            // moves the buffer into it (`RefinedMesh::into_mesh`).
            #[allow(unsafe_code)]
            unsafe {
                view2(bytemuck::cast_slice::<DVec3, f64>(positions), 3, owner)
            }
        })
    }

    /// Unit limit normals, `(n, 3)` float64 (a read-only view, as `vertices`), or `None`.
    #[getter]
    fn normals<'py>(slf: &Bound<'py, Self>) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
        let owner = slf.clone().into_any();
        slf.get()
            .normals
            .as_deref()
            // SAFETY: the normals are a field of this frozen mesh, set once when it was made.
            .map(|n| {
                #[allow(unsafe_code)]
                unsafe {
                    view2(bytemuck::cast_slice::<DVec3, f64>(n), 3, owner)
                }
            })
            .transpose()
    }

    /// Number of corners of every face, `(m,)` int64.
    #[getter]
    fn face_sizes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<i64>>> {
        if let (n, Some(k)) = self.face_counts(py) {
            return filled1(py, n, |_| k as i64);
        }
        self.with_faces(py, |f| {
            let offsets = f.offsets;
            filled1(py, offsets.len() - 1, |i| {
                i64::from(offsets[i + 1] - offsets[i])
            })
        })
    }

    /// Vertex indices of every face, one face after the other, in `index_dtype` (`"int64"`,
    /// `"int32"` or `"uint32"`), read-only.
    fn face_vertices<'py>(
        &self,
        py: Python<'py>,
        index_dtype: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let ty = IndexType::named(index_dtype)?;
        ty.check_holds(self.num_vertices(py))?;
        self.with_held(py, |held| match held {
            Held::Pending(r) => match r.face_stream() {
                Some(stream) => ty.faces(py, &stream),
                None => ty.copied(py, r.faces().1),
            },
            Held::Built(m) => ty.copied(py, m.topology.all_face_vertices()),
        })
    }

    /// The number of corners every face has, or `None` when faces differ.
    fn uniform_face_size(&self, py: Python<'_>) -> Option<usize> {
        self.face_counts(py).1
    }

    /// Texture coordinates, `(u, 2)` float64, or `None`.
    #[getter]
    fn uvs<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
        self.with_faces(py, |f| {
            f.uv.map(|(values, _)| flat_rows(py, values, 2)).transpose()
        })
    }

    /// One texture-coordinate index per face-vertex in `index_dtype`, or `None`.
    fn uv_indices<'py>(
        &self,
        py: Python<'py>,
        index_dtype: &str,
    ) -> PyResult<Option<Bound<'py, PyAny>>> {
        let ty = IndexType::named(index_dtype)?;
        self.with_faces(py, |f| {
            f.uv.map(|(values, x)| {
                ty.check_holds(values.len() / 2)?;
                ty.copied(py, x)
            })
            .transpose()
        })
    }

    /// The refinement level of every face (adaptive results), uint8, or `None`.
    #[getter]
    fn face_levels<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray1<u8>>>> {
        self.face_levels
            .as_deref()
            .map(|l| copied1(py, l))
            .transpose()
    }

    /// Edges used in the same direction by two faces, as the reader counted them.
    #[getter]
    fn orientation_conflicts(&self) -> usize {
        self.orientation_conflicts
    }

    /// Creases: `(edges (k, 2) int64, sharpness (k,) float64)`, edges with sharpness > 0.
    #[getter]
    #[allow(clippy::type_complexity)]
    fn creases<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyArray2<i64>>, Bound<'py, PyArray1<f64>>)> {
        let t = &self.mesh(py)?.topology;
        let creased: Vec<usize> = (0..t.num_edges())
            .filter(|&e| t.edge_sharpness(e) > 0.0)
            .collect();
        let edges = filled2(py, creased.len(), |i, r: &mut [i64; 2]| {
            *r = t.edge_vertices(creased[i]).map(i64::from)
        })?;
        let s: Vec<f64> = creased
            .iter()
            .map(|&e| f64::from(t.edge_sharpness(e)))
            .collect();
        Ok((edges, copied1(py, &s)?))
    }

    /// Corners: `(vertices (c,) int64, sharpness (c,) float64)`, vertices with sharpness > 0.
    #[getter]
    #[allow(clippy::type_complexity)]
    fn corners<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<f64>>)> {
        let t = &self.mesh(py)?.topology;
        let tagged: Vec<usize> = (0..t.num_vertices())
            .filter(|&v| t.vertex_sharpness(v) > 0.0)
            .collect();
        let v: Vec<i64> = tagged.iter().map(|&v| v as i64).collect();
        let s: Vec<f64> = tagged
            .iter()
            .map(|&v| f64::from(t.vertex_sharpness(v)))
            .collect();
        Ok((copied1(py, &v)?, copied1(py, &s)?))
    }

    /// Indices of the faces that are holes, int64.
    #[getter]
    fn holes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<i64>>> {
        // A refinement's result names its holes from the level above, without its topology.
        let streamed = self.with_held(py, |held| match held {
            Held::Pending(r) => r.face_stream().map(|s| s.hole_faces()),
            Held::Built(_) => None,
        });
        let h: Vec<i64> = match streamed {
            Some(faces) => faces.into_iter().map(|f| f as i64).collect(),
            None => {
                let t = &self.mesh(py)?.topology;
                (0..t.num_faces())
                    .filter(|&f| t.is_hole(f))
                    .map(|f| f as i64)
                    .collect()
            }
        };
        copied1(py, &h)
    }

    /// Number of vertices.
    #[getter]
    fn num_vertices(&self, py: Python<'_>) -> usize {
        self.with_positions(py, <[DVec3]>::len)
    }

    /// Number of faces.
    #[getter]
    fn num_faces(&self, py: Python<'_>) -> usize {
        self.face_counts(py).0
    }

    /// Number of edges.
    #[getter]
    fn num_edges(&self, py: Python<'_>) -> PyResult<usize> {
        Ok(self.mesh(py)?.topology.num_edges())
    }

    /// The USD prim the mesh (or the mesh it was made from) was read from, and its stage's
    /// units: `(prim path, metersPerUnit or None, upAxis or None)`, or None for other files.
    #[getter]
    fn stage(&self) -> Option<(String, Option<f64>, Option<String>)> {
        self.stage
            .as_ref()
            .map(|s| (s.prim.clone(), s.meters_per_unit, s.up_axis.clone()))
    }

    /// The scheme the file names for the mesh (USD's `subdivisionScheme`: `catmull-clark`,
    /// `loop`, `bilinear`, or `none` for plain polygons), or None when it names none.
    #[getter]
    fn file_scheme(&self, py: Python<'_>) -> PyResult<Option<&'static str>> {
        use subd_mesh::FileScheme;
        Ok(self.mesh(py)?.hints.scheme.map(|s| match s {
            FileScheme::CatmullClark => "catmull-clark",
            FileScheme::Loop => "loop",
            FileScheme::Bilinear => "bilinear",
            FileScheme::Polygons => "none",
        }))
    }

    /// Writes the mesh (OBJ with crease tags, PLY, glTF binary, USD by the extension), with
    /// its normals where it has them. The file appears whole or not at all. Returns the
    /// warnings: a USD file holds the cage of a scheme it cannot name refined, and says so.
    fn write(&self, py: Python<'_>, path: std::path::PathBuf) -> PyResult<Vec<String>> {
        let options = subd_io::WriteOptions {
            stage: self.stage.clone(),
            ..subd_io::WriteOptions::default()
        };
        let mesh = self.mesh(py)?;
        let usd = subd_io::Format::for_output(&path).is_some_and(subd_io::Format::is_usd);
        if let (Some(scheme), true) = (&self.unnamed_cage, usd) {
            return pool::run(py, || write_unnamed_cage(&path, mesh, scheme, &options))?;
        }
        pool::run(py, || match &self.normals {
            None => subd_io::write_mesh(&path, mesh, &options),
            Some(n) => {
                let view = subd_io::MeshView::from_mesh(mesh)
                    .with_normals(n)
                    .map_err(|e| subd_io::IoError::Invalid {
                        path: path.clone(),
                        message: e.to_string(),
                    })?;
                subd_io::write_view(&path, &view, &options)
            }
        })?
        .map_err(io_error)?;
        Ok(Vec::new())
    }
}

/// Writes `cage`, the control cage of `scheme`, which USD cannot name: refined to plain
/// polygons, as `subd pia` writes it; the warnings say so and what was left out.
fn write_unnamed_cage(
    path: &std::path::Path,
    cage: &Mesh,
    scheme: &Scheme,
    options: &subd_io::WriteOptions,
) -> PyResult<Vec<String>> {
    let (refined, left_out) = subd_limit::refined_mesh::refined_unnamed_cage(cage, scheme)
        .map_err(|e| mesh_error(e.to_string()))?;
    subd_io::write_mesh(path, &refined, options).map_err(io_error)?;
    let mut warnings = vec![format!(
        "{}: {}",
        path.display(),
        subd_limit::refined_mesh::unnamed_cage_warning(scheme)
    )];
    warnings.extend(left_out);
    Ok(warnings)
}
