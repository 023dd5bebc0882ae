//! A refinement's levels on the device: its stencil tables uploaded once, every level's
//! values recomputed from new base values with one submission.

use subd_mesh::DVec3;
use subd_schemes::Refinement;

use crate::stencils::f32_rows;
use crate::{Gpu, GpuColumns, GpuError, GpuStencilTable, StencilDispatch};

/// How the levels are reached from the base.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LevelTables {
    /// One table per level, each level computed from the one above and kept on the device.
    PerLevel,
    /// One table from the base to the last level (OpenSubdiv's factorized stencils): only
    /// the base and the last level are on the device.
    Composed,
}

/// A [`Refinement`]'s vertex stencils on the device, with a column buffer per level it
/// keeps: [`Self::update`] writes new base values and recomputes the levels.
#[derive(Debug)]
pub struct GpuRefiner {
    /// `levels[0]` holds the base values; then every level (or only the last).
    levels: Vec<GpuColumns>,
    /// The level number of each entry of `levels`.
    level_numbers: Vec<usize>,
    _tables: Vec<GpuStencilTable>,
    dispatches: Vec<StencilDispatch>,
}

impl GpuRefiner {
    /// Uploads the stencils of every level of `refinement` for columns of `width` values
    /// per vertex (3 for positions).
    ///
    /// # Errors
    /// The device's size and memory errors.
    pub fn new(
        gpu: &Gpu,
        refinement: &Refinement,
        width: usize,
        tables: LevelTables,
    ) -> Result<GpuRefiner, GpuError> {
        let last = refinement.num_levels();
        let (cpu_tables, level_numbers) = match tables {
            LevelTables::PerLevel => (
                (1..=last).map(|l| refinement.stencils(l).clone()).collect(),
                (0..=last).collect(),
            ),
            LevelTables::Composed if last == 0 => (Vec::new(), vec![0]),
            LevelTables::Composed => (vec![refinement.composed(last)], vec![0, last]),
        };
        let levels = level_numbers
            .iter()
            .map(|&l| gpu.columns(refinement.num_vertices(l), width))
            .collect::<Result<Vec<_>, _>>()?;
        let tables = cpu_tables
            .iter()
            .map(|t| GpuStencilTable::new(gpu, t))
            .collect::<Result<Vec<_>, _>>()?;
        let dispatches = tables
            .iter()
            .enumerate()
            .map(|(i, t)| t.bind(gpu, &levels[i], &levels[i + 1]))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(GpuRefiner {
            levels,
            level_numbers,
            _tables: tables,
            dispatches,
        })
    }

    /// Writes new base values (rows of the width given to [`Self::new`]) and submits the
    /// recomputation of every level; read the results with [`Gpu::read_columns`] or draw
    /// from [`Self::level`]'s buffer.
    ///
    /// # Errors
    /// [`GpuError::Mismatch`] where `base` is not one row per base vertex.
    pub fn update(&self, gpu: &Gpu, base: &[f32]) -> Result<(), GpuError> {
        gpu.write_columns(&self.levels[0], base)?;
        self.recompute(gpu);
        Ok(())
    }

    /// Submits the recomputation of every level from the base values already in
    /// [`Self::level`]`(0)`'s buffer (written there by the caller's own work, a skinning
    /// shader say).
    pub fn recompute(&self, gpu: &Gpu) {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        self.record(gpu, &mut encoder);
        gpu.queue.submit([encoder.finish()]);
    }

    /// Records the recomputation of every level into `encoder`, after whatever the caller
    /// recorded there before (the levels' dispatches see its writes to the base buffer).
    pub fn record(&self, gpu: &Gpu, encoder: &mut wgpu::CommandEncoder) {
        for d in &self.dispatches {
            d.record(gpu, encoder);
        }
    }

    /// [`Self::update`] with points (width 3).
    ///
    /// # Errors
    /// As [`Self::update`].
    pub fn update_points(&self, gpu: &Gpu, base: &[DVec3]) -> Result<(), GpuError> {
        self.update(gpu, &f32_rows(base))
    }

    /// The values of `level`, where they are kept (every level with
    /// [`LevelTables::PerLevel`]; the base and the last with [`LevelTables::Composed`]).
    pub fn level(&self, level: usize) -> Option<&GpuColumns> {
        let i = self.level_numbers.iter().position(|&l| l == level)?;
        Some(&self.levels[i])
    }

    /// The values of the last level.
    pub fn last(&self) -> &GpuColumns {
        self.levels.last().expect("the base is always kept")
    }
}

/// A face-varying channel (texture coordinates) of a refinement on the device: its last
/// level's values recomputed from new base values through one composed table
/// ([`subd_schemes::FaceVarying::composed`], OpenSubdiv's interpolation modes and the
/// split schemes' alike).
#[derive(Debug)]
pub struct GpuFaceVarying {
    base: GpuColumns,
    last: GpuColumns,
    _table: GpuStencilTable,
    dispatch: StencilDispatch,
}

impl GpuFaceVarying {
    /// Uploads the table from `channel`'s base values to its last level, for values of
    /// `width` numbers each (2 for texture coordinates).
    ///
    /// # Errors
    /// The device's size and memory errors.
    pub fn new(
        gpu: &Gpu,
        channel: &subd_schemes::FaceVarying<'_>,
        width: usize,
    ) -> Result<GpuFaceVarying, GpuError> {
        let table = channel.composed(channel.num_levels());
        let base = gpu.columns(table.num_sources(), width)?;
        let last = gpu.columns(table.num_rows(), width)?;
        let on_device = GpuStencilTable::new(gpu, &table)?;
        let dispatch = on_device.bind(gpu, &base, &last)?;
        Ok(GpuFaceVarying {
            base,
            last,
            _table: on_device,
            dispatch,
        })
    }

    /// Writes new base values and submits the recomputation of the last level's.
    ///
    /// # Errors
    /// [`GpuError::Mismatch`] where `base` is not one row per base value.
    pub fn update(&self, gpu: &Gpu, base: &[f32]) -> Result<(), GpuError> {
        gpu.write_columns(&self.base, base)?;
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        self.dispatch.record(gpu, &mut encoder);
        gpu.queue.submit([encoder.finish()]);
        Ok(())
    }

    /// The last level's values.
    pub fn last(&self) -> &GpuColumns {
        &self.last
    }
}
