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
    /// Local point rows over the refined vertices of all levels.
    local_rows: Vec<Row>,
    shared: HashMap<ShareKey, u32>,
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
            local_rows: Vec::new(),
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
        let mut slots = Vec::with_capacity(found.len());
        for p in found {
            let a = usize::from(!p.regular && caps != regular);
            let points = if p.regular {
                self.regular_points(p)
            } else {
                self.end_cap_points(p)
            };
            slots.push((a, arrays[a].len()));
            arrays[a].push((p.level, p.face), p.param, p.sharpness, &points);
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
        let local = StencilTable::from_rows(total, &self.local_rows);
        let arrays = arrays.into_iter().filter(|a| !a.is_empty()).collect();
        (arrays, handles, local)
    }

    /// The 16 or 12 points of a regular patch, as refined-vertex indices.
    fn regular_points(&self, p: &FoundPatch) -> Vec<u32> {
        let level = &self.levels[p.level as usize];
        let offset = self.level_offsets[p.level as usize];
        let f = p.face as usize;
        let local: Vec<u32> = if self.reg.face_size == 4 {
            gather::quad_points(&level.topology, f, p.points_mask).to_vec()
        } else {
            gather::triangle_points(&level.topology, f, p.points_mask).to_vec()
        };
        local.into_iter().map(|v| v + offset).collect()
    }

    /// The points of an end cap: local points (new ones appended, shared ones reused) as
    /// indices past the refined vertices, and the level's vertices a B-spline end cap takes
    /// as they are.
    fn end_cap_points(&mut self, p: &FoundPatch) -> Vec<u32> {
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
        let offset = self.level_offsets[p.level as usize];
        points
            .into_iter()
            .zip(keys)
            .map(|(point, key)| match point {
                CapPoint::Vertex(v) => v + offset,
                CapPoint::Local(row) => self.local_point(p.level, row, key),
            })
            .collect()
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
        let i = self.local_rows.len() as u32;
        self.local_rows
            .push(row.into_iter().map(|(v, w)| (v + offset, w)).collect());
        if let Some(k) = key {
            self.shared.insert(k, i);
        }
        total + i
    }
}
