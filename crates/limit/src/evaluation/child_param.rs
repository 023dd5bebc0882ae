//! Where a point of a face lies among the face's children after one refinement step.

/// The child of a quad holding (u, v) and the parameters in it: child j has the parent's
/// corner j at its corner j (OpenSubdiv's order), `(0,0)` at its first vertex.
pub(crate) fn quadrant(u: f64, v: f64) -> (usize, f64, f64) {
    match (u >= 0.5, v >= 0.5) {
        (false, false) => (0, 2.0 * u, 2.0 * v),
        (true, false) => (1, 2.0 * u - 1.0, 2.0 * v),
        (true, true) => (2, 2.0 * u - 1.0, 2.0 * v - 1.0),
        (false, true) => (3, 2.0 * u, 2.0 * v - 1.0),
    }
}

/// The child of a Loop triangle holding (u, v), its parameters there, and the scale of the
/// map (negative for the middle child, which is turned around): children
/// `(V0,E0,E2)`, `(E0,V1,E1)`, `(E2,E1,V2)`, `(E1,E2,E0)` in OpenSubdiv's order.
pub(crate) fn tri_child(u: f64, v: f64) -> (usize, f64, f64, f64) {
    if u >= 0.5 {
        (1, 2.0 * u - 1.0, 2.0 * v, 2.0)
    } else if v >= 0.5 {
        (2, 2.0 * u, 2.0 * v - 1.0, 2.0)
    } else if u + v < 0.5 {
        (0, 2.0 * u, 2.0 * v, 2.0)
    } else {
        (3, 1.0 - 2.0 * u, 1.0 - 2.0 * v, -2.0)
    }
}
