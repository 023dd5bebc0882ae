//! `subd render`: a headless, CPU-only shaded picture (PNG) of a mesh, of its refinement or
//! of its limit surface, with the control cage, the wireframe and marked points on top.

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use subd_mesh::DVec3;
use subd_schemes::{Capability, Scheme};

use crate::failure::{bad, refuse_overwrite};
use crate::raster::{Camera, Canvas, Rgb, shade};
use crate::refined::{RefinementWithLimit, last_level_limit, normals_or_faces};
use crate::rule_args::RuleArgs;
use crate::scheme_arg;
use crate::{Failure, print_warnings};

/// Largest picture side, in pixels.
const MAX_SIDE: usize = 16384;

/// The surface's colour.
const SURFACE: Rgb = [150, 175, 215];
/// Face colours by refinement level (a qualitative palette; level 8 and up repeat).
const LEVELS: [Rgb; 8] = [
    [141, 160, 203],
    [102, 194, 165],
    [252, 141, 98],
    [231, 138, 195],
    [166, 216, 84],
    [255, 217, 47],
    [229, 196, 148],
    [179, 179, 179],
];
/// End caps of a patch table (`--patches`), darker the deeper.
const END_CAP: Rgb = [215, 48, 39];
const CAGE: Rgb = [214, 96, 20];
const WIRE: Rgb = [55, 60, 75];
const POINT: Rgb = [200, 20, 40];

#[derive(Debug, Args)]
pub(crate) struct RenderArgs {
    /// Refine with this scheme before drawing (default: draw IN as it is; with --limit:
    /// loop for an all-triangle mesh, else catmull-clark).
    #[arg(long, value_parser = scheme_arg::parser(Capability::Refine))]
    scheme: Option<Scheme>,
    /// Levels of refinement (default 3 when refining).
    #[arg(long)]
    levels: Option<usize>,
    /// Tension w of --scheme butterfly (default 1/16).
    #[arg(long, allow_hyphen_values = true)]
    tension: Option<f64>,
    /// Draw the patches of the mesh's feature-adaptive patch table (Catmull-Clark or Loop),
    /// regular patches coloured by depth, end caps red.
    #[arg(long, conflicts_with_all = ["levels", "limit"])]
    patches: bool,
    /// Isolation level of --patches.
    #[arg(long, default_value_t = 3, requires = "patches",
          value_parser = clap::value_parser!(u8).range(1..=10))]
    isolation: u8,
    /// Draw the limit surface: the refined vertices at their exact limit positions, shaded
    /// with their limit normals.
    #[arg(long)]
    limit: bool,
    /// Draw IN's control cage over the surface (its hidden part faint).
    #[arg(long)]
    cage: bool,
    /// Draw the edges of the drawn surface.
    #[arg(long)]
    wireframe: bool,
    /// Mark the vertices of this mesh file with dots (a PIA run's targets: its input).
    #[arg(long, value_name = "MESH")]
    points: Option<PathBuf>,
    /// Picture size in pixels.
    #[arg(long, value_name = "WxH", default_value = "800x600", value_parser = parse_size)]
    size: (usize, usize),
    /// Viewing direction in degrees: azimuth about +y (0 looks down −z), elevation above
    /// the horizon.
    #[arg(long, value_name = "AZIMUTH,ELEVATION", default_value = "30,25", value_parser = parse_view, allow_hyphen_values = true)]
    view: (f64, f64),
    #[command(flatten)]
    rules: RuleArgs,
    /// Input mesh (.obj, .ply, .glb, .gltf). A PLY with a per-face `level` (as `subd
    /// adaptive` writes) drawn as it is gets its faces coloured by level.
    input: PathBuf,
    /// Output picture (.png).
    output: PathBuf,
    /// Print a JSON report on stdout.
    #[arg(long)]
    json: bool,
}

fn parse_size(s: &str) -> Result<(usize, usize), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or("expected WxH, e.g. 800x600")?;
    let side = |t: &str| match t.trim().parse::<usize>() {
        Ok(n) if (1..=MAX_SIDE).contains(&n) => Ok(n),
        _ => Err(format!("{t:?}: a side is 1 to {MAX_SIDE} pixels")),
    };
    Ok((side(w)?, side(h)?))
}

fn parse_view(s: &str) -> Result<(f64, f64), String> {
    let (a, e) = s
        .split_once(',')
        .ok_or("expected AZIMUTH,ELEVATION in degrees, e.g. 30,25")?;
    let angle = |t: &str| match t.trim().parse::<f64>() {
        Ok(d) if d.is_finite() => Ok(d),
        _ => Err(format!("{t:?}: expected an angle in degrees")),
    };
    Ok((angle(a)?, angle(e)?))
}

#[derive(Serialize)]
struct RenderReport {
    input: String,
    output: String,
    width: usize,
    height: usize,
    /// The scheme refined with, if any.
    scheme: Option<&'static str>,
    levels: usize,
    limit: bool,
    faces: usize,
    vertices: usize,
    coloured_by_level: bool,
    seconds: f64,
}

/// What is drawn as the surface: polygons, positions, unit normals and a colour per face.
struct Surface {
    offsets: Vec<u32>,
    vertices: Vec<u32>,
    holes: Vec<bool>,
    positions: Vec<DVec3>,
    normals: Vec<DVec3>,
    colors: Vec<Rgb>,
}

pub(crate) fn run(
    args: &RenderArgs,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    let t0 = Instant::now();
    let chosen = check_arguments(args)?;
    let refining = (args.scheme.is_some() || args.limit) && !args.patches;
    let file = subd_io::read_mesh(&args.input, &args.rules.read_options())?;
    print_warnings(err, &args.input, &file.warnings);
    let points = match &args.points {
        Some(p) => {
            let f = subd_io::read_mesh(p, &args.rules.read_options())?;
            print_warnings(err, p, &f.warnings);
            f.mesh.positions
        }
        None => Vec::new(),
    };
    let base = &file.mesh.topology;
    let scheme = chosen.unwrap_or(if (0..base.num_faces()).all(|f| base.face_size(f) == 3) {
        Scheme::Loop
    } else {
        Scheme::CatmullClark
    });
    let levels = if refining {
        args.levels.unwrap_or(3)
    } else {
        0
    };
    let surface = if args.patches {
        patches_surface(args, &file, &scheme)
    } else if refining {
        refined_surface(args, &file, &scheme, levels)
    } else {
        let holes = base.tags().holes().to_vec();
        let levels = file.face_levels.as_deref();
        surface(
            base.face_offsets().to_vec(),
            base.all_face_vertices().to_vec(),
            holes,
            file.mesh.positions.clone(),
            None,
            levels,
        )
    }
    .map_err(|e| bad(format!("{}: {e}", args.input.display())))?;
    let png = draw(args, &surface, &file.mesh, &points)
        .png()
        .map_err(|e| bad(format!("{}: cannot encode PNG: {e}", args.output.display())))?;
    subd_io::atomic_write(&args.output, |w| w.write_all(&png))?;
    if args.json {
        let report = RenderReport {
            input: args.input.display().to_string(),
            output: args.output.display().to_string(),
            width: args.size.0,
            height: args.size.1,
            scheme: refining.then(|| scheme.name()),
            levels,
            limit: args.limit,
            faces: surface.offsets.len() - 1,
            vertices: surface.positions.len(),
            coloured_by_level: !refining && file.face_levels.is_some(),
            seconds: t0.elapsed().as_secs_f64(),
        };
        crate::print_json(out, &report);
    }
    Ok(())
}

/// What can be checked before reading: the output, the scheme (with its tension; the
/// two-phase scheme needs its one `λ` in its name here) and `--levels`.
fn check_arguments(args: &RenderArgs) -> Result<Option<Scheme>, Failure> {
    refuse_overwrite(&args.input, &args.output)?;
    if !args
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"))
    {
        return Err(bad(format!(
            "{}: unsupported output extension (expected .png)",
            args.output.display()
        )));
    }
    let chosen = match &args.scheme {
        Some(s) => Some(scheme_arg::with_tension(s, args.tension, "--scheme")?),
        None if args.tension.is_some() => {
            return Err(bad("--tension applies to --scheme butterfly only".into()));
        }
        None => None,
    };
    if chosen
        .as_ref()
        .and_then(Scheme::two_phase)
        .is_some_and(|tp| !tp.is_set())
    {
        return Err(bad(
            "--scheme two-phase needs its λ: two-phase:λ, or refine with `subd refine` (per-vertex λ) and render its output".into(),
        ));
    }
    if args.levels.is_some() && args.scheme.is_none() && !args.limit {
        return Err(bad("--levels needs --scheme or --limit".into()));
    }
    Ok(chosen)
}

/// The patch table's patches to draw, each sampled on a small grid and coloured by its
/// type and depth.
fn patches_surface(
    args: &RenderArgs,
    file: &subd_io::MeshFile,
    scheme: &Scheme,
) -> Result<Surface, String> {
    use subd_limit::patches::{PatchOptions, PatchTable};
    if !scheme.supports(Capability::Evaluate) {
        return Err(format!(
            "--patches needs {}, not {scheme}",
            Scheme::list_with(Capability::Evaluate)
        ));
    }
    let options = PatchOptions {
        isolation: args.isolation,
        ..Default::default()
    };
    let rules = args.rules.options(&file.mesh.hints);
    let table = PatchTable::new(
        &file.mesh.topology,
        &file.mesh.positions,
        scheme,
        &rules,
        &options,
    )
    .map_err(|e| e.to_string())?;
    let grid = table.patch_grid(4).map_err(|e| e.to_string())?;
    let n = grid.patch.len();
    let colors = grid
        .patch
        .iter()
        .map(|&(a, i)| {
            let place = table.arrays()[a as usize].params()[i as usize].place();
            if place.regular {
                LEVELS[usize::from(place.depth) % LEVELS.len()]
            } else {
                let k = 1.0 - 0.06 * f64::from(place.depth.min(8));
                END_CAP.map(|c| (f64::from(c) * k) as u8)
            }
        })
        .collect();
    Ok(Surface {
        offsets: (0..=n as u32).map(|i| i * grid.face_size as u32).collect(),
        vertices: grid.faces,
        holes: vec![false; n],
        positions: grid.positions,
        normals: grid.normals,
        colors,
    })
}

/// The refined surface to draw: `levels` levels of `scheme`, at the limit with `--limit`.
fn refined_surface(
    args: &RenderArgs,
    file: &subd_io::MeshFile,
    scheme: &Scheme,
    levels: usize,
) -> Result<Surface, String> {
    let options = args.rules.options(&file.mesh.hints);
    let refinement =
        RefinementWithLimit::new(&file.mesh.topology, scheme.clone(), &options, levels)
            .map_err(|e| e.to_string())?;
    let (positions, limit_normals) = if args.limit {
        let limit = last_level_limit(&refinement, &options, &file.mesh.positions)
            .map_err(|e| e.to_string())?;
        (limit.positions, Some(limit.normals))
    } else {
        (refinement.last_positions(&file.mesh.positions), None)
    };
    let (offsets, vertices) = refinement.faces(levels);
    let holes = refinement.holes(levels).into_owned();
    surface(
        offsets.to_vec(),
        vertices.to_vec(),
        holes,
        positions,
        limit_normals,
        None,
    )
}

/// The picture: the surface, the cage (`--cage`) and the points (`--points`), framed to hold
/// all of them.
fn draw(args: &RenderArgs, surface: &Surface, cage: &subd_mesh::Mesh, points: &[DVec3]) -> Canvas {
    let (width, height) = args.size;
    let mut drawn: Vec<DVec3> = surface.positions.clone();
    if args.cage {
        drawn.extend_from_slice(&cage.positions);
    }
    drawn.extend_from_slice(points);
    let (centre, radius) = bounding_sphere(&drawn);
    let camera = Camera::new(centre, radius, args.view.0, args.view.1, width, height);
    let mut canvas = Canvas::new(width, height);
    draw_surface(&mut canvas, &camera, surface, args.wireframe, radius);
    let bias = 0.02 * radius;
    if args.cage {
        let base = &cage.topology;
        for e in 0..base.num_edges() {
            let [a, b] = base.edge_vertices(e);
            let (a, b) = (cage.positions[a as usize], cage.positions[b as usize]);
            canvas.line(camera.project(a), camera.project(b), CAGE, 2, bias, 0.25);
        }
        for &p in &cage.positions {
            canvas.dot(camera.project(p), 2.5, CAGE, bias, 0.25);
        }
    }
    for &p in points {
        canvas.dot(camera.project(p), 3.5, POINT, bias, 0.3);
    }
    canvas
}

/// The surface with unit normals (the limit's where given and defined, else the faces'
/// area-weighted ones) and face colours (by `levels` where given).
fn surface(
    offsets: Vec<u32>,
    vertices: Vec<u32>,
    holes: Vec<bool>,
    positions: Vec<DVec3>,
    limit_normals: Option<Vec<DVec3>>,
    levels: Option<&[u8]>,
) -> Result<Surface, String> {
    let view = subd_io::MeshView::new(&positions, &offsets, &vertices, &holes)
        .map_err(|e| e.to_string())?;
    let normals = match limit_normals {
        Some(n) => normals_or_faces(&n, &view).unwrap_or(n),
        None => subd_io::glb::vertex_normals(&view)
            .into_iter()
            .map(|n| n.try_normalize().unwrap_or(DVec3::Z))
            .collect(),
    };
    let faces = offsets.len() - 1;
    let colors = match levels {
        Some(l) if l.len() == faces => l
            .iter()
            .map(|&k| LEVELS[k as usize % LEVELS.len()])
            .collect(),
        _ => vec![SURFACE; faces],
    };
    Ok(Surface {
        offsets,
        vertices,
        holes,
        positions,
        normals,
        colors,
    })
}

/// The centre of the bounding box and the largest distance from it.
fn bounding_sphere(points: &[DVec3]) -> (DVec3, f64) {
    let (lo, hi) = points.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let centre = if points.is_empty() {
        DVec3::ZERO
    } else {
        (lo + hi) / 2.0
    };
    let radius = points
        .iter()
        .map(|p| p.distance(centre))
        .fold(0.0, f64::max);
    (centre, radius)
}

fn draw_surface(canvas: &mut Canvas, camera: &Camera, s: &Surface, wireframe: bool, radius: f64) {
    let screen: Vec<DVec3> = s.positions.iter().map(|&p| camera.project(p)).collect();
    let eye = camera.towards_eye();
    let (right, up) = camera.axes();
    for f in 0..s.offsets.len() - 1 {
        if s.holes[f] {
            continue;
        }
        let fv = &s.vertices[s.offsets[f] as usize..s.offsets[f + 1] as usize];
        for i in 1..fv.len() - 1 {
            let t = [fv[0], fv[i], fv[i + 1]].map(|v| v as usize);
            let n = t.map(|v| s.normals[v]);
            let color = s.colors[f];
            canvas.triangle(t.map(|v| screen[v]), |w| {
                let m = (w[0] * n[0] + w[1] * n[1] + w[2] * n[2])
                    .try_normalize()
                    .unwrap_or(eye);
                shade(color, m, eye, right, up)
            });
        }
    }
    if wireframe {
        let bias = 0.005 * radius;
        for f in 0..s.offsets.len() - 1 {
            if s.holes[f] {
                continue;
            }
            let fv = &s.vertices[s.offsets[f] as usize..s.offsets[f + 1] as usize];
            for i in 0..fv.len() {
                let (a, b) = (fv[i] as usize, fv[(i + 1) % fv.len()] as usize);
                canvas.line(screen[a], screen[b], WIRE, 1, bias, 0.0);
            }
        }
    }
}
