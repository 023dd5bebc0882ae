//! Compressed-row (CSR) adjacency built by a stable counting sort: count the entries of each
//! row, turn the counts into row offsets by a prefix sum, then scatter every entry into the
//! next free slot of its row.
//!
//! The scatter visits entries in input order, so each row lists its entries in the order
//! they were given (the sort is stable); rows with no entry are empty ranges. Everything is
//! linear in rows + entries and allocates the offsets, one cursor array and the values, never
//! anything per entry. [`offsets_of_keys`] and [`RowSlots`] are the two steps for callers that
//! scatter into several parallel arrays at once; [`group_by_key`] does both for one array.
//!
//! ```
//! use subd_mesh::csr::group_by_key;
//! // Entries 'a'..'e' keyed by row; row 1 is empty.
//! let rows = group_by_key(3, [(2, 'a'), (0, 'b'), (2, 'c'), (0, 'd'), (2, 'e')].into_iter());
//! assert_eq!(rows.offsets, [0, 2, 2, 5]);
//! assert_eq!(rows.row(0), ['b', 'd']);
//! assert_eq!(rows.row(2), ['a', 'c', 'e']);
//! ```

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
