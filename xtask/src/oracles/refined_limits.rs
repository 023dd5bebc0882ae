//! The exact limits of a uniform refinement's vertices: the reference the conformance
//! checks use where OpenSubdiv's patch evaluation is not exact.

use subd_mesh::{DVec3, Topology};
use subd_schemes::{Options, Refinement, Scheme};

/// Uniform refinement past semi-sharp decay (at least 4 levels) and the exact limits of its
/// vertices: the independent reference used where OpenSubdiv's patch evaluation is not exact.
pub(crate) struct RefinedLimits {
    refinement: Refinement,
    level: usize,
    limits: subd_limit::LimitPoints,
}

impl RefinedLimits {
    /// `None` where the mesh would be too large to refine that far here.
    pub(crate) fn new(
        topo: &Topology,
        positions: &[DVec3],
        scheme: &Scheme,
        options: &Options,
    ) -> Option<RefinedLimits> {
        let level = subd_limit::levels_for_exact_limit(topo, scheme).0.max(4);
        if topo.num_face_vertices() << (2 * level) > 1 << 23 {
            return None;
        }
        let refinement = Refinement::new(topo, scheme.clone(), options, level).ok()?;
        let table = subd_limit::LimitStencilTable::at_level(&refinement, level).ok()?;
        let limits = table.apply(&refinement.refine_points(positions)[level]);
        Some(RefinedLimits {
            refinement,
            level,
            limits,
        })
    }

    /// The limit of the refined vertex at dyadic parameter (u, v) of base face `f` (a quad
    /// for Catmull-Clark, a triangle for Loop); `None` off the refined vertices.
    pub(crate) fn at(&self, f: usize, u: f64, v: f64) -> Option<DVec3> {
        subd_limit::eval::dyadic_vertex(&self.refinement, self.level, f, u, v)
            .map(|vtx| self.limits.positions[vtx])
    }

    /// Whether subd's evaluation of ptex face `(f, sub)` equals the limit of the refined
    /// vertices at dyadic parameters, to 1e-12 of the diagonal (quads and Loop triangles).
    pub(crate) fn agrees(
        &self,
        table: &subd_limit::patches::PatchTable,
        (f, sub): (usize, usize),
        diag: f64,
    ) -> bool {
        use subd_limit::eval::{FaceParam, dyadic_vertex};
        let params = [
            (0.5, 0.5),
            (0.25, 0.25),
            (0.125, 0.1875),
            (0.5, 0.25),
            (0.0625, 0.375),
        ];
        params.iter().all(|&(u, v)| {
            let Some(vtx) = dyadic_vertex(&self.refinement, self.level, f, u, v) else {
                return false;
            };
            table
                .evaluate(FaceParam { face: f, sub, u, v })
                .is_ok_and(|p| (p.position - self.limits.positions[vtx]).length() <= 1e-12 * diag)
        })
    }
}
