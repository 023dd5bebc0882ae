//! Iso-parameter lines across a strip of quads (Li et al. 2008 §3.3).
//!
//! A line starts in a quad at a fixed value of one parameter and runs along the other,
//! crossing into the quad on the far side of each edge it reaches, for a given number of
//! faces. Over a strip of regular faces the limit curve along it is a uniform cubic
//! B-spline, and its `faces + 3` control points are linear in the control vertices (Li et al.'s
//! `N₀(t)..N₃(t)` combinations of the strip's rows; `(1/6, 2/3, 1/6)` at t = 0). Here
//! they are read off position and first and second derivatives along the line at the start
//! of each face, which for a cubic B-spline give its control points exactly:
//! `c₁ = P − P''/6`, `c₀ = c₁ − P' + P''/2`, `c₂ = c₁ + P' + P''/2`. Constraining them makes
//! the line *equal* the target curve. Where a face of the strip is not a B-spline patch
//! (an extraordinary vertex or a feature nearby; Li et al. leave this open) the line is
//! sampled instead: points at four parameters per face, each constrained to the target
//! curve's point there.

use glam::DVec3;
use subd_limit::PatchForm;
use subd_limit::eval::{FaceParam, LimitEvaluator};
use subd_limit::point_stencil::{DU, DV, POSITION};
use subd_mesh::Topology;

/// Which parameter a line runs along.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    /// Along u (v fixed).
    U,
    /// Along v (u fixed).
    V,
}

/// An iso-parameter line: starting in quad `face` at `at` of the other parameter, running
/// along `along` in its increasing direction across `faces` quads.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Isoline {
    /// First face (a quad).
    pub face: usize,
    /// The parameter it runs along in the first face.
    pub along: Axis,
    /// The fixed value of the other parameter, in [0, 1].
    pub at: f64,
    /// Number of faces it crosses (≥ 1).
    pub faces: usize,
}

/// Samples per face where the strip is not a B-spline.
pub const SAMPLES_PER_FACE: usize = 4;

/// One face of a line: the face, the axis and direction it runs along there, and the
/// value of the other parameter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StripFace {
    /// The face.
    pub face: usize,
    /// Axis along the line.
    pub along: Axis,
    /// `true` when the line runs in the decreasing direction of `along`.
    pub reversed: bool,
    /// The other parameter.
    pub at: f64,
}

impl StripFace {
    /// The face parameters at line parameter `s` ∈ [0, 1] within this face.
    pub fn param(&self, s: f64) -> FaceParam {
        let a = if self.reversed { 1.0 - s } else { s };
        let (u, v) = match self.along {
            Axis::U => (a, self.at),
            Axis::V => (self.at, a),
        };
        FaceParam {
            face: self.face,
            sub: 0,
            u,
            v,
        }
    }
}

/// The faces `line` crosses, walking over shared edges.
///
/// # Errors
/// A one-line reason: a face out of range or not a quad, `at` outside [0, 1], or the line
/// reaching a boundary or a non-manifold edge before its last face.
pub fn strip(topology: &Topology, line: &Isoline) -> Result<Vec<StripFace>, String> {
    if line.faces == 0 {
        return Err("an iso-line crosses at least one face".into());
    }
    if !(0.0..=1.0).contains(&line.at) {
        return Err(format!("iso-line parameter {} outside [0, 1]", line.at));
    }
    let quad = |f: usize| -> Result<(), String> {
        if f >= topology.num_faces() {
            return Err(format!(
                "face {f} out of range (the mesh has {} faces)",
                topology.num_faces()
            ));
        }
        if topology.face_size(f) != 4 {
            return Err(format!("face {f} is not a quad: iso-lines run over quads"));
        }
        Ok(())
    };
    quad(line.face)?;
    let mut cur = StripFace {
        face: line.face,
        along: line.along,
        reversed: false,
        at: line.at,
    };
    let mut out = vec![cur];
    while out.len() < line.faces {
        // The edge the line leaves by (edge k runs from corner k to k + 1) and the fraction
        // along it, from corner k.
        let (edge, s) = match (cur.along, cur.reversed) {
            (Axis::U, false) => (1, cur.at),
            (Axis::U, true) => (3, 1.0 - cur.at),
            (Axis::V, false) => (2, 1.0 - cur.at),
            (Axis::V, true) => (0, cur.at),
        };
        let fv = topology.face_vertices(cur.face);
        let (a, b) = (fv[edge], fv[(edge + 1) % 4]);
        let e = topology
            .find_edge(a, b)
            .ok_or_else(|| format!("face {}: edge not found", cur.face))?;
        let faces = topology.edge_faces(e as usize);
        if faces.len() != 2 {
            return Err(format!(
                "the iso-line leaves face {} across a {} edge after {} of {} faces",
                cur.face,
                if faces.len() < 2 {
                    "boundary"
                } else {
                    "non-manifold"
                },
                out.len(),
                line.faces
            ));
        }
        let g = if faces[0] as usize == cur.face {
            faces[1]
        } else {
            faces[0]
        } as usize;
        quad(g)?;
        let gv = topology.face_vertices(g);
        let m = (0..4)
            .find(|&m| gv[m] == b && gv[(m + 1) % 4] == a)
            .ok_or_else(|| format!("faces {} and {g} are not consistently oriented", cur.face))?;
        // Entering g through its edge m at fraction 1 − s from its corner m.
        let s2 = 1.0 - s;
        cur = match m {
            0 => StripFace {
                face: g,
                along: Axis::V,
                reversed: false,
                at: s2,
            },
            1 => StripFace {
                face: g,
                along: Axis::U,
                reversed: true,
                at: s2,
            },
            2 => StripFace {
                face: g,
                along: Axis::V,
                reversed: true,
                at: 1.0 - s2,
            },
            _ => StripFace {
                face: g,
                along: Axis::U,
                reversed: false,
                at: 1.0 - s2,
            },
        };
        out.push(cur);
    }
    Ok(out)
}

/// The uniform cubic B-spline with control points `c` at global parameter `x` ∈ [0, m]
/// (m = c.len() − 3 segments).
pub fn bspline_point(c: &[DVec3], x: f64) -> DVec3 {
    let m = c.len() - 3;
    let j = (x.floor() as usize).min(m - 1);
    let (b, _, _) = subd_limit::patch::bspline_basis(x - j as f64);
    (0..4).map(|k| b[k] * c[j + k]).sum()
}

/// A linear combination of stencils, merged by vertex.
fn combine(terms: &[(&[(u32, f64)], f64)]) -> Vec<(u32, f64)> {
    let mut all: Vec<(u32, f64)> = terms
        .iter()
        .flat_map(|(row, k)| row.iter().map(move |&(v, w)| (v, k * w)))
        .collect();
    all.sort_unstable_by_key(|p| p.0);
    let mut out: Vec<(u32, f64)> = Vec::with_capacity(all.len());
    for (v, w) in all {
        match out.last_mut() {
            Some(l) if l.0 == v => l.1 += w,
            _ => out.push((v, w)),
        }
    }
    out.retain(|p| p.1 != 0.0);
    out
}

/// Whether every face of the strip is one bicubic B-spline patch.
pub fn is_regular(ev: &LimitEvaluator, strip: &[StripFace]) -> bool {
    strip.iter().all(|s| {
        ev.face_patches(s.face)
            .map(|p| p.len() == 1 && matches!(p[0].form, PatchForm::Bicubic))
            .unwrap_or(false)
    })
}

/// Position, first and second derivative along the line at `s` of one strip face, as rows.
pub(crate) type AlongRows = [Vec<(u32, f64)>; 3];

pub(crate) fn along_rows(ev: &LimitEvaluator, f: &StripFace, s: f64) -> Result<AlongRows, String> {
    let st = ev.stencil(f.param(s)).map_err(|e| e.to_string())?;
    let (d1, d2) = match f.along {
        Axis::U => (DU, 3),
        Axis::V => (DV, 5),
    };
    let sign = if f.reversed { -1.0 } else { 1.0 };
    let row = |k: usize, scale: f64| -> Vec<(u32, f64)> {
        st.indices
            .iter()
            .zip(&st.weights[k])
            .map(|(&v, &w)| (v, scale * w))
            .collect()
    };
    Ok([row(POSITION, 1.0), row(d1, sign), row(d2, 1.0)])
}

/// The three curve control points `(c₀, c₁, c₂)` from position and derivatives at the start
/// of a segment.
pub(crate) fn control_triple(r: &AlongRows) -> [Vec<(u32, f64)>; 3] {
    let c1 = combine(&[(&r[0], 1.0), (&r[2], -1.0 / 6.0)]);
    let c0 = combine(&[(&c1, 1.0), (&r[1], -1.0), (&r[2], 0.5)]);
    let c2 = combine(&[(&c1, 1.0), (&r[1], 1.0), (&r[2], 0.5)]);
    [c0, c1, c2]
}

/// The current control points of a line over a regular strip (`None` when the strip is not
/// regular), for positions `x`.
pub fn current_control_points(
    ev: &LimitEvaluator,
    topology: &Topology,
    line: &Isoline,
    x: &[DVec3],
) -> Result<Option<Vec<DVec3>>, String> {
    let faces = strip(topology, line)?;
    if !is_regular(ev, &faces) {
        return Ok(None);
    }
    let apply = |r: &[(u32, f64)]| r.iter().map(|&(v, w)| w * x[v as usize]).sum::<DVec3>();
    let m = faces.len();
    let mut out = Vec::with_capacity(m + 3);
    for (j, f) in faces.iter().enumerate() {
        let [c0, c1, c2] = control_triple(&along_rows(ev, f, 0.0)?);
        if j == 0 {
            out.push(apply(&c0));
            out.push(apply(&c1));
        }
        out.push(apply(&c2));
    }
    let [_, _, last] = control_triple(&along_rows(ev, &faces[m - 1], 1.0)?);
    out.push(apply(&last));
    Ok(Some(out))
}
