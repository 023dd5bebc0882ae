//! Eigen analysis of the split schemes (Doo-Sabin, √3, the butterflies) around an
//! extraordinary vertex or face, read off the schemes' own stencils (the subdivision lecture notes
//! §5).
//!
//! The local subdivision matrix is not written down by hand. A disc of `K` rings of regular
//! faces around a centre of valence `n` is refined once, and both levels are labelled the
//! same way: a breadth-first walk from a root (the centre and one of its edges) that visits
//! the neighbours of every vertex counter-clockwise from the one it was reached from. The
//! children of the ball of radius `r` around the centre, in that labelling, are a linear
//! function of the ball itself once `r` is large enough (the ball is *invariant*); that
//! function is the local subdivision matrix `S`.
//!
//! Turning the root one sector gives the rotation `R` of the ball, which commutes with `S`.
//! So `S` splits into one block per Fourier frequency `k = 0 … n−1`:
//! `Ŝ_k[o′, o] = Σ_t ω^{kt} S[o′, R^t o]` over the rotation orbits `o` (`ω = e^{2πi/n}`), and
//! every eigenvalue comes with the frequency of its eigenvector. The test of smoothness
//! (Reif's conditions on the spectrum) is then: `1` simple, the subdominant eigenvalue `λ`
//! real, positive and double, from frequencies 1 and `n − 1` (a characteristic map that
//! winds once around the centre), and every other eigenvalue smaller than `λ` in modulus.
//!
//! Doo-Sabin is analysed around an `n`-sided face (its extraordinary elements): the disc is
//! a quad disc around a valence-`n` vertex refined once, whose vertex face is that `n`-gon.

use std::f64::consts::TAU;

use faer::{Mat, c64};
use glam::DVec3;
use subd_mesh::neighbourhood::{labelled_ball, ring_from};
use subd_mesh::{Topology, TopologyBuilder};
use subd_schemes::{Options, RefineError, Refinement, Scheme, Split};

use crate::LimitError;

/// One eigenvalue of a local subdivision matrix and the Fourier frequency of its eigenvector
/// (`min(k, n − k)`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct FourierEigenvalue {
    /// Real part.
    pub re: f64,
    /// Imaginary part.
    pub im: f64,
    /// Frequency `min(k, n − k)`.
    pub frequency: usize,
}

impl FourierEigenvalue {
    /// Modulus.
    pub fn norm(&self) -> f64 {
        self.re.hypot(self.im)
    }
}

/// The spectrum of a split scheme's local subdivision matrix at one valence.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SplitSpectrum {
    /// Valence of the centre (sides of the centre face for Doo-Sabin).
    pub valence: usize,
    /// Size of the invariant ball the matrix acts on.
    pub ball_size: usize,
    /// Every eigenvalue, largest modulus first (ties: lower frequency first).
    pub eigenvalues: Vec<FourierEigenvalue>,
}

/// The verdict of the eigenvalue test.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SpectrumTest {
    /// Whether the spectrum meets the conditions (see the module docs).
    pub passes: bool,
    /// The subdominant eigenvalue's modulus.
    pub subdominant: f64,
    /// Frequency of the subdominant eigenvalue.
    pub subdominant_frequency: usize,
    /// What fails, when something does.
    pub reason: Option<String>,
}

impl SplitSpectrum {
    /// Reif's necessary conditions for a C¹ limit at the centre, on the spectrum.
    ///
    /// Eigenvalues within 1e-5 of each other in modulus count as one (a defective eigenvalue
    /// comes out of a floating-point solver split by about the cube root of the rounding).
    pub fn test(&self) -> SpectrumTest {
        const CLUSTER: f64 = 1e-5;
        let ev = &self.eigenvalues;
        let sub = ev.get(1).copied().unwrap_or(FourierEigenvalue {
            re: 0.0,
            im: 0.0,
            frequency: 0,
        });
        let mu = sub.norm();
        let fail = |reason: String| SpectrumTest {
            passes: false,
            subdominant: mu,
            subdominant_frequency: sub.frequency,
            reason: Some(reason),
        };
        let one = ev[0];
        if (one.re - 1.0).abs() > 1e-9 || one.im.abs() > 1e-9 || mu > 1.0 - CLUSTER {
            return fail("the eigenvalue 1 is not simple and dominant".into());
        }
        let cluster: Vec<&FourierEigenvalue> = ev[1..]
            .iter()
            .filter(|e| (e.norm() - mu).abs() <= CLUSTER)
            .collect();
        let mut frequencies: Vec<usize> = cluster.iter().map(|e| e.frequency).collect();
        frequencies.sort_unstable();
        frequencies.dedup();
        let list = frequencies
            .iter()
            .map(|k| k.to_string())
            .collect::<Vec<_>>()
            .join(", ");
        if cluster.len() != 2 {
            return fail(format!(
                "the subdominant modulus {mu:.6} has multiplicity {} (frequencies {list}), not 2",
                cluster.len()
            ));
        }
        if frequencies != [1] {
            return fail(format!(
                "the subdominant eigenvalues {mu:.6} have frequency {list}: the characteristic map winds {list} times around the centre"
            ));
        }
        if cluster.iter().any(|e| e.im.abs() > CLUSTER || e.re <= 0.0) {
            return fail(format!(
                "the subdominant eigenvalue {:.6}{:+.6}i is not real and positive",
                sub.re, sub.im
            ));
        }
        SpectrumTest {
            passes: true,
            subdominant: mu,
            subdominant_frequency: 1,
            reason: None,
        }
    }
}

/// A disc of `rings` rings of regular faces (triangles, or quads) around vertex 0 of valence
/// `n`: sector `s` holds the lattice points `i·e_s + j·e_{s+1}`.
fn disc(n: usize, rings: usize, quads: bool) -> Result<Topology, LimitError> {
    let k = rings;
    // Vertices of sector s with i ≥ 1 (the points with i = 0 belong to sector s − 1 … or the
    // centre); quads take the full square, triangles the lattice triangle i + j ≤ K.
    let in_sector = |i: usize, j: usize| if quads { i <= k && j <= k } else { i + j <= k };
    let per_sector: Vec<(usize, usize)> = (1..=k)
        .flat_map(|i| (0..=k).map(move |j| (i, j)))
        .filter(|&(i, j)| in_sector(i, j))
        .collect();
    let index_of = |i: usize, j: usize| per_sector.iter().position(|&p| p == (i, j));
    let m = per_sector.len();
    let id = |s: usize, i: usize, j: usize| -> u32 {
        if i == 0 && j == 0 {
            0
        } else if i == 0 {
            (1 + ((s + 1) % n) * m + index_of(j, 0).expect("spoke point")) as u32
        } else {
            (1 + s * m + index_of(i, j).expect("sector point")) as u32
        }
    };
    let mut sizes = Vec::new();
    let mut verts = Vec::new();
    for s in 0..n {
        for i in 0..k {
            for j in 0..k {
                if quads {
                    sizes.push(4);
                    verts.extend([
                        id(s, i, j),
                        id(s, i + 1, j),
                        id(s, i + 1, j + 1),
                        id(s, i, j + 1),
                    ]);
                    continue;
                }
                if i + j < k {
                    sizes.push(3);
                    verts.extend([id(s, i, j), id(s, i + 1, j), id(s, i, j + 1)]);
                }
                if i + j + 2 <= k {
                    sizes.push(3);
                    verts.extend([id(s, i + 1, j), id(s, i + 1, j + 1), id(s, i, j + 1)]);
                }
            }
        }
    }
    TopologyBuilder::new(1 + n * m)
        .build(&sizes, &verts)
        .map_err(|e| LimitError::Analysis(format!("disc of valence {n}: {e}")))
}

/// A centre to analyse in a topology: its seeds for each of the `n` rotations.
struct Centre {
    /// `seeds[t]`: the walk's seeds with the root turned `t` sectors.
    seeds: Vec<Vec<(u32, u32)>>,
}

/// The triangle in which `a → b` is an edge (the one left of `a → b`).
fn face_with_edge(t: &Topology, a: u32, b: u32) -> usize {
    (0..t.num_faces())
        .find(|&f| {
            let fv = t.face_vertices(f);
            (0..fv.len()).any(|i| fv[i] == a && fv[(i + 1) % fv.len()] == b)
        })
        .expect("an interior edge has a face on each side")
}

/// A vertex centre: the vertex and its ring, turned.
fn vertex_centre(t: &Topology, v: u32, first: u32) -> Centre {
    let ring = ring_from(t, v, first);
    Centre {
        seeds: (0..ring.len()).map(|s| vec![(v, ring[s])]).collect(),
    }
}

/// A face centre: the face's corners in order, each walked from the next, turned.
fn face_centre(t: &Topology, f: usize) -> Centre {
    let fv = t.face_vertices(f);
    let n = fv.len();
    Centre {
        seeds: (0..n)
            .map(|s| {
                (0..n)
                    .map(|i| (fv[(s + i) % n], fv[(s + i + 1) % n]))
                    .collect()
            })
            .collect(),
    }
}

/// The local subdivision matrix of the ball of `radius`, or `None` when the ball is not
/// invariant (a child reaches outside it), with the rotation as a permutation of labels.
fn local_matrix(
    parent: &Topology,
    child: &Topology,
    stencils: &subd_schemes::StencilTable,
    old: &Centre,
    new: &Centre,
    radius: usize,
) -> Option<(Mat<f64>, Vec<usize>)> {
    let old_ball = labelled_ball(parent, &old.seeds[0], radius);
    let new_ball = labelled_ball(child, &new.seeds[0], radius);
    if old_ball.len() != new_ball.len() {
        return None;
    }
    let m = old_ball.len();
    let mut label = vec![usize::MAX; parent.num_vertices()];
    for (i, &v) in old_ball.iter().enumerate() {
        label[v as usize] = i;
    }
    let mut s = Mat::<f64>::zeros(m, m);
    for (row, &c) in new_ball.iter().enumerate() {
        let (idx, w) = stencils.row(c as usize);
        for (&j, &wj) in idx.iter().zip(w) {
            let col = label[j as usize];
            if col == usize::MAX {
                return None;
            }
            s[(row, col)] += wj;
        }
    }
    // The rotation: label i under the turned root is label rot[i] under the first root.
    let turned = labelled_ball(parent, &old.seeds[1], radius);
    let rot: Vec<usize> = turned.iter().map(|&v| label[v as usize]).collect();
    if rot.contains(&usize::MAX) {
        return None;
    }
    Some((s, rot))
}

/// Whether `s` commutes with the rotation `rot` (the labelling of both levels turned the same
/// way), which the Fourier split needs.
fn commutes(s: &Mat<f64>, rot: &[usize]) -> bool {
    let m = rot.len();
    (0..m).all(|i| (0..m).all(|j| (s[(rot[i], rot[j])] - s[(i, j)]).abs() <= 1e-12))
}

/// The rotation orbits of the ball's labels (each listed as `o, R(o), R²(o), …`).
fn orbits(rot: &[usize]) -> Vec<Vec<usize>> {
    let m = rot.len();
    let mut seen = vec![false; m];
    let mut out: Vec<Vec<usize>> = Vec::new();
    for o in 0..m {
        if seen[o] {
            continue;
        }
        let mut orbit = vec![o];
        seen[o] = true;
        let mut x = rot[o];
        while x != o {
            seen[x] = true;
            orbit.push(x);
            x = rot[x];
        }
        out.push(orbit);
    }
    out
}

/// The Fourier block of frequency `k`: `Ŝ_k[o′, o] = Σ_t ω^{kt} S[o′, R^t o]` over the orbits
/// that carry frequency `k` (all full orbits; the centre only for `k = 0`), and those orbits.
fn fourier_block<'a>(
    s: &Mat<f64>,
    orbits: &'a [Vec<usize>],
    n: usize,
    k: usize,
) -> (Mat<c64>, Vec<&'a Vec<usize>>) {
    let members: Vec<&Vec<usize>> = orbits.iter().filter(|o| o.len() == n || k == 0).collect();
    let size = members.len();
    let block = Mat::<c64>::from_fn(size, size, |a, b| {
        let (row, col) = (members[a][0], members[b]);
        (0..col.len())
            .map(|t| {
                let w = TAU * (k * t) as f64 / n as f64;
                c64::new(w.cos(), w.sin()) * s[(row, col[t])]
            })
            .fold(c64::new(0.0, 0.0), |acc, x| acc + x)
    });
    (block, members)
}

/// Eigenvalues per Fourier frequency of `s`, which commutes with the rotation `rot`.
fn fourier_spectrum(
    s: &Mat<f64>,
    rot: &[usize],
    n: usize,
) -> Result<Vec<FourierEigenvalue>, LimitError> {
    let orbits = orbits(rot);
    let mut out = Vec::new();
    for k in 0..n {
        let (block, members) = fourier_block(s, &orbits, n, k);
        if members.is_empty() {
            continue;
        }
        let ev = block
            .eigenvalues()
            .map_err(|e| LimitError::Analysis(format!("eigenvalues: {e:?}")))?;
        out.extend(ev.into_iter().map(|z| FourierEigenvalue {
            re: z.re,
            im: z.im,
            frequency: k.min(n - k),
        }));
    }
    out.sort_by(|a, b| {
        b.norm()
            .total_cmp(&a.norm())
            .then(a.frequency.cmp(&b.frequency))
    });
    Ok(out)
}

/// The left eigenvector of `block` for its eigenvalue of largest real part (the dominant one
/// of the block), from the right eigenvectors of the transpose.
fn dominant_left(block: &Mat<c64>) -> Result<(c64, Vec<c64>), LimitError> {
    let t = block.transpose().to_owned();
    let evd = t
        .eigen()
        .map_err(|e| LimitError::Analysis(format!("eigenvectors: {e:?}")))?;
    let values = evd.S();
    let vectors = evd.U();
    let best = (0..t.nrows())
        .max_by(|&a, &b| values[a].norm().total_cmp(&values[b].norm()))
        .ok_or_else(|| LimitError::Analysis("empty Fourier block".into()))?;
    Ok((
        values[best],
        (0..t.nrows()).map(|i| vectors[(i, best)]).collect(),
    ))
}

/// The spectrum of `scheme`'s local subdivision matrix at an interior vertex of valence `n`
/// (√3, the butterflies) or an `n`-sided face (Doo-Sabin), `3 ≤ n ≤ 64`.
///
/// ```
/// use subd_limit::split_eigen::split_spectrum;
/// use subd_schemes::Scheme;
///
/// // The modified butterfly is C¹ at every valence; its subdominant eigenvalue is ½.
/// let s = split_spectrum(&Scheme::ModifiedButterfly, 9).unwrap();
/// let test = s.test();
/// assert!(test.passes);
/// assert!((test.subdominant - 0.5).abs() < 1e-12);
/// ```
///
/// # Errors
/// [`LimitError::Analysis`] for a valence out of range, or when no invariant ball is found.
pub fn split_spectrum(scheme: &Scheme, n: usize) -> Result<SplitSpectrum, LimitError> {
    let local = local_system(scheme, n)?;
    Ok(SplitSpectrum {
        valence: n,
        ball_size: local.s.nrows(),
        eigenvalues: fourier_spectrum(&local.s, &local.rot, n)?,
    })
}

/// The local subdivision matrix on the smallest invariant ball, with the ball's rotation.
struct LocalSystem {
    radius: usize,
    s: Mat<f64>,
    rot: Vec<usize>,
}

fn local_system(scheme: &Scheme, n: usize) -> Result<LocalSystem, LimitError> {
    if !(3..=64).contains(&n) {
        return Err(LimitError::Analysis(format!(
            "valence {n}: must be 3 to 64"
        )));
    }
    let analysis = |e: RefineError| LimitError::Analysis(e.to_string());
    for radius in 1..=6 {
        let rings = 2 * radius + 4;
        let (parent, child, stencils, old, new) = if scheme.split() == Split::Dual {
            // The n-gon: the vertex face of a valence-n vertex after one step.
            let d = disc(n, rings + 1, true)?;
            let r =
                Refinement::new(&d, scheme.clone(), &Options::default(), 2).map_err(analysis)?;
            let level1 = r.topology(1);
            // F-faces, then E-faces, then V-faces in vertex order: vertex 0's comes first.
            let v_face = d.num_faces() + d.num_edges();
            let old = face_centre(level1, v_face);
            // Its F-face child keeps the face index and corner order.
            let new = face_centre(r.topology(2), v_face);
            (
                level1.clone(),
                r.topology(2).clone(),
                r.stencils(2).clone(),
                old,
                new,
            )
        } else {
            let d = disc(n, rings, false)?;
            let first = d.vertex_ring(0).next().expect("centre has a ring");
            let old = vertex_centre(&d, 0, first);
            if scheme.period() == 2 {
                // One step turns the mesh by π/n; two steps bring it back into line. The
                // root spoke of level 2 is the one along the root spoke of level 0: through
                // the centroid of the level-1 face right of the level-1 root spoke, itself
                // through the centroid of the level-0 face left of the root spoke.
                let r = Refinement::new(&d, scheme.clone(), &Options::default(), 2)
                    .map_err(analysis)?;
                let level1 = r.topology(1);
                let f0 = face_with_edge(&d, 0, first);
                let first1 = (d.num_vertices() + f0) as u32;
                let f1 = face_with_edge(level1, first1, 0);
                let first2 = (level1.num_vertices() + f1) as u32;
                let new = vertex_centre(r.topology(2), 0, first2);
                (d.clone(), r.topology(2).clone(), r.composed(2), old, new)
            } else {
                let r = Refinement::new(&d, scheme.clone(), &Options::default(), 1)
                    .map_err(analysis)?;
                // The root spoke's point.
                let e = d.find_edge(0, first).expect("root spoke");
                let new = vertex_centre(r.topology(1), 0, (d.num_vertices() + e as usize) as u32);
                (
                    d.clone(),
                    r.topology(1).clone(),
                    r.stencils(1).clone(),
                    old,
                    new,
                )
            }
        };
        if let Some((s, rot)) = local_matrix(&parent, &child, &stencils, &old, &new, radius) {
            if !commutes(&s, &rot) {
                return Err(LimitError::Analysis(format!(
                    "{} at valence {n}: the local matrix does not commute with the rotation",
                    scheme.name()
                )));
            }
            return Ok(LocalSystem { radius, s, rot });
        }
    }
    Err(LimitError::Analysis(format!(
        "no invariant ball of radius ≤ 6 for {} at valence {n}",
        scheme.name()
    )))
}

/// Limit and tangent masks of a split scheme at an interior vertex of valence `n` whose
/// ball of radius [`Self::radius`] is otherwise regular: weights over the ball's labels (see
/// [`Self::ball`]), from the left eigenvectors of the local subdivision matrix.
#[derive(Debug, Clone)]
pub struct LocalMasks {
    /// Radius of the invariant ball.
    pub radius: usize,
    /// Limit-position weights (eigenvalue 1, frequency 0), summing to 1.
    pub limit: Vec<f64>,
    /// Two tangent masks (real part and minus the imaginary part of the frequency-1 left
    /// eigenvector of the subdominant eigenvalue), whose cross product points to the side the
    /// faces' counter-clockwise order makes the outside; `None` where the spectrum fails the
    /// C¹ test.
    pub tangents: Option<[Vec<f64>; 2]>,
}

impl LocalMasks {
    /// The labels of the ball of `radius` around vertex `v` of `t`, walked as the masks'
    /// labels are (any first spoke: turning it turns the tangent masks within their plane).
    pub fn ball(t: &Topology, v: u32, radius: usize) -> Vec<u32> {
        match t.vertex_ring(v as usize).next() {
            Some(first) => labelled_ball(t, &[(v, first)], radius),
            None => vec![v],
        }
    }
}

/// The masks of `scheme` (√3 or a butterfly) at an interior vertex of valence `n`.
///
/// # Errors
/// [`LimitError::Analysis`] for Doo-Sabin (its centres are faces), a valence out of range or
/// a failed eigen solve.
pub fn local_masks(scheme: &Scheme, n: usize) -> Result<LocalMasks, LimitError> {
    if scheme.split() == Split::Dual {
        return Err(LimitError::Analysis(
            "Doo-Sabin's limit points are face centroids, not vertex masks".into(),
        ));
    }
    let local = local_system(scheme, n)?;
    let m = local.rot.len();
    let orbits = orbits(&local.rot);
    let (block0, members0) = fourier_block(&local.s, &orbits, n, 0);
    let (one, l0) = dominant_left(&block0)?;
    if (one.re - 1.0).abs() > 1e-9 {
        return Err(LimitError::Analysis(format!(
            "{} at valence {n}: dominant eigenvalue {one} is not 1",
            scheme.name()
        )));
    }
    // A block coefficient of a full orbit is 1/n of the sum over the orbit; the centre's is
    // its value.
    let mut limit = vec![0.0; m];
    for (o, w) in members0.iter().zip(&l0) {
        for &label in o.iter() {
            limit[label] = w.re / o.len() as f64;
        }
    }
    let total: f64 = limit.iter().sum();
    limit.iter_mut().for_each(|w| *w /= total);
    let passes = fourier_spectrum(&local.s, &local.rot, n)
        .map(|ev| {
            SplitSpectrum {
                valence: n,
                ball_size: m,
                eigenvalues: ev,
            }
            .test()
            .passes
        })
        .unwrap_or(false);
    let tangents = if passes {
        let (block1, members1) = fourier_block(&local.s, &orbits, n, 1);
        let (_, l1) = dominant_left(&block1)?;
        let (mut re, mut im) = (vec![0.0; m], vec![0.0; m]);
        for (o, w) in members1.iter().zip(&l1) {
            for (t, &label) in o.iter().enumerate() {
                let a = -TAU * t as f64 / n as f64;
                let z = *w * c64::new(a.cos(), a.sin());
                re[label] = z.re;
                // The conjugate's sign: with the labels counter-clockwise, (Re, −Im) is
                // (Σ cos·p, Σ sin·p) turned, so their cross product follows the faces'
                // orientation.
                im[label] = -z.im;
            }
        }
        Some([re, im])
    } else {
        None
    };
    Ok(LocalMasks {
        radius: local.radius,
        limit,
        tangents,
    })
}

/// A centre on a feature curve: a boundary vertex with `faces` triangles around it, or a
/// dart of valence `valence` (one infinitely sharp edge, whose crease runs on away from it).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FeatureCentre {
    /// A boundary vertex.
    Boundary {
        /// Triangles around it.
        faces: usize,
    },
    /// A crease ending inside the surface.
    Dart {
        /// Its valence.
        valence: usize,
    },
}

/// Masks at a feature centre, over the ball labelled from the centre's canonical feature
/// spoke ([`feature_spoke`]); the local subdivision matrix has no rotation symmetry there, so
/// its eigenvectors come from the dense matrix.
#[derive(Debug, Clone)]
pub struct FeatureMasks {
    /// Radius of the invariant ball.
    pub radius: usize,
    /// Steps the matrix covers (2 for √3).
    pub steps: usize,
    /// The local subdivision matrix over the ball (a level's ball to the ball `steps`
    /// levels down).
    pub matrix: Mat<f64>,
    /// Limit-position weights (the left eigenvector of eigenvalue 1, summing to 1).
    pub limit: Vec<f64>,
    /// Tangent masks: the left eigenvectors of the two subdominant eigenvalues when they
    /// are real, positive and larger than the rest, turned so that their cross product
    /// follows the faces' orientation; `None` otherwise.
    pub tangents: Option<[Vec<f64>; 2]>,
}

/// The spoke a feature centre's ball is labelled from: a boundary vertex's outgoing boundary
/// edge, or a dart's one sharp edge; `None` for other vertices.
pub fn feature_spoke(t: &Topology, v: u32) -> Option<u32> {
    let vi = v as usize;
    let edges = t.vertex_edges(vi);
    if t.is_boundary_vertex(vi) {
        let e = *edges.first()?;
        return t
            .is_boundary_edge(e as usize)
            .then(|| t.edge_other_vertex(e as usize, v));
    }
    let mut sharp = edges
        .iter()
        .filter(|&&e| subd_mesh::tags::is_infinite(t.edge_sharpness(e as usize)));
    match (sharp.next(), sharp.next()) {
        (Some(&e), None) => Some(t.edge_other_vertex(e as usize, v)),
        _ => None,
    }
}

/// The ball of `radius` around feature vertex `v`, labelled from its feature spoke.
pub fn feature_ball(t: &Topology, v: u32, radius: usize) -> Option<Vec<u32>> {
    feature_spoke(t, v).map(|s| labelled_ball(t, &[(v, s)], radius))
}

/// The local subdivision matrix of `v` over the ball of `radius`: the rows of the child
/// ball's vertices (`rows(c)`: weights over the parent level) on the parent ball, or `None`
/// when the balls differ in size or a row reaches outside.
pub fn feature_matrix(
    parent: &Topology,
    child: &Topology,
    rows: &dyn Fn(u32) -> Vec<(u32, f64)>,
    v: u32,
    radius: usize,
) -> Option<Mat<f64>> {
    let old = feature_ball(parent, v, radius)?;
    let new = feature_ball(child, v, radius)?;
    if old.len() != new.len() {
        return None;
    }
    let mut label = std::collections::HashMap::with_capacity(old.len());
    for (i, &u) in old.iter().enumerate() {
        label.insert(u, i);
    }
    let mut s = Mat::<f64>::zeros(old.len(), old.len());
    for (row, &c) in new.iter().enumerate() {
        for (j, w) in rows(c) {
            s[(row, *label.get(&j)?)] += w;
        }
    }
    Some(s)
}

/// A fan of triangles around vertex 0 (`rings` rings): `sectors` sectors of the lattice,
/// closed around the centre or open (a boundary vertex with that many triangles), with
/// planar positions whose triangles run counter-clockwise.
fn triangle_fan(sectors: usize, rings: usize, closed: bool) -> (Topology, Vec<DVec3>) {
    let k = rings;
    let per_sector: Vec<(usize, usize)> = (1..=k)
        .flat_map(|i| (0..=k - i).map(move |j| (i, j)))
        .collect();
    let m = per_sector.len();
    let index_of = |i: usize, j: usize| per_sector.iter().position(|&p| p == (i, j));
    let last_spoke = 1 + sectors * m;
    let id = |s: usize, i: usize, j: usize| -> u32 {
        if i == 0 && j == 0 {
            0
        } else if i == 0 && (closed || s + 1 < sectors) {
            (1 + ((s + 1) % sectors) * m + index_of(j, 0).expect("spoke point")) as u32
        } else if i == 0 {
            (last_spoke + j - 1) as u32
        } else {
            (1 + s * m + index_of(i, j).expect("sector point")) as u32
        }
    };
    let nv = last_spoke + if closed { 0 } else { k };
    let span = if closed { TAU } else { TAU / 2.0 };
    let at = |s: usize, i: usize, j: usize| {
        let r = (i + j) as f64;
        let a = (s as f64 + j as f64 / r.max(1.0)) * span / sectors as f64;
        DVec3::new(r * a.cos(), r * a.sin(), 0.0)
    };
    let mut positions = vec![DVec3::ZERO; nv];
    let mut verts = Vec::new();
    for s in 0..sectors {
        for i in 0..=k {
            for j in 0..=k - i {
                positions[id(s, i, j) as usize] = at(s, i, j);
            }
        }
        for i in 0..k {
            for j in 0..k - i {
                verts.extend([id(s, i, j), id(s, i + 1, j), id(s, i, j + 1)]);
                if i + j + 2 <= k {
                    verts.extend([id(s, i + 1, j), id(s, i + 1, j + 1), id(s, i, j + 1)]);
                }
            }
        }
    }
    let t = TopologyBuilder::new(nv)
        .build(&vec![3; verts.len() / 3], &verts)
        .expect("a lattice fan is a valid mesh");
    (t, positions)
}

/// A sparse row over a table's rows, re-expressed over the table's sources (entries in
/// order of first appearance).
pub fn expand_row(row: &[(u32, f64)], table: &subd_schemes::StencilTable) -> Vec<(u32, f64)> {
    let mut acc: std::collections::HashMap<u32, f64> = Default::default();
    let mut order = Vec::new();
    for &(v, w) in row {
        let (idx, wts) = table.row(v as usize);
        for (&s, &b) in idx.iter().zip(wts) {
            *acc.entry(s).or_insert_with(|| {
                order.push(s);
                0.0
            }) += w * b;
        }
    }
    order.into_iter().map(|s| (s, acc[&s])).collect()
}

/// A row of `r` from level `from` to level `to`, for vertex `c` of level `to`.
pub fn row_between(r: &Refinement, from: usize, to: usize, c: u32) -> Vec<(u32, f64)> {
    let mut row = vec![(c, 1.0)];
    for level in (from + 1..=to).rev() {
        row = expand_row(&row, r.stencils(level));
    }
    row
}

/// The masks of `scheme` (√3 or a butterfly) at a feature centre.
///
/// # Errors
/// [`LimitError::Analysis`] for Doo-Sabin, a centre out of range (3 to 64 edges; 1 to 32
/// boundary triangles), no invariant ball of radius ≤ 6, or a failed eigen solve.
pub fn feature_masks(scheme: &Scheme, centre: FeatureCentre) -> Result<FeatureMasks, LimitError> {
    if scheme.split() == Split::Dual {
        return Err(LimitError::Analysis(
            "Doo-Sabin's limit points are face centroids, not vertex masks".into(),
        ));
    }
    let (sectors, closed) = match centre {
        FeatureCentre::Boundary { faces } if (1..=32).contains(&faces) => (faces, false),
        FeatureCentre::Dart { valence } if (3..=64).contains(&valence) => (valence, true),
        _ => {
            return Err(LimitError::Analysis(format!(
                "no feature masks for {centre:?}"
            )));
        }
    };
    let steps = scheme.period();
    let analysis = |e: RefineError| LimitError::Analysis(e.to_string());
    for radius in 1..=6 {
        let (mut fan, positions) = triangle_fan(sectors, 2 * radius + 4, closed);
        if closed {
            // The dart's crease: spoke 0 from the centre to the edge of the fan.
            let mut prev = 0u32;
            // Vertex 1 is sector 0's lattice point (1, 0), the end of spoke 0.
            let mut next = 1u32;
            while let Some(e) = fan.find_edge(prev, next) {
                fan.set_edge_sharpness(e as usize, subd_mesh::tags::SHARPNESS_INFINITE);
                // Straight on: the neighbour of `next` opposite `prev` in its ring of six.
                let ring: Vec<u32> = ring_from(&fan, next, prev);
                if ring.len() != 6 || fan.is_boundary_vertex(next as usize) {
                    break;
                }
                (prev, next) = (next, ring[3]);
            }
        }
        let r =
            Refinement::new(&fan, scheme.clone(), &Options::default(), steps).map_err(analysis)?;
        let rows = |c: u32| row_between(&r, 0, steps, c);
        let Some(s) = feature_matrix(&fan, r.topology(steps), &rows, 0, radius) else {
            continue;
        };
        let labels = feature_ball(&fan, 0, radius).expect("a feature centre");
        let (limit, tangents) = left_masks(&s, &labels, &positions)?;
        return Ok(FeatureMasks {
            radius,
            steps,
            matrix: s,
            limit,
            tangents,
        });
    }
    Err(LimitError::Analysis(format!(
        "no invariant ball of radius ≤ 6 for {} at {centre:?}",
        scheme.name()
    )))
}

/// Limit and tangent masks from the dense local matrix `s` (left eigenvectors), the tangents
/// turned to follow the orientation of the planar fan whose ball `labels` has `positions`.
#[allow(clippy::type_complexity)]
fn left_masks(
    s: &Mat<f64>,
    labels: &[u32],
    positions: &[DVec3],
) -> Result<(Vec<f64>, Option<[Vec<f64>; 2]>), LimitError> {
    let m = s.nrows();
    let t = s.transpose().to_owned();
    let evd = t
        .eigen()
        .map_err(|e| LimitError::Analysis(format!("eigenvectors: {e:?}")))?;
    let values = evd.S();
    let vectors = evd.U();
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| values[b].norm().total_cmp(&values[a].norm()));
    let vec_of = |k: usize| -> Vec<f64> { (0..m).map(|i| vectors[(i, k)].re).collect() };
    let one = values[order[0]];
    if (one.re - 1.0).abs() > 1e-9 || one.im.abs() > 1e-9 {
        return Err(LimitError::Analysis(format!(
            "dominant eigenvalue {one} is not 1"
        )));
    }
    let mut limit = vec_of(order[0]);
    let total: f64 = limit.iter().sum();
    limit.iter_mut().for_each(|w| *w /= total);
    let tangents = (m >= 4).then(|| {
        let (l1, l2, l3) = (values[order[1]], values[order[2]], values[order[3]]);
        let real = |z: c64| z.im.abs() < 1e-9 && z.re > 1e-9;
        (real(l1) && real(l2) && l2.norm() > l3.norm() + 1e-9).then(|| {
            let (a, mut b) = (vec_of(order[1]), vec_of(order[2]));
            let apply = |w: &[f64]| -> DVec3 {
                labels
                    .iter()
                    .zip(w)
                    .map(|(&u, &x)| positions[u as usize] * x)
                    .sum()
            };
            if apply(&a).cross(apply(&b)).z < 0.0 {
                b.iter_mut().for_each(|x| *x = -*x);
            }
            [a, b]
        })
    });
    Ok((limit, tangents.flatten()))
}

#[cfg(test)]
mod tests;
