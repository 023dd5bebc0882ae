//! The two-phase limit of Lin et al. in closed form (its formula (2)), for closed smooth quad
//! meshes: no refinement needed.
//!
//! Around a vertex `v` of valence `n` whose faces are all quads, with edge neighbours `e_j`
//! and face-diagonal vertices `f_j`, phase 1 gives the face points
//! `F'_j = (v + e_j + f_j + e_{j+1}) / 4`, the edge points `E'_j = (v + e_j + F'_{j−1} + F'_j) / 4`
//! and the vertex point `v' = λ v + (1 − λ)[α Σe/n + (1 − α) Σf/n]`. Catmull-Clark's limit
//! mask on that level, `(n² v' + 4 Σ E'_j + Σ F'_j) / (n (n + 5))`, then sums to
//!
//! ```text
//! v∞ = [ (n² λ + 7n/4) v + (n (1 − λ) α + 5/2) Σ e_j + (n (1 − λ)(1 − α) + 3/4) Σ f_j ] / (n (n + 5))
//! ```
//!
//! since `Σ F'_j = n v/4 + Σe/2 + Σf/4` and `4 Σ E'_j = 3n v/2 + 2 Σe + Σf/2`. With
//! `α = 10/13` the edge weight is the paper's `β_n = n (1 − λ) 10/13 + 5/2` and the face
//! weight `3 β_n / 10`. Only the row vertex's own `λ` enters (the face and edge points of
//! phase 1 do not depend on `λ`). Valence 2 is left to the general path, whose limit there
//! comes from the eigen analysis.

use subd_mesh::Topology;
use subd_schemes::StencilTable;
use subd_schemes::two_phase::ALPHA;

/// Whether formula (2) gives every vertex's two-phase limit: the mesh closed and smooth, all
/// faces quads with four distinct vertices, every vertex of valence at least 3
/// ([`Topology::is_closed_smooth_uniform`]).
pub(crate) fn applies(t: &Topology) -> bool {
    t.is_closed_smooth_uniform(4)
}

/// The limit-position table of formula (2), rows in the order of the general path's limit
/// masks (face-diagonal vertices, then edge neighbours, then the vertex). Call only where
/// [`applies`] holds.
pub(crate) fn positions(t: &Topology, lambda: &[f64]) -> StencilTable {
    StencilTable::build(t.num_vertices(), t.num_vertices(), |v, sink| {
        let (faces, edges) = (t.vertex_faces(v), t.vertex_edges(v));
        let (n, l) = (faces.len() as f64, lambda[v]);
        let scale = 1.0 / (n * (n + 5.0));
        let w_face = (n * (1.0 - l) * (1.0 - ALPHA) + 0.75) * scale;
        let w_edge = (n * (1.0 - l) * ALPHA + 2.5) * scale;
        let w_vertex = (n * n * l + 1.75 * n) * scale;
        let local = t.vertex_face_local_indices(v);
        for (&f, &k) in faces.iter().zip(local) {
            sink.add(t.face_vertices(f as usize)[(k as usize + 2) % 4], w_face);
        }
        for &e in edges {
            sink.add(t.edge_other_vertex(e as usize, v as u32), w_edge);
        }
        sink.add(v as u32, w_vertex);
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use subd_mesh::TopologyBuilder;
    use subd_schemes::{Options, Refinement, Scheme, TwoPhase};

    /// Rows as sorted (source, weight) lists.
    fn rows(t: &StencilTable) -> Vec<Vec<(u32, f64)>> {
        (0..t.num_rows())
            .map(|r| {
                let (c, w) = t.row(r);
                let mut row: Vec<(u32, f64)> = c.iter().copied().zip(w.iter().copied()).collect();
                row.sort_by_key(|e| e.0);
                row
            })
            .collect()
    }

    /// A closed quad mesh with valences 3, 4 and 6: a torus grid with quad pairs merged into
    /// hexagons, refined once by Catmull-Clark.
    fn mixed_torus() -> Topology {
        let base = subd_mesh::primitives::torus_with_hexagons(6, 8, 4, 3.0, 1.0);
        let r = Refinement::new(
            &base.topology,
            subd_schemes::Scheme::CatmullClark,
            &Options::default(),
            1,
        )
        .unwrap();
        r.into_topology(1)
    }

    #[test]
    fn formula_two_equals_phase_one_then_the_catmull_clark_limit() {
        let faces = [
            0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4,
        ];
        let cube = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
        let mut valences = Vec::new();
        for t in [cube, mixed_torus()] {
            let nv = t.num_vertices();
            valences.extend((0..nv).map(|v| t.vertex_faces(v).len()));
            let lambda: Vec<f64> = (0..nv)
                .map(|v| 0.36 + 0.64 * ((v * 5) % 9) as f64 / 8.0)
                .collect();
            let tp = TwoPhase::new(lambda.clone()).unwrap();
            assert!(applies(&t));
            let closed = rows(&positions(&t, &lambda));
            // The general path: phase 1 refined, Catmull-Clark limit masks there, composed back.
            let r = Refinement::new(&t, Scheme::TwoPhase(tp), &Options::default(), 1).unwrap();
            let general = rows(&crate::positions_through(&r, 1).unwrap());
            for v in 0..nv {
                assert_eq!(closed[v].len(), general[v].len(), "vertex {v}");
                for (a, b) in closed[v].iter().zip(&general[v]) {
                    assert_eq!(a.0, b.0, "vertex {v}");
                    assert!((a.1 - b.1).abs() < 1e-15, "vertex {v}: {} vs {}", a.1, b.1);
                }
                let sum: f64 = closed[v].iter().map(|e| e.1).sum();
                assert!((sum - 1.0).abs() < 1e-15);
            }
        }
        for n in [3, 4, 6] {
            assert!(valences.contains(&n), "no vertex of valence {n}");
        }
    }

    #[test]
    fn open_creased_or_valence_two_meshes_take_the_general_path() {
        // A single quad: boundary.
        let quad = TopologyBuilder::new(4).build(&[4], &[0, 1, 2, 3]).unwrap();
        assert!(!applies(&quad));
        // Two quads glued along their whole boundary: closed, every vertex of valence 2.
        let pillow = TopologyBuilder::new(4)
            .build(&[4, 4], &[0, 1, 2, 3, 3, 2, 1, 0])
            .unwrap();
        assert!(!applies(&pillow));
        // A cube qualifies; a wrong λ count is refused before the formula is reached.
        let faces = [
            0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4,
        ];
        let cube = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
        assert!(applies(&cube));
        let seven = TwoPhase::new(vec![0.5; 7]).unwrap();
        assert!(crate::two_phase_base_limit_positions(&cube, &seven, &Options::default()).is_err());
    }
}
