//! The rows the conformance checks report.

/// Outcome of one check of one mesh at one level.
pub struct Row {
    pub mesh: String,
    /// "refine" (positions of the refined level) or "limit" (PrimvarRefiner::Limit there).
    pub check: &'static str,
    pub level: usize,
    pub vertices: usize,
    pub error: f64,
    /// Max difference of unit normals (limit checks only).
    pub normal_error: Option<f64>,
    /// Vertices left out of the limit check because OpenSubdiv is not exact there, with the
    /// largest |Δ|/diag seen at them.
    pub excluded: Option<(usize, f64)>,
    /// Something the row wants said when it passes.
    pub note: Option<String>,
    pub problem: Option<String>,
}

impl Row {
    /// A row not decided yet: infinite error, nothing found.
    pub(crate) fn pending(mesh: &str, check: &'static str, level: usize) -> Row {
        Row {
            mesh: mesh.to_string(),
            check,
            level,
            vertices: 0,
            error: f64::INFINITY,
            normal_error: None,
            excluded: None,
            note: None,
            problem: None,
        }
    }
}
