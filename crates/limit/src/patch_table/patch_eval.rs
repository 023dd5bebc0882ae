//! One patch evaluated: its basis at a place of its root face (derivatives taken back to
//! the root's parameters) and the weighted sums of its control points.

use glam::DVec3;

use super::basis;
use super::{PatchParam, PatchType};
use crate::evaluation::patch::SurfacePoint;

/// The weights of a patch's control points at a place: position, ∂u, ∂v, ∂uu, ∂uv, ∂vv
/// with respect to the root face's parameters ([`super::PatchTable::evaluate_basis`],
/// OpenSubdiv's `PatchTable::EvaluateBasis`).
#[derive(Debug, Clone, PartialEq)]
pub struct PatchWeights {
    /// One row per quantity (position, du, dv, duu, duv, dvv), one weight per control point.
    pub rows: [Vec<f64>; 6],
}

/// The basis of a patch of type `kind` with parameter `param` at `(u, v)` of its root face:
/// its 20 weight slots per row (the first `n` used) in the patch's own domain, scaled to the
/// root's parameters.
pub(crate) fn patch_weights(kind: PatchType, param: PatchParam, u: f64, v: f64) -> [[f64; 20]; 6] {
    let triangle = matches!(
        kind,
        PatchType::Loop | PatchType::Triangles | PatchType::GregoryTriangle
    );
    let (s, t) = if triangle {
        param.normalize_triangle(u, v)
    } else {
        param.normalize(u, v)
    };
    let mut d1 = 1.0 / param.fraction();
    if triangle && param.is_triangle_rotated() {
        d1 = -d1;
    }
    let mut w = basis::weights(kind, s, t, param.basis_boundary());
    let d2 = d1 * d1;
    for (row, scale) in w.iter_mut().zip([1.0, d1, d1, d2, d2, d2]) {
        for x in row.iter_mut() {
            *x *= scale;
        }
    }
    w
}

/// Evaluates one patch of type `kind` at `(u, v)` of its root face: the basis in the
/// patch's own domain, derivatives taken back to the root's parameters.
pub(crate) fn evaluate_patch(
    kind: PatchType,
    param: PatchParam,
    cps: &[u32],
    points: &[DVec3],
    u: f64,
    v: f64,
) -> SurfacePoint {
    let w = patch_weights(kind, param, u, v);
    let mut acc = [DVec3::ZERO; 6];
    for (k, &cp) in cps.iter().enumerate() {
        let p = points[cp as usize];
        for (a, row) in acc.iter_mut().zip(&w) {
            *a += row[k] * p;
        }
    }
    SurfacePoint {
        position: acc[0],
        du: acc[1],
        dv: acc[2],
        duu: acc[3],
        duv: acc[4],
        dvv: acc[5],
    }
}

/// An interior bicubic B-spline patch's position and first derivatives at `(s, t)`, summed
/// row by row (the tensor product's 32 products instead of 48).
pub(crate) fn bspline_first(cps: &[u32], points: &[DVec3], s: f64, t: f64) -> [DVec3; 3] {
    let (bs, ds, _) = crate::evaluation::patch::bspline_basis(s);
    let (bt, dt, _) = crate::evaluation::patch::bspline_basis(t);
    let mut out = [DVec3::ZERO; 3];
    for (r, row) in cps.chunks_exact(4).enumerate() {
        let (mut p, mut d) = (DVec3::ZERO, DVec3::ZERO);
        for (c, &cp) in row.iter().enumerate() {
            let x = points[cp as usize];
            p += bs[c] * x;
            d += ds[c] * x;
        }
        out[0] += bt[r] * p;
        out[1] += bt[r] * d;
        out[2] += dt[r] * p;
    }
    out
}
