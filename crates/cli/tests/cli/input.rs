//! Reading: malformed files of every kind, `subd info`, usage errors, glTF seams.

use super::*;

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

/// A `.glb` that subd wrote from a mesh with UV seams reads back with no warning: welding
/// only joins the copies the writer split at the seams.
#[test]
fn subds_own_glb_with_uv_seams_reads_back_without_warnings() {
    let s = Scratch::new("glb-seams");
    // A cube whose every face is a UV island of its own: twelve seam edges.
    let cube = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
        vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
        f 1/1 4/2 3/3 2/4\nf 5/1 6/2 7/3 8/4\nf 1/1 2/2 6/3 5/4\n\
        f 2/1 3/2 7/3 6/4\nf 3/1 4/2 8/3 7/4\nf 4/1 1/2 5/3 8/4\n";
    let input = s.file("cube.obj", cube.as_bytes());
    let glb = s.0.join("cube.glb");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "catmull-clark",
        "--levels",
        "1",
        input.to_str().unwrap(),
        glb.to_str().unwrap(),
    ]);
    assert_eq!((code, err.as_str()), (0, ""));
    let (code, out, err) = subd(&["info", glb.to_str().unwrap(), "--json"]);
    assert_eq!((code, err.as_str()), (0, ""));
    let report: serde_json::Value = serde_json::from_str(&out).unwrap();
    // Closed again: the refined cube's 26 vertices, 24 quads fanned into 48 triangles.
    assert_eq!(report["vertices"], 26);
    assert_eq!(report["faces"], 48);
    assert_eq!(report["boundary_edges"], 0);
}

/// An input refused for inconsistent orientation prints its refusal alone: one line, exit 2,
/// without the "treated as non-manifold" warnings read before it, whether the reader
/// refuses it or (accepted with the flag) the scheme does; in batch mode too, where the
/// other inputs keep their warnings. An input that is not refused keeps its warnings.
#[test]
fn a_refused_input_prints_the_refusal_alone() {
    let s = Scratch::new("refusal-alone");
    let vertices = "v 0 0 1\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nv 0 0 -1\n";
    // An octahedron with two faces turned over: six edges used twice the same way.
    let flipped = format!(
        "{vertices}f 1 3 2\nf 1 3 4\nf 1 4 5\nf 1 5 2\nf 6 3 2\nf 6 3 4\nf 6 5 4\nf 6 2 5\n"
    );
    // The octahedron as it should be, with a line the reader warns about.
    let warned = format!(
        "{vertices}f 1 2 3\nf 1 3 4\nf 1 4 5\nf 1 5 2\nf 6 3 2\nf 6 4 3\nf 6 5 4\nf 6 2 5\nfrob 1\n"
    );
    let input = s.file("flipped.obj", flipped.as_bytes());
    let good = s.file("warned.obj", warned.as_bytes());
    let output = s.0.join("out.obj");
    let (input, output) = (input.to_str().unwrap(), output.to_str().unwrap());
    let refine = |scheme: &str, accept: bool| {
        let mut args = vec!["refine", "--scheme", scheme, "--levels", "1"];
        if accept {
            args.push("--accept-inconsistent-orientation");
        }
        subd(&[&args[..], &[input, output]].concat())
    };
    for (scheme, accept, expect) in [
        (
            "loop",
            false,
            "in the same direction (inconsistent orientation)",
        ),
        (
            "sqrt3",
            true,
            "is non-manifold; the sqrt3 scheme needs a manifold mesh",
        ),
    ] {
        let (code, _, err) = refine(scheme, accept);
        assert_eq!(code, 2, "{scheme}: {err}");
        assert_eq!(err.lines().count(), 1, "{scheme}: {err}");
        assert!(err.starts_with(&format!("subd: {input}")), "{err}");
        assert!(err.contains(expect), "{scheme}: {err}");
    }
    // Accepted by a scheme that takes non-manifold edges, the warnings are printed.
    let (code, _, err) = refine("loop", true);
    assert_eq!(code, 0, "{err}");
    assert_eq!(err.matches("treated as non-manifold").count(), 6, "{err}");
    // In batch mode the refused input's refusal stands alone; the other input warns.
    let dir = s.0.join("batch");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "sqrt3",
        "--levels",
        "1",
        "--accept-inconsistent-orientation",
        "--out-dir",
        dir.to_str().unwrap(),
        input,
        good.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(!err.contains("treated as non-manifold"), "{err}");
    assert_eq!(err.matches("needs a manifold mesh").count(), 1, "{err}");
    assert!(
        err.contains("unknown OBJ statement \"frob\" ignored"),
        "{err}"
    );
    assert!(dir.join("warned.obj").exists());
}

/// `subd info --devices` lists the GPU adapters (CI has Mesa's lavapipe, a Vulkan one) or
/// says there is none; it takes no mesh.
#[test]
fn info_lists_the_gpu_adapters() {
    let (code, out, err) = subd(&["info", "--devices", "--json"]);
    assert_eq!(code, 0, "{err}");
    let adapters: Vec<serde_json::Value> = serde_json::from_str(&out).unwrap();
    if std::env::var_os("CI").is_some() {
        assert!(adapters.iter().any(|a| a["backend"] == "Vulkan"), "{out}");
    }
    let (code, text, err) = subd(&["info", "--devices"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(text.lines().count(), adapters.len().max(1), "{text}");
    let (code, _, err) = subd(&["info", "--devices", "some.obj"]);
    assert_eq!(code, 2, "{err}");
}
