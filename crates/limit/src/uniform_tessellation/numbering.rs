//! The numbering of a tessellation's samples, in parallel.
//!
//! The numbering is defined serially (see [`crate::tessellation`]): faces in order, each
//! face's grid row by row, and a sample on a base vertex or edge numbered by the first face
//! that reaches it, with that face's parameter. So the face that numbers a vertex or edge is
//! the lowest-numbered face around it that is not a hole (its *owner*), and the samples a
//! face numbers are a closed form of its size and of how many of its corners and sides it
//! owns. Counting them gives every chunk of faces its first sample; then two parallel
//! passes walk each chunk's faces in the serial order:
//!
//! 1. **assign**: number the chunk's samples, write their parameters and record the
//!    samples of the vertices and edges the chunk's faces own;
//! 2. **emit**: with every vertex and edge numbered, write the grids and the output faces
//!    (whose sizes are closed forms too, so each chunk writes its own slice).
//!
//! Both passes take the same walk ([`Walk`]) through a [`SampleSink`], so they agree with
//! each other and with the serial definition, which the tests keep as [`SerialSink`].

use std::sync::atomic::{AtomicU32, Ordering};

use rayon::prelude::*;
use subd_mesh::Topology;

use super::output::{Numbered, SampleGrid, Tessellation};
use crate::evaluation::eval::FaceParam;

/// Not numbered yet.
pub(crate) const UNSET: u32 = u32::MAX;

/// Faces per parallel job.
const CHUNK_FACES: usize = 512;

/// The mesh and rate a numbering walks.
#[derive(Clone, Copy)]
struct Grid<'a> {
    topo: &'a Topology,
    loop_scheme: bool,
    rate: u32,
}

/// What one walk does with the samples it meets.
trait SampleSink {
    /// A sample of the face alone (inside it, or on its spokes); its index.
    fn inner(&mut self, at: FaceParam) -> u32;
    /// Base vertex `v`'s sample, met by `face`; `at` is its parameter seen from `face`.
    fn vertex(&mut self, face: usize, v: u32, at: FaceParam) -> u32;
    /// The first of edge `e`'s `inner` samples, met by `face`; `at(k)` is the parameter of
    /// the k-th (k = 1 ..= inner, from the edge's first vertex) seen from `face`.
    fn edge(&mut self, face: usize, e: usize, inner: u32, at: &dyn Fn(u32) -> FaceParam) -> u32;
    /// A finished grid of (sub-)face `sub` of `face`.
    fn grid(&mut self, face: usize, sub: usize, segments: u32, samples: &[u32]);
    /// An output face.
    fn face(&mut self, vertices: &[u32]);
}

/// The walk of the faces in the serial order, generic over what is done with the samples.
struct Walk<'a, S> {
    grid: Grid<'a>,
    sink: S,
    /// The grid being filled (scratch, reused face to face).
    samples: Vec<u32>,
}

impl<'a, S: SampleSink> Walk<'a, S> {
    fn new(grid: Grid<'a>, sink: S) -> Self {
        Walk {
            grid,
            sink,
            samples: Vec::new(),
        }
    }

    /// Face `f` (holes are skipped).
    fn face(&mut self, f: usize) {
        let topo = self.grid.topo;
        if topo.is_hole(f) {
            return;
        }
        if self.grid.loop_scheme {
            self.triangle(f);
        } else if topo.face_size(f) == 4 {
            self.quad(f);
        } else {
            self.polygon(f);
        }
    }

    /// The scratch grid, `len` entries long, taken out of `self` while it is filled.
    fn take_samples(&mut self, len: usize) -> Vec<u32> {
        let mut samples = std::mem::take(&mut self.samples);
        samples.clear();
        samples.resize(len, 0);
        samples
    }

    /// A Catmull-Clark face that is not a quad: its centre and its n spokes (midpoint of a
    /// side to the centre) belong to it alone, then its n quad sub-faces.
    fn polygon(&mut self, f: usize) {
        let n = self.grid.topo.face_size(f);
        let m = self.grid.rate / 2;
        let centre = self.sink.inner(param(f, 0, 1, 1, 1));
        // The spokes are numbered one after another, so the first one's index gives all.
        let mut spokes = UNSET;
        for side in 0..n {
            for k in 1..m {
                // On sub-face `side`, the spoke of side `side` is its line u = 1.
                let s = self.sink.inner(param(f, side, m, k, m));
                spokes = spokes.min(s);
            }
        }
        for sub in 0..n {
            self.sub_face(f, sub, centre, spokes);
        }
    }

    /// The sample at step `t` of `rate` along the face's side `side` (from corner `side` to
    /// `side + 1`).
    fn on_side(&mut self, face: usize, side: usize, t: u32) -> u32 {
        let g = self.grid;
        let fv = g.topo.face_vertices(face);
        let (a, b) = (fv[side], fv[(side + 1) % fv.len()]);
        let rate = g.rate;
        if t == 0 || t == rate {
            let v = if t == 0 { a } else { b };
            return self.sink.vertex(face, v, g.side_param(face, side, t));
        }
        let e = g.topo.face_edges(face)[side] as usize;
        // Counted from the edge's first vertex, so both faces of the edge name it alike.
        let forward = g.topo.edge_vertices(e)[0] == a && a != b;
        let along = |k: u32| if forward { k } else { rate - k };
        let first = self
            .sink
            .edge(face, e, rate - 1, &|k| g.side_param(face, side, along(k)));
        first + along(t) - 1
    }

    /// A quad: corners 0, 1, 2, 3 at (0,0), (1,0), (1,1), (0,1).
    fn quad(&mut self, face: usize) {
        let n = self.grid.rate;
        let mut grid = self.take_samples(((n + 1) * (n + 1)) as usize);
        for j in 0..=n {
            for i in 0..=n {
                grid[(j * (n + 1) + i) as usize] = match (i, j) {
                    (_, 0) => self.on_side(face, 0, i),
                    (i, _) if i == n => self.on_side(face, 1, j),
                    (_, j) if j == n => self.on_side(face, 2, n - i),
                    (0, _) => self.on_side(face, 3, n - j),
                    _ => self.sink.inner(param(face, 0, i, j, n)),
                };
            }
        }
        self.finish_quads(face, 0, n, grid);
    }

    /// Sub-face `sub` of a non-quad: corner `sub` at (0,0), u towards the midpoint of side
    /// `sub`, v towards the midpoint of side `sub − 1`, the face centre at (1,1). `centre`
    /// and `spokes` are the face's own samples (`spokes`: side by side, `m − 1` each, from
    /// the side's midpoint inwards).
    fn sub_face(&mut self, face: usize, sub: usize, centre: u32, spokes: u32) {
        let m = self.grid.rate / 2;
        let sides = self.grid.topo.face_size(face);
        let prev = (sub + sides - 1) % sides;
        let spoke = |side: usize, k: u32| spokes + side as u32 * (m - 1) + k - 1;
        let mut grid = self.take_samples(((m + 1) * (m + 1)) as usize);
        for j in 0..=m {
            for i in 0..=m {
                grid[(j * (m + 1) + i) as usize] = match (i, j) {
                    (i, j) if i == m && j == m => centre,
                    (_, 0) => self.on_side(face, sub, i),
                    (0, _) => self.on_side(face, prev, self.grid.rate - j),
                    (i, _) if i == m => spoke(sub, j),
                    (_, j) if j == m => spoke(prev, i),
                    _ => self.sink.inner(param(face, sub, i, j, m)),
                };
            }
        }
        self.finish_quads(face, sub, m, grid);
    }

    /// Hands a filled quad grid of `n` segments and its quads to the sink.
    fn finish_quads(&mut self, face: usize, sub: usize, n: u32, grid: Vec<u32>) {
        self.sink.grid(face, sub, n, &grid);
        let at = |i: u32, j: u32| grid[(j * (n + 1) + i) as usize];
        for j in 0..n {
            for i in 0..n {
                self.sink
                    .face(&[at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        self.samples = grid;
    }

    /// A Loop triangle: corners 0, 1, 2 at (0,0), (1,0), (0,1).
    fn triangle(&mut self, face: usize) {
        let n = self.grid.rate;
        let row = |j: u32| (j * (2 * n + 3 - j) / 2) as usize;
        let mut grid = self.take_samples(row(n + 1));
        for j in 0..=n {
            for i in 0..=(n - j) {
                grid[row(j) + i as usize] = match (i, j) {
                    (_, 0) => self.on_side(face, 0, i),
                    (i, j) if i + j == n => self.on_side(face, 1, j),
                    (0, _) => self.on_side(face, 2, n - j),
                    _ => self.sink.inner(param(face, 0, i, j, n)),
                };
            }
        }
        self.sink.grid(face, 0, n, &grid);
        let at = |i: u32, j: u32| grid[row(j) + i as usize];
        for j in 0..n {
            for i in 0..(n - j) {
                self.sink.face(&[at(i, j), at(i + 1, j), at(i, j + 1)]);
                if i + j + 1 < n {
                    self.sink
                        .face(&[at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
                }
            }
        }
        self.samples = grid;
    }
}

/// The parameter (i, j) / m of sub-face `sub` of `face`, from integers so that a sample has
/// the same bits whichever way it is reached.
fn param(face: usize, sub: usize, i: u32, j: u32, m: u32) -> FaceParam {
    FaceParam {
        face,
        sub,
        u: f64::from(i) / f64::from(m),
        v: f64::from(j) / f64::from(m),
    }
}

impl Grid<'_> {
    /// The parameter of step `t` along side `side` of `face`.
    fn side_param(&self, face: usize, side: usize, t: u32) -> FaceParam {
        let n = self.rate;
        if self.loop_scheme {
            return match side {
                0 => param(face, 0, t, 0, n),
                1 => param(face, 0, n - t, t, n),
                _ => param(face, 0, 0, n - t, n),
            };
        }
        let size = self.topo.face_size(face);
        if size == 4 {
            return match side {
                0 => param(face, 0, t, 0, n),
                1 => param(face, 0, n, t, n),
                2 => param(face, 0, n - t, n, n),
                _ => param(face, 0, 0, n - t, n),
            };
        }
        // The first half of a side is on sub-face `side` (its u axis), the second half on
        // sub-face `side + 1` (its v axis, from the far corner).
        let m = n / 2;
        if t <= m {
            param(face, side, t, 0, m)
        } else {
            param(face, (side + 1) % size, 0, n - t, m)
        }
    }

    /// What face `f` adds: samples it numbers (given how many of its corners and sides it
    /// owns), grids, grid entries and output face corners.
    fn face_counts(&self, f: usize, owned_corners: u32, owned_sides: u32) -> Counts {
        let n = self.rate as usize;
        if self.topo.is_hole(f) {
            return Counts::default();
        }
        let shared = owned_corners as usize + owned_sides as usize * (n - 1);
        if self.loop_scheme {
            return Counts {
                samples: shared + (n - 1) * n.saturating_sub(2) / 2,
                grids: 1,
                grid_vertices: (n + 1) * (n + 2) / 2,
                face_vertices: 3 * n * n,
            };
        }
        let size = self.topo.face_size(f);
        if size == 4 {
            return Counts {
                samples: shared + (n - 1) * (n - 1),
                grids: 1,
                grid_vertices: (n + 1) * (n + 1),
                face_vertices: 4 * n * n,
            };
        }
        // The centre, the spokes and the sub-faces' insides.
        let m = n / 2;
        Counts {
            samples: shared + 1 + size * (m - 1) + size * (m - 1) * (m - 1),
            grids: size,
            grid_vertices: size * (m + 1) * (m + 1),
            face_vertices: 4 * size * m * m,
        }
    }
}

/// What a face or a run of faces adds to each array.
#[derive(Clone, Copy, Default, Debug, PartialEq)]
struct Counts {
    samples: usize,
    grids: usize,
    grid_vertices: usize,
    face_vertices: usize,
}

impl std::ops::Add for Counts {
    type Output = Counts;
    fn add(self, o: Counts) -> Counts {
        Counts {
            samples: self.samples + o.samples,
            grids: self.grids + o.grids,
            grid_vertices: self.grid_vertices + o.grid_vertices,
            face_vertices: self.face_vertices + o.face_vertices,
        }
    }
}

/// The lowest face around each vertex (`incident(v)`) that is not a hole; [`UNSET`] where
/// there is none.
fn owners<'a, I: IntoIterator<Item = &'a u32>>(
    topo: &Topology,
    n: usize,
    incident: impl Fn(usize) -> I + Sync,
) -> Vec<u32> {
    (0..n)
        .into_par_iter()
        .map(|x| {
            incident(x)
                .into_iter()
                .copied()
                .filter(|&f| !topo.is_hole(f as usize))
                .min()
                .unwrap_or(UNSET)
        })
        .collect()
}

/// Numbers the samples of every face that is not a hole, as the serial walk does.
pub(crate) fn number_samples(topo: &Topology, loop_scheme: bool, rate: u32) -> Numbered {
    let grid = Grid {
        topo,
        loop_scheme,
        rate,
    };
    let owner = Owners {
        vertex: owners(topo, topo.num_vertices(), |v| topo.vertex_faces(v)),
        edge: owners(topo, topo.num_edges(), |e| topo.edge_faces(e)),
    };
    let starts = chunk_starts(&grid, &owner);
    let total = *starts.last().expect("one more start than chunks");
    let vertex_sample: Vec<AtomicU32> = (0..topo.num_vertices())
        .map(|_| AtomicU32::new(UNSET))
        .collect();
    let edge_first: Vec<AtomicU32> = (0..topo.num_edges())
        .map(|_| AtomicU32::new(UNSET))
        .collect();
    let numbers = Numbers {
        owner: &owner,
        vertex_sample: &vertex_sample,
        edge_first: &edge_first,
    };
    let params = assign(&grid, &numbers, &starts);
    let out = emit(&grid, &numbers, &starts, total);
    Numbered { params, out }
}

/// Which face numbers each vertex's and edge's samples.
struct Owners {
    vertex: Vec<u32>,
    edge: Vec<u32>,
}

/// The shared numbering state of the two passes.
struct Numbers<'a> {
    owner: &'a Owners,
    /// Each base vertex's sample.
    vertex_sample: &'a [AtomicU32],
    /// The first of each base edge's inner samples.
    edge_first: &'a [AtomicU32],
}

/// What each chunk of [`CHUNK_FACES`] faces starts at, and the totals after the last.
fn chunk_starts(grid: &Grid, owner: &Owners) -> Vec<Counts> {
    let topo = grid.topo;
    let face = |f: usize| {
        let f32 = f as u32;
        let owned = |xs: &[u32], of: &[u32]| {
            // A corner or side repeated in a degenerate face is numbered once.
            (0..xs.len())
                .filter(|&k| of[xs[k] as usize] == f32 && !xs[..k].contains(&xs[k]))
                .count() as u32
        };
        let corners = owned(topo.face_vertices(f), &owner.vertex);
        let sides = owned(topo.face_edges(f), &owner.edge);
        grid.face_counts(f, corners, sides)
    };
    let per_chunk: Vec<Counts> = (0..topo.num_faces().div_ceil(CHUNK_FACES))
        .into_par_iter()
        .map(|c| {
            let end = ((c + 1) * CHUNK_FACES).min(topo.num_faces());
            (c * CHUNK_FACES..end)
                .map(face)
                .fold(Counts::default(), |a, b| a + b)
        })
        .collect();
    let mut starts = Vec::with_capacity(per_chunk.len() + 1);
    let mut at = Counts::default();
    starts.push(at);
    for c in per_chunk {
        at = at + c;
        starts.push(at);
    }
    starts
}

/// The faces of chunk `c`.
fn chunk_faces(topo: &Topology, c: usize) -> std::ops::Range<usize> {
    c * CHUNK_FACES..((c + 1) * CHUNK_FACES).min(topo.num_faces())
}

/// Splits `v` into consecutive slices of `lengths`.
fn split_lengths<T>(mut v: &mut [T], lengths: impl Iterator<Item = usize>) -> Vec<&mut [T]> {
    lengths
        .map(|len| {
            let (head, tail) = std::mem::take(&mut v).split_at_mut(len);
            v = tail;
            head
        })
        .collect()
}

/// Pass 1: numbers every sample and gives the vertices and edges their samples; returns
/// the samples' parameters.
fn assign(grid: &Grid, numbers: &Numbers, starts: &[Counts]) -> Vec<FaceParam> {
    let total = starts.last().map_or(0, |c| c.samples);
    let unset = param(0, 0, 0, 0, 1);
    // Huge pages where large: a rate-8 tessellation's parameters are ~200 MB, and 4 KiB
    // page faults on them cost as much as numbering them.
    let mut params = subd_mesh::memory::with_capacity::<FaceParam>(total);
    params.par_extend(rayon::iter::repeat_n(unset, total));
    let lengths = starts.windows(2).map(|w| w[1].samples - w[0].samples);
    split_lengths(&mut params, lengths)
        .into_par_iter()
        .enumerate()
        .for_each(|(c, params)| {
            let sink = Assign {
                numbers,
                next: starts[c].samples as u32,
                first: starts[c].samples as u32,
                params,
            };
            let mut walk = Walk::new(*grid, sink);
            chunk_faces(grid.topo, c).for_each(|f| walk.face(f));
            debug_assert_eq!(walk.sink.next, starts[c + 1].samples as u32);
        });
    params
}

/// Pass 2: writes the grids and the output faces.
fn emit(grid: &Grid, numbers: &Numbers, starts: &[Counts], total: Counts) -> Tessellation {
    let corners = if grid.loop_scheme { 3 } else { 4 };
    let no_grid = SampleGrid {
        face: 0,
        sub: 0,
        segments: 0,
        start: 0,
    };
    let mut grids = vec![no_grid; total.grids];
    let mut grid_vertices = subd_mesh::memory::zeroed::<u32>(total.grid_vertices);
    let mut face_vertices = subd_mesh::memory::zeroed::<u32>(total.face_vertices);
    let lengths = |k: fn(&Counts) -> usize| starts.windows(2).map(move |w| k(&w[1]) - k(&w[0]));
    let slices = split_lengths(&mut grids, lengths(|c| c.grids))
        .into_iter()
        .zip(split_lengths(
            &mut grid_vertices,
            lengths(|c| c.grid_vertices),
        ))
        .zip(split_lengths(
            &mut face_vertices,
            lengths(|c| c.face_vertices),
        ));
    slices
        .collect::<Vec<_>>()
        .into_par_iter()
        .enumerate()
        .for_each(|(c, ((grids, grid_vertices), face_vertices))| {
            let sink = Emit {
                numbers,
                next: starts[c].samples as u32,
                grid_start: starts[c].grid_vertices as u32,
                grids: SliceWriter::new(grids),
                grid_vertices: SliceWriter::new(grid_vertices),
                face_vertices: SliceWriter::new(face_vertices),
            };
            let mut walk = Walk::new(*grid, sink);
            chunk_faces(grid.topo, c).for_each(|f| walk.face(f));
        });
    let num_faces = total.face_vertices / corners;
    Tessellation {
        positions: Vec::new(),
        normals: Vec::new(),
        params: Vec::new(),
        face_offsets: face_offsets(num_faces, corners as u32),
        face_vertices,
        grids,
        grid_vertices,
    }
}

/// The offsets of `num_faces` faces of `corners` corners each.
fn face_offsets(num_faces: usize, corners: u32) -> Vec<u32> {
    let mut offsets = subd_mesh::memory::with_capacity::<u32>(num_faces + 1);
    offsets.par_extend((0..=num_faces as u32).into_par_iter().map(|k| k * corners));
    offsets
}

/// Pass 1's sink: numbers the chunk's samples from `next` and writes their parameters.
struct Assign<'a, 'p> {
    numbers: &'a Numbers<'a>,
    next: u32,
    /// The chunk's first sample (`params[0]`).
    first: u32,
    params: &'p mut [FaceParam],
}

impl Assign<'_, '_> {
    fn push(&mut self, at: FaceParam) -> u32 {
        self.params[(self.next - self.first) as usize] = at;
        self.next += 1;
        self.next - 1
    }
}

impl SampleSink for Assign<'_, '_> {
    fn inner(&mut self, at: FaceParam) -> u32 {
        self.push(at)
    }

    fn vertex(&mut self, face: usize, v: u32, at: FaceParam) -> u32 {
        let n = self.numbers;
        if n.owner.vertex[v as usize] != face as u32 {
            // An earlier face's to number; pass 2 reads it. This pass writes no grid, so
            // the number is not used.
            return 0;
        }
        let slot = &n.vertex_sample[v as usize];
        match slot.load(Ordering::Relaxed) {
            UNSET => {
                let s = self.push(at);
                slot.store(s, Ordering::Relaxed);
                s
            }
            s => s,
        }
    }

    fn edge(&mut self, face: usize, e: usize, inner: u32, at: &dyn Fn(u32) -> FaceParam) -> u32 {
        let n = self.numbers;
        if n.owner.edge[e] != face as u32 {
            return 0;
        }
        let slot = &n.edge_first[e];
        match slot.load(Ordering::Relaxed) {
            UNSET => {
                let first = self.next;
                for k in 1..=inner {
                    self.push(at(k));
                }
                slot.store(first, Ordering::Relaxed);
                first
            }
            s => s,
        }
    }

    fn grid(&mut self, _: usize, _: usize, _: u32, _: &[u32]) {}

    fn face(&mut self, _: &[u32]) {}
}

/// Pass 2's sink: reads every sample's number and writes grids and faces.
struct Emit<'a, 'o> {
    numbers: &'a Numbers<'a>,
    next: u32,
    /// Where the chunk's grid entries start in the whole array.
    grid_start: u32,
    grids: SliceWriter<'o, SampleGrid>,
    grid_vertices: SliceWriter<'o, u32>,
    face_vertices: SliceWriter<'o, u32>,
}

impl SampleSink for Emit<'_, '_> {
    fn inner(&mut self, _: FaceParam) -> u32 {
        self.next += 1;
        self.next - 1
    }

    // A vertex or edge is numbered where pass 1, walking the same way, met it first: its
    // number is then the next one. Anywhere else its number is lower: an earlier face's,
    // or this face's from an earlier meeting.
    fn vertex(&mut self, _: usize, v: u32, _: FaceParam) -> u32 {
        let s = self.numbers.vertex_sample[v as usize].load(Ordering::Relaxed);
        if s == self.next {
            self.next += 1;
        }
        s
    }

    fn edge(&mut self, _: usize, e: usize, inner: u32, _: &dyn Fn(u32) -> FaceParam) -> u32 {
        let first = self.numbers.edge_first[e].load(Ordering::Relaxed);
        if first == self.next {
            self.next += inner;
        }
        first
    }

    fn grid(&mut self, face: usize, sub: usize, segments: u32, samples: &[u32]) {
        let start = self.grid_start + self.grid_vertices.at as u32;
        self.grids.push(SampleGrid {
            face,
            sub,
            segments,
            start,
        });
        self.grid_vertices.extend(samples);
    }

    fn face(&mut self, vertices: &[u32]) {
        self.face_vertices.extend(vertices);
    }
}

/// Writes a slice front to back.
struct SliceWriter<'o, T> {
    slice: &'o mut [T],
    at: usize,
}

impl<'o, T: Copy> SliceWriter<'o, T> {
    fn new(slice: &'o mut [T]) -> Self {
        SliceWriter { slice, at: 0 }
    }

    fn push(&mut self, x: T) {
        self.slice[self.at] = x;
        self.at += 1;
    }

    fn extend(&mut self, xs: &[T]) {
        self.slice[self.at..self.at + xs.len()].copy_from_slice(xs);
        self.at += xs.len();
    }
}

/// The serial definition of the numbering: faces in order, each vertex and edge numbered by
/// the first face that meets it.
#[cfg(test)]
struct SerialSink {
    vertex_sample: Vec<u32>,
    edge_first: Vec<u32>,
    params: Vec<FaceParam>,
    out: Tessellation,
}

#[cfg(test)]
impl SampleSink for SerialSink {
    fn inner(&mut self, at: FaceParam) -> u32 {
        self.params.push(at);
        self.params.len() as u32 - 1
    }

    fn vertex(&mut self, _: usize, v: u32, at: FaceParam) -> u32 {
        if self.vertex_sample[v as usize] == UNSET {
            self.vertex_sample[v as usize] = self.inner(at);
        }
        self.vertex_sample[v as usize]
    }

    fn edge(&mut self, _: usize, e: usize, inner: u32, at: &dyn Fn(u32) -> FaceParam) -> u32 {
        if self.edge_first[e] == UNSET {
            self.edge_first[e] = self.params.len() as u32;
            self.params.extend((1..=inner).map(at));
        }
        self.edge_first[e]
    }

    fn grid(&mut self, face: usize, sub: usize, segments: u32, samples: &[u32]) {
        let start = self.out.grid_vertices.len() as u32;
        self.out.grids.push(SampleGrid {
            face,
            sub,
            segments,
            start,
        });
        self.out.grid_vertices.extend_from_slice(samples);
    }

    fn face(&mut self, vertices: &[u32]) {
        self.out.face_vertices.extend_from_slice(vertices);
        let end = self.out.face_vertices.len() as u32;
        self.out.face_offsets.push(end);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use subd_mesh::{TopologyBuilder, primitives};

    fn serial(topo: &Topology, loop_scheme: bool, rate: u32) -> Numbered {
        let sink = SerialSink {
            vertex_sample: vec![UNSET; topo.num_vertices()],
            edge_first: vec![UNSET; topo.num_edges()],
            params: Vec::new(),
            out: Tessellation {
                positions: Vec::new(),
                normals: Vec::new(),
                params: Vec::new(),
                face_offsets: vec![0],
                face_vertices: Vec::new(),
                grids: Vec::new(),
                grid_vertices: Vec::new(),
            },
        };
        let grid = Grid {
            topo,
            loop_scheme,
            rate,
        };
        let mut walk = Walk::new(grid, sink);
        (0..topo.num_faces()).for_each(|f| walk.face(f));
        let s = walk.sink;
        Numbered {
            params: s.params,
            out: s.out,
        }
    }

    fn assert_same(topo: &Topology, loop_scheme: bool, rate: u32) {
        let a = serial(topo, loop_scheme, rate);
        // Several threads, so chunks meet vertices and edges other chunks own.
        let b = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .unwrap()
            .install(|| number_samples(topo, loop_scheme, rate));
        assert_eq!(a.params, b.params, "rate {rate}");
        assert_eq!(a.out.face_offsets, b.out.face_offsets);
        assert_eq!(a.out.face_vertices, b.out.face_vertices);
        assert_eq!(a.out.grids, b.out.grids);
        assert_eq!(a.out.grid_vertices, b.out.grid_vertices);
    }

    /// Quads and hexagons over many chunks, some faces holes (so some vertices and edges
    /// are first met by a later face, or by none).
    #[test]
    fn parallel_numbering_is_the_serial_one() {
        let mut mesh = primitives::torus_with_hexagons(48, 40, 5, 3.0, 1.0).topology;
        let holes = (0..mesh.num_faces())
            .map(|f| f % 7 == 3 || f % 11 == 0)
            .collect();
        let (ne, nv) = (mesh.num_edges(), mesh.num_vertices());
        mesh.set_all_tags(vec![0.0; ne], vec![0.0; nv], holes)
            .unwrap();
        for rate in [1, 2, 3, 4, 6, 8] {
            if rate % 2 == 0 {
                assert_same(&mesh, false, rate);
            }
        }
        let quads = primitives::torus(40, 30, 3.0, 1.0).topology;
        for rate in [1, 2, 3, 5] {
            assert_same(&quads, false, rate);
        }
        let sizes = vec![3u32; 2 * quads.num_faces()];
        let triangles: Vec<u32> = (0..quads.num_faces())
            .flat_map(|f| {
                let v = quads.face_vertices(f);
                [v[0], v[1], v[2], v[0], v[2], v[3]]
            })
            .collect();
        let tri = TopologyBuilder::new(quads.num_vertices())
            .build(&sizes, &triangles)
            .unwrap();
        for rate in [1, 2, 3, 4, 7] {
            assert_same(&tri, true, rate);
        }
    }
}
