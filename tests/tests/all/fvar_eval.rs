//! Face-varying values (UVs) at any (face, u, v) against an independent computation: at every
//! corner of the faces two levels down (deeper where semi-sharp creases need it) the value is
//! the exact limit of that corner's refined value, taken with the limit masks of
//! `subd_limit::fvar::limit_at_level` (checked against OpenSubdiv's `LimitFaceVarying` by
//! `cargo xtask conformance`), in every mode, on every shape of OpenSubdiv's regression suite
//! that has UVs.

use subd_io::{ReadOptions, read_mesh};
use subd_limit::eval::{FaceParam, LimitEvaluator, dyadic_corner};
use subd_limit::fvar::limit_at_level;
use subd_mesh::fvar::FVarLinearInterpolation;
use subd_schemes::{FaceVaryingRefinement, Options, Refinement, Scheme};
use subd_tests::osd_meshes;

/// The dyadic parameters checked on face `f`: the corners of its level-2 pieces.
fn dyadic_params(t: &subd_mesh::Topology, scheme: Scheme, f: usize) -> Vec<FaceParam> {
    let mut out = Vec::new();
    let at = |sub, u, v| FaceParam { face: f, sub, u, v };
    match (scheme, t.face_size(f)) {
        (Scheme::Loop, _) => {
            for i in 0..=4 {
                for j in 0..=4 - i {
                    out.push(at(0, i as f64 / 4.0, j as f64 / 4.0));
                }
            }
        }
        (_, 4) => {
            for i in 0..=4 {
                for j in 0..=4 {
                    out.push(at(0, i as f64 / 4.0, j as f64 / 4.0));
                }
            }
        }
        (_, n) => {
            for sub in 0..n {
                for i in 0..=2 {
                    for j in 0..=2 {
                        out.push(at(sub, i as f64 / 2.0, j as f64 / 2.0));
                    }
                }
            }
        }
    }
    out
}

#[test]
fn uvs_at_dyadic_points_are_limits_of_refined_values() {
    let opts = ReadOptions {
        accept_inconsistent_orientation: true,
        ..Default::default()
    };
    let (mut shapes, mut points, mut refused, mut failures) = (0, 0, 0, Vec::new());
    for path in osd_meshes() {
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        let scheme = if name.starts_with("loop_") {
            Scheme::Loop
        } else if name.starts_with("catmark_") {
            Scheme::CatmullClark
        } else {
            continue;
        };
        let mesh = read_mesh(&path, &opts).unwrap().mesh;
        let Some(uv) = mesh.uv() else { continue };
        let options = Options::from_hints(&mesh.hints);
        let Ok(ev) = LimitEvaluator::new(&mesh.topology, &scheme, &options) else {
            continue;
        };
        let level = 2.max(subd_limit::levels_for_exact_limit(&mesh.topology, &scheme).0);
        if mesh.topology.num_face_vertices() << (2 * level) > 1 << 22 {
            continue;
        }
        shapes += 1;
        let positions = ev.prepare(&mesh.positions);
        let r = Refinement::new(&mesh.topology, scheme.clone(), &options, level).unwrap();
        let t = r.topology(0);
        let diagonal = {
            let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
            for x in uv.values().chunks(2) {
                for i in 0..2 {
                    lo[i] = lo[i].min(x[i]);
                    hi[i] = hi[i].max(x[i]);
                }
            }
            ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2))
                .sqrt()
                .max(1.0)
        };
        // The points the position evaluator covers (holes are not), on at most ~40 faces
        // a shape: every face on small shapes, a spread of them on larger ones.
        // Points next to non-manifold edges are refined locally, slowly: fewer faces there.
        let nonmanifold = (0..t.num_edges()).any(|e| t.is_non_manifold_edge(e));
        let stride = t.num_faces().div_ceil(if nonmanifold { 12 } else { 40 });
        let covered: Vec<FaceParam> = (0..t.num_faces())
            .step_by(stride)
            .flat_map(|f| dyadic_params(t, scheme.clone(), f))
            .filter(|&at| ev.evaluate(&positions, at).is_ok())
            .collect();
        let degenerate = (0..t.num_edges()).any(|e| t.is_degenerate_edge(e));
        for mode in FVarLinearInterpolation::ALL_MODES {
            let fr = FaceVaryingRefinement::new(&r, uv, mode).unwrap();
            let refined = fr.refine_values(&r, uv.values(), 2).swap_remove(level);
            let mut limits = vec![0.0; refined.len()];
            limit_at_level(&r, &fr, level)
                .unwrap()
                .apply(&refined, 2, &mut limits);
            let corner_values = fr.face_values(level);
            let offsets = r.topology(level).face_offsets();
            let uv_eval = match ev.face_varying(uv, mode) {
                Ok(e) => e,
                Err(e) => {
                    failures.push(format!("{name} {mode:?}: {e}"));
                    continue;
                }
            };
            let values = uv_eval.prepare(uv.values()).unwrap();
            let mut worst = (0.0f64, String::new());
            for &at in &covered {
                let got = match uv_eval.evaluate(&values, at) {
                    Ok(p) => p.value,
                    // Refused only next to degenerate edges with two values.
                    Err(subd_limit::LimitError::Unsupported { .. }) if degenerate => {
                        refused += 1;
                        continue;
                    }
                    Err(e) => {
                        failures.push(format!("{name} {mode:?} {at:?}: {e}"));
                        continue;
                    }
                };
                let (g, c) = dyadic_corner(&r, level, at).expect("a corner at that level");
                let i = corner_values[offsets[g] as usize + c] as usize;
                let d = (got[0] - limits[2 * i]).hypot(got[1] - limits[2 * i + 1]);
                points += 1;
                if d > worst.0 {
                    worst = (
                        d,
                        format!("{at:?}: {got:?} vs {:?}", &limits[2 * i..2 * i + 2]),
                    );
                }
            }
            if worst.0 > 1e-10 * diagonal {
                failures.push(format!(
                    "{name} {mode:?}: off by {:.3e} at {}",
                    worst.0, worst.1
                ));
            }
        }
    }
    assert!(shapes > 80, "only {shapes} shapes checked");
    assert!(points > 20_000, "only {points} points checked");
    assert!(refused * 100 < points, "{refused} points refused");
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
