//! [`adapt_mesh`]: adaptive refinement of a whole [`Mesh`] in one call, its criteria named
//! by their thresholds as `subd adaptive` takes them, its texture coordinates carried to
//! their exact limit at every corner; [`adapt_mesh_with`], the same with a report and
//! progress: the one workflow behind `subd adaptive` and the Python package's
//! `subd.adaptive`.

use std::time::Instant;

use serde::Serialize;
use subd_limit::eval::LimitEvaluator;
use subd_mesh::Mesh;
use subd_mesh::fvar::FVarLinearInterpolation;
use subd_schemes::{Options, Scheme};

pub use crate::report::{AdaptiveReport, CriteriaReport, Thresholds};
use crate::{
    AdaptiveError, AdaptiveFVar, AdaptiveMesh, AdaptiveRefinement, Criterion, DihedralAngle,
    FaceSelection, Flatness, GaussianCurvature, LimitDistance, LimitSurface, Positions,
};

/// The criteria and options of one adaptive refinement; a face is refined when any
/// criterion asks for it (every face, to `levels`, when none is given).
#[derive(Debug, Clone)]
pub struct AdaptiveRequest {
    /// Loop or Catmull-Clark.
    pub scheme: Scheme,
    /// Boundary, crease and triangle rules.
    pub options: Options,
    /// The level cap.
    pub levels: usize,
    /// Every vertex at its exact limit position, with limit normals.
    pub limit: bool,
    /// Sun et al.'s flatness, in degrees ([`Flatness`]).
    pub flatness: Option<f64>,
    /// Largest distance to the limit surface, relative to the bounding-box diagonal
    /// ([`LimitDistance`]).
    pub max_distance: Option<f64>,
    /// Gaussian curvature times the squared diagonal ([`GaussianCurvature`]).
    pub curvature: Option<f64>,
    /// Dihedral angle in degrees ([`DihedralAngle`]).
    pub dihedral: Option<f64>,
    /// Base faces whose descendants are refined.
    pub select_faces: Option<Vec<u64>>,
    /// Base vertices: the faces with two or more of them are refined.
    pub select_vertices: Option<Vec<u64>>,
    /// How the texture coordinates interpolate.
    pub fvar_interpolation: FVarLinearInterpolation,
}

impl AdaptiveRequest {
    /// The thresholds of the criteria.
    pub fn thresholds(&self) -> Thresholds {
        Thresholds {
            flatness: self.flatness,
            max_distance: self.max_distance,
            curvature: self.curvature,
            dihedral: self.dihedral,
        }
    }

    /// Checks what can be checked without the mesh: the thresholds and the level cap.
    ///
    /// # Errors
    /// As [`Thresholds::check`].
    pub fn check(&self) -> Result<(), AdaptiveError> {
        self.thresholds().check(self.levels)
    }
}

/// What [`adapt_mesh_with`] measures besides the mesh.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct AdaptOptions {
    /// Build an [`AdaptiveReport`].
    pub report: bool,
    /// With `report`, measure the largest sampled distance to the limit surface without a
    /// max-distance criterion (a limit evaluation at 7–9 points per output face).
    pub report_distance: bool,
}

/// Where [`adapt_mesh_with`] spent its time, in seconds.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct AdaptiveSeconds {
    /// Building the hierarchy (the criteria judged level by level).
    pub hierarchy: f64,
    /// Closing it into the conforming mesh.
    pub mesh: f64,
    /// The distance check and the report.
    pub report: f64,
}

/// An adaptive refinement's result: the crack-free mesh, its texture coordinates (their
/// exact limit at every corner) and what was left out.
#[derive(Debug)]
pub struct AdaptedMesh {
    /// The conforming mesh (positions, faces, the level of every face, normals with
    /// `limit`).
    pub mesh: AdaptiveMesh,
    /// The input's texture coordinates on it, where it has them.
    pub uv: Option<AdaptiveFVar>,
    /// What was left out or not met: a max-distance the level cap stopped short, texture
    /// coordinates the evaluator cannot carry.
    pub warnings: Vec<String>,
    /// The report, with [`AdaptOptions::report`].
    pub report: Option<AdaptiveReport>,
    /// Where the time went.
    pub seconds: AdaptiveSeconds,
}

/// `mesh` refined where `request`'s criteria ask, crack-free, every vertex one of uniform
/// refinement's (or, with `limit`, of the limit surface): [`adapt_mesh_with`] without a
/// report or progress, the call behind `subd.adaptive`.
///
/// ```
/// use subd_adaptive::request::{adapt_mesh, AdaptiveRequest};
/// use subd_mesh::fvar::FVarLinearInterpolation;
/// use subd_mesh::{DVec3, Mesh, TopologyBuilder};
/// use subd_schemes::{Options, Scheme};
///
/// let faces = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4];
/// let topology = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
/// let corners = (0..8).map(|i| DVec3::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2) as f64));
/// let cube = Mesh::new(topology, corners.collect()).unwrap();
/// let request = AdaptiveRequest {
///     scheme: Scheme::CatmullClark,
///     options: Options::default(),
///     levels: 2,
///     limit: false,
///     flatness: None,
///     max_distance: None,
///     curvature: None,
///     dihedral: None,
///     select_faces: Some(vec![0]),
///     select_vertices: None,
///     fvar_interpolation: FVarLinearInterpolation::CornersPlus1,
/// };
/// let adapted = adapt_mesh(&cube, &request).unwrap();
/// // Face 0 refined twice (16 faces); its neighbours carry the transition.
/// assert_eq!(adapted.mesh.face_levels.iter().filter(|&&l| l == 2).count(), 16);
/// ```
///
/// # Errors
/// As [`adapt_mesh_with`].
pub fn adapt_mesh(mesh: &Mesh, request: &AdaptiveRequest) -> Result<AdaptedMesh, AdaptiveError> {
    adapt_mesh_with(mesh, request, &AdaptOptions::default(), &mut |_| {})
}

/// The adaptive workflow, the one library call behind `subd adaptive` and `subd.adaptive`:
/// `mesh` refined where `request`'s criteria ask, closed into a crack-free mesh, checked
/// against the max-distance tolerance (a warning where the level cap stopped it short),
/// measured for a report with `options.report`, its texture coordinates carried to their
/// exact limit. `progress` hears each step ("level 2: 1234 faces", "conforming mesh", ...).
///
/// # Errors
/// A threshold or level cap out of range ([`AdaptiveRequest::check`]), a selected index
/// out of range, a scheme or mesh the refinement (or, with a distance criterion, the limit
/// evaluator) does not cover.
pub fn adapt_mesh_with(
    mesh: &Mesh,
    request: &AdaptiveRequest,
    options: &AdaptOptions,
    progress: &mut dyn FnMut(&str),
) -> Result<AdaptedMesh, AdaptiveError> {
    request.check()?;
    let diagonal = mesh
        .bounding_box()
        .map_or(0.0, |(lo, hi)| (hi - lo).length());
    let criteria = Criteria::new(mesh, request, diagonal)?;
    let base = &mesh.topology;
    let t0 = Instant::now();
    let mut hierarchy = AdaptiveRefinement::with_progress(
        base,
        &mesh.positions,
        &request.scheme,
        &request.options,
        &criteria.all(),
        request.levels,
        &mut |level, faces| progress(&format!("level {level}: {faces} faces")),
    )?;
    let t_hierarchy = t0.elapsed().as_secs_f64();
    progress("conforming mesh");
    let t1 = Instant::now();
    let positions = if request.limit {
        Positions::Limit
    } else {
        Positions::Refined
    };
    // The distance criterion judged this very mesh: taken, not built again.
    let result = hierarchy.take_mesh(positions)?;
    let t_mesh = t1.elapsed().as_secs_f64();

    let t2 = Instant::now();
    // One limit evaluator serves the distance criterion, the report and the UVs.
    let own;
    let surface = match &criteria.distance {
        Some(d) => Some(d.surface()),
        None if (options.report && options.report_distance) || mesh.uv().is_some() => {
            own = LimitSurface::new(base, &mesh.positions, &request.scheme, &request.options);
            own.as_ref().ok()
        }
        None => None,
    };
    progress("measuring");
    let check = DistanceCheck::new(
        (request, options),
        &criteria,
        (&hierarchy, &result),
        surface,
    );
    let mut warnings: Vec<String> = check.warning(request, diagonal).into_iter().collect();
    let report = options
        .report
        .then(|| report((mesh, request), (&hierarchy, &result), &check, diagonal));
    let t_report = t2.elapsed().as_secs_f64();

    progress("texture coordinates");
    let uv = mesh.uv().and_then(|_| {
        let evaluator = surface.map(LimitSurface::evaluator);
        adapted_uv(mesh, request, evaluator, &result)
            .map_err(|e| warnings.push(format!("texture coordinates left out: {e}")))
            .ok()
    });
    Ok(AdaptedMesh {
        mesh: result,
        uv,
        warnings,
        report,
        seconds: AdaptiveSeconds {
            hierarchy: t_hierarchy,
            mesh: t_mesh,
            report: t_report,
        },
    })
}

/// The criteria a request names, the distance criterion apart: its limit surface also
/// serves the texture coordinates and a report's distance.
pub struct Criteria {
    /// Flatness, dihedral angle, curvature and the selections, in that order.
    pub others: Vec<Box<dyn Criterion>>,
    /// The distance to the limit surface.
    pub distance: Option<LimitDistance>,
}

impl Criteria {
    /// The criteria of `request` on `mesh`, whose bounding-box diagonal is `diagonal`.
    ///
    /// # Errors
    /// A threshold out of range, a selected index out of range, or a mesh the limit
    /// evaluator does not cover (with a distance criterion).
    pub fn new(
        mesh: &Mesh,
        request: &AdaptiveRequest,
        diagonal: f64,
    ) -> Result<Criteria, AdaptiveError> {
        let base = &mesh.topology;
        let mut others: Vec<Box<dyn Criterion>> = Vec::new();
        if let Some(d) = request.flatness {
            others.push(Box::new(Flatness::new(d)?));
        }
        if let Some(d) = request.dihedral {
            others.push(Box::new(DihedralAngle::new(d)?));
        }
        if let Some(k) = request.curvature {
            others.push(Box::new(GaussianCurvature::new(k, diagonal)?));
        }
        if let Some(faces) = &request.select_faces {
            others.push(Box::new(FaceSelection::from_faces(
                base.num_faces(),
                faces,
            )?));
        }
        if let Some(vertices) = &request.select_vertices {
            others.push(Box::new(FaceSelection::from_vertices(base, vertices)?));
        }
        let distance = match request.max_distance {
            Some(d) => {
                let s =
                    LimitSurface::new(base, &mesh.positions, &request.scheme, &request.options)?;
                Some(LimitDistance::new(s, d * diagonal, request.limit)?)
            }
            None => None,
        };
        Ok(Criteria { others, distance })
    }

    /// Every criterion, the distance last.
    pub fn all(&self) -> Vec<&dyn Criterion> {
        let mut all: Vec<&dyn Criterion> = self.others.iter().map(|c| c.as_ref()).collect();
        if let Some(d) = &self.distance {
            all.push(d);
        }
        all
    }
}

/// The input's texture coordinates at every corner of `result`: their exact limit at the
/// corner's parameter, with `surface`'s evaluator when there is one.
///
/// # Panics
/// If `mesh` has no texture coordinates.
pub fn adapted_uv(
    mesh: &Mesh,
    request: &AdaptiveRequest,
    surface: Option<&LimitEvaluator>,
    result: &AdaptiveMesh,
) -> Result<AdaptiveFVar, AdaptiveError> {
    let channel = mesh.uv().expect("called with texture coordinates");
    let own;
    let evaluator = match surface {
        Some(s) => s,
        None => {
            own = LimitEvaluator::new(&mesh.topology, &request.scheme, &request.options)?;
            &own
        }
    };
    let uv_eval = evaluator.face_varying(channel, request.fvar_interpolation)?;
    let values = uv_eval.prepare(channel.values())?;
    result.face_varying_limit(&uv_eval, &values)
}

/// The largest sampled distance of the output to the limit surface (for the report), and
/// whether it meets the max-distance tolerance.
struct DistanceCheck {
    /// For the report.
    distance: Option<f64>,
    /// What the tolerance was checked with.
    worst: Option<f64>,
    met: Option<bool>,
}

impl DistanceCheck {
    /// Measures the output's distance to the limit where it is asked for: with a distance
    /// criterion from what it measured on this mesh (reused, not measured again), on
    /// `surface` for a report with `report_distance`; `None` otherwise.
    fn new(
        (request, options): (&AdaptiveRequest, &AdaptOptions),
        criteria: &Criteria,
        (hierarchy, result): (&AdaptiveRefinement, &AdaptiveMesh),
        surface: Option<&LimitSurface>,
    ) -> DistanceCheck {
        let report = options.report;
        let Some(criterion) = &criteria.distance else {
            let wanted = report && options.report_distance;
            let distance = surface
                .filter(|_| wanted)
                .and_then(|s| result.max_limit_distance(s).ok());
            return DistanceCheck {
                distance,
                worst: None,
                met: None,
            };
        };
        // The distance criterion is the last one (Criteria::all).
        let judged = hierarchy.final_errors().last().copied().flatten();
        // With `limit` the criterion left the leaves to its level-by-level selection, which
        // cleared those below the cap: the cap's leaves decide the tolerance, all of them
        // the report's distance.
        let leaves = |all: bool| {
            result
                .max_limit_distance_of(criterion.surface(), |f| {
                    !criterion.judged(result, f)
                        && (all || result.face_levels[f] as usize == request.levels)
                })
                .ok()
        };
        let worst = if request.limit {
            judged.zip(leaves(report)).map(|(a, b)| a.max(b))
        } else {
            judged
        };
        DistanceCheck {
            distance: worst.filter(|_| report),
            worst,
            met: worst.map(|w| w <= criterion.tolerance()),
        }
    }

    /// The warning that the level cap stopped the max-distance criterion short, naming the
    /// level that would meet it by the distance's ~4× fall per level (Loop and
    /// Catmull-Clark converge quadratically in the edge length, which halves per level).
    fn warning(&self, request: &AdaptiveRequest, diagonal: f64) -> Option<String> {
        let (Some(false), Some(tolerance)) = (self.met, request.max_distance) else {
            return None;
        };
        let levels = request.levels;
        let worst = self.worst? / diagonal;
        let more = (worst / tolerance).log(4.0).ceil().max(1.0) as usize;
        Some(format!(
            "max-distance {tolerance:e} not met: levels {levels} stopped the refinement at a \
             sampled distance of {worst:.3e} × the diagonal; about level {} would meet it \
             (the distance falls ~4× per level)",
            levels + more
        ))
    }
}

/// The report on `result`, built by `hierarchy` from `mesh` as `request` asks.
fn report(
    (mesh, request): (&subd_mesh::Mesh, &AdaptiveRequest),
    (hierarchy, result): (&AdaptiveRefinement, &AdaptiveMesh),
    check: &DistanceCheck,
    diagonal: f64,
) -> AdaptiveReport {
    let (base, options) = (&mesh.topology, &request.options);
    let depth = hierarchy.depth();
    let uniform_faces = hierarchy.uniform_counts(depth).faces;
    let size = |s: &Option<Vec<u64>>, (one, many): (&str, &str)| {
        s.as_ref().map(|s| match s.len() {
            1 => format!("1 {one}"),
            n => format!("{n} {many}"),
        })
    };
    AdaptiveReport {
        scheme: hierarchy.scheme().name(),
        levels: request.levels,
        depth,
        limit: request.limit,
        boundary_interpolation: options.boundary_interpolation,
        crease_method: options.crease_method,
        triangle_subdivision: options.triangle_subdivision,
        criteria: CriteriaReport {
            thresholds: request.thresholds(),
            select_faces: size(&request.select_faces, ("face", "faces")),
            select_vertices: size(&request.select_vertices, ("vertex", "vertices")),
        },
        input_faces: base.num_faces(),
        input_boundary_edges: (0..base.num_edges())
            .filter(|&e| base.is_boundary_edge(e))
            .count(),
        faces: result.num_faces(),
        vertices: result.positions.len(),
        faces_per_level: result.faces_per_level(),
        transition_faces: result.transition.iter().filter(|&&t| t).count(),
        uniform_faces,
        face_ratio: result.num_faces() as f64 / uniform_faces.max(1) as f64,
        level_builds: hierarchy.level_builds(),
        conformity: result.conformity(),
        min_angle_degrees: result.min_angle_degrees(),
        max_distance_to_limit: check.distance,
        max_distance_to_limit_relative: check.distance.map(|d| d / diagonal),
        tolerance_met: check.met,
        bbox_diagonal: diagonal,
    }
}

#[cfg(test)]
mod tests {
    use subd_mesh::fvar::FVarLinearInterpolation;
    use subd_mesh::{DVec3, Mesh, TopologyBuilder};
    use subd_schemes::{Options, Scheme};

    use super::{AdaptOptions, AdaptiveRequest, adapt_mesh, adapt_mesh_with};
    use crate::AdaptiveError;

    fn cube() -> Mesh {
        let faces = [
            0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4,
        ];
        let topology = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
        let corners =
            (0..8).map(|i| DVec3::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2) as f64));
        Mesh::new(topology, corners.collect()).unwrap()
    }

    fn request(levels: usize) -> AdaptiveRequest {
        AdaptiveRequest {
            scheme: Scheme::CatmullClark,
            options: Options::default(),
            levels,
            limit: false,
            flatness: None,
            max_distance: None,
            curvature: None,
            dihedral: None,
            select_faces: Some(vec![0]),
            select_vertices: None,
            fvar_interpolation: FVarLinearInterpolation::CornersPlus1,
        }
    }

    #[test]
    fn the_report_describes_the_mesh() {
        let what = AdaptOptions {
            report: true,
            report_distance: true,
        };
        let mut heard = Vec::new();
        let adapted = adapt_mesh_with(&cube(), &request(2), &what, &mut |m| {
            heard.push(m.to_string())
        })
        .unwrap();
        let report = adapted.report.unwrap();
        assert_eq!(report.faces, adapted.mesh.num_faces());
        assert_eq!(report.depth, 2);
        assert_eq!(report.criteria.select_faces.as_deref(), Some("1 face"));
        assert!(report.conformity.conforming);
        assert!(report.max_distance_to_limit.unwrap() > 0.0);
        assert_eq!(report.tolerance_met, None);
        assert!(heard.iter().any(|m| m == "conforming mesh"), "{heard:?}");
        // No report unless asked; the mesh is the same.
        let plain = adapt_mesh(&cube(), &request(2)).unwrap();
        assert!(plain.report.is_none());
        assert_eq!(plain.mesh.face_vertices, adapted.mesh.face_vertices);
    }

    #[test]
    fn thresholds_and_levels_are_checked_before_refining() {
        let mut r = request(2);
        r.flatness = Some(200.0);
        let e = adapt_mesh_with(&cube(), &r, &AdaptOptions::default(), &mut |_| {});
        assert!(matches!(
            e,
            Err(AdaptiveError::Threshold {
                name: "flatness",
                ..
            })
        ));
        let mut r = request(2);
        r.max_distance = Some(0.0);
        let e = r.check().unwrap_err().to_string();
        assert_eq!(e, "max-distance 0: must be a positive number");
        let e = request(crate::MAX_LEVELS + 1).check();
        assert!(matches!(e, Err(AdaptiveError::TooManyLevels { .. })));
    }

    #[test]
    fn a_distance_the_cap_stops_short_is_a_warning() {
        let mut r = request(1);
        (r.select_faces, r.max_distance) = (None, Some(1e-4));
        let adapted = adapt_mesh(&cube(), &r).unwrap();
        assert_eq!(adapted.warnings.len(), 1, "{:?}", adapted.warnings);
        assert!(adapted.warnings[0].starts_with("max-distance 1e-4 not met: levels 1"));
    }
}
