//! Uniform tessellation of the limit surface (see [`uniform`]): the samples numbered once
//! ([`numbering`]) into the output mesh ([`output`]), then evaluated on a patch table or an
//! exact evaluator. One way down: `uniform` → `numbering` → `output`.

mod numbering;
mod output;
mod uniform;

pub use output::{SampleGrid, Tessellation};
pub use uniform::{MAX_RATE, tessellate, tessellate_mesh, tessellate_patches};
