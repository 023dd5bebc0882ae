//! Exact evaluation next to irregular sharp features by local refinement.
//!
//! A face whose neighbourhood never becomes a B-spline, box-spline or Stam patch under
//! refinement (darts, crease and boundary vertices of irregular valence, semi-sharp creases
//! that have not decayed yet) is evaluated by refining a small piece of mesh around it, one
//! level at a time, following the query point into the child face that holds it, until that child is a patch the evaluator knows (a point at distance
//! `d` from the irregular vertex needs about `log2(1/d)` levels). Every step is the
//! refinement code's own uniform step, so the value is the limit surface itself, not an
//! approximation.
//!
//! **Why a 2-ring is enough.** The piece cut out around face `f` is every face within two
//! vertex-rings of `f`. Its outer boundary is artificial (the refinement treats it as a mesh
//! boundary), but the children that the next step needs — those of the faces at the
//! vertices of `f` and their 2-rings — only read vertices, edges and rules inside the first
//! ring, whose incident faces are all present. So the child 2-ring of the child face is
//! exact and the cut can repeat at every level.

use glam::DVec3;
use subd_mesh::neighbourhood::faces_within_two_rings;
use subd_mesh::tags::SHARPNESS_INFINITE;
use subd_mesh::{BoundaryInterpolation, Topology, TopologyBuilder};
use subd_schemes::{Options, Refinement, Rule, Scheme, StencilTable};

use crate::LimitStencilTable;

use crate::LimitError;
use crate::evaluation::patch::SurfacePoint;

mod shared;
pub(crate) use shared::evaluate_many;

/// Levels of local refinement before a point that still is not on a known patch is taken
/// as its face's nearest corner (the distance is then below `2^-MAX_LOCAL_LEVELS` of the
/// starting face's size, under the resolution of `f64` parameters). Only points closer than
/// that to an irregular vertex, but not exactly at it, get there.
pub const MAX_LOCAL_LEVELS: usize = 60;

/// The level the whole-mesh evaluator starts local refinement from.
pub(crate) const LIMIT_EVALUATOR_LEVEL: usize = 2;

/// The level (of the mesh's refinement) at which a descent that reaches a corner takes the
/// corner's limit, wherever it started (the evaluator's level-2 faces refine two more): where
/// the surface is singular (a boundary vertex of high valence) the derivatives there are the
/// tangent masks of that level's ring, so the level is fixed to keep them one value.
const CORNER_LEVEL: usize = LIMIT_EVALUATOR_LEVEL + 2;

/// A piece of a refined level around one face, with what is carried along for its
/// vertices (positions, or the weights of the first piece's vertices).
pub(crate) struct Neighbourhood<P = Vec<DVec3>> {
    topology: Topology,
    rules: Vec<Rule>,
    points: P,
    face: usize,
}

/// What the local descent carries for the vertices of each piece: positions, or weights
/// over the vertices of the first piece ([`Weights`]).
pub(crate) trait Carried: Sized {
    /// The values of vertices `ids` (in that order).
    fn pick(&self, ids: &[u32]) -> Self;
    /// The values of vertices `ids` of level 1 of `r` from those of its level 0.
    fn refined_pick(&self, r: &Refinement, ids: &[u32]) -> Self;
}

impl Carried for Vec<DVec3> {
    fn pick(&self, ids: &[u32]) -> Self {
        ids.iter().map(|&v| self[v as usize]).collect()
    }
    fn refined_pick(&self, r: &Refinement, ids: &[u32]) -> Self {
        r.refine_points(self).pop().expect("one level").pick(ids)
    }
}

/// Per vertex, its non-zero weights over the source vertices (indices into the first
/// piece's vertices, ascending).
pub(crate) struct Weights {
    rows: Vec<Vec<(u32, f64)>>,
}

impl Carried for Weights {
    fn pick(&self, ids: &[u32]) -> Self {
        Weights {
            rows: ids.iter().map(|&v| self.rows[v as usize].clone()).collect(),
        }
    }
    fn refined_pick(&self, r: &Refinement, ids: &[u32]) -> Self {
        // Only the rows the next piece keeps.
        let table = r.stencils(1);
        let rows = ids
            .iter()
            .map(|&i| {
                let (idx, w) = table.row(i as usize);
                let mut acc: Vec<(u32, f64)> = idx
                    .iter()
                    .zip(w)
                    .flat_map(|(&p, &wp)| {
                        self.rows[p as usize].iter().map(move |&(s, x)| (s, wp * x))
                    })
                    .collect();
                acc.sort_unstable_by_key(|e| e.0);
                let mut out: Vec<(u32, f64)> = Vec::with_capacity(acc.len());
                for (s, x) in acc {
                    match out.last_mut() {
                        Some(l) if l.0 == s => l.1 += x,
                        _ => out.push((s, x)),
                    }
                }
                out
            })
            .collect();
        Weights { rows }
    }
}

impl<P> Neighbourhood<P> {
    /// One uniform step of the piece, continuing the refinement it was cut from.
    fn refine(
        &self,
        scheme: &Scheme,
        options: &Options,
        levels: usize,
    ) -> Result<Refinement, LimitError> {
        Ok(Refinement::from_prepared(
            self.topology.clone(),
            self.rules.clone(),
            scheme.clone(),
            options,
            levels,
        )?)
    }
}

/// Faces within two vertex-rings of face `f` of a prepared level `t` (f first) as a
/// [`Neighbourhood`] with the positions `points`.
fn cut_out<P>(
    t: &Topology,
    rules: &[Rule],
    pick: impl FnOnce(&[u32]) -> P,
    f: usize,
) -> Result<Neighbourhood<P>, LimitError> {
    let mut faces = vec![f as u32];
    let mut frontier = 0..1;
    for _ in 0..2 {
        let end = faces.len();
        for i in frontier {
            for &v in t.face_vertices(faces[i] as usize) {
                for &g in t.vertex_faces(v as usize) {
                    if !faces.contains(&g) {
                        faces.push(g);
                    }
                }
            }
        }
        frontier = end..faces.len();
    }
    let cut = Cut::new(t, rules, &faces).map_err(|e| match e {
        LimitError::Unsupported { reason, .. } => LimitError::Unsupported { face: f, reason },
        e => e,
    })?;
    Ok(Neighbourhood {
        points: pick(&cut.vertices),
        topology: cut.topology,
        rules: cut.rules,
        face: 0,
    })
}

/// A set of faces of a prepared level as a mesh of its own that continues the level's
/// refinement: the faces in the given order, their vertices renumbered by first appearance,
/// with the level's sharpness and hole tags and vertex rules. The cut's outer boundary is
/// made infinitely sharp and the rules of the vertices on it re-derived from their tags;
/// those vertices only feed children outside the part of the cut whose every incident face
/// is present, where the refinement is exact.
pub(crate) struct Cut {
    /// The cut's topology.
    pub topology: Topology,
    /// Its vertex rules.
    pub rules: Vec<Rule>,
    /// The level's vertex of each cut vertex.
    pub vertices: Vec<u32>,
}

impl Cut {
    /// Cuts `faces` out of the prepared level `t` with vertex rules `rules`.
    pub(crate) fn new(t: &Topology, rules: &[Rule], faces: &[u32]) -> Result<Cut, LimitError> {
        use std::collections::HashMap;
        let mut local: HashMap<u32, u32> = HashMap::with_capacity(2 * faces.len());
        let mut vertices: Vec<u32> = Vec::new();
        let mut sizes = Vec::with_capacity(faces.len());
        let mut face_vertices = Vec::new();
        for &g in faces {
            let fv = t.face_vertices(g as usize);
            sizes.push(fv.len() as u32);
            for &v in fv {
                let new = *local.entry(v).or_insert_with(|| {
                    vertices.push(v);
                    (vertices.len() - 1) as u32
                });
                face_vertices.push(new);
            }
        }
        let mut sub = TopologyBuilder::new(vertices.len())
            .accept_inconsistent_orientation(true)
            .build(&sizes, &face_vertices)
            .map_err(|e| LimitError::Analysis(format!("local neighbourhood: {e}")))?;
        for (i, &g) in faces.iter().enumerate() {
            let g = g as usize;
            sub.set_hole(i, t.is_hole(g));
            let sub_edges = sub.face_edges(i).to_vec();
            for (&se, &ge) in sub_edges.iter().zip(t.face_edges(g)) {
                sub.set_edge_sharpness(se as usize, t.edge_sharpness(ge as usize));
            }
        }
        for (new, &old) in vertices.iter().enumerate() {
            sub.set_vertex_sharpness(new, t.vertex_sharpness(old as usize));
        }
        for e in 0..sub.num_edges() {
            if sub.is_boundary_edge(e) {
                sub.set_edge_sharpness(e, SHARPNESS_INFINITE);
            }
        }
        let in_cut: std::collections::HashSet<u32> = faces.iter().copied().collect();
        let complete: Vec<bool> = vertices
            .iter()
            .map(|&old| {
                t.vertex_faces(old as usize)
                    .iter()
                    .all(|g| in_cut.contains(g))
            })
            .collect();
        // Rebuilding from face lists merges repeated non-manifold edge instances that the
        // refined level keeps apart; such a cut would refine differently, so it is refused.
        let mut faithful = true;
        let sub_rules: Vec<Rule> = vertices
            .iter()
            .enumerate()
            .map(|(n, &old)| {
                let o = old as usize;
                if complete[n] {
                    if sub.vertex_edges(n).len() != t.vertex_edges(o).len()
                        || sub.is_non_manifold_vertex(n) != t.is_non_manifold_vertex(o)
                    {
                        faithful = false;
                    }
                    rules[o]
                } else {
                    let sharp = sub
                        .vertex_edges(n)
                        .iter()
                        .filter(|&&e| sub.edge_sharpness(e as usize) > 0.0)
                        .count();
                    Rule::determine(sub.vertex_sharpness(n), sharp)
                }
            })
            .collect();
        if !faithful {
            return Err(LimitError::Unsupported {
                face: faces[0] as usize,
                reason: "a non-manifold configuration that a local cut does not reproduce",
            });
        }
        Ok(Cut {
            topology: sub,
            rules: sub_rules,
            vertices,
        })
    }
}

/// The corner of the face that (u, v) is exactly at, if any (quads: (0,0), (1,0), (1,1),
/// (0,1); triangles: (0,0), (1,0), (0,1)).
fn exact_corner(scheme: &Scheme, u: f64, v: f64) -> Option<usize> {
    match (scheme, u, v) {
        (_, 0.0, 0.0) => Some(0),
        (_, 1.0, 0.0) => Some(1),
        (&Scheme::Loop, 0.0, 1.0) => Some(2),
        (&Scheme::Loop, _, _) => None,
        (_, 1.0, 1.0) => Some(2),
        (_, 0.0, 1.0) => Some(3),
        _ => None,
    }
}

/// The corner nearest to (u, v).
fn nearest_corner(scheme: &Scheme, u: f64, v: f64) -> usize {
    if *scheme == Scheme::Loop {
        if u + v < 0.5 {
            0
        } else if u >= v {
            1
        } else {
            2
        }
    } else {
        match (u >= 0.5, v >= 0.5) {
            (false, false) => 0,
            (true, false) => 1,
            (true, true) => 2,
            (false, true) => 3,
        }
    }
}

/// The limit at corner `c` of the neighbourhood's face: position and the limit tangents
/// (their directions exact, their scale the masks' convention; at an interior crease vertex
/// those of the face's side of the crease), second derivatives zero.
fn corner_limit<P>(
    nb: &Neighbourhood<P>,
    base_points: &[DVec3],
    scheme: &Scheme,
    options: &Options,
    c: usize,
) -> Result<SurfacePoint, LimitError> {
    let v = nb.topology.face_vertices(nb.face)[c] as usize;
    // Semi-sharp features decay first (a vertex keeps its index at every level).
    let levels = crate::levels_for_exact_limit(&nb.topology, scheme).0;
    let r = nb.refine(scheme, options, levels)?;
    let table = crate::LimitStencilTable::at_level(&r, levels)?;
    let points = r.refine_points(base_points).pop().expect("the last level");
    let row = |t: &subd_schemes::StencilTable| {
        let (idx, w) = t.row(v);
        idx.iter()
            .zip(w)
            .fold(DVec3::ZERO, |acc, (&i, &wi)| acc + wi * points[i as usize])
    };
    // At an interior crease vertex, the tangent plane of the face's own side: follow the
    // corner's child face down to the level the masks are taken at (child c of a face holds
    // its corner c, for quads and triangles alike).
    let mut face = nb.face;
    for l in 0..levels {
        face = match scheme {
            Scheme::Loop => 4 * face + c,
            _ => r.topology(l).face_offsets()[face] as usize + c,
        };
    }
    let t = r.topology(levels);
    let rule = r.vertex_rules(levels)[v];
    if rule == subd_schemes::Rule::Corner
        && let Some((du, dv)) = corner_sector_tangents(t, v, face, &points, scheme)
    {
        return Ok(SurfacePoint {
            position: row(&table.position),
            du,
            dv,
            ..SurfacePoint::default()
        });
    }
    let side = crate::limit_masks::table::crease_side_mask(t, v, rule, scheme, face);
    Ok(match side {
        Some(m) => SurfacePoint {
            position: row(&table.position),
            du: crate::limit_masks::table::apply_ring(t, v, &m.tangent1, &points),
            dv: crate::limit_masks::table::apply_ring(t, v, &m.tangent2, &points),
            ..SurfacePoint::default()
        },
        None => SurfacePoint {
            position: row(&table.position),
            du: row(&table.tangent1),
            dv: row(&table.tangent2),
            ..SurfacePoint::default()
        },
    })
}

/// The limit tangents at corner vertex `v` on face `f`'s side: along the two sharp edges
/// (infinitely sharp or boundary) that bound the sector of faces around `v` holding `f`,
/// oriented so that their cross product is `f`'s normal. A sharp edge's points stay its
/// midpoints at every level, so the limit curve leaves the corner towards the edge's other
/// end. `None` where `f`'s sector is not bounded by sharp edges on both sides (a corner
/// made by vertex sharpness alone) or `v` is not manifold: the vertex's own masks apply.
///
/// The vertex's corner mask takes the tangents of its first sector for every face, which
/// is the limit's only where the corner has one sector (OpenSubdiv's `Limit` convention).
fn corner_sector_tangents(
    t: &Topology,
    v: usize,
    f: usize,
    points: &[DVec3],
    scheme: &Scheme,
) -> Option<(DVec3, DVec3)> {
    let (ve, vf) = (t.vertex_edges(v), t.vertex_faces(v));
    if t.is_non_manifold_vertex(v) || !(ve.len() == vf.len() || ve.len() == vf.len() + 1) {
        return None;
    }
    let sharp = |e: u32| {
        let e = e as usize;
        t.is_boundary_edge(e) || subd_mesh::tags::is_infinite(t.edge_sharpness(e))
    };
    if ve.iter().filter(|&&e| sharp(e)).count() <= 2 {
        return None;
    }
    // Face k lies between edges k and k + 1 (cyclic around an interior vertex).
    let k = vf.iter().position(|&g| g as usize == f)?;
    let ne = ve.len();
    let before = (0..ne).map(|i| (k + ne - i) % ne).find(|&i| sharp(ve[i]))?;
    let after = (1..=ne).map(|i| (k + i) % ne).find(|&i| sharp(ve[i]))?;
    let scale = if *scheme == Scheme::Loop { 3.0 } else { 1.0 };
    let toward = |e: u32| {
        let [a, b] = t.edge_vertices(e as usize);
        let other = if a as usize == v { b } else { a };
        scale * (points[other as usize] - points[v])
    };
    let (ta, tb) = (toward(ve[before]), toward(ve[after]));
    // Orientation from the face itself: its corner at v, from the previous vertex to the
    // next.
    let fv = t.face_vertices(f);
    let c = fv.iter().position(|&x| x as usize == v)?;
    let next = points[fv[(c + 1) % fv.len()] as usize] - points[v];
    let prev = points[fv[(c + fv.len() - 1) % fv.len()] as usize] - points[v];
    Some(if ta.cross(tb).dot(next.cross(prev)) >= 0.0 {
        (ta, tb)
    } else {
        (tb, ta)
    })
}

/// The child of face `f` of `t` (level 0 of a one-level refinement) that holds (u, v), the
/// parameters there and the scale of the parameter map.
fn child_at(t: &Topology, scheme: &Scheme, f: usize, u: f64, v: f64) -> (usize, f64, f64, f64) {
    if *scheme == Scheme::Loop {
        let (j, s, tt, k) = crate::evaluation::child_param::tri_child(u, v.min(1.0 - u));
        (4 * f + j, s, tt, k)
    } else {
        let (j, s, tt) = crate::evaluation::child_param::quadrant(u, v);
        (t.face_offsets()[f] as usize + j, s, tt, 2.0)
    }
}

/// The limit surface at (u, v) of quad or triangle `f` of `t` (positions `points`), by
/// local refinement until the child face holding the point is a known patch. `options` are
/// the mesh's; `t` is refinement level `level` (boundaries and holes in its tags) with
/// vertex rules `rules`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn evaluate(
    t: &Topology,
    rules: &[Rule],
    level: usize,
    points: &[DVec3],
    f: usize,
    scheme: &Scheme,
    options: &Options,
    u: f64,
    v: f64,
) -> Result<SurfacePoint, LimitError> {
    inline(|| {
        let pick = |ids: &[u32]| ids.iter().map(|&v| points[v as usize]).collect::<Vec<_>>();
        let start = cut_out(t, rules, pick, f)?;
        let ending = descend(start, level, scheme, options, u, v)?;
        ending.value(&ending.piece().points, scheme, f)
    })
}

/// The options of a local descent: boundary edges are already infinitely sharp and holes
/// already tagged; the cut's artificial boundary must not turn faces into holes.
fn descent_options(options: &Options) -> Options {
    Options {
        boundary_interpolation: BoundaryInterpolation::EdgeOnly,
        ..*options
    }
}

/// The surface at `(u, v)` of `face` of a piece (its topology and rules), a known patch, for
/// positions `pts` of its vertices, with derivatives scaled by `scale` (`f` names the
/// starting face in errors).
fn patch_value(
    (topology, rules, face): (&Topology, &[Rule], usize),
    pts: &[DVec3],
    scheme: &Scheme,
    (u, v, scale): (f64, f64, f64),
    f: usize,
) -> Result<SurfacePoint, LimitError> {
    crate::evaluation::piece::direct_evaluation(topology, rules, pts, face, scheme, u, v)?
        .map(|p| p.scaled(scale))
        .ok_or(LimitError::Unsupported {
            face: f,
            reason: "local refinement ended off a patch",
        })
}

/// [`evaluate`] as weights: the limit at (u, v) of face `f` of `t` (level `level` of a
/// refinement) as (vertex of `t`,
/// weights of position, ∂u, ∂v, ∂uu, ∂uv, ∂vv) pairs, from one descent that carries each
/// vertex's weights over the first piece's vertices.
#[allow(clippy::too_many_arguments)]
pub(crate) fn stencil(
    t: &Topology,
    rules: &[Rule],
    level: usize,
    f: usize,
    scheme: &Scheme,
    options: &Options,
    u: f64,
    v: f64,
) -> Result<Vec<(u32, [f64; 6])>, LimitError> {
    inline(|| {
        let mut sources = Vec::new();
        let pick = |ids: &[u32]| {
            sources = ids.to_vec();
            Weights {
                rows: (0..ids.len() as u32).map(|i| vec![(i, 1.0)]).collect(),
            }
        };
        let start = cut_out(t, rules, pick, f)?;
        let ending = descend(start, level, scheme, options, u, v)?;
        let nb = ending.piece();
        // The final piece's weights over its own support, one unit-vector evaluation per
        // three vertices, then carried back to the sources through the weights.
        let support = crate::evaluation::support::face_support(&nb.topology, nb.face);
        let mut buf = Vec::new();
        let local = crate::evaluation::support::linear_weights(
            &mut buf,
            nb.topology.num_vertices(),
            &support,
            |pts| ending.value(pts, scheme, f),
        )?;
        let mut acc = vec![[0.0f64; 6]; sources.len()];
        for (v, w) in local {
            for &(src, x) in &nb.points.rows[v as usize] {
                for k in 0..6 {
                    acc[src as usize][k] += w[k] * x;
                }
            }
        }
        let out = sources.iter().copied().zip(acc).collect();
        Ok(out)
    })
}

/// Where the local descent stops: on a known patch (with the point's parameters there and
/// the scale of the parameter map), or at a corner of the face whose limit is taken.
enum Ending<P> {
    Patch {
        nb: Neighbourhood<P>,
        u: f64,
        v: f64,
        scale: f64,
    },
    Corner {
        nb: Neighbourhood<P>,
        corner: usize,
        options: Options,
    },
}

impl<P> Ending<P> {
    /// The piece the descent stopped in.
    fn piece(&self) -> &Neighbourhood<P> {
        match self {
            Ending::Patch { nb, .. } | Ending::Corner { nb, .. } => nb,
        }
    }

    /// The surface point there for positions `pts` of the piece's vertices (`f` names the
    /// face the descent started from in errors).
    fn value(&self, pts: &[DVec3], scheme: &Scheme, f: usize) -> Result<SurfacePoint, LimitError> {
        match self {
            Ending::Patch { nb, u, v, scale } => {
                let piece = (&nb.topology, &nb.rules[..], nb.face);
                patch_value(piece, pts, scheme, (*u, *v, *scale), f)
            }
            Ending::Corner {
                nb,
                corner,
                options,
            } => corner_limit(nb, pts, scheme, options, *corner),
        }
    }
}

/// Refines `nb` one level at a time, following (u, v) into the child face that holds it,
/// until that child is a known patch or the point is at (or, after
/// [`MAX_LOCAL_LEVELS`], indistinguishable from) a corner.
fn descend<P: Carried>(
    mut nb: Neighbourhood<P>,
    level: usize,
    scheme: &Scheme,
    options: &Options,
    u: f64,
    v: f64,
) -> Result<Ending<P>, LimitError> {
    let options = descent_options(options);
    let (mut u, mut v, mut scale) = (u, v, 1.0);
    for depth in 0..MAX_LOCAL_LEVELS {
        let r = nb.refine(scheme, &options, 1)?;
        let (t0, rules0) = (r.topology(0), r.vertex_rules(0));
        if crate::evaluation::piece::is_direct(t0, rules0, nb.face, scheme)? {
            return Ok(Ending::Patch { nb, u, v, scale });
        }
        // At a corner: once the other corners are refined away (two levels) and nothing
        // semi-sharp is left, the corner vertex is what keeps the face irregular for ever.
        if let Some(corner) = exact_corner(scheme, u, v)
            && depth >= 2.max(CORNER_LEVEL.saturating_sub(level))
            && crate::levels_for_exact_limit(&nb.topology, scheme).0 == 0
        {
            return Ok(Ending::Corner {
                nb,
                corner,
                options,
            });
        }
        let (child, s, tt, k) = child_at(t0, scheme, nb.face, u, v);
        let next = cut_out(
            r.topology(1),
            r.vertex_rules(1),
            |ids| nb.points.refined_pick(&r, ids),
            child,
        )?;
        nb = next;
        (u, v, scale) = (s, tt, scale * k);
    }
    let corner = nearest_corner(scheme, u, v);
    Ok(Ending::Corner {
        nb,
        corner,
        options,
    })
}

/// Runs `work` inline: the pieces are a few dozen faces, and the refinement's parallel loops
/// would spend far more waking the global pool's threads than computing. One single-thread
/// pool per calling thread runs them.
fn inline<R: Send>(work: impl FnOnce() -> R + Send) -> R {
    thread_local! {
        static INLINE: Option<rayon::ThreadPool> =
            rayon::ThreadPoolBuilder::new().num_threads(1).build().ok();
    }
    // Inside a pool's worker (a caller evaluating in parallel) the work runs where it is:
    // installing into another pool would let the blocked worker steal its own pool's next
    // evaluation meanwhile, nesting evaluations on one stack until it overflows.
    if rayon::current_thread_index().is_some() {
        return work();
    }
    INLINE.with(|pool| match pool {
        Some(pool) => pool.install(work),
        None => work(),
    })
}

/// The limits [`crate::base_limit`] gives, for meshes too large to refine whole until
/// semi-sharp features have decayed: only the vertices those features reach (a semi-sharp
/// edge or vertex on a face around them) are refined that far, one level at a time, each
/// level cut down to their 2-rings (so the work grows with the number of those vertices, not
/// with 4^levels); every other vertex takes its limit mask at once (after one global level
/// for Catmull-Clark non-quads).
///
/// # Errors
/// As [`crate::base_limit`]; [`LimitError::TooDeep`] when a cut would pass a quarter of
/// [`crate::MAX_DECAY_FACE_VERTICES`] face-vertices.
pub fn base_limit(
    topology: &Topology,
    scheme: &Scheme,
    options: &Options,
) -> Result<LimitStencilTable, LimitError> {
    let quads = *scheme != Scheme::CatmullClark
        || (0..topology.num_faces()).all(|f| topology.face_size(f) == 4);
    let pre = usize::from(!quads);
    let r = Refinement::new(topology, scheme.clone(), options, pre)?;
    base_limit_after(&r, options)
}

/// [`base_limit`] continued from the last level of `r` (0 or 1 levels: Catmull-Clark's
/// first level for non-quads, or phase 1 of the two-phase scheme), composed back to `r`'s
/// base.
pub(crate) fn base_limit_after(
    r: &Refinement,
    options: &Options,
) -> Result<LimitStencilTable, LimitError> {
    use subd_mesh::tags::is_semi_sharp;
    let scheme = r.scheme();
    let pre = r.num_levels();
    let (t, rules) = (r.topology(pre), r.vertex_rules(pre));
    let (decay, sharpness) = crate::levels_for_exact_limit(t, scheme);
    let direct = LimitStencilTable::at_level(r, pre)?;
    let nv = t.num_vertices();
    let mut affected = vec![false; nv];
    for f in 0..t.num_faces() {
        let semi = t
            .face_edges(f)
            .iter()
            .any(|&e| is_semi_sharp(t.edge_sharpness(e as usize)))
            || t.face_vertices(f)
                .iter()
                .any(|&v| is_semi_sharp(t.vertex_sharpness(v as usize)));
        if semi {
            for &v in t.face_vertices(f) {
                affected[v as usize] = true;
            }
        }
    }
    let options = Options {
        boundary_interpolation: BoundaryInterpolation::EdgeOnly,
        ..*options
    };
    // Refine one level at a time, each time cutting out only the 2-rings of the affected
    // vertices (a vertex keeps its index at every level, and its limit depends on the faces
    // around it only), and carry the cut vertices' stencils over `t`'s vertices along.
    let targets: Vec<u32> = (0..nv as u32).filter(|&v| affected[v as usize]).collect();
    let mut cut = Cut::new(t, rules, &faces_within_two_rings(t, &targets))?;
    let mut rows = select_rows(&StencilTable::identity(nv), &cut.vertices);
    let mut targets_in_cut = positions_in(&cut.vertices, &targets);
    for _ in 0..decay {
        if cut.topology.num_face_vertices() > crate::MAX_DECAY_FACE_VERTICES / 4 {
            return Err(LimitError::TooDeep {
                sharpness,
                levels: decay,
                max: crate::MAX_DECAY_FACE_VERTICES,
            });
        }
        let rc = Refinement::from_prepared(cut.topology, cut.rules, scheme.clone(), &options, 1)?;
        let child_rows = rows.then(rc.stencils(1));
        let next = Cut::new(
            rc.topology(1),
            rc.vertex_rules(1),
            &faces_within_two_rings(rc.topology(1), &targets_in_cut),
        )?;
        rows = select_rows(&child_rows, &next.vertices);
        targets_in_cut = positions_in(&next.vertices, &targets_in_cut);
        cut = next;
    }
    let rc = Refinement::from_prepared(cut.topology, cut.rules, scheme.clone(), &options, 0)?;
    let cut_rows = LimitStencilTable::at_level(&rc, 0)?.after(&rows);
    let mut local = vec![u32::MAX; nv];
    for (&v, &i) in targets.iter().zip(&targets_in_cut) {
        local[v as usize] = i;
    }
    let merge = |direct: &StencilTable, cut_table: &StencilTable| {
        csr(
            nv,
            (0..nv).map(|v| {
                if affected[v] {
                    cut_table.row(local[v] as usize)
                } else {
                    direct.row(v)
                }
            }),
        )
    };
    let mut table = LimitStencilTable {
        position: merge(&direct.position, &cut_rows.position),
        tangent1: merge(&direct.tangent1, &cut_rows.tangent1),
        tangent2: merge(&direct.tangent2, &cut_rows.tangent2),
        without_tangents: Vec::new(),
    };
    for l in (1..=pre).rev() {
        table = table.after(r.stencils(l));
    }
    let base = r.num_vertices(0);
    Ok(LimitStencilTable {
        position: crate::first_rows(&table.position, base),
        tangent1: crate::first_rows(&table.tangent1, base),
        tangent2: crate::first_rows(&table.tangent2, base),
        without_tangents: Vec::new(),
    })
}

/// The rows `which` of `table`, in that order.
fn select_rows(table: &StencilTable, which: &[u32]) -> StencilTable {
    csr(
        table.num_sources(),
        which.iter().map(|&r| table.row(r as usize)),
    )
}

/// A stencil table over `num_sources` sources from its rows.
fn csr<'a>(num_sources: usize, rows: impl Iterator<Item = (&'a [u32], &'a [f64])>) -> StencilTable {
    let mut offsets = vec![0u32];
    let (mut indices, mut weights) = (Vec::new(), Vec::new());
    for (idx, w) in rows {
        indices.extend_from_slice(idx);
        weights.extend_from_slice(w);
        offsets.push(indices.len() as u32);
    }
    StencilTable::from_csr(num_sources, offsets, indices, weights)
}

/// The position in `list` of each of `items` (every item is in the list).
fn positions_in(list: &[u32], items: &[u32]) -> Vec<u32> {
    let map: std::collections::HashMap<u32, u32> = list
        .iter()
        .enumerate()
        .map(|(i, &v)| (v, i as u32))
        .collect();
    items.iter().map(|v| map[v]).collect()
}
