//! Matching the faces' half-edges into edges: the faces as closed loops of face-vertices,
//! paired by vertex blocks in parallel, with non-manifold edges and orientation conflicts
//! found on the way.

use std::sync::atomic::{AtomicU32, Ordering};

use rayon::prelude::*;

use super::*;

/// The faces as closed loops of face-vertices ("half-edges": face-vertex `h` starts the
/// half-edge to the next vertex of its face).
pub(super) struct FaceLoops<'a> {
    pub(super) offsets: &'a [u32],
    pub(super) vertices: &'a [u32],
    pub(super) half_face: &'a [u32],
}

/// The result of matching half-edges into pairs (see [`FaceLoops::match_pairs`]).
pub(super) struct Pairs {
    /// Per half-edge: itself when it starts an edge, else the half-edge that started its
    /// edge.
    pub(super) link: Vec<u32>,
    /// Half-edges starting an edge that is non-manifold.
    pub(super) non_manifold: Vec<u32>,
    /// Second faces using an edge in its first face's direction: (half-edge, first face).
    pub(super) conflicts: Vec<(u32, u32)>,
}

/// What matching finds in a block of vertices besides the links.
#[derive(Default)]
struct Oddities {
    /// Half-edges starting an edge that is non-manifold.
    non_manifold: Vec<u32>,
    /// Orientation conflicts: (half-edge, first face of its edge).
    conflicts: Vec<(u32, u32)>,
}

impl FaceLoops<'_> {
    pub(super) fn num_faces(&self) -> usize {
        self.offsets.len() - 1
    }

    /// The half-edges before and after half-edge `h` in its face.
    #[inline]
    pub(super) fn prev_next(&self, h: usize) -> (usize, usize) {
        let f = self.half_face[h] as usize;
        let (start, end) = (self.offsets[f] as usize, self.offsets[f + 1] as usize);
        let prev = if h == start { end - 1 } else { h - 1 };
        let next = if h + 1 == end { start } else { h + 1 };
        (prev, next)
    }

    /// The vertices at the two ends of half-edge `h`.
    #[inline]
    pub(super) fn ends(&self, h: usize) -> (u32, u32) {
        (self.vertices[h], self.vertices[self.prev_next(h).1])
    }

    /// Refuses the first vertex index, in face order, that is out of range.
    pub(super) fn check_vertex_range(&self, nv: usize) -> Result<(), TopologyError> {
        let bad = |&v: &u32| v as usize >= nv;
        // Blocks first: a per-element parallel search costs more than the scan itself.
        let Some(b) = self
            .vertices
            .par_chunks(BLOCK)
            .position_first(|block| block.iter().any(bad))
        else {
            return Ok(());
        };
        let h = block(b, self.vertices.len())
            .find(|&h| bad(&self.vertices[h]))
            .unwrap_or(0);
        let face = self.half_face[h] as usize;
        Err(TopologyError::VertexIndexOutOfRange {
            face,
            corner: h - self.offsets[face] as usize,
            index: self.vertices[h] as u64,
            num_vertices: nv,
        })
    }

    /// A warning for every corner whose vertex occurs earlier in the same face, in face
    /// order.
    pub(super) fn repeated_vertex_warnings(&self) -> Vec<BuildWarning> {
        let face =
            |f: usize| &self.vertices[self.offsets[f] as usize..self.offsets[f + 1] as usize];
        // Such faces are rare: find them in parallel, then list their repeats.
        let faces: Vec<usize> = (0..self.num_faces())
            .into_par_iter()
            .with_min_len(BLOCK)
            .filter(|&f| has_repeat(face(f)))
            .collect();
        let warning = |f: usize, c: usize| BuildWarning::RepeatedVertex {
            face: f,
            vertex: face(f)[c],
        };
        faces
            .into_iter()
            .flat_map(|f| {
                repeated_corners(face(f))
                    .into_iter()
                    .map(move |c| warning(f, c))
            })
            .collect()
    }

    /// Pass 1 of the build: groups the non-degenerate half-edges by unordered vertex pair
    /// and decides, pair by pair, which half-edges start an edge. Each pair is found at its
    /// smaller vertex, among the half-edges leaving it and (one before those in their faces)
    /// entering it, so vertices are matched independently, in parallel.
    pub(super) fn match_pairs(&self, corners: &Csr<u32>) -> Pairs {
        let link = memory::atomic_u32s(self.vertices.len(), |h| h as u32);
        let nv = corners.num_rows();
        let found: Vec<Oddities> = (0..nv.div_ceil(BLOCK))
            .into_par_iter()
            .map(|b| {
                let mut found = Oddities::default();
                let mut pairs: Vec<(u32, u32)> = Vec::new();
                for a in b * BLOCK..((b + 1) * BLOCK).min(nv) {
                    self.pairs_at(a as u32, corners.row(a), &mut pairs);
                    for group in pairs.chunk_by(|x, y| x.0 == y.0) {
                        self.resolve_pair(group, &link, &mut found);
                    }
                }
                found
            })
            .collect();
        let mut conflicts: Vec<(u32, u32)> =
            found.iter().flat_map(|o| o.conflicts.clone()).collect();
        conflicts.sort_unstable();
        Pairs {
            link: memory::into_u32s(link),
            non_manifold: found.into_iter().flat_map(|o| o.non_manifold).collect(),
            conflicts,
        }
    }

    /// The half-edges whose smaller vertex is `a`, as (larger vertex, half-edge), sorted:
    /// each pair's half-edges together, in face order. `leaving` lists the half-edges that
    /// leave `a`.
    pub(super) fn pairs_at(&self, a: u32, leaving: &[u32], pairs: &mut Vec<(u32, u32)>) {
        pairs.clear();
        for &h in leaving {
            let (prev, next) = self.prev_next(h as usize);
            let b = self.vertices[next];
            if b > a {
                pairs.push((b, h));
            }
            let c = self.vertices[prev];
            if c > a {
                pairs.push((c, prev as u32));
            }
        }
        pairs.sort_unstable();
    }

    /// Decides which half-edges of one vertex pair (`group`, in face order) start an edge,
    /// following the serial rules: the first does; a later one in the same face as the one
    /// before it is a repeat in that face and starts a new, non-manifold instance; any other
    /// joins the first one's edge, which a second joining face makes non-manifold, and so
    /// does a first joining face in the same direction (an orientation conflict).
    fn resolve_pair(&self, group: &[(u32, u32)], link: &[AtomicU32], found: &mut Oddities) {
        let first = group[0].1;
        let first_face = self.half_face[first as usize];
        let mut prev_face = first_face;
        let mut joined = 0;
        let mut bad = false;
        for &(_, h) in &group[1..] {
            let face = self.half_face[h as usize];
            if face == prev_face {
                found.non_manifold.push(h);
                bad = true;
            } else {
                link[h as usize].store(first, Ordering::Relaxed);
                joined += 1;
                let same_direction = self.vertices[h as usize] == self.vertices[first as usize];
                if joined == 1 && same_direction {
                    found.conflicts.push((h, first_face));
                }
                bad |= joined > 1 || same_direction;
            }
            prev_face = face;
        }
        if bad {
            found.non_manifold.push(first);
        }
    }

    /// Pass 2 of the build: numbers the half-edges that start an edge in face order (an
    /// exclusive prefix sum over blocks of half-edges) and gives every half-edge its edge.
    pub(super) fn number_edges(&self, mut link: Vec<u32>, non_manifold: &[u32]) -> NumberedEdges {
        let starts_edge = |h: usize| link[h] == h as u32;
        let blocks = link.len().div_ceil(BLOCK);
        let counts: Vec<u32> = (0..blocks)
            .into_par_iter()
            .map(|b| block(b, link.len()).filter(|&h| starts_edge(h)).count() as u32)
            .collect();
        let first_edge = exclusive_prefix_sum(&counts);
        let ne = counts.iter().sum::<u32>() as usize;
        let mut edge_of: Vec<u32> = memory::zeroed(link.len());
        let mut edge_vertices: Vec<[u32; 2]> = memory::zeroed(ne);
        let pieces = split_at_starts(&mut edge_vertices, first_edge.iter().map(|&e| e as usize));
        edge_of
            .par_chunks_mut(BLOCK)
            .zip(pieces)
            .zip(&first_edge)
            .enumerate()
            .for_each(|(b, ((edge_of, ev), &first))| {
                let mut next = first;
                for (i, h) in block(b, link.len()).enumerate() {
                    if starts_edge(h) {
                        let (v0, v1) = self.ends(h);
                        ev[(next - first) as usize] = [v0, v1];
                        edge_of[i] = next;
                        next += 1;
                    }
                }
            });
        let mut edge_flags: Vec<u8> = memory::with_capacity(ne);
        edge_flags.par_extend(edge_vertices.par_iter().map(|&[a, b]| {
            if a == b {
                EDGE_NON_MANIFOLD | EDGE_DEGENERATE
            } else {
                0
            }
        }));
        for &h in non_manifold {
            edge_flags[edge_of[h as usize] as usize] |= EDGE_NON_MANIFOLD;
        }
        link.par_iter_mut()
            .with_min_len(BLOCK)
            .for_each(|l| *l = edge_of[*l as usize]);
        NumberedEdges {
            face_edges: link,
            edge_vertices,
            edge_flags,
        }
    }
}
