//! A whole mesh refined in one call: [`refine_mesh`] takes a [`Mesh`] (topology, tags,
//! positions, texture coordinates) through any [`Scheme`], optionally to the exact limit,
//! and gives the refined [`Mesh`] with its texture coordinates and limit normals. The
//! Python package calls it; the CLI, which streams deep levels to its writers, shares its
//! parts ([`LimitedRefinement`], [`output_limit`], [`refined_uv`]).
//!
//! ```
//! use subd_limit::refined_mesh::{refine_mesh, MeshRefinement};
//! use subd_mesh::{DVec3, Mesh, TopologyBuilder};
//! use subd_schemes::Scheme;
//!
//! let topology = TopologyBuilder::new(4).build(&[3, 3], &[0, 1, 2, 0, 2, 3]).unwrap();
//! let positions = vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
//! let square = Mesh::new(topology, positions).unwrap();
//! let request = MeshRefinement::new(Scheme::Loop, &square, 2);
//! let refined = refine_mesh(&square, &request).unwrap();
//! assert_eq!(refined.faces().1.len(), 3 * 2 * 16);
//! let (mesh, _normals) = refined.into_mesh().unwrap();
//! assert_eq!(mesh.topology.num_edges(), 56);
//! ```

use std::sync::OnceLock;

use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};
use subd_mesh::{DVec3, Mesh, SchemeHints, Topology};
use subd_schemes::split_schemes::{SplitFVarError, SplitFaceVarying};
use subd_schemes::{Options, Refinement, Scheme};

use crate::{LimitError, LimitPoints, LimitStencilTable, Tangents};

/// A refinement, and the limit stencils of a split scheme's last level once asked for: the
/// positions and the texture coordinates take their limits through the same ones.
pub struct LimitedRefinement {
    refinement: Refinement,
    last_limit: OnceLock<Result<LimitStencilTable, LimitError>>,
}

impl std::ops::Deref for LimitedRefinement {
    type Target = Refinement;
    fn deref(&self) -> &Refinement {
        &self.refinement
    }
}

impl LimitedRefinement {
    /// Refines `base` `levels` times with `scheme`; the error names the element.
    pub fn new(
        base: &Topology,
        scheme: Scheme,
        options: &Options,
        levels: usize,
    ) -> Result<LimitedRefinement, LimitError> {
        Ok(LimitedRefinement {
            refinement: Refinement::new(base, scheme, options, levels)?,
            last_limit: OnceLock::new(),
        })
    }

    /// The limit stencils of a split scheme's last level, built on first request.
    pub fn last_limit(&self) -> Result<&LimitStencilTable, LimitError> {
        self.last_limit
            .get_or_init(|| {
                let last = self.topology(self.num_levels());
                crate::split_limits::split_limit::split_limit_table(last, self.scheme())
            })
            .as_ref()
            .map_err(Clone::clone)
    }

    /// Edges of `level`; `None` for a split scheme's last level, whose edges are never
    /// built.
    pub fn edges(&self, level: usize) -> Option<usize> {
        if self.scheme().is_opensubdiv() {
            self.num_edges(level)
        } else {
            None
        }
    }

    /// The positions of the last level (each level dropped once the next is computed).
    pub fn last_positions(&self, base: &[DVec3]) -> Vec<DVec3> {
        self.points_at(base, self.num_levels())
    }

    /// The refinement itself.
    pub fn into_refinement(self) -> Refinement {
        self.refinement
    }
}

/// The exact limit (positions and unit normals; no tangents) of the vertices of
/// `refinement`'s last level, from `base`, the base mesh's points: the same surface as
/// [`output_limit`] of the last level's points. On Catmull-Clark, a child of a regular quad
/// of the level above is read off that quad's B-spline patch from the level above's points,
/// so where every quad is regular the last level's own points are never made (what
/// `subd refine --limit` and `subd.refine(limit=True)` take).
pub fn last_level_limit(
    refinement: &LimitedRefinement,
    options: &Options,
    base: &[DVec3],
) -> Result<LimitPoints, LimitError> {
    let levels = refinement.num_levels();
    if crate::limit_masks::regular_patches::applies(refinement) {
        let above = refinement.points_at(base, levels - 1);
        return crate::limit_masks::regular_patches::last_level_limit(refinement, &above);
    }
    let positions = refinement.last_positions(base);
    output_limit(refinement, levels, options, &positions)
}

/// The exact limit (positions and normals) of the vertices of `level`, from the limit
/// masks of that level's own topology: what Blender calls "use limit surface".
pub fn output_limit(
    refinement: &LimitedRefinement,
    level: usize,
    options: &Options,
    positions: &[DVec3],
) -> Result<LimitPoints, LimitError> {
    let scheme = &refinement.scheme().at_level(level);
    if scheme.is_opensubdiv() || level < refinement.num_levels() {
        return crate::level_limit_points(refinement, level, options, positions, Tangents::Dropped);
    }
    // A split scheme's last level: the stencils where texture coordinates built them
    // already (both callers carry those first), so the masks are found once; otherwise
    // the masks applied to the points as they are found, without stencils.
    if let Some(Ok(table)) = refinement.last_limit.get() {
        return Ok(table.apply(positions));
    }
    let last = refinement.topology(level);
    crate::split_limits::split_limit::split_limit_points(last, refinement.scheme(), positions)
}

/// Refined texture coordinates: `components` numbers per value, one value index per
/// face-vertex.
#[derive(Debug, Clone, PartialEq)]
pub struct RefinedUv {
    /// The values, `components` numbers each.
    pub values: Vec<f64>,
    /// One value index per face-vertex of the refined mesh.
    pub indices: Vec<u32>,
}

/// The mesh's texture coordinates (its first face-varying channel, two components) at the
/// last level of `refinement` (at their limit with `limit`), interpolated by `mode`; `None`
/// when the mesh has none, or, with a warning pushed, when a split scheme cannot carry
/// their seams.
pub fn refined_uv(
    refinement: &LimitedRefinement,
    mesh: &Mesh,
    mode: FVarLinearInterpolation,
    limit: bool,
    warnings: &mut Vec<String>,
) -> Result<Option<RefinedUv>, LimitError> {
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
        Err(e) => return Err(e.into()),
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
    let at_level = FVarChannel::new(topology, 2, values, indices)?;
    // At level 0 too the values take Catmull-Clark's limit, as before the one front door
    // (the two-phase phase-1 rule is left out there: noted on issue 39).
    match limit_uv(
        topology,
        &r.scheme().at_level(level.max(1)),
        r.options(),
        &at_level,
        mode,
    ) {
        Ok(uv) => Ok(Some(uv)),
        // Deep semi-sharp creases: the positions take their limit locally, the texture
        // coordinates keep their values of the output level.
        Err(e @ LimitError::TooDeep { .. }) => {
            warnings.push(format!(
                "texture coordinates left at level {level}, not moved to their limit: {e}"
            ));
            Ok(Some(RefinedUv {
                values: at_level.values().to_vec(),
                indices: at_level.indices().to_vec(),
            }))
        }
        Err(e) => Err(e),
    }
}

/// The limit of the values of `fv`'s output level: the butterflies interpolate, so each
/// value is its own limit; Doo-Sabin's and √3's values (one per vertex; their mesh of values
/// is the geometry) take the positions' limit stencils, from `stencils`.
fn split_values_limit<'a>(
    fv: &SplitFaceVarying,
    stencils: impl FnOnce() -> Result<&'a LimitStencilTable, LimitError>,
    values: Vec<f64>,
) -> Result<Vec<f64>, LimitError> {
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

/// The limit of a base mesh's texture coordinates under a split scheme, one value per
/// (vertex, value); the values as given, with a warning pushed, where Doo-Sabin or √3
/// cannot carry their seams.
pub fn split_limit_uv(
    topology: &Topology,
    (scheme, stencils): (&Scheme, &LimitStencilTable),
    channel: &FVarChannel,
    mode: FVarLinearInterpolation,
    warnings: &mut Vec<String>,
) -> Result<RefinedUv, LimitError> {
    let r = Refinement::new(topology, scheme.clone(), &Options::default(), 0)?;
    let fv = match SplitFaceVarying::new(&r, channel, mode) {
        Ok(fv) => fv,
        Err(e @ SplitFVarError::Seam { .. }) => {
            warnings.push(format!("texture coordinates kept as given: {e}"));
            return Ok(RefinedUv {
                values: channel.values().to_vec(),
                indices: channel.indices().to_vec(),
            });
        }
        Err(e) => return Err(e.into()),
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
pub fn limit_uv(
    topology: &Topology,
    scheme: &Scheme,
    options: &Options,
    channel: &FVarChannel,
    mode: FVarLinearInterpolation,
) -> Result<RefinedUv, LimitError> {
    let limit =
        crate::limit_masks::fvar::base_fvar_limit(topology, scheme, options, channel, mode)?;
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

/// What [`refine_mesh`] is asked: the scheme, its rule options, the level, whether to go
/// to the limit, and how the texture coordinates interpolate.
#[derive(Debug, Clone)]
pub struct MeshRefinement {
    /// The scheme.
    pub scheme: Scheme,
    /// Boundary, crease and triangle rules.
    pub options: Options,
    /// Levels of refinement.
    pub levels: usize,
    /// Move every vertex (and texture coordinate) to its exact limit; give limit normals.
    pub limit: bool,
    /// How the texture coordinates interpolate.
    pub fvar_interpolation: FVarLinearInterpolation,
}

impl MeshRefinement {
    /// `levels` of `scheme` with `mesh`'s own rules (its file's tags, else OpenSubdiv's
    /// defaults, and `corners-plus1` for the texture coordinates), not to the limit.
    pub fn new(scheme: Scheme, mesh: &Mesh, levels: usize) -> MeshRefinement {
        MeshRefinement {
            scheme,
            options: Options::from_hints(&mesh.hints),
            levels,
            limit: false,
            // The file's mode, else USD's and Blender's default (the CLI's too).
            fvar_interpolation: mesh
                .hints
                .fvar_interpolation
                .unwrap_or(FVarLinearInterpolation::CornersPlus1),
        }
    }
}

/// A refined mesh: the last level's faces, positions and texture coordinates, the unit
/// limit normals when it was taken to the limit, and what was left out (warnings).
///
/// The last level's full topology (edges, rings, tags) costs more than the refinement
/// itself and is built only by [`Self::into_mesh`]: the faces and positions are read
/// without it. Its hints are [`refined_hints`]'s, with the texture coordinates'
/// interpolation when they were carried.
#[derive(Debug)]
pub struct RefinedMesh {
    refinement: Refinement,
    level: usize,
    positions: Vec<DVec3>,
    uv: Option<RefinedUv>,
    hints: SchemeHints,
    /// The limit normal of every vertex (with `limit`); not unit where the limit defines no
    /// tangent plane (a split scheme's crease or corner).
    pub normals: Option<Vec<DVec3>>,
    /// What was left out, e.g. texture coordinates a split scheme cannot carry.
    pub warnings: Vec<String>,
}

impl RefinedMesh {
    /// The positions of the last level.
    pub fn positions(&self) -> &[DVec3] {
        &self.positions
    }

    /// Face offsets and face-vertex indices of the last level (no topology built).
    pub fn faces(&self) -> (&[u32], &[u32]) {
        self.refinement.faces(self.level)
    }

    /// The faces of the last level a range at a time (or written whole into a buffer of
    /// another index type), from the level above without holding the level's face lists;
    /// `None` where the scheme does not stream them (the split schemes) or nothing was
    /// refined.
    pub fn face_stream(&self) -> Option<subd_schemes::FaceStream<'_>> {
        (self.level > 0)
            .then(|| self.refinement.face_stream())
            .flatten()
    }

    /// The texture coordinates of the last level, if carried.
    pub fn uv(&self) -> Option<&RefinedUv> {
        self.uv.as_ref()
    }

    /// The scheme hints the refined mesh records.
    pub fn hints(&self) -> &SchemeHints {
        &self.hints
    }

    /// The refined mesh with its full topology (built now if it is not yet) and its limit
    /// normals. The positions are moved, not copied: the mesh's positions are the buffer
    /// [`Self::positions`] pointed at (what lets a binding hand out a view of them before
    /// the topology is built).
    pub fn into_mesh(self) -> Result<(Mesh, Option<Vec<DVec3>>), LimitError> {
        let topology = self.refinement.into_topology(self.level);
        let mut out = Mesh::new(topology, self.positions)?;
        out.hints = self.hints;
        if let Some(uv) = self.uv {
            out.fvar
                .push(FVarChannel::new(&out.topology, 2, uv.values, uv.indices)?);
        }
        Ok((out, self.normals))
    }
}

/// The scheme hints a refined mesh records: OpenSubdiv's rule options, for its schemes
/// only (the others' options mean nothing to OpenSubdiv); the triangle rule where the input
/// named one or `triangles_asked`.
pub fn refined_hints(
    scheme: &Scheme,
    options: &Options,
    read: &SchemeHints,
    triangles_asked: bool,
) -> SchemeHints {
    if !scheme.is_opensubdiv() {
        return SchemeHints::default();
    }
    SchemeHints {
        boundary_interpolation: Some(options.boundary_interpolation),
        crease_method: Some(options.crease_method),
        triangle_subdivision: read
            .triangle_subdivision
            .or(triangles_asked.then_some(options.triangle_subdivision)),
        fvar_interpolation: read.fvar_interpolation,
        // A refined mesh: polygons, not a cage to subdivide.
        scheme: None,
    }
}

/// `mesh` refined as `request` says: the one library call behind `subd.refine`, equal to
/// what `subd refine` writes.
pub fn refine_mesh(mesh: &Mesh, request: &MeshRefinement) -> Result<RefinedMesh, LimitError> {
    let levels = request.levels;
    let refinement = LimitedRefinement::new(
        &mesh.topology,
        request.scheme.clone(),
        &request.options,
        levels,
    )?;
    let mut warnings = Vec::new();
    let uv = refined_uv(
        &refinement,
        mesh,
        request.fvar_interpolation,
        request.limit,
        &mut warnings,
    )?;
    let (positions, normals) = if request.limit {
        let limit = last_level_limit(&refinement, &request.options, &mesh.positions)?;
        (limit.positions, Some(limit.normals))
    } else {
        (refinement.last_positions(&mesh.positions), None)
    };
    let asked = request.options.triangle_subdivision;
    let triangles_asked = asked != Options::from_hints(&mesh.hints).triangle_subdivision;
    let mut hints = refined_hints(
        &request.scheme,
        &request.options,
        &mesh.hints,
        triangles_asked,
    );
    hints.fvar_interpolation = uv.as_ref().map(|_| request.fvar_interpolation);
    Ok(RefinedMesh {
        refinement: refinement.into_refinement(),
        level: levels,
        positions,
        uv,
        hints,
        normals,
        warnings,
    })
}

/// Levels by which a control cage is refined when its scheme has no name in the output
/// format (USD names Catmull-Clark, Loop and Bilinear only): two levels give each face 16
/// (9 for √3), close enough to the limit surface for a viewer, which shows a `none` mesh
/// as it is.
pub const UNNAMED_CAGE_LEVELS: usize = 2;

/// What a writer says when it holds a cage of `scheme` refined because the file cannot
/// name the scheme (the caller puts the file's name in front).
pub fn unnamed_cage_warning(scheme: &Scheme) -> String {
    format!(
        "USD has no name for the {scheme} scheme: the cage is written refined {UNNAMED_CAGE_LEVELS} levels, as plain polygons (subdivisionScheme none)"
    )
}

/// A control cage as a file that cannot name its scheme must hold it: the cage
/// refined [`UNNAMED_CAGE_LEVELS`] levels of `scheme` with its own rules, texture
/// coordinates carried where the scheme carries them, as plain polygons. The warnings say
/// what was left out.
pub fn refined_unnamed_cage(
    cage: &Mesh,
    scheme: &Scheme,
) -> Result<(Mesh, Vec<String>), LimitError> {
    let request = MeshRefinement::new(scheme.clone(), cage, UNNAMED_CAGE_LEVELS);
    let refined = refine_mesh(cage, &request)?;
    let warnings = refined.warnings.clone();
    let (mut mesh, _) = refined.into_mesh()?;
    mesh.hints.scheme = Some(subd_mesh::FileScheme::Polygons);
    Ok((mesh, warnings))
}
