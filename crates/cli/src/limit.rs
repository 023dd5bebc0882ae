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

use crate::batch::{self, Files, Job, OutputFormat};
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
    /// Doo-Sabin: each vertex at the centroid of its vertex face one level down.
    DooSabin,
    /// √3: Kobbelt's limit masks (cubic B-spline along boundaries and creases).
    Sqrt3,
    /// Butterfly (interpolating: the vertices themselves; normals from the eigenvectors).
    Butterfly,
    /// Modified butterfly (interpolating, as butterfly).
    ModifiedButterfly,
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
    /// Also write unit normals (`.txt` output: `x y z nx ny nz` per line; `nan nan nan` where
    /// a split scheme defines none: inside creases, at corners, where the classic butterfly
    /// is not C¹).
    #[arg(long)]
    normals: bool,
    /// Tension w of --scheme butterfly (default 1/16).
    #[arg(long, allow_hyphen_values = true)]
    tension: Option<f64>,
    #[command(flatten)]
    files: Files,
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
    let command = batch::Command {
        name: "limit",
        formats: &[
            OutputFormat::Txt,
            OutputFormat::Obj,
            OutputFormat::Ply,
            OutputFormat::Glb,
        ],
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
    args: &LimitArgs,
    job: &Job,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    let t0 = Instant::now();
    refuse_overwrite(&job.input, &job.output)?;
    let is_text = job
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("txt"));
    if !is_text && subd_io::Format::for_output(&job.output).is_none() {
        return Err(bad(format!(
            "{}: unsupported output extension (expected .txt, .obj, .ply or .glb)",
            job.output.display()
        )));
    }
    let file = subd_io::read_mesh(&job.input, &args.rules.read_options())?;
    print_warnings(err, &job.input, &file.warnings);
    let options = args.rules.options(&file.mesh.hints);
    let topo = &file.mesh.topology;
    let (scheme, name) = match args.scheme {
        LimitCommandScheme::CatmullClark => (Scheme::CatmullClark, "catmull-clark"),
        LimitCommandScheme::Loop => (Scheme::Loop, "loop"),
        LimitCommandScheme::TwoPhase => (Scheme::CatmullClark, "two-phase"),
        _ => (Scheme::CatmullClark, "split"),
    };
    if args.tension.is_some() && !matches!(args.scheme, LimitCommandScheme::Butterfly) {
        return Err(bad("--tension applies to --scheme butterfly only".into()));
    }
    let split = match args.scheme {
        LimitCommandScheme::DooSabin => Some(Scheme::DooSabin),
        LimitCommandScheme::Sqrt3 => Some(Scheme::Sqrt3),
        LimitCommandScheme::Butterfly => Some(Scheme::Butterfly {
            tension: crate::rule_args::butterfly_tension(args.tension)?,
        }),
        LimitCommandScheme::ModifiedButterfly => Some(Scheme::ModifiedButterfly),
        _ => None,
    };
    if let Some(scheme) = split {
        if args.lambda.given() {
            return Err(bad(
                "--lambda and --lambda-file apply to --scheme two-phase only".into(),
            ));
        }
        if args.acc.is_some() {
            return Err(bad(
                "--acc: ACC patches approximate catmull-clark surfaces only".into(),
            ));
        }
        let in_file = |e: String| bad(format!("{}: {e}", job.input.display()));
        // One set of stencils for the positions and the texture coordinates.
        let stencils = subd_limit::split_limit::checked_split_limit_stencils(topo, &scheme)
            .map_err(|e| in_file(e.to_string()))?;
        let limit = stencils
            .limit_points(&scheme, &file.mesh.positions)
            .map_err(|e| in_file(e.to_string()))?;
        // Texture coordinates at their limit too, where the scheme carries them.
        let mut uv_warnings = Vec::new();
        let kept = match file.mesh.uv() {
            Some(c) if !is_text => Some(
                crate::uv::split_limit_uv(
                    topo,
                    (&scheme, &stencils),
                    c,
                    args.rules.fvar_mode(&file.mesh.hints),
                    &mut uv_warnings,
                )
                .map_err(|e| bad(format!("{}: {e}", job.input.display())))?,
            ),
            _ => None,
        };
        print_warnings(err, &job.input, &uv_warnings);
        write_limit(args, job, &limit, &file.mesh, kept.as_ref(), is_text, err)?;
        if args.json {
            let report = LimitReport {
                input: job.input.display().to_string(),
                output: job.output.display().to_string(),
                scheme: scheme.name(),
                vertices: topo.num_vertices(),
                levels_refined: 0,
                seconds: t0.elapsed().as_secs_f64(),
                warnings: file.warnings.clone(),
            };
            crate::print_json(out, &report);
        }
        return Ok(());
    }
    let table = match args.scheme {
        LimitCommandScheme::TwoPhase => {
            let tp = args.lambda.two_phase(&job.input, topo.num_vertices())?;
            two_phase_base_limit(topo, &tp, &options)
        }
        _ if args.lambda.given() => {
            return Err(bad(
                "--lambda and --lambda-file apply to --scheme two-phase only".into(),
            ));
        }
        _ => base_limit(topo, &scheme, &options),
    }
    .map_err(|e| bad(format!("{}: {e}", job.input.display())))?;
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
                .map_err(|e| bad(format!("{}: {e}", job.input.display())))?;
            let json = serde_json::to_vec(&patches)
                .map_err(|e| bad(format!("{}: {e}", path.display())))?;
            Some((path, json))
        }
        None => None,
    };
    // Texture coordinates at their limit too (two-phase: Catmull-Clark's face-varying rules,
    // which its second phase on is).
    let uv = match file.mesh.uv() {
        Some(c) if !is_text => Some(
            crate::uv::limit_uv(
                topo,
                &scheme,
                &options,
                c,
                args.rules.fvar_mode(&file.mesh.hints),
            )
            .map_err(|e| bad(format!("{}: {e}", job.input.display())))?,
        ),
        _ => None,
    };
    write_limit(args, job, &limit, &file.mesh, uv.as_ref(), is_text, err)?;
    if let Some((path, json)) = acc {
        subd_io::atomic_write(path, |w| w.write_all(&json))?;
    }
    if args.json {
        let report = LimitReport {
            input: job.input.display().to_string(),
            output: job.output.display().to_string(),
            scheme: name,
            vertices: topo.num_vertices(),
            levels_refined: levels_for_exact_limit(topo, &scheme)
                .0
                .max(usize::from(name == "two-phase")),
            seconds: t0.elapsed().as_secs_f64(),
            warnings: file.warnings.clone(),
        };
        crate::print_json(out, &report);
    }
    Ok(())
}

/// Writes the limit as text or as the input mesh with its vertices moved.
fn write_limit(
    args: &LimitArgs,
    job: &Job,
    limit: &LimitPoints,
    input: &Mesh,
    uv: Option<&crate::uv::RefinedUv>,
    is_text: bool,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    if is_text {
        let body = text(limit, args.normals);
        subd_io::atomic_write(&job.output, |w| w.write_all(body.as_bytes()))?;
    } else {
        let mut mesh = Mesh::new(input.topology.clone(), limit.positions.clone())
            .map_err(|e| bad(format!("{}: {e}", job.input.display())))?;
        mesh.hints = input.hints;
        if let Some(uv) = uv {
            let in_file =
                |e: subd_mesh::fvar::FVarError| bad(format!("{}: {e}", job.input.display()));
            let channel = subd_mesh::fvar::FVarChannel::new(
                &mesh.topology,
                2,
                uv.values.clone(),
                uv.indices.clone(),
            )
            .map_err(in_file)?;
            mesh = mesh.with_fvar(channel).map_err(in_file)?;
            let mut dropped = Vec::new();
            crate::uv::fit_ply(&mut mesh, &job.output, &mut dropped);
            print_warnings(err, &job.input, &dropped);
        }
        subd_io::write_mesh(&job.output, &mesh, &subd_io::WriteOptions::default())?;
    }
    Ok(())
}
