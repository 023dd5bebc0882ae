//! The limit check: subd's limit stencils at every vertex of one refined level against
//! OpenSubdiv's `PrimvarRefiner::Limit` there.

use subd_limit::LimitPoints;
use subd_mesh::{DVec3, Topology};
use subd_schemes::{Refinement, Scheme};

use super::{Case, MAX_LIMIT_FACE_VERTICES, Row, TOLERANCE, osd_limit};
use crate::oracles::osd;

/// Tolerance on the difference of unit normals.
const NORMAL_TOLERANCE: f64 = 1e-10;

/// Limit positions, tangents and normals of every vertex of level N against OpenSubdiv's
/// `PrimvarRefiner::Limit` there; N is the level where semi-sharp features have decayed
/// (at least 1), lowered where the mesh would grow too large (both sides then take the masks
/// of the rules at that level). Positions and tangents within 1e-12 of the bounding-box
/// diagonal, unit normals within 1e-10, except at the vertices where OpenSubdiv is not exact
/// (interior valence 2, darts on infinitely sharp edges), which are counted and reported.
pub fn compare(case: &Case) -> Row {
    let level = limit_level(case.topo, case.scheme);
    let mut row = Row::pending(case.name, "limit", level);
    let input = osd::encode(
        case.topo,
        case.positions,
        case.scheme,
        case.options,
        level as u32,
    );
    // Where OpenSubdiv crashes computing tangents (see `tangent_overflow`), compare positions.
    let (theirs, with_tangents) = match osd_limit(case.exe, &input, true) {
        Ok(l) => l,
        Err(e) => {
            row.problem = Some(format!("OpenSubdiv: {e}"));
            return row;
        }
    };
    let (topo_at, ours, skip) = match subd_limits(case, level) {
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
    let overflow = tangent_overflow(topo_at.topology(level), row.vertices);
    for &v in &skip {
        excluded[v] = true;
    }
    let sides = Sides {
        ours: &ours,
        theirs: &theirs,
        with_tangents,
    };
    let d = sides.differences(&excluded, &overflow, case.diag);
    row.error = d.err;
    row.normal_error = with_tangents.then_some(d.nerr);
    row.excluded = (!skip.is_empty()).then_some((skip.len(), d.skipped_err));
    if d.err.is_nan() || d.err > TOLERANCE || d.nerr > NORMAL_TOLERANCE {
        row.problem = Some(sides.worst_vertex(d.worst));
    }
    row
}

/// The level where semi-sharp features have decayed (at least 1), lowered while the mesh
/// would pass [`MAX_LIMIT_FACE_VERTICES`] there.
fn limit_level(topo: &Topology, scheme: &Scheme) -> usize {
    let mut level = subd_limit::levels_for_exact_limit(topo, scheme).0.max(1);
    while level > 1 && topo.num_face_vertices() << (2 * level) > MAX_LIMIT_FACE_VERTICES {
        level -= 1;
    }
    level
}

/// subd's refinement to `level`, the limits of that level's vertices, and the vertices where
/// OpenSubdiv's limit is not exact (left out of the comparison).
fn subd_limits(case: &Case, level: usize) -> Result<(Refinement, LimitPoints, Vec<usize>), String> {
    let topo_at = Refinement::new(case.topo, case.scheme.clone(), case.options, level)
        .map_err(|e| e.to_string())?;
    let (ours, skip) = subd_limit::LimitStencilTable::at_level(&topo_at, level)
        .map_err(|e| e.to_string())
        .map(|table| {
            let pts = topo_at.refine_points(case.positions);
            (
                table.apply(&pts[level]),
                subd_limit::eigen_limit_vertices(&topo_at, level),
            )
        })?;
    Ok((topo_at, ours, skip))
}

/// OpenSubdiv sizes its limit-mask buffers by `Level::getMaxValence()`, which refinement
/// sets to max(parent, 4, 2 + max edge faces) — fewer than the 2·k faces of the child of a
/// non-manifold edge with k > 2 faces. There the face weights of the first tangent run
/// into the second tangent's buffer (Far/primvarRefiner.h, `limit()`), so OpenSubdiv's
/// tangents are garbled; positions are unaffected. Tangents and normals of non-manifold
/// vertices with more faces than edges are left out of the comparison: those are `true`.
fn tangent_overflow(t: &Topology, vertices: usize) -> Vec<bool> {
    (0..vertices)
        .map(|v| t.is_non_manifold_vertex(v) && t.vertex_faces(v).len() > t.vertex_edges(v).len())
        .collect()
}

/// Both sides' limits of one level, and whether OpenSubdiv's tangents came.
struct Sides<'a> {
    ours: &'a LimitPoints,
    theirs: &'a osd::OsdLimit,
    with_tangents: bool,
}

/// The largest differences over the compared vertices.
struct Differences {
    /// Max |Δ|/diag of positions and (where compared) tangents.
    err: f64,
    /// Max difference of unit normals.
    nerr: f64,
    /// Max |Δ|/diag of the positions of the excluded vertices.
    skipped_err: f64,
    /// The vertex the problem names.
    worst: usize,
}

impl Sides<'_> {
    /// Compares every vertex not `excluded`; tangents only where OpenSubdiv gave them and
    /// they do not `overflow`.
    fn differences(&self, excluded: &[bool], overflow: &[bool], diag: f64) -> Differences {
        let (ours, theirs, with_tangents) = (self.ours, self.theirs, self.with_tangents);
        let (mut err, mut nerr, mut skipped_err) = (0.0f64, 0.0f64, 0.0f64);
        let mut worst = 0;
        for v in 0..excluded.len() {
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
        Differences {
            err,
            nerr,
            skipped_err,
            worst,
        }
    }

    /// The problem naming vertex `w`, with both sides' limits there.
    fn worst_vertex(&self, w: usize) -> String {
        let (ours, theirs) = (self.ours, self.theirs);
        format!(
            "worst vertex {w}: subd p {} t1 {} t2 {}, OpenSubdiv p {} t1 {} t2 {}",
            ours.positions[w],
            ours.tangent1[w],
            ours.tangent2[w],
            theirs.positions[w],
            theirs.tangent1[w],
            theirs.tangent2[w]
        )
    }
}
