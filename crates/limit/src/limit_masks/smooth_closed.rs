//! Limit positions on closed smooth meshes straight from the classical masks, without
//! refining or classifying.
//!
//! Where [`Topology::is_closed_smooth_uniform`] holds (quads for Catmull-Clark, triangles
//! for Loop) every vertex takes its scheme's smooth rule at level 0, so its limit position is
//! the classical smooth mask over its one-ring ([`masks::catmark_smooth`],
//! [`masks::loop_smooth`]). That is the mask the general path picks for it after building
//! level 0's rules and classifying every vertex; written from the same masks in the same
//! order, the table is the same bit for bit.

use rayon::prelude::*;
use subd_mesh::Topology;
use subd_schemes::{Scheme, StencilTable};

use crate::limit_masks::masks::{self, RingMask};
use crate::limit_masks::table::emit;

/// Faces or vertices per parallel block.
const CHUNK: usize = 4096;

/// Whether every vertex's limit position is its scheme's classical smooth mask.
pub(crate) fn applies(t: &Topology, scheme: &Scheme) -> bool {
    match scheme {
        Scheme::CatmullClark => t.is_closed_smooth_uniform(4),
        Scheme::Loop => t.is_closed_smooth_uniform(3),
        _ => false,
    }
}

/// The limit-position table from the classical masks. Call only where [`applies`] holds.
pub(crate) fn positions(t: &Topology, scheme: &Scheme) -> StencilTable {
    let nv = t.num_vertices();
    let valence = |v: usize| t.vertex_faces(v).len();
    let most = (0..nv)
        .into_par_iter()
        .with_min_len(CHUNK)
        .map(valence)
        .max()
        .unwrap_or(0);
    // One mask per valence that occurs (a fan of high valence would make every smaller one
    // costly to compute for nothing).
    let mut present = vec![false; most + 1];
    for v in 0..nv {
        present[valence(v)] = true;
    }
    let by_valence: Vec<Option<RingMask>> = present
        .iter()
        .enumerate()
        .map(|(n, &p)| {
            p.then(|| match scheme {
                Scheme::Loop => masks::loop_smooth(n).position,
                _ => masks::catmark_smooth(n).position,
            })
        })
        .collect();
    StencilTable::build(nv, nv, |v, sink| {
        let mask = by_valence[valence(v)]
            .as_ref()
            .expect("a mask for every valence present");
        emit(t, v, mask, sink);
    })
}
