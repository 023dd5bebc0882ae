//! The meshes the checks and benchmarks measure on: the bench tori (built here), the
//! bunny scan (fetched once), and random meshes ([`random`]).

pub mod random;

use std::path::{Path, PathBuf};
use std::process::Command;

use subd_mesh::{Mesh, TopologyBuilder};
use subd_schemes::{Options, Refinement, Scheme};

/// A closed quad mesh of about 100k faces with extraordinary vertices: a 160 x 160 torus
/// grid in which every 8th quad pair is merged into a hexagon (two valence-3 vertices each),
/// refined once with Catmull-Clark (the hexagon centres become valence-6 vertices).
pub fn quad_bench_mesh() -> Mesh {
    let base = subd_mesh::primitives::torus_with_hexagons(160, 160, 8, 3.0, 1.0);
    let r = Refinement::new(&base.topology, Scheme::CatmullClark, &Options::default(), 1)
        .expect("refine");
    let pts = r.refine_points(&base.positions).pop().expect("level 1");
    Mesh::new(r.into_topology(1), pts).expect("finite")
}

/// The quad bench mesh with every quad split along its 0-2 diagonal, for Loop.
pub fn tri_bench_mesh() -> Mesh {
    split_quads(&quad_bench_mesh())
}

/// An all-quad mesh with every quad split along its 0-2 diagonal.
pub fn split_quads(q: &Mesh) -> Mesh {
    let t = &q.topology;
    let mut idx = Vec::with_capacity(t.num_faces() * 6);
    for f in 0..t.num_faces() {
        let v = t.face_vertices(f);
        idx.extend_from_slice(&[v[0], v[1], v[2], v[0], v[2], v[3]]);
    }
    let topo = TopologyBuilder::new(t.num_vertices())
        .build(&vec![3; 2 * t.num_faces()], &idx)
        .expect("valid");
    Mesh::new(topo, q.positions.clone()).expect("finite")
}

/// The quad bench mesh with every face whose centre lies in a band around the x axis or
/// on the negative x side removed (two boundary loops): refinement on it takes the general
/// path (boundaries), not the closed smooth one.
pub fn open_quad_bench_mesh() -> Result<Mesh, String> {
    let quads = quad_bench_mesh();
    let t = &quads.topology;
    let mut sizes = Vec::new();
    let mut corners = Vec::new();
    for f in 0..t.num_faces() {
        let fv = t.face_vertices(f);
        let centre = fv
            .iter()
            .map(|&v| quads.positions[v as usize])
            .sum::<subd_mesh::DVec3>()
            / fv.len() as f64;
        if centre.y.abs() > 0.6 || centre.x < 0.0 {
            sizes.push(fv.len() as u32);
            corners.extend_from_slice(fv);
        }
    }
    let topo = TopologyBuilder::new(t.num_vertices())
        .build(&sizes, &corners)
        .map_err(|e| e.to_string())?;
    Mesh::new(topo, quads.positions.clone()).map_err(|e| e.to_string())
}

/// The bunny scan, fetched first when it is not there yet.
pub(crate) fn scan_mesh() -> Result<subd_mesh::Mesh, String> {
    let path = bunny()?;
    let opts = subd_io::ReadOptions {
        accept_inconsistent_orientation: true,
        ..Default::default()
    };
    Ok(subd_io::read_mesh(&path, &opts)
        .map_err(|e| e.to_string())?
        .mesh)
}

/// The bunny scan's path, fetched first when it is not there yet.
pub(crate) fn bunny() -> Result<PathBuf, String> {
    let path = bunny_path();
    if !path.exists() {
        fetch_bunny(&path)?;
    }
    Ok(path)
}

/// Where the bunny scan lives once fetched.
fn bunny_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/xtask/bench/StanfordBunny.ply")
}

/// Fetches `pymeshfix`'s wheel from PyPI with pip and unpacks its bunny scan.
fn fetch_bunny(dest: &Path) -> Result<(), String> {
    let dir = dest.parent().ok_or("no parent")?.join("pymeshfix");
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    // The test environment's interpreter where `cargo xtask test` made one (it has pip on
    // any system); the system's otherwise.
    let venv = crate::system::env_python(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(".."));
    let python = if venv.exists() {
        venv.into_os_string()
    } else {
        "python3".into()
    };
    let status = Command::new(&python)
        .args([
            "-m",
            "pip",
            "download",
            "--no-deps",
            "--quiet",
            "pymeshfix==0.18.1",
            "-d",
        ])
        .arg(&dir)
        .status()
        .map_err(|e| format!("pip: {e}"))?;
    if !status.success() {
        return Err("pip download pymeshfix failed".into());
    }
    let script = "import sys, zipfile, glob\n\
                  w = glob.glob(sys.argv[1] + '/pymeshfix-*.whl')[0]\n\
                  open(sys.argv[2], 'wb').write(zipfile.ZipFile(w).read('pymeshfix/examples/StanfordBunny.ply'))\n";
    let status = Command::new(&python)
        .args(["-c", script])
        .arg(&dir)
        .arg(dest)
        .status()
        .map_err(|e| format!("python3: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err("could not unpack StanfordBunny.ply".into())
    }
}
