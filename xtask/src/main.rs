//! Project automation: `cargo xtask test` runs the whole test suite; `cargo xtask conformance`
//! and `cargo xtask bench` compare subd with the system OpenSubdiv (installing `libosd-dev`
//! when run as root, otherwise saying what to install); `cargo xtask fuzz` runs the fuzz
//! targets.

use std::process::{Command, ExitCode};

use system::{
    REFERENCE_PACKAGES, TEST_PACKAGES, cargo, ensure_system_packages, run, usd_stages,
    workspace_root,
};

use clap::{Parser, Subcommand};

mod bench;
mod conformance;
mod lint;
mod meshes;
mod oracles;
mod python_tests;
mod system;

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
    Conformance(ConformanceArgs),
    /// Time subd against OpenSubdiv on ~100k-face meshes (levels 1..L, 1 and all threads).
    Bench(BenchArgs),
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
    /// Check the house rules that rustfmt and clippy do not: no function over 100 lines in
    /// `crates/*/src` or `xtask/src`, no file over 1,000 lines in `crates/*/src`, no circle
    /// of modules inside a crate.
    Lint,
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

/// The flags of `cargo xtask conformance`.
#[derive(clap::Args)]
struct ConformanceArgs {
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
    /// Print the table of checks run on every mesh (what each samples, what subd computes,
    /// what it is compared with) and exit.
    #[arg(long)]
    list: bool,
}

/// The flags of `cargo xtask bench`.
#[derive(clap::Args)]
struct BenchArgs {
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
    /// Only the adaptive benchmark (Sun et al.'s Table 1, faces for a given accuracy,
    /// speed against uniform refinement).
    #[arg(long)]
    adaptive_only: bool,
    /// Only the editing benchmark (least squares, energy, re-solve; Li et al.'s
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
}

/// The references `cargo xtask conformance` compares with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Against {
    Opensubdiv,
    CgalOpenmesh,
    All,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Task::Test { extra } => test_task(&extra),
        Task::Conformance(args) if args.list => {
            print!("{}", conformance::describe());
            Ok(())
        }
        Task::Conformance(args) => {
            ensure_system_packages(REFERENCE_PACKAGES).and_then(|_| conformance_task(&args))
        }
        Task::Bench(args) => bench_task(&args),
        Task::BenchEval { mesh, repeats } => bench::run_subd_eval(&mesh, repeats),
        Task::BenchSplitRun {
            mesh,
            scheme,
            levels,
            threads,
            repeats,
        } => bench::split::run_subd(&mesh, &scheme, levels, threads, repeats),
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
        Task::Lint => lint::run(&workspace_root()),
        Task::Fuzz { seconds, target } => fuzz_task(seconds, target),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask: {e}");
            ExitCode::FAILURE
        }
    }
}

/// `cargo xtask test`: the workspace's tests in release mode, then the Python package's.
fn test_task(extra: &[String]) -> Result<(), String> {
    ensure_system_packages(TEST_PACKAGES)
        .and_then(|_| {
            run(cargo()
                .args(["test", "--workspace", "--release"])
                .arg("--")
                .args(extra))
        })
        .and_then(|_| python_tests::run_python_tests(&workspace_root()))
}

/// `cargo xtask conformance` (its reference packages already there): the rows of every
/// check the flags select, then the report; an error when a row fails.
fn conformance_task(args: &ConformanceArgs) -> Result<(), String> {
    let shapes = &args.shapes;
    let random = args.random;
    let mut rows = Vec::new();
    if args.patches_only {
        let exe = oracles::osd::build_harness()?;
        rows.extend(patch_rows(args, &exe)?);
    } else if args.against != Against::CgalOpenmesh {
        let exe = oracles::osd::build_harness()?;
        rows.extend(patch_rows(args, &exe)?);
        if !args.fvar_only {
            rows.extend(timed("shapes", || conformance::shapes(&exe, shapes))?);
            rows.extend(timed("random", || conformance::random(&exe, random)));
        }
        rows.extend(timed("fvar shapes", || {
            conformance::fvar::shapes(&exe, shapes)
        })?);
        rows.extend(timed("fvar random", || {
            conformance::fvar::random(&exe, random)
        }));
        if !args.fvar_only {
            rows.extend(timed("usd", || {
                conformance::usd::stages(&exe, &usd_stages())
            })?);
        }
    }
    if args.against != Against::Opensubdiv && !args.fvar_only && !args.patches_only {
        let geom = oracles::geom::build_harness()?;
        rows.extend(timed("geom shapes", || {
            conformance::geom::shapes(&geom, shapes)
        })?);
        rows.extend(timed("geom random", || {
            conformance::geom::random(&geom, random)
        }));
    }
    if conformance::report(&rows) {
        Ok(())
    } else {
        Err("conformance failed".into())
    }
}

/// The patch-table rows of the conformance run (OpenSubdiv's harness `exe`): vertex and
/// face-varying tables, on the shapes, the real meshes and the random meshes.
fn patch_rows(
    args: &ConformanceArgs,
    exe: &std::path::Path,
) -> Result<Vec<conformance::row::Row>, String> {
    let shapes = &args.shapes;
    let mut rows = timed("patch shapes", || conformance::patches::shapes(exe, shapes))?;
    rows.extend(timed("patch meshes", || {
        conformance::patches::real_meshes(exe)
    })?);
    rows.extend(timed("patch random", || {
        conformance::patches::random(exe, args.random_patches)
    }));
    rows.extend(timed("fvar patch shapes", || {
        conformance::patch_fvar::shapes(exe, shapes)
    })?);
    rows.extend(timed("fvar patch random", || {
        conformance::patch_fvar::random(exe, args.random_fvar_patches)
    }));
    Ok(rows)
}

/// `cargo xtask bench`: the one benchmark a flag picks (the first set, in this order), or
/// by default refinement, evaluation and every other benchmark but the GPU, scaling,
/// patch-table and Python ones; `--eval-only` keeps evaluation alone.
fn bench_task(args: &BenchArgs) -> Result<(), String> {
    let repeats = args.repeats;
    if args.gpu {
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
            .args(["100000", &args.levels.to_string(), &repeats.to_string()]))
    } else if args.python_only {
        python_tests::run_python_bench(&workspace_root(), repeats)
    } else if args.usd_only {
        bench::usd::run(&workspace_root(), repeats)
    } else if args.scaling {
        ensure_system_packages(REFERENCE_PACKAGES)
            .and_then(|_| bench::scaling::run(repeats, &args.threads))
    } else if args.fvar_only {
        ensure_system_packages(REFERENCE_PACKAGES).and_then(|_| args.fvar())
    } else if args.tess_only {
        ensure_system_packages(REFERENCE_PACKAGES).and_then(|_| args.tess())
    } else if args.patches_only {
        ensure_system_packages(REFERENCE_PACKAGES).and_then(|_| bench::patch::run(repeats))
    } else if args.batch_only {
        args.batch()
    } else if args.split_only {
        ensure_system_packages(REFERENCE_PACKAGES).and_then(|_| args.split())
    } else if args.pia_only {
        bench::pia::run(repeats)
    } else if args.editing_only {
        bench::editing::run(repeats)
    } else if args.adaptive_only {
        ensure_system_packages(REFERENCE_PACKAGES).and_then(|_| bench::adaptive::run(repeats))
    } else if args.refine_only {
        ensure_system_packages(REFERENCE_PACKAGES).and_then(|_| args.refinement())
    } else {
        ensure_system_packages(REFERENCE_PACKAGES)
            .and_then(|_| {
                if args.eval_only {
                    Ok(())
                } else {
                    args.refinement()
                }
            })
            .and_then(|_| bench::run_eval(repeats))
            .and_then(|_| {
                if args.eval_only {
                    Ok(())
                } else {
                    args.the_rest()
                }
            })
    }
}

/// The benchmarks that take the bench flags' levels, repeats or rounds (at least one
/// round), as `bench_task` runs them alone or in the full run.
impl BenchArgs {
    /// The refinement benchmark.
    fn refinement(&self) -> Result<(), String> {
        bench::run(
            self.levels,
            self.repeats,
            self.rounds.max(1),
            self.huge_pages,
            !self.no_huge_page_advice,
            self.open,
        )
    }

    /// The split-scheme benchmark.
    fn split(&self) -> Result<(), String> {
        bench::split::run(self.levels, self.repeats, self.rounds.max(1))
    }

    /// The batch-mode benchmark, on OpenSubdiv's shapes.
    fn batch(&self) -> Result<(), String> {
        let shapes =
            std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/meshes/osd");
        bench::batch::run_batch(self.rounds.max(1), &shapes)
    }

    /// The tessellation benchmark.
    fn tess(&self) -> Result<(), String> {
        bench::tess::run(self.repeats)
    }

    /// The face-varying benchmark.
    fn fvar(&self) -> Result<(), String> {
        bench::fvar::run(self.levels, self.repeats, self.rounds.max(1))
    }

    /// What the full run does after refinement and evaluation: PIA, adaptive, editing,
    /// split schemes, batch, tessellation, face-varying and USD, stopping at the first
    /// error.
    fn the_rest(&self) -> Result<(), String> {
        let repeats = self.repeats;
        bench::pia::run(repeats)
            .and_then(|_| bench::adaptive::run(repeats))
            .and_then(|_| bench::editing::run(repeats))
            .and_then(|_| self.split())
            .and_then(|_| self.batch())
            .and_then(|_| self.tess())
            .and_then(|_| self.fvar())
            .and_then(|_| bench::usd::run(&workspace_root(), repeats))
    }
}

/// `cargo xtask fuzz`: each target (or only `target`) for `seconds`, stopping at the first
/// that fails.
fn fuzz_task(seconds: u64, target: Option<String>) -> Result<(), String> {
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
