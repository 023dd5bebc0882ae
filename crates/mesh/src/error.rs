//! Errors and warnings raised while building or validating a mesh.

use thiserror::Error;

/// Why a face-vertex list, a tag or a coordinate was rejected.
///
/// Every variant names the offending element (face, corner, vertex or edge index, all 0-based)
/// so that a caller can print a one-line message a user can act on.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum TopologyError {
    /// The face sizes do not add up to the number of face-vertex indices given.
    #[error("face sizes add up to {expected} face-vertex indices but {actual} were given")]
    FaceVertexCountMismatch {
        /// Sum of the face sizes.
        expected: usize,
        /// Length of the face-vertex index list.
        actual: usize,
    },
    /// A face has fewer than three vertices.
    #[error("face {face} has {size} vertices; a face needs at least 3")]
    FaceTooSmall {
        /// Face index.
        face: usize,
        /// Number of vertices the face was given.
        size: usize,
    },
    /// A face has more vertices than local indices can address (OpenSubdiv's
    /// `Vtr::VALENCE_LIMIT`, 16-bit local indices).
    #[error("face {face} has {size} vertices; a face may have at most {max}")]
    FaceTooLarge {
        /// Face index.
        face: usize,
        /// Number of vertices the face was given.
        size: usize,
        /// The limit, [`crate::MAX_FACE_SIZE`].
        max: usize,
    },
    /// A face refers to a vertex that does not exist.
    #[error(
        "face {face} corner {corner} refers to vertex {index}, but there are only {num_vertices} vertices"
    )]
    VertexIndexOutOfRange {
        /// Face index.
        face: usize,
        /// Position of the index within the face.
        corner: usize,
        /// The offending vertex index.
        index: u64,
        /// Number of vertices of the mesh.
        num_vertices: usize,
    },
    /// Two faces traverse a shared edge in the same direction, i.e. their windings disagree.
    #[error(
        "faces {first_face} and {second_face} both traverse edge ({v0}, {v1}) in the same direction (inconsistent orientation)"
    )]
    InconsistentOrientation {
        /// Face that introduced the edge.
        first_face: usize,
        /// Face that traverses it again in the same direction.
        second_face: usize,
        /// First vertex of the directed edge.
        v0: u32,
        /// Second vertex of the directed edge.
        v1: u32,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate ({x}, {y}, {z})")]
    NonFiniteCoordinate {
        /// Vertex index.
        vertex: usize,
        /// x coordinate.
        x: f64,
        /// y coordinate.
        y: f64,
        /// z coordinate.
        z: f64,
    },
    /// The number of positions differs from the number of topology vertices.
    #[error("{positions} positions given for a topology of {vertices} vertices")]
    PositionCountMismatch {
        /// Number of positions.
        positions: usize,
        /// Number of topology vertices.
        vertices: usize,
    },
    /// The mesh is too large for 32-bit indices.
    #[error("{what} count {count} exceeds the 32-bit index range")]
    TooLarge {
        /// Which element kind overflowed.
        what: &'static str,
        /// The count that overflowed.
        count: usize,
    },
    /// A tag names a vertex, edge or face that does not exist.
    #[error("{tag} tag names {what} {index}, but there are only {count}")]
    TagIndexOutOfRange {
        /// The tag kind (`crease`, `corner`, `hole`).
        tag: &'static str,
        /// What the index refers to (`vertex`, `face`).
        what: &'static str,
        /// The offending index.
        index: u64,
        /// Number of elements of that kind.
        count: usize,
    },
    /// Pre-numbered edges given to [`crate::Topology::from_numbered_edges`] do not match the
    /// faces.
    #[error("face {face}: {detail}")]
    InconsistentEdges {
        /// Face index.
        face: usize,
        /// What does not match.
        detail: &'static str,
    },
    /// A sharpness value is negative or not a number.
    #[error("{tag} tag has invalid sharpness {value}; sharpness must be a finite number >= 0")]
    InvalidSharpness {
        /// The tag kind (`crease`, `corner`).
        tag: &'static str,
        /// The offending value.
        value: f64,
    },
}

/// Something unusual about the input that is accepted (as OpenSubdiv accepts it) but worth
/// telling the user about.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum BuildWarning {
    /// A face lists the same vertex more than once; its degenerate or repeated edges become
    /// non-manifold edges, as in OpenSubdiv.
    RepeatedVertex {
        /// Face index.
        face: usize,
        /// The repeated vertex.
        vertex: u32,
    },
    /// Two faces traverse an edge in the same direction; accepted on request and the edge is
    /// then treated as non-manifold.
    InconsistentOrientation {
        /// Face that introduced the edge.
        first_face: usize,
        /// Face that traverses it again in the same direction.
        second_face: usize,
        /// First vertex of the directed edge.
        v0: u32,
        /// Second vertex of the directed edge.
        v1: u32,
    },
}

impl std::fmt::Display for BuildWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BuildWarning::RepeatedVertex { face, vertex } => write!(
                f,
                "face {face} repeats vertex {vertex}; its repeated edges are treated as non-manifold"
            ),
            BuildWarning::InconsistentOrientation {
                first_face,
                second_face,
                v0,
                v1,
            } => write!(
                f,
                "faces {first_face} and {second_face} both traverse edge ({v0}, {v1}) in the same direction; the edge is treated as non-manifold"
            ),
        }
    }
}
