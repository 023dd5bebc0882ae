//! The exact end caps ([`super::EndCaps::Exact`]): each irregular patch evaluated exactly
//! on its own face of the table's sparse level, so the table is the limit surface
//! everywhere. A face with one extraordinary corner is Stam's eigenbasis (Catmull-Clark or
//! Loop), a face along straight sharp features a spline with phantom points, and a face
//! next to an irregular sharp feature (or with several extraordinary corners) is refined
//! locally, as deep as the point needs (`crate::evaluation::local`).
//!
//! A sparse level keeps only the faces its patches need. A cap whose evaluation would read
//! past them (its corners' rings for a direct piece, two rings of faces for local
//! refinement) is evaluated by the whole-mesh exact evaluator instead, which is then built
//! with the table: the same surface, computed from the base level.

use glam::DVec3;
use rayon::prelude::*;
use subd_mesh::tags::{SHARPNESS_INFINITE, SHARPNESS_SMOOTH};
use subd_schemes::{Options, Scheme};

use super::array::PatchArray;
use super::levels::PatchLevel;
use super::param::PatchParam;
use crate::LimitError;
use crate::evaluation::eval::{FaceParam, WholeMeshEvaluator, WholePoints, on_base_face};
use crate::evaluation::patch::{Derivatives, SurfacePoint};
use crate::evaluation::piece::{Piece, eval_piece_to, piece_of, project};
use crate::evaluation::point_stencil::{PointStencil, single_piece};
use crate::evaluation::stam::Projected;
use crate::evaluation::support::{face_support, linear_weights};

/// How each exact patch of a table is evaluated (their points are in
/// [`super::TablePoints`]).
#[derive(Debug)]
pub(crate) struct ExactCaps {
    /// One per patch of the exact array, in its order.
    caps: Vec<Cap>,
    /// The whole-mesh exact evaluator, only when some cap needs it.
    whole: Option<WholeMeshEvaluator>,
}

/// How one exact patch is evaluated.
#[derive(Debug)]
enum Cap {
    /// On face `face` of level `level`: a piece evaluated directly, or [`Piece::Local`].
    OnLevel { level: u8, face: u32, piece: Piece },
    /// By the whole-mesh evaluator.
    Whole,
}

/// The caps' points beyond the table's own: eigenbasis projections of the corner pieces
/// and the whole-mesh evaluator's points.
#[derive(Debug, Clone)]
pub(crate) struct CapPoints {
    projected: Vec<Option<Projected>>,
    whole: Option<WholePoints>,
}

/// What the caps read of their table.
pub(crate) struct CapContext<'a> {
    pub levels: &'a [PatchLevel],
    pub level_offsets: &'a [u32],
    /// The table's points (refined vertices of every level first).
    pub points: &'a [DVec3],
    pub scheme: &'a Scheme,
    pub rules: &'a Options,
}

impl ExactCaps {
    /// The caps of `array` (the table's exact patches); `cx` needs no points.
    pub(crate) fn new(array: &PatchArray, cx: &CapContext<'_>) -> Result<ExactCaps, LimitError> {
        let caps: Vec<Cap> = array
            .faces
            .par_iter()
            .with_min_len(64)
            .map(|&(level, face)| cap_of(&cx.levels[level as usize], level, face, cx.scheme))
            .collect();
        let whole = if caps.iter().any(|c| matches!(c, Cap::Whole)) {
            let base = &cx.levels[0].topology;
            Some(WholeMeshEvaluator::new(base, cx.scheme, cx.rules)?)
        } else {
            None
        };
        Ok(ExactCaps { caps, whole })
    }

    /// The caps' points for the table points in `cx`, made from base `positions`.
    pub(crate) fn points_for(&self, cx: &CapContext<'_>, positions: &[DVec3]) -> CapPoints {
        let projected = self
            .caps
            .par_iter()
            .with_min_len(64)
            .map(|cap| match cap {
                Cap::OnLevel { level, piece, .. } => {
                    let first = cx.level_offsets[*level as usize] as usize;
                    project(piece, &cx.points[first..])
                }
                Cap::Whole => None,
            })
            .collect();
        CapPoints {
            projected,
            whole: self.whole.as_ref().map(|ev| ev.prepare(positions)),
        }
    }

    /// Exact patch `i` (placed by `param`) at `at`, up to the derivatives `d`, with respect
    /// to `at`'s (sub-)face parameters; `cap_points` are [`Self::points_for`] the points in
    /// `cx`.
    pub(crate) fn evaluate(
        &self,
        cx: &CapContext<'_>,
        cap_points: &CapPoints,
        i: usize,
        param: PatchParam,
        at: FaceParam,
        d: Derivatives,
    ) -> Result<SurfacePoint, LimitError> {
        let (level, face, piece) = match &self.caps[i] {
            Cap::OnLevel { level, face, piece } => (*level as usize, *face as usize, piece),
            Cap::Whole => {
                let ev = self.whole.as_ref().expect("whole caps have the evaluator");
                let points = cap_points.whole.as_ref().expect("and its points");
                return ev.evaluate_to(points, at, d);
            }
        };
        let (s, t, scale) = patch_local(param, *cx.scheme == Scheme::Loop, at.u, at.v);
        let first = cx.level_offsets[level] as usize;
        let end = cx.level_offsets[level + 1] as usize;
        let points = &cx.points[first..end];
        let p = match piece {
            Piece::Local => {
                let lv = &cx.levels[level];
                crate::evaluation::local::evaluate(
                    &lv.topology,
                    &lv.rules,
                    level,
                    points,
                    face,
                    cx.scheme,
                    cx.rules,
                    s,
                    t,
                )
                .map_err(|e| on_base_face(e, at.face))?
            }
            piece => eval_piece_to(
                piece,
                points,
                cap_points.projected[i].as_ref(),
                at.face,
                (s, t),
                d,
            )?,
        };
        Ok(p.scaled(scale))
    }
}

impl ExactCaps {
    /// Cap `i`'s level and piece when it is one of Stam's corner pieces (Catmull-Clark or
    /// Loop), whose values are fixed weights of its control points at each place.
    pub(crate) fn corner_piece(&self, i: usize) -> Option<(usize, &Piece)> {
        match &self.caps[i] {
            Cap::OnLevel { level, piece, .. }
                if matches!(piece, Piece::Corner { .. } | Piece::LoopCorner { .. }) =>
            {
                Some((*level as usize, piece))
            }
            _ => None,
        }
    }

    /// [`Self::evaluate`] at every place of `ats` (all in patch `i`), each the same bits:
    /// a cap refined locally shares its descent between the places
    /// ([`crate::evaluation::local::evaluate_many`]).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn evaluate_many(
        &self,
        cx: &CapContext<'_>,
        cap_points: &CapPoints,
        i: usize,
        param: PatchParam,
        ats: &[FaceParam],
        d: Derivatives,
    ) -> Result<Vec<SurfacePoint>, LimitError> {
        let (level, face) = match &self.caps[i] {
            Cap::OnLevel {
                level,
                face,
                piece: Piece::Local,
            } if ats.len() > 1 => (*level as usize, *face as usize),
            _ => {
                return ats
                    .iter()
                    .map(|&at| self.evaluate(cx, cap_points, i, param, at, d))
                    .collect();
            }
        };
        let triangle = *cx.scheme == Scheme::Loop;
        let places: Vec<(f64, f64)> = ats
            .iter()
            .map(|at| {
                let (s, t, _) = patch_local(param, triangle, at.u, at.v);
                (s, t)
            })
            .collect();
        // One patch, one map from its root: the same scale for every place.
        let (_, _, scale) = patch_local(param, triangle, ats[0].u, ats[0].v);
        let lv = &cx.levels[level];
        let first = cx.level_offsets[level] as usize;
        let end = cx.level_offsets[level + 1] as usize;
        let values = crate::evaluation::local::evaluate_many(
            &lv.topology,
            &lv.rules,
            level,
            &cx.points[first..end],
            face,
            cx.scheme,
            cx.rules,
            &places,
        )
        .map_err(|e| on_base_face(e, ats[0].face))?;
        Ok(values.into_iter().map(|p| p.scaled(scale)).collect())
    }
}

/// The weights of an exact cap at a place: over one level's vertices, or (a cap the
/// whole-mesh evaluator takes) over the base vertices already.
pub(crate) enum CapStencil {
    /// Level and `(vertex of the level, weights of position, ∂u, ∂v, ∂uu, ∂uv, ∂vv)`.
    OnLevel(usize, Vec<(u32, [f64; 6])>),
    /// Over the base vertices.
    Base(PointStencil),
}

impl ExactCaps {
    /// [`Self::evaluate`] as weights of the points it reads (linear in them, so the
    /// weights applied to any points give the evaluation to rounding).
    pub(crate) fn stencil(
        &self,
        cx: &CapContext<'_>,
        i: usize,
        param: PatchParam,
        at: FaceParam,
    ) -> Result<CapStencil, LimitError> {
        let (level, face, piece) = match &self.caps[i] {
            Cap::OnLevel { level, face, piece } => (*level as usize, *face as usize, piece),
            Cap::Whole => {
                let ev = self.whole.as_ref().expect("whole caps have the evaluator");
                return ev.stencil(at).map(CapStencil::Base);
            }
        };
        let (s, t, scale) = patch_local(param, *cx.scheme == Scheme::Loop, at.u, at.v);
        let lv = &cx.levels[level];
        let mut pairs = match piece {
            Piece::Local => crate::evaluation::local::stencil(
                &lv.topology,
                &lv.rules,
                level,
                face,
                cx.scheme,
                cx.rules,
                s,
                t,
            )
            .map_err(|e| on_base_face(e, at.face))?,
            piece => {
                let support = face_support(&lv.topology, face);
                let n = lv.topology.num_vertices();
                linear_weights(&mut Vec::new(), n, &support, |pts| {
                    single_piece(piece, pts, at.face, s, t)
                })?
            }
        };
        let factors = crate::evaluation::support::derivative_factors(scale);
        for (_, w) in &mut pairs {
            for (x, f) in w.iter_mut().zip(factors) {
                *x *= f;
            }
        }
        Ok(CapStencil::OnLevel(level, pairs))
    }
}

/// How face `face` of `level` (an exact patch's) is evaluated: on the level when what its
/// evaluation reads is whole there, else by the whole-mesh evaluator.
fn cap_of(level: &PatchLevel, depth: u8, face: u32, scheme: &Scheme) -> Cap {
    let t = &level.topology;
    let f = face as usize;
    let regular = if *scheme == Scheme::Loop { 3 } else { 4 };
    let corners_whole = |g: usize| {
        t.face_vertices(g)
            .iter()
            .all(|&v| level.is_complete(v as usize))
    };
    if t.face_size(f) != regular || !corners_whole(f) {
        return Cap::Whole;
    }
    // What the level cannot tell (and its errors) is the whole-mesh evaluator's to say.
    let piece = match piece_of(t, &level.rules, f, scheme) {
        Err(_) | Ok(Piece::Unsupported(_)) => return Cap::Whole,
        Ok(Piece::Refined | Piece::Local) => {
            // Local refinement cuts out two rings of faces: whole when every face around
            // the first ring's vertices is present.
            let ring_whole = t.face_vertices(f).iter().all(|&v| {
                t.vertex_faces(v as usize)
                    .iter()
                    .all(|&g| corners_whole(g as usize))
            });
            if !ring_whole || semi_sharp_near(t, f) {
                return Cap::Whole;
            }
            Piece::Local
        }
        Ok(piece) => piece,
    };
    Cap::OnLevel {
        level: depth,
        face,
        piece,
    }
}

/// Whether a semi-sharp edge or vertex (sharpness neither 0 nor infinite) lies on the faces
/// around face `f`'s vertices. Local refinement from a sparse level next to one departs
/// from the limit by up to 1e-10 (found on a random torus by the conformance run, cause not
/// yet found); the whole-mesh evaluator, which starts two levels down, takes those caps.
fn semi_sharp_near(t: &subd_mesh::Topology, f: usize) -> bool {
    let semi = |s: f32| s > SHARPNESS_SMOOTH && s < SHARPNESS_INFINITE;
    t.face_vertices(f).iter().any(|&v| {
        t.vertex_faces(v as usize).iter().any(|&g| {
            t.face_vertices(g as usize).iter().any(|&w| {
                semi(t.vertex_sharpness(w as usize))
                    || t.vertex_edges(w as usize)
                        .iter()
                        .any(|&e| semi(t.edge_sharpness(e as usize)))
            })
        })
    })
}

/// The patch's own parameters at `(u, v)` of its root face, and the factor its derivatives
/// take back to the root's (negative for a turned-around triangle).
pub(super) fn patch_local(param: PatchParam, triangle: bool, u: f64, v: f64) -> (f64, f64, f64) {
    let scale = 1.0 / param.fraction();
    if triangle {
        let (s, t) = param.normalize_triangle(u, v);
        let sign = if param.is_triangle_rotated() {
            -1.0
        } else {
            1.0
        };
        (s, t, sign * scale)
    } else {
        let (s, t) = param.normalize(u, v);
        (s, t, scale)
    }
}
