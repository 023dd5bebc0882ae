//! The `subd` command-line tool as a library: [`run`] parses arguments and executes a
//! command, writing to the given output streams and returning the process exit code.
//!
//! Exit codes: 0 success; 2 bad input (unreadable file, unknown extension, parse error,
//! invalid topology, bad arguments) with one line on stderr naming the file and, for parse
//! errors, the line; 1 for other failures (e.g. an output file that cannot be written).
//!
//! ```
//! let mut out = Vec::new();
//! let mut err = Vec::new();
//! let code = subd_cli::run(["subd", "info", "no-such-file.obj"], &mut out, &mut err);
//! assert_eq!(code, 2);
//! assert!(String::from_utf8(err).unwrap().starts_with("subd: no-such-file.obj: cannot read"));
//! ```

mod adaptive;
mod analyze;
mod batch;
mod budget;
mod cage;
mod choice_arg;
mod curve;
mod depth_first;
mod edit;
mod eval;
mod failure;
mod info;
mod level_stream;
mod limit;
mod opening;
mod patches;
mod pia;
mod progress;
mod raster;
mod refine;
mod refined;
mod render;
mod rule_args;
mod scheme_arg;
mod tessellate;
mod uv;
mod vertex_data;

use std::ffi::OsString;
use std::io::Write;

use clap::{Parser, Subcommand};

pub use failure::Failure;

/// Exit code for success.
pub const EXIT_OK: i32 = 0;
/// Exit code for other failures (writing output, internal).
pub const EXIT_FAILURE: i32 = 1;
/// Exit code for bad input.
pub const EXIT_BAD_INPUT: i32 = 2;

/// Warnings printed per input before the rest are summarised.
const MAX_WARNINGS: usize = 10;

#[derive(Debug, Parser)]
#[command(name = "subd", version, about = "Subdivision curves and surfaces", long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Topology summary: counts, face-size and valence histograms, boundary, non-manifold
    /// elements, tags, components, Euler characteristic and genus.
    Info(info::InfoArgs),
    /// Uniform refinement with any surface scheme: Catmull-Clark, Loop and Bilinear (agreeing
    /// with OpenSubdiv), two-phase, Doo-Sabin, √3, Butterfly and Modified Butterfly.
    Refine(refine::RefineArgs),
    /// Limit position (and normal) of every vertex with any scheme but Bilinear, exact:
    /// semi-sharp creases are refined until they decay, darts, valence-2 vertices and the
    /// split schemes use the eigen analysis.
    Limit(limit::LimitArgs),
    /// The exact Catmull-Clark or Loop limit surface (position and unit normal) at given
    /// (face, u, v) parameters, in OpenSubdiv's parameterisation.
    Eval(eval::EvalArgs),
    /// The feature-adaptive patch table of a Catmull-Clark or Loop mesh (OpenSubdiv's
    /// RefineAdaptive + PatchTableFactory, same patches): its census, and its flat arrays
    /// (control points, patch parameters, local-point stencils) as JSON.
    Patches(patches::PatchesArgs),
    /// The Catmull-Clark or Loop limit surface on a uniform grid of N segments per base edge,
    /// positions and normals, watertight (OpenSubdiv Bfr's uniform tessellation).
    Tessellate(tessellate::TessellateArgs),
    /// Adaptive Loop or Catmull-Clark refinement: only where criteria select (flatness,
    /// distance to the limit, curvature, dihedral angle, chosen faces or vertices), closed
    /// into a crack-free mesh whose every vertex is uniform refinement's (or the limit's).
    Adaptive(adaptive::AdaptiveArgs),
    /// Progressive iterative interpolation (Catmull-Clark, Loop, two-phase): a control mesh
    /// with IN's topology whose limit surface passes through IN's vertices (all, or those
    /// chosen with --moving/--fixed).
    Pia(pia::PiaArgs),
    /// Constraint-based editing of the Catmull-Clark or Loop limit surface (points, normals,
    /// iso-lines): the control vertices that meet the constraints with the least change or
    /// the least thin-plate energy.
    Edit(edit::EditArgs),
    /// Simple constrained deformation: points move by radial blends around constraint
    /// points, each constraint point exactly by its displacement (any mesh level).
    Deform(edit::DeformArgs),
    /// A shaded picture (PNG) of a mesh, its refinement or its limit surface, with the
    /// control cage, the wireframe and marked points drawn over it; headless, CPU only.
    Render(render::RenderArgs),
    /// Subdivision curves (linear and circle-average schemes) from a text point list, to
    /// text or SVG.
    Curve(curve::CurveArgs),
    /// Convergence and smoothness of a univariate mask (Laurent polynomials), or the
    /// eigenvalue test of a surface scheme at a valence.
    Analyze(analyze::AnalyzeArgs),
}

/// Prints `report` as one line of JSON on `out` (a closed pipe is not an error worth
/// reporting after the work is done).
pub(crate) fn print_json(out: &mut dyn Write, report: &impl serde::Serialize) {
    let _ = serde_json::to_writer(&mut *out, report);
    let _ = writeln!(out);
}

/// Prints reader warnings for `path` on `err`, at most [`MAX_WARNINGS`] of them.
pub(crate) fn print_warnings(err: &mut dyn Write, path: &std::path::Path, warnings: &[String]) {
    for w in warnings.iter().take(MAX_WARNINGS) {
        let _ = writeln!(err, "subd: warning: {}: {w}", path.display());
    }
    if warnings.len() > MAX_WARNINGS {
        let _ = writeln!(
            err,
            "subd: warning: {}: {} more warnings not shown",
            path.display(),
            warnings.len() - MAX_WARNINGS
        );
    }
}

/// Runs one input's work with its stderr held back: written out once the work is done, or
/// dropped when the input is refused (exit 2), so that the refusal is its one line rather
/// than the last of the warnings about the same problem gathered while reading it.
pub(crate) fn refusal_alone(
    err: &mut dyn Write,
    work: impl FnOnce(&mut dyn Write) -> Result<(), Failure>,
) -> Result<(), Failure> {
    let mut held = Vec::new();
    let result = work(&mut held);
    if !matches!(&result, Err(f) if f.code == EXIT_BAD_INPUT) {
        let _ = err.write_all(&held);
    }
    result
}

/// Runs `subd` with `args` (the first item is the program name). Returns the exit code.
pub fn run<I, T>(args: I, out: &mut dyn Write, err: &mut dyn Write) -> i32
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(c) => c,
        Err(e) => {
            let code = if e.use_stderr() {
                EXIT_BAD_INPUT
            } else {
                EXIT_OK
            };
            let text = e.render().to_string();
            if e.use_stderr() {
                let _ = write!(err, "{text}");
            } else {
                let _ = write!(out, "{text}");
            }
            return code;
        }
    };
    // The commands that take several inputs hold each one's stderr in `batch::run`.
    let result = match cli.command {
        Command::Info(a) => refusal_alone(err, |err| info::run(&a, out, err)),
        Command::Refine(a) => refine::run(&a, out, err),
        Command::Limit(a) => limit::run(&a, out, err),
        Command::Eval(a) => refusal_alone(err, |err| eval::run(&a, out, err)),
        Command::Tessellate(a) => refusal_alone(err, |err| tessellate::run(&a, out, err)),
        Command::Patches(a) => refusal_alone(err, |err| patches::run(&a, out, err)),
        Command::Pia(a) => pia::run(&a, out, err),
        Command::Adaptive(a) => adaptive::run(&a, out, err),
        Command::Edit(a) => edit::run(&a, out, err),
        Command::Deform(a) => edit::run_deform(&a, out, err),
        Command::Render(a) => refusal_alone(err, |err| render::run(&a, out, err)),
        Command::Curve(a) => refusal_alone(err, |err| curve::run(&a, out, err)),
        Command::Analyze(a) => analyze::run(&a, out),
    };
    match result {
        Ok(()) => EXIT_OK,
        Err(f) => {
            let _ = writeln!(err, "subd: {}", f.message);
            f.code
        }
    }
}

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
