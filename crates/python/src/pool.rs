//! The package's thread pool: `SUBD_NUM_THREADS` (else rayon's default, one thread per
//! core) until `subd.set_num_threads(n)` replaces it. Rayon's global pool can be set only
//! once per process, so the package keeps its own and runs every call inside it.

use std::sync::{Arc, Mutex, PoisonError};

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use rayon::{ThreadPool, ThreadPoolBuilder};

static POOL: Mutex<Option<Arc<ThreadPool>>> = Mutex::new(None);

/// A pool of `threads` threads (`0`: one per core).
fn build(threads: usize) -> PyResult<Arc<ThreadPool>> {
    ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("subd-{i}"))
        .build()
        .map(Arc::new)
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start the thread pool: {e}")))
}

/// The current pool, made from `SUBD_NUM_THREADS` on first use.
fn current() -> PyResult<Arc<ThreadPool>> {
    let mut pool = POOL.lock().unwrap_or_else(PoisonError::into_inner);
    if let Some(p) = pool.as_ref() {
        return Ok(p.clone());
    }
    let threads = match std::env::var("SUBD_NUM_THREADS") {
        Ok(v) => v.trim().parse::<usize>().map_err(|_| {
            PyValueError::new_err(format!(
                "SUBD_NUM_THREADS={v:?} is not a number of threads (a whole number, 0 for one per core)"
            ))
        })?,
        Err(_) => 0,
    };
    let p = build(threads)?;
    *pool = Some(p.clone());
    Ok(p)
}

/// Runs `work` on the package's pool with the GIL released: other Python threads run
/// meanwhile, and `work` sees no Python object.
pub(crate) fn run<T: Send>(py: Python<'_>, work: impl FnOnce() -> T + Send) -> PyResult<T> {
    let pool = current()?;
    Ok(py.detach(|| pool.install(work)))
}

/// Runs `work` on the package's pool from a thread that has released the GIL already (see
/// [`run`]).
pub(crate) fn install<T: Send>(work: impl FnOnce() -> T + Send) -> PyResult<T> {
    Ok(current()?.install(work))
}

/// Sets the number of threads every later call uses (`0`: one per core).
#[pyfunction]
pub(crate) fn set_num_threads(threads: usize) -> PyResult<()> {
    let p = build(threads)?;
    *POOL.lock().unwrap_or_else(PoisonError::into_inner) = Some(p);
    Ok(())
}

/// The number of threads calls run on.
#[pyfunction]
pub(crate) fn get_num_threads() -> PyResult<usize> {
    Ok(current()?.current_num_threads())
}
