//! Kobbelt's √3 scheme (SIGGRAPH 2000; seed 001 §4): triangles only.
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
//! trisected: its points `(p₋₁ + 16a + 10b)/27` and `(10a + 16b + p₂)/27` are inserted, each
//! of its triangles becomes `(a, t_a, c_f)`, `(t_a, t_b, c_f)`, `(t_b, b, c_f)`, and a vertex
//! inside a feature curve moves to `(4p₋₁ + 19p + 4p₁)/27`. Over two steps the curve is the
//! ternary subdivision with mask `(1, 4, 10, 16, 19, 16, 10, 4, 1)/27`, the uniform cubic
//! B-spline's, so a boundary of the limit surface is the cubic B-spline of the base boundary
//! polygon. Corners (corner tags, or three or more feature edges) stay put; at the end of a
//! curve the missing neighbour is reflected (`p₋₁ = 2a − b`).
//!
//! Vertex order of a level: the old vertices, the face centroids in face order, then (even
//! steps) two points per feature edge in edge order, the one next to the edge's first vertex
//! first. Faces: per edge in edge order, the triangles it makes (for a feature edge, those of
//! its first face, then its second).

use std::f64::consts::TAU;

use subd_mesh::{Topology, TopologyBuilder, tags};

use super::{Features, SplitLevel, StepError, check_size};
use crate::StencilTable;

/// Kobbelt's `α_n`.
pub fn alpha(n: usize) -> f64 {
    (4.0 - 2.0 * (TAU / n as f64).cos()) / 9.0
}

/// One √3 step; `trisect` on even steps.
pub(crate) fn refine(p: &Topology, trisect: bool) -> Result<SplitLevel, StepError> {
    let nv = p.num_vertices();
    let nf = p.num_faces();
    let features = Features::new(p);
    // Trisection points of feature edges: index of the first of each edge's two.
    let mut next = (nv + nf) as u32;
    let trisection: Vec<u32> = (0..p.num_edges())
        .map(|e| {
            if trisect && features.is_feature_edge(e) {
                next += 2;
                next - 2
            } else {
                u32::MAX
            }
        })
        .collect();
    let num_child = next as usize;
    check_size(9 * nf as u64 + 9 * p.num_edges() as u64)?;
    let centroid = |f: u32| (nv as u32) + f;

    let mut verts: Vec<u32> = Vec::with_capacity(6 * p.num_edges());
    for e in 0..p.num_edges() {
        let faces = p.edge_faces(e);
        let local = p.edge_face_local_indices(e);
        if !features.is_feature_edge(e) {
            let (f0, k0) = (faces[0], local[0] as usize);
            let fv = p.face_vertices(f0 as usize);
            let (a, b) = (fv[k0], fv[(k0 + 1) % 3]);
            let (c0, c1) = (centroid(f0), centroid(faces[1]));
            verts.extend([a, c1, c0, c1, b, c0]);
            continue;
        }
        let [e0, _] = p.edge_vertices(e);
        for (&f, &k) in faces.iter().zip(local) {
            let fv = p.face_vertices(f as usize);
            let (a, b) = (fv[k as usize], fv[(k as usize + 1) % 3]);
            let c = centroid(f);
            if trisect {
                // The trisection point next to `a` and the one next to `b`.
                let first = trisection[e];
                let (ta, tb) = if a == e0 {
                    (first, first + 1)
                } else {
                    (first + 1, first)
                };
                verts.extend([a, ta, c, ta, tb, c, tb, b, c]);
            } else {
                verts.extend([a, b, c]);
            }
        }
    }
    let sizes = vec![3u32; verts.len() / 3];
    let mut topology = TopologyBuilder::new(num_child).build(&sizes, &verts)?;
    carry_tags(p, &features, &trisection, &mut topology);

    let feature_edges: Vec<u32> = (0..p.num_edges() as u32)
        .filter(|&e| trisection[e as usize] != u32::MAX)
        .collect();
    let curve_point = |near: u32, far: u32, e: u32, sink: &mut crate::RowSink| {
        // (p₋₁ + 16 near + 10 far)/27, p₋₁ reflected at a curve end.
        sink.add(near, 16.0 / 27.0);
        sink.add(far, 10.0 / 27.0);
        match features.curve_neighbour(p, near, e) {
            Some(n) => sink.add(n, 1.0 / 27.0),
            None => {
                sink.add(near, 2.0 / 27.0);
                sink.add(far, -1.0 / 27.0);
            }
        }
    };
    let stencils = StencilTable::build(num_child, nv, |r, sink| {
        if r < nv {
            let v = r as u32;
            if features.is_corner(r) || (features.is_curve_vertex(r) && !trisect) {
                sink.add(v, 1.0);
            } else if features.is_curve_vertex(r) {
                let [e0, e1] = features.curve_edges(r);
                sink.add(p.edge_other_vertex(e0 as usize, v), 4.0 / 27.0);
                sink.add(v, 19.0 / 27.0);
                sink.add(p.edge_other_vertex(e1 as usize, v), 4.0 / 27.0);
            } else if p.vertex_faces(r).is_empty() {
                sink.add(v, 1.0);
            } else {
                let n = p.valence(r);
                let a = alpha(n);
                sink.add(v, 1.0 - a);
                for u in p.vertex_ring(r) {
                    sink.add(u, a / n as f64);
                }
            }
        } else if r < nv + nf {
            for &x in p.face_vertices(r - nv) {
                sink.add(x, 1.0 / 3.0);
            }
        } else {
            let i = r - nv - nf;
            let e = feature_edges[i / 2];
            let [a, b] = p.edge_vertices(e as usize);
            if i % 2 == 0 {
                curve_point(a, b, e, sink);
            } else {
                curve_point(b, a, e, sink);
            }
        }
    });
    Ok(SplitLevel { topology, stencils })
}

/// Infinitely sharp creases and corner tags of the child level: a crease edge's children (the
/// edge itself on odd steps, its three thirds on even steps) stay creases; corner tags stay
/// on their vertices.
fn carry_tags(p: &Topology, features: &Features, trisection: &[u32], child: &mut Topology) {
    for e in 0..p.num_edges() {
        if !features.is_feature_edge(e) || p.is_boundary_edge(e) {
            continue;
        }
        let [a, b] = p.edge_vertices(e);
        let pieces: Vec<[u32; 2]> = if trisection[e] == u32::MAX {
            vec![[a, b]]
        } else {
            let t = trisection[e];
            vec![[a, t], [t, t + 1], [t + 1, b]]
        };
        for [x, y] in pieces {
            if let Some(ce) = child.find_edge(x, y) {
                child.set_edge_sharpness(ce as usize, tags::SHARPNESS_INFINITE);
            }
        }
    }
    for v in 0..p.num_vertices() {
        let s = p.vertex_sharpness(v);
        if s > 0.0 {
            child.set_vertex_sharpness(v, s);
        }
    }
}
