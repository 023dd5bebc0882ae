//! Fuzzes the glTF reader (`.glb` and `.gltf` bytes): any input gives a mesh or a typed
//! error, never a panic; a mesh read survives a round trip through OBJ unchanged, its
//! texture coordinates included.
#![no_main]

use libfuzzer_sys::fuzz_target;
use subd_io::{Format, ReadOptions, WriteOptions, encode_mesh, parse_mesh};

fuzz_target!(|data: &[u8]| {
    let opts = ReadOptions {
        accept_inconsistent_orientation: true,
        ..Default::default()
    };
    if let Ok(file) = parse_mesh(data, Format::Glb, &opts) {
        let mut obj = Vec::new();
        encode_mesh(&mut obj, &file.mesh, Format::Obj, &WriteOptions::default()).unwrap();
        let again = parse_mesh(&obj, Format::Obj, &opts).expect("written OBJ must read back");
        assert_eq!(
            again.mesh.topology.all_face_vertices(),
            file.mesh.topology.all_face_vertices()
        );
        assert_eq!(again.mesh.positions, file.mesh.positions);
        // Texture coordinates (TEXCOORD_0, welded at seams) survive it too.
        assert_eq!(corner_uvs(&again.mesh), corner_uvs(&file.mesh));
    }
});

/// The texture coordinate of every face corner, if the mesh has any.
fn corner_uvs(mesh: &subd_mesh::Mesh) -> Option<Vec<Vec<f64>>> {
    mesh.uv().map(|c| {
        c.indices()
            .iter()
            .map(|&i| c.value(i as usize).to_vec())
            .collect()
    })
}
