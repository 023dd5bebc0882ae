//! Driving the OpenSubdiv harness (`xtask/cpp/osd_harness.cpp`): building it against the
//! system OpenSubdiv and exchanging meshes with it.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use subd_mesh::{BoundaryInterpolation, CreaseMethod, DVec3, Topology, TriangleSubdivision};
use subd_schemes::{Options, Scheme};

/// One refined level as OpenSubdiv produced it.
pub struct OsdLevel {
    pub face_sizes: Vec<u32>,
    pub face_vertices: Vec<u32>,
    pub positions: Vec<DVec3>,
}

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("workspace root")
        .to_path_buf()
}

/// A C++ reference harness: its source under `xtask/cpp`, the executable it becomes under
/// `target/xtask`, the compiler flags before the source and the libraries after it, and the
/// hint to give when the compile fails.
pub struct CppHarness<'a> {
    pub source: &'a str,
    pub exe: &'a str,
    pub flags: &'a [&'a str],
    pub libs: &'a [&'a str],
    pub hint: &'a str,
}

impl CppHarness<'_> {
    /// Compiles the harness when it is missing or older than its source; returns its path.
    pub fn build(&self) -> Result<PathBuf, String> {
        let root = workspace_root();
        let src = root.join("xtask/cpp").join(self.source);
        let out_dir = root.join("target/xtask");
        std::fs::create_dir_all(&out_dir).map_err(|e| e.to_string())?;
        let exe = out_dir.join(self.exe);
        let stale = match (std::fs::metadata(&exe), std::fs::metadata(&src)) {
            (Ok(a), Ok(b)) => a.modified().ok() < b.modified().ok(),
            _ => true,
        };
        if stale {
            eprintln!("xtask: compiling {}", self.source);
            let status = Command::new("g++")
                .args(self.flags)
                .arg("-o")
                .arg(&exe)
                .arg(&src)
                .args(self.libs)
                .status()
                .map_err(|e| format!("cannot run g++: {e}"))?;
            if !status.success() {
                return Err(format!("compiling {} failed ({})", self.source, self.hint));
            }
        }
        Ok(exe)
    }
}

/// Compiles the OpenSubdiv harness (when missing or older than its source) and returns its
/// path.
pub fn build_harness() -> Result<PathBuf, String> {
    CppHarness {
        source: "osd_harness.cpp",
        exe: "osd_harness",
        flags: &["-O2", "-std=c++14"],
        libs: &["-losdCPU"],
        hint: "is libosd-dev installed?",
    }
    .build()
}

/// The harness's scheme code (OpenSubdiv's `Sdc::SchemeType`); the two-phase scheme's
/// refined levels are Catmull-Clark's.
fn scheme_code(s: &Scheme) -> u32 {
    match s {
        Scheme::Bilinear => 0,
        Scheme::CatmullClark | Scheme::TwoPhase(_) => 1,
        Scheme::Loop => 2,
        other => unreachable!("OpenSubdiv has no {other} scheme"),
    }
}

/// Serialises a mesh for the harness.
pub fn encode(
    topo: &Topology,
    positions: &[DVec3],
    scheme: &Scheme,
    options: &Options,
    levels: u32,
) -> Vec<u8> {
    let mut b = Vec::new();
    let u = |b: &mut Vec<u8>, x: u32| b.extend_from_slice(&x.to_le_bytes());
    b.extend_from_slice(b"SUBDOSD1");
    u(&mut b, scheme_code(scheme));
    u(
        &mut b,
        match options.boundary_interpolation {
            BoundaryInterpolation::None => 0,
            BoundaryInterpolation::EdgeOnly => 1,
            BoundaryInterpolation::EdgeAndCorner => 2,
        },
    );
    u(
        &mut b,
        (options.crease_method == CreaseMethod::Chaikin) as u32,
    );
    u(
        &mut b,
        (options.triangle_subdivision == TriangleSubdivision::Smooth) as u32,
    );
    u(&mut b, levels);
    u(&mut b, topo.num_vertices() as u32);
    u(&mut b, topo.num_faces() as u32);
    for s in topo.face_sizes() {
        u(&mut b, s);
    }
    u(&mut b, topo.num_face_vertices() as u32);
    for &v in topo.all_face_vertices() {
        u(&mut b, v);
    }
    for p in positions {
        for c in p.to_array() {
            b.extend_from_slice(&c.to_le_bytes());
        }
    }
    let creases: Vec<usize> = (0..topo.num_edges())
        .filter(|&e| topo.edge_sharpness(e) > 0.0)
        .collect();
    u(&mut b, creases.len() as u32);
    for e in creases {
        let [x, y] = topo.edge_vertices(e);
        u(&mut b, x);
        u(&mut b, y);
        b.extend_from_slice(&topo.edge_sharpness(e).to_le_bytes());
    }
    let corners: Vec<usize> = (0..topo.num_vertices())
        .filter(|&v| topo.vertex_sharpness(v) > 0.0)
        .collect();
    u(&mut b, corners.len() as u32);
    for v in corners {
        u(&mut b, v as u32);
        b.extend_from_slice(&topo.vertex_sharpness(v).to_le_bytes());
    }
    let holes: Vec<usize> = (0..topo.num_faces()).filter(|&f| topo.is_hole(f)).collect();
    u(&mut b, holes.len() as u32);
    for f in holes {
        u(&mut b, f as u32);
    }
    b
}

/// Runs the harness with `args` on an encoded mesh and returns its standard output, or its
/// error message.
pub fn run(exe: &Path, input: &[u8], args: &[&str]) -> Result<Vec<u8>, String> {
    let mut child = Command::new(exe)
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot run {}: {e}", exe.display()))?;
    child
        .stdin
        .take()
        .expect("stdin")
        .write_all(input)
        .map_err(|e| e.to_string())?;
    let out = child.wait_with_output().map_err(|e| e.to_string())?;
    if !out.status.success() {
        let msg = String::from_utf8_lossy(&out.stderr).trim().to_string();
        return Err(if msg.is_empty() {
            format!("harness failed ({})", out.status)
        } else {
            msg
        });
    }
    Ok(out.stdout)
}

/// Decodes the harness output: `levels` refined levels.
pub fn decode(bytes: &[u8], levels: usize) -> Result<Vec<OsdLevel>, String> {
    let mut pos = 0usize;
    let u = |pos: &mut usize| -> Result<u32, String> {
        let s = bytes
            .get(*pos..*pos + 4)
            .ok_or("harness output truncated")?;
        *pos += 4;
        Ok(u32::from_le_bytes(s.try_into().unwrap()))
    };
    let mut out = Vec::with_capacity(levels);
    for _ in 0..levels {
        let nv = u(&mut pos)? as usize;
        let nf = u(&mut pos)? as usize;
        let face_sizes = (0..nf)
            .map(|_| u(&mut pos))
            .collect::<Result<Vec<_>, _>>()?;
        let total: usize = face_sizes.iter().map(|&s| s as usize).sum();
        let face_vertices = (0..total)
            .map(|_| u(&mut pos))
            .collect::<Result<Vec<_>, _>>()?;
        let need = nv * 24;
        let raw = bytes
            .get(pos..pos + need)
            .ok_or("harness output truncated")?;
        pos += need;
        let positions = raw
            .chunks_exact(24)
            .map(|c| {
                let f = |i: usize| f64::from_le_bytes(c[8 * i..8 * i + 8].try_into().unwrap());
                DVec3::new(f(0), f(1), f(2))
            })
            .collect();
        out.push(OsdLevel {
            face_sizes,
            face_vertices,
            positions,
        });
    }
    Ok(out)
}

/// OpenSubdiv's `PrimvarRefiner::Limit` at the last level: positions and both tangents.
pub struct OsdLimit {
    pub positions: Vec<DVec3>,
    pub tangent1: Vec<DVec3>,
    pub tangent2: Vec<DVec3>,
}

/// Decodes the output of `--limit`.
pub fn decode_limit(bytes: &[u8]) -> Result<OsdLimit, String> {
    let nv = bytes
        .get(..4)
        .map(|s| u32::from_le_bytes(s.try_into().unwrap()) as usize)
        .ok_or("harness output truncated")?;
    let raw = bytes
        .get(4..4 + 72 * nv)
        .ok_or("harness output truncated")?;
    let points = |k: usize| -> Vec<DVec3> {
        raw[24 * nv * k..24 * nv * (k + 1)]
            .chunks_exact(24)
            .map(|c| {
                let f = |i: usize| f64::from_le_bytes(c[8 * i..8 * i + 8].try_into().unwrap());
                DVec3::new(f(0), f(1), f(2))
            })
            .collect()
    };
    Ok(OsdLimit {
        positions: points(0),
        tangent1: points(1),
        tangent2: points(2),
    })
}

/// Appends evaluation points (ptex face, u, v) to an encoded mesh for `--eval`.
pub fn encode_eval_points(mut input: Vec<u8>, points: &[(u32, f64, f64)]) -> Vec<u8> {
    input.extend_from_slice(&(points.len() as u32).to_le_bytes());
    for &(f, u, v) in points {
        input.extend_from_slice(&f.to_le_bytes());
        input.extend_from_slice(&u.to_le_bytes());
        input.extend_from_slice(&v.to_le_bytes());
    }
    input
}

/// Decodes `--eval` output: per point position, Du, Dv, Duu, Duv, Dvv.
pub fn decode_eval(bytes: &[u8], count: usize) -> Result<Vec<[DVec3; 6]>, String> {
    if bytes.len() != count * 144 {
        return Err(format!(
            "harness returned {} bytes for {count} points",
            bytes.len()
        ));
    }
    Ok(bytes
        .chunks_exact(144)
        .map(|c| {
            std::array::from_fn(|d| {
                let f = |i: usize| {
                    f64::from_le_bytes(c[24 * d + 8 * i..24 * d + 8 * i + 8].try_into().unwrap())
                };
                DVec3::new(f(0), f(1), f(2))
            })
        })
        .collect())
}

/// Appends a two-component face-varying channel (values, one index per face-vertex) to an
/// encoded mesh for `--fvar` / `--fvar-limit`.
pub fn encode_fvar(mut input: Vec<u8>, values: &[f64], indices: &[u32]) -> Vec<u8> {
    input.extend_from_slice(&((values.len() / 2) as u32).to_le_bytes());
    for x in values {
        input.extend_from_slice(&x.to_le_bytes());
    }
    for i in indices {
        input.extend_from_slice(&i.to_le_bytes());
    }
    input
}

/// One refined level of a face-varying channel as OpenSubdiv produced it.
pub struct OsdFVarLevel {
    /// `GetFaceFVarValues`, face after face.
    pub face_values: Vec<u32>,
    /// Two numbers per value.
    pub values: Vec<f64>,
}

/// Little-endian reader of the harness output.
pub struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Cursor<'a> {
    /// A reader at the start of `bytes`.
    pub fn new(bytes: &'a [u8]) -> Cursor<'a> {
        Cursor { bytes, pos: 0 }
    }
    pub fn take(&mut self, n: usize) -> Result<&[u8], String> {
        let s = self
            .bytes
            .get(self.pos..self.pos + n)
            .ok_or("harness output truncated")?;
        self.pos += n;
        Ok(s)
    }
    /// Whether every byte has been read.
    pub fn is_empty(&self) -> bool {
        self.pos >= self.bytes.len()
    }
    pub fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into().unwrap()))
    }
    pub fn f64s(&mut self, n: usize) -> Result<Vec<f64>, String> {
        Ok(self
            .take(8 * n)?
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect())
    }
}

/// Decodes `--fvar` output: `levels` refined levels of the channel.
pub fn decode_fvar(bytes: &[u8], levels: usize) -> Result<Vec<OsdFVarLevel>, String> {
    let mut c = Cursor { bytes, pos: 0 };
    (0..levels)
        .map(|_| {
            let nvalues = c.u32()? as usize;
            let nfv = c.u32()? as usize;
            let face_values = (0..nfv).map(|_| c.u32()).collect::<Result<Vec<_>, _>>()?;
            let values = c.f64s(2 * nvalues)?;
            Ok(OsdFVarLevel {
                face_values,
                values,
            })
        })
        .collect()
}

/// Decodes `--fvar-limit` output: two numbers per value of the last level.
pub fn decode_fvar_limit(bytes: &[u8]) -> Result<Vec<f64>, String> {
    let mut c = Cursor { bytes, pos: 0 };
    let n = c.u32()? as usize;
    c.f64s(2 * n)
}
