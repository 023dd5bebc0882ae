//! Which faces of the sparse levels are patches, and of what kind: regular or end cap,
//! boundary and transition masks, single creases, and where each lies in its base face
//! (OpenSubdiv's `Far::PatchBuilder`: `IsFaceAPatch`, `IsFaceALeaf`, `IsPatchRegular`,
//! `GetRegularPatchBoundaryMask`, `ComputePatchParam`; behaviour reproduced, code our own).

use subd_mesh::Topology;
use subd_mesh::cut::NONE;
use subd_mesh::tags::is_infinite;

use super::features::{FeatureMask, Regularity, VTag, single_crease_edge};
use super::levels::PatchLevel;
use super::param::{PatchParam, PatchPlace};
use super::{EndCaps, PatchOptions};

/// One patch found in the levels.
#[derive(Debug, Clone, Copy)]
pub(crate) struct FoundPatch {
    pub level: u8,
    pub face: u32,
    pub regular: bool,
    pub param: PatchParam,
    /// Sharpness of a single-crease patch (0 otherwise).
    pub sharpness: f32,
    /// The boundary mask the regular patch's points are gathered with (a single-crease
    /// patch's parameter holds its crease edge instead).
    pub points_mask: u8,
}

/// How patches are told apart.
pub(crate) struct Classifier<'a> {
    pub levels: &'a [PatchLevel],
    pub options: &'a PatchOptions,
    pub reg: Regularity,
    /// First root (ptex) index of each base face.
    pub ptex: &'a [u32],
    /// The base mesh has faces of a size other than the regular one.
    pub irregular_faces: bool,
    /// The features the refinement isolates.
    pub mask: FeatureMask,
}

impl Classifier<'_> {
    /// Every patch, level by level and in face order within a level.
    pub fn patches(&self) -> Vec<FoundPatch> {
        let max_level = self.levels.len() - 1;
        let mut out = Vec::new();
        for (l, level) in self.levels.iter().enumerate() {
            let t = &level.topology;
            for f in 0..t.num_faces() {
                let leaf = l == max_level || !level.selected[f];
                if leaf && !t.is_hole(f) && self.is_patch(level, f) {
                    out.push(self.patch(l, f));
                }
            }
        }
        out
    }

    fn corner_tags(level: &PatchLevel, f: usize) -> Vec<VTag> {
        level
            .topology
            .face_vertices(f)
            .iter()
            .map(|&v| level.tags[v as usize])
            .collect()
    }

    /// `IsFaceAPatch` (holes excluded by the caller).
    fn is_patch(&self, level: &PatchLevel, f: usize) -> bool {
        let all = VTag::union(Self::corner_tags(level, f));
        if level.depth == 0 {
            !all.has(VTag::INCID_IRREG_FACE)
        } else if self.reg.face_size == 4 {
            !all.has(VTag::INCOMPLETE)
        } else {
            level.parent_selected[f]
        }
    }

    fn patch(&self, l: usize, f: usize) -> FoundPatch {
        let level = &self.levels[l];
        let corners = Self::corner_tags(level, f);
        let mut regular = self.is_regular(level, f, &corners);
        let (mut boundary, mut sharpness, mut points_mask) = (0u8, 0.0f32, 0u8);
        if regular {
            boundary = self.boundary_mask(level, f, &corners);
            points_mask = boundary;
            let isolation = usize::from(self.options.isolation);
            if self.options.single_crease
                && self.reg.face_size == 4
                && boundary == 0
                && l < isolation
            {
                if let Some(edge) = single_crease_edge(&level.topology, f, &corners) {
                    boundary = 1 << edge;
                    let e = level.topology.face_edges(f)[edge] as usize;
                    sharpness = level.topology.edge_sharpness(e).min((isolation - l) as f32);
                }
            }
        }
        if self.options.end_caps == EndCaps::Exact
            && regular
            && (sharpness > 0.0
                || (l + 1 == self.levels.len() && self.would_refine(level, f, &corners)))
        {
            // A regular patch OpenSubdiv approximates: a feature the isolation level cut
            // short (semi-sharp creases not decayed, sharp features taken as smooth, legacy
            // sharp corners), or a single crease. Exact end caps take it.
            regular = false;
            (boundary, sharpness, points_mask) = (0, 0.0, 0);
        }
        let transition = if l + 1 < self.levels.len() {
            level
                .topology
                .face_edges(f)
                .iter()
                .enumerate()
                .fold(0u8, |m, (i, &e)| {
                    m | (u8::from(level.is_transitional(e as usize)) << i)
                })
        } else {
            0
        };
        FoundPatch {
            level: l as u8,
            face: f as u32,
            regular,
            param: PatchParam::new(self.place(l, f, regular, boundary, transition)),
            sharpness,
            points_mask,
        }
    }

    /// Whether the refinement would isolate face `f` further, had it levels left.
    fn would_refine(&self, level: &PatchLevel, f: usize, corners: &[VTag]) -> bool {
        self.mask
            .select(corners, self.reg.face_size, level.depth, || {
                single_crease_edge(&level.topology, f, corners).is_some()
            })
    }

    /// `IsPatchRegular`.
    fn is_regular(&self, level: &PatchLevel, f: usize, corners: &[VTag]) -> bool {
        let all = VTag::union(corners.iter().copied());
        if !all.has(VTag::INF_SHARP | VTag::INF_SHARP_EDGES) {
            return !all.has(VTag::XORDINARY);
        }
        let test_inf = self.options.inf_sharp;
        let legacy = self.options.legacy_sharp_corners;
        let irregular_bits =
            VTag::NON_MANIFOLD | VTag::XORDINARY | if test_inf { VTag::INF_IRREGULAR } else { 0 };
        if !all.has(irregular_bits) {
            return true;
        }
        let needs_extra = usize::from(all.has(VTag::XORDINARY) && self.irregular_faces);
        if level.depth > needs_extra {
            let further = all.has(VTag::NON_MANIFOLD)
                || (legacy && all.has(VTag::XORDINARY) && all.has(VTag::BOUNDARY))
                || (test_inf && all.has(VTag::INF_IRREGULAR) && all.has(VTag::INF_SHARP_EDGES));
            if !further {
                return if test_inf {
                    !all.has(VTag::INF_IRREGULAR)
                } else {
                    !all.has(VTag::XORDINARY)
                };
            }
        }
        let t = &level.topology;
        let fe = t.face_edges(f);
        let n = corners.len();
        let span_regular = if self.reg.face_size == 4 { 2 } else { 3 };
        for (i, &tag) in corners.iter().enumerate() {
            if !tag.has(irregular_bits) {
                continue;
            }
            let v = t.face_vertices(f)[i] as usize;
            if tag.has(VTag::NON_MANIFOLD) {
                let span = corner_span(t, f, v, test_inf);
                let want = if tag.has(VTag::INF_SHARP) {
                    1
                } else {
                    span_regular
                };
                if span != want {
                    return false;
                }
                continue;
            }
            if tag.has(VTag::XORDINARY) {
                if !tag.has(VTag::INF_SHARP_EDGES) {
                    return false;
                }
                let boundary_edge = |e: u32| t.edge_faces(e as usize).len() < 2;
                if legacy
                    && tag.has(VTag::BOUNDARY)
                    && !tag.has(VTag::INF_SHARP)
                    && boundary_edge(fe[i])
                    && boundary_edge(fe[(i + n - 1) % n])
                {
                    continue;
                }
                if !test_inf {
                    return false;
                }
            }
            if tag.has(VTag::INF_IRREGULAR) {
                if !tag.has(VTag::INF_SHARP_EDGES)
                    || (tag.has(VTag::INF_SHARP_CREASE) && tag.has(VTag::BOUNDARY))
                {
                    return false;
                }
                let span = corner_span(t, f, v, true);
                let want = if tag.has(VTag::INF_SHARP_CREASE) {
                    span_regular
                } else {
                    1
                };
                if span != want {
                    return false;
                }
            }
        }
        true
    }

    /// `GetRegularPatchBoundaryMask`: quads, bit `i` for a boundary (non-manifold, or with
    /// infinitely sharp patches, sharp) face edge `i`; triangles, OpenSubdiv's five-bit
    /// encoding of edges and vertices.
    fn boundary_mask(&self, level: &PatchLevel, f: usize, corners: &[VTag]) -> u8 {
        if !corners.iter().any(|t| t.has(VTag::INF_SHARP_EDGES)) {
            return 0;
        }
        let t = &level.topology;
        let test_inf = self.options.inf_sharp;
        let e_bits = t.face_edges(f).iter().enumerate().fold(0u8, |m, (i, &e)| {
            let e = e as usize;
            let edge = t.edge_faces(e).len() < 2
                || t.is_non_manifold_edge(e)
                || (test_inf && is_infinite(t.edge_sharpness(e)));
            m | (u8::from(edge) << i)
        });
        if corners.len() == 4 {
            return e_bits;
        }
        let v_bits = corners.iter().enumerate().fold(0u8, |m, (i, tag)| {
            let bits = VTag::BOUNDARY
                | VTag::NON_MANIFOLD
                | if test_inf { VTag::INF_SHARP_EDGES } else { 0 };
            m | (u8::from(tag.has(bits)) << i)
        });
        encode_triangle_mask(e_bits, v_bits)
    }

    /// `ComputePatchParam`: the root face and the patch's position in it, walking up the
    /// levels through each face's parent.
    fn place(&self, l: usize, f: usize, regular: bool, boundary: u8, transition: u8) -> PatchPlace {
        let triangles = self.reg.face_size == 3;
        let (mut u, mut v, mut ofs, mut rotated) = (0i32, 0i32, 1i32, false);
        let mut child = f;
        let mut irregular_base = self.levels[l].topology.face_size(f) != self.reg.face_size;
        let mut sub_face = 0u32;
        for i in (1..=l).rev() {
            let (parent, k) = self.levels[i].face_parent[child];
            debug_assert_ne!(parent, NONE);
            let parent = parent as usize;
            irregular_base = self.levels[i - 1].topology.face_size(parent) != self.reg.face_size;
            if triangles {
                let s = if rotated { -1 } else { 1 };
                match k {
                    1 => u += s * ofs,
                    2 => v += s * ofs,
                    3 => {
                        u -= s * ofs;
                        v -= s * ofs;
                        rotated = !rotated;
                    }
                    _ => {}
                }
                ofs <<= 1;
            } else if !irregular_base {
                match k {
                    1 => u += ofs,
                    2 => {
                        u += ofs;
                        v += ofs;
                    }
                    3 => v += ofs,
                    _ => {}
                }
                ofs <<= 1;
            } else {
                sub_face = u32::from(k);
            }
            child = parent;
        }
        if rotated {
            u += ofs;
            v += ofs;
        }
        PatchPlace {
            face: self.ptex[child] + if irregular_base { sub_face } else { 0 },
            u: u as u16,
            v: v as u16,
            depth: l as u8,
            non_quad: irregular_base,
            boundary,
            transition,
            regular,
        }
    }
}

/// Faces in the span of face `f` around its corner `v`, bounded by boundary and
/// non-manifold edges (and infinitely sharp ones when `sharp_bounds`).
fn corner_span(t: &Topology, f: usize, v: usize, sharp_bounds: bool) -> usize {
    let bounds = |e: usize| {
        t.edge_faces(e).len() != 2
            || t.is_non_manifold_edge(e)
            || (sharp_bounds && is_infinite(t.edge_sharpness(e)))
    };
    // The two edges of `g` at `v`: the one leaving `v` and the one arriving at it.
    let edges_at = |g: usize| -> [usize; 2] {
        let fv = t.face_vertices(g);
        let fe = t.face_edges(g);
        let i = fv
            .iter()
            .position(|&x| x as usize == v)
            .expect("corner of its face");
        [fe[i] as usize, fe[(i + fv.len() - 1) % fv.len()] as usize]
    };
    let mut count = 1;
    for side in 0..2 {
        let (mut g, mut e) = (f, edges_at(f)[side]);
        loop {
            if bounds(e) {
                break;
            }
            let faces = t.edge_faces(e);
            let next = if faces[0] as usize == g {
                faces[1]
            } else {
                faces[0]
            } as usize;
            if next == f {
                // Closed around: every face counted once.
                return count;
            }
            count += 1;
            let [a, b] = edges_at(next);
            e = if a == e { b } else { a };
            g = next;
        }
    }
    count
}

/// OpenSubdiv's five-bit boundary mask of a triangle from its boundary edges and vertices
/// (`encodeTriBoundaryMask`).
fn encode_triangle_mask(e_bits: u8, v_bits: u8) -> u8 {
    if e_bits == 0 && v_bits == 0 {
        0
    } else if e_bits == 0 {
        (1 << 3) | v_bits
    } else if v_bits == 7 && matches!(e_bits, 1 | 2 | 4) {
        (2 << 3) | e_bits
    } else {
        e_bits
    }
}
