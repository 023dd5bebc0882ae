//! `subd limit`: text and mesh output, ACC patches, refusals.

use super::*;

#[test]
fn limit_writes_text_and_meshes() {
    let s = Scratch::new("limit");
    let cube = meshes().join("catmark_cube.obj");
    let txt = s.0.join("cube.txt");
    let (code, out, err) = subd(&[
        "limit",
        "--scheme",
        "catmull-clark",
        "--normals",
        "--json",
        cube.to_str().unwrap(),
        txt.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let report: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    assert_eq!(report["vertices"], 8);
    assert_eq!(report["levels_refined"], 0);
    // Closed form for a cube corner v with edge neighbours e and face diagonals f (valence
    // 3): (9 v + 4 Σ e + Σ f) / 24 = v / 2 for a cube centred at the origin.
    let corners: Vec<[f64; 3]> = std::fs::read_to_string(&cube)
        .unwrap()
        .lines()
        .filter(|l| l.starts_with("v "))
        .map(|l| {
            let c: Vec<f64> = l[2..]
                .split_whitespace()
                .map(|x| x.parse().unwrap())
                .collect();
            [c[0], c[1], c[2]]
        })
        .collect();
    let text = std::fs::read_to_string(&txt).unwrap();
    let rows: Vec<Vec<f64>> = text
        .lines()
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 8);
    for (r, c) in rows.iter().zip(&corners) {
        assert_eq!(r.len(), 6);
        for k in 0..3 {
            assert!((r[k] - 0.5 * c[k]).abs() < 1e-12, "{r:?} vs {c:?}");
        }
        // The normal points along the corner's direction from the centre.
        let len = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
        let dot: f64 = (0..3).map(|k| r[3 + k] * c[k] / len).sum();
        assert!((dot - 1.0).abs() < 1e-6, "{r:?}");
    }
    // A mesh output keeps the topology with the vertices moved.
    let obj = s.0.join("cube_limit.obj");
    let (code, _, err) = subd(&[
        "limit",
        "--scheme",
        "catmull-clark",
        cube.to_str().unwrap(),
        obj.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let written = std::fs::read_to_string(&obj).unwrap();
    assert_eq!(written.lines().filter(|l| l.starts_with("f ")).count(), 6);
    assert_eq!(written.lines().filter(|l| l.starts_with("v ")).count(), 8);
}

#[test]
fn limit_bad_input_exits_2_without_output() {
    let s = Scratch::new("limitbad");
    let cube = meshes().join("catmark_cube.obj");
    let out = s.0.join("x.txt");
    for args in [
        vec![
            "limit",
            "--scheme",
            "loop",
            cube.to_str().unwrap(),
            out.to_str().unwrap(),
        ],
        vec![
            "limit",
            "--scheme",
            "bilinear",
            cube.to_str().unwrap(),
            out.to_str().unwrap(),
        ],
        vec![
            "limit",
            "--scheme",
            "catmull-clark",
            cube.to_str().unwrap(),
            s.0.join("x.svg").to_str().unwrap(),
        ],
    ] {
        let (code, _, err) = subd(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(
            !out.exists() && !s.0.join("x.svg").exists(),
            "{args:?} left an output"
        );
        assert!(err.lines().count() <= 4, "{err}");
    }
}

#[test]
fn limit_writes_acc_patches_as_json() {
    let s = Scratch::new("acc");
    let cube = meshes().join("catmark_cube.obj");
    let (txt, acc) = (s.0.join("l.txt"), s.0.join("acc.json"));
    let (code, _, err) = subd(&[
        "limit",
        "--scheme",
        "catmull-clark",
        cube.to_str().unwrap(),
        txt.to_str().unwrap(),
        "--acc",
        acc.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let patches: serde_json::Value = serde_json::from_slice(&std::fs::read(&acc).unwrap()).unwrap();
    let patches = patches.as_array().unwrap();
    assert_eq!(patches.len(), 6);
    // Each patch's first corner is the exact limit of its face's first vertex, which the
    // text output lists: half the vertex on this cube.
    let limits: Vec<Vec<f64>> = std::fs::read_to_string(&txt)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect();
    let text = std::fs::read_to_string(&cube).unwrap();
    let first: usize = text
        .lines()
        .find(|l| l.starts_with("f "))
        .unwrap()
        .split_whitespace()
        .nth(1)
        .unwrap()
        .split('/')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let b00: Vec<f64> = patches[0]["geometry"][0]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    for k in 0..3 {
        assert!((b00[k] - limits[first - 1][k]).abs() < 1e-12, "{b00:?}");
    }
    // Loop has no ACC: exit 2 and nothing written.
    let (l2, a2) = (s.0.join("l2.txt"), s.0.join("a2.json"));
    let tri = meshes().join("loop_cube.obj");
    let (code, _, err) = subd(&[
        "limit",
        "--scheme",
        "loop",
        tri.to_str().unwrap(),
        l2.to_str().unwrap(),
        "--acc",
        a2.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(!l2.exists() && !a2.exists());
}
