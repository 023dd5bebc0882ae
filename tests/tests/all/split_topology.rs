//! The split schemes derive a level's topology from the level above (issue 40 item 3); it
//! must be, relation for relation, what `TopologyBuilder` builds from that level's faces and
//! tags, which is what defined the schemes' outputs (new vertices are numbered per edge).

use proptest::prelude::*;
use subd_mesh::{Topology, TopologyBuilder, tags};
use subd_schemes::{Options, Refinement, Scheme};
use subd_tests::{build, mesh_strategy, triangulated};

const SCHEMES: [Scheme; 4] = [
    Scheme::DooSabin,
    Scheme::Sqrt3,
    Scheme::BUTTERFLY,
    Scheme::ModifiedButterfly,
];

/// The builder's topology of level `l` of `r`: its faces, then its explicit tags.
fn reference(r: &Refinement, l: usize) -> Topology {
    let (offsets, vertices) = r.faces(l);
    let sizes: Vec<u32> = offsets.windows(2).map(|w| w[1] - w[0]).collect();
    let mut t = TopologyBuilder::new(r.topology(l).num_vertices())
        .build(&sizes, vertices)
        .expect("a refined level builds");
    let tags = r.explicit_tags(l);
    for ([a, b], s) in tags.creases {
        let e = t.find_edge(a, b).expect("a crease is an edge");
        t.set_edge_sharpness(e as usize, s);
    }
    for (v, s) in tags.corners {
        t.set_vertex_sharpness(v as usize, s);
    }
    t
}

/// The first relation in which `a` and `b` differ, named, or `None` when they are equal.
fn first_difference(a: &Topology, b: &Topology) -> Option<String> {
    let counts = |t: &Topology| (t.num_vertices(), t.num_edges(), t.num_faces());
    if counts(a) != counts(b) {
        return Some(format!("counts {:?} vs {:?}", counts(a), counts(b)));
    }
    if a.all_face_vertices() != b.all_face_vertices() || a.face_offsets() != b.face_offsets() {
        return Some("face vertices".into());
    }
    for f in 0..a.num_faces() {
        if a.face_edges(f) != b.face_edges(f) {
            return Some(format!(
                "face {f} edges {:?} vs {:?}",
                a.face_edges(f),
                b.face_edges(f)
            ));
        }
    }
    for e in 0..a.num_edges() {
        let rel = |t: &Topology| {
            (
                t.edge_vertices(e),
                t.edge_faces(e).to_vec(),
                t.edge_face_local_indices(e).to_vec(),
                t.is_boundary_edge(e),
                t.is_non_manifold_edge(e),
                t.edge_sharpness(e),
            )
        };
        if rel(a) != rel(b) {
            return Some(format!("edge {e}: {:?} vs {:?}", rel(a), rel(b)));
        }
    }
    for v in 0..a.num_vertices() {
        let rel = |t: &Topology| {
            (
                t.vertex_faces(v).to_vec(),
                t.vertex_face_local_indices(v).to_vec(),
                t.vertex_edges(v).to_vec(),
                t.is_boundary_vertex(v),
                t.is_non_manifold_vertex(v),
                t.vertex_sharpness(v),
            )
        };
        if rel(a) != rel(b) {
            return Some(format!("vertex {v}: {:?} vs {:?}", rel(a), rel(b)));
        }
    }
    (a != b).then(|| "a field the accessors do not show".into())
}

/// Every level of `scheme` over `base` (up to `levels`) against the builder's; the number of
/// levels compared (0 when the scheme refuses the mesh).
fn compare_levels(base: &Topology, scheme: &Scheme, levels: usize, what: &str) -> usize {
    let Ok(r) = Refinement::new(base, scheme.clone(), &Options::default(), levels) else {
        return 0;
    };
    for l in 1..=levels {
        if let Some(d) = first_difference(r.topology(l), &reference(&r, l)) {
            panic!("{what} {scheme:?} level {l}: {d}");
        }
    }
    levels
}

/// Levels 1–3 of every split scheme on every OpenSubdiv shape it accepts.
#[test]
fn derived_split_levels_are_the_builders_on_the_osd_shapes() {
    let mut compared = [0usize; 4];
    for path in subd_tests::osd_meshes() {
        let Ok(file) = subd_io::read_mesh(&path, &subd_io::ReadOptions::default()) else {
            continue;
        };
        for (i, scheme) in SCHEMES.iter().enumerate() {
            let what = path.display().to_string();
            compared[i] += compare_levels(&file.mesh.topology, scheme, 3, &what);
        }
    }
    assert!(
        compared.iter().all(|&n| n > 30),
        "levels compared: {compared:?}"
    );
}

/// Marks every `k`-th interior edge an infinitely sharp crease and every `k`-th vertex a
/// corner.
fn tagged(mut t: Topology, k: usize) -> Topology {
    for e in (0..t.num_edges()).step_by(k) {
        if !t.is_boundary_edge(e) {
            t.set_edge_sharpness(e, tags::SHARPNESS_INFINITE);
        }
    }
    for v in (0..t.num_vertices()).step_by(k + 1) {
        t.set_vertex_sharpness(v, 2.0);
    }
    t
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// Levels 1–3 on random meshes with boundaries, creases and corners.
    #[test]
    fn derived_split_levels_are_the_builders_on_random_meshes(
        m in mesh_strategy(),
        every in 3usize..9,
    ) {
        for scheme in SCHEMES {
            let t = if scheme == Scheme::DooSabin {
                build(m.num_vertices, &m.faces)
            } else {
                tagged(triangulated(&m), every)
            };
            compare_levels(&t, &scheme, 3, "random mesh");
        }
    }
}
