//! `cargo xtask conformance`, face-varying part: subd's `FaceVaryingRefinement` against
//! OpenSubdiv's `InterpolateFaceVarying` (double precision) on every shape with texture
//! coordinates, in all six `FVarLinearInterpolation` modes, and on random meshes with random
//! UV islands and modes.

use std::collections::HashMap;
use std::path::Path;

use subd_mesh::Topology;
use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};
use subd_schemes::{FaceVaryingRefinement, Options, Refinement, Scheme};

use rayon::prelude::*;

use crate::conformance::{Row, levels_for};
use crate::meshes::random::Rng;
use crate::oracles::osd;

/// Tolerance on max |Δ| / diagonal of the UV layout's bounding box.
const TOLERANCE: f64 = 1e-12;

fn check_name(mode: FVarLinearInterpolation) -> &'static str {
    match mode {
        FVarLinearInterpolation::None => "fvar none",
        FVarLinearInterpolation::CornersOnly => "fvar corners-only",
        FVarLinearInterpolation::CornersPlus1 => "fvar corners-plus1",
        FVarLinearInterpolation::CornersPlus2 => "fvar corners-plus2",
        FVarLinearInterpolation::Boundaries => "fvar boundaries",
        FVarLinearInterpolation::All => "fvar all",
    }
}

fn limit_check_name(mode: FVarLinearInterpolation) -> &'static str {
    match mode {
        FVarLinearInterpolation::None => "fvar-limit none",
        FVarLinearInterpolation::CornersOnly => "fvar-limit c-only",
        FVarLinearInterpolation::CornersPlus1 => "fvar-limit c-plus1",
        FVarLinearInterpolation::CornersPlus2 => "fvar-limit c-plus2",
        FVarLinearInterpolation::Boundaries => "fvar-limit bounds",
        FVarLinearInterpolation::All => "fvar-limit all",
    }
}

/// Where OpenSubdiv's `LimitFaceVarying` is off by more than round-off: its seam crease
/// weights are `float` (1/6 and 2/3 to about 3e-8).
const F32_SEAM_TOLERANCE: f64 = 1e-7;

/// subd's face-varying limits at the last level against OpenSubdiv's `LimitFaceVarying`.
/// Values where OpenSubdiv is not exact are left out of the 1e-12 comparison and reported:
/// seam creases (float weights: compared to 1e-7 instead), seam creases under Bilinear
/// (OpenSubdiv applies the crease mask although Bilinear refines every value linearly: subd
/// keeps the value, its refinement's limit), and values of vertices whose position limit
/// OpenSubdiv does not get exactly either (valence-2 interior vertices, darts on infinitely
/// sharp edges: subd takes the eigen limit).
#[allow(clippy::too_many_arguments)]
fn compare_limit(
    exe: &Path,
    input: &[u8],
    name: &str,
    refinement: &Refinement,
    fr: &FaceVaryingRefinement,
    last: &[f64],
    mode: FVarLinearInterpolation,
    diag: f64,
) -> Row {
    let levels = refinement.num_levels();
    let mut row = Row::pending(name, limit_check_name(mode), levels);
    let mode_arg = mode.to_shape_tag().to_string();
    let theirs = match osd::run(exe, input, &["--fvar-limit", &mode_arg])
        .and_then(|b| osd::decode_fvar_limit(&b))
    {
        Ok(v) => v,
        Err(e) => {
            row.problem = Some(format!("OpenSubdiv: {e}"));
            return row;
        }
    };
    let ours = match subd_limit::fvar::limit_values(refinement, fr, last, 2) {
        Ok(v) => v,
        Err(e) => {
            row.problem = Some(format!("subd: {e}"));
            return row;
        }
    };
    if ours.len() != theirs.len() {
        row.problem = Some(format!(
            "{} values, OpenSubdiv {}",
            ours.len() / 2,
            theirs.len() / 2
        ));
        return row;
    }
    let t = refinement.topology(levels);
    let values = fr.level_values(refinement, levels);
    let mut eigen = vec![false; t.num_vertices()];
    if *refinement.scheme() != Scheme::Bilinear {
        for v in subd_limit::eigen_limit_vertices(refinement, levels) {
            eigen[v] = true;
        }
    }
    let linear = values.is_linear();
    let (mut worst, mut at) = (0.0f64, 0usize);
    let (mut left_out, mut left_worst) = (0usize, 0.0f64);
    let mut f32_worst = 0.0f64;
    let mut r = 0usize;
    for (v, &at_eigen) in eigen.iter().enumerate() {
        for k in 0..values.num_vertex_values(v) {
            let d = (ours[2 * r] - theirs[2 * r])
                .abs()
                .max((ours[2 * r + 1] - theirs[2 * r + 1]).abs())
                / diag;
            let seam_crease = !linear && values.crease_ends(v, k).is_some();
            if seam_crease && *refinement.scheme() == Scheme::Bilinear {
                left_out += 1;
                left_worst = left_worst.max(d);
                // subd keeps the value: Bilinear's refinement never moves it.
                let i = values.vertex_value(v, k) as usize;
                let kept = (ours[2 * r] - last[2 * i])
                    .abs()
                    .max((ours[2 * r + 1] - last[2 * i + 1]).abs());
                if kept != 0.0 {
                    row.problem = Some(format!("Bilinear seam value {r} moved"));
                }
            } else if seam_crease {
                left_out += 1;
                left_worst = left_worst.max(d);
                f32_worst = f32_worst.max(d);
            } else if at_eigen && values.is_matching(v) {
                left_out += 1;
                left_worst = left_worst.max(d);
            } else if d > worst || d.is_nan() {
                worst = d;
                at = r;
            }
            r += 1;
        }
    }
    row.vertices = r;
    row.error = worst;
    if left_out > 0 {
        row.excluded = Some((left_out, left_worst));
    }
    if row.problem.is_none() {
        if worst.is_nan() || worst > TOLERANCE {
            row.problem = Some(format!("worst value {at}"));
        } else if f32_worst > F32_SEAM_TOLERANCE {
            row.problem = Some(format!(
                "seam crease values {f32_worst:.1e} from OpenSubdiv (float weights allow {F32_SEAM_TOLERANCE:.0e})"
            ));
        }
    }
    row
}

/// Diagonal of the bounding box of two-component values.
pub(crate) fn uv_diagonal(values: &[f64]) -> f64 {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for uv in values.chunks_exact(2) {
        for k in 0..2 {
            lo[k] = lo[k].min(uv[k]);
            hi[k] = hi[k].max(uv[k]);
        }
    }
    let d = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2)).sqrt();
    if d.is_finite() && d > 0.0 { d } else { 1.0 }
}

/// Compares one channel in one mode, level by level: the value at every face corner and the
/// number of values.
#[allow(clippy::too_many_arguments)]
pub fn compare(
    exe: &Path,
    name: &str,
    topo: &Topology,
    positions: &[subd_mesh::DVec3],
    scheme: &Scheme,
    options: &Options,
    channel: &FVarChannel,
    mode: FVarLinearInterpolation,
) -> Vec<Row> {
    let check = check_name(mode);
    let levels = levels_for(topo, scheme);
    let fail = |msg: String| Row {
        problem: Some(msg),
        ..Row::pending(name, check, 0)
    };
    let input = osd::encode_fvar(
        osd::encode(topo, positions, scheme, options, levels as u32),
        channel.values(),
        channel.indices(),
    );
    let mode_arg = mode.to_shape_tag().to_string();
    let theirs = match osd::run(exe, &input, &["--fvar", &mode_arg])
        .and_then(|b| osd::decode_fvar(&b, levels))
    {
        Ok(l) => l,
        Err(e) => return vec![fail(format!("OpenSubdiv: {e}"))],
    };
    let refinement = match Refinement::new(topo, scheme.clone(), options, levels) {
        Ok(r) => r,
        Err(e) => return vec![fail(format!("subd: {e}"))],
    };
    let fr = match FaceVaryingRefinement::new(&refinement, channel, mode) {
        Ok(r) => r,
        Err(e) => return vec![fail(format!("subd: {e}"))],
    };
    let ours = fr.refine_values(&refinement, channel.values(), 2);
    let diag = uv_diagonal(channel.values());
    let mut rows = Vec::new();
    for (l, o) in theirs.iter().enumerate() {
        let level = l + 1;
        let faces = fr.face_values(level);
        let mut row = Row::pending(name, check, level);
        row.vertices = fr.num_values(level);
        if fr.num_values(level) != o.values.len() / 2 {
            row.problem = Some(format!(
                "{} values, OpenSubdiv {}",
                fr.num_values(level),
                o.values.len() / 2
            ));
        } else if faces.len() != o.face_values.len() {
            row.problem = Some(format!(
                "{} face-vertices, OpenSubdiv {}",
                faces.len(),
                o.face_values.len()
            ));
        } else {
            let (mut worst, mut at) = (0.0f64, 0usize);
            for (k, (&a, &b)) in faces.iter().zip(&o.face_values).enumerate() {
                let (a, b) = (a as usize, b as usize);
                let d = (ours[level][2 * a] - o.values[2 * b])
                    .abs()
                    .max((ours[level][2 * a + 1] - o.values[2 * b + 1]).abs());
                if d > worst || d.is_nan() {
                    worst = d;
                    at = k;
                }
            }
            row.error = worst / diag;
            if row.error.is_nan() || row.error > TOLERANCE {
                row.problem = Some(format!("worst face-vertex {at}"));
            } else if faces != o.face_values {
                row.note = Some("same values, numbered differently".into());
            }
        }
        rows.push(row);
    }
    if levels >= 1 {
        rows.push(compare_limit(
            exe,
            &input,
            name,
            &refinement,
            &fr,
            &ours[levels],
            mode,
            diag,
        ));
    }
    rows
}

/// Every shape with texture coordinates, in every mode (shapes in parallel, rows in order).
pub fn shapes(exe: &Path, dir: &Path) -> Result<Vec<Row>, String> {
    let opts = subd_io::ReadOptions {
        accept_inconsistent_orientation: true,
        ..Default::default()
    };
    let paths = crate::conformance::shape_paths(dir)?;
    let per_shape = paths
        .par_iter()
        .map(|p| -> Result<Vec<Row>, String> {
            let name = p.file_stem().unwrap().to_string_lossy().to_string();
            let Some(scheme) = crate::conformance::scheme_of(&name) else {
                return Ok(Vec::new());
            };
            let file = subd_io::read_mesh(p, &opts).map_err(|e| e.to_string())?;
            let Some(uv) = file.mesh.uv() else {
                return Ok(Vec::new());
            };
            let options = Options::from_hints(&file.mesh.hints);
            Ok(FVarLinearInterpolation::ALL_MODES
                .iter()
                .flat_map(|&mode| {
                    compare(
                        exe,
                        &name,
                        &file.mesh.topology,
                        &file.mesh.positions,
                        &scheme,
                        &options,
                        uv,
                        mode,
                    )
                })
                .collect())
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(per_shape.into_iter().flatten().collect())
}

/// A random UV layout of `topo`: faces grouped into 1 to 4 islands grown from random seed
/// faces, a value per (vertex, island), sometimes an unused value; random numbers.
pub fn random_channel(rng: &mut Rng, topo: &Topology) -> FVarChannel {
    let nf = topo.num_faces();
    let islands = 1 + rng.below(4) as usize;
    let mut label = vec![usize::MAX; nf];
    let mut queue = std::collections::VecDeque::new();
    for i in 0..islands {
        let f = rng.below(nf as u64) as usize;
        if label[f] == usize::MAX {
            label[f] = i;
            queue.push_back(f);
        }
    }
    // Breadth-first growth over shared edges; faces never reached start islands of their own.
    let mut next_label = islands;
    for start in 0..nf {
        if label[start] == usize::MAX && queue.is_empty() {
            label[start] = next_label;
            next_label += 1;
            queue.push_back(start);
        }
        while let Some(f) = queue.pop_front() {
            for &e in topo.face_edges(f) {
                for &g in topo.edge_faces(e as usize) {
                    if label[g as usize] == usize::MAX {
                        label[g as usize] = label[f];
                        queue.push_back(g as usize);
                    }
                }
            }
        }
    }
    let mut index: HashMap<(u32, usize), u32> = HashMap::new();
    let mut indices = Vec::with_capacity(topo.num_face_vertices());
    for (f, &island) in label.iter().enumerate() {
        for &v in topo.face_vertices(f) {
            let n = index.len() as u32;
            indices.push(*index.entry((v, island)).or_insert(n));
        }
    }
    let count = index.len() + rng.below(2) as usize;
    let values = (0..2 * count)
        .map(|_| rng.below(1 << 20) as f64 / (1u64 << 20) as f64)
        .collect();
    FVarChannel::new(topo, 2, values, indices).expect("indices made for the topology")
}

/// `count` random meshes (`random_mesh::case`) with random UV islands and a random mode, in
/// parallel, rows in seed order.
pub fn random(exe: &Path, count: u64) -> Vec<Row> {
    (0..count)
        .into_par_iter()
        .flat_map_iter(|seed| {
            let c = crate::meshes::random::case(seed);
            let mut rng = Rng(seed.wrapping_mul(0xD1B5_4A32_D192_ED03) | 1);
            let channel = random_channel(&mut rng, &c.topology);
            let mode = FVarLinearInterpolation::ALL_MODES[rng.below(6) as usize];
            compare(
                exe,
                &c.name,
                &c.topology,
                &c.positions,
                &c.scheme,
                &c.options,
                &channel,
                mode,
            )
        })
        .collect()
}
