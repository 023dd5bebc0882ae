//! Progressive interpolation: the claims of Lin et al. (two-phase scheme, local PIA) and of
//! the Catmull-Clark and Loop PIA papers, on OpenSubdiv's shapes and synthetic meshes.
//!
//! Every check compares with something computed another way: formula (2) in closed form,
//! Theorem 2 with dense linear algebra, limits of the result from a fresh limit table.

use faer::Mat;
use glam::DVec3;
use subd_mesh::Topology;
use subd_pia::{Method, Moving, Pia, PiaOptions, Solver, bbox_diagonal};
use subd_schemes::{Options, Scheme, TwoPhase, two_phase};
use subd_tests::osd_meshes;

/// The λ grid over (7/20, 1].
const LAMBDAS: [f64; 8] = [0.351, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0];

struct Shape {
    name: String,
    topology: Topology,
    points: Vec<DVec3>,
    options: Options,
}

fn load(path: &std::path::Path) -> Shape {
    let f = subd_io::read_mesh(
        path,
        &subd_io::ReadOptions {
            accept_inconsistent_orientation: true,
            ..Default::default()
        },
    )
    .expect("readable shape");
    Shape {
        name: path.file_stem().unwrap().to_string_lossy().into_owned(),
        options: Options::from_hints(&f.mesh.hints),
        topology: f.mesh.topology,
        points: f.mesh.positions,
    }
}

fn untagged(t: &Topology) -> bool {
    (0..t.num_edges()).all(|e| t.edge_sharpness(e) == 0.0)
        && (0..t.num_vertices()).all(|v| t.vertex_sharpness(v) == 0.0)
        && (0..t.num_faces()).all(|f| !t.is_hole(f))
}

fn manifold(t: &Topology) -> bool {
    (0..t.num_edges()).all(|e| !t.is_non_manifold_edge(e))
        && (0..t.num_vertices()).all(|v| !t.is_non_manifold_vertex(v) && !t.is_isolated_vertex(v))
}

fn closed(t: &Topology) -> bool {
    (0..t.num_edges()).all(|e| !t.is_boundary_edge(e))
}

/// OpenSubdiv shapes of `prefix` that pass `keep`, up to `max_vertices` vertices.
fn shapes(prefix: &str, max_vertices: usize, keep: impl Fn(&Topology) -> bool) -> Vec<Shape> {
    osd_meshes()
        .iter()
        .filter(|p| p.file_name().unwrap().to_string_lossy().starts_with(prefix))
        .map(|p| load(p))
        .filter(|s| s.topology.num_vertices() <= max_vertices && keep(&s.topology))
        .collect()
}

fn all_quads(t: &Topology) -> bool {
    (0..t.num_faces()).all(|f| t.face_size(f) == 4)
}

/// Closed, untagged, manifold all-quad shapes (the paper's setting), plus the refined
/// pentagonal prism for valence 5.
fn closed_quad_shapes() -> Vec<Shape> {
    let mut v = shapes("catmark_", 700, |t| {
        all_quads(t) && closed(t) && untagged(t) && manifold(t)
    });
    let (prism, points) = subd_tests::pentagonal_prism();
    let r = subd_schemes::Refinement::new(
        &prism,
        subd_schemes::Scheme::CatmullClark,
        &Options::default(),
        1,
    )
    .unwrap();
    let points = r.refine_points(&points).pop().unwrap();
    v.push(Shape {
        name: "pentagonal_prism_l1".into(),
        topology: r.into_topology(1),
        points,
        options: Options::default(),
    });
    assert!(v.len() >= 3, "closed quad shapes: {}", v.len());
    v
}

/// Open all-quad shapes (boundaries), and closed ones with creases and corners.
fn open_or_creased_quad_shapes() -> Vec<Shape> {
    let v = shapes("catmark_", 400, |t| {
        all_quads(t) && manifold(t) && (!closed(t) || !untagged(t))
    });
    assert!(v.len() >= 5, "open/creased quad shapes: {}", v.len());
    v
}

/// Deterministic pseudo-random numbers in [0, 1).
fn rand01(seed: u64) -> f64 {
    let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xD1B5_4A32_D192_ED03;
    x ^= x >> 31;
    x = x.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x ^= x >> 29;
    (x >> 11) as f64 / (1u64 << 53) as f64
}

/// Every third vertex stays.
fn fixed_every_third(n: usize) -> Moving {
    Moving::AllBut((0..n as u32).filter(|v| v % 3 == 1).collect())
}

fn spectral_radius_of_iteration(m: &Mat<f64>) -> f64 {
    let n = m.nrows();
    let i_m = Mat::<f64>::from_fn(n, n, |i, j| if i == j { 1.0 } else { 0.0 } - m[(i, j)]);
    i_m.eigenvalues()
        .expect("eigenvalues")
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max)
}

/// Lin et al., formula (2), in closed form at a smooth vertex of a closed quad mesh.
fn formula_two(t: &Topology, p: &[DVec3], lambda: &[f64], v: usize) -> DVec3 {
    let n = t.valence(v) as f64;
    let l = lambda[v];
    let beta = n * (1.0 - l) * 10.0 / 13.0 + 2.5;
    let e: DVec3 = t.vertex_ring(v).map(|u| p[u as usize]).sum();
    let f: DVec3 = t
        .vertex_quad_diagonals(v)
        .map(|d| p[d.unwrap() as usize])
        .sum();
    ((n * n * l + 7.0 * n / 4.0) * p[v] + beta * e + 0.3 * beta * f) / (n * (n + 5.0))
}

#[test]
fn formula_two_equals_the_catmull_clark_limit_of_the_phase_one_mesh() {
    for s in closed_quad_shapes() {
        let nv = s.topology.num_vertices();
        let lambda: Vec<f64> = (0..nv).map(|v| 0.36 + 0.64 * rand01(v as u64)).collect();
        let tp = TwoPhase::new(lambda.clone()).unwrap();
        let table = subd_limit::two_phase_base_limit(&s.topology, &tp, &s.options).unwrap();
        let limit = table.apply(&s.points).positions;
        let diag = bbox_diagonal(&s.points);
        for (v, got) in limit.iter().enumerate() {
            let want = formula_two(&s.topology, &s.points, &lambda, v);
            let d = (*got - want).length() / diag;
            assert!(d < 1e-14, "{} vertex {v}: {d:e}", s.name);
        }
        // λ = 1 freezes the phase-1 vertex points: it is not ordinary Catmull-Clark.
        let frozen = subd_limit::two_phase_base_limit(
            &s.topology,
            &TwoPhase::uniform(1.0).unwrap(),
            &s.options,
        )
        .unwrap()
        .apply(&s.points)
        .positions;
        let cc =
            subd_limit::base_limit(&s.topology, &subd_schemes::Scheme::CatmullClark, &s.options)
                .unwrap()
                .apply(&s.points)
                .positions;
        let gap = frozen
            .iter()
            .zip(&cc)
            .map(|(a, b)| (*a - *b).length())
            .fold(0.0, f64::max);
        assert!(
            gap > 1e-3 * diag,
            "{}: λ = 1 equals ordinary Catmull-Clark?",
            s.name
        );
    }
}

/// The limit table of `scheme`, built afresh (not the one inside a [`Pia`]).
fn fresh_limit_table(s: &Shape, scheme: &Scheme) -> subd_schemes::StencilTable {
    let table = match scheme {
        Scheme::CatmullClark => {
            subd_limit::base_limit(&s.topology, &subd_schemes::Scheme::CatmullClark, &s.options)
        }
        Scheme::Loop => {
            subd_limit::base_limit(&s.topology, &subd_schemes::Scheme::Loop, &s.options)
        }
        Scheme::TwoPhase(tp) => subd_limit::two_phase_base_limit(&s.topology, tp, &s.options),
        other => panic!("no limit table for {other}"),
    };
    table.unwrap().position
}

/// A mesh and scheme with its PIA problem and an independently built limit table.
struct Case<'a> {
    s: &'a Shape,
    pia: Pia,
    check: subd_schemes::StencilTable,
}

impl<'a> Case<'a> {
    fn new(s: &'a Shape, scheme: &Scheme) -> Case<'a> {
        Case {
            s,
            pia: Pia::new(&s.topology, scheme, &s.options).unwrap(),
            check: fresh_limit_table(s, scheme),
        }
    }

    /// Solves, then checks interpolation (1e-10 of the diagonal, by the independent limit
    /// table) and that fixed vertices did not move. Returns the iterations.
    fn solve_and_check(&self, moving: &Moving, solver: Solver) -> usize {
        let s = self.s;
        let opts = PiaOptions {
            solver,
            tol: 1e-10,
            max_iter: 20_000,
        };
        let r = self.pia.solve(&s.points, moving, &opts).unwrap();
        assert!(
            r.converged,
            "{} {solver:?}: history tail {:?}",
            s.name,
            &r.history[r.history.len().saturating_sub(3)..]
        );
        let flags = moving.flags(s.topology.num_vertices()).unwrap();
        let limit = self.check.apply_points(&r.points);
        let diag = bbox_diagonal(&s.points);
        for v in 0..flags.len() {
            if flags[v] {
                let d = (limit[v] - s.points[v]).length() / diag;
                assert!(d <= 1.01e-10, "{} {solver:?} vertex {v}: {d:e}", s.name);
            } else {
                assert_eq!(
                    r.points[v], s.points[v],
                    "{}: fixed vertex {v} moved",
                    s.name
                );
            }
        }
        r.iterations
    }
}

#[test]
fn two_phase_pia_converges_for_every_lambda_on_closed_quad_meshes() {
    for s in closed_quad_shapes() {
        let nv = s.topology.num_vertices();
        let pia_moving = [Moving::All, fixed_every_third(nv)];
        for &l in &LAMBDAS {
            let scheme = Scheme::TwoPhase(TwoPhase::uniform(l).unwrap());
            let case = Case::new(&s, &scheme);
            let pia = &case.pia;
            for moving in &pia_moving {
                // Theorem 1: ρ(I − M̄) < 1.
                let (_, m) = pia.moving_matrix(moving).unwrap();
                let rho = spectral_radius_of_iteration(&m);
                assert!(rho < 1.0, "{} λ={l}: ρ = {rho}", s.name);
                // Lin et al. §3: M̄ = C̄ D̄ with D̄ symmetric, so CG applies.
                assert!(pia.is_symmetrizable(moving).unwrap(), "{} λ={l}", s.name);
                case.solve_and_check(moving, Solver::Iterate);
            }
        }
        // Per-vertex λ, every solver.
        let lambda: Vec<f64> = (0..nv)
            .map(|v| 0.36 + 0.64 * rand01(7 * v as u64 + 1))
            .collect();
        let case = Case::new(&s, &Scheme::TwoPhase(TwoPhase::new(lambda).unwrap()));
        for solver in [
            Solver::Iterate,
            Solver::Weighted,
            Solver::Cg,
            Solver::Chebyshev,
            Solver::Direct,
            Solver::Auto,
        ] {
            case.solve_and_check(&fixed_every_third(nv), solver);
        }
    }
}

#[test]
fn theorem_two_gives_the_final_limits_of_the_fixed_vertices() {
    for s in closed_quad_shapes().into_iter().take(4) {
        let nv = s.topology.num_vertices();
        let lambda: Vec<f64> = (0..nv)
            .map(|v| 0.36 + 0.64 * rand01(3 * v as u64 + 2))
            .collect();
        let scheme = Scheme::TwoPhase(TwoPhase::new(lambda).unwrap());
        let pia = Pia::new(&s.topology, &scheme, &s.options).unwrap();
        let moving = fixed_every_third(nv);
        let flags = moving.flags(nv).unwrap();
        // Dense B, D⁰ = p − B p, E = B[Q, P], M̄ = B[P, P].
        let (rows, cols, w) = {
            let t = pia.limit_table();
            let mut out = (Vec::new(), Vec::new(), Vec::new());
            for i in 0..nv {
                let (c, x) = t.row(i);
                for (&j, &x) in c.iter().zip(x) {
                    out.0.push(i);
                    out.1.push(j as usize);
                    out.2.push(x);
                }
            }
            out
        };
        let mut b = Mat::<f64>::zeros(nv, nv);
        for k in 0..rows.len() {
            b[(rows[k], cols[k])] += w[k];
        }
        let p_idx: Vec<usize> = (0..nv).filter(|&v| flags[v]).collect();
        let q_idx: Vec<usize> = (0..nv).filter(|&v| !flags[v]).collect();
        let pts = Mat::<f64>::from_fn(nv, 3, |i, k| s.points[i][k]);
        let d0 = &pts - &b * &pts;
        let mbar = Mat::<f64>::from_fn(p_idx.len(), p_idx.len(), |i, j| b[(p_idx[i], p_idx[j])]);
        let e = Mat::<f64>::from_fn(q_idx.len(), p_idx.len(), |i, j| b[(q_idx[i], p_idx[j])]);
        let d0p = Mat::<f64>::from_fn(p_idx.len(), 3, |i, k| d0[(p_idx[i], k)]);
        let lu = mbar.partial_piv_lu();
        let y = faer::linalg::solvers::Solve::solve(&lu, &d0p);
        let dq_inf = Mat::<f64>::from_fn(q_idx.len(), 3, |i, k| d0[(q_idx[i], k)]) - &e * &y;
        // The solved mesh's limits at Q are p_Q − D_Q^∞ (erratum: minus, not plus).
        let r = pia
            .solve(
                &s.points,
                &moving,
                &PiaOptions {
                    solver: Solver::Direct,
                    ..PiaOptions::default()
                },
            )
            .unwrap();
        let limit = fresh_limit_table(&s, &scheme).apply_points(&r.points);
        let diag = bbox_diagonal(&s.points);
        for (i, &q) in q_idx.iter().enumerate() {
            let want = s.points[q] - DVec3::new(dq_inf[(i, 0)], dq_inf[(i, 1)], dq_inf[(i, 2)]);
            let d = (limit[q] - want).length() / diag;
            assert!(d < 1e-12, "{} fixed vertex {q}: {d:e}", s.name);
        }
    }
}

#[test]
fn two_phase_pia_converges_on_open_and_creased_meshes() {
    for s in open_or_creased_quad_shapes() {
        let t0 = std::time::Instant::now();
        let nv = s.topology.num_vertices();
        for &l in &LAMBDAS {
            let scheme = Scheme::TwoPhase(TwoPhase::uniform(l).unwrap());
            let pia = Pia::new(&s.topology, &scheme, &s.options).unwrap();
            for moving in [Moving::All, fixed_every_third(nv)] {
                let (_, m) = pia.moving_matrix(&moving).unwrap();
                let rho = spectral_radius_of_iteration(&m);
                assert!(rho < 1.0, "{} λ={l}: ρ = {rho}", s.name);
            }
        }
        let lambda: Vec<f64> = (0..nv)
            .map(|v| 0.36 + 0.64 * rand01(5 * v as u64))
            .collect();
        let case = Case::new(&s, &Scheme::TwoPhase(TwoPhase::new(lambda).unwrap()));
        for solver in [Solver::Iterate, Solver::Cg, Solver::Direct] {
            case.solve_and_check(&Moving::All, solver);
        }
        println!("{} {nv}: {:.2}s", s.name, t0.elapsed().as_secs_f64());
    }
}

#[test]
fn the_boundary_rule_matches_its_closed_form() {
    // On an open grid, a boundary vertex's two-phase limit is the cubic B-spline limit of the
    // phase-1 boundary polygon: [(1 + 4μ) v + (5/2 − 2μ)(e₀ + e₁)] / 6.
    let (nx, ny) = (6u32, 5u32);
    let mut faces = Vec::new();
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            let v = j * nx + i;
            faces.push(vec![v, v + 1, v + nx + 1, v + nx]);
        }
    }
    let t = subd_tests::build((nx * ny) as usize, &faces);
    let p: Vec<DVec3> = (0..nx * ny)
        .map(|k| DVec3::new((k % nx) as f64, (k / nx) as f64, rand01(k as u64)))
        .collect();
    let lambda: Vec<f64> = (0..nx * ny)
        .map(|v| 0.36 + 0.6 * rand01(v as u64 + 99))
        .collect();
    let table = subd_limit::two_phase_base_limit(
        &t,
        &TwoPhase::new(lambda.clone()).unwrap(),
        &Options::default(),
    )
    .unwrap();
    let limit = table.apply(&p).positions;
    for i in 1..nx - 1 {
        let v = i as usize;
        let mu = two_phase::crease_vertex_weight(lambda[v]);
        let want = ((1.0 + 4.0 * mu) * p[v] + (2.5 - 2.0 * mu) * (p[v - 1] + p[v + 1])) / 6.0;
        assert!((limit[v] - want).length() < 1e-14, "boundary vertex {v}");
    }
}

#[test]
fn catmull_clark_and_loop_pia_converge_on_open_and_closed_meshes() {
    let cc = shapes("catmark_", 700, manifold);
    let lp = shapes("loop_", 700, manifold);
    assert!(cc.len() > 20 && lp.len() > 10);
    let (mut singular, mut divergent) = (Vec::new(), Vec::new());
    for (list, scheme) in [(cc, Scheme::CatmullClark), (lp, Scheme::Loop)] {
        for s in &list {
            let nv = s.topology.num_vertices();
            let case = Case::new(s, &scheme);
            let (_, m) = case.pia.moving_matrix(&Moving::All).unwrap();
            let ev = m.eigenvalues().unwrap();
            let smallest = ev.iter().map(|z| z.norm()).fold(f64::MAX, f64::min);
            let rho = spectral_radius_of_iteration(&m);
            let symmetric = case.pia.is_symmetrizable(&Moving::All).unwrap();
            // Closed, untagged, manifold meshes (quads only for Catmull-Clark: elsewhere the
            // limit comes through a refinement) have the C·D form.
            let quads = matches!(scheme, Scheme::Loop) || all_quads(&s.topology);
            if closed(&s.topology) && untagged(&s.topology) && quads {
                assert!(symmetric, "{} {scheme:?} should be symmetrisable", s.name);
            }
            if smallest < 1e-9 {
                // M̄ is singular: interpolation of arbitrary targets is impossible.
                singular.push(s.name.clone());
                continue;
            }
            let solvers: &[Solver] = if rho >= 1.0 {
                // The paper's iteration diverges; Krylov and direct solvers still apply.
                divergent.push(s.name.clone());
                &[Solver::Auto, Solver::Direct]
            } else {
                &[Solver::Iterate, Solver::Auto, Solver::Direct]
            };
            for &solver in solvers {
                case.solve_and_check(&Moving::All, solver);
            }
            case.solve_and_check(&fixed_every_third(nv), Solver::Auto);
        }
    }
    println!("singular {singular:?} divergent {divergent:?}");
    // No scheme/shape pair makes the paper's iteration diverge; four are singular. The cube
    // (and catmark_hole_test1, the same cube with a hole tag, which leaves vertex limits
    // alone): the Catmull-Clark limit mask at valence 3 (3/8, 1/6 per edge, 1/24 per
    // diagonal) sends the ±1 pattern of its bipartite vertices to 3/8 − 3/6 + 3/24 = 0 — the
    // two-phase scheme's λ > 7/20 is what rules this out. The two valence-2 shapes glue faces
    // back to back, so several vertices share one limit point.
    assert!(divergent.is_empty(), "{divergent:?}");
    assert_eq!(
        singular,
        [
            "catmark_cube",
            "catmark_hole_test1",
            "catmark_val2_back2back",
            "catmark_val2_foldover"
        ]
    );
}

#[test]
fn solvers_report_what_ran_and_cg_beats_the_plain_iteration() {
    let s = load(&subd_tests::osd_mesh_dir().join("catmark_torus.obj"));
    let pia = Pia::new(&s.topology, &Scheme::CatmullClark, &s.options).unwrap();
    let run = |solver| {
        pia.solve(
            &s.points,
            &Moving::All,
            &PiaOptions {
                solver,
                ..PiaOptions::default()
            },
        )
        .unwrap()
    };
    let plain = run(Solver::Iterate);
    let cg = run(Solver::Cg);
    let weighted = run(Solver::Weighted);
    assert_eq!(plain.method, Method::Iterate);
    // The torus's vertices are two-coloured along edges: CG is checkerboard-preconditioned.
    assert_eq!(cg.method, Method::CheckerboardCg);
    assert!(
        cg.iterations * 3 < plain.iterations,
        "cg {} vs {}",
        cg.iterations,
        plain.iterations
    );
    // ω = 2 / (λ_min + λ_max) from Lanczos estimates that match the dense spectrum.
    let (_, m) = pia.moving_matrix(&Moving::All).unwrap();
    let ev: Vec<f64> = m.eigenvalues().unwrap().iter().map(|z| z.re).collect();
    let (lo, hi) = ev
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
    let Method::Weighted {
        omega,
        lambda_min,
        lambda_max,
    } = weighted.method
    else {
        panic!("{:?}", weighted.method)
    };
    assert!(
        (lambda_min - lo).abs() < 1e-6 && (lambda_max - hi).abs() < 1e-6,
        "{lambda_min} {lambda_max} vs {lo} {hi}"
    );
    assert!((omega - 2.0 / (lambda_min + lambda_max)).abs() < 1e-15);
    assert!(weighted.converged);
    // Auto on an unprepared problem: checkerboard CG straight away (closed, two-coloured).
    let auto = run(Solver::Auto);
    assert_eq!(auto.method, Method::CheckerboardCg);
    assert!(auto.converged && auto.iterations * 3 < plain.iterations);
    // Prepared: Chebyshev on the checkerboard-preconditioned system (every vertex moves,
    // closed and two-coloured), its history one entry per checkpoint.
    assert!(pia.prepare());
    let auto = run(Solver::Auto);
    assert!(
        matches!(auto.method, Method::Chebyshev { .. }),
        "{:?}",
        auto.method
    );
    assert!(auto.converged && auto.iterations < plain.iterations);
    assert!(auto.history.len() <= auto.iterations + 1);
    let nv = s.topology.num_vertices();
    let slow = Pia::new(
        &s.topology,
        &Scheme::TwoPhase(TwoPhase::uniform(0.36).unwrap()),
        &s.options,
    )
    .unwrap();
    // Rough targets (every mode excited).
    let rough: Vec<DVec3> = s
        .points
        .iter()
        .enumerate()
        .map(|(v, p)| {
            *p + 0.1
                * DVec3::new(
                    rand01(v as u64),
                    rand01(v as u64 + 500),
                    rand01(v as u64 + 900),
                )
        })
        .collect();
    // With fixed vertices (no cached Chebyshev operator) auto runs checkerboard CG on the
    // cut system, near λ = 7/20 where the iteration crawls.
    let r = slow
        .solve(&rough, &fixed_every_third(nv), &PiaOptions::default())
        .unwrap();
    assert_eq!(r.method, Method::CheckerboardCg);
    assert!(r.converged);
    // Without a checkerboard (Loop: triangles) auto starts with the iteration and hands over
    // to CG once the observed contraction says CG finishes sooner.
    let tri = load(&subd_tests::osd_mesh_dir().join("loop_toroidal_tet.obj"));
    let r2 =
        subd_schemes::Refinement::new(&tri.topology, subd_schemes::Scheme::Loop, &tri.options, 2)
            .unwrap();
    let points = r2.refine_points(&tri.points).pop().unwrap();
    let topology = r2.into_topology(2);
    let tn = topology.num_vertices();
    let rough: Vec<DVec3> = points
        .iter()
        .enumerate()
        .map(|(v, p)| *p + 0.1 * DVec3::new(rand01(v as u64), rand01(v as u64 + 500), 0.0))
        .collect();
    let lp = Pia::new(&topology, &Scheme::Loop, &tri.options).unwrap();
    let r = lp
        .solve(&rough, &fixed_every_third(tn), &PiaOptions::default())
        .unwrap();
    assert!(
        matches!(r.method, Method::IterateThenCg { .. }),
        "{:?}",
        r.method
    );
    assert!(r.converged);
    // The paper's iteration contracts monotonically here (ρ < 1, symmetric-like system).
    assert!(
        plain
            .history
            .windows(2)
            .all(|w| w[1] <= w[0] * (1.0 + 1e-9))
    );
    assert_eq!(plain.history.len(), plain.iterations + 1);
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let s = load(&subd_tests::osd_mesh_dir().join("catmark_car.obj"));
    let pia = Pia::new(&s.topology, &Scheme::CatmullClark, &s.options).unwrap();
    for solver in [
        Solver::Iterate,
        Solver::Weighted,
        Solver::Cg,
        Solver::Chebyshev,
    ] {
        let opts = PiaOptions {
            solver,
            ..PiaOptions::default()
        };
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| pia.solve(&s.points, &Moving::All, &opts).unwrap())
        };
        let (a, b) = (run(1), run(3));
        assert_eq!(a.points, b.points, "{solver:?}");
        assert_eq!(a.history, b.history, "{solver:?}");
    }
}

#[test]
fn pia_commutes_with_affine_maps() {
    let s = load(&subd_tests::osd_mesh_dir().join("catmark_xord_boundary.obj"));
    let pia = Pia::new(&s.topology, &Scheme::CatmullClark, &s.options).unwrap();
    let m = glam::DMat3::from_cols_array(&[1.2, 0.3, -0.1, 0.2, 0.9, 0.4, -0.3, 0.1, 1.1]);
    let shift = DVec3::new(3.0, -2.0, 0.5);
    let moved: Vec<DVec3> = s.points.iter().map(|p| m * *p + shift).collect();
    let opts = PiaOptions {
        solver: Solver::Direct,
        ..PiaOptions::default()
    };
    let a = pia
        .solve(&s.points, &fixed_every_third(s.points.len()), &opts)
        .unwrap();
    let b = pia
        .solve(&moved, &fixed_every_third(s.points.len()), &opts)
        .unwrap();
    let diag = bbox_diagonal(&moved);
    for (pa, pb) in a.points.iter().zip(&b.points) {
        assert!((m * *pa + shift - *pb).length() < 1e-11 * diag);
    }
}

#[test]
fn bad_input_is_a_typed_error() {
    let s = load(&subd_tests::osd_mesh_dir().join("catmark_cube.obj"));
    let pia = Pia::new(&s.topology, &Scheme::CatmullClark, &s.options).unwrap();
    let err = pia.solve(
        &s.points,
        &Moving::Only(vec![0, 99]),
        &PiaOptions::default(),
    );
    assert!(matches!(
        err,
        Err(subd_pia::PiaError::Vertex { index: 99, .. })
    ));
    let err = pia.solve(&s.points[..3], &Moving::All, &PiaOptions::default());
    assert!(matches!(err, Err(subd_pia::PiaError::Targets { .. })));
    let tri = load(&subd_tests::osd_mesh_dir().join("loop_cube.obj"));
    let tp = TwoPhase::uniform(0.5).unwrap();
    assert!(Pia::new(&tri.topology, &Scheme::TwoPhase(tp), &tri.options).is_err());
    assert!(Pia::new(&s.topology, &Scheme::Loop, &s.options).is_err());
}

#[test]
fn two_phase_limits_near_deep_semi_sharp_creases_equal_global_refinement() {
    // `two_phase_base_limit` refines only around semi-sharp features past 3 decay levels;
    // the reference refines the whole mesh that far.
    let mut checked = 0;
    for s in shapes("catmark_", 200, |t| all_quads(t) && manifold(t)) {
        let (levels, _) =
            subd_limit::levels_for_exact_limit(&s.topology, &subd_schemes::Scheme::CatmullClark);
        if levels <= 3 || s.topology.num_face_vertices() << (2 * levels) > 1 << 24 {
            continue;
        }
        let nv = s.topology.num_vertices();
        let lambda: Vec<f64> = (0..nv)
            .map(|v| 0.36 + 0.64 * rand01(11 * v as u64))
            .collect();
        let tp = TwoPhase::new(lambda).unwrap();
        let local = subd_limit::two_phase_base_limit(&s.topology, &tp, &s.options).unwrap();
        let r = subd_schemes::Refinement::new(
            &s.topology,
            subd_schemes::Scheme::TwoPhase(tp.clone()),
            &s.options,
            levels,
        )
        .unwrap();
        let at = subd_limit::LimitStencilTable::at_level(&r, levels).unwrap();
        let fine = r.composed(levels).apply_points(&s.points);
        let global = at.position.apply_points(&fine);
        let got = local.position.apply_points(&s.points);
        let diag = bbox_diagonal(&s.points);
        for v in 0..nv {
            let d = (got[v] - global[v]).length() / diag;
            assert!(d < 1e-13, "{} vertex {v}: {d:e}", s.name);
        }
        checked += 1;
    }
    assert!(
        checked >= 3,
        "{checked} shapes with deep semi-sharp creases"
    );
}

/// A `Pia` keeps its solver-ready matrix and symmetric form between solves: a local solve
/// after a global one on the same `Pia` (its `C` cut from the whole matrix's) reaches the
/// same interpolant as the local solve on a fresh `Pia` (its `C` found for the cut alone).
#[test]
fn repeated_solves_on_one_pia_agree_with_fresh_ones() {
    for s in closed_quad_shapes()
        .iter()
        .chain(&open_or_creased_quad_shapes())
    {
        let fixed = fixed_every_third(s.points.len());
        let opts = PiaOptions {
            solver: Solver::Cg,
            tol: 1e-12,
            max_iter: 10_000,
        };
        let warm = Pia::new(&s.topology, &Scheme::CatmullClark, &s.options).unwrap();
        let global = warm.solve(&s.points, &Moving::All, &opts).unwrap();
        assert!(global.converged, "{}: global", s.name);
        let local_warm = warm.solve(&s.points, &fixed, &opts).unwrap();
        let fresh = Pia::new(&s.topology, &Scheme::CatmullClark, &s.options).unwrap();
        let local_fresh = fresh.solve(&s.points, &fixed, &opts).unwrap();
        assert!(local_warm.converged && local_fresh.converged, "{}", s.name);
        assert_eq!(local_warm.moving, local_fresh.moving);
        let diag = bbox_diagonal(&s.points);
        for (a, b) in local_warm.points.iter().zip(&local_fresh.points) {
            assert!((*a - *b).length() <= 1e-9 * diag, "{}: {a} vs {b}", s.name);
        }
    }
}
