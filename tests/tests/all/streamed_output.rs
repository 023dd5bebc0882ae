//! A refinement's last level written from its streams (points and faces made a window at a
//! time from the level above) is byte for byte the file written from the level held whole,
//! in every format, on every shape with every scheme that applies.

use std::ops::Range;

use subd_io::{
    FaceSource, Format, MeshView, PlyEncoding, PointSource, Points, WriteOptions, encode_view,
};
use subd_mesh::{DVec3, SchemeHints};
use subd_schemes::{FaceStream, Options, PointStream, Refinement, Scheme};
use subd_tests::{all_faces_of_size, small_shapes};

struct StreamedPoints<'a>(PointStream<'a>);

impl PointSource for StreamedPoints<'_> {
    fn len(&self) -> usize {
        self.0.len()
    }
    fn fill(&self, first: usize, out: &mut [DVec3]) {
        self.0.fill(first, out);
    }
}

struct StreamedFaces<'a>(FaceStream<'a>);

impl FaceSource for StreamedFaces<'_> {
    fn num_faces(&self) -> usize {
        self.0.num_faces()
    }
    fn face_size(&self) -> usize {
        self.0.face_size()
    }
    fn fill(&self, faces: Range<usize>, out: &mut Vec<u32>) {
        self.0.fill(faces, out);
    }
}

fn encode(view: &MeshView<'_>, format: Format, ascii: bool) -> Vec<u8> {
    let options = WriteOptions {
        ply_encoding: if ascii {
            PlyEncoding::Ascii
        } else {
            PlyEncoding::BinaryLittleEndian
        },
        ..Default::default()
    };
    let mut out = Vec::new();
    encode_view(&mut out, view, format, &options).unwrap();
    out
}

/// The streamed view `subd refine` writes.
fn streamed_view<'a>(
    source: Points<'a>,
    faces: &'a StreamedFaces<'a>,
    tags: &subd_schemes::ExplicitTags,
    hints: SchemeHints,
) -> MeshView<'a> {
    let mut v = MeshView::streamed(source, faces, faces.0.hole_faces())
        .unwrap()
        .with_tags(tags.creases.clone(), tags.corners.clone())
        .unwrap();
    v.hints = hints;
    v
}

#[test]
fn streamed_last_level_files_equal_the_held_ones() {
    let (mut files, mut with_holes, mut with_tags) = (0, 0, 0);
    for (name, file) in small_shapes(4000) {
        let base = &file.mesh.topology;
        let schemes: &[Scheme] = if all_faces_of_size(base, 3) {
            &[Scheme::Loop, Scheme::CatmullClark]
        } else {
            &[Scheme::CatmullClark, Scheme::Bilinear]
        };
        let options = Options::from_hints(&file.mesh.hints);
        let hints = SchemeHints {
            boundary_interpolation: Some(options.boundary_interpolation),
            crease_method: Some(options.crease_method),
            triangle_subdivision: file.mesh.hints.triangle_subdivision,
            fvar_interpolation: None,
            scheme: None,
        };
        for scheme in schemes {
            for levels in 1..=2 {
                let what = format!("{name} {scheme:?} L{levels}");
                let held_r = Refinement::new(base, scheme.clone(), &options, levels).unwrap();
                let positions = held_r.refine_points(&file.mesh.positions).pop().unwrap();
                let (offsets, vertices) = held_r.faces(levels);
                let holes = held_r.holes(levels);
                let tags = held_r.explicit_tags(levels);
                with_holes += usize::from(holes.iter().any(|&h| h));
                with_tags += usize::from(!tags.creases.is_empty() || !tags.corners.is_empty());
                let mut held = MeshView::new(&positions, offsets, vertices, &holes)
                    .unwrap()
                    .with_tags(tags.creases.clone(), tags.corners.clone())
                    .unwrap();
                held.hints = hints;

                let r = Refinement::new(base, scheme.clone(), &options, levels).unwrap();
                let above = r.points_at(&file.mesh.positions, levels - 1);
                let points = StreamedPoints(r.point_stream(&above).unwrap());
                let faces = StreamedFaces(r.face_stream().unwrap());
                let tags = r.explicit_tags(levels);
                let streamed = streamed_view(Points::Streamed(&points), &faces, &tags, hints);
                for (format, ascii) in [
                    (Format::Obj, false),
                    (Format::Ply, false),
                    (Format::Ply, true),
                    (Format::Glb, false),
                ] {
                    assert!(
                        encode(&held, format, ascii) == encode(&streamed, format, ascii),
                        "{what} {format:?} ascii {ascii}"
                    );
                    files += 1;
                }
                // `.glb` from held positions with streamed faces, as `subd refine` writes it.
                let half = streamed_view(Points::Held(&positions), &faces, &tags, hints);
                assert!(
                    encode(&held, Format::Glb, false) == encode(&half, Format::Glb, false),
                    "{what} glb, held points"
                );
                assert!(!r.has_topology(levels), "{what}: the level stays unbuilt");
            }
        }
    }
    assert!(files > 500, "{files} files");
    assert!(with_holes > 3 && with_tags > 20, "{with_holes} {with_tags}");
}

/// A face source that names a vertex beyond the positions, or a point source that makes a
/// non-finite point, fails the write with an error naming the element, in every format.
#[test]
fn bad_streamed_sources_fail_the_write() {
    struct Quads(u32);
    impl FaceSource for Quads {
        fn num_faces(&self) -> usize {
            1
        }
        fn face_size(&self) -> usize {
            4
        }
        fn fill(&self, _faces: Range<usize>, out: &mut Vec<u32>) {
            out.extend_from_slice(&[0, 1, 2, self.0]);
        }
    }
    struct Nan;
    impl PointSource for Nan {
        fn len(&self) -> usize {
            4
        }
        fn fill(&self, first: usize, out: &mut [DVec3]) {
            for (i, o) in out.iter_mut().enumerate() {
                *o = if first + i == 2 { DVec3::NAN } else { DVec3::X };
            }
        }
    }
    let points = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
    let beyond = Quads(9);
    let fine = Quads(3);
    for format in [Format::Obj, Format::Ply, Format::Glb] {
        let view = MeshView::streamed(Points::Held(&points), &beyond, vec![]).unwrap();
        let err = encode_view(&mut Vec::new(), &view, format, &WriteOptions::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains("face 0 uses vertex 9"), "{format:?}: {err}");
        let view = MeshView::streamed(Points::Streamed(&Nan), &fine, vec![]).unwrap();
        let err = encode_view(&mut Vec::new(), &view, format, &WriteOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("vertex 2 has a non-finite"),
            "{format:?}: {err}"
        );
    }
    assert!(MeshView::streamed(Points::Held(&points), &fine, vec![1]).is_err());
}

/// Levels larger than a writer's window (half a million records): a closed torus, whose
/// last level comes from its grandparent, and a creased one, whose last level comes from a
/// built parent, written in windows that split the stream.
#[test]
fn streamed_levels_larger_than_a_window_equal_the_held_ones() {
    let quads = subd_mesh::primitives::torus(128, 96, 3.0, 1.0);
    let (creased, creased_points) = subd_tests::creased_torus(44, 44);
    let cases = [
        ("torus", &quads.topology, &quads.positions[..], 3),
        ("creased torus", &creased, &creased_points[..], 4),
    ];
    let options = Options::default();
    for (name, base, base_points, levels) in cases {
        let held_r = Refinement::new(base, Scheme::CatmullClark, &options, levels).unwrap();
        let positions = held_r.points_at(base_points, levels);
        assert!(
            positions.len() > 600_000,
            "{name}: {} points",
            positions.len()
        );
        let (offsets, vertices) = held_r.faces(levels);
        let tags = held_r.explicit_tags(levels);
        let held_holes = held_r.holes(levels);
        let held = MeshView::new(&positions, offsets, vertices, &held_holes)
            .unwrap()
            .with_tags(tags.creases.clone(), tags.corners.clone())
            .unwrap();
        let r = Refinement::new(base, Scheme::CatmullClark, &options, levels).unwrap();
        let above = r.points_at(base_points, levels - 1);
        let points = StreamedPoints(r.point_stream(&above).unwrap());
        let faces = StreamedFaces(r.face_stream().unwrap());
        let streamed = streamed_view(
            Points::Streamed(&points),
            &faces,
            &r.explicit_tags(levels),
            SchemeHints::default(),
        );
        for format in [Format::Obj, Format::Ply, Format::Glb] {
            assert!(
                encode(&held, format, false) == encode(&streamed, format, false),
                "{name} {format:?}"
            );
        }
    }
}
