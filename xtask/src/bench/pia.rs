//! The PIA lines of `cargo xtask bench`: time to an interpolation error of 1e-10 of the
//! bounding-box diagonal for each solver on the ~100k-vertex closed quad bench mesh, and
//! Loop PIA end to end on a real scan (the Stanford bunny as `pymeshfix` ships it: 50k
//! vertices, open, with holes), fetched from PyPI into `target/` when it is not there yet.
//! OpenSubdiv has no interpolation, so these lines have no OpenSubdiv column.

use std::time::Instant;

use subd_mesh::Mesh;
use subd_pia::{Method, Moving, Pia, PiaError, PiaOptions, Solver};
use subd_schemes::{Options, Scheme, TwoPhase};

use crate::bench::median;
use crate::meshes::random::Rng;
use crate::meshes::{bunny, quad_bench_mesh};

/// Every solver on the quad bench mesh, Catmull-Clark and two-phase (λ = 0.5 and, nearer
/// the lower end of the range where the paper's iteration slows down, 0.4), all threads.
pub fn run(repeats: usize) -> Result<(), String> {
    let mesh = quad_bench_mesh();
    let nv = mesh.topology.num_vertices();
    let threads = rayon::current_num_threads();
    println!();
    println!(
        "PIA to max error 1e-10 × diagonal, closed quad torus, {nv} vertices (every vertex moves), {threads} threads, median of {repeats} runs; ratio = time / the paper's iteration's time; 'setup' is Pia::new (limit-position stencils in the solvers' form), 'prepare' Pia::prepare (Chebyshev operator, and the symmetric form where setup did not know it; built once), 'solve' the median of repeated solves on one prepared Pia, 'cold' the first solve on a fresh unprepared one (median over as many fresh ones)"
    );
    println!(
        "{:<14} {:<10} {:<14} {:>6} {:>10} {:>10} {:>10} {:>7} {:>10} {:>7} {:>12}",
        "scheme",
        "solver",
        "method",
        "iters",
        "setup s",
        "prepare s",
        "solve s",
        "ratio",
        "cold s",
        "ratio",
        "max error"
    );
    let schemes = [
        ("catmull-clark", Scheme::CatmullClark),
        (
            "two-phase 0.5",
            Scheme::TwoPhase(TwoPhase::uniform(0.5).map_err(|e| e.to_string())?),
        ),
        (
            "two-phase 0.4",
            Scheme::TwoPhase(TwoPhase::uniform(0.4).map_err(|e| e.to_string())?),
        ),
    ];
    for (name, scheme) in schemes {
        scheme_rows(&mesh, name, &scheme, repeats)?;
    }
    scan()
}

/// The solvers timed, in the table's order; the first one's times are the ratios' base
/// (the paper's iteration).
const SOLVERS: [(&str, Solver); 6] = [
    ("iterate", Solver::Iterate),
    ("weighted", Solver::Weighted),
    ("cg", Solver::Cg),
    ("chebyshev", Solver::Chebyshev),
    ("direct", Solver::Direct),
    ("auto", Solver::Auto),
];

/// The options of every timed solve: `solver` to 1e-10.
fn pia_options(solver: Solver) -> PiaOptions {
    PiaOptions {
        solver,
        tol: 1e-10,
        max_iter: 100_000,
    }
}

/// The table's rows for one scheme: setup and prepare once, then each solver's warm and
/// cold solves.
fn scheme_rows(mesh: &Mesh, name: &str, scheme: &Scheme, repeats: usize) -> Result<(), String> {
    let setup = median(
        (0..repeats)
            .map(|_| {
                let t = Instant::now();
                let p = Pia::new(&mesh.topology, scheme, &Options::default());
                let s = t.elapsed().as_secs_f64();
                p.map(|_| s).map_err(|e| e.to_string())
            })
            .collect::<Result<Vec<_>, _>>()?,
    );
    let fresh = || Pia::new(&mesh.topology, scheme, &Options::default());
    let prepare = median_on_fresh(repeats, fresh, |p| {
        p.prepare();
        Ok(())
    })?;
    let cold = cold_solves(mesh, fresh, repeats)?;
    let pia = fresh().map_err(|e| e.to_string())?;
    pia.prepare();
    let mut plain = None;
    for (i, &(sname, solver)) in SOLVERS.iter().enumerate() {
        let opts = pia_options(solver);
        let (cold, base_cold) = (cold[i], cold[0]);
        let mut times = Vec::new();
        let mut last = None;
        for _ in 0..repeats {
            let t = Instant::now();
            let r = pia
                .solve(&mesh.positions, &Moving::All, &opts)
                .map_err(|e| e.to_string())?;
            times.push(t.elapsed().as_secs_f64());
            last = Some(r);
        }
        let r = last.ok_or("no repeats")?;
        let solve = median(times);
        let base = *plain.get_or_insert(solve);
        let err = r.history.last().copied().unwrap_or(f64::NAN)
            / subd_pia::bbox_diagonal(&mesh.positions);
        println!(
            "{:<14} {:<10} {:<14} {:>6} {:>10.4} {:>10.4} {:>10.4} {:>7.2} {:>10.4} {:>7.2} {:>12.2e}",
            name,
            sname,
            method_name(&r.method),
            r.iterations,
            setup,
            prepare,
            solve,
            solve / base,
            cold,
            cold / base_cold,
            err
        );
    }
    Ok(())
}

/// Each solver's cold time, in [`SOLVERS`]' order: the first solve on a fresh, unprepared
/// `Pia`, which also builds what this solver needs beyond the limit matrix (the symmetric
/// form where setup did not know it, the Chebyshev operator); median over `repeats` fresh
/// ones. Taken in rounds of every solver, each round in its own shuffled order, so that
/// every solver meets the machine and the allocator in the same mix of states (in a fixed
/// order, the solver timed after `direct`, which frees hundreds of megabytes, pays for page
/// faults the others do not).
fn cold_solves(
    mesh: &Mesh,
    fresh: impl Fn() -> Result<Pia, PiaError> + Copy,
    repeats: usize,
) -> Result<Vec<f64>, String> {
    let mut cold_times = vec![Vec::new(); SOLVERS.len()];
    // Fixed seed: the same orders on every run.
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    for _ in 0..repeats {
        let mut order: Vec<usize> = (0..SOLVERS.len()).collect();
        // Fisher-Yates.
        for k in (1..order.len()).rev() {
            order.swap(k, rng.below(k as u64 + 1) as usize);
        }
        for i in order {
            let opts = pia_options(SOLVERS[i].1);
            cold_times[i].push(median_on_fresh(1, fresh, |p| {
                p.solve(&mesh.positions, &Moving::All, &opts).map(|_| ())
            })?);
        }
    }
    Ok(cold_times.into_iter().map(median).collect())
}

/// The table's name of the method a solve ran.
fn method_name(method: &Method) -> String {
    match method {
        Method::Iterate => "iterate".to_string(),
        Method::Weighted { .. } => "weighted".into(),
        Method::Cg => "cg".into(),
        Method::CheckerboardCg => "cb-cg".into(),
        Method::Chebyshev { .. } => "chebyshev".into(),
        Method::Bicgstab => "bicgstab".into(),
        Method::Cholesky => "cholesky".into(),
        Method::Lu => "lu".into(),
        Method::IterateThenCg { switched_after } => format!("{switched_after}it+cg"),
        Method::IterateThenBicgstab { switched_after } => {
            format!("{switched_after}it+bicgstab")
        }
    }
}

/// The median time of `work` over `repeats` fresh `Pia`s (each built by `new`, outside the
/// timing).
fn median_on_fresh(
    repeats: usize,
    new: impl Fn() -> Result<Pia, PiaError>,
    work: impl Fn(&Pia) -> Result<(), PiaError>,
) -> Result<f64, String> {
    let times = (0..repeats)
        .map(|_| {
            let p = new().map_err(|e| e.to_string())?;
            let t = Instant::now();
            work(&p).map_err(|e| e.to_string())?;
            Ok(t.elapsed().as_secs_f64())
        })
        .collect::<Result<Vec<_>, String>>()?;
    Ok(median(times))
}

/// Loop PIA on the bunny scan, end to end: read, limit stencils, solve, independent check,
/// write.
fn scan() -> Result<(), String> {
    let path = match bunny() {
        Ok(p) => p,
        Err(e) => {
            println!("(scan benchmark skipped: {e})");
            return Ok(());
        }
    };
    let t0 = Instant::now();
    let file = subd_io::read_mesh(
        &path,
        &subd_io::ReadOptions {
            accept_inconsistent_orientation: true,
            ..Default::default()
        },
    )
    .map_err(|e| e.to_string())?;
    let t_read = t0.elapsed().as_secs_f64();
    let topo = &file.mesh.topology;
    let boundary = (0..topo.num_edges())
        .filter(|&e| topo.is_boundary_edge(e))
        .count();
    let options = Options::from_hints(&file.mesh.hints);
    let t1 = Instant::now();
    let pia = Pia::new(topo, &Scheme::Loop, &options).map_err(|e| e.to_string())?;
    let t_setup = t1.elapsed().as_secs_f64();
    let t2 = Instant::now();
    let r = pia
        .solve(&file.mesh.positions, &Moving::All, &PiaOptions::default())
        .map_err(|e| e.to_string())?;
    let t_solve = t2.elapsed().as_secs_f64();
    let t3 = Instant::now();
    let check = subd_limit::base_limit_positions(topo, &subd_schemes::Scheme::Loop, &options)
        .map_err(|e| e.to_string())?;
    let limit = check.apply_points(&r.points);
    let err = limit
        .iter()
        .zip(&file.mesh.positions)
        .map(|(a, b)| (*a - *b).length())
        .fold(0.0, f64::max)
        / subd_pia::bbox_diagonal(&file.mesh.positions);
    let t_check = t3.elapsed().as_secs_f64();
    let out = path.with_file_name("StanfordBunny_pia.ply");
    let t4 = Instant::now();
    let mut mesh = file.mesh.clone();
    mesh.positions = r.points.clone();
    subd_io::write_mesh(&out, &mesh, &subd_io::WriteOptions::default())
        .map_err(|e| e.to_string())?;
    let t_write = t4.elapsed().as_secs_f64();
    println!();
    println!(
        "Loop PIA on a scan (Stanford bunny from pymeshfix: {} vertices, {} triangles, {} boundary edges), default solver, tol 1e-10, {} threads",
        topo.num_vertices(),
        topo.num_faces(),
        boundary,
        rayon::current_num_threads()
    );
    println!(
        "method {:?}, {} iterations, max error {:.2e} × diagonal; seconds: read {:.3}, setup {:.3}, solve {:.3}, check {:.3}, write {:.3}, total {:.3}",
        r.method,
        r.iterations,
        err,
        t_read,
        t_setup,
        t_solve,
        t_check,
        t_write,
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}
