//! glTF 2.0 binary (`.glb`) output: positions, smooth vertex normals and triangle indices.
//!
//! The JSON document is built with `gltf-json` and packed with `gltf`'s GLB writer. Polygons
//! are fan-triangulated from their first vertex; hole faces are left out. Normals are the
//! area-weighted average of the incident face normals (the polygon's Newell normal), the
//! usual choice for shading a subdivided mesh; a vertex with no well-defined normal gets
//! +Z. glTF stores `f32`, so positions are rounded on output.

use std::borrow::Cow;
use std::io::Write;

use gltf_json as json;
use json::validation::Checked::Valid;
use json::validation::USize64;
use subd_mesh::{DVec3, Mesh};

/// Area-weighted vertex normals (Newell's method per polygon, hole faces skipped).
pub fn vertex_normals(mesh: &Mesh) -> Vec<DVec3> {
    let topo = &mesh.topology;
    let mut normals = vec![DVec3::ZERO; topo.num_vertices()];
    for f in 0..topo.num_faces() {
        if topo.is_hole(f) {
            continue;
        }
        let fv = topo.face_vertices(f);
        let mut n = DVec3::ZERO;
        for i in 0..fv.len() {
            let a = mesh.positions[fv[i] as usize];
            let b = mesh.positions[fv[(i + 1) % fv.len()] as usize];
            n += a.cross(b);
        }
        // `n` is twice the vector area: weighting by it gives area weighting.
        for &v in fv {
            normals[v as usize] += n;
        }
    }
    for n in &mut normals {
        *n = n.try_normalize().unwrap_or(DVec3::Z);
    }
    normals
}

fn bounds(values: &[[f32; 3]]) -> (json::Value, json::Value) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in values {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if values.is_empty() {
        lo = [0.0; 3];
        hi = [0.0; 3];
    }
    (
        json::Value::from(lo.to_vec()),
        json::Value::from(hi.to_vec()),
    )
}

/// Writes `mesh` as a binary glTF 2.0 file.
pub fn write_glb(w: &mut dyn Write, mesh: &Mesh) -> std::io::Result<()> {
    let topo = &mesh.topology;
    let positions: Vec<[f32; 3]> = mesh
        .positions
        .iter()
        .map(|p| [p.x as f32, p.y as f32, p.z as f32])
        .collect();
    let normals: Vec<[f32; 3]> = vertex_normals(mesh)
        .iter()
        .map(|n| [n.x as f32, n.y as f32, n.z as f32])
        .collect();
    let mut indices: Vec<u32> = Vec::with_capacity(topo.num_face_vertices() * 3 / 2);
    for f in 0..topo.num_faces() {
        if topo.is_hole(f) {
            continue;
        }
        let fv = topo.face_vertices(f);
        for i in 1..fv.len() - 1 {
            indices.extend_from_slice(&[fv[0], fv[i], fv[i + 1]]);
        }
    }

    let mut bin: Vec<u8> = Vec::with_capacity(positions.len() * 24 + indices.len() * 4);
    for p in positions.iter().chain(normals.iter()) {
        for c in p {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    for i in &indices {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    let vec3_len = positions.len() * 12;

    let mut root = json::Root {
        asset: json::Asset {
            generator: Some(format!("subd {}", env!("CARGO_PKG_VERSION"))),
            ..Default::default()
        },
        ..Default::default()
    };
    let buffer = root.push(json::Buffer {
        byte_length: USize64::from(bin.len()),
        extensions: Default::default(),
        extras: Default::default(),
        uri: None,
    });
    let view = |root: &mut json::Root, offset: usize, len: usize, target: json::buffer::Target| {
        root.push(json::buffer::View {
            buffer,
            byte_length: USize64::from(len),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            extensions: Default::default(),
            extras: Default::default(),
            target: Some(Valid(target)),
        })
    };
    let pos_view = view(&mut root, 0, vec3_len, json::buffer::Target::ArrayBuffer);
    let nrm_view = view(
        &mut root,
        vec3_len,
        vec3_len,
        json::buffer::Target::ArrayBuffer,
    );
    let idx_view = view(
        &mut root,
        2 * vec3_len,
        indices.len() * 4,
        json::buffer::Target::ElementArrayBuffer,
    );
    let accessor = |root: &mut json::Root,
                    view: json::Index<json::buffer::View>,
                    count: usize,
                    ct: json::accessor::ComponentType,
                    ty: json::accessor::Type,
                    minmax: Option<(json::Value, json::Value)>| {
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
    };
    use json::accessor::{ComponentType as C, Type as T};
    let pos_acc = accessor(
        &mut root,
        pos_view,
        positions.len(),
        C::F32,
        T::Vec3,
        Some(bounds(&positions)),
    );
    let nrm_acc = accessor(&mut root, nrm_view, normals.len(), C::F32, T::Vec3, None);
    let idx_acc = accessor(&mut root, idx_view, indices.len(), C::U32, T::Scalar, None);
    let primitive = json::mesh::Primitive {
        attributes: [
            (Valid(json::mesh::Semantic::Positions), pos_acc),
            (Valid(json::mesh::Semantic::Normals), nrm_acc),
        ]
        .into_iter()
        .collect(),
        extensions: Default::default(),
        extras: Default::default(),
        indices: Some(idx_acc),
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

    let json_bytes = json::serialize::to_vec(&root).map_err(std::io::Error::other)?;
    // GLB chunks are 4-byte aligned: JSON is padded with spaces, BIN with zeros.
    let mut json_padded = json_bytes;
    while json_padded.len() % 4 != 0 {
        json_padded.push(b' ');
    }
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length: (12 + 8 + json_padded.len() + 8 + bin.len()) as u32,
        },
        json: Cow::Owned(json_padded),
        bin: Some(Cow::Owned(bin)),
    };
    glb.to_writer(w).map_err(std::io::Error::other)
}
