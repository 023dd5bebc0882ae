//! The last Catmull-Clark or Loop level built from its grandparent, skipping its parent's
//! topology.
//!
//! On a closed, smooth level `G` of quads (Catmull-Clark) or triangles (Loop) — no
//! boundary, no sharpness, no holes, no non-manifold or degenerate parts — the next level
//! `M` is again closed, smooth and of the same face size, and every relation of `M` is a
//! closed form of `G`'s: its faces are the children that [`split`] lists per parent face,
//! its edges the face-interior edges and edge halves of the split, and each vertex of `M`
//! is a child of a vertex, face or edge of `G` with neighbours that `G`'s relations name
//! directly. The level after `M` — faces, rules and points — therefore needs `G`'s topology
//! and `M`'s points only. Building `M`'s full topology (edges, edge-faces, vertex-faces,
//! vertex-edges: most of the memory and time of a uniform refinement) only to read it once
//! is skipped; `M`'s topology is still built if anyone asks for it.
//!
//! Every child is computed with the same operations in the same order as the general path
//! ([`super::Step::points`] over `M`'s built topology), so the results are identical bit
//! for bit; the relation orders below are those of [`split::quad_split`] and
//! [`split::tri_split`].

use glam::DVec3;
use rayon::prelude::*;
use subd_mesh::Topology;

use std::ops::Range;

use super::Sdc;
use super::rows::{self, PointRows};
use super::{loop_smooth_weights, split};
use crate::rules::Rule;

/// Whether the level after the child of `g` can be built from `g` directly: the scheme is
/// Catmull-Clark on an all-quad `g` or Loop (all triangles), and `g` is closed and
/// manifold (every edge has two faces and two distinct ends, no vertex is non-manifold or
/// isolated), has no sharpness and no holes, and every vertex is smooth.
pub(crate) fn applies(g: &Topology, rules: &[Rule], scheme: Sdc) -> bool {
    let faces = match scheme {
        Sdc::CatmullClark => split::all_quads(g),
        // Loop refines triangles only (checked before refining).
        Sdc::Loop => true,
        Sdc::Bilinear => false,
    };
    faces && rules.par_iter().all(|&r| r == Rule::Smooth) && g.is_closed_and_smooth()
}

/// Face size of every level that [`applies`] accepts, and of its children.
fn face_size(scheme: Sdc) -> usize {
    if scheme == Sdc::Loop { 3 } else { 4 }
}

/// Counts of the child `M` of a closed level `g` that [`applies`]: (vertices, faces,
/// edges).
fn child_counts(g: &Topology, scheme: Sdc) -> (usize, usize, usize) {
    let (nv, nf, ne) = (g.num_vertices(), g.num_faces(), g.num_edges());
    match scheme {
        Sdc::Loop => (nv + ne, 4 * nf, 3 * nf + 2 * ne),
        _ => (nv + nf + ne, 4 * nf, 4 * nf + 2 * ne),
    }
}

/// Whether `M` is too large to refine: the bound `Refinement::new` puts on every parent
/// level (its child's face-vertices and edges must stay below `u32::MAX`).
pub(crate) fn child_too_large(g: &Topology, scheme: Sdc) -> bool {
    let (_, nf, ne) = child_counts(g, scheme);
    4 * (face_size(scheme) * nf) as u64 + 4 * ne as u64 >= u32::MAX as u64
}

/// Number of vertices of the grandchild of `g`: children of `M`'s vertices, faces (quad
/// split only) and edges.
pub(crate) fn grandchild_num_vertices(g: &Topology, scheme: Sdc) -> usize {
    let (nv, nf, ne) = child_counts(g, scheme);
    nv + if scheme == Sdc::Loop { 0 } else { nf } + ne
}

/// Number of edges of the grandchild of `g`: the interior edges of `M`'s faces (one per
/// face-vertex) and two halves per edge of `M`.
pub(crate) fn grandchild_num_edges(g: &Topology, scheme: Sdc) -> usize {
    let (_, nf, ne) = child_counts(g, scheme);
    face_size(scheme) * nf + 2 * ne
}

/// Face offsets and face-vertex lists of the grandchild of `g`.
pub(crate) fn grandchild_faces(g: &Topology, scheme: Sdc) -> (Vec<u32>, Vec<u32>) {
    match scheme {
        Sdc::Loop => grandchild_triangles(g),
        _ => grandchild_quads(g),
    }
}

/// Points of the grandchild of `g` from `src`, the points of its child `M`.
pub(crate) fn grandchild_points(g: &Topology, scheme: Sdc, src: &[DVec3]) -> Vec<DVec3> {
    match scheme {
        Sdc::Loop => rows::build(&LoopGrandchildRows::new(g, src)),
        _ => rows::build(&CatmarkGrandchildRows::new(g, src)),
    }
}

/// Face-vertex lists of the Catmull-Clark grandchildren of `g` (16 quads per face of `g`, in the order
/// the split of the built child gives them): each child quad of `g` split again by the
/// same rule, from its vertices and edges as [`split::quad_child_vertices`] and
/// [`split::quad_child_edges`] list them.
fn grandchild_quads(g: &Topology) -> (Vec<u32>, Vec<u32>) {
    let vertices = split::per_face(g.num_faces(), |f| grandchild_quad_block(g, f));
    (split::uniform_offsets(16 * g.num_faces(), 4), vertices)
}

/// The 16 grandchild quads of face `f` of `g`, 4 vertices each.
pub(crate) fn grandchild_quad_block(g: &Topology, f: usize) -> [u32; 64] {
    let (nv_m, nf_m, _) = child_counts(g, Sdc::CatmullClark);
    let (nv_m, nf_m) = (nv_m as u32, nf_m as u32);
    let cv = split::quad_child_vertices(g, f);
    let ce = split::quad_child_edges(g, f);
    let mut out = [0u32; 64];
    for k in 0..4 {
        let fv = &cv[4 * k..4 * k + 4];
        let fp = nv_m + (4 * f + k) as u32;
        let e = [0, 1, 2, 3].map(|j| nv_m + nf_m + ce[4 * k + j]);
        out[16 * k..16 * k + 16].copy_from_slice(&[
            fv[0], e[0], fp, e[3], e[0], fv[1], e[1], fp, fp, e[1], fv[2], e[2], e[3], fp, e[2],
            fv[3],
        ]);
    }
    out
}

/// Catmull-Clark points of the grandchild level of `g` from `src`, the points of its child
/// `M`: face points of `M`'s faces first (the middle rows), then the smooth vertex and edge
/// rules, which read them.
pub(crate) struct CatmarkGrandchildRows<'a> {
    g: &'a Topology,
    src: &'a [DVec3],
}

impl<'a> CatmarkGrandchildRows<'a> {
    pub(crate) fn new(g: &'a Topology, src: &'a [DVec3]) -> Self {
        let (nv_m, _, _) = child_counts(g, Sdc::CatmullClark);
        assert_eq!(src.len(), nv_m, "one point per vertex of the child level");
        CatmarkGrandchildRows { g, src }
    }
}

impl PointRows for CatmarkGrandchildRows<'_> {
    fn len(&self) -> usize {
        grandchild_num_vertices(self.g, Sdc::CatmullClark)
    }

    fn middle(&self) -> Range<usize> {
        let (nv_m, nf_m, _) = child_counts(self.g, Sdc::CatmullClark);
        nv_m..nv_m + nf_m
    }

    fn middle_row(&self, r: usize) -> DVec3 {
        let (g, src) = (self.g, self.src);
        let nv_m = self.middle().start;
        // Face `4F + k` of `M`: child `k` of face `F` of `g`.
        let (f, k) = ((r - nv_m) / 4, (r - nv_m) % 4);
        let cv = split::quad_child_vertices(g, f);
        let mut acc = DVec3::ZERO;
        for &v in &cv[4 * k..4 * k + 4] {
            acc += 0.25 * src[v as usize];
        }
        acc
    }

    fn row(&self, r: usize, face_points: &[DVec3]) -> DVec3 {
        let (g, src) = (self.g, self.src);
        let (nv, nf) = (g.num_vertices(), g.num_faces());
        let Range {
            start: nv_m,
            end: middle_end,
        } = self.middle();
        let nf_m = middle_end - nv_m;
        let nh = 4 * nf;
        let face_point = |f: usize| (nv + f) as u32;
        let edge_point = |e: usize| (nv + nf + e) as u32;
        if r < nv_m {
            return if r < nv {
                // Child of vertex `v`: the children of its faces (at its corner) and
                // the halves of its edges, whose far ends are the edge points.
                let faces = g.vertex_faces(r);
                let corners = g.vertex_face_local_indices(r);
                let n = faces.len();
                let w = 1.0 / (n * n) as f64;
                let mut acc = DVec3::ZERO;
                for (&pf, &c) in faces.iter().zip(corners) {
                    acc += w * face_points[4 * pf as usize + c as usize];
                }
                for &e in g.vertex_edges(r) {
                    acc += w * src[edge_point(e as usize) as usize];
                }
                let n = n as f64;
                acc + ((n - 2.0) / n) * src[r]
            } else if r < nv + nf {
                // Child of face `F`: its four child faces; its interior edges, the
                // last first, end at the edge points.
                let f = r - nv;
                let fe = g.face_edges(f);
                let w = 1.0 / 16.0;
                let mut acc = DVec3::ZERO;
                for j in 0..4 {
                    acc += w * face_points[4 * f + j];
                }
                for j in [3, 0, 1, 2] {
                    acc += w * src[edge_point(fe[j] as usize) as usize];
                }
                acc + 0.5 * src[r]
            } else {
                // Child of edge `E`: two children of each adjacent face, and the
                // halves and interior edges around it in the split's order.
                let e = r - nv - nf;
                let [a, b] = g.edge_vertices(e);
                let ef = g.edge_faces(e);
                let el = g.edge_face_local_indices(e);
                let w = 1.0 / 16.0;
                let mut acc = DVec3::ZERO;
                for (&pf, &l) in ef.iter().zip(el) {
                    let (pf, l) = (pf as usize, l as usize);
                    acc += w * face_points[4 * pf + (l + 1) % 4];
                    acc += w * face_points[4 * pf + l];
                }
                let same_dir = g.face_vertices(ef[0] as usize)[el[0] as usize] == a;
                let (first, second) = if same_dir { (b, a) } else { (a, b) };
                acc += w * src[first as usize];
                acc += w * src[face_point(ef[0] as usize) as usize];
                acc += w * src[second as usize];
                acc += w * src[face_point(ef[1] as usize) as usize];
                acc + 0.5 * src[r]
            };
        }
        // Edge points of `M`'s edges: the interior edges of each face of `g`, then
        // the two halves of each edge of `g`.
        let e = r - nv_m - nf_m;
        let (a, b, f0, f1) = if e < nh {
            let (f, j) = (e / 4, e % 4);
            (
                face_point(f),
                edge_point(g.face_edges(f)[j] as usize),
                4 * f + j,
                4 * f + (j + 1) % 4,
            )
        } else {
            let (pe, k) = ((e - nh) / 2, (e - nh) % 2);
            let end = g.edge_vertices(pe)[k];
            let ef = g.edge_faces(pe);
            let el = g.edge_face_local_indices(pe);
            let child = |i: usize| {
                let (pf, l) = (ef[i] as usize, el[i] as usize);
                let c = usize::from(g.face_vertices(pf)[l] != end);
                4 * pf + (l + c) % 4
            };
            (edge_point(pe), end, child(0), child(1))
        };
        let mut acc = 0.25 * src[a as usize];
        acc += 0.25 * src[b as usize];
        acc += 0.25 * face_points[f0];
        acc += 0.25 * face_points[f1];
        acc
    }
}

/// Face-vertex lists of the Loop grandchildren of `g` (16 triangles per triangle of `g`):
/// each child triangle split again by [`split::tri_child_vertices`]'s rule, from its
/// vertices and edges as [`split::tri_child_vertices`] and [`split::tri_child_edges`] list
/// them.
fn grandchild_triangles(g: &Topology) -> (Vec<u32>, Vec<u32>) {
    let vertices = split::per_face(g.num_faces(), |f| grandchild_triangle_block(g, f));
    (split::uniform_offsets(16 * g.num_faces(), 3), vertices)
}

/// The 16 grandchild triangles of triangle `f` of `g`, 3 vertices each.
pub(crate) fn grandchild_triangle_block(g: &Topology, f: usize) -> [u32; 48] {
    let nv_m = child_counts(g, Sdc::Loop).0 as u32;
    let cv = split::tri_child_vertices(g, f);
    let ce = split::tri_child_edges(g, f);
    let mut out = [0u32; 48];
    for k in 0..4 {
        let v = &cv[3 * k..3 * k + 3];
        let [e0, e1, e2] = [0, 1, 2].map(|j| nv_m + ce[3 * k + j]);
        out[12 * k..12 * k + 12]
            .copy_from_slice(&[v[0], e0, e2, e0, v[1], e1, e2, e1, v[2], e1, e2, e0]);
    }
    out
}

/// Loop points of the grandchild level of `g` from `src`, the points of its child `M`:
/// the smooth vertex rule of every vertex of `M`, then the smooth edge rule of every edge
/// (no middle rows: Loop has no face points).
pub(crate) struct LoopGrandchildRows<'a> {
    g: &'a Topology,
    src: &'a [DVec3],
}

impl<'a> LoopGrandchildRows<'a> {
    pub(crate) fn new(g: &'a Topology, src: &'a [DVec3]) -> Self {
        let (nv_m, _, _) = child_counts(g, Sdc::Loop);
        assert_eq!(src.len(), nv_m, "one point per vertex of the child level");
        LoopGrandchildRows { g, src }
    }
}

impl PointRows for LoopGrandchildRows<'_> {
    fn len(&self) -> usize {
        grandchild_num_vertices(self.g, Sdc::Loop)
    }

    fn middle(&self) -> Range<usize> {
        0..0
    }

    fn middle_row(&self, _r: usize) -> DVec3 {
        DVec3::ZERO
    }

    fn row(&self, r: usize, _middle: &[DVec3]) -> DVec3 {
        let (g, src) = (self.g, self.src);
        let (nv, nf) = (g.num_vertices(), g.num_faces());
        let (nv_m, _, _) = child_counts(g, Sdc::Loop);
        let edge_point = |e: usize| nv + e;
        let third = |f: usize, k: usize| edge_point(g.face_edges(f)[k % 3] as usize);
        let interior = 3 * nf;
        if r < nv_m {
            let mut acc = DVec3::ZERO;
            return if r < nv {
                // Child of vertex `v`: the halves of its edges end at the edge points.
                let (ew, vw) = loop_smooth_weights(g.vertex_faces(r).len());
                for &e in g.vertex_edges(r) {
                    acc += ew * src[edge_point(e as usize)];
                }
                acc + vw * src[r]
            } else {
                // Child of edge `E` (six faces, valence 6): the far ends of its halves
                // and of the interior edges of each adjacent face, in the split's order.
                let e = r - nv;
                let ev = g.edge_vertices(e);
                let ef = g.edge_faces(e);
                let el = g.edge_face_local_indices(e);
                let (f0, l0) = (ef[0] as usize, el[0] as usize);
                let rev = usize::from(g.face_vertices(f0)[l0] != ev[0]);
                let (ew, vw) = loop_smooth_weights(6);
                let ring = [
                    ev[1 - rev] as usize,
                    third(f0, l0 + 1),
                    third(f0, l0 + 2),
                    ev[rev] as usize,
                    third(ef[1] as usize, el[1] as usize + 1),
                    third(ef[1] as usize, el[1] as usize + 2),
                ];
                for o in ring {
                    acc += ew * src[o];
                }
                acc + vw * src[r]
            };
        }
        // Edge points of `M`'s edges: the three interior edges of each triangle of `g`
        // (edge `j` from `E_j` to `E_{j+2}`, between corner `j` and the middle child),
        // then the two halves of each edge of `g`. The far vertex of each adjacent child
        // triangle sits before the edge's position in it.
        let e = r - nv_m;
        let (a, b, o0, o1) = if e < interior {
            let (f, j) = (e / 3, e % 3);
            (
                third(f, j),
                third(f, j + 2),
                g.face_vertices(f)[j] as usize,
                third(f, j + 1),
            )
        } else {
            let (pe, k) = ((e - interior) / 2, (e - interior) % 2);
            let end = g.edge_vertices(pe)[k];
            let ef = g.edge_faces(pe);
            let el = g.edge_face_local_indices(pe);
            // The half lies in corner child `m` of each adjacent parent face, at the
            // parent edge's local index `l`: `m = l` at the edge's start corner, with far
            // vertex `E_{l-1}`, else `m = l + 1`, with far vertex `E_{l+1}`.
            let far = |i: usize| {
                let (pf, l) = (ef[i] as usize, el[i] as usize);
                if g.face_vertices(pf)[l] == end {
                    third(pf, l + 2)
                } else {
                    third(pf, l + 1)
                }
            };
            (edge_point(pe), end as usize, far(0), far(1))
        };
        let mut acc = DVec3::ZERO;
        acc += 0.375 * src[a];
        acc += 0.375 * src[b];
        acc += 0.125 * src[o0];
        acc += 0.125 * src[o1];
        acc
    }
}
