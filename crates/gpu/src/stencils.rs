//! Stencil tables on the device: uploaded once, applied to columns of f32 values as often
//! as the source values change (every frame, for an animated cage).

use subd_mesh::DVec3;
use subd_schemes::StencilTable;

use crate::{Gpu, GpuError};

/// Threads per workgroup of the stencil shader (`@workgroup_size` in `stencils.wgsl`).
const WORKGROUP: u32 = 64;

/// Rows of `width` interleaved f32 columns in a device buffer: row `i`'s column `c` is the
/// f32 at index `i * width + c` (positions are `width` 3: x, y, z). The buffer is a
/// storage buffer that may also be copied from and to and bound as a vertex buffer, so a
/// renderer can draw from it directly.
#[derive(Debug)]
pub struct GpuColumns {
    pub(crate) buffer: wgpu::Buffer,
    pub(crate) rows: usize,
    pub(crate) width: usize,
}

impl GpuColumns {
    /// The device buffer (layout above).
    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// f32 values per row.
    pub fn width(&self) -> usize {
        self.width
    }

    pub(crate) fn bytes(&self) -> u64 {
        (self.rows * self.width * 4) as u64
    }
}

/// How a column buffer may be used besides storage.
fn column_usage() -> wgpu::BufferUsages {
    wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::VERTEX
}

impl Gpu {
    /// Uploads rows of `width` f32 values (`values.len()` a multiple of `width`).
    ///
    /// # Errors
    /// [`GpuError::Mismatch`] for a length that is not whole rows; the device's size and
    /// memory errors.
    pub fn upload_columns(&self, values: &[f32], width: usize) -> Result<GpuColumns, GpuError> {
        if width == 0 || !values.len().is_multiple_of(width) {
            return Err(GpuError::Mismatch(format!(
                "{} values are not whole rows of {width}",
                values.len()
            )));
        }
        Ok(GpuColumns {
            buffer: self.storage("columns", values, column_usage())?,
            rows: values.len() / width,
            width,
        })
    }

    /// Uploads points as rows of three f32 values.
    ///
    /// # Errors
    /// The device's size and memory errors.
    pub fn upload_points(&self, points: &[DVec3]) -> Result<GpuColumns, GpuError> {
        self.upload_columns(&f32_rows(points), 3)
    }

    /// Rows of `width` f32 values, their contents undefined until written.
    ///
    /// # Errors
    /// The device's size and memory errors.
    pub fn columns(&self, rows: usize, width: usize) -> Result<GpuColumns, GpuError> {
        let bytes = (rows as u64).saturating_mul(width as u64).saturating_mul(4);
        Ok(GpuColumns {
            buffer: self.storage_of_size("columns", bytes, column_usage())?,
            rows,
            width,
        })
    }

    /// Replaces the values of `columns` (same number of rows and width), as a frame does
    /// with its new cage.
    ///
    /// # Errors
    /// [`GpuError::Mismatch`] where `values` is not `columns`' size.
    pub fn write_columns(&self, columns: &GpuColumns, values: &[f32]) -> Result<(), GpuError> {
        if values.len() != columns.rows * columns.width {
            return Err(GpuError::Mismatch(format!(
                "{} values given for {} rows of {}",
                values.len(),
                columns.rows,
                columns.width
            )));
        }
        if !values.is_empty() {
            self.queue
                .write_buffer(&columns.buffer, 0, bytemuck::cast_slice(values));
        }
        Ok(())
    }

    /// Reads `columns` back to the host (waiting for the work submitted before).
    ///
    /// # Errors
    /// [`GpuError::Failed`] when the device fails.
    pub fn read_columns(&self, columns: &GpuColumns) -> Result<Vec<f32>, GpuError> {
        self.read_f32(&columns.buffer, columns.bytes())
    }

    /// Reads rows of three columns back as points.
    ///
    /// # Errors
    /// [`GpuError::Mismatch`] where the width is not 3; [`GpuError::Failed`] when the
    /// device fails.
    pub fn read_points(&self, columns: &GpuColumns) -> Result<Vec<DVec3>, GpuError> {
        if columns.width != 3 {
            return Err(GpuError::Mismatch(format!(
                "points are rows of 3 values, not {}",
                columns.width
            )));
        }
        let values = self.read_columns(columns)?;
        Ok(values
            .chunks_exact(3)
            .map(|p| DVec3::new(p[0].into(), p[1].into(), p[2].into()))
            .collect())
    }
}

/// Points as interleaved f32 values.
pub(crate) fn f32_rows(points: &[DVec3]) -> Vec<f32> {
    points
        .iter()
        .flat_map(|p| [p.x as f32, p.y as f32, p.z as f32])
        .collect()
}

/// A [`StencilTable`] on the device, its weights in the device's [`Precision`](crate::Precision).
#[derive(Debug)]
pub struct GpuStencilTable {
    offsets: wgpu::Buffer,
    indices: wgpu::Buffer,
    weights: wgpu::Buffer,
    rows: usize,
    sources: usize,
}

impl GpuStencilTable {
    /// Uploads `table`.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] for a table past the device's buffer limits;
    /// [`GpuError::OutOfMemory`].
    pub fn new(gpu: &Gpu, table: &StencilTable) -> Result<GpuStencilTable, GpuError> {
        let none = wgpu::BufferUsages::empty();
        let weights = gpu.storage_real("stencil weights", table.weights())?;
        Ok(GpuStencilTable {
            offsets: gpu.storage("stencil offsets", table.offsets(), none)?,
            indices: gpu.storage("stencil indices", table.indices(), none)?,
            weights,
            rows: table.num_rows(),
            sources: table.num_sources(),
        })
    }

    /// Number of rows (destination values).
    pub fn num_rows(&self) -> usize {
        self.rows
    }

    /// Number of source rows it reads.
    pub fn num_sources(&self) -> usize {
        self.sources
    }

    /// Binds `src` and `dst` to the table: a dispatch to record as often as `src` changes,
    /// with no allocation after this.
    ///
    /// # Errors
    /// [`GpuError::Mismatch`] where `src` has not [`Self::num_sources`] rows, `dst` not
    /// [`Self::num_rows`], or their widths differ.
    pub fn bind(
        &self,
        gpu: &Gpu,
        src: &GpuColumns,
        dst: &GpuColumns,
    ) -> Result<StencilDispatch, GpuError> {
        self.check(src, dst)?;
        Ok(self.dispatch(gpu, src, dst))
    }

    /// [`Self::bind`] for a source holding the table's source rows first and more after
    /// them (a patch table's points, whose first level a table reads).
    pub(crate) fn bind_prefix(
        &self,
        gpu: &Gpu,
        src: &GpuColumns,
        dst: &GpuColumns,
    ) -> Result<StencilDispatch, GpuError> {
        if src.rows < self.sources || dst.rows != self.rows || src.width != dst.width {
            return Err(self.mismatch(src, dst));
        }
        Ok(self.dispatch(gpu, src, dst))
    }

    fn dispatch(&self, gpu: &Gpu, src: &GpuColumns, dst: &GpuColumns) -> StencilDispatch {
        let rows = if src.width == 0 { 0 } else { self.rows };
        let (grid, per_line) = gpu.dispatch_grid(rows, WORKGROUP);
        let params = [self.rows as u32, src.width as u32, per_line, 0];
        let uniform = gpu.uniform("stencil parameters", &params);
        let buffers = [
            (0, &uniform),
            (1, &self.offsets),
            (2, &self.indices),
            (3, &self.weights),
            (4, &src.buffer),
            (5, &dst.buffer),
        ];
        let bind_group = gpu.bind_group("stencils", &gpu.pipelines.pipeline, &buffers);
        StencilDispatch {
            bind_group,
            grid,
            _parameters: uniform,
        }
    }

    /// `dst = table · src`, submitted now.
    ///
    /// # Errors
    /// As [`Self::bind`].
    pub fn apply(&self, gpu: &Gpu, src: &GpuColumns, dst: &GpuColumns) -> Result<(), GpuError> {
        let dispatch = self.bind(gpu, src, dst)?;
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        dispatch.record(gpu, &mut encoder);
        gpu.queue.submit([encoder.finish()]);
        Ok(())
    }

    fn check(&self, src: &GpuColumns, dst: &GpuColumns) -> Result<(), GpuError> {
        if src.rows != self.sources || dst.rows != self.rows || src.width != dst.width {
            return Err(self.mismatch(src, dst));
        }
        Ok(())
    }

    fn mismatch(&self, src: &GpuColumns, dst: &GpuColumns) -> GpuError {
        GpuError::Mismatch(format!(
            "a table from {} rows to {} applied to {} rows of {} into {} rows of {}",
            self.sources, self.rows, src.rows, src.width, dst.rows, dst.width
        ))
    }
}

/// A stencil table bound to its source and destination columns (see
/// [`GpuStencilTable::bind`]).
#[derive(Debug)]
pub struct StencilDispatch {
    bind_group: wgpu::BindGroup,
    /// Workgroups in x and y; (0, 0) when there is nothing to do.
    grid: (u32, u32),
    _parameters: wgpu::Buffer,
}

impl StencilDispatch {
    /// Records the table's application into `encoder` (nothing runs until the encoder's
    /// commands are submitted). Dispatches recorded one after another in one encoder run
    /// in order, each seeing the writes of those before (a level reads the one above).
    pub fn record(&self, gpu: &Gpu, encoder: &mut wgpu::CommandEncoder) {
        if self.grid.0 == 0 {
            return;
        }
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&gpu.pipelines.pipeline);
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.dispatch_workgroups(self.grid.0, self.grid.1, 1);
    }
}
