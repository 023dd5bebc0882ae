//! The limit of a Catmull-Clark level's vertices read off the level above's regular
//! patches: where a quad of the level above and its one-ring are regular (four smooth
//! interior corners of valence 4, quads around, nothing sharp, no hole), the limit surface
//! over it is the bicubic B-spline patch of its 16 control points (Stam 1998, §2; the
//! regular case of [`crate::evaluation::patch`]). Every child of such a quad lies on it at a
//! parameter of `{0, ½, 1}²` (corner, edge midpoint, centre), so its limit position and
//! normal are fixed weights over the level above's points: no point of the last level, and
//! no ring of it, is needed. The vertices whose quad is not regular take the general path
//! ([`super::child_limit`]) over the last level's points, made only when there are such.

use glam::DVec3;
use rayon::prelude::*;
use subd_mesh::Topology;
use subd_schemes::{Refinement, Rule, Scheme};

use crate::evaluation::patch::eval_bicubic_first;
use crate::limit_masks::child_limit::{self, ChildLimit};
use crate::limit_masks::table::Ring;
use crate::{LimitError, LimitPoints};

/// Vertices per parallel task.
const CHUNK: usize = 4096;

/// Marks a face whose patch is not regular.
const NOT_REGULAR: u32 = u32::MAX;

/// Whether [`last_level_limit`] covers `refinement`'s last level: Catmull-Clark at that
/// level and the one above, at least one level refined, and [`child_limit::applies`].
pub(crate) fn applies(refinement: &Refinement) -> bool {
    let last = refinement.num_levels();
    last > 0
        && refinement.scheme().at_level(last) == Scheme::CatmullClark
        && refinement.scheme().at_level(last - 1) == Scheme::CatmullClark
        && child_limit::applies(refinement, last)
}

/// The limit position and unit normal of every vertex of `refinement`'s last level from
/// `above`, the points of the level above it ([`applies`] must hold). Tangents are left
/// empty.
pub(crate) fn last_level_limit(
    refinement: &Refinement,
    above: &[DVec3],
) -> Result<LimitPoints, LimitError> {
    let last = refinement.num_levels();
    let t = refinement.topology(last - 1);
    let rules = refinement.vertex_rules(last - 1);
    let grids = Grids::new(t, rules);
    let numbering = Numbering::of(t);
    let n = numbering.len(t);
    // The general path needs the last level's points; made only for a mesh that has a
    // vertex it must take.
    let general = if grids.all_regular {
        None
    } else {
        let points = refinement.next_level_points(last, above);
        Some((ChildLimit::new(refinement, last)?, points))
    };
    let mut out = LimitPoints {
        positions: subd_mesh::memory::with_capacity(n),
        tangent1: Vec::new(),
        tangent2: Vec::new(),
        normals: subd_mesh::memory::with_capacity(n),
    };
    (0..n)
        .into_par_iter()
        .with_min_len(CHUNK)
        .map_init(Ring::default, |ring, v| match numbering.owner(t, v) {
            (f, at) if f != usize::MAX && grids.regular(f) => grids.limit(f, at, above),
            _ => {
                let (children, points) = general.as_ref().expect("made for irregular faces");
                let [p, _, _, normal] = children.limit(ring, v, points);
                (p, normal)
            }
        })
        .unzip_into_vecs(&mut out.positions, &mut out.normals);
    Ok(out)
}

/// Where a child lies on its owner quad's patch: corner `k`, the midpoint of side `k`
/// (corner `k` to `k + 1`), or the centre.
#[derive(Clone, Copy)]
enum At {
    Corner(usize),
    Side(usize),
    Centre,
}

/// OpenSubdiv's numbering of a Catmull-Clark child level: vertex children, then face
/// children, then edge children.
struct Numbering {
    first_face: usize,
    first_edge: usize,
}

impl Numbering {
    fn of(t: &Topology) -> Numbering {
        Numbering {
            first_face: t.num_vertices(),
            first_edge: t.num_vertices() + t.num_faces(),
        }
    }

    fn len(&self, t: &Topology) -> usize {
        self.first_edge + t.num_edges()
    }

    /// The quad of the level above that child `v` is evaluated on, and where: a face child
    /// on its face, an edge child on the edge's first face, a vertex child on its parent's
    /// first face. A vertex no face uses has no owner: `usize::MAX`.
    fn owner(&self, t: &Topology, v: usize) -> (usize, At) {
        if v >= self.first_edge {
            let e = v - self.first_edge;
            let Some(&f) = t.edge_faces(e).first() else {
                return (usize::MAX, At::Centre);
            };
            let k = t
                .face_edges(f as usize)
                .iter()
                .position(|&x| x as usize == e);
            (f as usize, At::Side(k.unwrap_or(0)))
        } else if v >= self.first_face {
            (v - self.first_face, At::Centre)
        } else {
            match t.vertex_faces(v).first() {
                Some(&f) => (
                    f as usize,
                    At::Corner(t.vertex_face_local_indices(v)[0] as usize),
                ),
                None => (usize::MAX, At::Centre),
            }
        }
    }
}

/// The 16 control points (grid order `4 j + i`, the quad being the square (1,1)–(2,2)) of
/// every quad of a level, `[NOT_REGULAR; 16]` where its patch is not regular.
struct Grids {
    points: Vec<[u32; 16]>,
    all_regular: bool,
}

impl Grids {
    fn new(t: &Topology, rules: &[Rule]) -> Grids {
        let regular: Vec<bool> = (0..t.num_vertices())
            .into_par_iter()
            .with_min_len(CHUNK)
            .map(|v| regular_corner(t, rules, v))
            .collect();
        let mut points = subd_mesh::memory::with_capacity(t.num_faces());
        points.par_extend(
            (0..t.num_faces())
                .into_par_iter()
                .with_min_len(CHUNK)
                .map(|f| regular_grid(t, &regular, f).unwrap_or([NOT_REGULAR; 16])),
        );
        let used = |v: usize| !t.vertex_faces(v).is_empty();
        let all_regular = points.par_iter().all(|g| g[0] != NOT_REGULAR)
            && (0..t.num_vertices()).all(used)
            && (0..t.num_edges()).all(|e| !t.edge_faces(e).is_empty());
        Grids {
            points,
            all_regular,
        }
    }

    /// Whether face `f`'s patch is regular.
    fn regular(&self, f: usize) -> bool {
        self.points[f][0] != NOT_REGULAR
    }

    /// Limit position and unit normal at `at` on face `f`'s patch, from the level's
    /// `points`.
    fn limit(&self, f: usize, at: At, points: &[DVec3]) -> (DVec3, DVec3) {
        let (u, v) = match at {
            At::Corner(k) => [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)][k],
            At::Side(k) => [(0.5, 0.0), (1.0, 0.5), (0.5, 1.0), (0.0, 0.5)][k],
            At::Centre => (0.5, 0.5),
        };
        let grid = self.points[f].map(|i| points[i as usize]);
        let (p, du, dv) = eval_bicubic_first(&grid, u, v);
        (p, du.cross(dv).normalize_or_zero())
    }
}

/// Whether vertex `v` is a regular smooth interior vertex: the smooth rule, no sharpness
/// at it or on its edges, valence 4 with four quads around it, none a hole.
fn regular_corner(t: &Topology, rules: &[Rule], v: usize) -> bool {
    let (faces, edges) = (t.vertex_faces(v), t.vertex_edges(v));
    rules[v] == Rule::Smooth
        && t.vertex_sharpness(v) == 0.0
        && faces.len() == 4
        && edges.len() == 4
        && !t.is_boundary_vertex(v)
        && !t.is_non_manifold_vertex(v)
        && edges.iter().all(|&e| t.edge_sharpness(e as usize) == 0.0)
        && faces
            .iter()
            .all(|&g| t.face_size(g as usize) == 4 && !t.is_hole(g as usize))
}

/// The 16 B-spline control points of quad `f` (grid order `4 j + i`; corner `k` of `f` at
/// (1,1), (2,1), (2,2), (1,2)) when its four corners are regular ([`regular_corner`],
/// `regular` per vertex) and the 16 points are distinct; `None` otherwise. Allocates nothing: it runs once per face of a
/// level.
fn regular_grid(t: &Topology, regular: &[bool], f: usize) -> Option<[u32; 16]> {
    let fv = t.face_vertices(f);
    if fv.len() != 4 || t.is_hole(f) || !fv.iter().all(|&v| regular[v as usize]) {
        return None;
    }
    let at = |i: usize, j: usize| 4 * j + i;
    let mut g = [0u32; 16];
    for (k, (i, j)) in [(1, 1), (2, 1), (2, 2), (1, 2)].into_iter().enumerate() {
        g[at(i, j)] = fv[k];
    }
    // Beside side k (corner k to k + 1): the points beyond corner k and beyond k + 1, from
    // the quad across, which runs (x_{k+1}, x_k, beyond x_k, beyond x_{k+1}).
    let beside = [
        [(1, 0), (2, 0)],
        [(3, 1), (3, 2)],
        [(2, 3), (1, 3)],
        [(0, 2), (0, 1)],
    ];
    let fe = t.face_edges(f);
    for k in 0..4 {
        let h = *t
            .edge_faces(fe[k] as usize)
            .iter()
            .find(|&&x| x as usize != f)? as usize;
        let hv = t.face_vertices(h);
        let s = hv.iter().position(|&x| x == fv[(k + 1) % 4])?;
        if hv[(s + 1) % 4] != fv[k] {
            return None;
        }
        g[at(beside[k][0].0, beside[k][0].1)] = hv[(s + 2) % 4];
        g[at(beside[k][1].0, beside[k][1].1)] = hv[(s + 3) % 4];
    }
    // The diagonal point at corner k: opposite it in the quad across the corner, two faces
    // on around it (its faces run counter-clockwise).
    let diagonal = [(0, 0), (3, 0), (3, 3), (0, 3)];
    for k in 0..4 {
        let v = fv[k] as usize;
        let (faces, local) = (t.vertex_faces(v), t.vertex_face_local_indices(v));
        let i = faces.iter().position(|&x| x as usize == f)?;
        let d = (i + 2) % 4;
        let dv = t.face_vertices(faces[d] as usize);
        g[at(diagonal[k].0, diagonal[k].1)] = dv[(local[d] as usize + 2) % 4];
    }
    // A neighbourhood that meets itself (two sheets back to back) is no B-spline grid.
    let mut sorted = g;
    sorted.sort_unstable();
    sorted.windows(2).all(|w| w[0] != w[1]).then_some(g)
}
