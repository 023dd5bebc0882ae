//! `subd refine`'s depth-first output: the last level made a chunk of base faces at a time
//! (`subd_schemes::DepthFirst`) and each chunk's records written at their places: in a
//! binary PLY file itself (`subd_io::ply::PlacedPly`), or for OBJ and ASCII PLY in a
//! scratch file of fixed-size records then encoded in order (`subd_io::PlacedMesh`), so
//! that no level is held whole and the peak memory does not grow with the level. The file
//! is byte for byte the one the level at a time writes.

use std::path::Path;

use subd_io::{IoError, MeshFile};
use subd_mesh::tags::is_infinite;
use subd_mesh::{DVec3, SchemeHints, Topology};
use subd_schemes::{DepthFirst, LevelCounts, Options, RefineError, Scheme};

use crate::Failure;
use crate::failure::bad;

/// Why `levels` levels of `file` under `scheme` cannot be written depth-first to `output`
/// (`None` when they can): what the output would hold beyond positions and faces of one
/// size is made level by level.
pub(crate) fn unsupported(
    scheme: &Scheme,
    levels: usize,
    limit: bool,
    output: &Path,
    file: &MeshFile,
) -> Option<&'static str> {
    let tags = file.mesh.topology.tags();
    let lasting = |s: &f32| is_infinite(*s) || *s > levels as f32;
    if !matches!(
        scheme,
        Scheme::CatmullClark | Scheme::Loop | Scheme::Bilinear
    ) {
        Some("it takes Catmull-Clark, Loop or Bilinear")
    } else if levels == 0 {
        Some("there is no level to refine")
    } else if limit {
        Some("--limit moves the whole level")
    } else if !matches!(
        subd_io::Format::for_output(output),
        Some(subd_io::Format::Ply | subd_io::Format::Obj)
    ) {
        Some("it writes PLY (.ply) or OBJ (.obj) only")
    } else if !file.mesh.fvar.is_empty() {
        Some("texture coordinates are carried level by level")
    } else if tags.num_holes() > 0 {
        Some("holes are carried level by level")
    } else if tags.edge_sharpness().iter().any(lasting)
        || tags.vertex_sharpness().iter().any(lasting)
    {
        Some("creases or corners sharp past the last level are written as tags")
    } else {
        None
    }
}

/// Binary PLY output levels of at least this many faces are made depth-first where they
/// can be, even when the level at a time fits: from there on it is the faster of the two
/// (BENCHMARKS.md, "Depth-first refinement"), and its memory stays flat. OBJ, whose records
/// go through a scratch file, is made depth-first only when asked or when the level does not
/// fit.
pub(crate) const BY_ITSELF_FROM_FACES: u64 = 1 << 24;

/// Refuses, before any work, a `.glb` output past glTF's 4 GiB binary limit: its `f32`
/// positions and normals and `u32` triangle indices (a quad is two triangles).
pub(crate) fn check_glb_fits(
    input: &Path,
    levels: usize,
    last: LevelCounts,
) -> Result<(), Failure> {
    let triangles = last.face_vertices.saturating_sub(2 * last.faces);
    let bytes = 24u64
        .saturating_mul(last.vertices)
        .saturating_add(12u64.saturating_mul(triangles));
    if bytes <= u32::MAX as u64 {
        return Ok(());
    }
    Err(bad(format!(
        "{}: level {levels} ({} vertices, {} faces) needs about {} as .glb, past glTF's 4 GiB limit on a binary file; write .ply or .obj",
        input.display(),
        last.vertices,
        last.faces,
        subd_mesh::memory::human_bytes(bytes),
    )))
}

/// What writing the last level depth-first needs.
pub(crate) struct Request<'a> {
    pub(crate) base: &'a Topology,
    pub(crate) positions: &'a [DVec3],
    pub(crate) scheme: &'a Scheme,
    pub(crate) options: &'a Options,
    pub(crate) levels: usize,
    pub(crate) faces_per_chunk: u64,
    pub(crate) hints: SchemeHints,
    pub(crate) input: &'a Path,
    pub(crate) output: &'a Path,
    pub(crate) write_options: subd_io::WriteOptions,
}

/// Where a chunk's records go: into a binary little-endian PLY file at their places, or
/// into the scratch file of any other output.
enum Placed {
    Ply(subd_io::ply::PlacedPly),
    Scratch(subd_io::PlacedMesh),
}

impl Placed {
    fn create(request: &Request<'_>, last: LevelCounts, size: usize) -> Result<Placed, IoError> {
        let binary_ply = subd_io::Format::for_output(request.output) == Some(subd_io::Format::Ply)
            && request.write_options.ply_encoding == subd_io::PlyEncoding::BinaryLittleEndian;
        Ok(if binary_ply {
            Placed::Ply(subd_io::ply::PlacedPly::create(
                request.output,
                &request.hints,
                last.vertices,
                last.faces,
                size,
            )?)
        } else {
            Placed::Scratch(subd_io::PlacedMesh::create(
                request.output,
                request.hints,
                last.vertices,
                last.faces,
                size,
            )?)
        })
    }

    fn write_points(&self, first: u64, points: &[DVec3]) -> Result<(), IoError> {
        match self {
            Placed::Ply(p) => p.write_points(first, points),
            Placed::Scratch(m) => m.write_points(first, points),
        }
    }

    fn write_faces(&self, first: u64, corners: &[u32]) -> Result<(), IoError> {
        match self {
            Placed::Ply(p) => p.write_faces(first, corners),
            Placed::Scratch(m) => m.write_faces(first, corners),
        }
    }

    fn finish(self, options: &subd_io::WriteOptions) -> Result<(), IoError> {
        match self {
            Placed::Ply(p) => p.finish(),
            Placed::Scratch(m) => m.finish(options),
        }
    }
}

/// A chunk's failure: refining its piece, or writing its records.
enum ChunkError {
    Refine(RefineError),
    Io(IoError),
}

impl From<RefineError> for ChunkError {
    fn from(e: RefineError) -> Self {
        ChunkError::Refine(e)
    }
}

impl From<IoError> for ChunkError {
    fn from(e: IoError) -> Self {
        ChunkError::Io(e)
    }
}

/// Refines and writes the last level chunk by chunk, all threads at work; its counts.
pub(crate) fn write(request: &Request<'_>) -> Result<LevelCounts, Failure> {
    let in_input = |e: RefineError| bad(format!("{}: {e}", request.input.display()));
    subd_mesh::memory::reuse_freed_memory();
    // PLY's limits are checked before any work.
    let last =
        subd_schemes::refined_counts(request.base, request.scheme, request.levels)[request.levels];
    let size = if *request.scheme == Scheme::Loop {
        3
    } else {
        4
    };
    let placed = Placed::create(request, last, size)?;
    let df = DepthFirst::new(
        request.base,
        request.scheme.clone(),
        request.options,
        request.levels,
        request.faces_per_chunk,
    )
    .map_err(in_input)?;
    let counts = df.counts();
    let threads = rayon::current_num_threads();
    let written = df.for_each_chunk(request.positions, threads, |chunk| {
        for (first, range) in chunk.point_runs() {
            placed.write_points(first, &chunk.points()[range])?;
        }
        for (first, range) in chunk.face_runs(size) {
            placed.write_faces(first, &chunk.face_vertices()[range])?;
        }
        Ok::<(), ChunkError>(())
    });
    match written {
        Ok(()) => placed.finish(&request.write_options)?,
        Err(ChunkError::Refine(e)) => return Err(in_input(e)),
        Err(ChunkError::Io(e)) => return Err(e.into()),
    }
    Ok(counts)
}
