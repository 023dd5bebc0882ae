//! The child relations of a Doo-Sabin step over a closed parent whose every vertex gets a
//! vertex face, in closed form from the parent's (no search beyond a vertex's own ring),
//! filled in parallel. [`doo_sabin::Step`](super::doo_sabin::Step) uses it there and builds
//! other levels (boundaries, valence-2 or isolated vertices) from their faces.
//!
//! Child vertices: one per parent corner `h` (face `f`, corner `k`). Child faces: the F-face
//! `f` (the corners of `f`), the E-face `nf + e = (b0, a0, ga, gb)` of parent edge
//! `e = (a, b)` (`a0`, `b0` the corners of its first face `f`, `ga`, `gb` those of its second
//! face `g`), the V-face `nf + ne + v` (the corners around `v`, in ring order). Child edges
//! (numbered here, put in the builder's order by [`subd_mesh::canonical::builder_order`]):
//! the F-edge `h` from corner `h` to the next corner of its face, then the spoke
//! `S(e, x) = nh + 2e + x` joining the corners at end `x` of `e` in its two faces.

// The relations are indexed by parent face, edge and corner together.
#![allow(clippy::needless_range_loop)]

use rayon::prelude::*;
use subd_mesh::{Topology, TopologyParts, memory};

use crate::refine::par;

/// Whether the closed form applies: no boundary edge, every vertex with three faces or more
/// (so every vertex has a V-face and every ring is closed); manifold, as the scheme's input
/// checks and the split keeps.
pub(crate) fn applies(p: &Topology) -> bool {
    (0..p.num_edges())
        .into_par_iter()
        .with_min_len(4096)
        .all(|e| p.edge_faces(e).len() == 2)
        && (0..p.num_vertices())
            .into_par_iter()
            .with_min_len(4096)
            .all(|v| p.vertex_faces(v).len() >= 3)
}

/// The child relations (the caller adds the tags).
pub(crate) fn split(p: &Topology) -> TopologyParts {
    let (ne, nh) = (p.num_edges(), p.num_face_vertices());
    let (face_offsets, face_vertices, face_edges) = faces(p);
    let (edge_faces, edge_face_local) = edge_faces(p);
    let (vertex_faces, vertex_face_local, vertex_edges) = rings(p);
    TopologyParts {
        num_vertices: nh,
        face_offsets,
        face_vertices,
        face_edges,
        edge_vertices: edge_vertices(p),
        edge_face_offsets: crate::refine::split::uniform_offsets(nh + 2 * ne, 2),
        edge_faces,
        edge_face_local,
        vertex_face_offsets: crate::refine::split::uniform_offsets(nh, 4),
        vertex_faces,
        vertex_face_local,
        vertex_edge_offsets: crate::refine::split::uniform_offsets(nh, 4),
        vertex_edges,
        edge_boundary: memory::zeroed(nh + 2 * ne),
        edge_non_manifold: memory::zeroed(nh + 2 * ne),
        vertex_non_manifold: memory::zeroed(nh),
        ..TopologyParts::default()
    }
}

/// Corner `k` of face `f` as a child vertex.
#[inline]
fn corner(p: &Topology, f: usize, k: usize) -> u32 {
    p.face_offsets()[f] + (k % p.face_size(f)) as u32
}

/// The spoke at end `x` of parent edge `e`.
#[inline]
fn spoke(p: &Topology, e: usize, x: usize) -> u32 {
    (p.num_face_vertices() + 2 * e + x) as u32
}

/// Which end of parent edge `e` is vertex `v`.
#[inline]
fn end_of(p: &Topology, e: usize, v: u32) -> usize {
    usize::from(p.edge_vertices(e)[0] != v)
}

/// Parent edge `e`'s faces `(f, k, g, j)` with the edge's position in each.
#[inline]
fn sides(p: &Topology, e: usize) -> (usize, usize, usize, usize) {
    let (f, l) = (p.edge_faces(e), p.edge_face_local_indices(e));
    (f[0] as usize, l[0] as usize, f[1] as usize, l[1] as usize)
}

/// Face offsets and vertices: F-faces, E-faces, V-faces (those of the rule's faces).
pub(crate) fn face_lists(p: &Topology) -> (Vec<u32>, Vec<u32>) {
    let (offsets, verts, _) = faces(p);
    (offsets, verts)
}

/// Face offsets, vertices and edges: F-faces, E-faces, V-faces.
fn faces(p: &Topology) -> (Vec<u32>, Vec<u32>, Vec<u32>) {
    let (nv, nf, ne, nh) = (
        p.num_vertices(),
        p.num_faces(),
        p.num_edges(),
        p.num_face_vertices(),
    );
    let (off, pvfo) = (p.face_offsets(), p.vertex_face_offsets());
    let total = 2 * nh + 4 * ne;
    let mut offsets: Vec<u32> = memory::zeroed(nf + ne + nv + 1);
    offsets[..nf].copy_from_slice(&off[..nf]);
    offsets[nf..nf + ne]
        .par_iter_mut()
        .enumerate()
        .for_each(|(e, o)| *o = (nh + 4 * e) as u32);
    offsets[nf + ne..]
        .par_iter_mut()
        .enumerate()
        .for_each(|(v, o)| *o = (nh + 4 * ne) as u32 + pvfo[v]);
    let mut verts: Vec<u32> = memory::zeroed(total);
    let mut edges: Vec<u32> = memory::zeroed(total);
    let (fv, rest) = verts.split_at_mut(nh);
    let (ev, vv) = rest.split_at_mut(4 * ne);
    let (fe, rest) = edges.split_at_mut(nh);
    let (ee, ve) = rest.split_at_mut(4 * ne);
    fv.par_iter_mut()
        .enumerate()
        .for_each(|(h, o)| *o = h as u32);
    fe.par_iter_mut()
        .enumerate()
        .for_each(|(h, o)| *o = h as u32);
    e_faces(p, ev, ee);
    v_faces(p, vv, ve);
    (offsets, verts, edges)
}

/// E-face `(b0, a0, ga, gb)` of each parent edge, with edges F-edge `(f, k)`, `S(e, 0)`,
/// F-edge `(g, j)`, `S(e, 1)`.
fn e_faces(p: &Topology, verts: &mut [u32], edges: &mut [u32]) {
    let ne = p.num_edges();
    par::fill_pair(
        verts,
        edges,
        ne,
        |e| 4 * e,
        |r, verts, edges| {
            for (i, e) in r.enumerate() {
                let (f, k, g, j) = sides(p, e);
                let (a0, b0) = (corner(p, f, k), corner(p, f, k + 1));
                let (gb, ga) = (corner(p, g, j), corner(p, g, j + 1));
                verts[4 * i..4 * i + 4].copy_from_slice(&[b0, a0, ga, gb]);
                edges[4 * i..4 * i + 4].copy_from_slice(&[a0, spoke(p, e, 0), gb, spoke(p, e, 1)]);
            }
        },
    );
}

/// V-face of each parent vertex: its corners in ring order; edge `i` joins faces `i` and
/// `i + 1` of the ring, across the parent edge that leaves the vertex in face `i + 1`.
fn v_faces(p: &Topology, verts: &mut [u32], edges: &mut [u32]) {
    let (nv, pvfo) = (p.num_vertices(), p.vertex_face_offsets());
    par::fill_pair(
        verts,
        edges,
        nv,
        |v| pvfo[v] as usize,
        |r, verts, edges| {
            let mut o = 0;
            for v in r {
                let (vf, vl, ve) = (
                    p.vertex_faces(v),
                    p.vertex_face_local_indices(v),
                    p.vertex_edges(v),
                );
                let m = vf.len();
                for i in 0..m {
                    verts[o + i] = corner(p, vf[i] as usize, vl[i] as usize);
                    let e = ve[(i + 1) % m] as usize;
                    edges[o + i] = spoke(p, e, end_of(p, e, v as u32));
                }
                o += m;
            }
        },
    );
}

/// F-edges, then spokes.
fn edge_vertices(p: &Topology) -> Vec<[u32; 2]> {
    let (nf, ne, nh) = (p.num_faces(), p.num_edges(), p.num_face_vertices());
    let off = p.face_offsets();
    let mut out: Vec<[u32; 2]> = memory::zeroed(nh + 2 * ne);
    let (fe, spokes) = out.split_at_mut(nh);
    par::fill(
        fe,
        nf,
        |f| off[f] as usize,
        |r, out| {
            let base = off[r.start] as usize;
            for f in r {
                for k in 0..p.face_size(f) {
                    out[off[f] as usize + k - base] = [corner(p, f, k), corner(p, f, k + 1)];
                }
            }
        },
    );
    spokes.par_chunks_mut(2).enumerate().for_each(|(e, o)| {
        let (f, k, g, j) = sides(p, e);
        o[0] = [corner(p, f, k), corner(p, g, j + 1)];
        o[1] = [corner(p, f, k + 1), corner(p, g, j)];
    });
    out
}

/// Two faces per child edge: an F-edge borders its F-face and the E-face of its parent edge
/// (position 0 from the first face, 2 from the second); the spoke `S(e, x)` the E-face of `e`
/// (position 1 or 3) and the V-face of end `x`.
fn edge_faces(p: &Topology) -> (Vec<u32>, Vec<u16>) {
    let (nf, ne, nh) = (p.num_faces(), p.num_edges(), p.num_face_vertices());
    let off = p.face_offsets();
    let mut faces: Vec<u32> = memory::zeroed(2 * (nh + 2 * ne));
    let mut local: Vec<u16> = memory::zeroed(2 * (nh + 2 * ne));
    let (ff, fs) = faces.split_at_mut(2 * nh);
    let (lf, ls) = local.split_at_mut(2 * nh);
    par::fill_pair(
        ff,
        lf,
        nf,
        |f| 2 * off[f] as usize,
        |r, faces, local| {
            let mut o = 0;
            for f in r {
                for (k, &e) in p.face_edges(f).iter().enumerate() {
                    let first = p.edge_faces(e as usize)[0] as usize == f;
                    faces[o..o + 2].copy_from_slice(&[f as u32, (nf + e as usize) as u32]);
                    local[o..o + 2].copy_from_slice(&[k as u16, if first { 0 } else { 2 }]);
                    o += 2;
                }
            }
        },
    );
    fs.par_chunks_mut(4)
        .zip(ls.par_chunks_mut(4))
        .enumerate()
        .for_each(|(e, (faces, local))| {
            for x in 0..2 {
                let v = p.edge_vertices(e)[x];
                let ve = p.vertex_edges(v as usize);
                let m = ve.len();
                let at = ve.iter().position(|&y| y as usize == e).unwrap_or(0);
                let v_face = (nf + ne + v as usize) as u32;
                faces[2 * x..2 * x + 2].copy_from_slice(&[(nf + e) as u32, v_face]);
                local[2 * x..2 * x + 2]
                    .copy_from_slice(&[1 + 2 * x as u16, ((at + m - 1) % m) as u16]);
            }
        });
    (faces, local)
}

/// The ring of each child vertex (corner `k` of face `f` at vertex `v`, `e` the parent edge
/// leaving it, `e'` the one entering it): F-face `f`, E-face of `e'`, V-face of `v`, E-face
/// of `e`, with leaving edges F-edge `h`, F-edge of corner `k − 1`, `S(e', v)`, `S(e, v)`.
fn rings(p: &Topology) -> (Vec<u32>, Vec<u16>, Vec<u32>) {
    let (nf, ne, nh) = (p.num_faces(), p.num_edges(), p.num_face_vertices());
    let off = p.face_offsets();
    let mut faces: Vec<u32> = memory::zeroed(4 * nh);
    let mut local: Vec<u16> = memory::zeroed(4 * nh);
    let mut edges: Vec<u32> = memory::zeroed(4 * nh);
    par::fill_pair(
        &mut faces,
        &mut local,
        nf,
        |f| 4 * off[f] as usize,
        |r, faces, local| {
            let mut o = 0;
            for f in r {
                let (fv, fe) = (p.face_vertices(f), p.face_edges(f));
                let n = fv.len();
                for k in 0..n {
                    let (e, ep) = (fe[k] as usize, fe[(k + n - 1) % n] as usize);
                    let v = fv[k] as usize;
                    let first = |x: usize| p.edge_faces(x)[0] as usize == f;
                    let ring = p
                        .vertex_faces(v)
                        .iter()
                        .zip(p.vertex_face_local_indices(v))
                        .position(|(&g, &c)| g as usize == f && c as usize == k)
                        .unwrap_or(0);
                    faces[o..o + 4].copy_from_slice(&[
                        f as u32,
                        (nf + ep) as u32,
                        (nf + ne + v) as u32,
                        (nf + e) as u32,
                    ]);
                    local[o..o + 4].copy_from_slice(&[
                        k as u16,
                        if first(ep) { 0 } else { 2 },
                        ring as u16,
                        if first(e) { 1 } else { 3 },
                    ]);
                    o += 4;
                }
            }
        },
    );
    par::fill(
        &mut edges,
        nf,
        |f| 4 * off[f] as usize,
        |r, edges| {
            let mut o = 0;
            for f in r {
                let (fv, fe) = (p.face_vertices(f), p.face_edges(f));
                let n = fv.len();
                for k in 0..n {
                    let (e, ep) = (fe[k] as usize, fe[(k + n - 1) % n] as usize);
                    let v = fv[k];
                    edges[o..o + 4].copy_from_slice(&[
                        corner(p, f, k),
                        corner(p, f, k + n - 1),
                        spoke(p, ep, end_of(p, ep, v)),
                        spoke(p, e, end_of(p, e, v)),
                    ]);
                    o += 4;
                }
            }
        },
    );
    (faces, local, edges)
}
