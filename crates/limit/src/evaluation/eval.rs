//! Exact evaluation of the Catmull-Clark limit surface at any (face, u, v).
//!
//! **Parameterisation** (OpenSubdiv's, so values can be compared with its patch evaluation):
//! a quad with vertices v0 v1 v2 v3 has `(0,0) = v0`, `(1,0) = v1`, `(1,1) = v2`,
//! `(0,1) = v3`; a face with n ≠ 4 vertices is split into n sub-faces, sub-face k being the
//! quad at corner k after one refinement step: `(0,0)` at vertex k, `(1,0)` at the midpoint
//! of edge k → k+1, `(0,1)` at the midpoint of edge k−1 → k, `(1,1)` at the centroid.
//! Derivatives are with respect to these (sub-)face parameters.
//!
//! **Method.** A face whose neighbourhood is regular is a bicubic B-spline patch; a face with
//! one extraordinary corner (and smooth, regular other corners) is evaluated with Stam's
//! eigenbasis ([`crate::stam`]). Any other face (several extraordinary corners, non-quads)
//! is refined two levels, after which each of its pieces is one of these two; the value is
//! exact either way (no end-cap approximation).
//!
//! Loop triangles (`(0,0) = v0`, `(1,0) = v1`, `(0,1) = v2`, barycentric
//! `(1 − u − v, u, v)`) are quartic box-spline patches where regular (with phantom points
//! along straight infinitely sharp creases and regular boundaries) and Stam's Loop
//! eigenbasis at one extraordinary corner ([`crate::loop_patch`]).
//!
//! Catmull-Clark faces along straight infinitely sharp creases, regular boundaries (boundary
//! vertices of valence 3) and sharp corners are B-spline patches with phantom points
//! ([`crate::patch::sharp_regular_grid`]); faces with other sharp features are refined two
//! levels like irregular faces, and the level-2 faces that are still next to an irregular
//! sharp feature (darts, crease or boundary vertices of irregular valence, semi-sharp creases
//! not yet decayed, Loop crease and boundary vertices of irregular valence) are refined
//! further, locally and only as deep as the point needs ([`crate::local`]).
//!
//! **Not on the surface** ([`LimitError::Unsupported`]): holes, and non-manifold
//! configurations that a local cut cannot reproduce (repeated edge instances).

use glam::DVec3;
use subd_mesh::Topology;
use subd_schemes::{Options, Refinement, Scheme};

use crate::LimitError;
use crate::evaluation::child_param::{quadrant, tri_child};
use crate::evaluation::loop_patch::box_spline;
use crate::evaluation::patch::{Derivatives, SurfacePoint};
use crate::evaluation::piece::{Piece, eval_piece_to, piece_of, project_all};
use crate::evaluation::stam::Projected;

/// A place on the limit surface: base face, sub-face (for a Catmull-Clark face that is not a
/// quad; 0 otherwise) and parameters in `[0, 1]²`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceParam {
    /// Base face.
    pub face: usize,
    /// Sub-face of a non-quad face (its corner index); 0 for quads.
    pub sub: usize,
    /// First parameter.
    pub u: f64,
    /// Second parameter.
    pub v: f64,
}

/// The exact limit evaluated from the base mesh and two uniform levels of the whole mesh
/// (where some face needs them): what [`crate::eval::LimitEvaluator`] was before it ran on a
/// patch table, kept for what is not evaluated on the table yet (point stencils, the pieces
/// of each face, face-varying channels) and for the exact caps the table's sparse levels
/// cannot evaluate.
#[derive(Debug)]
pub(crate) struct WholeMeshEvaluator {
    pub(crate) scheme: Scheme,
    pub(crate) options: Options,
    pub(crate) base: Topology,
    pub(crate) base_pieces: Vec<Piece>,
    /// Two levels of refinement, when some base face needs them.
    pub(crate) refined: Option<Refinement>,
    pub(crate) level2_pieces: Vec<Piece>,
}

/// Control points of every level the evaluator reads, for one set of base positions, with
/// the corner patches' points already projected on their eigenbases.
#[derive(Clone, Debug)]
pub(crate) struct WholePoints {
    base: Vec<DVec3>,
    level2: Vec<DVec3>,
    base_projected: Vec<Option<Projected>>,
    level2_projected: Vec<Option<Projected>>,
}

impl WholeMeshEvaluator {
    /// Prepares evaluation on `topology` (the rules of `options`; Catmull-Clark only).
    pub fn new(
        topology: &Topology,
        scheme: &Scheme,
        options: &Options,
    ) -> Result<Self, LimitError> {
        if crate::masks_scheme(scheme, false)? == Scheme::Loop {
            box_spline()?;
        }
        let r0 = Refinement::new(topology, scheme.clone(), options, 0)?;
        let base = r0.topology(0).clone();
        let rules0 = r0.vertex_rules(0);
        let base_pieces = (0..base.num_faces())
            .map(|f| piece_of(&base, rules0, f, scheme))
            .collect::<Result<Vec<_>, _>>()?;
        let (refined, level2_pieces) = if base_pieces.iter().any(|p| matches!(p, Piece::Refined)) {
            let r = Refinement::new(topology, scheme.clone(), options, 2)?;
            let t1 = r.topology(1);
            let t2 = r.topology(2);
            let rules2 = r.vertex_rules(2);
            // Only the level-2 descendants of the faces that need them are classified.
            let mut pieces = vec![Piece::Unsupported("not a refined face"); t2.num_faces()];
            for f in (0..base.num_faces()).filter(|&f| matches!(base_pieces[f], Piece::Refined)) {
                let children = base.face_offsets()[f] as usize..base.face_offsets()[f + 1] as usize;
                let children = if *scheme == Scheme::Loop {
                    4 * f..4 * f + 4
                } else {
                    children
                };
                for c in children {
                    let grand = t1.face_offsets()[c] as usize..t1.face_offsets()[c + 1] as usize;
                    let grand = if *scheme == Scheme::Loop {
                        4 * c..4 * c + 4
                    } else {
                        grand
                    };
                    for g in grand {
                        pieces[g] = match piece_of(t2, rules2, g, scheme)? {
                            Piece::Refined => Piece::Local,
                            p => p,
                        };
                    }
                }
            }
            (Some(r), pieces)
        } else {
            (None, Vec::new())
        };
        Ok(WholeMeshEvaluator {
            scheme: scheme.clone(),
            options: *options,
            base,
            base_pieces,
            refined,
            level2_pieces,
        })
    }

    /// The control points for base positions `points` (one per base vertex).
    ///
    /// # Panics
    /// If `points.len()` is not the number of base vertices.
    pub fn prepare(&self, points: &[DVec3]) -> WholePoints {
        assert_eq!(
            points.len(),
            self.base.num_vertices(),
            "one point per base vertex"
        );
        let level2 = match &self.refined {
            Some(r) => r.refine_points(points).pop().expect("level 2"),
            None => Vec::new(),
        };
        WholePoints {
            base_projected: project_all(&self.base_pieces, points),
            level2_projected: project_all(&self.level2_pieces, &level2),
            base: points.to_vec(),
            level2,
        }
    }

    /// Checks `at` against the topology: face and sub-face in range, parameters in [0, 1].
    pub fn check(&self, at: &FaceParam) -> Result<(), LimitError> {
        check_param(&self.base, &self.scheme, at)
    }

    /// The limit surface at `at`: position and first and second derivatives.
    pub fn evaluate(
        &self,
        points: &WholePoints,
        at: FaceParam,
    ) -> Result<SurfacePoint, LimitError> {
        self.evaluate_to(points, at, Derivatives::Second)
    }

    /// [`Self::evaluate`] up to the derivatives `d` (with [`Derivatives::First`] the
    /// eigenbasis pieces leave the second derivatives zero: half their work).
    pub(crate) fn evaluate_to(
        &self,
        points: &WholePoints,
        at: FaceParam,
        d: Derivatives,
    ) -> Result<SurfacePoint, LimitError> {
        self.check(&at)?;
        match &self.base_pieces[at.face] {
            Piece::Refined => {
                let r = self.refined.as_ref().expect("refined when a face needs it");
                let (f2, s2, t2, scale) = self.level2_location(&at);
                debug_assert!(f2 < r.topology(2).num_faces());
                if let Piece::Local = self.level2_pieces[f2] {
                    let p = crate::evaluation::local::evaluate(
                        r.topology(2),
                        r.vertex_rules(2),
                        crate::evaluation::local::LIMIT_EVALUATOR_LEVEL,
                        &points.level2,
                        f2,
                        &self.scheme,
                        &self.options,
                        s2,
                        t2,
                    )
                    // Name the base face, not the level-2 one.
                    .map_err(|e| on_base_face(e, at.face))?;
                    return Ok(p.scaled(scale));
                }
                let p = eval_piece_to(
                    &self.level2_pieces[f2],
                    &points.level2,
                    points.level2_projected[f2].as_ref(),
                    at.face,
                    (s2, t2),
                    d,
                )?;
                Ok(p.scaled(scale))
            }
            piece => eval_piece_to(
                piece,
                &points.base,
                points.base_projected[at.face].as_ref(),
                at.face,
                (at.u, at.v),
                d,
            ),
        }
    }
    /// The level-2 face holding `at` of a base face that is refined, its parameters there,
    /// and the scale of the map from the base (sub-)face's parameters to the level-2 face's.
    pub(crate) fn level2_location(&self, at: &FaceParam) -> (usize, f64, f64, f64) {
        let r = self.refined.as_ref().expect("refined when a face needs it");
        let (p, scale) = descend(r, 2, *at);
        (p.face, p.u, p.v, scale)
    }
}

/// Checks `at` against `base`: face and sub-face in range, parameters in [0, 1] (and in the
/// triangle for Loop).
pub(crate) fn check_param(
    base: &Topology,
    scheme: &Scheme,
    at: &FaceParam,
) -> Result<(), LimitError> {
    let nf = base.num_faces();
    if at.face >= nf {
        return Err(LimitError::Param(format!(
            "face {} out of range (the mesh has {nf} faces)",
            at.face
        )));
    }
    let size = base.face_size(at.face);
    let subs = if size == 4 || *scheme == Scheme::Loop {
        1
    } else {
        size
    };
    if at.sub >= subs {
        return Err(LimitError::Param(format!(
            "sub-face {} out of range (face {} has {subs})",
            at.sub, at.face
        )));
    }
    if !(0.0..=1.0).contains(&at.u) || !(0.0..=1.0).contains(&at.v) {
        return Err(LimitError::Param(format!(
            "parameters ({}, {}) outside [0, 1]",
            at.u, at.v
        )));
    }
    if *scheme == Scheme::Loop && at.u + at.v > 1.0 + 1e-12 {
        return Err(LimitError::Param(format!(
            "parameters ({}, {}) outside the triangle u + v ≤ 1",
            at.u, at.v
        )));
    }
    Ok(())
}

/// `e` naming base face `face` when it names a face (errors of local evaluation name the
/// refined face they met).
pub(crate) fn on_base_face(e: LimitError, face: usize) -> LimitError {
    match e {
        LimitError::Unsupported { reason, .. } => LimitError::Unsupported { face, reason },
        e => e,
    }
}

/// The vertex of level `level` of `r` at the dyadic parameter (u, v) of base face `face` (a
/// quad for Catmull-Clark, a triangle for Loop), following the child faces that hold the
/// point as [`LimitEvaluator::evaluate`](crate::eval::LimitEvaluator::evaluate) does; `None` when (u, v) is not a corner at that
/// level (not a multiple of 2^-level) or the face is not a quad or triangle.
pub fn dyadic_vertex(r: &Refinement, level: usize, face: usize, u: f64, v: f64) -> Option<usize> {
    let loop_scheme = *r.scheme() == Scheme::Loop;
    if r.topology(0).face_size(face) != if loop_scheme { 3 } else { 4 } {
        return None;
    }
    let at = FaceParam { face, sub: 0, u, v };
    let (f, corner) = dyadic_corner(r, level, at)?;
    Some(r.topology(level).face_vertices(f)[corner] as usize)
}

/// The face of level `level` (at least 1 for a Catmull-Clark face that is not a quad) of `r`
/// whose corner is at `at`, and that corner, following the child faces that hold the point as
/// [`LimitEvaluator::evaluate`](crate::eval::LimitEvaluator::evaluate) does (a sub-face of a face that is not a quad is its level-1
/// child); `None` when `at` is not a corner at that level.
pub fn dyadic_corner(r: &Refinement, level: usize, at: FaceParam) -> Option<(usize, usize)> {
    let loop_scheme = *r.scheme() == Scheme::Loop;
    let (
        FaceParam {
            face: f,
            u: s,
            v: t,
            ..
        },
        _,
    ) = descend(r, level, at);
    let size = r.topology(level).face_size(f);
    let corner = match (s, t) {
        (0.0, 0.0) => 0,
        (1.0, 0.0) => 1,
        (0.0, 1.0) if loop_scheme => 2,
        (1.0, 1.0) if !loop_scheme => 2,
        (0.0, 1.0) => 3,
        _ => return None,
    };
    (corner < size).then_some((f, corner))
}

/// The face of `level` of `r` holding base point `at`, its parameters there, and the scale
/// of the map from the base (sub-)face's parameters to that face's.
pub(crate) fn descend(r: &Refinement, level: usize, at: FaceParam) -> (FaceParam, f64) {
    let (mut f, mut s, mut t, mut scale) = (at.face, at.u, at.v, 1.0);
    for l in 0..level {
        if *r.scheme() == Scheme::Loop {
            let (j, a, b, k) = tri_child(s, t.min(1.0 - s));
            (f, s, t, scale) = (4 * f + j, a, b, scale * k);
        } else {
            let first = r.topology(l).face_offsets()[f] as usize;
            if r.topology(l).face_size(f) == 4 {
                let (j, a, b) = quadrant(s, t);
                (f, s, t, scale) = (first + j, a, b, 2.0 * scale);
            } else {
                // A sub-face is its level-1 child, with the same parameters.
                f = first + at.sub;
            }
        }
    }
    let p = FaceParam {
        face: f,
        sub: 0,
        u: s,
        v: t,
    };
    (p, scale)
}
