//! The numbering of uniform refinement, level by level, without refining: where the
//! children of a level's vertices, faces and edges land in the next level (OpenSubdiv's
//! default order, which this crate's refinement reproduces). Adaptive refinement gives every
//! element of its hierarchy its index in the uniform level, so that it can be named,
//! compared and tested against uniform refinement directly.

use subd_mesh::Topology;

use crate::{LevelCounts, Scheme, Split, refined_counts};

/// Element counts and child numbering of every uniform level up to a depth, for the schemes
/// that split a face into quads or a triangle into four (OpenSubdiv's and the butterflies).
#[derive(Clone, Debug)]
pub struct ChildLayout {
    split: Split,
    counts: Vec<LevelCounts>,
    /// Face offsets of the base level (Catmull-Clark's first level numbers a face's
    /// children and interior edges from them).
    base_offsets: Vec<u32>,
}

impl ChildLayout {
    /// The layout of `levels` uniform levels of `base` under `scheme`; `None` for a scheme
    /// whose split is neither [`Split::Quad`] nor [`Split::Triangle`] (Doo-Sabin, √3).
    pub fn new(base: &Topology, scheme: &Scheme, levels: usize) -> Option<ChildLayout> {
        let split = scheme.split();
        matches!(split, Split::Quad | Split::Triangle).then(|| ChildLayout {
            split,
            counts: refined_counts(base, scheme, levels),
            base_offsets: base.face_offsets().to_vec(),
        })
    }

    /// Counts of uniform level `level`.
    pub fn counts(&self, level: usize) -> LevelCounts {
        self.counts[level]
    }

    /// First of the consecutive child faces (and, for Catmull-Clark, interior child edges)
    /// of face `face` of level `level`.
    fn first_child(&self, level: usize, face: u64) -> u64 {
        match self.split {
            Split::Triangle => 4 * face,
            _ if level == 0 => self.base_offsets[face as usize] as u64,
            _ => 4 * face,
        }
    }

    /// Index in level `level + 1` of child `k` of face `face` of level `level`.
    pub fn child_face(&self, level: usize, face: u64, k: usize) -> u64 {
        self.first_child(level, face) + k as u64
    }

    /// Index in level `level + 1` of the interior child edge `j` of face `face`: Catmull-Clark
    /// `(F, E_j)`, Loop `(E_j, E_{j-1})`.
    pub fn interior_edge(&self, level: usize, face: u64, j: usize) -> u64 {
        match self.split {
            Split::Triangle => 3 * face + j as u64,
            _ => self.first_child(level, face) + j as u64,
        }
    }

    /// Index in level `level + 1` of the half of edge `edge` at its end `k`.
    pub fn half_edge(&self, level: usize, edge: u64, k: u32) -> u64 {
        let c = self.counts[level];
        let first = match self.split {
            Split::Triangle => 3 * c.faces,
            _ => c.face_vertices,
        };
        first + 2 * edge + k as u64
    }

    /// Index in level `level + 1` of the child of face `face` (Catmull-Clark and Bilinear).
    pub fn face_point(&self, level: usize, face: u64) -> u64 {
        self.counts[level].vertices + face
    }

    /// Index in level `level + 1` of the child of edge `edge`.
    pub fn edge_point(&self, level: usize, edge: u64) -> u64 {
        let c = self.counts[level];
        match self.split {
            Split::Triangle => c.vertices + edge,
            _ => c.vertices + c.faces + edge,
        }
    }

    /// Faces around the child of an edge used by `edge_faces` faces: two per face for the
    /// quad split, three for the triangle split.
    pub fn edge_point_faces(&self, edge_faces: u32) -> u32 {
        match self.split {
            Split::Triangle => 3 * edge_faces,
            _ => 2 * edge_faces,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Options, Refinement};
    use subd_mesh::TopologyBuilder;

    #[test]
    fn counts_match_uniform_refinement() {
        // A pyramid: a quad and four triangles.
        let fv = [0, 1, 2, 3, 0, 4, 1, 1, 4, 2, 2, 4, 3, 3, 4, 0];
        let t = TopologyBuilder::new(5)
            .build(&[4, 3, 3, 3, 3], &fv)
            .unwrap();
        let r = Refinement::new(&t, Scheme::CatmullClark, &Options::default(), 3).unwrap();
        let u = ChildLayout::new(&t, &Scheme::CatmullClark, 3).unwrap();
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
        let u = ChildLayout::new(&tri, &Scheme::Loop, 3).unwrap();
        assert!(ChildLayout::new(&tri, &Scheme::Sqrt3, 1).is_none());
        for l in 0..=3 {
            let tl = r.topology(l);
            assert_eq!(u.counts(l).edges, tl.num_edges() as u64);
            assert_eq!(u.counts(l).vertices, tl.num_vertices() as u64);
        }
    }
}
