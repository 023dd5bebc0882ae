//! Whole-mesh topological measures: components, Euler characteristic, genus, boundary loops,
//! histograms. What `subd info` prints.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::topology::Topology;

/// Union-find over `u32` indices with path halving and union by size.
struct DisjointSets {
    parent: Vec<u32>,
    size: Vec<u32>,
}

impl DisjointSets {
    fn new(n: usize) -> Self {
        DisjointSets {
            parent: (0..n as u32).collect(),
            size: vec![1; n],
        }
    }

    fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let p = self.parent[x as usize];
            self.parent[x as usize] = self.parent[p as usize];
            x = p;
        }
        x
    }

    fn union(&mut self, a: u32, b: u32) {
        let (mut ra, mut rb) = (self.find(a), self.find(b));
        if ra == rb {
            return;
        }
        if self.size[ra as usize] < self.size[rb as usize] {
            std::mem::swap(&mut ra, &mut rb);
        }
        self.parent[rb as usize] = ra;
        self.size[ra as usize] += self.size[rb as usize];
    }
}

/// One connected component (vertices joined through faces).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Component {
    /// Vertices in the component.
    pub vertices: usize,
    /// Edges in the component.
    pub edges: usize,
    /// Faces in the component.
    pub faces: usize,
    /// `V - E + F` of the component.
    pub euler: i64,
    /// No boundary edges.
    pub closed: bool,
    /// No non-manifold edges or vertices.
    pub manifold: bool,
    /// Genus, for a closed manifold component (consistently oriented by construction, since
    /// orientation conflicts make edges non-manifold); `None` otherwise.
    pub genus: Option<i64>,
}

/// Labels every vertex with its connected component (`u32::MAX` for isolated vertices) and
/// returns the number of components. Components are numbered by their lowest face.
pub fn component_labels(topo: &Topology) -> (Vec<u32>, usize) {
    let nv = topo.num_vertices();
    let mut sets = DisjointSets::new(nv);
    for f in 0..topo.num_faces() {
        let fv = topo.face_vertices(f);
        for w in fv.windows(2) {
            sets.union(w[0], w[1]);
        }
    }
    let mut root_label = vec![u32::MAX; nv];
    let mut labels = vec![u32::MAX; nv];
    let mut count = 0u32;
    for f in 0..topo.num_faces() {
        let r = sets.find(topo.face_vertices(f)[0]) as usize;
        if root_label[r] == u32::MAX {
            root_label[r] = count;
            count += 1;
        }
    }
    for (v, label) in labels.iter_mut().enumerate() {
        if !topo.is_isolated_vertex(v) {
            *label = root_label[sets.find(v as u32) as usize];
        }
    }
    (labels, count as usize)
}

/// The connected components of the mesh (isolated vertices excluded).
pub fn components(topo: &Topology) -> Vec<Component> {
    let (labels, n) = component_labels(topo);
    let mut comps = vec![
        Component {
            vertices: 0,
            edges: 0,
            faces: 0,
            euler: 0,
            closed: true,
            manifold: true,
            genus: None,
        };
        n
    ];
    for (v, &l) in labels.iter().enumerate() {
        if l != u32::MAX {
            let c = &mut comps[l as usize];
            c.vertices += 1;
            if topo.is_non_manifold_vertex(v) {
                c.manifold = false;
            }
        }
    }
    for e in 0..topo.num_edges() {
        let c = &mut comps[labels[topo.edge_vertices(e)[0] as usize] as usize];
        c.edges += 1;
        if topo.is_boundary_edge(e) {
            c.closed = false;
        }
        if topo.is_non_manifold_edge(e) {
            c.manifold = false;
        }
    }
    for f in 0..topo.num_faces() {
        comps[labels[topo.face_vertices(f)[0] as usize] as usize].faces += 1;
    }
    for c in &mut comps {
        c.euler = c.vertices as i64 - c.edges as i64 + c.faces as i64;
        if c.closed && c.manifold && (2 - c.euler) % 2 == 0 {
            c.genus = Some((2 - c.euler) / 2);
        }
    }
    comps
}

/// Number of closed loops formed by boundary edges (boundary edges joined at shared
/// vertices).
pub fn boundary_loops(topo: &Topology) -> usize {
    let mut sets = DisjointSets::new(topo.num_vertices());
    let mut on_boundary = vec![false; topo.num_vertices()];
    for e in 0..topo.num_edges() {
        if topo.is_boundary_edge(e) {
            let [a, b] = topo.edge_vertices(e);
            sets.union(a, b);
            on_boundary[a as usize] = true;
            on_boundary[b as usize] = true;
        }
    }
    (0..topo.num_vertices())
        .filter(|&v| on_boundary[v] && sets.find(v as u32) == v as u32)
        .count()
}

/// Summary of a topology: the numbers `subd info` reports.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TopologySummary {
    /// Number of vertices.
    pub vertices: usize,
    /// Number of edges.
    pub edges: usize,
    /// Number of faces.
    pub faces: usize,
    /// Face size → number of faces.
    pub face_sizes: BTreeMap<usize, usize>,
    /// Valence (incident edges) → number of vertices.
    pub valences: BTreeMap<usize, usize>,
    /// Edges with one face.
    pub boundary_edges: usize,
    /// Vertices on a boundary edge.
    pub boundary_vertices: usize,
    /// Closed loops of boundary edges.
    pub boundary_loops: usize,
    /// Non-manifold edges.
    pub nonmanifold_edges: usize,
    /// Non-manifold vertices (isolated vertices not counted).
    pub nonmanifold_vertices: usize,
    /// Degenerate edges (both ends the same vertex).
    pub degenerate_edges: usize,
    /// Vertices that no face uses.
    pub isolated_vertices: usize,
    /// Edges with a semi-sharp crease tag.
    pub semi_sharp_creases: usize,
    /// Edges with an infinitely sharp crease tag.
    pub infinite_creases: usize,
    /// Vertices with a corner tag.
    pub corners: usize,
    /// Faces tagged as holes.
    pub holes: usize,
    /// Connected components (isolated vertices excluded).
    pub components: usize,
    /// `V - E + F` of the whole mesh (isolated vertices included).
    pub euler: i64,
    /// Total genus when every component is a closed manifold, else `None`.
    pub genus: Option<i64>,
    /// Per-component details.
    pub component_details: Vec<Component>,
}

impl TopologySummary {
    /// Computes the summary of `topo`.
    pub fn new(topo: &Topology) -> Self {
        let mut face_sizes = BTreeMap::new();
        for n in topo.face_sizes() {
            *face_sizes.entry(n as usize).or_insert(0) += 1;
        }
        let mut valences = BTreeMap::new();
        for v in 0..topo.num_vertices() {
            *valences.entry(topo.valence(v)).or_insert(0) += 1;
        }
        let count_v =
            |p: &dyn Fn(usize) -> bool| (0..topo.num_vertices()).filter(|&v| p(v)).count();
        let count_e = |p: &dyn Fn(usize) -> bool| (0..topo.num_edges()).filter(|&e| p(e)).count();
        let tags = topo.tags();
        let comps = components(topo);
        let genus = if !comps.is_empty() && comps.iter().all(|c| c.genus.is_some()) {
            Some(comps.iter().filter_map(|c| c.genus).sum())
        } else {
            None
        };
        TopologySummary {
            vertices: topo.num_vertices(),
            edges: topo.num_edges(),
            faces: topo.num_faces(),
            face_sizes,
            valences,
            boundary_edges: count_e(&|e| topo.is_boundary_edge(e)),
            boundary_vertices: count_v(&|v| topo.is_boundary_vertex(v)),
            boundary_loops: boundary_loops(topo),
            nonmanifold_edges: count_e(&|e| topo.is_non_manifold_edge(e)),
            nonmanifold_vertices: count_v(&|v| topo.is_non_manifold_vertex(v)),
            degenerate_edges: count_e(&|e| topo.is_degenerate_edge(e)),
            isolated_vertices: count_v(&|v| topo.is_isolated_vertex(v)),
            semi_sharp_creases: tags.num_creased_edges() - tags.num_infinite_creases(),
            infinite_creases: tags.num_infinite_creases(),
            corners: tags.num_corners(),
            holes: tags.num_holes(),
            components: comps.len(),
            euler: topo.num_vertices() as i64 - topo.num_edges() as i64 + topo.num_faces() as i64,
            genus,
            component_details: comps,
        }
    }
}

/// Counts the vertices OpenSubdiv calls irregular (`Far::TopologyLevel::
/// IsVertexValenceRegular` false) for a scheme whose regular interior valence is
/// `regular_valence` (4 for Catmull-Clark and Bilinear, 6 for Loop): the extraordinary
/// vertices of [`Topology::is_extraordinary`] except those with exactly one face, which
/// OpenSubdiv treats as (regular) corners.
pub fn count_irregular(topo: &Topology, regular_valence: usize) -> usize {
    (0..topo.num_vertices())
        .filter(|&v| topo.is_extraordinary(v, regular_valence) && topo.vertex_faces(v).len() != 1)
        .count()
}
