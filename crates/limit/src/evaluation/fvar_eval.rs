//! Face-varying values (UVs) on the limit surface at any (face, u, v), beside the positions
//! of [`LimitEvaluator`](crate::eval::LimitEvaluator), with the parameterisation of [`crate::eval`].
//!
//! **Method.** A channel refined by [`FaceVaryingRefinement`] is the refinement of a mesh of
//! its own: one vertex per (vertex, value) pair, the faces of the geometry, seams as
//! boundaries. Tagged so that its vertex rules are the channel's, that mesh's limit surface
//! *is* the channel's limit, and [`LimitEvaluator`](crate::eval::LimitEvaluator) evaluates it exactly:
//! * a value that matches its neighbours (OpenSubdiv's "matching" value) follows its
//!   vertex's rule, so it keeps the vertex's sharpness and the sharpness of its edges, which
//!   are all continuous; where that rule pins the vertex because it is a boundary corner
//!   under `edge-and-corner`, the value is pinned too;
//! * a seam value refined with the crease rule (`Vtr::FVarLevel`'s crease value) is a
//!   boundary vertex with smooth boundary rules (`edge-only`): the crease rule along its two
//!   seam edges;
//! * a value the mode pins (corners, junctions, darts, linear boundaries) or that meets an
//!   infinitely sharp edge inside its span is a corner (infinitely sharp vertex).
//!
//! OpenSubdiv blends a seam value that is semi-sharp (a semi-sharp vertex, or semi-sharp
//! edges inside its span or, in the plus modes, the other value's span) from corner to
//! crease with its own fractional weight, which no vertex tag reproduces. The channel is
//! then refined uniformly until no value is semi-sharp, and the mesh of values is built at
//! that level. In mode `all` every value is refined linearly: the value is the bilinear
//! (Catmull-Clark) or linear (Loop) interpolation of the face's corner values.
//!
//! The check: at every corner of the faces two levels down, the value agrees with the exact
//! limit of that corner's refined value ([`crate::fvar::limit_at_level`], itself checked
//! against OpenSubdiv's `LimitFaceVarying`), for every shape of OpenSubdiv's regression suite
//! that has UVs, in every mode (`tests/tests/all/osd_meshes.rs`).

use glam::DVec3;
use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};
use subd_mesh::tags::{SHARPNESS_INFINITE, is_semi_sharp};
use subd_mesh::{BoundaryInterpolation, Topology, TopologyBuilder};
use subd_schemes::{
    FVarLevelValues, FVarValueKind, FaceVaryingRefinement, Refinement, Rule, Scheme,
};

use crate::LimitError;
use crate::evaluation::eval::{FaceParam, WholeMeshEvaluator, WholePoints, descend};

/// A face-varying value and its first derivatives with respect to the face parameters,
/// `components` numbers each.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FVarPoint {
    /// The value.
    pub value: Vec<f64>,
    /// ∂/∂u.
    pub du: Vec<f64>,
    /// ∂/∂v.
    pub dv: Vec<f64>,
}

impl FVarPoint {
    /// Empties the three vectors, keeping their memory, for a point of another evaluation.
    fn clear(&mut self) {
        self.value.clear();
        self.du.clear();
        self.dv.clear();
    }
}

/// Evaluates one face-varying channel on the limit surface of a [`LimitEvaluator`](crate::eval::LimitEvaluator)'s mesh
/// (made by [`LimitEvaluator::face_varying`](crate::eval::LimitEvaluator::face_varying)).
///
/// ```
/// use subd_mesh::TopologyBuilder;
/// use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};
/// use subd_schemes::{Options, Scheme};
/// use subd_limit::eval::{FaceParam, LimitEvaluator};
///
/// // A 3×3 grid of quads whose UV layout is cut in two along the middle column.
/// let mut faces = Vec::new();
/// for y in 0..3u32 {
///     for x in 0..3u32 {
///         faces.extend([4 * y + x, 4 * y + x + 1, 4 * y + x + 5, 4 * y + x + 4]);
///     }
/// }
/// let grid = TopologyBuilder::new(16).build(&[4; 9], &faces).unwrap();
/// // Value of a corner: its vertex, or vertex + 16 for the corners of the right column.
/// let indices: Vec<u32> = faces
///     .chunks(4)
///     .flat_map(|f| {
///         let right = f.iter().all(|&v| v % 4 >= 2);
///         f.iter().map(move |&v| v + 16 * u32::from(right)).collect::<Vec<_>>()
///     })
///     .collect();
/// let uv: Vec<f64> = (0..32)
///     .flat_map(|i| [(i % 4) as f64 + 4.0 * (i / 16) as f64, ((i % 16) / 4) as f64])
///     .collect();
/// let channel = FVarChannel::new(&grid, 2, uv, indices).unwrap();
/// let eval = LimitEvaluator::new(&grid, &Scheme::CatmullClark, &Options::default()).unwrap();
/// let uv_eval = eval.face_varying(&channel, FVarLinearInterpolation::All).unwrap();
/// let values = uv_eval.prepare(channel.values()).unwrap();
/// // Mode `all` is linear: the middle of face 4 is the average of its corners' UVs.
/// let p = uv_eval.evaluate(&values, FaceParam { face: 4, sub: 0, u: 0.5, v: 0.5 }).unwrap();
/// assert_eq!(p.value, vec![1.5, 1.5]);
/// ```
#[derive(Debug)]
pub struct FVarEvaluator {
    scheme: Scheme,
    components: usize,
    num_values: usize,
    /// The geometry's base topology (as the position evaluator sees it).
    base: Topology,
    /// The channel's value of every base face-vertex.
    indices: Vec<u32>,
    /// `None` in mode `all`, which is linear.
    patches: Option<ValuePatches>,
    /// Base faces next to a degenerate edge whose two ends carry different values.
    blocked: Vec<bool>,
}

/// The mesh of a channel's values and its evaluator.
#[derive(Debug)]
struct ValuePatches {
    /// The level at which the mesh of values is built (0 unless semi-sharp seam values had
    /// to decay first).
    level: usize,
    /// The refinement carrying geometry and channel to `level`, when it is above 0.
    refined: Option<(Refinement, FaceVaryingRefinement)>,
    /// At level 0: the channel value of each vertex of the mesh of values.
    slot_values: Vec<u32>,
    evaluator: WholeMeshEvaluator,
}

/// A channel's values prepared for [`FVarEvaluator::evaluate`].
#[derive(Clone, Debug)]
pub struct FVarPatchValues {
    /// The channel's values.
    values: Vec<f64>,
    /// Smooth modes: the patch points of each group of three components.
    groups: Vec<WholePoints>,
}

/// An evaluator of `channel` (defined on `base`, refined by `scheme` with the rules
/// `options`) interpolated by `mode` ([`crate::eval::LimitEvaluator::face_varying`]).
///
/// # Errors
/// [`LimitError::Param`] when the channel does not fit the mesh or has no values;
/// [`LimitError::TooDeep`] when a semi-sharp seam would need the whole mesh refined past
/// [`crate::MAX_DECAY_FACE_VERTICES`]; the errors of the evaluator on the mesh of values.
pub(crate) fn face_varying_evaluator(
    base: &Topology,
    scheme: &Scheme,
    options: &subd_schemes::Options,
    channel: &FVarChannel,
    mode: FVarLinearInterpolation,
) -> Result<FVarEvaluator, LimitError> {
    if channel.indices().len() != base.num_face_vertices() || channel.num_values() == 0 {
        return Err(LimitError::Param(format!(
            "face-varying channel with {} values and {} indices does not fit a mesh of {} face-vertices",
            channel.num_values(),
            channel.indices().len(),
            base.num_face_vertices()
        )));
    }
    let patches = if mode == FVarLinearInterpolation::All {
        None
    } else {
        Some(value_patches(base, scheme, options, channel, mode)?)
    };
    Ok(FVarEvaluator {
        scheme: scheme.clone(),
        components: channel.components(),
        num_values: channel.num_values(),
        base: base.clone(),
        indices: channel.indices().to_vec(),
        blocked: near_split_degenerate_edges(base, channel.indices()),
        patches,
    })
}

/// Faces within two rings of a degenerate edge (a face's two consecutive corners on one
/// vertex) whose two ends carry different values. Refinement reads such an edge's ends as two
/// values of one vertex; the mesh of values would make it an edge between two vertices with
/// rings of their own, so the faces it reaches are not evaluated.
fn near_split_degenerate_edges(t: &Topology, indices: &[u32]) -> Vec<bool> {
    let mut near_vertex = vec![false; t.num_vertices()];
    for f in 0..t.num_faces() {
        let (fv, off, n) = (
            t.face_vertices(f),
            t.face_offsets()[f] as usize,
            t.face_size(f),
        );
        for k in 0..n {
            if fv[k] == fv[(k + 1) % n] && indices[off + k] != indices[off + (k + 1) % n] {
                near_vertex[fv[k] as usize] = true;
            }
        }
    }
    // Twice: the faces at those vertices, then the faces at any of their vertices.
    for _ in 0..2 {
        let faces: Vec<usize> = (0..t.num_faces())
            .filter(|&f| t.face_vertices(f).iter().any(|&v| near_vertex[v as usize]))
            .collect();
        for f in faces {
            for &v in t.face_vertices(f) {
                near_vertex[v as usize] = true;
            }
        }
    }
    (0..t.num_faces())
        .map(|f| t.face_vertices(f).iter().any(|&v| near_vertex[v as usize]))
        .collect()
}

/// The mesh of values at the first level where no value is semi-sharp, and its evaluator.
fn value_patches(
    base: &Topology,
    scheme: &Scheme,
    options: &subd_schemes::Options,
    channel: &FVarChannel,
    mode: FVarLinearInterpolation,
) -> Result<ValuePatches, LimitError> {
    let mut level = 0;
    loop {
        let r = Refinement::new(base, scheme.clone(), options, level)?;
        let fr = FaceVaryingRefinement::new(&r, channel, mode)
            .map_err(|e| LimitError::Param(e.to_string()))?;
        let values = fr.level_values(&r, level);
        let t = r.topology(level);
        let semi_sharp = (0..t.num_vertices()).any(|v| {
            (0..values.num_vertex_values(v))
                .any(|k| values.value_kind(v, k) == FVarValueKind::SemiSharp)
        });
        if !semi_sharp {
            let mesh = mesh_of_values(t, r.vertex_rules(level), &values)?;
            // Seams are boundaries with the crease rule; pinned values carry their own tags.
            let mesh_options = subd_schemes::Options {
                boundary_interpolation: BoundaryInterpolation::EdgeOnly,
                ..*options
            };
            let evaluator = WholeMeshEvaluator::new(&mesh, scheme, &mesh_options)?;
            let slot_values = (0..values.num_slots())
                .map(|s| values.slot_value(s))
                .collect();
            return Ok(ValuePatches {
                level,
                refined: (level > 0).then_some((r, fr)),
                slot_values,
                evaluator,
            });
        }
        // Semi-sharp seam values are left: one level further (every finite sharpness has
        // decayed after ten).
        level += 1;
        let face_vertices = base.num_face_vertices().saturating_mul(1 << (2 * level));
        if level > subd_schemes::MAX_LEVELS || face_vertices > crate::MAX_DECAY_FACE_VERTICES {
            return Err(LimitError::TooDeep {
                sharpness: crate::levels_for_exact_limit(base, scheme).1,
                levels: level,
                max: crate::MAX_DECAY_FACE_VERTICES,
            });
        }
    }
}

/// The mesh of a level's values: a vertex per (vertex, value) slot, the level's faces over
/// their corners' slots, tagged so that each vertex's rule is its value's (module docs).
fn mesh_of_values(
    t: &Topology,
    rules: &[Rule],
    values: &FVarLevelValues<'_>,
) -> Result<Topology, LimitError> {
    let sizes: Vec<u32> = t.face_sizes().collect();
    let mut corners = Vec::with_capacity(t.num_face_vertices());
    for f in 0..t.num_faces() {
        corners.extend((0..t.face_size(f)).map(|k| values.corner_slot(f, k) as u32));
    }
    let mut mesh = TopologyBuilder::new(values.num_slots())
        .accept_inconsistent_orientation(true)
        .build(&sizes, &corners)
        .map_err(|e| LimitError::Param(format!("the mesh of face-varying values: {e}")))?;
    // Continuous edges keep their sharpness; seam edges are boundaries of the mesh of values.
    for f in 0..t.num_faces() {
        for (&own, &geometric) in mesh.face_edges(f).to_vec().iter().zip(t.face_edges(f)) {
            if mesh.edge_faces(own as usize).len() >= 2 {
                // A non-manifold edge is infinitely sharp (OpenSubdiv tags it so), also where
                // the seams leave it with two faces in the mesh of values.
                let g = geometric as usize;
                let sharpness = if t.is_non_manifold_edge(g) {
                    SHARPNESS_INFINITE
                } else {
                    t.edge_sharpness(g)
                };
                mesh.set_edge_sharpness(own as usize, sharpness);
            }
        }
        if t.is_hole(f) {
            mesh.set_hole(f, true);
        }
    }
    for v in 0..t.num_vertices() {
        for k in 0..values.num_vertex_values(v) {
            let sharpness = match values.value_kind(v, k) {
                FVarValueKind::Matching => matching_sharpness(t, rules, v),
                FVarValueKind::Corner => SHARPNESS_INFINITE,
                FVarValueKind::Crease => 0.0,
                FVarValueKind::SemiSharp => unreachable!("built where no value is semi-sharp"),
            };
            mesh.set_vertex_sharpness(values.slot(v, k), sharpness);
        }
    }
    Ok(mesh)
}

/// The sharpness that gives a matching value its vertex's rule in the mesh of values, whose
/// boundaries are smooth: the vertex's own, or infinite where the geometry pins the vertex
/// for a reason other than semi-sharp features (a boundary corner under `edge-and-corner`,
/// a non-manifold vertex).
fn matching_sharpness(t: &Topology, rules: &[Rule], v: usize) -> f32 {
    let own = t.vertex_sharpness(v);
    let semi = is_semi_sharp(own)
        || t.vertex_edges(v)
            .iter()
            .any(|&e| is_semi_sharp(t.edge_sharpness(e as usize)));
    if rules[v] == Rule::Corner && !semi {
        SHARPNESS_INFINITE
    } else {
        own
    }
}

impl FVarEvaluator {
    /// Numbers per value.
    pub fn components(&self) -> usize {
        self.components
    }

    /// The control values for the channel's values `values` (`components` numbers per
    /// value, in the channel's order).
    ///
    /// # Errors
    /// [`LimitError::Param`] when `values` does not hold `components` numbers per value.
    pub fn prepare(&self, values: &[f64]) -> Result<FVarPatchValues, LimitError> {
        let c = self.components;
        if values.len() != c * self.num_values {
            return Err(LimitError::Param(format!(
                "{} numbers given for {} face-varying values of {c} components",
                values.len(),
                self.num_values
            )));
        }
        let Some(p) = &self.patches else {
            return Ok(FVarPatchValues {
                values: values.to_vec(),
                groups: Vec::new(),
            });
        };
        // The values of the mesh of values' vertices, `c` numbers each.
        let level_values = match &p.refined {
            Some((r, fr)) => fr.refine_values(r, values, c).swap_remove(p.level),
            None => p
                .slot_values
                .iter()
                .flat_map(|&i| values[c * i as usize..c * (i as usize + 1)].iter().copied())
                .collect(),
        };
        let groups = (0..c.div_ceil(3))
            .map(|g| {
                let points: Vec<DVec3> = level_values
                    .chunks_exact(c)
                    .map(|x| {
                        let at = |i: usize| x.get(3 * g + i).copied().unwrap_or(0.0);
                        DVec3::new(at(0), at(1), at(2))
                    })
                    .collect();
                p.evaluator.prepare(&points)
            })
            .collect();
        Ok(FVarPatchValues {
            values: values.to_vec(),
            groups,
        })
    }

    /// The channel's limit value at `at` and its first derivatives.
    ///
    /// # Errors
    /// As [`LimitEvaluator::evaluate`](crate::eval::LimitEvaluator::evaluate) for the point.
    pub fn evaluate(
        &self,
        values: &FVarPatchValues,
        at: FaceParam,
    ) -> Result<FVarPoint, LimitError> {
        let mut out = FVarPoint::default();
        self.evaluate_into(values, at, &mut out)?;
        Ok(out)
    }

    /// [`Self::evaluate`] into `out`, whose memory is reused: for loops over many points.
    ///
    /// # Errors
    /// As [`Self::evaluate`]; `out` is then unspecified.
    pub fn evaluate_into(
        &self,
        values: &FVarPatchValues,
        at: FaceParam,
        out: &mut FVarPoint,
    ) -> Result<(), LimitError> {
        crate::evaluation::eval::check_param(&self.base, &self.scheme, &at)?;
        if self.blocked[at.face] && self.patches.is_some() {
            return Err(LimitError::Unsupported {
                face: at.face,
                reason: "next to a degenerate edge whose two ends carry different face-varying values",
            });
        }
        let Some(p) = &self.patches else {
            self.linear(&values.values, &at, out);
            return Ok(());
        };
        let (at_level, scale) = match &p.refined {
            Some((r, _)) => descend(r, p.level, at),
            None => (at, 1.0),
        };
        let c = self.components;
        out.clear();
        out.value.resize(c, 0.0);
        out.du.resize(c, 0.0);
        out.dv.resize(c, 0.0);
        for (g, points) in values.groups.iter().enumerate() {
            let s = p
                .evaluator
                .evaluate(points, at_level)
                .map_err(|e| crate::evaluation::eval::on_base_face(e, at.face))?;
            for i in 0..3.min(c - 3 * g) {
                out.value[3 * g + i] = s.position[i];
                out.du[3 * g + i] = scale * s.du[i];
                out.dv[3 * g + i] = scale * s.dv[i];
            }
        }
        Ok(())
    }

    /// The bilinear (Catmull-Clark) or linear (Loop) interpolation of the face's corner
    /// values at `at`, as mode `all` refines them: a value for faces the limit does not
    /// cover, such as holes, which have no surface of their own.
    ///
    /// # Errors
    /// [`LimitError::Param`] for a point outside the mesh or the parameter domain.
    pub fn evaluate_linear(
        &self,
        values: &FVarPatchValues,
        at: FaceParam,
    ) -> Result<FVarPoint, LimitError> {
        let mut out = FVarPoint::default();
        self.evaluate_linear_into(values, at, &mut out)?;
        Ok(out)
    }

    /// [`Self::evaluate_linear`] into `out`, whose memory is reused.
    ///
    /// # Errors
    /// As [`Self::evaluate_linear`].
    pub fn evaluate_linear_into(
        &self,
        values: &FVarPatchValues,
        at: FaceParam,
        out: &mut FVarPoint,
    ) -> Result<(), LimitError> {
        crate::evaluation::eval::check_param(&self.base, &self.scheme, &at)?;
        self.linear(&values.values, &at, out);
        Ok(())
    }

    /// Mode `all`: the bilinear interpolation of the (sub-)face's corners (Catmull-Clark:
    /// a sub-face of a face that is not a quad runs corner, edge midpoint, centre, edge
    /// midpoint), or the linear one of the triangle's (Loop).
    fn linear(&self, values: &[f64], at: &FaceParam, out: &mut FVarPoint) {
        let c = self.components;
        let off = self.base.face_offsets()[at.face] as usize;
        let n = self.base.face_size(at.face);
        let corner = |k: usize| {
            let i = self.indices[off + k % n] as usize;
            &values[c * i..c * (i + 1)]
        };
        let (u, v) = (at.u, at.v);
        out.clear();
        for i in 0..c {
            let (x, du, dv) = if self.scheme == Scheme::Loop {
                let (a, b, d) = (corner(0)[i], corner(1)[i], corner(2)[i]);
                ((1.0 - u - v) * a + u * b + v * d, b - a, d - a)
            } else {
                let [p00, p10, p11, p01] = if n == 4 {
                    [0, 1, 2, 3].map(|k| corner(k)[i])
                } else {
                    let k = at.sub;
                    let centre = (0..n).map(|j| corner(j)[i]).sum::<f64>() / n as f64;
                    [
                        corner(k)[i],
                        0.5 * (corner(k)[i] + corner(k + 1)[i]),
                        centre,
                        0.5 * (corner(k + n - 1)[i] + corner(k)[i]),
                    ]
                };
                (
                    (1.0 - u) * (1.0 - v) * p00
                        + u * (1.0 - v) * p10
                        + u * v * p11
                        + (1.0 - u) * v * p01,
                    (1.0 - v) * (p10 - p00) + v * (p11 - p01),
                    (1.0 - u) * (p01 - p00) + u * (p11 - p10),
                )
            };
            out.value.push(x);
            out.du.push(du);
            out.dv.push(dv);
        }
    }
}
