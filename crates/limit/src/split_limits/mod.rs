//! Limits of the split schemes (Doo-Sabin, √3, the butterflies, mid-edge): their local
//! subdivision matrices analysed in Fourier blocks, and the limit stencils from them.

pub(crate) mod composed_rows;
pub(crate) mod pieces;
pub(crate) mod split_eigen;
pub(crate) mod split_limit;
