//! USD stages written by Pixar's USD (`tests/data/usd`, made by `make_stages.py` with
//! `usd-core`): every mesh prim that names a scheme, read by `subd-io` and refined, against
//! OpenSubdiv refining the same mesh with the rules its attributes name; its texture
//! coordinates too, in the prim's face-varying mode.

use std::path::Path;

use subd_io::ReadOptions;
use subd_schemes::{Options, Scheme};

use crate::conformance::row::Row;

/// Rows for every mesh prim of every stage in `dir`.
pub fn stages(exe: &Path, dir: &Path) -> Result<Vec<Row>, String> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            matches!(
                p.extension().and_then(|e| e.to_str()),
                Some("usda" | "usdc" | "usdz")
            )
        })
        .collect();
    files.sort();
    let mut rows = Vec::new();
    for file in files {
        let name = file
            .file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .to_string();
        let prims = subd_io::usd::mesh_prims(&file).map_err(|e| e.to_string())?;
        for prim in prims {
            let options = ReadOptions {
                prim: Some(prim.path.clone()),
                ..ReadOptions::default()
            };
            let read = subd_io::read_mesh(&file, &options).map_err(|e| e.to_string())?;
            let mesh = &read.mesh;
            // A `none` mesh is polygons: nothing to subdivide.
            let Some(scheme) = mesh.hints.scheme.and_then(Scheme::from_file) else {
                continue;
            };
            let options = Options::from_hints(&mesh.hints);
            let label = format!("{name}{}", prim.path);
            rows.extend(crate::conformance::compare(
                exe,
                &label,
                &mesh.topology,
                &mesh.positions,
                &scheme,
                &options,
            ));
            if let (Some(uv), Some(mode)) = (mesh.uv(), mesh.hints.fvar_interpolation) {
                rows.extend(crate::conformance::fvar::compare(
                    exe,
                    &label,
                    &mesh.topology,
                    &mesh.positions,
                    &scheme,
                    &options,
                    uv,
                    mode,
                ));
            }
        }
    }
    if rows.is_empty() {
        return Err(format!("{}: no USD mesh prim to compare", dir.display()));
    }
    Ok(rows)
}
