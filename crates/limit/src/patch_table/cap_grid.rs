//! A tessellation's samples on Stam's corner pieces (the exact caps with one extraordinary
//! corner) as fixed weights of their control points.
//!
//! A corner piece's value at a place is linear in its control points, with coefficients
//! that depend only on the valence, the corner and the place (Stam 1998, "Exact evaluation
//! of Catmull-Clark subdivision surfaces at arbitrary parameter values", and his Loop
//! counterpart: the eigenbasis functions are fixed once the valence is). A tessellation
//! meets each piece only at the grid points of one span (see [`super::grid_samples`]), so
//! the weights of every grid point are computed once per (corner, valence, span), and each
//! sample is one weighted sum of the piece's points, as on the regular patches, instead of
//! an eigenbasis evaluation.

use std::collections::HashMap;

use glam::DVec3;
use rayon::prelude::*;
use subd_schemes::Scheme;

use super::exact_caps::patch_local;
use super::grid::{MAX_TABLE_POINTS, grid_index, grid_points, grid_step, tabulated_first};
use super::table::{PatchTable, TablePoints};
use crate::evaluation::eval::FaceParam;
use crate::evaluation::patch::Derivatives;
use crate::evaluation::piece::{Piece, eval_piece_to, project};

/// A corner piece's grid: its corner, its number of control points and the span.
type Key = (usize, usize, u32);

/// The weights of every corner piece of a table on the grids of one rate: position, ∂s
/// and ∂t weights (`3 n` per grid point, as [`super::grid_samples`]'s tables), by [`Key`].
pub(super) struct CapGrids {
    tables: HashMap<Key, Vec<f64>>,
    /// The table's pieces lie on triangles (Loop).
    triangle: bool,
}

/// The corner and control points of a corner piece.
fn corner_and_points(piece: &Piece) -> Option<(usize, &[u32])> {
    match piece {
        Piece::Corner { corner, cp, .. } | Piece::LoopCorner { corner, cp, .. } => {
            Some((*corner, cp))
        }
        _ => None,
    }
}

impl CapGrids {
    /// The grids of `table`'s corner pieces at the spans `spans` (of a root face, of a
    /// sub-face).
    pub(super) fn new(table: &PatchTable, spans: [u32; 2]) -> CapGrids {
        let triangle = *table.scheme() == Scheme::Loop;
        let mut pieces: Vec<(Key, &Piece)> = Vec::new();
        if let Some((caps, a)) = table.exact_caps() {
            for (i, param) in table.arrays()[a].params().iter().enumerate() {
                let Some((_, piece)) = caps.corner_piece(i) else {
                    continue;
                };
                let Some((corner, cp)) = corner_and_points(piece) else {
                    continue;
                };
                let m = spans[usize::from(param.place().non_quad)];
                let key = (corner, cp.len(), m);
                if grid_points(triangle, m) <= MAX_TABLE_POINTS
                    && !pieces.iter().any(|(k, _)| *k == key)
                {
                    pieces.push((key, piece));
                }
            }
        }
        let tables = pieces
            .into_par_iter()
            .filter_map(|(key, piece)| Some((key, tabulate(piece, key, triangle)?)))
            .collect();
        CapGrids { tables, triangle }
    }

    /// Position and unit normal of every place of `ats` on exact cap `cap`, from its grid:
    /// `None` when the cap is not a corner piece or a place is off the grid of span `m`.
    pub(super) fn samples(
        &self,
        table: &PatchTable,
        pts: &TablePoints,
        cap: usize,
        ats: &[FaceParam],
        m: u32,
    ) -> Option<Vec<(DVec3, DVec3)>> {
        let (caps, a) = table.exact_caps()?;
        let (level, piece) = caps.corner_piece(cap)?;
        let (corner, cp) = corner_and_points(piece)?;
        let n = cp.len();
        let weights = self.tables.get(&(corner, n, m))?;
        let param = table.arrays()[a].params()[cap];
        let points = &pts.points[table.level_offset(level) as usize..];
        ats.iter()
            .map(|at| {
                let (s, t, _) = patch_local(param, self.triangle, at.u, at.v);
                let (ks, kt) = grid_step(s, m).zip(grid_step(t, m))?;
                if self.triangle && ks + kt > m {
                    return None;
                }
                let first = 3 * n * grid_index(self.triangle, m, ks, kt);
                let (p, du, dv) = tabulated_first(&weights[first..first + 3 * n], cp, points);
                // The map from the root scales both derivatives alike (a turned triangle
                // negates both): the normal is the piece's own.
                Some((p, du.cross(dv).normalize_or_zero()))
            })
            .collect()
    }
}

/// The weights of corner piece `piece` (its [`Key`]) at every grid point: the piece
/// evaluated with unit control points, three at a time (one per coordinate).
fn tabulate(piece: &Piece, (_, n, m): Key, triangle: bool) -> Option<Vec<f64>> {
    let numbered: Vec<u32> = (0..n as u32).collect();
    let unit = match piece {
        Piece::Corner {
            corner, matrices, ..
        } => Piece::Corner {
            corner: *corner,
            cp: numbered,
            matrices: matrices.clone(),
        },
        Piece::LoopCorner {
            corner, matrices, ..
        } => Piece::LoopCorner {
            corner: *corner,
            cp: numbered,
            matrices: matrices.clone(),
        },
        _ => return None,
    };
    let mut out = vec![0.0; 3 * n * grid_points(triangle, m)];
    for first in (0..n).step_by(3) {
        let width = 3.min(n - first);
        let mut pts = vec![DVec3::ZERO; n];
        for c in 0..width {
            pts[first + c][c] = 1.0;
        }
        let projected = project(&unit, &pts);
        for j in 0..=m {
            let last = if triangle { m - j } else { m };
            for i in 0..=last {
                let st = (f64::from(i) / f64::from(m), f64::from(j) / f64::from(m));
                let p = eval_piece_to(&unit, &pts, projected.as_ref(), 0, st, Derivatives::First)
                    .ok()?;
                let at = 3 * n * grid_index(triangle, m, i, j);
                for c in 0..width {
                    out[at + first + c] = p.position[c];
                    out[at + n + first + c] = p.du[c];
                    out[at + 2 * n + first + c] = p.dv[c];
                }
            }
        }
    }
    Some(out)
}
