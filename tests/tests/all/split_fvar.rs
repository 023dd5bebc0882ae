//! Face-varying data through the split schemes (`subd_schemes::split_schemes::fvar`):
//! a seamless channel is refined exactly as positions are; across seams the butterflies
//! refine each UV island as a mesh of its own; mode `all` is midpoint subdivision; Doo-Sabin
//! and √3 refuse seams by name.

use proptest::prelude::*;
use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation as Mode};
use subd_mesh::{DVec3, Topology, tags};
use subd_schemes::split_schemes::{SplitFVarError, SplitFaceVarying};
use subd_schemes::{Options, Refinement, Scheme};
use subd_tests::{build, mesh_strategy, triangulated};

const MODES: [Mode; 6] = [
    Mode::None,
    Mode::CornersOnly,
    Mode::CornersPlus1,
    Mode::CornersPlus2,
    Mode::Boundaries,
    Mode::All,
];

/// Two numbers per vertex that vary irregularly with its index.
fn vertex_uv(v: usize) -> [f64; 2] {
    let t = v as f64;
    [(0.37 * t).sin() + 0.01 * t, (0.23 * t).cos() - 0.02 * t]
}

/// The value of every face-vertex of `level`, two numbers each.
fn corner_values(fv: &SplitFaceVarying, values: &[f64], level: usize) -> Vec<[f64; 2]> {
    let level_values = fv.refine_values(values, 2).swap_remove(level);
    fv.face_values(level)
        .iter()
        .map(|&i| {
            [
                level_values[2 * i as usize],
                level_values[2 * i as usize + 1],
            ]
        })
        .collect()
}

fn assert_close(got: [f64; 2], want: [f64; 2], what: &str) {
    let d = (got[0] - want[0]).abs().max((got[1] - want[1]).abs());
    assert!(d <= 1e-12, "{what}: {got:?}, expected {want:?} ({d:e} off)");
}

/// A seamless channel (one value per vertex) at each face corner of level 2 equals the
/// scheme's refined positions with the value as (u, v, 0): the direct masks of
/// `refine_points` against the composed stencils of the mesh of values.
fn seamless_matches_positions(t: &Topology, scheme: Scheme) -> Result<(), TestCaseError> {
    let levels = 2;
    let r = Refinement::new(t, scheme.clone(), &Options::default(), levels).expect("valid input");
    let uv: Vec<[f64; 2]> = (0..t.num_vertices()).map(vertex_uv).collect();
    let values: Vec<f64> = uv.iter().flatten().copied().collect();
    let channel =
        FVarChannel::new(t, 2, values.clone(), t.all_face_vertices().to_vec()).expect("channel");
    let points: Vec<DVec3> = uv.iter().map(|&[u, v]| DVec3::new(u, v, 0.0)).collect();
    let refined = r.refine_points(&points).swap_remove(levels);
    let (_, level_vertices) = r.faces(levels);
    // The butterflies follow their rules in every mode but `all` on a seamless channel
    // whose mesh boundary has no corner the mode pins; Doo-Sabin and √3 in every mode.
    let modes: &[Mode] = if scheme.is_interpolating() {
        &[Mode::None]
    } else {
        &MODES
    };
    for &mode in modes {
        let fv = SplitFaceVarying::new(&r, &channel, mode).expect("seamless channel");
        let got = corner_values(&fv, &values, levels);
        prop_assert_eq!(got.len(), level_vertices.len());
        for (i, (g, &v)) in got.iter().zip(level_vertices).enumerate() {
            let p = refined[v as usize];
            let d = (g[0] - p.x).abs().max((g[1] - p.y).abs());
            prop_assert!(
                d <= 1e-12,
                "{} {:?}: face-vertex {} is {:?}, its vertex {:?} ({:e} off)",
                scheme.name(),
                mode,
                i,
                g,
                p,
                d
            );
        }
        // The composed table says the same.
        let table = fv.composed(levels);
        let mut direct = vec![0.0; 2 * table.num_rows()];
        table.apply(&values, 2, &mut direct);
        let by_table: Vec<[f64; 2]> = fv
            .face_values(levels)
            .iter()
            .map(|&i| [direct[2 * i as usize], direct[2 * i as usize + 1]])
            .collect();
        for (a, b) in by_table.iter().zip(&got) {
            prop_assert!((a[0] - b[0]).abs().max((a[1] - b[1]).abs()) <= 1e-12);
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]

    #[test]
    fn seamless_channels_are_refined_as_positions(m in mesh_strategy(), crease_every in 3usize..9) {
        seamless_matches_positions(&build(m.num_vertices, &m.faces), Scheme::DooSabin)?;
        let mut tri = triangulated(&m);
        for e in (0..tri.num_edges()).step_by(crease_every) {
            if !tri.is_boundary_edge(e) {
                tri.set_edge_sharpness(e, tags::SHARPNESS_INFINITE);
            }
        }
        for scheme in [Scheme::Sqrt3, Scheme::BUTTERFLY, Scheme::ModifiedButterfly] {
            seamless_matches_positions(&tri, scheme)?;
        }
    }
}

/// A regular triangulated `k × k` grid and the UV island of each face: 0 on the left half,
/// 1 on the upper right, 2 on the lower right (three islands meet at the grid's centre).
fn grid_with_islands(k: u32) -> (Topology, Vec<usize>) {
    let id = |i: u32, j: u32| i * (k + 1) + j;
    let mut faces = Vec::new();
    let mut island = Vec::new();
    for i in 0..k {
        for j in 0..k {
            let here = if j < k / 2 {
                0
            } else if i < k / 2 {
                2
            } else {
                1
            };
            faces.push(vec![id(i, j), id(i, j + 1), id(i + 1, j + 1)]);
            faces.push(vec![id(i, j), id(i + 1, j + 1), id(i + 1, j)]);
            island.extend([here, here]);
        }
    }
    (build(((k + 1) * (k + 1)) as usize, &faces), island)
}

/// Texture coordinates of vertex `v` in island `i`: each island its own smooth map.
fn island_uv(i: usize, v: usize) -> [f64; 2] {
    let [a, b] = vertex_uv(v);
    let s = i as f64;
    [a + 3.0 * s + 0.1 * s * b * b, b - 0.2 * s * a]
}

/// A UV channel on `t` from each face's island: one value per (island, vertex) when
/// `shared`, else one per face corner (every edge a seam). Values are numbered in order of
/// first use; returns the values (two numbers each) and the index of every face-vertex.
fn island_channel(t: &Topology, island: &[usize], shared: bool) -> (Vec<f64>, Vec<u32>) {
    let mut value_of = std::collections::HashMap::new();
    let mut values = Vec::new();
    let mut indices = Vec::new();
    for (f, &i) in island.iter().enumerate() {
        for (k, &v) in t.face_vertices(f).iter().enumerate() {
            let key = (i, v as usize, if shared { 0 } else { 3 * f + k + 1 });
            let next = value_of.len() as u32;
            let x = *value_of.entry(key).or_insert_with(|| {
                values.extend(island_uv(i, v as usize));
                next
            });
            indices.push(x);
        }
    }
    (values, indices)
}

/// With seams, the butterflies refine each UV island as a mesh of its own: the values at the
/// face corners of an island equal the positions of the island, built as a separate mesh
/// (its vertices the (island, vertex) pairs) and refined with `refine_points`.
#[test]
fn butterfly_islands_refine_as_their_own_meshes() {
    let (t, island) = grid_with_islands(8);
    let levels = 2;
    let (values, indices) = island_channel(&t, &island, true);
    let channel = FVarChannel::new(&t, 2, values.clone(), indices.clone()).expect("channel");
    for scheme in [Scheme::BUTTERFLY, Scheme::ModifiedButterfly] {
        let r =
            Refinement::new(&t, scheme.clone(), &Options::default(), levels).expect("valid input");
        let fv = SplitFaceVarying::new(&r, &channel, Mode::None).expect("butterflies take seams");
        let got = corner_values(&fv, &values, levels);
        let per_face = 4usize.pow(levels as u32) * 3;
        for which in 0..3 {
            // The island as a mesh: its faces on its own (island, vertex) values.
            let faces: Vec<usize> = (0..t.num_faces()).filter(|&f| island[f] == which).collect();
            let island_faces: Vec<Vec<u32>> = faces
                .iter()
                .map(|&f| (0..3).map(|k| indices[3 * f + k]).collect())
                .collect();
            let n = values.len() / 2;
            let own = build(n, &island_faces);
            let points: Vec<DVec3> = (0..n)
                .map(|x| DVec3::new(values[2 * x], values[2 * x + 1], 0.0))
                .collect();
            let ir = Refinement::new(&own, scheme.clone(), &Options::default(), levels)
                .expect("an island is manifold");
            let refined = ir.refine_points(&points).swap_remove(levels);
            let (_, island_vertices) = ir.faces(levels);
            // Child faces of island face j are those of geometry face faces[j], in order.
            for (j, &f) in faces.iter().enumerate() {
                for c in 0..per_face {
                    let p = refined[island_vertices[j * per_face + c] as usize];
                    assert_close(
                        got[f * per_face + c],
                        [p.x, p.y],
                        &format!("{} island {which} face {f} corner {c}", scheme.name()),
                    );
                }
            }
        }
        // A seam vertex has one value per side: the centre, where three islands meet (the
        // butterflies keep every vertex's index).
        let centre = 4 * 9 + 4;
        let level_faces = fv.face_values(levels);
        let mut at_centre: Vec<u32> = (0..level_faces.len())
            .filter(|&i| r.faces(levels).1[i] == centre)
            .map(|i| level_faces[i])
            .collect();
        at_centre.sort_unstable();
        at_centre.dedup();
        assert_eq!(at_centre.len(), 3, "three values at the centre");
    }
}

/// Mode `all`: every level is midpoint subdivision of the triangles' corner values, in each
/// face's own values (a triangle's children `(V0,E0,E2)`, `(E0,V1,E1)`, `(E2,E1,V2)`,
/// `(E1,E2,E0)`), whatever the seams; so is mode `boundaries` along a seam or boundary edge.
#[test]
fn mode_all_is_midpoint_subdivision_and_boundaries_is_linear_along_seams() {
    let (t, island) = grid_with_islands(6);
    // Every corner its own value: every edge a seam.
    let (values, indices) = island_channel(&t, &island, false);
    let channel = FVarChannel::new(&t, 2, values.clone(), indices).expect("channel");
    let mid = |a: [f64; 2], b: [f64; 2]| [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
    let levels = 3;
    let mut expected: Vec<[[f64; 2]; 3]> = (0..t.num_faces())
        .map(|f| std::array::from_fn(|k| [values[6 * f + 2 * k], values[6 * f + 2 * k + 1]]))
        .collect();
    for _ in 0..levels {
        expected = expected
            .iter()
            .flat_map(|&[a, b, c]| {
                let (e0, e1, e2) = (mid(a, b), mid(b, c), mid(c, a));
                [[a, e0, e2], [e0, b, e1], [e2, e1, c], [e1, e2, e0]]
            })
            .collect();
    }
    for scheme in [Scheme::BUTTERFLY, Scheme::ModifiedButterfly] {
        let r =
            Refinement::new(&t, scheme.clone(), &Options::default(), levels).expect("valid input");
        let fv = SplitFaceVarying::new(&r, &channel, Mode::All).expect("any channel");
        let got = corner_values(&fv, &values, levels);
        for (i, (g, e)) in got.iter().zip(expected.iter().flatten()).enumerate() {
            assert_close(
                *g,
                *e,
                &format!("{} mode all, face-vertex {i}", scheme.name()),
            );
        }
        // Mode boundaries with every edge a seam: the same at level 1.
        let fv = SplitFaceVarying::new(&r, &channel, Mode::Boundaries).expect("any channel");
        let got = corner_values(&fv, &values, 1);
        let mut level1 = Vec::new();
        for f in 0..t.num_faces() {
            let c: [[f64; 2]; 3] =
                std::array::from_fn(|k| [values[6 * f + 2 * k], values[6 * f + 2 * k + 1]]);
            let (e0, e1, e2) = (mid(c[0], c[1]), mid(c[1], c[2]), mid(c[2], c[0]));
            level1.extend([c[0], e0, e2, e0, c[1], e1, e2, e1, c[2], e1, e2, e0]);
        }
        for (i, (g, e)) in got.iter().zip(&level1).enumerate() {
            assert_close(
                *g,
                *e,
                &format!("{} mode boundaries, face-vertex {i}", scheme.name()),
            );
        }
    }
}

/// Doo-Sabin and √3 refuse a channel with seams, naming a vertex that has two values.
#[test]
fn dual_and_sqrt3_refuse_seams_by_vertex() {
    let (t, island) = grid_with_islands(4);
    let (values, indices) = island_channel(&t, &island, true);
    let channel = FVarChannel::new(&t, 2, values, indices.clone()).expect("channel");
    for scheme in [Scheme::DooSabin, Scheme::Sqrt3] {
        let r = Refinement::new(&t, scheme.clone(), &Options::default(), 1).expect("valid input");
        match SplitFaceVarying::new(&r, &channel, Mode::CornersPlus1) {
            Err(SplitFVarError::Seam { vertex, .. }) => {
                let distinct: std::collections::BTreeSet<u32> = (0..t.num_face_vertices())
                    .filter(|&i| t.all_face_vertices()[i] as usize == vertex)
                    .map(|i| indices[i])
                    .collect();
                assert!(distinct.len() > 1, "vertex {vertex} is not on a seam");
            }
            other => panic!("{}: expected a seam error, got {other:?}", scheme.name()),
        }
    }
}

/// On every OpenSubdiv shape with UVs that the butterflies refine, in every mode: the
/// channel is carried, and every base corner keeps its value at level 2 (the butterflies
/// interpolate: the child faces 0, 5 and 10 of a triangle's sixteen keep its corners 0, 1
/// and 2).
#[test]
fn butterflies_keep_every_corner_value_on_the_osd_shapes() {
    let mut shapes = 0;
    for path in subd_tests::osd_meshes() {
        let Ok(file) = subd_io::read_mesh(&path, &subd_io::ReadOptions::default()) else {
            continue;
        };
        let (t, Some(channel)) = (&file.mesh.topology, file.mesh.uv()) else {
            continue;
        };
        let Ok(r) = Refinement::new(t, Scheme::ModifiedButterfly, &Options::default(), 2) else {
            continue;
        };
        shapes += 1;
        for mode in MODES {
            let fv = SplitFaceVarying::new(&r, channel, mode)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            let got = corner_values(&fv, channel.values(), 2);
            for f in 0..t.num_faces() {
                for (k, child) in [(0, 0), (1, 5), (2, 10)] {
                    let x = channel.indices()[3 * f + k] as usize;
                    let want = [channel.value(x)[0], channel.value(x)[1]];
                    assert_close(
                        got[3 * (16 * f + child) + k],
                        want,
                        &format!("{} {mode:?} face {f} corner {k}", path.display()),
                    );
                }
            }
        }
    }
    assert!(shapes >= 10, "only {shapes} shapes refined");
}
