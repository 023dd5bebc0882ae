//! What the writers read: positions, polygons and the tags to write, without the edge
//! topology.
//!
//! A [`Mesh`] carries its full adjacency, which a file needs none of: an OBJ, PLY or glTF
//! file is a list of points, a list of polygons and a few tags. [`MeshView`] is that list,
//! borrowed. [`MeshView::from_mesh`] takes it from a mesh; [`MeshView::new`] assembles it
//! from face lists, so a caller that has polygons but no edges (the last level of a
//! refinement, which `subd refine` writes without building its edges) can write them.

use std::borrow::Cow;

use subd_mesh::{DVec3, Mesh, SchemeHints};
use thiserror::Error;

/// A face list that does not describe a mesh a writer can write.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ViewError {
    /// Face offsets must start at 0, never decrease, and end at the number of indices.
    #[error("face offsets do not run from 0 to the {indices} face-vertex indices in order")]
    Offsets {
        /// Number of face-vertex indices given.
        indices: usize,
    },
    /// A face names a vertex without a position.
    #[error("face {face} uses vertex {vertex}, but there are only {vertices} positions")]
    VertexOutOfRange {
        /// The face.
        face: usize,
        /// The vertex it names.
        vertex: u32,
        /// Number of positions.
        vertices: usize,
    },
    /// A face with fewer than three corners.
    #[error("face {face} has {size} vertices (at least 3 needed)")]
    FaceTooSmall {
        /// The face.
        face: usize,
        /// Its size.
        size: usize,
    },
    /// A position with a NaN or infinite coordinate.
    #[error("vertex {vertex} has a non-finite coordinate")]
    NonFinite {
        /// The vertex.
        vertex: usize,
    },
    /// Hole flags, when given, must be one per face.
    #[error("{flags} hole flags for {faces} faces")]
    HoleCount {
        /// Flags given.
        flags: usize,
        /// Faces.
        faces: usize,
    },
    /// Normals or face levels, when given, must be one per vertex or per face.
    #[error("{given} {what} given for {expected}")]
    Count {
        /// `normals` or `face levels`.
        what: &'static str,
        /// How many were given.
        given: usize,
        /// How many are needed.
        expected: usize,
    },
    /// A crease or corner tag names a vertex without a position, or has a sharpness that
    /// is not a positive number.
    #[error("{what} tag {index} is invalid (vertex beyond the positions or sharpness not > 0)")]
    Tag {
        /// `crease` or `corner`.
        what: &'static str,
        /// Its index in the list.
        index: usize,
    },
}

/// Positions, polygons and tags, as a writer needs them (see the [module docs](self)).
#[derive(Debug, Clone)]
pub struct MeshView<'a> {
    positions: &'a [DVec3],
    face_offsets: &'a [u32],
    face_vertices: &'a [u32],
    holes: &'a [bool],
    creases: Cow<'a, [([u32; 2], f32)]>,
    corners: Cow<'a, [(u32, f32)]>,
    normals: Option<&'a [DVec3]>,
    face_levels: Option<&'a [u8]>,
    /// Scheme hints written as tags (OBJ) or comments (PLY).
    pub hints: SchemeHints,
}

impl<'a> MeshView<'a> {
    /// A view of `positions` and the polygons `face_vertices[face_offsets[f]..
    /// face_offsets[f + 1]]`, with one hole flag per face (or none: no holes), no crease or
    /// corner tags and no hints.
    ///
    /// ```
    /// use subd_io::{Format, MeshView, WriteOptions, encode_view};
    /// use subd_mesh::DVec3;
    /// let points = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
    /// let view = MeshView::new(&points, &[0, 4], &[0, 1, 2, 3], &[]).unwrap();
    /// let mut obj = Vec::new();
    /// encode_view(&mut obj, &view, Format::Obj, &WriteOptions::default()).unwrap();
    /// assert!(String::from_utf8(obj).unwrap().contains("\nf 1 2 3 4\n"));
    /// assert!(MeshView::new(&points, &[0, 4], &[0, 1, 2, 7], &[]).is_err());
    /// ```
    ///
    /// # Errors
    /// A [`ViewError`] for offsets out of order, a face with fewer than three corners, a
    /// vertex index without a position, a non-finite position, or hole flags that are not
    /// one per face.
    pub fn new(
        positions: &'a [DVec3],
        face_offsets: &'a [u32],
        face_vertices: &'a [u32],
        holes: &'a [bool],
    ) -> Result<MeshView<'a>, ViewError> {
        let indices = face_vertices.len();
        let ordered = face_offsets.first() == Some(&0)
            && face_offsets.last().map(|&o| o as usize) == Some(indices)
            && face_offsets.windows(2).all(|w| w[0] <= w[1]);
        if !ordered {
            return Err(ViewError::Offsets { indices });
        }
        let faces = face_offsets.len() - 1;
        if !holes.is_empty() && holes.len() != faces {
            return Err(ViewError::HoleCount {
                flags: holes.len(),
                faces,
            });
        }
        if let Some(face) = (0..faces).find(|&f| face_offsets[f + 1] - face_offsets[f] < 3) {
            let size = (face_offsets[face + 1] - face_offsets[face]) as usize;
            return Err(ViewError::FaceTooSmall { face, size });
        }
        if let Some(k) = face_vertices
            .iter()
            .position(|&v| v as usize >= positions.len())
        {
            let face = face_offsets.partition_point(|&o| o as usize <= k) - 1;
            return Err(ViewError::VertexOutOfRange {
                face,
                vertex: face_vertices[k],
                vertices: positions.len(),
            });
        }
        if let Some(vertex) = positions.iter().position(|p| !p.is_finite()) {
            return Err(ViewError::NonFinite { vertex });
        }
        Ok(MeshView {
            positions,
            face_offsets,
            face_vertices,
            holes,
            creases: Cow::Borrowed(&[]),
            corners: Cow::Borrowed(&[]),
            normals: None,
            face_levels: None,
            hints: SchemeHints::default(),
        })
    }

    /// Adds one unit normal per vertex, written instead of normals derived from the faces:
    /// OBJ `vn` lines, PLY `nx ny nz` vertex properties, the glTF `NORMAL` attribute.
    ///
    /// # Errors
    /// [`ViewError::Count`] unless there is one normal per position, [`ViewError::NonFinite`]
    /// for a normal with a NaN or infinite coordinate.
    pub fn with_normals(mut self, normals: &'a [DVec3]) -> Result<MeshView<'a>, ViewError> {
        if normals.len() != self.positions.len() {
            return Err(ViewError::Count {
                what: "normals",
                given: normals.len(),
                expected: self.positions.len(),
            });
        }
        if let Some(vertex) = normals.iter().position(|n| !n.is_finite()) {
            return Err(ViewError::NonFinite { vertex });
        }
        self.normals = Some(normals);
        Ok(self)
    }

    /// Adds a refinement level per face, written as the PLY face property `level` (`uchar`);
    /// OBJ and glTF files have no place for it.
    ///
    /// # Errors
    /// [`ViewError::Count`] unless there is one level per face.
    pub fn with_face_levels(mut self, levels: &'a [u8]) -> Result<MeshView<'a>, ViewError> {
        if levels.len() != self.num_faces() {
            return Err(ViewError::Count {
                what: "face levels",
                given: levels.len(),
                expected: self.num_faces(),
            });
        }
        self.face_levels = Some(levels);
        Ok(self)
    }

    /// The per-vertex normals given with [`Self::with_normals`].
    pub fn normals(&self) -> Option<&[DVec3]> {
        self.normals
    }

    /// The per-face levels given with [`Self::with_face_levels`].
    pub fn face_levels(&self) -> Option<&[u8]> {
        self.face_levels
    }

    /// Adds crease tags (edge end points and sharpness) and corner tags (vertex and
    /// sharpness), written in the order given.
    ///
    /// # Errors
    /// [`ViewError::Tag`] for a tag naming a vertex without a position or with a sharpness
    /// that is not a positive number.
    pub fn with_tags(
        mut self,
        creases: Vec<([u32; 2], f32)>,
        corners: Vec<(u32, f32)>,
    ) -> Result<MeshView<'a>, ViewError> {
        let n = self.positions.len();
        let ok = |v: u32, s: f32| (v as usize) < n && s > 0.0;
        if let Some(index) = creases
            .iter()
            .position(|&([a, b], s)| !ok(a, s) || !ok(b, s))
        {
            return Err(ViewError::Tag {
                what: "crease",
                index,
            });
        }
        if let Some(index) = corners.iter().position(|&(v, s)| !ok(v, s)) {
            return Err(ViewError::Tag {
                what: "corner",
                index,
            });
        }
        self.creases = Cow::Owned(creases);
        self.corners = Cow::Owned(corners);
        Ok(self)
    }

    /// The view of a mesh: its polygons, holes, hints, and a crease tag for every edge and
    /// a corner tag for every vertex with sharpness above zero (in edge and vertex order).
    pub fn from_mesh(mesh: &'a Mesh) -> MeshView<'a> {
        let topo = &mesh.topology;
        let creases = (0..topo.num_edges())
            .filter(|&e| topo.edge_sharpness(e) > 0.0)
            .map(|e| (topo.edge_vertices(e), topo.edge_sharpness(e)))
            .collect();
        let corners = (0..topo.num_vertices())
            .filter(|&v| topo.vertex_sharpness(v) > 0.0)
            .map(|v| (v as u32, topo.vertex_sharpness(v)))
            .collect();
        MeshView {
            positions: &mesh.positions,
            face_offsets: topo.face_offsets(),
            face_vertices: topo.all_face_vertices(),
            holes: topo.tags().holes(),
            creases: Cow::Owned(creases),
            corners: Cow::Owned(corners),
            normals: None,
            face_levels: None,
            hints: mesh.hints,
        }
    }

    /// Vertex positions.
    pub fn positions(&self) -> &[DVec3] {
        self.positions
    }

    /// Number of faces.
    pub fn num_faces(&self) -> usize {
        self.face_offsets.len() - 1
    }

    /// All face-vertex indices, face after face.
    pub fn all_face_vertices(&self) -> &[u32] {
        self.face_vertices
    }

    /// The vertices of face `f`.
    #[inline]
    pub fn face_vertices(&self, f: usize) -> &[u32] {
        &self.face_vertices[self.face_offsets[f] as usize..self.face_offsets[f + 1] as usize]
    }

    /// Whether face `f` is a hole.
    #[inline]
    pub fn is_hole(&self, f: usize) -> bool {
        self.holes.get(f).copied().unwrap_or(false)
    }

    /// Indices of the hole faces.
    pub fn hole_faces(&self) -> Vec<usize> {
        (0..self.holes.len()).filter(|&f| self.holes[f]).collect()
    }

    /// Crease tags: edge end points and sharpness.
    pub fn creases(&self) -> &[([u32; 2], f32)] {
        &self.creases
    }

    /// Corner tags: vertex and sharpness.
    pub fn corners(&self) -> &[(u32, f32)] {
        &self.corners
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_face_lists_are_named() {
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        let quad = [0, 1, 2, 3];
        assert!(MeshView::new(&p, &[0, 4], &quad, &[]).is_ok());
        assert_eq!(
            MeshView::new(&p, &[0, 3], &quad, &[]).unwrap_err(),
            ViewError::Offsets { indices: 4 }
        );
        assert_eq!(
            MeshView::new(&p, &[0, 2, 4], &quad, &[]).unwrap_err(),
            ViewError::FaceTooSmall { face: 0, size: 2 }
        );
        assert_eq!(
            MeshView::new(&p, &[0, 3, 6], &[0, 1, 2, 2, 3, 9], &[]).unwrap_err(),
            ViewError::VertexOutOfRange {
                face: 1,
                vertex: 9,
                vertices: 4
            }
        );
        assert_eq!(
            MeshView::new(&p, &[0, 4], &quad, &[false, true]).unwrap_err(),
            ViewError::HoleCount { flags: 2, faces: 1 }
        );
        let nan = [DVec3::ZERO, DVec3::X, DVec3::NAN, DVec3::Z];
        assert_eq!(
            MeshView::new(&nan, &[0, 4], &quad, &[]).unwrap_err(),
            ViewError::NonFinite { vertex: 2 }
        );
        let view = MeshView::new(&p, &[0, 4], &quad, &[]).unwrap();
        assert_eq!(
            view.clone()
                .with_tags(vec![([0, 4], 1.0)], vec![])
                .unwrap_err(),
            ViewError::Tag {
                what: "crease",
                index: 0
            }
        );
        assert_eq!(
            view.clone()
                .with_tags(vec![], vec![(1, 2.0), (2, 0.0)])
                .unwrap_err(),
            ViewError::Tag {
                what: "corner",
                index: 1
            }
        );
        let tagged = view.with_tags(vec![([0, 1], 2.5)], vec![(3, 1.0)]).unwrap();
        assert_eq!(tagged.creases(), &[([0, 1], 2.5)]);
        assert_eq!(tagged.corners(), &[(3, 1.0)]);
    }
}
