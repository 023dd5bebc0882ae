//! Subdivision rules for subd: every surface scheme behind one [`Scheme`] and one
//! [`Refinement`].
//!
//! | [`Scheme`] | input | split | family |
//! |---|---|---|---|
//! | `CatmullClark`, `Bilinear` | any polygons | quads, 1 → n | OpenSubdiv's |
//! | `Loop` | triangles | 1 → 4 | OpenSubdiv's |
//! | `TwoPhase` (Lin et al.) | quads | quads | OpenSubdiv's (phase 1, then Catmull-Clark) |
//! | `DooSabin` | any polygons | dual | split |
//! | `Sqrt3` | triangles | 1 → 3 with edge flips | split |
//! | `Butterfly { tension }`, `ModifiedButterfly` | triangles | 1 → 4 | split |
//!
//! OpenSubdiv's family reproduces Pixar's OpenSubdiv (Far/Vtr/Sdc 3.5): the same vertex, face
//! and face-vertex order, the same crease semantics (infinitely sharp and semi-sharp creases
//! decaying in `f32`, uniform and Chaikin crease methods, corners, holes, the three boundary
//! interpolation modes, non-manifold edges and vertices), and positions within 1e-12 of
//! OpenSubdiv run in double precision. The split family ([`split_schemes`]) holds the
//! schemes of the subdivision lecture notes that OpenSubdiv does not have.
//!
//! Refinement is data: [`Refinement::new`] computes the topology of every level and a
//! [`StencilTable`] per level (child vertices as weighted sums of parent vertices), which
//! [`Refinement::composed`] chains into one table from the base mesh to any level. Apply a
//! table to positions, UVs, colours or every frame of an animation.
//!
//! # What a scheme implements
//!
//! A scheme is a split plus masks. Behind [`Refinement`] each family implements one
//! crate-private trait (`Family`: the level's faces and tags, the topology on request, the
//! stencils between levels, direct evaluation of points). A split scheme is one rule file in
//! [`split_schemes`] implementing its `SplitRule` (for one step over a parent level: the
//! child faces with the tags they keep, and a row of weights over parent vertices for each
//! child vertex) plus its [`Scheme`] variant: `Scheme::split_step` makes the step, and the
//! variant's methods state the facts every caller needs ([`Scheme::input_faces`],
//! [`Scheme::split`], [`Scheme::period`], [`Scheme::is_interpolating`], [`Scheme::tags`],
//! [`Scheme::regular_valence`], [`Scheme::peak_bytes_per_vertex`]). Levels, stencil tables,
//! points, face-varying channels ([`Refinement::face_varying`]), counts
//! ([`refined_counts`]) and the memory estimate ([`peak::PeakModel`]) then work for it
//! unchanged; its limit masks go in `subd-limit`.
//!
//! # Ordering (OpenSubdiv's default uniform order)
//!
//! * Vertices of level L+1: the children of level-L vertices first, in vertex order (so base
//!   vertex `v` is vertex `v` at every level), then the children of faces (Catmull-Clark and
//!   Bilinear only), in face order, then the children of edges, in edge order.
//! * Faces: the children of each parent face are consecutive. A quad's child `j` keeps the
//!   parent's orientation and has the parent corner at position `j`:
//!   `(V0, E0, F, E3)`, `(E0, V1, E1, F)`, `(F, E1, V2, E2)`, `(E3, F, E2, V3)`; a face of
//!   another size n gives `(Vk, Ek, F, Ek-1)` for k in 0..n; a Loop triangle gives
//!   `(V0, E0, E2)`, `(E0, V1, E1)`, `(E2, E1, V2)`, `(E1, E2, E0)`.
//! * Edges: the edges interior to each parent face, then the two halves of each parent edge;
//!   base-level edges are numbered by first appearance (see `subd-mesh`).
//!
//! ```
//! use subd_mesh::{DVec3, TopologyBuilder};
//! use subd_schemes::{Options, Refinement, Scheme};
//!
//! // A cube, refined twice with Catmull-Clark.
//! let faces = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4];
//! let topo = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
//! let r = Refinement::new(&topo, Scheme::CatmullClark, &Options::default(), 2).unwrap();
//! assert_eq!(r.topology(2).num_faces(), 96);
//! let cube: Vec<DVec3> = (0..8)
//!     .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
//!     .collect();
//! let level2 = r.composed(2).apply_points(&cube);
//! assert_eq!(level2.len(), r.topology(2).num_vertices());
//! ```

pub mod analysis;
pub mod curve;
mod face_varying;
mod facts;
mod family;
pub mod named_curve;
pub mod peak;
mod refine;
mod refinement;
pub mod rules;
mod scheme;
pub mod split_schemes;
pub mod stencil;
pub mod two_phase;

use subd_mesh::{BoundaryInterpolation, CreaseMethod, SchemeHints, TriangleSubdivision};
use thiserror::Error;

pub use face_varying::FaceVarying;
pub use facts::{Capability, FaceKind, SchemeFacts, Split, TagSupport};
pub use refine::{
    ChildLayout, ChunkLevel, DepthFirst, FVarLevelState, FVarLevelValues, FVarPatchTag,
    FVarValueKind, FaceStream, FaceVaryingRefinement, LevelCounts, PointStream, refined_counts,
};
pub use refinement::Refinement;
pub use rules::Rule;
pub use scheme::{ParseSchemeError, Scheme};
pub use split_schemes::SplitFaceVarying;
pub use stencil::{RowSink, StencilTable};
pub use two_phase::TwoPhase;

/// The most levels a refinement may ask for (OpenSubdiv's limit too).
pub const MAX_LEVELS: usize = 15;

/// The sharpness of a refined level as a mesh file records it: every edge (as its two end
/// vertices) and every vertex with a sharpness above zero, in edge and vertex order, except
/// what the boundary rules imply and any reader applies again — boundary and non-manifold
/// edges, non-manifold and isolated vertices, and one-face corners under edge-and-corner
/// interpolation ([`Refinement::explicit_tags`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ExplicitTags {
    /// Crease tags: end vertices and sharpness.
    pub creases: Vec<([u32; 2], f32)>,
    /// Corner tags: vertex and sharpness.
    pub corners: Vec<(u32, f32)>,
}

/// Scheme options, as OpenSubdiv's `Sdc::Options`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Options {
    /// Boundary interpolation (default edge-only).
    pub boundary_interpolation: BoundaryInterpolation,
    /// Crease decay method (default uniform).
    pub crease_method: CreaseMethod,
    /// Catmull-Clark triangle rule (default the plain Catmark masks).
    pub triangle_subdivision: TriangleSubdivision,
}

impl Options {
    /// Options a mesh file asked for, defaults where it is silent.
    pub fn from_hints(hints: &SchemeHints) -> Options {
        Options {
            boundary_interpolation: hints.boundary_interpolation.unwrap_or_default(),
            crease_method: hints.crease_method.unwrap_or_default(),
            triangle_subdivision: hints.triangle_subdivision.unwrap_or_default(),
        }
    }
}

/// Why a refinement cannot be done.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum RefineError {
    /// The scheme needs triangles (Loop, √3, the butterflies).
    #[error("face {face} has {size} vertices; the {scheme} scheme needs triangles")]
    NotTriangle {
        /// The scheme's name.
        scheme: &'static str,
        /// Face index.
        face: usize,
        /// Its size.
        size: usize,
    },
    /// Too many levels.
    #[error("{levels} levels requested; at most {max} are supported")]
    TooManyLevels {
        /// Requested levels.
        levels: usize,
        /// The maximum.
        max: usize,
    },
    /// A prepared level was given a rule list of the wrong length.
    #[error("{rules} vertex rules given for {vertices} vertices")]
    RuleCount {
        /// Rules given.
        rules: usize,
        /// Vertices of the level.
        vertices: usize,
    },
    /// A two-phase shape parameter that is out of range or not a number.
    #[error("vertex {vertex}: lambda {value} is {reason}")]
    Lambda {
        /// Base vertex.
        vertex: usize,
        /// Its `λ`.
        value: f64,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// A two-phase scheme named without its `λ` ([`TwoPhase::unset`]).
    #[error("the two-phase scheme needs lambda (one for every vertex, or one per vertex)")]
    MissingLambda,
    /// A two-phase refinement given a `λ` list of the wrong length.
    #[error("{given} lambda values given for {vertices} vertices")]
    LambdaCount {
        /// Values given.
        given: usize,
        /// Base vertices.
        vertices: usize,
    },
    /// The two-phase scheme needs quads.
    #[error("face {face} has {size} vertices; the two-phase scheme needs quads")]
    NotQuad {
        /// Face index.
        face: usize,
        /// Its size.
        size: usize,
    },
    /// The refined mesh would not fit 32-bit indices.
    #[error("level {level} would have more than 2^32 face-vertices")]
    TooLarge {
        /// The level that overflows.
        level: usize,
    },
    /// A non-manifold edge, which the split schemes have no rule for.
    #[error("edge {edge} ({a}-{b}) is non-manifold; the {scheme} scheme needs a manifold mesh")]
    NonManifoldEdge {
        /// The scheme's name.
        scheme: &'static str,
        /// Edge index.
        edge: usize,
        /// Its end vertices.
        a: u32,
        /// Its end vertices.
        b: u32,
    },
    /// A non-manifold vertex (faces around it that are not one fan).
    #[error("vertex {vertex} is non-manifold; the {scheme} scheme needs a manifold mesh")]
    NonManifoldVertex {
        /// The scheme's name.
        scheme: &'static str,
        /// Vertex index.
        vertex: usize,
    },
    /// A tag the scheme has no rule for (see [`Scheme::tags`]).
    #[error("{what}: the {scheme} scheme {why}")]
    UnsupportedTag {
        /// The scheme's name.
        scheme: &'static str,
        /// The tagged element, e.g. `edge 4 (1-2)`.
        what: String,
        /// Why it cannot be used.
        why: &'static str,
    },
    /// A butterfly tension that is not a finite number.
    #[error("tension {0} is not a finite number")]
    Tension(f64),
    /// A feature the scheme does not have.
    #[error("the {scheme} scheme: {what}")]
    Unsupported {
        /// The scheme, as [`Scheme`]'s `Display` writes it.
        scheme: String,
        /// What is missing.
        what: &'static str,
    },
    /// Building a refined level's topology failed (a bug if it ever happens).
    #[error("level {level}: {source}")]
    Topology {
        /// The level.
        level: usize,
        /// What the topology builder said.
        source: subd_mesh::TopologyError,
    },
    /// The memory for a level could not be allocated (an address-space limit, or the
    /// system's memory): the request is refused before anything is written, instead of the
    /// process aborting part-way.
    #[error("level {level} needs about {} more memory, which cannot be allocated", subd_mesh::memory::human_bytes(*bytes))]
    OutOfMemory {
        /// The level that does not fit.
        level: usize,
        /// About how many bytes it needs.
        bytes: u64,
    },
}

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
