//! Limit surfaces for subd.
//!
//! * [`masks`]: closed-form limit position and tangent masks of Catmull-Clark and Loop for
//!   smooth, crease and corner vertices (the formulas OpenSubdiv's `Sdc` uses, with their
//!   sources).
//! * [`eigen`]: the local subdivision matrix around a vertex of any valence, read off the
//!   refinement itself, and its eigen analysis with `faer` (subdominant eigenvalues, limit
//!   masks as dominant left eigenvectors, tangent masks from the subdominant ones) — checked
//!   against the closed forms of the subdivision lecture notes §5, and used where no closed
//!   form is exact (darts, interior valence 2).
//! * [`LimitStencilTable`]: limit positions, tangents and normals of every vertex of a
//!   refinement level as stencil tables. [`limit_stencils`] is the one entry for every
//!   scheme: [`base_limit`] gives the exact limit of every base vertex of Catmull-Clark and
//!   Loop, refining first as far as semi-sharp creases need to decay,
//!   [`two_phase_base_limit`] the two-phase scheme's, [`split_limit`] the split schemes'.
//! * [`eval`]: exact evaluation at any (face, u, v) with derivatives, on a patch table that
//!   is the exact limit ([`patches`]) — bicubic B-splines and [`stam`]'s eigenbasis for
//!   Catmull-Clark, box splines and [`loop_patch`] for Loop. Next to irregular sharp
//!   features the evaluator refines locally, as deep as the point needs ([`local`]).
//! * [`acc`]: Loop & Schaefer's bicubic approximation (geometry and tangent patches).
//!
//! ```
//! use subd_mesh::{DVec3, TopologyBuilder};
//! use subd_schemes::{Options, Scheme};
//!
//! // A unit square grid of 3 × 3 quads: the limit of the centre vertices is smooth,
//! // boundary vertices follow the B-spline boundary curve.
//! let mut faces = Vec::new();
//! for j in 0..3u32 {
//!     for i in 0..3u32 {
//!         let v = j * 4 + i;
//!         faces.extend([v, v + 1, v + 5, v + 4]);
//!     }
//! }
//! let topo = TopologyBuilder::new(16).build(&[4; 9], &faces).unwrap();
//! let points: Vec<DVec3> =
//!     (0..16).map(|v| DVec3::new((v % 4) as f64, (v / 4) as f64, 0.0)).collect();
//! let table = subd_limit::base_limit(&topo, &Scheme::CatmullClark, &Options::default()).unwrap();
//! let limit = table.apply(&points);
//! // A flat grid stays flat and the interior vertex 5 is a regular B-spline point.
//! assert!((limit.positions[5] - DVec3::new(1.0, 1.0, 0.0)).length() < 1e-15);
//! assert!((limit.normals[5] - DVec3::Z).length() < 1e-15);
//! ```

// The crate's parts, one folder each, all private: the public surface is below.
mod evaluation;
mod limit_evaluator;
mod limit_masks;
mod patch_table;
mod split_limits;
mod uniform_tessellation;
mod whole_mesh;

use limit_masks::{child_limit, smooth_closed, table, two_phase_closed};

pub mod acc {
    //! Loop & Schaefer's approximation of Catmull-Clark by bicubic patches (ACC): geometry
    //! and tangent patches.
    pub use crate::evaluation::acc::{AccPatch, acc_patches};
}

pub mod eigen {
    //! The local subdivision matrix around a vertex of any valence, read off the
    //! refinement itself, and its eigen analysis (limit and tangent masks where no closed
    //! form is exact).
    pub use crate::limit_masks::eigen::{
        RingFeature, dominant_left_eigenvector, eigenvalues, ring_limit_mask, ring_matrix,
    };
}

pub mod eval {
    //! Exact evaluation at any (face, u, v) with derivatives.
    pub use crate::evaluation::eval::{FaceParam, dyadic_corner, dyadic_vertex};
    pub use crate::limit_evaluator::{LimitEvaluator, PatchPoints};
}

pub mod fvar {
    //! Limits of face-varying values (UVs), as OpenSubdiv's `LimitFaceVarying`, with exact
    //! weights.
    pub use crate::limit_masks::fvar::{
        BaseFVarLimit, base_fvar_limit, limit_at_level, limit_values,
    };
}

pub mod fvar_eval {
    //! Exact evaluation of face-varying values at any (face, u, v).
    pub use crate::evaluation::fvar_eval::{FVarEvaluator, FVarPatchValues, FVarPoint};
}

pub mod local {
    //! Exact evaluation and limits next to irregular sharp features by local refinement.
    pub use crate::evaluation::local::{MAX_LOCAL_LEVELS, base_limit};
}

pub mod loop_patch {
    //! Loop's limit near an extraordinary vertex: box splines and the eigenbasis.
    pub use crate::evaluation::loop_patch::{
        BoxSpline, LoopCornerMatrices, box_spline, loop_corner_matrices, loop_sharp_regular,
        tri_corner_patch,
    };
}

pub mod masks {
    //! Closed-form limit position and tangent masks of Catmull-Clark and Loop for smooth,
    //! crease and corner vertices (OpenSubdiv's `Sdc` formulas, with their sources).
    pub use crate::limit_masks::masks::{
        LimitMask, RingMask, catmark_crease, catmark_smooth, catmark_subdominant, corner,
        loop_crease, loop_smooth, loop_subdominant,
    };
}

pub mod patch {
    //! Regular bicubic patches: the B-spline basis, the 16 points of a regular face, and
    //! surface points with derivatives.
    pub use crate::evaluation::patch::{
        GridPoint, REGULAR_GRID, SurfacePoint, bspline_basis, corner_patch, eval_bicubic,
        eval_bicubic_first, regular_sharp_corner, sharp_regular_grid, smooth_neighbourhood,
    };
}

pub mod patches {
    //! Patch tables: feature-adaptive refinement into patches, as OpenSubdiv's
    //! `TopologyRefiner::RefineAdaptive` + `Far::PatchTableFactory` make them, with exact
    //! end caps besides OpenSubdiv's. See [`PatchTable`].
    pub use crate::evaluation::fvar_eval::FVarPoint;
    pub use crate::patch_table::{
        BasisBlend, EndCaps, FVarPatches, FVarPatchesLayout, MAX_ISOLATION, MONOMIALS, PatchArray,
        PatchArrayLayout, PatchBasisPolynomials, PatchCensus, PatchGrid, PatchMap, PatchOptions,
        PatchParam, PatchPlace, PatchTable, PatchTableLayout, PatchType, PatchWeights, TablePoints,
    };
}

pub mod point_stencil {
    //! The limit surface as linear functions of the base control vertices.
    pub use crate::evaluation::point_stencil::{
        ControlRow, DU, DV, FacePatch, POSITION, PatchForm, PointStencil,
    };
}

pub mod refined_mesh {
    //! A whole mesh refined in one call, optionally to the exact limit, texture coordinates
    //! included.
    pub use crate::whole_mesh::{
        LimitedRefinement, MeshRefinement, RefinedMesh, RefinedUv, UNNAMED_CAGE_LEVELS,
        last_level_limit, limit_uv, output_limit, refine_mesh, refined_hints, refined_unnamed_cage,
        refined_uv, split_limit_uv, unnamed_cage_warning,
    };
}

pub mod spectrum {
    //! The eigenvalue test of a surface scheme's local subdivision matrix at an interior
    //! vertex of a valence (Reif's necessary conditions for a C¹ limit).
    pub use crate::limit_masks::spectrum::{
        RingSpectrum, SplitSpectrumReport, SurfaceSpectrum, VALENCES, surface_spectrum,
    };
}

pub mod split_eigen {
    //! The split schemes' local subdivision matrices in Fourier blocks: eigenvalues, limit
    //! and tangent masks, and the masks of crease and corner features.
    pub use crate::split_limits::split_eigen::{
        FeatureCentre, FeatureMasks, FourierEigenvalue, LocalMasks, SpectrumTest, SplitSpectrum,
        expand_row, feature_ball, feature_masks, feature_matrix, feature_spoke, local_masks,
        row_between, split_spectrum,
    };
}

pub mod split_limit {
    //! Limit stencils of the split schemes, and their limit points without stencils.
    pub use crate::split_limits::split_limit::{
        MAX_LEVELS, Neighbourhoods, SplitLimitPoints, SplitLimitStencils, split_limit_points,
        split_limit_stencils, split_limit_stencils_in, split_limit_table,
    };
}

pub mod stam {
    //! Stam's eigenbasis evaluation of Catmull-Clark near an extraordinary vertex.
    pub use crate::evaluation::stam::{
        CornerPatchMatrices, Projected, SubpatchSubdivision, corner_patch_matrices,
    };
}

pub mod tessellation {
    //! Uniform tessellation of the limit surface, in OpenSubdiv's `Bfr` parameterisation,
    //! into one watertight mesh.
    pub use crate::uniform_tessellation::{
        MAX_RATE, SampleGrid, Tessellation, tessellate, tessellate_mesh, tessellate_patches,
    };
}

use subd_mesh::Topology;
use subd_mesh::tags::is_semi_sharp;
use subd_schemes::{Options, RefineError, Refinement, Scheme, StencilTable, TwoPhase};
use thiserror::Error;

pub use evaluation::point_stencil::{FacePatch, PatchForm, PointStencil};
pub use limit_masks::masks::{LimitMask, RingMask};
pub use limit_masks::table::{LimitPoints, LimitStencilTable, eigen_limit_vertices};

/// What can go wrong computing limits.
#[derive(Debug, Clone, Error)]
pub enum LimitError {
    /// A scheme without what was asked for (Bilinear has no limit masks: its limit is the
    /// mesh itself; exact evaluation covers Catmull-Clark and Loop).
    #[error("the {scheme} scheme: {what}")]
    Scheme {
        /// The scheme, as its `Display` writes it.
        scheme: String,
        /// What it is missing.
        what: &'static str,
    },
    /// Catmull-Clark limit masks at a level with a face that is not a quad.
    #[error(
        "level {level}, face {face}: {size} vertices; catmull-clark limit masks need quads (refine one level first)"
    )]
    NotQuad {
        /// Level.
        level: usize,
        /// Face.
        face: usize,
        /// Its size.
        size: usize,
    },
    /// Refinement failed.
    #[error(transparent)]
    Refine(#[from] RefineError),
    /// The refinement semi-sharp creases need to decay would be too large.
    #[error(
        "semi-sharp sharpness {sharpness} needs {levels} levels of refinement, more than {max} face-vertices"
    )]
    TooDeep {
        /// Largest finite sharpness.
        sharpness: f32,
        /// Levels needed.
        levels: usize,
        /// The face-vertex budget.
        max: usize,
    },
    /// An evaluation point outside the mesh or the parameter square.
    #[error("{0}")]
    Param(String),
    /// A face the exact evaluator does not cover yet.
    #[error("face {face}: {reason}")]
    Unsupported {
        /// Base face.
        face: usize,
        /// Why.
        reason: &'static str,
    },
    /// A vertex of a split scheme without a limit.
    #[error("vertex {vertex}: no {scheme} limit: {why}")]
    NoLimit {
        /// The vertex.
        vertex: usize,
        /// The scheme's name.
        scheme: &'static str,
        /// Why it has none.
        why: &'static str,
    },
    /// The eigen analysis failed (a degenerate local configuration).
    #[error("eigen analysis: {0}")]
    Analysis(String),
    /// A refined mesh that could not be assembled.
    #[error(transparent)]
    Mesh(#[from] subd_mesh::TopologyError),
    /// Texture coordinates that do not fit their mesh.
    #[error(transparent)]
    FaceVarying(#[from] subd_mesh::fvar::FVarError),
    /// Texture coordinates a split scheme cannot refine.
    #[error(transparent)]
    SplitFaceVarying(#[from] subd_schemes::split_schemes::SplitFVarError),
}

/// The scheme whose limit masks a level refined with `scheme` takes: Catmull-Clark's for a
/// refined level of the two-phase scheme (`refined`; phase 1 is its first step only), the
/// scheme's own for Catmull-Clark and Loop. The others have none here: Bilinear's limit is
/// the mesh itself, the split schemes' are in [`split_limit`].
pub(crate) fn masks_scheme(scheme: &Scheme, refined: bool) -> Result<Scheme, LimitError> {
    match scheme.at_level(usize::from(refined)) {
        s @ (Scheme::CatmullClark | Scheme::Loop) => Ok(s),
        s => Err(LimitError::Scheme {
            scheme: s.to_string(),
            what: "these limit masks exist for catmull-clark and loop only",
        }),
    }
}

/// Decay levels past which [`two_phase_base_limit`] refines only around semi-sharp
/// features (refining the whole mesh `4^levels` times over costs more than the cuts).
const LOCAL_DECAY_LEVELS: usize = 3;

/// Face-vertices the decay refinement of [`base_limit`] may create.
pub const MAX_DECAY_FACE_VERTICES: usize = 1 << 26;

/// Levels of uniform refinement after which no semi-sharp feature is left (every finite
/// sharpness `s` decays by at least 1 per level, Chaikin included), and, for Catmull-Clark,
/// at least one level when a face is not a quad.
pub fn levels_for_exact_limit(topology: &Topology, scheme: &Scheme) -> (usize, f32) {
    let semi = (0..topology.num_edges())
        .map(|e| topology.edge_sharpness(e))
        .chain((0..topology.num_vertices()).map(|v| topology.vertex_sharpness(v)))
        .filter(|&s| is_semi_sharp(s))
        .fold(0.0f32, f32::max);
    let quads = *scheme != Scheme::CatmullClark
        || (0..topology.num_faces()).all(|f| topology.face_size(f) == 4);
    let decay = semi.ceil() as usize;
    (decay.max(usize::from(!quads)), semi)
}

/// The rows `0..k` of `t`.
pub(crate) fn first_rows(t: &StencilTable, k: usize) -> StencilTable {
    let end = t.offsets()[k] as usize;
    StencilTable::from_csr(
        t.num_sources(),
        t.offsets()[..=k].to_vec(),
        t.indices()[..end].to_vec(),
        t.weights()[..end].to_vec(),
    )
}

/// The exact limit of every vertex of `topology` under any `scheme`, as stencils over its
/// vertices: the one limit entry. Catmull-Clark and Loop take [`base_limit`], the two-phase
/// scheme [`two_phase_base_limit`] (its phase 1 included), the split schemes
/// [`split_limit::split_limit_table`], whose creases and corners (√3, the butterflies) have no
/// tangents ([`LimitStencilTable::without_tangents`]: NaN tangents and normals once applied).
///
/// ```
/// use subd_mesh::{DVec3, TopologyBuilder};
/// use subd_schemes::{Options, Scheme};
///
/// // A tetrahedron: every scheme on triangles gives a limit point per vertex.
/// let tet = TopologyBuilder::new(4)
///     .build(&[3; 4], &[0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2])
///     .unwrap();
/// let p = [DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE];
/// for name in ["loop", "sqrt3", "butterfly", "modified-butterfly"] {
///     let scheme: Scheme = name.parse().unwrap();
///     let table = subd_limit::limit_stencils(&tet, &scheme, &Options::default()).unwrap();
///     assert_eq!(table.num_rows(), 4);
/// }
/// // The butterflies interpolate: each vertex is its own limit.
/// let b = subd_limit::limit_points(&tet, &Scheme::BUTTERFLY, &Options::default(), &p).unwrap();
/// assert_eq!(b.positions, p);
/// ```
///
/// # Errors
/// [`LimitError::Scheme`] for Bilinear (its limit is the mesh itself), and as the entry of
/// the scheme's family.
pub fn limit_stencils(
    topology: &Topology,
    scheme: &Scheme,
    options: &Options,
) -> Result<LimitStencilTable, LimitError> {
    match scheme {
        Scheme::TwoPhase(tp) => two_phase_base_limit(topology, tp, options),
        s if s.is_opensubdiv() => base_limit(topology, s, options),
        s => split_limits::split_limit::split_limit_table(topology, s),
    }
}

/// [`limit_stencils`] applied to `positions`; for the split schemes the masks are applied
/// to the points as they are found, without building the stencils
/// ([`split_limit::split_limit_points`]: the same values, up to rounding where a mask is
/// found below the base level).
///
/// # Errors
/// As [`limit_stencils`].
pub fn limit_points(
    topology: &Topology,
    scheme: &Scheme,
    options: &Options,
    positions: &[glam::DVec3],
) -> Result<LimitPoints, LimitError> {
    match scheme {
        Scheme::TwoPhase(_) => Ok(limit_stencils(topology, scheme, options)?.apply(positions)),
        s if s.is_opensubdiv() => Ok(limit_stencils(topology, scheme, options)?.apply(positions)),
        s => split_limits::split_limit::split_limit_points(topology, s, positions),
    }
}

/// The exact limit (positions, tangents, normals) of every vertex of `level` of
/// `refinement`, from `points`, that level's points: what `refine --limit` writes. Where
/// no semi-sharp feature is left at that level (and, for Catmull-Clark, every face is a
/// quad), each vertex's limit mask is applied straight to its ring in one parallel pass,
/// without stencil tables: the closed forms for smooth, crease and corner vertices, the
/// eigen analysis for darts and interior valence-2 vertices. The values are those of
/// [`limit_points`] of the level's topology, bit for bit. Elsewhere (semi-sharp features
/// left to decay, the two-phase scheme's level 0, a split scheme) it is [`limit_points`] of
/// that topology.
///
/// ```
/// use subd_mesh::{DVec3, TopologyBuilder};
/// use subd_schemes::{Options, Refinement, Scheme};
/// use subd_limit::Tangents;
///
/// let faces = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4];
/// let cube = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
/// let base: Vec<DVec3> = (0..8)
///     .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
///     .collect();
/// let o = Options::default();
/// let r = Refinement::new(&cube, Scheme::CatmullClark, &o, 2).unwrap();
/// let points = r.points_at(&base, 2);
/// let direct = subd_limit::level_limit_points(&r, 2, &o, &points, Tangents::Kept).unwrap();
/// let via_table =
///     subd_limit::limit_points(r.topology(2), &Scheme::CatmullClark, &o, &points).unwrap();
/// for v in 0..points.len() {
///     assert!((direct.positions[v] - via_table.positions[v]).length() < 1e-15);
///     assert!((direct.normals[v] - via_table.normals[v]).length() < 1e-14);
/// }
/// ```
///
/// # Errors
/// As [`limit_points`].
///
/// # Panics
/// If `points` does not hold one point per vertex of `level`.
pub fn level_limit_points(
    refinement: &Refinement,
    level: usize,
    options: &Options,
    points: &[glam::DVec3],
    tangents: Tangents,
) -> Result<LimitPoints, LimitError> {
    if child_limit::applies(refinement, level) {
        return child_limit::child_level_limit(refinement, level, points, tangents);
    }
    let scheme = refinement.scheme().at_level(level);
    let topology = refinement.topology(level);
    // The two-phase scheme's level 0 (phase 1 still to come) takes its own entry; a
    // non-manifold vertex its rules from the level's own tags.
    let with_masks = matches!(scheme, Scheme::CatmullClark | Scheme::Loop);
    if with_masks
        && levels_for_exact_limit(topology, &scheme).0 == 0
        && (0..topology.num_vertices()).all(|v| !topology.is_non_manifold_vertex(v))
    {
        return Ok(table::LevelMasks::new(refinement, level)?.apply(points, tangents));
    }
    let mut limit = limit_points(topology, &scheme, options, points)?;
    if tangents == Tangents::Dropped {
        (limit.tangent1, limit.tangent2) = (Vec::new(), Vec::new());
    }
    Ok(limit)
}

/// Whether [`level_limit_points`] keeps the limit tangents or only the positions and the
/// normals (half the memory written, all a mesh file takes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tangents {
    /// `tangent1` and `tangent2` filled.
    Kept,
    /// `tangent1` and `tangent2` left empty.
    Dropped,
}

/// The exact limit (position, tangents, normal) of every base vertex, as stencils over the
/// base vertices. Refines uniformly until semi-sharp creases and corners have decayed (and,
/// for Catmull-Clark, until every face is a quad), takes the limit masks there
/// ([`LimitStencilTable::at_level`]) and composes them back to the base mesh; base vertex
/// `v` is vertex `v` at every level. Where refining the whole mesh that far would pass
/// [`MAX_DECAY_FACE_VERTICES`], only the neighbourhoods of the semi-sharp features are
/// refined ([`evaluation::local::base_limit`], same limits).
pub fn base_limit(
    topology: &Topology,
    scheme: &Scheme,
    options: &Options,
) -> Result<LimitStencilTable, LimitError> {
    match whole_refinement(topology, scheme, options)? {
        Some((r, levels)) => limit_through(&r, levels),
        None => evaluation::local::base_limit(topology, scheme, options),
    }
}

/// The limit positions of [`base_limit`] alone (the same rows), for callers that need no
/// tangents, such as interpolation: about a third of the work. On closed smooth meshes of
/// quads (Catmull-Clark) or triangles (Loop) with no vertex of valence 2
/// ([`Topology::is_closed_smooth_uniform`]) the rows are written straight from the
/// classical smooth masks, without building level 0's rules.
///
/// ```
/// use subd_mesh::TopologyBuilder;
/// use subd_schemes::{Options, Scheme};
///
/// let faces = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4];
/// let cube = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
/// let o = Options::default();
/// let positions = subd_limit::base_limit_positions(&cube, &Scheme::CatmullClark, &o).unwrap();
/// let full = subd_limit::base_limit(&cube, &Scheme::CatmullClark, &o).unwrap();
/// assert_eq!(positions, full.position);
/// ```
///
/// # Errors
/// As [`base_limit`].
pub fn base_limit_positions(
    topology: &Topology,
    scheme: &Scheme,
    options: &Options,
) -> Result<StencilTable, LimitError> {
    if smooth_closed::applies(topology, scheme) {
        return Ok(smooth_closed::positions(topology, scheme));
    }
    match whole_refinement(topology, scheme, options)? {
        Some((r, levels)) => positions_through(&r, levels),
        None => Ok(evaluation::local::base_limit(topology, scheme, options)?.position),
    }
}

/// The uniform refinement [`base_limit`] takes its masks from, with its depth; `None` when
/// refining the whole mesh that far would pass [`MAX_DECAY_FACE_VERTICES`] (then only the
/// neighbourhoods of the semi-sharp features are refined).
fn whole_refinement(
    topology: &Topology,
    scheme: &Scheme,
    options: &Options,
) -> Result<Option<(Refinement, usize)>, LimitError> {
    masks_scheme(scheme, false)?;
    let (levels, _) = levels_for_exact_limit(topology, scheme);
    let estimate = topology
        .num_face_vertices()
        .saturating_mul(4usize.saturating_pow(levels as u32));
    if estimate > MAX_DECAY_FACE_VERTICES {
        return Ok(None);
    }
    Ok(Some((
        Refinement::new(topology, scheme.clone(), options, levels)?,
        levels,
    )))
}

/// The exact limit of every base vertex under the two-phase scheme of Lin et al.
/// ([`subd_schemes::two_phase`]): phase 1, then ordinary Catmull-Clark to the limit — the
/// Catmull-Clark limit masks of the phase-1 mesh (after semi-sharp decay), composed back to
/// the base. On a closed quad mesh this is the paper's formula (2).
///
/// ```
/// use subd_mesh::{DVec3, TopologyBuilder};
/// use subd_schemes::{Options, TwoPhase};
///
/// // A cube (every vertex of valence 3), λ = 1/2: formula (2) of Lin et al.
/// let faces = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4];
/// let cube = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
/// let tp = TwoPhase::uniform(0.5).unwrap();
/// let table = subd_limit::two_phase_base_limit(&cube, &tp, &Options::default()).unwrap();
/// let (n, l) = (3.0, 0.5);
/// let beta = n * (1.0 - l) * 10.0 / 13.0 + 2.5;
/// let (cols, weights) = table.position.row(0);
/// let w0 = weights[cols.iter().position(|&c| c == 0).unwrap()];
/// assert!((w0 - (n * n * l + 7.0 * n / 4.0) / (n * (n + 5.0))).abs() < 1e-15);
/// let w1 = weights[cols.iter().position(|&c| c == 1).unwrap()]; // an edge neighbour
/// assert!((w1 - beta / (n * (n + 5.0))).abs() < 1e-15);
/// ```
///
/// # Errors
/// [`LimitError::Refine`] for a mesh the scheme refuses (a face that is not a quad, a
/// wrong `λ` count), [`LimitError::TooDeep`] as for [`evaluation::local::base_limit`].
pub fn two_phase_base_limit(
    topology: &Topology,
    two_phase: &TwoPhase,
    options: &Options,
) -> Result<LimitStencilTable, LimitError> {
    match two_phase_refinement(topology, two_phase, options)? {
        (r, Some(levels)) => limit_through(&r, levels),
        (r, None) => evaluation::local::base_limit_after(&r, options),
    }
}

/// The limit positions of [`two_phase_base_limit`] alone, for callers that need no tangents,
/// such as interpolation. On a closed smooth quad mesh with no vertex of valence 2 the rows
/// come from the paper's formula (2) directly (no refinement; the same weights up to
/// rounding), elsewhere from [`two_phase_base_limit`]'s path without its tangents.
///
/// # Errors
/// As [`two_phase_base_limit`].
pub fn two_phase_base_limit_positions(
    topology: &Topology,
    two_phase: &TwoPhase,
    options: &Options,
) -> Result<StencilTable, LimitError> {
    if let Ok(lambda) = two_phase.lambda_for(topology.num_vertices())
        && two_phase_closed::applies(topology)
    {
        return Ok(two_phase_closed::positions(topology, &lambda));
    }
    match two_phase_refinement(topology, two_phase, options)? {
        (r, Some(levels)) => positions_through(&r, levels),
        (r, None) => Ok(evaluation::local::base_limit_after(&r, options)?.position),
    }
}

/// The refinement [`two_phase_base_limit`] takes its masks from: phase 1 and the levels
/// semi-sharp features need to decay, over the whole mesh (with their count); or phase 1
/// alone (`None`) when refining further would pass [`MAX_DECAY_FACE_VERTICES`] or
/// [`LOCAL_DECAY_LEVELS`], the rest then refined only around the features.
fn two_phase_refinement(
    topology: &Topology,
    two_phase: &TwoPhase,
    options: &Options,
) -> Result<(Refinement, Option<usize>), LimitError> {
    let (decay, _) = levels_for_exact_limit(topology, &Scheme::CatmullClark);
    let levels = decay.max(1);
    let estimate = topology
        .num_face_vertices()
        .saturating_mul(4usize.saturating_pow(levels as u32));
    if levels > 1 && (estimate > MAX_DECAY_FACE_VERTICES || levels > LOCAL_DECAY_LEVELS) {
        return Ok((
            Refinement::new(topology, Scheme::TwoPhase(two_phase.clone()), options, 1)?,
            None,
        ));
    }
    let r = Refinement::new(
        topology,
        Scheme::TwoPhase(two_phase.clone()),
        options,
        levels,
    )?;
    Ok((r, Some(levels)))
}

/// The limit masks of `r`'s level `levels`, restricted to the base vertices and composed
/// back to the base.
fn limit_through(r: &Refinement, levels: usize) -> Result<LimitStencilTable, LimitError> {
    let at = LimitStencilTable::at_level(r, levels)?;
    let nv = r.num_vertices(0);
    let mut t = LimitStencilTable {
        position: first_rows(&at.position, nv),
        tangent1: first_rows(&at.tangent1, nv),
        tangent2: first_rows(&at.tangent2, nv),
        without_tangents: Vec::new(),
    };
    for l in (1..=levels).rev() {
        t = t.after(r.stencils(l));
    }
    Ok(t)
}

/// [`limit_through`] for the positions alone.
pub(crate) fn positions_through(r: &Refinement, levels: usize) -> Result<StencilTable, LimitError> {
    let at = LimitStencilTable::positions_at_level(r, levels)?;
    let nv = r.num_vertices(0);
    // At level 0 the table is the base's already: no copy.
    let mut t = if at.num_rows() == nv {
        at
    } else {
        first_rows(&at, nv)
    };
    for l in (1..=levels).rev() {
        t = r.stencils(l).then(&t);
    }
    Ok(t)
}

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
