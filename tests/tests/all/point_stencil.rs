//! Point stencils and face patches of the limit surface, against the evaluator run on the
//! positions themselves (every OpenSubdiv shape, Catmull-Clark and Loop).

use subd_limit::eval::{FaceParam, LimitEvaluator};
use subd_limit::{PatchForm, point_stencil::POSITION};
use subd_mesh::DVec3;
use subd_schemes::Scheme;
use subd_tests::surface_shapes;

/// Deterministic parameters in the face (Loop: inside the triangle), corners included.
fn params(scheme: Scheme, k: usize) -> (f64, f64) {
    let table = [
        (0.0, 0.0),
        (1.0, 0.0),
        (0.5, 0.5),
        (0.3, 0.7),
        (0.11, 0.83),
        (0.625, 0.25),
    ];
    let (u, v) = table[k % table.len()];
    if scheme == Scheme::Loop && u + v > 1.0 {
        (u * 0.5, v * 0.5)
    } else {
        (u, v)
    }
}

#[test]
fn stencils_reproduce_the_evaluator_on_every_shape() {
    let mut checked = 0;
    for shape in surface_shapes() {
        let topo = &shape.mesh.topology;
        let Ok(ev) = LimitEvaluator::new(topo, &shape.scheme, &shape.options) else {
            continue;
        };
        let p = &shape.mesh.positions;
        let pts = ev.prepare(p);
        let diag = subd_pia::bbox_diagonal(p).max(1e-300);
        for face in (0..topo.num_faces()).step_by(1 + topo.num_faces() / 10) {
            let subs = if shape.scheme == Scheme::CatmullClark && topo.face_size(face) != 4 {
                topo.face_size(face)
            } else {
                1
            };
            for sub in 0..subs {
                let (u, v) = params(shape.scheme.clone(), face + 7 * sub);
                let at = FaceParam { face, sub, u, v };
                let Ok(direct) = ev.evaluate(&pts, at) else {
                    continue;
                };
                let st = ev.stencil(at).expect("a stencil wherever evaluate works");
                let sum: f64 = st.weights[POSITION].iter().sum();
                assert!(
                    (sum - 1.0).abs() < 1e-12,
                    "{} face {face}: sum {sum}",
                    shape.name
                );
                let support = ev.support(face);
                assert!(
                    st.indices.iter().all(|i| support.binary_search(i).is_ok()),
                    "{} face {face}: weights outside the face's support",
                    shape.name
                );
                let via = st.apply(p);
                let scale = diag * (1.0 + direct.du.length() + direct.dv.length());
                for (a, b, rel, what) in [
                    (via.position, direct.position, 1e-11, "position"),
                    (via.du, direct.du, 1e-11, "du"),
                    (via.dv, direct.dv, 1e-11, "dv"),
                    // Deep local refinement scales second derivatives by 4 per level, and
                    // their rounding with them.
                    (via.duu, direct.duu, 1e-8, "duu"),
                    (via.duv, direct.duv, 1e-8, "duv"),
                    (via.dvv, direct.dvv, 1e-8, "dvv"),
                ] {
                    let tol = rel * (scale + b.length());
                    assert!(
                        (a - b).length() <= tol,
                        "{} face {face} ({u}, {v}) {what}: {a} vs {b}",
                        shape.name
                    );
                }
                checked += 1;
            }
        }
    }
    assert!(checked > 500, "only {checked} points checked");
}

#[test]
fn face_patches_reproduce_the_evaluator() {
    let mut checked = 0;
    for shape in surface_shapes()
        .into_iter()
        .filter(|s| s.scheme == Scheme::CatmullClark)
    {
        let topo = &shape.mesh.topology;
        let Ok(ev) = LimitEvaluator::new(topo, &shape.scheme, &shape.options) else {
            continue;
        };
        let p = &shape.mesh.positions;
        let pts = ev.prepare(p);
        for face in (0..topo.num_faces()).step_by(1 + topo.num_faces() / 40) {
            let Ok(patches) = ev.face_patches(face) else {
                continue;
            };
            for patch in patches {
                let ctrl: Vec<DVec3> = patch
                    .controls
                    .iter()
                    .map(|row| row.iter().map(|&(v, w)| w * p[v as usize]).sum())
                    .collect();
                // The centre of the patch's domain, in its own and in the face's parameters.
                let (u, v) = (
                    patch.origin[0] + 0.5 * patch.size,
                    patch.origin[1] + 0.5 * patch.size,
                );
                let at = FaceParam {
                    face,
                    sub: patch.sub,
                    u,
                    v,
                };
                let Ok(direct) = ev.evaluate(&pts, at) else {
                    continue;
                };
                let own = match &patch.form {
                    PatchForm::Bicubic => {
                        let grid: [DVec3; 16] = std::array::from_fn(|i| ctrl[i]);
                        subd_limit::patch::eval_bicubic(&grid, 0.5, 0.5).position
                    }
                    PatchForm::Corner(m) => m.evaluate(&ctrl, 0.5, 0.5).position,
                    PatchForm::Other => continue,
                };
                let tol = 1e-11 * (1.0 + direct.position.length());
                assert!(
                    (own - direct.position).length() < tol,
                    "{} face {face}: patch {own} vs {}",
                    shape.name,
                    direct.position
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 500, "only {checked} patches checked");
}
