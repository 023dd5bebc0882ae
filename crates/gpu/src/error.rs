//! What can go wrong on the device, each as one variant that says what to do about it.

/// An error from the GPU path. None of them is a panic: a missing adapter, a lost device,
/// an allocation the device refuses or a table past the device's limits each come back as
/// one of these, checked before anything is dispatched where it can be.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// No adapter (Vulkan, Metal or DX12 device, or a software one such as Mesa's
    /// lavapipe) is available.
    #[error(
        "no GPU adapter found ({0}); on Linux, Mesa's software Vulkan driver (Debian's mesa-vulkan-drivers) provides one"
    )]
    NoAdapter(String),
    /// The adapter refused to open a device.
    #[error("the adapter {adapter} refused a device: {message}")]
    Device {
        /// The adapter's name.
        adapter: String,
        /// What it said.
        message: String,
    },
    /// A buffer larger than the device allows in one binding or allocation.
    #[error("{what} needs {bytes} bytes, past the device's limit of {limit} bytes for one buffer")]
    TooLarge {
        /// The buffer (e.g. "stencil weights").
        what: &'static str,
        /// Its size.
        bytes: u64,
        /// The device's limit.
        limit: u64,
    },
    /// The device ran out of memory.
    #[error("the device is out of memory allocating {what}")]
    OutOfMemory {
        /// The buffer being allocated.
        what: &'static str,
    },
    /// Arrays that do not fit together (a table applied to data with the wrong row count).
    #[error("{0}")]
    Mismatch(String),
    /// Something the device path does not do (a table with exact end caps).
    #[error("not on the GPU: {0}")]
    Unsupported(String),
    /// The host-side work before a dispatch failed (a place off the surface).
    #[error(transparent)]
    Limit(#[from] subd_limit::LimitError),
    /// The CPU's refinement, whose tables the device applies, refused the mesh.
    #[error(transparent)]
    Refine(#[from] subd_schemes::RefineError),
    /// The device was lost, or a command failed validation (a bug in subd if it happens).
    #[error("the device failed: {0}")]
    Failed(String),
}
