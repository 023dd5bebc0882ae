//! Closed-form limit masks of one vertex over its 1-ring: position and two tangents, for
//! Catmull-Clark and Loop, by vertex rule.
//!
//! A mask has a weight for the vertex, one per incident edge (applied to the vertex at the
//! other end, in vertex-edge order) and, for Catmull-Clark, one per incident face (applied to
//! the face's vertex diagonally opposite the centre, in vertex-face order; face `i` lies
//! between edges `i` and `i + 1`). The formulas are those OpenSubdiv's `Sdc` uses, so that
//! limit points agree with `PrimvarRefiner::Limit`:
//!
//! * Catmull-Clark smooth position: Halstead, Kass & DeRose, "Efficient, fair interpolation
//!   using Catmull-Clark surfaces" (SIGGRAPH 1993), eq. for the limit point:
//!   `(n² v + 4 Σ e_i + Σ f_i) / (n (n + 5))`; tangents from the same paper's eigenvectors,
//!   `Σ 4 cos(2πi/n) e_i + c (cos(2πi/n) + cos(2π(i+1)/n)) f_i` with `c = 1/(4λ − 1)` and λ
//!   the subdominant eigenvalue (the subdivision lecture notes §5).
//! * Crease position `(e_a + 4 v + e_b) / 6` (the cubic B-spline limit of the crease curve);
//!   cross-crease tangent: Biermann, Levin & Zorin, "Piecewise smooth subdivision surfaces
//!   with normal control" (SIGGRAPH 2000), with k = faces between the crease edges.
//! * Loop smooth position: Loop (1987), `e = 1 / (n + 3/(8γ))`, `γ = (5/8 − β̂²)/n`,
//!   `β̂ = 3/8 + cos(2π/n)/4`; tangents `Σ cos(2πi/n) e_i`, `Σ sin(2πi/n) e_i`; crease
//!   cross tangents from Hoppe et al., "Piecewise smooth surface reconstruction" (SIGGRAPH
//!   1994).
//! * Corner: the vertex itself; tangents along its first two edges.
//!
//! **Tangent convention.** `tangent1` points along edge 0 (for a crease: along the first
//! crease edge, the "leading" one), `tangent2` across, rotated counter-clockwise, so
//! `tangent1 × tangent2` is the outward normal of a counter-clockwise mesh. Tangents are
//! derivatives up to a positive scale that depends on the valence (the scales OpenSubdiv
//! uses, so tangents agree with it too); only their directions and the normal are defined
//! exactly.

use std::f64::consts::PI;

/// Weights of one mask over a vertex's 1-ring (see the module docs for the layout).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RingMask {
    /// Weight of the vertex itself.
    pub vertex: f64,
    /// Weight of the far end of each incident edge, in vertex-edge order.
    pub edges: Vec<f64>,
    /// Weight of the vertex opposite the centre in each incident face, in vertex-face order
    /// (empty for Loop and for masks without face terms).
    pub faces: Vec<f64>,
}

impl RingMask {
    fn new(vertex: f64, edges: usize, faces: usize) -> RingMask {
        RingMask {
            vertex,
            edges: vec![0.0; edges],
            faces: vec![0.0; faces],
        }
    }

    /// Sum of all weights (1 for positions, 0 for tangents).
    pub fn sum(&self) -> f64 {
        self.faces.iter().sum::<f64>() + self.edges.iter().sum::<f64>() + self.vertex
    }
}

/// Limit position and tangent masks of one vertex.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LimitMask {
    /// Limit position.
    pub position: RingMask,
    /// First tangent (along edge 0, or along the crease).
    pub tangent1: RingMask,
    /// Second tangent (counter-clockwise from the first, or across the crease).
    pub tangent2: RingMask,
}

/// Catmull-Clark subdominant eigenvalue for valence `n` (the subdivision lecture notes §5):
/// `λ = (4 + A_n)/16`, `A_n = 1 + cos(2π/n) + cos(π/n)·sqrt(2(9 + cos(2π/n)))`.
pub fn catmark_subdominant(n: usize) -> f64 {
    let c = (2.0 * PI / n as f64).cos();
    let a = 1.0 + c + (PI / n as f64).cos() * (2.0 * (9.0 + c)).sqrt();
    (4.0 + a) / 16.0
}

/// Loop subdominant eigenvalue for valence `n` (the subdivision lecture notes §5): `3/8 +
/// cos(2π/n)/4`.
pub fn loop_subdominant(n: usize) -> f64 {
    0.375 + 0.25 * (2.0 * PI / n as f64).cos()
}

/// Catmull-Clark smooth interior vertex of valence `n ≥ 3` with all faces quads.
pub fn catmark_smooth(n: usize) -> LimitMask {
    let mut pos = RingMask::new(0.0, n, n);
    if n == 4 {
        pos.vertex = 4.0 / 9.0;
        pos.edges.fill(1.0 / 9.0);
        pos.faces.fill(1.0 / 36.0);
    } else {
        let nf = n as f64;
        let f = 1.0 / (nf * (nf + 5.0));
        let e = 4.0 * f;
        pos.vertex = 1.0 - nf * (e + f);
        pos.edges.fill(e);
        pos.faces.fill(f);
    }
    let mut t1 = RingMask::new(0.0, n, n);
    if n == 4 {
        t1.edges.copy_from_slice(&[4.0, 0.0, -4.0, 0.0]);
        t1.faces.copy_from_slice(&[1.0, -1.0, -1.0, 1.0]);
    } else {
        let theta = 2.0 * PI / n as f64;
        // Face scale 1/(4λ − 1) makes the face and edge terms one eigenvector.
        let face_scale = 1.0 / (4.0 * catmark_subdominant(n) - 1.0);
        for i in 0..n {
            let (ci, cj) = ((i as f64 * theta).cos(), ((i + 1) as f64 * theta).cos());
            t1.edges[i] = 4.0 * ci;
            t1.faces[i] = face_scale * (ci + cj);
        }
    }
    // The second tangent is the first rotated by one edge counter-clockwise.
    let mut t2 = RingMask::new(0.0, n, n);
    for i in 0..n {
        t2.edges[(i + 1) % n] = t1.edges[i];
        t2.faces[(i + 1) % n] = t1.faces[i];
    }
    LimitMask {
        position: pos,
        tangent1: t1,
        tangent2: t2,
    }
}

/// Corner: the vertex itself; tangents along edges 0 and 1 (`scale` times the difference:
/// 1 for Catmull-Clark, 3 for Loop, as OpenSubdiv scales them).
pub fn corner(num_edges: usize, num_faces: usize, scale: f64) -> LimitMask {
    let mut t1 = RingMask::new(-scale, num_edges, num_faces);
    let mut t2 = RingMask::new(-scale, num_edges, num_faces);
    if num_edges > 0 {
        t1.edges[0] = scale;
    }
    if num_edges > 1 {
        t2.edges[1] = scale;
    }
    LimitMask {
        position: RingMask::new(1.0, num_edges, num_faces),
        tangent1: t1,
        tangent2: t2,
    }
}

/// Position of a crease vertex: `(e_a + 4 v + e_b)/6`, for both schemes.
fn crease_position(num_edges: usize, num_faces: usize, ends: (usize, usize)) -> RingMask {
    let mut pos = RingMask::new(2.0 / 3.0, num_edges, num_faces);
    pos.edges[ends.0] = 1.0 / 6.0;
    pos.edges[ends.1] = 1.0 / 6.0;
    pos
}

/// Catmull-Clark crease vertex with crease edges at positions `ends` (`ends.0 < ends.1`) of
/// its `num_edges` edges; the cross tangent is taken over the faces from `ends.0` to
/// `ends.1` counter-clockwise (Biermann, Levin & Zorin 2000).
pub fn catmark_crease(num_edges: usize, num_faces: usize, ends: (usize, usize)) -> LimitMask {
    let mut t1 = RingMask::new(0.0, num_edges, num_faces);
    t1.edges[ends.0] = 0.5;
    t1.edges[ends.1] = -0.5;
    let mut t2 = RingMask::new(0.0, num_edges, num_faces);
    let interior = ends.1 - ends.0 - 1;
    match interior {
        0 => {
            // One face: the average of the two crease edges, pointing into the face.
            t2.vertex = -6.0;
            t2.edges[ends.0] = 3.0;
            t2.edges[ends.1] = 3.0;
        }
        1 => {
            // Regular crease: the uniform cubic B-spline cross derivative.
            t2.vertex = -4.0 / 6.0;
            t2.edges[ends.0] = -1.0 / 6.0;
            t2.edges[ends.0 + 1] = 4.0 / 6.0;
            t2.edges[ends.1] = -1.0 / 6.0;
            t2.faces[ends.0] = 1.0 / 6.0;
            t2.faces[ends.0 + 1] = 1.0 / 6.0;
        }
        _ => {
            let k = (interior + 1) as f64;
            let theta = PI / k;
            let (c, s) = (theta.cos(), theta.sin());
            let denom = 1.0 / (k * (3.0 + c));
            let r = (c + 1.0) / s;
            t2.vertex = 4.0 * r * (c - 1.0) * denom;
            t2.edges[ends.0] = -r * (1.0 + 2.0 * c) * denom;
            t2.edges[ends.1] = -r * (1.0 + 2.0 * c) * denom;
            t2.faces[ends.0] = s * denom;
            for i in 1..=interior {
                let si = (i as f64 * theta).sin();
                let sj = ((i + 1) as f64 * theta).sin();
                t2.edges[ends.0 + i] = 4.0 * si * denom;
                t2.faces[ends.0 + i] = (si + sj) * denom;
            }
        }
    }
    LimitMask {
        position: crease_position(num_edges, num_faces, ends),
        tangent1: t1,
        tangent2: t2,
    }
}

/// Loop smooth interior vertex of valence `n`.
pub fn loop_smooth(n: usize) -> LimitMask {
    let mut pos = RingMask::new(0.0, n, 0);
    if n == 6 {
        pos.vertex = 0.5;
        pos.edges.fill(1.0 / 12.0);
    } else {
        let nf = n as f64;
        let beta = loop_subdominant(n);
        let gamma = (0.625 - beta * beta) / nf;
        let e = 1.0 / (nf + 3.0 / (8.0 * gamma));
        pos.vertex = 1.0 - e * nf;
        pos.edges.fill(e);
    }
    let mut t1 = RingMask::new(0.0, n, 0);
    let mut t2 = RingMask::new(0.0, n, 0);
    if n == 6 {
        let h = 0.5 * 3f64.sqrt();
        t1.edges.copy_from_slice(&[1.0, 0.5, -0.5, -1.0, -0.5, 0.5]);
        t2.edges.copy_from_slice(&[0.0, h, h, 0.0, -h, -h]);
    } else {
        let alpha = 2.0 * PI / n as f64;
        for i in 0..n {
            t1.edges[i] = (alpha * i as f64).cos();
            t2.edges[i] = (alpha * i as f64).sin();
        }
    }
    LimitMask {
        position: pos,
        tangent1: t1,
        tangent2: t2,
    }
}

/// Loop crease vertex (Hoppe et al. 1994 cross tangents, oriented into the surface between
/// the crease edges, scaled as OpenSubdiv scales them).
pub fn loop_crease(num_edges: usize, ends: (usize, usize)) -> LimitMask {
    let mut t1 = RingMask::new(0.0, num_edges, 0);
    t1.edges[ends.0] = 1.5;
    t1.edges[ends.1] = -1.5;
    let mut t2 = RingMask::new(0.0, num_edges, 0);
    let interior = ends.1 - ends.0 - 1;
    match interior {
        0 => {
            t2.vertex = -6.0;
            t2.edges[ends.0] = 3.0;
            t2.edges[ends.1] = 3.0;
        }
        1 => {
            t2.vertex = -3.0;
            t2.edges[ends.0 + 1] = 3.0;
        }
        2 => {
            let r3 = 3f64.sqrt();
            t2.vertex = -r3;
            t2.edges[ends.0] = -0.5 * r3;
            t2.edges[ends.1] = -0.5 * r3;
            t2.edges[ends.0 + 1] = r3;
            t2.edges[ends.0 + 2] = r3;
        }
        _ => {
            let theta = PI / (interior + 1) as f64;
            let c = -3.0 * theta.sin();
            t2.edges[ends.0] = c;
            t2.edges[ends.1] = c;
            let e = -6.0 * (theta.cos() - 1.0);
            for i in 1..=interior {
                t2.edges[ends.0 + i] = e * (i as f64 * theta).sin();
            }
        }
    }
    LimitMask {
        position: crease_position(num_edges, 0, ends),
        tangent1: t1,
        tangent2: t2,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_are_affine_and_tangents_annihilate_constants() {
        for n in 3..=12 {
            for m in [catmark_smooth(n), loop_smooth(n)] {
                assert!((m.position.sum() - 1.0).abs() < 1e-14, "n={n}");
                assert!(m.tangent1.sum().abs() < 1e-12, "n={n}");
                assert!(m.tangent2.sum().abs() < 1e-12, "n={n}");
            }
        }
        for (ne, nf, ends) in [
            (3, 2, (0, 2)),
            (4, 3, (0, 3)),
            (6, 6, (1, 4)),
            (2, 1, (0, 1)),
        ] {
            let m = catmark_crease(ne, nf, ends);
            assert!((m.position.sum() - 1.0).abs() < 1e-14);
            assert!(m.tangent1.sum().abs() < 1e-12);
            assert!(m.tangent2.sum().abs() < 1e-12, "{ne} {ends:?}");
            let m = loop_crease(ne, ends);
            assert!(m.tangent2.sum().abs() < 1e-12, "{ne} {ends:?}");
        }
    }

    #[test]
    fn general_formulas_reduce_to_the_regular_ones() {
        // The valence-4 Catmull-Clark and valence-6 Loop special cases equal the general
        // formulas (a check on both).
        let n = 4.0f64;
        let f = 1.0 / (n * (n + 5.0));
        assert!((f - 1.0 / 36.0).abs() < 1e-16 && (4.0 * f - 1.0 / 9.0).abs() < 1e-16);
        let beta = loop_subdominant(6);
        let gamma = (0.625 - beta * beta) / 6.0;
        let e = 1.0 / (6.0 + 3.0 / (8.0 * gamma));
        assert!((e - 1.0 / 12.0).abs() < 1e-15);
        assert!((catmark_subdominant(4) - 0.5).abs() < 1e-15);
        assert!((loop_subdominant(6) - 0.5).abs() < 1e-15);
    }
}
