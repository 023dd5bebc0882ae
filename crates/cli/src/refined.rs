//! A refinement as the commands hold it: [`RefinementWithLimit`] (the library's
//! `Refinement`, and the limit stencils of a split scheme's last level once asked for), the
//! exact limit of its output level, and the normals a writer gets where the limit defines
//! none.

use subd_limit::LimitStencilTable;
use subd_schemes::{Refinement, Scheme};

/// A refinement, and the limit stencils of a split scheme's last level once asked for: the
/// positions and the texture coordinates take their limits through the same ones.
pub(crate) struct RefinementWithLimit {
    refinement: Refinement,
    last_limit: std::sync::OnceLock<Result<LimitStencilTable, String>>,
}

impl std::ops::Deref for RefinementWithLimit {
    type Target = Refinement;
    fn deref(&self) -> &Refinement {
        &self.refinement
    }
}

impl RefinementWithLimit {
    /// Refines `base` with `scheme`; the error names the element.
    pub(crate) fn new(
        base: &subd_mesh::Topology,
        scheme: Scheme,
        options: &subd_schemes::Options,
        levels: usize,
    ) -> Result<RefinementWithLimit, String> {
        Ok(RefinementWithLimit {
            refinement: Refinement::new(base, scheme, options, levels)
                .map_err(|e| e.to_string())?,
            last_limit: std::sync::OnceLock::new(),
        })
    }

    /// The limit stencils of a split scheme's last level, built on first request.
    pub(crate) fn last_limit(&self) -> Result<&LimitStencilTable, String> {
        self.last_limit
            .get_or_init(|| {
                let last = self.topology(self.num_levels());
                subd_limit::split_limit::split_limit_table(last, self.scheme())
                    .map_err(|e| e.to_string())
            })
            .as_ref()
            .map_err(Clone::clone)
    }

    /// Edges of the level; not counted for a split scheme's last level, whose edges are
    /// never built.
    pub(crate) fn edges(&self, level: usize) -> Option<usize> {
        if self.scheme().is_opensubdiv() {
            self.num_edges(level)
        } else {
            None
        }
    }

    pub(crate) fn last_positions(&self, base: &[subd_mesh::DVec3]) -> Vec<subd_mesh::DVec3> {
        // Each level dropped once the next is computed.
        self.points_at(base, self.num_levels())
    }
}

/// The exact limit (positions and normals) of the vertices of the output level, from the
/// limit masks of that level's own topology: what Blender calls "use limit surface".
pub(crate) fn output_limit(
    refinement: &RefinementWithLimit,
    level: usize,
    options: &subd_schemes::Options,
    positions: &[subd_mesh::DVec3],
) -> Result<subd_limit::LimitPoints, String> {
    let scheme = &refinement.scheme().at_level(level);
    if scheme.is_opensubdiv() || level < refinement.num_levels() {
        return subd_limit::level_limit_points(
            refinement,
            level,
            options,
            positions,
            subd_limit::Tangents::Dropped,
        )
        .map_err(|e| e.to_string());
    }
    // A split scheme's last level: the stencils its texture coordinates share.
    Ok(refinement.last_limit()?.apply(positions))
}

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
