//! A level's face-varying state carried to a piece of that level: adaptive refinement
//! refines pieces of a level one step at a time, and each piece's values must be refined
//! with the tags the values have at that level (inherited from the levels above, as
//! OpenSubdiv's `Vtr::FVarRefinement` passes them down), not with tags found afresh from the
//! piece as if it were a base mesh: the two part where a value's tag depends on its history
//! (semi-sharp values, siblings of a non-manifold vertex that share a value).

use subd_mesh::Topology;
use subd_mesh::fvar::{FVarError, FVarLinearInterpolation};

use super::{ChannelLevel, FaceVaryingRefinement, ModeFlags};
use crate::Refinement;

/// One level of a face-varying refinement: its values (one per vertex and sibling), the
/// value of every face corner, each value's tags and each edge's seams, and the mode they
/// were found with ([`FaceVaryingRefinement::level_state`]).
#[derive(Debug, Clone)]
pub struct FVarLevelState {
    level: ChannelLevel,
    mode: FVarLinearInterpolation,
}

impl FVarLevelState {
    /// Number of values (per-vertex slots).
    pub fn num_values(&self) -> usize {
        self.level.num_values()
    }

    /// The value of every face corner, face after face.
    pub fn face_values(&self) -> &[u32] {
        &self.level.face_values
    }

    /// The value `slot` stands for: the channel's own value at a base level (a value used
    /// at two vertices has a slot at each), the slot itself at a refined one.
    pub fn source(&self, slot: usize) -> u32 {
        self.level.source(slot)
    }

    /// The interpolation mode the tags were found with.
    pub fn mode(&self) -> FVarLinearInterpolation {
        self.mode
    }

    /// The state on a cut of its topology `source`: `target` holds the source faces
    /// `faces` (in order, corners in the same order), its vertices and edges are the source's
    /// `vertices` and `edges`. Each target vertex keeps all its source vertex's values.
    /// Returns the state and the source slot of each of its values.
    ///
    /// The tags of a vertex whose ring is not whole in the cut are kept as they are (their
    /// span ends clamped into its ring), and such a vertex keeps all its values, also those
    /// of faces left out: refining the cut is right only where rings are whole.
    ///
    /// # Panics
    /// If `faces`, `vertices` and `edges` do not describe `target` as a cut of `source`
    /// (lengths; in debug builds also each corner's vertex).
    pub fn restrict(
        &self,
        source: &Topology,
        target: &Topology,
        faces: &[u32],
        vertices: &[u32],
        edges: &[u32],
    ) -> (FVarLevelState, Vec<u32>) {
        let src = &self.level;
        assert!(
            faces.len() == target.num_faces()
                && vertices.len() == target.num_vertices()
                && edges.len() == target.num_edges(),
            "restrict: the faces, vertices and edges of a cut of the state's topology"
        );
        let mut value_offsets = Vec::with_capacity(vertices.len() + 1);
        value_offsets.push(0u32);
        let mut slots = Vec::new();
        for &v in vertices {
            let (o, n) = (src.offset(v as usize), src.count(v as usize));
            slots.extend((o..o + n).map(|s| s as u32));
            value_offsets.push(slots.len() as u32);
        }
        let tags = slots.iter().map(|&s| src.tags[s as usize]).collect();
        let ends = vertices
            .iter()
            .enumerate()
            .flat_map(|(pv, &v)| {
                let last = target.vertex_faces(pv).len().saturating_sub(1) as u16;
                let (o, n) = (src.offset(v as usize), src.count(v as usize));
                src.ends[o..o + n]
                    .iter()
                    .map(move |&[a, b]| [a.min(last), b.min(last)])
            })
            .collect();
        let mut face_values = Vec::with_capacity(target.num_face_vertices());
        for (j, &f) in faces.iter().enumerate() {
            let corners = source.face_vertices(f as usize);
            let first = source.face_offsets()[f as usize] as usize;
            for (k, &pv) in target.face_vertices(j).iter().enumerate() {
                debug_assert_eq!(vertices[pv as usize], corners[k], "a cut keeps corners");
                let s = src.face_values[first + k] as usize;
                let within = s - src.offset(corners[k] as usize);
                face_values.push(value_offsets[pv as usize] + within as u32);
            }
        }
        let per_edge = |flags: &[bool]| edges.iter().map(|&e| flags[e as usize]).collect();
        let geometric = if src.geometric.is_empty() {
            Vec::new()
        } else {
            vertices
                .iter()
                .map(|&v| src.geometric[v as usize])
                .collect()
        };
        let level = ChannelLevel {
            value_offsets,
            face_values,
            user: None,
            tags,
            ends,
            edge_mismatch: per_edge(&src.edge_mismatch),
            edge_linear: per_edge(&src.edge_linear),
            geometric,
        };
        (
            FVarLevelState {
                level,
                mode: self.mode,
            },
            slots,
        )
    }
}

impl FaceVaryingRefinement {
    /// The state of `level` ([`FVarLevelState`]), to continue from on a piece of it.
    ///
    /// # Panics
    /// If `level` is past the last level.
    pub fn level_state(&self, level: usize) -> FVarLevelState {
        FVarLevelState {
            level: self.levels[level].clone(),
            mode: self.mode,
        }
    }

    /// Continues a face-varying refinement from `state`, the state of the level
    /// `refinement` starts from (a piece of a refined level, as [`FVarLevelState::restrict`]
    /// makes it), refined with the state's mode to every level of `refinement`. Level 0's
    /// values are the state's slots (one per vertex and sibling; [`FVarLevelState::source`]
    /// says which value each stands for): the stencils of level 1 read them.
    ///
    /// # Errors
    /// [`FVarError::Scheme`] for a scheme that is not OpenSubdiv's, [`FVarError::IndexCount`]
    /// when the state is not one value per face-vertex of `refinement`'s base.
    ///
    /// # Panics
    /// If the state's vertices or edges are not as many as the base's.
    pub fn from_state(
        refinement: &Refinement,
        state: FVarLevelState,
    ) -> Result<FaceVaryingRefinement, FVarError> {
        if refinement.opensubdiv().is_none() {
            return Err(FVarError::Scheme {
                scheme: refinement.scheme().to_string(),
            });
        }
        let base = refinement.topology(0);
        if state.level.face_values.len() != base.num_face_vertices() {
            return Err(FVarError::IndexCount {
                given: state.level.face_values.len(),
                expected: base.num_face_vertices(),
            });
        }
        assert!(
            state.level.value_offsets.len() == base.num_vertices() + 1
                && state.level.edge_mismatch.len() == base.num_edges(),
            "from_state: a state of another topology"
        );
        let mode = state.mode;
        let flags = ModeFlags::new(mode, refinement.options().boundary_interpolation);
        let mut first = state.level;
        // The slots are the values level 1 reads.
        first.user = None;
        let num_user_values = first.num_values();
        Ok(Self::refined_from(
            refinement,
            first,
            mode,
            flags,
            num_user_values,
        ))
    }
}
