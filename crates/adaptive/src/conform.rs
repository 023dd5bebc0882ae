//! Closing the leaves of the hierarchy into one conforming mesh.
//!
//! A leaf is a face that exists and is not refined. One of its edges is *split* when a face
//! across it is refined: the finer side has the edge's child (edge point) there. A leaf with
//! split edges is replaced by a transition pattern that uses its corners and those edge
//! points only, so no new vertex is made and every vertex stays a vertex of uniform
//! refinement:
//!
//! * Loop (Sun et al. 2012 §2.3): one split edge — bisect the triangle from the edge point to the
//!   opposite corner; two — a triangle at the corner between them and the remaining quad
//!   cut along the diagonal that gives the larger smallest angle. (Three split edges are
//!   refined by the closure.)
//! * Catmull-Clark quads: one split edge — a triangle and a quad; two opposite — two quads;
//!   two adjacent — a corner triangle, a quad and a triangle; where two cuts are possible,
//!   the one with the larger smallest angle. (Three or four split edges, and any split edge
//!   on a base face that is not a quad, are refined by the closure.)
//!
//! Transition faces are output only: the hierarchy refines their parent leaf, never them.
//! Each output vertex takes its finest instance in the hierarchy (a vertex keeps its
//! identity from level to level as the child of itself).

use glam::DVec3;
use subd_schemes::Scheme;

use crate::hierarchy::{AdaptiveRefinement, Positions};
use crate::level::WHOLE_FACE;
use crate::{AdaptiveError, AdaptiveMesh, EdgeOrigin};
use subd_mesh::cut::NONE;

/// A point of a transition pattern: corner `i` of the leaf, or the edge point of its edge `i`
/// (from corner `i` to corner `i + 1`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Point {
    Corner(usize),
    Edge(usize),
}

use Point::{Corner as C, Edge as E};

/// The polygons replacing a leaf of `n` corners whose edges `split` are split, choosing
/// between alternative cuts by the smallest angle (positions from `pos`).
fn pattern(
    scheme: &Scheme,
    n: usize,
    split: &[bool],
    pos: &dyn Fn(Point) -> DVec3,
) -> Vec<Vec<Point>> {
    let k = split.iter().filter(|&&s| s).count();
    if k == 0 {
        return vec![(0..n).map(C).collect()];
    }
    let best = |options: Vec<Vec<Vec<Point>>>| -> Vec<Vec<Point>> {
        let score = |faces: &Vec<Vec<Point>>| {
            faces
                .iter()
                .map(|f| min_angle(&f.iter().map(|&p| pos(p)).collect::<Vec<_>>()))
                .fold(f64::INFINITY, f64::min)
        };
        let mut it = options.into_iter();
        let mut pick = it.next().expect("at least one option");
        let mut pick_score = score(&pick);
        for o in it {
            let s = score(&o);
            if s > pick_score {
                pick = o;
                pick_score = s;
            }
        }
        pick
    };
    let first = |from: usize| (0..n).map(|i| (from + i) % n).find(|&i| split[i]);
    match (scheme, n, k) {
        (Scheme::Loop, 3, 1) => {
            let r = first(0).expect("one split edge");
            let (a, b, c) = (r, (r + 1) % 3, (r + 2) % 3);
            vec![vec![C(a), E(r), C(c)], vec![E(r), C(b), C(c)]]
        }
        (Scheme::Loop, 3, 2) => {
            // Split edges r and r + 1, meeting at corner r + 1.
            let r = (0..3)
                .find(|&i| split[i] && split[(i + 1) % 3])
                .expect("two split edges");
            let (a, b, c) = (r, (r + 1) % 3, (r + 2) % 3);
            let (ea, eb) = (E(r), E(b));
            let corner = vec![ea, C(b), eb];
            best(vec![
                vec![corner.clone(), vec![C(a), ea, eb], vec![C(a), eb, C(c)]],
                vec![corner, vec![C(a), ea, C(c)], vec![ea, eb, C(c)]],
            ])
        }
        (Scheme::CatmullClark | Scheme::Bilinear, 4, 1) => {
            let r = first(0).expect("one split edge");
            let c = |i: usize| C((r + i) % 4);
            best(vec![
                vec![vec![c(0), E(r), c(3)], vec![E(r), c(1), c(2), c(3)]],
                vec![vec![E(r), c(1), c(2)], vec![c(0), E(r), c(2), c(3)]],
            ])
        }
        (Scheme::CatmullClark | Scheme::Bilinear, 4, 2) => {
            if let Some(r) = (0..4).find(|&i| split[i] && split[(i + 2) % 4]) {
                let c = |i: usize| C((r + i) % 4);
                let far = E((r + 2) % 4);
                vec![vec![c(0), E(r), far, c(3)], vec![E(r), c(1), c(2), far]]
            } else {
                let r = (0..4)
                    .find(|&i| split[i] && split[(i + 1) % 4])
                    .expect("adjacent");
                let c = |i: usize| C((r + i) % 4);
                let (ea, eb) = (E(r), E((r + 1) % 4));
                let corner = vec![ea, c(1), eb];
                best(vec![
                    vec![
                        corner.clone(),
                        vec![ea, eb, c(2), c(3)],
                        vec![c(0), ea, c(3)],
                    ],
                    vec![corner, vec![c(0), ea, eb, c(2)], vec![c(0), c(2), c(3)]],
                ])
            }
        }
        _ => unreachable!("the closure refines leaves without a transition pattern"),
    }
}

/// The smallest interior angle of a polygon (radians).
pub(crate) fn min_angle(p: &[DVec3]) -> f64 {
    let n = p.len();
    (0..n)
        .map(|i| {
            let a = (p[(i + n - 1) % n] - p[i]).normalize_or_zero();
            let b = (p[(i + 1) % n] - p[i]).normalize_or_zero();
            a.dot(b).clamp(-1.0, 1.0).acos()
        })
        .fold(f64::INFINITY, f64::min)
}

/// The largest cosine of an interior angle of a polygon (clamped to `[-1, 1]`): the cosine of
/// [`min_angle`], without an `acos` per corner.
pub(crate) fn max_corner_cos(p: &[DVec3]) -> f64 {
    let n = p.len();
    (0..n)
        .map(|i| {
            let a = (p[(i + n - 1) % n] - p[i]).normalize_or_zero();
            let b = (p[(i + 1) % n] - p[i]).normalize_or_zero();
            a.dot(b).clamp(-1.0, 1.0)
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

/// A leaf of the hierarchy and its boundary points.
struct Leaf {
    level: usize,
    face: usize,
    /// Where its corners' and edge points' output vertices start in the flat id arrays.
    first: usize,
    /// Whether any of its edges is split.
    split: bool,
}

/// Output vertices of every leaf's corners and of its edges' edge points (`NONE` for an edge
/// that is not split), leaf after leaf.
struct LeafIds<'a> {
    corners: &'a [u32],
    edge_points: &'a [u32],
}

impl AdaptiveRefinement {
    /// The finest instance of vertex `v` of `level`.
    fn finest(&self, mut level: usize, mut v: usize) -> (usize, usize) {
        loop {
            let c = self.levels[level].vertex_child[v];
            if c == NONE {
                return (level, v);
            }
            level += 1;
            v = c as usize;
        }
    }

    /// The conforming mesh of the leaves, with transition patterns where leaves meet finer
    /// faces, vertices at `positions`.
    ///
    /// # Errors
    /// With [`Positions::Limit`], a limit computation's error.
    pub fn mesh(&self, positions: Positions) -> Result<AdaptiveMesh, AdaptiveError> {
        let depth = self.depth();
        // Output vertex of every finest instance.
        let mut ids: Vec<Vec<u32>> = self
            .levels
            .iter()
            .map(|l| vec![NONE; l.topology.num_vertices()])
            .collect();
        let mut instances: Vec<(usize, usize)> = Vec::new();
        let mut id_of = |level: usize, v: usize| -> u32 {
            let (l, w) = self.finest(level, v);
            if ids[l][w] == NONE {
                ids[l][w] = instances.len() as u32;
                instances.push((l, w));
            }
            ids[l][w]
        };
        let mut leaves = Vec::new();
        let (mut corner_ids, mut edge_ids) = (Vec::new(), Vec::new());
        for (l, lv) in self.levels.iter().enumerate() {
            let t = &lv.topology;
            for f in (0..t.num_faces()).filter(|&f| !lv.refined[f]) {
                let first = corner_ids.len();
                for &v in t.face_vertices(f) {
                    corner_ids.push(id_of(l, v as usize));
                }
                let mut split = false;
                for &e in t.face_edges(f) {
                    let across_refined = l < depth
                        && t.edge_faces(e as usize)
                            .iter()
                            .any(|&g| g as usize != f && lv.refined[g as usize]);
                    edge_ids.push(if across_refined {
                        split = true;
                        let child = lv.edge_child[e as usize];
                        debug_assert_ne!(child, NONE);
                        id_of(l + 1, child as usize)
                    } else {
                        NONE
                    });
                }
                leaves.push(Leaf {
                    level: l,
                    face: f,
                    first,
                    split,
                });
            }
        }

        let (points, normals) = match positions {
            Positions::Refined => (
                instances
                    .iter()
                    .map(|&(l, w)| self.levels[l].points[w])
                    .collect(),
                Vec::new(),
            ),
            Positions::Limit => crate::limit::limit_points(self, &instances)?,
        };

        let mut out = AdaptiveMesh {
            vertex_levels: instances.iter().map(|&(l, _)| l as u8).collect(),
            vertex_uniform: instances
                .iter()
                .map(|&(l, w)| self.levels[l].vertex_key[w])
                .collect(),
            positions: points,
            normals,
            face_offsets: vec![0],
            face_vertices: Vec::new(),
            face_levels: Vec::new(),
            face_uniform: Vec::new(),
            holes: Vec::new(),
            transition: Vec::new(),
            edge_origins: Vec::new(),
            face_domains: Vec::new(),
            corner_params: Vec::new(),
        };
        let ids = LeafIds {
            corners: &corner_ids,
            edge_points: &edge_ids,
        };
        // Sized for the leaves as they are (transition patterns add a little): growing by
        // doubling copied these arrays over and over.
        out.face_offsets.reserve(leaves.len());
        out.face_vertices.reserve(corner_ids.len());
        out.edge_origins.reserve(corner_ids.len());
        out.corner_params.reserve(corner_ids.len());
        out.face_levels.reserve(leaves.len());
        out.face_uniform.reserve(leaves.len());
        out.holes.reserve(leaves.len());
        out.transition.reserve(leaves.len());
        out.face_domains.reserve(leaves.len());
        for leaf in &leaves {
            self.emit(leaf, &ids, &mut out);
        }
        Ok(out)
    }

    /// Appends the polygons of `leaf` to `out`.
    fn emit(&self, leaf: &Leaf, ids: &LeafIds<'_>, out: &mut AdaptiveMesh) {
        let lv = &self.levels[leaf.level];
        let t = &lv.topology;
        let f = leaf.face;
        let params = lv.params(f);
        let fv = t.face_vertices(f);
        let fe = t.face_edges(f);
        let n = fv.len();
        let corners = &ids.corners[leaf.first..leaf.first + n];
        let edge_points = &ids.edge_points[leaf.first..leaf.first + n];
        if !leaf.split {
            // The common case: the leaf itself, its edges uniform edges of its level.
            out.face_vertices.extend_from_slice(corners);
            for &e in fe {
                out.edge_origins.push(EdgeOrigin::Uniform {
                    level: leaf.level as u8,
                    index: lv.edge_key[e as usize],
                    faces: lv.edge_full[e as usize],
                });
            }
            out.corner_params.extend_from_slice(params);
            self.close_face(out, leaf, false);
            return;
        }
        // The closure refines a whole non-quad base face before any of its edges is split.
        debug_assert_ne!(lv.sub_face[f], WHOLE_FACE);
        let split: Vec<bool> = edge_points.iter().map(|&e| e != NONE).collect();
        let vertex = |p: Point| match p {
            C(i) => corners[i],
            E(i) => edge_points[i],
        };
        let param = |p: Point| match p {
            C(i) => params[i],
            E(i) => {
                let (a, b) = (params[i], params[(i + 1) % n]);
                [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
            }
        };
        // The uniform edge between two consecutive pattern points, if they lie on one.
        let origin = |p: Point, q: Point| -> EdgeOrigin {
            let uniform =
                |level: usize, e: usize, lvl: &crate::level::SparseLevel| EdgeOrigin::Uniform {
                    level: level as u8,
                    index: lvl.edge_key[e],
                    faces: lvl.edge_full[e],
                };
            match (p, q) {
                (C(i), C(j)) if j == (i + 1) % n && !split[i] => {
                    uniform(leaf.level, fe[i] as usize, lv)
                }
                (C(j), C(i)) if j == (i + 1) % n && !split[i] => {
                    uniform(leaf.level, fe[i] as usize, lv)
                }
                (C(c), E(i)) | (E(i), C(c)) if c == i || c == (i + 1) % n => {
                    // The half of edge i at corner c, one level down.
                    let next = &self.levels[leaf.level + 1];
                    let ep = lv.edge_child[fe[i] as usize];
                    let vc = lv.vertex_child[fv[c] as usize];
                    match next.topology.find_edge(ep, vc) {
                        Some(h) => uniform(leaf.level + 1, h as usize, next),
                        None => EdgeOrigin::Diagonal,
                    }
                }
                _ => EdgeOrigin::Diagonal,
            }
        };
        let pos = |p: Point| out.positions[vertex(p) as usize];
        let polygons = pattern(&self.scheme, n, &split, &pos);
        for poly in polygons {
            let m = poly.len();
            for i in 0..m {
                out.face_vertices.push(vertex(poly[i]));
                out.edge_origins.push(origin(poly[i], poly[(i + 1) % m]));
                out.corner_params.push(param(poly[i]));
            }
            self.close_face(out, leaf, true);
        }
    }
}

impl AdaptiveRefinement {
    /// Ends the face just written to `out`: its offset and the per-face arrays of `leaf`.
    fn close_face(&self, out: &mut AdaptiveMesh, leaf: &Leaf, transition: bool) {
        let lv = &self.levels[leaf.level];
        let f = leaf.face;
        out.face_offsets.push(out.face_vertices.len() as u32);
        out.face_levels.push(leaf.level as u8);
        out.face_uniform.push(lv.face_key[f]);
        out.holes.push(lv.topology.is_hole(f));
        out.transition.push(transition);
        out.face_domains.push((lv.base_face[f], lv.sub_face[f]));
    }
}
