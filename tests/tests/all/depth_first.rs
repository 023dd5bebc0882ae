//! Depth-first refinement (`DepthFirst`): every chunk's faces and points, put at their
//! indices in the level, are bit for bit those of the whole level refined at once
//! (`Refinement`), and together they cover the level, on every shape with every scheme of
//! OpenSubdiv's family that applies, from one base face a chunk to the whole mesh.

use subd_mesh::DVec3;
use subd_schemes::{DepthFirst, Options, Refinement, Scheme};
use subd_tests::{all_faces_of_size, small_shapes};

/// Checks every chunk of `levels` levels in chunks of about `per_chunk` faces against the
/// whole refinement; the number of chunks.
fn check(
    name: &str,
    t: &subd_mesh::Topology,
    points: &[DVec3],
    scheme: &Scheme,
    options: &Options,
    levels: usize,
    per_chunk: u64,
) -> usize {
    let whole = Refinement::new(t, scheme.clone(), options, levels).unwrap();
    let expected = whole.points_at(points, levels);
    let (_, faces) = whole.faces(levels);
    let df = DepthFirst::new(t, scheme.clone(), options, levels, per_chunk).unwrap();
    let size = df.face_size();
    assert_eq!(df.counts().vertices as usize, expected.len(), "{name}");
    assert_eq!(df.counts().faces as usize * size, faces.len(), "{name}");
    let mut seen_points = vec![false; expected.len()];
    let mut seen_faces = vec![false; faces.len() / size];
    for i in 0..df.num_chunks() {
        let chunk = df.chunk(i, points).unwrap();
        for (first, range) in chunk.point_runs() {
            for (k, p) in chunk.points()[range].iter().enumerate() {
                let v = first as usize + k;
                assert_eq!(
                    p.to_array().map(f64::to_bits),
                    expected[v].to_array().map(f64::to_bits),
                    "{name} {scheme} L{levels}: vertex {v} of chunk {i}"
                );
                seen_points[v] = true;
            }
        }
        for (first, range) in chunk.face_runs(size) {
            let got = &chunk.face_vertices()[range];
            let at = first as usize * size;
            assert_eq!(
                got,
                &faces[at..at + got.len()],
                "{name} {scheme} L{levels}: faces from {first}"
            );
            for f in 0..got.len() / size {
                assert!(
                    !seen_faces[first as usize + f],
                    "{name}: face written twice"
                );
                seen_faces[first as usize + f] = true;
            }
        }
    }
    assert!(
        seen_faces.iter().all(|&s| s),
        "{name} {scheme} L{levels}: a face missing"
    );
    let missing = seen_points.iter().position(|&s| !s);
    assert_eq!(missing, None, "{name} {scheme} L{levels}: a vertex missing");
    df.num_chunks()
}

#[test]
fn chunks_put_together_are_the_whole_level_bit_for_bit() {
    let (mut cases, mut multi) = (0, 0);
    for (name, file) in small_shapes(600) {
        let t = &file.mesh.topology;
        let schemes: &[Scheme] = if all_faces_of_size(t, 3) {
            &[Scheme::Loop, Scheme::CatmullClark]
        } else {
            &[Scheme::CatmullClark, Scheme::Bilinear]
        };
        let options = Options::from_hints(&file.mesh.hints);
        for scheme in schemes {
            if Refinement::new(t, scheme.clone(), &options, 1).is_err() {
                continue;
            }
            for (levels, per_chunk) in [(1, 1), (2, 40), (3, 1 << 30)] {
                let n = check(
                    &name,
                    t,
                    &file.mesh.positions,
                    scheme,
                    &options,
                    levels,
                    per_chunk,
                );
                cases += 1;
                multi += usize::from(n > 1);
            }
        }
    }
    assert!(cases >= 300, "{cases} cases");
    assert!(multi >= 150, "{multi} cases in several chunks");
}
