//! subd on the GPU, with [`wgpu`] (Vulkan, Metal, DX12; WGSL compute shaders), headless.
//!
//! * [`Gpu`]: an adapter's device and queue ([`list_adapters`] names them all);
//! * [`GpuColumns`]: rows of f32 values in a device buffer (positions, colours, UVs), whose
//!   layout a renderer can draw from;
//! * [`GpuStencilTable`]: a [`subd_schemes::StencilTable`] uploaded once and applied to
//!   columns as often as they change;
//! * [`GpuRefiner`]: a refinement's levels recomputed on the device from new base values
//!   with one submission, per level or through one composed table;
//! * [`GpuLimitStencils`]: a level's limit positions and tangents
//!   ([`subd_limit::LimitStencilTable`]);
//! * [`GpuPatchTable`]: a [`subd_limit::patches::PatchTable`]'s points recomputed from new
//!   base positions, its patches evaluated at batches of places ([`GpuPatchCoords`]) and
//!   on a uniform grid of every patch ([`GpuTessellation`]);
//! * [`GpuUniformRefinement`]: a Catmull-Clark or Loop mesh refined uniformly on the
//!   device, topology (face vertices bit for bit the CPU's) and points, level by level.
//!
//! Values are f32 on the device (every adapter has it); stencil weights and sums are f64
//! where the adapter has 64-bit floats, else f32 ([`Precision`]). Results stay on the device
//! until read back ([`Gpu::read_columns`]).
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use subd_gpu::{Gpu, GpuRefiner, LevelTables};
//! use subd_mesh::{DVec3, TopologyBuilder};
//! use subd_schemes::{Options, Refinement, Scheme};
//!
//! let quad = TopologyBuilder::new(4).build(&[4], &[0, 1, 2, 3])?;
//! let refinement = Refinement::new(&quad, Scheme::CatmullClark, &Options::default(), 2)?;
//! // A machine without an adapter (no GPU, no Mesa lavapipe) stops here.
//! let Ok(gpu) = Gpu::new() else { return Ok(()) };
//! let refiner = GpuRefiner::new(&gpu, &refinement, 3, LevelTables::PerLevel)?;
//! let cage = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
//! refiner.update_points(&gpu, &cage)?; // every frame, with the new cage
//! let level2 = gpu.read_points(refiner.last())?;
//! assert_eq!(level2.len(), refinement.num_vertices(2));
//! # Ok(())
//! # }
//! ```

mod device;
mod error;
mod limit;
mod patches;
mod pipeline;
mod refiner;
mod stencils;
mod uniform;

pub use device::{AdapterSummary, Gpu, list_adapters};
pub use error::GpuError;
pub use limit::{GpuLimit, GpuLimitStencils};
pub use patches::{GpuPatchCoords, GpuPatchTable, GpuPatchValues, GpuTessellation, PatchDispatch};
pub use pipeline::Precision;
pub use refiner::{GpuFaceVarying, GpuRefiner, LevelTables};
pub use stencils::{GpuColumns, GpuStencilTable, StencilDispatch};
pub use uniform::GpuUniformRefinement;
