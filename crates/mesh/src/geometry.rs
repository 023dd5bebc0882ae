//! Geometry kept beside the topology: [`Mesh`] and coordinate validation.

use glam::DVec3;

use crate::error::TopologyError;
use crate::fvar::{FVarChannel, FVarError};
use crate::tags::SchemeHints;
use crate::topology::Topology;

/// A topology with its vertex positions and the scheme options its file asked for.
///
/// Positions are a plain `Vec<DVec3>` indexed by vertex, separate from the topology, so that
/// any other per-vertex data (UVs, colours, animation frames) can be handled the same way.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// Adjacency and tags.
    pub topology: Topology,
    /// One position per topology vertex.
    pub positions: Vec<DVec3>,
    /// Scheme options requested by the source file, if any.
    pub hints: SchemeHints,
    /// Face-varying channels made for `topology`; the first is the texture coordinates
    /// (OBJ `vt`, glTF `TEXCOORD_0`, PLY `u v`) when the file has them.
    pub fvar: Vec<FVarChannel>,
}

impl Mesh {
    /// Pairs a topology with positions, checking that the counts agree and that every
    /// coordinate is finite.
    pub fn new(topology: Topology, positions: Vec<DVec3>) -> Result<Self, TopologyError> {
        if positions.len() != topology.num_vertices() {
            return Err(TopologyError::PositionCountMismatch {
                positions: positions.len(),
                vertices: topology.num_vertices(),
            });
        }
        validate_positions(&positions)?;
        Ok(Mesh {
            topology,
            positions,
            hints: SchemeHints::default(),
            fvar: Vec::new(),
        })
    }

    /// Adds a face-varying channel, checking that it has one index per face-vertex of the
    /// topology (the channel checked its values and index range when it was made).
    ///
    /// # Errors
    /// [`FVarError::IndexCount`] when the channel was made for another topology.
    pub fn with_fvar(mut self, channel: FVarChannel) -> Result<Self, FVarError> {
        if channel.indices().len() != self.topology.num_face_vertices() {
            return Err(FVarError::IndexCount {
                given: channel.indices().len(),
                expected: self.topology.num_face_vertices(),
            });
        }
        self.fvar.push(channel);
        Ok(self)
    }

    /// The texture coordinates: the first face-varying channel, if any.
    pub fn uv(&self) -> Option<&FVarChannel> {
        self.fvar.first()
    }

    /// Axis-aligned bounding box of the positions of the vertices that faces use, or `None`
    /// when no face uses any vertex.
    pub fn bounding_box(&self) -> Option<(DVec3, DVec3)> {
        bounding_box(
            self.positions
                .iter()
                .enumerate()
                .filter(|(v, _)| !self.topology.is_isolated_vertex(*v))
                .map(|(_, p)| *p),
        )
    }
}

/// Rejects NaN or infinite coordinates, naming the first offending vertex.
pub fn validate_positions(positions: &[DVec3]) -> Result<(), TopologyError> {
    match positions.iter().position(|p| !p.is_finite()) {
        None => Ok(()),
        Some(v) => {
            let p = positions[v];
            Err(TopologyError::NonFiniteCoordinate {
                vertex: v,
                x: p.x,
                y: p.y,
                z: p.z,
            })
        }
    }
}

/// Axis-aligned bounding box of a set of points, `None` when empty.
pub fn bounding_box(points: impl IntoIterator<Item = DVec3>) -> Option<(DVec3, DVec3)> {
    points.into_iter().fold(None, |acc, p| match acc {
        None => Some((p, p)),
        Some((lo, hi)) => Some((lo.min(p), hi.max(p))),
    })
}
