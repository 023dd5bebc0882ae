//! The GPU as the Python package uses it: `device="cpu" | "gpu" | "auto"`, one device per
//! process, opened on first use and opened again after it was lost.

use std::sync::{Arc, Mutex};

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use subd_gpu::{Gpu, GpuError};

/// The process's device, once opened.
static DEVICE: Mutex<Option<Arc<Gpu>>> = Mutex::new(None);

/// The process's device: the one opened before while it works, else a new one.
fn open() -> Result<Arc<Gpu>, GpuError> {
    let mut held = DEVICE.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(gpu) = held.as_ref().filter(|g| g.check().is_ok()) {
        return Ok(Arc::clone(gpu));
    }
    let gpu = Arc::new(Gpu::new()?);
    *held = Some(Arc::clone(&gpu));
    Ok(gpu)
}

/// Where a computation runs, as asked: the device for `"gpu"` (an error without one), the
/// CPU for `"cpu"`, and for `"auto"` the device where there is one, else the CPU and the
/// warning that says so.
pub(crate) fn choose(device: &str) -> PyResult<(Option<Arc<Gpu>>, Option<String>)> {
    match device {
        "cpu" => Ok((None, None)),
        "gpu" => open().map(|g| (Some(g), None)).map_err(device_error),
        "auto" => Ok(match open() {
            Ok(g) => (Some(g), None),
            Err(e) => (
                None,
                Some(format!("device=\"auto\": {e}; running on the CPU")),
            ),
        }),
        other => Err(PyValueError::new_err(format!(
            "device: unknown value {other:?} (one of cpu, gpu, auto)"
        ))),
    }
}

/// What `device="auto"` says when the GPU fails and the CPU takes over.
pub(crate) fn fallback_warning(e: &GpuError) -> String {
    format!("device=\"auto\": {e}; running on the CPU")
}

/// `subd.DeviceError`: the GPU path failed (no adapter, a lost device, a buffer past its
/// limits, something it does not do).
pub(crate) fn device_error(e: GpuError) -> PyErr {
    crate::errors::named_error("DeviceError", e.to_string())
}
