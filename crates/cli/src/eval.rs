//! `subd eval`: the exact limit surface at given (face, u, v).

use std::fmt::Write as _;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use subd_limit::eval::{FaceParam, LimitEvaluator};
use subd_limit::patches::{PatchOptions, PatchTable};
use subd_schemes::{Capability, Scheme};

use crate::failure::{bad, refuse_overwrite};
use crate::rule_args::RuleArgs;
use crate::scheme_arg;
use crate::{Failure, print_warnings};

#[derive(Debug, Args)]
pub(crate) struct EvalArgs {
    /// Subdivision scheme (default: the scheme the input names, USD's subdivisionScheme).
    #[arg(long, value_parser = scheme_arg::parser(Capability::Evaluate))]
    scheme: Option<Scheme>,
    #[command(flatten)]
    rules: RuleArgs,
    #[command(flatten)]
    on_patches: crate::patches::OnPatchesArgs,
    /// Input mesh (.obj or .ply).
    input: PathBuf,
    /// Points to evaluate, one per line: `face u v`, or `face sub u v` for a face that is not
    /// a quad under Catmull-Clark (sub-face `sub` = the quad at its corner `sub`); blank
    /// lines and `#` comments are skipped.
    #[arg(long)]
    at: PathBuf,
    /// Output: one line `x y z nx ny nz` per point, followed by the limit texture
    /// coordinates `u v` when the mesh has UVs (interpolated by `--fvar-interpolation`).
    output: PathBuf,
    /// Print a JSON report on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct EvalReport {
    input: String,
    output: String,
    scheme: Scheme,
    points: usize,
    /// Whether each line carries the limit texture coordinates.
    uv: bool,
    seconds: f64,
}

/// Parses the parameter file into points, checking each against the mesh.
fn read_points(
    path: &Path,
    table: &PatchTable,
    sizes: &[u32],
    catmark: bool,
) -> Result<Vec<FaceParam>, Failure> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| bad(format!("{}: cannot read: {e}", path.display())))?;
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line_no = i + 1;
        let at_line = |m: String| bad(format!("{}:{line_no}: {m}", path.display()));
        let body = line.split('#').next().unwrap_or("").trim();
        if body.is_empty() {
            continue;
        }
        let fields: Vec<&str> = body.split_whitespace().collect();
        let int = |s: &str| {
            s.parse::<usize>()
                .map_err(|_| at_line(format!("expected a face index, found {s:?}")))
        };
        let real = |s: &str| {
            s.parse::<f64>()
                .map_err(|_| at_line(format!("expected a parameter, found {s:?}")))
        };
        let (face, sub, u, v) = match fields.as_slice() {
            [f, u, v] => (int(f)?, 0, real(u)?, real(v)?),
            [f, s, u, v] => (int(f)?, int(s)?, real(u)?, real(v)?),
            _ => {
                return Err(at_line(format!(
                    "expected `face u v` or `face sub u v`, found {} fields",
                    fields.len()
                )));
            }
        };
        if catmark && face < sizes.len() && sizes[face] != 4 && fields.len() == 3 {
            return Err(at_line(format!(
                "face {face} has {} vertices: give its sub-face (`face sub u v`)",
                sizes[face]
            )));
        }
        let p = FaceParam { face, sub, u, v };
        table.check(&p).map_err(|e| at_line(e.to_string()))?;
        out.push(p);
    }
    Ok(out)
}

pub(crate) fn run(
    args: &EvalArgs,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    let t0 = Instant::now();
    refuse_overwrite(&args.input, &args.output)?;
    let file = subd_io::read_mesh(&args.input, &args.rules.read_options())?;
    print_warnings(err, &args.input, &file.warnings);
    let scheme = scheme_arg::given_or_named(
        args.scheme.as_ref(),
        &file.mesh.hints,
        Capability::Evaluate,
        &args.input,
    )?;
    let options = args.rules.options(&file.mesh.hints);
    let topo = &file.mesh.topology;
    // On the patch table: the exact limit's (exact end caps) unless other patches are
    // asked for.
    let patch_options = args
        .on_patches
        .options()
        .unwrap_or_else(PatchOptions::exact_limit);
    let table = PatchTable::new(
        topo,
        &file.mesh.positions,
        &scheme,
        &options,
        &patch_options,
    )
    .map_err(|e| bad(format!("{}: {e}", args.input.display())))?;
    let sizes: Vec<u32> = topo.face_sizes().collect();
    let points = read_points(&args.at, &table, &sizes, scheme == Scheme::CatmullClark)?;
    let at_point = |i: usize, p: &FaceParam, e: subd_limit::LimitError| {
        bad(format!(
            "{}: point {} (face {}): {e}",
            args.at.display(),
            i + 1,
            p.face
        ))
    };
    // The texture coordinates' evaluator and control values, when the mesh has UVs.
    let uv = match file.mesh.uv() {
        Some(channel) => {
            let mode = args.rules.fvar_mode(&file.mesh.hints);
            // The exact limit of the texture coordinates (the table's face-varying patches
            // are OpenSubdiv's linear ones).
            let ev = LimitEvaluator::new(topo, &scheme, &options)
                .map_err(|e| bad(format!("{}: {e}", args.input.display())))?;
            let uv_eval = ev.face_varying(channel, mode).map_err(|e| {
                bad(format!(
                    "{}: texture coordinates: {e}",
                    args.input.display()
                ))
            })?;
            let values = uv_eval.prepare(channel.values()).map_err(|e| {
                bad(format!(
                    "{}: texture coordinates: {e}",
                    args.input.display()
                ))
            })?;
            Some((uv_eval, values))
        }
        None => None,
    };
    let mut body = String::with_capacity(points.len() * 160);
    for (i, p) in points.iter().enumerate() {
        let s = table.evaluate(*p).map_err(|e| at_point(i, p, e))?;
        let (x, n) = (s.position, s.normal());
        let _ = write!(body, "{} {} {} {} {} {}", x.x, x.y, x.z, n.x, n.y, n.z);
        if let Some((uv_eval, values)) = &uv {
            let t = uv_eval
                .evaluate(values, *p)
                .map_err(|e| at_point(i, p, e))?;
            for x in &t.value {
                let _ = write!(body, " {x}");
            }
        }
        body.push('\n');
    }
    subd_io::atomic_write(&args.output, |w| w.write_all(body.as_bytes()))?;
    if args.json {
        let report = EvalReport {
            input: args.input.display().to_string(),
            output: args.output.display().to_string(),
            scheme,
            points: points.len(),
            uv: uv.is_some(),
            seconds: t0.elapsed().as_secs_f64(),
        };
        crate::print_json(out, &report);
    }
    Ok(())
}
