//! `subd eval`: points at (face, u, v), UVs, bad lines.

use super::*;

#[test]
fn eval_writes_points_and_names_bad_lines() {
    let s = Scratch::new("eval");
    let cube = meshes().join("catmark_cube.obj");
    let at = s.file(
        "at.txt",
        b"# centre of face 0, then a corner\n0 0.5 0.5\n\n2 0 0\n",
    );
    let out = s.0.join("out.txt");
    let (code, json, err) = subd(&[
        "eval",
        "--scheme",
        "catmull-clark",
        "--json",
        cube.to_str().unwrap(),
        "--at",
        at.to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let report: serde_json::Value = serde_json::from_str(json.trim()).unwrap();
    assert_eq!(report["points"], 2);
    let rows: Vec<Vec<f64>> = std::fs::read_to_string(&out)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 2);
    // catmark_cube has faces at z = ±1 centred on the z axis: by symmetry the centre of
    // face 0 lies on the axis with normal +z.
    assert!(rows[0][0].abs() < 1e-12 && rows[0][1].abs() < 1e-12);
    assert!((rows[0][5] - 1.0).abs() < 1e-12, "{:?}", rows[0]);
    // A face corner is its vertex's limit: half the vertex on this origin-centred cube
    // (valence-3 mask (9 v + 4 Σ e + Σ f) / 24).
    let corner = {
        let text = std::fs::read_to_string(&cube).unwrap();
        let faces: Vec<&str> = text.lines().filter(|l| l.starts_with("f ")).collect();
        let first: usize = faces[2]
            .split_whitespace()
            .nth(1)
            .unwrap()
            .split('/')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        let v: Vec<f64> = text
            .lines()
            .filter(|l| l.starts_with("v "))
            .nth(first - 1)
            .unwrap()[2..]
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        v
    };
    for k in 0..3 {
        assert!(
            (rows[1][k] - 0.5 * corner[k]).abs() < 1e-12,
            "{:?} vs {corner:?}",
            rows[1]
        );
    }
    // catmark_cube has UVs: each line ends with the limit `u v`.
    assert!(rows.iter().all(|r| r.len() == 8), "{rows:?}");
    eval_uvs_are_linear_in_mode_all(&s, &cube, &at);
    for (args, expect) in [
        ("0 0.5 1.5\n", "at.txt:1: parameters"),
        ("1 0.5 0.5\n99 0.5 0.5\n", "at.txt:2: face 99 out of range"),
        ("0 0.5\n", "at.txt:1: expected"),
        ("0 x 0.5\n", "at.txt:1: expected a parameter"),
    ] {
        let bad = s.file("at.txt", args.as_bytes());
        let out2 = s.0.join("bad.txt");
        let (code, _, err) = subd(&[
            "eval",
            "--scheme",
            "catmull-clark",
            cube.to_str().unwrap(),
            "--at",
            bad.to_str().unwrap(),
            out2.to_str().unwrap(),
        ]);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(expect), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(!out2.exists());
    }
}

/// Under `--fvar-interpolation all` the UVs are bilinear over each face's corners: the centre
/// of face 0 is the mean of its four `vt`, read from the OBJ text, and a corner is its `vt`.
fn eval_uvs_are_linear_in_mode_all(s: &Scratch, cube: &Path, at: &Path) {
    let out = s.0.join("uv.txt");
    let (code, _, err) = subd(&[
        "eval",
        "--scheme",
        "catmull-clark",
        "--fvar-interpolation",
        "all",
        cube.to_str().unwrap(),
        "--at",
        at.to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let rows: Vec<Vec<f64>> = std::fs::read_to_string(&out)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect();
    let text = std::fs::read_to_string(cube).unwrap();
    let vt: Vec<[f64; 2]> = text
        .lines()
        .filter_map(|l| l.strip_prefix("vt "))
        .map(|l| {
            let x: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [x[0], x[1]]
        })
        .collect();
    let corner_vt = |face: usize| -> Vec<[f64; 2]> {
        let line = text
            .lines()
            .filter(|l| l.starts_with("f "))
            .nth(face)
            .unwrap();
        line.split_whitespace()
            .skip(1)
            .map(|c| vt[c.split('/').nth(1).unwrap().parse::<usize>().unwrap() - 1])
            .collect()
    };
    let f0 = corner_vt(0);
    for k in 0..2 {
        let mean = f0.iter().map(|c| c[k]).sum::<f64>() / 4.0;
        assert!(
            (rows[0][6 + k] - mean).abs() < 1e-12,
            "{:?} vs {f0:?}",
            rows[0]
        );
        assert!(
            (rows[1][6 + k] - corner_vt(2)[0][k]).abs() < 1e-12,
            "{:?}",
            rows[1]
        );
    }
}

#[test]
fn eval_loop_points_are_barycentric() {
    let s = Scratch::new("evalloop");
    let mesh = meshes().join("loop_cube.obj");
    let at = s.file("at.txt", b"0 0.25 0.25\n1 1 0\n");
    let out = s.0.join("out.txt");
    let (code, _, err) = subd(&[
        "eval",
        "--scheme",
        "loop",
        mesh.to_str().unwrap(),
        "--at",
        at.to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let rows: Vec<Vec<f64>> = std::fs::read_to_string(&out)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 2);
    for r in &rows {
        let n = (r[3] * r[3] + r[4] * r[4] + r[5] * r[5]).sqrt();
        assert!((n - 1.0).abs() < 1e-12, "{r:?}");
    }
    // Outside the triangle is refused with the line.
    let bad = s.file("bad.txt", b"0 0.75 0.5\n");
    let (code, _, err) = subd(&[
        "eval",
        "--scheme",
        "loop",
        mesh.to_str().unwrap(),
        "--at",
        bad.to_str().unwrap(),
        s.0.join("x.txt").to_str().unwrap(),
    ]);
    assert_eq!(code, 2);
    assert!(
        err.contains("bad.txt:1: parameters (0.75, 0.5) outside the triangle"),
        "{err}"
    );
}
