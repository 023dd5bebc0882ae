//! The kinds of patch a table holds, with OpenSubdiv's names and control-point counts.

/// A kind of patch (OpenSubdiv's `Far::PatchDescriptor::Type`, plus subd's exact end caps).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "SCREAMING_SNAKE_CASE")]
pub enum PatchType {
    /// Bilinear quad, 4 points (bilinear end caps).
    Quads,
    /// Linear triangle, 3 points (Loop's bilinear end caps).
    Triangles,
    /// Quartic box-spline triangle of Loop, 12 points.
    Loop,
    /// Bicubic B-spline quad, 16 points.
    Regular,
    /// Gregory quad, 20 points.
    GregoryBasis,
    /// Quartic Gregory triangle, 18 points.
    GregoryTriangle,
    /// An irregular patch evaluated exactly; its points are the level's ring around the
    /// patch (subd only).
    Exact,
}

impl PatchType {
    /// Every kind.
    pub const ALL: [PatchType; 7] = [
        PatchType::Quads,
        PatchType::Triangles,
        PatchType::Loop,
        PatchType::Regular,
        PatchType::GregoryBasis,
        PatchType::GregoryTriangle,
        PatchType::Exact,
    ];

    /// OpenSubdiv's name of the kind (`REGULAR`, `LOOP`, ...; `EXACT` is subd's).
    pub fn name(self) -> &'static str {
        match self {
            PatchType::Quads => "QUADS",
            PatchType::Triangles => "TRIANGLES",
            PatchType::Loop => "LOOP",
            PatchType::Regular => "REGULAR",
            PatchType::GregoryBasis => "GREGORY_BASIS",
            PatchType::GregoryTriangle => "GREGORY_TRIANGLE",
            PatchType::Exact => "EXACT",
        }
    }

    /// OpenSubdiv's `PatchDescriptor::Type` value (subd's `EXACT` takes the next free one).
    pub fn opensubdiv_type(self) -> u32 {
        match self {
            PatchType::Quads => 3,
            PatchType::Triangles => 4,
            PatchType::Loop => 5,
            PatchType::Regular => 6,
            PatchType::GregoryBasis => 9,
            PatchType::GregoryTriangle => 10,
            PatchType::Exact => 11,
        }
    }

    /// Control points per patch; `None` for exact patches, whose rings vary.
    pub fn num_control_points(self) -> Option<usize> {
        match self {
            PatchType::Quads => Some(4),
            PatchType::Triangles => Some(3),
            PatchType::Loop => Some(12),
            PatchType::Regular => Some(16),
            PatchType::GregoryBasis => Some(20),
            PatchType::GregoryTriangle => Some(18),
            PatchType::Exact => None,
        }
    }
}

impl std::fmt::Display for PatchType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
