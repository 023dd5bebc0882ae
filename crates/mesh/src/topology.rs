//! The [`Topology`] type: flat, index-based adjacency of a polygon mesh.

use rayon::prelude::*;

use crate::error::TopologyError;
use crate::tags::{self, Tags};

/// Edge flag: the edge has exactly one incident face.
pub(crate) const EDGE_BOUNDARY: u8 = 1;
/// Edge flag: the edge is non-manifold (more than two faces, same-direction use by two faces,
/// repeated within a face, or degenerate).
pub(crate) const EDGE_NON_MANIFOLD: u8 = 2;
/// Edge flag: both ends of the edge are the same vertex.
pub(crate) const EDGE_DEGENERATE: u8 = 4;

/// Vertex flag: the vertex lies on a boundary edge.
pub(crate) const VERTEX_BOUNDARY: u8 = 1;
/// Vertex flag: the faces and edges around the vertex do not form a single fan.
pub(crate) const VERTEX_NON_MANIFOLD: u8 = 2;
/// Vertex flag: no face uses the vertex.
pub(crate) const VERTEX_ISOLATED: u8 = 4;

/// The most vertices a face may have: local indices (a vertex's corner in a face, an edge's
/// position in a face) are 16-bit, as OpenSubdiv's `Vtr::LocalIndex`, whose limit this is.
pub const MAX_FACE_SIZE: usize = u16::MAX as usize;

/// Adjacency of a polygon mesh in compressed-sparse-row (CSR) arrays.
///
/// Built by [`crate::TopologyBuilder`] from face-vertex lists. All relations are flat `u32`
/// arrays with offsets, so a scheme can walk them without chasing pointers:
///
/// * face → vertices and face → edges (edge `i` of a face joins its vertices `i` and `i+1`);
/// * edge → its two vertices and edge → incident faces (in face order);
/// * vertex → incident faces and vertex → incident edges, **ordered counter-clockwise** (with
///   respect to the face winding) around every manifold vertex. For a boundary vertex the
///   walk starts at the boundary edge that leaves the vertex in its face.
///
/// Edges are numbered as OpenSubdiv numbers them: by first appearance when walking the faces
/// in order and each face's edges `(v_i, v_{i+1})`; an edge keeps the direction of the first
/// face that uses it. A face that repeats an edge, or has a degenerate edge (`v_i == v_{i+1}`),
/// gets an extra non-manifold edge instance, again as OpenSubdiv does.
///
/// Geometry is not stored here: positions live in a separate slice indexed by vertex (see
/// [`crate::Mesh`]). Tags (crease and corner sharpness, holes) are stored with the topology
/// because refinement propagates them together.
#[derive(Debug, Clone, PartialEq)]
pub struct Topology {
    pub(crate) num_vertices: u32,
    pub(crate) face_offsets: Vec<u32>,
    pub(crate) face_vertices: Vec<u32>,
    pub(crate) face_edges: Vec<u32>,
    pub(crate) edge_vertices: Vec<[u32; 2]>,
    pub(crate) edge_face_offsets: Vec<u32>,
    pub(crate) edge_faces: Vec<u32>,
    pub(crate) edge_face_local: Vec<u16>,
    pub(crate) vertex_face_offsets: Vec<u32>,
    pub(crate) vertex_faces: Vec<u32>,
    pub(crate) vertex_face_local: Vec<u16>,
    pub(crate) vertex_edge_offsets: Vec<u32>,
    pub(crate) vertex_edges: Vec<u32>,
    pub(crate) edge_flags: Vec<u8>,
    pub(crate) vertex_flags: Vec<u8>,
    pub(crate) tags: Tags,
}

#[inline]
fn range(offsets: &[u32], i: usize) -> std::ops::Range<usize> {
    offsets[i] as usize..offsets[i + 1] as usize
}

impl Topology {
    /// Number of vertices (including isolated ones that no face uses).
    #[inline]
    pub fn num_vertices(&self) -> usize {
        self.num_vertices as usize
    }

    /// Number of unique edges (non-manifold instances counted separately, as OpenSubdiv does).
    #[inline]
    pub fn num_edges(&self) -> usize {
        self.edge_vertices.len()
    }

    /// Number of faces.
    #[inline]
    pub fn num_faces(&self) -> usize {
        self.face_offsets.len() - 1
    }

    /// Total number of face-vertices (sum of the face sizes).
    #[inline]
    pub fn num_face_vertices(&self) -> usize {
        self.face_vertices.len()
    }

    /// Offsets of each face's run in [`Self::all_face_vertices`] (length `num_faces + 1`).
    #[inline]
    pub fn face_offsets(&self) -> &[u32] {
        &self.face_offsets
    }

    /// Offsets of each edge's run in the edge-face relation (length `num_edges + 1`).
    #[inline]
    pub fn edge_face_offsets(&self) -> &[u32] {
        &self.edge_face_offsets
    }

    /// Offsets of each vertex's run in the vertex-face relation (length `num_vertices + 1`).
    #[inline]
    pub fn vertex_face_offsets(&self) -> &[u32] {
        &self.vertex_face_offsets
    }

    /// Offsets of each vertex's run in the vertex-edge relation (length `num_vertices + 1`).
    #[inline]
    pub fn vertex_edge_offsets(&self) -> &[u32] {
        &self.vertex_edge_offsets
    }

    /// All face-vertex indices, face after face.
    #[inline]
    pub fn all_face_vertices(&self) -> &[u32] {
        &self.face_vertices
    }

    /// Number of vertices of face `f`.
    #[inline]
    pub fn face_size(&self, f: usize) -> usize {
        (self.face_offsets[f + 1] - self.face_offsets[f]) as usize
    }

    /// Vertices of face `f` in winding order.
    #[inline]
    pub fn face_vertices(&self, f: usize) -> &[u32] {
        &self.face_vertices[range(&self.face_offsets, f)]
    }

    /// Edges of face `f`: edge `i` joins face vertices `i` and `i + 1`.
    #[inline]
    pub fn face_edges(&self, f: usize) -> &[u32] {
        &self.face_edges[range(&self.face_offsets, f)]
    }

    /// The two vertices of edge `e`, in the direction of the first face that used it.
    #[inline]
    pub fn edge_vertices(&self, e: usize) -> [u32; 2] {
        self.edge_vertices[e]
    }

    /// Faces incident to edge `e`, in face order.
    #[inline]
    pub fn edge_faces(&self, e: usize) -> &[u32] {
        &self.edge_faces[range(&self.edge_face_offsets, e)]
    }

    /// For each face of [`Self::edge_faces`], the position of edge `e` within that face.
    #[inline]
    pub fn edge_face_local_indices(&self, e: usize) -> &[u16] {
        &self.edge_face_local[range(&self.edge_face_offsets, e)]
    }

    /// Faces incident to vertex `v`, counter-clockwise for manifold vertices.
    #[inline]
    pub fn vertex_faces(&self, v: usize) -> &[u32] {
        &self.vertex_faces[range(&self.vertex_face_offsets, v)]
    }

    /// For each face of [`Self::vertex_faces`], the corner of that face at which `v` sits.
    #[inline]
    pub fn vertex_face_local_indices(&self, v: usize) -> &[u16] {
        &self.vertex_face_local[range(&self.vertex_face_offsets, v)]
    }

    /// Edges incident to vertex `v`, counter-clockwise for manifold vertices.
    #[inline]
    pub fn vertex_edges(&self, v: usize) -> &[u32] {
        &self.vertex_edges[range(&self.vertex_edge_offsets, v)]
    }

    /// The end of edge `e` that is not `v` (for a degenerate edge, `v` itself).
    #[inline]
    pub fn edge_other_vertex(&self, e: usize, v: u32) -> u32 {
        let [a, b] = self.edge_vertices[e];
        if a == v { b } else { a }
    }

    /// Valence of `v`: the number of incident edges.
    #[inline]
    pub fn valence(&self, v: usize) -> usize {
        range(&self.vertex_edge_offsets, v).len()
    }

    /// The 1-ring of `v`: the far end of each incident edge, in the ordered edge order
    /// (counter-clockwise for a manifold vertex).
    pub fn vertex_ring(&self, v: usize) -> impl ExactSizeIterator<Item = u32> + '_ {
        let vv = v as u32;
        self.vertex_edges(v)
            .iter()
            .map(move |&e| self.edge_other_vertex(e as usize, vv))
    }

    /// The vertex diagonally opposite corner `corner` of face `f` when `f` is a quad; `None`
    /// for other face sizes. This is where Catmull-Clark limit masks put their face weights.
    #[inline]
    pub fn quad_opposite_vertex(&self, f: usize, corner: usize) -> Option<u32> {
        let fv = self.face_vertices(f);
        (fv.len() == 4).then(|| fv[(corner + 2) % 4])
    }

    /// For each face around `v` (in [`Self::vertex_faces`] order), the vertex diagonally
    /// opposite `v` if that face is a quad.
    pub fn vertex_quad_diagonals(
        &self,
        v: usize,
    ) -> impl ExactSizeIterator<Item = Option<u32>> + '_ {
        self.vertex_faces(v)
            .iter()
            .zip(self.vertex_face_local_indices(v))
            .map(|(&f, &c)| self.quad_opposite_vertex(f as usize, c as usize))
    }

    /// Looks up the edge joining `a` and `b` (either direction). For a pair with several
    /// non-manifold instances, the first one created is returned, as OpenSubdiv does.
    pub fn find_edge(&self, a: u32, b: u32) -> Option<u32> {
        if a as usize >= self.num_vertices() || b as usize >= self.num_vertices() {
            return None;
        }
        self.vertex_edges(a as usize)
            .iter()
            .copied()
            .filter(|&e| {
                let [x, y] = self.edge_vertices[e as usize];
                (x == a && y == b) || (x == b && y == a)
            })
            .min()
    }

    /// `true` when edge `e` has exactly one incident face.
    #[inline]
    pub fn is_boundary_edge(&self, e: usize) -> bool {
        self.edge_flags[e] & EDGE_BOUNDARY != 0
    }

    /// `true` when edge `e` is non-manifold (see [`Topology`]).
    #[inline]
    pub fn is_non_manifold_edge(&self, e: usize) -> bool {
        self.edge_flags[e] & EDGE_NON_MANIFOLD != 0
    }

    /// `true` when both ends of edge `e` are the same vertex.
    #[inline]
    pub fn is_degenerate_edge(&self, e: usize) -> bool {
        self.edge_flags[e] & EDGE_DEGENERATE != 0
    }

    /// `true` when `v` lies on a boundary edge.
    #[inline]
    pub fn is_boundary_vertex(&self, v: usize) -> bool {
        self.vertex_flags[v] & VERTEX_BOUNDARY != 0
    }

    /// `true` when the faces around `v` do not form one fan, or `v` touches a non-manifold
    /// edge. Isolated vertices are reported by [`Self::is_isolated_vertex`] instead.
    #[inline]
    pub fn is_non_manifold_vertex(&self, v: usize) -> bool {
        self.vertex_flags[v] & VERTEX_NON_MANIFOLD != 0
    }

    /// `true` when no face uses `v`.
    #[inline]
    pub fn is_isolated_vertex(&self, v: usize) -> bool {
        self.vertex_flags[v] & VERTEX_ISOLATED != 0
    }

    /// `true` when `v` is a manifold vertex whose number of faces differs from the scheme's
    /// regular count: `regular_valence` in the interior (4 for Catmull-Clark and Bilinear, 6
    /// for Loop) and half of it on a boundary. Non-manifold and isolated vertices are not
    /// called extraordinary, as in OpenSubdiv; OpenSubdiv additionally calls an infinitely
    /// sharp corner with one face regular, which depends on tags and boundary options and is
    /// left to the scheme.
    pub fn is_extraordinary(&self, v: usize, regular_valence: usize) -> bool {
        if self.vertex_flags[v] & (VERTEX_NON_MANIFOLD | VERTEX_ISOLATED) != 0 {
            return false;
        }
        let nf = self.vertex_faces(v).len();
        if self.is_boundary_vertex(v) {
            nf != regular_valence / 2
        } else {
            nf != regular_valence
        }
    }

    /// `true` when the mesh is closed, manifold and smooth: every edge has two faces and two
    /// distinct ends and no crease sharpness, every vertex is used, manifold, with as many
    /// faces as edges and no corner sharpness, and no face is a hole. On such a mesh every
    /// vertex takes its scheme's smooth interior rule wherever its valence allows, so
    /// closed-form shortcuts (fused refinement levels, closed-form limits) apply.
    ///
    /// ```
    /// let torus = subd_mesh::primitives::torus(4, 4, 3.0, 1.0);
    /// assert!(torus.topology.is_closed_and_smooth());
    /// let quad = subd_mesh::TopologyBuilder::new(4).build(&[4], &[0, 1, 2, 3]).unwrap();
    /// assert!(!quad.is_closed_and_smooth());
    /// ```
    pub fn is_closed_and_smooth(&self) -> bool {
        const CHUNK: usize = 4096;
        !self.tags.face_hole.par_iter().any(|&h| h)
            && (0..self.num_edges())
                .into_par_iter()
                .with_min_len(CHUNK)
                .all(|e| {
                    !self.is_degenerate_edge(e)
                        && self.edge_faces(e).len() == 2
                        && self.edge_sharpness(e) == 0.0
                })
            && (0..self.num_vertices())
                .into_par_iter()
                .with_min_len(CHUNK)
                .all(|v| {
                    !self.is_non_manifold_vertex(v)
                        && !self.is_isolated_vertex(v)
                        && self.vertex_sharpness(v) == 0.0
                        && self.vertex_faces(v).len() == self.vertex_edges(v).len()
                })
    }

    /// `true` when the mesh is [closed and smooth](Topology::is_closed_and_smooth), every
    /// face has `face_size` distinct vertices and every vertex has at least 3 faces. On such
    /// a mesh (quads for Catmull-Clark, triangles for Loop) every vertex's limit is its
    /// scheme's classical smooth mask over its one-ring, so limit stencils can be written
    /// straight from the topology.
    ///
    /// ```
    /// let torus = subd_mesh::primitives::torus(4, 4, 3.0, 1.0);
    /// assert!(torus.topology.is_closed_smooth_uniform(4));
    /// assert!(!torus.topology.is_closed_smooth_uniform(3));
    /// ```
    pub fn is_closed_smooth_uniform(&self, face_size: usize) -> bool {
        const CHUNK: usize = 4096;
        (0..self.num_faces())
            .into_par_iter()
            .with_min_len(CHUNK)
            .all(|f| {
                let fv = self.face_vertices(f);
                fv.len() == face_size && (1..fv.len()).all(|k| !fv[..k].contains(&fv[k]))
            })
            && (0..self.num_vertices())
                .into_par_iter()
                .with_min_len(CHUNK)
                .all(|v| self.vertex_faces(v).len() >= 3)
            && self.is_closed_and_smooth()
    }

    /// Tags: crease and corner sharpness, holes.
    #[inline]
    pub fn tags(&self) -> &Tags {
        &self.tags
    }

    /// Crease sharpness of edge `e`.
    #[inline]
    pub fn edge_sharpness(&self, e: usize) -> f32 {
        self.tags.edge_sharpness[e]
    }

    /// Corner sharpness of vertex `v`.
    #[inline]
    pub fn vertex_sharpness(&self, v: usize) -> f32 {
        self.tags.vertex_sharpness[v]
    }

    /// `true` when face `f` is a hole.
    #[inline]
    pub fn is_hole(&self, f: usize) -> bool {
        self.tags.face_hole[f]
    }

    /// Sets the crease sharpness of edge `e` (negative and NaN values become 0, infinity
    /// saturates at `f32::MAX`).
    pub fn set_edge_sharpness(&mut self, e: usize, sharpness: f32) {
        self.tags.edge_sharpness[e] = tags::sanitize(sharpness);
    }

    /// Sets the corner sharpness of vertex `v` (negative and NaN values become 0, infinity
    /// saturates at `f32::MAX`).
    pub fn set_vertex_sharpness(&mut self, v: usize, sharpness: f32) {
        self.tags.vertex_sharpness[v] = tags::sanitize(sharpness);
    }

    /// Replaces every tag at once (edge crease sharpness, vertex corner sharpness, holes),
    /// as a refinement does for a whole level. Sharpness is sanitised as by
    /// [`Self::set_edge_sharpness`].
    ///
    /// # Errors
    /// [`TopologyError::InconsistentEdges`] when a length does not match the topology.
    pub fn set_all_tags(
        &mut self,
        edge_sharpness: Vec<f32>,
        vertex_sharpness: Vec<f32>,
        holes: Vec<bool>,
    ) -> Result<(), TopologyError> {
        if edge_sharpness.len() != self.num_edges()
            || vertex_sharpness.len() != self.num_vertices()
            || holes.len() != self.num_faces()
        {
            return Err(TopologyError::InconsistentEdges {
                face: 0,
                detail: "tag arrays do not match the topology",
            });
        }
        let mut edge_sharpness = edge_sharpness;
        let mut vertex_sharpness = vertex_sharpness;
        edge_sharpness
            .iter_mut()
            .for_each(|s| *s = tags::sanitize(*s));
        vertex_sharpness
            .iter_mut()
            .for_each(|s| *s = tags::sanitize(*s));
        self.tags = Tags {
            edge_sharpness,
            vertex_sharpness,
            face_hole: holes,
        };
        Ok(())
    }

    /// Marks face `f` as a hole or not.
    pub fn set_hole(&mut self, f: usize, hole: bool) {
        self.tags.face_hole[f] = hole;
    }

    /// Face-vertex lists as (sizes, indices), the form the builder takes: handy to rebuild
    /// or to hand to another library.
    pub fn face_sizes(&self) -> impl ExactSizeIterator<Item = u32> + '_ {
        self.face_offsets.windows(2).map(|w| w[1] - w[0])
    }
}

/// Checked tag assignment, as a file reader needs it: indices are validated and sharpness
/// must be finite and non-negative.
impl Topology {
    /// Sets the crease sharpness of the edge joining `a` and `b`. Returns the edge, or
    /// `Ok(None)` when both vertices exist but no edge joins them (OpenSubdiv warns and skips
    /// such a tag).
    pub fn set_crease(
        &mut self,
        a: u64,
        b: u64,
        sharpness: f64,
    ) -> Result<Option<u32>, TopologyError> {
        let nv = self.num_vertices();
        for x in [a, b] {
            if x >= nv as u64 {
                return Err(TopologyError::TagIndexOutOfRange {
                    tag: "crease",
                    what: "vertex",
                    index: x,
                    count: nv,
                });
            }
        }
        check_sharpness("crease", sharpness)?;
        let e = self.find_edge(a as u32, b as u32);
        if let Some(e) = e {
            self.tags.edge_sharpness[e as usize] = tags::sharpness_from_f64(sharpness);
        }
        Ok(e)
    }

    /// Sets the corner sharpness of vertex `v`.
    pub fn set_corner(&mut self, v: u64, sharpness: f64) -> Result<(), TopologyError> {
        let nv = self.num_vertices();
        if v >= nv as u64 {
            return Err(TopologyError::TagIndexOutOfRange {
                tag: "corner",
                what: "vertex",
                index: v,
                count: nv,
            });
        }
        check_sharpness("corner", sharpness)?;
        self.tags.vertex_sharpness[v as usize] = tags::sharpness_from_f64(sharpness);
        Ok(())
    }

    /// Marks face `f` as a hole.
    pub fn set_hole_checked(&mut self, f: u64) -> Result<(), TopologyError> {
        let nf = self.num_faces();
        if f >= nf as u64 {
            return Err(TopologyError::TagIndexOutOfRange {
                tag: "hole",
                what: "face",
                index: f,
                count: nf,
            });
        }
        self.tags.face_hole[f as usize] = true;
        Ok(())
    }
}

fn check_sharpness(tag: &'static str, s: f64) -> Result<(), TopologyError> {
    if s.is_nan() || s < 0.0 || s.is_infinite() {
        return Err(TopologyError::InvalidSharpness { tag, value: s });
    }
    Ok(())
}

/// Every array of a [`Topology`], for code that derives a topology directly (a refinement
/// computes a child level's relations from its parent's in the order OpenSubdiv uses, with no
/// search). The invariants are those [`Topology`] documents: CSR offsets start at 0 and end
/// at the length of their array; `face_edges[i]` joins `face_vertices[i]` and the next
/// vertex of the face; edge-faces and vertex-faces come with the local index of the edge or
/// vertex in each face; vertex-faces and vertex-edges of a manifold vertex are ordered
/// counter-clockwise with `vertex_edges[i]` the edge leaving the vertex in `vertex_faces[i]`.
#[derive(Debug, Clone, Default)]
pub struct TopologyParts {
    /// Number of vertices.
    pub num_vertices: usize,
    /// Face offsets (faces + 1).
    pub face_offsets: Vec<u32>,
    /// Face vertices.
    pub face_vertices: Vec<u32>,
    /// Face edges (parallel to `face_vertices`).
    pub face_edges: Vec<u32>,
    /// Edge vertices.
    pub edge_vertices: Vec<[u32; 2]>,
    /// Edge-face offsets (edges + 1).
    pub edge_face_offsets: Vec<u32>,
    /// Edge faces.
    pub edge_faces: Vec<u32>,
    /// Position of the edge in each of its faces.
    pub edge_face_local: Vec<u16>,
    /// Vertex-face offsets (vertices + 1).
    pub vertex_face_offsets: Vec<u32>,
    /// Vertex faces.
    pub vertex_faces: Vec<u32>,
    /// Corner of the vertex in each of its faces.
    pub vertex_face_local: Vec<u16>,
    /// Vertex-edge offsets (vertices + 1).
    pub vertex_edge_offsets: Vec<u32>,
    /// Vertex edges.
    pub vertex_edges: Vec<u32>,
    /// Per edge: boundary (1 face).
    pub edge_boundary: Vec<bool>,
    /// Per edge: non-manifold.
    pub edge_non_manifold: Vec<bool>,
    /// Per vertex: non-manifold (faces not a single fan).
    pub vertex_non_manifold: Vec<bool>,
    /// Crease sharpness per edge; empty for all smooth.
    pub edge_sharpness: Vec<f32>,
    /// Corner sharpness per vertex; empty for all smooth.
    pub vertex_sharpness: Vec<f32>,
    /// Hole flag per face; empty for none.
    pub face_holes: Vec<bool>,
}

impl Topology {
    /// Assembles a topology from precomputed relations (see [`TopologyParts`]). The lengths
    /// of the arrays are checked; their contents are trusted, with full checks in debug
    /// builds. Degenerate, boundary-vertex and isolated flags are derived here. Tags are taken
    /// from the parts (sanitised as [`Self::set_all_tags`] does); empty tag arrays mean smooth
    /// and no holes.
    ///
    /// # Errors
    /// [`TopologyError::InconsistentEdges`] when the array lengths do not fit together.
    pub fn from_parts(parts: TopologyParts) -> Result<Topology, TopologyError> {
        let nv = parts.num_vertices;
        let nf = parts.face_offsets.len().saturating_sub(1);
        let ne = parts.edge_vertices.len();
        let nh = parts.face_vertices.len();
        let ok = !parts.face_offsets.is_empty()
            && parts.face_offsets.last() == Some(&(nh as u32))
            && parts.face_edges.len() == nh
            && parts.edge_face_offsets.len() == ne + 1
            && parts.edge_faces.len() == *parts.edge_face_offsets.last().unwrap_or(&0) as usize
            && parts.edge_face_local.len() == parts.edge_faces.len()
            && parts.vertex_face_offsets.len() == nv + 1
            && parts.vertex_faces.len() == *parts.vertex_face_offsets.last().unwrap_or(&0) as usize
            && parts.vertex_face_local.len() == parts.vertex_faces.len()
            && parts.vertex_edge_offsets.len() == nv + 1
            && parts.vertex_edges.len() == *parts.vertex_edge_offsets.last().unwrap_or(&0) as usize
            && parts.edge_boundary.len() == ne
            && parts.edge_non_manifold.len() == ne
            && parts.vertex_non_manifold.len() == nv
            && [
                parts.edge_sharpness.len(),
                parts.vertex_sharpness.len(),
                parts.face_holes.len(),
            ]
            .into_iter()
            .zip([ne, nv, nf])
            .all(|(given, n)| given == 0 || given == n)
            && nv < u32::MAX as usize;
        if !ok {
            return Err(TopologyError::InconsistentEdges {
                face: 0,
                detail: "topology parts do not agree in length",
            });
        }
        // Refined levels reach millions of elements: the flags are derived in parallel.
        let mut edge_flags = vec![0u8; ne];
        edge_flags.par_iter_mut().enumerate().for_each(|(e, fl)| {
            let [a, b] = parts.edge_vertices[e];
            *fl = (parts.edge_boundary[e] as u8 * EDGE_BOUNDARY)
                | (parts.edge_non_manifold[e] as u8 * EDGE_NON_MANIFOLD)
                | ((a == b) as u8 * (EDGE_DEGENERATE | EDGE_NON_MANIFOLD));
        });
        let mut vertex_flags = vec![0u8; nv];
        vertex_flags.par_iter_mut().enumerate().for_each(|(v, fl)| {
            *fl = parts.vertex_non_manifold[v] as u8 * VERTEX_NON_MANIFOLD;
            if parts.vertex_face_offsets[v] == parts.vertex_face_offsets[v + 1] {
                *fl |= VERTEX_ISOLATED;
            }
        });
        for (e, &fl) in edge_flags.iter().enumerate() {
            if fl & EDGE_BOUNDARY != 0 {
                let [a, b] = parts.edge_vertices[e];
                vertex_flags[a as usize] |= VERTEX_BOUNDARY;
                vertex_flags[b as usize] |= VERTEX_BOUNDARY;
            }
        }
        let topo = Topology {
            num_vertices: nv as u32,
            face_offsets: parts.face_offsets,
            face_vertices: parts.face_vertices,
            face_edges: parts.face_edges,
            edge_vertices: parts.edge_vertices,
            edge_face_offsets: parts.edge_face_offsets,
            edge_faces: parts.edge_faces,
            edge_face_local: parts.edge_face_local,
            vertex_face_offsets: parts.vertex_face_offsets,
            vertex_faces: parts.vertex_faces,
            vertex_face_local: parts.vertex_face_local,
            vertex_edge_offsets: parts.vertex_edge_offsets,
            vertex_edges: parts.vertex_edges,
            edge_flags,
            vertex_flags,
            tags: Tags::from_parts(
                parts.edge_sharpness,
                parts.vertex_sharpness,
                parts.face_holes,
                (nv, ne, nf),
            ),
        };
        debug_assert!(
            topo.check_relations().is_ok(),
            "{:?}",
            topo.check_relations()
        );
        Ok(topo)
    }

    /// Checks that the relations agree with each other (every face edge joins consecutive
    /// face vertices and lists the face; every vertex face contains the vertex at its local
    /// corner; every vertex edge touches the vertex). Used by tests and debug builds.
    pub fn check_relations(&self) -> Result<(), String> {
        for f in 0..self.num_faces() {
            let fv = self.face_vertices(f);
            for (i, &e) in self.face_edges(f).iter().enumerate() {
                let [a, b] = self.edge_vertices(e as usize);
                let (x, y) = (fv[i], fv[(i + 1) % fv.len()]);
                if !((a == x && b == y) || (a == y && b == x)) {
                    return Err(format!("face {f} edge {i} ({e}) does not join {x} {y}"));
                }
                let ef = self.edge_faces(e as usize);
                let el = self.edge_face_local_indices(e as usize);
                if !ef
                    .iter()
                    .zip(el)
                    .any(|(&g, &l)| g as usize == f && l as usize == i)
                {
                    return Err(format!("edge {e} does not list face {f} at {i}"));
                }
            }
        }
        for v in 0..self.num_vertices() {
            for (&f, &c) in self
                .vertex_faces(v)
                .iter()
                .zip(self.vertex_face_local_indices(v))
            {
                if self.face_vertices(f as usize).get(c as usize) != Some(&(v as u32)) {
                    return Err(format!("vertex {v} face {f} corner {c} mismatch"));
                }
            }
            for &e in self.vertex_edges(v) {
                let [a, b] = self.edge_vertices(e as usize);
                if a as usize != v && b as usize != v {
                    return Err(format!("vertex {v} lists edge {e} ({a}, {b})"));
                }
            }
        }
        Ok(())
    }
}
