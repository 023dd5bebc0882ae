//! Writing PLY: ASCII or binary little-endian, texture coordinates per vertex, subd's tags as
//! extra elements and header comments (see the parent module).

use std::io::Write;

use super::*;

/// Whether `view`'s texture coordinates fit a PLY file: every vertex's corners carry the
/// same value (no UV seam), or there are none.
pub fn holds_texcoords(view: &MeshView<'_>) -> bool {
    per_vertex_uv(view).is_ok()
}

/// One texture coordinate per vertex, for a format that has no per-corner values: an
/// error naming the first vertex whose corners disagree (a UV seam). Vertices no face uses
/// get (0, 0).
fn per_vertex_uv(mesh: &MeshView<'_>) -> std::io::Result<Option<Vec<[f64; 2]>>> {
    let Some(uv) = mesh.uv() else {
        return Ok(None);
    };
    let mut out: Vec<Option<[f64; 2]>> = vec![None; mesh.num_vertices()];
    let mut seam = None;
    for_each_windowed(
        mesh.num_faces(),
        |r| mesh.face_window(r),
        |faces, f| {
            let first = faces.first_corner(f);
            for (k, &v) in faces.face(f).iter().enumerate() {
                let value = uv.uv(uv.indices()[first + k] as usize);
                match out[v as usize] {
                    None => out[v as usize] = Some(value),
                    Some(old) if old != value && seam.is_none() => seam = Some(v),
                    Some(_) => {}
                }
            }
        },
    )?;
    if let Some(v) = seam {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "PLY stores one texture coordinate per vertex, but vertex {v} has several (a UV seam); write .obj or .glb to keep them"
            ),
        ));
    }
    Ok(Some(
        out.into_iter().map(|x| x.unwrap_or([0.0; 2])).collect(),
    ))
}

/// Writes `mesh` as PLY: positions as `double`, faces as a `uchar`/`uint` count list of
/// `int` indices, and subd's tag elements when the mesh has tags. Records are encoded by
/// all threads and written in order.
pub fn write_ply(
    w: &mut dyn Write,
    mesh: &MeshView<'_>,
    encoding: PlyEncoding,
) -> std::io::Result<()> {
    let out = PlyOutput::of(mesh)?;
    write_header_start(w, &mesh.hints, encoding)?;
    out.declarations().write(w)?;
    match encoding {
        PlyEncoding::Ascii => out.write_ascii_body(w),
        PlyEncoding::BinaryLittleEndian => out.write_binary_body(w),
    }
}

/// Bytes per write of data that needs no encoding (as `dd bs=8M` writes).
const RAW_BLOCK: usize = 8 << 20;

/// What a PLY output holds besides positions and faces, and how it stores it.
struct PlyOutput<'a> {
    mesh: &'a MeshView<'a>,
    normals: Option<&'a [DVec3]>,
    /// One texture coordinate per vertex, when the mesh has them (and no seams).
    uv: Option<Vec<[f64; 2]>>,
    levels: Option<&'a [u8]>,
    creases: &'a [([u32; 2], f32)],
    corners: &'a [(u32, f32)],
    holes: Vec<usize>,
    /// Face sizes need a `uint` count (binary): a face has more than 255 vertices.
    wide_lists: bool,
}

impl<'a> PlyOutput<'a> {
    fn of(mesh: &'a MeshView<'a>) -> std::io::Result<PlyOutput<'a>> {
        let holes = mesh.hole_faces();
        let uv = per_vertex_uv(mesh)?;
        Ok(PlyOutput {
            mesh,
            normals: mesh.normals(),
            uv,
            levels: mesh.face_levels(),
            creases: mesh.creases(),
            corners: mesh.corners(),
            holes,
            wide_lists: mesh.max_face_size() > 255,
        })
    }

    /// What the header declares.
    fn declarations(&self) -> Declarations {
        Declarations {
            num_vertices: self.mesh.num_vertices() as u64,
            num_faces: self.mesh.num_faces() as u64,
            normals: self.normals.is_some(),
            uv: self.uv.is_some(),
            wide_lists: self.wide_lists,
            levels: self.levels.is_some(),
            creases: self.creases.len(),
            corners: self.corners.len(),
            holes: self.holes.len(),
        }
    }

    fn write_ascii_body(&self, w: &mut dyn Write) -> std::io::Result<()> {
        let mesh = self.mesh;
        let (normals, uv, levels) = (self.normals, &self.uv, self.levels);
        write_windows(
            w,
            mesh.num_vertices(),
            |r| mesh.point_window(r),
            |points, i, b| {
                push_f64s(b, &points.get(i).to_array());
                if let Some(n) = normals {
                    b.push(b' ');
                    push_f64s(b, &n[i].to_array());
                }
                if let Some(uv) = uv {
                    b.push(b' ');
                    push_f64s(b, &uv[i]);
                }
                b.push(b'\n');
            },
        )?;
        write_windows(
            w,
            mesh.num_faces(),
            |r| mesh.face_window(r),
            |faces, f, b| {
                let fv = faces.face(f);
                push_u64(b, fv.len() as u64);
                for &v in fv {
                    b.push(b' ');
                    push_u64(b, v.into());
                }
                if let Some(l) = levels {
                    b.push(b' ');
                    push_u64(b, l[f].into());
                }
                b.push(b'\n');
            },
        )?;
        for &([a, b], s) in self.creases {
            writeln!(w, "{a} {b} {s}")?;
        }
        for &(v, s) in self.corners {
            writeln!(w, "{v} {s}")?;
        }
        for &f in &self.holes {
            writeln!(w, "{f}")?;
        }
        Ok(())
    }

    /// Vertex records (position, normal, uv) encoded by all threads.
    fn write_binary_vertices(&self, w: &mut dyn Write) -> std::io::Result<()> {
        let (normals, uv) = (self.normals, &self.uv);
        write_windows(
            w,
            self.mesh.num_vertices(),
            |r| self.mesh.point_window(r),
            |points, i, b| {
                for c in points.get(i).to_array() {
                    b.extend_from_slice(&c.to_le_bytes());
                }
                if let Some(n) = normals {
                    for c in n[i].to_array() {
                        b.extend_from_slice(&c.to_le_bytes());
                    }
                }
                if let Some(uv) = uv {
                    for c in uv[i] {
                        b.extend_from_slice(&c.to_le_bytes());
                    }
                }
            },
        )
    }

    fn write_binary_body(&self, w: &mut dyn Write) -> std::io::Result<()> {
        let mesh = self.mesh;
        let (normals, uv, levels) = (self.normals, &self.uv, self.levels);
        // Held positions alone are their own little-endian records: no encoding at all.
        let raw = match (mesh.positions(), normals, uv) {
            (Some(points), None, None) if cfg!(target_endian = "little") => Some(points),
            _ => None,
        };
        if let Some(points) = raw {
            for block in bytemuck::cast_slice::<DVec3, u8>(points).chunks(RAW_BLOCK) {
                w.write_all(block)?;
            }
        } else {
            self.write_binary_vertices(w)?;
        }
        let wide_lists = self.wide_lists;
        write_windows(
            w,
            mesh.num_faces(),
            |r| mesh.face_window(r),
            |faces, f, b| {
                let fv = faces.face(f);
                if wide_lists {
                    b.extend_from_slice(&(fv.len() as u32).to_le_bytes());
                } else {
                    b.push(fv.len() as u8);
                }
                for &v in fv {
                    b.extend_from_slice(&v.to_le_bytes());
                }
                if let Some(l) = levels {
                    b.push(l[f]);
                }
            },
        )?;
        // The tag elements are few: encoded in one buffer, written at once.
        let mut buf: Vec<u8> = Vec::new();
        for &([a, b], s) in self.creases {
            buf.extend_from_slice(&a.to_le_bytes());
            buf.extend_from_slice(&b.to_le_bytes());
            buf.extend_from_slice(&s.to_le_bytes());
        }
        for &(v, s) in self.corners {
            buf.extend_from_slice(&v.to_le_bytes());
            buf.extend_from_slice(&s.to_le_bytes());
        }
        for &f in &self.holes {
            buf.extend_from_slice(&(f as u32).to_le_bytes());
        }
        w.write_all(&buf)
    }
}

/// The header up to the elements: magic, format, and the comments that carry the mesh's
/// scheme hints.
pub(super) fn write_header_start(
    w: &mut dyn Write,
    hints: &SchemeHints,
    encoding: PlyEncoding,
) -> std::io::Result<()> {
    writeln!(w, "ply")?;
    writeln!(
        w,
        "format {} 1.0",
        match encoding {
            PlyEncoding::Ascii => "ascii",
            PlyEncoding::BinaryLittleEndian => "binary_little_endian",
        }
    )?;
    writeln!(w, "comment written by subd {}", env!("CARGO_PKG_VERSION"))?;
    if let Some(b) = hints.boundary_interpolation {
        writeln!(w, "comment subd interpolateboundary {}", b.to_shape_tag())?;
    }
    if let Some(c) = hints.crease_method {
        let s = if c == CreaseMethod::Chaikin {
            "chaikin"
        } else {
            "normal"
        };
        writeln!(w, "comment subd creasemethod {s}")?;
    }
    if let Some(m) = hints.fvar_interpolation {
        writeln!(
            w,
            "comment subd facevaryinginterpolateboundary {}",
            m.to_shape_tag()
        )?;
    }
    if let Some(t) = hints.triangle_subdivision {
        let s = if t == TriangleSubdivision::Smooth {
            "smooth"
        } else {
            "catmark"
        };
        writeln!(w, "comment subd smoothtriangles {s}")?;
    }
    Ok(())
}

/// `int` vertex indices, or `uint` past `i32`.
fn index_type(num_vertices: u64) -> &'static str {
    if num_vertices > i32::MAX as u64 {
        "uint"
    } else {
        "int"
    }
}

/// The elements a PLY header declares, from `element vertex` to `end_header`.
pub(super) struct Declarations {
    pub(super) num_vertices: u64,
    pub(super) num_faces: u64,
    pub(super) normals: bool,
    pub(super) uv: bool,
    /// Face sizes as `uint` (binary): a face has more than 255 vertices.
    pub(super) wide_lists: bool,
    pub(super) levels: bool,
    pub(super) creases: usize,
    pub(super) corners: usize,
    pub(super) holes: usize,
}

impl Declarations {
    pub(super) fn write(&self, w: &mut dyn Write) -> std::io::Result<()> {
        let index_ty = index_type(self.num_vertices);
        writeln!(w, "element vertex {}", self.num_vertices)?;
        for c in ["x", "y", "z"] {
            writeln!(w, "property double {c}")?;
        }
        if self.normals {
            for c in ["nx", "ny", "nz"] {
                writeln!(w, "property double {c}")?;
            }
        }
        if self.uv {
            writeln!(w, "property double u\nproperty double v")?;
        }
        writeln!(w, "element face {}", self.num_faces)?;
        writeln!(
            w,
            "property list {} {index_ty} vertex_indices",
            if self.wide_lists { "uint" } else { "uchar" }
        )?;
        if self.levels {
            writeln!(w, "property uchar level")?;
        }
        if self.creases > 0 {
            writeln!(w, "element crease {}", self.creases)?;
            writeln!(
                w,
                "property {index_ty} v0\nproperty {index_ty} v1\nproperty float sharpness"
            )?;
        }
        if self.corners > 0 {
            writeln!(w, "element corner {}", self.corners)?;
            writeln!(w, "property {index_ty} vertex\nproperty float sharpness")?;
        }
        if self.holes > 0 {
            writeln!(w, "element hole {}", self.holes)?;
            writeln!(w, "property int face")?;
        }
        writeln!(w, "end_header")
    }
}
