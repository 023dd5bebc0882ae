//! A [`MeshView`] as a layer with one `Mesh` prim, encoded as `.usda`, `.usdc` or `.usdz`.

use std::borrow::Cow;
use std::io::{self, Cursor, Write};

use openusd::sdf::{self, ChildrenKey, FieldKey, SpecType, Specifier, Value, Variability};
use openusd::{gf, usda, usdc, usdz};
use rayon::prelude::*;
use subd_mesh::{BoundaryInterpolation, DVec3, FileScheme};

use super::StageInfo;
use super::read::{
    BOUNDARIES, CREASE_METHOD_ATTR, CREASE_METHODS, FVAR_MODES, SCHEMES, TRIANGLE_RULES,
};
use super::values::token;
use crate::view::MeshView;
use crate::{Format, WriteOptions};

/// Writes `view` in `format` (`Usda`, `Usdc` or `Usdz`).
pub(crate) fn write_usd(
    w: &mut dyn Write,
    view: &MeshView<'_>,
    format: Format,
    options: &WriteOptions,
) -> io::Result<()> {
    let stage = options.stage.clone().unwrap_or_default();
    let name = prim_name(&stage.prim);
    let data = mesh_layer(view, &name, &stage)?;
    // The arrays' raw size (points, normals, counts, indices, st and its indices): the crate
    // file is rarely larger, so its buffer is allocated once.
    let raw = 24 * view.num_vertices() + 4 * view.num_faces() + 16 * view.num_face_vertices();
    match format {
        Format::Usda => usda::TextWriter::write(&data, &mut &mut *w).map_err(io::Error::other),
        Format::Usdc => w.write_all(&crate_bytes(&data, raw)?),
        Format::Usdz => {
            let mut archive = usdz::ArchiveWriter::new(Cursor::new(Vec::new()));
            archive
                .add_layer(&format!("{name}.usdc"), &crate_bytes(&data, raw)?)
                .map_err(io::Error::other)?;
            let bytes = archive.finish().map_err(io::Error::other)?.into_inner();
            w.write_all(&bytes)
        }
        _ => Err(io::Error::other("not a USD format")),
    }
}

fn crate_bytes(data: &sdf::Data, capacity: usize) -> io::Result<Vec<u8>> {
    let mut out = Cursor::new(Vec::with_capacity(capacity));
    usdc::CrateWriter::write(data, &mut out).map_err(io::Error::other)?;
    Ok(out.into_inner())
}

/// The prim's name: the last part of the path it was read from, made a USD identifier
/// (letters, digits, `_`, not starting with a digit), or `mesh`.
fn prim_name(path: &str) -> String {
    let last = path.rsplit('/').next().unwrap_or_default();
    let mut name: String = last
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    if name.is_empty() {
        name = "mesh".into();
    } else if name.starts_with(|c: char| c.is_ascii_digit()) {
        name.insert(0, '_');
    }
    name
}

/// One attribute to write: name, USD type, value, uniform or varying, interpolation.
struct Attr {
    name: String,
    type_name: &'static str,
    value: Value,
    uniform: bool,
    custom: bool,
    interpolation: Option<&'static str>,
}

impl Attr {
    fn new(name: &str, type_name: &'static str, value: Value) -> Attr {
        Attr {
            name: name.to_string(),
            type_name,
            value,
            uniform: false,
            custom: false,
            interpolation: None,
        }
    }

    fn uniform(mut self) -> Attr {
        self.uniform = true;
        self
    }
}

/// The layer: a root with the stage's metadata and `defaultPrim`, and the mesh prim.
fn mesh_layer(view: &MeshView<'_>, name: &str, stage: &StageInfo) -> io::Result<sdf::Data> {
    let attrs = mesh_attributes(view)?;
    let mut data = sdf::Data::new();
    let root = data.create_spec(sdf::Path::abs_root(), SpecType::PseudoRoot);
    root.add(
        ChildrenKey::PrimChildren,
        Value::TokenVec(vec![name.into()]),
    );
    root.add(FieldKey::DefaultPrim, token(name));
    if let Some(m) = stage.meters_per_unit {
        root.add("metersPerUnit", Value::Double(m));
    }
    if let Some(axis) = &stage.up_axis {
        root.add("upAxis", token(axis));
    }
    let prim_path = path(&format!("/{name}"))?;
    let prim = data.create_spec(prim_path, SpecType::Prim);
    prim.add(FieldKey::Specifier, Value::Specifier(Specifier::Def));
    prim.add(FieldKey::TypeName, token("Mesh"));
    let names = attrs.iter().map(|a| a.name.as_str().into()).collect();
    prim.add(ChildrenKey::PropertyChildren, Value::TokenVec(names));
    for a in attrs {
        let spec = data.create_spec(path(&format!("/{name}.{}", a.name))?, SpecType::Attribute);
        spec.add(FieldKey::TypeName, token(a.type_name));
        if a.uniform {
            spec.add(
                FieldKey::Variability,
                Value::Variability(Variability::Uniform),
            );
        }
        if a.custom {
            spec.add(FieldKey::Custom, Value::Bool(true));
        }
        if let Some(i) = a.interpolation {
            spec.add("interpolation", token(i));
        }
        spec.add(FieldKey::Default, a.value);
    }
    Ok(data)
}

fn path(p: &str) -> io::Result<sdf::Path> {
    sdf::Path::new(p).map_err(|e| io::Error::other(format!("prim path {p}: {e}")))
}

/// Every attribute of the mesh prim, sorted by name as USD lists them.
fn mesh_attributes(view: &MeshView<'_>) -> io::Result<Vec<Attr>> {
    let points = all_points(view)?;
    let (counts, indices) = all_faces(view)?;
    let mut attrs = vec![
        Attr::new("faceVertexCounts", "int[]", Value::IntVec(counts)),
        Attr::new("faceVertexIndices", "int[]", Value::IntVec(indices)),
        Attr::new("extent", "float3[]", Value::Vec3fVec(extent(&points))),
        Attr::new("points", "point3f[]", Value::Vec3fVec(vec3f(&points))),
    ];
    attrs.extend(rule_attributes(view));
    attrs.extend(tag_attributes(view)?);
    if let Some(normals) = view.normals() {
        let mut a = Attr::new("normals", "normal3f[]", Value::Vec3fVec(vec3f(normals)));
        a.interpolation = Some("vertex");
        attrs.push(a);
    }
    if let Some(uv) = view.uv() {
        let single = |x: f64| x.abs() <= f64::from(f32::MAX);
        if let Some(i) = (0..uv.len()).find(|&i| !uv.uv(i).into_iter().all(single)) {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!("texture coordinate {i} is beyond single precision, which USD's st holds"),
            ));
        }
        let values = (0..uv.len())
            .map(|i| {
                let [u, v] = uv.uv(i);
                gf::Vec2f {
                    x: u as f32,
                    y: v as f32,
                }
            })
            .collect();
        let mut st = Attr::new("primvars:st", "texCoord2f[]", Value::Vec2fVec(values));
        st.interpolation = Some("faceVarying");
        attrs.push(st);
        attrs.push(Attr::new(
            "primvars:st:indices",
            "int[]",
            Value::IntVec(to_ints(uv.indices())?),
        ));
    }
    attrs.sort_by(|a, b| a.name.cmp(&b.name));
    Ok(attrs)
}

/// The scheme and its rules. A view without a scheme is a refined (or limit) mesh: plain
/// polygons, `none`. Unset rules are written as subd reads them unset (edge-only
/// boundaries, not USD's `edgeAndCorner` fallback), so the file means the same to both.
fn rule_attributes(view: &MeshView<'_>) -> Vec<Attr> {
    let h = &view.hints;
    let scheme = h.scheme.unwrap_or(FileScheme::Polygons);
    let mut attrs = vec![
        Attr::new(
            "subdivisionScheme",
            "token",
            token(name_of(&SCHEMES, scheme)),
        )
        .uniform(),
        Attr::new(
            "interpolateBoundary",
            "token",
            token(name_of(
                &BOUNDARIES,
                h.boundary_interpolation
                    .unwrap_or(BoundaryInterpolation::EdgeOnly),
            )),
        ),
    ];
    if let Some(m) = h.fvar_interpolation {
        attrs.push(Attr::new(
            "faceVaryingLinearInterpolation",
            "token",
            token(name_of(&FVAR_MODES, m)),
        ));
    }
    if let Some(t) = h.triangle_subdivision {
        attrs.push(Attr::new(
            "triangleSubdivisionRule",
            "token",
            token(name_of(&TRIANGLE_RULES, t)),
        ));
    }
    if let Some(c) = h.crease_method {
        let mut a = Attr::new(
            CREASE_METHOD_ATTR,
            "token",
            token(name_of(&CREASE_METHODS, c)),
        );
        a.custom = true;
        attrs.push(a.uniform());
    }
    attrs
}

/// The token `table` gives `x`.
fn name_of<T: PartialEq>(table: &[(&'static str, T)], x: T) -> &'static str {
    table
        .iter()
        .find(|(_, t)| *t == x)
        .map(|(n, _)| *n)
        .unwrap_or_default()
}

/// Creases (one two-vertex crease per sharp edge), corners and holes, where there are any.
fn tag_attributes(view: &MeshView<'_>) -> io::Result<Vec<Attr>> {
    let mut attrs = Vec::new();
    let creases = view.creases();
    if !creases.is_empty() {
        let ends: Vec<u32> = creases.iter().flat_map(|(e, _)| *e).collect();
        attrs.push(Attr::new(
            "creaseIndices",
            "int[]",
            Value::IntVec(to_ints(&ends)?),
        ));
        attrs.push(Attr::new(
            "creaseLengths",
            "int[]",
            Value::IntVec(vec![2; creases.len()]),
        ));
        attrs.push(Attr::new(
            "creaseSharpnesses",
            "float[]",
            Value::FloatVec(creases.iter().map(|c| c.1).collect()),
        ));
    }
    let corners = view.corners();
    if !corners.is_empty() {
        let v: Vec<u32> = corners.iter().map(|c| c.0).collect();
        attrs.push(Attr::new(
            "cornerIndices",
            "int[]",
            Value::IntVec(to_ints(&v)?),
        ));
        attrs.push(Attr::new(
            "cornerSharpnesses",
            "float[]",
            Value::FloatVec(corners.iter().map(|c| c.1).collect()),
        ));
    }
    let holes: Vec<u32> = view.hole_faces().iter().map(|&f| f as u32).collect();
    if !holes.is_empty() {
        attrs.push(Attr::new(
            "holeIndices",
            "int[]",
            Value::IntVec(to_ints(&holes)?),
        ));
    }
    Ok(attrs)
}

/// Every position, checked to fit USD's single-precision `point3f` (a larger coordinate
/// would be written as infinity, which no reader takes back); borrowed where the view holds
/// them.
fn all_points<'a>(view: &'a MeshView<'_>) -> io::Result<Cow<'a, [DVec3]>> {
    let points = match view.positions() {
        Some(p) => Cow::Borrowed(p),
        None => Cow::Owned(view.point_window(0..view.num_vertices())?.points().to_vec()),
    };
    let beyond = |p: &DVec3| p.abs().max_element() > f64::from(f32::MAX);
    // Chunks, then the index only where one holds such a point: a per-point parallel
    // search costs more than the check itself.
    let any_beyond = points.par_chunks(1 << 15).any(|c| c.iter().any(beyond));
    if let Some(v) = any_beyond.then(|| points.iter().position(beyond)).flatten() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!("vertex {v} has a coordinate beyond single precision, which USD's points hold"),
        ));
    }
    Ok(points)
}

fn all_faces(view: &MeshView<'_>) -> io::Result<(Vec<i32>, Vec<i32>)> {
    if view.num_vertices() > i32::MAX as usize {
        return Err(io::Error::other(
            "more vertices than USD's int indices hold",
        ));
    }
    let n = view.num_faces();
    let faces = view.face_window(0..n)?;
    let counts = (0..n)
        .into_par_iter()
        .map(|f| faces.face(f).len() as i32)
        .collect();
    // Vertex indices fit `i32` (checked above).
    let indices = match view.all_face_vertices() {
        Some(all) => all.par_iter().map(|&v| v as i32).collect(),
        None => (0..n)
            .flat_map(|f| faces.face(f).iter().map(|&v| v as i32))
            .collect(),
    };
    Ok((counts, indices))
}

fn to_ints(v: &[u32]) -> io::Result<Vec<i32>> {
    v.iter()
        .map(|&x| i32::try_from(x).map_err(|_| io::Error::other("an index past USD's int range")))
        .collect()
}

fn vec3f(p: &[DVec3]) -> Vec<gf::Vec3f> {
    p.par_iter()
        .map(|p| gf::Vec3f {
            x: p.x as f32,
            y: p.y as f32,
            z: p.z as f32,
        })
        .collect()
}

/// `extent`: the bounding box of the points, as UsdGeomBoundable asks.
fn extent(p: &[DVec3]) -> Vec<gf::Vec3f> {
    match subd_mesh::bounding_box(p.iter().copied()) {
        Some((lo, hi)) => vec3f(&[lo, hi]),
        None => Vec::new(),
    }
}
