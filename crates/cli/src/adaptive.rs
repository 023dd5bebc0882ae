//! `subd adaptive`: selective Loop or Catmull-Clark refinement, crack-free, every vertex a
//! vertex of uniform refinement (or, with `--limit`, of the limit surface).

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use subd_adaptive::request::{
    AdaptOptions, AdaptiveReport, AdaptiveRequest, AdaptiveSeconds, Thresholds, adapt_mesh_with,
};
use subd_adaptive::{AdaptiveError, AdaptiveMesh};
use subd_mesh::SchemeHints;
use subd_schemes::{Capability, Scheme};

use crate::batch::{self, Files, Job};
use crate::failure::bad;
use crate::progress::Spinner;
use crate::rule_args::RuleArgs;
use crate::scheme_arg;
use crate::vertex_data::read_indices;
use crate::{Failure, print_warnings};

/// Level cap when `--levels` is not given.
const DEFAULT_LEVELS: usize = 4;

#[derive(Debug, Args)]
pub(crate) struct AdaptiveArgs {
    /// Subdivision scheme (default: the scheme the input names, USD's subdivisionScheme).
    #[arg(long, value_parser = scheme_arg::parser(Capability::Adaptive))]
    scheme: Option<Scheme>,
    /// Sun et al.'s flatness: refine every face that is not dead, a vertex being dead when the
    /// largest angle between its faces' normals is below DEG degrees.
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    flatness: Option<f64>,
    /// Refine until every face is within D × the bounding-box diagonal of the exact limit
    /// surface (sampled at corners, edge midpoints and centre).
    #[arg(long, value_name = "D", allow_negative_numbers = true)]
    max_distance: Option<f64>,
    /// Refine faces at a vertex whose Gaussian curvature (angle defect over area) times the
    /// squared bounding-box diagonal exceeds K (a sphere: 12).
    #[arg(long, value_name = "K", allow_negative_numbers = true)]
    curvature: Option<f64>,
    /// Refine both faces of an edge whose dihedral angle exceeds DEG degrees.
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    dihedral: Option<f64>,
    /// Refine the descendants of the base faces listed in F (0-based indices).
    #[arg(long, value_name = "F")]
    select_faces: Option<PathBuf>,
    /// Refine the descendants of the base faces with two or more of the vertices listed in F.
    #[arg(long, value_name = "F")]
    select_vertices: Option<PathBuf>,
    /// Level cap (0 to 15; default 4). With no criterion, every face is refined to it.
    #[arg(long)]
    levels: Option<usize>,
    /// Put every vertex at its exact limit position and write limit normals.
    #[arg(long)]
    limit: bool,
    #[command(flatten)]
    rules: RuleArgs,
    #[command(flatten)]
    files: Files,
    /// Print a JSON report on stdout. Its sampled distance to the limit comes with
    /// --max-distance (measured for the criterion anyway) or --report-distance; otherwise
    /// `max_distance_to_limit` and `max_distance_to_limit_relative` are null.
    #[arg(long)]
    json: bool,
    /// With --json, measure the largest sampled distance to the limit surface without a
    /// --max-distance criterion (a limit evaluation at 7–9 points per output face).
    #[arg(long)]
    report_distance: bool,
}

#[derive(Serialize)]
struct Timings {
    read: f64,
    #[serde(flatten)]
    adapt: AdaptiveSeconds,
    write: f64,
    total: f64,
}

/// The library's report between the files and the times, the selections named by their
/// files.
#[derive(Serialize)]
struct CliReport {
    input: String,
    output: String,
    #[serde(flatten)]
    adaptive: AdaptiveReport,
    seconds: Timings,
    warnings: Vec<String>,
}

/// Checks what can be checked before reading the input (the library's check, its errors
/// named by their flags): the thresholds and the level cap (returned).
fn check_arguments(args: &AdaptiveArgs) -> Result<usize, Failure> {
    let levels = args.levels.unwrap_or(DEFAULT_LEVELS);
    let thresholds = Thresholds {
        flatness: args.flatness,
        max_distance: args.max_distance,
        curvature: args.curvature,
        dihedral: args.dihedral,
    };
    thresholds.check(levels).map_err(|e| match e {
        AdaptiveError::Threshold {
            name,
            value,
            reason,
        } => bad(format!("--{name} {value}: {reason}")),
        AdaptiveError::TooManyLevels { levels, max } => bad(format!(
            "--levels {levels}: at most {max} levels are supported"
        )),
        e => bad(e.to_string()),
    })?;
    Ok(levels)
}

/// What the command line asks for, as the library's request (the selections read from
/// their files).
fn request_of(
    args: &AdaptiveArgs,
    mesh: &subd_mesh::Mesh,
    (scheme, options): (&Scheme, &subd_schemes::Options),
    levels: usize,
) -> Result<AdaptiveRequest, Failure> {
    let base = &mesh.topology;
    let read = |f: &Option<PathBuf>, n: usize, what: &str| -> Result<Option<Vec<u64>>, Failure> {
        f.as_ref()
            .map(|f| {
                Ok(read_indices(f, n, what)?
                    .into_iter()
                    .map(u64::from)
                    .collect())
            })
            .transpose()
    };
    Ok(AdaptiveRequest {
        scheme: scheme.clone(),
        options: *options,
        levels,
        limit: args.limit,
        flatness: args.flatness,
        max_distance: args.max_distance,
        curvature: args.curvature,
        dihedral: args.dihedral,
        select_faces: read(&args.select_faces, base.num_faces(), "face")?,
        select_vertices: read(&args.select_vertices, base.num_vertices(), "vertex")?,
        fvar_interpolation: args.rules.fvar_mode(&mesh.hints),
    })
}

/// `subd adaptive` writes meshes.
const ADAPTIVE: batch::Command = batch::Command {
    name: "adaptive",
    formats: batch::MESH_OUTPUTS,
};

pub(crate) fn run(
    args: &AdaptiveArgs,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    ADAPTIVE.run(&args.files, args.json, out, err, |job, out, err| {
        run_one(args, job, out, err)
    })
}

fn run_one(
    args: &AdaptiveArgs,
    job: &Job,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    let started = ADAPTIVE.start_job(job)?;
    let levels = check_arguments(args)?;
    let opened = started.read(&args.rules, err)?;
    let file = &opened.file;
    let mesh = &file.mesh;
    let scheme = scheme_arg::given_or_named(
        args.scheme.as_ref(),
        &mesh.hints,
        Capability::Adaptive,
        &job.input,
    )?;
    let options = args.rules.options(&mesh.hints);
    let request = request_of(args, mesh, (&scheme, &options), levels)?;
    let spinner = Spinner::new(args.json || job.quiet, "refining");
    let what = AdaptOptions {
        report: args.json,
        report_distance: args.report_distance,
    };
    let adapted = adapt_mesh_with(mesh, &request, &what, &mut |m| {
        spinner.message(m.to_string())
    })
    .map_err(|e| bad(format!("{}: {e}", job.input.display())))?;
    print_warnings(err, &job.input, &adapted.warnings);

    spinner.message("writing");
    let t3 = Instant::now();
    let uv = adapted.uv.map(|uv| crate::uv::RefinedUv {
        values: uv.values,
        indices: uv.indices,
    });
    let written = write(
        job,
        &adapted.mesh,
        &options,
        uv.as_ref(),
        &file.output_options(),
    )?;
    print_warnings(err, &job.input, &written);
    spinner.finish();
    let t_write = t3.elapsed().as_secs_f64();

    if let Some(mut report) = adapted.report {
        // The selections by their files, as they were given.
        let path = |p: &Option<PathBuf>| p.as_ref().map(|p| p.display().to_string());
        report.criteria.select_faces = path(&args.select_faces);
        report.criteria.select_vertices = path(&args.select_vertices);
        let report = CliReport {
            input: job.input.display().to_string(),
            output: job.output.display().to_string(),
            adaptive: report,
            seconds: Timings {
                read: opened.read_seconds,
                adapt: adapted.seconds,
                write: t_write,
                total: opened.elapsed(),
            },
            warnings: file.warnings.clone(),
        };
        crate::print_json(out, &report);
    }
    Ok(())
}

/// Writes the adaptive mesh; returns the warnings of leaving out UVs a PLY cannot hold.
fn write(
    job: &Job,
    mesh: &AdaptiveMesh,
    options: &subd_schemes::Options,
    uv: Option<&crate::uv::RefinedUv>,
    write_options: &subd_io::WriteOptions,
) -> Result<Vec<String>, Failure> {
    let fail = |e: subd_io::ViewError| bad(format!("{}: {e}", job.input.display()));
    let mut view = subd_io::MeshView::new(
        &mesh.positions,
        &mesh.face_offsets,
        &mesh.face_vertices,
        &mesh.holes,
    )
    .and_then(|v| v.with_face_levels(&mesh.face_levels))
    .map_err(fail)?;
    if !mesh.normals.is_empty() {
        view = view.with_normals(&mesh.normals).map_err(fail)?;
    }
    view.hints = SchemeHints {
        boundary_interpolation: Some(options.boundary_interpolation),
        crease_method: Some(options.crease_method),
        triangle_subdivision: Some(options.triangle_subdivision),
        fvar_interpolation: None,
        scheme: None,
    };
    let mut warnings = Vec::new();
    let with_uv = crate::uv::with_uv(view.clone(), uv).map_err(fail)?;
    let ply = subd_io::Format::for_output(&job.output) == Some(subd_io::Format::Ply);
    if uv.is_some() && ply && !subd_io::ply::holds_texcoords(&with_uv) {
        warnings.push(crate::uv::ply_seam_warning(&job.output));
    } else {
        view = with_uv;
    }
    subd_io::write_view(&job.output, &view, write_options)?;
    Ok(warnings)
}
