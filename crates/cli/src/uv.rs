//! Texture coordinates through the commands: a mesh's first face-varying channel refined
//! with the mesh (or taken to its limit, `subd_limit::refined_mesh`) and handed to the
//! writers.

pub(crate) use subd_limit::refined_mesh::{RefinedUv, limit_uv, refined_uv, split_limit_uv};

/// `view` with the texture coordinates `uv`, if any.
pub(crate) fn with_uv<'a>(
    view: subd_io::MeshView<'a>,
    uv: Option<&'a RefinedUv>,
) -> Result<subd_io::MeshView<'a>, subd_io::ViewError> {
    match uv {
        Some(uv) => view.with_uv(&uv.values, 2, &uv.indices),
        None => Ok(view),
    }
}

/// The warning for texture coordinates a PLY output leaves out.
pub(crate) fn ply_seam_warning(output: &std::path::Path) -> String {
    format!(
        "{}: texture coordinates left out: PLY stores one per vertex and these have seams (write .obj or .glb to keep them)",
        output.display()
    )
}

/// Drops `mesh`'s texture coordinates, with a warning, when `output` is a PLY file that
/// cannot hold them.
pub(crate) fn fit_ply(
    mesh: &mut subd_mesh::Mesh,
    output: &std::path::Path,
    warnings: &mut Vec<String>,
) {
    if subd_io::Format::for_output(output) != Some(subd_io::Format::Ply) {
        return;
    }
    if mesh.uv().is_some() && !subd_io::ply::holds_texcoords(&subd_io::MeshView::from_mesh(mesh)) {
        mesh.fvar.clear();
        warnings.push(ply_seam_warning(output));
    }
}
