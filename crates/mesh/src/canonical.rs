//! Putting relations derived in closed form into the order [`crate::TopologyBuilder`] gives
//! the same faces: edges numbered by first use, rings started where the builder starts them.
//!
//! A refinement that derives a child level from its parent (no search) numbers the child
//! edges in whatever order its derivation makes natural, e.g. OpenSubdiv's (face-interior
//! edges, then the halves of the parent edges). Schemes whose outputs were defined on the
//! builder's order (the split schemes number new vertices per edge) need that order back:
//! [`builder_order`] renumbers the edges and rotates the vertex rings, in parallel, with no
//! search.
//!
//! The builder numbers an edge by the first face-vertex ("corner") that starts it, walking
//! the faces in order; it orients the edge as that corner's face does; it lists an edge's
//! faces in face order; and it starts the ring of an interior vertex at its first face (a
//! boundary vertex's at the boundary edge leaving it, which a counter-clockwise ring derived
//! from a builder-ordered parent already does).

use rayon::prelude::*;

use crate::TopologyParts;
use crate::csr::exclusive_prefix_sum;
use crate::memory;

/// Rows or corners per parallel task.
const BLOCK: usize = 1 << 12;

/// `parts` with its edges renumbered and oriented by first use and every interior vertex's
/// ring started at its first face, as [`crate::TopologyBuilder`] builds the same faces.
///
/// The parts must describe a manifold mesh (every edge in at most two faces, once in each;
/// every vertex ring counter-clockwise) whose boundary rings already start at the boundary
/// edge leaving the vertex; relations and flags are permuted, not recomputed.
pub fn builder_order(mut parts: TopologyParts) -> TopologyParts {
    let first = first_corners(&parts);
    let rank = first_use_ranks(&parts.face_edges, &first);
    let new_of_old = gather(first.len(), |e| rank[first[e] as usize]);
    let old_of_new: Vec<u32> = parts
        .face_edges
        .par_iter()
        .enumerate()
        .with_min_len(BLOCK)
        .filter(|&(h, &e)| first[e as usize] as usize == h)
        .map(|(_, &e)| e)
        .collect();
    let face_edges = gather(parts.face_edges.len(), |h| {
        rank[first[parts.face_edges[h] as usize] as usize]
    });
    drop(rank);
    let edge_vertices = oriented_edges(&parts, &old_of_new, &first);
    let (edge_face_offsets, edge_faces, edge_face_local) = permuted_edge_faces(&parts, &old_of_new);
    parts.edge_boundary = gather(old_of_new.len(), |k| {
        parts.edge_boundary[old_of_new[k] as usize]
    });
    parts.edge_non_manifold = gather(old_of_new.len(), |k| {
        parts.edge_non_manifold[old_of_new[k] as usize]
    });
    if !parts.edge_sharpness.is_empty() {
        parts.edge_sharpness = gather(old_of_new.len(), |k| {
            parts.edge_sharpness[old_of_new[k] as usize]
        });
    }
    parts.face_edges = face_edges;
    parts.edge_vertices = edge_vertices;
    parts.edge_face_offsets = edge_face_offsets;
    parts.edge_faces = edge_faces;
    parts.edge_face_local = edge_face_local;
    parts
        .vertex_edges
        .par_iter_mut()
        .with_min_len(BLOCK)
        .for_each(|e| *e = new_of_old[*e as usize]);
    start_rings_at_first_face(&mut parts);
    parts
}

/// `n` values computed in parallel.
fn gather<T: Send>(n: usize, value: impl Fn(usize) -> T + Sync + Send) -> Vec<T> {
    let mut out = memory::with_capacity(n);
    out.par_extend((0..n).into_par_iter().with_min_len(BLOCK).map(value));
    out
}

/// The first corner (face-vertex) of every edge: the least of its faces' corners at it.
fn first_corners(p: &TopologyParts) -> Vec<u32> {
    let ne = p.edge_vertices.len();
    gather(ne, |e| {
        let r = p.edge_face_offsets[e] as usize..p.edge_face_offsets[e + 1] as usize;
        p.edge_faces[r.clone()]
            .iter()
            .zip(&p.edge_face_local[r])
            .map(|(&f, &l)| p.face_offsets[f as usize] + l as u32)
            .min()
            .unwrap_or(u32::MAX)
    })
}

/// Per corner, how many corners before it start an edge (an exclusive prefix sum over blocks
/// of corners): at a corner that starts edge `e`, the new number of `e`.
fn first_use_ranks(face_edges: &[u32], first: &[u32]) -> Vec<u32> {
    let starts = |h: usize| first[face_edges[h] as usize] as usize == h;
    let counts: Vec<u32> = face_edges
        .par_chunks(BLOCK)
        .enumerate()
        .map(|(b, c)| (0..c.len()).filter(|&i| starts(b * BLOCK + i)).count() as u32)
        .collect();
    let block_start = exclusive_prefix_sum(&counts);
    let mut rank: Vec<u32> = memory::zeroed(face_edges.len());
    rank.par_chunks_mut(BLOCK).enumerate().for_each(|(b, out)| {
        let mut next = block_start[b];
        for (i, r) in out.iter_mut().enumerate() {
            *r = next;
            next += u32::from(starts(b * BLOCK + i));
        }
    });
    rank
}

/// Every new edge's vertices, in the direction of its first corner's face.
fn oriented_edges(p: &TopologyParts, old_of_new: &[u32], first: &[u32]) -> Vec<[u32; 2]> {
    gather(old_of_new.len(), |k| {
        let old = old_of_new[k] as usize;
        let [a, b] = p.edge_vertices[old];
        if p.face_vertices[first[old] as usize] == a {
            [a, b]
        } else {
            [b, a]
        }
    })
}

/// The edge-face relation in the new edge order, each edge's faces in face order.
fn permuted_edge_faces(p: &TopologyParts, old_of_new: &[u32]) -> (Vec<u32>, Vec<u32>, Vec<u16>) {
    let count =
        |old: u32| p.edge_face_offsets[old as usize + 1] - p.edge_face_offsets[old as usize];
    let counts: Vec<u32> = gather(old_of_new.len(), |k| count(old_of_new[k]));
    let mut offsets = prefix_offsets(&counts);
    drop(counts);
    let total = *offsets.last().unwrap_or(&0) as usize;
    let mut faces: Vec<u32> = memory::zeroed(total);
    let mut local: Vec<u16> = memory::zeroed(total);
    let pieces = row_blocks(&offsets, &mut faces)
        .into_iter()
        .zip(row_blocks(&offsets, &mut local));
    pieces
        .collect::<Vec<_>>()
        .into_par_iter()
        .for_each(|((rows, faces), (_, local))| {
            let base = offsets[rows.start] as usize;
            for k in rows {
                let old = old_of_new[k] as usize;
                let r = p.edge_face_offsets[old] as usize..p.edge_face_offsets[old + 1] as usize;
                let o = offsets[k] as usize - base;
                let n = r.len();
                faces[o..o + n].copy_from_slice(&p.edge_faces[r.clone()]);
                local[o..o + n].copy_from_slice(&p.edge_face_local[r]);
                // A manifold edge has at most two faces: face order is one swap away.
                if n == 2 && faces[o] > faces[o + 1] {
                    faces.swap(o, o + 1);
                    local.swap(o, o + 1);
                }
            }
        });
    offsets.shrink_to_fit();
    (offsets, faces, local)
}

/// Row offsets from row sizes: a prefix sum over blocks, the blocks in parallel.
fn prefix_offsets(counts: &[u32]) -> Vec<u32> {
    let sums: Vec<u32> = counts.par_chunks(BLOCK).map(|c| c.iter().sum()).collect();
    let block_start = exclusive_prefix_sum(&sums);
    let mut offsets: Vec<u32> = memory::zeroed(counts.len() + 1);
    offsets[1..]
        .par_chunks_mut(BLOCK)
        .zip(counts.par_chunks(BLOCK))
        .zip(&block_start)
        .for_each(|((out, c), &start)| {
            let mut end = start;
            for (o, &n) in out.iter_mut().zip(c) {
                end += n;
                *o = end;
            }
        });
    offsets
}

/// `values` cut into the runs of blocks of rows (`offsets` as a CSR's): one piece per
/// parallel task, with its rows.
fn row_blocks<'a, T>(
    offsets: &[u32],
    mut values: &'a mut [T],
) -> Vec<(std::ops::Range<usize>, &'a mut [T])> {
    let n = offsets.len() - 1;
    (0..n.div_ceil(BLOCK))
        .map(|b| {
            let rows = b * BLOCK..((b + 1) * BLOCK).min(n);
            let len = (offsets[rows.end] - offsets[rows.start]) as usize;
            let (head, tail) = std::mem::take(&mut values).split_at_mut(len);
            values = tail;
            (rows, head)
        })
        .collect()
}

/// Rotates the faces (with their corners) and edges around every interior manifold vertex
/// so that its ring starts at its first face, where the builder's walk starts.
fn start_rings_at_first_face(p: &mut TopologyParts) {
    let (fo, eo) = (&p.vertex_face_offsets, &p.vertex_edge_offsets);
    let non_manifold = &p.vertex_non_manifold;
    let faces = row_blocks(fo, &mut p.vertex_faces);
    let local = row_blocks(fo, &mut p.vertex_face_local);
    let edges = row_blocks(eo, &mut p.vertex_edges);
    let pieces: Vec<_> = faces.into_iter().zip(local).zip(edges).collect();
    pieces
        .into_par_iter()
        .for_each(|(((rows, faces), (_, local)), (_, edges))| {
            let (fb, eb) = (fo[rows.start] as usize, eo[rows.start] as usize);
            for v in rows {
                let fr = fo[v] as usize - fb..fo[v + 1] as usize - fb;
                let er = eo[v] as usize - eb..eo[v + 1] as usize - eb;
                if non_manifold[v] || fr.is_empty() || fr.len() != er.len() {
                    continue;
                }
                let ring = &faces[fr.clone()];
                let start = (0..ring.len()).min_by_key(|&i| ring[i]).unwrap_or(0);
                faces[fr.clone()].rotate_left(start);
                local[fr].rotate_left(start);
                edges[er].rotate_left(start);
            }
        });
}
