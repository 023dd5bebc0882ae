//! Every OpenSubdiv regression shape: subd's topology against OpenSubdiv's own counts
//! (`INDEX.md`, produced by OpenSubdiv 3.5), and the file formats round-tripped.

use std::collections::BTreeMap;

use subd_io::{Format, PlyEncoding, ReadOptions, WriteOptions, encode_mesh, parse_mesh, read_mesh};
use subd_mesh::analysis::count_irregular;
use subd_mesh::{Mesh, TopologySummary};
use subd_tests::{index_rows, osd_mesh_dir, osd_meshes};

fn accept() -> ReadOptions {
    ReadOptions {
        accept_inconsistent_orientation: true,
        ..Default::default()
    }
}

#[test]
fn topology_matches_opensubdiv_counts() {
    let rows = index_rows();
    assert!(rows.len() >= 120, "INDEX.md rows: {}", rows.len());
    assert_eq!(rows.len(), osd_meshes().len());
    for row in &rows {
        let path = osd_mesh_dir().join(format!("{}.obj", row.shape));
        let file = read_mesh(&path, &accept()).unwrap_or_else(|e| panic!("{e}"));
        let t = &file.mesh.topology;
        let s = TopologySummary::new(t);
        let regular = if row.scheme == "loop" { 6 } else { 4 };
        let sizes: Vec<(usize, usize)> = s.face_sizes.iter().map(|(&k, &v)| (k, v)).collect();
        let got = (
            s.faces,
            s.vertices,
            s.edges,
            sizes,
            s.boundary_edges,
            s.nonmanifold_edges,
            s.nonmanifold_vertices,
            count_irregular(t, regular),
        );
        let want = (
            row.faces,
            row.vertices,
            row.edges,
            row.face_sizes.clone(),
            row.boundary_edges,
            row.nonmanifold_edges,
            row.nonmanifold_vertices,
            row.irregular,
        );
        assert_eq!(got, want, "{}", row.shape);
        // INDEX.md counts crease tag lines; a shape may tag the same edge twice
        // (catmark_inf_crease0 does), which sets one edge.
        let text = std::fs::read_to_string(&path).unwrap();
        // It also counts a tag of sharpness 0 (loop_cubes_infsharp has one), which sets nothing.
        let crease_lines: Vec<(u32, u32, f64)> = text
            .lines()
            .filter(|l| l.starts_with("t crease 2/1/0"))
            .map(|l| {
                let w: Vec<&str> = l.split_whitespace().skip(3).collect();
                let (a, b): (u32, u32) = (w[0].parse().unwrap(), w[1].parse().unwrap());
                (a.min(b), a.max(b), w[2].parse().unwrap())
            })
            .collect();
        let distinct: std::collections::BTreeSet<_> = crease_lines
            .iter()
            .filter(|c| c.2 > 0.0)
            .map(|c| (c.0, c.1))
            .collect();
        assert_eq!(
            crease_lines.len(),
            row.semi_sharp + row.inf_sharp,
            "{}",
            row.shape
        );
        assert_eq!(
            s.semi_sharp_creases + s.infinite_creases,
            distinct.len(),
            "creases of {}",
            row.shape
        );
        if distinct.len() == crease_lines.len() {
            assert_eq!(
                (s.semi_sharp_creases, s.infinite_creases),
                (row.semi_sharp, row.inf_sharp),
                "{}",
                row.shape
            );
        }
        assert_eq!(
            (s.corners, s.holes),
            (row.corners, row.holes),
            "tags of {}",
            row.shape
        );
        let rule = match file.mesh.hints.boundary_interpolation {
            None | Some(subd_mesh::BoundaryInterpolation::EdgeOnly) => "edge-only",
            Some(subd_mesh::BoundaryInterpolation::EdgeAndCorner) => "edge-and-corner",
            Some(subd_mesh::BoundaryInterpolation::None) => "none",
        };
        assert_eq!(rule, row.boundary_rule, "boundary rule of {}", row.shape);
    }
}

#[test]
fn closed_shapes_have_the_right_genus() {
    let expect = [
        ("catmark_cube", 0),
        ("catmark_torus", 1),
        ("catmark_pyramid", 0),
        ("loop_tetrahedron", 0),
        ("loop_icosahedron", 0),
        ("loop_cube", 0),
        ("bilinear_cube", 0),
    ];
    for (name, genus) in expect {
        let file = read_mesh(&osd_mesh_dir().join(format!("{name}.obj")), &accept()).unwrap();
        let s = TopologySummary::new(&file.mesh.topology);
        assert_eq!(s.genus, Some(genus), "{name}");
        assert_eq!(s.euler, 2 - 2 * genus, "{name}");
    }
}

/// Our OBJ reader against `tobj` (an independent parser): same polygons, same positions.
/// `tobj` renumbers vertices by first use per group, so compare through positions.
#[test]
fn obj_reader_agrees_with_tobj() {
    for path in osd_meshes() {
        let ours = read_mesh(&path, &accept()).unwrap();
        let opts = tobj::LoadOptions {
            triangulate: false,
            single_index: false,
            ignore_points: true,
            ignore_lines: true,
        };
        let (models, _) =
            tobj::load_obj(&path, &opts).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let t = &ours.mesh.topology;
        let mut f = 0usize;
        for m in &models {
            let mesh = &m.mesh;
            let arities: Vec<u32> = if mesh.face_arities.is_empty() {
                vec![3; mesh.indices.len() / 3]
            } else {
                mesh.face_arities.clone()
            };
            let mut k = 0usize;
            for n in arities {
                assert_eq!(t.face_size(f), n as usize, "{} face {f}", path.display());
                for (c, &v) in t.face_vertices(f).iter().enumerate() {
                    let ti = mesh.indices[k + c] as usize;
                    let tp = [
                        mesh.positions[3 * ti],
                        mesh.positions[3 * ti + 1],
                        mesh.positions[3 * ti + 2],
                    ];
                    assert_eq!(
                        ours.mesh.positions[v as usize].to_array(),
                        tp,
                        "{} face {f}",
                        path.display()
                    );
                }
                // Texture coordinates corner by corner, through tobj's own vt indices.
                if let Some(uv) = ours.mesh.uv() {
                    for (c, &x) in uv.face_values(t, f).iter().enumerate() {
                        let ti = mesh.texcoord_indices[k + c] as usize;
                        let theirs = [mesh.texcoords[2 * ti], mesh.texcoords[2 * ti + 1]];
                        assert_eq!(uv.value(x as usize), theirs, "{} face {f}", path.display());
                    }
                } else {
                    assert!(mesh.texcoord_indices.is_empty(), "{}", path.display());
                }
                k += n as usize;
                f += 1;
            }
        }
        assert_eq!(f, t.num_faces(), "{}", path.display());
    }
}

/// Creases (edge → sharpness bits), corners (vertex, sharpness bits), holes.
type TagSnapshot = (BTreeMap<[u32; 2], u32>, Vec<(usize, u32)>, Vec<usize>);

fn tag_map(m: &Mesh) -> TagSnapshot {
    let t = &m.topology;
    let creases = (0..t.num_edges())
        .filter(|&e| t.edge_sharpness(e) > 0.0)
        .map(|e| (t.edge_vertices(e), t.edge_sharpness(e).to_bits()))
        .collect();
    let corners = (0..t.num_vertices())
        .filter(|&v| t.vertex_sharpness(v) > 0.0)
        .map(|v| (v, t.vertex_sharpness(v).to_bits()))
        .collect();
    let holes = (0..t.num_faces()).filter(|&f| t.is_hole(f)).collect();
    (creases, corners, holes)
}

fn assert_same_mesh(a: &Mesh, b: &Mesh, what: &str) {
    assert_eq!(
        a.topology.face_offsets(),
        b.topology.face_offsets(),
        "{what}"
    );
    assert_eq!(
        a.topology.all_face_vertices(),
        b.topology.all_face_vertices(),
        "{what}"
    );
    assert_eq!(
        a.topology.num_vertices(),
        b.topology.num_vertices(),
        "{what}"
    );
    // Bit-exact positions: the writers use shortest round-trip formatting or raw f64.
    let bits = |m: &Mesh| {
        m.positions
            .iter()
            .map(|p| p.to_array().map(f64::to_bits))
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(a), bits(b), "{what}");
    assert_eq!(tag_map(a), tag_map(b), "tags, {what}");
    assert_eq!(a.hints, b.hints, "hints, {what}");
    assert_same_uv(a, b, what);
}

/// The same texture coordinate at every corner, bit for bit.
fn assert_same_uv(a: &Mesh, b: &Mesh, what: &str) {
    let corners = |m: &Mesh| {
        m.uv().map(|uv| {
            uv.indices()
                .iter()
                .map(|&i| {
                    uv.value(i as usize)
                        .iter()
                        .map(|x| x.to_bits())
                        .collect::<Vec<_>>()
                })
                .collect::<Vec<_>>()
        })
    };
    assert_eq!(corners(a), corners(b), "texture coordinates, {what}");
}

#[test]
fn obj_and_ply_round_trip_every_shape() {
    for path in osd_meshes() {
        let file = read_mesh(&path, &accept()).unwrap();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        // OBJ, with the uninterpreted tags passed through.
        let w = WriteOptions {
            extra_obj_tags: file.extra_tags.clone(),
            ..Default::default()
        };
        let mut buf = Vec::new();
        encode_mesh(&mut buf, &file.mesh, Format::Obj, &w).unwrap();
        let back = parse_mesh(&buf, Format::Obj, &accept()).unwrap();
        assert_same_mesh(&file.mesh, &back.mesh, &format!("{name} via OBJ"));
        assert_eq!(file.extra_tags, back.extra_tags, "{name}");
        // PLY holds one texture coordinate per vertex: a layout with seams is refused, and
        // the mesh goes without it.
        let seams = file.mesh.uv().is_some_and(|uv| {
            subd_mesh::fvar::FVarSeams::of(&file.mesh.topology, uv).num_seam_vertices() > 0
        });
        let mut plain = file.mesh.clone();
        if seams {
            let mut buf = Vec::new();
            let e = encode_mesh(&mut buf, &file.mesh, Format::Ply, &WriteOptions::default())
                .unwrap_err();
            assert!(e.to_string().contains("UV seam"), "{name}: {e}");
            plain.fvar.clear();
        }
        for enc in [PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian] {
            let w = WriteOptions {
                ply_encoding: enc,
                ..Default::default()
            };
            let mut buf = Vec::new();
            encode_mesh(&mut buf, &plain, Format::Ply, &w).unwrap();
            let back = parse_mesh(&buf, Format::Ply, &accept()).unwrap();
            assert_same_mesh(&plain, &back.mesh, &format!("{name} via PLY {enc:?}"));
        }
    }
}

/// The `.glb` output read back with the `gltf` crate: a valid document whose triangles are
/// the fan triangulation of the non-hole faces, with unit normals.
#[test]
fn glb_output_reads_back_with_gltf() {
    for path in osd_meshes() {
        let file = read_mesh(&path, &accept()).unwrap();
        let mut buf = Vec::new();
        encode_mesh(&mut buf, &file.mesh, Format::Glb, &WriteOptions::default()).unwrap();
        let gltf =
            gltf::Gltf::from_slice(&buf).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let blob = gltf.blob.as_deref().expect("GLB has a BIN chunk");
        let mesh = gltf.meshes().next().expect("one mesh");
        let prim = mesh.primitives().next().expect("one primitive");
        let reader = prim.reader(|_| Some(blob));
        let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
        let normals: Vec<[f32; 3]> = reader.read_normals().unwrap().collect();
        let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
        let t = &file.mesh.topology;
        for n in &normals {
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            assert!(
                (len - 1.0).abs() < 1e-5,
                "{}: normal length {len}",
                path.display()
            );
        }
        // Fan triangles of the non-hole faces, as (vertex, face-vertex) corners.
        let corners: Vec<(u32, usize)> = (0..t.num_faces())
            .filter(|&f| !t.is_hole(f))
            .flat_map(|f| {
                let fv = t.face_vertices(f);
                let o = t.face_offsets()[f] as usize;
                (1..fv.len() - 1)
                    .flat_map(move |i| [(fv[0], o), (fv[i], o + i), (fv[i + 1], o + i + 1)])
            })
            .collect();
        assert_eq!(indices.len(), corners.len(), "{}", path.display());
        let f32s = |q: subd_mesh::DVec3| [q.x as f32, q.y as f32, q.z as f32];
        match file.mesh.uv() {
            None => {
                assert!(reader.read_tex_coords(0).is_none());
                assert_eq!(positions.len(), t.num_vertices());
                for (p, q) in positions.iter().zip(&file.mesh.positions) {
                    assert_eq!(*p, f32s(*q));
                }
                let expected: Vec<u32> = corners.iter().map(|c| c.0).collect();
                assert_eq!(indices, expected, "{}", path.display());
            }
            Some(uv) => {
                // One glTF vertex per (vertex, texture coordinate) pair the corners use, each
                // with its vertex's position and its value, v flipped.
                let tex: Vec<[f32; 2]> = reader.read_tex_coords(0).unwrap().into_f32().collect();
                let pairs: std::collections::BTreeSet<(u32, u32)> = (0..t.num_faces())
                    .flat_map(|f| {
                        t.face_vertices(f)
                            .iter()
                            .copied()
                            .zip(uv.face_values(t, f).iter().copied())
                    })
                    .collect();
                assert_eq!(positions.len(), pairs.len(), "{}", path.display());
                assert_eq!(tex.len(), pairs.len());
                for (&i, &(v, k)) in indices.iter().zip(&corners) {
                    let i = i as usize;
                    assert_eq!(positions[i], f32s(file.mesh.positions[v as usize]));
                    let value = uv.value(uv.indices()[k] as usize);
                    assert_eq!(
                        tex[i],
                        [value[0] as f32, (1.0 - value[1]) as f32],
                        "{}",
                        path.display()
                    );
                }
            }
        }
    }
}

#[test]
fn write_mesh_is_atomic_and_chooses_format_by_extension() {
    let dir = tempfile_dir();
    let mut file = read_mesh(&osd_mesh_dir().join("catmark_cube.obj"), &accept()).unwrap();
    // The cube's UV layout has seams, which PLY cannot hold (tested with the round trips).
    file.mesh.fvar.clear();
    for ext in ["obj", "ply", "glb"] {
        let out = dir.join(format!("cube.{ext}"));
        subd_io::write_mesh(&out, &file.mesh, &WriteOptions::default()).unwrap();
        let bytes = std::fs::read(&out).unwrap();
        let magic: &[u8] = match ext {
            "obj" => b"# written by subd",
            "ply" => b"ply\n",
            _ => b"glTF",
        };
        assert!(bytes.starts_with(magic), "{ext}");
    }
    let bad = dir.join("cube.stl");
    assert!(matches!(
        subd_io::write_mesh(&bad, &file.mesh, &WriteOptions::default()),
        Err(subd_io::IoError::UnknownFormat { .. })
    ));
    // A writer that fails midway leaves neither the target nor a temporary file.
    let target = dir.join("partial.obj");
    let r = subd_io::atomic_write(&target, |w| {
        w.write_all(b"v 0 0 0\n")?;
        Err(std::io::Error::other("simulated failure"))
    });
    assert!(r.is_err());
    assert!(!target.exists());
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

fn tempfile_dir() -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("subd-test-{}-{}", std::process::id(), line!()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Re-assembling a topology from its own numbered edges gives the same topology: the two
/// construction paths (search-free for refinement, first-appearance for files) agree.
#[test]
fn numbered_edge_assembly_matches_builder() {
    for path in osd_meshes() {
        let t = read_mesh(&path, &accept()).unwrap().mesh.topology;
        let nm: Vec<u32> = (0..t.num_edges() as u32)
            .filter(|&e| t.is_non_manifold_edge(e as usize))
            .collect();
        let faces = (0..t.num_faces())
            .flat_map(|f| t.face_edges(f).to_vec())
            .collect();
        let edges = (0..t.num_edges()).map(|e| t.edge_vertices(e)).collect();
        let mut again = subd_mesh::Topology::from_numbered_edges(
            t.num_vertices(),
            t.face_offsets().to_vec(),
            t.all_face_vertices().to_vec(),
            faces,
            edges,
            &nm,
        )
        .unwrap();
        for e in 0..t.num_edges() {
            again.set_edge_sharpness(e, t.edge_sharpness(e));
        }
        for v in 0..t.num_vertices() {
            again.set_vertex_sharpness(v, t.vertex_sharpness(v));
        }
        for f in 0..t.num_faces() {
            again.set_hole(f, t.is_hole(f));
        }
        assert!(again == t, "{}", path.display());
    }
}
