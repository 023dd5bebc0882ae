//! A place on a table as weights of the base vertices ([`PatchTable::stencil`]): the
//! patch's basis over its control points, each refined or local point carried back to the
//! base through the table's own stencils.

use std::collections::BTreeMap;

use super::PatchType;
use super::exact_caps::CapStencil;
use super::patch_eval::patch_weights;
use super::table::PatchTable;
use crate::LimitError;
use crate::evaluation::eval::FaceParam;
use crate::evaluation::point_stencil::PointStencil;

impl PatchTable {
    /// The surface at `at` as weights over the base vertices: position and first and
    /// second derivatives, equal (to rounding) to [`Self::evaluate`] for any positions.
    ///
    /// # Errors
    /// As [`Self::evaluate`].
    pub fn stencil(&self, at: FaceParam) -> Result<PointStencil, LimitError> {
        let (_, a, i) = self.locate(&at)?;
        let array = &self.arrays()[a];
        let param = array.params()[i];
        let mut weights: BTreeMap<u32, [f64; 6]> = BTreeMap::new();
        if array.kind() == PatchType::Exact {
            match self.exact_cap_stencil(i, at)? {
                CapStencil::Base(stencil) => return Ok(stencil),
                CapStencil::OnLevel(level, pairs) => {
                    let first = self.level_offset(level);
                    for (v, w) in pairs {
                        add(&mut weights, first + v, &w, 1.0);
                    }
                }
            }
        } else {
            let w = patch_weights(array.kind(), param, at.u, at.v);
            for (k, &cp) in array.patch_points(i).iter().enumerate() {
                add(&mut weights, cp, &std::array::from_fn(|r| w[r][k]), 1.0);
            }
        }
        Ok(self.to_base(weights))
    }

    /// Weights over any of the table's points carried back to the base vertices: the
    /// highest point first, each replaced by its row (a local point's over refined
    /// vertices, a refined vertex's over the level above), which only names lower points.
    fn to_base(&self, mut weights: BTreeMap<u32, [f64; 6]>) -> PointStencil {
        let base = self.level_offset(1);
        while let Some((&p, _)) = weights.last_key_value() {
            if p < base {
                break;
            }
            let (_, w) = weights.pop_last().expect("a last entry");
            let (indices, row, first) = self.point_row(p);
            for (&q, &x) in indices.iter().zip(row) {
                add(&mut weights, first + q, &w, x);
            }
        }
        PointStencil::from_pairs(weights.into_iter().collect())
    }
}

/// `weights[p] += x · w`.
fn add(weights: &mut BTreeMap<u32, [f64; 6]>, p: u32, w: &[f64; 6], x: f64) {
    let acc = weights.entry(p).or_insert([0.0; 6]);
    for (a, b) in acc.iter_mut().zip(w) {
        *a += x * b;
    }
}
