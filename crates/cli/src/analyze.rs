//! `subd analyze`: convergence and smoothness of a univariate mask (Laurent polynomials), or
//! the eigenvalue test of a surface scheme at a valence.

use std::io::Write;

use clap::Args;
use subd_limit::spectrum::{
    RingSpectrum, SplitSpectrumReport, SurfaceSpectrum, VALENCES, surface_spectrum,
};
use subd_schemes::analysis::{AnalysisError, LEVEL_RANGE, Lattice, analyze_mask, analyze_mask2};
use subd_schemes::{Capability, Scheme};

use crate::Failure;
use crate::choice_arg;
use crate::failure::bad;
use crate::scheme_arg;

#[derive(Debug, Args)]
pub(crate) struct AnalyzeArgs {
    /// Mask coefficients a_j, comma-separated, in order of increasing power of z (the
    /// weights of one old point in the new ones; they sum to the arity).
    #[arg(
        long,
        allow_hyphen_values = true,
        required_unless_present_any = ["surface", "mask2"],
        conflicts_with_all = ["surface", "mask2"]
    )]
    mask: Option<String>,
    /// A bivariate binary mask: rows separated by `;` (row j holds the coefficients of
    /// z1^i z2^j for i = 0, 1, …), the four residue classes each summing to 1.
    #[arg(long, allow_hyphen_values = true, conflicts_with = "surface")]
    mask2: Option<String>,
    /// Lattice of --mask2.
    #[arg(long, default_value = "quad", value_parser = choice_arg::parser::<Lattice>())]
    lattice: Lattice,
    /// Arity of the mask: 2 (binary) or 3 (ternary).
    #[arg(long, default_value_t = 2)]
    arity: usize,
    /// Most levels L of the difference scheme to try.
    #[arg(long, default_value_t = 8)]
    max_levels: usize,
    /// Instead of a mask: the eigenvalue test of this surface scheme's local subdivision
    /// matrix at an interior vertex of valence --valence.
    #[arg(long, value_parser = scheme_arg::parser(Capability::Analyse), requires = "valence")]
    surface: Option<Scheme>,
    /// Valence for --surface (the number of sides of the centre face for doo-sabin).
    #[arg(long)]
    valence: Option<usize>,
    /// Tension w of --surface butterfly (default 1/16).
    #[arg(long, allow_hyphen_values = true, requires = "surface")]
    tension: Option<f64>,
    /// Print a JSON report on stdout.
    #[arg(long)]
    json: bool,
}

pub(crate) fn run(args: &AnalyzeArgs, out: &mut dyn Write) -> Result<(), Failure> {
    let surface = match &args.surface {
        Some(s) => Some(scheme_arg::with_tension(s, args.tension, "--surface")?),
        None => None,
    };
    if let (Some(scheme), Some(n)) = (surface, args.valence) {
        return run_surface(&scheme, n, args.json, out);
    }
    if let Some(text) = &args.mask2 {
        return run_bivariate(text, args, out);
    }
    let text = args.mask.as_deref().unwrap_or_default();
    let coeffs: Vec<f64> = text
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .enumerate()
        .map(|(i, t)| {
            parse_number(t).filter(|x| x.is_finite()).ok_or_else(|| {
                bad(format!(
                    "--mask: coefficient {i} ({t:?}) is not a finite number"
                ))
            })
        })
        .collect::<Result<_, _>>()?;
    let v = analyze_mask(&coeffs, args.arity, args.max_levels).map_err(|e| refusal("--mask", e))?;
    if args.json {
        crate::print_json(out, &v);
        return Ok(());
    }
    let mut s = String::new();
    use std::fmt::Write as _;
    let _ = writeln!(
        s,
        "converges: {}",
        if v.converges { "yes" } else { "not shown" }
    );
    match v.smoothness {
        Some(k) => {
            let _ = writeln!(s, "smoothness: C^{k} shown");
        }
        None => {
            let _ = writeln!(s, "smoothness: none shown");
        }
    }
    for (k, (norms, used)) in v.norms.iter().zip(&v.levels_used).enumerate() {
        let list: Vec<String> = norms.iter().map(|n| format!("{n:.6}")).collect();
        let _ = writeln!(
            s,
            "  derived mask of order {k}: ‖S_q^L‖∞ for L = 1.. = [{}]{}",
            list.join(", "),
            used.map_or_else(
                || " (never < 1)".to_string(),
                |l| format!(" (< 1 at L = {l})")
            )
        );
    }
    if !v.note.is_empty() {
        let _ = writeln!(s, "note: {}", v.note);
    }
    let _ = out.write_all(s.as_bytes());
    Ok(())
}

fn run_bivariate(text: &str, args: &AnalyzeArgs, out: &mut dyn Write) -> Result<(), Failure> {
    let rows: Vec<Vec<f64>> = text
        .split(';')
        .enumerate()
        .map(|(j, row)| {
            row.split(|c: char| c == ',' || c.is_whitespace())
                .filter(|t| !t.is_empty())
                .map(|t| {
                    parse_number(t).filter(|x| x.is_finite()).ok_or_else(|| {
                        bad(format!("--mask2: row {j}: {t:?} is not a finite number"))
                    })
                })
                .collect::<Result<Vec<f64>, _>>()
        })
        .collect::<Result<_, _>>()?;
    let v =
        analyze_mask2(&rows, args.lattice, args.max_levels).map_err(|e| refusal("--mask2", e))?;
    if args.json {
        crate::print_json(out, &v);
        return Ok(());
    }
    let _ = writeln!(
        out,
        "converges: {}\nsmoothness: {}",
        if v.converges { "yes" } else { "not shown" },
        v.smoothness
            .map_or_else(|| "none shown".to_string(), |k| format!("C^{k} shown"))
    );
    for (k, n) in v.norms.iter().enumerate() {
        let list: Vec<String> = n.iter().map(|x| format!("{x:.6}")).collect();
        let _ = writeln!(
            out,
            "  C^{k} test: max_k ‖S_q^L‖∞ for L = 1.. = [{}]",
            list.join(", ")
        );
    }
    if !v.note.is_empty() {
        let _ = writeln!(out, "note: {}", v.note);
    }
    Ok(())
}

/// A number, or a fraction `p/q`.
fn parse_number(t: &str) -> Option<f64> {
    match t.split_once('/') {
        Some((p, q)) => Some(p.trim().parse::<f64>().ok()? / q.trim().parse::<f64>().ok()?),
        None => t.parse().ok(),
    }
}

/// The eigenvalue test of `scheme` at an interior vertex of valence `n`
/// (`subd_limit::spectrum`).
fn run_surface(scheme: &Scheme, n: usize, json: bool, out: &mut dyn Write) -> Result<(), Failure> {
    let name = scheme.name();
    if !VALENCES.contains(&n) {
        return Err(bad(format!(
            "--valence {n}: must be {} to {}",
            VALENCES.start(),
            VALENCES.end()
        )));
    }
    let spectrum =
        surface_spectrum(scheme, n).map_err(|e| bad(format!("--surface {name}: {e}")))?;
    if json {
        crate::print_json(out, &spectrum);
        return Ok(());
    }
    let line = match &spectrum {
        SurfaceSpectrum::Ring(r) => ring_line(r),
        SurfaceSpectrum::Split(s) => split_line(s),
    };
    let _ = writeln!(out, "{line}");
    Ok(())
}

/// Catmull-Clark's or Loop's verdict, on one line.
fn ring_line(r: &RingSpectrum) -> String {
    let list: Vec<String> = r
        .eigenvalues
        .iter()
        .take(6)
        .map(|x| format!("{x:.6}"))
        .collect();
    format!(
        "{}, valence {}: |λ| = [{}{}]; λ1 = 1 > λ2 = λ3 > |λ4|: {}",
        r.scheme,
        r.valence,
        list.join(", "),
        if r.eigenvalues.len() > 6 { ", …" } else { "" },
        if r.passes { "yes" } else { "no" }
    )
}

/// A split scheme's verdict, on one line.
fn split_line(s: &SplitSpectrumReport) -> String {
    let list: Vec<String> = s
        .eigenvalues
        .iter()
        .take(6)
        .map(|e| format!("{:.6} (k={})", e.norm(), e.frequency))
        .collect();
    let n = s.valence;
    let centre = if s.scheme == Scheme::DooSabin.name() {
        format!("{n}-sided face")
    } else {
        format!("valence {n}")
    };
    format!(
        "{}, {centre}{}: |λ| = [{}{}]; C¹ eigenvalue test: {}",
        s.scheme,
        if s.steps == 2 { " (two steps)" } else { "" },
        list.join(", "),
        if s.eigenvalues.len() > 6 { ", …" } else { "" },
        match &s.test.reason {
            None => format!("yes (λ = {:.6}, frequency 1)", s.test.subdominant),
            Some(r) => format!("no: {r}"),
        }
    )
}

/// The library's refusal, named by the flag at fault.
fn refusal(mask: &str, e: AnalysisError) -> Failure {
    bad(match e {
        AnalysisError::Levels(n) => format!(
            "--max-levels {n}: must be {} to {}",
            LEVEL_RANGE.start(),
            LEVEL_RANGE.end()
        ),
        AnalysisError::Arity(n) => format!("--arity {n}: must be 2 or 3"),
        e => format!("{mask}: {e}"),
    })
}
