//! Filling flat arrays in parallel, block by block, without unsafe code: the output is cut
//! into disjoint slices (one per block of parent elements) that threads fill independently.

use std::ops::Range;

use rayon::prelude::*;

/// Elements per block: big enough to amortise scheduling, small enough to balance.
const BLOCK: usize = 8192;

/// Fills `out` in parallel: element range `r` of `0..n` owns `out[start(r.start)..start(r.end)]`,
/// where `start` is non-decreasing with `start(n) == out.len()`; `fill(r, slice)` writes it.
pub(crate) fn fill<T: Send>(
    out: &mut [T],
    n: usize,
    start: impl Fn(usize) -> usize + Sync,
    fill: impl Fn(Range<usize>, &mut [T]) + Sync,
) {
    debug_assert_eq!(start(n), out.len());
    let mut rest = out;
    let pieces: Vec<(Range<usize>, &mut [T])> = blocks(n)
        .map(|r| {
            let (head, tail) =
                std::mem::take(&mut rest).split_at_mut(start(r.end) - start(r.start));
            rest = tail;
            (r, head)
        })
        .collect();
    pieces.into_par_iter().for_each(|(r, s)| fill(r, s));
}

/// [`fill`] for two arrays cut alike (the same `start`), written in one pass: for relations
/// whose two arrays (e.g. faces and local indices) come from the same reads of the parent.
pub(crate) fn fill_pair<A: Send, B: Send>(
    a: &mut [A],
    b: &mut [B],
    n: usize,
    start: impl Fn(usize) -> usize + Sync,
    fill: impl Fn(Range<usize>, &mut [A], &mut [B]) + Sync,
) {
    debug_assert_eq!(start(n), a.len());
    debug_assert_eq!(a.len(), b.len());
    let (mut rest_a, mut rest_b) = (a, b);
    let pieces: Vec<(Range<usize>, &mut [A], &mut [B])> = blocks(n)
        .map(|r| {
            let len = start(r.end) - start(r.start);
            let (ha, ta) = std::mem::take(&mut rest_a).split_at_mut(len);
            let (hb, tb) = std::mem::take(&mut rest_b).split_at_mut(len);
            (rest_a, rest_b) = (ta, tb);
            (r, ha, hb)
        })
        .collect();
    pieces.into_par_iter().for_each(|(r, x, y)| fill(r, x, y));
}

/// The element ranges of the blocks of `0..n`.
fn blocks(n: usize) -> impl Iterator<Item = Range<usize>> {
    (0..n.div_ceil(BLOCK)).map(move |i| i * BLOCK..((i + 1) * BLOCK).min(n))
}

/// A vector of `len` elements (zeroed, huge-page advised when large) filled in parallel as [`fill`] does.
pub(crate) fn build<T: Send + Sync + Clone + bytemuck::Zeroable>(
    len: usize,
    n: usize,
    start: impl Fn(usize) -> usize + Sync,
    f: impl Fn(Range<usize>, &mut [T]) + Sync,
) -> Vec<T> {
    let mut out = subd_mesh::memory::zeroed(len);
    fill(&mut out, n, start, f);
    out
}
