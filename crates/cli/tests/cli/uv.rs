//! Texture coordinates through refine, limit, PIA, adaptive and the split schemes.

use super::*;

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
