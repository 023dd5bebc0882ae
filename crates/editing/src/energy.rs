//! The thin-plate (and membrane) energy of a Catmull-Clark limit surface as a quadratic form
//! in its control vertices (Li et al. 2008 §4).
//!
//! `E(S) = ∬ S_uu² + 2 S_uv² + S_vv²` (+ `w ∬ S_u² + S_v²`), summed over the faces in each
//! face's own parameters (sub-faces for non-quads), is `Σ_c X_cᵀ Q X_c` over the three
//! coordinates, with one sparse symmetric `Q` per mesh.
//!
//! * **Regular faces** are bicubic B-splines: `Q₀ = G₂⊗G₀ + 2 G₁⊗G₁ + G₀⊗G₂` with `Gₖ` the
//!   4 × 4 Gram matrices of the k-th derivatives of the uniform cubic B-spline basis, exact by
//!   4-point Gauss–Legendre quadrature (the products are polynomials of degree ≤ 6).
//! * **A face with one extraordinary vertex** (valence n) is Stam's corner patch: after m
//!   steps its quarters k = 1, 2, 3 are B-splines with control points `Ā_k A^(m−1) C` on
//!   squares of side `2^−m`. Second derivatives scale by `4^m` there and the area by `4^−m`,
//!   so `Q = Σ_{m≥1} 4^m (A^(m−1))ᵀ M A^(m−1)` with `M = Σ_k Ā_kᵀ Q₀ Ā_k`. In A's eigenbasis
//!   the pair (λᵢ, λⱼ) contributes `Gᵢⱼ · 4/(1 − 4λᵢλⱼ)`: the denominator Li et al. print
//!   as `4 − λᵢλⱼ` is `¼ − λᵢλⱼ` (with the 4 pulled out), a geometric series in `4λᵢλⱼ`.
//!   The series is summed here with the matrices themselves (robust to A's defective
//!   eigenvalues), with the eigenvalue 1 taken out first: `M` annihilates constants, so
//!   `A' = A − 1 wᵀ` (w the limit mask) gives the same sum without the growing `4^m` times
//!   rounding of the constant part.
//! * **Which pairs carry energy**: the constant pair (λ = 1) never does. The subdominant
//!   pair λ₁ = λ₂ (the characteristic map) does: its quarters are not linear in (u, v). For
//!   valence 3, λ₁ ≈ 0.41 and `4λ₁² < 1`: the series converges and is used whole. From
//!   valence 5 on, λ₁ > ½ (0.55 at n = 5, → 0.65 as n grows): the energy of the face is
//!   *infinite*, growing by `4λ₁²` per ring towards the vertex, for any displacement with a
//!   subdominant component (`corner_energy_pairs` lists the pairs). The finite value used is
//!   the energy of the face outside the corner square of side `2^−depth`
//!   ([`EnergyOptions::corner_depth`], default 8): the sum to m = depth, positive
//!   semi-definite like the true energy, and the energy of the surface everywhere but a
//!   region of a 65 536th of the face.
//! * Faces refined by the evaluator (several extraordinary corners, non-quads, sharp
//!   features) are summed over their level-2 pieces, each scaled by its parameter map.
//!   Pieces refined further next to irregular sharp features have no closed form here:
//!   4 × 4 Gauss points on the piece, with [`LimitEvaluator::stencil`] (exact where the
//!   piece is polynomial, an approximation where it is not).

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use faer::Mat;
use faer::sparse::{SparseColMat, Triplet};
use glam::DVec3;
use rayon::prelude::*;
use subd_limit::eval::{FaceParam, LimitEvaluator};
use subd_limit::patch::bspline_basis;
use subd_limit::stam::CornerPatchMatrices;
use subd_limit::{FacePatch, PatchForm};
use subd_mesh::Topology;

use crate::EditError;

/// Options of the energy.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnergyOptions {
    /// Weight of the membrane term `∬ S_u² + S_v²` (0: thin plate only).
    pub membrane: f64,
    /// Rings of the corner-patch hierarchy summed where the thin-plate series diverges
    /// (valence ≥ 5): the energy outside the corner square of side `2^−depth`.
    pub corner_depth: usize,
}

impl Default for EnergyOptions {
    fn default() -> Self {
        EnergyOptions {
            membrane: 0.0,
            corner_depth: 8,
        }
    }
}

/// 4-point Gauss–Legendre nodes and weights on [0, 1].
pub fn gauss4() -> [(f64, f64); 4] {
    let a = (3.0 / 7.0 - 2.0 / 7.0 * (6.0f64 / 5.0).sqrt()).sqrt();
    let b = (3.0 / 7.0 + 2.0 / 7.0 * (6.0f64 / 5.0).sqrt()).sqrt();
    let wa = (18.0 + 30f64.sqrt()) / 36.0;
    let wb = (18.0 - 30f64.sqrt()) / 36.0;
    [
        (0.5 - 0.5 * b, 0.5 * wb),
        (0.5 - 0.5 * a, 0.5 * wa),
        (0.5 + 0.5 * a, 0.5 * wa),
        (0.5 + 0.5 * b, 0.5 * wb),
    ]
}

/// Gram matrices `G_k[i][j] = ∫₀¹ N_i^(k) N_j^(k)` of the cubic B-spline basis, k = 0, 1, 2.
fn gram() -> [[[f64; 4]; 4]; 3] {
    let mut g = [[[0.0; 4]; 4]; 3];
    for (t, w) in gauss4() {
        let (b, d, dd) = bspline_basis(t);
        for i in 0..4 {
            for j in 0..4 {
                g[0][i][j] += w * b[i] * b[j];
                g[1][i][j] += w * d[i] * d[j];
                g[2][i][j] += w * dd[i] * dd[j];
            }
        }
    }
    g
}

/// The thin-plate matrix `Q₀` of a bicubic B-spline patch (grid order `4 j + i`, u along i).
pub fn bicubic_thin_plate() -> [[f64; 16]; 16] {
    let g = gram();
    std::array::from_fn(|a| {
        std::array::from_fn(|b| {
            let (i, j, k, l) = (a % 4, a / 4, b % 4, b / 4);
            g[2][i][k] * g[0][j][l] + 2.0 * g[1][i][k] * g[1][j][l] + g[0][i][k] * g[2][j][l]
        })
    })
}

/// The membrane matrix `∬ S_u² + S_v²` of a bicubic B-spline patch.
pub fn bicubic_membrane() -> [[f64; 16]; 16] {
    let g = gram();
    std::array::from_fn(|a| {
        std::array::from_fn(|b| {
            let (i, j, k, l) = (a % 4, a / 4, b % 4, b / 4);
            g[1][i][k] * g[0][j][l] + g[0][i][k] * g[1][j][l]
        })
    })
}

fn mat16(q: &[[f64; 16]; 16]) -> Mat<f64> {
    Mat::from_fn(16, 16, |i, j| q[i][j])
}

/// The corner patch's energy matrices for one valence.
#[derive(Debug)]
pub struct CornerEnergy {
    /// Valence.
    pub n: usize,
    /// Thin-plate matrix over the 2n + 8 control points.
    pub thin_plate: Mat<f64>,
    /// Membrane matrix over the 2n + 8 control points.
    pub membrane: Mat<f64>,
    /// Rings summed for the thin plate (`None`: the whole convergent series).
    pub truncated_at: Option<usize>,
}

/// `A − 1 wᵀ`, w the dominant left eigenvector (the limit mask): `A`'s powers converge to
/// `1 wᵀ`, read off `A^(2^10)`.
fn without_constant(a: &Mat<f64>) -> Mat<f64> {
    let mut p = a.clone();
    for _ in 0..10 {
        p = &p * &p;
    }
    let k = a.nrows();
    Mat::from_fn(k, k, |i, j| a[(i, j)] - p[(0, j)])
}

/// Catmull-Clark's subdominant eigenvalue at valence n (Doo & Sabin; Stam 1998).
pub fn subdominant(n: usize) -> f64 {
    let c = (2.0 * std::f64::consts::PI / n as f64).cos();
    let h = (std::f64::consts::PI / n as f64).cos();
    (5.0 + c + h * (2.0 * (9.0 + c)).sqrt()) / 16.0
}

/// `Σ_{m=1}^{rings} s^m (A'^(m−1))ᵀ M A'^(m−1)`, or to convergence when `rings` is `None`.
fn ring_series(a1: &Mat<f64>, m: &Mat<f64>, s: f64, rings: Option<usize>) -> Mat<f64> {
    let k = a1.nrows();
    let mut sum = Mat::<f64>::zeros(k, k);
    let mut p = Mat::<f64>::identity(k, k);
    let mut scale = s;
    for ring in 1..=rings.unwrap_or(4000) {
        let term = scale * (p.transpose() * m * &p);
        sum += &term;
        if rings.is_none() && term.norm_l2() <= 1e-17 * sum.norm_l2() {
            break;
        }
        if ring < rings.unwrap_or(usize::MAX) {
            p = a1 * &p;
            scale *= s;
        }
    }
    sum
}

impl CornerEnergy {
    /// The matrices for valence `n`: the whole thin-plate series where it converges
    /// (`4λ₁² < 1`, valence 3), else its first `depth` rings; the whole membrane series.
    pub fn new(m: &CornerPatchMatrices, depth: usize) -> CornerEnergy {
        Self::with_membrane(m, depth, true)
    }

    /// [`CornerEnergy::new`], the membrane matrix left zero unless `membrane` (its series
    /// costs a few hundred products of (2n + 8)² matrices at high valence).
    pub fn with_membrane(m: &CornerPatchMatrices, depth: usize, membrane: bool) -> CornerEnergy {
        let divergent = 4.0 * subdominant(m.n).powi(2) >= 1.0;
        let rings = divergent.then_some(depth.max(1));
        let mut e = Self::series(m, rings, membrane);
        e.truncated_at = rings;
        e
    }

    /// The thin-plate series summed over rings 1..=`rings` exactly (`None`: to
    /// convergence, which only valence 3 reaches), with the whole membrane series.
    pub fn partial(m: &CornerPatchMatrices, rings: Option<usize>) -> CornerEnergy {
        Self::series(m, rings, true)
    }

    fn series(m: &CornerPatchMatrices, rings: Option<usize>, membrane: bool) -> CornerEnergy {
        let sub = &m.sub;
        let q0 = mat16(&bicubic_thin_plate());
        let q1 = mat16(&bicubic_membrane());
        let k = sub.a.nrows();
        let mut mt = Mat::<f64>::zeros(k, k);
        let mut mm = Mat::<f64>::zeros(k, k);
        for ab in &sub.abar {
            mt += ab.transpose() * &q0 * ab;
            mm += ab.transpose() * &q1 * ab;
        }
        let a1 = without_constant(&sub.a);
        CornerEnergy {
            n: m.n,
            // Thin plate: 4^m per ring; membrane: 1 per ring (λ² < 1 but for constants).
            thin_plate: ring_series(&a1, &mt, 4.0, rings),
            membrane: if membrane {
                ring_series(&a1, &mm, 1.0, None)
            } else {
                Mat::zeros(k, k)
            },
            truncated_at: rings,
        }
    }
}

/// Cached [`CornerEnergy`] per (valence, depth), with the membrane matrix.
pub fn corner_energy(n: usize, depth: usize) -> Result<Arc<CornerEnergy>, EditError> {
    cached_corner_energy(n, depth, true)
}

type CornerCache = Mutex<HashMap<(usize, usize, bool), Arc<CornerEnergy>>>;

fn cached_corner_energy(
    n: usize,
    depth: usize,
    membrane: bool,
) -> Result<Arc<CornerEnergy>, EditError> {
    static CACHE: OnceLock<CornerCache> = OnceLock::new();
    let cache = CACHE.get_or_init(|| Mutex::new(HashMap::new()));
    // Held while computing: faces of one valence in parallel wait for one computation.
    let mut guard = cache.lock().expect("cache");
    if let Some(e) = guard.get(&(n, depth, membrane)) {
        return Ok(e.clone());
    }
    let m = subd_limit::stam::corner_patch_matrices(n)?;
    let e = Arc::new(CornerEnergy::with_membrane(&m, depth, membrane));
    guard.insert((n, depth, membrane), e.clone());
    Ok(e)
}

/// The eigenpairs of valence `n`'s corner patch that carry thin-plate energy, with their
/// per-ring factor `4 λᵢ λⱼ`: (λᵢ, λⱼ, |Gᵢⱼ|), for every pair with `|Gᵢⱼ|` above `1e-9`
/// of the largest (G the energy of one ring in the eigenbasis, eigenvectors of unit length).
pub fn corner_energy_pairs(n: usize) -> Result<Vec<(f64, f64, f64)>, EditError> {
    let m = subd_limit::stam::corner_patch_matrices(n)?;
    let a = &m.sub.a;
    let k = a.nrows();
    let q0 = mat16(&bicubic_thin_plate());
    let mut mt = Mat::<f64>::zeros(k, k);
    for ab in &m.sub.abar {
        mt += ab.transpose() * &q0 * ab;
    }
    let evd = a
        .eigen()
        .map_err(|e| EditError::Solve(format!("eigen decomposition: {e:?}")))?;
    let vals = evd.S().column_vector();
    let vecs = evd.U();
    let mut out = Vec::new();
    let mut g = vec![vec![0.0; k]; k];
    let mut largest = 0.0f64;
    for i in 0..k {
        for j in 0..k {
            // Real parts suffice for the size of a pair's term (Catmull-Clark's spectrum
            // is real at the pairs that matter).
            let mut s = 0.0;
            for r in 0..k {
                for c in 0..k {
                    s += vecs[(r, i)].re * mt[(r, c)] * vecs[(c, j)].re;
                }
            }
            g[i][j] = s.abs();
            largest = largest.max(g[i][j]);
        }
    }
    for i in 0..k {
        for j in i..k {
            if g[i][j] > 1e-9 * largest {
                out.push((vals[i].re, vals[j].re, g[i][j]));
            }
        }
    }
    Ok(out)
}

/// A face's piece as a dense matrix over its control rows, scaled to the face's parameters.
fn patch_matrix(
    patch: &FacePatch,
    options: &EnergyOptions,
    q0: &Mat<f64>,
    q1: &Mat<f64>,
) -> Result<Option<Mat<f64>>, EditError> {
    // Second derivatives in the face's parameters are those in the piece's over size², the
    // area size²: thin plate × 1/size², membrane × 1.
    let tp = 1.0 / (patch.size * patch.size);
    Ok(match &patch.form {
        PatchForm::Bicubic => Some(tp * q0 + options.membrane * q1),
        PatchForm::Corner(m) => {
            let e = cached_corner_energy(m.n, options.corner_depth, options.membrane != 0.0)?;
            Some(tp * &e.thin_plate + options.membrane * &e.membrane)
        }
        PatchForm::Other => None,
    })
}

/// The energy's matrix over the base vertices of a mesh (faces given), as triplets.
fn face_triplets(
    ev: &LimitEvaluator,
    face: usize,
    options: &EnergyOptions,
    q0: &Mat<f64>,
    q1: &Mat<f64>,
    out: &mut Vec<(u32, u32, f64)>,
) -> Result<(), EditError> {
    let patches = match ev.face_patches(face) {
        Ok(p) => p,
        // Holes carry no surface.
        Err(subd_limit::LimitError::Unsupported { .. }) => return Ok(()),
        Err(e) => return Err(e.into()),
    };
    for patch in &patches {
        match patch_matrix(patch, options, q0, q1)? {
            Some(l) => {
                let rows = &patch.controls;
                if rows.iter().all(|r| r.len() == 1 && r[0].1 == 1.0) {
                    for (i, ri) in rows.iter().enumerate() {
                        for (j, rj) in rows.iter().enumerate() {
                            out.push((ri[0].0, rj[0].0, l[(i, j)]));
                        }
                    }
                    continue;
                }
                // Rᵀ L R over the vertices the rows involve.
                let mut verts: Vec<u32> = rows.iter().flat_map(|r| r.iter().map(|e| e.0)).collect();
                verts.sort_unstable();
                verts.dedup();
                let mut r = Mat::<f64>::zeros(rows.len(), verts.len());
                for (i, row) in rows.iter().enumerate() {
                    for &(v, w) in row {
                        let c = verts.binary_search(&v).expect("listed");
                        r[(i, c)] += w;
                    }
                }
                let m = r.transpose() * &l * &r;
                for (a, &va) in verts.iter().enumerate() {
                    for (b, &vb) in verts.iter().enumerate() {
                        out.push((va, vb, m[(a, b)]));
                    }
                }
            }
            None => quadrature_triplets(ev, face, patch, options, out)?,
        }
    }
    Ok(())
}

/// A piece without a closed form: 4 × 4 Gauss points on its domain.
fn quadrature_triplets(
    ev: &LimitEvaluator,
    face: usize,
    patch: &FacePatch,
    options: &EnergyOptions,
    out: &mut Vec<(u32, u32, f64)>,
) -> Result<(), EditError> {
    let g = gauss4();
    let h = patch.size;
    let mut stencils = Vec::with_capacity(16);
    for (qi, qj) in [(0, 0)] {
        for &(x, wx) in &g {
            for &(y, wy) in &g {
                let u = patch.origin[0] + h * (qi as f64 + x);
                let v = patch.origin[1] + h * (qj as f64 + y);
                let st = ev.stencil(FaceParam {
                    face,
                    sub: patch.sub,
                    u,
                    v,
                })?;
                stencils.push((wx * wy * h * h, st));
            }
        }
    }
    // One dense matrix over the union of the points' vertices, then its entries.
    let mut verts: Vec<u32> = stencils
        .iter()
        .flat_map(|(_, s)| s.indices.iter().copied())
        .collect();
    verts.sort_unstable();
    verts.dedup();
    let n = verts.len();
    let mut m = vec![0.0; n * n];
    for (w, st) in &stencils {
        let local: Vec<usize> = st
            .indices
            .iter()
            .map(|v| verts.binary_search(v).expect("listed"))
            .collect();
        for (a, &la) in local.iter().enumerate() {
            for (b, &lb) in local.iter().enumerate() {
                let tp = st.weights[3][a] * st.weights[3][b]
                    + 2.0 * st.weights[4][a] * st.weights[4][b]
                    + st.weights[5][a] * st.weights[5][b];
                let mem = st.weights[1][a] * st.weights[1][b] + st.weights[2][a] * st.weights[2][b];
                m[la * n + lb] += w * (tp + options.membrane * mem);
            }
        }
    }
    for (a, &va) in verts.iter().enumerate() {
        for (b, &vb) in verts.iter().enumerate() {
            if m[a * n + b] != 0.0 {
                out.push((va, vb, m[a * n + b]));
            }
        }
    }
    Ok(())
}

/// The energy of the whole limit surface at positions `x`: `Σ_c x_cᵀ Q x_c` with `Q` over
/// every face of the evaluator's mesh (holes carry no surface), each face's piece as
/// [`EnergyMatrix`] assembles it. A property of the surface alone, whatever the edit method
/// or region; with [`EnergyOptions::default`] the thin-plate energy
/// `∬ S_uu² + 2 S_uv² + S_vv²` summed over the faces in their own parameters (the corner
/// square of side `2^−corner_depth` left out at valence ≥ 5, as [`EnergyOptions`] says).
/// Faces are summed in order: the same value for any thread count.
///
/// # Errors
/// A face the evaluator cannot evaluate (other than holes), or `x` of the wrong length.
///
/// ```
/// use subd_editing::energy::{EnergyOptions, surface_energy};
/// use subd_limit::eval::LimitEvaluator;
/// use subd_schemes::{Options, Scheme};
///
/// let mesh = subd_mesh::primitives::torus(12, 8, 2.0, 0.5);
/// let ev = LimitEvaluator::new(&mesh.topology, &Scheme::CatmullClark, &Options::default())
///     .unwrap();
/// let e = surface_energy(&ev, &mesh.positions, &EnergyOptions::default()).unwrap();
/// // Moving the surface rigidly costs nothing: the energy is the same.
/// let moved: Vec<_> = mesh.positions.iter().map(|p| *p + subd_mesh::DVec3::X).collect();
/// let f = surface_energy(&ev, &moved, &EnergyOptions::default()).unwrap();
/// assert!(e > 0.0 && (e - f).abs() < 1e-9 * e);
/// ```
pub fn surface_energy(
    ev: &LimitEvaluator,
    x: &[DVec3],
    options: &EnergyOptions,
) -> Result<f64, EditError> {
    check_length(ev, x)?;
    let all: Vec<usize> = (0..ev.topology().num_faces()).collect();
    Ok(face_energies(ev, x, &all, options)?.iter().sum())
}

/// [`surface_energy`] of `before` and of `after` (an edit of it), bit for bit, with only the
/// faces whose patches reach a vertex that moved evaluated twice.
///
/// # Errors
/// As [`surface_energy`].
pub fn surface_energy_before_after(
    ev: &LimitEvaluator,
    before: &[DVec3],
    after: &[DVec3],
    options: &EnergyOptions,
) -> Result<(f64, f64), EditError> {
    check_length(ev, before)?;
    check_length(ev, after)?;
    let topology = ev.topology();
    let all: Vec<usize> = (0..topology.num_faces()).collect();
    let mut per_face = face_energies(ev, before, &all, options)?;
    let energy_before = per_face.iter().sum();
    let moved: Vec<u32> = (0..before.len() as u32)
        .filter(|&v| before[v as usize] != after[v as usize])
        .collect();
    let changed = faces_reaching(topology, &moved);
    for (&f, e) in changed
        .iter()
        .zip(face_energies(ev, after, &changed, options)?)
    {
        per_face[f] = e;
    }
    // The same faces summed in the same order as a fresh evaluation of `after`.
    Ok((energy_before, per_face.iter().sum()))
}

fn check_length(ev: &LimitEvaluator, x: &[DVec3]) -> Result<(), EditError> {
    let n = ev.topology().num_vertices();
    if x.len() != n {
        return Err(EditError::Solve(format!(
            "{} positions for {n} vertices",
            x.len()
        )));
    }
    Ok(())
}

/// The energies `Σ_c x_cᵀ Q_f x_c` of `faces` (in parallel; each face's value depends on
/// that face alone).
fn face_energies(
    ev: &LimitEvaluator,
    x: &[DVec3],
    faces: &[usize],
    options: &EnergyOptions,
) -> Result<Vec<f64>, EditError> {
    let q0 = mat16(&bicubic_thin_plate());
    let q1 = mat16(&bicubic_membrane());
    faces
        .par_iter()
        .map(|&f| {
            let mut t = Vec::new();
            face_triplets(ev, f, options, &q0, &q1, &mut t)?;
            Ok(t.iter()
                .map(|&(i, j, v)| v * x[i as usize].dot(x[j as usize]))
                .sum::<f64>())
        })
        .collect()
}

/// The faces whose limit patches depend on one of `vertices`, ascending: a Catmull-Clark
/// patch depends on the vertices of the faces around its corners, so these are the faces
/// sharing a vertex with a face around one of `vertices`.
fn faces_reaching(topology: &Topology, vertices: &[u32]) -> Vec<usize> {
    let mut near = vec![false; topology.num_vertices()];
    for &v in vertices {
        for &f in topology.vertex_faces(v as usize) {
            for &w in topology.face_vertices(f as usize) {
                near[w as usize] = true;
            }
        }
    }
    let mut hit = vec![false; topology.num_faces()];
    for w in (0..near.len()).filter(|&w| near[w]) {
        for &f in topology.vertex_faces(w) {
            hit[f as usize] = true;
        }
    }
    (0..hit.len()).filter(|&f| hit[f]).collect()
}

/// Appends a chunk's entries to `merged`; where they repeat a few vertex pairs many times
/// (the faces around a vertex of high valence share their (2n + 8)² pairs) they are summed
/// in a dense block over the chunk's vertices first. `local` is an all-`MAX` scratch map
/// from vertex to block index, left as it was found.
fn accumulate(
    chunk: Vec<Vec<(u32, u32, f64)>>,
    local: &mut [u32],
    merged: &mut Vec<(u32, u32, f64)>,
) {
    let mut verts: Vec<u32> = Vec::new();
    let mut count = 0usize;
    for &(i, _, _) in chunk.iter().flatten() {
        count += 1;
        if local[i as usize] == u32::MAX {
            local[i as usize] = verts.len() as u32;
            verts.push(i);
        }
    }
    let n = verts.len();
    if count > 4 * n * n {
        // Faces in order, entries in order: the same sums for any thread count.
        let mut block = vec![0.0; n * n];
        for &(i, j, v) in chunk.iter().flatten() {
            block[local[i as usize] as usize * n + local[j as usize] as usize] += v;
        }
        for (a, &va) in verts.iter().enumerate() {
            for (b, &vb) in verts.iter().enumerate() {
                if block[a * n + b] != 0.0 {
                    merged.push((va, vb, block[a * n + b]));
                }
            }
        }
    } else {
        merged.extend(chunk.into_iter().flatten());
    }
    for &v in &verts {
        local[v as usize] = u32::MAX;
    }
}

/// Sorts entries by (column, row) and sums repeated ones. The order is a function of the
/// entries alone (not of the thread count that produced them, which `collect` keeps in face
/// order), so the sums are reproducible.
fn merge_entries(e: &mut Vec<(u32, u32, f64)>) {
    let mut keyed: Vec<(u64, f64)> = e
        .iter()
        .map(|&(i, j, v)| ((u64::from(j) << 32) | u64::from(i), v))
        .collect();
    keyed.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    e.clear();
    for (k, v) in keyed {
        let (i, j) = ((k & 0xffff_ffff) as u32, (k >> 32) as u32);
        match e.last_mut() {
            Some(last) if last.0 == i && last.1 == j => last.2 += v,
            _ => e.push((i, j, v)),
        }
    }
}

/// The energy's matrix `Q` (n × n, symmetric) over the faces `faces` of the evaluator's
/// mesh.
#[derive(Clone, Debug)]
pub struct EnergyMatrix {
    /// `Q`, every entry stored (both triangles).
    pub q: SparseColMat<usize, f64>,
}

impl EnergyMatrix {
    /// Assembles `Q` over `faces` (in parallel; the sum is the same for any thread count,
    /// the entries being merged in face order).
    ///
    /// # Errors
    /// A face the evaluator cannot evaluate (other than holes).
    pub fn new(
        ev: &LimitEvaluator,
        num_vertices: usize,
        faces: &[usize],
        options: &EnergyOptions,
    ) -> Result<EnergyMatrix, EditError> {
        let q0 = mat16(&bicubic_thin_plate());
        let q1 = mat16(&bicubic_membrane());
        // Faces in chunks, each chunk's entries merged before the next (a face at a vertex
        // of valence n has (2n + 8)² of them, the same pairs for every face around it).
        let mut merged: Vec<(u32, u32, f64)> = Vec::new();
        let mut local = vec![u32::MAX; num_vertices];
        for chunk in faces.chunks(32) {
            let per_face: Vec<Vec<(u32, u32, f64)>> = chunk
                .par_iter()
                .map(|&f| {
                    let mut t = Vec::new();
                    face_triplets(ev, f, options, &q0, &q1, &mut t).map(|_| t)
                })
                .collect::<Result<_, _>>()?;
            accumulate(per_face, &mut local, &mut merged);
            if merged.len() > 1 << 22 {
                merge_entries(&mut merged);
            }
        }
        merge_entries(&mut merged);
        let triplets: Vec<Triplet<usize, usize, f64>> = merged
            .iter()
            .map(|&(i, j, v)| Triplet::new(i as usize, j as usize, v))
            .collect();
        let q = SparseColMat::try_new_from_triplets(num_vertices, num_vertices, &triplets)
            .map_err(|e| EditError::Solve(format!("energy matrix: {e:?}")))?;
        Ok(EnergyMatrix { q })
    }

    /// `Σ_c x_cᵀ Q x_c` for positions (or displacements) `x`.
    pub fn energy(&self, x: &[DVec3]) -> f64 {
        let q = self.q.as_ref();
        let mut e = 0.0;
        for j in 0..q.ncols() {
            let rows = q.row_idx_of_col_raw(j);
            let vals = q.val_of_col(j);
            for (&i, &v) in rows.iter().zip(vals) {
                e += v * x[i].dot(x[j]);
            }
        }
        e
    }
}
