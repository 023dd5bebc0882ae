//! What a uniform tessellation produces: the output mesh with its samples' parameters and
//! each (sub-)face's grid of samples.

use glam::DVec3;

use crate::evaluation::eval::FaceParam;

/// A tessellated limit surface.
#[derive(Debug, Clone)]
pub struct Tessellation {
    /// Positions on the limit surface.
    pub positions: Vec<DVec3>,
    /// Unit normals there (zero where the surface has no tangent plane).
    pub normals: Vec<DVec3>,
    /// Where each sample was evaluated.
    pub params: Vec<FaceParam>,
    /// Face offsets into [`Self::face_vertices`]: quads (Catmull-Clark) or triangles (Loop).
    pub face_offsets: Vec<u32>,
    /// Vertices of each output face, counter-clockwise as the base face.
    pub face_vertices: Vec<u32>,
    /// Each tessellated (face, sub-face) with its grid of samples, in face order.
    pub grids: Vec<SampleGrid>,
    /// The samples of every grid, row by row (`v` rows of `u`), as vertex indices.
    pub grid_vertices: Vec<u32>,
}

/// The samples of one face (or sub-face): the vertex at (u, v) = (i, j) / `segments` is
/// `grid_vertices[start + index]`, where `index` is `j (segments + 1) + i` on a quad and
/// `j (2 segments + 3 − j) / 2 + i` (i + j ≤ segments) on a triangle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleGrid {
    /// Base face.
    pub face: usize,
    /// Sub-face (0 for quads and triangles).
    pub sub: usize,
    /// Segments per side.
    pub segments: u32,
    /// Offset of its first sample in [`Tessellation::grid_vertices`].
    pub start: u32,
}

impl Tessellation {
    /// The output vertex at grid point (i, j) of `grid` (see [`SampleGrid`]).
    pub fn grid_vertex(&self, grid: &SampleGrid, triangle: bool, i: u32, j: u32) -> u32 {
        let n = grid.segments;
        let index = if triangle {
            j * (2 * n + 3 - j) / 2 + i
        } else {
            j * (n + 1) + i
        };
        self.grid_vertices[(grid.start + index) as usize]
    }
}

/// The samples of a tessellation before evaluation.
pub(crate) struct Numbered {
    /// The parameter of each sample.
    pub params: Vec<FaceParam>,
    /// The output faces and grids over the samples (positions and normals left empty).
    pub out: Tessellation,
}
