use super::*;
use subd_mesh::TopologyBuilder;

/// A 6 x 5 grid of vertices cut into triangles (a boundary all round), with a
/// semi-sharp crease across it and a corner.
fn open_triangles() -> Topology {
    let (w, h) = (6u32, 5u32);
    let mut corners = Vec::new();
    for y in 0..h - 1 {
        for x in 0..w - 1 {
            let v = y * w + x;
            corners.extend_from_slice(&[v, v + 1, v + w + 1, v, v + w + 1, v + w]);
        }
    }
    let mut t = TopologyBuilder::new((w * h) as usize)
        .build(&vec![3; corners.len() / 3], &corners)
        .expect("valid grid");
    for x in 0..w - 1 {
        let e = t.find_edge(2 * w + x, 2 * w + x + 1).expect("grid edge");
        t.set_edge_sharpness(e as usize, 1.5);
    }
    t.set_vertex_sharpness((w + 2) as usize, 2.0);
    t
}

/// The smooth Loop rows agree bit for bit with the general mask machinery at every level
/// of an open, creased mesh, and leave the boundary and crease rows to it.
#[test]
fn smooth_loop_rows_match_the_general_masks() {
    let base = open_triangles();
    let r = OsdRefinement::new(&base, Sdc::Loop, &Options::default(), 3).expect("refine");
    let mut src: Vec<DVec3> = (0..base.num_vertices())
        .map(|v| {
            let x = v as f64;
            DVec3::new(x.sin(), (1.3 * x).cos(), 0.1 * x)
        })
        .collect();
    let (mut fast, mut general) = (0, 0);
    for level in 1..=3 {
        let step = r.step(level);
        for row in 0..step.layout.num_child_vertices {
            let expected: DVec3 = step.general_point(row, &src[..], &[][..]);
            match step.smooth_loop_point(row, &src[..]) {
                Some(p) => {
                    fast += 1;
                    assert_eq!(
                        p.to_array().map(f64::to_bits),
                        expected.to_array().map(f64::to_bits)
                    );
                }
                None => general += 1,
            }
        }
        src = step.points(&src);
    }
    assert!(
        fast > 0 && general > 0,
        "{fast} fast rows, {general} general rows"
    );
}
