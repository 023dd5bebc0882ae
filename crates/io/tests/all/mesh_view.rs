//! `MeshView::new` on arbitrary face lists: it accepts exactly the well-formed ones
//! (checked here by a separate scan), and whatever it accepts encodes in every format
//! without a panic, with one record per vertex and face.

use proptest::prelude::*;
use subd_io::{Format, MeshView, PlyEncoding, WriteOptions, encode_view};
use subd_mesh::DVec3;

/// Sizes, indices and coordinates drawn so that most lists are valid and each kind of
/// defect shows up often.
fn lists() -> impl Strategy<Value = (Vec<DVec3>, Vec<u32>, Vec<u32>, Vec<bool>)> {
    (
        prop::collection::vec(
            prop_oneof![
                8 => (-2.0f64..2.0, -2.0f64..2.0, -2.0f64..2.0).prop_map(|(x, y, z)| DVec3::new(x, y, z)),
                1 => Just(DVec3::new(f64::NAN, 0.0, 0.0)),
            ],
            0..8,
        ),
        prop::collection::vec(prop_oneof![9 => 3u32..6, 1 => 0u32..3], 0..6),
        prop::collection::vec(prop_oneof![9 => 0u32..8, 1 => 8u32..12], 0..40),
        prop::collection::vec(any::<bool>(), 0..7),
    )
        .prop_map(|(positions, sizes, pool, holes)| {
            // Offsets from the sizes; indices cycled from the pool (or out of range when the
            // pool is empty), sometimes a few short or long.
            let mut offsets = vec![0u32];
            for s in &sizes {
                offsets.push(offsets.last().unwrap() + s);
            }
            let total = *offsets.last().unwrap() as usize;
            let vertices: Vec<u32> = (0..total)
                .map(|k| if pool.is_empty() { 99 } else { pool[k % pool.len()] })
                .collect();
            (positions, offsets, vertices, holes)
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn views_accept_exactly_the_well_formed_lists((positions, offsets, vertices, holes) in lists()) {
        let faces = offsets.len() - 1;
        let well_formed = offsets.windows(2).all(|w| w[1] - w[0] >= 3)
            && vertices.iter().all(|&v| (v as usize) < positions.len())
            && positions.iter().all(|p| p.is_finite())
            && (holes.is_empty() || holes.len() == faces);
        let view = MeshView::new(&positions, &offsets, &vertices, &holes);
        prop_assert_eq!(view.is_ok(), well_formed, "{:?}", view.as_ref().err());
        let Ok(view) = view else { return Ok(()) };
        let mut obj = Vec::new();
        encode_view(&mut obj, &view, Format::Obj, &WriteOptions::default()).unwrap();
        let text = String::from_utf8(obj).unwrap();
        prop_assert_eq!(text.lines().filter(|l| l.starts_with("v ")).count(), positions.len());
        prop_assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), faces);
        for ply_encoding in [PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian] {
            let w = WriteOptions { ply_encoding, ..Default::default() };
            let mut ply = Vec::new();
            encode_view(&mut ply, &view, Format::Ply, &w).unwrap();
            let head = String::from_utf8_lossy(&ply[..ply.len().min(400)]).into_owned();
            let vertex_line = format!("element vertex {}", positions.len());
            let face_line = format!("element face {faces}");
            prop_assert!(head.contains(&vertex_line));
            prop_assert!(head.contains(&face_line));
        }
        let mut glb = Vec::new();
        encode_view(&mut glb, &view, Format::Glb, &WriteOptions::default()).unwrap();
        prop_assert_eq!(&glb[..4], b"glTF");
        prop_assert_eq!(u32::from_le_bytes(glb[8..12].try_into().unwrap()) as usize, glb.len());
    }
}

#[test]
fn ply_face_levels_read_back_in_both_encodings() {
    let positions = [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
    ];
    let (offsets, vertices, holes) = ([0u32, 3, 6], [0u32, 1, 2, 0, 2, 3], [false, false]);
    let levels = [2u8, 7];
    let view = MeshView::new(&positions, &offsets, &vertices, &holes)
        .unwrap()
        .with_face_levels(&levels)
        .unwrap();
    for encoding in [PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian] {
        let mut ply = Vec::new();
        let w = WriteOptions {
            ply_encoding: encoding,
            ..Default::default()
        };
        encode_view(&mut ply, &view, Format::Ply, &w).unwrap();
        let file = subd_io::parse_mesh(&ply, Format::Ply, &Default::default()).unwrap();
        assert_eq!(
            file.face_levels.as_deref(),
            Some(&levels[..]),
            "{encoding:?}"
        );
    }
    // A file without the property has none.
    let plain = MeshView::new(&positions, &offsets, &vertices, &holes).unwrap();
    let mut ply = Vec::new();
    encode_view(&mut ply, &plain, Format::Ply, &WriteOptions::default()).unwrap();
    let file = subd_io::parse_mesh(&ply, Format::Ply, &Default::default()).unwrap();
    assert_eq!(file.face_levels, None);
}
