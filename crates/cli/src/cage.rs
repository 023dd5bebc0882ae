//! A control cage as an output (`pia`, `edit`, `refine --levels 0`): the scheme it is the
//! cage of goes with it, so that a USD renderer subdivides it into the same limit surface.
//! Refined and limit meshes are plain polygons and name no scheme.

use std::path::Path;

use subd_mesh::SchemeHints;
use subd_schemes::Scheme;

/// Names `scheme` in `hints`. Where a USD output cannot name it (Doo-Sabin, √3, the
/// butterflies, the two-phase scheme), the cage is written as plain polygons
/// (`subdivisionScheme = "none"`) and `warnings` says so.
pub(crate) fn name_scheme(
    hints: &mut SchemeHints,
    scheme: &Scheme,
    output: &Path,
    warnings: &mut Vec<String>,
) {
    hints.scheme = scheme.file_scheme();
    let usd = matches!(
        subd_io::Format::for_output(output),
        Some(subd_io::Format::Usda | subd_io::Format::Usdc | subd_io::Format::Usdz)
    );
    if hints.scheme.is_none() && usd {
        warnings.push(format!(
            "{}: USD has no name for the {scheme} scheme: the cage is written as plain polygons (subdivisionScheme none), which a renderer does not subdivide",
            output.display()
        ));
    }
}
