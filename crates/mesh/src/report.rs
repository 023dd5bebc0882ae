//! [`MeshReport`]: what `subd info` reports of a mesh (and `subd.info` gives Python), in
//! one serializable value: the topology summary, irregular vertices, the rule tags and the
//! face-varying channels with their seams.

use serde::Serialize;

use crate::analysis::{TopologySummary, count_irregular};
use crate::fvar::{FVarLinearInterpolation, FVarSeams};
use crate::{BoundaryInterpolation, Mesh};

/// Vertices whose valence is not the regular one.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct IrregularVertices {
    /// Regular valence 4 (Catmull-Clark, Bilinear).
    pub quad: usize,
    /// Regular valence 6 (Loop).
    pub triangle: usize,
}

/// One face-varying channel: its size and where its values are discontinuous.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChannelReport {
    /// Numbers per value.
    pub components: usize,
    /// Values the channel has.
    pub values: usize,
    /// Distinct values at vertices (a vertex on a seam counts once per side).
    pub vertex_values: usize,
    /// Edges whose faces name different values at one of their ends.
    pub seam_edges: usize,
    /// Vertices with more than one value.
    pub seam_vertices: usize,
}

/// A mesh's topology, tags and face-varying channels, summarised.
///
/// ```
/// use subd_mesh::report::MeshReport;
/// use subd_mesh::{DVec3, Mesh, TopologyBuilder};
///
/// let topology = TopologyBuilder::new(4).build(&[4], &[0, 1, 2, 3]).unwrap();
/// let quad = Mesh::new(topology, vec![DVec3::ZERO; 4]).unwrap();
/// let report = MeshReport::of(&quad, 0);
/// assert_eq!((report.summary.faces, report.summary.boundary_edges), (1, 4));
/// ```
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MeshReport {
    /// Counts, histograms, boundaries, components, genus.
    #[serde(flatten)]
    pub summary: TopologySummary,
    /// Irregular vertices for the quad and the triangle schemes.
    pub irregular_vertices: IrregularVertices,
    /// Edges used in the same direction by two faces (as the reader counted them).
    pub orientation_conflicts: usize,
    /// The mesh's boundary rule tag, if any.
    pub boundary_interpolation: Option<BoundaryInterpolation>,
    /// Face-varying channels (the first is the texture coordinates).
    pub fvar_channels: Vec<ChannelReport>,
    /// The mesh's face-varying interpolation tag, if any.
    pub fvar_interpolation: Option<FVarLinearInterpolation>,
    /// The scheme the file names (USD's `subdivisionScheme`), if any; left out of the JSON
    /// for files that name none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scheme: Option<crate::FileScheme>,
}

impl MeshReport {
    /// The report of `mesh`, whose reader counted `orientation_conflicts`.
    pub fn of(mesh: &Mesh, orientation_conflicts: usize) -> MeshReport {
        let topo = &mesh.topology;
        MeshReport {
            summary: TopologySummary::new(topo),
            irregular_vertices: IrregularVertices {
                quad: count_irregular(topo, 4),
                triangle: count_irregular(topo, 6),
            },
            orientation_conflicts,
            boundary_interpolation: mesh.hints.boundary_interpolation,
            fvar_channels: mesh
                .fvar
                .iter()
                .map(|c| {
                    let seams = FVarSeams::of(topo, c);
                    ChannelReport {
                        components: c.components(),
                        values: c.num_values(),
                        vertex_values: seams.num_vertex_values(),
                        seam_edges: seams.num_seam_edges(),
                        seam_vertices: seams.num_seam_vertices(),
                    }
                })
                .collect(),
            fvar_interpolation: mesh.hints.fvar_interpolation,
            scheme: mesh.hints.scheme,
        }
    }
}
