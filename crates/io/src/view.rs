//! What the writers read: positions, polygons and the tags to write, without the edge
//! topology.
//!
//! A [`Mesh`] carries its full adjacency, which a file needs none of: an OBJ, PLY or glTF
//! file is a list of points, a list of polygons and a few tags. [`MeshView`] is that list,
//! borrowed. [`MeshView::from_mesh`] takes it from a mesh; [`MeshView::new`] assembles it
//! from face lists, so a caller that has polygons but no edges (the last level of a
//! refinement, which `subd refine` writes without building its edges) can write them.
//! [`MeshView::streamed`] takes the points, the polygons or both from sources that make
//! them a range at a time ([`PointSource`], [`FaceSource`]), so a level too large to hold
//! whole (the last level of a deep refinement) is written window by window.

use std::borrow::Cow;
use std::ops::Range;

use rayon::prelude::*;
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
    /// A texture-coordinate index names a value that does not exist.
    #[error("face {face} uses texture coordinate {index}, but there are only {values}")]
    TexCoordOutOfRange {
        /// The face.
        face: usize,
        /// The index it names.
        index: u32,
        /// Number of texture coordinates.
        values: usize,
    },
    /// A texture coordinate with a NaN or infinite component.
    #[error("texture coordinate {value} is not finite")]
    NonFiniteTexCoord {
        /// The value.
        value: usize,
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

/// Vertex positions made a range at a time, for a [`MeshView::streamed`] view.
pub trait PointSource: Sync {
    /// Number of points.
    fn len(&self) -> usize;
    /// Whether there are no points.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Writes points `first..first + out.len()` into `out`.
    fn fill(&self, first: usize, out: &mut [DVec3]);
}

/// Polygons of one size made a range at a time, for a [`MeshView::streamed`] view.
pub trait FaceSource: Sync {
    /// Number of faces.
    fn num_faces(&self) -> usize;
    /// Corners of every face.
    fn face_size(&self) -> usize;
    /// Appends the vertices of faces `faces` to `out`, [`Self::face_size`] per face.
    fn fill(&self, faces: Range<usize>, out: &mut Vec<u32>);
}

/// The positions of a [`MeshView::streamed`] view: held whole, or made a range at a time.
#[derive(Clone, Copy)]
pub enum Points<'a> {
    /// Every position, in memory (what vertex normals need).
    Held(&'a [DVec3]),
    /// Positions made window by window while writing.
    Streamed(&'a dyn PointSource),
}

impl std::fmt::Debug for Points<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Points::Held(p) => write!(f, "Held({} points)", p.len()),
            Points::Streamed(s) => write!(f, "Streamed({} points)", s.len()),
        }
    }
}

impl Points<'_> {
    fn len(&self) -> usize {
        match self {
            Points::Held(p) => p.len(),
            Points::Streamed(s) => s.len(),
        }
    }
}

#[derive(Clone, Copy)]
enum Faces<'a> {
    Held {
        offsets: &'a [u32],
        vertices: &'a [u32],
    },
    Streamed(&'a dyn FaceSource),
}

impl std::fmt::Debug for Faces<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Faces::Held { offsets, .. } => write!(f, "Held({} faces)", offsets.len() - 1),
            Faces::Streamed(s) => write!(f, "Streamed({} faces)", s.num_faces()),
        }
    }
}

#[derive(Clone, Debug)]
enum Holes<'a> {
    /// One flag per face, or none at all.
    Flags(&'a [bool]),
    /// The hole faces, ascending.
    List(Vec<usize>),
}

/// Texture coordinates of a view: values and, per face-vertex, the index of its value.
#[derive(Debug, Clone, Copy)]
pub struct TexCoords<'a> {
    values: &'a [f64],
    components: usize,
    indices: &'a [u32],
}

impl TexCoords<'_> {
    /// Number of values.
    pub fn len(&self) -> usize {
        self.values.len() / self.components
    }

    /// Whether there are no values.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Value `i`'s u and v.
    #[inline]
    pub fn uv(&self, i: usize) -> [f64; 2] {
        [
            self.values[i * self.components],
            self.values[i * self.components + 1],
        ]
    }

    /// The value index of every face-vertex, face after face.
    pub fn indices(&self) -> &[u32] {
        self.indices
    }
}

/// Points of a window of vertices, borrowed from a held view or made for the window.
pub(crate) struct PointWindow<'a> {
    first: usize,
    points: Cow<'a, [DVec3]>,
}

impl PointWindow<'_> {
    /// Point `i` (an index of the whole view, inside the window).
    #[inline]
    pub(crate) fn get(&self, i: usize) -> DVec3 {
        self.points[i - self.first]
    }

    pub(crate) fn points(&self) -> &[DVec3] {
        &self.points
    }
}

/// Polygons of a window of faces, borrowed from a held view or made for the window.
pub(crate) struct FaceWindow<'a> {
    first: usize,
    /// Face-vertex index of the first corner of `offsets[0]`'s face, less `offsets[0]`.
    corner_base: usize,
    /// Offsets of the window's faces into `vertices` (for a held view, the view's own).
    offsets: Cow<'a, [u32]>,
    vertices: Cow<'a, [u32]>,
}

impl FaceWindow<'_> {
    /// The vertices of face `f` (an index of the whole view, inside the window).
    #[inline]
    pub(crate) fn face(&self, f: usize) -> &[u32] {
        let k = f - self.first;
        &self.vertices[self.offsets[k] as usize..self.offsets[k + 1] as usize]
    }

    /// The face-vertex index (in the whole view) of face `f`'s first corner.
    #[inline]
    pub(crate) fn first_corner(&self, f: usize) -> usize {
        self.corner_base + self.offsets[f - self.first] as usize
    }
}

/// Positions, polygons and tags, as a writer needs them (see the [module docs](self)).
#[derive(Debug, Clone)]
pub struct MeshView<'a> {
    positions: Points<'a>,
    faces: Faces<'a>,
    holes: Holes<'a>,
    creases: Cow<'a, [([u32; 2], f32)]>,
    corners: Cow<'a, [(u32, f32)]>,
    normals: Option<&'a [DVec3]>,
    face_levels: Option<&'a [u8]>,
    uv: Option<TexCoords<'a>>,
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
            positions: Points::Held(positions),
            faces: Faces::Held {
                offsets: face_offsets,
                vertices: face_vertices,
            },
            holes: Holes::Flags(holes),
            creases: Cow::Borrowed(&[]),
            corners: Cow::Borrowed(&[]),
            normals: None,
            face_levels: None,
            uv: None,
            hints: SchemeHints::default(),
        })
    }

    /// A view whose positions, polygons or both are made a range at a time while writing
    /// (see the [module docs](self)), with the given hole faces, no crease or corner tags
    /// and no hints. Streamed positions are checked finite, and streamed polygons against
    /// the number of positions, as each window is made: a bad one fails the write (an
    /// `InvalidData` error naming the element) rather than the view.
    ///
    /// ```
    /// use std::ops::Range;
    /// use subd_io::{FaceSource, Format, MeshView, Points, WriteOptions, encode_view};
    /// use subd_mesh::DVec3;
    ///
    /// /// A strip of `n` quads, made on demand.
    /// struct Strip(usize);
    /// impl FaceSource for Strip {
    ///     fn num_faces(&self) -> usize { self.0 }
    ///     fn face_size(&self) -> usize { 4 }
    ///     fn fill(&self, faces: Range<usize>, out: &mut Vec<u32>) {
    ///         for f in faces {
    ///             let f = f as u32;
    ///             out.extend_from_slice(&[2 * f, 2 * f + 2, 2 * f + 3, 2 * f + 1]);
    ///         }
    ///     }
    /// }
    /// let points: Vec<DVec3> = (0..8).map(|i| DVec3::new((i / 2) as f64, (i % 2) as f64, 0.0)).collect();
    /// let view = MeshView::streamed(Points::Held(&points), &Strip(3), vec![]).unwrap();
    /// let mut obj = Vec::new();
    /// encode_view(&mut obj, &view, Format::Obj, &WriteOptions::default()).unwrap();
    /// assert!(String::from_utf8(obj).unwrap().contains("\nf 3 5 6 4\n"));
    /// ```
    ///
    /// # Errors
    /// [`ViewError::FaceTooSmall`] for faces of fewer than three corners, and
    /// [`ViewError::HoleCount`] for hole faces that are not ascending face indices.
    pub fn streamed(
        positions: Points<'a>,
        faces: &'a dyn FaceSource,
        hole_faces: Vec<usize>,
    ) -> Result<MeshView<'a>, ViewError> {
        if faces.face_size() < 3 && faces.num_faces() > 0 {
            return Err(ViewError::FaceTooSmall {
                face: 0,
                size: faces.face_size(),
            });
        }
        let ascending = hole_faces.windows(2).all(|w| w[0] < w[1]);
        if !ascending || hole_faces.last().is_some_and(|&f| f >= faces.num_faces()) {
            return Err(ViewError::HoleCount {
                flags: hole_faces.len(),
                faces: faces.num_faces(),
            });
        }
        if let Points::Held(p) = positions
            && let Some(vertex) = p.iter().position(|p| !p.is_finite())
        {
            return Err(ViewError::NonFinite { vertex });
        }
        Ok(MeshView {
            positions,
            faces: Faces::Streamed(faces),
            holes: Holes::List(hole_faces),
            creases: Cow::Borrowed(&[]),
            corners: Cow::Borrowed(&[]),
            normals: None,
            face_levels: None,
            uv: None,
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
        if normals.len() != self.num_vertices() {
            return Err(ViewError::Count {
                what: "normals",
                given: normals.len(),
                expected: self.num_vertices(),
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

    /// Adds texture coordinates: `components` numbers per value (the first two are u and
    /// v) and, per face-vertex (face after face), the index of its value. Corners of one
    /// vertex may name different values (seams): OBJ keeps them (`f v/vt`), `.glb` splits
    /// the vertex, PLY refuses them.
    ///
    /// # Errors
    /// [`ViewError::Count`] unless there is one index per face-vertex and a whole number
    /// of values of at least two components, [`ViewError::TexCoordOutOfRange`] for an
    /// index without a value, [`ViewError::NonFiniteTexCoord`] for a non-finite value.
    pub fn with_uv(
        mut self,
        values: &'a [f64],
        components: usize,
        indices: &'a [u32],
    ) -> Result<MeshView<'a>, ViewError> {
        let corners = self.num_face_vertices();
        if indices.len() != corners {
            return Err(ViewError::Count {
                what: "texture coordinate indices",
                given: indices.len(),
                expected: corners,
            });
        }
        if components < 2 || values.len() % components != 0 {
            return Err(ViewError::Count {
                what: "texture coordinate numbers",
                given: values.len(),
                expected: values.len().div_ceil(components.max(2)) * components.max(2),
            });
        }
        let n = values.len() / components;
        if let Some(k) = indices.iter().position(|&i| i as usize >= n) {
            return Err(ViewError::TexCoordOutOfRange {
                face: self.face_of_corner(k),
                index: indices[k],
                values: n,
            });
        }
        if let Some(i) = values.iter().position(|x| !x.is_finite()) {
            return Err(ViewError::NonFiniteTexCoord {
                value: i / components,
            });
        }
        self.uv = Some(TexCoords {
            values,
            components,
            indices,
        });
        Ok(self)
    }

    /// The texture coordinates given with [`Self::with_uv`] (or the mesh's first
    /// face-varying channel for [`Self::from_mesh`]).
    pub fn uv(&self) -> Option<TexCoords<'a>> {
        self.uv
    }

    /// Number of face-vertices (corners of all faces).
    pub fn num_face_vertices(&self) -> usize {
        match self.faces {
            Faces::Held { vertices, .. } => vertices.len(),
            Faces::Streamed(s) => s.num_faces() * s.face_size(),
        }
    }

    /// The face of face-vertex `k`.
    fn face_of_corner(&self, k: usize) -> usize {
        match self.faces {
            Faces::Held { offsets, .. } => offsets.partition_point(|&o| o as usize <= k) - 1,
            Faces::Streamed(s) => k / s.face_size().max(1),
        }
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
        let n = self.num_vertices();
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
        // Every edge and vertex is looked at (millions in a refined mesh): by all threads,
        // collected in order.
        let creases = (0..topo.num_edges())
            .into_par_iter()
            .filter(|&e| topo.edge_sharpness(e) > 0.0)
            .map(|e| (topo.edge_vertices(e), topo.edge_sharpness(e)))
            .collect();
        let corners = (0..topo.num_vertices())
            .into_par_iter()
            .filter(|&v| topo.vertex_sharpness(v) > 0.0)
            .map(|v| (v as u32, topo.vertex_sharpness(v)))
            .collect();
        MeshView {
            positions: Points::Held(&mesh.positions),
            faces: Faces::Held {
                offsets: topo.face_offsets(),
                vertices: topo.all_face_vertices(),
            },
            holes: Holes::Flags(topo.tags().holes()),
            creases: Cow::Owned(creases),
            corners: Cow::Owned(corners),
            normals: None,
            face_levels: None,
            // Writers read u and v: a channel of fewer components is not texture
            // coordinates.
            uv: mesh
                .uv()
                .filter(|c| c.components() >= 2)
                .map(|c| TexCoords {
                    values: c.values(),
                    components: c.components(),
                    indices: c.indices(),
                }),
            hints: mesh.hints,
        }
    }

    /// Vertex positions, when the view holds them (not for [`Points::Streamed`]).
    pub fn positions(&self) -> Option<&[DVec3]> {
        match self.positions {
            Points::Held(p) => Some(p),
            Points::Streamed(_) => None,
        }
    }

    /// Number of vertices.
    pub fn num_vertices(&self) -> usize {
        self.positions.len()
    }

    /// Number of faces.
    pub fn num_faces(&self) -> usize {
        match self.faces {
            Faces::Held { offsets, .. } => offsets.len() - 1,
            Faces::Streamed(s) => s.num_faces(),
        }
    }

    /// The largest face size.
    pub fn max_face_size(&self) -> usize {
        match self.faces {
            Faces::Held { offsets, .. } => offsets
                .windows(2)
                .map(|w| (w[1] - w[0]) as usize)
                .max()
                .unwrap_or(0),
            Faces::Streamed(s) => s.face_size(),
        }
    }

    /// Number of triangles in the fan triangulation of the faces that are not holes.
    pub fn num_fan_triangles(&self) -> usize {
        match self.faces {
            Faces::Held { offsets, .. } => (0..offsets.len() - 1)
                .filter(|&f| !self.is_hole(f))
                .map(|f| (offsets[f + 1] - offsets[f]) as usize - 2)
                .sum(),
            Faces::Streamed(s) => (s.num_faces() - self.hole_faces().len()) * (s.face_size() - 2),
        }
    }

    /// All face-vertex indices, face after face, when the view holds them (not for a
    /// streamed [`FaceSource`]).
    pub fn all_face_vertices(&self) -> Option<&[u32]> {
        match self.faces {
            Faces::Held { vertices, .. } => Some(vertices),
            Faces::Streamed(_) => None,
        }
    }

    /// Whether face `f` is a hole.
    #[inline]
    pub fn is_hole(&self, f: usize) -> bool {
        match &self.holes {
            Holes::Flags(h) => h.get(f).copied().unwrap_or(false),
            Holes::List(l) => l.binary_search(&f).is_ok(),
        }
    }

    /// Indices of the hole faces.
    pub fn hole_faces(&self) -> Vec<usize> {
        match &self.holes {
            Holes::Flags(h) => (0..h.len()).filter(|&f| h[f]).collect(),
            Holes::List(l) => l.clone(),
        }
    }

    /// The points of vertices `range`, checked finite where they are made here.
    pub(crate) fn point_window(&self, range: Range<usize>) -> std::io::Result<PointWindow<'_>> {
        let points = match self.positions {
            Points::Held(p) => Cow::Borrowed(&p[range.clone()]),
            Points::Streamed(s) => {
                let mut out = vec![DVec3::ZERO; range.len()];
                s.fill(range.start, &mut out);
                if let Some(i) = out.iter().position(|p| !p.is_finite()) {
                    return Err(invalid(ViewError::NonFinite {
                        vertex: range.start + i,
                    }));
                }
                Cow::Owned(out)
            }
        };
        Ok(PointWindow {
            first: range.start,
            points,
        })
    }

    /// The polygons of faces `range`, their vertices checked against the positions where
    /// they are made here.
    pub(crate) fn face_window(&self, range: Range<usize>) -> std::io::Result<FaceWindow<'_>> {
        let mut corner_base = 0;
        let (offsets, vertices) = match self.faces {
            Faces::Held { offsets, vertices } => (
                Cow::Borrowed(&offsets[range.start..=range.end]),
                Cow::Borrowed(vertices),
            ),
            Faces::Streamed(s) => {
                let k = s.face_size();
                let mut out = Vec::with_capacity(k * range.len());
                s.fill(range.clone(), &mut out);
                let n = self.num_vertices();
                if out.len() != k * range.len() {
                    return Err(invalid(ViewError::Offsets { indices: out.len() }));
                }
                if let Some(i) = out.iter().position(|&v| v as usize >= n) {
                    return Err(invalid(ViewError::VertexOutOfRange {
                        face: range.start + i / k,
                        vertex: out[i],
                        vertices: n,
                    }));
                }
                let offsets = (0..=range.len()).map(|f| (k * f) as u32).collect();
                corner_base = k * range.start;
                (Cow::Owned(offsets), Cow::Owned(out))
            }
        };
        Ok(FaceWindow {
            first: range.start,
            corner_base,
            offsets,
            vertices,
        })
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

/// A view error met while writing, as an I/O error.
fn invalid(e: ViewError) -> std::io::Error {
    std::io::Error::new(std::io::ErrorKind::InvalidData, e)
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
        let uv = [0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0];
        assert_eq!(
            view.clone().with_uv(&uv, 2, &[0, 1, 2]).unwrap_err(),
            ViewError::Count {
                what: "texture coordinate indices",
                given: 3,
                expected: 4
            }
        );
        assert_eq!(
            view.clone().with_uv(&uv, 2, &[0, 1, 2, 4]).unwrap_err(),
            ViewError::TexCoordOutOfRange {
                face: 0,
                index: 4,
                values: 4
            }
        );
        let nan_uv = [0.0, 0.0, 1.0, f64::NAN];
        assert_eq!(
            view.clone().with_uv(&nan_uv, 2, &[0, 1, 1, 0]).unwrap_err(),
            ViewError::NonFiniteTexCoord { value: 1 }
        );
        assert!(view.clone().with_uv(&uv, 1, &[0, 1, 2, 3]).is_err());
        let textured = view.clone().with_uv(&uv, 2, &[0, 1, 2, 3]).unwrap();
        assert_eq!(textured.uv().unwrap().uv(2), [1.0, 1.0]);
        let tagged = view.with_tags(vec![([0, 1], 2.5)], vec![(3, 1.0)]).unwrap();
        assert_eq!(tagged.creases(), &[([0, 1], 2.5)]);
        assert_eq!(tagged.corners(), &[(3, 1.0)]);
    }
}
