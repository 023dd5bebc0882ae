//! What the limit masks and the patches read of a level's values: each value's kind (how it
//! is refined) and the informational tags OpenSubdiv's patch builder reads (§2.3).

use subd_mesh::Topology;

use super::{ChannelLevel, ValueTag};

/// The values of one level of a [`FaceVaryingRefinement`](crate::FaceVaryingRefinement) as limit masks need them: which
/// values each vertex has, whether they follow the geometry (matching) or are seam corners
/// or seam creases, and a crease value's two end values (`Vtr::FVarLevel`'s state).
///
/// Values are named by their index at that level (at level 0, the channel's own indices).
#[derive(Debug, Clone, Copy)]
pub struct FVarLevelValues<'a> {
    pub(super) level: &'a ChannelLevel,
    pub(super) topology: &'a Topology,
    pub(super) linear: bool,
    /// Faces of a regular boundary vertex: 2 (quads) or 3 (Loop's triangles).
    pub(super) regular_span: u16,
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

    /// What a patch reads of value `k` of vertex `v` beyond its kind ([`FVarPatchTag`]).
    pub fn patch_tag(&self, v: usize, k: usize) -> FVarPatchTag {
        self.level.tags[self.slot(v, k)].patch_tag(self.regular_span)
    }
}

impl ChannelLevel {
    /// How per-vertex value `slot` of vertex `v` is refined.
    pub(super) fn kind(&self, v: usize, slot: usize) -> FVarValueKind {
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

impl ValueTag {
    /// The value's patch tags with `regular_span` the faces of a regular boundary vertex
    /// (2 quads, 3 triangles): `FVarLevel`'s `_nonManifold`, `_xordinary`,
    /// `_infSharpEdges` and `_infIrregular` as §2.3 sets them.
    fn patch_tag(self, regular_span: u16) -> FVarPatchTag {
        if !self.mismatch || (self.span_faces == 0 && !self.disjoint) {
            return FVarPatchTag::default();
        }
        if self.disjoint {
            return FVarPatchTag {
                non_manifold: true,
                ..FVarPatchTag::default()
            };
        }
        let (size, inf) = (self.span_faces, self.span_inf_edges);
        let xordinary = if size == 1 {
            !self.inf_sharp
        } else {
            size != regular_span
        };
        let inf_irregular = if inf > 0 {
            size.saturating_sub(inf) > 1
        } else if self.inf_sharp {
            size > 1
        } else {
            xordinary
        };
        FVarPatchTag {
            non_manifold: false,
            xordinary,
            inf_sharp_edges: inf > 0,
            inf_irregular,
        }
    }
}

/// What OpenSubdiv's patch builder reads of a face-varying value beyond how it is refined
/// (`Vtr::FVarLevel::ValueTag`'s informational bits, set from the value's span of faces at
/// the base level and kept by the values of vertex children; all clear for a matching
/// value, whose patch is its vertex's, and for the values of edge children).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FVarPatchTag {
    /// The value's faces are not one run around its vertex (a value met again after
    /// another), or the vertex is non-manifold: a corner, and no other bit is set.
    pub non_manifold: bool,
    /// Irregular as a patch corner: a span of one face that is not pinned, or a span of
    /// more or fewer faces than a regular boundary vertex has (2 quads, 3 triangles).
    pub xordinary: bool,
    /// Infinitely sharp edges lie inside the span.
    pub inf_sharp_edges: bool,
    /// Irregular once infinitely sharp features count: more than one face between them,
    /// or, without them, a pinned value spanning several faces or an `xordinary` one.
    pub inf_irregular: bool,
}
