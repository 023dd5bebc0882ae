//! Face-varying data (UVs) through the split schemes.
//!
//! A channel is refined as a **mesh of values**: one vertex per wedge of a vertex (the faces
//! around it joined across edges whose two sides carry the same values), the
//! geometry's faces in the same order with wedges for corners, the geometry's creases and
//! corners, and every seam a boundary. The scheme refines that mesh, and because its faces
//! are the geometry's faces, the child faces of the two refinements correspond one to one:
//! the level-`L` faces of the mesh of values are the per-face-vertex value indices of the
//! level-`L` geometry.
//!
//! * **Butterfly and modified butterfly** split every triangle into four whatever the
//!   boundaries, so any channel is carried. A seam is a boundary of each of its islands,
//!   refined with the scheme's 4-point boundary rule on each side. The mode pins the values
//!   OpenSubdiv would pin (its classification with the `edge-only` boundary rule, the
//!   butterflies' own): those become corners, where the 4-point rule reflects its missing
//!   neighbour. In `boundaries` every seam value is pinned, so seam edges get their midpoints;
//!   `all` uses the butterfly with tension 0, linear interpolation on every triangle. Every
//!   value stays where it is (the schemes interpolate), so a value's limit is itself.
//! * **Doo-Sabin and √3** cut across every edge of the level above (Doo-Sabin's edge faces
//!   straddle it, √3 flips it), so a seam cannot stay an edge of the refined mesh and no
//!   per-corner values keep its two islands apart. They carry seamless channels only (one
//!   value per vertex), refined with the positions' own rules whatever the mode; a seam is a
//!   [`SplitFVarError::Seam`] naming a vertex on it.
//!
//! ```
//! use subd_mesh::TopologyBuilder;
//! use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};
//! use subd_schemes::split_schemes::SplitFaceVarying;
//! use subd_schemes::{Options, Refinement, Scheme};
//!
//! // Two triangles whose UVs are cut apart along their shared edge 1-2.
//! let t = TopologyBuilder::new(4).build(&[3, 3], &[0, 1, 2, 2, 1, 3]).unwrap();
//! let uv = vec![0., 0., 1., 0., 0., 1., 3., 1., 3., 0., 4., 0.];
//! let channel = FVarChannel::new(&t, 2, uv, (0..6).collect()).unwrap();
//! let r = Refinement::new(&t, Scheme::BUTTERFLY, &Options::default(), 1).unwrap();
//! let fv = SplitFaceVarying::new(&r, &channel, FVarLinearInterpolation::All).unwrap();
//! let level1 = fv.refine_values(channel.values(), 2).pop().unwrap();
//! // Six corner values, and the midpoints of 3 + 3 edges (the seam's once per side).
//! assert_eq!(fv.num_values(1), 12);
//! let at = |i: u32| [level1[2 * i as usize], level1[2 * i as usize + 1]];
//! // Corner 1 of the first child face is the midpoint of edge 0-1 in the first island.
//! assert_eq!(at(fv.face_values(1)[1]), [0.5, 0.0]);
//! ```

use subd_mesh::fvar::{FVarChannel, FVarError, FVarLinearInterpolation};
use subd_mesh::{BoundaryInterpolation, Topology, TopologyBuilder, TopologyError, tags};
use thiserror::Error;

use super::SplitRefinement;
use crate::{FVarValueKind, Refinement, Scheme, StencilTable};

/// Why a face-varying channel cannot be refined with a split scheme.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SplitFVarError {
    /// OpenSubdiv's schemes refine face-varying data in their own modes
    /// ([`crate::FaceVaryingRefinement`]).
    #[error("the {scheme} scheme refines face-varying data with FaceVaryingRefinement")]
    Scheme {
        /// The scheme's name.
        scheme: &'static str,
    },
    /// Doo-Sabin and √3 carry seamless channels only (see the [module docs](self)).
    #[error(
        "vertex {vertex} is on a texture seam; the {scheme} split cuts across every edge, so it carries only seamless face-varying data (use a butterfly scheme, or one of OpenSubdiv's)"
    )]
    Seam {
        /// The scheme's name.
        scheme: &'static str,
        /// A vertex with more than one value.
        vertex: usize,
    },
    /// The channel does not fit the base mesh.
    #[error(transparent)]
    Channel(#[from] FVarError),
    /// The mesh of values cannot be refined (a bug if it ever happens: it has the
    /// geometry's faces and tags).
    #[error("the mesh of face-varying values: {0}")]
    Values(#[from] crate::RefineError),
    /// The mesh of values cannot be built (a bug if it ever happens).
    #[error("the mesh of face-varying values: {0}")]
    Topology(#[from] TopologyError),
}

/// A face-varying channel refined with a split scheme (see the [module docs](self)).
#[derive(Debug)]
pub struct SplitFaceVarying {
    mode: FVarLinearInterpolation,
    num_user_values: usize,
    base_indices: Vec<u32>,
    /// The channel's value at each vertex of the base mesh of values.
    slot_values: Vec<u32>,
    values: SplitRefinement,
}

impl SplitFaceVarying {
    /// Refines `channel` (made for `refinement`'s base topology) to every level of
    /// `refinement`, interpolated by `mode`.
    ///
    /// # Errors
    /// [`SplitFVarError::Seam`] for a channel with seams under Doo-Sabin or √3;
    /// [`SplitFVarError::Channel`] for a channel without values or without one index per
    /// face-vertex of the base topology.
    pub fn new(
        refinement: &Refinement,
        channel: &FVarChannel,
        mode: FVarLinearInterpolation,
    ) -> Result<SplitFaceVarying, SplitFVarError> {
        if refinement.scheme().is_opensubdiv() {
            return Err(SplitFVarError::Scheme {
                scheme: refinement.scheme().name(),
            });
        }
        let base = refinement.topology(0);
        crate::refine::check_channel(base, channel)?;
        let indices = channel.indices();
        let wedges = Wedges::of(base, indices);
        let scheme = refinement.scheme();
        if !scheme.is_interpolating()
            && let Some(v) = wedges.first_seam_vertex(base.num_vertices())
        {
            return Err(SplitFVarError::Seam {
                scheme: scheme.name(),
                vertex: v,
            });
        }
        let mut topology = wedges.topology(base)?;
        if scheme.is_interpolating() && mode != FVarLinearInterpolation::All {
            // The values OpenSubdiv pins in this mode are corners of the mesh of values.
            let kinds = crate::refine::base_corner_kinds(
                base,
                indices,
                mode,
                BoundaryInterpolation::EdgeOnly,
            );
            for (i, kind) in kinds.into_iter().enumerate() {
                if matches!(kind, FVarValueKind::Corner | FVarValueKind::SemiSharp) {
                    let slot = wedges.corner_slot[i] as usize;
                    topology.set_vertex_sharpness(slot, tags::SHARPNESS_INFINITE);
                }
            }
        }
        let value_scheme = if mode == FVarLinearInterpolation::All {
            scheme.linear_values()
        } else {
            scheme.clone()
        };
        let values = SplitRefinement::new(&topology, &value_scheme, refinement.num_levels())?;
        Ok(SplitFaceVarying {
            mode,
            num_user_values: channel.num_values(),
            base_indices: indices.to_vec(),
            slot_values: wedges.slot_value,
            values,
        })
    }

    /// The interpolation mode.
    pub fn mode(&self) -> FVarLinearInterpolation {
        self.mode
    }

    /// Number of refined levels.
    pub fn num_levels(&self) -> usize {
        self.values.num_levels()
    }

    /// Number of values at `level`: the channel's own count at level 0, and at refined
    /// levels one per vertex of the mesh of values (a vertex on a seam has one per side).
    pub fn num_values(&self, level: usize) -> usize {
        if level == 0 {
            self.num_user_values
        } else {
            self.values.num_vertices(level)
        }
    }

    /// The value index of every face-vertex of `level` (the channel's own indices at level
    /// 0), face after face in the geometry's face order.
    pub fn face_values(&self, level: usize) -> Vec<u32> {
        if level == 0 {
            self.base_indices.clone()
        } else {
            self.values.faces(level).1.to_vec()
        }
    }

    /// The mesh of values at `level`: its vertices are the values of that level (at level 0
    /// the wedges; see [`Self::wedge_values`]), its faces the geometry's.
    pub fn values_topology(&self, level: usize) -> &Topology {
        self.values.topology(level)
    }

    /// The scheme the values are refined with: the geometry's, or the linear butterfly
    /// (tension 0) in mode `all`.
    pub fn values_scheme(&self) -> &Scheme {
        self.values.scheme()
    }

    /// The channel's value at each vertex of the base mesh of values (an isolated vertex,
    /// which no face reads, names value 0).
    pub fn wedge_values(&self) -> &[u32] {
        &self.slot_values
    }

    /// One table from the channel's values to the values of `level`.
    pub fn composed(&self, level: usize) -> StencilTable {
        if level == 0 {
            return StencilTable::identity(self.num_user_values);
        }
        let mut t = StencilTable::build(self.slot_values.len(), self.num_user_values, |r, s| {
            s.add(self.slot_values[r], 1.0)
        });
        for l in 1..=level {
            t = t.then(self.values.stencils(l));
        }
        t
    }

    /// The values of every level (`result[0]` is `values`), `components` numbers each.
    ///
    /// # Panics
    /// If `values` is not `components` numbers per value of the channel.
    pub fn refine_values(&self, values: &[f64], components: usize) -> Vec<Vec<f64>> {
        assert_eq!(
            values.len(),
            components * self.num_user_values,
            "components numbers per value"
        );
        let mut out = vec![values.to_vec()];
        // Level 0 of the mesh of values: the channel's value at each wedge.
        let wedges: Vec<f64> = self
            .slot_values
            .iter()
            .flat_map(|&x| {
                let x = x as usize;
                values[components * x..components * (x + 1)].iter().copied()
            })
            .collect();
        for l in 1..=self.num_levels() {
            let src = if l == 1 { &wedges } else { &out[l - 1] };
            let s = self.values.stencils(l);
            let mut next = vec![0.0; s.num_rows() * components];
            s.apply(src, components, &mut next);
            out.push(next);
        }
        out
    }
}

/// The wedges of a channel: per face-vertex, its wedge (a vertex of the mesh of values); per
/// wedge, its vertex and value. Wedges are numbered vertex by vertex; an isolated vertex has
/// one, so a seamless channel's wedges are its vertices.
struct Wedges {
    corner_slot: Vec<u32>,
    slot_vertex: Vec<u32>,
    slot_value: Vec<u32>,
}

impl Wedges {
    fn of(t: &Topology, indices: &[u32]) -> Wedges {
        let fo = t.face_offsets();
        let fv = t.all_face_vertices();
        // Union-find over face-vertices: the corners of one vertex on the two sides of an
        // edge are one wedge when the edge carries the same values on both sides.
        let mut parent: Vec<u32> = (0..indices.len() as u32).collect();
        fn find(parent: &mut [u32], mut i: u32) -> u32 {
            while parent[i as usize] != i {
                let up = parent[parent[i as usize] as usize];
                parent[i as usize] = up;
                i = up;
            }
            i
        }
        for e in 0..t.num_edges() {
            let faces = t.edge_faces(e);
            if faces.len() != 2 {
                continue;
            }
            let local = t.edge_face_local_indices(e);
            // The corner of `v` on edge `e` in its `j`-th face.
            let corner = |j: usize, v: u32| {
                let (f, l) = (faces[j] as usize, local[j] as usize);
                let n = t.face_size(f);
                let first = fo[f] as usize;
                if fv[first + l] == v {
                    first + l
                } else {
                    first + (l + 1) % n
                }
            };
            // Only an edge continuous at both ends joins its sides: an edge with a seam at one
            // end is two boundary edges of the mesh of values, and joining across it at the
            // other end could pinch two fans into one non-manifold vertex.
            let ends = t.edge_vertices(e).map(|v| (corner(0, v), corner(1, v)));
            if ends.iter().all(|&(a, b)| indices[a] == indices[b]) {
                for (a, b) in ends {
                    let (ra, rb) = (find(&mut parent, a as u32), find(&mut parent, b as u32));
                    parent[ra as usize] = rb;
                }
            }
        }
        let mut slot_of_root = vec![u32::MAX; indices.len()];
        let mut corner_slot = vec![0u32; indices.len()];
        let (mut slot_vertex, mut slot_value) = (Vec::new(), Vec::new());
        for v in 0..t.num_vertices() {
            let faces = t.vertex_faces(v);
            if faces.is_empty() {
                slot_vertex.push(v as u32);
                slot_value.push(0);
                continue;
            }
            for (&f, &k) in faces.iter().zip(t.vertex_face_local_indices(v)) {
                let i = fo[f as usize] as usize + k as usize;
                let root = find(&mut parent, i as u32) as usize;
                if slot_of_root[root] == u32::MAX {
                    slot_of_root[root] = slot_vertex.len() as u32;
                    slot_vertex.push(v as u32);
                    slot_value.push(indices[i]);
                }
                corner_slot[i] = slot_of_root[root];
            }
        }
        Wedges {
            corner_slot,
            slot_vertex,
            slot_value,
        }
    }

    /// A vertex with two wedges or more, if any: one with two different values where there
    /// is one (a vertex whose wedges share a value is cut apart by a seam ending next to it).
    fn first_seam_vertex(&self, num_vertices: usize) -> Option<usize> {
        if self.slot_vertex.len() == num_vertices {
            return None;
        }
        let split = |i: usize| self.slot_vertex[i] == self.slot_vertex[i + 1];
        let pairs = 0..self.slot_vertex.len() - 1;
        pairs
            .clone()
            .find(|&i| split(i) && self.slot_value[i] != self.slot_value[i + 1])
            .or_else(|| pairs.clone().find(|&i| split(i)))
            .map(|i| self.slot_vertex[i] as usize)
    }

    /// The mesh of values: the geometry's faces on wedges, with the geometry's infinitely
    /// sharp creases (where they are not seams) and corner tags.
    fn topology(&self, t: &Topology) -> Result<Topology, TopologyError> {
        let sizes: Vec<u32> = (0..t.num_faces()).map(|f| t.face_size(f) as u32).collect();
        let mut m =
            TopologyBuilder::new(self.slot_vertex.len()).build(&sizes, &self.corner_slot)?;
        let fo = t.face_offsets();
        for e in 0..t.num_edges() {
            if t.edge_sharpness(e) <= 0.0 || t.is_boundary_edge(e) {
                continue;
            }
            let (f, l) = (t.edge_faces(e)[0] as usize, t.edge_face_local_indices(e)[0]);
            let first = fo[f] as usize;
            let a = self.corner_slot[first + l as usize];
            let b = self.corner_slot[first + (l as usize + 1) % t.face_size(f)];
            if let Some(me) = m.find_edge(a, b)
                && !m.is_boundary_edge(me as usize)
            {
                m.set_edge_sharpness(me as usize, t.edge_sharpness(e));
            }
        }
        for (slot, &v) in self.slot_vertex.iter().enumerate() {
            let s = t.vertex_sharpness(v as usize);
            if s > 0.0 {
                m.set_vertex_sharpness(slot, s);
            }
        }
        Ok(m)
    }
}
