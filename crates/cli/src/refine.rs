//! `subd refine`: uniform Catmull-Clark, Loop or Bilinear refinement of a mesh file.

use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::time::Instant;

use clap::{Args, ValueEnum};
use serde::Serialize;
use subd_mesh::{BoundaryInterpolation, CreaseMethod, SchemeHints, TriangleSubdivision};
use subd_schemes::{Refinement, Scheme};

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
}

impl SchemeArg {
    /// The refinement scheme (two-phase refines with Catmull-Clark's topology and rules
    /// after its first step).
    pub(crate) fn scheme(self) -> Scheme {
        match self {
            SchemeArg::CatmullClark | SchemeArg::TwoPhase => Scheme::CatmullClark,
            SchemeArg::Loop => Scheme::Loop,
            SchemeArg::Bilinear => Scheme::Bilinear,
        }
    }

    /// The name the command line uses.
    pub(crate) fn name(self) -> &'static str {
        match self {
            SchemeArg::CatmullClark => "catmull-clark",
            SchemeArg::Loop => "loop",
            SchemeArg::Bilinear => "bilinear",
            SchemeArg::TwoPhase => "two-phase",
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
    #[command(flatten)]
    lambda: LambdaArgs,
    #[command(flatten)]
    rules: RuleArgs,
    /// Input mesh (.obj or .ply).
    input: PathBuf,
    /// Output mesh (.obj with tags, .ply or .glb).
    output: PathBuf,
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
    boundary_interpolation: BoundaryInterpolation,
    crease_method: CreaseMethod,
    triangle_subdivision: TriangleSubdivision,
    input_counts: Counts,
    output_counts: Counts,
    seconds: Timings,
    warnings: Vec<String>,
}

pub(crate) fn run(
    args: &RefineArgs,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    let t_start = Instant::now();
    refuse_overwrite(&args.input, &args.output)?;
    if subd_io::Format::from_path(&args.output).is_none() {
        return Err(bad(format!(
            "{}: unsupported output extension (expected .obj, .ply or .glb)",
            args.output.display()
        )));
    }
    let file = subd_io::read_mesh(&args.input, &args.rules.read_options())?;
    print_warnings(err, &args.input, &file.warnings);
    let t_read = t_start.elapsed().as_secs_f64();
    let scheme = args.scheme.scheme();
    let options = args.rules.options(&file.mesh.hints);
    let base = &file.mesh.topology;
    let two_phase = match args.scheme {
        SchemeArg::TwoPhase => Some(args.lambda.two_phase(&args.input, base.num_vertices())?),
        _ if args.lambda.given() => {
            return Err(bad(
                "--lambda and --lambda-file apply to --scheme two-phase only".into(),
            ));
        }
        _ => None,
    };

    let progress = Progress::new(args.levels, args.json);
    let t0 = Instant::now();
    let refinement = match &two_phase {
        Some(tp) => Refinement::two_phase(base, tp, &options, args.levels),
        None => Refinement::new(base, scheme, &options, args.levels),
    }
    .map_err(|e| bad(format!("{}: {e}", args.input.display())))?;
    progress.step("topology");
    let t_topology = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let mut levels = refinement.refine_points(&file.mesh.positions);
    let positions = levels.pop().expect("last level");
    drop(levels);
    progress.step("positions");
    let t_positions = t1.elapsed().as_secs_f64();

    let t2 = Instant::now();
    let hints = SchemeHints {
        boundary_interpolation: Some(options.boundary_interpolation),
        crease_method: Some(options.crease_method),
        triangle_subdivision: file
            .mesh
            .hints
            .triangle_subdivision
            .or(args.rules.triangles.map(|_| options.triangle_subdivision)),
    };
    // Polygons, holes and the tags a reader cannot infer are all the file holds: they are
    // written without building the output level's edges (most of the time and memory of a
    // deep refinement's output).
    let (offsets, vertices) = refinement.faces(args.levels);
    let tags = refinement.explicit_tags(args.levels);
    let mut view =
        subd_io::MeshView::new(&positions, offsets, vertices, refinement.holes(args.levels))
            .and_then(|v| v.with_tags(tags.creases, tags.corners))
            .map_err(|e| bad(format!("{}: {e}", args.input.display())))?;
    view.hints = hints;
    subd_io::write_view(&args.output, &view, &subd_io::WriteOptions::default())?;
    let out_counts = Counts {
        vertices: positions.len(),
        edges: Some(refinement.num_edges(args.levels)),
        faces: view.num_faces(),
    };
    progress.finish();
    let t_write = t2.elapsed().as_secs_f64();

    if args.json {
        let report = RefineReport {
            input: args.input.display().to_string(),
            output: args.output.display().to_string(),
            scheme: args.scheme.name(),
            levels: args.levels,
            boundary_interpolation: options.boundary_interpolation,
            crease_method: options.crease_method,
            triangle_subdivision: options.triangle_subdivision,
            input_counts: Counts {
                vertices: base.num_vertices(),
                edges: Some(base.num_edges()),
                faces: base.num_faces(),
            },
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
