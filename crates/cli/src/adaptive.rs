//! `subd adaptive`: selective Loop or Catmull-Clark refinement, crack-free, every vertex a
//! vertex of uniform refinement (or, with `--limit`, of the limit surface).

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use subd_adaptive::request::{AdaptiveRequest, Criteria, adapted_uv};
use subd_adaptive::{
    AdaptiveError, AdaptiveMesh, AdaptiveRefinement, Conformity, LimitSurface, Positions,
};
use subd_mesh::{BoundaryInterpolation, CreaseMethod, SchemeHints, TriangleSubdivision};
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
struct CriteriaReport {
    flatness: Option<f64>,
    max_distance: Option<f64>,
    curvature: Option<f64>,
    dihedral: Option<f64>,
    select_faces: Option<String>,
    select_vertices: Option<String>,
}

#[derive(Serialize)]
struct Timings {
    read: f64,
    hierarchy: f64,
    mesh: f64,
    report: f64,
    write: f64,
    total: f64,
}

#[derive(Serialize)]
struct AdaptiveReport {
    input: String,
    output: String,
    scheme: &'static str,
    levels: usize,
    depth: usize,
    limit: bool,
    boundary_interpolation: BoundaryInterpolation,
    crease_method: CreaseMethod,
    triangle_subdivision: TriangleSubdivision,
    criteria: CriteriaReport,
    input_faces: usize,
    input_boundary_edges: usize,
    faces: usize,
    vertices: usize,
    faces_per_level: Vec<usize>,
    transition_faces: usize,
    uniform_faces: u64,
    face_ratio: f64,
    level_builds: usize,
    #[serde(flatten)]
    conformity: Conformity,
    min_angle_degrees: f64,
    /// Absolute, and relative to the bounding-box diagonal; `null` where the exact
    /// evaluator does not cover the mesh.
    max_distance_to_limit: Option<f64>,
    max_distance_to_limit_relative: Option<f64>,
    /// Whether every face is within --max-distance (`null` without it); `false` when the
    /// level cap stopped the refinement short.
    tolerance_met: Option<bool>,
    bbox_diagonal: f64,
    seconds: Timings,
    warnings: Vec<String>,
}

fn in_range(name: &str, value: f64, ok: bool, what: &str) -> Result<(), Failure> {
    if value.is_nan() || !ok {
        return Err(bad(format!("--{name} {value}: {what}")));
    }
    Ok(())
}

/// Checks what can be checked before reading the input: the thresholds and the level cap
/// (returned).
fn check_arguments(args: &AdaptiveArgs) -> Result<usize, Failure> {
    let degrees = |d: f64| (0.0..=180.0).contains(&d);
    if let Some(d) = args.flatness {
        in_range("flatness", d, degrees(d), "expected degrees in [0, 180]")?;
    }
    if let Some(d) = args.dihedral {
        in_range("dihedral", d, degrees(d), "expected degrees in [0, 180]")?;
    }
    if let Some(d) = args.max_distance {
        let ok = d.is_finite() && d > 0.0;
        in_range("max-distance", d, ok, "expected a positive number")?;
    }
    if let Some(k) = args.curvature {
        let ok = k.is_finite() && k >= 0.0;
        in_range("curvature", k, ok, "expected a number ≥ 0")?;
    }
    let levels = args.levels.unwrap_or(DEFAULT_LEVELS);
    if levels > subd_adaptive::MAX_LEVELS {
        return Err(bad(format!(
            "--levels {levels}: at most {} levels are supported",
            subd_adaptive::MAX_LEVELS
        )));
    }
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
    let (file, t_read) = (&opened.file, opened.read_seconds);
    let (mesh, base) = (&file.mesh, &file.mesh.topology);
    let scheme = scheme_arg::given_or_named(
        args.scheme.as_ref(),
        &mesh.hints,
        Capability::Adaptive,
        &job.input,
    )?;
    let options = args.rules.options(&mesh.hints);
    let input_err = |e: AdaptiveError| bad(format!("{}: {e}", job.input.display()));
    let diagonal = mesh
        .bounding_box()
        .map_or(0.0, |(lo, hi)| (hi - lo).length());
    let request = request_of(args, mesh, (&scheme, &options), levels)?;
    let selection = Criteria::new(mesh, &request, diagonal).map_err(input_err)?;

    let spinner = Spinner::new(args.json || job.quiet, "refining");
    let t0 = Instant::now();
    let mut hierarchy = AdaptiveRefinement::with_progress(
        base,
        &mesh.positions,
        &scheme,
        &options,
        &selection.all(),
        levels,
        &mut |level, faces| spinner.message(format!("level {level}: {faces} faces")),
    )
    .map_err(input_err)?;
    let t_hierarchy = t0.elapsed().as_secs_f64();
    spinner.message("conforming mesh");
    let t1 = Instant::now();
    let positions = if args.limit {
        Positions::Limit
    } else {
        Positions::Refined
    };
    // The distance criterion judged this very mesh: taken, not built again.
    let result = hierarchy.take_mesh(positions).map_err(input_err)?;
    let t_mesh = t1.elapsed().as_secs_f64();

    let t2 = Instant::now();
    // One limit evaluator serves the distance criterion, the report and the UVs.
    let own;
    let surface = match &selection.distance {
        Some(d) => Some(d.surface()),
        None if (args.json && args.report_distance) || mesh.uv().is_some() => {
            own = LimitSurface::new(base, &mesh.positions, &scheme, &options);
            own.as_ref().ok()
        }
        None => None,
    };
    spinner.message("measuring");
    let check = check_distance(args, &selection, &hierarchy, &result, surface, levels);
    if let Some(warning) = check.warning(args, levels, diagonal) {
        print_warnings(err, &job.input, &[warning]);
    }
    let measured = args.json.then(|| measure(&result));
    let t_report = t2.elapsed().as_secs_f64();

    spinner.message("texture coordinates");
    let uv = adaptive_uv(mesh, &request, surface, &result, err, job);
    spinner.message("writing");
    let t3 = Instant::now();
    let written = write(job, &result, &options, uv.as_ref(), &file.output_options())?;
    print_warnings(err, &job.input, &written);
    spinner.finish();
    let t_write = t3.elapsed().as_secs_f64();

    if let Some(measured) = measured {
        let seconds = Timings {
            read: t_read,
            hierarchy: t_hierarchy,
            mesh: t_mesh,
            report: t_report,
            write: t_write,
            total: opened.elapsed(),
        };
        let context = ReportContext {
            args,
            job,
            base,
            options: &options,
            levels,
            diagonal,
            warnings: &file.warnings,
        };
        let report = context.report(&hierarchy, &result, (measured, check), seconds);
        crate::print_json(out, &report);
    }
    Ok(())
}

/// The largest sampled distance of the output to the limit surface (for the report), and
/// whether it meets --max-distance.
struct DistanceCheck {
    /// For the report (with --json).
    distance: Option<f64>,
    /// What the tolerance was checked with.
    worst: Option<f64>,
    met: Option<bool>,
}

impl DistanceCheck {
    /// The warning that the level cap stopped --max-distance short, naming the level that
    /// would meet it by the distance's ~4× fall per level (Loop and Catmull-Clark converge
    /// quadratically in the edge length, which halves per level).
    fn warning(&self, args: &AdaptiveArgs, levels: usize, diagonal: f64) -> Option<String> {
        let (Some(false), Some(tolerance)) = (self.met, args.max_distance) else {
            return None;
        };
        let worst = self.worst? / diagonal;
        let more = (worst / tolerance).log(4.0).ceil().max(1.0) as usize;
        Some(format!(
            "--max-distance {tolerance:e} not met: --levels {levels} stopped the refinement \
             at a sampled distance of {worst:.3e} × the diagonal; about level {} would meet \
             it (the distance falls ~4× per level)",
            levels + more
        ))
    }
}

/// Measures the output's distance to the limit where it is asked for: with --max-distance
/// from what the criterion measured on this mesh (reused, not measured again), with
/// --report-distance and --json here; `None` otherwise.
fn check_distance(
    args: &AdaptiveArgs,
    selection: &Criteria,
    hierarchy: &AdaptiveRefinement,
    result: &AdaptiveMesh,
    surface: Option<&LimitSurface>,
    levels: usize,
) -> DistanceCheck {
    let Some(criterion) = &selection.distance else {
        let wanted = args.json && args.report_distance;
        let distance = surface
            .filter(|_| wanted)
            .and_then(|s| result.max_limit_distance(s).ok());
        return DistanceCheck {
            distance,
            worst: None,
            met: None,
        };
    };
    // The distance criterion is the last one (Criteria::all).
    let judged = hierarchy.final_errors().last().copied().flatten();
    // With --limit the criterion left the leaves to its level-by-level selection, which
    // cleared those below the cap: the cap's leaves decide the tolerance, all of them the
    // report's distance.
    let leaves = |all: bool| {
        result
            .max_limit_distance_of(criterion.surface(), |f| {
                !criterion.judged(result, f) && (all || result.face_levels[f] as usize == levels)
            })
            .ok()
    };
    let worst = if args.limit {
        judged.zip(leaves(args.json)).map(|(a, b)| a.max(b))
    } else {
        judged
    };
    DistanceCheck {
        distance: worst.filter(|_| args.json),
        worst,
        met: worst.map(|w| w <= criterion.tolerance()),
    }
}

/// What the JSON report says besides the hierarchy and the mesh.
struct ReportContext<'a> {
    args: &'a AdaptiveArgs,
    job: &'a Job,
    base: &'a subd_mesh::Topology,
    options: &'a subd_schemes::Options,
    levels: usize,
    diagonal: f64,
    warnings: &'a [String],
}

impl ReportContext<'_> {
    fn report(
        &self,
        hierarchy: &AdaptiveRefinement,
        result: &AdaptiveMesh,
        ((conformity, min_angle), check): ((Conformity, f64), DistanceCheck),
        seconds: Timings,
    ) -> AdaptiveReport {
        let (args, job, base, options) = (self.args, self.job, self.base, self.options);
        let depth = hierarchy.depth();
        let uniform_faces = hierarchy.uniform_counts(depth).faces;
        let path = |p: &Option<PathBuf>| p.as_ref().map(|p| p.display().to_string());
        AdaptiveReport {
            input: job.input.display().to_string(),
            output: job.output.display().to_string(),
            scheme: hierarchy.scheme().name(),
            levels: self.levels,
            depth,
            limit: args.limit,
            boundary_interpolation: options.boundary_interpolation,
            crease_method: options.crease_method,
            triangle_subdivision: options.triangle_subdivision,
            criteria: CriteriaReport {
                flatness: args.flatness,
                max_distance: args.max_distance,
                curvature: args.curvature,
                dihedral: args.dihedral,
                select_faces: path(&args.select_faces),
                select_vertices: path(&args.select_vertices),
            },
            input_faces: base.num_faces(),
            input_boundary_edges: (0..base.num_edges())
                .filter(|&e| base.is_boundary_edge(e))
                .count(),
            faces: result.num_faces(),
            vertices: result.positions.len(),
            faces_per_level: result.faces_per_level(),
            transition_faces: result.transition.iter().filter(|&&t| t).count(),
            uniform_faces,
            face_ratio: result.num_faces() as f64 / uniform_faces.max(1) as f64,
            level_builds: hierarchy.level_builds(),
            conformity,
            min_angle_degrees: min_angle,
            max_distance_to_limit: check.distance,
            max_distance_to_limit_relative: check.distance.map(|d| d / self.diagonal),
            tolerance_met: check.met,
            bbox_diagonal: self.diagonal,
            seconds,
            warnings: self.warnings.to_vec(),
        }
    }
}

/// The report's cheap measures: conformity and smallest angle.
fn measure(mesh: &AdaptiveMesh) -> (Conformity, f64) {
    (mesh.conformity(), mesh.min_angle_degrees())
}

/// The input's texture coordinates on the adaptive mesh: their exact limit at every corner's
/// parameter (`None` without UVs, or with a warning where they cannot be evaluated).
fn adaptive_uv(
    mesh: &subd_mesh::Mesh,
    request: &AdaptiveRequest,
    surface: Option<&LimitSurface>,
    result: &AdaptiveMesh,
    err: &mut dyn Write,
    job: &Job,
) -> Option<crate::uv::RefinedUv> {
    mesh.uv()?;
    let evaluator = surface.map(LimitSurface::evaluator);
    match adapted_uv(mesh, request, evaluator, result) {
        Ok(uv) => Some(crate::uv::RefinedUv {
            values: uv.values,
            indices: uv.indices,
        }),
        Err(e) => {
            print_warnings(
                err,
                &job.input,
                &[format!("texture coordinates left out: {e}")],
            );
            None
        }
    }
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
