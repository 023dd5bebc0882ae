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
    let mut pieces: Vec<(Range<usize>, &mut [T])> = Vec::with_capacity(n / BLOCK + 1);
    let mut rest = out;
    let mut first = 0;
    while first < n {
        let last = (first + BLOCK).min(n);
        let len = start(last) - start(first);
        let (head, tail) = rest.split_at_mut(len);
        pieces.push((first..last, head));
        rest = tail;
        first = last;
    }
    pieces.into_par_iter().for_each(|(r, s)| fill(r, s));
}

/// A vector of `len` default values filled in parallel as [`fill`] does.
pub(crate) fn build<T: Send + Default + Clone>(
    len: usize,
    n: usize,
    start: impl Fn(usize) -> usize + Sync,
    f: impl Fn(Range<usize>, &mut [T]) + Sync,
) -> Vec<T> {
    let mut out = vec![T::default(); len];
    fill(&mut out, n, start, f);
    out
}
