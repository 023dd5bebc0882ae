//! Fuzzes the PLY reader (ASCII and binary): any bytes must give a mesh or a typed error,
//! never a panic or an allocation driven by a forged header count.
#![no_main]

use libfuzzer_sys::fuzz_target;
use subd_io::{Format, PlyEncoding, ReadOptions, WriteOptions, encode_mesh, parse_mesh};

fuzz_target!(|data: &[u8]| {
    let opts = ReadOptions {
        accept_inconsistent_orientation: true,
        ..Default::default()
    };
    if let Ok(file) = parse_mesh(data, Format::Ply, &opts) {
        for encoding in [PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian] {
            let mut out = Vec::new();
            let w = WriteOptions {
                ply_encoding: encoding,
                ..Default::default()
            };
            encode_mesh(&mut out, &file.mesh, Format::Ply, &w).unwrap();
            let again = parse_mesh(&out, Format::Ply, &opts).expect("written PLY must read back");
            assert_eq!(
                again.mesh.topology.all_face_vertices(),
                file.mesh.topology.all_face_vertices()
            );
            assert_eq!(again.mesh.positions, file.mesh.positions);
        }
    }
});
