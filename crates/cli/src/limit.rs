//! `subd limit`: the limit position (and normal) of every vertex of a mesh.

use std::fmt::Write as _;
use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use clap::{Args, ValueEnum};
use serde::Serialize;
use subd_limit::{LimitPoints, base_limit, levels_for_exact_limit, two_phase_base_limit};
use subd_mesh::Mesh;
use subd_schemes::Scheme;

use crate::failure::{bad, refuse_overwrite};
use crate::rule_args::RuleArgs;
use crate::vertex_data::LambdaArgs;
use crate::{Failure, print_warnings};

/// The schemes with a limit surface other than the mesh itself.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub(crate) enum LimitSchemeArg {
    CatmullClark,
    Loop,
}

impl LimitSchemeArg {
    pub(crate) fn scheme(self) -> Scheme {
        match self {
            LimitSchemeArg::CatmullClark => Scheme::CatmullClark,
            LimitSchemeArg::Loop => Scheme::Loop,
        }
    }
}

/// Schemes of `subd limit`: those with limit masks, and the two-phase scheme.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub(crate) enum LimitCommandScheme {
    CatmullClark,
    Loop,
    /// Seed 000's two-phase scheme: formula (2) on closed quad meshes (needs --lambda or
    /// --lambda-file).
    TwoPhase,
}

#[derive(Debug, Args)]
pub(crate) struct LimitArgs {
    /// Subdivision scheme.
    #[arg(long, value_enum)]
    scheme: LimitCommandScheme,
    #[command(flatten)]
    lambda: LambdaArgs,
    #[command(flatten)]
    rules: RuleArgs,
    /// Also write unit normals (`.txt` output: `x y z nx ny nz` per line).
    #[arg(long)]
    normals: bool,
    /// Input mesh (.obj or .ply).
    input: PathBuf,
    /// Output: `.txt` (one line per vertex) or a mesh (.obj, .ply, .glb) whose vertices are
    /// moved to their limit positions.
    output: PathBuf,
    /// Also write the ACC approximation (Loop & Schaefer 2008: a bicubic Bézier geometry
    /// patch and two tangent patches per face) to this JSON file (Catmull-Clark, closed
    /// all-quad meshes).
    #[arg(long, value_name = "FILE.json")]
    acc: Option<PathBuf>,
    /// Print a JSON report on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct LimitReport {
    input: String,
    output: String,
    scheme: &'static str,
    vertices: usize,
    /// Uniform levels refined first (semi-sharp decay, Catmull-Clark non-quads).
    levels_refined: usize,
    seconds: f64,
    warnings: Vec<String>,
}

/// `x y z` (and `nx ny nz`) per vertex, full precision.
fn text(limit: &LimitPoints, normals: bool) -> String {
    let mut s = String::with_capacity(limit.positions.len() * if normals { 120 } else { 60 });
    for (p, n) in limit.positions.iter().zip(&limit.normals) {
        let _ = write!(s, "{} {} {}", p.x, p.y, p.z);
        if normals {
            let _ = write!(s, " {} {} {}", n.x, n.y, n.z);
        }
        s.push('\n');
    }
    s
}

pub(crate) fn run(
    args: &LimitArgs,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    let t0 = Instant::now();
    refuse_overwrite(&args.input, &args.output)?;
    let is_text = args
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("txt"));
    if !is_text && subd_io::Format::from_path(&args.output).is_none() {
        return Err(bad(format!(
            "{}: unsupported output extension (expected .txt, .obj, .ply or .glb)",
            args.output.display()
        )));
    }
    let file = subd_io::read_mesh(&args.input, &args.rules.read_options())?;
    print_warnings(err, &args.input, &file.warnings);
    let options = args.rules.options(&file.mesh.hints);
    let topo = &file.mesh.topology;
    let (scheme, name) = match args.scheme {
        LimitCommandScheme::CatmullClark => (Scheme::CatmullClark, "catmull-clark"),
        LimitCommandScheme::Loop => (Scheme::Loop, "loop"),
        LimitCommandScheme::TwoPhase => (Scheme::CatmullClark, "two-phase"),
    };
    let table = match args.scheme {
        LimitCommandScheme::TwoPhase => {
            let tp = args.lambda.two_phase(&args.input, topo.num_vertices())?;
            two_phase_base_limit(topo, &tp, &options)
        }
        _ if args.lambda.given() => {
            return Err(bad(
                "--lambda and --lambda-file apply to --scheme two-phase only".into(),
            ));
        }
        _ => base_limit(topo, scheme, &options),
    }
    .map_err(|e| bad(format!("{}: {e}", args.input.display())))?;
    let limit = table.apply(&file.mesh.positions);
    // ACC first, so that a mesh it does not cover fails before any file is written.
    let acc = match &args.acc {
        Some(path) => {
            if !matches!(args.scheme, LimitCommandScheme::CatmullClark) {
                return Err(bad(format!(
                    "{}: ACC patches approximate catmull-clark surfaces only",
                    path.display()
                )));
            }
            let patches = subd_limit::acc::acc_patches(topo, &file.mesh.positions)
                .map_err(|e| bad(format!("{}: {e}", args.input.display())))?;
            let json = serde_json::to_vec(&patches)
                .map_err(|e| bad(format!("{}: {e}", path.display())))?;
            Some((path, json))
        }
        None => None,
    };
    if is_text {
        let body = text(&limit, args.normals);
        subd_io::atomic_write(&args.output, |w| w.write_all(body.as_bytes()))?;
    } else {
        let mut mesh = Mesh::new(topo.clone(), limit.positions.clone())
            .map_err(|e| bad(format!("{}: {e}", args.input.display())))?;
        mesh.hints = file.mesh.hints;
        subd_io::write_mesh(&args.output, &mesh, &subd_io::WriteOptions::default())?;
    }
    if let Some((path, json)) = acc {
        subd_io::atomic_write(path, |w| w.write_all(&json))?;
    }
    if args.json {
        let report = LimitReport {
            input: args.input.display().to_string(),
            output: args.output.display().to_string(),
            scheme: name,
            vertices: topo.num_vertices(),
            levels_refined: levels_for_exact_limit(topo, scheme)
                .0
                .max(usize::from(name == "two-phase")),
            seconds: t0.elapsed().as_secs_f64(),
            warnings: file.warnings.clone(),
        };
        crate::print_json(out, &report);
    }
    Ok(())
}
