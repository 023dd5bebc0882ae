//! Topology splits: the child topology of one uniform refinement step, numbered exactly as
//! OpenSubdiv numbers it (`Vtr::QuadRefinement`, `Vtr::TriRefinement`).
//!
//! Child vertices: children of parent vertices first (so vertex `v` stays `v`), then of
//! faces (quad split only), then of edges. Child faces are consecutive per parent face.
//! Child edges: the edges interior to each parent face (face order), then the two halves of
//! each parent edge (edge order), each half listed as (edge point, end vertex).

use subd_mesh::Topology;

/// Which half of parent edge `e` touches the child of the parent vertex at face corner
/// `corner` of a face whose vertices are `fv`: `start` says whether the half is the one that
/// leaves the corner (edge `corner` of the face) or the one that arrives at it (edge
/// `corner - 1`). For a degenerate edge both ends are the same vertex; the leaving side then
/// takes half 0 and the arriving side half 1.
#[inline]
fn half_at(parent: &Topology, e: u32, v: u32, leaving: bool) -> u32 {
    let [a, b] = parent.edge_vertices(e as usize);
    let half = if a == b {
        u32::from(!leaving)
    } else {
        u32::from(a != v)
    };
    2 * e + half
}

/// Child edges that inherit a parent edge's non-manifold flag: both halves of it.
fn inherited_non_manifold(parent: &Topology, half_base: u32) -> Vec<u32> {
    (0..parent.num_edges() as u32)
        .filter(|&e| parent.is_non_manifold_edge(e as usize))
        .flat_map(|e| [half_base + 2 * e, half_base + 2 * e + 1])
        .collect()
}

/// The quad split of Catmull-Clark and Bilinear: every face of size n becomes n quads.
pub(crate) fn quad_split(parent: &Topology) -> Topology {
    let nv = parent.num_vertices() as u32;
    let nf = parent.num_faces();
    let nh = parent.num_face_vertices();
    let face_point = |f: usize| nv + f as u32;
    let edge_point = |e: u32| nv + nf as u32 + e;
    let half_base = nh as u32;

    let n_child_faces = nh;
    let mut face_offsets = Vec::with_capacity(n_child_faces + 1);
    let mut face_vertices = Vec::with_capacity(4 * n_child_faces);
    let mut face_edges = Vec::with_capacity(4 * n_child_faces);
    for f in 0..nf {
        let fv = parent.face_vertices(f);
        let fe = parent.face_edges(f);
        let n = fv.len();
        let interior = parent.face_offsets()[f];
        for k in 0..n {
            let km1 = if k == 0 { n - 1 } else { k - 1 };
            // The n-gon child: (V_k, E_k, F, E_{k-1}) with its four edges.
            let verts = [fv[k], edge_point(fe[k]), face_point(f), edge_point(fe[km1])];
            let edges = [
                half_base + half_at(parent, fe[k], fv[k], true),
                interior + k as u32,
                interior + km1 as u32,
                half_base + half_at(parent, fe[km1], fv[k], false),
            ];
            // A quad's child k keeps the parent corner at position k.
            let rot = if n == 4 { k } else { 0 };
            face_offsets.push(face_vertices.len() as u32);
            for j in 0..4 {
                let src = (j + 4 - rot) % 4;
                face_vertices.push(verts[src]);
                face_edges.push(edges[src]);
            }
        }
    }
    face_offsets.push(face_vertices.len() as u32);

    let ne = parent.num_edges();
    let mut edge_vertices = Vec::with_capacity(nh + 2 * ne);
    for f in 0..nf {
        for &e in parent.face_edges(f) {
            edge_vertices.push([face_point(f), edge_point(e)]);
        }
    }
    for e in 0..ne as u32 {
        let [a, b] = parent.edge_vertices(e as usize);
        edge_vertices.push([edge_point(e), a]);
        edge_vertices.push([edge_point(e), b]);
    }
    let nm = inherited_non_manifold(parent, half_base);
    let num_vertices = nv as usize + nf + ne;
    Topology::from_numbered_edges(
        num_vertices,
        face_offsets,
        face_vertices,
        face_edges,
        edge_vertices,
        &nm,
    )
    .expect("a quad split of a valid topology is valid")
}

/// The triangle split of Loop: every triangle becomes four. The caller checks that every face
/// is a triangle.
pub(crate) fn tri_split(parent: &Topology) -> Topology {
    let nv = parent.num_vertices() as u32;
    let nf = parent.num_faces();
    let ne = parent.num_edges();
    let edge_point = |e: u32| nv + e;
    let half_base = 3 * nf as u32;
    let mut face_vertices = Vec::with_capacity(12 * nf);
    let mut face_edges = Vec::with_capacity(12 * nf);
    for f in 0..nf {
        let v = parent.face_vertices(f);
        let e = parent.face_edges(f);
        let (e0, e1, e2) = (edge_point(e[0]), edge_point(e[1]), edge_point(e[2]));
        let i = 3 * f as u32;
        let h = |k: usize, corner: usize, leaving: bool| {
            half_base + half_at(parent, e[k], v[corner], leaving)
        };
        face_vertices.extend_from_slice(&[v[0], e0, e2, e0, v[1], e1, e2, e1, v[2], e1, e2, e0]);
        face_edges.extend_from_slice(&[
            h(0, 0, true),
            i,
            h(2, 0, false),
            h(0, 1, false),
            h(1, 1, true),
            i + 1,
            i + 2,
            h(1, 2, false),
            h(2, 2, true),
            i + 2,
            i,
            i + 1,
        ]);
    }
    let face_offsets = (0..=4 * nf as u32).map(|k| 3 * k).collect();
    let mut edge_vertices = Vec::with_capacity(3 * nf + 2 * ne);
    for f in 0..nf {
        let e = parent.face_edges(f);
        let (e0, e1, e2) = (edge_point(e[0]), edge_point(e[1]), edge_point(e[2]));
        edge_vertices.extend_from_slice(&[[e0, e2], [e1, e0], [e2, e1]]);
    }
    for e in 0..ne as u32 {
        let [a, b] = parent.edge_vertices(e as usize);
        edge_vertices.push([edge_point(e), a]);
        edge_vertices.push([edge_point(e), b]);
    }
    let nm = inherited_non_manifold(parent, half_base);
    Topology::from_numbered_edges(
        nv as usize + ne,
        face_offsets,
        face_vertices,
        face_edges,
        edge_vertices,
        &nm,
    )
    .expect("a triangle split of a valid topology is valid")
}
