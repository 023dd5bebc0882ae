//! The PIA check: subd's progressive-iterative interpolation, then OpenSubdiv's limit of the
//! result at the moving vertices, which must be their targets.

use subd_mesh::DVec3;
use subd_pia::{Moving, Pia, PiaOptions, PiaResult, Solver};
use subd_schemes::{Refinement, Scheme};

use super::{Case, MAX_LIMIT_FACE_VERTICES, Row};
use crate::oracles::osd;

/// Tolerance of the PIA check: OpenSubdiv's limit of subd's interpolating mesh must hit the
/// moving targets within this fraction of the bounding-box diagonal.
const PIA_TOLERANCE: f64 = 1e-9;

/// Local PIA (every third vertex fixed, the rest moving) with subd, then OpenSubdiv's
/// `PrimvarRefiner::Limit` of the result: the moving vertices' limits must equal their
/// targets. Vertices where OpenSubdiv's limit is not exact (darts, valence 2) are left out,
/// and so are meshes whose limit matrix is singular (no interpolant exists).
pub fn compare(case: &Case) -> Row {
    let Case {
        exe,
        name,
        topo,
        positions,
        scheme,
        options,
        ..
    } = *case;
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
    let Some(result) = solve(&pia, positions, &moving) else {
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
    let hits = Hits::measure(case, &result, &theirs.positions, &flags, &inexact);
    if let Some(v) = hits.fixed_moved {
        row.problem = Some(format!("fixed vertex {v} moved"));
    }
    row.vertices = nv - hits.left_out;
    row.error = hits.err;
    row.note = Some(format!(
        "{:?}, {} iterations{}",
        result.method,
        result.iterations,
        if hits.left_out > 0 {
            format!(
                ", {} moving vertices where OpenSubdiv's limit is inexact left out",
                hits.left_out
            )
        } else {
            String::new()
        }
    ));
    if row.problem.is_none() && (hits.err.is_nan() || hits.err > PIA_TOLERANCE) {
        row.problem = Some(format!("worst vertex {}", hits.worst));
    }
    row
}

/// A converged interpolant: the automatic solver's, else the direct one's.
fn solve(pia: &Pia, positions: &[DVec3], moving: &Moving) -> Option<PiaResult> {
    [Solver::Auto, Solver::Direct]
        .into_iter()
        .find_map(|solver| {
            let opts = PiaOptions {
                solver,
                tol: 1e-11,
                max_iter: 5000,
            };
            pia.solve(positions, moving, &opts)
                .ok()
                .filter(|r| r.converged)
        })
}

/// How close OpenSubdiv's limits come to the targets.
struct Hits {
    /// Max |Δ|/diag over the moving vertices compared.
    err: f64,
    /// The moving vertex of `err`.
    worst: usize,
    /// Moving vertices left out: OpenSubdiv's limit is inexact there.
    left_out: usize,
    /// The last fixed vertex that the solve moved, if any.
    fixed_moved: Option<usize>,
}

impl Hits {
    /// Compares OpenSubdiv's `limits` of the moving vertices (`flags`) with their targets,
    /// leaving the `inexact` ones out, and checks that the fixed ones kept their positions.
    fn measure(
        case: &Case,
        result: &PiaResult,
        limits: &[DVec3],
        flags: &[bool],
        inexact: &[usize],
    ) -> Hits {
        let (positions, nv) = (case.positions, case.topo.num_vertices());
        let mut skip = vec![false; nv];
        for &v in inexact.iter().filter(|&&v| v < nv) {
            skip[v] = true;
        }
        let mut hits = Hits {
            err: 0.0,
            worst: 0,
            left_out: 0,
            fixed_moved: None,
        };
        for v in 0..nv {
            if !flags[v] {
                if result.points[v] != positions[v] {
                    hits.fixed_moved = Some(v);
                }
                continue;
            }
            if skip[v] {
                hits.left_out += 1;
                continue;
            }
            let d = (limits[v] - positions[v]).abs().max_element() / case.diag;
            if d > hits.err || d.is_nan() {
                (hits.err, hits.worst) = (d, v);
            }
        }
        hits
    }
}
