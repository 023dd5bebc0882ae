//! The schemes of the subdivision lecture notes §4 that OpenSubdiv does not have: Doo-Sabin, √3
//! (Kobbelt), Butterfly (Dyn, Levin, Gregory) and Modified Butterfly (Zorin, Schröder, Sweldens).
//!
//! Each is a topology split plus masks (one rule file: [`doo_sabin`], [`sqrt3`],
//! [`butterfly`]), refined one level at a time behind [`crate::Refinement`]: the topology of
//! every level and a [`StencilTable`] per level, which compose into one table from the base
//! mesh to any level, as for OpenSubdiv's schemes.
//!
//! A rule file gives, for one step over a parent level, the child faces (with the tags the
//! child keeps) and the mask of every child vertex as weights of parent vertices; a new
//! scheme is such a file plus its [`Scheme`] variant.
//!
//! | scheme | input faces | split | interpolating | boundary | creases |
//! |---|---|---|---|---|---|
//! | Doo-Sabin | any polygons | dual (F, E and V faces) | no | Chaikin along the boundary polygon | no |
//! | √3 | triangles | 1 → 3 with edge flips | no | Kobbelt's: trisected every second step | infinitely sharp |
//! | Butterfly | triangles | 1 → 4 | yes | 4-point rule | infinitely sharp |
//! | Modified Butterfly | triangles | 1 → 4 | yes | 4-point rule (see [`butterfly`]) | infinitely sharp |
//!
//! Face-varying data (UVs) goes through the butterflies with any seams and through
//! Doo-Sabin and √3 where it has none: [`SplitFaceVarying`].
//!
//! Every level is a new [`Topology`]; rows of the stencil tables are built in parallel and do
//! not depend on the number of threads. A level's topology is derived from the level above
//! in closed form, in parallel, where the rule has a derivation
//! (`SplitRule::derived_topology`: the butterflies always, √3 and Doo-Sabin over closed
//! levels without feature edges) and built from its faces by [`TopologyBuilder`] otherwise;
//! both give the same topology, relation for relation (the derived one is put in the
//! builder's order by [`subd_mesh::canonical::builder_order`]).
//!
//! ```
//! use subd_mesh::{DVec3, TopologyBuilder};
//! use subd_schemes::{Options, Refinement, Scheme};
//!
//! // A tetrahedron, three √3 steps: 4 → 12 → 36 → 108 faces.
//! let faces = [0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2];
//! let topo = TopologyBuilder::new(4).build(&[3; 4], &faces).unwrap();
//! let r = Refinement::new(&topo, Scheme::Sqrt3, &Options::default(), 3).unwrap();
//! assert_eq!(r.topology(3).num_faces(), 108);
//! let points = [DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE];
//! let level3 = r.refine_points(&points).pop().unwrap();
//! assert_eq!(level3.len(), r.topology(3).num_vertices());
//! ```

pub mod butterfly;
pub mod doo_sabin;
mod doo_sabin_split;
mod features;
pub mod fvar;
pub mod sqrt3;
mod sqrt3_split;

use std::sync::OnceLock;

use glam::DVec3;
use rayon::prelude::*;
use subd_mesh::{Topology, TopologyBuilder, TopologyError, TopologyParts, tags};

use crate::rules::Rule;
use crate::{MAX_LEVELS, RefineError, RowSink, Scheme, StencilTable};

pub use features::Features;
pub use fvar::{SplitFVarError, SplitFaceVarying};

/// The faces and tags of a refined level, before its topology is built.
#[derive(Debug, Clone)]
pub(crate) struct ChildFaces {
    pub(crate) num_vertices: usize,
    /// Face offsets (one more than faces) and vertices.
    pub(crate) offsets: Vec<u32>,
    pub(crate) vertices: Vec<u32>,
    /// Infinitely sharp interior creases, as end vertices.
    pub(crate) creases: Vec<[u32; 2]>,
    /// Corner tags.
    pub(crate) corners: Vec<(u32, f32)>,
}

impl ChildFaces {
    /// Faces from offsets and vertices, no tags yet.
    fn untagged(num_vertices: usize, offsets: Vec<u32>, vertices: Vec<u32>) -> ChildFaces {
        ChildFaces {
            num_vertices,
            offsets,
            vertices,
            creases: Vec::new(),
            corners: Vec::new(),
        }
    }

    /// Faces from per-face sizes.
    pub(crate) fn from_sizes(num_vertices: usize, sizes: &[u32], vertices: Vec<u32>) -> ChildFaces {
        let offsets = std::iter::once(0)
            .chain(sizes.iter().scan(0u32, |end, &n| {
                *end += n;
                Some(*end)
            }))
            .collect();
        ChildFaces::untagged(num_vertices, offsets, vertices)
    }

    /// All faces triangles.
    pub(crate) fn triangles(num_vertices: usize, vertices: Vec<u32>) -> ChildFaces {
        let offsets = (0..=vertices.len() as u32 / 3).map(|f| 3 * f).collect();
        ChildFaces::untagged(num_vertices, offsets, vertices)
    }

    /// The topology of these faces by [`TopologyBuilder`]: the reference the derived
    /// topologies ([`SplitRule::derived_topology`]) are put in the order of.
    pub(crate) fn build(&self) -> Result<Topology, TopologyError> {
        let sizes: Vec<u32> = self.offsets.windows(2).map(|w| w[1] - w[0]).collect();
        let t = TopologyBuilder::new(self.num_vertices).build(&sizes, &self.vertices)?;
        Ok(self.tagged(t))
    }

    /// The topology of these faces from relations a rule derived from the parent (`parts`,
    /// whose faces are these), put in the builder's order: what [`Self::build`] gives,
    /// without its search. Without `parts`, [`Self::build`].
    fn build_from(&self, parts: Option<TopologyParts>) -> Result<Topology, TopologyError> {
        let Some(parts) = parts else {
            return self.build();
        };
        debug_assert!(parts.face_offsets == self.offsets && parts.face_vertices == self.vertices);
        let t = Topology::from_parts(subd_mesh::canonical::builder_order(parts))?;
        Ok(self.tagged(t))
    }

    /// `t` with the creases and corners of these faces.
    fn tagged(&self, mut t: Topology) -> Topology {
        for &[a, b] in &self.creases {
            if let Some(e) = t.find_edge(a, b) {
                t.set_edge_sharpness(e as usize, tags::SHARPNESS_INFINITE);
            }
        }
        for &(v, s) in &self.corners {
            t.set_vertex_sharpness(v as usize, s);
        }
        t
    }
}

/// Where a row's weights go: a stencil row, or a point being summed.
pub(crate) trait Weights {
    /// Adds `w` times parent vertex `i`.
    fn add(&mut self, i: u32, w: f64);
}

impl Weights for RowSink<'_> {
    #[inline]
    fn add(&mut self, i: u32, w: f64) {
        RowSink::add(self, i, w);
    }
}

/// A child point summed from parent points.
struct PointSum<'a> {
    src: &'a [DVec3],
    acc: DVec3,
}

impl Weights for PointSum<'_> {
    #[inline]
    fn add(&mut self, i: u32, w: f64) {
        self.acc += self.src[i as usize] * w;
    }
}

/// What a split scheme's rule file implements: one step over a parent level, with the
/// child faces (and the tags the child keeps) and each child vertex's mask as weights of
/// parent vertices. [`Scheme::split_step`] makes the step of a scheme at a level; the rest
/// (levels, stencil tables, points, face-varying data, limits) is the same for every
/// scheme.
pub(crate) trait SplitRule: Sync {
    /// Child vertices (rows).
    fn num_rows(&self) -> usize;
    /// The weights of child vertex `r`, given to `w` in a fixed order.
    fn fill<W: Weights>(&self, r: usize, w: &mut W);
    /// The child level's faces and tags.
    fn child_faces(&self) -> Result<ChildFaces, StepError>;
    /// The child level's relations derived from the parent's (the faces of
    /// [`Self::child_faces`], edges and rings in any order
    /// [`subd_mesh::canonical::builder_order`] takes), or `None` where the rule has no such
    /// derivation and the child is built from its faces.
    fn derived_topology(&self) -> Option<TopologyParts> {
        None
    }
}

/// A [`SplitRule`] behind a pointer: rows written to a stencil table or summed into points,
/// one call per row.
pub(crate) trait SplitStep: Sync {
    /// Child vertices.
    fn num_rows(&self) -> usize;
    /// Row `r` into a stencil table.
    fn row(&self, r: usize, sink: &mut RowSink);
    /// Child point `r` from the parent points.
    fn point(&self, r: usize, src: &[DVec3]) -> DVec3;
    /// The child level's faces and tags.
    fn child_faces(&self) -> Result<ChildFaces, StepError>;
    /// The child level's topology, the faces being `faces` (from [`Self::child_faces`]).
    fn child_topology(&self, faces: &ChildFaces) -> Result<Topology, TopologyError>;
}

impl<T: SplitRule> SplitStep for T {
    fn num_rows(&self) -> usize {
        SplitRule::num_rows(self)
    }

    #[inline]
    fn row(&self, r: usize, sink: &mut RowSink) {
        self.fill(r, sink);
    }

    #[inline]
    fn point(&self, r: usize, src: &[DVec3]) -> DVec3 {
        let mut sum = PointSum {
            src,
            acc: DVec3::ZERO,
        };
        self.fill(r, &mut sum);
        sum.acc
    }

    fn child_faces(&self) -> Result<ChildFaces, StepError> {
        SplitRule::child_faces(self)
    }

    fn child_topology(&self, faces: &ChildFaces) -> Result<Topology, TopologyError> {
        faces.build_from(self.derived_topology())
    }
}

/// One step of `scheme` over `parent`, the parent being level `level - 1`.
fn step<'a>(parent: &'a Topology, scheme: &Scheme, level: usize) -> Box<dyn SplitStep + 'a> {
    scheme
        .split_step(parent, level)
        .expect("the split family refines split schemes only")
}

/// The stencils of a step: one row per child vertex over the parent's `num_sources`.
fn step_stencils(step: &dyn SplitStep, num_sources: usize) -> StencilTable {
    StencilTable::build(step.num_rows(), num_sources, |r, sink| step.row(r, sink))
}

/// The child points of a step, in parallel.
fn step_points(step: &dyn SplitStep, src: &[DVec3]) -> Vec<DVec3> {
    let mut out = Vec::new();
    (0..step.num_rows())
        .into_par_iter()
        .with_min_len(1024)
        .map(|r| step.point(r, src))
        .collect_into_vec(&mut out);
    out
}

/// One refined level: its faces and tags, its topology (built eagerly below the last level,
/// which the next step needs, and on first request for the last), and the stencils from the
/// level above (built on first request).
#[derive(Debug)]
struct SplitLevel {
    faces: ChildFaces,
    topology: OnceLock<Topology>,
    stencils: OnceLock<StencilTable>,
    rules: OnceLock<Vec<Rule>>,
}

/// A uniform refinement with a split scheme: the topology of every level and the stencils
/// between levels (the family behind [`crate::Refinement`] for Doo-Sabin, √3 and the
/// butterflies).
///
/// Like [`crate::Refinement`], it computes what a refinement always needs up front (the
/// faces of every level, the topology of every level but the last) and the rest on request:
/// the last level's full topology, and the stencil tables. [`Self::refine_points`] evaluates
/// the masks directly, level by level, in parallel, with the same rows the tables hold.
#[derive(Debug)]
pub(crate) struct SplitRefinement {
    scheme: Scheme,
    base: Topology,
    base_rules: OnceLock<Vec<Rule>>,
    levels: Vec<SplitLevel>,
}

impl SplitRefinement {
    /// Refines `base` uniformly `levels` times with `scheme`.
    ///
    /// # Errors
    /// [`RefineError`] for a face the scheme cannot take (triangles for all but Doo-Sabin),
    /// non-manifold input, tags the scheme has no rule for (semi-sharp creases, holes; any
    /// crease for Doo-Sabin), a tension that is not finite, or too many levels.
    pub fn new(
        base: &Topology,
        scheme: &Scheme,
        levels: usize,
    ) -> Result<SplitRefinement, RefineError> {
        check_input(base, scheme, levels)?;
        let mut out: Vec<SplitLevel> = Vec::with_capacity(levels);
        for l in 1..=levels {
            let parent = match out.last() {
                None => base,
                Some(s) => s.topology.get().expect("levels above the last are built"),
            };
            // Refuse a level whose arrays cannot be allocated before filling any of them.
            let child = crate::LevelCounts::of(parent).refined(scheme);
            let need = if l < levels {
                crate::refine::topology_bytes(child)
            } else {
                crate::refine::last_level_bytes(child)
            };
            if !subd_mesh::memory::can_allocate(need) {
                return Err(RefineError::OutOfMemory {
                    level: l,
                    bytes: need,
                });
            }
            let step = step(parent, scheme, l);
            let faces = step.child_faces().map_err(|e| e.at_level(l))?;
            let topology = OnceLock::new();
            if l < levels {
                let t = step
                    .child_topology(&faces)
                    .map_err(|e| StepError::Topology(e).at_level(l))?;
                let _ = topology.set(t);
            }
            drop(step);
            out.push(SplitLevel {
                faces,
                topology,
                stencils: OnceLock::new(),
                rules: OnceLock::new(),
            });
        }
        Ok(SplitRefinement {
            scheme: scheme.clone(),
            base: base.clone(),
            base_rules: OnceLock::new(),
            levels: out,
        })
    }

    /// The scheme.
    pub fn scheme(&self) -> &Scheme {
        &self.scheme
    }

    /// Number of refined levels.
    pub fn num_levels(&self) -> usize {
        self.levels.len()
    }

    /// Number of vertices of `level`.
    pub fn num_vertices(&self, level: usize) -> usize {
        match level {
            0 => self.base.num_vertices(),
            l => self.levels[l - 1].faces.num_vertices,
        }
    }

    /// Face offsets and face vertices of `level`, without building its topology.
    pub fn faces(&self, level: usize) -> (&[u32], &[u32]) {
        match level {
            0 => (self.base.face_offsets(), self.base.all_face_vertices()),
            l => {
                let f = &self.levels[l - 1].faces;
                (&f.offsets, &f.vertices)
            }
        }
    }

    /// The interior infinitely sharp creases (end vertices) and corner tags of `level`: the
    /// tags a mesh file records beyond what its faces imply.
    pub fn explicit_tags(&self, level: usize) -> crate::ExplicitTags {
        let (creases, corners): (Vec<[u32; 2]>, Vec<(u32, f32)>) = match level {
            0 => {
                let t = &self.base;
                (
                    (0..t.num_edges())
                        .filter(|&e| t.edge_sharpness(e) > 0.0 && !t.is_boundary_edge(e))
                        .map(|e| t.edge_vertices(e))
                        .collect(),
                    (0..t.num_vertices() as u32)
                        .filter(|&v| t.vertex_sharpness(v as usize) > 0.0)
                        .map(|v| (v, t.vertex_sharpness(v as usize)))
                        .collect(),
                )
            }
            l => {
                let f = &self.levels[l - 1].faces;
                (f.creases.clone(), f.corners.clone())
            }
        };
        crate::ExplicitTags {
            creases: creases
                .into_iter()
                .map(|c| (c, tags::SHARPNESS_INFINITE))
                .collect(),
            corners,
        }
    }

    /// Topology of `level` (0 is the base mesh); the last level's is built on first request.
    pub fn topology(&self, level: usize) -> &Topology {
        match level {
            0 => &self.base,
            l => {
                let lv = &self.levels[l - 1];
                lv.topology.get_or_init(|| {
                    // The faces were derived from a valid manifold parent; building them is
                    // what the levels above the last already did without fail.
                    step(self.topology(l - 1), &self.scheme, l)
                        .child_topology(&lv.faces)
                        .expect("a refined level is a valid mesh")
                })
            }
        }
    }

    /// Stencils giving the vertices of `level` from those of `level - 1` (`level ≥ 1`), built
    /// on first request.
    pub fn stencils(&self, level: usize) -> &StencilTable {
        self.levels[level - 1].stencils.get_or_init(|| {
            let parent = self.topology(level - 1);
            step_stencils(&*step(parent, &self.scheme, level), parent.num_vertices())
        })
    }

    /// Points of `level` from those of the level above, the masks evaluated directly, in
    /// parallel, with the same rows the tables hold.
    pub fn next_points(&self, level: usize, above: &[DVec3]) -> Vec<DVec3> {
        step_points(&*step(self.topology(level - 1), &self.scheme, level), above)
    }

    /// The rule of every vertex of `level`, as OpenSubdiv would name it from the level's
    /// feature edges (boundary and infinitely sharp) and corner tags.
    pub fn vertex_rules(&self, level: usize) -> &[Rule] {
        let cell = match level {
            0 => &self.base_rules,
            l => &self.levels[l - 1].rules,
        };
        cell.get_or_init(|| {
            let t = self.topology(level);
            (0..t.num_vertices())
                .map(|v| {
                    let sharp = t
                        .vertex_edges(v)
                        .iter()
                        .filter(|&&e| {
                            let e = e as usize;
                            t.is_boundary_edge(e) || t.edge_sharpness(e) > 0.0
                        })
                        .count();
                    Rule::determine(t.vertex_sharpness(v), sharp)
                })
                .collect()
        })
    }

    /// Takes the topology of `level` out of the refinement.
    pub fn into_topology(mut self, level: usize) -> Topology {
        self.topology(level);
        match level {
            0 => self.base,
            l => self
                .levels
                .swap_remove(l - 1)
                .topology
                .into_inner()
                .expect("built just above"),
        }
    }
}

impl crate::family::Family for SplitRefinement {
    fn num_levels(&self) -> usize {
        SplitRefinement::num_levels(self)
    }
    fn num_vertices(&self, level: usize) -> usize {
        SplitRefinement::num_vertices(self, level)
    }
    fn num_edges(&self, level: usize) -> Option<usize> {
        // The last level's edges are never built unless its topology is asked for.
        (level == 0 || level < self.levels.len() || self.levels[level - 1].topology.get().is_some())
            .then(|| self.topology(level).num_edges())
    }
    fn faces(&self, level: usize) -> (&[u32], &[u32]) {
        SplitRefinement::faces(self, level)
    }
    fn holes(&self, level: usize) -> std::borrow::Cow<'_, [bool]> {
        // The split schemes refuse holes.
        std::borrow::Cow::Owned(vec![false; self.faces(level).0.len() - 1])
    }
    fn has_sharpness(&self, level: usize) -> bool {
        let tags = SplitRefinement::explicit_tags(self, level);
        !tags.creases.is_empty() || !tags.corners.is_empty()
    }
    fn explicit_tags(&self, level: usize) -> crate::ExplicitTags {
        SplitRefinement::explicit_tags(self, level)
    }
    fn topology(&self, level: usize) -> &Topology {
        SplitRefinement::topology(self, level)
    }
    fn has_topology(&self, level: usize) -> bool {
        level == 0 || self.levels[level - 1].topology.get().is_some()
    }
    fn into_topology(self: Box<Self>, level: usize) -> Topology {
        SplitRefinement::into_topology(*self, level)
    }
    fn vertex_rules(&self, level: usize) -> &[Rule] {
        SplitRefinement::vertex_rules(self, level)
    }
    fn stencils(&self, level: usize) -> &StencilTable {
        SplitRefinement::stencils(self, level)
    }
    fn next_points(&self, level: usize, above: &[DVec3]) -> Vec<DVec3> {
        SplitRefinement::next_points(self, level, above)
    }
    fn face_stream(&self) -> Option<crate::FaceStream<'_>> {
        None
    }
    fn point_stream<'a>(&'a self, _above: &'a [DVec3]) -> Option<crate::PointStream<'a>> {
        None
    }
}

/// What a single step can fail with; [`SplitRefinement::new`] adds the level.
#[derive(Debug)]
pub(crate) enum StepError {
    TooLarge,
    Topology(TopologyError),
}

impl StepError {
    fn at_level(self, level: usize) -> RefineError {
        match self {
            StepError::TooLarge => RefineError::TooLarge { level },
            StepError::Topology(source) => RefineError::Topology { level, source },
        }
    }
}

impl From<TopologyError> for StepError {
    fn from(e: TopologyError) -> Self {
        StepError::Topology(e)
    }
}

/// The checks every split scheme makes on its input before the first step: the level count,
/// the butterfly's tension, and then what [`Scheme::input_faces`] and [`Scheme::tags`] say
/// the scheme takes.
fn check_input(base: &Topology, scheme: &Scheme, levels: usize) -> Result<(), RefineError> {
    if levels > MAX_LEVELS {
        return Err(RefineError::TooManyLevels {
            levels,
            max: MAX_LEVELS,
        });
    }
    scheme.check_parameters()?;
    check_faces(base, scheme)?;
    check_manifold(base, scheme)?;
    check_tags(base, scheme)
}

/// Faces of the kind the scheme takes.
fn check_faces(base: &Topology, scheme: &Scheme) -> Result<(), RefineError> {
    if scheme.input_faces() == crate::FaceKind::Triangles
        && let Some(f) = (0..base.num_faces()).find(|&f| base.face_size(f) != 3)
    {
        return Err(RefineError::NotTriangle {
            scheme: scheme.name(),
            face: f,
            size: base.face_size(f),
        });
    }
    Ok(())
}

/// No non-manifold edge or vertex unless the scheme has rules for them.
fn check_manifold(base: &Topology, scheme: &Scheme) -> Result<(), RefineError> {
    if scheme.tags().non_manifold {
        return Ok(());
    }
    if let Some(e) = (0..base.num_edges()).find(|&e| base.is_non_manifold_edge(e)) {
        let [a, b] = base.edge_vertices(e);
        return Err(RefineError::NonManifoldEdge {
            scheme: scheme.name(),
            edge: e,
            a,
            b,
        });
    }
    if let Some(v) = (0..base.num_vertices()).find(|&v| base.is_non_manifold_vertex(v)) {
        return Err(RefineError::NonManifoldVertex {
            scheme: scheme.name(),
            vertex: v,
        });
    }
    Ok(())
}

/// Holes, interior creases and corners only where the scheme has a rule for them.
fn check_tags(base: &Topology, scheme: &Scheme) -> Result<(), RefineError> {
    let (name, rules) = (scheme.name(), scheme.tags());
    let refuse = |what: String, why| {
        Err(RefineError::UnsupportedTag {
            scheme: name,
            what,
            why,
        })
    };
    if !rules.holes
        && let Some(f) = (0..base.num_faces()).find(|&f| base.is_hole(f))
    {
        return refuse(format!("face {f}"), "has no rule for holes");
    }
    for e in 0..base.num_edges() {
        let s = base.edge_sharpness(e);
        if s <= 0.0 || base.is_boundary_edge(e) {
            continue;
        }
        let [a, b] = base.edge_vertices(e);
        let what = format!("edge {e} ({a}-{b}) crease {s}");
        if !rules.infinite_creases {
            return refuse(what, "has no crease rule");
        }
        if !rules.semi_sharp_creases && !tags::is_infinite(s) {
            return refuse(what, "supports only infinitely sharp creases");
        }
    }
    if !rules.corners
        && let Some(v) = (0..base.num_vertices()).find(|&v| base.vertex_sharpness(v) > 0.0)
    {
        return refuse(
            format!("vertex {v} corner {}", base.vertex_sharpness(v)),
            "has no corner rule",
        );
    }
    Ok(())
}

/// Guards the 32-bit indices of a child level with `face_vertices` face-vertices.
fn check_size(face_vertices: u64) -> Result<(), StepError> {
    if face_vertices >= u32::MAX as u64 {
        Err(StepError::TooLarge)
    } else {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed torus of quads, and its quads split along a diagonal.
    fn closed_meshes() -> (Topology, Topology) {
        let quads = subd_mesh::primitives::torus(7, 5, 3.0, 1.0).topology;
        let tris: Vec<u32> = quads
            .all_face_vertices()
            .chunks(4)
            .flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]])
            .collect();
        let sizes = vec![3; tris.len() / 3];
        let tris = TopologyBuilder::new(quads.num_vertices())
            .build(&sizes, &tris)
            .unwrap();
        (quads, tris)
    }

    /// Checks that `rule` derives the child of `parent` and that the derived topology is the
    /// builder's; returns the child.
    fn derived_is_built(rule: &impl SplitRule, what: &str) -> Topology {
        let faces = rule.child_faces().unwrap();
        let parts = rule.derived_topology();
        assert!(parts.is_some(), "{what}: no closed form");
        let derived = faces.build_from(parts).unwrap();
        assert!(
            derived == faces.build().unwrap(),
            "{what}: not the builder's"
        );
        derived
    }

    /// On closed meshes every split scheme takes its closed form, three levels deep (√3's
    /// trisecting steps included), and gets the builder's topology.
    #[test]
    fn closed_forms_apply_on_closed_meshes_and_give_the_builders() {
        let (quads, tris) = closed_meshes();
        let mut t = quads;
        for l in 1..=3 {
            t = derived_is_built(&doo_sabin::Step::new(&t), &format!("doo-sabin {l}"));
        }
        let mut t = tris.clone();
        for l in 1..=3 {
            t = derived_is_built(&sqrt3::Step::new(&t, l % 2 == 0), &format!("sqrt3 {l}"));
        }
        let mut t = tris;
        for l in 1..=3 {
            let rule = butterfly::Step::new(&t, butterfly::EdgeRule::Modified);
            t = derived_is_built(&rule, &format!("butterfly {l}"));
        }
    }
}
