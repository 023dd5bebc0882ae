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
            for v in 0..reference.positions.len() {
                let d = (reference.positions[v] - ours.positions[v]).length() / diag;
                assert!(
                    d <= 2e-15,
                    "{} level {level} vertex {v}: position {d:e}",
                    s.name
                );
                let (a, b) = (reference.normals[v], ours.normals[v]);
                let same = (a - b).length() < 1e-13
                    || (a == DVec3::ZERO && b == DVec3::ZERO)
                    || (a.is_nan() && b.is_nan());
                assert!(
                    same,
                    "{} level {level} vertex {v}: normal {a} vs {b}",
                    s.name
                );
            }
            compared += 1;
        }
    }
    assert!(compared > 150, "only {compared} levels compared");
}
