//! A mesh written record by record at its place, for any output format: positions and
//! faces of one size go into a scratch file of fixed-size records beside the target (24 bytes
//! a point, 4 a corner), from any thread and in any order, as a producer that makes a level
//! in pieces (depth-first refinement) hands them out; [`PlacedMesh::finish`] then encodes
//! the scratch file into the target's format a window at a time, in order, with the same
//! writer as [`crate::write_view`] (so the file is byte for byte the one a held mesh gives),
//! and removes it. Neither step holds the mesh. Binary little-endian PLY, whose records are
//! fixed-size themselves, is written in place without the scratch file
//! ([`crate::ply::PlacedPly`]).

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use subd_mesh::{DVec3, SchemeHints};

use crate::ply::placed::{read_exact_at, write_all_at};
use crate::view::{FaceSource, PointSource};
use crate::{IoError, MeshView, Points, WriteOptions};

/// Bytes of a point record: three little-endian `f64`s.
const POINT_BYTES: u64 = 24;

/// A mesh of `num_vertices` positions and `num_faces` faces of `face_size` corners whose
/// records are written at their places ([`Self::write_points`], [`Self::write_faces`]) and
/// then encoded into the target ([`Self::finish`]).
///
/// ```
/// use subd_io::PlacedMesh;
/// use subd_mesh::{DVec3, SchemeHints};
///
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("quad.obj");
/// let placed = PlacedMesh::create(&path, SchemeHints::default(), 4, 1, 4).unwrap();
/// placed.write_faces(0, &[0, 1, 2, 3]).unwrap();
/// placed.write_points(2, &[DVec3::new(1.0, 1.0, 0.0), DVec3::new(0.0, 1.0, 0.0)]).unwrap();
/// placed.write_points(0, &[DVec3::ZERO, DVec3::X]).unwrap();
/// placed.finish(&Default::default()).unwrap();
/// let mesh = subd_io::read_mesh(&path, &Default::default()).unwrap().mesh;
/// assert_eq!(mesh.positions[2], DVec3::new(1.0, 1.0, 0.0));
/// assert_eq!(mesh.topology.face_vertices(0), &[0, 1, 2, 3]);
/// assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "no scratch file left");
/// ```
#[derive(Debug)]
pub struct PlacedMesh {
    scratch: tempfile::NamedTempFile,
    /// Held while writing (the kernel serialises writes to one file anyway).
    writing: Mutex<()>,
    path: PathBuf,
    hints: SchemeHints,
    num_vertices: u64,
    num_faces: u64,
    face_size: usize,
    /// Byte offset of the first face record in the scratch file.
    face_start: u64,
}

impl PlacedMesh {
    /// A mesh for `path` (its format from the extension), with `hints`, and a scratch file
    /// beside it sized for the records.
    ///
    /// # Errors
    /// [`IoError::UnknownFormat`] for an extension no writer takes, [`IoError::Invalid`]
    /// when PLY cannot hold the mesh (checked here, before any record is made), and
    /// [`IoError::Write`] when the scratch file cannot be made.
    pub fn create(
        path: &Path,
        hints: SchemeHints,
        num_vertices: u64,
        num_faces: u64,
        face_size: usize,
    ) -> Result<PlacedMesh, IoError> {
        match crate::Format::for_output(path) {
            None => {
                return Err(IoError::UnknownFormat {
                    path: path.to_path_buf(),
                    expected: ".obj, .ply, .glb, .usda, .usdc, .usdz or .usd",
                });
            }
            Some(crate::Format::Ply) => {
                crate::ply::placed::check_fits(path, num_vertices, face_size)?;
            }
            Some(_) => {}
        }
        let scratch = crate::temp_beside(path)?;
        let face_start = POINT_BYTES * num_vertices;
        let end = face_start + 4 * face_size as u64 * num_faces;
        scratch
            .as_file()
            .set_len(end)
            .map_err(|source| IoError::Write {
                path: path.to_path_buf(),
                source,
            })?;
        Ok(PlacedMesh {
            scratch,
            writing: Mutex::new(()),
            path: path.to_path_buf(),
            hints,
            num_vertices,
            num_faces,
            face_size,
            face_start,
        })
    }

    /// Writes the positions of vertices `first..first + points.len()`.
    ///
    /// # Errors
    /// [`IoError::Write`]: the scratch file cannot be written, or the vertices are beyond the
    /// count.
    pub fn write_points(&self, first: u64, points: &[DVec3]) -> Result<(), IoError> {
        if first + points.len() as u64 > self.num_vertices {
            return Err(self.beyond("vertex", first + points.len() as u64 - 1));
        }
        let offset = POINT_BYTES * first;
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
    /// [`IoError::Write`]: the scratch file cannot be written, the faces are beyond the
    /// count, or `corners` is not a whole number of faces.
    pub fn write_faces(&self, first: u64, corners: &[u32]) -> Result<(), IoError> {
        let n = self.face_size;
        let faces = (corners.len() / n) as u64;
        if corners.len() % n != 0 || first + faces > self.num_faces {
            return Err(self.beyond("face", first + faces));
        }
        let offset = self.face_start + 4 * n as u64 * first;
        if cfg!(target_endian = "little") {
            return self.write_at(offset, bytemuck::cast_slice(corners));
        }
        let bytes: Vec<u8> = corners.iter().flat_map(|v| v.to_le_bytes()).collect();
        self.write_at(offset, &bytes)
    }

    /// Encodes the records (every one should have been written: what was not reads as
    /// zeros) into the target with `options`, then removes the scratch file.
    ///
    /// # Errors
    /// [`IoError::UnknownFormat`] for an extension no writer takes, [`IoError::Read`] when
    /// the scratch file cannot be read back, and the writer's errors.
    pub fn finish(self, options: &WriteOptions) -> Result<(), IoError> {
        let failed = Mutex::new(None);
        let records = Records {
            mesh: &self,
            failed: &failed,
        };
        let mut view = MeshView::streamed(Points::Streamed(&records), &records, Vec::new())
            .map_err(|e| self.beyond(&e.to_string(), 0))?;
        view.hints = self.hints;
        let written = crate::write_view(&self.path, &view, options);
        // A record that could not be read back fails the write as a bad value; the read's
        // own error says what happened.
        if let Some(source) = failed.into_inner().unwrap_or_else(|p| p.into_inner()) {
            return Err(IoError::Read {
                path: self.scratch.path().to_path_buf(),
                source,
            });
        }
        written
    }

    fn write_at(&self, offset: u64, bytes: &[u8]) -> Result<(), IoError> {
        let _writing = self.writing.lock().unwrap_or_else(|p| p.into_inner());
        write_all_at(self.scratch.as_file(), bytes, offset).map_err(|source| IoError::Write {
            path: self.path.clone(),
            source,
        })
    }

    fn beyond(&self, what: &str, index: u64) -> IoError {
        IoError::Write {
            path: self.path.clone(),
            source: std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!("{what} {index} is beyond the mesh's counts"),
            ),
        }
    }
}

/// The scratch file's records read back a window at a time, for the writer. A failed read
/// is kept and its window filled with values the view refuses (non-finite points, vertex
/// indices out of range), which stops the write.
struct Records<'a> {
    mesh: &'a PlacedMesh,
    failed: &'a Mutex<Option<std::io::Error>>,
}

impl Records<'_> {
    fn read(&self, offset: u64, out: &mut [u8]) -> bool {
        match read_exact_at(self.mesh.scratch.as_file(), out, offset) {
            Ok(()) => true,
            Err(e) => {
                let mut failed = self.failed.lock().unwrap_or_else(|p| p.into_inner());
                failed.get_or_insert(e);
                false
            }
        }
    }
}

impl PointSource for Records<'_> {
    fn len(&self) -> usize {
        self.mesh.num_vertices as usize
    }

    fn fill(&self, first: usize, out: &mut [DVec3]) {
        let offset = POINT_BYTES * first as u64;
        if cfg!(target_endian = "little") {
            // The records are the points' own bytes: read straight into them.
            if !self.read(offset, bytemuck::cast_slice_mut(out)) {
                out.fill(DVec3::NAN);
            }
            return;
        }
        let mut bytes = vec![0u8; out.len() * POINT_BYTES as usize];
        if !self.read(offset, &mut bytes) {
            out.fill(DVec3::NAN);
            return;
        }
        for (p, b) in out.iter_mut().zip(bytes.chunks_exact(POINT_BYTES as usize)) {
            let x = |k: usize| f64::from_le_bytes(b[8 * k..8 * k + 8].try_into().expect("8 bytes"));
            *p = DVec3::new(x(0), x(1), x(2));
        }
    }
}

impl FaceSource for Records<'_> {
    fn num_faces(&self) -> usize {
        self.mesh.num_faces as usize
    }

    fn face_size(&self) -> usize {
        self.mesh.face_size
    }

    fn fill(&self, faces: Range<usize>, out: &mut Vec<u32>) {
        let n = self.mesh.face_size;
        let offset = self.mesh.face_start + (4 * n * faces.start) as u64;
        if cfg!(target_endian = "little") {
            let start = out.len();
            out.resize(start + faces.len() * n, 0);
            if !self.read(offset, bytemuck::cast_slice_mut(&mut out[start..])) {
                out[start..].fill(u32::MAX);
            }
            return;
        }
        let mut bytes = vec![0u8; faces.len() * n * 4];
        if !self.read(offset, &mut bytes) {
            out.extend(std::iter::repeat_n(u32::MAX, faces.len() * n));
            return;
        }
        out.extend(
            bytes
                .chunks_exact(4)
                .map(|b| u32::from_le_bytes(b.try_into().expect("4 bytes"))),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What no writer takes, and what PLY cannot hold, is refused before a scratch file is
    /// made; out-of-range records are refused as they come.
    #[test]
    fn refusals_come_first() {
        let dir = tempfile::tempdir().unwrap();
        let unknown =
            PlacedMesh::create(&dir.path().join("a.xyz"), SchemeHints::default(), 3, 1, 3);
        assert!(matches!(unknown, Err(IoError::UnknownFormat { .. })));
        let huge = PlacedMesh::create(
            &dir.path().join("b.ply"),
            SchemeHints::default(),
            (1 << 32) + 1,
            1,
            3,
        );
        assert!(matches!(huge, Err(IoError::Invalid { .. })), "{huge:?}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        let placed =
            PlacedMesh::create(&dir.path().join("c.obj"), SchemeHints::default(), 3, 1, 3).unwrap();
        assert!(placed.write_points(2, &[DVec3::ZERO, DVec3::X]).is_err());
        assert!(placed.write_faces(0, &[0, 1]).is_err());
        assert!(placed.write_faces(1, &[0, 1, 2]).is_err());
        drop(placed);
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            0,
            "scratch removed"
        );
    }
}
