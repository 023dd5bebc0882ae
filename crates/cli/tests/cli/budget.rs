//! The memory budget: refusals, not aborts.

use super::*;

#[test]
fn requests_over_the_memory_budget_are_refused_not_aborted() {
    let s = Scratch::new("budget");
    let torus =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/meshes/torus_creased.obj");
    let torus = torus.to_str().unwrap();
    let out = s.0.join("out.obj");
    // --max-memory: the estimate, the budget and the deepest level that fits, before any work.
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "catmull-clark",
        "--levels",
        "6",
        "--max-memory",
        "30M",
        torus,
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.starts_with(&format!("subd: {torus}: refining 6 levels needs about "))
            && err.contains("over the budget of 30.0 MiB (--max-memory); --levels 5 fits"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!out.exists());
    // The level it names does fit.
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "catmull-clark",
        "--levels",
        "5",
        "--max-memory",
        "30M",
        torus,
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    std::fs::remove_file(&out).unwrap();

    // Under an address-space limit (`ulimit -v`, 1 GiB): the CLI's estimate refuses a cube
    // to 12 levels (100 M faces)...
    let cube = meshes().join("catmark_cube.obj");
    let limited = |extra: &str| {
        let script = format!(
            "ulimit -v 1048576; exec \"$0\" refine --scheme catmull-clark --levels 12 {extra} \"$1\" \"$2\""
        );
        let o = Command::new("bash")
            .args(["-c", &script, env!("CARGO_BIN_EXE_subd")])
            .arg(&cube)
            .arg(&out)
            .output()
            .unwrap();
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let (code, err) = limited("");
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("(the address-space limit, ulimit -v)"),
        "{err}"
    );
    // ...and with the estimate overridden, the library refuses the level it cannot allocate
    // with a typed error: one line, exit 2, no abort, no partial file.
    let (code, err) = limited("--max-memory 1T");
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("more memory, which cannot be allocated"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!err.contains("memory allocation of"), "{err}");
    assert!(!out.exists());

    // In a batch, a file over the budget fails alone.
    let input = s.0.join("in");
    std::fs::create_dir_all(&input).unwrap();
    std::fs::copy(&cube, input.join("cube.obj")).unwrap();
    std::fs::copy(torus, input.join("torus.obj")).unwrap();
    let out_dir = s.0.join("out");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "catmull-clark",
        "--levels",
        "6",
        "--max-memory",
        "60M",
        "--jobs",
        "2",
        input.to_str().unwrap(),
        "--out-dir",
        out_dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("torus.obj: refining 6 levels"), "{err}");
    assert!(err.contains("refine: 1 of 2 files done, 1 failed"), "{err}");
    assert_eq!(file_names(&out_dir), ["cube.obj"]);
}
