//! The control points of a regular patch: the 16 points of a bicubic B-spline quad, the 12
//! of a quartic box-spline triangle, in OpenSubdiv's order (`PatchBuilder::
//! GetRegularPatchPoints`), with the points beyond boundary edges filled with the face's
//! first vertex (the basis gives them weight zero).
//!
//! Around a corner `v` of a face, the next face counter-clockwise is the one across the
//! face's edge that arrives at `v`; OpenSubdiv's rings run the same way, so "two faces on"
//! is two such steps.

use subd_mesh::Topology;

/// The 4 × 4 grid rows bottom to top; per corner, its own index and its three outer points
/// in the order they are read from the faces around it.
const QUAD_CORNER_POINTS: [[usize; 4]; 4] =
    [[5, 4, 0, 1], [6, 2, 3, 7], [10, 11, 15, 14], [9, 13, 12, 8]];

/// The box-spline rows {0,1,2}, {3,4,5,6}, {7,8,9}, {10,11}; per corner as above.
const TRI_CORNER_POINTS: [[usize; 4]; 3] = [[4, 7, 3, 0], [5, 1, 2, 6], [8, 9, 11, 10]];

/// Position of `v` in face `g`.
fn corner_of(t: &Topology, g: usize, v: u32) -> usize {
    t.face_vertices(g)
        .iter()
        .position(|&x| x == v)
        .expect("a face around a vertex has it as a corner")
}

/// The face across edge `e` from `g`.
fn across(t: &Topology, g: usize, e: u32) -> usize {
    let faces = t.edge_faces(e as usize);
    if faces[0] as usize == g {
        faces[1] as usize
    } else {
        faces[0] as usize
    }
}

/// The next face counter-clockwise around corner `v` of `g`: across `g`'s edge into `v`.
fn next_around(t: &Topology, g: usize, v: u32) -> usize {
    let j = corner_of(t, g, v);
    let n = t.face_size(g);
    across(t, g, t.face_edges(g)[(j + n - 1) % n])
}

/// The previous face around corner `v` of `g`: across `g`'s edge out of `v`.
fn prev_around(t: &Topology, g: usize, v: u32) -> usize {
    let j = corner_of(t, g, v);
    across(t, g, t.face_edges(g)[j])
}

/// Vertex `k` places after `v` in face `g`.
fn after(t: &Topology, g: usize, v: u32, k: usize) -> u32 {
    let fv = t.face_vertices(g);
    fv[(corner_of(t, g, v) + k) % fv.len()]
}

/// The 16 points of regular quad `f` whose boundary edges are `mask` (bit `i`: edge `i`).
pub(crate) fn quad_points(t: &Topology, f: usize, mask: u8) -> [u32; 16] {
    let fv = t.face_vertices(f);
    let fill = fv[0];
    let mut out = [fill; 16];
    for (i, slots) in QUAD_CORNER_POINTS.iter().enumerate() {
        let v = fv[i];
        out[slots[0]] = v;
        let leading = mask & (1 << i) != 0;
        let trailing = mask & (1 << ((i + 3) % 4)) != 0;
        match (leading, trailing) {
            (false, false) => {
                let opposite = next_around(t, next_around(t, f, v), v);
                for k in 1..4 {
                    out[slots[k]] = after(t, opposite, v, k);
                }
            }
            (true, true) => {}
            (true, false) => out[slots[1]] = after(t, next_around(t, f, v), v, 3),
            (false, true) => out[slots[3]] = after(t, prev_around(t, f, v), v, 1),
        }
    }
    out
}

/// The edge and vertex bits of OpenSubdiv's five-bit triangle boundary mask
/// (`decodeTriBoundaryMask`).
fn decode_triangle_mask(mask: u8) -> (u8, u8) {
    const VERTICES_OF_EDGES: [u8; 8] = [0, 3, 6, 7, 5, 7, 7, 7];
    let lower = mask & 7;
    match mask >> 3 {
        1 => (0, lower),
        2 => (lower, 7),
        _ => (lower, VERTICES_OF_EDGES[lower as usize]),
    }
}

/// The 12 points of regular triangle `f` with OpenSubdiv's boundary mask `mask`.
pub(crate) fn triangle_points(t: &Topology, f: usize, mask: u8) -> [u32; 12] {
    let fv = t.face_vertices(f);
    let fill = fv[0];
    let mut out = [fill; 12];
    let (e_mask, v_mask) = if mask == 0 {
        (0, 0)
    } else {
        decode_triangle_mask(mask)
    };
    for (i, slots) in TRI_CORNER_POINTS.iter().enumerate() {
        let v = fv[i];
        out[slots[0]] = v;
        let leading = e_mask & (1 << i) != 0;
        let trailing = e_mask & (1 << ((i + 2) % 3)) != 0;
        if v_mask & (1 << i) == 0 {
            let f2 = next_around(t, next_around(t, f, v), v);
            let f3 = next_around(t, f2, v);
            out[slots[1]] = after(t, f2, v, 1);
            out[slots[2]] = after(t, f3, v, 1);
            out[slots[3]] = after(t, f3, v, 2);
        } else if leading && trailing {
        } else if leading {
            // The corner's faces run from `f`: the one two steps on has the outer points.
            let f2 = next_around(t, next_around(t, f, v), v);
            out[slots[1]] = after(t, f2, v, 1);
            out[slots[2]] = after(t, f2, v, 2);
        } else if trailing {
            let f0 = prev_around(t, prev_around(t, f, v), v);
            out[slots[3]] = after(t, f0, v, 1);
        } else {
            // A boundary vertex whose edges in `f` are interior: `f` is the middle face.
            out[slots[1]] = after(t, next_around(t, f, v), v, 2);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use subd_mesh::TopologyBuilder;

    /// A 4 × 4 grid of vertices `x + 4 y`, quads counter-clockwise.
    fn grid() -> Topology {
        let mut faces = Vec::new();
        for y in 0..3u32 {
            for x in 0..3u32 {
                let v = x + 4 * y;
                faces.extend([v, v + 1, v + 5, v + 4]);
            }
        }
        TopologyBuilder::new(16).build(&[4; 9], &faces).unwrap()
    }

    #[test]
    fn the_centre_quad_reads_the_whole_grid_in_row_order() {
        let t = grid();
        assert_eq!(quad_points(&t, 4, 0), std::array::from_fn(|k| k as u32));
    }

    #[test]
    fn a_bottom_boundary_quad_fills_the_missing_row_with_its_first_vertex() {
        let t = grid();
        // Face 1 = (1, 2, 6, 5): edge 0 on the boundary.
        let p = quad_points(&t, 1, 1);
        assert_eq!(&p[..4], &[1, 1, 1, 1]);
        assert_eq!(&p[4..], &[0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11]);
    }

    #[test]
    fn triangle_masks_decode_as_encoded() {
        assert_eq!(decode_triangle_mask(0b01_001), (0, 1));
        assert_eq!(decode_triangle_mask(0b10_010), (2, 7));
        assert_eq!(decode_triangle_mask(0b00_011), (3, 7));
    }
}
