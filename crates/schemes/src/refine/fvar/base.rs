//! The channel's base level: which face-vertices' values match their neighbours', the
//! spans of faces around a vertex that share a value, and each value's kind under the
//! interpolation mode.

use super::*;

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
pub(super) fn base_level(t: &Topology, indices: &[u32], flags: ModeFlags) -> ChannelLevel {
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
pub(super) struct BaseScan<'a> {
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
pub(super) struct Span {
    size: u16,
    start: u16,
    discts: u16,
    semi: u16,
    inf: u16,
}

/// A mismatched vertex of the base level, as its values are classified.
pub(super) struct MismatchedVertex<'a> {
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
pub(super) fn classify_vertex(
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
        let inf_sharp =
            all_corners || s.inf > 0 || (s.size == 1 && flags.corners_sharp) || s.discts > 0;
        let mut tag = ValueTag {
            mismatch: true,
            span_faces: s.size,
            span_inf_edges: s.inf,
            disjoint: s.discts > 0,
            inf_sharp,
            ..ValueTag::default()
        };
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
pub(super) fn span_ends(s: &Span, k: usize, nf: usize) -> [u16; 2] {
    let (start, size) = (s.start as i64, s.size as i64);
    let end = if k == 0 && start != 0 {
        start + size - 1 - nf as i64
    } else {
        start + size - 1
    };
    [s.start, end as u16]
}
