//! Limits of face-varying values (UVs): OpenSubdiv's `PrimvarRefiner::LimitFaceVarying`
//! (digest: `docs/opensubdiv-face-varying.md` §5), with exact weights.
//!
//! A value that follows the geometry (its vertex has one value and no seam) takes its
//! vertex's limit mask, read over values: the face terms at the corner opposite the vertex,
//! the edge terms at the edge's far end, the centre at the value itself. A seam value refined
//! with the crease rule takes the cubic B-spline's limit along its seam,
//! `(e₀ + 4 v + e₁) / 6` over its two crease ends; a pinned (corner) value, and every value of
//! a linear channel (mode `all`) or of Bilinear, is its own limit.
//!
//! Where this differs from OpenSubdiv, OpenSubdiv is the one off:
//! * it writes the seam weights as `float` literals (`1.0f/6.0f`, `2.0f/3.0f`), about 3e-8
//!   from 1/6 and 2/3 even in a double-precision refiner;
//! * it applies that seam mask under Bilinear too, whose refinement of every value is
//!   linear, so the limit of a Bilinear refinement is the value itself;
//! * at interior Catmull-Clark vertices of valence 2 and darts on infinitely sharp edges it
//!   uses closed forms that are not the limit there; subd takes the eigen limit, as for
//!   positions ([`crate::eigen_limit_vertices`]).

use std::ops::Range;

use subd_mesh::Topology;
use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};
use subd_schemes::{FaceVaryingRefinement, Options, Refinement, Scheme, StencilTable};

use crate::LimitError;
use crate::limit_masks::table::{LevelMasks, ring_terms_by};

/// The cubic B-spline's limit along a crease: the ends' weight and the centre's.
const CREASE_END: f64 = 1.0 / 6.0;
const CREASE_CENTRE: f64 = 2.0 / 3.0;

/// Limit stencils of every value of `level` (at least 1) of a channel refined with
/// `refinement`, over the values of that level (see the module [`crate::fvar`]).
///
/// # Errors
/// [`LimitError::Param`] for level 0 (its values are the channel's own, which a vertex may
/// share with others: take [`base_fvar_limit`]), and the errors of the position limit masks
/// at that level ([`crate::LimitStencilTable::at_level`]).
pub fn limit_at_level(
    refinement: &Refinement,
    fvar: &FaceVaryingRefinement,
    level: usize,
) -> Result<StencilTable, LimitError> {
    if level == 0 || level > refinement.num_levels() {
        return Err(LimitError::Param(format!(
            "face-varying limits are taken at a refined level (1 to {}), not {level}",
            refinement.num_levels()
        )));
    }
    let n = fvar.num_values(level);
    let values = fvar.level_values(refinement, level);
    if values.is_linear() || *refinement.scheme() == Scheme::Bilinear {
        return Ok(StencilTable::identity(n));
    }
    let t = refinement.topology(level);
    let masks = LevelMasks::new(refinement, level)?;
    // The vertex and sibling of each value (values are numbered vertex by vertex).
    let mut owner = Vec::with_capacity(n);
    for v in 0..t.num_vertices() {
        for k in 0..values.num_vertex_values(v) {
            owner.push((v as u32, k as u16));
        }
    }
    Ok(StencilTable::build(n, n, |r, sink| {
        let (v, k) = (owner[r].0 as usize, owner[r].1 as usize);
        let own = values.vertex_value(v, k);
        if t.vertex_edges(v).is_empty() {
            sink.add(own, 1.0);
        } else if values.is_matching(v) {
            ring_terms_by(
                t,
                v,
                &masks.of(v).position,
                |f, c| values.corner_value(f, c),
                |e| values.far_value(e, v as u32),
                own,
                |i, w| sink.add(i, w),
            );
        } else if let Some([a, b]) = values.crease_ends(v, k) {
            sink.add(a, CREASE_END);
            sink.add(b, CREASE_END);
            sink.add(own, CREASE_CENTRE);
        } else {
            sink.add(own, 1.0);
        }
    }))
}

/// Limit stencils of a channel at the last level of `refinement`, applied to that level's
/// values (`components` numbers each): the values' limits, in the same layout.
///
/// # Errors
/// As [`limit_at_level`] at the last level.
pub fn limit_values(
    refinement: &Refinement,
    fvar: &FaceVaryingRefinement,
    values: &[f64],
    components: usize,
) -> Result<Vec<f64>, LimitError> {
    let table = limit_at_level(refinement, fvar, refinement.num_levels())?;
    let mut out = vec![0.0; values.len()];
    table.apply(values, components, &mut out);
    Ok(out)
}

/// The exact limit of every value of every base vertex of a channel: one row per (vertex,
/// value) pair, vertex after vertex, over the channel's values.
#[derive(Debug, Clone)]
pub struct BaseFVarLimit {
    /// Where each base vertex's rows start (one more entry than vertices).
    offsets: Vec<u32>,
    /// The channel value of each row.
    values: Vec<u32>,
    /// Limit stencils over the channel's values.
    pub table: StencilTable,
}

impl BaseFVarLimit {
    /// The rows of base vertex `v`, one per distinct value its corners name (in
    /// OpenSubdiv's sibling order).
    pub fn vertex_rows(&self, v: usize) -> Range<usize> {
        self.offsets[v] as usize..self.offsets[v + 1] as usize
    }

    /// The channel value whose limit row `r` is.
    pub fn value(&self, r: usize) -> u32 {
        self.values[r]
    }

    /// Number of rows.
    pub fn num_rows(&self) -> usize {
        self.values.len()
    }

    /// The limits of `values` (`components` numbers per channel value), a row at a time.
    pub fn apply(&self, values: &[f64], components: usize) -> Vec<f64> {
        let mut out = vec![0.0; self.num_rows() * components];
        self.table.apply(values, components, &mut out);
        out
    }
}

/// The exact limit of every base vertex's values of `channel` on `topology`, interpolated
/// by `mode`: refined until semi-sharp features have decayed (at least one level, so that
/// Catmull-Clark faces are quads and each value is its vertex's own), the limit masks taken
/// there ([`limit_at_level`]) and composed back to the channel's values. Base vertex `v` is
/// vertex `v` at every level, with the same values.
///
/// ```
/// use subd_mesh::TopologyBuilder;
/// use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};
/// use subd_schemes::{Options, Scheme};
///
/// // A 3x3 grid of quads whose UVs are the positions: a seamless planar layout.
/// let mut faces = Vec::new();
/// for i in 0..3u32 {
///     for j in 0..3u32 {
///         let a = 4 * i + j;
///         faces.extend([a, a + 1, a + 5, a + 4]);
///     }
/// }
/// let grid = TopologyBuilder::new(16).build(&[4; 9], &faces).unwrap();
/// let uv: Vec<f64> = (0..16).flat_map(|v| [(v % 4) as f64, (v / 4) as f64]).collect();
/// let channel = FVarChannel::new(&grid, 2, uv, faces.clone()).unwrap();
/// let limit = subd_limit::fvar::base_fvar_limit(
///     &grid, &Scheme::CatmullClark, &Options::default(), &channel,
///     FVarLinearInterpolation::CornersOnly,
/// ).unwrap();
/// let at = limit.apply(channel.values(), 2);
/// // Catmull-Clark reproduces linear functions: an interior value is its own limit.
/// let r = limit.vertex_rows(5).start;
/// assert!((at[2 * r] - 1.0).abs() < 1e-12 && (at[2 * r + 1] - 1.0).abs() < 1e-12);
/// ```
///
/// # Errors
/// As [`crate::base_limit`], [`LimitError::TooDeep`] when refining the whole mesh until
/// its semi-sharp creases decay would pass [`crate::MAX_DECAY_FACE_VERTICES`], and
/// [`LimitError::Param`] for a channel that does not fit `topology`.
pub fn base_fvar_limit(
    topology: &Topology,
    scheme: &Scheme,
    options: &Options,
    channel: &FVarChannel,
    mode: FVarLinearInterpolation,
) -> Result<BaseFVarLimit, LimitError> {
    let (levels, sharpness) = crate::levels_for_exact_limit(topology, scheme);
    let levels = levels.max(1);
    // The whole channel is refined until the creases have decayed: refused, as the
    // positions' whole refinement is, where that would pass the budget (a sharpness of 8
    // multiplies the mesh by 4^8).
    let estimate = topology
        .num_face_vertices()
        .saturating_mul(4usize.saturating_pow(levels as u32));
    if estimate > crate::MAX_DECAY_FACE_VERTICES {
        return Err(LimitError::TooDeep {
            sharpness,
            levels,
            max: crate::MAX_DECAY_FACE_VERTICES,
        });
    }
    let r = Refinement::new(topology, scheme.clone(), options, levels)?;
    let fr = FaceVaryingRefinement::new(&r, channel, mode)
        .map_err(|e| LimitError::Param(e.to_string()))?;
    let at = limit_at_level(&r, &fr, levels)?;
    let base = fr.level_values(&r, 0);
    let last = fr.level_values(&r, levels);
    let nv = topology.num_vertices();
    let mut offsets = Vec::with_capacity(nv + 1);
    let mut values = Vec::new();
    for v in 0..nv {
        offsets.push(values.len() as u32);
        for k in 0..base.num_vertex_values(v) {
            values.push(base.vertex_value(v, k));
        }
    }
    offsets.push(values.len() as u32);
    // Base vertex v is vertex v at every level, and keeps its values: its rows are the first
    // of the last level's values.
    let rows = values.len();
    debug_assert!((0..nv).all(|v| last.num_vertex_values(v) == base.num_vertex_values(v)));
    let table = crate::first_rows(&fr.composed(&r, levels).then(&at), rows);
    Ok(BaseFVarLimit {
        offsets,
        values,
        table,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use subd_mesh::TopologyBuilder;

    /// A 4 × 4 grid of quads (25 vertices) whose UV layout is cut along the middle column
    /// into two islands, with an infinitely sharp crease across it; and its triangulation.
    fn grid() -> (Topology, Topology, Vec<u32>, Vec<u32>) {
        let mut quads = Vec::new();
        for y in 0..4u32 {
            for x in 0..4u32 {
                let v = 5 * y + x;
                quads.extend([v, v + 1, v + 6, v + 5]);
            }
        }
        let tris: Vec<u32> = quads
            .chunks(4)
            .flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]])
            .collect();
        let mut q = TopologyBuilder::new(25).build(&[4; 16], &quads).unwrap();
        let mut t = TopologyBuilder::new(25).build(&[3; 32], &tris).unwrap();
        for topo in [&mut q, &mut t] {
            for (a, b) in [(5, 6), (6, 7), (7, 8)] {
                let e = topo.find_edge(a, b).unwrap() as usize;
                topo.set_edge_sharpness(e, subd_mesh::tags::SHARPNESS_INFINITE);
            }
        }
        // Value of a corner: its vertex, offset by 25 on the right island (x ≥ 2 faces).
        let island = |face_vertices: &[u32], size: usize| -> Vec<u32> {
            face_vertices
                .chunks(size)
                .flat_map(|f| {
                    let right = f.iter().all(|&v| v % 5 >= 2);
                    f.iter()
                        .map(move |&v| v + 25 * u32::from(right))
                        .collect::<Vec<_>>()
                })
                .collect()
        };
        let qi = island(&quads, 4);
        let ti = island(&tris, 3);
        (q, t, qi, ti)
    }

    /// Limits are left eigenvectors of the refinement: a value's limit taken at level 1
    /// equals its child's limit taken at level 2, for smooth, seam-crease and corner values
    /// in every mode (no semi-sharp features, so nothing decays in between).
    #[test]
    fn limits_agree_across_a_level_of_refinement() {
        let (quads, tris, qi, ti) = grid();
        let values: Vec<f64> = (0..100).map(|i| ((i * 37) % 101) as f64 / 101.0).collect();
        for (scheme, topo, idx) in [
            (Scheme::CatmullClark, &quads, &qi),
            (Scheme::Loop, &tris, &ti),
        ] {
            let channel = FVarChannel::new(topo, 2, values.clone(), idx.clone()).unwrap();
            let r = Refinement::new(topo, scheme.clone(), &Options::default(), 2).unwrap();
            for mode in FVarLinearInterpolation::ALL_MODES {
                let fr = FaceVaryingRefinement::new(&r, &channel, mode).unwrap();
                let levels = fr.refine_values(&r, channel.values(), 2);
                let at = |l: usize| {
                    let t = limit_at_level(&r, &fr, l).unwrap();
                    let mut out = vec![0.0; levels[l].len()];
                    t.apply(&levels[l], 2, &mut out);
                    out
                };
                let (one, two) = (at(1), at(2));
                // Level-1 vertices are vertices 0.. of level 2, with the same values.
                let n = fr.num_values(1);
                for i in 0..2 * n {
                    assert!(
                        (one[i] - two[i]).abs() < 1e-13,
                        "{scheme:?} {mode:?} value {}: {} vs {}",
                        i / 2,
                        one[i],
                        two[i]
                    );
                }
            }
        }
    }

    #[test]
    fn level_zero_and_levels_past_the_refinement_are_refused() {
        let (quads, _, qi, _) = grid();
        let channel = FVarChannel::new(&quads, 2, vec![0.0; 100], qi).unwrap();
        let r = Refinement::new(&quads, Scheme::CatmullClark, &Options::default(), 1).unwrap();
        let fr = FaceVaryingRefinement::new(&r, &channel, FVarLinearInterpolation::None).unwrap();
        assert!(matches!(
            limit_at_level(&r, &fr, 0),
            Err(LimitError::Param(_))
        ));
        assert!(matches!(
            limit_at_level(&r, &fr, 2),
            Err(LimitError::Param(_))
        ));
    }

    /// A crease of sharpness 9.5 would need 10 levels of the whole 32-triangle grid (96 ×
    /// 4^10 face-vertices, over the budget): refused at once instead of allocated.
    #[test]
    fn creases_too_sharp_for_the_budget_are_refused_before_refining() {
        let (_, mut tris, _, ti) = grid();
        let e = tris.find_edge(11, 12).unwrap() as usize; // interior
        tris.set_edge_sharpness(e, 9.5);
        let channel = FVarChannel::new(&tris, 2, vec![0.0; 100], ti).unwrap();
        let limit = base_fvar_limit(
            &tris,
            &Scheme::Loop,
            &Options::default(),
            &channel,
            FVarLinearInterpolation::CornersPlus1,
        );
        assert!(
            matches!(limit, Err(LimitError::TooDeep { levels: 10, .. })),
            "{limit:?}"
        );
    }
}
