//! Fuzzes the USD reader (`.usda` text, `.usdc` binary, `.usdz` package, through `openusd`)
//! and the mesh built from a prim: any bytes must give a mesh or a typed error, never a
//! panic; a mesh that comes back must survive a write/read round trip in every encoding.
#![no_main]

use libfuzzer_sys::fuzz_target;
use subd_io::{Format, ReadOptions, WriteOptions, encode_mesh, parse_mesh};

fuzz_target!(|data: &[u8]| {
    let opts = ReadOptions {
        accept_inconsistent_orientation: true,
        ..Default::default()
    };
    // The first byte picks the encoding the rest is read as, so one corpus covers all three.
    let Some((&pick, bytes)) = data.split_first() else {
        return;
    };
    let format = [Format::Usda, Format::Usdc, Format::Usdz][usize::from(pick % 3)];
    if let Ok(file) = parse_mesh(bytes, format, &opts) {
        for again_as in [Format::Usda, Format::Usdc, Format::Usdz] {
            let mut out = Vec::new();
            if let Err(e) = encode_mesh(&mut out, &file.mesh, again_as, &WriteOptions::default())
            {
                // Double-precision points or UVs (or a transform) can leave single precision,
                // which USD's points and st hold: the one refusal allowed.
                assert!(e.to_string().contains("beyond single precision"), "{e}");
                return;
            }
            let again = parse_mesh(&out, again_as, &opts).expect("written USD must read back");
            assert_eq!(
                again.mesh.topology.all_face_vertices(),
                file.mesh.topology.all_face_vertices()
            );
            assert_eq!(again.mesh.topology.tags(), file.mesh.topology.tags());
        }
    }
});
