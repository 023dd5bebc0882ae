//! Tessellation at a rate of 2^k by uniform refinement: the samples of a grid of 2^k segments
//! per base edge are exactly the vertices of the k-th uniform level (OpenSubdiv's child
//! faces keep their parent's parameter axes, see [`crate::eval`]), so their limit positions
//! and normals are the limit masks of that level ([`crate::level_limit_points`]), one
//! parallel pass instead of one patch evaluation per sample.
//!
//! Each sample (face, sub-face, u, v) is found among the level's vertices by walking down
//! the child faces that hold it, in integer grid coordinates, to a face of level k − 1, and
//! reading it off that face's children: the vertex child of a corner, the child of an edge
//! or (Catmull-Clark) the face's own child, numbered as OpenSubdiv numbers them (vertex
//! children first, keeping their index, then face children, then edge children).

use glam::DVec3;
use rayon::prelude::*;
use subd_mesh::Topology;
use subd_schemes::{Options, Refinement, Rule, Scheme};

use crate::child_limit::{self, ChildLimit};
use crate::eval::{FaceParam, LimitEvaluator};
use crate::sample_numbering::number_samples;
use crate::table::limit_by_vertex;
use crate::tessellation::{Numbered, Tessellation, check_rate};
use crate::{LimitError, Tangents, level_limit_points};

/// The refinement depth k of a rate 2^k that this path tessellates: Catmull-Clark or Loop
/// on a manifold mesh (the evaluator reports non-manifold configurations it cannot cut,
/// which refinement would not) without interior vertices of valence 2 (where the limit
/// masks' normals and the patches' may point either way).
pub(crate) fn depth(topology: &Topology, scheme: &Scheme, rate: usize) -> Option<usize> {
    let covered = matches!(scheme, Scheme::CatmullClark | Scheme::Loop);
    if !covered || !rate.is_power_of_two() {
        return None;
    }
    let t = topology;
    let manifold = (0..t.num_edges()).all(|e| !t.is_non_manifold_edge(e))
        && (0..t.num_vertices()).all(|v| !t.is_non_manifold_vertex(v));
    let valence_2 =
        (0..t.num_vertices()).any(|v| t.vertex_edges(v).len() == 2 && !t.is_boundary_vertex(v));
    (manifold && !valence_2).then(|| rate.trailing_zeros() as usize)
}

/// Tessellates at rate `2^levels` ([`depth`] gives `levels`): refines, takes the limit of
/// the last level, and gives each sample its vertex's value; the samples on base vertices
/// whose limit masks are not the patches' ([`masks_match_patches`]) are evaluated.
pub(crate) fn tessellate_refined(
    topology: &Topology,
    scheme: &Scheme,
    options: &Options,
    positions: &[DVec3],
    levels: usize,
) -> Result<Tessellation, LimitError> {
    let r = Refinement::new(topology, scheme.clone(), options, levels)?;
    let loop_scheme = *scheme == Scheme::Loop;
    // On the prepared base, as the evaluator checks it (a boundary face is a hole under
    // `BoundaryInterpolation::None`).
    check_rate(r.topology(0), loop_scheme, 1 << levels)?;
    // The sample numbering of the evaluator path, on the same (prepared) base topology.
    let Numbered {
        params,
        mut out,
        vertex_sample,
    } = number_samples(r.topology(0), loop_scheme, 1 << levels);
    let points = r.points_at(positions, levels);
    let finder = VertexFinder::new(&r, levels);
    (out.positions, out.normals) = sample_limits(&r, levels, options, &points, &params, &finder)?;
    drop(points);
    let evaluated: Vec<usize> = (0..r.topology(0).num_vertices())
        .filter(|&v| vertex_sample[v] != u32::MAX && !masks_match_patches(&r, v))
        .map(|v| vertex_sample[v] as usize)
        .collect();
    if !evaluated.is_empty() {
        let evaluator = LimitEvaluator::new(topology, scheme, options)?;
        let points = evaluator.prepare(positions);
        for s in evaluated {
            (out.positions[s], out.normals[s]) =
                evaluator.evaluate_position_normal(&points, params[s])?;
        }
    }
    out.params = params;
    Ok(out)
}

/// The limit position and normal of every sample: its vertex's at level `levels`. Where the
/// level's masks can be read off the level above, each sample's vertex is evaluated in
/// sample order straight into the outputs; otherwise the level's limits are computed and
/// gathered.
fn sample_limits(
    r: &Refinement,
    levels: usize,
    options: &Options,
    points: &[DVec3],
    params: &[FaceParam],
    finder: &VertexFinder,
) -> Result<(Vec<DVec3>, Vec<DVec3>), LimitError> {
    if child_limit::applies(r, levels) {
        let children = ChildLimit::new(r, levels)?;
        let limit = limit_by_vertex(params.len(), Tangents::Dropped, |ring, s| {
            children.limit(ring, finder.vertex(&params[s]) as usize, points)
        });
        return Ok((limit.positions, limit.normals));
    }
    let limit = level_limit_points(r, levels, options, points, Tangents::Dropped)?;
    Ok(params
        .par_iter()
        .map(|at| {
            let v = finder.vertex(at) as usize;
            (limit.positions[v], limit.normals[v])
        })
        .unzip())
}

/// Whether the limit masks of base vertex `v`, carried to any level, give the normal the
/// patches around it give (the data: every OpenSubdiv shape): a smooth interior vertex, or
/// a regular boundary vertex (two quads or three triangles) with no other sharp edge. At
/// an irregular crease, boundary or corner the masks' cross tangent is not the patches'
/// one-sided derivative, and on a crease the sample takes the normal of the face that
/// reaches it first, as the evaluator gives it.
fn masks_match_patches(r: &Refinement, v: usize) -> bool {
    let t = r.topology(0);
    let rule = r.vertex_rules(0)[v];
    if !t.is_boundary_vertex(v) {
        return rule == Rule::Smooth && t.vertex_edges(v).len() >= 3;
    }
    let regular_faces = if *r.scheme() == Scheme::Loop { 3 } else { 2 };
    let inner_sharp = t
        .vertex_edges(v)
        .iter()
        .any(|&e| !t.is_boundary_edge(e as usize) && t.edge_sharpness(e as usize) > 0.0);
    rule == Rule::Crease
        && t.vertex_faces(v).len() == regular_faces
        && !inner_sharp
        && t.vertex_sharpness(v) == 0.0
}

/// Finds the vertex of level k at a sample of rate 2^k.
struct VertexFinder<'a> {
    base: &'a Topology,
    /// Level k − 1 (the base when k = 0).
    above: &'a Topology,
    levels: u32,
    loop_scheme: bool,
    /// Where the children of level k − 1's faces and edges start among level k's vertices.
    first_face: u32,
    first_edge: u32,
}

/// A place in a face of some level: the face and integer coordinates on a grid of `size`
/// segments per side (u = i / size, v = j / size; the sub-face's for a base face that is not
/// a quad).
#[derive(Clone, Copy)]
struct GridPoint {
    face: usize,
    i: u32,
    j: u32,
    size: u32,
}

impl<'a> VertexFinder<'a> {
    fn new(r: &'a Refinement, levels: usize) -> VertexFinder<'a> {
        let above = r.topology(levels.saturating_sub(1));
        let loop_scheme = *r.scheme() == Scheme::Loop;
        let (nv, nf) = (above.num_vertices() as u32, above.num_faces() as u32);
        VertexFinder {
            base: r.topology(0),
            above,
            levels: levels as u32,
            loop_scheme,
            first_face: nv,
            first_edge: if loop_scheme { nv } else { nv + nf },
        }
    }

    /// The level-k vertex at sample `at`.
    fn vertex(&self, at: &FaceParam) -> u32 {
        let polygon = !self.loop_scheme && self.base.face_size(at.face) != 4;
        // A sub-face of a face that is not a quad takes half the rate.
        let size = 1u32 << (self.levels - u32::from(polygon));
        // Exact: the parameters are multiples of 1/size, itself a power of two.
        let p = GridPoint {
            face: at.face,
            i: (at.u * f64::from(size)) as u32,
            j: (at.v * f64::from(size)) as u32,
            size,
        };
        if self.levels == 0 {
            return self.base_corner(p);
        }
        if polygon {
            if self.levels == 1 {
                return self.sub_face_corner(at.face, at.sub, p);
            }
            // The sub-face is the face's level-1 child `sub`, parameters unchanged.
            let first = self.base.face_offsets()[at.face] as usize;
            return self.in_quads(
                GridPoint {
                    face: first + at.sub,
                    ..p
                },
                1,
            );
        }
        if self.loop_scheme {
            self.in_triangles(p)
        } else {
            self.in_quads(p, 0)
        }
    }

    /// Rate 1: the base face's corner at (0,0), (1,0), (1,1) or (0,1) (quads; (0,1) is
    /// corner 2 of a triangle).
    fn base_corner(&self, p: GridPoint) -> u32 {
        let corner = match (p.i, p.j) {
            (0, 0) => 0,
            (1, 0) => 1,
            (1, 1) => 2,
            _ if self.loop_scheme => 2,
            _ => 3,
        };
        self.base.face_vertices(p.face)[corner]
    }

    /// Rate 2 on sub-face `sub` of a base face that is not a quad: its corners are the
    /// face's corner `sub`, the children of its sides `sub` and `sub − 1` and the face's
    /// child (at (0,0), (1,0), (0,1), (1,1)).
    fn sub_face_corner(&self, face: usize, sub: usize, p: GridPoint) -> u32 {
        let (fv, fe) = (self.base.face_vertices(face), self.base.face_edges(face));
        let n = fv.len();
        match (p.i, p.j) {
            (0, 0) => fv[sub],
            (1, 0) => self.first_edge + fe[sub],
            (0, 1) => self.first_edge + fe[(sub + n - 1) % n],
            _ => self.first_face + face as u32,
        }
    }

    /// Down the quad children from a quad of level `level` to level k − 1: child j holds the
    /// parent's quadrant at corner j (u, v ≥ ½ picks the upper halves; a point on the split
    /// line is a corner of either side).
    fn in_quads(&self, mut p: GridPoint, level: u32) -> u32 {
        for l in level..self.levels - 1 {
            let h = p.size / 2;
            let child = match (p.i >= h, p.j >= h) {
                (false, false) => 0,
                (true, false) => 1,
                (true, true) => 2,
                (false, true) => 3,
            };
            // Children are consecutive: from the face offsets at the base, four per quad
            // below it.
            let first = if l == 0 {
                self.base.face_offsets()[p.face] as usize
            } else {
                4 * p.face
            };
            p = GridPoint {
                face: first + child,
                i: p.i - if p.i >= h { h } else { 0 },
                j: p.j - if p.j >= h { h } else { 0 },
                size: h,
            };
        }
        self.quad_child_vertex(p)
    }

    /// On a quad of level k − 1 at grid size 2: child 0 = (V0, E0, F, E3), and so on round
    /// the face, so (2a, 2b) is a corner, the midpoint of a side its edge's child, (1, 1)
    /// the face's child.
    fn quad_child_vertex(&self, p: GridPoint) -> u32 {
        let (fv, fe) = (
            self.above.face_vertices(p.face),
            self.above.face_edges(p.face),
        );
        let edge = |j: usize| self.first_edge + fe[j];
        match (p.i, p.j) {
            (0, 0) => fv[0],
            (2, 0) => fv[1],
            (2, 2) => fv[2],
            (0, 2) => fv[3],
            (1, 0) => edge(0),
            (2, 1) => edge(1),
            (1, 2) => edge(2),
            (0, 1) => edge(3),
            _ => self.first_face + p.face as u32,
        }
    }

    /// Down the Loop children to level k − 1: (V0,E0,E2) at (0,0), (E0,V1,E1) at (½,0),
    /// (E2,E1,V2) at (0,½), and the middle one (E1,E2,E0), turned round: its (s, t) is
    /// (½ − u, ½ − v) in the parent's halves.
    fn in_triangles(&self, mut p: GridPoint) -> u32 {
        for _ in 0..self.levels - 1 {
            let h = p.size / 2;
            let (child, i, j) = if p.i >= h {
                (1, p.i - h, p.j)
            } else if p.j >= h {
                (2, p.i, p.j - h)
            } else if p.i + p.j <= h {
                (0, p.i, p.j)
            } else {
                (3, h - p.i, h - p.j)
            };
            p = GridPoint {
                face: 4 * p.face + child,
                i,
                j,
                size: h,
            };
        }
        self.triangle_child_vertex(p)
    }

    /// On a triangle of level k − 1 at grid size 2: corners at (0,0), (2,0), (0,2), the
    /// children of edges 0, 1, 2 (corner j to j + 1) at (1,0), (1,1), (0,1).
    fn triangle_child_vertex(&self, p: GridPoint) -> u32 {
        let (fv, fe) = (
            self.above.face_vertices(p.face),
            self.above.face_edges(p.face),
        );
        let edge = |j: usize| self.first_edge + fe[j];
        match (p.i, p.j) {
            (0, 0) => fv[0],
            (2, 0) => fv[1],
            (0, 2) => fv[2],
            (1, 0) => edge(0),
            (1, 1) => edge(1),
            _ => edge(2),
        }
    }
}
