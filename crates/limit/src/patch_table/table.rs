//! [`PatchTable`]: the patches of a feature-adaptive refinement as flat arrays.

use std::collections::BTreeMap;

use glam::DVec3;
use subd_mesh::Topology;
use subd_schemes::{Options, Scheme, StencilTable};

use super::array::PatchArray;
use super::assembly::Assembly;
use super::basis;
use super::classify::Classifier;
use super::exact_caps::{CapContext, CapPoints, CapStencil, ExactCaps};
use super::face_varying::FVarPatches;
use super::features::{FeatureMask, Regularity, VTag, single_crease_edge};
use super::levels::PatchLevel;
use super::map::PatchMap;
use super::patch_eval::{bspline_first, evaluate_patch, patch_weights};
use super::{EndCaps, MAX_ISOLATION, PatchOptions, PatchType, PatchWeights};
use crate::LimitError;
use crate::evaluation::eval::FaceParam;
use crate::evaluation::fvar_eval::FVarPoint;
use crate::evaluation::patch::Derivatives;
use crate::evaluation::patch::SurfacePoint;
use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};

/// Counts of a table's patches, as `subd patches --json` prints them.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct PatchCensus {
    /// Every patch.
    pub patches: usize,
    /// Patches by type.
    pub by_type: BTreeMap<PatchType, usize>,
    /// Patches by depth.
    pub by_depth: BTreeMap<u8, usize>,
    /// Regular patches by boundary mask.
    pub regular_by_boundary_mask: BTreeMap<u8, usize>,
    /// Local points (end-cap points computed from the refined vertices).
    pub local_points: usize,
}

/// One patch array as a file stores it ([`PatchTableLayout`]).
#[derive(Debug, Clone, serde::Serialize)]
pub struct PatchArrayLayout<'a> {
    /// OpenSubdiv's name of the patch type.
    #[serde(rename = "type")]
    pub kind: &'static str,
    /// Control points per patch (0 for exact patches).
    pub control_points_per_patch: usize,
    /// Number of patches.
    pub patches: usize,
    /// The control points, patch after patch: indices into `points`.
    pub control_points: &'a [u32],
    /// Per patch, the two words of its [`super::PatchParam`] (OpenSubdiv's bit layout).
    pub params: Vec<[u32; 2]>,
    /// Per patch, its single-crease sharpness (0 when none).
    pub sharpness: &'a [f32],
}

/// A whole table as flat arrays, the layout `subd patches OUT.json` writes: the options,
/// the vertex count of each refined level, the arrays, the local points' stencils (CSR
/// over the refined vertices of all levels) and the points themselves (refined vertices of
/// all levels, then local points), which the control points index.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PatchTableLayout<'a> {
    /// The scheme's name.
    pub scheme: &'static str,
    /// The options.
    pub options: PatchOptions,
    /// Vertices of each refined level (level 0: the base vertices).
    pub level_vertex_counts: Vec<usize>,
    /// Number of local points.
    pub local_points: usize,
    /// The patch arrays.
    pub arrays: Vec<PatchArrayLayout<'a>>,
    /// Row offsets of the local points' stencils (one more than local points).
    pub local_point_offsets: &'a [u32],
    /// Column (refined vertex) of each stencil entry.
    pub local_point_indices: &'a [u32],
    /// Weight of each stencil entry.
    pub local_point_weights: &'a [f64],
    /// Refined vertices of all levels, then local points.
    pub points: Vec<[f64; 3]>,
    /// The face-varying channels ([`PatchTable::add_face_varying`]).
    pub face_varying: Vec<super::FVarPatchesLayout<'a>>,
}

/// The patches of a table sampled on grids ([`PatchTable::patch_grid`]).
#[derive(Debug, Clone, Default)]
pub struct PatchGrid {
    /// Vertices per face (4 for Catmull-Clark, 3 for Loop).
    pub face_size: usize,
    /// Face vertices, `face_size` per face.
    pub faces: Vec<u32>,
    /// Positions.
    pub positions: Vec<DVec3>,
    /// Unit normals.
    pub normals: Vec<DVec3>,
    /// The patch (array, index in the array) of each face.
    pub patch: Vec<(u32, u32)>,
}

/// The points of one set of base positions ([`PatchTable::points_for`]).
#[derive(Debug, Clone)]
pub struct TablePoints {
    /// Refined vertices of all levels, then the local points.
    pub(crate) points: Vec<DVec3>,
    /// The exact end caps' own points, when the table has exact caps.
    pub(crate) exact: Option<CapPoints>,
}

/// A feature-adaptive patch table of a Catmull-Clark or Loop mesh (OpenSubdiv's
/// `Far::PatchTable`), with the points of one set of base positions
/// ([`Self::update`] moves them).
#[derive(Debug)]
pub struct PatchTable {
    scheme: Scheme,
    /// The refinement rules (boundaries, creases) the levels were made with.
    rules: Options,
    options: PatchOptions,
    levels: Vec<PatchLevel>,
    arrays: Vec<PatchArray>,
    /// First index of each level's vertices among the refined vertices.
    level_offsets: Vec<u32>,
    /// Local points as weights of the refined vertices.
    local: StencilTable,
    /// The points of the positions given last.
    points: TablePoints,
    /// First root (ptex) index of each base face.
    ptex: Vec<u32>,
    /// The array and index of each patch, in global order.
    handles: Vec<(u32, u32)>,
    map: PatchMap,
    exact: Option<ExactCaps>,
    /// The index of the exact array, when the table has one.
    exact_array: Option<usize>,
    /// Face-varying channels ([`Self::add_face_varying`]).
    face_varying: Vec<FVarPatches>,
}

impl PatchTable {
    /// Refines `base` adaptively with `scheme` (Catmull-Clark or Loop) and the rules
    /// `rules`, builds its patches with `options`, and computes their points from the base
    /// positions `positions`.
    ///
    /// # Errors
    /// [`LimitError::Scheme`] for another scheme, [`LimitError::Param`] for an isolation level
    /// outside `1..=10` or a position count that is not the vertex count, and the
    /// refinement's errors (a Loop mesh that is not all triangles).
    pub fn new(
        base: &Topology,
        positions: &[DVec3],
        scheme: &Scheme,
        rules: &Options,
        options: &PatchOptions,
    ) -> Result<PatchTable, LimitError> {
        check_request(scheme, options)?;
        check_positions(base, positions)?;
        let mut table = Self::without_points(base, scheme, rules, options)?;
        table.points = table.points_for(positions)?;
        Ok(table)
    }

    /// [`Self::new`] without points: the topology, patches and end caps, to be evaluated with
    /// points from [`Self::points_for`] ([`crate::eval::LimitEvaluator`] keeps one table for
    /// any number of point sets).
    pub(crate) fn without_points(
        base: &Topology,
        scheme: &Scheme,
        rules: &Options,
        options: &PatchOptions,
    ) -> Result<PatchTable, LimitError> {
        let reg = check_request(scheme, options)?;
        let levels = refine_adaptive(base, scheme, rules, options, reg)?;
        let ptex = ptex_offsets(base, reg.face_size);
        let irregular_faces = (0..base.num_faces()).any(|f| base.face_size(f) != reg.face_size);
        let found = Classifier {
            levels: &levels,
            options,
            reg,
            ptex: &ptex,
            irregular_faces,
            mask: feature_mask(options, reg),
        }
        .patches();
        let level_offsets = level_offsets(&levels);
        let caps = end_cap_type(options.end_caps, reg);
        let (arrays, handles, local) =
            Assembly::new(&levels, &level_offsets, options, reg).run(&found, caps);
        let num_roots = ptex_count(base, reg.face_size);
        let map = PatchMap::new(
            handles
                .iter()
                .map(|&(a, i)| arrays[a as usize].params[i as usize]),
            num_roots,
            reg.face_size == 3,
        );
        let mut table = PatchTable {
            scheme: scheme.clone(),
            rules: *rules,
            options: *options,
            levels,
            arrays,
            level_offsets,
            local,
            points: TablePoints {
                points: Vec::new(),
                exact: None,
            },
            ptex,
            handles,
            map,
            exact: None,
            exact_array: None,
            face_varying: Vec::new(),
        };
        table.exact_array = table.arrays.iter().position(|a| a.kind == PatchType::Exact);
        if let Some(a) = table.exact_array {
            table.exact = Some(ExactCaps::new(&table.arrays[a], &table.cap_context(&[]))?);
        }
        Ok(table)
    }

    /// The cheapest table that is the exact limit ([`PatchOptions::exact_limit`]), what
    /// `subd eval` and `subd tessellate` evaluate.
    ///
    /// # Errors
    /// As [`Self::new`].
    pub fn exact_limit(
        base: &Topology,
        positions: &[DVec3],
        scheme: &Scheme,
        rules: &Options,
    ) -> Result<PatchTable, LimitError> {
        Self::new(base, positions, scheme, rules, &PatchOptions::exact_limit())
    }

    /// Recomputes the refined and local points (and the exact end caps' points) for moved
    /// base vertices, keeping the topology: animation refines once, updates every frame.
    ///
    /// # Errors
    /// [`LimitError::Param`] when `positions` does not have one point per base vertex.
    pub fn update(&mut self, positions: &[DVec3]) -> Result<(), LimitError> {
        let next = self.points_for(positions)?;
        self.set_points(next);
        Ok(())
    }

    /// [`Self::update`]'s work without changing the table: the points of new base
    /// positions, to be put in place by [`Self::set_points`] (so a renderer can read the
    /// table while the next frame's points are computed).
    ///
    /// # Errors
    /// [`LimitError::Param`] when `positions` does not have one point per base vertex.
    pub fn points_for(&self, positions: &[DVec3]) -> Result<TablePoints, LimitError> {
        check_positions(&self.levels[0].topology, positions)?;
        let points = self.compute_points(positions);
        let exact = self
            .exact
            .as_ref()
            .map(|e| e.points_for(&self.cap_context(&points), positions));
        Ok(TablePoints { points, exact })
    }

    /// Puts points from [`Self::points_for`] in place. The buffer [`Self::points`] returns
    /// stays where it is (its values are overwritten), so views of it stay valid.
    ///
    /// # Panics
    /// If `next` was computed by another table (a different point count).
    pub fn set_points(&mut self, next: TablePoints) {
        self.points.points.copy_from_slice(&next.points);
        self.points.exact = next.exact;
    }

    /// What the exact caps read of the table, with its points `points`.
    fn cap_context<'a>(&'a self, points: &'a [DVec3]) -> CapContext<'a> {
        CapContext {
            levels: &self.levels,
            level_offsets: &self.level_offsets,
            points,
            scheme: &self.scheme,
            rules: &self.rules,
        }
    }

    /// The refined vertices of every level, then the local points.
    fn compute_points(&self, positions: &[DVec3]) -> Vec<DVec3> {
        let mut points = positions.to_vec();
        for (l, level) in self.levels.iter().enumerate().skip(1) {
            let rows = level.rows.as_ref().expect("a refined level has rows");
            let above = &points[self.level_offsets[l - 1] as usize..self.level_offsets[l] as usize];
            let next = rows.apply_points(above);
            points.extend(next);
        }
        let local = self.local.apply_points(&points);
        points.extend(local);
        points
    }

    /// The stencils of each refined level from the level above it (level 1 first): with
    /// [`Self::local_point_stencils`], what recomputes [`Self::points`] from new base
    /// positions, level by level (a GPU does it so).
    pub fn level_stencils(&self) -> Vec<&StencilTable> {
        self.levels
            .iter()
            .skip(1)
            .map(|l| l.rows.as_ref().expect("a refined level has rows"))
            .collect()
    }

    /// The base level as the table sees it (OpenSubdiv's tags applied: boundary faces are
    /// holes under `BoundaryInterpolation::None`).
    pub fn base_topology(&self) -> &Topology {
        &self.levels[0].topology
    }

    /// The points of the positions given last (to evaluate with them).
    pub(crate) fn own_points(&self) -> &TablePoints {
        &self.points
    }

    /// The scheme.
    pub fn scheme(&self) -> &Scheme {
        &self.scheme
    }

    /// The options the table was built with.
    pub fn options(&self) -> &PatchOptions {
        &self.options
    }

    /// The patch arrays: the regular type first, then the end caps' (B-spline end caps
    /// share the regular array); empty arrays left out.
    pub fn arrays(&self) -> &[PatchArray] {
        &self.arrays
    }

    /// Number of refinement levels (the deepest patch's depth).
    pub fn max_depth(&self) -> usize {
        self.levels.len() - 1
    }

    /// Vertices of each refined level (level 0 = the base vertices); the control points of
    /// the patches index them concatenated, then the local points.
    pub fn level_vertex_counts(&self) -> Vec<usize> {
        self.levels
            .iter()
            .map(|l| l.topology.num_vertices())
            .collect()
    }

    /// The refined vertices of all levels, then the local points: what the control points
    /// index.
    pub fn points(&self) -> &[DVec3] {
        &self.points.points
    }

    /// The local points as weights of the refined vertices of all levels (OpenSubdiv's
    /// local-point stencil table).
    pub fn local_point_stencils(&self) -> &StencilTable {
        &self.local
    }

    /// The local points as weights of the base vertices: the level stencils composed down
    /// to level 0 and the local points' stencils applied to them (OpenSubdiv's
    /// `AppendLocalPointStencilTable` with `factorize`), so a caller with only the base
    /// positions gets the end caps' points in one product.
    pub fn local_point_stencils_base(&self) -> StencilTable {
        let base = self.levels[0].topology.num_vertices();
        let mut level = StencilTable::identity(base);
        let (mut offsets, mut indices, mut weights) = (vec![0u32], Vec::new(), Vec::new());
        for (l, next) in self.levels.iter().enumerate() {
            if l > 0 {
                level = level.then(next.rows.as_ref().expect("a refined level has rows"));
            }
            let shift = *offsets.last().expect("offsets start at 0");
            offsets.extend(level.offsets()[1..].iter().map(|&o| o + shift));
            indices.extend_from_slice(level.indices());
            weights.extend_from_slice(level.weights());
        }
        StencilTable::from_csr(base, offsets, indices, weights).then(&self.local)
    }

    /// The patch map: (root face, u, v) to the patch (global index, arrays in order).
    pub fn patch_map(&self) -> &PatchMap {
        &self.map
    }

    /// Checks `at` against the base topology: face and sub-face in range, parameters in
    /// the face's domain (holes are found by [`Self::find`]).
    ///
    /// # Errors
    /// [`LimitError::Param`] naming what is out of range.
    pub fn check(&self, at: &FaceParam) -> Result<(), LimitError> {
        crate::evaluation::eval::check_param(&self.levels[0].topology, &self.scheme, at)
    }

    /// The patch covering `at` (its array and index in the array).
    ///
    /// # Errors
    /// [`LimitError::Param`] for a face, sub-face or parameter out of range,
    /// [`LimitError::Unsupported`] where the face has no surface (a hole).
    pub fn find(&self, at: &FaceParam) -> Result<(usize, usize), LimitError> {
        self.locate(at).map(|(_, a, i)| (a, i))
    }

    /// The root (ptex) index of `at`'s face and sub-face.
    pub(crate) fn root_of(&self, at: &FaceParam) -> usize {
        self.ptex[at.face] as usize + at.sub
    }

    /// [`Self::find`] with the patch's global index first.
    pub(crate) fn locate(&self, at: &FaceParam) -> Result<(usize, usize, usize), LimitError> {
        self.check(at)?;
        let root = self.ptex[at.face] as usize + at.sub;
        let p = self
            .map
            .find(root, at.u, at.v)
            .ok_or(LimitError::Unsupported {
                face: at.face,
                reason: "the face is a hole",
            })?;
        let (a, i) = self.handles[p];
        Ok((p, a as usize, i as usize))
    }

    /// Position and normal at `at` of exact end cap `i` (index in the exact array).
    pub(crate) fn exact_position_normal(
        &self,
        pts: &TablePoints,
        i: usize,
        at: FaceParam,
    ) -> Result<(DVec3, DVec3), LimitError> {
        let p = self.exact_cap(pts, i, at, Derivatives::First)?;
        Ok((p.position, p.normal()))
    }

    /// The exact end caps and the index of their array, when the table has them.
    pub(crate) fn exact_caps(&self) -> Option<(&ExactCaps, usize)> {
        self.exact.as_ref().zip(self.exact_array)
    }

    /// [`Self::exact_position_normal`] at every place of `ats` (all in cap `i`), the
    /// places sharing what their evaluation can share.
    pub(crate) fn exact_position_normals(
        &self,
        pts: &TablePoints,
        i: usize,
        ats: &[FaceParam],
    ) -> Result<Vec<(DVec3, DVec3)>, LimitError> {
        let exact = self.exact.as_ref().expect("exact end caps are set up");
        let cap_points = pts.exact.as_ref().expect("and their points");
        let a = self.exact_array.expect("an exact array");
        let param = self.arrays[a].params[i];
        let cx = self.cap_context(&pts.points);
        let values = exact.evaluate_many(&cx, cap_points, i, param, ats, Derivatives::First)?;
        Ok(values.iter().map(|p| (p.position, p.normal())).collect())
    }

    /// Exact end cap `i` (index in the exact array) at `at` as weights of the points it
    /// reads.
    pub(crate) fn exact_cap_stencil(
        &self,
        i: usize,
        at: FaceParam,
    ) -> Result<CapStencil, LimitError> {
        let exact = self.exact.as_ref().expect("exact end caps are set up");
        let a = self.exact_array.expect("an exact array");
        exact.stencil(&self.cap_context(&[]), i, self.arrays[a].params[i], at)
    }

    /// The index of the first point of level `level` among the table's points (the number
    /// of refined vertices for one past the last level).
    pub(crate) fn level_offset(&self, level: usize) -> u32 {
        self.level_offsets[level]
    }

    /// The row of point `p` above the base level: its points, their weights, and the
    /// index the points are counted from (a local point's row names refined vertices, a
    /// refined vertex's the vertices of the level above it).
    pub(crate) fn point_row(&self, p: u32) -> (&[u32], &[f64], u32) {
        let refined = *self.level_offsets.last().expect("offsets");
        if p >= refined {
            let (indices, weights) = self.local.row((p - refined) as usize);
            return (indices, weights, 0);
        }
        let level = self.level_offsets.partition_point(|&o| o <= p) - 1;
        let rows = self.levels[level]
            .rows
            .as_ref()
            .expect("a refined level has rows");
        let (indices, weights) = rows.row((p - self.level_offsets[level]) as usize);
        (indices, weights, self.level_offsets[level - 1])
    }

    /// Exact end cap `i` (index in the exact array) at `at`, up to the derivatives `d`.
    fn exact_cap(
        &self,
        pts: &TablePoints,
        i: usize,
        at: FaceParam,
        d: Derivatives,
    ) -> Result<SurfacePoint, LimitError> {
        let exact = self.exact.as_ref().expect("exact end caps are set up");
        let cap_points = pts.exact.as_ref().expect("and their points");
        let a = self.exact_array.expect("an exact array");
        let param = self.arrays[a].params[i];
        exact.evaluate(&self.cap_context(&pts.points), cap_points, i, param, at, d)
    }

    /// The surface at `at`: position and first and second derivatives with respect to the
    /// face's (sub-face's) parameters.
    ///
    /// # Errors
    /// As [`Self::find`].
    pub fn evaluate(&self, at: FaceParam) -> Result<SurfacePoint, LimitError> {
        self.evaluate_on(&self.points, at)
    }

    /// [`Self::evaluate`] with points `pts` from [`Self::points_for`].
    pub(crate) fn evaluate_on(
        &self,
        pts: &TablePoints,
        at: FaceParam,
    ) -> Result<SurfacePoint, LimitError> {
        let (a, i) = self.find(&at)?;
        self.evaluate_in(pts, a, i, at)
    }

    /// The weights of patch `index` of array `array`'s control points at `(u, v)` of its
    /// root face (OpenSubdiv's `PatchTable::EvaluateBasis`): a renderer's own sums of
    /// [`Self::points`] with them give [`Self::evaluate`]'s values. Derivatives are with
    /// respect to the root's parameters; in a sub-face of a face that is not a quad that is
    /// the sub-face's `(u, v)`, where OpenSubdiv's are twice (first) and four times (second)
    /// these, being taken with respect to the face's half-size ptex parameters.
    ///
    /// # Errors
    /// [`LimitError::Param`] for a patch that does not exist, [`LimitError::Unsupported`] for
    /// an exact end cap (it has no control points).
    pub fn evaluate_basis(
        &self,
        array: usize,
        index: usize,
        u: f64,
        v: f64,
    ) -> Result<PatchWeights, LimitError> {
        let a = self
            .arrays
            .get(array)
            .filter(|a| index < a.len())
            .ok_or_else(|| LimitError::Param(format!("no patch {index} in array {array}")))?;
        let Some(n) = a.kind.num_control_points() else {
            let (face, _) = self.root_faces()[a.params[index].place().face as usize];
            return Err(LimitError::Unsupported {
                face,
                reason: "an exact end cap has no control points",
            });
        };
        let w = patch_weights(a.kind, a.params[index], u, v);
        Ok(PatchWeights {
            rows: w.map(|row| row[..n].to_vec()),
        })
    }

    /// The table as flat arrays ([`PatchTableLayout`]).
    pub fn layout(&self) -> PatchTableLayout<'_> {
        PatchTableLayout {
            scheme: self.scheme.name(),
            options: self.options,
            level_vertex_counts: self.level_vertex_counts(),
            local_points: self.local.num_rows(),
            arrays: self
                .arrays
                .iter()
                .map(|a| PatchArrayLayout {
                    kind: a.kind.name(),
                    control_points_per_patch: a.kind.num_control_points().unwrap_or(0),
                    patches: a.len(),
                    control_points: &a.control_points,
                    params: a.params.iter().map(|p| [p.field0, p.field1]).collect(),
                    sharpness: &a.sharpness,
                })
                .collect(),
            local_point_offsets: self.local.offsets(),
            local_point_indices: self.local.indices(),
            local_point_weights: self.local.weights(),
            points: self.points.points.iter().map(|p| p.to_array()).collect(),
            face_varying: self.face_varying.iter().map(FVarPatches::layout).collect(),
        }
    }

    /// Position and first derivatives at `at`: [`Self::evaluate`] without the second
    /// derivatives, and with the bicubic B-spline summed as a tensor product.
    pub(crate) fn evaluate_first_on(
        &self,
        pts: &TablePoints,
        at: FaceParam,
    ) -> Result<[DVec3; 3], LimitError> {
        let (a, i) = self.find(&at)?;
        let array = &self.arrays[a];
        let param = array.params[i];
        let place = param.place();
        if array.kind == PatchType::Regular && place.boundary == 0 {
            let (s, t) = param.normalize(at.u, at.v);
            let d1 = 1.0 / param.fraction();
            let [p, du, dv] = bspline_first(array.patch_points(i), &pts.points, s, t);
            return Ok([p, du * d1, dv * d1]);
        }
        if array.kind == PatchType::Loop && place.boundary == 0 {
            let (s, t) = param.normalize_triangle(at.u, at.v);
            let mut d1 = 1.0 / param.fraction();
            if param.is_triangle_rotated() {
                d1 = -d1;
            }
            let [p, du, dv] = basis::box_spline_first(array.patch_points(i), &pts.points, s, t);
            return Ok([p, du * d1, dv * d1]);
        }
        self.evaluate_in(pts, a, i, at)
            .map(|s| [s.position, s.du, s.dv])
    }

    /// Every patch sampled on its own `rate × rate` grid of its domain (a triangle's in
    /// `rate²` triangles): a mesh of the patches as they lie, for pictures (adjacent
    /// patches of different depths share no vertices).
    ///
    /// # Errors
    /// An evaluation's error (none for a table that was built).
    pub fn patch_grid(&self, rate: usize) -> Result<PatchGrid, LimitError> {
        let rate = rate.max(1);
        let roots = self.root_faces();
        let triangles = self.scheme == Scheme::Loop;
        let mut grid = PatchGrid::default();
        for (a, array) in self.arrays.iter().enumerate() {
            for (i, param) in array.params.iter().enumerate() {
                let (face, sub) = roots[param.place().face as usize];
                let first = grid.positions.len() as u32;
                let id = |x: usize, y: usize| first + (y * (rate + 1) + x) as u32;
                for y in 0..=rate {
                    for x in 0..=rate {
                        let (s, t) = (x as f64 / rate as f64, y as f64 / rate as f64);
                        // Points past a triangle's hypotenuse are folded onto it.
                        let (s, t) = if triangles && s + t > 1.0 {
                            (s / (s + t), t / (s + t))
                        } else {
                            (s, t)
                        };
                        let (u, v) = if triangles {
                            param.unnormalize_triangle(s, t)
                        } else {
                            param.unnormalize(s, t)
                        };
                        let at = FaceParam { face, sub, u, v };
                        let p = self.evaluate_in(&self.points, a, i, at)?;
                        grid.positions.push(p.position);
                        grid.normals.push(p.normal());
                    }
                }
                for y in 0..rate {
                    for x in 0..rate {
                        if triangles {
                            if x + y < rate {
                                grid.faces.extend([id(x, y), id(x + 1, y), id(x, y + 1)]);
                                grid.patch.push((a as u32, i as u32));
                            }
                            if x + y + 1 < rate {
                                grid.faces
                                    .extend([id(x + 1, y), id(x + 1, y + 1), id(x, y + 1)]);
                                grid.patch.push((a as u32, i as u32));
                            }
                        } else {
                            grid.faces.extend([
                                id(x, y),
                                id(x + 1, y),
                                id(x + 1, y + 1),
                                id(x, y + 1),
                            ]);
                            grid.patch.push((a as u32, i as u32));
                        }
                    }
                }
            }
        }
        grid.face_size = if triangles { 3 } else { 4 };
        Ok(grid)
    }

    /// The base face and sub-face of each root (ptex) face.
    fn root_faces(&self) -> Vec<(usize, usize)> {
        let base = &self.levels[0].topology;
        let regular = if self.scheme == Scheme::Loop { 3 } else { 4 };
        (0..base.num_faces())
            .flat_map(|f| {
                let n = base.face_size(f);
                (0..if n == regular { 1 } else { n }).map(move |sub| (f, sub))
            })
            .collect()
    }

    /// Patch `i` of array `a` at `at` (which it covers).
    fn evaluate_in(
        &self,
        pts: &TablePoints,
        a: usize,
        i: usize,
        at: FaceParam,
    ) -> Result<SurfacePoint, LimitError> {
        let array = &self.arrays[a];
        if array.kind == PatchType::Exact {
            return self.exact_cap(pts, i, at, Derivatives::Second);
        }
        Ok(evaluate_patch(
            array.kind,
            array.params[i],
            array.patch_points(i),
            &pts.points,
            at.u,
            at.v,
        ))
    }

    /// Adds a face-varying channel (texture coordinates with seams; one value index per
    /// base face corner) refined with `mode` through the table's levels, and returns its
    /// index: OpenSubdiv's `generateFVarTables` with its default linear face-varying
    /// patches (each patch's values are its face's at its level, interpolated bilinearly on
    /// quads, linearly on triangles).
    ///
    /// # Errors
    /// [`LimitError::Param`] or [`LimitError::FaceVarying`] when the channel does not fit
    /// the base mesh.
    pub fn add_face_varying(
        &mut self,
        channel: &FVarChannel,
        mode: FVarLinearInterpolation,
    ) -> Result<usize, LimitError> {
        let fvar = FVarPatches::build(
            &self.levels,
            &self.arrays,
            &self.scheme,
            &self.rules,
            channel,
            mode,
        )?;
        self.face_varying.push(fvar);
        Ok(self.face_varying.len() - 1)
    }

    /// The face-varying channels, in the order they were added.
    pub fn face_varying(&self) -> &[FVarPatches] {
        &self.face_varying
    }

    /// Face-varying channel `channel` at `at`: its value and first derivatives with respect
    /// to the face's (sub-face's) parameters (OpenSubdiv's `EvaluateBasisFaceVarying`, whose
    /// derivatives in a sub-face are twice these, as [`Self::evaluate_basis`] says).
    ///
    /// # Errors
    /// [`LimitError::Param`] for a channel that was not added, else as [`Self::find`].
    pub fn evaluate_face_varying(
        &self,
        channel: usize,
        at: FaceParam,
    ) -> Result<FVarPoint, LimitError> {
        let fvar = self.face_varying_channel(channel)?;
        let (a, i) = self.find(&at)?;
        Ok(fvar.evaluate(a, i, self.arrays[a].params[i], at.u, at.v))
    }

    /// Recomputes channel `channel`'s refined values for new values (the channel's layout:
    /// its components per value), keeping the topology. The buffer
    /// [`FVarPatches::values`] returns stays where it is.
    ///
    /// # Errors
    /// [`LimitError::Param`] for a channel that was not added or a value count that is not
    /// the channel's.
    pub fn update_face_varying(
        &mut self,
        channel: usize,
        values: &[f64],
    ) -> Result<(), LimitError> {
        let next = self.face_varying_channel(channel)?.values_for(values)?;
        self.set_face_varying_values(channel, &next)
    }

    /// Puts values from [`FVarPatches::values_for`] of channel `channel` in place
    /// (overwriting the buffer, so views of it stay valid).
    ///
    /// # Errors
    /// [`LimitError::Param`] for a channel that was not added or values of another length.
    pub fn set_face_varying_values(
        &mut self,
        channel: usize,
        values: &[f64],
    ) -> Result<(), LimitError> {
        self.face_varying_channel(channel)?;
        self.face_varying[channel].set_values(values)
    }

    fn face_varying_channel(&self, channel: usize) -> Result<&FVarPatches, LimitError> {
        self.face_varying.get(channel).ok_or_else(|| {
            LimitError::Param(format!(
                "face-varying channel {channel}: the table has {}",
                self.face_varying.len()
            ))
        })
    }

    /// Counts of the patches by type, depth and boundary mask.
    pub fn census(&self) -> PatchCensus {
        let mut c = PatchCensus {
            local_points: self.local.num_rows(),
            ..Default::default()
        };
        let regular = regular_type_of(&self.scheme);
        for a in &self.arrays {
            for p in &a.params {
                let place = p.place();
                c.patches += 1;
                let kind = if place.regular { regular } else { a.kind };
                *c.by_type.entry(kind).or_default() += 1;
                *c.by_depth.entry(place.depth).or_default() += 1;
                if place.regular {
                    *c.regular_by_boundary_mask
                        .entry(place.boundary)
                        .or_default() += 1;
                }
            }
        }
        c
    }
}

fn check_positions(base: &Topology, positions: &[DVec3]) -> Result<(), LimitError> {
    if positions.len() == base.num_vertices() {
        Ok(())
    } else {
        Err(LimitError::Param(format!(
            "{} positions given for {} vertices",
            positions.len(),
            base.num_vertices()
        )))
    }
}

/// The scheme's regular face and valence, once the scheme and isolation level are checked.
fn check_request(scheme: &Scheme, options: &PatchOptions) -> Result<Regularity, LimitError> {
    let reg = regularity(scheme)?;
    if !(1..=MAX_ISOLATION).contains(&options.isolation) {
        return Err(LimitError::Param(format!(
            "isolation level {} is outside 1..={MAX_ISOLATION}",
            options.isolation
        )));
    }
    Ok(reg)
}

fn regularity(scheme: &Scheme) -> Result<Regularity, LimitError> {
    match scheme {
        Scheme::CatmullClark => Ok(Regularity {
            valence: 4,
            face_size: 4,
        }),
        Scheme::Loop => Ok(Regularity {
            valence: 6,
            face_size: 3,
        }),
        s => Err(LimitError::Scheme {
            scheme: s.to_string(),
            what: "patch tables exist for catmull-clark and loop only",
        }),
    }
}

/// First index of each level's vertices in the concatenation of all levels.
fn level_offsets(levels: &[PatchLevel]) -> Vec<u32> {
    let mut offsets = Vec::with_capacity(levels.len() + 1);
    let mut next = 0u32;
    for l in levels {
        offsets.push(next);
        next += l.topology.num_vertices() as u32;
    }
    offsets.push(next);
    offsets
}

/// Number of root (ptex) faces.
fn ptex_count(base: &Topology, regular_size: usize) -> usize {
    (0..base.num_faces())
        .map(|f| match base.face_size(f) {
            n if n == regular_size => 1,
            n => n,
        })
        .sum()
}

fn regular_type_of(scheme: &Scheme) -> PatchType {
    if *scheme == Scheme::Loop {
        PatchType::Loop
    } else {
        PatchType::Regular
    }
}

fn regular_type(reg: Regularity) -> PatchType {
    if reg.face_size == 3 {
        PatchType::Loop
    } else {
        PatchType::Regular
    }
}

/// The patch type of the end caps `caps` for the scheme (`patchTypeFromBasisArray`).
fn end_cap_type(caps: EndCaps, reg: Regularity) -> PatchType {
    let tri = reg.face_size == 3;
    match caps {
        EndCaps::Bilinear if tri => PatchType::Triangles,
        EndCaps::Bilinear => PatchType::Quads,
        EndCaps::BSpline => regular_type(reg),
        EndCaps::GregoryBasis if tri => PatchType::GregoryTriangle,
        EndCaps::GregoryBasis => PatchType::GregoryBasis,
        EndCaps::Exact => PatchType::Exact,
    }
}

/// The first root (ptex) index of every base face: a face of the regular size has one, any
/// other face one per corner (its sub-faces).
fn ptex_offsets(base: &Topology, regular_size: usize) -> Vec<u32> {
    let mut next = 0u32;
    (0..base.num_faces())
        .map(|f| {
            let first = next;
            let n = base.face_size(f);
            next += if n == regular_size { 1 } else { n as u32 };
            first
        })
        .collect()
}

/// The sparse levels: each level's faces with features selected and refined, until the
/// isolation level or until nothing is selected (`RefineAdaptive`).
/// The features isolated with `options` (single-crease patches are Catmull-Clark's only).
fn feature_mask(options: &PatchOptions, reg: Regularity) -> FeatureMask {
    FeatureMask::new(
        options.single_crease && reg.face_size == 4,
        options.inf_sharp,
    )
}

fn refine_adaptive(
    base: &Topology,
    scheme: &Scheme,
    rules: &Options,
    options: &PatchOptions,
    reg: Regularity,
) -> Result<Vec<PatchLevel>, LimitError> {
    let mask = feature_mask(options, reg);
    let mut levels = vec![PatchLevel::base(base, scheme, rules, reg)?];
    for _ in 0..options.isolation {
        let level = levels.last_mut().expect("the base level");
        let t = &level.topology;
        let mut any = false;
        for f in 0..t.num_faces() {
            if t.is_hole(f) {
                continue;
            }
            let corners: Vec<VTag> = t
                .face_vertices(f)
                .iter()
                .map(|&v| level.tags[v as usize])
                .collect();
            let select = mask.select(&corners, reg.face_size, level.depth, || {
                single_crease_edge(t, f, &corners).is_some()
            });
            level.selected[f] = select;
            any |= select;
        }
        if !any {
            break;
        }
        let next = level.refine(scheme, rules, reg)?;
        levels.push(next);
    }
    Ok(levels)
}
