//! Uniform refinement of topology and points on the device against the CPU's: every
//! OpenSubdiv Catmull-Clark and Loop shape (and a torus), three levels, the face vertices
//! bit for bit and the points within 1e-6 of the bounding-box diagonal of the CPU's f64
//! points (the device's own masks on the shapes whose sharpness is all or nothing, the
//! CPU's stencil tables on the others).

mod common;

use common::{diagonal, gpu, osd_shapes, read_shape};
use subd_gpu::{GpuError, GpuUniformRefinement};
use subd_mesh::{DVec3, Mesh};
use subd_schemes::{Options, Refinement, Scheme};

fn shapes() -> Vec<(String, Scheme, Mesh)> {
    let mut out: Vec<(String, Scheme, Mesh)> = osd_shapes()
        .into_iter()
        .filter(|(_, scheme)| *scheme != Scheme::Bilinear)
        .map(|(path, scheme)| {
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            (name, scheme, read_shape(&path))
        })
        .collect();
    out.push((
        "torus 12 x 9".into(),
        Scheme::CatmullClark,
        subd_mesh::primitives::torus(12, 9, 1.0, 0.3),
    ));
    out
}

#[test]
fn every_shape_refines_on_the_device_as_on_the_cpu() {
    let Some(gpu) = gpu() else { return };
    let (mut checked, mut by_masks, mut worst) = (Vec::new(), Vec::new(), 0.0_f64);
    for (name, scheme, mesh) in shapes() {
        let topology = &mesh.topology;
        let rules = Options::from_hints(&mesh.hints);
        let Ok(refinement) = Refinement::new(topology, scheme.clone(), &rules, 3) else {
            continue; // Loop on quads
        };
        let on_device =
            GpuUniformRefinement::new(&gpu, topology, &scheme, &rules, &mesh.positions, 3)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
        if on_device.points_by_masks() {
            by_masks.push(name.clone());
        }
        let cpu = refinement.refine_points(&mesh.positions);
        let tolerance = 1e-6 * diagonal(&mesh.positions);
        for (level, cpu_level) in cpu.iter().enumerate().skip(1) {
            let want = refinement.topology(level).all_face_vertices();
            let got = on_device.read_face_vertices(&gpu, level).unwrap();
            assert!(got == want, "{name}: level {level}: face vertices differ");
            if level == 3 {
                // The triangle list a renderer draws: quads split (a, b, c), (a, c, d).
                let list = on_device.triangle_indices(&gpu, level).unwrap();
                let bytes = (want.len() * if scheme == Scheme::Loop { 4 } else { 6 }) as u64;
                let got: Vec<u32> = gpu.read_u32(&list, bytes).unwrap();
                let split: Vec<u32> = if scheme == Scheme::Loop {
                    want.to_vec()
                } else {
                    want.chunks_exact(4)
                        .flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]])
                        .collect()
                };
                assert!(got == split, "{name}: triangle list");
            }
            let points = gpu.read_points(on_device.points(level).unwrap()).unwrap();
            assert_eq!(points.len(), cpu_level.len(), "{name}: level {level}");
            for (k, (p, q)) in points.iter().zip(cpu_level).enumerate() {
                let d = p.distance(*q);
                assert!(d <= tolerance, "{name}: level {level}: vertex {k}: {d:e}");
                worst = worst.max(d / tolerance * 1e-6);
            }
        }
        checked.push(name);
    }
    eprintln!(
        "{} shapes refined on the device, {} with the device's masks ({}); worst {worst:e} of the diagonal",
        checked.len(),
        by_masks.len(),
        by_masks.join(", ")
    );
    assert!(checked.len() >= 100, "only {} shapes", checked.len());
    assert!(by_masks.len() >= 55, "only {} by the masks", by_masks.len());
}

/// The base positions change, the topology stays: a new frame, the same faces.
#[test]
fn new_positions_refine_again() {
    let Some(gpu) = gpu() else { return };
    let torus = subd_mesh::primitives::torus(8, 6, 1.0, 0.3);
    let scheme = Scheme::CatmullClark;
    let refinement =
        Refinement::new(&torus.topology, scheme.clone(), &Options::default(), 2).unwrap();
    let r = GpuUniformRefinement::new(
        &gpu,
        &torus.topology,
        &scheme,
        &Options::default(),
        &torus.positions,
        2,
    )
    .unwrap();
    let moved: Vec<DVec3> = torus
        .positions
        .iter()
        .map(|p| *p * 2.0 + DVec3::X)
        .collect();
    r.update_points(&gpu, &moved).unwrap();
    let want = refinement.points_at(&moved, 2);
    let got = gpu.read_points(r.points(2).unwrap()).unwrap();
    let tolerance = 1e-6 * diagonal(&moved);
    assert!(
        got.iter()
            .zip(&want)
            .all(|(p, q)| p.distance(*q) <= tolerance)
    );
    assert_eq!(
        r.read_face_vertices(&gpu, 2).unwrap(),
        refinement.topology(2).all_face_vertices()
    );
    // A level that was not refined has no triangles.
    assert!(matches!(
        r.triangle_indices(&gpu, 3),
        Err(GpuError::Mismatch(_))
    ));
}

#[test]
fn what_the_device_does_not_refine_is_an_error() {
    let Some(gpu) = gpu() else { return };
    let o = Options::default();
    let corners = [DVec3::ZERO, DVec3::X, DVec3::ONE, DVec3::Y];
    let torus = subd_mesh::primitives::torus(4, 4, 1.0, 0.3);
    let sqrt3 = GpuUniformRefinement::new(
        &gpu,
        &torus.topology,
        &Scheme::Sqrt3,
        &o,
        &torus.positions,
        1,
    );
    assert!(matches!(sqrt3, Err(GpuError::Unsupported(_))));
    let few = GpuUniformRefinement::new(
        &gpu,
        &torus.topology,
        &Scheme::CatmullClark,
        &o,
        &corners,
        1,
    );
    assert!(matches!(few, Err(GpuError::Mismatch(_))));
    let quads = GpuUniformRefinement::new(
        &gpu,
        &torus.topology,
        &Scheme::Loop,
        &o,
        &torus.positions,
        1,
    );
    assert!(matches!(quads, Err(GpuError::Mismatch(_))));
}
