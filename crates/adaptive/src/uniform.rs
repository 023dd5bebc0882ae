//! The numbering of uniform refinement, level by level, without refining: where the
//! children of a level's vertices, faces and edges land in the next level (OpenSubdiv's
//! default order, which `subd-schemes` reproduces). Every element of the adaptive hierarchy
//! carries its index in the uniform level, so it can be named, compared and tested against
//! uniform refinement directly.

use subd_mesh::Topology;
use subd_schemes::Scheme;

/// Element counts of one uniform level (`u64`: deep levels of large meshes pass `u32`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UniformCounts {
    /// Vertices.
    pub vertices: u64,
    /// Faces.
    pub faces: u64,
    /// Edges.
    pub edges: u64,
    /// Face-vertices.
    pub face_vertices: u64,
}

/// Element counts and child numbering of every uniform level up to a depth.
#[derive(Clone, Debug)]
pub(crate) struct UniformLayout {
    scheme: Scheme,
    counts: Vec<UniformCounts>,
    /// Face offsets of the base level (Catmull-Clark's first level numbers a face's
    /// children and interior edges from them).
    base_offsets: Vec<u32>,
}

impl UniformLayout {
    pub(crate) fn new(base: &Topology, scheme: &Scheme, levels: usize) -> UniformLayout {
        let mut c = UniformCounts {
            vertices: base.num_vertices() as u64,
            faces: base.num_faces() as u64,
            edges: base.num_edges() as u64,
            face_vertices: base.num_face_vertices() as u64,
        };
        let mut counts = vec![c];
        for _ in 0..levels {
            c = match scheme {
                Scheme::Loop => UniformCounts {
                    vertices: c.vertices + c.edges,
                    faces: 4 * c.faces,
                    edges: 2 * c.edges + 3 * c.faces,
                    face_vertices: 12 * c.faces,
                },
                _ => UniformCounts {
                    vertices: c.vertices + c.faces + c.edges,
                    faces: c.face_vertices,
                    edges: 2 * c.edges + c.face_vertices,
                    face_vertices: 4 * c.face_vertices,
                },
            };
            counts.push(c);
        }
        UniformLayout {
            scheme: scheme.clone(),
            counts,
            base_offsets: base.face_offsets().to_vec(),
        }
    }

    /// Counts of uniform level `level`.
    pub(crate) fn counts(&self, level: usize) -> UniformCounts {
        self.counts[level]
    }

    /// First of the consecutive child faces (and, for Catmull-Clark, interior child edges)
    /// of face `face` of level `level`.
    fn first_child(&self, level: usize, face: u64) -> u64 {
        match self.scheme {
            Scheme::Loop => 4 * face,
            _ if level == 0 => self.base_offsets[face as usize] as u64,
            _ => 4 * face,
        }
    }

    /// Index in level `level + 1` of child `k` of face `face` of level `level`.
    pub(crate) fn child_face(&self, level: usize, face: u64, k: usize) -> u64 {
        self.first_child(level, face) + k as u64
    }

    /// Index in level `level + 1` of the interior child edge `j` of face `face`: Catmull-Clark
    /// `(F, E_j)`, Loop `(E_j, E_{j-1})`.
    pub(crate) fn interior_edge(&self, level: usize, face: u64, j: usize) -> u64 {
        match self.scheme {
            Scheme::Loop => 3 * face + j as u64,
            _ => self.first_child(level, face) + j as u64,
        }
    }

    /// Index in level `level + 1` of the half of edge `edge` at its end `k`.
    pub(crate) fn half_edge(&self, level: usize, edge: u64, k: u32) -> u64 {
        let c = self.counts[level];
        let first = match self.scheme {
            Scheme::Loop => 3 * c.faces,
            _ => c.face_vertices,
        };
        first + 2 * edge + k as u64
    }

    /// Index in level `level + 1` of the child of face `face` (Catmull-Clark and Bilinear).
    pub(crate) fn face_point(&self, level: usize, face: u64) -> u64 {
        self.counts[level].vertices + face
    }

    /// Index in level `level + 1` of the child of edge `edge`.
    pub(crate) fn edge_point(&self, level: usize, edge: u64) -> u64 {
        let c = self.counts[level];
        match self.scheme {
            Scheme::Loop => c.vertices + edge,
            _ => c.vertices + c.faces + edge,
        }
    }

    /// Faces around the child of an edge used by `edge_faces` faces: two per face for the
    /// quad split, three for the triangle split.
    pub(crate) fn edge_point_faces(&self, edge_faces: u32) -> u32 {
        match self.scheme {
            Scheme::Loop => 3 * edge_faces,
            _ => 2 * edge_faces,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use subd_mesh::TopologyBuilder;
    use subd_schemes::{Options, Refinement};

    #[test]
    fn counts_match_uniform_refinement() {
        // A pyramid: a quad and four triangles.
        let fv = [0, 1, 2, 3, 0, 4, 1, 1, 4, 2, 2, 4, 3, 3, 4, 0];
        let t = TopologyBuilder::new(5)
            .build(&[4, 3, 3, 3, 3], &fv)
            .unwrap();
        let r = Refinement::new(&t, Scheme::CatmullClark, &Options::default(), 3).unwrap();
        let u = UniformLayout::new(&t, &Scheme::CatmullClark, 3);
        for l in 0..=3 {
            let c = u.counts(l);
            let tl = r.topology(l);
            assert_eq!(c.vertices, tl.num_vertices() as u64);
            assert_eq!(c.faces, tl.num_faces() as u64);
            assert_eq!(c.edges, tl.num_edges() as u64);
            assert_eq!(c.face_vertices, tl.num_face_vertices() as u64);
        }
        let tri = TopologyBuilder::new(4)
            .build(&[3; 4], &[0, 1, 2, 0, 3, 1, 1, 3, 2, 2, 3, 0])
            .unwrap();
        let r = Refinement::new(&tri, Scheme::Loop, &Options::default(), 3).unwrap();
        let u = UniformLayout::new(&tri, &Scheme::Loop, 3);
        for l in 0..=3 {
            let tl = r.topology(l);
            assert_eq!(u.counts(l).edges, tl.num_edges() as u64);
            assert_eq!(u.counts(l).vertices, tl.num_vertices() as u64);
        }
    }
}
