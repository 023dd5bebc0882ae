//! `subd._subd.analyze_*`: convergence and smoothness of subdivision masks
//! (`subd_schemes::analysis`) and the eigenvalue test of surface schemes
//! (`subd_limit::spectrum`), each as the JSON text `subd analyze --json` prints.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use serde::Serialize;
use subd_schemes::analysis::{Lattice, analyze, analyze_bivariate, check_total};

use crate::errors::mesh_error;
use crate::ops::{named, scheme};
use crate::pool;

/// The levels of the difference scheme a verdict may try.
const MAX_LEVELS: std::ops::RangeInclusive<usize> = 1..=20;

/// A univariate mask (`a_j` by increasing power of `z`, summing to the arity).
#[pyfunction]
pub(crate) fn analyze_mask(
    py: Python<'_>,
    mask: Vec<f64>,
    arity: usize,
    max_levels: usize,
) -> PyResult<String> {
    check_levels(max_levels)?;
    check_total(&mask, arity as f64, &format!("a mask of arity {arity}"))
        .map_err(|e| mesh_error(format!("mask: {e}")))?;
    let verdict = pool::run(py, || analyze(&mask, arity, max_levels))?
        .map_err(|e| mesh_error(format!("mask: {e}")))?;
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
    check_levels(max_levels)?;
    let lattice: Lattice = named("lattice", lattice)?;
    let all: Vec<f64> = rows.iter().flatten().copied().collect();
    check_total(&all, 4.0, "a bivariate binary mask")
        .map_err(|e| mesh_error(format!("mask2: {e}")))?;
    let verdict = pool::run(py, || analyze_bivariate(&rows, lattice, max_levels))?
        .map_err(|e| mesh_error(format!("mask2: {e}")))?;
    json(&verdict)
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

fn check_levels(max_levels: usize) -> PyResult<()> {
    if MAX_LEVELS.contains(&max_levels) {
        return Ok(());
    }
    Err(PyValueError::new_err(format!(
        "max_levels {max_levels}: must be {} to {}",
        MAX_LEVELS.start(),
        MAX_LEVELS.end()
    )))
}

fn json(value: &impl Serialize) -> PyResult<String> {
    serde_json::to_string(value).map_err(|e| PyValueError::new_err(e.to_string()))
}
