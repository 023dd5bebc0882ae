//! ACC (Loop & Schaefer 2008) against the exact limit surface: equal where the mesh is
//! regular, corners at the exact limit points, a small distance elsewhere that shrinks as
//! the control mesh is refined, and a normal field that agrees across faces.

use glam::DVec3;
use subd_limit::acc::{AccPatch, acc_patches};
use subd_limit::eval::{FaceParam, LimitEvaluator};
use subd_mesh::Topology;
use subd_schemes::{Options, Refinement, Scheme};

/// A pentagonal prism (valence-3 corners, valence-5 cap centres once refined) refined
/// `levels` times, as a base mesh.
fn prism(levels: usize) -> (Topology, Vec<DVec3>) {
    let (topo, pts) = subd_tests::pentagonal_prism();
    let r = Refinement::new(&topo, Scheme::CatmullClark, &Options::default(), levels).unwrap();
    let p = r.refine_points(&pts).pop().unwrap();
    (r.into_topology(levels), p)
}

const GRID: [f64; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];

/// Max and RMS distance between ACC and the exact surface over a 5 × 5 grid per face, and
/// the largest angle between their normals, relative to the bounding-box diagonal.
fn compare(t: &Topology, p: &[DVec3], patches: &[AccPatch]) -> (f64, f64, f64) {
    let ev = LimitEvaluator::new(t, &Scheme::CatmullClark, &Options::default()).unwrap();
    let pp = ev.prepare(p);
    let (lo, hi) = subd_mesh::bounding_box(p.iter().copied()).unwrap();
    let diag = (hi - lo).length();
    let (mut max, mut sum, mut count, mut angle) = (0.0f64, 0.0, 0usize, 0.0f64);
    for patch in patches {
        for &u in &GRID {
            for &v in &GRID {
                let exact = ev
                    .evaluate(
                        &pp,
                        FaceParam {
                            face: patch.face,
                            sub: 0,
                            u,
                            v,
                        },
                    )
                    .unwrap();
                let d = (patch.position(u, v) - exact.position).length() / diag;
                max = max.max(d);
                sum += d * d;
                count += 1;
                let (a, b) = (patch.normal(u, v), exact.normal());
                angle = angle.max(a.cross(b).length().atan2(a.dot(b)));
            }
        }
    }
    (max, (sum / count as f64).sqrt(), angle)
}

#[test]
fn regular_regions_are_the_exact_b_spline() {
    let torus = subd_mesh::primitives::torus(12, 9, 3.0, 1.0);
    let patches = acc_patches(&torus.topology, &torus.positions).unwrap();
    let (max, _, angle) = compare(&torus.topology, &torus.positions, &patches);
    assert!(max < 1e-14, "{max:e}");
    assert!(angle < 1e-12, "{angle:e}");
}

#[test]
fn acc_approximates_the_limit_and_converges_under_refinement() {
    let mut previous = f64::INFINITY;
    for levels in 1..=3 {
        let (t, p) = prism(levels);
        let patches = acc_patches(&t, &p).unwrap();
        // Corners are the exact limit points.
        let ev = LimitEvaluator::new(&t, &Scheme::CatmullClark, &Options::default()).unwrap();
        let pp = ev.prepare(&p);
        for patch in &patches {
            for (u, v) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                let exact = ev
                    .evaluate(
                        &pp,
                        FaceParam {
                            face: patch.face,
                            sub: 0,
                            u,
                            v,
                        },
                    )
                    .unwrap();
                assert!((patch.position(u, v) - exact.position).length() < 1e-14);
            }
        }
        let (max, rms, angle) = compare(&t, &p, &patches);
        eprintln!(
            "prism refined {levels}×: {} faces, ACC − exact: max {max:.3e}, rms {rms:.3e} of the bbox diagonal; normals within {angle:.3e} rad",
            t.num_faces()
        );
        assert!(max > 0.0 && max < 1e-2, "{max:e}");
        assert!(
            max < previous,
            "distance must shrink: {max:e} after {previous:e}"
        );
        previous = max;
    }
}

#[test]
fn acc_normals_agree_across_faces_at_corners() {
    let (t, p) = prism(2);
    let patches = acc_patches(&t, &p).unwrap();
    let mut corner_jump = 0.0f64;
    let mut edge_jump = 0.0f64;
    let on_edge = |k: usize, s: f64| match k {
        0 => (s, 0.0),
        1 => (1.0, s),
        2 => (1.0 - s, 1.0),
        _ => (0.0, 1.0 - s),
    };
    for e in 0..t.num_edges() {
        let ef = t.edge_faces(e);
        let l = t.edge_face_local_indices(e);
        for s in [0.0, 0.3, 0.5, 1.0] {
            let (u0, v0) = on_edge(l[0] as usize, s);
            let (u1, v1) = on_edge(l[1] as usize, 1.0 - s);
            let a = patches[ef[0] as usize].normal(u0, v0);
            let b = patches[ef[1] as usize].normal(u1, v1);
            let angle = a.cross(b).length().atan2(a.dot(b));
            if s == 0.0 || s == 1.0 {
                corner_jump = corner_jump.max(angle);
            } else {
                edge_jump = edge_jump.max(angle);
            }
        }
    }
    eprintln!(
        "ACC normal jumps across edges: at corners {corner_jump:.3e} rad, inside edges {edge_jump:.3e} rad"
    );
    assert!(corner_jump < 1e-12, "{corner_jump:e}");
    assert!(edge_jump < 0.05, "{edge_jump:e}");
}

#[test]
fn acc_patches_serialise_to_json() {
    let (t, p) = prism(1);
    let patches = acc_patches(&t, &p).unwrap();
    let json = serde_json::to_value(&patches).unwrap();
    assert_eq!(json.as_array().unwrap().len(), t.num_faces());
    assert_eq!(json[0]["geometry"].as_array().unwrap().len(), 16);
    assert_eq!(json[0]["tangent_u"].as_array().unwrap().len(), 12);
    let x = json[3]["geometry"][5][1].as_f64().unwrap();
    assert_eq!(x, patches[3].geometry[5][1]);
}
