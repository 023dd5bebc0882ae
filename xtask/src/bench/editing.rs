//! The editing lines of `cargo xtask bench` (issue 20): least squares, the energy method and
//! the editor's re-solve on closed meshes of 10k and 100k control vertices with 20
//! constraints (points, normals, two iso-lines), and Li et al.'s two examples next to the
//! paper's timings (2.9 GHz Pentium 4).

use std::sync::Arc;
use std::time::Instant;

use subd_editing::isoline::{is_regular, strip};
use subd_editing::{Axis, Constraint, Editor, EnergyOptions, Goal, Isoline, Location, Method};
use subd_limit::eval::{FaceParam, LimitEvaluator};
use subd_mesh::{DVec3, Mesh, TopologyBuilder};
use subd_schemes::{Options, Refinement, Scheme};

use crate::bench::median;

/// A closed quad mesh with extraordinary vertices (valence 6 at refined hexagons) and about
/// `m² × 4` control vertices.
fn closed_mesh(m: u32) -> Mesh {
    let base = subd_mesh::primitives::torus_with_hexagons(m, m, 8, 3.0, 1.0);
    let r = Refinement::new(&base.topology, Scheme::CatmullClark, &Options::default(), 1)
        .expect("refine");
    let pts = r.refine_points(&base.positions).pop().expect("level 1");
    Mesh::new(r.into_topology(1), pts).expect("finite")
}

/// An open regular grid of n × n quads on a bump.
fn open_grid(n: u32) -> Mesh {
    let mut faces = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let v = j * (n + 1) + i;
            faces.extend([v, v + 1, v + n + 2, v + n + 1]);
        }
    }
    let topo = TopologyBuilder::new(((n + 1) * (n + 1)) as usize)
        .build(&vec![4; (n * n) as usize], &faces)
        .expect("grid");
    let pts = (0..(n + 1) * (n + 1))
        .map(|k| {
            let (x, y) = (
                (k % (n + 1)) as f64 / n as f64,
                (k / (n + 1)) as f64 / n as f64,
            );
            DVec3::new(x, y, 0.2 * (3.0 * x).sin() * (2.0 * y).cos())
        })
        .collect();
    Mesh::new(topo, pts).expect("finite")
}

/// `count` regular iso-lines of 4 faces, spread over the mesh.
fn isolines(m: &Mesh, count: usize, faces: usize) -> Vec<Constraint> {
    let ev = LimitEvaluator::new(&m.topology, &Scheme::CatmullClark, &Options::default())
        .expect("evaluator");
    let nf = m.topology.num_faces();
    let mut out = Vec::new();
    let mut f = nf / 7;
    while out.len() < count && f < nf {
        let line = Isoline {
            face: f,
            along: Axis::U,
            at: 0.5,
            faces,
        };
        if strip(&m.topology, &line).is_ok_and(|s| is_regular(&ev, &s)) {
            let d = 0.02 * (out.len() as f64 + 1.0);
            out.push(Constraint::Isoline {
                line,
                goals: (0..faces + 3)
                    .map(|k| {
                        let t = k as f64 / (faces + 2) as f64;
                        Goal::Displacement(DVec3::new(
                            0.0,
                            0.0,
                            d * (std::f64::consts::PI * t).sin(),
                        ))
                    })
                    .collect(),
            });
            f += nf / 3;
        } else {
            f += 1;
        }
    }
    out
}

/// 20 constraints: 7 vertex points, 7 face points, 4 normals, 2 iso-lines.
fn twenty(m: &Mesh) -> Vec<Constraint> {
    let nv = m.topology.num_vertices();
    let nf = m.topology.num_faces();
    let mut cs = Vec::new();
    for k in 0..7 {
        cs.push(Constraint::Point {
            at: Location::Vertex((k * 7919 + 11) % nv),
            goal: Goal::Displacement(DVec3::new(0.0, 0.0, 0.05)),
        });
        cs.push(Constraint::Point {
            at: Location::Face(FaceParam {
                face: (k * 104_729 + 5) % nf,
                sub: 0,
                u: 0.3,
                v: 0.6,
            }),
            goal: Goal::Displacement(DVec3::new(0.03, 0.0, -0.02)),
        });
    }
    for k in 0..4 {
        cs.push(Constraint::Normal {
            at: Location::Face(FaceParam {
                face: (k * 15_485_863 + 77) % nf,
                sub: 0,
                u: 0.5,
                v: 0.5,
            }),
            normal: DVec3::new(0.1 * k as f64, 0.2, 1.0),
        });
    }
    cs.extend(isolines(m, 2, 4));
    cs
}

fn energy(rings: Option<usize>) -> Method {
    Method::Energy {
        penalty: None,
        region_rings: rings,
        energy: EnergyOptions::default(),
    }
}

/// Median seconds of `f` over `repeats` runs.
fn time(repeats: usize, mut f: impl FnMut()) -> f64 {
    median(
        (0..repeats.max(1))
            .map(|_| {
                let t = Instant::now();
                f();
                t.elapsed().as_secs_f64()
            })
            .collect(),
    )
}

/// Median seconds of an edit (rows, assembly, factorisation, one solve) with the mesh's
/// evaluator built beforehand, and the editor.
fn edit_time(m: &Mesh, cs: &[Constraint], method: Method, repeats: usize) -> (f64, Editor) {
    let ev = Arc::new(
        LimitEvaluator::new(&m.topology, &Scheme::CatmullClark, &Options::default())
            .expect("evaluator"),
    );
    let build = || {
        Editor::with_evaluator(
            ev.clone(),
            &m.topology,
            &m.positions,
            &Scheme::CatmullClark,
            cs,
            method,
        )
        .expect("editor")
    };
    let t = time(repeats, || {
        let ed = build();
        std::hint::black_box(ed.solve(cs).expect("solve"));
    });
    (t, build())
}

/// Runs the editing benchmark and prints its two tables: the 10k and 100k closed meshes,
/// then Li et al.'s examples.
pub fn run(repeats: usize) -> Result<(), String> {
    let repeats = repeats.max(3);
    closed_meshes(repeats);
    seed_examples(repeats);
    Ok(())
}

/// The methods timed on the closed mesh `label`: every vertex free only on the 10k one,
/// where its dense solve is still affordable.
fn methods(label: &str) -> Vec<(Method, &'static str)> {
    if label == "10k" {
        vec![
            (Method::LeastSquares, "least squares"),
            (energy(Some(3)), "energy, exact, 3 rings"),
            (energy(None), "energy, exact, every vertex free"),
        ]
    } else {
        vec![
            (Method::LeastSquares, "least squares"),
            (energy(Some(3)), "energy, exact, 3 rings"),
        ]
    }
}

/// The first table: the 20 constraints on the closed 10k and 100k meshes, each method's
/// evaluator, edit and re-solve times.
fn closed_meshes(repeats: usize) {
    println!("\n## Constraint-based editing (Li et al. 2008)\n");
    println!(
        "20 constraints (7 vertex points, 7 face points, 4 normals, 2 iso-lines over 4 regular faces) on closed Catmull-Clark meshes with valence-6 vertices; medians of {repeats} runs. `edit` is the constraint rows, the energy assembly, the factorisation and one solve, with the mesh's limit evaluator built beforehand (once per mesh, as a modeller keeps it; its time is the `evaluator` column).\n"
    );
    println!(
        "| mesh | control vertices | method | evaluator | edit | assemble | factor | `Editor::solve` |"
    );
    println!("|---|---:|---|---:|---:|---:|---:|---:|");
    for (m_size, label) in [(50u32, "10k"), (158, "100k")] {
        let m = closed_mesh(m_size);
        let cs = twenty(&m);
        let nv = m.topology.num_vertices();
        let evaluator = time(repeats, || {
            std::hint::black_box(
                LimitEvaluator::new(&m.topology, &Scheme::CatmullClark, &Options::default())
                    .expect("evaluator"),
            );
        });
        for (method, name) in methods(label) {
            // The every-vertex-free energy is the slow one: a third of the runs.
            let reps = if matches!(
                method,
                Method::Energy {
                    region_rings: None,
                    ..
                }
            ) {
                1.max(repeats / 3)
            } else {
                repeats
            };
            let (total, ed) = edit_time(&m, &cs, method, reps);
            let resolve = time(repeats * 3, || {
                std::hint::black_box(ed.solve(&cs).expect("solve"));
            });
            println!(
                "| {label} | {nv} | {name} | {:.1} ms | {:.1} ms | {:.1} ms | {:.1} ms | {:.2} ms |",
                1e3 * evaluator,
                1e3 * total,
                1e3 * ed.timings.assemble,
                1e3 * ed.timings.factor,
                1e3 * resolve
            );
        }
    }
}

/// The second table: Li et al.'s two examples on stand-in meshes, least squares and the
/// energy method beside the paper's timings.
fn seed_examples(repeats: usize) {
    println!(
        "\nLi et al.'s two examples (its meshes are not published: an open 20 × 20 grid on a bump and the closed 10k mesh above stand in), edits as above, against the paper's Pentium 4 timings:\n"
    );
    println!("| example | constraints | least squares | paper | energy (exact, 3 rings) | paper |");
    println!("|---|---|---:|---:|---:|---:|");
    let open = open_grid(20);
    let mut cs = isolines(&open, 2, 6);
    cs.push(Constraint::Point {
        at: Location::Vertex(220),
        goal: Goal::Displacement(DVec3::new(0.0, 0.0, 0.1)),
    });
    cs.push(Constraint::Normal {
        at: Location::Vertex(230),
        normal: DVec3::new(0.2, 0.0, 1.0),
    });
    cs.push(Constraint::Point {
        at: Location::Vertex(100),
        goal: Goal::Displacement(DVec3::new(0.0, 0.0, -0.05)),
    });
    let (ls, _) = edit_time(&open, &cs, Method::LeastSquares, repeats);
    let (en, _) = edit_time(&open, &cs, energy(Some(3)), repeats);
    println!(
        "| open surface | 2 iso-lines + point + normal + point | {:.2} ms | 94 ms | {:.2} ms | 4219 ms |",
        1e3 * ls,
        1e3 * en
    );
    let closed = closed_mesh(50);
    let mut cs = isolines(&closed, 1, 6);
    cs.push(Constraint::Point {
        at: Location::Vertex(1000),
        goal: Goal::Displacement(DVec3::new(0.0, 0.0, 0.1)),
    });
    cs.push(Constraint::Normal {
        at: Location::Vertex(1500),
        normal: DVec3::new(0.2, 0.0, 1.0),
    });
    let (ls, _) = edit_time(&closed, &cs, Method::LeastSquares, repeats);
    let (en, _) = edit_time(&closed, &cs, energy(Some(3)), repeats);
    println!(
        "| closed surface | iso-line + point + normal | {:.2} ms | 32 ms | {:.2} ms | 484 ms |",
        1e3 * ls,
        1e3 * en
    );
}
