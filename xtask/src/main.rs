//! Project automation: `cargo xtask test` runs the whole test suite; `cargo xtask conformance`
//! and `cargo xtask bench` compare subd with the system OpenSubdiv (installing `libosd-dev`
//! when run as root, otherwise saying what to install); `cargo xtask fuzz` runs the fuzz
//! targets.

use std::process::{Command, ExitCode};

use clap::{Parser, Subcommand};

mod adaptive_bench;
mod batch_bench;
mod bench;
mod conformance;
mod editing_bench;
mod fvar_bench;
mod fvar_conformance;
mod geom_conformance;
mod geom_ref;
mod osd;
mod patch_bench;
mod patch_conformance;
mod patch_fvar_conformance;
mod pia_bench;
mod python_tests;
mod random_mesh;
mod refined_limits;
mod row;
mod scaling_bench;
mod split_bench;
mod tess_bench;
mod tess_conformance;
mod usd_bench;
mod usd_conformance;

#[derive(Parser)]
#[command(name = "xtask", about = "subd project automation")]
struct Cli {
    #[command(subcommand)]
    command: Task,
}

#[derive(Subcommand)]
enum Task {
    /// Build once in release mode and run every test of the workspace (unit, integration,
    /// property and doc tests), then the Python package's tests (installed with pip into
    /// `target/python-env`).
    Test {
        /// Extra arguments passed to `cargo test` (after `--`).
        #[arg(last = true)]
        extra: Vec<String>,
    },
    /// Compare subd's refinement with OpenSubdiv's on every shape and on random meshes.
    Conformance {
        /// Directory of OpenSubdiv shapes.
        #[arg(long, default_value = "../shared/meshes/osd")]
        shapes: std::path::PathBuf,
        /// Number of random meshes.
        #[arg(long, default_value_t = 360)]
        random: u64,
        /// Which references: OpenSubdiv, CGAL and OpenMesh, or all.
        #[arg(long, value_enum, default_value = "all")]
        against: Against,
        /// Only the face-varying checks (OpenSubdiv's InterpolateFaceVarying and
        /// LimitFaceVarying).
        #[arg(long)]
        fvar_only: bool,
        /// Only the patch-table checks (OpenSubdiv's RefineAdaptive and PatchTableFactory).
        #[arg(long)]
        patches_only: bool,
        /// Patch tables on this many random meshes (four option sets each, the Catmull-Clark
        /// and Loop ones). Points where OpenSubdiv's adaptive refinement leaves its own
        /// uniform refinement (two Loop meshes of the 360) are compared apart and counted.
        #[arg(long, default_value_t = 360)]
        random_patches: u64,
        /// Face-varying patch tables on the Catmull-Clark and Loop meshes among this many
        /// random meshes (a random UV layout and mode each). Points where OpenSubdiv's
        /// adaptive refinement leaves its own uniform one (two meshes of the 360) are
        /// compared apart and counted.
        #[arg(long, default_value_t = 360)]
        random_fvar_patches: u64,
    },
    /// Time subd against OpenSubdiv on ~100k-face meshes (levels 1..L, 1 and all threads).
    Bench {
        /// Deepest level.
        #[arg(long, default_value_t = 3)]
        levels: usize,
        /// Runs per measurement (the median is reported).
        #[arg(long, default_value_t = 5)]
        repeats: usize,
        /// Refinement, split schemes and face-varying data: rounds of (reference, subd 1
        /// thread, subd all threads) run back to back; times are medians over rounds, ratios
        /// the medians of each round's ratio, so a slow spell of a shared machine hits both
        /// sides of a ratio.
        #[arg(long, default_value_t = 3)]
        rounds: usize,
        /// Run both OpenSubdiv and subd with glibc's transparent-huge-page malloc
        /// (`GLIBC_TUNABLES=glibc.malloc.hugetlb=1`), which removes most page-fault time from
        /// both sides where the kernel allows THP on request.
        #[arg(long)]
        huge_pages: bool,
        /// Run subd with its huge-page advice for large arrays turned off
        /// (`subd_mesh::memory::set_huge_pages(false)`).
        #[arg(long)]
        no_huge_page_advice: bool,
        /// Only the refinement benchmark.
        #[arg(long)]
        refine_only: bool,
        /// The refinement benchmark on open meshes (the bench torus with a band of faces
        /// removed: boundaries, so the general path) instead of the closed tori.
        #[arg(long)]
        open: bool,
        /// Only the evaluation benchmark.
        #[arg(long)]
        eval_only: bool,
        /// Only the GPU benchmark (subd-gpu's stencils on the preferred adapter against the
        /// CPU on all cores, `crates/gpu/examples/gpu_bench.rs`).
        #[arg(long)]
        gpu: bool,
        /// Only the PIA benchmark (solvers on the quad bench mesh, Loop on a scan).
        #[arg(long)]
        pia_only: bool,
        /// Only the adaptive benchmark (seed 002's Table 1, faces for a given accuracy,
        /// speed against uniform refinement).
        #[arg(long)]
        adaptive_only: bool,
        /// Only the editing benchmark (least squares, energy, re-solve; seed 003's
        /// examples).
        #[arg(long)]
        editing_only: bool,
        /// Only the split-scheme benchmark (Doo-Sabin, √3, butterflies against CGAL and
        /// OpenMesh).
        #[arg(long)]
        split_only: bool,
        /// Only the batch-mode benchmark (`subd refine` on 1,000 small and 10 large meshes
        /// against a shell loop of single runs).
        #[arg(long)]
        batch_only: bool,
        /// Only the tessellation benchmark (`subd tessellate` against OpenSubdiv's Bfr).
        #[arg(long)]
        tess_only: bool,
        /// Only the patch-table benchmark (building and evaluating 1M points against
        /// OpenSubdiv's RefineAdaptive + PatchTableFactory and PatchMap + EvaluateBasis).
        #[arg(long)]
        patches_only: bool,
        /// Only the face-varying benchmark (UVs with seams against OpenSubdiv's
        /// InterpolateFaceVarying).
        #[arg(long)]
        fvar_only: bool,
        /// Only the USD benchmark: a 1M-face mesh read and written as .usdc against binary
        /// PLY, and Pixar's USD reading it from Python.
        #[arg(long)]
        usd_only: bool,
        /// Only the Python benchmark: the package's Loop level 3 against trimesh, libigl and
        /// PyMeshLab, conversions included (installs them in `target/python-env`).
        #[arg(long)]
        python_only: bool,
        /// Only the scaling table: every path of the `subd` binary (refine with each kind of
        /// scheme, --limit, UVs, tessellate, adaptive), each phase at 1, 2 and all threads,
        /// OpenSubdiv on one thread beside it.
        #[arg(long)]
        scaling: bool,
        /// The thread counts of --scaling (default 1, 2 and every CPU), e.g. 1,2,4,8,16.
        #[arg(long, value_delimiter = ',')]
        threads: Vec<usize>,
    },
    /// (internal) One subd split-scheme measurement for `bench`, in its own process.
    #[command(hide = true)]
    BenchSplitRun {
        #[arg(long)]
        mesh: std::path::PathBuf,
        #[arg(long)]
        scheme: String,
        #[arg(long)]
        levels: usize,
        #[arg(long)]
        threads: usize,
        #[arg(long)]
        repeats: usize,
    },
    /// (internal) The subd side of the evaluation benchmark, in its own process.
    #[command(hide = true)]
    BenchEval {
        #[arg(long)]
        mesh: std::path::PathBuf,
        #[arg(long)]
        repeats: usize,
    },
    /// (internal) One subd measurement for `bench`, in its own process.
    #[command(hide = true)]
    BenchRun {
        #[arg(long)]
        mesh: std::path::PathBuf,
        #[arg(long)]
        scheme: String,
        #[arg(long)]
        levels: usize,
        #[arg(long)]
        threads: usize,
        #[arg(long)]
        repeats: usize,
        /// Turn off subd's huge-page advice for its large arrays.
        #[arg(long)]
        no_huge_page_advice: bool,
    },
    /// Run each cargo-fuzz target for a while (needs `cargo install cargo-fuzz` and a nightly
    /// toolchain).
    Fuzz {
        /// Seconds per target.
        #[arg(long, default_value_t = 600)]
        seconds: u64,
        /// Only this target.
        #[arg(long)]
        target: Option<String>,
    },
}

/// The references `cargo xtask conformance` compares with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Against {
    Opensubdiv,
    CgalOpenmesh,
    All,
}

/// System packages the reference harnesses (OpenSubdiv, CGAL, OpenMesh) need: (file that proves it is there, Debian
/// package). The unit and integration tests need none.
const REFERENCE_PACKAGES: &[(&str, &str)] = &[
    (
        "/usr/include/opensubdiv/far/topologyRefinerFactory.h",
        "libosd-dev",
    ),
    ("/usr/bin/g++", "g++"),
    (
        "/usr/include/CGAL/Subdivision_method_3/subdivision_methods_3.h",
        "libcgal-dev",
    ),
    (
        "/usr/include/OpenMesh/Tools/Subdivider/Uniform/Sqrt3T.hh",
        "libopenmesh-dev",
    ),
];

/// System packages the tests need: a Vulkan adapter for subd-gpu's tests (Mesa's software
/// driver, lavapipe, where the machine has no GPU).
const TEST_PACKAGES: &[(&str, &str)] = &[(
    "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json",
    "mesa-vulkan-drivers",
)];

fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
        .unwrap_or(false)
}

fn ensure_system_packages(packages: &[(&str, &str)]) -> Result<(), String> {
    let missing: Vec<&str> = packages
        .iter()
        .filter(|(probe, _)| !std::path::Path::new(probe).exists())
        .map(|(_, pkg)| *pkg)
        .collect();
    if missing.is_empty() {
        return Ok(());
    }
    if !is_root() {
        return Err(format!(
            "missing system packages: {}; install them with: sudo apt-get install -y {}",
            missing.join(" "),
            missing.join(" ")
        ));
    }
    run(Command::new("apt-get").arg("update"))?;
    run(Command::new("apt-get")
        .args(["install", "-y"])
        .args(&missing))
}

fn run(cmd: &mut Command) -> Result<(), String> {
    eprintln!("xtask: running {cmd:?}");
    let start = std::time::Instant::now();
    let status = cmd
        .status()
        .map_err(|e| format!("cannot run {cmd:?}: {e}"))?;
    // Where CI's time goes, step by step.
    eprintln!(
        "xtask: {:?} took {:.0} s",
        cmd.get_program(),
        start.elapsed().as_secs_f64()
    );
    if status.success() {
        Ok(())
    } else {
        Err(format!("{cmd:?} failed with {status}"))
    }
}

/// The USD stages Pixar's USD wrote for the conformance rows (`tests/data/usd`).
fn usd_stages() -> std::path::PathBuf {
    workspace_root().join("tests/data/usd")
}

/// The workspace's root directory.
fn workspace_root() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(std::path::Path::to_path_buf)
        .unwrap_or_default()
}

fn cargo() -> Command {
    Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Task::Test { extra } => ensure_system_packages(TEST_PACKAGES)
            .and_then(|_| {
                run(cargo()
                    .args(["test", "--workspace", "--release"])
                    .arg("--")
                    .args(&extra))
            })
            .and_then(|_| python_tests::run_python_tests(&workspace_root())),
        Task::Conformance {
            shapes,
            random,
            against,
            fvar_only,
            patches_only,
            random_patches,
            random_fvar_patches,
        } => ensure_system_packages(REFERENCE_PACKAGES).and_then(|_| {
            let mut rows = Vec::new();
            let patch_rows = |exe: &std::path::Path| -> Result<Vec<_>, String> {
                let mut rows = timed("patch shapes", || patch_conformance::shapes(exe, &shapes))?;
                rows.extend(timed("patch meshes", || {
                    patch_conformance::real_meshes(exe)
                })?);
                rows.extend(timed("patch random", || {
                    patch_conformance::random(exe, random_patches)
                }));
                rows.extend(timed("fvar patch shapes", || {
                    patch_fvar_conformance::shapes(exe, &shapes)
                })?);
                rows.extend(timed("fvar patch random", || {
                    patch_fvar_conformance::random(exe, random_fvar_patches)
                }));
                Ok(rows)
            };
            if patches_only {
                let exe = osd::build_harness()?;
                rows.extend(patch_rows(&exe)?);
            } else if against != Against::CgalOpenmesh {
                let exe = osd::build_harness()?;
                rows.extend(patch_rows(&exe)?);
                if !fvar_only {
                    rows.extend(timed("shapes", || conformance::shapes(&exe, &shapes))?);
                    rows.extend(timed("random", || conformance::random(&exe, random)));
                }
                rows.extend(timed("fvar shapes", || {
                    fvar_conformance::shapes(&exe, &shapes)
                })?);
                rows.extend(timed("fvar random", || {
                    fvar_conformance::random(&exe, random)
                }));
                if !fvar_only {
                    rows.extend(timed("usd", || {
                        usd_conformance::stages(&exe, &usd_stages())
                    })?);
                }
            }
            if against != Against::Opensubdiv && !fvar_only && !patches_only {
                let geom = geom_ref::build_harness()?;
                rows.extend(timed("geom shapes", || {
                    geom_conformance::shapes(&geom, &shapes)
                })?);
                rows.extend(timed("geom random", || {
                    geom_conformance::random(&geom, random)
                }));
            }
            if conformance::report(&rows) {
                Ok(())
            } else {
                Err("conformance failed".into())
            }
        }),
        Task::Bench {
            levels,
            repeats,
            rounds,
            huge_pages,
            no_huge_page_advice,
            refine_only,
            open,
            eval_only,
            gpu,
            pia_only,
            adaptive_only,
            editing_only,
            split_only,
            batch_only,
            tess_only,
            patches_only,
            fvar_only,
            python_only,
            usd_only,
            scaling,
            threads,
        } => {
            let refinement = || {
                bench::run(
                    levels,
                    repeats,
                    rounds.max(1),
                    huge_pages,
                    !no_huge_page_advice,
                    open,
                )
            };
            let split = || split_bench::run(levels, repeats, rounds.max(1));
            let shapes = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                .join("../../shared/meshes/osd");
            let batch = || batch_bench::run_batch(rounds.max(1), &shapes);
            let tess = || tess_bench::run(repeats);
            let fvar = || fvar_bench::run(levels, repeats, rounds.max(1));
            if gpu {
                run(cargo()
                    .args([
                        "run",
                        "--release",
                        "-p",
                        "subd-gpu",
                        "--example",
                        "gpu_bench",
                        "--",
                    ])
                    .args(["100000", &levels.to_string(), &repeats.to_string()]))
            } else if python_only {
                python_tests::run_python_bench(&workspace_root(), repeats)
            } else if usd_only {
                usd_bench::run(&workspace_root(), repeats)
            } else if scaling {
                ensure_system_packages(REFERENCE_PACKAGES)
                    .and_then(|_| scaling_bench::run(repeats, &threads))
            } else if fvar_only {
                ensure_system_packages(REFERENCE_PACKAGES).and_then(|_| fvar())
            } else if tess_only {
                ensure_system_packages(REFERENCE_PACKAGES).and_then(|_| tess())
            } else if patches_only {
                ensure_system_packages(REFERENCE_PACKAGES).and_then(|_| patch_bench::run(repeats))
            } else if batch_only {
                batch()
            } else if split_only {
                ensure_system_packages(REFERENCE_PACKAGES).and_then(|_| split())
            } else if pia_only {
                pia_bench::run(repeats)
            } else if editing_only {
                editing_bench::run(repeats)
            } else if adaptive_only {
                ensure_system_packages(REFERENCE_PACKAGES)
                    .and_then(|_| adaptive_bench::run(repeats))
            } else if refine_only {
                ensure_system_packages(REFERENCE_PACKAGES).and_then(|_| refinement())
            } else {
                ensure_system_packages(REFERENCE_PACKAGES)
                    .and_then(|_| if eval_only { Ok(()) } else { refinement() })
                    .and_then(|_| bench::run_eval(repeats))
                    .and_then(|_| {
                        if eval_only {
                            Ok(())
                        } else {
                            pia_bench::run(repeats)
                                .and_then(|_| adaptive_bench::run(repeats))
                                .and_then(|_| editing_bench::run(repeats))
                                .and_then(|_| split())
                                .and_then(|_| batch())
                                .and_then(|_| tess())
                                .and_then(|_| fvar())
                                .and_then(|_| usd_bench::run(&workspace_root(), repeats))
                        }
                    })
            }
        }
        Task::BenchEval { mesh, repeats } => bench::run_subd_eval(&mesh, repeats),
        Task::BenchSplitRun {
            mesh,
            scheme,
            levels,
            threads,
            repeats,
        } => split_bench::run_subd(&mesh, &scheme, levels, threads, repeats),
        Task::BenchRun {
            mesh,
            scheme,
            levels,
            threads,
            repeats,
            no_huge_page_advice,
        } => {
            subd_mesh::memory::set_huge_pages(!no_huge_page_advice);
            let scheme = if scheme == "loop" {
                subd_schemes::Scheme::Loop
            } else {
                subd_schemes::Scheme::CatmullClark
            };
            bench::run_subd(&mesh, &scheme, levels, threads, repeats)
        }
        Task::Fuzz { seconds, target } => {
            let targets = match target {
                Some(t) => vec![t],
                None => vec![
                    "obj_topology".to_string(),
                    "ply".to_string(),
                    "edit_constraints".to_string(),
                    "gltf".to_string(),
                    "usd".to_string(),
                ],
            };
            targets.iter().try_for_each(|t| {
                // `$CARGO` is the toolchain's own cargo, which takes no `+nightly`: go
                // through rustup.
                run(Command::new("rustup").args([
                    "run",
                    "nightly",
                    "cargo",
                    "fuzz",
                    "run",
                    t,
                    "--",
                    &format!("-max_total_time={seconds}"),
                ]))
            })
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask: {e}");
            ExitCode::FAILURE
        }
    }
}

/// `f()`, with the seconds it took on stderr (to see where CI's budget goes).
fn timed<T>(what: &str, f: impl FnOnce() -> T) -> T {
    let start = std::time::Instant::now();
    let out = f();
    eprintln!(
        "xtask: conformance {what} took {:.0} s",
        start.elapsed().as_secs_f64()
    );
    out
}
