//! `subd tessellate` against OpenSubdiv's `Bfr::SurfaceFactory` + `Bfr::Tessellation` at the
//! same uniform rate: every Bfr sample is looked up by its parameter in subd's grid and must
//! have the same position to 1e-12 of the bounding-box diagonal; a closed input must give a
//! closed, manifold tessellation.

use std::collections::HashMap;
use std::path::Path;

use subd_limit::eval::FaceParam;
use subd_limit::patches::PatchTable;
use subd_limit::tessellation::{Tessellation, tessellate_mesh};
use subd_mesh::{DVec3, Topology, TopologyBuilder};
use subd_schemes::{Options, Scheme};

use crate::conformance::row::Row;
use crate::oracles::osd;

/// The rate compared (even, so Catmull-Clark non-quads are covered too).
pub const RATE: usize = 4;

/// One Bfr sample.
struct BfrPoint {
    at: FaceParam,
    position: DVec3,
}

fn decode(bytes: &[u8]) -> Result<Vec<BfrPoint>, String> {
    let u32_at = |o: usize| -> Result<u32, String> {
        bytes
            .get(o..o + 4)
            .map(|b| u32::from_le_bytes(b.try_into().unwrap()))
            .ok_or_else(|| "Bfr output truncated".to_string())
    };
    let f64_at = |o: usize| -> Result<f64, String> {
        bytes
            .get(o..o + 8)
            .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
            .ok_or_else(|| "Bfr output truncated".to_string())
    };
    let count = u32_at(0)? as usize;
    if bytes.len() != 4 + 48 * count {
        return Err(format!(
            "Bfr output has {} bytes for {count} points",
            bytes.len()
        ));
    }
    let mut out = Vec::with_capacity(count);
    for k in 0..count {
        let o = 4 + 48 * k;
        out.push(BfrPoint {
            at: FaceParam {
                face: u32_at(o)? as usize,
                sub: u32_at(o + 4)? as usize,
                u: f64_at(o + 8)?,
                v: f64_at(o + 16)?,
            },
            position: DVec3::new(f64_at(o + 24)?, f64_at(o + 32)?, f64_at(o + 40)?),
        });
    }
    Ok(out)
}

/// Whether every edge of `t` has two faces and no vertex is non-manifold.
fn closed_manifold(t: &Topology) -> bool {
    (0..t.num_edges()).all(|e| t.edge_faces(e).len() == 2)
        && (0..t.num_vertices()).all(|v| !t.is_non_manifold_vertex(v))
}

/// The tessellation row of one mesh.
pub fn compare(
    exe: &Path,
    name: &str,
    topo: &Topology,
    positions: &[DVec3],
    scheme: &Scheme,
    options: &Options,
    diag: f64,
) -> Row {
    let mut row = Row::pending(name, "tessellate", RATE);
    // What `subd tessellate` runs: the exact limit's patch table.
    let table = match PatchTable::exact_limit(topo, positions, scheme, options) {
        Ok(t) => t,
        Err(e) => {
            row.problem = Some(format!("subd: {e}"));
            return row;
        }
    };
    let input = osd::encode(topo, positions, scheme, options, 0);
    let theirs = match osd::run(exe, &input, &["--bfr", &RATE.to_string()]).and_then(|b| decode(&b))
    {
        Ok(p) => p,
        Err(e) => {
            row.problem = Some(format!("Bfr: {e}"));
            return row;
        }
    };
    // subd's own tessellation; a mesh with a face the evaluator does not cover has none, and
    // its points are then checked by direct evaluation only.
    let ours = tessellate_mesh(topo, scheme, options, positions, RATE).ok();
    let mut tally = match_points(&theirs, ours.as_ref(), &table, scheme, diag);
    if let Err(e) = arbitrate(exe, topo, positions, scheme, options, diag, &mut tally) {
        row.problem = Some(format!("Far patch table: {e}"));
        return row;
    }
    fill_row(&mut row, topo, &theirs, ours.as_ref(), &tally);
    row
}

/// Where Bfr's points stand against subd's.
#[derive(Default)]
struct Tally {
    /// The largest difference over the compared points, / diag.
    error: f64,
    /// The compared point with the largest difference, once arbitration found one over
    /// the tolerance.
    worst: Option<FaceParam>,
    /// Points compared and found equal (or, after arbitration, charged to subd).
    compared: usize,
    /// Points at a patch corner off by more than the tolerance (reported, not checked),
    /// and their largest difference.
    corners: usize,
    corner_error: f64,
    /// Points neither subd's grid nor its evaluation covers.
    uncovered: usize,
    /// Points that are not samples of subd's grid.
    unmatched: usize,
    /// Points off by more than the tolerance, to be arbitrated by Far's patch table.
    disputed: Vec<(FaceParam, DVec3, f64)>,
    /// Disputed points where Bfr is the one off, and their largest difference.
    bfr_off: (usize, f64),
}

/// Looks each Bfr point up in subd's tessellation `ours` (or, without one, evaluates
/// `table` there) and sorts it: equal, at a corner, disputed, uncovered or unmatched.
fn match_points(
    theirs: &[BfrPoint],
    ours: Option<&Tessellation>,
    table: &PatchTable,
    scheme: &Scheme,
    diag: f64,
) -> Tally {
    let grids: HashMap<(usize, usize), subd_limit::tessellation::SampleGrid> = ours
        .map(|t| t.grids.iter().map(|g| ((g.face, g.sub), *g)).collect())
        .unwrap_or_default();
    // The sample of subd's grid at a Bfr point's parameter.
    let lookup = |t: &Tessellation, at: &FaceParam| {
        let g = grids.get(&(at.face, at.sub))?;
        let m = f64::from(g.segments);
        let (i, j) = ((at.u * m).round(), (at.v * m).round());
        let on_grid = (at.u * m - i).abs() < 1e-9 && (at.v * m - j).abs() < 1e-9;
        let triangle = *scheme == Scheme::Loop;
        (on_grid && i + if triangle { j } else { 0.0 } <= m && j <= m)
            .then(|| t.positions[t.grid_vertex(g, triangle, i as u32, j as u32) as usize])
    };
    let mut tally = Tally::default();
    for p in theirs {
        let at = p.at;
        let sample = match ours {
            Some(t) => match lookup(t, &at) {
                Some(q) => Some(q),
                None => {
                    tally.unmatched += 1;
                    continue;
                }
            },
            None => table.evaluate(at).ok().map(|s| s.position),
        };
        let Some(ours_p) = sample else {
            tally.uncovered += 1;
            continue;
        };
        let d = (ours_p - p.position).length() / diag;
        let at_corner = [at.u, at.v].iter().all(|&x| x == 0.0 || x == 1.0);
        if at_corner && d > 1e-12 {
            // Bfr's irregular patches end in Gregory caps whose corner is the limit mask at
            // the approximation level: exact at smooth and crease vertices, not always at
            // darts, corners or semi-sharp ones. Reported, not checked.
            tally.corners += 1;
            tally.corner_error = tally.corner_error.max(d);
        } else if d > 1e-12 {
            tally.disputed.push((at, ours_p, d));
        } else {
            tally.compared += 1;
            tally.error = tally.error.max(d);
        }
    }
    tally
}

/// Where Bfr and subd disagree, Far's patch table at isolation 10 (exact outside its
/// end-cap squares) decides: a point where subd agrees with it is Bfr's inexactness (its
/// irregular-patch approximation), reported, not a failure. Where Far is off too (it is at
/// some semi-sharp and dart configurations, see the eval check), a dyadic point is decided
/// by the exact limit of uniform refinement's vertex there. An error when Far's table
/// cannot be had.
fn arbitrate(
    exe: &Path,
    topo: &Topology,
    positions: &[DVec3],
    scheme: &Scheme,
    options: &Options,
    diag: f64,
    tally: &mut Tally,
) -> Result<(), String> {
    if tally.disputed.is_empty() {
        return Ok(());
    }
    let refined =
        crate::oracles::refined_limits::RefinedLimits::new(topo, positions, scheme, options);
    let refinement_agrees = |at: &FaceParam, p: DVec3| {
        let quad_or_tri = at.sub == 0 && (*scheme == Scheme::Loop || topo.face_size(at.face) == 4);
        quad_or_tri
            && refined
                .as_ref()
                .and_then(|r| r.at(at.face, at.u, at.v))
                .is_some_and(|q| (q - p).length() / diag <= 1e-12)
    };
    let far = far_positions(exe, topo, positions, scheme, options, &tally.disputed)?;
    for ((at, ours_p, d), f) in tally.disputed.iter().zip(far) {
        if (*ours_p - f).length() / diag <= 1e-12 || refinement_agrees(at, *ours_p) {
            tally.bfr_off.0 += 1;
            tally.bfr_off.1 = tally.bfr_off.1.max(*d);
        } else {
            tally.compared += 1;
            if *d > tally.error {
                tally.error = *d;
                tally.worst = Some(*at);
            }
        }
    }
    Ok(())
}

/// The row's counts, notes and problem from the tally: a closed input must also give a
/// closed, manifold tessellation.
fn fill_row(
    row: &mut Row,
    topo: &Topology,
    theirs: &[BfrPoint],
    ours: Option<&Tessellation>,
    tally: &Tally,
) {
    let error = tally.error;
    row.vertices = tally.compared;
    row.error = error;
    row.excluded = Some((tally.corners + tally.uncovered, tally.corner_error));
    let closed_input = closed_manifold(topo) && (0..topo.num_faces()).all(|f| !topo.is_hole(f));
    let mut notes = vec![format!("{} Bfr points", theirs.len())];
    if tally.bfr_off.0 > 0 {
        notes.push(format!(
            "{} where Bfr is off by up to {:.1e} × diag while subd agrees with Far's patches or, at dyadic points, with uniform refinement's limit",
            tally.bfr_off.0, tally.bfr_off.1
        ));
    }
    match ours {
        Some(t) => {
            let sizes: Vec<u32> = t.face_offsets.windows(2).map(|w| w[1] - w[0]).collect();
            let built = TopologyBuilder::new(t.positions.len()).build(&sizes, &t.face_vertices);
            if closed_input {
                match built {
                    Ok(out) if closed_manifold(&out) => notes.push("closed, manifold".into()),
                    Ok(_) => {
                        row.problem = Some("closed input, open or non-manifold tessellation".into())
                    }
                    Err(e) => row.problem = Some(format!("tessellation topology: {e}")),
                }
            }
        }
        None => notes
            .push("subd tessellate does not cover this mesh; points evaluated one by one".into()),
    }
    row.note = Some(notes.join(", "));
    if tally.unmatched > 0 && row.problem.is_none() {
        row.problem = Some(format!(
            "{} Bfr points are not samples of subd's grid",
            tally.unmatched
        ));
    }
    if row.problem.is_none() && error > 1e-12 {
        let at = tally.worst.expect("a compared point");
        row.problem = Some(format!(
            "positions differ by {error:.2e} × diag (worst at face {} sub {} ({}, {}))",
            at.face, at.sub, at.u, at.v
        ));
    }
    if theirs.is_empty() && ours.is_none_or(|t| t.grids.is_empty()) {
        row.error = 0.0;
        notes.push("no face has a limit surface (holes, or boundary interpolation none)".into());
        row.note = Some(notes.join(", "));
    }
}

/// Far's patch-table positions (isolation 10) at `points`.
fn far_positions(
    exe: &Path,
    topo: &Topology,
    positions: &[DVec3],
    scheme: &Scheme,
    options: &Options,
    points: &[(FaceParam, DVec3, f64)],
) -> Result<Vec<DVec3>, String> {
    // Ptex faces: one per quad (or Loop triangle), one per corner of other faces.
    let mut first_ptex = Vec::with_capacity(topo.num_faces());
    let mut next = 0u32;
    for f in 0..topo.num_faces() {
        first_ptex.push(next);
        let n = topo.face_size(f);
        next += if n == 4 || *scheme == Scheme::Loop {
            1
        } else {
            n as u32
        };
    }
    let queries: Vec<(u32, f64, f64)> = points
        .iter()
        .map(|(at, _, _)| (first_ptex[at.face] + at.sub as u32, at.u, at.v))
        .collect();
    let input =
        osd::encode_eval_points(osd::encode(topo, positions, scheme, options, 10), &queries);
    let out = osd::run(exe, &input, &["--eval"])?;
    Ok(osd::decode_eval(&out, queries.len())?
        .into_iter()
        .map(|d| d[0])
        .collect())
}
