//! [`OsdRefinement`]: the topology of every level of a uniform refinement and the stencils
//! between levels, for OpenSubdiv's schemes and the two-phase scheme (the family behind
//! [`crate::Refinement`] for those schemes).

use std::sync::OnceLock;

use subd_mesh::{DVec3, Topology};

use super::Sdc;
use crate::facts::{Capability, FaceKind, OPENSUBDIV_TAGS, SchemeFacts, Split, TagSupport};
use crate::rules::Rule;
use crate::stencil::StencilTable;
use crate::{ExplicitTags, MAX_LEVELS, Options, RefineError};
use subd_mesh::memory;

/// One level of a refinement.
#[derive(Debug)]
struct Level {
    /// Full topology with tags; built eagerly below the last level (the next level needs it),
    /// on first request for the last, and for the level before it when the last comes from
    /// its grandparent.
    topology: OnceLock<Topology>,
    /// Face lists of the last level without its full topology, built on first request.
    faces: OnceLock<super::ChildFaces>,
    /// Rule of every vertex.
    rules: Vec<Rule>,
    /// Number of vertices.
    num_vertices: usize,
    /// Faces, rules and points of this level come from the level two above
    /// ([`super::grandchild_points`]): the level above is not built unless asked for.
    from_grandparent: bool,
}

/// A uniform refinement: the topology of every level and the stencils between levels.
///
/// The work OpenSubdiv's `TopologyRefiner` and `PrimvarRefiner` do is split the same way: the
/// constructor derives every level's topology and vertex rules; [`Self::refine_points`]
/// evaluates the masks level by level (any other primvar goes through the stencil tables,
/// [`StencilTable::apply`]). Stencil tables and the last
/// level's full topology (edges, rings, tags) are built on first request, so a refinement that
/// only needs the final faces and positions does not pay for them. On a closed, smooth
/// mesh refined by Catmull-Clark (all quads, as every level after the first is) or Loop (no
/// boundary, crease, corner, hole or non-manifold part) the level before the last is not
/// built either: the last level's faces, rules and points are derived from the level two
/// above, with the same results bit for bit ([`Self::has_topology`]).
#[derive(Debug)]
pub(crate) struct OsdRefinement {
    scheme: Sdc,
    options: Options,
    levels: Vec<Level>,
    stencils: Vec<OnceLock<StencilTable>>,
    /// `λ` per base vertex when the first step is the two-phase scheme's phase 1.
    phase_one: Option<Vec<f64>>,
}

/// What every refinement checks first: the level count, and triangles for Loop.
fn check_request(t: &Topology, scheme: Sdc, levels: usize) -> Result<(), RefineError> {
    if levels > MAX_LEVELS {
        return Err(RefineError::TooManyLevels {
            levels,
            max: MAX_LEVELS,
        });
    }
    if scheme == Sdc::Loop
        && let Some(f) = (0..t.num_faces()).find(|&f| t.face_size(f) != 3)
    {
        return Err(RefineError::NotTriangle {
            scheme: "Loop",
            face: f,
            size: t.face_size(f),
        });
    }
    Ok(())
}

impl OsdRefinement {
    /// Refines `base` uniformly `levels` times.
    pub fn new(
        base: &Topology,
        scheme: Sdc,
        options: &Options,
        levels: usize,
    ) -> Result<Self, RefineError> {
        check_request(base, scheme, levels)?;
        let (t0, rules0) = super::prepare_base(base, scheme, options);
        Self::refine_prepared(t0, rules0, scheme, options, levels)
    }

    /// Refines a level that is already prepared — its boundary and non-manifold tags
    /// applied and the rule of every vertex known, as in the levels of another refinement —
    /// `levels` more times. Unlike [`Self::new`] it does not re-derive base-level tags (a
    /// non-manifold vertex of a refined level, for instance, is not a corner unless its tags
    /// say so). Used to continue refining a piece cut out of a refined level.
    ///
    /// # Errors
    /// As [`Self::new`]; also [`RefineError::RuleCount`] when `rules` does not have one rule
    /// per vertex.
    pub fn from_prepared(
        level: Topology,
        rules: Vec<Rule>,
        scheme: Sdc,
        options: &Options,
        levels: usize,
    ) -> Result<Self, RefineError> {
        if rules.len() != level.num_vertices() {
            return Err(RefineError::RuleCount {
                rules: rules.len(),
                vertices: level.num_vertices(),
            });
        }
        check_request(&level, scheme, levels)?;
        Self::refine_prepared(level, rules, scheme, options, levels)
    }

    fn refine_prepared(
        t0: Topology,
        rules0: Vec<Rule>,
        scheme: Sdc,
        options: &Options,
        levels: usize,
    ) -> Result<Self, RefineError> {
        let mut r = OsdRefinement {
            scheme,
            options: *options,
            levels: vec![Level {
                num_vertices: t0.num_vertices(),
                topology: OnceLock::from(t0),
                faces: OnceLock::new(),
                rules: rules0,
                from_grandparent: false,
            }],
            stencils: (0..levels).map(|_| OnceLock::new()).collect(),
            phase_one: None,
        };
        for l in 1..=levels {
            let p = r.levels[l - 1]
                .topology
                .get()
                .expect("parent level is built");
            // Each level multiplies face-vertices by 4 (quad split) or 4 (triangles, 3 → 12).
            if 4 * p.num_face_vertices() as u64 + 4 * p.num_edges() as u64 >= u32::MAX as u64 {
                return Err(RefineError::TooLarge { level: l });
            }
            // Refuse a level whose arrays cannot be allocated before filling any of them.
            let child = super::LevelCounts::of(p).refined(&scheme.scheme());
            let fused = l + 1 == levels;
            let need = match (l < levels, fused) {
                (true, true) => super::last_level_bytes(child.refined(&scheme.scheme())),
                (true, false) => super::topology_bytes(child),
                (false, _) => super::last_level_bytes(child),
            };
            if !memory::can_allocate(need) {
                let level = if fused { levels } else { l };
                return Err(RefineError::OutOfMemory { level, bytes: need });
            }
            let layout = super::Layout::new(p, scheme);
            let rules = super::child_rules(p, &r.levels[l - 1].rules, options, layout);
            if l + 1 == levels && super::fusion_applies(p, &r.levels[l - 1].rules, scheme) {
                // The last two levels of a closed smooth mesh: the last one straight from
                // this parent, its own parent left unbuilt.
                if super::fused_child_too_large(p, scheme) {
                    return Err(RefineError::TooLarge { level: levels });
                }
                let num_vertices = super::grandchild_num_vertices(p, scheme);
                let last = Level {
                    num_vertices,
                    topology: OnceLock::new(),
                    faces: OnceLock::new(),
                    // Closed and smooth stays closed and smooth: no creases, no corners.
                    rules: vec![Rule::Smooth; num_vertices],
                    from_grandparent: true,
                };
                r.levels.push(Level {
                    num_vertices: layout.num_child_vertices,
                    topology: OnceLock::new(),
                    faces: OnceLock::new(),
                    rules,
                    from_grandparent: false,
                });
                r.levels.push(last);
                break;
            }
            let level = if l < levels {
                Level {
                    num_vertices: layout.num_child_vertices,
                    topology: OnceLock::from(super::child_topology(p, scheme, options, layout)),
                    faces: OnceLock::new(),
                    rules,
                    from_grandparent: false,
                }
            } else {
                Level {
                    num_vertices: layout.num_child_vertices,
                    topology: OnceLock::new(),
                    faces: OnceLock::new(),
                    rules,
                    from_grandparent: false,
                }
            };
            r.levels.push(level);
        }
        Ok(r)
    }

    /// Refines `base` with the two-phase modified Catmull-Clark scheme of Lin et al.: level 1
    /// is phase 1 (the modified vertex rule with `two_phase`'s `λ`, see
    /// [`two_phase`](crate::two_phase)), levels 2 and on are ordinary Catmull-Clark.
    ///
    /// # Errors
    /// [`RefineError::NotQuad`] for a face that is not a quad, [`RefineError::LambdaCount`]
    /// or [`RefineError::MissingLambda`] when there is not one `λ` per vertex, and as
    /// [`Self::new`].
    pub fn two_phase(
        base: &Topology,
        two_phase: &crate::TwoPhase,
        options: &Options,
        levels: usize,
    ) -> Result<Self, RefineError> {
        if let Some(f) = (0..base.num_faces()).find(|&f| base.face_size(f) != 4) {
            return Err(RefineError::NotQuad {
                face: f,
                size: base.face_size(f),
            });
        }
        let lambda = two_phase.lambda_for(base.num_vertices())?;
        let mut r = Self::new(base, Sdc::CatmullClark, options, levels)?;
        r.phase_one = Some(lambda);
        Ok(r)
    }

    /// `λ` of every base vertex when this is a two-phase refinement.
    pub fn phase_one_lambda(&self) -> Option<&[f64]> {
        self.phase_one.as_deref()
    }

    /// Number of refined levels (level 0 is the base).
    pub fn num_levels(&self) -> usize {
        self.levels.len() - 1
    }

    /// Number of vertices of `level`.
    pub fn num_vertices(&self, level: usize) -> usize {
        self.levels[level].num_vertices
    }

    /// Number of edges of `level`, without building its topology: each parent edge has two
    /// halves, and each parent face adds one interior edge per corner (Catmull-Clark,
    /// bilinear) or three (Loop).
    pub fn num_edges(&self, level: usize) -> usize {
        if let Some(t) = self.levels[level].topology.get() {
            return t.num_edges();
        }
        if self.skips_parent(level) {
            return super::grandchild_num_edges(self.topology(level - 2), self.scheme);
        }
        // Only the last level can be unbuilt, and it is not the base level.
        let p = self.topology(level - 1);
        super::Layout::new(p, self.scheme).half_edge_base as usize + 2 * p.num_edges()
    }

    /// Whether any edge or vertex of `level` has a crease or corner sharpness above zero
    /// (boundary and non-manifold edges count: the refinement makes them infinitely
    /// sharp), without building the level's topology. When it is `false`, the level's
    /// only tags are its holes ([`Self::holes`]), so [`Self::faces`] describes it whole.
    pub fn has_sharpness(&self, level: usize) -> bool {
        if let Some(t) = self.levels[level].topology.get() {
            let tags = t.tags();
            return tags.edge_sharpness().iter().any(|&s| s > 0.0)
                || tags.vertex_sharpness().iter().any(|&s| s > 0.0);
        }
        if self.levels[level].from_grandparent {
            return false;
        }
        super::child_has_sharpness(self.topology(level - 1), &self.options)
    }

    /// The crease and corner tags of `level` that a file must carry (see [`ExplicitTags`]),
    /// without building the level's topology.
    pub fn explicit_tags(&self, level: usize) -> ExplicitTags {
        if let Some(t) = self.levels[level].topology.get() {
            return super::explicit_tags(t, &self.options);
        }
        if self.levels[level].from_grandparent {
            return ExplicitTags::default();
        }
        super::child_explicit_tags(self.topology(level - 1), self.scheme, &self.options)
    }

    /// Face offsets and face-vertex indices of `level`, without building its full topology.
    pub fn faces(&self, level: usize) -> (&[u32], &[u32]) {
        match self.face_lists(level) {
            Some(f) => (&f.offsets, &f.vertices),
            None => {
                let t = self.topology(level);
                (t.face_offsets(), t.all_face_vertices())
            }
        }
    }

    /// Hole flags of the faces of `level`.
    pub fn holes(&self, level: usize) -> &[bool] {
        match self.face_lists(level) {
            Some(f) => &f.holes,
            None => self.topology(level).tags().holes(),
        }
    }

    /// The face lists of an unbuilt level, built on first request; `None` where the
    /// level's topology is built (or is to be, below the last level).
    fn face_lists(&self, level: usize) -> Option<&super::ChildFaces> {
        let lists = &self.levels[level].faces;
        if lists.get().is_none()
            && (level == 0 || level < self.num_levels() || self.has_topology(level))
        {
            return None;
        }
        Some(lists.get_or_init(|| {
            if self.skips_parent(level) {
                let g = self.topology(level - 2);
                let (offsets, vertices) = super::grandchild_faces(g, self.scheme);
                // A level refined from its grandparent has no holes.
                let holes = memory::zeroed(offsets.len() - 1);
                super::ChildFaces {
                    offsets,
                    vertices,
                    holes,
                }
            } else {
                super::child_faces(self.topology(level - 1), self.scheme)
            }
        }))
    }

    /// The faces of the last level, a range at a time, computed from the level above (or
    /// the one above that, see [`Self::has_topology`]) without building them all: for
    /// writing a deep level to a file. `None` when nothing is refined (level 0 is the
    /// last).
    pub fn face_stream(&self) -> Option<super::FaceStream<'_>> {
        let last = self.num_levels();
        if last == 0 {
            return None;
        }
        let quads = self.scheme != Sdc::Loop;
        Some(if self.skips_parent(last) {
            super::FaceStream::grandchild(self.topology(last - 2), quads)
        } else if quads {
            super::FaceStream::quad_split(self.topology(last - 1))
        } else {
            super::FaceStream::tri_split(self.topology(last - 1))
        })
    }

    /// The points of the last level, a range at a time, from `above`, the points of the
    /// level before it ([`Self::points_at`]): bit for bit those of [`Self::refine_points`],
    /// without holding them all. `None` when nothing is refined.
    ///
    /// # Panics
    /// If `above` does not have one point per vertex of the level before the last.
    pub fn point_stream<'a>(&'a self, above: &'a [DVec3]) -> Option<super::PointStream<'a>> {
        let last = self.num_levels();
        if last == 0 {
            return None;
        }
        assert_eq!(
            above.len(),
            self.num_vertices(last - 1),
            "one point per vertex of level {}",
            last - 1
        );
        Some(if self.skips_parent(last) {
            let g = self.topology(last - 2);
            match self.scheme {
                Sdc::Loop => super::PointStream::loop_grandchild(g, above),
                _ => super::PointStream::catmark_grandchild(g, above),
            }
        } else {
            super::PointStream::step(self.step(last), above)
        })
    }

    /// Topology of `level` (0 = base, with the boundary rules applied to its tags), built on
    /// first request where it is not built yet ([`Self::has_topology`]).
    pub fn topology(&self, level: usize) -> &Topology {
        self.levels[level].topology.get_or_init(|| {
            let p = self.topology(level - 1);
            let layout = super::Layout::new(p, self.scheme);
            super::child_topology(p, self.scheme, &self.options, layout)
        })
    }

    /// Whether the full topology of `level` is built. The last level is built only on
    /// request; so is the level before it on a closed, smooth Catmull-Clark (all-quad) or Loop
    /// mesh, whose last level is then derived from the level two above (every result is the
    /// same as with the level built, bit for bit).
    pub fn has_topology(&self, level: usize) -> bool {
        self.levels[level].topology.get().is_some()
    }

    /// Takes the topology of `level` out of the refinement (building it if needed), without
    /// copying it.
    pub fn into_topology(mut self, level: usize) -> Topology {
        self.topology(level);
        self.levels
            .swap_remove(level)
            .topology
            .into_inner()
            .expect("built just above")
    }

    /// The rule of every vertex of `level`.
    pub fn vertex_rules(&self, level: usize) -> &[Rule] {
        &self.levels[level].rules
    }

    pub(super) fn step(&self, level: usize) -> super::Step<'_> {
        let p = self.topology(level - 1);
        super::Step {
            parent: p,
            parent_rules: &self.levels[level - 1].rules,
            child_rules: &self.levels[level].rules,
            scheme: self.scheme,
            options: &self.options,
            layout: super::Layout::new(p, self.scheme),
            phase_one: if level == 1 {
                self.phase_one.as_deref()
            } else {
                None
            },
        }
    }

    /// Stencils giving the vertices of `level` from those of `level - 1` (`level ≥ 1`), built
    /// on first request.
    pub fn stencils(&self, level: usize) -> &StencilTable {
        self.stencils[level - 1].get_or_init(|| self.step(level).stencils())
    }

    /// Whether `level` comes from its grandparent with the level between still unbuilt
    /// (so its faces and points are derived from `level - 2`).
    fn skips_parent(&self, level: usize) -> bool {
        self.levels[level].from_grandparent && !self.has_topology(level - 1)
    }

    /// Points of `level` from those of the level above.
    pub(crate) fn next_points(&self, level: usize, src: &[DVec3]) -> Vec<DVec3> {
        if self.skips_parent(level) {
            super::grandchild_points(self.topology(level - 2), self.scheme, src)
        } else {
            self.step(level).points(src)
        }
    }
}

/// Catmull-Clark's facts (OpenSubdiv's masks, `Sdc::Scheme<CATMARK>`).
pub(crate) const CATMULL_CLARK: SchemeFacts = SchemeFacts {
    name: "catmull-clark",
    summary: "Catmull-Clark (OpenSubdiv's), any polygons",
    input_faces: FaceKind::Any,
    split: Split::Quad,
    interpolating: false,
    opensubdiv_family: true,
    tags: OPENSUBDIV_TAGS,
    peak_bytes_per_vertex: (105, Some(70)),
    // Everything subd computes, it computes for Catmull-Clark.
    capabilities: &Capability::ALL,
};

/// Loop's facts (OpenSubdiv's masks, `Sdc::Scheme<LOOP>`).
pub(crate) const LOOP: SchemeFacts = SchemeFacts {
    name: "loop",
    summary: "Loop (OpenSubdiv's), triangles",
    input_faces: FaceKind::Triangles,
    split: Split::Triangle,
    peak_bytes_per_vertex: (120, Some(90)),
    ..CATMULL_CLARK
};

/// Bilinear's facts: it keeps every vertex and edge, so sharpness changes nothing and the
/// mesh is its own limit.
pub(crate) const BILINEAR: SchemeFacts = SchemeFacts {
    name: "bilinear",
    summary: "Bilinear (OpenSubdiv's), any polygons",
    interpolating: true,
    tags: TagSupport {
        semi_sharp_creases: false,
        infinite_creases: false,
        corners: false,
        ..OPENSUBDIV_TAGS
    },
    peak_bytes_per_vertex: (120, Some(70)),
    capabilities: &[Capability::Refine],
    ..CATMULL_CLARK
};
