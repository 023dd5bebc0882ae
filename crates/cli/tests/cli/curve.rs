//! `subd curve`: text and SVG output, refusals.

use super::*;

#[test]
fn curve_writes_text_and_svg() {
    let s = Scratch::new("curve");
    // A square, closed.
    let square = s.file("square.txt", b"# a square\n0 0\n1 0\n1 1\n0 1\n");
    let out = s.0.join("c.txt");
    let (code, stdout, err) = subd(&[
        "curve",
        "--scheme",
        "chaikin",
        "--levels",
        "3",
        "--closed",
        square.to_str().unwrap(),
        out.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let j: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(j["output_points"], 32);
    assert_eq!(std::fs::read_to_string(&out).unwrap().lines().count(), 32);
    // Open, 3D, csv out.
    let helix = s.file("helix.csv", b"0,0,0\n1,0,0.5\n1,1,1\n0,1,1.5\n0,0,2\n");
    let out = s.0.join("h.csv");
    let (code, _, err) = subd(&[
        "curve",
        "--scheme",
        "bspline",
        "--order",
        "5",
        "--levels",
        "2",
        helix.to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.lines().all(|l| l.split(',').count() == 3));
    assert!(
        text.starts_with("0,0,0\n"),
        "open curves keep their end points"
    );
    // Circle-average scheme with normals, to SVG; and without normals (estimated, warned).
    let pn = s.file("pn.txt", b"1 0 1 0\n0 1 0 1\n-1 0 -1 0\n0 -1 0 -1\n");
    let svg = s.0.join("c.svg");
    let (code, _, err) = subd(&[
        "curve",
        "--scheme",
        "circle-four-point",
        "--levels",
        "4",
        "--closed",
        pn.to_str().unwrap(),
        svg.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let body = std::fs::read_to_string(&svg).unwrap();
    assert!(body.starts_with("<svg") && body.contains("<path") && body.contains("stroke=\"#d33\""));
    let txt = s.0.join("c2.txt");
    let (code, _, err) = subd(&[
        "curve",
        "--scheme",
        "circle-ternary",
        "--levels",
        "2",
        "--closed",
        square.to_str().unwrap(),
        txt.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("normals estimated") || err.contains("estimated from the polygon"),
        "{err}"
    );
    let lines: Vec<Vec<f64>> = std::fs::read_to_string(&txt)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().map(|t| t.parse().unwrap()).collect())
        .collect();
    assert_eq!(lines.len(), 36);
    // The square's estimated normals point outward, and a square's vertices lie on its
    // circumcircle: the circle schemes keep every point on it.
    for l in &lines {
        let r = ((l[0] - 0.5).powi(2) + (l[1] - 0.5).powi(2)).sqrt();
        assert!((r - 0.5f64.sqrt()).abs() < 1e-12, "{l:?}");
    }
}

#[test]
fn curve_bad_input_exits_2_without_output() {
    let s = Scratch::new("curve-bad");
    let good = s.file("good.txt", b"0 0\n1 0\n1 1\n");
    let one = s.file("one.txt", b"0 0\n");
    let nan = s.file("nan.txt", b"0 0\n1 nan\n");
    let mixed = s.file("mixed.txt", b"0 0\n1 0 0\n");
    let out = s.0.join("out.txt");
    let g = good.to_str().unwrap();
    let o = out.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec![
                "curve",
                "--scheme",
                "four-point",
                "--levels",
                "1",
                "--order",
                "3",
                g,
                o,
            ],
            "--order does not apply",
        ),
        (
            vec![
                "curve", "--scheme", "bspline", "--levels", "1", "--order", "1", g, o,
            ],
            "order 1",
        ),
        (
            vec![
                "curve", "--scheme", "tension", "--levels", "1", "--alpha0", "-3", g, o,
            ],
            "alpha0",
        ),
        (
            vec![
                "curve",
                "--scheme",
                "chaikin",
                "--levels",
                "1",
                one.to_str().unwrap(),
                o,
            ],
            "1 points",
        ),
        (
            vec![
                "curve",
                "--scheme",
                "chaikin",
                "--levels",
                "1",
                nan.to_str().unwrap(),
                o,
            ],
            "nan.txt:2:",
        ),
        (
            vec![
                "curve",
                "--scheme",
                "chaikin",
                "--levels",
                "1",
                mixed.to_str().unwrap(),
                o,
            ],
            "mixed.txt:2:",
        ),
        (
            vec![
                "curve", "--scheme", "chaikin", "--levels", "40", "--closed", g, o,
            ],
            "2^28",
        ),
        (
            vec![
                "curve",
                "--scheme",
                "circle-ternary",
                "--levels",
                "1",
                "--omega",
                "1",
                g,
                o,
            ],
            "omega",
        ),
        (vec!["analyze", "--mask", "0.25,1,0.5"], "sum to 1.75"),
        (vec!["analyze", "--mask", "1,x,1"], "coefficient 1"),
        (
            vec!["analyze", "--mask", "0.5,1,0.5", "--arity", "4"],
            "--arity 4",
        ),
        (
            vec!["analyze", "--surface", "loop", "--valence", "2"],
            "--valence 2",
        ),
    ];
    for (args, expect) in cases {
        let (code, stdout, err) = subd(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(stdout.is_empty(), "{args:?}");
        let errors: Vec<&str> = err
            .lines()
            .filter(|l| !l.starts_with("subd: warning:"))
            .collect();
        assert_eq!(errors.len(), 1, "{args:?}: {err}");
        assert!(
            err.contains(expect),
            "{args:?}: expected {expect:?} in {err:?}"
        );
        assert!(!out.exists(), "{args:?} left an output file");
    }
}
