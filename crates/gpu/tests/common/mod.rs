//! What the device tests share: the device (or a loud skip outside CI), the OSD shapes and
//! the size their tolerances are relative to.

use std::path::{Path, PathBuf};

use subd_gpu::{Gpu, Precision};
use subd_mesh::{DVec3, Mesh};
use subd_schemes::Scheme;

/// The device, or None outside CI where the machine has no adapter (said loudly). In CI
/// (`CI` set) a missing adapter fails the test: CI installs Mesa's lavapipe.
pub fn gpu() -> Option<Gpu> {
    gpu_with(None)
}

/// [`gpu`] with the sums' precision chosen.
pub fn gpu_with(precision: Option<Precision>) -> Option<Gpu> {
    match Gpu::with_precision(precision) {
        Ok(g) => Some(g),
        Err(e) if std::env::var_os("CI").is_some() => panic!("CI needs a GPU adapter: {e}"),
        Err(e) => {
            eprintln!("SKIPPED: no GPU adapter ({e}); install mesa-vulkan-drivers");
            None
        }
    }
}

/// The OSD regression shapes, in name order, with the scheme their name gives.
pub fn osd_shapes() -> Vec<(PathBuf, Scheme)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/meshes/osd");
    let mut out: Vec<(PathBuf, Scheme)> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| {
            let path = e.unwrap().path();
            let name = path.file_name()?.to_str()?.to_string();
            let scheme = match name.split('_').next()? {
                "catmark" => Scheme::CatmullClark,
                "loop" => Scheme::Loop,
                "bilinear" => Scheme::Bilinear,
                _ => return None,
            };
            name.ends_with(".obj").then_some((path, scheme))
        })
        .collect();
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

/// A shape as the OSD regression suite has it (some have faces wound against their
/// neighbours, which OpenSubdiv accepts).
pub fn read_shape(path: &Path) -> Mesh {
    let options = subd_io::ReadOptions {
        accept_inconsistent_orientation: true,
        ..Default::default()
    };
    subd_io::read_mesh(path, &options).unwrap().mesh
}

/// The bounding-box diagonal of `points`.
pub fn diagonal(points: &[DVec3]) -> f64 {
    let (lo, hi) = subd_mesh::bounding_box(points.iter().copied()).unwrap();
    (hi - lo).length().max(1e-300)
}
