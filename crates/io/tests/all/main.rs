//! subd-io's integration tests, in one binary (one link instead of one per file).

mod atomic_write;
mod fuzz_regressions;
mod gltf_input;
mod mesh_view;
mod usd;
