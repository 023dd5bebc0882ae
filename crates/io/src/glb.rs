//! glTF 2.0 binary (`.glb`) output: positions, smooth vertex normals, texture coordinates
//! (`TEXCOORD_0`, vertices split at UV seams) and triangle indices.
//!
//! The JSON document is built with `gltf-json` and packed with `gltf`'s GLB writer. Polygons
//! are fan-triangulated from their first vertex; hole faces are left out. Normals are the
//! area-weighted average of the incident face normals (the polygon's Newell normal), the
//! usual choice for shading a subdivided mesh; a vertex with no well-defined normal gets
//! +Z. glTF stores `f32`, so positions are rounded on output.

use std::io::Write;

use gltf_json as json;
use json::validation::Checked::Valid;
use json::validation::USize64;
use rayon::prelude::*;
use subd_mesh::DVec3;

use crate::records::{for_each_windowed, write_records, write_windows};
use crate::view::MeshView;

/// Area-weighted vertex normals (Newell's method per polygon, hole faces skipped). Needs
/// every position at hand: streamed positions ([`crate::Points::Streamed`]) are made
/// whole first.
pub fn vertex_normals(mesh: &MeshView<'_>) -> Vec<DVec3> {
    let made;
    let positions = match mesh.positions() {
        Some(p) => p,
        None => {
            made = mesh
                .point_window(0..mesh.num_vertices())
                .map(|w| w.points().to_vec())
                .unwrap_or_else(|_| vec![DVec3::ZERO; mesh.num_vertices()]);
            &made[..]
        }
    };
    let mut normals = vec![DVec3::ZERO; positions.len()];
    // Faces in order, serially: the sums (and so the bits) do not depend on threads. A
    // streamed face naming a vertex beyond the positions ends the walk early (nothing is
    // indexed out of range); the writer reports it when it reaches the same window.
    let _ = for_each_windowed(
        mesh.num_faces(),
        |r| mesh.face_window(r),
        |faces, f| {
            if mesh.is_hole(f) {
                return;
            }
            let fv = faces.face(f);
            let mut n = DVec3::ZERO;
            for i in 0..fv.len() {
                let a = positions[fv[i] as usize];
                let b = positions[fv[(i + 1) % fv.len()] as usize];
                n += a.cross(b);
            }
            // `n` is twice the vector area: weighting by it gives area weighting.
            for &v in fv {
                normals[v as usize] += n;
            }
        },
    );
    normals
        .par_iter_mut()
        .with_min_len(4096)
        .for_each(|n| *n = n.try_normalize().unwrap_or(DVec3::Z));
    normals
}

/// Per-axis bounds of the `f32` positions, as glTF's accessor `min` and `max`.
fn bounds(mesh: &MeshView<'_>) -> std::io::Result<(json::Value, json::Value)> {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for_each_windowed(
        mesh.num_vertices(),
        |r| mesh.point_window(r),
        |points, i| {
            for (k, c) in to_f32(&points.get(i)).into_iter().enumerate() {
                lo[k] = lo[k].min(c);
                hi[k] = hi[k].max(c);
            }
        },
    )?;
    if mesh.num_vertices() == 0 {
        lo = [0.0; 3];
        hi = [0.0; 3];
    }
    Ok((
        json::Value::from(lo.to_vec()),
        json::Value::from(hi.to_vec()),
    ))
}

fn to_f32(p: &DVec3) -> [f32; 3] {
    [p.x as f32, p.y as f32, p.z as f32]
}

/// Writes `mesh` as a binary glTF 2.0 file. The arrays are encoded by all threads straight
/// into the output, so besides the normals nothing the size of the mesh is held. Texture
/// coordinates become `TEXCOORD_0`, with each vertex split into one glTF vertex per value
/// its corners name (glTF has one attribute set per vertex; the normal stays the vertex's
/// own, so seams do not show in the shading) and v flipped to glTF's top-left origin
/// (`1 - v`).
pub fn write_glb(w: &mut dyn Write, mesh: &MeshView<'_>) -> std::io::Result<()> {
    let computed;
    let normals = match mesh.normals() {
        Some(n) => n,
        None => {
            computed = vertex_normals(mesh);
            &computed[..]
        }
    };
    let Some(uv) = mesh.uv() else {
        return write_arrays(w, mesh, normals, None);
    };
    let split = SplitAtSeams::new(mesh, normals, uv)?;
    let holes: Vec<bool> = (0..mesh.num_faces()).map(|f| mesh.is_hole(f)).collect();
    let view = MeshView::new(
        &split.positions,
        &split.face_offsets,
        &split.face_vertices,
        &holes,
    )
    .map_err(std::io::Error::other)?;
    write_arrays(w, &view, &split.normals, Some(&split.texcoords))
}

/// A mesh with texture coordinates as glTF needs it: one vertex per (vertex, value) pair
/// its corners use.
struct SplitAtSeams {
    positions: Vec<DVec3>,
    normals: Vec<DVec3>,
    /// (u, 1 - v) per split vertex.
    texcoords: Vec<[f32; 2]>,
    face_offsets: Vec<u32>,
    face_vertices: Vec<u32>,
}

impl SplitAtSeams {
    fn new(
        mesh: &MeshView<'_>,
        normals: &[DVec3],
        uv: crate::TexCoords<'_>,
    ) -> std::io::Result<SplitAtSeams> {
        let mut face_offsets = Vec::with_capacity(mesh.num_faces() + 1);
        let mut original = Vec::with_capacity(mesh.num_face_vertices());
        face_offsets.push(0u32);
        for_each_windowed(
            mesh.num_faces(),
            |r| mesh.face_window(r),
            |faces, f| {
                original.extend_from_slice(faces.face(f));
                face_offsets.push(original.len() as u32);
            },
        )?;
        // A sorted list of the (vertex, value) pairs in use numbers the split vertices.
        let pair = |k: usize| (original[k] as u64) << 32 | uv.indices()[k] as u64;
        let mut pairs: Vec<u64> = (0..original.len()).map(pair).collect();
        pairs.par_sort_unstable();
        pairs.dedup();
        let face_vertices = (0..original.len())
            .into_par_iter()
            .map(|k| pairs.binary_search(&pair(k)).expect("every pair is listed") as u32)
            .collect();
        let points = mesh.point_window(0..mesh.num_vertices())?;
        let vertex = |p: u64| (p >> 32) as usize;
        Ok(SplitAtSeams {
            positions: pairs.iter().map(|&p| points.get(vertex(p))).collect(),
            normals: pairs.iter().map(|&p| normals[vertex(p)]).collect(),
            texcoords: pairs
                .iter()
                .map(|&p| {
                    let [u, v] = uv.uv(p as u32 as usize);
                    [u as f32, (1.0 - v) as f32]
                })
                .collect(),
            face_offsets,
            face_vertices,
        })
    }
}

/// Writes the arrays of one glTF primitive: positions, normals, texture coordinates when
/// given (one per vertex), and fan-triangulated indices.
fn write_arrays(
    w: &mut dyn Write,
    mesh: &MeshView<'_>,
    normals: &[DVec3],
    texcoords: Option<&[[f32; 2]]>,
) -> std::io::Result<()> {
    let layout = BinLayout::new(mesh, texcoords.is_some());
    let root = document(mesh, normals, &layout)?;
    let json_bytes = json::serialize::to_vec(&root).map_err(std::io::Error::other)?;
    write_container_start(w, json_bytes, layout.bin_len)?;
    write_bin_chunk(w, mesh, normals, texcoords)
}

/// Where each array lies in the BIN chunk: positions, normals, texture coordinates (when
/// present), indices, one after the other.
struct BinLayout {
    has_texcoords: bool,
    num_vertices: usize,
    num_indices: usize,
    vec3_len: usize,
    uv_len: usize,
    bin_len: usize,
}

impl BinLayout {
    fn new(mesh: &MeshView<'_>, has_texcoords: bool) -> BinLayout {
        let nv = mesh.num_vertices();
        let num_indices = 3 * mesh.num_fan_triangles();
        // Every element is 4 bytes, so the BIN chunk needs no padding.
        let vec3_len = nv * 12;
        let uv_len = if has_texcoords { nv * 8 } else { 0 };
        BinLayout {
            has_texcoords,
            num_vertices: nv,
            num_indices,
            vec3_len,
            uv_len,
            bin_len: 2 * vec3_len + uv_len + num_indices * 4,
        }
    }
}

/// The glTF JSON document: one buffer, its views and accessors, one mesh with one
/// primitive, one node, one scene (pushed in this order, which fixes their indices).
fn document(
    mesh: &MeshView<'_>,
    normals: &[DVec3],
    layout: &BinLayout,
) -> std::io::Result<json::Root> {
    let mut root = json::Root {
        asset: json::Asset {
            generator: Some(format!("subd {}", env!("CARGO_PKG_VERSION"))),
            ..Default::default()
        },
        ..Default::default()
    };
    let buffer = root.push(json::Buffer {
        byte_length: USize64::from(layout.bin_len),
        extensions: Default::default(),
        extras: Default::default(),
        uri: None,
    });
    let (vec3_len, uv_len) = (layout.vec3_len, layout.uv_len);
    let array = json::buffer::Target::ArrayBuffer;
    let pos_view = push_view(&mut root, buffer, 0, vec3_len, array);
    let nrm_view = push_view(&mut root, buffer, vec3_len, vec3_len, array);
    let uv_view = layout
        .has_texcoords
        .then(|| push_view(&mut root, buffer, 2 * vec3_len, uv_len, array));
    let idx_view = push_view(
        &mut root,
        buffer,
        2 * vec3_len + uv_len,
        layout.num_indices * 4,
        json::buffer::Target::ElementArrayBuffer,
    );
    use json::accessor::{ComponentType as C, Type as T};
    let nv = layout.num_vertices;
    let pos_acc = push_accessor(
        &mut root,
        pos_view,
        nv,
        C::F32,
        T::Vec3,
        Some(bounds(mesh)?),
    );
    let nrm_acc = push_accessor(&mut root, nrm_view, normals.len(), C::F32, T::Vec3, None);
    let uv_acc = uv_view.map(|v| push_accessor(&mut root, v, nv, C::F32, T::Vec2, None));
    let idx_acc = push_accessor(
        &mut root,
        idx_view,
        layout.num_indices,
        C::U32,
        T::Scalar,
        None,
    );
    let mut attributes: std::collections::BTreeMap<_, _> = [
        (Valid(json::mesh::Semantic::Positions), pos_acc),
        (Valid(json::mesh::Semantic::Normals), nrm_acc),
    ]
    .into_iter()
    .collect();
    if let Some(a) = uv_acc {
        attributes.insert(Valid(json::mesh::Semantic::TexCoords(0)), a);
    }
    push_scene(&mut root, attributes, idx_acc);
    Ok(root)
}

/// A view of `len` bytes of `buffer` from `offset`.
fn push_view(
    root: &mut json::Root,
    buffer: json::Index<json::Buffer>,
    offset: usize,
    len: usize,
    target: json::buffer::Target,
) -> json::Index<json::buffer::View> {
    root.push(json::buffer::View {
        buffer,
        byte_length: USize64::from(len),
        byte_offset: Some(USize64::from(offset)),
        byte_stride: None,
        extensions: Default::default(),
        extras: Default::default(),
        target: Some(Valid(target)),
    })
}

/// An accessor of `count` elements over a whole view, with bounds when given.
fn push_accessor(
    root: &mut json::Root,
    view: json::Index<json::buffer::View>,
    count: usize,
    ct: json::accessor::ComponentType,
    ty: json::accessor::Type,
    minmax: Option<(json::Value, json::Value)>,
) -> json::Index<json::Accessor> {
    let (min, max) = match minmax {
        Some((a, b)) => (Some(a), Some(b)),
        None => (None, None),
    };
    root.push(json::Accessor {
        buffer_view: Some(view),
        byte_offset: Some(USize64(0)),
        count: USize64::from(count),
        component_type: Valid(json::accessor::GenericComponentType(ct)),
        extensions: Default::default(),
        extras: Default::default(),
        type_: Valid(ty),
        min,
        max,
        normalized: false,
        sparse: None,
    })
}

/// One triangle primitive with these attributes and indices, in a mesh, a node and the
/// default scene.
fn push_scene(
    root: &mut json::Root,
    attributes: std::collections::BTreeMap<
        json::validation::Checked<json::mesh::Semantic>,
        json::Index<json::Accessor>,
    >,
    indices: json::Index<json::Accessor>,
) {
    let primitive = json::mesh::Primitive {
        attributes,
        extensions: Default::default(),
        extras: Default::default(),
        indices: Some(indices),
        material: None,
        mode: Valid(json::mesh::Mode::Triangles),
        targets: None,
    };
    let gmesh = root.push(json::Mesh {
        extensions: Default::default(),
        extras: Default::default(),
        primitives: vec![primitive],
        weights: None,
    });
    let node = root.push(json::Node {
        mesh: Some(gmesh),
        ..Default::default()
    });
    let scene = root.push(json::Scene {
        extensions: Default::default(),
        extras: Default::default(),
        nodes: vec![node],
    });
    root.scene = Some(scene);
}

/// The GLB header, the JSON chunk, and the header of the BIN chunk of `bin_len` bytes.
///
/// The GLB container (glTF 2.0 §4.4: a 12-byte header, then chunks of length, type and
/// data) is framed here rather than by `gltf::binary::Glb`, which wants the whole BIN chunk
/// as one slice: a copy of every array, hundreds of megabytes for a deep refinement.
fn write_container_start(
    w: &mut dyn Write,
    json_bytes: Vec<u8>,
    bin_len: usize,
) -> std::io::Result<()> {
    // GLB chunks are 4-byte aligned: JSON is padded with spaces, BIN with zeros.
    let mut json_padded = json_bytes;
    while json_padded.len() % 4 != 0 {
        json_padded.push(b' ');
    }
    let total = 12 + 8 + json_padded.len() + 8 + bin_len;
    let total = u32::try_from(total)
        .map_err(|_| std::io::Error::other("the mesh is too large for a .glb file (4 GiB)"))?;
    w.write_all(b"glTF")?;
    w.write_all(&2u32.to_le_bytes())?;
    w.write_all(&total.to_le_bytes())?;
    w.write_all(&(json_padded.len() as u32).to_le_bytes())?;
    w.write_all(b"JSON")?;
    w.write_all(&json_padded)?;
    w.write_all(&(bin_len as u32).to_le_bytes())?;
    w.write_all(b"BIN\0")
}

/// The BIN chunk's data, in the order of [`BinLayout`], encoded by all threads.
fn write_bin_chunk(
    w: &mut dyn Write,
    mesh: &MeshView<'_>,
    normals: &[DVec3],
    texcoords: Option<&[[f32; 2]]>,
) -> std::io::Result<()> {
    write_windows(
        w,
        mesh.num_vertices(),
        |r| mesh.point_window(r),
        |points, i, b| {
            for c in to_f32(&points.get(i)) {
                b.extend_from_slice(&c.to_le_bytes());
            }
        },
    )?;
    write_records(w, normals.len(), |i, b| {
        for c in to_f32(&normals[i]) {
            b.extend_from_slice(&c.to_le_bytes());
        }
    })?;
    if let Some(t) = texcoords {
        write_records(w, t.len(), |i, b| {
            for c in t[i] {
                b.extend_from_slice(&c.to_le_bytes());
            }
        })?;
    }
    // Polygons as fans from their first corner.
    write_windows(
        w,
        mesh.num_faces(),
        |r| mesh.face_window(r),
        |faces, f, b| {
            if mesh.is_hole(f) {
                return;
            }
            let fv = faces.face(f);
            for i in 1..fv.len() - 1 {
                for v in [fv[0], fv[i], fv[i + 1]] {
                    b.extend_from_slice(&v.to_le_bytes());
                }
            }
        },
    )
}
