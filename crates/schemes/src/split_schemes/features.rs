//! Feature curves of a level: boundary edges and infinitely sharp creases, along which √3 and
//! the butterflies apply their curve rules.

use rayon::prelude::*;
use subd_mesh::{Topology, tags};

/// Which edges are feature edges (boundary, or an infinitely sharp crease) and how the feature
/// curves run through each vertex.
#[derive(Debug, Clone)]
pub struct Features {
    edge: Vec<bool>,
    /// Per vertex: the feature edges at it (up to two kept), and how many there are.
    at_vertex: Vec<([u32; 2], u8)>,
    corner: Vec<bool>,
}

impl Features {
    /// The features of `t`: boundary edges, infinitely sharp edges; a vertex is a corner when
    /// it has a corner tag or three or more feature edges.
    pub fn new(t: &Topology) -> Features {
        // Per edge, then per vertex from its edges: both in parallel.
        let edge: Vec<bool> = (0..t.num_edges())
            .into_par_iter()
            .with_min_len(4096)
            .map(|e| t.is_boundary_edge(e) || tags::is_infinite(t.edge_sharpness(e)))
            .collect();
        let (at_vertex, corner): (Vec<([u32; 2], u8)>, Vec<bool>) = (0..t.num_vertices())
            .into_par_iter()
            .with_min_len(4096)
            .map(|v| {
                let mut slot = ([u32::MAX; 2], 0u8);
                for &e in t.vertex_edges(v) {
                    if edge[e as usize] {
                        if (slot.1 as usize) < 2 {
                            slot.0[slot.1 as usize] = e;
                        }
                        slot.1 = slot.1.saturating_add(1);
                    }
                }
                (slot, slot.1 >= 3 || t.vertex_sharpness(v) > 0.0)
            })
            .unzip();
        Features {
            edge,
            at_vertex,
            corner,
        }
    }

    /// Whether edge `e` is a feature edge.
    #[inline]
    pub fn is_feature_edge(&self, e: usize) -> bool {
        self.edge[e]
    }

    /// Number of feature edges at `v`.
    #[inline]
    pub fn degree(&self, v: usize) -> usize {
        self.at_vertex[v].1 as usize
    }

    /// Whether `v` is on a feature curve (one feature edge or more).
    #[inline]
    pub fn is_on_feature(&self, v: usize) -> bool {
        self.at_vertex[v].1 > 0
    }

    /// Whether `v` is where feature curves end or meet: a corner tag, or three or more
    /// feature edges.
    #[inline]
    pub fn is_corner(&self, v: usize) -> bool {
        self.corner[v]
    }

    /// Whether `v` is inside a feature curve: exactly two feature edges and no corner tag.
    #[inline]
    pub fn is_curve_vertex(&self, v: usize) -> bool {
        self.at_vertex[v].1 == 2 && !self.corner[v]
    }

    /// The two feature edges of a curve vertex.
    #[inline]
    pub fn curve_edges(&self, v: usize) -> [u32; 2] {
        self.at_vertex[v].0
    }

    /// The neighbour of `v` along its feature curve other than across edge `e`: `None` when
    /// `v` is not inside a curve (an end, a corner, or a dart).
    pub fn curve_neighbour(&self, t: &Topology, v: u32, e: u32) -> Option<u32> {
        let vi = v as usize;
        if !self.is_curve_vertex(vi) {
            return None;
        }
        let [e0, e1] = self.at_vertex[vi].0;
        let other = if e0 == e { e1 } else { e0 };
        Some(t.edge_other_vertex(other as usize, v))
    }
}
