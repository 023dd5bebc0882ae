//! The child relations of a √3 step over a closed parent without feature edges, in closed
//! form from the parent's (no search), filled in parallel: there every face gets its
//! centroid and every edge is flipped, so each relation is a fixed pattern per parent
//! element. [`sqrt3::Step`](super::sqrt3::Step) uses it there and builds other levels
//! (boundaries, creases, trisection) from their faces.
//!
//! Child vertices: the parent's `v`, then the centroid `C_f = nv + f`. Child faces: for
//! parent edge `e = (a, b)` (in its first face `f0`'s direction, `f1` its second face)
//! `2e = (a, C_f1, C_f0)` and `2e + 1 = (C_f1, b, C_f0)`. Child edges (numbered here, put in
//! the builder's order by [`subd_mesh::canonical::builder_order`]): the flip `F_e =
//! (C_f0, C_f1)` is `e`; the corner edge `K(f, k) = (fv_k, C_f)` of parent corner `k` of `f`
//! is `ne + 3f + k`.

// The relations are indexed by parent face, edge and corner together.
#![allow(clippy::needless_range_loop)]

use rayon::prelude::*;
use subd_mesh::{Topology, TopologyParts, memory};

use crate::refine::par;

/// Whether the closed form applies: a closed triangle mesh with no feature edge (every edge
/// has two faces and is not an infinitely sharp crease), manifold (which the scheme's input
/// checks and the split keeps).
pub(crate) fn applies(p: &Topology, features: &super::Features) -> bool {
    (0..p.num_edges())
        .into_par_iter()
        .with_min_len(4096)
        .all(|e| p.edge_faces(e).len() == 2 && !features.is_feature_edge(e))
        && p.num_face_vertices() == 3 * p.num_faces()
}

/// The parent edge `e`'s faces `(f0, l0, f1, l1)`: faces with the edge's position in each.
#[inline]
fn sides(p: &Topology, e: usize) -> (usize, usize, usize, usize) {
    let (f, l) = (p.edge_faces(e), p.edge_face_local_indices(e));
    (f[0] as usize, l[0] as usize, f[1] as usize, l[1] as usize)
}

/// The child relations (the caller adds the tags).
pub(crate) fn split(p: &Topology) -> TopologyParts {
    let (nv, nf, ne) = (p.num_vertices(), p.num_faces(), p.num_edges());
    let (vertex_face_offsets, vertex_faces, vertex_face_local) = vertex_faces(p);
    let (vertex_edge_offsets, vertex_edges) = vertex_edges(p);
    let (edge_faces, edge_face_local) = edge_faces(p);
    TopologyParts {
        num_vertices: nv + nf,
        face_offsets: crate::refine::split::uniform_offsets(2 * ne, 3),
        face_vertices: face_vertices(p),
        face_edges: face_edges(p),
        edge_vertices: edge_vertices(p),
        edge_face_offsets: crate::refine::split::uniform_offsets(ne + 3 * nf, 2),
        edge_faces,
        edge_face_local,
        vertex_face_offsets,
        vertex_faces,
        vertex_face_local,
        vertex_edge_offsets,
        vertex_edges,
        edge_boundary: memory::zeroed(ne + 3 * nf),
        edge_non_manifold: memory::zeroed(ne + 3 * nf),
        vertex_non_manifold: memory::zeroed(nv + nf),
        ..TopologyParts::default()
    }
}

/// A flat array of `per` values per parent edge, written in parallel.
fn per_edge<T: Send + Sync + Clone + bytemuck::Zeroable, const N: usize>(
    p: &Topology,
    block: impl Fn(usize) -> [T; N] + Sync,
) -> Vec<T> {
    par::build(
        N * p.num_edges(),
        p.num_edges(),
        |e| N * e,
        |r, out| {
            for (i, e) in r.enumerate() {
                out[N * i..N * i + N].clone_from_slice(&block(e));
            }
        },
    )
}

/// `(a, C_f1, C_f0)`, `(C_f1, b, C_f0)` per parent edge, as the rule's faces.
pub(crate) fn face_vertices(p: &Topology) -> Vec<u32> {
    let nv = p.num_vertices() as u32;
    per_edge(p, |e| {
        let (f0, l0, f1, _) = sides(p, e);
        let fv = p.face_vertices(f0);
        let (a, b) = (fv[l0], fv[(l0 + 1) % 3]);
        let (c0, c1) = (nv + f0 as u32, nv + f1 as u32);
        [a, c1, c0, c1, b, c0]
    })
}

/// Corner edge `K(f, k)`.
#[inline]
fn corner_edge(ne: usize, f: usize, k: usize) -> u32 {
    (ne + 3 * f + k) as u32
}

/// Face 2e: `a→C_f1` is `K(f1, l1 + 1)`, the flip, `C_f0→a` is `K(f0, l0)`; face 2e + 1:
/// `C_f1→b` is `K(f1, l1)`, `b→C_f0` is `K(f0, l0 + 1)`, the flip (in `f1` the edge runs
/// from `b` at `l1` to `a`).
fn face_edges(p: &Topology) -> Vec<u32> {
    let ne = p.num_edges();
    per_edge(p, |e| {
        let (f0, l0, f1, l1) = sides(p, e);
        let k = |f, c: usize| corner_edge(ne, f, c % 3);
        [
            k(f1, l1 + 1),
            e as u32,
            k(f0, l0),
            k(f1, l1),
            k(f0, l0 + 1),
            e as u32,
        ]
    })
}

/// The flips, then the corner edges.
fn edge_vertices(p: &Topology) -> Vec<[u32; 2]> {
    let (nv, nf, ne) = (p.num_vertices(), p.num_faces(), p.num_edges());
    let mut out: Vec<[u32; 2]> = memory::zeroed(ne + 3 * nf);
    let (flips, corners) = out.split_at_mut(ne);
    flips.par_iter_mut().enumerate().for_each(|(e, o)| {
        let (f0, _, f1, _) = sides(p, e);
        *o = [(nv + f0) as u32, (nv + f1) as u32];
    });
    corners.par_chunks_mut(3).enumerate().for_each(|(f, o)| {
        for (k, &v) in p.face_vertices(f).iter().enumerate() {
            o[k] = [v, (nv + f) as u32];
        }
    });
    out
}

/// Two faces per child edge: a flip borders both faces of its parent edge (at positions 1
/// and 2); a corner edge `K(f, k)` one child face of each parent edge of `f` at corner `k`.
fn edge_faces(p: &Topology) -> (Vec<u32>, Vec<u16>) {
    let (nf, ne) = (p.num_faces(), p.num_edges());
    let n = 2 * (ne + 3 * nf);
    let mut faces: Vec<u32> = memory::zeroed(n);
    let mut local: Vec<u16> = memory::zeroed(n);
    let (ff, fk) = faces.split_at_mut(2 * ne);
    let (lf, lk) = local.split_at_mut(2 * ne);
    ff.par_chunks_mut(2)
        .zip(lf.par_chunks_mut(2))
        .enumerate()
        .for_each(|(e, (f, l))| {
            f.copy_from_slice(&[2 * e as u32, 2 * e as u32 + 1]);
            l.copy_from_slice(&[1, 2]);
        });
    fk.par_chunks_mut(6)
        .zip(lk.par_chunks_mut(6))
        .enumerate()
        .for_each(|(f, (faces, local))| {
            for k in 0..3 {
                let [a, b] = corner_edge_faces(p, f, k);
                faces[2 * k..2 * k + 2].copy_from_slice(&[a.0, b.0]);
                local[2 * k..2 * k + 2].copy_from_slice(&[a.1, b.1]);
            }
        });
    (faces, local)
}

/// The two child faces (with the corner edge's position) of corner edge `K(f, k)`: from the
/// parent edge leaving corner `k` in `f` and from the one entering it.
fn corner_edge_faces(p: &Topology, f: usize, k: usize) -> [(u32, u16); 2] {
    let fe = p.face_edges(f);
    let leaving = fe[k] as usize;
    let entering = fe[(k + 2) % 3] as usize;
    // Leaving: in f0 it is `C_f0→a` of face 2e (position 2); in f1 `C_f1→b` of 2e + 1 (0).
    let from_leaving = if p.edge_faces(leaving)[0] as usize == f {
        (2 * leaving as u32, 2)
    } else {
        (2 * leaving as u32 + 1, 0)
    };
    // Entering: in f0 it is `b→C_f0` of face 2e + 1 (position 1); in f1 `a→C_f1` of 2e (0).
    let from_entering = if p.edge_faces(entering)[0] as usize == f {
        (2 * entering as u32 + 1, 1)
    } else {
        (2 * entering as u32, 0)
    };
    [from_leaving, from_entering]
}

/// Vertex-faces: a parent vertex keeps one child face per parent edge at it, in the parent's
/// ring order (`2e` where it is the edge's first end, at corner 0; else `2e + 1`, corner 1);
/// a centroid has six, the two children of each parent edge of its face in turn.
fn vertex_faces(p: &Topology) -> (Vec<u32>, Vec<u32>, Vec<u16>) {
    let (nv, nf) = (p.num_vertices(), p.num_faces());
    let pveo = p.vertex_edge_offsets();
    let nve = pveo[nv] as usize;
    let offsets = ring_offsets(pveo, nf);
    let mut faces: Vec<u32> = memory::zeroed(nve + 6 * nf);
    let mut local: Vec<u16> = memory::zeroed(nve + 6 * nf);
    let (fv, fc) = faces.split_at_mut(nve);
    let (lv, lc) = local.split_at_mut(nve);
    par::fill_pair(
        fv,
        lv,
        nv,
        |v| pveo[v] as usize,
        |r, faces, local| {
            let mut i = 0;
            for v in r {
                for &e in p.vertex_edges(v) {
                    let first = p.edge_vertices(e as usize)[0] as usize == v;
                    faces[i] = 2 * e + u32::from(!first);
                    local[i] = u16::from(!first);
                    i += 1;
                }
            }
        },
    );
    fc.par_chunks_mut(6)
        .zip(lc.par_chunks_mut(6))
        .enumerate()
        .for_each(|(f, (faces, local))| {
            for (k, &e) in p.face_edges(f).iter().enumerate() {
                let in_f0 = p.edge_faces(e as usize)[0] as usize == f;
                // A_k (with corner k's vertex) then B_k (with corner k + 1's).
                let (a, b) = if in_f0 {
                    (2 * e, 2 * e + 1)
                } else {
                    (2 * e + 1, 2 * e)
                };
                let (la, lb) = if in_f0 { (2, 2) } else { (0, 1) };
                faces[2 * k..2 * k + 2].copy_from_slice(&[a, b]);
                local[2 * k..2 * k + 2].copy_from_slice(&[la, lb]);
            }
        });
    (offsets, faces, local)
}

/// Vertex-edges, each leaving its vertex in the ring's face: at a parent vertex the corner
/// edge of the parent face before (the ring's previous face); at a centroid `K(f, 0)`,
/// `F_e0`, `K(f, 1)`, `F_e1`, `K(f, 2)`, `F_e2`.
fn vertex_edges(p: &Topology) -> (Vec<u32>, Vec<u32>) {
    let (nv, nf, ne) = (p.num_vertices(), p.num_faces(), p.num_edges());
    let pvfo = p.vertex_face_offsets();
    let nvf = pvfo[nv] as usize;
    let offsets = ring_offsets(pvfo, nf);
    let mut edges: Vec<u32> = memory::zeroed(nvf + 6 * nf);
    let (ev, ec) = edges.split_at_mut(nvf);
    par::fill(
        ev,
        nv,
        |v| pvfo[v] as usize,
        |r, out| {
            let mut i = 0;
            for v in r {
                let (faces, corners) = (p.vertex_faces(v), p.vertex_face_local_indices(v));
                let n = faces.len();
                for j in 0..n {
                    let prev = (j + n - 1) % n;
                    out[i] = corner_edge(ne, faces[prev] as usize, corners[prev] as usize);
                    i += 1;
                }
            }
        },
    );
    ec.par_chunks_mut(6).enumerate().for_each(|(f, out)| {
        for (k, &e) in p.face_edges(f).iter().enumerate() {
            out[2 * k..2 * k + 2].copy_from_slice(&[corner_edge(ne, f, k), e]);
        }
    });
    (offsets, edges)
}

/// Ring offsets: the parent vertices' (`parent`), then six per centroid.
fn ring_offsets(parent: &[u32], nf: usize) -> Vec<u32> {
    let nv = parent.len() - 1;
    let base = parent[nv];
    let mut out: Vec<u32> = memory::zeroed(nv + nf + 1);
    out[..nv].copy_from_slice(&parent[..nv]);
    out[nv..]
        .par_iter_mut()
        .enumerate()
        .for_each(|(f, o)| *o = base + 6 * f as u32);
    out
}
