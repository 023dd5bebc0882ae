//! Fuzzes the OBJ reader and the topology builder behind it: any bytes must give a mesh or a
//! typed error, never a panic; the parallel reader, cut into chunks of a few bytes so that
//! an input spans many, must give the serial reader's mesh or its error; a mesh that comes
//! back must be internally consistent and survive a write/read round trip.
#![no_main]

use libfuzzer_sys::fuzz_target;
use subd_io::fuzzing::{parse_obj_in_chunks, parse_obj_serially};
use subd_io::{Format, MeshFile, ReadError, ReadOptions, WriteOptions, encode_mesh, parse_mesh};

fuzz_target!(|data: &[u8]| {
    for accept in [false, true] {
        let opts = ReadOptions {
            accept_inconsistent_orientation: accept,
            ..Default::default()
        };
        let serial = parse_obj_serially(data, &opts);
        // Chunk sizes from a line's length down to one byte (every cut a line end allows).
        for chunk_bytes in [1, 7, 64] {
            same_result(&parse_obj_in_chunks(data, &opts, chunk_bytes), &serial);
        }
        if let Ok(file) = parse_mesh(data, Format::Obj, &opts) {
            let topo = &file.mesh.topology;
            // Cross-relations must agree: every face edge lists the face.
            for f in 0..topo.num_faces() {
                for &e in topo.face_edges(f) {
                    assert!(topo.edge_faces(e as usize).contains(&(f as u32)));
                }
            }
            let _ = subd_mesh::TopologySummary::new(topo);
            let mut out = Vec::new();
            encode_mesh(&mut out, &file.mesh, Format::Obj, &WriteOptions::default()).unwrap();
            let again = parse_mesh(&out, Format::Obj, &opts).expect("written OBJ must read back");
            assert_eq!(again.mesh.topology.all_face_vertices(), topo.all_face_vertices());
            // `vt` with `f v/vt` survives it too, corner by corner.
            assert_eq!(corner_uvs(&again.mesh), corner_uvs(&file.mesh));
        }
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

/// The chunked reader's result must be the serial one: the same mesh, tags, UVs and warnings,
/// or the same error, worded the same.
fn same_result(chunked: &Result<MeshFile, ReadError>, serial: &Result<MeshFile, ReadError>) {
    match (chunked, serial) {
        (Ok(c), Ok(s)) => {
            assert_eq!(c.mesh, s.mesh);
            assert_eq!(c.warnings, s.warnings);
            assert_eq!(c.extra_tags, s.extra_tags);
            assert_eq!(c.orientation_conflicts, s.orientation_conflicts);
        }
        (Err(c), Err(s)) => assert_eq!(c.to_string(), s.to_string()),
        (c, s) => panic!("chunked {:?} but serial {:?}", c.as_ref().err(), s.as_ref().err()),
    }
}
