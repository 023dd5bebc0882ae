//! A set of faces of a topology as a mesh of its own ([`cut`]), every relation kept in the
//! source's order (adaptive refinement refines such pieces).
//!
//! Rebuilding a piece from its face lists would number its edges and start its vertex rings
//! wherever the builder starts them. Masks sum their terms in ring order (and Chaikin's
//! sharpness average sums `f32` values in that order), so a vertex whose ring is complete in
//! the piece is given exactly the ring — same faces, same edges, same order — it has in the
//! level: the refinement of the piece then computes its children with the same operations,
//! bit for bit, as the refinement of the whole level.

use crate::{Topology, TopologyParts};

/// Marks an index that has no counterpart.
pub const NONE: u32 = u32::MAX;

/// Faces of a source topology cut out, with the map back to the source.
#[derive(Debug)]
pub struct SubMesh {
    /// The cut's topology, with the source's tags.
    pub topology: Topology,
    /// Source vertex of each cut vertex.
    pub vertices: Vec<u32>,
    /// Source edge of each cut edge.
    pub edges: Vec<u32>,
    /// Whether each cut vertex has every source face around it.
    pub complete: Vec<bool>,
}

impl SubMesh {
    /// The cut vertex of each of the source's `source_vertices` vertices ([`NONE`] for one
    /// outside the cut): the inverse of [`Self::vertices`].
    pub fn vertex_of_source(&self, source_vertices: usize) -> Vec<u32> {
        let mut of_source = vec![NONE; source_vertices];
        for (i, &v) in self.vertices.iter().enumerate() {
            of_source[v as usize] = i as u32;
        }
        of_source
    }
}

/// Cuts `faces` (indices into `src`, each once) out of `src`. Vertices and edges are numbered
/// by first appearance in `faces`; face-edges, edge-faces, vertex-faces and vertex-edges are
/// the source's, filtered to the cut, in the source's order. A manifold vertex that lost
/// faces keeps them as the boundary fan they form when they are one run of its ring, and is
/// flagged non-manifold otherwise (as a mesh built from the cut's face lists would have it);
/// nothing the caller keeps reads such a vertex's ring.
pub fn cut(src: &Topology, faces: &[u32]) -> SubMesh {
    let numbering = Numbering::of(src, faces);
    // The three read the numbering only: built side by side.
    let (edges, (vertices, (edge_sharpness, vertex_sharpness, face_holes))) = rayon::join(
        || edge_relations(src, &numbering),
        || {
            rayon::join(
                || vertex_relations(src, &numbering),
                || cut_tags(src, faces, &numbering),
            )
        },
    );
    let Numbering {
        vertices: cut_vertices,
        edges: cut_edges,
        face_offsets,
        face_vertices,
        face_edges,
        ..
    } = numbering;
    let topology = Topology::from_parts(TopologyParts {
        num_vertices: cut_vertices.len(),
        face_offsets,
        face_vertices,
        face_edges,
        edge_vertices: edges.vertices,
        edge_face_offsets: edges.face_offsets,
        edge_faces: edges.faces,
        edge_face_local: edges.face_local,
        vertex_face_offsets: vertices.face_offsets,
        vertex_faces: vertices.faces,
        vertex_face_local: vertices.face_local,
        vertex_edge_offsets: vertices.edge_offsets,
        vertex_edges: vertices.edges,
        edge_boundary: edges.boundary,
        edge_non_manifold: edges.non_manifold,
        vertex_non_manifold: vertices.non_manifold,
        edge_sharpness,
        vertex_sharpness,
        face_holes,
    })
    .expect("a cut of a valid topology has consistent parts");
    SubMesh {
        topology,
        vertices: cut_vertices,
        edges: cut_edges,
        complete: vertices.complete,
    }
}

/// The cut's numbering: source vertices and edges by first appearance in the cut faces, the
/// maps from source to cut (`NONE` outside), and the cut faces' vertices and edges.
struct Numbering {
    vertex_map: Vec<u32>,
    edge_map: Vec<u32>,
    face_map: Vec<u32>,
    vertices: Vec<u32>,
    edges: Vec<u32>,
    face_offsets: Vec<u32>,
    face_vertices: Vec<u32>,
    face_edges: Vec<u32>,
}

impl Numbering {
    fn of(src: &Topology, faces: &[u32]) -> Numbering {
        // Sized up front: growing these by doubling copied them over and over.
        let corners: usize = faces.iter().map(|&f| src.face_size(f as usize)).sum();
        let mut n = Numbering {
            vertex_map: vec![NONE; src.num_vertices()],
            edge_map: vec![NONE; src.num_edges()],
            face_map: vec![NONE; src.num_faces()],
            vertices: Vec::with_capacity(corners.min(src.num_vertices())),
            edges: Vec::with_capacity(corners.min(src.num_edges())),
            face_offsets: Vec::with_capacity(faces.len() + 1),
            face_vertices: Vec::with_capacity(corners),
            face_edges: Vec::with_capacity(corners),
        };
        n.face_offsets.push(0u32);
        for (i, &f) in faces.iter().enumerate() {
            n.face_map[f as usize] = i as u32;
            for (&v, &e) in src
                .face_vertices(f as usize)
                .iter()
                .zip(src.face_edges(f as usize))
            {
                if n.vertex_map[v as usize] == NONE {
                    n.vertex_map[v as usize] = n.vertices.len() as u32;
                    n.vertices.push(v);
                }
                if n.edge_map[e as usize] == NONE {
                    n.edge_map[e as usize] = n.edges.len() as u32;
                    n.edges.push(e);
                }
                n.face_vertices.push(n.vertex_map[v as usize]);
                n.face_edges.push(n.edge_map[e as usize]);
            }
            n.face_offsets.push(n.face_vertices.len() as u32);
        }
        n
    }
}

/// The cut's edge relations: ends, faces (the source's, filtered, in its order) and flags.
struct EdgeRelations {
    vertices: Vec<[u32; 2]>,
    face_offsets: Vec<u32>,
    faces: Vec<u32>,
    face_local: Vec<u16>,
    boundary: Vec<bool>,
    non_manifold: Vec<bool>,
}

fn edge_relations(src: &Topology, n: &Numbering) -> EdgeRelations {
    let ne = n.edges.len();
    let mut r = EdgeRelations {
        vertices: n
            .edges
            .iter()
            .map(|&e| {
                src.edge_vertices(e as usize)
                    .map(|v| n.vertex_map[v as usize])
            })
            .collect(),
        face_offsets: Vec::with_capacity(ne + 1),
        faces: Vec::with_capacity(n.face_vertices.len()),
        face_local: Vec::with_capacity(n.face_vertices.len()),
        boundary: Vec::with_capacity(ne),
        non_manifold: Vec::with_capacity(ne),
    };
    r.face_offsets.push(0u32);
    for &e in &n.edges {
        let start = r.faces.len();
        for (&g, &l) in src
            .edge_faces(e as usize)
            .iter()
            .zip(src.edge_face_local_indices(e as usize))
        {
            if n.face_map[g as usize] != NONE {
                r.faces.push(n.face_map[g as usize]);
                r.face_local.push(l);
            }
        }
        r.face_offsets.push(r.faces.len() as u32);
        r.boundary.push(r.faces.len() - start == 1);
        r.non_manifold.push(src.is_non_manifold_edge(e as usize));
    }
    r
}

/// The cut's vertex relations: faces and edges (the source's ring where whole; a boundary fan
/// where one run of it is kept; filtered and non-manifold otherwise), and which vertices
/// kept every face.
struct VertexRelations {
    face_offsets: Vec<u32>,
    faces: Vec<u32>,
    face_local: Vec<u16>,
    edge_offsets: Vec<u32>,
    edges: Vec<u32>,
    non_manifold: Vec<bool>,
    complete: Vec<bool>,
}

fn vertex_relations(src: &Topology, n: &Numbering) -> VertexRelations {
    let nv = n.vertices.len();
    let mut r = VertexRelations {
        face_offsets: Vec::with_capacity(nv + 1),
        faces: Vec::with_capacity(n.face_vertices.len()),
        face_local: Vec::with_capacity(n.face_vertices.len()),
        edge_offsets: Vec::with_capacity(nv + 1),
        // About one edge more than faces a vertex (a hint: a non-manifold one may have more).
        edges: Vec::with_capacity(n.face_vertices.len() + nv),
        non_manifold: Vec::with_capacity(nv),
        complete: Vec::with_capacity(nv),
    };
    r.face_offsets.push(0u32);
    r.edge_offsets.push(0u32);
    let mut kept: Vec<usize> = Vec::new();
    for &v in &n.vertices {
        let v = v as usize;
        let (vf, vl, ve) = (
            src.vertex_faces(v),
            src.vertex_face_local_indices(v),
            src.vertex_edges(v),
        );
        kept.clear();
        kept.extend((0..vf.len()).filter(|&i| n.face_map[vf[i] as usize] != NONE));
        let whole = kept.len() == vf.len();
        let arc = if whole || src.is_non_manifold_vertex(v) {
            None
        } else {
            single_arc(&kept, vf.len(), ve.len() == vf.len())
        };
        match arc {
            Some(first) => {
                // One contiguous run of the ring: a boundary fan of the cut, starting at the
                // run's first face (whose leaving edge is now a boundary edge).
                let (nf, ne) = (vf.len(), ve.len());
                for j in 0..kept.len() {
                    let i = (first + j) % nf;
                    r.faces.push(n.face_map[vf[i] as usize]);
                    r.face_local.push(vl[i]);
                }
                for j in 0..=kept.len() {
                    r.edges.push(n.edge_map[ve[(first + j) % ne] as usize]);
                }
                r.non_manifold.push(false);
            }
            None => {
                for &i in &kept {
                    r.faces.push(n.face_map[vf[i] as usize]);
                    r.face_local.push(vl[i]);
                }
                for &e in ve {
                    if n.edge_map[e as usize] != NONE {
                        r.edges.push(n.edge_map[e as usize]);
                    }
                }
                r.non_manifold.push(src.is_non_manifold_vertex(v) || !whole);
            }
        }
        r.face_offsets.push(r.faces.len() as u32);
        r.edge_offsets.push(r.edges.len() as u32);
        r.complete.push(whole);
    }
    r
}

/// The source's tags on the cut's edges, vertices and faces (empty where the source has
/// none).
fn cut_tags(src: &Topology, faces: &[u32], n: &Numbering) -> (Vec<f32>, Vec<f32>, Vec<bool>) {
    let tags = src.tags();
    let edge_sharpness = if tags.edge_sharpness().is_empty() {
        Vec::new()
    } else {
        n.edges
            .iter()
            .map(|&e| src.edge_sharpness(e as usize))
            .collect()
    };
    let vertex_sharpness = if tags.vertex_sharpness().is_empty() {
        Vec::new()
    } else {
        n.vertices
            .iter()
            .map(|&v| src.vertex_sharpness(v as usize))
            .collect()
    };
    let face_holes = if tags.holes().is_empty() {
        Vec::new()
    } else {
        faces.iter().map(|&f| src.is_hole(f as usize)).collect()
    };
    (edge_sharpness, vertex_sharpness, face_holes)
}

/// The start (ring position) of the single run of consecutive ring positions `kept`
/// (increasing) in a ring of `n` faces, cyclic when `closed`; `None` for several runs.
fn single_arc(kept: &[usize], n: usize, closed: bool) -> Option<usize> {
    let k = kept.len();
    // Breaks between consecutive kept positions; the last wraps around on a closed ring.
    let mut breaks = 0;
    let mut after = 0;
    for j in 0..k {
        let broken = if j + 1 == k {
            !closed || (kept[j] + 1) % n != kept[0]
        } else {
            kept[j] + 1 != kept[j + 1]
        };
        if broken {
            breaks += 1;
            after = (j + 1) % k;
        }
    }
    // One break in the (cyclic or linear) sequence: the run starts after it.
    (breaks == 1).then(|| kept[after])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::TopologyBuilder;

    #[test]
    fn complete_vertices_keep_their_rings_in_order() {
        // A 3 × 3 grid of quads; cut the four faces around the centre-left vertex 5 and
        // two more.
        let mut fv = Vec::new();
        for j in 0..3u32 {
            for i in 0..3u32 {
                let v = j * 4 + i;
                fv.extend([v, v + 1, v + 5, v + 4]);
            }
        }
        let t = TopologyBuilder::new(16).build(&[4; 9], &fv).unwrap();
        let faces = [0, 1, 3, 4, 5];
        let s = cut(&t, &faces);
        assert!(s.topology.check_relations().is_ok());
        let local5 = s.vertices.iter().position(|&v| v == 5).unwrap();
        assert!(s.complete[local5]);
        let src_ring: Vec<u32> = t.vertex_faces(5).to_vec();
        let cut_ring: Vec<u32> = s
            .topology
            .vertex_faces(local5)
            .iter()
            .map(|&g| faces[g as usize])
            .collect();
        assert_eq!(src_ring, cut_ring);
        let src_edges: Vec<u32> = t.vertex_edges(5).to_vec();
        let cut_edges: Vec<u32> = s
            .topology
            .vertex_edges(local5)
            .iter()
            .map(|&e| s.edges[e as usize])
            .collect();
        assert_eq!(src_edges, cut_edges);
        // Vertex 2 lost face 2: incomplete, a boundary fan of the cut.
        let local2 = s.vertices.iter().position(|&v| v == 2).unwrap();
        assert!(!s.complete[local2]);
        assert!(!s.topology.is_non_manifold_vertex(local2));
        assert!(s.topology.is_boundary_vertex(local2));
        // Vertex 6 lost face 2 of its four; every flag agrees with a rebuild from face lists.
        let six = s.vertices.iter().position(|&v| v == 6).unwrap();
        assert!(!s.complete[six]);
        let rebuilt = TopologyBuilder::new(s.topology.num_vertices())
            .build(
                &vec![4; s.topology.num_faces()],
                s.topology.all_face_vertices(),
            )
            .unwrap();
        for v in 0..s.topology.num_vertices() {
            assert_eq!(
                s.topology.is_non_manifold_vertex(v),
                rebuilt.is_non_manifold_vertex(v),
                "vertex {v}"
            );
            assert_eq!(
                s.topology.vertex_faces(v).len(),
                rebuilt.vertex_faces(v).len()
            );
        }
        for v in 0..s.topology.num_vertices() {
            if !s.topology.is_non_manifold_vertex(v) {
                // A manifold fan: each vertex edge leaves the vertex in the face at its place.
                let (vf, ve) = (s.topology.vertex_faces(v), s.topology.vertex_edges(v));
                for (i, (&f, &c)) in vf
                    .iter()
                    .zip(s.topology.vertex_face_local_indices(v))
                    .enumerate()
                {
                    assert_eq!(s.topology.face_edges(f as usize)[c as usize], ve[i]);
                }
            }
        }
        assert_eq!(s.topology.num_faces(), 5);
    }
}
