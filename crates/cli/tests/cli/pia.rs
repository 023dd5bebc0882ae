//! `subd pia` and two-phase λ refusals.

use super::*;

#[test]
fn pia_interpolates_and_reports_json() {
    let s = Scratch::new("pia");
    let input = meshes().join("catmark_torus.obj");
    let targets = obj_vertices(&input);
    let fixed = s.file("fixed.txt", b"# keep these\n0 5\n9\n");
    for (scheme, extra) in [
        ("catmull-clark", vec!["--solver", "iterate"]),
        ("catmull-clark", vec!["--solver", "weighted"]),
        ("catmull-clark", vec!["--solver", "direct"]),
        (
            "two-phase",
            vec!["--lambda", "0.6", "--fixed", fixed.to_str().unwrap()],
        ),
    ] {
        let out = s.0.join(format!("{scheme}-{}.obj", extra[1]));
        let mut args = vec!["pia", "--scheme", scheme, "--json"];
        args.extend(&extra);
        args.extend([input.to_str().unwrap(), out.to_str().unwrap()]);
        let (code, stdout, err) = subd(&args);
        assert_eq!(code, 0, "{err}");
        let j: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        assert_eq!(j["converged"], true);
        assert!(j["max_error_relative"].as_f64().unwrap() <= 1e-10);
        let history = j["history"].as_array().unwrap();
        assert_eq!(
            history.len(),
            j["iterations"].as_u64().unwrap() as usize + 1
        );
        // The limit of the output, by `subd limit`, passes through the moving targets.
        let lim = s.0.join("limit.txt");
        let mut largs = vec!["limit", "--scheme", scheme];
        if scheme == "two-phase" {
            largs.extend(["--lambda", "0.6"]);
        }
        largs.extend([out.to_str().unwrap(), lim.to_str().unwrap()]);
        assert_eq!(subd(&largs).0, 0);
        let limits: Vec<Vec<f64>> = std::fs::read_to_string(&lim)
            .unwrap()
            .lines()
            .map(|l| l.split_whitespace().map(|t| t.parse().unwrap()).collect())
            .collect();
        let solved = obj_vertices(&out);
        for (v, t) in targets.iter().enumerate() {
            if scheme == "two-phase" && [0, 5, 9].contains(&v) {
                assert_eq!(&solved[v], t, "fixed vertex {v} moved");
                continue;
            }
            let d: f64 = (0..3)
                .map(|k| (limits[v][k] - t[k]).powi(2))
                .sum::<f64>()
                .sqrt();
            assert!(d < 1e-9, "{scheme} vertex {v}: {d}");
        }
    }
}

#[test]
fn pia_and_two_phase_bad_input_exit_2_without_output() {
    let s = Scratch::new("pia-bad");
    let quad = meshes().join("catmark_torus.obj");
    let tri = meshes().join("loop_cube.obj");
    let out = s.0.join("out.obj");
    let bad_index = s.file("bad_index.txt", b"0 1\n2 x\n");
    let far_index = s.file("far_index.txt", b"0\n\n31 32\n");
    let short_lambda = s.file("short.txt", b"0.5 0.5\n");
    let nan_lambda = s.file("nan.txt", b"0.5\nabc\n");
    let q = quad.to_str().unwrap();
    let o = out.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["pia", "--scheme", "two-phase", "--lambda", "0.3", q, o],
            "outside (7/20, 1]",
        ),
        (
            vec!["pia", "--scheme", "two-phase", "--lambda", "1.5", q, o],
            "outside (7/20, 1]",
        ),
        (vec!["pia", "--scheme", "two-phase", q, o], "needs --lambda"),
        (
            vec![
                "pia",
                "--scheme",
                "two-phase",
                "--lambda",
                "0.5",
                tri.to_str().unwrap(),
                o,
            ],
            "needs quads",
        ),
        (
            vec!["pia", "--scheme", "loop", q, o],
            "Loop scheme needs triangles",
        ),
        (
            vec![
                "pia",
                "--scheme",
                "catmull-clark",
                "--moving",
                bad_index.to_str().unwrap(),
                q,
                o,
            ],
            "bad_index.txt:2:",
        ),
        (
            vec![
                "pia",
                "--scheme",
                "catmull-clark",
                "--fixed",
                far_index.to_str().unwrap(),
                q,
                o,
            ],
            "far_index.txt:3: vertex 32 does not exist",
        ),
        (
            vec![
                "pia",
                "--scheme",
                "two-phase",
                "--lambda-file",
                short_lambda.to_str().unwrap(),
                q,
                o,
            ],
            "2 lambda values for 32 vertices",
        ),
        (
            vec![
                "pia",
                "--scheme",
                "two-phase",
                "--lambda-file",
                nan_lambda.to_str().unwrap(),
                q,
                o,
            ],
            "nan.txt:2:",
        ),
        (
            vec!["pia", "--scheme", "catmull-clark", "--tol=-1", q, o],
            "--tol",
        ),
        (
            vec!["pia", "--scheme", "catmull-clark", "--lambda", "0.5", q, o],
            "two-phase only",
        ),
        (
            vec![
                "refine",
                "--scheme",
                "two-phase",
                "--lambda",
                "0.2",
                "--levels",
                "1",
                q,
                o,
            ],
            "outside (7/20, 1]",
        ),
        (
            vec![
                "refine",
                "--scheme",
                "two-phase",
                "--lambda",
                "0.5",
                "--levels",
                "1",
                tri.to_str().unwrap(),
                o,
            ],
            "needs quads",
        ),
        (
            vec!["limit", "--scheme", "two-phase", q, o],
            "needs --lambda",
        ),
    ];
    for (args, expect) in cases {
        let (code, stdout, err) = subd(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(stdout.is_empty());
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(
            err.contains(expect),
            "{args:?}: expected {expect:?} in {err:?}"
        );
        assert!(!out.exists(), "{args:?} left an output file");
    }
    // Outside the proven range is accepted on request (and λ = 0.3 still converges here).
    let (code, _, err) = subd(&[
        "pia",
        "--scheme",
        "two-phase",
        "--lambda",
        "0.3",
        "--allow-any-lambda",
        q,
        o,
    ]);
    assert_eq!(code, 0, "{err}");
    // Too few iterations: exit 1, no output.
    let out2 = s.0.join("out2.obj");
    let (code, _, err) = subd(&[
        "pia",
        "--scheme",
        "catmull-clark",
        "--solver",
        "iterate",
        "--max-iter",
        "2",
        q,
        out2.to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("did not reach --tol"), "{err}");
    assert!(!out2.exists());
}
