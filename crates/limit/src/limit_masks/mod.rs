//! Limits of the vertices of a level: closed-form masks, masks from the eigen analysis of the
//! local subdivision matrix, their stencil tables, the limits of face-varying values, and
//! the eigenvalue test of a scheme.

pub(crate) mod child_limit;
pub(crate) mod eigen;
pub(crate) mod fvar;
pub(crate) mod masks;
pub(crate) mod regular_patches;
pub(crate) mod smooth_closed;
pub(crate) mod spectrum;
pub(crate) mod table;
pub(crate) mod two_phase_closed;
