//! Uniform tessellation of the limit surface: every face sampled on a regular grid of `rate`
//! segments per base edge, in OpenSubdiv's parameterisation (as `Bfr::Tessellation` with a
//! uniform rate), into one watertight mesh.
//!
//! * A Catmull-Clark quad: an (N + 1)² grid of quads over (u, v) = (i/N, j/N).
//! * A Catmull-Clark face of n ≠ 4 sides: its n quad sub-faces (`FaceParam::sub`, the quad at
//!   each corner after one step, as `Bfr`'s quad sub-faces), each an (N/2 + 1)² grid, so its
//!   edges get N segments like a quad's. N must be even then.
//! * A Loop triangle: the barycentric grid (i/N, j/N), i + j ≤ N, of N² triangles.
//! * Hole faces are left out.
//!
//! Watertight by construction: a sample on a base vertex, on a base edge or on a sub-face
//! boundary is evaluated once, from the first face that reaches it, and shared by index, so
//! the two sides of an edge hold the same bits and a closed input gives a closed, manifold
//! output.
//!
//! Two passes: the samples are numbered first (faces in order, each sample on a base
//! vertex or edge with the parameter of the first face that reaches it; computed in parallel
//! from closed-form counts, [`crate::sample_numbering`]), then evaluated in parallel; each
//! sample's value depends only on its own parameter, so any number of threads gives the same
//! bits.

use glam::DVec3;
use subd_mesh::Topology;
use subd_schemes::{Options, Scheme};

use super::numbering::number_samples;
use super::output::{Numbered, Tessellation};
use crate::LimitError;
use crate::limit_evaluator::{LimitEvaluator, PatchPoints};
use crate::patch_table::{PatchTable, TablePoints};

/// The largest rate accepted.
pub const MAX_RATE: usize = 1024;

/// Tessellates the limit surface of `points` (from [`LimitEvaluator::prepare`]) at `rate`.
///
/// # Errors
/// A rate of 0 or above [`MAX_RATE`], an odd rate on a Catmull-Clark mesh with non-quad
/// faces, and the evaluator's errors (a face it does not cover) naming the face.
///
/// ```
/// use subd_limit::eval::LimitEvaluator;
/// use subd_limit::tessellation::tessellate;
/// use subd_mesh::{DVec3, TopologyBuilder};
/// use subd_schemes::{Options, Scheme};
///
/// let faces = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4];
/// let cube = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
/// let s = [(-1., -1., 1.), (1., -1., 1.), (-1., 1., 1.), (1., 1., 1.),
///          (-1., 1., -1.), (1., 1., -1.), (-1., -1., -1.), (1., -1., -1.)];
/// let p: Vec<DVec3> = s.iter().map(|&(x, y, z)| DVec3::new(x, y, z)).collect();
/// let eval = LimitEvaluator::new(&cube, &Scheme::CatmullClark, &Options::default()).unwrap();
/// let t = tessellate(&eval, &eval.prepare(&p), 4).unwrap();
/// assert_eq!(t.face_offsets.len() - 1, 6 * 16);
/// // Shared samples: V - E + F = 2 for the closed grid, 6·16 quads.
/// assert_eq!(t.positions.len(), 6 * 16 + 2);
/// ```
pub fn tessellate(
    evaluator: &LimitEvaluator,
    points: &PatchPoints,
    rate: usize,
) -> Result<Tessellation, LimitError> {
    sample_table(evaluator.table(), &points.table, rate)
}

/// The surface of a patch table sampled as [`tessellate`] samples the exact limit: the same
/// samples, faces and grids, each sample evaluated on the table (its regular patches and
/// end caps, OpenSubdiv's approximation where its end caps approximate).
///
/// # Errors
/// As [`tessellate`].
pub fn tessellate_patches(table: &PatchTable, rate: usize) -> Result<Tessellation, LimitError> {
    sample_table(table, table.own_points(), rate)
}

/// The samples of a uniform tessellation at `rate`, evaluated on `table` with its points
/// `points`.
fn sample_table(
    table: &PatchTable,
    points: &TablePoints,
    rate: usize,
) -> Result<Tessellation, LimitError> {
    let topo = table.base_topology();
    let loop_scheme = *table.scheme() == Scheme::Loop;
    check_rate(topo, loop_scheme, rate)?;
    let Numbered {
        params, mut out, ..
    } = number_samples(topo, loop_scheme, rate as u32);
    (out.positions, out.normals) = table.evaluate_grid_samples(points, &params, rate as u32)?;
    out.params = params;
    Ok(out)
}

/// Tessellates the limit surface of `positions` on `topology` at `rate`, as [`tessellate`]
/// does with an evaluator of the mesh: the same samples, faces and grids, the same values to
/// rounding, evaluated on a patch table that is the exact limit
/// ([`PatchTable::exact_limit`], [`tessellate_patches`]): each patch's control points
/// gathered once for its samples, the basis computed once per rate.
///
/// ```
/// use subd_limit::tessellation::tessellate_mesh;
/// use subd_mesh::{DVec3, TopologyBuilder};
/// use subd_schemes::{Options, Scheme};
///
/// let faces = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4];
/// let cube = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
/// let p: Vec<DVec3> = (0..8)
///     .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
///     .collect();
/// let t = tessellate_mesh(&cube, &Scheme::CatmullClark, &Options::default(), &p, 8).unwrap();
/// assert_eq!(t.face_offsets.len() - 1, 6 * 64);
/// assert_eq!(t.positions.len(), 6 * 64 + 2);
/// ```
///
/// # Errors
/// As [`tessellate`], and [`LimitError::Param`] when `positions` does not hold one point
/// per vertex of `topology`.
pub fn tessellate_mesh(
    topology: &Topology,
    scheme: &Scheme,
    options: &Options,
    positions: &[DVec3],
    rate: usize,
) -> Result<Tessellation, LimitError> {
    check_range(rate)?;
    let table = PatchTable::exact_limit(topology, positions, scheme, options)?;
    tessellate_patches(&table, rate)
}

/// Checks `rate`: 1 to [`MAX_RATE`], even where a Catmull-Clark face is not a quad.
pub(crate) fn check_rate(
    topo: &Topology,
    loop_scheme: bool,
    rate: usize,
) -> Result<(), LimitError> {
    check_range(rate)?;
    if !loop_scheme && rate % 2 == 1 {
        if let Some(f) = (0..topo.num_faces()).find(|&f| topo.face_size(f) != 4 && !topo.is_hole(f))
        {
            return Err(LimitError::Param(format!(
                "rate {rate}: face {f} is not a quad, and its quad sub-faces take half the rate each; use an even rate"
            )));
        }
    }
    Ok(())
}

/// Checks that `rate` is 1 to [`MAX_RATE`].
fn check_range(rate: usize) -> Result<(), LimitError> {
    if rate == 0 || rate > MAX_RATE {
        return Err(LimitError::Param(format!(
            "rate {rate}: expected 1 to {MAX_RATE}"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use subd_schemes::Options;

    #[test]
    fn one_thread_gives_the_same_bits_as_many() {
        let mesh = subd_mesh::primitives::torus_with_hexagons(12, 8, 4, 3.0, 1.0);
        let ev = LimitEvaluator::new(&mesh.topology, &Scheme::CatmullClark, &Options::default())
            .unwrap();
        let pts = ev.prepare(&mesh.positions);
        let many = tessellate(&ev, &pts, 6).unwrap();
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| tessellate(&ev, &pts, 6).unwrap());
        assert_eq!(many.positions, one.positions);
        assert_eq!(many.normals, one.normals);
        assert_eq!(many.face_vertices, one.face_vertices);
        // Every sample of every grid is an output vertex at its own parameter.
        for g in &many.grids {
            let v = many.grid_vertex(g, false, 0, 0) as usize;
            let at = many.params[v];
            let p = ev.evaluate(&pts, at).unwrap().position;
            assert!((p - many.positions[v]).length() < 1e-14);
        }
    }
}
