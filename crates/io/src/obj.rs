//! Wavefront OBJ with OpenSubdiv's tag lines.
//!
//! Read: `v` (first three coordinates, `f64`), `f` (polygons kept as they are, vertex index
//! before the first `/`, negative indices relative to the vertices read so far as OBJ
//! defines them), and OpenSubdiv's `t` tag lines with **0-based** indices:
//! `t crease 2/1/0 a b s` (a chain `n/1/0` or `n/(n-1)/0` also works), `t corner 1/1/0 v s`,
//! `t hole 1/0/0 f`, `t interpolateboundary 1/0/0 k` (0 none, 1 edge-and-corner, 2 edge-only),
//! `t creasemethod 0/0/1 normal|chaikin`, `t smoothtriangles 0/0/1 catmark|smooth`,
//! `t facevaryinginterpolateboundary 1/0/0 k` (OpenSubdiv's `FVarLinearInterpolation`, 0 none
//! to 5 all). Other tags (the hierarchical edits `vertexedit`/`edgeedit`/`faceedit`, ...)
//! are kept verbatim and reported in a warning. Texture coordinates (`vt u v`, a third
//! coordinate dropped, and the `vt` index of `f v/vt` or `f v/vt/vn`) become the mesh's
//! first face-varying channel when every face gives them; normals, groups and materials are
//! skipped. Written: `v`, `vt` and `f v/vt` when the view has texture coordinates, `vn`
//! when it has normals, and the tags.
//!
//! Why not `tobj` for the geometry: `tobj` renumbers vertices by first use and drops vertices
//! no face uses, which would break the vertex-index contract with OpenSubdiv (vertex `v` of the
//! file is vertex `v` of the mesh, unused ones included); it reports no line numbers and turns
//! two-vertex faces into lines silently. The reader here is tested against `tobj` on every
//! shape instead.

use std::io::Write;

use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};
use subd_mesh::{
    BoundaryInterpolation, CreaseMethod, DVec3, Mesh, SchemeHints, TopologyBuilder,
    TriangleSubdivision,
};

use crate::error::ReadError;
use crate::records::{write_records, write_windows};
use crate::text::{push_f64s, push_u64};
use crate::view::MeshView;
use crate::{MeshFile, ReadOptions};

mod chunks;

/// One `t` line.
struct TagLine {
    line: usize,
    name: String,
    ints: Vec<i64>,
    floats: Vec<f64>,
    strings: Vec<String>,
    raw: String,
}

fn is_statement_name(s: &str) -> bool {
    !s.is_empty()
        && s.bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'#')
}

/// The statements of an OBJ file that make a mesh, before any checking across lines.
#[derive(Default)]
struct ObjStatements {
    positions: Vec<DVec3>,
    /// `vt` lines: (u, v); a third coordinate is dropped.
    texcoords: Vec<[f64; 2]>,
    face_sizes: Vec<u32>,
    face_vertices: Vec<u32>,
    /// Per face-vertex, its `vt` index, for the faces that give one.
    face_texcoords: Vec<u32>,
    /// Faces that give `vt` indices, and the line of the first that gives none.
    faces_with_texcoords: usize,
    first_face_without_texcoords: Option<usize>,
    face_lines: Vec<u32>,
    tags: Vec<TagLine>,
    warnings: Vec<String>,
}

/// Parses OBJ text. Errors carry the 1-based line number.
pub fn parse_obj(bytes: &[u8], options: &ReadOptions) -> Result<MeshFile, ReadError> {
    parse_obj_in_chunks(bytes, options, chunks::chunk_bytes())
}

/// [`parse_obj`] with the statements read in parallel chunks of about `chunk_bytes`; input
/// the chunks refuse is read again serially, so that the first error in file order is the
/// one reported, worded as the serial reader words it.
pub(crate) fn parse_obj_in_chunks(
    bytes: &[u8],
    options: &ReadOptions,
    chunk_bytes: usize,
) -> Result<MeshFile, ReadError> {
    let st = match chunks::read_statements(bytes, chunk_bytes) {
        Ok(st) => st,
        Err(chunks::Failed) => read_statements(bytes)?,
    };
    mesh_from_statements(st, options)
}

/// [`parse_obj`] with the statements read by the serial reader alone: what the chunked
/// reader must agree with (the fuzz target holds it to that).
#[cfg(feature = "fuzzing")]
pub(crate) fn parse_obj_serially(
    bytes: &[u8],
    options: &ReadOptions,
) -> Result<MeshFile, ReadError> {
    mesh_from_statements(read_statements(bytes)?, options)
}

/// The mesh, tags and UVs the statements give.
fn mesh_from_statements(
    mut st: ObjStatements,
    options: &ReadOptions,
) -> Result<MeshFile, ReadError> {
    check_face_indices(&st)?;
    let (mut topology, orientation_conflicts) = build_topology(&mut st, options)?;
    let mut hints = SchemeHints::default();
    let mut extra_tags = Vec::new();
    for tag in &st.tags {
        apply_tag(
            tag,
            &mut topology,
            &mut hints,
            &mut st.warnings,
            &mut extra_tags,
        )?;
    }
    let uv = texcoord_channel(&mut st, &topology)?;
    let mut mesh =
        Mesh::new(topology, std::mem::take(&mut st.positions)).map_err(ReadError::Topology)?;
    mesh.hints = hints;
    mesh = crate::with_texcoords(mesh, uv)?;
    Ok(MeshFile {
        mesh,
        warnings: st.warnings,
        extra_tags,
        orientation_conflicts,
        face_levels: None,
        stage: None,
    })
}

/// Reads the file line by line into its statements (joining `\`-continued lines).
fn read_statements(bytes: &[u8]) -> Result<ObjStatements, ReadError> {
    let mut st = ObjStatements::default();
    let mut unknown_reported = false;
    let mut line_no = 0usize;
    let mut rest = bytes;
    let mut joined = String::new();
    while !rest.is_empty() {
        let end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        let raw = &rest[..end];
        rest = if end < rest.len() {
            &rest[end + 1..]
        } else {
            &[]
        };
        line_no += 1;
        let this_line = line_no;
        let text = std::str::from_utf8(raw).map_err(|_| {
            ReadError::line(this_line, "not valid UTF-8 text (is this an OBJ file?)")
        })?;
        let text = text.strip_suffix('\r').unwrap_or(text);
        // A trailing backslash continues the statement on the next line.
        if let Some(head) = text.strip_suffix('\\') {
            joined.push_str(head);
            joined.push(' ');
            continue;
        }
        let owned;
        let text = if joined.is_empty() {
            text
        } else {
            joined.push_str(text);
            owned = std::mem::take(&mut joined);
            owned.as_str()
        };
        let mut tokens = text.split_ascii_whitespace();
        let Some(keyword) = tokens.next() else {
            continue;
        };
        if keyword.starts_with('#') {
            continue;
        }
        match keyword {
            "v" => {
                let p = read_coordinates::<3>(this_line, tokens, "vertex", st.positions.len())?;
                st.positions.push(DVec3::from_array(p));
            }
            "vt" => {
                let uv = read_coordinates::<2>(
                    this_line,
                    tokens,
                    "texture coordinate",
                    st.texcoords.len(),
                )?;
                st.texcoords.push(uv);
            }
            "f" | "fo" => read_face(this_line, tokens, &mut st)?,
            "t" => {
                let tag = parse_tag(this_line, text, tokens)?;
                st.tags.push(tag);
            }
            "vn" | "vp" | "o" | "g" | "s" | "mg" | "usemtl" | "mtllib" | "l" | "p" | "lod"
            | "bevel" | "c_interp" | "d_interp" | "shadow_obj" | "trace_obj" | "maplib"
            | "usemap" | "cstype" | "deg" | "bmat" | "step" | "curv" | "curv2" | "surf"
            | "parm" | "trim" | "hole" | "scrv" | "sp" | "end" | "con" | "ctech" | "stech"
            | "call" | "csh" => {}
            other if is_statement_name(other) => {
                if !unknown_reported {
                    st.warnings.push(format!(
                        "line {this_line}: unknown OBJ statement {other:?} ignored"
                    ));
                    unknown_reported = true;
                }
            }
            _ => {
                return Err(ReadError::line(
                    this_line,
                    "not an OBJ statement (is this an OBJ file?)",
                ));
            }
        }
    }
    if !joined.is_empty() {
        return Err(ReadError::line(line_no, "line continuation at end of file"));
    }
    if st.face_sizes.is_empty() {
        return Err(ReadError::general(if st.positions.is_empty() {
            "no vertices and no faces (empty or not an OBJ file)"
        } else {
            "no faces"
        }));
    }
    Ok(st)
}

/// The first `N` numbers of a `v` or `vt` line (a `vt` line may give only u; v is then 0).
fn read_coordinates<'a, const N: usize>(
    line: usize,
    mut tokens: impl Iterator<Item = &'a str>,
    what: &str,
    read_so_far: usize,
) -> Result<[f64; N], ReadError> {
    let mut p = [0.0f64; N];
    for (k, slot) in p.iter_mut().enumerate() {
        let Some(tok) = tokens.next() else {
            if what == "vertex" || k == 0 {
                return Err(ReadError::line(
                    line,
                    format!("{what} has {k} coordinates; {N} are needed"),
                ));
            }
            break;
        };
        *slot = tok.parse::<f64>().map_err(|_| {
            ReadError::line(line, format!("{what} coordinate {tok:?} is not a number"))
        })?;
        if !slot.is_finite() {
            return Err(ReadError::line(
                line,
                format!(
                    "{what} {} has a non-finite coordinate {tok:?}",
                    read_so_far + 1
                ),
            ));
        }
    }
    Ok(p)
}

/// Resolves one OBJ index (1-based, or negative: relative to the `count` elements read so
/// far) to a 0-based index.
fn resolve_index(line: usize, idx: i64, count: usize, what: &str) -> Result<i64, ReadError> {
    if idx > 0 {
        Ok(idx - 1)
    } else if idx < 0 {
        let r = count as i64 + idx;
        if r < 0 {
            return Err(ReadError::line(
                line,
                format!(
                    "relative face index {idx} points before the first {what} ({count} read so far)"
                ),
            ));
        }
        Ok(r)
    } else {
        Err(ReadError::line(
            line,
            format!("face index 0 is invalid (OBJ {what} indices start at 1)"),
        ))
    }
}

/// One `f` line: `v`, `v/vt`, `v/vt/vn` or `v//vn` per corner.
fn read_face<'a>(
    line: usize,
    tokens: impl Iterator<Item = &'a str>,
    st: &mut ObjStatements,
) -> Result<(), ReadError> {
    let first = st.face_vertices.len();
    let first_uv = st.face_texcoords.len();
    let mut corners = 0usize;
    let mut with_uv = 0usize;
    for tok in tokens {
        let mut parts = tok.split('/');
        let head = parts.next().unwrap_or("");
        let idx = head
            .parse::<i64>()
            .map_err(|_| ReadError::line(line, format!("face vertex {tok:?} is not an index")))?;
        let v = resolve_index(line, idx, st.positions.len(), "vertex")?;
        // Range against the final vertex count is checked once all lines are read.
        st.face_vertices.push(u32::try_from(v).unwrap_or(u32::MAX));
        corners += 1;
        match parts.next() {
            Some(t) if !t.is_empty() => {
                let idx = t.parse::<i64>().map_err(|_| {
                    ReadError::line(
                        line,
                        format!("texture coordinate index {t:?} of {tok:?} is not an index"),
                    )
                })?;
                let uv = resolve_index(line, idx, st.texcoords.len(), "texture coordinate")?;
                st.face_texcoords
                    .push(u32::try_from(uv).unwrap_or(u32::MAX));
                with_uv += 1;
            }
            _ => {}
        }
    }
    if corners < 3 {
        return Err(ReadError::line(
            line,
            format!("face has {corners} vertices; a face needs at least 3"),
        ));
    }
    if corners >= u32::MAX as usize {
        return Err(ReadError::line(line, "face has too many vertices"));
    }
    if with_uv != 0 && with_uv != corners {
        return Err(ReadError::line(
            line,
            format!("face gives texture coordinates at {with_uv} of its {corners} corners"),
        ));
    }
    debug_assert_eq!(st.face_vertices.len() - first, corners);
    if with_uv == 0 {
        st.face_texcoords.truncate(first_uv);
        st.first_face_without_texcoords.get_or_insert(line);
    } else {
        st.faces_with_texcoords += 1;
    }
    st.face_sizes.push(corners as u32);
    st.face_lines.push(line as u32);
    Ok(())
}

/// Checks every face's vertex and `vt` indices against the final counts, naming the line.
fn check_face_indices(st: &ObjStatements) -> Result<(), ReadError> {
    let nv = st.positions.len();
    let mut offset = 0usize;
    for (f, &n) in st.face_sizes.iter().enumerate() {
        for &v in &st.face_vertices[offset..offset + n as usize] {
            if v as usize >= nv {
                return Err(ReadError::line(
                    st.face_lines[f] as usize,
                    format!(
                        "face refers to vertex {}, but the file has {nv} vertices",
                        shown_index(v)
                    ),
                ));
            }
        }
        offset += n as usize;
    }
    // Texture indices parallel the face-vertices when every face gives them; otherwise
    // they are dropped (see `texcoord_channel`) and not checked.
    let nt = st.texcoords.len();
    let out_of_range = match st.first_face_without_texcoords {
        None => st.face_texcoords.iter().position(|&t| t as usize >= nt),
        Some(_) => None,
    };
    if let Some(k) = out_of_range {
        let mut end = 0usize;
        let face = st
            .face_sizes
            .iter()
            .position(|&n| {
                end += n as usize;
                end > k
            })
            .unwrap_or(0);
        return Err(ReadError::line(
            st.face_lines[face] as usize,
            format!(
                "face refers to texture coordinate {}, but the file has {nt}",
                shown_index(st.face_texcoords[k])
            ),
        ));
    }
    Ok(())
}

fn shown_index(i: u32) -> String {
    if i == u32::MAX {
        "beyond 2^32".to_string()
    } else {
        (i as u64 + 1).to_string()
    }
}

/// Builds the topology of the faces; returns it with the number of accepted orientation
/// conflicts, and turns the builder's warnings into lines of `st.warnings`.
fn build_topology(
    st: &mut ObjStatements,
    options: &ReadOptions,
) -> Result<(subd_mesh::Topology, usize), ReadError> {
    let face_lines = &st.face_lines;
    let (topology, build_warnings) = TopologyBuilder::new(st.positions.len())
        .accept_inconsistent_orientation(options.accept_inconsistent_orientation)
        .build_with_warnings(&st.face_sizes, &st.face_vertices)
        .map_err(|e| match e {
            subd_mesh::TopologyError::InconsistentOrientation { second_face, .. } => {
                ReadError::line(
                    face_lines[second_face] as usize,
                    format!("{e} (accept with --accept-inconsistent-orientation)"),
                )
            }
            other => ReadError::Topology(other),
        })?;
    let orientation_conflicts = build_warnings
        .iter()
        .filter(|w| matches!(w, subd_mesh::BuildWarning::InconsistentOrientation { .. }))
        .count();
    for w in build_warnings {
        let face = match &w {
            subd_mesh::BuildWarning::RepeatedVertex { face, .. } => *face,
            subd_mesh::BuildWarning::InconsistentOrientation { second_face, .. } => *second_face,
            _ => 0,
        };
        st.warnings.push(format!("line {}: {w}", face_lines[face]));
    }
    Ok((topology, orientation_conflicts))
}

/// The texture coordinates as a face-varying channel, when every face gives `vt` indices.
/// A file where only some faces do keeps its geometry and loses its texture coordinates,
/// with a warning naming the first face without them.
fn texcoord_channel(
    st: &mut ObjStatements,
    topology: &subd_mesh::Topology,
) -> Result<Option<FVarChannel>, ReadError> {
    if st.faces_with_texcoords == 0 {
        return Ok(None);
    }
    if let Some(line) = st.first_face_without_texcoords {
        st.warnings.push(format!(
            "line {line}: face has no texture coordinate indices while {} other faces have them; texture coordinates dropped",
            st.faces_with_texcoords
        ));
        return Ok(None);
    }
    let values: Vec<f64> = st.texcoords.iter().flatten().copied().collect();
    let indices = std::mem::take(&mut st.face_texcoords);
    FVarChannel::new(topology, 2, values, indices)
        .map(Some)
        .map_err(|e| ReadError::general(format!("texture coordinates: {e}")))
}

fn parse_tag<'a>(
    line: usize,
    text: &str,
    mut tokens: impl Iterator<Item = &'a str>,
) -> Result<TagLine, ReadError> {
    let name = tokens
        .next()
        .ok_or_else(|| ReadError::line(line, "tag line has no tag name"))?
        .to_string();
    let counts = tokens.next().ok_or_else(|| {
        ReadError::line(line, format!("tag {name:?} has no argument counts (n/m/k)"))
    })?;
    let parts: Vec<&str> = counts.split('/').collect();
    let parsed: Option<Vec<usize>> = parts.iter().map(|p| p.parse::<usize>().ok()).collect();
    let [ni, nf, ns] = match parsed.as_deref() {
        Some(&[a, b, c]) => [a, b, c],
        _ => {
            return Err(ReadError::line(
                line,
                format!("tag {name:?} has malformed argument counts {counts:?} (expected n/m/k)"),
            ));
        }
    };
    let args: Vec<&str> = tokens.collect();
    if args.len() != ni.saturating_add(nf).saturating_add(ns) {
        return Err(ReadError::line(
            line,
            format!(
                "tag {name:?} declares {ni}/{nf}/{ns} arguments but has {}",
                args.len()
            ),
        ));
    }
    let ints = args[..ni]
        .iter()
        .map(|s| {
            s.parse::<i64>().map_err(|_| {
                ReadError::line(line, format!("tag {name:?}: {s:?} is not an integer"))
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let floats = args[ni..ni + nf]
        .iter()
        .map(|s| {
            s.parse::<f64>()
                .map_err(|_| ReadError::line(line, format!("tag {name:?}: {s:?} is not a number")))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let strings = args[ni + nf..].iter().map(|s| s.to_string()).collect();
    Ok(TagLine {
        line,
        name,
        ints,
        floats,
        strings,
        raw: text.trim().to_string(),
    })
}

fn tag_index(tag: &TagLine, what: &str, i: i64) -> Result<u64, ReadError> {
    u64::try_from(i).map_err(|_| {
        ReadError::line(
            tag.line,
            format!("{} tag names {what} {i}, which does not exist", tag.name),
        )
    })
}

/// An error of a malformed tag line.
fn tag_error(tag: &TagLine, msg: &str) -> ReadError {
    ReadError::line(tag.line, format!("{} tag: {msg}", tag.name))
}

/// A topology's refusal of a tag, at the tag's line.
fn topology_error(tag: &TagLine, e: subd_mesh::TopologyError) -> ReadError {
    ReadError::line(tag.line, e.to_string())
}

/// Applies one tag line: sharpness and holes to `topo`, scheme options to `hints`; tags
/// that change nothing are kept verbatim in `extra`, with a warning.
fn apply_tag(
    tag: &TagLine,
    topo: &mut subd_mesh::Topology,
    hints: &mut SchemeHints,
    warnings: &mut Vec<String>,
    extra: &mut Vec<String>,
) -> Result<(), ReadError> {
    match tag.name.as_str() {
        "crease" => return apply_crease(tag, topo, warnings),
        "corner" => return apply_corner(tag, topo),
        "hole" => return apply_hole(tag, topo),
        "interpolateboundary"
        | "creasemethod"
        | "smoothtriangles"
        | "facevaryinginterpolateboundary" => return apply_hint(tag, hints),
        "vertexedit" | "edgeedit" | "faceedit" => {
            warnings.push(format!(
                "line {}: hierarchical edit tag {:?} is not supported (OpenSubdiv's Far ignores it too); kept but not applied",
                tag.line, tag.name
            ));
        }
        other => {
            warnings.push(format!(
                "line {}: tag {other:?} does not affect vertex positions; kept but not applied",
                tag.line
            ));
        }
    }
    extra.push(tag.raw.clone());
    Ok(())
}

/// `t crease n 1|n-1 v0 .. vn-1 s..`: sharpness on the edges of a vertex chain; a pair that
/// is not an edge is ignored with a warning.
fn apply_crease(
    tag: &TagLine,
    topo: &mut subd_mesh::Topology,
    warnings: &mut Vec<String>,
) -> Result<(), ReadError> {
    let n = tag.ints.len();
    if n < 2 || !(tag.floats.len() == 1 || tag.floats.len() == n - 1) {
        return Err(tag_error(
            tag,
            "expected n >= 2 vertices and 1 or n-1 sharpness values",
        ));
    }
    for i in 0..n - 1 {
        let a = tag_index(tag, "vertex", tag.ints[i])?;
        let b = tag_index(tag, "vertex", tag.ints[i + 1])?;
        let s = tag.floats[i.min(tag.floats.len() - 1)];
        if topo
            .set_crease(a, b, s)
            .map_err(|e| topology_error(tag, e))?
            .is_none()
        {
            warnings.push(format!(
                "line {}: crease tag names edge ({a}, {b}), which is not an edge of the mesh; ignored",
                tag.line
            ));
        }
    }
    Ok(())
}

/// `t corner n 1|n v.. s..`: vertex sharpness.
fn apply_corner(tag: &TagLine, topo: &mut subd_mesh::Topology) -> Result<(), ReadError> {
    let n = tag.ints.len();
    if n < 1 || !(tag.floats.len() == 1 || tag.floats.len() == n) {
        return Err(tag_error(
            tag,
            "expected n >= 1 vertices and 1 or n sharpness values",
        ));
    }
    for i in 0..n {
        let v = tag_index(tag, "vertex", tag.ints[i])?;
        topo.set_corner(v, tag.floats[i.min(tag.floats.len() - 1)])
            .map_err(|e| topology_error(tag, e))?;
    }
    Ok(())
}

/// `t hole n 0 f..`: faces made holes.
fn apply_hole(tag: &TagLine, topo: &mut subd_mesh::Topology) -> Result<(), ReadError> {
    if tag.ints.is_empty() {
        return Err(tag_error(tag, "expected at least one face index"));
    }
    for &f in &tag.ints {
        topo.set_hole_checked(tag_index(tag, "face", f)?)
            .map_err(|e| topology_error(tag, e))?;
    }
    Ok(())
}

/// The tags that choose scheme options: boundary and face-varying interpolation, crease
/// method, triangle rule.
fn apply_hint(tag: &TagLine, hints: &mut SchemeHints) -> Result<(), ReadError> {
    let bad = |msg: &str| tag_error(tag, msg);
    match tag.name.as_str() {
        "interpolateboundary" => {
            let k = match tag.ints.as_slice() {
                [k] => *k,
                _ => {
                    return Err(bad(
                        "expected one integer (0 none, 1 edge-and-corner, 2 edge-only)",
                    ));
                }
            };
            hints.boundary_interpolation =
                Some(BoundaryInterpolation::from_shape_tag(k).ok_or_else(|| {
                    bad(&format!(
                        "unknown value {k} (0 none, 1 edge-and-corner, 2 edge-only)"
                    ))
                })?);
        }
        "creasemethod" => {
            hints.crease_method = Some(match tag.strings.first().map(String::as_str) {
                Some("normal") | Some("uniform") => CreaseMethod::Uniform,
                Some("chaikin") => CreaseMethod::Chaikin,
                _ => return Err(bad("expected one string: normal or chaikin")),
            });
        }
        "smoothtriangles" => {
            hints.triangle_subdivision = Some(match tag.strings.first().map(String::as_str) {
                Some("catmark") => TriangleSubdivision::Catmark,
                Some("smooth") => TriangleSubdivision::Smooth,
                _ => return Err(bad("expected one string: catmark or smooth")),
            });
        }
        // "facevaryinginterpolateboundary", the last of the tags `apply_tag` sends here.
        _ => {
            let k = match tag.ints.as_slice() {
                [k] => *k,
                _ => return Err(bad("expected one integer (0 none ... 5 all)")),
            };
            hints.fvar_interpolation =
                Some(FVarLinearInterpolation::from_shape_tag(k).ok_or_else(|| {
                    bad(&format!(
                        "unknown value {k} (0 none, 1 corners-only, 2 corners-plus1, 3 corners-plus2, 4 boundaries, 5 all)"
                    ))
                })?);
        }
    }
    Ok(())
}

/// Writes `mesh` as OBJ with OpenSubdiv's tag lines (0-based indices in tags), plus the
/// verbatim `extra_tags`. Coordinates are written with Rust's shortest round-trip formatting,
/// so reading the file back gives the same `f64` values. Lines are formatted by all threads
/// and written in order.
pub fn write_obj(
    w: &mut dyn Write,
    mesh: &MeshView<'_>,
    extra_tags: &[String],
) -> std::io::Result<()> {
    writeln!(w, "# written by subd {}", env!("CARGO_PKG_VERSION"))?;
    writeln!(
        w,
        "# {} vertices, {} faces; tag indices are 0-based (OpenSubdiv shape convention)",
        mesh.num_vertices(),
        mesh.num_faces()
    )?;
    write_windows(
        w,
        mesh.num_vertices(),
        |r| mesh.point_window(r),
        |points, i, b| push_numbers_line(b, b"v", &points.get(i).to_array()),
    )?;
    if let Some(normals) = mesh.normals() {
        write_records(w, normals.len(), |i, b| {
            push_numbers_line(b, b"vn", &normals[i].to_array())
        })?;
    }
    let uv = mesh.uv();
    if let Some(uv) = uv {
        write_records(w, uv.len(), |i, b| push_numbers_line(b, b"vt", &uv.uv(i)))?;
    }
    let with_normals = mesh.normals().is_some();
    write_windows(
        w,
        mesh.num_faces(),
        |r| mesh.face_window(r),
        |faces, f, b| {
            b.push(b'f');
            let first = faces.first_corner(f);
            for (k, &v) in faces.face(f).iter().enumerate() {
                let v = v as u64 + 1;
                b.push(b' ');
                push_u64(b, v);
                match uv {
                    Some(uv) => {
                        b.push(b'/');
                        push_u64(b, uv.indices()[first + k] as u64 + 1);
                    }
                    None if with_normals => b.push(b'/'),
                    None => continue,
                }
                if with_normals {
                    b.push(b'/');
                    push_u64(b, v);
                }
            }
            b.push(b'\n');
        },
    )?;
    write_tags(w, mesh)?;
    for t in extra_tags {
        writeln!(w, "{t}")?;
    }
    Ok(())
}

/// A line `keyword x y ..` of shortest round-trip numbers.
fn push_numbers_line(b: &mut Vec<u8>, keyword: &[u8], values: &[f64]) {
    b.extend_from_slice(keyword);
    b.push(b' ');
    push_f64s(b, values);
    b.push(b'\n');
}

fn write_tags(w: &mut dyn Write, mesh: &MeshView<'_>) -> std::io::Result<()> {
    if let Some(b) = mesh.hints.boundary_interpolation {
        writeln!(w, "t interpolateboundary 1/0/0 {}", b.to_shape_tag())?;
    }
    if let Some(c) = mesh.hints.crease_method {
        let s = match c {
            CreaseMethod::Uniform => "normal",
            CreaseMethod::Chaikin => "chaikin",
        };
        writeln!(w, "t creasemethod 0/0/1 {s}")?;
    }
    if let Some(m) = mesh.hints.fvar_interpolation {
        writeln!(
            w,
            "t facevaryinginterpolateboundary 1/0/0 {}",
            m.to_shape_tag()
        )?;
    }
    if let Some(t) = mesh.hints.triangle_subdivision {
        let s = match t {
            TriangleSubdivision::Catmark => "catmark",
            TriangleSubdivision::Smooth => "smooth",
        };
        writeln!(w, "t smoothtriangles 0/0/1 {s}")?;
    }
    for &([a, b], s) in mesh.creases() {
        writeln!(w, "t crease 2/1/0 {a} {b} {s}")?;
    }
    for &(v, s) in mesh.corners() {
        writeln!(w, "t corner 1/1/0 {v} {s}")?;
    }
    for f in mesh.hole_faces() {
        writeln!(w, "t hole 1/0/0 {f}")?;
    }
    Ok(())
}
