//! A child level of the channel from its parent: value offsets, face values, edge and
//! value tags, the semi-sharp reclassification, and each child value's stencil row.

use super::*;

/// The channel at the child level of `step` (§3): value counts, face values, edge and value
/// tags, crease ends, semi-sharp decay.
pub(super) fn child_level(
    step: &crate::refine::Step<'_>,
    parent: &ChannelLevel,
    flags: ModeFlags,
) -> ChannelLevel {
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
pub(super) fn child_value_offsets(
    step: &crate::refine::Step<'_>,
    parent: &ChannelLevel,
    quads: bool,
) -> Vec<u32> {
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
pub(super) fn child_face_values(
    step: &crate::refine::Step<'_>,
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
pub(super) fn child_edge_tags(
    step: &crate::refine::Step<'_>,
    parent: &ChannelLevel,
) -> (Vec<bool>, Vec<bool>) {
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
pub(super) fn child_value_tags(
    step: &crate::refine::Step<'_>,
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
pub(super) fn reclassify_semi_sharp(
    step: &crate::refine::Step<'_>,
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
pub(super) fn span_interior_edges(s: u16, e: u16, num_edges: usize) -> impl Iterator<Item = usize> {
    let (s, e) = (s as usize, e as usize);
    let count = if e >= s { e - s } else { e + num_edges - s };
    (1..=count).map(move |i| (s + i) % num_edges.max(1))
}

/// The mask of child value `r` (§4).
pub(super) fn value_row<S: ValueTerms>(
    step: &crate::refine::Step<'_>,
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
pub(super) fn fractional_weight(
    step: &crate::refine::Step<'_>,
    parent: &ChannelLevel,
    v: usize,
    slot: usize,
) -> f32 {
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
