//! Limit positions and normals of the split schemes (Doo-Sabin, √3, the butterflies) at the
//! base vertices, as stencil tables over the base vertices.
//!
//! * **√3**: an interior vertex's limit and tangents come from the left eigenvectors of its
//!   local subdivision matrix ([`crate::split_eigen::local_masks`]; the limit mask is
//!   Kobbelt's `(1 − β) p + β/n Σ p_i`, `β = 3α_n/(1 + 3α_n)`). They are applied at the first
//!   level (0 to [`MAX_LEVELS`]) where the vertex's invariant ball is regular but for the
//!   vertex itself: away from features that is the base level; next to a boundary, a crease or
//!   another extraordinary vertex, one or two levels down. A vertex inside a boundary or crease
//!   curve has the cubic B-spline limit `(p₋₁ + 4p + p₁)/6` of its curve (the curve is refined
//!   by the ternary cubic B-spline mask every second step and left alone in between); a corner
//!   stays put.
//! * **Butterflies**: interpolating, so the limit of a vertex is the vertex. Normals come from
//!   the tangent masks (left eigenvectors) at the first level where the ball is regular; none
//!   where the scheme is not C¹ (the classic butterfly at valence 3 and above 7).
//! * **Boundary vertices and darts** (√3 and the butterflies): the dense local subdivision
//!   matrix of a synthetic boundary fan or dart disc of the same size
//!   ([`crate::split_eigen::feature_masks`]) gives the limit (a dart's, for √3) and the
//!   tangents, applied where the vertex's own local matrix, read off the refinement, equals
//!   it. Vertices inside a crease have two one-sided normals and get none; corners none.
//! * **Doo-Sabin**: every face of every level shrinks to its centroid, so the limit of a base
//!   vertex is the centroid of its vertex face one level down, with the normal of that face's
//!   first Fourier mode (the face circulant's eigenvalue-½ pair). An interior vertex of
//!   valence 2 has no vertex face and no limit here.
//!
//! Where a value is not given, [`SplitLimitStencils::position_known`] or
//! [`SplitLimitStencils::tangents_known`] says so and the row is empty;
//! [`split_limit_table`] gives the same rows as the [`LimitStencilTable`] every scheme's
//! limit takes ([`crate::limit_stencils`]).

use std::collections::HashMap;
use std::f64::consts::TAU;

use glam::DVec3;
use rayon::prelude::*;
use subd_mesh::Topology;
use subd_schemes::StencilTable;
use subd_schemes::split_schemes::{Features, doo_sabin};
use subd_schemes::{Options, Refinement, Scheme, Split};

use crate::split_limits::composed_rows::{ComposedRows, Row};
pub use crate::split_limits::pieces::Neighbourhoods;
use crate::split_limits::pieces::{PointsLevel, Refined, Refiner};
use crate::split_limits::split_eigen::{
    FeatureCentre, FeatureMasks, LocalMasks, expand_row, feature_ball, feature_masks,
    feature_matrix, local_masks, row_between,
};
use crate::{LimitError, LimitPoints, LimitStencilTable};

/// The deepest level searched for a regular ball around an interior vertex.
pub const MAX_LEVELS: usize = 4;

/// Limit position and tangent stencils of every base vertex.
#[derive(Debug, Clone)]
pub struct SplitLimitStencils {
    /// Limit position of each base vertex (an empty row where unknown).
    pub position: StencilTable,
    /// Two tangents of each base vertex (empty rows where unknown).
    pub tangents: [StencilTable; 2],
    /// Whether the position row of a vertex is given.
    pub position_known: Vec<bool>,
    /// Whether the tangent rows of a vertex are given.
    pub tangents_known: Vec<bool>,
}

/// Limit positions and unit normals, `None` where not given.
#[derive(Debug, Clone, PartialEq)]
pub struct SplitLimitPoints {
    /// Limit position per base vertex.
    pub positions: Vec<Option<DVec3>>,
    /// Unit normal per base vertex (from the tangents' cross product).
    pub normals: Vec<Option<DVec3>>,
}

impl SplitLimitStencils {
    /// Applies the stencils to base positions.
    pub fn evaluate(&self, points: &[DVec3]) -> SplitLimitPoints {
        let p = self.position.apply_points(points);
        let t1 = self.tangents[0].apply_points(points);
        let t2 = self.tangents[1].apply_points(points);
        SplitLimitPoints {
            positions: (0..p.len())
                .map(|v| self.position_known[v].then_some(p[v]))
                .collect(),
            normals: (0..p.len())
                .map(|v| {
                    let n = t1[v].cross(t2[v]);
                    (self.tangents_known[v] && n.length() > 0.0).then(|| n.normalize())
                })
                .collect(),
        }
    }
}

/// Rows over level-`l` vertices carried back to the base through `composed` (`l ≥ 1`).
fn to_base(row: &Row, composed: &StencilTable) -> Row {
    expand_row(row, composed)
}

/// The split family's part of the one limit entry ([`crate::limit_stencils`]): after the
/// refinement's own checks of the mesh (so a mesh the scheme cannot take is refused as
/// [`Refinement::new`] refuses it, the element named), the limit of every vertex of `base`
/// as a [`LimitStencilTable`]; vertices without tangents are marked
/// ([`LimitStencilTable::without_tangents`]).
///
/// # Errors
/// [`LimitError::Refine`] for a mesh the scheme cannot refine; [`LimitError::NoLimit`]
/// naming the first vertex without a limit; as [`split_limit_stencils`].
pub fn split_limit_table(
    base: &Topology,
    scheme: &Scheme,
) -> Result<LimitStencilTable, LimitError> {
    Refinement::new(base, scheme.clone(), &Options::default(), 0)?;
    split_limit_stencils(base, scheme)?.into_table(scheme)
}

impl SplitLimitStencils {
    /// The stencils as a [`LimitStencilTable`], every vertex with a position.
    ///
    /// # Errors
    /// [`LimitError::NoLimit`] naming the first vertex without a limit.
    pub fn into_table(self, scheme: &Scheme) -> Result<LimitStencilTable, LimitError> {
        if let Some(v) = self.position_known.iter().position(|known| !known) {
            return Err(no_limit(v, scheme));
        }
        let [tangent1, tangent2] = self.tangents;
        Ok(LimitStencilTable {
            position: self.position,
            tangent1,
            tangent2,
            without_tangents: self.tangents_known.iter().map(|known| !known).collect(),
        })
    }
}

/// The stencils of `scheme`'s limit at every vertex of `base`, the levels below the base
/// refined only around the vertices that need them ([`Neighbourhoods::Local`]).
///
/// # Errors
/// [`LimitError::Analysis`] when `base` is not a mesh `scheme` refines (see
/// [`Refinement::new`]) or an eigen solve fails.
pub fn split_limit_stencils(
    base: &Topology,
    scheme: &Scheme,
) -> Result<SplitLimitStencils, LimitError> {
    split_limit_stencils_in(base, scheme, Neighbourhoods::Local)
}

/// [`split_limit_stencils`], with the levels below the base refined as `how` says.
///
/// # Errors
/// As [`split_limit_stencils`].
pub fn split_limit_stencils_in(
    base: &Topology,
    scheme: &Scheme,
    how: Neighbourhoods,
) -> Result<SplitLimitStencils, LimitError> {
    let nv = base.num_vertices();
    let refiner = Refiner { base, scheme, how };
    let mut found = Found::Rows {
        position: vec![None; nv],
        tangents: vec![None; nv],
    };
    find_limits(&refiner, &mut found)?;
    let Found::Rows { position, tangents } = found else {
        unreachable!("rows asked for")
    };
    let table = |rows: Vec<Row>| {
        StencilTable::build(nv, nv, |v, sink| {
            for &(s, w) in &rows[v] {
                sink.add(s, w);
            }
        })
    };
    let position_known: Vec<bool> = position.iter().map(Option::is_some).collect();
    let tangents_known: Vec<bool> = tangents.iter().map(Option::is_some).collect();
    let (mut t1, mut t2) = (Vec::with_capacity(nv), Vec::with_capacity(nv));
    for t in tangents {
        let [a, b] = t.unwrap_or_default();
        t1.push(a);
        t2.push(b);
    }
    Ok(SplitLimitStencils {
        position: table(
            position
                .into_iter()
                .map(Option::unwrap_or_default)
                .collect(),
        ),
        tangents: [table(t1), table(t2)],
        position_known,
        tangents_known,
    })
}

/// The exact limit (positions, tangents, normals) of every vertex of `base` under a split
/// scheme, from `points`, without stencil tables: the values of
/// [`split_limit_table`]`(base, scheme)?.apply(points)`, with each mask applied to the
/// points of the level where it is found instead of being composed back into a row over the
/// base. A vertex whose mask applies at the base level (most of them) gets the table's
/// value bit for bit; one whose mask applies further down gets it up to rounding (the
/// piece's points refined level by level rather than its rows composed). This is what
/// `refine --limit`, `limit` and `subd.refine(limit=True)` take for those schemes; the
/// stencils are built only where texture coordinates share them.
///
/// ```
/// use subd_mesh::{DVec3, TopologyBuilder};
/// use subd_schemes::Scheme;
/// use subd_limit::split_limit::{split_limit_points, split_limit_table};
///
/// // An octahedron, every vertex of valence 4.
/// let faces = [0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5];
/// let octahedron = TopologyBuilder::new(6).build(&[3; 8], &faces).unwrap();
/// let p = [DVec3::X, -DVec3::X, DVec3::Y, -DVec3::Y, DVec3::Z, -DVec3::Z];
/// let direct = split_limit_points(&octahedron, &Scheme::Sqrt3, &p).unwrap();
/// let by_table = split_limit_table(&octahedron, &Scheme::Sqrt3).unwrap().apply(&p);
/// for v in 0..6 {
///     assert!((direct.positions[v] - by_table.positions[v]).length() < 1e-14);
///     assert!((direct.normals[v] - by_table.normals[v]).length() < 1e-12);
/// }
/// ```
///
/// # Errors
/// As [`split_limit_table`].
///
/// # Panics
/// If `points` does not hold one point per vertex of `base`.
pub fn split_limit_points(
    base: &Topology,
    scheme: &Scheme,
    points: &[DVec3],
) -> Result<LimitPoints, LimitError> {
    assert_eq!(points.len(), base.num_vertices(), "one point per vertex");
    Refinement::new(base, scheme.clone(), &Options::default(), 0)?;
    let nv = base.num_vertices();
    let refiner = Refiner {
        base,
        scheme,
        how: Neighbourhoods::Local,
    };
    let mut found = Found::Points {
        base: points,
        position: vec![None; nv],
        tangents: vec![None; nv],
    };
    find_limits(&refiner, &mut found)?;
    let Found::Points {
        position, tangents, ..
    } = found
    else {
        unreachable!("points asked for")
    };
    if let Some(v) = position.iter().position(Option::is_none) {
        return Err(no_limit(v, scheme));
    }
    let nan = DVec3::splat(f64::NAN);
    let (mut tangent1, mut tangent2, mut normals) = (
        Vec::with_capacity(nv),
        Vec::with_capacity(nv),
        Vec::with_capacity(nv),
    );
    for t in &tangents {
        let (a, b, n) = match t {
            Some([a, b]) => (*a, *b, a.cross(*b).normalize_or_zero()),
            None => (nan, nan, nan),
        };
        tangent1.push(a);
        tangent2.push(b);
        normals.push(n);
    }
    Ok(LimitPoints {
        positions: position.into_iter().map(|p| p.expect("checked")).collect(),
        tangent1,
        tangent2,
        normals,
    })
}

/// Where the masks' findings go: rows over the base vertices (for the stencil tables), or
/// the values themselves, taken from the base points as each vertex is settled.
enum Found<'p> {
    Rows {
        position: Vec<Option<Row>>,
        tangents: Vec<Option<[Row; 2]>>,
    },
    Points {
        base: &'p [DVec3],
        position: Vec<Option<DVec3>>,
        tangents: Vec<Option<[DVec3; 2]>>,
    },
}

impl Found<'_> {
    /// Whether vertex `v` has its position.
    fn has_position(&self, v: usize) -> bool {
        match self {
            Found::Rows { position, .. } => position[v].is_some(),
            Found::Points { position, .. } => position[v].is_some(),
        }
    }

    /// The base points, when values rather than rows are asked for.
    fn points(&self) -> Option<&[DVec3]> {
        match self {
            Found::Rows { .. } => None,
            Found::Points { base, .. } => Some(base),
        }
    }

    /// Sets vertex `v`'s position row (applied to the base points for values).
    fn set_position(&mut self, v: usize, row: Row) {
        match self {
            Found::Rows { position, .. } => position[v] = Some(row),
            Found::Points { base, position, .. } => position[v] = Some(apply_row(&row, base)),
        }
    }

    /// Sets vertex `v`'s two tangent rows.
    fn set_tangents(&mut self, v: usize, rows: [Row; 2]) {
        match self {
            Found::Rows { tangents, .. } => tangents[v] = Some(rows),
            Found::Points { base, tangents, .. } => {
                tangents[v] = Some([apply_row(&rows[0], base), apply_row(&rows[1], base)]);
            }
        }
    }

    /// Records what the masks found at vertex `v`.
    fn set(&mut self, v: usize, at: AtVertex) {
        match (self, at) {
            (found, AtVertex::Rows(p, t)) => {
                if let Some(p) = p {
                    found.set_position(v, p);
                }
                if let Some(t) = t {
                    found.set_tangents(v, t);
                }
            }
            (
                Found::Points {
                    position, tangents, ..
                },
                AtVertex::Values(p, t),
            ) => {
                if p.is_some() {
                    position[v] = p;
                }
                if t.is_some() {
                    tangents[v] = t;
                }
            }
            (Found::Rows { .. }, AtVertex::Values(..)) => unreachable!("rows were asked for"),
        }
    }
}

/// The masks' findings at one vertex: position and tangent rows, or their values.
enum AtVertex {
    Rows(Option<Row>, Option<[Row; 2]>),
    Values(Option<DVec3>, Option<[DVec3; 2]>),
}

/// `Σ w p[s]` over a row, summed as [`StencilTable::apply_points`] sums its rows.
fn apply_row(row: &[(u32, f64)], p: &[DVec3]) -> DVec3 {
    let mut acc = DVec3::ZERO;
    for &(s, w) in row {
        acc += w * p[s as usize];
    }
    acc
}

/// The error naming vertex `v`, which has no limit under `scheme`.
fn no_limit(v: usize, scheme: &Scheme) -> LimitError {
    let why = if scheme.split() == Split::Dual {
        "an interior vertex of valence 2 has no vertex face"
    } else {
        "its neighbourhood never became one with a known limit mask (a dart or boundary vertex whose refined neighbourhood stays irregular)"
    };
    LimitError::NoLimit {
        vertex: v,
        scheme: scheme.name(),
        why,
    }
}

/// The limit of every vertex of the refiner's base, as `found` asks for it.
fn find_limits(refiner: &Refiner<'_>, found: &mut Found<'_>) -> Result<(), LimitError> {
    if refiner.scheme.split() == Split::Dual {
        let r = refiner.whole(1)?.r;
        doo_sabin_rows(refiner.base, &r, found);
        Ok(())
    } else {
        vertex_rows(refiner.base, refiner.scheme, refiner, found)
    }
}

/// Doo-Sabin: centroid and first Fourier mode of each vertex's vertex face.
fn doo_sabin_rows(base: &Topology, r: &Refinement, found: &mut Found<'_>) {
    let level1 = r.topology(1);
    let stencils = r.stencils(1);
    for (v, face) in doo_sabin::vertex_face_indices(base).into_iter().enumerate() {
        let Some(face) = face else { continue };
        let corners = level1.face_vertices(face as usize);
        let m = corners.len();
        let mode = |f: fn(f64) -> f64| -> Row {
            corners
                .iter()
                .enumerate()
                .map(|(i, &c)| (c, f(TAU * i as f64 / m as f64)))
                .collect()
        };
        let centroid: Row = corners.iter().map(|&c| (c, 1.0 / m as f64)).collect();
        found.set_position(v, to_base(&centroid, stencils));
        found.set_tangents(
            v,
            [
                to_base(&mode(f64::cos), stencils),
                to_base(&mode(f64::sin), stencils),
            ],
        );
    }
}

/// Whether the ball of `radius` around interior vertex `v` of `t` is regular but for `v`:
/// no vertex of it on a feature, every other one of valence 6, and as many vertices as the
/// regular ball has.
fn regular_ball(t: &Topology, features: &Features, v: u32, ball: &[u32], expected: usize) -> bool {
    ball.len() == expected
        && ball.iter().all(|&u| {
            !features.is_on_feature(u as usize)
                && !t.is_boundary_vertex(u as usize)
                && (u == v || t.valence(u as usize) == 6)
        })
}

/// √3 and the butterflies: features by their curve rules, interior vertices by their masks
/// at the first level with a regular ball.
fn vertex_rows(
    base: &Topology,
    scheme: &Scheme,
    refiner: &Refiner<'_>,
    found: &mut Found<'_>,
) -> Result<(), LimitError> {
    let nv = base.num_vertices();
    let features = Features::new(base);
    let mut pending: Vec<u32> = Vec::new();
    let mut feature_pending: Vec<u32> = Vec::new();
    for v in 0..nv as u32 {
        let vi = v as usize;
        if base.vertex_faces(vi).is_empty() || scheme.is_interpolating() {
            found.set_position(vi, vec![(v, 1.0)]);
        }
        if base.vertex_faces(vi).is_empty() {
            continue;
        }
        if features.is_on_feature(vi) {
            let dart = features.degree(vi) == 1 && !base.is_boundary_vertex(vi);
            let boundary_curve = base.is_boundary_vertex(vi) && features.is_curve_vertex(vi);
            if (dart || boundary_curve) && !features.is_corner(vi) {
                feature_pending.push(v);
            }
            if scheme.split() == Split::Sqrt3 {
                if features.is_corner(vi) {
                    found.set_position(vi, vec![(v, 1.0)]);
                } else if features.is_curve_vertex(vi) {
                    found.set_position(vi, sqrt3_curve_limit(base, &features, v, refiner)?);
                }
                // A dart (one crease edge ending inside the surface): no mask here.
            }
            continue;
        }
        pending.push(v);
    }
    interior_rows(base, scheme, refiner, pending, found)?;
    feature_rows(scheme, refiner, &feature_pending, found)
}

/// Interior vertices: the masks of their valence at the first level (0 to [`MAX_LEVELS`])
/// where their ball is regular, each level refined around the vertices still pending.
fn interior_rows(
    base: &Topology,
    scheme: &Scheme,
    refiner: &Refiner<'_>,
    mut pending: Vec<u32>,
    found: &mut Found<'_>,
) -> Result<(), LimitError> {
    let mut masks: HashMap<usize, (LocalMasks, usize)> = HashMap::new();
    pending.retain(|&v| (3..=64).contains(&base.valence(v as usize)));
    for &v in &pending {
        let n = base.valence(v as usize);
        if let std::collections::hash_map::Entry::Vacant(e) = masks.entry(n) {
            let m = local_masks(scheme, n)?;
            let size = m.limit.len();
            e.insert((m, size));
        }
    }
    let interior = Interior {
        base,
        interpolating: scheme.is_interpolating(),
        masks: &masks,
    };
    let mut above: Option<PointsLevel> = None;
    let mut level = 0;
    while !pending.is_empty() && level <= MAX_LEVELS {
        let radius = pending
            .iter()
            .map(|&v| masks[&base.valence(v as usize)].0.radius)
            .max()
            .unwrap_or(0);
        let results = if let Some(base_points) = found.points() {
            let at =
                refiner.level_for_points(above.take(), &pending, level, radius, base_points)?;
            let points = Source::Points(at.points(base_points));
            let at_level = interior.at(at.topology(base), at.numbering(), points);
            let results = masks_in_chunks(&pending, |v, _| at_level.at(v, None), || None);
            above = Some(at);
            results
        } else {
            let refined = refiner.around_last_level(&pending, level, radius)?;
            let numbering = refined.piece.as_ref().map(|(of_base, _)| &of_base[..]);
            let rows = Source::Rows(&refined, level);
            let at_level = interior.at(refined.r.topology(level), numbering, rows);
            // Each chunk composes the rows it reads (a row two chunks read is composed
            // twice, the same way): the rows do not depend on the chunks.
            masks_in_chunks(
                &pending,
                |v, composed| at_level.at(v, composed),
                || Some(ComposedRows::new(&refined.r)),
            )
        };
        let mut still = Vec::new();
        for (&v, at) in pending.iter().zip(results) {
            match at {
                None => still.push(v),
                Some(at) => found.set(v as usize, at),
            }
        }
        pending = still;
        level += 1;
    }
    Ok(())
}

/// `at(v, scratch)` for every pending vertex, in parallel chunks with a scratch each.
fn masks_in_chunks<'r>(
    pending: &[u32],
    at: impl Fn(u32, Option<&mut ComposedRows<'r>>) -> Option<AtVertex> + Sync,
    scratch: impl Fn() -> Option<ComposedRows<'r>> + Sync,
) -> Vec<Option<AtVertex>> {
    let chunks: Vec<Vec<Option<AtVertex>>> = pending
        .par_chunks(ROWS_CHUNK)
        .map(|chunk| {
            let mut composed = scratch();
            chunk.iter().map(|&v| at(v, composed.as_mut())).collect()
        })
        .collect();
    chunks.into_iter().flatten().collect()
}

/// Where a level's masks take their values from: the rows of a refinement's level
/// (composed back to the base), or the level's points.
enum Source<'a> {
    Rows(&'a Refined, usize),
    Points(&'a [DVec3]),
}

/// What the interior masks need at every level: the base, and the masks by valence (with
/// their balls' sizes).
struct Interior<'a> {
    base: &'a Topology,
    interpolating: bool,
    masks: &'a HashMap<usize, (LocalMasks, usize)>,
}

impl<'a> Interior<'a> {
    /// The masks at a level of `topology`, whose vertex of each base vertex `numbering`
    /// gives (`None`: the same), read as `source` says.
    fn at(
        &self,
        topology: &'a Topology,
        numbering: Option<&'a [u32]>,
        source: Source<'a>,
    ) -> LevelMasks<'a> {
        LevelMasks {
            base: self.base,
            interpolating: self.interpolating,
            masks: self.masks,
            topology,
            features: Features::new(topology),
            numbering,
            source,
        }
    }
}

/// The interior masks at one level of a refinement around the pending vertices.
struct LevelMasks<'a> {
    base: &'a Topology,
    interpolating: bool,
    masks: &'a HashMap<usize, (LocalMasks, usize)>,
    topology: &'a Topology,
    features: Features,
    /// The level's vertex of each base vertex; `None` where they are the same.
    numbering: Option<&'a [u32]>,
    source: Source<'a>,
}

impl LevelMasks<'_> {
    /// Base vertex `v`'s limit and tangents, as rows (through `composed`) or values; `None`
    /// while its ball is not regular yet.
    fn at(&self, v: u32, composed: Option<&mut ComposedRows>) -> Option<AtVertex> {
        let (m, size) = &self.masks[&self.base.valence(v as usize)];
        let t = self.topology;
        let lv = self.numbering.map_or(v, |n| n[v as usize]);
        let ball = LocalMasks::ball(t, lv, m.radius);
        if !regular_ball(t, &self.features, lv, &ball, *size) {
            return None;
        }
        let limit = (!self.interpolating).then_some(&m.limit);
        match self.source {
            Source::Points(points) => {
                // As `apply_row` sums the entries, without collecting them.
                let value = |w: &Vec<f64>| {
                    ball.iter()
                        .zip(w)
                        .filter(|(_, w)| **w != 0.0)
                        .fold(DVec3::ZERO, |acc, (&u, &w)| acc + w * points[u as usize])
                };
                let tangents = m.tangents.as_ref().map(|[a, b]| [value(a), value(b)]);
                Some(AtVertex::Values(limit.map(value), tangents))
            }
            Source::Rows(refined, level) => {
                let composed = composed.expect("rows compose through the refinement");
                let mut row = |w: &Vec<f64>| {
                    let entries: Row = ball
                        .iter()
                        .zip(w)
                        .filter(|(_, w)| **w != 0.0)
                        .map(|(&u, &w)| (u, w))
                        .collect();
                    refined.base_row(entries, level, composed)
                };
                let limit = limit.map(&mut row);
                let tangents = m.tangents.as_ref().map(|[a, b]| [row(a), row(b)]);
                Some(AtVertex::Rows(limit, tangents))
            }
        }
    }
}

/// Pending vertices per parallel task of [`interior_rows`].
const ROWS_CHUNK: usize = 2048;

/// √3's limit of a vertex inside a boundary or crease curve: `(p₋₁ + 4p + p₁)/6` of its
/// curve neighbours. The mask is invariant under every step as long as those neighbours do
/// not move on odd steps, which holds unless one is a dart (the end of a crease inside the
/// surface, moved by the smooth rule); then it is applied two levels down, where the
/// neighbours are trisection points.
fn sqrt3_curve_limit(
    base: &Topology,
    features: &Features,
    v: u32,
    refiner: &Refiner<'_>,
) -> Result<Row, LimitError> {
    let curve = |t: &Topology, f: &Features, v: u32| -> Row {
        let [e0, e1] = f.curve_edges(v as usize);
        vec![
            (t.edge_other_vertex(e0 as usize, v), 1.0 / 6.0),
            (v, 4.0 / 6.0),
            (t.edge_other_vertex(e1 as usize, v), 1.0 / 6.0),
        ]
    };
    let row = curve(base, features, v);
    let is_dart = |u: u32| features.degree(u as usize) == 1 && !base.is_boundary_vertex(u as usize);
    if !row.iter().any(|&(u, _)| u != v && is_dart(u)) {
        return Ok(row);
    }
    let refined = refiner.around(&[v], 2, 1)?;
    let t2 = refined.r.topology(2);
    let row = curve(t2, &Features::new(t2), refined.vertex(v));
    Ok(refined.base_row(row, 2, &mut ComposedRows::new(&refined.r)))
}

/// Darts and boundary vertices: the masks of the synthetic feature centre of the same kind
/// ([`feature_masks`]) wherever the vertex's own local subdivision matrix, read off the
/// refinement, is that centre's (so its neighbourhood has become regular but for it). √3's
/// matrix covers an odd and an even step, so only even levels are tried there.
fn feature_rows(
    scheme: &Scheme,
    refiner: &Refiner<'_>,
    vertices: &[u32],
    found: &mut Found<'_>,
) -> Result<(), LimitError> {
    if vertices.is_empty() {
        return Ok(());
    }
    let steps = scheme.period();
    let mut masks: HashMap<FeatureCentre, Option<FeatureMasks>> = HashMap::new();
    let mut pending = vertices.to_vec();
    for level in (0..=MAX_LEVELS - steps).step_by(steps) {
        // Refined only as deep as this level needs, only around the vertices still pending
        // (most vertices are settled at level 0).
        let refined = refiner.around(&pending, level + steps, FEATURE_RADIUS)?;
        let mut composed = ComposedRows::new(&refined.r);
        let r = &refined.r;
        let (parent, child) = (r.topology(level), r.topology(level + steps));
        let rows = |c: u32| row_between(r, level, level + steps, c);
        let mut still = Vec::new();
        for &v in &pending {
            let lv = refined.vertex(v);
            let centre = if parent.is_boundary_vertex(lv as usize) {
                FeatureCentre::Boundary {
                    faces: parent.vertex_faces(lv as usize).len(),
                }
            } else {
                FeatureCentre::Dart {
                    valence: parent.valence(lv as usize),
                }
            };
            let m = masks
                .entry(centre)
                .or_insert_with(|| feature_masks(scheme, centre).ok());
            let Some(m) = m else { continue };
            let Some(local) = feature_matrix(parent, child, &rows, lv, m.radius) else {
                still.push(v);
                continue;
            };
            let same = local.nrows() == m.matrix.nrows()
                && (0..local.nrows()).all(|i| {
                    (0..local.ncols()).all(|j| (local[(i, j)] - m.matrix[(i, j)]).abs() <= 1e-12)
                });
            if !same {
                still.push(v);
                continue;
            }
            let ball = feature_ball(parent, lv, m.radius).expect("a feature vertex");
            let mut row = |w: &[f64]| -> Row {
                let r: Row = ball
                    .iter()
                    .zip(w)
                    .filter(|(_, w)| w.abs() > 1e-15)
                    .map(|(&u, &w)| (u, w))
                    .collect();
                refined.base_row(r, level, &mut composed)
            };
            if !found.has_position(v as usize) {
                found.set_position(v as usize, row(&m.limit));
            }
            if let Some([a, b]) = &m.tangents {
                found.set_tangents(v as usize, [row(a), row(b)]);
            }
        }
        pending = still;
        if pending.is_empty() {
            break;
        }
    }
    Ok(())
}

/// The largest ball radius [`feature_masks`] reads (its search stops at 6).
const FEATURE_RADIUS: usize = 6;
