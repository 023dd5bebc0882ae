//! The butterfly schemes on triangles: Dyn, Levin and Gregory's (1990) and Zorin, Schröder
//! and Sweldens' modified butterfly (1996); seed 001 §4 (d), (e).
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

use std::f64::consts::TAU;

use subd_mesh::Topology;

use super::{Features, SplitLevel, StepError};
use crate::{Options, RefineError, Refinement, RowSink, Scheme, StencilTable};

/// The rule for the point of an interior edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum EdgeRule {
    Classic { tension: f64 },
    Modified,
}

/// Zorin's weights `s_j` of the ring of an extraordinary vertex of valence `n` (`j = 0` is
/// the other end of the edge); the vertex itself weighs ¾.
pub fn zorin_weights(n: usize) -> Vec<f64> {
    match n {
        3 => vec![5.0 / 12.0, -1.0 / 12.0, -1.0 / 12.0],
        4 => vec![3.0 / 8.0, 0.0, -1.0 / 8.0, 0.0],
        _ => (0..n)
            .map(|j| {
                let t = TAU * j as f64 / n as f64;
                (0.25 + t.cos() + 0.5 * (2.0 * t).cos()) / n as f64
            })
            .collect(),
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
    fn add_to(self, sink: &mut RowSink, w: f64) {
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

/// Topology and features of the level being refined, with the stencil walks over it.
struct Level<'a> {
    t: &'a Topology,
    features: Features,
}

impl Level<'_> {
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
    fn curve_point(&self, e: usize, w: f64, sink: &mut RowSink) {
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
    fn butterfly_point(&self, e: usize, w: f64, sink: &mut RowSink) {
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
    fn zorin_point(&self, e: usize, a: u32, scale: f64, sink: &mut RowSink) {
        let t = self.t;
        let edges = t.vertex_edges(a as usize);
        let n = edges.len();
        let start = edges
            .iter()
            .position(|&x| x as usize == e)
            .expect("edge at its end");
        sink.add(a, 0.75 * scale);
        for (j, s) in zorin_weights(n).into_iter().enumerate() {
            let v = t.edge_other_vertex(edges[(start + j) % n] as usize, a);
            sink.add(v, s * scale);
        }
    }

    fn is_regular_for_modified(&self, v: u32) -> bool {
        self.features.is_on_feature(v as usize) || self.t.valence(v as usize) == 6
    }

    fn edge_point(&self, e: usize, rule: EdgeRule, sink: &mut RowSink) {
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

/// One butterfly step: Loop's split (and its tag propagation), butterfly masks.
pub(crate) fn refine(p: &Topology, rule: EdgeRule) -> Result<SplitLevel, StepError> {
    let split = Refinement::new(p, Scheme::Loop, &Options::default(), 1).map_err(|e| match e {
        RefineError::TooLarge { .. } => StepError::TooLarge,
        other => unreachable!("checked before the first step: {other}"),
    })?;
    let level = Level {
        t: p,
        features: Features::new(p),
    };
    let nv = p.num_vertices();
    let stencils = StencilTable::build(nv + p.num_edges(), nv, |r, sink| {
        if r < nv {
            sink.add(r as u32, 1.0);
        } else {
            level.edge_point(r - nv, rule, sink);
        }
    });
    Ok(SplitLevel {
        topology: split.into_topology(1),
        stencils,
    })
}
