//! `level_limit_points`, the limit of a refined level that `refine --limit` writes, against
//! the stencil tables of that level's own topology (`limit_points`, a separate route: the
//! masks written as rows over a rebuilt refinement of the level, then applied), on every
//! OpenSubdiv shape, Catmull-Clark and Loop, levels 1 to 3.

use glam::DVec3;
use subd_limit::{Tangents, level_limit_points, levels_for_exact_limit, limit_points};
use subd_schemes::Refinement;
use subd_tests::surface_shapes;

fn diagonal(p: &[DVec3]) -> f64 {
    subd_pia::bbox_diagonal(p).max(1e-300)
}

/// Positions of `ours` within `tolerance.0` × `diag` of `reference`'s and unit normals within
/// `tolerance.1`; normals that are zero (parallel tangents) or undefined agree as such.
fn assert_same_limit(
    reference: &subd_limit::LimitPoints,
    ours: &subd_limit::LimitPoints,
    diag: f64,
    (position, normal): (f64, f64),
    what: &str,
) {
    assert_eq!(reference.positions.len(), ours.positions.len(), "{what}");
    for v in 0..reference.positions.len() {
        let d = (reference.positions[v] - ours.positions[v]).length() / diag;
        assert!(d <= position, "{what} vertex {v}: position {d:e}");
        let (a, b) = (reference.normals[v], ours.normals[v]);
        let same = (a - b).length() < normal
            || (a == DVec3::ZERO && b == DVec3::ZERO)
            || (a.is_nan() && b.is_nan());
        assert!(same, "{what} vertex {v}: normal {a} vs {b}");
    }
}

/// Positions agree to 2e-15 of the bounding box (a few units in the last place) and unit normals to 1e-13 (the sums run in
/// another order where the level's rings are read off the level above); normals that are
/// zero (parallel tangents) or undefined agree as such.
#[test]
fn level_limit_equals_the_tables_of_the_level() {
    let mut compared = 0;

    for s in surface_shapes() {
        let levels = 3;
        // Semi-sharp features still decaying at level 3 take `limit_points` itself at every
        // level: nothing to compare (and their reference refines deepest).
        let (decay, _) = levels_for_exact_limit(&s.mesh.topology, &s.scheme);
        if decay > levels || s.mesh.topology.num_face_vertices() << (2 * levels) > 400_000 {
            continue;
        }
        let r = Refinement::new(&s.mesh.topology, s.scheme.clone(), &s.options, levels).unwrap();
        let points = r.refine_points(&s.mesh.positions);
        let diag = diagonal(&s.mesh.positions);
        for (level, points) in points.iter().enumerate().skip(1) {
            let scheme = s.scheme.at_level(level);
            let reference = limit_points(r.topology(level), &scheme, &s.options, points);
            let ours = level_limit_points(&r, level, &s.options, points, Tangents::Kept);
            let (reference, ours) = match (reference, ours) {
                (Ok(a), Ok(b)) => (a, b),
                (Err(a), Err(b)) => {
                    assert_eq!(a.to_string(), b.to_string(), "{} level {level}", s.name);
                    continue;
                }
                (a, b) => panic!("{} level {level}: {:?} vs {:?}", s.name, a.err(), b.err()),
            };
            let what = format!("{} level {level}", s.name);
            assert_same_limit(&reference, &ours, diag, (2e-15, 1e-13), &what);
            compared += 1;
        }
    }
    assert!(compared > 150, "only {compared} levels compared");
}

/// `last_level_limit`, which reads the children of regular quads off the level above's
/// B-spline patches (the rest by the masks of the last level), against `output_limit` of
/// the last level's points (every vertex by its own ring's masks), on every Catmull-Clark
/// shape, levels 1 to 3: positions to 4e-15 of the bounding box, unit normals to 1e-12.
#[test]
fn last_level_limit_from_the_patches_above_equals_the_masks() {
    use subd_limit::refined_mesh::{LimitedRefinement, last_level_limit, output_limit};
    let (mut compared, mut all_regular) = (0, 0);
    for s in surface_shapes() {
        if s.scheme != subd_schemes::Scheme::CatmullClark
            || s.mesh.topology.num_face_vertices() << 6 > 60_000
        {
            continue;
        }
        let diag = diagonal(&s.mesh.positions);
        for levels in 1..=3 {
            let r = LimitedRefinement::new(&s.mesh.topology, s.scheme.clone(), &s.options, levels)
                .unwrap();
            let last = r.last_positions(&s.mesh.positions);
            let (reference, ours) = match (
                output_limit(&r, levels, &s.options, &last),
                last_level_limit(&r, &s.options, &s.mesh.positions),
            ) {
                (Ok(a), Ok(b)) => (a, b),
                (Err(a), Err(b)) => {
                    assert_eq!(a.to_string(), b.to_string(), "{} L{levels}", s.name);
                    continue;
                }
                (a, b) => panic!("{} L{levels}: {:?} vs {:?}", s.name, a.err(), b.err()),
            };
            let what = format!("{} L{levels}", s.name);
            assert_same_limit(&reference, &ours, diag, (4e-15, 1e-12), &what);
            // Bit for bit where the patches were not taken: the same masks.
            all_regular += usize::from(reference.positions != ours.positions);
            compared += 1;
        }
    }
    assert!(compared > 60, "only {compared} levels compared");
    assert!(
        all_regular > 20,
        "the patches were taken on only {all_regular} levels"
    );
}
