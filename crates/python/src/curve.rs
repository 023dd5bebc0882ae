//! `subd._subd.curve`: subdivision curves (`subd_schemes::named_curve`).

use numpy::{PyArray2, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use subd_mesh::DVec3;
use subd_schemes::named_curve::{CurveParameters, NamedCurve, subdivide_curve};

use crate::arrays::{columns, contiguous, filled2};
use crate::errors::mesh_error;
use crate::pool;

/// Points of the last level, `(m, k)` with the input's `k` (2 or 3) columns.
type Points<'py> = Bound<'py, PyArray2<f64>>;

/// `points` (`(n, 2)` or `(n, 3)`) subdivided `levels` times with the curve scheme
/// `scheme_name`: the points, and their unit normals under a circle-average scheme
/// (`normals` `(n, 2)` given, or estimated from the polygon when `None`).
#[pyfunction]
#[pyo3(signature = (points, scheme_name, levels, closed, parameters, normals = None))]
#[allow(clippy::type_complexity)]
pub(crate) fn curve<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'_, f64>,
    scheme_name: &str,
    levels: usize,
    closed: bool,
    parameters: (Option<f64>, Option<f64>, Option<usize>, Option<f64>),
    normals: Option<PyReadonlyArray2<'_, f64>>,
) -> PyResult<(Points<'py>, Option<Points<'py>>)> {
    let (omega, mu, order, alpha0) = parameters;
    let scheme = NamedCurve::new(
        scheme_name,
        &CurveParameters {
            omega,
            mu,
            order,
            alpha0,
        },
    )
    .map_err(|e| mesh_error(e.to_string()))?;
    let k = points.shape()[1];
    if !(2..=3).contains(&k) {
        return Err(PyValueError::new_err(format!(
            "points: shape {:?}, expected (n, 2) or (n, 3)",
            points.shape()
        )));
    }
    let flat = contiguous(&points, "points")?;
    let input: Vec<DVec3> = flat
        .chunks_exact(k)
        .map(|c| DVec3::new(c[0], c[1], if k == 3 { c[2] } else { 0.0 }))
        .collect();
    let given = match &normals {
        Some(n) => Some(normal_rows(n)?),
        None => None,
    };
    let out = pool::run(py, || {
        subdivide_curve(&scheme, &input, given.as_deref(), closed, levels)
    })?
    .map_err(|e| mesh_error(e.to_string()))?;
    let p = &out.points;
    let points = match k {
        2 => filled2(py, p.len(), |i, r: &mut [f64; 2]| *r = [p[i].x, p[i].y])?,
        _ => filled2(py, p.len(), |i, r: &mut [f64; 3]| *r = p[i].to_array())?,
    };
    let normals = match &out.normals {
        Some(n) => Some(filled2(py, n.len(), |i, r: &mut [f64; 2]| {
            *r = n[i].to_array()
        })?),
        None => None,
    };
    Ok((points, normals))
}

/// Normals given as an `(n, 2)` array.
fn normal_rows(n: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<glam::DVec2>> {
    Ok(columns(n, 2, "normals")?
        .chunks_exact(2)
        .map(|c| glam::DVec2::new(c[0], c[1]))
        .collect())
}
