//! Exact limit positions and normals of the output vertices, from subd-limit's masks.
//!
//! A vertex's limit is the same at every level it exists at (it is the child of itself), so
//! it is taken at the finest level where its whole ring of faces is present: there
//! [`LimitStencilTable::at_level`] applies, after refining the ring as far as semi-sharp
//! creases need to decay (a vertex's ring at the next level lies inside the children of its
//! ring, so the 1-ring is all the refinement reads). Only the edge points of transition
//! edges have no complete ring anywhere in the hierarchy (the leaf beside them is not
//! refined); their limit is taken one level down from the rings of their edge's two end
//! vertices, which are complete (they belong to the refined face across the edge) and which
//! contain every face the edge point's own ring is made from.

use glam::DVec3;
use subd_limit::LimitStencilTable;
use subd_schemes::{Refinement, Scheme};

use crate::AdaptiveError;
use crate::hierarchy::AdaptiveRefinement;
use crate::level::Origin;
use crate::submesh::NONE;

/// Where an output vertex's limit is taken.
#[derive(Clone, Copy, Debug)]
enum Anchor {
    /// A complete vertex of the level.
    Vertex(u32),
    /// The child of an edge of the level (one level down).
    EdgePoint(u32),
}

/// Limit positions and unit normals of the vertex instances `instances` (level, vertex).
pub(crate) fn limit_points(
    h: &AdaptiveRefinement,
    instances: &[(usize, usize)],
) -> Result<(Vec<DVec3>, Vec<DVec3>), AdaptiveError> {
    let mut by_level: Vec<Vec<(Anchor, usize)>> = vec![Vec::new(); h.levels.len()];
    for (i, &(l0, w0)) in instances.iter().enumerate() {
        let (mut l, mut w) = (l0, w0);
        let anchor = loop {
            let lv = &h.levels[l];
            if lv.is_complete(w) {
                break (l, Anchor::Vertex(w as u32));
            }
            match lv.vertex_origin[w] {
                Origin::Vertex(u) => {
                    l -= 1;
                    w = u as usize;
                }
                Origin::Edge(e) => break (l - 1, Anchor::EdgePoint(e)),
                Origin::Base | Origin::Face(_) => {
                    return Err(AdaptiveError::Internal(
                        "a base vertex or face point without its ring",
                    ));
                }
            }
        };
        by_level[anchor.0].push((anchor.1, i));
    }
    let mut positions = vec![DVec3::ZERO; instances.len()];
    let mut normals = vec![DVec3::ZERO; instances.len()];
    for (l, anchors) in by_level.iter().enumerate() {
        // Anchors whose rings still carry semi-sharp features are refined apart, so their
        // decay does not multiply the work of the rest.
        let lv = &h.levels[l];
        let (sharp, plain): (Vec<_>, Vec<_>) = anchors
            .iter()
            .partition(|(a, _)| anchor_rings(lv, *a).any(|v| ring_is_semi_sharp(lv, v)));
        for group in [plain, sharp] {
            if !group.is_empty() {
                level_limits(h, l, &group, &mut positions, &mut normals)?;
            }
        }
    }
    Ok((positions, normals))
}

/// The vertices whose rings an anchor's limit reads.
fn anchor_rings(lv: &crate::level::SparseLevel, a: Anchor) -> impl Iterator<Item = u32> {
    match a {
        Anchor::Vertex(v) => [v, NONE],
        Anchor::EdgePoint(e) => lv.topology.edge_vertices(e as usize),
    }
    .into_iter()
    .filter(|&v| v != NONE)
}

/// Whether a face around `v` has a semi-sharp edge or vertex.
fn ring_is_semi_sharp(lv: &crate::level::SparseLevel, v: u32) -> bool {
    use subd_mesh::tags::is_semi_sharp;
    let t = &lv.topology;
    t.vertex_faces(v as usize).iter().any(|&f| {
        t.face_edges(f as usize)
            .iter()
            .any(|&e| is_semi_sharp(t.edge_sharpness(e as usize)))
            || t.face_vertices(f as usize)
                .iter()
                .any(|&w| is_semi_sharp(t.vertex_sharpness(w as usize)))
    })
}

/// The limits of the anchors of level `l`, written to the anchors' output slots.
fn level_limits(
    h: &AdaptiveRefinement,
    l: usize,
    anchors: &[(Anchor, usize)],
    positions: &mut [DVec3],
    normals: &mut [DVec3],
) -> Result<(), AdaptiveError> {
    let lv = &h.levels[l];
    let t = &lv.topology;
    let mut take = vec![false; t.num_faces()];
    let mut ring = |v: u32| {
        for &f in t.vertex_faces(v as usize) {
            take[f as usize] = true;
        }
    };
    let mut edge_points = false;
    for &(a, _) in anchors {
        match a {
            Anchor::Vertex(v) => ring(v),
            Anchor::EdgePoint(e) => {
                edge_points = true;
                for v in t.edge_vertices(e as usize) {
                    if !lv.is_complete(v as usize) {
                        return Err(AdaptiveError::Internal(
                            "an edge point whose edge ends lack their rings",
                        ));
                    }
                    ring(v);
                }
            }
        }
    }
    let faces: Vec<u32> = (0..t.num_faces() as u32)
        .filter(|&f| take[f as usize])
        .collect();
    let (cut, rules, points) = lv.piece(&faces);
    let mut local_vertex = vec![NONE; t.num_vertices()];
    for (i, &v) in cut.vertices.iter().enumerate() {
        local_vertex[v as usize] = i as u32;
    }
    let mut local_edge = vec![NONE; t.num_edges()];
    for (i, &e) in cut.edges.iter().enumerate() {
        local_edge[e as usize] = i as u32;
    }
    let (nv, nf) = (cut.topology.num_vertices(), cut.topology.num_faces());
    let edge_point_base = if h.scheme == Scheme::Loop {
        nv
    } else {
        nv + nf
    };
    let (decay, _) = subd_limit::levels_for_exact_limit(&cut.topology, h.scheme);
    let levels = decay.max(usize::from(edge_points));
    let r = Refinement::from_prepared(cut.topology, rules, h.scheme, &h.options, levels)?;
    let pts = r.refine_points(&points).pop().expect("level 0 at least");
    let table = LimitStencilTable::at_level(&r, levels)?;
    let apply = |t: &subd_schemes::StencilTable, row: usize| -> DVec3 {
        let (idx, w) = t.row(row);
        idx.iter()
            .zip(w)
            .fold(DVec3::ZERO, |acc, (&i, &w)| acc + w * pts[i as usize])
    };
    for &(a, slot) in anchors {
        // A vertex keeps its index at every level of the refinement; an edge point gets the
        // child-of-edge index at level 1 and keeps it.
        let row = match a {
            Anchor::Vertex(v) => local_vertex[v as usize] as usize,
            Anchor::EdgePoint(e) => edge_point_base + local_edge[e as usize] as usize,
        };
        positions[slot] = apply(&table.position, row);
        let t1 = apply(&table.tangent1, row);
        let t2 = apply(&table.tangent2, row);
        normals[slot] = t1.cross(t2).normalize_or_zero();
    }
    Ok(())
}
