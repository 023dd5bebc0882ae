//! Uniform refinement on the device, level by level (`uniform.wgsl`): the topology of any
//! Catmull-Clark or Loop mesh, every relation of a child level following from its parent's
//! by index arithmetic; the points of manifold meshes whose sharpness is all or nothing
//! (boundaries, infinitely sharp creases and corners, smooth elsewhere) by OpenSubdiv's
//! smooth, crease and corner masks on the device, those of the others (semi-sharp creases,
//! holes, non-manifold parts, the smooth-triangle rule) through the CPU's stencil tables of
//! each level.

use subd_mesh::tags::is_infinite;
use subd_mesh::{BoundaryInterpolation, DVec3, Topology};
use subd_schemes::rules::Rule;
use subd_schemes::{Options, Scheme};

use crate::pipeline::STAGES;
use crate::stencils::f32_rows;
use crate::{Gpu, GpuColumns, GpuError, GpuStencilTable, StencilDispatch};

const WORKGROUP: u32 = 64;

/// Element counts of a level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Counts {
    vertices: u64,
    faces: u64,
    edges: u64,
    corners: u64,
}

impl Counts {
    fn of(t: &Topology) -> Counts {
        Counts {
            vertices: t.num_vertices() as u64,
            faces: t.num_faces() as u64,
            edges: t.num_edges() as u64,
            corners: t.num_face_vertices() as u64,
        }
    }

    /// The child's counts: Catmull-Clark a quad per corner, Loop four triangles per face.
    fn child(self, loop_scheme: bool) -> Counts {
        let c = self;
        if loop_scheme {
            Counts {
                vertices: c.vertices + c.edges,
                faces: 4 * c.faces,
                edges: 3 * c.faces + 2 * c.edges,
                corners: 12 * c.faces,
            }
        } else {
            Counts {
                vertices: c.vertices + c.faces + c.edges,
                faces: c.corners,
                edges: c.corners + 2 * c.edges,
                corners: 4 * c.corners,
            }
        }
    }
}

/// One level on the device.
#[derive(Debug)]
struct DeviceLevel {
    counts: Counts,
    /// Vertices per face where all faces have as many, else 0.
    face_size: u32,
    face_vertices: wgpu::Buffer,
    face_edges: wgpu::Buffer,
    edge_vertices: wgpu::Buffer,
    /// Per edge 1 where it is infinitely sharp (boundaries included).
    edge_sharp: wgpu::Buffer,
    /// Per vertex its rule: 0 smooth or dart, 1 crease, 2 corner.
    vertex_rules: wgpu::Buffer,
    points: GpuColumns,
}

/// A level as a parent: where its edges' corners, a corner of each vertex and each
/// corner's twin are found.
#[derive(Debug)]
struct Walks {
    edge_corners: wgpu::Buffer,
    vertex_corner: wgpu::Buffer,
    twin: wgpu::Buffer,
}

/// One dispatch of a stage.
#[derive(Debug)]
struct Pass {
    stage: usize,
    bind_group: wgpu::BindGroup,
    grid: (u32, u32),
    _parameters: wgpu::Buffer,
}

/// A mesh refined uniformly on the device, every level's topology and points kept there:
/// faces as [`Self::face_vertices`] (u32, the CPU's vertex numbering and face order bit for
/// bit, usable as an index buffer: quads for Catmull-Clark, triangles for Loop) and points
/// as [`Self::points`].
#[derive(Debug)]
pub struct GpuUniformRefinement {
    levels: Vec<DeviceLevel>,
    _walks: Vec<Walks>,
    _base: [wgpu::Buffer; 3],
    passes: Vec<Pass>,
    /// Where the points do not come from the device's masks: each level's stencil table
    /// from the CPU's refinement, applied level to level.
    stencils: Vec<(GpuStencilTable, StencilDispatch)>,
    /// Whether the device's masks compute the points.
    masks: bool,
}

/// Whether the device's masks give `base`'s points: a manifold mesh without holes whose
/// creases and corners are all infinitely sharp (boundaries too, unless boundary
/// interpolation is `None`), without Catmull-Clark's smooth-triangle rule on triangles.
fn points_by_masks(base: &Topology, scheme: &Scheme, rules: &Options) -> bool {
    let smooth_triangles = rules.triangle_subdivision == subd_mesh::TriangleSubdivision::Smooth;
    let triangle_rule = *scheme == Scheme::CatmullClark
        && smooth_triangles
        && (0..base.num_faces()).any(|f| base.face_size(f) == 3);
    let all_or_nothing = |s: f32| s == 0.0 || is_infinite(s);
    let edges_ok = (0..base.num_edges()).all(|e| {
        let faces = base.edge_faces(e).len();
        !base.is_degenerate_edge(e)
            && (faces == 2
                || (faces == 1 && rules.boundary_interpolation != BoundaryInterpolation::None))
            && all_or_nothing(base.edge_sharpness(e))
    });
    let vertices_ok = (0..base.num_vertices()).all(|v| {
        !base.is_non_manifold_vertex(v)
            && !base.is_isolated_vertex(v)
            && all_or_nothing(base.vertex_sharpness(v))
    });
    let holes = (0..base.num_faces()).any(|f| base.is_hole(f));
    !triangle_rule && !holes && edges_ok && vertices_ok
}

/// The base level's sharp edges and vertex rules as OpenSubdiv tags them: boundary edges
/// infinitely sharp, one-face corners too under edge-and-corner interpolation, then each
/// vertex's rule by its sharpness and sharp edges.
fn base_tags(base: &Topology, rules: &Options) -> (Vec<u32>, Vec<u32>) {
    let sharp: Vec<u32> = (0..base.num_edges())
        .map(|e| u32::from(base.is_boundary_edge(e) || is_infinite(base.edge_sharpness(e))))
        .collect();
    let corner_rule = rules.boundary_interpolation == BoundaryInterpolation::EdgeAndCorner;
    let vertex_rules = (0..base.num_vertices())
        .map(|v| {
            let one_face_corner =
                corner_rule && base.vertex_faces(v).len() == 1 && base.valence(v) == 2;
            let s = if one_face_corner {
                f32::INFINITY
            } else {
                base.vertex_sharpness(v)
            };
            let sharp_edges = base
                .vertex_edges(v)
                .iter()
                .filter(|&&e| sharp[e as usize] != 0)
                .count();
            match Rule::determine(s, sharp_edges) {
                Rule::Smooth | Rule::Dart => 0,
                Rule::Crease => 1,
                Rule::Corner => 2,
            }
        })
        .collect();
    (sharp, vertex_rules)
}

/// Why `base` cannot be refined on the device with `scheme`, if it cannot.
fn check_input(base: &Topology, scheme: &Scheme, positions: &[DVec3]) -> Result<(), GpuError> {
    if !matches!(scheme, Scheme::CatmullClark | Scheme::Loop) {
        return Err(GpuError::Unsupported(format!(
            "uniform refinement with {scheme} (Catmull-Clark and Loop only)"
        )));
    }
    if positions.len() != base.num_vertices() {
        return Err(GpuError::Mismatch(format!(
            "{} positions for {} vertices",
            positions.len(),
            base.num_vertices()
        )));
    }
    if *scheme == Scheme::Loop && base.num_face_vertices() != 3 * base.num_faces() {
        return Err(GpuError::Mismatch("Loop refines triangles only".into()));
    }
    Ok(())
}

impl GpuUniformRefinement {
    /// Uploads `base` and `positions` and refines `levels` levels of `scheme` with `rules`
    /// on the device (submitted now; read the results when needed). The topology is
    /// refined on the device for every mesh; the points by the device's masks where the
    /// mesh is manifold, has no holes, and its creases and corners (boundaries included,
    /// with edge-only or edge-and-corner interpolation) are all infinitely sharp, without
    /// Catmull-Clark's smooth-triangle rule on triangles; else by each level's stencil
    /// table, which the CPU computes here once ([`Self::points_by_masks`] says which).
    ///
    /// # Errors
    /// [`GpuError::Unsupported`] for a scheme other than Catmull-Clark and Loop;
    /// [`GpuError::Refine`] where the CPU's refinement refuses the mesh;
    /// [`GpuError::Mismatch`] for positions that are not one per vertex, or Loop on
    /// faces that are not triangles; [`GpuError::TooLarge`] where a level passes the
    /// device's buffers or 32-bit indices; the device's memory errors.
    pub fn new(
        gpu: &Gpu,
        base: &Topology,
        scheme: &Scheme,
        rules: &Options,
        positions: &[DVec3],
        levels: usize,
    ) -> Result<GpuUniformRefinement, GpuError> {
        check_input(base, scheme, positions)?;
        let masks = points_by_masks(base, scheme, rules);
        let loop_scheme = *scheme == Scheme::Loop;
        let mut counts = vec![Counts::of(base)];
        for l in 0..levels {
            let child = counts[l].child(loop_scheme);
            if 2 * child.edges.max(child.corners) >= u64::from(u32::MAX) {
                return Err(GpuError::TooLarge {
                    what: "a refined level (32-bit indices)",
                    bytes: 8 * child.edges.max(child.corners),
                    limit: u64::from(u32::MAX) * 4,
                });
            }
            counts.push(child);
        }
        let (level0, base_buffers) = upload_base(gpu, base, rules, positions, loop_scheme)?;
        let mut out = GpuUniformRefinement {
            levels: vec![level0],
            _walks: Vec::new(),
            _base: base_buffers,
            passes: Vec::new(),
            stencils: Vec::new(),
            masks,
        };
        for &child in &counts[1..] {
            let face_size = if loop_scheme { 3 } else { 4 };
            out.add_level(gpu, child, face_size, loop_scheme, masks)?;
        }
        if !masks {
            out.stencils = level_stencils(gpu, base, scheme, rules, levels, &out.levels)?;
        }
        out.recompute(gpu);
        Ok(out)
    }

    /// Whether the device's masks compute the points, not the CPU's stencil tables.
    pub fn points_by_masks(&self) -> bool {
        self.masks
    }

    /// Refines every level again from the base (the timing of a refinement: topology and
    /// points), submitted now.
    pub fn recompute(&self, gpu: &Gpu) {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        self.record(gpu, &mut encoder);
        gpu.queue.submit([encoder.finish()]);
    }

    /// Records the refinement of every level into `encoder`.
    pub fn record(&self, gpu: &Gpu, encoder: &mut wgpu::CommandEncoder) {
        // Each run finds the corners of every edge again: no slot may hold an old one.
        for walks in &self._walks {
            encoder.clear_buffer(&walks.edge_corners, 0, None);
            encoder.clear_buffer(&walks.vertex_corner, 0, None);
        }
        for pass in &self.passes {
            if pass.grid.0 == 0 {
                continue;
            }
            let mut compute = encoder.begin_compute_pass(&Default::default());
            compute.set_pipeline(&gpu.uniform_pipelines.stages[pass.stage]);
            compute.set_bind_group(0, &pass.bind_group, &[]);
            compute.dispatch_workgroups(pass.grid.0, pass.grid.1, 1);
        }
        for (_, dispatch) in &self.stencils {
            dispatch.record(gpu, encoder);
        }
    }

    /// Writes new base positions and refines again (the topology is recomputed too: it is
    /// the same).
    ///
    /// # Errors
    /// [`GpuError::Mismatch`] where `positions` is not one per base vertex.
    pub fn update_points(&self, gpu: &Gpu, positions: &[DVec3]) -> Result<(), GpuError> {
        gpu.write_columns(&self.levels[0].points, &f32_rows(positions))?;
        self.recompute(gpu);
        Ok(())
    }

    /// Number of levels refined.
    pub fn num_levels(&self) -> usize {
        self.levels.len() - 1
    }

    /// The face vertices of `level` (u32, the level's faces one after another; every face
    /// of a refined level has [`Self::face_size`] vertices).
    pub fn face_vertices(&self, level: usize) -> Option<&wgpu::Buffer> {
        self.levels.get(level).map(|l| &l.face_vertices)
    }

    /// Vertices per face of `level` (0 for a base level of mixed faces).
    pub fn face_size(&self, level: usize) -> usize {
        self.levels.get(level).map_or(0, |l| l.face_size as usize)
    }

    /// Number of faces of `level`.
    pub fn num_faces(&self, level: usize) -> usize {
        self.levels
            .get(level)
            .map_or(0, |l| l.counts.faces as usize)
    }

    /// The points of `level` (rows of three f32).
    pub fn points(&self, level: usize) -> Option<&GpuColumns> {
        self.levels.get(level).map(|l| &l.points)
    }

    /// The faces of refined `level` as a triangle list (u32, three per triangle) a renderer
    /// draws directly: Loop's triangles as they are, Catmull-Clark's quads `(a, b, c, d)` as
    /// `(a, b, c)`, `(a, c, d)`, computed on the device now (the topology does not change
    /// with the points, so one list serves every frame).
    ///
    /// # Errors
    /// [`GpuError::Mismatch`] for a level not refined, or the base level of mixed faces;
    /// the device's size and memory errors.
    pub fn triangle_indices(&self, gpu: &Gpu, level: usize) -> Result<wgpu::Buffer, GpuError> {
        let l = self
            .levels
            .get(level)
            .filter(|l| l.face_size == 3 || l.face_size == 4)
            .ok_or_else(|| {
                GpuError::Mismatch(format!(
                    "level {level} is not a level of triangles or quads"
                ))
            })?;
        let faces = l.counts.faces;
        let triangles = if l.face_size == 4 { 2 * faces } else { faces };
        let usage =
            wgpu::BufferUsages::INDEX | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let out = gpu.storage_of_size("triangle indices", 12 * triangles, usage)?;
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        if l.face_size == 3 {
            encoder.copy_buffer_to_buffer(&l.face_vertices, 0, &out, 0, 12 * triangles);
        } else {
            let (grid, per_line) = gpu.dispatch_grid(faces as usize, WORKGROUP);
            let params = [0, 0, 0, 0, 4, 0, faces as u32, per_line];
            let uniform = gpu.uniform("triangle parameters", &params);
            let pipeline = &gpu.uniform_pipelines.stages[8];
            let buffers = [(0, &uniform), (3, &l.face_vertices), (22, &out)];
            let bind_group = gpu.bind_group("quad triangles", pipeline, &buffers);
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.dispatch_workgroups(grid.0, grid.1, 1);
        }
        gpu.queue.submit([encoder.finish()]);
        Ok(out)
    }

    /// Reads the face vertices of `level` back.
    ///
    /// # Errors
    /// [`GpuError::Mismatch`] for a level not refined; [`GpuError::Failed`] when the device
    /// fails.
    pub fn read_face_vertices(&self, gpu: &Gpu, level: usize) -> Result<Vec<u32>, GpuError> {
        let l = self
            .levels
            .get(level)
            .ok_or_else(|| GpuError::Mismatch(format!("no level {level}")))?;
        gpu.read_back(&l.face_vertices, l.counts.corners * 4)
    }
}

/// The base level on the device, and its buffers every level's passes bind: face offsets,
/// per-corner face and next corner, Loop's vertex weights per valence.
fn upload_base(
    gpu: &Gpu,
    base: &Topology,
    rules: &Options,
    positions: &[DVec3],
    loop_scheme: bool,
) -> Result<(DeviceLevel, [wgpu::Buffer; 3]), GpuError> {
    let nf = base.num_faces();
    let mut corner_face = Vec::with_capacity(3 * base.num_face_vertices());
    let mut next = Vec::with_capacity(base.num_face_vertices());
    let mut prev = Vec::with_capacity(base.num_face_vertices());
    let mut face_edges = Vec::with_capacity(base.num_face_vertices());
    let offsets = base.face_offsets();
    for (f, range) in offsets.windows(2).enumerate() {
        let (start, n) = (range[0], range[1] - range[0]);
        for k in 0..n {
            corner_face.push(f as u32);
            next.push(start + (k + 1) % n);
            prev.push(start + (k + n - 1) % n);
        }
        face_edges.extend_from_slice(base.face_edges(f));
    }
    corner_face.extend(next);
    corner_face.extend(prev);
    let (edge_sharp, vertex_rules) = base_tags(base, rules);
    let edge_vertices: Vec<u32> = (0..base.num_edges())
        .flat_map(|e| base.edge_vertices(e))
        .collect();
    let sizes = (0..nf).map(|f| base.face_size(f) as u32);
    let first = sizes.clone().next().unwrap_or(0);
    let face_size = if sizes.clone().all(|s| s == first) {
        first
    } else {
        0
    };
    let max_valence = (0..base.num_vertices())
        .map(|v| base.valence(v))
        .max()
        .unwrap_or(0)
        .max(6);
    let weights: Vec<f64> = (0..=max_valence)
        .flat_map(|n| {
            let (e, own) = if n == 0 {
                (0.0, 1.0)
            } else {
                subd_schemes::rules::loop_smooth_weights(n)
            };
            [e, own]
        })
        .collect();
    // Catmull-Clark binds the table too (it reads none of it).
    let weights = gpu.storage_real("loop weights", if loop_scheme { &weights } else { &[0.0] })?;
    let none = wgpu::BufferUsages::empty();
    let level = DeviceLevel {
        counts: Counts::of(base),
        face_size,
        face_vertices: gpu.storage("face vertices", base.all_face_vertices(), index_usage())?,
        face_edges: gpu.storage("face edges", &face_edges, none)?,
        edge_vertices: gpu.storage("edge vertices", &edge_vertices, none)?,
        edge_sharp: gpu.storage("sharp edges", &edge_sharp, none)?,
        vertex_rules: gpu.storage("vertex rules", &vertex_rules, none)?,
        points: gpu.upload_points(positions)?,
    };
    let shared = [
        gpu.storage("face offsets", offsets, none)?,
        gpu.storage("corner faces", &corner_face, none)?,
        weights,
    ];
    Ok((level, shared))
}

/// Each level's stencil table from the CPU's refinement, bound to the levels' point
/// buffers: the points of a mesh the device's masks do not cover.
fn level_stencils(
    gpu: &Gpu,
    base: &Topology,
    scheme: &Scheme,
    rules: &Options,
    levels: usize,
    on_device: &[DeviceLevel],
) -> Result<Vec<(GpuStencilTable, StencilDispatch)>, GpuError> {
    let refinement = subd_schemes::Refinement::new(base, scheme.clone(), rules, levels)?;
    (1..=levels)
        .map(|l| {
            let table = GpuStencilTable::new(gpu, refinement.stencils(l))?;
            let dispatch = table.bind(gpu, &on_device[l - 1].points, &on_device[l].points)?;
            Ok((table, dispatch))
        })
        .collect()
}

/// Face vertices are an index buffer a renderer draws from, and read back on request.
fn index_usage() -> wgpu::BufferUsages {
    wgpu::BufferUsages::INDEX | wgpu::BufferUsages::COPY_SRC
}

impl GpuUniformRefinement {
    /// Allocates the child of the last level (`child` counts, `face_size` vertices per
    /// face) and adds the passes that compute it.
    fn add_level(
        &mut self,
        gpu: &Gpu,
        child: Counts,
        face_size: u32,
        loop_scheme: bool,
        masks: bool,
    ) -> Result<(), GpuError> {
        let none = wgpu::BufferUsages::empty();
        let parent = self.levels.last().expect("the base is there");
        let c = parent.counts;
        let walks = Walks {
            edge_corners: gpu.storage_of_size(
                "edge corners",
                8 * c.edges,
                wgpu::BufferUsages::COPY_DST,
            )?,
            vertex_corner: gpu.storage_of_size(
                "vertex corners",
                4 * c.vertices,
                wgpu::BufferUsages::COPY_DST,
            )?,
            twin: gpu.storage_of_size("twins", 4 * c.corners, none)?,
        };
        let next = DeviceLevel {
            counts: child,
            face_size,
            face_vertices: gpu.storage_of_size(
                "face vertices",
                4 * child.corners,
                index_usage(),
            )?,
            face_edges: gpu.storage_of_size("face edges", 4 * child.corners, none)?,
            edge_vertices: gpu.storage_of_size("edge vertices", 8 * child.edges, none)?,
            edge_sharp: gpu.storage_of_size("sharp edges", 4 * child.edges, none)?,
            vertex_rules: gpu.storage_of_size("vertex rules", 4 * child.vertices, none)?,
            points: gpu.columns(child.vertices as usize, 3)?,
        };
        let stages = stage_bindings(&self._base, parent, &walks, &next, loop_scheme);
        let c = parent.counts;
        let p = parent;
        let mut passes = Vec::new();
        // Without the masks only the topology's stages run.
        let topology_only = |&(stage, _, _): &StageBindings<'_>| masks || stage == 2 || stage == 3;
        for (stage, count, buffers) in stages.into_iter().filter(topology_only) {
            let (grid, per_line) = gpu.dispatch_grid(count as usize, WORKGROUP);
            let params = [
                c.vertices as u32,
                c.faces as u32,
                c.edges as u32,
                c.corners as u32,
                p.face_size,
                u32::from(loop_scheme),
                count as u32,
                per_line,
            ];
            let uniform = gpu.uniform("refinement parameters", &params);
            let mut all = vec![(0, &uniform)];
            all.extend(buffers);
            let pipeline = &gpu.uniform_pipelines.stages[stage];
            passes.push(Pass {
                stage,
                bind_group: gpu.bind_group(STAGES[stage], pipeline, &all),
                grid,
                _parameters: uniform,
            });
        }
        self.passes.extend(passes);
        self._walks.push(walks);
        self.levels.push(next);
        Ok(())
    }
}

/// A stage's bindings: its index, its invocations, its buffers by binding.
type StageBindings<'a> = (usize, u64, Vec<(u32, &'a wgpu::Buffer)>);

/// The eight stages computing `next` from `p` (their order in [`STAGES`]), with the
/// buffers each reads and writes.
fn stage_bindings<'a>(
    base: &'a [wgpu::Buffer; 3],
    p: &'a DeviceLevel,
    walks: &'a Walks,
    next: &'a DeviceLevel,
    loop_scheme: bool,
) -> [StageBindings<'a>; 8] {
    let [offsets, corner_info, weights] = base;
    let c = p.counts;
    let (fv, fe, ev) = (&p.face_vertices, &p.face_edges, &p.edge_vertices);
    let (points, child_points) = (&p.points.buffer, &next.points.buffer);
    let (sharp, child_sharp) = (&p.edge_sharp, &next.edge_sharp);
    [
        (
            0,
            c.corners,
            vec![(3, fv), (4, fe), (5, ev), (6, &walks.edge_corners)],
        ),
        (
            1,
            c.corners,
            vec![
                (3, fv),
                (4, fe),
                (5, ev),
                (16, &walks.edge_corners),
                (8, &walks.twin),
                (7, &walks.vertex_corner),
                (2, corner_info),
                (18, sharp),
            ],
        ),
        (
            2,
            c.faces,
            vec![
                (1, offsets),
                (3, fv),
                (4, fe),
                (5, ev),
                (10, &next.face_vertices),
                (11, &next.face_edges),
                (12, &next.edge_vertices),
                (19, child_sharp),
            ],
        ),
        (
            3,
            c.edges,
            vec![
                (5, ev),
                (12, &next.edge_vertices),
                (18, sharp),
                (19, child_sharp),
            ],
        ),
        (
            4,
            if loop_scheme { 0 } else { c.faces },
            vec![(1, offsets), (3, fv), (9, points), (13, child_points)],
        ),
        (
            5,
            c.edges,
            vec![
                (16, &walks.edge_corners),
                (3, fv),
                (2, corner_info),
                (9, points),
                (13, child_points),
                (18, sharp),
                (5, ev),
            ],
        ),
        (
            6,
            c.vertices,
            vec![
                (17, &walks.vertex_corner),
                (3, fv),
                (2, corner_info),
                (15, &walks.twin),
                (9, points),
                (13, child_points),
                (14, weights),
                (20, &p.vertex_rules),
            ],
        ),
        (
            7,
            next.counts.vertices,
            vec![(20, &p.vertex_rules), (18, sharp), (21, &next.vertex_rules)],
        ),
    ]
}
