//! Simple parametric meshes for examples, tests and benchmarks.

use glam::DVec3;

use crate::{Mesh, TopologyBuilder};

/// A closed quad torus of `m` × `n` faces: ring radius `major`, tube radius `minor`. Vertex
/// `i·n + j` sits at angle `2πi/m` around the axis and `2πj/n` around the tube; face `i·n + j`
/// is `(v(i,j), v(i+1,j), v(i+1,j+1), v(i,j+1))`, all consistently oriented. Genus 1.
///
/// ```
/// let t = subd_mesh::primitives::torus(8, 6, 3.0, 1.0);
/// assert_eq!((t.topology.num_faces(), t.topology.num_edges()), (48, 96));
/// ```
///
/// # Panics
/// If `m < 3` or `n < 3`.
pub fn torus(m: u32, n: u32, major: f64, minor: f64) -> Mesh {
    assert!(m >= 3 && n >= 3, "a torus needs at least 3 x 3 faces");
    let id = |i: u32, j: u32| (i % m) * n + (j % n);
    let mut idx = Vec::with_capacity((4 * m * n) as usize);
    for i in 0..m {
        for j in 0..n {
            idx.extend_from_slice(&[id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let tau = std::f64::consts::TAU;
    let positions = (0..m * n)
        .map(|k| {
            let (u, v) = (
                (k / n) as f64 * tau / m as f64,
                (k % n) as f64 * tau / n as f64,
            );
            DVec3::new(
                (major + minor * v.cos()) * u.cos(),
                (major + minor * v.cos()) * u.sin(),
                minor * v.sin(),
            )
        })
        .collect();
    let topology = TopologyBuilder::new((m * n) as usize)
        .build(&vec![4; (m * n) as usize], &idx)
        .expect("a torus grid is a valid mesh");
    Mesh::new(topology, positions).expect("finite positions")
}
