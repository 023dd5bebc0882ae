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
    /// What the patches read of the value's span at the base level (§2.3, the
    /// "informational" tags), kept by vertex children and zero for edge children's values;
    /// refinement never reads them: the faces the value spans, the infinitely sharp edges
    /// inside the span, whether the span is disjoint (or the vertex non-manifold), and
    /// whether the value was pinned as an infinitely sharp corner.
    span_faces: u16,
    span_inf_edges: u16,
    disjoint: bool,
    inf_sharp: bool,
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
        let first = base_level(base, channel.indices(), flags);
        Ok(Self::refined_from(
            refinement,
            first,
            mode,
            flags,
            channel.num_values(),
        ))
    }

    /// The channel from its level-0 state `first` down every level of `refinement`, each
    /// child level's tags passed down from its parent's; level 1's stencils read
    /// `num_user_values` values.
    fn refined_from(
        refinement: &Refinement,
        first: ChannelLevel,
        mode: FVarLinearInterpolation,
        flags: ModeFlags,
        num_user_values: usize,
    ) -> FaceVaryingRefinement {
        let mut levels = vec![first];
        for l in 1..=refinement.num_levels() {
            let step = osd(refinement).step(l);
            let mut child = child_level(&step, &levels[l - 1], flags);
            child.geometric = geometric_vertices(&step, &levels[l - 1], &child, flags);
            levels.push(child);
        }
        FaceVaryingRefinement {
            mode,
            flags,
            num_user_values,
            stencils: (0..refinement.num_levels())
                .map(|_| OnceLock::new())
                .collect(),
            levels,
        }
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
            regular_span: if *refinement.scheme() == crate::Scheme::Loop {
                3
            } else {
                2
            },
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

mod base;
mod child;
mod state;
#[cfg(test)]
mod tests;
mod values;

pub use state::FVarLevelState;
pub use values::{FVarLevelValues, FVarPatchTag, FVarValueKind};

use base::*;
pub(crate) use base::{base_corner_kinds, check_channel};
use child::*;
