//! The restricted hierarchy and its closure.
//!
//! Level `l` holds the faces of uniform level `l` whose parents were refined. Three rules
//! decide which of them are refined in turn, and the hierarchy is rebuilt until all three
//! hold at once:
//!
//! 1. **Selection**: the criteria's union ([`crate::criteria`]).
//! 2. **Red-green closure** (Sun et al. 2012 §2.3): a face that would be left with more edges split
//!    by finer neighbours than a transition pattern covers is refined itself — a triangle
//!    with three split edges; a quad with three or four; a Catmull-Clark base face that is
//!    not a quad with any.
//! 3. **Balance**: when a face `f` of level `l ≥ 1` is refined, every face of level `l − 1`
//!    sharing a vertex with `f`'s parent is refined. This is what makes `f`'s children exact:
//!    their masks read the faces around `f`'s vertices, which are children of exactly those
//!    faces. It also keeps leaves sharing an edge or a vertex within one level of each other.
//!
//! Rule 3 reaches back to coarser levels. Such a request is recorded (by uniform face index,
//! which survives rebuilding), the hierarchy returns to that level and goes forward again.
//! Every rule only ever adds refined faces, so this ends, at the smallest hierarchy that
//! satisfies all three — whatever order faces are visited in.

use std::collections::HashSet;

use glam::DVec3;
use rayon::prelude::*;
use subd_mesh::Topology;
use subd_schemes::{Options, Scheme};

use crate::criteria::{Criterion, EveryFace, LevelView};
use crate::level::SparseLevel;
use crate::{AdaptiveError, AdaptiveMesh, MAX_LEVELS};
use subd_mesh::cut::NONE;
use subd_schemes::{ChildLayout, LevelCounts};

/// Adaptive refinement of a mesh: the hierarchy of levels, each with the faces of uniform
/// refinement that exist there (exact positions, uniform indices), and which of them are
/// refined. [`Self::mesh`] closes the leaves into a conforming mesh.
///
/// ```
/// use subd_adaptive::{AdaptiveRefinement, FaceSelection, Positions};
/// use subd_mesh::{DVec3, TopologyBuilder};
/// use subd_schemes::{Options, Scheme};
///
/// // An octahedron; refine the descendants of face 0 three levels with Loop.
/// let fv = [0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1, 5, 2, 1, 5, 3, 2, 5, 4, 3, 5, 1, 4];
/// let topo = TopologyBuilder::new(6).build(&[3; 8], &fv).unwrap();
/// let points = [DVec3::Z, DVec3::X, DVec3::Y, -DVec3::X, -DVec3::Y, -DVec3::Z];
/// let select = FaceSelection::from_faces(8, &[0]).unwrap();
/// let a = AdaptiveRefinement::new(&topo, &points, &Scheme::Loop, &Options::default(), &[&select], 3)
///     .unwrap();
/// let mesh = a.mesh(Positions::Refined).unwrap();
/// // Far fewer faces than uniform level 3 (512), closed and crack-free.
/// assert!(mesh.num_faces() < 512);
/// let report = mesh.conformity();
/// assert!(report.conforming && report.boundary_edges == 0);
/// assert!(report.max_level_difference_vertex <= 1);
/// ```
#[derive(Debug)]
pub struct AdaptiveRefinement {
    pub(crate) scheme: Scheme,
    pub(crate) options: Options,
    pub(crate) levels: Vec<SparseLevel>,
    pub(crate) uniform: ChildLayout,
    level_builds: usize,
    /// The last conforming mesh the criteria judged (the final one), kept for
    /// [`Self::take_mesh`].
    judged: Option<(Positions, AdaptiveMesh)>,
    /// The largest error each criterion measured on it.
    final_errors: Vec<Option<f64>>,
}

/// Which positions the conforming mesh gets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Positions {
    /// Each vertex at its position in uniform refinement at the finest level it has in the
    /// result.
    Refined,
    /// Each vertex at its exact limit position, with limit normals.
    Limit,
}

impl AdaptiveRefinement {
    /// Refines `base` (positions `points`) adaptively with `scheme` and `options`, at most
    /// `max_level` levels deep, refining the faces any of `criteria` selects (every face when
    /// `criteria` is empty) and what the closure adds.
    ///
    /// # Errors
    /// [`AdaptiveError::Scheme`] for a scheme other than Catmull-Clark, Loop and Bilinear,
    /// [`AdaptiveError::TooManyLevels`], [`AdaptiveError::PointCount`], a refinement error
    /// (Loop on a face that is not a triangle), or a criterion's error.
    pub fn new(
        base: &Topology,
        points: &[DVec3],
        scheme: &Scheme,
        options: &Options,
        criteria: &[&dyn Criterion],
        max_level: usize,
    ) -> Result<Self, AdaptiveError> {
        Self::with_progress(
            base,
            points,
            scheme,
            options,
            criteria,
            max_level,
            &mut |_, _| {},
        )
    }

    /// [`Self::new`], calling `progress(level, faces)` each time a level is built.
    ///
    /// # Errors
    /// As [`Self::new`].
    pub fn with_progress(
        base: &Topology,
        points: &[DVec3],
        scheme: &Scheme,
        options: &Options,
        criteria: &[&dyn Criterion],
        max_level: usize,
        progress: &mut dyn FnMut(usize, usize),
    ) -> Result<Self, AdaptiveError> {
        check_arguments(scheme, max_level)?;
        let every = EveryFace;
        let criteria: Vec<&dyn Criterion> = if criteria.is_empty() {
            vec![&every]
        } else {
            criteria.to_vec()
        };
        let mut uniform =
            ChildLayout::new(base, scheme, max_level).ok_or_else(|| AdaptiveError::Scheme {
                scheme: scheme.to_string(),
            })?;
        let mut levels = vec![SparseLevel::base(base, points, scheme, options)?];
        let mut requests: Vec<HashSet<u64>> = vec![HashSet::new(); max_level];
        // The criteria's selection of each level built, kept while the level is: when the
        // closure returns to a level, only its requests changed.
        let mut picked: Vec<Vec<bool>> = Vec::new();
        let mut level_builds = 1;
        let mut l = 0;
        loop {
            while l < max_level {
                if picked.len() <= l {
                    picked.push(select(&levels[l], l, &criteria)?);
                }
                let sel = decide(&levels[l], &picked[l], &requests[l], scheme);
                if l > 0 {
                    let before = requests[l - 1].len();
                    request_support(&levels[l - 1], &levels[l], &sel, &mut requests[l - 1]);
                    if requests[l - 1].len() > before {
                        levels.truncate(l);
                        picked.truncate(l);
                        l -= 1;
                        continue;
                    }
                }
                let any = sel.iter().any(|&s| s);
                levels[l].refined = sel;
                if !any {
                    break;
                }
                let child = levels[l].refine(l + 1, scheme, options, &uniform)?;
                level_builds += 1;
                progress(l + 1, child.num_faces());
                levels.push(child);
                l += 1;
            }
            // Criteria that judge the conforming mesh: refine the leaves of the faces they
            // reject, and go back to the coarsest such level.
            let mut h = AdaptiveRefinement {
                scheme: scheme.clone(),
                options: *options,
                levels,
                uniform,
                level_builds,
                judged: None,
                final_errors: vec![None; criteria.len()],
            };
            let Some(r) = h.judge_output(&criteria, &mut requests, max_level)? else {
                return Ok(h);
            };
            h.levels.truncate(r + 1);
            picked.truncate(r + 1);
            (levels, uniform, level_builds) = (h.levels, h.uniform, h.level_builds);
            l = r;
        }
    }

    /// Lets the criteria that judge the conforming mesh judge it: the leaves of the faces
    /// they reject are requested for refinement. The coarsest level that got a new request,
    /// where the hierarchy must be rebuilt from; `None` when every criterion is met.
    fn judge_output(
        &mut self,
        criteria: &[&dyn Criterion],
        requests: &mut [HashSet<u64>],
        max_level: usize,
    ) -> Result<Option<usize>, AdaptiveError> {
        let mut restart = None;
        for (i, c) in criteria.iter().enumerate() {
            let Some(positions) = c.output_positions() else {
                continue;
            };
            let mesh = match self.judged.take() {
                Some((p, mesh)) if p == positions => mesh,
                _ => self.mesh(positions)?,
            };
            let judgement = c.judge(&mesh)?;
            self.final_errors[i] = judgement.worst;
            for (f, rejected) in judgement.rejected.into_iter().enumerate() {
                let level = mesh.face_levels[f] as usize;
                if rejected && level < max_level && requests[level].insert(mesh.face_uniform[f]) {
                    restart = Some(restart.map_or(level, |r: usize| r.min(level)));
                }
            }
            self.judged = Some((positions, mesh));
        }
        Ok(restart)
    }

    /// The scheme.
    pub fn scheme(&self) -> &Scheme {
        &self.scheme
    }

    /// The options.
    pub fn options(&self) -> &Options {
        &self.options
    }

    /// The deepest level that has faces.
    pub fn depth(&self) -> usize {
        self.levels.len() - 1
    }

    /// Faces that exist at `level` (refined or not).
    pub fn num_faces(&self, level: usize) -> usize {
        self.levels[level].num_faces()
    }

    /// Faces refined at `level`.
    pub fn num_refined(&self, level: usize) -> usize {
        self.levels[level].refined.iter().filter(|&&r| r).count()
    }

    /// Element counts of uniform refinement at `level` (up to the level cap).
    pub fn uniform_counts(&self, level: usize) -> LevelCounts {
        self.uniform.counts(level)
    }

    /// The conforming mesh with vertices at `positions`: the one the criteria judged last
    /// when it has those positions (taken, not built again), otherwise [`Self::mesh`].
    ///
    /// # Errors
    /// As [`Self::mesh`].
    pub fn take_mesh(&mut self, positions: Positions) -> Result<AdaptiveMesh, AdaptiveError> {
        match self.judged.take() {
            Some((p, mesh)) if p == positions => Ok(mesh),
            _ => self.mesh(positions),
        }
    }

    /// The largest error each criterion (in the order given) measured on the final
    /// conforming mesh ([`Criterion::judge`]); `None` for one that measures none (one `None`
    /// with no criterion given: every face is refined).
    pub fn final_errors(&self) -> &[Option<f64>] {
        &self.final_errors
    }

    /// How many times a level was built, rebuilds after the closure reached back included.
    pub fn level_builds(&self) -> usize {
        self.level_builds
    }

    /// The faces of `level` as criteria see them.
    pub fn level_view(&self, level: usize) -> LevelView<'_> {
        LevelView {
            level,
            data: &self.levels[level],
        }
    }

    /// Uniform index of each vertex of `level` and its position there (exactly uniform
    /// refinement's).
    pub fn level_vertices(&self, level: usize) -> impl Iterator<Item = (u64, DVec3)> + '_ {
        let l = &self.levels[level];
        l.vertex_key.iter().copied().zip(l.points.iter().copied())
    }

    /// Uniform index of each face of `level`, its vertices' uniform indices and whether it
    /// is refined.
    pub fn level_faces(&self, level: usize) -> impl Iterator<Item = (u64, Vec<u64>, bool)> + '_ {
        let l = &self.levels[level];
        (0..l.num_faces()).map(move |f| {
            let corners = l
                .topology
                .face_vertices(f)
                .iter()
                .map(|&v| l.vertex_key[v as usize])
                .collect();
            (l.face_key[f], corners, l.refined[f])
        })
    }
}

/// The faces of level `l` the criteria select (their union).
fn select(
    level: &SparseLevel,
    l: usize,
    criteria: &[&dyn Criterion],
) -> Result<Vec<bool>, AdaptiveError> {
    let mut sel = vec![false; level.num_faces()];
    let view = LevelView {
        level: l,
        data: level,
    };
    for c in criteria {
        c.select(&view, &mut sel)?;
    }
    Ok(sel)
}

/// The faces of a level to refine: the criteria's selection `picked`, the faces requested by
/// finer levels, and the red-green closure.
fn decide(
    level: &SparseLevel,
    picked: &[bool],
    requests: &HashSet<u64>,
    scheme: &Scheme,
) -> Vec<bool> {
    let mut sel = picked.to_vec();
    if !requests.is_empty() {
        for (s, k) in sel.iter_mut().zip(&level.face_key) {
            if requests.contains(k) {
                *s = true;
            }
        }
    }
    red_green(&level.topology, &mut sel, scheme);
    sel
}

/// Whether a face left unrefined with `split` edges split by finer neighbours has no
/// transition pattern, and must be refined.
fn needs_refining(scheme: &Scheme, size: usize, split: usize) -> bool {
    match (scheme, size) {
        (Scheme::Loop, _) => split >= 3,
        (_, 4) => split >= 3,
        _ => split >= 1,
    }
}

/// Edges of face `f` with another face across that is refined.
fn split_edges(t: &Topology, sel: &[bool], f: usize) -> usize {
    t.face_edges(f)
        .iter()
        .filter(|&&e| {
            t.edge_faces(e as usize)
                .iter()
                .any(|&g| g as usize != f && sel[g as usize])
        })
        .count()
}

/// Refines every face that the transition patterns cannot close, until none is left.
fn red_green(t: &Topology, sel: &mut [bool], scheme: &Scheme) {
    let mut queue: Vec<u32> = (0..t.num_faces())
        .into_par_iter()
        .filter(|&f| !sel[f] && split_edges(t, sel, f) > 0)
        .map(|f| f as u32)
        .collect();
    while let Some(f) = queue.pop() {
        let f = f as usize;
        if sel[f] || !needs_refining(scheme, t.face_size(f), split_edges(t, sel, f)) {
            continue;
        }
        sel[f] = true;
        for &e in t.face_edges(f) {
            for &g in t.edge_faces(e as usize) {
                if !sel[g as usize] {
                    queue.push(g);
                }
            }
        }
    }
}

/// Records the faces of `up` (the level above `level`) that must be refined for the faces
/// `sel` of `level` to be refined: every face sharing a vertex with a refined face's parent.
fn request_support(up: &SparseLevel, level: &SparseLevel, sel: &[bool], out: &mut HashSet<u64>) {
    let t = &up.topology;
    for f in (0..sel.len()).filter(|&f| sel[f]) {
        let p = level.face_parent[f];
        debug_assert_ne!(p, NONE);
        for &v in t.face_vertices(p as usize) {
            for &g in t.vertex_faces(v as usize) {
                if !up.refined[g as usize] {
                    out.insert(up.face_key[g as usize]);
                }
            }
        }
    }
}

/// The schemes adaptive refinement covers, and the level cap.
fn check_arguments(scheme: &Scheme, max_level: usize) -> Result<(), AdaptiveError> {
    if !matches!(
        scheme,
        Scheme::CatmullClark | Scheme::Loop | Scheme::Bilinear
    ) {
        return Err(AdaptiveError::Scheme {
            scheme: scheme.to_string(),
        });
    }
    if max_level > MAX_LEVELS {
        return Err(AdaptiveError::TooManyLevels {
            levels: max_level,
            max: MAX_LEVELS,
        });
    }
    Ok(())
}
