//! A patch table on the device (OpenSubdiv's `GLPatchTable` + `GLComputeEvaluator`
//! together): its points recomputed from new base positions, its patches evaluated at
//! batches of (face, u, v) and on a uniform grid of every patch, results left in device
//! buffers a renderer draws from.

use std::collections::HashMap;

use subd_limit::eval::FaceParam;
use subd_limit::patches::{PatchBasisPolynomials, PatchTable, PatchType};
use subd_mesh::DVec3;

use crate::stencils::f32_rows;
use crate::{Gpu, GpuColumns, GpuError, GpuStencilTable, StencilDispatch};

/// Threads per workgroup of `patches.wgsl`.
const WORKGROUP: u32 = 64;
/// Words per class in `patches.wgsl`'s `words`: points, triangle flag, 20 blend codes.
const CLASS_WORDS: usize = 22;

/// Positions and first derivatives (with respect to the root face's parameters, as
/// [`PatchTable::evaluate`] gives them), one row of three f32 each per place.
#[derive(Debug)]
pub struct GpuPatchValues {
    /// Positions.
    pub positions: GpuColumns,
    /// ∂/∂u.
    pub du: GpuColumns,
    /// ∂/∂v.
    pub dv: GpuColumns,
}

impl GpuPatchValues {
    /// Buffers for `rows` places.
    ///
    /// # Errors
    /// The device's size and memory errors.
    pub fn new(gpu: &Gpu, rows: usize) -> Result<GpuPatchValues, GpuError> {
        Ok(GpuPatchValues {
            positions: gpu.columns(rows, 3)?,
            du: gpu.columns(rows, 3)?,
            dv: gpu.columns(rows, 3)?,
        })
    }

    /// Number of places.
    pub fn rows(&self) -> usize {
        self.positions.rows()
    }
}

/// Places on a table's patches, located on the host ([`GpuPatchTable::coords`]): per
/// place the patch's index on the device and `(u, v)` of its root face, three 32-bit
/// words (OpenSubdiv's `PatchCoord`).
#[derive(Debug)]
pub struct GpuPatchCoords {
    buffer: wgpu::Buffer,
    count: usize,
}

impl GpuPatchCoords {
    /// Number of places.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }
}

/// One of the patch shaders bound to its buffers: recorded as often as its inputs change.
#[derive(Debug)]
pub struct PatchDispatch {
    bind_group: wgpu::BindGroup,
    grid: (u32, u32),
    entry: Entry,
    _parameters: wgpu::Buffer,
}

#[derive(Debug, Clone, Copy)]
enum Entry {
    Evaluate,
    Tessellate,
    GridIndices,
}

impl PatchDispatch {
    /// Records the dispatch into `encoder`.
    pub fn record(&self, gpu: &Gpu, encoder: &mut wgpu::CommandEncoder) {
        if self.grid.0 == 0 {
            return;
        }
        let p = &gpu.patch_pipelines;
        let pipeline = match self.entry {
            Entry::Evaluate => &p.evaluate,
            Entry::Tessellate => &p.tessellate,
            Entry::GridIndices => &p.grid_indices,
        };
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.dispatch_workgroups(self.grid.0, self.grid.1, 1);
    }

    /// Records and submits the dispatch now.
    pub fn submit(&self, gpu: &Gpu) {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        self.record(gpu, &mut encoder);
        gpu.queue.submit([encoder.finish()]);
    }
}

/// Every patch sampled on its own `rate × rate` grid on the device, as
/// [`PatchTable::patch_grid`] samples it: patch after patch (arrays in order), sample
/// `x + (rate + 1) y` of a patch at `(x, y) / rate` of its domain (a triangle's points past
/// its hypotenuse folded onto it); `indices` a triangle list (u32, usable as an index
/// buffer): a quad cell `a b c d` as `a b c`, `a c d`, a triangle patch's `rate²` triangles
/// as `patch_grid` lists them.
#[derive(Debug)]
pub struct GpuTessellation {
    /// Grid segments per patch side.
    pub rate: usize,
    /// Positions and derivatives of the samples.
    pub values: GpuPatchValues,
    /// The triangle list.
    pub indices: wgpu::Buffer,
    /// Number of triangles.
    pub triangles: usize,
    dispatch: PatchDispatch,
    _weights: wgpu::Buffer,
}

impl GpuTessellation {
    /// Records the evaluation of the grid into `encoder` (after the table's
    /// [`GpuPatchTable::record_update`] when both go in one submission).
    pub fn record(&self, gpu: &Gpu, encoder: &mut wgpu::CommandEncoder) {
        self.dispatch.record(gpu, encoder);
    }

    /// Evaluates the grid from the table's current points, submitted now.
    pub fn evaluate(&self, gpu: &Gpu) {
        self.dispatch.submit(gpu);
    }

    /// Reads the triangle list back.
    ///
    /// # Errors
    /// [`GpuError::Failed`] when the device fails.
    pub fn read_indices(&self, gpu: &Gpu) -> Result<Vec<u32>, GpuError> {
        gpu.read_back(&self.indices, (self.triangles * 12) as u64)
    }
}

/// A [`PatchTable`] on the device: its points (refined vertices of every level, then the
/// local points, [`PatchTable::points`]' order, rows of three f32 in [`Self::points`]),
/// recomputed from new base positions by its level and local-point stencils, and its
/// patches, evaluated by one shader for every kind (the bases of
/// [`PatchBasisPolynomials`]). Tables with exact end caps have no fixed basis and stay on
/// the host ([`GpuError::Unsupported`]): build them with Gregory, B-spline or bilinear end
/// caps.
#[derive(Debug)]
pub struct GpuPatchTable {
    points: GpuColumns,
    /// First row of each level in `points`, then of the local points.
    level_offsets: Vec<usize>,
    /// Levels 1 and deeper, then the local points, each in its own buffer (a stencil
    /// shader may not write the buffer it reads), copied into `points` after.
    parts: Vec<GpuColumns>,
    _tables: Vec<GpuStencilTable>,
    dispatches: Vec<StencilDispatch>,
    /// Per patch its record, then the control points, then the classes (`patches.wgsl`).
    words: wgpu::Buffer,
    coefficients: wgpu::Buffer,
    cps_base: u32,
    classes_base: u32,
    /// The device index of each array's first patch.
    array_first: Vec<u32>,
    patches: usize,
    /// The basis of each class (kind and boundary mask).
    bases: Vec<PatchBasisPolynomials>,
    /// Loop's triangles, not Catmull-Clark's quads.
    triangles: bool,
}

/// The table's patches as `patches.wgsl` reads them.
struct PatchWords {
    words: Vec<u32>,
    bases: Vec<PatchBasisPolynomials>,
    coefficients: Vec<f64>,
    cps_base: u32,
    classes_base: u32,
    array_first: Vec<u32>,
}

/// Lays out `table`'s patches: records, control points, and one class per kind and basis
/// boundary mask present.
fn patch_words(table: &PatchTable) -> Result<PatchWords, GpuError> {
    let (mut records, mut cps, mut array_first) = (Vec::new(), Vec::new(), Vec::new());
    let mut classes: HashMap<(PatchType, u8), u32> = HashMap::new();
    let mut class_list: Vec<PatchBasisPolynomials> = Vec::new();
    for array in table.arrays() {
        array_first.push((records.len() / 4) as u32);
        if array.kind() == PatchType::Exact {
            return Err(GpuError::Unsupported(
                "a table with exact end caps: they have no fixed basis to evaluate on the device (build the table with Gregory, B-spline or bilinear end caps)".into(),
            ));
        }
        for (i, param) in array.params().iter().enumerate() {
            let key = (array.kind(), param.basis_boundary());
            let class = match classes.get(&key) {
                Some(&c) => c,
                None => {
                    let basis = PatchBasisPolynomials::new(key.0, key.1)
                        .map_err(|e| GpuError::Unsupported(e.to_string()))?;
                    class_list.push(basis);
                    classes.insert(key, class_list.len() as u32 - 1);
                    class_list.len() as u32 - 1
                }
            };
            records.extend([cps.len() as u32, class, param.field0, param.field1]);
            cps.extend_from_slice(array.patch_points(i));
        }
    }
    let cps_base = records.len() as u32;
    let classes_base = cps_base + cps.len() as u32;
    let mut words = records;
    words.extend(cps);
    let mut coefficients = Vec::with_capacity(class_list.len() * 20 * 25);
    for basis in &class_list {
        let mut class = [0u32; CLASS_WORDS];
        class[0] = basis.coefficients.len() as u32;
        class[1] = u32::from(basis.is_triangle());
        for (k, b) in basis.blends.iter().enumerate() {
            class[2 + k] = blend_code(*b);
        }
        words.extend(class);
        for k in 0..20 {
            coefficients.extend(basis.coefficients.get(k).copied().unwrap_or([0.0; 25]));
        }
    }
    Ok(PatchWords {
        words,
        bases: class_list,
        coefficients,
        cps_base,
        classes_base,
        array_first,
    })
}

/// `patches.wgsl`'s code of a blend.
fn blend_code(b: subd_limit::patches::BasisBlend) -> u32 {
    use subd_limit::patches::BasisBlend as B;
    match b {
        B::One => 0,
        B::QuadFp(c) => 1 + u32::from(c),
        B::QuadFm(c) => 5 + u32::from(c),
        B::TriangleFp(c) => 9 + u32::from(c),
        B::TriangleFm(c) => 12 + u32::from(c),
    }
}

impl GpuPatchTable {
    /// Uploads `table`: its stencils and patches, and its current points.
    ///
    /// # Errors
    /// [`GpuError::Unsupported`] for a table with exact end caps; the device's size and
    /// memory errors.
    pub fn new(gpu: &Gpu, table: &PatchTable) -> Result<GpuPatchTable, GpuError> {
        let layout = patch_words(table)?;
        let counts = table.level_vertex_counts();
        let mut level_offsets = vec![0];
        for c in &counts {
            level_offsets.push(level_offsets.last().expect("starts at 0") + c);
        }
        let total = table.points().len();
        let points = gpu.upload_points(table.points())?;
        let mut cpu_tables = table.level_stencils();
        cpu_tables.push(table.local_point_stencils());
        let mut parts = counts[1..]
            .iter()
            .map(|&n| gpu.columns(n, 3))
            .collect::<Result<Vec<_>, _>>()?;
        parts.push(gpu.columns(total - level_offsets[counts.len()], 3)?);
        let tables = cpu_tables
            .iter()
            .map(|&t| GpuStencilTable::new(gpu, t))
            .collect::<Result<Vec<_>, _>>()?;
        let dispatches = level_dispatches(gpu, &tables, &points, &parts)?;
        let none = wgpu::BufferUsages::empty();
        let coefficients = gpu.storage_real("patch bases", &layout.coefficients)?;
        Ok(GpuPatchTable {
            points,
            level_offsets,
            parts,
            _tables: tables,
            dispatches,
            words: gpu.storage("patches", &layout.words, none)?,
            coefficients,
            cps_base: layout.cps_base,
            classes_base: layout.classes_base,
            array_first: layout.array_first,
            patches: table.arrays().iter().map(|a| a.len()).sum(),
            bases: layout.bases,
            triangles: *table.scheme() == subd_schemes::Scheme::Loop,
        })
    }

    /// The points the patches read: refined vertices of every level, then the local
    /// points (rows of three f32).
    pub fn points(&self) -> &GpuColumns {
        &self.points
    }

    /// Number of patches.
    pub fn num_patches(&self) -> usize {
        self.patches
    }

    /// Writes new base positions (rows of three f32, one per base vertex) and submits the
    /// recomputation of every level and the local points ([`PatchTable::update`] on the
    /// device).
    ///
    /// # Errors
    /// [`GpuError::Mismatch`] where `base` is not one row per base vertex.
    pub fn update(&self, gpu: &Gpu, base: &[f32]) -> Result<(), GpuError> {
        let n = self.level_offsets[1];
        if base.len() != 3 * n {
            return Err(GpuError::Mismatch(format!(
                "{} values given for {n} base vertices of 3",
                base.len()
            )));
        }
        if n > 0 {
            gpu.queue
                .write_buffer(&self.points.buffer, 0, bytemuck::cast_slice(base));
        }
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        self.record_update(gpu, &mut encoder);
        gpu.queue.submit([encoder.finish()]);
        Ok(())
    }

    /// [`Self::update`] with points.
    ///
    /// # Errors
    /// As [`Self::update`].
    pub fn update_points(&self, gpu: &Gpu, base: &[DVec3]) -> Result<(), GpuError> {
        self.update(gpu, &f32_rows(base))
    }

    /// Records the recomputation of the points from the base positions in the first rows
    /// of [`Self::points`] (written there by the caller's own work, a skinning shader
    /// say).
    pub fn record_update(&self, gpu: &Gpu, encoder: &mut wgpu::CommandEncoder) {
        for (k, (dispatch, part)) in self.dispatches.iter().zip(&self.parts).enumerate() {
            dispatch.record(gpu, encoder);
            let bytes = part.bytes();
            if part.rows > 0 {
                let at = (self.level_offsets[k + 1] * 12) as u64;
                encoder.copy_buffer_to_buffer(&part.buffer, 0, &self.points.buffer, at, bytes);
            }
        }
    }

    /// Locates `at` on the host (`table` must be the table uploaded) and uploads the
    /// places for [`Self::bind_evaluate`].
    ///
    /// # Errors
    /// [`GpuError::Limit`] for a place off the surface (a face out of range, a hole);
    /// [`GpuError::Mismatch`] for another table; the device's size and memory errors.
    pub fn coords(
        &self,
        gpu: &Gpu,
        table: &PatchTable,
        at: &[FaceParam],
    ) -> Result<GpuPatchCoords, GpuError> {
        let firsts = table.arrays().iter().scan(0, |first, a| {
            let at = *first;
            *first += a.len() as u32;
            Some(at)
        });
        let same = firsts.eq(self.array_first.iter().copied())
            && table.arrays().iter().map(|a| a.len()).sum::<usize>() == self.patches
            && table.points().len() == self.points.rows;
        if !same {
            return Err(GpuError::Mismatch(
                "places located in a table that is not the one on the device".into(),
            ));
        }
        let mut words = Vec::with_capacity(3 * at.len());
        for place in at {
            let (array, index) = table.find(place)?;
            let patch = self.array_first[array] + index as u32;
            words.extend([
                patch,
                (place.u as f32).to_bits(),
                (place.v as f32).to_bits(),
            ]);
        }
        Ok(GpuPatchCoords {
            buffer: gpu.storage("patch coordinates", &words, wgpu::BufferUsages::empty())?,
            count: at.len(),
        })
    }

    /// Binds the evaluation of the places `coords` into `out` (one row per place).
    ///
    /// # Errors
    /// [`GpuError::Mismatch`] where `out` has not one row per place.
    pub fn bind_evaluate(
        &self,
        gpu: &Gpu,
        coords: &GpuPatchCoords,
        out: &GpuPatchValues,
    ) -> Result<PatchDispatch, GpuError> {
        if out.rows() != coords.count {
            return Err(GpuError::Mismatch(format!(
                "{} places evaluated into {} rows",
                coords.count,
                out.rows()
            )));
        }
        let inputs = [(2, &self.coefficients), (4, &coords.buffer)];
        Ok(self.dispatch(gpu, Entry::Evaluate, coords.count, 0, &inputs, out))
    }

    /// Evaluates the places `coords` into `out`, submitted now.
    ///
    /// # Errors
    /// As [`Self::bind_evaluate`].
    pub fn evaluate(
        &self,
        gpu: &Gpu,
        coords: &GpuPatchCoords,
        out: &GpuPatchValues,
    ) -> Result<(), GpuError> {
        self.bind_evaluate(gpu, coords, out)?.submit(gpu);
        Ok(())
    }

    /// The buffers of every patch's `rate × rate` grid, its triangle list computed now and
    /// its samples evaluated now from the current points ([`GpuTessellation::evaluate`]
    /// again after an update).
    ///
    /// # Errors
    /// [`GpuError::Mismatch`] for a rate of 0; [`GpuError::TooLarge`] where the grid does
    /// not fit the device's buffers (or 32-bit indices); the device's memory errors.
    pub fn tessellation(&self, gpu: &Gpu, rate: usize) -> Result<GpuTessellation, GpuError> {
        if rate == 0 {
            return Err(GpuError::Mismatch("a tessellation rate of 0".into()));
        }
        let side = rate as u64 + 1;
        let samples = side
            .checked_mul(side)
            .and_then(|n| n.checked_mul(self.patches as u64))
            .unwrap_or(u64::MAX);
        let cells = (rate as u64 * rate as u64).saturating_mul(self.patches as u64);
        // The grid's weights (per class and sample, 60 numbers) are built on the host first.
        let weight_bytes = (self.bases.len() as u64)
            .saturating_mul(side.saturating_mul(side))
            .saturating_mul(60 * 8);
        gpu.check_size("tessellation weights", weight_bytes)?;
        if samples > u64::from(u32::MAX) {
            return Err(GpuError::TooLarge {
                what: "tessellation samples (32-bit indices)",
                bytes: samples.saturating_mul(4),
                limit: u64::from(u32::MAX) * 4,
            });
        }
        let values = GpuPatchValues::new(gpu, samples as usize)?;
        let triangles = 2 * cells as usize; // quads: two per cell; triangle patches: rate²
        let triangles = if self.triangles {
            triangles / 2
        } else {
            triangles
        };
        let usage = wgpu::BufferUsages::INDEX | wgpu::BufferUsages::COPY_SRC;
        let indices = gpu.storage_of_size("tessellation indices", triangles as u64 * 12, usage)?;
        let index_dispatch = self.index_dispatch(gpu, rate, cells as usize, &indices);
        index_dispatch.submit(gpu);
        let weights = self.grid_weights(gpu, rate)?;
        let inputs = [(9, &weights)];
        let samples = samples as usize;
        let dispatch = self.dispatch(gpu, Entry::Tessellate, samples, rate, &inputs, &values);
        dispatch.submit(gpu);
        Ok(GpuTessellation {
            rate,
            values,
            indices,
            triangles,
            dispatch,
            _weights: weights,
        })
    }

    /// `entry` (evaluate or tessellate) over `count` places into `out`; `inputs` the
    /// entry's own buffers with their bindings (the places and bases, or the grid's
    /// weights).
    fn dispatch(
        &self,
        gpu: &Gpu,
        entry: Entry,
        count: usize,
        rate: usize,
        inputs: &[(u32, &wgpu::Buffer)],
        out: &GpuPatchValues,
    ) -> PatchDispatch {
        let (grid, per_line) = gpu.dispatch_grid(count, WORKGROUP);
        let uniform = gpu.uniform("patch parameters", &self.params(count, per_line, rate));
        let mut buffers = vec![(0, &uniform), (1, &self.words), (3, &self.points.buffer)];
        buffers.extend_from_slice(inputs);
        buffers.extend([
            (5, &out.positions.buffer),
            (6, &out.du.buffer),
            (7, &out.dv.buffer),
        ]);
        let pipelines = &gpu.patch_pipelines;
        let pipeline = match entry {
            Entry::Evaluate => &pipelines.evaluate,
            _ => &pipelines.tessellate,
        };
        let bind_group = gpu.bind_group("patches", pipeline, &buffers);
        PatchDispatch {
            bind_group,
            grid,
            entry,
            _parameters: uniform,
        }
    }

    /// The weights (position, ∂s, ∂t) of every class's control points at every sample of
    /// a `rate` grid, in the device's precision: the same for every patch of a class, so a
    /// sample is one weighted sum of its patch's points.
    fn grid_weights(&self, gpu: &Gpu, rate: usize) -> Result<wgpu::Buffer, GpuError> {
        let side = rate + 1;
        let mut weights = Vec::with_capacity(self.bases.len() * side * side * 60);
        for basis in &self.bases {
            for y in 0..side {
                for x in 0..side {
                    let (mut s, mut t) = (x as f64 / rate as f64, y as f64 / rate as f64);
                    if basis.is_triangle() && s + t > 1.0 {
                        (s, t) = (s / (s + t), t / (s + t));
                    }
                    let w = basis.weights(s, t);
                    for k in 0..20 {
                        weights.extend((0..3).map(|d| w[d].get(k).copied().unwrap_or(0.0)));
                    }
                }
            }
        }
        gpu.storage_real("tessellation weights", &weights)
    }

    /// The triangle list of the `rate` grids (`cells` cells in all) into `indices`.
    fn index_dispatch(
        &self,
        gpu: &Gpu,
        rate: usize,
        cells: usize,
        indices: &wgpu::Buffer,
    ) -> PatchDispatch {
        let (grid, per_line) = gpu.dispatch_grid(cells, WORKGROUP);
        let uniform = gpu.uniform("grid parameters", &self.params(cells, per_line, rate));
        let buffers = [(0, &uniform), (1, &self.words), (8, indices)];
        let pipeline = &gpu.patch_pipelines.grid_indices;
        let bind_group = gpu.bind_group("grid indices", pipeline, &buffers);
        PatchDispatch {
            bind_group,
            grid,
            entry: Entry::GridIndices,
            _parameters: uniform,
        }
    }

    /// `patches.wgsl`'s `Params`.
    fn params(&self, count: usize, per_line: u32, rate: usize) -> [u32; 8] {
        [
            count as u32,
            per_line,
            rate as u32,
            self.patches as u32,
            self.cps_base,
            self.classes_base,
            0,
            0,
        ]
    }
}

/// The stencil dispatches of a table's levels and local points: level 1 reads the base
/// rows of `points`, each deeper level the level above, the local points all of `points`.
fn level_dispatches(
    gpu: &Gpu,
    tables: &[GpuStencilTable],
    points: &GpuColumns,
    parts: &[GpuColumns],
) -> Result<Vec<StencilDispatch>, GpuError> {
    let last = tables.len() - 1;
    tables
        .iter()
        .enumerate()
        .map(|(k, table)| {
            if k == 0 || k == last {
                table.bind_prefix(gpu, points, &parts[k])
            } else {
                table.bind(gpu, &parts[k - 1], &parts[k])
            }
        })
        .collect()
}
