//! `subd tessellate`: watertight output and the rate check.

use super::*;

#[test]
fn tessellate_is_watertight_and_checks_its_rate() {
    let s = Scratch::new("tessellate");
    for (scheme, shape, rate, faces_per_base) in [
        ("catmull-clark", "catmark_pyramid.obj", "4", None),
        ("catmull-clark", "catmark_torus.obj", "5", Some(25)),
        ("loop", "loop_icosahedron.obj", "3", Some(9)),
    ] {
        let input = meshes().join(shape);
        let out = s.0.join(format!("{shape}.obj"));
        let (code, stdout, err) = subd(&[
            "tessellate",
            "--scheme",
            scheme,
            "--rate",
            rate,
            input.to_str().unwrap(),
            out.to_str().unwrap(),
            "--json",
        ]);
        assert_eq!(code, 0, "{shape}: {err}");
        let report: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        let base = subd_io::read_mesh(&input, &subd_io::ReadOptions::default()).unwrap();
        let mesh = subd_io::read_mesh(&out, &subd_io::ReadOptions::default()).unwrap();
        let topo = &mesh.mesh.topology;
        if let Some(k) = faces_per_base {
            assert_eq!(
                topo.num_faces(),
                k * base.mesh.topology.num_faces(),
                "{shape}"
            );
        }
        assert_eq!(report["faces"].as_u64(), Some(topo.num_faces() as u64));
        // Closed in, closed and manifold out: every edge between two faces, shared samples.
        assert!(
            (0..topo.num_edges()).all(|e| topo.edge_faces(e).len() == 2),
            "{shape}"
        );
        assert_eq!(
            topo.num_vertices() + topo.num_faces() - topo.num_edges(),
            base.mesh.topology.num_vertices() + base.mesh.topology.num_faces()
                - base.mesh.topology.num_edges(),
            "{shape}: the Euler characteristic is kept"
        );
        let text = std::fs::read_to_string(&out).unwrap();
        assert_eq!(
            text.lines().filter(|l| l.starts_with("vn ")).count(),
            topo.num_vertices()
        );
    }
    // An odd rate cannot split a non-quad's sides between its quad sub-faces.
    let pyramid = meshes().join("catmark_pyramid.obj");
    let out = s.0.join("odd.obj");
    for (rate, expect) in [("3", "use an even rate"), ("0", "expected 1 to")] {
        let (code, _, err) = subd(&[
            "tessellate",
            "--scheme",
            "catmull-clark",
            "--rate",
            rate,
            pyramid.to_str().unwrap(),
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(expect), "{err}");
        assert!(!out.exists());
    }
}

/// A rate that is a power of two takes uniform refinement and the last level's limit masks:
/// the file holds the evaluator's samples (`tessellate`, one patch per sample), in its order.
#[test]
fn tessellate_at_a_power_of_two_writes_the_evaluated_samples() {
    use subd_limit::eval::LimitEvaluator;
    use subd_limit::tessellation::tessellate;
    let s = Scratch::new("tessellate_pow2");
    for (scheme_arg, scheme, shape) in [
        (
            "catmull-clark",
            subd_schemes::Scheme::CatmullClark,
            "catmark_pyramid.obj",
        ),
        ("loop", subd_schemes::Scheme::Loop, "loop_icosahedron.obj"),
    ] {
        let input = meshes().join(shape);
        let out = s.0.join(format!("{shape}.obj"));
        let (code, _, err) = subd(&[
            "tessellate",
            "--scheme",
            scheme_arg,
            "--rate",
            "4",
            input.to_str().unwrap(),
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{shape}: {err}");
        let base = subd_io::read_mesh(&input, &subd_io::ReadOptions::default()).unwrap();
        let options = subd_schemes::Options::from_hints(&base.mesh.hints);
        let ev = LimitEvaluator::new(&base.mesh.topology, &scheme, &options).unwrap();
        let reference = tessellate(&ev, &ev.prepare(&base.mesh.positions), 4).unwrap();
        let written = subd_io::read_mesh(&out, &subd_io::ReadOptions::default()).unwrap();
        let (p, t) = (&written.mesh.positions, &written.mesh.topology);
        assert_eq!(p.len(), reference.positions.len(), "{shape}");
        assert_eq!(
            t.all_face_vertices(),
            &reference.face_vertices[..],
            "{shape}"
        );
        for (a, b) in p.iter().zip(&reference.positions) {
            assert!((*a - *b).length() < 1e-9, "{shape}: {a} vs {b}");
        }
    }
}
