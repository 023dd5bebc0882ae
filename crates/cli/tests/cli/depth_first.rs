//! `subd refine --depth-first`: the same bytes as the level at a time, a peak memory that
//! does not grow with the level, and outputs it cannot make (or no format can hold)
//! refused before any work with one line and no file.

use std::fmt::Write as _;

use super::{Scratch, subd};

/// A torus of `m × n` quads as OBJ, wavy so no two points coincide, with a semi-sharp
/// crease ring and a semi-sharp corner (both gone by level 3).
fn torus_obj(m: usize, n: usize) -> String {
    let mut s = String::new();
    for j in 0..n {
        for i in 0..m {
            let (u, v) = (
                std::f64::consts::TAU * i as f64 / m as f64,
                std::f64::consts::TAU * j as f64 / n as f64,
            );
            let r = 3.0 + v.cos();
            let z = v.sin() + 0.05 * (7.0 * u).sin();
            writeln!(s, "v {} {} {z}", r * u.cos(), r * u.sin()).unwrap();
        }
    }
    let id = |i: usize, j: usize| (j % n) * m + (i % m) + 1;
    for j in 0..n {
        for i in 0..m {
            let c = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
            writeln!(s, "f {} {} {} {}", c[0], c[1], c[2], c[3]).unwrap();
        }
    }
    for i in 0..m {
        writeln!(
            s,
            "t crease 2/1/0 {} {} 1.5",
            id(i, 0) - 1,
            id(i + 1, 0) - 1
        )
        .unwrap();
    }
    writeln!(s, "t corner 1/1/0 {} 2.5", id(3, 5) - 1).unwrap();
    s
}

/// An open strip of `m × n` squares split into triangles.
fn open_triangles_obj(m: usize, n: usize) -> String {
    let mut s = String::new();
    for j in 0..=n {
        for i in 0..=m {
            let (x, y) = (i as f64 / m as f64, j as f64 / n as f64);
            writeln!(s, "v {x} {y} {}", 0.2 * (5.0 * x).sin() * (3.0 * y).cos()).unwrap();
        }
    }
    for j in 0..n {
        for i in 0..m {
            let a = j * (m + 1) + i + 1;
            let (b, c, d) = (a + 1, a + m + 2, a + m + 1);
            writeln!(s, "f {a} {b} {c}\nf {a} {c} {d}").unwrap();
        }
    }
    s
}

#[test]
fn depth_first_files_equal_the_level_at_a_time() {
    let dir = Scratch::new("depth-first-same");
    let torus = dir.file("torus.obj", torus_obj(12, 9).as_bytes());
    let open = dir.file("open.obj", open_triangles_obj(9, 7).as_bytes());
    let cases = [
        (&torus, "catmull-clark", "3"),
        (&torus, "bilinear", "3"),
        (&torus, "catmull-clark", "4"),
        (&open, "loop", "3"),
        (&open, "catmull-clark", "3"),
    ];
    for ((input, scheme, levels), ext) in cases.into_iter().flat_map(|c| [(c, "ply"), (c, "obj")]) {
        let a = dir.0.join(format!("a.{ext}"));
        let b = dir.0.join(format!("b.{ext}"));
        let input = input.to_str().unwrap();
        let common = ["refine", input, "--scheme", scheme, "--levels", levels];
        let (code, out, err) = subd(
            &[
                &common[..],
                &[
                    a.to_str().unwrap(),
                    "--depth-first",
                    "--max-memory",
                    "40M",
                    "--json",
                ],
            ]
            .concat(),
        );
        assert_eq!(code, 0, "{err}");
        assert!(out.contains("\"depth_first\":true"), "{out}");
        let (code, out, err) = subd(&[&common[..], &[b.to_str().unwrap(), "--json"]].concat());
        assert_eq!(code, 0, "{err}");
        assert!(out.contains("\"depth_first\":false"), "{out}");
        let (a, b) = (std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
        assert!(
            a == b,
            "{scheme} L{levels} of {input} to .{ext}: the files differ"
        );
    }
}

/// The peak resident memory of a depth-first run to `output` (in `dir`) under a budget of
/// `budget_mib` MiB, from its report.
fn peak(dir: &Scratch, input: &str, levels: &str, output: &str, budget_mib: u64) -> u64 {
    let out_path = dir.0.join(output);
    let budget = format!("{budget_mib}M");
    let (code, out, err) = subd(&[
        "refine",
        input,
        out_path.to_str().unwrap(),
        "--scheme",
        "catmull-clark",
        "--levels",
        levels,
        "--depth-first",
        "--max-memory",
        &budget,
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let report: serde_json::Value = serde_json::from_str(&out).unwrap();
    report["peak_memory"]
        .as_u64()
        .expect("peak_memory in the report")
}

/// L5 and L6 of one mesh (6.6M and 26M quads, many chunks each) peak within 20% of each
/// other: chunks sized by the budget, not by the level.
#[test]
#[cfg(target_os = "linux")]
fn depth_first_memory_is_flat_in_the_level() {
    let dir = Scratch::new("depth-first-flat");
    let torus = dir.file("torus.obj", torus_obj(80, 80).as_bytes());
    let torus = torus.to_str().unwrap();
    assert_flat_peaks(&dir, torus, ["5", "6"], "out.ply", 100);
}

/// The peaks of two levels of `input` written depth-first to `output` (the second four
/// times the first) are within 20% of each other, and the deeper one within the budget.
/// The allowance is for the allocator and the chunks' count, which grows with the level
/// (a few MB either way on a 2-core machine); a level at a time grows with the level.
fn assert_flat_peaks(dir: &Scratch, input: &str, levels: [&str; 2], output: &str, budget_mib: u64) {
    let (a, b) = (
        peak(dir, input, levels[0], output, budget_mib),
        peak(dir, input, levels[1], output, budget_mib),
    );
    let ratio = b as f64 / a as f64;
    assert!(
        (0.8..=1.2).contains(&ratio),
        "{output}: peaks {a} and {b} bytes: ratio {ratio}"
    );
    assert!(
        b <= budget_mib << 20,
        "{output}: peak {b} bytes over --max-memory {budget_mib}M"
    );
}

/// The same for OBJ, whose records go through a scratch file and are encoded in order a
/// window at a time: L4 and L5 of a 1,600-quad torus (410k and 1.6M quads; the OBJ of L5
/// is ~150 MB) peak within 20% of each other, under a budget of 40M (the level at a time
/// peaks at ~55 MB for L5), and no scratch file is left.
#[test]
#[cfg(target_os = "linux")]
fn depth_first_obj_memory_is_flat_in_the_level() {
    let dir = Scratch::new("depth-first-flat-obj");
    let torus = dir.file("torus.obj", torus_obj(40, 40).as_bytes());
    let torus = torus.to_str().unwrap();
    assert_flat_peaks(&dir, torus, ["4", "5"], "out.obj", 40);
    let names: Vec<String> = std::fs::read_dir(&dir.0)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(!names.iter().any(|n| n.starts_with(".subd-")), "{names:?}");
    let text = std::fs::read_to_string(dir.0.join("out.obj")).unwrap();
    assert_eq!(
        text.lines().filter(|l| l.starts_with("f ")).count(),
        1600 << 10
    );
}

/// What depth-first cannot write, and what PLY or glTF cannot hold, is refused before any
/// work: exit 2, one line naming the input or output and the reason, no file.
#[test]
fn outputs_that_cannot_be_made_are_refused_first() {
    let dir = Scratch::new("depth-first-refused");
    let torus = dir.file("torus.obj", torus_obj(12, 9).as_bytes());
    let torus = torus.to_str().unwrap();
    let cases: [(&str, &[&str], &str); 4] = [
        (
            "a.usda",
            &["--levels", "2", "--depth-first"],
            "PLY (.ply) or OBJ (.obj) only",
        ),
        (
            "b.ply",
            &["--levels", "2", "--depth-first", "--limit"],
            "--limit",
        ),
        ("c.ply", &["--levels", "15"], "32-bit indices"),
        ("d.glb", &["--levels", "11"], "4 GiB"),
    ];
    for (name, args, expect) in cases {
        let out = dir.0.join(name);
        let (code, _, err) = subd(
            &[
                &[
                    "refine",
                    torus,
                    out.to_str().unwrap(),
                    "--scheme",
                    "catmull-clark",
                ],
                args,
            ]
            .concat(),
        );
        assert_eq!(code, 2, "{name}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(expect), "{name}: expected {expect:?} in {err}");
        assert!(!out.exists(), "{name} was written");
        let leftovers = std::fs::read_dir(&dir.0).unwrap().filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .starts_with(".subd-")
        });
        assert_eq!(leftovers.count(), 0, "a temporary file was left");
    }
}
