//! Solvers for `M̄ x = b` (see [`crate::system`]): the paper's iteration, its optimally
//! weighted version, conjugate gradients on the symmetrised system (BiCGSTAB where there is
//! none), and sparse direct factorisation with faer.
//!
//! The Krylov methods are written here rather than taken from `faer::matrix_free`: the stop
//! test is the *max-norm* of the interpolation error in model units (what the user's
//! tolerance means), every iteration's value goes into the reported history, the three
//! coordinates run in lockstep through one matrix pass, and reductions are summed in
//! fixed-size blocks so that results are identical with 1 and N threads.

use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};
use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;

use crate::PiaError;
use crate::system::{CHUNK, ReducedSystem, dot, finite_or_inf, max_norm, safe_div};

/// Which solver to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Solver {
    /// The fastest valid one: starts with the paper's iteration (cheapest per step, and
    /// quick when the targets are smooth), and switches to conjugate gradients (BiCGSTAB
    /// where the system has no symmetric form) from where it got, as soon as the observed
    /// contraction predicts that the Krylov method finishes sooner.
    #[default]
    Auto,
    /// The paper's iteration: `x ← x + (b − M̄ x)`, every moving vertex moved by its
    /// interpolation error (Chen et al. 2008; Zhao & Lin 2012 for the local form).
    Iterate,
    /// `x ← x + ω (b − M̄ x)` with `ω = 2 / (λ_min + λ_max)` from estimated extreme
    /// eigenvalues of `M̄`.
    Weighted,
    /// Conjugate gradients on the symmetric form of `M̄ = C D` (seed 000 eqs. 17–18);
    /// BiCGSTAB when there is no such `C`.
    Cg,
    /// Sparse Cholesky of `D` (LU of `M̄` when not symmetrisable), faer.
    Direct,
}

/// The method that actually ran.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "kebab-case", tag = "method")]
pub enum Method {
    /// The paper's iteration.
    Iterate,
    /// Weighted iteration with this `ω`.
    Weighted {
        /// The step weight.
        omega: f64,
        /// Estimated smallest eigenvalue of `M̄`.
        lambda_min: f64,
        /// Estimated largest eigenvalue of `M̄`.
        lambda_max: f64,
    },
    /// Conjugate gradients on the symmetrised system.
    Cg,
    /// BiCGSTAB (no symmetric form, or CG met a non-positive curvature).
    Bicgstab,
    /// Sparse Cholesky of the symmetrised matrix.
    Cholesky,
    /// Sparse LU.
    Lu,
    /// [`Solver::Auto`]: the paper's iteration for `switched_after` steps, then CG.
    IterateThenCg {
        /// Steps of the paper's iteration before the switch.
        switched_after: usize,
    },
    /// [`Solver::Auto`]: the paper's iteration for `switched_after` steps, then BiCGSTAB.
    IterateThenBicgstab {
        /// Steps of the paper's iteration before the switch.
        switched_after: usize,
    },
}

/// Stop rule shared by the solvers.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Controls {
    /// Converged when `max_i |b_i − (M̄ x)_i| ≤ threshold`.
    pub threshold: f64,
    /// Most iterations (matrix passes for `Iterate`/`Weighted`, steps for the Krylov
    /// methods).
    pub max_iter: usize,
}

/// What a solver returns.
#[derive(Debug)]
pub(crate) struct Outcome {
    pub x: Vec<DVec3>,
    pub history: Vec<f64>,
    pub method: Method,
}

pub(crate) fn solve(
    s: &ReducedSystem,
    x0: Vec<DVec3>,
    solver: Solver,
    ctl: Controls,
) -> Result<Outcome, PiaError> {
    match solver {
        Solver::Iterate => Ok(richardson(s, x0, 1.0, Method::Iterate, ctl)),
        Solver::Weighted => {
            let (lo, hi) = extreme_eigenvalues(s);
            let omega = 2.0 / (lo + hi);
            let method = Method::Weighted {
                omega,
                lambda_min: lo,
                lambda_max: hi,
            };
            Ok(richardson(s, x0, omega, method, ctl))
        }
        Solver::Cg => Ok(krylov(s, x0, ctl)),
        Solver::Auto => Ok(auto(s, x0, ctl)),
        Solver::Direct => direct(s, x0),
    }
}

/// CG on the symmetric form, BiCGSTAB where there is none or CG breaks down.
fn krylov(s: &ReducedSystem, x0: Vec<DVec3>, ctl: Controls) -> Outcome {
    match s.symmetrizer() {
        Some(c) => match cg(s, &c, x0.clone(), ctl) {
            Some(o) => o,
            None => bicgstab(s, x0, ctl),
        },
        None => bicgstab(s, x0, ctl),
    }
}

/// Cost of a Krylov step in passes of the paper's iteration (a matrix pass plus vector
/// updates; BiCGSTAB has two matrix passes, CG one, so this errs toward iterating).
const KRYLOV_STEP_COST: f64 = 2.0;
/// Cost of starting a Krylov method (restricting, symmetrising, scaling) in iteration
/// passes.
const KRYLOV_SETUP_COST: f64 = 15.0;
/// Iterations over which the contraction rate is measured.
const WINDOW: usize = 2;

/// [`Solver::Auto`]: the paper's iteration while it is predicted to be the cheaper way to
/// the threshold, then the Krylov method from the current iterate.
///
/// With the observed contraction `ρ` per iteration over the last [`WINDOW`] steps, the
/// iteration needs `ln(t/e) / ln ρ` more steps to go from error `e` to threshold `t`. Its
/// slowest mode has eigenvalue `≈ 1 − ρ` and the largest is `≤ 1`, so CG's rate is about
/// `(√κ − 1)/(√κ + 1)` with `κ = 1/(1 − ρ)`. Switch when the second, with its setup and its
/// dearer steps, is cheaper. `ρ` only grows as the fast modes die out, so the decision is
/// taken again after every step.
fn auto(s: &ReducedSystem, mut x: Vec<DVec3>, ctl: Controls) -> Outcome {
    let mut next = vec![DVec3::ZERO; s.len()];
    let mut history: Vec<f64> = Vec::new();
    loop {
        let res = s.step(&x, 1.0, &mut next);
        history.push(res);
        let k = history.len();
        if res <= ctl.threshold || k > ctl.max_iter {
            return Outcome {
                x,
                history,
                method: Method::Iterate,
            };
        }
        if k > WINDOW {
            let rho = (res / history[k - 1 - WINDOW]).powf(1.0 / WINDOW as f64);
            let gain = (ctl.threshold / res).ln();
            let iterate_left = if rho < 1.0 {
                gain / rho.ln()
            } else {
                f64::INFINITY
            };
            let kappa = 1.0 / (1.0 - rho.min(1.0 - 1e-12));
            let cg_rate = (kappa.sqrt() - 1.0) / (kappa.sqrt() + 1.0);
            let krylov_left = KRYLOV_SETUP_COST + KRYLOV_STEP_COST * gain / cg_rate.ln();
            if iterate_left > krylov_left || iterate_left.is_nan() {
                let rest = Controls {
                    threshold: ctl.threshold,
                    max_iter: ctl.max_iter - (k - 1),
                };
                let tail = krylov(s, x, rest);
                history.extend_from_slice(&tail.history[1..]);
                let switched_after = k - 1;
                let method = match tail.method {
                    Method::Cg => Method::IterateThenCg { switched_after },
                    _ => Method::IterateThenBicgstab { switched_after },
                };
                return Outcome {
                    x: tail.x,
                    history,
                    method,
                };
            }
        }
        std::mem::swap(&mut x, &mut next);
    }
}

/// `x ← x + ω r` until the residual is small enough. One pass per iteration: the residual
/// of `x` and the next iterate are computed together (the next goes to a second buffer, as
/// every row reads its neighbours' current values).
fn richardson(
    s: &ReducedSystem,
    mut x: Vec<DVec3>,
    omega: f64,
    method: Method,
    ctl: Controls,
) -> Outcome {
    let mut next = vec![DVec3::ZERO; s.len()];
    let mut history = Vec::new();
    loop {
        let res = s.step(&x, omega, &mut next);
        history.push(res);
        if res <= ctl.threshold || history.len() > ctl.max_iter {
            break;
        }
        std::mem::swap(&mut x, &mut next);
    }
    Outcome { x, history, method }
}

/// `x += a ⊙ y` (one coefficient per coordinate), in parallel.
fn axpy3(x: &mut [DVec3], a: DVec3, y: &[DVec3]) {
    x.par_chunks_mut(CHUNK)
        .zip(y.par_chunks(CHUNK))
        .for_each(|(x, y)| x.iter_mut().zip(y).for_each(|(x, y)| *x += a * *y));
}

/// Conjugate gradients for `M̄ = C D` in the inner product `⟨x, y⟩ = Σ x_i y_i / c_i`, in
/// which `M̄` is self-adjoint (`⟨M̄x, y⟩ = xᵀ D y`) and, with `D` positive definite, positive:
/// the iterates are those of CG on the symmetric `C^{-1/2} M̄ C^{1/2}`, without forming it,
/// and the residual is the interpolation error itself. Restarted from the true residual when
/// the updated one has drifted. `None` when a non-positive curvature shows that `D` is not
/// positive definite. Three passes per iteration: `q = M̄ p` with `⟨p, q⟩`; the updates of
/// `x` and `r` with `⟨r, r⟩` and `max |r_i|`; the new direction.
fn cg(s: &ReducedSystem, c: &[f64], mut x: Vec<DVec3>, ctl: Controls) -> Option<Outcome> {
    let n = s.len();
    let weight: Vec<f64> = c.iter().map(|c| 1.0 / c).collect();
    let mut r = vec![DVec3::ZERO; n];
    let mut q = vec![DVec3::ZERO; n];
    let mut p = vec![DVec3::ZERO; n];
    let mut res = s.residual(&x, &mut r);
    let mut history = vec![res];
    let mut steps = 0usize;
    while res > ctl.threshold && steps < ctl.max_iter {
        p.copy_from_slice(&r);
        let mut rr = weighted_dot(&r, &r, &weight);
        loop {
            let pq = s.apply_weighted_dot(&weight, &p, &mut q);
            if [pq.x, pq.y, pq.z]
                .iter()
                .zip([rr.x, rr.y, rr.z])
                .any(|(&a, b)| b != 0.0 && a.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater))
            {
                return None;
            }
            let alpha = safe_div(rr, pq);
            let (rr_new, error) = cg_update(&mut x, &mut r, alpha, &p, &q, &weight);
            steps += 1;
            history.push(error);
            if error <= ctl.threshold || steps >= ctl.max_iter {
                break;
            }
            let beta = safe_div(rr_new, rr);
            rr = rr_new;
            p.par_chunks_mut(CHUNK)
                .zip(r.par_chunks(CHUNK))
                .for_each(|(p, r)| p.iter_mut().zip(r).for_each(|(p, r)| *p = *r + beta * *p));
        }
        res = s.residual(&x, &mut r);
        *history.last_mut().expect("one step taken") = res;
    }
    Some(Outcome {
        x,
        history,
        method: Method::Cg,
    })
}

/// `Σ_i w_i a_i ⊙ b_i` in fixed-size blocks summed in order.
fn weighted_dot(a: &[DVec3], b: &[DVec3], w: &[f64]) -> DVec3 {
    let partial: Vec<DVec3> = a
        .par_chunks(CHUNK)
        .zip(b.par_chunks(CHUNK))
        .zip(w.par_chunks(CHUNK))
        .map(|((a, b), w)| {
            a.iter()
                .zip(b)
                .zip(w)
                .fold(DVec3::ZERO, |s, ((a, b), &w)| s + w * (*a * *b))
        })
        .collect();
    partial.into_iter().fold(DVec3::ZERO, |s, x| s + x)
}

/// One fused CG update: `x += α p`, `r −= α q`; returns `⟨r, r⟩` (blocks summed in order)
/// and the interpolation error `max |r_i|`.
fn cg_update(
    x: &mut [DVec3],
    r: &mut [DVec3],
    alpha: DVec3,
    p: &[DVec3],
    q: &[DVec3],
    weight: &[f64],
) -> (DVec3, f64) {
    let partial: Vec<(DVec3, f64)> = x
        .par_chunks_mut(CHUNK)
        .zip(r.par_chunks_mut(CHUNK))
        .zip(p.par_chunks(CHUNK))
        .zip(q.par_chunks(CHUNK))
        .zip(weight.par_chunks(CHUNK))
        .map(|((((x, r), p), q), w)| {
            let (mut rr, mut m) = (DVec3::ZERO, 0.0f64);
            for ((((x, r), p), q), &w) in x.iter_mut().zip(r.iter_mut()).zip(p).zip(q).zip(w) {
                *x += alpha * *p;
                *r -= alpha * *q;
                rr += w * (*r * *r);
                m = m.max(finite_or_inf(r.length()));
            }
            (rr, m)
        })
        .collect();
    partial
        .into_iter()
        .fold((DVec3::ZERO, 0.0), |(a, m), (b, n)| (a + b, m.max(n)))
}

/// `z_i = r_i · inv_i`.
fn precondition(r: &[DVec3], inv: &[f64], z: &mut [DVec3]) {
    z.par_chunks_mut(CHUNK)
        .zip(r.par_chunks(CHUNK))
        .zip(inv.par_chunks(CHUNK))
        .for_each(|((z, r), inv)| {
            for ((z, r), &d) in z.iter_mut().zip(r).zip(inv) {
                *z = *r * d;
            }
        });
}

/// Jacobi-preconditioned BiCGSTAB (van der Vorst 1992), three coordinates in lockstep,
/// restarted from the true residual after a breakdown or when the updated residual has
/// drifted.
fn bicgstab(s: &ReducedSystem, mut x: Vec<DVec3>, ctl: Controls) -> Outcome {
    let n = s.len();
    let inv_d: Vec<f64> = s
        .diag()
        .iter()
        .map(|&d| if d != 0.0 { 1.0 / d } else { 1.0 })
        .collect();
    let mut r = vec![DVec3::ZERO; n];
    let mut res = s.residual(&x, &mut r);
    let mut history = vec![res];
    let mut steps = 0usize;
    let (mut y, mut v, mut zz, mut t) = (
        vec![DVec3::ZERO; n],
        vec![DVec3::ZERO; n],
        vec![DVec3::ZERO; n],
        vec![DVec3::ZERO; n],
    );
    while res > ctl.threshold && steps < ctl.max_iter {
        let r_hat = r.clone();
        let mut p = r.clone();
        let mut rho = dot(&r_hat, &r);
        loop {
            precondition(&p, &inv_d, &mut y);
            s.apply(&y, &mut v);
            let alpha = safe_div(rho, dot(&r_hat, &v));
            axpy3(&mut x, alpha, &y);
            axpy3(&mut r, -alpha, &v);
            steps += 1;
            let half = max_norm(&r);
            if half <= ctl.threshold || steps >= ctl.max_iter {
                history.push(half);
                break;
            }
            precondition(&r, &inv_d, &mut zz);
            s.apply(&zz, &mut t);
            let omega = safe_div(dot(&t, &r), dot(&t, &t));
            axpy3(&mut x, omega, &zz);
            axpy3(&mut r, -omega, &t);
            let full = max_norm(&r);
            history.push(full);
            if full <= ctl.threshold || steps >= ctl.max_iter {
                break;
            }
            let rho_new = dot(&r_hat, &r);
            if [rho_new.x, rho_new.y, rho_new.z, omega.x, omega.y, omega.z]
                .iter()
                .any(|v| !v.is_finite())
            {
                break;
            }
            let beta = safe_div(rho_new, rho) * safe_div(alpha, omega);
            rho = rho_new;
            // p ← r + β (p − ω v)
            p.par_chunks_mut(CHUNK)
                .zip(r.par_chunks(CHUNK))
                .zip(v.par_chunks(CHUNK))
                .for_each(|((p, r), v)| {
                    for ((p, r), v) in p.iter_mut().zip(r).zip(v) {
                        *p = *r + beta * (*p - omega * *v);
                    }
                });
            if rho.x == 0.0 && rho.y == 0.0 && rho.z == 0.0 {
                break;
            }
        }
        res = s.residual(&x, &mut r);
        *history.last_mut().expect("one step taken") = res;
    }
    Outcome {
        x,
        history,
        method: Method::Bicgstab,
    }
}

/// Sparse direct solve: Cholesky of the symmetrised `D` when there is one and it factors,
/// LU of `M̄` otherwise.
fn direct(s: &ReducedSystem, x0: Vec<DVec3>) -> Result<Outcome, PiaError> {
    let n = s.len();
    let mut r = vec![DVec3::ZERO; n];
    let first = s.residual(&x0, &mut r);
    let sym = s.symmetrizer();
    let mut triplets = Vec::with_capacity(s.matrix.cols.len());
    let mut rhs = Mat::<f64>::zeros(n, 3);
    let mut solved = None;
    if let Some(c) = &sym {
        for i in 0..n {
            let (cols, w) = s.row(i);
            for (&j, &x) in cols.iter().zip(w) {
                // Lower triangle of D = C⁻¹ M̄.
                if j as usize <= i {
                    triplets.push(Triplet::new(i, j as usize, x / c[i]));
                }
            }
            for k in 0..3 {
                rhs[(i, k)] = s.rhs[i][k] / c[i];
            }
        }
        let d = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &triplets)
            .map_err(|e| PiaError::Solver(format!("sparse matrix: {e:?}")))?;
        if let Ok(llt) = d.sp_cholesky(Side::Lower) {
            llt.solve_in_place(rhs.as_mut());
            solved = Some(Method::Cholesky);
        }
    }
    if solved.is_none() {
        triplets.clear();
        for i in 0..n {
            let (cols, w) = s.row(i);
            for (&j, &x) in cols.iter().zip(w) {
                triplets.push(Triplet::new(i, j as usize, x));
            }
            for k in 0..3 {
                rhs[(i, k)] = s.rhs[i][k];
            }
        }
        let m = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &triplets)
            .map_err(|e| PiaError::Solver(format!("sparse matrix: {e:?}")))?;
        let lu = m
            .sp_lu()
            .map_err(|e| PiaError::Solver(format!("sparse LU: {e:?}")))?;
        lu.solve_in_place(rhs.as_mut());
        solved = Some(Method::Lu);
    }
    let x: Vec<DVec3> = (0..n)
        .map(|i| DVec3::new(rhs[(i, 0)], rhs[(i, 1)], rhs[(i, 2)]))
        .collect();
    let last = s.residual(&x, &mut r);
    Ok(Outcome {
        x,
        history: vec![first, last],
        method: solved.expect("one of the two ran"),
    })
}

/// Estimates of the smallest and largest eigenvalue of `M̄` for the weighted iteration.
///
/// Symmetrisable systems: 30 Lanczos steps on `C^{-1/2} M̄ C^{1/2}` (symmetric, similar to
/// `M̄`); the extreme Ritz values converge fast. Otherwise: `λ_max ≤ ‖M̄‖_∞` and `λ_min`
/// from power iteration on `‖M̄‖_∞ I − M̄`. Either way `ω λ_max < 2`, so the weighted
/// iteration converges whenever the plain one does.
pub(crate) fn extreme_eigenvalues(s: &ReducedSystem) -> (f64, f64) {
    let n = s.len();
    if n == 0 {
        return (1.0, 1.0);
    }
    let start = |i: usize| 1.0 + ((i * 7919) % 97) as f64 / 97.0;
    if let Some(c) = s.symmetrizer() {
        let sq: Vec<f64> = c.iter().map(|c| c.sqrt()).collect();
        // One scratch vector for every step (no allocation inside the Lanczos loop).
        let mut u = vec![0.0; n];
        let mut op = |x: &[f64], y: &mut [f64]| {
            u.iter_mut()
                .zip(x.iter().zip(&sq))
                .for_each(|(u, (x, s))| *u = x * s);
            apply_scalar(s, &u, y);
            y.iter_mut().zip(&sq).for_each(|(y, s)| *y /= s);
        };
        let k = n.min(30);
        let mut q: Vec<f64> = (0..n).map(start).collect();
        let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        q.iter_mut().for_each(|x| *x /= norm);
        let mut q_prev = vec![0.0; n];
        let mut w = vec![0.0; n];
        let (mut alphas, mut betas) = (Vec::new(), Vec::new());
        let mut beta = 0.0;
        for _ in 0..k {
            op(&q, &mut w);
            let a: f64 = w.iter().zip(&q).map(|(w, q)| w * q).sum();
            for i in 0..n {
                w[i] -= a * q[i] + beta * q_prev[i];
            }
            alphas.push(a);
            beta = w.iter().map(|x| x * x).sum::<f64>().sqrt();
            if beta < 1e-12 {
                break;
            }
            betas.push(beta);
            std::mem::swap(&mut q_prev, &mut q);
            for i in 0..n {
                q[i] = w[i] / beta;
            }
        }
        let m = alphas.len();
        let t = Mat::<f64>::from_fn(m, m, |i, j| {
            if i == j {
                alphas[i]
            } else if i == j + 1 {
                betas[j]
            } else if j == i + 1 {
                betas[i]
            } else {
                0.0
            }
        });
        if let Ok(ev) = t.self_adjoint_eigenvalues(Side::Lower)
            && let (Some(&lo), Some(&hi)) = (ev.first(), ev.last())
            && lo > 0.0
        {
            return (lo, hi);
        }
    }
    let hi = s.inf_norm();
    let mut x: Vec<f64> = (0..n).map(start).collect();
    let mut y = vec![0.0; n];
    let mut mu = 0.0;
    for _ in 0..100 {
        apply_scalar(s, &x, &mut y);
        for i in 0..n {
            y[i] = hi * x[i] - y[i];
        }
        let ny = y.iter().map(|v| v * v).sum::<f64>().sqrt();
        let nx = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        mu = ny / nx;
        x.iter_mut().zip(&y).for_each(|(x, y)| *x = y / ny);
    }
    let lo = (hi - mu).max(1e-3 * hi);
    (lo, hi)
}

/// `y = M̄ x` for one scalar column.
fn apply_scalar(s: &ReducedSystem, x: &[f64], y: &mut [f64]) {
    y.par_chunks_mut(CHUNK).enumerate().for_each(|(c, out)| {
        for (k, o) in out.iter_mut().enumerate() {
            let (cols, w) = s.row(c * CHUNK + k);
            *o = cols.iter().zip(w).map(|(&j, &w)| w * x[j as usize]).sum();
        }
    });
}
