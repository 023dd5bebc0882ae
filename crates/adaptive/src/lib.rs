//! Adaptive (selective) refinement for subd: Loop and Catmull-Clark refined only where the
//! surface needs it, without cracks, and without changing the surface.
//!
//! * [`AdaptiveRefinement`] builds a *restricted* hierarchy: per level, the faces of uniform
//!   refinement whose parents were refined, in flat index-based arrays (each face knows its
//!   parent, each vertex and edge its child). A balancing closure refines neighbours so that
//!   faces sharing an edge or a vertex differ by at most one level, and so that refining a
//!   face at level `l` makes every vertex its level-`l` masks read available.
//! * **Exact positions.** Every vertex of the hierarchy is computed by `subd-schemes`'
//!   [`Refinement`](subd_schemes::Refinement) from its complete ring, in the uniform level's
//!   order, so it *is* the vertex of uniform refinement at its level — the same operations,
//!   bit for bit — with creases, semi-sharp decay, corners, boundaries, holes and non-manifold
//!   input treated as uniform refinement treats them. Each element carries its uniform index
//!   ([`AdaptiveMesh::vertex_uniform`]). Selecting every face gives uniform refinement.
//!   Sun et al. 2012 instead leaves "dead" vertices where they are while their neighbours move on:
//!   its adaptive surface is not the Loop surface of the input, and two selections give two
//!   different surfaces. Here the selection decides only how finely the one subdivision
//!   surface is sampled, so results of different criteria can be compared, mixed, and
//!   measured against the limit surface ([`Positions::Limit`] puts every vertex on it).
//! * [`AdaptiveRefinement::mesh`] closes the leaves into a conforming mesh with transition
//!   patterns (a triangle or quad split from the leaf's corners and the edge points of its split edges): every edge has as many faces as it has in uniform refinement,
//!   so a closed input gives a closed, manifold output with no hanging vertex
//!   ([`AdaptiveMesh::conformity`] checks it).
//! * [`criteria`]: Sun et al.'s flatness with its dead vertex / edge / face rules, user face
//!   or vertex selection, Gaussian curvature, dihedral angle and distance to the exact limit
//!   surface, each one type behind the [`Criterion`] trait; they compose by union, under a
//!   level cap.
//!
//! ```
//! use subd_adaptive::{AdaptiveRefinement, Flatness, Positions};
//! use subd_mesh::{DVec3, TopologyBuilder};
//! use subd_schemes::{Options, Scheme};
//!
//! // A cube: refine where it is not flat (everywhere at first, then near the corners).
//! let fv = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4];
//! let cube = TopologyBuilder::new(8).build(&[4; 6], &fv).unwrap();
//! let p: Vec<DVec3> = (0..8)
//!     .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
//!     .collect();
//! let flat = Flatness::new(20.0).unwrap();
//! let a = AdaptiveRefinement::new(&cube, &p, &Scheme::CatmullClark, &Options::default(), &[&flat], 4)
//!     .unwrap();
//! let mesh = a.mesh(Positions::Limit).unwrap();
//! assert!(mesh.num_faces() < 6 * 256); // uniform level 4 has 1536
//! assert!(mesh.conformity().conforming);
//! ```

mod conform;
pub mod criteria;
mod fvar;
mod hierarchy;
mod level;
mod limit;
pub mod report;
pub mod request;

use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;
use subd_limit::LimitError;
use subd_mesh::TopologyBuilder;
use subd_schemes::RefineError;
use thiserror::Error;

pub use criteria::{
    Criterion, DihedralAngle, EveryFace, FaceSelection, Flatness, GaussianCurvature, Judgement,
    LevelView, LimitDistance, LimitSurface, RandomSelection,
};
pub use fvar::AdaptiveFVar;
pub use hierarchy::{AdaptiveRefinement, Positions};

/// The deepest level adaptive refinement goes to (uniform refinement's limit too).
pub const MAX_LEVELS: usize = subd_schemes::MAX_LEVELS;

/// Why adaptive refinement cannot be done.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum AdaptiveError {
    /// The refinement itself failed (Loop on a face that is not a triangle, a mesh too large).
    #[error(transparent)]
    Refine(#[from] RefineError),
    /// A limit computation or evaluation failed.
    #[error(transparent)]
    Limit(#[from] LimitError),
    /// A scheme adaptive refinement has no rules for.
    #[error(
        "adaptive refinement needs catmull-clark, loop or bilinear (the {scheme} scheme has no adaptive hierarchy)"
    )]
    Scheme {
        /// The scheme given.
        scheme: String,
    },
    /// Not one position per base vertex.
    #[error("{given} positions given for {vertices} vertices")]
    PointCount {
        /// Positions given.
        given: usize,
        /// Base vertices.
        vertices: usize,
    },
    /// A threshold out of range or not a number.
    #[error("{name} {value}: {reason}")]
    Threshold {
        /// The criterion.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// A selected face or vertex that the mesh does not have.
    #[error("{what} {index} is out of range (the mesh has {count})")]
    SelectionIndex {
        /// `face` or `vertex`.
        what: &'static str,
        /// The index given.
        index: u64,
        /// How many the mesh has.
        count: usize,
    },
    /// Too many levels.
    #[error("{levels} levels requested; at most {max} are supported")]
    TooManyLevels {
        /// Requested.
        levels: usize,
        /// The maximum.
        max: usize,
    },
    /// An invariant of the hierarchy did not hold (a bug, reported rather than hidden).
    #[error("internal error: {0}")]
    Internal(&'static str),
}

/// Where an edge of the output mesh comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeOrigin {
    /// An edge of uniform refinement (or part of one: a leaf edge that finer levels split).
    Uniform {
        /// Its level.
        level: u8,
        /// Its index in that uniform level.
        index: u64,
        /// The faces it has in uniform refinement.
        faces: u32,
    },
    /// A diagonal a transition pattern adds inside a leaf (two faces).
    Diagonal,
}

/// The conforming mesh of an adaptive refinement.
#[derive(Clone, Debug)]
pub struct AdaptiveMesh {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Unit limit normals (with [`Positions::Limit`]; empty otherwise).
    pub normals: Vec<DVec3>,
    /// Face offsets into [`Self::face_vertices`] (faces + 1).
    pub face_offsets: Vec<u32>,
    /// Face-vertex indices.
    pub face_vertices: Vec<u32>,
    /// Level of each face (a transition face has its leaf's level).
    pub face_levels: Vec<u8>,
    /// Index in uniform refinement at [`Self::face_levels`] of each face's leaf.
    pub face_uniform: Vec<u64>,
    /// Hole flag of each face.
    pub holes: Vec<bool>,
    /// Whether each face is part of a transition pattern.
    pub transition: Vec<bool>,
    /// The level each vertex's position comes from (its finest level in the hierarchy).
    pub vertex_levels: Vec<u8>,
    /// Each vertex's index in uniform refinement at [`Self::vertex_levels`].
    pub vertex_uniform: Vec<u64>,
    /// Origin of the edge from each face-vertex to the next one of its face.
    pub edge_origins: Vec<EdgeOrigin>,
    /// Base face and sub-face (`u16::MAX` for a whole Catmull-Clark base face that is not a
    /// quad) of each face.
    pub face_domains: Vec<(u32, u16)>,
    /// `(u, v)` on the base face of each face-vertex (NaN on a whole non-quad base face).
    pub corner_params: Vec<[f64; 2]>,
}

/// What [`AdaptiveMesh::conformity`] finds.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Conformity {
    /// Every edge of uniform refinement that the mesh uses (or a piece of it) is used by as
    /// many faces as it has in uniform refinement, and every diagonal of a transition
    /// pattern by two: no crack, no hanging vertex.
    pub conforming: bool,
    /// Uniform edges and diagonals that are not.
    pub mismatched_edges: usize,
    /// Edges with one face (of the mesh as a file describes it: edges between the same two
    /// vertices are one).
    pub boundary_edges: usize,
    /// Non-manifold edges.
    pub nonmanifold_edges: usize,
    /// Largest level difference between two faces sharing an edge.
    pub max_level_difference_edge: u8,
    /// Largest level difference between two faces sharing a vertex.
    pub max_level_difference_vertex: u8,
}

/// How many runs of equal values `values` has, once sorted, that `off` says are off.
fn runs_off(mut values: Vec<u64>, off: impl Fn(&[u64]) -> bool) -> usize {
    values.par_sort_unstable();
    values
        .chunk_by(|a, b| a == b)
        .filter(|run| off(run))
        .count()
}

impl AdaptiveMesh {
    /// Number of faces.
    pub fn num_faces(&self) -> usize {
        self.face_offsets.len() - 1
    }

    /// The vertices of face `f`.
    pub fn face(&self, f: usize) -> &[u32] {
        &self.face_vertices[self.face_offsets[f] as usize..self.face_offsets[f + 1] as usize]
    }

    /// Faces per level.
    pub fn faces_per_level(&self) -> Vec<usize> {
        let depth = self.face_levels.iter().copied().max().unwrap_or(0) as usize;
        let mut count = vec![0; depth + 1];
        for &l in &self.face_levels {
            count[l as usize] += 1;
        }
        count
    }

    /// Checks that the mesh is conforming (see [`Conformity`]) and measures level
    /// differences across edges and vertices.
    pub fn conformity(&self) -> Conformity {
        let sizes: Vec<u32> = self.face_offsets.windows(2).map(|w| w[1] - w[0]).collect();
        // The edges alone: the vertex rings a full build would order are not needed here.
        let edges = match TopologyBuilder::new(self.positions.len())
            .accept_inconsistent_orientation(true)
            .edges(&sizes, &self.face_vertices)
        {
            Ok(edges) => edges,
            Err(_) => {
                return Conformity {
                    mismatched_edges: usize::MAX,
                    ..Conformity::default()
                };
            }
        };
        let mut report = Conformity {
            mismatched_edges: self.mismatched_edges(),
            ..Conformity::default()
        };
        let ne = edges.num_edges();
        report.boundary_edges = (0..ne).filter(|&e| edges.is_boundary_edge(e)).count();
        report.nonmanifold_edges = (0..ne).filter(|&e| edges.is_non_manifold_edge(e)).count();
        report.max_level_difference_edge = self.level_spread(edges.face_edges(), ne);
        report.max_level_difference_vertex =
            self.level_spread(&self.face_vertices, self.positions.len());
        report.conforming = report.mismatched_edges == 0;
        report
    }

    /// The largest difference between the levels of two faces that share an element, each
    /// face-vertex naming the element (of `count`) it puts its face at.
    fn level_spread(&self, element_of_corner: &[u32], count: usize) -> u8 {
        let mut lowest = vec![u8::MAX; count];
        let mut highest = vec![0u8; count];
        for f in 0..self.num_faces() {
            let level = self.face_levels[f];
            let corners = self.face_offsets[f] as usize..self.face_offsets[f + 1] as usize;
            for &x in &element_of_corner[corners] {
                lowest[x as usize] = lowest[x as usize].min(level);
                highest[x as usize] = highest[x as usize].max(level);
            }
        }
        // An element no face uses has lowest > highest: no spread.
        lowest
            .iter()
            .zip(&highest)
            .map(|(&lo, &hi)| hi.saturating_sub(lo))
            .max()
            .unwrap_or(0)
    }

    /// Uniform edges (or pieces of one) used by another number of face sides than the faces
    /// they have in uniform refinement — one side short is a crack or a hanging vertex — and
    /// transition diagonals not used twice. Counted per origin, not per vertex pair, since
    /// uniform refinement itself can have two edges between the same two vertices (two
    /// faces on the same three vertices, refined). Sorted runs rather than hashing: the
    /// count does not depend on the order.
    fn mismatched_edges(&self) -> usize {
        let diagonals: Vec<u64> = (0..self.num_faces())
            .into_par_iter()
            .with_min_len(4096)
            .flat_map_iter(|f| {
                let (fv, first) = (self.face(f), self.face_offsets[f] as usize);
                (0..fv.len())
                    .filter(move |&i| self.edge_origins[first + i] == EdgeOrigin::Diagonal)
                    .map(move |i| {
                        let (a, b) = (fv[i], fv[(i + 1) % fv.len()]);
                        (u64::from(a.min(b)) << 32) | u64::from(a.max(b))
                    })
            })
            .collect();
        let diagonals_off = runs_off(diagonals, |run| run.len() % 2 != 0);
        diagonals_off + self.mismatched_uniform_edges()
    }

    /// The uniform part of [`Self::mismatched_edges`]: each side's (level, index, faces)
    /// packed into one `u64` (4 + 52 + 8 bits), so the sort moves half the bytes of the
    /// tuples; tuples where a value does not fit.
    fn mismatched_uniform_edges(&self) -> usize {
        let uniform = || {
            self.edge_origins.par_iter().filter_map(|o| match *o {
                EdgeOrigin::Uniform {
                    level,
                    index,
                    faces,
                } => Some((level, index, faces)),
                EdgeOrigin::Diagonal => None,
            })
        };
        // One pass: `None` as soon as a value does not fit.
        let packed: Option<Vec<u64>> = uniform()
            .map(|(l, i, f)| {
                (l < 16 && i < 1 << 52 && f < 255)
                    .then(|| (u64::from(l) << 60) | (i << 8) | u64::from(f))
            })
            .collect();
        if let Some(packed) = packed {
            return runs_off(packed, |run| run.len() as u64 != run[0] & 0xff);
        }
        let mut uses: Vec<(u8, u64, u32)> = uniform().collect();
        uses.par_sort_unstable();
        uses.chunk_by(|a, b| (a.0, a.1) == (b.0, b.1))
            .filter(|run| run.len() != run[0].2 as usize)
            .count()
    }

    /// The smallest angle of any face that is not a hole, in degrees.
    pub fn min_angle_degrees(&self) -> f64 {
        let cos = (0..self.num_faces())
            .into_par_iter()
            .filter(|&f| !self.holes[f])
            .map(|f| {
                let face = self.face(f);
                // Faces here are triangles and quads but for whole n-gons of the base.
                let mut small = [DVec3::ZERO; 4];
                let large: Vec<DVec3>;
                let p = if face.len() <= small.len() {
                    for (q, &v) in small.iter_mut().zip(face) {
                        *q = self.positions[v as usize];
                    }
                    &small[..face.len()]
                } else {
                    large = face.iter().map(|&v| self.positions[v as usize]).collect();
                    &large
                };
                conform::max_corner_cos(p)
            })
            .reduce(|| f64::NEG_INFINITY, f64::max);
        if cos == f64::NEG_INFINITY {
            return f64::INFINITY; // no face
        }
        // acos decreases: one acos for the whole mesh instead of one per corner.
        cos.acos().to_degrees()
    }

    /// The largest sampled distance of any face that is not a hole to the limit surface,
    /// at the same parameters ([`LimitSurface::face_distance`]).
    ///
    /// # Errors
    /// As [`LimitSurface::position`].
    pub fn max_limit_distance(&self, surface: &LimitSurface) -> Result<f64, AdaptiveError> {
        self.max_limit_distance_of(surface, |_| true)
    }

    /// [`Self::max_limit_distance`] over the faces `f` with `faces(f)` only (0 for none).
    ///
    /// # Errors
    /// As [`LimitSurface::position`].
    pub fn max_limit_distance_of(
        &self,
        surface: &LimitSurface,
        faces: impl Fn(usize) -> bool + Sync,
    ) -> Result<f64, AdaptiveError> {
        (0..self.num_faces())
            .into_par_iter()
            .filter(|&f| !self.holes[f] && faces(f))
            .map(|f| self.face_distance(surface, f))
            .try_reduce(|| 0.0, |a, b| Ok(a.max(b)))
    }

    /// The largest sampled distance of face `f` to the limit surface.
    ///
    /// # Errors
    /// As [`LimitSurface::position`].
    pub fn face_distance(&self, surface: &LimitSurface, f: usize) -> Result<f64, AdaptiveError> {
        let range = self.face_offsets[f] as usize..self.face_offsets[f + 1] as usize;
        let p: Vec<DVec3> = self.face_vertices[range.clone()]
            .iter()
            .map(|&v| self.positions[v as usize])
            .collect();
        let (face, sub) = self.face_domains[f];
        if sub == u16::MAX {
            surface.polygon_distance(face as usize, &p)
        } else {
            surface.face_distance(face as usize, sub as usize, &p, &self.corner_params[range])
        }
    }
}

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
