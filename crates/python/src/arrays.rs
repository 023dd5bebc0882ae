//! Arrays handed to Python: allocated by numpy (so they own their data, `OWNDATA` set, and
//! outlive the mesh they came from) and filled in place, in parallel on the package's pool
//! with the GIL released: the library's values are converted once, with no intermediate
//! vector.

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

/// Indices (`k` per row) as an `(n, k)` int64 array.
pub(crate) fn flat_ints<'py>(
    py: Python<'py>,
    values: &[u32],
    k: usize,
) -> PyResult<Bound<'py, PyArray2<i64>>> {
    flat(py, values, k, i64::from)
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
