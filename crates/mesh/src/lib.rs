//! Polygon-mesh topology for subdivision surfaces.
//!
//! `subd-mesh` turns face-vertex lists into a [`Topology`]: flat compressed-sparse-row arrays
//! of every adjacency a subdivision scheme needs (face→vertices, face→edges, edge→vertices,
//! edge→faces, vertex→faces and vertex→edges ordered around the vertex), boundary and
//! non-manifold flags, and the tags OpenSubdiv uses (crease sharpness per edge, corner
//! sharpness per vertex, holes). It holds no geometry rules: schemes live in `subd-schemes`.
//!
//! * Edges are numbered as OpenSubdiv numbers them, so an edge index means the same thing in
//!   both libraries; non-manifold input (edges with more than two faces, faces that repeat a
//!   vertex, bow-tie vertices) is flagged, not rejected.
//! * The build is linear in the mesh size (counting sorts instead of hashing) and allocates a
//!   fixed number of flat arrays, never one per element.
//! * Geometry (`glam::DVec3`, `f64`) lives beside the topology in [`Mesh`].
//!
//! ```
//! use subd_mesh::{TopologyBuilder, TopologySummary};
//!
//! // A cube: 8 vertices, 6 quads.
//! let faces = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4];
//! let topo = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
//! assert_eq!(topo.num_edges(), 12);
//! assert_eq!(topo.valence(0), 3);
//! assert!(topo.is_extraordinary(0, 4));
//! let summary = TopologySummary::new(&topo);
//! assert_eq!((summary.euler, summary.genus), (2, Some(0)));
//! ```

pub mod analysis;
mod build;
pub mod canonical;
pub mod choice;
pub mod csr;
pub mod cut;
pub mod error;
pub mod fvar;
pub mod geometry;
pub mod memory;
pub mod neighbourhood;
pub mod primitives;
pub mod report;
pub mod tags;
mod topology;

pub use analysis::{Component, TopologySummary};
pub use build::{FaceEdges, TopologyBuilder};
pub use error::{BuildWarning, TopologyError};
pub use geometry::{Mesh, bounding_box, validate_positions};
pub use glam::DVec3;
pub use tags::{
    BoundaryInterpolation, CreaseMethod, FileScheme, SchemeHints, Tags, TriangleSubdivision,
};
pub use topology::{MAX_FACE_SIZE, Topology, TopologyParts};

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
