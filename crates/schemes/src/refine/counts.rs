//! Element counts of refined levels in closed form, without refining: what a caller needs to
//! estimate time and memory before committing to a request.

use subd_mesh::Topology;

use crate::{Scheme, Split};

/// Element counts of one level.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LevelCounts {
    /// Vertices.
    pub vertices: u64,
    /// Edges.
    pub edges: u64,
    /// Faces.
    pub faces: u64,
    /// Face-vertex incidences (the length of the face-vertex list).
    pub face_vertices: u64,
}

impl LevelCounts {
    /// The counts of `t`.
    pub fn of(t: &Topology) -> LevelCounts {
        LevelCounts {
            vertices: t.num_vertices() as u64,
            edges: t.num_edges() as u64,
            faces: t.num_faces() as u64,
            face_vertices: t.num_face_vertices() as u64,
        }
    }

    /// The counts one uniform step of `scheme` gives. Exact for OpenSubdiv's schemes on
    /// every input: Catmull-Clark and Bilinear split an n-gon into n quads around a face
    /// point (V + E + F vertices, 2E + FV edges); Loop and the butterflies split a triangle
    /// into 4 (V + E vertices, 2E + 3F edges). Exact for Doo-Sabin and √3 on closed
    /// manifolds; on open meshes the boundary's extra elements (Doo-Sabin's Chaikin points,
    /// √3's boundary trisection) are within a small fraction of the total.
    pub fn refined(self, scheme: &Scheme) -> LevelCounts {
        let LevelCounts {
            vertices: v,
            edges: e,
            faces: f,
            face_vertices: fv,
        } = self;
        match scheme.split() {
            Split::Quad => LevelCounts {
                vertices: v + e + f,
                edges: 2 * e + fv,
                faces: fv,
                face_vertices: 4 * fv,
            },
            Split::Triangle => LevelCounts {
                vertices: v + e,
                edges: 2 * e + 3 * f,
                faces: 4 * f,
                face_vertices: 12 * f,
            },
            // F-faces, E-faces and V-faces; a vertex per face corner.
            Split::Dual => LevelCounts {
                vertices: fv,
                edges: fv + 2 * e,
                faces: f + e + v,
                face_vertices: fv + 4 * e + 2 * e,
            },
            // A centroid per triangle, each triangle into three after the flips.
            Split::Sqrt3 => LevelCounts {
                vertices: v + f,
                edges: e + 3 * f,
                faces: 3 * f,
                face_vertices: 9 * f,
            },
        }
    }
}

/// The counts of levels `0..=levels` of a uniform refinement of `base` with `scheme`.
///
/// ```
/// use subd_mesh::TopologyBuilder;
/// use subd_schemes::{LevelCounts, Refinement, Scheme, refined_counts};
///
/// let faces = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4];
/// let cube = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
/// let counts = refined_counts(&cube, &Scheme::CatmullClark, 3);
/// let r = Refinement::new(&cube, Scheme::CatmullClark, &Default::default(), 2).unwrap();
/// assert_eq!(counts[2], LevelCounts::of(r.topology(2)));
/// assert_eq!(counts[3].faces, 6 * 64);
/// ```
pub fn refined_counts(base: &Topology, scheme: &Scheme, levels: usize) -> Vec<LevelCounts> {
    let mut out = vec![LevelCounts::of(base)];
    for _ in 0..levels {
        let last = *out.last().expect("level 0");
        out.push(last.refined(scheme));
    }
    out
}

/// Bytes a fully built level of these counts takes (face, edge and vertex relations, tags
/// and rules), for the allocation probe before it is built.
pub(crate) fn topology_bytes(c: LevelCounts) -> u64 {
    24 * c.face_vertices + 32 * c.edges + 16 * c.vertices + 8 * c.faces
}

/// Bytes of a last level kept as face lists with its positions.
pub(crate) fn last_level_bytes(c: LevelCounts) -> u64 {
    4 * c.face_vertices + 4 * c.faces + 24 * c.vertices
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Options, Refinement};
    use subd_mesh::TopologyBuilder;

    /// A closed torus of quads and hexagons, and its quads cut into triangles.
    fn meshes() -> (Topology, Topology) {
        let mixed = subd_mesh::primitives::torus_with_hexagons(8, 6, 4, 3.0, 1.0).topology;
        let quads = subd_mesh::primitives::torus(8, 6, 3.0, 1.0).topology;
        let mut tris = Vec::new();
        for f in 0..quads.num_faces() {
            let v = quads.face_vertices(f);
            tris.extend_from_slice(&[v[0], v[1], v[2], v[0], v[2], v[3]]);
        }
        let tri = TopologyBuilder::new(quads.num_vertices())
            .build(&vec![3; tris.len() / 3], &tris)
            .unwrap();
        (mixed, tri)
    }

    #[test]
    fn counts_match_the_refined_levels() {
        let (mixed, tri) = meshes();
        for (base, scheme) in [
            (&mixed, Scheme::CatmullClark),
            (&mixed, Scheme::Bilinear),
            (&tri, Scheme::Loop),
            (&mixed, Scheme::DooSabin),
            (&tri, Scheme::Sqrt3),
            (&tri, Scheme::ModifiedButterfly),
        ] {
            let r = Refinement::new(base, scheme.clone(), &Options::default(), 3).unwrap();
            let counts = refined_counts(base, &scheme, 3);
            for (l, c) in counts.iter().enumerate() {
                assert_eq!(*c, LevelCounts::of(r.topology(l)), "{scheme:?} level {l}");
            }
        }
    }
}
