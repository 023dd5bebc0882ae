//! `subd refine`: formats, JSON, refusals, progress, `--limit`, two-phase and the split schemes.

use super::*;

#[test]
fn refine_writes_each_format_and_reports_json() {
    let s = Scratch::new("refine");
    let input =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/meshes/torus_creased.obj");
    for ext in ["obj", "ply", "glb"] {
        let out = s.0.join(format!("torus.{ext}"));
        let (code, stdout, err) = subd(&[
            "refine",
            "--scheme",
            "catmull-clark",
            "--levels",
            "2",
            input.to_str().unwrap(),
            out.to_str().unwrap(),
            "--json",
        ]);
        assert_eq!(code, 0, "{err}");
        let j: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        // 72 quads -> 72 * 16 after two levels; a closed quad mesh has V = F and E = 2F.
        assert_eq!(j["output_counts"]["faces"], 1152);
        assert_eq!(j["output_counts"]["vertices"], 1152);
        assert_eq!(j["input_counts"]["faces"], 72);
        for phase in ["read", "topology", "positions", "write", "total"] {
            assert!(j["seconds"][phase].as_f64().unwrap() >= 0.0);
        }
        assert!(out.exists());
    }
    // The OBJ keeps the decayed tags: the 2.5 crease ring is 0.5 after two levels, the
    // infinitely sharp ring stays infinite, the corner (3) is 1.
    let (code, stdout, _) = subd(&["info", s.0.join("torus.obj").to_str().unwrap(), "--json"]);
    assert_eq!(code, 0);
    let j: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(j["infinite_creases"], 6 * 4);
    assert_eq!(j["semi_sharp_creases"], 6 * 4);
    assert_eq!(j["corners"], 1);
    let text = std::fs::read_to_string(s.0.join("torus.obj")).unwrap();
    assert!(
        text.lines()
            .any(|l| l.starts_with("t crease 2/1/0") && l.ends_with(" 0.5"))
    );
    assert!(
        text.lines()
            .any(|l| l.starts_with("t corner 1/1/0") && l.ends_with(" 1"))
    );
}

#[test]
fn refine_bad_input_exits_2_without_output() {
    let s = Scratch::new("refine-bad");
    let quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
    let cases: &[(&str, String, &[&str], &str)] = &[
        (
            "quads.obj",
            quad.into(),
            &["--scheme", "loop"],
            "face 0 has 4 vertices; the Loop scheme needs triangles",
        ),
        (
            "neg.obj",
            format!("{quad}t crease 2/1/0 0 1 -1\n"),
            &["--scheme", "catmull-clark"],
            "invalid sharpness -1",
        ),
        (
            "nan.obj",
            "v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".into(),
            &["--scheme", "loop"],
            "non-finite coordinate",
        ),
        (
            "ok.obj",
            quad.into(),
            &["--scheme", "kobbelt"],
            "invalid value 'kobbelt'",
        ),
        (
            "quads3.obj",
            quad.into(),
            &["--scheme", "sqrt3"],
            "face 0 has 4 vertices; the sqrt3 scheme needs triangles",
        ),
        (
            "semi.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\nt crease 2/1/0 1 2 2.5\n".into(),
            &["--scheme", "butterfly"],
            "supports only infinitely sharp creases",
        ),
        (
            "crease_ds.obj",
            "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\nf 1 2 5 4\nf 2 3 6 5\nt crease 2/1/0 1 4 10\n".into(),
            &["--scheme", "doo-sabin"],
            "the doo-sabin scheme has no crease rule",
        ),
        (
            "fin.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n".into(),
            &["--scheme", "modified-butterfly"],
            "needs a manifold mesh",
        ),
        (
            "tension.obj",
            quad.into(),
            &["--scheme", "catmull-clark", "--tension", "0.1"],
            "--tension applies to --scheme butterfly only",
        ),
        (
            "ok2.obj",
            quad.into(),
            &["--scheme", "bilinear", "--levels", "99"],
            "99 levels requested",
        ),
    ];
    for (name, text, extra, expect) in cases {
        let input = s.file(name, text.as_bytes());
        let out = s.0.join(format!("{name}.out.obj"));
        let mut args = vec!["refine"];
        args.extend_from_slice(extra);
        if !extra.contains(&"--levels") {
            args.extend_from_slice(&["--levels", "1"]);
        }
        args.push(input.to_str().unwrap());
        args.push(out.to_str().unwrap());
        let (code, _, err) = subd(&args);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(
            err.contains(expect),
            "{name}: expected {expect:?} in {err:?}"
        );
        assert!(!err.contains("panicked"), "{err}");
        assert!(!out.exists(), "{name}: output written");
    }
    // The input is never overwritten.
    let input = s.file("same.obj", quad.as_bytes());
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "bilinear",
        "--levels",
        "1",
        input.to_str().unwrap(),
        input.to_str().unwrap(),
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("would overwrite the input"), "{err}");
    assert_eq!(std::fs::read_to_string(&input).unwrap(), quad);
}

/// On a terminal a deep refinement shows a progress bar drawn from its own thread; it must
/// not deadlock against the command's own stderr (it once did). `script` gives the run a
/// pseudo-terminal.
#[test]
fn progress_bar_on_a_terminal_does_not_block() {
    let s = Scratch::new("tty");
    let input =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/meshes/torus_creased.obj");
    let out = s.0.join("deep.ply");
    let cmd = format!(
        "{} refine --scheme catmull-clark --levels 7 {} {}",
        env!("CARGO_BIN_EXE_subd"),
        input.display(),
        out.display()
    );
    let mut child = Command::new("script")
        .args(["-qec", &cmd, "/dev/null"])
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .spawn()
        .expect("`script` (util-linux) runs the command on a pseudo-terminal");
    let start = std::time::Instant::now();
    let status = loop {
        if let Some(st) = child.try_wait().unwrap() {
            break st;
        }
        if start.elapsed() > std::time::Duration::from_secs(60) {
            let _ = child.kill();
            panic!("subd refine on a terminal did not finish within 60 s");
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    };
    assert!(status.success(), "{status:?}");
    assert!(out.exists());
}

#[test]
fn two_phase_refine_level_one_is_phase_one() {
    // λ = 1 freezes the base vertices in phase 1; later levels are ordinary Catmull-Clark.
    let s = Scratch::new("two-phase");
    let input = meshes().join("catmark_cube.obj");
    let base = obj_vertices(&input);
    let out = s.0.join("l1.obj");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "two-phase",
        "--lambda",
        "1",
        "--levels",
        "1",
        input.to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let l1 = obj_vertices(&out);
    assert_eq!(&l1[..base.len()], &base[..]);
    // Level 2 of two-phase = Catmull-Clark level 1 of the phase-1 mesh.
    let out2 = s.0.join("l2.obj");
    let cc = s.0.join("cc.obj");
    assert_eq!(
        subd(&[
            "refine",
            "--scheme",
            "two-phase",
            "--lambda",
            "1",
            "--levels",
            "2",
            input.to_str().unwrap(),
            out2.to_str().unwrap()
        ])
        .0,
        0
    );
    assert_eq!(
        subd(&[
            "refine",
            "--scheme",
            "catmull-clark",
            "--levels",
            "1",
            out.to_str().unwrap(),
            cc.to_str().unwrap()
        ])
        .0,
        0
    );
    // Edge children follow edge order, which a mesh read back from a file numbers anew:
    // compare as sorted point sets.
    let (mut a, mut b) = (obj_vertices(&out2), obj_vertices(&cc));
    assert_eq!(a.len(), b.len());
    a.sort_by(|p, q| p.partial_cmp(q).unwrap());
    b.sort_by(|p, q| p.partial_cmp(q).unwrap());
    for (p, q) in a.iter().zip(&b) {
        for k in 0..3 {
            assert!((p[k] - q[k]).abs() < 1e-12);
        }
    }
}

/// `subd refine` writes its output level from the level's polygons and the tags derived
/// from the level above, without building the level's edges. The file is byte for byte the
/// one the library writes from the fully built level, with the sharpness the boundary
/// rules imply cleared (boundary and non-manifold edges, non-manifold and isolated vertices,
/// corners under edge-and-corner), on shapes with creases, corners, holes, boundaries and
/// non-manifold parts.
#[test]
fn refine_output_equals_the_fully_built_level() {
    use subd_io::{Format, WriteOptions, encode_mesh, read_mesh};
    use subd_mesh::{BoundaryInterpolation, Mesh, SchemeHints};
    use subd_schemes::{Options, Refinement, Scheme};
    let s = Scratch::new("full-level");
    let (mut compared, mut tagged) = (0, 0);
    for name in [
        "catmark_cube",
        "catmark_hole_test1",
        "catmark_nonquads",
        "catmark_torus_creases0",
        "catmark_cube_corner3",
        "catmark_chaikin1",
        "catmark_edgecorner",
        "catmark_nonman_edges",
        "catmark_nonman_verts",
        "bilinear_nonquads0",
        "loop_icosahedron",
        "loop_cube_creases0",
        "loop_triangle_edgecorner",
        "catmark_cubes_infsharp",
        "loop_cubes_infsharp",
    ] {
        let input = meshes().join(format!("{name}.obj"));
        let read = subd_io::ReadOptions {
            accept_inconsistent_orientation: true,
            ..Default::default()
        };
        let file = read_mesh(&input, &read).unwrap();
        let (scheme, arg) = match &name[..4] {
            "loop" => (Scheme::Loop, "loop"),
            "bili" => (Scheme::Bilinear, "bilinear"),
            _ => (Scheme::CatmullClark, "catmull-clark"),
        };
        let options = Options::from_hints(&file.mesh.hints);
        let r = Refinement::new(&file.mesh.topology, scheme, &options, 2).unwrap();
        let positions = r.refine_points(&file.mesh.positions).pop().unwrap();
        let refined_uv = file.mesh.uv().map(|uv| {
            let mode = file
                .mesh
                .hints
                .fvar_interpolation
                .unwrap_or(subd_mesh::fvar::FVarLinearInterpolation::CornersPlus1);
            let fr = subd_schemes::FaceVaryingRefinement::new(&r, uv, mode).unwrap();
            let values = fr.refine_values(&r, uv.values(), 2).pop().unwrap();
            (values, fr.face_values(2), mode)
        });
        let mut t = r.into_topology(2);
        for e in 0..t.num_edges() {
            if t.is_boundary_edge(e) || t.is_non_manifold_edge(e) {
                t.set_edge_sharpness(e, 0.0);
            }
        }
        for v in 0..t.num_vertices() {
            let corner = t.vertex_faces(v).len() == 1 && t.valence(v) == 2;
            if t.is_non_manifold_vertex(v)
                || t.is_isolated_vertex(v)
                || (corner
                    && options.boundary_interpolation == BoundaryInterpolation::EdgeAndCorner)
            {
                t.set_vertex_sharpness(v, 0.0);
            }
        }
        let mut mesh = Mesh::new(t, positions).unwrap();
        mesh.hints = SchemeHints {
            boundary_interpolation: Some(options.boundary_interpolation),
            crease_method: Some(options.crease_method),
            triangle_subdivision: file.mesh.hints.triangle_subdivision,
            fvar_interpolation: None,
            scheme: None,
        };
        // Texture coordinates refined beside, in the file's mode or corners-plus1.
        let mut textured = mesh.clone();
        if let Some((values, indices, mode)) = refined_uv {
            let channel =
                subd_mesh::fvar::FVarChannel::new(&textured.topology, 2, values, indices).unwrap();
            textured = textured.with_fvar(channel).unwrap();
            textured.hints.fvar_interpolation = Some(mode);
        }
        // PLY keeps them where every vertex has one value.
        let ply_keeps = textured
            .uv()
            .is_none_or(|uv| uv.num_values() == textured.topology.num_vertices());
        let tags = mesh.topology.tags();
        tagged += (tags.num_creased_edges() > 0 || tags.vertex_sharpness().iter().any(|&s| s > 0.0))
            as usize;
        for (ext, format) in [
            ("obj", Format::Obj),
            ("ply", Format::Ply),
            ("glb", Format::Glb),
        ] {
            let out = s.0.join(format!("{name}.{ext}"));
            let (code, _, err) = subd(&[
                "refine",
                "--scheme",
                arg,
                "--levels",
                "2",
                "--accept-inconsistent-orientation",
                input.to_str().unwrap(),
                out.to_str().unwrap(),
            ]);
            assert_eq!(code, 0, "{name}: {err}");
            let mut expected = Vec::new();
            let with = if format != Format::Ply || ply_keeps {
                &textured
            } else {
                &mesh
            };
            encode_mesh(&mut expected, with, format, &WriteOptions::default()).unwrap();
            assert!(
                std::fs::read(&out).unwrap() == expected,
                "{name}.{ext} differs"
            );
            compared += 1;
        }
    }
    assert!(
        compared == 45 && tagged >= 6,
        "{compared} compared, {tagged} tagged"
    );
}

/// Doo-Sabin, √3 and the butterflies through `refine`, `limit` and `analyze`.
#[test]
fn split_schemes_refine_limit_and_analyze() {
    let s = Scratch::new("split");
    let cube = meshes().join("loop_cube.obj");
    let quads = meshes().join("catmark_cube.obj");
    for (scheme, input, vertices, faces) in [
        // loop_cube: 14 vertices, 36 edges, 24 triangles; √3 adds F per step and triples F,
        // the butterflies add E and quadruple F.
        ("sqrt3", &cube, 14 + 24 + 72, 216),
        ("butterfly", &cube, 194, 384),
        ("modified-butterfly", &cube, 194, 384),
        // catmark_cube: Doo-Sabin gives Σ face sizes vertices and F + E + V faces per step.
        ("doo-sabin", &quads, 96, 98),
    ] {
        let out = s.0.join(format!("{scheme}.obj"));
        let (code, stdout, err) = subd(&[
            "refine",
            "--scheme",
            scheme,
            "--levels",
            "2",
            "--json",
            input.to_str().unwrap(),
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{scheme}: {err}");
        let report: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        assert_eq!(report["scheme"], scheme);
        assert_eq!(report["output_counts"]["faces"], faces, "{scheme}");
        assert_eq!(report["output_counts"]["vertices"], vertices, "{scheme}");
        assert!(report.get("boundary_interpolation").is_none());
        let back = std::fs::read_to_string(&out).unwrap();
        assert!(back.lines().filter(|l| l.starts_with("f ")).count() > 0);
        let lim = s.0.join(format!("{scheme}.txt"));
        let (code, _, err) = subd(&[
            "limit",
            "--scheme",
            scheme,
            "--normals",
            input.to_str().unwrap(),
            lim.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{scheme}: {err}");
        let text = std::fs::read_to_string(&lim).unwrap();
        let base_vertices = if scheme == "doo-sabin" { 8 } else { 14 };
        assert_eq!(text.lines().count(), base_vertices, "{scheme}");
        assert!(
            text.lines()
                .all(|l| l.split(' ').count() == 6 && !l.contains("NaN"))
        );
    }
    // Tension 0: linear interpolation, and the JSON says which tension.
    let out = s.0.join("linear.obj");
    let (code, stdout, err) = subd(&[
        "refine",
        "--scheme",
        "butterfly",
        "--tension",
        "0",
        "--levels",
        "1",
        "--json",
        cube.to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("\"tension\":0.0"), "{stdout}");
    // Darts (infinitely sharp creases ending inside the surface) have √3 limits too.
    let lim = s.0.join("dart.txt");
    let (code, _, err) = subd(&[
        "limit",
        "--scheme",
        "sqrt3",
        "--normals",
        meshes().join("loop_icos_infsharp.obj").to_str().unwrap(),
        lim.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let text = std::fs::read_to_string(&lim).unwrap();
    assert!(text.lines().all(|l| {
        l.split(' ')
            .take(3)
            .all(|x| x.parse::<f64>().unwrap().is_finite())
    }));
    // A bad mesh is refused as by refine: exit 2, no output.
    let quads_out = s.0.join("quads.txt");
    let (code, _, err) = subd(&[
        "limit",
        "--scheme",
        "butterfly",
        quads.to_str().unwrap(),
        quads_out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("needs triangles"), "{err}");
    assert!(!quads_out.exists());
    // The eigenvalue test: the classic butterfly fails at valence 3, passes at 6.
    let (code, out, _) = subd(&[
        "analyze",
        "--surface",
        "butterfly",
        "--valence",
        "3",
        "--json",
    ]);
    assert_eq!(code, 0);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["test"]["passes"], false);
    let (code, out, _) = subd(&[
        "analyze",
        "--surface",
        "modified-butterfly",
        "--valence",
        "3",
    ]);
    assert_eq!(code, 0);
    assert!(out.contains("C¹ eigenvalue test: yes"), "{out}");
    let (code, _, err) = subd(&["analyze", "--surface", "sqrt3", "--valence", "2"]);
    assert_eq!(code, 2, "{err}");
}

/// `x y z nx ny nz` lines of `subd limit --normals` output.
fn limit_lines(path: &Path) -> Vec<[f64; 6]> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2], v[3], v[4], v[5]]
        })
        .collect()
}

#[test]
fn refine_limit_puts_every_output_vertex_on_the_limit_surface() {
    let s = Scratch::new("refine-limit");
    let torus =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/meshes/torus_creased.obj");
    for (scheme, input) in [
        ("catmull-clark", torus),
        ("loop", meshes().join("loop_cube_creases0.obj")),
        ("sqrt3", meshes().join("loop_cube.obj")),
    ] {
        let input = input.to_str().unwrap();
        let on_limit = s.0.join(format!("{scheme}-limit.obj"));
        let (code, _, err) = subd(&[
            "refine",
            "--scheme",
            scheme,
            "--levels",
            "2",
            "--limit",
            input,
            on_limit.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{scheme}: {err}");
        let refined = subd_io::read_mesh(&on_limit, &subd_io::ReadOptions::default()).unwrap();
        let text = std::fs::read_to_string(&on_limit).unwrap();
        let normals: Vec<[f64; 3]> = text
            .lines()
            .filter_map(|l| l.strip_prefix("vn "))
            .map(|l| {
                let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
                [v[0], v[1], v[2]]
            })
            .collect();
        assert_eq!(
            normals.len(),
            refined.mesh.positions.len(),
            "{scheme}: one vn per vertex"
        );
        // The same points another way: plain refinement, then `subd limit` on that file.
        let plain = s.0.join(format!("{scheme}-plain.obj"));
        let plain_limit = s.0.join(format!("{scheme}-plain-limit.txt"));
        let (code, _, err) = subd(&[
            "refine",
            "--scheme",
            scheme,
            "--levels",
            "2",
            input,
            plain.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
        let (code, _, err) = subd(&[
            "limit",
            "--scheme",
            scheme,
            "--normals",
            plain.to_str().unwrap(),
            plain_limit.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
        let expected = limit_lines(&plain_limit);
        assert_eq!(expected.len(), normals.len());
        for (v, (p, e)) in refined.mesh.positions.iter().zip(&expected).enumerate() {
            let d = (*p - subd_mesh::DVec3::new(e[0], e[1], e[2])).length();
            assert!(d < 1e-12, "{scheme}: vertex {v} off by {d}");
            let n = subd_mesh::DVec3::from_array(normals[v]);
            assert!(
                (n.length() - 1.0).abs() < 1e-12,
                "{scheme}: vertex {v} normal {n}"
            );
            let en = subd_mesh::DVec3::new(e[3], e[4], e[5]);
            if en.is_finite() {
                assert!(
                    n.dot(en) > 1.0 - 1e-12,
                    "{scheme}: vertex {v} normal {n} vs {en}"
                );
            }
        }
        // Two levels apart, the base vertices' own limits are among the output's.
        let base_limit = s.0.join(format!("{scheme}-base-limit.txt"));
        let (code, _, err) = subd(&[
            "limit",
            "--scheme",
            scheme,
            input,
            base_limit.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
        for (v, b) in std::fs::read_to_string(&base_limit)
            .unwrap()
            .lines()
            .enumerate()
        {
            let b: Vec<f64> = b.split_whitespace().map(|x| x.parse().unwrap()).collect();
            let b = subd_mesh::DVec3::new(b[0], b[1], b[2]);
            let nearest = refined
                .mesh
                .positions
                .iter()
                .map(|p| (*p - b).length())
                .fold(f64::INFINITY, f64::min);
            assert!(
                nearest < 1e-12,
                "{scheme}: base vertex {v}'s limit is {nearest} from the output"
            );
        }
    }
}
