//! Compressed-row (CSR) adjacency built by a stable counting sort: count the entries of each
//! row, turn the counts into row offsets by a prefix sum, then scatter every entry into the
//! next free slot of its row.
//!
//! The scatter visits entries in input order, so each row lists its entries in the order
//! they were given (the sort is stable); rows with no entry are empty ranges. Everything is
//! linear in rows + entries and allocates the offsets, one cursor array and the values, never
//! anything per entry. [`offsets_of_keys`] and [`RowSlots`] are the two steps for callers that
//! scatter into several parallel arrays at once; [`group_by_key`] does both for one array.
//! [`par_group_indices`] is the same sort run by all threads, for the large arrays of a
//! topology build; its result does not depend on the number of threads.
//!
//! ```
//! use subd_mesh::csr::group_by_key;
//! // Entries 'a'..'e' keyed by row; row 1 is empty.
//! let rows = group_by_key(3, [(2, 'a'), (0, 'b'), (2, 'c'), (0, 'd'), (2, 'e')].into_iter());
//! assert_eq!(rows.offsets, [0, 2, 2, 5]);
//! assert_eq!(rows.row(0), ['b', 'd']);
//! assert_eq!(rows.row(2), ['a', 'c', 'e']);
//! ```

use std::sync::atomic::Ordering;

use rayon::prelude::*;

use crate::memory;

/// Row offsets (`num_rows + 1` of them, starting at 0) for entries whose rows are `keys`:
/// row `r` will occupy `offsets[r]..offsets[r + 1]`. Every key must be below `num_rows`, and
/// there must be fewer than `u32::MAX` entries.
#[inline]
pub fn offsets_of_keys(num_rows: usize, keys: impl IntoIterator<Item = u32>) -> Vec<u32> {
    let mut offsets = vec![0u32; num_rows + 1];
    // Count row r in offsets[r + 1] so that the in-place prefix sum leaves row starts.
    for k in keys {
        offsets[k as usize + 1] += 1;
    }
    for r in 0..num_rows {
        offsets[r + 1] += offsets[r];
    }
    offsets
}

/// The scatter step: hands out the slots of each row in turn, from its start in `offsets`.
/// Asking for the slots of the entries in input order keeps each row in input order.
#[derive(Debug, Clone)]
pub struct RowSlots {
    next: Vec<u32>,
}

impl RowSlots {
    /// Slots for rows laid out by `offsets` (as from [`offsets_of_keys`]).
    pub fn new(offsets: &[u32]) -> RowSlots {
        RowSlots {
            next: offsets[..offsets.len().saturating_sub(1)].to_vec(),
        }
    }

    /// The next free slot of `row` (an index into the values array), which is then taken.
    #[inline]
    pub fn take(&mut self, row: usize) -> usize {
        let slot = self.next[row];
        self.next[row] += 1;
        slot as usize
    }
}

/// Compressed rows: row `r` of `values` is `values[offsets[r]..offsets[r + 1]]`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Csr<T> {
    /// Row starts, one more than the rows; the last is `values.len()`.
    pub offsets: Vec<u32>,
    /// The entries, row after row.
    pub values: Vec<T>,
}

impl<T> Csr<T> {
    /// The number of rows.
    pub fn num_rows(&self) -> usize {
        self.offsets.len() - 1
    }

    /// The entries of row `r`.
    pub fn row(&self, r: usize) -> &[T] {
        &self.values[self.offsets[r] as usize..self.offsets[r + 1] as usize]
    }
}

/// Groups `(row, value)` entries into `num_rows` compressed rows, each row in input order.
/// `entries` is walked twice (count, then scatter), so it should be cheap to clone.
pub fn group_by_key<T: Copy + Default>(
    num_rows: usize,
    entries: impl Iterator<Item = (u32, T)> + Clone,
) -> Csr<T> {
    let offsets = offsets_of_keys(num_rows, entries.clone().map(|(k, _)| k));
    let mut values = vec![T::default(); offsets[num_rows] as usize];
    let mut slots = RowSlots::new(&offsets);
    for (k, v) in entries {
        values[slots.take(k as usize)] = v;
    }
    Csr { offsets, values }
}

/// Entries below which a parallel sort uses a single chunk (and so runs on one thread).
const MIN_ENTRIES_PER_CHUNK: usize = 1 << 15;
/// Most chunks a parallel sort counts separately: each holds one count per row.
const MAX_CHUNKS: usize = 8;
/// Rows per task when the per-chunk counts are turned into cursors.
const ROWS_PER_TASK: usize = 1 << 14;

/// [`group_by_key`] of the indices `0..n`, index `i` in row `key(i)`, run in parallel: each
/// chunk of the indices counts its rows, the counts become one cursor per row and chunk
/// (rows in order, and within a row the chunks in order), then all chunks scatter at once.
/// Each row lists its indices in increasing order, the stable order, so the result is that
/// of the serial sort whatever the number of threads.
///
/// ```
/// use subd_mesh::csr::par_group_indices;
/// let keys = [2u32, 0, 2, 0, 2];
/// let rows = par_group_indices(3, keys.len(), |i| keys[i]);
/// assert_eq!(rows.offsets, [0, 2, 2, 5]);
/// assert_eq!(rows.row(2), [0, 2, 4]);
/// ```
///
/// # Panics
/// If a key is not below `num_rows` or `n` does not fit a `u32`.
pub fn par_group_indices(num_rows: usize, n: usize, key: impl Fn(usize) -> u32 + Sync) -> Csr<u32> {
    assert!(n < u32::MAX as usize, "too many entries for u32 indices");
    let chunks = index_chunks(n);
    let mut cursors: Vec<Vec<u32>> = chunks
        .par_iter()
        .map(|r| {
            let mut counts = vec![0u32; num_rows];
            for i in r.clone() {
                counts[key(i) as usize] += 1;
            }
            counts
        })
        .collect();
    let offsets = cursors_from_counts(num_rows, n, &mut cursors);
    // Chunks write to disjoint slots; atomics let them share the array without locks
    // (relaxed stores compile to plain stores).
    let values = memory::atomic_u32s(n, |_| 0);
    chunks
        .par_iter()
        .zip(cursors.par_iter_mut())
        .for_each(|(r, next)| {
            for i in r.clone() {
                let k = key(i) as usize;
                values[next[k] as usize].store(i as u32, Ordering::Relaxed);
                next[k] += 1;
            }
        });
    Csr {
        offsets,
        values: memory::into_u32s(values),
    }
}

/// Splits `0..n` into chunks for a parallel sort: one per thread (at most [`MAX_CHUNKS`]),
/// fewer for small `n`.
fn index_chunks(n: usize) -> Vec<std::ops::Range<usize>> {
    let count = (n / MIN_ENTRIES_PER_CHUNK).clamp(1, rayon::current_num_threads().min(MAX_CHUNKS));
    let size = n.div_ceil(count).max(1);
    (0..count)
        .map(|c| (c * size).min(n)..((c + 1) * size).min(n))
        .collect()
}

/// Turns per-chunk row counts into per-chunk cursors (the slot of each chunk's first entry
/// in each row) and returns the row offsets; `n` is the number of entries.
fn cursors_from_counts(num_rows: usize, n: usize, counts: &mut [Vec<u32>]) -> Vec<u32> {
    let totals: Vec<u32> = (0..num_rows.div_ceil(ROWS_PER_TASK))
        .into_par_iter()
        .map(|t| {
            let rows = t * ROWS_PER_TASK..((t + 1) * ROWS_PER_TASK).min(num_rows);
            counts
                .iter()
                .map(|c| c[rows.clone()].iter().sum::<u32>())
                .sum()
        })
        .collect();
    let starts = exclusive_prefix_sum(&totals);
    // Each task takes its rows of every chunk's counts.
    let mut tasks: Vec<Vec<&mut [u32]>> = totals.iter().map(|_| Vec::new()).collect();
    for c in counts.iter_mut() {
        for (task, rows) in tasks.iter_mut().zip(c.chunks_mut(ROWS_PER_TASK)) {
            task.push(rows);
        }
    }
    let mut offsets = vec![0u32; num_rows + 1];
    offsets[..num_rows]
        .par_chunks_mut(ROWS_PER_TASK)
        .zip(tasks)
        .zip(starts)
        .for_each(|((offsets, mut counts), mut next)| {
            for (r, offset) in offsets.iter_mut().enumerate() {
                *offset = next;
                for c in counts.iter_mut() {
                    let count = c[r];
                    c[r] = next;
                    next += count;
                }
            }
        });
    offsets[num_rows] = n as u32;
    offsets
}

/// The exclusive prefix sums of `counts`: element `i` is the sum of `counts[..i]`.
pub(crate) fn exclusive_prefix_sum(counts: &[u32]) -> Vec<u32> {
    let mut sum = 0;
    counts
        .iter()
        .map(|&c| {
            let start = sum;
            sum += c;
            start
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The naive construction: a stable sort of the entries by row, and counts per row.
    fn naive(num_rows: usize, entries: &[(u32, u32)]) -> Csr<u32> {
        let mut sorted = entries.to_vec();
        sorted.sort_by_key(|&(k, _)| k);
        let mut offsets = vec![0u32];
        for r in 0..num_rows as u32 {
            offsets.push(sorted.iter().filter(|&&(k, _)| k <= r).count() as u32);
        }
        Csr {
            offsets,
            values: sorted.into_iter().map(|(_, v)| v).collect(),
        }
    }

    /// A deterministic pseudo-random sequence (no dependency on a generator crate).
    fn lcg(seed: &mut u64) -> u32 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 33) as u32
    }

    #[test]
    fn matches_a_stable_sort_by_key() {
        let mut seed = 7;
        for num_rows in [1usize, 2, 5, 17, 100] {
            for len in [0usize, 1, 3, 50, 400] {
                // Keys from a smaller range than the rows leave trailing rows empty, and
                // values equal to the input position make any instability visible.
                let span = (num_rows / 2).max(1) as u32;
                let entries: Vec<(u32, u32)> = (0..len as u32)
                    .map(|i| (lcg(&mut seed) % span * 2 % num_rows as u32, i))
                    .collect();
                let got = group_by_key(num_rows, entries.iter().copied());
                assert_eq!(got, naive(num_rows, &entries), "{num_rows} rows, {len}");
                assert_eq!(got.num_rows(), num_rows);
            }
        }
    }

    #[test]
    fn parallel_sort_matches_the_serial_one_in_any_pool() {
        let mut seed = 11;
        for (num_rows, len) in [(0usize, 0usize), (1, 5), (7, 100_000), (50_000, 200_000)] {
            let keys: Vec<u32> = (0..len)
                .map(|_| lcg(&mut seed) % num_rows.max(1) as u32)
                .collect();
            let want = group_by_key(num_rows, keys.iter().copied().zip(0u32..));
            for threads in [1, 2, 4] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                let got = pool.install(|| par_group_indices(num_rows, len, |i| keys[i]));
                assert_eq!(
                    got, want,
                    "{num_rows} rows, {len} entries, {threads} threads"
                );
            }
        }
    }

    #[test]
    fn empty_rows_and_no_rows() {
        let got = group_by_key(4, [(3u32, 1u32), (0, 2), (3, 3)].into_iter());
        assert_eq!(got.offsets, [0, 1, 1, 1, 3]);
        assert!(got.row(1).is_empty() && got.row(2).is_empty());
        assert_eq!(got.row(3), [1, 3]);
        let none = group_by_key::<u32>(0, std::iter::empty());
        assert_eq!(none.offsets, [0]);
        assert!(none.values.is_empty());
        assert_eq!(offsets_of_keys(3, []), [0, 0, 0, 0]);
    }

    #[test]
    fn slots_fill_parallel_arrays_in_input_order() {
        let keys = [1u32, 0, 1, 1, 0];
        let offsets = offsets_of_keys(2, keys);
        let mut slots = RowSlots::new(&offsets);
        let taken: Vec<usize> = keys.iter().map(|&k| slots.take(k as usize)).collect();
        assert_eq!(taken, [2, 0, 3, 4, 1]);
    }
}
