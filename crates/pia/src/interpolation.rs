//! The whole interpolation workflow in one call, as `subd pia` and `subd.pia` run it: set
//! up, solve, then measure the result with a limit table built afresh (not the solver's own
//! residual), and report what happened.

use std::time::Instant;

use glam::DVec3;
use serde::Serialize;
use subd_mesh::Topology;
use subd_schemes::{Options, Scheme};

use crate::{Method, Moving, Pia, PiaError, PiaOptions, Solver, deviation};

/// An interpolation asked for: the scheme whose limit surface is to pass through the
/// targets, its rule options, which vertices move and how to solve.
#[derive(Debug, Clone)]
pub struct InterpolationRequest<'a> {
    /// The scheme.
    pub scheme: &'a Scheme,
    /// Its rule options.
    pub options: &'a Options,
    /// The vertices that move (the others keep their targets).
    pub moving: &'a Moving,
    /// The solver, tolerance and iteration limit.
    pub solve: PiaOptions,
}

/// What an interpolation did, as the reports show it (`subd pia --json`, `subd.pia`'s
/// report): every field is measured, none is the request echoed back but `tol`.
#[derive(Debug, Clone, Serialize)]
pub struct InterpolationReport {
    /// The scheme's name.
    pub scheme: &'static str,
    /// The solver asked for.
    pub solver: Solver,
    /// The method that ran.
    pub method: Method,
    /// Vertices of the mesh.
    pub vertices: usize,
    /// Vertices that moved.
    pub moving: usize,
    /// Iterations run.
    pub iterations: usize,
    /// Whether the solver converged and the fresh measurement confirms the tolerance.
    pub converged: bool,
    /// Max |limit − target| over the moving vertices, from a limit table built afresh for
    /// the result (model units).
    pub max_error: f64,
    /// `max_error` over the targets' bounding-box diagonal.
    pub max_error_relative: f64,
    /// The tolerance asked for (relative to the diagonal).
    pub tol: f64,
    /// The solver's max interpolation error before the first iteration and after each.
    pub history: Vec<f64>,
}

/// Seconds spent in each step of [`interpolate`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct InterpolationSeconds {
    /// The limit matrix.
    pub setup: f64,
    /// The solve.
    pub solve: f64,
    /// The fresh measurement.
    pub check: f64,
}

/// An interpolation's outcome: the control points, what happened and how long it took.
#[derive(Debug, Clone)]
pub struct Interpolation {
    /// The control points (with the topology given, a cage of the scheme). Meaningful only
    /// where [`InterpolationReport::converged`]: a solve that did not converge may hold
    /// points that are not finite.
    pub points: Vec<DVec3>,
    /// The report.
    pub report: InterpolationReport,
    /// The time of each step.
    pub seconds: InterpolationSeconds,
}

/// Control points on `topology` whose limit surface under the request's scheme passes
/// through `targets` (the moving vertices'), measured afresh.
///
/// ```
/// use subd_mesh::primitives;
/// use subd_pia::interpolation::{InterpolationRequest, interpolate};
/// use subd_pia::{Moving, PiaOptions};
/// use subd_schemes::{Options, Scheme};
///
/// // A torus of 8 × 6 quads: its limit surface made to pass through its vertices.
/// let torus = primitives::torus(8, 6, 2.0, 0.5);
/// let request = InterpolationRequest {
///     scheme: &Scheme::CatmullClark,
///     options: &Options::default(),
///     moving: &Moving::All,
///     solve: PiaOptions::default(),
/// };
/// let fitted = interpolate(&torus.topology, &torus.positions, &request).unwrap();
/// assert!(fitted.report.converged && fitted.report.max_error_relative <= 1e-10);
/// ```
///
/// # Errors
/// [`PiaError`]: a scheme that does not interpolate, a limit not defined for the mesh, bad
/// targets, vertex indices or tolerance.
pub fn interpolate(
    topology: &Topology,
    targets: &[DVec3],
    request: &InterpolationRequest<'_>,
) -> Result<Interpolation, PiaError> {
    let r = request;
    let t0 = Instant::now();
    let pia = Pia::new(topology, r.scheme, r.options)?;
    let t1 = Instant::now();
    let result = pia.solve(targets, r.moving, &r.solve)?;
    let t2 = Instant::now();
    let measured = deviation(
        topology,
        r.scheme,
        r.options,
        &result.points,
        targets,
        r.moving,
    )?;
    let seconds = InterpolationSeconds {
        setup: (t1 - t0).as_secs_f64(),
        solve: (t2 - t1).as_secs_f64(),
        check: t2.elapsed().as_secs_f64(),
    };
    let report = InterpolationReport {
        scheme: r.scheme.name(),
        solver: r.solve.solver,
        method: result.method,
        vertices: topology.num_vertices(),
        moving: result.moving,
        iterations: result.iterations,
        converged: result.converged && measured.within(r.solve.tol),
        max_error: measured.max_error,
        max_error_relative: measured.relative,
        tol: r.solve.tol,
        history: result.history,
    };
    Ok(Interpolation {
        points: result.points,
        report,
        seconds,
    })
}
