//! `cargo xtask conformance`: subd's uniform refinement against OpenSubdiv's, level by level,
//! on every shape of `../shared/meshes/osd` and on random meshes, then the other checks of
//! [`MESH_CHECKS`] on each of them.

mod adaptive;
mod edit;
mod eval;
pub mod fvar;
pub mod geom;
mod limit;
pub mod patch_fvar;
pub mod patches;
mod pia;
mod refine;
pub mod row;
pub mod tess;
pub mod usd;

use std::path::{Path, PathBuf};

use subd_mesh::{DVec3, Topology};
use subd_schemes::{Options, Scheme};

use rayon::prelude::*;

pub use crate::conformance::row::Row;
use crate::oracles::osd;

/// Tolerance on max |Δ| / bounding-box diagonal.
pub(crate) const TOLERANCE: f64 = 1e-12;
/// Levels are capped where the mesh would pass this many vertices.
const MAX_VERTICES: usize = 2_000_000;
/// Limit checks refine at most this many face-vertices deep.
pub(crate) const MAX_LIMIT_FACE_VERTICES: usize = 8_000_000;

/// Levels to check: up to 3, fewer where the mesh would grow past [`MAX_VERTICES`].
pub(crate) fn levels_for(topo: &Topology, scheme: &Scheme) -> usize {
    let mut faces = topo.num_face_vertices() as f64;
    let mut levels = 0;
    while levels < 3 {
        // Each level multiplies face-vertices by ~4; vertices are about face-vertices / 4·2.
        faces *= 4.0;
        let est_vertices = match scheme {
            Scheme::Loop => faces / 6.0,
            _ => faces / 4.0,
        };
        if est_vertices > MAX_VERTICES as f64 {
            break;
        }
        levels += 1;
    }
    levels.max(1)
}

/// One mesh as every check of [`MESH_CHECKS`] sees it.
pub struct Case<'a> {
    /// The OpenSubdiv harness.
    pub exe: &'a Path,
    pub name: &'a str,
    pub topo: &'a Topology,
    pub positions: &'a [DVec3],
    pub scheme: &'a Scheme,
    pub options: &'a Options,
    /// The bounding-box diagonal, which errors are divided by.
    pub diag: f64,
    /// OpenSubdiv's uniform levels and subd's refinement as deep, made once: the refine
    /// check compares them, the adaptive check looks its vertices up in OpenSubdiv's.
    pub uniform: refine::Uniform,
}

/// One check of a mesh against OpenSubdiv: what it samples, what subd computes there and
/// what that is compared with, for which schemes, and how it runs.
pub struct Check {
    /// The row's check name.
    pub name: &'static str,
    /// Which points are compared.
    pub samples: &'static str,
    /// What subd computes at them.
    pub computes: &'static str,
    /// What that is compared with: the OpenSubdiv call and the tolerance.
    pub compares: &'static str,
    /// Whether the check runs on a mesh of this scheme.
    pub applies: fn(&Scheme) -> bool,
    /// The check's rows for one mesh (refine: one per level; the others one).
    pub run: fn(&Case) -> Vec<Row>,
}

/// Uniform refinement is checked on every scheme.
fn every_scheme(_: &Scheme) -> bool {
    true
}

/// Bilinear has no limit surface: only its refinement is checked.
fn not_bilinear(scheme: &Scheme) -> bool {
    *scheme != Scheme::Bilinear
}

/// The energy method is checked on Catmull-Clark meshes only.
fn catmull_clark(scheme: &Scheme) -> bool {
    *scheme == Scheme::CatmullClark
}

/// The checks [`compare`] runs on every mesh, in the order of its rows.
pub const MESH_CHECKS: &[Check] = &[
    Check {
        name: "refine",
        samples: "every vertex of uniform levels 1..3 (fewer on large meshes)",
        computes: "Refinement::refine_points",
        compares: "OpenSubdiv's RefineUniform + Interpolate: same topology, positions to 1e-12 of the diagonal",
        applies: every_scheme,
        run: refine::compare,
    },
    Check {
        name: "adaptv",
        samples: "every output vertex of adaptive refinement of random 40 % face selections (2 seeds)",
        computes: "AdaptiveRefinement::mesh (refined positions) and its closure invariants",
        compares: "OpenSubdiv's uniform vertex at the same level and index, to 1e-12 of the diagonal",
        applies: not_bilinear,
        run: |case| vec![adaptive::compare(case)],
    },
    Check {
        name: "limit",
        samples: "every vertex of level N (semi-sharp features decayed, at least 1)",
        computes: "LimitStencilTable: limit positions, tangents, unit normals",
        compares: "OpenSubdiv's PrimvarRefiner::Limit, to 1e-12 of the diagonal (normals 1e-10); inexact vertices left out",
        applies: not_bilinear,
        run: |case| vec![limit::compare(case)],
    },
    Check {
        name: "eval",
        samples: "14 (u, v) per ptex face: spread over it, on its edges, near its corners",
        computes: "PatchTable::exact_limit evaluation: position and normal",
        compares: "OpenSubdiv's patch table at isolation 10, to 1e-12 of the diagonal (normals 1e-9, scaled); inside the 2^-10 Gregory-cap squares reported only",
        applies: not_bilinear,
        run: |case| vec![eval::compare(case)],
    },
    Check {
        name: "tessellate",
        samples: "every sample of a uniform tessellation at rate 4",
        computes: "tessellate_mesh (what `subd tessellate` runs)",
        compares: "OpenSubdiv's Bfr::Tessellation sample positions, to 1e-12 of the diagonal; closed inputs stay closed",
        applies: not_bilinear,
        run: |case| {
            vec![tess::compare(
                case.exe,
                case.name,
                case.topo,
                case.positions,
                case.scheme,
                case.options,
                case.diag,
            )]
        },
    },
    Check {
        name: "pia",
        samples: "the moving vertices (every third vertex fixed)",
        computes: "Pia::solve: control points whose limits interpolate the targets",
        compares: "OpenSubdiv's PrimvarRefiner::Limit of the result, to 1e-9 of the diagonal",
        applies: not_bilinear,
        run: |case| vec![pia::compare(case)],
    },
    Check {
        name: "edit",
        samples: "up to 4 vertex point constraints and (Catmull-Clark) 1 normal constraint",
        computes: "Editor::solve, least squares",
        compares: "OpenSubdiv's PrimvarRefiner::Limit of the edited mesh meets them to 1e-9 of the diagonal",
        applies: not_bilinear,
        run: |case| vec![edit::compare(case, edit::EditCheck::LeastSquares)],
    },
    Check {
        name: "edit-e",
        samples: "up to 4 vertex point constraints and 1 normal constraint",
        computes: "Editor::solve, energy method (2 rings)",
        compares: "OpenSubdiv's PrimvarRefiner::Limit of the edited mesh meets them to 1e-9 of the diagonal",
        applies: catmull_clark,
        run: |case| vec![edit::compare(case, edit::EditCheck::Energy)],
    },
];

/// [`MESH_CHECKS`] as aligned text, one line per check (name | samples | computes |
/// compares), for `cargo xtask conformance --list`.
pub fn describe() -> String {
    let header = ["check", "samples", "subd computes", "compared with"];
    let lines: Vec<[&str; 4]> = std::iter::once(header)
        .chain(
            MESH_CHECKS
                .iter()
                .map(|c| [c.name, c.samples, c.computes, c.compares]),
        )
        .collect();
    let width = |k: usize| {
        lines
            .iter()
            .map(|l| l[k].chars().count())
            .max()
            .unwrap_or(0)
    };
    let widths = [width(0), width(1), width(2)];
    let mut out = String::new();
    for l in &lines {
        let line = format!(
            "{:<w0$} | {:<w1$} | {:<w2$} | {}",
            l[0],
            l[1],
            l[2],
            l[3],
            w0 = widths[0],
            w1 = widths[1],
            w2 = widths[2],
        );
        out.push_str(&line);
        out.push('\n');
    }
    out
}

/// Compares subd and OpenSubdiv on one mesh: one row per level of uniform refinement, then
/// one row for each other check of [`MESH_CHECKS`] that applies to its scheme. Where either
/// side fails to refine uniformly, that failure is the mesh's only row.
pub fn compare(
    exe: &Path,
    name: &str,
    topo: &Topology,
    positions: &[DVec3],
    scheme: &Scheme,
    options: &Options,
) -> Vec<Row> {
    let uniform = match refine::Uniform::new(exe, topo, positions, scheme, options) {
        Ok(u) => u,
        Err(problem) => {
            return vec![Row {
                problem: Some(problem),
                ..Row::pending(name, "refine", 0)
            }];
        }
    };
    let (lo, hi) = subd_mesh::bounding_box(positions.iter().copied()).unwrap_or_default();
    let case = Case {
        exe,
        name,
        topo,
        positions,
        scheme,
        options,
        diag: (hi - lo).length().max(f64::MIN_POSITIVE),
        uniform,
    };
    MESH_CHECKS
        .iter()
        .filter(|c| (c.applies)(scheme))
        .flat_map(|c| (c.run)(&case))
        .collect()
}

/// OpenSubdiv's `Limit` of an encoded mesh, with tangents when asked and OpenSubdiv computes
/// them (its tangent masks overflow and crash on some meshes: then positions only), and
/// whether the tangents came. Used by the limit and edit checks.
pub(crate) fn osd_limit(
    exe: &Path,
    input: &[u8],
    tangents: bool,
) -> Result<(osd::OsdLimit, bool), String> {
    if tangents
        && let Ok(l) = osd::run(exe, input, &["--limit"]).and_then(|b| osd::decode_limit(&b))
    {
        return Ok((l, true));
    }
    osd::run(exe, input, &["--limit-positions"])
        .and_then(|b| osd::decode_limit(&b))
        .map(|l| (l, false))
}

pub(crate) fn scheme_of(name: &str) -> Option<Scheme> {
    if name.starts_with("catmark_") {
        Some(Scheme::CatmullClark)
    } else if name.starts_with("loop_") {
        Some(Scheme::Loop)
    } else if name.starts_with("bilinear_") {
        Some(Scheme::Bilinear)
    } else {
        None
    }
}

/// The OBJ shapes of a directory, sorted.
pub(crate) fn shape_paths(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "obj"))
        .collect();
    paths.sort();
    Ok(paths)
}

/// `compare` run on every shape of the OpenSubdiv directory whose scheme `wanted` takes,
/// in parallel (each mostly waits on its own harness process); the rows keep the shapes'
/// order.
pub(crate) fn per_shape(
    dir: &Path,
    wanted: impl Fn(&Scheme) -> bool + Sync,
    compare: impl Fn(&str, &subd_mesh::Mesh, &Scheme, &Options) -> Vec<Row> + Sync,
) -> Result<Vec<Row>, String> {
    let paths = shape_paths(dir)?;
    let opts = subd_io::ReadOptions {
        accept_inconsistent_orientation: true,
        ..Default::default()
    };
    let per_shape = paths
        .par_iter()
        .map(|p| -> Result<Vec<Row>, String> {
            let name = p.file_stem().unwrap().to_string_lossy().to_string();
            let Some(scheme) = scheme_of(&name).filter(|s| wanted(s)) else {
                return Ok(Vec::new());
            };
            let file = subd_io::read_mesh(p, &opts).map_err(|e| e.to_string())?;
            let options = Options::from_hints(&file.mesh.hints);
            Ok(compare(&name, &file.mesh, &scheme, &options))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(per_shape.into_iter().flatten().collect())
}

/// Every shape of the OpenSubdiv directory.
pub fn shapes(exe: &Path, dir: &Path) -> Result<Vec<Row>, String> {
    per_shape(
        dir,
        |_| true,
        |name, mesh, scheme, options| {
            compare(exe, name, &mesh.topology, &mesh.positions, scheme, options)
        },
    )
}

/// `count` random meshes (see `random_mesh`), in parallel, rows in seed order.
pub fn random(exe: &Path, count: u64) -> Vec<Row> {
    (0..count)
        .into_par_iter()
        .flat_map_iter(|seed| {
            let c = crate::meshes::random::case(seed);
            compare(
                exe,
                &c.name,
                &c.topology,
                &c.positions,
                &c.scheme,
                &c.options,
            )
        })
        .collect()
}

/// Prints the table and returns whether every row passed.
pub fn report(rows: &[Row]) -> bool {
    println!(
        "{:<36} {:<18} {:>5} {:>9} {:>12} {:>10}  status",
        "mesh", "check", "level", "vertices", "max|Δ|/diag", "normal Δ"
    );
    let mut ok = true;
    for r in rows {
        let pass = r.problem.is_none();
        ok &= pass;
        let normal = r
            .normal_error
            .map_or_else(|| "-".to_string(), |e| format!("{e:.3e}"));
        let excluded = r.excluded.map_or_else(String::new, |(n, e)| {
            if r.check == "tessellate" {
                format!(" ({n} points left out: Bfr's Gregory-cap corners off the exact limit, or faces subd does not evaluate; there |Δ|/diag ≤ {e:.1e})")
            } else if r.check.starts_with("fvar-limit") {
                format!(" ({n} values where OpenSubdiv is inexact checked apart: seam creases to 1e-7 (its float weights), Bilinear seam values kept, eigen-limit vertices; there |Δ|/diag ≤ {e:.1e})")
            } else if r.check == "patches" {
                format!(" ({n} points checked apart: in Loop box-spline end caps, held to 1e-5 as OpenSubdiv fits them with float constants off the exact fit by up to 2.6e-5, at valence-2 darts, or where OpenSubdiv's adaptive refinement leaves its uniform one; there |Δ|/diag ≤ {e:.1e})")
            } else if r.check.starts_with("patch fvar") {
                format!(" ({n} points compared apart: where OpenSubdiv's adaptive refinement leaves its uniform one (subd's patch values are uniform refinement's, OpenSubdiv's are not); there |Δ|/diag ≤ {e:.1e})")
            } else if r.check == "eval" {
                format!(" ({n} points not on the surface (holes) or not covered left out; in the 2^-10 end-cap squares |Δ|/diag ≤ {e:.1e})")
            } else {
                format!(" ({n} vertices where OpenSubdiv is inexact left out; there |Δ|/diag ≤ {e:.1e})")
            }
        });
        let note = r
            .note
            .as_deref()
            .map_or_else(String::new, |n| format!("; {n}"));
        println!(
            "{:<36} {:<18} {:>5} {:>9} {:>12.3e} {:>10}  {}{}{}",
            r.mesh,
            r.check,
            r.level,
            r.vertices,
            r.error,
            normal,
            r.problem.as_deref().unwrap_or("ok"),
            excluded,
            note
        );
    }
    let failed = rows.iter().filter(|r| r.problem.is_some()).count();
    println!("{} passed, {} failed", rows.len() - failed, failed);
    ok
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn describe_aligns_one_line_per_check() {
        let text = describe();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), MESH_CHECKS.len() + 1);
        // Every line has its three separators at the same columns.
        let columns = |l: &str| -> Vec<usize> {
            let chars: Vec<char> = l.chars().collect();
            (0..chars.len().saturating_sub(2))
                .filter(|&i| chars[i..i + 3] == [' ', '|', ' '])
                .take(3)
                .collect()
        };
        let first = columns(lines[0]);
        assert_eq!(first.len(), 3);
        for l in &lines {
            assert_eq!(columns(l), first, "{l}");
        }
        for (l, c) in lines[1..].iter().zip(MESH_CHECKS) {
            assert!(l.starts_with(c.name), "{l}");
        }
    }
}
