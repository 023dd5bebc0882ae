//! `subd info`: a topology summary of a mesh file.

use std::io::Write;
use std::path::PathBuf;

use clap::Args;
use serde::Serialize;
use subd_mesh::report::MeshReport;

use crate::{Failure, print_warnings};

#[derive(Debug, Args)]
pub(crate) struct InfoArgs {
    /// Input mesh (.obj, .ply, .glb, .gltf, .usda, .usdc, .usdz, .usd). Faces whose windings
    /// disagree are accepted and counted. A USD stage's mesh prims are listed; the report
    /// is of its only one, or of --prim.
    #[arg(required_unless_present = "devices")]
    input: Option<PathBuf>,
    /// List the GPU adapters subd can use (Vulkan, Metal, DX12) instead of reading a mesh.
    #[arg(long, conflicts_with_all = ["input", "prim", "time"])]
    devices: bool,
    /// USD input: the mesh prim to report on.
    #[arg(long, value_name = "PATH")]
    prim: Option<String>,
    /// USD input: the time code at which time-sampled attributes are read.
    #[arg(long, value_name = "T")]
    time: Option<f64>,
    /// Print one JSON object on stdout instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct InfoReport<'a> {
    file: String,
    /// A USD stage's mesh prims.
    #[serde(skip_serializing_if = "Option::is_none")]
    prims: Option<Vec<PrimReport>>,
    /// The prim reported on and the stage's units (USD).
    #[serde(skip_serializing_if = "Option::is_none")]
    stage: Option<StageReport>,
    #[serde(flatten)]
    mesh: Option<&'a MeshReport>,
    warnings: &'a [String],
}

#[derive(Serialize)]
struct PrimReport {
    path: String,
    faces: usize,
    points: usize,
    scheme: String,
}

#[derive(Serialize)]
struct StageReport {
    prim: String,
    meters_per_unit: Option<f64>,
    up_axis: Option<String>,
}

pub(crate) fn run(
    args: &InfoArgs,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    let Some(input) = &args.input else {
        print_devices(args.json, out);
        return Ok(());
    };
    // `info` is the diagnostic command: it accepts orientation conflicts (as OpenSubdiv does,
    // making the edge non-manifold) so that it can report them instead of stopping at the
    // first one.
    let options = subd_io::ReadOptions {
        accept_inconsistent_orientation: true,
        prim: args.prim.clone(),
        time: args.time,
        ..subd_io::ReadOptions::default()
    };
    let prims = usd_prims(input)?;
    // A stage with several mesh prims and no --prim: the list alone.
    let listed_only = args.prim.is_none() && prims.as_ref().is_some_and(|p| p.len() > 1);
    let file = if listed_only {
        None
    } else {
        Some(subd_io::read_mesh(input, &options)?)
    };
    if let Some(file) = &file {
        print_warnings(err, input, &file.warnings);
    }
    let mesh = file
        .as_ref()
        .map(|f| MeshReport::of(&f.mesh, f.orientation_conflicts));
    let report = InfoReport {
        file: input.display().to_string(),
        prims,
        stage: file
            .as_ref()
            .and_then(|f| f.stage.as_ref())
            .map(|s| StageReport {
                prim: s.prim.clone(),
                meters_per_unit: s.meters_per_unit,
                up_axis: s.up_axis.clone(),
            }),
        mesh: mesh.as_ref(),
        warnings: file.as_ref().map_or(&[], |f| &f.warnings),
    };
    let written = if args.json {
        serde_json::to_writer(&mut *out, &report)
            .map_err(std::io::Error::other)
            .and_then(|_| writeln!(out))
    } else {
        write_text(out, &report)
    };
    // A closed pipe (e.g. `| head`) is not an error of the input.
    let _ = written;
    Ok(())
}

fn histogram(h: &std::collections::BTreeMap<usize, usize>) -> String {
    h.iter()
        .map(|(k, v)| format!("{k}:{v}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The mesh prims of a USD input (`None` for the other formats).
fn usd_prims(input: &std::path::Path) -> Result<Option<Vec<PrimReport>>, Failure> {
    let usd = subd_io::Format::from_path(input).is_some_and(subd_io::Format::is_usd);
    if !usd {
        return Ok(None);
    }
    let prims = subd_io::usd::mesh_prims(input)?;
    Ok(Some(
        prims
            .into_iter()
            .map(|p| PrimReport {
                path: p.path,
                faces: p.faces,
                points: p.points,
                scheme: p.scheme,
            })
            .collect(),
    ))
}

fn write_text(out: &mut dyn Write, report: &InfoReport) -> std::io::Result<()> {
    writeln!(out, "file              {}", report.file)?;
    for p in report.prims.iter().flatten() {
        writeln!(
            out,
            "mesh prim         {} ({} faces, {} points, {})",
            p.path, p.faces, p.points, p.scheme
        )?;
    }
    if let Some(s) = &report.stage {
        writeln!(out, "prim              {}", s.prim)?;
        let units = s.meters_per_unit.map_or("unset".into(), |m| m.to_string());
        writeln!(out, "meters per unit   {units}")?;
        writeln!(
            out,
            "up axis           {}",
            s.up_axis.as_deref().unwrap_or("unset")
        )?;
    }
    match report.mesh {
        Some(r) => write_mesh_text(out, r),
        None => writeln!(
            out,
            "(several mesh prims: pick one with --prim for its report)"
        ),
    }
}

fn write_mesh_text(out: &mut dyn Write, r: &MeshReport) -> std::io::Result<()> {
    let s = &r.summary;
    let opt = |g: Option<i64>| {
        g.map_or(
            "undefined (not every component is a closed manifold)".to_string(),
            |g| g.to_string(),
        )
    };
    writeln!(out, "vertices          {}", s.vertices)?;
    writeln!(out, "edges             {}", s.edges)?;
    writeln!(out, "faces             {}", s.faces)?;
    writeln!(out, "face sizes        {}", histogram(&s.face_sizes))?;
    writeln!(out, "valences          {}", histogram(&s.valences))?;
    writeln!(
        out,
        "boundary          {} edges, {} vertices, {} loops",
        s.boundary_edges, s.boundary_vertices, s.boundary_loops
    )?;
    writeln!(
        out,
        "non-manifold      {} edges, {} vertices ({} degenerate edges)",
        s.nonmanifold_edges, s.nonmanifold_vertices, s.degenerate_edges
    )?;
    writeln!(out, "isolated vertices {}", s.isolated_vertices)?;
    writeln!(
        out,
        "orientation       {} edges used in the same direction by two faces",
        r.orientation_conflicts
    )?;
    writeln!(
        out,
        "irregular         {} (quad schemes), {} (Loop)",
        r.irregular_vertices.quad, r.irregular_vertices.triangle
    )?;
    writeln!(
        out,
        "creases           {} semi-sharp, {} infinitely sharp",
        s.semi_sharp_creases, s.infinite_creases
    )?;
    writeln!(out, "corners           {}", s.corners)?;
    writeln!(out, "holes             {}", s.holes)?;
    if let Some(b) = r.boundary_interpolation {
        writeln!(
            out,
            "boundary rule     {}",
            serde_json::to_value(b)
                .unwrap_or_default()
                .as_str()
                .unwrap_or("")
        )?;
    }
    for (i, c) in r.fvar_channels.iter().enumerate() {
        let what = if i == 0 {
            "uv".to_string()
        } else {
            format!("fvar {i}")
        };
        writeln!(
            out,
            "{what:<17} {} values of {} components, {} at vertices; seams: {} edges, {} vertices",
            c.values, c.components, c.vertex_values, c.seam_edges, c.seam_vertices
        )?;
    }
    if let Some(m) = r.fvar_interpolation {
        writeln!(out, "fvar rule         {}", m.name())?;
    }
    if let Some(scheme) = r.scheme {
        let name = serde_json::to_value(scheme).unwrap_or_default();
        writeln!(out, "scheme            {}", name.as_str().unwrap_or(""))?;
    }
    writeln!(out, "components        {}", s.components)?;
    writeln!(out, "euler             {}", s.euler)?;
    writeln!(out, "genus             {}", opt(s.genus))?;
    Ok(())
}

#[derive(Serialize)]
struct DeviceReport {
    name: String,
    backend: String,
    device_type: String,
    driver: String,
    shader_f64: bool,
}

/// `--devices`: the GPU adapters, one line each (or a JSON list); none is not an error.
fn print_devices(json: bool, out: &mut dyn Write) {
    let adapters: Vec<DeviceReport> = subd_gpu::list_adapters()
        .into_iter()
        .map(|a| DeviceReport {
            name: a.name,
            backend: a.backend,
            device_type: a.device_type,
            driver: a.driver,
            shader_f64: a.shader_f64,
        })
        .collect();
    if json {
        crate::print_json(out, &adapters);
        return;
    }
    if adapters.is_empty() {
        let _ = writeln!(
            out,
            "no GPU adapter (on Linux, Mesa's software Vulkan driver, Debian's mesa-vulkan-drivers, provides one)"
        );
    }
    for a in &adapters {
        let f64_note = if a.shader_f64 { ", f64" } else { "" };
        let _ = writeln!(
            out,
            "{} ({}, {}{f64_note}; driver {})",
            a.name, a.backend, a.device_type, a.driver
        );
    }
}
