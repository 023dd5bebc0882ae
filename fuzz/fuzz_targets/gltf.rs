//! Fuzzes the glTF reader (`.glb` and `.gltf` bytes): any input gives a mesh or a typed
//! error, never a panic; a mesh read survives a round trip through OBJ unchanged.
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
    }
});
