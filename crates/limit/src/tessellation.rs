//! Uniform tessellation of the limit surface: every face sampled on a regular grid of `rate`
//! segments per base edge, in OpenSubdiv's parameterisation (as `Bfr::Tessellation` with a
//! uniform rate), into one watertight mesh.
//!
//! * A Catmull-Clark quad: an (N + 1)² grid of quads over (u, v) = (i/N, j/N).
//! * A Catmull-Clark face of n ≠ 4 sides: its n quad sub-faces (`FaceParam::sub`, the quad at
//!   each corner after one step, as `Bfr`'s quad sub-faces), each an (N/2 + 1)² grid, so its
//!   edges get N segments like a quad's. N must be even then.
//! * A Loop triangle: the barycentric grid (i/N, j/N), i + j ≤ N, of N² triangles.
//! * Hole faces are left out.
//!
//! Watertight by construction: a sample on a base vertex, on a base edge or on a sub-face
//! boundary is evaluated once, from the first face that reaches it, and shared by index, so
//! the two sides of an edge hold the same bits and a closed input gives a closed, manifold
//! output.
//!
//! Two passes: the samples are numbered first (serially, by arithmetic on the base vertex,
//! edge and face indices, each with the parameter of the first face that reaches it), then
//! evaluated in parallel; each sample's value depends only on its own parameter, so any
//! number of threads gives the same bits.

use glam::DVec3;
use rayon::prelude::*;
use subd_mesh::Topology;
use subd_schemes::{Options, Scheme};

use crate::LimitError;
use crate::eval::{FaceParam, LimitEvaluator, PatchPoints};

/// The largest rate accepted.
pub const MAX_RATE: usize = 1024;

/// A tessellated limit surface.
#[derive(Debug, Clone)]
pub struct Tessellation {
    /// Positions on the limit surface.
    pub positions: Vec<DVec3>,
    /// Unit normals there (zero where the surface has no tangent plane).
    pub normals: Vec<DVec3>,
    /// Where each sample was evaluated.
    pub params: Vec<FaceParam>,
    /// Face offsets into [`Self::face_vertices`]: quads (Catmull-Clark) or triangles (Loop).
    pub face_offsets: Vec<u32>,
    /// Vertices of each output face, counter-clockwise as the base face.
    pub face_vertices: Vec<u32>,
    /// Each tessellated (face, sub-face) with its grid of samples, in face order.
    pub grids: Vec<SampleGrid>,
    /// The samples of every grid, row by row (`v` rows of `u`), as vertex indices.
    pub grid_vertices: Vec<u32>,
}

/// The samples of one face (or sub-face): the vertex at (u, v) = (i, j) / `segments` is
/// `grid_vertices[start + index]`, where `index` is `j (segments + 1) + i` on a quad and
/// `j (2 segments + 3 − j) / 2 + i` (i + j ≤ segments) on a triangle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleGrid {
    /// Base face.
    pub face: usize,
    /// Sub-face (0 for quads and triangles).
    pub sub: usize,
    /// Segments per side.
    pub segments: u32,
    /// Offset of its first sample in [`Tessellation::grid_vertices`].
    pub start: u32,
}

impl Tessellation {
    /// The output vertex at grid point (i, j) of `grid` (see [`SampleGrid`]).
    pub fn grid_vertex(&self, grid: &SampleGrid, triangle: bool, i: u32, j: u32) -> u32 {
        let n = grid.segments;
        let index = if triangle {
            j * (2 * n + 3 - j) / 2 + i
        } else {
            j * (n + 1) + i
        };
        self.grid_vertices[(grid.start + index) as usize]
    }
}

/// Tessellates the limit surface of `points` (from [`LimitEvaluator::prepare`]) at `rate`.
///
/// # Errors
/// A rate of 0 or above [`MAX_RATE`], an odd rate on a Catmull-Clark mesh with non-quad
/// faces, and the evaluator's errors (a face it does not cover) naming the face.
///
/// ```
/// use subd_limit::eval::LimitEvaluator;
/// use subd_limit::tessellation::tessellate;
/// use subd_mesh::{DVec3, TopologyBuilder};
/// use subd_schemes::{Options, Scheme};
///
/// let faces = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4];
/// let cube = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
/// let s = [(-1., -1., 1.), (1., -1., 1.), (-1., 1., 1.), (1., 1., 1.),
///          (-1., 1., -1.), (1., 1., -1.), (-1., -1., -1.), (1., -1., -1.)];
/// let p: Vec<DVec3> = s.iter().map(|&(x, y, z)| DVec3::new(x, y, z)).collect();
/// let eval = LimitEvaluator::new(&cube, &Scheme::CatmullClark, &Options::default()).unwrap();
/// let t = tessellate(&eval, &eval.prepare(&p), 4).unwrap();
/// assert_eq!(t.face_offsets.len() - 1, 6 * 16);
/// // Shared samples: V - E + F = 2 for the closed grid, 6·16 quads.
/// assert_eq!(t.positions.len(), 6 * 16 + 2);
/// ```
pub fn tessellate(
    evaluator: &LimitEvaluator,
    points: &PatchPoints,
    rate: usize,
) -> Result<Tessellation, LimitError> {
    let topo = evaluator.topology();
    let loop_scheme = evaluator.scheme == Scheme::Loop;
    check_rate(topo, loop_scheme, rate)?;
    let Numbered {
        params, mut out, ..
    } = number_samples(topo, loop_scheme, rate as u32);
    let evaluated: Result<Vec<(DVec3, DVec3)>, LimitError> = params
        .par_iter()
        .map(|&at| evaluator.evaluate_position_normal(points, at))
        .collect();
    let evaluated = match evaluated {
        Ok(values) => values,
        Err(any) => {
            // The first failing sample's error, not whichever a thread met first.
            let first = params
                .iter()
                .find_map(|&at| evaluator.evaluate_position_normal(points, at).err());
            return Err(first.unwrap_or(any));
        }
    };
    (out.positions, out.normals) = evaluated.into_iter().unzip();
    out.params = params;
    Ok(out)
}

/// Tessellates the limit surface of `positions` on `topology` at `rate`, as [`tessellate`]
/// does with an evaluator of the mesh: the same samples, faces and grids, the same values to
/// rounding. A rate that is a power of two on a manifold Catmull-Clark or Loop mesh takes
/// uniform refinement instead, its samples being the vertices of the refined level: the
/// limit masks of that level ([`crate::level_limit_points`]), one pass over its vertices,
/// in place of one patch evaluation per sample (positions agree with the evaluator's to
/// ~1e-15 of the mesh's size, normals to ~1e-12). Other rates build a [`LimitEvaluator`].
///
/// ```
/// use subd_limit::tessellation::tessellate_mesh;
/// use subd_mesh::{DVec3, TopologyBuilder};
/// use subd_schemes::{Options, Scheme};
///
/// let faces = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4];
/// let cube = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
/// let p: Vec<DVec3> = (0..8)
///     .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
///     .collect();
/// let t = tessellate_mesh(&cube, &Scheme::CatmullClark, &Options::default(), &p, 8).unwrap();
/// assert_eq!(t.face_offsets.len() - 1, 6 * 64);
/// assert_eq!(t.positions.len(), 6 * 64 + 2);
/// ```
///
/// # Errors
/// As [`tessellate`], and [`LimitError::Param`] when `positions` does not hold one point
/// per vertex of `topology`.
pub fn tessellate_mesh(
    topology: &Topology,
    scheme: &Scheme,
    options: &Options,
    positions: &[DVec3],
    rate: usize,
) -> Result<Tessellation, LimitError> {
    if positions.len() != topology.num_vertices() {
        return Err(LimitError::Param(format!(
            "{} positions for {} vertices",
            positions.len(),
            topology.num_vertices()
        )));
    }
    check_range(rate)?;
    if let Some(levels) = crate::tess_refined::depth(topology, scheme, rate) {
        return crate::tess_refined::tessellate_refined(
            topology, scheme, options, positions, levels,
        );
    }
    let evaluator = LimitEvaluator::new(topology, scheme, options)?;
    tessellate(&evaluator, &evaluator.prepare(positions), rate)
}

/// Checks `rate`: 1 to [`MAX_RATE`], even where a Catmull-Clark face is not a quad.
pub(crate) fn check_rate(
    topo: &Topology,
    loop_scheme: bool,
    rate: usize,
) -> Result<(), LimitError> {
    check_range(rate)?;
    if !loop_scheme && rate % 2 == 1 {
        if let Some(f) = (0..topo.num_faces()).find(|&f| topo.face_size(f) != 4 && !topo.is_hole(f))
        {
            return Err(LimitError::Param(format!(
                "rate {rate}: face {f} is not a quad, and its quad sub-faces take half the rate each; use an even rate"
            )));
        }
    }
    Ok(())
}

/// Checks that `rate` is 1 to [`MAX_RATE`].
fn check_range(rate: usize) -> Result<(), LimitError> {
    if rate == 0 || rate > MAX_RATE {
        return Err(LimitError::Param(format!(
            "rate {rate}: expected 1 to {MAX_RATE}"
        )));
    }
    Ok(())
}

/// The samples of a tessellation before evaluation.
pub(crate) struct Numbered {
    /// The parameter of each sample.
    pub params: Vec<FaceParam>,
    /// The output faces and grids over the samples (positions and normals left empty).
    pub out: Tessellation,
    /// Each base vertex's sample (`u32::MAX` where no face reaches it).
    pub vertex_sample: Vec<u32>,
}

/// Numbers the samples of every face that is not a hole (see the module docs).
pub(crate) fn number_samples(topo: &Topology, loop_scheme: bool, rate: u32) -> Numbered {
    let sizes = GridSizes::of(topo, loop_scheme, rate);
    let mut face_offsets = Vec::with_capacity(sizes.faces + 1);
    face_offsets.push(0);
    let mut t = Builder {
        topo,
        loop_scheme,
        rate,
        vertex_index: vec![UNSET; topo.num_vertices()],
        edge_first: vec![UNSET; topo.num_edges()],
        params: Vec::with_capacity(sizes.grid_vertices),
        out: Tessellation {
            positions: Vec::new(),
            normals: Vec::new(),
            params: Vec::new(),
            face_offsets,
            face_vertices: Vec::with_capacity(sizes.face_vertices),
            grids: Vec::with_capacity(sizes.grids),
            grid_vertices: Vec::with_capacity(sizes.grid_vertices),
        },
        grid: Vec::new(),
    };
    for f in 0..topo.num_faces() {
        if topo.is_hole(f) {
            continue;
        }
        let n = topo.face_size(f);
        if loop_scheme {
            t.triangle(f);
        } else if n == 4 {
            t.quad(f);
        } else {
            t.polygon(f);
        }
    }
    Numbered {
        params: t.params,
        out: t.out,
        vertex_sample: t.vertex_index,
    }
}

/// Not numbered yet.
const UNSET: u32 = u32::MAX;

/// The sizes of a tessellation's arrays, counted before they are filled so that each is
/// allocated once (a grow-by-doubling copy of the samples' parameters cost as much as
/// numbering them). The samples are fewer than the grids' entries, which count shared ones
/// once per grid: an upper bound whose unused tail is never touched.
struct GridSizes {
    grids: usize,
    grid_vertices: usize,
    faces: usize,
    face_vertices: usize,
}

impl GridSizes {
    fn of(topo: &Topology, loop_scheme: bool, rate: u32) -> GridSizes {
        let n = rate as usize;
        let mut s = GridSizes {
            grids: 0,
            grid_vertices: 0,
            faces: 0,
            face_vertices: 0,
        };
        for f in (0..topo.num_faces()).filter(|&f| !topo.is_hole(f)) {
            let size = topo.face_size(f);
            if loop_scheme {
                s.grids += 1;
                s.grid_vertices += (n + 1) * (n + 2) / 2;
                s.faces += n * n;
                s.face_vertices += 3 * n * n;
            } else {
                // A quad is one grid of n segments; another polygon `size` grids of n / 2.
                let (grids, m) = if size == 4 { (1, n) } else { (size, n / 2) };
                s.grids += grids;
                s.grid_vertices += grids * (m + 1) * (m + 1);
                s.faces += grids * m * m;
                s.face_vertices += 4 * grids * m * m;
            }
        }
        s
    }
}

struct Builder<'a> {
    topo: &'a Topology,
    loop_scheme: bool,
    rate: u32,
    /// Each base vertex's sample, once numbered.
    vertex_index: Vec<u32>,
    /// The first of each base edge's `rate − 1` inner samples, once numbered.
    edge_first: Vec<u32>,
    /// The parameter each sample is evaluated at, by sample index.
    params: Vec<FaceParam>,
    out: Tessellation,
    /// The grid being numbered (scratch, reused face to face).
    grid: Vec<u32>,
}

impl Builder<'_> {
    /// A Catmull-Clark face that is not a quad: its centre and its n spokes (midpoint of a
    /// side to the centre) belong to it alone, then its n quad sub-faces.
    fn polygon(&mut self, f: usize) {
        let n = self.topo.face_size(f);
        let m = self.rate / 2;
        let centre = self.new_sample(FaceParam {
            face: f,
            sub: 0,
            u: 1.0,
            v: 1.0,
        });
        let spokes = self.params.len() as u32;
        for side in 0..n {
            for k in 1..m {
                // On sub-face `side`, the spoke of side `side` is its line u = 1.
                let v = f64::from(k) / f64::from(m);
                self.new_sample(FaceParam {
                    face: f,
                    sub: side,
                    u: 1.0,
                    v,
                });
            }
        }
        for sub in 0..n {
            self.sub_face(f, sub, centre, spokes);
        }
    }

    /// The scratch grid, `len` entries long, taken out of `self` while it is filled.
    fn scratch_grid(&mut self, len: usize) -> Vec<u32> {
        let mut grid = std::mem::take(&mut self.grid);
        grid.clear();
        grid.resize(len, 0);
        grid
    }

    fn new_sample(&mut self, at: FaceParam) -> u32 {
        self.params.push(at);
        self.params.len() as u32 - 1
    }

    /// The sample at step `t` of `rate` along the face's side `side` (from corner `side` to
    /// `side + 1`), numbered with this face's parameter if no face reached it before.
    fn on_side(&mut self, face: usize, side: usize, t: u32) -> u32 {
        let topo = self.topo;
        let fv = topo.face_vertices(face);
        let n = fv.len();
        let (a, b) = (fv[side], fv[(side + 1) % n]);
        let corner = match t {
            0 => Some(a),
            t if t == self.rate => Some(b),
            _ => None,
        };
        if let Some(v) = corner {
            if self.vertex_index[v as usize] == UNSET {
                let at = self.side_param(face, side, t);
                self.vertex_index[v as usize] = self.new_sample(at);
            }
            return self.vertex_index[v as usize];
        }
        let e = topo.face_edges(face)[side] as usize;
        let first_vertex = topo.edge_vertices(e)[0];
        // Counted from the edge's first vertex, so both faces of the edge name it alike.
        let k = if first_vertex == a && a != b {
            t
        } else {
            self.rate - t
        };
        if self.edge_first[e] == UNSET {
            // All of the edge's inner samples at once, each with this face's parameter.
            let first = self.params.len() as u32;
            self.edge_first[e] = first;
            for kk in 1..self.rate {
                let tt = if first_vertex == a && a != b {
                    kk
                } else {
                    self.rate - kk
                };
                let p = self.side_param(face, side, tt);
                self.params.push(p);
            }
        }
        self.edge_first[e] + k - 1
    }

    /// The parameter of step `t` along side `side` of `face`, in the grid's own integer
    /// coordinates (so a sample has the same bits whichever way it is reached).
    fn side_param(&self, face: usize, side: usize, t: u32) -> FaceParam {
        let n = self.rate;
        let size = self.topo.face_size(face);
        let param = |sub: usize, i: u32, j: u32, m: u32| FaceParam {
            face,
            sub,
            u: f64::from(i) / f64::from(m),
            v: f64::from(j) / f64::from(m),
        };
        if self.loop_scheme {
            return match side {
                0 => param(0, t, 0, n),
                1 => param(0, n - t, t, n),
                _ => param(0, 0, n - t, n),
            };
        }
        if size == 4 {
            return match side {
                0 => param(0, t, 0, n),
                1 => param(0, n, t, n),
                2 => param(0, n - t, n, n),
                _ => param(0, 0, n - t, n),
            };
        }
        // The first half of a side is on sub-face `side` (its u axis), the second half on
        // sub-face `side + 1` (its v axis, from the far corner).
        let m = n / 2;
        if t <= m {
            param(side, t, 0, m)
        } else {
            param((side + 1) % size, 0, n - t, m)
        }
    }

    fn push_face(&mut self, vertices: &[u32]) {
        self.out.face_vertices.extend_from_slice(vertices);
        self.out
            .face_offsets
            .push(self.out.face_vertices.len() as u32);
    }

    /// A quad: corners 0, 1, 2, 3 at (0,0), (1,0), (1,1), (0,1).
    fn quad(&mut self, face: usize) {
        let n = self.rate;
        let mut grid = self.scratch_grid(((n + 1) * (n + 1)) as usize);
        for j in 0..=n {
            for i in 0..=n {
                grid[(j * (n + 1) + i) as usize] = match (i, j) {
                    (_, 0) => self.on_side(face, 0, i),
                    (i, _) if i == n => self.on_side(face, 1, j),
                    (_, j) if j == n => self.on_side(face, 2, n - i),
                    (0, _) => self.on_side(face, 3, n - j),
                    _ => self.new_sample(FaceParam {
                        face,
                        sub: 0,
                        u: f64::from(i) / f64::from(n),
                        v: f64::from(j) / f64::from(n),
                    }),
                };
            }
        }
        self.record(face, 0, n, &grid);
        self.grid_quads(&grid, n);
        self.grid = grid;
    }

    fn record(&mut self, face: usize, sub: usize, segments: u32, grid: &[u32]) {
        self.out.grids.push(SampleGrid {
            face,
            sub,
            segments,
            start: self.out.grid_vertices.len() as u32,
        });
        self.out.grid_vertices.extend_from_slice(grid);
    }

    /// Sub-face `sub` of a non-quad: corner `sub` at (0,0), u towards the midpoint of side
    /// `sub`, v towards the midpoint of side `sub − 1`, the face centre at (1,1). `centre`
    /// and `spokes` are the face's own samples (`spokes`: side by side, `m − 1` each, from
    /// the side's midpoint inwards).
    fn sub_face(&mut self, face: usize, sub: usize, centre: u32, spokes: u32) {
        let m = self.rate / 2;
        let sides = self.topo.face_size(face);
        let prev = (sub + sides - 1) % sides;
        let spoke = |side: usize, k: u32| spokes + side as u32 * (m - 1) + k - 1;
        let mut grid = self.scratch_grid(((m + 1) * (m + 1)) as usize);
        for j in 0..=m {
            for i in 0..=m {
                grid[(j * (m + 1) + i) as usize] = match (i, j) {
                    (i, j) if i == m && j == m => centre,
                    (_, 0) => self.on_side(face, sub, i),
                    (0, _) => self.on_side(face, prev, self.rate - j),
                    (i, _) if i == m => spoke(sub, j),
                    (_, j) if j == m => spoke(prev, i),
                    _ => self.new_sample(FaceParam {
                        face,
                        sub,
                        u: f64::from(i) / f64::from(m),
                        v: f64::from(j) / f64::from(m),
                    }),
                };
            }
        }
        self.record(face, sub, m, &grid);
        self.grid_quads(&grid, m);
        self.grid = grid;
    }

    fn grid_quads(&mut self, grid: &[u32], n: u32) {
        let at = |i: u32, j: u32| grid[(j * (n + 1) + i) as usize];
        for j in 0..n {
            for i in 0..n {
                self.push_face(&[at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
    }

    /// A Loop triangle: corners 0, 1, 2 at (0,0), (1,0), (0,1).
    fn triangle(&mut self, face: usize) {
        let n = self.rate;
        let row = |j: u32| (j * (2 * n + 3 - j) / 2) as usize;
        let mut grid = self.scratch_grid(row(n + 1));
        for j in 0..=n {
            for i in 0..=(n - j) {
                grid[row(j) + i as usize] = match (i, j) {
                    (_, 0) => self.on_side(face, 0, i),
                    (i, j) if i + j == n => self.on_side(face, 1, j),
                    (0, _) => self.on_side(face, 2, n - j),
                    _ => self.new_sample(FaceParam {
                        face,
                        sub: 0,
                        u: f64::from(i) / f64::from(n),
                        v: f64::from(j) / f64::from(n),
                    }),
                };
            }
        }
        self.record(face, 0, n, &grid);
        let at = |i: u32, j: u32| grid[row(j) + i as usize];
        for j in 0..n {
            for i in 0..(n - j) {
                self.push_face(&[at(i, j), at(i + 1, j), at(i, j + 1)]);
                if i + j + 1 < n {
                    self.push_face(&[at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
                }
            }
        }
        self.grid = grid;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use subd_schemes::Options;

    #[test]
    fn one_thread_gives_the_same_bits_as_many() {
        let mesh = subd_mesh::primitives::torus_with_hexagons(12, 8, 4, 3.0, 1.0);
        let ev = LimitEvaluator::new(&mesh.topology, &Scheme::CatmullClark, &Options::default())
            .unwrap();
        let pts = ev.prepare(&mesh.positions);
        let many = tessellate(&ev, &pts, 6).unwrap();
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| tessellate(&ev, &pts, 6).unwrap());
        assert_eq!(many.positions, one.positions);
        assert_eq!(many.normals, one.normals);
        assert_eq!(many.face_vertices, one.face_vertices);
        // Every sample of every grid is an output vertex at its own parameter.
        for g in &many.grids {
            let v = many.grid_vertex(g, false, 0, 0) as usize;
            let at = many.params[v];
            let p = ev.evaluate(&pts, at).unwrap().position;
            assert!((p - many.positions[v]).length() < 1e-14);
        }
    }
}
