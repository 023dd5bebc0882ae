//! [`FaceVarying`]: a face-varying channel (texture coordinates) refined with a
//! [`Refinement`] of any scheme, [`Refinement::face_varying`]. OpenSubdiv's schemes carry it
//! in OpenSubdiv's six interpolation modes ([`FaceVaryingRefinement`]); the split schemes on
//! a mesh of values of their own ([`SplitFaceVarying`]).

use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};

use crate::split_schemes::{SplitFVarError, SplitFaceVarying};
use crate::{FaceVaryingRefinement, Refinement, StencilTable};

/// A face-varying channel refined to every level of a refinement.
///
/// ```
/// use subd_mesh::TopologyBuilder;
/// use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};
/// use subd_schemes::{Options, Refinement, Scheme};
///
/// // Two triangles sharing an edge, one texture coordinate per corner of the square.
/// let t = TopologyBuilder::new(4).build(&[3, 3], &[0, 1, 2, 0, 2, 3]).unwrap();
/// let uv = [0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0];
/// let channel = FVarChannel::new(&t, 2, uv.to_vec(), vec![0, 1, 2, 0, 2, 3]).unwrap();
/// for name in ["loop", "butterfly"] {
///     let scheme: Scheme = name.parse().unwrap();
///     let r = Refinement::new(&t, scheme, &Options::default(), 2).unwrap();
///     let fv = r.face_varying(&channel, FVarLinearInterpolation::All).unwrap();
///     let values = fv.refine_values(&uv, 2);
///     // Linear everywhere: every refined value stays inside the unit square.
///     assert!(values[2].iter().all(|x| (0.0..=1.0).contains(x)));
///     assert_eq!(fv.face_values(2).len(), r.faces(2).1.len());
/// }
/// ```
#[derive(Debug)]
pub struct FaceVarying<'r> {
    refinement: &'r Refinement,
    family: Family,
}

#[derive(Debug)]
enum Family {
    OpenSubdiv(FaceVaryingRefinement),
    Split(Box<SplitFaceVarying>),
}

impl Refinement {
    /// `channel` (made for the base topology) refined to every level, interpolated by
    /// `mode`.
    ///
    /// # Errors
    /// [`SplitFVarError::Channel`] for a channel that does not fit the base topology;
    /// [`SplitFVarError::Seam`] where Doo-Sabin or √3 cannot carry a seam.
    pub fn face_varying(
        &self,
        channel: &FVarChannel,
        mode: FVarLinearInterpolation,
    ) -> Result<FaceVarying<'_>, SplitFVarError> {
        let family = if self.scheme().is_opensubdiv() {
            Family::OpenSubdiv(FaceVaryingRefinement::new(self, channel, mode)?)
        } else {
            Family::Split(Box::new(SplitFaceVarying::new(self, channel, mode)?))
        };
        Ok(FaceVarying {
            refinement: self,
            family,
        })
    }
}

impl FaceVarying<'_> {
    /// The interpolation mode.
    pub fn mode(&self) -> FVarLinearInterpolation {
        match &self.family {
            Family::OpenSubdiv(f) => f.mode(),
            Family::Split(f) => f.mode(),
        }
    }

    /// Number of refined levels.
    pub fn num_levels(&self) -> usize {
        self.refinement.num_levels()
    }

    /// Number of values at `level`.
    pub fn num_values(&self, level: usize) -> usize {
        match &self.family {
            Family::OpenSubdiv(f) => f.num_values(level),
            Family::Split(f) => f.num_values(level),
        }
    }

    /// The value index of every face-vertex of `level`, face after face.
    pub fn face_values(&self, level: usize) -> Vec<u32> {
        match &self.family {
            Family::OpenSubdiv(f) => f.face_values(level),
            Family::Split(f) => f.face_values(level),
        }
    }

    /// The values of every level (`result[0]` is `values`), `components` numbers each.
    ///
    /// # Panics
    /// If `values` is not `components` numbers per value of the channel.
    pub fn refine_values(&self, values: &[f64], components: usize) -> Vec<Vec<f64>> {
        match &self.family {
            Family::OpenSubdiv(f) => f.refine_values(self.refinement, values, components),
            Family::Split(f) => f.refine_values(values, components),
        }
    }

    /// One table from the channel's values to the values of `level`.
    pub fn composed(&self, level: usize) -> StencilTable {
        match &self.family {
            Family::OpenSubdiv(f) => f.composed(self.refinement, level),
            Family::Split(f) => f.composed(level),
        }
    }

    /// OpenSubdiv's face-varying refinement, for its schemes (its per-level value states
    /// feed the face-varying limit masks).
    pub fn opensubdiv(&self) -> Option<&FaceVaryingRefinement> {
        match &self.family {
            Family::OpenSubdiv(f) => Some(f),
            Family::Split(_) => None,
        }
    }

    /// The split schemes' refinement of the values, for the split schemes (its mesh of
    /// values takes the limit stencils of the geometry).
    pub fn split(&self) -> Option<&SplitFaceVarying> {
        match &self.family {
            Family::OpenSubdiv(_) => None,
            Family::Split(f) => Some(f),
        }
    }
}
