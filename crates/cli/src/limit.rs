//! `subd limit`: the limit position (and normal) of every vertex of a mesh.

use std::fmt::Write as _;
use std::io::Write;
use std::path::{Path, PathBuf};

use clap::Args;
use serde::Serialize;
use subd_limit::{LimitPoints, LimitStencilTable, levels_for_exact_limit};
use subd_mesh::Mesh;
use subd_schemes::{Capability, Scheme};

use crate::batch::{self, Files, Job, OutputFormat};
use crate::failure::bad;
use crate::rule_args::RuleArgs;
use crate::scheme_arg;
use crate::vertex_data::LambdaArgs;
use crate::{Failure, print_warnings};

#[derive(Debug, Args)]
pub(crate) struct LimitArgs {
    /// Subdivision scheme: the limit of its limit masks (Catmull-Clark, Loop), of Lin et al.'s
    /// formula (2) (two-phase, closed quad meshes), of each vertex's vertex face one level down
    /// (Doo-Sabin), of Kobbelt's masks (√3), or the vertices themselves with normals from the
    /// eigenvectors (the butterflies). Default: the scheme the input names (USD's
    /// subdivisionScheme).
    #[arg(long, value_parser = scheme_arg::parser(Capability::Limit))]
    scheme: Option<Scheme>,
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

/// `subd limit`'s outputs: text or the input mesh with its vertices moved.
const LIMIT: batch::Command = batch::Command {
    name: "limit",
    formats: &[
        OutputFormat::Txt,
        OutputFormat::Obj,
        OutputFormat::Ply,
        OutputFormat::Glb,
    ],
};

pub(crate) fn run(
    args: &LimitArgs,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    LIMIT.run(&args.files, args.json, out, err, |job, out, err| {
        run_one(args, job, out, err)
    })
}

fn run_one(
    args: &LimitArgs,
    job: &Job,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    let started = LIMIT.start_job(job)?;
    let is_text = OutputFormat::of(&job.output) == Some(OutputFormat::Txt);
    let opened = started.read(&args.rules, err)?;
    let (mesh, input) = (&opened.file.mesh, &job.input);
    let given = args.scheme.as_ref();
    let scheme = scheme_arg::given_or_named(given, &mesh.hints, Capability::Limit, input)?;
    let scheme = scheme_arg::with_tension(&scheme, args.tension, "--scheme")?;
    if args.acc.is_some() && scheme != Scheme::CatmullClark {
        return Err(bad(
            "--acc: ACC patches approximate catmull-clark surfaces only".into(),
        ));
    }
    let in_file = |e: &dyn std::fmt::Display| bad(format!("{}: {e}", input.display()));
    let topo = &mesh.topology;
    let options = args.rules.options(&mesh.hints);
    let scheme = scheme_arg::with_lambda(&scheme, &args.lambda, input, topo.num_vertices())?;
    // A split scheme's texture coordinates take their limit through the stencils the
    // positions' masks write as rows: built once for both; otherwise the masks are applied
    // to the points as they are found.
    let uv_table = (mesh.uv().is_some() && !is_text && !scheme.is_opensubdiv())
        .then(|| subd_limit::limit_stencils(topo, &scheme, &options))
        .transpose()
        .map_err(|e| in_file(&e))?;
    let limit = match &uv_table {
        Some(table) => table.apply(&mesh.positions),
        None => subd_limit::limit_points(topo, &scheme, &options, &mesh.positions)
            .map_err(|e| in_file(&e))?,
    };
    // ACC first, so that a mesh it does not cover fails before any file is written.
    let acc = match &args.acc {
        Some(path) => Some((path, acc_json(path, topo, &mesh.positions, input)?)),
        None => None,
    };
    let mut uv_warnings = Vec::new();
    let uv = match mesh.uv() {
        Some(c) if !is_text => Some(
            limit_uv(
                args,
                mesh,
                (&scheme, &options, uv_table.as_ref()),
                c,
                &mut uv_warnings,
            )
            .map_err(|e| in_file(&e))?,
        ),
        _ => None,
    };
    print_warnings(err, input, &uv_warnings);
    let write_options = opened.file.output_options();
    write_limit(
        args,
        job,
        &limit,
        mesh,
        uv.as_ref(),
        (is_text, &write_options),
        err,
    )?;
    if let Some((path, json)) = acc {
        subd_io::atomic_write(path, |w| w.write_all(&json))?;
    }
    if args.json {
        let report = LimitReport {
            input: input.display().to_string(),
            output: job.output.display().to_string(),
            scheme: scheme.name(),
            vertices: topo.num_vertices(),
            levels_refined: levels_refined(topo, &scheme),
            seconds: opened.elapsed(),
            warnings: opened.file.warnings.clone(),
        };
        crate::print_json(out, &report);
    }
    Ok(())
}
/// The ACC patches of a Catmull-Clark mesh as JSON, for `path`.
fn acc_json(
    path: &Path,
    topo: &subd_mesh::Topology,
    positions: &[subd_mesh::DVec3],
    input: &Path,
) -> Result<Vec<u8>, Failure> {
    let patches = subd_limit::acc::acc_patches(topo, positions)
        .map_err(|e| bad(format!("{}: {e}", input.display())))?;
    serde_json::to_vec(&patches).map_err(|e| bad(format!("{}: {e}", path.display())))
}

/// The texture coordinates at their limit too: through the positions' limit stencils
/// (`table`) for the split schemes (warnings where they cannot carry seams), through the
/// face-varying limit of Catmull-Clark or Loop otherwise (two-phase: Catmull-Clark's, which
/// its second phase on is).
fn limit_uv(
    args: &LimitArgs,
    mesh: &Mesh,
    (scheme, options, table): (&Scheme, &subd_schemes::Options, Option<&LimitStencilTable>),
    channel: &subd_mesh::fvar::FVarChannel,
    warnings: &mut Vec<String>,
) -> Result<crate::uv::RefinedUv, String> {
    let mode = args.rules.fvar_mode(&mesh.hints);
    let topo = &mesh.topology;
    if !scheme.is_opensubdiv() {
        let table = table.expect("the split schemes' stencils are built for their UVs");
        crate::uv::split_limit_uv(topo, (scheme, table), channel, mode, warnings)
            .map_err(|e| e.to_string())
    } else {
        crate::uv::limit_uv(topo, &scheme.at_level(1), options, channel, mode)
            .map_err(|e| e.to_string())
    }
}

/// Uniform levels the limit refines first: as semi-sharp features need to decay (and
/// Catmull-Clark non-quads), phase 1 at least for the two-phase scheme; none for the split
/// schemes, whose stencils look as deep as each vertex needs.
fn levels_refined(topo: &subd_mesh::Topology, scheme: &Scheme) -> usize {
    if !scheme.is_opensubdiv() {
        return 0;
    }
    let two_phase = usize::from(scheme.two_phase().is_some());
    levels_for_exact_limit(topo, &scheme.at_level(1))
        .0
        .max(two_phase)
}

/// Writes the limit as text or as the input mesh with its vertices moved.
fn write_limit(
    args: &LimitArgs,
    job: &Job,
    limit: &LimitPoints,
    input: &Mesh,
    uv: Option<&crate::uv::RefinedUv>,
    (is_text, write_options): (bool, &subd_io::WriteOptions),
    err: &mut dyn Write,
) -> Result<(), Failure> {
    if is_text {
        let body = text(limit, args.normals);
        subd_io::atomic_write(&job.output, |w| w.write_all(body.as_bytes()))?;
    } else {
        let mut mesh = Mesh::new(input.topology.clone(), limit.positions.clone())
            .map_err(|e| bad(format!("{}: {e}", job.input.display())))?;
        mesh.hints = input.hints;
        // Points on the limit surface: polygons, no longer a cage to subdivide.
        mesh.hints.scheme = None;
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
        subd_io::write_mesh(&job.output, &mesh, write_options)?;
    }
    Ok(())
}
