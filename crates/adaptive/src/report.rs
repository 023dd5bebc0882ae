//! What the adaptive workflow (`request::adapt_mesh_with`) says about its result besides
//! the mesh: the report `subd adaptive --json` prints, and the thresholds it names (checked
//! before any mesh is read).

use serde::Serialize;
use subd_mesh::{BoundaryInterpolation, CreaseMethod, TriangleSubdivision};

use crate::{AdaptiveError, Conformity, DihedralAngle, Flatness, GaussianCurvature, MAX_LEVELS};

/// The criteria's thresholds as a request names them (`None`: not used).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Thresholds {
    /// Sun et al.'s flatness, in degrees.
    pub flatness: Option<f64>,
    /// Largest distance to the limit surface, relative to the bounding-box diagonal.
    pub max_distance: Option<f64>,
    /// Gaussian curvature times the squared diagonal.
    pub curvature: Option<f64>,
    /// Dihedral angle in degrees.
    pub dihedral: Option<f64>,
}

/// The criteria of a report: the thresholds, and where the selections came from.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CriteriaReport {
    /// The thresholds given.
    #[serde(flatten)]
    pub thresholds: Thresholds,
    /// The face selection: the library names its size (`"3 faces"`); a front may name where
    /// it came from instead (the CLI: its file).
    pub select_faces: Option<String>,
    /// The vertex selection, named as [`Self::select_faces`] is.
    pub select_vertices: Option<String>,
}

/// What an adaptive refinement made, measured: the hierarchy, the conforming mesh and its
/// distance to the limit surface (the report of `subd adaptive --json`, less its files).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AdaptiveReport {
    /// The scheme's name.
    pub scheme: &'static str,
    /// The level cap.
    pub levels: usize,
    /// The deepest level built.
    pub depth: usize,
    /// Whether every vertex is at its limit position.
    pub limit: bool,
    /// The boundary rule.
    pub boundary_interpolation: BoundaryInterpolation,
    /// The crease rule.
    pub crease_method: CreaseMethod,
    /// The triangle rule.
    pub triangle_subdivision: TriangleSubdivision,
    /// The criteria asked for.
    pub criteria: CriteriaReport,
    /// Faces of the input.
    pub input_faces: usize,
    /// Boundary edges of the input.
    pub input_boundary_edges: usize,
    /// Faces of the output.
    pub faces: usize,
    /// Vertices of the output.
    pub vertices: usize,
    /// Output faces at each level.
    pub faces_per_level: Vec<usize>,
    /// Faces of the transition patterns.
    pub transition_faces: usize,
    /// Faces of uniform refinement to [`Self::depth`].
    pub uniform_faces: u64,
    /// [`Self::faces`] over [`Self::uniform_faces`].
    pub face_ratio: f64,
    /// How many level builds the hierarchy took.
    pub level_builds: usize,
    /// Whether the output is crack-free, and its level differences.
    #[serde(flatten)]
    pub conformity: Conformity,
    /// The smallest angle of the output's faces.
    pub min_angle_degrees: f64,
    /// Largest sampled distance to the limit surface: measured with a max-distance
    /// criterion or on request, `None` otherwise or where the exact evaluator does not
    /// cover the mesh.
    pub max_distance_to_limit: Option<f64>,
    /// [`Self::max_distance_to_limit`] over the bounding-box diagonal.
    pub max_distance_to_limit_relative: Option<f64>,
    /// Whether every face is within the max-distance tolerance (`None` without it); `false`
    /// when the level cap stopped the refinement short.
    pub tolerance_met: Option<bool>,
    /// The input's bounding-box diagonal.
    pub bbox_diagonal: f64,
}

impl Thresholds {
    /// Checks the thresholds and the level cap `levels`, before any mesh is read: both
    /// fronts (the CLI, Python) get the same errors, named as the criteria are.
    ///
    /// # Errors
    /// [`AdaptiveError::Threshold`] for flatness or dihedral degrees outside `[0, 180]`, a
    /// max-distance that is not a positive number or a curvature that is not a number
    /// ≥ 0; [`AdaptiveError::TooManyLevels`] above [`MAX_LEVELS`].
    pub fn check(&self, levels: usize) -> Result<(), AdaptiveError> {
        if let Some(d) = self.flatness {
            Flatness::new(d)?;
        }
        if let Some(d) = self.dihedral {
            DihedralAngle::new(d)?;
        }
        if let Some(d) = self.max_distance
            && !(d.is_finite() && d > 0.0)
        {
            // LimitDistance checks the absolute tolerance; this names the value given.
            return Err(AdaptiveError::Threshold {
                name: "max-distance",
                value: d,
                reason: "must be a positive number",
            });
        }
        if let Some(k) = self.curvature {
            // Any positive diagonal: only the threshold is checked here.
            GaussianCurvature::new(k, 1.0)?;
        }
        if levels > MAX_LEVELS {
            return Err(AdaptiveError::TooManyLevels {
                levels,
                max: MAX_LEVELS,
            });
        }
        Ok(())
    }
}
