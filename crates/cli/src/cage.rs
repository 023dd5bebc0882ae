//! A control cage as an output (`pia`, `edit`, `refine --levels 0`): the scheme it is the
//! cage of goes with it, so that a USD renderer subdivides it into the same limit surface.
//! Refined and limit meshes are plain polygons and name no scheme.

use std::path::Path;

use subd_mesh::Mesh;
use subd_schemes::Scheme;

use crate::Failure;

/// Whether `output` is a USD file.
fn is_usd(output: &Path) -> bool {
    subd_io::Format::for_output(output).is_some_and(subd_io::Format::is_usd)
}

/// The warning for a cage of `scheme` written refined to `output`.
fn refined_warning(scheme: &Scheme, output: &Path) -> String {
    format!(
        "{}: {}",
        output.display(),
        subd_limit::refined_mesh::unnamed_cage_warning(scheme)
    )
}

/// The levels `subd refine --levels 0` writes: the cage itself, unless the output is USD
/// and cannot name `scheme` (Doo-Sabin, √3, the butterflies, two-phase); then the cage
/// refined [`subd_limit::refined_mesh::UNNAMED_CAGE_LEVELS`] levels, and `warnings` says
/// so.
pub(crate) fn levels_for_refine(
    levels: usize,
    limit: bool,
    scheme: Option<&Scheme>,
    output: &Path,
    warnings: &mut Vec<String>,
) -> usize {
    match scheme {
        Some(s) if levels == 0 && !limit && s.file_scheme().is_none() && is_usd(output) => {
            warnings.push(refined_warning(s, output));
            subd_limit::refined_mesh::UNNAMED_CAGE_LEVELS
        }
        _ => levels,
    }
}

/// `mesh`, the cage of `scheme`, as `output` holds it: naming the scheme, or, where a USD
/// output cannot name it, refined to plain polygons (and `warnings` says so).
pub(crate) fn for_output(
    mut mesh: Mesh,
    scheme: &Scheme,
    output: &Path,
    warnings: &mut Vec<String>,
) -> Result<Mesh, Failure> {
    mesh.hints.scheme = scheme.file_scheme();
    if mesh.hints.scheme.is_some() || !is_usd(output) {
        return Ok(mesh);
    }
    let (refined, left_out) = subd_limit::refined_mesh::refined_unnamed_cage(&mesh, scheme)
        .map_err(|e| crate::failure::bad(format!("{}: {e}", output.display())))?;
    warnings.push(refined_warning(scheme, output));
    warnings.extend(left_out);
    Ok(refined)
}
