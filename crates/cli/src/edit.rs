//! `subd edit`: move the limit surface to meet constraints (Li et al. 2008), and `subd deform`:
//! simple constrained deformation of a mesh at any level (Sun et al. 2012 §3).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use subd_editing::{Constraint, Deformation, EditReport, Method, MethodKind, MethodRequest};
use subd_mesh::{DVec3, Mesh};
use subd_schemes::{Capability, Scheme};

use crate::batch::{self, Files, Job};
use crate::choice_arg;
use crate::failure::bad;
use crate::rule_args::RuleArgs;
use crate::scheme_arg;
use crate::{Failure, print_warnings};

#[derive(Debug, Args)]
pub(crate) struct EditArgs {
    /// Constraint file (JSON; see the README for the schema).
    #[arg(long, value_name = "FILE")]
    constraints: PathBuf,
    /// How the control vertices change.
    #[arg(long, default_value = "least-squares", value_parser = choice_arg::parser::<MethodKind>())]
    method: MethodKind,
    /// Scheme of the limit surface (the energy method needs catmull-clark; default: the
    /// scheme the input names, USD's subdivisionScheme, if catmull-clark or loop, else
    /// catmull-clark).
    #[arg(long, value_parser = scheme_arg::parser(Capability::Edit))]
    scheme: Option<Scheme>,
    /// Energy method: Li et al.'s penalty form with this weight (relative to
    /// mean diag Q / mean diag AᵀA) instead of the exact solve.
    #[arg(long, conflicts_with = "exact")]
    penalty: Option<f64>,
    /// Energy method: the exact equality-constrained solve (the default).
    #[arg(long)]
    exact: bool,
    /// Energy method: weight of the membrane term ∬ S_u² + S_v².
    #[arg(long, default_value_t = 0.0)]
    membrane: f64,
    /// Energy method: only vertices within K rings of the constraints move (default 3;
    /// `all`: every vertex, so that one point constraint translates the whole surface).
    #[arg(long, value_name = "K", default_value = "3")]
    region_rings: String,
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
    constraints: f64,
    assemble: f64,
    factor: f64,
    solve: f64,
    check: f64,
    write: f64,
    total: f64,
}

/// `subd edit --json`: the files, the library's report of the edit, and the time of every
/// step.
#[derive(Serialize)]
struct CliEditReport<'a> {
    input: String,
    output: String,
    #[serde(flatten)]
    edit: &'a EditReport,
    seconds: Seconds,
}

fn read_text(path: &Path) -> Result<String, Failure> {
    std::fs::read_to_string(path).map_err(|e| bad(format!("{}: cannot read: {e}", path.display())))
}

fn region_rings(text: &str) -> Result<Option<usize>, Failure> {
    if text == "all" {
        return Ok(None);
    }
    text.parse::<usize>().map(Some).map_err(|_| {
        bad(format!(
            "--region-rings {text:?}: expected a number of rings or `all`"
        ))
    })
}

/// The method the arguments ask for.
fn method(args: &EditArgs) -> Result<Method, Failure> {
    MethodRequest {
        kind: args.method,
        penalty: args.penalty,
        exact: args.exact,
        membrane: args.membrane,
        region_rings: region_rings(&args.region_rings)?,
    }
    .method()
    .map_err(bad)
}

pub(crate) fn run(
    args: &EditArgs,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    EDIT.run(&args.files, args.json, out, err, |job, out, err| {
        run_one(args, job, out, err)
    })
}

/// `subd edit` writes meshes.
const EDIT: batch::Command = batch::Command {
    name: "edit",
    formats: batch::MESH_OUTPUTS,
};

/// `subd deform` writes meshes.
const DEFORM: batch::Command = batch::Command {
    name: "deform",
    formats: batch::MESH_OUTPUTS,
};

/// The constraints of `path`, at least one.
fn read_constraints(path: &Path) -> Result<Vec<Constraint>, Failure> {
    let constraints = subd_editing::spec::parse_constraints(&read_text(path)?)
        .map_err(|e| bad(format!("{}: {e}", path.display())))?;
    if constraints.is_empty() {
        return Err(bad(format!("{}: no constraints", path.display())));
    }
    Ok(constraints)
}

/// Writes IN's topology, tags and texture coordinates with the edited control vertices: a
/// cage that a USD renderer subdivides with `scheme`.
fn write_edited(
    job: &Job,
    file: &subd_io::MeshFile,
    scheme: &Scheme,
    positions: &[DVec3],
    err: &mut dyn Write,
) -> Result<(), Failure> {
    let mut mesh = Mesh::new(file.mesh.topology.clone(), positions.to_vec())
        .map_err(|e| bad(format!("{}: {e}", job.input.display())))?;
    mesh.hints = file.mesh.hints;
    // The edit moves control points only: texture coordinates stay as given.
    mesh.fvar = file.mesh.fvar.clone();
    let mut dropped = Vec::new();
    let mut mesh = crate::cage::for_output(mesh, scheme, &job.output, &mut dropped)?;
    crate::uv::fit_ply(&mut mesh, &job.output, &mut dropped);
    print_warnings(err, &job.input, &dropped);
    subd_io::write_mesh(&job.output, &mesh, &file.output_options())?;
    Ok(())
}

fn run_one(
    args: &EditArgs,
    job: &Job,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    let started = EDIT.start_job(job)?;
    let method = method(args)?;
    let constraints = read_constraints(&args.constraints)?;
    let opened = started.read(&args.rules, err)?;
    let (file, t_read) = (&opened.file, opened.read_seconds);
    let named = file.mesh.hints.scheme.and_then(Scheme::from_file);
    let scheme = args
        .scheme
        .clone()
        .or(named.filter(|s| s.supports(Capability::Edit)))
        .unwrap_or(Scheme::CatmullClark);
    let options = args.rules.options(&file.mesh.hints);
    let topo = &file.mesh.topology;
    let named = |e: subd_editing::EditError| match e {
        subd_editing::EditError::Constraint { .. } => {
            bad(format!("{}: {e}", args.constraints.display()))
        }
        e => bad(format!("{}: {e}", job.input.display())),
    };
    let edited = subd_editing::edit_mesh(&file.mesh, &scheme, &options, &constraints, method, true)
        .map_err(named)?;
    print_warnings(err, &args.constraints, &edited.warnings);
    let t_write = Instant::now();
    write_edited(job, file, &scheme, &edited.edit.positions, err)?;
    let t_write = t_write.elapsed().as_secs_f64();

    if args.json {
        let t = edited.seconds();
        let report = CliEditReport {
            input: job.input.display().to_string(),
            output: job.output.display().to_string(),
            edit: &edited.report(&scheme, &method, topo.num_vertices(), &constraints),
            seconds: Seconds {
                read: t_read,
                constraints: t.constraints,
                assemble: t.assemble,
                factor: t.factor,
                solve: t.solve,
                check: t.check,
                write: t_write,
                total: opened.elapsed(),
            },
        };
        crate::print_json(out, &report);
    }
    Ok(())
}

#[derive(Debug, Args)]
pub(crate) struct DeformArgs {
    /// Deformation file (JSON: constraint points with radius and displacement).
    #[arg(long, value_name = "FILE")]
    constraints: PathBuf,
    #[command(flatten)]
    files: Files,
    /// Print a JSON report on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct DeformReport {
    input: String,
    output: String,
    vertices: usize,
    constraints: usize,
    moved: usize,
    /// max |d(C_i) − D_i| over the constraint points, from the solved deformation.
    max_constraint_error: f64,
    seconds: f64,
}

pub(crate) fn run_deform(
    args: &DeformArgs,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    DEFORM.run(&args.files, args.json, out, err, |job, out, err| {
        run_deform_one(args, job, out, err)
    })
}

fn run_deform_one(
    args: &DeformArgs,
    job: &Job,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    let started = DEFORM.start_job(job)?;
    let cs = subd_editing::spec::parse_deformation(&read_text(&args.constraints)?)
        .map_err(|e| bad(format!("{}: {e}", args.constraints.display())))?;
    let d =
        Deformation::new(&cs).map_err(|e| bad(format!("{}: {e}", args.constraints.display())))?;
    let opened = started.read_with(&subd_io::ReadOptions::default(), err)?;
    let started = opened.started;
    let write_options = opened.file.output_options();
    let mut mesh = opened.file.mesh;
    let moved = d.apply(&mut mesh.positions);
    let max_err = d.max_constraint_error();
    let mut dropped = Vec::new();
    crate::uv::fit_ply(&mut mesh, &job.output, &mut dropped);
    print_warnings(err, &job.input, &dropped);
    subd_io::write_mesh(&job.output, &mesh, &write_options)?;
    if args.json {
        crate::print_json(
            out,
            &DeformReport {
                input: job.input.display().to_string(),
                output: job.output.display().to_string(),
                vertices: mesh.positions.len(),
                constraints: cs.len(),
                moved,
                max_constraint_error: max_err,
                seconds: started.elapsed().as_secs_f64(),
            },
        );
    }
    Ok(())
}
