//! End caps of Loop patches: the 18 points of a quartic Gregory triangle fitted to an
//! irregular triangle, and the 12 points of a box-spline patch fitted to that Gregory
//! triangle (OpenSubdiv's `GregoryTriConverter` and `convertToLoop`; formulas restated, code
//! our own).
//!
//! **Gregory triangle** (Loop, Schaefer, Ni, Castaño 2009, with OpenSubdiv's choices). Per
//! corner the limit position `P` and two *cubic* edge points `Ep`, `Em` one third of the way
//! along the limit tangents towards the next and previous corners, from Loop's limit masks
//! (the tangents of Sdc's masks, scaled so that a regular vertex lands on the cubic
//! boundary curve's points). The face points `Fp`, `Fm` blend the edge points of the two
//! corners of their edge by the corners' face angles; the mid-edge points `M` are the
//! quartic boundary curve's middle point where both ends are regular, else the average of
//! the two cubic edge points. The cubic edge points are finally raised to the quartic:
//! `E ← P/4 + 3E/4`.
//!
//! **Box-spline end cap.** The 12 box-spline points whose patch matches the Gregory
//! triangle's quartic Bézier net along its boundary and at its centre, in the least-squares
//! sense of [`super::box_fit`].
//!
//! Corner fans are those of [`super::end_caps`]: `e_0 … e_{m−1}` around `V` from the fan's
//! first face (plus `e_m` on a boundary), the patch face at `k`, `e_k` the next corner and
//! `e_{k+1}` the previous one.

use std::f64::consts::PI;

use subd_mesh::Topology;

use super::box_fit;
use super::end_caps::{
    Corner, CornerRules, FacePoint, Row, add, boundary_limit, corners, face_point_kinds,
    loop_interior_limit, point, resolve_copies,
};
use super::features::VTag;

/// `P`, `Ep`, `Em` of an irregular interior corner: Sdc's smooth tangent mask
/// `cos(2πj/n)` scaled by `(3 + 2cos(2π/n)) / (6n)` (OpenSubdiv's `LoopLimits`), which puts
/// the point of a valence-6 vertex on its cubic boundary curve.
fn interior_points(c: &Corner) -> [Row; 3] {
    let n = c.m;
    let p = loop_interior_limit(c);
    let alpha = 2.0 * PI / n as f64;
    let scale = (3.0 + 2.0 * alpha.cos()) / (6.0 * n as f64);
    let along = |shift: usize| {
        let mut r = p.clone();
        for j in 0..n {
            r.push((c.e(j + shift), scale * (alpha * j as f64).cos()));
        }
        r
    };
    [p.clone(), along(c.k), along(c.k + 1)]
}

/// Sdc's crease tangent across the surface of a boundary vertex with `m ≥ 2` faces
/// (`assignCreaseLimitTangentMasks`: special masks for 1 and 2 interior edges, the
/// half-disk sine mask beyond).
fn across_boundary(c: &Corner) -> Row {
    let m = c.m;
    match m {
        2 => vec![(c.v, -3.0), (c.e[1], 3.0)],
        3 => {
            let r3 = 3.0f64.sqrt();
            vec![
                (c.v, -r3),
                (c.e[0], -r3 / 2.0),
                (c.e[3], -r3 / 2.0),
                (c.e[1], r3),
                (c.e[2], r3),
            ]
        }
        _ => {
            let theta = PI / m as f64;
            let ends = -3.0 * theta.sin();
            let inner = -6.0 * (theta.cos() - 1.0);
            let mut r = vec![(c.v, 0.0), (c.e[0], ends), (c.e[m], ends)];
            r.extend((1..m).map(|i| (c.e[i], inner * (i as f64 * theta).sin())));
            r
        }
    }
}

/// `P`, `Ep`, `Em` of an irregular boundary corner with `m ≥ 2` faces: the tangent at
/// angle `φ = jπ/m` is `sin φ` across the surface (Sdc's mask / 24) plus `cos φ` along the
/// boundary (`(e_0 − e_m)/6`); an edge point on the boundary is on the boundary curve.
fn boundary_points(c: &Corner) -> [Row; 3] {
    let m = c.m;
    let p = boundary_limit(c);
    let across = across_boundary(c);
    let alpha = PI / m as f64;
    let at = |j: usize| {
        let phi = alpha * j as f64;
        let mut r = p.clone();
        add(&mut r, phi.sin() / 24.0, &across);
        r.push((c.e[0], phi.cos() / 6.0));
        r.push((c.e[m], -phi.cos() / 6.0));
        r
    };
    let along_boundary = |end: u32| vec![(c.v, 2.0 / 3.0), (end, 1.0 / 3.0)];
    let ep = if c.ep_on_boundary() {
        along_boundary(c.e[0])
    } else {
        at(c.k)
    };
    // At j = m the formula is this point up to rounding; OpenSubdiv keeps only its two
    // entries along the boundary edge.
    let em = if c.em_on_boundary() {
        along_boundary(c.e[m])
    } else {
        at(c.k + 1)
    };
    [p, ep, em]
}

/// `P`, `Ep`, `Em` of a regular interior corner (valence 6): the cubic boundary curves of
/// the box spline.
fn regular_interior_points(c: &Corner) -> [Row; 3] {
    let mut p = vec![(c.v, 0.5)];
    p.extend(c.e.iter().map(|&e| (e, 1.0 / 12.0)));
    const AROUND: [f64; 6] = [7.0, 5.0, 1.0, -1.0, 1.0, 5.0];
    let edge = |from: usize| {
        let mut r = vec![(c.v, 0.5)];
        r.extend((0..6).map(|j| (c.e(from + j), AROUND[j] / 36.0)));
        r
    };
    [p, edge(c.k), edge(c.k + 1)]
}

/// `P`, `Ep`, `Em` of a regular boundary corner (three faces); an edge point inside the
/// surface averages the vertex with the three neighbours on its side.
fn regular_boundary_points(c: &Corner) -> [Row; 3] {
    let p = boundary_limit(c);
    let along = |end: u32| vec![(c.v, 2.0 / 3.0), (end, 1.0 / 3.0)];
    let inner = |third: u32| {
        vec![
            (c.v, 0.5),
            (c.e[1], 1.0 / 6.0),
            (c.e[2], 1.0 / 6.0),
            (third, 1.0 / 6.0),
        ]
    };
    let (ep_on, em_on) = (c.ep_on_boundary(), c.em_on_boundary());
    let ep = if ep_on {
        along(c.e[0])
    } else {
        inner(if em_on { c.e[3] } else { c.e[0] })
    };
    let em = if em_on {
        along(c.e[3])
    } else {
        inner(if ep_on { c.e[0] } else { c.e[3] })
    };
    [p, ep, em]
}

/// The cubic `P`, `Ep`, `Em` of a corner, by its kind.
fn edge_points(c: &Corner) -> [Row; 3] {
    let towards = |end: u32| vec![(c.v, 2.0 / 3.0), (end, 1.0 / 3.0)];
    if c.regular() && c.boundary {
        regular_boundary_points(c)
    } else if c.regular() {
        regular_interior_points(c)
    } else if c.sharp {
        [point(c.v), towards(c.next()), towards(c.prev())]
    } else if !c.boundary {
        interior_points(c)
    } else if c.m > 1 {
        boundary_points(c)
    } else {
        let p = vec![
            (c.v, 2.0 / 3.0),
            (c.next(), 1.0 / 6.0),
            (c.prev(), 1.0 / 6.0),
        ];
        [p, towards(c.next()), towards(c.prev())]
    }
}

/// The face point of a corner whose neighbourhood is regular on that side (or a 1-face
/// corner): the box spline's interior Bézier point next to the corner.
fn regular_face_point(c: &Corner) -> Row {
    let w = |x: f64| x / 24.0;
    if c.m == 1 {
        vec![(c.v, 0.5), (c.next(), 0.25), (c.prev(), 0.25)]
    } else if c.ep_on_boundary() {
        vec![
            (c.v, w(11.0)),
            (c.e[0], w(7.0)),
            (c.e[1], w(5.0)),
            (c.e[2], w(1.0)),
        ]
    } else if c.em_on_boundary() {
        vec![
            (c.v, w(11.0)),
            (c.e[3], w(7.0)),
            (c.e[2], w(5.0)),
            (c.e[1], w(1.0)),
        ]
    } else {
        let (x, y) = if c.boundary {
            (c.e[0], c.e[3])
        } else {
            (c.e(c.k + 5), c.e(c.k + 2))
        };
        vec![
            (c.v, w(10.0)),
            (c.prev(), 0.25),
            (c.next(), 0.25),
            (x, w(1.0)),
            (y, w(1.0)),
        ]
    }
}

/// `Fp` and `Fm` of corner `i`, from the corners' cubic `P, Ep, Em`: Loop et al.'s face
/// point with `d = 4`, `F = (c₁P + (4 − 2c₀ − c₁)E_near + 2c₀E_far)/4` plus the twist
/// `±7/72 (e_{i+1} − e_{i−1})` of the near corner's ring around the edge.
fn face_points(cs: &[Corner], edges: &[[Row; 3]], i: usize) -> [Row; 2] {
    let c = &cs[i];
    let (next, prev) = (&cs[(i + 1) % 3], &cs[(i + 2) % 3]);
    let [p, ep, em] = &edges[i];
    let val = c.valence();
    let computed = |sign: f64, ring: usize, near: &Row, far_c: &Corner, far: &Row| {
        let (ca_near, ca_far) = (c.cos_a(), far_c.cos_a());
        let mut r: Row = Vec::new();
        add(&mut r, ca_far / 4.0, p);
        add(&mut r, (4.0 - 2.0 * ca_near - ca_far) / 4.0, near);
        add(&mut r, 2.0 * ca_near / 4.0, far);
        let twist = 0.25 * (7.0 / 18.0);
        r.push((c.e(ring + val - 1), -sign * twist));
        r.push((c.e(ring + 1), sign * twist));
        r
    };
    let kinds = face_point_kinds(c, next, prev);
    let make = |kind: FacePoint, plus: bool| match (kind, plus) {
        (FacePoint::Regular, _) => Some(regular_face_point(c)),
        (FacePoint::Computed, true) => Some(computed(1.0, c.k, ep, next, &edges[(i + 1) % 3][2])),
        (FacePoint::Computed, false) => Some(computed(
            -1.0,
            (c.k + 1) % val,
            em,
            prev,
            &edges[(i + 2) % 3][1],
        )),
        (FacePoint::CopyOther, _) => None,
    };
    resolve_copies(make(kinds[0], true), make(kinds[1], false))
}

/// The quartic middle point `M_e` of edge `e` (corner `e` to corner `e + 1`): the box
/// spline's where the edge is a boundary or both ends are regular, else the average of the
/// two cubic edge points along it.
fn mid_edge_point(cs: &[Corner], edges: &[[Row; 3]], e: usize) -> Row {
    let (c0, c1) = (&cs[e], &cs[(e + 1) % 3]);
    let boundary_edge = c0.ep_on_boundary() && c1.em_on_boundary();
    // One end sees the edge as a boundary, the other does not: a dart-like edge.
    let dart_edge = c0.ep_on_boundary() != c1.em_on_boundary();
    if boundary_edge || (c0.regular() && c1.regular() && !dart_edge) {
        if c0.ep_on_boundary() {
            return vec![(c0.v, 0.5), (c0.next(), 0.5)];
        }
        // The vertex of the other triangle across the edge: e_{k−1} around corner e.
        let across = c0.e(c0.k + c0.valence() - 1);
        return vec![
            (c0.v, 1.0 / 3.0),
            (c0.next(), 1.0 / 3.0),
            (c0.prev(), 1.0 / 6.0),
            (across, 1.0 / 6.0),
        ];
    }
    let mut m = Vec::new();
    add(&mut m, 0.5, &edges[e][1]);
    add(&mut m, 0.5, &edges[(e + 1) % 3][2]);
    m
}

/// The 18 points of the Gregory triangle of triangle `f`: per corner
/// `P, Ep, Em, Fp, Fm`, then the mid-edge points `M_0, M_1, M_2`.
pub(crate) fn gregory_triangle(
    t: &Topology,
    tags: &[VTag],
    f: usize,
    rules: &CornerRules,
) -> Vec<Row> {
    let cs = corners(t, tags, f, rules);
    let cubic: Vec<[Row; 3]> = cs.iter().map(edge_points).collect();
    let mut out = Vec::with_capacity(18);
    for (i, [p, ep, em]) in cubic.iter().enumerate() {
        let [fp, fm] = face_points(&cs, &cubic, i);
        // Degree elevation of the boundary curves: the quartic's point next to a corner.
        let quartic = |e: &Row| {
            let mut r = Vec::new();
            add(&mut r, 0.25, p);
            add(&mut r, 0.75, e);
            r
        };
        out.extend([p.clone(), quartic(ep), quartic(em), fp, fm]);
    }
    out.extend((0..3).map(|e| mid_edge_point(&cs, &cubic, e)));
    out
}

/// The Gregory point standing for each quartic Bézier point `p_{ijk}` in the fit, row by
/// row from corner 0 (`p004, p103, …, p040`): one face point of each interior pair
/// (`Fm0`, `Fp1`, `Fm2`), as OpenSubdiv picks them.
const FIT_SOURCES: [usize; 15] = [0, 1, 15, 7, 5, 2, 4, 8, 6, 17, 14, 16, 11, 12, 10];

/// The 12 points of the box-spline end cap of triangle `f`, fitted to its Gregory
/// triangle.
pub(crate) fn box_spline(t: &Topology, tags: &[VTag], f: usize, rules: &CornerRules) -> Vec<Row> {
    let gregory = gregory_triangle(t, tags, f, rules);
    box_fit::matrix()
        .iter()
        .map(|weights| {
            let mut r = Vec::new();
            for (&w, &g) in weights.iter().zip(&FIT_SOURCES) {
                add(&mut r, w, &gregory[g]);
            }
            r
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use subd_mesh::TopologyBuilder;
    use subd_schemes::{Options, Scheme};

    use super::*;
    use crate::patch_table::basis;
    use crate::patch_table::features::Regularity;
    use crate::patch_table::gather;
    use crate::patch_table::levels::PatchLevel;

    const RULES: CornerRules = CornerRules {
        inf_sharp: false,
        legacy_sharp_corners: true,
    };

    /// A Loop level of `base` (topology and tags).
    fn level(base: &Topology) -> PatchLevel {
        let reg = Regularity {
            valence: 6,
            face_size: 3,
        };
        PatchLevel::base(base, &Scheme::Loop, &Options::default(), reg).unwrap()
    }

    /// A regular triangle grid of 7 × 7 vertices, and its triangle whose corners are the
    /// vertices (3, 3), (4, 3), (3, 4).
    fn triangle_grid() -> (Topology, usize) {
        let id = |i: u32, j: u32| i + 7 * j;
        let mut faces = Vec::new();
        for j in 0..6 {
            for i in 0..6 {
                faces.extend([id(i, j), id(i + 1, j), id(i, j + 1)]);
                faces.extend([id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let t = TopologyBuilder::new(49).build(&[3; 72], &faces).unwrap();
        (t, 2 * (3 * 6 + 3))
    }

    fn dense(row: &Row) -> BTreeMap<u32, f64> {
        let mut m = BTreeMap::new();
        for &(v, w) in row {
            *m.entry(v).or_insert(0.0) += w;
        }
        m.retain(|_, w: &mut f64| w.abs() > 1e-12);
        m
    }

    #[test]
    fn a_regular_triangle_gives_its_box_spline_patch_back() {
        let (t, f) = triangle_grid();
        let l = level(&t);
        let regular = gather::triangle_points(&l.topology, f, 0);
        let fitted = box_spline(&l.topology, &l.tags, f, &RULES);
        for (k, row) in fitted.iter().enumerate() {
            let d = dense(row);
            assert_eq!(d.len(), 1, "point {k}: {d:?}");
            assert!((d[&regular[k]] - 1.0).abs() < 1e-11, "point {k}: {d:?}");
        }
    }

    #[test]
    fn a_regular_gregory_triangle_is_the_box_spline_patch() {
        let (t, f) = triangle_grid();
        let l = level(&t);
        let regular = gather::triangle_points(&l.topology, f, 0);
        let gregory = gregory_triangle(&l.topology, &l.tags, f, &RULES);
        let spline = crate::evaluation::loop_patch::box_spline().unwrap();
        for &(s, u) in &[
            (0.2, 0.3),
            (0.0, 0.0),
            (0.6, 0.1),
            (0.05, 0.9),
            (1.0 / 3.0, 1.0 / 3.0),
        ] {
            let gw = basis::gregory_triangle(s, u);
            let bw = basis::box_spline(spline, s, u, 0);
            for d in 0..6 {
                // Both as weights of the level's vertices.
                let mut a = Row::new();
                for (k, g) in gregory.iter().enumerate() {
                    add(&mut a, gw[d][k], g);
                }
                let mut b = dense(&regular.iter().zip(bw[d]).map(|(&v, w)| (v, w)).collect());
                for (v, w) in dense(&a) {
                    *b.entry(v).or_insert(0.0) -= w;
                }
                let worst = b.values().fold(0.0f64, |m, w| m.max(w.abs()));
                assert!(worst < 1e-11, "({s}, {u}) derivative {d}: off by {worst}");
            }
        }
    }
}
