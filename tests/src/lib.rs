//! Shared helpers for subd's workspace-level integration tests: where the real meshes are and
//! what OpenSubdiv says about them (`../shared/meshes/osd/INDEX.md`).

use std::path::{Path, PathBuf};

/// Directory of OpenSubdiv's regression shapes (`<repo>/../shared/meshes/osd`), overridable
/// with the `SUBD_MESHES` environment variable (pointing at the `meshes` directory).
pub fn osd_mesh_dir() -> PathBuf {
    let base = match std::env::var_os("SUBD_MESHES") {
        Some(p) => PathBuf::from(p),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/meshes"),
    };
    base.join("osd")
}

/// Every `.obj` file of the OpenSubdiv shape directory, sorted by name.
pub fn osd_meshes() -> Vec<PathBuf> {
    let dir = osd_mesh_dir();
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "obj"))
        .collect();
    v.sort();
    v
}

/// One row of `INDEX.md`: OpenSubdiv 3.5's own view of a shape's topology.
#[derive(Debug, Clone)]
pub struct IndexRow {
    /// Shape name (file stem).
    pub shape: String,
    /// Scheme prefix: `catmark`, `loop` or `bilinear`.
    pub scheme: String,
    /// Faces.
    pub faces: usize,
    /// Vertices.
    pub vertices: usize,
    /// Edges.
    pub edges: usize,
    /// Face size histogram as `(size, count)`.
    pub face_sizes: Vec<(usize, usize)>,
    /// Boundary edges.
    pub boundary_edges: usize,
    /// Boundary interpolation in effect (`none`, `edge-only`, `edge-and-corner`).
    pub boundary_rule: String,
    /// Tagged semi-sharp creases.
    pub semi_sharp: usize,
    /// Tagged infinitely sharp creases.
    pub inf_sharp: usize,
    /// Corner tags.
    pub corners: usize,
    /// Non-manifold edges.
    pub nonmanifold_edges: usize,
    /// Non-manifold vertices.
    pub nonmanifold_vertices: usize,
    /// Hole tags.
    pub holes: usize,
    /// Extraordinary vertices (OpenSubdiv's `!IsVertexValenceRegular`).
    pub irregular: usize,
}

fn count(cell: &str) -> usize {
    let c = cell.trim();
    if c == "no" {
        0
    } else {
        c.parse().unwrap_or_else(|_| panic!("bad count cell {c:?}"))
    }
}

/// Parses the shape table of `INDEX.md`.
pub fn index_rows() -> Vec<IndexRow> {
    let path = osd_mesh_dir().join("INDEX.md");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let mut rows = Vec::new();
    for line in text.lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        // | shape | scheme | F | V | E | sizes | boundary | rule | creases | corners | nonman | holes | irregular | notes |
        if cells.len() < 15 || cells[1] == "shape" || cells[1].starts_with("---") {
            continue;
        }
        let pair = |c: &str| -> (usize, usize) {
            if c == "no" {
                return (0, 0);
            }
            let mut it = c.split('/').map(|s| {
                s.trim()
                    .trim_end_matches(|ch: char| ch.is_alphabetic())
                    .trim()
            });
            let a = it.next().map(count).unwrap_or(0);
            let b = it.next().map(count).unwrap_or(0);
            (a, b)
        };
        let (semi, inf) = pair(cells[9]);
        let (nme, nmv) = pair(cells[11]);
        rows.push(IndexRow {
            shape: cells[1].to_string(),
            scheme: cells[2].to_string(),
            faces: count(cells[3]),
            vertices: count(cells[4]),
            edges: count(cells[5]),
            face_sizes: cells[6]
                .split_whitespace()
                .map(|t| {
                    let (a, b) = t.split_once(':').expect("size:count");
                    (a.parse().unwrap(), b.parse().unwrap())
                })
                .collect(),
            boundary_edges: count(cells[7]),
            boundary_rule: cells[8].to_string(),
            semi_sharp: semi,
            inf_sharp: inf,
            corners: count(cells[10]),
            nonmanifold_edges: nme,
            nonmanifold_vertices: nmv,
            holes: count(cells[12]),
            irregular: count(cells[13]),
        });
    }
    rows
}
