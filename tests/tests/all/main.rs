//! Every workspace-level integration test, in one binary: one link instead of one per file
//! (the release test build is most of CI's time).

mod acc;
mod adaptive;
mod curves;
mod depth_first;
mod editing;
mod front_door;
mod fvar_eval;
mod level_limit;
mod limit_eval;
mod limit_shapes;
mod osd_meshes;
mod pia;
mod point_stencil;
mod proptest_adaptive;
mod proptest_limit;
mod proptest_refine;
mod proptest_topology;
mod refined_topology;
mod split_fvar;
mod split_schemes;
mod split_topology;
mod streamed_output;
mod tessellation;
