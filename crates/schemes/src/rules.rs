//! Crease rules shared by the surface schemes: vertex rules, sharpness decay and the
//! fractional weights of semi-sharp transitions, with OpenSubdiv's `f32` arithmetic
//! (`Sdc::Crease`).

use subd_mesh::CreaseMethod;
use subd_mesh::tags::{SHARPNESS_INFINITE, is_infinite, is_semi_sharp};

/// How a vertex is refined (OpenSubdiv's `Sdc::Crease::Rule`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Rule {
    /// No sharp incident edges: the smooth mask.
    Smooth,
    /// One sharp incident edge: still the smooth mask.
    Dart,
    /// Two sharp incident edges: the crease mask along them.
    Crease,
    /// Vertex sharpness, or three or more sharp edges: the vertex stays put.
    Corner,
}

impl Rule {
    /// The rule of a vertex with corner sharpness `vertex_sharpness` and `sharp_edges` sharp
    /// (semi or infinitely) incident edges (`Sdc::Crease::DetermineVertexVertexRule`).
    pub fn determine(vertex_sharpness: f32, sharp_edges: usize) -> Rule {
        if vertex_sharpness > 0.0 {
            return Rule::Corner;
        }
        match sharp_edges {
            0 => Rule::Smooth,
            1 => Rule::Dart,
            2 => Rule::Crease,
            _ => Rule::Corner,
        }
    }
}

/// Uniform decay of a sharpness by one level: infinite stays infinite, `s > 1` loses one,
/// anything else becomes smooth (`Sdc::Crease::decrementSharpness`).
#[inline]
pub fn decrement(s: f32) -> f32 {
    if s <= 0.0 {
        0.0
    } else if is_infinite(s) {
        SHARPNESS_INFINITE
    } else if s > 1.0 {
        s - 1.0
    } else {
        0.0
    }
}

/// Chaikin's sharpness of the half of a semi-sharp edge with sharpness `s` at an end vertex
/// whose incident edge sharpnesses are `around` (the edge itself included, in vertex-edge
/// order): `0.75 s + 0.25 · mean(other semi-sharp edges) − 1`, clamped at 0
/// (`Sdc::Crease::SubdivideEdgeSharpnessAtVertex`). Sums run in `f32`, in list order, so the
/// result is OpenSubdiv's to the bit.
pub fn chaikin(s: f32, around: impl ExactSizeIterator<Item = f32>) -> f32 {
    if around.len() < 2 {
        return decrement(s);
    }
    let mut sum = 0.0f32;
    let mut count = 0u32;
    for x in around {
        if is_semi_sharp(x) {
            sum += x;
            count += 1;
        }
    }
    let mut t = s;
    if count > 1 {
        let avg = (sum - s) / (count - 1) as f32;
        t = 0.75 * s + 0.25 * avg;
    }
    t -= 1.0;
    if t > 0.0 { t } else { 0.0 }
}

/// Sharpness of a child edge: infinite stays infinite, semi-sharp decays by the crease method
/// (`at_vertex` gives the parent edges around the end vertex, for Chaikin), smooth stays
/// smooth.
#[inline]
pub fn child_edge_sharpness(
    s: f32,
    method: CreaseMethod,
    at_vertex: impl ExactSizeIterator<Item = f32>,
) -> f32 {
    if is_infinite(s) {
        SHARPNESS_INFINITE
    } else if s > 0.0 {
        match method {
            CreaseMethod::Uniform => decrement(s),
            CreaseMethod::Chaikin => chaikin(s, at_vertex),
        }
    } else {
        0.0
    }
}

/// Sharpness of a vertex's child: infinite stays, semi-sharp decays by one, smooth stays.
#[inline]
pub fn child_vertex_sharpness(s: f32) -> f32 {
    if is_infinite(s) {
        SHARPNESS_INFINITE
    } else if s > 0.0 {
        decrement(s)
    } else {
        0.0
    }
}

/// Weight of the parent rule when a vertex's rule changes in one step
/// (`Sdc::Crease::ComputeFractionalWeightAtVertex`): the mean sharpness of what decayed — the
/// vertex itself if its sharpness reached 0, and each semi-sharp edge that "transitions"
/// (uniform: every edge with `0 < s ≤ 1`; Chaikin: every sharp edge whose child is smooth) —
/// clamped to 1. `edges` yields (parent, child) sharpness per incident edge in vertex-edge
/// order; `f32` throughout.
pub fn fractional_weight(
    parent_vertex: f32,
    child_vertex: f32,
    edges: impl IntoIterator<Item = (f32, f32)>,
    method: CreaseMethod,
) -> f32 {
    let mut sum = 0.0f32;
    let mut n = 0u32;
    if parent_vertex > 0.0 && child_vertex <= 0.0 {
        sum = parent_vertex;
        n = 1;
    }
    for (p, c) in edges {
        let include = match method {
            CreaseMethod::Uniform => p > 0.0 && p <= 1.0,
            CreaseMethod::Chaikin => p > 0.0 && c <= 0.0,
        };
        if include {
            sum += p;
            n += 1;
        }
    }
    let w = if n > 0 { sum / n as f32 } else { 0.0 };
    w.min(1.0)
}

/// Positions, among `count` incident edges in vertex-edge order, of the two edges a crease
/// mask uses: the first sharp edge from the front and the first from the back
/// (`Sdc::Crease::GetSharpEdgePairOfCrease`).
pub fn crease_pair(count: usize, is_sharp: impl Fn(usize) -> bool) -> (usize, usize) {
    let first = (0..count).find(|&i| is_sharp(i)).unwrap_or(0);
    let last = (0..count).rev().find(|&i| is_sharp(i)).unwrap_or(first);
    (first, last)
}

/// Loop's smooth vertex weights (edge weight, vertex weight) for valence `n`
/// (`Sdc::Scheme<SCHEME_LOOP>::assignSmoothMaskForVertex`).
pub fn loop_smooth_weights(n: usize) -> (f64, f64) {
    if n == 6 {
        return (0.0625, 0.625);
    }
    let inv = 1.0 / n as f64;
    let cos_t = (std::f64::consts::PI * 2.0 * inv).cos();
    let beta = 0.25 * cos_t + 0.375;
    let e = (0.625 - beta * beta) * inv;
    (e, 1.0 - e * n as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crease_pair_takes_outermost_sharp_edges() {
        let s = [0.0f32, 2.0, 0.0, 1.0, 0.0];
        assert_eq!(crease_pair(s.len(), |i| s[i] > 0.0), (1, 3));
    }

    #[test]
    fn rules_by_sharp_edge_count() {
        assert_eq!(Rule::determine(0.0, 0), Rule::Smooth);
        assert_eq!(Rule::determine(0.0, 1), Rule::Dart);
        assert_eq!(Rule::determine(0.0, 2), Rule::Crease);
        assert_eq!(Rule::determine(0.0, 3), Rule::Corner);
        assert_eq!(Rule::determine(0.5, 0), Rule::Corner);
    }

    #[test]
    fn uniform_decay_in_f32() {
        assert_eq!(decrement(7.9), 7.9f32 - 1.0);
        assert_eq!(decrement(1.0), 0.0);
        assert_eq!(decrement(12.0), SHARPNESS_INFINITE);
        // 7.9 in f32 is 7.9000001: after 7 levels 0.9000001, not 0.9.
        let mut s = 7.9f32;
        for _ in 0..7 {
            s = decrement(s);
        }
        assert_eq!(s, 0.900_000_1f32);
        assert_ne!(s as f64, 0.9);
    }

    #[test]
    fn chaikin_averages_the_other_semi_sharp_edges() {
        // Edge 2.0 with neighbours 1.0 (semi) and 10 (infinite, ignored): 0.75·2 + 0.25·1 − 1.
        let around = [2.0f32, 1.0, 10.0];
        assert_eq!(chaikin(2.0, around.iter().copied()), 0.75);
        // Alone among semi-sharp edges: plain decrement.
        assert_eq!(chaikin(2.0, [2.0f32, 0.0].iter().copied()), 1.0);
    }

    #[test]
    fn fractional_weight_means_what_decays() {
        // Uniform: edges with s ≤ 1 transition; 0.5 and 1.0 average to 0.75.
        let edges = [(0.5, 0.0), (1.0, 0.0), (3.0, 2.0)];
        let w = fractional_weight(0.0, 0.0, edges, CreaseMethod::Uniform);
        assert_eq!(w, 0.75);
        // A decayed vertex sharpness counts too, and the mean is clamped at 1.
        let w = fractional_weight(3.0, 0.0, [], CreaseMethod::Uniform);
        assert_eq!(w, 1.0);
        // Chaikin counts the edges whose child became smooth.
        let w = fractional_weight(0.0, 0.0, [(1.5, 0.0), (2.5, 0.5)], CreaseMethod::Chaikin);
        assert_eq!(w, 1.0);
        let w = fractional_weight(0.0, 0.0, [(0.25, 0.0), (0.75, 0.0)], CreaseMethod::Chaikin);
        assert_eq!(w, 0.5);
    }
}
