//! Times tessellation on the bench torus (`cargo xtask bench`'s quad mesh, or its
//! triangulation for Loop): `tess_time <cc|loop> <rate> <repeats> [eval]`, `eval` for the
//! evaluator path (`tessellate`), else `tessellate_mesh`; prints wall and CPU seconds of each
//! run (CPU from /proc, in clock ticks). Run it with `RAYON_NUM_THREADS` set.

use std::time::Instant;

use subd_limit::eval::LimitEvaluator;
use subd_limit::tessellation::{tessellate, tessellate_mesh};
use subd_mesh::{DVec3, Topology, TopologyBuilder};
use subd_schemes::{Options, Refinement, Scheme};

fn bench_torus() -> (Topology, Vec<DVec3>) {
    let base = subd_mesh::primitives::torus_with_hexagons(160, 160, 8, 3.0, 1.0);
    let r = Refinement::new(&base.topology, Scheme::CatmullClark, &Options::default(), 1)
        .expect("refine");
    let pts = r.refine_points(&base.positions).pop().expect("level 1");
    (r.into_topology(1), pts)
}

fn split_quads(t: &Topology) -> Topology {
    let mut idx = Vec::with_capacity(t.num_faces() * 6);
    for f in 0..t.num_faces() {
        let v = t.face_vertices(f);
        idx.extend_from_slice(&[v[0], v[1], v[2], v[0], v[2], v[3]]);
    }
    TopologyBuilder::new(t.num_vertices())
        .build(&vec![3; 2 * t.num_faces()], &idx)
        .expect("valid")
}

/// User + system CPU seconds of this process so far (Linux; 0 elsewhere).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the command name (in parentheses): utime and stime are the 12th and 13th.
    let rest = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<f64> = rest
        .split_whitespace()
        .filter_map(|x| x.parse().ok())
        .collect();
    f.get(11)
        .zip(f.get(12))
        .map_or(0.0, |(u, s)| (u + s) / 100.0)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let scheme = if args[1] == "loop" {
        Scheme::Loop
    } else {
        Scheme::CatmullClark
    };
    let rate: usize = args[2].parse().unwrap();
    let repeats: usize = args[3].parse().unwrap();
    let (mut topo, pts) = bench_torus();
    if scheme == Scheme::Loop {
        topo = split_quads(&topo);
    }
    let o = Options::default();
    let eval = args.get(4).is_some_and(|a| a == "eval");
    for _ in 0..repeats {
        let (t0, c0) = (Instant::now(), cpu_seconds());
        let t = if eval {
            let ev = LimitEvaluator::new(&topo, &scheme, &o).unwrap();
            tessellate(&ev, &ev.prepare(&pts), rate).unwrap()
        } else {
            tessellate_mesh(&topo, &scheme, &o, &pts, rate).unwrap()
        };
        let (wall, cpu) = (t0.elapsed().as_secs_f64(), cpu_seconds() - c0);
        println!("wall {wall:.3} cpu {cpu:.2} samples {}", t.positions.len());
    }
}
