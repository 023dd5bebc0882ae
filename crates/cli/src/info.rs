//! `subd info`: a topology summary of a mesh file.

use std::io::Write;
use std::path::PathBuf;

use clap::Args;
use serde::Serialize;
use subd_mesh::report::MeshReport;

use crate::{Failure, print_warnings};

#[derive(Debug, Args)]
pub(crate) struct InfoArgs {
    /// Input mesh (.obj or .ply). Faces whose windings disagree are accepted and counted.
    input: PathBuf,
    /// Print one JSON object on stdout instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct InfoReport<'a> {
    file: String,
    #[serde(flatten)]
    mesh: &'a MeshReport,
    warnings: &'a [String],
}

pub(crate) fn run(
    args: &InfoArgs,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    // `info` is the diagnostic command: it accepts orientation conflicts (as OpenSubdiv does,
    // making the edge non-manifold) so that it can report them instead of stopping at the
    // first one.
    let options = subd_io::ReadOptions {
        accept_inconsistent_orientation: true,
        ..subd_io::ReadOptions::default()
    };
    let file = subd_io::read_mesh(&args.input, &options)?;
    print_warnings(err, &args.input, &file.warnings);
    let mesh = MeshReport::of(&file.mesh, file.orientation_conflicts);
    let report = InfoReport {
        file: args.input.display().to_string(),
        mesh: &mesh,
        warnings: &file.warnings,
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

fn write_text(out: &mut dyn Write, report: &InfoReport) -> std::io::Result<()> {
    let r = report.mesh;
    let s = &r.summary;
    let opt = |g: Option<i64>| {
        g.map_or(
            "undefined (not every component is a closed manifold)".to_string(),
            |g| g.to_string(),
        )
    };
    writeln!(out, "file              {}", report.file)?;
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
    writeln!(out, "components        {}", s.components)?;
    writeln!(out, "euler             {}", s.euler)?;
    writeln!(out, "genus             {}", opt(s.genus))?;
    Ok(())
}
