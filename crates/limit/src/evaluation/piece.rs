//! How one face (of the base level or of level 2) is evaluated, and its evaluation: the
//! patch kinds [`crate::eval::LimitEvaluator`] and local refinement both evaluate directly.

use glam::DVec3;
use subd_mesh::Topology;
use subd_schemes::Scheme;

use crate::LimitError;
use crate::evaluation::loop_patch::{
    LoopCornerMatrices, box_spline, loop_corner_matrices, loop_sharp_regular, tri_corner_patch,
};
use crate::evaluation::patch::{
    Derivatives, GridPoint, REGULAR_GRID, SurfacePoint, corner_patch, eval_bicubic,
    sharp_regular_grid, smooth_neighbourhood,
};
use crate::evaluation::stam::{
    CornerPatchMatrices, Projected, corner_patch_matrices, steps_to_regular,
};
use crate::limit_masks::masks;
use std::sync::Arc;

/// How one face (of the base level or of level 2) is evaluated.
#[derive(Clone, Debug)]
pub(crate) enum Piece {
    /// Bicubic B-spline over 16 control points (grid order).
    Regular([u32; 16]),
    /// Bicubic B-spline over 16 control points some of which are phantom points reflected
    /// across infinitely sharp edges or boundaries.
    SharpRegular(Box<[GridPoint; 16]>),
    /// Stam evaluation with the extraordinary vertex at corner `corner` of the face.
    Corner {
        corner: usize,
        cp: Vec<u32>,
        matrices: Arc<CornerPatchMatrices>,
    },
    /// Quartic box spline over 12 control points (Loop).
    LoopRegular(Vec<u32>),
    /// Quartic box spline over 12 control points some of which are phantom points across
    /// infinitely sharp edges or boundaries (Loop).
    LoopSharpRegular(Box<[GridPoint; 12]>),
    /// Loop eigenbasis evaluation, extraordinary vertex at corner `corner`.
    LoopCorner {
        corner: usize,
        cp: Vec<u32>,
        matrices: Arc<LoopCornerMatrices>,
    },
    /// Refined two levels (base faces only).
    Refined,
    /// Refined locally, as deep as the point needs (level-2 faces next to irregular sharp
    /// features, [`crate::local`]).
    Local,
    /// Not covered, with the reason.
    Unsupported(&'static str),
}

/// How face `f` of `t` is evaluated.
pub(crate) fn piece_of(
    t: &Topology,
    rules: &[subd_schemes::Rule],
    f: usize,
    scheme: &Scheme,
) -> Result<Piece, LimitError> {
    if *scheme == Scheme::Loop {
        return loop_piece(t, rules, f);
    }
    Ok(match piece_kind(t, rules, f) {
        Ok(p) => p,
        Err((corner, cp)) => Piece::Corner {
            corner,
            matrices: corner_patch_matrices((cp.len() - 8) / 2)?,
            cp,
        },
    })
}

/// How Loop triangle `f` of `t` is evaluated.
fn loop_piece(t: &Topology, rules: &[subd_schemes::Rule], f: usize) -> Result<Piece, LimitError> {
    if t.is_hole(f) {
        return Ok(Piece::Unsupported("the face is a hole"));
    }
    if !smooth_neighbourhood(t, rules, f) {
        // Straight infinitely sharp creases and regular boundaries are box splines with
        // phantom points; other features nearby are refined.
        return Ok(match loop_sharp_regular(t, rules, f) {
            Some(g) => Piece::LoopSharpRegular(Box::new(g)),
            None => Piece::Refined,
        });
    }
    let fv = t.face_vertices(f);
    let irregular: Vec<usize> = (0..3)
        .filter(|&c| t.vertex_faces(fv[c] as usize).len() != 6)
        .collect();
    Ok(match irregular.as_slice() {
        [] => match tri_corner_patch(t, f, 0) {
            Some(cp) => Piece::LoopRegular(cp),
            None => Piece::Refined,
        },
        [c] if t.vertex_faces(fv[*c] as usize).len() < 3 => Piece::Refined,
        [c] => match tri_corner_patch(t, f, *c) {
            Some(cp) => Piece::LoopCorner {
                corner: *c,
                matrices: loop_corner_matrices(cp.len() - 6)?,
                cp,
            },
            None => Piece::Refined,
        },
        _ => Piece::Refined,
    })
}

/// `Ok(piece)` for every kind but a corner patch, which is `Err((corner, control points))`.
fn piece_kind(
    t: &Topology,
    rules: &[subd_schemes::Rule],
    f: usize,
) -> Result<Piece, (usize, Vec<u32>)> {
    if t.is_hole(f) {
        return Ok(Piece::Unsupported("the face is a hole"));
    }
    if t.face_size(f) != 4 {
        return Ok(Piece::Refined);
    }
    if !smooth_neighbourhood(t, rules, f) {
        // Straight infinitely sharp creases, regular boundaries and sharp corners are
        // B-splines with phantom points; other features are refined (and stay unsupported
        // next to an irregular feature).
        return Ok(match sharp_regular_grid(t, rules, f) {
            Some(g) => Piece::SharpRegular(Box::new(g)),
            None => Piece::Refined,
        });
    }
    let fv = t.face_vertices(f);
    let irregular: Vec<usize> = (0..4)
        .filter(|&c| t.vertex_faces(fv[c] as usize).len() != 4)
        .collect();
    match irregular.as_slice() {
        [] => Ok(match corner_patch(t, f, 0) {
            Some(cp) => Piece::Regular(REGULAR_GRID.map(|g| cp[g])),
            None => Piece::Refined,
        }),
        [c] => match corner_patch(t, f, *c) {
            Some(cp) => Err((*c, cp)),
            None => Ok(Piece::Refined),
        },
        _ => Ok(Piece::Refined),
    }
}

/// Projected control points of every corner piece.
pub(crate) fn project_all(pieces: &[Piece], pts: &[DVec3]) -> Vec<Option<Projected>> {
    pieces.iter().map(|p| project(p, pts)).collect()
}

/// The control points of a corner piece (Stam's, Catmull-Clark or Loop) projected on its
/// eigenbasis; `None` for every other piece.
pub(crate) fn project(piece: &Piece, pts: &[DVec3]) -> Option<Projected> {
    match piece {
        Piece::Corner { cp, matrices, .. } => {
            let c: Vec<DVec3> = cp.iter().map(|&i| pts[i as usize]).collect();
            Some(matrices.project(&c))
        }
        Piece::LoopCorner { cp, matrices, .. } => {
            let c: Vec<DVec3> = cp.iter().map(|&i| pts[i as usize]).collect();
            Some(matrices.project(&c))
        }
        _ => None,
    }
}

/// Face `f` of `t` evaluated directly when it is a patch (B-spline, box spline, Stam corner),
/// `None` when it needs refining; holes are an error.
pub(crate) fn direct_evaluation(
    t: &Topology,
    rules: &[subd_schemes::Rule],
    pts: &[DVec3],
    f: usize,
    scheme: &Scheme,
    s: f64,
    tp: f64,
) -> Result<Option<SurfacePoint>, LimitError> {
    let piece = piece_of(t, rules, f, scheme)?;
    if matches!(piece, Piece::Refined | Piece::Local) {
        return Ok(None);
    }
    let projected = project_all(std::slice::from_ref(&piece), pts)
        .pop()
        .flatten();
    eval_piece(&piece, pts, projected.as_ref(), f, s, tp).map(Some)
}

/// Whether face `f` of `t` is a patch [`direct_evaluation`] evaluates (not one that needs
/// refining).
pub(crate) fn is_direct(
    t: &Topology,
    rules: &[subd_schemes::Rule],
    f: usize,
    scheme: &Scheme,
) -> Result<bool, LimitError> {
    Ok(!matches!(
        piece_of(t, rules, f, scheme)?,
        Piece::Refined | Piece::Local
    ))
}

/// A grid point's position: a vertex or a phantom combination.
fn combine(g: &GridPoint, pts: &[DVec3]) -> DVec3 {
    g.iter()
        .fold(DVec3::ZERO, |acc, &(v, w)| acc + w * pts[v as usize])
}

/// Evaluates one piece at (s, t) in its face's parameters.
pub(crate) fn eval_piece(
    piece: &Piece,
    pts: &[DVec3],
    projected: Option<&Projected>,
    face: usize,
    s: f64,
    tp: f64,
) -> Result<SurfacePoint, LimitError> {
    eval_piece_to(piece, pts, projected, face, (s, tp), Derivatives::Second)
}

/// [`eval_piece`] up to the derivatives `d`: the eigenbasis pieces leave the second
/// derivatives out (zero) for [`Derivatives::First`]; the others compute them anyway.
pub(crate) fn eval_piece_to(
    piece: &Piece,
    pts: &[DVec3],
    projected: Option<&Projected>,
    face: usize,
    (s, tp): (f64, f64),
    d: Derivatives,
) -> Result<SurfacePoint, LimitError> {
    match piece {
        Piece::Regular(grid) => {
            let g: [DVec3; 16] = std::array::from_fn(|i| pts[grid[i] as usize]);
            Ok(eval_bicubic(&g, s, tp))
        }
        Piece::SharpRegular(grid) => {
            let g: [DVec3; 16] = std::array::from_fn(|i| combine(&grid[i], pts));
            Ok(eval_bicubic(&g, s, tp))
        }
        Piece::Corner {
            corner,
            cp,
            matrices,
        } => {
            let n = (cp.len() - 8) / 2;
            // Corner frame (a, b): origin at the corner, a towards the next corner, b towards
            // the previous one; J = ∂(a, b)/∂(s, t).
            let (a, b, j) = match corner {
                0 => (s, tp, [[1.0, 0.0], [0.0, 1.0]]),
                1 => (tp, 1.0 - s, [[0.0, 1.0], [-1.0, 0.0]]),
                2 => (1.0 - s, 1.0 - tp, [[-1.0, 0.0], [0.0, -1.0]]),
                _ => (1.0 - tp, s, [[0.0, -1.0], [1.0, 0.0]]),
            };
            let q = if a == 0.0 && b == 0.0 {
                let c: Vec<DVec3> = cp.iter().map(|&i| pts[i as usize]).collect();
                at_extraordinary_vertex(&c, n)?
            } else {
                corner_value(matrices, cp, pts, projected, (a, b), d)
            };
            Ok(pull_back(&q, j))
        }
        Piece::LoopRegular(cp) => {
            let c: Vec<DVec3> = cp.iter().map(|&i| pts[i as usize]).collect();
            Ok(box_spline()?.evaluate(&c, s, tp))
        }
        Piece::LoopSharpRegular(grid) => {
            let c: Vec<DVec3> = grid.iter().map(|g| combine(g, pts)).collect();
            Ok(box_spline()?.evaluate(&c, s, tp))
        }
        Piece::LoopCorner {
            corner,
            cp,
            matrices,
        } => {
            let n = cp.len() - 6;
            // Corner frame: origin at the corner, a towards the next corner, b towards the
            // one after; J = ∂(a, b)/∂(s, t).
            let (a, b, j) = match corner {
                0 => (s, tp, [[1.0, 0.0], [0.0, 1.0]]),
                1 => (tp, 1.0 - s - tp, [[0.0, 1.0], [-1.0, -1.0]]),
                _ => (1.0 - s - tp, s, [[-1.0, -1.0], [1.0, 0.0]]),
            };
            let q = if a <= 0.0 && b <= 0.0 {
                let m = masks::loop_smooth(n);
                let apply = |r: &masks::RingMask| {
                    let mut p = r.vertex * pts[cp[0] as usize];
                    for i in 0..n {
                        p += r.edges[i] * pts[cp[1 + i] as usize];
                    }
                    p
                };
                SurfacePoint {
                    position: apply(&m.position),
                    du: apply(&m.tangent1),
                    dv: apply(&m.tangent2),
                    ..SurfacePoint::default()
                }
            } else if steps_to_regular(a.max(0.0) + b.max(0.0)).0 <= DIRECT_STEPS {
                // As for Catmull-Clark corners: the points themselves near the regular
                // sub-patches.
                let c = Projected::Points(cp.iter().map(|&i| pts[i as usize]).collect());
                matrices.evaluate_to(&c, a.max(0.0), b.max(0.0), d)?
            } else {
                matrices.evaluate_to(
                    projected.expect("corner pieces are projected"),
                    a.max(0.0),
                    b.max(0.0),
                    d,
                )?
            };
            Ok(pull_back(&q, j))
        }
        Piece::Refined | Piece::Local => unreachable!("refined pieces are resolved by the caller"),
        Piece::Unsupported(reason) => Err(LimitError::Unsupported { face, reason }),
    }
}

/// A Catmull-Clark corner piece at `(a, b)` of its corner frame, away from the vertex.
/// Within a step of the regular sub-patches the subdivision matrix applied to the points
/// themselves costs about what the eigenbasis does, without its round-off (V⁻¹ is
/// ill-conditioned at valence 3: 1e-12 in the derivatives).
fn corner_value(
    matrices: &CornerPatchMatrices,
    cp: &[u32],
    pts: &[DVec3],
    projected: Option<&Projected>,
    (a, b): (f64, f64),
    d: Derivatives,
) -> SurfacePoint {
    if steps_to_regular(a.max(b)).0 <= DIRECT_STEPS {
        let c = Projected::Points(cp.iter().map(|&i| pts[i as usize]).collect());
        matrices.evaluate_projected_to(&c, a, b, d)
    } else {
        let c = projected.expect("corner pieces are projected");
        matrices.evaluate_projected_to(c, a, b, d)
    }
}

/// Subdivision steps up to which a corner piece is evaluated from its points rather than
/// their eigenbasis projection.
const DIRECT_STEPS: i32 = 1;

/// At the extraordinary vertex itself the parametric derivatives are singular (they vanish
/// or grow without bound with the valence); the position is the limit mask's and the first
/// derivatives are the limit tangents (their directions are exact, their scale is the mask's
/// convention), second derivatives zero.
fn at_extraordinary_vertex(c: &[DVec3], n: usize) -> Result<SurfacePoint, LimitError> {
    // Valence 2 has no closed form (OpenSubdiv's is not the limit): the eigen analysis.
    let m = if n == 2 {
        crate::limit_masks::eigen::ring_limit_mask(
            &Scheme::CatmullClark,
            2,
            crate::limit_masks::eigen::RingFeature::Smooth,
        )?
    } else {
        masks::catmark_smooth(n)
    };
    let apply = |r: &masks::RingMask| {
        let mut p = r.vertex * c[0];
        for i in 0..n {
            p += r.edges[i] * c[1 + 2 * i] + r.faces[i] * c[2 + 2 * i];
        }
        p
    };
    // tangent1 runs along edge 0 = the a axis; the b axis is edge 1 of the ring only when
    // n = 4, so take the tangent towards edge 1 from the smooth tangent pair: for the normal
    // only the plane and its orientation matter.
    Ok(SurfacePoint {
        position: apply(&m.position),
        du: apply(&m.tangent1),
        dv: apply(&m.tangent2),
        ..SurfacePoint::default()
    })
}

/// Derivatives with respect to (s, t) from those with respect to (a, b), `j = ∂(a,b)/∂(s,t)`
/// (rows a, b; columns s, t).
fn pull_back(q: &SurfacePoint, j: [[f64; 2]; 2]) -> SurfacePoint {
    let (a_s, a_t, b_s, b_t) = (j[0][0], j[0][1], j[1][0], j[1][1]);
    SurfacePoint {
        position: q.position,
        du: a_s * q.du + b_s * q.dv,
        dv: a_t * q.du + b_t * q.dv,
        duu: a_s * a_s * q.duu + 2.0 * a_s * b_s * q.duv + b_s * b_s * q.dvv,
        duv: a_s * a_t * q.duu + (a_s * b_t + a_t * b_s) * q.duv + b_s * b_t * q.dvv,
        dvv: a_t * a_t * q.duu + 2.0 * a_t * b_t * q.duv + b_t * b_t * q.dvv,
    }
}
