//! The serial build, kept as the reference the parallel build is tested against: it numbers
//! edges by walking the half-edges one after another, exactly as the rules read.

use super::{check_index_range, checked_face_offsets};
use crate::csr::{RowSlots, group_by_key, offsets_of_keys};
use crate::error::{BuildWarning, TopologyError};
use crate::tags::Tags;
use crate::topology::*;

const NONE: u32 = u32::MAX;

/// [`super::TopologyBuilder::build_with_warnings`], serially.
pub(super) fn build_serial(
    nv: usize,
    accept_inconsistent_orientation: bool,
    face_sizes: &[u32],
    face_vertices: &[u32],
) -> Result<(Topology, Vec<BuildWarning>), TopologyError> {
    check_index_range(nv, face_sizes, face_vertices)?;
    let face_offsets = checked_face_offsets(face_sizes, face_vertices.len())?;
    let faces = FaceLoops {
        offsets: &face_offsets,
        vertices: face_vertices,
    };
    let mut warnings = Vec::new();
    let mut stamp = vec![NONE; nv];
    faces.check_vertices(nv, &mut stamp, &mut warnings)?;
    let half_face = faces.half_faces();
    let first_half = faces.first_halves(nv, &half_face, &mut stamp);
    let numbering = EdgeNumbering::number(
        &faces,
        &half_face,
        &first_half,
        accept_inconsistent_orientation,
        &mut warnings,
    )?;
    let topo = assemble(
        nv,
        face_offsets.clone(),
        face_vertices.to_vec(),
        numbering.face_edges,
        numbering.edge_vertices,
        numbering.edge_flags,
    );
    Ok((topo, warnings))
}

/// The faces as closed loops of face-vertices ("half-edges": face-vertex `h` starts the
/// half-edge to the next vertex of its face).
struct FaceLoops<'a> {
    offsets: &'a [u32],
    vertices: &'a [u32],
}

impl FaceLoops<'_> {
    fn num_faces(&self) -> usize {
        self.offsets.len() - 1
    }

    fn range(&self, f: usize) -> std::ops::Range<usize> {
        self.offsets[f] as usize..self.offsets[f + 1] as usize
    }

    /// The vertices at the two ends of half-edge `h` of face `f`.
    #[inline]
    fn ends(&self, f: usize, h: usize) -> (u32, u32) {
        let end = self.offsets[f + 1] as usize;
        let next = if h + 1 == end {
            self.offsets[f] as usize
        } else {
            h + 1
        };
        (self.vertices[h], self.vertices[next])
    }

    /// Refuses vertex indices out of range; warns about faces that repeat a vertex.
    fn check_vertices(
        &self,
        nv: usize,
        stamp: &mut [u32],
        warnings: &mut Vec<BuildWarning>,
    ) -> Result<(), TopologyError> {
        for f in 0..self.num_faces() {
            for (corner, &v) in self.vertices[self.range(f)].iter().enumerate() {
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
        Ok(())
    }

    /// The face of every half-edge.
    fn half_faces(&self) -> Vec<u32> {
        let mut half_face = vec![0u32; self.vertices.len()];
        for f in 0..self.num_faces() {
            half_face[self.range(f)].fill(f as u32);
        }
        half_face
    }

    /// Pass 1 of the build: for every non-degenerate half-edge, the first half-edge (in face
    /// order) joining the same unordered vertex pair. Half-edges are bucketed by their
    /// smaller vertex with a stable counting sort, then matched on the larger vertex
    /// (`stamp` is scratch space of one entry per vertex).
    fn first_halves(&self, nv: usize, half_face: &[u32], stamp: &mut [u32]) -> Vec<u32> {
        let non_degenerate_by_smaller_end = (0..self.vertices.len()).filter_map(|h| {
            let (a, b) = self.ends(half_face[h] as usize, h);
            (a != b).then_some((a.min(b), h as u32))
        });
        let buckets = group_by_key(nv, non_degenerate_by_smaller_end);
        let mut first_half = vec![NONE; self.vertices.len()];
        stamp.fill(NONE);
        let mut first_of = vec![0u32; nv];
        for a in 0..nv {
            for &h in buckets.row(a) {
                let h = h as usize;
                let (x, y) = self.ends(half_face[h] as usize, h);
                let b = x.max(y) as usize;
                if stamp[b] != a as u32 {
                    stamp[b] = a as u32;
                    first_of[b] = h as u32;
                }
                first_half[h] = first_of[b];
            }
        }
        first_half
    }
}

/// Pass 2 of the build: the edges numbered by first appearance, following OpenSubdiv's rules
/// for non-manifold cases (Vtr::Level::completeTopologyFromFaceVertices).
struct EdgeNumbering {
    face_edges: Vec<u32>,
    edge_vertices: Vec<[u32; 2]>,
    edge_flags: Vec<u8>,
    edge_face_count: Vec<u32>,
    edge_last_face: Vec<u32>,
}

impl EdgeNumbering {
    fn number(
        faces: &FaceLoops<'_>,
        half_face: &[u32],
        first_half: &[u32],
        accept_inconsistent_orientation: bool,
        warnings: &mut Vec<BuildWarning>,
    ) -> Result<EdgeNumbering, TopologyError> {
        let nh = faces.vertices.len();
        let mut n = EdgeNumbering {
            face_edges: vec![0u32; nh],
            edge_vertices: Vec::with_capacity(nh / 2 + 16),
            edge_flags: Vec::with_capacity(nh / 2 + 16),
            edge_face_count: Vec::with_capacity(nh / 2 + 16),
            edge_last_face: Vec::with_capacity(nh / 2 + 16),
        };
        for h in 0..nh {
            let f = half_face[h];
            let (v0, v1) = faces.ends(f as usize, h);
            let mut edge = NONE;
            let mut new_flags = 0u8;
            if v0 == v1 {
                new_flags = EDGE_NON_MANIFOLD | EDGE_DEGENERATE;
            } else if first_half[h] != h as u32 {
                let e = n.face_edges[first_half[h] as usize] as usize;
                if n.edge_last_face[e] == f {
                    // The pair occurs twice in this face: a new, non-manifold instance.
                    n.edge_flags[e] |= EDGE_NON_MANIFOLD;
                    new_flags = EDGE_NON_MANIFOLD;
                } else {
                    n.add_face(e, f, v0, v1, accept_inconsistent_orientation, warnings)?;
                    edge = e as u32;
                }
            }
            if edge == NONE {
                edge = n.edge_vertices.len() as u32;
                n.edge_vertices.push([v0, v1]);
                n.edge_face_count.push(1);
                n.edge_last_face.push(f);
                n.edge_flags.push(new_flags);
            }
            n.face_edges[h] = edge;
        }
        Ok(n)
    }

    /// Adds face `f`, traversing `v0 -> v1`, to edge `e` that an earlier face already has:
    /// a third face makes it non-manifold, and so does a second face in the same direction
    /// (an orientation conflict, refused unless accepted).
    fn add_face(
        &mut self,
        e: usize,
        f: u32,
        v0: u32,
        v1: u32,
        accept_inconsistent_orientation: bool,
        warnings: &mut Vec<BuildWarning>,
    ) -> Result<(), TopologyError> {
        if self.edge_face_count[e] > 1 {
            self.edge_flags[e] |= EDGE_NON_MANIFOLD;
        } else if v0 == self.edge_vertices[e][0] {
            let first_face = self.edge_last_face[e] as usize;
            if !accept_inconsistent_orientation {
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
            self.edge_flags[e] |= EDGE_NON_MANIFOLD;
        }
        self.edge_face_count[e] += 1;
        self.edge_last_face[e] = f;
        Ok(())
    }
}

/// Completes a topology from face-vertices, face-edges and numbered edges: edge-faces,
/// vertex-faces, vertex-edges (ordered), boundary/non-manifold/isolated flags. `edge_flags`
/// carries non-manifold and degenerate flags already known; boundary flags and edges with
/// more than two faces are added here.
pub(super) fn assemble(
    nv: usize,
    face_offsets: Vec<u32>,
    face_vertices: Vec<u32>,
    face_edges: Vec<u32>,
    edge_vertices: Vec<[u32; 2]>,
    mut edge_flags: Vec<u8>,
) -> Topology {
    let nf = face_offsets.len() - 1;
    let ne = edge_vertices.len();
    let faces = FaceLoops {
        offsets: &face_offsets,
        vertices: &face_vertices,
    };
    let half_face = faces.half_faces();
    // Edge -> faces and vertex -> faces, in face order (vertex fans are ordered below), with
    // the edge's or vertex's position in each face.
    let (edge_face_offsets, edge_faces, edge_face_local) =
        faces_by_key(ne, &face_edges, &half_face, &face_offsets);
    flag_edges_by_face_count(&edge_face_offsets, &mut edge_flags);
    let (vertex_face_offsets, vertex_faces, vertex_face_local) =
        faces_by_key(nv, &face_vertices, &half_face, &face_offsets);
    drop(half_face);
    // Vertex -> edges in creation order (a degenerate edge appears twice at its vertex).
    let vertex_edges = group_by_key(
        nv,
        (0..ne as u32).flat_map(|e| {
            let [a, b] = edge_vertices[e as usize];
            [(a, e), (b, e)]
        }),
    );
    let vertex_flags = vertex_flags(nv, &edge_vertices, &edge_flags, &vertex_face_offsets);
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
        vertex_edge_offsets: vertex_edges.offsets,
        vertex_edges: vertex_edges.values,
        edge_flags,
        vertex_flags,
        tags: Tags::new(nv, ne, nf),
    };
    topo.order_vertex_fans_serial();
    topo
}

/// The faces of each of `num_rows` keys, where face-vertex `h` belongs to row `keys[h]`
/// (its edge or its vertex), in face order: offsets, faces, and the face-vertex's position
/// in its face.
fn faces_by_key(
    num_rows: usize,
    keys: &[u32],
    half_face: &[u32],
    face_offsets: &[u32],
) -> (Vec<u32>, Vec<u32>, Vec<u16>) {
    let offsets = offsets_of_keys(num_rows, keys.iter().copied());
    let mut faces = vec![0u32; keys.len()];
    let mut local = vec![0u16; keys.len()];
    let mut slots = RowSlots::new(&offsets);
    for (h, &key) in keys.iter().enumerate() {
        let f = half_face[h];
        let slot = slots.take(key as usize);
        faces[slot] = f;
        local[slot] = (h - face_offsets[f as usize] as usize) as u16;
    }
    (offsets, faces, local)
}

/// Flags edges with one face as boundary and edges with more than two as non-manifold.
fn flag_edges_by_face_count(edge_face_offsets: &[u32], edge_flags: &mut [u8]) {
    for (e, fl) in edge_flags.iter_mut().enumerate() {
        let count = edge_face_offsets[e + 1] - edge_face_offsets[e];
        if count > 2 {
            *fl |= EDGE_NON_MANIFOLD;
        }
        if count == 1 {
            *fl |= EDGE_BOUNDARY;
        }
    }
}

/// Vertex flags: boundary and non-manifold from the vertex's edges, isolated when no face
/// uses it.
fn vertex_flags(
    nv: usize,
    edge_vertices: &[[u32; 2]],
    edge_flags: &[u8],
    vertex_face_offsets: &[u32],
) -> Vec<u8> {
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
    vertex_flags
}

impl Topology {
    /// Orders the faces and edges around every vertex counter-clockwise; a vertex whose
    /// neighbourhood is not a single fan is flagged non-manifold and keeps face order.
    fn order_vertex_fans_serial(&mut self) {
        let mut faces: Vec<(u32, u16)> = Vec::new();
        let mut edges: Vec<u32> = Vec::new();
        for v in 0..self.num_vertices() {
            if self.vertex_flags[v] & (VERTEX_NON_MANIFOLD | VERTEX_ISOLATED) != 0 {
                continue;
            }
            if self.walk_fan_serial(v, &mut faces, &mut edges) {
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
    fn walk_fan_serial(&self, v: usize, faces: &mut Vec<(u32, u16)>, edges: &mut Vec<u32>) -> bool {
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
