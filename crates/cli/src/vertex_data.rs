//! Per-vertex inputs given on the command line or in text files: the two-phase scheme's
//! `λ` (`--lambda`, `--lambda-file`) and index lists (`--moving`, `--fixed`, `--select-faces`,
//! `--select-vertices`).
//!
//! Files are whitespace-separated numbers; `#` starts a comment. Errors name the file and
//! the line.

use std::path::{Path, PathBuf};

use clap::Args;
use subd_schemes::TwoPhase;
use subd_schemes::two_phase::{LAMBDA_MAX, LAMBDA_MIN};

use crate::Failure;
use crate::failure::bad;

/// The two-phase scheme's shape parameter.
#[derive(Debug, Clone, Args)]
pub(crate) struct LambdaArgs {
    /// Two-phase scheme: the same λ for every vertex, in (7/20, 1].
    #[arg(long, conflicts_with = "lambda_file")]
    lambda: Option<f64>,
    /// Two-phase scheme: one λ per vertex, in vertex order (whitespace-separated, `#`
    /// comments).
    #[arg(long, value_name = "FILE")]
    lambda_file: Option<PathBuf>,
    /// Accept any finite λ (convergence of interpolation is proven for (7/20, 1] only).
    #[arg(long)]
    allow_any_lambda: bool,
}

impl LambdaArgs {
    /// Whether `--lambda` or `--lambda-file` was given.
    pub(crate) fn given(&self) -> bool {
        self.lambda.is_some() || self.lambda_file.is_some()
    }

    /// The shape parameters for a mesh of `num_vertices` vertices read from `input`.
    pub(crate) fn two_phase(&self, input: &Path, num_vertices: usize) -> Result<TwoPhase, Failure> {
        let (values, source) = match (&self.lambda, &self.lambda_file) {
            (Some(l), _) => (vec![*l; num_vertices], None),
            (None, Some(f)) => (read_lambda_file(f, num_vertices)?, Some(f)),
            (None, None) => {
                return Err(bad(format!(
                    "{}: the two-phase scheme needs --lambda or --lambda-file",
                    input.display()
                )));
            }
        };
        let checked = if self.allow_any_lambda {
            TwoPhase::with_any_lambda(values)
        } else {
            TwoPhase::new(values)
        };
        checked.map_err(|e| {
            let hint = if self.allow_any_lambda {
                ""
            } else {
                " (use --allow-any-lambda to accept it)"
            };
            match source {
                Some(f) => bad(format!("{}: {e}{hint}", f.display())),
                None => bad(format!("--lambda: {e}{hint}")),
            }
        })
    }
}

/// Whitespace-separated numbers of `path` with the line each came from.
fn numbers(path: &Path) -> Result<Vec<(usize, String)>, Failure> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| bad(format!("{}: cannot read: {e}", path.display())))?;
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let body = line.split('#').next().unwrap_or("");
        out.extend(body.split_whitespace().map(|t| (i + 1, t.to_string())));
    }
    Ok(out)
}

fn read_lambda_file(path: &Path, num_vertices: usize) -> Result<Vec<f64>, Failure> {
    let tokens = numbers(path)?;
    let mut values = Vec::with_capacity(tokens.len());
    for (line, tok) in &tokens {
        let x: f64 = tok.parse().map_err(|_| {
            bad(format!(
                "{}:{line}: {tok:?} is not a number",
                path.display()
            ))
        })?;
        if !x.is_finite() {
            return Err(bad(format!(
                "{}:{line}: lambda {tok} is not finite",
                path.display()
            )));
        }
        values.push(x);
    }
    if values.len() != num_vertices {
        return Err(bad(format!(
            "{}: {} lambda values for {num_vertices} vertices (one per vertex, in (7/20, 1] = ({LAMBDA_MIN}, {LAMBDA_MAX}])",
            path.display(),
            values.len()
        )));
    }
    Ok(values)
}

/// A file of 0-based indices of `what` (`vertex` or `face`), each below `count`.
pub(crate) fn read_indices(path: &Path, count: usize, what: &str) -> Result<Vec<u32>, Failure> {
    let tokens = numbers(path)?;
    let mut out = Vec::with_capacity(tokens.len());
    for (line, tok) in &tokens {
        let v: u64 = tok.parse().map_err(|_| {
            bad(format!(
                "{}:{line}: {tok:?} is not a {what} index (a non-negative integer)",
                path.display()
            ))
        })?;
        if v >= count as u64 {
            let plural = if what == "vertex" {
                "vertices"
            } else {
                "faces"
            };
            return Err(bad(format!(
                "{}:{line}: {what} {v} does not exist (the mesh has {count} {plural})",
                path.display()
            )));
        }
        out.push(v as u32);
    }
    Ok(out)
}
