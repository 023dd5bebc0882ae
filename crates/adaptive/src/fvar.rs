//! Face-varying values (UVs) of the conforming mesh: each face-vertex takes the channel's
//! exact limit value at its parameter on the base face ([`FVarEvaluator`]).
//!
//! One value per parameter, whatever the level of the faces around a vertex: a refined value
//! depends on its level, and a vertex shared by a leaf and a finer transition face would get
//! two, tearing the texture along the transition. The limit is the same from every level.

use subd_limit::eval::FaceParam;
use subd_limit::fvar_eval::{FVarEvaluator, FVarPatchValues, FVarPoint};

use crate::{AdaptiveError, AdaptiveMesh};

/// A face-varying channel of an [`AdaptiveMesh`]: values, and one index per face-vertex.
/// Face-vertices of one vertex with the same value share it; across a seam a vertex has one
/// value per side.
#[derive(Clone, Debug, PartialEq)]
pub struct AdaptiveFVar {
    /// Numbers per value.
    pub components: usize,
    /// The values, `components` numbers each.
    pub values: Vec<f64>,
    /// The value of every face-vertex of the mesh.
    pub indices: Vec<u32>,
}

impl AdaptiveMesh {
    /// The limit values of a channel at every face-vertex, from an evaluator of the base mesh
    /// the hierarchy was built on ([`subd_limit::eval::LimitEvaluator::face_varying`]) and its
    /// prepared values. Faces the limit surface does not cover (holes) take the bilinear
    /// interpolation of their base face's corner values ([`FVarEvaluator::evaluate_linear`]).
    ///
    /// # Errors
    /// [`AdaptiveError::Limit`] when a point cannot be evaluated (a non-manifold neighbourhood
    /// the exact evaluator does not cover).
    pub fn face_varying_limit(
        &self,
        evaluator: &FVarEvaluator,
        values: &FVarPatchValues,
    ) -> Result<AdaptiveFVar, AdaptiveError> {
        use rayon::prelude::*;
        let c = evaluator.components();
        let num_corners = self.face_vertices.len();
        // Every face-vertex's value, in parallel, one scratch point per thread.
        let mut corner_values = vec![0.0; c * num_corners];
        let face_of: Vec<u32> = (0..self.num_faces() as u32)
            .flat_map(|f| {
                let n = self.face_offsets[f as usize + 1] - self.face_offsets[f as usize];
                std::iter::repeat_n(f, n as usize)
            })
            .collect();
        corner_values
            .par_chunks_mut(c)
            .enumerate()
            .try_for_each_init(FVarPoint::default, |point, (i, out)| {
                let f = face_of[i] as usize;
                let k = i - self.face_offsets[f] as usize;
                let (face, sub) = self.face_domains[f];
                let [u, v] = self.corner_params[i];
                // A whole base face that is not a quad: its corners are its base vertices.
                let at = if sub == u16::MAX {
                    FaceParam {
                        face: face as usize,
                        sub: k,
                        u: 0.0,
                        v: 0.0,
                    }
                } else {
                    FaceParam {
                        face: face as usize,
                        sub: sub as usize,
                        u,
                        v,
                    }
                };
                if self.holes[f] {
                    evaluator.evaluate_linear_into(values, at, point)?;
                } else {
                    evaluator.evaluate_into(values, at, point)?;
                }
                out.copy_from_slice(&point.value);
                Ok::<(), AdaptiveError>(())
            })?;
        // Corners of one vertex with bit-identical values share an index: sort the corners
        // by (vertex, value bits) and number the runs, vertex by vertex.
        let value = |i: usize| &corner_values[c * i..c * (i + 1)];
        let key_order = |&a: &u32, &b: &u32| {
            let (a, b) = (a as usize, b as usize);
            self.face_vertices[a]
                .cmp(&self.face_vertices[b])
                .then_with(|| {
                    value(a)
                        .iter()
                        .map(|x| x.to_bits())
                        .cmp(value(b).iter().map(|x| x.to_bits()))
                })
        };
        let mut order: Vec<u32> = (0..num_corners as u32).collect();
        order.par_sort_unstable_by(key_order);
        let mut out = AdaptiveFVar {
            components: c,
            values: Vec::new(),
            indices: vec![0; num_corners],
        };
        for (n, &i) in order.iter().enumerate() {
            let starts_run = n == 0 || key_order(&order[n - 1], &i) != std::cmp::Ordering::Equal;
            if starts_run {
                out.values.extend_from_slice(value(i as usize));
            }
            out.indices[i as usize] = (out.values.len() / c - 1) as u32;
        }
        Ok(out)
    }
}
