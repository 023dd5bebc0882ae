//! glTF input: seams welded into one closed topology, node transforms, strips, bad files.

use base64::Engine;
use subd_io::{Format, ReadOptions, parse_mesh};
use subd_mesh::DVec3;

/// A unit cube as an exporter writes it: 24 vertices (each face its own four, split at the
/// UV and normal seams), with TEXCOORD_0, as a `.gltf` document with a data-URI buffer.
/// `node` is the JSON of the node(s) that place the mesh; the copies of the corners on
/// odd faces are moved by `jitter` along x.
fn split_cube_gltf_jittered(node: &str, jitter: f32) -> String {
    let corners = [
        [0.0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
        [0.0, 1.0, 1.0],
    ];
    // Counter-clockwise seen from outside.
    let faces = [
        [0, 3, 2, 1],
        [4, 5, 6, 7],
        [0, 1, 5, 4],
        [1, 2, 6, 5],
        [2, 3, 7, 6],
        [3, 0, 4, 7],
    ];
    let mut bytes = Vec::new();
    for (i, f) in faces.iter().enumerate() {
        for &c in f {
            let mut p = corners[c];
            if i % 2 == 1 {
                p[0] += jitter;
            }
            for x in p {
                bytes.extend(x.to_le_bytes());
            }
        }
    }
    for _ in &faces {
        for uv in [[0.0f32, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]] {
            for x in uv {
                bytes.extend(x.to_le_bytes());
            }
        }
    }
    let index_offset = bytes.len();
    for f in 0..6u16 {
        for i in [0, 1, 2, 0, 2, 3] {
            bytes.extend((4 * f + i).to_le_bytes());
        }
    }
    let data = base64::engine::general_purpose::STANDARD.encode(&bytes);
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0]}}],
  "nodes": [{node}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}, "indices": 2}}]}}],
  "buffers": [{{"byteLength": {len}, "uri": "data:application/octet-stream;base64,{data}"}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 288}},
    {{"buffer": 0, "byteOffset": 288, "byteLength": 192}},
    {{"buffer": 0, "byteOffset": {index_offset}, "byteLength": 72}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 24, "type": "VEC3", "min": [0,0,0], "max": [1,1,1]}},
    {{"bufferView": 1, "componentType": 5126, "count": 24, "type": "VEC2"}},
    {{"bufferView": 2, "componentType": 5123, "count": 36, "type": "SCALAR"}}
  ]
}}"#,
        len = bytes.len()
    )
}

fn split_cube_gltf(node: &str) -> String {
    split_cube_gltf_jittered(node, 0.0)
}

fn read(text: &str, options: &ReadOptions) -> Result<subd_io::MeshFile, subd_io::ReadError> {
    parse_mesh(text.as_bytes(), Format::Gltf, options)
}

/// Six times the enclosed volume, positive for outward-facing triangles.
fn signed_volume6(file: &subd_io::MeshFile) -> f64 {
    let topo = &file.mesh.topology;
    let p = &file.mesh.positions;
    (0..topo.num_faces())
        .map(|f| {
            let v = topo.face_vertices(f);
            let [a, b, c] = [0, 1, 2].map(|i| p[v[i] as usize]);
            a.dot(b.cross(c))
        })
        .sum()
}

#[test]
fn split_seams_weld_into_a_closed_cube_placed_by_its_node() {
    let node = r#"{"mesh": 0, "translation": [10, 0, 0], "scale": [2, 2, 2]}"#;
    let file = read(&split_cube_gltf(node), &ReadOptions::default()).unwrap();
    let topo = &file.mesh.topology;
    assert_eq!(
        topo.num_vertices(),
        8,
        "24 split vertices weld to the cube's 8"
    );
    assert_eq!(topo.num_faces(), 12);
    assert_eq!(topo.num_edges(), 18);
    assert!(
        (0..topo.num_edges()).all(|e| topo.edge_faces(e).len() == 2),
        "closed and manifold"
    );
    for p in &file.mesh.positions {
        assert!([10.0, 12.0].contains(&p.x) && [0.0, 2.0].contains(&p.y));
    }
    assert!((signed_volume6(&file) - 6.0 * 8.0).abs() < 1e-12);
    let warnings = file.warnings.join("\n");
    assert!(
        warnings.contains("24 glTF vertices welded by position into 8"),
        "{warnings}"
    );
    // TEXCOORD_0 comes along: each cube face is its own UV island (the unit square), so
    // the 12 cube edges are seams, the 6 face diagonals are not, and every corner has 3
    // values, one per face; v is flipped back from glTF's top-left origin.
    let uv = file.mesh.uv().expect("TEXCOORD_0 read");
    assert_eq!(uv.num_values(), 24);
    let seams = subd_mesh::fvar::FVarSeams::of(topo, uv);
    assert_eq!(seams.num_seam_edges(), 12);
    assert!((0..8).all(|v| seams.siblings(v) == 3));
    let mut corners: Vec<[u32; 2]> = uv
        .indices()
        .iter()
        .map(|&i| {
            let c = uv.value(i as usize);
            [c[0] as u32, c[1] as u32]
        })
        .collect();
    corners.sort();
    corners.dedup();
    assert_eq!(corners, [[0, 0], [0, 1], [1, 0], [1, 1]]);
    // glTF vertex 0 has (0, 0): (0, 1) with v flipped.
    assert_eq!(uv.value(0), [0.0, 1.0]);
}

#[test]
fn no_transform_reads_the_mesh_as_stored() {
    let node = r#"{"mesh": 0, "translation": [10, 0, 0]}"#;
    let options = ReadOptions {
        ignore_transforms: true,
        ..Default::default()
    };
    let file = read(&split_cube_gltf(node), &options).unwrap();
    let max = file
        .mesh
        .positions
        .iter()
        .fold(DVec3::splat(f64::MIN), |m, p| m.max(*p));
    assert_eq!(max, DVec3::ONE);
}

#[test]
fn a_mirroring_node_keeps_the_triangles_facing_out() {
    let node = r#"{"mesh": 0, "scale": [-1, 1, 1]}"#;
    let file = read(&split_cube_gltf(node), &ReadOptions::default()).unwrap();
    assert!((signed_volume6(&file) - 6.0).abs() < 1e-12);
}

#[test]
fn a_node_hierarchy_composes_parent_and_child_transforms() {
    let doc = split_cube_gltf(
        r#"{"children": [1], "translation": [0, 5, 0]}, {"mesh": 0, "scale": [3, 3, 3]}"#,
    );
    let file = read(&doc, &ReadOptions::default()).unwrap();
    let min = file
        .mesh
        .positions
        .iter()
        .fold(DVec3::splat(f64::MAX), |m, p| m.min(*p));
    let max = file
        .mesh
        .positions
        .iter()
        .fold(DVec3::splat(f64::MIN), |m, p| m.max(*p));
    assert_eq!(
        (min, max),
        (DVec3::new(0.0, 5.0, 0.0), DVec3::new(3.0, 8.0, 3.0))
    );
}

#[test]
fn a_tolerance_welds_vertices_that_differ_by_rounding() {
    // Every corner has copies on odd and on even faces; moving the odd ones by 1e-5 leaves
    // 16 distinct positions, which a tolerance of 1e-4 welds back to 8.
    let doc = split_cube_gltf_jittered(r#"{"mesh": 0}"#, 1e-5);
    let exact = read(&doc, &ReadOptions::default());
    let exact_vertices = exact.map(|f| f.mesh.topology.num_vertices());
    assert_ne!(
        exact_vertices,
        Ok(8),
        "without a tolerance the jittered copies stay apart"
    );
    let opts = ReadOptions {
        weld_tolerance: Some(1e-4),
        ..Default::default()
    };
    let loose = read(&doc, &opts).unwrap();
    let topo = &loose.mesh.topology;
    assert_eq!(topo.num_vertices(), 8);
    assert!((0..topo.num_edges()).all(|e| topo.edge_faces(e).len() == 2));
    // Each welded vertex keeps its first copy's position (face 0 is even: unmoved).
    assert!(loose.mesh.positions.contains(&DVec3::ZERO));
}

#[test]
fn malformed_documents_are_errors_not_panics() {
    let good = split_cube_gltf(r#"{"mesh": 0}"#);
    let cases = [
        // An accessor reaching past its buffer view.
        good.replace(
            r#""count": 24, "type": "VEC3""#,
            r#""count": 25, "type": "VEC3""#,
        ),
        // An index past the vertices.
        good.replace(
            r#""count": 24, "type": "VEC3""#,
            r#""count": 20, "type": "VEC3""#,
        ),
        // POSITION of the wrong type.
        good.replace(
            r#""count": 24, "type": "VEC3""#,
            r#""count": 24, "type": "VEC2""#,
        ),
        // A buffer shorter than declared.
        good.replace(r#""byteLength": 552"#, r#""byteLength": 900"#),
        // No triangles at all.
        good.replace(r#""indices": 2}"#, r#""indices": 2, "mode": 1}"#),
        // Not glTF.
        "{\"asset\": 3}".to_string(),
    ];
    for (i, doc) in cases.iter().enumerate() {
        assert_ne!(doc, &good, "case {i} must change the document");
        let e = read(doc, &ReadOptions::default());
        assert!(e.is_err(), "case {i} was accepted");
    }
}

/// GLB containers with forged header and chunk lengths (found by the `gltf` fuzz target:
/// a declared length under the header's own 12 bytes overflowed inside `gltf`) are errors.
#[test]
fn forged_glb_lengths_are_errors_not_panics() {
    let json = br#"{"asset":{"version":"2.0"}}"#;
    let glb = |declared: u32, chunk: u32| {
        let mut b = b"glTF".to_vec();
        b.extend_from_slice(&2u32.to_le_bytes());
        b.extend_from_slice(&declared.to_le_bytes());
        b.extend_from_slice(&chunk.to_le_bytes());
        b.extend_from_slice(b"JSON");
        b.extend_from_slice(json);
        b
    };
    let honest = (12 + 8 + json.len()) as u32;
    for (declared, chunk) in [
        (0, json.len() as u32),
        (11, json.len() as u32),
        (honest + 100, json.len() as u32),
        (honest, u32::MAX),
        (honest, 3),
    ] {
        let r = parse_mesh(&glb(declared, chunk), Format::Glb, &ReadOptions::default());
        assert!(r.is_err(), "declared {declared}, chunk {chunk}");
    }
    let e = parse_mesh(&glb(5, 27), Format::Glb, &ReadOptions::default()).unwrap_err();
    assert!(e.to_string().contains("declares 5 bytes"), "{e}");
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(400))]

    /// Any number of the document's JSON (counts, offsets, lengths, strides, indices,
    /// component types, modes) set to an arbitrary value gives a mesh or an error, never a
    /// panic; a mesh that comes back is closed or has a valid topology.
    #[test]
    fn forged_numbers_never_panic(picks in proptest::collection::vec((0usize..64, 0u32..70000), 1..4)) {
        let doc = split_cube_gltf(r#"{"mesh": 0}"#);
        let header_end = doc.find("\"data:").unwrap();
        let (json, tail) = doc.split_at(header_end);
        let mut json = json.to_string();
        for (which, value) in picks {
            let numbers: Vec<(usize, usize)> = number_spans(&json);
            let (start, end) = numbers[which % numbers.len()];
            json.replace_range(start..end, &value.to_string());
        }
        let bytes = format!("{json}{tail}");
        if let Ok(file) = parse_mesh(bytes.as_bytes(), Format::Gltf, &ReadOptions::default()) {
            proptest::prop_assert!(file.mesh.topology.num_faces() > 0);
            proptest::prop_assert_eq!(file.mesh.positions.len(), file.mesh.topology.num_vertices());
        }
    }
}

/// Byte ranges of the unsigned integers in `text` (outside strings is not checked: the
/// document's only string with digits is after the cut).
fn number_spans(text: &str) -> Vec<(usize, usize)> {
    let bytes = text.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i].is_ascii_digit() && (i == 0 || !bytes[i - 1].is_ascii_alphanumeric()) {
            let start = i;
            while i < bytes.len() && bytes[i].is_ascii_digit() {
                i += 1;
            }
            spans.push((start, i));
        } else {
            i += 1;
        }
    }
    spans
}

#[test]
fn a_gltf_with_an_external_buffer_reads_it_beside_the_document() {
    let doc = split_cube_gltf(r#"{"mesh": 0}"#);
    // Move the data-URI buffer into a file named with a space (percent-encoded in the URI).
    let start = doc.find("data:application/octet-stream;base64,").unwrap();
    let end = start + doc[start..].find('"').unwrap();
    let payload = &doc[start + "data:application/octet-stream;base64,".len()..end];
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(payload)
        .unwrap();
    let dir = std::env::temp_dir().join(format!("subd-gltf-ext-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("cube data.bin"), &bytes).unwrap();
    let external = format!("{}cube%20data.bin{}", &doc[..start], &doc[end..]);
    let path = dir.join("cube.gltf");
    std::fs::write(&path, &external).unwrap();
    let file = subd_io::read_mesh(&path, &ReadOptions::default()).unwrap();
    assert_eq!(file.mesh.topology.num_vertices(), 8);
    // Without the directory (bytes only) the external file cannot be found: a typed error.
    let e = parse_mesh(external.as_bytes(), Format::Gltf, &ReadOptions::default()).unwrap_err();
    assert!(
        e.to_string().contains("needs the document's directory"),
        "{e}"
    );
    // A missing file names it.
    std::fs::remove_file(dir.join("cube data.bin")).unwrap();
    let e = subd_io::read_mesh(&path, &ReadOptions::default()).unwrap_err();
    assert!(e.to_string().contains("cube data.bin"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A unit cube whose six faces are UV islands of their own (the unit square), as an OBJ
/// with `vt` lines: all twelve edges are UV seams.
const SEAMED_CUBE_OBJ: &str = "\
v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
f 1/1 4/2 3/3 2/4\nf 5/1 6/2 7/3 8/4\nf 1/1 2/2 6/3 5/4\n\
f 2/1 3/2 7/3 6/4\nf 3/1 4/2 8/3 7/4\nf 4/1 1/2 5/3 8/4\n";

/// `obj` read, written as `.glb` by subd, and read back.
fn through_glb(obj: &str) -> subd_io::MeshFile {
    use subd_io::{WriteOptions, encode_mesh};
    let file = parse_mesh(obj.as_bytes(), Format::Obj, &ReadOptions::default()).unwrap();
    let mut glb = Vec::new();
    encode_mesh(&mut glb, &file.mesh, Format::Glb, &WriteOptions::default()).unwrap();
    parse_mesh(&glb, Format::Glb, &ReadOptions::default()).unwrap()
}

#[test]
fn subds_own_seam_split_glb_welds_back_without_a_warning() {
    let back = through_glb(SEAMED_CUBE_OBJ);
    assert!(back.warnings.is_empty(), "{:?}", back.warnings);
    // The writer split the 8 corners at the seams; welding restored them, seams kept.
    let topo = &back.mesh.topology;
    assert_eq!((topo.num_vertices(), topo.num_faces()), (8, 12));
    assert!((0..topo.num_edges()).all(|e| topo.edge_faces(e).len() == 2));
    let uv = back.mesh.uv().expect("TEXCOORD_0 read back");
    let seams = subd_mesh::fvar::FVarSeams::of(topo, uv);
    assert_eq!(seams.num_seam_edges(), 12);
}

#[test]
fn welding_coincident_distinct_vertices_still_warns() {
    // An L of unit squares: the first flat, the second and third standing on its edge
    // x = 1. The second has its own copies (vertices 7 and 8) of the corners it shares
    // with the first, whose normals differ from theirs (an edge, not a seam), which the
    // writer keeps as distinct glTF vertices. The third shares vertices 5 and 6 with the
    // second but maps them elsewhere: a real UV seam, split by the writer.
    let obj = "\
v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 1 0 1\nv 1 1 1\nv 1 0 0\nv 1 1 0\nv 1 0 2\nv 1 1 2\n\
vt 0 0\nvt 0.5 0\nvt 0.5 1\nvt 0 1\nvt 1 0\nvt 1 1\n\
f 1/1 2/2 3/3 4/4\nf 8/3 7/2 5/5 6/6\nf 6/4 5/1 9/2 10/3\n";
    let back = through_glb(obj);
    // 12 glTF vertices (the 10 and the seam copies of 5 and 6) weld into 8; of the four
    // merges only the two along the fold joined distinct vertices (six triangles, 13 edges).
    let topo = &back.mesh.topology;
    assert_eq!((topo.num_vertices(), topo.num_edges()), (8, 13));
    assert_eq!(
        back.warnings,
        [
            "12 glTF vertices welded by position into 8, 2 of them into a vertex they were \
          distinct from (another normal, or none to tell)"
        ]
    );
}
