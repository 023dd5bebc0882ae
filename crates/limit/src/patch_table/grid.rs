//! The lattice of a tessellation's samples on one patch: how many points a grid of span
//! `m` has, where each lies in a table, which grid step a coordinate falls on, and the sum
//! of tabulated weights at one. Shared by the patch types' grids
//! ([`super::grid_samples`]) and the exact caps' ([`super::cap_grid`]).

use glam::DVec3;

/// The largest grid (points of a root face) whose non-product basis is tabulated; beyond
/// it (rates above 64) those patch types are evaluated sample by sample.
pub(super) const MAX_TABLE_POINTS: usize = 65 * 65;

/// Grid points of span `m` on a triangle or a quad.
pub(super) fn grid_points(triangle: bool, m: u32) -> usize {
    let m = m as usize;
    if triangle {
        (m + 1) * (m + 2) / 2
    } else {
        (m + 1) * (m + 1)
    }
}

/// The index of grid point `(i, j)` of span `m`, row by row.
pub(super) fn grid_index(triangle: bool, m: u32, i: u32, j: u32) -> usize {
    if triangle {
        (j * (2 * m + 3 - j) / 2 + i) as usize
    } else {
        (j * (m + 1) + i) as usize
    }
}

/// The grid step nearest `x · m`, when `x` is a grid coordinate (within rounding).
pub(super) fn grid_step(x: f64, m: u32) -> Option<u32> {
    let y = x * f64::from(m);
    if !(-0.5..=f64::from(m) + 0.5).contains(&y) {
        return None;
    }
    // Rounding by a cast (y + 0.5 ≥ 0 here): `f64::round` is a library call.
    let k = (y + 0.5) as u32;
    ((y - f64::from(k)).abs() < 1e-6 && k <= m).then_some(k)
}

/// Position and first derivatives from tabulated weights (`n` each for the position, ∂s
/// and ∂t) of the points `cps`.
pub(super) fn tabulated_first(w: &[f64], cps: &[u32], points: &[DVec3]) -> (DVec3, DVec3, DVec3) {
    let n = cps.len();
    let (mut pos, mut du, mut dv) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
    for (k, &cp) in cps.iter().enumerate() {
        let x = points[cp as usize];
        pos += w[k] * x;
        du += w[n + k] * x;
        dv += w[2 * n + k] * x;
    }
    (pos, du, dv)
}
