//! The two solution methods of Li et al. 2008 §3.4 and §4, both as one linear map from the
//! constraints' right-hand side to the control-vertex changes, computed once per set of
//! constraint locations ([`Editor`]).
//!
//! * **Least squares** (minimum norm): `ΔX = Aᵀ (A Aᵀ)⁻¹ r`, r = b − A X₀, over the vertices
//!   the constraint rows involve and nothing else. `A Aᵀ` is c × c (c rows): factored by
//!   Cholesky (dense up to [`DENSE_ROWS`] rows, faer's sparse Cholesky above). A pivot below
//!   `1e-12` of its diagonal (dependent or conflicting rows) switches to the pseudo-inverse
//!   `A⁺` from the SVD of A: the minimum-norm least-squares solution.
//! * **Energy**: minimise the thin-plate (+ membrane) energy of the displacement,
//!   `Σ_c ΔX_cᵀ Q ΔX_c`, over the vertices within `region_rings` rings of the constraints
//!   (the rest fixed), subject to the rows. Exactly (the KKT system `[Q Aᵀ; A 0]` by faer's
//!   sparse LU; when it is singular — dependent or conflicting rows — by its Schur
//!   complement `ΔX = Q⁻¹Aᵀ (A Q⁻¹ Aᵀ)⁺ r`, Q by faer's sparse Cholesky, the c × c Schur
//!   matrix's pseudo-inverse giving the least-squares solution), or by Li et al.'s penalty
//!   `(Q + λ AᵀA) ΔX = λ Aᵀ r`. `Q` gets `1e-12` of its largest diagonal added: that keeps it
//!   definite when no vertex of a component is fixed (a translation costs no energy; with
//!   the term the smallest such move is taken) and changes nothing else measurably.
//!
//! Where the rows are dependent (and always for the penalty form, which cannot tell), the
//! [`crate::dependency`] analysis groups them by constraint; each solve reports the groups
//! with whether their targets agree ([`Edit::dependencies`]).

use std::sync::Arc;
use std::time::Instant;

use faer::linalg::solvers::{DenseSolveCore, Solve};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};
use glam::DVec3;
use subd_limit::eval::LimitEvaluator;
use subd_mesh::Topology;
use subd_mesh::choice::Choice;
use subd_mesh::neighbourhood;
use subd_schemes::{Options, Scheme};

use crate::EditError;
use crate::constraint::{Constraint, ConstraintRows, Row};
use crate::dependency::{Dependencies, DependentGroup};
use crate::energy::{EnergyMatrix, EnergyOptions};

/// Rows up to which `A Aᵀ` is factored densely.
pub const DENSE_ROWS: usize = 1500;

/// How the changes are chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// Minimum-norm change of the vertices the constraints involve.
    LeastSquares,
    /// Minimum energy of the displacement over a region.
    Energy {
        /// `None`: the exact equality-constrained solve; `Some(λ)`: the penalty form with
        /// weight λ relative to `mean diag Q / mean diag AᵀA`.
        penalty: Option<f64>,
        /// Rings around the constraints' vertices that may move (`None`: every vertex).
        region_rings: Option<usize>,
        /// The energy.
        energy: EnergyOptions,
    },
}

/// The methods by name, as `subd edit --method` and `subd.edit(method=…)` take them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum MethodKind {
    /// [`Method::LeastSquares`].
    #[default]
    LeastSquares,
    /// [`Method::Energy`].
    Energy,
}

impl Choice for MethodKind {
    const OPTION: &'static str = "editing method";
    const VALUES: &'static [(Self, &'static str, &'static str)] = &[
        (
            MethodKind::LeastSquares,
            "least-squares",
            "The smallest change of the control vertices the constraints involve (A⁺ r)",
        ),
        (
            MethodKind::Energy,
            "energy",
            "The smallest thin-plate (+ membrane) energy of the change over a region",
        ),
    ];
}

subd_mesh::choice_by_name!(MethodKind);

/// A method as a request names it: the kind and the energy method's options, checked by
/// [`MethodRequest::method`] the same way for every front.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct MethodRequest {
    /// Which method.
    pub kind: MethodKind,
    /// Energy method: the penalty form with this weight instead of the exact solve.
    pub penalty: Option<f64>,
    /// Energy method: the exact equality-constrained solve (the default; refused with a
    /// penalty).
    pub exact: bool,
    /// Energy method: weight of the membrane term (≥ 0).
    pub membrane: f64,
    /// Energy method: rings around the constraints' vertices that may move (`None`: all).
    pub region_rings: Option<usize>,
}

impl MethodRequest {
    /// The method, or why the options do not fit it (energy options given to least
    /// squares, a penalty that is not positive, a membrane weight that is negative or not
    /// finite, both a penalty and `exact`).
    pub fn method(&self) -> Result<Method, String> {
        let energy_only = self.penalty.is_some() || self.exact || self.membrane != 0.0;
        match self.kind {
            MethodKind::LeastSquares if energy_only => {
                Err("penalty, exact and membrane apply to the energy method only".into())
            }
            MethodKind::LeastSquares => Ok(Method::LeastSquares),
            MethodKind::Energy => self.energy(),
        }
    }

    /// The energy method's options, checked.
    fn energy(&self) -> Result<Method, String> {
        if self.penalty.is_some() && self.exact {
            return Err("penalty and exact: give one of them".into());
        }
        if let Some(p) = self.penalty
            && (p.is_nan() || p <= 0.0)
        {
            return Err(format!("penalty {p}: must be a positive number"));
        }
        let m = self.membrane;
        if !(m >= 0.0 && m.is_finite()) {
            return Err(format!("membrane {m}: must be a non-negative number"));
        }
        Ok(Method::Energy {
            penalty: self.penalty,
            region_rings: self.region_rings,
            energy: EnergyOptions {
                membrane: m,
                ..EnergyOptions::default()
            },
        })
    }
}

impl Method {
    /// The name reports give the method: `least-squares`, `energy-exact` or
    /// `energy-penalty`.
    pub fn report_name(&self) -> &'static str {
        match self {
            Method::LeastSquares => "least-squares",
            Method::Energy { penalty: None, .. } => "energy-exact",
            Method::Energy {
                penalty: Some(_), ..
            } => "energy-penalty",
        }
    }
}

/// Seconds spent in each phase.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Timings {
    /// The limit evaluator (0 when one was given).
    pub evaluator: f64,
    /// The constraint rows.
    pub constraints: f64,
    /// Energy matrix assembly (0 for least squares).
    pub assemble: f64,
    /// Factorisation and the solution map.
    pub factor: f64,
    /// The last solve (substitution).
    pub solve: f64,
}

/// What a solve found.
#[derive(Clone, Debug)]
pub struct Edit {
    /// New control vertices.
    pub positions: Vec<DVec3>,
    /// Vertices that moved, ascending.
    pub moved: Vec<u32>,
    /// Constraints whose rows are dependent (empty when the rows are independent): each
    /// group redundant (its targets agree, every row met) or conflicting (no change meets
    /// them all; the least-squares compromise and what it leaves unmet).
    pub dependencies: Vec<DependentGroup>,
}

/// An edit prepared for one set of constraint locations: the rows factored once, so that
/// [`Editor::solve`] with new targets only substitutes (the dragging loop of a modeller).
///
/// ```
/// use subd_editing::{Constraint, Editor, Goal, Location, Method};
/// use subd_mesh::DVec3;
/// use subd_schemes::{Options, Scheme};
///
/// // A torus: pull the limit point of vertex 0 outwards by 0.1.
/// let mesh = subd_mesh::primitives::torus(12, 8, 2.0, 0.5);
/// let c = vec![Constraint::Point {
///     at: Location::Vertex(0),
///     goal: Goal::Displacement(DVec3::new(0.0, 0.0, 0.1)),
/// }];
/// let ed = Editor::new(&mesh.topology, &mesh.positions, &Scheme::CatmullClark,
///                      &Options::default(), &c, Method::LeastSquares).unwrap();
/// let edit = ed.solve(&c).unwrap();
/// // The limit point moved by exactly the displacement.
/// let before = ed.limit_of(&c[0], &mesh.positions).unwrap();
/// let after = ed.limit_of(&c[0], &edit.positions).unwrap();
/// assert!((after - before - DVec3::new(0.0, 0.0, 0.1)).length() < 1e-12);
/// ```
#[derive(Debug)]
pub struct Editor {
    topology: Topology,
    scheme: Scheme,
    ev: Arc<LimitEvaluator>,
    base: Vec<DVec3>,
    constraints: Vec<Constraint>,
    rows: ConstraintRows,
    /// The vertices that may move, ascending; unknown `3 i + c` is coordinate c of
    /// `free[i]`.
    free: Vec<u32>,
    /// The solution map: changes (3 |free|) = `map` · (`pre` · r), r the c rows' right-hand
    /// side (`pre` = identity when absent).
    map: Mat<f64>,
    pre: Option<Mat<f64>>,
    /// Whether the map solves the rows exactly (not the penalty form).
    exact: bool,
    /// The dependent rows, grouped by constraint.
    dependencies: Dependencies,
    /// Whether the rows were dependent or conflicting (the exact methods then use a
    /// pseudo-inverse: the least-squares solution). Which constraints, and whether they
    /// agree, is in [`Edit::dependencies`].
    pub rank_deficient: bool,
    /// The rank found (rows when full; for the penalty form, the rows less the dependent
    /// rows [`Dependencies`] finds).
    pub rank: usize,
    /// The energy matrix, when the method assembled one.
    pub energy: Option<EnergyMatrix>,
    /// Time per phase.
    pub timings: Timings,
}

impl Editor {
    /// Prepares `constraints` on the mesh `topology` / `positions` for `method`.
    ///
    /// # Errors
    /// A bad constraint ([`EditError::Constraint`]), a mesh the limit evaluator rejects,
    /// the energy method on Loop, or a factorisation failure.
    pub fn new(
        topology: &Topology,
        positions: &[DVec3],
        scheme: &Scheme,
        options: &Options,
        constraints: &[Constraint],
        method: Method,
    ) -> Result<Editor, EditError> {
        let t = Instant::now();
        let ev = Arc::new(LimitEvaluator::new(topology, scheme, options)?);
        let evaluator = t.elapsed().as_secs_f64();
        let mut ed = Self::with_evaluator(ev, topology, positions, scheme, constraints, method)?;
        ed.timings.evaluator = evaluator;
        Ok(ed)
    }

    /// [`Editor::new`] with an evaluator already built for `topology` (a modeller keeps one
    /// per mesh: building it is the one step that grows with the whole mesh).
    ///
    /// # Errors
    /// As [`Editor::new`].
    pub fn with_evaluator(
        ev: Arc<LimitEvaluator>,
        topology: &Topology,
        positions: &[DVec3],
        scheme: &Scheme,
        constraints: &[Constraint],
        method: Method,
    ) -> Result<Editor, EditError> {
        if positions.len() != topology.num_vertices()
            || ev.topology().num_vertices() != positions.len()
        {
            return Err(EditError::Solve(format!(
                "{} positions for {} vertices",
                positions.len(),
                topology.num_vertices()
            )));
        }
        if constraints.is_empty() {
            return Err(EditError::Solve("no constraints".into()));
        }
        let t0 = Instant::now();
        let rows = ConstraintRows::new(&ev, topology, scheme, constraints)?;
        let mut timings = Timings {
            constraints: t0.elapsed().as_secs_f64(),
            ..Timings::default()
        };
        let (free, (map, pre, rank), energy) =
            solution_map(&ev, topology, scheme, &rows, method, &mut timings)?;
        let exact = !matches!(
            method,
            Method::Energy {
                penalty: Some(_),
                ..
            }
        );
        // The exact solves find the rank and the dependent rows only where it falls short;
        // the penalty form never looks, so its rows are always examined.
        let t_deps = Instant::now();
        let dependencies = if rank < rows.rows.len() || !exact {
            Dependencies::new(&rows.rows)
        } else {
            Dependencies::default()
        };
        let rank = if exact {
            rank
        } else {
            rows.rows.len() - dependencies.dependent_rows()
        };
        timings.factor += t_deps.elapsed().as_secs_f64();
        Ok(Editor {
            topology: topology.clone(),
            scheme: scheme.clone(),
            ev,
            base: positions.to_vec(),
            constraints: constraints.to_vec(),
            rank_deficient: rank < rows.rows.len(),
            rank,
            rows,
            free,
            map,
            pre,
            exact,
            dependencies,
            energy,
            timings,
        })
    }

    /// The constraint rows.
    pub fn rows(&self) -> &ConstraintRows {
        &self.rows
    }

    /// The vertices that may move.
    pub fn free_vertices(&self) -> &[u32] {
        &self.free
    }

    /// New control vertices for `constraints`: the same locations (and normal directions) as
    /// those the editor was built with, new targets.
    ///
    /// # Errors
    /// [`EditError::Constraint`] when a constraint's location differs from the prepared one.
    pub fn solve(&self, constraints: &[Constraint]) -> Result<Edit, EditError> {
        if constraints.len() != self.constraints.len() {
            return Err(EditError::Solve(format!(
                "{} constraints, the editor was prepared for {}",
                constraints.len(),
                self.constraints.len()
            )));
        }
        for (i, (a, b)) in constraints.iter().zip(&self.constraints).enumerate() {
            if !same_location(a, b) {
                return Err(EditError::Constraint {
                    index: i,
                    message: "its location differs from the one the editor was prepared for".into(),
                });
            }
        }
        let goals = ConstraintRows::new(&self.ev, &self.topology, &self.scheme, constraints)?;
        let r = goals.residual(&self.base);
        let mut edit = self.apply(&r);
        edit.dependencies = self.dependencies.report(&self.rows.rows, &r, &self.base);
        Ok(edit)
    }

    /// [`Editor::solve`] timed: the substitution's seconds go into [`Editor::timings`].
    pub fn solve_timed(&mut self, constraints: &[Constraint]) -> Result<Edit, EditError> {
        let t = Instant::now();
        let e = self.solve(constraints)?;
        self.timings.solve = t.elapsed().as_secs_f64();
        Ok(e)
    }

    /// The change for right-hand side `r` applied to the base positions.
    fn apply(&self, r: &[f64]) -> Edit {
        let mut dx = self.changes(r);
        if self.exact {
            // Iterative refinement: the solution map of a nearly singular energy (every
            // vertex of a component free) loses digits to its null space; correcting with
            // the residual restores them (a few steps at most).
            let scale = r
                .iter()
                .fold(0.0f64, |m, x| m.max(x.abs()))
                .max(f64::MIN_POSITIVE);
            let mut last = f64::INFINITY;
            for _ in 0..5 {
                let mut moved = self.base.clone();
                for (i, &v) in self.free.iter().enumerate() {
                    moved[v as usize] += DVec3::new(dx[3 * i], dx[3 * i + 1], dx[3 * i + 2]);
                }
                let r2: Vec<f64> = self
                    .rows
                    .rows
                    .iter()
                    .zip(r)
                    .map(|(row, &ri)| ri - (row.value(&moved) - row.value(&self.base)))
                    .collect();
                let worst = r2.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                if worst <= 1e-15 * scale || worst >= 0.5 * last {
                    break;
                }
                last = worst;
                for (d, c) in dx.iter_mut().zip(self.changes(&r2)) {
                    *d += c;
                }
            }
        }
        let mut positions = self.base.clone();
        let mut moved = Vec::new();
        for (i, &v) in self.free.iter().enumerate() {
            let d = DVec3::new(dx[3 * i], dx[3 * i + 1], dx[3 * i + 2]);
            if d != DVec3::ZERO {
                positions[v as usize] += d;
                moved.push(v);
            }
        }
        Edit {
            positions,
            moved,
            dependencies: Vec::new(),
        }
    }

    /// The changes of the free vertices' coordinates for right-hand side `r`.
    fn changes(&self, r: &[f64]) -> Vec<f64> {
        let r: Vec<f64> = match &self.pre {
            Some(p) => (0..p.nrows())
                .map(|i| (0..r.len()).map(|k| p[(i, k)] * r[k]).sum())
                .collect(),
            None => r.to_vec(),
        };
        let n = self.map.nrows();
        let mut dx = vec![0.0; n];
        for (k, &rk) in r.iter().enumerate() {
            if rk == 0.0 {
                continue;
            }
            let col = self.map.col(k);
            for (i, d) in dx.iter_mut().enumerate() {
                *d += col[i] * rk;
            }
        }
        dx
    }

    /// The limit point of a point constraint's location for positions `x` (`None` for other
    /// kinds).
    pub fn limit_of(&self, c: &Constraint, x: &[DVec3]) -> Option<DVec3> {
        match c {
            Constraint::Point { at, .. } => {
                crate::constraint::stencil_at(&self.ev, &self.scheme, at)
                    .ok()
                    .map(|s| s.apply(x).position)
            }
            _ => None,
        }
    }
}

/// The vertices that may move, the solution map and the energy matrix (energy method) for
/// `method`, with the seconds of assembly and factorisation in `timings`.
fn solution_map(
    ev: &LimitEvaluator,
    topology: &Topology,
    scheme: &Scheme,
    constraint_rows: &ConstraintRows,
    method: Method,
    timings: &mut Timings,
) -> Result<(Vec<u32>, SolutionMap, Option<EnergyMatrix>), EditError> {
    let support = constraint_rows.support();
    let rows = &constraint_rows.rows;
    let (penalty, region_rings, energy) = match method {
        Method::LeastSquares => {
            let t1 = Instant::now();
            let m = min_norm_map(rows, &support)?;
            timings.factor = t1.elapsed().as_secs_f64();
            return Ok((support, m, None));
        }
        Method::Energy {
            penalty,
            region_rings,
            energy,
        } => (penalty, region_rings, energy),
    };
    if *scheme != Scheme::CatmullClark {
        return Err(EditError::EnergyScheme);
    }
    let t1 = Instant::now();
    let free = region(topology, &support, region_rings);
    let faces = faces_touching(topology, &free);
    let q = EnergyMatrix::new(ev, topology.num_vertices(), &faces, &energy)?;
    timings.assemble = t1.elapsed().as_secs_f64();
    let t2 = Instant::now();
    // With vertices fixed around the region Q is definite and its Cholesky Schur complement
    // is accurate and the faster; with every vertex free Q is singular up to the
    // regularisation and the KKT system is solved instead.
    let bounded = free.len() < topology.num_vertices();
    let m = match penalty {
        None if bounded => schur_map(rows, &free, &q)?,
        None => match independent(rows, &support)
            .then(|| kkt_map(rows, &free, &q))
            .transpose()?
            .flatten()
        {
            Some(map) => (map, None, rows.len()),
            None => schur_map(rows, &free, &q)?,
        },
        Some(lambda) => (penalty_map(rows, &free, &q, lambda)?, None, rows.len()),
    };
    timings.factor = t2.elapsed().as_secs_f64();
    Ok((free, m, Some(q)))
}

fn same_location(a: &Constraint, b: &Constraint) -> bool {
    match (a, b) {
        (Constraint::Point { at: x, .. }, Constraint::Point { at: y, .. }) => x == y,
        (Constraint::Normal { at: x, normal: n }, Constraint::Normal { at: y, normal: m }) => {
            x == y && n.normalize_or_zero() == m.normalize_or_zero()
        }
        (Constraint::Isoline { line: x, goals: g }, Constraint::Isoline { line: y, goals: h }) => {
            x == y
                && g.len() == h.len()
                && g.iter()
                    .zip(h)
                    .all(|(a, b)| std::mem::discriminant(a) == std::mem::discriminant(b))
        }
        _ => false,
    }
}

/// Vertices within `rings` vertex-rings (through faces) of `seed` (`None`: all), ascending
/// ([`subd_mesh::neighbourhood::vertices_within_rings`]).
pub fn region(topology: &Topology, seed: &[u32], rings: Option<usize>) -> Vec<u32> {
    match rings {
        Some(rings) => neighbourhood::vertices_within_rings(topology, seed, rings),
        None => (0..topology.num_vertices() as u32).collect(),
    }
}

/// Faces with a vertex in `vertices` (ascending): the faces an edit of those vertices
/// can change ([`subd_mesh::neighbourhood::faces_touching`]).
pub fn faces_touching(topology: &Topology, vertices: &[u32]) -> Vec<usize> {
    neighbourhood::faces_touching(topology, vertices)
        .into_iter()
        .map(|f| f as usize)
        .collect()
}

/// The non-zero coefficients of row `r` as (unknown `3 i + coordinate`, coefficient),
/// `i` the vertex's place in `free` (which holds every vertex of the rows).
fn coefficients<'a>(r: &'a Row, free: &'a [u32]) -> impl Iterator<Item = (usize, f64)> + 'a {
    r.entries.iter().flat_map(move |&(v, w)| {
        let i = free
            .binary_search(&v)
            .expect("rows lie inside the free set");
        (0..3)
            .map(move |c| (3 * i + c, r.coefficient(w, c)))
            .filter(|&(_, a)| a != 0.0)
    })
}

/// A as a dense c × 3|free| matrix.
fn dense_rows(rows: &[Row], free: &[u32]) -> Mat<f64> {
    let mut a = Mat::<f64>::zeros(rows.len(), 3 * free.len());
    for (k, r) in rows.iter().enumerate() {
        for (u, x) in coefficients(r, free) {
            a[(k, u)] += x;
        }
    }
    a
}

/// Dense Cholesky of symmetric `s` when every pivot is above `1e-12` of its diagonal
/// entry; `None` when the matrix is (numerically) singular or indefinite.
fn definite_inverse(s: &Mat<f64>) -> Option<Mat<f64>> {
    let n = s.nrows();
    let llt = s.llt(Side::Lower).ok()?;
    let l = llt.L();
    for i in 0..n {
        if l[(i, i)] * l[(i, i)] <= 1e-12 * s[(i, i)].abs().max(f64::MIN_POSITIVE) {
            return None;
        }
    }
    Some(llt.inverse())
}

/// Pseudo-inverse of symmetric positive semi-definite `s` and its rank (eigenvalues below
/// `1e-12` of the largest dropped).
fn psd_pseudo_inverse(s: &Mat<f64>) -> Result<(Mat<f64>, usize), EditError> {
    let n = s.nrows();
    let evd = s
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| EditError::Solve(format!("eigen decomposition: {e:?}")))?;
    let vals = evd.S().column_vector();
    let u = evd.U();
    let top = (0..n).map(|i| vals[i].abs()).fold(0.0, f64::max);
    let keep: Vec<usize> = (0..n).filter(|&i| vals[i] > 1e-12 * top).collect();
    let inv = Mat::from_fn(n, n, |i, j| {
        keep.iter()
            .map(|&k| u[(i, k)] * u[(j, k)] / vals[k])
            .sum::<f64>()
    });
    Ok((inv, keep.len()))
}

/// The solution map, the optional c × c factor applied first, and the rank.
type SolutionMap = (Mat<f64>, Option<Mat<f64>>, usize);

/// Least squares: `Aᵀ` after `(A Aᵀ)⁻¹`, or `A⁺` when the rows are dependent.
fn min_norm_map(rows: &[Row], free: &[u32]) -> Result<SolutionMap, EditError> {
    let c = rows.len();
    let a = dense_rows(rows, free);
    if c <= DENSE_ROWS {
        let aat = &a * a.transpose();
        if let Some(inv) = definite_inverse(&aat) {
            return Ok((a.transpose().to_owned(), Some(inv), c));
        }
    } else {
        let mut t = Vec::new();
        for j in 0..c {
            for k in 0..c {
                let d = rows[j].dot(&rows[k]);
                if d != 0.0 {
                    t.push(Triplet::new(j, k, d));
                }
            }
        }
        let aat = SparseColMat::<usize, f64>::try_new_from_triplets(c, c, &t)
            .map_err(|e| EditError::Solve(format!("A Aᵀ: {e:?}")))?;
        if let Ok(llt) = aat.sp_cholesky(Side::Lower) {
            let mut inv = Mat::<f64>::identity(c, c);
            llt.solve_in_place(inv.as_mut());
            let map = a.transpose() * &inv;
            // Accept only when it reproduces the rows (a near-singular A Aᵀ would not).
            let check = &a * &map;
            let worst = (0..c)
                .map(|i| (check[(i, i)] - 1.0).abs())
                .fold(0.0, f64::max);
            if worst < 1e-8 {
                return Ok((map, None, c));
            }
        }
    }
    let svd = a
        .thin_svd()
        .map_err(|e| EditError::Solve(format!("SVD: {e:?}")))?;
    let s = svd.S().column_vector();
    let top = (0..s.nrows()).map(|i| s[i]).fold(0.0, f64::max);
    let rank = (0..s.nrows()).filter(|&i| s[i] > 1e-12 * top).count();
    Ok((svd.pseudoinverse(), None, rank))
}

/// `Q` restricted to the free vertices (scalar, per coordinate), with the regularising
/// diagonal term.
fn free_block(q: &EnergyMatrix, free: &[u32]) -> Result<SparseColMat<usize, f64>, EditError> {
    let qr = q.q.as_ref();
    let mut local = vec![usize::MAX; qr.nrows()];
    for (i, &v) in free.iter().enumerate() {
        local[v as usize] = i;
    }
    let mut t = Vec::new();
    let mut top = 0.0f64;
    for (j, &v) in free.iter().enumerate() {
        let col = v as usize;
        for (&r, &x) in qr.row_idx_of_col_raw(col).iter().zip(qr.val_of_col(col)) {
            let i = local[r];
            if i != usize::MAX {
                t.push(Triplet::new(i, j, x));
                if i == j {
                    top = top.max(x.abs());
                }
            }
        }
    }
    let eps = 1e-12 * top.max(f64::MIN_POSITIVE);
    for i in 0..free.len() {
        t.push(Triplet::new(i, i, eps));
    }
    SparseColMat::try_new_from_triplets(free.len(), free.len(), &t)
        .map_err(|e| EditError::Solve(format!("energy block: {e:?}")))
}

/// Whether the rows are linearly independent (the pivot test of [`definite_inverse`] on
/// `A Aᵀ`; above [`DENSE_ROWS`] rows assumed, the KKT check deciding).
fn independent(rows: &[Row], support: &[u32]) -> bool {
    if rows.len() > DENSE_ROWS {
        return true;
    }
    let a = dense_rows(rows, support);
    definite_inverse(&(&a * a.transpose())).is_some()
}

/// Exact: the KKT system `[Q Aᵀ; A 0] [ΔX; μ] = [0; r]` by faer's sparse LU, its solution
/// map being the first block of `[Q Aᵀ; A 0]⁻¹ [0; I]`. `None` when the system is singular
/// (dependent or conflicting rows): the map must reproduce the rows (`A W = I` to 1e-9).
fn kkt_map(rows: &[Row], free: &[u32], q: &EnergyMatrix) -> Result<Option<Mat<f64>>, EditError> {
    let qf = free_block(q, free)?;
    let nf = free.len();
    let c = rows.len();
    let n = 3 * nf + c;
    let qr = qf.as_ref();
    let mut t = Vec::new();
    for j in 0..nf {
        for (&i, &x) in qr.row_idx_of_col_raw(j).iter().zip(qr.val_of_col(j)) {
            for coord in 0..3 {
                t.push(Triplet::new(3 * i + coord, 3 * j + coord, x));
            }
        }
    }
    for (k, r) in rows.iter().enumerate() {
        for (u, a) in coefficients(r, free) {
            t.push(Triplet::new(3 * nf + k, u, a));
            t.push(Triplet::new(u, 3 * nf + k, a));
        }
    }
    let m = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &t)
        .map_err(|e| EditError::Solve(format!("KKT matrix: {e:?}")))?;
    let Ok(lu) = m.sp_lu() else {
        return Ok(None);
    };
    let mut rhs = Mat::<f64>::zeros(n, c);
    for k in 0..c {
        rhs[(3 * nf + k, k)] = 1.0;
    }
    lu.solve_in_place(rhs.as_mut());
    let w = Mat::from_fn(3 * nf, c, |i, k| rhs[(i, k)]);
    // A W must be the identity.
    for (j, r) in rows.iter().enumerate() {
        for k in 0..c {
            let s: f64 = coefficients(r, free).map(|(u, a)| a * w[(u, k)]).sum();
            let want = if j == k { 1.0 } else { 0.0 };
            if !s.is_finite() || (s - want).abs() > 1e-9 {
                return Ok(None);
            }
        }
    }
    Ok(Some(w))
}

/// Exact: `Q⁻¹ Aᵀ (A Q⁻¹ Aᵀ)⁻¹` (Q per coordinate), pseudo-inverse of the Schur complement
/// when it is singular.
fn schur_map(rows: &[Row], free: &[u32], q: &EnergyMatrix) -> Result<SolutionMap, EditError> {
    let qf = free_block(q, free)?;
    let llt = qf
        .sp_cholesky(Side::Lower)
        .map_err(|e| EditError::Solve(format!("energy matrix not definite: {e:?}")))?;
    let c = rows.len();
    let nf = free.len();
    // Per coordinate, Aᵀ's slice as columns: |free| × 3c (column 3k + coord).
    let mut rhs = Mat::<f64>::zeros(nf, 3 * c);
    for (k, r) in rows.iter().enumerate() {
        for (u, a) in coefficients(r, free) {
            rhs[(u / 3, 3 * k + u % 3)] += a;
        }
    }
    llt.solve_in_place(rhs.as_mut());
    // W = Q⁻¹Aᵀ in the interleaved unknowns; S = A W from A's sparse rows.
    let w = Mat::from_fn(3 * nf, c, |i, k| rhs[(i / 3, 3 * k + i % 3)]);
    let mut s = Mat::<f64>::zeros(c, c);
    for (j, r) in rows.iter().enumerate() {
        for (u, a) in coefficients(r, free) {
            for k in 0..c {
                s[(j, k)] += a * w[(u, k)];
            }
        }
    }
    // Symmetric in exact arithmetic: symmetrise the rounding.
    let s = Mat::from_fn(c, c, |j, k| 0.5 * (s[(j, k)] + s[(k, j)]));
    let (s_inv, rank) = match definite_inverse(&s) {
        Some(inv) => (inv, c),
        None => psd_pseudo_inverse(&s)?,
    };
    Ok((w, Some(s_inv), rank))
}

/// Penalty: `λ (Q + λ AᵀA)⁻¹ Aᵀ`, λ relative to `mean diag Q / mean diag AᵀA`.
fn penalty_map(
    rows: &[Row],
    free: &[u32],
    q: &EnergyMatrix,
    lambda: f64,
) -> Result<Mat<f64>, EditError> {
    let qf = free_block(q, free)?;
    let nf = free.len();
    let c = rows.len();
    let a = dense_rows(rows, free);
    let qr = qf.as_ref();
    let mut t = Vec::new();
    let mut diag_q = 0.0;
    for j in 0..nf {
        for (&i, &x) in qr.row_idx_of_col_raw(j).iter().zip(qr.val_of_col(j)) {
            for coord in 0..3 {
                t.push(Triplet::new(3 * i + coord, 3 * j + coord, x));
            }
            if i == j {
                diag_q += 3.0 * x;
            }
        }
    }
    let diag_ata: f64 = (0..3 * nf)
        .map(|i| (0..c).map(|k| a[(k, i)] * a[(k, i)]).sum::<f64>())
        .sum();
    let lam = lambda * diag_q / diag_ata.max(f64::MIN_POSITIVE);
    // λ AᵀA over each row's unknowns.
    for k in 0..c {
        let nz: Vec<usize> = (0..3 * nf).filter(|&i| a[(k, i)] != 0.0).collect();
        for &i in &nz {
            for &j in &nz {
                t.push(Triplet::new(i, j, lam * a[(k, i)] * a[(k, j)]));
            }
        }
    }
    let m = SparseColMat::<usize, f64>::try_new_from_triplets(3 * nf, 3 * nf, &t)
        .map_err(|e| EditError::Solve(format!("penalty matrix: {e:?}")))?;
    let llt = m
        .sp_cholesky(Side::Lower)
        .map_err(|e| EditError::Solve(format!("Q + λAᵀA is not positive definite: {e:?}")))?;
    let mut rhs = Mat::from_fn(3 * nf, c, |i, k| lam * a[(k, i)]);
    llt.solve_in_place(rhs.as_mut());
    Ok(rhs)
}
