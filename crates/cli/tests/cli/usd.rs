//! USD through the commands: the scheme a stage names, prims picked and batched, cages that
//! keep their scheme, refusals that name the prim.

use std::path::{Path, PathBuf};

use super::{Scratch, subd};

/// The stages Pixar's USD wrote for the tests (`tests/data/usd`).
fn stage(name: &str) -> PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/usd")
        .join(name)
}

fn path(p: &std::path::Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn the_scheme_the_stage_names_is_the_default() {
    let s = Scratch::new("usd-scheme");
    let input = stage("meshes.usda");
    let (named, given) = (s.0.join("named.obj"), s.0.join("given.obj"));
    let prim = ["--prim", "/World/Strip"];
    let (code, _, err) = subd(&[
        "refine",
        "--levels",
        "2",
        prim[0],
        prim[1],
        path(&input),
        path(&named),
    ]);
    assert_eq!(code, 0, "{err}");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "loop",
        "--levels",
        "2",
        prim[0],
        prim[1],
        path(&input),
        path(&given),
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        std::fs::read(&named).unwrap(),
        std::fs::read(&given).unwrap()
    );
    // A polygon mesh names none, an OBJ names none: --scheme is needed.
    let out = s.0.join("flat.obj");
    let (code, _, err) = subd(&[
        "refine",
        "--levels",
        "1",
        "--prim",
        "/World/Flat",
        path(&input),
        path(&out),
    ]);
    assert_eq!(code, 2);
    assert!(
        err.contains("subdivisionScheme none): give --scheme"),
        "{err}"
    );
    let cube = super::meshes().join("catmark_cube.obj");
    let (code, _, err) = subd(&["refine", "--levels", "1", path(&cube), path(&out)]);
    assert_eq!(code, 2);
    assert!(
        err.contains("no --scheme given, and the file names no subdivision scheme"),
        "{err}"
    );
    assert!(!out.exists());
}

#[test]
fn several_prims_need_a_choice_or_the_batch() {
    let s = Scratch::new("usd-prims");
    let input = stage("meshes.usda");
    let out = s.0.join("one.usda");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "bilinear",
        "--levels",
        "1",
        path(&input),
        path(&out),
    ]);
    assert_eq!(code, 2);
    assert!(
        err.contains("the stage has 4 Mesh prims; pick one with --prim"),
        "{err}"
    );
    let dir = s.0.join("batch");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "bilinear",
        "--levels",
        "1",
        path(&input),
        "--out-dir",
        path(&dir),
    ]);
    assert_eq!(code, 0, "{err}");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "meshes_World_Cage.usda",
            "meshes_World_Flat.usda",
            "meshes_World_Strip.usda",
            "meshes_World_Sub_Grid.usda"
        ]
    );
    // The output prim is named after the input's, the stage's units written back.
    let text = std::fs::read_to_string(dir.join("meshes_World_Cage.usda")).unwrap();
    assert!(text.contains("def Mesh \"Cage\""), "{text}");
    assert!(text.contains("metersPerUnit = 0.01") && text.contains("upAxis = \"Z\""));
    assert!(text.contains("uniform token subdivisionScheme = \"none\""));
}

#[test]
fn a_cage_keeps_its_scheme_and_a_nameless_one_is_warned_about() {
    let s = Scratch::new("usd-cage");
    let cube = super::meshes().join("catmark_cube.obj");
    let cage = s.0.join("cage.usda");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "loop",
        "--levels",
        "0",
        path(&super::meshes().join("loop_cube.obj")),
        path(&cage),
    ]);
    assert_eq!(code, 0, "{err}");
    let text = std::fs::read_to_string(&cage).unwrap();
    assert!(
        text.contains("uniform token subdivisionScheme = \"loop\""),
        "{text}"
    );
    let ds = s.0.join("ds.usdc");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "doo-sabin",
        "--levels",
        "0",
        path(&cube),
        path(&ds),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("USD has no name for the doo-sabin scheme"),
        "{err}"
    );
    let (code, info, err) = subd(&["info", "--json", path(&ds)]);
    assert_eq!(code, 0, "{err}");
    assert!(info.contains("\"scheme\":\"polygons\""), "{info}");
    // It holds the cage refined two levels: what `refine --levels 2` writes as OBJ.
    let obj = s.0.join("ds2.obj");
    let flags = ["refine", "--scheme", "doo-sabin", "--levels", "2"];
    let (code, _, err) = subd(&[&flags[..], &[path(&cube), path(&obj)]].concat());
    assert_eq!(code, 0, "{err}");
    let read = |p: &Path| subd_io::read_mesh(p, &subd_io::ReadOptions::default()).unwrap();
    let (usd, obj) = (read(&ds).mesh, read(&obj).mesh);
    let faces = |m: &subd_mesh::Mesh| m.topology.all_face_vertices().to_vec();
    assert_eq!(faces(&usd), faces(&obj));
    for (a, b) in usd.positions.iter().zip(&obj.positions) {
        // The OBJ holds 17 significant digits, the .usdc single precision.
        assert!((*a - *b).abs().max_element() < 1e-6, "{a} {b}");
    }
}

#[test]
fn bad_stages_exit_2_naming_the_prim_and_leave_nothing() {
    let s = Scratch::new("usd-bad");
    let bad = s.file(
        "bad.usda",
        b"#usda 1.0\ndef Mesh \"M\"\n{\n int[] faceVertexCounts = [4]\n int[] faceVertexIndices = [0, 1, 2, 3]\n point3f[] points = [(0,0,0), (1,0,0), (1,1,0), (0,1,0)]\n int[] creaseIndices = [0, 1]\n int[] creaseLengths = [2]\n float[] creaseSharpnesses = [1, 2]\n}\n",
    );
    let out = s.0.join("out.usdc");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "catmull-clark",
        "--levels",
        "1",
        path(&bad),
        path(&out),
    ]);
    assert_eq!(code, 2);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("bad.usda: prim /M attribute creaseSharpnesses: has 2 values"),
        "{err}"
    );
    assert!(!out.exists());
    let cut = s.file(
        "cut.usdc",
        &std::fs::read(stage("meshes.usdc")).unwrap()[..900],
    );
    let (code, _, err) = subd(&["info", path(&cut)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("cut.usdc: cannot open as USD"), "{err}");
}
