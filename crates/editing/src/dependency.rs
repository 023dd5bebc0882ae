//! Dependent constraints: rows of the system `A ΔX = r` that are combinations of other rows,
//! grouped by the constraints they come from, and whether their targets agree.
//!
//! The rows are taken in order. A row whose pivot in the Cholesky factorisation of `A Aᵀ`
//! over the rows kept so far falls to `1e-12` of its diagonal entry (the test the
//! least-squares solver uses) is a combination of the kept rows, `a_k = Σ α_j a_j`, and
//! gives the relation `y = e_k − Σ α_j e_j` with `yᵀ A = 0`. Whatever the change ΔX,
//! `yᵀ A ΔX = 0`: all the rows can be met only when `yᵀ r = 0`. Constraints linked through
//! relations form a [`DependentGroup`]. Its rows are met together exactly when r has no part
//! in the span of the group's relations; that part's length is what no change can meet, the
//! residual `‖A ΔX − r‖` over the group's rows of the least-squares (minimum-norm, or
//! minimum-energy) solution.
//!
//! The relations depend on the constraints' locations only ([`Dependencies`], found once by
//! the [`crate::Editor`]); consistency depends on the targets and is decided per solve
//! ([`Dependencies::report`]).

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use glam::DVec3;

use crate::constraint::Row;

/// A row is dependent when its Cholesky pivot is at most this fraction of its diagonal
/// entry of `A Aᵀ` (as in the least-squares solver's test).
pub const PIVOT_TOLERANCE: f64 = 1e-12;

/// A group is consistent when its residual is at most this fraction of the largest row
/// value (right-hand side, or the row's value on the base positions) among its rows:
/// rounding in `r = b − A X₀` is relative to those.
pub const CONSISTENCY_TOLERANCE: f64 = 1e-9;

/// Coefficients `|α_j| ‖a_j‖` below this fraction of `‖a_k‖` are rounding, not a link.
const COEFFICIENT_TOLERANCE: f64 = 1e-10;

/// Constraints whose rows are linearly dependent, and whether their targets agree.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct DependentGroup {
    /// The constraints involved (indices in the list given), ascending.
    pub constraints: Vec<usize>,
    /// How many of the group's rows are combinations of the others (its rows less its rank).
    pub dependent_rows: usize,
    /// Whether one change meets every row of the group: the dependent rows are redundant
    /// (`true`) or the constraints conflict (`false`).
    pub consistent: bool,
    /// What no change can meet: `‖A ΔX − r‖` over the group's rows for the least-squares
    /// solution, in the rows' units (model units for points and iso-lines; normals'
    /// rows are tangents dotted with the unit normal). 0 up to rounding when consistent.
    pub residual: f64,
}

/// One relation `Σ coefficient · row = 0` among the rows (a left null vector of `A`).
#[derive(Clone, Debug, PartialEq)]
struct Relation {
    /// (row, coefficient), the dependent row first with coefficient 1.
    terms: Vec<(usize, f64)>,
}

/// The constraints of one group and the relations among their rows.
#[derive(Clone, Debug, PartialEq)]
struct Group {
    constraints: Vec<usize>,
    relations: Vec<Relation>,
}

/// The dependent groups of a set of rows: where the rows are dependent, not yet whether
/// their targets agree ([`Dependencies::report`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Dependencies {
    groups: Vec<Group>,
}

impl Dependencies {
    /// Finds the relations among `rows` (rows sharing no vertex are orthogonal, so each set
    /// of rows connected through shared vertices is factored on its own).
    pub fn new(rows: &[Row]) -> Dependencies {
        let relations: Vec<Relation> = connected_rows(rows)
            .iter()
            .flat_map(|members| relations_among(rows, members))
            .collect();
        Dependencies {
            groups: group_by_constraint(rows, relations),
        }
    }

    /// Rows that are combinations of others, over all groups (the rows less the rank).
    pub fn dependent_rows(&self) -> usize {
        self.groups.iter().map(|g| g.relations.len()).sum()
    }

    /// Each group with its residual for right-hand side `r` (`b − A X₀`, per row) and
    /// whether its rows agree; `base` (X₀) gives the scale of the rows' values.
    pub fn report(&self, rows: &[Row], r: &[f64], base: &[DVec3]) -> Vec<DependentGroup> {
        self.groups
            .iter()
            .map(|g| {
                let residual = unmet_part(&g.relations, r);
                let scale = rows
                    .iter()
                    .zip(r)
                    .filter(|(row, _)| g.constraints.binary_search(&row.constraint).is_ok())
                    .map(|(row, &rk)| rk.abs().max(row.value(base).abs()))
                    .fold(0.0, f64::max);
                DependentGroup {
                    constraints: g.constraints.clone(),
                    dependent_rows: g.relations.len(),
                    consistent: residual <= CONSISTENCY_TOLERANCE * scale,
                    residual,
                }
            })
            .collect()
    }
}

/// Root of `i` in a union-find forest (path halving).
fn root(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Joins the sets of `a` and `b`.
fn join(parent: &mut [usize], a: usize, b: usize) {
    let (ra, rb) = (root(parent, a), root(parent, b));
    parent[ra.max(rb)] = ra.min(rb);
}

/// The sets of row indices connected through shared vertices, each ascending.
fn connected_rows(rows: &[Row]) -> Vec<Vec<usize>> {
    let mut parent: Vec<usize> = (0..rows.len()).collect();
    let mut by_vertex: Vec<(u32, usize)> = rows
        .iter()
        .enumerate()
        .flat_map(|(k, r)| r.entries.iter().map(move |&(v, _)| (v, k)))
        .collect();
    by_vertex.sort_unstable();
    for pair in by_vertex.windows(2) {
        if pair[0].0 == pair[1].0 {
            join(&mut parent, pair[0].1, pair[1].1);
        }
    }
    sets_of(&mut parent)
}

/// The sets of a union-find forest, each ascending, in order of their first member.
fn sets_of(parent: &mut [usize]) -> Vec<Vec<usize>> {
    let mut index = vec![usize::MAX; parent.len()];
    let mut sets: Vec<Vec<usize>> = Vec::new();
    for k in 0..parent.len() {
        let r = root(parent, k);
        if index[r] == usize::MAX {
            index[r] = sets.len();
            sets.push(Vec::new());
        }
        sets[index[r]].push(k);
    }
    sets
}

/// The relations among `members` (row indices, ascending): a pivoted-out Cholesky of their
/// Gram matrix, rows taken in order.
fn relations_among(rows: &[Row], members: &[usize]) -> Vec<Relation> {
    let m = members.len();
    let gram = Mat::from_fn(m, m, |i, j| rows[members[i]].dot(&rows[members[j]]));
    // Kept rows (local indices) and their Cholesky factor, row by row.
    let mut kept: Vec<usize> = Vec::new();
    let mut factor: Vec<Vec<f64>> = Vec::new();
    let mut out = Vec::new();
    for k in 0..m {
        let g: Vec<f64> = kept.iter().map(|&j| gram[(j, k)]).collect();
        let mut z = forward(&factor, &g);
        let pivot = gram[(k, k)] - z.iter().map(|x| x * x).sum::<f64>();
        if pivot > PIVOT_TOLERANCE * gram[(k, k)] {
            z.push(pivot.sqrt());
            factor.push(z);
            kept.push(k);
            continue;
        }
        // a_k = Σ α_j a_j, the least-squares fit of a_k by the kept rows.
        let alpha = backward(&factor, &z);
        let size = gram[(k, k)].sqrt();
        let mut terms = vec![(members[k], 1.0)];
        for (&j, &a) in kept.iter().zip(&alpha) {
            if a.abs() * gram[(j, j)].sqrt() > COEFFICIENT_TOLERANCE * size {
                terms.push((members[j], -a));
            }
        }
        out.push(Relation { terms });
    }
    out
}

/// Solves `L z = g`, L lower triangular given row by row.
fn forward(l: &[Vec<f64>], g: &[f64]) -> Vec<f64> {
    let mut z: Vec<f64> = Vec::with_capacity(g.len());
    for (i, row) in l.iter().enumerate() {
        let s: f64 = row[..i].iter().zip(&z).map(|(a, b)| a * b).sum();
        z.push((g[i] - s) / row[i]);
    }
    z
}

/// Solves `Lᵀ α = z`, L lower triangular given row by row.
fn backward(l: &[Vec<f64>], z: &[f64]) -> Vec<f64> {
    let n = z.len();
    let mut alpha = vec![0.0; n];
    for i in (0..n).rev() {
        let s: f64 = (i + 1..n).map(|j| l[j][i] * alpha[j]).sum();
        alpha[i] = (z[i] - s) / l[i][i];
    }
    alpha
}

/// The relations grouped by the constraints their rows come from (constraints sharing a
/// relation, directly or through others, are one group), in order of first constraint.
fn group_by_constraint(rows: &[Row], relations: Vec<Relation>) -> Vec<Group> {
    let n = rows.iter().map(|r| r.constraint + 1).max().unwrap_or(0);
    let mut parent: Vec<usize> = (0..n).collect();
    for rel in &relations {
        let first = rows[rel.terms[0].0].constraint;
        for &(k, _) in &rel.terms[1..] {
            join(&mut parent, first, rows[k].constraint);
        }
    }
    let mut groups: Vec<Group> = Vec::new();
    let mut index = vec![usize::MAX; n];
    for rel in relations {
        let r = root(&mut parent, rows[rel.terms[0].0].constraint);
        if index[r] == usize::MAX {
            index[r] = groups.len();
            groups.push(Group {
                constraints: Vec::new(),
                relations: Vec::new(),
            });
        }
        let g = &mut groups[index[r]];
        g.constraints
            .extend(rel.terms.iter().map(|&(k, _)| rows[k].constraint));
        g.relations.push(rel);
    }
    for g in &mut groups {
        g.constraints.sort_unstable();
        g.constraints.dedup();
    }
    groups.sort_by_key(|g| g.constraints[0]);
    groups
}

/// The length of r's part in the span of the relations Y: `‖Y (YᵀY)⁻¹ Yᵀ r‖`. YᵀY is
/// definite: each relation has a row (its first) that no other relation of the group has.
fn unmet_part(relations: &[Relation], r: &[f64]) -> f64 {
    let m = relations.len();
    let dot = |a: &Relation, b: &Relation| -> f64 {
        a.terms
            .iter()
            .flat_map(|&(i, x)| {
                b.terms
                    .iter()
                    .filter(move |t| t.0 == i)
                    .map(move |t| x * t.1)
            })
            .sum()
    };
    let yty = Mat::from_fn(m, m, |i, j| dot(&relations[i], &relations[j]));
    let ytr = Mat::from_fn(m, 1, |i, _| {
        relations[i]
            .terms
            .iter()
            .map(|&(k, x)| x * r[k])
            .sum::<f64>()
    });
    let Ok(llt) = yty.llt(Side::Lower) else {
        // Unreachable in exact arithmetic; the largest single relation's part then.
        return relations
            .iter()
            .zip(ytr.col(0).iter())
            .map(|(rel, &yr)| yr.abs() / dot(rel, rel).sqrt())
            .fold(0.0, f64::max);
    };
    let w = llt.solve(&ytr);
    (0..m)
        .map(|i| ytr[(i, 0)] * w[(i, 0)])
        .sum::<f64>()
        .max(0.0)
        .sqrt()
}
