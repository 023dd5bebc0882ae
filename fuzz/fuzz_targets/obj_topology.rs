//! Fuzzes the OBJ reader and the topology builder behind it: any bytes must give a mesh or a
//! typed error, never a panic; a mesh that comes back must be internally consistent and
//! survive a write/read round trip.
#![no_main]

use libfuzzer_sys::fuzz_target;
use subd_io::{Format, ReadOptions, WriteOptions, encode_mesh, parse_mesh};

fuzz_target!(|data: &[u8]| {
    for accept in [false, true] {
        let opts = ReadOptions {
            accept_inconsistent_orientation: accept,
            ..Default::default()
        };
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
