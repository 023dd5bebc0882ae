//! The readers' two paths, for the fuzz targets (feature `fuzzing`): the parallel readers
//! cut into pieces small enough that a fuzzer's inputs span many of them, and the serial
//! readers alone. Every input must give the same mesh, or the same error, through both.

use crate::error::ReadError;
use crate::ply::BinaryReading;
use crate::{MeshFile, ReadOptions};

/// OBJ read in parallel chunks of about `chunk_bytes` (cut at line ends).
pub fn parse_obj_in_chunks(
    bytes: &[u8],
    options: &ReadOptions,
    chunk_bytes: usize,
) -> Result<MeshFile, ReadError> {
    crate::obj::parse_obj_in_chunks(bytes, options, chunk_bytes.max(1))
}

/// OBJ read by the serial reader alone.
pub fn parse_obj_serially(bytes: &[u8], options: &ReadOptions) -> Result<MeshFile, ReadError> {
    crate::obj::parse_obj_serially(bytes, options)
}

/// PLY with binary vertices decoded in parallel tasks of `vertices_per_task`.
pub fn parse_ply_in_tasks(
    bytes: &[u8],
    options: &ReadOptions,
    vertices_per_task: usize,
) -> Result<MeshFile, ReadError> {
    crate::ply::parse_ply_with(bytes, options, BinaryReading::Parallel(vertices_per_task))
}

/// PLY read by the per-value reader alone (no fast binary decoders).
pub fn parse_ply_serially(bytes: &[u8], options: &ReadOptions) -> Result<MeshFile, ReadError> {
    crate::ply::parse_ply_with(bytes, options, BinaryReading::PerValue)
}
