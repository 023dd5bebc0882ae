//! [`LimitEvaluator`]: the exact limit at any (face, u, v), evaluated on a patch table that
//! is the exact limit ([`crate::patches::PatchOptions::exact_limit`]: isolation 1, exact end
//! caps), one table for any number of point sets.
//!
//! The regular patches are bicubic B-splines (Catmull-Clark) and quartic box splines (Loop);
//! each irregular patch is evaluated exactly on its own face of the table's sparse level:
//! Stam's eigenbasis at one extraordinary corner, splines with phantom points along straight
//! sharp features, local refinement as deep as the point needs next to irregular sharp
//! features. Where a sparse level does not hold what a cap reads, the cap is evaluated from
//! two uniform levels of the whole mesh instead, built only then. Point stencils are the
//! table's ([`crate::patches::PatchTable::stencil`]); the pieces of each face
//! ([`LimitEvaluator::face_patches`]) are still computed from the whole mesh, built on first
//! request, and face-varying channels from their own mesh of values.

use std::sync::OnceLock;

use glam::DVec3;
use subd_mesh::Topology;
use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};
use subd_schemes::{Options, Scheme};

use crate::LimitError;
use crate::evaluation::eval::{FaceParam, WholeMeshEvaluator};
use crate::evaluation::fvar_eval::{FVarEvaluator, face_varying_evaluator};
use crate::evaluation::patch::SurfacePoint;
use crate::evaluation::point_stencil::{FacePatch, PointStencil};
use crate::evaluation::support::face_support;
use crate::patch_table::{PatchOptions, PatchTable, TablePoints};

/// Exact limit-surface evaluator for one mesh topology (Catmull-Clark or Loop), on a patch
/// table that is the exact limit.
///
/// ```
/// use subd_mesh::{DVec3, TopologyBuilder};
/// use subd_schemes::{Options, Scheme};
/// use subd_limit::eval::{FaceParam, LimitEvaluator};
///
/// // A cube: every face has four extraordinary (valence-3) corners.
/// let faces = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4];
/// let topo = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
/// let s = [(-1., -1., 1.), (1., -1., 1.), (-1., 1., 1.), (1., 1., 1.),
///          (-1., 1., -1.), (1., 1., -1.), (-1., -1., -1.), (1., -1., -1.)];
/// let p: Vec<DVec3> = s.iter().map(|&(x, y, z)| DVec3::new(x, y, z)).collect();
/// let eval = LimitEvaluator::new(&topo, &Scheme::CatmullClark, &Options::default()).unwrap();
/// let points = eval.prepare(&p);
/// // The centre of face 0 (z = 1): on the z axis, below the face, normal +z.
/// let c = eval.evaluate(&points, FaceParam { face: 0, sub: 0, u: 0.5, v: 0.5 }).unwrap();
/// assert!(c.position.x.abs() < 1e-14 && c.position.y.abs() < 1e-14);
/// assert!(c.position.z > 0.5 && c.position.z < 1.0);
/// assert!((c.normal() - DVec3::Z).length() < 1e-12);
/// ```
#[derive(Debug)]
pub struct LimitEvaluator {
    /// The exact-limit table, without points of its own.
    table: PatchTable,
    /// The rules the mesh is refined with.
    rules: Options,
    /// The whole-mesh evaluator, for the pieces of faces.
    whole: OnceLock<Result<WholeMeshEvaluator, LimitError>>,
}

/// The points of one set of base positions ([`LimitEvaluator::prepare`]): the table's
/// refined and local points, and its exact end caps' projections.
#[derive(Clone, Debug)]
pub struct PatchPoints {
    pub(crate) table: TablePoints,
}

impl LimitEvaluator {
    /// Prepares evaluation on `topology` with the rules of `options` (Catmull-Clark or
    /// Loop).
    ///
    /// # Errors
    /// [`LimitError::Scheme`] for another scheme, and the refinement's errors (a Loop mesh
    /// that is not all triangles, a face the tags make invalid).
    pub fn new(
        topology: &Topology,
        scheme: &Scheme,
        options: &Options,
    ) -> Result<Self, LimitError> {
        crate::masks_scheme(scheme, false)?;
        let table =
            PatchTable::without_points(topology, scheme, options, &PatchOptions::exact_limit())?;
        Ok(LimitEvaluator {
            table,
            rules: *options,
            whole: OnceLock::new(),
        })
    }

    /// The base topology as the evaluator sees it (boundary faces are holes under
    /// `BoundaryInterpolation::None`).
    pub fn topology(&self) -> &Topology {
        self.table.base_topology()
    }

    /// The scheme.
    pub fn scheme(&self) -> &Scheme {
        self.table.scheme()
    }

    /// The table the evaluator runs on.
    pub(crate) fn table(&self) -> &PatchTable {
        &self.table
    }

    /// The control points for base positions `points` (one per base vertex).
    ///
    /// # Panics
    /// If `points.len()` is not the number of base vertices.
    pub fn prepare(&self, points: &[DVec3]) -> PatchPoints {
        assert_eq!(
            points.len(),
            self.topology().num_vertices(),
            "one point per base vertex"
        );
        let table = self.table.points_for(points).expect("one point per vertex");
        PatchPoints { table }
    }

    /// Checks `at` against the topology: face and sub-face in range, parameters in [0, 1].
    ///
    /// # Errors
    /// [`LimitError::Param`] naming what is out of range.
    pub fn check(&self, at: &FaceParam) -> Result<(), LimitError> {
        self.table.check(at)
    }

    /// The limit surface at `at`: position and first and second derivatives.
    ///
    /// # Errors
    /// [`LimitError::Param`] for a place out of range, [`LimitError::Unsupported`] where the
    /// face has no surface (a hole).
    pub fn evaluate(
        &self,
        points: &PatchPoints,
        at: FaceParam,
    ) -> Result<SurfacePoint, LimitError> {
        self.table.evaluate_on(&points.table, at)
    }

    /// Position and unit normal at `at`, as [`Self::evaluate`] gives them (to rounding),
    /// without the second derivatives: what a tessellation needs.
    ///
    /// # Errors
    /// As [`Self::evaluate`].
    pub fn evaluate_position_normal(
        &self,
        points: &PatchPoints,
        at: FaceParam,
    ) -> Result<(DVec3, DVec3), LimitError> {
        let [p, du, dv] = self.table.evaluate_first_on(&points.table, at)?;
        Ok((p, du.cross(dv).normalize_or_zero()))
    }

    /// The base vertices the limit surface over `face` can depend on: the vertices of the
    /// faces around its vertices.
    pub fn support(&self, face: usize) -> Vec<u32> {
        face_support(self.topology(), face)
    }

    /// The weights of the base vertices giving the position and first and second
    /// derivatives at `at`, equal (to rounding) to [`Self::evaluate`] for any points.
    ///
    /// # Errors
    /// As [`Self::evaluate`].
    pub fn stencil(&self, at: FaceParam) -> Result<PointStencil, LimitError> {
        self.table.stencil(at)
    }

    /// The pieces of the limit surface over base `face` and their control points as rows
    /// over base vertices: one piece for a regular face or a face with one extraordinary
    /// corner, the 16 level-2 pieces of a refined quad, 4 per sub-face of a non-quad.
    ///
    /// # Errors
    /// [`LimitError::Param`] for a face out of range, [`LimitError::Unsupported`] for holes
    /// and faces the evaluator does not cover.
    pub fn face_patches(&self, face: usize) -> Result<Vec<FacePatch>, LimitError> {
        self.whole()?.face_patches(face)
    }

    /// An evaluator of `channel` (defined on this evaluator's mesh) interpolated by `mode`.
    ///
    /// # Errors
    /// [`LimitError::Param`] when the channel does not fit the mesh or has no values;
    /// [`LimitError::TooDeep`] when a semi-sharp seam would need the whole mesh refined past
    /// [`crate::MAX_DECAY_FACE_VERTICES`]; the errors of [`LimitEvaluator::new`] on the mesh
    /// of values.
    pub fn face_varying(
        &self,
        channel: &FVarChannel,
        mode: FVarLinearInterpolation,
    ) -> Result<FVarEvaluator, LimitError> {
        face_varying_evaluator(self.topology(), self.scheme(), &self.rules, channel, mode)
    }

    /// The whole-mesh evaluator, built on first request.
    fn whole(&self) -> Result<&WholeMeshEvaluator, LimitError> {
        self.whole
            .get_or_init(|| WholeMeshEvaluator::new(self.topology(), self.scheme(), &self.rules))
            .as_ref()
            .map_err(Clone::clone)
    }
}
