//! Building a [`Topology`] from face-vertex lists in O(V + E + F).

use crate::error::{BuildWarning, TopologyError};
use crate::tags::Tags;
use crate::topology::MAX_FACE_SIZE;
use crate::topology::*;

const NONE: u32 = u32::MAX;

/// Builds a [`Topology`] from face sizes and face-vertex indices (OpenSubdiv's
/// `numVertsPerFace` / `vertIndicesPerFace` form).
///
/// ```
/// use subd_mesh::TopologyBuilder;
/// // Two quads sharing an edge.
/// let topo = TopologyBuilder::new(6)
///     .build(&[4, 4], &[0, 1, 4, 3, 1, 2, 5, 4])
///     .unwrap();
/// assert_eq!(topo.num_edges(), 7);
/// assert_eq!(topo.edge_faces(topo.find_edge(1, 4).unwrap() as usize), &[0, 1]);
/// ```
#[derive(Debug, Clone)]
pub struct TopologyBuilder {
    num_vertices: usize,
    accept_inconsistent_orientation: bool,
}

impl TopologyBuilder {
    /// A builder for a mesh with `num_vertices` vertices (vertices no face uses are kept).
    pub fn new(num_vertices: usize) -> Self {
        TopologyBuilder {
            num_vertices,
            accept_inconsistent_orientation: false,
        }
    }

    /// Accept two faces that traverse a shared edge in the same direction (the edge then
    /// becomes non-manifold, as in OpenSubdiv) instead of returning
    /// [`TopologyError::InconsistentOrientation`].
    pub fn accept_inconsistent_orientation(mut self, accept: bool) -> Self {
        self.accept_inconsistent_orientation = accept;
        self
    }

    /// Builds the topology, dropping warnings.
    pub fn build(
        &self,
        face_sizes: &[u32],
        face_vertices: &[u32],
    ) -> Result<Topology, TopologyError> {
        self.build_with_warnings(face_sizes, face_vertices)
            .map(|(t, _)| t)
    }

    /// Builds the topology and returns the warnings about accepted oddities (faces that
    /// repeat a vertex, accepted orientation conflicts).
    pub fn build_with_warnings(
        &self,
        face_sizes: &[u32],
        face_vertices: &[u32],
    ) -> Result<(Topology, Vec<BuildWarning>), TopologyError> {
        let nv = self.num_vertices;
        if nv >= NONE as usize {
            return Err(TopologyError::TooLarge {
                what: "vertex",
                count: nv,
            });
        }
        if face_vertices.len() >= NONE as usize || face_sizes.len() >= NONE as usize {
            return Err(TopologyError::TooLarge {
                what: "face-vertex",
                count: face_vertices.len(),
            });
        }
        let mut warnings = Vec::new();

        // Face offsets and index validation.
        let mut face_offsets = Vec::with_capacity(face_sizes.len() + 1);
        face_offsets.push(0u32);
        let mut total: usize = 0;
        for (f, &n) in face_sizes.iter().enumerate() {
            if n < 3 {
                return Err(TopologyError::FaceTooSmall {
                    face: f,
                    size: n as usize,
                });
            }
            if n as usize > MAX_FACE_SIZE {
                return Err(TopologyError::FaceTooLarge {
                    face: f,
                    size: n as usize,
                    max: MAX_FACE_SIZE,
                });
            }
            total += n as usize;
            if total > face_vertices.len() {
                return Err(TopologyError::FaceVertexCountMismatch {
                    expected: face_sizes.iter().map(|&s| s as usize).sum(),
                    actual: face_vertices.len(),
                });
            }
            face_offsets.push(total as u32);
        }
        if total != face_vertices.len() {
            return Err(TopologyError::FaceVertexCountMismatch {
                expected: total,
                actual: face_vertices.len(),
            });
        }
        let nf = face_sizes.len();
        // `stamp[v]` remembers the last face (or bucket) that touched `v`; it replaces a hash
        // set so that repeated-vertex detection and edge matching stay linear.
        let mut stamp = vec![NONE; nv];
        for f in 0..nf {
            let fv = &face_vertices[face_offsets[f] as usize..face_offsets[f + 1] as usize];
            for (corner, &v) in fv.iter().enumerate() {
                if v as usize >= nv {
                    return Err(TopologyError::VertexIndexOutOfRange {
                        face: f,
                        corner,
                        index: v as u64,
                        num_vertices: nv,
                    });
                }
                if stamp[v as usize] == f as u32 {
                    warnings.push(BuildWarning::RepeatedVertex { face: f, vertex: v });
                }
                stamp[v as usize] = f as u32;
            }
        }

        let nh = face_vertices.len();
        let next_in_face = |f: usize, h: usize| -> usize {
            let end = face_offsets[f + 1] as usize;
            if h + 1 == end {
                face_offsets[f] as usize
            } else {
                h + 1
            }
        };

        // Pass 1: for every non-degenerate half-edge, the first half-edge (in face order)
        // joining the same unordered vertex pair. Half-edges are bucketed by their smaller
        // vertex with a stable counting sort, then matched on the larger vertex.
        let mut bucket_offsets = vec![0u32; nv + 1];
        let mut half_face = vec![0u32; nh];
        for f in 0..nf {
            for h in face_offsets[f] as usize..face_offsets[f + 1] as usize {
                half_face[h] = f as u32;
                let (a, b) = (face_vertices[h], face_vertices[next_in_face(f, h)]);
                if a != b {
                    bucket_offsets[a.min(b) as usize + 1] += 1;
                }
            }
        }
        for i in 0..nv {
            bucket_offsets[i + 1] += bucket_offsets[i];
        }
        let mut bucket = vec![0u32; bucket_offsets[nv] as usize];
        {
            let mut fill = bucket_offsets.clone();
            for h in 0..nh {
                let f = half_face[h] as usize;
                let (a, b) = (face_vertices[h], face_vertices[next_in_face(f, h)]);
                if a != b {
                    let slot = &mut fill[a.min(b) as usize];
                    bucket[*slot as usize] = h as u32;
                    *slot += 1;
                }
            }
        }
        let mut first_half = vec![NONE; nh];
        stamp.fill(NONE);
        let mut first_of = vec![0u32; nv];
        for a in 0..nv {
            for &h in &bucket[bucket_offsets[a] as usize..bucket_offsets[a + 1] as usize] {
                let h = h as usize;
                let f = half_face[h] as usize;
                let (x, y) = (face_vertices[h], face_vertices[next_in_face(f, h)]);
                let b = x.max(y) as usize;
                if stamp[b] != a as u32 {
                    stamp[b] = a as u32;
                    first_of[b] = h as u32;
                }
                first_half[h] = first_of[b];
            }
        }
        drop(bucket);
        drop(bucket_offsets);
        drop(first_of);

        // Pass 2: number the edges by first appearance, following OpenSubdiv's rules for
        // non-manifold cases (Vtr::Level::completeTopologyFromFaceVertices).
        let mut face_edges = vec![0u32; nh];
        let mut edge_vertices: Vec<[u32; 2]> = Vec::with_capacity(nh / 2 + 16);
        let mut edge_face_count: Vec<u32> = Vec::with_capacity(nh / 2 + 16);
        let mut edge_last_face: Vec<u32> = Vec::with_capacity(nh / 2 + 16);
        let mut edge_flags: Vec<u8> = Vec::with_capacity(nh / 2 + 16);
        for h in 0..nh {
            let f = half_face[h];
            let (v0, v1) = (face_vertices[h], face_vertices[next_in_face(f as usize, h)]);
            let mut edge = NONE;
            let mut new_flags = 0u8;
            if v0 == v1 {
                new_flags = EDGE_NON_MANIFOLD | EDGE_DEGENERATE;
            } else if first_half[h] != h as u32 {
                let e = face_edges[first_half[h] as usize] as usize;
                if edge_last_face[e] == f {
                    // The pair occurs twice in this face: a new, non-manifold instance.
                    edge_flags[e] |= EDGE_NON_MANIFOLD;
                    new_flags = EDGE_NON_MANIFOLD;
                } else {
                    if edge_face_count[e] > 1 {
                        edge_flags[e] |= EDGE_NON_MANIFOLD;
                    } else if v0 == edge_vertices[e][0] {
                        let first_face = edge_last_face[e] as usize;
                        if !self.accept_inconsistent_orientation {
                            return Err(TopologyError::InconsistentOrientation {
                                first_face,
                                second_face: f as usize,
                                v0,
                                v1,
                            });
                        }
                        warnings.push(BuildWarning::InconsistentOrientation {
                            first_face,
                            second_face: f as usize,
                            v0,
                            v1,
                        });
                        edge_flags[e] |= EDGE_NON_MANIFOLD;
                    }
                    edge_face_count[e] += 1;
                    edge_last_face[e] = f;
                    edge = e as u32;
                }
            }
            if edge == NONE {
                edge = edge_vertices.len() as u32;
                edge_vertices.push([v0, v1]);
                edge_face_count.push(1);
                edge_last_face.push(f);
                edge_flags.push(new_flags);
            }
            face_edges[h] = edge;
        }
        drop(first_half);
        drop(edge_last_face);
        drop(edge_face_count);
        drop(half_face);
        let topo = assemble(
            nv,
            face_offsets,
            face_vertices.to_vec(),
            face_edges,
            edge_vertices,
            edge_flags,
        );
        Ok((topo, warnings))
    }
}

impl Topology {
    /// Assembles a topology whose edges are already numbered: `face_edges[i]` is the edge
    /// from face-vertex `i` to the next vertex of the same face, and `edge_vertices` gives each
    /// edge's two vertices. This is how a refinement builds a child level with OpenSubdiv's
    /// edge order without a search. The remaining relations, vertex rings and flags are
    /// computed as by [`TopologyBuilder`]; an edge is flagged non-manifold when it has more
    /// than two faces, when two faces use it in the same direction, when it is degenerate,
    /// or when it is listed in `non_manifold_edges` (flags a refinement inherits).
    ///
    /// ```
    /// use subd_mesh::Topology;
    /// // One quad, edges numbered by hand.
    /// let t = Topology::from_numbered_edges(
    ///     4, vec![0, 4], vec![0, 1, 2, 3], vec![0, 1, 2, 3],
    ///     vec![[0, 1], [1, 2], [2, 3], [3, 0]], &[],
    /// ).unwrap();
    /// assert_eq!(t.edge_faces(2), &[0]);
    /// assert!(t.is_boundary_vertex(3));
    /// ```
    pub fn from_numbered_edges(
        num_vertices: usize,
        face_offsets: Vec<u32>,
        face_vertices: Vec<u32>,
        face_edges: Vec<u32>,
        edge_vertices: Vec<[u32; 2]>,
        non_manifold_edges: &[u32],
    ) -> Result<Topology, TopologyError> {
        if num_vertices >= NONE as usize || face_vertices.len() >= NONE as usize {
            return Err(TopologyError::TooLarge {
                what: "vertex",
                count: num_vertices.max(face_vertices.len()),
            });
        }
        let bad = |face, detail| Err(TopologyError::InconsistentEdges { face, detail });
        if face_offsets.first() != Some(&0)
            || *face_offsets.last().unwrap_or(&0) as usize != face_vertices.len()
            || face_edges.len() != face_vertices.len()
        {
            return bad(
                0,
                "face offsets, face-vertices and face-edges do not agree in length",
            );
        }
        let ne = edge_vertices.len();
        let mut uses = vec![[0u8; 2]; ne];
        for f in 0..face_offsets.len() - 1 {
            let (a, b) = (face_offsets[f] as usize, face_offsets[f + 1] as usize);
            if b < a + 3 {
                return Err(TopologyError::FaceTooSmall {
                    face: f,
                    size: b.saturating_sub(a),
                });
            }
            if b - a > MAX_FACE_SIZE {
                return Err(TopologyError::FaceTooLarge {
                    face: f,
                    size: b - a,
                    max: MAX_FACE_SIZE,
                });
            }
            for h in a..b {
                let (v0, v1) = (
                    face_vertices[h],
                    face_vertices[if h + 1 == b { a } else { h + 1 }],
                );
                if v0 as usize >= num_vertices {
                    return Err(TopologyError::VertexIndexOutOfRange {
                        face: f,
                        corner: h - a,
                        index: v0 as u64,
                        num_vertices,
                    });
                }
                let e = face_edges[h] as usize;
                if e >= ne {
                    return bad(f, "face edge index out of range");
                }
                let ev = edge_vertices[e];
                let dir = if ev == [v0, v1] {
                    0
                } else if ev == [v1, v0] {
                    1
                } else {
                    return bad(f, "face edge does not join the face's consecutive vertices");
                };
                uses[e][dir] = uses[e][dir].saturating_add(1);
            }
        }
        let mut edge_flags = vec![0u8; ne];
        for (e, &[a, b]) in edge_vertices.iter().enumerate() {
            if a == b {
                edge_flags[e] |= EDGE_NON_MANIFOLD | EDGE_DEGENERATE;
            } else if uses[e][0] > 1 || uses[e][1] > 1 {
                edge_flags[e] |= EDGE_NON_MANIFOLD;
            }
        }
        for &e in non_manifold_edges {
            if let Some(fl) = edge_flags.get_mut(e as usize) {
                *fl |= EDGE_NON_MANIFOLD;
            }
        }
        Ok(assemble(
            num_vertices,
            face_offsets,
            face_vertices,
            face_edges,
            edge_vertices,
            edge_flags,
        ))
    }
}

/// Completes a topology from face-vertices, face-edges and numbered edges: edge-faces,
/// vertex-faces, vertex-edges (ordered), boundary/non-manifold/isolated flags. `edge_flags`
/// carries non-manifold and degenerate flags already known; boundary flags and edges with
/// more than two faces are added here.
pub(crate) fn assemble(
    nv: usize,
    face_offsets: Vec<u32>,
    face_vertices: Vec<u32>,
    face_edges: Vec<u32>,
    edge_vertices: Vec<[u32; 2]>,
    mut edge_flags: Vec<u8>,
) -> Topology {
    let nf = face_offsets.len() - 1;
    let nh = face_vertices.len();
    let ne = edge_vertices.len();
    let mut half_face = vec![0u32; nh];
    for f in 0..nf {
        half_face[face_offsets[f] as usize..face_offsets[f + 1] as usize].fill(f as u32);
    }
    let mut edge_face_count = vec![0u32; ne];
    for &e in &face_edges {
        edge_face_count[e as usize] += 1;
    }
    for (e, &c) in edge_face_count.iter().enumerate() {
        if c > 2 {
            edge_flags[e] |= EDGE_NON_MANIFOLD;
        }
    }

    // Edge -> faces, in face order, with the edge's position in each face.
    let mut edge_face_offsets = Vec::with_capacity(ne + 1);
    edge_face_offsets.push(0u32);
    let mut acc = 0u32;
    for &c in &edge_face_count {
        acc += c;
        edge_face_offsets.push(acc);
    }
    let mut edge_faces = vec![0u32; nh];
    let mut edge_face_local = vec![0u16; nh];
    {
        let mut fill = edge_face_offsets.clone();
        for h in 0..nh {
            let f = half_face[h];
            let e = face_edges[h] as usize;
            let slot = fill[e] as usize;
            edge_faces[slot] = f;
            edge_face_local[slot] = (h - face_offsets[f as usize] as usize) as u16;
            fill[e] += 1;
        }
    }
    for (e, &c) in edge_face_count.iter().enumerate() {
        if c == 1 {
            edge_flags[e] |= EDGE_BOUNDARY;
        }
    }

    // Vertex -> faces (face order for now, with the corner index).
    let mut vertex_face_offsets = vec![0u32; nv + 1];
    for &v in &face_vertices {
        vertex_face_offsets[v as usize + 1] += 1;
    }
    for i in 0..nv {
        vertex_face_offsets[i + 1] += vertex_face_offsets[i];
    }
    let mut vertex_faces = vec![0u32; nh];
    let mut vertex_face_local = vec![0u16; nh];
    {
        let mut fill = vertex_face_offsets.clone();
        for h in 0..nh {
            let v = face_vertices[h] as usize;
            let f = half_face[h];
            let slot = fill[v] as usize;
            vertex_faces[slot] = f;
            vertex_face_local[slot] = (h - face_offsets[f as usize] as usize) as u16;
            fill[v] += 1;
        }
    }

    // Vertex -> edges in creation order (a degenerate edge appears twice at its vertex).
    let mut vertex_edge_offsets = vec![0u32; nv + 1];
    for &[a, b] in &edge_vertices {
        vertex_edge_offsets[a as usize + 1] += 1;
        vertex_edge_offsets[b as usize + 1] += 1;
    }
    for i in 0..nv {
        vertex_edge_offsets[i + 1] += vertex_edge_offsets[i];
    }
    let mut vertex_edges = vec![0u32; vertex_edge_offsets[nv] as usize];
    {
        let mut fill = vertex_edge_offsets.clone();
        for (e, &[a, b]) in edge_vertices.iter().enumerate() {
            for v in [a, b] {
                vertex_edges[fill[v as usize] as usize] = e as u32;
                fill[v as usize] += 1;
            }
        }
    }

    // Vertex flags.
    let mut vertex_flags = vec![0u8; nv];
    for (e, &[a, b]) in edge_vertices.iter().enumerate() {
        let fl = edge_flags[e];
        let mut vf = 0;
        if fl & EDGE_BOUNDARY != 0 {
            vf |= VERTEX_BOUNDARY;
        }
        if fl & EDGE_NON_MANIFOLD != 0 {
            vf |= VERTEX_NON_MANIFOLD;
        }
        vertex_flags[a as usize] |= vf;
        vertex_flags[b as usize] |= vf;
    }
    for v in 0..nv {
        if vertex_face_offsets[v] == vertex_face_offsets[v + 1] {
            vertex_flags[v] |= VERTEX_ISOLATED;
        }
    }

    let mut topo = Topology {
        num_vertices: nv as u32,
        face_offsets,
        face_vertices,
        face_edges,
        edge_vertices,
        edge_face_offsets,
        edge_faces,
        edge_face_local,
        vertex_face_offsets,
        vertex_faces,
        vertex_face_local,
        vertex_edge_offsets,
        vertex_edges,
        edge_flags,
        vertex_flags,
        tags: Tags::new(nv, ne, nf),
    };
    topo.order_vertex_fans();
    topo
}

impl Topology {
    /// Orders the faces and edges around every vertex counter-clockwise; a vertex whose
    /// neighbourhood is not a single fan is flagged non-manifold and keeps face order.
    fn order_vertex_fans(&mut self) {
        let mut faces: Vec<(u32, u16)> = Vec::new();
        let mut edges: Vec<u32> = Vec::new();
        for v in 0..self.num_vertices() {
            if self.vertex_flags[v] & (VERTEX_NON_MANIFOLD | VERTEX_ISOLATED) != 0 {
                continue;
            }
            if self.walk_fan(v, &mut faces, &mut edges) {
                let fr =
                    self.vertex_face_offsets[v] as usize..self.vertex_face_offsets[v + 1] as usize;
                for (slot, &(f, c)) in fr.zip(faces.iter()) {
                    self.vertex_faces[slot] = f;
                    self.vertex_face_local[slot] = c;
                }
                let er =
                    self.vertex_edge_offsets[v] as usize..self.vertex_edge_offsets[v + 1] as usize;
                self.vertex_edges[er].copy_from_slice(&edges);
            } else {
                self.vertex_flags[v] |= VERTEX_NON_MANIFOLD;
            }
        }
    }

    /// Walks the fan of faces around `v` counter-clockwise, starting (on a boundary) at the
    /// boundary edge that leaves `v` in its face. Returns `false` when the faces and edges
    /// around `v` do not form a single fan. Mirrors the conditions of OpenSubdiv's
    /// `Vtr::Level::orderVertexFacesAndEdges` so the same vertices come out non-manifold.
    fn walk_fan(&self, v: usize, faces: &mut Vec<(u32, u16)>, edges: &mut Vec<u32>) -> bool {
        faces.clear();
        edges.clear();
        let vf = self.vertex_faces(v);
        let ve = self.vertex_edges(v);
        let (nf, ne) = (vf.len(), ve.len());
        if nf == 0 || ne < 2 || ne > nf + 1 {
            return false;
        }
        let corner_of = |f: usize| -> u16 {
            self.face_vertices(f)
                .iter()
                .position(|&x| x as usize == v)
                .unwrap_or(0) as u16
        };
        let (mut f, mut c, mut e_cur);
        if ne == nf {
            f = vf[0] as usize;
            c = corner_of(f);
            e_cur = self.face_edges(f)[c as usize];
        } else {
            let mut start = None;
            for &e in ve {
                let ef = self.edge_faces(e as usize);
                if ef.len() == 1 {
                    let f0 = ef[0] as usize;
                    let c0 = corner_of(f0);
                    start = Some((f0, c0, e));
                    if self.face_edges(f0)[c0 as usize] == e {
                        break;
                    }
                }
            }
            let Some((f0, c0, e0)) = start else {
                return false;
            };
            (f, c, e_cur) = (f0, c0, e0);
        }
        let e_first = e_cur;
        faces.push((f as u32, c));
        edges.push(e_cur);
        while edges.len() < ne {
            let fe = self.face_edges(f);
            let prev = if c == 0 { fe.len() - 1 } else { c as usize - 1 };
            let e_next = fe[prev];
            if e_next == e_cur || e_next == e_first {
                return false;
            }
            edges.push(e_next);
            if faces.len() < nf {
                let ef = self.edge_faces(e_next as usize);
                if ef.is_empty() || (ef.len() == 1 && ef[0] as usize == f) {
                    return false;
                }
                let g = if ef[0] as usize == f && ef.len() > 1 {
                    ef[1]
                } else {
                    ef[0]
                } as usize;
                let Some(pos) = self.face_edges(g).iter().position(|&x| x == e_next) else {
                    return false;
                };
                f = g;
                c = pos as u16;
                faces.push((f as u32, c));
            }
            e_cur = e_next;
        }
        faces.len() == nf
    }
}
