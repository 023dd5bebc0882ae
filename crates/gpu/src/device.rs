//! The device: one adapter, its device and queue, and the moves of f32 columns between the
//! host and the device.

use std::sync::{Arc, Mutex, mpsc};

use wgpu::util::DeviceExt;

use crate::GpuError;
use crate::pipeline::Precision;

/// An adapter as `subd info --devices` lists it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AdapterSummary {
    /// The adapter's name (e.g. "NVIDIA H100", "llvmpipe (LLVM 15.0.6, 256 bits)").
    pub name: String,
    /// The backend: Vulkan, Metal or Dx12.
    pub backend: String,
    /// Discrete, integrated, virtual, CPU (software) or other.
    pub device_type: String,
    /// The driver and its version, as the adapter reports them.
    pub driver: String,
    /// Whether the adapter offers 64-bit floats in shaders.
    pub shader_f64: bool,
}

impl AdapterSummary {
    fn of(adapter: &wgpu::Adapter) -> AdapterSummary {
        let info = adapter.get_info();
        AdapterSummary {
            name: info.name,
            backend: format!("{:?}", info.backend),
            device_type: format!("{:?}", info.device_type),
            driver: format!("{} {}", info.driver, info.driver_info)
                .trim()
                .to_string(),
            shader_f64: adapter.features().contains(wgpu::Features::SHADER_F64),
        }
    }
}

/// Routes the device's loss and its uncaught errors to a [`Health`] instead of wgpu's
/// default panic.
fn watch(device: &wgpu::Device) -> Arc<Health> {
    let health = Arc::new(Health::default());
    let lost = Arc::clone(&health);
    device.set_device_lost_callback(move |reason, message| {
        lost.fail(format!("the device was lost ({reason:?}): {message}"));
    });
    let uncaught = Arc::clone(&health);
    device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| uncaught.fail(e.to_string())));
    health
}

/// The native backends (Vulkan, Metal, DX12), no GL: compute shaders with storage buffers.
fn instance() -> wgpu::Instance {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    desc.backends = wgpu::Backends::VULKAN | wgpu::Backends::METAL | wgpu::Backends::DX12;
    wgpu::Instance::new(desc)
}

/// Every adapter this machine offers, best first as wgpu orders them.
pub fn list_adapters() -> Vec<AdapterSummary> {
    let instance = instance();
    let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()));
    adapters.iter().map(AdapterSummary::of).collect()
}

/// What the device's callbacks saw: its loss, or an error no error scope caught (wgpu's
/// default for those is a panic; subd reports them from [`Gpu::check`] and [`Gpu::wait`]).
#[derive(Debug, Default)]
struct Health {
    failure: Mutex<Option<String>>,
}

impl Health {
    /// Keeps the first failure: later ones usually follow from it.
    fn fail(&self, message: String) {
        let mut failure = self.failure.lock().unwrap_or_else(|e| e.into_inner());
        failure.get_or_insert(message);
    }

    fn check(&self) -> Result<(), GpuError> {
        let failure = self.failure.lock().unwrap_or_else(|e| e.into_inner());
        match failure.as_ref() {
            Some(message) => Err(GpuError::Failed(message.clone())),
            None => Ok(()),
        }
    }
}

/// A device to run subd's compute shaders on, with its queue.
#[derive(Debug)]
pub struct Gpu {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    adapter: AdapterSummary,
    pub(crate) limits: wgpu::Limits,
    precision: Precision,
    pub(crate) pipelines: crate::pipeline::StencilPipeline,
    pub(crate) patch_pipelines: crate::pipeline::PatchPipelines,
    pub(crate) uniform_pipelines: crate::pipeline::UniformPipelines,
    health: Arc<Health>,
}

impl Gpu {
    /// The system's preferred high-performance adapter, with the largest buffers it allows,
    /// summing in f64 where the adapter has it ([`Precision`]).
    ///
    /// # Errors
    /// [`GpuError::NoAdapter`] where the machine has none, [`GpuError::Device`] where it
    /// refuses a device.
    pub fn new() -> Result<Gpu, GpuError> {
        Gpu::with_precision(None)
    }

    /// As [`Self::new`], with the precision chosen: `Some(Precision::F32)` on any adapter
    /// (faster where f64 is slow), `Some(Precision::F64)` only where the adapter has it.
    ///
    /// # Errors
    /// As [`Self::new`]; [`GpuError::Device`] when f64 is asked of an adapter without it.
    pub fn with_precision(precision: Option<Precision>) -> Result<Gpu, GpuError> {
        let instance = instance();
        let options = wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            ..Default::default()
        };
        let adapter = pollster::block_on(instance.request_adapter(&options))
            .map_err(|e| GpuError::NoAdapter(e.to_string()))?;
        let summary = AdapterSummary::of(&adapter);
        let precision = match (precision, summary.shader_f64) {
            (Some(Precision::F64), false) => {
                return Err(GpuError::Device {
                    adapter: summary.name,
                    message: "it has no 64-bit floats in shaders (SHADER_F64)".into(),
                });
            }
            (Some(p), _) => p,
            (None, true) => Precision::F64,
            (None, false) => Precision::F32,
        };
        let required_features = match precision {
            Precision::F64 => wgpu::Features::SHADER_F64,
            Precision::F32 => wgpu::Features::empty(),
        };
        // Storage buffers as large as the adapter allows: a refined level's columns and
        // tables are the largest arrays subd hands the device.
        let limits = adapter.limits();
        let desc = wgpu::DeviceDescriptor {
            label: Some("subd"),
            required_limits: limits.clone(),
            required_features,
            ..Default::default()
        };
        let (device, queue) =
            pollster::block_on(adapter.request_device(&desc)).map_err(|e| GpuError::Device {
                adapter: summary.name.clone(),
                message: e.to_string(),
            })?;
        let health = watch(&device);
        let pipelines = crate::pipeline::StencilPipeline::new(&device, precision);
        let patch_pipelines = crate::pipeline::PatchPipelines::new(&device, precision);
        let uniform_pipelines = crate::pipeline::UniformPipelines::new(&device, precision);
        health.check()?;
        Ok(Gpu {
            device,
            queue,
            adapter: summary,
            limits,
            precision,
            pipelines,
            patch_pipelines,
            uniform_pipelines,
            health,
        })
    }

    /// The arithmetic of the stencil sums.
    pub fn precision(&self) -> Precision {
        self.precision
    }

    /// The adapter this device is on.
    pub fn adapter(&self) -> &AdapterSummary {
        &self.adapter
    }

    /// The underlying `wgpu` device and queue, for a renderer that draws from subd's
    /// buffers or records its own work beside subd's.
    pub fn device_and_queue(&self) -> (&wgpu::Device, &wgpu::Queue) {
        (&self.device, &self.queue)
    }

    /// The workgroups (x, y) of a dispatch of `invocations` invocations in workgroups of
    /// `workgroup`, and the invocations per line of that grid: a grid is two-dimensional
    /// where one dimension cannot hold every workgroup. (0, 0) for no work.
    pub(crate) fn dispatch_grid(&self, invocations: usize, workgroup: u32) -> ((u32, u32), u32) {
        let groups = (invocations as u32).div_ceil(workgroup);
        let max = self.limits.max_compute_workgroups_per_dimension;
        let grid = (groups.min(max), groups.div_ceil(max));
        if invocations == 0 {
            return ((0, 0), grid.0 * workgroup);
        }
        (grid, grid.0 * workgroup)
    }

    /// A uniform buffer holding `words`.
    pub(crate) fn uniform(&self, what: &'static str, words: &[u32]) -> wgpu::Buffer {
        self.device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(what),
                contents: bytemuck::cast_slice(words),
                usage: wgpu::BufferUsages::UNIFORM,
            })
    }

    /// A bind group of `pipeline`'s group 0 with `buffers` at their bindings.
    pub(crate) fn bind_group(
        &self,
        what: &'static str,
        pipeline: &wgpu::ComputePipeline,
        buffers: &[(u32, &wgpu::Buffer)],
    ) -> wgpu::BindGroup {
        let entries: Vec<wgpu::BindGroupEntry<'_>> = buffers
            .iter()
            .map(|&(binding, b)| wgpu::BindGroupEntry {
                binding,
                resource: b.as_entire_binding(),
            })
            .collect();
        self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(what),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &entries,
        })
    }

    /// Checks a storage buffer of `bytes` against the device's limits.
    pub(crate) fn check_size(&self, what: &'static str, bytes: u64) -> Result<(), GpuError> {
        let limit = self
            .limits
            .max_storage_buffer_binding_size
            .min(self.limits.max_buffer_size);
        if bytes > limit {
            return Err(GpuError::TooLarge { what, bytes, limit });
        }
        Ok(())
    }

    /// A storage buffer holding `data` (at least 8 bytes: a binding may not be empty, nor
    /// shorter than one element, f64 included).
    pub(crate) fn storage<T: bytemuck::Pod>(
        &self,
        what: &'static str,
        data: &[T],
        usage: wgpu::BufferUsages,
    ) -> Result<wgpu::Buffer, GpuError> {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        self.check_size(what, bytes.len() as u64)?;
        let padding = [0_u8; 8];
        let contents = if bytes.is_empty() {
            &padding[..]
        } else {
            bytes
        };
        self.allocating(what, || {
            self.device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(what),
                    contents,
                    usage: wgpu::BufferUsages::STORAGE | usage,
                })
        })
    }

    /// A storage buffer of real numbers in the device's [`Precision`]: `values` as they
    /// are (f64) or rounded once to f32.
    pub(crate) fn storage_real(
        &self,
        what: &'static str,
        values: &[f64],
    ) -> Result<wgpu::Buffer, GpuError> {
        let none = wgpu::BufferUsages::empty();
        match self.precision {
            Precision::F64 => self.storage(what, values, none),
            Precision::F32 => {
                let rounded: Vec<f32> = values.iter().map(|&x| x as f32).collect();
                self.storage(what, &rounded, none)
            }
        }
    }

    /// An uninitialised storage buffer of `bytes` (at least 4).
    pub(crate) fn storage_of_size(
        &self,
        what: &'static str,
        bytes: u64,
        usage: wgpu::BufferUsages,
    ) -> Result<wgpu::Buffer, GpuError> {
        self.check_size(what, bytes)?;
        self.allocating(what, || {
            self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(what),
                size: bytes.max(4).next_multiple_of(4),
                usage: wgpu::BufferUsages::STORAGE | usage,
                mapped_at_creation: false,
            })
        })
    }

    /// Runs `allocate`, turning the device's out-of-memory or validation error into a
    /// [`GpuError`] instead of wgpu's default (a panic).
    fn allocating(
        &self,
        what: &'static str,
        allocate: impl FnOnce() -> wgpu::Buffer,
    ) -> Result<wgpu::Buffer, GpuError> {
        let memory = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let buffer = allocate();
        let invalid = pollster::block_on(validation.pop());
        let oom = pollster::block_on(memory.pop());
        if oom.is_some() {
            return Err(GpuError::OutOfMemory { what });
        }
        if let Some(e) = invalid {
            return Err(GpuError::Failed(format!("allocating {what}: {e}")));
        }
        Ok(buffer)
    }

    /// Copies `bytes` bytes of `buffer` back to the host as f32 values, waiting for the
    /// device to finish the work submitted before.
    pub(crate) fn read_f32(&self, buffer: &wgpu::Buffer, bytes: u64) -> Result<Vec<f32>, GpuError> {
        self.read_back(buffer, bytes)
    }

    /// Reads the first `bytes` bytes of a buffer of u32 values (an index buffer subd
    /// made) back to the host, waiting for the work submitted before.
    ///
    /// # Errors
    /// [`GpuError::Mismatch`] for a length past the buffer or not whole u32 values;
    /// [`GpuError::Failed`] when the device fails.
    pub fn read_u32(&self, buffer: &wgpu::Buffer, bytes: u64) -> Result<Vec<u32>, GpuError> {
        if bytes > buffer.size() || !bytes.is_multiple_of(4) {
            return Err(GpuError::Mismatch(format!(
                "{bytes} bytes read from a buffer of {} (whole u32 values within it)",
                buffer.size()
            )));
        }
        self.read_back(buffer, bytes)
    }

    /// Copies `bytes` bytes of `buffer` back to the host as values of `T`, waiting for the
    /// device to finish the work submitted before.
    pub(crate) fn read_back<T: bytemuck::Pod>(
        &self,
        buffer: &wgpu::Buffer,
        bytes: u64,
    ) -> Result<Vec<T>, GpuError> {
        if bytes == 0 {
            return Ok(Vec::new());
        }
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("read-back"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, bytes);
        self.queue.submit([encoder.finish()]);
        let slice = staging.slice(..);
        let (sent, received) = mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            // The receiver waits below; it cannot be gone.
            let _ = sent.send(r);
        });
        self.wait()?;
        received
            .recv()
            .map_err(|e| GpuError::Failed(e.to_string()))?
            .map_err(|e| GpuError::Failed(format!("reading back: {e}")))?;
        let values = {
            let view = slice
                .get_mapped_range()
                .map_err(|e| GpuError::Failed(format!("reading back: {e}")))?;
            bytemuck::cast_slice::<u8, T>(&view).to_vec()
        };
        staging.unmap();
        Ok(values)
    }

    /// Waits for the work submitted so far.
    ///
    /// # Errors
    /// [`GpuError::Failed`] when the device is lost, a command failed, or the wait fails.
    pub fn wait(&self) -> Result<(), GpuError> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Failed(e.to_string()))?;
        self.check()
    }

    /// Whether the device still works: [`GpuError::Failed`] once it was lost (a driver
    /// reset, a removed GPU) or a command failed; every later call fails alike, and the
    /// caller opens a new [`Gpu`] (or goes on on the CPU).
    ///
    /// # Errors
    /// As said.
    pub fn check(&self) -> Result<(), GpuError> {
        self.health.check()
    }
}
