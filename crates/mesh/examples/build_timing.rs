//! Times `TopologyBuilder::build` on 1M-face meshes in rayon pools of 1 and 2 threads:
//! a quad torus with hexagons (1000 x 1000) and a triangulated torus (708 x 708 quads split
//! in two). Prints the median of each over the repeats, the pools interleaved so that noise
//! from other processes falls on both alike.
//!
//! `cargo run --release -p subd-mesh --example build_timing -- [repeats] [threads...]`

use std::time::Instant;

use subd_mesh::TopologyBuilder;
use subd_mesh::primitives::{torus, torus_with_hexagons};

/// Face sizes and face-vertices of a mesh, ready to build.
struct Input {
    name: &'static str,
    num_vertices: usize,
    sizes: Vec<u32>,
    vertices: Vec<u32>,
}

fn quads_with_hexagons() -> Input {
    let t = torus_with_hexagons(1000, 1000, 8, 3.0, 1.0).topology;
    Input {
        name: "quad+hex torus 1000x1000",
        num_vertices: t.num_vertices(),
        sizes: t.face_sizes().collect(),
        vertices: t.all_face_vertices().to_vec(),
    }
}

/// Every quad of a torus split along its diagonal.
fn triangles() -> Input {
    let t = torus(708, 708, 3.0, 1.0).topology;
    let vertices: Vec<u32> = t
        .all_face_vertices()
        .chunks(4)
        .flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]])
        .collect();
    Input {
        name: "triangle torus 708x708x2",
        num_vertices: t.num_vertices(),
        sizes: vec![3; vertices.len() / 3],
        vertices,
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("numbers: repeats, then thread counts"))
        .collect();
    let repeats = args.first().copied().unwrap_or(7);
    let threads = if args.len() > 1 {
        args[1..].to_vec()
    } else {
        vec![1, 2]
    };
    let pools: Vec<rayon::ThreadPool> = threads
        .iter()
        .map(|&n| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .unwrap()
        })
        .collect();
    for input in [quads_with_hexagons(), triangles()] {
        let mut times = vec![Vec::new(); pools.len()];
        for _ in 0..repeats {
            for (pool, t) in pools.iter().zip(&mut times) {
                let start = Instant::now();
                let topo = pool.install(|| {
                    TopologyBuilder::new(input.num_vertices)
                        .build(&input.sizes, &input.vertices)
                        .unwrap()
                });
                t.push(start.elapsed().as_secs_f64() * 1e3);
                std::hint::black_box(topo);
            }
        }
        for (n, t) in threads.iter().zip(times) {
            println!("{}: {n} thread(s): median {:.1} ms", input.name, median(t));
        }
    }
}
