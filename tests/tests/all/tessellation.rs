//! `tessellate_mesh` (the exact-limit patch table, each patch's samples from one gather and
//! a basis tabulated per rate) against `tessellate` with the exact evaluator (one patch
//! evaluation per sample, a separate route), on every OpenSubdiv shape, Catmull-Clark and
//! Loop, rates 1 (where the faces allow), 2, 4 and 8.

use glam::DVec3;
use subd_limit::eval::LimitEvaluator;
use subd_limit::tessellation::{tessellate, tessellate_mesh};
use subd_tests::surface_shapes;

fn diagonal(p: &[DVec3]) -> f64 {
    subd_pia::bbox_diagonal(p).max(1e-300)
}

/// The same samples (parameters), faces and grids. Positions within 2.5e-14 of the bounding
/// box; unit normals within 2e-10, and within 1e-12 but for a few near extraordinary
/// vertices, where the evaluator's eigenbasis sums and the table's regular patches one
/// level down round differently. Where a tangent vanishes (back-to-back faces fold over
/// along their edges) the normal is undefined, rounding on either side: not compared.
#[test]
fn refined_tessellation_equals_the_evaluated_one() {
    let (mut compared, mut samples, mut loose, mut folds) = (0, 0, 0, 0);
    let (mut worst_p, mut worst_n) = (0.0f64, 0.0f64);
    for s in surface_shapes() {
        let diag = diagonal(&s.mesh.positions);
        for rate in [1, 2, 4, 8] {
            if s.mesh.topology.num_face_vertices() * rate * rate > 100_000 {
                continue;
            }
            let name = format!("{} rate {rate}", s.name);
            let (topo, p) = (&s.mesh.topology, &s.mesh.positions);
            let ours = tessellate_mesh(topo, &s.scheme, &s.options, p, rate);
            let evaluator =
                LimitEvaluator::new(topo, &s.scheme, &s.options).map(|ev| (ev.prepare(p), ev));
            let reference = evaluator
                .as_ref()
                .map_err(Clone::clone)
                .and_then(|(pts, ev)| tessellate(ev, pts, rate));
            let (reference, ours) = match (reference, ours) {
                (Ok(a), Ok(b)) => (a, b),
                (Err(a), Err(b)) => {
                    assert_eq!(a.to_string(), b.to_string(), "{name}");
                    continue;
                }
                (a, b) => panic!("{name}: {:?} vs {:?}", a.err(), b.err()),
            };
            assert_eq!(reference.params, ours.params, "{name}");
            assert_eq!(reference.face_offsets, ours.face_offsets, "{name}");
            assert_eq!(reference.face_vertices, ours.face_vertices, "{name}");
            assert_eq!(reference.grids, ours.grids, "{name}");
            assert_eq!(reference.grid_vertices, ours.grid_vertices, "{name}");
            for v in 0..reference.positions.len() {
                let at = reference.params[v];
                let d = (reference.positions[v] - ours.positions[v]).length() / diag;
                assert!(d <= 2.5e-14, "{name} sample {v} at {at:?}: position {d:e}");
                let (a, b) = (reference.normals[v], ours.normals[v]);
                let dn = (a - b).length();
                if dn > 2e-10 {
                    let (pts, ev) = evaluator.as_ref().expect("the reference had one");
                    let d = ev.evaluate(pts, at).expect("on the surface");
                    let (du, dv) = (d.du.length(), d.dv.length());
                    if du.min(dv) <= 1e-9 * du.max(dv) {
                        folds += 1;
                        continue;
                    }
                }
                assert!(
                    dn <= 2e-10,
                    "{name} sample {v} at {at:?}: normal {a} vs {b}"
                );
                (worst_p, worst_n) = (worst_p.max(d), worst_n.max(dn));
                loose += usize::from(dn > 1e-12);
            }
            samples += reference.positions.len();
            compared += 1;
        }
    }
    eprintln!(
        "{compared} tessellations, {samples} samples: worst position {worst_p:e}, normal {worst_n:e}; {loose} normals beyond 1e-12; {folds} at folds"
    );
    assert!(
        folds * 1000 < samples,
        "{folds} of {samples} samples at folds"
    );
    assert!(compared > 150, "{compared} tessellations compared");
    assert!(
        loose * 50 < samples,
        "{loose} of {samples} normals beyond 1e-12"
    );
}
