//! Topology splits: the child topology of one uniform refinement step, with every relation
//! derived directly from the parent's in the order OpenSubdiv's `Vtr::QuadRefinement` and
//! `Vtr::TriRefinement` give it — no search, no sort, one pass per relation.
//!
//! Child vertices: children of parent vertices first (so vertex `v` stays `v`), then of
//! faces (quad split only), then of edges. Child faces are consecutive per parent face.
//! Child edges: the edges interior to each parent face (face order), then the two halves of
//! each parent edge (edge order), each half listed as (edge point, end vertex).

// The relations are indexed by parent face, edge and end together, so index loops read best.
#![allow(clippy::needless_range_loop)]

use std::ops::Range;

use rayon::prelude::*;
use subd_mesh::{Topology, TopologyParts};

use super::par;
use subd_mesh::memory;

/// Index of the half of parent edge `e` at its end `k` (0 or 1), relative to the first half.
#[inline]
fn half(e: u32, k: u32) -> u32 {
    2 * e + k
}

/// Which end (0 or 1) of parent edge `e` is at face corner vertex `v`: for a degenerate edge
/// the leaving side of the corner takes end 0 and the arriving side end 1.
#[inline]
fn end_at(p: &Topology, e: u32, v: u32, leaving: bool) -> u32 {
    let [a, b] = p.edge_vertices(e as usize);
    if a == b {
        u32::from(!leaving)
    } else {
        u32::from(a != v)
    }
}

/// Ends of each parent vertex's edges, in vertex-edge order: `k_i` with `e_i.v[k_i] == v`
/// (for a degenerate edge listed twice, 0 then 1).
#[inline]
fn vertex_edge_end(p: &Topology, v: usize, i: usize) -> u32 {
    let ve = p.vertex_edges(v);
    let e = ve[i];
    let [a, b] = p.edge_vertices(e as usize);
    if a == b {
        u32::from(i > 0 && ve[i - 1] == e)
    } else {
        u32::from(b as usize == v)
    }
}

/// The four child faces of parent quad `f`, in the order of [`quad_face_block`]:
/// `(V0, E0, F, E3)`, `(E0, V1, E1, F)`, `(F, E1, V2, E2)`, `(E3, F, E2, V3)`.
#[inline]
pub(super) fn quad_child_vertices(p: &Topology, f: usize) -> [u32; 16] {
    let (nv, nf) = (p.num_vertices() as u32, p.num_faces() as u32);
    let (fv, fe) = (p.face_vertices(f), p.face_edges(f));
    let fp = nv + f as u32;
    let e = [0, 1, 2, 3].map(|k| nv + nf + fe[k]);
    [
        fv[0], e[0], fp, e[3], e[0], fv[1], e[1], fp, fp, e[1], fv[2], e[2], e[3], fp, e[2], fv[3],
    ]
}

/// The edges of the four child faces of parent quad `f`, in the order of
/// [`quad_face_block`]: child k lists (a_k, I_k, I_{k-1}, b_k) rotated by k, where a_k is the
/// half of edge k at corner k, b_k the half of edge k-1 at corner k and I_k the interior edge
/// from the face point to edge point k.
#[inline]
pub(super) fn quad_child_edges(p: &Topology, f: usize) -> [u32; 16] {
    let hb = p.num_face_vertices() as u32;
    let base = p.face_offsets()[f];
    let (fv, fe) = (p.face_vertices(f), p.face_edges(f));
    let a = [0, 1, 2, 3].map(|k| hb + half(fe[k], end_at(p, fe[k], fv[k], true)));
    let b = [0, 1, 2, 3].map(|k| {
        let km1 = (k + 3) % 4;
        hb + half(fe[km1], end_at(p, fe[km1], fv[k], false))
    });
    let i = [0, 1, 2, 3].map(|k| base + k);
    [
        a[0], i[0], i[3], b[0], b[1], a[1], i[1], i[0], i[1], b[2], a[2], i[2], i[3], i[2], b[3],
        a[3],
    ]
}

/// `true` when every face of `p` is a quad: then each parent face has a fixed-size block of
/// children and the child arrays are written block by block, in place.
pub(super) fn all_quads(p: &Topology) -> bool {
    p.num_face_vertices() == 4 * p.num_faces()
        && p.face_offsets().par_windows(2).all(|w| w[1] - w[0] == 4)
}

/// A flat array made of one block (a `u32` array) per parent face, written once, in place.
pub(super) fn per_face<B: bytemuck::Pod + Send>(
    nf: usize,
    block: impl Fn(usize) -> B + Sync,
) -> Vec<u32> {
    let mut out: Vec<B> = memory::with_capacity(nf);
    out.par_extend((0..nf).into_par_iter().with_min_len(1024).map(&block));
    // A block is an array of `u32` (same alignment), so the buffer is reused as is.
    bytemuck::allocation::cast_vec(out)
}

/// Child faces of the quad split for parent faces `faces`: (V_k, E_k, F, E_{k-1}) with
/// edges (hNext, I_k, I_{k-1}, hPrev); a quad's child k is rotated so that the parent corner
/// sits at position k. Writes the vertices into `verts` and, when given, the edges into
/// `edges`; both start at the first child face-vertex of `faces`.
pub(super) fn quad_face_block(
    p: &Topology,
    faces: Range<usize>,
    verts: &mut [u32],
    mut edges: Option<&mut [u32]>,
) {
    let (nv, nf, nh) = (p.num_vertices(), p.num_faces(), p.num_face_vertices());
    let off = p.face_offsets();
    let face_point = |f: usize| (nv + f) as u32;
    let edge_point = |e: u32| (nv + nf) as u32 + e;
    let hb = nh as u32;
    let origin = 4 * off[faces.start] as usize;
    for f in faces {
        let fv = p.face_vertices(f);
        let fe = p.face_edges(f);
        let n = fv.len();
        let base = off[f];
        if n == 4 {
            let o = 4 * base as usize - origin;
            verts[o..o + 16].copy_from_slice(&quad_child_vertices(p, f));
            if let Some(out) = edges.as_deref_mut() {
                out[o..o + 16].copy_from_slice(&quad_child_edges(p, f));
            }
            continue;
        }
        for k in 0..n {
            let km1 = if k == 0 { n - 1 } else { k - 1 };
            let o = 4 * (base as usize + k) - origin;
            let vv = [fv[k], edge_point(fe[k]), face_point(f), edge_point(fe[km1])];
            verts[o..o + 4].copy_from_slice(&vv);
            if let Some(out) = edges.as_deref_mut() {
                let ee = [
                    hb + half(fe[k], end_at(p, fe[k], fv[k], true)),
                    base + k as u32,
                    base + km1 as u32,
                    hb + half(fe[km1], end_at(p, fe[km1], fv[k], false)),
                ];
                out[o..o + 4].copy_from_slice(&ee);
            }
        }
    }
}

/// Face offsets and face-vertices of the quad split alone.
pub(crate) fn quad_faces(p: &Topology) -> (Vec<u32>, Vec<u32>) {
    let (nf, nh) = (p.num_faces(), p.num_face_vertices());
    let off = p.face_offsets();
    let face_vertices = if all_quads(p) {
        per_face(nf, |f| quad_child_vertices(p, f))
    } else {
        par::build(
            4 * nh,
            nf,
            |f| 4 * off[f] as usize,
            |r, out| quad_face_block(p, r, out, None),
        )
    };
    (uniform_offsets(nh, 4), face_vertices)
}

/// Face offsets and face-vertices of the triangle split alone.
pub(crate) fn tri_faces(p: &Topology) -> (Vec<u32>, Vec<u32>) {
    let face_vertices = per_face(p.num_faces(), |f| tri_child_vertices(p, f));
    (uniform_offsets(4 * p.num_faces(), 3), face_vertices)
}

/// The four child triangles of parent triangle `f`: the corners `(V0, E0, E2)`,
/// `(E0, V1, E1)`, `(E2, E1, V2)`, then the middle `(E1, E2, E0)`.
#[inline]
pub(super) fn tri_child_vertices(p: &Topology, f: usize) -> [u32; 12] {
    let nv = p.num_vertices() as u32;
    let v = p.face_vertices(f);
    let e = p.face_edges(f);
    let (e0, e1, e2) = (nv + e[0], nv + e[1], nv + e[2]);
    [v[0], e0, e2, e0, v[1], e1, e2, e1, v[2], e1, e2, e0]
}

/// The edges of the four child triangles of parent triangle `f`, in the order of
/// [`tri_child_vertices`] (edge `k` of a child joins its vertices `k` and `k + 1`).
#[inline]
pub(super) fn tri_child_edges(p: &Topology, f: usize) -> [u32; 12] {
    let hb = 3 * p.num_faces() as u32;
    let v = p.face_vertices(f);
    let e = p.face_edges(f);
    let i = 3 * f as u32;
    // S_k: the half of edge k at its start corner; T_k: at its end corner.
    let s = |k: usize| hb + half(e[k], end_at(p, e[k], v[k], true));
    let t = |k: usize| hb + half(e[k], end_at(p, e[k], v[(k + 1) % 3], false));
    [
        s(0),
        i,
        t(2),
        t(0),
        s(1),
        i + 1,
        i + 2,
        t(1),
        s(2),
        i + 2,
        i,
        i + 1,
    ]
}

/// Offsets of `faces` faces of `size` vertices each.
pub(crate) fn uniform_offsets(faces: usize, size: u32) -> Vec<u32> {
    let mut out = memory::with_capacity(faces + 1);
    out.par_extend(
        (0..faces + 1)
            .into_par_iter()
            .with_min_len(4096)
            .map(|i| size * i as u32),
    );
    out
}

/// Offsets of a child vertex relation: vertex-children copy the parent's offsets
/// (`parent[..nv]`), face-children start at `face_start(f)` and edge-children at
/// `edge_start(e)`; `edge_start(ne)` closes the array. All closed forms, filled in parallel.
fn child_vertex_offsets(
    parent: &[u32],
    nf: usize,
    ne: usize,
    face_start: impl Fn(usize) -> usize + Sync + Send,
    edge_start: impl Fn(usize) -> usize + Sync + Send,
) -> Vec<u32> {
    let nv = parent.len() - 1;
    let mut out = memory::zeroed(nv + nf + ne + 1);
    let (a, rest) = out.split_at_mut(nv);
    let (b, c) = rest.split_at_mut(nf);
    a.copy_from_slice(&parent[..nv]);
    b.par_iter_mut()
        .enumerate()
        .for_each(|(f, o)| *o = face_start(f) as u32);
    c.par_iter_mut()
        .enumerate()
        .for_each(|(e, o)| *o = edge_start(e) as u32);
    out
}

/// Vertices of the half-edge children, `H(e, k) = (E_e, V_{e.v[k]})`, into `out` (two per
/// parent edge); `edge_point_base` is the first edge-child vertex.
fn half_edge_vertices(p: &Topology, edge_point_base: usize, out: &mut [[u32; 2]]) {
    par::fill(
        out,
        p.num_edges(),
        |e| 2 * e,
        |r, out| {
            for (i, e) in r.enumerate() {
                let [a, b] = p.edge_vertices(e);
                let ep = (edge_point_base + e) as u32;
                out[2 * i] = [ep, a];
                out[2 * i + 1] = [ep, b];
            }
        },
    );
}

/// Edge-face offsets of a child level: two faces per face-interior child edge (the first
/// `interior_edges` edges), then for each parent edge two halves with as many faces as the
/// parent edge has.
fn child_edge_face_offsets(p: &Topology, interior_edges: usize) -> Vec<u32> {
    let (ne, pefo) = (p.num_edges(), p.edge_face_offsets());
    let mut out = memory::zeroed(interior_edges + 2 * ne + 1);
    let (a, b) = out.split_at_mut(interior_edges);
    a.par_iter_mut()
        .enumerate()
        .for_each(|(i, o)| *o = 2 * i as u32);
    b.par_chunks_mut(2).enumerate().for_each(|(e, o)| {
        let base = (2 * interior_edges) as u32 + 2 * pefo[e];
        o[0] = base;
        if e < ne {
            o[1] = base + (pefo[e + 1] - pefo[e]);
        }
    });
    out
}

/// Flags the children inherit (`Vtr::Refinement::propagateComponentTags`): both halves of a
/// parent edge take its boundary and non-manifold flags, a vertex-child its vertex's
/// non-manifold flag, an edge-child its edge's; the `interior_edges` face-interior edges and
/// `face_children` face-children are manifold interior. Returns (edge boundary, edge
/// non-manifold, vertex non-manifold).
fn inherited_flags(
    p: &Topology,
    interior_edges: usize,
    face_children: usize,
) -> (Vec<bool>, Vec<bool>, Vec<bool>) {
    let (nv, ne) = (p.num_vertices(), p.num_edges());
    let mut edge_boundary = memory::zeroed::<bool>(interior_edges + 2 * ne);
    let mut edge_non_manifold = memory::zeroed::<bool>(interior_edges + 2 * ne);
    for (dst, nm) in [(&mut edge_boundary, false), (&mut edge_non_manifold, true)] {
        dst[interior_edges..]
            .par_chunks_mut(2)
            .enumerate()
            .for_each(|(e, o)| {
                o.fill(if nm {
                    p.is_non_manifold_edge(e)
                } else {
                    p.is_boundary_edge(e)
                });
            });
    }
    let mut vertex_non_manifold = memory::zeroed::<bool>(nv + face_children + ne);
    vertex_non_manifold[..nv]
        .par_iter_mut()
        .enumerate()
        .for_each(|(v, o)| *o = p.is_non_manifold_vertex(v));
    vertex_non_manifold[nv + face_children..]
        .par_iter_mut()
        .enumerate()
        .for_each(|(e, o)| *o = p.is_non_manifold_edge(e));
    (edge_boundary, edge_non_manifold, vertex_non_manifold)
}

/// Vertex-edges of the vertex-children: the half of each parent vertex-edge at the vertex,
/// in the parent's order. `out` is the vertex-child part of the child vertex-edge relation.
fn vertex_child_edges(p: &Topology, hb: u32, out: &mut [u32]) {
    let pveo = p.vertex_edge_offsets();
    par::fill(
        out,
        p.num_vertices(),
        |v| pveo[v] as usize,
        |r, out| {
            let mut i = 0;
            for v in r {
                for (k, &e) in p.vertex_edges(v).iter().enumerate() {
                    out[i] = hb + half(e, vertex_edge_end(p, v, k));
                    i += 1;
                }
            }
        },
    );
}

/// The quad split of Catmull-Clark and Bilinear: every face of size n becomes n quads (the
/// relations; the caller adds the tags).
/// Every relation is filled in parallel blocks; offsets come in closed form from the
/// parent's offsets.
pub(crate) fn quad_split(p: &Topology) -> TopologyParts {
    let nh = p.num_face_vertices();
    let (face_vertices, face_edges) = quad_face_relations(p);
    let (edge_face_offsets, edge_faces, edge_face_local) = quad_edge_faces(p);
    let (vertex_face_offsets, vertex_faces, vertex_face_local) = quad_vertex_faces(p);
    let (vertex_edge_offsets, vertex_edges) = quad_vertex_edges(p);
    let (edge_boundary, edge_non_manifold, vertex_non_manifold) =
        inherited_flags(p, nh, p.num_faces());
    TopologyParts {
        num_vertices: p.num_vertices() + p.num_faces() + p.num_edges(),
        face_offsets: uniform_offsets(nh, 4),
        face_vertices,
        face_edges,
        edge_vertices: quad_edge_vertices(p),
        edge_face_offsets,
        edge_faces,
        edge_face_local,
        vertex_face_offsets,
        vertex_faces,
        vertex_face_local,
        vertex_edge_offsets,
        vertex_edges,
        edge_boundary,
        edge_non_manifold,
        vertex_non_manifold,
        ..TopologyParts::default()
    }
}

/// The quad split's child faces' vertices and edges, four each per parent face-vertex.
fn quad_face_relations(p: &Topology) -> (Vec<u32>, Vec<u32>) {
    let (nf, nh) = (p.num_faces(), p.num_face_vertices());
    if all_quads(p) {
        return (
            per_face(nf, |f| quad_child_vertices(p, f)),
            per_face(nf, |f| quad_child_edges(p, f)),
        );
    }
    let off = p.face_offsets();
    let mut face_vertices = memory::zeroed(4 * nh);
    let mut face_edges = memory::zeroed(4 * nh);
    par::fill_pair(
        &mut face_vertices,
        &mut face_edges,
        nf,
        |f| 4 * off[f] as usize,
        |r, verts, edges| quad_face_block(p, r, verts, Some(edges)),
    );
    (face_vertices, face_edges)
}

/// The quad split's child edges' vertices: I_f[j] = (F, E_j) for the face edges, then
/// H(e, k) = (E, V_{e.v[k]}).
fn quad_edge_vertices(p: &Topology) -> Vec<[u32; 2]> {
    let (nv, nf, ne, nh) = (
        p.num_vertices(),
        p.num_faces(),
        p.num_edges(),
        p.num_face_vertices(),
    );
    let off = p.face_offsets();
    let face_point = |f: usize| (nv + f) as u32;
    let edge_point = |e: usize| (nv + nf + e) as u32;
    let mut edge_vertices = memory::zeroed::<[u32; 2]>(nh + 2 * ne);
    let (interior, halves) = edge_vertices.split_at_mut(nh);
    par::fill(
        interior,
        nf,
        |f| off[f] as usize,
        |r, out| {
            let mut i = 0;
            for f in r {
                for &e in p.face_edges(f) {
                    out[i] = [face_point(f), edge_point(e as usize)];
                    i += 1;
                }
            }
        },
    );
    half_edge_vertices(p, nv + nf, halves);
    edge_vertices
}

/// The quad split's edge -> faces (offsets, faces, local indices): two per interior edge;
/// as many per half as the parent edge has faces.
fn quad_edge_faces(p: &Topology) -> (Vec<u32>, Vec<u32>, Vec<u16>) {
    let (nf, ne, nh) = (p.num_faces(), p.num_edges(), p.num_face_vertices());
    let off = p.face_offsets();
    let pefo = p.edge_face_offsets();
    let total_ef = 2 * nh + 2 * pefo[ne] as usize;
    let edge_face_offsets = child_edge_face_offsets(p, nh);
    let mut edge_faces = memory::zeroed(total_ef);
    let mut edge_face_local = memory::zeroed(total_ef);
    let (fa, fb) = edge_faces.split_at_mut(2 * nh);
    let (la, lb) = edge_face_local.split_at_mut(2 * nh);
    par::fill_pair(
        fa,
        la,
        nf,
        |f| 2 * off[f] as usize,
        |r, faces, local| {
            let mut i = 0;
            for f in r {
                let n = p.face_size(f);
                let base = off[f];
                for j in 0..n {
                    faces[i] = base + j as u32;
                    faces[i + 1] = base + ((j + 1) % n) as u32;
                    (local[i], local[i + 1]) = if n == 4 {
                        (((j + 1) % 4) as u16, ((j + 3) % 4) as u16)
                    } else {
                        (1, 2)
                    };
                    i += 2;
                }
            }
        },
    );
    par::fill_pair(
        fb,
        lb,
        ne,
        |e| 2 * pefo[e] as usize,
        |r, faces, local| {
            let mut i = 0;
            for e in r {
                let ev = p.edge_vertices(e);
                let degenerate = ev[0] == ev[1];
                for k in 0..2usize {
                    for (&pf, &l) in p.edge_faces(e).iter().zip(p.edge_face_local_indices(e)) {
                        let (pf, l) = (pf as usize, l as usize);
                        let n = p.face_size(pf);
                        let c = if degenerate {
                            k
                        } else {
                            usize::from(p.face_vertices(pf)[l] != ev[k])
                        };
                        faces[i] = off[pf] + ((l + c) % n) as u32;
                        local[i] = if n == 4 {
                            l as u16
                        } else if c == 1 {
                            3
                        } else {
                            0
                        };
                        i += 1;
                    }
                }
            }
        },
    );
    (edge_face_offsets, edge_faces, edge_face_local)
}

/// The quad split's vertex -> faces (offsets, faces, local indices): V_v (as the parent),
/// F_f (n), E_e (two per parent face).
fn quad_vertex_faces(p: &Topology) -> (Vec<u32>, Vec<u32>, Vec<u16>) {
    let (nv, nf, ne, nh) = (
        p.num_vertices(),
        p.num_faces(),
        p.num_edges(),
        p.num_face_vertices(),
    );
    let off = p.face_offsets();
    let pefo = p.edge_face_offsets();
    let pvfo = p.vertex_face_offsets();
    let nvf = pvfo[nv] as usize;
    let vertex_face_offsets = child_vertex_offsets(
        pvfo,
        nf,
        ne,
        |f| nvf + off[f] as usize,
        |e| nvf + nh + 2 * pefo[e] as usize,
    );
    let total_vf = nvf + nh + 2 * pefo[ne] as usize;
    let mut vertex_faces = memory::zeroed(total_vf);
    let mut vertex_face_local = memory::zeroed(total_vf);
    let (fa, rest) = vertex_faces.split_at_mut(nvf);
    let (fb, fc) = rest.split_at_mut(nh);
    let (la, rest) = vertex_face_local.split_at_mut(nvf);
    let (lb, lc) = rest.split_at_mut(nh);
    par::fill_pair(
        fa,
        la,
        nv,
        |v| pvfo[v] as usize,
        |r, faces, local| {
            let mut i = 0;
            for v in r {
                for (&pf, &c) in p.vertex_faces(v).iter().zip(p.vertex_face_local_indices(v)) {
                    faces[i] = off[pf as usize] + c as u32;
                    local[i] = if p.face_size(pf as usize) == 4 { c } else { 0 };
                    i += 1;
                }
            }
        },
    );
    par::fill_pair(
        fb,
        lb,
        nf,
        |f| off[f] as usize,
        |r, faces, local| {
            let mut i = 0;
            for f in r {
                let n = p.face_size(f);
                for j in 0..n {
                    faces[i] = off[f] + j as u32;
                    local[i] = if n == 4 { ((j + 2) % 4) as u16 } else { 2 };
                    i += 1;
                }
            }
        },
    );
    par::fill_pair(
        fc,
        lc,
        ne,
        |e| 2 * pefo[e] as usize,
        |r, faces, local| {
            let mut i = 0;
            for e in r {
                for (&pf, &l) in p.edge_faces(e).iter().zip(p.edge_face_local_indices(e)) {
                    let (pf, l) = (pf as usize, l as usize);
                    let n = p.face_size(pf);
                    faces[i] = off[pf] + ((l + 1) % n) as u32;
                    faces[i + 1] = off[pf] + l as u32;
                    (local[i], local[i + 1]) = if n == 4 {
                        (l as u16, ((l + 1) % 4) as u16)
                    } else {
                        (3, 1)
                    };
                    i += 2;
                }
            }
        },
    );
    (vertex_face_offsets, vertex_faces, vertex_face_local)
}

/// The quad split's vertex -> edges (offsets, edges): V_v (halves, as the parent), F_f
/// (interior, leading edges first), E_e (halves and interior edges interleaved, in
/// OpenSubdiv's order).
fn quad_vertex_edges(p: &Topology) -> (Vec<u32>, Vec<u32>) {
    let (nv, nf, ne, nh) = (
        p.num_vertices(),
        p.num_faces(),
        p.num_edges(),
        p.num_face_vertices(),
    );
    let off = p.face_offsets();
    let pefo = p.edge_face_offsets();
    let pveo = p.vertex_edge_offsets();
    let hb = nh as u32;
    let nve = pveo[nv] as usize;
    let vertex_edge_offsets = child_vertex_offsets(
        pveo,
        nf,
        ne,
        |f| nve + off[f] as usize,
        |e| nve + nh + pefo[e] as usize + 2 * e,
    );
    let total_ve = nve + nh + pefo[ne] as usize + 2 * ne;
    let mut vertex_edges = memory::zeroed(total_ve);
    let (a, rest) = vertex_edges.split_at_mut(nve);
    let (b, c) = rest.split_at_mut(nh);
    vertex_child_edges(p, hb, a);
    par::fill(
        b,
        nf,
        |f| off[f] as usize,
        |r, out| {
            let mut i = 0;
            for f in r {
                let n = p.face_size(f) as u32;
                let base = off[f];
                out[i] = base + n - 1;
                for j in 0..n - 1 {
                    out[i + 1 + j as usize] = base + j;
                }
                i += n as usize;
            }
        },
    );
    par::fill(
        c,
        ne,
        |e| pefo[e] as usize + 2 * e,
        |r, out| {
            let mut i = 0;
            for e in r {
                let ev = p.edge_vertices(e);
                let ef = p.edge_faces(e);
                let el = p.edge_face_local_indices(e);
                let (h0, h1) = (hb + half(e as u32, 0), hb + half(e as u32, 1));
                let first = off[ef[0] as usize] + el[0] as u32;
                let same_dir =
                    ev[0] != ev[1] && p.face_vertices(ef[0] as usize)[el[0] as usize] == ev[0];
                let head = if same_dir {
                    [h1, first, h0]
                } else {
                    [h0, first, h1]
                };
                out[i..i + 3].copy_from_slice(&head);
                i += 3;
                for (&pf, &l) in ef.iter().zip(el).skip(1) {
                    out[i] = off[pf as usize] + l as u32;
                    i += 1;
                }
            }
        },
    );
    (vertex_edge_offsets, vertex_edges)
}

/// The triangle split of Loop: every triangle becomes four (the relations; the caller adds
/// the tags). The caller checks that every face is a triangle. Filled in parallel blocks like the quad split.
pub(crate) fn tri_split(p: &Topology) -> TopologyParts {
    let (nv, nf, ne) = (p.num_vertices(), p.num_faces(), p.num_edges());
    let (face_offsets, face_vertices) = tri_faces(p);
    let face_edges = per_face(nf, |f| tri_child_edges(p, f));
    let (edge_face_offsets, edge_faces, edge_face_local) = tri_edge_faces(p);
    let (vertex_face_offsets, vertex_faces, vertex_face_local) = tri_vertex_faces(p);
    let (vertex_edge_offsets, vertex_edges) = tri_vertex_edges(p);
    let (edge_boundary, edge_non_manifold, vertex_non_manifold) = inherited_flags(p, 3 * nf, 0);
    TopologyParts {
        num_vertices: nv + ne,
        face_offsets,
        face_vertices,
        face_edges,
        edge_vertices: tri_edge_vertices(p),
        edge_face_offsets,
        edge_faces,
        edge_face_local,
        vertex_face_offsets,
        vertex_faces,
        vertex_face_local,
        vertex_edge_offsets,
        vertex_edges,
        edge_boundary,
        edge_non_manifold,
        vertex_non_manifold,
        ..TopologyParts::default()
    }
}

/// The triangle split's child edges' vertices: the three edges of each parent face's middle
/// triangle, `(E0, E2)`, `(E1, E0)`, `(E2, E1)`, then H(e, k) = (E, V_{e.v[k]}).
fn tri_edge_vertices(p: &Topology) -> Vec<[u32; 2]> {
    let (nv, nf, ne) = (p.num_vertices(), p.num_faces(), p.num_edges());
    let edge_point = |e: usize| (nv + e) as u32;
    let mut edge_vertices = memory::zeroed::<[u32; 2]>(3 * nf + 2 * ne);
    let (interior, halves) = edge_vertices.split_at_mut(3 * nf);
    par::fill(
        interior,
        nf,
        |f| 3 * f,
        |r, out| {
            for (o, f) in r.enumerate() {
                let e = p.face_edges(f);
                let (e0, e1, e2) = (
                    edge_point(e[0] as usize),
                    edge_point(e[1] as usize),
                    edge_point(e[2] as usize),
                );
                out[3 * o..3 * o + 3].copy_from_slice(&[[e0, e2], [e1, e0], [e2, e1]]);
            }
        },
    );
    half_edge_vertices(p, nv, halves);
    edge_vertices
}

/// The triangle split's edge -> faces (offsets, faces, local indices): each interior edge
/// borders its corner triangle and the middle one; each half as many faces as its parent.
fn tri_edge_faces(p: &Topology) -> (Vec<u32>, Vec<u32>, Vec<u16>) {
    let (nf, ne) = (p.num_faces(), p.num_edges());
    let pefo = p.edge_face_offsets();
    let total_ef = 6 * nf + 2 * pefo[ne] as usize;
    let edge_face_offsets = child_edge_face_offsets(p, 3 * nf);
    let mut edge_faces = memory::zeroed(total_ef);
    let mut edge_face_local = memory::zeroed(total_ef);
    let (fa, fb) = edge_faces.split_at_mut(6 * nf);
    let (la, lb) = edge_face_local.split_at_mut(6 * nf);
    par::fill_pair(
        fa,
        la,
        nf,
        |f| 6 * f,
        |r, faces, local| {
            for (o, f) in r.enumerate() {
                let f = f as u32;
                for j in 0..3u32 {
                    let k = 6 * o + 2 * j as usize;
                    faces[k..k + 2].copy_from_slice(&[4 * f + j, 4 * f + 3]);
                    local[k..k + 2].fill(((j + 1) % 3) as u16);
                }
            }
        },
    );
    par::fill_pair(
        fb,
        lb,
        ne,
        |e| 2 * pefo[e] as usize,
        |r, faces, local| {
            let mut i = 0;
            for e in r {
                let ev = p.edge_vertices(e);
                let degenerate = ev[0] == ev[1];
                for k in 0..2usize {
                    for (&pf, &l) in p.edge_faces(e).iter().zip(p.edge_face_local_indices(e)) {
                        let c = if degenerate {
                            k as u32
                        } else {
                            u32::from(p.face_vertices(pf as usize)[l as usize] != ev[k])
                        };
                        faces[i] = 4 * pf + (l as u32 + c) % 3;
                        local[i] = l;
                        i += 1;
                    }
                }
            }
        },
    );
    (edge_face_offsets, edge_faces, edge_face_local)
}

/// The triangle split's vertex -> faces (offsets, faces, local indices): V_v (as the
/// parent), then E_e (three per parent face: two corner triangles and the middle one).
fn tri_vertex_faces(p: &Topology) -> (Vec<u32>, Vec<u32>, Vec<u16>) {
    let (nv, ne) = (p.num_vertices(), p.num_edges());
    let pefo = p.edge_face_offsets();
    let pvfo = p.vertex_face_offsets();
    let nvf = pvfo[nv] as usize;
    let total_vf = nvf + 3 * pefo[ne] as usize;
    let vertex_face_offsets =
        child_vertex_offsets(pvfo, 0, ne, |_| 0, |e| nvf + 3 * pefo[e] as usize);
    let mut vertex_faces = memory::zeroed(total_vf);
    let mut vertex_face_local = memory::zeroed(total_vf);
    let (fa, fb) = vertex_faces.split_at_mut(nvf);
    let (la, lb) = vertex_face_local.split_at_mut(nvf);
    par::fill_pair(
        fa,
        la,
        nv,
        |v| pvfo[v] as usize,
        |r, faces, local| {
            let mut i = 0;
            for v in r {
                for (&pf, &c) in p.vertex_faces(v).iter().zip(p.vertex_face_local_indices(v)) {
                    faces[i] = 4 * pf + c as u32;
                    local[i] = c;
                    i += 1;
                }
            }
        },
    );
    par::fill_pair(
        fb,
        lb,
        ne,
        |e| 3 * pefo[e] as usize,
        |r, faces, local| {
            let mut i = 0;
            for e in r {
                for (&pf, &l) in p.edge_faces(e).iter().zip(p.edge_face_local_indices(e)) {
                    let l32 = l as u32;
                    faces[i..i + 3].copy_from_slice(&[
                        4 * pf + (l32 + 1) % 3,
                        4 * pf + 3,
                        4 * pf + l32,
                    ]);
                    local[i..i + 3].copy_from_slice(&[l, (l + 2) % 3, (l + 1) % 3]);
                    i += 3;
                }
            }
        },
    );
    (vertex_face_offsets, vertex_faces, vertex_face_local)
}

/// The triangle split's vertex -> edges (offsets, edges): V_v takes the half of each parent
/// edge at it; E_e its two halves around the first face's two interior edges, then two
/// interior edges per further face (OpenSubdiv's order).
fn tri_vertex_edges(p: &Topology) -> (Vec<u32>, Vec<u32>) {
    let (nv, nf, ne) = (p.num_vertices(), p.num_faces(), p.num_edges());
    let pefo = p.edge_face_offsets();
    let pveo = p.vertex_edge_offsets();
    let hb = 3 * nf as u32;
    let nve = pveo[nv] as usize;
    let total_ve = nve + 2 * pefo[ne] as usize + 2 * ne;
    let vertex_edge_offsets =
        child_vertex_offsets(pveo, 0, ne, |_| 0, |e| nve + 2 * pefo[e] as usize + 2 * e);
    let mut vertex_edges = memory::zeroed(total_ve);
    let (a, b) = vertex_edges.split_at_mut(nve);
    vertex_child_edges(p, hb, a);
    par::fill(
        b,
        ne,
        |e| 2 * pefo[e] as usize + 2 * e,
        |r, out| {
            let mut i = 0;
            for e in r {
                let ev = p.edge_vertices(e);
                let ef = p.edge_faces(e);
                let el = p.edge_face_local_indices(e);
                let (pf, l) = (ef[0], el[0] as u32);
                let rev =
                    u32::from(ev[0] != ev[1] && p.face_vertices(pf as usize)[l as usize] != ev[0]);
                out[i..i + 4].copy_from_slice(&[
                    hb + half(e as u32, 1 - rev),
                    3 * pf + (l + 1) % 3,
                    3 * pf + l,
                    hb + half(e as u32, rev),
                ]);
                i += 4;
                for (&pf, &l) in ef.iter().zip(el).skip(1) {
                    let l = l as u32;
                    out[i..i + 2].copy_from_slice(&[3 * pf + (l + 1) % 3, 3 * pf + l]);
                    i += 2;
                }
            }
        },
    );
    (vertex_edge_offsets, vertex_edges)
}
