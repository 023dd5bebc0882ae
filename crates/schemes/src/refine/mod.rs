//! One uniform refinement step: child topology, child tags and rules, and the stencils that
//! give child vertices from parent vertices, following OpenSubdiv's Far/Vtr/Sdc behaviour.

mod split;

use subd_mesh::tags::{SHARPNESS_INFINITE, is_infinite, is_semi_sharp};
use subd_mesh::{BoundaryInterpolation, CreaseMethod, Topology, TriangleSubdivision};

use crate::rules::{self, Rule};
use crate::stencil::{RowSink, StencilTable};
use crate::{Options, Scheme};

/// A refinement level: topology with its tags (sharpness after the boundary rules) and the
/// rule of every vertex.
#[derive(Debug, Clone)]
pub(crate) struct Level {
    pub topology: Topology,
    pub rules: Vec<Rule>,
}

/// OpenSubdiv's notion of a non-manifold vertex includes isolated ones.
fn nm_vertex(t: &Topology, v: usize) -> bool {
    t.is_non_manifold_vertex(v) || t.is_isolated_vertex(v)
}

/// Applies the boundary rules to the base level and determines its vertex rules
/// (`Far::TopologyRefinerFactoryBase::prepareComponentTagsAndSharpness`): boundary and
/// non-manifold edges become infinitely sharp, non-manifold vertices (except interior "fin"
/// vertices) and, with edge-and-corner, one-face corners become infinitely sharp, and with
/// boundary `None` the faces around unsharpened boundaries become holes.
pub(crate) fn prepare_base(base: &Topology, scheme: Scheme, options: &Options) -> Level {
    let mut t = base.clone();
    if options.boundary_interpolation == BoundaryInterpolation::None && scheme != Scheme::Bilinear {
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
    Level { topology: t, rules }
}

/// Sharpness of the half of parent edge `e` at its end vertex `u`.
fn half_sharpness(p: &Topology, e: usize, u: usize, method: CreaseMethod) -> f32 {
    let s = p.edge_sharpness(e);
    if method == CreaseMethod::Chaikin && is_semi_sharp(s) {
        let around = p
            .vertex_edges(u)
            .iter()
            .map(|&x| p.edge_sharpness(x as usize));
        rules::child_edge_sharpness(s, method, around)
    } else {
        rules::child_edge_sharpness(s, method, std::iter::empty())
    }
}

/// Where the children of a parent level live in the child level.
#[derive(Clone, Copy)]
struct Layout {
    /// First face-child vertex (quad split) — equal to `edge_vertex_base` for Loop.
    face_vertex_base: u32,
    /// First edge-child vertex.
    edge_vertex_base: u32,
    /// First child edge that is a half of a parent edge.
    half_edge_base: u32,
}

/// Refines `parent` one level: the child level and the stencils of its vertices.
pub(crate) fn refine_level(
    parent: &Level,
    scheme: Scheme,
    options: &Options,
) -> (Level, StencilTable) {
    let p = &parent.topology;
    let method = options.crease_method;
    let (nv, nf, ne) = (
        p.num_vertices() as u32,
        p.num_faces() as u32,
        p.num_edges() as u32,
    );
    let (mut child, layout) = match scheme {
        Scheme::Loop => (
            split::tri_split(p),
            Layout {
                face_vertex_base: nv,
                edge_vertex_base: nv,
                half_edge_base: 3 * nf,
            },
        ),
        Scheme::CatmullClark | Scheme::Bilinear => (
            split::quad_split(p),
            Layout {
                face_vertex_base: nv,
                edge_vertex_base: nv + nf,
                half_edge_base: p.num_face_vertices() as u32,
            },
        ),
    };

    // Holes: children of holes are holes.
    for f in 0..nf as usize {
        if p.is_hole(f) {
            let children = match scheme {
                Scheme::Loop => 4 * f..4 * f + 4,
                _ => p.face_offsets()[f] as usize..p.face_offsets()[f + 1] as usize,
            };
            for c in children {
                child.set_hole(c, true);
            }
        }
    }
    // Edge sharpness: interior child edges are smooth, halves decay.
    for e in 0..ne as usize {
        let [a, b] = p.edge_vertices(e);
        let h = layout.half_edge_base as usize + 2 * e;
        child.set_edge_sharpness(h, half_sharpness(p, e, a as usize, method));
        child.set_edge_sharpness(h + 1, half_sharpness(p, e, b as usize, method));
    }
    // Vertex sharpness: only vertex-children inherit (decayed).
    for v in 0..nv as usize {
        child.set_vertex_sharpness(v, rules::child_vertex_sharpness(p.vertex_sharpness(v)));
    }

    // Rules (`Vtr::Refinement::propagateComponentTags` and `reclassifySemisharpVertices`).
    let mut child_rules = vec![Rule::Smooth; child.num_vertices()];
    for v in 0..nv as usize {
        let mut rule = parent.rules[v];
        let (ps, cs) = (p.vertex_sharpness(v), child.vertex_sharpness(v));
        let semi_edges = p
            .vertex_edges(v)
            .iter()
            .any(|&e| is_semi_sharp(p.edge_sharpness(e as usize)));
        if (is_semi_sharp(ps) || semi_edges) && (semi_edges || (ps > 0.0 && cs <= 0.0)) && cs <= 0.0
        {
            let sharp = p
                .vertex_edges(v)
                .iter()
                .filter(|&&e| half_sharpness(p, e as usize, v, method) > 0.0)
                .count();
            rule = Rule::determine(0.0, sharp);
        }
        child_rules[v] = rule;
    }
    for e in 0..ne as usize {
        let s = p.edge_sharpness(e);
        let h = layout.half_edge_base as usize + 2 * e;
        let rule = if is_infinite(s) {
            Rule::Crease
        } else if s > 0.0 {
            let semi = [h, h + 1]
                .iter()
                .filter(|&&c| child.edge_sharpness(c) > 0.0)
                .count();
            [Rule::Smooth, Rule::Dart, Rule::Crease][semi]
        } else {
            Rule::Smooth
        };
        child_rules[(layout.edge_vertex_base + e as u32) as usize] = rule;
    }

    let stencils = match scheme {
        Scheme::Bilinear => bilinear_stencils(p, layout, child.num_vertices()),
        _ => smooth_stencils(parent, &child, &child_rules, scheme, options, layout),
    };
    (
        Level {
            topology: child,
            rules: child_rules,
        },
        stencils,
    )
}

/// Adds the face point of parent face `f`, times `w`, to a row: `w/n` on each face vertex.
#[inline]
fn add_face_point(p: &Topology, f: usize, w: f64, sink: &mut RowSink) {
    let fv = p.face_vertices(f);
    let inv = 1.0 / fv.len() as f64;
    for &v in fv {
        sink.add(v, w * inv);
    }
}

fn bilinear_stencils(p: &Topology, layout: Layout, num_rows: usize) -> StencilTable {
    let nv = p.num_vertices();
    StencilTable::build(num_rows, nv, |r, sink| {
        let r32 = r as u32;
        if r < nv {
            sink.add(r32, 1.0);
        } else if r32 < layout.edge_vertex_base {
            add_face_point(p, (r32 - layout.face_vertex_base) as usize, 1.0, sink);
        } else {
            let [a, b] = p.edge_vertices((r32 - layout.edge_vertex_base) as usize);
            sink.add(a, 0.5);
            sink.add(b, 0.5);
        }
    })
}

/// Weights of a vertex mask: on the vertex, on each incident edge's far end (vertex-edge
/// order) and on each incident face (vertex-face order; face points for Catmull-Clark).
#[derive(Default, Clone)]
struct VertexMask {
    vertex: f64,
    edges: Option<Vec<f64>>,
    faces: Option<Vec<f64>>,
}

fn smooth_vertex_mask(p: &Topology, v: usize, scheme: Scheme) -> VertexMask {
    let nf = p.vertex_faces(v).len();
    let ne = p.valence(v);
    match scheme {
        Scheme::Loop => {
            let (e, vw) = loop_smooth_weights(nf);
            VertexMask {
                vertex: vw,
                edges: Some(vec![e; ne]),
                faces: None,
            }
        }
        _ => {
            let n = nf as f64;
            let w = 1.0 / (nf * nf) as f64;
            VertexMask {
                vertex: (n - 2.0) / n,
                edges: Some(vec![w; ne]),
                faces: Some(vec![w; nf]),
            }
        }
    }
}

/// Loop's smooth vertex weights (edge weight, vertex weight) for valence `n`
/// (`Sdc::Scheme<SCHEME_LOOP>::assignSmoothMaskForVertex`).
fn loop_smooth_weights(n: usize) -> (f64, f64) {
    if n == 6 {
        return (0.0625, 0.625);
    }
    let inv = 1.0 / n as f64;
    let cos_t = (std::f64::consts::PI * 2.0 * inv).cos();
    let beta = 0.25 * cos_t + 0.375;
    let e = (0.625 - beta * beta) * inv;
    (e, 1.0 - e * n as f64)
}

fn crease_vertex_mask(ne: usize, pair: (usize, usize)) -> VertexMask {
    let mut edges = vec![0.0; ne];
    edges[pair.0] = 0.125;
    edges[pair.1] = 0.125;
    VertexMask {
        vertex: 0.75,
        edges: Some(edges),
        faces: None,
    }
}

fn corner_vertex_mask() -> VertexMask {
    VertexMask {
        vertex: 1.0,
        edges: None,
        faces: None,
    }
}

fn mask_for_rule(
    p: &Topology,
    v: usize,
    rule: Rule,
    scheme: Scheme,
    edge_sharpness: &[f32],
) -> VertexMask {
    match rule {
        Rule::Smooth | Rule::Dart => smooth_vertex_mask(p, v, scheme),
        Rule::Crease => crease_vertex_mask(p.valence(v), rules::crease_pair(edge_sharpness)),
        Rule::Corner => corner_vertex_mask(),
    }
}

/// Blends two masks: `pw · parent + (1 − pw) · child` (`Sdc::Scheme::LocalMask::
/// CombineVertexVertexMasks`).
fn combine(parent: VertexMask, child: VertexMask, pw: f64) -> VertexMask {
    let cw = 1.0 - pw;
    let mix = |a: Option<Vec<f64>>, b: Option<Vec<f64>>| match (a, b) {
        (None, None) => None,
        (Some(a), None) => Some(a.iter().map(|x| pw * x).collect()),
        (None, Some(b)) => Some(b.iter().map(|x| cw * x).collect()),
        (Some(a), Some(b)) => Some(a.iter().zip(&b).map(|(x, y)| pw * x + cw * y).collect()),
    };
    VertexMask {
        vertex: pw * parent.vertex + cw * child.vertex,
        edges: mix(parent.edges, child.edges),
        faces: mix(parent.faces, child.faces),
    }
}

fn smooth_stencils(
    parent: &Level,
    child: &Topology,
    child_rules: &[Rule],
    scheme: Scheme,
    options: &Options,
    layout: Layout,
) -> StencilTable {
    let p = &parent.topology;
    let nv = p.num_vertices();
    let method = options.crease_method;
    StencilTable::build(child.num_vertices(), nv, |r, sink| {
        let r32 = r as u32;
        if r < nv {
            vertex_row(parent, child, child_rules, scheme, method, r, sink);
        } else if r32 < layout.edge_vertex_base {
            add_face_point(p, (r32 - layout.face_vertex_base) as usize, 1.0, sink);
        } else {
            let e = (r32 - layout.edge_vertex_base) as usize;
            edge_row(
                p,
                e,
                child_rules[r],
                scheme,
                options.triangle_subdivision,
                sink,
            );
        }
    })
}

/// Stencil of the child of parent edge `e` (`Sdc::Scheme::ComputeEdgeVertexMask`).
fn edge_row(
    p: &Topology,
    e: usize,
    child_rule: Rule,
    scheme: Scheme,
    tri: TriangleSubdivision,
    sink: &mut RowSink,
) {
    let [a, b] = p.edge_vertices(e);
    let s = p.edge_sharpness(e);
    if s > 0.0 && child_rule == Rule::Crease {
        sink.add(a, 0.5);
        sink.add(b, 0.5);
        return;
    }
    let faces = p.edge_faces(e);
    let nf = faces.len();
    let (mut vw, mut fw) = match scheme {
        Scheme::Loop => (
            0.375,
            if nf == 2 {
                0.125
            } else {
                0.125 * 2.0 / nf as f64
            },
        ),
        _ => {
            if nf == 2 {
                if tri == TriangleSubdivision::Smooth
                    && (p.face_size(faces[0] as usize) == 3 || p.face_size(faces[1] as usize) == 3)
                {
                    let wt = |f: u32| {
                        if p.face_size(f as usize) == 3 {
                            0.470
                        } else {
                            0.25
                        }
                    };
                    let f = 0.5 * (wt(faces[0]) + wt(faces[1]));
                    (0.5 * (1.0 - 2.0 * f), f)
                } else {
                    (0.25, 0.25)
                }
            } else {
                (0.25, 0.5 / nf as f64)
            }
        }
    };
    if s > 0.0 {
        // A semi-sharp edge whose child is no longer a crease: blend by the parent sharpness
        // (not clamped: Chaikin can extrapolate).
        let pw = s as f64;
        let cw = 1.0 - pw;
        vw = pw * 0.5 + cw * vw;
        fw *= cw;
    }
    sink.add(a, vw);
    sink.add(b, vw);
    let locals = p.edge_face_local_indices(e);
    for (&f, &l) in faces.iter().zip(locals) {
        match scheme {
            Scheme::Loop => {
                let fv = p.face_vertices(f as usize);
                // The vertex opposite the edge; the edge's first position in the face.
                let k = p
                    .face_edges(f as usize)
                    .iter()
                    .position(|&x| x as usize == e)
                    .unwrap_or(l as usize);
                sink.add(fv[(k + 2) % 3], fw);
            }
            _ => add_face_point(p, f as usize, fw, sink),
        }
    }
}

/// Stencil of the child of parent vertex `v` (`Sdc::Scheme::ComputeVertexVertexMask`).
fn vertex_row(
    parent: &Level,
    child: &Topology,
    child_rules: &[Rule],
    scheme: Scheme,
    method: CreaseMethod,
    v: usize,
    sink: &mut RowSink,
) {
    let p = &parent.topology;
    let prule = parent.rules[v];
    let crule = child_rules[v];
    let pe: Vec<f32> = p
        .vertex_edges(v)
        .iter()
        .map(|&e| p.edge_sharpness(e as usize))
        .collect();
    let mask = match prule {
        Rule::Smooth | Rule::Dart => smooth_vertex_mask(p, v, scheme),
        _ => {
            let pmask = mask_for_rule(p, v, prule, scheme, &pe);
            if crule == prule {
                pmask
            } else {
                let ce: Vec<f32> = p
                    .vertex_edges(v)
                    .iter()
                    .map(|&e| half_sharpness(p, e as usize, v, method))
                    .collect();
                let cmask = mask_for_rule(p, v, crule, scheme, &ce);
                let pw = rules::fractional_weight(
                    p.vertex_sharpness(v),
                    child.vertex_sharpness(v),
                    &pe,
                    &ce,
                    method,
                );
                combine(pmask, cmask, pw as f64)
            }
        }
    };
    if let Some(fw) = &mask.faces {
        for (&f, &w) in p.vertex_faces(v).iter().zip(fw) {
            add_face_point(p, f as usize, w, sink);
        }
    }
    if let Some(ew) = &mask.edges {
        for (&e, &w) in p.vertex_edges(v).iter().zip(ew) {
            sink.add(p.edge_other_vertex(e as usize, v as u32), w);
        }
    }
    sink.add(v as u32, mask.vertex);
}
