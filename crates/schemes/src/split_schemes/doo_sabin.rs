//! Doo-Sabin's dual scheme (Doo and Sabin 1978; the subdivision lecture notes §4 (b)).
//!
//! Every corner `k` of an n-sided face gets a child point `Σ_j α_{(j−k) mod n} p_j` with
//! `α_0 = (n + 5)/(4n)` and `α_d = (3 + 2cos(2πd/n))/(4n)`. The children are joined into an
//! F-face per face (same size), an E-face per edge (a quad) and a V-face per vertex (one
//! corner per face around it). A face's children have the face's centroid as their centroid,
//! and the face's circulant mask has the eigenvalue 1 once, ½ twice (frequencies ±1) and ¼ at
//! every other frequency, so under repeated
//! refinement each face shrinks to its centroid: the limit surface passes through the
//! centroid of every face of every level.
//!
//! **Boundary rule (subd's choice, documented):** every boundary edge also gets its two
//! Chaikin points `¾a + ¼b` and `¼a + ¾b`. The E-face of a boundary edge is the quad of its
//! two Chaikin points and the two children of its face; the V-face of a boundary vertex with
//! `m` faces is the `(m + 2)`-gon of its Chaikin point on the outgoing edge, its `m` face
//! children and its Chaikin point on the incoming edge. The boundary polygon of each level is
//! therefore Chaikin's corner cutting of the one before, and the boundary of the limit surface
//! is the quadratic B-spline of the base boundary polygon. (CGAL's `DooSabin_subdivision`
//! leaves the boundary open without these faces, which loses a strip of the surface at every
//! level.)
//!
//! An interior vertex with two faces gets no V-face (it would be a 2-gon): the E-faces of its
//! two edges share the edge between its two face children instead.
//!
//! Vertex order of a level: the face children in face-vertex order (child `offset(f) + k` of
//! corner `k` of face `f`), then two Chaikin points per boundary edge, in edge order, the one
//! next to the edge's first vertex first. Face order: F-faces in face order, E-faces in edge
//! order, V-faces in vertex order.

use crate::facts::{Capability, FaceKind, SPLIT_TAGS, SchemeFacts, Split, TagSupport};
use std::f64::consts::TAU;

use subd_mesh::{Topology, TopologyParts};

use super::{ChildFaces, SplitRule, StepError, Weights, check_size};

/// Doo-Sabin weight `α_d` of corner distance `d` in an `n`-sided face.
pub fn weight(n: usize, d: usize) -> f64 {
    let nf = n as f64;
    if d == 0 {
        (nf + 5.0) / (4.0 * nf)
    } else {
        (3.0 + 2.0 * (TAU * d as f64 / nf).cos()) / (4.0 * nf)
    }
}

/// Weights of every face size `< cached` (index `n(n−1)/2 + d`), so rows do not call `cos`.
struct WeightTable {
    cached: usize,
    weights: Vec<f64>,
}

impl WeightTable {
    fn new(cached: usize) -> WeightTable {
        let mut weights = Vec::new();
        for n in 0..cached {
            for d in 0..n {
                weights.push(weight(n, d));
            }
        }
        WeightTable { cached, weights }
    }

    #[inline]
    fn get(&self, n: usize, d: usize) -> f64 {
        if n < self.cached {
            self.weights[n * (n - 1) / 2 + d]
        } else {
            weight(n, d)
        }
    }
}

/// Where the Chaikin points of boundary edges are numbered: per edge, the index of its first
/// point (two consecutive ones), or `u32::MAX` for an interior edge.
fn boundary_points(p: &Topology, first: u32) -> (Vec<u32>, usize) {
    let mut next = first;
    let at: Vec<u32> = (0..p.num_edges())
        .map(|e| {
            if p.is_boundary_edge(e) {
                next += 2;
                next - 2
            } else {
                u32::MAX
            }
        })
        .collect();
    (at, (next - first) as usize)
}

/// Whether vertex `v` of `p` gets a vertex face: it has faces, and two or more when it is
/// interior (the vertex face of an interior valence-2 vertex would be a 2-gon).
fn has_vertex_face(p: &Topology, v: usize) -> bool {
    let faces = p.vertex_faces(v).len();
    faces > 0 && (p.is_boundary_vertex(v) || faces >= 3)
}

/// For each vertex of `p`, the index of its vertex face in the child level (`None` for an
/// isolated vertex and an interior vertex of valence 2). Its corners, in order, are the face
/// children around the vertex (with the two Chaikin points first and last at a boundary).
pub fn vertex_face_indices(p: &Topology) -> Vec<Option<u32>> {
    let mut next = (p.num_faces() + p.num_edges()) as u32;
    (0..p.num_vertices())
        .map(|v| {
            has_vertex_face(p, v).then(|| {
                next += 1;
                next - 1
            })
        })
        .collect()
}

/// One Doo-Sabin step over a parent level.
pub(crate) struct Step<'a> {
    p: &'a Topology,
    /// First Chaikin point of each boundary edge (`u32::MAX` inside).
    chaikin_at: Vec<u32>,
    num_chaikin: usize,
    /// The face of each face-vertex.
    face_of: Vec<u32>,
    boundary_edges: Vec<u32>,
    table: WeightTable,
}

impl<'a> Step<'a> {
    pub(crate) fn new(p: &'a Topology) -> Step<'a> {
        let (chaikin_at, num_chaikin) = boundary_points(p, p.num_face_vertices() as u32);
        let face_of = crate::refine::par::build(
            p.num_face_vertices(),
            p.num_faces(),
            |f| p.face_offsets()[f] as usize,
            |r, out: &mut [u32]| {
                let base = p.face_offsets()[r.start] as usize;
                for f in r {
                    let o = p.face_offsets()[f] as usize - base;
                    out[o..o + p.face_size(f)].fill(f as u32);
                }
            },
        );
        let boundary_edges = (0..p.num_edges() as u32)
            .filter(|&e| chaikin_at[e as usize] != u32::MAX)
            .collect();
        Step {
            p,
            chaikin_at,
            num_chaikin,
            face_of,
            boundary_edges,
            table: WeightTable::new(17),
        }
    }

    /// The Chaikin point of boundary edge `e` next to its end `v`.
    fn chaikin(&self, e: u32, v: u32) -> u32 {
        self.chaikin_at[e as usize] + u32::from(self.p.edge_vertices(e as usize)[1] == v)
    }
}

impl SplitRule for Step<'_> {
    fn num_rows(&self) -> usize {
        self.p.num_face_vertices() + self.num_chaikin
    }

    #[inline]
    fn fill<W: Weights>(&self, r: usize, w: &mut W) {
        let p = self.p;
        let nfv = p.num_face_vertices();
        if r < nfv {
            let f = self.face_of[r] as usize;
            let k = r - p.face_offsets()[f] as usize;
            let fv = p.face_vertices(f);
            let n = fv.len();
            for (j, &x) in fv.iter().enumerate() {
                w.add(x, self.table.get(n, (j + n - k) % n));
            }
        } else {
            let i = r - nfv;
            let [a, b] = p.edge_vertices(self.boundary_edges[i / 2] as usize);
            let (near, far) = if i % 2 == 0 { (a, b) } else { (b, a) };
            w.add(near, 0.75);
            w.add(far, 0.25);
        }
    }

    fn child_faces(&self) -> Result<ChildFaces, StepError> {
        let p = self.p;
        let nfv = p.num_face_vertices();
        if super::doo_sabin_split::applies(p) {
            // The same faces, written in parallel.
            check_size(2 * nfv as u64 + 4 * p.num_edges() as u64)?;
            let (offsets, verts) = super::doo_sabin_split::face_lists(p);
            return Ok(ChildFaces::untagged(self.num_rows(), offsets, verts));
        }
        let num_boundary_vertices = (0..p.num_vertices())
            .filter(|&v| p.is_boundary_vertex(v))
            .count();
        check_size(2 * nfv as u64 + 4 * p.num_edges() as u64 + 2 * num_boundary_vertices as u64)?;
        let offsets = p.face_offsets();
        let child = |f: u32, k: usize| offsets[f as usize] + k as u32;
        let mut sizes: Vec<u32> =
            Vec::with_capacity(p.num_faces() + p.num_edges() + p.num_vertices());
        let mut verts: Vec<u32> = Vec::with_capacity(2 * nfv + 4 * p.num_edges());
        // F-faces.
        sizes.extend(p.face_sizes());
        verts.extend(0..nfv as u32);
        // E-faces.
        for e in 0..p.num_edges() {
            let faces = p.edge_faces(e);
            let local = p.edge_face_local_indices(e);
            let n0 = p.face_size(faces[0] as usize);
            // In face 0 the edge runs from corner k to corner k+1, which may be either end.
            let (f, k) = (faces[0], local[0] as usize);
            let (a_child, b_child) = (child(f, k), child(f, (k + 1) % n0));
            sizes.push(4);
            if faces.len() == 1 {
                let fv = p.face_vertices(f as usize);
                let (a, b) = (fv[k], fv[(k + 1) % n0]);
                verts.extend([
                    self.chaikin(e as u32, a),
                    self.chaikin(e as u32, b),
                    b_child,
                    a_child,
                ]);
            } else {
                let (g, j) = (faces[1], local[1] as usize);
                let n1 = p.face_size(g as usize);
                // Face 1 runs the edge the other way: from corner j (= b) to j+1 (= a).
                let (gb, ga) = (child(g, j), child(g, (j + 1) % n1));
                verts.extend([b_child, a_child, ga, gb]);
            }
        }
        // V-faces.
        for v in 0..p.num_vertices() {
            if !has_vertex_face(p, v) {
                continue;
            }
            let faces = p.vertex_faces(v);
            let local = p.vertex_face_local_indices(v);
            let boundary = p.is_boundary_vertex(v);
            sizes.push((faces.len() + if boundary { 2 } else { 0 }) as u32);
            if boundary {
                let (f0, c0) = (faces[0] as usize, local[0] as usize);
                verts.push(self.chaikin(p.face_edges(f0)[c0], v as u32));
            }
            verts.extend(faces.iter().zip(local).map(|(&f, &c)| child(f, c as usize)));
            if boundary {
                let (fl, cl) = (
                    faces[faces.len() - 1] as usize,
                    local[local.len() - 1] as usize,
                );
                let n = p.face_size(fl);
                verts.push(self.chaikin(p.face_edges(fl)[(cl + n - 1) % n], v as u32));
            }
        }
        Ok(ChildFaces::from_sizes(self.num_rows(), &sizes, verts))
    }

    /// In closed form on a closed parent ([`super::doo_sabin_split`]); other levels are
    /// built from their faces.
    fn derived_topology(&self) -> Option<TopologyParts> {
        super::doo_sabin_split::applies(self.p).then(|| super::doo_sabin_split::split(self.p))
    }
}

/// Doo-Sabin's facts: no crease rules (its dual split moves every vertex off the edges).
pub const FACTS: SchemeFacts = SchemeFacts {
    name: "doo-sabin",
    summary: "Doo-Sabin's dual scheme, any polygons",
    input_faces: FaceKind::Any,
    split: Split::Dual,
    interpolating: false,
    opensubdiv_family: false,
    tags: TagSupport {
        infinite_creases: false,
        corners: false,
        ..SPLIT_TAGS
    },
    peak_bytes_per_vertex: (145, None),
    capabilities: &[Capability::Refine, Capability::Limit, Capability::Analyse],
};
