//! The parallel build against the serial reference, on random meshes with every oddity the
//! rules handle, in thread pools of 1, 2 and 4 threads.

use super::reference::build_serial;
use super::*;

/// A deterministic pseudo-random sequence (no dependency on a generator crate).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> u32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 33) as u32
    }

    fn below(&mut self, n: u32) -> u32 {
        self.next() % n.max(1)
    }

    /// True with probability `p` percent.
    fn percent(&mut self, p: u32) -> bool {
        self.below(100) < p
    }
}

/// A mesh to build: vertex count, face sizes, face-vertices.
#[derive(Debug, Clone)]
struct Input {
    nv: usize,
    sizes: Vec<u32>,
    vertices: Vec<u32>,
}

impl Input {
    fn push(&mut self, face: &[u32]) {
        self.sizes.push(face.len() as u32);
        self.vertices.extend_from_slice(face);
    }
}

/// An `n` x `m` grid of quads, some split into triangles or merged with their right
/// neighbour into a hexagon, some flipped; then odd faces added from a few chosen vertices
/// (repeated edges, degenerate edges, repeated vertices, copies of faces, one large face),
/// and the vertices renumbered into a larger index space with unused indices.
fn random_mesh(rng: &mut Lcg, n: u32, m: u32, oddity: u32) -> Input {
    let id = |i: u32, j: u32| i * (m + 1) + j;
    let mut mesh = Input {
        nv: ((n + 1) * (m + 1)) as usize,
        sizes: Vec::new(),
        vertices: Vec::new(),
    };
    for i in 0..n {
        let mut j = 0;
        while j < m {
            let q = [id(i, j), id(i, j + 1), id(i + 1, j + 1), id(i + 1, j)];
            let mut faces: Vec<Vec<u32>> = match rng.below(10) {
                0 => vec![vec![q[0], q[1], q[2]], vec![q[0], q[2], q[3]]],
                1 if j + 1 < m => {
                    j += 1;
                    let (r1, r2) = (id(i, j + 1), id(i + 1, j + 1));
                    vec![vec![q[0], q[1], r1, r2, q[2], q[3]]]
                }
                _ => vec![q.to_vec()],
            };
            for face in &mut faces {
                if rng.percent(oddity) {
                    face.reverse();
                }
                mesh.push(face);
            }
            j += 1;
        }
    }
    add_odd_faces(rng, &mut mesh, oddity);
    renumber_with_gaps(rng, &mut mesh);
    mesh
}

/// Faces with non-manifold features, inserted among the others.
fn add_odd_faces(rng: &mut Lcg, mesh: &mut Input, oddity: u32) {
    let count = (mesh.sizes.len() as u32 * oddity / 100).max(1);
    let nv = mesh.nv as u32;
    let mut faces: Vec<Vec<u32>> = (0..mesh.sizes.len())
        .map(|f| {
            let start: u32 = mesh.sizes[..f].iter().sum();
            mesh.vertices[start as usize..(start + mesh.sizes[f]) as usize].to_vec()
        })
        .collect();
    for _ in 0..count {
        let face: Vec<u32> = match rng.below(6) {
            // A copy of a face, maybe reversed: third faces and orientation conflicts.
            0 | 1 => {
                let mut f = faces[rng.below(faces.len() as u32) as usize].clone();
                if rng.percent(50) {
                    f.reverse();
                }
                f
            }
            // A face over a few vertices: repeated vertices, repeated and degenerate edges.
            2 | 3 => {
                let pool: Vec<u32> = (0..3).map(|_| rng.below(nv)).collect();
                (0..3 + rng.below(5))
                    .map(|_| pool[rng.below(3) as usize])
                    .collect()
            }
            // The same edge twice in one face, in both directions.
            4 => {
                let (a, b, c) = (rng.below(nv), rng.below(nv), rng.below(nv));
                vec![a, b, a, c, b, a]
            }
            // A large face (the sorted repeat check), with some repeats.
            _ => (0..33 + rng.below(10)).map(|_| rng.below(nv)).collect(),
        };
        let at = rng.below(faces.len() as u32 + 1) as usize;
        faces.insert(at, face);
    }
    mesh.sizes.clear();
    mesh.vertices.clear();
    for f in &faces {
        mesh.push(f);
    }
}

/// Renumbers the vertices by a random permutation into up to twice as many indices.
fn renumber_with_gaps(rng: &mut Lcg, mesh: &mut Input) {
    let total = mesh.nv + rng.below(mesh.nv as u32 + 1) as usize;
    let mut ids: Vec<u32> = (0..total as u32).collect();
    for i in (1..total).rev() {
        ids.swap(i, rng.below(i as u32 + 1) as usize);
    }
    for v in &mut mesh.vertices {
        *v = ids[*v as usize];
    }
    mesh.nv = total;
}

type Built = Result<(Topology, Vec<BuildWarning>), TopologyError>;

/// The first public relation in which two builds differ, named.
fn difference(a: &Topology, b: &Topology) -> Option<String> {
    let per = |name: &str, n: usize, f: &dyn Fn(&Topology, usize) -> String| {
        (0..n)
            .find(|&i| f(a, i) != f(b, i))
            .map(|i| format!("{name} {i}: {} vs {}", f(a, i), f(b, i)))
    };
    if (a.num_vertices(), a.num_edges(), a.num_faces())
        != (b.num_vertices(), b.num_edges(), b.num_faces())
    {
        return Some("counts".into());
    }
    per("face", a.num_faces(), &|t, f| {
        format!("{:?} {:?}", t.face_vertices(f), t.face_edges(f))
    })
    .or_else(|| {
        per("edge", a.num_edges(), &|t, e| {
            let flags = (t.is_boundary_edge(e), t.is_non_manifold_edge(e));
            let faces = (t.edge_faces(e), t.edge_face_local_indices(e));
            format!(
                "{:?} {faces:?} {flags:?} {}",
                t.edge_vertices(e),
                t.is_degenerate_edge(e)
            )
        })
    })
    .or_else(|| {
        per("vertex", a.num_vertices(), &|t, v| {
            let flags = (
                t.is_boundary_vertex(v),
                t.is_non_manifold_vertex(v),
                t.is_isolated_vertex(v),
            );
            let faces = (t.vertex_faces(v), t.vertex_face_local_indices(v));
            format!("{faces:?} {:?} {flags:?}", t.vertex_edges(v))
        })
    })
    .or_else(|| (a != b).then(|| "fields".into()))
}

/// Builds `input` serially and in pools of 1, 2 and 4 threads and checks all agree.
fn check_same(input: &Input, accept: bool, what: &str) -> Built {
    let want = build_serial(input.nv, accept, &input.sizes, &input.vertices);
    for threads in [1, 2, 4] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let got = pool.install(|| {
            TopologyBuilder::new(input.nv)
                .accept_inconsistent_orientation(accept)
                .build_with_warnings(&input.sizes, &input.vertices)
        });
        match (&got, &want) {
            (Ok((g, gw)), Ok((w, ww))) => {
                assert_eq!(difference(g, w), None, "{what}, {threads} threads");
                assert_eq!(gw, ww, "{what}, {threads} threads: warnings");
            }
            _ => assert_eq!(got, want, "{what}, {threads} threads"),
        }
        let edges = pool.install(|| {
            TopologyBuilder::new(input.nv)
                .accept_inconsistent_orientation(accept)
                .edges(&input.sizes, &input.vertices)
        });
        check_edges(&edges, &want, &format!("{what}, {threads} threads: edges"));
    }
    want
}

/// The edge census against the serial build's edges and flags, or its error.
fn check_edges(got: &Result<FaceEdges, TopologyError>, want: &Built, what: &str) {
    match (got, want) {
        (Ok(edges), Ok((topo, _))) => {
            let face_edges: Vec<u32> = (0..topo.num_faces())
                .flat_map(|f| topo.face_edges(f).iter().copied())
                .collect();
            assert_eq!(edges.face_edges(), face_edges, "{what}");
            assert_eq!(edges.num_edges(), topo.num_edges(), "{what}");
            for e in 0..topo.num_edges() {
                assert_eq!(
                    (edges.is_boundary_edge(e), edges.is_non_manifold_edge(e)),
                    (topo.is_boundary_edge(e), topo.is_non_manifold_edge(e)),
                    "{what}: edge {e}"
                );
            }
        }
        (Err(g), Err(w)) => assert_eq!(g, w, "{what}"),
        _ => panic!("{what}: one refused, the other not"),
    }
}

#[test]
fn parallel_build_matches_serial_on_random_meshes() {
    let mut rng = Lcg(5);
    let mut outcomes = [0usize; 3];
    for case in 0..300u32 {
        let (n, m) = (1 + rng.below(12), 1 + rng.below(12));
        let oddity = [0, 2, 10, 40][case as usize % 4];
        let input = random_mesh(&mut rng, n, m, oddity);
        for accept in [false, true] {
            let what = format!("case {case} ({n} x {m}, oddity {oddity}, accept {accept})");
            let built = check_same(&input, accept, &what);
            outcomes[match built {
                Ok((_, w)) if w.is_empty() => 0,
                Ok(_) => 1,
                Err(_) => 2,
            }] += 1;
        }
    }
    // Clean builds, builds with warnings and refused builds all occur.
    assert!(outcomes.iter().all(|&n| n > 20), "{outcomes:?}");
}

#[test]
fn parallel_build_matches_serial_on_large_meshes() {
    // Over a sort chunk (2^15 half-edges) and many blocks, so work is really split.
    let mut rng = Lcg(9);
    for (case, oddity) in [0u32, 1, 5].into_iter().enumerate() {
        let input = random_mesh(&mut rng, 120, 110, oddity);
        for accept in [false, true] {
            let what = format!("large case {case}, accept {accept}");
            let built = check_same(&input, accept, &what);
            // Only refused orientation conflicts fail here.
            assert!(built.is_ok() || !accept, "{what}");
        }
    }
}

#[test]
fn first_error_in_face_order_is_reported() {
    let mut rng = Lcg(3);
    for case in 0..50 {
        let mut input = random_mesh(&mut rng, 70, 70, 1);
        // Several out-of-range indices, the earliest must be reported.
        for _ in 0..1 + case % 3 {
            let h = rng.below(input.vertices.len() as u32) as usize;
            input.vertices[h] = input.nv as u32 + rng.below(3);
        }
        assert!(check_same(&input, case % 2 == 0, &format!("range case {case}")).is_err());
    }
}

#[test]
fn numbered_edges_assemble_as_the_serial_build() {
    let mut rng = Lcg(17);
    for case in 0..100 {
        let (n, m) = (1 + rng.below(15), 1 + rng.below(15));
        let input = random_mesh(&mut rng, n, m, 10);
        let Ok((want, _)) = build_serial(input.nv, true, &input.sizes, &input.vertices) else {
            panic!("case {case}: accepted builds do not fail");
        };
        let non_manifold: Vec<u32> = (0..want.num_edges() as u32)
            .filter(|&e| want.is_non_manifold_edge(e as usize))
            .collect();
        let got = Topology::from_numbered_edges(
            input.nv,
            want.face_offsets.clone(),
            want.face_vertices.clone(),
            want.face_edges.clone(),
            want.edge_vertices.clone(),
            &non_manifold,
        )
        .unwrap();
        assert_eq!(difference(&got, &want), None, "case {case}");
    }
}

#[test]
fn repeated_corners_small_and_large_faces() {
    assert_eq!(repeated_corners(&[1, 2, 1, 3, 2, 1]), [2, 4, 5]);
    let mut large: Vec<u32> = (0..40).collect();
    large[35] = 3;
    large[20] = 3;
    large[39] = 38;
    assert_eq!(repeated_corners(&large), [20, 35, 39]);
}

#[test]
fn malformed_face_lists_are_refused_alike() {
    let quad = |sizes: Vec<u32>, vertices: Vec<u32>| Input {
        nv: 4,
        sizes,
        vertices,
    };
    let cases = [
        (
            "a face of two vertices",
            quad(vec![4, 2], vec![0, 1, 2, 3, 0, 1]),
        ),
        ("a face of none", quad(vec![0, 4], vec![0, 1, 2, 3])),
        (
            "sizes past the list",
            quad(vec![4, 4], vec![0, 1, 2, 3, 0, 1]),
        ),
        ("indices left over", quad(vec![4], vec![0, 1, 2, 3, 0])),
        (
            "a face over the size limit",
            quad(vec![MAX_FACE_SIZE as u32 + 1], vec![0; MAX_FACE_SIZE + 1]),
        ),
    ];
    for (what, input) in cases {
        assert!(check_same(&input, false, what).is_err(), "{what}");
    }
}
