//! Exact evaluation of the limit at any (face, u, v): bicubic B-splines and Stam's eigenbasis
//! for Catmull-Clark, box splines and its Loop counterpart, local refinement next to
//! irregular sharp features, the limit as stencils over the base vertices, face-varying
//! values, and Loop & Schaefer's approximation.

pub(crate) mod acc;
pub(crate) mod child_param;
pub(crate) mod eval;
pub(crate) mod fvar_eval;
pub(crate) mod local;
pub(crate) mod loop_patch;
pub(crate) mod patch;
pub(crate) mod piece;
pub(crate) mod point_stencil;
pub(crate) mod stam;
pub(crate) mod support;
