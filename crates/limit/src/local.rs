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
use subd_mesh::tags::SHARPNESS_INFINITE;
use subd_mesh::{BoundaryInterpolation, Topology, TopologyBuilder};
use subd_schemes::{Options, Refinement, Rule, Scheme};

use crate::LimitError;
use crate::patch::SurfacePoint;

/// Levels of local refinement before a point that still is not on a known patch is taken
/// as its face's nearest corner (the distance is then below `2^-MAX_LOCAL_LEVELS` of the
/// starting face's size, under the resolution of `f64` parameters). Only points closer than
/// that to an irregular vertex, but not exactly at it, get there.
pub const MAX_LOCAL_LEVELS: usize = 60;

/// A piece of a refined level around one face.
pub(crate) struct Neighbourhood {
    topology: Topology,
    rules: Vec<Rule>,
    points: Vec<DVec3>,
    face: usize,
}

impl Neighbourhood {
    /// One uniform step of the piece, continuing the refinement it was cut from.
    fn refine(
        &self,
        scheme: Scheme,
        options: &Options,
        levels: usize,
    ) -> Result<Refinement, LimitError> {
        Ok(Refinement::from_prepared(
            self.topology.clone(),
            self.rules.clone(),
            scheme,
            options,
            levels,
        )?)
    }
}

/// Faces within two vertex-rings of face `f` of a prepared level `t` (f first), their
/// vertices renumbered by first appearance, with the sharpness and hole tags of `t` and the
/// vertex rules `rules`. The cut's outer boundary is made infinitely sharp and the rules of
/// the vertices on it re-derived from their tags (they only feed children that are not used).
fn cut_out(
    t: &Topology,
    rules: &[Rule],
    points: &[DVec3],
    f: usize,
) -> Result<Neighbourhood, LimitError> {
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
    let mut vertex_map: Vec<(u32, u32)> = Vec::new();
    let mut sizes = Vec::with_capacity(faces.len());
    let mut face_vertices = Vec::new();
    for &g in &faces {
        let fv = t.face_vertices(g as usize);
        sizes.push(fv.len() as u32);
        for &v in fv {
            let local = match vertex_map.iter().find(|&&(old, _)| old == v) {
                Some(&(_, new)) => new,
                None => {
                    let new = vertex_map.len() as u32;
                    vertex_map.push((v, new));
                    new
                }
            };
            face_vertices.push(local);
        }
    }
    let mut sub = TopologyBuilder::new(vertex_map.len())
        .accept_inconsistent_orientation(true)
        .build(&sizes, &face_vertices)
        .map_err(|e| LimitError::Analysis(format!("local neighbourhood of face {f}: {e}")))?;
    for (i, &g) in faces.iter().enumerate() {
        let g = g as usize;
        sub.set_hole(i, t.is_hole(g));
        let sub_edges = sub.face_edges(i).to_vec();
        for (&se, &ge) in sub_edges.iter().zip(t.face_edges(g)) {
            sub.set_edge_sharpness(se as usize, t.edge_sharpness(ge as usize));
        }
    }
    for &(old, new) in &vertex_map {
        sub.set_vertex_sharpness(new as usize, t.vertex_sharpness(old as usize));
    }
    for e in 0..sub.num_edges() {
        if sub.is_boundary_edge(e) {
            sub.set_edge_sharpness(e, SHARPNESS_INFINITE);
        }
    }
    // Rebuilding from face lists merges repeated non-manifold edge instances that the
    // refined level keeps apart; such a cut would refine differently, so it is refused.
    let mut faithful = true;
    let sub_rules: Vec<Rule> = vertex_map
        .iter()
        .map(|&(old, new)| {
            let complete = t
                .vertex_faces(old as usize)
                .iter()
                .all(|g| faces.contains(g));
            if complete {
                let (o, n) = (old as usize, new as usize);
                if sub.vertex_edges(n).len() != t.vertex_edges(o).len()
                    || sub.is_non_manifold_vertex(n) != t.is_non_manifold_vertex(o)
                {
                    faithful = false;
                }
                rules[o]
            } else {
                let ve = sub.vertex_edges(new as usize);
                let sharp = ve
                    .iter()
                    .filter(|&&e| sub.edge_sharpness(e as usize) > 0.0)
                    .count();
                Rule::determine(sub.vertex_sharpness(new as usize), sharp)
            }
        })
        .collect();
    if !faithful {
        return Err(LimitError::Unsupported {
            face: f,
            reason: "a non-manifold configuration that a local cut does not reproduce",
        });
    }
    let points = vertex_map
        .iter()
        .map(|&(old, _)| points[old as usize])
        .collect();
    Ok(Neighbourhood {
        topology: sub,
        rules: sub_rules,
        points,
        face: 0,
    })
}

/// The corner of the face that (u, v) is exactly at, if any (quads: (0,0), (1,0), (1,1),
/// (0,1); triangles: (0,0), (1,0), (0,1)).
fn exact_corner(scheme: Scheme, u: f64, v: f64) -> Option<usize> {
    match (scheme, u, v) {
        (_, 0.0, 0.0) => Some(0),
        (_, 1.0, 0.0) => Some(1),
        (Scheme::Loop, 0.0, 1.0) => Some(2),
        (Scheme::Loop, _, _) => None,
        (_, 1.0, 1.0) => Some(2),
        (_, 0.0, 1.0) => Some(3),
        _ => None,
    }
}

/// The corner nearest to (u, v).
fn nearest_corner(scheme: Scheme, u: f64, v: f64) -> usize {
    if scheme == Scheme::Loop {
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
fn corner_limit(
    nb: &Neighbourhood,
    scheme: Scheme,
    options: &Options,
    c: usize,
) -> Result<SurfacePoint, LimitError> {
    let v = nb.topology.face_vertices(nb.face)[c] as usize;
    // Semi-sharp features decay first (a vertex keeps its index at every level).
    let levels = crate::levels_for_exact_limit(&nb.topology, scheme).0;
    let r = nb.refine(scheme, options, levels)?;
    let table = crate::LimitStencilTable::at_level(&r, levels)?;
    let points = r.refine_points(&nb.points).pop().expect("the last level");
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
    let side = crate::table::crease_side_mask(t, v, r.vertex_rules(levels)[v], scheme, face);
    Ok(match side {
        Some(m) => SurfacePoint {
            position: row(&table.position),
            du: crate::table::apply_ring(t, v, &m.tangent1, &points),
            dv: crate::table::apply_ring(t, v, &m.tangent2, &points),
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

/// The child of face `f` of `t` (level 0 of a one-level refinement) that holds (u, v), the
/// parameters there and the scale of the parameter map.
fn child_at(t: &Topology, scheme: Scheme, f: usize, u: f64, v: f64) -> (usize, f64, f64, f64) {
    if scheme == Scheme::Loop {
        let (j, s, tt, k) = crate::eval::tri_child(u, v.min(1.0 - u));
        (4 * f + j, s, tt, k)
    } else {
        let (j, s, tt) = crate::eval::quadrant(u, v);
        (t.face_offsets()[f] as usize + j, s, tt, 2.0)
    }
}

/// The limit surface at (u, v) of quad or triangle `f` of `t` (positions `points`), by
/// local refinement until the child face holding the point is a known patch. `options` are
/// the mesh's; `t` is a prepared level (boundaries and holes in its tags) with vertex rules
/// `rules`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn evaluate(
    t: &Topology,
    rules: &[Rule],
    points: &[DVec3],
    f: usize,
    scheme: Scheme,
    options: &Options,
    u: f64,
    v: f64,
) -> Result<SurfacePoint, LimitError> {
    // The pieces are a few dozen faces: the refinement's parallel loops would spend far more
    // waking the global pool's threads than computing. One single-thread pool per calling
    // thread runs them inline.
    thread_local! {
        static INLINE: Option<rayon::ThreadPool> =
            rayon::ThreadPoolBuilder::new().num_threads(1).build().ok();
    }
    INLINE.with(|pool| match pool {
        Some(pool) => pool.install(|| descend(t, rules, points, f, scheme, options, u, v)),
        None => descend(t, rules, points, f, scheme, options, u, v),
    })
}

/// [`evaluate`]'s descent.
#[allow(clippy::too_many_arguments)]
fn descend(
    t: &Topology,
    rules: &[Rule],
    points: &[DVec3],
    f: usize,
    scheme: Scheme,
    options: &Options,
    u: f64,
    v: f64,
) -> Result<SurfacePoint, LimitError> {
    // Boundary edges are already infinitely sharp and holes already tagged; the cut's
    // artificial boundary must not turn faces into holes.
    let options = Options {
        boundary_interpolation: BoundaryInterpolation::EdgeOnly,
        ..*options
    };
    let mut nb = cut_out(t, rules, points, f)?;
    let (mut u, mut v, mut scale) = (u, v, 1.0);
    for depth in 0..MAX_LOCAL_LEVELS {
        let r = nb.refine(scheme, &options, 1)?;
        let (t0, rules0) = (r.topology(0), r.vertex_rules(0));
        if let Some(p) =
            crate::eval::direct_evaluation(t0, rules0, &nb.points, nb.face, scheme, u, v)?
        {
            return Ok(p.scaled(scale));
        }
        // At a corner: once the other corners are refined away (two levels) and nothing
        // semi-sharp is left, the corner vertex is what keeps the face irregular for ever.
        if let Some(c) = exact_corner(scheme, u, v)
            && depth >= 2
            && crate::levels_for_exact_limit(&nb.topology, scheme).0 == 0
        {
            return corner_limit(&nb, scheme, &options, c);
        }
        let child_points = r.refine_points(&nb.points).pop().expect("one level");
        let (child, s, tt, k) = child_at(t0, scheme, nb.face, u, v);
        nb = cut_out(r.topology(1), r.vertex_rules(1), &child_points, child)?;
        (u, v, scale) = (s, tt, scale * k);
    }
    let c = nearest_corner(scheme, u, v);
    corner_limit(&nb, scheme, &options, c)
}
