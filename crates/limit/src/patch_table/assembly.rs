//! Filling the patch arrays: control points of the regular patches, local points of the
//! end caps (shared between neighbours where OpenSubdiv shares them), patch order.

use std::collections::HashMap;

use subd_schemes::StencilTable;

use super::array::PatchArray;
use super::bspline_caps::{self, CapPoint};
use super::classify::FoundPatch;
use super::end_caps::{self, CornerRules, Row};
use super::features::Regularity;
use super::gather;
use super::levels::PatchLevel;
use super::loop_caps;
use super::{EndCaps, PatchOptions, PatchType};

/// What a local point is shared under (`shareEndCapPatchPoints`): a corner's limit
/// position by its vertex, an edge point by its edge and the end it is nearest, within a
/// level.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum ShareKey {
    Vertex {
        level: u8,
        vertex: u32,
    },
    EdgeEnd {
        level: u8,
        edge: u32,
        first_end: bool,
    },
}

pub(crate) struct Assembly<'a> {
    levels: &'a [PatchLevel],
    level_offsets: &'a [u32],
    options: &'a PatchOptions,
    reg: Regularity,
    /// Local point rows over the refined vertices of all levels, as CSR arrays filled in
    /// place (no row of its own per point).
    local: LocalRows,
    shared: HashMap<ShareKey, u32>,
}

/// The local points' stencil rows as they are appended.
struct LocalRows {
    offsets: Vec<u32>,
    indices: Vec<u32>,
    weights: Vec<f64>,
}

/// A patch's points before the local ones are numbered: a regular patch's refined-vertex
/// indices, or an end cap's points and what each is shared under.
enum PatchPoints {
    Regular([u32; 16], usize),
    Cap(Vec<(CapPoint, Option<ShareKey>)>),
}

/// The arrays, each patch's (array, index) in global order, and the local points' stencils.
pub(crate) type Assembled = (Vec<PatchArray>, Vec<(u32, u32)>, StencilTable);

impl<'a> Assembly<'a> {
    pub fn new(
        levels: &'a [PatchLevel],
        level_offsets: &'a [u32],
        options: &'a PatchOptions,
        reg: Regularity,
    ) -> Assembly<'a> {
        Assembly {
            levels,
            level_offsets,
            options,
            reg,
            local: LocalRows {
                offsets: vec![0],
                indices: Vec::new(),
                weights: Vec::new(),
            },
            shared: HashMap::new(),
        }
    }

    /// The arrays for `found` with end caps of type `caps`: the regular type first (end
    /// caps of the same type in it), then the end caps'; empty arrays dropped.
    pub fn run(mut self, found: &[FoundPatch], caps: PatchType) -> Assembled {
        let regular = if self.reg.face_size == 3 {
            PatchType::Loop
        } else {
            PatchType::Regular
        };
        let mut arrays = [PatchArray::new_of(regular), PatchArray::new_of(caps)];
        let in_caps = found
            .iter()
            .filter(|p| !p.regular && caps != regular)
            .count();
        arrays[0].reserve(found.len() - in_caps);
        arrays[1].reserve(in_caps);
        let mut slots = Vec::with_capacity(found.len());
        let mut cap_indices = Vec::with_capacity(20);
        for p in found {
            let a = usize::from(!p.regular && caps != regular);
            let points = self.patch_points(p);
            slots.push((a, arrays[a].len()));
            let points: &[u32] = match points {
                PatchPoints::Regular(points, n) => {
                    let offset = self.level_offsets[p.level as usize];
                    cap_indices.clear();
                    cap_indices.extend(points[..n].iter().map(|&v| v + offset));
                    &cap_indices
                }
                PatchPoints::Cap(points) => {
                    cap_indices.clear();
                    for (point, key) in points {
                        let i = self.numbered(p.level, point, key);
                        cap_indices.push(i);
                    }
                    &cap_indices
                }
            };
            arrays[a].push((p.level, p.face), p.param, p.sharpness, points);
        }
        let keep: Vec<bool> = arrays.iter().map(|a| !a.is_empty()).collect();
        // Global order: arrays in order, patches in order within each.
        let first = [0, arrays[0].len()];
        let renumber = |a: usize| if keep[0] { a } else { a - 1 };
        let mut handles = vec![(0u32, 0u32); found.len()];
        let mut order: Vec<usize> = (0..found.len()).collect();
        order.sort_by_key(|&i| first[slots[i].0] + slots[i].1);
        for (g, &i) in order.iter().enumerate() {
            let (a, k) = slots[i];
            handles[g] = (renumber(a) as u32, k as u32);
        }
        let total = *self.level_offsets.last().expect("offsets") as usize;
        let LocalRows {
            offsets,
            indices,
            weights,
        } = self.local;
        let local = StencilTable::from_csr(total, offsets, indices, weights);
        let arrays = arrays.into_iter().filter(|a| !a.is_empty()).collect();
        (arrays, handles, local)
    }

    /// A patch's points, before the local ones are numbered.
    fn patch_points(&self, p: &FoundPatch) -> PatchPoints {
        if !p.regular {
            return PatchPoints::Cap(self.end_cap_points(p));
        }
        let t = &self.levels[p.level as usize].topology;
        let f = p.face as usize;
        if self.reg.face_size == 4 {
            PatchPoints::Regular(gather::quad_points(t, f, p.points_mask), 16)
        } else {
            let mut points = [0; 16];
            points[..12].copy_from_slice(&gather::triangle_points(t, f, p.points_mask));
            PatchPoints::Regular(points, 12)
        }
    }

    /// The points of an end cap (rows over its level's vertices, or vertices of the level
    /// a B-spline end cap takes as they are) and what each is shared under.
    fn end_cap_points(&self, p: &FoundPatch) -> Vec<(CapPoint, Option<ShareKey>)> {
        let level = &self.levels[p.level as usize];
        let (t, tags, f) = (&level.topology, &level.tags, p.face as usize);
        let rules = CornerRules {
            inf_sharp: self.options.inf_sharp,
            legacy_sharp_corners: self.options.legacy_sharp_corners,
        };
        let quads = self.reg.face_size == 4;
        let local = |rows: Vec<Row>| rows.into_iter().map(CapPoint::Local).collect();
        let points: Vec<CapPoint> = match self.options.end_caps {
            EndCaps::Exact => return Vec::new(),
            EndCaps::GregoryBasis if quads => local(end_caps::gregory(t, tags, f, &rules)),
            EndCaps::GregoryBasis => local(loop_caps::gregory_triangle(t, tags, f, &rules)),
            EndCaps::BSpline if quads => bspline_caps::bspline(t, tags, f, &rules),
            EndCaps::BSpline => local(loop_caps::box_spline(t, tags, f, &rules)),
            EndCaps::Bilinear => local(end_caps::linear(t, tags, f, &rules)),
        };
        let keys = self.share_keys(p, points.len());
        points.into_iter().zip(keys).collect()
    }

    /// An end cap's point as an index into [refined vertices | local points]: a level
    /// vertex, or a local point (new ones appended, shared ones reused).
    fn numbered(&mut self, level: u8, point: CapPoint, key: Option<ShareKey>) -> u32 {
        match point {
            CapPoint::Vertex(v) => v + self.level_offsets[level as usize],
            CapPoint::Local(row) => self.local_point(level, row, key),
        }
    }

    /// The sharing key of each of an end cap's points (`None`: never shared). Gregory quads
    /// share `P` by vertex and `Ep`/`Em` by edge end on interior edges; bilinear quads
    /// share corners by vertex; B-spline end caps and triangles share nothing.
    fn share_keys(&self, p: &FoundPatch, n: usize) -> Vec<Option<ShareKey>> {
        let level = &self.levels[p.level as usize];
        let t = &level.topology;
        let (fv, fe) = (
            t.face_vertices(p.face as usize),
            t.face_edges(p.face as usize),
        );
        let vertex = |c: usize| {
            Some(ShareKey::Vertex {
                level: p.level,
                vertex: fv[c],
            })
        };
        let edge_end = |e: u32, v: u32| {
            (t.edge_faces(e as usize).len() >= 2).then(|| ShareKey::EdgeEnd {
                level: p.level,
                edge: e,
                first_end: t.edge_vertices(e as usize)[0] == v,
            })
        };
        match (self.reg.face_size, n) {
            (4, 20) => (0..20)
                .map(|k| {
                    let c = k / 5;
                    match k % 5 {
                        0 => vertex(c),
                        1 => edge_end(fe[c], fv[c]),
                        2 => edge_end(fe[(c + 3) % 4], fv[c]),
                        _ => None,
                    }
                })
                .collect(),
            (4, 4) => (0..4).map(vertex).collect(),
            _ => vec![None; n],
        }
    }

    /// The index of a local point with stencil `row` over level `level`'s vertices, new or
    /// shared under `key`.
    fn local_point(&mut self, level: u8, row: Row, key: Option<ShareKey>) -> u32 {
        let total = *self.level_offsets.last().expect("offsets");
        if let Some(k) = key {
            if let Some(&i) = self.shared.get(&k) {
                return total + i;
            }
        }
        let offset = self.level_offsets[level as usize];
        let i = (self.local.offsets.len() - 1) as u32;
        for (v, w) in row {
            self.local.indices.push(v + offset);
            self.local.weights.push(w);
        }
        self.local.offsets.push(self.local.indices.len() as u32);
        if let Some(k) = key {
            self.shared.insert(k, i);
        }
        total + i
    }
}
