//! A refinement as the commands hold it: [`RefinementWithLimit`] (the library's
//! `Refinement`, and the limit stencils of a split scheme's last level once asked for), the
//! exact limit of its output level (both from `subd_limit::refined_mesh`), and the normals
//! a writer gets where the limit defines none.

pub(crate) use subd_limit::refined_mesh::{
    LimitedRefinement as RefinementWithLimit, last_level_limit,
};

/// Whether every normal is a unit vector (the limit defines every tangent plane).
pub(crate) fn all_unit(normals: &[subd_mesh::DVec3]) -> bool {
    normals
        .iter()
        .all(|n| n.is_finite() && n.length_squared() > 0.5)
}

/// `normals` where they are unit vectors; elsewhere (a split scheme's creases and corners,
/// parallel tangents) the area-weighted normal of the output faces, as `.glb` shading uses.
/// `None` when every normal is a unit vector already (the face normals are not computed).
pub(crate) fn normals_or_faces(
    normals: &[subd_mesh::DVec3],
    view: &subd_io::MeshView<'_>,
) -> Option<Vec<subd_mesh::DVec3>> {
    if all_unit(normals) {
        return None;
    }
    let is_unit = |n: &subd_mesh::DVec3| n.is_finite() && n.length_squared() > 0.5;
    let from_faces = subd_io::glb::vertex_normals(view);
    Some(
        normals
            .iter()
            .zip(from_faces)
            .map(|(n, f)| {
                if is_unit(n) {
                    *n
                } else {
                    f.try_normalize().unwrap_or(subd_mesh::DVec3::Z)
                }
            })
            .collect(),
    )
}
