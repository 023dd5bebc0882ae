//! A set of faces of a level as a mesh of its own, every relation kept in the level's order.
//!
//! Rebuilding a piece from its face lists would number its edges and start its vertex rings
//! wherever the builder starts them. Masks sum their terms in ring order (and Chaikin's
//! sharpness average sums `f32` values in that order), so a vertex whose ring is complete in
//! the piece is given exactly the ring — same faces, same edges, same order — it has in the
//! level: the refinement of the piece then computes its children with the same operations,
//! bit for bit, as the refinement of the whole level.

use subd_mesh::{Topology, TopologyParts};

/// Marks an index that has no counterpart.
pub(crate) const NONE: u32 = u32::MAX;

/// Faces of a source topology cut out, with the map back to the source.
#[derive(Debug)]
pub(crate) struct SubMesh {
    /// The cut's topology, with the source's tags.
    pub topology: Topology,
    /// Source vertex of each cut vertex.
    pub vertices: Vec<u32>,
    /// Source edge of each cut edge.
    pub edges: Vec<u32>,
    /// Whether each cut vertex has every source face around it.
    pub complete: Vec<bool>,
}

/// Cuts `faces` (indices into `src`, each once) out of `src`. Vertices and edges are numbered
/// by first appearance in `faces`; face-edges, edge-faces, vertex-faces and vertex-edges are
/// the source's, filtered to the cut, in the source's order. A manifold vertex that lost
/// faces keeps them as the boundary fan they form when they are one run of its ring, and is
/// flagged non-manifold otherwise (as a mesh built from the cut's face lists would have it);
/// nothing the caller keeps reads such a vertex's ring.
pub(crate) fn cut(src: &Topology, faces: &[u32]) -> SubMesh {
    let mut vmap = vec![NONE; src.num_vertices()];
    let mut emap = vec![NONE; src.num_edges()];
    let mut fmap = vec![NONE; src.num_faces()];
    let mut vertices = Vec::new();
    let mut edges = Vec::new();
    let mut face_offsets = Vec::with_capacity(faces.len() + 1);
    face_offsets.push(0u32);
    let mut face_vertices = Vec::new();
    let mut face_edges = Vec::new();
    for (i, &f) in faces.iter().enumerate() {
        fmap[f as usize] = i as u32;
        for (&v, &e) in src
            .face_vertices(f as usize)
            .iter()
            .zip(src.face_edges(f as usize))
        {
            if vmap[v as usize] == NONE {
                vmap[v as usize] = vertices.len() as u32;
                vertices.push(v);
            }
            if emap[e as usize] == NONE {
                emap[e as usize] = edges.len() as u32;
                edges.push(e);
            }
            face_vertices.push(vmap[v as usize]);
            face_edges.push(emap[e as usize]);
        }
        face_offsets.push(face_vertices.len() as u32);
    }
    let edge_vertices: Vec<[u32; 2]> = edges
        .iter()
        .map(|&e| src.edge_vertices(e as usize).map(|v| vmap[v as usize]))
        .collect();

    let mut edge_face_offsets = Vec::with_capacity(edges.len() + 1);
    edge_face_offsets.push(0u32);
    let mut edge_faces = Vec::with_capacity(face_vertices.len());
    let mut edge_face_local = Vec::with_capacity(face_vertices.len());
    let mut edge_boundary = Vec::with_capacity(edges.len());
    let mut edge_non_manifold = Vec::with_capacity(edges.len());
    for &e in &edges {
        let start = edge_faces.len();
        for (&g, &l) in src
            .edge_faces(e as usize)
            .iter()
            .zip(src.edge_face_local_indices(e as usize))
        {
            if fmap[g as usize] != NONE {
                edge_faces.push(fmap[g as usize]);
                edge_face_local.push(l);
            }
        }
        edge_face_offsets.push(edge_faces.len() as u32);
        edge_boundary.push(edge_faces.len() - start == 1);
        edge_non_manifold.push(src.is_non_manifold_edge(e as usize));
    }

    let mut vertex_face_offsets = Vec::with_capacity(vertices.len() + 1);
    vertex_face_offsets.push(0u32);
    let mut vertex_faces = Vec::with_capacity(face_vertices.len());
    let mut vertex_face_local = Vec::with_capacity(face_vertices.len());
    let mut vertex_edge_offsets = Vec::with_capacity(vertices.len() + 1);
    vertex_edge_offsets.push(0u32);
    let mut vertex_edges = Vec::new();
    let mut vertex_non_manifold = Vec::with_capacity(vertices.len());
    let mut complete = Vec::with_capacity(vertices.len());
    let mut kept: Vec<usize> = Vec::new();
    for &v in &vertices {
        let v = v as usize;
        let (vf, vl, ve) = (
            src.vertex_faces(v),
            src.vertex_face_local_indices(v),
            src.vertex_edges(v),
        );
        kept.clear();
        kept.extend((0..vf.len()).filter(|&i| fmap[vf[i] as usize] != NONE));
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
                let (n, ne) = (vf.len(), ve.len());
                for j in 0..kept.len() {
                    let i = (first + j) % n;
                    vertex_faces.push(fmap[vf[i] as usize]);
                    vertex_face_local.push(vl[i]);
                }
                for j in 0..=kept.len() {
                    vertex_edges.push(emap[ve[(first + j) % ne] as usize]);
                }
                vertex_non_manifold.push(false);
            }
            None => {
                for &i in &kept {
                    vertex_faces.push(fmap[vf[i] as usize]);
                    vertex_face_local.push(vl[i]);
                }
                for &e in ve {
                    if emap[e as usize] != NONE {
                        vertex_edges.push(emap[e as usize]);
                    }
                }
                vertex_non_manifold.push(src.is_non_manifold_vertex(v) || !whole);
            }
        }
        vertex_face_offsets.push(vertex_faces.len() as u32);
        vertex_edge_offsets.push(vertex_edges.len() as u32);
        complete.push(whole);
    }

    let tags = src.tags();
    let edge_sharpness = if tags.edge_sharpness().is_empty() {
        Vec::new()
    } else {
        edges
            .iter()
            .map(|&e| src.edge_sharpness(e as usize))
            .collect()
    };
    let vertex_sharpness = if tags.vertex_sharpness().is_empty() {
        Vec::new()
    } else {
        vertices
            .iter()
            .map(|&v| src.vertex_sharpness(v as usize))
            .collect()
    };
    let face_holes = if tags.holes().is_empty() {
        Vec::new()
    } else {
        faces.iter().map(|&f| src.is_hole(f as usize)).collect()
    };
    let topology = Topology::from_parts(TopologyParts {
        num_vertices: vertices.len(),
        face_offsets,
        face_vertices,
        face_edges,
        edge_vertices,
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
        edge_sharpness,
        vertex_sharpness,
        face_holes,
    })
    .expect("a cut of a valid topology has consistent parts");
    SubMesh {
        topology,
        vertices,
        edges,
        complete,
    }
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
    use subd_mesh::TopologyBuilder;

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
