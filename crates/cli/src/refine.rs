//! `subd refine`: uniform refinement of a mesh file with any surface scheme (one
//! `subd_schemes::Refinement`): Catmull-Clark, Loop or Bilinear (OpenSubdiv's schemes), seed
//! 000's two-phase scheme, or Doo-Sabin, √3 and the butterflies.

use std::io::{IsTerminal, Write};
use std::time::Instant;

use clap::{Args, ValueEnum};
use serde::Serialize;
use subd_limit::split_limit::SplitLimitStencils;
use subd_mesh::{BoundaryInterpolation, CreaseMethod, SchemeHints, TriangleSubdivision};
use subd_schemes::{Refinement, Scheme, TwoPhase};

use crate::batch::{self, Files, Job};
use crate::budget::{Budget, PeakModel};
use crate::failure::{bad, refuse_overwrite};
use crate::rule_args::RuleArgs;
use crate::vertex_data::LambdaArgs;
use crate::{Failure, print_warnings};

#[derive(Debug, Clone, Copy, ValueEnum)]
pub(crate) enum SchemeArg {
    CatmullClark,
    Loop,
    Bilinear,
    /// Seed 000's two-phase modified Catmull-Clark (needs --lambda or --lambda-file).
    TwoPhase,
    /// Doo-Sabin's dual scheme, any polygons.
    DooSabin,
    /// Kobbelt's √3 scheme, triangles.
    Sqrt3,
    /// The interpolating butterfly scheme (Dyn, Levin, Gregory), triangles; see --tension.
    Butterfly,
    /// Zorin, Schröder and Sweldens' modified butterfly, triangles.
    ModifiedButterfly,
}

impl SchemeArg {
    /// The scheme, with the butterfly's `tension` and the two-phase scheme's `λ`.
    pub(crate) fn scheme(self, tension: f64, two_phase: Option<TwoPhase>) -> Scheme {
        match self {
            SchemeArg::CatmullClark => Scheme::CatmullClark,
            SchemeArg::TwoPhase => Scheme::TwoPhase(two_phase.unwrap_or_else(TwoPhase::unset)),
            SchemeArg::Loop => Scheme::Loop,
            SchemeArg::Bilinear => Scheme::Bilinear,
            SchemeArg::DooSabin => Scheme::DooSabin,
            SchemeArg::Sqrt3 => Scheme::Sqrt3,
            SchemeArg::Butterfly => Scheme::Butterfly { tension },
            SchemeArg::ModifiedButterfly => Scheme::ModifiedButterfly,
        }
    }

    /// The name the command line uses.
    pub(crate) fn name(self) -> &'static str {
        match self {
            SchemeArg::CatmullClark => "catmull-clark",
            SchemeArg::Loop => "loop",
            SchemeArg::Bilinear => "bilinear",
            SchemeArg::TwoPhase => "two-phase",
            SchemeArg::DooSabin => "doo-sabin",
            SchemeArg::Sqrt3 => "sqrt3",
            SchemeArg::Butterfly => "butterfly",
            SchemeArg::ModifiedButterfly => "modified-butterfly",
        }
    }
}

#[derive(Debug, Args)]
pub(crate) struct RefineArgs {
    /// Subdivision scheme.
    #[arg(long, value_enum)]
    scheme: SchemeArg,
    /// Number of uniform refinement levels (0 to 15; for two-phase, level 1 is phase 1).
    #[arg(long)]
    levels: usize,
    /// Tension w of --scheme butterfly (default 1/16, the classic scheme).
    #[arg(long, allow_hyphen_values = true)]
    tension: Option<f64>,
    #[command(flatten)]
    lambda: LambdaArgs,
    #[command(flatten)]
    rules: RuleArgs,
    #[command(flatten)]
    files: Files,
    /// The memory the refinement may use (e.g. 800M, 4G); default: the available memory
    /// and the address-space limit (`ulimit -v`). A request estimated to need more is
    /// refused before any work, naming the deepest level that fits.
    #[arg(long, value_name = "SIZE", value_parser = crate::budget::parse_size)]
    max_memory: Option<u64>,
    /// Move every output vertex to its exact limit position and write its limit normal
    /// (OBJ `vn`, PLY `nx ny nz`, glTF `NORMAL`): the limit masks of the output level.
    #[arg(long)]
    limit: bool,
    /// Print a JSON report (counts, timings) on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct Counts {
    vertices: usize,
    edges: Option<usize>,
    faces: usize,
}

#[derive(Serialize)]
struct Timings {
    read: f64,
    topology: f64,
    positions: f64,
    write: f64,
    total: f64,
}

#[derive(Serialize)]
struct RefineReport {
    input: String,
    output: String,
    scheme: &'static str,
    levels: usize,
    /// The butterfly's tension.
    #[serde(skip_serializing_if = "Option::is_none")]
    tension: Option<f64>,
    /// OpenSubdiv's rule options (its schemes only).
    #[serde(skip_serializing_if = "Option::is_none")]
    boundary_interpolation: Option<BoundaryInterpolation>,
    #[serde(skip_serializing_if = "Option::is_none")]
    crease_method: Option<CreaseMethod>,
    #[serde(skip_serializing_if = "Option::is_none")]
    triangle_subdivision: Option<TriangleSubdivision>,
    /// Whether the vertices were moved to the limit surface.
    limit: bool,
    input_counts: Counts,
    output_counts: Counts,
    seconds: Timings,
    warnings: Vec<String>,
}

/// A refinement, and the limit stencils of a split scheme's last level once asked for: the
/// positions and the texture coordinates take their limits through the same ones.
pub(crate) struct Refined {
    refinement: Refinement,
    last_limit: std::sync::OnceLock<Result<SplitLimitStencils, String>>,
}

impl std::ops::Deref for Refined {
    type Target = Refinement;
    fn deref(&self) -> &Refinement {
        &self.refinement
    }
}

impl Refined {
    /// Refines `base` with `scheme`; the error names the element.
    pub(crate) fn new(
        base: &subd_mesh::Topology,
        scheme: Scheme,
        options: &subd_schemes::Options,
        levels: usize,
    ) -> Result<Refined, String> {
        Ok(Refined {
            refinement: Refinement::new(base, scheme, options, levels)
                .map_err(|e| e.to_string())?,
            last_limit: std::sync::OnceLock::new(),
        })
    }

    /// The limit stencils of a split scheme's last level, built on first request.
    pub(crate) fn last_limit(&self) -> Result<&SplitLimitStencils, String> {
        self.last_limit
            .get_or_init(|| {
                let last = self.topology(self.num_levels());
                subd_limit::split_limit::checked_split_limit_stencils(last, self.scheme())
                    .map_err(|e| e.to_string())
            })
            .as_ref()
            .map_err(Clone::clone)
    }

    /// Edges of the level; not counted for a split scheme's last level, whose edges are
    /// never built.
    fn edges(&self, level: usize) -> Option<usize> {
        if self.scheme().is_opensubdiv() {
            self.num_edges(level)
        } else {
            None
        }
    }

    pub(crate) fn last_positions(&self, base: &[subd_mesh::DVec3]) -> Vec<subd_mesh::DVec3> {
        // Each level dropped once the next is computed.
        self.points_at(base, self.num_levels())
    }
}

pub(crate) fn run(
    args: &RefineArgs,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    let command = batch::Command {
        name: "refine",
        formats: batch::MESH_OUTPUTS,
    };
    batch::run(
        &args.files,
        &command,
        args.json,
        out,
        err,
        |job, out, err| run_one(args, job, out, err),
    )
}

fn run_one(
    args: &RefineArgs,
    job: &Job,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    let t_start = Instant::now();
    refuse_overwrite(&job.input, &job.output)?;
    if subd_io::Format::for_output(&job.output).is_none() {
        return Err(bad(format!(
            "{}: unsupported output extension (expected .obj, .ply or .glb)",
            job.output.display()
        )));
    }
    if args.tension.is_some() && !matches!(args.scheme, SchemeArg::Butterfly) {
        return Err(bad("--tension applies to --scheme butterfly only".into()));
    }
    let tension = crate::rule_args::butterfly_tension(args.tension)?;
    let mut file = subd_io::read_mesh(&job.input, &args.rules.read_options())?;
    print_warnings(err, &job.input, &file.warnings);
    let warned = file.warnings.len();
    let t_read = t_start.elapsed().as_secs_f64();
    let options = args.rules.options(&file.mesh.hints);
    let base = &file.mesh.topology;
    let two_phase = match args.scheme {
        SchemeArg::TwoPhase => Some(args.lambda.two_phase(&job.input, base.num_vertices())?),
        _ if args.lambda.given() => {
            return Err(bad(
                "--lambda and --lambda-file apply to --scheme two-phase only".into(),
            ));
        }
        _ => None,
    };
    let scheme = args.scheme.scheme(tension, two_phase);
    check_memory(args, job, &file, &scheme)?;

    let progress = Progress::new(args.levels, args.json || job.quiet);
    let t0 = Instant::now();
    let in_file = |e: &dyn std::fmt::Display| bad(format!("{}: {e}", job.input.display()));
    let refinement =
        Refined::new(base, scheme.clone(), &options, args.levels).map_err(|e| in_file(&e))?;
    let input_counts = Counts {
        vertices: base.num_vertices(),
        edges: Some(base.num_edges()),
        faces: base.num_faces(),
    };
    let fvar_mode = args.rules.fvar_mode(&file.mesh.hints);
    let uv = crate::uv::refined_uv(
        &refinement,
        &file.mesh,
        fvar_mode,
        args.limit,
        &mut file.warnings,
    )
    .map_err(|e| in_file(&e))?;
    // PLY holds one texture coordinate per vertex: a seamed layout is left out (a refined
    // level gives a seamless layout exactly one value per vertex).
    let uv = match uv {
        Some(u)
            if subd_io::Format::for_output(&job.output) == Some(subd_io::Format::Ply)
                && if args.levels == 0 {
                    let t = &file.mesh.topology;
                    !subd_io::MeshView::new(
                        &file.mesh.positions,
                        t.face_offsets(),
                        t.all_face_vertices(),
                        &[],
                    )
                    .and_then(|v| v.with_uv(&u.values, 2, &u.indices))
                    .is_ok_and(|v| subd_io::ply::holds_texcoords(&v))
                } else {
                    u.values.len() / 2 != refinement.topology(args.levels).num_vertices()
                } =>
        {
            file.warnings.push(crate::uv::ply_seam_warning(&job.output));
            None
        }
        u => u,
    };
    print_warnings(
        err,
        &job.input,
        &file.warnings[file.warnings.len().min(warned)..],
    );
    // The refinement holds its own copy of the base level: the file's is not needed again.
    if let Ok(empty) = subd_mesh::TopologyBuilder::new(0).build(&[], &[]) {
        file.mesh.topology = empty;
    }
    progress.step("topology");
    let t_topology = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let osd = scheme.is_opensubdiv();
    let mut hints = output_hints(osd, &options, &file.mesh.hints, &args.rules);
    hints.fvar_interpolation = uv.as_ref().map(|_| fvar_mode);
    let in_view = |e: subd_io::ViewError| bad(format!("{}: {e}", job.input.display()));
    let streams = match &refinement {
        r if osd && !args.limit && args.levels > 0 => Some(r),
        _ => None,
    };
    let (out_counts, t_positions, t2) = if let Some(r) = streams {
        // The last level straight to the file, a window at a time, from the level above.
        let above = r.points_at(&file.mesh.positions, args.levels - 1);
        let points = crate::level_stream::Points(r.point_stream(&above).expect("levels > 0"));
        let faces = crate::level_stream::Faces(r.face_stream().expect("levels > 0"));
        // `.glb` normals need every position at hand.
        let held = (subd_io::Format::for_output(&job.output) == Some(subd_io::Format::Glb))
            .then(|| points.all());
        progress.step("positions");
        let t_positions = t1.elapsed().as_secs_f64();
        let t2 = Instant::now();
        let source = match &held {
            Some(p) => subd_io::Points::Held(p),
            None => subd_io::Points::Streamed(&points),
        };
        let tags = refinement.explicit_tags(args.levels);
        let view = subd_io::MeshView::streamed(source, &faces, faces.0.hole_faces())
            .and_then(|v| v.with_tags(tags.creases, tags.corners))
            .and_then(|v| crate::uv::with_uv(v, uv.as_ref()))
            .map_err(in_view)?;
        let counts = write_level(job, view, hints, refinement.edges(args.levels))?;
        (counts, t_positions, t2)
    } else {
        let mut positions = refinement.last_positions(&file.mesh.positions);
        let normals = if args.limit {
            let limit = output_limit(&refinement, args.levels, &options, &positions)
                .map_err(|e| in_file(&e))?;
            positions = limit.positions;
            Some(limit.normals)
        } else {
            None
        };
        progress.step("positions");
        let t_positions = t1.elapsed().as_secs_f64();
        let t2 = Instant::now();
        // Polygons, holes and the tags a reader cannot infer are all the file holds: they
        // are written without building the output level's edges (most of the time and
        // memory of a deep refinement's output).
        let (offsets, vertices) = refinement.faces(args.levels);
        let tags = refinement.explicit_tags(args.levels);
        let holes = refinement.holes(args.levels);
        let mut view = subd_io::MeshView::new(&positions, offsets, vertices, &holes)
            .and_then(|v| v.with_tags(tags.creases, tags.corners))
            .and_then(|v| crate::uv::with_uv(v, uv.as_ref()))
            .map_err(in_view)?;
        let filled;
        if let Some(n) = &normals {
            filled = normals_or_faces(n, &view);
            view = view.with_normals(&filled).map_err(in_view)?;
        }
        let counts = write_level(job, view, hints, refinement.edges(args.levels))?;
        (counts, t_positions, t2)
    };
    progress.finish();
    let t_write = t2.elapsed().as_secs_f64();

    if args.json {
        let report = RefineReport {
            input: job.input.display().to_string(),
            output: job.output.display().to_string(),
            scheme: args.scheme.name(),
            levels: args.levels,
            tension: scheme.tension(),
            boundary_interpolation: osd.then_some(options.boundary_interpolation),
            crease_method: osd.then_some(options.crease_method),
            triangle_subdivision: osd.then_some(options.triangle_subdivision),
            limit: args.limit,
            input_counts,
            output_counts: out_counts,
            seconds: Timings {
                read: t_read,
                topology: t_topology,
                positions: t_positions,
                write: t_write,
                total: t_start.elapsed().as_secs_f64(),
            },
            warnings: file.warnings.clone(),
        };
        crate::print_json(out, &report);
    }
    Ok(())
}

/// Writes the output level with its hints; its counts for the report.
fn write_level(
    job: &Job,
    mut view: subd_io::MeshView<'_>,
    hints: SchemeHints,
    edges: Option<usize>,
) -> Result<Counts, Failure> {
    view.hints = hints;
    subd_io::write_view(&job.output, &view, &subd_io::WriteOptions::default())?;
    Ok(Counts {
        vertices: view.num_vertices(),
        edges,
        faces: view.num_faces(),
    })
}

/// The scheme hints a refined file records: OpenSubdiv's rule options, for its schemes
/// only.
fn output_hints(
    osd: bool,
    options: &subd_schemes::Options,
    read: &SchemeHints,
    rules: &RuleArgs,
) -> SchemeHints {
    if !osd {
        return SchemeHints::default();
    }
    SchemeHints {
        boundary_interpolation: Some(options.boundary_interpolation),
        crease_method: Some(options.crease_method),
        triangle_subdivision: read
            .triangle_subdivision
            .or(rules.triangles.map(|_| options.triangle_subdivision)),
        fvar_interpolation: read.fvar_interpolation,
    }
}

/// Refuses the request if its estimated peak memory is over the budget (see
/// [`crate::budget`]).
fn check_memory(
    args: &RefineArgs,
    job: &Job,
    file: &subd_io::MeshFile,
    scheme: &Scheme,
) -> Result<(), Failure> {
    let base = &file.mesh.topology;
    let counts = subd_schemes::refined_counts(base, scheme, args.levels);
    let model = PeakModel::of(scheme);
    let file_bytes = std::fs::metadata(&job.input).map_or(0, |m| m.len());
    let glb = subd_io::Format::for_output(&job.output) == Some(subd_io::Format::Glb);
    let budget = Budget::detect(args.max_memory).map(|b| b.share(job.concurrent));
    crate::budget::check_refinement(
        &job.input,
        &counts,
        |last| model.peak(file_bytes, last, glb, args.limit),
        budget,
    )
}

/// The exact limit (positions and normals) of the vertices of the output level, from the
/// limit masks of that level's own topology: what Blender calls "use limit surface".
pub(crate) fn output_limit(
    refinement: &Refined,
    level: usize,
    options: &subd_schemes::Options,
    positions: &[subd_mesh::DVec3],
) -> Result<subd_limit::LimitPoints, String> {
    let scheme = &refinement.scheme().at_level(level);
    if scheme.is_opensubdiv() || level < refinement.num_levels() {
        return subd_limit::limit_points(refinement.topology(level), scheme, options, positions)
            .map_err(|e| e.to_string());
    }
    // A split scheme's last level: the stencils its texture coordinates share.
    refinement
        .last_limit()?
        .limit_points(scheme, positions)
        .map_err(|e| e.to_string())
}

/// `normals` where they are unit vectors; elsewhere (a split scheme's creases and corners,
/// parallel tangents) the area-weighted normal of the output faces, as `.glb` shading uses.
pub(crate) fn normals_or_faces(
    normals: &[subd_mesh::DVec3],
    view: &subd_io::MeshView<'_>,
) -> Vec<subd_mesh::DVec3> {
    let from_faces = subd_io::glb::vertex_normals(view);
    normals
        .iter()
        .zip(from_faces)
        .map(|(n, f)| {
            if n.is_finite() && n.length_squared() > 0.5 {
                *n
            } else {
                f.try_normalize().unwrap_or(subd_mesh::DVec3::Z)
            }
        })
        .collect()
}

/// A progress bar on a terminal for refinements deep enough to take a while; nothing when
/// stderr is not a terminal or a JSON report was asked for.
struct Progress(Option<indicatif::ProgressBar>);

impl Progress {
    fn new(levels: usize, json: bool) -> Progress {
        if json || levels < 4 || !std::io::stderr().is_terminal() {
            return Progress(None);
        }
        let bar = indicatif::ProgressBar::new(3);
        bar.set_style(
            indicatif::ProgressStyle::with_template("{spinner} refining [{bar:20}] {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        bar.set_message("topology");
        bar.enable_steady_tick(std::time::Duration::from_millis(100));
        Progress(Some(bar))
    }

    fn step(&self, done: &str) {
        if let Some(b) = &self.0 {
            b.inc(1);
            b.set_message(match done {
                "topology" => "positions",
                _ => "writing",
            });
        }
    }

    fn finish(&self) {
        if let Some(b) = &self.0 {
            b.finish_and_clear();
        }
    }
}
