//! `cargo xtask bench --scaling`: how each path of the `subd` binary scales with threads.
//! Every job runs the binary with `--json` at 1, 2 and all threads (or the counts given with
//! `--threads`), `RAYON_NUM_THREADS` set per run, and prints the medians of the phases its
//! report names (read, topology, positions, write, ...); beside the refinement,
//! face-varying and tessellation jobs, OpenSubdiv's time for the same work on one thread
//! (no file I/O: `TopologyRefinerFactory` + `RefineUniform` + `Interpolate`, the
//! face-varying channel with `InterpolateFaceVarying`, or Bfr's tessellation).
//!
//! The meshes are the bench tori of `cargo xtask bench` and an open mesh (the bench torus
//! with a band of faces removed, so refinement takes the general path), written once under
//! `target/xtask/bench/scaling`.

use std::path::{Path, PathBuf};
use std::process::Command;

use subd_mesh::Mesh;
use subd_mesh::fvar::FVarLinearInterpolation;
use subd_schemes::{Options, Scheme};

use crate::bench::{json_number, median};
use crate::meshes::{open_quad_bench_mesh, quad_bench_mesh, split_quads};
use crate::oracles::osd;

/// One command line of the table.
struct Job {
    /// What the row is.
    title: &'static str,
    /// The input, one of [`Inputs`].
    input: PathBuf,
    /// Output file extension.
    output: &'static str,
    /// Arguments before the input and output.
    args: Vec<&'static str>,
    /// OpenSubdiv's one-thread reference: harness arguments and input.
    reference: Option<Reference>,
}

/// OpenSubdiv's side of a job: the harness input and its arguments; `key` names the time.
struct Reference {
    input: Vec<u8>,
    args: Vec<String>,
    keys: &'static [&'static str],
}

/// The meshes the jobs read.
struct Inputs {
    quads: Mesh,
    triangles: Mesh,
    open: Mesh,
    quads_path: PathBuf,
    triangles_path: PathBuf,
    open_path: PathBuf,
    uv_path: PathBuf,
}

impl Inputs {
    fn write(dir: &Path) -> Result<Inputs, String> {
        let quads = quad_bench_mesh();
        let triangles = split_quads(&quads);
        let open = split_quads(&open_quad_bench_mesh()?);
        let mut with_uv = quads.clone();
        with_uv.fvar = vec![crate::bench::fvar::torus_uv(&quads)];
        let path = |name: &str| dir.join(name);
        let write = |m: &Mesh, p: &Path| {
            subd_io::write_mesh(p, m, &subd_io::WriteOptions::default()).map_err(|e| e.to_string())
        };
        write(&quads, &path("quads.obj"))?;
        write(&triangles, &path("triangles.obj"))?;
        write(&open, &path("open.obj"))?;
        write(&with_uv, &path("uv.obj"))?;
        Ok(Inputs {
            quads,
            triangles,
            open,
            quads_path: path("quads.obj"),
            triangles_path: path("triangles.obj"),
            open_path: path("open.obj"),
            uv_path: path("uv.obj"),
        })
    }
}

/// OpenSubdiv refining `mesh` to `level` (topology + points), `repeats` runs.
fn refinement_reference(mesh: &Mesh, scheme: &Scheme, level: u32, repeats: usize) -> Reference {
    Reference {
        input: osd::encode(
            &mesh.topology,
            &mesh.positions,
            scheme,
            &Options::default(),
            level,
        ),
        args: vec!["--bench".into(), repeats.to_string()],
        keys: &["seconds"],
    }
}

fn jobs(inputs: &Inputs, repeats: usize) -> Vec<Job> {
    let refine = |title, input: &PathBuf, args: Vec<&'static str>, reference| Job {
        title,
        input: input.clone(),
        output: "ply",
        args: [vec!["refine"], args].concat(),
        reference,
    };
    let (cc, lp) = (Scheme::CatmullClark, Scheme::Loop);
    let uv = &inputs.quads;
    let channel = crate::bench::fvar::torus_uv(uv);
    let fvar = osd::encode_fvar(
        osd::encode(&uv.topology, &uv.positions, &cc, &Options::default(), 2),
        channel.values(),
        channel.indices(),
    );
    let plus1 = FVarLinearInterpolation::CornersPlus1
        .to_shape_tag()
        .to_string();
    vec![
        refine(
            "refine catmull-clark L3 (closed quads)",
            &inputs.quads_path,
            vec!["--scheme", "catmull-clark", "--levels", "3"],
            Some(refinement_reference(&inputs.quads, &cc, 3, repeats)),
        ),
        refine(
            "refine loop L3 (closed triangles)",
            &inputs.triangles_path,
            vec!["--scheme", "loop", "--levels", "3"],
            Some(refinement_reference(&inputs.triangles, &lp, 3, repeats)),
        ),
        refine(
            "refine loop L3 (open: the general path)",
            &inputs.open_path,
            vec!["--scheme", "loop", "--levels", "3"],
            Some(refinement_reference(&inputs.open, &lp, 3, repeats)),
        ),
        refine(
            "refine catmull-clark L2 --limit",
            &inputs.quads_path,
            vec!["--scheme", "catmull-clark", "--levels", "2", "--limit"],
            None,
        ),
        refine(
            "refine sqrt3 L2",
            &inputs.triangles_path,
            vec!["--scheme", "sqrt3", "--levels", "2"],
            None,
        ),
        refine(
            "refine doo-sabin L2",
            &inputs.quads_path,
            vec!["--scheme", "doo-sabin", "--levels", "2"],
            None,
        ),
        Job {
            output: "obj",
            ..refine(
                "refine catmull-clark L2 with UVs (face-varying, corners-plus1)",
                &inputs.uv_path,
                vec!["--scheme", "catmull-clark", "--levels", "2"],
                Some(Reference {
                    input: fvar,
                    args: vec!["--fvar-bench".into(), plus1, repeats.to_string()],
                    keys: &["topology_seconds", "fvar_seconds"],
                }),
            )
        },
        Job {
            title: "tessellate catmull-clark rate 8",
            input: inputs.quads_path.clone(),
            output: "ply",
            args: vec!["tessellate", "--scheme", "catmull-clark", "--rate", "8"],
            reference: Some(Reference {
                input: osd::encode(&uv.topology, &uv.positions, &cc, &Options::default(), 0),
                args: vec!["--bfr-bench".into(), "8".into(), repeats.to_string()],
                keys: &["seconds"],
            }),
        },
        Job {
            title: "adaptive loop --flatness 8 --levels 3 (open)",
            input: inputs.open_path.clone(),
            output: "ply",
            args: vec![
                "adaptive",
                "--scheme",
                "loop",
                "--flatness",
                "8",
                "--levels",
                "3",
            ],
            reference: None,
        },
    ]
}

/// The phases of one run's JSON report, in the report's order: the numbers of its
/// `"seconds"` object.
fn phases(report: &str) -> Result<Vec<(String, f64)>, String> {
    let start = report
        .find("\"seconds\":{")
        .ok_or("no seconds in the report")?
        + 11;
    let end = start + report[start..].find('}').ok_or("unterminated seconds")?;
    report[start..end]
        .split(',')
        .map(|kv| {
            let (k, v) = kv.split_once(':').ok_or("bad seconds entry")?;
            let v: f64 = v.trim().parse().map_err(|_| format!("bad number {v}"))?;
            Ok((k.trim().trim_matches('"').to_string(), v))
        })
        .collect()
}

/// Medians of each phase of `job` over `repeats` runs on `threads` threads.
fn measure(
    subd: &Path,
    job: &Job,
    dir: &Path,
    threads: usize,
    repeats: usize,
) -> Result<Vec<(String, f64)>, String> {
    let out = dir.join(format!("out.{}", job.output));
    let mut runs = Vec::with_capacity(repeats);
    for _ in 0..repeats {
        let _ = std::fs::remove_file(&out);
        let o = Command::new(subd)
            .args(&job.args)
            .arg(&job.input)
            .arg(&out)
            .arg("--json")
            .env("RAYON_NUM_THREADS", threads.to_string())
            .output()
            .map_err(|e| e.to_string())?;
        if !o.status.success() {
            return Err(format!(
                "{}: {}",
                job.title,
                String::from_utf8_lossy(&o.stderr)
            ));
        }
        runs.push(phases(&String::from_utf8_lossy(&o.stdout))?);
    }
    let _ = std::fs::remove_file(&out);
    let names: Vec<String> = runs[0].iter().map(|(k, _)| k.clone()).collect();
    Ok(names
        .iter()
        .enumerate()
        .map(|(i, k)| (k.clone(), median(runs.iter().map(|r| r[i].1).collect())))
        .collect())
}

/// OpenSubdiv's time for a job's reference: the sum of its keys.
fn reference_seconds(exe: &Path, r: &Reference) -> Result<f64, String> {
    let args: Vec<&str> = r.args.iter().map(String::as_str).collect();
    let out = osd::run(exe, &r.input, &args)?;
    let line = String::from_utf8_lossy(&out);
    r.keys
        .iter()
        .map(|k| json_number(&line, k).ok_or(format!("OpenSubdiv: no {k}")))
        .sum()
}

/// Thread counts: the given list, or 1, 2 and every CPU.
fn thread_counts(given: &[usize]) -> Vec<usize> {
    if !given.is_empty() {
        return given.to_vec();
    }
    let all = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut t = vec![1, 2, all];
    t.dedup();
    t.retain(|&n| n <= all.max(2));
    t
}

/// Runs every job and prints one table per job.
pub fn run(repeats: usize, threads: &[usize]) -> Result<(), String> {
    let subd = crate::bench::batch::subd_binary()?;
    let exe = osd::build_harness()?;
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/xtask/bench/scaling");
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let inputs = Inputs::write(&dir)?;
    println!(
        "subd phases by thread count (RAYON_NUM_THREADS), medians of {repeats} runs of the binary with --json; OpenSubdiv: 1 thread, library time (no file I/O)"
    );
    for job in jobs(&inputs, repeats) {
        let reference = match &job.reference {
            Some(r) => format!("{:.4} s", reference_seconds(&exe, r)?),
            None => "—".to_string(),
        };
        println!(
            "\n{}: {}; OpenSubdiv {reference}",
            job.title,
            job.input.display()
        );
        let mut header = false;
        for &t in &thread_counts(threads) {
            let p = measure(&subd, &job, &dir, t, repeats)?;
            if !header {
                let names: Vec<String> = p.iter().map(|(k, _)| format!("{k:>11}")).collect();
                println!("{:>8}{}", "threads", names.join(""));
                header = true;
            }
            let values: Vec<String> = p.iter().map(|(_, v)| format!("{v:>11.4}")).collect();
            println!("{t:>8}{}", values.join(""));
        }
    }
    Ok(())
}
