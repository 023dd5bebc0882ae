//! The limit of every vertex of a uniformly refined level, read off the level above it: the
//! rings of the children of a level are closed forms of that level's topology (OpenSubdiv's
//! child numbering: vertex children first, then face children for Catmull-Clark, then edge
//! children), so the last level's limit masks apply without building the last level's
//! topology, the largest structure of a refinement.
//!
//! * A vertex child takes its parent's limit mask (a vertex's case — smooth, crease, corner,
//!   dart, valence — is its parent's once no semi-sharp feature is left), over the children
//!   of the parent's edges and faces.
//! * A face child is a smooth vertex whose valence is its parent's size: ring the children
//!   of the face's edges, face terms the children of its corners.
//! * An edge child is a regular smooth vertex (valence 4 for Catmull-Clark, 6 for Loop), or,
//!   on a boundary or infinitely sharp edge, a regular crease vertex.
//!
//! Rings are counter-clockwise as [`crate::masks`] needs: around a child on the edge `a → b`
//! of a face `f` (so `f` lies to its left), `b`'s child comes first, then the children
//! inside `f`, then `a`'s child, then the other face's.

use glam::DVec3;
use subd_mesh::Topology;
use subd_schemes::{Refinement, Scheme};

use crate::limit_masks::masks::{self, LimitMask};
use crate::limit_masks::table::{LevelMasks, Ring, limit_by_vertex};
use crate::{LimitError, LimitPoints, Tangents, levels_for_exact_limit};

/// Whether [`child_level_limit`] covers level `level` of `refinement`: Catmull-Clark or Loop
/// at that level and the level above (so not the two-phase scheme's first level), nothing
/// semi-sharp left above it, every face of the level above a quad for Catmull-Clark, no
/// non-manifold edge or vertex.
pub(crate) fn applies(refinement: &Refinement, level: usize) -> bool {
    if level == 0 {
        return false;
    }
    let (above, here) = (
        refinement.scheme().at_level(level - 1),
        refinement.scheme().at_level(level),
    );
    if above != here || !matches!(here, Scheme::CatmullClark | Scheme::Loop) {
        return false;
    }
    let t = refinement.topology(level - 1);
    levels_for_exact_limit(t, &here).0 == 0
        && (0..t.num_edges()).all(|e| !t.is_non_manifold_edge(e))
        && (0..t.num_vertices()).all(|v| !t.is_non_manifold_vertex(v))
}

/// The masks of the children that are not vertex children, built once.
struct ChildMasks {
    /// Face child of a face of size `n`, at index `n` (Catmull-Clark).
    face: Vec<LimitMask>,
    smooth_edge: LimitMask,
    boundary_edge: LimitMask,
    sharp_edge: LimitMask,
}

impl ChildMasks {
    fn new(scheme: &Scheme, t: &Topology) -> ChildMasks {
        if *scheme == Scheme::Loop {
            return ChildMasks {
                face: Vec::new(),
                smooth_edge: masks::loop_smooth(6),
                boundary_edge: masks::loop_crease(4, (0, 3)),
                sharp_edge: masks::loop_crease(6, (0, 3)),
            };
        }
        let largest = (0..t.num_faces())
            .map(|f| t.face_size(f))
            .max()
            .unwrap_or(4);
        ChildMasks {
            face: (0..=largest)
                .map(|n| {
                    if n >= 3 {
                        masks::catmark_smooth(n)
                    } else {
                        LimitMask::default()
                    }
                })
                .collect(),
            smooth_edge: masks::catmark_smooth(4),
            boundary_edge: masks::catmark_crease(3, 2, (0, 2)),
            sharp_edge: masks::catmark_crease(4, 4, (0, 2)),
        }
    }
}

/// Where the children of the level above sit in the level: vertex `v`'s child is `v`, face
/// `f`'s `first_face + f` (Catmull-Clark), edge `e`'s `first_edge + e`.
struct Numbering {
    first_face: u32,
    first_edge: u32,
}

/// One side of an edge: the face, the edge's tail and head as the face runs along it, and
/// the face's edges before and after it.
struct Side {
    face: u32,
    tail: u32,
    head: u32,
    prev: u32,
    next: u32,
}

fn side(t: &Topology, e: usize, f: u32) -> Side {
    let (fe, fv) = (t.face_edges(f as usize), t.face_vertices(f as usize));
    let n = fe.len();
    let j = fe.iter().position(|&x| x as usize == e).unwrap_or(0);
    Side {
        face: f,
        tail: fv[j],
        head: fv[(j + 1) % n],
        prev: fe[(j + n - 1) % n],
        next: fe[(j + 1) % n],
    }
}

/// The limit of every vertex of `level` from `points`, that level's points, through the
/// topology of the level above ([`applies`] must hold).
pub(crate) fn child_level_limit(
    refinement: &Refinement,
    level: usize,
    points: &[DVec3],
    tangents: Tangents,
) -> Result<LimitPoints, LimitError> {
    let children = ChildLimit::new(refinement, level)?;
    assert_eq!(
        points.len(),
        children.num_vertices(),
        "one point per vertex of the level"
    );
    Ok(limit_by_vertex(points.len(), tangents, |ring, v| {
        children.limit(ring, v, points)
    }))
}

/// The limit masks of the vertices of a level, one vertex at a time, read off the level
/// above ([`applies`] must hold): for callers that visit the vertices in an order of their
/// own, as tessellation does.
pub(crate) struct ChildLimit<'a> {
    above: &'a Topology,
    parents: LevelMasks<'a>,
    children: ChildMasks,
    at: Numbering,
    loop_scheme: bool,
}

impl<'a> ChildLimit<'a> {
    pub(crate) fn new(refinement: &'a Refinement, level: usize) -> Result<Self, LimitError> {
        let scheme = refinement.scheme().at_level(level);
        let above = refinement.topology(level - 1);
        let loop_scheme = scheme == Scheme::Loop;
        let (nv, nf) = (above.num_vertices() as u32, above.num_faces() as u32);
        Ok(ChildLimit {
            above,
            parents: LevelMasks::new(refinement, level - 1)?,
            children: ChildMasks::new(&scheme, above),
            at: Numbering {
                first_face: nv,
                first_edge: if loop_scheme { nv } else { nv + nf },
            },
            loop_scheme,
        })
    }

    /// Vertices of the level.
    pub(crate) fn num_vertices(&self) -> usize {
        self.at.first_edge as usize + self.above.num_edges()
    }

    /// Vertex `v`'s (position, tangents, normal) from the level's `points`, with a scratch
    /// [`Ring`].
    pub(crate) fn limit(&self, ring: &mut Ring, v: usize, points: &[DVec3]) -> [DVec3; 4] {
        let (t, at) = (self.above, &self.at);
        let (v32, nv) = (v as u32, t.num_vertices() as u32);
        if v32 < nv {
            vertex_child(t, at, self.loop_scheme, v, ring);
            ring.limit(self.parents.of(v), points)
        } else if v32 < at.first_edge {
            let f = (v32 - nv) as usize;
            face_child(t, at, f, ring);
            ring.limit(&self.children.face[t.face_size(f)], points)
        } else {
            let e = (v32 - at.first_edge) as usize;
            let mask = edge_child(t, at, &self.children, self.loop_scheme, e, ring);
            ring.limit(mask, points)
        }
    }
}

/// The ring of vertex `v`'s child: its parent's ring with every edge and face replaced by
/// its child (in a face's child at `v`, the corner opposite `v`'s child is the face's child).
fn vertex_child(t: &Topology, at: &Numbering, loop_scheme: bool, v: usize, ring: &mut Ring) {
    let faces = (!loop_scheme).then(|| t.vertex_faces(v).iter().map(|&f| at.first_face + f));
    let edges = t.vertex_edges(v).iter().map(|&e| at.first_edge + e);
    ring.set(faces.into_iter().flatten(), edges, v as u32);
}

/// The ring of face `f`'s child: the children of the face's edges in face order, and
/// between edges `j` and `j + 1` the child of corner `j + 1`.
fn face_child(t: &Topology, at: &Numbering, f: usize, ring: &mut Ring) {
    let corners = t.face_vertices(f);
    let n = corners.len();
    let faces = (0..n).map(|j| corners[(j + 1) % n]);
    let edges = t.face_edges(f).iter().map(|&e| at.first_edge + e);
    ring.set(faces, edges, at.first_face + f as u32);
}

/// The ring of edge `e`'s child and its mask.
fn edge_child<'m>(
    t: &Topology,
    at: &Numbering,
    children: &'m ChildMasks,
    loop_scheme: bool,
    e: usize,
    ring: &mut Ring,
) -> &'m LimitMask {
    let centre = at.first_edge + e as u32;
    let ef = t.edge_faces(e);
    let first = side(t, e, ef[0]);
    let second = ef.get(1).map(|&f| side(t, e, f));
    let child = |x: u32| at.first_edge + x;
    // Fixed arrays: this runs once per edge child, and allocates nothing.
    let sides = 1 + usize::from(second.is_some());
    if loop_scheme {
        let s = second.as_ref().unwrap_or(&first);
        let edges = [
            first.head,
            child(first.next),
            child(first.prev),
            first.tail,
            child(s.next),
            child(s.prev),
        ];
        ring.set([], edges[..2 + 2 * sides].iter().copied(), centre);
    } else {
        let s = second.as_ref().unwrap_or(&first);
        let edges = [
            first.head,
            at.first_face + first.face,
            first.tail,
            at.first_face + s.face,
        ];
        let faces = [
            child(first.next),
            child(first.prev),
            child(s.next),
            child(s.prev),
        ];
        ring.set(
            faces[..2 * sides].iter().copied(),
            edges[..sides + 2].iter().copied(),
            centre,
        );
    }
    match second {
        None => &children.boundary_edge,
        Some(_) if t.edge_sharpness(e) > 0.0 => &children.sharp_edge,
        Some(_) => &children.smooth_edge,
    }
}
