//! `cargo xtask bench`: subd and OpenSubdiv side by side on the same meshes in one run.
//!
//! Each measurement runs in its own process (the OpenSubdiv harness, or `xtask bench-run`
//! for subd) so that peak memory is that of the work alone. Times are medians of repeated
//! runs: topology refinement + stencils + positions for subd, topology refinement + primvar
//! interpolation for OpenSubdiv (double precision, default uniform options).

pub mod adaptive;
pub mod batch;
pub mod editing;
pub mod fvar;
pub mod patch;
pub mod pia;
pub mod scaling;
pub mod split;
pub mod tess;
pub mod usd;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use subd_mesh::{Mesh, TopologyBuilder};
use subd_schemes::{Options, Refinement, Scheme};

use crate::meshes::{open_quad_bench_mesh, quad_bench_mesh, split_quads, tri_bench_mesh};
use crate::oracles::osd;

pub(crate) fn peak_rss_bytes() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<u64>().ok())
        })
        .map_or(0, |kb| kb * 1024)
}

/// CPU time (user + system, all threads) this process has used so far: beside wall time on
/// a shared machine, where other work stretches the wall clock but not this.
#[allow(unsafe_code)]
pub(crate) fn cpu_seconds() -> f64 {
    // SAFETY: `getrusage` only writes the `rusage` it is given.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: a valid pointer to a `rusage`; RUSAGE_SELF is always a valid target.
    if unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) } != 0 {
        return 0.0;
    }
    let t = |v: libc::timeval| v.tv_sec as f64 + v.tv_usec as f64 * 1e-6;
    t(u.ru_utime) + t(u.ru_stime)
}

pub(crate) fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The subd side, run in a child process: from `mesh`'s face lists, build the base topology
/// and refine it to `levels` with `threads` threads, `repeats` times, and print one JSON
/// line.
pub fn run_subd(
    mesh: &Path,
    scheme: &Scheme,
    levels: usize,
    threads: usize,
    repeats: usize,
) -> Result<(), String> {
    let file =
        subd_io::read_mesh(mesh, &subd_io::ReadOptions::default()).map_err(|e| e.to_string())?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| e.to_string())?;
    let (base, pos) = (&file.mesh.topology, &file.mesh.positions);
    // The face lists as OpenSubdiv's side gets them: its timing starts with
    // `TopologyRefinerFactory::Create`, which builds the base topology from them, so this
    // side's starts with `TopologyBuilder::build`.
    let sizes: Vec<u32> = (0..base.num_faces())
        .map(|f| base.face_size(f) as u32)
        .collect();
    let (mut total, mut refine, mut points) = (Vec::new(), Vec::new(), Vec::new());
    let mut cpu = Vec::new();
    let mut check = 0.0;
    for _ in 0..repeats {
        pool.install(|| {
            let c0 = cpu_seconds();
            let t0 = Instant::now();
            let topo = TopologyBuilder::new(base.num_vertices())
                .build(&sizes, base.all_face_vertices())
                .expect("valid base");
            let r = Refinement::new(&topo, scheme.clone(), &Options::default(), levels)
                .expect("refine");
            let t1 = Instant::now();
            let p = r.refine_points(pos);
            let t2 = Instant::now();
            cpu.push(cpu_seconds() - c0);
            check += p[levels].len() as f64;
            refine.push((t1 - t0).as_secs_f64());
            points.push((t2 - t1).as_secs_f64());
            total.push((t2 - t0).as_secs_f64());
        });
    }
    println!(
        "{{\"seconds\": {:.9}, \"topology_seconds\": {:.9}, \"primvar_seconds\": {:.9}, \"cpu_seconds\": {:.9}, \"peak_rss_bytes\": {}, \"vertices\": {}}}",
        median(total),
        median(refine),
        median(points),
        median(cpu),
        peak_rss_bytes(),
        check / repeats as f64
    );
    Ok(())
}

pub(crate) fn json_number(line: &str, key: &str) -> Option<f64> {
    let k = format!("\"{key}\":");
    let rest = &line[line.find(&k)? + k.len()..];
    let end = rest.find([',', '}']).unwrap_or(rest.len());
    rest[..end].trim().parse().ok()
}

struct Measure {
    seconds: f64,
    peak: f64,
}

fn measure(cmd: &mut Command, huge_pages: bool) -> Result<Measure, String> {
    if huge_pages {
        cmd.env("GLIBC_TUNABLES", "glibc.malloc.hugetlb=1");
    }
    let out = cmd.output().map_err(|e| e.to_string())?;
    if !out.status.success() {
        return Err(String::from_utf8_lossy(&out.stderr).to_string());
    }
    let line = String::from_utf8_lossy(&out.stdout).to_string();
    Ok(Measure {
        seconds: json_number(&line, "seconds").ok_or("no seconds")?,
        peak: json_number(&line, "peak_rss_bytes").ok_or("no peak")? / (1024.0 * 1024.0),
    })
}

/// Runs the whole comparison and prints the table; with `huge_pages` both sides run under
/// the same transparent-huge-page malloc setting; `advice` is subd's own huge-page advice
/// for its large arrays (on by default in the library). Each level is measured in `rounds`
/// back-to-back rounds of OpenSubdiv, subd on one thread and subd on all threads; the table
/// shows medians over rounds, and each ratio is the median of the rounds' ratios. With
/// `open` the meshes are the open ones ([`open_quad_bench_mesh`], triangulated for Loop),
/// which take the general path.
pub fn run(
    levels: usize,
    repeats: usize,
    rounds: usize,
    huge_pages: bool,
    advice: bool,
    open: bool,
) -> Result<(), String> {
    let exe = osd::build_harness()?;
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/xtask/bench");
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let me = std::env::current_exe().map_err(|e| e.to_string())?;
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    print_header(rounds, repeats, huge_pages, advice, open, threads);
    let meshes = if open {
        let quads = open_quad_bench_mesh()?;
        let tris = split_quads(&quads);
        [(Scheme::CatmullClark, quads), (Scheme::Loop, tris)]
    } else {
        [
            (Scheme::CatmullClark, quad_bench_mesh()),
            (Scheme::Loop, tri_bench_mesh()),
        ]
    };
    let sides = Sides {
        exe: &exe,
        me: &me,
        repeats,
        huge_pages,
        advice,
    };
    for (scheme, mesh) in meshes {
        let name = if scheme == Scheme::Loop {
            "loop"
        } else {
            "catmark"
        };
        let file = if open {
            format!("{name}_open")
        } else {
            name.to_string()
        };
        let path = dir.join(format!("{file}.obj"));
        subd_io::write_mesh(&path, &mesh, &subd_io::WriteOptions::default())
            .map_err(|e| e.to_string())?;
        for level in 1..=levels {
            let input = osd::encode(
                &mesh.topology,
                &mesh.positions,
                &scheme,
                &Options::default(),
                level as u32,
            );
            let input_path = dir.join(format!("{file}_{level}.bin"));
            std::fs::write(&input_path, &input).map_err(|e| e.to_string())?;
            let mut runs = Vec::with_capacity(rounds);
            for _ in 0..rounds {
                runs.push([
                    sides.osd(&input_path)?,
                    sides.subd(&path, name, level, 1)?,
                    sides.subd(&path, name, level, threads)?,
                ]);
            }
            print_row(name, &scheme, &mesh, level, &runs);
        }
    }
    Ok(())
}

/// The table's opening lines (the setup, the huge-page settings, the meshes) and column
/// names.
fn print_header(
    rounds: usize,
    repeats: usize,
    huge_pages: bool,
    advice: bool,
    open: bool,
    threads: usize,
) {
    println!(
        "subd vs OpenSubdiv 3.5 (Far, double), uniform refinement; {rounds} rounds of (OpenSubdiv, subd 1 thread, subd all threads) back to back, each the median of {repeats} runs; times: median over rounds; ratio = subd time / OpenSubdiv time, median of the rounds' ratios{}",
        if huge_pages {
            "; both with GLIBC_TUNABLES=glibc.malloc.hugetlb=1"
        } else {
            ""
        }
    );
    println!(
        "subd's huge-page advice for its large arrays: {}",
        if advice { "on (default)" } else { "off" }
    );
    if open {
        println!(
            "meshes: the bench tori with a band of faces removed (boundaries: the general path)"
        );
    }
    println!(
        "{:<8} {:>8} {:>5} {:>10} {:>10} {:>10} {:>7} {:>10} {:>7} {:>9} {:>9}",
        "scheme",
        "faces",
        "level",
        "out faces",
        "osd s",
        "subd 1T s",
        "ratio",
        format!("subd {threads}T s"),
        "ratio",
        "osd MB",
        "subd MB"
    );
}

/// The two sides of a refinement measurement, each in its own process: the OpenSubdiv
/// harness and `xtask bench-run`.
struct Sides<'a> {
    exe: &'a Path,
    me: &'a Path,
    repeats: usize,
    huge_pages: bool,
    advice: bool,
}

impl Sides<'_> {
    /// OpenSubdiv on the encoded input at `input_path`.
    fn osd(&self, input_path: &Path) -> Result<Measure, String> {
        measure(
            Command::new(self.exe)
                .args(["--bench", &self.repeats.to_string()])
                .stdin(std::fs::File::open(input_path).map_err(|e| e.to_string())?),
            self.huge_pages,
        )
    }

    /// subd on `threads` threads, the mesh at `path` with the scheme `name` to `level`.
    fn subd(
        &self,
        path: &Path,
        name: &str,
        level: usize,
        threads: usize,
    ) -> Result<Measure, String> {
        measure(
            Command::new(self.me)
                .args([
                    "bench-run",
                    "--mesh",
                    path.to_str().unwrap(),
                    "--scheme",
                    name,
                    "--levels",
                    &level.to_string(),
                    "--threads",
                    &threads.to_string(),
                    "--repeats",
                    &self.repeats.to_string(),
                ])
                .args((!self.advice).then_some("--no-huge-page-advice")),
            self.huge_pages,
        )
    }
}

/// One row: medians over the rounds `runs` (OpenSubdiv, subd on one thread, subd on all),
/// the ratios the medians of the rounds' ratios, peak memories over the rounds.
fn print_row(name: &str, scheme: &Scheme, mesh: &Mesh, level: usize, runs: &[[Measure; 3]]) {
    let med = |f: &dyn Fn(&[Measure; 3]) -> f64| median(runs.iter().map(f).collect());
    let peak = |k: usize| runs.iter().map(|r| r[k].peak).fold(0.0, f64::max);
    let out_faces = mesh.topology.num_face_vertices()
        * 4usize.pow(level as u32 - 1)
        * if *scheme == Scheme::Loop { 4 } else { 1 }
        / if *scheme == Scheme::Loop { 3 } else { 1 };
    println!(
        "{:<8} {:>8} {:>5} {:>10} {:>10.4} {:>10.4} {:>7.2} {:>10.4} {:>7.2} {:>9.0} {:>9.0}",
        name,
        mesh.topology.num_faces(),
        level,
        out_faces,
        med(&|r| r[0].seconds),
        med(&|r| r[1].seconds),
        med(&|r| r[1].seconds / r[0].seconds),
        med(&|r| r[2].seconds),
        med(&|r| r[2].seconds / r[0].seconds),
        peak(0),
        peak(1).max(peak(2))
    );
}

/// Points evaluated by the evaluation benchmark.
pub const EVAL_POINTS: usize = 100_000;

/// `count` pseudo-random (face, u, v) on a quad mesh with `faces` faces (a fixed LCG, so
/// both processes draw the same points).
pub fn eval_points(faces: usize, count: usize) -> Vec<(u32, f64, f64)> {
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut next = || {
        x = x
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (x >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..count)
        .map(|_| {
            let f = ((next() * faces as f64) as usize).min(faces - 1) as u32;
            (f, next(), next())
        })
        .collect()
}

/// The subd side of the evaluation benchmark, in its own process: setup (evaluator and
/// control points) once, then the median over `repeats` of evaluating every point with
/// derivatives on one thread; prints one JSON line.
pub fn run_subd_eval(mesh: &Path, repeats: usize) -> Result<(), String> {
    use subd_limit::eval::{FaceParam, LimitEvaluator};
    let file =
        subd_io::read_mesh(mesh, &subd_io::ReadOptions::default()).map_err(|e| e.to_string())?;
    let (topo, pos) = (&file.mesh.topology, &file.mesh.positions);
    let t0 = Instant::now();
    let ev = LimitEvaluator::new(topo, &Scheme::CatmullClark, &Options::default())
        .map_err(|e| e.to_string())?;
    let pts = ev.prepare(pos);
    let setup = t0.elapsed().as_secs_f64();
    let points = eval_points(topo.num_faces(), EVAL_POINTS);
    let mut times = Vec::new();
    let mut check = 0.0;
    for _ in 0..repeats {
        let t = Instant::now();
        for &(face, u, v) in &points {
            let at = FaceParam {
                face: face as usize,
                sub: 0,
                u,
                v,
            };
            let p = ev.evaluate(&pts, at).map_err(|e| e.to_string())?;
            check += p.position.x + p.du.y;
        }
        times.push(t.elapsed().as_secs_f64());
    }
    println!(
        "{{\"setup_seconds\": {setup:.9}, \"seconds\": {:.9}, \"points\": {}, \"check\": {check:.6}}}",
        median(times),
        points.len()
    );
    Ok(())
}

/// Evaluation throughput against OpenSubdiv's PatchTable + PatchMap on the quad bench mesh.
pub fn run_eval(repeats: usize) -> Result<(), String> {
    let exe = osd::build_harness()?;
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/xtask/bench");
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let me = std::env::current_exe().map_err(|e| e.to_string())?;
    let mesh = quad_bench_mesh();
    let path = dir.join("catmark.obj");
    subd_io::write_mesh(&path, &mesh, &subd_io::WriteOptions::default())
        .map_err(|e| e.to_string())?;
    let points = eval_points(mesh.topology.num_faces(), EVAL_POINTS);
    let input = osd::encode_eval_points(
        osd::encode(
            &mesh.topology,
            &mesh.positions,
            &Scheme::CatmullClark,
            &Options::default(),
            10,
        ),
        &points,
    );
    let run = |cmd: &mut Command| -> Result<(f64, f64), String> {
        let out = cmd.output().map_err(|e| e.to_string())?;
        if !out.status.success() {
            return Err(String::from_utf8_lossy(&out.stderr).to_string());
        }
        let line = String::from_utf8_lossy(&out.stdout).to_string();
        Ok((
            json_number(&line, "setup_seconds").ok_or("no setup time")?,
            json_number(&line, "seconds").ok_or("no time")?,
        ))
    };
    let input_path = dir.join("catmark_eval.bin");
    std::fs::write(&input_path, &input).map_err(|e| e.to_string())?;
    let (osd_setup, osd_eval) = run(Command::new(&exe)
        .args(["--eval-bench", &repeats.to_string()])
        .stdin(std::fs::File::open(&input_path).map_err(|e| e.to_string())?))?;
    let (subd_setup, subd_eval) = run(Command::new(&me).args([
        "bench-eval",
        "--mesh",
        path.to_str().unwrap(),
        "--repeats",
        &repeats.to_string(),
    ]))?;
    println!();
    println!(
        "Exact evaluation vs OpenSubdiv's PatchTable + PatchMap (isolation 10, Gregory end caps), {} random (face, u, v) with first and second derivatives, 1 thread, median of {repeats} passes",
        points.len()
    );
    println!(
        "{:<8} {:>8} {:>12} {:>12} {:>12} {:>12} {:>7} {:>12} {:>12}",
        "scheme",
        "faces",
        "osd pts/s",
        "subd pts/s",
        "osd eval s",
        "subd eval s",
        "ratio",
        "osd setup s",
        "subd setup s"
    );
    let n = points.len() as f64;
    println!(
        "{:<8} {:>8} {:>12.0} {:>12.0} {:>12.4} {:>12.4} {:>7.2} {:>12.4} {:>12.4}",
        "catmark",
        mesh.topology.num_faces(),
        n / osd_eval,
        n / subd_eval,
        osd_eval,
        subd_eval,
        subd_eval / osd_eval,
        osd_setup,
        subd_setup
    );
    Ok(())
}
