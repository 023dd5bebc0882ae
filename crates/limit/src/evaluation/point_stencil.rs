//! The limit surface as linear functions of the base control vertices.
//!
//! Every evaluation [`LimitEvaluator`](crate::eval::LimitEvaluator) makes is linear in the control points, and the limit
//! surface over a face depends only on the vertices of the faces around it (every rule of
//! these schemes, creases and their decay included, reads one ring). So the weights of the
//! control vertices at a point are read off the evaluator itself: evaluate with unit vectors
//! on that support, three vertices at a time (x, y, z), and carry the weights of level-2
//! vertices back to the base through the refinement's stencils. The result is a
//! [`PointStencil`]: sparse rows of position and derivatives, exact to rounding, the
//! building block of constraint rows (Li et al. 2008 §3).
//!
//! [`LimitEvaluator::face_patches`](crate::eval::LimitEvaluator::face_patches) exposes the same structure per face: the pieces the
//! evaluator uses (bicubic B-splines, Stam corner patches), with their control points as
//! rows over the base vertices, for quadratic forms such as the thin-plate energy.

use std::cell::RefCell;
use std::sync::Arc;

use glam::DVec3;
use subd_schemes::{Refinement, Scheme};

use crate::LimitError;
use crate::evaluation::eval::{FaceParam, WholeMeshEvaluator};
use crate::evaluation::patch::SurfacePoint;
use crate::evaluation::piece::{Piece, eval_piece, project_all};
use crate::evaluation::stam::CornerPatchMatrices;
use crate::evaluation::support::{face_support, linear_weights};

/// Position, ∂u, ∂v, ∂uu, ∂uv, ∂vv of the limit surface at one point as weights over base
/// control vertices.
///
/// ```
/// use subd_mesh::{DVec3, TopologyBuilder};
/// use subd_schemes::{Options, Scheme};
/// use subd_limit::eval::{FaceParam, LimitEvaluator};
///
/// // A cube (every corner extraordinary): the stencil reproduces the evaluation.
/// let faces = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4];
/// let topo = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
/// let s = [(-1., -1., 1.), (1., -1., 1.), (-1., 1., 1.), (1., 1., 1.),
///          (-1., 1., -1.), (1., 1., -1.), (-1., -1., -1.), (1., -1., -1.)];
/// let p: Vec<DVec3> = s.iter().map(|&(x, y, z)| DVec3::new(x, y, z)).collect();
/// let eval = LimitEvaluator::new(&topo, &Scheme::CatmullClark, &Options::default()).unwrap();
/// let at = FaceParam { face: 0, sub: 0, u: 0.3, v: 0.6 };
/// let direct = eval.evaluate(&eval.prepare(&p), at).unwrap();
/// let stencil = eval.stencil(at).unwrap();
/// // The weights of the position sum to one (affine invariance).
/// assert!((stencil.weights[0].iter().sum::<f64>() - 1.0).abs() < 1e-14);
/// let via = stencil.apply(&p);
/// assert!((via.position - direct.position).length() < 1e-14);
/// assert!((via.du - direct.du).length() < 1e-13);
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointStencil {
    /// Base vertices with a non-zero weight, ascending.
    pub indices: Vec<u32>,
    /// Weights per quantity (position, ∂u, ∂v, ∂uu, ∂uv, ∂vv), each parallel to `indices`.
    pub weights: [Vec<f64>; 6],
}

/// Which quantity of a [`PointStencil`].
pub const POSITION: usize = 0;
/// ∂/∂u in a [`PointStencil`].
pub const DU: usize = 1;
/// ∂/∂v in a [`PointStencil`].
pub const DV: usize = 2;

impl PointStencil {
    /// The surface point for base positions `points`.
    pub fn apply(&self, points: &[DVec3]) -> SurfacePoint {
        let sum = |k: usize| {
            self.indices
                .iter()
                .zip(&self.weights[k])
                .fold(DVec3::ZERO, |acc, (&i, &w)| acc + w * points[i as usize])
        };
        SurfacePoint {
            position: sum(0),
            du: sum(1),
            dv: sum(2),
            duu: sum(3),
            duv: sum(4),
            dvv: sum(5),
        }
    }

    /// Number of base vertices involved.
    pub fn len(&self) -> usize {
        self.indices.len()
    }

    /// Whether no vertex is involved (never the case for a stencil of a surface point).
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }

    /// From (vertex, weights) pairs, merging repeated vertices and dropping all-zero ones.
    pub(crate) fn from_pairs(mut pairs: Vec<(u32, [f64; 6])>) -> PointStencil {
        pairs.sort_unstable_by_key(|p| p.0);
        let mut out = PointStencil::default();
        let mut i = 0;
        while i < pairs.len() {
            let v = pairs[i].0;
            let mut w = [0.0; 6];
            while i < pairs.len() && pairs[i].0 == v {
                for (a, b) in w.iter_mut().zip(&pairs[i].1) {
                    *a += b;
                }
                i += 1;
            }
            if w.iter().any(|&x| x != 0.0) {
                out.indices.push(v);
                for (k, x) in w.iter().enumerate() {
                    out.weights[k].push(*x);
                }
            }
        }
        out
    }
}

/// A control point as (vertex, weight) pairs.
pub type ControlRow = Vec<(u32, f64)>;

/// How a [`FacePatch`] is a function of its control points.
#[derive(Clone, Debug)]
pub enum PatchForm {
    /// A bicubic B-spline over 16 control points in grid order `4 j + i` (as
    /// [`crate::patch::eval_bicubic`]).
    Bicubic,
    /// Stam's corner patch over 2n + 8 control points ([`crate::stam`]), the extraordinary
    /// vertex at one of its corners.
    Corner(Arc<CornerPatchMatrices>),
    /// Neither (Loop's pieces, pieces refined locally next to irregular sharp features): use
    /// [`LimitEvaluator::stencil`](crate::eval::LimitEvaluator::stencil) at points of its domain.
    Other,
}

/// One piece of the limit surface over a base face.
#[derive(Clone, Debug)]
pub struct FacePatch {
    /// Its form.
    pub form: PatchForm,
    /// Control points as rows over base vertices (empty for [`PatchForm::Other`]).
    pub controls: Vec<ControlRow>,
    /// The sub-face of the base face it lies in (0 for quads).
    pub sub: usize,
    /// Its domain in the base (sub-)face's parameters: the square with corner `origin` and
    /// side `size`; the patch's own parameters are `(u − origin) / size`.
    pub origin: [f64; 2],
    /// Side of the domain (1, ½ or ¼).
    pub size: f64,
}

thread_local! {
    /// Zeroed point buffers (base level, level 2) for unit-vector evaluations; entries set
    /// are reset before the buffer is released.
    static SCRATCH: RefCell<[Vec<DVec3>; 2]> = const { RefCell::new([Vec::new(), Vec::new()]) };
}

/// One piece evaluated on its own (projecting a corner patch's points first).
pub(crate) fn single_piece(
    piece: &Piece,
    pts: &[DVec3],
    face: usize,
    s: f64,
    t: f64,
) -> Result<SurfacePoint, LimitError> {
    let projected = project_all(std::slice::from_ref(piece), pts)
        .pop()
        .flatten();
    eval_piece(piece, pts, projected.as_ref(), face, s, t)
}

/// The row over base vertices of level-2 vertex `v2` of `r`.
fn base_row(r: &Refinement, v2: u32) -> Vec<(u32, f64)> {
    let (s2, w2) = r.stencils(2).row(v2 as usize);
    let mut out = Vec::with_capacity(4 * s2.len());
    for (&v1, &a) in s2.iter().zip(w2) {
        let (s1, w1) = r.stencils(1).row(v1 as usize);
        out.extend(s1.iter().zip(w1).map(|(&v0, &b)| (v0, a * b)));
    }
    merge_row(out)
}

/// Sorts a row by vertex and merges repeated vertices.
fn merge_row(mut row: Vec<(u32, f64)>) -> Vec<(u32, f64)> {
    row.sort_unstable_by_key(|p| p.0);
    let mut out: Vec<(u32, f64)> = Vec::with_capacity(row.len());
    for (v, w) in row {
        match out.last_mut() {
            Some(last) if last.0 == v => last.1 += w,
            _ => out.push((v, w)),
        }
    }
    out
}

impl WholeMeshEvaluator {
    /// The limit surface at `at` as weights over the base control vertices: position and
    /// derivatives, equal (to rounding) to [`LimitEvaluator::evaluate`](crate::eval::LimitEvaluator::evaluate) for any points.
    ///
    /// # Errors
    /// As [`LimitEvaluator::evaluate`](crate::eval::LimitEvaluator::evaluate).
    pub fn stencil(&self, at: FaceParam) -> Result<PointStencil, LimitError> {
        self.check(&at)?;
        SCRATCH.with(|cell| {
            let mut bufs = cell.borrow_mut();
            let [base_buf, level2_buf] = &mut *bufs;
            let piece = &self.base_pieces[at.face];
            if !matches!(piece, Piece::Refined) {
                let support = face_support(&self.base, at.face);
                let pairs = linear_weights(base_buf, self.base.num_vertices(), &support, |p| {
                    single_piece(piece, p, at.face, at.u, at.v)
                })?;
                return Ok(PointStencil::from_pairs(pairs));
            }
            let r = self.refined.as_ref().expect("refined when a face needs it");
            let (f2, s2, t2, scale) = self.level2_location(&at);
            let t2top = r.topology(2);
            let support = face_support(t2top, f2);
            let n2 = t2top.num_vertices();
            let pairs = match &self.level2_pieces[f2] {
                Piece::Local => crate::evaluation::local::stencil(
                    t2top,
                    r.vertex_rules(2),
                    crate::evaluation::local::LIMIT_EVALUATOR_LEVEL,
                    f2,
                    &self.scheme,
                    &self.options,
                    s2,
                    t2,
                )
                .map_err(|e| crate::evaluation::eval::on_base_face(e, at.face))?,
                p2 => linear_weights(level2_buf, n2, &support, |p| {
                    single_piece(p2, p, at.face, s2, t2)
                })?,
            };
            // Derivatives by the parameter map's scale, then level 2 back to the base.
            let factors = crate::evaluation::support::derivative_factors(scale);
            let mut base_pairs = Vec::with_capacity(pairs.len() * 16);
            for (v2, w) in pairs {
                if w.iter().all(|&x| x == 0.0) {
                    continue;
                }
                for (v0, b) in base_row(r, v2) {
                    base_pairs.push((v0, std::array::from_fn(|k| w[k] * factors[k] * b)));
                }
            }
            Ok(PointStencil::from_pairs(base_pairs))
        })
    }

    /// The pieces of the limit surface over base `face` and their control points as rows
    /// over base vertices: one piece for a regular face or a face with one extraordinary
    /// corner, the 16 level-2 pieces of a refined quad, 4 per sub-face of a non-quad.
    ///
    /// # Errors
    /// [`LimitError::Unsupported`] for holes and faces the evaluator does not cover.
    pub fn face_patches(&self, face: usize) -> Result<Vec<FacePatch>, LimitError> {
        if face >= self.base.num_faces() {
            return Err(LimitError::Param(format!(
                "face {face} out of range (the mesh has {} faces)",
                self.base.num_faces()
            )));
        }
        let whole = |form, controls| FacePatch {
            form,
            controls,
            sub: 0,
            origin: [0.0, 0.0],
            size: 1.0,
        };
        match &self.base_pieces[face] {
            Piece::Refined => {}
            piece => {
                return Ok(vec![match piece_form(piece, face)? {
                    Some((form, rows)) => whole(form, rows),
                    None => whole(PatchForm::Other, Vec::new()),
                }]);
            }
        }
        let r = self.refined.as_ref().expect("refined when a face needs it");
        let off = self.base.face_offsets()[face] as usize;
        let size = self.base.face_size(face);
        let mut out = Vec::new();
        if self.scheme == Scheme::Loop {
            // Loop's refined pieces are triangles: evaluated by stencils only.
            out.push(whole(PatchForm::Other, Vec::new()));
            return Ok(out);
        }
        let quad = size == 4;
        let corner_origin = |j: usize| match j {
            0 => [0.0, 0.0],
            1 => [0.5, 0.0],
            2 => [0.5, 0.5],
            _ => [0.0, 0.5],
        };
        for j in 0..size {
            let c1 = off + j;
            let (sub, o1, s1) = if quad {
                (0, corner_origin(j), 0.5)
            } else {
                (j, [0.0, 0.0], 1.0)
            };
            for k in 0..4 {
                let g = 4 * c1 + k;
                let ok = corner_origin(k);
                let origin = [o1[0] + s1 * ok[0], o1[1] + s1 * ok[1]];
                let size2 = s1 * 0.5;
                let (form, controls) = match piece_form(&self.level2_pieces[g], face)? {
                    Some((form, rows)) => (
                        form,
                        rows.iter()
                            .map(|row| {
                                merge_row(
                                    row.iter()
                                        .flat_map(|&(v2, a)| {
                                            base_row(r, v2)
                                                .into_iter()
                                                .map(move |(v, b)| (v, a * b))
                                        })
                                        .collect(),
                                )
                            })
                            .collect(),
                    ),
                    None => (PatchForm::Other, Vec::new()),
                };
                out.push(FacePatch {
                    form,
                    controls,
                    sub,
                    origin,
                    size: size2,
                });
            }
        }
        Ok(out)
    }
}

/// The form of one piece and its control rows over its own level's vertices (`None` for
/// pieces that have no closed form here).
fn piece_form(
    piece: &Piece,
    face: usize,
) -> Result<Option<(PatchForm, Vec<ControlRow>)>, LimitError> {
    let unit = |ids: &[u32]| ids.iter().map(|&i| vec![(i, 1.0)]).collect();
    Ok(match piece {
        Piece::Regular(grid) => Some((PatchForm::Bicubic, unit(grid))),
        Piece::SharpRegular(grid) => Some((PatchForm::Bicubic, grid.to_vec())),
        Piece::Corner { cp, matrices, .. } => Some((PatchForm::Corner(matrices.clone()), unit(cp))),
        Piece::Unsupported(reason) => return Err(LimitError::Unsupported { face, reason }),
        _ => None,
    })
}
