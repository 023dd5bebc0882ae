//! A tessellation's samples evaluated on a patch table, with the basis computed once per
//! rate instead of once per sample.
//!
//! A uniform tessellation samples every root face (or sub-face) at `(i, j) / m`. A patch at
//! depth `d` spans `2^-d` of its root's side from a corner at integer multiples of that, so a
//! sample's coordinates in the patch are `(i 2^d − m p) / m`: again whole multiples of `1 / m`,
//! at every depth (a turned triangle's run backwards, still by whole steps). So the basis of
//! each patch type is a table over the `m + 1` (quads: per direction, the bicubic being a
//! tensor product) or `(m + 1)(m + 2) / 2` (triangles, and the patch types that are not
//! products) grid points, computed once; a sample looks its row up, and the control points
//! of a patch are gathered once for the run of samples that falls in it.
//!
//! A B-spline patch on a boundary gathers its phantom points (`2B − I`) instead of folding
//! them into the weights ([`super::basis`] folds the weights): the same sums, grouped
//! differently. Exact end caps take their samples after the rest of a chunk's, cap by cap:
//! Stam's corner pieces from weights tabulated the same way ([`super::cap_grid`]), the
//! others by their own evaluation (`super::exact_caps`), a cap refined locally sharing its
//! pieces between its samples.

use std::collections::HashMap;

use glam::DVec3;
use rayon::prelude::*;

use super::basis;
use super::cap_grid::CapGrids;
use super::grid::{MAX_TABLE_POINTS, grid_index, grid_points, grid_step, tabulated_first};
use super::table::{PatchTable, TablePoints};
use super::{PatchParam, PatchType};

use crate::LimitError;
use crate::evaluation::eval::FaceParam;

/// Samples per parallel job: many faces' worth, so that a face's run of samples is rarely
/// split.
const SAMPLE_CHUNK: usize = 4096;

/// A cubic B-spline's four values and four derivatives at one grid coordinate.
type CubicRow = [[f64; 4]; 2];

/// The basis of every patch type of a table on the grids of one rate.
struct GridBasis {
    /// Segments per side of a root face's grid (`rate`) and of a sub-face's (`rate / 2`).
    spans: [u32; 2],
    /// The cubic B-spline at `k / span`, `k = 0..=span`, per span.
    cubic: [Vec<CubicRow>; 2],
    /// Position, ∂s and ∂t weights (`3 n` per grid point) of the other tabulated types, by
    /// (type, boundary mask, span).
    tables: HashMap<(PatchType, u8, u32), Vec<f64>>,
    /// The exact caps' corner pieces on the same grids.
    caps: CapGrids,
}

impl GridBasis {
    fn new(table: &PatchTable, rate: u32) -> GridBasis {
        let spans = [rate, (rate / 2).max(1)];
        let cubic = spans.map(|m| {
            (0..=m)
                .map(|k| {
                    let (b, d, _) =
                        crate::evaluation::patch::bspline_basis(f64::from(k) / f64::from(m));
                    [b, d]
                })
                .collect()
        });
        let mut keys: Vec<(PatchType, u8, u32)> = Vec::new();
        for array in table.arrays() {
            if matches!(array.kind(), PatchType::Regular | PatchType::Exact) {
                continue;
            }
            for p in array.params() {
                let place = p.place();
                let boundary = if place.regular { place.boundary } else { 0 };
                let m = spans[usize::from(place.non_quad)];
                let key = (array.kind(), boundary, m);
                if grid_points_of(array.kind(), m) <= MAX_TABLE_POINTS && !keys.contains(&key) {
                    keys.push(key);
                }
            }
        }
        let tables = keys
            .into_par_iter()
            .map(|key| (key, tabulate(key.0, key.1, key.2)))
            .collect();
        GridBasis {
            spans,
            cubic,
            tables,
            caps: CapGrids::new(table, spans),
        }
    }
}

/// Whether a patch type lies on a triangle.
fn is_triangle(kind: PatchType) -> bool {
    matches!(
        kind,
        PatchType::Loop | PatchType::Triangles | PatchType::GregoryTriangle
    )
}

/// Grid points of span `m` on a patch of type `kind`.
fn grid_points_of(kind: PatchType, m: u32) -> usize {
    grid_points(is_triangle(kind), m)
}

/// The position, ∂s and ∂t weights of `kind` at every grid point of span `m`.
fn tabulate(kind: PatchType, boundary: u8, m: u32) -> Vec<f64> {
    let n = kind
        .num_control_points()
        .expect("a tabulated type has points");
    let triangle = is_triangle(kind);
    let mut out = vec![0.0; 3 * n * grid_points_of(kind, m)];
    for j in 0..=m {
        let last = if triangle { m - j } else { m };
        for i in 0..=last {
            let (s, t) = (f64::from(i) / f64::from(m), f64::from(j) / f64::from(m));
            let w = basis::weights(kind, s, t, boundary);
            let at = 3 * n * grid_index(triangle, m, i, j);
            for (r, row) in w.iter().take(3).enumerate() {
                out[at + r * n..at + (r + 1) * n].copy_from_slice(&row[..n]);
            }
        }
    }
    out
}

/// One thread's memory of the patch it met last: where it lies, its basis, its points.
struct Gathered {
    root: usize,
    patch: usize,
    /// The patch covers its whole root.
    whole: bool,
    /// Its array and index there.
    handle: (usize, usize),
    kind: PatchType,
    triangle: bool,
    rotated: bool,
    /// The boundary mask its basis folds in (0 for end caps).
    boundary: u8,
    /// `1 / fraction` and the corner, in patch units, of the map from the root.
    scale: f64,
    origin: (f64, f64),
    /// The grid's span on its root, and which of [`GridBasis::spans`] it is.
    span: u32,
    row: usize,
    /// A B-spline patch's points, phantoms in place.
    points: [DVec3; 16],
    /// The grid row `rows` holds (`u32::MAX`: none yet for this patch).
    row_step: u32,
    /// A B-spline patch's columns combined with one grid row's basis: position and ∂t
    /// (the tensor product's inner sums, shared by the row's samples).
    rows: [[DVec3; 4]; 2],
}

impl PatchTable {
    /// The position and unit normal (zero where the surface has no tangent plane) at every
    /// sample of a uniform tessellation at `rate`: `params` are `(i, j) / rate` of root faces
    /// and `(i, j) / (rate / 2)` of sub-faces, each face's samples together. Parallel in
    /// chunks; each sample's value depends on its parameter alone, so any number of threads
    /// gives the same bits.
    ///
    /// # Errors
    /// As [`Self::find`], for the first failing sample.
    pub(crate) fn evaluate_grid_samples(
        &self,
        pts: &TablePoints,
        params: &[FaceParam],
        rate: u32,
    ) -> Result<(Vec<DVec3>, Vec<DVec3>), LimitError> {
        let basis = GridBasis::new(self, rate);
        let mut positions = subd_mesh::memory::zeroed::<DVec3>(params.len());
        let mut normals = subd_mesh::memory::zeroed::<DVec3>(params.len());
        let failed = positions
            .par_chunks_mut(SAMPLE_CHUNK)
            .zip(normals.par_chunks_mut(SAMPLE_CHUNK))
            .zip(params.par_chunks(SAMPLE_CHUNK))
            .any(|((p, n), at)| {
                let mut gathered = Gathered::new();
                // Samples on exact caps, as (cap, sample): evaluated per cap after the rest.
                let mut on_caps = Vec::new();
                for k in 0..at.len() {
                    match self.grid_sample(pts, &basis, at[k], &mut gathered) {
                        Ok(Some(value)) => (p[k], n[k]) = value,
                        Ok(None) => on_caps.push((gathered.handle.1, k)),
                        Err(_) => return true,
                    }
                }
                self.cap_samples(pts, &basis, at, &mut on_caps, p, n)
                    .is_err()
            });
        if failed {
            // The first failing sample's error, not whichever a thread met first.
            let mut gathered = Gathered::new();
            let first = params.iter().find_map(|&at| {
                match self.grid_sample(pts, &basis, at, &mut gathered) {
                    Ok(None) => self.exact_position_normal(pts, gathered.handle.1, at).err(),
                    sample => sample.err(),
                }
            });
            return Err(first.unwrap_or_else(|| LimitError::Param("a sample failed".into())));
        }
        Ok((positions, normals))
    }

    /// The samples `on_caps` ((exact cap, index in `at`)) of one chunk, each cap's together
    /// (a cap refined locally shares its pieces between them), into `p` and `n`.
    fn cap_samples(
        &self,
        pts: &TablePoints,
        basis: &GridBasis,
        at: &[FaceParam],
        on_caps: &mut [(usize, usize)],
        p: &mut [DVec3],
        n: &mut [DVec3],
    ) -> Result<(), LimitError> {
        on_caps.sort_unstable();
        let exact = self.exact_caps().map(|(_, a)| &self.arrays()[a]);
        for run in on_caps.chunk_by(|a, b| a.0 == b.0) {
            let cap = run[0].0;
            let places: Vec<FaceParam> = run.iter().map(|&(_, k)| at[k]).collect();
            let span = exact.map(|e| basis.spans[usize::from(e.params()[cap].place().non_quad)]);
            let tabulated = span.and_then(|m| basis.caps.samples(self, pts, cap, &places, m));
            let values = match tabulated {
                Some(values) => values,
                None => self.exact_position_normals(pts, cap, &places)?,
            };
            for (&(_, k), value) in run.iter().zip(values) {
                (p[k], n[k]) = value;
            }
        }
        Ok(())
    }

    /// One sample's position and normal; `None` for a sample on an exact cap (the cap is
    /// `cur.handle.1`), which [`Self::cap_samples`] evaluates.
    fn grid_sample(
        &self,
        pts: &TablePoints,
        basis: &GridBasis,
        at: FaceParam,
        cur: &mut Gathered,
    ) -> Result<Option<(DVec3, DVec3)>, LimitError> {
        let root = self.root_of(&at);
        // A patch covering its whole root (depth 0) holds every sample of it: no search.
        if root != cur.root || !cur.whole {
            let (patch, a, i) = self.locate(&at)?;
            if patch != cur.patch {
                cur.enter(self, pts, basis, patch, a, i);
            }
            cur.root = root;
        }
        let (s, t) = cur.local(at.u, at.v);
        let m = cur.span;
        let steps = grid_step(s, m).zip(grid_step(t, m));
        let (p, du, dv) = match (cur.kind, steps) {
            (PatchType::Exact, _) => return Ok(None),
            (PatchType::Regular, Some((ks, kt))) => {
                if cur.row_step != kt {
                    cur.rows = cubic_rows(&cur.points, &basis.cubic[cur.row][kt as usize]);
                    cur.row_step = kt;
                }
                cubic_across(&cur.rows, &basis.cubic[cur.row][ks as usize])
            }
            (kind, Some((ks, kt))) if !cur.triangle || ks + kt <= m => {
                let (a, i) = cur.handle;
                let cps = self.arrays()[a].patch_points(i);
                match basis.tables.get(&(kind, cur.boundary, m)) {
                    Some(w) => {
                        let n = cps.len();
                        let at = 3 * n * grid_index(cur.triangle, m, ks, kt);
                        tabulated_first(&w[at..at + 3 * n], cps, &pts.points)
                    }
                    None => return self.position_normal(pts, at).map(Some),
                }
            }
            _ => return self.position_normal(pts, at).map(Some),
        };
        // Derivatives in the patch's own parameters: the map to the root's scales both by
        // the same factor (negated for a turned triangle), which leaves the normal as it is.
        Ok(Some((p, du.cross(dv).normalize_or_zero())))
    }

    /// Position and normal at `at`, found and evaluated on its own.
    fn position_normal(
        &self,
        pts: &TablePoints,
        at: FaceParam,
    ) -> Result<(DVec3, DVec3), LimitError> {
        self.evaluate_on(pts, at).map(|p| (p.position, p.normal()))
    }
}

impl Gathered {
    fn new() -> Gathered {
        Gathered {
            root: usize::MAX,
            patch: usize::MAX,
            whole: false,
            handle: (0, 0),
            kind: PatchType::Exact,
            triangle: false,
            rotated: false,
            boundary: 0,
            scale: 1.0,
            origin: (0.0, 0.0),
            span: 1,
            row: 0,
            points: [DVec3::ZERO; 16],
            row_step: u32::MAX,
            rows: [[DVec3::ZERO; 4]; 2],
        }
    }

    /// Takes patch `patch` (array `a`, index `i`) as the current one.
    fn enter(
        &mut self,
        table: &PatchTable,
        pts: &TablePoints,
        basis: &GridBasis,
        patch: usize,
        a: usize,
        i: usize,
    ) {
        let array = &table.arrays()[a];
        let param = array.params()[i];
        let place = param.place();
        self.patch = patch;
        self.handle = (a, i);
        self.kind = array.kind();
        self.triangle = is_triangle(self.kind);
        self.rotated = self.triangle && param.is_triangle_rotated();
        self.whole = place.depth == u8::from(place.non_quad);
        self.boundary = if place.regular { place.boundary } else { 0 };
        self.row = usize::from(place.non_quad);
        self.span = basis.spans[self.row];
        self.scale = 1.0 / param.fraction();
        self.origin = (f64::from(place.u), f64::from(place.v));
        if self.kind == PatchType::Regular {
            self.points = bspline_points(param, array.patch_points(i), &pts.points);
            self.row_step = u32::MAX;
        }
    }

    /// `(u, v)` of the root in the current patch's own domain (as
    /// [`PatchParam::normalize`] and [`PatchParam::normalize_triangle`]).
    fn local(&self, u: f64, v: f64) -> (f64, f64) {
        if self.rotated {
            let side = self.scale;
            (
                (side - self.origin.0) - u * side,
                (side - self.origin.1) - v * side,
            )
        } else {
            (
                u * self.scale - self.origin.0,
                v * self.scale - self.origin.1,
            )
        }
    }
}

/// The 16 points of a B-spline patch, with the phantom points of a regular patch's boundary
/// (`2B − I`, the end condition [`super::basis`] folds into its weights) in place of the
/// missing rows and columns.
fn bspline_points(param: PatchParam, cps: &[u32], points: &[DVec3]) -> [DVec3; 16] {
    let mut p: [DVec3; 16] = std::array::from_fn(|k| points[cps[k] as usize]);
    let place = param.place();
    let boundary = if place.regular { place.boundary } else { 0 };
    // The weights fold the sides in the order 0, 1, 2, 3, so the points take them in the
    // reverse order.
    for bit in (0..4).rev() {
        if boundary & (1 << bit) != 0 {
            for k in 0..4 {
                let (m, b, i) = basis::bspline_side(bit, k);
                p[m] = 2.0 * p[b] - p[i];
            }
        }
    }
    p
}

/// The inner sums of a bicubic B-spline at one grid row: each column of its 16 points
/// (row-major, 4 × 4) combined with the row parameter's values (position) and derivatives
/// (∂t).
fn cubic_rows(p: &[DVec3; 16], t: &CubicRow) -> [[DVec3; 4]; 2] {
    let column =
        |c: usize, w: &[f64; 4]| w[0] * p[c] + w[1] * p[4 + c] + w[2] * p[8 + c] + w[3] * p[12 + c];
    [
        std::array::from_fn(|c| column(c, &t[0])),
        std::array::from_fn(|c| column(c, &t[1])),
    ]
}

/// A bicubic B-spline's position and first derivatives at one sample of a grid row from the
/// row's inner sums ([`cubic_rows`]) and the basis of its column parameter.
fn cubic_across(rows: &[[DVec3; 4]; 2], s: &CubicRow) -> (DVec3, DVec3, DVec3) {
    let [pos, dt] = rows;
    let sum = |w: &[f64; 4], x: &[DVec3; 4]| w[0] * x[0] + w[1] * x[1] + w[2] * x[2] + w[3] * x[3];
    (sum(&s[0], pos), sum(&s[1], pos), sum(&s[0], dt))
}
