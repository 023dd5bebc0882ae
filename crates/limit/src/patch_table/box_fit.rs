//! The matrix that fits a quartic box-spline triangle (12 points) to a quartic Bézier
//! triangle (15 points), for Loop's box-spline end caps.
//!
//! The box splines span only 12 of the 15 dimensions of quartic polynomials, so the fit is
//! a least-squares one. OpenSubdiv's `convertToLoop` describes it: the two patches agree on
//! their boundary curves (12 constraints, of rank 11: a box spline's three boundary
//! quartics are not independent) and at the patch's midpoint, and the conversion is the
//! pseudo-inverse of those 13 constraints. Worked back from its coefficients, the boundary
//! constraints are positions at four points per edge (parameters 0, ¼, ½ and ¾ from each
//! corner) and the midpoint is the centroid: the least-squares solution over exactly those
//! points has the same structure as OpenSubdiv's table and agrees with it to 2.6e-5 per
//! entry. It cannot be made to agree further: OpenSubdiv's constants (float literals with
//! 6 decimals) are not a rounding of the exact solution (rationals with denominators
//! dividing 1152), their errors are not symmetric where the exact values are, and its rows
//! sum to 1 only within 2e-6, so its table was derived numerically in low precision (no
//! single-precision least-squares route tried reproduced it). Here the matrix is derived
//! in double precision from the box-spline basis and the Bernstein polynomials; patches
//! fitted with it differ from OpenSubdiv's by about 1e-6 of the mesh size.

use std::sync::OnceLock;

use faer::Mat;
use faer::linalg::solvers::SolveLstsq;

use super::basis;

/// Row `i`: box-spline point `i` (OpenSubdiv's layout) as weights of the 15 Bézier points
/// `p_{ijk}` (row by row from corner 0: `p004, p103, p202, p301, p400, p013, …, p040`).
pub(crate) type FitMatrix = [[f64; 15]; 12];

/// The fitting points: four per edge (corner 0 → 1, 1 → 2, 2 → 0) at parameters 0, ¼, ½,
/// ¾, then the centroid.
fn fit_points() -> Vec<(f64, f64)> {
    let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)];
    let mut out = Vec::with_capacity(13);
    for e in 0..3 {
        let (a, b) = (corners[e], corners[(e + 1) % 3]);
        for q in 0..4 {
            let x = f64::from(q) / 4.0;
            out.push((a.0 + x * (b.0 - a.0), a.1 + x * (b.1 - a.1)));
        }
    }
    out.push((1.0 / 3.0, 1.0 / 3.0));
    out
}

/// Least squares over the fitting points: box spline = Bézier triangle there.
fn derive() -> FitMatrix {
    let points = fit_points();
    let box_weights: Vec<[f64; 12]> = points
        .iter()
        .map(|&(s, t)| {
            let spline = crate::evaluation::loop_patch::box_spline()
                .expect("the box-spline basis derives on a fixed grid");
            basis::box_spline(spline, s, t, 0)[0]
        })
        .collect();
    let a = Mat::<f64>::from_fn(points.len(), 12, |r, i| box_weights[r][i]);
    let rhs = Mat::<f64>::from_fn(points.len(), 15, |r, q| {
        let (s, t) = points[r];
        basis::bezier_triangle(s, t)[0][q]
    });
    let x = a.qr().solve_lstsq(&rhs);
    std::array::from_fn(|i| std::array::from_fn(|q| x[(i, q)]))
}

/// The fitting matrix, derived once.
pub(crate) fn matrix() -> &'static FitMatrix {
    static MATRIX: OnceLock<FitMatrix> = OnceLock::new();
    MATRIX.get_or_init(derive)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Exact rational entries of the least-squares fit (computed apart with rational
    /// arithmetic) at a few places: corner, edge and interior Bézier points.
    #[test]
    fn the_fit_equals_its_exact_rational_values() {
        let m = matrix();
        let exact = [
            (0, 0, 9463.0 / 1152.0),
            (0, 1, 4361.0 / 576.0),
            (0, 2, -2953.0 / 384.0),
            (0, 5, -9463.0 / 576.0),
            (0, 6, 2.0 / 3.0),
            (1, 2, 2593.0 / 384.0),
            (1, 6, -10.0 / 3.0),
            (4, 0, -937.0 / 1152.0),
            (4, 2, -99.0 / 128.0),
            (4, 11, 157.0 / 128.0),
        ];
        for (i, q, want) in exact {
            assert!(
                (m[i][q] - want).abs() < 1e-12,
                "[{i}][{q}] = {} vs {want}",
                m[i][q]
            );
        }
    }

    #[test]
    fn rows_are_affine_and_fit_a_box_spline_back_to_itself() {
        let m = matrix();
        for row in m {
            assert!((row.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        }
        // The Bézier net of a box-spline patch: its values at enough points determine it;
        // fitting it must give the box-spline points back.
        let spline = crate::evaluation::loop_patch::box_spline().unwrap();
        let controls: Vec<f64> = (0..12).map(|i| ((i * 7 + 3) % 11) as f64 - 4.0).collect();
        let samples: Vec<(f64, f64)> = (0..5)
            .flat_map(|j| (0..5 - j).map(move |i| (f64::from(i) / 4.0, f64::from(j) / 4.0)))
            .collect();
        let values: Vec<f64> = samples
            .iter()
            .map(|&(s, t)| {
                let w = basis::box_spline(spline, s, t, 0)[0];
                w.iter().zip(&controls).map(|(a, b)| a * b).sum()
            })
            .collect();
        let bern = Mat::<f64>::from_fn(15, 15, |r, q| {
            basis::bezier_triangle(samples[r].0, samples[r].1)[0][q]
        });
        let net = bern
            .qr()
            .solve_lstsq(Mat::<f64>::from_fn(15, 1, |r, _| values[r]));
        for (i, row) in m.iter().enumerate() {
            let back: f64 = row.iter().enumerate().map(|(q, w)| w * net[(q, 0)]).sum();
            assert!((back - controls[i]).abs() < 1e-10, "point {i}: {back}");
        }
    }
}
