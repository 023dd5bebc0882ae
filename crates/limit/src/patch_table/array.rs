//! [`PatchArray`]: the patches of one type as flat arrays, what the assembly fills and the
//! table holds.

use super::{PatchParam, PatchType};

/// The patches of one type, in level order and face order within a level.
#[derive(Debug, Clone)]
pub struct PatchArray {
    pub(super) kind: PatchType,
    pub(super) params: Vec<PatchParam>,
    pub(super) sharpness: Vec<f32>,
    pub(super) control_points: Vec<u32>,
    /// Level and face (in that level) of each patch.
    pub(super) faces: Vec<(u8, u32)>,
}

impl PatchArray {
    pub(crate) fn new_of(kind: PatchType) -> PatchArray {
        PatchArray {
            kind,
            params: Vec::new(),
            sharpness: Vec::new(),
            control_points: Vec::new(),
            faces: Vec::new(),
        }
    }

    /// Makes room for `patches` more patches.
    pub(crate) fn reserve(&mut self, patches: usize) {
        let n = self.kind.num_control_points().unwrap_or(0);
        self.faces.reserve(patches);
        self.params.reserve(patches);
        self.sharpness.reserve(patches);
        self.control_points.reserve(n * patches);
    }

    /// Appends a patch.
    pub(crate) fn push(
        &mut self,
        (level, face): (u8, u32),
        param: PatchParam,
        sharpness: f32,
        points: &[u32],
    ) {
        self.faces.push((level, face));
        self.params.push(param);
        self.sharpness.push(sharpness);
        self.control_points.extend_from_slice(points);
    }

    /// The patches' type.
    pub fn kind(&self) -> PatchType {
        self.kind
    }

    /// Number of patches.
    pub fn len(&self) -> usize {
        self.params.len()
    }

    /// Whether the array holds no patch.
    pub fn is_empty(&self) -> bool {
        self.params.is_empty()
    }

    /// One [`PatchParam`] per patch.
    pub fn params(&self) -> &[PatchParam] {
        &self.params
    }

    /// Per patch, the sharpness of its single crease (0 for every other patch; only with
    /// [`super::PatchOptions::single_crease`]).
    pub fn sharpness(&self) -> &[f32] {
        &self.sharpness
    }

    /// The control points, [`PatchType::num_control_points`] per patch, as indices into the
    /// refined vertices of all levels followed by the local points
    /// ([`super::PatchTable::points`]); empty for exact patches.
    pub fn control_points(&self) -> &[u32] {
        &self.control_points
    }

    /// The control points of patch `i`.
    pub fn patch_points(&self, i: usize) -> &[u32] {
        let n = self.kind.num_control_points().unwrap_or(0);
        &self.control_points[n * i..n * (i + 1)]
    }
}
