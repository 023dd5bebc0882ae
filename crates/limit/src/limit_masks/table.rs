//! [`LimitStencilTable`]: limit positions and tangents of every vertex of a level, as stencils.

use std::collections::HashMap;
use std::collections::hash_map::Entry;

use glam::DVec3;
use rayon::prelude::*;
use subd_mesh::Topology;
use subd_mesh::tags::is_infinite;
use subd_schemes::{Refinement, RowSink, Rule, Scheme, StencilTable, rules};

use crate::limit_masks::eigen::{RingFeature, ring_limit_mask};
use crate::limit_masks::masks::{self, LimitMask, RingMask};
use crate::{LimitError, Tangents};

/// Limit position, tangents and unit normals of a set of vertices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LimitPoints {
    /// Limit positions.
    pub positions: Vec<DVec3>,
    /// First tangents (see [`crate::masks`] for the convention).
    pub tangent1: Vec<DVec3>,
    /// Second tangents.
    pub tangent2: Vec<DVec3>,
    /// `normalize(tangent1 × tangent2)`; zero where the tangents are parallel, NaN where the
    /// scheme defines no tangents ([`LimitStencilTable::without_tangents`]).
    pub normals: Vec<DVec3>,
}

/// Three stencil tables with one row per vertex: limit position, first and second tangent.
/// Same CSR form as the refinement stencils, so they compose with them and apply to any
/// per-vertex data.
///
/// ```
/// use subd_mesh::{DVec3, TopologyBuilder};
/// use subd_schemes::{Options, Refinement, Scheme};
/// use subd_limit::LimitStencilTable;
///
/// // A cube (OpenSubdiv's catmark_cube): every vertex is smooth of valence 3.
/// let faces = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4];
/// let topo = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
/// let s = [(-1., -1., 1.), (1., -1., 1.), (-1., 1., 1.), (1., 1., 1.),
///          (-1., 1., -1.), (1., 1., -1.), (-1., -1., -1.), (1., -1., -1.)];
/// let cube: Vec<DVec3> = s.iter().map(|&(x, y, z)| 0.5 * DVec3::new(x, y, z)).collect();
/// let r = Refinement::new(&topo, Scheme::CatmullClark, &Options::default(), 0).unwrap();
/// let limit = LimitStencilTable::at_level(&r, 0).unwrap().apply(&cube);
/// // The limit of corner 0 lies on the diagonal through it, inside the cube, and its normal
/// // points outwards along that diagonal.
/// let (p, d) = (limit.positions[0], DVec3::new(-1.0, -1.0, 1.0));
/// assert!(p.cross(d).length() < 1e-15 && p.dot(d) > 0.0 && p.dot(d) < 1.5);
/// assert!((limit.normals[0] - d.normalize()).length() < 1e-15);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct LimitStencilTable {
    /// Limit positions.
    pub position: StencilTable,
    /// First tangents.
    pub tangent1: StencilTable,
    /// Second tangents.
    pub tangent2: StencilTable,
    /// Vertices where the scheme defines no tangents (and so no normal), their tangent rows
    /// empty: inside a crease or at a corner of √3 and the butterflies, where the classic
    /// butterfly is not C¹. Empty when every vertex has them (Catmull-Clark, Loop, the
    /// two-phase scheme); otherwise one flag per row.
    pub without_tangents: Vec<bool>,
}

/// How one vertex's limit is taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum VertexCase {
    Isolated,
    Corner,
    Crease(usize, usize),
    /// Closed form (Catmull-Clark valence ≥ 3, Loop), or a semi-sharp dart.
    Smooth,
    /// By eigen analysis: an infinitely sharp dart (sharp edge at the given position), or a
    /// Catmull-Clark interior vertex of valence 2 (smooth, or a semi-sharp dart).
    Numeric(RingFeature, usize),
}

/// The smooth case of a vertex with `nf` faces and `ne` edges: the closed form, except at
/// an interior Catmull-Clark vertex of valence 2, where it is not the limit (OpenSubdiv
/// copies the vertex there) and the eigen analysis gives it.
fn smooth_case(nf: usize, ne: usize, scheme: &Scheme) -> VertexCase {
    if *scheme == Scheme::CatmullClark && nf == 2 && ne == 2 {
        VertexCase::Numeric(RingFeature::Smooth, 0)
    } else {
        VertexCase::Smooth
    }
}

fn classify(t: &Topology, v: usize, rule: Rule, scheme: &Scheme) -> VertexCase {
    let ve = t.vertex_edges(v);
    if ve.is_empty() {
        return VertexCase::Isolated;
    }
    let n = t.vertex_faces(v).len();
    match rule {
        Rule::Corner => VertexCase::Corner,
        Rule::Crease => {
            let (a, b) = rules::crease_pair(ve.len(), |i| t.edge_sharpness(ve[i] as usize) > 0.0);
            VertexCase::Crease(a, b)
        }
        Rule::Dart => {
            let k = ve
                .iter()
                .position(|&e| t.edge_sharpness(e as usize) > 0.0)
                .unwrap_or(0);
            if is_infinite(t.edge_sharpness(ve[k] as usize)) && n == ve.len() {
                VertexCase::Numeric(RingFeature::Dart, k)
            } else {
                // A semi-sharp dart takes the smooth mask at this level.
                smooth_case(n, ve.len(), scheme)
            }
        }
        Rule::Smooth => smooth_case(n, ve.len(), scheme),
    }
}

/// Vertices of `level` whose limit comes from the eigen analysis rather than a closed form:
/// interior Catmull-Clark vertices of valence 2 and darts on infinitely sharp edges — the
/// vertices where OpenSubdiv's `PrimvarRefiner::Limit` is not the limit (see OPENSUBDIV.md).
pub fn eigen_limit_vertices(refinement: &Refinement, level: usize) -> Vec<usize> {
    let t = refinement.topology(level);
    let rules = refinement.vertex_rules(level);
    (0..t.num_vertices())
        .filter(|&v| {
            matches!(
                classify(t, v, rules[v], refinement.scheme()),
                VertexCase::Numeric(..)
            )
        })
        .collect()
}

/// `m` with its ring rotated so that entry `i` moves to `i + k`.
fn rotated(m: &RingMask, k: usize) -> RingMask {
    let rot = |w: &[f64]| -> Vec<f64> {
        let n = w.len();
        let mut out = vec![0.0; n];
        for (i, &x) in w.iter().enumerate() {
            out[(i + k) % n] = x;
        }
        out
    };
    RingMask {
        vertex: m.vertex,
        edges: rot(&m.edges),
        faces: rot(&m.faces),
    }
}

/// The limit mask of every vertex of one level: masks depend only on the vertex's case and
/// its edge and face counts, so each distinct one is built once and vertices point at it
/// (filling the rows then allocates and hashes nothing per vertex).
pub(crate) struct LevelMasks<'a> {
    topology: &'a Topology,
    library: Vec<LimitMask>,
    /// Index into `library` per vertex.
    mask: Vec<u32>,
}

impl<'a> LevelMasks<'a> {
    pub(crate) fn new(
        refinement: &'a Refinement,
        level: usize,
    ) -> Result<LevelMasks<'a>, LimitError> {
        let scheme = &crate::masks_scheme(refinement.scheme(), level > 0)?;
        let t = refinement.topology(level);
        if *scheme == Scheme::CatmullClark
            && let Some(f) = (0..t.num_faces()).find(|&f| t.face_size(f) != 4)
        {
            return Err(LimitError::NotQuad {
                level,
                face: f,
                size: t.face_size(f),
            });
        }
        let rules = refinement.vertex_rules(level);
        let keys: Vec<(VertexCase, usize, usize)> = (0..t.num_vertices())
            .into_par_iter()
            .with_min_len(4096)
            .map(|v| {
                (
                    classify(t, v, rules[v], scheme),
                    t.vertex_edges(v).len(),
                    t.vertex_faces(v).len(),
                )
            })
            .collect();
        let mut index: HashMap<(VertexCase, usize, usize), u32> = HashMap::new();
        let mut numeric: HashMap<(RingFeature, usize), LimitMask> = HashMap::new();
        let mut library = Vec::new();
        let mut mask = Vec::with_capacity(keys.len());
        let mut last: Option<((VertexCase, usize, usize), u32)> = None;
        for &k in &keys {
            // Neighbouring vertices mostly share a case: skip the hash then.
            if let Some((lk, li)) = last
                && lk == k
            {
                mask.push(li);
                continue;
            }
            let id = match index.entry(k) {
                Entry::Occupied(e) => *e.get(),
                Entry::Vacant(e) => {
                    let (case, ne, nf) = k;
                    library.push(case_mask(scheme, case, ne, nf, &mut numeric)?);
                    *e.insert((library.len() - 1) as u32)
                }
            };
            last = Some((k, id));
            mask.push(id);
        }
        Ok(LevelMasks {
            topology: t,
            library,
            mask,
        })
    }

    /// The limit mask of vertex `v`.
    pub(crate) fn of(&self, v: usize) -> &LimitMask {
        &self.library[self.mask[v] as usize]
    }

    /// The limit points of every vertex of the level from that level's `points`: each mask
    /// applied straight to the ring, without building a table, in parallel chunks. The sums
    /// are those of [`StencilTable::apply_points`] over [`LevelMasks::table`]'s rows, term
    /// for term, so the values are the same bit for bit.
    pub(crate) fn apply(&self, points: &[DVec3], tangents: Tangents) -> LimitPoints {
        let t = self.topology;
        assert_eq!(points.len(), t.num_vertices(), "one point per vertex");
        let with_faces = self.library.iter().any(|m| !m.position.faces.is_empty());
        limit_by_vertex(t.num_vertices(), tangents, |ring, v| {
            ring.gather(t, v, with_faces);
            ring.limit(self.of(v), points)
        })
    }

    /// The table of one of the masks (`which` picks position or a tangent).
    fn table(&self, which: impl Fn(&LimitMask) -> &RingMask + Sync) -> StencilTable {
        let t = self.topology;
        StencilTable::build(t.num_vertices(), t.num_vertices(), |v, sink| {
            emit(t, v, which(&self.library[self.mask[v] as usize]), sink)
        })
    }
}

/// The limit mask of a vertex case with `ne` edges and `nf` faces (numeric masks are shared
/// between rotations through `numeric`).
fn case_mask(
    scheme: &Scheme,
    case: VertexCase,
    ne: usize,
    nf: usize,
    numeric: &mut HashMap<(RingFeature, usize), LimitMask>,
) -> Result<LimitMask, LimitError> {
    Ok(match case {
        VertexCase::Isolated => masks::corner(0, 0, 0.0),
        VertexCase::Corner => {
            masks::corner(ne, nf, if *scheme == Scheme::Loop { 3.0 } else { 1.0 })
        }
        VertexCase::Crease(a, b) => match scheme {
            Scheme::Loop => masks::loop_crease(ne, (a, b)),
            _ => masks::catmark_crease(ne, nf, (a, b)),
        },
        VertexCase::Smooth => match scheme {
            Scheme::Loop => masks::loop_smooth(nf),
            _ => masks::catmark_smooth(nf),
        },
        VertexCase::Numeric(feature, rot) => {
            let m = match numeric.entry((feature, nf)) {
                Entry::Occupied(e) => e.into_mut(),
                Entry::Vacant(e) => e.insert(ring_limit_mask(scheme, nf, feature)?),
            };
            LimitMask {
                position: rotated(&m.position, rot),
                tangent1: rotated(&m.tangent1, rot),
                tangent2: rotated(&m.tangent2, rot),
            }
        }
    })
}

impl LimitStencilTable {
    /// Limit masks of every vertex of `level` of `refinement`, in terms of the vertices of
    /// that level. Each vertex takes the mask of its rule at that level, as OpenSubdiv's
    /// `PrimvarRefiner::Limit` does (so semi-sharp features still present at that level count
    /// as sharp), except where OpenSubdiv is not exact: an interior Catmull-Clark vertex of
    /// valence 2 and a dart on an infinitely sharp edge get their true limit, from the eigen
    /// analysis of their local subdivision matrix ([`crate::eigen`]).
    ///
    /// Catmull-Clark needs quads at that level (any level ≥ 1 is all quads); Bilinear has no
    /// limit masks.
    pub fn at_level(refinement: &Refinement, level: usize) -> Result<Self, LimitError> {
        let masks = LevelMasks::new(refinement, level)?;
        Ok(LimitStencilTable {
            position: masks.table(|m| &m.position),
            tangent1: masks.table(|m| &m.tangent1),
            tangent2: masks.table(|m| &m.tangent2),
            without_tangents: Vec::new(),
        })
    }

    /// The limit positions of [`LimitStencilTable::at_level`] alone (same rows, bit for
    /// bit), for callers that need no tangents, such as interpolation: a third of the work.
    ///
    /// # Errors
    /// As [`LimitStencilTable::at_level`].
    pub fn positions_at_level(
        refinement: &Refinement,
        level: usize,
    ) -> Result<StencilTable, LimitError> {
        Ok(LevelMasks::new(refinement, level)?.table(|m| &m.position))
    }

    /// Number of rows (vertices).
    pub fn num_rows(&self) -> usize {
        self.position.num_rows()
    }

    /// The three tables composed after `first`: rows of this table expressed in terms of
    /// `first`'s sources (e.g. `refinement.composed(level)` gives limit stencils over the base
    /// vertices).
    pub fn after(&self, first: &StencilTable) -> LimitStencilTable {
        LimitStencilTable {
            position: first.then(&self.position),
            tangent1: first.then(&self.tangent1),
            tangent2: first.then(&self.tangent2),
            without_tangents: self.without_tangents.clone(),
        }
    }

    /// Limit positions, tangents and unit normals from the control points the rows refer to;
    /// NaN tangents and normals at the vertices [`LimitStencilTable::without_tangents`] names.
    pub fn apply(&self, points: &[DVec3]) -> LimitPoints {
        let positions = self.position.apply_points(points);
        let mut tangent1 = self.tangent1.apply_points(points);
        let mut tangent2 = self.tangent2.apply_points(points);
        let mut normals: Vec<DVec3> = tangent1
            .iter()
            .zip(&tangent2)
            .map(|(a, b)| a.cross(*b).normalize_or_zero())
            .collect();
        let nan = DVec3::splat(f64::NAN);
        for (v, &without) in self.without_tangents.iter().enumerate() {
            if without {
                (tangent1[v], tangent2[v], normals[v]) = (nan, nan, nan);
            }
        }
        LimitPoints {
            positions,
            tangent1,
            tangent2,
            normals,
        }
    }
}

/// Vertices per parallel job of [`limit_by_vertex`].
const APPLY_CHUNK: usize = 4096;

/// The limit points of `n` vertices, vertex `v`'s (position, tangents, normal) given by
/// `limit(ring, v)` with a scratch [`Ring`], filled in parallel chunks straight into the
/// arrays (their zeroed pages first touched by the thread that fills them); the tangent
/// arrays left empty when `tangents` drops them.
pub(crate) fn limit_by_vertex(
    n: usize,
    tangents: Tangents,
    limit: impl Fn(&mut Ring, usize) -> [DVec3; 4] + Sync,
) -> LimitPoints {
    let kept = if tangents == Tangents::Kept { n } else { 0 };
    let mut out = LimitPoints {
        positions: subd_mesh::memory::zeroed(n),
        tangent1: subd_mesh::memory::zeroed(kept),
        tangent2: subd_mesh::memory::zeroed(kept),
        normals: subd_mesh::memory::zeroed(n),
    };
    let fill = |chunk: usize, p: &mut [DVec3], normal: &mut [DVec3], mut t: TangentChunks| {
        let mut ring = Ring::default();
        for k in 0..p.len() {
            let [pk, t1, t2, nk] = limit(&mut ring, chunk * APPLY_CHUNK + k);
            (p[k], normal[k]) = (pk, nk);
            if let Some((a, b)) = &mut t {
                (a[k], b[k]) = (t1, t2);
            }
        }
    };
    let points = out
        .positions
        .par_chunks_mut(APPLY_CHUNK)
        .zip(out.normals.par_chunks_mut(APPLY_CHUNK))
        .enumerate();
    if kept > 0 {
        let t = out
            .tangent1
            .par_chunks_mut(APPLY_CHUNK)
            .zip(out.tangent2.par_chunks_mut(APPLY_CHUNK));
        points
            .zip(t)
            .for_each(|((c, (p, nm)), (a, b))| fill(c, p, nm, Some((a, b))));
    } else {
        points.for_each(|(c, (p, nm))| fill(c, p, nm, None));
    }
    out
}

/// One chunk of both tangent arrays, where they are kept.
type TangentChunks<'a> = Option<(&'a mut [DVec3], &'a mut [DVec3])>;

/// The points one vertex's ring masks read, in [`emit`]'s order (the face terms' opposite
/// corners, the edges' far ends, the vertex), gathered once for its three masks.
#[derive(Default)]
pub(crate) struct Ring {
    indices: Vec<u32>,
    num_faces: usize,
    num_edges: usize,
    /// Whether a point occurs twice (a small closed mesh): its stencil row then merges the
    /// terms, and [`Ring::apply`] sums as that row does.
    repeats: bool,
}

impl Ring {
    /// The ring of vertex `v` of `t` (without the face terms when no mask has any).
    fn gather(&mut self, t: &Topology, v: usize, with_faces: bool) {
        let faces = with_faces.then(|| {
            let local = t.vertex_face_local_indices(v);
            t.vertex_faces(v).iter().zip(local).map(|(&f, &k)| {
                let corners = t.face_vertices(f as usize);
                corners[(k as usize + 2) % corners.len()]
            })
        });
        let edges = t
            .vertex_edges(v)
            .iter()
            .map(|&e| t.edge_other_vertex(e as usize, v as u32));
        self.set(faces.into_iter().flatten(), edges, v as u32);
    }

    /// A ring given by its points: the face terms' opposite corners, the edges' far ends,
    /// the centre.
    pub(crate) fn set(
        &mut self,
        faces: impl IntoIterator<Item = u32>,
        edges: impl IntoIterator<Item = u32>,
        centre: u32,
    ) {
        self.indices.clear();
        self.indices.extend(faces);
        self.num_faces = self.indices.len();
        self.indices.extend(edges);
        self.num_edges = self.indices.len() - self.num_faces;
        self.indices.push(centre);
        let ix = &self.indices;
        self.repeats = (1..ix.len()).any(|i| ix[..i].contains(&ix[i]));
    }

    /// The three masks of `m` applied to `points`: position, tangents, unit normal.
    pub(crate) fn limit(&self, m: &LimitMask, points: &[DVec3]) -> [DVec3; 4] {
        let [p, t1, t2] = if self.repeats {
            [&m.position, &m.tangent1, &m.tangent2].map(|r| self.apply(r, points))
        } else {
            self.apply_three(m, points)
        };
        [p, t1, t2, t1.cross(t2).normalize_or_zero()]
    }

    /// [`Ring::apply`] of the three masks in one pass over the ring (each point read once;
    /// each sum in the same order as alone), for a ring without repeated points.
    fn apply_three(&self, m: &LimitMask, points: &[DVec3]) -> [DVec3; 3] {
        let masks = [&m.position, &m.tangent1, &m.tangent2];
        let (nf, ne) = (self.num_faces, self.num_edges);
        let mut acc = [DVec3::ZERO; 3];
        let mut add = |i: u32, w: [f64; 3]| {
            let p = points[i as usize];
            for (a, w) in acc.iter_mut().zip(w) {
                *a += w * p;
            }
        };
        let at = |w: &[f64], k: usize| w.get(k).copied().unwrap_or(0.0);
        for (k, &i) in self.indices[..nf].iter().enumerate() {
            add(i, masks.map(|r| at(&r.faces, k)));
        }
        for (k, &i) in self.indices[nf..nf + ne].iter().enumerate() {
            add(i, masks.map(|r| at(&r.edges, k)));
        }
        add(self.indices[nf + ne], masks.map(|r| r.vertex));
        acc
    }

    /// Mask `m` applied to `points`. A term of weight zero, which the row leaves out, adds
    /// a signed zero to a sum that started at +0: no change for finite points.
    fn apply(&self, m: &RingMask, points: &[DVec3]) -> DVec3 {
        if self.repeats {
            // As `RowSink` merges: nonzero terms, per point in order of first appearance.
            let mut merged: Vec<(u32, f64)> = Vec::with_capacity(self.indices.len());
            for (i, w) in self.terms(m).filter(|&(_, w)| w != 0.0) {
                match merged.iter_mut().find(|(j, _)| *j == i) {
                    Some((_, sum)) => *sum += w,
                    None => merged.push((i, w)),
                }
            }
            return merged
                .iter()
                .fold(DVec3::ZERO, |acc, &(i, w)| acc + w * points[i as usize]);
        }
        let mut acc = DVec3::ZERO;
        for (i, w) in self.terms(m) {
            acc += w * points[i as usize];
        }
        acc
    }

    /// (point, weight) in order; weights past a mask's end are zero.
    fn terms<'a>(&'a self, m: &'a RingMask) -> impl Iterator<Item = (u32, f64)> + 'a {
        let (nf, ne) = (self.num_faces, self.num_edges);
        let weight = |w: &[f64], i: usize| w.get(i).copied().unwrap_or(0.0);
        self.indices.iter().enumerate().map(move |(k, &i)| {
            let w = if k < nf {
                weight(&m.faces, k)
            } else if k < nf + ne {
                weight(&m.edges, k - nf)
            } else {
                m.vertex
            };
            (i, w)
        })
    }
}

/// Writes a ring mask of vertex `v` as a stencil row: face terms first, then edge terms, then
/// the vertex (OpenSubdiv's summation order); zero weights are left out.
pub(crate) fn emit(t: &Topology, v: usize, m: &RingMask, sink: &mut RowSink) {
    ring_terms(t, v, m, |i, w| sink.add(i, w));
}

/// The nonzero terms (vertex, weight) of ring mask `m` of vertex `v`, in [`emit`]'s order: a
/// face weight goes to the face's vertex opposite `v`, an edge weight to the edge's other end.
pub(crate) fn ring_terms(t: &Topology, v: usize, m: &RingMask, term: impl FnMut(u32, f64)) {
    ring_terms_by(
        t,
        v,
        m,
        |f, k| t.face_vertices(f)[k],
        |e| t.edge_other_vertex(e, v as u32),
        v as u32,
        term,
    );
}

/// [`ring_terms`] with the points named by the caller: `corner(f, k)` for the point at
/// corner `k` of face `f`, `far(e)` for the far end of edge `e`, `centre` for the vertex
/// (a face-varying channel names its values there).
pub(crate) fn ring_terms_by(
    t: &Topology,
    v: usize,
    m: &RingMask,
    corner: impl Fn(usize, usize) -> u32,
    far: impl Fn(usize) -> u32,
    centre: u32,
    mut term: impl FnMut(u32, f64),
) {
    if !m.faces.is_empty() {
        let local = t.vertex_face_local_indices(v);
        for (i, &f) in t.vertex_faces(v).iter().enumerate() {
            if m.faces[i] != 0.0 {
                let n = t.face_size(f as usize);
                term(corner(f as usize, (local[i] as usize + 2) % n), m.faces[i]);
            }
        }
    }
    for (i, &e) in t.vertex_edges(v).iter().enumerate() {
        if i < m.edges.len() && m.edges[i] != 0.0 {
            term(far(e as usize), m.edges[i]);
        }
    }
    if m.vertex != 0.0 {
        term(centre, m.vertex);
    }
}

/// At an interior crease vertex the surface has one tangent plane per side of the crease.
/// The limit mask of vertex `v` (rule `rule`) whose cross tangent is taken over the side
/// that holds face `f`; `None` where `v` is not an interior manifold crease vertex or `f` is
/// already on the side the table's mask uses (the faces from the first crease edge to the
/// second, counter-clockwise).
pub(crate) fn crease_side_mask(
    t: &Topology,
    v: usize,
    rule: Rule,
    scheme: &Scheme,
    f: usize,
) -> Option<LimitMask> {
    let (ve, vf) = (t.vertex_edges(v), t.vertex_faces(v));
    if rule != Rule::Crease
        || t.is_boundary_vertex(v)
        || t.is_non_manifold_vertex(v)
        || ve.len() != vf.len()
    {
        return None;
    }
    let VertexCase::Crease(a, b) = classify(t, v, rule, scheme) else {
        return None;
    };
    let k = vf.iter().position(|&g| g as usize == f)?;
    if (a..b).contains(&k) {
        return None;
    }
    // The other side, seen from the second crease edge: rotate it to position 0.
    let (ne, nf) = (ve.len(), vf.len());
    let ends = (0, a + ne - b);
    let m = match scheme {
        Scheme::Loop => masks::loop_crease(ne, ends),
        _ => masks::catmark_crease(ne, nf, ends),
    };
    Some(LimitMask {
        position: rotated(&m.position, b),
        tangent1: rotated(&m.tangent1, b),
        tangent2: rotated(&m.tangent2, b),
    })
}

/// A ring mask of vertex `v` applied to `points` (the sum of the row [`emit`] writes).
pub(crate) fn apply_ring(t: &Topology, v: usize, m: &RingMask, points: &[DVec3]) -> DVec3 {
    let mut p = DVec3::ZERO;
    ring_terms(t, v, m, |i, w| p += w * points[i as usize]);
    p
}
