//! The rule options every surface command shares (`--boundary`, `--crease-method`,
//! `--triangles`, `--accept-inconsistent-orientation`, and glTF's `--no-transform` and
//! `--weld-tolerance`): defaults from the file's tags,
//! overridden on the command line.

use clap::{Args, ValueEnum};
use subd_mesh::{BoundaryInterpolation, CreaseMethod, SchemeHints, TriangleSubdivision};
use subd_schemes::Options;

#[derive(Debug, Clone, Copy, ValueEnum)]
pub(crate) enum BoundaryArg {
    None,
    EdgeOnly,
    EdgeAndCorner,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub(crate) enum CreaseArg {
    Uniform,
    Chaikin,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub(crate) enum TriangleArg {
    Catmark,
    Smooth,
}

/// The rule options a command shares: defaults from the file's tags, overridden here.
#[derive(Debug, Args)]
pub(crate) struct RuleArgs {
    /// Boundary interpolation (default: the file's `t interpolateboundary` tag, else
    /// edge-only).
    #[arg(long, value_enum)]
    boundary: Option<BoundaryArg>,
    /// Crease method for semi-sharp creases (default: the file's `t creasemethod` tag, else
    /// uniform).
    #[arg(long, value_enum)]
    crease_method: Option<CreaseArg>,
    /// Catmull-Clark triangle rule (default: the file's `t smoothtriangles` tag, else
    /// catmark).
    #[arg(long, value_enum)]
    pub(crate) triangles: Option<TriangleArg>,
    /// Accept faces whose windings disagree across a shared edge (treated as non-manifold).
    #[arg(long)]
    pub(crate) accept_inconsistent_orientation: bool,
    /// glTF input: read each mesh as stored, without its nodes' transforms.
    #[arg(long)]
    no_transform: bool,
    /// glTF input: weld vertices closer than this (default: only identical positions).
    #[arg(long, value_name = "D", value_parser = non_negative_distance)]
    weld_tolerance: Option<f64>,
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
            options.boundary_interpolation = match b {
                BoundaryArg::None => BoundaryInterpolation::None,
                BoundaryArg::EdgeOnly => BoundaryInterpolation::EdgeOnly,
                BoundaryArg::EdgeAndCorner => BoundaryInterpolation::EdgeAndCorner,
            };
        }
        if let Some(c) = self.crease_method {
            options.crease_method = match c {
                CreaseArg::Uniform => CreaseMethod::Uniform,
                CreaseArg::Chaikin => CreaseMethod::Chaikin,
            };
        }
        if let Some(t) = self.triangles {
            options.triangle_subdivision = match t {
                TriangleArg::Catmark => TriangleSubdivision::Catmark,
                TriangleArg::Smooth => TriangleSubdivision::Smooth,
            };
        }
        options
    }

    /// Reader options.
    pub(crate) fn read_options(&self) -> subd_io::ReadOptions {
        subd_io::ReadOptions {
            accept_inconsistent_orientation: self.accept_inconsistent_orientation,
            ignore_transforms: self.no_transform,
            weld_tolerance: self.weld_tolerance,
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
