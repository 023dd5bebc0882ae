//! The evaluation check: subd's exact limit evaluation at points of every ptex face against
//! OpenSubdiv's patch table at isolation level 10.

use std::collections::HashMap;

use subd_limit::eval::FaceParam;
use subd_limit::patch::SurfacePoint;
use subd_limit::patches::PatchTable;
use subd_mesh::{DVec3, Topology};
use subd_schemes::{Refinement, Rule, Scheme};

use super::{Case, Row, TOLERANCE};
use crate::oracles::osd;
use crate::oracles::refined_limits::RefinedLimits;

/// OpenSubdiv's isolation level for the evaluation check.
const ISOLATION: u32 = 10;

/// Unit-normal tolerance of the evaluation check (scaled by the distance to the nearest
/// feature): a point evaluated k levels of local refinement down carries derivative
/// round-off multiplied by 2^k, on both sides.
const EVAL_NORMAL_TOLERANCE: f64 = 1e-9;

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
/// of the bounding-box diagonal and unit normals to 1e-9 (scaled). Inside, OpenSubdiv has a
/// Gregory end cap; the largest difference there is reported, not checked. Holes and
/// uncovered faces are counted and left out. Where OpenSubdiv differs but subd's face equals
/// uniform refinement at dyadic points, the point is counted as OpenSubdiv's inexactness, not
/// a failure.
pub fn compare(case: &Case) -> Row {
    let Case {
        topo,
        positions,
        scheme,
        options,
        ..
    } = *case;
    let mut row = Row::pending(case.name, "eval", ISOLATION as usize);
    // What `subd eval` runs: the exact limit's patch table.
    let table = match PatchTable::exact_limit(topo, positions, scheme, options) {
        Ok(t) => t,
        Err(e) => {
            row.problem = Some(format!("subd: {e}"));
            return row;
        }
    };
    let prepared = match Refinement::new(topo, scheme.clone(), options, 0) {
        Ok(r) => r,
        Err(e) => {
            row.problem = Some(format!("subd: {e}"));
            return row;
        }
    };
    let corners = Corners {
        t0: prepared.topology(0),
        rules0: prepared.vertex_rules(0),
        scheme,
    };
    let samples = match sample_faces(case, &table, &corners) {
        Ok(s) => s,
        Err(e) => {
            row.problem = Some(e);
            return row;
        }
    };
    row.vertices = samples.points.len();
    row.excluded = Some((samples.uncovered, 0.0));
    if samples.points.is_empty() {
        row.error = 0.0;
        return row;
    }
    let theirs = match opensubdiv(case, &samples.points) {
        Ok(t) => t,
        Err(e) => {
            row.problem = Some(format!("OpenSubdiv: {e}"));
            return row;
        }
    };
    Comparison::measure(case, &table, &samples.points, &theirs).into_row(row, &samples, &theirs)
}

/// Which base vertices OpenSubdiv's patches isolate and cap at level 10.
struct Corners<'a> {
    t0: &'a Topology,
    rules0: &'a [Rule],
    scheme: &'a Scheme,
}

impl Corners<'_> {
    /// Irregular: anything but a smooth vertex of the regular valence or (Catmull-Clark) a
    /// vertex on a straight infinitely sharp crease, regular boundary or sharp corner — the
    /// vertices OpenSubdiv's patches isolate and cap at level 10. Darts, turning creases and
    /// semi-sharp vertices count as irregular.
    fn irregular(&self, v: u32) -> bool {
        let (t0, rules0) = (self.t0, self.rules0);
        let regular_valence = if *self.scheme == Scheme::Loop { 6 } else { 4 };
        let v = v as usize;
        let smooth_regular = t0.vertex_faces(v).len() == regular_valence
            && !t0.is_boundary_vertex(v)
            && rules0[v] == Rule::Smooth
            && t0.vertex_sharpness(v) == 0.0
            && t0
                .vertex_edges(v)
                .iter()
                .all(|&e| t0.edge_sharpness(e as usize) == 0.0);
        let sharp_regular = *self.scheme == Scheme::CatmullClark
            && subd_limit::patch::regular_sharp_corner(t0, rules0, v);
        !(smooth_regular || sharp_regular)
    }
}

/// One point subd evaluated.
struct Sample {
    ours: SurfacePoint,
    /// (ptex face, u, v), as OpenSubdiv is asked.
    query: (u32, f64, f64),
    /// Inside the end-cap square of an irregular corner.
    inside: bool,
    /// L∞ distance to the nearest irregular corner.
    dist: f64,
    /// The smaller of `dist` and the distance to a sharp edge of the ptex face.
    feature_dist: f64,
    /// The (face, sub-face) evaluated.
    face: (usize, usize),
}

/// The points of every ptex face, and how many points no patch covers.
struct Samples {
    points: Vec<Sample>,
    uncovered: usize,
}

/// [`EVAL_PARAMS`] on every ptex face, in ptex order (Loop triangles, quads, and the
/// sub-faces of other Catmull-Clark faces).
fn sample_faces(case: &Case, table: &PatchTable, corners: &Corners) -> Result<Samples, String> {
    let loop_scheme = *case.scheme == Scheme::Loop;
    let mut samples = Samples {
        points: Vec::new(),
        uncovered: 0,
    };
    let mut ptex = 0u32;
    for f in 0..case.topo.num_faces() {
        let n = case.topo.face_vertices(f).len();
        let subs = if n == 4 || loop_scheme { 1 } else { n };
        for sub in 0..subs {
            let face = PtexFace::new(case.topo, corners, loop_scheme, f, sub);
            for &(u, v) in &EVAL_PARAMS {
                // A Loop triangle's parameters are barycentric: fold the square onto it.
                let (u, v) = if loop_scheme && u + v > 1.0 {
                    (1.0 - v, 1.0 - u)
                } else {
                    (u, v)
                };
                match table.evaluate(FaceParam { face: f, sub, u, v }) {
                    Ok(p) => samples.points.push(face.sample(p, ptex, u, v)),
                    Err(subd_limit::LimitError::Unsupported { .. }) => samples.uncovered += 1,
                    Err(e) => return Err(format!("subd: face {f}: {e}")),
                }
            }
            ptex += 1;
        }
    }
    Ok(samples)
}

/// A ptex face: its base face, which of its sub-faces, and its features.
struct PtexFace<'a> {
    f: usize,
    sub: usize,
    /// The base face's vertex count.
    n: usize,
    loop_scheme: bool,
    /// The irregular corners of this ptex face, in its (u, v).
    corners: Vec<(f64, f64)>,
    /// The size of the end-cap squares at those corners.
    near: f64,
    t0: &'a Topology,
}

impl<'a> PtexFace<'a> {
    fn new(
        topo: &Topology,
        irregular: &Corners<'a>,
        loop_scheme: bool,
        f: usize,
        sub: usize,
    ) -> PtexFace<'a> {
        let fv = topo.face_vertices(f);
        let n = fv.len();
        let at_irregular = |square: &[(f64, f64)]| -> Vec<(f64, f64)> {
            square
                .iter()
                .zip(fv)
                .filter(|&(_, &v)| irregular.irregular(v))
                .map(|(&c, _)| c)
                .collect()
        };
        let corners = if loop_scheme {
            at_irregular(&[(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)])
        } else if n == 4 {
            at_irregular(&[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)])
        } else {
            // A sub-face's (1, 1) is the face centre, of valence n.
            let mut c = vec![(1.0, 1.0)];
            if irregular.irregular(fv[sub]) {
                c.push((0.0, 0.0));
            }
            c
        };
        let near = 1.0 / f64::from(1u32 << ISOLATION);
        // A sub-face is already one level down, so its end caps are twice as large.
        let near = if n == 4 || loop_scheme {
            near
        } else {
            2.0 * near
        };
        PtexFace {
            f,
            sub,
            n,
            loop_scheme,
            corners,
            near,
            t0: irregular.t0,
        }
    }

    /// subd's point `p` at (u, v) of this face, numbered `ptex`, with its distances to the
    /// features that drive local refinement.
    fn sample(&self, p: SurfacePoint, ptex: u32, u: f64, v: f64) -> Sample {
        let (n, sub) = (self.n, self.sub);
        // L∞ distance to the nearest irregular corner.
        let dist = self
            .corners
            .iter()
            .map(|&(cu, cv)| (u - cu).abs().max((v - cv).abs()))
            .fold(f64::INFINITY, f64::min);
        // Distance to each sharp edge (boundaries included) of the ptex face.
        let fe = self.t0.face_edges(self.f);
        let sharp = |k: usize| self.t0.edge_sharpness(fe[k] as usize) > 0.0;
        let edges: Vec<(usize, f64)> = if self.loop_scheme {
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
        Sample {
            ours: p,
            query: (ptex, u, v),
            inside: dist < self.near,
            dist,
            // Derivative round-off grows with the depth of local refinement, which next to a
            // sharp edge is driven by the distance to it.
            feature_dist: dist.min(strip),
            face: (self.f, sub),
        }
    }
}

/// OpenSubdiv's position and derivatives at every sample.
fn opensubdiv(case: &Case, samples: &[Sample]) -> Result<Vec<[DVec3; 6]>, String> {
    let queries: Vec<(u32, f64, f64)> = samples.iter().map(|s| s.query).collect();
    let input = osd::encode_eval_points(
        osd::encode(
            case.topo,
            case.positions,
            case.scheme,
            case.options,
            ISOLATION,
        ),
        &queries,
    );
    osd::run(case.exe, &input, &["--eval"]).and_then(|b| osd::decode_eval(&b, queries.len()))
}

/// Where OpenSubdiv differs, whether subd's face agrees with uniform refinement at dyadic
/// points (the reference built once, each face checked once).
struct Verifier<'a> {
    case: &'a Case<'a>,
    table: &'a PatchTable,
    reference: Option<Option<RefinedLimits>>,
    checked_faces: HashMap<(usize, usize), bool>,
}

impl Verifier<'_> {
    fn agrees(&mut self, face: (usize, usize)) -> bool {
        let c = self.case;
        let reference = self
            .reference
            .get_or_insert_with(|| RefinedLimits::new(c.topo, c.positions, c.scheme, c.options));
        let table = self.table;
        *self.checked_faces.entry(face).or_insert_with(|| {
            reference
                .as_ref()
                .is_some_and(|r| r.agrees(table, face, c.diag))
        })
    }
}

/// The differences over the samples outside the end-cap squares, and what was left out.
struct Comparison {
    /// Max |Δ|/diag of positions.
    err: f64,
    /// Max difference of unit normals, scaled by min(1, distance to the nearest feature).
    nerr: f64,
    /// Max |Δ|/diag inside the end-cap squares (reported, not checked).
    inside_err: f64,
    /// Points where OpenSubdiv is off but subd agrees with uniform refinement.
    osd_inexact: usize,
    /// Points where a tangent vanishes: normals not compared.
    folds: usize,
    /// The first point off in position, and the first off in normal.
    worst: Option<usize>,
    worst_normal: Option<usize>,
}

impl Comparison {
    /// Normals come from derivatives, whose round-off (on both sides) grows like 1/δ at
    /// distance δ from an extraordinary vertex or the sharp edge that forces local
    /// refinement: the normal bound is 1e-9 · max(1, 1/δ). `nerr` is the largest normal
    /// difference divided by that factor.
    fn measure(case: &Case, table: &PatchTable, samples: &[Sample], theirs: &[[DVec3; 6]]) -> Self {
        let mut c = Comparison {
            err: 0.0,
            nerr: 0.0,
            inside_err: 0.0,
            osd_inexact: 0,
            folds: 0,
            worst: None,
            worst_normal: None,
        };
        let mut verifier = Verifier {
            case,
            table,
            reference: None,
            checked_faces: HashMap::new(),
        };
        for (i, (s, t)) in samples.iter().zip(theirs).enumerate() {
            let p = &s.ours;
            let d = (p.position - t[0]).abs().max_element() / case.diag;
            if s.inside {
                c.inside_err = c.inside_err.max(d);
                continue;
            }
            // Where OpenSubdiv is not exact either (seen on Loop meshes with semi-sharp
            // creases next to holes), subd's face is checked against uniform refinement.
            if d > TOLERANCE && !d.is_nan() && verifier.agrees(s.face) {
                c.osd_inexact += 1;
                continue;
            }
            if d.is_nan() || d > TOLERANCE {
                c.worst.get_or_insert(i);
            }
            c.err = if d.is_nan() || c.err.is_nan() {
                f64::NAN
            } else {
                c.err.max(d)
            };
            let on = t[1].cross(t[2]);
            // Where a tangent vanishes (the surface folds over, as back-to-back faces do along
            // their shared edges) the normal is undefined: either side's is rounding.
            let vanishes = |a: DVec3, b: DVec3| {
                let (a, b) = (a.length(), b.length());
                a.min(b) <= 1e-9 * a.max(b)
            };
            if vanishes(p.du, p.dv) || vanishes(t[1], t[2]) {
                c.folds += 1;
                continue;
            }
            if on.length() > 1e-12 * t[1].length() * t[2].length() && p.normal() != DVec3::ZERO {
                let dn = (p.normal() - on.normalize()).abs().max_element()
                    * s.dist.min(s.feature_dist).min(1.0);
                if dn > EVAL_NORMAL_TOLERANCE {
                    c.worst_normal.get_or_insert(i);
                }
                c.nerr = c.nerr.max(dn);
            }
        }
        c
    }

    /// Fills the row: errors, what was left out, and the worst point named.
    fn into_row(self, mut row: Row, samples: &Samples, theirs: &[[DVec3; 6]]) -> Row {
        row.error = self.err;
        row.normal_error = Some(self.nerr);
        row.excluded = Some((samples.uncovered, self.inside_err));
        let mut notes = Vec::new();
        if self.osd_inexact > 0 {
            notes.push(format!(
                "{} points where OpenSubdiv is off but subd's face agrees with uniform refinement at dyadic points",
                self.osd_inexact
            ));
        }
        if self.folds > 0 {
            notes.push(format!(
                "{} points where a tangent vanishes (a fold): normals not compared",
                self.folds
            ));
        }
        if !notes.is_empty() {
            row.note = Some(notes.join("; "));
        }
        if let Some(worst) = self.worst.or(self.worst_normal) {
            let (s, t) = (&samples.points[worst], &theirs[worst]);
            let q = s.query;
            row.problem = Some(format!(
                "worst point ptex {} ({}, {}): subd {} n {}, OpenSubdiv {} n {}",
                q.0,
                q.1,
                q.2,
                s.ours.position,
                s.ours.normal(),
                t[0],
                t[1].cross(t[2]).normalize_or_zero()
            ));
        }
        row
    }
}
