//! Patch tables against OpenSubdiv's `Far::PatchTableFactory`: for every shape, scheme,
//! isolation level and option set, the same patches (type, root face, u, v, depth, boundary
//! and transition masks), and the same values where they are evaluated.

use std::collections::BTreeMap;
use std::path::Path;

use subd_limit::eval::FaceParam;
use subd_limit::patches::{EndCaps, PatchOptions, PatchParam, PatchTable, PatchType};
use subd_mesh::{DVec3, Topology};
use subd_schemes::{Options, Scheme};

use rayon::prelude::*;

use crate::conformance::row::Row;
use crate::oracles::osd;

/// One patch as the harness writes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct OsdPatch {
    /// OpenSubdiv's `PatchDescriptor::Type`.
    pub kind: u32,
    pub face: u32,
    pub u: u32,
    pub v: u32,
    pub depth: u32,
    pub non_quad: u32,
    pub boundary: u32,
    pub transition: u32,
    pub regular: u32,
}

/// One evaluation of the harness's face-varying patches: value, du, dv (two numbers each),
/// and the values of the patch (two numbers each).
pub struct OsdFVarPoint {
    pub eval: [f64; 6],
    pub patch_values: Vec<[f64; 2]>,
}

/// The harness's patch table: its patches, local point count, the evaluations, and with a
/// face-varying channel its evaluations.
pub struct OsdPatchTable {
    pub patches: Vec<OsdPatch>,
    /// Each patch's control points (indices into `points`).
    pub control_points: Vec<Vec<u32>>,
    /// The refined vertices of every level, then the local points.
    pub points: Vec<DVec3>,
    pub local_points: usize,
    pub evaluations: Vec<[DVec3; 6]>,
    pub fvar: Vec<OsdFVarPoint>,
}

/// The harness's `--patches` arguments for `options`.
pub fn harness_args(options: &PatchOptions) -> Vec<String> {
    let end_cap = match options.end_caps {
        EndCaps::Bilinear => 1,
        EndCaps::BSpline => 2,
        EndCaps::GregoryBasis | EndCaps::Exact => 3,
    };
    [
        "--patches".to_string(),
        end_cap.to_string(),
        u8::from(options.single_crease).to_string(),
        u8::from(options.inf_sharp).to_string(),
        u8::from(options.legacy_sharp_corners).to_string(),
    ]
    .to_vec()
}

/// Decodes `--patches` output for `points` evaluation points.
pub fn decode(bytes: &[u8], points: usize) -> Result<OsdPatchTable, String> {
    let mut c = osd::Cursor::new(bytes);
    let (mut patches, mut control_points) = (Vec::new(), Vec::new());
    for _ in 0..c.u32()? {
        let (kind, cvs, n) = (c.u32()?, c.u32()? as usize, c.u32()?);
        for _ in 0..n {
            let f: Vec<u32> = (0..8).map(|_| c.u32()).collect::<Result<_, _>>()?;
            c.take(4)?;
            control_points.push((0..cvs).map(|_| c.u32()).collect::<Result<_, _>>()?);
            patches.push(OsdPatch {
                kind,
                face: f[0],
                u: f[1],
                v: f[2],
                depth: f[3],
                non_quad: f[4],
                boundary: f[5],
                transition: f[6],
                regular: f[7],
            });
        }
    }
    let local_points = c.u32()? as usize;
    let refined = c.u32()? as usize;
    let mut evaluations = Vec::with_capacity(points);
    for _ in 0..points {
        let mut e = [DVec3::ZERO; 6];
        for d in &mut e {
            *d = DVec3::from_slice(&c.f64s(3)?);
        }
        evaluations.push(e);
    }
    let table_points = c
        .f64s(3 * (refined + local_points))?
        .chunks_exact(3)
        .map(DVec3::from_slice)
        .collect();
    let mut fvar = Vec::new();
    if !c.is_empty() {
        for _ in 0..points {
            let x = c.f64s(6)?;
            let n = c.u32()? as usize;
            let values = c.f64s(2 * n)?;
            fvar.push(OsdFVarPoint {
                eval: std::array::from_fn(|k| x[k]),
                patch_values: values.chunks_exact(2).map(|v| [v[0], v[1]]).collect(),
            });
        }
    }
    Ok(OsdPatchTable {
        patches,
        control_points,
        points: table_points,
        local_points,
        evaluations,
        fvar,
    })
}

/// subd's patches in the harness's form.
pub fn subd_patches(table: &PatchTable) -> Vec<OsdPatch> {
    let mut out = Vec::new();
    for array in table.arrays() {
        for p in array.params() {
            let p = p.place();
            out.push(OsdPatch {
                kind: array.kind().opensubdiv_type(),
                face: p.face,
                u: p.u.into(),
                v: p.v.into(),
                depth: p.depth.into(),
                non_quad: p.non_quad.into(),
                boundary: p.boundary.into(),
                transition: p.transition.into(),
                regular: p.regular.into(),
            });
        }
    }
    out
}

/// The first difference between two patch lists (compared as sets keyed by type and place),
/// or `None`.
pub fn census_difference(osd: &[OsdPatch], subd: &[OsdPatch]) -> Option<String> {
    let key = |p: &OsdPatch| (p.kind, p.face, p.u, p.v, p.depth, p.non_quad);
    let a: BTreeMap<_, _> = osd.iter().map(|p| (key(p), *p)).collect();
    let b: BTreeMap<_, _> = subd.iter().map(|p| (key(p), *p)).collect();
    if a.len() != osd.len() || b.len() != subd.len() {
        return Some("a patch listed twice".into());
    }
    for (k, p) in &a {
        match b.get(k) {
            None => {
                return Some(format!(
                    "{} patches vs OpenSubdiv's {}: missing {p:?}",
                    subd.len(),
                    osd.len()
                ));
            }
            Some(q) if q != p => return Some(format!("OpenSubdiv {p:?}, subd {q:?}")),
            _ => {}
        }
    }
    b.iter().find(|(k, _)| !a.contains_key(k)).map(|(_, q)| {
        format!(
            "{} patches vs OpenSubdiv's {}: extra {q:?}",
            subd.len(),
            osd.len()
        )
    })
}

/// The option sets a mesh of `scheme` is checked with: every isolation level of a few,
/// each flag combination, and every kind of end caps OpenSubdiv has.
pub fn option_sets(scheme: &Scheme) -> Vec<PatchOptions> {
    let mut sets = Vec::new();
    let caps: &[EndCaps] = if *scheme == Scheme::Loop {
        &[EndCaps::Bilinear, EndCaps::GregoryBasis, EndCaps::BSpline]
    } else {
        &[EndCaps::GregoryBasis, EndCaps::Bilinear, EndCaps::BSpline]
    };
    for isolation in [1u8, 2, 3, 6] {
        for (single_crease, inf_sharp, legacy_sharp_corners) in [
            (false, false, true),
            (true, true, false),
            (false, true, true),
            (true, false, false),
        ] {
            for (i, &end_caps) in caps.iter().enumerate() {
                // Every flag set with the first end caps; the others at two levels.
                if i > 0 && !matches!(isolation, 2 | 6) {
                    continue;
                }
                sets.push(PatchOptions {
                    isolation,
                    end_caps,
                    single_crease,
                    inf_sharp,
                    legacy_sharp_corners,
                });
            }
        }
    }
    sets
}

/// A deterministic stream of numbers in [0, 1).
fn uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64) / ((1u64 << 53) as f64)
    }
}

/// Evaluation points: a few per root face the table covers, and one inside each of up to
/// 100 end caps (spread over the table), as (base face, sub-face, u, v) and the harness's
/// (ptex face, u, v).
pub(crate) fn eval_points(
    table: &PatchTable,
    topo: &Topology,
    scheme: &Scheme,
    seed: u64,
) -> Vec<(FaceParam, u32)> {
    let mut next = uniform(seed);
    let loop_scheme = *scheme == Scheme::Loop;
    let mut out = Vec::new();
    // The (base face, sub-face) of each root face.
    let mut roots = Vec::new();
    for f in 0..topo.num_faces() {
        let n = topo.face_size(f);
        let subs = if loop_scheme || n == 4 { 1 } else { n };
        for sub in 0..subs {
            roots.push((f, sub));
            for _ in 0..2 {
                let (mut u, mut v) = (next(), next());
                if loop_scheme && u + v > 1.0 {
                    (u, v) = (1.0 - u, 1.0 - v);
                }
                let at = FaceParam { face: f, sub, u, v };
                if table.find(&at).is_ok() {
                    out.push((at, (roots.len() - 1) as u32));
                }
            }
        }
    }
    // Keep the harness's input small on big meshes.
    let step = out.len().div_ceil(400).max(1);
    let mut out: Vec<_> = out.into_iter().step_by(step).collect();
    // End caps are a small part of the surface at high isolation: visit some on purpose.
    let caps: Vec<_> = table
        .arrays()
        .iter()
        .flat_map(|a| a.params())
        .filter(|p| !p.place().regular)
        .collect();
    for p in caps.iter().step_by(caps.len().div_ceil(100).max(1)) {
        let (mut s, mut t) = (next(), next());
        let (u, v) = if loop_scheme {
            if s + t > 1.0 {
                (s, t) = (1.0 - s, 1.0 - t);
            }
            p.unnormalize_triangle(s, t)
        } else {
            p.unnormalize(s, t)
        };
        let root = p.place().face;
        let (face, sub) = roots[root as usize];
        let at = FaceParam { face, sub, u, v };
        if table.find(&at).is_ok() {
            out.push((at, root));
        }
    }
    out
}

/// How far OpenSubdiv's box-spline end caps of Loop may lie from subd's, relative to the
/// bounding-box diagonal. OpenSubdiv fits them with a table of float constants printed to 6
/// decimals that differ from the exact least-squares fit (`patches::box_fit`) by up to
/// 2.6e-5 per weight (and whose rows sum to 1 only within 2e-6), so the two cannot agree to
/// 1e-12; everything else in those tables (the Gregory triangles the fit is applied to, the
/// regular patches) still must.
/// Over the shapes they differ by at most 1.0e-6 (isolation 2, where the caps are
/// largest).
const BOX_SPLINE_CAP_TOLERANCE: f64 = 1e-5;

/// The largest differences between subd's and OpenSubdiv's evaluations, relative to the
/// bounding-box diagonal: everywhere but in Loop's box-spline end caps and at valence-2
/// darts, and there (with the number of points there).
struct EvalErrors {
    strict: f64,
    box_caps: (usize, f64),
    darts: (usize, f64),
    /// Points where OpenSubdiv's patch evaluates exactly as subd's basis applied to
    /// OpenSubdiv's own control points, but those points are not subd's: see
    /// [`osd_points_depart`].
    osd_points: (usize, f64),
}

/// subd's refined vertices that OpenSubdiv's refinement lacks: no refined vertex of
/// OpenSubdiv lies within 1e-12 of the diagonal of them (OpenSubdiv's adaptive refinement
/// put its counterpart elsewhere), while subd's uniform refinement (`uniform`, all levels,
/// asked for only when some vertex is missing) has it: a subd vertex off uniform
/// refinement is never taken for OpenSubdiv's departure.
fn refined_points_osd_lacks(
    table: &PatchTable,
    osd: &OsdPatchTable,
    diag: f64,
    uniform: impl FnOnce() -> Vec<DVec3>,
) -> Vec<bool> {
    let refined: usize = table.level_vertex_counts().iter().sum();
    let tol = 1e-12 * diag;
    let osd_refined = sorted_by_x(&osd.points[..osd.points.len() - osd.local_points]);
    let mut lacking: Vec<bool> = table.points()[..refined]
        .iter()
        .map(|p| !has_near(&osd_refined, *p, tol))
        .collect();
    if lacking.iter().any(|&l| l) {
        let uniform = sorted_by_x(&uniform());
        for (l, p) in lacking.iter_mut().zip(table.points()) {
            *l = *l && has_near(&uniform, *p, tol);
        }
    }
    lacking
}

fn sorted_by_x(points: &[DVec3]) -> Vec<DVec3> {
    let mut by_x = points.to_vec();
    by_x.sort_by(|p, q| p.x.total_cmp(&q.x));
    by_x
}

/// Whether `by_x` (sorted by x) has a point within `tol` of `p`.
fn has_near(by_x: &[DVec3], p: DVec3, tol: f64) -> bool {
    let first = by_x.partition_point(|q| q.x < p.x - tol);
    by_x[first..]
        .iter()
        .take_while(|q| q.x <= p.x + tol)
        .any(|q| (p - *q).length() <= tol)
}

/// Whether patch `i` of array `a` reads a refined vertex in `lacking`: as a control point,
/// or through the stencil of one of its local points.
fn reads_lacking(table: &PatchTable, (a, i): (usize, usize), lacking: &[bool]) -> bool {
    let stencils = table.local_point_stencils();
    table.arrays()[a].patch_points(i).iter().any(|&c| {
        let c = c as usize;
        if c < lacking.len() {
            lacking[c]
        } else {
            stencils
                .row(c - lacking.len())
                .0
                .iter()
                .any(|&r| lacking[r as usize])
        }
    })
}

/// The patch key the census compares by.
type PatchKey = (u32, u32, u32, u32, u32, u32);

fn key_of(p: &OsdPatch) -> PatchKey {
    (p.kind, p.face, p.u, p.v, p.depth, p.non_quad)
}

/// Whether the difference at a point lies in OpenSubdiv's control points alone: its
/// evaluation equals subd's basis (`PatchTable::evaluate_basis`) applied to OpenSubdiv's
/// control points of the same patch to 1e-12, while subd's evaluation differs. subd's
/// refined points are uniform refinement's, computed by the same operations (the sparse
/// levels are cut from the uniform ones and the `refine` rows hold subd's uniform
/// refinement equal to OpenSubdiv's), so such a point shows OpenSubdiv's adaptive refinement
/// leaving its own uniform refinement: on `random_073_torus_loop` (Loop, Chaikin, boundary
/// none) its level-2 vertex 595 is 4.5e-3 of the diagonal from every uniform level-2 vertex.
#[allow(clippy::too_many_arguments)]
fn osd_points_depart(
    table: &PatchTable,
    (a, i): (usize, usize),
    at: &FaceParam,
    osd: &OsdPatchTable,
    keys: &BTreeMap<PatchKey, usize>,
    theirs: &[DVec3; 6],
    scale: [f64; 6],
    own: [f64; 6],
    diag: f64,
) -> bool {
    let array = &table.arrays()[a];
    let place = array.params()[i].place();
    let key = (
        array.kind().opensubdiv_type(),
        place.face,
        place.u.into(),
        place.v.into(),
        place.depth.into(),
        place.non_quad.into(),
    );
    let (Some(&p), Ok(w)) = (keys.get(&key), table.evaluate_basis(a, i, at.u, at.v)) else {
        return false;
    };
    let cvs = &osd.control_points[p];
    if cvs.len() != w.rows[0].len() {
        return false;
    }
    (0..6).all(|d| {
        let rebuilt: DVec3 = cvs
            .iter()
            .zip(&w.rows[d])
            .map(|(&c, &x)| x * osd.points[c as usize])
            .sum();
        (rebuilt - theirs[d] * scale[d]).length() * own[d] / diag <= 1e-12
    })
}

/// Whether a base vertex is a valence-2 dart: interior, two faces, exactly one infinitely
/// sharp edge. OpenSubdiv 3.5's `Far::PatchBuilder` builds the patches with such a corner
/// wrongly — off the limit surface (a regular smooth corner of one such Gregory patch has
/// a tangent off the exact limit's by 0.1): the defect OpenSubdiv fixed after 3.6.0
/// (PixarAnimationStudios/OpenSubdiv pull request #1336, "Fixed rare topological bug creating
/// patches at valence-2 darts"). The vertex keeps its valence and edge at every level, so the
/// patches concerned are those with a corner on it.
fn is_valence_two_dart(t: &Topology, v: u32) -> bool {
    let v = v as usize;
    let edges = t.vertex_edges(v);
    t.vertex_faces(v).len() == 2
        && edges.len() == 2
        && edges.iter().all(|&e| t.edge_faces(e as usize).len() == 2)
        && edges
            .iter()
            .filter(|&&e| subd_mesh::tags::is_infinite(t.edge_sharpness(e as usize)))
            .count()
            == 1
}

/// Whether the patch with parameter `param`, in the (sub-)face of `at`, reads a valence-2
/// dart of the base mesh: a corner of the patch on the dart or next to it (within one patch
/// width of the dart's corner of the base face; in a face that is not a quad, any patch of
/// its sub-faces). OpenSubdiv's wrong ring at the dart also spoils the neighbouring corners'
/// tangents, whose rings hold it.
fn at_valence_two_dart(t: &Topology, scheme: &Scheme, at: &FaceParam, param: PatchParam) -> bool {
    let fv = t.face_vertices(at.face);
    let loop_scheme = *scheme == Scheme::Loop;
    if !loop_scheme && fv.len() != 4 {
        return fv.iter().any(|&v| is_valence_two_dart(t, v));
    }
    let frac = param.fraction();
    let corners: Vec<(f64, f64)> = if loop_scheme {
        [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]
            .iter()
            .map(|&(s, u)| param.unnormalize_triangle(s, u))
            .collect()
    } else {
        [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            .iter()
            .map(|&(s, u)| param.unnormalize(s, u))
            .collect()
    };
    let base: &[(f64, f64)] = if loop_scheme {
        &[(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]
    } else {
        &[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
    };
    base.iter().zip(fv).any(|(&(bu, bv), &v)| {
        is_valence_two_dart(t, v)
            && corners
                .iter()
                .any(|&(u, w)| (u - bu).abs() <= frac && (w - bv).abs() <= frac)
    })
}

/// The differences between subd's and OpenSubdiv's evaluations, with OpenSubdiv's
/// derivative conventions undone: its derivatives in patches of non-quad faces are twice
/// (first) and four times (second) the derivatives with respect to the sub-face, and its
/// second derivatives of half-turned triangles have the wrong sign.
fn eval_error(
    table: &PatchTable,
    points: &[(FaceParam, u32)],
    osd: &OsdPatchTable,
    diag: f64,
    uniform: impl FnOnce() -> Vec<DVec3>,
) -> Result<EvalErrors, String> {
    let mut errors = EvalErrors {
        strict: 0.0,
        box_caps: (0, 0.0),
        darts: (0, 0.0),
        osd_points: (0, 0.0),
    };
    let lacking = refined_points_osd_lacks(table, osd, diag, uniform);
    let keys: BTreeMap<PatchKey, usize> = osd
        .patches
        .iter()
        .enumerate()
        .map(|(k, p)| (key_of(p), k))
        .collect();
    for ((at, _), theirs) in points.iter().zip(&osd.evaluations) {
        let (a, i) = table.find(at).map_err(|e| e.to_string())?;
        let array = &table.arrays()[a];
        let param = array.params()[i];
        let place = param.place();
        let (mut d1, mut d2) = (1.0, 1.0);
        if place.non_quad {
            (d1, d2) = (0.5, 0.25);
        }
        if *table.scheme() == Scheme::Loop && param.is_triangle_rotated() {
            d2 = -d2;
        }
        let mine = table.evaluate(*at).map_err(|e| e.to_string())?;
        let ours = [
            mine.position,
            mine.du,
            mine.dv,
            mine.duu,
            mine.duv,
            mine.dvv,
        ];
        // Derivatives compared in the patch's own parameters: both sides round there and
        // scale by 2^depth per order afterwards.
        let frac = param.fraction();
        let scale = [1.0, d1, d1, d2, d2, d2];
        let own = [1.0, frac, frac, frac * frac, frac * frac, frac * frac];
        let mut worst = 0.0f64;
        for (k, (m, t)) in ours.iter().zip(theirs).enumerate() {
            worst = worst.max((*m - *t * scale[k]).length() * own[k] / diag);
        }
        let box_cap = array.kind() == PatchType::Loop && !place.regular;
        let departs = worst > 1e-12
            && reads_lacking(table, (a, i), &lacking)
            && (box_cap
                || osd_points_depart(table, (a, i), at, osd, &keys, theirs, scale, own, diag));
        if departs {
            errors.osd_points.0 += 1;
            errors.osd_points.1 = errors.osd_points.1.max(worst);
        } else if at_valence_two_dart(table.base_topology(), table.scheme(), at, param) {
            errors.darts.0 += 1;
            errors.darts.1 = errors.darts.1.max(worst);
        } else if array.kind() == PatchType::Loop && !place.regular {
            errors.box_caps.0 += 1;
            errors.box_caps.1 = errors.box_caps.1.max(worst);
        } else {
            errors.strict = errors.strict.max(worst);
        }
    }
    Ok(errors)
}

/// Compares the census and the evaluation of one mesh with every option set; one row per
/// option set.
pub fn compare_census(
    exe: &Path,
    name: &str,
    topo: &Topology,
    positions: &[DVec3],
    scheme: &Scheme,
    options: &Options,
) -> Vec<Row> {
    compare_sets(
        exe,
        name,
        topo,
        positions,
        scheme,
        options,
        &option_sets(scheme),
    )
}

/// [`compare_census`] with the option sets `sets`.
fn compare_sets(
    exe: &Path,
    name: &str,
    topo: &Topology,
    positions: &[DVec3],
    scheme: &Scheme,
    options: &Options,
    sets: &[PatchOptions],
) -> Vec<Row> {
    let diag = bbox_diagonal(positions);
    sets.iter()
        .enumerate()
        .map(|(k, po)| {
            let mut row = Row::pending(name, "patches", po.isolation as usize);
            let result = PatchTable::new(topo, positions, scheme, options, po)
                .map_err(|e| e.to_string())
                .and_then(|table| {
                    let points = eval_points(&table, topo, scheme, k as u64);
                    let osd = osd_table(exe, topo, positions, scheme, options, po, &points)?;
                    same_census(&table, &osd)?;
                    // subd's uniform refinement to the table's depth, every level.
                    let uniform = || {
                        subd_schemes::Refinement::new(
                            topo,
                            scheme.clone(),
                            options,
                            table.max_depth(),
                        )
                        .map(|r| r.refine_points(positions).into_iter().flatten().collect())
                        .unwrap_or_default()
                    };
                    let error = eval_error(&table, &points, &osd, diag, uniform)?;
                    Ok((osd.patches.len(), points.len(), error))
                });
            match result {
                Ok((n, p, errors)) => record(&mut row, po, n, p, &errors),
                Err(e) => row.problem = Some(format!("{}: {e}", option_label(po))),
            }
            row
        })
        .collect()
}

/// OpenSubdiv's patch table for the option set `po`, evaluated at `points`.
fn osd_table(
    exe: &Path,
    topo: &Topology,
    positions: &[DVec3],
    scheme: &Scheme,
    options: &Options,
    po: &PatchOptions,
    points: &[(FaceParam, u32)],
) -> Result<OsdPatchTable, String> {
    let harness_points: Vec<(u32, f64, f64)> = points
        .iter()
        .map(|(at, root)| (*root, at.u, at.v))
        .collect();
    let input = osd::encode(topo, positions, scheme, options, po.isolation.into());
    let input = osd::encode_eval_points(input, &harness_points);
    let args = harness_args(po);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    decode(&osd::run(exe, &input, &args)?, points.len())
}

/// The same patches and the same number of local points on both sides, or what differs.
fn same_census(table: &PatchTable, osd: &OsdPatchTable) -> Result<(), String> {
    let mine = subd_patches(table);
    if let Some(d) = census_difference(&osd.patches, &mine) {
        return Err(d);
    }
    if osd.local_points != table.census().local_points {
        return Err(format!(
            "{} local points vs OpenSubdiv's {}",
            table.census().local_points,
            osd.local_points
        ));
    }
    Ok(())
}

/// The row of one option set from its `n` patches, `p` evaluated points and their
/// errors: the points compared apart are counted and noted, and the strict error or the
/// box-spline caps' error beyond its tolerance is the problem.
fn record(row: &mut Row, po: &PatchOptions, n: usize, p: usize, errors: &EvalErrors) {
    row.vertices = n;
    row.error = errors.strict;
    let (in_caps, caps_error) = errors.box_caps;
    let (at_darts, dart_error) = errors.darts;
    let darts = if at_darts > 0 {
        format!(
            "; {at_darts} of them in patches at valence-2 darts, which \
             OpenSubdiv 3.5 builds off the limit (fixed upstream after 3.6.0), \
             not compared: there |Δ|/diag ≤ {dart_error:.1e}"
        )
    } else {
        String::new()
    };
    let (departing, depart_error) = errors.osd_points;
    let departs = if departing > 0 {
        format!(
            "; {departing} of them where OpenSubdiv's adaptive refinement \
             leaves its uniform one (its evaluation is subd's basis on its \
             control points, which are not uniform refinement's), not \
             compared: there |Δ|/diag ≤ {depart_error:.1e}"
        )
    } else {
        String::new()
    };
    row.note = Some(format!(
        "{}; {p} points evaluated{darts}{departs}",
        option_label(po)
    ));
    let apart = in_caps + at_darts + departing;
    if apart > 0 {
        let worst = caps_error.max(dart_error).max(depart_error);
        row.excluded = Some((apart, worst));
    }
    if errors.strict > 1e-12 {
        row.problem = Some(format!(
            "{}: evaluation off by {:.3e}",
            option_label(po),
            errors.strict
        ));
    } else if caps_error > BOX_SPLINE_CAP_TOLERANCE {
        row.problem = Some(format!(
            "{}: box-spline end caps off by {caps_error:.3e}",
            option_label(po)
        ));
    }
}

pub(crate) fn bbox_diagonal(p: &[DVec3]) -> f64 {
    let (lo, hi) = p.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(a, b), &x| (a.min(x), b.max(x)),
    );
    (hi - lo).length().max(f64::MIN_POSITIVE)
}

/// A short label of an option set.
pub fn option_label(o: &PatchOptions) -> String {
    format!(
        "isolation {} {}{}{}{}",
        o.isolation,
        o.end_caps,
        if o.single_crease {
            " single-crease"
        } else {
            ""
        },
        if o.inf_sharp { " inf-sharp" } else { "" },
        if o.legacy_sharp_corners {
            ""
        } else {
            " no-legacy-corners"
        },
    )
}

/// The census of every Catmull-Clark and Loop shape of the OpenSubdiv directory, shapes in
/// parallel, rows in shape order.
pub fn shapes(exe: &Path, dir: &Path) -> Result<Vec<Row>, String> {
    crate::conformance::per_shape(
        dir,
        |s| matches!(s, Scheme::CatmullClark | Scheme::Loop),
        |name, mesh, scheme, options| {
            compare_census(exe, name, &mesh.topology, &mesh.positions, scheme, options)
        },
    )
}

/// Real meshes beside the regression shapes, every option set: a CAD part (the gear of
/// 13,000 triangles with 2,600 infinitely sharp edges, Loop) and a piece of a laser scan
/// (the bunny of `pymeshfix`, fetched once: an open piece with a ragged boundary, under
/// Loop and, its triangles split into quads, under Catmull-Clark).
pub fn real_meshes(exe: &Path) -> Result<Vec<Row>, String> {
    let scan = scan_piece()?;
    let meshes = [
        (
            "gear_65_5_9",
            Scheme::Loop,
            subd_mesh::primitives::gear(65, 5, 9),
        ),
        ("bunny_piece", Scheme::Loop, scan.clone()),
        ("bunny_piece", Scheme::CatmullClark, scan),
    ];
    Ok(meshes
        .par_iter()
        .flat_map_iter(|(name, scheme, mesh)| {
            let label = format!(
                "{name}_{}",
                if *scheme == Scheme::Loop {
                    "loop"
                } else {
                    "catmark"
                }
            );
            let options = Options::from_hints(&mesh.hints);
            compare_census(
                exe,
                &label,
                &mesh.topology,
                &mesh.positions,
                scheme,
                &options,
            )
        })
        .collect())
}

/// The faces of the bunny scan within 12 rings of its vertex 0 (a few thousand triangles,
/// open, with the scan's irregular valences and its own holes where the ring runs out).
fn scan_piece() -> Result<subd_mesh::Mesh, String> {
    let scan = crate::meshes::scan_mesh()?;
    let t = &scan.topology;
    let from = t
        .vertex_ring(0)
        .next()
        .ok_or("the scan's vertex 0 has no neighbour")?;
    let ball = subd_mesh::neighbourhood::labelled_ball(t, &[(0, from)], 12);
    let inside: std::collections::HashSet<u32> = ball.into_iter().collect();
    let faces: Vec<u32> = (0..t.num_faces() as u32)
        .filter(|&f| {
            t.face_vertices(f as usize)
                .iter()
                .all(|v| inside.contains(v))
        })
        .collect();
    // Rebuilt from its face lists, as a file holding the piece would give it.
    let mut index = vec![u32::MAX; t.num_vertices()];
    let mut positions = Vec::new();
    let mut corners = Vec::new();
    for &f in &faces {
        for &v in t.face_vertices(f as usize) {
            if index[v as usize] == u32::MAX {
                index[v as usize] = positions.len() as u32;
                positions.push(scan.positions[v as usize]);
            }
            corners.push(index[v as usize]);
        }
    }
    let sizes = vec![3u32; faces.len()];
    let topology = subd_mesh::TopologyBuilder::new(positions.len())
        .accept_inconsistent_orientation(true)
        .build(&sizes, &corners)
        .map_err(|e| format!("bunny piece: {e}"))?;
    subd_mesh::Mesh::new(topology, positions).map_err(|e| e.to_string())
}

/// `count` random meshes (`random_mesh`, the Catmull-Clark and Loop ones), four option sets
/// each, taken in turn from [`option_sets`] so that the run covers every set.
pub fn random(exe: &Path, count: u64) -> Vec<Row> {
    (0..count)
        .into_par_iter()
        .flat_map_iter(|seed| {
            let c = crate::meshes::random::case(seed);
            if !matches!(c.scheme, Scheme::CatmullClark | Scheme::Loop) {
                return Vec::new();
            }
            let all = option_sets(&c.scheme);
            let sets: Vec<PatchOptions> = (0..4)
                .map(|k| all[(seed as usize * 4 + k) % all.len()])
                .collect();
            compare_sets(
                exe,
                &c.name,
                &c.topology,
                &c.positions,
                &c.scheme,
                &c.options,
                &sets,
            )
        })
        .collect()
}
