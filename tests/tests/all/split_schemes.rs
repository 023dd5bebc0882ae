//! Doo-Sabin, √3, Butterfly and Modified Butterfly (`subd_schemes::split_schemes`) and their
//! limits (`subd_limit::split_limit`): invariants on random meshes, closed forms (polynomial
//! reproduction, the boundary curves' univariate schemes, counts), errors.

use proptest::prelude::*;
use subd_limit::split_limit::split_limit_stencils;
use subd_mesh::{DVec3, Topology, tags};
use subd_schemes::StencilTable;
use subd_schemes::{Options, RefineError, Refinement, Scheme};
use subd_tests::{RandomMesh, build, mesh_strategy, triangulated};

const SCHEMES: [Scheme; 4] = [
    Scheme::DooSabin,
    Scheme::Sqrt3,
    Scheme::BUTTERFLY,
    Scheme::ModifiedButterfly,
];

/// Positions for a random mesh: its planar ones lifted by a wave, or points on a torus-ish
/// surface from the vertex index.
fn positions(m: &RandomMesh) -> Vec<DVec3> {
    match &m.planar {
        Some(p) => p
            .iter()
            .map(|&[x, y]| DVec3::new(x, y, 0.3 * (x * 1.3).sin() * (y * 0.7).cos()))
            .collect(),
        None => (0..m.num_vertices)
            .map(|i| {
                let t = i as f64 * 0.61;
                DVec3::new(
                    t.cos() * (2.0 + (t * 1.7).cos()),
                    t.sin() * 2.1,
                    (t * 1.7).sin(),
                )
            })
            .collect(),
    }
}

/// Marks every `k`-th interior edge an infinitely sharp crease.
fn with_creases(mut t: Topology, k: usize) -> Topology {
    for e in (0..t.num_edges()).step_by(k) {
        if !t.is_boundary_edge(e) {
            t.set_edge_sharpness(e, tags::SHARPNESS_INFINITE);
        }
    }
    t
}

fn rows_sum_to_one(t: &StencilTable) -> Result<(), String> {
    for r in 0..t.num_rows() {
        let s: f64 = t.row(r).1.iter().sum();
        if (s - 1.0).abs() > 1e-12 {
            return Err(format!("row {r} sums to {s}"));
        }
    }
    Ok(())
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool")
        .install(f)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Stencil rows sum to 1 (affine invariance), composed tables agree with level-by-level
    /// application, and one thread gives the same tables and points as four, bit for bit.
    #[test]
    fn invariants_on_random_meshes(m in mesh_strategy(), crease_every in 3usize..9) {
        let p = positions(&m);
        for scheme in SCHEMES {
            let t = if scheme == Scheme::DooSabin {
                build(m.num_vertices, &m.faces)
            } else {
                with_creases(triangulated(&m), crease_every)
            };
            let one = in_pool(1, || Refinement::new(&t, scheme.clone(), &Options::default(), 3).unwrap());
            let four = in_pool(4, || Refinement::new(&t, scheme.clone(), &Options::default(), 3).unwrap());
            for l in 1..=3 {
                rows_sum_to_one(one.stencils(l)).map_err(|e| TestCaseError::fail(format!("{scheme:?} level {l}: {e}")))?;
                prop_assert_eq!(one.stencils(l), four.stencils(l));
                prop_assert_eq!(one.topology(l), four.topology(l));
            }
            let levels = one.refine_points(&p);
            let composed = in_pool(4, || one.composed(3).apply_points(&p));
            for (a, b) in levels[3].iter().zip(&composed) {
                prop_assert!((*a - *b).length() < 1e-12, "{scheme:?}: composed differs");
            }
            if scheme.is_interpolating() {
                for level in &levels[1..] {
                    prop_assert_eq!(&level[..p.len()], &p[..]);
                }
            }
        }
    }
}

/// A regular triangulated grid in the plane: (k+1)² vertices, lattice spacing 1, triangles
/// split along the same diagonal (every interior vertex has valence 6).
fn regular_grid(k: u32) -> (Topology, Vec<DVec3>) {
    let id = |i: u32, j: u32| i * (k + 1) + j;
    let mut faces = Vec::new();
    for i in 0..k {
        for j in 0..k {
            faces.push(vec![id(i, j), id(i, j + 1), id(i + 1, j + 1)]);
            faces.push(vec![id(i, j), id(i + 1, j + 1), id(i + 1, j)]);
        }
    }
    let points = (0..=k)
        .flat_map(|i| (0..=k).map(move |j| DVec3::new(f64::from(j), f64::from(i), 0.0)))
        .collect();
    (build(((k + 1) * (k + 1)) as usize, &faces), points)
}

/// The butterfly with `w = 1/16` reproduces cubic polynomials on a regular grid (Dyn, Levin
/// and Gregory): away from the boundary, every new point's height is the cubic at its
/// position. So does the modified butterfly, which is the same rule there.
#[test]
fn butterflies_reproduce_cubics_on_a_regular_grid() {
    let (t, mut p) = regular_grid(10);
    let cubic = |x: f64, y: f64| {
        0.3 * x * x * x - 0.2 * x * x * y + 0.1 * x * y * y - 0.05 * y * y * y + x * y - 2.0 * y
            + 1.0
    };
    for q in &mut p {
        q.z = cubic(q.x, q.y);
    }
    for scheme in [Scheme::BUTTERFLY, Scheme::ModifiedButterfly] {
        let r = Refinement::new(&t, scheme.clone(), &Options::default(), 1).unwrap();
        let out = r.refine_points(&p).pop().unwrap();
        let mut checked = 0;
        for q in &out {
            // Stencils reach two lattice steps: stay three away from the boundary.
            if q.x >= 3.0 && q.x <= 7.0 && q.y >= 3.0 && q.y <= 7.0 {
                assert!((q.z - cubic(q.x, q.y)).abs() < 1e-12, "{scheme:?} at {q}");
                checked += 1;
            }
        }
        assert!(checked > 50);
    }
    // Tension 0 is linear interpolation: every new point is its edge's midpoint.
    let r = Refinement::new(
        &t,
        Scheme::Butterfly { tension: 0.0 },
        &Options::default(),
        1,
    )
    .unwrap();
    let out = r.refine_points(&p).pop().unwrap();
    for e in 0..t.num_edges() {
        let [a, b] = t.edge_vertices(e);
        let mid = (p[a as usize] + p[b as usize]) / 2.0;
        assert!((out[p.len() + e] - mid).length() < 1e-14);
    }
}

/// The boundary loop of `t` as vertices in order.
fn boundary_loop(t: &Topology) -> Vec<u32> {
    let start = (0..t.num_edges()).find(|&e| t.is_boundary_edge(e)).unwrap();
    let [a, mut b] = t.edge_vertices(start);
    let mut order = vec![a];
    let mut prev = start;
    while b != a {
        order.push(b);
        let e = t
            .vertex_edges(b as usize)
            .iter()
            .copied()
            .find(|&e| e as usize != prev && t.is_boundary_edge(e as usize))
            .unwrap() as usize;
        prev = e;
        b = t.edge_other_vertex(e, b);
    }
    order
}

/// √3's boundary after two steps is the base boundary polygon refined once by the ternary
/// cubic B-spline mask (1, 4, 10, 16, 19, 16, 10, 4, 1)/27 (Kobbelt 2000, §4); Doo-Sabin's
/// boundary after one step is Chaikin's corner cutting of it.
#[test]
fn boundary_curves_follow_their_univariate_schemes() {
    let (t, mut p) = regular_grid(5);
    for (i, q) in p.iter_mut().enumerate() {
        q.z = (i as f64 * 0.37).sin();
        q.x += 0.1 * (i as f64 * 1.1).cos();
    }
    let base = boundary_loop(&t);
    let n = base.len();
    let at = |i: isize| p[base[i.rem_euclid(n as isize) as usize] as usize];
    // Ternary cubic B-spline of the closed boundary polygon.
    let mut ternary = Vec::new();
    for i in 0..n as isize {
        ternary.push((at(i - 1) * 4.0 + at(i) * 19.0 + at(i + 1) * 4.0) / 27.0);
        ternary.push((at(i - 1) + at(i) * 16.0 + at(i + 1) * 10.0) / 27.0);
        ternary.push((at(i) * 10.0 + at(i + 1) * 16.0 + at(i + 2)) / 27.0);
    }
    let r = Refinement::new(&t, Scheme::Sqrt3, &Options::default(), 2).unwrap();
    let out = r.refine_points(&p).pop().unwrap();
    let mut ours = boundary_loop(r.topology(2));
    assert_eq!(ours.len(), 3 * n);
    // Base vertices keep their numbers: start the loop where the base loop starts.
    let start = ours.iter().position(|&v| v == base[0]).unwrap();
    ours.rotate_left(start);
    let ours: Vec<DVec3> = ours.iter().map(|&v| out[v as usize]).collect();
    // Same loop, maybe walked the other way.
    let forward = (0..3 * n).all(|i| (ours[i] - ternary[i]).length() < 1e-12);
    let backward = (0..3 * n).all(|i| (ours[(3 * n - i) % (3 * n)] - ternary[i]).length() < 1e-12);
    assert!(
        forward || backward,
        "√3 boundary is not the ternary cubic B-spline"
    );

    let (tq, pq) = {
        let m = subd_tests::random_mesh(2, 4, 4, &[0], &[(0.3, -0.2), (0.1, 0.4)]);
        (build(m.num_vertices, &m.faces), positions(&m))
    };
    let base = boundary_loop(&tq);
    let n = base.len();
    let r = Refinement::new(&tq, Scheme::DooSabin, &Options::default(), 1).unwrap();
    let out = r.refine_points(&pq).pop().unwrap();
    let ours: Vec<DVec3> = boundary_loop(r.topology(1))
        .iter()
        .map(|&v| out[v as usize])
        .collect();
    assert_eq!(ours.len(), 2 * n);
    for i in 0..n {
        let (a, b) = (pq[base[i] as usize], pq[base[(i + 1) % n] as usize]);
        for c in [a * 0.75 + b * 0.25, a * 0.25 + b * 0.75] {
            assert!(
                ours.iter().any(|q| (*q - c).length() < 1e-12),
                "Chaikin point {c} missing"
            );
        }
    }
}

/// Vertex and face counts per step on closed meshes: √3 V + F and 3F; the butterflies V + E
/// and 4F; Doo-Sabin Σ face sizes and F + E + V.
#[test]
fn counts_per_step() {
    let m = subd_tests::random_mesh(0, 5, 6, &[0, 2, 3, 1, 2], &[(0.0, 0.0)]);
    let quads = build(m.num_vertices, &m.faces);
    let tris = triangulated(&m);
    let ds = Refinement::new(&quads, Scheme::DooSabin, &Options::default(), 1).unwrap();
    assert_eq!(ds.topology(1).num_vertices(), quads.num_face_vertices());
    assert_eq!(
        ds.topology(1).num_faces(),
        quads.num_faces() + quads.num_edges() + quads.num_vertices()
    );
    let s3 = Refinement::new(&tris, Scheme::Sqrt3, &Options::default(), 1).unwrap();
    assert_eq!(
        s3.topology(1).num_vertices(),
        tris.num_vertices() + tris.num_faces()
    );
    assert_eq!(s3.topology(1).num_faces(), 3 * tris.num_faces());
    for scheme in [Scheme::BUTTERFLY, Scheme::ModifiedButterfly] {
        let b = Refinement::new(&tris, scheme.clone(), &Options::default(), 1).unwrap();
        assert_eq!(
            b.topology(1).num_vertices(),
            tris.num_vertices() + tris.num_edges()
        );
        assert_eq!(b.topology(1).num_faces(), 4 * tris.num_faces());
    }
}

/// Infinitely sharp creases stay creases: their children are tagged, and with the
/// butterflies the points on a crease follow the 4-point rule of the crease curve alone.
#[test]
fn creases_are_carried_and_use_the_curve_rule() {
    let (t, mut p) = regular_grid(6);
    for (i, q) in p.iter_mut().enumerate() {
        q.z = (i as f64 * 0.7).sin();
    }
    // The middle row of lattice edges: y = 3.
    let mut t = t;
    let row: Vec<u32> = (0..=6).map(|j| 3 * 7 + j).collect();
    for w in row.windows(2) {
        let e = t.find_edge(w[0], w[1]).unwrap() as usize;
        t.set_edge_sharpness(e, tags::SHARPNESS_INFINITE);
    }
    for scheme in [Scheme::Sqrt3, Scheme::BUTTERFLY, Scheme::ModifiedButterfly] {
        let r = Refinement::new(&t, scheme.clone(), &Options::default(), 2).unwrap();
        let t2 = r.topology(2);
        let creased = (0..t2.num_edges())
            .filter(|&e| !t2.is_boundary_edge(e) && tags::is_infinite(t2.edge_sharpness(e)))
            .count();
        let expected = if scheme == Scheme::Sqrt3 { 18 } else { 24 };
        assert_eq!(creased, expected, "{scheme:?}");
    }
    let r = Refinement::new(&t, Scheme::BUTTERFLY, &Options::default(), 1).unwrap();
    let out = r.refine_points(&p).pop().unwrap();
    for i in 1..5 {
        let e = t.find_edge(row[i], row[i + 1]).unwrap() as usize;
        let q = |k: usize| p[row[k] as usize];
        let four = (q(i) + q(i + 1)) * (9.0 / 16.0) - (q(i - 1) + q(i + 2)) / 16.0;
        assert!((out[p.len() + e] - four).length() < 1e-14);
    }
}

#[test]
fn bad_input_is_a_typed_error() {
    let quad = build(4, &[vec![0, 1, 2, 3]]);
    for scheme in [Scheme::Sqrt3, Scheme::BUTTERFLY, Scheme::ModifiedButterfly] {
        assert!(matches!(
            Refinement::new(&quad, scheme.clone(), &Options::default(), 1),
            Err(RefineError::NotTriangle {
                face: 0,
                size: 4,
                ..
            })
        ));
    }
    // Three triangles on one edge.
    let fin = subd_mesh::TopologyBuilder::new(5)
        .build(&[3, 3, 3], &[0, 1, 2, 1, 0, 3, 0, 1, 4])
        .unwrap_or_else(|_| {
            subd_mesh::TopologyBuilder::new(5)
                .accept_inconsistent_orientation(true)
                .build(&[3, 3, 3], &[0, 1, 2, 1, 0, 3, 0, 1, 4])
                .unwrap()
        });
    for scheme in SCHEMES {
        assert!(matches!(
            Refinement::new(&fin, scheme.clone(), &Options::default(), 1),
            Err(RefineError::NonManifoldEdge { .. })
        ));
    }
    let (mut t, _) = regular_grid(3);
    t.set_edge_sharpness(t.find_edge(5, 6).unwrap() as usize, 2.0);
    assert!(matches!(
        Refinement::new(&t, Scheme::Sqrt3, &Options::default(), 1),
        Err(RefineError::UnsupportedTag { .. })
    ));
    assert!(matches!(
        Refinement::new(&t, Scheme::DooSabin, &Options::default(), 1),
        Err(RefineError::UnsupportedTag { .. })
    ));
    assert!(matches!(
        Refinement::new(
            &t,
            Scheme::Butterfly { tension: f64::NAN },
            &Options::default(),
            1
        ),
        Err(RefineError::Tension(_))
    ));
    assert!(matches!(
        Refinement::new(&quad, Scheme::DooSabin, &Options::default(), 16),
        Err(RefineError::TooManyLevels { .. })
    ));
}

/// A closed triangle mesh with valences 3 to 8: a random torus, triangulated, plus an
/// octahedron-like bump.
fn closed_triangles() -> (Topology, Vec<DVec3>) {
    let m = subd_tests::random_mesh(0, 6, 7, &[2, 3, 2, 0, 3], &[(0.0, 0.0)]);
    let t = triangulated(&m);
    let p: Vec<DVec3> = (0..m.num_vertices)
        .map(|i| {
            let (u, v) = ((i % 7) as f64, (i / 7) as f64);
            let (a, b) = (
                u * std::f64::consts::TAU / 7.0 + 0.1 * v,
                v * std::f64::consts::TAU / 6.0,
            );
            DVec3::new(
                (3.0 + b.cos()) * a.cos(),
                (3.0 + b.cos()) * a.sin(),
                b.sin() + 0.05 * (i as f64).sin(),
            )
        })
        .collect();
    (t, p)
}

/// The limit of a base vertex is the limit of the same vertex two levels down: the masks
/// are eigen-functionals of the refinement (positions to 1e-12, normals parallel to 1e-10),
/// for √3 and both butterflies, on a closed and an open mesh.
#[test]
fn limits_are_invariant_under_refinement() {
    let (tc, pc) = closed_triangles();
    let (to, mut po) = regular_grid(8);
    for (i, q) in po.iter_mut().enumerate() {
        q.z = 0.4 * (i as f64 * 0.9).sin();
    }
    // A crease from the boundary into the middle of the grid: it ends in a dart.
    let mut td = to.clone();
    for j in 0..4u32 {
        let e = td.find_edge(4 * 9 + j, 4 * 9 + j + 1).unwrap() as usize;
        td.set_edge_sharpness(e, tags::SHARPNESS_INFINITE);
    }
    let pd = po.clone();
    for (t, p) in [(tc, pc), (to, po), (td, pd)] {
        for scheme in [Scheme::Sqrt3, Scheme::BUTTERFLY, Scheme::ModifiedButterfly] {
            let base = split_limit_stencils(&t, &scheme).unwrap().evaluate(&p);
            let r = Refinement::new(&t, scheme.clone(), &Options::default(), 2).unwrap();
            let p2 = r.refine_points(&p).pop().unwrap();
            // √3's boundary rule depends on the step's parity: level 2 starts a new pair.
            let deep = split_limit_stencils(r.topology(2), &scheme)
                .unwrap()
                .evaluate(&p2);
            let mut normals = 0;
            for v in 0..p.len() {
                if let (Some(a), Some(b)) = (base.positions[v], deep.positions[v]) {
                    assert!(
                        (a - b).length() < 1e-12,
                        "{scheme:?} vertex {v}: {a} vs {b}"
                    );
                }
                if let (Some(a), Some(b)) = (base.normals[v], deep.normals[v]) {
                    assert!(
                        a.cross(b).length() < 1e-10 && a.dot(b) > 0.0,
                        "{scheme:?} normal {v}"
                    );
                    normals += 1;
                }
            }
            assert!(normals > 0, "{scheme:?}: no normals compared");
            if scheme != Scheme::BUTTERFLY {
                // Every interior vertex has a normal and every vertex a position.
                assert!(base.positions.iter().all(Option::is_some), "{scheme:?}");
            }
        }
    }
}

/// Doo-Sabin: the limit of a vertex is its vertex face's centroid, and the face's corners,
/// refined on and on, close in on it in the plane of the limit normal.
#[test]
fn doo_sabin_limit_points_and_normals() {
    // A torus with a hexagon every few quads (valence-3 vertices, 6-sided faces).
    let mesh = subd_mesh::primitives::torus_with_hexagons(8, 10, 3, 3.0, 1.0);
    let (t, p) = (mesh.topology, mesh.positions);
    let limits = split_limit_stencils(&t, &Scheme::DooSabin)
        .unwrap()
        .evaluate(&p);
    let r = Refinement::new(&t, Scheme::DooSabin, &Options::default(), 1).unwrap();
    let p1 = r.refine_points(&p).pop().unwrap();
    let vface = subd_schemes::split_schemes::doo_sabin::vertex_face_indices(&t);
    for (v, face) in vface.iter().enumerate() {
        let f = face.unwrap() as usize;
        let corners: Vec<DVec3> = r
            .topology(1)
            .face_vertices(f)
            .iter()
            .map(|&c| p1[c as usize])
            .collect();
        let k = corners.len();
        let centroid = corners.iter().copied().sum::<DVec3>() / k as f64;
        assert!((limits.positions[v].unwrap() - centroid).length() < 1e-12);
        // The face's own chain of F-faces: its circulant mask, 30 times, applied to the
        // corners' offsets from the centroid (which the mask keeps).
        let mut corners: Vec<DVec3> = corners.iter().map(|&c| c - centroid).collect();
        for _ in 0..30 {
            corners = (0..k)
                .map(|i| {
                    (0..k)
                        .map(|j| {
                            corners[j]
                                * subd_schemes::split_schemes::doo_sabin::weight(k, (j + k - i) % k)
                        })
                        .sum()
                })
                .collect();
            // The mean stays zero but for rounding, which the mask keeps while the rest
            // halves: take it out again.
            let mean = corners.iter().copied().sum::<DVec3>() / k as f64;
            corners.iter_mut().for_each(|d| *d -= mean);
        }
        let n = limits.normals[v].unwrap();
        for d in &corners {
            assert!((d.normalize().dot(n)).abs() < 1e-8, "vertex {v}");
        }
    }
}

/// Doo-Sabin's face mask is a circulant whose eigenvalues are 1 (frequency 0), ½
/// (frequencies ±1) and ¼ (every other frequency): the weights `α_d` are chosen for it.
#[test]
fn doo_sabin_face_mask_spectrum() {
    use subd_schemes::split_schemes::doo_sabin::weight;
    for k in 3..=12 {
        for j in 0..k {
            let lambda: f64 = (0..k)
                .map(|d| weight(k, d) * (std::f64::consts::TAU * (j * d) as f64 / k as f64).cos())
                .sum();
            let expected = match j.min(k - j) {
                0 => 1.0,
                1 => 0.5,
                _ => 0.25,
            };
            assert!((lambda - expected).abs() < 1e-14, "k {k} j {j}: {lambda}");
        }
    }
}

/// Normals point to the side the faces' winding makes the outside: on a convex closed mesh,
/// away from the centre.
#[test]
fn normals_point_outwards() {
    let path = subd_tests::osd_mesh_dir().join("loop_icosahedron.obj");
    let file = subd_io::read_mesh(&path, &subd_io::ReadOptions::default()).unwrap();
    let (t, p) = (&file.mesh.topology, &file.mesh.positions);
    let centre = p.iter().copied().sum::<DVec3>() / p.len() as f64;
    for scheme in [Scheme::Sqrt3, Scheme::BUTTERFLY, Scheme::ModifiedButterfly] {
        let l = split_limit_stencils(t, &scheme).unwrap().evaluate(p);
        for (v, (n, q)) in l.normals.iter().zip(p).enumerate() {
            assert!(n.unwrap().dot(*q - centre) > 0.0, "{scheme:?} vertex {v}");
        }
    }
    let cube = subd_tests::osd_mesh_dir().join("catmark_cube.obj");
    let file = subd_io::read_mesh(&cube, &subd_io::ReadOptions::default()).unwrap();
    let (t, p) = (&file.mesh.topology, &file.mesh.positions);
    let centre = p.iter().copied().sum::<DVec3>() / p.len() as f64;
    let l = split_limit_stencils(t, &Scheme::DooSabin)
        .unwrap()
        .evaluate(p);
    for (v, (n, q)) in l.normals.iter().zip(p).enumerate() {
        assert!(n.unwrap().dot(*q - centre) > 0.0, "doo-sabin vertex {v}");
    }
}

/// On a flat grid every limit normal is the plane's, at interior and boundary vertices alike
/// (turned by the faces' orientation: +z here), for √3 and both butterflies.
#[test]
fn normals_of_a_flat_grid_are_the_plane_normal() {
    let (t, p) = regular_grid(7);
    for scheme in [Scheme::Sqrt3, Scheme::BUTTERFLY, Scheme::ModifiedButterfly] {
        let l = split_limit_stencils(&t, &scheme).unwrap().evaluate(&p);
        let mut boundary = 0;
        for v in 0..p.len() {
            let corner = t.vertex_faces(v).len() < 2 && t.is_boundary_vertex(v);
            match l.normals[v] {
                Some(n) => {
                    assert!(
                        (n - DVec3::Z).length() < 1e-12,
                        "{scheme:?} vertex {v}: {n}"
                    );
                    boundary += usize::from(t.is_boundary_vertex(v));
                }
                None => assert!(
                    corner || t.vertex_faces(v).len() == 2,
                    "{scheme:?} vertex {v}"
                ),
            }
        }
        assert!(boundary > 10, "{scheme:?}: {boundary} boundary normals");
    }
}

/// A `n × n` grid of squares, each cut along a diagonal chosen by a fixed pseudo-random
/// sequence, lifted onto a wavy height field: valences 2 to 8 everywhere, a boundary, and
/// wide enough that the pieces cut around vertices are much smaller than the mesh.
fn irregular_grid(n: u32) -> (Topology, Vec<DVec3>) {
    let id = |i: u32, j: u32| j * (n + 1) + i;
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut faces = Vec::new();
    for j in 0..n {
        for i in 0..n {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if state.is_multiple_of(3) {
                faces.extend([a, b, d, b, c, d]);
            } else {
                faces.extend([a, b, c, a, c, d]);
            }
        }
    }
    let nv = ((n + 1) * (n + 1)) as usize;
    let t = subd_mesh::TopologyBuilder::new(nv)
        .build(&vec![3; faces.len() / 3], &faces)
        .unwrap();
    let p = (0..nv as u32)
        .map(|v| {
            let (x, y) = (f64::from(v % (n + 1)), f64::from(v / (n + 1)));
            DVec3::new(x, y, (0.7 * x).sin() + (0.45 * y).cos())
        })
        .collect();
    (t, p)
}

/// [`split_limits_of_local_pieces_match_the_whole_mesh`] where the pieces are far smaller
/// than the mesh (the OpenSubdiv shapes are mostly refined whole): an irregular grid with a
/// boundary, at the base and one level down.
#[test]
fn split_limits_of_small_pieces_match_the_whole_mesh() {
    use subd_limit::split_limit::{Neighbourhoods, split_limit_stencils_in};
    let (t, p) = irregular_grid(40);
    for scheme in [Scheme::Sqrt3, Scheme::BUTTERFLY, Scheme::ModifiedButterfly] {
        let r = Refinement::new(&t, scheme.clone(), &Options::default(), 1).unwrap();
        let p1 = r.refine_points(&p).pop().unwrap();
        for (level, (t, p)) in [(&t, &p), (r.topology(1), &p1)].into_iter().enumerate() {
            let whole = split_limit_stencils_in(t, &scheme, Neighbourhoods::Whole).unwrap();
            let local = split_limit_stencils_in(t, &scheme, Neighbourhoods::Local).unwrap();
            assert_eq!(
                whole.position_known, local.position_known,
                "{scheme:?} {level}"
            );
            assert_eq!(
                whole.tangents_known, local.tangents_known,
                "{scheme:?} {level}"
            );
            let (w, l) = (whole.evaluate(p), local.evaluate(p));
            assert_eq!(w, l, "{scheme:?} level {level}");
            // Most interior vertices have a normal: the comparison is not of empty rows.
            let normals = w.normals.iter().filter(|n| n.is_some()).count();
            assert!(
                normals * 2 > t.num_vertices(),
                "{scheme:?} {level}: {normals}"
            );
        }
    }
}

/// The limits of √3 and the butterflies read off pieces cut around the vertices that need
/// deeper levels are those read off the whole mesh refined that deep, bit for bit: on every
/// OpenSubdiv shape the scheme refines, at the base and one level down (where the pieces
/// are smaller than the mesh).
#[test]
fn split_limits_of_local_pieces_match_the_whole_mesh() {
    use subd_limit::split_limit::{Neighbourhoods, split_limit_stencils_in};
    let mut compared = 0;
    for path in subd_tests::osd_meshes() {
        let Ok(file) = subd_io::read_mesh(&path, &subd_io::ReadOptions::default()) else {
            continue;
        };
        for scheme in [Scheme::Sqrt3, Scheme::BUTTERFLY, Scheme::ModifiedButterfly] {
            let (t, p) = (&file.mesh.topology, &file.mesh.positions);
            let Ok(r) = Refinement::new(t, scheme.clone(), &Options::default(), 1) else {
                continue;
            };
            let p1 = r.refine_points(p).pop().unwrap();
            for (t, p) in [(t, p), (r.topology(1), &p1)] {
                let whole = split_limit_stencils_in(t, &scheme, Neighbourhoods::Whole);
                let local = split_limit_stencils_in(t, &scheme, Neighbourhoods::Local);
                let (Ok(whole), Ok(local)) = (whole, local) else {
                    panic!("{} {scheme:?}: one path failed", path.display());
                };
                assert_eq!(whole.position_known, local.position_known);
                assert_eq!(whole.tangents_known, local.tangents_known);
                assert_eq!(
                    whole.evaluate(p),
                    local.evaluate(p),
                    "{} {scheme:?}",
                    path.display()
                );
                compared += 1;
            }
        }
    }
    assert!(compared > 50, "only {compared} meshes compared");
}

/// `split_limit_points` (each mask applied to the points of the level where it is found)
/// against the stencil tables of `split_limit_table` applied to the same points (the rows
/// composed back to the base): on every OpenSubdiv shape each split scheme refines, and an
/// irregular grid with a boundary, at the base and one level down. Positions agree to 1e-14
/// of the bounding box and unit normals to 1e-11 (the deeper masks' sums run in another
/// order), undefined normals are undefined on both sides, a mesh without a limit fails with
/// the same message, and the vertices settled at the base level are equal bit for bit.
#[test]
fn split_limit_points_equal_the_tables_applied() {
    use subd_limit::split_limit::{split_limit_points, split_limit_table};
    let mut meshes: Vec<(String, Topology, Vec<DVec3>)> = subd_tests::osd_meshes()
        .into_iter()
        .filter_map(|path| {
            let file = subd_io::read_mesh(&path, &subd_io::ReadOptions::default()).ok()?;
            let name = path.file_stem()?.to_string_lossy().to_string();
            Some((name, file.mesh.topology, file.mesh.positions))
        })
        .collect();
    let (t, p) = irregular_grid(30);
    meshes.push(("irregular grid".into(), t, p));
    let (mut compared, mut same_bits, mut vertices) = (0, 0, 0);
    let schemes = [
        Scheme::DooSabin,
        Scheme::Sqrt3,
        Scheme::BUTTERFLY,
        Scheme::ModifiedButterfly,
    ];
    for (name, t, p) in &meshes {
        for scheme in &schemes {
            let Ok(r) = Refinement::new(t, scheme.clone(), &Options::default(), 1) else {
                continue;
            };
            let p1 = r.refine_points(p).pop().unwrap();
            let diag = subd_pia::bbox_diagonal(p).max(1e-300);
            for (level, (t, p)) in [(t, p), (r.topology(1), &p1)].into_iter().enumerate() {
                let what = format!("{name} {scheme:?} level {level}");
                let (table, ours) = match (
                    split_limit_table(t, scheme).map(|table| table.apply(p)),
                    split_limit_points(t, scheme, p),
                ) {
                    (Ok(a), Ok(b)) => (a, b),
                    (Err(a), Err(b)) => {
                        assert_eq!(a.to_string(), b.to_string(), "{what}");
                        continue;
                    }
                    (a, b) => panic!("{what}: {:?} vs {:?}", a.err(), b.err()),
                };
                for v in 0..p.len() {
                    let d = (table.positions[v] - ours.positions[v]).length() / diag;
                    assert!(d <= 1e-14, "{what} vertex {v}: position {d:e}");
                    let (a, b) = (table.normals[v], ours.normals[v]);
                    let same = (a - b).length() < 1e-11
                        || (a == DVec3::ZERO && b == DVec3::ZERO)
                        || (a.is_nan() && b.is_nan());
                    assert!(same, "{what} vertex {v}: normal {a} vs {b}");
                    same_bits += usize::from(table.positions[v] == ours.positions[v]);
                }
                vertices += p.len();
                compared += 1;
            }
        }
    }
    assert!(compared > 100, "only {compared} levels compared");
    // Most vertices are settled at the base level, where the sums are the table's.
    assert!(
        same_bits * 10 > vertices * 9,
        "{same_bits} of {vertices} positions bit for bit"
    );
}
