//! `subd analyze`: the seeds' verdicts.

use super::*;

#[test]
fn analyze_reports_the_seeds_verdicts() {
    // The 4-point scheme: C¹, with fractions accepted.
    let (code, out, err) = subd(&["analyze", "--mask", "-1/16,0,9/16,1,9/16,0,-1/16"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("converges: yes") && out.contains("C^1 shown"),
        "{out}"
    );
    let (code, out, _) = subd(&["analyze", "--mask", "0.125,0.5,0.75,0.5,0.125", "--json"]);
    assert_eq!(code, 0);
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["converges"], true);
    assert_eq!(j["smoothness"], 2);
    assert_eq!(j["norms"][0][0], 0.5);
    // Ternary, ω = 1/4: C¹.
    let (code, out, _) = subd(&[
        "analyze",
        "--arity",
        "3",
        "--mask",
        "-1/12,0,1/4,5/6,1,5/6,1/4,0,-1/12",
        "--json",
    ]);
    assert_eq!(code, 0);
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["smoothness"], 1);
    // Bivariate: the tensor-product cubic B-spline, C¹ shown.
    let row = [1.0, 4.0, 6.0, 4.0, 1.0];
    let mask2: Vec<String> = row
        .iter()
        .map(|y| {
            row.iter()
                .map(|x| format!("{}", x * y / 64.0))
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect();
    let (code, out, err) = subd(&["analyze", "--mask2", &mask2.join(";"), "--json"]);
    assert_eq!(code, 0, "{err}");
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["smoothness"], 1);
    // Surface eigenvalue test.
    let (code, out, _) = subd(&[
        "analyze",
        "--surface",
        "catmull-clark",
        "--valence",
        "5",
        "--json",
    ]);
    assert_eq!(code, 0);
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["passes"], true);
    assert!((j["eigenvalues"][0].as_f64().unwrap() - 1.0).abs() < 1e-12);
}
