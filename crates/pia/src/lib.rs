//! Progressive iterative interpolation (PIA) for subdivision surfaces.
//!
//! Given a mesh whose vertices are *targets*, PIA finds control positions whose limit surface
//! passes through them: Chen et al. (2008) for Catmull-Clark, Cheng et al. (2009) for Loop,
//! and the two-phase modified Catmull-Clark scheme of Lin et al. (Lin, Pan et al.), whose
//! per-vertex `λ` shapes the surface between the interpolated points.
//!
//! * **Global** PIA moves every vertex; **local** PIA (Zhao & Lin 2012, Lin et al. §2) moves
//!   only a chosen set `P` and keeps the others (`Q`) where they are, so their limits stay
//!   approximations ([`Moving`]).
//! * The limit of every vertex comes from [`subd_limit`]'s exact limit stencils, so
//!   boundaries, creases, corners and (Catmull-Clark, Loop) non-quad faces work wherever the
//!   scheme's limit is defined. The paper's scheme needs quads; its boundary rule is derived
//!   in [`subd_schemes::two_phase`].
//! * Solvers ([`Solver`]): the paper's iteration exactly as published, an optimally weighted
//!   iteration, conjugate gradients on the symmetrised system (Lin et al. eqs. 17–18: the
//!   limit matrix is `C·D` with `C` positive diagonal and `D` symmetric; BiCGSTAB where no
//!   such split exists, e.g. at boundaries and creases), a Chebyshev iteration on the
//!   checkerboard-preconditioned system (two-coloured closed quad meshes; see
//!   [`Solver::Chebyshev`]), and sparse direct factorisation. Every solver reports the max
//!   interpolation error after each iteration (Chebyshev: after each checkpoint).
//!
//! The tolerance is relative to the bounding-box diagonal of the targets: a solve stops when
//! `max_{i ∈ P} |v∞_i − p_i| ≤ tol · diagonal`.
//!
//! ```
//! use subd_mesh::{DVec3, TopologyBuilder};
//! use subd_pia::{Moving, Pia, PiaOptions};
//! use subd_schemes::{Options, Scheme};
//!
//! // Make the Catmull-Clark limit surface of a cube pass through its 8 corners.
//! let faces = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4];
//! let cube = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
//! let targets: Vec<DVec3> = (0..8)
//!     .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
//!     .collect();
//! let pia = Pia::new(&cube, &Scheme::CatmullClark, &Options::default()).unwrap();
//! let result = pia.solve(&targets, &Moving::All, &PiaOptions::default()).unwrap();
//! assert!(result.converged);
//! let limit = pia.limit_table().apply_points(&result.points);
//! for (l, t) in limit.iter().zip(&targets) {
//!     assert!((*l - *t).length() < 1e-9);
//! }
//! ```

pub mod checkerboard;
pub mod interpolation;
mod matrix;
mod ritz;
mod solvers;
mod system;

use std::sync::Arc;

use glam::DVec3;
use subd_limit::LimitError;
use subd_mesh::Topology;
use subd_schemes::{Capability, Options, Scheme, StencilTable};
use thiserror::Error;

pub use interpolation::{Interpolation, InterpolationReport, InterpolationRequest, interpolate};
pub use solvers::{Method, Solver};
use system::{FullSystem, ReducedSystem};

/// What can go wrong setting up or solving an interpolation.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum PiaError {
    /// The scheme's limit is not defined for this mesh (or refinement failed).
    #[error(transparent)]
    Limit(#[from] LimitError),
    /// A vertex index outside the mesh.
    #[error("vertex {index} does not exist (the mesh has {count} vertices)")]
    Vertex {
        /// The index given.
        index: u64,
        /// Vertices of the mesh.
        count: usize,
    },
    /// Not one target per vertex.
    #[error("{given} targets for {vertices} vertices")]
    Targets {
        /// Targets given.
        given: usize,
        /// Vertices of the mesh.
        vertices: usize,
    },
    /// A target that is not finite.
    #[error("vertex {0}: target is not a finite point")]
    NotFinite(usize),
    /// A tolerance that is not a positive number.
    #[error("tolerance {0} is not a positive number")]
    Tolerance(f64),
    /// A scheme without a limit-position matrix here.
    #[error(
        "interpolation needs {} (the {scheme} scheme has no limit matrix here)",
        Scheme::list_with(Capability::Interpolate)
    )]
    Scheme {
        /// The scheme given.
        scheme: String,
    },
    /// The linear algebra failed (a singular system).
    #[error("solver: {0}")]
    Solver(String),
}

/// Which vertices move.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Moving {
    /// Every vertex (global PIA).
    All,
    /// These vertices move, the others stay (local PIA).
    Only(Vec<u32>),
    /// These vertices stay, the others move (local PIA).
    AllBut(Vec<u32>),
}

impl Moving {
    /// One flag per vertex.
    ///
    /// # Errors
    /// [`PiaError::Vertex`] for an index outside `0..num_vertices`.
    pub fn flags(&self, num_vertices: usize) -> Result<Vec<bool>, PiaError> {
        let (list, value) = match self {
            Moving::All => return Ok(vec![true; num_vertices]),
            Moving::Only(l) => (l, true),
            Moving::AllBut(l) => (l, false),
        };
        let mut flags = vec![!value; num_vertices];
        for &v in list {
            if v as usize >= num_vertices {
                return Err(PiaError::Vertex {
                    index: v as u64,
                    count: num_vertices,
                });
            }
            flags[v as usize] = value;
        }
        Ok(flags)
    }
}

/// Solver choice and stop rule.
#[derive(Debug, Clone, Copy)]
pub struct PiaOptions {
    /// The solver.
    pub solver: Solver,
    /// Stop when the max interpolation error is at most `tol` × the targets' bounding-box
    /// diagonal.
    pub tol: f64,
    /// Most iterations.
    pub max_iter: usize,
}

impl Default for PiaOptions {
    fn default() -> Self {
        PiaOptions {
            solver: Solver::Auto,
            tol: 1e-10,
            max_iter: 10_000,
        }
    }
}

/// The outcome of a solve.
#[derive(Debug, Clone)]
pub struct PiaResult {
    /// New control positions: moved vertices solved, fixed ones equal to their targets.
    pub points: Vec<DVec3>,
    /// Max interpolation error over the moving vertices before the first iteration and
    /// after each one (model units).
    pub history: Vec<f64>,
    /// Iterations run (`history.len() − 1`, except for [`Method::Chebyshev`], whose history
    /// holds the error at its checkpoints).
    pub iterations: usize,
    /// The method that ran.
    pub method: Method,
    /// Whether the last error is within the threshold.
    pub converged: bool,
    /// The stop threshold in model units (`tol` × diagonal).
    pub threshold: f64,
    /// Number of moving vertices.
    pub moving: usize,
}

/// A PIA problem: the limit-position matrix of a scheme on one mesh, ready to interpolate
/// any targets. It holds the matrix in the form every solver reads (rounding noise of
/// stencil composition dropped, rows sorted). Where every row is the scheme's classical
/// smooth mask (closed smooth meshes of quads, or triangles for Loop) the symmetric form of
/// the Krylov and direct solvers is known from the start; elsewhere the first solve that
/// needs it finds and checks it. That solve, or [`Pia::prepare`], also builds the Chebyshev
/// operator where it applies. Both are kept, so later solves on the same `Pia` (other
/// targets, other moving sets) start at once.
#[derive(Debug, Clone)]
pub struct Pia {
    limit: StencilTable,
    /// The limit matrix in the solvers' form, with the checkerboard scaling for the
    /// preconditioned solvers (Catmull-Clark family, two-coloured vertex graph).
    full: Arc<FullSystem>,
}

impl Pia {
    /// The limit matrix of `scheme` on `topology` (the exact limit-position stencils of
    /// [`subd_limit::base_limit_positions`] / [`subd_limit::two_phase_base_limit_positions`]),
    /// in the solvers' form.
    ///
    /// # Errors
    /// [`PiaError::Limit`] when the scheme does not apply (Loop on a non-triangle,
    /// two-phase on a non-quad or with a wrong `λ` count).
    pub fn new(topology: &Topology, scheme: &Scheme, options: &Options) -> Result<Pia, PiaError> {
        let table = match scheme {
            Scheme::CatmullClark | Scheme::Loop => {
                subd_limit::base_limit_positions(topology, scheme, options)?
            }
            Scheme::TwoPhase(tp) => {
                subd_limit::two_phase_base_limit_positions(topology, tp, options)?
            }
            other => {
                return Err(PiaError::Scheme {
                    scheme: other.to_string(),
                });
            }
        };
        // Loop's mask has no checkerboard structure (and triangles no two-colouring).
        let signs = match scheme {
            Scheme::Loop => None,
            _ => checkerboard::checkerboard_signs(topology),
        };
        let face_size = match scheme {
            Scheme::Loop => 3,
            _ => 4,
        };
        // Where every vertex takes its scheme's classical smooth mask, row `i` is `c_i` times
        // one weight for each edge neighbour, another for each face-diagonal vertex and one
        // for the vertex itself: Catmull-Clark 4, 1 and `n²` over `n (n + 5)`; two-phase
        // `β_n` and `3 β_n / 10` (formula (2); the ratio does not depend on `λ`, Lin et al.
        // eqs. 17–18); Loop one weight for the whole ring. Scaled by the edge weight, `D`
        // holds 1 at edge neighbours and `1/4` or `3/10` at diagonal ones on every row
        // alike: `M̄ = C D` with `D` symmetric by construction.
        let classical = topology.is_closed_smooth_uniform(face_size);
        // Rows of the classical masks: the vertex, its edge neighbours and (quads) its
        // face-diagonal vertices.
        let row_len = |v: usize| 1 + (face_size - 2) * topology.vertex_edges(v).len();
        let full = FullSystem::new(
            &table,
            signs,
            classical.then_some(&row_len as &(dyn Fn(usize) -> usize + Sync)),
        );
        Ok(Pia {
            limit: table,
            full: Arc::new(full),
        })
    }

    /// A problem from any square limit-position table (row `i`: the limit of vertex `i`).
    ///
    /// # Panics
    /// If the table is not square.
    pub fn from_limit_table(limit: StencilTable) -> Pia {
        assert_eq!(
            limit.num_rows(),
            limit.num_sources(),
            "a square limit table"
        );
        let full = Arc::new(FullSystem::new(&limit, None, None));
        Pia { limit, full }
    }

    /// The limit-position table `B`.
    pub fn limit_table(&self) -> &StencilTable {
        &self.limit
    }

    /// Number of vertices.
    pub fn num_vertices(&self) -> usize {
        self.limit.num_rows()
    }

    /// Solves for control positions whose limits interpolate `targets` at the moving
    /// vertices; fixed vertices keep their targets as positions. Starts from the targets
    /// (as the paper does).
    ///
    /// # Errors
    /// [`PiaError::Targets`], [`PiaError::NotFinite`], [`PiaError::Vertex`],
    /// [`PiaError::Tolerance`] for bad input; [`PiaError::Solver`] when a direct
    /// factorisation fails.
    pub fn solve(
        &self,
        targets: &[DVec3],
        moving: &Moving,
        options: &PiaOptions,
    ) -> Result<PiaResult, PiaError> {
        let system = self.system(targets, moving)?;
        if options.tol.is_nan() || options.tol <= 0.0 {
            return Err(PiaError::Tolerance(options.tol));
        }
        let diagonal = bbox_diagonal(targets);
        let threshold = options.tol * if diagonal > 0.0 { diagonal } else { 1.0 };
        let x0: Vec<DVec3> = system.moving.iter().map(|&v| targets[v as usize]).collect();
        let ctl = solvers::Controls {
            threshold,
            max_iter: options.max_iter,
        };
        let out = solvers::solve(&system, x0, options.solver, ctl)?;
        let last = *out.history.last().unwrap_or(&0.0);
        // Every vertex moving: the unknowns are the points, in order.
        let points = if system.len() == targets.len() {
            out.x
        } else {
            let mut points = targets.to_vec();
            for (&v, &x) in system.moving.iter().zip(&out.x) {
                points[v as usize] = x;
            }
            points
        };
        Ok(PiaResult {
            points,
            iterations: out.steps,
            converged: last <= threshold,
            history: out.history,
            method: out.method,
            threshold,
            moving: system.len(),
        })
    }

    /// Builds now what the solvers of a global solve (every vertex moving) keep for later
    /// solves: the symmetric form of the limit matrix and, for the Catmull-Clark family on
    /// a two-coloured closed quad mesh, the checkerboard operator of [`Solver::Chebyshev`]
    /// with its spectral interval. A prepared `Pia` solves with Chebyshev under
    /// [`Solver::Auto`] (an unprepared one with checkerboard CG, which needs only the
    /// symmetric form): for interactive editing or animation, where one mesh is solved many
    /// times.
    /// Returns whether the Chebyshev operator is available.
    pub fn prepare(&self) -> bool {
        self.full.preconditioned().is_some()
    }

    /// `M̄ = B[P, P]` as a dense matrix, for analysis of small meshes (spectral radius of
    /// `I − M̄`, Theorem 1 of Lin et al.).
    ///
    /// # Errors
    /// [`PiaError::Vertex`] for a bad index in `moving`.
    pub fn moving_matrix(&self, moving: &Moving) -> Result<(Vec<u32>, faer::Mat<f64>), PiaError> {
        let zero = vec![DVec3::ZERO; self.num_vertices()];
        let s = self.system(&zero, moving)?;
        let n = s.len();
        let mut m = faer::Mat::<f64>::zeros(n, n);
        for i in 0..n {
            let (cols, w) = s.row(i);
            for (&j, &x) in cols.iter().zip(w) {
                m[(i, j as usize)] += x;
            }
        }
        Ok((s.moving, m))
    }

    /// Whether `M̄` has the symmetric form `C·D` (C positive diagonal, D symmetric) that the
    /// conjugate-gradient solver uses.
    ///
    /// # Errors
    /// [`PiaError::Vertex`] for a bad index in `moving`.
    pub fn is_symmetrizable(&self, moving: &Moving) -> Result<bool, PiaError> {
        let zero = vec![DVec3::ZERO; self.num_vertices()];
        // Always the pairwise check (the solvers take the form from theory where they can).
        Ok(self.system(&zero, moving)?.matrix.symmetrizer().is_some())
    }

    pub(crate) fn system(
        &self,
        targets: &[DVec3],
        moving: &Moving,
    ) -> Result<ReducedSystem, PiaError> {
        let n = self.num_vertices();
        if targets.len() != n {
            return Err(PiaError::Targets {
                given: targets.len(),
                vertices: n,
            });
        }
        if let Some(v) = targets.iter().position(|p| !p.is_finite()) {
            return Err(PiaError::NotFinite(v));
        }
        let flags = moving.flags(n)?;
        Ok(ReducedSystem::from_full(&self.full, targets, &flags))
    }
}

/// How far a solve's limit surface is from its targets, measured independently of the
/// solver: with a limit table built afresh and applied to the solved points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Deviation {
    /// The largest distance of a moving vertex's limit from its target (model units).
    pub max_error: f64,
    /// `max_error` over the targets' bounding-box diagonal (`max_error` itself when the
    /// diagonal is 0).
    pub relative: f64,
}

impl Deviation {
    /// Whether the relative error is within `tol`, with a margin of `1e-6 tol` for the
    /// fresh table, whose rounding differs from the solver's.
    pub fn within(&self, tol: f64) -> bool {
        !(self.relative.is_nan() || self.relative > tol * (1.0 + 1e-6))
    }
}

/// The [`Deviation`] of `points` as control points of `scheme` on `topology` from `targets`
/// at the `moving` vertices.
///
/// # Errors
/// [`PiaError::Limit`] where the scheme's limit is not defined for the mesh;
/// [`PiaError::Vertex`] for a bad index in `moving`; [`PiaError::Targets`] when `points` or
/// `targets` is not one per vertex.
pub fn deviation(
    topology: &Topology,
    scheme: &Scheme,
    options: &Options,
    points: &[DVec3],
    targets: &[DVec3],
    moving: &Moving,
) -> Result<Deviation, PiaError> {
    let nv = topology.num_vertices();
    if let Some(given) = [points.len(), targets.len()].into_iter().find(|&n| n != nv) {
        return Err(PiaError::Targets {
            given,
            vertices: nv,
        });
    }
    let check = match scheme {
        Scheme::TwoPhase(tp) => subd_limit::two_phase_base_limit_positions(topology, tp, options),
        s => subd_limit::base_limit_positions(topology, s, options),
    }?;
    let limit = check.apply_points(points);
    let flags = moving.flags(nv)?;
    let max_error = (0..nv)
        .filter(|&v| flags[v])
        .map(|v| (limit[v] - targets[v]).length())
        .fold(0.0, f64::max);
    let diagonal = bbox_diagonal(targets);
    let relative = if diagonal > 0.0 {
        max_error / diagonal
    } else {
        max_error
    };
    Ok(Deviation {
        max_error,
        relative,
    })
}

/// Length of the diagonal of the axis-aligned bounding box of `points`.
pub fn bbox_diagonal(points: &[DVec3]) -> f64 {
    if points.is_empty() {
        return 0.0;
    }
    let (lo, hi) = points.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    (hi - lo).length()
}

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
