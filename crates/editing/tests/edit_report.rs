//! What an edit reports beside the positions: dependent constraints (redundant or
//! conflicting, against cases worked out by hand) and the surface's energy (against a closed
//! form and the assembled matrix).

use std::f64::consts::TAU;

use subd_editing::energy::{
    EnergyMatrix, EnergyOptions, surface_energy, surface_energy_before_after,
};
use subd_editing::{Axis, Constraint, Edit, Editor, Goal, Isoline, Location, Method};
use subd_limit::eval::{FaceParam, LimitEvaluator};
use subd_mesh::{DVec3, Mesh};
use subd_schemes::{Options, Scheme};

fn torus() -> Mesh {
    subd_mesh::primitives::torus(12, 8, 2.0, 0.5)
}

fn at(face: usize, u: f64, v: f64) -> Location {
    Location::Face(FaceParam { face, sub: 0, u, v })
}

fn up(z: f64) -> Goal {
    Goal::Displacement(DVec3::new(0.0, 0.0, z))
}

/// Least squares, the exact energy solve and the penalty form.
fn methods() -> [Method; 3] {
    let energy = |penalty| Method::Energy {
        penalty,
        region_rings: Some(2),
        energy: EnergyOptions::default(),
    };
    [Method::LeastSquares, energy(None), energy(Some(1e8))]
}

fn edit(mesh: &Mesh, cs: &[Constraint], method: Method) -> (Editor, Edit) {
    let ed = Editor::new(
        &mesh.topology,
        &mesh.positions,
        &Scheme::CatmullClark,
        &Options::default(),
        cs,
        method,
    )
    .unwrap();
    let e = ed.solve(cs).unwrap();
    (ed, e)
}

/// Each constraint's distance to its target on the edited surface, evaluated afresh.
fn misses(mesh: &Mesh, cs: &[Constraint], x: &[DVec3]) -> Vec<f64> {
    let ev =
        LimitEvaluator::new(&mesh.topology, &Scheme::CatmullClark, &Options::default()).unwrap();
    subd_editing::check::residuals(
        &ev,
        &mesh.topology,
        &Scheme::CatmullClark,
        cs,
        &mesh.positions,
        x,
    )
    .unwrap()
}

#[test]
fn two_targets_for_one_point_conflict_by_half_their_distance_times_root_two() {
    let m = torus();
    // Vertex 52 is across the torus from vertex 0: its stencil shares no vertex.
    let cs = [
        Constraint::Point {
            at: Location::Vertex(0),
            goal: up(0.2),
        },
        Constraint::Point {
            at: Location::Vertex(0),
            goal: up(0.4),
        },
        Constraint::Point {
            at: Location::Vertex(52),
            goal: up(0.1),
        },
    ];
    for method in methods() {
        let (ed, e) = edit(&m, &cs, method);
        assert!(ed.rank_deficient && ed.rank == 6, "{method:?}: {}", ed.rank);
        assert_eq!(e.dependencies.len(), 1, "{method:?}: {:?}", e.dependencies);
        let g = &e.dependencies[0];
        assert_eq!(g.constraints, [0, 1]);
        assert_eq!(g.dependent_rows, 3);
        assert!(!g.consistent);
        // The z rows ask 0.2 and 0.4 of one value: (−1, 1)/√2 · r is unmet.
        let hand = 0.2 / 2f64.sqrt();
        assert!((g.residual - hand).abs() < 1e-12, "{}", g.residual);
        if method == Method::LeastSquares || methods()[1] == method {
            // The compromise (0.3) misses each by 0.1: √(0.1² + 0.1²) over the two.
            let r = misses(&m, &cs, &e.positions);
            assert!((r[0].hypot(r[1]) - hand).abs() < 1e-9, "{r:?}");
            assert!(r[2] < 1e-9, "{r:?}");
        }
    }
}

#[test]
fn the_same_target_twice_is_redundant_not_conflicting() {
    let m = torus();
    let ev = LimitEvaluator::new(&m.topology, &Scheme::CatmullClark, &Options::default()).unwrap();
    let q = FaceParam {
        face: 3,
        sub: 0,
        u: 0.3,
        v: 0.6,
    };
    let now = ev.evaluate(&ev.prepare(&m.positions), q).unwrap().position;
    let point = Constraint::Point {
        at: Location::Face(q),
        goal: Goal::Position(now + DVec3::new(0.05, 0.0, 0.1)),
    };
    let cs = [point.clone(), point];
    for method in methods() {
        let (ed, e) = edit(&m, &cs, method);
        assert!(ed.rank_deficient && ed.rank == 3, "{method:?}: {}", ed.rank);
        assert_eq!(e.dependencies.len(), 1, "{method:?}");
        let g = &e.dependencies[0];
        assert_eq!(
            (g.constraints.as_slice(), g.dependent_rows),
            (&[0, 1][..], 3)
        );
        assert!(g.consistent && g.residual < 1e-14, "{method:?}: {g:?}");
        if method != methods()[2] {
            let r = misses(&m, &cs, &e.positions);
            assert!(r.iter().all(|&r| r < 1e-10), "{r:?}");
        }
    }
}

/// An iso-line starting at the corner (0, 0) of a regular face and a point there: the
/// curve's point at its first knot is `(c₀ + 4 c₁ + c₂) / 6` of its control points.
fn isoline_and_point(miss: f64) -> Vec<Constraint> {
    let goals: Vec<Goal> = [0.0, 0.1, 0.3, 0.2, 0.0].into_iter().map(up).collect();
    vec![
        Constraint::Isoline {
            line: Isoline {
                face: 20,
                along: Axis::U,
                at: 0.0,
                faces: 2,
            },
            goals,
        },
        Constraint::Point {
            at: at(20, 0.0, 0.0),
            goal: up((0.0 + 4.0 * 0.1 + 0.3) / 6.0 + miss),
        },
    ]
}

#[test]
fn a_point_on_an_isoline_agrees_or_conflicts_by_its_miss_over_root_one_and_a_half() {
    let m = torus();
    for method in methods() {
        let (ed, e) = edit(&m, &isoline_and_point(0.0), method);
        assert_eq!(ed.rank, 15, "{method:?}");
        assert_eq!(e.dependencies.len(), 1, "{method:?}");
        let g = &e.dependencies[0];
        assert_eq!(
            (g.constraints.as_slice(), g.dependent_rows),
            (&[0, 1][..], 3)
        );
        assert!(g.consistent && g.residual < 1e-12, "{method:?}: {g:?}");

        // The relation e_p − (e₀ + 4 e₁ + e₂)/6 has length √1.5: a miss δ leaves δ/√1.5.
        let (_, e) = edit(&m, &isoline_and_point(0.06), method);
        let g = &e.dependencies[0];
        assert!(!g.consistent, "{method:?}: {g:?}");
        assert!((g.residual - 0.06 / 1.5f64.sqrt()).abs() < 1e-10, "{g:?}");
    }
}

#[test]
fn independent_constraints_report_no_dependencies() {
    let m = torus();
    let cs = [
        Constraint::Point {
            at: Location::Vertex(0),
            goal: up(0.2),
        },
        Constraint::Point {
            at: at(40, 0.5, 0.5),
            goal: up(-0.1),
        },
        Constraint::Normal {
            at: at(40, 0.5, 0.5),
            normal: DVec3::new(0.2, 0.0, 1.0),
        },
    ];
    for method in methods() {
        let (ed, e) = edit(&m, &cs, method);
        assert!(!ed.rank_deficient && ed.rank == 8, "{method:?}");
        assert!(
            e.dependencies.is_empty(),
            "{method:?}: {:?}",
            e.dependencies
        );
    }
}

/// Control points `(cos 2πi/m, sin 2πi/m, cos 2πj/n)` on an m × n torus grid: every
/// coordinate a function of one grid direction, so the thin-plate energy is `∫ F''²` along
/// it. A uniform cubic B-spline's F'' is linear on each span between the second
/// differences `κ f_i` (κ = 2 cos ω − 2 for samples of cos/sin ωi), and
/// `∫₀¹ ((1−s) a + s b)² = (a² + ab + b²)/3`, so
/// `E = m n [κ_m² (2 + cos ω)/3 + κ_n² (2 + cos ψ)/6]` (ω = 2π/m, ψ = 2π/n).
#[test]
fn surface_energy_of_a_separable_torus_grid_has_its_closed_form() {
    let (m, n) = (12u32, 8u32);
    let mut mesh = subd_mesh::primitives::torus(m, n, 2.0, 0.5);
    let (w, p) = (TAU / m as f64, TAU / n as f64);
    for (k, x) in mesh.positions.iter_mut().enumerate() {
        let (i, j) = ((k as u32 / n) as f64, (k as u32 % n) as f64);
        *x = DVec3::new((w * i).cos(), (w * i).sin(), (p * j).cos());
    }
    let ev =
        LimitEvaluator::new(&mesh.topology, &Scheme::CatmullClark, &Options::default()).unwrap();
    let e = surface_energy(&ev, &mesh.positions, &EnergyOptions::default()).unwrap();
    let (km, kn) = (2.0 * w.cos() - 2.0, 2.0 * p.cos() - 2.0);
    let hand = (m * n) as f64 * (km * km * (2.0 + w.cos()) / 3.0 + kn * kn * (2.0 + p.cos()) / 6.0);
    assert!((e - hand).abs() < 1e-12 * hand, "{e} against {hand}");
}

#[test]
fn surface_energy_is_the_assembled_matrix_over_every_face() {
    // Hexagons give valence-3 and (refined) valence-6 corners: corner patches and pieces.
    let mesh = subd_mesh::primitives::torus_with_hexagons(12, 8, 4, 2.0, 0.5);
    let ev =
        LimitEvaluator::new(&mesh.topology, &Scheme::CatmullClark, &Options::default()).unwrap();
    for options in [
        EnergyOptions::default(),
        EnergyOptions {
            membrane: 0.3,
            ..EnergyOptions::default()
        },
    ] {
        let faces: Vec<usize> = (0..mesh.topology.num_faces()).collect();
        let q = EnergyMatrix::new(&ev, mesh.positions.len(), &faces, &options).unwrap();
        let want = q.energy(&mesh.positions);
        let e = surface_energy(&ev, &mesh.positions, &options).unwrap();
        assert!((e - want).abs() < 1e-12 * want, "{e} against {want}");
    }
}

#[test]
fn surface_energy_before_after_is_two_fresh_evaluations_bit_for_bit() {
    let mesh = subd_mesh::primitives::torus_with_hexagons(12, 8, 4, 2.0, 0.5);
    let ev =
        LimitEvaluator::new(&mesh.topology, &Scheme::CatmullClark, &Options::default()).unwrap();
    let options = EnergyOptions::default();
    // Vertex 0 is a hexagon's corner; 33 a regular vertex elsewhere.
    let mut after = mesh.positions.clone();
    after[0] += DVec3::new(0.0, 0.1, 0.2);
    after[33] += DVec3::new(-0.1, 0.0, 0.05);
    let (b, a) = surface_energy_before_after(&ev, &mesh.positions, &after, &options).unwrap();
    assert_eq!(b, surface_energy(&ev, &mesh.positions, &options).unwrap());
    assert_eq!(a, surface_energy(&ev, &after, &options).unwrap());
    assert!(a != b);
}
