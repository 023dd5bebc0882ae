//! The `subd` binary as a user runs it: exit codes, one-line errors, JSON output.

use std::path::{Path, PathBuf};
use std::process::Command;

fn subd(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_subd"))
        .args(args)
        .env("RUST_BACKTRACE", "1")
        .output()
        .expect("run subd");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn meshes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/meshes/osd")
}

struct Scratch(PathBuf);

impl Scratch {
    fn new(tag: &str) -> Self {
        let d = std::env::temp_dir().join(format!("subd-cli-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        Scratch(d)
    }
    fn file(&self, name: &str, bytes: &[u8]) -> PathBuf {
        let p = self.0.join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Runs `subd info` on a bad input and checks the user-facing contract: exit 2, exactly one
/// line on stderr starting with `subd: <file>`, containing `expect`, no panic or backtrace.
fn assert_bad_input(path: &Path, expect: &str) {
    let p = path.to_str().unwrap();
    let (code, out, err) = subd(&["info", p]);
    assert_eq!(code, 2, "{p}: stderr {err:?}");
    assert!(out.is_empty(), "{p}: stdout {out:?}");
    let lines: Vec<&str> = err
        .lines()
        .filter(|l| !l.starts_with("subd: warning:"))
        .collect();
    assert_eq!(lines.len(), 1, "{p}: stderr {err:?}");
    assert!(lines[0].starts_with(&format!("subd: {p}")), "{p}: {err:?}");
    assert!(
        lines[0].contains(expect),
        "{p}: expected {expect:?} in {err:?}"
    );
    assert!(
        !err.contains("panicked") && !err.contains("backtrace"),
        "{err}"
    );
}

#[test]
fn malformed_obj_inputs_exit_2_with_the_line() {
    let s = Scratch::new("bad");
    let quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";
    let cases: &[(&str, String, &str)] = &[
        (
            "truncated_vertex.obj",
            "v 0 0 0\nv 1 0\n".into(),
            ":2: vertex has 2 coordinates",
        ),
        (
            "index_zero.obj",
            format!("{quad}f 0 1 2\n"),
            ":5: face index 0 is invalid",
        ),
        (
            "index_beyond.obj",
            format!("{quad}f 1 2 9\n"),
            ":5: face refers to vertex 9, but the file has 4 vertices",
        ),
        (
            "relative_before_start.obj",
            format!("{quad}f -1 -2 -5\n"),
            ":5: relative face index -5",
        ),
        (
            "nan.obj",
            "v 0 nan 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".into(),
            ":1: vertex 1 has a non-finite coordinate",
        ),
        (
            "inf.obj",
            "v 0 0 0\nv inf 0 0\nv 0 1 0\nf 1 2 3\n".into(),
            ":2: vertex 2 has a non-finite coordinate",
        ),
        ("empty.obj", String::new(), "no vertices and no faces"),
        (
            "two_vertex_face.obj",
            format!("{quad}f 1 2\n"),
            ":5: face has 2 vertices; a face needs at least 3",
        ),
        (
            "bad_number.obj",
            "v 0 0 x\n".into(),
            ":1: vertex coordinate \"x\" is not a number",
        ),
        (
            "bad_index.obj",
            format!("{quad}f 1 2 three\n"),
            ":5: face vertex \"three\" is not an index",
        ),
        (
            "truncated_face.obj",
            format!("{quad}f 1 2 3 4\nf 1"),
            ":6: face has 1 vertices",
        ),
        (
            "crease_missing_vertex.obj",
            format!("{quad}f 1 2 3 4\nt crease 2/1/0 0 7 1.0\n"),
            ":6: crease tag names vertex 7",
        ),
        (
            "crease_negative_sharpness.obj",
            format!("{quad}f 1 2 3 4\nt crease 2/1/0 0 1 -2\n"),
            ":6: crease tag has invalid sharpness -2",
        ),
        (
            "corner_negative_index.obj",
            format!("{quad}f 1 2 3 4\nt corner 1/1/0 -1 2\n"),
            ":6: corner tag names vertex -1",
        ),
        (
            "hole_missing_face.obj",
            format!("{quad}f 1 2 3 4\nt hole 1/0/0 3\n"),
            ":6: hole tag names face 3",
        ),
        (
            "tag_counts.obj",
            format!("{quad}f 1 2 3 4\nt crease 2/1/0 0 1\n"),
            ":6: tag \"crease\" declares 2/1/0 arguments but has 2",
        ),
        ("no_faces.obj", quad.into(), "no faces"),
        (
            "uv_some_corners.obj",
            format!("{quad}vt 0 0\nvt 1 0\nvt 1 1\nf 1/1 2/2 3\n"),
            ":8: face gives texture coordinates at 2 of its 3 corners",
        ),
        (
            "uv_index_beyond.obj",
            format!("{quad}vt 0 0\nvt 1 0\nvt 1 1\nf 1/1 2/2 3/9\n"),
            ":8: face refers to texture coordinate 9, but the file has 3",
        ),
        (
            "uv_index_zero.obj",
            format!("{quad}vt 0 0\nf 1/0 2/1 3/1\n"),
            ":6: face index 0 is invalid (OBJ texture coordinate indices start at 1)",
        ),
        (
            "uv_relative_before_start.obj",
            format!("{quad}vt 0 0\nf 1/-1 2/-1 3/-2\n"),
            ":6: relative face index -2 points before the first texture coordinate",
        ),
        (
            "uv_not_an_index.obj",
            format!("{quad}vt 0 0\nf 1/x 2/1 3/1\n"),
            ":6: texture coordinate index \"x\" of \"1/x\" is not an index",
        ),
        (
            "uv_nan.obj",
            format!("{quad}vt 0 nan\nf 1/1 2/1 3/1\n"),
            ":5: texture coordinate 1 has a non-finite coordinate",
        ),
        (
            "uv_no_numbers.obj",
            format!("{quad}vt\nf 1/1 2/1 3/1\n"),
            ":5: texture coordinate has 0 coordinates",
        ),
        (
            "fvar_tag_value.obj",
            format!("{quad}f 1 2 3 4\nt facevaryinginterpolateboundary 1/0/0 7\n"),
            ":6: facevaryinginterpolateboundary tag: unknown value 7",
        ),
    ];
    for (name, text, expect) in cases {
        let p = s.file(name, text.as_bytes());
        assert_bad_input(&p, expect);
    }
    // Faces without texture coordinates beside faces with them: the geometry is read, the
    // texture coordinates are dropped with a warning naming the first such face.
    let mixed = s.file(
        "uv_mixed.obj",
        format!("{quad}vt 0 0\nvt 1 0\nvt 1 1\nf 1/1 2/2 3/3\nf 1 3 4\n").as_bytes(),
    );
    let (code, out, err) = subd(&["info", mixed.to_str().unwrap(), "--json"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains(
            "line 9: face has no texture coordinate indices while 1 other faces have them"
        ),
        "{err}"
    );
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["fvar_channels"].as_array().unwrap().len(), 0);
    // Binary garbage: bytes that are not text.
    let garbage: Vec<u8> = (0..4096u32)
        .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
        .collect();
    assert_bad_input(&s.file("garbage.obj", &garbage), ":1: ");
    // Text that is not OBJ.
    assert_bad_input(
        &s.file("prose.obj", b"{\"not\": \"obj\"}\n"),
        ":1: not an OBJ statement",
    );
}

#[test]
fn malformed_files_of_other_kinds_exit_2() {
    let s = Scratch::new("other");
    assert_bad_input(&s.0.join("missing.obj"), "cannot read");
    assert_bad_input(
        &s.file("mesh.stl", b"solid x\n"),
        "unsupported file extension",
    );
    assert_bad_input(
        &s.file(
            "bad.ply",
            b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n",
        ),
        "lacks an x, y or z",
    );
    assert_bad_input(
        &s.file("short.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n\x00\x00"),
        "element vertex declares 1000000000 instances but only 2 bytes of data remain",
    );
    assert_bad_input(
        &s.file("short2.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n\x00\x00"),
        "binary data ends inside vertex 0 property x",
    );
    // Found by fuzzing: a huge element with no properties must fail fast, not loop.
    assert_bad_input(
        &s.file(
            "empty_element.ply",
            b"ply\nformat binary_big_endian 1.0\nelement crease 01569664312\nend_header\n",
        ),
        "element crease declares 1569664312 instances but has no properties",
    );
    assert_bad_input(
        &s.file("ascii_face.ply", b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n"),
        ":13: face 0 has 2 vertices",
    );
    // A directory is not a mesh file.
    let dir = s.0.join("dir.obj");
    std::fs::create_dir_all(&dir).unwrap();
    assert_bad_input(&dir, "cannot read");
}

#[test]
fn negative_indices_resolve_as_obj_defines() {
    let s = Scratch::new("neg");
    let p = s.file(
        "neg.obj",
        b"v 0 0 0\nv 1 0 0\nv 1 1 0\nf -3 -2 -1\nv 0 1 0\nf 1 -2 -1\n",
    );
    let (code, out, err) = subd(&["info", p.to_str().unwrap(), "--json"]);
    assert_eq!(code, 0, "{err}");
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    // Faces (0,1,2) and (0,2,3): two triangles sharing edge (0,2).
    assert_eq!(
        (
            j["vertices"].as_u64(),
            j["edges"].as_u64(),
            j["faces"].as_u64()
        ),
        (Some(4), Some(5), Some(2))
    );
}

#[test]
fn info_json_on_a_shape() {
    let p = meshes().join("catmark_torus.obj");
    let (code, out, err) = subd(&["info", p.to_str().unwrap(), "--json"]);
    assert_eq!(code, 0, "{err}");
    let j: serde_json::Value = serde_json::from_str(&out).expect("one JSON object");
    for key in [
        "vertices",
        "edges",
        "faces",
        "boundary_edges",
        "nonmanifold_edges",
        "components",
        "euler",
        "genus",
    ] {
        assert!(j.get(key).is_some(), "missing {key}");
    }
    assert_eq!(j["genus"], 1);
    assert_eq!(j["euler"], 0);
    // Open mesh: genus is null.
    let p = meshes().join("catmark_tent.obj");
    let (_, out, _) = subd(&["info", p.to_str().unwrap(), "--json"]);
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(j["genus"].is_null());
    assert_eq!(j["boundary_edges"], 12);
}

#[test]
fn info_text_and_warnings() {
    let p = meshes().join("catmark_square_hedit0.obj");
    let (code, out, err) = subd(&["info", p.to_str().unwrap()]);
    assert_eq!(code, 0);
    assert!(out.contains("faces             9"), "{out}");
    assert!(
        err.contains("hierarchical edit tag \"vertexedit\" is not supported"),
        "{err}"
    );
    let p = meshes().join("catmark_nonman_quadpole8.obj");
    let (code, _, err) = subd(&["info", p.to_str().unwrap()]);
    assert_eq!(code, 0);
    assert!(err.contains("repeats vertex"), "{err}");
}

#[test]
fn usage_errors_exit_2() {
    let (code, _, err) = subd(&["info"]);
    assert_eq!(code, 2);
    assert!(err.contains("Usage"), "{err}");
    let (code, _, _) = subd(&["frobnicate"]);
    assert_eq!(code, 2);
    let (code, out, _) = subd(&["--help"]);
    assert_eq!(code, 0);
    assert!(out.contains("info"));
}

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
fn limit_writes_text_and_meshes() {
    let s = Scratch::new("limit");
    let cube = meshes().join("catmark_cube.obj");
    let txt = s.0.join("cube.txt");
    let (code, out, err) = subd(&[
        "limit",
        "--scheme",
        "catmull-clark",
        "--normals",
        "--json",
        cube.to_str().unwrap(),
        txt.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let report: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    assert_eq!(report["vertices"], 8);
    assert_eq!(report["levels_refined"], 0);
    // Closed form for a cube corner v with edge neighbours e and face diagonals f (valence
    // 3): (9 v + 4 Σ e + Σ f) / 24 = v / 2 for a cube centred at the origin.
    let corners: Vec<[f64; 3]> = std::fs::read_to_string(&cube)
        .unwrap()
        .lines()
        .filter(|l| l.starts_with("v "))
        .map(|l| {
            let c: Vec<f64> = l[2..]
                .split_whitespace()
                .map(|x| x.parse().unwrap())
                .collect();
            [c[0], c[1], c[2]]
        })
        .collect();
    let text = std::fs::read_to_string(&txt).unwrap();
    let rows: Vec<Vec<f64>> = text
        .lines()
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 8);
    for (r, c) in rows.iter().zip(&corners) {
        assert_eq!(r.len(), 6);
        for k in 0..3 {
            assert!((r[k] - 0.5 * c[k]).abs() < 1e-12, "{r:?} vs {c:?}");
        }
        // The normal points along the corner's direction from the centre.
        let len = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
        let dot: f64 = (0..3).map(|k| r[3 + k] * c[k] / len).sum();
        assert!((dot - 1.0).abs() < 1e-6, "{r:?}");
    }
    // A mesh output keeps the topology with the vertices moved.
    let obj = s.0.join("cube_limit.obj");
    let (code, _, err) = subd(&[
        "limit",
        "--scheme",
        "catmull-clark",
        cube.to_str().unwrap(),
        obj.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let written = std::fs::read_to_string(&obj).unwrap();
    assert_eq!(written.lines().filter(|l| l.starts_with("f ")).count(), 6);
    assert_eq!(written.lines().filter(|l| l.starts_with("v ")).count(), 8);
}

#[test]
fn limit_bad_input_exits_2_without_output() {
    let s = Scratch::new("limitbad");
    let cube = meshes().join("catmark_cube.obj");
    let out = s.0.join("x.txt");
    for args in [
        vec![
            "limit",
            "--scheme",
            "loop",
            cube.to_str().unwrap(),
            out.to_str().unwrap(),
        ],
        vec![
            "limit",
            "--scheme",
            "bilinear",
            cube.to_str().unwrap(),
            out.to_str().unwrap(),
        ],
        vec![
            "limit",
            "--scheme",
            "catmull-clark",
            cube.to_str().unwrap(),
            s.0.join("x.svg").to_str().unwrap(),
        ],
    ] {
        let (code, _, err) = subd(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(
            !out.exists() && !s.0.join("x.svg").exists(),
            "{args:?} left an output"
        );
        assert!(err.lines().count() <= 4, "{err}");
    }
}

#[test]
fn eval_writes_points_and_names_bad_lines() {
    let s = Scratch::new("eval");
    let cube = meshes().join("catmark_cube.obj");
    let at = s.file(
        "at.txt",
        b"# centre of face 0, then a corner\n0 0.5 0.5\n\n2 0 0\n",
    );
    let out = s.0.join("out.txt");
    let (code, json, err) = subd(&[
        "eval",
        "--scheme",
        "catmull-clark",
        "--json",
        cube.to_str().unwrap(),
        "--at",
        at.to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let report: serde_json::Value = serde_json::from_str(json.trim()).unwrap();
    assert_eq!(report["points"], 2);
    let rows: Vec<Vec<f64>> = std::fs::read_to_string(&out)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 2);
    // catmark_cube has faces at z = ±1 centred on the z axis: by symmetry the centre of
    // face 0 lies on the axis with normal +z.
    assert!(rows[0][0].abs() < 1e-12 && rows[0][1].abs() < 1e-12);
    assert!((rows[0][5] - 1.0).abs() < 1e-12, "{:?}", rows[0]);
    // A face corner is its vertex's limit: half the vertex on this origin-centred cube
    // (valence-3 mask (9 v + 4 Σ e + Σ f) / 24).
    let corner = {
        let text = std::fs::read_to_string(&cube).unwrap();
        let faces: Vec<&str> = text.lines().filter(|l| l.starts_with("f ")).collect();
        let first: usize = faces[2]
            .split_whitespace()
            .nth(1)
            .unwrap()
            .split('/')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        let v: Vec<f64> = text
            .lines()
            .filter(|l| l.starts_with("v "))
            .nth(first - 1)
            .unwrap()[2..]
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        v
    };
    for k in 0..3 {
        assert!(
            (rows[1][k] - 0.5 * corner[k]).abs() < 1e-12,
            "{:?} vs {corner:?}",
            rows[1]
        );
    }
    // catmark_cube has UVs: each line ends with the limit `u v`.
    assert!(rows.iter().all(|r| r.len() == 8), "{rows:?}");
    eval_uvs_are_linear_in_mode_all(&s, &cube, &at);
    for (args, expect) in [
        ("0 0.5 1.5\n", "at.txt:1: parameters"),
        ("1 0.5 0.5\n99 0.5 0.5\n", "at.txt:2: face 99 out of range"),
        ("0 0.5\n", "at.txt:1: expected"),
        ("0 x 0.5\n", "at.txt:1: expected a parameter"),
    ] {
        let bad = s.file("at.txt", args.as_bytes());
        let out2 = s.0.join("bad.txt");
        let (code, _, err) = subd(&[
            "eval",
            "--scheme",
            "catmull-clark",
            cube.to_str().unwrap(),
            "--at",
            bad.to_str().unwrap(),
            out2.to_str().unwrap(),
        ]);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(expect), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(!out2.exists());
    }
}

/// Under `--fvar-interpolation all` the UVs are bilinear over each face's corners: the centre
/// of face 0 is the mean of its four `vt`, read from the OBJ text, and a corner is its `vt`.
fn eval_uvs_are_linear_in_mode_all(s: &Scratch, cube: &Path, at: &Path) {
    let out = s.0.join("uv.txt");
    let (code, _, err) = subd(&[
        "eval",
        "--scheme",
        "catmull-clark",
        "--fvar-interpolation",
        "all",
        cube.to_str().unwrap(),
        "--at",
        at.to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let rows: Vec<Vec<f64>> = std::fs::read_to_string(&out)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect();
    let text = std::fs::read_to_string(cube).unwrap();
    let vt: Vec<[f64; 2]> = text
        .lines()
        .filter_map(|l| l.strip_prefix("vt "))
        .map(|l| {
            let x: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [x[0], x[1]]
        })
        .collect();
    let corner_vt = |face: usize| -> Vec<[f64; 2]> {
        let line = text
            .lines()
            .filter(|l| l.starts_with("f "))
            .nth(face)
            .unwrap();
        line.split_whitespace()
            .skip(1)
            .map(|c| vt[c.split('/').nth(1).unwrap().parse::<usize>().unwrap() - 1])
            .collect()
    };
    let f0 = corner_vt(0);
    for k in 0..2 {
        let mean = f0.iter().map(|c| c[k]).sum::<f64>() / 4.0;
        assert!(
            (rows[0][6 + k] - mean).abs() < 1e-12,
            "{:?} vs {f0:?}",
            rows[0]
        );
        assert!(
            (rows[1][6 + k] - corner_vt(2)[0][k]).abs() < 1e-12,
            "{:?}",
            rows[1]
        );
    }
}

#[test]
fn eval_loop_points_are_barycentric() {
    let s = Scratch::new("evalloop");
    let mesh = meshes().join("loop_cube.obj");
    let at = s.file("at.txt", b"0 0.25 0.25\n1 1 0\n");
    let out = s.0.join("out.txt");
    let (code, _, err) = subd(&[
        "eval",
        "--scheme",
        "loop",
        mesh.to_str().unwrap(),
        "--at",
        at.to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let rows: Vec<Vec<f64>> = std::fs::read_to_string(&out)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 2);
    for r in &rows {
        let n = (r[3] * r[3] + r[4] * r[4] + r[5] * r[5]).sqrt();
        assert!((n - 1.0).abs() < 1e-12, "{r:?}");
    }
    // Outside the triangle is refused with the line.
    let bad = s.file("bad.txt", b"0 0.75 0.5\n");
    let (code, _, err) = subd(&[
        "eval",
        "--scheme",
        "loop",
        mesh.to_str().unwrap(),
        "--at",
        bad.to_str().unwrap(),
        s.0.join("x.txt").to_str().unwrap(),
    ]);
    assert_eq!(code, 2);
    assert!(
        err.contains("bad.txt:1: parameters (0.75, 0.5) outside the triangle"),
        "{err}"
    );
}

#[test]
fn limit_writes_acc_patches_as_json() {
    let s = Scratch::new("acc");
    let cube = meshes().join("catmark_cube.obj");
    let (txt, acc) = (s.0.join("l.txt"), s.0.join("acc.json"));
    let (code, _, err) = subd(&[
        "limit",
        "--scheme",
        "catmull-clark",
        cube.to_str().unwrap(),
        txt.to_str().unwrap(),
        "--acc",
        acc.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let patches: serde_json::Value = serde_json::from_slice(&std::fs::read(&acc).unwrap()).unwrap();
    let patches = patches.as_array().unwrap();
    assert_eq!(patches.len(), 6);
    // Each patch's first corner is the exact limit of its face's first vertex, which the
    // text output lists: half the vertex on this cube.
    let limits: Vec<Vec<f64>> = std::fs::read_to_string(&txt)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect();
    let text = std::fs::read_to_string(&cube).unwrap();
    let first: usize = text
        .lines()
        .find(|l| l.starts_with("f "))
        .unwrap()
        .split_whitespace()
        .nth(1)
        .unwrap()
        .split('/')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let b00: Vec<f64> = patches[0]["geometry"][0]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    for k in 0..3 {
        assert!((b00[k] - limits[first - 1][k]).abs() < 1e-12, "{b00:?}");
    }
    // Loop has no ACC: exit 2 and nothing written.
    let (l2, a2) = (s.0.join("l2.txt"), s.0.join("a2.json"));
    let tri = meshes().join("loop_cube.obj");
    let (code, _, err) = subd(&[
        "limit",
        "--scheme",
        "loop",
        tri.to_str().unwrap(),
        l2.to_str().unwrap(),
        "--acc",
        a2.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(!l2.exists() && !a2.exists());
}

/// Reads the vertex positions of an OBJ file (`v x y z` lines).
fn obj_vertices(path: &Path) -> Vec<[f64; 3]> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

#[test]
fn pia_interpolates_and_reports_json() {
    let s = Scratch::new("pia");
    let input = meshes().join("catmark_torus.obj");
    let targets = obj_vertices(&input);
    let fixed = s.file("fixed.txt", b"# keep these\n0 5\n9\n");
    for (scheme, extra) in [
        ("catmull-clark", vec!["--solver", "iterate"]),
        ("catmull-clark", vec!["--solver", "weighted"]),
        ("catmull-clark", vec!["--solver", "direct"]),
        (
            "two-phase",
            vec!["--lambda", "0.6", "--fixed", fixed.to_str().unwrap()],
        ),
    ] {
        let out = s.0.join(format!("{scheme}-{}.obj", extra[1]));
        let mut args = vec!["pia", "--scheme", scheme, "--json"];
        args.extend(&extra);
        args.extend([input.to_str().unwrap(), out.to_str().unwrap()]);
        let (code, stdout, err) = subd(&args);
        assert_eq!(code, 0, "{err}");
        let j: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        assert_eq!(j["converged"], true);
        assert!(j["max_error_relative"].as_f64().unwrap() <= 1e-10);
        let history = j["history"].as_array().unwrap();
        assert_eq!(
            history.len(),
            j["iterations"].as_u64().unwrap() as usize + 1
        );
        // The limit of the output, by `subd limit`, passes through the moving targets.
        let lim = s.0.join("limit.txt");
        let mut largs = vec!["limit", "--scheme", scheme];
        if scheme == "two-phase" {
            largs.extend(["--lambda", "0.6"]);
        }
        largs.extend([out.to_str().unwrap(), lim.to_str().unwrap()]);
        assert_eq!(subd(&largs).0, 0);
        let limits: Vec<Vec<f64>> = std::fs::read_to_string(&lim)
            .unwrap()
            .lines()
            .map(|l| l.split_whitespace().map(|t| t.parse().unwrap()).collect())
            .collect();
        let solved = obj_vertices(&out);
        for (v, t) in targets.iter().enumerate() {
            if scheme == "two-phase" && [0, 5, 9].contains(&v) {
                assert_eq!(&solved[v], t, "fixed vertex {v} moved");
                continue;
            }
            let d: f64 = (0..3)
                .map(|k| (limits[v][k] - t[k]).powi(2))
                .sum::<f64>()
                .sqrt();
            assert!(d < 1e-9, "{scheme} vertex {v}: {d}");
        }
    }
}

#[test]
fn pia_and_two_phase_bad_input_exit_2_without_output() {
    let s = Scratch::new("pia-bad");
    let quad = meshes().join("catmark_torus.obj");
    let tri = meshes().join("loop_cube.obj");
    let out = s.0.join("out.obj");
    let bad_index = s.file("bad_index.txt", b"0 1\n2 x\n");
    let far_index = s.file("far_index.txt", b"0\n\n31 32\n");
    let short_lambda = s.file("short.txt", b"0.5 0.5\n");
    let nan_lambda = s.file("nan.txt", b"0.5\nabc\n");
    let q = quad.to_str().unwrap();
    let o = out.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["pia", "--scheme", "two-phase", "--lambda", "0.3", q, o],
            "outside (7/20, 1]",
        ),
        (
            vec!["pia", "--scheme", "two-phase", "--lambda", "1.5", q, o],
            "outside (7/20, 1]",
        ),
        (vec!["pia", "--scheme", "two-phase", q, o], "needs --lambda"),
        (
            vec![
                "pia",
                "--scheme",
                "two-phase",
                "--lambda",
                "0.5",
                tri.to_str().unwrap(),
                o,
            ],
            "needs quads",
        ),
        (
            vec!["pia", "--scheme", "loop", q, o],
            "Loop scheme needs triangles",
        ),
        (
            vec![
                "pia",
                "--scheme",
                "catmull-clark",
                "--moving",
                bad_index.to_str().unwrap(),
                q,
                o,
            ],
            "bad_index.txt:2:",
        ),
        (
            vec![
                "pia",
                "--scheme",
                "catmull-clark",
                "--fixed",
                far_index.to_str().unwrap(),
                q,
                o,
            ],
            "far_index.txt:3: vertex 32 does not exist",
        ),
        (
            vec![
                "pia",
                "--scheme",
                "two-phase",
                "--lambda-file",
                short_lambda.to_str().unwrap(),
                q,
                o,
            ],
            "2 lambda values for 32 vertices",
        ),
        (
            vec![
                "pia",
                "--scheme",
                "two-phase",
                "--lambda-file",
                nan_lambda.to_str().unwrap(),
                q,
                o,
            ],
            "nan.txt:2:",
        ),
        (
            vec!["pia", "--scheme", "catmull-clark", "--tol=-1", q, o],
            "--tol",
        ),
        (
            vec!["pia", "--scheme", "catmull-clark", "--lambda", "0.5", q, o],
            "two-phase only",
        ),
        (
            vec![
                "refine",
                "--scheme",
                "two-phase",
                "--lambda",
                "0.2",
                "--levels",
                "1",
                q,
                o,
            ],
            "outside (7/20, 1]",
        ),
        (
            vec![
                "refine",
                "--scheme",
                "two-phase",
                "--lambda",
                "0.5",
                "--levels",
                "1",
                tri.to_str().unwrap(),
                o,
            ],
            "needs quads",
        ),
        (
            vec!["limit", "--scheme", "two-phase", q, o],
            "needs --lambda",
        ),
    ];
    for (args, expect) in cases {
        let (code, stdout, err) = subd(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(stdout.is_empty());
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(
            err.contains(expect),
            "{args:?}: expected {expect:?} in {err:?}"
        );
        assert!(!out.exists(), "{args:?} left an output file");
    }
    // Outside the proven range is accepted on request (and λ = 0.3 still converges here).
    let (code, _, err) = subd(&[
        "pia",
        "--scheme",
        "two-phase",
        "--lambda",
        "0.3",
        "--allow-any-lambda",
        q,
        o,
    ]);
    assert_eq!(code, 0, "{err}");
    // Too few iterations: exit 1, no output.
    let out2 = s.0.join("out2.obj");
    let (code, _, err) = subd(&[
        "pia",
        "--scheme",
        "catmull-clark",
        "--solver",
        "iterate",
        "--max-iter",
        "2",
        q,
        out2.to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("did not reach --tol"), "{err}");
    assert!(!out2.exists());
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

#[test]
fn curve_writes_text_and_svg() {
    let s = Scratch::new("curve");
    // A square, closed.
    let square = s.file("square.txt", b"# a square\n0 0\n1 0\n1 1\n0 1\n");
    let out = s.0.join("c.txt");
    let (code, stdout, err) = subd(&[
        "curve",
        "--scheme",
        "chaikin",
        "--levels",
        "3",
        "--closed",
        square.to_str().unwrap(),
        out.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let j: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(j["output_points"], 32);
    assert_eq!(std::fs::read_to_string(&out).unwrap().lines().count(), 32);
    // Open, 3D, csv out.
    let helix = s.file("helix.csv", b"0,0,0\n1,0,0.5\n1,1,1\n0,1,1.5\n0,0,2\n");
    let out = s.0.join("h.csv");
    let (code, _, err) = subd(&[
        "curve",
        "--scheme",
        "bspline",
        "--order",
        "5",
        "--levels",
        "2",
        helix.to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.lines().all(|l| l.split(',').count() == 3));
    assert!(
        text.starts_with("0,0,0\n"),
        "open curves keep their end points"
    );
    // Circle-average scheme with normals, to SVG; and without normals (estimated, warned).
    let pn = s.file("pn.txt", b"1 0 1 0\n0 1 0 1\n-1 0 -1 0\n0 -1 0 -1\n");
    let svg = s.0.join("c.svg");
    let (code, _, err) = subd(&[
        "curve",
        "--scheme",
        "circle-four-point",
        "--levels",
        "4",
        "--closed",
        pn.to_str().unwrap(),
        svg.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let body = std::fs::read_to_string(&svg).unwrap();
    assert!(body.starts_with("<svg") && body.contains("<path") && body.contains("stroke=\"#d33\""));
    let txt = s.0.join("c2.txt");
    let (code, _, err) = subd(&[
        "curve",
        "--scheme",
        "circle-ternary",
        "--levels",
        "2",
        "--closed",
        square.to_str().unwrap(),
        txt.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("normals estimated") || err.contains("estimated from the polygon"),
        "{err}"
    );
    let lines: Vec<Vec<f64>> = std::fs::read_to_string(&txt)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().map(|t| t.parse().unwrap()).collect())
        .collect();
    assert_eq!(lines.len(), 36);
    // The square's estimated normals point outward, and a square's vertices lie on its
    // circumcircle: the circle schemes keep every point on it.
    for l in &lines {
        let r = ((l[0] - 0.5).powi(2) + (l[1] - 0.5).powi(2)).sqrt();
        assert!((r - 0.5f64.sqrt()).abs() < 1e-12, "{l:?}");
    }
}

#[test]
fn curve_bad_input_exits_2_without_output() {
    let s = Scratch::new("curve-bad");
    let good = s.file("good.txt", b"0 0\n1 0\n1 1\n");
    let one = s.file("one.txt", b"0 0\n");
    let nan = s.file("nan.txt", b"0 0\n1 nan\n");
    let mixed = s.file("mixed.txt", b"0 0\n1 0 0\n");
    let out = s.0.join("out.txt");
    let g = good.to_str().unwrap();
    let o = out.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec![
                "curve",
                "--scheme",
                "four-point",
                "--levels",
                "1",
                "--order",
                "3",
                g,
                o,
            ],
            "--order does not apply",
        ),
        (
            vec![
                "curve", "--scheme", "bspline", "--levels", "1", "--order", "1", g, o,
            ],
            "order 1",
        ),
        (
            vec![
                "curve", "--scheme", "tension", "--levels", "1", "--alpha0", "-3", g, o,
            ],
            "alpha0",
        ),
        (
            vec![
                "curve",
                "--scheme",
                "chaikin",
                "--levels",
                "1",
                one.to_str().unwrap(),
                o,
            ],
            "1 points",
        ),
        (
            vec![
                "curve",
                "--scheme",
                "chaikin",
                "--levels",
                "1",
                nan.to_str().unwrap(),
                o,
            ],
            "nan.txt:2:",
        ),
        (
            vec![
                "curve",
                "--scheme",
                "chaikin",
                "--levels",
                "1",
                mixed.to_str().unwrap(),
                o,
            ],
            "mixed.txt:2:",
        ),
        (
            vec![
                "curve", "--scheme", "chaikin", "--levels", "40", "--closed", g, o,
            ],
            "2^28",
        ),
        (
            vec![
                "curve",
                "--scheme",
                "circle-ternary",
                "--levels",
                "1",
                "--omega",
                "1",
                g,
                o,
            ],
            "omega",
        ),
        (vec!["analyze", "--mask", "0.25,1,0.5"], "sum to 1.75"),
        (vec!["analyze", "--mask", "1,x,1"], "coefficient 1"),
        (
            vec!["analyze", "--mask", "0.5,1,0.5", "--arity", "4"],
            "--arity 4",
        ),
        (
            vec!["analyze", "--surface", "loop", "--valence", "2"],
            "--valence 2",
        ),
    ];
    for (args, expect) in cases {
        let (code, stdout, err) = subd(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(stdout.is_empty(), "{args:?}");
        let errors: Vec<&str> = err
            .lines()
            .filter(|l| !l.starts_with("subd: warning:"))
            .collect();
        assert_eq!(errors.len(), 1, "{args:?}: {err}");
        assert!(
            err.contains(expect),
            "{args:?}: expected {expect:?} in {err:?}"
        );
        assert!(!out.exists(), "{args:?} left an output file");
    }
}

#[test]
fn analyze_reports_the_seeds_verdicts() {
    // The 4-point scheme: C¹, with fractions accepted.
    let (code, out, err) = subd(&["analyze", "--mask", "-1/16,0,9/16,1,9/16,0,-1/16"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("converges: yes") && out.contains("C^1 shown"),
        "{out}"
    );
    let (code, out, _) = subd(&["analyze", "--mask", "0.125,0.5,0.75,0.5,0.125", "--json"]);
    assert_eq!(code, 0);
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["converges"], true);
    assert_eq!(j["smoothness"], 2);
    assert_eq!(j["norms"][0][0], 0.5);
    // Ternary, ω = 1/4: C¹.
    let (code, out, _) = subd(&[
        "analyze",
        "--arity",
        "3",
        "--mask",
        "-1/12,0,1/4,5/6,1,5/6,1/4,0,-1/12",
        "--json",
    ]);
    assert_eq!(code, 0);
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["smoothness"], 1);
    // Bivariate: the tensor-product cubic B-spline, C¹ shown.
    let row = [1.0, 4.0, 6.0, 4.0, 1.0];
    let mask2: Vec<String> = row
        .iter()
        .map(|y| {
            row.iter()
                .map(|x| format!("{}", x * y / 64.0))
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect();
    let (code, out, err) = subd(&["analyze", "--mask2", &mask2.join(";"), "--json"]);
    assert_eq!(code, 0, "{err}");
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["smoothness"], 1);
    // Surface eigenvalue test.
    let (code, out, _) = subd(&[
        "analyze",
        "--surface",
        "catmull-clark",
        "--valence",
        "5",
        "--json",
    ]);
    assert_eq!(code, 0);
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["passes"], true);
    assert!((j["eigenvalues"][0].as_f64().unwrap() - 1.0).abs() < 1e-12);
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
fn edit_meets_constraints_and_reports_json() {
    let s = Scratch::new("edit");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let input = root.join("meshes/torus_creased.obj");
    let constraints = root.join("edit/torus_edit.json");
    for (method, extra) in [
        ("least-squares", vec![]),
        ("energy", vec![]),
        ("energy", vec!["--region-rings", "1"]),
        ("energy", vec!["--penalty", "1e10", "--membrane", "0.1"]),
    ] {
        let out = s.0.join(format!("edit-{method}-{}.obj", extra.len()));
        let mut args = vec![
            "edit",
            "--constraints",
            constraints.to_str().unwrap(),
            "--method",
            method,
        ];
        args.extend(&extra);
        args.extend([input.to_str().unwrap(), out.to_str().unwrap(), "--json"]);
        let (code, stdout, err) = subd(&args);
        assert_eq!(code, 0, "{err}");
        let j: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        let tol = if extra.contains(&"--penalty") {
            1e-6
        } else {
            1e-10
        };
        assert!(
            j["max_residual_relative"].as_f64().unwrap() < tol,
            "{stdout}"
        );
        for r in j["residuals"].as_array().unwrap() {
            assert!(r["residual"].as_f64().unwrap() < 100.0 * tol, "{stdout}");
        }
        assert_eq!(j["constraints"], 4);
        assert!(j["energy_after"].as_f64().is_some());
        let moved = j["moved_vertices"].as_array().unwrap().len();
        assert!(moved > 0 && moved <= j["free_vertices"].as_u64().unwrap() as usize);
        assert!(out.exists());
    }
}

#[test]
fn edit_and_deform_bad_input_exit_2_without_output() {
    let s = Scratch::new("edit-bad");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let input = root.join("meshes/torus_creased.obj");
    let cases = [
        (
            r#"{"constraints": [{"kind": "pin", "vertex": 1}]}"#,
            "constraint 0: unknown kind \"pin\"",
        ),
        (
            r#"{"constraints": [{"kind": "point", "vertex": 1, "target": [0,0,0]}, {"kind": "point", "face": 999, "uv": [0.5, 0.5], "target": [0,0,0]}]}"#,
            "constraint 1: face 999 out of range",
        ),
        (
            r#"{"constraints": [{"kind": "point", "vertex": 720, "target": [0,0,0]}]}"#,
            "constraint 0: vertex 720 out of range",
        ),
        (
            r#"{"constraints": [{"kind": "point", "face": 3, "uv": [1.5, 0.5], "target": [0,0,0]}]}"#,
            "constraint 0: parameters (1.5, 0.5) outside [0, 1]",
        ),
        (
            r#"{"constraints": [{"kind": "normal", "vertex": 3, "normal": [0, 0, 0]}]}"#,
            "constraint 0: the normal is zero",
        ),
        (
            r#"{"constraints": [{"kind": "point", "vertex": 3, "target": [NaN, 0, 0]}]}"#,
            "not JSON",
        ),
        (
            r#"{"constraints": [{"kind": "isoline", "face": 3, "along": "u", "at": 0.5, "faces": 2, "targets": [[0,0,0]]}]}"#,
            "constraint 0: an iso-line over 2 faces needs 5 control points",
        ),
    ];
    for (k, (text, want)) in cases.iter().enumerate() {
        let c = s.file(&format!("c{k}.json"), text.as_bytes());
        let out = s.0.join(format!("out{k}.obj"));
        let (code, _, err) = subd(&[
            "edit",
            "--constraints",
            c.to_str().unwrap(),
            input.to_str().unwrap(),
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 2, "{text}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.starts_with(&format!("subd: {}", c.display())) && err.contains(want),
            "{err:?} lacks {want:?}"
        );
        assert!(!out.exists());
    }
    // Energy on Loop, and energy options with least squares.
    let c = root.join("edit/torus_edit.json");
    let out = s.0.join("x.obj");
    let (code, _, err) = subd(&[
        "edit",
        "--constraints",
        c.to_str().unwrap(),
        "--penalty",
        "5",
        input.to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--method energy only"), "{err}");
    let (code, _, err) = subd(&[
        "edit",
        "--constraints",
        c.to_str().unwrap(),
        "--method",
        "energy",
        "--region-rings",
        "many",
        input.to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(!out.exists());
    // Deformation: a zero radius, and coinciding centres.
    for (k, (text, want)) in [
        (r#"{"constraints": [{"center": [0,0,0], "radius": 0, "displacement": [0,0,1]}]}"#, "deformation constraint 0: the radius must be positive"),
        (r#"{"constraints": [{"center": [0,0,0], "radius": 1, "displacement": [0,0,1]}, {"center": [0,0,0], "radius": 2, "displacement": [0,0,1]}]}"#, "deformation constraint 1: its centre coincides"),
        (r#"{"constraints": [{"centre": [0,0,0], "radius": 1, "displacement": [0,0,1]}]}"#, "constraint 0: unknown field \"centre\""),
    ]
    .iter()
    .enumerate()
    {
        let c = s.file(&format!("d{k}.json"), text.as_bytes());
        let out = s.0.join(format!("d{k}.obj"));
        let (code, _, err) = subd(&["deform", "--constraints", c.to_str().unwrap(), input.to_str().unwrap(), out.to_str().unwrap()]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(want), "{err:?} lacks {want:?}");
        assert!(!out.exists());
    }
}

#[test]
fn deform_moves_constraint_points_and_keeps_the_rest() {
    let s = Scratch::new("deform");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let input = root.join("meshes/torus_creased.obj");
    let out = s.0.join("deformed.obj");
    let (code, stdout, err) = subd(&[
        "deform",
        "--constraints",
        root.join("edit/torus_deform.json").to_str().unwrap(),
        input.to_str().unwrap(),
        out.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let j: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert!(j["moved"].as_u64().unwrap() > 0);
    let (a, b) = (obj_vertices(&input), obj_vertices(&out));
    // Vertex 0 is the first centre (2.6, 0, 0): moved by exactly (0.4, 0, 0.3).
    assert!((b[0][0] - 3.0).abs() < 1e-12 && (b[0][2] - 0.3).abs() < 1e-12);
    let centres = [[2.6, 0.0, 0.0, 1.0], [-1.4, 0.0, 0.0, 0.6]];
    for (p, q) in a.iter().zip(&b) {
        let inside = centres.iter().any(|c| {
            ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2)).sqrt() < c[3]
        });
        if !inside {
            assert_eq!(p, q);
        }
    }
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

/// The regular files of `dir`, by name.
fn file_names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn batch_refine_goes_on_past_a_bad_file_and_matches_single_runs() {
    let s = Scratch::new("batch");
    let input = s.0.join("in");
    std::fs::create_dir_all(input.join("nested")).unwrap();
    for name in ["catmark_cube.obj", "catmark_pyramid.obj"] {
        std::fs::copy(meshes().join(name), input.join(name)).unwrap();
    }
    std::fs::copy(
        meshes().join("catmark_torus.obj"),
        input.join("nested/catmark_torus.obj"),
    )
    .unwrap();
    std::fs::write(input.join("broken.obj"), "v 0 0 0\nf 1 2 3\n").unwrap();
    std::fs::write(input.join("notes.txt"), "not a mesh").unwrap();
    let out_dir = s.0.join("out");
    let batch = |extra: &[&str]| {
        let mut args = vec![
            "refine",
            "--scheme",
            "catmull-clark",
            "--levels",
            "2",
            input.to_str().unwrap(),
            "--out-dir",
            out_dir.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        subd(&args)
    };
    let (code, out, err) = batch(&["--json"]);
    assert_eq!(code, 2, "one file failed: {err}");
    // One JSON line per file (four, the .txt is not a mesh), then the summary.
    let lines: Vec<serde_json::Value> = out
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 5, "{out}");
    let summary = &lines[4]["summary"];
    assert_eq!(
        (
            summary["files"].as_u64(),
            summary["succeeded"].as_u64(),
            summary["failed"].as_u64()
        ),
        (Some(4), Some(3), Some(1)),
        "{out}"
    );
    let failed: Vec<&serde_json::Value> = lines[..4]
        .iter()
        .filter(|l| l.get("error").is_some())
        .collect();
    assert_eq!(failed.len(), 1);
    assert!(failed[0]["input"].as_str().unwrap().ends_with("broken.obj"));
    assert_eq!(failed[0]["code"], 2);
    // Lines come in completion order; each names its input's place in the batch, the
    // inputs sorted by name, once each.
    let mut by_index: Vec<(u64, String)> = lines[..4]
        .iter()
        .map(|l| {
            (
                l["index"].as_u64().unwrap(),
                l["input"].as_str().unwrap().to_string(),
            )
        })
        .collect();
    by_index.sort();
    assert_eq!(
        by_index.iter().map(|x| x.0).collect::<Vec<_>>(),
        [0, 1, 2, 3]
    );
    assert!(by_index.windows(2).all(|w| w[0].1 < w[1].1), "{by_index:?}");
    // The bad file's usual one-line error, and the summary line.
    let broken = input.join("broken.obj");
    let errors: Vec<&str> = err
        .lines()
        .filter(|l| !l.starts_with("subd: warning"))
        .collect();
    assert_eq!(errors.len(), 2, "{err}");
    assert!(
        errors[0].starts_with(&format!("subd: {}", broken.display())),
        "{err}"
    );
    assert!(
        errors[1].contains("refine: 3 of 4 files done, 1 failed"),
        "{err}"
    );
    assert!(!err.contains("panicked"));
    // Outputs are named after the stems; nothing for the bad file, no temporary files.
    assert_eq!(
        file_names(&out_dir),
        [
            "catmark_cube.obj",
            "catmark_pyramid.obj",
            "catmark_torus.obj"
        ]
    );
    // Each output is what a single run writes.
    for (rel, name) in [
        ("catmark_cube.obj", "catmark_cube.obj"),
        ("nested/catmark_torus.obj", "catmark_torus.obj"),
    ] {
        let single = s.0.join(format!("single-{name}"));
        let (code, _, err) = subd(&[
            "refine",
            "--scheme",
            "catmull-clark",
            "--levels",
            "2",
            input.join(rel).to_str().unwrap(),
            single.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
        assert!(std::fs::read(&single).unwrap() == std::fs::read(out_dir.join(name)).unwrap());
    }
    // One file at a time gives the same files; --format picks the extension.
    std::fs::remove_dir_all(&out_dir).unwrap();
    let (code, out, err) = batch(&["--jobs", "1", "--format", "ply"]);
    assert_eq!(code, 2, "{err}");
    assert!(out.is_empty(), "no --json, nothing on stdout: {out}");
    assert_eq!(
        file_names(&out_dir),
        [
            "catmark_cube.ply",
            "catmark_pyramid.ply",
            "catmark_torus.ply"
        ]
    );
    // Without the bad file the batch succeeds, and says so on stderr.
    std::fs::remove_file(&broken).unwrap();
    let (code, _, err) = batch(&[]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("refine: 3 of 3 files done, 0 failed"), "{err}");
}

#[test]
fn batch_refuses_colliding_outputs_and_never_overwrites_inputs() {
    let s = Scratch::new("batch-refuse");
    let (a, b) = (s.0.join("a"), s.0.join("b"));
    for d in [&a, &b] {
        std::fs::create_dir_all(d).unwrap();
        std::fs::copy(meshes().join("loop_cube.obj"), d.join("cube.obj")).unwrap();
    }
    let out_dir = s.0.join("out");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "loop",
        "--levels",
        "1",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--out-dir",
        out_dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("would both write it"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        !out_dir.exists(),
        "nothing is written when the plan is refused"
    );
    // Writing into the input directory in the input's format would replace each input.
    let before = std::fs::read(a.join("cube.obj")).unwrap();
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "loop",
        "--levels",
        "1",
        a.to_str().unwrap(),
        "--out-dir",
        a.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("would overwrite the input"), "{err}");
    assert!(std::fs::read(a.join("cube.obj")).unwrap() == before);
    // Usage errors: three paths without --out-dir; a format refine does not write.
    let (code, _, err) = subd(&[
        "refine", "--scheme", "loop", "--levels", "1", "x.obj", "y.obj", "z.obj",
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("expected IN OUT"), "{err}");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "loop",
        "--levels",
        "1",
        a.to_str().unwrap(),
        "--out-dir",
        out_dir.to_str().unwrap(),
        "--format",
        "txt",
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("does not write it"), "{err}");
}

#[test]
fn batch_limit_pia_and_adaptive() {
    let s = Scratch::new("batch-others");
    let input = s.0.join("in");
    std::fs::create_dir_all(&input).unwrap();
    for name in ["loop_cube.obj", "loop_tetrahedron.obj"] {
        std::fs::copy(meshes().join(name), input.join(name)).unwrap();
    }
    let inp = input.to_str().unwrap();
    let runs: [(&str, Vec<&str>, &str); 3] = [
        ("limit", vec!["--scheme", "loop", "--format", "txt"], "txt"),
        ("pia", vec!["--scheme", "loop"], "obj"),
        (
            "adaptive",
            vec!["--scheme", "loop", "--flatness", "10"],
            "obj",
        ),
    ];
    for (command, options, ext) in runs {
        let out_dir = s.0.join(command);
        let mut args = vec![command];
        args.extend(options);
        args.extend([inp, "--out-dir", out_dir.to_str().unwrap(), "--json"]);
        let (code, out, err) = subd(&args);
        assert_eq!(code, 0, "{command}: {err}");
        let lines: Vec<serde_json::Value> = out
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        assert_eq!(lines.len(), 3, "{command}: {out}");
        assert_eq!(lines[2]["summary"]["succeeded"], 2, "{command}: {out}");
        assert_eq!(
            file_names(&out_dir),
            [
                format!("loop_cube.{ext}"),
                format!("loop_tetrahedron.{ext}")
            ],
            "{command}"
        );
    }
}

#[test]
fn a_gltf_exported_with_split_seams_refines_to_a_closed_mesh() {
    use subd_io::{MeshView, encode_view};
    let s = Scratch::new("gltf");
    // The cube as an exporter writes it: every face has its own four vertices.
    let corners = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
        [0.0, 1.0, 1.0],
    ];
    let faces = [
        [0, 3, 2, 1],
        [4, 5, 6, 7],
        [0, 1, 5, 4],
        [1, 2, 6, 5],
        [2, 3, 7, 6],
        [3, 0, 4, 7],
    ];
    let positions: Vec<subd_mesh::DVec3> = faces
        .iter()
        .flatten()
        .map(|&c| subd_mesh::DVec3::from_array(corners[c]))
        .collect();
    let offsets: Vec<u32> = (0..=6).map(|f| 4 * f).collect();
    let vertices: Vec<u32> = (0..24).collect();
    let holes = vec![false; 6];
    let view = MeshView::new(&positions, &offsets, &vertices, &holes).unwrap();
    let mut glb = Vec::new();
    encode_view(
        &mut glb,
        &view,
        subd_io::Format::Glb,
        &subd_io::WriteOptions::default(),
    )
    .unwrap();
    let input = s.file("cube.glb", &glb);
    let output = s.0.join("cube-refined.obj");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "loop",
        "--levels",
        "2",
        input.to_str().unwrap(),
        output.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("24 glTF vertices welded by position into 8"),
        "{err}"
    );
    let refined = subd_io::read_mesh(&output, &subd_io::ReadOptions::default()).unwrap();
    let topo = &refined.mesh.topology;
    assert_eq!(topo.num_faces(), 12 * 16);
    assert!(
        (0..topo.num_edges()).all(|e| topo.edge_faces(e).len() == 2),
        "closed, manifold"
    );
    assert_eq!(
        topo.num_vertices() + topo.num_faces() - topo.num_edges(),
        2,
        "a sphere"
    );
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

/// The pixels of an 8-bit RGB PNG, with its width and height.
fn read_png(path: &Path) -> (usize, usize, Vec<[u8; 3]>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    let pixels = buf[..info.buffer_size()]
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    (info.width as usize, info.height as usize, pixels)
}

#[test]
fn render_draws_a_limit_sphere_as_the_expected_disc() {
    let s = Scratch::new("render");
    let ico = meshes().join("loop_icosahedron.obj");
    let picture = s.0.join("ico.png");
    let (code, _, err) = subd(&[
        "render",
        ico.to_str().unwrap(),
        picture.to_str().unwrap(),
        "--limit",
        "--levels",
        "4",
        "--size",
        "240x200",
        "--view",
        "0,0",
    ]);
    assert_eq!(code, 0, "{err}");
    // The limit surface's extent, from `subd refine --limit` at the same level: the picture
    // frames the bounding sphere about the bounding box's centre into 45% of the shorter side
    // (90 pixels); looking down −z, the silhouette is the surface's extent in x and y.
    let samples = s.0.join("ico-limit.obj");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "loop",
        "--levels",
        "4",
        "--limit",
        ico.to_str().unwrap(),
        samples.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let p = subd_io::read_mesh(&samples, &subd_io::ReadOptions::default())
        .unwrap()
        .mesh
        .positions;
    let (lo, hi) = p.iter().fold(
        (
            subd_mesh::DVec3::splat(f64::MAX),
            subd_mesh::DVec3::splat(f64::MIN),
        ),
        |(l, h), q| (l.min(*q), h.max(*q)),
    );
    let c = (lo + hi) / 2.0;
    let radius = p.iter().map(|q| q.distance(c)).fold(0.0, f64::max);
    let inner = p.iter().map(|q| q.distance(c)).fold(f64::MAX, f64::min);
    let scale = 90.0 / radius;
    assert!(inner / radius > 0.97, "sphere-like: {inner} .. {radius}");
    let (w, h, pixels) = read_png(&picture);
    assert_eq!((w, h), (240, 200));
    let background = pixels[0];
    let (cx, cy) = (120.0 + scale * -c.x, 100.0 - scale * c.y);
    let (mut inside, mut covered) = (0usize, 0usize);
    for y in 0..h {
        for x in 0..w {
            let d = ((x as f64 + 0.5 - cx).powi(2) + (y as f64 + 0.5 - cy).powi(2)).sqrt();
            let px = pixels[y * w + x];
            if d < scale * inner - 1.5 {
                assert_ne!(
                    px, background,
                    "pixel ({x}, {y}) inside the disc is background"
                );
                inside += 1;
            }
            if d > scale * radius + 1.5 {
                assert_eq!(px, background, "pixel ({x}, {y}) outside the disc is drawn");
            }
            covered += usize::from(px != background);
        }
    }
    let r_mid = scale * (inner + radius) / 2.0;
    let expected = std::f64::consts::PI * r_mid * r_mid;
    assert!(inside > 20_000, "{inside}");
    assert!(
        (covered as f64 / expected - 1.0).abs() < 0.04,
        "{covered} pixels, expected about {expected:.0}"
    );
    // Lit from the upper left: the upper-left quadrant is brighter than the lower right.
    let luma = |x: usize, y: usize| pixels[y * w + x].iter().map(|&v| u32::from(v)).sum::<u32>();
    assert!(luma(95, 75) > luma(145, 125));

    // The cage is drawn over the surface in its own colour; bad requests leave no file.
    let caged = s.0.join("caged.png");
    let (code, _, err) = subd(&[
        "render",
        ico.to_str().unwrap(),
        caged.to_str().unwrap(),
        "--cage",
        "--scheme",
        "loop",
    ]);
    assert_eq!(code, 0, "{err}");
    let (_, _, pixels) = read_png(&caged);
    assert!(pixels.contains(&[214, 96, 20]), "cage colour present");
    for (args, expect) in [
        (vec!["--size", "0x10"], "a side is 1 to"),
        (vec!["--levels", "2"], "--levels needs --scheme or --limit"),
        (vec!["--view", "north"], "AZIMUTH,ELEVATION"),
    ] {
        let bad = s.0.join("bad.png");
        let mut a = vec!["render", ico.to_str().unwrap(), bad.to_str().unwrap()];
        a.extend(args);
        let (code, _, err) = subd(&a);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(expect), "{err}");
        assert!(!bad.exists());
    }
    let (code, _, err) = subd(&[
        "render",
        ico.to_str().unwrap(),
        s.0.join("x.jpg").to_str().unwrap(),
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("expected .png"), "{err}");
}

#[test]
fn the_readme_pictures_come_from_docs_pictures_sh() {
    let s = Scratch::new("pictures");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let status = Command::new("bash")
        .arg("docs/pictures.sh")
        .current_dir(&root)
        .env("SUBD", env!("CARGO_BIN_EXE_subd"))
        .env("OUT", &s.0)
        .status()
        .expect("run bash");
    assert!(status.success());
    for name in [
        "torus_creased.png",
        "pia_targets.png",
        "adaptive_levels.png",
    ] {
        let (w, h, made) = read_png(&s.0.join(name));
        let (cw, ch, committed) = read_png(&root.join("docs").join(name));
        assert_eq!((w, h), (cw, ch), "{name}");
        let differing = made.iter().zip(&committed).filter(|(a, b)| a != b).count();
        assert!(
            differing * 100 < made.len(),
            "{name}: {differing} of {} pixels differ from the committed picture",
            made.len()
        );
    }
}

#[test]
fn requests_over_the_memory_budget_are_refused_not_aborted() {
    let s = Scratch::new("budget");
    let torus =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/meshes/torus_creased.obj");
    let torus = torus.to_str().unwrap();
    let out = s.0.join("out.obj");
    // --max-memory: the estimate, the budget and the deepest level that fits, before any work.
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "catmull-clark",
        "--levels",
        "6",
        "--max-memory",
        "30M",
        torus,
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.starts_with(&format!("subd: {torus}: refining 6 levels needs about "))
            && err.contains("over the budget of 30.0 MiB (--max-memory); --levels 5 fits"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!out.exists());
    // The level it names does fit.
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "catmull-clark",
        "--levels",
        "5",
        "--max-memory",
        "30M",
        torus,
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    std::fs::remove_file(&out).unwrap();

    // Under an address-space limit (`ulimit -v`, 1 GiB): the CLI's estimate refuses a cube
    // to 12 levels (100 M faces)...
    let cube = meshes().join("catmark_cube.obj");
    let limited = |extra: &str| {
        let script = format!(
            "ulimit -v 1048576; exec \"$0\" refine --scheme catmull-clark --levels 12 {extra} \"$1\" \"$2\""
        );
        let o = Command::new("bash")
            .args(["-c", &script, env!("CARGO_BIN_EXE_subd")])
            .arg(&cube)
            .arg(&out)
            .output()
            .unwrap();
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let (code, err) = limited("");
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("(the address-space limit, ulimit -v)"),
        "{err}"
    );
    // ...and with the estimate overridden, the library refuses the level it cannot allocate
    // with a typed error: one line, exit 2, no abort, no partial file.
    let (code, err) = limited("--max-memory 1T");
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("more memory, which cannot be allocated"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!err.contains("memory allocation of"), "{err}");
    assert!(!out.exists());

    // In a batch, a file over the budget fails alone.
    let input = s.0.join("in");
    std::fs::create_dir_all(&input).unwrap();
    std::fs::copy(&cube, input.join("cube.obj")).unwrap();
    std::fs::copy(torus, input.join("torus.obj")).unwrap();
    let out_dir = s.0.join("out");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "catmull-clark",
        "--levels",
        "6",
        "--max-memory",
        "60M",
        "--jobs",
        "2",
        input.to_str().unwrap(),
        "--out-dir",
        out_dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("torus.obj: refining 6 levels"), "{err}");
    assert!(err.contains("refine: 1 of 2 files done, 1 failed"), "{err}");
    assert_eq!(file_names(&out_dir), ["cube.obj"]);
}

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

#[test]
fn batch_progress_bar_on_a_terminal_draws_and_finishes() {
    let s = Scratch::new("batch-tty");
    let input = s.0.join("in");
    std::fs::create_dir_all(&input).unwrap();
    for name in ["catmark_cube.obj", "catmark_torus.obj"] {
        std::fs::copy(meshes().join(name), input.join(name)).unwrap();
    }
    std::fs::write(input.join("broken.obj"), "v 0 0\n").unwrap();
    let out_dir = s.0.join("out");
    let cmd = format!(
        "{} refine --scheme catmull-clark --levels 5 {} --out-dir {}",
        env!("CARGO_BIN_EXE_subd"),
        input.display(),
        out_dir.display()
    );
    let transcript = s.0.join("transcript.txt");
    let status = Command::new("script")
        .args(["-qec", &cmd, transcript.to_str().unwrap()])
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .status()
        .expect("`script` (util-linux) runs the command on a pseudo-terminal");
    // `script -e` passes on the command's exit code: 2, one file failed.
    assert_eq!(status.code(), Some(2));
    let seen = String::from_utf8_lossy(&std::fs::read(&transcript).unwrap()).into_owned();
    assert!(seen.contains("files"), "the bar counts files: {seen}");
    assert!(
        seen.contains("broken.obj"),
        "the failed file's line: {seen}"
    );
    assert!(
        seen.contains("refine: 2 of 3 files done, 1 failed"),
        "{seen}"
    );
    assert_eq!(
        file_names(&out_dir),
        ["catmark_cube.obj", "catmark_torus.obj"]
    );
}

/// The texture coordinate of every corner of a mesh file, face after face.
fn corner_uvs(path: &Path) -> Vec<[f64; 2]> {
    let file = subd_io::read_mesh(path, &subd_io::ReadOptions::default()).unwrap();
    let uv = file.mesh.uv().expect("texture coordinates");
    uv.indices()
        .iter()
        .map(|&i| [uv.value(i as usize)[0], uv.value(i as usize)[1]])
        .collect()
}

#[test]
fn refine_carries_texture_coordinates_to_obj_and_glb() {
    use subd_mesh::fvar::FVarLinearInterpolation;
    let s = Scratch::new("uv");
    let input = meshes().join("catmark_fvar_bound1.obj");
    let obj = s.0.join("uv.obj");
    let glb = s.0.join("uv.glb");
    for out in [&obj, &glb] {
        let args = ["refine", "--scheme", "catmull-clark", "--levels", "2"];
        let (code, _, err) =
            subd(&[&args[..], &[input.to_str().unwrap(), out.to_str().unwrap()]].concat());
        assert_eq!(code, 0, "{err}");
    }
    // The OBJ's corners hold the library's refinement (corners-plus1: the file has no tag).
    let file = subd_io::read_mesh(&input, &subd_io::ReadOptions::default()).unwrap();
    let options = subd_schemes::Options::from_hints(&file.mesh.hints);
    let r = subd_schemes::Refinement::new(
        &file.mesh.topology,
        subd_schemes::Scheme::CatmullClark,
        &options,
        2,
    )
    .unwrap();
    let channel = file.mesh.uv().unwrap();
    let fr = subd_schemes::FaceVaryingRefinement::new(
        &r,
        channel,
        FVarLinearInterpolation::CornersPlus1,
    )
    .unwrap();
    let values = fr.refine_values(&r, channel.values(), 2).pop().unwrap();
    let expected: Vec<[f64; 2]> = fr
        .face_values(2)
        .iter()
        .map(|&i| [values[2 * i as usize], values[2 * i as usize + 1]])
        .collect();
    let written = corner_uvs(&obj);
    assert_eq!(written, expected);
    let text = std::fs::read_to_string(&obj).unwrap();
    assert!(text.contains("\nt facevaryinginterpolateboundary 1/0/0 2\n"));
    assert_eq!(
        text.lines().filter(|l| l.starts_with("vt ")).count(),
        fr.num_values(2)
    );

    // The .glb read back with the gltf crate: every triangle corner carries its corner's
    // value, v flipped to glTF's origin, at its vertex's position.
    let refined = subd_io::read_mesh(&obj, &subd_io::ReadOptions::default())
        .unwrap()
        .mesh;
    let bytes = std::fs::read(&glb).unwrap();
    let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
    let blob = gltf.blob.as_deref().unwrap();
    let prim = gltf.meshes().next().unwrap().primitives().next().unwrap();
    let reader = prim.reader(|_| Some(blob));
    let tex: Vec<[f32; 2]> = reader
        .read_tex_coords(0)
        .expect("TEXCOORD_0")
        .into_f32()
        .collect();
    let pos: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
    let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
    let t = &refined.topology;
    let mut k = 0;
    for f in 0..t.num_faces() {
        let fv = t.face_vertices(f);
        let o = t.face_offsets()[f] as usize;
        for i in 1..fv.len() - 1 {
            for c in [0, i, i + 1] {
                let g = indices[k] as usize;
                k += 1;
                let [u, v] = written[o + c];
                assert_eq!(tex[g], [u as f32, (1.0 - v) as f32]);
                let p = refined.positions[fv[c] as usize];
                assert_eq!(pos[g], [p.x as f32, p.y as f32, p.z as f32]);
            }
        }
    }
    assert_eq!(k, indices.len());
    // Read back by subd: the seams survive the welding.
    let back = subd_io::read_mesh(&glb, &subd_io::ReadOptions::default())
        .unwrap()
        .mesh;
    let seams = |m: &subd_mesh::Mesh| {
        subd_mesh::fvar::FVarSeams::of(&m.topology, m.uv().unwrap()).num_seam_edges()
    };
    assert_eq!(seams(&back), seams(&refined));
}

#[test]
fn ply_leaves_out_texture_coordinates_with_seams() {
    let s = Scratch::new("uvply");
    let input = meshes().join("catmark_fvar_bound1.obj");
    let out = s.0.join("uv.ply");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "catmull-clark",
        "--levels",
        "1",
        input.to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("subd: warning:") && err.contains("seams") && err.contains(".obj or .glb"),
        "{err}"
    );
    let bytes = std::fs::read(&out).unwrap();
    assert!(!String::from_utf8_lossy(&bytes).contains("property double u"));
    // A seamless layout goes through PLY as u v and comes back the same.
    let quad = s.file(
        "quad.obj",
        b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n",
    );
    let ply = s.0.join("quad.ply");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "bilinear",
        "--levels",
        "1",
        quad.to_str().unwrap(),
        ply.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let bytes = std::fs::read(&ply).unwrap();
    assert!(String::from_utf8_lossy(&bytes).contains("property double u\nproperty double v\n"));
    // Bilinear UVs of a unit square laid out as its positions: u = x, v = y everywhere.
    let back = subd_io::read_mesh(&ply, &subd_io::ReadOptions::default())
        .unwrap()
        .mesh;
    let uv = back.uv().unwrap();
    for (c, &v) in back.topology.all_face_vertices().iter().enumerate() {
        let p = back.positions[v as usize];
        assert_eq!(uv.value(uv.indices()[c] as usize), [p.x, p.y]);
    }
}

#[test]
fn fvar_interpolation_comes_from_the_option_then_the_tag_then_corners_plus1() {
    let s = Scratch::new("uvmode");
    let refine = |input: &Path, mode: Option<&str>, out: &str| -> Vec<u8> {
        let out = s.0.join(out);
        let mut args = vec![
            "refine",
            "--scheme",
            "catmull-clark",
            "--levels",
            "2",
            input.to_str().unwrap(),
            out.to_str().unwrap(),
        ];
        if let Some(m) = mode {
            args.extend(["--fvar-interpolation", m]);
        }
        let (code, _, err) = subd(&args);
        assert_eq!(code, 0, "{err}");
        std::fs::read(&out).unwrap()
    };
    // catmark_cubes_semisharp carries `t facevaryinginterpolateboundary 1/0/0 1`.
    let tagged = meshes().join("catmark_cubes_semisharp.obj");
    assert_eq!(
        refine(&tagged, None, "a.obj"),
        refine(&tagged, Some("corners-only"), "b.obj")
    );
    assert_ne!(
        refine(&tagged, None, "a.obj"),
        refine(&tagged, Some("all"), "c.obj")
    );
    let untagged = meshes().join("catmark_fvar_bound1.obj");
    assert_eq!(
        refine(&untagged, None, "d.obj"),
        refine(&untagged, Some("corners-plus1"), "e.obj")
    );
    assert_ne!(
        refine(&untagged, None, "d.obj"),
        refine(&untagged, Some("none"), "f.obj")
    );
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "loop",
        "--levels",
        "1",
        "--fvar-interpolation",
        "sideways",
        untagged.to_str().unwrap(),
        s.0.join("g.obj").to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
}

#[test]
fn info_pia_and_limit_keep_texture_coordinates() {
    let s = Scratch::new("uvcmd");
    let input = meshes().join("catmark_fvar_bound1.obj");
    let (code, stdout, err) = subd(&["info", input.to_str().unwrap(), "--json"]);
    assert_eq!(code, 0, "{err}");
    let j: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let file = subd_io::read_mesh(&input, &subd_io::ReadOptions::default()).unwrap();
    let seams = subd_mesh::fvar::FVarSeams::of(&file.mesh.topology, file.mesh.uv().unwrap());
    assert_eq!(j["fvar_channels"][0]["seam_edges"], seams.num_seam_edges());
    assert_eq!(
        j["fvar_channels"][0]["seam_vertices"],
        seams.num_seam_vertices()
    );
    assert_eq!(
        j["fvar_channels"][0]["values"],
        file.mesh.uv().unwrap().num_values()
    );
    // PIA changes positions only: every corner keeps its texture coordinate.
    let fitted = s.0.join("pia.obj");
    let (code, _, err) = subd(&[
        "pia",
        "--scheme",
        "catmull-clark",
        input.to_str().unwrap(),
        fitted.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(corner_uvs(&fitted), corner_uvs(&input));
    // The limit command moves them to their limit: the library's base limit.
    let limit = s.0.join("limit.obj");
    let (code, _, err) = subd(&[
        "limit",
        "--scheme",
        "catmull-clark",
        input.to_str().unwrap(),
        limit.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let options = subd_schemes::Options::from_hints(&file.mesh.hints);
    let base = subd_limit::fvar::base_fvar_limit(
        &file.mesh.topology,
        &subd_schemes::Scheme::CatmullClark,
        &options,
        file.mesh.uv().unwrap(),
        subd_mesh::fvar::FVarLinearInterpolation::CornersPlus1,
    )
    .unwrap();
    let at = base.apply(file.mesh.uv().unwrap().values(), 2);
    let t = &file.mesh.topology;
    let uvs = corner_uvs(&limit);
    for f in 0..t.num_faces() {
        let o = t.face_offsets()[f] as usize;
        for (c, (&v, &x)) in t
            .face_vertices(f)
            .iter()
            .zip(file.mesh.uv().unwrap().face_values(t, f))
            .enumerate()
        {
            let r = base
                .vertex_rows(v as usize)
                .find(|&r| base.value(r) == x)
                .unwrap();
            assert_eq!(uvs[o + c], [at[2 * r], at[2 * r + 1]]);
        }
    }
}

/// `subd adaptive` carries UVs: with every face selected its `--limit` output has the same
/// (position, UV) pairs at its corners as `subd refine --limit` (limit masks on the refined
/// values there, patch evaluation at each corner's parameter here), and a PLY output leaves
/// seamed UVs out with a warning.
#[test]
fn adaptive_carries_limit_uvs() {
    let s = Scratch::new("adaptiveuv");
    let cube = meshes().join("catmark_cube.obj");
    let (a, r) = (s.0.join("a.obj"), s.0.join("r.obj"));
    let (code, _, err) = subd(&[
        "adaptive",
        "--scheme",
        "catmull-clark",
        "--levels",
        "2",
        "--limit",
        cube.to_str().unwrap(),
        a.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("texture"), "{err}");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "catmull-clark",
        "--levels",
        "2",
        "--limit",
        cube.to_str().unwrap(),
        r.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let corners = |path: &Path| {
        let m = subd_io::read_mesh(path, &subd_io::ReadOptions::default())
            .unwrap()
            .mesh;
        let uv = m.uv().expect("UVs written").clone();
        let t = &m.topology;
        let mut out: Vec<[i64; 5]> = Vec::new();
        for f in 0..t.num_faces() {
            for (&v, &x) in t.face_vertices(f).iter().zip(uv.face_values(t, f)) {
                let p = m.positions[v as usize];
                let q = uv.value(x as usize);
                let key = |y: f64| (y * 1e9).round() as i64;
                out.push([key(p.x), key(p.y), key(p.z), key(q[0]), key(q[1])]);
            }
        }
        out.sort_unstable();
        out
    };
    assert_eq!(corners(&a), corners(&r));
    let ply = s.0.join("a.ply");
    let (code, _, err) = subd(&[
        "adaptive",
        "--scheme",
        "catmull-clark",
        "--levels",
        "1",
        cube.to_str().unwrap(),
        ply.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("texture coordinates left out"), "{err}");
}

/// The split schemes carry texture coordinates: the butterflies with their seams (every base
/// corner keeps its value, the scheme interpolates; `limit` leaves them as they are, each
/// its own limit), Doo-Sabin and √3 only without seams (else a warning and none written).
#[test]
fn split_schemes_carry_texture_coordinates() {
    let s = Scratch::new("splituv");
    let input = meshes().join("loop_cube.obj");
    let given = corner_uvs(&input);
    let out = s.0.join("b.obj");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "modified-butterfly",
        "--levels",
        "2",
        input.to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.is_empty(), "{err}");
    let written = corner_uvs(&out);
    assert_eq!(written.len(), 16 * given.len());
    for f in 0..given.len() / 3 {
        for (k, child) in [(0, 0), (1, 5), (2, 10)] {
            assert_eq!(written[3 * (16 * f + child) + k], given[3 * f + k]);
        }
    }
    let limit = s.0.join("bl.obj");
    let (code, _, err) = subd(&[
        "limit",
        "--scheme",
        "butterfly",
        input.to_str().unwrap(),
        limit.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.is_empty(), "{err}");
    assert_eq!(corner_uvs(&limit), given);

    // Doo-Sabin: the cube's UVs have seams.
    let ds = s.0.join("ds.obj");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "doo-sabin",
        "--levels",
        "1",
        input.to_str().unwrap(),
        ds.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("subd: warning:") && err.contains("texture seam"),
        "{err}"
    );
    let text = std::fs::read_to_string(&ds).unwrap();
    assert!(!text.contains("\nvt "), "no texture coordinates");
    // `limit` keeps them as given, with the same warning.
    let dsl = s.0.join("dsl.obj");
    let (code, _, err) = subd(&[
        "limit",
        "--scheme",
        "doo-sabin",
        input.to_str().unwrap(),
        dsl.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("texture seam"), "{err}");
    assert_eq!(corner_uvs(&dsl), given);

    // A seamless square grid: √3 writes one value per vertex, the vertex's x y where the
    // UVs are the positions (√3 maps the plane to itself).
    let grid = s.file(
        "grid.obj",
        b"v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\n\
         vt 0 0\nvt 1 0\nvt 2 0\nvt 0 1\nvt 1 1\nvt 2 1\n\
         f 1/1 2/2 5/5\nf 1/1 5/5 4/4\nf 2/2 3/3 6/6\nf 2/2 6/6 5/5\n",
    );
    let s3 = s.0.join("s3.obj");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "sqrt3",
        "--levels",
        "2",
        grid.to_str().unwrap(),
        s3.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.is_empty(), "{err}");
    // The same for √3's limit points (`refine --limit` and `limit`).
    let s3l = s.0.join("s3l.obj");
    let gl = s.0.join("gl.obj");
    for (args, out) in [
        (
            &["refine", "--scheme", "sqrt3", "--levels", "2", "--limit"][..],
            &s3l,
        ),
        (&["limit", "--scheme", "sqrt3"][..], &gl),
    ] {
        let (code, _, err) =
            subd(&[args, &[grid.to_str().unwrap(), out.to_str().unwrap()]].concat());
        assert_eq!(code, 0, "{err}");
        assert!(err.is_empty(), "{err}");
    }
    for path in [&s3, &s3l, &gl] {
        let refined = subd_io::read_mesh(path, &subd_io::ReadOptions::default())
            .unwrap()
            .mesh;
        let uvs = corner_uvs(path);
        let t = &refined.topology;
        for (i, &v) in t.all_face_vertices().iter().enumerate() {
            let p = refined.positions[v as usize];
            assert!(
                (uvs[i][0] - p.x).abs() < 1e-12 && (uvs[i][1] - p.y).abs() < 1e-12,
                "{}: corner {i}: {:?} at {p:?}",
                path.display(),
                uvs[i]
            );
        }
    }
}
