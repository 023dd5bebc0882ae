//! [`adapt_mesh`]: adaptive refinement of a whole [`Mesh`] in one call, its criteria named
//! by their thresholds as `subd adaptive` takes them, its texture coordinates carried to
//! their exact limit at every corner. The Python package's `subd.adaptive` calls it.

use subd_limit::eval::LimitEvaluator;
use subd_mesh::Mesh;
use subd_mesh::fvar::FVarLinearInterpolation;
use subd_schemes::{Options, Scheme};

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

/// An adaptive refinement's result: the crack-free mesh, its texture coordinates (their
/// exact limit at every corner) and what was left out.
#[derive(Debug)]
pub struct AdaptedMesh {
    /// The conforming mesh (positions, faces, the level of every face, normals with
    /// `limit`).
    pub mesh: AdaptiveMesh,
    /// The input's texture coordinates on it, where it has them.
    pub uv: Option<AdaptiveFVar>,
    /// What was left out (texture coordinates the evaluator cannot carry).
    pub warnings: Vec<String>,
}

/// `mesh` refined where `request`'s criteria ask, crack-free, every vertex one of uniform
/// refinement's (or, with `limit`, of the limit surface): the one library call behind
/// `subd.adaptive`, with the criteria `subd adaptive` builds from the same thresholds.
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
pub fn adapt_mesh(mesh: &Mesh, request: &AdaptiveRequest) -> Result<AdaptedMesh, AdaptiveError> {
    let diagonal = mesh
        .bounding_box()
        .map_or(0.0, |(lo, hi)| (hi - lo).length());
    let criteria = Criteria::new(mesh, request, diagonal)?;
    let base = &mesh.topology;
    let mut hierarchy = AdaptiveRefinement::new(
        base,
        &mesh.positions,
        &request.scheme,
        &request.options,
        &criteria.all(),
        request.levels,
    )?;
    let positions = if request.limit {
        Positions::Limit
    } else {
        Positions::Refined
    };
    let result = hierarchy.take_mesh(positions)?;
    let mut warnings = Vec::new();
    let uv = match mesh.uv() {
        None => None,
        Some(_) => {
            let surface = criteria.distance.as_ref().map(|d| d.surface().evaluator());
            match adapted_uv(mesh, request, surface, &result) {
                Ok(uv) => Some(uv),
                Err(e) => {
                    warnings.push(format!("texture coordinates left out: {e}"));
                    None
                }
            }
        }
    };
    Ok(AdaptedMesh {
        mesh: result,
        uv,
        warnings,
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
