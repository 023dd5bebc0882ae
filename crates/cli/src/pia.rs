//! `subd pia`: progressive iterative interpolation — a control mesh with the input's
//! topology whose limit surface passes through the input's vertices.

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use subd_mesh::Mesh;
use subd_pia::{
    InterpolationReport, InterpolationRequest, Moving, PiaOptions, Solver, interpolate,
};
use subd_schemes::{Capability, Scheme};

use crate::batch::{self, Files, Job};
use crate::choice_arg;
use crate::failure::bad;
use crate::progress::Spinner;
use crate::rule_args::RuleArgs;
use crate::scheme_arg;
use crate::vertex_data::{LambdaArgs, read_indices};
use crate::{EXIT_FAILURE, Failure, print_warnings};

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
    #[arg(long, default_value = "auto", value_parser = choice_arg::parser::<Solver>())]
    solver: Solver,
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

/// `subd pia --json`: the files, the library's report of the interpolation, and the time
/// of every step.
#[derive(Serialize)]
struct PiaReport<'a> {
    input: String,
    output: String,
    #[serde(flatten)]
    interpolation: &'a InterpolationReport,
    seconds: Seconds,
    warnings: &'a [String],
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
    let moving = moving_vertices(args, nv)?;
    let request = InterpolationRequest {
        scheme: &scheme,
        options: &options,
        moving: &moving,
        solve: PiaOptions {
            solver: args.solver,
            tol: args.tol,
            max_iter: args.max_iter,
        },
    };
    let spinner = Spinner::new(args.json || job.quiet, "interpolating");
    let fitted = interpolate(topo, &file.mesh.positions, &request)
        .map_err(|e| bad(format!("{}: {e}", job.input.display())))?;
    spinner.finish();
    if !fitted.report.converged {
        return Err(not_converged(args, job, &fitted.report));
    }
    let t_write = Instant::now();
    let cage = Fitted {
        mesh: &file.mesh,
        points: &fitted.points,
        scheme: &scheme,
        options: file.output_options(),
    };
    cage.write(job, err)?;
    let t_write = t_write.elapsed().as_secs_f64();

    if args.json {
        let s = fitted.seconds;
        let report = PiaReport {
            input: job.input.display().to_string(),
            output: job.output.display().to_string(),
            interpolation: &fitted.report,
            seconds: Seconds {
                read: t_read,
                setup: s.setup,
                solve: s.solve,
                check: s.check,
                write: t_write,
                total: opened.elapsed(),
            },
            warnings: &file.warnings,
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
fn not_converged(args: &PiaArgs, job: &Job, report: &InterpolationReport) -> Failure {
    Failure {
        code: EXIT_FAILURE,
        message: format!(
            "{}: {} interpolation did not reach --tol {} in {} iterations ({:?}): max error {:e} of the diagonal; no output written (raise --max-iter or try another --solver)",
            job.input.display(),
            report.scheme,
            args.tol,
            report.iterations,
            report.method,
            report.max_error_relative
        ),
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
