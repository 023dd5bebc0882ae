//! `subd._subd.analyze_*`: convergence and smoothness of subdivision masks
//! (`subd_schemes::analysis`) and the eigenvalue test of surface schemes
//! (`subd_limit::spectrum`), each as the JSON text `subd analyze --json` prints.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use serde::Serialize;
use subd_schemes::analysis::{self, AnalysisError, Lattice};

use crate::errors::mesh_error;
use crate::ops::{named, scheme};
use crate::pool;

/// A univariate mask (`a_j` by increasing power of `z`, summing to the arity).
#[pyfunction]
pub(crate) fn analyze_mask(
    py: Python<'_>,
    mask: Vec<f64>,
    arity: usize,
    max_levels: usize,
) -> PyResult<String> {
    let verdict = pool::run(py, || analysis::analyze_mask(&mask, arity, max_levels))?
        .map_err(|e| analysis_error("mask", e))?;
    json(&verdict)
}

/// A bivariate binary mask (row `j` holds the coefficients of `z1^i z2^j`) on `lattice`
/// (`"quad"` or `"three-direction"`).
#[pyfunction]
pub(crate) fn analyze_mask2(
    py: Python<'_>,
    rows: Vec<Vec<f64>>,
    lattice: &str,
    max_levels: usize,
) -> PyResult<String> {
    let lattice: Lattice = named("lattice", lattice)?;
    let verdict = pool::run(py, || analysis::analyze_mask2(&rows, lattice, max_levels))?
        .map_err(|e| analysis_error("mask2", e))?;
    json(&verdict)
}

/// The library's refusal, named by the argument at fault: a `ValueError` for the level
/// limit, a `MeshError` for the mask.
fn analysis_error(mask: &str, e: AnalysisError) -> PyErr {
    match e {
        AnalysisError::Levels(n) => PyValueError::new_err(format!(
            "max_levels {n}: must be {} to {}",
            analysis::LEVEL_RANGE.start(),
            analysis::LEVEL_RANGE.end()
        )),
        e => mesh_error(format!("{mask}: {e}")),
    }
}

/// The eigenvalue test of a surface scheme at an interior vertex of valence `valence`.
#[pyfunction]
pub(crate) fn analyze_surface(
    py: Python<'_>,
    scheme_name: &str,
    valence: usize,
) -> PyResult<String> {
    let scheme = scheme(scheme_name)?;
    let spectrum = pool::run(py, || {
        subd_limit::spectrum::surface_spectrum(&scheme, valence)
    })?
    .map_err(|e| mesh_error(format!("{}: {e}", scheme.name())))?;
    json(&spectrum)
}

fn json(value: &impl Serialize) -> PyResult<String> {
    serde_json::to_string(value).map_err(|e| PyValueError::new_err(e.to_string()))
}
