//! Depth-first uniform refinement: the last level of Catmull-Clark, Loop or Bilinear made a
//! chunk of base faces at a time, each chunk refined from the base straight to the last
//! level, so that no level is ever held whole and the peak memory does not grow with the
//! level.
//!
//! A chunk is a compact set of base faces grown breadth-first. It is refined as a piece cut
//! out of the base ([`subd_mesh::cut`]): the chunk with every face sharing a vertex with it
//! (the one-ring that the limit surface over a face depends on, so every level's points
//! over the chunk depend on nothing else). The cut keeps every relation in the base's order,
//! so the piece's refinement computes the chunk's children with the same operations, bit
//! for bit, as the refinement of the whole mesh. Each element of the piece's levels is
//! given its index in the uniform level ([`ChildLayout`]): the chunk's faces and points land
//! where a whole refinement puts them.

use std::collections::VecDeque;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::DVec3;
use subd_mesh::Topology;
use subd_mesh::cut as submesh;
use subd_mesh::neighbourhood::{faces_touching, without_pinches};

use super::ChildLayout;
use crate::rules::Rule;
use crate::{LevelCounts, Options, RefineError, Refinement, Scheme, Split};

/// A uniform refinement's last level produced chunk by chunk ([`Self::chunk`]): the faces
/// and points of each chunk with their indices in the level, for a writer that puts records
/// at their places (a binary PLY file).
///
/// ```
/// use subd_mesh::{DVec3, TopologyBuilder};
/// use subd_schemes::{DepthFirst, Options, Refinement, Scheme};
///
/// // A 4 × 4 grid of quads.
/// let mut faces = Vec::new();
/// for j in 0..4u32 {
///     for i in 0..4u32 {
///         let v = j * 5 + i;
///         faces.extend([v, v + 1, v + 6, v + 5]);
///     }
/// }
/// let t = TopologyBuilder::new(25).build(&[4; 16], &faces).unwrap();
/// let points: Vec<DVec3> = (0..25).map(|v| DVec3::new((v % 5) as f64, (v / 5) as f64, (v % 3) as f64)).collect();
/// let opts = Options::default();
/// let depth_first = DepthFirst::new(&t, Scheme::CatmullClark, &opts, 3, 64).unwrap();
/// let whole = Refinement::new(&t, Scheme::CatmullClark, &opts, 3).unwrap();
/// let expected = whole.points_at(&points, 3);
/// let mut seen = 0;
/// for i in 0..depth_first.num_chunks() {
///     let chunk = depth_first.chunk(i, &points).unwrap();
///     for (first, range) in chunk.point_runs() {
///         for (k, p) in chunk.points()[range].iter().enumerate() {
///             assert_eq!(*p, expected[first as usize + k]);
///             seen += 1;
///         }
///     }
/// }
/// assert!(seen >= expected.len());
/// ```
#[derive(Debug)]
pub struct DepthFirst {
    /// The base level prepared (boundary tags applied) and its vertex rules.
    prepared: Refinement,
    /// Numbering of the whole mesh's levels.
    layout: ChildLayout,
    levels: usize,
    /// Base faces of each chunk, ascending.
    chunks: Vec<Vec<u32>>,
}

/// The faces and points of a chunk of the last level, each a run of consecutive indices in
/// the level.
#[derive(Debug, Default, Clone)]
pub struct ChunkLevel {
    /// `(first face, faces)` of each run; their corners follow one another in
    /// [`Self::face_vertices`].
    face_runs: Vec<(u64, usize)>,
    face_vertices: Vec<u32>,
    /// `(first vertex, points)` of each run; their positions follow one another in
    /// [`Self::points`].
    point_runs: Vec<(u64, usize)>,
    points: Vec<DVec3>,
}

impl ChunkLevel {
    /// Each run of faces: its first face's index in the level and the range of its
    /// corners in [`Self::face_vertices`] (every face has the level's face size).
    pub fn face_runs(
        &self,
        face_size: usize,
    ) -> impl Iterator<Item = (u64, std::ops::Range<usize>)> {
        let mut start = 0;
        self.face_runs.iter().map(move |&(first, n)| {
            let r = start..start + n * face_size;
            start = r.end;
            (first, r)
        })
    }

    /// Corners of the chunk's faces, as indices of the level's vertices.
    pub fn face_vertices(&self) -> &[u32] {
        &self.face_vertices
    }

    /// Each run of points: its first vertex's index in the level and the range of its
    /// positions in [`Self::points`].
    pub fn point_runs(&self) -> impl Iterator<Item = (u64, std::ops::Range<usize>)> + '_ {
        let mut start = 0;
        self.point_runs.iter().map(move |&(first, n)| {
            let r = start..start + n;
            start = r.end;
            (first, r)
        })
    }

    /// Positions of the chunk's vertices (every vertex of its faces, some shared with other
    /// chunks: theirs are the same, bit for bit).
    pub fn points(&self) -> &[DVec3] {
        &self.points
    }
}

impl DepthFirst {
    /// Plans `levels` uniform levels of `base` under `scheme` (Catmull-Clark, Loop or
    /// Bilinear), in chunks of about `faces_per_chunk` faces of the last level (at least one
    /// base face each).
    ///
    /// # Errors
    /// What [`Refinement::new`] refuses in `base`; [`RefineError::Unsupported`] for another
    /// scheme (the two-phase scheme and the split schemes) or no level;
    /// [`RefineError::TooManyLevels`] past [`crate::MAX_LEVELS`]; [`RefineError::TooLarge`] when the
    /// last level has more than 2^32 vertices (its faces could not name them in 32 bits).
    pub fn new(
        base: &Topology,
        scheme: Scheme,
        options: &Options,
        levels: usize,
        faces_per_chunk: u64,
    ) -> Result<DepthFirst, RefineError> {
        let osd = matches!(
            scheme,
            Scheme::CatmullClark | Scheme::Loop | Scheme::Bilinear
        );
        if !osd || levels == 0 {
            return Err(RefineError::Unsupported {
                scheme: scheme.to_string(),
                what: "depth-first refinement takes Catmull-Clark, Loop or Bilinear, one level or more",
            });
        }
        if levels > crate::MAX_LEVELS {
            return Err(RefineError::TooManyLevels {
                levels,
                max: crate::MAX_LEVELS,
            });
        }
        let layout = ChildLayout::new(base, &scheme, levels).expect("a quad or triangle split");
        if layout.counts(levels).vertices > 1 << 32 {
            return Err(RefineError::TooLarge { level: levels });
        }
        let prepared = Refinement::new(base, scheme, options, 0)?;
        let per_face = (1u64 << (2 * levels)).max(1);
        let base_faces = (faces_per_chunk / per_face).max(1) as usize;
        let mut chunks = compact_chunks(prepared.topology(0), base_faces);
        let t = prepared.topology(0);
        if (0..t.num_vertices()).any(|v| t.vertex_faces(v).is_empty()) {
            // The isolated vertices' chunk.
            chunks.push(Vec::new());
        }
        Ok(DepthFirst {
            prepared,
            layout,
            levels,
            chunks,
        })
    }

    /// Counts of the last level.
    pub fn counts(&self) -> LevelCounts {
        self.layout.counts(self.levels)
    }

    /// Corners of every face of the last level: 4, or 3 for Loop.
    pub fn face_size(&self) -> usize {
        match self.split() {
            Split::Triangle => 3,
            _ => 4,
        }
    }

    /// Number of chunks.
    pub fn num_chunks(&self) -> usize {
        self.chunks.len()
    }

    /// Base faces of chunk `i`, ascending (none for the chunk of the base's isolated
    /// vertices, the last).
    pub fn chunk_faces(&self, i: usize) -> &[u32] {
        &self.chunks[i]
    }

    fn split(&self) -> Split {
        self.prepared.scheme().split()
    }

    /// The faces and points of chunk `i` of the last level, from the base positions.
    ///
    /// # Errors
    /// What refining the chunk's piece refuses (nothing that [`Self::new`] accepted, short
    /// of memory).
    ///
    /// # Panics
    /// If `base` does not have one point per base vertex.
    pub fn chunk(&self, i: usize, base: &[DVec3]) -> Result<ChunkLevel, RefineError> {
        let t = self.prepared.topology(0);
        assert_eq!(base.len(), t.num_vertices(), "one point per base vertex");
        let chunk = &self.chunks[i];
        if chunk.is_empty() {
            return Ok(isolated_points(t, base));
        }
        let mut in_chunk = vec![false; t.num_faces()];
        chunk.iter().for_each(|&f| in_chunk[f as usize] = true);
        let mut piece = self.base_piece(t, &in_chunk, base);
        for level in 0..self.levels - 1 {
            piece = self.next_piece(piece, level)?;
        }
        self.last_level(piece)
    }

    /// The chunk's piece of the base: the chunk and its one-ring.
    fn base_piece(&self, t: &Topology, in_chunk: &[bool], base: &[DVec3]) -> Piece {
        let faces = piece_faces(t, in_chunk);
        let cut = submesh::cut(t, &faces);
        let rules = self.prepared.vertex_rules(0);
        Piece {
            rules: cut.vertices.iter().map(|&v| rules[v as usize]).collect(),
            points: cut.vertices.iter().map(|&v| base[v as usize]).collect(),
            keys: Keys {
                vertices: cut.vertices.iter().map(|&v| v as u64).collect(),
                edges: cut.edges.iter().map(|&e| e as u64).collect(),
                faces: faces.iter().map(|&f| f as u64).collect(),
            },
            in_chunk: faces.iter().map(|&f| in_chunk[f as usize]).collect(),
            topology: cut.topology,
        }
    }

    /// The piece of level `level + 1`: `piece` refined once, less the faces that neither
    /// descend from the chunk nor touch a vertex of one that does.
    fn next_piece(&self, piece: Piece, level: usize) -> Result<Piece, RefineError> {
        let r = self.refine_once(piece.topology, piece.rules)?;
        let sub = ChildLayout::new(r.topology(0), r.scheme(), 1).expect("a split");
        let child = self.child_keys(&sub, level, r.topology(0), &piece.keys);
        let points = r.points_at(&piece.points, 1);
        let t0 = r.topology(0);
        let mut in_chunk = vec![false; r.topology(1).num_faces()];
        for f in (0..t0.num_faces()).filter(|&f| piece.in_chunk[f]) {
            for k in 0..self.children(t0.face_size(f)) {
                in_chunk[sub.child_face(0, f as u64, k) as usize] = true;
            }
        }
        let t1 = r.topology(1);
        let faces = piece_faces(t1, &in_chunk);
        let cut = submesh::cut(t1, &faces);
        let rules = r.vertex_rules(1);
        let vertex = |v: &u32| *v as usize;
        Ok(Piece {
            rules: cut.vertices.iter().map(|v| rules[vertex(v)]).collect(),
            points: cut.vertices.iter().map(|v| points[vertex(v)]).collect(),
            keys: Keys {
                vertices: cut
                    .vertices
                    .iter()
                    .map(|v| child.vertices[vertex(v)])
                    .collect(),
                edges: cut.edges.iter().map(|&e| child.edges[e as usize]).collect(),
                faces: faces.iter().map(|&f| child.faces[f as usize]).collect(),
            },
            in_chunk: faces.iter().map(|&f| in_chunk[f as usize]).collect(),
            topology: cut.topology,
        })
    }

    /// The chunk's faces and points of the last level, from the piece of the level above.
    fn last_level(&self, piece: Piece) -> Result<ChunkLevel, RefineError> {
        let level = self.levels - 1;
        let in_chunk = piece.in_chunk;
        let r = self.refine_once(piece.topology, piece.rules)?;
        let sub = ChildLayout::new(r.topology(0), r.scheme(), 1).expect("a split");
        let keys = self
            .child_keys(&sub, level, r.topology(0), &piece.keys)
            .vertices;
        let mut out = ChunkLevel::default();
        let faces = r.face_stream().expect("one level");
        let t0 = r.topology(0);
        let mut used = vec![false; keys.len()];
        let mut local = Vec::new();
        for f in (0..t0.num_faces()).filter(|&f| in_chunk[f]) {
            let n = self.children(t0.face_size(f));
            let first = sub.child_face(0, f as u64, 0) as usize;
            local.clear();
            faces.fill(first..first + n, &mut local);
            for &v in &local {
                used[v as usize] = true;
                out.face_vertices.push(keys[v as usize] as u32);
            }
            let key = self.layout.child_face(level, piece.keys.faces[f], 0);
            match out.face_runs.last_mut() {
                Some((f0, m)) if *f0 + *m as u64 == key => *m += n,
                _ => out.face_runs.push((key, n)),
            }
        }
        let stream = r.point_stream(&piece.points).expect("one level");
        let mut all = vec![DVec3::ZERO; stream.len()];
        stream.fill(0, &mut all);
        chunk_points_out(&all, &keys, &used, &mut out);
        Ok(out)
    }

    /// One level of a prepared piece.
    fn refine_once(&self, topology: Topology, rules: Vec<Rule>) -> Result<Refinement, RefineError> {
        let scheme = self.prepared.scheme().clone();
        Refinement::from_prepared(topology, rules, scheme, self.prepared.options(), 1)
    }

    /// Child faces of a face of `size` corners: 4 for a triangle split, one per corner for
    /// a quad split.
    fn children(&self, size: usize) -> usize {
        match self.split() {
            Split::Triangle => 4,
            _ => size,
        }
    }

    /// Uniform indices of the elements of a piece's child level (numbered by `sub`, the
    /// piece's own layout), from those of the piece (level `level` of the mesh, topology
    /// `t`).
    fn child_keys(&self, sub: &ChildLayout, level: usize, t: &Topology, keys: &Keys) -> Keys {
        let next = sub.counts(1);
        let mut vertices = vec![0u64; next.vertices as usize];
        vertices[..keys.vertices.len()].copy_from_slice(&keys.vertices);
        if self.split() == Split::Quad {
            for (f, &key) in keys.faces.iter().enumerate() {
                vertices[sub.face_point(0, f as u64) as usize] = self.layout.face_point(level, key);
            }
        }
        for (e, &key) in keys.edges.iter().enumerate() {
            vertices[sub.edge_point(0, e as u64) as usize] = self.layout.edge_point(level, key);
        }
        let mut faces = vec![0u64; next.faces as usize];
        let mut edges = vec![0u64; next.edges as usize];
        for (f, &key) in keys.faces.iter().enumerate() {
            let n = t.face_size(f);
            for k in 0..self.children(n) {
                faces[sub.child_face(0, f as u64, k) as usize] =
                    self.layout.child_face(level, key, k);
            }
            let interior = if self.split() == Split::Triangle {
                3
            } else {
                n
            };
            for j in 0..interior {
                edges[sub.interior_edge(0, f as u64, j) as usize] =
                    self.layout.interior_edge(level, key, j);
            }
        }
        for (e, &key) in keys.edges.iter().enumerate() {
            for k in 0..2 {
                edges[sub.half_edge(0, e as u64, k) as usize] =
                    self.layout.half_edge(level, key, k);
            }
        }
        Keys {
            vertices,
            edges,
            faces,
        }
    }
}

/// The faces a chunk's piece of a level holds: those of the chunk (`in_chunk`) and every
/// face sharing a vertex with one, grown where a vertex would be pinched, ascending.
fn piece_faces(t: &Topology, in_chunk: &[bool]) -> Vec<u32> {
    // Marked, not sorted: a chunk's faces name millions of corners at the deep levels.
    let mut touched = vec![false; t.num_vertices()];
    for f in (0..t.num_faces()).filter(|&f| in_chunk[f]) {
        for &v in t.face_vertices(f) {
            touched[v as usize] = true;
        }
    }
    let vertices: Vec<u32> = (0..t.num_vertices() as u32)
        .filter(|&v| touched[v as usize])
        .collect();
    without_pinches(t, &faces_touching(t, &vertices))
}

/// The positions of the used vertices of the piece's last level (`all`), in runs of
/// consecutive uniform indices.
fn chunk_points_out(all: &[DVec3], keys: &[u64], used: &[bool], out: &mut ChunkLevel) {
    // Uniform index and piece index in one `u64` (both are below 2^32, `DepthFirst::new`
    // checks the level's count): one plain sort, on the calling thread (the chunks keep
    // every thread busy).
    let mut order: Vec<u64> = (0..keys.len())
        .filter(|&v| used[v])
        .map(|v| (keys[v] << 32) | v as u64)
        .collect();
    order.sort_unstable();
    out.points.reserve(order.len());
    let mut last = None;
    for &packed in &order {
        let (key, v) = (packed >> 32, packed & 0xffff_ffff);
        if last == Some(key) {
            continue;
        }
        last = Some(key);
        out.points.push(all[v as usize]);
        match out.point_runs.last_mut() {
            Some((first, n)) if *first + *n as u64 == key => *n += 1,
            _ => out.point_runs.push((key, 1)),
        }
    }
}

/// The isolated vertices of `t` (no face uses them): each is its own child at every level,
/// where it stays.
fn isolated_points(t: &Topology, base: &[DVec3]) -> ChunkLevel {
    let mut out = ChunkLevel::default();
    for v in (0..t.num_vertices()).filter(|&v| t.vertex_faces(v).is_empty()) {
        out.points.push(base[v]);
        match out.point_runs.last_mut() {
            Some((first, n)) if *first + *n as u64 == v as u64 => *n += 1,
            _ => out.point_runs.push((v as u64, 1)),
        }
    }
    out
}

/// Uniform indices of the vertices, edges and faces of a piece.
struct Keys {
    vertices: Vec<u64>,
    edges: Vec<u64>,
    faces: Vec<u64>,
}

/// A chunk's piece of a level: the faces descending from the chunk and their one-ring, cut
/// out with the level's tags, the rule and position of every vertex, every element's
/// uniform index, and which faces descend from the chunk.
struct Piece {
    topology: Topology,
    rules: Vec<Rule>,
    points: Vec<DVec3>,
    keys: Keys,
    in_chunk: Vec<bool>,
}

/// The base faces in compact chunks of `per_chunk` faces (fewer where a component or a
/// pocket runs out): each grown breadth-first across edges from the lowest face not yet
/// taken, ascending.
fn compact_chunks(t: &Topology, per_chunk: usize) -> Vec<Vec<u32>> {
    let nf = t.num_faces();
    let mut taken = vec![false; nf];
    let mut queued = vec![false; nf];
    let mut chunks = Vec::new();
    let mut queue = VecDeque::new();
    for seed in 0..nf {
        if taken[seed] {
            continue;
        }
        let mut chunk = Vec::with_capacity(per_chunk);
        queue.clear();
        queue.push_back(seed as u32);
        queued[seed] = true;
        while let Some(f) = queue.pop_front() {
            if chunk.len() == per_chunk {
                queued[f as usize] = false;
                continue;
            }
            taken[f as usize] = true;
            chunk.push(f);
            for &e in t.face_edges(f as usize) {
                for &g in t.edge_faces(e as usize) {
                    if !taken[g as usize] && !queued[g as usize] {
                        queued[g as usize] = true;
                        queue.push_back(g);
                    }
                }
            }
        }
        chunk.sort_unstable();
        chunks.push(chunk);
    }
    chunks
}

impl DepthFirst {
    /// Runs `visit` on every chunk, `threads` chunks at a time (so that at most that many
    /// pieces are held), in no set order. Each of `threads` workers takes the next chunk
    /// as soon as it is done with one (no worker waits for another); the work inside a
    /// chunk still runs on rayon's pool.
    ///
    /// # Errors
    /// The first error of a chunk's refinement or of `visit`; the workers stop at it.
    pub fn for_each_chunk<E>(
        &self,
        base: &[DVec3],
        threads: usize,
        visit: impl Fn(&ChunkLevel) -> Result<(), E> + Sync,
    ) -> Result<(), E>
    where
        E: From<RefineError> + Send,
    {
        let next = AtomicUsize::new(0);
        let failed: Mutex<Option<E>> = Mutex::new(None);
        let worker = || {
            loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                if i >= self.num_chunks() {
                    return;
                }
                let done = self.chunk(i, base).map_err(E::from).and_then(|c| visit(&c));
                if let Err(e) = done {
                    // Later chunks are not started; one error is reported.
                    next.store(usize::MAX / 2, Ordering::Relaxed);
                    let mut slot = failed.lock().unwrap_or_else(|p| p.into_inner());
                    slot.get_or_insert(e);
                    return;
                }
            }
        };
        std::thread::scope(|scope| {
            for _ in 0..threads.max(1) {
                scope.spawn(worker);
            }
        });
        match failed.into_inner().unwrap_or_else(|p| p.into_inner()) {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use subd_mesh::TopologyBuilder;

    /// What cannot be planned is an error naming why, never a panic or an overflow.
    #[test]
    fn plans_out_of_reach_are_errors() {
        let quad = TopologyBuilder::new(4).build(&[4], &[0, 1, 2, 3]).unwrap();
        let opts = Options::default();
        let plan = |scheme: Scheme, levels| DepthFirst::new(&quad, scheme, &opts, levels, 1);
        assert!(matches!(
            plan(Scheme::CatmullClark, 64),
            Err(RefineError::TooManyLevels { levels: 64, .. })
        ));
        assert!(matches!(
            plan(Scheme::CatmullClark, 0),
            Err(RefineError::Unsupported { .. })
        ));
        assert!(matches!(
            plan(Scheme::Sqrt3, 2),
            Err(RefineError::Unsupported { .. })
        ));
        assert!(matches!(
            plan(Scheme::Loop, 1),
            Err(RefineError::NotTriangle { face: 0, .. })
        ));
        // One quad to level 15: 2^30 faces, 2^30 + 2^16 + ... vertices, within 2^32.
        let deep = plan(Scheme::CatmullClark, 15).unwrap();
        assert_eq!(deep.counts().faces, 1 << 30);
        assert_eq!(deep.counts().vertices, ((1u64 << 15) + 1).pow(2));
    }
}
