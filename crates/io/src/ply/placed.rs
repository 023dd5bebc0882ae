//! Binary PLY written record by record at its place: positions are 24 bytes and faces of
//! one size `1 + 4 × size` bytes, so the byte offset of any vertex or face follows from its
//! index. A producer that makes a level in pieces (depth-first refinement) writes each piece
//! where it belongs, from any thread, in any order, and never holds the level.
//!
//! The file is a temporary one beside the target, sized up front and renamed over the target
//! by [`PlacedPly::finish`]: as with every writer here, a failed run leaves no partial file.
//! The header is the one [`super::write_ply`] writes for the same mesh, so the two files are
//! byte for byte the same.

use std::path::{Path, PathBuf};

use subd_mesh::{DVec3, SchemeHints};

use super::write::{Declarations, write_header_start};
use crate::IoError;
use crate::PlyEncoding;

/// Bytes of a vertex record: three little-endian `double`s.
const POINT_BYTES: u64 = 24;

/// A binary little-endian PLY file of positions and faces of one size, its records written
/// at their places ([`Self::write_points`], [`Self::write_faces`]) and the file put in place
/// by [`Self::finish`].
///
/// ```
/// use subd_io::ply::PlacedPly;
/// use subd_mesh::{DVec3, SchemeHints};
///
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("quad.ply");
/// let ply = PlacedPly::create(&path, &SchemeHints::default(), 4, 1, 4).unwrap();
/// ply.write_faces(0, &[0, 1, 2, 3]).unwrap();
/// ply.write_points(2, &[DVec3::new(1.0, 1.0, 0.0), DVec3::new(0.0, 1.0, 0.0)]).unwrap();
/// ply.write_points(0, &[DVec3::ZERO, DVec3::X]).unwrap();
/// ply.finish().unwrap();
/// let mesh = subd_io::read_mesh(&path, &Default::default()).unwrap().mesh;
/// assert_eq!(mesh.positions[2], DVec3::new(1.0, 1.0, 0.0));
/// assert_eq!(mesh.topology.face_vertices(0), &[0, 1, 2, 3]);
/// ```
#[derive(Debug)]
pub struct PlacedPly {
    file: tempfile::NamedTempFile,
    /// Held while writing: the kernel serialises writes to one file anyway, and threads
    /// that wait here sleep instead of spinning on the file's lock in the kernel.
    writing: std::sync::Mutex<()>,
    path: PathBuf,
    num_vertices: u64,
    num_faces: u64,
    face_size: usize,
    /// Byte offsets of the first vertex and the first face record.
    vertex_start: u64,
    face_start: u64,
}

impl PlacedPly {
    /// A file for `num_vertices` positions and `num_faces` faces of `face_size` corners,
    /// with `hints` in its header.
    ///
    /// # Errors
    /// [`IoError::Invalid`] when PLY cannot hold the mesh (more than 2^32 vertices, which its
    /// 32-bit indices cannot name, or faces of more than 255 corners); [`IoError::Write`]
    /// when the file cannot be made.
    pub fn create(
        path: &Path,
        hints: &SchemeHints,
        num_vertices: u64,
        num_faces: u64,
        face_size: usize,
    ) -> Result<PlacedPly, IoError> {
        check_fits(path, num_vertices, face_size)?;
        let mut header = Vec::new();
        let declarations = Declarations {
            num_vertices,
            num_faces,
            normals: false,
            uv: false,
            wide_lists: false,
            levels: false,
            creases: 0,
            corners: 0,
            holes: 0,
        };
        write_header_start(&mut header, hints, PlyEncoding::BinaryLittleEndian)
            .and_then(|()| declarations.write(&mut header))
            .expect("writing to memory");
        let vertex_start = header.len() as u64;
        let face_start = vertex_start + POINT_BYTES * num_vertices;
        let end = face_start + (1 + 4 * face_size as u64) * num_faces;
        let file = crate::temp_beside(path)?;
        let placed = PlacedPly {
            file,
            writing: std::sync::Mutex::new(()),
            path: path.to_path_buf(),
            num_vertices,
            num_faces,
            face_size,
            vertex_start,
            face_start,
        };
        placed.write_at(0, &header)?;
        placed
            .file
            .as_file()
            .set_len(end)
            .map_err(|e| placed.error(e))?;
        Ok(placed)
    }

    /// Writes the positions of vertices `first..first + points.len()`.
    ///
    /// # Errors
    /// [`IoError::Write`]: the file cannot be written, or the vertices are beyond the count.
    pub fn write_points(&self, first: u64, points: &[DVec3]) -> Result<(), IoError> {
        if first + points.len() as u64 > self.num_vertices {
            return Err(self.beyond("vertex", first + points.len() as u64 - 1));
        }
        let offset = self.vertex_start + POINT_BYTES * first;
        if cfg!(target_endian = "little") {
            return self.write_at(offset, bytemuck::cast_slice(points));
        }
        let bytes: Vec<u8> = points
            .iter()
            .flat_map(|p| p.to_array())
            .flat_map(f64::to_le_bytes)
            .collect();
        self.write_at(offset, &bytes)
    }

    /// Writes faces `first..`, one per `face_size` entries of `corners` (vertex indices).
    ///
    /// # Errors
    /// [`IoError::Write`]: the file cannot be written, or the faces are beyond the count, or
    /// `corners` is not a whole number of faces.
    pub fn write_faces(&self, first: u64, corners: &[u32]) -> Result<(), IoError> {
        let n = self.face_size;
        let faces = (corners.len() / n) as u64;
        if corners.len() % n != 0 || first + faces > self.num_faces {
            return Err(self.beyond("face", first + faces));
        }
        let record = 1 + 4 * n;
        FACE_BYTES.with_borrow_mut(|bytes| {
            bytes.clear();
            bytes.reserve(corners.len() / n * record);
            for face in corners.chunks_exact(n) {
                bytes.push(n as u8);
                for &v in face {
                    bytes.extend_from_slice(&v.to_le_bytes());
                }
            }
            self.write_at(self.face_start + record as u64 * first, bytes)
        })
    }

    /// Puts the file in place of the target (every record should have been written: what
    /// was not reads as zeros).
    ///
    /// # Errors
    /// [`IoError::Write`] when the file cannot be renamed over the target.
    pub fn finish(self) -> Result<(), IoError> {
        let path = self.path;
        self.file
            .persist(&path)
            .map(drop)
            .map_err(|e| IoError::Write {
                path,
                source: e.error,
            })
    }

    fn write_at(&self, offset: u64, bytes: &[u8]) -> Result<(), IoError> {
        let _writing = self.writing.lock().unwrap_or_else(|p| p.into_inner());
        write_all_at(self.file.as_file(), bytes, offset).map_err(|e| self.error(e))
    }

    fn error(&self, source: std::io::Error) -> IoError {
        IoError::Write {
            path: self.path.clone(),
            source,
        }
    }

    fn beyond(&self, what: &str, index: u64) -> IoError {
        self.error(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("{what} {index} is beyond the counts in the header"),
        ))
    }
}

thread_local! {
    /// Each thread's encoded face records, kept between calls (a fresh buffer's first touch
    /// costs more than encoding into it).
    static FACE_BYTES: std::cell::RefCell<Vec<u8>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// PLY's limits: 32-bit vertex indices, a `uchar` face size.
pub(crate) fn check_fits(path: &Path, num_vertices: u64, face_size: usize) -> Result<(), IoError> {
    let message = if num_vertices > 1 << 32 {
        format!(
            "{num_vertices} vertices: PLY names vertices with 32-bit indices (at most 2^32 = 4294967296); refine fewer levels or split the input"
        )
    } else if face_size > 255 || face_size == 0 {
        format!("faces of {face_size} corners: a placed PLY takes 1 to 255")
    } else {
        return Ok(());
    };
    Err(IoError::Invalid {
        path: path.to_path_buf(),
        message,
    })
}

#[cfg(unix)]
pub(crate) fn write_all_at(file: &std::fs::File, bytes: &[u8], offset: u64) -> std::io::Result<()> {
    std::os::unix::fs::FileExt::write_all_at(file, bytes, offset)
}

#[cfg(windows)]
pub(crate) fn write_all_at(
    file: &std::fs::File,
    mut bytes: &[u8],
    mut offset: u64,
) -> std::io::Result<()> {
    while !bytes.is_empty() {
        let n = std::os::windows::fs::FileExt::seek_write(file, bytes, offset)?;
        if n == 0 {
            return Err(std::io::ErrorKind::WriteZero.into());
        }
        bytes = &bytes[n..];
        offset += n as u64;
    }
    Ok(())
}

#[cfg(unix)]
pub(crate) fn read_exact_at(
    file: &std::fs::File,
    out: &mut [u8],
    offset: u64,
) -> std::io::Result<()> {
    std::os::unix::fs::FileExt::read_exact_at(file, out, offset)
}

#[cfg(windows)]
pub(crate) fn read_exact_at(
    file: &std::fs::File,
    mut out: &mut [u8],
    mut offset: u64,
) -> std::io::Result<()> {
    while !out.is_empty() {
        let n = std::os::windows::fs::FileExt::seek_read(file, out, offset)?;
        if n == 0 {
            return Err(std::io::ErrorKind::UnexpectedEof.into());
        }
        out = &mut out[n..];
        offset += n as u64;
    }
    Ok(())
}
