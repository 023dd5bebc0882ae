//! Driving the CGAL / OpenMesh harness (`xtask/cpp/geom_harness.cpp`): building it against
//! the system libraries, exchanging meshes as OFF files, and matching vertices by position
//! (the libraries number vertices their own way).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use subd_mesh::{DVec3, Topology};

/// The two reference libraries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Library {
    Cgal,
    OpenMesh,
}

impl Library {
    pub fn name(self) -> &'static str {
        match self {
            Library::Cgal => "cgal",
            Library::OpenMesh => "openmesh",
        }
    }
}

/// A mesh a reference library produced.
pub struct RefMesh {
    pub positions: Vec<DVec3>,
    pub num_faces: usize,
}

/// What a harness run can end in besides a mesh.
pub enum RefOutcome {
    Mesh(RefMesh),
    /// The library refused the input (exit code 3), with its reason.
    Refused(String),
}

/// Compiles the harness (when missing or older than its source) and returns its path.
pub fn build_harness() -> Result<PathBuf, String> {
    // CGAL asks for -frounding-math; its kernel here is plain `double`, header-only.
    crate::oracles::osd::CppHarness {
        source: "geom_harness.cpp",
        exe: "geom_harness",
        flags: &["-O2", "-std=c++17", "-frounding-math"],
        libs: &["-lOpenMeshCore"],
        hint: "are libcgal-dev and libopenmesh-dev installed?",
    }
    .build()
}

pub fn write_off(path: &Path, topo: &Topology, positions: &[DVec3]) -> Result<(), String> {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(s, "OFF\n{} {} 0", topo.num_vertices(), topo.num_faces());
    for p in positions {
        // `{:?}` prints the shortest text that reads back as the same f64.
        let _ = writeln!(s, "{:?} {:?} {:?}", p.x, p.y, p.z);
    }
    for f in 0..topo.num_faces() {
        let fv = topo.face_vertices(f);
        let _ = write!(s, "{}", fv.len());
        for v in fv {
            let _ = write!(s, " {v}");
        }
        s.push('\n');
    }
    std::fs::write(path, s).map_err(|e| format!("{}: {e}", path.display()))
}

fn read_off(path: &Path) -> Result<RefMesh, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut words = text
        .lines()
        .filter(|l| !l.trim_start().starts_with('#'))
        .flat_map(str::split_whitespace);
    let bad = || format!("{}: not an OFF file the harness writes", path.display());
    if words.next() != Some("OFF") {
        return Err(bad());
    }
    let mut num =
        || -> Result<usize, String> { words.next().and_then(|w| w.parse().ok()).ok_or_else(bad) };
    let (nv, nf) = (num()?, num()?);
    let _edges = num()?;
    let mut coord =
        || -> Result<f64, String> { words.next().and_then(|w| w.parse().ok()).ok_or_else(bad) };
    let mut positions = Vec::with_capacity(nv);
    for _ in 0..nv {
        positions.push(DVec3::new(coord()?, coord()?, coord()?));
    }
    Ok(RefMesh {
        positions,
        num_faces: nf,
    })
}

/// Refines `topo` with `library`'s `scheme` (the harness's name for it), `levels` levels in
/// one call.
pub fn refine(
    exe: &Path,
    library: Library,
    scheme: &str,
    levels: usize,
    topo: &Topology,
    positions: &[DVec3],
) -> Result<RefOutcome, String> {
    // One folder per call: shapes are compared in parallel.
    static CALLS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("subd-geom-{}-{call}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let (input, output) = (dir.join("in.off"), dir.join("out.off"));
    write_off(&input, topo, positions)?;
    let result = Command::new(exe)
        .args([library.name(), scheme, &levels.to_string()])
        .arg(&input)
        .arg(&output)
        .output()
        .map_err(|e| format!("cannot run {}: {e}", exe.display()));
    let outcome = result.and_then(|result| outcome(result, &output, library, scheme));
    let _ = std::fs::remove_dir_all(&dir);
    outcome
}

/// What one harness run gave.
fn outcome(
    result: std::process::Output,
    output: &Path,
    library: Library,
    scheme: &str,
) -> Result<RefOutcome, String> {
    match result.status.code() {
        Some(0) => read_off(output).map(RefOutcome::Mesh),
        Some(3) => Ok(RefOutcome::Refused(
            String::from_utf8_lossy(&result.stderr).trim().to_string(),
        )),
        _ => Err(format!(
            "{} {scheme} failed ({}): {}",
            library.name(),
            result.status,
            String::from_utf8_lossy(&result.stderr).trim()
        )),
    }
}

/// Largest distance from a point of `a` to its nearest point of `b`, found through a grid of
/// cells of side `cell` (distances beyond a cell's neighbours count as infinite).
fn one_way(a: &[DVec3], b: &[DVec3], cell: f64) -> f64 {
    let key = |p: DVec3| {
        let q = p / cell;
        (q.x.floor() as i64, q.y.floor() as i64, q.z.floor() as i64)
    };
    let mut grid: HashMap<(i64, i64, i64), Vec<u32>> = HashMap::new();
    for (i, &p) in b.iter().enumerate() {
        grid.entry(key(p)).or_default().push(i as u32);
    }
    let mut worst = 0.0f64;
    for &p in a {
        let (x, y, z) = key(p);
        let mut best = f64::INFINITY;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = grid.get(&(x + dx, y + dy, z + dz)) {
                        for &j in list {
                            best = best.min(p.distance(b[j as usize]));
                        }
                    }
                }
            }
        }
        worst = worst.max(best);
    }
    worst
}

/// The distance between two point sets matched by nearest position, both ways (Hausdorff),
/// relative to `diag`; a gap larger than `1e-6 × diag` reads as infinite.
pub fn matched_error(ours: &[DVec3], theirs: &[DVec3], diag: f64) -> f64 {
    let cell = 1e-6 * diag.max(f64::MIN_POSITIVE);
    one_way(ours, theirs, cell).max(one_way(theirs, ours, cell)) / diag
}
