//! Face-varying patches: a channel of per-corner values (texture coordinates with seams)
//! carried through the table's sparse levels and taken over each patch's face, as
//! OpenSubdiv's `PatchTableFactory` does with `generateFVarTables` and its default
//! `generateFVarLegacyLinearPatches`: each patch's face-varying patch is its face at the
//! patch's level, bilinear (quads) or linear (triangles) in the values refined to that level
//! with the channel's own rules (`FVarLinearInterpolation`).
//!
//! The values of a level are refined from the level above exactly as the vertices are
//! ([`PatchLevel::piece`]): the faces around the selected vertices are cut out and refined
//! one step with the channel, and the kept children's values are the next level's. The
//! piece's values continue from the level's state (`subd_schemes::FVarLevelState`: each
//! value's tags as the levels above passed them down, as OpenSubdiv's `FVarRefinement` does),
//! not from tags found afresh on the piece, which part from the inherited ones at semi-sharp
//! values, at values where several UV regions meet and at non-manifold vertices. Every value
//! a kept face reads is computed from a neighbourhood that is whole in the piece, so it
//! equals the uniform refinement's value.

use subd_mesh::Topology;
use subd_mesh::cut as submesh;
use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};
use subd_schemes::{
    FVarLevelState, FaceVaryingRefinement, Options, Refinement, Scheme, StencilTable,
};

use super::array::PatchArray;
use super::levels::PatchLevel;
use super::param::PatchParam;
use crate::LimitError;
use crate::evaluation::fvar_eval::FVarPoint;

/// One face-varying channel of a [`super::PatchTable`]: the values of every sparse level
/// and, per patch, the values of its face.
#[derive(Debug, Clone)]
pub struct FVarPatches {
    mode: FVarLinearInterpolation,
    components: usize,
    /// Values of each level (level 0: the channel's own).
    level_value_counts: Vec<usize>,
    /// Level `l + 1`'s values as weights of level `l`'s.
    rows: Vec<StencilTable>,
    /// Per patch array, the values of each patch's face (`face_size` per patch), as value
    /// indices into the values of all levels.
    patch_values: Vec<Vec<u32>>,
    /// Values of all levels, `components` numbers each.
    values: Vec<f64>,
    face_size: usize,
}

/// A face-varying channel as flat arrays, in a table's layout
/// ([`super::PatchTableLayout::face_varying`]).
#[derive(Debug, Clone, serde::Serialize)]
pub struct FVarPatchesLayout<'a> {
    /// The interpolation mode's name (`Sdc::Options::FVarLinearInterpolation`).
    pub interpolation: &'static str,
    /// Numbers per value.
    pub components: usize,
    /// Values per patch (4: bilinear quads; 3: linear triangles).
    pub values_per_patch: usize,
    /// Values of each level (level 0: the channel's own).
    pub level_value_counts: &'a [usize],
    /// Per patch array (the table's order), the values of each patch: value indices (value
    /// `k` is `values[components * k..components * (k + 1)]`).
    pub patch_values: Vec<&'a [u32]>,
    /// The values of all levels, `components` numbers each.
    pub values: &'a [f64],
}

/// One level's face-varying values: which value each face corner takes, how many values,
/// and the refinement's state of them (their tags), which the next level continues from.
struct LevelValues {
    face_values: Vec<u32>,
    num_values: usize,
    state: FVarLevelState,
}

impl FVarPatches {
    /// The channel refined through `levels` (the table's) and taken over each patch of
    /// `arrays`.
    pub(crate) fn build(
        levels: &[PatchLevel],
        arrays: &[PatchArray],
        scheme: &Scheme,
        rules: &Options,
        channel: &FVarChannel,
        mode: FVarLinearInterpolation,
    ) -> Result<FVarPatches, LimitError> {
        let base = &levels[0].topology;
        if channel.indices().len() != base.num_face_vertices() {
            return Err(LimitError::Param(format!(
                "face-varying channel: {} corner indices for {} face corners",
                channel.indices().len(),
                base.num_face_vertices()
            )));
        }
        // The base level's state: the channel analysed on the whole base level, as uniform
        // refinement analyses it.
        let prepared = Refinement::from_prepared(
            base.clone(),
            levels[0].rules.clone(),
            scheme.clone(),
            rules,
            0,
        )?;
        let base_state = FaceVaryingRefinement::new(&prepared, channel, mode)?.level_state(0);
        let mut level_values = vec![LevelValues {
            face_values: channel.indices().to_vec(),
            num_values: channel.num_values(),
            state: base_state,
        }];
        let mut rows = Vec::with_capacity(levels.len());
        for (l, level) in levels.iter().enumerate().take(levels.len() - 1) {
            let above = level_values.last().expect("the base level's values");
            // Level 0's values are the channel's own; a refined level's are its slots.
            let base_level = l == 0;
            let (next, step) = refine_values(level, above, base_level, scheme, rules)?;
            debug_assert_eq!(
                next.face_values.len(),
                levels[l + 1].topology.num_face_vertices()
            );
            level_values.push(next);
            rows.push(step);
        }
        let offsets = value_offsets(&level_values);
        let face_size = if *scheme == Scheme::Loop { 3 } else { 4 };
        let patch_values = arrays
            .iter()
            .map(|a| patch_values_of(a, levels, &level_values, &offsets))
            .collect();
        let mut out = FVarPatches {
            mode,
            components: channel.components(),
            level_value_counts: level_values.iter().map(|l| l.num_values).collect(),
            rows,
            patch_values,
            values: Vec::new(),
            face_size,
        };
        out.values = out.refined_values(channel.values());
        Ok(out)
    }

    /// The values of every level from the channel's values.
    fn refined_values(&self, base: &[f64]) -> Vec<f64> {
        let c = self.components;
        let total: usize = self.level_value_counts.iter().sum();
        let mut values = Vec::with_capacity(total * c);
        values.extend_from_slice(base);
        let mut start = 0;
        for rows in &self.rows {
            let end = values.len();
            let mut next = vec![0.0; rows.num_rows() * c];
            rows.apply(&values[start..end], c, &mut next);
            values.extend_from_slice(&next);
            start = end;
        }
        values
    }

    /// The values of every level for new channel values (same layout: `components` numbers
    /// per value), without changing the table ([`super::PatchTable::update_face_varying`]
    /// puts them in place).
    ///
    /// # Errors
    /// [`LimitError::Param`] when `base` is not the channel's value count × components.
    pub fn values_for(&self, base: &[f64]) -> Result<Vec<f64>, LimitError> {
        let expected = self.level_value_counts[0] * self.components;
        if base.len() != expected {
            return Err(LimitError::Param(format!(
                "face-varying channel: {} numbers given for {} values of {} components",
                base.len(),
                self.level_value_counts[0],
                self.components
            )));
        }
        if let Some(k) = base.iter().position(|x| !x.is_finite()) {
            return Err(LimitError::Param(format!(
                "face-varying channel: value {} is not finite",
                k / self.components
            )));
        }
        Ok(self.refined_values(base))
    }

    /// Overwrites the values in place (views of [`Self::values`] stay valid).
    pub(crate) fn set_values(&mut self, values: &[f64]) -> Result<(), LimitError> {
        if values.len() != self.values.len() {
            return Err(LimitError::Param(format!(
                "face-varying channel: {} numbers given for {} refined values",
                values.len(),
                self.values.len()
            )));
        }
        self.values.copy_from_slice(values);
        Ok(())
    }

    /// The interpolation mode the values were refined with.
    pub fn mode(&self) -> FVarLinearInterpolation {
        self.mode
    }

    /// Numbers per value.
    pub fn components(&self) -> usize {
        self.components
    }

    /// Values of each level (level 0 = the channel's own values).
    pub fn level_value_counts(&self) -> &[usize] {
        &self.level_value_counts
    }

    /// Values per patch: 4 (a bilinear quad, OpenSubdiv's `QUADS`) for Catmull-Clark, 3 (a
    /// linear triangle, `TRIANGLES`) for Loop.
    pub fn values_per_patch(&self) -> usize {
        self.face_size
    }

    /// The values of array `array`'s patches, [`Self::values_per_patch`] per patch, as
    /// value indices (value `k` is `values()[components * k..components * (k + 1)]`;
    /// OpenSubdiv's `GetPatchArrayFVarValues`).
    pub fn array_values(&self, array: usize) -> &[u32] {
        &self.patch_values[array]
    }

    /// The values of patch `index` of array `array` ([`Self::values_per_patch`] value
    /// indices; OpenSubdiv's `GetPatchFVarValues`).
    pub fn patch_values(&self, array: usize, index: usize) -> &[u32] {
        let n = self.face_size;
        &self.patch_values[array][n * index..n * (index + 1)]
    }

    /// The values of every level, [`Self::components`] numbers each: what
    /// [`Self::array_values`] indexes. A refined level also holds values no patch reads
    /// (a vertex at the edge of a level's piece keeps all its values, also those of faces
    /// the level left out), so its count is not OpenSubdiv's `GetNumFVarValues`.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// Each refined level's values as weights of the level above's (level `l + 1` from
    /// level `l`, `l` from 0).
    pub fn level_stencils(&self) -> &[StencilTable] {
        &self.rows
    }

    /// The channel as flat arrays.
    pub fn layout(&self) -> FVarPatchesLayout<'_> {
        FVarPatchesLayout {
            interpolation: self.mode.name(),
            components: self.components,
            values_per_patch: self.face_size,
            level_value_counts: &self.level_value_counts,
            patch_values: self.patch_values.iter().map(Vec::as_slice).collect(),
            values: &self.values,
        }
    }

    /// The value and its first derivatives on patch `i` of array `array` at `(u, v)` of its
    /// root face (the patch's parameter `param` places it).
    pub(crate) fn evaluate(
        &self,
        array: usize,
        i: usize,
        param: PatchParam,
        u: f64,
        v: f64,
    ) -> FVarPoint {
        let n = self.face_size;
        let corners = &self.patch_values[array][n * i..n * (i + 1)];
        let mut d1 = 1.0 / param.fraction();
        let (w, ws, wt) = if n == 3 {
            let (s, t) = param.normalize_triangle(u, v);
            if param.is_triangle_rotated() {
                d1 = -d1;
            }
            linear_triangle(s, t)
        } else {
            let (s, t) = param.normalize(u, v);
            bilinear_quad(s, t)
        };
        let c = self.components;
        let mut out = FVarPoint {
            value: vec![0.0; c],
            du: vec![0.0; c],
            dv: vec![0.0; c],
        };
        for (k, &value) in corners.iter().enumerate() {
            let x = &self.values[value as usize * c..(value as usize + 1) * c];
            let sums = out.value.iter_mut().zip(&mut out.du).zip(&mut out.dv);
            for (((p, du), dv), &xj) in sums.zip(x) {
                *p += w[k] * xj;
                *du += ws[k] * xj * d1;
                *dv += wt[k] * xj * d1;
            }
        }
        out
    }
}

/// The bilinear basis over a quad's corners (0,0), (1,0), (1,1), (0,1) and its derivatives.
fn bilinear_quad(s: f64, t: f64) -> ([f64; 4], [f64; 4], [f64; 4]) {
    (
        [(1.0 - s) * (1.0 - t), s * (1.0 - t), s * t, (1.0 - s) * t],
        [t - 1.0, 1.0 - t, t, -t],
        [s - 1.0, -s, s, 1.0 - s],
    )
}

/// The linear basis over a triangle's corners (0,0), (1,0), (0,1) and its derivatives.
fn linear_triangle(s: f64, t: f64) -> ([f64; 4], [f64; 4], [f64; 4]) {
    (
        [1.0 - s - t, s, t, 0.0],
        [-1.0, 1.0, 0.0, 0.0],
        [-1.0, 0.0, 1.0, 0.0],
    )
}

/// The next level's values: the piece around the level's selected vertices refined one
/// step, its values continuing from the level's state (so their tags are the inherited
/// ones), the kept children's values as the next level's, with their rows over the level's
/// values (`base_level`: the level's values are the channel's own, which its slots copy).
fn refine_values(
    level: &PatchLevel,
    above: &LevelValues,
    base_level: bool,
    scheme: &Scheme,
    rules: &Options,
) -> Result<(LevelValues, StencilTable), LimitError> {
    let piece = level.piece(scheme, rules)?;
    let (piece_state, piece_slots) = above.state.restrict(
        &level.topology,
        &piece.cut.topology,
        &piece.faces,
        &piece.cut.vertices,
        &piece.cut.edges,
    );
    let level_value = |piece_slot: u32| {
        let slot = piece_slots[piece_slot as usize];
        if base_level {
            above.state.source(slot as usize)
        } else {
            slot
        }
    };
    let fr = FaceVaryingRefinement::from_state(&piece.refinement, piece_state)?;
    let stencils = fr.stencils(&piece.refinement, 1);
    let children = piece.refinement.topology(1);
    let next = submesh::cut(children, &piece.kept.faces);
    let (state, child_slots) = fr.level_state(1).restrict(
        children,
        &next.topology,
        &piece.kept.faces,
        &next.vertices,
        &next.edges,
    );
    let rows: Vec<Vec<(u32, f64)>> = child_slots
        .iter()
        .map(|&c| {
            let (idx, w) = stencils.row(c as usize);
            idx.iter()
                .map(|&i| level_value(i))
                .zip(w.iter().copied())
                .collect()
        })
        .collect();
    let step = StencilTable::from_rows(above.num_values, &rows);
    Ok((
        LevelValues {
            face_values: state.face_values().to_vec(),
            num_values: state.num_values(),
            state,
        },
        step,
    ))
}

/// The corner values of face `f` of `t` from its face-vertex values.
fn corner_values<'a>(t: &Topology, face_values: &'a [u32], f: usize) -> &'a [u32] {
    let offsets = t.face_offsets();
    &face_values[offsets[f] as usize..offsets[f + 1] as usize]
}

/// First index of each level's values among the values of all levels.
fn value_offsets(levels: &[LevelValues]) -> Vec<u32> {
    let mut next = 0u32;
    levels
        .iter()
        .map(|l| {
            let first = next;
            next += l.num_values as u32;
            first
        })
        .collect()
}

/// The values of each patch of `array`: its face's corner values at its level.
fn patch_values_of(
    array: &PatchArray,
    levels: &[PatchLevel],
    level_values: &[LevelValues],
    offsets: &[u32],
) -> Vec<u32> {
    let mut out = Vec::new();
    for &(level, face) in &array.faces {
        let l = level as usize;
        let corners = corner_values(
            &levels[l].topology,
            &level_values[l].face_values,
            face as usize,
        );
        out.extend(corners.iter().map(|&v| v + offsets[l]));
    }
    out
}
