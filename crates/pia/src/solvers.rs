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
use subd_mesh::choice::Choice;
use subd_mesh::memory;

use crate::PiaError;
use crate::checkerboard::Preconditioned;
use crate::matrix::{CHUNK, Matrix};
use crate::ritz::ritz_extremes;
use crate::system::{ReducedSystem, dot, finite_or_inf, max_norm, safe_div};

/// Which solver to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Solver {
    /// The fastest valid one. Every vertex moving on a [prepared](crate::Pia::prepare)
    /// problem that has the checkerboard operator (closed two-coloured quad meshes,
    /// Catmull-Clark and two-phase): [`Solver::Chebyshev`]. Otherwise, where the mesh is
    /// two-coloured and the system has a symmetric form: checkerboard-preconditioned CG.
    /// Otherwise it starts with the paper's iteration (cheapest per step, and quick when the
    /// targets are smooth), and switches to conjugate gradients (BiCGSTAB where the system
    /// has no symmetric form) from where it got, as soon as the observed contraction
    /// predicts that the Krylov method finishes sooner.
    #[default]
    Auto,
    /// The paper's iteration: `x ← x + (b − M̄ x)`, every moving vertex moved by its
    /// interpolation error (Chen et al. 2008; Zhao & Lin 2012 for the local form).
    Iterate,
    /// `x ← x + ω (b − M̄ x)` with `ω = 2 / (λ_min + λ_max)` from estimated extreme
    /// eigenvalues of `M̄`.
    Weighted,
    /// Conjugate gradients on the symmetric form of `M̄ = C D` (Lin et al. eqs. 17–18),
    /// preconditioned by the checkerboard-conjugated, diagonally scaled matrix `T M̄ T` where
    /// the mesh is two-coloured ([`crate::checkerboard`]); BiCGSTAB when there is no such
    /// `C`.
    Cg,
    /// Chebyshev iteration on the checkerboard-preconditioned system `T M̄ T M̄ x = T M̄ T b`
    /// (Catmull-Clark and two-phase on two-coloured meshes with a symmetric form), one
    /// matrix pass per step; CG where it does not apply. Its operator and spectral interval
    /// are built on first use (about as long as a CG solve) and kept by the `Pia` when
    /// every vertex moves, so it pays off from the second solve on.
    Chebyshev,
    /// Sparse Cholesky of `D` (LU of `M̄` when not symmetrisable), faer.
    Direct,
}

impl Choice for Solver {
    const OPTION: &'static str = "solver";
    const VALUES: &'static [(Self, &'static str, &'static str)] = &[
        (
            Solver::Auto,
            "auto",
            "The fastest valid solver (Chebyshev on the checkerboard-preconditioned system for closed two-coloured quad meshes with every vertex moving; otherwise conjugate gradients, BiCGSTAB where the system has no symmetric form)",
        ),
        (
            Solver::Iterate,
            "iterate",
            "The paper's iteration: every moving vertex moves by its interpolation error",
        ),
        (
            Solver::Weighted,
            "weighted",
            "The iteration with the optimal weight 2 / (λ_min + λ_max)",
        ),
        (
            Solver::Cg,
            "cg",
            "Conjugate gradients on the symmetrised system (BiCGSTAB where there is none)",
        ),
        (
            Solver::Chebyshev,
            "chebyshev",
            "Chebyshev iteration on the checkerboard-preconditioned system (Catmull-Clark and two-phase on two-coloured closed quad meshes; CG elsewhere)",
        ),
        (Solver::Direct, "direct", "Sparse Cholesky / LU"),
    ];
}

subd_mesh::choice_by_name!(Solver);

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
    /// Conjugate gradients preconditioned by the checkerboard-conjugated, diagonally scaled
    /// limit matrix (quad meshes whose vertices are two-coloured along edges; see
    /// [`Solver::Cg`]).
    CheckerboardCg,
    /// BiCGSTAB (no symmetric form, or CG met a non-positive curvature).
    Bicgstab,
    /// Chebyshev iteration on the checkerboard-preconditioned system.
    Chebyshev {
        /// Lower end of the interval used (estimated smallest eigenvalue, less a margin).
        lambda_min: f64,
        /// Upper end of the interval used.
        lambda_max: f64,
    },
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
    /// Iterations run: `history.len() − 1`, except for Chebyshev, whose history holds the
    /// error at its checkpoints only.
    pub steps: usize,
}

impl Outcome {
    /// An outcome whose history has an entry per iteration.
    fn new(x: Vec<DVec3>, history: Vec<f64>, method: Method) -> Outcome {
        let steps = history.len().saturating_sub(1);
        Outcome {
            x,
            history,
            method,
            steps,
        }
    }
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
        Solver::Chebyshev => {
            let Some(t) = s.conjugation() else {
                return Ok(krylov(s, x0, ctl));
            };
            // The whole system keeps its operator; a cut of it (fixed vertices) builds its own.
            let local;
            let pre = match s.whole_preconditioned(true) {
                Some(p) => Some(p),
                None => {
                    local = s
                        .symmetrizer()
                        .and_then(|c| Preconditioned::new(&s.matrix, &c, &t));
                    local.as_ref()
                }
            };
            match pre {
                Some(pre) => Ok(chebyshev(s, pre, &t, x0, ctl)),
                None => Ok(krylov(s, x0, ctl)),
            }
        }
        Solver::Auto => Ok(auto(s, x0, ctl)),
        Solver::Direct => direct(s, x0),
    }
}

/// CG on the symmetric form, BiCGSTAB where there is none or CG breaks down.
fn krylov(s: &ReducedSystem, x0: Vec<DVec3>, ctl: Controls) -> Outcome {
    match s.symmetrizer() {
        Some(c) => match cg(s, &c, s.conjugation().as_deref(), x0.clone(), ctl) {
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
    if let Some(t) = s.conjugation() {
        if let Some(pre) = s.whole_preconditioned(false) {
            return chebyshev(s, pre, &t, x, ctl);
        }
        // Checkerboard CG needs 8–13 steps of two passes where the iteration needs ~100
        // passes or more (its rate is about 1/7 per step against 8/9 per pass): start with
        // it rather than probing the iteration first.
        if let Some(c) = s.symmetrizer()
            && let Some(o) = cg(s, &c, Some(&t), x.clone(), ctl)
        {
            return o;
        }
    }
    let mut next = vec![DVec3::ZERO; s.len()];
    let mut history: Vec<f64> = Vec::new();
    loop {
        let res = s.step(&x, 1.0, &mut next);
        history.push(res);
        let k = history.len();
        if res <= ctl.threshold || k > ctl.max_iter {
            return Outcome::new(x, history, Method::Iterate);
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
                    Method::Cg | Method::CheckerboardCg => Method::IterateThenCg { switched_after },
                    _ => Method::IterateThenBicgstab { switched_after },
                };
                return Outcome::new(tail.x, history, method);
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
    Outcome::new(x, history, method)
}

/// Relative widening of the estimated spectral interval of `K` at its lower and upper end:
/// Lanczos' extreme Ritz values lie inside the spectrum, and a mode beyond the interval's
/// upper end would grow.
const INTERVAL_MARGIN: (f64, f64) = (0.05, 0.02);

/// The first Chebyshev checkpoint comes after 1/this of the steps that the a-priori
/// bound asks for (later ones after the steps the asymptotic rate asks for).
const FIRST_CHECKPOINT: f64 = 4.0;

/// Chebyshev iteration (Saad, *Iterative Methods for Sparse Linear Systems*, 2nd ed.,
/// Alg. 12.1) on `K x = f`, `K = T M̄ T M̄`, `f = T M̄ T b`, over the interval of `pre`,
/// in its three-term form
///
/// ```text
/// x_{k+1} = x_k + ρ_k ρ_{k−1} (x_k − x_{k−1}) + (2 ρ_k / δ) (f − K x_k),   ρ_k = 1 / (2σ − ρ_{k−1})
/// ```
///
/// (first step `x_1 = x_0 + (f − K x_0) / θ`; `θ`, `δ` the interval's centre and
/// half-width, `σ = θ / δ`, `ρ_0 = 1/σ`). It needs no inner products, so a step is one
/// pass over the rows of `K`, reading `x_k` and writing `x_{k+1}` over `x_{k−1}`. The
/// steps that the a-priori bound `‖e_k‖ ≤ ‖e_0‖ / T_k(σ)` (`T_k` the Chebyshev
/// polynomial) needs for the threshold are run at once (a quarter of them before the
/// first check); then a checkpoint computes the true residual `b − M̄ x`, whose max-norm is
/// the stop test and the history entry. Short of the threshold, the same recurrence goes
/// on for the steps its asymptotic rate `e^{−acosh σ}` needs for the rest.
pub(crate) fn chebyshev(
    s: &ReducedSystem,
    pre: &Preconditioned,
    t: &[f64],
    mut x: Vec<DVec3>,
    ctl: Controls,
) -> Outcome {
    let n = s.len();
    let lo = pre.lambda_min * (1.0 - INTERVAL_MARGIN.0);
    let hi = pre.lambda_max * (1.0 + INTERVAL_MARGIN.1);
    let (theta, delta) = ((hi + lo) / 2.0, (hi - lo) / 2.0);
    let sigma = theta / delta;
    let mut res = s.residual_max(&x);
    let mut history = vec![res];
    let mut steps = 0usize;
    if res > ctl.threshold && ctl.max_iter > 0 {
        let mut f = vec![DVec3::ZERO; n];
        s.apply_conjugated(t, &s.rhs, &mut f);
        // x_{k−1}; overwritten by x_{k+1} in each pass (the first step does not read it).
        let mut older = vec![DVec3::ZERO; n];
        let rate = sigma.acosh();
        // Smooth targets converge far sooner than the bound says: check early.
        let mut block = ((res / ctl.threshold).acosh() / rate / FIRST_CHECKPOINT).ceil();
        let mut rho = 1.0 / sigma;
        loop {
            let block_steps = (block as usize).clamp(1, ctl.max_iter - steps);
            for k in steps..steps + block_steps {
                let (keep, add) = if k == 0 {
                    (0.0, 1.0 / theta)
                } else {
                    let rho_next = 1.0 / (2.0 * sigma - rho);
                    let coefficients = (rho_next * rho, 2.0 * rho_next / delta);
                    rho = rho_next;
                    coefficients
                };
                chebyshev_pass(&pre.k, &x, &mut older, &f, keep, add);
                std::mem::swap(&mut x, &mut older);
            }
            steps += block_steps;
            let last = res;
            res = s.residual_max(&x);
            history.push(res);
            if res <= ctl.threshold || steps >= ctl.max_iter {
                break;
            }
            // A block that did not reduce the error means a wrong interval (an eigenvalue
            // above it grows): start over with CG, which needs none, from the right side
            // (the targets when every vertex moves), as the iterate may have grown.
            if res.partial_cmp(&last) != Some(std::cmp::Ordering::Less) {
                let mut cg = krylov(s, s.rhs.clone(), ctl);
                cg.steps += steps;
                return cg;
            }
            block = ((res / ctl.threshold).ln() / rate).ceil();
        }
    }
    Outcome {
        x,
        history,
        method: Method::Chebyshev {
            lambda_min: lo,
            lambda_max: hi,
        },
        steps,
    }
}

/// One Chebyshev step over every row `i`:
/// `older_i ← x_i + keep · (x_i − older_i) + add · (f_i − (K x)_i)`.
fn chebyshev_pass(k: &Matrix, x: &[DVec3], older: &mut [DVec3], f: &[DVec3], keep: f64, add: f64) {
    older
        .par_chunks_mut(CHUNK)
        .zip(f.par_chunks(CHUNK))
        .enumerate()
        .for_each(|(c, (older, f))| {
            for (o, (old, f)) in older.iter_mut().zip(f).enumerate() {
                let i = c * CHUNK + o;
                let (cols, w) = k.row(i);
                let kx = cols
                    .iter()
                    .zip(w)
                    .fold(DVec3::ZERO, |acc, (&j, &w)| acc + w * x[j as usize]);
                *old = x[i] + keep * (x[i] - *old) + add * (*f - kx);
            }
        });
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
/// positive definite.
///
/// With the checkerboard scaling `t` (`T = S Δ⁻¹`) the method is preconditioned by `T M̄ T`
/// ([`crate::checkerboard`]), self-adjoint and positive in the same inner product
/// (`C⁻¹ T M̄ T = T D T`). A step is two matrix passes and one vector sweep:
/// * (preconditioned) `z = T M̄ r̃ = T M̄ T r` with `⟨r, z⟩`. The residual is kept
///   scaled, `r̃ = T r`, so that this pass gathers plain values;
/// * the new direction `p ← z + β p` together with `q ← M̄ z + β q`, which equals `M̄ p` by
///   linearity, and `⟨p, q⟩`: no separate pass for `M̄ p`. The drift this recurrence adds
///   is caught by the true residual at the end, which restarts the method if needed;
/// * the sweep: `x += α p`, `r̃ −= α T q` with `max |r_i|` and `⟨r, r⟩`.
fn cg(
    s: &ReducedSystem,
    c: &[f64],
    t: Option<&[f64]>,
    mut x: Vec<DVec3>,
    ctl: Controls,
) -> Option<Outcome> {
    let n = s.len();
    let weight: Vec<f64> = c.iter().map(|c| 1.0 / c).collect();
    // The scaled residual T r (r itself without T), the direction, its product with M̄
    // and the preconditioned residual (only with T), in one allocation: large enough for
    // huge pages (`subd_mesh::memory`), one page fault per 2 MiB instead of per 4 KiB,
    // which on a first solve took about a fifth of CG's time.
    let mut work: Vec<DVec3> = memory::zeroed(if t.is_some() { 4 * n } else { 3 * n });
    let (r, rest) = work.split_at_mut(n);
    let (p, rest) = rest.split_at_mut(n);
    let (q, z) = rest.split_at_mut(n);
    let not_positive = |v: DVec3, scale: DVec3| {
        [v.x, v.y, v.z]
            .iter()
            .zip([scale.x, scale.y, scale.z])
            .any(|(&a, b)| b != 0.0 && a.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater))
    };
    let mut res = s.scaled_residual(t, &x, r);
    let mut history = vec![res];
    let mut steps = 0usize;
    while res > ctl.threshold && steps < ctl.max_iter {
        let mut rr = weighted_dot(r, r, &weight);
        // ρ of the step before (none on the first step, whose direction is z itself).
        let mut rho: Option<DVec3> = None;
        loop {
            // ρ = ⟨r, z⟩ with z = T M̄ T r (preconditioned) or z = r.
            let rho_new = match t {
                Some(t) => s.precondition_pass(&weight, t, r, z),
                None => rr,
            };
            if not_positive(rho_new, rr) {
                return None;
            }
            let beta = rho.map(|old| safe_div(rho_new, old));
            rho = Some(rho_new);
            let direction: &[DVec3] = if t.is_some() { z } else { r };
            let pq = s.direction_pass(&weight, direction, beta, p, q);
            if not_positive(pq, rho_new) {
                return None;
            }
            let alpha = safe_div(rho_new, pq);
            let (rr_new, error) = cg_update(&mut x, r, alpha, p, q, t, &weight);
            steps += 1;
            history.push(error);
            if error <= ctl.threshold || steps >= ctl.max_iter {
                break;
            }
            rr = rr_new;
        }
        res = s.scaled_residual(t, &x, r);
        *history.last_mut().expect("one step taken") = res;
    }
    let method = if t.is_some() {
        Method::CheckerboardCg
    } else {
        Method::Cg
    };
    Some(Outcome::new(x, history, method))
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

/// One fused CG update: `x += α p`, `r̃ −= α T q` (`T` the diagonal of `t`, the identity
/// when `None`); returns `⟨r, r⟩` (blocks summed in order) and the interpolation error
/// `max |r_i|`, both of the unscaled `r = T⁻¹ r̃`.
fn cg_update(
    x: &mut [DVec3],
    r: &mut [DVec3],
    alpha: DVec3,
    p: &[DVec3],
    q: &[DVec3],
    t: Option<&[f64]>,
    weight: &[f64],
) -> (DVec3, f64) {
    let partial: Vec<(DVec3, f64)> = x
        .par_chunks_mut(CHUNK)
        .zip(r.par_chunks_mut(CHUNK))
        .zip(p.par_chunks(CHUNK))
        .zip(q.par_chunks(CHUNK))
        .zip(weight.par_chunks(CHUNK))
        .enumerate()
        .map(|(c, ((((x, r), p), q), w))| {
            let t = t.map(|t| &t[c * CHUNK..]);
            let (mut rr, mut m) = (DVec3::ZERO, 0.0f64);
            for (k, ((((x, r), p), q), &w)) in x
                .iter_mut()
                .zip(r.iter_mut())
                .zip(p)
                .zip(q)
                .zip(w)
                .enumerate()
            {
                *x += alpha * *p;
                let step = alpha * *q;
                let unscaled = match t {
                    Some(t) => {
                        *r -= t[k] * step;
                        *r / t[k]
                    }
                    None => {
                        *r -= step;
                        *r
                    }
                };
                rr += w * (unscaled * unscaled);
                m = m.max(finite_or_inf(unscaled.length()));
            }
            (rr, m)
        })
        .collect();
    partial
        .into_iter()
        .fold((DVec3::ZERO, 0.0), |(a, m), (b, n)| (a + b, m.max(n)))
}

/// `z_i = r_i · inv_i` (a diagonal scaling: BiCGSTAB's Jacobi preconditioner).
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
    Outcome::new(x, history, Method::Bicgstab)
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
    Ok(Outcome::new(
        x,
        vec![first, last],
        solved.expect("one of the two ran"),
    ))
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
            s.matrix.apply_scalar(&u, y);
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
        if let Some(bounds) = ritz_extremes(&alphas, &betas) {
            return bounds;
        }
    }
    let hi = s.inf_norm();
    let mut x: Vec<f64> = (0..n).map(start).collect();
    let mut y = vec![0.0; n];
    let mut mu = 0.0;
    for _ in 0..100 {
        s.matrix.apply_scalar(&x, &mut y);
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
