//! `subd pia`: progressive iterative interpolation — a control mesh with the input's
//! topology whose limit surface passes through the input's vertices.

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use clap::{Args, ValueEnum};
use serde::Serialize;
use subd_mesh::Mesh;
use subd_pia::{Method, Moving, Pia, PiaOptions, Solver};
use subd_schemes::{Capability, Scheme};

use crate::batch::{self, Files, Job};
use crate::failure::bad;
use crate::progress::Spinner;
use crate::rule_args::RuleArgs;
use crate::scheme_arg;
use crate::vertex_data::{LambdaArgs, read_indices};
use crate::{EXIT_FAILURE, Failure, print_warnings};

#[derive(Debug, Clone, Copy, ValueEnum)]
pub(crate) enum SolverArg {
    /// The fastest valid solver (Chebyshev on the checkerboard-preconditioned system for
    /// closed two-coloured quad meshes with every vertex moving; otherwise conjugate
    /// gradients, BiCGSTAB where the system has no symmetric form).
    Auto,
    /// The paper's iteration: every moving vertex moves by its interpolation error.
    Iterate,
    /// The iteration with the optimal weight 2 / (λ_min + λ_max).
    Weighted,
    /// Conjugate gradients on the symmetrised system (BiCGSTAB where there is none).
    Cg,
    /// Chebyshev iteration on the checkerboard-preconditioned system (Catmull-Clark and
    /// two-phase on two-coloured closed quad meshes; CG elsewhere).
    Chebyshev,
    /// Sparse Cholesky / LU.
    Direct,
}

#[derive(Debug, Args)]
pub(crate) struct PiaArgs {
    /// Scheme whose limit surface interpolates (default: the scheme the input names, USD's
    /// subdivisionScheme).
    #[arg(long, value_parser = scheme_arg::parser(Capability::Interpolate))]
    scheme: Option<Scheme>,
    #[command(flatten)]
    lambda: LambdaArgs,
    /// Only these vertices move (a file of 0-based indices); the others keep their
    /// positions (local PIA).
    #[arg(long, value_name = "FILE", conflicts_with = "fixed")]
    moving: Option<PathBuf>,
    /// These vertices keep their positions (a file of 0-based indices); the others move.
    #[arg(long, value_name = "FILE")]
    fixed: Option<PathBuf>,
    /// Solver.
    #[arg(long, value_enum, default_value = "auto")]
    solver: SolverArg,
    /// Stop when every moving vertex's limit is within tol × the bounding-box diagonal of
    /// its target.
    #[arg(long, default_value_t = 1e-10)]
    tol: f64,
    /// Most iterations.
    #[arg(long, default_value_t = 10_000)]
    max_iter: usize,
    #[command(flatten)]
    rules: RuleArgs,
    #[command(flatten)]
    files: Files,
    /// Print a JSON report on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct Seconds {
    read: f64,
    setup: f64,
    solve: f64,
    check: f64,
    write: f64,
    total: f64,
}

#[derive(Serialize)]
struct PiaReport {
    input: String,
    output: String,
    scheme: &'static str,
    solver: Solver,
    method: Method,
    vertices: usize,
    moving: usize,
    iterations: usize,
    converged: bool,
    /// Max |limit − target| over the moving vertices, from a limit table built afresh for
    /// the output mesh (model units).
    max_error: f64,
    /// `max_error` over the targets' bounding-box diagonal.
    max_error_relative: f64,
    tol: f64,
    /// The solver's max interpolation error before the first iteration and after each.
    history: Vec<f64>,
    seconds: Seconds,
    warnings: Vec<String>,
}

/// `subd pia` writes meshes.
const PIA: batch::Command = batch::Command {
    name: "pia",
    formats: batch::MESH_OUTPUTS,
};

pub(crate) fn run(args: &PiaArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<(), Failure> {
    PIA.run(&args.files, args.json, out, err, |job, out, err| {
        run_one(args, job, out, err)
    })
}

fn run_one(
    args: &PiaArgs,
    job: &Job,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    let started = PIA.start_job(job)?;
    if args.tol.is_nan() || args.tol <= 0.0 {
        return Err(bad(format!(
            "--tol {}: must be a positive number",
            args.tol
        )));
    }
    let opened = started.read(&args.rules, err)?;
    let (file, t_read) = (&opened.file, opened.read_seconds);
    let topo = &file.mesh.topology;
    let nv = topo.num_vertices();
    let options = args.rules.options(&file.mesh.hints);
    let named = scheme_arg::given_or_named(
        args.scheme.as_ref(),
        &file.mesh.hints,
        Capability::Interpolate,
        &job.input,
    )?;
    let scheme = scheme_arg::with_lambda(&named, &args.lambda, &job.input, nv)?;
    let name = scheme.name();
    let moving = moving_vertices(args, nv)?;
    let solver = args.solver.solver();
    let at_input = |e: subd_pia::PiaError| bad(format!("{}: {e}", job.input.display()));
    let spinner = Spinner::new(args.json || job.quiet, "limit stencils");
    let t0 = Instant::now();
    let pia = Pia::new(topo, &scheme, &options).map_err(at_input)?;
    let t_setup = t0.elapsed().as_secs_f64();
    spinner.message("solving");
    let t1 = Instant::now();
    let opts = PiaOptions {
        solver,
        tol: args.tol,
        max_iter: args.max_iter,
    };
    let result = pia
        .solve(&file.mesh.positions, &moving, &opts)
        .map_err(at_input)?;
    let t_solve = t1.elapsed().as_secs_f64();

    // The error of the output, measured with a limit table built afresh and applied to the
    // written positions, not the solver's own residual.
    spinner.message("checking");
    let t2 = Instant::now();
    let positions = &file.mesh.positions;
    let deviation =
        subd_pia::deviation(topo, &scheme, &options, &result.points, positions, &moving)
            .map_err(at_input)?;
    let (max_error, relative) = (deviation.max_error, deviation.relative);
    let t_check = t2.elapsed().as_secs_f64();
    spinner.finish();
    if !result.converged || !deviation.within(args.tol) {
        return Err(not_converged(args, job, name, &result, relative));
    }
    let fitted = Fitted {
        mesh: &file.mesh,
        points: &result.points,
        scheme: &scheme,
        options: file.output_options(),
    };

    let t3 = Instant::now();
    fitted.write(job, err)?;
    let t_write = t3.elapsed().as_secs_f64();

    if args.json {
        let report = PiaReport {
            input: job.input.display().to_string(),
            output: job.output.display().to_string(),
            scheme: name,
            solver,
            method: result.method,
            vertices: nv,
            moving: result.moving,
            iterations: result.iterations,
            converged: result.converged,
            max_error,
            max_error_relative: relative,
            tol: args.tol,
            history: result.history,
            seconds: Seconds {
                read: t_read,
                setup: t_setup,
                solve: t_solve,
                check: t_check,
                write: t_write,
                total: opened.elapsed(),
            },
            warnings: file.warnings.clone(),
        };
        crate::print_json(out, &report);
    }
    Ok(())
}

/// The vertices that move: `--moving`, all but `--fixed`, or all.
fn moving_vertices(args: &PiaArgs, nv: usize) -> Result<Moving, Failure> {
    Ok(match (&args.moving, &args.fixed) {
        (Some(f), _) => Moving::Only(read_indices(f, nv, "vertex")?),
        (None, Some(f)) => Moving::AllBut(read_indices(f, nv, "vertex")?),
        (None, None) => Moving::All,
    })
}

/// The failure of an interpolation that did not reach `--tol`: nothing is written.
fn not_converged(
    args: &PiaArgs,
    job: &Job,
    name: &str,
    result: &subd_pia::PiaResult,
    relative: f64,
) -> Failure {
    Failure {
        code: EXIT_FAILURE,
        message: format!(
            "{}: {name} interpolation did not reach --tol {} in {} iterations ({:?}): max error {:e} of the diagonal; no output written (raise --max-iter or try another --solver)",
            job.input.display(),
            args.tol,
            result.iterations,
            result.method,
            relative
        ),
    }
}

impl SolverArg {
    /// The library's solver.
    fn solver(self) -> Solver {
        match self {
            SolverArg::Auto => Solver::Auto,
            SolverArg::Iterate => Solver::Iterate,
            SolverArg::Weighted => Solver::Weighted,
            SolverArg::Cg => Solver::Cg,
            SolverArg::Chebyshev => Solver::Chebyshev,
            SolverArg::Direct => Solver::Direct,
        }
    }
}

/// The input and its fitted control points.
struct Fitted<'a> {
    mesh: &'a Mesh,
    points: &'a [subd_mesh::DVec3],
    /// The scheme the points are the cage of.
    scheme: &'a Scheme,
    /// What the output keeps of the input (a USD prim's name and units).
    options: subd_io::WriteOptions,
}

impl Fitted<'_> {
    /// Writes the fitted mesh: the input's topology, hints and texture coordinates (the
    /// topology is kept, so the coordinates stay as given) with the fitted points.
    fn write(&self, job: &Job, err: &mut dyn Write) -> Result<(), Failure> {
        let mut mesh = Mesh::new(self.mesh.topology.clone(), self.points.to_vec())
            .map_err(|e| bad(format!("{}: {e}", job.input.display())))?;
        mesh.hints = self.mesh.hints;
        mesh.fvar = self.mesh.fvar.clone();
        let mut dropped = Vec::new();
        let mut mesh = crate::cage::for_output(mesh, self.scheme, &job.output, &mut dropped)?;
        crate::uv::fit_ply(&mut mesh, &job.output, &mut dropped);
        print_warnings(err, &job.input, &dropped);
        subd_io::write_mesh(&job.output, &mesh, &self.options)?;
        Ok(())
    }
}
