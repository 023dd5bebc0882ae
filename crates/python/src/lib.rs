//! The compiled core of the Python package `subd` (`subd._subd`): meshes held as the
//! library's [`subd_mesh::Mesh`], numpy arrays at the boundary, and one library call per
//! function. Argument conversion (dtypes, shapes, mixed polygons) is done by the Python
//! layer (`python/subd/__init__.py`), which hands this module C-contiguous arrays of the
//! exact dtypes it asks for; the checks that name an element (a face's corner out of range,
//! a non-finite coordinate, an unknown scheme) are made here, where the library makes them.
//!
//! Every function releases the GIL while the library works and runs on the package's own
//! thread pool (the `pool` module), so Python threads refine in parallel and
//! `subd.set_num_threads` takes effect at once.

use pyo3::prelude::*;

mod adaptive;
mod analysis;
mod arrays;
mod curve;
mod device;
mod errors;
mod mesh;
mod ops;
mod patches;
mod pool;
mod refiner;
mod shape;
mod surface;

/// The module `subd._subd`.
#[pymodule]
fn _subd(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<mesh::CoreMesh>()?;
    m.add_class::<refiner::CoreRefiner>()?;
    m.add_class::<patches::CorePatchTable>()?;
    m.add_function(wrap_pyfunction!(ops::read, m)?)?;
    m.add_function(wrap_pyfunction!(ops::mesh_prims, m)?)?;
    m.add_function(wrap_pyfunction!(ops::refine, m)?)?;
    m.add_function(wrap_pyfunction!(ops::limit, m)?)?;
    m.add_function(wrap_pyfunction!(ops::info, m)?)?;
    m.add_function(wrap_pyfunction!(adaptive::adaptive, m)?)?;
    m.add_function(wrap_pyfunction!(analysis::analyze_mask, m)?)?;
    m.add_function(wrap_pyfunction!(analysis::analyze_mask2, m)?)?;
    m.add_function(wrap_pyfunction!(analysis::analyze_surface, m)?)?;
    m.add_function(wrap_pyfunction!(curve::curve, m)?)?;
    m.add(
        "CURVE_SCHEMES",
        subd_schemes::named_curve::CURVE_SCHEMES.to_vec(),
    )?;
    m.add_function(wrap_pyfunction!(surface::evaluate, m)?)?;
    m.add_function(wrap_pyfunction!(surface::tessellate, m)?)?;
    m.add_function(wrap_pyfunction!(shape::pia, m)?)?;
    m.add_function(wrap_pyfunction!(shape::edit, m)?)?;
    m.add_function(wrap_pyfunction!(shape::deform, m)?)?;
    m.add_function(wrap_pyfunction!(pool::set_num_threads, m)?)?;
    m.add_function(wrap_pyfunction!(pool::get_num_threads, m)?)?;
    m.add("SCHEMES", ops::SCHEME_NAMES.to_vec())?;
    Ok(())
}
