//! The kernels' compute pipelines, made once per device: the arithmetic they sum in, how a
//! WGSL source becomes pipelines, and each shader's set. Below the device, which holds
//! them, and the kernels, which dispatch them.

/// The arithmetic of the stencil sums. Values in device buffers are f32 either way.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Precision {
    /// f64 weights and sums (adapters with `SHADER_F64`): every result within about one
    /// f32 rounding of the f64 result, however long its stencil.
    F64,
    /// f32 weights and sums (every adapter): the error grows with a stencil's length, a
    /// few f32 roundings per level's row (e.g. 5 units in the last place on a table composed
    /// over three levels of Catmull-Clark).
    F32,
}

/// The compute pipelines of the WGSL `shader` (named `label`) at `entries`, with its
/// `Real` type the device's precision (f64 or f32), each with the layout the shader implies.
pub(crate) fn compute_pipelines(
    device: &wgpu::Device,
    precision: Precision,
    label: &'static str,
    shader: &str,
    entries: &[&'static str],
) -> Vec<wgpu::ComputePipeline> {
    let real = match precision {
        Precision::F64 => "f64",
        Precision::F32 => "f32",
    };
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(format!("alias Real = {real};\n{shader}").into()),
    });
    entries
        .iter()
        .map(|entry| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: None,
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        })
        .collect()
}

/// The compute pipeline of `stencils.wgsl`, made once per device.
#[derive(Debug)]
pub(crate) struct StencilPipeline {
    pub(crate) pipeline: wgpu::ComputePipeline,
}

impl StencilPipeline {
    pub(crate) fn new(device: &wgpu::Device, precision: Precision) -> StencilPipeline {
        let shader = include_str!("shaders/stencils.wgsl");
        let mut pipelines =
            compute_pipelines(device, precision, "stencils.wgsl", shader, &["apply"]);
        StencilPipeline {
            pipeline: pipelines.remove(0),
        }
    }
}

/// The compute pipelines of `patches.wgsl`, made once per device.
#[derive(Debug)]
pub(crate) struct PatchPipelines {
    pub(crate) evaluate: wgpu::ComputePipeline,
    pub(crate) tessellate: wgpu::ComputePipeline,
    pub(crate) grid_indices: wgpu::ComputePipeline,
}

impl PatchPipelines {
    pub(crate) fn new(device: &wgpu::Device, precision: Precision) -> PatchPipelines {
        let shader = include_str!("shaders/patches.wgsl");
        let entries = ["evaluate", "tessellate", "grid_indices"];
        let [evaluate, tessellate, grid_indices]: [wgpu::ComputePipeline; 3] =
            compute_pipelines(device, precision, "patches.wgsl", shader, &entries)
                .try_into()
                .expect("one pipeline per entry");
        PatchPipelines {
            evaluate,
            tessellate,
            grid_indices,
        }
    }
}

/// The stages of one level of `uniform.wgsl`, in the order they run.
pub(crate) const STAGES: [&str; 9] = [
    "corners",
    "twins",
    "child_faces",
    "edge_halves",
    "face_points",
    "edge_points",
    "vertex_points",
    "child_rules",
    // Not a stage of a level: a level's quads as triangles, on request.
    "quad_triangles",
];

/// The compute pipelines of `uniform.wgsl`, one per stage.
#[derive(Debug)]
pub(crate) struct UniformPipelines {
    pub(crate) stages: Vec<wgpu::ComputePipeline>,
}

impl UniformPipelines {
    pub(crate) fn new(device: &wgpu::Device, precision: Precision) -> UniformPipelines {
        let shader = include_str!("shaders/uniform.wgsl");
        UniformPipelines {
            stages: compute_pipelines(device, precision, "uniform.wgsl", shader, &STAGES),
        }
    }
}
