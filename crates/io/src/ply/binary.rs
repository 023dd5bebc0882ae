//! Binary vertex and face elements read without the per-value reader: vertices (of fixed
//! size when every property is a scalar) decoded by all threads, faces in one tight serial
//! pass (their lists make their sizes vary).
//!
//! Anything unusual (a non-finite coordinate, a face of fewer than three vertices, an index
//! that is no `u32`, a layout not handled here) leaves the element to the per-value reader
//! of the parent module, from its first byte, which finds and words the error.

use rayon::prelude::*;
use subd_mesh::DVec3;

use super::{Body, Element, ElementReader, Property, Role, Scalar, scalar_value};

/// Vertices per parallel task.
pub(super) const VERTICES_PER_TASK: usize = 1 << 14;

/// Reads every instance of `el` when this module handles it, and returns whether it did
/// (having changed nothing when it did not).
pub(super) fn read_element(
    r: &mut ElementReader,
    el: &Element,
    role: Option<Role>,
    body: &mut Body<'_>,
    vertices_per_task: usize,
) -> bool {
    let Body::Binary {
        data,
        pos,
        big_endian,
    } = body
    else {
        return false;
    };
    let rest = &data[*pos..];
    let read = match role {
        Some(Role::Vertex(xyz)) => {
            read_vertices(r, el, xyz, rest, *big_endian, vertices_per_task.max(1))
        }
        Some(Role::Face { list, level }) => read_faces(r, el, list, level, rest, *big_endian),
        _ => None,
    };
    match read {
        Some(bytes) => {
            *pos += bytes;
            true
        }
        None => false,
    }
}

/// Where each scalar property of an instance starts, and the instance's size; `None` if a
/// property is a list.
fn scalar_offsets(props: &[Property]) -> Option<(Vec<(usize, Scalar)>, usize)> {
    let mut offsets = Vec::with_capacity(props.len());
    let mut size = 0;
    for p in props {
        let Property::Scalar(_, ty) = p else {
            return None;
        };
        offsets.push((size, *ty));
        size += ty.size();
    }
    Some((offsets, size))
}

/// The vertex element: positions (and texture coordinates) decoded by all threads from
/// fixed-size records; the bytes read.
fn read_vertices(
    r: &mut ElementReader,
    el: &Element,
    [x, y, z]: [usize; 3],
    data: &[u8],
    big_endian: bool,
    per_task: usize,
) -> Option<usize> {
    let (fields, stride) = scalar_offsets(&el.props)?;
    if stride == 0 {
        return None;
    }
    let bytes = data.get(..el.count.checked_mul(stride)?)?;
    let value =
        |rec: &[u8], (offset, ty): (usize, Scalar)| scalar_value(&rec[offset..], ty, big_endian);
    let (fx, fy, fz) = (fields[x], fields[y], fields[z]);
    let first = r.d.positions.len();
    r.d.positions.resize(first + el.count, DVec3::ZERO);
    let finite = r.d.positions[first..]
        .par_chunks_mut(per_task)
        .zip(bytes.par_chunks(per_task * stride))
        .all(|(out, records)| {
            out.iter_mut()
                .zip(records.chunks_exact(stride))
                .all(|(p, rec)| {
                    *p = DVec3::new(value(rec, fx), value(rec, fy), value(rec, fz));
                    p.is_finite()
                })
        });
    let uv_finite = finite
        && match r.uv_props {
            Some([u, v]) => read_texcoords(&mut r.texcoords, bytes, stride, per_task, |rec| {
                [value(rec, fields[u]), value(rec, fields[v])]
            }),
            None => true,
        };
    if !uv_finite {
        r.d.positions.truncate(first);
        return None;
    }
    Some(bytes.len())
}

/// Appends the texture coordinates `uv(record)` of every record to `texcoords`, by all
/// threads; `false` (having appended nothing) if one is not finite.
fn read_texcoords(
    texcoords: &mut Vec<f64>,
    bytes: &[u8],
    stride: usize,
    per_task: usize,
    uv: impl Fn(&[u8]) -> [f64; 2] + Sync,
) -> bool {
    let first = texcoords.len();
    texcoords.resize(first + 2 * (bytes.len() / stride), 0.0);
    let finite = texcoords[first..]
        .par_chunks_mut(2 * per_task)
        .zip(bytes.par_chunks(per_task * stride))
        .all(|(out, records)| {
            out.chunks_exact_mut(2)
                .zip(records.chunks_exact(stride))
                .all(|(t, rec)| {
                    let [u, v] = uv(rec);
                    (t[0], t[1]) = (u, v);
                    u.is_finite() && v.is_finite()
                })
        });
    if !finite {
        texcoords.truncate(first);
    }
    finite
}

/// The layout of a face instance: scalars, the vertex list, scalars.
struct FaceLayout {
    before: usize,
    count: Scalar,
    index: Scalar,
    after: usize,
    /// Offset of the `level` byte in the scalars after the list, when there is one.
    level: Option<usize>,
}

impl FaceLayout {
    /// The layout of `el`, when every property but the vertex list `list` is a scalar and
    /// `level`, if any, is a `uchar` after the list (any level value is then valid).
    fn of(el: &Element, list: usize, level: usize) -> Option<FaceLayout> {
        let Property::List(_, count, index) = el.props[list] else {
            return None;
        };
        let (_, before) = scalar_offsets(&el.props[..list])?;
        let (after_fields, after) = scalar_offsets(&el.props[list + 1..])?;
        let level = match level {
            usize::MAX => None,
            l if l > list && after_fields[l - list - 1].1 == Scalar::U8 => {
                Some(after_fields[l - list - 1].0)
            }
            _ => return None,
        };
        Some(FaceLayout {
            before,
            count,
            index,
            after,
            level,
        })
    }
}

/// The face element in one serial pass; the bytes read.
fn read_faces(
    r: &mut ElementReader,
    el: &Element,
    list: usize,
    level: usize,
    data: &[u8],
    big_endian: bool,
) -> Option<usize> {
    let layout = FaceLayout::of(el, list, level)?;
    let d = &mut r.d;
    let marks = (
        d.face_sizes.len(),
        d.face_vertices.len(),
        d.face_levels.len(),
    );
    // At most this many indices fit in the data; pages never written cost nothing.
    d.face_vertices.reserve(data.len() / layout.index.size());
    let mut pos = 0;
    for _ in 0..el.count {
        match read_face(d, &layout, data, pos, big_endian) {
            Some(next) => pos = next,
            None => {
                d.face_sizes.truncate(marks.0);
                d.face_vertices.truncate(marks.1);
                d.face_levels.truncate(marks.2);
                return None;
            }
        }
    }
    Some(pos)
}

/// One face starting at `pos`, checked as the per-value reader checks it; where the next
/// face starts.
#[inline]
fn read_face(
    d: &mut super::PlyData,
    layout: &FaceLayout,
    data: &[u8],
    pos: usize,
    big_endian: bool,
) -> Option<usize> {
    let pos = pos + layout.before;
    let n = scalar_value(
        data.get(pos..pos + layout.count.size())?,
        layout.count,
        big_endian,
    );
    if !(3.0..=u32::MAX as f64).contains(&n) {
        return None;
    }
    let (n, size) = (n as usize, layout.index.size());
    let first = pos + layout.count.size();
    let indices = data.get(first..first.checked_add(n.checked_mul(size)?)?)?;
    for bytes in indices.chunks_exact(size) {
        let v = scalar_value(bytes, layout.index, big_endian);
        if v < 0.0 || v.fract() != 0.0 || v >= u32::MAX as f64 {
            return None;
        }
        d.face_vertices.push(v as u32);
    }
    let after = first + indices.len();
    let end = after.checked_add(layout.after)?;
    data.get(after..end)?;
    if let Some(offset) = layout.level {
        d.face_levels.push(data[after + offset]);
    }
    d.face_sizes.push(n as u32);
    Some(end)
}

#[cfg(test)]
mod tests {
    use crate::view::MeshView;
    use crate::{Format, PlyEncoding, ReadOptions, WriteOptions, encode_view, parse_mesh};
    use subd_mesh::DVec3;

    /// Positions, face offsets, face vertices, per-vertex uv, face levels.
    type Grid = (Vec<DVec3>, Vec<u32>, Vec<u32>, Vec<f64>, Vec<u8>);

    /// A grid of `n` x `n` quads with odd coordinates, per-vertex uv and face levels.
    fn grid(n: u32) -> Grid {
        let w = n + 1;
        let positions = (0..w * w)
            .map(|i| {
                let (x, y) = ((i % w) as f64, (i / w) as f64);
                DVec3::new(x / 3.0, y * 1e-9 + 0.1, (x * y).sqrt() * -7.7e10)
            })
            .collect();
        let (mut offsets, mut vertices) = (vec![0], Vec::new());
        for j in 0..n {
            for i in 0..n {
                let v = j * w + i;
                vertices.extend([v, v + 1, v + w + 1, v + w]);
                offsets.push(vertices.len() as u32);
            }
        }
        let uv = (0..w * w)
            .flat_map(|i| [i as f64 / 7.0, 1.0 / (i + 1) as f64])
            .collect();
        let levels = (0..n * n).map(|f| (f % 5) as u8).collect();
        (positions, offsets, vertices, uv, levels)
    }

    /// `view` written as PLY in `ply_encoding`.
    fn encoded(view: &MeshView<'_>, ply_encoding: PlyEncoding) -> Vec<u8> {
        let mut out = Vec::new();
        let options = WriteOptions {
            ply_encoding,
            ..WriteOptions::default()
        };
        encode_view(&mut out, view, Format::Ply, &options).unwrap();
        out
    }

    fn read(bytes: &[u8]) -> crate::MeshFile {
        parse_mesh(bytes, Format::Ply, &ReadOptions::default()).unwrap()
    }

    /// The binary reader gives what the per-value reader gives for the ASCII file of the same
    /// mesh (whose text holds the same `f64` values).
    #[test]
    fn binary_reads_as_ascii_reads() {
        let (positions, offsets, vertices, uv, levels) = grid(300);
        let view = MeshView::new(&positions, &offsets, &vertices, &[])
            .and_then(|v| v.with_uv(&uv, 2, &vertices))
            .and_then(|v| v.with_face_levels(&levels))
            .unwrap();
        let binary = read(&encoded(&view, PlyEncoding::BinaryLittleEndian));
        let ascii = read(&encoded(&view, PlyEncoding::Ascii));
        let bits = |f: &crate::MeshFile| {
            f.mesh
                .positions
                .iter()
                .map(|p| p.to_array().map(f64::to_bits))
                .collect::<Vec<_>>()
        };
        assert_eq!(bits(&binary), bits(&ascii));
        assert_eq!(
            binary.mesh.topology.all_face_vertices(),
            ascii.mesh.topology.all_face_vertices()
        );
        assert_eq!(binary.face_levels, ascii.face_levels);
        let uv_values = |f: &crate::MeshFile| f.mesh.uv().map(|c| c.values().to_vec());
        assert_eq!(uv_values(&binary), uv_values(&ascii));
        assert!(uv_values(&binary).is_some());
    }

    /// A binary file by hand: `vertex_props` and `face_props` header lines, then `body`.
    fn file(big_endian: bool, counts: [usize; 2], props: [&str; 2], body: &[u8]) -> Vec<u8> {
        let format = if big_endian {
            "binary_big_endian"
        } else {
            "binary_little_endian"
        };
        let mut out = format!(
            "ply\nformat {format} 1.0\nelement vertex {}\n{}element face {}\n{}end_header\n",
            counts[0], props[0], counts[1], props[1]
        )
        .into_bytes();
        out.extend_from_slice(body);
        out
    }

    /// Vertices `(w, x, y, z)` as `short` and `float`s, faces as a `ushort` count of `int`
    /// indices between an `int` before and a `uchar` after; `tweak` changes the body.
    fn odd_layout(
        big_endian: bool,
        tweak: impl Fn(&mut Vec<u8>, usize),
    ) -> Result<crate::MeshFile, String> {
        let n = 50u32;
        let (positions, offsets, vertices, _, _) = grid(n);
        let mut body = Vec::new();
        let put = |body: &mut Vec<u8>, le: &[u8]| {
            let mut b = le.to_vec();
            if big_endian {
                b.reverse();
            }
            body.extend_from_slice(&b);
        };
        for p in &positions {
            put(&mut body, &7i16.to_le_bytes());
            for c in p.to_array() {
                put(&mut body, &(c as f32).to_le_bytes());
            }
        }
        let faces_at = body.len();
        for f in 0..offsets.len() - 1 {
            put(&mut body, &(-1i32).to_le_bytes());
            let face = &vertices[offsets[f] as usize..offsets[f + 1] as usize];
            put(&mut body, &(face.len() as u16).to_le_bytes());
            for &v in face {
                put(&mut body, &(v as i32).to_le_bytes());
            }
            body.push(9);
        }
        tweak(&mut body, faces_at);
        let bytes = file(
            big_endian,
            [positions.len(), (n * n) as usize],
            [
                "property short w\nproperty float x\nproperty float y\nproperty float z\n",
                "property int before\nproperty list ushort int vertex_indices\nproperty uchar after\n",
            ],
            &body,
        );
        parse_mesh(&bytes, Format::Ply, &ReadOptions::default()).map_err(|e| e.to_string())
    }

    #[test]
    fn both_byte_orders_and_extra_properties() {
        let le = odd_layout(false, |_, _| {}).unwrap();
        let be = odd_layout(true, |_, _| {}).unwrap();
        assert_eq!(le.mesh.positions, be.mesh.positions);
        assert_eq!(le.mesh.topology.num_faces(), 2500);
        assert_eq!(
            le.mesh.topology.all_face_vertices(),
            be.mesh.topology.all_face_vertices()
        );
        let (positions, ..) = grid(50);
        assert_eq!(le.mesh.positions[1000].x, positions[1000].x as f32 as f64);
    }

    /// Errors in late instances are the per-value reader's, naming the instance.
    #[test]
    fn late_errors_name_the_instance() {
        // Vertex 2600 (of 2601): x = NaN.
        let nan = |b: &mut Vec<u8>, _| {
            b[2600 * 14 + 2..2600 * 14 + 6].copy_from_slice(&f32::NAN.to_le_bytes())
        };
        assert_eq!(
            odd_layout(false, nan).unwrap_err(),
            "vertex 2600 has a non-finite coordinate"
        );
        // Face 2499 (the last; 4 + 2 + 16 + 1 bytes each): count 2, or index -3.
        let short = |b: &mut Vec<u8>, at: usize| b[at + 2499 * 23 + 4] = 2;
        assert_eq!(
            odd_layout(false, short).unwrap_err(),
            "face 2499 has 2 vertices; a face needs at least 3"
        );
        let negative = |b: &mut Vec<u8>, at: usize| {
            b[at + 2499 * 23 + 6..at + 2499 * 23 + 10].copy_from_slice(&(-3i32).to_le_bytes())
        };
        assert_eq!(
            odd_layout(false, negative).unwrap_err(),
            "face 2499 has invalid vertex index -3"
        );
        let truncated = |b: &mut Vec<u8>, _| b.truncate(b.len() - 1);
        assert!(
            odd_layout(false, truncated)
                .unwrap_err()
                .contains("binary data ends inside face 2499")
        );
    }

    /// Vertices decoded in tasks of one, three or all of them give what the per-value reader
    /// gives, bit for bit, and the same errors where a late value is bad.
    #[test]
    fn tiny_tasks_give_the_per_value_result() {
        use super::super::{BinaryReading, parse_ply_with};
        let (positions, offsets, vertices, uv, levels) = grid(40);
        let view = MeshView::new(&positions, &offsets, &vertices, &[])
            .and_then(|v| v.with_uv(&uv, 2, &vertices))
            .and_then(|v| v.with_face_levels(&levels))
            .unwrap();
        let good = encoded(&view, PlyEncoding::BinaryLittleEndian);
        let mut bad = good.clone();
        // The last vertex's last value (its v, a double) becomes infinite.
        let header_end = bad.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
        let last_v = header_end + positions.len() * 40 - 8;
        bad[last_v..last_v + 8].copy_from_slice(&f64::INFINITY.to_le_bytes());
        let read = |bytes: &[u8], reading| {
            parse_ply_with(bytes, &ReadOptions::default(), reading).map_err(|e| e.to_string())
        };
        for bytes in [&good, &bad] {
            let serial = read(bytes, BinaryReading::PerValue);
            for per_task in [1, 3, 1 << 14] {
                let fast = read(bytes, BinaryReading::Parallel(per_task));
                match (&fast, &serial) {
                    (Ok(f), Ok(s)) => {
                        assert_eq!(f.mesh, s.mesh);
                        assert_eq!(f.face_levels, s.face_levels);
                    }
                    (Err(f), Err(s)) => assert_eq!(f, s),
                    _ => panic!("fast {:?} but per-value {:?}", fast.err(), serial.err()),
                }
            }
        }
        assert!(read(&bad, BinaryReading::PerValue).is_err());
    }
}
