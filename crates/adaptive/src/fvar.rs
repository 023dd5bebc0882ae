//! Face-varying values (UVs) of the conforming mesh: each face-vertex takes the channel's
//! exact limit value at its parameter on the base face ([`FVarEvaluator`]).
//!
//! One value per parameter, whatever the level of the faces around a vertex: a refined value
//! depends on its level, and a vertex shared by a leaf and a finer transition face would get
//! two, tearing the texture along the transition. The limit is the same from every level.

use subd_limit::eval::FaceParam;
use subd_limit::fvar_eval::{FVarEvaluator, FVarPatchValues};

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
        // Every face-vertex's value, face by face in parallel.
        let per_face: Vec<Vec<f64>> = (0..self.num_faces())
            .into_par_iter()
            .map(|f| {
                let range = self.face_offsets[f] as usize..self.face_offsets[f + 1] as usize;
                let (face, sub) = self.face_domains[f];
                let mut out = Vec::with_capacity(c * range.len());
                for (k, i) in range.enumerate() {
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
                    let p = if self.holes[f] {
                        evaluator.evaluate_linear(values, at)?
                    } else {
                        evaluator.evaluate(values, at)?
                    };
                    out.extend_from_slice(&p.value);
                }
                Ok(out)
            })
            .collect::<Result<_, AdaptiveError>>()?;
        // Corners of one vertex with bit-identical values share an index.
        let mut index_of = std::collections::HashMap::new();
        let mut out = AdaptiveFVar {
            components: c,
            values: Vec::new(),
            indices: Vec::with_capacity(self.face_vertices.len()),
        };
        for (f, corner_values) in per_face.iter().enumerate() {
            let vertices = self.face(f);
            for (k, value) in corner_values.chunks_exact(c.max(1)).enumerate() {
                let key = (
                    vertices[k],
                    value.iter().map(|x| x.to_bits()).collect::<Vec<u64>>(),
                );
                let next = (out.values.len() / c.max(1)) as u32;
                let index = *index_of.entry(key).or_insert_with(|| {
                    out.values.extend_from_slice(value);
                    next
                });
                out.indices.push(index);
            }
        }
        Ok(out)
    }
}
