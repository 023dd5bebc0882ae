//! Face-varying refinement: a channel's values (UVs) refined beside the vertices, with
//! their own seams, as OpenSubdiv's `Vtr::FVarLevel`/`FVarRefinement` and
//! `Far::PrimvarRefiner::InterpolateFaceVarying` do. The rules are digested in
//! `docs/opensubdiv-face-varying.md` (section numbers below refer to it).
//!
//! Each level numbers its values by vertex: the values ("siblings") of vertex 0, then of
//! vertex 1, ... . A value that matches its neighbours follows the geometric rule of its
//! vertex; values on a seam (or, in the boundary modes, the mesh boundary) follow
//! OpenSubdiv's face-varying crease and corner rules, chosen by [`FVarLinearInterpolation`].

use std::mem::MaybeUninit;
use std::sync::OnceLock;

use glam::DVec3;
use subd_mesh::Topology;
use subd_mesh::fvar::{FVarChannel, FVarError, FVarLinearInterpolation};
use subd_mesh::tags::{is_infinite, is_semi_sharp};

use rayon::prelude::*;

use super::Sdc;
use super::tags::nm_vertex;
use super::{Lanes, MaskSink, OsdRefinement, Points, half_sharpness};
use crate::Refinement;
use crate::rules;
use crate::stencil::{RowSink, StencilTable};
use subd_mesh::BoundaryInterpolation;

/// OpenSubdiv's family behind `refinement`, which a [`FaceVaryingRefinement`] was made with.
fn osd(refinement: &Refinement) -> &OsdRefinement {
    refinement
        .opensubdiv()
        .expect("a FaceVaryingRefinement is made with one of OpenSubdiv's schemes")
}

/// The tags of one face-varying value (`Vtr::FVarLevel::ValueTag`, the bits that change
/// interpolation).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
struct ValueTag {
    /// Not the one value of a smooth, seamless vertex.
    mismatch: bool,
    /// Refined with the crease rule (otherwise a mismatched value is a corner).
    crease: bool,
    /// A corner until its semi-sharp features decay.
    semi_sharp: bool,
    /// Semi-sharp because the other value at its vertex is (the two-value plus modes).
    dep_sharp: bool,
}

impl ValueTag {
    fn is_corner(self) -> bool {
        !self.crease
    }
}

/// The mode's consequences (§2.1).
#[derive(Debug, Clone, Copy)]
struct ModeFlags {
    linear_all: bool,
    linear_boundaries: bool,
    dependent_sharpness: bool,
    corners_sharp: bool,
    smooth_corners_sharp: bool,
    sharpen_both_if_one_corner: bool,
    sharpen_darts: bool,
}

impl ModeFlags {
    fn new(mode: FVarLinearInterpolation, boundary: BoundaryInterpolation) -> ModeFlags {
        use FVarLinearInterpolation as M;
        let linear_boundaries = matches!(mode, M::All | M::Boundaries);
        let corners_sharp = mode != M::None;
        ModeFlags {
            linear_all: mode == M::All,
            linear_boundaries,
            dependent_sharpness: matches!(mode, M::CornersPlus1 | M::CornersPlus2),
            corners_sharp,
            smooth_corners_sharp: boundary != BoundaryInterpolation::EdgeAndCorner && corners_sharp,
            sharpen_both_if_one_corner: mode == M::CornersPlus2,
            sharpen_darts: mode == M::CornersPlus2 || linear_boundaries,
        }
    }

    /// Whether every value is interpolated linearly: mode `all`, or the Bilinear scheme.
    fn linear(self, scheme: Sdc) -> bool {
        self.linear_all || scheme == Sdc::Bilinear
    }

    fn smooth_boundaries(self) -> bool {
        !self.linear_boundaries
    }
}

/// One level of a refined channel.
#[derive(Debug, Clone)]
struct ChannelLevel {
    /// Where each vertex's values start (one more entry than vertices).
    value_offsets: Vec<u32>,
    /// The value of every face-vertex.
    face_values: Vec<u32>,
    /// Level 0 only: the caller's value index of each per-vertex value.
    user: Option<Vec<u32>>,
    tags: Vec<ValueTag>,
    /// First and last local face (in the vertex's face order) of each crease value's span.
    ends: Vec<[u16; 2]>,
    /// Per edge: discontinuous at one end or both.
    edge_mismatch: Vec<bool>,
    /// Per edge: kept linear by the mode.
    edge_linear: Vec<bool>,
    /// Refined levels: per vertex, whether its one value is the geometric mask over one
    /// value per parent vertex (its mask reads only faces whose corners all have one value);
    /// empty in the linear modes.
    geometric: Vec<bool>,
}

impl ChannelLevel {
    fn num_values(&self) -> usize {
        *self.value_offsets.last().unwrap_or(&0) as usize
    }

    fn offset(&self, v: usize) -> usize {
        self.value_offsets[v] as usize
    }

    fn count(&self, v: usize) -> usize {
        (self.value_offsets[v + 1] - self.value_offsets[v]) as usize
    }

    /// Whether vertex `v`'s values are mismatched (all or none of them are).
    fn is_mismatched(&self, v: usize) -> bool {
        self.tags[self.offset(v)].mismatch
    }

    /// The source index (into the values a stencil reads) of per-vertex value `slot`.
    fn source(&self, slot: usize) -> u32 {
        match &self.user {
            Some(u) => u[slot],
            None => slot as u32,
        }
    }

    fn corner_slot(&self, t: &Topology, f: usize, k: usize) -> usize {
        self.face_values[t.face_offsets()[f] as usize + k] as usize
    }

    /// The source of corner `k` of face `f`.
    fn corner_source(&self, t: &Topology, f: usize, k: usize) -> u32 {
        self.source(self.corner_slot(t, f, k))
    }

    /// The sources of edge `e`'s two ends inside its `j`-th face, in that face's order
    /// (which end comes first is not looked up).
    fn edge_face_corner_sources(&self, t: &Topology, e: usize, j: usize) -> [u32; 2] {
        let f = t.edge_faces(e)[j] as usize;
        let l = t.edge_face_local_indices(e)[j] as usize;
        let first = t.face_offsets()[f] as usize;
        let n = t.face_offsets()[f + 1] as usize - first;
        let slot = |k: usize| self.source(self.face_values[first + k] as usize);
        [slot(l), slot((l + 1) % n)]
    }

    /// The sources of edge `e`'s two ends (in edge order) inside its `j`-th face.
    fn edge_face_sources(&self, t: &Topology, e: usize, j: usize) -> [u32; 2] {
        let [here, next] = self.edge_face_corner_sources(t, e, j);
        let f = t.edge_faces(e)[j] as usize;
        let l = t.edge_face_local_indices(e)[j] as usize;
        if t.face_vertices(f)[l] == t.edge_vertices(e)[0] {
            [here, next]
        } else {
            [next, here]
        }
    }

    /// The crease end values of value `slot` of vertex `v` (§2.3 "crease end values"): the
    /// far end of the span's leading edge and of its trailing edge.
    fn crease_end_sources(&self, t: &Topology, v: usize, slot: usize) -> [u32; 2] {
        let [s, e] = self.ends[slot];
        let faces = t.vertex_faces(v);
        let local = t.vertex_face_local_indices(v);
        let after = |i: usize| {
            let f = faces[i] as usize;
            let n = t.face_size(f);
            self.corner_source(t, f, (local[i] as usize + 1) % n)
        };
        let before = |i: usize| {
            let f = faces[i] as usize;
            let n = t.face_size(f);
            self.corner_source(t, f, (local[i] as usize + n - 1) % n)
        };
        [after(s as usize), before(e as usize)]
    }
}

/// Where a value's mask goes: a stencil row, or the value being summed.
trait ValueTerms {
    /// Adds `w` times source value `i`.
    fn add(&mut self, i: u32, w: f64);
}

impl ValueTerms for RowSink<'_> {
    #[inline]
    fn add(&mut self, i: u32, w: f64) {
        RowSink::add(self, i, w);
    }
}

/// A value summed straight from the source values.
struct ValueSum<'a, V> {
    src: &'a [V],
    acc: V,
}

impl<V: Lanes> ValueTerms for ValueSum<'_, V> {
    #[inline]
    fn add(&mut self, i: u32, w: f64) {
        // `x * w`, the same product as the tables' `w * x`.
        self.acc += self.src[i as usize] * w;
    }
}

/// Where a mask of a matching value reads: face-varying values in place of vertices.
struct ValueSink<'a, S> {
    level: &'a ChannelLevel,
    row: &'a mut S,
}

impl<S: ValueTerms> MaskSink for ValueSink<'_, S> {
    #[inline]
    fn vertex(&mut self, i: u32, w: f64) {
        // Only the centre vertex of a vertex mask comes here; it matches, so has one value.
        self.row
            .add(self.level.source(self.level.offset(i as usize)), w);
    }

    #[inline]
    fn face(&mut self, p: &Topology, f: usize, w: f64) {
        let n = p.face_size(f);
        let inv = 1.0 / n as f64;
        for k in 0..n {
            self.row.add(self.level.corner_source(p, f, k), w * inv);
        }
    }

    #[inline]
    fn edge_end(&mut self, p: &Topology, e: usize, v: u32, w: f64) {
        // Every edge at a matching value is continuous: any of its faces gives the value.
        let [a, b] = self.level.edge_face_sources(p, e, 0);
        let far_is_a = p.edge_vertices(e)[0] != v;
        self.row.add(if far_is_a { a } else { b }, w);
    }

    #[inline]
    fn edge_vertex(&mut self, p: &Topology, e: usize, end: usize, w: f64) {
        // OpenSubdiv's `getEdgeFaceValues(edge, 0)`: the ends as they are in edge-face 0.
        self.row.add(self.level.edge_face_sources(p, e, 0)[end], w);
    }

    #[inline]
    fn corner(&mut self, p: &Topology, f: usize, k: usize, w: f64) {
        self.row.add(self.level.corner_source(p, f, k), w);
    }
}

/// A face-varying channel refined with a [`Refinement`]: per level, the values of every
/// face corner, and on request the [`StencilTable`] giving a level's values from the level
/// above ([`Self::refine_values`] evaluates the masks without them).
///
/// ```
/// use subd_mesh::TopologyBuilder;
/// use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};
/// use subd_schemes::{FaceVaryingRefinement, Options, Refinement, Scheme};
///
/// // Two quads whose UVs are cut apart along their shared edge 1-4.
/// let t = TopologyBuilder::new(6).build(&[4, 4], &[0, 1, 4, 3, 1, 2, 5, 4]).unwrap();
/// let uv = vec![0., 0., 1., 0., 1., 1., 0., 1., 2., 0., 3., 0., 3., 1., 2., 1.];
/// let channel = FVarChannel::new(&t, 2, uv, (0..8).collect()).unwrap();
/// let r = Refinement::new(&t, Scheme::CatmullClark, &Options::default(), 1).unwrap();
/// let fr = FaceVaryingRefinement::new(&r, &channel, FVarLinearInterpolation::All).unwrap();
/// let level1 = fr.refine_values(&r, channel.values(), 2).pop().unwrap();
/// // The seam's midpoint has one value per side.
/// assert_eq!(fr.num_values(1), 18);
/// assert_eq!(level1.len(), 2 * 18);
/// ```
#[derive(Debug, Clone)]
pub struct FaceVaryingRefinement {
    mode: FVarLinearInterpolation,
    flags: ModeFlags,
    num_user_values: usize,
    levels: Vec<ChannelLevel>,
    /// Per level, built on first request.
    stencils: Vec<OnceLock<StencilTable>>,
}

impl FaceVaryingRefinement {
    /// Refines `channel` (made for `refinement`'s base topology) to every level of
    /// `refinement`, interpolated by `mode`.
    ///
    /// # Errors
    /// [`FVarError::NoValues`] for a channel without values (OpenSubdiv refuses it too), and
    /// [`FVarError::IndexCount`] when the channel does not have one index per face-vertex
    /// of the base topology.
    pub fn new(
        refinement: &Refinement,
        channel: &FVarChannel,
        mode: FVarLinearInterpolation,
    ) -> Result<FaceVaryingRefinement, FVarError> {
        if refinement.opensubdiv().is_none() {
            return Err(FVarError::Scheme {
                scheme: refinement.scheme().to_string(),
            });
        }
        let base = refinement.topology(0);
        check_channel(base, channel)?;
        let options = refinement.options();
        let flags = ModeFlags::new(mode, options.boundary_interpolation);
        let mut levels = vec![base_level(base, channel.indices(), flags)];
        for l in 1..=refinement.num_levels() {
            let step = osd(refinement).step(l);
            let mut child = child_level(&step, &levels[l - 1], flags);
            child.geometric = geometric_vertices(&step, &levels[l - 1], &child, flags);
            levels.push(child);
        }
        Ok(FaceVaryingRefinement {
            mode,
            flags,
            num_user_values: channel.num_values(),
            stencils: (0..refinement.num_levels())
                .map(|_| OnceLock::new())
                .collect(),
            levels,
        })
    }

    /// The interpolation mode.
    pub fn mode(&self) -> FVarLinearInterpolation {
        self.mode
    }

    /// Number of refined levels.
    pub fn num_levels(&self) -> usize {
        self.levels.len() - 1
    }

    /// Number of values at `level`: the channel's own count at level 0, and at refined
    /// levels the distinct values of every vertex (OpenSubdiv's `GetNumFVarValues`).
    pub fn num_values(&self, level: usize) -> usize {
        if level == 0 {
            self.num_user_values
        } else {
            self.levels[level].num_values()
        }
    }

    /// The value index of every face-vertex of `level` (the channel's own indices at level
    /// 0; OpenSubdiv's `GetFaceFVarValues`, face after face).
    pub fn face_values(&self, level: usize) -> Vec<u32> {
        let l = &self.levels[level];
        l.face_values
            .iter()
            .map(|&s| l.source(s as usize))
            .collect()
    }

    /// The state of the values of `level`, for limit masks (`refinement` is the one the
    /// channel was refined with).
    pub fn level_values<'a>(
        &'a self,
        refinement: &'a Refinement,
        level: usize,
    ) -> FVarLevelValues<'a> {
        FVarLevelValues {
            level: &self.levels[level],
            topology: refinement.topology(level),
            linear: self.mode == FVarLinearInterpolation::All,
        }
    }

    /// Stencils giving the values of `level` from those of `level - 1` (`level ≥ 1`),
    /// built on first request (`refinement` is the one the channel was refined with).
    pub fn stencils(&self, refinement: &Refinement, level: usize) -> &StencilTable {
        self.stencils[level - 1].get_or_init(|| {
            let step = osd(refinement).step(level);
            let (parent, child) = (&self.levels[level - 1], &self.levels[level]);
            let num_sources = if level == 1 {
                self.num_user_values
            } else {
                parent.num_values()
            };
            StencilTable::build(child.num_values(), num_sources, |r, sink| {
                let cv = child.value_offsets.partition_point(|&o| o as usize <= r) - 1;
                value_row(&step, parent, child, self.flags, r, cv, sink)
            })
        })
    }

    /// One table from the channel's values to the values of `level`.
    pub fn composed(&self, refinement: &Refinement, level: usize) -> StencilTable {
        let mut t = StencilTable::identity(self.num_user_values);
        for l in 1..=level {
            t = t.then(self.stencils(refinement, l));
        }
        t
    }

    /// The values of every level (`result[0]` is `values`), `components` numbers each, as
    /// `InterpolateFaceVarying` gives them (`refinement` is the one the channel was refined
    /// with). The masks are evaluated directly, without stencil tables: values whose masks
    /// reach only seamless vertices take the geometry's own point evaluation (over the one
    /// value of each vertex), the others walk their masks. Values of more than three numbers
    /// are refined three numbers at a time.
    ///
    /// # Panics
    /// If `values` is not `components` numbers per value of the channel.
    pub fn refine_values(
        &self,
        refinement: &Refinement,
        values: &[f64],
        components: usize,
    ) -> Vec<Vec<f64>> {
        assert_eq!(
            values.len(),
            components * self.num_user_values,
            "components numbers per value"
        );
        let c = components;
        if c <= 3 {
            return self.refine_columns(refinement, values, c);
        }
        // Three numbers at a time (the last group one to three), interleaved back per level.
        let starts: Vec<usize> = (0..c).step_by(3).collect();
        let groups: Vec<Vec<Vec<f64>>> = starts
            .iter()
            .map(|&first| {
                let w = (c - first).min(3);
                self.refine_columns(refinement, &column_group(values, c, first, w), w)
            })
            .collect();
        (0..self.levels.len())
            .map(|l| {
                let n = groups[0][l].len() / 3;
                let mut level = Vec::with_capacity(c * n);
                for i in 0..n {
                    for (&first, g) in starts.iter().zip(&groups) {
                        let w = (c - first).min(3);
                        level.extend_from_slice(&g[l][w * i..w * (i + 1)]);
                    }
                }
                level
            })
            .collect()
    }

    /// The values of `level` (`level ≥ 1`) from those of `level - 1`, written into `dst`, a
    /// buffer the caller owns: OpenSubdiv's `PrimvarRefiner::InterpolateFaceVarying`. `src`
    /// holds `components` numbers per value of `level - 1` (at level 1, the channel's own
    /// values), `dst` as many per value of `level` ([`Self::num_values`]); every number of
    /// `dst` is overwritten, with what [`Self::refine_values`] gives for that level. For
    /// loops that refine new values over the same channel layout (animated UVs, many
    /// channels of one layout) without allocating; values of more than three numbers go
    /// through scratch copies, three numbers at a time.
    ///
    /// ```
    /// use subd_mesh::TopologyBuilder;
    /// use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};
    /// use subd_schemes::{FaceVaryingRefinement, Options, Refinement, Scheme};
    ///
    /// let t = TopologyBuilder::new(6).build(&[4, 4], &[0, 1, 4, 3, 1, 2, 5, 4]).unwrap();
    /// let uv = vec![0., 0., 1., 0., 1., 1., 0., 1., 2., 0., 3., 0., 3., 1., 2., 1.];
    /// let channel = FVarChannel::new(&t, 2, uv, (0..8).collect()).unwrap();
    /// let r = Refinement::new(&t, Scheme::CatmullClark, &Options::default(), 2).unwrap();
    /// let mode = FVarLinearInterpolation::CornersPlus1;
    /// let fr = FaceVaryingRefinement::new(&r, &channel, mode).unwrap();
    /// // One buffer per level, allocated once.
    /// let mut levels: Vec<Vec<f64>> = (0..=2).map(|l| vec![0.0; 2 * fr.num_values(l)]).collect();
    /// levels[0].copy_from_slice(channel.values());
    /// for l in 1..=2 {
    ///     let (done, rest) = levels.split_at_mut(l);
    ///     fr.refine_level_into(&r, l, &done[l - 1], &mut rest[0], 2);
    /// }
    /// assert_eq!(levels, fr.refine_values(&r, channel.values(), 2));
    /// ```
    ///
    /// # Panics
    /// If `level` is 0 or deeper than the refinement, or `src` or `dst` does not hold
    /// `components` numbers per value of its level.
    pub fn refine_level_into(
        &self,
        refinement: &Refinement,
        level: usize,
        src: &[f64],
        dst: &mut [f64],
        components: usize,
    ) {
        assert!(
            (1..self.levels.len()).contains(&level),
            "level {level} is not a refined level (1..={})",
            self.num_levels()
        );
        let c = components;
        assert_eq!(src.len(), c * self.num_values(level - 1), "source numbers");
        assert_eq!(dst.len(), c * self.num_values(level), "destination numbers");
        let next = self.next_values(refinement, level);
        if c <= 3 {
            next.columns_into(src, dst, c);
            return;
        }
        // Three numbers at a time (the last group one to three), through scratch copies.
        for first in (0..c).step_by(3) {
            let w = (c - first).min(3);
            let mut out = vec![0.0; w * self.num_values(level)];
            next.columns_into(&column_group(src, c, first, w), &mut out, w);
            for (d, o) in dst.chunks_exact_mut(c).zip(out.chunks_exact(w)) {
                d[first..first + w].copy_from_slice(o);
            }
        }
    }

    /// The step from level `level - 1` of the channel to level `level`.
    fn next_values<'a>(&'a self, refinement: &'a Refinement, level: usize) -> NextValues<'a> {
        NextValues {
            step: osd(refinement).step(level),
            parent: &self.levels[level - 1],
            child: &self.levels[level],
            flags: self.flags,
        }
    }

    /// [`Self::refine_values`] for values of `c` (at most three) numbers, refined as one
    /// [`Lanes`] point each.
    fn refine_columns(&self, refinement: &Refinement, values: &[f64], c: usize) -> Vec<Vec<f64>> {
        match c {
            0 => vec![Vec::new(); self.levels.len()],
            1 => self.refine_lanes::<f64>(refinement, values),
            2 => self.refine_lanes::<glam::DVec2>(refinement, values),
            _ => self.refine_lanes::<DVec3>(refinement, values),
        }
    }

    /// Every level's values from `values`, one `V` per value: refined as slices of `V`,
    /// handed back as `f64`s in the same allocations.
    fn refine_lanes<V: Lanes>(&self, refinement: &Refinement, values: &[f64]) -> Vec<Vec<f64>> {
        let mut out: Vec<Vec<V>> = vec![bytemuck::cast_slice(values).to_vec()];
        for l in 1..self.levels.len() {
            let next = self
                .next_values(refinement, l)
                .compute(out.last().expect("level 0"));
            out.push(next);
        }
        out.into_iter()
            .map(bytemuck::allocation::cast_vec::<V, f64>)
            .collect()
    }
}

/// Per child vertex of `step`, whether its value is the geometric mask over one value per
/// parent vertex: its mask reads only parent faces whose corners all have one value (no
/// seam, nothing mismatched), and the mode is not linear. Such a vertex has one value.
fn geometric_vertices(
    step: &super::Step<'_>,
    parent: &ChannelLevel,
    child: &ChannelLevel,
    flags: ModeFlags,
) -> Vec<bool> {
    if flags.linear(step.scheme) {
        return Vec::new();
    }
    let p = step.parent;
    let l = step.layout;
    let matching = |u: usize| parent.count(u) > 0 && !parent.tags[parent.offset(u)].mismatch;
    let clean_face: Vec<bool> = (0..p.num_faces())
        .into_par_iter()
        .map(|f| p.face_vertices(f).iter().all(|&u| matching(u as usize)))
        .collect();
    let clean = |faces: &[u32]| faces.iter().all(|&f| clean_face[f as usize]);
    (0..l.num_child_vertices)
        .into_par_iter()
        .with_min_len(CHUNK)
        .map(|cv| {
            let cv32 = cv as u32;
            if child.count(cv) != 1 {
                false
            } else if cv32 < l.face_vertex_base {
                matching(cv) && clean(p.vertex_faces(cv))
            } else if cv32 < l.edge_vertex_base {
                clean_face[(cv32 - l.face_vertex_base) as usize]
            } else {
                let e = (cv32 - l.edge_vertex_base) as usize;
                !child.tags[child.offset(cv)].mismatch && clean(p.edge_faces(e))
            }
        })
        .collect()
}

/// Child vertices per parallel task.
const CHUNK: usize = 4096;

/// Numbers `first..first + w` of each value of `values` (`c` numbers a value), packed.
fn column_group(values: &[f64], c: usize, first: usize, w: usize) -> Vec<f64> {
    values
        .chunks_exact(c)
        .flat_map(|v| &v[first..first + w])
        .copied()
        .collect()
}

/// The one value of each vertex of a level (its first; the geometric rows read only vertices
/// with one value), as the points of [`super::Step::lane_point`].
struct FirstValues<'a, V> {
    level: &'a ChannelLevel,
    values: &'a [V],
}

impl<V: Lanes> Points<V> for FirstValues<'_, V> {
    #[inline]
    fn point(&self, v: usize) -> V {
        self.values[self.level.source(self.level.offset(v)) as usize]
    }
}

/// The slots of child vertices `vertices`, `slots`, cut into pieces of [`CHUNK`] vertices,
/// each with its vertices.
fn pieces<'s, V>(
    child: &ChannelLevel,
    vertices: std::ops::Range<usize>,
    mut slots: &'s mut [MaybeUninit<V>],
) -> Vec<(std::ops::Range<usize>, &'s mut [MaybeUninit<V>])> {
    let mut out = Vec::with_capacity(vertices.len().div_ceil(CHUNK));
    for first in vertices.clone().step_by(CHUNK) {
        let end = (first + CHUNK).min(vertices.end);
        let (piece, rest) =
            std::mem::take(&mut slots).split_at_mut(child.offset(end) - child.offset(first));
        slots = rest;
        out.push((first..end, piece));
    }
    out
}

/// One step of [`FaceVaryingRefinement::refine_values`]: the child level's values from the
/// parent level's.
struct NextValues<'a> {
    step: super::Step<'a>,
    parent: &'a ChannelLevel,
    child: &'a ChannelLevel,
    flags: ModeFlags,
}

impl NextValues<'_> {
    /// The child level's values from `src`, the parent level's, in a new vector
    /// ([`Self::write`]).
    fn compute<V: Lanes>(&self, src: &[V]) -> Vec<V> {
        let total = self.child.num_values();
        let mut out: Vec<V> = subd_mesh::memory::with_capacity(total);
        self.write(src, &mut out.spare_capacity_mut()[..total]);
        #[allow(unsafe_code)]
        // SAFETY: `write` wrote every slot of `0..total` within the capacity
        // `with_capacity` reserved. A panic unwinds before this, leaving the length 0.
        unsafe {
            out.set_len(total)
        };
        out
    }

    /// [`Self::compute`] into `dst`, `c` (at most three) numbers per value, as one
    /// [`Lanes`] point each.
    fn columns_into(&self, src: &[f64], dst: &mut [f64], c: usize) {
        match c {
            0 => {}
            1 => self.compute_into::<f64>(src, dst),
            2 => self.compute_into::<glam::DVec2>(
                bytemuck::cast_slice(src),
                bytemuck::cast_slice_mut(dst),
            ),
            _ => {
                self.compute_into::<DVec3>(bytemuck::cast_slice(src), bytemuck::cast_slice_mut(dst))
            }
        }
    }

    /// [`Self::compute`] into `dst`, one slot per child value.
    fn compute_into<V: Lanes>(&self, src: &[V], dst: &mut [V]) {
        #[allow(unsafe_code)]
        // SAFETY: `MaybeUninit<V>` has `V`'s layout, and `write` stores only initialised
        // values through the view, so `dst` stays initialised.
        let slots: &mut [MaybeUninit<V>] = unsafe {
            std::slice::from_raw_parts_mut(dst.as_mut_ptr().cast::<MaybeUninit<V>>(), dst.len())
        };
        self.write(src, slots);
    }

    /// Writes every child value, computed from `src` (the parent level's values), into
    /// `slots` (one per value of the child level).
    ///
    /// Geometric vertices take the positions' rows ([`super::Step::lane_point`]) over the
    /// one value of each parent vertex; the others, next to seams and in the linear modes,
    /// compute their values from `src` directly. Face children come first, as
    /// `PrimvarRefiner` computes them: each has one value, so their values are one block of
    /// the output, in face order, which the vertex and edge rows then read as their face
    /// points. Every vertex is computed alone, so the result does not depend on the number
    /// of threads.
    fn write<V: Lanes>(&self, src: &[V], slots: &mut [MaybeUninit<V>]) {
        let (l, child) = (self.step.layout, self.child);
        let faces = l.face_vertex_base as usize..l.edge_vertex_base as usize;
        assert_eq!(slots.len(), child.num_values(), "one slot per child value");
        let (head, rest) = slots.split_at_mut(child.offset(faces.start));
        let (middle, tail) = rest.split_at_mut(child.offset(faces.end) - child.offset(faces.start));
        self.fill_faces(faces.start, middle, src);
        #[allow(unsafe_code)]
        // SAFETY: `fill_faces` wrote every slot of the face children (one each, `middle`
        // whole), so viewing them as initialised is sound;
        // `MaybeUninit<V>` has `V`'s layout.
        let face_points: &[V] =
            unsafe { std::slice::from_raw_parts(middle.as_ptr().cast::<V>(), middle.len()) };
        let mut rest = pieces(child, 0..faces.start, head);
        rest.extend(pieces(child, faces.end..l.num_child_vertices, tail));
        // Head, middle and tail partition `slots`, and each vertex writes all of its slots,
        // so every slot is written.
        self.fill(rest, src, face_points);
    }

    /// Writes the values of the face children, `slots` (one value each, in face order, the
    /// first being child vertex `first`): each the mean of its face's corner values, in
    /// every mode (`value_row`'s face rows, the same products in the same order; for faces
    /// away from seams also the geometric face rows). The corners' values are read through
    /// the face's own value list, which lies in face order, rather than through each
    /// corner vertex's value offset.
    fn fill_faces<V: Lanes>(&self, first: usize, slots: &mut [MaybeUninit<V>], src: &[V]) {
        let base = first - self.step.layout.face_vertex_base as usize;
        slots
            .par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(i, out)| {
                let start = base + i * CHUNK;
                for (j, value) in out.iter_mut().enumerate() {
                    value.write(self.face_value(src, start + j));
                }
            });
    }

    /// The value of the child of parent face `f`: the mean of its corners' values.
    #[inline]
    fn face_value<V: Lanes>(&self, src: &[V], f: usize) -> V {
        let (p, parent) = (self.step.parent, self.parent);
        let n = p.face_size(f);
        let inv = 1.0 / n as f64;
        let mut acc = V::default();
        for j in 0..n {
            acc += src[parent.corner_source(p, f, j) as usize] * inv;
        }
        acc
    }

    /// Writes the values of the child vertices and edges of each piece into its slots,
    /// reading the child face points `face_points`.
    fn fill<V: Lanes>(
        &self,
        pieces: Vec<(std::ops::Range<usize>, &mut [MaybeUninit<V>])>,
        src: &[V],
        face_points: &[V],
    ) {
        let (step, parent, child, flags) = (&self.step, self.parent, self.child, self.flags);
        let linear = flags.linear(step.scheme);
        let firsts = FirstValues {
            level: parent,
            values: src,
        };
        pieces.into_par_iter().for_each(|(vertices, out)| {
            let base = child.offset(vertices.start);
            for cv in vertices {
                let first = child.offset(cv);
                let values = &mut out[first - base..child.offset(cv + 1) - base];
                if linear {
                    for (k, value) in values.iter_mut().enumerate() {
                        value.write(self.linear_value(src, cv, k));
                    }
                } else if child.geometric[cv] {
                    values[0].write(step.lane_point(cv, &firsts, face_points));
                } else {
                    for (k, value) in values.iter_mut().enumerate() {
                        let mut sum = ValueSum {
                            src,
                            acc: V::default(),
                        };
                        value_row(step, parent, child, flags, first + k, cv, &mut sum);
                        value.write(sum.acc);
                    }
                }
            }
        });
    }

    /// In the linear modes, value `k` of child vertex `cv`: what [`value_row`] gives (the
    /// same products in the same order) without walking a mask. A vertex's values stay, a
    /// face's value is the mean of its corners' values, and an edge's the mean of its ends'
    /// values on the value's side.
    #[inline]
    fn linear_value<V: Lanes>(&self, src: &[V], cv: usize, k: usize) -> V {
        let (step, parent) = (&self.step, self.parent);
        let (p, l) = (step.parent, step.layout);
        let at = |i: u32| src[i as usize];
        let cv32 = cv as u32;
        if cv32 < l.face_vertex_base {
            return at(parent.source(parent.offset(cv) + k));
        }
        if cv32 < l.edge_vertex_base {
            return self.face_value(src, (cv32 - l.face_vertex_base) as usize);
        }
        let e = (cv32 - l.edge_vertex_base) as usize;
        // The mean does not depend on which end comes first (0 + x/2 is exact, and the
        // second sum commutes), so the ends are taken in whichever order is at hand.
        let [u, w] = p.edge_vertices(e);
        let [a, b] = if parent.count(u as usize) == 1 && parent.count(w as usize) == 1 {
            // Ends of one value each, so the edge is continuous: their values, found
            // through the ends' offsets rather than through an edge-face's corners.
            [u, w].map(|v| parent.source(parent.offset(v as usize)))
        } else {
            let side = if self.child.tags[self.child.offset(cv) + k].mismatch {
                k
            } else {
                0
            };
            parent.edge_face_corner_sources(p, e, side)
        };
        let mut acc = V::default();
        acc += at(a) * 0.5;
        acc += at(b) * 0.5;
        acc
    }
}

/// The values of one level of a [`FaceVaryingRefinement`] as limit masks need them: which
/// values each vertex has, whether they follow the geometry (matching) or are seam corners
/// or seam creases, and a crease value's two end values (`Vtr::FVarLevel`'s state).
///
/// Values are named by their index at that level (at level 0, the channel's own indices).
#[derive(Debug, Clone, Copy)]
pub struct FVarLevelValues<'a> {
    level: &'a ChannelLevel,
    topology: &'a Topology,
    linear: bool,
}

impl FVarLevelValues<'_> {
    /// Whether the channel is linear everywhere (mode `all`): every value's limit is itself.
    pub fn is_linear(&self) -> bool {
        self.linear
    }

    /// Number of values of vertex `v` (its siblings).
    pub fn num_vertex_values(&self, v: usize) -> usize {
        self.level.count(v)
    }

    /// The `k`-th value of vertex `v`.
    pub fn vertex_value(&self, v: usize, k: usize) -> u32 {
        self.level.source(self.level.offset(v) + k)
    }

    /// Whether vertex `v`'s values follow the geometry's rules (one value, no seam, and
    /// not pinned by the mode).
    pub fn is_matching(&self, v: usize) -> bool {
        !self.level.tags[self.level.offset(v)].mismatch
    }

    /// The value at corner `k` of face `f`.
    pub fn corner_value(&self, f: usize, k: usize) -> u32 {
        self.level.corner_source(self.topology, f, k)
    }

    /// The value at the far end of edge `e` from vertex `v`, seen from a vertex whose
    /// values match (every edge there is continuous, so any of its faces gives it).
    pub fn far_value(&self, e: usize, v: u32) -> u32 {
        let [a, b] = self.level.edge_face_sources(self.topology, e, 0);
        if self.topology.edge_vertices(e)[0] != v {
            a
        } else {
            b
        }
    }

    /// For a seam value `k` of a mismatched vertex `v` that is refined with the crease rule,
    /// the values at the far ends of the two edges bounding its span; `None` for a value
    /// pinned as a corner (including one still semi-sharp).
    pub fn crease_ends(&self, v: usize, k: usize) -> Option<[u32; 2]> {
        let slot = self.level.offset(v) + k;
        let tag = self.level.tags[slot];
        (tag.mismatch && !tag.is_corner())
            .then(|| self.level.crease_end_sources(self.topology, v, slot))
    }
}

/// How a face-varying value is refined at its level (`Vtr::FVarLevel`'s value tags, in the
/// terms of the vertex rules).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FVarValueKind {
    /// The one value of a seamless vertex: it follows the vertex's own rule.
    Matching,
    /// Pinned by the mode or by infinitely sharp features: it stays put.
    Corner,
    /// On a seam: the crease rule along the two seam edges bounding its span.
    Crease,
    /// Pinned until the semi-sharp features around it decay, a crease after that.
    SemiSharp,
}

impl FVarLevelValues<'_> {
    /// Number of (vertex, value) pairs at this level. At refined levels that is the number of
    /// values; at level 0 a channel value used at two vertices counts once at each.
    pub fn num_slots(&self) -> usize {
        self.level.num_values()
    }

    /// The slot of value `k` of vertex `v`: slots number the (vertex, value) pairs vertex by
    /// vertex, and at refined levels a slot is the value's own index.
    pub fn slot(&self, v: usize, k: usize) -> usize {
        self.level.offset(v) + k
    }

    /// The slot at corner `k` of face `f`.
    pub fn corner_slot(&self, f: usize, k: usize) -> usize {
        self.level.corner_slot(self.topology, f, k)
    }

    /// The value (the channel's own index at level 0) of slot `slot`.
    pub fn slot_value(&self, slot: usize) -> u32 {
        self.level.source(slot)
    }

    /// How value `k` of vertex `v` is refined.
    pub fn value_kind(&self, v: usize, k: usize) -> FVarValueKind {
        self.level.kind(v, self.slot(v, k))
    }
}

impl ChannelLevel {
    /// How per-vertex value `slot` of vertex `v` is refined.
    fn kind(&self, v: usize, slot: usize) -> FVarValueKind {
        let tag = self.tags[slot];
        if !self.tags[self.offset(v)].mismatch {
            FVarValueKind::Matching
        } else if tag.semi_sharp {
            FVarValueKind::SemiSharp
        } else if tag.crease {
            FVarValueKind::Crease
        } else {
            FVarValueKind::Corner
        }
    }
}

/// How the value at every face-vertex of `t` (value indices `indices`) is refined at level 0
/// under `mode`, with `boundary` the rule of the mesh boundary: OpenSubdiv's classification,
/// for schemes refined without a [`Refinement`] (the split schemes' face-varying data).
pub(crate) fn base_corner_kinds(
    t: &Topology,
    indices: &[u32],
    mode: FVarLinearInterpolation,
    boundary: BoundaryInterpolation,
) -> Vec<FVarValueKind> {
    let level = base_level(t, indices, ModeFlags::new(mode, boundary));
    (0..t.num_faces())
        .flat_map(|f| {
            let level = &level;
            t.face_vertices(f)
                .iter()
                .enumerate()
                .map(move |(k, &v)| level.kind(v as usize, level.corner_slot(t, f, k)))
        })
        .collect()
}

/// The checks every refinement of a channel makes: it has values (OpenSubdiv refuses a
/// channel without), and one index per face-vertex of `base`.
pub(crate) fn check_channel(base: &Topology, channel: &FVarChannel) -> Result<(), FVarError> {
    if channel.num_values() == 0 {
        return Err(FVarError::NoValues);
    }
    if channel.indices().len() != base.num_face_vertices() {
        return Err(FVarError::IndexCount {
            given: channel.indices().len(),
            expected: base.num_face_vertices(),
        });
    }
    Ok(())
}

/// Per-vertex classification of the base level (`FVarLevel::completeTopologyFromFaceValues`,
/// §2.2–2.3).
fn base_level(t: &Topology, indices: &[u32], flags: ModeFlags) -> ChannelLevel {
    let mut scan = BaseScan::new(t, indices, flags);
    // First pass (§2.2), in vertex order: "not yet mismatched" depends on it.
    for v in 0..t.num_vertices() {
        scan.scan_vertex(v);
    }
    scan.distinct_offsets.push(scan.distinct.len() as u32);
    // Second pass (§2.3): the tags of each value of a mismatched vertex.
    let (tags, ends) = scan.classify_values();
    let face_values = scan.corner_values();
    ChannelLevel {
        value_offsets: scan.distinct_offsets,
        face_values,
        user: Some(scan.distinct),
        tags,
        ends,
        edge_mismatch: scan.edge_mismatch,
        edge_linear: scan.edge_linear,
        geometric: Vec::new(),
    }
}

/// The base level's classification while its first pass walks the vertices: what the
/// vertices walked so far marked (a later vertex reads its ends' marks) and found.
struct BaseScan<'a> {
    t: &'a Topology,
    /// The caller's value index of every face-vertex.
    indices: &'a [u32],
    flags: ModeFlags,
    edge_mismatch: Vec<bool>,
    edge_linear: Vec<bool>,
    mismatched: Vec<bool>,
    /// Per vertex-face, the sibling of the corner.
    siblings: Vec<u16>,
    /// Per vertex, where its distinct values start in `distinct`.
    distinct_offsets: Vec<u32>,
    distinct: Vec<u32>,
    /// The values around the vertex being scanned, in its face order (reused).
    vals: Vec<u32>,
}

impl<'a> BaseScan<'a> {
    fn new(t: &'a Topology, indices: &'a [u32], flags: ModeFlags) -> BaseScan<'a> {
        let (nv, ne) = (t.num_vertices(), t.num_edges());
        BaseScan {
            t,
            indices,
            flags,
            edge_mismatch: vec![false; ne],
            edge_linear: vec![false; ne],
            mismatched: vec![false; nv],
            siblings: vec![0u16; t.vertex_face_offsets()[nv] as usize],
            distinct_offsets: Vec::with_capacity(nv + 1),
            distinct: Vec::new(),
            vals: Vec::new(),
        }
    }

    /// The value of corner `k` of face `f`.
    fn value_at(&self, f: u32, k: u16) -> u32 {
        self.indices[self.t.face_offsets()[f as usize] as usize + k as usize]
    }

    /// The first pass at vertex `v`: its discontinuous edges, whether it is mismatched, the
    /// siblings of its corners.
    fn scan_vertex(&mut self, v: usize) {
        let t = self.t;
        let faces = t.vertex_faces(v);
        let (indices, fo) = (self.indices, t.face_offsets());
        self.vals.clear();
        self.vals.extend(
            faces
                .iter()
                .zip(t.vertex_face_local_indices(v))
                .map(|(&f, &k)| indices[fo[f as usize] as usize + k as usize]),
        );
        let manifold = !nm_vertex(t, v);
        if manifold {
            self.mark_manifold_seams(v);
        } else if !faces.is_empty() {
            self.mark_non_manifold_seams(v);
        }
        if t.is_boundary_vertex(v) && !self.mismatched[v] {
            self.sharpen_boundary_vertex(v, manifold);
        }
        let values = self.assign_siblings(v);
        if !manifold && values > 1 {
            self.mismatched[v] = true;
        }
    }

    /// Edge `e` is discontinuous: it and both its ends are mismatched.
    fn mark_seam(&mut self, e: usize) {
        self.edge_mismatch[e] = true;
        self.edge_linear[e] = self.flags.linear_boundaries;
        let [a, b] = self.t.edge_vertices(e);
        self.mismatched[a as usize] = true;
        self.mismatched[b as usize] = true;
    }

    /// Around manifold vertex `v`, an edge between two faces whose corners differ is a seam
    /// (the leading boundary edge has no face before it).
    fn mark_manifold_seams(&mut self, v: usize) {
        let t = self.t;
        let edges = t.vertex_edges(v);
        let nf = self.vals.len();
        let first = usize::from(t.is_boundary_vertex(v));
        // Edge i lies between faces i - 1 and i (cyclically).
        for (i, &e) in edges.iter().enumerate().take(nf).skip(first) {
            let prev = if i == 0 { nf - 1 } else { i - 1 };
            if self.vals[i] != self.vals[prev] {
                self.mark_seam(e as usize);
            }
        }
    }

    /// Around non-manifold vertex `v` (faces not in order), an edge is a seam when its faces
    /// disagree on the value at `v`.
    fn mark_non_manifold_seams(&mut self, v: usize) {
        let t = self.t;
        for &e in t.vertex_edges(v) {
            let e = e as usize;
            let ef = t.edge_faces(e);
            if ef.len() < 2 {
                continue;
            }
            let at_v = |j: usize| {
                let f = ef[j];
                let l = t.edge_face_local_indices(e)[j];
                let fv = t.face_vertices(f as usize);
                let k = if fv[l as usize] as usize == v {
                    l
                } else {
                    ((l as usize + 1) % fv.len()) as u16
                };
                self.value_at(f, k)
            };
            if (1..ef.len()).any(|j| at_v(j) != at_v(0)) {
                self.mark_seam(e);
            }
        }
    }

    /// A boundary vertex without a seam is still mismatched when the mode keeps the
    /// boundaries linear (its boundary edges with it) or sharpens a smooth corner.
    fn sharpen_boundary_vertex(&mut self, v: usize, manifold: bool) {
        let t = self.t;
        let (nf, edges) = (self.vals.len(), t.vertex_edges(v));
        if self.flags.linear_boundaries && nf > 0 {
            self.mismatched[v] = true;
            if manifold {
                self.edge_linear[edges[0] as usize] = true;
                self.edge_linear[edges[edges.len() - 1] as usize] = true;
            } else {
                for &e in edges {
                    if t.is_boundary_edge(e as usize) {
                        self.edge_linear[e as usize] = true;
                    }
                }
            }
        } else if nf == 1 && self.flags.smooth_corners_sharp {
            self.mismatched[v] = true;
        }
    }

    /// The siblings of `v`'s corners and its distinct values; returns how many.
    ///
    /// Siblings: the k-th distinct value met walking the faces, with OpenSubdiv's shortcut
    /// (`completeTopologyFromFaceValues`): while exactly two values are known, a change of
    /// value is looked up against the first only, so A B A B gives siblings 0 1 0 2 (three
    /// values, the last two both B).
    fn assign_siblings(&mut self, v: usize) -> usize {
        let vfo = self.t.vertex_face_offsets();
        let (vals, distinct) = (&self.vals, &mut self.distinct);
        let first = distinct.len();
        self.distinct_offsets.push(first as u32);
        let sib = &mut self.siblings[vfo[v] as usize..vfo[v + 1] as usize];
        for (i, &x) in vals.iter().enumerate() {
            let known = &distinct[first..];
            let k = if i > 0 && x == vals[i - 1] {
                sib[i - 1] as usize
            } else {
                let found = match known.len() {
                    0 | 1 => None,
                    2 => (known[0] == x).then_some(0),
                    _ => known.iter().position(|&d| d == x),
                };
                found.unwrap_or_else(|| {
                    distinct.push(x);
                    distinct.len() - first - 1
                })
            };
            sib[i] = k as u16;
        }
        if vals.is_empty() {
            // A vertex without faces still has one value, value 0.
            distinct.push(0);
        }
        distinct.len() - first
    }

    /// The tags and crease ends of every value (§2.3); those of a matched vertex stay
    /// default.
    fn classify_values(&self) -> (Vec<ValueTag>, Vec<[u16; 2]>) {
        let t = self.t;
        let vfo = t.vertex_face_offsets();
        let num = self.distinct.len();
        let mut tags = vec![ValueTag::default(); num];
        let mut ends = vec![[0u16; 2]; num];
        for v in 0..t.num_vertices() {
            if !self.mismatched[v] {
                continue;
            }
            let o = self.distinct_offsets[v] as usize;
            let n = self.distinct_offsets[v + 1] as usize - o;
            let vertex = MismatchedVertex {
                t,
                v,
                n,
                sib: &self.siblings[vfo[v] as usize..vfo[v + 1] as usize],
                edge_mismatch: &self.edge_mismatch,
                nonmanifold: nm_vertex(t, v),
                boundary: t.is_boundary_vertex(v),
            };
            classify_vertex(
                &vertex,
                self.flags,
                &mut tags[o..o + n],
                &mut ends[o..o + n],
            );
        }
        (tags, ends)
    }

    /// The value of every face-vertex. Each corner names its vertex's sibling (not a search
    /// by value: two siblings can share a value, see [`BaseScan::assign_siblings`]).
    fn corner_values(&self) -> Vec<u32> {
        let t = self.t;
        let (fo, vfo) = (t.face_offsets(), t.vertex_face_offsets());
        let mut face_values = vec![0u32; t.num_face_vertices()];
        for v in 0..t.num_vertices() {
            let o = self.distinct_offsets[v];
            let range = vfo[v] as usize..vfo[v + 1] as usize;
            for ((&f, &k), &s) in t
                .vertex_faces(v)
                .iter()
                .zip(t.vertex_face_local_indices(v))
                .zip(&self.siblings[range])
            {
                face_values[fo[f as usize] as usize + k as usize] = o + s as u32;
            }
        }
        face_values
    }
}

/// The span of one value around its vertex (`FVarLevel::ValueSpan`).
#[derive(Debug, Clone, Copy, Default)]
struct Span {
    size: u16,
    start: u16,
    discts: u16,
    semi: u16,
    inf: u16,
}

/// A mismatched vertex of the base level, as its values are classified.
struct MismatchedVertex<'a> {
    t: &'a Topology,
    v: usize,
    /// Number of distinct values.
    n: usize,
    /// The sibling of each of its faces.
    sib: &'a [u16],
    edge_mismatch: &'a [bool],
    nonmanifold: bool,
    boundary: bool,
}

impl MismatchedVertex<'_> {
    /// `gatherValueSpans`: the span of each value around the vertex.
    fn spans(&self) -> Vec<Span> {
        let mut spans = vec![Span::default(); self.n];
        if self.nonmanifold {
            for s in &mut spans {
                s.discts = 1;
            }
        } else if self.n == 1 && !self.boundary {
            self.single_value_span(&mut spans[0]);
        } else if !self.sib.is_empty() {
            self.sibling_spans(&mut spans);
        }
        spans
    }

    /// Counts continuous edge `e` inside `span` by its sharpness; a discontinuous one as a
    /// discontinuity.
    fn count_edge(&self, span: &mut Span, e: u32) {
        let e = e as usize;
        if self.edge_mismatch[e] {
            span.discts += 1;
        } else if is_infinite(self.t.edge_sharpness(e)) {
            span.inf += 1;
        } else if is_semi_sharp(self.t.edge_sharpness(e)) {
            span.semi += 1;
        }
    }

    /// The one value of an interior vertex: all its faces, starting after its one
    /// discontinuous edge.
    fn single_value_span(&self, s: &mut Span) {
        s.size = self.sib.len() as u16;
        let mut seen = false;
        for (i, &e) in self.t.vertex_edges(self.v).iter().enumerate() {
            if !self.edge_mismatch[e as usize] {
                self.count_edge(s, e);
            } else if seen {
                // A second discontinuous edge: the one value is split in two (disjoint).
                s.discts = 1;
                break;
            } else {
                seen = true;
                s.start = i as u16;
            }
        }
    }

    /// Several values (or a boundary): each value's span is its run of faces; a value met
    /// again after another counts a discontinuity, except the run wrapping around face 0.
    fn sibling_spans(&self, spans: &mut [Span]) {
        let (sib, nf) = (self.sib, self.sib.len());
        let edges = self.t.vertex_edges(self.v);
        spans[0].size = 1;
        let wraps = !self.boundary && sib[nf - 1] == 0;
        if wraps {
            self.count_edge(&mut spans[0], edges[0]);
        }
        for i in 1..nf {
            let k = sib[i] as usize;
            if sib[i] == sib[i - 1] {
                self.count_edge(&mut spans[k], edges[i]);
            } else {
                if spans[k].size > 0 {
                    spans[k].discts += 1;
                }
                spans[k].start = i as u16;
            }
            spans[k].size += 1;
        }
        if wraps {
            spans[0].discts -= 1;
        }
    }
}

/// Tags and crease ends of the values of mismatched vertex `m`: `gatherValueSpans` and the
/// per-value decisions of §2.3.
fn classify_vertex(
    m: &MismatchedVertex<'_>,
    flags: ModeFlags,
    tags: &mut [ValueTag],
    ends: &mut [[u16; 2]],
) {
    let (n, nf) = (m.n, m.sib.len());
    let vs = m.t.vertex_sharpness(m.v);
    let mut all_corners = flags.linear_boundaries
        || is_infinite(vs)
        || m.nonmanifold
        || (flags.dependent_sharpness && n > 2)
        || (flags.sharpen_darts && n == 1 && !m.boundary);
    let spans = m.spans();
    let mut dependent = false;
    if flags.dependent_sharpness && n == 2 && !all_corners {
        let (a, b) = (spans[0], spans[1]);
        all_corners |= a.inf > 0 || b.inf > 0 || a.discts > 0 || b.discts > 0;
        if flags.sharpen_both_if_one_corner {
            all_corners |= a.size == 1 || b.size == 1;
        }
        dependent = (a.semi > 0) != (b.semi > 0);
    }
    for (k, s) in spans.iter().enumerate() {
        let mut tag = ValueTag {
            mismatch: true,
            ..ValueTag::default()
        };
        let inf_sharp =
            all_corners || s.inf > 0 || (s.size == 1 && flags.corners_sharp) || s.discts > 0;
        if !inf_sharp {
            if s.semi > 0 || is_semi_sharp(vs) {
                tag.semi_sharp = true;
            } else if dependent {
                tag.semi_sharp = true;
                tag.dep_sharp = true;
            } else {
                tag.crease = true;
            }
            if flags.smooth_boundaries() {
                ends[k] = span_ends(s, k, nf);
            }
        }
        tags[k] = tag;
    }
}

/// First and last local face of span `s` of value `k` among `nf` faces: the first value's
/// span, when it starts past face 0, wraps around the last face and ends before its start.
fn span_ends(s: &Span, k: usize, nf: usize) -> [u16; 2] {
    let (start, size) = (s.start as i64, s.size as i64);
    let end = if k == 0 && start != 0 {
        start + size - 1 - nf as i64
    } else {
        start + size - 1
    };
    [s.start, end as u16]
}

/// The channel at the child level of `step` (§3): value counts, face values, edge and value
/// tags, crease ends, semi-sharp decay.
fn child_level(step: &super::Step<'_>, parent: &ChannelLevel, flags: ModeFlags) -> ChannelLevel {
    let quads = step.scheme != Sdc::Loop;
    let offsets = child_value_offsets(step, parent, quads);
    let face_values = child_face_values(step, parent, &offsets, quads);
    let (edge_mismatch, edge_linear) = child_edge_tags(step, parent);
    let (mut tags, ends) = child_value_tags(step, parent, &offsets, flags, quads);
    if flags.smooth_boundaries() {
        reclassify_semi_sharp(step, parent, &offsets, flags, &mut tags);
    }
    ChannelLevel {
        value_offsets: offsets,
        face_values,
        user: None,
        tags,
        ends,
        edge_mismatch,
        edge_linear,
        geometric: Vec::new(),
    }
}

/// Where each child vertex's values start, in child vertex order: a mismatched vertex's
/// child keeps its values, a face child has one, a seam edge's child one per face.
fn child_value_offsets(step: &super::Step<'_>, parent: &ChannelLevel, quads: bool) -> Vec<u32> {
    let p = step.parent;
    let (nv, nf, ne) = (p.num_vertices(), p.num_faces(), p.num_edges());
    let mut offsets = Vec::with_capacity(step.layout.num_child_vertices + 1);
    let mut total = 0u32;
    for v in 0..nv {
        offsets.push(total);
        total += if parent.is_mismatched(v) {
            parent.count(v) as u32
        } else {
            1
        };
    }
    if quads {
        for _ in 0..nf {
            offsets.push(total);
            total += 1;
        }
    }
    for e in 0..ne {
        offsets.push(total);
        total += if parent.edge_mismatch[e] {
            p.edge_faces(e).len() as u32
        } else {
            1
        };
    }
    offsets.push(total);
    offsets
}

/// The child faces' values from the parent faces' corners, in the split's child order.
fn child_face_values(
    step: &super::Step<'_>,
    parent: &ChannelLevel,
    offsets: &[u32],
    quads: bool,
) -> Vec<u32> {
    let (p, l) = (step.parent, step.layout);
    let vertex_value = |f: usize, k: usize| {
        let v = p.face_vertices(f)[k] as usize;
        let c = offsets[v];
        if parent.is_mismatched(v) {
            c + (parent.corner_slot(p, f, k) - parent.offset(v)) as u32
        } else {
            c
        }
    };
    let edge_value = |f: usize, k: usize| {
        let e = p.face_edges(f)[k] as usize;
        let c = offsets[l.edge_vertex_base as usize + e];
        if parent.edge_mismatch[e] {
            let j = p
                .edge_faces(e)
                .iter()
                .zip(p.edge_face_local_indices(e))
                .position(|(&ef, &el)| ef as usize == f && el as usize == k)
                .unwrap_or(0);
            c + j as u32
        } else {
            c
        }
    };
    let mut face_values = Vec::with_capacity(4 * p.num_face_vertices());
    for f in 0..p.num_faces() {
        let n = p.face_size(f);
        if quads {
            let fc = offsets[l.face_vertex_base as usize + f];
            for k in 0..n {
                let mut child = [
                    vertex_value(f, k),
                    edge_value(f, k),
                    fc,
                    edge_value(f, (k + n - 1) % n),
                ];
                // A quad's child k has the parent corner at position k.
                if n == 4 {
                    child.rotate_right(k);
                }
                face_values.extend(child);
            }
        } else {
            let (v0, v1, v2) = (vertex_value(f, 0), vertex_value(f, 1), vertex_value(f, 2));
            let (e0, e1, e2) = (edge_value(f, 0), edge_value(f, 1), edge_value(f, 2));
            face_values.extend([v0, e0, e2, e0, v1, e1, e2, e1, v2, e1, e2, e0]);
        }
    }
    face_values
}

/// Child edge tags (mismatch, linear): face-interior edges continuous, halves copy their
/// parent.
fn child_edge_tags(step: &super::Step<'_>, parent: &ChannelLevel) -> (Vec<bool>, Vec<bool>) {
    let ne = step.parent.num_edges();
    let hb = step.layout.half_edge_base as usize;
    let nce = hb + 2 * ne;
    let mut edge_mismatch = vec![false; nce];
    let mut edge_linear = vec![false; nce];
    for e in 0..ne {
        for h in [0, 1] {
            let c = hb + 2 * e + h;
            edge_mismatch[c] = parent.edge_mismatch[e];
            edge_linear[c] = parent.edge_linear[e];
        }
    }
    (edge_mismatch, edge_linear)
}

/// Child value tags and crease ends (before semi-sharp decay): a mismatched vertex's child
/// copies its values', a seam or linear edge's child values are creases (or corners when
/// the boundaries are linear), spanning the child faces of their parent face.
fn child_value_tags(
    step: &super::Step<'_>,
    parent: &ChannelLevel,
    offsets: &[u32],
    flags: ModeFlags,
    quads: bool,
) -> (Vec<ValueTag>, Vec<[u16; 2]>) {
    let (p, l) = (step.parent, step.layout);
    let (nv, ne) = (p.num_vertices(), p.num_edges());
    let num = *offsets.last().unwrap_or(&0) as usize;
    let mut tags = vec![ValueTag::default(); num];
    let mut ends = vec![[0u16; 2]; num];
    for (v, &co) in offsets[..nv].iter().enumerate() {
        if parent.is_mismatched(v) {
            let (po, co, n) = (parent.offset(v), co as usize, parent.count(v));
            tags[co..co + n].copy_from_slice(&parent.tags[po..po + n]);
            ends[co..co + n].copy_from_slice(&parent.ends[po..po + n]);
        }
    }
    let per_face = if quads { 2 } else { 3 };
    for e in 0..ne {
        if parent.edge_mismatch[e] || parent.edge_linear[e] {
            let c = offsets[l.edge_vertex_base as usize + e] as usize;
            let n = offsets[l.edge_vertex_base as usize + e + 1] as usize - c;
            for j in 0..n {
                tags[c + j] = ValueTag {
                    mismatch: true,
                    crease: flags.smooth_boundaries(),
                    ..ValueTag::default()
                };
                if flags.smooth_boundaries() && parent.edge_mismatch[e] {
                    ends[c + j] = [(per_face * j) as u16, (per_face * j + per_face - 1) as u16];
                }
            }
        }
    }
    (tags, ends)
}

/// Semi-sharp values whose features decayed become creases (`reclassifySemisharpValues`,
/// §3.5). Child edges and faces keep the parent's order around a vertex child, so the
/// child edge at a position is the half of the parent edge there.
fn reclassify_semi_sharp(
    step: &super::Step<'_>,
    parent: &ChannelLevel,
    offsets: &[u32],
    flags: ModeFlags,
    tags: &mut [ValueTag],
) {
    let p = step.parent;
    let method = step.options.crease_method;
    for (v, &co) in offsets[..p.num_vertices()].iter().enumerate() {
        if !parent.tags[parent.offset(v)].mismatch {
            continue;
        }
        let edges = p.vertex_edges(v);
        let ps = p.vertex_sharpness(v);
        let parent_semi_edges = edges
            .iter()
            .any(|&e| is_semi_sharp(p.edge_sharpness(e as usize)));
        if !is_semi_sharp(ps) && !parent_semi_edges {
            continue;
        }
        let cs = rules::child_vertex_sharpness(ps);
        if is_semi_sharp(cs) || is_infinite(cs) {
            continue;
        }
        let child_edge_semi =
            |i: usize| is_semi_sharp(half_sharpness(p, edges[i] as usize, v, method));
        let child_semi_edges = (0..edges.len()).any(child_edge_semi);
        let (co, n) = (co as usize, parent.count(v));
        let values = &mut tags[co..co + n];
        let to_crease = |t: &mut ValueTag| {
            t.crease = true;
            t.semi_sharp = false;
            t.dep_sharp = false;
        };
        if !child_semi_edges {
            for t in values.iter_mut().filter(|t| t.semi_sharp) {
                to_crease(t);
            }
            continue;
        }
        for (k, t) in values.iter_mut().enumerate() {
            if t.semi_sharp && !t.dep_sharp {
                let [s, e] = parent.ends[parent.offset(v) + k];
                let still = span_interior_edges(s, e, edges.len()).any(child_edge_semi);
                if !still {
                    to_crease(t);
                }
            }
        }
        if flags.dependent_sharpness && n == 2 {
            if values[0].dep_sharp && !values[1].semi_sharp {
                values[0].dep_sharp = false;
            }
            if values[1].dep_sharp && !values[0].semi_sharp {
                values[1].dep_sharp = false;
            }
        }
    }
}

/// Positions of the edges inside a span of faces `s..=e` (with wrap-around): edges
/// `s+1 ..= e`, edge `i` lying between faces `i-1` and `i`.
fn span_interior_edges(s: u16, e: u16, num_edges: usize) -> impl Iterator<Item = usize> {
    let (s, e) = (s as usize, e as usize);
    let count = if e >= s { e - s } else { e + num_edges - s };
    (1..=count).map(move |i| (s + i) % num_edges.max(1))
}

/// The mask of child value `r` (§4).
fn value_row<S: ValueTerms>(
    step: &super::Step<'_>,
    parent: &ChannelLevel,
    child: &ChannelLevel,
    flags: ModeFlags,
    r: usize,
    cv: usize,
    sink: &mut S,
) {
    let p = step.parent;
    let l = step.layout;
    let linear = flags.linear(step.scheme);
    let k = r - child.offset(cv);
    let cv32 = cv as u32;
    if cv32 >= l.face_vertex_base && cv32 < l.edge_vertex_base {
        let f = (cv32 - l.face_vertex_base) as usize;
        let n = p.face_size(f);
        let inv = 1.0 / n as f64;
        for c in 0..n {
            sink.add(parent.corner_source(p, f, c), inv);
        }
    } else if cv32 >= l.edge_vertex_base {
        let e = (cv32 - l.edge_vertex_base) as usize;
        if child.tags[r].mismatch {
            let [a, b] = parent.edge_face_sources(p, e, k);
            sink.add(a, 0.5);
            sink.add(b, 0.5);
        } else if linear {
            let [a, b] = parent.edge_face_sources(p, e, 0);
            sink.add(a, 0.5);
            sink.add(b, 0.5);
        } else {
            let mut s = ValueSink {
                level: parent,
                row: sink,
            };
            step.edge_row(e, step.child_rules[cv], &mut s);
        }
    } else {
        let v = cv;
        let pslot = parent.offset(v) + k;
        if !parent.tags[parent.offset(v)].mismatch {
            if linear {
                sink.add(parent.source(pslot), 1.0);
            } else {
                let mut s = ValueSink {
                    level: parent,
                    row: sink,
                };
                step.vertex_row(v, &mut s);
            }
            return;
        }
        let tag = child.tags[r];
        if linear || tag.is_corner() {
            sink.add(parent.source(pslot), 1.0);
            return;
        }
        let [end0, end1] = parent.crease_end_sources(p, v, pslot);
        let (mut vw, mut ew) = (0.75, 0.125);
        let ptag = parent.tags[pslot];
        if ptag.semi_sharp {
            let other = if ptag.dep_sharp { 1 - k.min(1) } else { k };
            let w = fractional_weight(step, parent, v, parent.offset(v) + other) as f64;
            vw = (1.0 - w) * 0.75 + w;
            ew = (1.0 - w) * 0.125;
        }
        sink.add(end0, ew);
        sink.add(end1, ew);
        sink.add(parent.source(pslot), vw);
    }
}

/// `FVarRefinement::getFractionalWeight` (§3.6): the fractional weight of the edges inside
/// the span of value `slot` of vertex `v`, in `f32`.
fn fractional_weight(step: &super::Step<'_>, parent: &ChannelLevel, v: usize, slot: usize) -> f32 {
    let p = step.parent;
    let method = step.options.crease_method;
    let edges = p.vertex_edges(v);
    let [s, e] = parent.ends[slot];
    let ps = p.vertex_sharpness(v);
    let interior = span_interior_edges(s, e, edges.len()).map(|i| {
        let e = edges[i] as usize;
        (p.edge_sharpness(e), half_sharpness(p, e, v, method))
    });
    rules::fractional_weight(ps, rules::child_vertex_sharpness(ps), interior, method)
}

#[cfg(test)]
mod tests;
