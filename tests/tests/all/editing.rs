//! Constraint-based editing (Li et al. 2008) and constrained deformation (Sun et al. 2012 §3): the
//! claims of the seed and the invariants of the methods, checked by evaluating the edited
//! surface afresh with subd-limit.

use subd_editing::energy::{
    EnergyOptions, bicubic_thin_plate, corner_energy, corner_energy_pairs, gauss4,
};
use subd_editing::isoline::{bspline_point, current_control_points};
use subd_editing::{
    Axis, Constraint, DeformConstraint, Deformation, Editor, Goal, Isoline, Location, Method,
};
use subd_limit::eval::{FaceParam, LimitEvaluator};
use subd_mesh::{DVec3, Topology, TopologyBuilder};
use subd_schemes::{Options, Refinement, Scheme};

fn torus() -> subd_mesh::Mesh {
    subd_mesh::primitives::torus(24, 12, 2.0, 0.6)
}

fn energy_method(rings: Option<usize>) -> Method {
    Method::Energy {
        penalty: None,
        region_rings: rings,
        energy: EnergyOptions::default(),
    }
}

fn at(face: usize, u: f64, v: f64) -> Location {
    Location::Face(FaceParam { face, sub: 0, u, v })
}

/// A mixed set: points (vertex and face), a normal, an iso-line.
fn mixed(d: f64) -> Vec<Constraint> {
    vec![
        Constraint::Point {
            at: Location::Vertex(30),
            goal: Goal::Displacement(DVec3::new(0.0, 0.0, 0.3 * d)),
        },
        Constraint::Point {
            at: at(100, 0.3, 0.6),
            goal: Goal::Displacement(DVec3::new(0.1 * d, -0.05 * d, 0.2 * d)),
        },
        Constraint::Normal {
            at: at(180, 0.5, 0.5),
            normal: DVec3::new(0.2, 0.1, 1.0),
        },
        Constraint::Isoline {
            line: Isoline {
                face: 200,
                along: Axis::U,
                at: 0.5,
                faces: 3,
            },
            goals: (0..6)
                .map(|k| Goal::Displacement(DVec3::new(0.0, 0.0, 0.05 * d * k as f64)))
                .collect(),
        },
    ]
}

/// The worst violation of the constraints by positions `x` relative to `diag`, measured with
/// a fresh evaluator (points: distance; normals: |n · t| / |t|; iso-lines: control points).
fn violation(topo: &Topology, x0: &[DVec3], x: &[DVec3], cs: &[Constraint]) -> f64 {
    let ev = LimitEvaluator::new(topo, &Scheme::CatmullClark, &Options::default()).unwrap();
    let p0 = ev.prepare(x0);
    let p = ev.prepare(x);
    let diag = subd_pia::bbox_diagonal(x0);
    let param = |l: &Location| match l {
        Location::Face(p) => *p,
        Location::Vertex(v) => {
            let f = topo.vertex_faces(*v)[0] as usize;
            let c = topo.vertex_face_local_indices(*v)[0] as usize;
            let (u, w) = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)][c];
            FaceParam {
                face: f,
                sub: 0,
                u,
                v: w,
            }
        }
    };
    let mut worst = 0.0f64;
    for c in cs {
        match c {
            Constraint::Point { at, goal } => {
                let q = param(at);
                let now = ev.evaluate(&p, q).unwrap().position;
                let want = match goal {
                    Goal::Position(t) => *t,
                    Goal::Displacement(d) => ev.evaluate(&p0, q).unwrap().position + *d,
                };
                worst = worst.max((now - want).length() / diag);
            }
            Constraint::Normal { at, normal } => {
                let s = ev.evaluate(&p, param(at)).unwrap();
                let n = normal.normalize();
                worst = worst
                    .max(n.dot(s.du).abs() / s.du.length())
                    .max(n.dot(s.dv).abs() / s.dv.length());
            }
            Constraint::Isoline { line, goals } => {
                let before = current_control_points(&ev, topo, line, x0)
                    .unwrap()
                    .unwrap();
                let after = current_control_points(&ev, topo, line, x).unwrap().unwrap();
                for ((b, a), g) in before.iter().zip(&after).zip(goals) {
                    let want = match g {
                        Goal::Position(t) => *t,
                        Goal::Displacement(d) => *b + *d,
                    };
                    worst = worst.max((*a - want).length() / diag);
                }
            }
        }
    }
    worst
}

fn edit(m: &subd_mesh::Mesh, cs: &[Constraint], method: Method) -> (Editor, Vec<DVec3>) {
    let ed = Editor::new(
        &m.topology,
        &m.positions,
        &Scheme::CatmullClark,
        &Options::default(),
        cs,
        method,
    )
    .unwrap();
    let x = ed.solve(cs).unwrap().positions;
    (ed, x)
}

#[test]
fn constraints_are_met_by_both_methods() {
    let m = torus();
    let cs = mixed(1.0);
    for method in [
        Method::LeastSquares,
        energy_method(Some(3)),
        energy_method(None),
        Method::Energy {
            penalty: Some(1e8),
            region_rings: Some(3),
            energy: EnergyOptions::default(),
        },
    ] {
        let (ed, x) = edit(&m, &cs, method);
        assert!(!ed.rank_deficient);
        let v = violation(&m.topology, &m.positions, &x, &cs);
        let tol = if matches!(
            method,
            Method::Energy {
                penalty: Some(_),
                ..
            }
        ) {
            1e-5
        } else {
            1e-10
        };
        assert!(v < tol, "{method:?}: violation {v}");
    }
}

#[test]
fn normal_constraint_gives_the_target_normal() {
    let m = torus();
    let n = DVec3::new(0.3, -0.2, 1.0).normalize();
    let q = FaceParam {
        face: 40,
        sub: 0,
        u: 0.4,
        v: 0.7,
    };
    let cs = vec![Constraint::Normal {
        at: Location::Face(q),
        normal: n,
    }];
    for method in [Method::LeastSquares, energy_method(Some(2))] {
        let (_, x) = edit(&m, &cs, method);
        let ev =
            LimitEvaluator::new(&m.topology, &Scheme::CatmullClark, &Options::default()).unwrap();
        let got = ev.evaluate(&ev.prepare(&x), q).unwrap().normal();
        assert!((got.dot(n).abs() - 1.0).abs() < 1e-12, "{got} vs {n}");
    }
}

#[test]
fn isoline_on_a_regular_strip_equals_the_target_curve() {
    let m = torus();
    let line = Isoline {
        face: 50,
        along: Axis::V,
        at: 0.25,
        faces: 4,
    };
    let ev = LimitEvaluator::new(&m.topology, &Scheme::CatmullClark, &Options::default()).unwrap();
    let cp = current_control_points(&ev, &m.topology, &line, &m.positions)
        .unwrap()
        .unwrap();
    let target: Vec<DVec3> = cp
        .iter()
        .enumerate()
        .map(|(k, p)| *p * 1.1 + DVec3::new(0.0, 0.0, 0.02 * (k as f64).sin()))
        .collect();
    let cs = vec![Constraint::Isoline {
        line,
        goals: target.iter().map(|&p| Goal::Position(p)).collect(),
    }];
    let (_, x) = edit(&m, &cs, energy_method(Some(2)));
    let pts = ev.prepare(&x);
    let faces = subd_editing::isoline::strip(&m.topology, &line).unwrap();
    // The line on the edited surface, sampled densely, is the target B-spline.
    for (j, f) in faces.iter().enumerate() {
        for k in 0..=8 {
            let s = k as f64 / 8.0;
            let on = ev.evaluate(&pts, f.param(s)).unwrap().position;
            let want = bspline_point(&target, j as f64 + s);
            assert!(
                (on - want).length() < 1e-11,
                "face {j} s {s}: {on} vs {want}"
            );
        }
    }
}

#[test]
fn isoline_through_an_extraordinary_region_is_sampled() {
    // A cube refined once: every face has an extraordinary corner.
    let (topo, p) = cube();
    let r = Refinement::new(&topo, Scheme::CatmullClark, &Options::default(), 1).unwrap();
    let t1 = r.topology(1).clone();
    let p1 = r.refine_points(&p).pop().unwrap();
    let mesh = subd_mesh::Mesh {
        topology: t1,
        positions: p1,
        hints: Default::default(),
        fvar: Vec::new(),
    };
    let line = Isoline {
        face: 0,
        along: Axis::U,
        at: 0.5,
        faces: 4,
    };
    let goals: Vec<Goal> = (0..7)
        .map(|_| Goal::Displacement(DVec3::new(0.0, 0.0, 0.1)))
        .collect();
    let cs = vec![Constraint::Isoline { line, goals }];
    let (ed, x) = edit(&mesh, &cs, Method::LeastSquares);
    assert_eq!(
        ed.rows().rows.len(),
        3 * 4 * subd_editing::isoline::SAMPLES_PER_FACE
    );
    let ev =
        LimitEvaluator::new(&mesh.topology, &Scheme::CatmullClark, &Options::default()).unwrap();
    let (a, b) = (ev.prepare(&mesh.positions), ev.prepare(&x));
    for f in subd_editing::isoline::strip(&mesh.topology, &line).unwrap() {
        for s in [0.125, 0.375, 0.625, 0.875] {
            let d = ev.evaluate(&b, f.param(s)).unwrap().position
                - ev.evaluate(&a, f.param(s)).unwrap().position;
            assert!((d - DVec3::new(0.0, 0.0, 0.1)).length() < 1e-12);
        }
    }
}

#[test]
fn edits_are_reversible_commutative_and_additive() {
    let m = torus();
    for method in [Method::LeastSquares, energy_method(Some(3))] {
        let cs = mixed(1.0);
        let (_, x) = edit(&m, &cs, method);
        // Reversible: the inverse displacements on the edited mesh.
        let back: Vec<Constraint> = mixed(-1.0)
            .into_iter()
            .filter(|c| !matches!(c, Constraint::Normal { .. }))
            .collect();
        let fwd: Vec<Constraint> = cs
            .iter()
            .filter(|c| !matches!(c, Constraint::Normal { .. }))
            .cloned()
            .collect();
        let x1 = Editor::new(
            &m.topology,
            &m.positions,
            &Scheme::CatmullClark,
            &Options::default(),
            &fwd,
            method,
        )
        .unwrap()
        .solve(&fwd)
        .unwrap()
        .positions;
        let m1 = subd_mesh::Mesh {
            topology: m.topology.clone(),
            positions: x1,
            hints: Default::default(),
            fvar: Vec::new(),
        };
        let (_, x2) = edit(&m1, &back, method);
        for (a, b) in x2.iter().zip(&m.positions) {
            assert!(
                (*a - *b).length() < 1e-12,
                "{method:?}: not reversed: {a} vs {b}"
            );
        }
        // Additive: two half steps (the second from the first's result) give the whole.
        let half = mixed(0.5);
        let (_, h1) = edit(&m, &half, method);
        let m_h = subd_mesh::Mesh {
            topology: m.topology.clone(),
            positions: h1,
            hints: Default::default(),
            fvar: Vec::new(),
        };
        let (_, h2) = edit(&m_h, &half, method);
        for (a, b) in h2.iter().zip(&x) {
            assert!((*a - *b).length() < 1e-12, "{method:?}: not additive");
        }
        // Commutative: the constraints in another order.
        let mut rev = cs.clone();
        rev.reverse();
        let (_, xr) = edit(&m, &rev, method);
        for (a, b) in xr.iter().zip(&x) {
            assert!((*a - *b).length() < 1e-12, "{method:?}: order matters");
        }
    }
}

#[test]
fn least_squares_moves_only_the_support() {
    let m = torus();
    let cs = mixed(1.0);
    let (ed, x) = edit(&m, &cs, Method::LeastSquares);
    let support = ed.rows().support();
    for (v, (a, b)) in x.iter().zip(&m.positions).enumerate() {
        if support.binary_search(&(v as u32)).is_err() {
            assert_eq!(a, b, "vertex {v} outside the support moved");
        }
    }
    // And the energy method moves nothing outside its region.
    let (ed, x) = edit(&m, &cs, energy_method(Some(1)));
    let free = ed.free_vertices();
    for (v, (a, b)) in x.iter().zip(&m.positions).enumerate() {
        if free.binary_search(&(v as u32)).is_err() {
            assert_eq!(a, b, "vertex {v} outside the region moved");
        }
    }
}

#[test]
fn energy_method_is_fairer_than_least_squares() {
    let m = torus();
    let cs = mixed(1.0);
    let (_, x_ls) = edit(&m, &cs, Method::LeastSquares);
    let (ed, x_en) = edit(&m, &cs, energy_method(Some(3)));
    let q = ed.energy.as_ref().unwrap();
    let d =
        |x: &[DVec3]| -> Vec<DVec3> { x.iter().zip(&m.positions).map(|(a, b)| *a - *b).collect() };
    let (e_ls, e_en) = (q.energy(&d(&x_ls)), q.energy(&d(&x_en)));
    assert!(e_en < 0.5 * e_ls, "energy {e_en} vs least squares {e_ls}");
    // The penalty form approaches the exact solution as λ grows.
    let pen = |lambda: f64| {
        edit(
            &m,
            &cs,
            Method::Energy {
                penalty: Some(lambda),
                region_rings: Some(3),
                energy: EnergyOptions::default(),
            },
        )
        .1
    };
    let gap = |x: &[DVec3]| {
        x.iter()
            .zip(&x_en)
            .map(|(a, b)| (*a - *b).length())
            .fold(0.0, f64::max)
    };
    let (g4, g8) = (gap(&pen(1e4)), gap(&pen(1e8)));
    assert!(g8 < g4 && g8 < 1e-5, "penalty gaps {g4} {g8}");
}

#[test]
fn without_a_region_one_point_translates_the_surface() {
    // The seed's "global deformation": with every vertex free, a point constraint is met
    // by a rigid translation at zero energy.
    let m = torus();
    let d = DVec3::new(0.1, 0.2, -0.3);
    let cs = vec![Constraint::Point {
        at: at(7, 0.5, 0.5),
        goal: Goal::Displacement(d),
    }];
    let (_, x) = edit(&m, &cs, energy_method(None));
    // A rigid translation, to the 1e-10 regularisation of Q.
    for (a, b) in x.iter().zip(&m.positions) {
        assert!(
            (*a - *b - d).length() < 1e-7,
            "{} not a translation",
            *a - *b
        );
    }
}

#[test]
fn conflicting_constraints_give_the_least_squares_solution() {
    let m = torus();
    let p = at(10, 0.5, 0.5);
    let cs = vec![
        Constraint::Point {
            at: p,
            goal: Goal::Displacement(DVec3::new(0.0, 0.0, 0.2)),
        },
        Constraint::Point {
            at: p,
            goal: Goal::Displacement(DVec3::new(0.0, 0.0, 0.4)),
        },
    ];
    for method in [Method::LeastSquares, energy_method(Some(2))] {
        let (ed, x) = edit(&m, &cs, method);
        assert!(
            ed.rank_deficient && ed.rank == 3,
            "{method:?}: rank {}",
            ed.rank
        );
        let ev =
            LimitEvaluator::new(&m.topology, &Scheme::CatmullClark, &Options::default()).unwrap();
        let Location::Face(q) = p else { unreachable!() };
        let moved = ev.evaluate(&ev.prepare(&x), q).unwrap().position
            - ev.evaluate(&ev.prepare(&m.positions), q).unwrap().position;
        // The average of the two requests.
        assert!(
            (moved - DVec3::new(0.0, 0.0, 0.3)).length() < 1e-9,
            "{method:?}: {moved}"
        );
    }
}

#[test]
fn editor_resolves_new_targets_like_a_fresh_solve() {
    let m = torus();
    let cs = mixed(1.0);
    let ed = Editor::new(
        &m.topology,
        &m.positions,
        &Scheme::CatmullClark,
        &Options::default(),
        &cs,
        energy_method(Some(3)),
    )
    .unwrap();
    let cs2 = mixed(2.5);
    let again = ed.solve(&cs2).unwrap().positions;
    let (_, fresh) = edit(&m, &cs2, energy_method(Some(3)));
    for (a, b) in again.iter().zip(&fresh) {
        assert!((*a - *b).length() < 1e-12);
    }
    // A moved location is refused.
    let mut other = cs.clone();
    other[1] = Constraint::Point {
        at: at(101, 0.3, 0.6),
        goal: Goal::Displacement(DVec3::ZERO),
    };
    assert!(ed.solve(&other).is_err());
}

#[test]
fn bad_constraints_are_named() {
    let m = torus();
    let cases = [
        (
            Constraint::Point {
                at: Location::Vertex(1 << 20),
                goal: Goal::Position(DVec3::ZERO),
            },
            "out of range",
        ),
        (
            Constraint::Point {
                at: at(0, 1.5, 0.5),
                goal: Goal::Position(DVec3::ZERO),
            },
            "outside",
        ),
        (
            Constraint::Point {
                at: at(0, f64::NAN, 0.5),
                goal: Goal::Position(DVec3::ZERO),
            },
            "not finite",
        ),
        (
            Constraint::Normal {
                at: at(0, 0.5, 0.5),
                normal: DVec3::ZERO,
            },
            "zero",
        ),
        (
            Constraint::Point {
                at: at(0, 0.5, 0.5),
                goal: Goal::Position(DVec3::new(f64::INFINITY, 0.0, 0.0)),
            },
            "not finite",
        ),
    ];
    for (c, what) in cases {
        let cs = vec![
            Constraint::Point {
                at: at(1, 0.5, 0.5),
                goal: Goal::Position(DVec3::ZERO),
            },
            c,
        ];
        let e = Editor::new(
            &m.topology,
            &m.positions,
            &Scheme::CatmullClark,
            &Options::default(),
            &cs,
            Method::LeastSquares,
        )
        .unwrap_err()
        .to_string();
        assert!(e.starts_with("constraint 1:") && e.contains(what), "{e}");
    }
}

#[test]
fn least_squares_edits_loop_surfaces_too() {
    let m = subd_mesh::primitives::torus(12, 8, 2.0, 0.5);
    let tri = triangulate(&m);
    let cs = vec![Constraint::Point {
        at: Location::Face(FaceParam {
            face: 9,
            sub: 0,
            u: 0.2,
            v: 0.3,
        }),
        goal: Goal::Displacement(DVec3::new(0.0, 0.1, 0.0)),
    }];
    let ed = Editor::new(
        &tri.topology,
        &tri.positions,
        &Scheme::Loop,
        &Options::default(),
        &cs,
        Method::LeastSquares,
    )
    .unwrap();
    let x = ed.solve(&cs).unwrap().positions;
    let ev = LimitEvaluator::new(&tri.topology, &Scheme::Loop, &Options::default()).unwrap();
    let q = FaceParam {
        face: 9,
        sub: 0,
        u: 0.2,
        v: 0.3,
    };
    let d = ev.evaluate(&ev.prepare(&x), q).unwrap().position
        - ev.evaluate(&ev.prepare(&tri.positions), q)
            .unwrap()
            .position;
    assert!((d - DVec3::new(0.0, 0.1, 0.0)).length() < 1e-12);
    let energy = Editor::new(
        &tri.topology,
        &tri.positions,
        &Scheme::Loop,
        &Options::default(),
        &cs,
        energy_method(Some(2)),
    );
    assert!(energy.is_err());
}

#[test]
fn constraints_at_boundaries_creases_and_extraordinary_vertices_are_met() {
    let mut checked = 0;
    for shape in subd_tests::surface_shapes().into_iter().filter(|s| {
        s.scheme == Scheme::CatmullClark
            && [
                "catmark_cube_creases1",
                "catmark_fvar_bound0",
                "catmark_pyramid",
                "catmark_dart_edgecorner",
                "catmark_helmet",
                "catmark_square_hedit0",
            ]
            .contains(&s.name.as_str())
    }) {
        let topo = &shape.mesh.topology;
        let p = &shape.mesh.positions;
        let diag = subd_pia::bbox_diagonal(p);
        let ev = LimitEvaluator::new(topo, &Scheme::CatmullClark, &shape.options).unwrap();
        let cs: Vec<Constraint> = [0usize, topo.num_vertices() / 2]
            .into_iter()
            .map(|v| Constraint::Point {
                at: Location::Vertex(v),
                goal: Goal::Displacement(DVec3::new(0.0, 0.01 * diag, 0.0)),
            })
            .chain([Constraint::Point {
                at: at(topo.num_faces() - 1, 0.01, 0.02),
                goal: Goal::Displacement(DVec3::new(0.02 * diag, 0.0, 0.0)),
            }])
            .collect();
        for method in [Method::LeastSquares, energy_method(Some(2))] {
            let ed =
                Editor::new(topo, p, &Scheme::CatmullClark, &shape.options, &cs, method).unwrap();
            if ed.rank_deficient {
                // Constraints too close together on a tiny mesh: least squares, not exact.
                continue;
            }
            checked += 1;
            let x = ed.solve(&cs).unwrap().positions;
            let (a, b) = (ev.prepare(p), ev.prepare(&x));
            for (c, r) in cs.iter().zip(ed.rows().rows.chunks(3)) {
                let Constraint::Point {
                    goal: Goal::Displacement(d),
                    ..
                } = c
                else {
                    unreachable!()
                };
                let moved = DVec3::new(
                    r[0].value(&x) - r[0].value(p),
                    r[1].value(&x) - r[1].value(p),
                    r[2].value(&x) - r[2].value(p),
                );
                assert!(
                    (moved - *d).length() < 1e-10 * diag,
                    "{}: {moved} vs {d}",
                    shape.name
                );
            }
            // Independently: the face point by the evaluator.
            let q = FaceParam {
                face: topo.num_faces() - 1,
                sub: 0,
                u: 0.01,
                v: 0.02,
            };
            if topo.face_size(q.face) == 4 {
                let d = ev.evaluate(&b, q).unwrap().position - ev.evaluate(&a, q).unwrap().position;
                assert!(
                    (d - DVec3::new(0.02 * diag, 0.0, 0.0)).length() < 1e-10 * diag,
                    "{}",
                    shape.name
                );
            }
        }
    }
    assert!(checked >= 8, "only {checked} edits checked");
}

#[test]
fn mirror_extension_reproduces_the_boundary_rules() {
    // Li et al. 2008 §2.2: a boundary face of an open grid is the B-spline over its 3 × 4 grid
    // extended by mirrored points v' = 2 v_i − v_j (a corner face by 4v₃ − 2v₂ − 2v₆ + v₉ at
    // its corner), which must be subd-limit's boundary evaluation (edge-only boundaries
    // away from corners, edge-and-corner at corners).
    let n = 5usize;
    let mut faces = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let v = (j * n + i) as u32;
            faces.extend([v, v + 1, v + 1 + n as u32, v + n as u32]);
        }
    }
    let topo = TopologyBuilder::new(n * n)
        .build(&vec![4; (n - 1) * (n - 1)], &faces)
        .unwrap();
    let p: Vec<DVec3> = (0..n * n)
        .map(|k| {
            let (i, j) = ((k % n) as f64, (k / n) as f64);
            DVec3::new(
                i + 0.1 * (j * 1.3).sin(),
                j + 0.2 * (i * 0.7).cos(),
                0.3 * (i * j * 0.4).sin(),
            )
        })
        .collect();
    let grid_point = |i: isize, j: isize| -> DVec3 {
        // Mirror across the boundary rows/columns (index −1 and n).
        let m = |k: isize| -> (usize, Option<usize>) {
            if k < 0 {
                (0, Some(1))
            } else if k >= n as isize {
                (n - 1, Some(n - 2))
            } else {
                (k as usize, None)
            }
        };
        let ((i0, i1), (j0, j1)) = (m(i), m(j));
        let at = |a: usize, b: usize| p[b * n + a];
        match (i1, j1) {
            (None, None) => at(i0, j0),
            (Some(i1), None) => 2.0 * at(i0, j0) - at(i1, j0),
            (None, Some(j1)) => 2.0 * at(i0, j0) - at(i0, j1),
            (Some(i1), Some(j1)) => {
                4.0 * at(i0, j0) - 2.0 * at(i1, j0) - 2.0 * at(i0, j1) + at(i1, j1)
            }
        }
    };
    for (boundary, faces_to_check) in [
        (subd_mesh::BoundaryInterpolation::EdgeOnly, vec![1usize, 2]),
        (
            subd_mesh::BoundaryInterpolation::EdgeAndCorner,
            vec![0usize, 1],
        ),
    ] {
        let opts = Options {
            boundary_interpolation: boundary,
            ..Options::default()
        };
        let ev = LimitEvaluator::new(&topo, &Scheme::CatmullClark, &opts).unwrap();
        let pts = ev.prepare(&p);
        for f in faces_to_check {
            let (fi, fj) = ((f % (n - 1)) as isize, (f / (n - 1)) as isize);
            let grid: [DVec3; 16] = std::array::from_fn(|k| {
                grid_point(fi - 1 + (k % 4) as isize, fj - 1 + (k / 4) as isize)
            });
            for (u, v) in [(0.5, 0.5), (0.1, 0.9), (0.0, 0.3), (0.7, 0.0)] {
                let mirrored = subd_limit::patch::eval_bicubic(&grid, u, v).position;
                let ours = ev
                    .evaluate(
                        &pts,
                        FaceParam {
                            face: f,
                            sub: 0,
                            u,
                            v,
                        },
                    )
                    .unwrap()
                    .position;
                assert!(
                    (mirrored - ours).length() < 1e-13,
                    "{boundary:?} face {f} ({u}, {v}): {mirrored} vs {ours}"
                );
            }
        }
    }
}

#[test]
fn bicubic_energy_matches_quadrature() {
    // Q₀ against a composite midpoint rule on a 200 × 200 grid of the patch's own
    // second derivatives.
    let q0 = bicubic_thin_plate();
    let grid: [DVec3; 16] = std::array::from_fn(|k| {
        let x = k as f64;
        DVec3::new((x * 0.7).sin(), (x * 1.3).cos(), (x * x * 0.1).sin())
    });
    let closed: f64 = (0..3)
        .map(|c| {
            (0..16)
                .map(|a| {
                    (0..16)
                        .map(|b| grid[a][c] * q0[a][b] * grid[b][c])
                        .sum::<f64>()
                })
                .sum::<f64>()
        })
        .sum();
    let k = 200;
    let mut numeric = 0.0;
    for i in 0..k {
        for j in 0..k {
            let s = subd_limit::patch::eval_bicubic(
                &grid,
                (i as f64 + 0.5) / k as f64,
                (j as f64 + 0.5) / k as f64,
            );
            numeric +=
                (s.duu.length_squared() + 2.0 * s.duv.length_squared() + s.dvv.length_squared())
                    / (k * k) as f64;
        }
    }
    assert!(
        (closed - numeric).abs() < 1e-5 * closed,
        "{closed} vs {numeric}"
    );
}

fn cube() -> (Topology, Vec<DVec3>) {
    let faces = [
        0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4,
    ];
    let topo = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
    let s = [
        (-1., -1., 1.),
        (1., -1., 1.),
        (-1., 1., 1.),
        (1., 1., 1.),
        (-1., 1., -1.),
        (1., 1., -1.),
        (-1., -1., -1.),
        (1., -1., -1.),
    ];
    (
        topo,
        s.iter().map(|&(x, y, z)| DVec3::new(x, y, z)).collect(),
    )
}

/// A disk of quads around one vertex of valence `n`: an n-gon refined three times (the
/// centre keeps valence n, every other interior vertex has 4), jittered.
fn valence_disk(n: usize) -> subd_mesh::Mesh {
    let faces: Vec<u32> = (0..n as u32).collect();
    let topo = TopologyBuilder::new(n).build(&[n as u32], &faces).unwrap();
    let p: Vec<DVec3> = (0..n)
        .map(|k| {
            let a = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
            DVec3::new(a.cos(), a.sin(), 0.2 * (3.0 * a).sin())
        })
        .collect();
    let r = Refinement::new(&topo, Scheme::CatmullClark, &Options::default(), 3).unwrap();
    let mut pts = r.refine_points(&p).pop().unwrap();
    for (k, q) in pts.iter_mut().enumerate() {
        let x = k as f64;
        *q += 0.02 * DVec3::new((x * 1.7).sin(), (x * 0.9).cos(), (x * 2.3).sin());
    }
    subd_mesh::Mesh {
        topology: r.topology(3).clone(),
        positions: pts,
        hints: Default::default(),
        fvar: Vec::new(),
    }
}

/// The energy of the face at the centre of [`valence_disk`] by the corner series summed over
/// `rings` rings, against Gauss quadrature (exact on B-spline faces) over the faces of
/// uniform level `rings` inside it, all but the one at the centre.
fn corner_check(n: usize, rings: usize) {
    let b = valence_disk(n);
    let topo = &b.topology;
    let centre = (0..topo.num_vertices())
        .find(|&v| topo.vertex_faces(v).len() == n && !topo.is_boundary_vertex(v))
        .unwrap();
    let face = topo.vertex_faces(centre)[0] as usize;
    let ev = LimitEvaluator::new(topo, &Scheme::CatmullClark, &Options::default()).unwrap();
    let patches = ev.face_patches(face).unwrap();
    let subd_limit::PatchForm::Corner(m) = &patches[0].form else {
        panic!("not a corner patch")
    };
    let ctrl: Vec<DVec3> = patches[0]
        .controls
        .iter()
        .map(|r| r.iter().map(|&(v, w)| w * b.positions[v as usize]).sum())
        .collect();
    let h = subd_editing::energy::CornerEnergy::partial(m, Some(rings)).thin_plate;
    let series: f64 = (0..3)
        .map(|c| {
            (0..ctrl.len())
                .map(|i| {
                    (0..ctrl.len())
                        .map(|j| ctrl[i][c] * h[(i, j)] * ctrl[j][c])
                        .sum::<f64>()
                })
                .sum::<f64>()
        })
        .sum();
    let r = Refinement::new(topo, Scheme::CatmullClark, &Options::default(), rings).unwrap();
    let pts = r.refine_points(&b.positions).pop().unwrap();
    let tl = r.topology(rings);
    let ev_l = LimitEvaluator::new(tl, &Scheme::CatmullClark, &Options::default()).unwrap();
    let mut desc = vec![face];
    for l in 0..rings {
        let t = r.topology(l);
        desc = desc
            .iter()
            .flat_map(|&f| t.face_offsets()[f] as usize..t.face_offsets()[f + 1] as usize)
            .collect();
    }
    let prep = ev_l.prepare(&pts);
    let g = gauss4();
    let mut deep = 0.0;
    for &f in &desc {
        if tl.face_vertices(f).contains(&(centre as u32)) {
            continue; // the corner square
        }
        for &(x, wx) in &g {
            for &(y, wy) in &g {
                let s = ev_l
                    .evaluate(
                        &prep,
                        FaceParam {
                            face: f,
                            sub: 0,
                            u: x,
                            v: y,
                        },
                    )
                    .unwrap();
                deep += wx
                    * wy
                    * (s.duu.length_squared()
                        + 2.0 * s.duv.length_squared()
                        + s.dvv.length_squared());
            }
        }
    }
    // Level-l faces have parameters 2^l times the base face's: energy × 4^l.
    deep *= 4f64.powi(rings as i32);
    assert!(
        (deep - series).abs() < 1e-9 * series,
        "n = {n}, {rings} rings: {deep} vs {series}"
    );
    if n == 3 {
        // The whole series converges, from above the partial sums.
        let full = corner_energy(3, 8).unwrap();
        assert!(full.truncated_at.is_none());
        let whole: f64 = (0..3)
            .map(|c| {
                (0..ctrl.len())
                    .map(|i| {
                        (0..ctrl.len())
                            .map(|j| ctrl[i][c] * full.thin_plate[(i, j)] * ctrl[j][c])
                            .sum::<f64>()
                    })
                    .sum::<f64>()
            })
            .sum();
        assert!(
            whole >= series && whole < 1.5 * series,
            "{whole} vs {series}"
        );
    }
}

#[test]
fn corner_energy_matches_deep_refinement() {
    corner_check(3, 4);
    corner_check(5, 4);
    corner_check(6, 3);
}

#[test]
fn divergent_pairs_are_the_subdominant_ones() {
    for n in [5usize, 6, 8] {
        let pairs = corner_energy_pairs(n).unwrap();
        let divergent: Vec<_> = pairs.iter().filter(|p| 4.0 * p.0 * p.1 >= 1.0).collect();
        assert!(!divergent.is_empty(), "n = {n}");
        let sub = subd_limit::stam::corner_patch_matrices(n)
            .unwrap()
            .eigenvalues()[1]
            .re;
        // Every divergent pair that carries energy involves the subdominant eigenvalue, and
        // the subdominant pair itself is among them.
        for p in &divergent {
            assert!(
                (p.0 - sub).abs() < 1e-9 || (p.1 - sub).abs() < 1e-9,
                "n = {n}: pair {p:?}, subdominant {sub}"
            );
        }
        assert!(
            divergent
                .iter()
                .any(|p| (p.0 - sub).abs() < 1e-9 && (p.1 - sub).abs() < 1e-9)
        );
        assert!((sub - subd_editing::energy::subdominant(n)).abs() < 1e-12);
        assert!(corner_energy(n, 8).unwrap().truncated_at.is_some());
    }
    assert!(corner_energy(3, 8).unwrap().truncated_at.is_none());
}

#[test]
fn deformation_moves_constraint_points_exactly_and_nothing_outside() {
    let m = torus();
    let cs = [
        DeformConstraint {
            center: m.positions[10],
            radius: 0.8,
            displacement: DVec3::new(0.0, 0.0, 0.4),
        },
        DeformConstraint {
            center: m.positions[13],
            radius: 0.6,
            displacement: DVec3::new(0.1, 0.0, -0.2),
        },
    ];
    let d = Deformation::new(&cs).unwrap();
    let mut x = m.positions.clone();
    d.apply(&mut x);
    assert_eq!(x[10], m.positions[10] + cs[0].displacement);
    assert_eq!(x[13], m.positions[13] + cs[1].displacement);
    // At a constraint point computed through the blend sum (not the exact branch).
    for c in &cs {
        assert!((d.displacement(c.center) - c.displacement).length() < 1e-12);
    }
    let mut moved = 0;
    for (a, b) in x.iter().zip(&m.positions) {
        let inside = cs.iter().any(|c| (*b - c.center).length() < c.radius);
        if inside {
            moved += 1;
        } else {
            assert_eq!(
                a.to_array().map(f64::to_bits),
                b.to_array().map(f64::to_bits)
            );
        }
    }
    assert!(moved > 2);
    // Continuity: the blend and its first two derivatives vanish at the radius.
    let h = 1e-4;
    let b = subd_editing::deform::blend;
    assert!(b(1.0 - h) < 1e-14 && b(1.0) == 0.0);
    assert!((b(1.0 - h) - 2.0 * b(1.0 - 2.0 * h) + b(1.0 - 3.0 * h)).abs() / (h * h) < 1e-5);
    // Coinciding centres are refused.
    assert!(Deformation::new(&[cs[0], cs[0]]).is_err());
}

#[test]
fn deformation_applies_to_an_adaptive_mesh_and_refinement_continues() {
    let m = torus();
    let sel =
        subd_adaptive::FaceSelection::from_faces(m.topology.num_faces(), &[0, 1, 2, 3]).unwrap();
    let ar = subd_adaptive::AdaptiveRefinement::new(
        &m.topology,
        &m.positions,
        &Scheme::CatmullClark,
        &Options::default(),
        &[&sel],
        2,
    )
    .unwrap();
    let am = ar.mesh(subd_adaptive::Positions::Refined).unwrap();
    let mut pts = am.positions.clone();
    let c = DeformConstraint {
        center: pts[0],
        radius: 0.5,
        displacement: DVec3::new(0.0, 0.0, 0.1),
    };
    Deformation::new(&[c]).unwrap().apply(&mut pts);
    assert_eq!(pts[0], am.positions[0] + c.displacement);
    // Refinement continues from the deformed adaptive mesh.
    let sizes: Vec<u32> = am.face_offsets.windows(2).map(|w| w[1] - w[0]).collect();
    let t = TopologyBuilder::new(pts.len())
        .build(&sizes, &am.face_vertices)
        .unwrap();
    let r = Refinement::new(&t, Scheme::CatmullClark, &Options::default(), 1).unwrap();
    assert_eq!(r.refine_points(&pts).len(), 2);
}

fn triangulate(m: &subd_mesh::Mesh) -> subd_mesh::Mesh {
    let mut faces = Vec::new();
    for f in 0..m.topology.num_faces() {
        let v = m.topology.face_vertices(f);
        faces.extend([v[0], v[1], v[2], v[0], v[2], v[3]]);
    }
    let topology = TopologyBuilder::new(m.positions.len())
        .build(&vec![3; faces.len() / 3], &faces)
        .unwrap();
    subd_mesh::Mesh {
        topology,
        positions: m.positions.clone(),
        hints: Default::default(),
        fvar: Vec::new(),
    }
}
