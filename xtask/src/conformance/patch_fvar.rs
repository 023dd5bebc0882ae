//! `cargo xtask conformance`, face-varying patches: the texture coordinates of every shape
//! that has them, refined through the patch table's sparse levels in each of the six
//! `FVarLinearInterpolation` modes and evaluated on each patch's face-varying patch, against
//! OpenSubdiv's `PatchTableFactory` with `generateFVarTables` (its default linear patches)
//! and `EvaluateBasisFaceVarying`.

use std::path::Path;

use rayon::prelude::*;

use subd_limit::patches::{EndCaps, PatchOptions, PatchTable};
use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};
use subd_mesh::{DVec3, Topology};
use subd_schemes::{Options, Scheme};

use crate::conformance::fvar::{random_channel, uv_diagonal};
use crate::conformance::patches::{decode, eval_points, harness_args, option_label};
use crate::conformance::row::Row;
use crate::meshes::random::Rng;
use crate::oracles::osd;

/// The option sets each channel is checked under: a shallow table with Gregory end caps
/// and OpenSubdiv's default flags, and a deep one with B-spline end caps and every feature
/// patch.
fn option_sets() -> [PatchOptions; 2] {
    [
        PatchOptions {
            isolation: 2,
            ..PatchOptions::default()
        },
        PatchOptions {
            isolation: 6,
            end_caps: EndCaps::BSpline,
            single_crease: true,
            inf_sharp: true,
            legacy_sharp_corners: false,
        },
    ]
}

fn check_name(mode: FVarLinearInterpolation) -> &'static str {
    match mode {
        FVarLinearInterpolation::None => "patch fvar none",
        FVarLinearInterpolation::CornersOnly => "patch fvar c-only",
        FVarLinearInterpolation::CornersPlus1 => "patch fvar c-plus1",
        FVarLinearInterpolation::CornersPlus2 => "patch fvar c-plus2",
        FVarLinearInterpolation::Boundaries => "patch fvar bounds",
        FVarLinearInterpolation::All => "patch fvar all",
    }
}

/// One mesh's channel in the modes `modes` under every option set: one row each.
#[allow(clippy::too_many_arguments)]
pub fn compare_channel(
    exe: &Path,
    name: &str,
    topo: &Topology,
    positions: &[DVec3],
    scheme: &Scheme,
    options: &Options,
    channel: &FVarChannel,
    modes: &[FVarLinearInterpolation],
) -> Vec<Row> {
    let diag = uv_diagonal(channel.values());
    let mut rows = Vec::new();
    for &mode in modes {
        for (k, po) in option_sets().iter().enumerate() {
            let mut row = Row::pending(name, check_name(mode), po.isolation as usize);
            let input = Input {
                exe,
                topo,
                positions,
                scheme,
                options,
                channel,
            };
            match compare_one(&input, po, mode, k as u64) {
                Ok(c) => {
                    row.vertices = c.points;
                    row.error = c.strict / diag;
                    row.note = Some(format!("{}; {} points", option_label(po), c.points));
                    if c.departed.0 > 0 {
                        row.excluded = Some((c.departed.0, c.departed.1 / diag));
                    }
                    if row.error.is_nan() || row.error > 1e-12 {
                        row.problem =
                            Some(format!("{}: off by {:.3e}", option_label(po), row.error));
                    }
                }
                Err(e) => row.problem = Some(format!("{}: {e}", option_label(po))),
            }
            rows.push(row);
        }
    }
    rows
}

/// What one comparison reads.
struct Input<'a> {
    exe: &'a Path,
    topo: &'a Topology,
    positions: &'a [DVec3],
    scheme: &'a Scheme,
    options: &'a Options,
    channel: &'a FVarChannel,
}

/// The largest difference of value and first derivatives (in the patch's own parameters,
/// OpenSubdiv's derivative convention in non-quad faces undone) over the evaluation points,
/// and the number of points.
fn compare_one(
    input: &Input<'_>,
    po: &PatchOptions,
    mode: FVarLinearInterpolation,
    seed: u64,
) -> Result<Compared, String> {
    let Input {
        exe,
        topo,
        positions,
        scheme,
        options,
        channel,
    } = *input;
    let mut table =
        PatchTable::new(topo, positions, scheme, options, po).map_err(|e| e.to_string())?;
    let fvc = table
        .add_face_varying(channel, mode)
        .map_err(|e| e.to_string())?;
    let points = eval_points(&table, topo, scheme, seed);
    let harness_points: Vec<(u32, f64, f64)> = points
        .iter()
        .map(|(at, root)| (*root, at.u, at.v))
        .collect();
    let encoded = osd::encode(topo, positions, scheme, options, po.isolation.into());
    let encoded = osd::encode_fvar(encoded, channel.values(), channel.indices());
    let encoded = osd::encode_eval_points(encoded, &harness_points);
    let mut args = harness_args(po);
    args.push(mode.to_shape_tag().to_string());
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let osd = decode(&osd::run(exe, &encoded, &args)?, points.len())?;
    if osd.fvar.len() != points.len() {
        return Err("OpenSubdiv wrote no face-varying evaluations".into());
    }
    let tol = 1e-12 * uv_diagonal(channel.values());
    let mut uniform = Uniform::new(input, mode);
    let mut out = Compared {
        points: points.len(),
        strict: 0.0,
        departed: (0, 0.0),
    };
    let mut worst_patch = (0, 0);
    for ((at, _), theirs) in points.iter().zip(&osd.fvar) {
        let (a, i) = table.find(at).map_err(|e| e.to_string())?;
        let param = table.arrays()[a].params()[i];
        let d1 = if param.place().non_quad { 0.5 } else { 1.0 };
        let frac = param.fraction();
        let mine = table
            .evaluate_face_varying(fvc, *at)
            .map_err(|e| e.to_string())?;
        let t = &theirs.eval;
        let mut error = 0.0f64;
        for c in 0..2 {
            error = error
                .max((mine.value[c] - t[c]).abs())
                .max((mine.du[c] - t[2 + c] * d1).abs() * frac)
                .max((mine.dv[c] - t[4 + c] * d1).abs() * frac);
        }
        if error.is_nan() || error > tol {
            let depth = param.place().depth as usize;
            let fvar = &table.face_varying()[fvc];
            let ours = fvar.patch_values(a, i).iter().map(|&v| {
                let x = &fvar.values()[2 * v as usize..2 * v as usize + 2];
                [x[0], x[1]]
            });
            let ours_uniform = uniform.holds(depth, ours, tol);
            let theirs_uniform = uniform.holds(depth, theirs.patch_values.iter().copied(), tol);
            if ours_uniform && !theirs_uniform {
                out.departed.0 += 1;
                out.departed.1 = out.departed.1.max(error);
                continue;
            }
        }
        if !out.strict.is_nan() && (error.is_nan() || error > out.strict) {
            out.strict = error;
            worst_patch = (a, i);
        }
    }
    if out.strict.is_nan() || out.strict > tol {
        let diag = uv_diagonal(channel.values());
        return Err(format!(
            "off by {:.3e} of the UV layout; at the worst point {}",
            out.strict / diag,
            diagnose(&table, fvc, worst_patch, &mut uniform, tol)
        ));
    }
    Ok(out)
}

/// Whether the sparse levels or the patch are at fault where a row fails: how many of the
/// values of patch `(a, i)` are not values of subd's uniform refinement at its depth.
fn diagnose(
    table: &PatchTable,
    fvc: usize,
    (a, i): (usize, usize),
    uniform: &mut Uniform<'_>,
    tol: f64,
) -> String {
    let depth = table.arrays()[a].params()[i].place().depth as usize;
    let fvar = &table.face_varying()[fvc];
    let n = fvar.values_per_patch();
    let foreign = fvar
        .patch_values(a, i)
        .iter()
        .filter(|&&v| {
            let x = &fvar.values()[2 * v as usize..2 * v as usize + 2];
            !uniform.holds(depth, std::iter::once([x[0], x[1]]), tol)
        })
        .count();
    format!("{foreign} of the patch's {n} values are not uniform level-{depth} values")
}

/// One comparison's outcome: points, the largest difference, and the points (with their
/// largest difference) where OpenSubdiv's adaptive refinement leaves its own uniform one:
/// the values of subd's patch are values of uniform refinement at the patch's depth,
/// OpenSubdiv's are not.
struct Compared {
    points: usize,
    strict: f64,
    departed: (usize, f64),
}

/// subd's uniform refinement of the channel, level by level as asked for (the `fvar` rows
/// hold it equal to OpenSubdiv's uniform refinement).
struct Uniform<'a> {
    input: &'a Input<'a>,
    mode: FVarLinearInterpolation,
    levels: std::collections::HashMap<usize, Option<Vec<f64>>>,
}

impl<'a> Uniform<'a> {
    fn new(input: &'a Input<'a>, mode: FVarLinearInterpolation) -> Uniform<'a> {
        Uniform {
            input,
            mode,
            levels: std::collections::HashMap::new(),
        }
    }

    /// Whether every value of `values` is within `tol` of a value of uniform level `depth`.
    fn holds(&mut self, depth: usize, values: impl Iterator<Item = [f64; 2]>, tol: f64) -> bool {
        let (input, mode) = (self.input, self.mode);
        let level = self.levels.entry(depth).or_insert_with(|| {
            let r = subd_schemes::Refinement::new(
                input.topo,
                input.scheme.clone(),
                input.options,
                depth,
            )
            .ok()?;
            let fr = subd_schemes::FaceVaryingRefinement::new(&r, input.channel, mode).ok()?;
            Some(
                fr.refine_values(&r, input.channel.values(), 2)
                    .swap_remove(depth),
            )
        });
        let Some(level) = level else {
            return false;
        };
        values.into_iter().all(|x| {
            level
                .chunks_exact(2)
                .any(|y| (y[0] - x[0]).abs().max((y[1] - x[1]).abs()) <= tol)
        })
    }
}

/// Every Catmull-Clark and Loop shape with texture coordinates.
pub fn shapes(exe: &Path, dir: &Path) -> Result<Vec<Row>, String> {
    crate::conformance::per_shape(
        dir,
        |s| matches!(s, Scheme::CatmullClark | Scheme::Loop),
        |name, mesh, scheme, options| match mesh.uv() {
            Some(uv) => compare_channel(
                exe,
                name,
                &mesh.topology,
                &mesh.positions,
                scheme,
                options,
                uv,
                &FVarLinearInterpolation::ALL_MODES,
            ),
            None => Vec::new(),
        },
    )
}

/// The Catmull-Clark and Loop meshes among `count` random meshes, each with a random UV
/// layout (islands, seams, unused values) in one random mode.
pub fn random(exe: &Path, count: u64) -> Vec<Row> {
    (0..count)
        .into_par_iter()
        .flat_map_iter(|seed| {
            let c = crate::meshes::random::case(seed);
            if !matches!(c.scheme, Scheme::CatmullClark | Scheme::Loop) {
                return Vec::new();
            }
            // The face-varying checks' own stream for this seed, so each mesh has the layout
            // and mode it has there.
            let mut rng = Rng(seed.wrapping_mul(0xD1B5_4A32_D192_ED03) | 1);
            let channel = random_channel(&mut rng, &c.topology);
            let mode = FVarLinearInterpolation::ALL_MODES[rng.below(6) as usize];
            compare_channel(
                exe,
                &c.name,
                &c.topology,
                &c.positions,
                &c.scheme,
                &c.options,
                &channel,
                &[mode],
            )
        })
        .collect()
}
