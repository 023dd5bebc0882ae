//! The adaptive check: subd's adaptive refinement of random face selections, vertex by
//! vertex, against OpenSubdiv's uniform levels, and its closure invariants.

use subd_adaptive::{AdaptiveRefinement, Positions, RandomSelection};

use super::{Case, Row, TOLERANCE};

/// Adaptive refinement of random selections (two seeds, about 40 % of the faces of every
/// level) against OpenSubdiv's uniform levels: every output vertex must be OpenSubdiv's
/// vertex at its level and index (so it is found by position among that level's vertices),
/// and the output must pass the closure invariants — conforming (every edge used by as many
/// faces as in uniform refinement), levels of faces sharing an edge or a vertex at most one
/// apart.
pub fn compare(case: &Case) -> Row {
    let Case {
        name,
        topo,
        positions,
        scheme,
        options,
        diag,
        ..
    } = *case;
    let osd_levels = &case.uniform.osd_levels;
    let levels = osd_levels.len();
    let mut row = Row::pending(name, "adaptv", levels);
    let mut worst = 0.0f64;
    let mut vertices = 0;
    for seed in [1u64, 2] {
        let pick = RandomSelection::new(seed, 0.4).expect("a fraction in [0, 1]");
        let a = match AdaptiveRefinement::new(topo, positions, scheme, options, &[&pick], levels) {
            Ok(a) => a,
            Err(e) => {
                row.problem = Some(format!("subd: {e}"));
                return row;
            }
        };
        let mesh = match a.mesh(Positions::Refined) {
            Ok(m) => m,
            Err(e) => {
                row.problem = Some(format!("subd: {e}"));
                return row;
            }
        };
        for (v, (&l, &k)) in mesh
            .vertex_levels
            .iter()
            .zip(&mesh.vertex_uniform)
            .enumerate()
        {
            let theirs = if l == 0 {
                positions.get(k as usize)
            } else {
                osd_levels[l as usize - 1].positions.get(k as usize)
            };
            let Some(theirs) = theirs else {
                row.problem = Some(format!("level {l} vertex {k} is not in OpenSubdiv's level"));
                return row;
            };
            worst = worst.max((mesh.positions[v] - *theirs).abs().max_element() / diag);
        }
        let c = mesh.conformity();
        if !c.conforming || c.max_level_difference_edge > 1 || c.max_level_difference_vertex > 1 {
            row.problem = Some(format!("seed {seed}: closure invariants fail: {c:?}"));
            return row;
        }
        vertices += mesh.positions.len();
    }
    row.vertices = vertices;
    row.error = worst;
    if worst.is_nan() || worst > TOLERANCE {
        row.problem = Some("an output vertex is off OpenSubdiv's".into());
    }
    row
}
