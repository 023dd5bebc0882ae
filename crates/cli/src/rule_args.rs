//! The rule options every surface command shares (`--boundary`, `--crease-method`,
//! `--triangles`, `--fvar-interpolation`, `--accept-inconsistent-orientation`, and glTF's `--no-transform` and
//! `--weld-tolerance`): defaults from the file's tags,
//! overridden on the command line.

use clap::Args;
use subd_mesh::fvar::FVarLinearInterpolation;
use subd_mesh::{BoundaryInterpolation, CreaseMethod, SchemeHints, TriangleSubdivision};
use subd_schemes::Options;

use crate::choice_arg;

/// The rule options a command shares: defaults from the file's tags, overridden here.
#[derive(Debug, Clone, Args)]
pub(crate) struct RuleArgs {
    /// Boundary interpolation (default: the file's `t interpolateboundary` tag, else
    /// edge-only).
    #[arg(long, value_parser = choice_arg::parser::<BoundaryInterpolation>())]
    boundary: Option<BoundaryInterpolation>,
    /// Crease method for semi-sharp creases (default: the file's `t creasemethod` tag, else
    /// uniform).
    #[arg(long, value_parser = choice_arg::parser::<CreaseMethod>())]
    crease_method: Option<CreaseMethod>,
    /// Catmull-Clark triangle rule (default: the file's `t smoothtriangles` tag, else
    /// catmark).
    #[arg(long, value_parser = choice_arg::parser::<TriangleSubdivision>())]
    pub(crate) triangles: Option<TriangleSubdivision>,
    /// How texture coordinates are interpolated along seams and the boundary (default: the
    /// file's `t facevaryinginterpolateboundary` tag, else corners-plus1, as USD and
    /// Blender).
    #[arg(long, value_name = "MODE", value_parser = choice_arg::parser::<FVarLinearInterpolation>())]
    fvar_interpolation: Option<FVarLinearInterpolation>,
    /// Accept faces whose windings disagree across a shared edge (treated as non-manifold).
    #[arg(long)]
    pub(crate) accept_inconsistent_orientation: bool,
    /// glTF and USD input: read each mesh as stored, without its nodes' (prims') transforms.
    #[arg(long)]
    no_transform: bool,
    /// USD input: the path of the mesh prim to read (default: the stage's only one).
    #[arg(long, value_name = "PATH")]
    pub(crate) prim: Option<String>,
    /// USD input: the time code at which time-sampled attributes are read (default: their
    /// default values).
    #[arg(long, value_name = "T", value_parser = finite_time)]
    time: Option<f64>,
    /// glTF input: weld vertices closer than this (default: only identical positions).
    #[arg(long, value_name = "D", value_parser = non_negative_distance)]
    weld_tolerance: Option<f64>,
}

fn finite_time(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(t) if t.is_finite() => Ok(t),
        _ => Err("expected a finite time code".into()),
    }
}

fn non_negative_distance(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(d) if d.is_finite() && d >= 0.0 => Ok(d),
        _ => Err("expected a finite distance ≥ 0".into()),
    }
}

impl RuleArgs {
    /// The options for `hints` (a file's tags) with this command line's overrides.
    pub(crate) fn options(&self, hints: &SchemeHints) -> Options {
        let mut options = Options::from_hints(hints);
        if let Some(b) = self.boundary {
            options.boundary_interpolation = b;
        }
        if let Some(c) = self.crease_method {
            options.crease_method = c;
        }
        if let Some(t) = self.triangles {
            options.triangle_subdivision = t;
        }
        options
    }

    /// The face-varying interpolation: this command line's, else the file's tag, else
    /// corners-plus1.
    pub(crate) fn fvar_mode(&self, hints: &SchemeHints) -> FVarLinearInterpolation {
        self.fvar_interpolation
            .or(hints.fvar_interpolation)
            .unwrap_or(FVarLinearInterpolation::CornersPlus1)
    }

    /// Reader options.
    pub(crate) fn read_options(&self) -> subd_io::ReadOptions {
        subd_io::ReadOptions {
            accept_inconsistent_orientation: self.accept_inconsistent_orientation,
            ignore_transforms: self.no_transform,
            weld_tolerance: self.weld_tolerance,
            prim: self.prim.clone(),
            time: self.time,
        }
    }
}

/// The butterfly's tension `w` from `--tension` (1/16, the classic scheme, when absent).
pub(crate) fn butterfly_tension(tension: Option<f64>) -> Result<f64, crate::Failure> {
    let w = tension.unwrap_or(1.0 / 16.0);
    if w.is_finite() {
        Ok(w)
    } else {
        Err(crate::failure::bad(format!(
            "--tension {w}: must be a finite number"
        )))
    }
}
