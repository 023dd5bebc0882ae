//! PLY (Stanford polygon format): ASCII, binary little-endian and binary big-endian in,
//! ASCII and binary little-endian out.
//!
//! The `vertex` element must have `x`, `y`, `z`; faces come from the list property
//! `vertex_indices` (or `vertex_index`) of the `face` element; other elements and properties
//! are skipped. subd also writes (and reads back) its tags as extra elements that other
//! readers ignore: `crease` (`v0`, `v1`, `sharpness`), `corner` (`vertex`, `sharpness`),
//! `hole` (`face`), and scheme options as `comment subd <tag> <value>` header lines.
//! Texture coordinates are the vertex properties `u v` (or `s t`, `texture_u texture_v`):
//! one per vertex, so a channel with seams cannot be written (the error says so).
//!
//! Written by hand rather than with a PLY crate: the available crates are unmaintained or
//! allocate per element, and a reader here must name the header line or the element of
//! every error, reject absurd counts without allocating them, and be fuzzed as part of subd.

use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};
use subd_mesh::{
    BoundaryInterpolation, CreaseMethod, DVec3, Mesh, SchemeHints, TopologyBuilder,
    TriangleSubdivision,
};

use crate::error::ReadError;
use crate::records::{for_each_windowed, write_windows};
use crate::text::{push_f64s, push_u64};
use crate::view::MeshView;
use crate::{MeshFile, ReadOptions};

mod binary;
pub(crate) mod placed;
mod write;

pub use placed::PlacedPly;
pub use write::{holds_texcoords, write_ply};

/// PLY encoding to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PlyEncoding {
    /// Human-readable text.
    Ascii,
    /// Binary little-endian (compact, exact).
    #[default]
    BinaryLittleEndian,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Scalar> {
        Some(match s {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

#[derive(Debug, Clone)]
enum Property {
    Scalar(String, Scalar),
    List(String, Scalar, Scalar),
}

impl Property {
    fn name(&self) -> &str {
        match self {
            Property::Scalar(n, _) | Property::List(n, _, _) => n,
        }
    }
}

#[derive(Debug, Clone)]
struct Element {
    name: String,
    count: usize,
    props: Vec<Property>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Encoding {
    Ascii,
    Le,
    Be,
}

/// Reads values of an element body, either from ASCII tokens or from binary bytes.
enum Body<'a> {
    Ascii {
        text: &'a str,
        pos: usize,
        line: usize,
    },
    Binary {
        data: &'a [u8],
        pos: usize,
        big_endian: bool,
    },
}

impl Body<'_> {
    fn line(&self) -> Option<usize> {
        match self {
            Body::Ascii { line, .. } => Some(*line),
            Body::Binary { .. } => None,
        }
    }

    fn remaining_bytes(&self) -> usize {
        match self {
            Body::Ascii { text, pos, .. } => text.len() - pos,
            Body::Binary { data, pos, .. } => data.len() - pos,
        }
    }

    fn read(&mut self, ty: Scalar, what: &dyn Fn() -> String) -> Result<f64, ReadError> {
        match self {
            Body::Ascii { text, pos, line } => {
                let bytes = text.as_bytes();
                while *pos < bytes.len() && bytes[*pos].is_ascii_whitespace() {
                    if bytes[*pos] == b'\n' {
                        *line += 1;
                    }
                    *pos += 1;
                }
                let start = *pos;
                while *pos < bytes.len() && !bytes[*pos].is_ascii_whitespace() {
                    *pos += 1;
                }
                if start == *pos {
                    return Err(ReadError::line(
                        *line,
                        format!("file ends inside {}", what()),
                    ));
                }
                let tok = &text[start..*pos];
                let v: f64 = tok.parse().map_err(|_| {
                    ReadError::line(*line, format!("{}: {tok:?} is not a number", what()))
                })?;
                if !matches!(ty, Scalar::F32 | Scalar::F64) && v.fract() != 0.0 {
                    return Err(ReadError::line(
                        *line,
                        format!("{}: {tok:?} is not an integer", what()),
                    ));
                }
                Ok(v)
            }
            Body::Binary {
                data,
                pos,
                big_endian,
            } => {
                let n = ty.size();
                if data.len() - *pos < n {
                    return Err(ReadError::general(format!(
                        "binary data ends inside {}",
                        what()
                    )));
                }
                let v = scalar_value(&data[*pos..*pos + n], ty, *big_endian);
                *pos += n;
                Ok(v)
            }
        }
    }
}

/// The value of a binary scalar of type `ty` at the start of `bytes` (which holds at
/// least `ty.size()` of them).
#[inline]
fn scalar_value(bytes: &[u8], ty: Scalar, big_endian: bool) -> f64 {
    let n = ty.size();
    let mut b = [0u8; 8];
    b[..n].copy_from_slice(&bytes[..n]);
    if big_endian {
        b[..n].reverse();
    }
    match ty {
        Scalar::I8 => b[0] as i8 as f64,
        Scalar::U8 => b[0] as f64,
        Scalar::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
        Scalar::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
        Scalar::I32 => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        Scalar::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        Scalar::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        Scalar::F64 => f64::from_le_bytes(b),
    }
}

fn err_at(body: &Body, msg: String) -> ReadError {
    match body.line() {
        Some(l) => ReadError::line(l, msg),
        None => ReadError::general(msg),
    }
}

struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    hints: SchemeHints,
    body_offset: usize,
    body_line: usize,
}

fn parse_header(bytes: &[u8]) -> Result<Header, ReadError> {
    if !bytes.starts_with(b"ply") {
        return Err(ReadError::line(
            1,
            "not a PLY file (it must start with \"ply\")",
        ));
    }
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut hints = SchemeHints::default();
    let mut pos = 0usize;
    let mut line = 0usize;
    loop {
        if pos >= bytes.len() {
            return Err(ReadError::line(
                line.max(1),
                "header has no end_header line",
            ));
        }
        let end = bytes[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |i| pos + i);
        line += 1;
        let text = std::str::from_utf8(&bytes[pos..end])
            .map_err(|_| ReadError::line(line, "header line is not text"))?;
        let text = text.strip_suffix('\r').unwrap_or(text);
        pos = (end + 1).min(bytes.len());
        let words: Vec<&str> = text.split_ascii_whitespace().collect();
        match words.as_slice() {
            ["ply"] if line == 1 => {}
            ["format", f, _version] => {
                encoding = Some(match *f {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::Le,
                    "binary_big_endian" => Encoding::Be,
                    _ => return Err(ReadError::line(line, format!("unknown PLY format {f:?}"))),
                });
            }
            ["comment", "subd", rest @ ..] => parse_hint(line, rest, &mut hints)?,
            ["comment", ..] | ["obj_info", ..] | [] => {}
            ["element", name, count] => {
                let count: usize = count.parse().map_err(|_| {
                    ReadError::line(line, format!("element count {count:?} is not a number"))
                })?;
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    props: Vec::new(),
                });
            }
            ["property", "list", c, i, name] => {
                let el = elements
                    .last_mut()
                    .ok_or_else(|| ReadError::line(line, "property before any element"))?;
                let (Some(c), Some(i)) = (Scalar::parse(c), Scalar::parse(i)) else {
                    return Err(ReadError::line(line, "unknown property type in list"));
                };
                if matches!(c, Scalar::F32 | Scalar::F64) {
                    return Err(ReadError::line(
                        line,
                        "list count type must be an integer type",
                    ));
                }
                el.props.push(Property::List(name.to_string(), c, i));
            }
            ["property", ty, name] => {
                let el = elements
                    .last_mut()
                    .ok_or_else(|| ReadError::line(line, "property before any element"))?;
                let ty = Scalar::parse(ty).ok_or_else(|| {
                    ReadError::line(line, format!("unknown property type {ty:?}"))
                })?;
                el.props.push(Property::Scalar(name.to_string(), ty));
            }
            ["end_header"] => break,
            _ => {
                return Err(ReadError::line(
                    line,
                    format!("unrecognised header line {text:?}"),
                ));
            }
        }
    }
    let encoding = encoding.ok_or_else(|| ReadError::line(line, "header has no format line"))?;
    Ok(Header {
        encoding,
        elements,
        hints,
        body_offset: pos,
        body_line: line + 1,
    })
}

fn parse_hint(line: usize, words: &[&str], hints: &mut SchemeHints) -> Result<(), ReadError> {
    let bad = || {
        ReadError::line(
            line,
            format!("unrecognised subd comment {:?}", words.join(" ")),
        )
    };
    match words {
        ["interpolateboundary", k] => {
            let k: i64 = k.parse().map_err(|_| bad())?;
            hints.boundary_interpolation =
                Some(BoundaryInterpolation::from_shape_tag(k).ok_or_else(bad)?);
        }
        ["facevaryinginterpolateboundary", k] => {
            let k: i64 = k.parse().map_err(|_| bad())?;
            hints.fvar_interpolation =
                Some(FVarLinearInterpolation::from_shape_tag(k).ok_or_else(bad)?);
        }
        ["creasemethod", "normal"] => hints.crease_method = Some(CreaseMethod::Uniform),
        ["creasemethod", "chaikin"] => hints.crease_method = Some(CreaseMethod::Chaikin),
        ["smoothtriangles", "catmark"] => {
            hints.triangle_subdivision = Some(TriangleSubdivision::Catmark)
        }
        ["smoothtriangles", "smooth"] => {
            hints.triangle_subdivision = Some(TriangleSubdivision::Smooth)
        }
        _ => return Err(bad()),
    }
    Ok(())
}

/// Parses a PLY file. ASCII errors carry the line; binary errors name the element.
pub fn parse_ply(bytes: &[u8], options: &ReadOptions) -> Result<MeshFile, ReadError> {
    parse_ply_with(
        bytes,
        options,
        BinaryReading::Parallel(binary::VERTICES_PER_TASK),
    )
}

/// How binary vertex and face elements are read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum BinaryReading {
    /// By the fast decoders ([`binary`]), vertices in parallel tasks of this many.
    Parallel(usize),
    /// By the per-value reader alone: what the fast decoders must agree with (the fuzz
    /// target and the tests hold them to that).
    #[cfg_attr(not(any(test, feature = "fuzzing")), allow(dead_code))]
    PerValue,
}

/// [`parse_ply`] with binary elements read as `reading` says.
pub(crate) fn parse_ply_with(
    bytes: &[u8],
    options: &ReadOptions,
    reading: BinaryReading,
) -> Result<MeshFile, ReadError> {
    let header = parse_header(bytes)?;
    let data = &bytes[header.body_offset..];
    let mut body = match header.encoding {
        Encoding::Ascii => Body::Ascii {
            text: std::str::from_utf8(data)
                .map_err(|_| ReadError::line(header.body_line, "ASCII PLY body is not text"))?,
            pos: 0,
            line: header.body_line,
        },
        Encoding::Le | Encoding::Be => Body::Binary {
            data,
            pos: 0,
            big_endian: header.encoding == Encoding::Be,
        },
    };
    let d = read_elements(&header, &mut body, reading)?;
    check_faces(&d)?;
    let nv = d.positions.len();
    let (mut topology, build_warnings) = TopologyBuilder::new(nv)
        .accept_inconsistent_orientation(options.accept_inconsistent_orientation)
        .build_with_warnings(&d.face_sizes, &d.face_vertices)?;
    let orientation_conflicts = build_warnings
        .iter()
        .filter(|w| matches!(w, subd_mesh::BuildWarning::InconsistentOrientation { .. }))
        .count();
    let mut warnings: Vec<String> = build_warnings.iter().map(|w| w.to_string()).collect();
    apply_tags(&d, &mut topology, &mut warnings)?;
    let uv = match d.texcoords {
        // One value per vertex: the corners name their vertex's value.
        Some(texcoords) => Some(
            FVarChannel::new(&topology, 2, texcoords, d.face_vertices)
                .map_err(|e| ReadError::general(format!("texture coordinates: {e}")))?,
        ),
        None => None,
    };
    let mut mesh = Mesh::new(topology, d.positions)?;
    mesh.hints = header.hints;
    mesh = crate::with_texcoords(mesh, uv)?;
    let face_levels = d.face_levels;
    Ok(MeshFile {
        mesh,
        warnings,
        extra_tags: Vec::new(),
        orientation_conflicts,
        face_levels: (!face_levels.is_empty()).then_some(face_levels),
        stage: None,
    })
}

/// What the elements of a PLY body give, before any checking across elements.
struct PlyData {
    positions: Vec<DVec3>,
    /// `u v` per vertex, when the vertex element has them.
    texcoords: Option<Vec<f64>>,
    face_sizes: Vec<u32>,
    face_vertices: Vec<u32>,
    face_levels: Vec<u8>,
    /// Tag elements as read (indices still numbers) with their text line, if any.
    creases: Vec<(f64, f64, f64, Option<usize>)>,
    corners: Vec<(f64, f64, Option<usize>)>,
    holes: Vec<(f64, Option<usize>)>,
    have_vertex: bool,
    have_face: bool,
}

/// Reads every element instance of the body (see the module docs for the roles).
fn read_elements(
    header: &Header,
    body: &mut Body<'_>,
    reading: BinaryReading,
) -> Result<PlyData, ReadError> {
    let mut r = ElementReader {
        d: PlyData {
            positions: Vec::new(),
            texcoords: None,
            face_sizes: Vec::new(),
            face_vertices: Vec::new(),
            face_levels: Vec::new(),
            creases: Vec::new(),
            corners: Vec::new(),
            holes: Vec::new(),
            have_vertex: false,
            have_face: false,
        },
        texcoords: Vec::new(),
        uv_props: None,
        values: Vec::new(),
        list: Vec::new(),
    };
    for el in &header.elements {
        let role = r.role_of(el)?;
        check_instance_count(el, body)?;
        match role {
            Some(Role::Vertex(_)) => r.d.positions.reserve(el.count),
            Some(Role::Face { .. }) => r.d.face_sizes.reserve(el.count),
            _ => {}
        }
        if let BinaryReading::Parallel(vertices_per_task) = reading
            && binary::read_element(&mut r, el, role, body, vertices_per_task)
        {
            continue;
        }
        for k in 0..el.count {
            r.read_values(el, k, role, body)?;
            r.keep_instance(k, role, body)?;
        }
    }
    let mut d = r.d;
    d.texcoords = r.uv_props.map(|_| r.texcoords);
    Ok(d)
}

/// What an element's instances give, with the positions of the properties that give it.
#[derive(Debug, Clone, Copy)]
enum Role {
    /// x, y, z.
    Vertex([usize; 3]),
    /// The vertex index list, and `level` (as `subd adaptive` writes it; `usize::MAX`:
    /// absent).
    Face { list: usize, level: usize },
    /// v0, v1, sharpness.
    Crease([usize; 3]),
    /// vertex, sharpness.
    Corner([usize; 2]),
    /// face.
    Hole(usize),
}

/// The state of [`read_elements`]: the data so far, the vertex texture coordinates, and the
/// values of the instance being read (reused, never allocated per instance).
struct ElementReader {
    d: PlyData,
    texcoords: Vec<f64>,
    /// The `u v` properties of the vertex element, when it has them.
    uv_props: Option<[usize; 2]>,
    /// The instance's values, one per property (NaN for a list).
    values: Vec<f64>,
    /// The face's vertex indices.
    list: Vec<f64>,
}

impl ElementReader {
    /// The role of `el`; an element of another name, or one lacking a property its name
    /// needs, has none (but vertex and face elements must have theirs).
    fn role_of(&mut self, el: &Element) -> Result<Option<Role>, ReadError> {
        let find = |n: &str| el.props.iter().position(|p| p.name() == n);
        Ok(match el.name.as_str() {
            "vertex" => {
                self.d.have_vertex = true;
                let (Some(x), Some(y), Some(z)) = (find("x"), find("y"), find("z")) else {
                    return Err(ReadError::general(
                        "vertex element lacks an x, y or z property",
                    ));
                };
                self.uv_props = texcoord_properties(&el.props);
                Some(Role::Vertex([x, y, z]))
            }
            "face" => {
                self.d.have_face = true;
                let Some(i) = find("vertex_indices").or_else(|| find("vertex_index")) else {
                    return Err(ReadError::general(
                        "face element has no vertex_indices list",
                    ));
                };
                if !matches!(el.props[i], Property::List(..)) {
                    return Err(ReadError::general(
                        "face vertex_indices is not a list property",
                    ));
                }
                let level = find("level").unwrap_or(usize::MAX);
                Some(Role::Face { list: i, level })
            }
            "crease" => match (find("v0"), find("v1"), find("sharpness")) {
                (Some(a), Some(b), Some(s)) => Some(Role::Crease([a, b, s])),
                _ => None,
            },
            "corner" => match (find("vertex"), find("sharpness")) {
                (Some(a), Some(s)) => Some(Role::Corner([a, s])),
                _ => None,
            },
            "hole" => find("face").map(Role::Hole),
            _ => None,
        })
    }

    /// Reads instance `k` of `el` into `values` (and a face's index list into `list`; other
    /// lists are read past).
    fn read_values(
        &mut self,
        el: &Element,
        k: usize,
        role: Option<Role>,
        body: &mut Body<'_>,
    ) -> Result<(), ReadError> {
        self.values.clear();
        self.list.clear();
        for (pi, prop) in el.props.iter().enumerate() {
            let what = || format!("{} {k} property {}", el.name, prop.name());
            match prop {
                Property::Scalar(_, ty) => self.values.push(body.read(*ty, &what)?),
                Property::List(_, cty, ity) => {
                    let n = body.read(*cty, &what)?;
                    if n < 0.0 {
                        return Err(err_at(body, format!("{}: negative list length", what())));
                    }
                    let n = n as usize;
                    if n > body.remaining_bytes() {
                        return Err(err_at(
                            body,
                            format!("{}: list length {n} exceeds the file", what()),
                        ));
                    }
                    let keep = matches!(role, Some(Role::Face { list, .. }) if list == pi);
                    for _ in 0..n {
                        let v = body.read(*ity, &what)?;
                        if keep {
                            self.list.push(v);
                        }
                    }
                    self.values.push(f64::NAN);
                }
            }
        }
        Ok(())
    }

    /// Keeps what instance `k`, just read, gives in its role.
    fn keep_instance(
        &mut self,
        k: usize,
        role: Option<Role>,
        body: &Body<'_>,
    ) -> Result<(), ReadError> {
        // The line of the instance's last value: where a text instance lives.
        let line = body.line();
        let values = &self.values;
        match role {
            Some(Role::Vertex(xyz)) => self.keep_vertex(k, xyz, body)?,
            Some(Role::Face { level, .. }) => self.keep_face(k, level, body)?,
            Some(Role::Crease([a, b, s])) => {
                self.d.creases.push((values[a], values[b], values[s], line))
            }
            Some(Role::Corner([a, s])) => self.d.corners.push((values[a], values[s], line)),
            Some(Role::Hole(a)) => self.d.holes.push((values[a], line)),
            None => {}
        }
        Ok(())
    }

    /// Keeps vertex `k`'s position and texture coordinates, which must be finite.
    fn keep_vertex(
        &mut self,
        k: usize,
        [x, y, z]: [usize; 3],
        body: &Body<'_>,
    ) -> Result<(), ReadError> {
        let values = &self.values;
        let p = DVec3::new(values[x], values[y], values[z]);
        if !p.is_finite() {
            return Err(err_at(
                body,
                format!("vertex {k} has a non-finite coordinate"),
            ));
        }
        self.d.positions.push(p);
        if let Some([u, v]) = self.uv_props {
            if !(values[u].is_finite() && values[v].is_finite()) {
                return Err(err_at(
                    body,
                    format!("vertex {k} has a non-finite texture coordinate"),
                ));
            }
            self.texcoords.extend([values[u], values[v]]);
        }
        Ok(())
    }

    /// Keeps face `k`'s level (when `level` is a property) and its vertex indices, which
    /// must be at least 3 valid `u32` indices.
    fn keep_face(&mut self, k: usize, level: usize, body: &Body<'_>) -> Result<(), ReadError> {
        if level != usize::MAX {
            let l = self.values[level];
            if !(0.0..=255.0).contains(&l) || l.fract() != 0.0 {
                return Err(err_at(body, format!("face {k} has invalid level {l}")));
            }
            self.d.face_levels.push(l as u8);
        }
        let list = &self.list;
        if list.len() < 3 {
            return Err(err_at(
                body,
                format!(
                    "face {k} has {} vertices; a face needs at least 3",
                    list.len()
                ),
            ));
        }
        for &v in list {
            if v < 0.0 || v.fract() != 0.0 || v >= u32::MAX as f64 {
                return Err(err_at(
                    body,
                    format!("face {k} has invalid vertex index {v}"),
                ));
            }
            self.d.face_vertices.push(v as u32);
        }
        self.d.face_sizes.push(list.len() as u32);
        Ok(())
    }
}

/// Refuses instance counts a body cannot hold. An instance with at least one property takes
/// at least one byte, so a count beyond the remaining bytes is malformed. Checking it up
/// front keeps a forged header from driving allocation or a long loop (found by fuzzing:
/// `element crease 01569664312` with no properties spun for billions of empty iterations).
fn check_instance_count(el: &Element, body: &Body<'_>) -> Result<(), ReadError> {
    if el.count > 0 && el.props.is_empty() {
        return Err(ReadError::general(format!(
            "element {} declares {} instances but has no properties",
            el.name, el.count
        )));
    }
    if el.count > body.remaining_bytes() {
        return Err(ReadError::general(format!(
            "element {} declares {} instances but only {} bytes of data remain",
            el.name,
            el.count,
            body.remaining_bytes()
        )));
    }
    Ok(())
}

/// Checks that there are faces and that every face names an existing vertex.
fn check_faces(d: &PlyData) -> Result<(), ReadError> {
    if !d.have_vertex || !d.have_face || d.face_sizes.is_empty() {
        return Err(ReadError::general(
            "PLY file has no faces (needs vertex and face elements)",
        ));
    }
    let nv = d.positions.len();
    let mut offset = 0;
    for (f, &n) in d.face_sizes.iter().enumerate() {
        for &v in &d.face_vertices[offset..offset + n as usize] {
            if v as usize >= nv {
                return Err(ReadError::general(format!(
                    "face {f} refers to vertex {v}, but there are only {nv} vertices"
                )));
            }
        }
        offset += n as usize;
    }
    Ok(())
}

/// Applies the crease, corner and hole elements to `topology`.
fn apply_tags(
    d: &PlyData,
    topology: &mut subd_mesh::Topology,
    warnings: &mut Vec<String>,
) -> Result<(), ReadError> {
    let nv = d.positions.len();
    let at = |line: Option<usize>, e: subd_mesh::TopologyError| match line {
        Some(l) => ReadError::line(l, e.to_string()),
        None => ReadError::Topology(e),
    };
    let index =
        |x: f64, tag: &'static str, what: &'static str, count: usize, line: Option<usize>| {
            if x >= 0.0 && x.fract() == 0.0 {
                Ok(x as u64)
            } else {
                Err(at(
                    line,
                    subd_mesh::TopologyError::TagIndexOutOfRange {
                        tag,
                        what,
                        index: x.max(0.0) as u64,
                        count,
                    },
                ))
            }
        };
    for &(a, b, s, line) in &d.creases {
        let (a, b) = (
            index(a, "crease", "vertex", nv, line)?,
            index(b, "crease", "vertex", nv, line)?,
        );
        if topology
            .set_crease(a, b, s)
            .map_err(|e| at(line, e))?
            .is_none()
        {
            warnings.push(format!(
                "crease names edge ({a}, {b}), which is not an edge of the mesh; ignored"
            ));
        }
    }
    for &(v, s, line) in &d.corners {
        let v = index(v, "corner", "vertex", nv, line)?;
        topology.set_corner(v, s).map_err(|e| at(line, e))?;
    }
    let nf = d.face_sizes.len();
    for &(f, line) in &d.holes {
        let f = index(f, "hole", "face", nf, line)?;
        topology.set_hole_checked(f).map_err(|e| at(line, e))?;
    }
    Ok(())
}

/// The vertex properties holding texture coordinates: `u v`, `s t` or `texture_u
/// texture_v` (the names exporters use), scalars both.
fn texcoord_properties(props: &[Property]) -> Option<[usize; 2]> {
    let find = |n: &str| {
        props
            .iter()
            .position(|p| p.name() == n && matches!(p, Property::Scalar(..)))
    };
    [("u", "v"), ("s", "t"), ("texture_u", "texture_v")]
        .iter()
        .find_map(|&(a, b)| Some([find(a)?, find(b)?]))
}
