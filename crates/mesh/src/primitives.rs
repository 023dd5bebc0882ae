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

/// A spur gear as a closed triangle mesh of genus 1 — a toothed ring with a round bore, its
/// rims creased — as a subdivision modeller would build a mechanical part: `teeth` teeth
/// of `per_tooth` profile points, the flat faces in `annuli` rings between bore and teeth,
/// `4 · teeth · per_tooth · (annuli + 1)` triangles (Sun et al.'s mechanical part has 2000:
/// 20 teeth of 5 points, 4 annuli). The profile rises from the root radius `0.8` to the tip
/// radius `1.0`; the bore has radius `0.3`; the gear is `0.25` thick. The four rim loops
/// (top and bottom of the teeth and of the bore) are infinitely sharp creases, so the flat
/// faces stay flat in the limit.
///
/// ```
/// let g = subd_mesh::primitives::gear(20, 5, 4);
/// assert_eq!(g.topology.num_faces(), 2000);
/// let s = subd_mesh::TopologySummary::new(&g.topology);
/// assert_eq!((s.boundary_edges, s.genus, s.infinite_creases), (0, Some(1), 400));
/// ```
///
/// # Panics
/// If `teeth < 3`, `per_tooth < 4` or `annuli < 1`.
pub fn gear(teeth: u32, per_tooth: u32, annuli: u32) -> Mesh {
    assert!(
        teeth >= 3 && per_tooth >= 4 && annuli >= 1,
        "a gear needs 3 teeth of 4 points and one annulus"
    );
    let n = teeth * per_tooth;
    let (root, tip, bore, half) = (0.8, 1.0, 0.3, 0.125);
    // Radius along a tooth: root, rising flank, tip, falling flank.
    let profile = |k: u32| {
        let t = (k % per_tooth) as f64 / per_tooth as f64;
        let s = match t {
            t if t < 0.25 => 0.0,
            t if t < 0.45 => (t - 0.25) / 0.2,
            t if t < 0.75 => 1.0,
            t if t < 0.95 => (0.95 - t) / 0.2,
            _ => 0.0,
        };
        root + (tip - root) * s
    };
    // Rings r = 0..=annuli from the bore (0) to the teeth (annuli), top then bottom.
    let rings = annuli + 1;
    let id = |side: u32, r: u32, k: u32| (side * rings + r) * n + (k % n);
    let mut positions = Vec::with_capacity((2 * rings * n) as usize);
    for side in 0..2 {
        for r in 0..rings {
            for k in 0..n {
                let a = std::f64::consts::TAU * k as f64 / n as f64;
                let w = r as f64 / annuli as f64;
                let radius = bore + (profile(k) - bore) * w;
                let z = if side == 0 { half } else { -half };
                positions.push(DVec3::new(radius * a.cos(), radius * a.sin(), z));
            }
        }
    }
    let mut idx = Vec::new();
    let mut quad = |a: u32, b: u32, c: u32, d: u32| idx.extend_from_slice(&[a, b, c, a, c, d]);
    for k in 0..n {
        let j = k + 1;
        for r in 0..annuli {
            quad(id(0, r, k), id(0, r + 1, k), id(0, r + 1, j), id(0, r, j)); // top, +z
            quad(id(1, r + 1, k), id(1, r, k), id(1, r, j), id(1, r + 1, j)); // bottom, −z
        }
        quad(
            id(0, annuli, k),
            id(1, annuli, k),
            id(1, annuli, j),
            id(0, annuli, j),
        ); // teeth
        quad(id(1, 0, k), id(0, 0, k), id(0, 0, j), id(1, 0, j)); // bore wall
    }
    let mut topology = TopologyBuilder::new(positions.len())
        .build(&vec![3; idx.len() / 3], &idx)
        .expect("a gear is a valid closed mesh");
    for side in 0..2 {
        for r in [0, annuli] {
            for k in 0..n {
                let e = topology
                    .find_edge(id(side, r, k), id(side, r, k + 1))
                    .expect("a rim edge");
                topology.set_edge_sharpness(e as usize, crate::tags::SHARPNESS_INFINITE);
            }
        }
    }
    Mesh::new(topology, positions).expect("finite positions")
}
