//! Face-varying data: per-corner values with their own topology, as OpenSubdiv's
//! face-varying channels (UVs with seams).
//!
//! A [`FVarChannel`] holds values of any number of `f64` components and, per face-vertex
//! (face order, then corner order, as [`Topology::all_face_vertices`]), the index of that
//! corner's value. Corners of different faces at one vertex that name different values make
//! a seam there; which vertices and edges are seams follows from the indices alone, never
//! from the values ([`FVarSeams`]). How linear a refined channel is kept along seams and
//! boundaries is OpenSubdiv's [`FVarLinearInterpolation`].

use thiserror::Error;

use crate::Topology;
use crate::choice::Choice;

/// How face-varying values are interpolated along their seams and boundaries: OpenSubdiv's
/// `Sdc::Options::FVarLinearInterpolation`, in its order (which is also the value of the
/// OpenSubdiv shape tag `facevaryinginterpolateboundary`).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum FVarLinearInterpolation {
    /// Smooth along seams and boundaries too; only values the geometry makes sharp
    /// (infinitely sharp or non-manifold vertices, disjoint regions) are pinned.
    None,
    /// As `None`, plus every value that has a single face at its vertex (a corner of the
    /// UV layout) is pinned.
    CornersOnly,
    /// As `CornersOnly`, plus every value where three or more UV regions meet, and both
    /// values of a two-region vertex beside an infinitely sharp or disjoint edge: USD's
    /// and Blender's default.
    CornersPlus1,
    /// As `CornersPlus1`, plus both values of a two-region vertex where one region has a
    /// single face (a concave corner), and interior seam ends (darts).
    CornersPlus2,
    /// Every value on a seam or the mesh boundary is pinned and their edges split at the
    /// midpoint: seams and boundaries stay piecewise linear, interiors are smooth.
    Boundaries,
    /// Linear everywhere: the channel is refined bilinearly (`Sdc::Options()`'s default).
    #[default]
    All,
}

impl FVarLinearInterpolation {
    /// Every mode, in OpenSubdiv's order.
    pub const ALL_MODES: [FVarLinearInterpolation; 6] = {
        // Read off the one table of names (kept in OpenSubdiv's order, which the shape tag's
        // value is the position in).
        let values = <FVarLinearInterpolation as Choice>::VALUES;
        assert!(values.len() == 6);
        let mut all = [FVarLinearInterpolation::All; 6];
        let mut i = 0;
        while i < all.len() {
            all[i] = values[i].0;
            i += 1;
        }
        all
    };

    /// The mode of OpenSubdiv's shape tag value (`t facevaryinginterpolateboundary 1/0/0 N`),
    /// which is its position in `Sdc::Options::FVarLinearInterpolation`.
    pub fn from_shape_tag(value: i64) -> Option<FVarLinearInterpolation> {
        usize::try_from(value)
            .ok()
            .and_then(|i| Self::ALL_MODES.get(i).copied())
    }

    /// The shape tag value of the mode ([`Self::from_shape_tag`]'s inverse).
    pub fn to_shape_tag(self) -> i64 {
        Self::ALL_MODES
            .iter()
            .position(|&m| m == self)
            .expect("every mode is listed") as i64
    }

    /// The name the command line uses (`corners-plus1`, ...).
    pub fn name(self) -> &'static str {
        <Self as Choice>::name(self)
    }
}

// In OpenSubdiv's order: `ALL_MODES` and the shape tag's value follow it.
impl Choice for FVarLinearInterpolation {
    const OPTION: &'static str = "face-varying interpolation";
    const VALUES: &'static [(Self, &'static str, &'static str)] = &[
        (
            FVarLinearInterpolation::None,
            "none",
            "Smooth everywhere; only what the geometry makes sharp is pinned",
        ),
        (
            FVarLinearInterpolation::CornersOnly,
            "corners-only",
            "Smooth, with UV corners (a value used by one face at its vertex) pinned",
        ),
        (
            FVarLinearInterpolation::CornersPlus1,
            "corners-plus1",
            "As corners-only, plus junctions of three or more UV regions (USD's, Blender's default)",
        ),
        (
            FVarLinearInterpolation::CornersPlus2,
            "corners-plus2",
            "As corners-plus1, plus concave corners and seam ends inside the mesh",
        ),
        (
            FVarLinearInterpolation::Boundaries,
            "boundaries",
            "Seams and the mesh boundary kept piecewise linear, interiors smooth",
        ),
        (
            FVarLinearInterpolation::All,
            "all",
            "Linear everywhere (bilinear UVs)",
        ),
    ];
}

crate::choice_by_name!(FVarLinearInterpolation);

/// Why a face-varying channel was rejected; each variant names the element.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum FVarError {
    /// A scheme that refines face-varying data as a mesh of values, not in OpenSubdiv's
    /// interpolation modes.
    #[error(
        "the {scheme} scheme refines face-varying data as a mesh of values (SplitFaceVarying), not in OpenSubdiv's modes"
    )]
    Scheme {
        /// The scheme's name.
        scheme: String,
    },
    /// A channel needs at least one component per value.
    #[error("a face-varying channel needs at least one component per value")]
    NoComponents,
    /// A channel without values (OpenSubdiv refuses it: "face-varying channel has no
    /// values").
    #[error("a face-varying channel has no values")]
    NoValues,
    /// The value array is not a whole number of values.
    #[error("{len} face-varying numbers are not a whole number of {components}-component values")]
    ValueLength {
        /// Numbers given.
        len: usize,
        /// Components per value.
        components: usize,
    },
    /// There must be one index per face-vertex of the topology.
    #[error("{given} face-varying indices for {expected} face-vertices")]
    IndexCount {
        /// Indices given.
        given: usize,
        /// Face-vertices of the topology.
        expected: usize,
    },
    /// A corner names a value that does not exist.
    #[error(
        "face {face} corner {corner} uses face-varying value {index}, but there are only {values}"
    )]
    IndexOutOfRange {
        /// Face.
        face: usize,
        /// Corner within the face.
        corner: usize,
        /// The index.
        index: u32,
        /// Number of values.
        values: usize,
    },
    /// A value with a NaN or infinite component.
    #[error("face-varying value {value} has a non-finite component")]
    NonFinite {
        /// The value.
        value: usize,
    },
}

/// One face-varying channel of a topology (see the [module docs](self)).
#[derive(Debug, Clone, PartialEq)]
pub struct FVarChannel {
    components: usize,
    values: Vec<f64>,
    indices: Vec<u32>,
}

impl FVarChannel {
    /// A channel of `values` (`components` numbers each) with one value index per
    /// face-vertex of `topology`.
    ///
    /// ```
    /// use subd_mesh::TopologyBuilder;
    /// use subd_mesh::fvar::{FVarChannel, FVarError};
    ///
    /// let quad = TopologyBuilder::new(4).build(&[4], &[0, 1, 2, 3]).unwrap();
    /// let uv = vec![0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0];
    /// let channel = FVarChannel::new(&quad, 2, uv.clone(), vec![0, 1, 2, 3]).unwrap();
    /// assert_eq!(channel.value(2), &[1.0, 1.0]);
    /// assert_eq!(
    ///     FVarChannel::new(&quad, 2, uv, vec![0, 1, 2, 4]),
    ///     Err(FVarError::IndexOutOfRange { face: 0, corner: 3, index: 4, values: 4 })
    /// );
    /// ```
    ///
    /// # Errors
    /// An [`FVarError`] naming the element: no components, a value array that is not a
    /// whole number of values, an index count that is not the topology's face-vertex count,
    /// an index without a value, a non-finite value.
    pub fn new(
        topology: &Topology,
        components: usize,
        values: Vec<f64>,
        indices: Vec<u32>,
    ) -> Result<FVarChannel, FVarError> {
        if components == 0 {
            return Err(FVarError::NoComponents);
        }
        if values.len() % components != 0 {
            return Err(FVarError::ValueLength {
                len: values.len(),
                components,
            });
        }
        if indices.len() != topology.num_face_vertices() {
            return Err(FVarError::IndexCount {
                given: indices.len(),
                expected: topology.num_face_vertices(),
            });
        }
        let num_values = values.len() / components;
        if let Some(k) = indices.iter().position(|&i| i as usize >= num_values) {
            let offsets = topology.face_offsets();
            let face = offsets.partition_point(|&o| o as usize <= k) - 1;
            return Err(FVarError::IndexOutOfRange {
                face,
                corner: k - offsets[face] as usize,
                index: indices[k],
                values: num_values,
            });
        }
        if let Some(i) = values.iter().position(|x| !x.is_finite()) {
            return Err(FVarError::NonFinite {
                value: i / components,
            });
        }
        Ok(FVarChannel {
            components,
            values,
            indices,
        })
    }

    /// Numbers per value.
    pub fn components(&self) -> usize {
        self.components
    }

    /// Number of values.
    pub fn num_values(&self) -> usize {
        self.values.len() / self.components
    }

    /// Value `i`'s components.
    pub fn value(&self, i: usize) -> &[f64] {
        &self.values[i * self.components..(i + 1) * self.components]
    }

    /// Every value's components, value after value.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The value index of every face-vertex, face after face.
    pub fn indices(&self) -> &[u32] {
        &self.indices
    }

    /// The value indices of the corners of face `f` of `topology` (the topology the
    /// channel was made for).
    pub fn face_values<'a>(&'a self, topology: &Topology, f: usize) -> &'a [u32] {
        let o = topology.face_offsets();
        &self.indices[o[f] as usize..o[f + 1] as usize]
    }
}

/// Where a channel is discontinuous, from its indices alone, as OpenSubdiv's
/// `Vtr::FVarLevel` derives it before any interpolation mode applies.
///
/// An edge is discontinuous when its faces name different values at either end. The values
/// at a vertex are its *siblings*, numbered in the order the vertex's ordered faces
/// ([`Topology::vertex_faces`]) first meet them: a value that comes back after another
/// keeps its first number, so values A B A B around a vertex are siblings 0 1 0 1. (This is
/// the layout's own seam structure. OpenSubdiv's refinement numbers such a vertex 0 1 0 2,
/// a shortcut in `FVarLevel::completeTopologyFromFaceValues` that
/// `subd_schemes::FaceVaryingRefinement` reproduces.)
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FVarSeams {
    discontinuous_edges: Vec<bool>,
    /// Per vertex, where its siblings start in a per-vertex numbering of all values.
    sibling_offsets: Vec<u32>,
    /// Per vertex-face (vertex after vertex, in each vertex's face order), the sibling its
    /// corner names.
    vertex_face_siblings: Vec<u16>,
    /// Where each vertex's faces start in `vertex_face_siblings`.
    vertex_face_offsets: Vec<u32>,
}

impl FVarSeams {
    /// The seams of `channel` on `topology` (the topology the channel was made for).
    ///
    /// ```
    /// use subd_mesh::TopologyBuilder;
    /// use subd_mesh::fvar::{FVarChannel, FVarSeams};
    ///
    /// // Two quads side by side whose UVs are cut apart along the shared edge 1-4.
    /// let t = TopologyBuilder::new(6).build(&[4, 4], &[0, 1, 4, 3, 1, 2, 5, 4]).unwrap();
    /// let uv = vec![0.0; 2 * 8];
    /// let c = FVarChannel::new(&t, 2, uv, vec![0, 1, 2, 3, 4, 5, 6, 7]).unwrap();
    /// let seams = FVarSeams::of(&t, &c);
    /// assert_eq!(seams.num_seam_edges(), 1);
    /// assert_eq!((seams.siblings(1), seams.siblings(4), seams.siblings(0)), (2, 2, 1));
    /// ```
    pub fn of(topology: &Topology, channel: &FVarChannel) -> FVarSeams {
        let value_in = |f: usize, corner: usize| channel.face_values(topology, f)[corner];
        let edge_end_values = |e: usize, i: usize| {
            let f = topology.edge_faces(e)[i] as usize;
            let l = topology.edge_face_local_indices(e)[i] as usize;
            let fv = topology.face_vertices(f);
            let next = (l + 1) % fv.len();
            // Oriented by the edge's own end points, whichever way the face runs.
            if fv[l] == topology.edge_vertices(e)[0] {
                (value_in(f, l), value_in(f, next))
            } else {
                (value_in(f, next), value_in(f, l))
            }
        };
        let discontinuous_edges = (0..topology.num_edges())
            .map(|e| {
                let n = topology.edge_faces(e).len();
                (1..n).any(|i| edge_end_values(e, i) != edge_end_values(e, 0))
            })
            .collect();
        let nv = topology.num_vertices();
        let mut sibling_offsets = Vec::with_capacity(nv + 1);
        let mut vertex_face_offsets = Vec::with_capacity(nv + 1);
        let mut vertex_face_siblings = Vec::new();
        let mut distinct: Vec<u32> = Vec::new();
        let mut total = 0u32;
        for v in 0..nv {
            sibling_offsets.push(total);
            vertex_face_offsets.push(vertex_face_siblings.len() as u32);
            let faces = topology.vertex_faces(v);
            let corners = topology.vertex_face_local_indices(v);
            distinct.clear();
            for (&f, &c) in faces.iter().zip(corners) {
                let value = value_in(f as usize, c as usize);
                let sibling = match distinct.iter().position(|&d| d == value) {
                    Some(k) => k,
                    None => {
                        distinct.push(value);
                        distinct.len() - 1
                    }
                };
                vertex_face_siblings.push(sibling as u16);
            }
            // A vertex without faces still has one value (OpenSubdiv gives it value 0).
            total += distinct.len().max(1) as u32;
        }
        sibling_offsets.push(total);
        vertex_face_offsets.push(vertex_face_siblings.len() as u32);
        FVarSeams {
            discontinuous_edges,
            sibling_offsets,
            vertex_face_siblings,
            vertex_face_offsets,
        }
    }

    /// Whether edge `e`'s faces name different values at one of its ends.
    pub fn is_discontinuous(&self, e: usize) -> bool {
        self.discontinuous_edges[e]
    }

    /// Number of distinct values at vertex `v` (1 away from seams).
    pub fn siblings(&self, v: usize) -> usize {
        (self.sibling_offsets[v + 1] - self.sibling_offsets[v]) as usize
    }

    /// The sibling each of vertex `v`'s faces names there, in its face order.
    pub fn face_siblings(&self, v: usize) -> &[u16] {
        let o = &self.vertex_face_offsets;
        &self.vertex_face_siblings[o[v] as usize..o[v + 1] as usize]
    }

    /// Total number of distinct values at vertices, every vertex's siblings counted.
    /// (`subd_schemes::FaceVaryingRefinement` numbers one more at a vertex whose values
    /// come back A B A B, as OpenSubdiv does: see there.)
    pub fn num_vertex_values(&self) -> usize {
        *self.sibling_offsets.last().unwrap_or(&0) as usize
    }

    /// Number of discontinuous edges.
    pub fn num_seam_edges(&self) -> usize {
        self.discontinuous_edges.iter().filter(|&&d| d).count()
    }

    /// Number of vertices with more than one value.
    pub fn num_seam_vertices(&self) -> usize {
        (0..self.sibling_offsets.len() - 1)
            .filter(|&v| self.siblings(v) > 1)
            .count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::TopologyBuilder;

    /// Four quads around vertex 4 of a 3 × 3 grid of vertices.
    fn grid() -> Topology {
        TopologyBuilder::new(9)
            .build(&[4; 4], &[0, 1, 4, 3, 1, 2, 5, 4, 3, 4, 7, 6, 4, 5, 8, 7])
            .unwrap()
    }

    #[test]
    fn bad_channels_name_the_element() {
        let t = grid();
        let idx = |v: u32| vec![v; 16];
        assert_eq!(
            FVarChannel::new(&t, 0, vec![], idx(0)),
            Err(FVarError::NoComponents)
        );
        assert_eq!(
            FVarChannel::new(&t, 2, vec![0.0; 3], idx(0)),
            Err(FVarError::ValueLength {
                len: 3,
                components: 2
            })
        );
        assert_eq!(
            FVarChannel::new(&t, 2, vec![0.0; 2], vec![0; 15]),
            Err(FVarError::IndexCount {
                given: 15,
                expected: 16
            })
        );
        let mut bad = idx(0);
        bad[9] = 1;
        assert_eq!(
            FVarChannel::new(&t, 2, vec![0.0; 2], bad),
            Err(FVarError::IndexOutOfRange {
                face: 2,
                corner: 1,
                index: 1,
                values: 1
            })
        );
        assert_eq!(
            FVarChannel::new(&t, 1, vec![0.0, f64::NAN], idx(0)),
            Err(FVarError::NonFinite { value: 1 })
        );
    }

    #[test]
    fn siblings_are_numbered_by_first_appearance_around_the_vertex() {
        let t = grid();
        // Every face its own UV island: vertex 4 has four values, edges to it are seams.
        let islands: Vec<u32> = (0..16).collect();
        let c = FVarChannel::new(&t, 1, (0..16).map(f64::from).collect(), islands).unwrap();
        let s = FVarSeams::of(&t, &c);
        assert_eq!(s.siblings(4), 4);
        assert_eq!(s.face_siblings(4), &[0, 1, 2, 3]);
        assert_eq!(s.num_seam_edges(), 4);
        assert_eq!(s.num_vertex_values(), 16);
        // Values A B A B around vertex 4 (diagonal faces share one): two siblings, 0 1 0 1
        // in the vertex's face order, and every edge at it a seam.
        let faces = t.vertex_faces(4).to_vec();
        let mut abab: Vec<u32> = (0..16).collect();
        for (i, &f) in faces.iter().enumerate() {
            let corner = t
                .face_vertices(f as usize)
                .iter()
                .position(|&v| v == 4)
                .unwrap();
            abab[4 * f as usize + corner] = 16 + (i % 2) as u32;
        }
        let c = FVarChannel::new(&t, 1, vec![0.0; 18], abab).unwrap();
        let s = FVarSeams::of(&t, &c);
        assert_eq!(s.siblings(4), 2);
        assert_eq!(s.face_siblings(4), &[0, 1, 0, 1]);
        // One shared value per vertex: no seams at all.
        let c = FVarChannel::new(&t, 1, vec![0.0; 9], t.all_face_vertices().to_vec()).unwrap();
        let s = FVarSeams::of(&t, &c);
        assert_eq!((s.num_seam_edges(), s.num_seam_vertices()), (0, 0));
        assert_eq!(s.num_vertex_values(), 9);
    }

    #[test]
    fn modes_follow_the_shape_tag_order() {
        for (i, m) in FVarLinearInterpolation::ALL_MODES.iter().enumerate() {
            assert_eq!(FVarLinearInterpolation::from_shape_tag(i as i64), Some(*m));
            assert_eq!(m.to_shape_tag(), i as i64);
        }
        assert_eq!(FVarLinearInterpolation::from_shape_tag(6), None);
        assert_eq!(FVarLinearInterpolation::from_shape_tag(-1), None);
        assert_eq!(
            FVarLinearInterpolation::default(),
            FVarLinearInterpolation::All
        );
        assert_eq!(
            FVarLinearInterpolation::CornersPlus1.name(),
            "corners-plus1"
        );
    }
}
