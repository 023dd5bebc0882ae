//! The tags of a level as OpenSubdiv derives them: the base level's boundary rules and
//! vertex rules (`prepareComponentTagsAndSharpness`), and the sharpness a mesh file records
//! explicitly (what the boundary rules do not imply).

use subd_mesh::tags::{SHARPNESS_INFINITE, is_infinite};
use subd_mesh::{BoundaryInterpolation, Topology};

use super::{Layout, Sdc, half_sharpness};
use crate::Options;
use crate::rules::{self, Rule};

/// OpenSubdiv's notion of a non-manifold vertex includes isolated ones.
pub(super) fn nm_vertex(t: &Topology, v: usize) -> bool {
    t.is_non_manifold_vertex(v) || t.is_isolated_vertex(v)
}

/// Applies the boundary rules to the base level and determines its vertex rules
/// (`Far::TopologyRefinerFactoryBase::prepareComponentTagsAndSharpness`): boundary and
/// non-manifold edges become infinitely sharp, non-manifold vertices (except interior "fin"
/// vertices) and, with edge-and-corner, one-face corners become infinitely sharp, and with
/// boundary `None` the faces around unsharpened boundaries become holes.
pub(crate) fn prepare_base(
    base: &Topology,
    scheme: Sdc,
    options: &Options,
) -> (Topology, Vec<Rule>) {
    let mut t = base.clone();
    if options.boundary_interpolation == BoundaryInterpolation::None && scheme != Sdc::Bilinear {
        let mut holes = Vec::new();
        for v in 0..t.num_vertices() {
            let (ve, vf) = (t.vertex_edges(v), t.vertex_faces(v));
            if ve.len() == vf.len() && !nm_vertex(&t, v) {
                continue;
            }
            let open = ve.iter().any(|&e| {
                t.edge_faces(e as usize).len() == 1 && !is_infinite(t.edge_sharpness(e as usize))
            });
            if open {
                holes.extend_from_slice(vf);
            }
        }
        for f in holes {
            t.set_hole(f as usize, true);
        }
    }
    for e in 0..t.num_edges() {
        if t.is_boundary_edge(e) || t.is_non_manifold_edge(e) {
            t.set_edge_sharpness(e, SHARPNESS_INFINITE);
        }
    }
    let mut rules = Vec::with_capacity(t.num_vertices());
    for v in 0..t.num_vertices() {
        let (ve, nf) = (t.vertex_edges(v), t.vertex_faces(v).len());
        let (mut boundary, mut sharp, mut nm) = (0usize, 0usize, 0usize);
        for &e in ve {
            let e = e as usize;
            boundary += t.is_boundary_edge(e) as usize;
            sharp += (t.edge_sharpness(e) > 0.0) as usize;
            nm += t.is_non_manifold_edge(e) as usize;
        }
        let corner = nf == 1 && ve.len() == 2;
        if corner && options.boundary_interpolation == BoundaryInterpolation::EdgeAndCorner {
            t.set_vertex_sharpness(v, SHARPNESS_INFINITE);
        } else if nm_vertex(&t, v) {
            let fin = nm == 2 && boundary == 0 && nf > ve.len();
            if !fin {
                t.set_vertex_sharpness(v, SHARPNESS_INFINITE);
            }
        }
        rules.push(Rule::determine(t.vertex_sharpness(v), sharp));
    }
    (t, rules)
}

/// Whether the boundary rules make vertex `v` of `t` sharp whatever its tags say: a
/// non-manifold or isolated vertex, or a one-face corner under edge-and-corner interpolation.
fn implied_sharp_vertex(t: &Topology, v: usize, options: &Options) -> bool {
    let corner = t.vertex_faces(v).len() == 1 && t.valence(v) == 2;
    nm_vertex(t, v)
        || (corner && options.boundary_interpolation == BoundaryInterpolation::EdgeAndCorner)
}

/// [`crate::ExplicitTags`] of a built level.
pub(crate) fn explicit_tags(t: &Topology, options: &Options) -> crate::ExplicitTags {
    crate::ExplicitTags {
        creases: (0..t.num_edges())
            .filter(|&e| {
                t.edge_sharpness(e) > 0.0 && !t.is_boundary_edge(e) && !t.is_non_manifold_edge(e)
            })
            .map(|e| (t.edge_vertices(e), t.edge_sharpness(e)))
            .collect(),
        corners: (0..t.num_vertices())
            .filter(|&v| t.vertex_sharpness(v) > 0.0 && !implied_sharp_vertex(t, v, options))
            .map(|v| (v as u32, t.vertex_sharpness(v)))
            .collect(),
    }
}

/// [`crate::ExplicitTags`] of the child of `p`, from `p` alone: the values and order
/// [`child_topology`] would give. Only halves of parent edges can be sharp (half `k` of
/// edge `e` joins the edge point to end `k`, in edge order after the interior edges), and
/// they are boundary or non-manifold exactly when their parent edge is; only vertex
/// children keep a vertex sharpness, with their parent's face and edge counts and kind.
pub(crate) fn child_explicit_tags(
    p: &Topology,
    scheme: Sdc,
    options: &Options,
) -> crate::ExplicitTags {
    let method = options.crease_method;
    let edge_point_base = Layout::new(p, scheme).edge_vertex_base;
    let mut creases = Vec::new();
    for e in 0..p.num_edges() {
        if p.edge_sharpness(e) <= 0.0 || p.is_boundary_edge(e) || p.is_non_manifold_edge(e) {
            continue;
        }
        let ep = edge_point_base + e as u32;
        for u in p.edge_vertices(e) {
            let s = half_sharpness(p, e, u as usize, method);
            if s > 0.0 {
                creases.push(([ep, u], s));
            }
        }
    }
    let corners = (0..p.num_vertices())
        .filter(|&v| !implied_sharp_vertex(p, v, options))
        .map(|v| {
            (
                v as u32,
                rules::child_vertex_sharpness(p.vertex_sharpness(v)),
            )
        })
        .filter(|&(_, s)| s > 0.0)
        .collect();
    crate::ExplicitTags { creases, corners }
}
