//! The last level of a refinement a range at a time: its faces from the level above (or
//! the one above that), its points from the points of the level above, so a writer can
//! stream a deep level to a file without the level ever being held whole.

use std::ops::Range;

use glam::DVec3;
use rayon::prelude::*;
use subd_mesh::Topology;

use super::fused::{
    CatmarkGrandchildRows, LoopGrandchildRows, grandchild_quad_block, grandchild_triangle_block,
};
use super::rows::{self, PointRows};
use super::{CHUNK, Step, StepRows, split};

/// Parent faces per parallel task when producing faces.
const FACES_PER_TASK: usize = 1024;

/// How the last level's faces follow from the level they are computed from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum FaceRule {
    /// Catmull-Clark and Bilinear: one quad per corner of each parent face.
    QuadSplit,
    /// Loop: four triangles per parent triangle.
    TriSplit,
    /// Catmull-Clark from the grandparent: 16 quads per grandparent quad.
    GrandchildQuads,
    /// Loop from the grandparent: 16 triangles per grandparent triangle.
    GrandchildTriangles,
}

/// The faces of a refinement's last level, produced a range at a time
/// ([`crate::Refinement::face_stream`]); the same lists as [`crate::Refinement::faces`].
///
/// Every face of a refined level has the same size ([`Self::face_size`]): quads for
/// Catmull-Clark and Bilinear, triangles for Loop.
#[derive(Clone, Copy, Debug)]
pub struct FaceStream<'a> {
    from: &'a Topology,
    rule: FaceRule,
}

impl<'a> FaceStream<'a> {
    pub(crate) fn quad_split(parent: &'a Topology) -> Self {
        FaceStream {
            from: parent,
            rule: FaceRule::QuadSplit,
        }
    }

    pub(crate) fn tri_split(parent: &'a Topology) -> Self {
        FaceStream {
            from: parent,
            rule: FaceRule::TriSplit,
        }
    }

    pub(crate) fn grandchild(grandparent: &'a Topology, quads: bool) -> Self {
        FaceStream {
            from: grandparent,
            rule: if quads {
                FaceRule::GrandchildQuads
            } else {
                FaceRule::GrandchildTriangles
            },
        }
    }

    /// Corners of every face: 4 or 3.
    pub fn face_size(&self) -> usize {
        match self.rule {
            FaceRule::QuadSplit | FaceRule::GrandchildQuads => 4,
            FaceRule::TriSplit | FaceRule::GrandchildTriangles => 3,
        }
    }

    /// Number of faces.
    pub fn num_faces(&self) -> usize {
        self.first_child(self.from.num_faces())
    }

    /// The first child face of face `f` of the level the faces come from (`f` may be one
    /// past the last face).
    fn first_child(&self, f: usize) -> usize {
        match self.rule {
            FaceRule::QuadSplit => self.from.face_offsets()[f] as usize,
            FaceRule::TriSplit => 4 * f,
            FaceRule::GrandchildQuads | FaceRule::GrandchildTriangles => 16 * f,
        }
    }

    /// The face of the level the faces come from that child face `c` descends from.
    fn parent_of(&self, c: usize) -> usize {
        match self.rule {
            FaceRule::QuadSplit => {
                self.from
                    .face_offsets()
                    .partition_point(|&o| o as usize <= c)
                    - 1
            }
            FaceRule::TriSplit => c / 4,
            FaceRule::GrandchildQuads | FaceRule::GrandchildTriangles => c / 16,
        }
    }

    /// Appends the children of source face `f` to `out`.
    fn push_children(&self, f: usize, out: &mut Vec<u32>) {
        let p = self.from;
        match self.rule {
            FaceRule::QuadSplit => {
                let at = out.len();
                out.resize(at + 4 * p.face_size(f), 0);
                split::quad_face_block(p, f..f + 1, &mut out[at..], None);
            }
            FaceRule::TriSplit => out.extend_from_slice(&split::tri_child_vertices(p, f)),
            FaceRule::GrandchildQuads => out.extend_from_slice(&grandchild_quad_block(p, f)),
            FaceRule::GrandchildTriangles => {
                out.extend_from_slice(&grandchild_triangle_block(p, f))
            }
        }
    }

    /// Appends the vertices of faces `faces` to `out`, [`Self::face_size`] per face, in
    /// parallel.
    ///
    /// # Panics
    /// If `faces` reaches beyond [`Self::num_faces`].
    pub fn fill(&self, faces: Range<usize>, out: &mut Vec<u32>) {
        assert!(
            faces.start <= faces.end && faces.end <= self.num_faces(),
            "face range {faces:?} beyond the {} faces",
            self.num_faces()
        );
        if faces.is_empty() {
            return;
        }
        let (first, last) = (self.parent_of(faces.start), self.parent_of(faces.end - 1));
        let blocks: Vec<Vec<u32>> = (first..last + 1)
            .into_par_iter()
            .with_min_len(FACES_PER_TASK)
            .fold(Vec::new, |mut v, f| {
                self.push_children(f, &mut v);
                v
            })
            .collect();
        // Trim the children of the first and last source faces to the range asked for.
        let k = self.face_size();
        let mut skip = k * (faces.start - self.first_child(first));
        let mut take = k * faces.len();
        out.reserve(take);
        for b in &blocks {
            let from = skip.min(b.len());
            let n = take.min(b.len() - from);
            out.extend_from_slice(&b[from..from + n]);
            skip -= from;
            take -= n;
        }
    }

    /// Writes the vertices of every face into `out` ([`Self::face_size`] per face), each
    /// index converted by `convert`, in parallel: the whole level written once into the
    /// buffer that keeps it (a numpy array of another index type, say), with no list of
    /// `u32` in between.
    ///
    /// # Panics
    /// If `out` does not hold exactly [`Self::num_faces`] × [`Self::face_size`] indices.
    pub fn write_all<T: Send>(&self, out: &mut [T], convert: impl Fn(u32) -> T + Sync) {
        let k = self.face_size();
        assert_eq!(
            out.len(),
            k * self.num_faces(),
            "{} indices for {} faces of {k}",
            out.len(),
            self.num_faces()
        );
        // The output of every run of source faces, cut off the front of `out` in order.
        let sources = self.from.num_faces();
        let mut tasks = Vec::with_capacity(sources.div_ceil(FACES_PER_TASK));
        let mut rest = out;
        for start in (0..sources).step_by(FACES_PER_TASK) {
            let end = (start + FACES_PER_TASK).min(sources);
            let len = k * (self.first_child(end) - self.first_child(start));
            let (mine, after) = rest.split_at_mut(len);
            tasks.push((start..end, mine));
            rest = after;
        }
        tasks.into_par_iter().for_each(|(faces, out)| {
            let mut block = Vec::new();
            let mut at = 0;
            for f in faces {
                block.clear();
                self.push_children(f, &mut block);
                for (slot, &v) in out[at..at + block.len()].iter_mut().zip(&block) {
                    *slot = convert(v);
                }
                at += block.len();
            }
        });
    }

    /// The faces that are holes: the children of hole faces, in order.
    pub fn hole_faces(&self) -> Vec<usize> {
        let p = self.from;
        (0..p.num_faces())
            .filter(|&f| p.is_hole(f))
            .flat_map(|f| self.first_child(f)..self.first_child(f + 1))
            .collect()
    }
}

/// How the last level's points follow from the points of the level above.
enum PointRule<'a> {
    /// One refinement step, with every rule.
    Step(Step<'a>),
    /// A closed smooth Catmull-Clark level from its grandparent's topology.
    CatmarkGrandchild(CatmarkGrandchildRows<'a>),
    /// A closed smooth Loop level from its grandparent's topology.
    LoopGrandchild(LoopGrandchildRows<'a>),
}

/// The points of a refinement's last level, produced a range at a time
/// ([`crate::Refinement::point_stream`]), bit for bit those of
/// [`crate::Refinement::refine_points`]. Holds the level's face points (which the other
/// points read) and borrows the points of the level above.
pub struct PointStream<'a> {
    rule: PointRule<'a>,
    src: &'a [DVec3],
    middle: Vec<DVec3>,
}

impl<'a> PointStream<'a> {
    pub(crate) fn step(step: Step<'a>, src: &'a [DVec3]) -> Self {
        let middle = rows::build_middle(&StepRows { step: &step, src });
        PointStream {
            rule: PointRule::Step(step),
            src,
            middle,
        }
    }

    pub(crate) fn catmark_grandchild(g: &'a Topology, src: &'a [DVec3]) -> Self {
        let r = CatmarkGrandchildRows::new(g, src);
        let middle = rows::build_middle(&r);
        PointStream {
            rule: PointRule::CatmarkGrandchild(r),
            src,
            middle,
        }
    }

    pub(crate) fn loop_grandchild(g: &'a Topology, src: &'a [DVec3]) -> Self {
        let r = LoopGrandchildRows::new(g, src);
        PointStream {
            rule: PointRule::LoopGrandchild(r),
            src,
            middle: Vec::new(),
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        match &self.rule {
            PointRule::Step(s) => StepRows {
                step: s,
                src: self.src,
            }
            .len(),
            PointRule::CatmarkGrandchild(r) => r.len(),
            PointRule::LoopGrandchild(r) => r.len(),
        }
    }

    /// Whether the level has no points.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Writes points `first..first + out.len()` into `out`, in parallel.
    ///
    /// # Panics
    /// If the range reaches beyond [`Self::len`].
    pub fn fill(&self, first: usize, out: &mut [DVec3]) {
        assert!(
            first + out.len() <= self.len(),
            "points {first}..{} beyond the {}",
            first + out.len(),
            self.len()
        );
        match &self.rule {
            PointRule::Step(s) => self.fill_rows(
                &StepRows {
                    step: s,
                    src: self.src,
                },
                first,
                out,
            ),
            PointRule::CatmarkGrandchild(r) => self.fill_rows(r, first, out),
            PointRule::LoopGrandchild(r) => self.fill_rows(r, first, out),
        }
    }

    fn fill_rows(&self, rows: &impl PointRows, first: usize, out: &mut [DVec3]) {
        let m = rows.middle();
        out.par_iter_mut()
            .with_min_len(CHUNK)
            .enumerate()
            .for_each(|(i, o)| {
                let r = first + i;
                *o = if m.contains(&r) {
                    self.middle[r - m.start]
                } else {
                    rows.row(r, &self.middle)
                };
            });
    }
}
