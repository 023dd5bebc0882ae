//! Mesh file formats for subd.
//!
//! * **OBJ** in and out, with the tag lines of OpenSubdiv's shape files (`t crease`,
//!   `t corner`, `t hole`, `t interpolateboundary`, `t creasemethod`, `t smoothtriangles`);
//!   vertex indices are kept exactly as in the file ([`obj`]).
//! * **PLY** in (ASCII, binary little- and big-endian) and out (ASCII, binary little-endian)
//!   ([`ply`]).
//! * **glTF 2.0 binary** (`.glb`) out: positions, normals, triangle indices ([`glb`]).
//! * **glTF 2.0** in (`.glb`, `.gltf`): every triangle primitive, node transforms applied,
//!   vertices welded by position ([`gltf_input`]).
//! * **USD** in and out (`.usda`, `.usdc`, `.usdz`, `.usd`): a `UsdGeomMesh` prim with
//!   OpenSubdiv's rules as its attributes, composed stages, transforms, time samples
//!   ([`usd`]).
//!
//! The format is chosen by the file extension. Every output goes through
//! [`atomic_write`]: the data is written to a temporary file beside the target and renamed
//! over it only when complete, so a failed run leaves no partial file.
//!
//! ```
//! use subd_io::{parse_mesh, Format, ReadOptions};
//! let obj = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nt corner 1/1/0 0 10\n";
//! let file = parse_mesh(obj, Format::Obj, &ReadOptions::default()).unwrap();
//! assert_eq!(file.mesh.topology.num_faces(), 1);
//! assert_eq!(file.mesh.topology.vertex_sharpness(0), 10.0);
//! ```

pub mod error;
#[cfg(feature = "fuzzing")]
pub mod fuzzing;
pub mod glb;
pub mod gltf_input;
pub mod obj;
mod placed;
pub mod ply;
mod records;
mod text;
pub mod usd;
pub mod view;
#[cfg(test)]
mod write_reference_tests;

use std::io::Write;
use std::path::Path;

pub use error::{IoError, ReadError};
pub use placed::PlacedMesh;
pub use ply::PlyEncoding;
use subd_mesh::Mesh;
pub use view::{FaceSource, MeshView, PointSource, Points, TexCoords, ViewError};

/// A mesh file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Wavefront OBJ with OpenSubdiv tags.
    Obj,
    /// Stanford PLY.
    Ply,
    /// glTF 2.0 binary.
    Glb,
    /// glTF 2.0 JSON (read only).
    Gltf,
    /// USD text (`.usda`).
    Usda,
    /// USD binary (`.usdc`, and `.usd`, which USD writes as binary and reads as either).
    Usdc,
    /// USD package (`.usdz`): one binary layer in a zip archive.
    Usdz,
}

impl Format {
    /// The format named by a path's extension (case-insensitive).
    pub fn from_path(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "obj" => Some(Format::Obj),
            "ply" => Some(Format::Ply),
            "glb" => Some(Format::Glb),
            "gltf" => Some(Format::Gltf),
            "usda" => Some(Format::Usda),
            "usdc" | "usd" => Some(Format::Usdc),
            "usdz" => Some(Format::Usdz),
            _ => None,
        }
    }

    /// Whether subd writes this format (all but `.gltf`, whose external buffers make it a
    /// set of files; `.glb` is the one-file form).
    pub fn can_write(self) -> bool {
        !matches!(self, Format::Gltf)
    }

    /// Whether this is one of USD's formats (`.usda`, `.usdc`, `.usdz`), whose
    /// `subdivisionScheme` names Catmull-Clark, Loop and Bilinear only.
    pub fn is_usd(self) -> bool {
        matches!(self, Format::Usda | Format::Usdc | Format::Usdz)
    }

    /// The format named by an output path's extension, if subd writes it.
    pub fn for_output(path: &Path) -> Option<Format> {
        Format::from_path(path).filter(|f| f.can_write())
    }
}

/// Options for reading.
#[derive(Debug, Clone, Default)]
pub struct ReadOptions {
    /// Accept faces whose windings disagree across a shared edge (the edge becomes
    /// non-manifold) instead of failing.
    pub accept_inconsistent_orientation: bool,
    /// glTF: read each mesh as stored instead of placing it by its nodes' transforms.
    pub ignore_transforms: bool,
    /// glTF: weld vertices within this distance of each other (default: only vertices at
    /// exactly the same position).
    pub weld_tolerance: Option<f64>,
    /// USD: the path of the mesh prim to read (default: the stage's only one).
    pub prim: Option<String>,
    /// USD: the time code to read time-sampled attributes at (default: their default
    /// values).
    pub time: Option<f64>,
}

/// Options for writing.
#[derive(Debug, Clone, Default)]
pub struct WriteOptions {
    /// PLY encoding.
    pub ply_encoding: PlyEncoding,
    /// Tag lines written verbatim at the end of an OBJ file (e.g. [`MeshFile::extra_tags`]).
    pub extra_obj_tags: Vec<String>,
    /// USD: the prim name and the stage units to write (e.g. [`MeshFile::stage`]).
    pub stage: Option<usd::StageInfo>,
}

/// A mesh read from a file, with what the reader noticed.
#[derive(Debug, Clone)]
pub struct MeshFile {
    /// Topology, positions and scheme hints.
    pub mesh: Mesh,
    /// Accepted oddities worth telling the user (repeated vertices in a face, tags that are
    /// kept but not applied, ...), one line each.
    pub warnings: Vec<String>,
    /// OBJ tag lines kept verbatim but not interpreted (hierarchical edits, face-varying
    /// options).
    pub extra_tags: Vec<String>,
    /// Number of edges that two faces traverse in the same direction (only non-zero when
    /// [`ReadOptions::accept_inconsistent_orientation`] is set).
    pub orientation_conflicts: usize,
    /// Per-face refinement levels: the PLY face property `level`, as `subd adaptive` writes
    /// it (`None` where the file has none).
    pub face_levels: Option<Vec<u8>>,
    /// USD: the prim read and the stage's units (`None` for the other formats).
    pub stage: Option<usd::StageInfo>,
}

impl MeshFile {
    /// The options of an output made from this input: a USD output keeps its prim's name
    /// and its stage's units.
    pub fn output_options(&self) -> WriteOptions {
        WriteOptions {
            stage: self.stage.clone(),
            ..WriteOptions::default()
        }
    }
}

/// Parses a mesh from bytes in the given format. A `.gltf` document whose buffers are
/// external files needs [`read_mesh`], which knows the document's directory.
pub fn parse_mesh(
    bytes: &[u8],
    format: Format,
    options: &ReadOptions,
) -> Result<MeshFile, ReadError> {
    match format {
        Format::Obj => obj::parse_obj(bytes, options),
        Format::Ply => ply::parse_ply(bytes, options),
        Format::Glb | Format::Gltf => gltf_input::parse_gltf(bytes, None, options),
        Format::Usda | Format::Usdc | Format::Usdz => usd::parse_usd(bytes, format, options),
    }
}

/// Reads a mesh file, choosing the format by extension (`.obj`, `.ply`, `.glb`, `.gltf`,
/// `.usda`, `.usdc`, `.usdz`, `.usd`). A USD stage is opened composed, so its references
/// reach the files beside it.
pub fn read_mesh(path: &Path, options: &ReadOptions) -> Result<MeshFile, IoError> {
    let Some(format) = Format::from_path(path) else {
        return Err(IoError::UnknownFormat {
            path: path.to_path_buf(),
            expected: ".obj, .ply, .glb, .gltf, .usda, .usdc, .usdz or .usd",
        });
    };
    if matches!(format, Format::Usda | Format::Usdc | Format::Usdz) {
        if let Err(source) = std::fs::metadata(path) {
            return Err(IoError::Read {
                path: path.to_path_buf(),
                source,
            });
        }
        return usd::read_usd(path, options).map_err(|e| e.at(path));
    }
    let bytes = std::fs::read(path).map_err(|source| IoError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    let parsed = match format {
        Format::Glb | Format::Gltf => {
            let dir = path.parent().unwrap_or(Path::new("."));
            gltf_input::parse_gltf(&bytes, Some(dir), options)
        }
        _ => parse_mesh(&bytes, format, options),
    };
    parsed.map_err(|e| e.at(path))
}

/// Encodes `mesh` in `format` into `w`.
pub fn encode_mesh(
    w: &mut dyn Write,
    mesh: &Mesh,
    format: Format,
    options: &WriteOptions,
) -> std::io::Result<()> {
    encode_view(w, &MeshView::from_mesh(mesh), format, options)
}

/// Encodes the polygons, positions and tags of `view` in `format` into `w`.
pub fn encode_view(
    w: &mut dyn Write,
    view: &MeshView<'_>,
    format: Format,
    options: &WriteOptions,
) -> std::io::Result<()> {
    match format {
        Format::Obj => obj::write_obj(w, view, &options.extra_obj_tags),
        Format::Ply => ply::write_ply(w, view, options.ply_encoding),
        Format::Glb => glb::write_glb(w, view),
        Format::Usda | Format::Usdc | Format::Usdz => usd::write_usd(w, view, format, options),
        Format::Gltf => Err(std::io::Error::new(
            std::io::ErrorKind::Unsupported,
            "writing .gltf is not supported; use .glb",
        )),
    }
}

/// Writes a mesh file atomically, choosing the format by extension (`.obj`, `.ply`, `.glb`,
/// `.usda`, `.usdc`, `.usdz`, `.usd`).
pub fn write_mesh(path: &Path, mesh: &Mesh, options: &WriteOptions) -> Result<(), IoError> {
    write_view(path, &MeshView::from_mesh(mesh), options)
}

/// Writes the polygons, positions and tags of `view` atomically, choosing the format by
/// extension (`.obj`, `.ply`, `.glb`): for callers that have face lists but no edge
/// topology.
pub fn write_view(path: &Path, view: &MeshView<'_>, options: &WriteOptions) -> Result<(), IoError> {
    let format = Format::for_output(path).ok_or_else(|| IoError::UnknownFormat {
        path: path.to_path_buf(),
        expected: ".obj, .ply, .glb, .usda, .usdc, .usdz or .usd",
    })?;
    atomic_write(path, |w| encode_view(w, view, format, options))
}

/// Writes a file atomically: `write` fills a temporary file in the target's directory, which
/// is flushed and renamed over `path` only if `write` succeeds, so no reader ever sees a
/// partial file. On any failure the temporary file is removed and `path` is left as it was.
/// (No fsync: the contract is that a failed run leaves no partial file, which the rename
/// gives; durability across power loss is left to the file system.)
pub fn atomic_write(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), IoError> {
    let err = |source| IoError::Write {
        path: path.to_path_buf(),
        source,
    };
    let mut tmp = temp_beside(path)?;
    {
        let mut buf = std::io::BufWriter::with_capacity(1 << 20, tmp.as_file_mut());
        write(&mut buf).map_err(err)?;
        buf.flush().map_err(err)?;
    }
    tmp.persist(path).map_err(|e| err(e.error))?;
    Ok(())
}

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;

/// An empty temporary file in `path`'s directory, to be renamed over `path` when complete
/// ([`atomic_write`]).
pub(crate) fn temp_beside(path: &Path) -> Result<tempfile::NamedTempFile, IoError> {
    let err = |source| IoError::Write {
        path: path.to_path_buf(),
        source,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".subd-").suffix(".tmp");
    // A temporary file is created owner-only (0600); the output is an ordinary file, which
    // others (a render farm, a web server) may need to read: 0666 less the umask, as any
    // program that creates it directly gets.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    builder.tempfile_in(dir).map_err(err)
}

/// `mesh` with the texture coordinates a reader found, if any (made for its topology).
pub(crate) fn with_texcoords(
    mesh: subd_mesh::Mesh,
    uv: Option<subd_mesh::fvar::FVarChannel>,
) -> Result<subd_mesh::Mesh, ReadError> {
    match uv {
        Some(uv) => mesh
            .with_fvar(uv)
            .map_err(|e| ReadError::general(e.to_string())),
        None => Ok(mesh),
    }
}
