//! The checkerboard preconditioner for the Catmull-Clark family: its derivation (the module
//! holds no public items; the solvers use it through [`crate::Solver`]).
//!
//! On a regular quad grid the Catmull-Clark limit mask is the tensor product of the 1D
//! mask `(1, 4, 1)/6`, whose symbol `a(θ) = (2 + cos θ)/3` lies in `[1/3, 1]`: `M̄` has
//! condition number 9, and its slow modes are the *highest* frequencies (the checkerboard,
//! `θ = π`). Conjugating by the checkerboard signs `S = diag(±1)` (neighbours along an edge
//! get opposite signs) shifts every frequency by `π`, so `S M̄ S` has the symbol
//! `a(θ₁ + π) a(θ₂ + π)` and
//!
//! ```text
//! a(θ) · a(θ + π) = (4 − cos² θ) / 9  ∈ [1/3, 4/9]
//! ```
//!
//! per direction: `S M̄ S` is an approximate inverse of `M̄` up to scale, and the
//! preconditioned operator has condition number `(4/3)² = 16/9` instead of 9 (CG's rate per
//! step from about 1/2 to about 1/7).
//!
//! At extraordinary vertices the mask's centre weight differs (`n/(n + 5)` at valence `n`
//! against `4/9`), and the plain conjugate no longer matches `M̄⁻¹` there: on the bench
//! torus (valences 3 and 6) the condition number of `S M̄ S M̄` is 3.0. Scaling each row
//! and column by the inverse diagonal, `T = S Δ⁻¹` (`Δ` the diagonal of `M̄`), as Jacobi
//! does, restores the regular bound: `T M̄ T M̄` has condition 1.81 on the same mesh (found
//! numerically over the scalings `Δ^p` and `C^p`; `C^{1/2}` does about as well but
//! depends on the symmetrizer's free scale). On regular regions `T` is the constant
//! `9/4 · S`, so the spectrum there is `(81/16) [1/9, 16/81] = [9/16, 1]`.
//!
//! `T M̄ T` is a valid preconditioner on any mesh: with `M̄ = C D`,
//! `C⁻¹ T M̄ T = T D T` is symmetric, and positive definite whenever `D` is. It is an
//! effective one where the vertex graph is two-coloured along edges (every closed quad
//! mesh of genus 0, and tori with even grid sizes). This is our own derivation from the
//! Fourier symbol of the limit mask.

use rayon::prelude::*;
use subd_mesh::Topology;

use crate::matrix::{CHUNK, Matrix, RowBlock};
use crate::ritz::ritz_extremes;

/// Lanczos steps for the spectral interval of `K`: its spectrum is a narrow interval
/// (condition about 16/9 on regular regions), whose ends the Ritz values find in a few steps.
const LANCZOS_STEPS: usize = 8;

/// Largest condition number of `K` for which the Chebyshev iteration is offered (its step
/// count grows as the square root; CG copes better with a few outlying eigenvalues).
const MAX_CONDITION: f64 = 100.0;

/// Entries of `K` below this fraction of their row's largest are cancellation residue: on
/// regular regions the entries between vertices of opposite colours cancel exactly in
/// exact arithmetic.
const CANCELLED: f64 = 1e-13;

/// The explicitly preconditioned operator `K = T M̄ T M̄` and the interval holding its
/// spectrum, for the Chebyshev iteration.
///
/// `K` is self-adjoint and positive in the inner product `⟨x, y⟩ = xᵀ D y` (`M̄ = C D`):
/// `D K = M̄ᵀ (T D T) M̄`. On regular regions of a two-coloured quad mesh its entries
/// between vertices of opposite colours cancel (the symbol `a(θ) a(θ + π)` is even in
/// every direction), so it has about as many entries as `M̄` itself, and one product with
/// it advances the preconditioned iteration a full step.
#[derive(Debug)]
pub(crate) struct Preconditioned {
    pub k: Matrix,
    /// Estimated smallest and largest eigenvalue of `K`.
    pub lambda_min: f64,
    pub lambda_max: f64,
}

impl Preconditioned {
    /// `K` for `M̄ = m` (symmetrizer `c`, scaling `t`, see [`conjugation`]) and its
    /// spectral interval; `None` when the Lanczos estimate finds no positive interval (`D`
    /// not positive definite) or one too wide for Chebyshev to pay off (condition above
    /// [`MAX_CONDITION`]).
    pub fn new(m: &Matrix, c: &[f64], t: &[f64]) -> Option<Preconditioned> {
        let k = product(m, t);
        let weight: Vec<f64> = c.iter().map(|c| 1.0 / c).collect();
        let (lambda_min, lambda_max) = spectral_interval(m, &k, &weight)?;
        if lambda_max > MAX_CONDITION * lambda_min {
            return None;
        }
        Some(Preconditioned {
            k,
            lambda_min,
            lambda_max,
        })
    }
}

/// `K = T M̄ T M̄` for `T` the diagonal of `scale`: `K_ij = t_i Σ_k t_k M̄_ik M̄_kj`, rows
/// in parallel blocks with one dense accumulator per worker. Columns stay in the order
/// they are met (only products use `K`).
fn product(m: &Matrix, scale: &[f64]) -> Matrix {
    let n = m.len();
    // A few block ranges per thread, each with its own scratch (`map_init` would build
    // one per rayon job, many more than threads).
    let blocks_per_task = n
        .div_ceil(CHUNK)
        .div_ceil(2 * rayon::current_num_threads())
        .max(1);
    let ranges: Vec<Vec<RowBlock>> = (0..n.div_ceil(CHUNK * blocks_per_task))
        .into_par_iter()
        .map(|t| {
            // Accumulator, and the row (+ 1) that last touched each column.
            let (mut acc, mut stamp) = (vec![0.0f64; n], vec![0u32; n]);
            let (mut touched, mut row) = (Vec::<u32>::new(), Vec::new());
            let blocks = t * blocks_per_task..((t + 1) * blocks_per_task).min(n.div_ceil(CHUNK));
            blocks
                .map(|b| {
                    let first = b * CHUNK;
                    let last = (first + CHUNK).min(n);
                    let mut blk = RowBlock::with_rows(last - first);
                    for i in first..last {
                        let mark = i as u32 + 1;
                        let (ci, wi) = m.row(i);
                        for (&k, &mik) in ci.iter().zip(wi) {
                            let f = scale[i] * scale[k as usize] * mik;
                            let (ck, wk) = m.row(k as usize);
                            for (&j, &mkj) in ck.iter().zip(wk) {
                                let j = j as usize;
                                if stamp[j] != mark {
                                    stamp[j] = mark;
                                    acc[j] = 0.0;
                                    touched.push(j as u32);
                                }
                                acc[j] += f * mkj;
                            }
                        }
                        let largest = touched
                            .iter()
                            .map(|&j| acc[j as usize].abs())
                            .fold(0.0, f64::max);
                        row.clear();
                        row.extend(
                            touched
                                .iter()
                                .map(|&j| (j, acc[j as usize]))
                                .filter(|e| e.1.abs() > CANCELLED * largest),
                        );
                        touched.clear();
                        blk.push_row(first, &row);
                    }
                    blk
                })
                .collect()
        })
        .collect();
    Matrix::from_blocks(ranges.into_iter().flatten().collect())
}

/// The interval `[λ_min, λ_max]` of `K`'s spectrum from [`LANCZOS_STEPS`] Lanczos steps in
/// the `D` inner product (`⟨x, y⟩_D = xᵀ W M̄ y`, `W = C⁻¹`), where `K` is self-adjoint.
fn spectral_interval(m: &Matrix, k: &Matrix, weight: &[f64]) -> Option<(f64, f64)> {
    let n = m.len();
    if n == 0 {
        return None;
    }
    let d_dot = |x: &[f64], mx: &[f64]| -> f64 {
        x.par_chunks(CHUNK)
            .zip(mx.par_chunks(CHUNK))
            .zip(weight.par_chunks(CHUNK))
            .map(|((x, y), w)| {
                x.iter()
                    .zip(y)
                    .zip(w)
                    .map(|((x, y), w)| x * y * w)
                    .sum::<f64>()
            })
            .collect::<Vec<f64>>()
            .into_iter()
            .sum()
    };
    // A deterministic start with every frequency present.
    let mut v: Vec<f64> = (0..n)
        .map(|i| 1.0 + ((i * 7919) % 97) as f64 / 97.0)
        .collect();
    let mut mv = vec![0.0; n];
    m.apply_scalar(&v, &mut mv);
    let norm = d_dot(&v, &mv).sqrt();
    if norm.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    v.iter_mut().zip(mv.iter_mut()).for_each(|(v, m)| {
        *v /= norm;
        *m /= norm;
    });
    let (mut v_prev, mut u, mut mu) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut alphas, mut betas) = (Vec::new(), Vec::new());
    let mut beta = 0.0;
    for _ in 0..LANCZOS_STEPS.min(n) {
        k.apply_scalar(&v, &mut u);
        let alpha = d_dot(&u, &mv);
        u.par_iter_mut()
            .zip(v.par_iter().zip(v_prev.par_iter()))
            .for_each(|(u, (v, p))| *u -= alpha * v + beta * p);
        alphas.push(alpha);
        m.apply_scalar(&u, &mut mu);
        beta = d_dot(&u, &mu).max(0.0).sqrt();
        if beta <= 1e-12 * alpha.abs() {
            break;
        }
        betas.push(beta);
        std::mem::swap(&mut v_prev, &mut v);
        v.par_iter_mut()
            .zip(u.par_iter())
            .for_each(|(v, u)| *v = u / beta);
        mv.par_iter_mut()
            .zip(mu.par_iter())
            .for_each(|(m, u)| *m = u / beta);
    }
    betas.truncate(alphas.len().saturating_sub(1));
    ritz_extremes(&alphas, &betas)
}

/// `±1` per vertex, opposite across every edge, when the vertex graph (along edges) is
/// bipartite; `None` otherwise (an odd cycle, e.g. any triangle). Found by a breadth-first
/// colouring of each connected component.
pub(crate) fn checkerboard_signs(topology: &Topology) -> Option<Vec<f64>> {
    let nv = topology.num_vertices();
    let mut sign = vec![0.0f64; nv];
    let mut queue = Vec::new();
    for root in 0..nv {
        if sign[root] != 0.0 {
            continue;
        }
        sign[root] = 1.0;
        queue.clear();
        queue.push(root as u32);
        let mut head = 0;
        while head < queue.len() {
            let v = queue[head] as usize;
            head += 1;
            for &e in topology.vertex_edges(v) {
                let [a, b] = topology.edge_vertices(e as usize);
                let w = if a as usize == v { b } else { a } as usize;
                if w == v {
                    continue;
                }
                if sign[w] == 0.0 {
                    sign[w] = -sign[v];
                    queue.push(w as u32);
                } else if sign[w] == sign[v] {
                    return None;
                }
            }
        }
    }
    Some(sign)
}

/// The preconditioner's scaling `t_i = s_i / M̄_ii` (see the module docs); `None` when a
/// diagonal entry is not positive, where the scaling has no meaning.
pub(crate) fn conjugation(signs: &[f64], diag: &[f64]) -> Option<Vec<f64>> {
    signs
        .iter()
        .zip(diag)
        .map(|(&s, &d)| (d > 0.0 && d.is_finite()).then(|| s / d))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solvers::{Controls, Method, Solver, solve};
    use crate::system::ReducedSystem;
    use crate::{Moving, Pia};
    use glam::DVec3;
    use subd_mesh::TopologyBuilder;
    use subd_schemes::Options;
    use subd_schemes::Scheme;

    /// An `n × n` quad grid on a torus: every vertex regular (valence 4).
    fn regular_torus(n: usize) -> (Topology, Vec<DVec3>) {
        let id = |i: usize, j: usize| ((i % n) * n + j % n) as u32;
        let mut faces = Vec::new();
        for i in 0..n {
            for j in 0..n {
                faces.extend([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let t = TopologyBuilder::new(n * n)
            .build(&vec![4; n * n], &faces)
            .unwrap();
        let tau = std::f64::consts::TAU;
        let points = (0..n * n)
            .map(|v| {
                let (u, w) = (
                    tau * (v / n) as f64 / n as f64,
                    tau * (v % n) as f64 / n as f64,
                );
                let r = 2.0 + 0.7 * w.cos() + 0.05 * ((7 * v) % 5) as f64;
                DVec3::new(r * u.cos(), r * u.sin(), 0.7 * w.sin())
            })
            .collect();
        (t, points)
    }

    fn whole_system(pia: &Pia, targets: &[DVec3]) -> ReducedSystem {
        pia.system(targets, &Moving::All).unwrap()
    }

    #[test]
    fn the_regular_operator_has_the_fourier_interval_and_no_opposite_colour_entries() {
        // Symbol of S M̄ S M̄ on a regular grid: Π_d (4 − cos² θ_d)/9, over [1/9, 16/81]; a
        // 16 × 16 torus has θ = 0, π/2 and π among its frequencies, so both ends are
        // eigenvalues. Every diagonal entry is 4/9, so T = (9/4) S and K's interval is
        // (81/16) [1/9, 16/81] = [9/16, 1].
        let (t, points) = regular_torus(16);
        let pia = Pia::new(&t, &Scheme::CatmullClark, &Options::default()).unwrap();
        assert!(pia.prepare());
        let s = whole_system(&pia, &points);
        let pre = s.whole_preconditioned(false).expect("prepared");
        // Entries only between same-coloured vertices at (0,0), (±2,0), (0,±2), (±2,±2).
        let signs = checkerboard_signs(&t).unwrap();
        for i in 0..s.len() {
            let (cols, _) = pre.k.row(i);
            assert_eq!(cols.len(), 9, "row {i}");
            assert!(cols.iter().all(|&j| signs[j as usize] == signs[i]));
        }
        let (lo, hi) = (9.0 / 16.0, 1.0);
        // Ritz values lie inside the spectrum and near its ends.
        assert!(pre.lambda_min >= lo - 1e-12 && pre.lambda_min <= lo * 1.03);
        assert!(pre.lambda_max <= hi + 1e-12 && pre.lambda_max >= hi * 0.99);
    }

    /// Extreme eigenvalues of `T M̄ T M̄` (dense; real, as it is similar to a symmetric
    /// matrix) for the scaling `t`.
    fn dense_interval(m: &faer::Mat<f64>, t: &[f64]) -> (f64, f64) {
        let n = m.nrows();
        let tm = faer::Mat::<f64>::from_fn(n, n, |i, j| t[i] * m[(i, j)] * t[j]);
        let k = &tm * m;
        let ev = k.eigenvalues().unwrap();
        assert!(ev.iter().all(|z| z.im.abs() < 1e-9));
        ev.iter().fold((f64::MAX, f64::MIN), |(lo, hi), z| {
            (lo.min(z.re), hi.max(z.re))
        })
    }

    #[test]
    fn diagonal_scaling_keeps_extraordinary_vertices_inside_the_regular_interval() {
        // Valence 3 and 6 after one Catmull-Clark step of a torus with hexagons (the bench
        // mesh's structure, smaller).
        let base = subd_mesh::primitives::torus_with_hexagons(12, 12, 6, 3.0, 1.0);
        let r = subd_schemes::Refinement::new(
            &base.topology,
            subd_schemes::Scheme::CatmullClark,
            &Options::default(),
            1,
        )
        .unwrap();
        let t = r.into_topology(1);
        let valences: std::collections::BTreeSet<usize> = (0..t.num_vertices())
            .map(|v| t.vertex_edges(v).len())
            .collect();
        assert_eq!(valences.into_iter().collect::<Vec<_>>(), [3, 4, 6]);
        let pia = Pia::new(&t, &Scheme::CatmullClark, &Options::default()).unwrap();
        let (_, m) = pia.moving_matrix(&Moving::All).unwrap();
        let signs = checkerboard_signs(&t).unwrap();
        let diag: Vec<f64> = (0..m.nrows()).map(|i| m[(i, i)]).collect();
        // Plain conjugation: the extraordinary vertices widen the interval well beyond the
        // regular one's condition 16/9.
        let (lo, hi) = dense_interval(&m, &signs);
        assert!(hi / lo > 2.5, "S M̄ S M̄: [{lo}, {hi}]");
        // Scaled by the inverse diagonal: close to the regular [9/16, 1].
        let (lo, hi) = dense_interval(&m, &conjugation(&signs, &diag).unwrap());
        assert!(hi / lo < 1.85, "T M̄ T M̄: [{lo}, {hi}]");
        assert!(lo > 0.5 && hi < 1.0 + 1e-9, "T M̄ T M̄: [{lo}, {hi}]");
    }

    #[test]
    fn a_wrong_interval_falls_back_to_cg() {
        let (t, points) = regular_torus(16);
        let pia = Pia::new(&t, &Scheme::CatmullClark, &Options::default()).unwrap();
        let s = whole_system(&pia, &points);
        let good = Preconditioned::new(
            &s.matrix,
            &s.symmetrizer().unwrap(),
            &s.conjugation().unwrap(),
        )
        .unwrap();
        // Half the true upper end: the modes above it grow.
        let bad = Preconditioned {
            lambda_max: good.lambda_max * 0.5,
            lambda_min: good.lambda_min * 0.5,
            k: good.k.clone(),
        };
        let ctl = Controls {
            threshold: 1e-10,
            max_iter: 1000,
        };
        let x0: Vec<DVec3> = points.clone();
        let out = crate::solvers::chebyshev(&s, &bad, &s.conjugation().unwrap(), x0.clone(), ctl);
        assert_eq!(out.method, Method::CheckerboardCg);
        assert!(*out.history.last().unwrap() <= 1e-10);
        // The right interval converges by itself, to the same solution.
        let ok = solve(&s, x0, Solver::Chebyshev, ctl).unwrap();
        assert!(matches!(ok.method, Method::Chebyshev { .. }));
        for (a, b) in ok.x.iter().zip(&out.x) {
            assert!((*a - *b).length() < 1e-8);
        }
    }

    #[test]
    fn quad_grid_is_two_coloured_and_a_triangle_is_not() {
        // 3×3 vertices, 2×2 quads.
        let faces = [0, 1, 4, 3, 1, 2, 5, 4, 3, 4, 7, 6, 4, 5, 8, 7];
        let grid = TopologyBuilder::new(9).build(&[4; 4], &faces).unwrap();
        let s = checkerboard_signs(&grid).expect("a grid is bipartite");
        for e in 0..grid.num_edges() {
            let [a, b] = grid.edge_vertices(e);
            assert_eq!(s[a as usize], -s[b as usize]);
        }
        let tri = TopologyBuilder::new(3).build(&[3], &[0, 1, 2]).unwrap();
        assert!(checkerboard_signs(&tri).is_none());
    }
}
