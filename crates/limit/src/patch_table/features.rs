//! The topological features feature-adaptive refinement isolates, and the choice of faces
//! to refine (OpenSubdiv's `Vtr::Level::VTag` and `Far::TopologyRefiner`'s feature selection,
//! `doesFaceHaveFeatures`; behaviour reproduced, code our own).
//!
//! Every vertex carries a small set of flags. At the base level they are read off the
//! prepared topology; at a refined level most are **inherited** from the parent vertex, edge
//! or face rather than re-derived from the child's own ring (a vertex's valence never
//! changes, an edge point is never extraordinary), and a child is *incomplete* unless its
//! parent was selected. The selection, the patch census and the regular/irregular split all
//! read these flags, so inheriting them the same way is what makes the census equal.

use subd_mesh::Topology;
use subd_mesh::tags::{is_infinite, is_semi_sharp};
use subd_schemes::Rule;

/// Vertex flags (OpenSubdiv's `VTag`; the rule as a bit set: smooth 1, dart 2, crease 4,
/// corner 8).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct VTag(u16);

impl VTag {
    pub const NON_MANIFOLD: u16 = 1 << 0;
    pub const XORDINARY: u16 = 1 << 1;
    pub const BOUNDARY: u16 = 1 << 2;
    pub const CORNER: u16 = 1 << 3;
    pub const INF_SHARP: u16 = 1 << 4;
    pub const SEMI_SHARP: u16 = 1 << 5;
    pub const SEMI_SHARP_EDGES: u16 = 1 << 6;
    pub const INCOMPLETE: u16 = 1 << 7;
    pub const INCID_IRREG_FACE: u16 = 1 << 8;
    pub const INF_SHARP_EDGES: u16 = 1 << 9;
    pub const INF_SHARP_CREASE: u16 = 1 << 10;
    pub const INF_IRREGULAR: u16 = 1 << 11;
    const RULE_SHIFT: u16 = 12;
    pub const RULE_SMOOTH: u16 = 1;
    pub const RULE_DART: u16 = 2;
    pub const RULE_CREASE: u16 = 4;
    pub const RULE_CORNER: u16 = 8;

    pub fn has(self, bits: u16) -> bool {
        self.0 & bits != 0
    }

    pub fn set(&mut self, bits: u16, on: bool) {
        if on {
            self.0 |= bits;
        } else {
            self.0 &= !bits;
        }
    }

    /// The rule bits.
    pub fn rule(self) -> u16 {
        self.0 >> Self::RULE_SHIFT
    }

    pub fn set_rule(&mut self, rule: Rule) {
        let bits = match rule {
            Rule::Smooth => Self::RULE_SMOOTH,
            Rule::Dart => Self::RULE_DART,
            Rule::Crease => Self::RULE_CREASE,
            Rule::Corner => Self::RULE_CORNER,
        };
        self.0 = (self.0 & ((1 << Self::RULE_SHIFT) - 1)) | (bits << Self::RULE_SHIFT);
    }

    /// The bitwise union of the tags of a face's corners.
    pub fn union(tags: impl IntoIterator<Item = VTag>) -> VTag {
        VTag(tags.into_iter().fold(0, |a, t| a | t.0))
    }
}

/// What the scheme regards as regular.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Regularity {
    /// Faces around a regular interior vertex (4 Catmull-Clark, 6 Loop).
    pub valence: usize,
    /// Vertices of a regular face (4, 3).
    pub face_size: usize,
}

/// Counts of a vertex's incident edges by kind.
struct EdgeCounts {
    boundary: usize,
    inf: usize,
    semi: usize,
}

fn edge_counts(t: &Topology, v: usize) -> EdgeCounts {
    let mut c = EdgeCounts {
        boundary: 0,
        inf: 0,
        semi: 0,
    };
    for &e in t.vertex_edges(v) {
        let (e, s) = (e as usize, t.edge_sharpness(e as usize));
        c.boundary += usize::from(t.edge_faces(e).len() < 2);
        c.inf += usize::from(is_infinite(s));
        c.semi += usize::from(is_semi_sharp(s));
    }
    c
}

/// The tags of every vertex of a prepared base level
/// (`TopologyRefinerFactoryBase::prepareComponentTagsAndSharpness`).
pub(crate) fn base_tags(t: &Topology, rules: &[Rule], reg: Regularity) -> Vec<VTag> {
    let irregular_faces = (0..t.num_faces()).any(|f| t.face_size(f) != reg.face_size);
    (0..t.num_vertices())
        .map(|v| {
            let c = edge_counts(t, v);
            let nf = t.vertex_faces(v).len();
            let vs = t.vertex_sharpness(v);
            let non_manifold = t.is_non_manifold_vertex(v) || t.is_isolated_vertex(v);
            let mut tag = VTag::default();
            tag.set(VTag::NON_MANIFOLD, non_manifold);
            tag.set(VTag::BOUNDARY, c.boundary > 0);
            tag.set(VTag::INF_SHARP, is_infinite(vs));
            tag.set(VTag::SEMI_SHARP, is_semi_sharp(vs));
            tag.set(VTag::SEMI_SHARP_EDGES, c.semi > 0);
            tag.set_rule(rules[v]);
            let corner = nf == 1 && t.vertex_edges(v).len() == 2 && is_infinite(vs);
            tag.set(VTag::CORNER, corner);
            let xordinary = !non_manifold
                && !corner
                && if c.boundary > 0 {
                    nf != reg.valence / 2
                } else {
                    nf != reg.valence
                };
            tag.set(VTag::XORDINARY, xordinary);
            tag.set(VTag::INF_SHARP_EDGES, c.inf > 0);
            tag.set(VTag::INF_IRREGULAR, is_infinite(vs) || c.inf > 0);
            if c.inf > 0 {
                inf_sharp_regularity(t, v, &mut tag, &c, reg);
            }
            if irregular_faces {
                let incident = t
                    .vertex_faces(v)
                    .iter()
                    .any(|&f| t.face_size(f as usize) != reg.face_size);
                tag.set(VTag::INCID_IRREG_FACE, incident);
            }
            tag
        })
        .collect()
}

/// Whether the infinitely sharp features at base vertex `v` still form a regular
/// configuration (a crease through opposite edges, a boundary crease, every edge sharp).
fn inf_sharp_regularity(t: &Topology, v: usize, tag: &mut VTag, c: &EdgeCounts, reg: Regularity) {
    let vs = t.vertex_sharpness(v);
    let edges = t.vertex_edges(v);
    let inf_rule = Rule::determine(if is_infinite(vs) { vs } else { 0.0 }, c.inf);
    match inf_rule {
        Rule::Crease => {
            tag.set(VTag::INF_SHARP_CREASE, true);
            if !tag.has(VTag::XORDINARY | VTag::NON_MANIFOLD) {
                let inf = |i: usize| is_infinite(t.edge_sharpness(edges[i] as usize));
                let irregular = if tag.has(VTag::BOUNDARY) {
                    false
                } else if reg.valence == 4 {
                    inf(0) != inf(2)
                } else {
                    inf(0) != inf(3) || inf(1) != inf(4)
                };
                tag.set(VTag::INF_IRREGULAR, irregular);
            }
        }
        Rule::Corner => {
            if c.inf == edges.len() && (edges.len() > 2 || is_infinite(vs)) {
                tag.set(VTag::INF_IRREGULAR, false);
            }
        }
        Rule::Smooth | Rule::Dart => {}
    }
}

/// Where a vertex of a refined level comes from.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Parent {
    /// The child of vertex `0` of the level above.
    Vertex(u32),
    /// The face point of face `0`.
    Face(u32),
    /// The edge point of edge `0`.
    Edge(u32),
}

/// The tags of a refined level's vertices (`Refinement::propagateComponentTags` and the
/// reclassification after sharpness decays): inherited from the parent element, with the
/// sharpness-dependent bits and the rule read off the child level.
pub(crate) struct ChildTagInput<'a> {
    pub parent: &'a Topology,
    pub parent_tags: &'a [VTag],
    /// The parent level's depth.
    pub parent_depth: usize,
    pub parent_vertex_selected: &'a [bool],
    pub parent_edge_selected: &'a [bool],
    pub parent_face_selected: &'a [bool],
    pub reg: Regularity,
}

pub(crate) fn child_tags(
    input: &ChildTagInput<'_>,
    child: &Topology,
    rules: &[Rule],
    parents: &[Parent],
) -> Vec<VTag> {
    let p = input.parent;
    parents
        .iter()
        .enumerate()
        .map(|(cv, &origin)| {
            let (mut tag, complete) = match origin {
                Parent::Vertex(v) => {
                    let mut tag = input.parent_tags[v as usize];
                    tag.set(VTag::INCID_IRREG_FACE, false);
                    (tag, input.parent_vertex_selected[v as usize])
                }
                Parent::Face(f) => {
                    let mut tag = VTag::default();
                    let odd = p.face_size(f as usize) != input.reg.face_size;
                    tag.set(VTag::XORDINARY, input.parent_depth == 0 && odd);
                    (tag, input.parent_face_selected[f as usize])
                }
                Parent::Edge(e) => {
                    let e = e as usize;
                    let s = p.edge_sharpness(e);
                    let nm = p.is_non_manifold_edge(e);
                    let mut tag = VTag::default();
                    tag.set(VTag::NON_MANIFOLD, nm);
                    tag.set(VTag::BOUNDARY, p.edge_faces(e).len() < 2);
                    tag.set(VTag::INF_SHARP_EDGES, is_infinite(s));
                    tag.set(VTag::INF_SHARP_CREASE, is_infinite(s));
                    tag.set(VTag::INF_IRREGULAR, is_infinite(s) && nm);
                    (tag, input.parent_edge_selected[e])
                }
            };
            // Sharpness decays: the semi-sharp bits and the rule follow the child level.
            let vs = child.vertex_sharpness(cv);
            tag.set(VTag::SEMI_SHARP, is_semi_sharp(vs));
            let semi_edges = child
                .vertex_edges(cv)
                .iter()
                .any(|&e| is_semi_sharp(child.edge_sharpness(e as usize)));
            tag.set(VTag::SEMI_SHARP_EDGES, semi_edges);
            tag.set_rule(rules[cv]);
            tag.set(VTag::INCOMPLETE, !complete);
            tag
        })
        .collect()
}

/// Which features are isolated (OpenSubdiv's `internal::FeatureMask`, with the secondary
/// level left at its default, past every isolation level).
#[derive(Debug, Clone, Copy)]
pub(crate) struct FeatureMask {
    pub semi_sharp_single: bool,
    pub inf_sharp_regular_crease: bool,
    pub inf_sharp_regular_corner: bool,
    pub unisolated_interior_edge: bool,
}

impl FeatureMask {
    /// The mask for single-crease patches `single_crease` (Catmull-Clark only) and
    /// infinitely sharp patches `inf_sharp`.
    pub fn new(single_crease: bool, inf_sharp: bool) -> FeatureMask {
        FeatureMask {
            semi_sharp_single: !single_crease,
            inf_sharp_regular_crease: !(inf_sharp || single_crease),
            inf_sharp_regular_corner: !inf_sharp,
            unisolated_interior_edge: single_crease && !inf_sharp,
        }
    }

    /// Whether a corner's tag, or a face's union of them, has an infinitely sharp feature
    /// to isolate (`doesInfSharpVTagHaveFeatures`).
    fn inf_sharp_tag(self, t: VTag) -> bool {
        let rule = t.rule();
        if t.has(VTag::INF_IRREGULAR) {
            // Corner before crease before dart; irregular boundary creases are
            // extraordinary boundary vertices, always isolated.
            rule & (VTag::RULE_CORNER | VTag::RULE_CREASE | VTag::RULE_DART) != 0
        } else if t.has(VTag::BOUNDARY) {
            rule & VTag::RULE_CORNER != 0 && !t.has(VTag::CORNER) && self.inf_sharp_regular_corner
        } else if rule & VTag::RULE_CORNER != 0 {
            self.inf_sharp_regular_corner
        } else {
            self.inf_sharp_regular_crease
        }
    }

    /// `doesInfSharpFaceHaveFeatures`.
    fn inf_sharp_face(self, all: VTag, corners: &[VTag]) -> bool {
        let smooth_corner = all.rule() & VTag::RULE_SMOOTH != 0;
        if corners.len() == 4 {
            if smooth_corner {
                return self.inf_sharp_tag(all);
            }
            if self.unisolated_interior_edge
                && corners
                    .iter()
                    .any(|t| t.has(VTag::INF_SHARP_EDGES) && !t.has(VTag::BOUNDARY))
            {
                return true;
            }
        } else if smooth_corner && !all.has(VTag::BOUNDARY) {
            return self.inf_sharp_tag(all);
        }
        corners
            .iter()
            .any(|&t| t.rule() & VTag::RULE_SMOOTH == 0 && self.inf_sharp_tag(t))
    }

    /// Whether face `f` of a level at `depth` is refined further (`doesFaceHaveFeatures`).
    /// `single_crease` says whether the face is a regular single-crease patch.
    pub fn select(
        self,
        corners: &[VTag],
        regular_size: usize,
        depth: usize,
        single_crease: impl FnOnce() -> bool,
    ) -> bool {
        if corners.len() != regular_size {
            return true;
        }
        let all = VTag::union(corners.iter().copied());
        if all.has(VTag::INCID_IRREG_FACE) {
            return true;
        }
        if all.has(VTag::INCOMPLETE) {
            return false;
        }
        if all.has(VTag::NON_MANIFOLD) {
            return true;
        }
        let smooth = all.rule() == VTag::RULE_SMOOTH;
        if all.has(VTag::XORDINARY) {
            if smooth {
                return true;
            }
            if depth < 2
                && corners
                    .iter()
                    .any(|t| t.has(VTag::XORDINARY) && t.rule() == VTag::RULE_SMOOTH)
            {
                return true;
            }
        }
        if smooth {
            return false;
        }
        if all.has(VTag::SEMI_SHARP | VTag::SEMI_SHARP_EDGES) {
            return self.semi_sharp_single || !single_crease();
        }
        if all.has(VTag::INF_SHARP | VTag::INF_SHARP_EDGES) {
            return self.inf_sharp_face(all, corners);
        }
        false
    }
}

/// The sharp edge of a quad that is a regular patch along one crease
/// (`Vtr::Level::isSingleCreasePatch`): two adjacent crease corners, the other two smooth,
/// interior, regular, and each crease vertex with equal sharpness on opposite edges.
/// Returns the face edge along the crease.
pub(crate) fn single_crease_edge(t: &Topology, f: usize, corners: &[VTag]) -> Option<usize> {
    let all = VTag::union(corners.iter().copied());
    if all.rule() & VTag::RULE_CREASE == 0
        || all.rule() & (VTag::RULE_CORNER | VTag::RULE_DART) != 0
        || all.has(VTag::BOUNDARY | VTag::XORDINARY | VTag::NON_MANIFOLD)
    {
        return None;
    }
    let mask = corners.iter().enumerate().fold(0, |m, (i, t)| {
        m | (usize::from(t.rule() == VTag::RULE_CREASE) << i)
    });
    let edge = match mask {
        3 => 0,
        6 => 1,
        12 => 2,
        9 => 3,
        _ => return None,
    };
    let fv = t.face_vertices(f);
    for x in [fv[edge], fv[(edge + 1) % 4]] {
        let e = t.vertex_edges(x as usize);
        let s = |i: usize| t.edge_sharpness(e[i] as usize);
        if e.len() != 4 || s(0) != s(2) || s(1) != s(3) {
            return None;
        }
    }
    Some(edge)
}
