//! ACC: the bicubic approximation of Catmull-Clark surfaces by Loop & Schaefer,
//! "Approximating Catmull-Clark subdivision surfaces with bicubic patches" (ACM TOG 27(1),
//! 2008; the subdivision lecture notes §5(c)).
//!
//! One bicubic Bézier **geometry patch** per quad, `b[i][j]` (i along u, j along v, corner
//! (0,0) at the face's vertex 0), from the masks of the subdivision lecture notes §5(c):
//! * interior point at corner v (valence n) of the face: `(n v + 2 (e⁺ + e⁻) + f) / (n + 5)`
//!   (e± the face's two neighbours of v, f its opposite vertex);
//! * edge point: the average of the two interior points beside it (mask 2n, 4, 2, 2, 1, 1
//!   over 2n + 10);
//! * corner point: the Catmull-Clark limit position `(n² v + 4 Σ e + Σ f) / (n (n + 5))`.
//!
//! Where every vertex has valence 4 the patch is the B-spline patch itself. Elsewhere the
//! patches join with C⁰ continuity only, so ACC adds two **tangent patches** per face — the u
//! derivative (bidegree 2 × 3) and the v derivative (3 × 2) — whose cross product is the
//! shading normal: corner tangents are the limit tangents (the α/β mask of the paper, equal
//! to the B-spline derivative at valence 4), and the cross-derivative points next to each
//! corner are corrected with `cos(2π/n)` of the corner valences, as in the paper's §4.

// Patch control points are indexed by (i, j) in several arrays at once.
#![allow(clippy::needless_range_loop)]

use glam::DVec3;
use serde::Serialize;
use subd_mesh::Topology;
use subd_mesh::neighbourhood::quad_ring_from;

use crate::LimitError;

/// The ACC patches of one quad face.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AccPatch {
    /// Base face.
    pub face: usize,
    /// Bicubic Bézier geometry patch, `geometry[4 j + i]` = `b[i][j]`.
    pub geometry: [[f64; 3]; 16],
    /// u-tangent patch, bidegree 2 (u) × 3 (v): `tangent_u[3 j + i]`, i ∈ 0..3, j ∈ 0..4.
    pub tangent_u: [[f64; 3]; 12],
    /// v-tangent patch, bidegree 3 (u) × 2 (v): `tangent_v[4 j + i]`, i ∈ 0..4, j ∈ 0..3.
    pub tangent_v: [[f64; 3]; 12],
}

/// Bernstein basis of degree 2 or 3 at `t` (the first `degree + 1` entries).
fn bernstein(degree: usize, t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    match degree {
        2 => [s * s, 2.0 * s * t, t * t, 0.0],
        _ => [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t],
    }
}

impl AccPatch {
    /// Position on the geometry patch.
    pub fn position(&self, u: f64, v: f64) -> DVec3 {
        let (bu, bv) = (bernstein(3, u), bernstein(3, v));
        let mut p = DVec3::ZERO;
        for j in 0..4 {
            for i in 0..4 {
                p += bu[i] * bv[j] * DVec3::from(self.geometry[4 * j + i]);
            }
        }
        p
    }

    /// The two tangent patches at (u, v).
    pub fn tangents(&self, u: f64, v: f64) -> (DVec3, DVec3) {
        let (bu2, bv3) = (bernstein(2, u), bernstein(3, v));
        let (bu3, bv2) = (bernstein(3, u), bernstein(2, v));
        let (mut tu, mut tv) = (DVec3::ZERO, DVec3::ZERO);
        for j in 0..4 {
            for i in 0..3 {
                tu += bu2[i] * bv3[j] * DVec3::from(self.tangent_u[3 * j + i]);
            }
        }
        for j in 0..3 {
            for i in 0..4 {
                tv += bu3[i] * bv2[j] * DVec3::from(self.tangent_v[4 * j + i]);
            }
        }
        (tu, tv)
    }

    /// Unit normal from the tangent patches.
    pub fn normal(&self, u: f64, v: f64) -> DVec3 {
        let (tu, tv) = self.tangents(u, v);
        tu.cross(tv).normalize_or_zero()
    }
}

/// The limit tangent of `v` towards its neighbour `first`, scaled as ACC scales corner
/// tangents (equal to 3 (b₁₀ − b₀₀) of the B-spline patch at valence 4):
/// `Σ α_i e_i + β_i f_i`, `β = 1 / (n sqrt(4 + cos²(π/n)))`, `α_i = (1/n + cos(π/n) β)
/// cos(2πi/n)`, `β_i = β cos((2i + 1)π/n)`.
fn corner_tangent(t: &Topology, p: &[DVec3], v: usize, first: u32) -> Option<DVec3> {
    let (edges, diags) = quad_ring_from(t, v, first)?;
    let n = edges.len() as f64;
    let pi = std::f64::consts::PI;
    let c = (pi / n).cos();
    let beta = 1.0 / (n * (4.0 + c * c).sqrt());
    let alpha = 1.0 / n + c * beta;
    let mut out = DVec3::ZERO;
    for (i, (&e, &f)) in edges.iter().zip(&diags).enumerate() {
        let i = i as f64;
        out += alpha * (2.0 * pi * i / n).cos() * p[e as usize];
        out += beta * ((2.0 * i + 1.0) * pi / n).cos() * p[f as usize];
    }
    Some(out)
}

/// ACC patches of every face of a closed, all-quad mesh whose vertices are all smooth and
/// interior (the construction the paper gives; boundaries and creases are not covered).
pub fn acc_patches(t: &Topology, p: &[DVec3]) -> Result<Vec<AccPatch>, LimitError> {
    let mut out = Vec::with_capacity(t.num_faces());
    for f in 0..t.num_faces() {
        check_closed_quad(t, f)?;
        let b = geometry_patch(t, p, f)?;
        let (tu, tv) = tangent_patches(t, p, f, &b)?;
        out.push(AccPatch {
            face: f,
            geometry: b.map(|x| x.to_array()),
            tangent_u: tu.map(|x| x.to_array()),
            tangent_v: tv.map(|x| x.to_array()),
        });
    }
    Ok(out)
}

/// The error naming face `face` and why ACC does not cover it.
fn unsupported<T>(face: usize, reason: &'static str) -> Result<T, LimitError> {
    Err(LimitError::Unsupported { face, reason })
}

/// The error of a corner that is not an interior vertex with quads around it.
fn not_a_quad_corner(face: usize) -> LimitError {
    LimitError::Unsupported {
        face,
        reason: "a corner is not an interior vertex with quads around it",
    }
}

/// Valence of vertex `v`.
fn valence(t: &Topology, v: u32) -> f64 {
    t.vertex_faces(v as usize).len() as f64
}

/// Index of Bézier control point `b[i][j]` in a geometry patch.
fn at(i: usize, j: usize) -> usize {
    4 * j + i
}

/// Whether face `f` is a quad with no boundary or non-manifold vertex.
fn check_closed_quad(t: &Topology, f: usize) -> Result<(), LimitError> {
    let fv = t.face_vertices(f);
    if fv.len() != 4 {
        return unsupported(f, "ACC needs quads");
    }
    if fv
        .iter()
        .any(|&v| t.is_boundary_vertex(v as usize) || t.is_non_manifold_vertex(v as usize))
    {
        return unsupported(f, "ACC here covers closed manifold meshes");
    }
    Ok(())
}

/// Interior point of face `g` at its vertex `v`: `(n v + 2 (e⁺ + e⁻) + f) / (n + 5)`.
fn interior_point(t: &Topology, p: &[DVec3], g: usize, v: u32) -> DVec3 {
    let fv = t.face_vertices(g);
    let c = fv.iter().position(|&x| x == v).expect("v is a vertex of g");
    let n = valence(t, v);
    (n * p[v as usize]
        + 2.0 * (p[fv[(c + 1) % 4] as usize] + p[fv[(c + 3) % 4] as usize])
        + p[fv[(c + 2) % 4] as usize])
        / (n + 5.0)
}

/// The bicubic Bézier geometry patch of quad `f`: interior, edge and corner points.
fn geometry_patch(t: &Topology, p: &[DVec3], f: usize) -> Result<[DVec3; 16], LimitError> {
    let mut b = [DVec3::ZERO; 16];
    set_interior_points(t, p, f, &mut b);
    set_edge_points(t, p, f, &mut b)?;
    set_corner_points(t, p, f, &mut b)?;
    Ok(b)
}

/// The four interior points, each next to its corner.
fn set_interior_points(t: &Topology, p: &[DVec3], f: usize, b: &mut [DVec3; 16]) {
    let fv = t.face_vertices(f);
    let inner_ij = [(1, 1), (2, 1), (2, 2), (1, 2)];
    for k in 0..4 {
        let (i, j) = inner_ij[k];
        b[at(i, j)] = interior_point(t, p, f, fv[k]);
    }
}

/// The eight edge points: the average of the interior points on either side of the edge,
/// in `f` and in the face across it.
fn set_edge_points(
    t: &Topology,
    p: &[DVec3],
    f: usize,
    b: &mut [DVec3; 16],
) -> Result<(), LimitError> {
    let fv = t.face_vertices(f);
    // The face across edge k (from corner k to k + 1).
    let fe = t.face_edges(f);
    let across = |k: usize| -> Option<usize> {
        t.edge_faces(fe[k] as usize)
            .iter()
            .map(|&g| g as usize)
            .find(|&g| g != f)
    };
    // Edge points: corner k's end of edge k and corner k+1's end.
    let edge_ij = [
        [(1, 0), (2, 0)],
        [(3, 1), (3, 2)],
        [(2, 3), (1, 3)],
        [(0, 2), (0, 1)],
    ];
    for k in 0..4 {
        let Some(g) = across(k) else {
            return unsupported(f, "an edge of the face has no neighbour");
        };
        if t.face_size(g) != 4 {
            return unsupported(f, "ACC needs quads");
        }
        for (end, &(i, j)) in edge_ij[k].iter().enumerate() {
            let v = fv[(k + end) % 4];
            b[at(i, j)] = 0.5 * (interior_point(t, p, f, v) + interior_point(t, p, g, v));
        }
    }
    Ok(())
}

/// The four corner points: the Catmull-Clark limit positions `(n² v + 4 Σ e + Σ f) /
/// (n (n + 5))`.
fn set_corner_points(
    t: &Topology,
    p: &[DVec3],
    f: usize,
    b: &mut [DVec3; 16],
) -> Result<(), LimitError> {
    let fv = t.face_vertices(f);
    let corner_ij = [(0, 0), (3, 0), (3, 3), (0, 3)];
    for k in 0..4 {
        let v = fv[k] as usize;
        let (edges, diags) =
            quad_ring_from(t, v, fv[(k + 1) % 4]).ok_or_else(|| not_a_quad_corner(f))?;
        let n = edges.len() as f64;
        let sum_e: DVec3 = edges.iter().map(|&e| p[e as usize]).sum();
        let sum_f: DVec3 = diags.iter().map(|&d| p[d as usize]).sum();
        let (i, j) = corner_ij[k];
        b[at(i, j)] = (n * n * p[v] + 4.0 * sum_e + sum_f) / (n * (n + 5.0));
    }
    Ok(())
}

/// A u-tangent patch and a v-tangent patch (the layouts of [`AccPatch`]).
type TangentPatches = ([DVec3; 12], [DVec3; 12]);

/// The u- and v-tangent patches of quad `f` with geometry patch `b`: differences of the
/// geometry patch, with limit tangents at the corners and the corner-adjacent cross
/// derivatives corrected (paper §4).
fn tangent_patches(
    t: &Topology,
    p: &[DVec3],
    f: usize,
    b: &[DVec3; 16],
) -> Result<TangentPatches, LimitError> {
    let (mut tu, mut tv) = difference_patches(b);
    set_corner_tangents(t, p, f, &mut tu, &mut tv)?;
    set_cross_derivatives(t, f, b, &mut tu, &mut tv);
    Ok((tu, tv))
}

/// The derivative patches of the geometry patch: 3 × the differences of its points along u
/// and along v.
fn difference_patches(b: &[DVec3; 16]) -> TangentPatches {
    let mut tu = [DVec3::ZERO; 12];
    let mut tv = [DVec3::ZERO; 12];
    for j in 0..4 {
        for i in 0..3 {
            tu[3 * j + i] = 3.0 * (b[at(i + 1, j)] - b[at(i, j)]);
        }
    }
    for j in 0..3 {
        for i in 0..4 {
            tv[4 * j + i] = 3.0 * (b[at(i, j + 1)] - b[at(i, j)]);
        }
    }
    (tu, tv)
}

/// The limit tangents at the corners of quad `f`, in place of the differences there.
fn set_corner_tangents(
    t: &Topology,
    p: &[DVec3],
    f: usize,
    tu: &mut [DVec3; 12],
    tv: &mut [DVec3; 12],
) -> Result<(), LimitError> {
    let fv = t.face_vertices(f);
    let ct = |k: usize, towards: usize| -> Result<DVec3, LimitError> {
        corner_tangent(t, p, fv[k] as usize, fv[towards]).ok_or_else(|| not_a_quad_corner(f))
    };
    // Corner tangents: +u at corners 0 and 3 points to corners 1 and 2; at corners 1
    // and 2 +u points away from 0 and 3. Likewise for +v.
    tu[0] = ct(0, 1)?;
    tu[2] = -ct(1, 0)?;
    tu[3 * 3] = ct(3, 2)?;
    tu[3 * 3 + 2] = -ct(2, 3)?;
    tv[0] = ct(0, 3)?;
    tv[4 * 2] = -ct(3, 0)?;
    tv[3] = ct(1, 2)?;
    tv[4 * 2 + 3] = -ct(2, 1)?;
    Ok(())
}

/// The cross derivatives next to the corners of quad `f`, from the geometry patch `b` and
/// the corner valences.
fn set_cross_derivatives(
    t: &Topology,
    f: usize,
    b: &[DVec3; 16],
    tu: &mut [DVec3; 12],
    tv: &mut [DVec3; 12],
) {
    let fv = t.face_vertices(f);
    let cosv = |k: usize| (2.0 * std::f64::consts::PI / valence(t, fv[k])).cos();
    // Cross derivatives next to the corners of the edges v = 0 and v = 1 (in tv) and
    // u = 0 and u = 1 (in tu): the along-edge differences weighted by the corner cosines.
    let along_u = |j: usize, i: usize| 3.0 * (b[at(i + 1, j)] - b[at(i, j)]);
    let along_v = |i: usize, j: usize| 3.0 * (b[at(i, j + 1)] - b[at(i, j)]);
    // Along each edge, with the edge run in +u or +v from corner c0 to corner c1 and
    // X the cross derivative pointing into the face:
    //   X₁ = (2 c0 D₁ − c1 D₀)/3 + 3 (b_inner,1 − b_edge,1),
    //   X₂ = (c0 D₂ − 2 c1 D₁)/3 + 3 (b_inner,2 − b_edge,2),
    // D the along-edge differences; the formula is the same run either way (swapping c0
    // and c1 and reversing D maps X₁ to X₂). The stored tangent is +X on the edges at 0,
    // −X on the edges at 1, where +u / +v point out of the face.
    for (row, inner, sign, c0, c1) in [
        (0usize, 1usize, 1.0, cosv(0), cosv(1)),
        (3, 2, -1.0, cosv(3), cosv(2)),
    ] {
        let jr = if row == 0 { 0 } else { 2 };
        let x1 = (2.0 * c0 * along_u(row, 1) - c1 * along_u(row, 0)) / 3.0
            + 3.0 * (b[at(1, inner)] - b[at(1, row)]);
        let x2 = (c0 * along_u(row, 2) - 2.0 * c1 * along_u(row, 1)) / 3.0
            + 3.0 * (b[at(2, inner)] - b[at(2, row)]);
        tv[4 * jr + 1] = sign * x1;
        tv[4 * jr + 2] = sign * x2;
    }
    for (col, inner, sign, c0, c1) in [
        (0usize, 1usize, 1.0, cosv(0), cosv(3)),
        (3, 2, -1.0, cosv(1), cosv(2)),
    ] {
        let ic = if col == 0 { 0 } else { 2 };
        let x1 = (2.0 * c0 * along_v(col, 1) - c1 * along_v(col, 0)) / 3.0
            + 3.0 * (b[at(inner, 1)] - b[at(col, 1)]);
        let x2 = (c0 * along_v(col, 2) - 2.0 * c1 * along_v(col, 1)) / 3.0
            + 3.0 * (b[at(inner, 2)] - b[at(col, 2)]);
        tu[3 + ic] = sign * x1;
        tu[6 + ic] = sign * x2;
    }
}
