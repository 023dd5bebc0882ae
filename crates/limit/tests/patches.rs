//! Patch tables: the patch map covers every face's domain exactly once, neighbouring
//! patches meet along their edges (across faces and across depth changes), exact end caps
//! are the exact limit, and `update` equals a rebuild.

use proptest::prelude::*;
use subd_limit::eval::{FaceParam, LimitEvaluator};
use subd_limit::patches::{EndCaps, PatchOptions, PatchTable, PatchType};
use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};
use subd_mesh::{DVec3, Topology, TopologyBuilder};
use subd_schemes::{Options, Scheme};

/// A mesh for the tests: topology, positions, scheme.
#[derive(Clone)]
struct Case {
    topology: Topology,
    positions: Vec<DVec3>,
    scheme: Scheme,
}

fn build(sizes: &[u32], faces: &[u32], positions: Vec<DVec3>, scheme: Scheme) -> Case {
    let topology = TopologyBuilder::new(positions.len())
        .build(sizes, faces)
        .unwrap();
    Case {
        topology,
        positions,
        scheme,
    }
}

/// A cube with a pentagon-free twist: valence-3 corners everywhere.
fn cube() -> Case {
    let faces = [
        0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4,
    ];
    let p = (0..8)
        .map(|i| {
            DVec3::new(
                (i & 1) as f64,
                ((i >> 1) & 1) as f64,
                ((i >> 2) & 1) as f64 * 1.3,
            )
        })
        .collect();
    build(&[4; 6], &faces, p, Scheme::CatmullClark)
}

/// A 4 × 4 grid of quads with an open boundary, one interior vertex raised, one crease.
fn open_grid() -> Case {
    let mut faces = Vec::new();
    for y in 0..4u32 {
        for x in 0..4u32 {
            let v = x + 5 * y;
            faces.extend([v, v + 1, v + 6, v + 5]);
        }
    }
    let p = (0..25)
        .map(|v| {
            let (x, y) = ((v % 5) as f64, (v / 5) as f64);
            DVec3::new(x, y, if v == 12 { 1.0 } else { 0.1 * x * y })
        })
        .collect();
    let mut c = build(&[4; 16], &faces, p, Scheme::CatmullClark);
    c.topology.set_crease(6, 7, 2.5).unwrap();
    c.topology.set_crease(7, 8, 2.5).unwrap();
    c
}

/// A pentagon surrounded by quads (a non-quad base face), closed into a cap.
fn pentagon() -> Case {
    // Pentagon 0..4, outer ring 5..9, quads between; the outer ring closed by a second
    // pentagon.
    let mut faces = vec![0, 1, 2, 3, 4];
    let mut sizes = vec![5];
    for i in 0..5u32 {
        let j = (i + 1) % 5;
        faces.extend([i, i + 5, j + 5, j]);
        sizes.push(4);
    }
    faces.extend([9, 8, 7, 6, 5]);
    sizes.push(5);
    let p = (0..10)
        .map(|v| {
            let a = (v % 5) as f64 * std::f64::consts::TAU / 5.0;
            let r = if v < 5 { 1.0 } else { 1.4 };
            DVec3::new(r * a.cos(), r * a.sin(), if v < 5 { 0.5 } else { -0.5 })
        })
        .collect();
    build(&sizes, &faces, p, Scheme::CatmullClark)
}

/// An octahedron with one vertex pulled (Loop, valence 4 everywhere).
fn octahedron() -> Case {
    let fv = [
        0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1, 5, 2, 1, 5, 3, 2, 5, 4, 3, 5, 1, 4,
    ];
    let p = vec![
        DVec3::new(0.0, 0.0, 1.2),
        DVec3::X,
        DVec3::Y,
        -DVec3::X,
        -DVec3::Y,
        -DVec3::Z,
    ];
    build(&[3; 8], &fv, p, Scheme::Loop)
}

/// A triangle fan with a boundary (Loop): an open hexagon missing one triangle.
fn open_fan() -> Case {
    let fv = [0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 5, 0, 5, 6];
    let p = (0..7)
        .map(|v| {
            if v == 0 {
                DVec3::new(0.0, 0.0, 0.4)
            } else {
                let a = (v - 1) as f64 * std::f64::consts::TAU / 6.0;
                DVec3::new(a.cos(), a.sin(), 0.0)
            }
        })
        .collect();
    build(&[3; 5], &fv, p, Scheme::Loop)
}

fn cases() -> Vec<Case> {
    vec![cube(), open_grid(), pentagon(), octahedron(), open_fan()]
}

/// The root faces of a base face: one, or one per corner of a Catmull-Clark non-quad.
fn subs(c: &Case, f: usize) -> usize {
    let n = c.topology.face_size(f);
    if c.scheme == Scheme::Loop || n == 4 {
        1
    } else {
        n
    }
}

/// The patch map covers each root face exactly once: every sample lies in the domain of the
/// patch found for it, and the patches of a root face add up to its area.
fn check_coverage(c: &Case, table: &PatchTable) {
    let triangles = c.scheme == Scheme::Loop;
    let mut area = vec![0.0f64; 0];
    for a in table.arrays() {
        for p in a.params() {
            let place = p.place();
            let root = place.face as usize;
            if area.len() <= root {
                area.resize(root + 1, 0.0);
            }
            let side = p.fraction();
            area[root] += if triangles {
                side * side / 2.0
            } else {
                side * side
            };
        }
    }
    let mut root = 0;
    for f in 0..c.topology.num_faces() {
        for sub in 0..subs(c, f) {
            let want = if triangles { 0.5 } else { 1.0 };
            assert!(
                (area[root] - want).abs() < 1e-12,
                "root {root}: patches cover {}",
                area[root]
            );
            for i in 0..=8 {
                for j in 0..=8 {
                    let (u, v) = (i as f64 / 8.0, j as f64 / 8.0);
                    if triangles && u + v > 1.0 {
                        continue;
                    }
                    let at = FaceParam { face: f, sub, u, v };
                    let (a, k) = table.find(&at).unwrap();
                    let p = table.arrays()[a].params()[k];
                    let (s, t) = if triangles {
                        p.normalize_triangle(u, v)
                    } else {
                        p.normalize(u, v)
                    };
                    let inside = if triangles {
                        s >= -1e-12 && t >= -1e-12 && s + t <= 1.0 + 1e-12
                    } else {
                        (-1e-12..=1.0 + 1e-12).contains(&s) && (-1e-12..=1.0 + 1e-12).contains(&t)
                    };
                    assert!(
                        inside,
                        "({u}, {v}) of root {root} outside its patch ({s}, {t})"
                    );
                }
            }
            root += 1;
        }
    }
}

/// The parameters of the point at `t` along edge `e` (corner `e` to corner `e + 1`) of base
/// face `f`: the face (or sub-face) and its (u, v).
fn on_edge(c: &Case, f: usize, e: usize, t: f64) -> FaceParam {
    let n = c.topology.face_size(f);
    if c.scheme == Scheme::Loop {
        let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)];
        let (a, b) = (corners[e], corners[(e + 1) % 3]);
        return FaceParam {
            face: f,
            sub: 0,
            u: a.0 + t * (b.0 - a.0),
            v: a.1 + t * (b.1 - a.1),
        };
    }
    if n == 4 {
        let corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
        let (a, b) = (corners[e], corners[(e + 1) % 4]);
        return FaceParam {
            face: f,
            sub: 0,
            u: a.0 + t * (b.0 - a.0),
            v: a.1 + t * (b.1 - a.1),
        };
    }
    // Sub-face e runs along the first half of edge e as its u axis; sub-face e + 1 has the
    // second half as its v axis, from the midpoint (v = 1) to its corner (v = 0).
    if t <= 0.5 {
        FaceParam {
            face: f,
            sub: e,
            u: 2.0 * t,
            v: 0.0,
        }
    } else {
        FaceParam {
            face: f,
            sub: (e + 1) % n,
            u: 0.0,
            v: 2.0 * (1.0 - t),
        }
    }
}

/// Neighbouring base faces give the same point along their shared edges.
fn check_edges_agree(c: &Case, table: &PatchTable, tol: f64) {
    let t = &c.topology;
    for e in 0..t.num_edges() {
        let faces = t.edge_faces(e);
        if faces.len() != 2 {
            continue;
        }
        let [a, b] = t.edge_vertices(e);
        let side = |f: usize| {
            let fv = t.face_vertices(f);
            let i = fv.iter().position(|&x| x == a).unwrap();
            let forward = fv[(i + 1) % fv.len()] == b;
            (
                if forward {
                    i
                } else {
                    (i + fv.len() - 1) % fv.len()
                },
                forward,
            )
        };
        let (f, g) = (faces[0] as usize, faces[1] as usize);
        let ((ef, ff), (eg, fg)) = (side(f), side(g));
        for k in 1..8 {
            let s = k as f64 / 8.0 + 0.013;
            let pf = table
                .evaluate(on_edge(c, f, ef, if ff { s } else { 1.0 - s }))
                .unwrap()
                .position;
            let pg = table
                .evaluate(on_edge(c, g, eg, if fg { s } else { 1.0 - s }))
                .unwrap()
                .position;
            assert!((pf - pg).length() < tol, "edge {e} at {s}: {pf} vs {pg}");
        }
    }
}

/// Inside each root face, points on the boundaries between patches (including where a
/// patch meets deeper ones) evaluate the same from both sides.
fn check_inner_edges_agree(c: &Case, table: &PatchTable, tol: f64) {
    let triangles = c.scheme == Scheme::Loop;
    for f in 0..c.topology.num_faces() {
        for sub in 0..subs(c, f) {
            for i in 1..16 {
                let x = i as f64 / 16.0;
                for j in 0..20 {
                    let y = (j as f64 + 0.37) / 20.0;
                    let (u, v) = (x, y * if triangles { 1.0 - x } else { 1.0 });
                    let eps = 1e-9;
                    let lo = table
                        .evaluate(FaceParam {
                            face: f,
                            sub,
                            u: u - eps,
                            v,
                        })
                        .unwrap();
                    let hi = table
                        .evaluate(FaceParam {
                            face: f,
                            sub,
                            u: u + eps,
                            v,
                        })
                        .unwrap();
                    // Allow the tiny step's own change along the surface.
                    let slack = 4.0 * eps * (lo.du.length() + hi.du.length());
                    assert!(
                        (lo.position - hi.position).length() < tol + slack,
                        "face {f}.{sub} at u = {u}, v = {v}: {} apart",
                        (lo.position - hi.position).length()
                    );
                }
            }
        }
    }
}

fn options(isolation: u8, end_caps: EndCaps, inf_sharp: bool) -> PatchOptions {
    PatchOptions {
        isolation,
        end_caps,
        inf_sharp,
        single_crease: false,
        legacy_sharp_corners: false,
    }
}

/// Every kind of end caps, for either scheme.
const ALL_CAPS: [EndCaps; 4] = [
    EndCaps::GregoryBasis,
    EndCaps::Bilinear,
    EndCaps::BSpline,
    EndCaps::Exact,
];

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn the_patch_map_covers_every_face_once(case in 0usize..5, isolation in 1u8..5, inf_sharp: bool, caps in 0usize..4) {
        let c = &cases()[case];
        let table = PatchTable::new(&c.topology, &c.positions, &c.scheme, &Options::default(), &options(isolation, ALL_CAPS[caps], inf_sharp)).unwrap();
        check_coverage(c, &table);
    }

    #[test]
    fn neighbouring_patches_meet(case in 0usize..5, isolation in 1u8..5, inf_sharp: bool, exact: bool) {
        let c = &cases()[case];
        // Gregory end caps (quads and triangles) share their boundary curves with their
        // neighbours; exact end caps are the limit itself. Bilinear caps, and B-spline and
        // box-spline caps (fitted, each on its own), are not continuous with the regular
        // patches.
        let caps = if exact { EndCaps::Exact } else { EndCaps::GregoryBasis };
        let table = PatchTable::new(&c.topology, &c.positions, &c.scheme, &Options::default(), &options(isolation, caps, inf_sharp)).unwrap();
        check_edges_agree(c, &table, 1e-12);
        check_inner_edges_agree(c, &table, 1e-12);
    }
}

/// B-spline end caps are patches of the regular type, in the regular array: the irregular
/// corner of a Catmull-Clark cube needs 7 new points per cap (the other 9 are the level's
/// vertices), a Loop box-spline cap 12.
#[test]
fn b_spline_end_caps_join_the_regular_patches() {
    for (c, regular, new_per_cap) in [
        (cube(), PatchType::Regular, 7),
        (octahedron(), PatchType::Loop, 12),
    ] {
        let o = options(2, EndCaps::BSpline, false);
        let table = PatchTable::new(
            &c.topology,
            &c.positions,
            &c.scheme,
            &Options::default(),
            &o,
        )
        .unwrap();
        assert_eq!(table.arrays().len(), 1);
        assert_eq!(table.arrays()[0].kind(), regular);
        let caps = table.arrays()[0]
            .params()
            .iter()
            .filter(|p| !p.place().regular)
            .count();
        assert!(caps > 0);
        assert_eq!(table.census().local_points, new_per_cap * caps);
    }
}

#[test]
fn exact_end_caps_are_the_exact_limit_everywhere() {
    for c in cases() {
        let eval = LimitEvaluator::new(&c.topology, &c.scheme, &Options::default()).unwrap();
        let points = eval.prepare(&c.positions);
        let mut regular = 0;
        for isolation in [1, 3] {
            let o = options(isolation, EndCaps::Exact, true);
            let table = PatchTable::new(
                &c.topology,
                &c.positions,
                &c.scheme,
                &Options::default(),
                &o,
            )
            .unwrap();
            for f in 0..c.topology.num_faces() {
                for sub in 0..subs(&c, f) {
                    for &(u, v) in &[(0.3, 0.2), (0.05, 0.61), (0.7, 0.15), (0.011, 0.013)] {
                        let at = FaceParam { face: f, sub, u, v };
                        let (a, _) = table.find(&at).unwrap();
                        regular += usize::from(table.arrays()[a].kind() != PatchType::Exact);
                        let mine = table.evaluate(at).unwrap();
                        let exact = eval.evaluate(&points, at).unwrap();
                        assert!(
                            (mine.position - exact.position).length() < 1e-12,
                            "{:?} {at:?}: {} vs {} in a {} patch",
                            c.scheme,
                            mine.position,
                            exact.position,
                            table.arrays()[a].kind()
                        );
                        assert!(
                            (mine.du - exact.du).length() < 1e-9
                                && (mine.dv - exact.dv).length() < 1e-9,
                            "{at:?}"
                        );
                    }
                }
            }
        }
        // The regular patches were compared too, not only the delegated end caps.
        assert!(regular > 0);
    }
}

#[test]
fn update_equals_a_rebuild() {
    for (c, caps) in cases()
        .into_iter()
        .flat_map(|c| ALL_CAPS.map(|e| (c.clone(), e)))
    {
        let o = options(3, caps, false);
        let mut table = PatchTable::new(
            &c.topology,
            &c.positions,
            &c.scheme,
            &Options::default(),
            &o,
        )
        .unwrap();
        let moved: Vec<DVec3> = c
            .positions
            .iter()
            .enumerate()
            .map(|(i, p)| *p * 1.5 + DVec3::new(0.1 * i as f64, 0.0, 0.2))
            .collect();
        table.update(&moved).unwrap();
        let rebuilt =
            PatchTable::new(&c.topology, &moved, &c.scheme, &Options::default(), &o).unwrap();
        assert_eq!(table.points(), rebuilt.points());
    }
}

#[test]
fn bad_requests_are_errors_naming_the_problem() {
    let c = cube();
    let o = PatchOptions {
        isolation: 11,
        ..Default::default()
    };
    let e = PatchTable::new(
        &c.topology,
        &c.positions,
        &c.scheme,
        &Options::default(),
        &o,
    )
    .unwrap_err();
    assert!(e.to_string().contains("isolation level 11"), "{e}");
    let o = PatchOptions::default();
    let e = PatchTable::new(
        &c.topology,
        &c.positions[..7],
        &c.scheme,
        &Options::default(),
        &o,
    )
    .unwrap_err();
    assert!(e.to_string().contains("7 positions"), "{e}");
    let e = PatchTable::new(
        &c.topology,
        &c.positions,
        &Scheme::Loop,
        &Options::default(),
        &o,
    )
    .unwrap_err();
    assert!(e.to_string().contains("triangles"), "{e}");
    let table = PatchTable::new(
        &c.topology,
        &c.positions,
        &c.scheme,
        &Options::default(),
        &PatchOptions { isolation: 2, ..o },
    )
    .unwrap();
    let e = table
        .evaluate(FaceParam {
            face: 6,
            sub: 0,
            u: 0.5,
            v: 0.5,
        })
        .unwrap_err();
    assert!(e.to_string().contains('6'), "{e}");
}

#[test]
fn local_points_factorised_to_the_base_vertices_are_the_local_points() {
    for c in cases() {
        let o = options(3, EndCaps::GregoryBasis, false);
        let table = PatchTable::new(
            &c.topology,
            &c.positions,
            &c.scheme,
            &Options::default(),
            &o,
        )
        .unwrap();
        let base = table.local_point_stencils_base();
        let local = base.apply_points(&c.positions);
        let refined: usize = table.level_vertex_counts().iter().sum();
        assert_eq!(local.len(), table.points().len() - refined);
        let scale = c.positions.iter().map(|p| p.length()).fold(1.0, f64::max);
        for (a, b) in local.iter().zip(&table.points()[refined..]) {
            assert!((*a - *b).length() <= 1e-13 * scale, "{a} vs {b}");
        }
    }
}

/// A gear (Loop): infinitely sharp creases along its rims and teeth.
fn gear() -> Case {
    let g = subd_mesh::primitives::gear(6, 4, 2);
    Case {
        topology: g.topology,
        positions: g.positions,
        scheme: Scheme::Loop,
    }
}

#[test]
fn tessellation_on_the_exact_table_is_the_evaluators() {
    use subd_limit::tessellation::{tessellate, tessellate_mesh};
    let mut all = cases();
    all.push(gear());
    for c in all {
        let o = Options::default();
        let ev = LimitEvaluator::new(&c.topology, &c.scheme, &o).unwrap();
        let pts = ev.prepare(&c.positions);
        let scale = c.positions.iter().map(|p| p.length()).fold(1.0, f64::max);
        for rate in [1, 2, 4, 6, 8] {
            // The evaluator's path, sample by sample; the table's, patch by patch.
            let a = tessellate(&ev, &pts, rate);
            let b = tessellate_mesh(&c.topology, &c.scheme, &o, &c.positions, rate);
            let (Ok(a), Ok(b)) = (&a, &b) else {
                // An odd rate on a non-quad: refused by both, with the same message.
                assert_eq!(a.unwrap_err().to_string(), b.unwrap_err().to_string());
                continue;
            };
            assert_eq!(a.params, b.params);
            assert_eq!(a.face_vertices, b.face_vertices);
            for k in 0..a.positions.len() {
                let (dp, dn) = (
                    (a.positions[k] - b.positions[k]).length(),
                    (a.normals[k] - b.normals[k]).length(),
                );
                assert!(dp <= 1e-14 * scale, "rate {rate} sample {k}: {dp:e}");
                // The exact caps are evaluated on the table's level, the evaluator's on its
                // own: the same surface from other points, rounded otherwise. Where the
                // tangents are short (next to an extraordinary vertex) the unit normal's
                // rounding is a few times theirs, and where they are parallel (the twisted
                // cube folds over) the normal is rounding alone: not compared.
                let d = ev.evaluate(&pts, a.params[k]).unwrap();
                if d.du.cross(d.dv).length() > 1e-9 * scale * scale {
                    assert!(dn <= 1e-13, "rate {rate} sample {k} normal: {dn:e}");
                }
            }
        }
    }
}

/// Random values, one per face corner (every edge a seam): `components` numbers each.
fn seamed_channel(c: &Case, components: usize, seed: u64) -> FVarChannel {
    let n = c.topology.num_face_vertices();
    let mut state = seed;
    let values = (0..n * components)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        })
        .collect();
    FVarChannel::new(&c.topology, components, values, (0..n as u32).collect()).unwrap()
}

/// The bilinear (quads; a non-quad's sub-face runs corner, edge midpoint, centre, edge
/// midpoint) or linear (triangles) interpolation of a face's corner values: what mode
/// `all` refines to at every level.
fn linear_in_face(c: &Case, ch: &FVarChannel, at: FaceParam) -> Vec<f64> {
    let k = ch.components();
    let corners = ch.face_values(&c.topology, at.face);
    let n = corners.len();
    let corner = |j: usize| ch.value(corners[j % n] as usize).to_vec();
    let mix = |a: &[f64], b: &[f64], wa: f64, wb: f64| -> Vec<f64> {
        a.iter().zip(b).map(|(x, y)| wa * x + wb * y).collect()
    };
    let (u, v) = (at.u, at.v);
    if c.scheme == Scheme::Loop {
        let ab = mix(&corner(0), &corner(1), 1.0 - u - v, u);
        return mix(&ab, &corner(2), 1.0, v);
    }
    let [p00, p10, p11, p01] = if n == 4 {
        [0, 1, 2, 3].map(corner)
    } else {
        let s = at.sub;
        let centre: Vec<f64> = (0..k)
            .map(|i| (0..n).map(|j| corner(j)[i]).sum::<f64>() / n as f64)
            .collect();
        [
            corner(s),
            mix(&corner(s), &corner(s + 1), 0.5, 0.5),
            centre,
            mix(&corner(s + n - 1), &corner(s), 0.5, 0.5),
        ]
    };
    let bottom = mix(&p00, &p10, 1.0 - u, u);
    let top = mix(&p01, &p11, 1.0 - u, u);
    mix(&bottom, &top, 1.0 - v, v)
}

/// With every value refined linearly (mode `all`), each face-varying patch is the base
/// face's own bilinear or linear interpolation, at every depth and under every end cap.
#[test]
fn linear_face_varying_patches_are_the_faces_interpolation() {
    for (ci, c) in cases().iter().enumerate() {
        let ch = seamed_channel(c, 2, ci as u64 + 7);
        for isolation in [1u8, 3] {
            for caps in ALL_CAPS {
                let mut table = PatchTable::new(
                    &c.topology,
                    &c.positions,
                    &c.scheme,
                    &Options::default(),
                    &options(isolation, caps, false),
                )
                .unwrap();
                let channel = table
                    .add_face_varying(&ch, FVarLinearInterpolation::All)
                    .unwrap();
                for f in 0..c.topology.num_faces() {
                    for sub in 0..subs(c, f) {
                        for (u, v) in [(0.1, 0.2), (0.7, 0.05), (0.33, 0.6), (0.0, 0.0)] {
                            let at = FaceParam { face: f, sub, u, v };
                            let got = table.evaluate_face_varying(channel, at).unwrap();
                            let want = linear_in_face(c, &ch, at);
                            for (g, w) in got.value.iter().zip(&want) {
                                assert!(
                                    (g - w).abs() < 1e-14,
                                    "case {ci} face {f} sub {sub} at ({u}, {v}): {g} vs {w}"
                                );
                            }
                            // The derivatives: central differences of the closed form.
                            if u > 0.0 && v > 0.0 {
                                let h = 1e-6;
                                let d = |du: f64, dv: f64| {
                                    let a = FaceParam {
                                        u: u + du,
                                        v: v + dv,
                                        ..at
                                    };
                                    let b = FaceParam {
                                        u: u - du,
                                        v: v - dv,
                                        ..at
                                    };
                                    let (a, b) =
                                        (linear_in_face(c, &ch, a), linear_in_face(c, &ch, b));
                                    a.iter()
                                        .zip(&b)
                                        .map(|(x, y)| (x - y) / (2.0 * h))
                                        .collect::<Vec<_>>()
                                };
                                for (k, (du, dv)) in d(h, 0.0).iter().zip(d(0.0, h)).enumerate() {
                                    assert!(
                                        (got.du[k] - du).abs() < 1e-7,
                                        "case {ci} face {f}: du"
                                    );
                                    assert!(
                                        (got.dv[k] - dv).abs() < 1e-7,
                                        "case {ci} face {f}: dv"
                                    );
                                }
                            }
                        }
                    }
                }
            }
        }
    }
}

/// A channel without seams holding the positions, refined smoothly (mode `none`) on a
/// closed mesh without creases, is refined by the vertex rules: each regular patch's
/// face-varying values are its face's refined vertices, its control points at the face's
/// corners.
#[test]
fn smooth_face_varying_without_seams_follows_the_vertices() {
    for c in [cube(), pentagon(), octahedron()] {
        let positions: Vec<f64> = c.positions.iter().flat_map(|p| p.to_array()).collect();
        let indices = c.topology.all_face_vertices().to_vec();
        let ch = FVarChannel::new(&c.topology, 3, positions, indices).unwrap();
        let mut table = PatchTable::new(
            &c.topology,
            &c.positions,
            &c.scheme,
            &Options::default(),
            &options(4, EndCaps::GregoryBasis, false),
        )
        .unwrap();
        table
            .add_face_varying(&ch, FVarLinearInterpolation::None)
            .unwrap();
        let fvar = &table.face_varying()[0];
        let corners: &[usize] = if c.scheme == Scheme::Loop {
            &[4, 5, 8]
        } else {
            &[5, 6, 10, 9]
        };
        let mut checked = 0;
        for (a, array) in table.arrays().iter().enumerate() {
            if !matches!(array.kind(), PatchType::Regular | PatchType::Loop) {
                continue;
            }
            for i in 0..array.len() {
                let cps = array.patch_points(i);
                let values = fvar.patch_values(a, i);
                for (k, &corner) in corners.iter().enumerate() {
                    let p = table.points()[cps[corner] as usize];
                    let x = &fvar.values()[3 * values[k] as usize..3 * values[k] as usize + 3];
                    assert!(
                        (p - DVec3::from_slice(x)).length() < 1e-13,
                        "array {a} patch {i} corner {k}: {p} vs {x:?}"
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked > 100, "only {checked} corners checked");
    }
}

/// Face-varying requests that do not fit are errors, not panics.
#[test]
fn bad_face_varying_requests_are_errors() {
    let c = cube();
    let mut table = PatchTable::new(
        &c.topology,
        &c.positions,
        &c.scheme,
        &Options::default(),
        &PatchOptions::default(),
    )
    .unwrap();
    let at = FaceParam {
        face: 0,
        sub: 0,
        u: 0.5,
        v: 0.5,
    };
    assert!(table.evaluate_face_varying(0, at).is_err());
    let ch = seamed_channel(&c, 2, 1);
    let i = table
        .add_face_varying(&ch, FVarLinearInterpolation::CornersPlus1)
        .unwrap();
    assert!(table.update_face_varying(i, &[0.0; 3]).is_err());
    let moved: Vec<f64> = ch.values().iter().map(|x| x + 1.0).collect();
    let before = table.evaluate_face_varying(i, at).unwrap();
    table.update_face_varying(i, &moved).unwrap();
    let after = table.evaluate_face_varying(i, at).unwrap();
    // Refinement is affine: moving every value by one moves every refined value by one.
    for (b, a) in before.value.iter().zip(&after.value) {
        assert!((a - b - 1.0).abs() < 1e-14);
    }
    let bad = FaceParam { face: 9, ..at };
    assert!(table.evaluate_face_varying(i, bad).is_err());
}

/// `evaluate_basis` is OpenSubdiv's `EvaluateBasis`: its position weights sum to one and its
/// derivative weights to zero (a partition of unity), and the renderer's own sums of the
/// table's points with them are the table's evaluation (the tensor-product path for
/// regular patches, the patch sums elsewhere).
#[test]
fn basis_weights_are_a_partition_of_unity_that_gives_the_evaluation() {
    for c in cases() {
        let table = PatchTable::new(
            &c.topology,
            &c.positions,
            &c.scheme,
            &Options::default(),
            &options(3, EndCaps::GregoryBasis, true),
        )
        .unwrap();
        let mut checked = 0;
        for f in 0..c.topology.num_faces() {
            for sub in 0..subs(&c, f) {
                for (u, v) in [(0.15, 0.3), (0.6, 0.2), (0.45, 0.45)] {
                    let at = FaceParam { face: f, sub, u, v };
                    let Ok((a, i)) = table.find(&at) else {
                        continue;
                    };
                    let w = table.evaluate_basis(a, i, u, v).unwrap();
                    let cps = table.arrays()[a].patch_points(i);
                    let sum: f64 = w.rows[0].iter().sum();
                    assert!((sum - 1.0).abs() < 1e-13, "position weights sum to {sum}");
                    for row in &w.rows[1..] {
                        let s: f64 = row.iter().sum();
                        assert!(s.abs() < 1e-9, "derivative weights sum to {s}");
                    }
                    let weighted = |k: usize| -> DVec3 {
                        cps.iter()
                            .zip(&w.rows[k])
                            .map(|(&p, &x)| x * table.points()[p as usize])
                            .sum()
                    };
                    let first = table.evaluate_first(&[at]).unwrap()[0];
                    for (k, want) in first.iter().enumerate() {
                        assert!((weighted(k) - *want).length() < 1e-12, "row {k} at {at:?}");
                    }
                    checked += 1;
                }
            }
        }
        assert!(checked > 0);
    }
}

/// Many places (past the count from which they are taken face by face) in a scrambled
/// order: each value is the one a single place gets, bit for bit, in the caller's order,
/// and a bad place among them is the error, the first in the caller's order.
#[test]
fn many_places_are_each_places_own_value() {
    for c in [cube(), octahedron()] {
        let o = options(3, EndCaps::GregoryBasis, false);
        let table = PatchTable::new(
            &c.topology,
            &c.positions,
            &c.scheme,
            &Options::default(),
            &o,
        )
        .unwrap();
        let nf = c.topology.num_faces();
        let mut state = 7u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let at: Vec<FaceParam> = (0..40_000)
            .map(|_| {
                let face = ((next() * nf as f64) as usize).min(nf - 1);
                let (mut u, mut v) = (next(), next());
                if c.scheme == Scheme::Loop && u + v > 1.0 {
                    (u, v) = (1.0 - u, 1.0 - v);
                }
                FaceParam { face, sub: 0, u, v }
            })
            .collect();
        let many = table.evaluate_first(&at).unwrap();
        for (p, got) in at.iter().zip(&many).step_by(97) {
            assert_eq!(*got, table.evaluate_first(&[*p]).unwrap()[0], "{p:?}");
        }
        let mut bad = at.clone();
        bad[30_000].face = nf + 3;
        bad[20_000].u = 2.0;
        let e = table.evaluate_first(&bad).unwrap_err().to_string();
        assert!(
            e.contains("(2, "),
            "the first bad place in order is named: {e}"
        );
    }
}
