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

/// [`torus`] with extraordinary vertices: wherever `i` and `j` are both multiples of `every`,
/// the quads `(i, j)` and `(i, j + 1)` are merged into one hexagon (their shared edge
/// dropped), whose two middle vertices then have valence 3. One Catmull-Clark step makes it
/// all quads, the hexagon centres valence 6: the closed test and benchmark mesh of subd's
/// refinement and interpolation benches (`m = n = 160`, `every = 8`). Same vertices and
/// positions as [`torus`]; faces row by row, each hexagon in place of its two quads.
///
/// ```
/// let t = subd_mesh::primitives::torus_with_hexagons(8, 8, 4, 3.0, 1.0);
/// // Four quad pairs merged: 64 − 4 faces, 4 of them hexagons.
/// assert_eq!(t.topology.num_faces(), 60);
/// let valence3 = (0..64).filter(|&v| t.topology.vertex_faces(v).len() == 3).count();
/// assert_eq!(valence3, 8);
/// ```
///
/// # Panics
/// If `m < 3`, `n < 4` or `every < 2`.
pub fn torus_with_hexagons(m: u32, n: u32, every: u32, major: f64, minor: f64) -> Mesh {
    assert!(
        m >= 3 && n >= 4 && every >= 2,
        "a torus with hexagons needs at least 3 x 4 faces and hexagons at most every other quad"
    );
    let id = |i: u32, j: u32| (i % m) * n + (j % n);
    let (mut sizes, mut idx) = (Vec::new(), Vec::with_capacity((4 * m * n) as usize));
    for i in 0..m {
        let mut j = 0;
        while j < n {
            if i % every == 0 && j % every == 0 && j + 1 < n {
                idx.extend_from_slice(&[id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                idx.extend_from_slice(&[id(i + 1, j + 2), id(i, j + 2), id(i, j + 1)]);
                sizes.push(6);
                j += 2;
            } else {
                idx.extend_from_slice(&[id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
                sizes.push(4);
                j += 1;
            }
        }
    }
    let positions = torus(m, n, major, minor).positions;
    let topology = TopologyBuilder::new((m * n) as usize)
        .build(&sizes, &idx)
        .expect("a torus grid with merged quad pairs is a valid mesh");
    Mesh::new(topology, positions).expect("finite positions")
}
