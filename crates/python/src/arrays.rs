//! Arrays handed to Python. Where the library's buffer has numpy's type (positions,
//! normals) the array is a read-only view of it that keeps its mesh alive ([`view2`]);
//! otherwise it is allocated by numpy (owning its data) and filled in place, in parallel on
//! the package's pool with the GIL released, the values converted once with no
//! intermediate vector (indices in the [`IndexType`] asked for).

use numpy::ndarray::Dimension;
use numpy::{
    Element, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray, PyReadonlyArray2,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;
use subd_mesh::DVec3;

use crate::pool;

/// Rows per parallel task when filling (enough work per task to pay for the split).
const CHUNK_ROWS: usize = 1 << 14;

/// A new zeroed `(n, K)` array, C-contiguous and owned by numpy, with `fill` writing its
/// rows (`K` numbers each) on the pool.
pub(crate) fn filled2<'py, T, const K: usize>(
    py: Python<'py>,
    n: usize,
    fill: impl Fn(usize, &mut [T; K]) + Sync + Send,
) -> PyResult<Bound<'py, PyArray2<T>>>
where
    T: Element + Copy + Send + Sync,
{
    let array = PyArray2::<T>::zeros(py, [n, K], false);
    {
        let mut rw = array.readwrite();
        let out = rw.as_slice_mut().expect("a new array is contiguous");
        pool::run(py, || {
            out.par_chunks_mut(K * CHUNK_ROWS)
                .enumerate()
                .for_each(|(c, chunk)| {
                    for (i, row) in chunk.chunks_exact_mut(K).enumerate() {
                        let row: &mut [T; K] = row.try_into().expect("K numbers");
                        fill(c * CHUNK_ROWS + i, row);
                    }
                });
        })?;
    }
    Ok(array)
}

/// A new zeroed `(n,)` array owned by numpy, `fill` writing its values on the pool.
pub(crate) fn filled1<'py, T>(
    py: Python<'py>,
    n: usize,
    fill: impl Fn(usize) -> T + Sync + Send,
) -> PyResult<Bound<'py, PyArray1<T>>>
where
    T: Element + Copy + Send + Sync,
{
    let array = PyArray1::<T>::zeros(py, n, false);
    {
        let mut rw = array.readwrite();
        fill_values(
            py,
            rw.as_slice_mut().expect("a new array is contiguous"),
            fill,
        )?;
    }
    Ok(array)
}

/// `out[i] = fill(i)` for every `i`, on the pool.
fn fill_values<T: Send>(
    py: Python<'_>,
    out: &mut [T],
    fill: impl Fn(usize) -> T + Sync + Send,
) -> PyResult<()> {
    const CHUNK: usize = 4 * CHUNK_ROWS;
    pool::run(py, || {
        out.par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(c, chunk)| {
                for (i, x) in chunk.iter_mut().enumerate() {
                    *x = fill(c * CHUNK + i);
                }
            });
    })
}

/// Points as an `(n, 3)` float64 array.
pub(crate) fn points<'py>(py: Python<'py>, p: &[DVec3]) -> PyResult<Bound<'py, PyArray2<f64>>> {
    filled2(py, p.len(), |i, row: &mut [f64; 3]| *row = p[i].to_array())
}

/// A copy of `values` as a 1-D array.
pub(crate) fn copied1<'py, T>(py: Python<'py>, values: &[T]) -> PyResult<Bound<'py, PyArray1<T>>>
where
    T: Element + Copy + Send + Sync,
{
    filled1(py, values.len(), |i| values[i])
}

/// `values` (`k` per row) as an `(n, k)` array of `T`, each converted by `convert`.
fn flat<'py, S, T>(
    py: Python<'py>,
    values: &[S],
    k: usize,
    convert: impl Fn(S) -> T + Sync + Send,
) -> PyResult<Bound<'py, PyArray2<T>>>
where
    S: Copy + Sync,
    T: Element + Copy + Send + Sync,
{
    let n = values.len().checked_div(k).unwrap_or(0);
    let array = PyArray2::<T>::zeros(py, [n, k], false);
    {
        let mut rw = array.readwrite();
        let out = rw.as_slice_mut().expect("a new array is contiguous");
        fill_values(py, out, |i| convert(values[i]))?;
    }
    Ok(array)
}

/// `values` (`k` numbers per row) as an `(n, k)` array, for any `k`.
pub(crate) fn flat_rows<'py>(
    py: Python<'py>,
    values: &[f64],
    k: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    flat(py, values, k, |x| x)
}

/// The elements of a C-contiguous array, or a `ValueError` naming the argument `what`.
pub(crate) fn contiguous<'a, T: Element, D: Dimension>(
    a: &'a PyReadonlyArray<'_, T, D>,
    what: &str,
) -> PyResult<&'a [T]> {
    a.as_slice()
        .map_err(|_| PyValueError::new_err(format!("{what}: a C-contiguous array is needed")))
}

/// The elements of a C-contiguous 2-D array of `k` columns, or a `ValueError` naming `what`.
pub(crate) fn columns<'a, T: Element>(
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
    contiguous(a, what)
}

/// An index given as `i64`, refused (named) when negative; the library checks the upper
/// bound.
pub(crate) fn index(i: i64) -> Result<u64, String> {
    u64::try_from(i).map_err(|_| format!("index {i} is negative"))
}

/// A read-only `(n, k)` numpy view of `data` (`k` per row), whose memory `owner` keeps.
///
/// # Safety
/// `data` must be memory `owner` holds, and `owner` must neither free nor move it while
/// any Python object is alive (numpy keeps `owner` as the view's base).
#[allow(unsafe_code)] // a view without a copy is the point: numpy's own borrowing constructor
pub(crate) unsafe fn view2<'py, T: Element>(
    data: &[T],
    k: usize,
    owner: Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<T>>> {
    let rows = data.len().checked_div(k).unwrap_or(0);
    let view = numpy::ndarray::ArrayView2::from_shape((rows, k), data)
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
    // SAFETY: as the caller promises.
    let array = unsafe { PyArray2::borrow_from_array(&view, owner) };
    array.readwrite().make_nonwriteable();
    Ok(array)
}

/// The integer type face indices are handed out in (`index_dtype` in Python): numpy's
/// int64 by default, as trimesh and libigl take them; int32 or uint32 for half the memory.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum IndexType {
    I64,
    I32,
    U32,
}

impl IndexType {
    /// The type numpy names `name` (`"int64"`, `"int32"`, `"uint32"`).
    pub(crate) fn named(name: &str) -> PyResult<IndexType> {
        match name {
            "int64" => Ok(IndexType::I64),
            "int32" => Ok(IndexType::I32),
            "uint32" => Ok(IndexType::U32),
            _ => Err(PyValueError::new_err(format!(
                "index_dtype: {name} is not int64, int32 or uint32"
            ))),
        }
    }

    /// Refuses int32 for indices that reach past its range (`bound` elements indexed).
    pub(crate) fn check_holds(self, bound: usize) -> PyResult<()> {
        if self == IndexType::I32 && bound > i32::MAX as usize + 1 {
            return Err(crate::errors::mesh_error(format!(
                "index_dtype int32 cannot index {bound} vertices: take int64 or uint32"
            )));
        }
        Ok(())
    }

    /// A new read-only `(n,)` array of this type, numpy's own, `write` filling it on the
    /// pool with indices converted as the type needs (the GIL released).
    pub(crate) fn filled<'py>(
        self,
        py: Python<'py>,
        n: usize,
        write: impl Fn(&mut dyn IndexSink) + Send + Sync,
    ) -> PyResult<Bound<'py, PyAny>> {
        fn make<'py, T: Element + Copy + Send + Sync>(
            py: Python<'py>,
            n: usize,
            fill: impl FnOnce(&mut [T]) + Send,
        ) -> PyResult<Bound<'py, PyAny>> {
            let array = PyArray1::<T>::zeros(py, n, false);
            {
                let mut rw = array.readwrite();
                let out = rw.as_slice_mut().expect("a new array is contiguous");
                pool::run(py, || fill(out))?;
                rw.make_nonwriteable();
            }
            Ok(array.into_any())
        }
        match self {
            IndexType::I64 => make(py, n, |out: &mut [i64]| write(&mut Sink(out))),
            IndexType::I32 => make(py, n, |out: &mut [i32]| write(&mut Sink(out))),
            IndexType::U32 => make(py, n, |out: &mut [u32]| write(&mut Sink(out))),
        }
    }

    /// The faces of a refinement's last level, written once from `stream` into a new
    /// read-only array of this type.
    pub(crate) fn faces<'py>(
        self,
        py: Python<'py>,
        stream: &subd_schemes::FaceStream<'_>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = stream.num_faces() * stream.face_size();
        self.filled(py, n, |sink| sink.faces_from(stream))
    }

    /// `values` as a new read-only array of this type.
    pub(crate) fn copied<'py>(
        self,
        py: Python<'py>,
        values: &[u32],
    ) -> PyResult<Bound<'py, PyAny>> {
        self.filled(py, values.len(), |sink| sink.convert_from(values))
    }
}

/// Where indices are written in whatever type the caller asked for.
pub(crate) trait IndexSink {
    /// `values` converted into the whole buffer, in parallel.
    fn convert_from(&mut self, values: &[u32]);
    /// The faces of a refinement's last level written into the whole buffer.
    fn faces_from(&mut self, stream: &subd_schemes::FaceStream<'_>);
}

/// An index buffer of one type.
struct Sink<'a, T>(&'a mut [T]);

/// The conversion from the library's `u32` (checked against the type's range by
/// [`IndexType::check_holds`] before any writing).
trait FromIndex: Copy + Send + Sync {
    fn from_index(v: u32) -> Self;
}

impl FromIndex for i64 {
    fn from_index(v: u32) -> Self {
        i64::from(v)
    }
}

impl FromIndex for i32 {
    fn from_index(v: u32) -> Self {
        v as i32
    }
}

impl FromIndex for u32 {
    fn from_index(v: u32) -> Self {
        v
    }
}

impl<T: FromIndex> IndexSink for Sink<'_, T> {
    fn convert_from(&mut self, values: &[u32]) {
        self.0
            .par_chunks_mut(4 * CHUNK_ROWS)
            .zip(values.par_chunks(4 * CHUNK_ROWS))
            .for_each(|(out, v)| {
                for (o, &x) in out.iter_mut().zip(v) {
                    *o = T::from_index(x);
                }
            });
    }

    fn faces_from(&mut self, stream: &subd_schemes::FaceStream<'_>) {
        stream.write_all(self.0, T::from_index);
    }
}
