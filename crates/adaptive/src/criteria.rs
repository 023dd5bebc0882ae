//! What decides that a face is refined: one small trait, [`Criterion`], and one type per
//! rule. Criteria compose by union — a face is refined when any criterion selects it — and
//! are evaluated level by level on the faces that exist there. Vertex-based criteria
//! (flatness, curvature) look at the faces present around a vertex; a vertex's ring only
//! grows as the hierarchy is completed, and the hierarchy is iterated until no criterion
//! selects anything new, so the result does not depend on the order faces are visited.

use glam::DVec3;
use rayon::prelude::*;
use subd_limit::eval::{FaceParam, LimitEvaluator, PatchPoints};
use subd_mesh::Topology;
use subd_schemes::{Options, Scheme};

use crate::level::{SparseLevel, WHOLE_FACE};
use crate::{AdaptiveError, AdaptiveMesh, Positions};

/// The faces of one level of the hierarchy as a criterion sees them.
pub struct LevelView<'a> {
    pub(crate) level: usize,
    pub(crate) data: &'a SparseLevel,
}

impl LevelView<'_> {
    /// The level (0 = base).
    pub fn level(&self) -> usize {
        self.level
    }

    /// The faces of this level that exist, as a topology (with the uniform level's tags).
    pub fn topology(&self) -> &Topology {
        &self.data.topology
    }

    /// Positions of the topology's vertices: exactly uniform refinement's at this level.
    pub fn points(&self) -> &[DVec3] {
        &self.data.points
    }

    /// The base face that face `f` descends from.
    pub fn base_face(&self, f: usize) -> usize {
        self.data.base_face[f] as usize
    }

    /// Index of face `f` in uniform refinement's level.
    pub fn uniform_face(&self, f: usize) -> u64 {
        self.data.face_key[f]
    }

    /// Whether every face around vertex `v` in uniform refinement is present.
    pub fn is_complete_vertex(&self, v: usize) -> bool {
        self.data.is_complete(v)
    }

    /// Where face `f` lies on the limit surface: its base face, the sub-face of a
    /// Catmull-Clark base face that is not a quad, and `(u, v)` at each corner; `None` for a
    /// whole base face that is not a quad (Catmull-Clark level 0).
    pub fn domain(&self, f: usize) -> Option<(usize, usize, &[[f64; 2]])> {
        let sub = self.data.sub_face[f];
        (sub != WHOLE_FACE).then(|| (self.base_face(f), sub as usize, self.data.params(f)))
    }
}

/// A rule that selects faces to refine.
pub trait Criterion: Send + Sync {
    /// Sets `selected[f]` for every face `f` of `level` this criterion refines (and leaves
    /// the other entries as they are).
    ///
    /// # Errors
    /// Whatever the criterion cannot evaluate (for instance the limit surface on a face the
    /// evaluator does not cover).
    fn select(&self, level: &LevelView<'_>, selected: &mut [bool]) -> Result<(), AdaptiveError>;

    /// A criterion that also judges the conforming mesh (the transition faces the leaves are
    /// cut into) names the positions it judges it with; `None` (the default) for one that
    /// judges the hierarchy's faces only.
    fn output_positions(&self) -> Option<Positions> {
        None
    }

    /// The faces of the conforming mesh `mesh` (built with [`Self::output_positions`]) this
    /// criterion rejects: their leaves are refined and the mesh built again. The default
    /// rejects none.
    ///
    /// # Errors
    /// As [`Self::select`].
    fn reject(&self, mesh: &AdaptiveMesh) -> Result<Vec<bool>, AdaptiveError> {
        Ok(vec![false; mesh.num_faces()])
    }

    /// [`Self::reject`], with the largest error measured on the way where the criterion
    /// measures one (the hierarchy keeps it for the final mesh,
    /// [`crate::AdaptiveRefinement::final_errors`]). The default measures none.
    ///
    /// # Errors
    /// As [`Self::select`].
    fn judge(&self, mesh: &AdaptiveMesh) -> Result<Judgement, AdaptiveError> {
        Ok(Judgement {
            rejected: self.reject(mesh)?,
            worst: None,
        })
    }
}

/// What [`Criterion::judge`] finds on a conforming mesh.
#[derive(Clone, Debug, Default)]
pub struct Judgement {
    /// The faces rejected: their leaves are refined.
    pub rejected: Vec<bool>,
    /// The largest error measured over the faces judged (`None` for a criterion that
    /// measures none).
    pub worst: Option<f64>,
}

/// Checks an angle threshold in degrees and returns it in radians.
fn angle_threshold(name: &'static str, degrees: f64) -> Result<f64, AdaptiveError> {
    if !(degrees.is_finite() && (0.0..=180.0).contains(&degrees)) {
        return Err(AdaptiveError::Threshold {
            name,
            value: degrees,
            reason: "must be a number of degrees in [0, 180]",
        });
    }
    Ok(degrees.to_radians())
}

/// Unit normal of every face (Newell's method; zero for a degenerate face).
fn face_normals(t: &Topology, p: &[DVec3]) -> Vec<DVec3> {
    (0..t.num_faces())
        .into_par_iter()
        .map(|f| newell(t.face_vertices(f).iter().map(|&v| p[v as usize])).normalize_or_zero())
        .collect()
}

/// Newell's normal of a polygon (twice the area vector).
pub(crate) fn newell(corners: impl Iterator<Item = DVec3> + Clone) -> DVec3 {
    let mut n = DVec3::ZERO;
    let first = corners.clone().next().unwrap_or(DVec3::ZERO);
    let mut prev: Option<DVec3> = None;
    for c in corners {
        if let Some(a) = prev {
            n += (a - first).cross(c - first);
        }
        prev = Some(c);
    }
    n
}

fn angle_between(a: DVec3, b: DVec3) -> f64 {
    a.dot(b).clamp(-1.0, 1.0).acos()
}

/// Sun et al. 2012 §2.2's flatness: `ε(v)` is the largest angle between the normals of two faces
/// at `v`. A vertex with `ε(v) < ε_T` is dead, an edge between two dead vertices is dead,
/// and a face with two or more dead edges is dead; every other face is refined.
#[derive(Clone, Copy, Debug)]
pub struct Flatness {
    threshold: f64,
}

impl Flatness {
    /// Flatness with threshold `ε_T` in degrees.
    ///
    /// # Errors
    /// [`AdaptiveError::Threshold`] unless `degrees` is in `[0, 180]`.
    pub fn new(degrees: f64) -> Result<Self, AdaptiveError> {
        Ok(Flatness {
            threshold: angle_threshold("flatness", degrees)?,
        })
    }

    /// `ε(v)` of every vertex of a level, over the faces present (radians).
    pub fn vertex_flatness(t: &Topology, p: &[DVec3]) -> Vec<f64> {
        min_normal_dots(t, p)
            .into_iter()
            .map(|d| d.clamp(-1.0, 1.0).acos())
            .collect()
    }
}

/// The smallest dot product between the unit normals of two faces at each vertex (1 where
/// fewer than two faces have a normal): the cosine of Sun et al.'s `ε(v)`.
fn min_normal_dots(t: &Topology, p: &[DVec3]) -> Vec<f64> {
    let normals = face_normals(t, p);
    (0..t.num_vertices())
        .into_par_iter()
        .map(|v| {
            let vf = t.vertex_faces(v);
            let mut least = 1.0f64;
            for (i, &a) in vf.iter().enumerate() {
                let na = normals[a as usize];
                if na == DVec3::ZERO {
                    continue;
                }
                for &b in &vf[i + 1..] {
                    let nb = normals[b as usize];
                    if nb != DVec3::ZERO {
                        least = least.min(na.dot(nb));
                    }
                }
            }
            least
        })
        .collect()
}

impl Criterion for Flatness {
    fn select(&self, level: &LevelView<'_>, selected: &mut [bool]) -> Result<(), AdaptiveError> {
        let t = level.topology();
        // ε(v) < ε_T exactly when cos ε(v) > cos ε_T (acos decreases): no acos per vertex.
        let cos_t = self.threshold.cos();
        let dead: Vec<bool> = min_normal_dots(t, level.points())
            .into_iter()
            .map(|d| d.clamp(-1.0, 1.0) > cos_t)
            .collect();
        selected.par_iter_mut().enumerate().for_each(|(f, s)| {
            let fv = t.face_vertices(f);
            let n = fv.len();
            let dead_edges = (0..n)
                .filter(|&i| dead[fv[i] as usize] && dead[fv[(i + 1) % n] as usize])
                .count();
            if dead_edges < 2 {
                *s = true;
            }
        });
        Ok(())
    }
}

/// User selection (Sun et al. 2012 §2.1): every descendant of the chosen base faces is refined.
#[derive(Clone, Debug)]
pub struct FaceSelection {
    base_faces: Vec<bool>,
}

impl FaceSelection {
    /// The base faces `faces` of a mesh with `num_faces` faces.
    ///
    /// # Errors
    /// [`AdaptiveError::SelectionIndex`] for an index out of range.
    pub fn from_faces(num_faces: usize, faces: &[u64]) -> Result<Self, AdaptiveError> {
        Ok(FaceSelection {
            base_faces: marks(num_faces, faces, "face")?,
        })
    }

    /// The base faces with two or more of the chosen `vertices` (Sun et al. 2012 §2.1: "any
    /// triangle with at least two selected vertices is refined").
    ///
    /// # Errors
    /// [`AdaptiveError::SelectionIndex`] for an index out of range.
    pub fn from_vertices(base: &Topology, vertices: &[u64]) -> Result<Self, AdaptiveError> {
        let chosen = marks(base.num_vertices(), vertices, "vertex")?;
        let base_faces = (0..base.num_faces())
            .map(|f| {
                base.face_vertices(f)
                    .iter()
                    .filter(|&&v| chosen[v as usize])
                    .count()
                    >= 2
            })
            .collect();
        Ok(FaceSelection { base_faces })
    }

    /// Number of base faces selected.
    pub fn num_selected(&self) -> usize {
        self.base_faces.iter().filter(|&&b| b).count()
    }
}

/// A flag per element of `count`, set for each of `indices`.
fn marks(count: usize, indices: &[u64], what: &'static str) -> Result<Vec<bool>, AdaptiveError> {
    let mut m = vec![false; count];
    for &i in indices {
        if i >= count as u64 {
            return Err(AdaptiveError::SelectionIndex {
                what,
                index: i,
                count,
            });
        }
        m[i as usize] = true;
    }
    Ok(m)
}

impl Criterion for FaceSelection {
    fn select(&self, level: &LevelView<'_>, selected: &mut [bool]) -> Result<(), AdaptiveError> {
        for (f, s) in selected.iter_mut().enumerate() {
            if self.base_faces.get(level.base_face(f)) == Some(&true) {
                *s = true;
            }
        }
        Ok(())
    }
}

/// A reproducible pseudo-random selection: a face is refined when a hash of its level, its
/// uniform index and the seed falls below `fraction`. For stress tests and benchmarks: it
/// depends on neither labels nor geometry, only on where a face is in uniform refinement.
#[derive(Clone, Copy, Debug)]
pub struct RandomSelection {
    seed: u64,
    fraction: f64,
}

impl RandomSelection {
    /// Refine about `fraction` (in `[0, 1]`) of the faces of every level.
    ///
    /// # Errors
    /// [`AdaptiveError::Threshold`] for a fraction outside `[0, 1]`.
    pub fn new(seed: u64, fraction: f64) -> Result<Self, AdaptiveError> {
        if !(0.0..=1.0).contains(&fraction) {
            return Err(AdaptiveError::Threshold {
                name: "fraction",
                value: fraction,
                reason: "must be in [0, 1]",
            });
        }
        Ok(RandomSelection { seed, fraction })
    }
}

/// SplitMix64's finaliser: a well-mixed 64-bit hash.
fn mix(mut x: u64) -> u64 {
    x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

impl Criterion for RandomSelection {
    fn select(&self, level: &LevelView<'_>, selected: &mut [bool]) -> Result<(), AdaptiveError> {
        let salt = mix(self.seed ^ mix(level.level() as u64 + 1));
        for (f, s) in selected.iter_mut().enumerate() {
            let h = mix(salt ^ level.uniform_face(f));
            if ((h >> 11) as f64) < self.fraction * (1u64 << 53) as f64 {
                *s = true;
            }
        }
        Ok(())
    }
}

/// Every face (uniform refinement, up to the level cap).
#[derive(Clone, Copy, Debug, Default)]
pub struct EveryFace;

impl Criterion for EveryFace {
    fn select(&self, _level: &LevelView<'_>, selected: &mut [bool]) -> Result<(), AdaptiveError> {
        selected.fill(true);
        Ok(())
    }
}

/// Gaussian curvature by angle defect: a face is refined when one of its vertices has
/// `|K| · d² > threshold`, with `K = (2π − Σ θ) / (A / k)` (`π` instead of `2π` on a
/// boundary; `θ` the face angles at the vertex, `A / k` each face's area shared among its
/// `k` corners) and `d` the base mesh's bounding-box diagonal, so the threshold does not
/// depend on the model's scale (a sphere has `K d² = 12`). Only vertices whose every face is
/// present are measured.
#[derive(Clone, Copy, Debug)]
pub struct GaussianCurvature {
    threshold: f64,
    diagonal: f64,
}

impl GaussianCurvature {
    /// Curvature threshold `threshold` (dimensionless, see the type) on a mesh with
    /// bounding-box diagonal `diagonal`.
    ///
    /// # Errors
    /// [`AdaptiveError::Threshold`] unless `threshold ≥ 0` and `diagonal > 0`.
    pub fn new(threshold: f64, diagonal: f64) -> Result<Self, AdaptiveError> {
        if !(threshold.is_finite() && threshold >= 0.0) {
            return Err(AdaptiveError::Threshold {
                name: "curvature",
                value: threshold,
                reason: "must be a number ≥ 0",
            });
        }
        if !(diagonal.is_finite() && diagonal > 0.0) {
            return Err(AdaptiveError::Threshold {
                name: "bounding-box diagonal",
                value: diagonal,
                reason: "must be positive",
            });
        }
        Ok(GaussianCurvature {
            threshold,
            diagonal,
        })
    }

    /// `K` at vertex `v` (`None` where its ring is incomplete, it is non-manifold, or its
    /// faces have no area).
    pub fn at_vertex(level: &LevelView<'_>, v: usize) -> Option<f64> {
        let t = level.topology();
        if !level.is_complete_vertex(v) || t.is_non_manifold_vertex(v) {
            return None;
        }
        let p = level.points();
        let (mut angles, mut area) = (0.0, 0.0);
        for (&f, &c) in t.vertex_faces(v).iter().zip(t.vertex_face_local_indices(v)) {
            let fv = t.face_vertices(f as usize);
            let n = fv.len();
            let c = c as usize;
            let at = p[fv[c] as usize];
            let a = p[fv[(c + 1) % n] as usize] - at;
            let b = p[fv[(c + n - 1) % n] as usize] - at;
            angles += angle_between(a.normalize_or_zero(), b.normalize_or_zero());
            area += 0.5 * newell(fv.iter().map(|&w| p[w as usize])).length() / n as f64;
        }
        let full = if t.is_boundary_vertex(v) {
            std::f64::consts::PI
        } else {
            2.0 * std::f64::consts::PI
        };
        (area > 0.0).then(|| (full - angles) / area)
    }
}

impl Criterion for GaussianCurvature {
    fn select(&self, level: &LevelView<'_>, selected: &mut [bool]) -> Result<(), AdaptiveError> {
        let t = level.topology();
        let d2 = self.diagonal * self.diagonal;
        let hot: Vec<bool> = (0..t.num_vertices())
            .into_par_iter()
            .map(|v| {
                GaussianCurvature::at_vertex(level, v)
                    .is_some_and(|k| k.abs() * d2 > self.threshold)
            })
            .collect();
        selected.par_iter_mut().enumerate().for_each(|(f, s)| {
            if t.face_vertices(f).iter().any(|&v| hot[v as usize]) {
                *s = true;
            }
        });
        Ok(())
    }
}

/// Dihedral angle: both faces of an edge whose normals differ by more than the threshold are
/// refined.
#[derive(Clone, Copy, Debug)]
pub struct DihedralAngle {
    threshold: f64,
}

impl DihedralAngle {
    /// Threshold in degrees.
    ///
    /// # Errors
    /// [`AdaptiveError::Threshold`] unless `degrees` is in `[0, 180]`.
    pub fn new(degrees: f64) -> Result<Self, AdaptiveError> {
        Ok(DihedralAngle {
            threshold: angle_threshold("dihedral", degrees)?,
        })
    }
}

impl Criterion for DihedralAngle {
    fn select(&self, level: &LevelView<'_>, selected: &mut [bool]) -> Result<(), AdaptiveError> {
        let t = level.topology();
        let normals = face_normals(t, level.points());
        selected.par_iter_mut().enumerate().for_each(|(f, s)| {
            let n = normals[f];
            let bent = t.face_edges(f).iter().any(|&e| {
                let ef = t.edge_faces(e as usize);
                ef.len() == 2 && {
                    let g = if ef[0] as usize == f { ef[1] } else { ef[0] };
                    let m = normals[g as usize];
                    n != DVec3::ZERO && m != DVec3::ZERO && angle_between(n, m) > self.threshold
                }
            });
            if bent {
                *s = true;
            }
        });
        Ok(())
    }
}

/// The exact limit surface, for measuring how far a face is from it.
pub struct LimitSurface {
    evaluator: LimitEvaluator,
    points: PatchPoints,
}

impl LimitSurface {
    /// The limit surface of `points` on `base` under `scheme` and `options`.
    ///
    /// # Errors
    /// As [`LimitEvaluator::new`].
    pub fn new(
        base: &Topology,
        points: &[DVec3],
        scheme: &Scheme,
        options: &Options,
    ) -> Result<Self, AdaptiveError> {
        let evaluator = LimitEvaluator::new(base, scheme, options)?;
        let points = evaluator.prepare(points);
        Ok(LimitSurface { evaluator, points })
    }

    /// The evaluator of the base mesh, for other data on the same surface (such as a
    /// face-varying channel through [`LimitEvaluator::face_varying`]).
    pub fn evaluator(&self) -> &LimitEvaluator {
        &self.evaluator
    }

    /// Position on the limit surface at `(u, v)` of sub-face `sub` of base face `face`.
    ///
    /// # Errors
    /// As [`LimitEvaluator::evaluate`].
    pub fn position(
        &self,
        face: usize,
        sub: usize,
        u: f64,
        v: f64,
    ) -> Result<DVec3, AdaptiveError> {
        // Rounding can put a midpoint's parameter a hair outside [0, 1].
        let (u, v) = (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0));
        Ok(self
            .evaluator
            .evaluate(&self.points, FaceParam { face, sub, u, v })?
            .position)
    }

    /// The largest distance to the limit surface over samples of a triangle or quad (its
    /// corners, edge midpoints and centre, interpolated linearly or bilinearly in position
    /// and parameters alike).
    ///
    /// # Errors
    /// As [`LimitEvaluator::evaluate`].
    pub fn face_distance(
        &self,
        face: usize,
        sub: usize,
        positions: &[DVec3],
        params: &[[f64; 2]],
    ) -> Result<f64, AdaptiveError> {
        let mut worst = 0.0f64;
        for (w, n) in sample_weights(positions.len()) {
            let (mut p, mut uv) = (DVec3::ZERO, [0.0, 0.0]);
            for i in 0..n {
                p += w[i] * positions[i];
                uv[0] += w[i] * params[i][0];
                uv[1] += w[i] * params[i][1];
            }
            worst = worst.max((p - self.position(face, sub, uv[0], uv[1])?).length());
        }
        Ok(worst)
    }

    /// [`Self::face_distance`] of a whole Catmull-Clark base face that is not a quad: each
    /// sub-face is the quad (corner, edge midpoint, centroid, edge midpoint).
    ///
    /// # Errors
    /// As [`LimitEvaluator::evaluate`].
    pub fn polygon_distance(&self, face: usize, corners: &[DVec3]) -> Result<f64, AdaptiveError> {
        let n = corners.len();
        let centroid = corners.iter().sum::<DVec3>() / n as f64;
        let unit = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let mut worst = 0.0f64;
        for k in 0..n {
            let quad = [
                corners[k],
                0.5 * (corners[k] + corners[(k + 1) % n]),
                centroid,
                0.5 * (corners[(k + n - 1) % n] + corners[k]),
            ];
            worst = worst.max(self.face_distance(face, k, &quad, &unit)?);
        }
        Ok(worst)
    }
}

/// Sample weights over a face's `n` (3 or 4) corners: corners, edge midpoints and centre,
/// without allocating (it runs for every face of every level).
fn sample_weights(n: usize) -> impl Iterator<Item = ([f64; 4], usize)> {
    let k = n.min(4);
    (0..2 * k + 1).map(move |s| {
        let mut w = [0.0; 4];
        match s {
            s if s == 2 * k => w[..k].fill(1.0 / k as f64),
            s if s % 2 == 0 => w[s / 2] = 1.0,
            s => {
                w[s / 2] = 0.5;
                w[(s / 2 + 1) % k] = 0.5;
            }
        }
        (w, k)
    })
}

/// Distance to the exact limit surface: a face is refined while its largest sampled distance
/// to the limit surface (at the same parameters, see [`LimitSurface::face_distance`])
/// exceeds the tolerance. With `limit_corners` the face is measured with its corners on the
/// limit surface (the output of `--limit`), otherwise at their positions at its level. The
/// transition faces of the conforming mesh are measured too ([`Criterion::reject`]), so
/// every face of the result is within the tolerance (up to the level cap).
pub struct LimitDistance {
    surface: LimitSurface,
    tolerance: f64,
    limit_corners: bool,
}

impl LimitDistance {
    /// Refine while the distance exceeds `tolerance` (absolute, in model units).
    ///
    /// # Errors
    /// [`AdaptiveError::Threshold`] unless `tolerance > 0`.
    pub fn new(
        surface: LimitSurface,
        tolerance: f64,
        limit_corners: bool,
    ) -> Result<Self, AdaptiveError> {
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(AdaptiveError::Threshold {
                name: "max-distance",
                value: tolerance,
                reason: "must be a positive number",
            });
        }
        Ok(LimitDistance {
            surface,
            tolerance,
            limit_corners,
        })
    }

    /// The limit surface it measures against.
    pub fn surface(&self) -> &LimitSurface {
        &self.surface
    }

    /// The tolerance (absolute).
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// Whether [`Criterion::judge`] measures face `f` of the conforming mesh: every face
    /// that is not a hole, except, with limit corners, a leaf that is not a transition face
    /// (measured as the criterion saw it; its corners cannot have moved on).
    pub fn judged(&self, mesh: &AdaptiveMesh, f: usize) -> bool {
        !(mesh.holes[f] || (self.limit_corners && !mesh.transition[f]))
    }
}

impl Criterion for LimitDistance {
    fn select(&self, level: &LevelView<'_>, selected: &mut [bool]) -> Result<(), AdaptiveError> {
        let t = level.topology();
        let far: Vec<bool> = (0..t.num_faces())
            .into_par_iter()
            .map(|f| -> Result<bool, AdaptiveError> {
                if t.is_hole(f) {
                    return Ok(false);
                }
                let fv = t.face_vertices(f);
                let mut corners: Vec<DVec3> =
                    fv.iter().map(|&v| level.points()[v as usize]).collect();
                let d = match level.domain(f) {
                    Some((face, sub, params)) => {
                        if self.limit_corners {
                            for (c, uv) in corners.iter_mut().zip(params) {
                                *c = self.surface.position(face, sub, uv[0], uv[1])?;
                            }
                        }
                        self.surface.face_distance(face, sub, &corners, params)?
                    }
                    None => {
                        let face = level.base_face(f);
                        if self.limit_corners {
                            for (k, c) in corners.iter_mut().enumerate() {
                                *c = self.surface.position(face, k, 0.0, 0.0)?;
                            }
                        }
                        self.surface.polygon_distance(face, &corners)?
                    }
                };
                Ok(d > self.tolerance)
            })
            .collect::<Result<_, _>>()?;
        for (s, far) in selected.iter_mut().zip(far) {
            if far {
                *s = true;
            }
        }
        Ok(())
    }

    fn output_positions(&self) -> Option<Positions> {
        Some(if self.limit_corners {
            Positions::Limit
        } else {
            Positions::Refined
        })
    }

    fn reject(&self, mesh: &AdaptiveMesh) -> Result<Vec<bool>, AdaptiveError> {
        Ok(self.judge(mesh)?.rejected)
    }

    /// Measures every face that is not a hole, except, with limit corners, the leaves that
    /// are not transition faces: the criterion measured those as it saw them at their level
    /// (see [`LimitDistance::judged`]). The worst is the largest distance measured.
    fn judge(&self, mesh: &AdaptiveMesh) -> Result<Judgement, AdaptiveError> {
        let distances: Vec<f64> = (0..mesh.num_faces())
            .into_par_iter()
            .map(|f| {
                if !self.judged(mesh, f) {
                    return Ok(0.0);
                }
                mesh.face_distance(&self.surface, f)
            })
            .collect::<Result<_, AdaptiveError>>()?;
        let worst = distances.iter().copied().fold(0.0, f64::max);
        Ok(Judgement {
            rejected: distances.iter().map(|&d| d > self.tolerance).collect(),
            worst: Some(worst),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::AdaptiveRefinement;
    use subd_mesh::TopologyBuilder;

    /// A flat 4 × 4 grid of triangles (each quad split along its diagonal) with vertex 12
    /// (an interior vertex) lifted.
    fn bump(height: f64) -> (Topology, Vec<DVec3>) {
        let mut fv = Vec::new();
        for j in 0..4u32 {
            for i in 0..4u32 {
                let v = j * 5 + i;
                fv.extend([v, v + 1, v + 6, v, v + 6, v + 5]);
            }
        }
        let t = TopologyBuilder::new(25).build(&[3; 32], &fv).unwrap();
        let p = (0..25)
            .map(|v| {
                let z = if v == 12 { height } else { 0.0 };
                DVec3::new((v % 5) as f64, (v / 5) as f64, z)
            })
            .collect();
        (t, p)
    }

    /// The unit octahedron.
    fn octahedron() -> (Topology, [DVec3; 6]) {
        let fv = [
            0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1, 5, 2, 1, 5, 3, 2, 5, 4, 3, 5, 1, 4,
        ];
        let t = TopologyBuilder::new(6).build(&[3; 8], &fv).unwrap();
        (
            t,
            [
                DVec3::Z,
                DVec3::X,
                DVec3::Y,
                -DVec3::X,
                -DVec3::Y,
                -DVec3::Z,
            ],
        )
    }

    fn level0<'a>(a: &'a AdaptiveRefinement) -> LevelView<'a> {
        a.level_view(0)
    }

    fn selected(c: &dyn Criterion, t: &Topology, p: &[DVec3]) -> Vec<bool> {
        let a = AdaptiveRefinement::new(t, p, &Scheme::Loop, &Options::default(), &[], 0).unwrap();
        let mut s = vec![false; t.num_faces()];
        c.select(&level0(&a), &mut s).unwrap();
        s
    }

    #[test]
    fn flatness_kills_flat_vertices_edges_and_faces_as_seed_002_says() {
        let (t, p) = bump(1.0);
        let eps = Flatness::vertex_flatness(&t, &p);
        // Only vertex 12 and its ring see a bent normal; far vertices are flat.
        assert_eq!(eps[0], 0.0);
        assert!(eps[12] > 0.5);
        let ring: Vec<u32> = t.vertex_ring(12).collect();
        for &w in &ring {
            assert!(eps[w as usize] > 0.1, "ring vertex {w}");
        }
        // A triangle is refined unless two of its edges are dead, i.e. unless at most one
        // of its vertices is live (dead edges need two dead ends).
        let live: Vec<bool> = eps.iter().map(|&e| e >= 10f64.to_radians()).collect();
        let s = selected(&Flatness::new(10.0).unwrap(), &t, &p);
        for (f, &picked) in s.iter().enumerate() {
            let fv = t.face_vertices(f);
            let dead_edges = (0..3)
                .filter(|&i| !live[fv[i] as usize] && !live[fv[(i + 1) % 3] as usize])
                .count();
            assert_eq!(picked, dead_edges < 2, "face {f}");
        }
        assert!(s.iter().any(|&x| x) && !s.iter().all(|&x| x));
        // A flat mesh has no live vertex.
        let (t, p) = bump(0.0);
        assert!(
            !selected(&Flatness::new(1.0).unwrap(), &t, &p)
                .iter()
                .any(|&x| x)
        );
        assert!(Flatness::new(f64::NAN).is_err() && Flatness::new(181.0).is_err());
    }

    #[test]
    fn dihedral_angle_selects_both_faces_of_a_bent_edge() {
        let (t, p) = bump(1.0);
        // Normals of the faces at vertex 12 tilt by atan(1) = 45° against flat neighbours.
        let s = selected(&DihedralAngle::new(30.0).unwrap(), &t, &p);
        for (f, &picked) in s.iter().enumerate() {
            let touches = t.face_vertices(f).contains(&12)
                || t.face_edges(f).iter().any(|&e| {
                    t.edge_faces(e as usize)
                        .iter()
                        .any(|&g| t.face_vertices(g as usize).contains(&12))
                });
            if !touches {
                assert!(!picked, "face {f} is flat with flat neighbours");
            }
        }
        assert!(t.vertex_faces(12).iter().all(|&f| s[f as usize]));
        assert!(
            !selected(&DihedralAngle::new(80.0).unwrap(), &t, &p)
                .iter()
                .any(|&x| x)
        );
    }

    #[test]
    fn angle_defect_of_an_octahedron_is_the_sphere_curvature_sum() {
        // Octahedron: 4 faces of 60° at each vertex, defect 2π − 4π/3 = 2π/3, six vertices
        // sum to 4π (Gauss–Bonnet for a sphere).
        let (t, p) = octahedron();
        let a =
            AdaptiveRefinement::new(&t, &p, &Scheme::Loop, &Options::default(), &[], 0).unwrap();
        let view = level0(&a);
        let area = 3f64.sqrt() / 2.0; // each face: an equilateral triangle of side √2
        for v in 0..6 {
            let k = GaussianCurvature::at_vertex(&view, v).unwrap();
            let want = (2.0 * std::f64::consts::PI / 3.0) / (4.0 * area / 3.0);
            assert!((k - want).abs() < 1e-12, "vertex {v}: {k} vs {want}");
        }
        let d = 2.0 * 3f64.sqrt();
        let hot = GaussianCurvature::new(1.0, d).unwrap();
        let mut s = vec![false; 8];
        hot.select(&view, &mut s).unwrap();
        assert!(s.iter().all(|&x| x));
        let cold = GaussianCurvature::new(1e6, d).unwrap();
        let mut s = vec![false; 8];
        cold.select(&view, &mut s).unwrap();
        assert!(!s.iter().any(|&x| x));
        assert!(GaussianCurvature::new(-1.0, d).is_err());
    }

    #[test]
    fn a_vertex_selection_takes_faces_with_two_selected_vertices() {
        let (t, _) = bump(0.0);
        // Vertices 0 and 6 share faces 0 (0, 1, 6) and 1 (0, 6, 5); 24 alone selects nothing.
        let s = FaceSelection::from_vertices(&t, &[0, 6, 24]).unwrap();
        assert_eq!(s.num_selected(), 2);
        assert!(FaceSelection::from_vertices(&t, &[25]).is_err());
        assert!(FaceSelection::from_faces(32, &[32]).is_err());
    }

    #[test]
    fn the_distance_criterion_meets_its_tolerance_on_every_face() {
        let (t, p) = octahedron();
        let o = Options::default();
        for limit in [false, true] {
            let surface = LimitSurface::new(&t, &p, &Scheme::Loop, &o).unwrap();
            let tol = 2e-3;
            let c = LimitDistance::new(surface, tol, limit).unwrap();
            let a = AdaptiveRefinement::new(&t, &p, &Scheme::Loop, &o, &[&c], 8).unwrap();
            let positions = if limit {
                Positions::Limit
            } else {
                Positions::Refined
            };
            let mesh = a.mesh(positions).unwrap();
            let d = mesh.max_limit_distance(c.surface()).unwrap();
            assert!(d <= tol, "limit {limit}: {d}");
            assert!(a.depth() < 8);
        }
    }
}
