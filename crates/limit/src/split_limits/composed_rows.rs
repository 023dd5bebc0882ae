//! Rows of a refinement's stencils composed back to its level 0, for the vertices asked for
//! only.
//!
//! [`Refinement::composed`] composes every vertex of a level: at level 2 of a 300k-vertex
//! piece that is millions of rows of ~12 entries, when the split schemes' limit masks read
//! the balls of a few thousand vertices. Here a row is composed on its first request, from
//! the rows of the level above it that its stencil reads, and kept. Each row is the sum
//! [`subd_schemes::StencilTable::then`] forms (the same products, added in the same order,
//! repeated sources merged where they first appear), so the rows are those of
//! [`Refinement::composed`] bit for bit.

use std::collections::HashMap;

use subd_schemes::Refinement;

/// A sparse row: `(source, weight)` in order of first appearance.
pub(crate) type Row = Vec<(u32, f64)>;

/// The composed rows of one refinement, filled on request.
pub(crate) struct ComposedRows<'r> {
    r: &'r Refinement,
    /// `rows[l - 1]`: the composed rows of the vertices of level `l` asked for so far.
    rows: Vec<HashMap<u32, Row>>,
    /// Where each level-0 vertex sits in the row being summed (valid where `stamp` holds
    /// the current row's number), as `then`'s row sink keeps it; made on the first row
    /// composed (a chunk of vertices whose masks apply at level 0 composes none).
    stamp: Vec<u32>,
    pos: Vec<u32>,
    current: u32,
    /// Vertices of level 0.
    sources: usize,
}

impl<'r> ComposedRows<'r> {
    /// No row composed yet.
    pub(crate) fn new(r: &'r Refinement) -> Self {
        ComposedRows {
            r,
            rows: (0..r.num_levels()).map(|_| HashMap::new()).collect(),
            stamp: Vec::new(),
            pos: Vec::new(),
            current: 0,
            sources: r.num_vertices(0),
        }
    }

    /// `row`, over the vertices of `level` (`≥ 1`), as a row over level 0: what
    /// [`crate::split_eigen::expand_row`] gives through `r.composed(level)`.
    pub(crate) fn over_level_zero(&mut self, row: &[(u32, f64)], level: usize) -> Row {
        for &(v, _) in row {
            self.compose(level, v);
        }
        // `expand_row`'s sums (each starting at 0.0), merged through the stamps rather than
        // a hash map.
        let current = self.next_stamp();
        let (stamp, pos) = (&mut self.stamp, &mut self.pos);
        let mut out: Row = Vec::new();
        for &(v, w) in row {
            for &(s, b) in &self.rows[level - 1][&v] {
                let i = s as usize;
                if stamp[i] != current {
                    stamp[i] = current;
                    pos[i] = out.len() as u32;
                    out.push((s, 0.0));
                }
                out[pos[i] as usize].1 += w * b;
            }
        }
        out
    }

    /// A stamp no entry holds yet (on wrapping round, the stamps are cleared once).
    fn next_stamp(&mut self) -> u32 {
        if self.stamp.is_empty() {
            self.stamp = vec![u32::MAX; self.sources];
            self.pos = vec![0; self.sources];
        }
        self.current = self.current.wrapping_add(1);
        if self.current == u32::MAX {
            self.stamp.fill(u32::MAX);
            self.current = 0;
        }
        self.current
    }

    /// Composes (once) the row of vertex `v` of `level`, and first those of the vertices of
    /// the level above that its stencil reads.
    fn compose(&mut self, level: usize, v: u32) {
        if self.rows[level - 1].contains_key(&v) {
            return;
        }
        let (sources, weights) = self.r.stencils(level).row(v as usize);
        if level > 1 {
            for &m in sources {
                self.compose(level - 1, m);
            }
        }
        let row = self.sum(level, sources, weights);
        self.rows[level - 1].insert(v, row);
    }

    /// `Σ a · (composed row of m)` over the stencil `(sources, weights)` of a vertex of
    /// `level`, merged as `then`'s row sink merges (level 1 reads the identity).
    fn sum(&mut self, level: usize, sources: &[u32], weights: &[f64]) -> Row {
        let current = self.next_stamp();
        let mut out: Row = Vec::new();
        let (stamp, pos) = (&mut self.stamp, &mut self.pos);
        let mut add = |s: u32, w: f64| {
            let i = s as usize;
            if stamp[i] == current {
                out[pos[i] as usize].1 += w;
            } else {
                stamp[i] = current;
                pos[i] = out.len() as u32;
                out.push((s, w));
            }
        };
        for (&m, &a) in sources.iter().zip(weights) {
            if level == 1 {
                // The identity's row of `m`: `a · 1`, which is `a`.
                add(m, a);
            } else {
                for &(s, b) in &self.rows[level - 2][&m] {
                    add(s, a * b);
                }
            }
        }
        out
    }
}
