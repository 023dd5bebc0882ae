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
use subd_schemes::{Refinement, Scheme};

use crate::AdaptiveError;
use crate::hierarchy::AdaptiveRefinement;
use crate::level::Origin;
use subd_mesh::cut::NONE;

/// Decay levels up to which a piece is refined whole for its limits.
const LOCAL_DECAY: usize = 2;

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
        if !anchors.is_empty() {
            level_limits(h, l, anchors, &mut positions, &mut normals)?;
        }
    }
    Ok((positions, normals))
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
    // Edge points exist one level down: refine the cut once and take the limits there.
    let (topology, pts) = if edge_points {
        let r = Refinement::from_prepared(cut.topology, rules, h.scheme.clone(), &h.options, 1)?;
        let pts = r.refine_points(&points).pop().expect("one level");
        (r.into_topology(1), pts)
    } else {
        (cut.topology, points)
    };
    // subd-limit's exact limits of every vertex of the piece (refining only around semi-sharp
    // features, as far as they need to decay). Re-deriving the piece's tags changes only
    // vertices on its cut, whose limits are not read.
    // Past a couple of decay levels refining the whole piece costs 4^levels; subd-limit's
    // local path refines only around the semi-sharp features.
    let (decay, _) = subd_limit::levels_for_exact_limit(&topology, &h.scheme);
    let exact = if decay <= LOCAL_DECAY {
        subd_limit::base_limit(&topology, &h.scheme, &h.options)
    } else {
        subd_limit::local::base_limit(&topology, &h.scheme, &h.options)
    };
    let table = match exact {
        Err(e @ subd_limit::LimitError::Unsupported { .. }) => whole_limit(h, topology, &pts, e)?,
        other => other?,
    };
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

/// The limits [`subd_limit::base_limit`] gives, by refining the whole piece until semi-sharp
/// features have decayed: for the non-manifold pieces its local refinement does not
/// reproduce. The piece's tags are prepared as `base_limit` prepares them.
fn whole_limit(
    h: &AdaptiveRefinement,
    topology: subd_mesh::Topology,
    pts: &[DVec3],
    refused: subd_limit::LimitError,
) -> Result<subd_limit::LimitStencilTable, AdaptiveError> {
    let (levels, _) = subd_limit::levels_for_exact_limit(&topology, &h.scheme);
    let size = topology
        .num_face_vertices()
        .saturating_mul(4usize.saturating_pow(levels as u32));
    if size > subd_limit::MAX_DECAY_FACE_VERTICES {
        return Err(refused.into());
    }
    let r = Refinement::new(&topology, h.scheme.clone(), &h.options, levels)?;
    let mut table = subd_limit::LimitStencilTable::at_level(&r, levels)?;
    for l in (1..=levels).rev() {
        table = table.after(r.stencils(l));
    }
    debug_assert_eq!(table.position.num_sources(), pts.len());
    Ok(table)
}
