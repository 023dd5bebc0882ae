//! The writers' bytes against the serial `write!` formatting they replaced, on random meshes
//! large enough to span several windows of [`crate::records`].

use std::io::Write;

use subd_mesh::DVec3;

use crate::view::MeshView;
use crate::{Format, PlyEncoding, WriteOptions, encode_view};

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    /// Finite values of every magnitude, and short ones, as meshes hold them.
    fn value(&mut self) -> f64 {
        let s = self.next();
        match s % 4 {
            0 => f64::from_bits(s >> 2) * if s & 2 == 0 { 1.0 } else { -1.0 },
            1 => (s >> 11) as f64 / (1u64 << 53) as f64 * 8.0 - 4.0,
            2 => ((s >> 50) as f64) / 8.0,
            _ => (s >> 12) as f64 * 1e-12,
        }
    }
}

/// A random polygon mesh: `n` vertices, faces of 3 to 6 corners, one uv per corner.
struct Random {
    positions: Vec<DVec3>,
    normals: Vec<DVec3>,
    offsets: Vec<u32>,
    vertices: Vec<u32>,
    uv: Vec<f64>,
    uv_indices: Vec<u32>,
}

fn random(n: usize, seed: u64) -> Random {
    let mut r = Rng(seed);
    let point = |r: &mut Rng| DVec3::new(r.value(), r.value(), r.value());
    let positions = (0..n).map(|_| point(&mut r)).collect();
    let normals = (0..n).map(|_| point(&mut r)).collect();
    let (mut offsets, mut vertices) = (vec![0u32], Vec::new());
    for _ in 0..n {
        for _ in 0..3 + r.next() % 4 {
            vertices.push((r.next() % n as u64) as u32);
        }
        offsets.push(vertices.len() as u32);
    }
    let uv = (0..2 * n).map(|_| r.value()).collect();
    let uv_indices = (0..vertices.len())
        .map(|_| (r.next() % n as u64) as u32)
        .collect();
    Random {
        positions,
        normals,
        offsets,
        vertices,
        uv,
        uv_indices,
    }
}

/// The records of an OBJ file as the serial `write!` code wrote them.
fn reference_obj_records(m: &Random) -> Vec<u8> {
    let mut b = Vec::new();
    for p in &m.positions {
        writeln!(b, "v {} {} {}", p.x, p.y, p.z).unwrap();
    }
    for n in &m.normals {
        writeln!(b, "vn {} {} {}", n.x, n.y, n.z).unwrap();
    }
    for uv in m.uv.chunks(2) {
        writeln!(b, "vt {} {}", uv[0], uv[1]).unwrap();
    }
    for f in 0..m.offsets.len() - 1 {
        b.push(b'f');
        for k in m.offsets[f] as usize..m.offsets[f + 1] as usize {
            let v = m.vertices[k] as u64 + 1;
            write!(b, " {v}/{}/{v}", m.uv_indices[k] as u64 + 1).unwrap();
        }
        b.push(b'\n');
    }
    b
}

fn contains(haystack: &[u8], needle: &[u8]) -> bool {
    haystack.windows(needle.len()).any(|w| w == needle)
}

#[test]
fn obj_records_are_the_serial_formatters_bytes() {
    let m = random(600_000, 11);
    let view = MeshView::new(&m.positions, &m.offsets, &m.vertices, &[])
        .and_then(|v| v.with_normals(&m.normals))
        .and_then(|v| v.with_uv(&m.uv, 2, &m.uv_indices))
        .unwrap();
    let mut out = Vec::new();
    encode_view(&mut out, &view, Format::Obj, &WriteOptions::default()).unwrap();
    let expected = reference_obj_records(&m);
    // After the two comment lines, the records; no tags follow.
    let body_start = out
        .iter()
        .enumerate()
        .filter(|&(_, &c)| c == b'\n')
        .nth(1)
        .unwrap()
        .0
        + 1;
    assert!(out[body_start..] == expected[..], "OBJ records differ");
    assert!(contains(&out, b"\nv "));
}

#[test]
fn ascii_ply_records_are_the_serial_formatters_bytes() {
    let m = random(600_000, 23);
    let view = MeshView::new(&m.positions, &m.offsets, &m.vertices, &[])
        .and_then(|v| v.with_normals(&m.normals))
        .unwrap();
    let mut out = Vec::new();
    let options = WriteOptions {
        ply_encoding: PlyEncoding::Ascii,
        ..WriteOptions::default()
    };
    encode_view(&mut out, &view, Format::Ply, &options).unwrap();
    let mut expected = Vec::new();
    for (p, n) in m.positions.iter().zip(&m.normals) {
        writeln!(expected, "{} {} {} {} {} {}", p.x, p.y, p.z, n.x, n.y, n.z).unwrap();
    }
    for f in 0..m.offsets.len() - 1 {
        let face = &m.vertices[m.offsets[f] as usize..m.offsets[f + 1] as usize];
        write!(expected, "{}", face.len()).unwrap();
        for v in face {
            write!(expected, " {v}").unwrap();
        }
        expected.push(b'\n');
    }
    let header_end = b"end_header\n";
    let body = out
        .windows(header_end.len())
        .position(|w| w == header_end)
        .unwrap()
        + header_end.len();
    assert!(out[body..] == expected[..], "ASCII PLY records differ");
}

/// The bytes do not depend on the number of threads (windows and tasks do).
#[test]
fn output_is_the_same_on_one_thread() {
    let m = random(200_000, 5);
    let view = MeshView::new(&m.positions, &m.offsets, &m.vertices, &[]).unwrap();
    for format in [Format::Obj, Format::Ply] {
        let encode = || {
            let mut out = Vec::new();
            encode_view(&mut out, &view, format, &WriteOptions::default()).unwrap();
            out
        };
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(encode);
        assert!(one == encode());
    }
}

/// Binary PLY bodies, positions alone (written straight from memory) and with normals
/// (encoded record by record), against the serial encoding.
#[test]
fn binary_ply_records_are_the_serial_encoders_bytes() {
    let m = random(300_000, 37);
    for with_normals in [false, true] {
        let mut view = MeshView::new(&m.positions, &m.offsets, &m.vertices, &[]).unwrap();
        if with_normals {
            view = view.with_normals(&m.normals).unwrap();
        }
        let mut out = Vec::new();
        encode_view(&mut out, &view, Format::Ply, &WriteOptions::default()).unwrap();
        let mut expected = Vec::new();
        for (i, p) in m.positions.iter().enumerate() {
            let normal = with_normals.then(|| m.normals[i].to_array());
            for c in p.to_array().iter().chain(normal.iter().flatten()) {
                expected.extend_from_slice(&c.to_le_bytes());
            }
        }
        for f in 0..m.offsets.len() - 1 {
            let face = &m.vertices[m.offsets[f] as usize..m.offsets[f + 1] as usize];
            expected.push(face.len() as u8);
            for v in face {
                expected.extend_from_slice(&v.to_le_bytes());
            }
        }
        let header_end = b"end_header\n";
        let body = out
            .windows(header_end.len())
            .position(|w| w == header_end)
            .unwrap()
            + header_end.len();
        assert!(out[body..] == expected[..], "normals: {with_normals}");
    }
}
