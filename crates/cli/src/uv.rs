//! Texture coordinates through the commands: a mesh's first face-varying channel refined
//! with the mesh (or taken to its limit) and handed to the writers.

use subd_limit::LimitStencilTable;
use subd_mesh::DVec3;
use subd_mesh::Topology;
use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};
use subd_schemes::split_schemes::{SplitFVarError, SplitFaceVarying};
use subd_schemes::{Options, Refinement, Scheme};

/// `view` with the texture coordinates `uv`, if any.
pub(crate) fn with_uv<'a>(
    view: subd_io::MeshView<'a>,
    uv: Option<&'a RefinedUv>,
) -> Result<subd_io::MeshView<'a>, subd_io::ViewError> {
    match uv {
        Some(uv) => view.with_uv(&uv.values, 2, &uv.indices),
        None => Ok(view),
    }
}

/// A refined face-varying channel: two numbers per value, one value index per face-vertex.
pub(crate) struct RefinedUv {
    pub(crate) values: Vec<f64>,
    pub(crate) indices: Vec<u32>,
}

/// The mesh's texture coordinates at the last level of `refinement` (at their limit with
/// `limit`), interpolated by `mode`; `None` when the mesh has none, or, with a warning, when
/// a split scheme cannot carry their seams.
pub(crate) fn refined_uv(
    refinement: &crate::refined::RefinementWithLimit,
    mesh: &subd_mesh::Mesh,
    mode: FVarLinearInterpolation,
    limit: bool,
    warnings: &mut Vec<String>,
) -> Result<Option<RefinedUv>, String> {
    let Some(channel) = mesh.uv() else {
        return Ok(None);
    };
    let r: &Refinement = refinement;
    let fv = match r.face_varying(channel, mode) {
        Ok(fv) => fv,
        Err(e @ SplitFVarError::Seam { .. }) => {
            warnings.push(format!("texture coordinates left out: {e}"));
            return Ok(None);
        }
        Err(e) => return Err(e.to_string()),
    };
    let level = r.num_levels();
    let values = fv
        .refine_values(channel.values(), 2)
        .pop()
        .expect("level 0 at least");
    let indices = fv.face_values(level);
    if !limit {
        return Ok(Some(RefinedUv { values, indices }));
    }
    if let Some(split) = fv.split() {
        let values = split_values_limit(split, || refinement.last_limit(), values)?;
        return Ok(Some(RefinedUv { values, indices }));
    }
    // The exact limit of the output level's values, as the positions take theirs.
    let topology = r.topology(level);
    let at_level = FVarChannel::new(topology, 2, values, indices).map_err(|e| e.to_string())?;
    // At level 0 too the values take Catmull-Clark's limit, as before the one front door
    // (the two-phase phase-1 rule is left out there: noted on issue 39).
    limit_uv(
        topology,
        &r.scheme().at_level(level.max(1)),
        r.options(),
        &at_level,
        mode,
    )
    .map(Some)
}

/// The limit of the values of `fv`'s output level: the butterflies interpolate, so each
/// value is its own limit; Doo-Sabin's and √3's values (one per vertex; their mesh of values
/// is the geometry) take the positions' limit stencils, from `stencils`.
fn split_values_limit<'a>(
    fv: &SplitFaceVarying,
    stencils: impl FnOnce() -> Result<&'a LimitStencilTable, String>,
    values: Vec<f64>,
) -> Result<Vec<f64>, String> {
    if fv.values_scheme().is_interpolating() {
        return Ok(values);
    }
    let points: Vec<DVec3> = values
        .chunks_exact(2)
        .map(|x| DVec3::new(x[0], x[1], 0.0))
        .collect();
    let limit = stencils()?.position.apply_points(&points);
    Ok(limit.iter().flat_map(|p| [p.x, p.y]).collect())
}

/// The limit of a base mesh's texture coordinates under a split scheme (see
/// [`split_values_limit`]), one value per (vertex, value); the values as given, with a
/// warning, where Doo-Sabin or √3 cannot carry their seams.
pub(crate) fn split_limit_uv(
    topology: &Topology,
    (scheme, stencils): (&Scheme, &LimitStencilTable),
    channel: &FVarChannel,
    mode: FVarLinearInterpolation,
    warnings: &mut Vec<String>,
) -> Result<RefinedUv, String> {
    let r = Refinement::new(topology, scheme.clone(), &Options::default(), 0)
        .map_err(|e| e.to_string())?;
    let fv = match SplitFaceVarying::new(&r, channel, mode) {
        Ok(fv) => fv,
        Err(e @ SplitFVarError::Seam { .. }) => {
            warnings.push(format!("texture coordinates kept as given: {e}"));
            return Ok(RefinedUv {
                values: channel.values().to_vec(),
                indices: channel.indices().to_vec(),
            });
        }
        Err(e) => return Err(e.to_string()),
    };
    // The base mesh of values: one value per wedge, its faces on wedges.
    let values: Vec<f64> = fv
        .wedge_values()
        .iter()
        .flat_map(|&x| channel.value(x as usize).iter().copied())
        .collect();
    Ok(RefinedUv {
        values: split_values_limit(&fv, || Ok(stencils), values)?,
        indices: fv.values_topology(0).all_face_vertices().to_vec(),
    })
}

/// The exact limit of every value of `channel` (two components) on `topology`: one value
/// per (vertex, value) pair, each corner naming its own.
pub(crate) fn limit_uv(
    topology: &Topology,
    scheme: &Scheme,
    options: &Options,
    channel: &FVarChannel,
    mode: FVarLinearInterpolation,
) -> Result<RefinedUv, String> {
    let limit = subd_limit::fvar::base_fvar_limit(topology, scheme, options, channel, mode)
        .map_err(|e| e.to_string())?;
    let mut indices = Vec::with_capacity(topology.num_face_vertices());
    for f in 0..topology.num_faces() {
        for (&v, &x) in topology
            .face_vertices(f)
            .iter()
            .zip(channel.face_values(topology, f))
        {
            // Refined levels give each (vertex, value) pair its own index; at a base level
            // a vertex may name one value twice (OpenSubdiv's A B A B numbering): its first
            // row then stands for both.
            let rows = limit.vertex_rows(v as usize);
            let row = rows
                .clone()
                .find(|&q| limit.value(q) == x)
                .unwrap_or(rows.start);
            indices.push(row as u32);
        }
    }
    Ok(RefinedUv {
        values: limit.apply(channel.values(), 2),
        indices,
    })
}

/// The warning for texture coordinates a PLY output leaves out.
pub(crate) fn ply_seam_warning(output: &std::path::Path) -> String {
    format!(
        "{}: texture coordinates left out: PLY stores one per vertex and these have seams (write .obj or .glb to keep them)",
        output.display()
    )
}

/// Drops `mesh`'s texture coordinates, with a warning, when `output` is a PLY file that
/// cannot hold them.
pub(crate) fn fit_ply(
    mesh: &mut subd_mesh::Mesh,
    output: &std::path::Path,
    warnings: &mut Vec<String>,
) {
    if subd_io::Format::for_output(output) != Some(subd_io::Format::Ply) {
        return;
    }
    if mesh.uv().is_some() && !subd_io::ply::holds_texcoords(&subd_io::MeshView::from_mesh(mesh)) {
        mesh.fvar.clear();
        warnings.push(ply_seam_warning(output));
    }
}
