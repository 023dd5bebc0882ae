//! [`StencilTable`]: refinement as a sparse matrix.

use glam::DVec3;
use rayon::prelude::*;

use subd_mesh::memory;

/// Rows per parallel task: large enough to amortise scheduling, small enough to balance.
const CHUNK_ROWS: usize = 4096;

/// One chunk of rows of a table being built: row sizes, sources, weights.
type Chunk = (Vec<u32>, Vec<u32>, Vec<f64>);

/// A sparse matrix in compressed-sparse-row form: row `i` gives child value `i` as a weighted
/// sum of source values, `child[i] = Σ_k weights[k] · source[indices[k]]`.
///
/// A refinement produces one table per level (child level from parent level) and can compose
/// them into one table from the base mesh to any level. Applying a table works for any
/// per-vertex data with any number of `f64` components (positions, UVs, colours) and for a
/// batch of frames; the topology is refined once and the table re-applied.
///
/// Rows are evaluated independently, so applying a table gives bit-identical results with one
/// or many threads.
///
/// ```
/// use subd_schemes::StencilTable;
/// // Two children: the midpoint of sources 0 and 1, and source 2 itself.
/// let t = StencilTable::from_rows(3, &[vec![(0, 0.5), (1, 0.5)], vec![(2, 1.0)]]);
/// let mut out = vec![0.0; 2];
/// t.apply(&[1.0, 3.0, 7.0], 1, &mut out);
/// assert_eq!(out, [2.0, 7.0]);
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StencilTable {
    num_sources: usize,
    offsets: Vec<u32>,
    indices: Vec<u32>,
    weights: Vec<f64>,
}

impl StencilTable {
    /// Builds a table from CSR arrays. `offsets` has one entry more than there are rows.
    ///
    /// # Panics
    /// If the arrays are inconsistent (a programming error, not an input error).
    pub fn from_csr(
        num_sources: usize,
        offsets: Vec<u32>,
        indices: Vec<u32>,
        weights: Vec<f64>,
    ) -> Self {
        assert!(
            !offsets.is_empty() && offsets[0] == 0,
            "offsets must start at 0"
        );
        assert_eq!(
            *offsets.last().unwrap() as usize,
            indices.len(),
            "offsets/indices length"
        );
        assert_eq!(indices.len(), weights.len(), "indices/weights length");
        assert!(
            indices.iter().all(|&i| (i as usize) < num_sources),
            "source index out of range"
        );
        StencilTable {
            num_sources,
            offsets,
            indices,
            weights,
        }
    }

    /// Builds a table from rows of `(source, weight)` pairs.
    pub fn from_rows(num_sources: usize, rows: &[Vec<(u32, f64)>]) -> Self {
        let mut offsets = Vec::with_capacity(rows.len() + 1);
        offsets.push(0);
        let mut indices = Vec::new();
        let mut weights = Vec::new();
        for r in rows {
            for &(i, w) in r {
                indices.push(i);
                weights.push(w);
            }
            offsets.push(indices.len() as u32);
        }
        StencilTable::from_csr(num_sources, offsets, indices, weights)
    }

    /// The identity on `n` sources.
    pub fn identity(n: usize) -> Self {
        StencilTable {
            num_sources: n,
            offsets: (0..=n as u32).collect(),
            indices: (0..n as u32).collect(),
            weights: vec![1.0; n],
        }
    }

    /// Number of rows (child values).
    pub fn num_rows(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Number of source values a row may refer to.
    pub fn num_sources(&self) -> usize {
        self.num_sources
    }

    /// Total number of (source, weight) entries.
    pub fn num_entries(&self) -> usize {
        self.indices.len()
    }

    /// Row `i`: its source indices and weights.
    pub fn row(&self, i: usize) -> (&[u32], &[f64]) {
        let r = self.offsets[i] as usize..self.offsets[i + 1] as usize;
        (&self.indices[r.clone()], &self.weights[r])
    }

    /// Row offsets (CSR), length `num_rows + 1`.
    pub fn offsets(&self) -> &[u32] {
        &self.offsets
    }

    /// Source indices of all rows (CSR).
    pub fn indices(&self) -> &[u32] {
        &self.indices
    }

    /// Weights of all rows (CSR).
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// Applies the table to `src`, `dims` components per value (`src.len() == dims ·
    /// num_sources`), writing `dims · num_rows` values into `dst`. Parallel over rows.
    ///
    /// # Panics
    /// If the slice lengths do not match.
    pub fn apply(&self, src: &[f64], dims: usize, dst: &mut [f64]) {
        assert_eq!(src.len(), dims * self.num_sources, "source length");
        assert_eq!(dst.len(), dims * self.num_rows(), "destination length");
        if dims == 0 {
            return;
        }
        dst.par_chunks_mut(CHUNK_ROWS * dims)
            .enumerate()
            .for_each(|(chunk, out)| {
                let first = chunk * CHUNK_ROWS;
                for (r, o) in out.chunks_exact_mut(dims).enumerate() {
                    let (idx, w) = self.row(first + r);
                    o.fill(0.0);
                    for (&i, &wk) in idx.iter().zip(w) {
                        let s = &src[i as usize * dims..(i as usize + 1) * dims];
                        for (x, y) in o.iter_mut().zip(s) {
                            *x += wk * y;
                        }
                    }
                }
            });
    }

    /// Applies the table to points.
    pub fn apply_points(&self, src: &[DVec3]) -> Vec<DVec3> {
        assert_eq!(src.len(), self.num_sources, "source length");
        let mut out = vec![DVec3::ZERO; self.num_rows()];
        out.par_chunks_mut(CHUNK_ROWS)
            .enumerate()
            .for_each(|(chunk, o)| {
                let first = chunk * CHUNK_ROWS;
                for (r, p) in o.iter_mut().enumerate() {
                    let (idx, w) = self.row(first + r);
                    let mut acc = DVec3::ZERO;
                    for (&i, &wk) in idx.iter().zip(w) {
                        acc += wk * src[i as usize];
                    }
                    *p = acc;
                }
            });
        out
    }

    /// The table of `next ∘ self`: rows of `next` expressed in terms of `self`'s sources.
    /// Entries are merged per source in order of first appearance, so the result does not
    /// depend on the number of threads.
    ///
    /// # Panics
    /// If `next.num_sources() != self.num_rows()`.
    pub fn then(&self, next: &StencilTable) -> StencilTable {
        assert_eq!(next.num_sources, self.num_rows(), "tables do not chain");
        StencilTable::build(next.num_rows(), self.num_sources, |r, sink| {
            let (ni, nw) = next.row(r);
            for (&m, &a) in ni.iter().zip(nw) {
                let (si, sw) = self.row(m as usize);
                for (&s, &b) in si.iter().zip(sw) {
                    sink.add(s, a * b);
                }
            }
        })
    }
}

/// Accumulates one stencil row, merging repeated sources (entries keep the order in which
/// sources first appear). Handed to the closure of [`StencilTable::build`].
pub struct RowSink<'a> {
    stamp: &'a mut [u32],
    pos: &'a mut [u32],
    row: u32,
    indices: &'a mut Vec<u32>,
    weights: &'a mut Vec<f64>,
}

impl RowSink<'_> {
    /// Adds `weight · source[index]` to the row.
    #[inline]
    pub fn add(&mut self, index: u32, weight: f64) {
        let i = index as usize;
        if self.stamp[i] == self.row {
            self.weights[self.pos[i] as usize] += weight;
        } else {
            self.stamp[i] = self.row;
            self.pos[i] = self.indices.len() as u32;
            self.indices.push(index);
            self.weights.push(weight);
        }
    }
}

impl StencilTable {
    /// Builds a table of `num_rows` rows over `num_sources` sources, row `r` filled by
    /// `fill(r, sink)`. Rows are built in parallel chunks and concatenated in order, so the
    /// table does not depend on the number of threads.
    pub fn build<F>(num_rows: usize, num_sources: usize, fill: F) -> StencilTable
    where
        F: Fn(usize, &mut RowSink) + Sync,
    {
        let num_chunks = num_rows.div_ceil(CHUNK_ROWS);
        // A few runs of consecutive chunks per thread, each with one scratch pair over the
        // sources (`map_init` would allocate and clear one per rayon job, many more than
        // threads); the chunks themselves, not the runs, fix the output.
        let per_run = num_chunks.div_ceil(2 * rayon::current_num_threads()).max(1);
        let runs: Vec<Vec<Chunk>> = (0..num_chunks.div_ceil(per_run))
            .into_par_iter()
            .map(|run| {
                let (mut stamp, mut pos) = (vec![u32::MAX; num_sources], vec![0u32; num_sources]);
                (run * per_run..((run + 1) * per_run).min(num_chunks))
                    .map(|c| {
                        let rows = c * CHUNK_ROWS..((c + 1) * CHUNK_ROWS).min(num_rows);
                        let mut counts = Vec::with_capacity(rows.len());
                        let mut indices = Vec::with_capacity(rows.len() * 8);
                        let mut weights = Vec::with_capacity(rows.len() * 8);
                        for r in rows {
                            let start = indices.len();
                            let mut sink = RowSink {
                                stamp: &mut stamp,
                                pos: &mut pos,
                                row: r as u32,
                                indices: &mut indices,
                                weights: &mut weights,
                            };
                            fill(r, &mut sink);
                            counts.push((indices.len() - start) as u32);
                        }
                        (counts, indices, weights)
                    })
                    .collect()
            })
            .collect();
        let chunks: Vec<Chunk> = runs.into_iter().flatten().collect();
        // The chunks are copied into the final arrays in parallel, each into its own piece
        // (a sequential copy was a fifth of a 100k-row table's build, most of it page
        // faults on the fresh arrays, which `memory::zeroed` takes in huge pages).
        let total: usize = chunks.iter().map(|c| c.1.len()).sum();
        let mut offsets: Vec<u32> = memory::zeroed(num_rows + 1);
        let mut indices: Vec<u32> = memory::zeroed(total);
        let mut weights: Vec<f64> = memory::zeroed(total);
        let mut pieces = Vec::with_capacity(chunks.len());
        let (mut o_rest, mut i_rest, mut w_rest) =
            (&mut offsets[1..], &mut indices[..], &mut weights[..]);
        let mut first = 0u32;
        for (counts, idx, _) in &chunks {
            let (o, o_next) = std::mem::take(&mut o_rest).split_at_mut(counts.len());
            let (i, i_next) = std::mem::take(&mut i_rest).split_at_mut(idx.len());
            let (w, w_next) = std::mem::take(&mut w_rest).split_at_mut(idx.len());
            (o_rest, i_rest, w_rest) = (o_next, i_next, w_next);
            pieces.push((first, o, i, w));
            first += idx.len() as u32;
        }
        pieces.into_par_iter().zip(chunks.par_iter()).for_each(
            |((first, o, i, w), (counts, idx, wts))| {
                i.copy_from_slice(idx);
                w.copy_from_slice(wts);
                let mut end = first;
                for (slot, &c) in o.iter_mut().zip(counts) {
                    end += c;
                    *slot = end;
                }
            },
        );
        StencilTable {
            num_sources,
            offsets,
            indices,
            weights,
        }
    }
}
