//! `subd adaptive`: formats, JSON, closedness, refusals.

use super::*;

#[test]
fn adaptive_writes_each_format_and_reports_json() {
    let s = Scratch::new("adaptive");
    let input =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/meshes/torus_creased.obj");
    for ext in ["obj", "ply", "glb"] {
        let out = s.0.join(format!("torus.{ext}"));
        let (code, stdout, err) = subd(&[
            "adaptive",
            "--scheme",
            "catmull-clark",
            "--max-distance",
            "2e-3",
            "--levels",
            "4",
            "--limit",
            input.to_str().unwrap(),
            out.to_str().unwrap(),
            "--json",
        ]);
        assert_eq!(code, 0, "{err}");
        let j: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        let faces = j["faces"].as_u64().unwrap();
        let per_level: u64 = j["faces_per_level"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_u64().unwrap())
            .sum();
        assert_eq!(per_level, faces);
        assert!(faces < j["uniform_faces"].as_u64().unwrap());
        assert_eq!(j["conforming"], true);
        assert_eq!(j["boundary_edges"], 0);
        assert_eq!(j["input_boundary_edges"], 0);
        assert_eq!(j["nonmanifold_edges"], 0);
        assert!(j["max_level_difference_edge"].as_u64().unwrap() <= 1);
        assert!(j["max_level_difference_vertex"].as_u64().unwrap() <= 1);
        assert!(j["min_angle_degrees"].as_f64().unwrap() > 1.0);
        assert!(j["max_distance_to_limit_relative"].as_f64().unwrap() <= 2e-3);
        for phase in ["read", "hierarchy", "mesh", "report", "write", "total"] {
            assert!(j["seconds"][phase].as_f64().unwrap() >= 0.0);
        }
        assert!(out.exists());
    }
    // The PLY carries the level of each face and the limit normals.
    let ply = std::fs::read(s.0.join("torus.ply")).unwrap();
    let header = String::from_utf8_lossy(&ply[..ply.len().min(800)]).to_string();
    assert!(header.contains("property uchar level"), "{header}");
    assert!(header.contains("property double nx"), "{header}");
    let obj = std::fs::read_to_string(s.0.join("torus.obj")).unwrap();
    assert!(obj.lines().any(|l| l.starts_with("vn ")));
    assert!(obj.lines().any(|l| l.starts_with("f ") && l.contains("//")));
    // The written mesh reads back closed.
    let (code, stdout, _) = subd(&["info", s.0.join("torus.ply").to_str().unwrap(), "--json"]);
    assert_eq!(code, 0);
    let j: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(j["boundary_edges"], 0);

    // Selections and the other criteria; with no criterion, uniform to --levels.
    let faces = s.file("faces.txt", b"0 1 # two base faces\n5\n");
    let vertices = s.file("vertices.txt", b"0 1 2\n");
    for extra in [
        vec!["--select-faces", faces.to_str().unwrap()],
        vec!["--select-vertices", vertices.to_str().unwrap()],
        vec!["--flatness", "20"],
        vec!["--curvature", "40"],
        vec!["--dihedral", "25"],
        vec![],
    ] {
        let out = s.0.join("sel.obj");
        let mut args = vec!["adaptive", "--scheme", "catmull-clark", "--levels", "2"];
        args.extend_from_slice(&extra);
        args.extend_from_slice(&[input.to_str().unwrap(), out.to_str().unwrap(), "--json"]);
        let (code, stdout, err) = subd(&args);
        assert_eq!(code, 0, "{extra:?}: {err}");
        let j: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        assert_eq!(j["conforming"], true, "{extra:?}");
        let faces = j["faces"].as_u64().unwrap();
        if extra.is_empty() {
            assert_eq!(faces, 72 * 16);
            assert_eq!(j["transition_faces"], 0);
        } else if extra[0].starts_with("--select") {
            assert!(faces < 72 * 16, "{extra:?}");
            assert!(j["transition_faces"].as_u64().unwrap() > 0, "{extra:?}");
        } else {
            assert!(faces <= 72 * 16, "{extra:?}");
        }
    }
}

#[test]
fn adaptive_loop_on_a_shape_is_closed() {
    let s = Scratch::new("adaptive-loop");
    let input = meshes().join("loop_cube.obj");
    let out = s.0.join("cube.ply");
    let (code, stdout, err) = subd(&[
        "adaptive",
        "--scheme",
        "loop",
        "--flatness",
        "30",
        "--levels",
        "3",
        input.to_str().unwrap(),
        out.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let j: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(j["scheme"], "loop");
    assert_eq!(j["conforming"], true);
    assert_eq!(j["boundary_edges"], 0);
}

#[test]
fn adaptive_bad_input_exits_2_without_output() {
    let s = Scratch::new("adaptive-bad");
    let quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
    let input = s.file("quad.obj", quad.as_bytes());
    let faces_bad = s.file("bad_faces.txt", b"0\n7\n");
    let faces_word = s.file("word_faces.txt", b"0 x\n");
    let verts_bad = s.file("bad_vertices.txt", b"4\n");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["--scheme", "loop"],
            "face 0 has 4 vertices; the Loop scheme needs triangles",
        ),
        (
            vec!["--scheme", "catmull-clark", "--flatness", "nan"],
            "--flatness NaN",
        ),
        (
            vec!["--scheme", "catmull-clark", "--flatness", "200"],
            "--flatness 200",
        ),
        (
            vec!["--scheme", "catmull-clark", "--dihedral", "-1"],
            "--dihedral -1",
        ),
        (
            vec!["--scheme", "catmull-clark", "--max-distance", "0"],
            "--max-distance 0",
        ),
        (
            vec!["--scheme", "catmull-clark", "--curvature", "-2"],
            "--curvature -2",
        ),
        (
            vec!["--scheme", "catmull-clark", "--levels", "16"],
            "--levels 16",
        ),
        (
            vec![
                "--scheme",
                "catmull-clark",
                "--select-faces",
                faces_bad.to_str().unwrap(),
            ],
            "bad_faces.txt:2: face 7 does not exist (the mesh has 1 faces)",
        ),
        (
            vec![
                "--scheme",
                "catmull-clark",
                "--select-faces",
                faces_word.to_str().unwrap(),
            ],
            "word_faces.txt:1: \"x\" is not a face index",
        ),
        (
            vec![
                "--scheme",
                "catmull-clark",
                "--select-vertices",
                verts_bad.to_str().unwrap(),
            ],
            "bad_vertices.txt:1: vertex 4 does not exist (the mesh has 4 vertices)",
        ),
    ];
    for (extra, expect) in cases {
        let out = s.0.join("out.obj");
        let mut args = vec!["adaptive"];
        args.extend_from_slice(&extra);
        args.extend_from_slice(&[input.to_str().unwrap(), out.to_str().unwrap()]);
        let (code, _, err) = subd(&args);
        assert_eq!(code, 2, "{extra:?}: {err}");
        let lines: Vec<&str> = err.lines().collect();
        assert_eq!(lines.len(), 1, "{extra:?}: {err:?}");
        assert!(
            err.contains(expect),
            "{extra:?}: expected {expect:?} in {err:?}"
        );
        assert!(!err.contains("panicked"), "{err}");
        assert!(!out.exists(), "{extra:?}: output written");
    }
    let (code, _, err) = subd(&[
        "adaptive",
        "--scheme",
        "catmull-clark",
        input.to_str().unwrap(),
        input.to_str().unwrap(),
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("would overwrite the input"), "{err}");
}

#[test]
fn adaptive_says_when_the_level_cap_stops_the_distance_short() {
    let s = Scratch::new("adaptive-tolerance");
    let input =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/meshes/torus_creased.obj");
    let out = s.0.join("torus.obj");
    let run = |extra: &[&str]| {
        let mut args = vec!["adaptive", "--scheme", "catmull-clark"];
        args.extend_from_slice(extra);
        args.extend_from_slice(&[input.to_str().unwrap(), out.to_str().unwrap(), "--json"]);
        let (code, stdout, err) = subd(&args);
        assert_eq!(code, 0, "{extra:?}: {err}");
        let j: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        (j, err)
    };
    for limit in [&[][..], &["--limit"][..]] {
        // One level cannot reach 1e-4: a warning names a deeper level, the JSON says so.
        let (j, err) = run(&[&["--max-distance", "1e-4", "--levels", "1"][..], limit].concat());
        assert_eq!(j["tolerance_met"], false, "{limit:?}");
        let d = j["max_distance_to_limit_relative"].as_f64().unwrap();
        assert!(d > 1e-4, "{limit:?}: {d}");
        let warning: Vec<&str> = err.lines().filter(|l| l.contains("not met")).collect();
        assert_eq!(warning.len(), 1, "{limit:?}: {err}");
        assert!(warning[0].starts_with("subd: warning: "), "{err}");
        assert!(
            warning[0].contains("max-distance 1e-4 not met: levels 1 stopped"),
            "{err}"
        );
        let level: usize = warning[0]
            .split("about level ")
            .nth(1)
            .and_then(|r| r.split_whitespace().next())
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("no level in {err}"));
        // By the ~4× fall per level the estimate claims.
        let want = 1 + (d / 1e-4).log(4.0).ceil() as usize;
        assert_eq!(level, want, "{err}");
        assert!(level > 1, "{err}");

        // Enough levels: met, no warning.
        let (j, err) = run(&[&["--max-distance", "2e-3", "--levels", "4"][..], limit].concat());
        assert_eq!(j["tolerance_met"], true, "{limit:?}");
        assert!(j["max_distance_to_limit_relative"].as_f64().unwrap() <= 2e-3);
        assert!(!err.contains("not met"), "{err}");
    }
    // No distance criterion: the distance is measured only on request.
    let (j, _) = run(&["--flatness", "20", "--levels", "2"]);
    assert!(j["max_distance_to_limit"].is_null() && j["tolerance_met"].is_null());
    assert!(
        j.as_object()
            .unwrap()
            .contains_key("max_distance_to_limit_relative")
    );
    let (j, _) = run(&["--flatness", "20", "--levels", "2", "--report-distance"]);
    assert!(j["max_distance_to_limit_relative"].as_f64().unwrap() > 0.0);
    assert!(j["tolerance_met"].is_null());
}
