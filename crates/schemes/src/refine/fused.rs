//! The last Catmull-Clark level built from its grandparent, skipping its parent's topology.
//!
//! On a closed, smooth, all-quad level `G` (no boundary, no sharpness, no holes, no
//! non-manifold or degenerate parts), the next level `M` is again closed, smooth and all
//! quads, and every relation of `M` is a closed form of `G`'s: its faces are the rotated
//! children of [`split::quad_child_vertices`], its edges the face-interior edges and edge
//! halves of [`split`], and each vertex of `M` is a child of a vertex, face or edge of `G`
//! with neighbours that `G`'s relations name directly. The level after `M` — faces, rules
//! and points — therefore needs `G`'s topology and `M`'s points only. Building `M`'s full
//! topology (edges, edge-faces, vertex-faces, vertex-edges: most of the memory and
//! time of a uniform refinement) only to read it once is skipped; `M`'s topology is still
//! built if anyone asks for it.
//!
//! Every child is computed with the same operations in the same order as the general path
//! ([`super::Step::points`] over `M`'s built topology), so the results are identical bit
//! for bit; the relation orders below are those of [`split::quad_split`].

use glam::DVec3;
use rayon::prelude::*;
use subd_mesh::Topology;

use super::{CHUNK, split};
use crate::memory;
use crate::rules::Rule;

/// Whether the level after the child of `g` can be built from `g` directly: `g` is all
/// quads, closed and manifold (every edge has two faces and two distinct ends, no vertex
/// is non-manifold or isolated), has no sharpness and no holes, and every vertex is smooth.
pub(crate) fn applies(g: &Topology, rules: &[Rule]) -> bool {
    let (nv, ne) = (g.num_vertices(), g.num_edges());
    split::all_quads(g)
        && !g.tags().holes().par_iter().any(|&h| h)
        && rules.par_iter().all(|&r| r == Rule::Smooth)
        && (0..ne).into_par_iter().with_min_len(CHUNK).all(|e| {
            let [a, b] = g.edge_vertices(e);
            a != b && g.edge_faces(e).len() == 2 && g.edge_sharpness(e) == 0.0
        })
        && (0..nv).into_par_iter().with_min_len(CHUNK).all(|v| {
            !g.is_non_manifold_vertex(v)
                && !g.is_isolated_vertex(v)
                && g.vertex_sharpness(v) == 0.0
                && g.vertex_faces(v).len() == g.vertex_edges(v).len()
        })
}

/// Counts of the child `M` of a closed all-quad level `g`: (vertices, faces, edges).
pub(crate) fn child_counts(g: &Topology) -> (usize, usize, usize) {
    let (nv, nf, ne) = (g.num_vertices(), g.num_faces(), g.num_edges());
    (nv + nf + ne, 4 * nf, 4 * nf + 2 * ne)
}

/// Face-vertex lists of the grandchildren of `g` (16 quads per face of `g`, in the order
/// the split of the built child gives them): each child quad of `g` split again by the
/// same rule, from its vertices and edges as [`split::quad_child_vertices`] and
/// [`split::quad_child_edges`] list them.
pub(crate) fn grandchild_faces(g: &Topology) -> (Vec<u32>, Vec<u32>) {
    let (nv_m, nf_m, _) = child_counts(g);
    let (nv_m, nf_m) = (nv_m as u32, nf_m as u32);
    let vertices = split::per_face(g.num_faces(), |f| {
        let cv = split::quad_child_vertices(g, f);
        let ce = split::quad_child_edges(g, f);
        let mut out = [0u32; 64];
        for k in 0..4 {
            let fv = &cv[4 * k..4 * k + 4];
            let fp = nv_m + (4 * f + k) as u32;
            let e = [0, 1, 2, 3].map(|j| nv_m + nf_m + ce[4 * k + j]);
            out[16 * k..16 * k + 16].copy_from_slice(&[
                fv[0], e[0], fp, e[3], e[0], fv[1], e[1], fp, fp, e[1], fv[2], e[2], e[3], fp,
                e[2], fv[3],
            ]);
        }
        out
    });
    (split::uniform_offsets(16 * g.num_faces(), 4), vertices)
}

/// Points of the grandchild level of `g` from `src`, the points of its child `M`: face
/// points of `M`'s faces first, then the smooth vertex and edge rules, which read them.
pub(crate) fn grandchild_points(g: &Topology, src: &[DVec3]) -> Vec<DVec3> {
    let (nv, nf) = (g.num_vertices(), g.num_faces());
    let (nv_m, nf_m, ne_m) = child_counts(g);
    assert_eq!(src.len(), nv_m, "one point per vertex of the child level");
    let nh = 4 * nf;
    let face_point = |f: usize| (nv + f) as u32;
    let edge_point = |e: usize| (nv + nf + e) as u32;
    memory::build_around(
        nv_m + nf_m + ne_m,
        nv_m..nv_m + nf_m,
        CHUNK,
        |r| {
            // Face `4F + k` of `M`: child `k` of face `F` of `g`.
            let (f, k) = ((r - nv_m) / 4, (r - nv_m) % 4);
            let cv = split::quad_child_vertices(g, f);
            let mut acc = DVec3::ZERO;
            for &v in &cv[4 * k..4 * k + 4] {
                acc += 0.25 * src[v as usize];
            }
            acc
        },
        |r, face_points| {
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
        },
    )
}
