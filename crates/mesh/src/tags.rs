//! Crease, corner and hole tags, and the scheme options a mesh file may carry.
//!
//! Sharpness is stored as `f32`, exactly as OpenSubdiv's `Sdc::Crease` keeps it: 0 is smooth,
//! values at or above [`SHARPNESS_INFINITE`] are infinitely sharp, anything in between is
//! semi-sharp and decays by one per refinement level. Keeping `f32` is what lets a refinement
//! agree with OpenSubdiv to 1e-12 (an `f64` port of a sharpness of 7.9 drifts by ~1e-7).

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::choice::Choice;

/// Sharpness at or above which an edge or vertex is infinitely sharp (OpenSubdiv's
/// `Sdc::Crease::SHARPNESS_INFINITE`).
pub const SHARPNESS_INFINITE: f32 = 10.0;

/// Sharpness of a smooth edge or vertex.
pub const SHARPNESS_SMOOTH: f32 = 0.0;

/// Rounds a user-given sharpness to the `f32` OpenSubdiv stores. Values beyond the `f32`
/// range saturate at `f32::MAX` (still infinitely sharp) rather than becoming `inf`, so that
/// every stored sharpness can be written out and read back as a finite number.
#[inline]
pub fn sharpness_from_f64(s: f64) -> f32 {
    s.clamp(-(f32::MAX as f64), f32::MAX as f64) as f32
}

/// A storable sharpness: NaN and negative values become smooth (0), infinity saturates at
/// `f32::MAX`.
#[inline]
pub fn sanitize(s: f32) -> f32 {
    if s.is_nan() {
        SHARPNESS_SMOOTH
    } else {
        s.clamp(SHARPNESS_SMOOTH, f32::MAX)
    }
}

/// `true` when `s` is infinitely sharp.
#[inline]
pub fn is_infinite(s: f32) -> bool {
    s >= SHARPNESS_INFINITE
}

/// `true` when `s` is sharp at all (semi-sharp or infinite).
#[inline]
pub fn is_sharp(s: f32) -> bool {
    s > SHARPNESS_SMOOTH
}

/// `true` when `s` is semi-sharp: sharp but finite.
#[inline]
pub fn is_semi_sharp(s: f32) -> bool {
    s > SHARPNESS_SMOOTH && s < SHARPNESS_INFINITE
}

/// Per-element tags of a topology: edge crease sharpness, vertex corner sharpness, holes.
///
/// The arrays are indexed by edge, vertex and face index of the topology that owns them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Tags {
    pub(crate) edge_sharpness: Vec<f32>,
    pub(crate) vertex_sharpness: Vec<f32>,
    pub(crate) face_hole: Vec<bool>,
}

impl Tags {
    pub(crate) fn new(num_vertices: usize, num_edges: usize, num_faces: usize) -> Self {
        Tags::from_parts(
            Vec::new(),
            Vec::new(),
            Vec::new(),
            (num_vertices, num_edges, num_faces),
        )
    }

    /// Tags from given arrays, each empty for "all smooth" / "no holes"; values sanitised.
    /// Arrays that are already sane (the usual case for refined levels) are only read.
    pub(crate) fn from_parts(
        mut edge_sharpness: Vec<f32>,
        mut vertex_sharpness: Vec<f32>,
        mut face_hole: Vec<bool>,
        (nv, ne, nf): (usize, usize, usize),
    ) -> Self {
        for (v, n) in [(&mut edge_sharpness, ne), (&mut vertex_sharpness, nv)] {
            if v.is_empty() {
                *v = vec![SHARPNESS_SMOOTH; n];
            } else if v.par_iter().any(|&s| sanitize(s).to_bits() != s.to_bits()) {
                v.par_iter_mut().for_each(|s| *s = sanitize(*s));
            }
        }
        if face_hole.is_empty() {
            face_hole = vec![false; nf];
        }
        Tags {
            edge_sharpness,
            vertex_sharpness,
            face_hole,
        }
    }

    /// Crease sharpness of every edge, indexed by edge.
    pub fn edge_sharpness(&self) -> &[f32] {
        &self.edge_sharpness
    }

    /// Corner sharpness of every vertex, indexed by vertex.
    pub fn vertex_sharpness(&self) -> &[f32] {
        &self.vertex_sharpness
    }

    /// Hole flag of every face, indexed by face.
    pub fn holes(&self) -> &[bool] {
        &self.face_hole
    }

    /// Number of edges with a non-zero crease sharpness.
    pub fn num_creased_edges(&self) -> usize {
        self.edge_sharpness.iter().filter(|&&s| is_sharp(s)).count()
    }

    /// Number of infinitely sharp creased edges.
    pub fn num_infinite_creases(&self) -> usize {
        self.edge_sharpness
            .iter()
            .filter(|&&s| is_infinite(s))
            .count()
    }

    /// Number of vertices with a non-zero corner sharpness.
    pub fn num_corners(&self) -> usize {
        self.vertex_sharpness
            .iter()
            .filter(|&&s| is_sharp(s))
            .count()
    }

    /// Number of faces tagged as holes.
    pub fn num_holes(&self) -> usize {
        self.face_hole.iter().filter(|&&h| h).count()
    }
}

/// How boundary vertices are treated (OpenSubdiv's `Sdc::Options::VtxBoundaryInterpolation`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BoundaryInterpolation {
    /// Boundary faces are dropped (`VTX_BOUNDARY_NONE`).
    None,
    /// Boundary edges are infinitely sharp (`VTX_BOUNDARY_EDGE_ONLY`, the default).
    #[default]
    EdgeOnly,
    /// Boundary edges and corner vertices (one face) are infinitely sharp
    /// (`VTX_BOUNDARY_EDGE_AND_CORNER`).
    EdgeAndCorner,
}

impl BoundaryInterpolation {
    /// Decodes the integer of an OpenSubdiv shape file's `t interpolateboundary` tag
    /// (0 none, 1 edge-and-corner, 2 edge-only).
    pub fn from_shape_tag(k: i64) -> Option<Self> {
        match k {
            0 => Some(BoundaryInterpolation::None),
            1 => Some(BoundaryInterpolation::EdgeAndCorner),
            2 => Some(BoundaryInterpolation::EdgeOnly),
            _ => None,
        }
    }

    /// The integer written in a `t interpolateboundary` tag.
    pub fn to_shape_tag(self) -> i64 {
        match self {
            BoundaryInterpolation::None => 0,
            BoundaryInterpolation::EdgeAndCorner => 1,
            BoundaryInterpolation::EdgeOnly => 2,
        }
    }
}

/// How semi-sharp crease sharpness decays (OpenSubdiv's `Sdc::Options::CreasingMethod`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CreaseMethod {
    /// Sharpness decreases by one per level (`CREASE_UNIFORM`, written `normal` in shape files).
    #[default]
    Uniform,
    /// Chaikin's averaging of neighbouring sharpness (`CREASE_CHAIKIN`).
    Chaikin,
}

/// How Catmull-Clark treats triangles (OpenSubdiv's `Sdc::Options::TriangleSubdivision`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TriangleSubdivision {
    /// The plain Catmull-Clark masks (`TRI_SUB_CATMARK`, the default).
    #[default]
    Catmark,
    /// The "smooth triangle" edge weights (`TRI_SUB_SMOOTH`).
    Smooth,
}

impl Choice for BoundaryInterpolation {
    const OPTION: &'static str = "boundary interpolation";
    const VALUES: &'static [(Self, &'static str, &'static str)] = &[
        (
            BoundaryInterpolation::None,
            "none",
            "Faces on the boundary are left out of the limit surface",
        ),
        (
            BoundaryInterpolation::EdgeOnly,
            "edge-only",
            "Boundary edges are infinitely sharp (OpenSubdiv's default)",
        ),
        (
            BoundaryInterpolation::EdgeAndCorner,
            "edge-and-corner",
            "Boundary edges and corner vertices (one face) are infinitely sharp",
        ),
    ];
}

impl Choice for CreaseMethod {
    const OPTION: &'static str = "crease method";
    const VALUES: &'static [(Self, &'static str, &'static str)] = &[
        (
            CreaseMethod::Uniform,
            "uniform",
            "Semi-sharp creases lose one unit of sharpness per level (OpenSubdiv's default)",
        ),
        (
            CreaseMethod::Chaikin,
            "chaikin",
            "Chaikin's averaging of the sharpness along a crease",
        ),
    ];
}

impl Choice for TriangleSubdivision {
    const OPTION: &'static str = "triangle rule";
    const VALUES: &'static [(Self, &'static str, &'static str)] = &[
        (
            TriangleSubdivision::Catmark,
            "catmark",
            "Catmull-Clark's own masks on triangles (OpenSubdiv's default)",
        ),
        (
            TriangleSubdivision::Smooth,
            "smooth",
            "OpenSubdiv's smooth-triangle edge weights",
        ),
    ];
}

crate::choice_by_name!(BoundaryInterpolation);
crate::choice_by_name!(CreaseMethod);
crate::choice_by_name!(TriangleSubdivision);

/// The subdivision scheme a mesh file names for its surface: USD's `subdivisionScheme`
/// (the schemes USD shares with OpenSubdiv), kept as the file says it. The crates that know
/// the schemes turn it into theirs (`subd_schemes::Scheme::from_file`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FileScheme {
    /// `catmullClark`.
    CatmullClark,
    /// `loop`.
    Loop,
    /// `bilinear`.
    Bilinear,
    /// `none`: a plain polygon mesh, not a subdivision surface.
    Polygons,
}

/// Scheme options a mesh file asks for (the `t interpolateboundary`, `t creasemethod`,
/// `t smoothtriangles` and `t facevaryinginterpolateboundary` tags of OpenSubdiv's shape
/// files). `None` means the file is silent and
/// the scheme's default applies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct SchemeHints {
    /// Requested boundary interpolation.
    pub boundary_interpolation: Option<BoundaryInterpolation>,
    /// Requested crease method.
    pub crease_method: Option<CreaseMethod>,
    /// Requested triangle rule for Catmull-Clark.
    pub triangle_subdivision: Option<TriangleSubdivision>,
    /// Requested face-varying interpolation (`t facevaryinginterpolateboundary 1/0/0 k`).
    pub fvar_interpolation: Option<crate::fvar::FVarLinearInterpolation>,
    /// The scheme the file names (USD's `subdivisionScheme`; OBJ, PLY and glTF name none).
    pub scheme: Option<FileScheme>,
}
