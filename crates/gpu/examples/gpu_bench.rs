//! The GPU's stencil evaluation against the CPU's refinement, one run:
//!
//! ```text
//! cargo run --release -p subd-gpu --example gpu_bench -- [QUADS] [LEVELS] [REPEATS]
//! ```
//!
//! A closed quad torus of about QUADS faces (default 100,000), Catmull-Clark to LEVELS
//! (default 3). Times, medians of REPEATS (default 7): uploading the stencil tables, one
//! frame's compute (every level from a new cage, the cage already written), writing the
//! cage, reading the last level back; and the CPU computing the same level from the cage
//! on all its cores (`Refinement::points_at`). Then the cage's patch table (OpenSubdiv's
//! default options) tessellated at rate 8 on the device (every patch's 9 × 9 samples:
//! positions and derivatives), against the CPU's tessellation of the same table on all
//! its cores (`tessellate_patches`, the same number of samples). Last, the cage refined
//! uniformly to LEVELS + 1 on the device, topology and points (`GpuUniformRefinement`),
//! against the CPU's `Refinement::new` + `points_at` on all its cores. `cargo xtask bench
//! --gpu` runs it.

use std::time::Instant;

use subd_gpu::{Gpu, GpuPatchTable, GpuRefiner, GpuUniformRefinement, LevelTables};
use subd_limit::patches::{PatchOptions, PatchTable};
use subd_schemes::{Options, Refinement, Scheme};

fn median(mut t: Vec<f64>) -> f64 {
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

fn timed(repeats: usize, mut f: impl FnMut()) -> f64 {
    median(
        (0..repeats.max(1))
            .map(|_| {
                let t = Instant::now();
                f();
                t.elapsed().as_secs_f64()
            })
            .collect(),
    )
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let quads = args.first().copied().unwrap_or(100_000);
    let levels = args.get(1).copied().unwrap_or(3);
    let repeats = args.get(2).copied().unwrap_or(7);
    let side = (quads as f64).sqrt().round().max(3.0) as u32;
    let cage = subd_mesh::primitives::torus(side, side, 1.0, 0.3);
    let gpu = Gpu::new()?;
    let adapter = gpu.adapter();
    println!(
        "device: {} ({}, {}); sums {:?}",
        adapter.name,
        adapter.backend,
        adapter.device_type,
        gpu.precision()
    );
    // A part the device cannot hold (a buffer past its limits) is reported and skipped.
    let parts = [
        ("stencils", stencils(&gpu, &cage, levels, repeats)),
        ("patches", patch_tessellation(&gpu, &cage, repeats)),
        (
            "uniform refinement",
            uniform_refinement(&gpu, &cage, levels + 1, repeats),
        ),
    ];
    for (what, result) in parts {
        if let Err(e) = result {
            println!("{what}: not run: {e}");
        }
    }
    Ok(())
}

/// Every level of the cage's refinement recomputed on the device from the cage, and on the
/// CPU.
fn stencils(
    gpu: &Gpu,
    cage: &subd_mesh::Mesh,
    levels: usize,
    repeats: usize,
) -> Result<(), Box<dyn std::error::Error>> {
    let refinement = Refinement::new(
        &cage.topology,
        Scheme::CatmullClark,
        &Options::default(),
        levels,
    )?;
    let vertices = refinement.num_vertices(levels);
    for l in 1..=levels {
        refinement.stencils(l); // built before the timing: the tables are the input here
    }
    println!(
        "cage: {} quads, Catmull-Clark level {levels}: {vertices} vertices, {} faces; medians of {repeats}",
        cage.topology.num_faces(),
        refinement.faces(levels).0.len() - 1
    );
    let t = Instant::now();
    let refiner = GpuRefiner::new(gpu, &refinement, 3, LevelTables::PerLevel)?;
    gpu.wait()?;
    let upload = t.elapsed().as_secs_f64();
    refiner.update_points(gpu, &cage.positions)?;
    gpu.wait()?;
    let frame = timed(repeats, || {
        refiner.recompute(gpu);
        gpu.wait().expect("the device stays");
    });
    let write = timed(repeats, || {
        refiner
            .update_points(gpu, &cage.positions)
            .expect("same size");
        gpu.wait().expect("the device stays");
    }) - frame;
    let read = timed(repeats, || {
        gpu.read_points(refiner.last()).expect("read back");
    });
    let cpu = timed(repeats, || {
        refinement.points_at(&cage.positions, levels);
    });
    let threads = std::thread::available_parallelism().map_or(1, usize::from);
    println!("tables upload        {upload:9.4} s");
    println!("cage write           {:9.4} s", write.max(0.0));
    println!(
        "frame (all levels)   {frame:9.4} s   {:.3e} vertices/s",
        vertices as f64 / frame
    );
    println!("read back last level {read:9.4} s");
    println!(
        "CPU, {threads} threads      {cpu:9.4} s   GPU frame is {:.2}x the CPU's speed",
        cpu / frame
    );
    Ok(())
}

/// The cage's patch table tessellated at rate 8 on the device and on the CPU.
fn patch_tessellation(
    gpu: &Gpu,
    cage: &subd_mesh::Mesh,
    repeats: usize,
) -> Result<(), Box<dyn std::error::Error>> {
    const RATE: usize = 8;
    let table = PatchTable::new(
        &cage.topology,
        &cage.positions,
        &Scheme::CatmullClark,
        &Options::default(),
        &PatchOptions::default(),
    )?;
    let t = Instant::now();
    let on_device = GpuPatchTable::new(gpu, &table)?;
    let tessellation = on_device.tessellation(gpu, RATE)?;
    gpu.wait()?;
    let upload = t.elapsed().as_secs_f64();
    let samples = tessellation.values.rows();
    let update = timed(repeats, || {
        on_device
            .update_points(gpu, &cage.positions)
            .expect("same size");
        gpu.wait().expect("the device stays");
    });
    let compute = timed(repeats, || {
        tessellation.evaluate(gpu);
        gpu.wait().expect("the device stays");
    });
    let read = timed(repeats, || {
        gpu.read_points(&tessellation.values.positions)
            .expect("read back");
    });
    let cpu = timed(repeats, || {
        subd_limit::tessellation::tessellate_patches(&table, RATE).expect("a built table");
    });
    println!(
        "patches: {} patches at rate {RATE}: {samples} samples",
        on_device.num_patches()
    );
    println!("table upload + grid   {upload:9.4} s");
    println!("points update         {update:9.4} s");
    println!(
        "tessellation compute  {compute:9.4} s   {:.3e} samples/s",
        samples as f64 / compute
    );
    println!("read back positions   {read:9.4} s");
    println!(
        "CPU tessellate_patches {cpu:8.4} s   GPU compute is {:.2}x the CPU's speed",
        cpu / compute
    );
    Ok(())
}

/// The cage refined `levels` levels on the device, topology and points, and on the CPU.
fn uniform_refinement(
    gpu: &Gpu,
    cage: &subd_mesh::Mesh,
    levels: usize,
    repeats: usize,
) -> Result<(), Box<dyn std::error::Error>> {
    let scheme = Scheme::CatmullClark;
    let rules = Options::default();
    let t = Instant::now();
    let on_device = GpuUniformRefinement::new(
        gpu,
        &cage.topology,
        &scheme,
        &rules,
        &cage.positions,
        levels,
    )?;
    gpu.wait()?;
    let first = t.elapsed().as_secs_f64();
    let faces = on_device.num_faces(levels);
    let compute = timed(repeats, || {
        on_device.recompute(gpu);
        gpu.wait().expect("the device stays");
    });
    let read = timed(repeats, || {
        on_device
            .read_face_vertices(gpu, levels)
            .expect("read back");
        gpu.read_points(on_device.points(levels).expect("refined"))
            .expect("read back");
    });
    let cpu = timed(repeats, || {
        let r = subd_schemes::Refinement::new(&cage.topology, scheme.clone(), &rules, levels)
            .expect("a closed quad mesh");
        r.points_at(&cage.positions, levels);
    });
    println!("uniform refinement to level {levels}: {faces} faces");
    println!("upload + first refinement {first:9.4} s");
    println!(
        "refinement compute        {compute:9.4} s   {:.3e} faces/s",
        faces as f64 / compute
    );
    println!("read back faces + points  {read:9.4} s");
    println!(
        "CPU Refinement::new + points_at {cpu:9.4} s   {:.3e} faces/s; GPU compute is {:.2}x",
        faces as f64 / cpu,
        cpu / compute
    );
    Ok(())
}
