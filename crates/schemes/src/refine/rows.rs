//! A level's points as independent rows, computed all at once ([`build`]) or a range at a
//! time ([`super::PointStream`]) with the same operations, so both give the same bits.

use std::ops::Range;

use glam::DVec3;

use super::CHUNK;
use subd_mesh::memory;

/// The points of one level as rows. The `middle` rows (the face points, for the schemes
/// that have them) come from the parent level alone; every other row reads the parent level
/// and the middle rows, as OpenSubdiv's `PrimvarRefiner` computes face points first.
pub(crate) trait PointRows: Sync {
    /// Number of rows.
    fn len(&self) -> usize;
    /// The rows computed first.
    fn middle(&self) -> Range<usize>;
    /// Row `r` of [`Self::middle`].
    fn middle_row(&self, r: usize) -> DVec3;
    /// Row `r` outside [`Self::middle`], from the middle rows.
    fn row(&self, r: usize, middle: &[DVec3]) -> DVec3;
}

/// Every row, in parallel: the middle first, then the rest from it.
pub(crate) fn build(rows: &impl PointRows) -> Vec<DVec3> {
    memory::build_around(
        rows.len(),
        rows.middle(),
        CHUNK,
        |r| rows.middle_row(r),
        |r, middle| rows.row(r, middle),
    )
}

/// The middle rows alone, in parallel: what a range of the other rows needs.
pub(crate) fn build_middle(rows: &impl PointRows) -> Vec<DVec3> {
    use rayon::prelude::*;
    let mut out = memory::with_capacity(rows.middle().len());
    out.par_extend(
        rows.middle()
            .into_par_iter()
            .with_min_len(CHUNK)
            .map(|r| rows.middle_row(r)),
    );
    out
}
