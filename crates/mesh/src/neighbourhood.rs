//! Neighbourhoods of vertices: rings in counter-clockwise order, breadth-first balls, the
//! faces or vertices within a number of rings. Limit masks, eigen analysis, local refinement,
//! editing regions and adaptive cuts all walk these; they are written here once.
//!
//! ```
//! use subd_mesh::TopologyBuilder;
//! use subd_mesh::neighbourhood::{ring_from, vertices_within_rings};
//!
//! // A 3 × 3 grid of quads: vertex 5 is interior with four neighbours.
//! let mut faces = Vec::new();
//! for j in 0..3u32 {
//!     for i in 0..3u32 {
//!         let v = j * 4 + i;
//!         faces.extend([v, v + 1, v + 5, v + 4]);
//!     }
//! }
//! let t = TopologyBuilder::new(16).build(&[4; 9], &faces).unwrap();
//! let ring = ring_from(&t, 5, 9);
//! assert_eq!(ring[0], 9);
//! assert_eq!(ring.len(), 4);
//! // One ring through faces around vertex 0: its quad's four corners.
//! assert_eq!(vertices_within_rings(&t, &[0], 1), vec![0, 1, 4, 5]);
//! ```

use std::collections::{HashSet, VecDeque};

use crate::Topology;

/// The edge neighbours of `v` counter-clockwise, starting at `from` (the first neighbour
/// when `from` is not one of them).
pub fn ring_from(t: &Topology, v: u32, from: u32) -> Vec<u32> {
    let mut ring = Vec::new();
    ring_from_into(t, v, from, &mut ring);
    ring
}

/// [`ring_from`] into `ring` (cleared first).
fn ring_from_into(t: &Topology, v: u32, from: u32, ring: &mut Vec<u32>) {
    ring.clear();
    ring.extend(t.vertex_ring(v as usize));
    let start = ring.iter().position(|&u| u == from).unwrap_or(0);
    ring.rotate_left(start);
}

/// Breadth-first labels of the ball of radius `radius` (in edges) around `seeds`, each a
/// vertex and the neighbour its ring walk starts from, seeds first: `labels[i]` is the
/// vertex labelled `i`. A vertex's neighbours are labelled counter-clockwise from the
/// vertex it was reached from, so two balls of the same shape get the same labels.
pub fn labelled_ball(t: &Topology, seeds: &[(u32, u32)], radius: usize) -> Vec<u32> {
    // Not a per-vertex array: balls are small and taken around many vertices of large
    // meshes, where clearing an array the size of the mesh each time dominates. The labels
    // themselves are searched while there are few of them, a set kept past that.
    const SEARCHED: usize = 48;
    let mut labelled: Option<HashSet<u32>> = None;
    let mut order: Vec<u32> = Vec::new();
    let mut queue: VecDeque<(u32, u32, usize)> = VecDeque::new();
    let mut ring = Vec::new();
    for &(v, from) in seeds {
        order.push(v);
        queue.push_back((v, from, 0));
    }
    while let Some((v, from, d)) = queue.pop_front() {
        if d == radius {
            continue;
        }
        ring_from_into(t, v, from, &mut ring);
        for &u in &ring {
            let new = if labelled.is_none() && order.len() < SEARCHED {
                !order.contains(&u)
            } else {
                labelled
                    .get_or_insert_with(|| order.iter().copied().collect())
                    .insert(u)
            };
            if new {
                order.push(u);
                queue.push_back((u, v, d + 1));
            }
        }
    }
    order
}

/// The faces around interior manifold vertex `v` counter-clockwise from face `f`: for each,
/// its vertices after `v` (`[next, …, previous]`). `None` unless every face around `v` has
/// `K + 1` vertices, `v` is interior and manifold, and `f` is incident to it.
pub fn face_ring<const K: usize>(t: &Topology, v: usize, f: usize) -> Option<Vec<[u32; K]>> {
    let faces = t.vertex_faces(v);
    if t.is_boundary_vertex(v)
        || t.is_non_manifold_vertex(v)
        || faces.len() != t.vertex_edges(v).len()
    {
        return None;
    }
    let start = faces.iter().position(|&g| g as usize == f)?;
    let local = t.vertex_face_local_indices(v);
    let n = faces.len();
    (0..n)
        .map(|j| {
            let i = (start + j) % n;
            let fv = t.face_vertices(faces[i] as usize);
            if fv.len() != K + 1 {
                return None;
            }
            let c = local[i] as usize;
            Some(std::array::from_fn(|k| fv[(c + 1 + k) % (K + 1)]))
        })
        .collect()
}

/// The quad ring of interior vertex `v` starting at the edge towards `first`: (edge
/// neighbours, face-opposite vertices), counter-clockwise. `None` unless `v` is interior and
/// manifold with quads around it and `first` is a neighbour.
pub fn quad_ring_from(t: &Topology, v: usize, first: u32) -> Option<(Vec<u32>, Vec<u32>)> {
    let f0 = *t.vertex_faces(v).first()? as usize;
    let (mut edges, mut diagonals): (Vec<u32>, Vec<u32>) = face_ring::<3>(t, v, f0)?
        .iter()
        .map(|r| (r[0], r[1]))
        .unzip();
    let k = edges.iter().position(|&e| e == first)?;
    edges.rotate_left(k);
    diagonals.rotate_left(k);
    Some((edges, diagonals))
}

/// Vertices within `rings` rings of `seed`, a ring being every vertex of a face around a
/// vertex already in (so a quad's diagonal is one ring away), ascending.
pub fn vertices_within_rings(t: &Topology, seed: &[u32], rings: usize) -> Vec<u32> {
    let mut inside = vec![false; t.num_vertices()];
    let mut frontier: Vec<u32> = seed.to_vec();
    for &v in seed {
        inside[v as usize] = true;
    }
    for _ in 0..rings {
        // Nothing new to reach: more rings would only spin (a count may be huge).
        if frontier.is_empty() {
            break;
        }
        let mut next = Vec::new();
        for &v in &frontier {
            for &f in t.vertex_faces(v as usize) {
                for &w in t.face_vertices(f as usize) {
                    if !inside[w as usize] {
                        inside[w as usize] = true;
                        next.push(w);
                    }
                }
            }
        }
        frontier = next;
    }
    (0..t.num_vertices() as u32)
        .filter(|&v| inside[v as usize])
        .collect()
}

/// Faces with a vertex in `vertices`, ascending.
pub fn faces_touching(t: &Topology, vertices: &[u32]) -> Vec<u32> {
    let mut take = vec![false; t.num_faces()];
    for &v in vertices {
        for &f in t.vertex_faces(v as usize) {
            take[f as usize] = true;
        }
    }
    (0..t.num_faces() as u32)
        .filter(|&f| take[f as usize])
        .collect()
}

/// `faces` (ascending) grown until no vertex they touch is pinched, ascending. A vertex is
/// pinched when the faces around it that are in make more than one run of its fan: cut
/// out, it would be non-manifold, which a refinement of the piece refuses. A pinched vertex
/// (and a non-manifold one missing faces) gets all its faces, which may pinch others.
pub fn without_pinches(t: &Topology, faces: &[u32]) -> Vec<u32> {
    let mut taken = vec![false; t.num_faces()];
    let mut check: Vec<u32> = Vec::new();
    for &f in faces {
        taken[f as usize] = true;
        check.extend_from_slice(t.face_vertices(f as usize));
    }
    while let Some(v) = check.pop() {
        let around = t.vertex_faces(v as usize);
        if !is_pinched(t, v as usize, around, &taken) {
            continue;
        }
        for &f in around {
            if !taken[f as usize] {
                taken[f as usize] = true;
                check.extend_from_slice(t.face_vertices(f as usize));
            }
        }
    }
    (0..t.num_faces() as u32)
        .filter(|&f| taken[f as usize])
        .collect()
}

/// Whether the taken faces of `around` (vertex `v`'s faces, in fan order where `v` is
/// manifold) are neither all of them nor one run of the fan (cyclic for an interior vertex).
fn is_pinched(t: &Topology, v: usize, around: &[u32], taken: &[bool]) -> bool {
    let is_in = |i: usize| taken[around[i] as usize];
    let count = (0..around.len()).filter(|&i| is_in(i)).count();
    if count == around.len() {
        return false;
    }
    if t.is_non_manifold_vertex(v) {
        return true;
    }
    let cyclic = !t.is_boundary_vertex(v);
    let starts = (0..around.len())
        .filter(|&i| {
            let before = match i {
                0 if cyclic => is_in(around.len() - 1),
                0 => false,
                _ => is_in(i - 1),
            };
            is_in(i) && !before
        })
        .count();
    starts > 1
}

/// Faces within two rings of `targets` (the faces touching [`vertices_within_rings`] of
/// radius 1), ascending: what the masks of the targets' one-ring read.
pub fn faces_within_two_rings(t: &Topology, targets: &[u32]) -> Vec<u32> {
    faces_touching(t, &vertices_within_rings(t, targets, 1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::TopologyBuilder;

    /// An n × n grid of quads, vertex `j (n + 1) + i` at (i, j).
    fn grid(n: u32) -> Topology {
        let mut faces = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let v = j * (n + 1) + i;
                faces.extend([v, v + 1, v + n + 2, v + n + 1]);
            }
        }
        TopologyBuilder::new(((n + 1) * (n + 1)) as usize)
            .build(&vec![4; (n * n) as usize], &faces)
            .unwrap()
    }

    /// (i, j) of grid vertex `v`.
    fn at(n: u32, v: u32) -> (i64, i64) {
        ((v % (n + 1)) as i64, (v / (n + 1)) as i64)
    }

    #[test]
    fn rings_turn_counter_clockwise_from_the_given_neighbour() {
        let (n, centre) = (4, 12); // (2, 2)
        let t = grid(n);
        for from in ring_from(&t, centre, 13) {
            let ring = ring_from(&t, centre, from);
            assert_eq!(ring[0], from);
            // Consecutive neighbours turn by +90° about the centre (counter-clockwise).
            for k in 0..4 {
                let (a, b) = (at(n, ring[k]), at(n, ring[(k + 1) % 4]));
                let (c, d) = ((a.0 - 2, a.1 - 2), (b.0 - 2, b.1 - 2));
                assert_eq!((c.0 * d.1 - c.1 * d.0, c.0 * d.0 + c.1 * d.1), (1, 0));
            }
        }
        let (edges, diagonals) = quad_ring_from(&t, centre as usize, 17).unwrap();
        assert_eq!(edges[0], 17);
        for (e, d) in edges.iter().zip(&diagonals) {
            // Each diagonal is one step further round than its edge neighbour.
            let (a, b) = (at(n, *e), at(n, *d));
            assert_eq!((a.0 - b.0).abs() + (a.1 - b.1).abs(), 1);
        }
        assert!(
            quad_ring_from(&t, 0, 1).is_none(),
            "a boundary vertex has no ring"
        );
    }

    #[test]
    fn balls_and_rings_reach_as_far_as_their_radius() {
        let (n, centre) = (6, 24); // (3, 3)
        let t = grid(n);
        let ball = labelled_ball(&t, &[(centre, 25)], 2);
        // Radius 2 in edges: the vertices with |di| + |dj| ≤ 2, each once, the seed first.
        assert_eq!(ball[0], centre);
        let mut expected: Vec<u32> = (0..49)
            .filter(|&v| {
                let (i, j) = at(n, v);
                (i - 3).abs() + (j - 3).abs() <= 2
            })
            .collect();
        let mut got = ball.clone();
        got.sort_unstable();
        expected.sort_unstable();
        assert_eq!(got, expected);
        // Rings through faces reach diagonals too: a (2k + 1)² square.
        let square = vertices_within_rings(&t, &[centre], 2);
        assert_eq!(square.len(), 25);
        assert!(square.iter().all(|&v| {
            let (i, j) = at(n, v);
            (i - 3).abs() <= 2 && (j - 3).abs() <= 2
        }));
        // The faces those masks read: every face touching the 3 × 3 square, a 4 × 4 block.
        assert_eq!(faces_within_two_rings(&t, &[centre]).len(), 16);
        assert_eq!(faces_touching(&t, &[0]), vec![0]);
    }

    #[test]
    fn face_rings_name_each_face_from_the_vertex_on() {
        let t = grid(2);
        let rings = face_ring::<3>(&t, 4, t.vertex_faces(4)[0] as usize).unwrap();
        assert_eq!(rings.len(), 4);
        for r in &rings {
            // [next, opposite, previous] of a unit quad around (1, 1).
            let (a, b, c) = (at(2, r[0]), at(2, r[1]), at(2, r[2]));
            let d = |p: (i64, i64)| (p.0 - 1).abs() + (p.1 - 1).abs();
            assert_eq!((d(a), d(b), d(c)), (1, 2, 1));
        }
        assert!(
            face_ring::<2>(&t, 4, 0).is_none(),
            "quads are not triangles"
        );
    }
}
