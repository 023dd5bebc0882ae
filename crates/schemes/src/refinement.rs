//! [`Refinement`]: uniform refinement with any [`Scheme`], the one entry for all eight.

use std::borrow::Cow;

use subd_mesh::{DVec3, Topology};

use crate::family::Family;
use crate::refine::{OsdRefinement, Sdc};
use crate::rules::Rule;
use crate::split_schemes::SplitRefinement;
use crate::stencil::StencilTable;
use crate::{ExplicitTags, FaceStream, Options, PointStream, RefineError, Scheme};

/// A uniform refinement with any [`Scheme`]: the topology of every level and the stencils
/// between levels.
///
/// The work OpenSubdiv's `TopologyRefiner` and `PrimvarRefiner` do is split the same way: the
/// constructor derives every level's topology (and, for OpenSubdiv's schemes, every vertex's
/// rule); [`Self::refine_points`] evaluates the masks level by level, in parallel (any other
/// primvar goes through the stencil tables, [`StencilTable::apply`]). Stencil tables and the
/// last level's full topology (edges, rings, tags) are built on first request, so a
/// refinement that only needs the final faces and positions does not pay for them. On a
/// closed, smooth mesh refined by Catmull-Clark (all quads, as every level after the first
/// is) or Loop the level before the last is not built either: the last level's faces, rules
/// and points are derived from the level two above, with the same results bit for bit
/// ([`Self::has_topology`]).
///
/// The same calls work for every scheme; only the scheme value changes:
///
/// ```
/// use subd_mesh::{DVec3, TopologyBuilder};
/// use subd_schemes::{Options, Refinement, Scheme};
///
/// // A tetrahedron.
/// let faces = [0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2];
/// let tet = TopologyBuilder::new(4).build(&[3; 4], &faces).unwrap();
/// let points = [DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE];
/// for name in ["loop", "sqrt3", "butterfly", "modified-butterfly", "catmull-clark"] {
///     let scheme: Scheme = name.parse().unwrap();
///     let r = Refinement::new(&tet, scheme, &Options::default(), 2).unwrap();
///     let level2 = r.refine_points(&points).pop().unwrap();
///     assert_eq!(level2.len(), r.num_vertices(2));
///     assert_eq!(r.faces(2).0.len() - 1, r.topology(2).num_faces());
/// }
/// ```
///
/// The two-phase scheme of Lin et al. refines with Catmull-Clark's topology; its level 1 is
/// phase 1:
///
/// ```
/// use subd_mesh::{DVec3, TopologyBuilder};
/// use subd_schemes::{Options, Refinement, Scheme, TwoPhase};
///
/// let faces = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4];
/// let cube = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
/// let points: Vec<DVec3> = (0..8)
///     .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
///     .collect();
/// // λ = 1 freezes the vertices in phase 1.
/// let scheme = Scheme::TwoPhase(TwoPhase::uniform(1.0).unwrap());
/// let r = Refinement::new(&cube, scheme, &Options::default(), 1).unwrap();
/// let level1 = r.refine_points(&points).pop().unwrap();
/// assert_eq!(level1[..8], points[..]);
/// ```
#[derive(Debug)]
pub struct Refinement {
    scheme: Scheme,
    options: Options,
    family: Box<dyn Family>,
}

impl Refinement {
    /// Refines `base` uniformly `levels` times with `scheme`. `options` are OpenSubdiv's
    /// (boundary interpolation, crease method, triangle rule); the split schemes have rules of
    /// their own and ignore them.
    ///
    /// # Errors
    /// [`RefineError`] naming the element: a face the scheme cannot take
    /// ([`Scheme::input_faces`]), a tag or non-manifold part it has no rule for
    /// ([`Scheme::tags`]), a two-phase `λ` missing or not one per vertex, a butterfly
    /// tension that is not finite, too many levels, or a level that does not fit memory or
    /// 32-bit indices.
    pub fn new(
        base: &Topology,
        scheme: Scheme,
        options: &Options,
        levels: usize,
    ) -> Result<Refinement, RefineError> {
        let family: Box<dyn Family> = match (&scheme, Sdc::of(&scheme)) {
            (Scheme::TwoPhase(tp), _) => {
                Box::new(OsdRefinement::two_phase(base, tp, options, levels)?)
            }
            (_, Some(sdc)) => Box::new(OsdRefinement::new(base, sdc, options, levels)?),
            (_, None) => Box::new(SplitRefinement::new(base, &scheme, levels)?),
        };
        Ok(Refinement {
            scheme,
            options: *options,
            family,
        })
    }

    /// Refines a level that is already prepared — its boundary and non-manifold tags
    /// applied and the rule of every vertex known, as in the levels of another refinement —
    /// `levels` more times with Catmull-Clark, Loop or Bilinear. Unlike [`Self::new`] it does
    /// not re-derive base-level tags (a non-manifold vertex of a refined level, for
    /// instance, is not a corner unless its tags say so). Used to continue refining a piece
    /// cut out of a refined level. A refined level of the two-phase scheme continues with
    /// Catmull-Clark (phase 1 is the first step only), and the result reports
    /// [`Scheme::CatmullClark`].
    ///
    /// # Errors
    /// As [`Self::new`]; also [`RefineError::RuleCount`] when `rules` does not have one rule
    /// per vertex, and [`RefineError::Unsupported`] for a scheme other than OpenSubdiv's
    /// three.
    pub fn from_prepared(
        level: Topology,
        rules: Vec<Rule>,
        scheme: Scheme,
        options: &Options,
        levels: usize,
    ) -> Result<Refinement, RefineError> {
        let Some(sdc) = Sdc::of(&scheme) else {
            return Err(RefineError::Unsupported {
                scheme: scheme.to_string(),
                what: "continuing from a prepared level needs one of OpenSubdiv's schemes",
            });
        };
        let family = OsdRefinement::from_prepared(level, rules, sdc, options, levels)?;
        Ok(Refinement {
            scheme: sdc.scheme(),
            options: *options,
            family: Box::new(family),
        })
    }

    /// The scheme.
    pub fn scheme(&self) -> &Scheme {
        &self.scheme
    }

    /// The options.
    pub fn options(&self) -> &Options {
        &self.options
    }

    /// Number of refined levels (level 0 is the base).
    pub fn num_levels(&self) -> usize {
        self.family.num_levels()
    }

    /// Number of vertices of `level`.
    pub fn num_vertices(&self, level: usize) -> usize {
        self.family.num_vertices(level)
    }

    /// Number of edges of `level`, without building its topology: each parent edge has two
    /// halves, and each parent face adds one interior edge per corner (Catmull-Clark,
    /// Bilinear) or three (Loop). `None` for a split scheme's last level while its topology
    /// is not built (its edges are only counted by building it).
    pub fn num_edges(&self, level: usize) -> Option<usize> {
        self.family.num_edges(level)
    }

    /// Whether any edge or vertex of `level` has a crease or corner sharpness above zero
    /// (boundary and non-manifold edges count: OpenSubdiv's schemes make them infinitely
    /// sharp), without building the level's topology. When it is `false`, the level's only
    /// tags are its holes ([`Self::holes`]), so [`Self::faces`] describes it whole.
    pub fn has_sharpness(&self, level: usize) -> bool {
        self.family.has_sharpness(level)
    }

    /// The crease and corner tags of `level` that a file must carry (see [`ExplicitTags`]),
    /// without building the level's topology.
    pub fn explicit_tags(&self, level: usize) -> ExplicitTags {
        self.family.explicit_tags(level)
    }

    /// Face offsets and face-vertex indices of `level`, without building its full topology.
    pub fn faces(&self, level: usize) -> (&[u32], &[u32]) {
        self.family.faces(level)
    }

    /// Hole flags of the faces of `level` (all `false` for the split schemes, which refuse
    /// holes).
    pub fn holes(&self, level: usize) -> Cow<'_, [bool]> {
        self.family.holes(level)
    }

    /// The faces of the last level, a range at a time, computed from the level above (or
    /// the one above that, see [`Self::has_topology`]) without building them all: for
    /// writing a deep level to a file. `None` when nothing is refined (level 0 is the last)
    /// or for the split schemes, whose levels hold their faces already.
    ///
    /// ```
    /// use subd_mesh::TopologyBuilder;
    /// use subd_schemes::{Options, Refinement, Scheme};
    ///
    /// let faces = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4];
    /// let cube = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
    /// let r = Refinement::new(&cube, Scheme::CatmullClark, &Options::default(), 3).unwrap();
    /// let stream = r.face_stream().unwrap();
    /// assert_eq!(stream.num_faces(), 6 * 64);
    /// let mut part = Vec::new();
    /// stream.fill(100..110, &mut part);
    /// assert_eq!(part[..], r.faces(3).1[4 * 100..4 * 110]);
    /// ```
    pub fn face_stream(&self) -> Option<FaceStream<'_>> {
        self.family.face_stream()
    }

    /// The points of the last level, a range at a time, from `above`, the points of the
    /// level before it ([`Self::points_at`]): bit for bit those of [`Self::refine_points`],
    /// without holding them all. `None` when nothing is refined, or for the split schemes.
    ///
    /// ```
    /// use subd_mesh::{DVec3, TopologyBuilder};
    /// use subd_schemes::{Options, Refinement, Scheme};
    ///
    /// let faces = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4];
    /// let cube = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
    /// let points: Vec<DVec3> = (0..8)
    ///     .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
    ///     .collect();
    /// let r = Refinement::new(&cube, Scheme::CatmullClark, &Options::default(), 2).unwrap();
    /// let above = r.points_at(&points, 1);
    /// let stream = r.point_stream(&above).unwrap();
    /// let mut part = vec![DVec3::ZERO; 20];
    /// stream.fill(50, &mut part);
    /// assert_eq!(part[..], r.refine_points(&points)[2][50..70]);
    /// ```
    ///
    /// # Panics
    /// If `above` does not have one point per vertex of the level before the last.
    pub fn point_stream<'a>(&'a self, above: &'a [DVec3]) -> Option<PointStream<'a>> {
        self.family.point_stream(above)
    }

    /// Topology of `level` (0 = base, with the boundary rules applied to its tags), built on
    /// first request where it is not built yet ([`Self::has_topology`]).
    pub fn topology(&self, level: usize) -> &Topology {
        self.family.topology(level)
    }

    /// Whether the full topology of `level` is built. The last level is built only on
    /// request; so is the level before it on a closed, smooth Catmull-Clark (all-quad) or Loop
    /// mesh, whose last level is then derived from the level two above (every result is the
    /// same as with the level built, bit for bit).
    ///
    /// ```
    /// use subd_mesh::TopologyBuilder;
    /// use subd_schemes::{Options, Refinement, Scheme};
    ///
    /// // A cube: closed, smooth, all quads.
    /// let faces = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4];
    /// let cube = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
    /// let r = Refinement::new(&cube, Scheme::CatmullClark, &Options::default(), 3).unwrap();
    /// assert!(r.has_topology(1));
    /// assert!(!r.has_topology(2) && !r.has_topology(3));
    /// assert_eq!(r.faces(3).1.len(), 4 * 6 * 64);
    /// assert_eq!(r.topology(3).num_faces(), 6 * 64); // builds levels 2 and 3
    /// assert!(r.has_topology(2));
    /// ```
    pub fn has_topology(&self, level: usize) -> bool {
        self.family.has_topology(level)
    }

    /// Takes the topology of `level` out of the refinement (building it if needed), without
    /// copying it.
    pub fn into_topology(self, level: usize) -> Topology {
        self.family.into_topology(level)
    }

    /// The rule of every vertex of `level` (for the split schemes, named from the level's
    /// feature edges and corner tags on first request).
    pub fn vertex_rules(&self, level: usize) -> &[Rule] {
        self.family.vertex_rules(level)
    }

    /// `λ` of every base vertex when this is a two-phase refinement.
    pub fn phase_one_lambda(&self) -> Option<&[f64]> {
        self.family.as_opensubdiv()?.phase_one_lambda()
    }

    /// Stencils giving the vertices of `level` from those of `level - 1` (`level ≥ 1`), built
    /// on first request.
    pub fn stencils(&self, level: usize) -> &StencilTable {
        self.family.stencils(level)
    }

    /// One table from the base vertices to the vertices of `level`.
    pub fn composed(&self, level: usize) -> StencilTable {
        let mut t = StencilTable::identity(self.num_vertices(0));
        for l in 1..=level {
            t = t.then(self.stencils(l));
        }
        t
    }

    /// Positions of every level from base positions (`result[0]` is `base`), evaluating the
    /// masks directly, level by level, in parallel.
    ///
    /// # Panics
    /// If `base.len()` differs from the number of base vertices.
    pub fn refine_points(&self, base: &[DVec3]) -> Vec<Vec<DVec3>> {
        self.check_base(base);
        let mut out = vec![base.to_vec()];
        for l in 1..=self.num_levels() {
            let next = self.family.next_points(l, out.last().expect("level 0"));
            out.push(next);
        }
        out
    }

    /// The points of `level` from `above`, the points of the level before it (one step of
    /// [`Self::points_at`], bit for bit).
    ///
    /// # Panics
    /// If `level` is 0 or not refined, or `above` does not have one point per vertex of
    /// the level before.
    pub fn next_level_points(&self, level: usize, above: &[DVec3]) -> Vec<DVec3> {
        assert!(
            (1..=self.num_levels()).contains(&level),
            "level {level} is not refined"
        );
        assert_eq!(
            above.len(),
            self.num_vertices(level - 1),
            "one point per vertex of level {}",
            level - 1
        );
        self.family.next_points(level, above)
    }

    /// Positions of `level` alone from base positions, each level dropped once the next is
    /// computed: [`Self::refine_points`]`(base)[level]` in less memory.
    ///
    /// # Panics
    /// If `base.len()` differs from the number of base vertices, or `level` is beyond
    /// [`Self::num_levels`].
    pub fn points_at(&self, base: &[DVec3], level: usize) -> Vec<DVec3> {
        self.check_base(base);
        assert!(level <= self.num_levels(), "level {level} is not refined");
        let mut points = base.to_vec();
        for l in 1..=level {
            points = self.family.next_points(l, &points);
        }
        points
    }

    /// OpenSubdiv's family behind this refinement, when the scheme is one of its.
    pub(crate) fn opensubdiv(&self) -> Option<&OsdRefinement> {
        self.family.as_opensubdiv()
    }

    fn check_base(&self, base: &[DVec3]) {
        assert_eq!(
            base.len(),
            self.num_vertices(0),
            "one position per base vertex"
        );
    }
}
