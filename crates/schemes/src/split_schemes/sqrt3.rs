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

use std::f64::consts::TAU;

use subd_mesh::{Topology, TopologyBuilder, tags};

use super::{Features, SplitLevel, StepError, check_size};
use crate::StencilTable;

/// Kobbelt's `α_n`.
pub fn alpha(n: usize) -> f64 {
    (4.0 - 2.0 * (TAU / n as f64).cos()) / 9.0
}

/// What stands in for a face's centroid in the flip of one of its edges.
enum Apex {
    /// The face's centroid (child vertex index).
    Centroid(u32),
    /// A face with a feature edge on a trisecting step: no centroid; the face is fanned from
    /// its opposite vertex, and an edge flip uses the trisection point next to the vertex the
    /// flipped edge shares with the feature edge. Holds the feature edge's position in the
    /// face.
    Fan(usize),
}

/// One √3 step; `trisect` on even steps.
pub(crate) fn refine(p: &Topology, trisect: bool) -> Result<SplitLevel, StepError> {
    let nv = p.num_vertices();
    let nf = p.num_faces();
    let features = Features::new(p);
    // The feature edge of each face on a trisecting step (after an odd step a face has at
    // most one).
    let fan_edge: Vec<Option<usize>> = (0..nf)
        .map(|f| {
            if !trisect {
                return None;
            }
            p.face_edges(f)
                .iter()
                .position(|&e| features.is_feature_edge(e as usize))
        })
        .collect();
    let mut next = nv as u32;
    let centroid_of: Vec<u32> = fan_edge
        .iter()
        .map(|fan| {
            if fan.is_some() {
                u32::MAX
            } else {
                next += 1;
                next - 1
            }
        })
        .collect();
    let num_centroids = next as usize - nv;
    // Trisection points of feature edges: index of the first of each edge's two.
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
    // The trisection point of feature edge `e` next to its end `v`.
    let third =
        |e: u32, v: u32| trisection[e as usize] + u32::from(p.edge_vertices(e as usize)[1] == v);
    let apex = |f: usize| match fan_edge[f] {
        None => Apex::Centroid(centroid_of[f]),
        Some(pos) => Apex::Fan(pos),
    };
    // The apex of face `f` for the flip of the edge at `pos` (from corner `pos` to `pos + 1`).
    let apex_for = |f: usize, pos: usize| match apex(f) {
        Apex::Centroid(c) => c,
        Apex::Fan(fe) => {
            let fv = p.face_vertices(f);
            // The flipped edge shares corner `pos` with the feature edge when the feature
            // edge ends there, else corner `pos + 1`.
            let shared = if (fe + 1) % 3 == pos {
                fv[pos]
            } else {
                fv[(pos + 1) % 3]
            };
            third(p.face_edges(f)[fe], shared)
        }
    };

    let mut verts: Vec<u32> = Vec::with_capacity(6 * p.num_edges());
    for e in 0..p.num_edges() {
        let faces = p.edge_faces(e);
        let local = p.edge_face_local_indices(e);
        if !features.is_feature_edge(e) {
            let (f0, k0) = (faces[0] as usize, local[0] as usize);
            let fv = p.face_vertices(f0);
            let (a, b) = (fv[k0], fv[(k0 + 1) % 3]);
            let c0 = apex_for(f0, k0);
            let c1 = apex_for(faces[1] as usize, local[1] as usize);
            verts.extend([a, c1, c0, c1, b, c0]);
            continue;
        }
        for (&f, &k) in faces.iter().zip(local) {
            let fv = p.face_vertices(f as usize);
            let k = k as usize;
            let (a, b, x) = (fv[k], fv[(k + 1) % 3], fv[(k + 2) % 3]);
            if trisect {
                // The middle of the fan; its two outer triangles come from the flips of the
                // face's other edges.
                verts.extend([third(e as u32, a), third(e as u32, b), x]);
            } else {
                verts.extend([a, b, centroid_of[f as usize]]);
            }
        }
    }
    let sizes = vec![3u32; verts.len() / 3];
    let mut topology = TopologyBuilder::new(num_child).build(&sizes, &verts)?;
    carry_tags(p, &features, &trisection, &mut topology);

    let centroid_faces: Vec<u32> = (0..nf as u32)
        .filter(|&f| fan_edge[f as usize].is_none())
        .collect();
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
        } else if r < nv + num_centroids {
            for &x in p.face_vertices(centroid_faces[r - nv] as usize) {
                sink.add(x, 1.0 / 3.0);
            }
        } else {
            let i = r - nv - num_centroids;
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
    for (e, &t) in trisection.iter().enumerate() {
        if !features.is_feature_edge(e) || p.is_boundary_edge(e) {
            continue;
        }
        let [a, b] = p.edge_vertices(e);
        let pieces: Vec<[u32; 2]> = if t == u32::MAX {
            vec![[a, b]]
        } else {
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
