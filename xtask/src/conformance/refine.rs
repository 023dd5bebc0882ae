//! The refine check: subd's uniform refinement against OpenSubdiv's, level by level — the
//! same vertex and face counts, the same face-vertex lists and positions within
//! [`TOLERANCE`] of the bounding-box diagonal.

use std::path::Path;

use subd_mesh::{DVec3, Topology};
use subd_schemes::{Options, Refinement, Scheme};

use super::{Case, Row, TOLERANCE, levels_for};
use crate::oracles::osd;

/// Both uniform refinements of a mesh, [`levels_for`] levels deep.
pub struct Uniform {
    /// OpenSubdiv's levels 1..=L.
    pub osd_levels: Vec<osd::OsdLevel>,
    /// subd's refinement to the same level.
    pub refinement: Refinement,
}

impl Uniform {
    /// Runs OpenSubdiv, then subd; where either fails, the `Err` is the problem of the
    /// mesh's only row (a refine row at level 0).
    pub fn new(
        exe: &Path,
        topo: &Topology,
        positions: &[DVec3],
        scheme: &Scheme,
        options: &Options,
    ) -> Result<Uniform, String> {
        let levels = levels_for(topo, scheme);
        let input = osd::encode(topo, positions, scheme, options, levels as u32);
        let osd_levels = osd::run(exe, &input, &[])
            .and_then(|b| osd::decode(&b, levels))
            .map_err(|e| format!("OpenSubdiv: {e}"))?;
        let refinement = Refinement::new(topo, scheme.clone(), options, levels)
            .map_err(|e| format!("subd: {e}"))?;
        Ok(Uniform {
            osd_levels,
            refinement,
        })
    }
}

/// One row per level.
pub fn compare(case: &Case) -> Vec<Row> {
    let ours = case.uniform.refinement.refine_points(case.positions);
    case.uniform
        .osd_levels
        .iter()
        .enumerate()
        .map(|(l, theirs)| level_row(case, l + 1, &ours[l + 1], theirs))
        .collect()
}

/// The row of one level: topology first, positions only where it matches.
fn level_row(case: &Case, level: usize, ours: &[DVec3], o: &osd::OsdLevel) -> Row {
    let t = case.uniform.refinement.topology(level);
    let mut problem = topology_mismatch(t, o);
    let error = if problem.is_none() {
        ours.iter()
            .zip(&o.positions)
            .map(|(a, b)| (*a - *b).abs().max_element())
            .fold(0.0, f64::max)
            / case.diag
    } else {
        f64::INFINITY
    };
    if problem.is_none() && (error.is_nan() || error > TOLERANCE) {
        let v = ours
            .iter()
            .zip(&o.positions)
            .enumerate()
            .max_by(|a, b| {
                let da = (*a.1.0 - *a.1.1).abs().max_element();
                let db = (*b.1.0 - *b.1.1).abs().max_element();
                da.total_cmp(&db)
            })
            .map(|x| x.0)
            .unwrap_or(0);
        problem = Some(format!("worst vertex {v}"));
    }
    Row {
        mesh: case.name.to_string(),
        check: "refine",
        level,
        vertices: t.num_vertices(),
        error,
        normal_error: None,
        excluded: None,
        note: None,
        problem,
    }
}

/// How subd's level `t` differs from OpenSubdiv's `o` in counts or face-vertex lists.
fn topology_mismatch(t: &Topology, o: &osd::OsdLevel) -> Option<String> {
    if t.num_vertices() != o.positions.len() {
        Some(format!(
            "{} vertices, OpenSubdiv {}",
            t.num_vertices(),
            o.positions.len()
        ))
    } else if t.num_faces() != o.face_sizes.len() {
        Some(format!(
            "{} faces, OpenSubdiv {}",
            t.num_faces(),
            o.face_sizes.len()
        ))
    } else if t.all_face_vertices() != o.face_vertices.as_slice() {
        let f = (0..t.num_faces())
            .find(|&f| {
                let a = t.face_offsets()[f] as usize;
                let b = t.face_offsets()[f + 1] as usize;
                t.all_face_vertices()[a..b]
                    != o.face_vertices[a.min(o.face_vertices.len())..b.min(o.face_vertices.len())]
            })
            .unwrap_or(0);
        Some(format!("face-vertex lists differ (first at face {f})"))
    } else {
        None
    }
}
