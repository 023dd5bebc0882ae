//! `subd edit` and `subd deform`.

use super::*;

#[test]
fn edit_meets_constraints_and_reports_json() {
    let s = Scratch::new("edit");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let input = root.join("meshes/torus_creased.obj");
    let constraints = root.join("edit/torus_edit.json");
    let mut energy_before = Vec::new();
    for (method, extra) in [
        ("least-squares", vec![]),
        ("energy", vec![]),
        ("energy", vec!["--region-rings", "1"]),
        ("energy", vec!["--penalty", "1e10", "--membrane", "0.1"]),
    ] {
        let out = s.0.join(format!("edit-{method}-{}.obj", extra.len()));
        let mut args = vec![
            "edit",
            "--constraints",
            constraints.to_str().unwrap(),
            "--method",
            method,
        ];
        args.extend(&extra);
        args.extend([input.to_str().unwrap(), out.to_str().unwrap(), "--json"]);
        let (code, stdout, err) = subd(&args);
        assert_eq!(code, 0, "{err}");
        let j: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        let tol = if extra.contains(&"--penalty") {
            1e-6
        } else {
            1e-10
        };
        assert!(
            j["max_residual_relative"].as_f64().unwrap() < tol,
            "{stdout}"
        );
        for r in j["residuals"].as_array().unwrap() {
            assert!(r["residual"].as_f64().unwrap() < 100.0 * tol, "{stdout}");
        }
        assert_eq!(j["constraints"], 4);
        assert!(j["energy_after"].as_f64().is_some());
        energy_before.push(j["energy_before"].as_f64().unwrap());
        // The iso-line ends at the infinitely sharp crease: its last control point is the
        // extrapolation 2 c₃ − c₂, and its displacements (…, 0.1, 0.05, 0) agree with that.
        assert_eq!(j["dependencies"][0]["constraints"], serde_json::json!([3]));
        assert!(
            err.contains("constraint 3 (isoline from face 60 along u at 0.5) is redundant")
                && !err.contains("conflict"),
            "{err}"
        );
        let moved = j["moved_vertices"].as_array().unwrap().len();
        assert!(moved > 0 && moved <= j["free_vertices"].as_u64().unwrap() as usize);
        assert!(out.exists());
    }
    // A property of the input surface, not of the method or its options.
    assert!(
        energy_before.iter().all(|&e| e == energy_before[0]),
        "{energy_before:?}"
    );
}

#[test]
fn edit_and_deform_bad_input_exit_2_without_output() {
    let s = Scratch::new("edit-bad");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let input = root.join("meshes/torus_creased.obj");
    let cases = [
        (
            r#"{"constraints": [{"kind": "pin", "vertex": 1}]}"#,
            "constraint 0: unknown kind \"pin\"",
        ),
        (
            r#"{"constraints": [{"kind": "point", "vertex": 1, "target": [0,0,0]}, {"kind": "point", "face": 999, "uv": [0.5, 0.5], "target": [0,0,0]}]}"#,
            "constraint 1: face 999 out of range",
        ),
        (
            r#"{"constraints": [{"kind": "point", "vertex": 720, "target": [0,0,0]}]}"#,
            "constraint 0: vertex 720 out of range",
        ),
        (
            r#"{"constraints": [{"kind": "point", "face": 3, "uv": [1.5, 0.5], "target": [0,0,0]}]}"#,
            "constraint 0: parameters (1.5, 0.5) outside [0, 1]",
        ),
        (
            r#"{"constraints": [{"kind": "normal", "vertex": 3, "normal": [0, 0, 0]}]}"#,
            "constraint 0: the normal is zero",
        ),
        (
            r#"{"constraints": [{"kind": "point", "vertex": 3, "target": [NaN, 0, 0]}]}"#,
            "not JSON",
        ),
        (
            r#"{"constraints": [{"kind": "isoline", "face": 3, "along": "u", "at": 0.5, "faces": 2, "targets": [[0,0,0]]}]}"#,
            "constraint 0: an iso-line over 2 faces needs 5 control points",
        ),
    ];
    for (k, (text, want)) in cases.iter().enumerate() {
        let c = s.file(&format!("c{k}.json"), text.as_bytes());
        let out = s.0.join(format!("out{k}.obj"));
        let (code, _, err) = subd(&[
            "edit",
            "--constraints",
            c.to_str().unwrap(),
            input.to_str().unwrap(),
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 2, "{text}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.starts_with(&format!("subd: {}", c.display())) && err.contains(want),
            "{err:?} lacks {want:?}"
        );
        assert!(!out.exists());
    }
    // Energy on Loop, and energy options with least squares.
    let c = root.join("edit/torus_edit.json");
    let out = s.0.join("x.obj");
    let (code, _, err) = subd(&[
        "edit",
        "--constraints",
        c.to_str().unwrap(),
        "--penalty",
        "5",
        input.to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("apply to the energy method only"), "{err}");
    let (code, _, err) = subd(&[
        "edit",
        "--constraints",
        c.to_str().unwrap(),
        "--method",
        "energy",
        "--region-rings",
        "many",
        input.to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(!out.exists());
    // Deformation: a zero radius, and coinciding centres.
    for (k, (text, want)) in [
        (r#"{"constraints": [{"center": [0,0,0], "radius": 0, "displacement": [0,0,1]}]}"#, "deformation constraint 0: the radius must be positive"),
        (r#"{"constraints": [{"center": [0,0,0], "radius": 1, "displacement": [0,0,1]}, {"center": [0,0,0], "radius": 2, "displacement": [0,0,1]}]}"#, "deformation constraint 1: its centre coincides"),
        (r#"{"constraints": [{"centre": [0,0,0], "radius": 1, "displacement": [0,0,1]}]}"#, "constraint 0: unknown field \"centre\""),
    ]
    .iter()
    .enumerate()
    {
        let c = s.file(&format!("d{k}.json"), text.as_bytes());
        let out = s.0.join(format!("d{k}.obj"));
        let (code, _, err) = subd(&["deform", "--constraints", c.to_str().unwrap(), input.to_str().unwrap(), out.to_str().unwrap()]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(want), "{err:?} lacks {want:?}");
        assert!(!out.exists());
    }
}

#[test]
fn deform_moves_constraint_points_and_keeps_the_rest() {
    let s = Scratch::new("deform");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let input = root.join("meshes/torus_creased.obj");
    let out = s.0.join("deformed.obj");
    let (code, stdout, err) = subd(&[
        "deform",
        "--constraints",
        root.join("edit/torus_deform.json").to_str().unwrap(),
        input.to_str().unwrap(),
        out.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let j: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert!(j["moved"].as_u64().unwrap() > 0);
    let (a, b) = (obj_vertices(&input), obj_vertices(&out));
    // Vertex 0 is the first centre (2.6, 0, 0): moved by exactly (0.4, 0, 0.3).
    assert!((b[0][0] - 3.0).abs() < 1e-12 && (b[0][2] - 0.3).abs() < 1e-12);
    let centres = [[2.6, 0.0, 0.0, 1.0], [-1.4, 0.0, 0.0, 0.6]];
    for (p, q) in a.iter().zip(&b) {
        let inside = centres.iter().any(|c| {
            ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2)).sqrt() < c[3]
        });
        if !inside {
            assert_eq!(p, q);
        }
    }
}

/// Runs `subd edit` with `constraints` (JSON text) on `input`; (exit code, JSON report,
/// stderr).
fn edit_json(
    s: &Scratch,
    tag: &str,
    input: &Path,
    constraints: &str,
    extra: &[&str],
) -> (i32, serde_json::Value, String) {
    let c = s.file(&format!("{tag}.json"), constraints.as_bytes());
    let out = s.0.join(format!("{tag}.obj"));
    let mut args = vec!["edit", "--constraints", c.to_str().unwrap()];
    args.extend(extra);
    args.extend([input.to_str().unwrap(), out.to_str().unwrap(), "--json"]);
    let (code, stdout, err) = subd(&args);
    let j = serde_json::from_str(&stdout).unwrap_or(serde_json::Value::Null);
    (code, j, err)
}

fn torus_creased() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/meshes/torus_creased.obj")
}

#[test]
fn edit_warns_naming_conflicting_constraints_with_their_residual() {
    let s = Scratch::new("edit-conflict");
    // Two displacements of vertex 8's limit point, 0.25 and 0.05 along z: the z rows ask
    // two values of one, and (−1, 1)/√2 · r = 0.2/√2 is what no change can meet.
    let text = r#"{"constraints": [
      {"kind": "point", "vertex": 8, "displacement": [0, 0, 0.25]},
      {"kind": "point", "face": 40, "uv": [0.5, 0.5], "displacement": [0, 0, -0.15]},
      {"kind": "point", "vertex": 8, "displacement": [0, 0, 0.05]}
    ]}"#;
    let hand = 0.2 / 2f64.sqrt();
    for method in ["least-squares", "energy"] {
        let (code, j, err) = edit_json(&s, method, &torus_creased(), text, &["--method", method]);
        assert_eq!(code, 0, "{err}");
        let c = s.0.join(format!("{method}.json"));
        let want = format!(
            "subd: warning: {}: constraints 0 (point at vertex 8) and 2 (point at vertex 8) \
             conflict: no surface meets them all (3 dependent rows); the least-squares \
             compromise leaves {hand:.4e} unmet",
            c.display()
        );
        assert_eq!(err.trim_end(), want, "{method}");
        assert_eq!(j["rank_deficient"], true);
        let groups = j["dependencies"].as_array().unwrap();
        assert_eq!(groups.len(), 1, "{j}");
        assert_eq!(groups[0]["constraints"], serde_json::json!([0, 2]));
        assert_eq!(groups[0]["consistent"], false);
        assert!((groups[0]["residual"].as_f64().unwrap() - hand).abs() < 1e-12);
        // Measured afresh: the compromise (0.15) misses each request by 0.1.
        let r = &j["residuals"];
        for k in [0, 2] {
            assert!(
                (r[k]["residual"].as_f64().unwrap() - 0.1).abs() < 1e-9,
                "{r}"
            );
        }
    }
}

#[test]
fn edit_notes_redundant_constraints_as_dependent_not_conflicting() {
    let s = Scratch::new("edit-redundant");
    let text = r#"{"constraints": [
      {"kind": "point", "vertex": 8, "displacement": [0, 0, 0.25]},
      {"kind": "point", "face": 40, "uv": [0.5, 0.5], "displacement": [0, 0, -0.15]},
      {"kind": "point", "vertex": 8, "displacement": [0, 0, 0.25]}
    ]}"#;
    for method in ["least-squares", "energy"] {
        let (code, j, err) = edit_json(&s, method, &torus_creased(), text, &["--method", method]);
        assert_eq!(code, 0, "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.starts_with("subd: warning: ")
                && err.contains(
                    "constraints 0 (point at vertex 8) and 2 (point at vertex 8) are \
                     redundant: their rows are dependent but consistent"
                )
                && !err.contains("conflict"),
            "{err}"
        );
        let groups = j["dependencies"].as_array().unwrap();
        assert_eq!(groups.len(), 1, "{j}");
        assert_eq!(groups[0]["constraints"], serde_json::json!([0, 2]));
        assert_eq!(groups[0]["consistent"], true);
        assert!(groups[0]["residual"].as_f64().unwrap() < 1e-12, "{j}");
        assert!(j["max_residual_relative"].as_f64().unwrap() < 1e-10, "{j}");
    }
}

/// An m × n torus grid whose control points are `(cos ωi, sin ωi, cos(ψj + 0.3))` (ω = 2π/m,
/// ψ = 2π/n), as OBJ, and its thin-plate energy: every coordinate varies along one grid
/// direction, F'' of a uniform cubic B-spline is linear between the second differences
/// κ f (κ = 2 cos ω − 2) and `∫₀¹ ((1−s) a + s b)² = (a² + ab + b²)/3`, so
/// `E = m n [κ_m² (2 + cos ω)/3 + κ_n² (2 + cos ψ)/6]`.
fn separable_torus(m: usize, n: usize) -> (String, f64) {
    let (w, p) = (
        std::f64::consts::TAU / m as f64,
        std::f64::consts::TAU / n as f64,
    );
    let mut obj = String::new();
    for i in 0..m {
        for j in 0..n {
            let (a, b) = (w * i as f64, p * j as f64 + 0.3);
            obj += &format!("v {} {} {}\n", a.cos(), a.sin(), b.cos());
        }
    }
    let id = |i: usize, j: usize| (i % m) * n + (j % n) + 1;
    for i in 0..m {
        for j in 0..n {
            let f = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
            obj += &format!("f {} {} {} {}\n", f[0], f[1], f[2], f[3]);
        }
    }
    let (km, kn) = (2.0 * w.cos() - 2.0, 2.0 * p.cos() - 2.0);
    let e = (m * n) as f64 * (km * km * (2.0 + w.cos()) / 3.0 + kn * kn * (2.0 + p.cos()) / 6.0);
    (obj, e)
}

#[test]
fn edit_energy_before_is_the_input_surfaces_whatever_the_method() {
    let s = Scratch::new("edit-energy");
    let (obj, hand) = separable_torus(12, 8);
    let grid = s.file("grid.obj", obj.as_bytes());
    let text = r#"{"constraints": [
      {"kind": "point", "vertex": 30, "displacement": [0, 0, 0.2]},
      {"kind": "normal", "face": 50, "uv": [0.5, 0.5], "normal": [0.1, 0.2, 1.0]}
    ]}"#;
    let runs: [(&str, &[&str]); 4] = [
        ("ls", &["--method", "least-squares"]),
        ("energy", &["--method", "energy"]),
        ("ring", &["--method", "energy", "--region-rings", "1"]),
        (
            "penalty",
            &[
                "--method",
                "energy",
                "--penalty",
                "1e8",
                "--membrane",
                "0.5",
            ],
        ),
    ];
    // The grid has a closed form; the creased torus (creases, semi-sharp ones) has not.
    for (input, hand) in [(grid, Some(hand)), (torus_creased(), None)] {
        let mut reports = Vec::new();
        for (tag, extra) in runs {
            let (code, j, err) = edit_json(&s, tag, &input, text, extra);
            assert_eq!(code, 0, "{tag}: {err}");
            let e = j["energy_before"].as_f64().unwrap();
            if let Some(hand) = hand {
                assert!((e - hand).abs() < 1e-10 * hand, "{tag}: {e} against {hand}");
            }
            reports.push(j);
        }
        // One function of the surface: the same bits for every method, and a method's
        // energy_after is the energy_before of its output.
        for j in &reports[1..] {
            assert_eq!(j["energy_before"], reports[0]["energy_before"]);
        }
        for (tag, j) in ["ls", "energy"].iter().zip(&reports) {
            let output = s.0.join(format!("{tag}.obj"));
            let (_, again, err) = edit_json(&s, &format!("{tag}-again"), &output, text, &[]);
            assert_eq!(again["energy_before"], j["energy_after"], "{tag}: {err}");
        }
    }
}
