//! Batch mode: going on past bad files, collisions, progress.

use super::*;

#[test]
fn batch_refine_goes_on_past_a_bad_file_and_matches_single_runs() {
    let s = Scratch::new("batch");
    let input = s.0.join("in");
    std::fs::create_dir_all(input.join("nested")).unwrap();
    for name in ["catmark_cube.obj", "catmark_pyramid.obj"] {
        std::fs::copy(meshes().join(name), input.join(name)).unwrap();
    }
    std::fs::copy(
        meshes().join("catmark_torus.obj"),
        input.join("nested/catmark_torus.obj"),
    )
    .unwrap();
    std::fs::write(input.join("broken.obj"), "v 0 0 0\nf 1 2 3\n").unwrap();
    std::fs::write(input.join("notes.txt"), "not a mesh").unwrap();
    let out_dir = s.0.join("out");
    let batch = |extra: &[&str]| {
        let mut args = vec![
            "refine",
            "--scheme",
            "catmull-clark",
            "--levels",
            "2",
            input.to_str().unwrap(),
            "--out-dir",
            out_dir.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        subd(&args)
    };
    let (code, out, err) = batch(&["--json"]);
    assert_eq!(code, 2, "one file failed: {err}");
    // One JSON line per file (four, the .txt is not a mesh), then the summary.
    let lines: Vec<serde_json::Value> = out
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 5, "{out}");
    let summary = &lines[4]["summary"];
    assert_eq!(
        (
            summary["files"].as_u64(),
            summary["succeeded"].as_u64(),
            summary["failed"].as_u64()
        ),
        (Some(4), Some(3), Some(1)),
        "{out}"
    );
    let failed: Vec<&serde_json::Value> = lines[..4]
        .iter()
        .filter(|l| l.get("error").is_some())
        .collect();
    assert_eq!(failed.len(), 1);
    assert!(failed[0]["input"].as_str().unwrap().ends_with("broken.obj"));
    assert_eq!(failed[0]["code"], 2);
    // Lines come in completion order; each names its input's place in the batch, the
    // inputs sorted by name, once each.
    let mut by_index: Vec<(u64, String)> = lines[..4]
        .iter()
        .map(|l| {
            (
                l["index"].as_u64().unwrap(),
                l["input"].as_str().unwrap().to_string(),
            )
        })
        .collect();
    by_index.sort();
    assert_eq!(
        by_index.iter().map(|x| x.0).collect::<Vec<_>>(),
        [0, 1, 2, 3]
    );
    assert!(by_index.windows(2).all(|w| w[0].1 < w[1].1), "{by_index:?}");
    // The bad file's usual one-line error, and the summary line.
    let broken = input.join("broken.obj");
    let errors: Vec<&str> = err
        .lines()
        .filter(|l| !l.starts_with("subd: warning"))
        .collect();
    assert_eq!(errors.len(), 2, "{err}");
    assert!(
        errors[0].starts_with(&format!("subd: {}", broken.display())),
        "{err}"
    );
    assert!(
        errors[1].contains("refine: 3 of 4 files done, 1 failed"),
        "{err}"
    );
    assert!(!err.contains("panicked"));
    // Outputs are named after the stems; nothing for the bad file, no temporary files.
    assert_eq!(
        file_names(&out_dir),
        [
            "catmark_cube.obj",
            "catmark_pyramid.obj",
            "catmark_torus.obj"
        ]
    );
    // Each output is what a single run writes.
    for (rel, name) in [
        ("catmark_cube.obj", "catmark_cube.obj"),
        ("nested/catmark_torus.obj", "catmark_torus.obj"),
    ] {
        let single = s.0.join(format!("single-{name}"));
        let (code, _, err) = subd(&[
            "refine",
            "--scheme",
            "catmull-clark",
            "--levels",
            "2",
            input.join(rel).to_str().unwrap(),
            single.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
        assert!(std::fs::read(&single).unwrap() == std::fs::read(out_dir.join(name)).unwrap());
    }
    // One file at a time gives the same files; --format picks the extension.
    std::fs::remove_dir_all(&out_dir).unwrap();
    let (code, out, err) = batch(&["--jobs", "1", "--format", "ply"]);
    assert_eq!(code, 2, "{err}");
    assert!(out.is_empty(), "no --json, nothing on stdout: {out}");
    assert_eq!(
        file_names(&out_dir),
        [
            "catmark_cube.ply",
            "catmark_pyramid.ply",
            "catmark_torus.ply"
        ]
    );
    // Without the bad file the batch succeeds, and says so on stderr.
    std::fs::remove_file(&broken).unwrap();
    let (code, _, err) = batch(&[]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("refine: 3 of 3 files done, 0 failed"), "{err}");
}

#[test]
fn batch_refuses_colliding_outputs_and_never_overwrites_inputs() {
    let s = Scratch::new("batch-refuse");
    let (a, b) = (s.0.join("a"), s.0.join("b"));
    for d in [&a, &b] {
        std::fs::create_dir_all(d).unwrap();
        std::fs::copy(meshes().join("loop_cube.obj"), d.join("cube.obj")).unwrap();
    }
    let out_dir = s.0.join("out");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "loop",
        "--levels",
        "1",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--out-dir",
        out_dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("would both write it"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        !out_dir.exists(),
        "nothing is written when the plan is refused"
    );
    // Writing into the input directory in the input's format would replace each input.
    let before = std::fs::read(a.join("cube.obj")).unwrap();
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "loop",
        "--levels",
        "1",
        a.to_str().unwrap(),
        "--out-dir",
        a.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("would overwrite the input"), "{err}");
    assert!(std::fs::read(a.join("cube.obj")).unwrap() == before);
    // Usage errors: three paths without --out-dir; a format refine does not write.
    let (code, _, err) = subd(&[
        "refine", "--scheme", "loop", "--levels", "1", "x.obj", "y.obj", "z.obj",
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("expected IN OUT"), "{err}");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "loop",
        "--levels",
        "1",
        a.to_str().unwrap(),
        "--out-dir",
        out_dir.to_str().unwrap(),
        "--format",
        "txt",
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("does not write it"), "{err}");
}

#[test]
fn batch_limit_pia_and_adaptive() {
    let s = Scratch::new("batch-others");
    let input = s.0.join("in");
    std::fs::create_dir_all(&input).unwrap();
    for name in ["loop_cube.obj", "loop_tetrahedron.obj"] {
        std::fs::copy(meshes().join(name), input.join(name)).unwrap();
    }
    let inp = input.to_str().unwrap();
    let runs: [(&str, Vec<&str>, &str); 3] = [
        ("limit", vec!["--scheme", "loop", "--format", "txt"], "txt"),
        ("pia", vec!["--scheme", "loop"], "obj"),
        (
            "adaptive",
            vec!["--scheme", "loop", "--flatness", "10"],
            "obj",
        ),
    ];
    for (command, options, ext) in runs {
        let out_dir = s.0.join(command);
        let mut args = vec![command];
        args.extend(options);
        args.extend([inp, "--out-dir", out_dir.to_str().unwrap(), "--json"]);
        let (code, out, err) = subd(&args);
        assert_eq!(code, 0, "{command}: {err}");
        let lines: Vec<serde_json::Value> = out
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        assert_eq!(lines.len(), 3, "{command}: {out}");
        assert_eq!(lines[2]["summary"]["succeeded"], 2, "{command}: {out}");
        assert_eq!(
            file_names(&out_dir),
            [
                format!("loop_cube.{ext}"),
                format!("loop_tetrahedron.{ext}")
            ],
            "{command}"
        );
    }
}

#[test]
fn batch_progress_bar_on_a_terminal_draws_and_finishes() {
    let s = Scratch::new("batch-tty");
    let input = s.0.join("in");
    std::fs::create_dir_all(&input).unwrap();
    for name in ["catmark_cube.obj", "catmark_torus.obj"] {
        std::fs::copy(meshes().join(name), input.join(name)).unwrap();
    }
    std::fs::write(input.join("broken.obj"), "v 0 0\n").unwrap();
    let out_dir = s.0.join("out");
    let cmd = format!(
        "{} refine --scheme catmull-clark --levels 5 {} --out-dir {}",
        env!("CARGO_BIN_EXE_subd"),
        input.display(),
        out_dir.display()
    );
    let transcript = s.0.join("transcript.txt");
    let status = Command::new("script")
        .args(["-qec", &cmd, transcript.to_str().unwrap()])
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .status()
        .expect("`script` (util-linux) runs the command on a pseudo-terminal");
    // `script -e` passes on the command's exit code: 2, one file failed.
    assert_eq!(status.code(), Some(2));
    let seen = String::from_utf8_lossy(&std::fs::read(&transcript).unwrap()).into_owned();
    assert!(seen.contains("files"), "the bar counts files: {seen}");
    assert!(
        seen.contains("broken.obj"),
        "the failed file's line: {seen}"
    );
    assert!(
        seen.contains("refine: 2 of 3 files done, 1 failed"),
        "{seen}"
    );
    assert_eq!(
        file_names(&out_dir),
        ["catmark_cube.obj", "catmark_torus.obj"]
    );
}
