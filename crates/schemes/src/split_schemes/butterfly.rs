//! The butterfly schemes on triangles: Dyn, Levin and Gregory's (1990) and Zorin, Schröder
//! and Sweldens' modified butterfly (1996); the subdivision lecture notes §4 (d), (e).
//!
//! Both split every triangle into four as Loop does (old vertices first, then one point per
//! edge in edge order; faces as [`crate::Refinement`] orders Loop's) and keep every old vertex
//! where it is. They differ in the point of an edge `(a, b)` with opposite vertices `c`, `d`
//! and the four "wing" vertices across the edges `ac`, `cb`, `ad`, `db`:
//!
//! * **Butterfly** with tension `w`: `½(a + b) + 2w(c + d) − w Σ wings` (`w = 1/16` is the
//!   classic scheme).
//! * **Modified butterfly**: the butterfly with `w = 1/16` when both ends have valence 6; when
//!   one end `a` has another valence `n`, Zorin's rule over its ring `v_0 = b, v_1, …` (in
//!   order around `a`): `¾a + Σ s_j v_j` with `s_j = (¼ + cos(2πj/n) + ½cos(4πj/n))/n` for
//!   `n ≥ 5`, `s = (5/12, −1/12, −1/12)` for `n = 3` and `(3/8, 0, −1/8, 0)` for `n = 4`; the
//!   average of the two ends' rules when both are extraordinary.
//!
//! **Boundaries and creases** (both schemes, the rule OpenMesh's `ModifiedButterflyT` uses):
//! a boundary edge or an infinitely sharp crease edge gets the 4-point rule along its curve,
//! `−w p₋₁ + (½ + w)(a + b) − w p₂` (`w = 1/16` for the modified scheme), with a missing
//! neighbour at a curve end or corner reflected (`p₋₁ = 2a − b`). A wing or opposite vertex
//! that lies across a boundary or crease is reflected through the edge it would be seen
//! across (`x + y − z` for the vertex `z` on this side of edge `xy`). In the modified scheme
//! the ends of an edge that lie on a boundary or crease count as regular.

use crate::facts::{Capability, FaceKind, SPLIT_TAGS, SchemeFacts, Split, TagSupport};
use std::f64::consts::TAU;

use rayon::prelude::*;
use subd_mesh::{Topology, TopologyParts, tags};

use super::{ChildFaces, Features, SplitRule, StepError, Weights, check_size};

/// The rule for the point of an interior edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum EdgeRule {
    Classic { tension: f64 },
    Modified,
}

/// Zorin's weight `s_j` of ring vertex `j` of an extraordinary vertex of valence `n`
/// (`j = 0` is the other end of the edge); the vertex itself weighs ¾.
pub fn zorin_weight(n: usize, j: usize) -> f64 {
    match n {
        3 => [5.0 / 12.0, -1.0 / 12.0, -1.0 / 12.0][j],
        4 => [3.0 / 8.0, 0.0, -1.0 / 8.0, 0.0][j],
        _ => {
            let t = TAU * j as f64 / n as f64;
            (0.25 + t.cos() + 0.5 * (2.0 * t).cos()) / n as f64
        }
    }
}

/// A vertex of the butterfly stencil, or its reflection when it lies across a feature.
#[derive(Clone, Copy)]
enum Point {
    Vertex(u32),
    /// `x + y − z`.
    Reflected(u32, u32, u32),
}

impl Point {
    fn add_to<W: Weights>(self, sink: &mut W, w: f64) {
        match self {
            Point::Vertex(v) => sink.add(v, w),
            Point::Reflected(x, y, z) => {
                sink.add(x, w);
                sink.add(y, w);
                sink.add(z, -w);
            }
        }
    }
}

/// One butterfly step over a parent level: its features and edge rule.
pub(crate) struct Step<'a> {
    t: &'a Topology,
    features: Features,
    rule: EdgeRule,
}

impl<'a> Step<'a> {
    pub(crate) fn new(t: &'a Topology, rule: EdgeRule) -> Step<'a> {
        Step {
            t,
            features: Features::new(t),
            rule,
        }
    }

    /// The vertex across edge `pos` of triangle `f` (the edge from corner `pos` to
    /// `pos + 1`), or that edge's reflection of `f`'s own third vertex when the edge is a
    /// feature.
    fn across(&self, f: usize, pos: usize) -> Point {
        let t = self.t;
        let e = t.face_edges(f)[pos] as usize;
        let fv = t.face_vertices(f);
        let (x, y, z) = (fv[pos], fv[(pos + 1) % 3], fv[(pos + 2) % 3]);
        if self.features.is_feature_edge(e) {
            return Point::Reflected(x, y, z);
        }
        let faces = t.edge_faces(e);
        let local = t.edge_face_local_indices(e);
        let i = usize::from(faces[0] as usize == f);
        let g = faces[i] as usize;
        Point::Vertex(t.face_vertices(g)[(local[i] as usize + 2) % 3])
    }

    /// Point of feature edge `e` by the 4-point rule along its curve.
    fn curve_point<W: Weights>(&self, e: usize, w: f64, sink: &mut W) {
        let t = self.t;
        let [a, b] = t.edge_vertices(e);
        for (near, far) in [(a, b), (b, a)] {
            sink.add(near, 0.5 + w);
            match self.features.curve_neighbour(t, near, e as u32) {
                Some(n) => sink.add(n, -w),
                None => Point::Reflected(near, near, far).add_to(sink, -w),
            }
        }
    }

    /// The butterfly stencil of interior edge `e` with tension `w`.
    fn butterfly_point<W: Weights>(&self, e: usize, w: f64, sink: &mut W) {
        let t = self.t;
        let faces = t.edge_faces(e);
        let local = t.edge_face_local_indices(e);
        let [a, b] = t.edge_vertices(e);
        sink.add(a, 0.5);
        sink.add(b, 0.5);
        for (&f, &k) in faces.iter().zip(local) {
            let (f, k) = (f as usize, k as usize);
            // Opposite vertex of this face, then the wings across its two other edges.
            sink.add(t.face_vertices(f)[(k + 2) % 3], 2.0 * w);
            self.across(f, (k + 1) % 3).add_to(sink, -w);
            self.across(f, (k + 2) % 3).add_to(sink, -w);
        }
    }

    /// Zorin's rule at extraordinary end `a` of edge `e` (weight `scale` for averaging).
    fn zorin_point<W: Weights>(&self, e: usize, a: u32, scale: f64, sink: &mut W) {
        let t = self.t;
        let edges = t.vertex_edges(a as usize);
        let n = edges.len();
        let start = edges
            .iter()
            .position(|&x| x as usize == e)
            .expect("edge at its end");
        sink.add(a, 0.75 * scale);
        for j in 0..n {
            let v = t.edge_other_vertex(edges[(start + j) % n] as usize, a);
            sink.add(v, zorin_weight(n, j) * scale);
        }
    }

    fn is_regular_for_modified(&self, v: u32) -> bool {
        self.features.is_on_feature(v as usize) || self.t.valence(v as usize) == 6
    }

    fn edge_point<W: Weights>(&self, e: usize, sink: &mut W) {
        let rule = self.rule;
        let w = match rule {
            EdgeRule::Classic { tension } => tension,
            EdgeRule::Modified => 1.0 / 16.0,
        };
        if self.features.is_feature_edge(e) {
            return self.curve_point(e, w, sink);
        }
        if rule == EdgeRule::Modified {
            let [a, b] = self.t.edge_vertices(e);
            match (
                self.is_regular_for_modified(a),
                self.is_regular_for_modified(b),
            ) {
                (true, true) => {}
                (false, true) => return self.zorin_point(e, a, 1.0, sink),
                (true, false) => return self.zorin_point(e, b, 1.0, sink),
                (false, false) => {
                    self.zorin_point(e, a, 0.5, sink);
                    return self.zorin_point(e, b, 0.5, sink);
                }
            }
        }
        self.butterfly_point(e, w, sink)
    }
}

impl SplitRule for Step<'_> {
    fn num_rows(&self) -> usize {
        self.t.num_vertices() + self.t.num_edges()
    }

    #[inline]
    fn fill<W: Weights>(&self, r: usize, w: &mut W) {
        let nv = self.t.num_vertices();
        if r < nv {
            w.add(r as u32, 1.0);
        } else {
            self.edge_point(r - nv, w);
        }
    }

    /// Loop's split: triangle `(v0, v1, v2)` with edge points `E_i` of its edges
    /// `(v_i, v_i+1)` becomes `(v0, E0, E2)`, `(E0, v1, E1)`, `(E2, E1, v2)`, `(E1, E2, E0)`;
    /// an interior crease's two halves stay creases, corner tags stay.
    fn child_faces(&self) -> Result<ChildFaces, StepError> {
        let t = self.t;
        let nv = t.num_vertices() as u32;
        check_size(12 * t.num_faces() as u64)?;
        // The same faces as OpenSubdiv's triangle split, written in parallel.
        let (offsets, verts) = crate::refine::split::tri_faces(t);
        let mut faces = ChildFaces::untagged(self.num_rows(), offsets, verts);
        faces.creases = (0..t.num_edges())
            .into_par_iter()
            .with_min_len(4096)
            .filter(|&e| !t.is_boundary_edge(e) && tags::is_infinite(t.edge_sharpness(e)))
            .flat_map_iter(|e| {
                let [a, b] = t.edge_vertices(e);
                [[a, nv + e as u32], [nv + e as u32, b]]
            })
            .collect();
        faces.corners = (0..t.num_vertices())
            .into_par_iter()
            .with_min_len(4096)
            .filter(|&v| t.vertex_sharpness(v) > 0.0)
            .map(|v| (v as u32, t.vertex_sharpness(v)))
            .collect();
        Ok(faces)
    }

    /// Loop's split is OpenSubdiv's triangle split: the relations come in closed form from
    /// the parent's ([`crate::refine::split::tri_split`], the faces of
    /// [`Self::child_faces`]).
    fn derived_topology(&self) -> Option<TopologyParts> {
        Some(crate::refine::split::tri_split(self.t))
    }
}

/// The butterfly's facts: interpolating, texture coordinates with seams carried by the
/// tension-0 butterfly.
pub const FACTS: SchemeFacts = SchemeFacts {
    name: "butterfly",
    summary: "The interpolating butterfly (Dyn, Levin, Gregory), triangles; tension w (butterfly:w, default 1/16)",
    input_faces: FaceKind::Triangles,
    split: Split::Triangle,
    interpolating: true,
    opensubdiv_family: false,
    tags: TagSupport {
        uv_seams: true,
        ..SPLIT_TAGS
    },
    peak_bytes_per_vertex: (190, None),
    capabilities: &[Capability::Refine, Capability::Limit, Capability::Analyse],
};

/// The modified butterfly's facts: the butterfly's, under its own name.
pub const MODIFIED_FACTS: SchemeFacts = SchemeFacts {
    name: "modified-butterfly",
    summary: "Zorin, Schröder and Sweldens' modified butterfly, triangles",
    ..FACTS
};
