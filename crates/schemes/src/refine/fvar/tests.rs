use super::*;
use crate::{Options, Scheme};
use subd_mesh::{DVec3, TopologyBuilder};

/// A 3 × 3 grid of quads (16 vertices), z bumped so no two rules agree by accident.
fn grid() -> (Topology, Vec<DVec3>) {
    let mut faces = Vec::new();
    for y in 0..3u32 {
        for x in 0..3u32 {
            let v = 4 * y + x;
            faces.extend([v, v + 1, v + 5, v + 4]);
        }
    }
    let t = TopologyBuilder::new(16).build(&[4; 9], &faces).unwrap();
    let p = (0..16)
        .map(|i| {
            let (x, y) = ((i % 4) as f64, (i / 4) as f64);
            DVec3::new(x, y, (x * 1.3 + y * y * 0.7).sin())
        })
        .collect();
    (t, p)
}

/// Per face-vertex values of a refined channel.
fn corners(
    r: &Refinement,
    fr: &FaceVaryingRefinement,
    values: &[f64],
    c: usize,
    level: usize,
) -> Vec<f64> {
    let v = fr.refine_values(r, values, c).swap_remove(level);
    fr.face_values(level)
        .iter()
        .flat_map(|&i| v[c * i as usize..c * (i as usize + 1)].to_vec())
        .collect()
}

#[test]
fn a_seamless_channel_in_mode_none_is_refined_as_the_positions() {
    let (mut t, p) = grid();
    let e = t.find_edge(5, 6).unwrap() as usize;
    t.set_edge_sharpness(e, 1.5);
    t.set_vertex_sharpness(10, 2.25);
    let xyz: Vec<f64> = p.iter().flat_map(|q| q.to_array()).collect();
    let tri_faces: Vec<u32> = (0..9)
        .flat_map(|f| {
            let q = t.face_vertices(f);
            [q[0], q[1], q[2], q[0], q[2], q[3]]
        })
        .collect();
    let mut tris = TopologyBuilder::new(16)
        .build(&[3; 18], &tri_faces)
        .unwrap();
    let e = tris.find_edge(5, 6).unwrap() as usize;
    tris.set_edge_sharpness(e, 1.5);
    tris.set_vertex_sharpness(10, 2.25);
    // Lin et al.'s two-phase scheme too: its phase-1 vertex rule (here with λ varying per
    // vertex) reaches matching values through the same rows.
    let lambda: Vec<f64> = (0..16).map(|v| 0.4 + 0.03 * v as f64).collect();
    let two_phase = crate::TwoPhase::new(lambda).unwrap();
    for (scheme, t) in [
        (Scheme::CatmullClark, &t),
        (Scheme::Bilinear, &t),
        (Scheme::Loop, &tris),
        (Scheme::TwoPhase(two_phase), &t),
    ] {
        let r = Refinement::new(t, scheme.clone(), &Options::default(), 3).unwrap();
        let channel = FVarChannel::new(t, 3, xyz.clone(), t.all_face_vertices().to_vec()).unwrap();
        let fr = FaceVaryingRefinement::new(&r, &channel, FVarLinearInterpolation::None).unwrap();
        let pts = r.refine_points(&p);
        for (level, level_points) in pts.iter().enumerate().skip(1) {
            assert_eq!(fr.num_values(level), r.num_vertices(level));
            let got = corners(&r, &fr, &xyz, 3, level);
            let (_, fv) = r.faces(level);
            for (k, &v) in fv.iter().enumerate() {
                let want = level_points[v as usize].to_array();
                for d in 0..3 {
                    assert!(
                        (got[3 * k + d] - want[d]).abs() < 1e-13,
                        "{scheme:?} L{level} corner {k} vertex {v}: {got:?} {want:?}",
                        got = &got[3 * k..3 * k + 3]
                    );
                }
            }
        }
    }
}

#[test]
fn mode_all_is_the_bilinear_refinement_of_the_uv_layout() {
    let (t, _) = grid();
    // Every face its own UV island except the middle column, which shares its values.
    let mut indices = Vec::new();
    let mut uv = Vec::new();
    for f in 0..9 {
        for (k, &v) in t.face_vertices(f).iter().enumerate() {
            if f % 3 == 1 {
                indices.push(100 + v);
            } else {
                indices.push((4 * f + k) as u32);
            }
        }
    }
    for i in 0..116u32 {
        uv.extend([(i as f64 * 0.37).sin(), (i as f64 * 0.11).cos()]);
    }
    let channel = FVarChannel::new(&t, 2, uv.clone(), indices.clone()).unwrap();
    let layout = TopologyBuilder::new(116).build(&[4; 9], &indices).unwrap();
    let layout_points: Vec<DVec3> = (0..116)
        .map(|i| DVec3::new(uv[2 * i], uv[2 * i + 1], 0.0))
        .collect();
    let bilinear = Refinement::new(&layout, Scheme::Bilinear, &Options::default(), 3)
        .unwrap()
        .refine_points(&layout_points);
    let r = Refinement::new(&t, Scheme::CatmullClark, &Options::default(), 3).unwrap();
    let fr = FaceVaryingRefinement::new(&r, &channel, FVarLinearInterpolation::All).unwrap();
    let lr = Refinement::new(&layout, Scheme::Bilinear, &Options::default(), 3).unwrap();
    for (level, level_points) in bilinear.iter().enumerate().skip(1) {
        let got = corners(&r, &fr, &uv, 2, level);
        let (_, fv) = lr.faces(level);
        for (k, &v) in fv.iter().enumerate() {
            let want = level_points[v as usize];
            assert!((got[2 * k] - want.x).abs() < 1e-14);
            assert!((got[2 * k + 1] - want.y).abs() < 1e-14);
        }
    }
}

#[test]
fn corners_only_pins_the_corners_of_the_layout_and_none_does_not() {
    let (t, p) = grid();
    let uv: Vec<f64> = p.iter().flat_map(|q| [q.x + 0.1 * q.z, q.y]).collect();
    let channel = FVarChannel::new(&t, 2, uv.clone(), t.all_face_vertices().to_vec()).unwrap();
    let r = Refinement::new(&t, Scheme::CatmullClark, &Options::default(), 2).unwrap();
    let at_vertex0 = |mode| {
        let fr = FaceVaryingRefinement::new(&r, &channel, mode).unwrap();
        let v = fr.refine_values(&r, &uv, 2).swap_remove(2);
        // Vertex 0 keeps its index at every level and has one value.
        [v[0], v[1]]
    };
    assert_eq!(
        at_vertex0(FVarLinearInterpolation::CornersOnly),
        [uv[0], uv[1]]
    );
    assert_ne!(at_vertex0(FVarLinearInterpolation::None), [uv[0], uv[1]]);
    // Every stencil row of every mode sums to one.
    for mode in FVarLinearInterpolation::ALL_MODES {
        let fr = FaceVaryingRefinement::new(&r, &channel, mode).unwrap();
        let table = fr.composed(&r, 2);
        for i in 0..table.num_rows() {
            let s: f64 = table.row(i).1.iter().sum();
            assert!((s - 1.0).abs() < 1e-14, "{mode:?} row {i}");
        }
    }
}

/// The direct evaluation of `refine_values` (geometric rows away from seams, walked
/// masks near them) equals the stencil tables' rows applied, in every mode, with one to
/// five numbers per value, on one thread and on several, and level by level into
/// buffers.
#[test]
fn direct_values_equal_the_stencil_tables() {
    let (mut t, p) = grid();
    let e = t.find_edge(9, 10).unwrap() as usize;
    t.set_edge_sharpness(e, 1.5);
    // Islands: the left column of faces apart from the rest (a seam along x = 1).
    let mut indices = Vec::new();
    for f in 0..9 {
        for &v in t.face_vertices(f) {
            indices.push(if f % 3 == 0 { v } else { 16 + v });
        }
    }
    let r = Refinement::new(&t, Scheme::CatmullClark, &Options::default(), 3).unwrap();
    // One, two, three and five numbers per value: one group of lanes narrower than,
    // equal to and wider than a point, and two groups with a padded second.
    for c in [1, 2, 3, 5] {
        let values: Vec<f64> = (0..32)
            .flat_map(|i| {
                let q = p[i % 16];
                let shift = 0.3 * (i / 16) as f64;
                [q.x + shift, q.y, q.z, q.x * q.y - shift, q.z - q.y][..c].to_vec()
            })
            .collect();
        let channel = FVarChannel::new(&t, c, values.clone(), indices.clone()).unwrap();
        for mode in FVarLinearInterpolation::ALL_MODES {
            let fr = FaceVaryingRefinement::new(&r, &channel, mode).unwrap();
            let direct = fr.refine_values(&r, &values, c);
            let one = rayon::ThreadPoolBuilder::new()
                .num_threads(1)
                .build()
                .unwrap()
                .install(|| fr.refine_values(&r, &values, c));
            assert_eq!(one, direct, "{mode:?}, {c} numbers: 1 thread and many");
            // Level by level into buffers that held something else.
            for level in 1..direct.len() {
                let mut dst = vec![f64::NAN; direct[level].len()];
                fr.refine_level_into(&r, level, &direct[level - 1], &mut dst, c);
                assert_eq!(dst, direct[level], "{mode:?}, {c} numbers, L{level} into");
            }
            for (level, got) in direct.iter().enumerate().skip(1) {
                let table = fr.composed(&r, level);
                let mut want = vec![0.0; c * table.num_rows()];
                table.apply(&values, c, &mut want);
                assert_eq!(want.len(), got.len());
                for (i, (a, b)) in got.iter().zip(&want).enumerate() {
                    assert!(
                        (a - b).abs() < 1e-13,
                        "{mode:?}, {c} numbers, L{level} [{i}]: {a} vs {b}"
                    );
                }
            }
        }
    }
}

#[test]
fn a_seam_doubles_the_values_of_its_vertices_and_edge_children() {
    let t = TopologyBuilder::new(6)
        .build(&[4, 4], &[0, 1, 4, 3, 1, 2, 5, 4])
        .unwrap();
    let channel =
        FVarChannel::new(&t, 1, (0..8).map(f64::from).collect(), (0..8).collect()).unwrap();
    let r = Refinement::new(&t, Scheme::CatmullClark, &Options::default(), 2).unwrap();
    let fr =
        FaceVaryingRefinement::new(&r, &channel, FVarLinearInterpolation::CornersPlus1).unwrap();
    // Level 1: 6 vertices (1 and 4 doubled: 8), 2 face points, 7 edges (1-4 doubled: 8).
    assert_eq!(fr.num_values(1), 18);
    let v = fr.refine_values(&r, channel.values(), 1).swap_remove(1);
    // The seam's edge child on each side is the midpoint of that side's values.
    let fv = fr.face_values(1);
    // Face 0's child 1 is (E0, V1, E1, F); E1 of face 0 is edge 1-4, the seam.
    let seam_side0 = v[fv[4 + 2] as usize];
    assert_eq!(seam_side0, 0.5 * (1.0 + 2.0));
}

/// Four quads around vertex 4 of a 3 × 3 vertex grid, UV islands alternating A B A B
/// around it: OpenSubdiv's numbering gives that vertex three values (siblings 0 1 0 2),
/// the layout itself two.
#[test]
fn values_coming_back_a_b_a_b_make_three_siblings_as_opensubdiv() {
    let faces = [0, 1, 4, 3, 1, 2, 5, 4, 4, 5, 8, 7, 3, 4, 7, 6];
    let t = TopologyBuilder::new(9).build(&[4; 4], &faces).unwrap();
    // Islands: faces 0 and 2 share island A, faces 1 and 3 island B; each island names
    // its own value at every vertex it touches.
    let mut index = std::collections::HashMap::new();
    let indices: Vec<u32> = faces
        .iter()
        .enumerate()
        .map(|(k, &v)| {
            let island = (k / 4) % 2;
            let n = index.len() as u32;
            *index.entry((v, island)).or_insert(n)
        })
        .collect();
    let values: Vec<f64> = (0..2 * index.len()).map(|i| i as f64).collect();
    let channel = FVarChannel::new(&t, 2, values, indices).unwrap();
    let seams = subd_mesh::fvar::FVarSeams::of(&t, &channel);
    assert_eq!(seams.siblings(4), 2);
    assert_eq!(seams.face_siblings(4), &[0, 1, 0, 1]);
    let r = Refinement::new(&t, Scheme::CatmullClark, &Options::default(), 1).unwrap();
    for mode in FVarLinearInterpolation::ALL_MODES {
        let fr = FaceVaryingRefinement::new(&r, &channel, mode).unwrap();
        // Vertex 4 is vertex 4 at level 1 and keeps its siblings.
        let level = &fr.levels[1];
        assert_eq!(level.count(4), 3, "{mode:?}");
        let base = &fr.levels[0];
        let walk: Vec<usize> = t
            .vertex_faces(4)
            .iter()
            .zip(t.vertex_face_local_indices(4))
            .map(|(&f, &k)| base.corner_slot(&t, f as usize, k as usize) - base.offset(4))
            .collect();
        assert_eq!(walk, [0, 1, 0, 2], "{mode:?}");
    }
}

/// Continuing from a level's state (`level_state` → `restrict` → `from_state`) on the whole
/// level, its faces cut out in order, refines one more level exactly as a two-level
/// refinement does, in every mode: the values' tags are passed down, with a seam, a
/// semi-sharp crease and a semi-sharp vertex whose values' tags depend on their history.
#[test]
fn continuing_from_a_levels_state_is_the_next_level() {
    let (mut t, _) = grid();
    let e = t.find_edge(5, 6).unwrap() as usize;
    t.set_edge_sharpness(e, 1.5);
    t.set_vertex_sharpness(9, 1.25);
    // A seam along x = 1: the faces of column 0 have values of their own there.
    let mut indices = Vec::new();
    for f in 0..9 {
        for &v in t.face_vertices(f) {
            let own = f % 3 == 0 && v % 4 == 1;
            indices.push(if own { 16 + v / 4 } else { v });
        }
    }
    let values: Vec<f64> = (0..2 * 20)
        .map(|i| ((i * 7919) % 97) as f64 / 97.0)
        .collect();
    let ch = FVarChannel::new(&t, 2, values.clone(), indices).unwrap();
    let options = Options::default();
    for mode in FVarLinearInterpolation::ALL_MODES {
        let r2 = Refinement::new(&t, Scheme::CatmullClark, &options, 2).unwrap();
        let fr2 = FaceVaryingRefinement::new(&r2, &ch, mode).unwrap();
        let want = corners(&r2, &fr2, &values, 2, 2);
        let r1 = Refinement::new(&t, Scheme::CatmullClark, &options, 1).unwrap();
        let fr1 = FaceVaryingRefinement::new(&r1, &ch, mode).unwrap();
        let level1 = r1.topology(1);
        let faces: Vec<u32> = (0..level1.num_faces() as u32).collect();
        let cut = subd_mesh::cut::cut(level1, &faces);
        let (state, slots) =
            fr1.level_state(1)
                .restrict(level1, &cut.topology, &faces, &cut.vertices, &cut.edges);
        let rules: Vec<_> = cut
            .vertices
            .iter()
            .map(|&v| r1.vertex_rules(1)[v as usize])
            .collect();
        let next = Refinement::from_prepared(
            cut.topology.clone(),
            rules,
            Scheme::CatmullClark,
            &options,
            1,
        )
        .unwrap();
        let fr = FaceVaryingRefinement::from_state(&next, state).unwrap();
        let v1 = fr1.refine_values(&r1, &values, 2).swap_remove(1);
        let start: Vec<f64> = slots
            .iter()
            .flat_map(|&s| [v1[2 * s as usize], v1[2 * s as usize + 1]])
            .collect();
        let got = corners(&next, &fr, &start, 2, 1);
        assert_eq!(got.len(), want.len());
        for (k, (g, w)) in got.iter().zip(&want).enumerate() {
            assert!((g - w).abs() < 1e-15, "{mode:?}: corner {k}: {g} vs {w}");
        }
    }
}

/// A channel on `faces` (a list of quads or triangles of `t`) in which each face's island
/// (`island(face)`) names its own value at every vertex it touches: seams wherever two
/// islands meet.
fn island_channel(
    t: &Topology,
    faces: &[u32],
    n: usize,
    island: impl Fn(usize) -> usize,
) -> FVarChannel {
    let mut index = std::collections::HashMap::new();
    let indices: Vec<u32> = faces
        .iter()
        .enumerate()
        .map(|(k, &v)| {
            let fresh = index.len() as u32;
            *index.entry((v, island(k / n))).or_insert(fresh)
        })
        .collect();
    let values = (0..index.len()).map(|i| i as f64).collect();
    FVarChannel::new(t, 1, values, indices).unwrap()
}

/// The patch tags of every value of vertex `v` at `level`.
fn patch_tags(
    r: &Refinement,
    channel: &FVarChannel,
    mode: FVarLinearInterpolation,
    level: usize,
    v: usize,
) -> Vec<FVarPatchTag> {
    let fr = FaceVaryingRefinement::new(r, channel, mode).unwrap();
    let values = fr.level_values(r, level);
    (0..values.num_vertex_values(v))
        .map(|k| values.patch_tag(v, k))
        .collect()
}

const REGULAR_CREASE: FVarPatchTag = FVarPatchTag {
    non_manifold: false,
    xordinary: false,
    inf_sharp_edges: false,
    inf_irregular: false,
};

/// The informational value tags of §2.3 on small layouts, each expectation read off the
/// rules there (OpenSubdiv's `FVarLevel::completeTopologyFromFaceValues`): a straight seam
/// through a regular vertex is two regular crease values, its ends on the boundary are
/// one-face spans (smooth corners, irregular, in mode `none`; pinned, regular, with the
/// corners sharp), a seam that ends inside is a dart (one value over four faces), and a
/// value met again after another is non-manifold. Vertex children keep the tags, the values
/// of a seam's edge children have none.
#[test]
fn patch_tags_follow_the_value_spans() {
    use FVarLinearInterpolation as M;
    let faces = [0, 1, 4, 3, 1, 2, 5, 4, 4, 5, 8, 7, 3, 4, 7, 6];
    let t = TopologyBuilder::new(9).build(&[4; 4], &faces).unwrap();
    let r = Refinement::new(&t, Scheme::CatmullClark, &Options::default(), 1).unwrap();
    // Faces 0, 1 below the seam 3-4-5, faces 2, 3 above it.
    let straight = island_channel(&t, &faces, 4, |f| usize::from(f >= 2));
    for mode in [M::None, M::CornersOnly, M::CornersPlus1] {
        assert_eq!(
            patch_tags(&r, &straight, mode, 0, 4),
            [REGULAR_CREASE; 2],
            "{mode:?}"
        );
        assert_eq!(
            patch_tags(&r, &straight, mode, 1, 4),
            [REGULAR_CREASE; 2],
            "{mode:?}"
        );
    }
    let smooth_corner = FVarPatchTag {
        xordinary: true,
        inf_irregular: true,
        ..REGULAR_CREASE
    };
    assert_eq!(patch_tags(&r, &straight, M::None, 0, 3), [smooth_corner; 2]);
    assert_eq!(
        patch_tags(&r, &straight, M::CornersOnly, 0, 3),
        [REGULAR_CREASE; 2]
    );
    // The seam's edge child between vertices 4 and 5: two values, no informational bits,
    // and the matching vertex 0 none either.
    let layout = crate::ChildLayout::new(&t, &Scheme::CatmullClark, 1).unwrap();
    let seam_edge = t.find_edge(4, 5).unwrap();
    let edge_child = layout.edge_point(0, u64::from(seam_edge)) as usize;
    assert_eq!(
        patch_tags(&r, &straight, M::None, 1, edge_child),
        [FVarPatchTag::default(); 2]
    );
    assert_eq!(
        patch_tags(&r, &straight, M::None, 0, 0),
        [FVarPatchTag::default()]
    );
    // A dart: only edge 1-4 is a seam (face 1's value at vertex 1 is its own), so vertex 4
    // has one value spanning all four faces.
    let mut dart_indices: Vec<u32> = faces.to_vec();
    dart_indices[4] = 9;
    let dart = FVarChannel::new(&t, 1, (0..10).map(f64::from).collect(), dart_indices).unwrap();
    let dart_value = FVarPatchTag {
        xordinary: true,
        inf_irregular: true,
        ..REGULAR_CREASE
    };
    for mode in [M::None, M::CornersPlus2] {
        assert_eq!(patch_tags(&r, &dart, mode, 0, 4), [dart_value], "{mode:?}");
    }
    // Islands A B A B around vertex 4: A's value comes back, a disjoint span.
    let alternating = island_channel(&t, &faces, 4, |f| f % 2);
    let tags = patch_tags(&r, &alternating, M::None, 0, 4);
    assert!(tags[0].non_manifold && !tags[0].xordinary, "{tags:?}");
    assert!(tags[1..].iter().all(|g| !g.non_manifold), "{tags:?}");
}

/// Loop's regular boundary vertex has three faces: a straight seam through a valence-6
/// vertex leaves two regular crease values (they would be irregular for quads).
#[test]
fn loop_patch_tags_count_three_faces_as_regular() {
    let faces: Vec<u32> = (0..6u32)
        .flat_map(|i| [0, 1 + i, 1 + (i + 1) % 6])
        .collect();
    let t = TopologyBuilder::new(7).build(&[3; 6], &faces).unwrap();
    let r = Refinement::new(&t, Scheme::Loop, &Options::default(), 1).unwrap();
    let straight = island_channel(&t, &faces, 3, |f| usize::from(f >= 3));
    let tags = patch_tags(&r, &straight, FVarLinearInterpolation::None, 0, 0);
    assert_eq!(tags, [REGULAR_CREASE; 2]);
}
