//! USD in and out (`.usda`, `.usdc`, `.usdz`) through the `openusd` crate: a `UsdGeomMesh`
//! prim carries OpenSubdiv's rules as attributes (Pixar designed them together), and they map
//! one to one onto a [`Mesh`](subd_mesh::Mesh), its tags and its [`SchemeHints`](subd_mesh::SchemeHints):
//!
//! | USD | subd |
//! |---|---|
//! | `faceVertexCounts`, `faceVertexIndices`, `points` | topology, positions (`point3f`, read as `f64`) |
//! | `subdivisionScheme` (`catmullClark`, `loop`, `bilinear`, `none`) | [`SchemeHints::scheme`](subd_mesh::SchemeHints::scheme) |
//! | `interpolateBoundary` | [`SchemeHints::boundary_interpolation`](subd_mesh::SchemeHints::boundary_interpolation) (USD's fallback `edgeAndCorner`) |
//! | `faceVaryingLinearInterpolation` | [`SchemeHints::fvar_interpolation`](subd_mesh::SchemeHints::fvar_interpolation) (fallback `cornersPlus1`) |
//! | `triangleSubdivisionRule` | [`SchemeHints::triangle_subdivision`](subd_mesh::SchemeHints::triangle_subdivision) |
//! | `creaseIndices`, `creaseLengths`, `creaseSharpnesses` | edge sharpness (per crease or per edge) |
//! | `cornerIndices`, `cornerSharpnesses` | vertex sharpness |
//! | `holeIndices` | holes |
//! | `orientation = "leftHanded"` | every face's winding reversed on reading |
//! | `primvars:st` (`faceVarying` with or without indices, `vertex`, `varying`) | the UV channel, seams kept |
//! | `subd:creaseMethod` (custom) | [`SchemeHints::crease_method`](subd_mesh::SchemeHints::crease_method) (USD has no attribute for it) |
//!
//! The mesh prim's composed transform (its own `xformOp`s and its ancestors', `!invert!` and
//! `!resetXformStack!` included) is applied to the points unless
//! [`ReadOptions::ignore_transforms`](crate::ReadOptions::ignore_transforms) is set. Stages
//! are composed as `openusd` composes them (sublayers, references, payloads, variant
//! selections); time-sampled attributes are read at
//! [`ReadOptions::time`](crate::ReadOptions::time) (linear interpolation between samples)
//! or, without one, their default value.
//!
//! Writing gives one `Mesh` prim with the tags above, `normals` (vertex interpolation) when
//! the view has them and `primvars:st` indexed; `metersPerUnit` and `upAxis` are written back
//! from [`WriteOptions::stage`](crate::WriteOptions::stage).
//!
//! ```
//! use subd_io::{Format, MeshView, ReadOptions, WriteOptions, encode_view, parse_mesh};
//! use subd_mesh::DVec3;
//! let points = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
//! let view = MeshView::new(&points, &[0, 4], &[0, 1, 2, 3], &[]).unwrap();
//! let mut usda = Vec::new();
//! encode_view(&mut usda, &view, Format::Usda, &WriteOptions::default()).unwrap();
//! let read = parse_mesh(&usda, Format::Usda, &ReadOptions::default()).unwrap();
//! assert_eq!(read.mesh.topology.num_faces(), 1);
//! assert_eq!(read.mesh.positions[2], DVec3::new(1.0, 1.0, 0.0));
//! ```

mod read;
mod values;
mod write;
mod xform;

use std::path::Path;

use openusd::usd;

use crate::error::{IoError, ReadError};
use crate::{Format, MeshFile, ReadOptions};

pub(crate) use write::write_usd;

/// Where a mesh came from in its stage, and the stage's units: what a USD output writes
/// back.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StageInfo {
    /// The mesh prim's path (`/World/Body`); an output names its prim after the last part.
    pub prim: String,
    /// The stage's `metersPerUnit`, when authored.
    pub meters_per_unit: Option<f64>,
    /// The stage's `upAxis` (`Y` or `Z`), when authored.
    pub up_axis: Option<String>,
}

/// A mesh prim of a stage, as `subd info` lists them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MeshPrim {
    /// The prim's path.
    pub path: String,
    /// Number of faces (`faceVertexCounts`).
    pub faces: usize,
    /// Number of points.
    pub points: usize,
    /// The `subdivisionScheme` token (`catmullClark` when not authored).
    pub scheme: String,
}

/// The mesh prims of the stage at `path`, in traversal order.
///
/// # Errors
/// [`IoError`] when the file cannot be opened as a stage.
pub fn mesh_prims(path: &Path) -> Result<Vec<MeshPrim>, IoError> {
    let stage = open_stage(path).map_err(|e| e.at(path))?;
    read::list_mesh_prims(&stage, None).map_err(|e| e.at(path))
}

/// Reads the mesh prim [`ReadOptions::prim`] names (or the stage's only one) from the stage
/// at `path`, composed.
pub(crate) fn read_usd(path: &Path, options: &ReadOptions) -> Result<MeshFile, ReadError> {
    let stage = open_stage(path)?;
    read::read_stage(&stage, options)
}

/// [`read_usd`] from bytes in memory: the one layer, with no file beside it for its
/// references to reach.
pub(crate) fn parse_usd(
    bytes: &[u8],
    format: Format,
    options: &ReadOptions,
) -> Result<MeshFile, ReadError> {
    let name = match format {
        Format::Usdc => "memory.usdc",
        Format::Usdz => "memory.usdz",
        _ => "memory.usda",
    };
    let resolver = read::MemoryResolver::new(name, bytes.to_vec());
    let stage = usd::Stage::builder()
        .resolver(resolver)
        .open(name)
        .map_err(|e| ReadError::general(format!("cannot open as USD: {}", one_line(&e))))?;
    read::read_stage(&stage, options)
}

fn open_stage(path: &Path) -> Result<usd::Stage, ReadError> {
    let name = path.to_str().ok_or_else(|| {
        ReadError::general("the path is not valid UTF-8, which USD's asset paths must be")
    })?;
    usd::Stage::open(name)
        .map_err(|e| ReadError::general(format!("cannot open as USD: {}", one_line(&e))))
}

/// An error of `openusd` on one line (its messages can hold newlines).
fn one_line(e: &dyn std::fmt::Display) -> String {
    e.to_string()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}
