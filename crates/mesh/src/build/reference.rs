//! An independent oracle for the topology build.
//!
//! [`build_serial`] computes what [`super::TopologyBuilder::build_with_warnings`] must
//! return, written the plainest way from the documented rules: the docs of `build.rs`,
//! `topology.rs` and `error.rs`, and the two OpenSubdiv routines they follow,
//! `Vtr::Level::completeTopologyFromFaceVertices` (edge numbering, non-manifold edges) and
//! `Vtr::Level::orderVertexFacesAndEdges` (the counter-clockwise fans). The parallel build is
//! therefore tested against a second reading of the rules, not against a copy of itself.
//!
//! It shares no code with `build.rs`, `build/face_loops.rs` or `csr.rs`: not the index and
//! face-size checks, not the half-edge pairing by smaller vertex, not the counting sorts or
//! any CSR helper, not the edge flagging, not the fan walk. Instead it keeps a `HashMap` from
//! each unordered vertex pair to the first edge made for it, gathers every relation as one
//! `Vec` per face, edge or vertex while walking the faces once, in order, and flattens the
//! rows into offset arrays only at the end. Nothing runs in parallel.
//!
//! From the crate it takes only what it has to produce: the [`Topology`] struct (its
//! `pub(crate)` fields are filled directly, so every array and flag is this module's own),
//! `Tags::new` for the default tags (all smooth, no holes), the flag constants and
//! [`MAX_FACE_SIZE`], and the error and warning types.

use std::collections::HashMap;

use crate::error::{BuildWarning, TopologyError};
use crate::tags::Tags;
use crate::topology::{
    EDGE_BOUNDARY, EDGE_DEGENERATE, EDGE_NON_MANIFOLD, MAX_FACE_SIZE, Topology, VERTEX_BOUNDARY,
    VERTEX_ISOLATED, VERTEX_NON_MANIFOLD,
};

/// A face or vertex with the position of an edge or vertex in that face.
type FaceCorner = (u32, u16);

/// [`super::TopologyBuilder::build_with_warnings`], computed independently. Errors come in
/// the order the rules check them (sizes, then vertex indices, then orientation), each the
/// first in face order; warnings list every repeated vertex, then every accepted
/// orientation conflict, each in face order.
pub(super) fn build_serial(
    nv: usize,
    accept_inconsistent_orientation: bool,
    face_sizes: &[u32],
    face_vertices: &[u32],
) -> Result<(Topology, Vec<BuildWarning>), TopologyError> {
    check_counts(nv, face_sizes, face_vertices)?;
    let faces = split_into_faces(face_sizes, face_vertices)?;
    check_vertex_indices(nv, &faces)?;
    let mut warnings = repeated_vertex_warnings(&faces);
    let edges = find_edges(&faces, accept_inconsistent_orientation, &mut warnings)?;
    Ok((assemble(nv, &faces, edges), warnings))
}

/// Every count must fit a `u32` index with `u32::MAX` left over (the build's "no index").
fn check_counts(nv: usize, face_sizes: &[u32], face_vertices: &[u32]) -> Result<(), TopologyError> {
    let limit = u32::MAX as usize;
    if nv >= limit {
        return Err(TopologyError::TooLarge {
            what: "vertex",
            count: nv,
        });
    }
    if face_vertices.len() >= limit || face_sizes.len() >= limit {
        return Err(TopologyError::TooLarge {
            what: "face-vertex",
            count: face_vertices.len(),
        });
    }
    Ok(())
}

/// The face-vertex list cut into faces. Faces are checked in order: the first one with
/// fewer than 3 or more than `MAX_FACE_SIZE` vertices is refused, and so is the list when a
/// face runs past its end or the faces leave some of it over (reporting the sum of all the
/// sizes, as `FaceVertexCountMismatch` documents).
fn split_into_faces<'a>(
    face_sizes: &[u32],
    face_vertices: &'a [u32],
) -> Result<Vec<&'a [u32]>, TopologyError> {
    let sum_of_sizes: usize = face_sizes.iter().map(|&n| n as usize).sum();
    let mismatch = TopologyError::FaceVertexCountMismatch {
        expected: sum_of_sizes,
        actual: face_vertices.len(),
    };
    let mut faces = Vec::with_capacity(face_sizes.len());
    let mut start = 0;
    for (face, &n) in face_sizes.iter().enumerate() {
        let size = n as usize;
        if size < 3 {
            return Err(TopologyError::FaceTooSmall { face, size });
        }
        if size > MAX_FACE_SIZE {
            return Err(TopologyError::FaceTooLarge {
                face,
                size,
                max: MAX_FACE_SIZE,
            });
        }
        let Some(face_vertices) = face_vertices.get(start..start + size) else {
            return Err(mismatch);
        };
        faces.push(face_vertices);
        start += size;
    }
    if start != face_vertices.len() {
        return Err(mismatch);
    }
    Ok(faces)
}

/// Refuses the first vertex index, in face order, that names no vertex.
fn check_vertex_indices(nv: usize, faces: &[&[u32]]) -> Result<(), TopologyError> {
    for (face, vertices) in faces.iter().enumerate() {
        for (corner, &v) in vertices.iter().enumerate() {
            if v as usize >= nv {
                return Err(TopologyError::VertexIndexOutOfRange {
                    face,
                    corner,
                    index: v as u64,
                    num_vertices: nv,
                });
            }
        }
    }
    Ok(())
}

/// One warning for every corner whose vertex already occurs at an earlier corner of the same
/// face (a vertex listed three times warns twice), in face order.
fn repeated_vertex_warnings(faces: &[&[u32]]) -> Vec<BuildWarning> {
    let mut warnings = Vec::new();
    for (face, vertices) in faces.iter().enumerate() {
        for (corner, &vertex) in vertices.iter().enumerate() {
            if vertices[..corner].contains(&vertex) {
                warnings.push(BuildWarning::RepeatedVertex { face, vertex });
            }
        }
    }
    warnings
}

/// The edges, as the faces make them.
#[derive(Default)]
struct Edges {
    /// Per edge: its two vertices, in the direction of the first face that used it.
    vertices: Vec<[u32; 2]>,
    /// Per edge: its faces in face order, with the edge's position in each.
    faces: Vec<Vec<FaceCorner>>,
    /// Per edge: made non-manifold by a rule of the numbering (repeated in a face, a third
    /// face, a same-direction second face). Degenerate edges and face counts are flagged
    /// later, from `vertices` and `faces`.
    non_manifold: Vec<bool>,
    /// Per face: the edge at each corner (from that corner's vertex to the next one's).
    of_face: Vec<Vec<u32>>,
}

impl Edges {
    /// Makes a new edge from `v0` to `v1` whose first face is `face`, at `corner`.
    fn make(&mut self, v0: u32, v1: u32, face: usize, corner: usize, non_manifold: bool) -> usize {
        self.vertices.push([v0, v1]);
        self.faces.push(vec![(face as u32, corner as u16)]);
        self.non_manifold.push(non_manifold);
        self.vertices.len() - 1
    }

    /// Adds `face`, which runs `v0 -> v1` at `corner`, to edge `e` that earlier faces made
    /// or joined. A third face makes the edge non-manifold. A second face running the same
    /// way as the first means the two faces disagree on orientation: refused, or (accepted)
    /// a warning and a non-manifold edge.
    fn join(
        &mut self,
        e: usize,
        (face, corner): (usize, usize),
        (v0, v1): (u32, u32),
        accept_inconsistent_orientation: bool,
        warnings: &mut Vec<BuildWarning>,
    ) -> Result<(), TopologyError> {
        if self.faces[e].len() >= 2 {
            self.non_manifold[e] = true;
        } else if self.vertices[e][0] == v0 {
            let first_face = self.faces[e][0].0 as usize;
            if !accept_inconsistent_orientation {
                return Err(TopologyError::InconsistentOrientation {
                    first_face,
                    second_face: face,
                    v0,
                    v1,
                });
            }
            warnings.push(BuildWarning::InconsistentOrientation {
                first_face,
                second_face: face,
                v0,
                v1,
            });
            self.non_manifold[e] = true;
        }
        self.faces[e].push((face as u32, corner as u16));
        Ok(())
    }
}

/// Numbers the edges by first appearance, walking the faces in order and each face's
/// corners `(v_i, v_{i+1})`, as OpenSubdiv does: a pair of distinct vertices seen before
/// joins the first edge made for that pair, unless that edge's last face is this face (the
/// face repeats the pair), which makes a new non-manifold instance and flags the first one
/// too. Every degenerate corner (`v_i == v_{i+1}`) makes an edge of its own.
fn find_edges(
    faces: &[&[u32]],
    accept_inconsistent_orientation: bool,
    warnings: &mut Vec<BuildWarning>,
) -> Result<Edges, TopologyError> {
    let mut edges = Edges::default();
    // Keyed by (smaller, larger) vertex: both directions find the same edge.
    let mut first_edge_of_pair: HashMap<(u32, u32), usize> = HashMap::new();
    for (face, vertices) in faces.iter().enumerate() {
        let n = vertices.len();
        let mut face_edges = Vec::with_capacity(n);
        for corner in 0..n {
            let (v0, v1) = (vertices[corner], vertices[(corner + 1) % n]);
            let pair = (v0.min(v1), v0.max(v1));
            let earlier = (v0 != v1)
                .then(|| first_edge_of_pair.get(&pair).copied())
                .flatten();
            let e = match earlier {
                Some(e) if edges.faces[e].last().map(|fc| fc.0) == Some(face as u32) => {
                    edges.non_manifold[e] = true;
                    edges.make(v0, v1, face, corner, true)
                }
                Some(e) => {
                    let at = (face, corner);
                    edges.join(e, at, (v0, v1), accept_inconsistent_orientation, warnings)?;
                    e
                }
                None => {
                    let e = edges.make(v0, v1, face, corner, false);
                    if v0 != v1 {
                        first_edge_of_pair.insert(pair, e);
                    }
                    e
                }
            };
            face_edges.push(e as u32);
        }
        edges.of_face.push(face_edges);
    }
    Ok(edges)
}

/// The edge flags: degenerate edges (both ends the same vertex) are degenerate and
/// non-manifold; edges with one face are boundary; edges with more than two faces, or that
/// a numbering rule flagged, are non-manifold.
fn edge_flags(edges: &Edges) -> Vec<u8> {
    let mut flags = Vec::with_capacity(edges.vertices.len());
    for (e, &[a, b]) in edges.vertices.iter().enumerate() {
        let mut fl = 0;
        if a == b {
            fl |= EDGE_DEGENERATE | EDGE_NON_MANIFOLD;
        }
        if edges.non_manifold[e] || edges.faces[e].len() > 2 {
            fl |= EDGE_NON_MANIFOLD;
        }
        if edges.faces[e].len() == 1 {
            fl |= EDGE_BOUNDARY;
        }
        flags.push(fl);
    }
    flags
}

/// The vertex relations before any fan is ordered: each vertex's faces with its corner in
/// each, in face order (a face that repeats the vertex is listed once per corner), and its
/// edges in edge order (a degenerate edge is listed twice, once per end).
fn vertex_relations(
    nv: usize,
    faces: &[&[u32]],
    edge_vertices: &[[u32; 2]],
) -> (Vec<Vec<FaceCorner>>, Vec<Vec<u32>>) {
    let mut vertex_faces = vec![Vec::new(); nv];
    for (face, vertices) in faces.iter().enumerate() {
        for (corner, &v) in vertices.iter().enumerate() {
            vertex_faces[v as usize].push((face as u32, corner as u16));
        }
    }
    let mut vertex_edges = vec![Vec::new(); nv];
    for (e, &[a, b]) in edge_vertices.iter().enumerate() {
        vertex_edges[a as usize].push(e as u32);
        vertex_edges[b as usize].push(e as u32);
    }
    (vertex_faces, vertex_edges)
}

/// Vertex flags before the fans are walked: boundary on a boundary edge, non-manifold on a
/// non-manifold edge, isolated when no face uses the vertex.
fn vertex_flags(
    vertex_faces: &[Vec<FaceCorner>],
    edge_vertices: &[[u32; 2]],
    edge_flags: &[u8],
) -> Vec<u8> {
    let mut flags: Vec<u8> = vertex_faces
        .iter()
        .map(|faces| if faces.is_empty() { VERTEX_ISOLATED } else { 0 })
        .collect();
    for (&[a, b], &fl) in edge_vertices.iter().zip(edge_flags) {
        for v in [a, b] {
            if fl & EDGE_BOUNDARY != 0 {
                flags[v as usize] |= VERTEX_BOUNDARY;
            }
            if fl & EDGE_NON_MANIFOLD != 0 {
                flags[v as usize] |= VERTEX_NON_MANIFOLD;
            }
        }
    }
    flags
}

/// What a fan walk reads: the faces' vertices and edges, and the edges' faces.
struct Mesh<'a> {
    faces: &'a [&'a [u32]],
    face_edges: &'a [Vec<u32>],
    edge_faces: &'a [Vec<FaceCorner>],
}

impl Mesh<'_> {
    /// The first corner of `face` at vertex `v` (OpenSubdiv's `findInArray`).
    fn corner_of(&self, face: usize, v: u32) -> usize {
        self.faces[face].iter().position(|&x| x == v).unwrap_or(0)
    }

    /// Where the walk around `v` starts: face, corner of `v` in it, and first edge. With as
    /// many edges as faces (interior) it is the first face and the edge leaving `v` there;
    /// otherwise the first one-face edge (in edge order) that leaves `v` in its face, or
    /// failing that the last one-face edge; `None` when `v` has no one-face edge.
    fn fan_start(&self, v: u32, vf: &[FaceCorner], ve: &[u32]) -> Option<(usize, usize, u32)> {
        if vf.len() == ve.len() {
            let face = vf[0].0 as usize;
            let corner = self.corner_of(face, v);
            return Some((face, corner, self.face_edges[face][corner]));
        }
        let mut start = None;
        for &e in ve {
            if let [(face, _)] = self.edge_faces[e as usize][..] {
                let face = face as usize;
                let corner = self.corner_of(face, v);
                start = Some((face, corner, e));
                if self.face_edges[face][corner] == e {
                    break;
                }
            }
        }
        start
    }

    /// OpenSubdiv's `orderVertexFacesAndEdges` for vertex `v`, whose faces `vf` and edges
    /// `ve` come in face and edge order: from the start, step to the edge entering `v` in the
    /// current face (the next edge counter-clockwise), then across it to its other face.
    /// `None` (`v` is non-manifold) when the counts cannot make one fan, when the walk meets
    /// the same edge twice running or its first edge again, when an edge has no other face
    /// to cross to, or when it ends without having visited every face.
    fn walk_fan(
        &self,
        v: u32,
        vf: &[FaceCorner],
        ve: &[u32],
    ) -> Option<(Vec<FaceCorner>, Vec<u32>)> {
        let (nf, ne) = (vf.len(), ve.len());
        if nf == 0 || ne < 2 || ne > nf + 1 {
            return None;
        }
        let (mut face, mut corner, mut edge) = self.fan_start(v, vf, ve)?;
        let first_edge = edge;
        let mut faces = vec![(face as u32, corner as u16)];
        let mut edges = vec![edge];
        while edges.len() < ne {
            let n = self.faces[face].len();
            let next = self.face_edges[face][(corner + n - 1) % n];
            if next == edge || next == first_edge {
                return None;
            }
            edges.push(next);
            if faces.len() < nf {
                // Across `next` to its other face, where `next` leaves `v`.
                let (g, at) = match self.edge_faces[next as usize][..] {
                    [] => return None,
                    [(g, _)] if g as usize == face => return None,
                    [(g, _), (h, at), ..] if g as usize == face => (h, at),
                    [(g, at), ..] => (g, at),
                };
                (face, corner) = (g as usize, at as usize);
                faces.push((g, at));
            }
            edge = next;
        }
        (faces.len() == nf).then_some((faces, edges))
    }
}

/// Orders the faces and edges around every vertex that is neither isolated nor already
/// non-manifold counter-clockwise; a vertex whose walk fails becomes non-manifold and keeps
/// its faces and edges in face and edge order.
fn order_fans(
    mesh: &Mesh<'_>,
    vertex_faces: &mut [Vec<FaceCorner>],
    vertex_edges: &mut [Vec<u32>],
    vertex_flags: &mut [u8],
) {
    for v in 0..vertex_flags.len() {
        if vertex_flags[v] & (VERTEX_ISOLATED | VERTEX_NON_MANIFOLD) != 0 {
            continue;
        }
        match mesh.walk_fan(v as u32, &vertex_faces[v], &vertex_edges[v]) {
            Some((faces, edges)) => {
                vertex_faces[v] = faces;
                vertex_edges[v] = edges;
            }
            None => vertex_flags[v] |= VERTEX_NON_MANIFOLD,
        }
    }
}

/// Rows laid end to end: `(offsets, values)` with row `i` at `offsets[i]..offsets[i + 1]`.
fn flatten<T: Copy>(rows: &[impl AsRef<[T]>]) -> (Vec<u32>, Vec<T>) {
    let mut offsets = vec![0u32];
    let mut values = Vec::new();
    for row in rows {
        values.extend_from_slice(row.as_ref());
        offsets.push(values.len() as u32);
    }
    (offsets, values)
}

/// [`flatten`] for rows of (face, position) pairs, split into two arrays.
fn flatten_face_corners(rows: &[Vec<FaceCorner>]) -> (Vec<u32>, Vec<u32>, Vec<u16>) {
    let (offsets, pairs) = flatten(rows);
    let (faces, positions) = pairs.into_iter().unzip();
    (offsets, faces, positions)
}

/// Completes the relations and lays them out as a [`Topology`].
fn assemble(nv: usize, faces: &[&[u32]], edges: Edges) -> Topology {
    let edge_flags = edge_flags(&edges);
    let (mut vertex_faces, mut vertex_edges) = vertex_relations(nv, faces, &edges.vertices);
    let mut vertex_flags = vertex_flags(&vertex_faces, &edges.vertices, &edge_flags);
    let mesh = Mesh {
        faces,
        face_edges: &edges.of_face,
        edge_faces: &edges.faces,
    };
    order_fans(
        &mesh,
        &mut vertex_faces,
        &mut vertex_edges,
        &mut vertex_flags,
    );
    let (face_offsets, face_vertices) = flatten(faces);
    let (_, face_edges) = flatten(&edges.of_face);
    let (edge_face_offsets, edge_faces, edge_face_local) = flatten_face_corners(&edges.faces);
    let (vertex_face_offsets, vertex_faces, vertex_face_local) =
        flatten_face_corners(&vertex_faces);
    let (vertex_edge_offsets, vertex_edges) = flatten(&vertex_edges);
    let (ne, nf) = (edges.vertices.len(), faces.len());
    Topology {
        num_vertices: nv as u32,
        face_offsets,
        face_vertices,
        face_edges,
        edge_vertices: edges.vertices,
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
    }
}
