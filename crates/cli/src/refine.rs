//! `subd refine`: uniform refinement of a mesh file with any surface scheme (one
//! `subd_schemes::Refinement`): Catmull-Clark, Loop or Bilinear (OpenSubdiv's schemes), seed
//! 000's two-phase scheme, or Doo-Sabin, √3 and the butterflies.

use std::io::{IsTerminal, Write};
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use subd_mesh::{BoundaryInterpolation, CreaseMethod, SchemeHints, TriangleSubdivision};
use subd_schemes::peak::{DepthFirstPeak, PeakModel};
use subd_schemes::{Capability, Scheme};

use crate::batch::{self, Files, Job};
use crate::budget::Budget;
use crate::failure::bad;
use crate::refined::{RefinementWithLimit, all_unit, last_level_limit, normals_or_faces};
use crate::rule_args::RuleArgs;
use crate::scheme_arg;
use crate::vertex_data::LambdaArgs;
use crate::{Failure, print_warnings};

#[derive(Debug, Clone, Args)]
pub(crate) struct RefineArgs {
    /// Subdivision scheme (a parameter may follow a colon: butterfly:0.05, two-phase:0.6;
    /// default: the scheme the input names, USD's subdivisionScheme).
    #[arg(long, value_parser = scheme_arg::parser(Capability::Refine))]
    scheme: Option<Scheme>,
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
    /// Refine depth-first: chunks of base faces taken to the last level one at a time and
    /// written in place (OBJ: into a scratch file beside it, then encoded in order), so
    /// that the memory does not grow with the level (Catmull-Clark, Loop or Bilinear to PLY
    /// or OBJ, without texture coordinates, holes or creases sharp past the last level).
    /// Chosen by itself when the level at a time would not fit the memory budget.
    #[arg(long)]
    depth_first: bool,
    /// Print a JSON report (counts, timings) on stdout.
    #[arg(long)]
    json: bool,
}

/// How the output level is made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Plan {
    /// Level by level, the last one streamed to the file where it can be.
    LevelAtATime,
    /// Depth-first, in chunks of about this many last-level faces.
    DepthFirst(u64),
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
    /// Whether the level was made depth-first (chunks of base faces, no level held whole).
    depth_first: bool,
    /// The process's peak resident memory so far, in bytes (Linux's `VmHWM`; absent
    /// elsewhere).
    #[serde(skip_serializing_if = "Option::is_none")]
    peak_memory: Option<u64>,
    input_counts: Counts,
    output_counts: Counts,
    seconds: Timings,
    warnings: Vec<String>,
}

impl RefineReport {
    /// The report of refining `job` with `scheme` and `options` (OpenSubdiv's rule options
    /// for its schemes only), the counts and times given; the peak memory read now.
    #[allow(clippy::too_many_arguments)]
    fn new(
        args: &RefineArgs,
        job: &Job,
        scheme: &Scheme,
        options: &subd_schemes::Options,
        depth_first: bool,
        (input_counts, output_counts): (Counts, Counts),
        seconds: Timings,
        warnings: Vec<String>,
    ) -> RefineReport {
        let osd = scheme.is_opensubdiv();
        RefineReport {
            input: job.input.display().to_string(),
            output: job.output.display().to_string(),
            scheme: scheme.name(),
            levels: args.levels,
            tension: scheme.tension(),
            boundary_interpolation: osd.then_some(options.boundary_interpolation),
            crease_method: osd.then_some(options.crease_method),
            triangle_subdivision: osd.then_some(options.triangle_subdivision),
            limit: args.limit,
            depth_first,
            peak_memory: crate::budget::peak_resident_bytes(),
            input_counts,
            output_counts,
            seconds,
            warnings,
        }
    }
}

/// `subd refine` writes meshes.
const REFINE: batch::Command = batch::Command {
    name: "refine",
    formats: batch::MESH_OUTPUTS,
};

pub(crate) fn run(
    args: &RefineArgs,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    REFINE.run(&args.files, args.json, out, err, |job, out, err| {
        let mut warnings = Vec::new();
        let scheme = args.scheme.as_ref();
        let levels = crate::cage::levels_for_refine(
            args.levels,
            args.limit,
            scheme,
            &job.output,
            &mut warnings,
        );
        print_warnings(err, &job.input, &warnings);
        if levels == args.levels {
            return run_one(args, job, out, err);
        }
        let refined = RefineArgs {
            levels,
            ..args.clone()
        };
        run_one(&refined, job, out, err)
    })
}

/// One file: open it, refine, carry the texture coordinates, write the last level (streamed
/// where it can be), report.
fn run_one(
    args: &RefineArgs,
    job: &Job,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    let (mut opened, scheme, plan) = open(args, job, err)?;
    let options = args.rules.options(&opened.file.mesh.hints);
    if let Plan::DepthFirst(faces_per_chunk) = plan {
        return run_depth_first(
            args,
            job,
            opened,
            &scheme,
            &options,
            faces_per_chunk,
            out,
            err,
        );
    }
    let progress = Progress::new(args.levels, args.json || job.quiet);
    let t0 = Instant::now();
    let base = &opened.file.mesh.topology;
    let refinement = RefinementWithLimit::new(base, scheme, &options, args.levels)
        .map_err(|e| in_file(job, &e))?;
    let input_counts = Counts {
        vertices: base.num_vertices(),
        edges: Some(base.num_edges()),
        faces: base.num_faces(),
    };
    let fvar_mode = args.rules.fvar_mode(&opened.file.mesh.hints);
    let uv = output_uv(args, job, &refinement, &mut opened.file, fvar_mode)?;
    opened.print_new_warnings(&job.input, err);
    // The refinement holds its own copy of the base level: the file's is not needed again.
    if let Ok(empty) = subd_mesh::TopologyBuilder::new(0).build(&[], &[]) {
        opened.file.mesh.topology = empty;
    }
    progress.step("topology");
    let t_topology = t0.elapsed().as_secs_f64();
    let osd = refinement.scheme().is_opensubdiv();
    let mut hints = subd_limit::refined_mesh::refined_hints(
        refinement.scheme(),
        &options,
        &opened.file.mesh.hints,
        args.rules.triangles.is_some(),
    );
    hints.fvar_interpolation = uv.as_ref().map(|_| fvar_mode);
    if args.levels == 0 && !args.limit {
        // Level 0 is the cage itself, which a USD renderer subdivides (the scheme is one
        // USD names: `run` refines the others' cages).
        hints.scheme = refinement.scheme().file_scheme();
    }
    let output = Output {
        write_options: opened.file.output_options(),
        args,
        job,
        refinement: &refinement,
        base: &opened.file.mesh.positions,
        uv: uv.as_ref(),
        hints,
        progress: &progress,
    };
    let written = if osd && !args.limit && args.levels > 0 {
        output.streamed()?
    } else {
        output.held(&options)?
    };
    progress.finish();
    if args.json {
        let report = RefineReport::new(
            args,
            job,
            refinement.scheme(),
            &options,
            false,
            (input_counts, written.counts),
            Timings {
                read: opened.read_seconds,
                topology: t_topology,
                positions: written.positions_seconds,
                write: written.write_seconds,
                total: opened.elapsed(),
            },
            opened.file.warnings.clone(),
        );
        crate::print_json(out, &report);
    }
    Ok(())
}

/// One file depth-first ([`crate::depth_first`]): no level is built whole, so the report's
/// `positions` time covers refining and writing together.
#[allow(clippy::too_many_arguments)]
fn run_depth_first(
    args: &RefineArgs,
    job: &Job,
    mut opened: crate::opening::Opened,
    scheme: &Scheme,
    options: &subd_schemes::Options,
    faces_per_chunk: u64,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    opened.print_new_warnings(&job.input, err);
    let t0 = Instant::now();
    let mesh = &opened.file.mesh;
    let hints = subd_limit::refined_mesh::refined_hints(
        scheme,
        options,
        &mesh.hints,
        args.rules.triangles.is_some(),
    );
    let request = crate::depth_first::Request {
        base: &mesh.topology,
        positions: &mesh.positions,
        scheme,
        options,
        levels: args.levels,
        faces_per_chunk,
        hints,
        input: &job.input,
        output: &job.output,
        write_options: opened.file.output_options(),
    };
    let counts = crate::depth_first::write(&request)?;
    if args.json {
        let input_counts = Counts {
            vertices: mesh.topology.num_vertices(),
            edges: Some(mesh.topology.num_edges()),
            faces: mesh.topology.num_faces(),
        };
        let output_counts = Counts {
            vertices: counts.vertices as usize,
            edges: Some(counts.edges as usize),
            faces: counts.faces as usize,
        };
        // Refining and writing go together, chunk by chunk: one time for both.
        let seconds = Timings {
            read: opened.read_seconds,
            topology: 0.0,
            positions: t0.elapsed().as_secs_f64(),
            write: 0.0,
            total: opened.elapsed(),
        };
        let warnings = opened.file.warnings.clone();
        let report = RefineReport::new(
            args,
            job,
            scheme,
            options,
            true,
            (input_counts, output_counts),
            seconds,
            warnings,
        );
        crate::print_json(out, &report);
    }
    Ok(())
}

/// `e` as a message naming the input.
fn in_file(job: &Job, e: &dyn std::fmt::Display) -> Failure {
    bad(format!("{}: {e}", job.input.display()))
}

/// The checks before and after reading: the output, the butterfly's tension, the input
/// itself, the two-phase scheme's `λ` and the memory budget. The file and the complete
/// scheme.
fn open(
    args: &RefineArgs,
    job: &Job,
    err: &mut dyn Write,
) -> Result<(crate::opening::Opened, Scheme, Plan), Failure> {
    let started = REFINE.start_job(job)?;
    let opened = started.read(&args.rules, err)?;
    let hints = &opened.file.mesh.hints;
    let scheme =
        scheme_arg::given_or_named(args.scheme.as_ref(), hints, Capability::Refine, &job.input)?;
    let scheme = scheme_arg::with_tension(&scheme, args.tension, "--scheme")?;
    let vertices = opened.file.mesh.topology.num_vertices();
    let scheme = scheme_arg::with_lambda(&scheme, &args.lambda, &job.input, vertices)?;
    let plan = plan_memory(args, job, &opened.file, &scheme)?;
    Ok((opened, scheme, plan))
}

/// The texture coordinates of the output level, if the input has them. PLY holds one per
/// vertex: a seamed layout is left out with a warning (a refined level gives a seamless
/// layout exactly one value per vertex).
fn output_uv(
    args: &RefineArgs,
    job: &Job,
    refinement: &RefinementWithLimit,
    file: &mut subd_io::MeshFile,
    fvar_mode: subd_mesh::fvar::FVarLinearInterpolation,
) -> Result<Option<crate::uv::RefinedUv>, Failure> {
    let uv = crate::uv::refined_uv(
        refinement,
        &file.mesh,
        fvar_mode,
        args.limit,
        &mut file.warnings,
    )
    .map_err(|e| in_file(job, &e))?;
    let Some(u) = uv else { return Ok(None) };
    if subd_io::Format::for_output(&job.output) != Some(subd_io::Format::Ply) {
        return Ok(Some(u));
    }
    let seamed = if args.levels == 0 {
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
    };
    if seamed {
        file.warnings.push(crate::uv::ply_seam_warning(&job.output));
        return Ok(None);
    }
    Ok(Some(u))
}

/// What writing the output level needs.
struct Output<'a> {
    args: &'a RefineArgs,
    job: &'a Job,
    refinement: &'a RefinementWithLimit,
    /// The base positions.
    base: &'a [subd_mesh::DVec3],
    uv: Option<&'a crate::uv::RefinedUv>,
    hints: SchemeHints,
    /// What the output keeps of the input (a USD prim's name and units).
    write_options: subd_io::WriteOptions,
    progress: &'a Progress,
}

/// The output level's counts and the seconds its positions and its writing took.
struct Written {
    counts: Counts,
    positions_seconds: f64,
    write_seconds: f64,
}

impl Output<'_> {
    fn in_view(&self, e: subd_io::ViewError) -> Failure {
        in_file(self.job, &e)
    }

    /// The last level straight to the file, a window at a time, from the level above
    /// (OpenSubdiv's schemes without `--limit`).
    fn streamed(&self) -> Result<Written, Failure> {
        let (r, levels) = (self.refinement, self.args.levels);
        let t1 = Instant::now();
        let above = r.points_at(self.base, levels - 1);
        let points = crate::level_stream::Points(r.point_stream(&above).expect("levels > 0"));
        let faces = crate::level_stream::Faces(r.face_stream().expect("levels > 0"));
        // `.glb` normals need every position at hand.
        let glb = subd_io::Format::for_output(&self.job.output) == Some(subd_io::Format::Glb);
        let held = glb.then(|| points.all());
        self.progress.step("positions");
        let positions_seconds = t1.elapsed().as_secs_f64();
        let t2 = Instant::now();
        let source = match &held {
            Some(p) => subd_io::Points::Held(p),
            None => subd_io::Points::Streamed(&points),
        };
        let tags = r.explicit_tags(levels);
        let view = subd_io::MeshView::streamed(source, &faces, faces.0.hole_faces())
            .and_then(|v| v.with_tags(tags.creases, tags.corners))
            .and_then(|v| crate::uv::with_uv(v, self.uv))
            .map_err(|e| self.in_view(e))?;
        let counts = self.write_level(view, r.edges(levels))?;
        Ok(Written {
            counts,
            positions_seconds,
            write_seconds: t2.elapsed().as_secs_f64(),
        })
    }

    /// The last level's positions computed in full (moved to the limit with `--limit`),
    /// then written. Polygons, holes and the tags a reader cannot infer are all the file
    /// holds: they are written without building the output level's edges (most of the time
    /// and memory of a deep refinement's output).
    fn held(&self, options: &subd_schemes::Options) -> Result<Written, Failure> {
        let (r, levels) = (self.refinement, self.args.levels);
        let t1 = Instant::now();
        let (positions, normals) = if self.args.limit {
            let limit =
                last_level_limit(r, options, self.base).map_err(|e| in_file(self.job, &e))?;
            (limit.positions, Some(limit.normals))
        } else {
            (r.last_positions(self.base), None)
        };
        self.progress.step("positions");
        let positions_seconds = t1.elapsed().as_secs_f64();
        let t2 = Instant::now();
        if let Some(n) = normals.as_deref().filter(|n| all_unit(n)) {
            if let Some(counts) = self.with_streamed_faces(&positions, n)? {
                return Ok(Written {
                    counts,
                    positions_seconds,
                    write_seconds: t2.elapsed().as_secs_f64(),
                });
            }
        }
        let (offsets, vertices) = r.faces(levels);
        let tags = r.explicit_tags(levels);
        let holes = r.holes(levels);
        let mut view = subd_io::MeshView::new(&positions, offsets, vertices, &holes)
            .and_then(|v| v.with_tags(tags.creases, tags.corners))
            .and_then(|v| crate::uv::with_uv(v, self.uv))
            .map_err(|e| self.in_view(e))?;
        let filled;
        if let Some(n) = &normals {
            filled = normals_or_faces(n, &view);
            let n = filled.as_deref().unwrap_or(n);
            view = view.with_normals(n).map_err(|e| self.in_view(e))?;
        }
        let counts = self.write_level(view, r.edges(levels))?;
        Ok(Written {
            counts,
            positions_seconds,
            write_seconds: t2.elapsed().as_secs_f64(),
        })
    }
}

impl Output<'_> {
    /// Held positions and normals with the faces streamed as [`Self::streamed`] streams
    /// them (OpenSubdiv's schemes, `--limit`): the faces of a deep level, its largest array,
    /// are never held. `None` where the faces cannot be streamed (level 0, a split scheme).
    fn with_streamed_faces(
        &self,
        positions: &[subd_mesh::DVec3],
        normals: &[subd_mesh::DVec3],
    ) -> Result<Option<Counts>, Failure> {
        let (r, levels) = (self.refinement, self.args.levels);
        let last = levels > 0 && levels == r.num_levels();
        let Some(stream) = r.face_stream().filter(|_| last) else {
            return Ok(None);
        };
        let faces = crate::level_stream::Faces(stream);
        let tags = r.explicit_tags(levels);
        let view = subd_io::MeshView::streamed(
            subd_io::Points::Held(positions),
            &faces,
            faces.0.hole_faces(),
        )
        .and_then(|v| v.with_tags(tags.creases, tags.corners))
        .and_then(|v| crate::uv::with_uv(v, self.uv))
        .and_then(|v| v.with_normals(normals))
        .map_err(|e| self.in_view(e))?;
        self.write_level(view, r.edges(levels)).map(Some)
    }
}

impl Output<'_> {
    /// Writes the output level with its hints; its counts for the report.
    fn write_level(
        &self,
        mut view: subd_io::MeshView<'_>,
        edges: Option<usize>,
    ) -> Result<Counts, Failure> {
        view.hints = self.hints;
        subd_io::write_view(&self.job.output, &view, &self.write_options)?;
        Ok(Counts {
            vertices: view.num_vertices(),
            edges,
            faces: view.num_faces(),
        })
    }
}

/// How the output is made, within the memory budget (see [`crate::budget`]): depth-first
/// when asked or when the level at a time would not fit and the output allows it; the
/// request refused if its estimated peak is over the budget either way.
fn plan_memory(
    args: &RefineArgs,
    job: &Job,
    file: &subd_io::MeshFile,
    scheme: &Scheme,
) -> Result<Plan, Failure> {
    let base = &file.mesh.topology;
    let counts = subd_schemes::refined_counts(base, scheme, args.levels);
    let model = PeakModel::of(scheme);
    let file_bytes = std::fs::metadata(&job.input).map_or(0, |m| m.len());
    let glb = subd_io::Format::for_output(&job.output) == Some(subd_io::Format::Glb);
    let budget = Budget::detect(args.max_memory).map(|b| b.share(job.concurrent));
    let level_at_a_time = |last| model.peak(file_bytes, last, glb, args.limit);
    let fits = budget.is_none_or(|b| level_at_a_time(counts[args.levels]) <= b.bytes);
    let last = counts[args.levels];
    if glb {
        crate::depth_first::check_glb_fits(&job.input, args.levels, last)?;
    }
    let why_not =
        crate::depth_first::unsupported(scheme, args.levels, args.limit, &job.output, file);
    // Only where the records go straight into the file (binary PLY): through a scratch
    // file (OBJ) depth-first is the slower of the two, taken when the level does not fit.
    let in_place = subd_io::Format::for_output(&job.output) == Some(subd_io::Format::Ply);
    let large = in_place && last.faces >= crate::depth_first::BY_ITSELF_FROM_FACES;
    match why_not {
        Some(why) if args.depth_first => Err(bad(format!(
            "{}: --depth-first cannot make this output: {why}",
            job.input.display()
        ))),
        None if args.depth_first || !fits || large => {
            let threads = rayon::current_num_threads();
            let bytes = budget.map_or(u64::MAX, |b| b.bytes);
            let peak = DepthFirstPeak::fitting(bytes, file_bytes, threads);
            match budget.filter(|b| peak.bytes > b.bytes) {
                Some(b) => Err(bad(format!(
                    "{}: refining {} levels depth-first needs about {}, over the budget of {} ({})",
                    job.input.display(),
                    args.levels,
                    subd_mesh::memory::human_bytes(peak.bytes),
                    subd_mesh::memory::human_bytes(b.bytes),
                    b.source,
                ))),
                None => Ok(Plan::DepthFirst(peak.faces_per_chunk)),
            }
        }
        _ => {
            crate::budget::check_refinement(&job.input, &counts, level_at_a_time, budget)?;
            Ok(Plan::LevelAtATime)
        }
    }
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
