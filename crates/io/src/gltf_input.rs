//! glTF 2.0 input (`.glb`, and `.gltf` with embedded, data-URI or external buffers), read
//! with the `gltf` crate.
//!
//! Every triangle primitive (triangles, strips and fans) of every mesh is read, placed by
//! its node's world transform unless [`ReadOptions::ignore_transforms`] is set (then each
//! mesh is read once, as stored). A mesh no scene node instances is read untransformed.
//!
//! glTF stores a vertex once per distinct (position, normal, UV, ...) tuple, so a closed
//! surface arrives cut open along its UV and normal seams. Subdividing that as it is would
//! open cracks along every seam; the reader therefore welds vertices by position (exactly,
//! or within [`ReadOptions::weld_tolerance`]) into one topology. Normals are dropped (the
//! scheme makes its own). `TEXCOORD_0` becomes the mesh's texture coordinates: each corner
//! keeps its glTF vertex's value (v flipped back to OBJ's bottom-left origin), so vertices
//! welded across a UV seam keep the seam as a face-varying discontinuity. Other sets are
//! dropped with a warning, and so is `TEXCOORD_0` unless every primitive has it.
//!
//! Welding warns only when it joins vertices that are not copies of one vertex split at a
//! seam. Seam copies, as subd's own `.glb` writer makes them, share their position and their
//! `NORMAL` and differ in `TEXCOORD_0` only (or not even there: values of two UV islands
//! may coincide), so glTF vertices at one position with the same normal are taken as one
//! vertex. Vertices with different normals (a hard edge, a face's own corners, two surfaces
//! meeting at an angle) or without normals were distinct, or cannot be told apart from
//! distinct ones; welding them is reported. Coincident distinct vertices with equal normals
//! (a crack in a flat region) look exactly like seam copies and are welded silently.

use std::collections::HashMap;
use std::path::Path;

use glam::{DMat3, DMat4};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;
use subd_mesh::fvar::FVarChannel;
use subd_mesh::{DVec3, Mesh, SchemeHints, TopologyBuilder};

use crate::error::ReadError;
use crate::{MeshFile, ReadOptions};

/// Parses glTF (binary or JSON) from `bytes`. External buffer files are looked up in
/// `base_dir`; without one, only embedded and data-URI buffers can be read.
pub fn parse_gltf(
    bytes: &[u8],
    base_dir: Option<&Path>,
    options: &ReadOptions,
) -> Result<MeshFile, ReadError> {
    let gltf = parse_document(bytes)?;
    let buffers = load_buffers(&gltf, base_dir)?;
    let mut soup = TriangleSoup::default();
    for (mesh, transform) in instances(&gltf.document, options.ignore_transforms) {
        soup.add_mesh(&mesh, transform, &buffers)?;
    }
    if soup.triangles.is_empty() {
        return Err(ReadError::general("no triangle primitives"));
    }
    soup.into_mesh_file(options)
}

/// The document, validated. `gltf-json` 1.4's validator looks up each POSITION accessor
/// without a bounds check (a forged index panics), so that index is checked first.
fn parse_document(bytes: &[u8]) -> Result<gltf::Gltf, ReadError> {
    use gltf::json::mesh::Semantic;
    use gltf::json::validation::Checked;
    let bad = |e: gltf::Error| ReadError::general(e.to_string());
    // `gltf` 1.4 subtracts the 12-byte header from the declared file length unchecked (an
    // overflow panic under overflow checks), so a shorter declared length is refused here.
    if let Some(len) = bytes
        .strip_prefix(b"glTF")
        .and_then(|rest| rest.get(4..8))
        .map(|l| u32::from_le_bytes([l[0], l[1], l[2], l[3]]))
        && len < 12
    {
        return Err(ReadError::general(format!(
            "the GLB header declares {len} bytes, less than the 12 of the header itself"
        )));
    }
    let gltf::Gltf { document, blob } =
        gltf::Gltf::from_slice_without_validation(bytes).map_err(bad)?;
    let root = document.into_json();
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            if let Some(i) = primitive
                .attributes
                .get(&Checked::Valid(Semantic::Positions))
                && i.value() >= root.accessors.len()
            {
                return Err(ReadError::general(format!(
                    "mesh {m} primitive {p}: POSITION accessor {} does not exist",
                    i.value()
                )));
            }
        }
    }
    let document = gltf::Document::from_json(root).map_err(bad)?;
    Ok(gltf::Gltf { document, blob })
}

/// Each buffer's bytes: the GLB binary chunk, a base64 data URI, or a file beside the
/// document.
fn load_buffers(gltf: &gltf::Gltf, base_dir: Option<&Path>) -> Result<Vec<Vec<u8>>, ReadError> {
    let mut out = Vec::new();
    for buffer in gltf.buffers() {
        let at = |m: String| ReadError::general(format!("buffer {}: {m}", buffer.index()));
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => gltf
                .blob
                .clone()
                .ok_or_else(|| at("refers to the GLB binary chunk, which is missing".into()))?,
            gltf::buffer::Source::Uri(uri) => {
                if let Some(rest) = uri.strip_prefix("data:") {
                    let (header, payload) = rest
                        .split_once(',')
                        .ok_or_else(|| at("malformed data URI".into()))?;
                    if !header.ends_with(";base64") {
                        return Err(at("data URI is not base64".into()));
                    }
                    use base64::Engine;
                    base64::engine::general_purpose::STANDARD
                        .decode(payload)
                        .map_err(|e| at(format!("bad base64 data: {e}")))?
                } else {
                    let dir = base_dir.ok_or_else(|| {
                        at(format!(
                            "external file {uri:?} needs the document's directory"
                        ))
                    })?;
                    let name = percent_encoding::percent_decode_str(uri).decode_utf8_lossy();
                    let path = dir.join(name.as_ref());
                    std::fs::read(&path)
                        .map_err(|e| at(format!("cannot read {}: {e}", path.display())))?
                }
            }
        };
        if data.len() < buffer.length() {
            return Err(at(format!(
                "holds {} bytes, but the document declares {}",
                data.len(),
                buffer.length()
            )));
        }
        out.push(data);
    }
    Ok(out)
}

/// The meshes to read with their world transforms: every node of every scene that has a
/// mesh (a mesh appears once per instance), then the meshes no node instances. With
/// `ignore_transforms`, every mesh once with the identity.
fn instances(doc: &gltf::Document, ignore_transforms: bool) -> Vec<(gltf::Mesh<'_>, DMat4)> {
    if ignore_transforms {
        return doc.meshes().map(|m| (m, DMat4::IDENTITY)).collect();
    }
    let mut out = Vec::new();
    let mut instanced = vec![false; doc.meshes().len()];
    // A node may be reached from several scenes; each scene is a separate placement.
    for scene in doc.scenes() {
        let mut stack: Vec<(gltf::Node<'_>, DMat4, usize)> =
            scene.nodes().map(|n| (n, DMat4::IDENTITY, 0)).collect();
        while let Some((node, parent, depth)) = stack.pop() {
            // Valid glTF node graphs are trees; the depth bound stops a cyclic file.
            if depth > doc.nodes().len() {
                continue;
            }
            let local =
                DMat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(f64::from)));
            let world = parent * local;
            if let Some(mesh) = node.mesh() {
                instanced[mesh.index()] = true;
                out.push((mesh, world));
            }
            stack.extend(node.children().map(|c| (c, world, depth + 1)));
        }
    }
    for mesh in doc.meshes() {
        if !instanced[mesh.index()] {
            out.push((mesh, DMat4::IDENTITY));
        }
    }
    out
}

/// Triangles of all primitives in one vertex space, before welding.
#[derive(Default)]
struct TriangleSoup {
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    warnings: Vec<String>,
    /// `TEXCOORD_0` per glTF vertex (flipped back to a bottom-left origin: `1 - v`),
    /// parallel to `positions` while every primitive has it.
    texcoords: Vec<[f64; 2]>,
    /// A triangle primitive without `TEXCOORD_0` was read: the channel is dropped.
    missing_uv: bool,
    /// Texture coordinate sets beyond the first, which are not read.
    dropped_uv_sets: usize,
    /// Each glTF vertex's `NORMAL` in world space as bits (`None` where its primitive has
    /// none), parallel to `positions`: compared only, to tell seam copies from distinct
    /// vertices when welding ([`distinct_merged`]).
    normals: Vec<Option<[u64; 3]>>,
}

impl TriangleSoup {
    fn add_mesh(
        &mut self,
        mesh: &gltf::Mesh<'_>,
        transform: DMat4,
        buffers: &[Vec<u8>],
    ) -> Result<(), ReadError> {
        // A mirroring transform turns counter-clockwise triangles clockwise.
        let mirrored = transform.determinant() < 0.0;
        for primitive in mesh.primitives() {
            let at = |m: &str| {
                ReadError::general(format!(
                    "mesh {} primitive {}: {m}",
                    mesh.index(),
                    primitive.index()
                ))
            };
            let mode = primitive.mode();
            if !matches!(
                mode,
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
            ) {
                self.warnings.push(format!(
                    "mesh {} primitive {}: {mode:?} primitive skipped (only triangles are surfaces)",
                    mesh.index(),
                    primitive.index()
                ));
                continue;
            }
            let position_accessor = primitive
                .get(&gltf::Semantic::Positions)
                .ok_or_else(|| at("has no POSITION attribute"))?;
            check_accessor(
                &position_accessor,
                &[DataType::F32],
                Dimensions::Vec3,
                buffers,
            )
            .map_err(|m| at(&format!("POSITION {m}")))?;
            if let Some(indices) = primitive.indices() {
                let types = [DataType::U8, DataType::U16, DataType::U32];
                check_accessor(&indices, &types, Dimensions::Scalar, buffers)
                    .map_err(|m| at(&format!("indices {m}")))?;
            }
            let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
            let first = u32::try_from(self.positions.len())
                .map_err(|_| at("more than 2^32 vertices in all"))?;
            let positions = reader
                .read_positions()
                .ok_or_else(|| at("has no POSITION attribute"))?;
            for p in positions {
                let p = DVec3::new(p[0].into(), p[1].into(), p[2].into());
                let q = transform.transform_point3(p);
                if !q.is_finite() {
                    return Err(at("a position is not finite"));
                }
                self.positions.push(q);
            }
            let count = self.positions.len() - first as usize;
            self.read_texcoords(&primitive, &reader, count, buffers)
                .map_err(|m| at(&m))?;
            self.read_normals(&primitive, &reader, count, transform, buffers);
            let indices: Vec<u32> = match reader.read_indices() {
                Some(i) => i.into_u32().collect(),
                None => (0..count as u32).collect(),
            };
            if let Some(&bad) = indices.iter().find(|&&i| i as usize >= count) {
                return Err(at(&format!(
                    "index {bad} is out of range ({count} vertices)"
                )));
            }
            for mut t in corners(mode, &indices) {
                if mirrored {
                    t.swap(1, 2);
                }
                self.triangles.push(t.map(|i| first + i));
            }
            self.dropped_uv_sets += primitive
                .attributes()
                .filter(|(s, _)| matches!(s, gltf::Semantic::TexCoords(k) if *k > 0))
                .count();
        }
        Ok(())
    }

    /// Appends the primitive's `TEXCOORD_0` (`count` vertices), or notes that it has none.
    fn read_texcoords<'a, 's, F>(
        &mut self,
        primitive: &gltf::Primitive<'a>,
        reader: &gltf::mesh::Reader<'a, 's, F>,
        count: usize,
        buffers: &[Vec<u8>],
    ) -> Result<(), String>
    where
        F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
    {
        let Some(accessor) = primitive.get(&gltf::Semantic::TexCoords(0)) else {
            self.missing_uv = true;
            return Ok(());
        };
        check_accessor(
            &accessor,
            &[DataType::F32, DataType::U8, DataType::U16],
            Dimensions::Vec2,
            buffers,
        )
        .map_err(|m| format!("TEXCOORD_0 {m}"))?;
        if accessor.count() != count {
            return Err(format!(
                "TEXCOORD_0 has {} values for {count} vertices",
                accessor.count()
            ));
        }
        let uv = reader
            .read_tex_coords(0)
            .ok_or("TEXCOORD_0 cannot be read")?;
        for [u, v] in uv.into_f32() {
            if !(u.is_finite() && v.is_finite()) {
                return Err("a TEXCOORD_0 value is not finite".into());
            }
            self.texcoords.push([f64::from(u), 1.0 - f64::from(v)]);
        }
        Ok(())
    }

    /// Appends the primitive's `NORMAL`s (`count` vertices) moved into world space by
    /// `transform`'s inverse transpose, as bits with −0 made +0. A primitive without a
    /// readable `NORMAL` accessor gives `None`s: normals are dropped from the mesh anyway,
    /// so an unusable accessor is no reason to refuse the file.
    fn read_normals<'a, 's, F>(
        &mut self,
        primitive: &gltf::Primitive<'a>,
        reader: &gltf::mesh::Reader<'a, 's, F>,
        count: usize,
        transform: DMat4,
        buffers: &[Vec<u8>],
    ) where
        F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
    {
        let usable = primitive.get(&gltf::Semantic::Normals).is_some_and(|a| {
            a.count() == count
                && check_accessor(&a, &[DataType::F32], Dimensions::Vec3, buffers).is_ok()
        });
        let start = self.normals.len();
        if usable && let Some(normals) = reader.read_normals() {
            let to_world = DMat3::from_mat4(transform).inverse().transpose();
            self.normals.extend(normals.map(|n| {
                let n = to_world * DVec3::new(n[0].into(), n[1].into(), n[2].into());
                Some((n + DVec3::ZERO).to_array().map(f64::to_bits))
            }));
        }
        // A primitive whose normals were not read has none.
        self.normals.resize(start + count, None);
    }

    fn into_mesh_file(mut self, options: &ReadOptions) -> Result<MeshFile, ReadError> {
        let read = self.positions.len();
        let (remap, positions) = weld(&self.positions, options.weld_tolerance.unwrap_or(0.0));
        let mut face_vertices = Vec::with_capacity(self.triangles.len() * 3);
        // Each corner keeps its glTF vertex's texture coordinate: welded vertices whose
        // coordinates differ become a seam.
        let mut uv_indices = Vec::with_capacity(self.triangles.len() * 3);
        let mut degenerate = 0;
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| remap[i as usize]);
            if a == b || b == c || c == a {
                degenerate += 1;
                continue;
            }
            face_vertices.extend([a, b, c]);
            uv_indices.extend(t);
        }
        let distinct = distinct_merged(&remap, positions.len(), &self.normals);
        if distinct > 0 {
            self.warnings.push(format!(
                "{read} glTF vertices welded by position into {}, {distinct} of them into a \
                 vertex they were distinct from (another normal, or none to tell)",
                positions.len()
            ));
        }
        if degenerate > 0 {
            self.warnings.push(format!(
                "{degenerate} triangles with repeated vertices (after welding) left out"
            ));
        }
        if self.dropped_uv_sets > 0 {
            self.warnings.push(format!(
                "{} texture coordinate sets beyond TEXCOORD_0 dropped",
                self.dropped_uv_sets
            ));
        }
        let with_uv = !self.missing_uv && self.texcoords.len() == read;
        if self.missing_uv && !self.texcoords.is_empty() {
            self.warnings
                .push("texture coordinates dropped: some primitives have no TEXCOORD_0".into());
        }
        if face_vertices.is_empty() {
            return Err(ReadError::general("every triangle is degenerate"));
        }
        let sizes = vec![3u32; face_vertices.len() / 3];
        let (topology, build_warnings) = TopologyBuilder::new(positions.len())
            .accept_inconsistent_orientation(options.accept_inconsistent_orientation)
            .build_with_warnings(&sizes, &face_vertices)?;
        let orientation_conflicts = build_warnings
            .iter()
            .filter(|w| matches!(w, subd_mesh::BuildWarning::InconsistentOrientation { .. }))
            .count();
        self.warnings
            .extend(build_warnings.iter().map(|w| w.to_string()));
        let uv = if with_uv {
            let values = self.texcoords.iter().flatten().copied().collect();
            Some(
                FVarChannel::new(&topology, 2, values, uv_indices)
                    .map_err(|e| ReadError::general(format!("TEXCOORD_0: {e}")))?,
            )
        } else {
            None
        };
        let mut mesh = Mesh::new(topology, positions)?;
        mesh.hints = SchemeHints::default();
        mesh = crate::with_texcoords(mesh, uv)?;
        Ok(MeshFile {
            mesh,
            warnings: self.warnings,
            extra_tags: Vec::new(),
            orientation_conflicts,
            face_levels: None,
            stage: None,
        })
    }
}

/// Checks what `gltf`'s accessor reader takes on trust (element type, strides, ranges
/// within the buffers), so a malformed file is an error rather than a panic.
fn check_accessor(
    accessor: &gltf::Accessor<'_>,
    types: &[DataType],
    dimensions: Dimensions,
    buffers: &[Vec<u8>],
) -> Result<(), String> {
    if !types.contains(&accessor.data_type()) || accessor.dimensions() != dimensions {
        return Err(format!(
            "accessor {} has type {:?} {:?}",
            accessor.index(),
            accessor.dimensions(),
            accessor.data_type()
        ));
    }
    let count = accessor.count();
    if count == 0 {
        return Err(format!("accessor {} is empty", accessor.index()));
    }
    let element = accessor.size();
    if let Some(view) = accessor.view() {
        check_range(&view, accessor.offset(), count, element, buffers)?;
    }
    if let Some(sparse) = accessor.sparse() {
        let n = sparse.count();
        if n == 0 || n > count {
            return Err(format!("accessor {}: {n} sparse values", accessor.index()));
        }
        let indices = sparse.indices();
        check_range(
            &indices.view(),
            indices.offset(),
            n,
            indices.index_type().size(),
            buffers,
        )?;
        let values = sparse.values();
        check_range(&values.view(), values.offset(), n, element, buffers)?;
    }
    Ok(())
}

/// `count` elements of `element` bytes from `offset` in `view` lie inside the view, and the
/// view inside its buffer.
fn check_range(
    view: &gltf::buffer::View<'_>,
    offset: usize,
    count: usize,
    element: usize,
    buffers: &[Vec<u8>],
) -> Result<(), String> {
    let out_of_range = || format!("buffer view {} is too short for its data", view.index());
    let stride = view.stride().unwrap_or(element);
    if stride < element {
        return Err(format!("buffer view {} has stride {stride}", view.index()));
    }
    let end = stride
        .checked_mul(count - 1)
        .and_then(|x| x.checked_add(element))
        .and_then(|x| x.checked_add(offset))
        .ok_or_else(out_of_range)?;
    let view_end = view
        .offset()
        .checked_add(view.length())
        .ok_or_else(out_of_range)?;
    let buffer_len = buffers.get(view.buffer().index()).map_or(0, Vec::len);
    if end > view.length() || view_end > buffer_len {
        return Err(out_of_range());
    }
    Ok(())
}

/// The triangles of a primitive's index list in its mode (glTF 2.0 §3.7.2.1: strips
/// alternate winding so every triangle keeps the first one's orientation).
fn corners(mode: Mode, indices: &[u32]) -> Vec<[u32; 3]> {
    match mode {
        Mode::TriangleStrip => (2..indices.len())
            .map(|i| {
                let (a, b, c) = (indices[i - 2], indices[i - 1], indices[i]);
                if i % 2 == 0 { [a, b, c] } else { [b, a, c] }
            })
            .collect(),
        Mode::TriangleFan => (2..indices.len())
            .map(|i| [indices[i - 1], indices[i], indices[0]])
            .collect(),
        _ => indices
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect(),
    }
}

/// How many glTF vertices welding merged into a vertex they were distinct from, rather
/// than into a copy of themselves split at a seam.
///
/// `remap` gives each glTF vertex its welded vertex (`kept` of them) and `normals` its
/// normal's bits. Within one welded vertex, the glTF vertices with one normal are the seam
/// copies of one vertex (a writer splitting at UV seams copies the normal with the
/// position); each further normal is a further vertex, and so is every glTF vertex without
/// a normal, since nothing tells what it was split from.
fn distinct_merged(remap: &[u32], kept: usize, normals: &[Option<[u64; 3]>]) -> usize {
    if remap.len() == kept {
        return 0;
    }
    let mut vertices = std::collections::HashSet::new();
    let mut without_normal = 0;
    for (&w, normal) in remap.iter().zip(normals) {
        match normal {
            Some(n) => {
                vertices.insert((w, *n));
            }
            None => without_normal += 1,
        }
    }
    // Every welded vertex has at least one glTF vertex: at least `kept` distinct ones.
    vertices.len() + without_normal - kept
}

/// Merges vertices at the same position (`tolerance` 0: bit-equal coordinates, with −0 and
/// +0 equal) or within `tolerance` of an earlier kept vertex. Returns each input vertex's
/// new index and the kept positions, in first-seen order.
fn weld(positions: &[DVec3], tolerance: f64) -> (Vec<u32>, Vec<DVec3>) {
    let mut remap = Vec::with_capacity(positions.len());
    let mut kept: Vec<DVec3> = Vec::new();
    if tolerance > 0.0 {
        // Cells of the tolerance's size: a vertex within it of a kept one lies in one of
        // the 27 cells around its own.
        let cell = |p: DVec3| (p / tolerance).floor().as_i64vec3().to_array();
        let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        for &p in positions {
            let [x, y, z] = cell(p);
            let mut found = None;
            // The earliest kept vertex within reach, so the result does not depend on the
            // order cells are visited in.
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        for &k in grid.get(&[x + dx, y + dy, z + dz]).into_iter().flatten() {
                            if kept[k as usize].distance(p) <= tolerance
                                && found.is_none_or(|f: u32| k < f)
                            {
                                found = Some(k);
                            }
                        }
                    }
                }
            }
            let k = found.unwrap_or_else(|| {
                let k = kept.len() as u32;
                kept.push(p);
                grid.entry([x, y, z]).or_default().push(k);
                k
            });
            remap.push(k);
        }
    } else {
        let key = |p: DVec3| (p + DVec3::ZERO).to_array().map(f64::to_bits);
        let mut seen: HashMap<[u64; 3], u32> = HashMap::with_capacity(positions.len());
        for &p in positions {
            let k = *seen.entry(key(p)).or_insert_with(|| {
                kept.push(p);
                kept.len() as u32 - 1
            });
            remap.push(k);
        }
    }
    (remap, kept)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weld_exact_merges_equal_positions_and_signed_zeros() {
        let p = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(-0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 1e-300),
        ];
        let (remap, kept) = weld(&p, 0.0);
        assert_eq!(remap, vec![0, 1, 0, 2]);
        assert_eq!(kept.len(), 3);
    }

    #[test]
    fn weld_with_tolerance_joins_near_points_only() {
        let p = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 0.0, 0.9e-3),
            DVec3::new(0.0, 0.0, 2.5e-3),
            DVec3::new(0.5e-3, 0.0, 0.0),
        ];
        let (remap, kept) = weld(&p, 1e-3);
        assert_eq!(remap, vec![0, 0, 1, 0]);
        assert_eq!(kept, vec![p[0], p[2]]);
    }

    #[test]
    fn seam_copies_are_not_counted_as_distinct_vertices() {
        let (n, m) = (Some([1, 2, 3]), Some([4, 5, 6]));
        // Welded vertex 0: three seam copies (one normal). Welded vertex 1: two normals.
        // Welded vertex 2: two glTF vertices without normals.
        let remap = [0, 0, 0, 1, 1, 2, 2];
        let normals = [n, n, n, n, m, None, None];
        assert_eq!(distinct_merged(&remap, 3, &normals), 2);
        // Nothing merged.
        assert_eq!(distinct_merged(&[0, 1], 2, &[None, None]), 0);
    }

    #[test]
    fn strips_and_fans_keep_the_first_triangles_winding() {
        assert_eq!(
            corners(Mode::TriangleStrip, &[0, 1, 2, 3]),
            vec![[0, 1, 2], [2, 1, 3]]
        );
        assert_eq!(
            corners(Mode::TriangleFan, &[0, 1, 2, 3]),
            vec![[1, 2, 0], [2, 3, 0]]
        );
    }
}
