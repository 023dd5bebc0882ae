//! Fuzzes the PLY reader (ASCII and binary): any bytes must give a mesh or a typed error,
//! never a panic or an allocation driven by a forged header count; the fast binary decoders,
//! with vertices in parallel tasks of one to a few vertices, must give the per-value
//! reader's mesh or its error.
#![no_main]

use libfuzzer_sys::fuzz_target;
use subd_io::fuzzing::{parse_ply_in_tasks, parse_ply_serially};
use subd_io::{
    Format, MeshFile, PlyEncoding, ReadError, ReadOptions, WriteOptions, encode_mesh, parse_mesh,
};

fuzz_target!(|data: &[u8]| {
    let opts = ReadOptions {
        accept_inconsistent_orientation: true,
        ..Default::default()
    };
    let serial = parse_ply_serially(data, &opts);
    for vertices_per_task in [1, 3] {
        same_result(&parse_ply_in_tasks(data, &opts, vertices_per_task), &serial);
    }
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

/// The fast decoders' result must be the per-value reader's: the same mesh, levels and
/// warnings, or an error (the fast decoders hand anything unusual to the per-value reader,
/// so the error is that reader's own).
fn same_result(fast: &Result<MeshFile, ReadError>, serial: &Result<MeshFile, ReadError>) {
    match (fast, serial) {
        (Ok(f), Ok(s)) => {
            assert_eq!(f.mesh, s.mesh);
            assert_eq!(f.face_levels, s.face_levels);
            assert_eq!(f.warnings, s.warnings);
        }
        (Err(f), Err(s)) => assert_eq!(f.to_string(), s.to_string()),
        (f, s) => panic!("fast {:?} but per-value {:?}", f.as_ref().err(), s.as_ref().err()),
    }
}
