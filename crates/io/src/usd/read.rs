//! A `UsdGeomMesh` prim of a composed stage into a [`MeshFile`].

use std::io;
use std::sync::Arc;

use openusd::{ar, usd, usdz};
use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};
use subd_mesh::{
    BoundaryInterpolation, CreaseMethod, DVec3, FileScheme, Mesh, SchemeHints, Topology,
    TopologyBuilder, TriangleSubdivision,
};

use super::values::{PrimValues, enum_token};
use super::{MeshPrim, StageInfo, one_line};
use crate::error::ReadError;
use crate::{MeshFile, ReadOptions};

/// `subdivisionScheme`'s tokens.
pub(super) const SCHEMES: [(&str, FileScheme); 4] = [
    ("catmullClark", FileScheme::CatmullClark),
    ("loop", FileScheme::Loop),
    ("bilinear", FileScheme::Bilinear),
    ("none", FileScheme::Polygons),
];

/// `interpolateBoundary`'s tokens.
pub(super) const BOUNDARIES: [(&str, BoundaryInterpolation); 3] = [
    ("none", BoundaryInterpolation::None),
    ("edgeOnly", BoundaryInterpolation::EdgeOnly),
    ("edgeAndCorner", BoundaryInterpolation::EdgeAndCorner),
];

/// `faceVaryingLinearInterpolation`'s tokens.
pub(super) const FVAR_MODES: [(&str, FVarLinearInterpolation); 6] = [
    ("none", FVarLinearInterpolation::None),
    ("cornersOnly", FVarLinearInterpolation::CornersOnly),
    ("cornersPlus1", FVarLinearInterpolation::CornersPlus1),
    ("cornersPlus2", FVarLinearInterpolation::CornersPlus2),
    ("boundaries", FVarLinearInterpolation::Boundaries),
    ("all", FVarLinearInterpolation::All),
];

/// `triangleSubdivisionRule`'s tokens.
pub(super) const TRIANGLE_RULES: [(&str, TriangleSubdivision); 2] = [
    ("catmullClark", TriangleSubdivision::Catmark),
    ("smooth", TriangleSubdivision::Smooth),
];

/// `subd:creaseMethod`'s tokens (subd's own attribute: USD has none for it).
pub(super) const CREASE_METHODS: [(&str, CreaseMethod); 2] = [
    ("uniform", CreaseMethod::Uniform),
    ("chaikin", CreaseMethod::Chaikin),
];

/// subd's own attribute for the crease method, which USD has none for.
pub(super) const CREASE_METHOD_ATTR: &str = "subd:creaseMethod";

/// The mesh prims of `stage` (every `Mesh` prim an active traversal meets), with counts read
/// at `time`.
pub(super) fn list_mesh_prims(
    stage: &usd::Stage,
    time: Option<f64>,
) -> Result<Vec<MeshPrim>, ReadError> {
    let mut prims = Vec::new();
    for path in mesh_paths(stage)? {
        let prim = prim_at(stage, &path)?;
        let values = PrimValues { prim: &prim, time };
        let scheme = values
            .token("subdivisionScheme")?
            .unwrap_or_else(|| "catmullClark".into());
        prims.push(MeshPrim {
            faces: values.indices("faceVertexCounts")?.map_or(0, |c| c.len()),
            points: values.points("points")?.map_or(0, |p| p.len()),
            scheme,
            path,
        });
    }
    Ok(prims)
}

fn mesh_paths(stage: &usd::Stage) -> Result<Vec<String>, ReadError> {
    let mut paths = Vec::new();
    stage
        .traverse(usd::PrimPredicate::DEFAULT, |p| paths.push(p.to_string()))
        .map_err(|e| ReadError::general(format!("cannot traverse the stage: {}", one_line(&e))))?;
    let mut meshes = Vec::new();
    for path in paths {
        let prim = prim_at(stage, &path)?;
        let ty = prim
            .type_name()
            .map_err(|e| ReadError::general(format!("prim {path}: {}", one_line(&e))))?;
        if ty.is_some_and(|t| t.as_str() == "Mesh") {
            meshes.push(path);
        }
    }
    Ok(meshes)
}

fn prim_at(stage: &usd::Stage, path: &str) -> Result<usd::Prim, ReadError> {
    stage
        .prim(path)
        .map_err(|e| ReadError::general(format!("prim {path}: {}", one_line(&e))))
}

/// The mesh prim `wanted` names, or the stage's only one.
fn choose_prim(stage: &usd::Stage, wanted: Option<&str>) -> Result<String, ReadError> {
    let meshes = mesh_paths(stage)?;
    match wanted {
        Some(w) if meshes.iter().any(|m| m == w) => Ok(w.to_string()),
        Some(w) => {
            let prim = prim_at(stage, w)?;
            let what = match prim.type_name() {
                Ok(Some(t)) => format!("is a {}, not a Mesh", t.as_str()),
                _ => "is not a Mesh prim of the stage".to_string(),
            };
            Err(ReadError::general(format!(
                "prim {w} {what} (mesh prims: {})",
                list_or_none(&meshes)
            )))
        }
        None => match meshes.as_slice() {
            [one] => Ok(one.clone()),
            [] => Err(ReadError::general("the stage has no Mesh prim")),
            many => Err(ReadError::general(format!(
                "the stage has {} Mesh prims; pick one with --prim (prim= in Python): {}",
                many.len(),
                many.join(", ")
            ))),
        },
    }
}

fn list_or_none(paths: &[String]) -> String {
    if paths.is_empty() {
        "none".into()
    } else {
        paths.join(", ")
    }
}

/// Reads the chosen mesh prim of `stage` (see the [module docs](super)).
pub(super) fn read_stage(stage: &usd::Stage, options: &ReadOptions) -> Result<MeshFile, ReadError> {
    let path = choose_prim(stage, options.prim.as_deref())?;
    let prim = prim_at(stage, &path)?;
    let values = PrimValues {
        prim: &prim,
        time: options.time,
    };
    let mut warnings = Vec::new();
    let mut polygons = Polygons::read(&values)?;
    let uv = read_uv(&values, &polygons, &mut warnings)?;
    let mut uv_corners = uv.as_ref().map(|(_, corners)| corners.clone());
    if values.token("orientation")?.as_deref() == Some("leftHanded") {
        polygons.reverse_windings(uv_corners.as_deref_mut());
    }
    if !options.ignore_transforms {
        let world = super::xform::world_transform(&prim, options.time)?;
        if world != glam::DMat4::IDENTITY {
            for p in &mut polygons.points {
                *p = world.transform_point3(*p);
            }
        }
    }
    let (mut topology, conflicts) = polygons.build(&values, options, &mut warnings)?;
    read_tags(&values, &mut topology, &mut warnings)?;
    let mut mesh = Mesh::new(topology, polygons.points)?;
    mesh.hints = read_hints(&values)?;
    if let (Some((uv_values, _)), Some(corners)) = (uv, uv_corners) {
        let channel = FVarChannel::new(&mesh.topology, 2, uv_values, corners)
            .map_err(|e| values.error("primvars:st", e))?;
        mesh = mesh
            .with_fvar(channel)
            .map_err(|e| values.error("primvars:st", e))?;
    }
    Ok(MeshFile {
        mesh,
        warnings,
        extra_tags: Vec::new(),
        orientation_conflicts: conflicts,
        face_levels: None,
        stage: Some(stage_info(stage, path)?),
    })
}

/// The polygons of a mesh prim as USD stores them.
struct Polygons {
    counts: Vec<u32>,
    indices: Vec<u32>,
    points: Vec<DVec3>,
}

impl Polygons {
    fn read(values: &PrimValues<'_>) -> Result<Polygons, ReadError> {
        let required = |name: &str| values.error(name, "missing (a Mesh needs it)");
        let counts = values
            .indices("faceVertexCounts")?
            .ok_or_else(|| required("faceVertexCounts"))?;
        let indices = values
            .indices("faceVertexIndices")?
            .ok_or_else(|| required("faceVertexIndices"))?;
        let points = values.points("points")?.ok_or_else(|| required("points"))?;
        let total: u64 = counts.iter().map(|&c| u64::from(c)).sum();
        if total != indices.len() as u64 {
            return Err(values.error(
                "faceVertexIndices",
                format!(
                    "has {} indices, but faceVertexCounts adds up to {total}",
                    indices.len()
                ),
            ));
        }
        if let Some(k) = indices.iter().position(|&v| v as usize >= points.len()) {
            return Err(values.error(
                "faceVertexIndices",
                format!(
                    "value [{k}] = {} is out of range ({} points)",
                    indices[k],
                    points.len()
                ),
            ));
        }
        Ok(Polygons {
            counts,
            indices,
            points,
        })
    }

    /// Reverses every face's winding (`leftHanded`), keeping its first corner first, and
    /// the texture coordinates' corners with it.
    fn reverse_windings(&mut self, mut uv: Option<&mut [u32]>) {
        let mut start = 0;
        for &c in &self.counts {
            let end = start + c as usize;
            if c > 1 {
                self.indices[start + 1..end].reverse();
                if let Some(uv) = uv.as_deref_mut() {
                    uv[start + 1..end].reverse();
                }
            }
            start = end;
        }
    }

    /// The topology, with the number of accepted orientation conflicts.
    fn build(
        &self,
        values: &PrimValues<'_>,
        options: &ReadOptions,
        warnings: &mut Vec<String>,
    ) -> Result<(Topology, usize), ReadError> {
        let (topology, built) = TopologyBuilder::new(self.points.len())
            .accept_inconsistent_orientation(options.accept_inconsistent_orientation)
            .build_with_warnings(&self.counts, &self.indices)
            .map_err(|e| match e {
                subd_mesh::TopologyError::InconsistentOrientation { .. } => values.prim_error(
                    format!("{e} (accept with --accept-inconsistent-orientation)"),
                ),
                other => values.prim_error(other),
            })?;
        let conflicts = built
            .iter()
            .filter(|w| matches!(w, subd_mesh::BuildWarning::InconsistentOrientation { .. }))
            .count();
        warnings.extend(
            built
                .iter()
                .map(|w| format!("prim {}: {w}", values.prim.path())),
        );
        Ok((topology, conflicts))
    }
}

/// Creases (per crease or per edge sharpness), corners and holes.
fn read_tags(
    values: &PrimValues<'_>,
    topology: &mut Topology,
    warnings: &mut Vec<String>,
) -> Result<(), ReadError> {
    for (attr, edge) in crease_edges(values)? {
        let ([a, b], s) = edge;
        let set = topology
            .set_crease(a.into(), b.into(), s)
            .map_err(|e| values.error(attr, e))?;
        if set.is_none() {
            warnings.push(format!(
                "prim {} attribute creaseIndices: ({a}, {b}) is not an edge of the mesh; ignored",
                values.prim.path()
            ));
        }
    }
    let corners = values.indices("cornerIndices")?.unwrap_or_default();
    let sharp = values.floats("cornerSharpnesses")?.unwrap_or_default();
    if corners.len() != sharp.len() {
        return Err(values.error(
            "cornerSharpnesses",
            format!(
                "has {} values for {} cornerIndices",
                sharp.len(),
                corners.len()
            ),
        ));
    }
    for (&v, &s) in corners.iter().zip(&sharp) {
        topology
            .set_corner(v.into(), s)
            .map_err(|e| values.error("cornerIndices", e))?;
    }
    for f in values.indices("holeIndices")?.unwrap_or_default() {
        topology
            .set_hole_checked(f.into())
            .map_err(|e| values.error("holeIndices", e))?;
    }
    Ok(())
}

/// A creased edge: the attribute that names it, its end vertices and its sharpness.
type CreasedEdge = (&'static str, ([u32; 2], f64));

/// Every creased edge: `creaseLengths` cut `creaseIndices` into vertex chains, and
/// `creaseSharpnesses` holds one value per chain or one per edge.
fn crease_edges(values: &PrimValues<'_>) -> Result<Vec<CreasedEdge>, ReadError> {
    let lengths = values.indices("creaseLengths")?.unwrap_or_default();
    let chain = values.indices("creaseIndices")?.unwrap_or_default();
    let sharp = values.floats("creaseSharpnesses")?.unwrap_or_default();
    let total: u64 = lengths.iter().map(|&n| u64::from(n)).sum();
    if total != chain.len() as u64 {
        return Err(values.error(
            "creaseLengths",
            format!(
                "adds up to {total}, but creaseIndices has {} values",
                chain.len()
            ),
        ));
    }
    if let Some(k) = lengths.iter().position(|&n| n < 2) {
        return Err(values.error(
            "creaseLengths",
            format!(
                "value [{k}] = {} (a crease joins 2 vertices or more)",
                lengths[k]
            ),
        ));
    }
    let edges: u64 = lengths.iter().map(|&n| u64::from(n) - 1).sum();
    let per_edge = sharp.len() as u64 == edges && sharp.len() != lengths.len();
    if !per_edge && sharp.len() != lengths.len() {
        return Err(values.error(
            "creaseSharpnesses",
            format!(
                "has {} values; expected one per crease ({}) or one per edge ({edges})",
                sharp.len(),
                lengths.len()
            ),
        ));
    }
    let (mut out, mut start, mut edge) = (Vec::new(), 0usize, 0usize);
    for (c, &n) in lengths.iter().enumerate() {
        let n = n as usize;
        for w in chain[start..start + n].windows(2) {
            let s = if per_edge { sharp[edge] } else { sharp[c] };
            out.push(("creaseIndices", ([w[0], w[1]], s)));
            edge += 1;
        }
        start += n;
    }
    Ok(out)
}

/// The scheme and its options; USD's fallbacks where an attribute is not authored
/// (`catmullClark`, `edgeAndCorner`, `cornersPlus1`, `catmullClark` triangles).
fn read_hints(values: &PrimValues<'_>) -> Result<SchemeHints, ReadError> {
    let read = |attr: &str| values.token(attr);
    let scheme = match read("subdivisionScheme")? {
        Some(t) => enum_token(values, "subdivisionScheme", &t, &SCHEMES)?,
        None => FileScheme::CatmullClark,
    };
    let boundary = match read("interpolateBoundary")? {
        Some(t) => enum_token(values, "interpolateBoundary", &t, &BOUNDARIES)?,
        None => BoundaryInterpolation::EdgeAndCorner,
    };
    let fvar = match read("faceVaryingLinearInterpolation")? {
        Some(t) => enum_token(values, "faceVaryingLinearInterpolation", &t, &FVAR_MODES)?,
        None => FVarLinearInterpolation::CornersPlus1,
    };
    let triangles = match read("triangleSubdivisionRule")? {
        Some(t) => enum_token(values, "triangleSubdivisionRule", &t, &TRIANGLE_RULES)?,
        None => TriangleSubdivision::Catmark,
    };
    let crease_method = match read(CREASE_METHOD_ATTR)? {
        Some(t) => Some(enum_token(values, CREASE_METHOD_ATTR, &t, &CREASE_METHODS)?),
        None => None,
    };
    Ok(SchemeHints {
        boundary_interpolation: Some(boundary),
        crease_method,
        triangle_subdivision: Some(triangles),
        fvar_interpolation: Some(fvar),
        scheme: Some(scheme),
    })
}

/// Texture coordinates: u and v interleaved, and one value index per face-vertex.
type UvLayout = (Vec<f64>, Vec<u32>);

/// The texture coordinates: `primvars:st`, as values and one value index per face-vertex.
/// `constant` and `uniform` ones are not coordinates a surface carries: left out, with a
/// warning.
fn read_uv(
    values: &PrimValues<'_>,
    polygons: &Polygons,
    warnings: &mut Vec<String>,
) -> Result<Option<UvLayout>, ReadError> {
    const ST: &str = "primvars:st";
    let Some(uv) = values.pairs(ST)? else {
        return Ok(None);
    };
    let n = uv.len() / 2;
    let indices = values.indices("primvars:st:indices")?;
    let interpolation = values
        .metadata_token(ST, "interpolation")?
        .unwrap_or_else(|| "constant".into());
    let corners = match interpolation.as_str() {
        "faceVarying" => match indices {
            Some(ix) => check_count(values, "primvars:st:indices", ix, polygons.indices.len())?,
            None => check_count(values, ST, (0..n as u32).collect(), polygons.indices.len())?,
        },
        "vertex" | "varying" => {
            let per_vertex = match indices {
                Some(ix) => check_count(values, "primvars:st:indices", ix, polygons.points.len())?,
                None => check_count(values, ST, (0..n as u32).collect(), polygons.points.len())?,
            };
            polygons
                .indices
                .iter()
                .map(|&v| per_vertex[v as usize])
                .collect()
        }
        other => {
            warnings.push(format!(
                "prim {} attribute {ST}: {other} interpolation, not texture coordinates over the surface; left out",
                values.prim.path()
            ));
            return Ok(None);
        }
    };
    if let Some(k) = corners.iter().position(|&i| i as usize >= n) {
        return Err(values.error(
            "primvars:st:indices",
            format!("value [{k}] = {} is out of range ({n} values)", corners[k]),
        ));
    }
    Ok(Some((uv, corners)))
}

fn check_count(
    values: &PrimValues<'_>,
    attr: &str,
    v: Vec<u32>,
    expected: usize,
) -> Result<Vec<u32>, ReadError> {
    if v.len() == expected {
        Ok(v)
    } else {
        Err(values.error(
            attr,
            format!("has {} entries, expected {expected}", v.len()),
        ))
    }
}

fn stage_info(stage: &usd::Stage, prim: String) -> Result<StageInfo, ReadError> {
    let meta = |key: &str| {
        stage
            .stage_metadata(key)
            .map_err(|e| ReadError::general(format!("stage metadata {key}: {}", one_line(&e))))
    };
    let meters_per_unit = match meta("metersPerUnit")? {
        Some(openusd::sdf::Value::Double(x)) => Some(x),
        Some(openusd::sdf::Value::Float(x)) => Some(f64::from(x)),
        _ => None,
    };
    let up_axis = match meta("upAxis")? {
        Some(openusd::sdf::Value::Token(t)) => Some(t.as_str().to_string()),
        _ => None,
    };
    Ok(StageInfo {
        prim,
        meters_per_unit,
        up_axis,
    })
}

/// A resolver that knows one asset, held in memory: a stage read from bytes.
pub(super) struct MemoryResolver {
    name: String,
    bytes: Arc<Vec<u8>>,
}

impl MemoryResolver {
    pub(super) fn new(name: &str, bytes: Vec<u8>) -> Self {
        MemoryResolver {
            name: name.to_string(),
            bytes: Arc::new(bytes),
        }
    }
}

impl MemoryResolver {
    /// The entry `path` names inside the package in memory (`memory.usdz[entry]`).
    fn packaged<'a>(&self, path: &'a str) -> Option<&'a str> {
        path.strip_prefix(self.name.as_str())?
            .strip_prefix('[')?
            .strip_suffix(']')
    }
}

impl ar::Resolver for MemoryResolver {
    fn create_identifier(&self, asset_path: &str, _anchor: Option<&ar::ResolvedPath>) -> String {
        asset_path.to_string()
    }

    fn resolve(&self, asset_path: &str) -> Option<ar::ResolvedPath> {
        (asset_path == self.name || self.packaged(asset_path).is_some())
            .then(|| ar::ResolvedPath::new(asset_path))
    }

    fn resolve_for_new_asset(&self, _asset_path: &str) -> Option<ar::ResolvedPath> {
        None
    }

    fn open_asset(&self, resolved: &ar::ResolvedPath) -> io::Result<Box<dyn ar::Asset>> {
        let path = resolved.to_str().unwrap_or_default();
        if path == self.name {
            Ok(Box::new(io::Cursor::new(self.bytes.as_ref().clone())))
        } else if let Some(inner) = self.packaged(path) {
            // `memory.usdz[layer.usdc]`: an entry of the package in memory.
            let mut archive =
                usdz::Archive::from_bytes(self.bytes.as_ref().clone()).map_err(io::Error::other)?;
            let entry = archive.entry(inner).map_err(io::Error::other)?;
            Ok(Box::new(io::Cursor::new(entry)))
        } else {
            Err(io::Error::new(
                io::ErrorKind::NotFound,
                format!("{resolved}: only the layer in memory can be read"),
            ))
        }
    }
}
