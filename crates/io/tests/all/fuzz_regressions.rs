//! Inputs the fuzzers found problems with, kept as regression tests: each must give a mesh
//! that survives a write/read round trip, or a typed error, quickly and without a panic.

use std::path::Path;
use std::time::{Duration, Instant};

use subd_io::{Format, PlyEncoding, ReadOptions, WriteOptions, encode_mesh, parse_mesh};

fn check(name: &str, format: Format) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz_regressions")
        .join(name);
    let bytes = std::fs::read(&path).unwrap();
    let opts = ReadOptions {
        accept_inconsistent_orientation: true,
        ..Default::default()
    };
    let start = Instant::now();
    let parsed = parse_mesh(&bytes, format, &opts);
    assert!(
        start.elapsed() < Duration::from_secs(2),
        "{name} took {:?}",
        start.elapsed()
    );
    if let Ok(file) = parsed {
        for enc in [PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian] {
            let w = WriteOptions {
                ply_encoding: enc,
                ..Default::default()
            };
            for out_format in [Format::Obj, Format::Ply] {
                let mut out = Vec::new();
                encode_mesh(&mut out, &file.mesh, out_format, &w).unwrap();
                let back = parse_mesh(&out, out_format, &opts).unwrap_or_else(|e| {
                    panic!("{name} written as {out_format:?} does not read back: {e}")
                });
                assert_eq!(
                    back.mesh.topology.tags(),
                    file.mesh.topology.tags(),
                    "{name}"
                );
            }
        }
    }
}

/// A crease sharpness of 3.4e79 became `inf` in `f32` and was written as `inf`.
#[test]
fn huge_sharpness_round_trips() {
    check("ply_huge_sharpness.ply", Format::Ply);
}

/// `element crease 01569664312` without properties spun through 1.5e9 empty instances.
#[test]
fn empty_element_with_huge_count_fails_fast() {
    check("ply_empty_element_slow.ply", Format::Ply);
}

/// The OBJ twin of `huge_sharpness_round_trips`.
#[test]
fn obj_huge_sharpness_round_trips() {
    check("obj_huge_sharpness.obj", Format::Obj);
}
