//! End caps of Catmull-Clark patches: the points of a Gregory patch (20) or a bilinear quad
//! (4) fitted to an irregular face, as weights of the face's level vertices
//! (OpenSubdiv's `GregoryConverter` and `LinearConverter`; formulas restated, code our own);
//! and the corners every end cap is built from, quads and triangles alike
//! (`bspline_caps` and `loop_caps` build the other kinds on them).
//!
//! **Corners.** Each corner `V` of the face sees a fan of faces `G_0 … G_{m−1}` counter-
//! clockwise, the patch face at position `k`: the whole ring of an interior vertex, the fan
//! from a boundary, or (at a non-manifold vertex, or along infinitely sharp edges when they
//! bound patches) the span between singular edges. In `G_j`, `e_j` is the vertex after `V`
//! and `f_j` the one diagonally across; a boundary fan adds `e_m`, the vertex before `V` in
//! its last face.
//!
//! **Points.** Per corner the limit position `P` and two points along the edges, `Ep`
//! towards the next corner and `Em` towards the previous one, from the limit masks of the
//! corner's kind (Halstead et al. 1993 for interior vertices, with OpenSubdiv's tangent
//! scale `1/(n λ)`; the B-spline crease mask on boundaries; `V` itself at sharp corners).
//! The interior points `Fp`, `Fm` make the Gregory patch's cross-boundary tangents meet
//! those of the neighbouring patches (Loop, Schaefer, Ni, Castaño 2009, "Approximating
//! subdivision surfaces with Gregory patches for hardware tessellation").

use std::f64::consts::PI;

use subd_mesh::Topology;
use subd_mesh::tags::is_infinite;

use super::features::VTag;

/// A point as weights of the level's vertices.
pub(crate) type Row = Vec<(u32, f64)>;

/// Appends `w` times `row` to `out`.
pub(crate) fn add(out: &mut Row, w: f64, row: &[(u32, f64)]) {
    out.extend(row.iter().map(|&(i, x)| (i, w * x)));
}

pub(crate) fn point(v: u32) -> Row {
    vec![(v, 1.0)]
}

/// One corner of the patch face and its fan.
#[derive(Debug)]
pub(crate) struct Corner {
    pub v: u32,
    /// Faces in the fan.
    pub m: usize,
    /// The patch face's position in the fan.
    pub k: usize,
    /// The fan does not close around `v`.
    pub boundary: bool,
    pub sharp: bool,
    /// `e_0 … e_{m−1}` (and `e_m` on a boundary).
    pub e: Vec<u32>,
    /// `f_0 … f_{m−1}` (quads only: the vertex diagonally across `G_j`).
    pub f: Vec<u32>,
    /// Faces around a regular interior vertex: 4 for quads, 6 for triangles.
    regular_faces: usize,
}

impl Corner {
    pub fn valence(&self) -> usize {
        self.m + usize::from(self.boundary)
    }
    /// `e_i`, the index taken around the fan's edges.
    pub fn e(&self, i: usize) -> u32 {
        self.e[i % self.valence()]
    }
    pub fn f(&self, i: usize) -> u32 {
        self.f[i % self.m]
    }
    /// The patch face's next corner (`e_k`).
    pub fn next(&self) -> u32 {
        self.e[self.k]
    }
    /// The patch face's previous corner (`e_{k+1}`).
    pub fn prev(&self) -> u32 {
        self.e((self.k + 1) % self.valence())
    }
    /// Regular valence (a boundary fan counts double) and not sharp.
    pub fn regular(&self) -> bool {
        (self.m << usize::from(self.boundary)) == self.regular_faces && !self.sharp
    }
    /// `Ep` lies along the boundary edge `e_0`.
    pub fn ep_on_boundary(&self) -> bool {
        self.boundary && self.k == 0
    }
    /// `Em` lies along the boundary edge `e_m`.
    pub fn em_on_boundary(&self) -> bool {
        self.boundary && self.k + 1 == self.m
    }
    /// The cosine of the corner's face angle, which the face points blend with: the
    /// regular angle's exactly (0 for quads, ½ for triangles), else `cos(2π/m)` (`π/m` on a
    /// boundary).
    pub fn cos_a(&self) -> f64 {
        if self.regular() {
            if self.regular_faces == 4 { 0.0 } else { 0.5 }
        } else {
            let full = if self.boundary { PI } else { 2.0 * PI };
            (full / self.m as f64).cos()
        }
    }
}

/// How a corner's face point is made (OpenSubdiv's `GregoryConverter::Initialize`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum FacePoint {
    /// The regular-neighbourhood formula.
    Regular,
    /// Blended from the edge points of this corner and the next one along the edge.
    Computed,
    /// The same as the corner's other face point: beside a boundary edge the two sides
    /// must agree, the edge having no second patch to match.
    CopyOther,
}

/// How `Fp` and `Fm` of corner `c` are made, `next` and `prev` its neighbours around the
/// face. Both sides of a face point must be regular for the regular formula; a 1-face
/// corner always uses it.
pub(crate) fn face_point_kinds(c: &Corner, next: &Corner, prev: &Corner) -> [FacePoint; 2] {
    let mut fp_regular = c.regular() && next.regular();
    let mut fm_regular = c.regular() && prev.regular();
    let (mut fp_copy, mut fm_copy) = (false, false);
    if c.boundary {
        if c.m > 1 {
            if c.ep_on_boundary() {
                fp_regular = fm_regular;
                fp_copy = !fp_regular;
            }
            if c.em_on_boundary() {
                fm_regular = fp_regular;
                fm_copy = !fm_regular;
            }
        } else {
            fp_regular = true;
            fm_regular = true;
        }
    }
    let kind = |regular: bool, copy: bool| match (regular, copy) {
        (true, _) => FacePoint::Regular,
        (false, true) => FacePoint::CopyOther,
        (false, false) => FacePoint::Computed,
    };
    [kind(fp_regular, fp_copy), kind(fm_regular, fm_copy)]
}

/// What decides a corner's fan and sharpness.
pub(crate) struct CornerRules {
    /// Infinitely sharp edges bound patches (`useInfSharpPatch`).
    pub inf_sharp: bool,
    /// Smooth one-face corners are taken as sharp (`generateLegacySharpCornerPatches`).
    pub legacy_sharp_corners: bool,
}

/// Position of `v` in face `g`.
fn corner_of(t: &Topology, g: usize, v: u32) -> usize {
    t.face_vertices(g)
        .iter()
        .position(|&x| x == v)
        .expect("a corner of its face")
}

/// The face across edge `e` from `g`, if the edge has exactly two faces.
fn across(t: &Topology, g: usize, e: u32) -> Option<usize> {
    match t.edge_faces(e as usize) {
        [a, b] => Some(if *a as usize == g { *b } else { *a } as usize),
        _ => None,
    }
}

/// The fan of corner `c` of face `f` (module docs).
fn corner(t: &Topology, tags: &[VTag], f: usize, c: usize, rules: &CornerRules) -> Corner {
    let v = t.face_vertices(f)[c];
    let tag = tags[v as usize];
    let span = tag.has(VTag::NON_MANIFOLD)
        || (rules.inf_sharp && tag.has(VTag::INF_SHARP_EDGES) && tag.rule() != VTag::RULE_DART);
    let singular = |e: u32| {
        let e = e as usize;
        t.edge_faces(e).len() != 2
            || t.is_non_manifold_edge(e)
            || (span && rules.inf_sharp && is_infinite(t.edge_sharpness(e)))
    };
    let leading = |g: usize| t.face_edges(g)[corner_of(t, g, v)];
    let trailing = |g: usize| {
        let n = t.face_size(g);
        t.face_edges(g)[(corner_of(t, g, v) + n - 1) % n]
    };
    // Back (clockwise) from f across leading edges to the fan's first face.
    let (mut first, mut k, mut periodic) = (f, 0usize, false);
    while !singular(leading(first)) {
        let g = across(t, first, leading(first)).expect("a regular edge has two faces");
        if g == f {
            periodic = true;
            break;
        }
        first = g;
        k += 1;
    }
    let mut fan = vec![first];
    let mut g = first;
    loop {
        let e = trailing(g);
        if singular(e) {
            break;
        }
        let next = across(t, g, e).expect("a regular edge has two faces");
        if next == first {
            break;
        }
        fan.push(next);
        g = next;
    }
    let boundary = !periodic;
    let at = |g: usize, d: usize| {
        let fv = t.face_vertices(g);
        fv[(corner_of(t, g, v) + d) % fv.len()]
    };
    let mut e: Vec<u32> = fan.iter().map(|&g| at(g, 1)).collect();
    let f_pts: Vec<u32> = fan.iter().map(|&g| at(g, 2)).collect();
    if boundary {
        let last = *fan.last().expect("a fan has a face");
        e.push(at(last, t.face_size(last) - 1));
    }
    let m = fan.len();
    let regular_faces = if t.face_size(f) == 3 { 6 } else { 4 };
    let sharp = if tag.has(VTag::CORNER) {
        true
    } else if tag.has(VTag::NON_MANIFOLD) {
        tag.has(VTag::INF_SHARP)
    } else if rules.inf_sharp {
        if span {
            !tag.has(VTag::INF_SHARP_CREASE)
        } else {
            tag.has(VTag::INF_SHARP)
        }
    } else {
        // Without infinitely sharp patches, end caps treat sharp features as smooth.
        false
    };
    let legacy = rules.legacy_sharp_corners
        && m == 1
        && tag.has(VTag::BOUNDARY)
        && tag.has(VTag::XORDINARY)
        && !tag.has(VTag::INF_SHARP | VTag::NON_MANIFOLD);
    Corner {
        v,
        m,
        k,
        boundary,
        sharp: sharp || legacy,
        e,
        f: f_pts,
        regular_faces,
    }
}

/// OpenSubdiv's tangent scale `1 / (n λ_n)` of an interior vertex of valence `n`
/// (0 below 3).
fn tangent_scale(n: usize) -> f64 {
    if n <= 2 {
        return 0.0;
    }
    let c = (2.0 * PI / n as f64).cos();
    16.0 / (n as f64 * (c + 5.0 + ((c + 9.0) * (c + 1.0)).sqrt()))
}

/// The limit position of an interior vertex (Catmull-Clark's limit mask).
fn interior_limit(c: &Corner) -> Row {
    let n = c.m as f64;
    let (we, wf) = (4.0 / (n * (n + 5.0)), 1.0 / (n * (n + 5.0)));
    let mut p = vec![(c.v, n / (n + 5.0))];
    for j in 0..c.m {
        p.push((c.e[j], we));
        p.push((c.f[j], wf));
    }
    p
}

/// The limit position of a boundary vertex (the cubic B-spline of its boundary).
pub(crate) fn boundary_limit(c: &Corner) -> Row {
    vec![(c.v, 2.0 / 3.0), (c.e[0], 1.0 / 6.0), (c.e[c.m], 1.0 / 6.0)]
}

/// `P`, `Ep`, `Em` of an interior corner of any valence.
pub(crate) fn interior_points(c: &Corner) -> [Row; 3] {
    let n = c.m;
    let p = interior_limit(c);
    let theta = 2.0 * PI / n as f64;
    let tc = tangent_scale(n) * 0.5 / (n as f64 + 5.0);
    let cs: Vec<f64> = (0..n).map(|i| tc * (theta * i as f64).cos()).collect();
    let te: Vec<f64> = (0..n)
        .map(|j| 4.0 * cs[j] + 2.0 * (cs[(j + 1) % n] + cs[(j + n - 1) % n]))
        .collect();
    let tf: Vec<f64> = (0..n).map(|j| cs[j] + cs[(j + 1) % n]).collect();
    let along = |shift: usize| {
        let mut r = p.clone();
        for j in 0..n {
            r.push((c.e(j + shift), te[j]));
            r.push((c.f(j + shift), tf[j]));
        }
        r
    };
    [p.clone(), along(c.k), along(c.k + 1)]
}

/// `P`, `Ep`, `Em` of an irregular boundary corner (fan of `m ≥ 2` faces).
fn boundary_points(c: &Corner) -> [Row; 3] {
    let m = c.m;
    let p = boundary_limit(c);
    let theta = PI / m as f64;
    let (cs, sn) = (theta.cos(), theta.sin());
    let d = 1.0 / (3.0 * m as f64 + cs);
    let mut interior: Row = vec![(c.v, -4.0 * sn * d / 3.0)];
    let end = -(1.0 + 2.0 * cs) * (1.0 + cs).sqrt() / (1.0 - cs).sqrt() * d / 3.0;
    interior.push((c.e[0], end));
    interior.push((c.e[m], end));
    for i in 1..m {
        interior.push((c.e[i], 4.0 * (i as f64 * theta).sin() * d / 3.0));
    }
    for i in 0..m {
        let w = ((i as f64 * theta).sin() + ((i + 1) as f64 * theta).sin()) * d / 3.0;
        interior.push((c.f[i], w));
    }
    let along_boundary = |end: u32| vec![(c.v, 2.0 / 3.0), (end, 1.0 / 3.0)];
    let at = |j: usize| {
        let a = j as f64 * theta;
        let mut r = p.clone();
        add(&mut r, a.sin(), &interior);
        r.push((c.e[0], a.cos() / 6.0));
        r.push((c.e[m], -a.cos() / 6.0));
        r
    };
    let ep = if c.k == 0 {
        along_boundary(c.e[0])
    } else {
        at(c.k)
    };
    let em = if c.k == m - 1 {
        along_boundary(c.e[m])
    } else {
        at(c.k + 1)
    };
    [p, ep, em]
}

/// `P`, `Ep`, `Em` of a regular interior corner (the bicubic B-spline's points).
fn regular_interior_points(c: &Corner) -> [Row; 3] {
    let k = c.k;
    let mut p = vec![(c.v, 4.0 / 9.0)];
    for j in 0..4 {
        p.push((c.e[j], 1.0 / 9.0));
        p.push((c.f[j], 1.0 / 36.0));
    }
    let edge = |a: usize| {
        vec![
            (c.v, 4.0 / 9.0),
            (c.e(a), 2.0 / 9.0),
            (c.e(a + 1), 1.0 / 9.0),
            (c.e(a + 3), 1.0 / 9.0),
            (c.f(a), 1.0 / 18.0),
            (c.f(a + 3), 1.0 / 18.0),
        ]
    };
    [p, edge(k), edge(k + 1)]
}

/// `P`, `Ep`, `Em` of a regular boundary corner (two faces).
fn regular_boundary_points(c: &Corner) -> [Row; 3] {
    let p = boundary_limit(c);
    let inner = vec![
        (c.v, 4.0 / 9.0),
        (c.e[1], 2.0 / 9.0),
        (c.e[0], 1.0 / 9.0),
        (c.e[2], 1.0 / 9.0),
        (c.f[0], 1.0 / 18.0),
        (c.f[1], 1.0 / 18.0),
    ];
    let along = |end: u32| vec![(c.v, 2.0 / 3.0), (end, 1.0 / 3.0)];
    if c.k == 0 {
        [p, along(c.e[0]), inner]
    } else {
        [p, inner, along(c.e[2])]
    }
}

/// `P`, `Ep`, `Em` of a corner, by its kind.
fn edge_points(c: &Corner) -> [Row; 3] {
    let towards = |end: u32| vec![(c.v, 2.0 / 3.0), (end, 1.0 / 3.0)];
    if c.sharp {
        [point(c.v), towards(c.next()), towards(c.prev())]
    } else if c.boundary && c.m == 1 {
        let p = vec![
            (c.v, 2.0 / 3.0),
            (c.next(), 1.0 / 6.0),
            (c.prev(), 1.0 / 6.0),
        ];
        [p, towards(c.next()), towards(c.prev())]
    } else if c.regular() && c.boundary {
        regular_boundary_points(c)
    } else if c.regular() {
        regular_interior_points(c)
    } else if c.boundary {
        boundary_points(c)
    } else {
        interior_points(c)
    }
}

/// The corners of face `f` of a level.
pub(crate) fn corners(t: &Topology, tags: &[VTag], f: usize, rules: &CornerRules) -> Vec<Corner> {
    (0..t.face_size(f))
        .map(|c| corner(t, tags, f, c, rules))
        .collect()
}

/// The 20 points of the Gregory patch of quad `f`: per corner `P, Ep, Em, Fp, Fm`.
pub(crate) fn gregory(t: &Topology, tags: &[VTag], f: usize, rules: &CornerRules) -> Vec<Row> {
    gregory_points(&corners(t, tags, f, rules))
}

/// The 20 Gregory points of a quad with corners `cs`.
pub(crate) fn gregory_points(cs: &[Corner]) -> Vec<Row> {
    let edges: Vec<[Row; 3]> = cs.iter().map(edge_points).collect();
    let mut out = Vec::with_capacity(20);
    for (i, [p, ep, em]) in edges.iter().enumerate() {
        let [fp, fm] = quad_face_points(cs, &edges, i);
        out.extend([p.clone(), ep.clone(), em.clone(), fp, fm]);
    }
    out
}

/// `Fp` and `Fm` of corner `i` of a quad, from the corners' `P, Ep, Em`.
fn quad_face_points(cs: &[Corner], edges: &[[Row; 3]], i: usize) -> [Row; 2] {
    let c = &cs[i];
    let (next, prev) = (&cs[(i + 1) % 4], &cs[(i + 3) % 4]);
    let [p, ep, em] = &edges[i];
    let regular = || {
        vec![
            (c.v, 4.0 / 9.0),
            (c.prev(), 2.0 / 9.0),
            (c.next(), 2.0 / 9.0),
            (c.f(c.k), 1.0 / 9.0),
        ]
    };
    let val = c.valence();
    // Loop et al. 2009: the cross tangent blends the two corners' edge points by their
    // face angles, plus the twist of the ring's points on either side of edge `ring`.
    let computed = |sign: f64, ring: usize, near: &Row, far_c: &Corner, far: &Row| {
        let (ca_near, ca_far) = (c.cos_a(), far_c.cos_a());
        let mut r: Row = Vec::new();
        add(&mut r, ca_far / 3.0, p);
        add(&mut r, (3.0 - 2.0 * ca_near - ca_far) / 3.0, near);
        add(&mut r, 2.0 * ca_near / 3.0, far);
        r.extend([
            (c.e(ring + 1), sign / 9.0),
            (c.e(ring + val - 1), -sign / 9.0),
            (c.f(ring), sign / 18.0),
            (c.f(ring + c.m - 1), -sign / 18.0),
        ]);
        r
    };
    let kinds = face_point_kinds(c, next, prev);
    let make = |kind: FacePoint, plus: bool| match (kind, plus) {
        (FacePoint::Regular, _) => Some(regular()),
        (FacePoint::Computed, true) => Some(computed(1.0, c.k, ep, next, &edges[(i + 1) % 4][2])),
        (FacePoint::Computed, false) => Some(computed(
            -1.0,
            (c.k + 1) % val,
            em,
            prev,
            &edges[(i + 3) % 4][1],
        )),
        (FacePoint::CopyOther, _) => None,
    };
    resolve_copies(make(kinds[0], true), make(kinds[1], false))
}

/// `[Fp, Fm]`, the one not made (`None`: a copy) taken from the other.
pub(crate) fn resolve_copies(fp: Option<Row>, fm: Option<Row>) -> [Row; 2] {
    match (fp, fm) {
        (Some(fp), Some(fm)) => [fp, fm],
        (None, Some(fm)) => [fm.clone(), fm],
        (Some(fp), None) => [fp.clone(), fp],
        // Copying both sides needs the patch face first and last in a fan of two or more.
        (None, None) => unreachable!("a corner copies at most one face point"),
    }
}

/// Loop's limit position of an interior vertex of valence `n` (Loop 1987; the valence-6
/// mask `1/2, 1/12`).
pub(crate) fn loop_interior_limit(c: &Corner) -> Row {
    let n = c.m as f64;
    let we = if c.m == 6 {
        1.0 / 12.0
    } else {
        let beta = (2.0 * PI / n).cos() / 4.0 + 3.0 / 8.0;
        let gamma = (5.0 / 8.0 - beta * beta) / n;
        1.0 / (n + 3.0 / (8.0 * gamma))
    };
    let mut p = vec![(c.v, 1.0 - n * we)];
    p.extend(c.e[..c.m].iter().map(|&e| (e, we)));
    p
}

/// The points of the linear end cap of face `f` (a bilinear quad, a linear triangle): its
/// corners' limit positions (`V` at a sharp corner, the B-spline's on a boundary, the
/// scheme's interior mask inside).
pub(crate) fn linear(t: &Topology, tags: &[VTag], f: usize, rules: &CornerRules) -> Vec<Row> {
    let quad = t.face_size(f) == 4;
    corners(t, tags, f, rules)
        .iter()
        .map(|c| {
            if c.sharp {
                point(c.v)
            } else if c.boundary {
                boundary_limit(c)
            } else if quad {
                interior_limit(c)
            } else {
                loop_interior_limit(c)
            }
        })
        .collect()
}
