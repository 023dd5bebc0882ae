//! Building a [`Topology`] from face-vertex lists in O(V + E + F).

use rayon::prelude::*;

use crate::csr::{Csr, exclusive_prefix_sum, par_group_indices};
use crate::error::{BuildWarning, TopologyError};
use crate::memory;
use crate::tags::Tags;
use crate::topology::MAX_FACE_SIZE;
use crate::topology::*;

use face_loops::FaceLoops;

mod face_loops;
#[cfg(test)]
mod reference;
#[cfg(test)]
mod tests;

const NONE: u32 = u32::MAX;
/// Faces, vertices or half-edges per parallel task: large enough that a task's bookkeeping
/// is negligible, small enough that two threads share the work evenly.
const BLOCK: usize = 1 << 12;

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
    ///
    /// The build runs on rayon's current thread pool; its result, warnings and errors do not
    /// depend on the number of threads (an error is the first in face order).
    pub fn build_with_warnings(
        &self,
        face_sizes: &[u32],
        face_vertices: &[u32],
    ) -> Result<(Topology, Vec<BuildWarning>), TopologyError> {
        let Numbered {
            face_offsets,
            half_face,
            corners,
            edges,
            warnings,
        } = self.numbered(face_sizes, face_vertices)?;
        let relations = Relations {
            face_offsets: &face_offsets,
            face_vertices: par_copy(face_vertices),
            half_face: &half_face,
            face_edges: edges.face_edges,
            edge_vertices: edges.edge_vertices,
            edge_flags: edges.edge_flags,
        };
        let topo = relations.assemble(self.num_vertices, corners);
        Ok((topo, warnings))
    }

    /// The edges of the mesh alone, numbered and flagged as [`Self::build`] numbers and
    /// flags them, without the vertex rings and the other relations: for measures over
    /// edges (boundary and non-manifold counts, what meets at an edge) at a fraction of a
    /// build's cost.
    ///
    /// ```
    /// use subd_mesh::TopologyBuilder;
    /// // Two quads sharing an edge: 7 edges, 6 of them on the boundary.
    /// let edges = TopologyBuilder::new(6)
    ///     .edges(&[4, 4], &[0, 1, 4, 3, 1, 2, 5, 4])
    ///     .unwrap();
    /// assert_eq!(edges.num_edges(), 7);
    /// assert_eq!((0..7).filter(|&e| edges.is_boundary_edge(e)).count(), 6);
    /// ```
    ///
    /// # Errors
    /// As [`Self::build`].
    pub fn edges(
        &self,
        face_sizes: &[u32],
        face_vertices: &[u32],
    ) -> Result<FaceEdges, TopologyError> {
        let numbered = self.numbered(face_sizes, face_vertices)?.edges;
        let mut face_counts = vec![0u32; numbered.edge_vertices.len()];
        for &e in &numbered.face_edges {
            face_counts[e as usize] += 1;
        }
        let mut edge_flags = numbered.edge_flags;
        for (fl, &count) in edge_flags.iter_mut().zip(&face_counts) {
            *fl |= edge_flags_by_face_count(count);
        }
        Ok(FaceEdges {
            face_edges: numbered.face_edges,
            edge_flags,
        })
    }

    /// Passes 1 and 2 of a build, after checking the index ranges and face sizes: the face
    /// offsets, each half-edge's face, the half-edges grouped by first vertex, and the
    /// matched and numbered edges, with the warnings about accepted oddities (or the first
    /// orientation conflict when they are refused).
    fn numbered(
        &self,
        face_sizes: &[u32],
        face_vertices: &[u32],
    ) -> Result<Numbered, TopologyError> {
        let nv = self.num_vertices;
        check_index_range(nv, face_sizes, face_vertices)?;
        let face_offsets = checked_face_offsets(face_sizes, face_vertices.len())?;
        let half_face = half_faces(&face_offsets, face_vertices.len());
        let faces = FaceLoops {
            offsets: &face_offsets,
            vertices: face_vertices,
            half_face: &half_face,
        };
        faces.check_vertex_range(nv)?;
        let mut warnings = faces.repeated_vertex_warnings();
        // Half-edges by their first vertex: the vertex-face relation, and where edge matching
        // finds each vertex's half-edges.
        let corners = par_group_indices(nv, face_vertices.len(), |h| face_vertices[h]);
        let pairs = faces.match_pairs(&corners);
        report_conflicts(
            &faces,
            pairs.conflicts,
            self.accept_inconsistent_orientation,
            &mut warnings,
        )?;
        let edges = faces.number_edges(pairs.link, &pairs.non_manifold);
        Ok(Numbered {
            face_offsets,
            half_face,
            corners,
            edges,
            warnings,
        })
    }
}

/// What [`TopologyBuilder::numbered`] gives a build (or an edge census) to go on with.
struct Numbered {
    face_offsets: Vec<u32>,
    half_face: Vec<u32>,
    corners: Csr<u32>,
    edges: NumberedEdges,
    warnings: Vec<BuildWarning>,
}

/// The edges of a face list ([`TopologyBuilder::edges`]): each face-vertex's edge (the one
/// leaving it along its face) and each edge's flags, as in the [`Topology`] built from the
/// same lists.
#[derive(Debug, Clone)]
pub struct FaceEdges {
    face_edges: Vec<u32>,
    edge_flags: Vec<u8>,
}

impl FaceEdges {
    /// Number of edges.
    pub fn num_edges(&self) -> usize {
        self.edge_flags.len()
    }

    /// The edge of every face-vertex, in face-vertex order ([`Topology::face_edges`] of
    /// every face, one after the other).
    pub fn face_edges(&self) -> &[u32] {
        &self.face_edges
    }

    /// As [`Topology::is_boundary_edge`].
    pub fn is_boundary_edge(&self, e: usize) -> bool {
        self.edge_flags[e] & EDGE_BOUNDARY != 0
    }

    /// As [`Topology::is_non_manifold_edge`].
    pub fn is_non_manifold_edge(&self, e: usize) -> bool {
        self.edge_flags[e] & EDGE_NON_MANIFOLD != 0
    }
}

/// Refuses counts that do not fit the `u32` indices (with `NONE` kept free).
fn check_index_range(
    nv: usize,
    face_sizes: &[u32],
    face_vertices: &[u32],
) -> Result<(), TopologyError> {
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
    Ok(())
}

/// Face offsets from face sizes, refusing faces too small or too large and sizes that do not
/// add up to the `num_face_vertices` given.
fn checked_face_offsets(
    face_sizes: &[u32],
    num_face_vertices: usize,
) -> Result<Vec<u32>, TopologyError> {
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
        if total > num_face_vertices {
            return Err(TopologyError::FaceVertexCountMismatch {
                expected: face_sizes.iter().map(|&s| s as usize).sum(),
                actual: num_face_vertices,
            });
        }
        face_offsets.push(total as u32);
    }
    if total != num_face_vertices {
        return Err(TopologyError::FaceVertexCountMismatch {
            expected: total,
            actual: num_face_vertices,
        });
    }
    Ok(face_offsets)
}

/// The face of every half-edge, filled face block by face block in parallel.
fn half_faces(face_offsets: &[u32], num_half_edges: usize) -> Vec<u32> {
    let nf = face_offsets.len() - 1;
    let mut half_face: Vec<u32> = memory::zeroed(num_half_edges);
    let block_starts = (0..nf.div_ceil(BLOCK)).map(|b| face_offsets[b * BLOCK] as usize);
    split_at_starts(&mut half_face, block_starts)
        .into_par_iter()
        .enumerate()
        .for_each(|(b, out)| {
            let first = b * BLOCK;
            let base = face_offsets[first] as usize;
            for f in first..(first + BLOCK).min(nf) {
                let r = face_offsets[f] as usize - base..face_offsets[f + 1] as usize - base;
                out[r].fill(f as u32);
            }
        });
    half_face
}

/// Splits `data` into consecutive pieces starting at `starts` (increasing, the first 0), the
/// last piece running to the end; for parallel tasks that each own a contiguous range.
fn split_at_starts<T>(mut data: &mut [T], starts: impl Iterator<Item = usize>) -> Vec<&mut [T]> {
    let mut pieces = Vec::new();
    let mut at = 0;
    for next in starts.skip(1) {
        let (piece, rest) = data.split_at_mut(next - at);
        pieces.push(piece);
        (data, at) = (rest, next);
    }
    pieces.push(data);
    pieces
}

/// A copy of `values`, made by all threads.
fn par_copy(values: &[u32]) -> Vec<u32> {
    let mut copy = memory::with_capacity(values.len());
    copy.par_extend(values.par_iter().copied());
    copy
}

/// The half-edges of block `b` of `n`.
fn block(b: usize, n: usize) -> std::ops::Range<usize> {
    b * BLOCK..((b + 1) * BLOCK).min(n)
}

/// Whether a vertex occurs twice in `face`.
fn has_repeat(face: &[u32]) -> bool {
    match *face {
        [a, b, c] => a == b || b == c || a == c,
        [a, b, c, d] => a == b || a == c || a == d || b == c || b == d || c == d,
        _ => !repeated_corners(face).is_empty(),
    }
}

/// The corners of `face` whose vertex occurs at an earlier corner, in order.
fn repeated_corners(face: &[u32]) -> Vec<usize> {
    // Faces are mostly small: comparing all pairs is faster than sorting there.
    if face.len() <= 32 {
        return (1..face.len())
            .filter(|&c| face[..c].contains(&face[c]))
            .collect();
    }
    let mut sorted: Vec<(u32, usize)> = face.iter().copied().zip(0..).collect();
    sorted.sort_unstable();
    let mut repeated: Vec<usize> = sorted
        .windows(2)
        .filter(|w| w[0].0 == w[1].0)
        .map(|w| w[1].1)
        .collect();
    repeated.sort_unstable();
    repeated
}

/// Refuses the first orientation conflict in face order, or warns about all of them when
/// they are accepted.
fn report_conflicts(
    faces: &FaceLoops<'_>,
    conflicts: Vec<(u32, u32)>,
    accept: bool,
    warnings: &mut Vec<BuildWarning>,
) -> Result<(), TopologyError> {
    let describe = |(h, first_face): (u32, u32)| {
        let (v0, v1) = faces.ends(h as usize);
        (
            first_face as usize,
            faces.half_face[h as usize] as usize,
            v0,
            v1,
        )
    };
    if let (false, Some(&first)) = (accept, conflicts.first()) {
        let (first_face, second_face, v0, v1) = describe(first);
        return Err(TopologyError::InconsistentOrientation {
            first_face,
            second_face,
            v0,
            v1,
        });
    }
    warnings.extend(conflicts.into_iter().map(|c| {
        let (first_face, second_face, v0, v1) = describe(c);
        BuildWarning::InconsistentOrientation {
            first_face,
            second_face,
            v0,
            v1,
        }
    }));
    Ok(())
}

/// Edges numbered by first appearance: each half-edge's edge, each edge's vertices (in its
/// first face's direction) and its non-manifold and degenerate flags.
struct NumberedEdges {
    face_edges: Vec<u32>,
    edge_vertices: Vec<[u32; 2]>,
    edge_flags: Vec<u8>,
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
        let half_face = half_faces(&face_offsets, face_vertices.len());
        let corners = par_group_indices(num_vertices, face_vertices.len(), |h| face_vertices[h]);
        let relations = Relations {
            face_offsets: &face_offsets,
            face_vertices,
            half_face: &half_face,
            face_edges,
            edge_vertices,
            edge_flags,
        };
        let topo = relations.assemble(num_vertices, corners);
        Ok(topo)
    }
}

/// The relations a topology is completed from: face-vertices, face-edges and numbered edges
/// with the non-manifold and degenerate flags already known, and the face of each
/// face-vertex.
struct Relations<'a> {
    face_offsets: &'a [u32],
    face_vertices: Vec<u32>,
    half_face: &'a [u32],
    face_edges: Vec<u32>,
    edge_vertices: Vec<[u32; 2]>,
    edge_flags: Vec<u8>,
}

impl Relations<'_> {
    /// Completes the topology: edge-faces, vertex-faces (from `corners`, the face-vertices
    /// grouped by vertex), vertex-edges (ordered), boundary/non-manifold/isolated flags.
    /// Boundary flags and edges with more than two faces are added here.
    fn assemble(self, nv: usize, corners: Csr<u32>) -> Topology {
        let nf = self.face_offsets.len() - 1;
        let ne = self.edge_vertices.len();
        let by_edge = par_group_indices(ne, self.face_edges.len(), |h| self.face_edges[h]);
        let (edge_faces, edge_face_local) = self.faces_and_corners(&by_edge.values);
        let (vertex_faces, vertex_face_local) = self.faces_and_corners(&corners.values);
        drop(corners.values);
        let mut edge_flags = self.edge_flags;
        flag_edges_by_face_count(&by_edge.offsets, &mut edge_flags);
        // Vertex -> edges in creation order (a degenerate edge appears twice at its vertex).
        let edge_ends: &[u32] = bytemuck::cast_slice(&self.edge_vertices);
        let mut vertex_edges = par_group_indices(nv, edge_ends.len(), |i| edge_ends[i]);
        vertex_edges.values.par_iter_mut().for_each(|i| *i /= 2);
        let vertex_flags = vertex_flags(&vertex_edges, &edge_flags, &corners.offsets);
        let mut topo = Topology {
            num_vertices: nv as u32,
            face_offsets: par_copy(self.face_offsets),
            face_vertices: self.face_vertices,
            face_edges: self.face_edges,
            edge_vertices: self.edge_vertices,
            edge_face_offsets: by_edge.offsets,
            edge_faces,
            edge_face_local,
            vertex_face_offsets: corners.offsets,
            vertex_faces,
            vertex_face_local,
            vertex_edge_offsets: vertex_edges.offsets,
            vertex_edges: vertex_edges.values,
            edge_flags,
            vertex_flags,
            tags: Tags::new(nv, ne, nf),
        };
        topo.order_vertex_fans();
        topo
    }

    /// The face of each face-vertex in `corners`, and its position in that face.
    fn faces_and_corners(&self, corners: &[u32]) -> (Vec<u32>, Vec<u16>) {
        let mut faces: Vec<u32> = memory::with_capacity(corners.len());
        faces.par_extend(corners.par_iter().map(|&h| self.half_face[h as usize]));
        let mut local: Vec<u16> = memory::with_capacity(corners.len());
        local.par_extend(
            corners
                .par_iter()
                .zip(&faces)
                .map(|(&h, &f)| (h - self.face_offsets[f as usize]) as u16),
        );
        (faces, local)
    }
}

/// Flags edges with one face as boundary and edges with more than two as non-manifold.
fn flag_edges_by_face_count(edge_face_offsets: &[u32], edge_flags: &mut [u8]) {
    edge_flags
        .par_iter_mut()
        .with_min_len(BLOCK)
        .enumerate()
        .for_each(|(e, fl)| {
            *fl |= edge_flags_by_face_count(edge_face_offsets[e + 1] - edge_face_offsets[e]);
        });
}

/// The flags an edge gets from its number of faces: boundary with one, non-manifold with
/// more than two.
fn edge_flags_by_face_count(count: u32) -> u8 {
    match count {
        1 => EDGE_BOUNDARY,
        0 | 2 => 0,
        _ => EDGE_NON_MANIFOLD,
    }
}

/// Vertex flags: boundary and non-manifold from the vertex's edges, isolated when no face
/// uses it.
fn vertex_flags(
    vertex_edges: &Csr<u32>,
    edge_flags: &[u8],
    vertex_face_offsets: &[u32],
) -> Vec<u8> {
    (0..vertex_edges.num_rows())
        .into_par_iter()
        .with_min_len(BLOCK)
        .map(|v| {
            let mut vf = 0;
            for &e in vertex_edges.row(v) {
                let fl = edge_flags[e as usize];
                if fl & EDGE_BOUNDARY != 0 {
                    vf |= VERTEX_BOUNDARY;
                }
                if fl & EDGE_NON_MANIFOLD != 0 {
                    vf |= VERTEX_NON_MANIFOLD;
                }
            }
            if vertex_face_offsets[v] == vertex_face_offsets[v + 1] {
                vf |= VERTEX_ISOLATED;
            }
            vf
        })
        .collect()
}

/// A block of vertices' part of the vertex relations, which ordering its fans rewrites.
struct FanBlock<'a> {
    first: usize,
    faces: &'a mut [u32],
    local: &'a mut [u16],
    edges: &'a mut [u32],
    flags: &'a mut [u8],
}

impl Topology {
    /// Orders the faces and edges around every vertex counter-clockwise; a vertex whose
    /// neighbourhood is not a single fan is flagged non-manifold and keeps face order.
    /// Vertices are independent, so blocks of them are ordered in parallel.
    fn order_vertex_fans(&mut self) {
        let mut faces = std::mem::take(&mut self.vertex_faces);
        let mut local = std::mem::take(&mut self.vertex_face_local);
        let mut edges = std::mem::take(&mut self.vertex_edges);
        let mut flags = std::mem::take(&mut self.vertex_flags);
        let nv = self.num_vertices();
        let firsts = || (0..nv.div_ceil(BLOCK)).map(|b| b * BLOCK);
        let at = |offsets: &[u32]| {
            firsts()
                .map(move |v| offsets[v] as usize)
                .collect::<Vec<_>>()
        };
        let (face_starts, edge_starts) =
            (at(&self.vertex_face_offsets), at(&self.vertex_edge_offsets));
        let blocks: Vec<FanBlock<'_>> = split_at_starts(&mut faces, face_starts.iter().copied())
            .into_iter()
            .zip(split_at_starts(&mut local, face_starts.iter().copied()))
            .zip(split_at_starts(&mut edges, edge_starts.iter().copied()))
            .zip(split_at_starts(&mut flags, firsts()))
            .zip(firsts())
            .map(|((((faces, local), edges), flags), first)| FanBlock {
                first,
                faces,
                local,
                edges,
                flags,
            })
            .collect();
        let this = &*self;
        blocks
            .into_par_iter()
            .for_each(|block| this.order_fans_of(block));
        self.vertex_faces = faces;
        self.vertex_face_local = local;
        self.vertex_edges = edges;
        self.vertex_flags = flags;
    }

    /// [`Self::order_vertex_fans`] for one block of vertices.
    fn order_fans_of(&self, block: FanBlock<'_>) {
        let (mut fan_faces, mut fan_edges) = (Vec::new(), Vec::new());
        let face_base = self.vertex_face_offsets[block.first] as usize;
        let edge_base = self.vertex_edge_offsets[block.first] as usize;
        for (i, flags) in block.flags.iter_mut().enumerate() {
            if *flags & (VERTEX_NON_MANIFOLD | VERTEX_ISOLATED) != 0 {
                continue;
            }
            let v = block.first + i;
            let fr = self.vertex_face_offsets[v] as usize - face_base
                ..self.vertex_face_offsets[v + 1] as usize - face_base;
            let er = self.vertex_edge_offsets[v] as usize - edge_base
                ..self.vertex_edge_offsets[v + 1] as usize - edge_base;
            let around = (&block.faces[fr.clone()], &block.edges[er.clone()]);
            if self.walk_fan(v, around, &mut fan_faces, &mut fan_edges) {
                for ((f, c), &(g, d)) in block.faces[fr.clone()]
                    .iter_mut()
                    .zip(&mut block.local[fr])
                    .zip(&fan_faces)
                {
                    (*f, *c) = (g, d);
                }
                block.edges[er].copy_from_slice(&fan_edges);
            } else {
                *flags |= VERTEX_NON_MANIFOLD;
            }
        }
    }

    /// Walks the fan of faces around `v` counter-clockwise, starting (on a boundary) at the
    /// boundary edge that leaves `v` in its face. Returns `false` when the faces and edges
    /// around `v` do not form a single fan. Mirrors the conditions of OpenSubdiv's
    /// `Vtr::Level::orderVertexFacesAndEdges` so the same vertices come out non-manifold.
    /// `around` holds the faces and edges of `v` in face order.
    fn walk_fan(
        &self,
        v: usize,
        (vf, ve): (&[u32], &[u32]),
        faces: &mut Vec<(u32, u16)>,
        edges: &mut Vec<u32>,
    ) -> bool {
        faces.clear();
        edges.clear();
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
