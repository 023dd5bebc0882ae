//! One uniform refinement step, following OpenSubdiv's Far/Vtr/Sdc behaviour: the child
//! topology and its tags, the rule of every child vertex, and the masks that give child
//! vertices from parent vertices — evaluated directly into positions, or recorded as a
//! [`StencilTable`].

mod counts;
mod depth_first;
mod fused;
mod fvar;
mod layout;
mod osd;
pub(crate) mod par;
mod rows;
pub(crate) mod split;
mod stream;
mod tags;

pub use counts::{LevelCounts, refined_counts};
pub(crate) use counts::{last_level_bytes, topology_bytes};
pub use depth_first::{ChunkLevel, DepthFirst};
pub use fvar::{
    FVarLevelState, FVarLevelValues, FVarPatchTag, FVarValueKind, FaceVaryingRefinement,
};
pub(crate) use fvar::{base_corner_kinds, check_channel};
pub use layout::ChildLayout;
pub(crate) use osd::{BILINEAR, CATMULL_CLARK, LOOP, OsdRefinement};
pub use stream::{FaceStream, PointStream};
pub(crate) use tags::{child_explicit_tags, explicit_tags, prepare_base};

pub(crate) use fused::{
    applies as fusion_applies, child_too_large as fused_child_too_large, grandchild_faces,
    grandchild_num_edges, grandchild_num_vertices, grandchild_points,
};

use glam::DVec3;
use rayon::prelude::*;
use subd_mesh::tags::{is_infinite, is_semi_sharp};
use subd_mesh::{CreaseMethod, Topology, TriangleSubdivision};

use crate::rules::{self, Rule};
use crate::stencil::{RowSink, StencilTable};
use crate::{Options, two_phase};
use subd_mesh::memory;

/// The mask set of OpenSubdiv's family (its `Sdc::SchemeType`): which split and which
/// vertex, edge and face masks a level takes. The two-phase scheme is Catmull-Clark with its
/// first step's vertex masks changed (`Step::phase_one`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Sdc {
    CatmullClark,
    Loop,
    Bilinear,
}

impl Sdc {
    /// The mask set of `scheme`, when it is one of OpenSubdiv's family.
    pub(crate) fn of(scheme: &crate::Scheme) -> Option<Sdc> {
        use crate::Scheme as S;
        match scheme {
            S::CatmullClark | S::TwoPhase(_) => Some(Sdc::CatmullClark),
            S::Loop => Some(Sdc::Loop),
            S::Bilinear => Some(Sdc::Bilinear),
            S::DooSabin | S::Sqrt3 | S::Butterfly { .. } | S::ModifiedButterfly => None,
        }
    }

    /// The public scheme of these masks.
    pub(crate) fn scheme(self) -> crate::Scheme {
        match self {
            Sdc::CatmullClark => crate::Scheme::CatmullClark,
            Sdc::Loop => crate::Scheme::Loop,
            Sdc::Bilinear => crate::Scheme::Bilinear,
        }
    }
}

/// Rows per parallel task when evaluating points.
const CHUNK: usize = 4096;

/// Sharpness of the half of parent edge `e` at its end vertex `u`.
pub(super) fn half_sharpness(p: &Topology, e: usize, u: usize, method: CreaseMethod) -> f32 {
    let s = p.edge_sharpness(e);
    if method == CreaseMethod::Chaikin && is_semi_sharp(s) {
        let around = p
            .vertex_edges(u)
            .iter()
            .map(|&x| p.edge_sharpness(x as usize));
        rules::child_edge_sharpness(s, method, around)
    } else {
        rules::child_edge_sharpness(s, method, std::iter::empty())
    }
}

/// Where the children of a parent level live in the child level.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Layout {
    /// Number of parent vertices (= first face-child vertex).
    pub face_vertex_base: u32,
    /// First edge-child vertex.
    pub edge_vertex_base: u32,
    /// First child edge that is a half of a parent edge.
    pub half_edge_base: u32,
    /// Number of child vertices.
    pub num_child_vertices: usize,
}

impl Layout {
    pub(crate) fn new(p: &Topology, scheme: Sdc) -> Layout {
        let (nv, nf, ne) = (
            p.num_vertices() as u32,
            p.num_faces() as u32,
            p.num_edges() as u32,
        );
        match scheme {
            Sdc::Loop => Layout {
                face_vertex_base: nv,
                edge_vertex_base: nv,
                half_edge_base: 3 * nf,
                num_child_vertices: (nv + ne) as usize,
            },
            _ => Layout {
                face_vertex_base: nv,
                edge_vertex_base: nv + nf,
                half_edge_base: p.num_face_vertices() as u32,
                num_child_vertices: (nv + nf + ne) as usize,
            },
        }
    }
}

/// Whether any edge or vertex of the child of `p` will have a sharpness above zero: the
/// same values [`child_topology`] assigns (halves of parent edges decay, vertex children
/// keep a decayed vertex sharpness, everything else is smooth), without the split.
pub(crate) fn child_has_sharpness(p: &Topology, options: &Options) -> bool {
    let method = options.crease_method;
    let edges = (0..p.num_edges()).into_par_iter().any(|e| {
        let [a, b] = p.edge_vertices(e);
        half_sharpness(p, e, a as usize, method) > 0.0
            || half_sharpness(p, e, b as usize, method) > 0.0
    });
    edges
        || (0..p.num_vertices())
            .into_par_iter()
            .any(|v| rules::child_vertex_sharpness(p.vertex_sharpness(v)) > 0.0)
}

/// Faces of a child level without the other relations: what a last level needs for output.
#[derive(Debug, Clone)]
pub(crate) struct ChildFaces {
    pub offsets: Vec<u32>,
    pub vertices: Vec<u32>,
    pub holes: Vec<bool>,
}

/// Hole flags of the child faces: children of holes are holes ([`FaceStream::hole_faces`]).
fn child_holes(p: &Topology, scheme: Sdc, num_child_faces: usize) -> Vec<bool> {
    let faces = match scheme {
        Sdc::Loop => FaceStream::tri_split(p),
        _ => FaceStream::quad_split(p),
    };
    let mut holes: Vec<bool> = memory::zeroed(num_child_faces);
    for f in faces.hole_faces() {
        holes[f] = true;
    }
    holes
}

/// The child faces only (face-vertex lists and holes).
pub(crate) fn child_faces(p: &Topology, scheme: Sdc) -> ChildFaces {
    let (offsets, vertices) = match scheme {
        Sdc::Loop => split::tri_faces(p),
        _ => split::quad_faces(p),
    };
    let holes = child_holes(p, scheme, offsets.len() - 1);
    ChildFaces {
        offsets,
        vertices,
        holes,
    }
}

/// The full child topology with its tags: holes, decayed edge and vertex sharpness.
pub(crate) fn child_topology(
    p: &Topology,
    scheme: Sdc,
    options: &Options,
    layout: Layout,
) -> Topology {
    let mut child = match scheme {
        Sdc::Loop => split::tri_split(p),
        _ => split::quad_split(p),
    };
    let method = options.crease_method;
    let hb = layout.half_edge_base as usize;
    // Interior child edges are smooth; the halves of each parent edge decay.
    let mut edge_sharpness: Vec<f32> = memory::zeroed(child.edge_vertices.len());
    edge_sharpness[hb..]
        .par_chunks_mut(2)
        .enumerate()
        .for_each(|(e, o)| {
            let [a, b] = p.edge_vertices(e);
            o[0] = half_sharpness(p, e, a as usize, method);
            o[1] = half_sharpness(p, e, b as usize, method);
        });
    // Only vertex-children keep a (decayed) vertex sharpness.
    let mut vertex_sharpness: Vec<f32> = memory::zeroed(child.num_vertices);
    vertex_sharpness[..p.num_vertices()]
        .par_iter_mut()
        .enumerate()
        .for_each(|(v, o)| *o = rules::child_vertex_sharpness(p.vertex_sharpness(v)));
    child.face_holes = child_holes(p, scheme, child.face_offsets.len() - 1);
    child.edge_sharpness = edge_sharpness;
    child.vertex_sharpness = vertex_sharpness;
    Topology::from_parts(child).expect("a split of a valid topology is valid")
}

/// The rule of every child vertex (`Vtr::Refinement::propagateComponentTags` and
/// `reclassifySemisharpVertices`), from the parent alone.
pub(crate) fn child_rules(
    p: &Topology,
    parent_rules: &[Rule],
    options: &Options,
    layout: Layout,
) -> Vec<Rule> {
    let method = options.crease_method;
    let nv = p.num_vertices();
    // Without semi-sharp features nothing is reclassified: vertex-children keep the parent's
    // rule and edge-children are creases exactly on infinitely sharp edges.
    let semi = p
        .tags()
        .edge_sharpness()
        .par_iter()
        .any(|&s| is_semi_sharp(s))
        || p.tags()
            .vertex_sharpness()
            .par_iter()
            .any(|&s| is_semi_sharp(s));
    let mut out = memory::with_capacity(layout.num_child_vertices);
    if semi {
        out.par_extend((0..nv).into_par_iter().map(|v| {
            let rule = parent_rules[v];
            let ps = p.vertex_sharpness(v);
            let cs = rules::child_vertex_sharpness(ps);
            let ve = p.vertex_edges(v);
            let semi_edges = ve
                .iter()
                .any(|&e| is_semi_sharp(p.edge_sharpness(e as usize)));
            // Reclassify only a vertex that had semi-sharp features and ends up not sharp
            // itself: its semi-sharp edges decayed, or its own semi-sharpness did.
            if cs <= 0.0 && (semi_edges || is_semi_sharp(ps)) {
                let sharp = ve
                    .iter()
                    .filter(|&&e| half_sharpness(p, e as usize, v, method) > 0.0)
                    .count();
                Rule::determine(0.0, sharp)
            } else {
                rule
            }
        }));
    } else {
        out.extend_from_slice(&parent_rules[..nv]);
    }
    out.resize(layout.edge_vertex_base as usize, Rule::Smooth);
    out.par_extend((0..p.num_edges()).into_par_iter().map(|e| {
        let s = p.edge_sharpness(e);
        if is_infinite(s) {
            Rule::Crease
        } else if s > 0.0 {
            let [a, b] = p.edge_vertices(e);
            let semi = (half_sharpness(p, e, a as usize, method) > 0.0) as usize
                + (half_sharpness(p, e, b as usize, method) > 0.0) as usize;
            [Rule::Smooth, Rule::Dart, Rule::Crease][semi]
        } else {
            Rule::Smooth
        }
    }));
    debug_assert_eq!(out.len(), layout.num_child_vertices);
    out
}

/// Where a mask's weights go: a stencil row (face points expanded onto the parent face's
/// vertices) or a point being accumulated (face points read from the child level).
pub(crate) trait MaskSink {
    /// Adds `w` times parent vertex `i`.
    fn vertex(&mut self, i: u32, w: f64);
    /// Adds `w` times the face point of parent face `f`.
    fn face(&mut self, p: &Topology, f: usize, w: f64);
    /// Adds `w` times the vertex at the far end of edge `e` from `v`: a face-varying sink
    /// reads the value on that edge rather than the vertex's own.
    #[inline]
    fn edge_end(&mut self, p: &Topology, e: usize, v: u32, w: f64) {
        self.vertex(p.edge_other_vertex(e, v), w);
    }
    /// Adds `w` times end `end` (0 or 1) of edge `e`: an edge mask names its ends this way,
    /// not as "far from the other", which a degenerate edge (both ends one vertex) would
    /// not tell apart.
    #[inline]
    fn edge_vertex(&mut self, p: &Topology, e: usize, end: usize, w: f64) {
        self.vertex(p.edge_vertices(e)[end], w);
    }
    /// Adds `w` times the vertex at corner `k` of face `f` (a face-varying sink reads that
    /// corner's value).
    #[inline]
    fn corner(&mut self, p: &Topology, f: usize, k: usize, w: f64) {
        self.vertex(p.face_vertices(f)[k], w);
    }
}

impl MaskSink for RowSink<'_> {
    #[inline]
    fn vertex(&mut self, i: u32, w: f64) {
        self.add(i, w);
    }
    #[inline]
    fn face(&mut self, p: &Topology, f: usize, w: f64) {
        let fv = p.face_vertices(f);
        let inv = 1.0 / fv.len() as f64;
        for &v in fv {
            self.add(v, w * inv);
        }
    }
}

/// Numbers refined together as one point: positions (`DVec3`), or a face-varying channel's
/// values one, two or three numbers at a time (a value is then a plain run of `f64`s, hence
/// `Pod`).
pub(crate) trait Lanes:
    Copy
    + Default
    + Send
    + Sync
    + bytemuck::Pod
    + std::ops::Add<Output = Self>
    + std::ops::AddAssign
    + std::ops::Mul<f64, Output = Self>
{
}

impl Lanes for f64 {}
impl Lanes for glam::DVec2 {}
impl Lanes for DVec3 {}

/// Points a row reads by index: a slice of them, or (face-varying) the one value of each
/// vertex of a level, found through the level's value offsets.
pub(crate) trait Points<V>: Sync {
    /// Point `i`.
    fn point(&self, i: usize) -> V;
}

impl<V: Copy + Sync> Points<V> for [V] {
    #[inline]
    fn point(&self, i: usize) -> V {
        self[i]
    }
}

/// Accumulates a child point from parent points and the already computed child face points.
struct PointSink<'a, V, S: ?Sized, F: ?Sized> {
    src: &'a S,
    face_points: &'a F,
    acc: V,
}

impl<V: Lanes, S: Points<V> + ?Sized, F: Points<V> + ?Sized> MaskSink for PointSink<'_, V, S, F> {
    #[inline]
    fn vertex(&mut self, i: u32, w: f64) {
        self.acc += self.src.point(i as usize) * w;
    }
    #[inline]
    fn face(&mut self, _p: &Topology, f: usize, w: f64) {
        self.acc += self.face_points.point(f) * w;
    }
}

/// Everything a child row needs.
pub(crate) struct Step<'a> {
    pub parent: &'a Topology,
    pub parent_rules: &'a [Rule],
    pub child_rules: &'a [Rule],
    pub scheme: Sdc,
    pub options: &'a Options,
    pub layout: Layout,
    /// `λ` per parent vertex when this step is phase 1 of the two-phase scheme.
    pub phase_one: Option<&'a [f64]>,
}

impl Step<'_> {
    /// The mask of child vertex `r` into `sink`.
    fn row<S: MaskSink>(&self, r: usize, sink: &mut S) {
        let p = self.parent;
        let r32 = r as u32;
        let l = self.layout;
        if r32 < l.face_vertex_base {
            match self.scheme {
                Sdc::Bilinear => sink.vertex(r32, 1.0),
                _ => self.vertex_row(r, sink),
            }
        } else if r32 < l.edge_vertex_base {
            let f = (r32 - l.face_vertex_base) as usize;
            let fv = p.face_vertices(f);
            let inv = 1.0 / fv.len() as f64;
            for &v in fv {
                sink.vertex(v, inv);
            }
        } else {
            let e = (r32 - l.edge_vertex_base) as usize;
            match self.scheme {
                Sdc::Bilinear => {
                    let [a, b] = p.edge_vertices(e);
                    sink.vertex(a, 0.5);
                    sink.vertex(b, 0.5);
                }
                _ => self.edge_row(e, self.child_rules[r], sink),
            }
        }
    }

    /// Stencil of the child of parent edge `e` (`Sdc::Scheme::ComputeEdgeVertexMask`).
    fn edge_row<S: MaskSink>(&self, e: usize, child_rule: Rule, sink: &mut S) {
        let p = self.parent;
        let s = p.edge_sharpness(e);
        if s > 0.0 && child_rule == Rule::Crease {
            sink.edge_vertex(p, e, 0, 0.5);
            sink.edge_vertex(p, e, 1, 0.5);
            return;
        }
        let faces = p.edge_faces(e);
        let nf = faces.len();
        let (mut vw, mut fw) = match self.scheme {
            Sdc::Loop => (
                0.375,
                if nf == 2 {
                    0.125
                } else {
                    0.125 * 2.0 / nf as f64
                },
            ),
            _ if nf == 2 => {
                let tri = |f: u32| p.face_size(f as usize) == 3;
                if self.options.triangle_subdivision == TriangleSubdivision::Smooth
                    && (tri(faces[0]) || tri(faces[1]))
                {
                    let wt = |f: u32| if tri(f) { 0.470 } else { 0.25 };
                    let f = 0.5 * (wt(faces[0]) + wt(faces[1]));
                    (0.5 * (1.0 - 2.0 * f), f)
                } else {
                    (0.25, 0.25)
                }
            }
            _ => (0.25, 0.5 / nf as f64),
        };
        if s > 0.0 {
            // A semi-sharp edge whose child is no longer a crease: blend by the parent
            // sharpness (not clamped: Chaikin can extrapolate).
            let pw = s as f64;
            let cw = 1.0 - pw;
            vw = pw * 0.5 + cw * vw;
            fw *= cw;
        }
        sink.edge_vertex(p, e, 0, vw);
        sink.edge_vertex(p, e, 1, vw);
        for (&f, &l) in faces.iter().zip(p.edge_face_local_indices(e)) {
            match self.scheme {
                Sdc::Loop => {
                    let k = loop_opposite_corner(p, f as usize, e, l);
                    sink.corner(p, f as usize, k, fw);
                }
                _ => sink.face(p, f as usize, fw),
            }
        }
    }

    /// Stencil of the child of parent vertex `v` (`Sdc::Scheme::ComputeVertexVertexMask`).
    fn vertex_row<S: MaskSink>(&self, v: usize, sink: &mut S) {
        let p = self.parent;
        let prule = self.parent_rules[v];
        let crule = self.child_rules[v];
        if let Some(lambda) = self.phase_one {
            return self.phase_one_row(v, lambda[v], prule, crule, sink);
        }
        let mask = match prule {
            Rule::Smooth | Rule::Dart => Mask::smooth(p, v, self.scheme),
            _ => {
                let pmask = Mask::for_rule(p, v, prule, self.scheme, |e| p.edge_sharpness(e));
                if crule == prule {
                    pmask
                } else {
                    let method = self.options.crease_method;
                    let half = |e: usize| half_sharpness(p, e, v, method);
                    let cmask = Mask::for_rule(p, v, crule, self.scheme, half);
                    let ps = p.vertex_sharpness(v);
                    let pw =
                        fractional_weight_at(p, v, ps, rules::child_vertex_sharpness(ps), method);
                    return self.emit_blend(v, &pmask, &cmask, pw as f64, sink);
                }
            }
        };
        self.emit(v, &mask, sink);
    }

    fn emit<S: MaskSink>(&self, v: usize, m: &Mask, sink: &mut S) {
        let p = self.parent;
        if m.has_faces() {
            for (i, &f) in p.vertex_faces(v).iter().enumerate() {
                sink.face(p, f as usize, m.face(i));
            }
        }
        if m.has_edges() {
            for (i, &e) in p.vertex_edges(v).iter().enumerate() {
                sink.edge_end(p, e as usize, v as u32, m.edge(i));
            }
        }
        sink.vertex(v as u32, m.vertex());
    }

    /// Emits `pw · parent + (1 − pw) · child` (`Sdc::Scheme::LocalMask::
    /// CombineVertexVertexMasks`).
    fn emit_blend<S: MaskSink>(&self, v: usize, pm: &Mask, cm: &Mask, pw: f64, sink: &mut S) {
        let p = self.parent;
        let cw = 1.0 - pw;
        let mix = |has_p: bool, a: f64, has_c: bool, b: f64| match (has_p, has_c) {
            (true, true) => pw * a + cw * b,
            (true, false) => pw * a,
            (false, true) => cw * b,
            (false, false) => 0.0,
        };
        if pm.has_faces() || cm.has_faces() {
            for (i, &f) in p.vertex_faces(v).iter().enumerate() {
                let w = mix(pm.has_faces(), pm.face(i), cm.has_faces(), cm.face(i));
                sink.face(p, f as usize, w);
            }
        }
        if pm.has_edges() || cm.has_edges() {
            for (i, &e) in p.vertex_edges(v).iter().enumerate() {
                let w = mix(pm.has_edges(), pm.edge(i), cm.has_edges(), cm.edge(i));
                sink.edge_end(p, e as usize, v as u32, w);
            }
        }
        sink.vertex(v as u32, pw * pm.vertex() + cw * cm.vertex());
    }

    /// Phase 1 of the two-phase scheme at vertex `v` (Lin et al. eq. (1); boundary and crease
    /// rule derived in [`crate::two_phase`]), blended across a rule change as ordinary
    /// Catmull-Clark blends its masks.
    fn phase_one_row<S: MaskSink>(
        &self,
        v: usize,
        lambda: f64,
        prule: Rule,
        crule: Rule,
        sink: &mut S,
    ) {
        let p = self.parent;
        let emit = |rule: Rule, sharpness: &dyn Fn(usize) -> f32, w: f64, sink: &mut S| {
            match rule {
                Rule::Smooth | Rule::Dart => {
                    // λ v + (1 − λ)(α E + (1 − α) F), E and F means over edges and quads.
                    let ve = p.vertex_edges(v);
                    let we = w * (1.0 - lambda) * two_phase::ALPHA / ve.len() as f64;
                    for &e in ve {
                        sink.edge_end(p, e as usize, v as u32, we);
                    }
                    let vf = p.vertex_faces(v);
                    let wf = w * (1.0 - lambda) * (1.0 - two_phase::ALPHA) / vf.len() as f64;
                    for (&f, &c) in vf.iter().zip(p.vertex_face_local_indices(v)) {
                        let fv = p.face_vertices(f as usize);
                        sink.corner(p, f as usize, (c as usize + fv.len() / 2) % fv.len(), wf);
                    }
                    sink.vertex(v as u32, w * lambda);
                }
                Rule::Crease => {
                    let ve = p.vertex_edges(v);
                    let (a, b) = rules::crease_pair(ve.len(), |i| sharpness(ve[i] as usize) > 0.0);
                    let mu = two_phase::crease_vertex_weight(lambda);
                    for i in [a, b] {
                        sink.edge_end(p, ve[i] as usize, v as u32, w * 0.5 * (1.0 - mu));
                    }
                    sink.vertex(v as u32, w * mu);
                }
                Rule::Corner => sink.vertex(v as u32, w),
            }
        };
        let parent_sharpness = |e: usize| p.edge_sharpness(e);
        if crule == prule || matches!(prule, Rule::Smooth | Rule::Dart) {
            emit(prule, &parent_sharpness, 1.0, sink);
        } else {
            let method = self.options.crease_method;
            let ps = p.vertex_sharpness(v);
            let pw =
                fractional_weight_at(p, v, ps, rules::child_vertex_sharpness(ps), method) as f64;
            emit(prule, &parent_sharpness, pw, sink);
            emit(
                crule,
                &|e: usize| half_sharpness(p, e, v, method),
                1.0 - pw,
                sink,
            );
        }
    }

    /// The stencil table of this step.
    pub(crate) fn stencils(&self) -> StencilTable {
        StencilTable::build(
            self.layout.num_child_vertices,
            self.parent.num_vertices(),
            |r, sink| self.row(r, sink),
        )
    }

    /// Child points from parent points: face points first, then vertex and edge points,
    /// which use them (the order of OpenSubdiv's `PrimvarRefiner`). Parallel over rows; each
    /// row is computed alone, so the result does not depend on the number of threads.
    pub(crate) fn points(&self, src: &[DVec3]) -> Vec<DVec3> {
        rows::build(&StepRows { step: self, src })
    }

    /// The child point of row `r` through the general mask machinery.
    fn general_point<V: Lanes, S: Points<V> + ?Sized, F: Points<V> + ?Sized>(
        &self,
        r: usize,
        src: &S,
        face_points: &F,
    ) -> V {
        let mut s = PointSink {
            src,
            face_points,
            acc: V::default(),
        };
        self.row(r, &mut s);
        s.acc
    }

    /// The child point of row `r` from parent points `src` and, unless `r` is a face row,
    /// the child face points `face_points` (indexed by parent face): what [`StepRows`]
    /// gives, for points of any width read through any [`Points`].
    #[inline]
    pub(crate) fn lane_point<V: Lanes, S: Points<V> + ?Sized, F: Points<V> + ?Sized>(
        &self,
        r: usize,
        src: &S,
        face_points: &F,
    ) -> V {
        let fast = match self.scheme {
            Sdc::CatmullClark => self.smooth_catmark_point(r, src, face_points),
            Sdc::Loop => self.smooth_loop_point(r, src),
            Sdc::Bilinear => None,
        };
        fast.unwrap_or_else(|| self.general_point(r, src, face_points))
    }
}

/// The rows of one step's child points ([`Step::points`]): the face points are the middle
/// rows, and the vertex and edge points read them.
pub(crate) struct StepRows<'a> {
    pub step: &'a Step<'a>,
    pub src: &'a [DVec3],
}

impl rows::PointRows for StepRows<'_> {
    fn len(&self) -> usize {
        self.step.layout.num_child_vertices
    }

    fn middle(&self) -> std::ops::Range<usize> {
        let l = self.step.layout;
        l.face_vertex_base as usize..l.edge_vertex_base as usize
    }

    fn middle_row(&self, r: usize) -> DVec3 {
        self.step.general_point(r, self.src, &[][..])
    }

    fn row(&self, r: usize, face_points: &[DVec3]) -> DVec3 {
        self.step.lane_point(r, self.src, face_points)
    }
}

impl Step<'_> {
    /// The common Catmull-Clark cases without the general mask machinery: the child of a
    /// smooth (or dart) vertex, and of an uncreased edge between two faces without the
    /// smooth-triangle rule. Same sums in the same order as [`Step::row`] with a
    /// [`PointSink`], so the results are identical bit for bit; `None` for every other row.
    #[inline]
    fn smooth_catmark_point<V: Lanes, S: Points<V> + ?Sized, F: Points<V> + ?Sized>(
        &self,
        r: usize,
        src: &S,
        face_points: &F,
    ) -> Option<V> {
        if self.scheme != Sdc::CatmullClark {
            return None;
        }
        let p = self.parent;
        let l = self.layout;
        let r32 = r as u32;
        if r32 < l.face_vertex_base {
            if self.phase_one.is_some()
                || !matches!(self.parent_rules[r], Rule::Smooth | Rule::Dart)
            {
                return None;
            }
            let faces = p.vertex_faces(r);
            let n = faces.len();
            let w = 1.0 / (n * n) as f64;
            // `x * w` rather than `w * x`: the same product, for any width.
            let mut acc = V::default();
            for &f in faces {
                acc += face_points.point(f as usize) * w;
            }
            for &e in p.vertex_edges(r) {
                acc += src.point(p.edge_other_vertex(e as usize, r32) as usize) * w;
            }
            let nf = n as f64;
            return Some(acc + src.point(r) * ((nf - 2.0) / nf));
        }
        if r32 < l.edge_vertex_base {
            // A face row: the general mask, which reads no face points.
            return None;
        }
        let e = (r32 - l.edge_vertex_base) as usize;
        let faces = p.edge_faces(e);
        if p.edge_sharpness(e) > 0.0
            || faces.len() != 2
            || self.options.triangle_subdivision == TriangleSubdivision::Smooth
        {
            return None;
        }
        let [a, b] = p.edge_vertices(e);
        let mut acc = src.point(a as usize) * 0.25;
        acc += src.point(b as usize) * 0.25;
        acc += face_points.point(faces[0] as usize) * 0.25;
        acc += face_points.point(faces[1] as usize) * 0.25;
        Some(acc)
    }
}

impl Step<'_> {
    /// The common Loop cases without the general mask machinery: the child of a smooth (or
    /// dart) vertex, and of an uncreased edge between two triangles. Same sums in the same
    /// order as [`Step::row`] with a [`PointSink`] (starting from zero), so the results are
    /// identical bit for bit; `None` for every other row.
    #[inline]
    fn smooth_loop_point<V: Lanes, S: Points<V> + ?Sized>(&self, r: usize, src: &S) -> Option<V> {
        let p = self.parent;
        let r32 = r as u32;
        let mut acc = V::default();
        if r32 < self.layout.edge_vertex_base {
            if !matches!(self.parent_rules[r], Rule::Smooth | Rule::Dart) {
                return None;
            }
            // `Mask::smooth` and `Step::emit` without face weights.
            let (ew, vw) = loop_smooth_weights(p.vertex_faces(r).len());
            for &e in p.vertex_edges(r) {
                acc += src.point(p.edge_other_vertex(e as usize, r32) as usize) * ew;
            }
            return Some(acc + src.point(r) * vw);
        }
        let e = (r32 - self.layout.edge_vertex_base) as usize;
        let faces = p.edge_faces(e);
        if p.edge_sharpness(e) > 0.0 || faces.len() != 2 {
            return None;
        }
        let [a, b] = p.edge_vertices(e);
        acc += src.point(a as usize) * 0.375;
        acc += src.point(b as usize) * 0.375;
        for (&f, &l) in faces.iter().zip(p.edge_face_local_indices(e)) {
            let k = loop_opposite_corner(p, f as usize, e, l);
            acc += src.point(p.face_vertices(f as usize)[k] as usize) * 0.125;
        }
        Some(acc)
    }
}

/// The corner of triangle `f` opposite its edge `e` (`l`: the edge's local index in `f`),
/// from the edge's first position among the face's edges (a degenerate triangle can list
/// an edge twice).
#[inline]
fn loop_opposite_corner(p: &Topology, f: usize, e: usize, l: u16) -> usize {
    let fe = p.face_edges(f);
    let k = if fe[0] as usize == e {
        0
    } else if fe[1] as usize == e {
        1
    } else {
        l as usize
    };
    (k + 2) % 3
}

/// A vertex mask without storage: weights are computed per incident edge or face.
enum Mask {
    /// Uniform edge and face weights (Catmull-Clark) or edge weights only (Loop).
    Smooth {
        vertex: f64,
        edge: f64,
        face: Option<f64>,
    },
    /// 3/4 on the vertex, 1/8 on the two crease neighbours (positions in vertex-edge order).
    Crease { pair: (usize, usize) },
    /// The vertex itself.
    Corner,
}

impl Mask {
    fn smooth(p: &Topology, v: usize, scheme: Sdc) -> Mask {
        let nf = p.vertex_faces(v).len();
        match scheme {
            Sdc::Loop => {
                let (e, vw) = loop_smooth_weights(nf);
                Mask::Smooth {
                    vertex: vw,
                    edge: e,
                    face: None,
                }
            }
            _ => {
                let n = nf as f64;
                let w = 1.0 / (nf * nf) as f64;
                Mask::Smooth {
                    vertex: (n - 2.0) / n,
                    edge: w,
                    face: Some(w),
                }
            }
        }
    }

    /// The mask of `rule`, with `sharpness(e)` the sharpness used to find crease edges.
    fn for_rule(
        p: &Topology,
        v: usize,
        rule: Rule,
        scheme: Sdc,
        sharpness: impl Fn(usize) -> f32,
    ) -> Mask {
        match rule {
            Rule::Smooth | Rule::Dart => Mask::smooth(p, v, scheme),
            Rule::Crease => {
                let ve = p.vertex_edges(v);
                Mask::Crease {
                    pair: rules::crease_pair(ve.len(), |i| sharpness(ve[i] as usize) > 0.0),
                }
            }
            Rule::Corner => Mask::Corner,
        }
    }

    fn has_faces(&self) -> bool {
        matches!(self, Mask::Smooth { face: Some(_), .. })
    }

    fn has_edges(&self) -> bool {
        !matches!(self, Mask::Corner)
    }

    fn vertex(&self) -> f64 {
        match self {
            Mask::Smooth { vertex, .. } => *vertex,
            Mask::Crease { .. } => 0.75,
            Mask::Corner => 1.0,
        }
    }

    fn edge(&self, i: usize) -> f64 {
        match self {
            Mask::Smooth { edge, .. } => *edge,
            Mask::Crease { pair } => {
                if i == pair.0 || i == pair.1 {
                    0.125
                } else {
                    0.0
                }
            }
            Mask::Corner => 0.0,
        }
    }

    fn face(&self, _i: usize) -> f64 {
        match self {
            Mask::Smooth { face: Some(f), .. } => *f,
            _ => 0.0,
        }
    }
}

pub(crate) use crate::rules::loop_smooth_weights;

/// [`rules::fractional_weight`] over the edges of parent vertex `v`, without allocating.
fn fractional_weight_at(p: &Topology, v: usize, ps: f32, cs: f32, method: CreaseMethod) -> f32 {
    let edges = p.vertex_edges(v).iter().map(|&e| {
        let e = e as usize;
        let pe = p.edge_sharpness(e);
        // The child's sharpness matters only to Chaikin (uniform looks at the parent alone).
        let ce = if method == CreaseMethod::Chaikin {
            half_sharpness(p, e, v, method)
        } else {
            0.0
        };
        (pe, ce)
    });
    rules::fractional_weight(ps, cs, edges, method)
}

#[cfg(test)]
mod tests;
