//! The package's exceptions, raised from Rust. They are defined in Python
//! (`subd.SubdError`, `subd.MeshError(SubdError, ValueError)`,
//! `subd.FormatError(SubdError, ValueError)`), where multiple inheritance is plain, and
//! looked up here when raised.

use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyType;

/// An exception of class `name` of the package `subd` with `message`; a `ValueError` if
/// the package cannot be imported (it always can once `subd._subd` is loaded through it).
fn subd_error(py: Python<'_>, name: &str, message: String) -> PyErr {
    let class = py
        .import("subd")
        .and_then(|m| m.getattr(name))
        .and_then(|c| c.cast_into::<PyType>().map_err(PyErr::from));
    match class {
        Ok(class) => PyErr::from_type(class, message),
        Err(_) => PyValueError::new_err(message),
    }
}

/// The package's exception `name` with `message`, raised from the modules beside this one.
pub(crate) fn named_error(name: &str, message: String) -> PyErr {
    Python::attach(|py| subd_error(py, name, message))
}

/// Emits `message` as a `subd.SubdWarning` (where a Python warning filter makes warnings
/// errors, that error).
pub(crate) fn warn(py: Python<'_>, message: &str) -> PyResult<()> {
    let class = py.import("subd")?.getattr("SubdWarning")?;
    let text =
        std::ffi::CString::new(message.replace('\0', " ")).expect("no NUL left in the message");
    PyErr::warn(py, &class, &text, 2)
}

/// `subd.MeshError`: an invalid mesh, tag or option, naming the element.
pub(crate) fn mesh_error(message: impl std::fmt::Display) -> PyErr {
    Python::attach(|py| subd_error(py, "MeshError", message.to_string()))
}

/// `subd.FormatError`: a file that cannot be parsed, naming file and line.
fn format_error(message: impl std::fmt::Display) -> PyErr {
    Python::attach(|py| subd_error(py, "FormatError", message.to_string()))
}

/// A file error as Python sees one: `OSError` for reading and writing, `FormatError` for
/// contents, `MeshError` for a valid file whose mesh is not.
pub(crate) fn io_error(e: subd_io::IoError) -> PyErr {
    use subd_io::IoError;
    match e {
        IoError::Read { .. } | IoError::Write { .. } => PyOSError::new_err(e.to_string()),
        IoError::UnknownFormat { .. } => PyValueError::new_err(e.to_string()),
        IoError::Topology { .. } => mesh_error(e),
        _ => format_error(e),
    }
}
