//! A refinement's last level as sources the writers stream from: the point and face
//! streams of `subd-schemes` behind `subd-io`'s source traits (neither crate knows the
//! other).

use subd_mesh::DVec3;

/// The last level's points, made a window at a time.
pub(crate) struct Points<'a>(pub subd_schemes::PointStream<'a>);

impl Points<'_> {
    /// Every point at once, for writers that need them all (`.glb` normals).
    pub(crate) fn all(&self) -> Vec<DVec3> {
        let mut out = vec![DVec3::ZERO; self.0.len()];
        self.0.fill(0, &mut out);
        out
    }
}

impl subd_io::PointSource for Points<'_> {
    fn len(&self) -> usize {
        self.0.len()
    }

    fn fill(&self, first: usize, out: &mut [DVec3]) {
        self.0.fill(first, out);
    }
}

/// The last level's faces, made a window at a time.
pub(crate) struct Faces<'a>(pub subd_schemes::FaceStream<'a>);

impl subd_io::FaceSource for Faces<'_> {
    fn num_faces(&self) -> usize {
        self.0.num_faces()
    }

    fn face_size(&self) -> usize {
        self.0.face_size()
    }

    fn fill(&self, faces: std::ops::Range<usize>, out: &mut Vec<u32>) {
        self.0.fill(faces, out);
    }
}
