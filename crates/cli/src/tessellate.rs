//! `subd tessellate`: the limit surface sampled on a uniform grid per face, watertight, with
//! positions and normals.

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use subd_limit::patches::PatchTable;
use subd_limit::tessellation::{tessellate_mesh, tessellate_patches};

use subd_schemes::{Capability, Scheme};

use crate::Failure;
use crate::failure::bad;
use crate::refined::normals_or_faces;
use crate::rule_args::RuleArgs;
use crate::scheme_arg;

#[derive(Debug, Args)]
pub(crate) struct TessellateArgs {
    /// Subdivision scheme (default: the scheme the input names, USD's subdivisionScheme).
    #[arg(long, value_parser = scheme_arg::parser(Capability::Evaluate))]
    scheme: Option<Scheme>,
    /// Segments per base edge (even when a Catmull-Clark face is not a quad: each of its quad
    /// sub-faces takes half).
    #[arg(long)]
    rate: usize,
    #[command(flatten)]
    rules: RuleArgs,
    #[command(flatten)]
    on_patches: crate::patches::OnPatchesArgs,
    /// Input mesh (.obj, .ply, .glb, .gltf).
    input: PathBuf,
    /// Output mesh (.obj, .ply, .glb) with normals: quads (Catmull-Clark) or triangles (Loop).
    output: PathBuf,
    /// Print a JSON report on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct TessellateReport {
    input: String,
    output: String,
    scheme: subd_schemes::Scheme,
    rate: usize,
    vertices: usize,
    faces: usize,
    seconds: Seconds,
}

#[derive(Serialize)]
struct Seconds {
    read: f64,
    setup: f64,
    evaluate: f64,
    write: f64,
}

/// `subd tessellate` writes meshes (one file: no batch mode).
const TESSELLATE: crate::batch::Command = crate::batch::Command {
    name: "tessellate",
    formats: crate::batch::MESH_OUTPUTS,
};

pub(crate) fn run(
    args: &TessellateArgs,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    let opened = TESSELLATE
        .start(&args.input, &args.output)?
        .read(&args.rules, err)?;
    let (file, t_read) = (&opened.file, opened.read_seconds);
    let in_file = |e: &dyn std::fmt::Display| bad(format!("{}: {e}", args.input.display()));
    let t1 = Instant::now();
    let options = args.rules.options(&file.mesh.hints);
    let scheme = scheme_arg::given_or_named(
        args.scheme.as_ref(),
        &file.mesh.hints,
        Capability::Evaluate,
        &args.input,
    )?;
    let t_setup = t1.elapsed().as_secs_f64();
    let t2 = Instant::now();
    // Refinement and the last level's limit masks at a rate that is a power of two, the
    // evaluator (set up inside, so counted here) at others.
    let (topology, positions) = (&file.mesh.topology, &file.mesh.positions);
    let t = match args.on_patches.options() {
        Some(po) => PatchTable::new(topology, positions, &scheme, &options, &po)
            .and_then(|table| tessellate_patches(&table, args.rate)),
        None => tessellate_mesh(topology, &scheme, &options, positions, args.rate),
    }
    .map_err(|e| in_file(&e))?;
    let t_evaluate = t2.elapsed().as_secs_f64();
    let t3 = Instant::now();
    let holes = vec![false; t.face_offsets.len() - 1];
    let view = subd_io::MeshView::new(&t.positions, &t.face_offsets, &t.face_vertices, &holes)
        .map_err(|e| in_file(&e))?;
    let normals = normals_or_faces(&t.normals, &view);
    let normals = normals.as_deref().unwrap_or(&t.normals);
    let view = view.with_normals(normals).map_err(|e| in_file(&e))?;
    subd_io::write_view(&args.output, &view, &file.output_options())?;
    if args.json {
        let report = TessellateReport {
            input: args.input.display().to_string(),
            output: args.output.display().to_string(),
            scheme,
            rate: args.rate,
            vertices: t.positions.len(),
            faces: holes.len(),
            seconds: Seconds {
                read: t_read,
                setup: t_setup,
                evaluate: t_evaluate,
                write: t3.elapsed().as_secs_f64(),
            },
        };
        crate::print_json(out, &report);
    }
    Ok(())
}
