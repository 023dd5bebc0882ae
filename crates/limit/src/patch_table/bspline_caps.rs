//! B-spline end caps of Catmull-Clark patches: a bicubic B-spline patch (16 points, the
//! regular patches' type and array) standing in for an irregular quad (OpenSubdiv's
//! `BSplineConverter`; formulas restated, code our own).
//!
//! **Isolated interior corner.** When one corner is an interior extraordinary vertex
//! (valence `n ≥ 3`) and the other three are regular, nine of the 16 points are the level's
//! own vertices (the face and the regular grid beyond it) and seven are placed so that the
//! patch interpolates the corner's limit position `P` and its edge points `Ep`, `Em` (the
//! Gregory patch's), the outer points continuing the neighbouring grid. For `n = 4` this
//! gives the regular patch back.
//!
//! **Any other irregular quad.** The 20-point Gregory patch's Bézier net (its `Fp` points
//! inside, the `Fm` ones left out) converted back to B-spline points by the inverse of the
//! cubic B-spline-to-Bézier map, in both directions.

use subd_mesh::Topology;

use super::end_caps::{Corner, CornerRules, Row, add, corners, gregory_points, interior_points};
use super::features::VTag;
use super::gather;

/// One point of an end cap: a vertex of the level taken as it is, or a new local point.
#[derive(Debug)]
pub(crate) enum CapPoint {
    Vertex(u32),
    Local(Row),
}

/// The 16 points of the B-spline end cap of quad `f` (rows bottom to top, as a regular
/// patch's).
pub(crate) fn bspline(t: &Topology, tags: &[VTag], f: usize, rules: &CornerRules) -> Vec<CapPoint> {
    let cs = corners(t, tags, f, rules);
    match isolated_corner(&cs) {
        Some(i) => isolated(t, f, &cs, i),
        None => from_gregory(&gregory_points(&cs))
            .into_iter()
            .map(CapPoint::Local)
            .collect(),
    }
}

/// The one irregular corner when it is the only one, interior, of valence at least 3, and
/// no corner is on a boundary or sharp.
fn isolated_corner(cs: &[Corner]) -> Option<usize> {
    let mut irregular = (0..cs.len()).filter(|&i| !cs[i].regular());
    let i = irregular.next()?;
    let clean = cs.iter().all(|c| !c.boundary && !c.sharp);
    (irregular.next().is_none() && clean && cs[i].valence() > 2).then_some(i)
}

/// A corner's place in the 4 × 4 grid (column, row) and its two unit steps, towards the
/// next corner and towards the previous one.
struct Frame {
    at: (i32, i32),
    next: (i32, i32),
    prev: (i32, i32),
}

const FRAMES: [Frame; 4] = [
    Frame {
        at: (1, 1),
        next: (1, 0),
        prev: (0, 1),
    },
    Frame {
        at: (2, 1),
        next: (0, 1),
        prev: (-1, 0),
    },
    Frame {
        at: (2, 2),
        next: (-1, 0),
        prev: (0, -1),
    },
    Frame {
        at: (1, 2),
        next: (0, -1),
        prev: (1, 0),
    },
];

/// The 4 × 4 grid index of the point `x` steps towards corner `i`'s next corner and `y`
/// towards its previous one, from corner `i` (the grid turns with the corner).
fn grid(i: usize, x: i32, y: i32) -> usize {
    let f = &FRAMES[i];
    let col = f.at.0 + x * f.next.0 + y * f.prev.0;
    let row = f.at.1 + x * f.next.1 + y * f.prev.1;
    (4 * row + col) as usize
}

/// `Σ wᵢ rowᵢ`.
fn combine(terms: &[(f64, &Row)]) -> Row {
    let mut r = Row::new();
    for &(w, row) in terms {
        add(&mut r, w, row);
    }
    r
}

/// The ring points on one side of the irregular corner `V`, seen from the edge towards
/// `along`: the face's corners `diag` and `across`, and behind the corner (beyond the
/// edge from the face) `back` and its diagonal `back_diag`.
struct Side<'a> {
    along: &'a Row,
    diag: &'a Row,
    across: &'a Row,
    back: &'a Row,
    back_diag: &'a Row,
}

/// The two points behind the corner's row along an edge, `(behind V, behind along)`:
/// chosen so that the patch's Bézier point next to the corner on that edge is the edge
/// point `e`, while the one after it keeps the value the actual ring gives (`X + 2X'`
/// equals `back + 2 back_diag`).
fn behind_edge(e: &Row, v: &Row, s: &Side) -> (Row, Row) {
    let third = 1.0 / 3.0;
    let behind_v = combine(&[
        (36.0 * third, e),
        (-16.0 * third, v),
        (-8.0 * third, s.along),
        (-2.0 * third, s.diag),
        (-4.0 * third, s.across),
        (-third, s.back),
        (-2.0 * third, s.back_diag),
    ]);
    let behind_along = combine(&[
        (-6.0, e),
        (8.0 * third, v),
        (4.0 * third, s.along),
        (third, s.diag),
        (2.0 * third, s.across),
        (2.0 * third, s.back),
        (4.0 * third, s.back_diag),
    ]);
    (behind_v, behind_along)
}

/// The isolated-corner end cap: the seven points on the irregular corner's outer side
/// solved for from its limit position and edge points, the rest the level's vertices.
fn isolated(t: &Topology, f: usize, cs: &[Corner], i: usize) -> Vec<CapPoint> {
    let c = &cs[i];
    let k = c.k;
    // The regular corners' grid: every slot off the irregular corner's outer side is right.
    let regular = gather::quad_points(t, f, 0);
    let at = |x: i32, y: i32| vec![(regular[grid(i, x, y)], 1.0)];
    let one = |v: u32| vec![(v, 1.0)];
    // The patch face and the ring around the corner, named by their grid places.
    let p0 = one(c.v);
    let (p1, p2, p3) = (one(c.e(k)), one(c.f(k)), one(c.e(k + 1)));
    let (p4, p15) = (one(c.e(k + 2)), one(c.f(k + 1)));
    let (p6, p7) = (one(c.e(k + c.m - 1)), one(c.f(k + c.m - 1)));
    let (p8, p14) = (at(2, -1), at(-1, 2));
    let [p, ep, em] = interior_points(c);
    let next_side = Side {
        along: &p1,
        diag: &p2,
        across: &p3,
        back: &p6,
        back_diag: &p7,
    };
    let prev_side = Side {
        along: &p3,
        diag: &p2,
        across: &p1,
        back: &p4,
        back_diag: &p15,
    };
    let (x1, x3) = behind_edge(&ep, &p0, &next_side);
    let (x2, x4) = behind_edge(&em, &p0, &prev_side);
    // The outer rows run on parallel to the ring's.
    let x5 = combine(&[(1.0, &x1), (1.0, &p8), (-1.0, &p6)]);
    let x6 = combine(&[(1.0, &x2), (1.0, &p14), (-1.0, &p4)]);
    // The diagonal point puts the patch's corner on the limit position.
    let x0 = combine(&[
        (36.0, &p),
        (-16.0, &p0),
        (-4.0, &p1),
        (-1.0, &p2),
        (-4.0, &p3),
        (-4.0, &x1),
        (-4.0, &x2),
        (-1.0, &x3),
        (-1.0, &x4),
    ]);
    let mut out: Vec<Option<CapPoint>> = (0..16).map(|_| None).collect();
    for (x, y, row) in [
        (-1, -1, x0),
        (0, -1, x1),
        (-1, 0, x2),
        (1, -1, x3),
        (-1, 1, x4),
        (2, -1, x5),
        (-1, 2, x6),
    ] {
        out[grid(i, x, y)] = Some(CapPoint::Local(row));
    }
    out.into_iter()
        .zip(regular)
        .map(|(p, v)| p.unwrap_or(CapPoint::Vertex(v)))
        .collect()
}

/// The inverse of the cubic B-spline-to-Bézier map of one segment (Bézier = M · B-spline
/// with `M = [1 4 1 0; 0 4 2 0; 0 2 4 0; 0 1 4 1] / 6`).
const BEZIER_TO_BSPLINE: [[f64; 4]; 4] = [
    [6.0, -7.0, 2.0, 0.0],
    [0.0, 2.0, -1.0, 0.0],
    [0.0, -1.0, 2.0, 0.0],
    [0.0, 2.0, -7.0, 6.0],
];

/// The Gregory point in each place (column, row) of the 4 × 4 Bézier net: the boundary's
/// `P`, `Ep`, `Em`, and inside each corner's `Fp`.
const BEZIER_NET: [[usize; 4]; 4] = [
    [0, 1, 7, 5],
    [2, 3, 8, 6],
    [16, 18, 13, 12],
    [15, 17, 11, 10],
];

/// The 16 B-spline points of the patch whose Bézier net is the Gregory patch's
/// (`gregory`: its 20 points).
fn from_gregory(gregory: &[Row]) -> Vec<Row> {
    let mut out = Vec::with_capacity(16);
    for by_row in &BEZIER_TO_BSPLINE {
        for by_col in &BEZIER_TO_BSPLINE {
            let mut row = Row::new();
            for (i, net_row) in BEZIER_NET.iter().enumerate() {
                for (j, &g) in net_row.iter().enumerate() {
                    let w = by_row[i] * by_col[j];
                    if w != 0.0 {
                        add(&mut row, w, &gregory[g]);
                    }
                }
            }
            out.push(row);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use subd_mesh::TopologyBuilder;
    use subd_schemes::{Options, Refinement, Scheme};

    use super::*;
    use crate::patch_table::features::Regularity;
    use crate::patch_table::levels::PatchLevel;

    const RULES: CornerRules = CornerRules {
        inf_sharp: false,
        legacy_sharp_corners: true,
    };

    /// A Catmull-Clark level (topology and tags) of `base`, refined `levels` times.
    fn level(base: &Topology, levels: usize) -> PatchLevel {
        let o = Options::default();
        let r = Refinement::new(base, Scheme::CatmullClark, &o, levels).unwrap();
        let reg = Regularity {
            valence: 4,
            face_size: 4,
        };
        PatchLevel::base(&r.into_topology(levels), &Scheme::CatmullClark, &o, reg).unwrap()
    }

    /// A stencil with its entries summed per vertex and zeros dropped.
    fn dense(row: &Row) -> BTreeMap<u32, f64> {
        let mut m = BTreeMap::new();
        for &(v, w) in row {
            *m.entry(v).or_insert(0.0) += w;
        }
        m.retain(|_, w: &mut f64| w.abs() > 1e-13);
        m
    }

    fn assert_same(a: &Row, b: &Row, what: &str) {
        let (a, b) = (dense(a), dense(b));
        assert_eq!(
            a.keys().collect::<Vec<_>>(),
            b.keys().collect::<Vec<_>>(),
            "{what}"
        );
        for (v, w) in &a {
            assert!(
                (w - b[v]).abs() < 1e-12,
                "{what}: vertex {v}: {w} vs {}",
                b[v]
            );
        }
    }

    fn as_row(p: &CapPoint) -> Row {
        match p {
            CapPoint::Vertex(v) => vec![(*v, 1.0)],
            CapPoint::Local(r) => r.clone(),
        }
    }

    /// A 6 × 6 grid of quads.
    fn grid_mesh() -> Topology {
        let mut faces = Vec::new();
        for y in 0..6u32 {
            for x in 0..6u32 {
                let v = x + 7 * y;
                faces.extend([v, v + 1, v + 8, v + 7]);
            }
        }
        TopologyBuilder::new(49).build(&[4; 36], &faces).unwrap()
    }

    #[test]
    fn both_conversions_give_a_regular_patch_back() {
        let l = level(&grid_mesh(), 0);
        let f = 2 * 6 + 2;
        let cs = corners(&l.topology, &l.tags, f, &RULES);
        let regular = gather::quad_points(&l.topology, f, 0);
        let from_gregory = from_gregory(&gregory_points(&cs));
        for i in 0..4 {
            let isolated = isolated(&l.topology, f, &cs, i);
            for k in 0..16 {
                let want = vec![(regular[k], 1.0)];
                assert_same(
                    &as_row(&isolated[k]),
                    &want,
                    &format!("corner {i}, point {k}"),
                );
                assert_same(&from_gregory[k], &want, &format!("from Gregory, point {k}"));
            }
        }
    }

    #[test]
    fn an_isolated_corner_interpolates_its_limit_and_edge_points() {
        // A cube refined once: each face at an original corner has one valence-3 corner
        // and three regular ones.
        let faces = [
            0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4,
        ];
        let cube = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
        let l = level(&cube, 1);
        let mut checked = 0;
        for f in 0..l.topology.num_faces() {
            let cs = corners(&l.topology, &l.tags, f, &RULES);
            let Some(i) = isolated_corner(&cs) else {
                continue;
            };
            let points = bspline(&l.topology, &l.tags, f, &RULES);
            let locals = points
                .iter()
                .filter(|p| matches!(p, CapPoint::Local(_)))
                .count();
            assert_eq!(locals, 7);
            // The Bézier corner net of the patch at corner i: B-spline rows (1, 4, 1)/6 for
            // the corner, (0, 4, 2)/6 for the point next to it.
            let corner_w = [1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0, 0.0];
            let next_w = [0.0, 4.0 / 6.0, 2.0 / 6.0, 0.0];
            let bezier = |wx: &[f64; 4], wy: &[f64; 4]| {
                let mut r = Row::new();
                for (x, a) in wx.iter().enumerate() {
                    for (y, b) in wy.iter().enumerate() {
                        let p = as_row(&points[grid(i, x as i32 - 1, y as i32 - 1)]);
                        add(&mut r, a * b, &p);
                    }
                }
                r
            };
            let [p, ep, em] = interior_points(&cs[i]);
            assert_same(&bezier(&corner_w, &corner_w), &p, "P");
            assert_same(&bezier(&next_w, &corner_w), &ep, "Ep");
            assert_same(&bezier(&corner_w, &next_w), &em, "Em");
            checked += 1;
        }
        assert_eq!(checked, 24);
    }

    #[test]
    fn the_inverse_map_inverts_the_b_spline_to_bezier_map() {
        let m = [
            [1.0, 4.0, 1.0, 0.0],
            [0.0, 4.0, 2.0, 0.0],
            [0.0, 2.0, 4.0, 0.0],
            [0.0, 1.0, 4.0, 1.0],
        ];
        for (i, m_row) in m.iter().enumerate() {
            for j in 0..4 {
                let x: f64 = m_row
                    .iter()
                    .zip(&BEZIER_TO_BSPLINE)
                    .map(|(a, inv_row)| a / 6.0 * inv_row[j])
                    .sum();
                assert!((x - f64::from(u8::from(i == j))).abs() < 1e-15);
            }
        }
    }

    #[test]
    fn the_grid_frames_put_each_corner_on_the_face() {
        assert_eq!(
            [grid(0, 0, 0), grid(1, 0, 0), grid(2, 0, 0), grid(3, 0, 0)],
            [5, 6, 10, 9]
        );
        // Corner i's next corner is corner i + 1.
        for i in 0..4 {
            assert_eq!(grid(i, 1, 0), grid((i + 1) % 4, 0, 0));
            assert_eq!(grid(i, 0, 1), grid((i + 3) % 4, 0, 0));
        }
    }
}
