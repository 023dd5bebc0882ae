//! The base vertices a face's limit surface reads, and the weights of a linear evaluation
//! over them.

use glam::DVec3;
use subd_mesh::Topology;

use crate::LimitError;
use crate::evaluation::patch::SurfacePoint;

/// Vertices of the faces around the vertices of face `f`, ascending.
pub(crate) fn face_support(t: &Topology, f: usize) -> Vec<u32> {
    let mut out = Vec::new();
    for &v in t.face_vertices(f) {
        for &g in t.vertex_faces(v as usize) {
            out.extend_from_slice(t.face_vertices(g as usize));
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// The weights of `support` in `eval`, a linear function of `n` points that reads only
/// `support`, by evaluating with unit vectors three vertices at a time.
pub(crate) fn linear_weights(
    scratch: &mut Vec<DVec3>,
    n: usize,
    support: &[u32],
    mut eval: impl FnMut(&[DVec3]) -> Result<SurfacePoint, LimitError>,
) -> Result<Vec<(u32, [f64; 6])>, LimitError> {
    if scratch.len() < n {
        scratch.resize(n, DVec3::ZERO);
    }
    let mut out = Vec::with_capacity(support.len());
    for chunk in support.chunks(3) {
        for (k, &v) in chunk.iter().enumerate() {
            scratch[v as usize] = DVec3::AXES[k];
        }
        let p = eval(&scratch[..n]);
        for &v in chunk {
            scratch[v as usize] = DVec3::ZERO;
        }
        let p = p?;
        for (k, &v) in chunk.iter().enumerate() {
            out.push((
                v,
                [
                    p.position[k],
                    p.du[k],
                    p.dv[k],
                    p.duu[k],
                    p.duv[k],
                    p.dvv[k],
                ],
            ));
        }
    }
    Ok(out)
}

/// The factors that take position and first and second derivatives through a parameter
/// map of scale `scale`: 1, `scale` twice, `scale²` three times.
pub(crate) fn derivative_factors(scale: f64) -> [f64; 6] {
    let s2 = scale * scale;
    [1.0, scale, scale, s2, s2, s2]
}
