//! `subd curve`: subdivision curves from a text point list, to text or SVG.

use std::fmt::Write as _;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use glam::{DVec2, DVec3};
use serde::Serialize;
use subd_mesh::choice::Choice;
use subd_schemes::named_curve::{
    CurveName, CurveParameters, NamedCurve, SubdividedCurve, subdivide_curve,
};

use crate::Failure;
use crate::choice_arg;
use crate::failure::{bad, refuse_overwrite};

#[derive(Debug, Args)]
pub(crate) struct CurveArgs {
    /// Curve scheme.
    #[arg(long, value_parser = choice_arg::parser::<CurveName>())]
    scheme: CurveName,
    /// Number of subdivision levels.
    #[arg(long)]
    levels: usize,
    /// The input polygon is closed.
    #[arg(long)]
    closed: bool,
    /// Tension ω (four-point, four-point-2p, ternary-3pt, circle schemes).
    #[arg(long, allow_hyphen_values = true)]
    omega: Option<f64>,
    /// Displacement μ (four-point-2p, circle-four-point).
    #[arg(long, allow_hyphen_values = true)]
    mu: Option<f64>,
    /// B-spline order k ≥ 2 (bspline).
    #[arg(long)]
    order: Option<usize>,
    /// Initial tension α₀ ≥ −1 (tension); cos(2π/N) turns a regular N-gon into a circle.
    #[arg(long, allow_hyphen_values = true)]
    alpha0: Option<f64>,
    /// Input points (.txt or .csv): `x y`, `x y z`, or `x y nx ny` per line; `#` comments.
    input: PathBuf,
    /// Output: .txt or .csv (one point per line, with normals for the circle schemes) or
    /// .svg (control polygon, result and normals).
    output: PathBuf,
    /// Print a JSON report on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct CurveReport {
    input: String,
    output: String,
    scheme: &'static str,
    levels: usize,
    closed: bool,
    input_points: usize,
    output_points: usize,
    normals_estimated: bool,
    seconds: f64,
}

/// Points read from a text file: positions (z = 0 for 2D), the column count, and normals
/// when there were four columns.
struct PointFile {
    points: Vec<DVec3>,
    columns: usize,
    normals: Option<Vec<DVec2>>,
}

fn read_points(path: &Path) -> Result<PointFile, Failure> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| bad(format!("{}: cannot read: {e}", path.display())))?;
    let mut points = Vec::new();
    let mut normals = Vec::new();
    let mut columns = 0;
    for (i, line) in text.lines().enumerate() {
        let at = |m: String| bad(format!("{}:{}: {m}", path.display(), i + 1));
        let body = line.split('#').next().unwrap_or("").trim();
        if body.is_empty() {
            continue;
        }
        let vals: Vec<f64> = body
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|t| !t.is_empty())
            .map(|t| {
                t.parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| at(format!("{t:?} is not a finite number")))
            })
            .collect::<Result<_, _>>()?;
        if !(2..=4).contains(&vals.len()) {
            return Err(at(format!(
                "{} values; expected `x y`, `x y z` or `x y nx ny`",
                vals.len()
            )));
        }
        if columns == 0 {
            columns = vals.len();
        } else if vals.len() != columns {
            return Err(at(format!(
                "{} values, but earlier lines have {columns}",
                vals.len()
            )));
        }
        points.push(DVec3::new(
            vals[0],
            vals[1],
            if columns == 3 { vals[2] } else { 0.0 },
        ));
        if columns == 4 {
            let n = DVec2::new(vals[2], vals[3]);
            if n.length() == 0.0 {
                return Err(at("the normal is zero".into()));
            }
            // Made unit length by the library, once.
            normals.push(n);
        }
    }
    Ok(PointFile {
        points,
        columns,
        normals: (columns == 4).then_some(normals),
    })
}

pub(crate) fn run(
    args: &CurveArgs,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    let t0 = Instant::now();
    let ext = check_arguments(args)?;
    let name = args.scheme.name();
    let file = read_points(&args.input)?;
    let scheme = NamedCurve::of(args.scheme, &parameters(args))
        .map_err(|e| bad(format!("--scheme {name}: {e}")))?;
    let circle = matches!(scheme, NamedCurve::Circle(_));
    if circle && file.columns == 3 {
        return Err(bad(format!(
            "{}: the circle-average schemes work on planar points (`x y` or `x y nx ny`), not `x y z`",
            args.input.display()
        )));
    }
    if circle && file.normals.is_none() {
        let _ = writeln!(
            err,
            "subd: warning: {}: no normals given; estimated from the polygon",
            args.input.display()
        );
    }
    let SubdividedCurve {
        points,
        normals,
        normals_estimated,
    } = subdivide_curve(
        &scheme,
        &file.points,
        file.normals.as_deref(),
        args.closed,
        args.levels,
    )
    .map_err(|e| bad(format!("{}: {e}", args.input.display())))?;
    let body = if ext == "svg" {
        svg(
            &file.points,
            &points,
            normals.as_deref(),
            args.closed,
            name,
            args.levels,
        )
    } else {
        let sep = if ext == "csv" { "," } else { " " };
        text(&points, normals.as_deref(), file.columns == 3, sep)
    };
    subd_io::atomic_write(&args.output, |w| w.write_all(body.as_bytes()))?;
    if args.json {
        crate::print_json(
            out,
            &CurveReport {
                input: args.input.display().to_string(),
                output: args.output.display().to_string(),
                scheme: name,
                levels: args.levels,
                closed: args.closed,
                input_points: file.points.len(),
                output_points: points.len(),
                normals_estimated,
                seconds: t0.elapsed().as_secs_f64(),
            },
        );
    }
    Ok(())
}

/// Checks the output (not the input; `.txt`, `.csv` or `.svg`, returned in lower case) and
/// refuses parameters the scheme does not take, rather than ignoring them.
fn check_arguments(args: &CurveArgs) -> Result<String, Failure> {
    refuse_overwrite(&args.input, &args.output)?;
    let ext = args
        .output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    if !["txt", "csv", "svg"].contains(&ext.as_str()) {
        return Err(bad(format!(
            "{}: unsupported output extension (expected .txt, .csv or .svg)",
            args.output.display()
        )));
    }
    let scheme = args.scheme;
    let takes = |flag: &str| scheme.takes(flag);
    for (flag, given) in [
        ("omega", args.omega.is_some()),
        ("mu", args.mu.is_some()),
        ("order", args.order.is_some()),
        ("alpha0", args.alpha0.is_some()),
    ] {
        if given && !takes(flag) {
            return Err(bad(format!(
                "--{flag} does not apply to --scheme {}",
                scheme.name()
            )));
        }
    }
    Ok(ext)
}

/// The parameters given (the library supplies the defaults).
fn parameters(args: &CurveArgs) -> CurveParameters {
    CurveParameters {
        omega: args.omega,
        mu: args.mu,
        order: args.order,
        alpha0: args.alpha0,
    }
}

/// One line per point: `x y` (`z` for 3D input), then the normal where there is one.
fn text(points: &[DVec3], normals: Option<&[DVec2]>, three_d: bool, sep: &str) -> String {
    let mut s = String::with_capacity(points.len() * 48);
    for (i, p) in points.iter().enumerate() {
        let _ = write!(s, "{}{sep}{}", p.x, p.y);
        if three_d {
            let _ = write!(s, "{sep}{}", p.z);
        }
        if let Some(n) = normals {
            let _ = write!(s, "{sep}{}{sep}{}", n[i].x, n[i].y);
        }
        s.push('\n');
    }
    s
}

/// An SVG figure (x, y; z dropped): the control polygon in grey with its points, the result
/// in blue, and normals as short red ticks where there are normals (every one up to 400
/// points, fewer beyond).
fn svg(
    control: &[DVec3],
    result: &[DVec3],
    normals: Option<&[DVec2]>,
    closed: bool,
    name: &str,
    levels: usize,
) -> String {
    let (lo, hi) = control.iter().chain(result).fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p.truncate()), hi.max(p.truncate())),
    );
    let size = (hi - lo).max_element().max(1e-300);
    let (w, margin) = (800.0, 40.0);
    let scale = (w - 2.0 * margin) / size;
    let height = (hi.y - lo.y) * scale + 2.0 * margin + 30.0;
    // y grows downwards in SVG.
    let map = |p: DVec2| {
        DVec2::new(
            margin + (p.x - lo.x) * scale,
            margin + 30.0 + (hi.y - p.y) * scale,
        )
    };
    let path = |pts: &[DVec3], close: bool| {
        let mut d = String::new();
        for (i, p) in pts.iter().enumerate() {
            let q = map(p.truncate());
            let _ = write!(
                d,
                "{}{:.3},{:.3} ",
                if i == 0 { "M" } else { "L" },
                q.x,
                q.y
            );
        }
        if close {
            d.push('Z');
        }
        d
    };
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{height:.0}" viewBox="0 0 {w} {height:.0}">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{margin}" y="24" font-family="sans-serif" font-size="16">{name}, {levels} levels: {} → {} points (grey: control polygon, blue: result{})</text>"#,
        control.len(),
        result.len(),
        if normals.is_some() {
            ", red: normals"
        } else {
            ""
        }
    );
    let _ = writeln!(
        s,
        r##"<path d="{}" fill="none" stroke="#999" stroke-width="1.5" stroke-dasharray="6 4"/>"##,
        path(control, closed)
    );
    for p in control {
        let q = map(p.truncate());
        let _ = writeln!(
            s,
            r##"<circle cx="{:.3}" cy="{:.3}" r="4" fill="#666"/>"##,
            q.x, q.y
        );
    }
    let _ = writeln!(
        s,
        r##"<path d="{}" fill="none" stroke="#1f5fbf" stroke-width="2"/>"##,
        path(result, closed)
    );
    if let Some(ns) = normals {
        let step = result.len().div_ceil(400).max(1);
        let len = 0.04 * (w - 2.0 * margin);
        for (p, n) in result.iter().zip(ns).step_by(step) {
            let a = map(p.truncate());
            let b = a + len * DVec2::new(n.x, -n.y);
            let _ = writeln!(
                s,
                r##"<line x1="{:.3}" y1="{:.3}" x2="{:.3}" y2="{:.3}" stroke="#d33" stroke-width="1"/>"##,
                a.x, a.y, b.x, b.y
            );
        }
    }
    s.push_str("</svg>\n");
    s
}
