//! `subd patches`: the census on stdout, the arrays in a JSON file whose parts agree with
//! each other and with `subd eval`, and one-line refusals.

use super::{Scratch, meshes, subd};

fn json(s: &str) -> serde_json::Value {
    serde_json::from_str(s.trim()).unwrap_or_else(|e| panic!("{e}: {s}"))
}

#[test]
fn the_census_and_the_arrays_agree() {
    let dir = Scratch::new("patches");
    let out = dir.0.join("cube.json");
    let cube = meshes().join("catmark_cube.obj");
    let (code, stdout, stderr) = subd(&[
        "patches",
        "--scheme",
        "catmull-clark",
        "--isolation",
        "3",
        cube.to_str().unwrap(),
        out.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let census = json(&stdout);
    let keys: Vec<&str> = census
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    assert_eq!(
        keys,
        [
            "by_depth",
            "by_type",
            "local_points",
            "patches",
            "regular_by_boundary_mask"
        ]
    );
    let layout = json(&std::fs::read_to_string(&out).unwrap());
    let arrays = layout["arrays"].as_array().unwrap();
    let total: u64 = arrays.iter().map(|a| a["patches"].as_u64().unwrap()).sum();
    assert_eq!(total, census["patches"].as_u64().unwrap());
    let by_type: u64 = census["by_type"]
        .as_object()
        .unwrap()
        .values()
        .map(|v| v.as_u64().unwrap())
        .sum();
    assert_eq!(by_type, total);
    // Every control point indexes the points; every array holds its stated count.
    let points = layout["points"].as_array().unwrap().len() as u64;
    for a in arrays {
        let n = a["control_points_per_patch"].as_u64().unwrap();
        let cps = a["control_points"].as_array().unwrap();
        assert_eq!(cps.len() as u64, n * a["patches"].as_u64().unwrap());
        assert!(cps.iter().all(|c| c.as_u64().unwrap() < points));
        // Depth in the low 4 bits of the second word, as the census counts them.
        for p in a["params"].as_array().unwrap() {
            let depth = p[1].as_u64().unwrap() & 15;
            assert!(census["by_depth"][depth.to_string()].as_u64().unwrap() > 0);
        }
    }
    let levels: u64 = layout["level_vertex_counts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap())
        .sum();
    assert_eq!(levels + layout["local_points"].as_u64().unwrap(), points);
}

#[test]
fn bad_requests_are_refused_in_one_line() {
    let dir = Scratch::new("patches-bad");
    let cube = meshes().join("catmark_cube.obj");
    let cube = cube.to_str().unwrap();
    for (args, needle) in [
        (vec!["patches", "--scheme", "loop", cube], "needs triangles"),
        (
            vec![
                "patches",
                "--scheme",
                "catmull-clark",
                "--isolation",
                "0",
                cube,
            ],
            "0 is not in 1..=10",
        ),
        (vec!["patches", "--scheme", "bilinear", cube], "bilinear"),
    ] {
        let (code, _, stderr) = subd(&args);
        assert_eq!(code, 2, "{args:?}: {stderr}");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
    }
    let bad_out = dir.0.join("table.txt");
    let (code, _, stderr) = subd(&[
        "patches",
        "--scheme",
        "catmull-clark",
        cube,
        bad_out.to_str().unwrap(),
    ]);
    assert_eq!((code, stderr.lines().count()), (2, 1), "{stderr}");
    assert!(!bad_out.exists());
}

/// Numbers of a text output, line by line.
fn numbers(path: &std::path::Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .map(|l| {
            l.split_whitespace()
                .filter_map(|x| x.parse().ok())
                .collect()
        })
        .collect()
}

#[test]
fn eval_and_tessellate_on_exact_end_caps_are_the_exact_limit() {
    let dir = Scratch::new("patches-eval");
    let shape = meshes().join("catmark_cube_creases1.obj");
    let shape = shape.to_str().unwrap();
    let at = dir.file("at.txt", b"0 0.3 0.2\n3 0.7 0.9\n5 0.01 0.02\n2 0.5 0.5\n");
    let at = at.to_str().unwrap();
    let (exact, table, gregory) = (
        dir.0.join("e.txt"),
        dir.0.join("t.txt"),
        dir.0.join("g.txt"),
    );
    for (out, extra) in [
        (&exact, vec![]),
        (&table, vec!["--end-caps", "exact", "--isolation", "2"]),
        (&gregory, vec!["--end-caps", "gregory"]),
    ] {
        let mut args = vec![
            "eval",
            "--scheme",
            "catmull-clark",
            shape,
            "--at",
            at,
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        let (code, _, stderr) = subd(&args);
        assert_eq!(code, 0, "{stderr}");
    }
    let (e, t, g) = (numbers(&exact), numbers(&table), numbers(&gregory));
    assert_eq!(e.len(), 4);
    for ((a, b), c) in e.iter().zip(&t).zip(&g) {
        for k in 0..3 {
            assert!((a[k] - b[k]).abs() < 1e-12, "{a:?} vs {b:?}");
            // Gregory end caps approximate the limit near the corners only.
            assert!((a[k] - c[k]).abs() < 1e-2, "{a:?} vs {c:?}");
        }
    }
    // Tessellation: the same samples, on the table or the exact evaluator (rate 3 is not a
    // power of two, so both evaluate every sample).
    let (ta, tb) = (dir.0.join("a.obj"), dir.0.join("b.obj"));
    let (code, _, stderr) = subd(&[
        "tessellate",
        "--scheme",
        "catmull-clark",
        "--rate",
        "3",
        shape,
        ta.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let (code, _, stderr) = subd(&[
        "tessellate",
        "--scheme",
        "catmull-clark",
        "--rate",
        "3",
        "--end-caps",
        "exact",
        "--isolation",
        "3",
        shape,
        tb.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let (a, b) = (numbers(&ta), numbers(&tb));
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x.len(), y.len());
        for (p, q) in x.iter().zip(y) {
            assert!((p - q).abs() < 1e-12, "{x:?} vs {y:?}");
        }
    }
}

/// Texture coordinates in the input become the table's face-varying channel: its base
/// values are the file's, every patch names `values_per_patch` of them, and refined
/// linearly (mode `all`) every value is a convex combination of the file's, so it lies in
/// their bounding box.
#[test]
fn texture_coordinates_become_face_varying_patches() {
    let dir = Scratch::new("patches_fvar");
    let out = dir.0.join("cube.json");
    let cube = meshes().join("catmark_cube.obj");
    let (code, _, stderr) = subd(&[
        "patches",
        "--scheme",
        "catmull-clark",
        "--isolation",
        "3",
        "--fvar-interpolation",
        "all",
        cube.to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let layout = json(&std::fs::read_to_string(&out).unwrap());
    let fvar = &layout["face_varying"].as_array().unwrap()[0];
    assert_eq!(fvar["interpolation"], "all");
    assert_eq!(fvar["components"], 2);
    let file_uvs: Vec<f64> = std::fs::read_to_string(&cube)
        .unwrap()
        .lines()
        .filter_map(|l| l.strip_prefix("vt "))
        .flat_map(|l| {
            l.split_whitespace()
                .take(2)
                .map(|x| x.parse::<f64>().unwrap())
                .collect::<Vec<_>>()
        })
        .collect();
    let values: Vec<f64> = fvar["values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let counts: Vec<u64> = fvar["level_value_counts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_u64().unwrap())
        .collect();
    assert_eq!(counts[0] as usize * 2, file_uvs.len());
    assert_eq!(values[..file_uvs.len()], file_uvs[..]);
    assert_eq!(values.len() as u64, 2 * counts.iter().sum::<u64>());
    let (lo, hi) = file_uvs
        .chunks(2)
        .fold(([f64::MAX; 2], [f64::MIN; 2]), |(lo, hi), p| {
            (
                [lo[0].min(p[0]), lo[1].min(p[1])],
                [hi[0].max(p[0]), hi[1].max(p[1])],
            )
        });
    for p in values.chunks(2) {
        for k in 0..2 {
            assert!(p[k] >= lo[k] - 1e-15 && p[k] <= hi[k] + 1e-15, "{p:?}");
        }
    }
    let arrays = layout["arrays"].as_array().unwrap();
    let per_patch = fvar["values_per_patch"].as_u64().unwrap();
    assert_eq!(per_patch, 4);
    for (a, pv) in arrays.iter().zip(fvar["patch_values"].as_array().unwrap()) {
        let pv = pv.as_array().unwrap();
        assert_eq!(pv.len() as u64, per_patch * a["patches"].as_u64().unwrap());
        assert!(
            pv.iter()
                .all(|v| v.as_u64().unwrap() < values.len() as u64 / 2)
        );
    }
}
