//! Kobbelt's √3 scheme (SIGGRAPH 2000; the subdivision lecture notes §4): triangles only.
//!
//! Every step inserts the centroid of every triangle, moves every old interior vertex of
//! valence `n` to `(1 − α_n) p + (α_n / n) Σ p_i` with `α_n = (4 − 2cos(2π/n))/9`, and flips
//! every old interior edge: edge `ab` between the triangles with centroids `c_f` (on the side
//! where it runs `a → b`) and `c_g` becomes the two triangles `(a, c_g, c_f)` and
//! `(c_g, b, c_f)`. A closed mesh's face count triples; two steps split every edge in three.
//!
//! **Boundaries and infinitely sharp creases** (Kobbelt's rule, §4 of the paper). They are
//! treated alike: a feature edge is never flipped. On odd steps (1, 3, …) its triangles keep
//! it, `(a, b, c_f)`, and its vertices stay where they are. On even steps (2, 4, …) it is
//! trisected: its points `t_a = (p₋₁ + 16a + 10b)/27` and `t_b = (10a + 16b + p₂)/27` are
//! inserted, and a vertex inside a feature curve moves to `(4p₋₁ + 19p + 4p₁)/27`. A
//! triangle `(a, b, x)` on the feature edge gets no centroid: it is fanned from `x` into
//! `(a, t_a, x)`, `(t_a, t_b, x)`, `(t_b, b, x)`, and the flips of its edges `xa` and `bx` use
//! `t_a` and `t_b` where another triangle uses its centroid. (After an odd step every
//! triangle has at most one feature edge, so this is well defined.) CGAL's
//! `Sqrt3_subdivision` and OpenMesh's `Sqrt3T` do the same, counting steps within one call. Over two steps the curve is the
//! ternary subdivision with mask `(1, 4, 10, 16, 19, 16, 10, 4, 1)/27`, the uniform cubic
//! B-spline's, so a boundary of the limit surface is the cubic B-spline of the base boundary
//! polygon. Corners (corner tags, or three or more feature edges) stay put; at the end of a
//! curve the missing neighbour is reflected (`p₋₁ = 2a − b`).
//!
//! Vertex order of a level: the old vertices, the face centroids in face order (faces
//! without one skipped), then (even steps) two points per feature edge in edge order, the one
//! next to the edge's first vertex first. Faces: per edge in edge order, the triangles it
//! makes (for a feature edge, those of its first face, then its second).

use crate::facts::{Capability, FaceKind, SPLIT_TAGS, SchemeFacts, Split};
use std::f64::consts::TAU;

use subd_mesh::{Topology, TopologyParts};

use super::{ChildFaces, Features, SplitRule, StepError, Weights, check_size};

/// Kobbelt's `α_n`.
pub fn alpha(n: usize) -> f64 {
    (4.0 - 2.0 * (TAU / n as f64).cos()) / 9.0
}

/// One √3 step over a parent level.
pub(crate) struct Step<'a> {
    p: &'a Topology,
    trisect: bool,
    features: Features,
    /// The feature edge of each face on a trisecting step (after an odd step a face has at
    /// most one): such a face gets no centroid and is fanned from its opposite vertex.
    fan_edge: Vec<Option<u8>>,
    /// Child index of each face's centroid (`u32::MAX` for fanned faces).
    centroid_of: Vec<u32>,
    centroid_faces: Vec<u32>,
    /// First of the two trisection points of each feature edge (`u32::MAX` elsewhere).
    trisection: Vec<u32>,
    feature_edges: Vec<u32>,
    num_child: usize,
}

impl<'a> Step<'a> {
    pub(crate) fn new(p: &'a Topology, trisect: bool) -> Step<'a> {
        let nv = p.num_vertices();
        let features = Features::new(p);
        let fan_edge: Vec<Option<u8>> = (0..p.num_faces())
            .map(|f| {
                if !trisect {
                    return None;
                }
                p.face_edges(f)
                    .iter()
                    .position(|&e| features.is_feature_edge(e as usize))
                    .map(|i| i as u8)
            })
            .collect();
        let mut next = nv as u32;
        let mut centroid_faces = Vec::with_capacity(p.num_faces());
        let centroid_of: Vec<u32> = fan_edge
            .iter()
            .enumerate()
            .map(|(f, fan)| {
                if fan.is_some() {
                    u32::MAX
                } else {
                    centroid_faces.push(f as u32);
                    next += 1;
                    next - 1
                }
            })
            .collect();
        let mut feature_edges = Vec::new();
        let trisection: Vec<u32> = (0..p.num_edges())
            .map(|e| {
                if trisect && features.is_feature_edge(e) {
                    feature_edges.push(e as u32);
                    next += 2;
                    next - 2
                } else {
                    u32::MAX
                }
            })
            .collect();
        Step {
            p,
            trisect,
            features,
            fan_edge,
            centroid_of,
            centroid_faces,
            trisection,
            feature_edges,
            num_child: next as usize,
        }
    }

    /// The trisection point of feature edge `e` next to its end `v`.
    fn third(&self, e: u32, v: u32) -> u32 {
        self.trisection[e as usize] + u32::from(self.p.edge_vertices(e as usize)[1] == v)
    }

    /// What stands in for face `f`'s centroid in the flip of its edge at `pos` (from corner
    /// `pos` to `pos + 1`): the centroid, or for a fanned face the trisection point next to
    /// the corner the flipped edge shares with the feature edge.
    fn apex(&self, f: usize, pos: usize) -> u32 {
        match self.fan_edge[f] {
            None => self.centroid_of[f],
            Some(fe) => {
                let fe = fe as usize;
                let fv = self.p.face_vertices(f);
                let shared = if (fe + 1) % 3 == pos {
                    fv[pos]
                } else {
                    fv[(pos + 1) % 3]
                };
                self.third(self.p.face_edges(f)[fe], shared)
            }
        }
    }

    /// `(p₋₁ + 16 near + 10 far)/27`, `p₋₁` reflected at a curve end.
    fn curve_point<W: Weights>(&self, near: u32, far: u32, e: u32, w: &mut W) {
        w.add(near, 16.0 / 27.0);
        w.add(far, 10.0 / 27.0);
        match self.features.curve_neighbour(self.p, near, e) {
            Some(n) => w.add(n, 1.0 / 27.0),
            None => {
                w.add(near, 2.0 / 27.0);
                w.add(far, -1.0 / 27.0);
            }
        }
    }
}

/// Infinitely sharp creases and corner tags of the child level: a crease edge's children (the
/// edge itself on odd steps, its three thirds on even steps) stay creases; corner tags stay
/// on their vertices.
fn carry_tags(p: &Topology, features: &Features, trisection: &[u32], child: &mut ChildFaces) {
    for (e, &t) in trisection.iter().enumerate() {
        if !features.is_feature_edge(e) || p.is_boundary_edge(e) {
            continue;
        }
        let [a, b] = p.edge_vertices(e);
        if t == u32::MAX {
            child.creases.push([a, b]);
        } else {
            child.creases.extend([[a, t], [t, t + 1], [t + 1, b]]);
        }
    }
    for v in 0..p.num_vertices() {
        let s = p.vertex_sharpness(v);
        if s > 0.0 {
            child.corners.push((v as u32, s));
        }
    }
}

impl SplitRule for Step<'_> {
    fn num_rows(&self) -> usize {
        self.num_child
    }

    #[inline]
    fn fill<W: Weights>(&self, r: usize, w: &mut W) {
        let p = self.p;
        let nv = p.num_vertices();
        let num_centroids = self.centroid_faces.len();
        if r < nv {
            let v = r as u32;
            let f = &self.features;
            if f.is_corner(r) || (f.is_curve_vertex(r) && !self.trisect) {
                w.add(v, 1.0);
            } else if f.is_curve_vertex(r) {
                let [e0, e1] = f.curve_edges(r);
                w.add(p.edge_other_vertex(e0 as usize, v), 4.0 / 27.0);
                w.add(v, 19.0 / 27.0);
                w.add(p.edge_other_vertex(e1 as usize, v), 4.0 / 27.0);
            } else if p.vertex_faces(r).is_empty() {
                w.add(v, 1.0);
            } else {
                let n = p.valence(r);
                let a = alpha(n);
                w.add(v, 1.0 - a);
                for u in p.vertex_ring(r) {
                    w.add(u, a / n as f64);
                }
            }
        } else if r < nv + num_centroids {
            for &x in p.face_vertices(self.centroid_faces[r - nv] as usize) {
                w.add(x, 1.0 / 3.0);
            }
        } else {
            let i = r - nv - num_centroids;
            let e = self.feature_edges[i / 2];
            let [a, b] = p.edge_vertices(e as usize);
            if i % 2 == 0 {
                self.curve_point(a, b, e, w);
            } else {
                self.curve_point(b, a, e, w);
            }
        }
    }

    fn child_faces(&self) -> Result<ChildFaces, StepError> {
        let p = self.p;
        check_size(9 * p.num_faces() as u64 + 9 * p.num_edges() as u64)?;
        if super::sqrt3_split::applies(p, &self.features) {
            // The same faces, written in parallel; no tag but corners to carry.
            let verts = super::sqrt3_split::face_vertices(p);
            let mut faces = ChildFaces::triangles(self.num_child, verts);
            carry_tags(p, &self.features, &self.trisection, &mut faces);
            return Ok(faces);
        }
        let mut verts: Vec<u32> = Vec::with_capacity(9 * p.num_faces());
        for e in 0..p.num_edges() {
            let faces = p.edge_faces(e);
            let local = p.edge_face_local_indices(e);
            if !self.features.is_feature_edge(e) {
                let (f0, k0) = (faces[0] as usize, local[0] as usize);
                let fv = p.face_vertices(f0);
                let (a, b) = (fv[k0], fv[(k0 + 1) % 3]);
                let c0 = self.apex(f0, k0);
                let c1 = self.apex(faces[1] as usize, local[1] as usize);
                verts.extend([a, c1, c0, c1, b, c0]);
                continue;
            }
            for (&f, &k) in faces.iter().zip(local) {
                let fv = p.face_vertices(f as usize);
                let k = k as usize;
                let (a, b, x) = (fv[k], fv[(k + 1) % 3], fv[(k + 2) % 3]);
                if self.trisect {
                    // The middle of the fan; its two outer triangles come from the flips
                    // of the face's other edges.
                    verts.extend([self.third(e as u32, a), self.third(e as u32, b), x]);
                } else {
                    verts.extend([a, b, self.centroid_of[f as usize]]);
                }
            }
        }
        let mut faces = ChildFaces::triangles(self.num_child, verts);
        carry_tags(p, &self.features, &self.trisection, &mut faces);
        Ok(faces)
    }

    /// In closed form where every edge is flipped ([`super::sqrt3_split`]); other levels are
    /// built from their faces.
    fn derived_topology(&self) -> Option<TopologyParts> {
        super::sqrt3_split::applies(self.p, &self.features)
            .then(|| super::sqrt3_split::split(self.p))
    }
}

/// √3's facts.
pub const FACTS: SchemeFacts = SchemeFacts {
    name: "sqrt3",
    summary: "Kobbelt's √3 scheme, triangles",
    input_faces: FaceKind::Triangles,
    split: Split::Sqrt3,
    interpolating: false,
    opensubdiv_family: false,
    tags: SPLIT_TAGS,
    peak_bytes_per_vertex: (235, None),
    capabilities: &[Capability::Refine, Capability::Limit, Capability::Analyse],
};
