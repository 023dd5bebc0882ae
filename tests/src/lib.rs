//! Shared helpers for subd's workspace-level integration tests: where the real meshes are and
//! what OpenSubdiv says about them (`../shared/meshes/osd/INDEX.md`).

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use subd_mesh::{CreaseMethod, Topology, TopologyBuilder};
use subd_schemes::{Options, Scheme};

/// Directory of OpenSubdiv's regression shapes (`<repo>/../shared/meshes/osd`), overridable
/// with the `SUBD_MESHES` environment variable (pointing at the `meshes` directory).
pub fn osd_mesh_dir() -> PathBuf {
    let base = match std::env::var_os("SUBD_MESHES") {
        Some(p) => PathBuf::from(p),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/meshes"),
    };
    base.join("osd")
}

/// Every OpenSubdiv shape with at most `max_face_vertices` face-vertices, by name, read
/// as OpenSubdiv reads them (inconsistent orientation accepted).
pub fn small_shapes(max_face_vertices: usize) -> impl Iterator<Item = (String, subd_io::MeshFile)> {
    let opts = subd_io::ReadOptions {
        accept_inconsistent_orientation: true,
        ..Default::default()
    };
    osd_meshes().into_iter().filter_map(move |path| {
        let name = path.file_stem()?.to_string_lossy().to_string();
        let file =
            subd_io::read_mesh(&path, &opts).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        (file.mesh.topology.num_face_vertices() <= max_face_vertices).then_some((name, file))
    })
}

/// Whether every face of `t` has `n` corners.
pub fn all_faces_of_size(t: &Topology, n: usize) -> bool {
    (0..t.num_faces()).all(|f| t.face_size(f) == n)
}

/// Every `.obj` file of the OpenSubdiv shape directory, sorted by name.
pub fn osd_meshes() -> Vec<PathBuf> {
    let dir = osd_mesh_dir();
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "obj"))
        .collect();
    v.sort();
    v
}

/// One row of `INDEX.md`: OpenSubdiv 3.5's own view of a shape's topology.
#[derive(Debug, Clone)]
pub struct IndexRow {
    /// Shape name (file stem).
    pub shape: String,
    /// Scheme prefix: `catmark`, `loop` or `bilinear`.
    pub scheme: String,
    /// Faces.
    pub faces: usize,
    /// Vertices.
    pub vertices: usize,
    /// Edges.
    pub edges: usize,
    /// Face size histogram as `(size, count)`.
    pub face_sizes: Vec<(usize, usize)>,
    /// Boundary edges.
    pub boundary_edges: usize,
    /// Boundary interpolation in effect (`none`, `edge-only`, `edge-and-corner`).
    pub boundary_rule: String,
    /// Tagged semi-sharp creases.
    pub semi_sharp: usize,
    /// Tagged infinitely sharp creases.
    pub inf_sharp: usize,
    /// Corner tags.
    pub corners: usize,
    /// Non-manifold edges.
    pub nonmanifold_edges: usize,
    /// Non-manifold vertices.
    pub nonmanifold_vertices: usize,
    /// Hole tags.
    pub holes: usize,
    /// Extraordinary vertices (OpenSubdiv's `!IsVertexValenceRegular`).
    pub irregular: usize,
}

fn count(cell: &str) -> usize {
    let c = cell.trim();
    if c == "no" {
        0
    } else {
        c.parse().unwrap_or_else(|_| panic!("bad count cell {c:?}"))
    }
}

/// Parses the shape table of `INDEX.md`.
pub fn index_rows() -> Vec<IndexRow> {
    let path = osd_mesh_dir().join("INDEX.md");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let mut rows = Vec::new();
    for line in text.lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        // | shape | scheme | F | V | E | sizes | boundary | rule | creases | corners | nonman | holes | irregular | notes |
        if cells.len() < 15 || cells[1] == "shape" || cells[1].starts_with("---") {
            continue;
        }
        let pair = |c: &str| -> (usize, usize) {
            if c == "no" {
                return (0, 0);
            }
            let mut it = c.split('/').map(|s| {
                s.trim()
                    .trim_end_matches(|ch: char| ch.is_alphabetic())
                    .trim()
            });
            let a = it.next().map(count).unwrap_or(0);
            let b = it.next().map(count).unwrap_or(0);
            (a, b)
        };
        let (semi, inf) = pair(cells[9]);
        let (nme, nmv) = pair(cells[11]);
        rows.push(IndexRow {
            shape: cells[1].to_string(),
            scheme: cells[2].to_string(),
            faces: count(cells[3]),
            vertices: count(cells[4]),
            edges: count(cells[5]),
            face_sizes: cells[6]
                .split_whitespace()
                .map(|t| {
                    let (a, b) = t.split_once(':').expect("size:count");
                    (a.parse().unwrap(), b.parse().unwrap())
                })
                .collect(),
            boundary_edges: count(cells[7]),
            boundary_rule: cells[8].to_string(),
            semi_sharp: semi,
            inf_sharp: inf,
            corners: count(cells[10]),
            nonmanifold_edges: nme,
            nonmanifold_vertices: nmv,
            holes: count(cells[12]),
            irregular: count(cells[13]),
        });
    }
    rows
}

/// A random face list: a closed surface (torus grid, or a cylinder capped by two n-gons) or
/// an open planar grid, whose quads are randomly kept, split into two triangles, or fanned
/// around a new centre vertex (which gives random valences).
#[derive(Debug, Clone)]
pub struct RandomMesh {
    /// Number of vertices.
    pub num_vertices: usize,
    /// Faces.
    pub faces: Vec<Vec<u32>>,
    /// Planar positions for the open grid (None for closed surfaces).
    pub planar: Option<Vec<[f64; 2]>>,
    /// Genus of a closed surface, `None` for the open grid.
    pub genus: Option<i64>,
}

/// Builds the random mesh of `kind` (0 torus, 1 capped cylinder, 2 planar grid).
pub fn random_mesh(kind: u8, m: u32, n: u32, choices: &[u8], jitter: &[(f64, f64)]) -> RandomMesh {
    let mut faces: Vec<Vec<u32>> = Vec::new();
    let mut nv;
    let mut planar = None;
    let quads: Vec<[u32; 4]>;
    let genus;
    match kind {
        0 => {
            // Torus: m x n grid, wrapping both ways.
            let id = |i: u32, j: u32| (i % m) * n + (j % n);
            quads = (0..m)
                .flat_map(|i| {
                    (0..n).map(move |j| [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
                })
                .collect();
            nv = (m * n) as usize;
            genus = Some(1);
        }
        1 => {
            // Cylinder of m rings of n vertices, capped by two n-gons: a sphere.
            let id = |i: u32, j: u32| i * n + (j % n);
            quads = (0..m - 1)
                .flat_map(|i| {
                    (0..n).map(move |j| [id(i, j), id(i, j + 1), id(i + 1, j + 1), id(i + 1, j)])
                })
                .collect();
            faces.push((0..n).rev().map(|j| id(0, j)).collect());
            faces.push((0..n).map(|j| id(m - 1, j)).collect());
            nv = (m * n) as usize;
            genus = Some(0);
        }
        _ => {
            // Open planar (m+1) x (n+1) grid, counter-clockwise in the xy plane, jittered.
            let id = |i: u32, j: u32| i * (n + 1) + j;
            quads = (0..m)
                .flat_map(|i| {
                    (0..n).map(move |j| [id(i, j), id(i, j + 1), id(i + 1, j + 1), id(i + 1, j)])
                })
                .collect();
            let mut pos = Vec::new();
            for i in 0..=m {
                for j in 0..=n {
                    let (dx, dy) = jitter[(i * (n + 1) + j) as usize % jitter.len()];
                    pos.push([j as f64 + 0.15 * dx, i as f64 + 0.15 * dy]);
                }
            }
            planar = Some(pos);
            nv = ((m + 1) * (n + 1)) as usize;
            genus = None;
        }
    }
    for (k, q) in quads.iter().enumerate() {
        match choices[k % choices.len()] % 4 {
            0 | 1 => faces.push(q.to_vec()),
            2 => {
                faces.push(vec![q[0], q[1], q[2]]);
                faces.push(vec![q[0], q[2], q[3]]);
            }
            _ => {
                let c = nv as u32;
                nv += 1;
                if let Some(pos) = planar.as_mut() {
                    let p = q.iter().fold([0.0, 0.0], |a, &v| {
                        [
                            a[0] + pos[v as usize][0] / 4.0,
                            a[1] + pos[v as usize][1] / 4.0,
                        ]
                    });
                    pos.push(p);
                }
                for i in 0..4 {
                    faces.push(vec![q[i], q[(i + 1) % 4], c]);
                }
            }
        }
    }
    RandomMesh {
        num_vertices: nv,
        faces,
        planar,
        genus,
    }
}

/// The topology of a random mesh with every face fanned into triangles from its first
/// corner.
pub fn triangulated(m: &RandomMesh) -> Topology {
    let faces: Vec<Vec<u32>> = m
        .faces
        .iter()
        .flat_map(|f| (1..f.len() - 1).map(move |i| vec![f[0], f[i], f[i + 1]]))
        .collect();
    build(m.num_vertices, &faces)
}

/// Builds the topology of a face list.
pub fn build(nv: usize, faces: &[Vec<u32>]) -> Topology {
    let sizes: Vec<u32> = faces.iter().map(|f| f.len() as u32).collect();
    let idx: Vec<u32> = faces.iter().flatten().copied().collect();
    TopologyBuilder::new(nv)
        .build(&sizes, &idx)
        .expect("valid mesh")
}

/// Strategy for [`RandomMesh`].
pub fn mesh_strategy() -> impl Strategy<Value = RandomMesh> {
    (
        0u8..3,
        3u32..9,
        3u32..9,
        prop::collection::vec(any::<u8>(), 1..64),
        prop::collection::vec((-1.0f64..1.0, -1.0f64..1.0), 1..32),
    )
        .prop_map(|(k, m, n, c, j)| random_mesh(k, m, n, &c, &j))
}

/// A closed pentagonal prism (two pentagons, five quads) with slightly irregular positions:
/// after one Catmull-Clark step it has extraordinary vertices of valence 3 and 5.
pub fn pentagonal_prism() -> (Topology, Vec<subd_mesh::DVec3>) {
    let mut faces: Vec<Vec<u32>> = vec![(0..5).rev().collect(), (5..10).collect()];
    for i in 0..5u32 {
        let j = (i + 1) % 5;
        faces.push(vec![i, j, 5 + j, 5 + i]);
    }
    let points = (0..10)
        .map(|v| {
            let a = std::f64::consts::TAU * (v % 5) as f64 / 5.0 + 0.1 * v as f64;
            subd_mesh::DVec3::new(
                a.cos() * (1.0 + 0.1 * v as f64),
                a.sin(),
                if v < 5 { -0.6 } else { 0.7 },
            )
        })
        .collect();
    (build(10, &faces), points)
}

/// A refinement case for property tests: a random mesh with positions, crease and corner
/// tags, a scheme and a crease method.
#[derive(Debug, Clone)]
pub struct TaggedCase {
    /// The mesh (fan-triangulated for Loop).
    pub mesh: RandomMesh,
    /// Positions in [-1, 1]³.
    pub positions: Vec<subd_mesh::DVec3>,
    /// Crease tags: edge (modulo the edge count) and sharpness.
    pub creases: Vec<(usize, f32)>,
    /// Corner tags: vertex (modulo the vertex count) and sharpness.
    pub corners: Vec<(usize, f32)>,
    /// Scheme.
    pub scheme: Scheme,
    /// Chaikin crease method instead of uniform.
    pub chaikin: bool,
}

/// Sharpness values the cases draw from: semi-sharp, integer and infinite.
const SHARPNESS: [f32; 6] = [0.3, 1.0, 1.7, 2.5, 4.2, 10.0];

impl TaggedCase {
    /// The topology of `faces` (the case's faces, or a relabelling of them) with the case's
    /// tags.
    pub fn topology(&self, faces: &[Vec<u32>]) -> Topology {
        let mut t = build(self.mesh.num_vertices, faces);
        let (ne, nv) = (t.num_edges(), t.num_vertices());
        for &(e, s) in &self.creases {
            t.set_edge_sharpness(e % ne, s);
        }
        for &(v, s) in &self.corners {
            t.set_vertex_sharpness(v % nv, s);
        }
        t
    }

    /// The case's options.
    pub fn options(&self) -> Options {
        Options {
            crease_method: if self.chaikin {
                CreaseMethod::Chaikin
            } else {
                CreaseMethod::Uniform
            },
            ..Options::default()
        }
    }
}

/// Strategy for [`TaggedCase`] with one of `schemes`.
pub fn tagged_case_strategy(schemes: &'static [Scheme]) -> impl Strategy<Value = TaggedCase> {
    (
        mesh_strategy(),
        0..schemes.len(),
        any::<bool>(),
        prop::collection::vec((any::<u16>(), 0usize..6), 0..12),
        prop::collection::vec((any::<u16>(), 0usize..6), 0..4),
        any::<u64>(),
    )
        .prop_map(move |(mut mesh, s, chaikin, creases, corners, seed)| {
            let scheme = schemes[s].clone();
            if scheme == Scheme::Loop {
                // Fan-triangulate every face for Loop.
                mesh.faces = mesh
                    .faces
                    .iter()
                    .flat_map(|f| (1..f.len() - 1).map(move |i| vec![f[0], f[i], f[i + 1]]))
                    .collect();
            }
            let mut state = seed | 1;
            let mut rnd = || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 11) as f64 / (1u64 << 53) as f64
            };
            let positions = (0..mesh.num_vertices)
                .map(|_| subd_mesh::DVec3::new(rnd(), rnd(), rnd()) * 2.0 - subd_mesh::DVec3::ONE)
                .collect();
            TaggedCase {
                creases: creases
                    .into_iter()
                    .map(|(e, s)| (e as usize, SHARPNESS[s]))
                    .collect(),
                corners: corners
                    .into_iter()
                    .map(|(v, s)| (v as usize, SHARPNESS[s]))
                    .collect(),
                mesh,
                positions,
                scheme,
                chaikin,
            }
        })
}

/// An OpenSubdiv shape with a surface scheme (`catmark_*`, `loop_*`), read with its options.
#[derive(Debug, Clone)]
pub struct SurfaceShape {
    /// File stem.
    pub name: String,
    /// Catmull-Clark or Loop, from the name.
    pub scheme: Scheme,
    /// The options its tags ask for.
    pub options: Options,
    /// Topology and positions.
    pub mesh: subd_mesh::Mesh,
}

/// Every Catmull-Clark and Loop shape of the OpenSubdiv directory that reads (windings that
/// disagree accepted as non-manifold edges, as OpenSubdiv accepts them), in name order.
pub fn surface_shapes() -> Vec<SurfaceShape> {
    let opts = subd_io::ReadOptions {
        accept_inconsistent_orientation: true,
        ..Default::default()
    };
    osd_meshes()
        .into_iter()
        .filter_map(|path| {
            let name = path.file_stem()?.to_string_lossy().to_string();
            let scheme = if name.starts_with("loop_") {
                Scheme::Loop
            } else if name.starts_with("catmark_") {
                Scheme::CatmullClark
            } else {
                return None;
            };
            let file = subd_io::read_mesh(&path, &opts).ok()?;
            Some(SurfaceShape {
                name,
                scheme,
                options: Options::from_hints(&file.mesh.hints),
                mesh: file.mesh,
            })
        })
        .collect()
}

/// A random relabelling of a case's vertices (a shuffle seeded by `seed`): the permutation
/// (old vertex → new), the case's topology, the relabelled topology with the same tags, and
/// the relabelled positions.
pub fn relabelled(
    c: &TaggedCase,
    seed: u64,
) -> (Vec<u32>, Topology, Topology, Vec<subd_mesh::DVec3>) {
    let nv = c.mesh.num_vertices;
    let mut perm: Vec<u32> = (0..nv as u32).collect();
    let mut state = seed | 1;
    for i in (1..nv).rev() {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        perm.swap(i, (state % (i as u64 + 1)) as usize);
    }
    let t = c.topology(&c.mesh.faces);
    let faces: Vec<Vec<u32>> = c
        .mesh
        .faces
        .iter()
        .map(|f| f.iter().map(|&v| perm[v as usize]).collect())
        .collect();
    let mut u = build(nv, &faces);
    // Carry the tags over through the permutation.
    for e in 0..t.num_edges() {
        let [x, y] = t.edge_vertices(e);
        let g = u
            .find_edge(perm[x as usize], perm[y as usize])
            .expect("a relabelled edge") as usize;
        u.set_edge_sharpness(g, t.edge_sharpness(e));
    }
    let mut pos = vec![subd_mesh::DVec3::ZERO; nv];
    for (v, &w) in perm.iter().enumerate() {
        u.set_vertex_sharpness(w as usize, t.vertex_sharpness(v));
        pos[w as usize] = c.positions[v];
    }
    (perm, t, u, pos)
}

/// A random torus mesh (quads, triangles and fans) of `m` × `n` cells with every seventh edge
/// a 1.7 crease and wavy positions: a mesh large enough for the parallel loops to split.
pub fn creased_torus(m: u32, n: u32) -> (Topology, Vec<subd_mesh::DVec3>) {
    let mesh = random_mesh(0, m, n, &[0, 1, 2, 3, 0, 2, 1], &[(0.0, 0.0)]);
    let mut t = build(mesh.num_vertices, &mesh.faces);
    for e in (0..t.num_edges()).step_by(7) {
        t.set_edge_sharpness(e, 1.7);
    }
    let positions = (0..mesh.num_vertices)
        .map(|i| {
            subd_mesh::DVec3::new(
                (i as f64 * 0.37).sin(),
                (i as f64 * 0.11).cos(),
                (i as f64 * 0.05).sin(),
            )
        })
        .collect();
    (t, positions)
}

/// The workspace README's "Use it as a library" examples, run as doctests here: this crate
/// depends on every library crate they use and, unlike the published crates, sits beside
/// the `examples/` meshes they read.
#[cfg(doctest)]
#[doc = include_str!("../../README.md")]
struct WorkspaceReadmeDoctests;
