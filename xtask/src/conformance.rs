//! `cargo xtask conformance`: subd's uniform refinement against OpenSubdiv's, level by level,
//! on every shape of `../shared/meshes/osd` and on random meshes.

use std::path::{Path, PathBuf};

use subd_mesh::{DVec3, Topology};
use subd_schemes::{Options, Refinement, Scheme};

use rayon::prelude::*;

use crate::osd;
use crate::refined_limits::RefinedLimits;
pub use crate::row::Row;

/// Tolerance on max |Δ| / bounding-box diagonal.
const TOLERANCE: f64 = 1e-12;
/// Levels are capped where the mesh would pass this many vertices.
const MAX_VERTICES: usize = 2_000_000;

/// Tolerance on the difference of unit normals.
const NORMAL_TOLERANCE: f64 = 1e-10;
/// Unit-normal tolerance of the evaluation check (scaled by the distance to the nearest
/// feature): a point evaluated k levels of local refinement down carries derivative
/// round-off multiplied by 2^k, on both sides.
const EVAL_NORMAL_TOLERANCE: f64 = 1e-9;
/// Limit checks refine at most this many face-vertices deep.
const MAX_LIMIT_FACE_VERTICES: usize = 8_000_000;

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

/// Compares subd and OpenSubdiv on one mesh, returning one row per level.
pub fn compare(
    exe: &Path,
    name: &str,
    topo: &Topology,
    positions: &[DVec3],
    scheme: &Scheme,
    options: &Options,
) -> Vec<Row> {
    let levels = levels_for(topo, scheme);
    let fail = |level: usize, msg: String| Row {
        problem: Some(msg),
        ..Row::pending(name, "refine", level)
    };
    let input = osd::encode(topo, positions, scheme, options, levels as u32);
    let osd_levels = match osd::run(exe, &input, &[]).and_then(|b| osd::decode(&b, levels)) {
        Ok(l) => l,
        Err(e) => return vec![fail(0, format!("OpenSubdiv: {e}"))],
    };
    let refinement = match Refinement::new(topo, scheme.clone(), options, levels) {
        Ok(r) => r,
        Err(e) => return vec![fail(0, format!("subd: {e}"))],
    };
    let ours = refinement.refine_points(positions);
    let (lo, hi) = subd_mesh::bounding_box(positions.iter().copied()).unwrap_or_default();
    let diag = (hi - lo).length().max(f64::MIN_POSITIVE);
    let mut rows = Vec::new();
    for (l, o) in osd_levels.iter().enumerate() {
        let level = l + 1;
        let t = refinement.topology(level);
        let mut problem = None;
        if t.num_vertices() != o.positions.len() {
            problem = Some(format!(
                "{} vertices, OpenSubdiv {}",
                t.num_vertices(),
                o.positions.len()
            ));
        } else if t.num_faces() != o.face_sizes.len() {
            problem = Some(format!(
                "{} faces, OpenSubdiv {}",
                t.num_faces(),
                o.face_sizes.len()
            ));
        } else if t.all_face_vertices() != o.face_vertices.as_slice() {
            let f = (0..t.num_faces())
                .find(|&f| {
                    let a = t.face_offsets()[f] as usize;
                    let b = t.face_offsets()[f + 1] as usize;
                    t.all_face_vertices()[a..b]
                        != o.face_vertices
                            [a.min(o.face_vertices.len())..b.min(o.face_vertices.len())]
                })
                .unwrap_or(0);
            problem = Some(format!("face-vertex lists differ (first at face {f})"));
        }
        let error = if problem.is_none() {
            ours[level]
                .iter()
                .zip(&o.positions)
                .map(|(a, b)| (*a - *b).abs().max_element())
                .fold(0.0, f64::max)
                / diag
        } else {
            f64::INFINITY
        };
        if problem.is_none() && (error.is_nan() || error > TOLERANCE) {
            let v = ours[level]
                .iter()
                .zip(&o.positions)
                .enumerate()
                .max_by(|a, b| {
                    let da = (*a.1.0 - *a.1.1).abs().max_element();
                    let db = (*b.1.0 - *b.1.1).abs().max_element();
                    da.total_cmp(&db)
                })
                .map(|x| x.0)
                .unwrap_or(0);
            problem = Some(format!("worst vertex {v}"));
        }
        rows.push(Row {
            mesh: name.to_string(),
            check: "refine",
            level,
            vertices: t.num_vertices(),
            error,
            normal_error: None,
            excluded: None,
            note: None,
            problem,
        });
    }
    if *scheme != Scheme::Bilinear {
        rows.push(compare_adaptive(
            name,
            topo,
            positions,
            scheme,
            options,
            &osd_levels,
            diag,
        ));
        rows.push(compare_limit(
            exe, name, topo, positions, scheme, options, diag,
        ));
    }
    if *scheme != Scheme::Bilinear {
        rows.push(compare_eval(
            exe, name, topo, positions, scheme, options, diag,
        ));
        rows.push(crate::tess_conformance::compare(
            exe, name, topo, positions, scheme, options, diag,
        ));
        rows.push(compare_pia(
            exe, name, topo, positions, scheme, options, diag,
        ));
        for method in [EditCheck::LeastSquares, EditCheck::Energy] {
            if method == EditCheck::Energy && *scheme != Scheme::CatmullClark {
                continue;
            }
            rows.push(compare_edit(
                exe, name, topo, positions, scheme, options, diag, method,
            ));
        }
    }
    rows
}

/// OpenSubdiv's `Limit` of an encoded mesh, with tangents when asked and OpenSubdiv computes
/// them (its tangent masks overflow and crash on some meshes: then positions only), and
/// whether the tangents came.
fn osd_limit(exe: &Path, input: &[u8], tangents: bool) -> Result<(osd::OsdLimit, bool), String> {
    if tangents
        && let Ok(l) = osd::run(exe, input, &["--limit"]).and_then(|b| osd::decode_limit(&b))
    {
        return Ok((l, true));
    }
    osd::run(exe, input, &["--limit-positions"])
        .and_then(|b| osd::decode_limit(&b))
        .map(|l| (l, false))
}

/// Which method an `edit` row checks.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum EditCheck {
    LeastSquares,
    Energy,
}

/// Tolerance of the edit check (relative to the bounding-box diagonal; normals: |n · t| / |t|).
const EDIT_TOLERANCE: f64 = 1e-9;

/// A random edit (seeded by the mesh name): point constraints at the limits of up to four
/// vertices (spread over the vertex list from a seeded start), displaced by 5 % of the diagonal in varied directions, and (Catmull-Clark) a
/// normal constraint at a smooth interior vertex; solved by subd-editing, then OpenSubdiv's
/// `Limit` of the edited control mesh must meet them to 1e-9 of the diagonal (points) and
/// with both limit tangents perpendicular to the target normal. Vertices where OpenSubdiv's
/// limit is inexact (darts, interior valence 2, see OPENSUBDIV.md) are not used.
#[allow(clippy::too_many_arguments)]
fn compare_edit(
    exe: &Path,
    name: &str,
    topo: &Topology,
    positions: &[DVec3],
    scheme: &Scheme,
    options: &Options,
    diag: f64,
    method: EditCheck,
) -> Row {
    use subd_editing::{Constraint, Editor, Goal, Location, Method};
    let mut row = Row::pending(
        name,
        match method {
            EditCheck::LeastSquares => "edit",
            EditCheck::Energy => "edit-e",
        },
        0,
    );
    let level = subd_limit::levels_for_exact_limit(topo, scheme).0.max(1);
    if topo.num_face_vertices() << (2 * level) > MAX_LIMIT_FACE_VERTICES {
        row.error = 0.0;
        row.note = Some("too deep for OpenSubdiv's limit, not checked".into());
        return row;
    }
    row.level = level;
    let prepared = match Refinement::new(topo, scheme.clone(), options, level) {
        Ok(r) => r,
        Err(e) => {
            row.problem = Some(format!("subd: {e}"));
            return row;
        }
    };
    let inexact = subd_limit::eigen_limit_vertices(&prepared, level);
    let (t0, rules0) = (prepared.topology(0), prepared.vertex_rules(0));
    // Holes as the evaluator sees them (boundary faces too under boundary "none").
    let surface = match subd_limit::eval::LimitEvaluator::new(topo, scheme, options) {
        Ok(ev) => ev.topology().clone(),
        Err(e) => {
            row.error = 0.0;
            row.note = Some(format!("subd-limit: {e}; not checked"));
            return row;
        }
    };
    let nv = topo.num_vertices();
    let seed = name
        .bytes()
        .fold(7u64, |h, b| h.wrapping_mul(31).wrapping_add(b as u64));
    let usable = |v: usize| {
        v < nv
            && !inexact.contains(&v)
            && surface
                .vertex_faces(v)
                .iter()
                .any(|&f| !surface.is_hole(f as usize))
    };
    // Up to four usable vertices, spread from a seeded start.
    let start = ((seed >> 7) % nv as u64) as usize;
    let stride = (nv / 4).max(1);
    let mut chosen: Vec<usize> = Vec::new();
    for k in 0..nv {
        let v = (start + k * stride + k / 4) % nv;
        if chosen.len() == 4 {
            break;
        }
        if usable(v) && !chosen.contains(&v) {
            chosen.push(v);
        }
    }
    let normal_vertex = (0..nv).map(|k| (k + seed as usize) % nv).find(|&v| {
        usable(v)
            && !chosen.contains(&v)
            && *scheme == Scheme::CatmullClark
            && !t0.is_boundary_vertex(v)
            && rules0[v] == subd_schemes::Rule::Smooth
            && t0.vertex_faces(v).len() >= 3
    });
    let dirs = [
        DVec3::new(0.0, 0.0, 1.0),
        DVec3::new(0.6, 0.8, 0.0),
        DVec3::new(-0.48, 0.6, 0.64),
        DVec3::new(0.0, -1.0, 0.0),
    ];
    let mut cs: Vec<Constraint> = chosen
        .iter()
        .enumerate()
        .map(|(k, &v)| Constraint::Point {
            at: Location::Vertex(v),
            goal: Goal::Displacement(0.05 * diag * dirs[k % 4]),
        })
        .collect();
    let target_normal = DVec3::new(0.3, -0.2, 0.93).normalize();
    if let Some(v) = normal_vertex {
        cs.push(Constraint::Normal {
            at: Location::Vertex(v),
            normal: target_normal,
        });
    }
    if cs.is_empty() {
        row.error = 0.0;
        row.note = Some(
            "no vertex on the surface (off holes) with an exact OpenSubdiv limit, not checked"
                .into(),
        );
        return row;
    }
    let m = match method {
        EditCheck::LeastSquares => Method::LeastSquares,
        EditCheck::Energy => Method::Energy {
            penalty: None,
            region_rings: Some(2),
            energy: Default::default(),
        },
    };
    let edited = Editor::new(topo, positions, scheme, options, &cs, m)
        .and_then(|ed| ed.solve(&cs).map(|e| (ed.rank_deficient, e)));
    let (rank_deficient, edit) = match edited {
        Ok(e) => e,
        Err(e) => {
            row.error = 0.0;
            row.note = Some(format!("subd-editing: {e}; not checked"));
            return row;
        }
    };
    let before = match osd_limit(
        exe,
        &osd::encode(topo, positions, scheme, options, level as u32),
        false,
    ) {
        Ok((l, _)) => l,
        Err(e) => {
            row.problem = Some(format!("OpenSubdiv: {e}"));
            return row;
        }
    };
    // Tangents for the normal check; where OpenSubdiv's tangent masks crash (see
    // `compare_limit`), positions only.
    let edited_input = osd::encode(topo, &edit.positions, scheme, options, level as u32);
    let (after, with_tangents) = match osd_limit(exe, &edited_input, normal_vertex.is_some()) {
        Ok(l) => l,
        Err(e) => {
            row.problem = Some(format!("OpenSubdiv: {e}"));
            return row;
        }
    };
    let mut err = 0.0f64;
    for (k, &v) in chosen.iter().enumerate() {
        let moved = after.positions[v] - before.positions[v];
        err = err.max((moved - 0.05 * diag * dirs[k % 4]).length() / diag);
    }
    let mut normal_err = None;
    if let Some(v) = normal_vertex.filter(|_| with_tangents) {
        let (a, b) = (after.tangent1[v], after.tangent2[v]);
        let e =
            (target_normal.dot(a).abs() / a.length()).max(target_normal.dot(b).abs() / b.length());
        normal_err = Some(e);
    }
    row.vertices = chosen.len() + usize::from(normal_vertex.is_some());
    row.error = err;
    row.normal_error = normal_err;
    row.note = Some(format!(
        "{} points{}, {} vertices moved{}",
        chosen.len(),
        if normal_vertex.is_some() {
            " + 1 normal"
        } else {
            ""
        },
        edit.moved.len(),
        if rank_deficient {
            ", rank-deficient: least-squares solution"
        } else {
            ""
        }
    ));
    let bad_normal = normal_err.is_some_and(|e| e.is_nan() || e > EDIT_TOLERANCE);
    if !rank_deficient && (err.is_nan() || err > EDIT_TOLERANCE || bad_normal) {
        row.problem = Some(format!(
            "constraints not met by OpenSubdiv's limit (points {err:e}, normal {normal_err:?})"
        ));
    }
    row
}

/// Adaptive refinement of random selections (two seeds, about 40 % of the faces of every
/// level) against OpenSubdiv's uniform levels: every output vertex must be OpenSubdiv's
/// vertex at its level and index (so it is found by position among that level's vertices),
/// and the output must pass the closure invariants — conforming (every edge used by as many
/// faces as in uniform refinement), levels of faces sharing an edge or a vertex at most one
/// apart.
fn compare_adaptive(
    name: &str,
    topo: &Topology,
    positions: &[DVec3],
    scheme: &Scheme,
    options: &Options,
    osd_levels: &[osd::OsdLevel],
    diag: f64,
) -> Row {
    use subd_adaptive::{AdaptiveRefinement, Positions, RandomSelection};
    let levels = osd_levels.len();
    let mut row = Row::pending(name, "adaptv", levels);
    let mut worst = 0.0f64;
    let mut vertices = 0;
    for seed in [1u64, 2] {
        let pick = RandomSelection::new(seed, 0.4).expect("a fraction in [0, 1]");
        let a = match AdaptiveRefinement::new(topo, positions, scheme, options, &[&pick], levels) {
            Ok(a) => a,
            Err(e) => {
                row.problem = Some(format!("subd: {e}"));
                return row;
            }
        };
        let mesh = match a.mesh(Positions::Refined) {
            Ok(m) => m,
            Err(e) => {
                row.problem = Some(format!("subd: {e}"));
                return row;
            }
        };
        for (v, (&l, &k)) in mesh
            .vertex_levels
            .iter()
            .zip(&mesh.vertex_uniform)
            .enumerate()
        {
            let theirs = if l == 0 {
                positions.get(k as usize)
            } else {
                osd_levels[l as usize - 1].positions.get(k as usize)
            };
            let Some(theirs) = theirs else {
                row.problem = Some(format!("level {l} vertex {k} is not in OpenSubdiv's level"));
                return row;
            };
            worst = worst.max((mesh.positions[v] - *theirs).abs().max_element() / diag);
        }
        let c = mesh.conformity();
        if !c.conforming || c.max_level_difference_edge > 1 || c.max_level_difference_vertex > 1 {
            row.problem = Some(format!("seed {seed}: closure invariants fail: {c:?}"));
            return row;
        }
        vertices += mesh.positions.len();
    }
    row.vertices = vertices;
    row.error = worst;
    if worst.is_nan() || worst > TOLERANCE {
        row.problem = Some("an output vertex is off OpenSubdiv's".into());
    }
    row
}

/// Tolerance of the PIA check: OpenSubdiv's limit of subd's interpolating mesh must hit the
/// moving targets within this fraction of the bounding-box diagonal.
const PIA_TOLERANCE: f64 = 1e-9;

/// Local PIA (every third vertex fixed, the rest moving) with subd, then OpenSubdiv's
/// `PrimvarRefiner::Limit` of the result: the moving vertices' limits must equal their
/// targets. Vertices where OpenSubdiv's limit is not exact (darts, valence 2) are left out,
/// and so are meshes whose limit matrix is singular (no interpolant exists).
fn compare_pia(
    exe: &Path,
    name: &str,
    topo: &Topology,
    positions: &[DVec3],
    scheme: &Scheme,
    options: &Options,
    diag: f64,
) -> Row {
    use subd_pia::{Moving, Pia, PiaOptions, Solver};
    let mut row = Row::pending(name, "pia", 0);
    let level = subd_limit::levels_for_exact_limit(topo, scheme).0.max(1);
    if topo.num_face_vertices() << (2 * level) > MAX_LIMIT_FACE_VERTICES {
        row.error = 0.0;
        row.note = Some("too deep for OpenSubdiv's limit, not checked".into());
        return row;
    }
    row.level = level;
    let pia_scheme = match scheme {
        Scheme::Loop => Scheme::Loop,
        _ => Scheme::CatmullClark,
    };
    let pia = match Pia::new(topo, &pia_scheme, options) {
        Ok(p) => p,
        Err(e) => {
            row.problem = Some(format!("subd: {e}"));
            return row;
        }
    };
    let nv = topo.num_vertices();
    let moving = Moving::AllBut((0..nv as u32).filter(|v| v % 3 == 1).collect());
    let flags = moving.flags(nv).expect("indices in range");
    let solved = [Solver::Auto, Solver::Direct]
        .into_iter()
        .find_map(|solver| {
            let opts = PiaOptions {
                solver,
                tol: 1e-11,
                max_iter: 5000,
            };
            pia.solve(positions, &moving, &opts)
                .ok()
                .filter(|r| r.converged)
        });
    let Some(result) = solved else {
        row.error = 0.0;
        row.note = Some("limit matrix singular: no interpolant, not checked".into());
        return row;
    };
    let input = osd::encode(topo, &result.points, scheme, options, level as u32);
    let theirs =
        match osd::run(exe, &input, &["--limit-positions"]).and_then(|b| osd::decode_limit(&b)) {
            Ok(l) => l,
            Err(e) => {
                row.problem = Some(format!("OpenSubdiv: {e}"));
                return row;
            }
        };
    let inexact = match Refinement::new(topo, scheme.clone(), options, level) {
        Ok(r) => subd_limit::eigen_limit_vertices(&r, level),
        Err(e) => {
            row.problem = Some(format!("subd: {e}"));
            return row;
        }
    };
    let mut skip = vec![false; nv];
    for &v in inexact.iter().filter(|&&v| v < nv) {
        skip[v] = true;
    }
    let (mut err, mut worst, mut left_out) = (0.0f64, 0, 0);
    for v in 0..nv {
        if !flags[v] {
            if result.points[v] != positions[v] {
                row.problem = Some(format!("fixed vertex {v} moved"));
            }
            continue;
        }
        if skip[v] {
            left_out += 1;
            continue;
        }
        let d = (theirs.positions[v] - positions[v]).abs().max_element() / diag;
        if d > err || d.is_nan() {
            (err, worst) = (d, v);
        }
    }
    row.vertices = nv - left_out;
    row.error = err;
    row.note = Some(format!(
        "{:?}, {} iterations{}",
        result.method,
        result.iterations,
        if left_out > 0 {
            format!(", {left_out} moving vertices where OpenSubdiv's limit is inexact left out")
        } else {
            String::new()
        }
    ));
    if row.problem.is_none() && (err.is_nan() || err > PIA_TOLERANCE) {
        row.problem = Some(format!("worst vertex {worst}"));
    }
    row
}

/// OpenSubdiv's isolation level for the evaluation check.
const ISOLATION: u32 = 10;

/// Parameters sampled on every ptex face: spread over the face, on its edges, and close to
/// its corners (inside and just outside the 2^-10 squares).
const EVAL_PARAMS: [(f64, f64); 14] = [
    (0.5, 0.5),
    (0.1, 0.2),
    (0.9, 0.3),
    (0.25, 0.75),
    (0.7, 0.95),
    (0.0, 0.5),
    (1.0, 0.25),
    (0.01, 0.03),
    (0.001, 0.0015),
    (0.999, 0.998),
    (1e-4, 3e-4),
    (3e-4, 2e-5),
    (0.9995, 0.9996),
    (0.0002, 0.9999),
];

/// Exact evaluation at (face, u, v) against OpenSubdiv's patch table at isolation level 10
/// (infinitely sharp patches on, legacy sharp corners off). Outside the 2^-10 squares at
/// irregular corners OpenSubdiv's patches are exact B-splines: positions must agree to 1e-12
/// of the bounding-box diagonal and unit normals to 1e-9 (scaled). Inside, OpenSubdiv has a Gregory
/// end cap; the largest difference there is reported, not checked. Holes and uncovered faces
/// are counted and left out. Where OpenSubdiv differs but
/// subd's face equals uniform refinement at dyadic points, the point is counted as
/// OpenSubdiv's inexactness, not a failure.
fn compare_eval(
    exe: &Path,
    name: &str,
    topo: &Topology,
    positions: &[DVec3],
    scheme: &Scheme,
    options: &Options,
    diag: f64,
) -> Row {
    use subd_limit::eval::FaceParam;
    use subd_limit::patches::PatchTable;
    let mut row = Row::pending(name, "eval", ISOLATION as usize);
    // What `subd eval` runs: the exact limit's patch table.
    let table = match PatchTable::exact_limit(topo, positions, scheme, options) {
        Ok(t) => t,
        Err(e) => {
            row.problem = Some(format!("subd: {e}"));
            return row;
        }
    };
    let near = 1.0 / f64::from(1u32 << ISOLATION);
    let regular_valence = if *scheme == Scheme::Loop { 6 } else { 4 };
    // Irregular: anything but a smooth vertex of the regular valence or (Catmull-Clark) a
    // vertex on a straight infinitely sharp crease, regular boundary or sharp corner — the
    // vertices OpenSubdiv's patches isolate and cap at level 10. Darts, turning creases and
    // semi-sharp vertices count as irregular.
    let prepared = match Refinement::new(topo, scheme.clone(), options, 0) {
        Ok(r) => r,
        Err(e) => {
            row.problem = Some(format!("subd: {e}"));
            return row;
        }
    };
    let (t0, rules0) = (prepared.topology(0), prepared.vertex_rules(0));
    let irregular = |v: u32| {
        let v = v as usize;
        let smooth_regular = t0.vertex_faces(v).len() == regular_valence
            && !t0.is_boundary_vertex(v)
            && rules0[v] == subd_schemes::Rule::Smooth
            && t0.vertex_sharpness(v) == 0.0
            && t0
                .vertex_edges(v)
                .iter()
                .all(|&e| t0.edge_sharpness(e as usize) == 0.0);
        let sharp_regular = *scheme == Scheme::CatmullClark
            && subd_limit::patch::regular_sharp_corner(t0, rules0, v);
        !(smooth_regular || sharp_regular)
    };
    let mut ours = Vec::new();
    let mut queries = Vec::new();
    let mut inside = Vec::new();
    let mut feature_dist = Vec::new();
    let mut ptex_face = Vec::new();
    let mut uncovered = 0usize;
    let mut ptex = 0u32;
    for f in 0..topo.num_faces() {
        let fv = topo.face_vertices(f);
        let n = fv.len();
        let loop_scheme = *scheme == Scheme::Loop;
        let subs = if n == 4 || loop_scheme { 1 } else { n };
        for sub in 0..subs {
            // The irregular corners of this ptex face, in its (u, v).
            let corners: Vec<(f64, f64)> = if loop_scheme {
                [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]
                    .into_iter()
                    .zip(fv)
                    .filter(|&(_, &v)| irregular(v))
                    .map(|(c, _)| c)
                    .collect()
            } else if n == 4 {
                [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
                    .into_iter()
                    .zip(fv)
                    .filter(|&(_, &v)| irregular(v))
                    .map(|(c, _)| c)
                    .collect()
            } else {
                // A sub-face's (1, 1) is the face centre, of valence n.
                let mut c = vec![(1.0, 1.0)];
                if irregular(fv[sub]) {
                    c.push((0.0, 0.0));
                }
                c
            };
            // A sub-face is already one level down, so its end caps are twice as large.
            let near = if n == 4 || loop_scheme {
                near
            } else {
                2.0 * near
            };
            for &(u, v) in &EVAL_PARAMS {
                // A Loop triangle's parameters are barycentric: fold the square onto it.
                let (u, v) = if loop_scheme && u + v > 1.0 {
                    (1.0 - v, 1.0 - u)
                } else {
                    (u, v)
                };
                match table.evaluate(FaceParam { face: f, sub, u, v }) {
                    Ok(p) => {
                        ours.push(p);
                        queries.push((ptex, u, v));
                        // L∞ distance to the nearest irregular corner.
                        let dist = corners
                            .iter()
                            .map(|&(cu, cv)| (u - cu).abs().max((v - cv).abs()))
                            .fold(f64::INFINITY, f64::min);
                        // Distance to each sharp edge (boundaries included) of the ptex face.
                        let fe = t0.face_edges(f);
                        let sharp = |k: usize| t0.edge_sharpness(fe[k] as usize) > 0.0;
                        let edges: Vec<(usize, f64)> = if loop_scheme {
                            vec![(0, v), (1, 1.0 - u - v), (2, u)]
                        } else if n == 4 {
                            vec![(0, v), (1, 1.0 - u), (2, 1.0 - v), (3, u)]
                        } else {
                            vec![(sub, v), ((sub + n - 1) % n, u)]
                        };
                        let strip = edges
                            .iter()
                            .filter(|&&(k, _)| sharp(k))
                            .map(|&(_, d)| d)
                            .fold(f64::INFINITY, f64::min);
                        inside.push((dist < near, dist));
                        // Derivative round-off grows with the depth of local refinement,
                        // which next to a sharp edge is driven by the distance to it.
                        feature_dist.push(dist.min(strip));
                        ptex_face.push((f, sub));
                    }
                    Err(subd_limit::LimitError::Unsupported { .. }) => uncovered += 1,
                    Err(e) => {
                        row.problem = Some(format!("subd: face {f}: {e}"));
                        return row;
                    }
                }
            }
            ptex += 1;
        }
    }
    row.vertices = queries.len();
    row.excluded = Some((uncovered, 0.0));
    if queries.is_empty() {
        row.error = 0.0;
        return row;
    }
    let input = osd::encode_eval_points(
        osd::encode(topo, positions, scheme, options, ISOLATION),
        &queries,
    );
    let theirs = match osd::run(exe, &input, &["--eval"])
        .and_then(|b| osd::decode_eval(&b, queries.len()))
    {
        Ok(t) => t,
        Err(e) => {
            row.problem = Some(format!("OpenSubdiv: {e}"));
            return row;
        }
    };
    // Normals come from derivatives, whose round-off (on both sides) grows like 1/δ at
    // distance δ from an extraordinary vertex or the sharp edge that forces local refinement:
    // the normal bound is 1e-9 · max(1, 1/δ).
    // The column reports the largest normal difference divided by that factor.
    let (mut err, mut nerr, mut inside_err) = (0.0f64, 0.0f64, 0.0f64);
    let mut checked_faces = std::collections::HashMap::new();
    let mut reference = None;
    let mut osd_inexact = 0usize;
    let mut folds = 0usize;
    let (mut worst, mut worst_normal) = (None, None);
    for (i, (p, t)) in ours.iter().zip(&theirs).enumerate() {
        let d = (p.position - t[0]).abs().max_element() / diag;
        let (is_inside, dist) = inside[i];
        if is_inside {
            inside_err = inside_err.max(d);
            continue;
        }
        if d > TOLERANCE && !d.is_nan() {
            // Where OpenSubdiv is not exact either (seen on Loop meshes with semi-sharp
            // creases next to holes), subd's face is checked against uniform refinement.
            let face = ptex_face[i];
            let reference = reference
                .get_or_insert_with(|| RefinedLimits::new(topo, positions, scheme, options));
            let verified = *checked_faces.entry(face).or_insert_with(|| {
                reference
                    .as_ref()
                    .is_some_and(|r| r.agrees(&table, face, diag))
            });
            if verified {
                osd_inexact += 1;
                continue;
            }
        }
        if d.is_nan() || d > TOLERANCE {
            worst.get_or_insert(i);
        }
        err = if d.is_nan() || err.is_nan() {
            f64::NAN
        } else {
            err.max(d)
        };
        let on = t[1].cross(t[2]);
        // Where a tangent vanishes (the surface folds over, as back-to-back faces do along
        // their shared edges) the normal is undefined: either side's is rounding.
        let vanishes = |a: DVec3, b: DVec3| {
            let (a, b) = (a.length(), b.length());
            a.min(b) <= 1e-9 * a.max(b)
        };
        if vanishes(p.du, p.dv) || vanishes(t[1], t[2]) {
            folds += 1;
            continue;
        }
        if on.length() > 1e-12 * t[1].length() * t[2].length() && p.normal() != DVec3::ZERO {
            let dn = (p.normal() - on.normalize()).abs().max_element()
                * dist.min(feature_dist[i]).min(1.0);
            if dn > EVAL_NORMAL_TOLERANCE {
                worst_normal.get_or_insert(i);
            }
            nerr = nerr.max(dn);
        }
    }
    row.error = err;
    row.normal_error = Some(nerr);
    row.excluded = Some((uncovered, inside_err));
    let mut notes = Vec::new();
    if osd_inexact > 0 {
        notes.push(format!(
            "{osd_inexact} points where OpenSubdiv is off but subd's face agrees with uniform refinement at dyadic points"
        ));
    }
    if folds > 0 {
        notes.push(format!(
            "{folds} points where a tangent vanishes (a fold): normals not compared"
        ));
    }
    if !notes.is_empty() {
        row.note = Some(notes.join("; "));
    }
    if let Some(worst) = worst.or(worst_normal) {
        let q = queries[worst];
        row.problem = Some(format!(
            "worst point ptex {} ({}, {}): subd {} n {}, OpenSubdiv {} n {}",
            q.0,
            q.1,
            q.2,
            ours[worst].position,
            ours[worst].normal(),
            theirs[worst][0],
            theirs[worst][1].cross(theirs[worst][2]).normalize_or_zero()
        ));
    }
    row
}

/// Limit positions, tangents and normals of every vertex of level N against OpenSubdiv's
/// `PrimvarRefiner::Limit` there; N is the level where semi-sharp features have decayed
/// (at least 1), lowered where the mesh would grow too large (both sides then take the masks
/// of the rules at that level). Positions and tangents within 1e-12 of the bounding-box
/// diagonal, unit normals within 1e-10, except at the vertices where OpenSubdiv is not exact
/// (interior valence 2, darts on infinitely sharp edges), which are counted and reported.
fn compare_limit(
    exe: &Path,
    name: &str,
    topo: &Topology,
    positions: &[DVec3],
    scheme: &Scheme,
    options: &Options,
    diag: f64,
) -> Row {
    let mut level = subd_limit::levels_for_exact_limit(topo, scheme).0.max(1);
    while level > 1 && topo.num_face_vertices() << (2 * level) > MAX_LIMIT_FACE_VERTICES {
        level -= 1;
    }
    let mut row = Row::pending(name, "limit", level);
    let input = osd::encode(topo, positions, scheme, options, level as u32);
    // Where OpenSubdiv crashes computing tangents (see `overflow` below), compare positions.
    let (theirs, with_tangents) = match osd_limit(exe, &input, true) {
        Ok(l) => l,
        Err(e) => {
            row.problem = Some(format!("OpenSubdiv: {e}"));
            return row;
        }
    };
    let topo_at = match Refinement::new(topo, scheme.clone(), options, level) {
        Ok(r) => r,
        Err(e) => {
            row.problem = Some(format!("subd: {e}"));
            return row;
        }
    };
    let ours = subd_limit::LimitStencilTable::at_level(&topo_at, level)
        .map_err(|e| e.to_string())
        .map(|table| {
            let pts = topo_at.refine_points(positions);
            (
                table.apply(&pts[level]),
                subd_limit::eigen_limit_vertices(&topo_at, level),
            )
        });
    let (ours, skip) = match ours {
        Ok(x) => x,
        Err(e) => {
            row.problem = Some(format!("subd: {e}"));
            return row;
        }
    };
    row.vertices = ours.positions.len();
    if ours.positions.len() != theirs.positions.len() {
        row.problem = Some(format!(
            "{} limit points, OpenSubdiv {}",
            ours.positions.len(),
            theirs.positions.len()
        ));
        return row;
    }
    let mut excluded = vec![false; row.vertices];
    // OpenSubdiv sizes its limit-mask buffers by `Level::getMaxValence()`, which refinement
    // sets to max(parent, 4, 2 + max edge faces) — fewer than the 2·k faces of the child of a
    // non-manifold edge with k > 2 faces. There the face weights of the first tangent run
    // into the second tangent's buffer (Far/primvarRefiner.h, `limit()`), so OpenSubdiv's
    // tangents are garbled; positions are unaffected. Tangents and normals of non-manifold
    // vertices with more faces than edges are left out of the comparison.
    let overflow: Vec<bool> = (0..row.vertices)
        .map(|v| {
            let t = topo_at.topology(level);
            t.is_non_manifold_vertex(v) && t.vertex_faces(v).len() > t.vertex_edges(v).len()
        })
        .collect();
    for &v in &skip {
        excluded[v] = true;
    }
    let (mut err, mut nerr, mut skipped_err) = (0.0f64, 0.0f64, 0.0f64);
    let mut worst = 0;
    for v in 0..row.vertices {
        let tangents = if overflow[v] || !with_tangents { 1 } else { 3 };
        let d = [
            ours.positions[v] - theirs.positions[v],
            ours.tangent1[v] - theirs.tangent1[v],
            ours.tangent2[v] - theirs.tangent2[v],
        ][..tangents]
            .iter()
            .map(|x| x.abs().max_element())
            .fold(0.0, f64::max)
            / diag;
        let pd = (ours.positions[v] - theirs.positions[v])
            .abs()
            .max_element()
            / diag;
        if excluded[v] {
            skipped_err = skipped_err.max(pd);
            continue;
        }
        if d > err || d.is_nan() {
            worst = v;
        }
        err = err.max(d);
        if d.is_nan() {
            err = f64::NAN;
        }
        let cross = theirs.tangent1[v].cross(theirs.tangent2[v]);
        let (l1, l2) = (theirs.tangent1[v].length(), theirs.tangent2[v].length());
        // No normal where a tangent vanishes or both are parallel.
        let defined = l1.min(l2) > 1e-9 * diag && cross.length() > 1e-9 * l1 * l2;
        if with_tangents && defined && ours.normals[v] != DVec3::ZERO && !overflow[v] {
            let dn = (ours.normals[v] - cross.normalize()).abs().max_element();
            if dn > nerr && dn > NORMAL_TOLERANCE && d <= TOLERANCE {
                worst = v;
            }
            nerr = nerr.max(dn);
        }
    }
    row.error = err;
    row.normal_error = with_tangents.then_some(nerr);
    row.excluded = (!skip.is_empty()).then_some((skip.len(), skipped_err));
    if err.is_nan() || err > TOLERANCE || nerr > NORMAL_TOLERANCE {
        let w = worst;
        row.problem = Some(format!(
            "worst vertex {w}: subd p {} t1 {} t2 {}, OpenSubdiv p {} t1 {} t2 {}",
            ours.positions[w],
            ours.tangent1[w],
            ours.tangent2[w],
            theirs.positions[w],
            theirs.tangent1[w],
            theirs.tangent2[w]
        ));
    }
    row
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
            let c = crate::random_mesh::case(seed);
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
