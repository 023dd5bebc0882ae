//! Limit stencils on the device: a level's limit positions and tangents from its points.

use subd_limit::LimitStencilTable;

use crate::{Gpu, GpuColumns, GpuError, GpuStencilTable};

/// A [`LimitStencilTable`] on the device: position, first and second tangent tables.
#[derive(Debug)]
pub struct GpuLimitStencils {
    position: GpuStencilTable,
    tangent1: GpuStencilTable,
    tangent2: GpuStencilTable,
}

/// The limit of a level on the device: one row per vertex each.
#[derive(Debug)]
pub struct GpuLimit {
    /// Limit positions.
    pub positions: GpuColumns,
    /// First tangents (the convention of [`subd_limit::masks`]); rows of zeros where the
    /// scheme defines no tangents.
    pub tangent1: GpuColumns,
    /// Second tangents.
    pub tangent2: GpuColumns,
}

impl GpuLimitStencils {
    /// Uploads `table`.
    ///
    /// # Errors
    /// The device's size and memory errors.
    pub fn new(gpu: &Gpu, table: &LimitStencilTable) -> Result<GpuLimitStencils, GpuError> {
        Ok(GpuLimitStencils {
            position: GpuStencilTable::new(gpu, &table.position)?,
            tangent1: GpuStencilTable::new(gpu, &table.tangent1)?,
            tangent2: GpuStencilTable::new(gpu, &table.tangent2)?,
        })
    }

    /// Number of vertices (rows).
    pub fn num_rows(&self) -> usize {
        self.position.num_rows()
    }

    /// Buffers for the limit of columns of `width` values per vertex.
    ///
    /// # Errors
    /// The device's size and memory errors.
    pub fn outputs(&self, gpu: &Gpu, width: usize) -> Result<GpuLimit, GpuError> {
        let rows = self.num_rows();
        Ok(GpuLimit {
            positions: gpu.columns(rows, width)?,
            tangent1: gpu.columns(rows, width)?,
            tangent2: gpu.columns(rows, width)?,
        })
    }

    /// Computes the limit of `points` (the level's values) into `out`, submitted now.
    ///
    /// # Errors
    /// [`GpuError::Mismatch`] where `points` is not one row per vertex or `out` not
    /// [`Self::outputs`] of its width.
    pub fn apply(&self, gpu: &Gpu, points: &GpuColumns, out: &GpuLimit) -> Result<(), GpuError> {
        let dispatches = [
            self.position.bind(gpu, points, &out.positions)?,
            self.tangent1.bind(gpu, points, &out.tangent1)?,
            self.tangent2.bind(gpu, points, &out.tangent2)?,
        ];
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        for d in &dispatches {
            d.record(gpu, &mut encoder);
        }
        gpu.queue.submit([encoder.finish()]);
        Ok(())
    }
}
