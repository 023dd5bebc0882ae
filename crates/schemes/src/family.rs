//! The seam between [`Refinement`](crate::Refinement) and the two families of schemes behind
//! it.
//!
//! A family is a way of splitting a level plus the masks of its schemes:
//!
//! * OpenSubdiv's family (`refine`): Catmull-Clark, Loop, Bilinear and the two-phase scheme,
//!   with OpenSubdiv's vertex order, crease semantics, vertex rules and options;
//! * the split family (`split_schemes`): Doo-Sabin, √3 and the butterflies, each a rule file
//!   that gives a level's child faces and the mask of every child vertex.
//!
//! [`Family`] is what a family implements; the front type only checks requests and forwards.

use std::borrow::Cow;
use std::fmt::Debug;

use glam::DVec3;
use subd_mesh::Topology;

use crate::refine::OsdRefinement;
use crate::rules::Rule;
use crate::stencil::StencilTable;
use crate::{ExplicitTags, FaceStream, PointStream};

/// A refinement of a family of schemes: the levels it has built and the masks between them.
/// Level 0 is the base mesh with the family's boundary rules applied to its tags.
pub(crate) trait Family: Debug + Send + Sync {
    /// Number of refined levels.
    fn num_levels(&self) -> usize;
    /// Vertices of `level`, without building its topology.
    fn num_vertices(&self, level: usize) -> usize;
    /// Edges of `level` where the family counts them without building the level.
    fn num_edges(&self, level: usize) -> Option<usize>;
    /// Face offsets and face vertices of `level`.
    fn faces(&self, level: usize) -> (&[u32], &[u32]);
    /// Hole flags of the faces of `level`.
    fn holes(&self, level: usize) -> Cow<'_, [bool]>;
    /// Whether any edge or vertex of `level` has a sharpness above zero.
    fn has_sharpness(&self, level: usize) -> bool;
    /// The crease and corner tags of `level` that a file must carry.
    fn explicit_tags(&self, level: usize) -> ExplicitTags;
    /// The full topology of `level`, built on first request.
    fn topology(&self, level: usize) -> &Topology;
    /// Whether the full topology of `level` is built.
    fn has_topology(&self, level: usize) -> bool;
    /// The topology of `level`, taken out of the refinement.
    fn into_topology(self: Box<Self>, level: usize) -> Topology;
    /// The rule of every vertex of `level`.
    fn vertex_rules(&self, level: usize) -> &[Rule];
    /// Stencils from `level - 1` to `level`, built on first request.
    fn stencils(&self, level: usize) -> &StencilTable;
    /// Points of `level` from the points of `level - 1`.
    fn next_points(&self, level: usize, above: &[DVec3]) -> Vec<DVec3>;
    /// The last level's faces a range at a time, where the family streams them.
    fn face_stream(&self) -> Option<FaceStream<'_>>;
    /// The last level's points a range at a time, where the family streams them.
    fn point_stream<'a>(&'a self, above: &'a [DVec3]) -> Option<PointStream<'a>>;
    /// OpenSubdiv's family, for what only it has (face-varying modes, vertex rules of
    /// prepared levels).
    fn as_opensubdiv(&self) -> Option<&OsdRefinement> {
        None
    }
}

/// OpenSubdiv's family: the trait forwarded to [`OsdRefinement`]'s own methods.
impl Family for OsdRefinement {
    fn num_levels(&self) -> usize {
        OsdRefinement::num_levels(self)
    }
    fn num_vertices(&self, level: usize) -> usize {
        OsdRefinement::num_vertices(self, level)
    }
    fn num_edges(&self, level: usize) -> Option<usize> {
        Some(OsdRefinement::num_edges(self, level))
    }
    fn faces(&self, level: usize) -> (&[u32], &[u32]) {
        OsdRefinement::faces(self, level)
    }
    fn holes(&self, level: usize) -> std::borrow::Cow<'_, [bool]> {
        std::borrow::Cow::Borrowed(OsdRefinement::holes(self, level))
    }
    fn has_sharpness(&self, level: usize) -> bool {
        OsdRefinement::has_sharpness(self, level)
    }
    fn explicit_tags(&self, level: usize) -> ExplicitTags {
        OsdRefinement::explicit_tags(self, level)
    }
    fn topology(&self, level: usize) -> &Topology {
        OsdRefinement::topology(self, level)
    }
    fn has_topology(&self, level: usize) -> bool {
        OsdRefinement::has_topology(self, level)
    }
    fn into_topology(self: Box<Self>, level: usize) -> Topology {
        OsdRefinement::into_topology(*self, level)
    }
    fn vertex_rules(&self, level: usize) -> &[Rule] {
        OsdRefinement::vertex_rules(self, level)
    }
    fn stencils(&self, level: usize) -> &StencilTable {
        OsdRefinement::stencils(self, level)
    }
    fn next_points(&self, level: usize, above: &[DVec3]) -> Vec<DVec3> {
        OsdRefinement::next_points(self, level, above)
    }
    fn face_stream(&self) -> Option<FaceStream<'_>> {
        OsdRefinement::face_stream(self)
    }
    fn point_stream<'a>(&'a self, above: &'a [DVec3]) -> Option<PointStream<'a>> {
        OsdRefinement::point_stream(self, above)
    }
    fn as_opensubdiv(&self) -> Option<&OsdRefinement> {
        Some(self)
    }
}
