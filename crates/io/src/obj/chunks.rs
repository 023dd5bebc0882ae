//! The OBJ statements read in parallel: the text is cut into chunks at line ends, every chunk
//! is read by one task into arrays of its own, and the arrays are joined in file order.
//!
//! What a chunk cannot know alone is fixed up at the join: its first line number (tags,
//! face lines and warnings hold chunk-local lines until then) and the vertices before it
//! (relative face indices are kept aside and resolved then). Any error makes the whole read
//! fall back to the serial reader of the parent module, which is kept as the reference: it
//! finds the first error in file order and words it exactly, so this reader only has to
//! notice that something is wrong.

use rayon::prelude::*;
use subd_mesh::DVec3;

use super::{ObjStatements, TagLine, is_statement_name, parse_tag};

/// Bytes per chunk: large enough that joining costs little, small enough that two threads
/// share a file of a few megabytes.
const CHUNK_BYTES: usize = 1 << 20;

/// Bytes per chunk for the pool this runs in: one chunk on one thread, whose arrays are
/// then the file's without a copy (the chunks give the same statements, however cut).
pub(super) fn chunk_bytes() -> usize {
    if rayon::current_num_threads() > 1 {
        CHUNK_BYTES
    } else {
        usize::MAX
    }
}

/// A chunk failed to read; the serial reader says why.
pub(super) struct Failed;

/// What one chunk gives, with chunk-local line numbers.
#[derive(Default)]
struct Chunk {
    st: ObjStatements,
    /// Lines in the chunk.
    lines: usize,
    /// The first unknown statement: its local line and name.
    unknown: Option<(usize, String)>,
    /// Relative indices: (slot in `face_vertices` / `face_texcoords`, index relative to the
    /// chunk's own count: negative when it points before the chunk).
    relative_vertices: Vec<(usize, i64)>,
    relative_texcoords: Vec<(usize, i64)>,
}

/// Reads the statements of `bytes` in chunks of about `chunk_bytes`; `Err` for any input
/// the serial reader would refuse.
pub(super) fn read_statements(bytes: &[u8], chunk_bytes: usize) -> Result<ObjStatements, Failed> {
    let text = std::str::from_utf8(bytes).map_err(|_| Failed)?;
    let ranges = chunk_ranges(bytes, chunk_bytes);
    let chunks = ranges
        .into_par_iter()
        .map(|r| read_chunk(&text[r]))
        .collect::<Result<Vec<Chunk>, Failed>>()?;
    let st = join(chunks)?;
    if st.face_sizes.is_empty() {
        return Err(Failed);
    }
    Ok(st)
}

/// Cuts `bytes` into ranges of about `chunk_bytes` that end just after a line end, never
/// inside a `\`-continued statement.
fn chunk_ranges(bytes: &[u8], chunk_bytes: usize) -> Vec<std::ops::Range<usize>> {
    let len = bytes.len();
    let mut ranges = Vec::with_capacity(len / chunk_bytes.max(1) + 1);
    let mut start = 0;
    while start < len {
        // Search for a line end from the chunk's nominal last byte on.
        let mut from = start.saturating_add(chunk_bytes.max(1)).min(len) - 1;
        let end = loop {
            let Some(p) = bytes[from..].iter().position(|&b| b == b'\n') else {
                break len;
            };
            let newline = from + p;
            if !continues(&bytes[start..newline]) {
                break newline + 1;
            }
            from = newline + 1;
            if from >= len {
                break len;
            }
        };
        ranges.push(start..end);
        start = end;
    }
    ranges
}

/// Whether a line (without its `\n`) ends with a continuation, as the serial reader sees
/// it: `\`, before one `\r` that is dropped.
fn continues(line: &[u8]) -> bool {
    line.strip_suffix(b"\r").unwrap_or(line).ends_with(b"\\")
}

/// Reads the lines of one chunk.
fn read_chunk(text: &str) -> Result<Chunk, Failed> {
    let mut c = Chunk::default();
    let mut joined = String::new();
    for raw in text.split_inclusive('\n') {
        c.lines += 1;
        let line = raw.strip_suffix('\n').unwrap_or(raw);
        let line = line.strip_suffix('\r').unwrap_or(line);
        if let Some(head) = line.strip_suffix('\\') {
            joined.push_str(head);
            joined.push(' ');
            continue;
        }
        if joined.is_empty() {
            c.statement(line)?;
        } else {
            joined.push_str(line);
            let whole = std::mem::take(&mut joined);
            c.statement(&whole)?;
        }
    }
    if !joined.is_empty() {
        return Err(Failed);
    }
    Ok(c)
}

impl Chunk {
    /// One statement, at local line `self.lines`.
    fn statement(&mut self, text: &str) -> Result<(), Failed> {
        let mut tokens = text.split_ascii_whitespace();
        let Some(keyword) = tokens.next() else {
            return Ok(());
        };
        match keyword {
            "v" => {
                let p = coordinates::<3>(&mut tokens, 3)?;
                self.st.positions.push(DVec3::from_array(p));
            }
            "vt" => {
                let uv = coordinates::<2>(&mut tokens, 1)?;
                self.st.texcoords.push(uv);
            }
            "f" | "fo" => self.face(tokens)?,
            "t" => {
                let tag: TagLine = parse_tag(self.lines, text, tokens).map_err(|_| Failed)?;
                self.st.tags.push(tag);
            }
            k if k.starts_with('#') => {}
            "vn" | "vp" | "o" | "g" | "s" | "mg" | "usemtl" | "mtllib" | "l" | "p" | "lod"
            | "bevel" | "c_interp" | "d_interp" | "shadow_obj" | "trace_obj" | "maplib"
            | "usemap" | "cstype" | "deg" | "bmat" | "step" | "curv" | "curv2" | "surf"
            | "parm" | "trim" | "hole" | "scrv" | "sp" | "end" | "con" | "ctech" | "stech"
            | "call" | "csh" => {}
            other if is_statement_name(other) => {
                if self.unknown.is_none() {
                    self.unknown = Some((self.lines, other.to_string()));
                }
            }
            _ => return Err(Failed),
        }
        Ok(())
    }

    /// One `f` line; relative indices are kept aside for the join.
    fn face<'a>(&mut self, tokens: impl Iterator<Item = &'a str>) -> Result<(), Failed> {
        let st = &mut self.st;
        let first_uv = st.face_texcoords.len();
        let (mut corners, mut with_uv) = (0usize, 0usize);
        for tok in tokens {
            let (head, rest) = tok.split_once('/').unwrap_or((tok, ""));
            let idx = head.parse::<i64>().map_err(|_| Failed)?;
            let slot = st.face_vertices.len();
            st.face_vertices.push(absolute(
                idx,
                st.positions.len(),
                slot,
                &mut self.relative_vertices,
            )?);
            corners += 1;
            let t = rest.split('/').next().unwrap_or("");
            if !t.is_empty() {
                let idx = t.parse::<i64>().map_err(|_| Failed)?;
                let slot = st.face_texcoords.len();
                let uv = absolute(idx, st.texcoords.len(), slot, &mut self.relative_texcoords)?;
                st.face_texcoords.push(uv);
                with_uv += 1;
            }
        }
        if corners < 3 || corners >= u32::MAX as usize || (with_uv != 0 && with_uv != corners) {
            return Err(Failed);
        }
        if with_uv == 0 {
            st.face_texcoords.truncate(first_uv);
            st.first_face_without_texcoords.get_or_insert(self.lines);
        } else {
            st.faces_with_texcoords += 1;
        }
        st.face_sizes.push(corners as u32);
        st.face_lines.push(self.lines as u32);
        Ok(())
    }
}

/// A 1-based index as 0-based; a relative one is noted in `relative` (with the `count`
/// read so far in the chunk) and left as a placeholder.
fn absolute(
    idx: i64,
    count: usize,
    slot: usize,
    relative: &mut Vec<(usize, i64)>,
) -> Result<u32, Failed> {
    match idx {
        0 => Err(Failed),
        i if i > 0 => Ok(u32::try_from(i - 1).unwrap_or(u32::MAX)),
        i => {
            relative.push((slot, count as i64 + i));
            Ok(0)
        }
    }
}

/// The first `N` numbers of a `v` or `vt` line; at least `needed` must be there.
fn coordinates<'a, const N: usize>(
    tokens: &mut impl Iterator<Item = &'a str>,
    needed: usize,
) -> Result<[f64; N], Failed> {
    let mut p = [0.0f64; N];
    for (k, slot) in p.iter_mut().enumerate() {
        let Some(tok) = tokens.next() else {
            return if k < needed { Err(Failed) } else { Ok(p) };
        };
        *slot = tok.parse::<f64>().map_err(|_| Failed)?;
        if !slot.is_finite() {
            return Err(Failed);
        }
    }
    Ok(p)
}

/// Joins the chunks in file order, fixing up line numbers and relative indices.
fn join(chunks: Vec<Chunk>) -> Result<ObjStatements, Failed> {
    let total = |f: fn(&ObjStatements) -> usize| chunks.iter().map(|c| f(&c.st)).sum::<usize>();
    let totals = Totals {
        positions: total(|s| s.positions.len()),
        texcoords: total(|s| s.texcoords.len()),
        faces: total(|s| s.face_sizes.len()),
        face_vertices: total(|s| s.face_vertices.len()),
        face_texcoords: total(|s| s.face_texcoords.len()),
    };
    let mut st = ObjStatements::default();
    let mut first_line = 0usize;
    for mut c in chunks {
        resolve(
            &mut c.st.face_vertices,
            &c.relative_vertices,
            st.positions.len(),
        )?;
        resolve(
            &mut c.st.face_texcoords,
            &c.relative_texcoords,
            st.texcoords.len(),
        )?;
        append(&mut st, c.st, first_line, &totals);
        if let Some((line, name)) = c.unknown.filter(|_| st.warnings.is_empty()) {
            st.warnings.push(format!(
                "line {}: unknown OBJ statement {name:?} ignored",
                first_line + line
            ));
        }
        first_line += c.lines;
    }
    Ok(st)
}

/// The lengths of the joined arrays.
struct Totals {
    positions: usize,
    texcoords: usize,
    faces: usize,
    face_vertices: usize,
    face_texcoords: usize,
}

/// Appends `src` to `dst`, which has room for `total` after the first call. The first
/// non-empty chunk's array becomes `dst` (a file read as one chunk is never copied).
fn extend<T>(dst: &mut Vec<T>, src: &mut Vec<T>, total: usize) {
    if dst.is_empty() {
        std::mem::swap(dst, src);
        dst.reserve_exact(total - dst.len());
    } else {
        dst.append(src);
    }
}

/// Resolves a chunk's relative indices now that `before` elements precede it.
fn resolve(indices: &mut [u32], relative: &[(usize, i64)], before: usize) -> Result<(), Failed> {
    for &(slot, r) in relative {
        let r = before as i64 + r;
        if r < 0 {
            return Err(Failed);
        }
        indices[slot] = u32::try_from(r).unwrap_or(u32::MAX);
    }
    Ok(())
}

/// Appends a chunk's statements whose lines start after `first_line`.
fn append(st: &mut ObjStatements, mut c: ObjStatements, first_line: usize, totals: &Totals) {
    // Lines are kept as `u32` the way the serial reader keeps them (wrapping alike).
    let base = first_line as u32;
    c.face_lines
        .iter_mut()
        .for_each(|l| *l = l.wrapping_add(base));
    extend(&mut st.positions, &mut c.positions, totals.positions);
    extend(&mut st.texcoords, &mut c.texcoords, totals.texcoords);
    extend(&mut st.face_sizes, &mut c.face_sizes, totals.faces);
    extend(&mut st.face_lines, &mut c.face_lines, totals.faces);
    extend(
        &mut st.face_vertices,
        &mut c.face_vertices,
        totals.face_vertices,
    );
    extend(
        &mut st.face_texcoords,
        &mut c.face_texcoords,
        totals.face_texcoords,
    );
    st.faces_with_texcoords += c.faces_with_texcoords;
    if st.first_face_without_texcoords.is_none() {
        st.first_face_without_texcoords = c.first_face_without_texcoords.map(|l| first_line + l);
    }
    st.tags.extend(c.tags.into_iter().map(|mut t| {
        t.line += first_line;
        t
    }));
}

#[cfg(test)]
mod tests {
    use super::super::read_statements as read_serially;
    use super::*;

    /// A small deterministic generator (xorshift), so failures reproduce.
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }
        fn below(&mut self, n: u64) -> u64 {
            self.next() % n
        }
        fn coordinate(&mut self) -> String {
            let x = f64::from_bits(self.next() >> 2) % 1e6 - 5e5;
            match self.below(4) {
                0 => format!("{x}"),
                1 => format!("{x:e}"),
                2 => format!("{:.3}", x / 7.0),
                _ => format!("{}", self.below(100)),
            }
        }
    }

    /// An OBJ text with every statement kind the reader handles: CRLF and LF ends, comments,
    /// blank lines, continuations, relative and absolute indices with texture coordinates,
    /// unknown statements and tags.
    fn generated(seed: u64, lines: usize) -> String {
        let mut r = Rng(seed);
        let (mut out, mut nv, mut nt) = (String::new(), 0u64, 0u64);
        for _ in 0..lines {
            let end = if r.below(3) == 0 { "\r\n" } else { "\n" };
            let line = match r.below(12) {
                0..=3 => {
                    nv += 1;
                    let c: Vec<String> = (0..3).map(|_| r.coordinate()).collect();
                    format!("v {} {}  {}", c[0], c[1], c[2])
                }
                4 => {
                    nt += 1;
                    format!("vt {} {}", r.coordinate(), r.coordinate())
                }
                5..=7 if nv >= 3 && nt >= 1 => {
                    let k = 3 + r.below(3);
                    let corners: Vec<String> = (0..k)
                        .map(|_| {
                            let v = 1 + r.below(nv);
                            let t = 1 + r.below(nt);
                            let v = if r.below(2) == 0 {
                                v as i64
                            } else {
                                v as i64 - nv as i64 - 1
                            };
                            let t = if r.below(2) == 0 {
                                t as i64
                            } else {
                                t as i64 - nt as i64 - 1
                            };
                            format!("{v}/{t}")
                        })
                        .collect();
                    format!("f {}", corners.join(" "))
                }
                8 => "# a comment \\".to_string() + end + "v continues the comment",
                9 => format!("t corner 1/1/0 {} 2.5", r.below(nv.max(1))),
                10 => "g group".to_string(),
                _ if nv >= 2 => "f -1 -2 \\".to_string() + end + "  1",
                _ => "frob x".to_string(),
            };
            out.push_str(&line);
            out.push_str(end);
        }
        out.push_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1");
        out
    }

    fn assert_same(a: &ObjStatements, b: &ObjStatements) {
        let bits = |p: &[DVec3]| {
            p.iter()
                .map(|p| p.to_array().map(f64::to_bits))
                .collect::<Vec<_>>()
        };
        assert_eq!(bits(&a.positions), bits(&b.positions));
        assert_eq!(a.texcoords, b.texcoords);
        assert_eq!(a.face_sizes, b.face_sizes);
        assert_eq!(a.face_vertices, b.face_vertices);
        assert_eq!(a.face_texcoords, b.face_texcoords);
        assert_eq!(a.faces_with_texcoords, b.faces_with_texcoords);
        assert_eq!(
            a.first_face_without_texcoords,
            b.first_face_without_texcoords
        );
        assert_eq!(a.face_lines, b.face_lines);
        assert_eq!(a.warnings, b.warnings);
        let tag = |t: &TagLine| {
            (
                t.line,
                t.name.clone(),
                t.ints.clone(),
                t.floats.clone(),
                t.strings.clone(),
                t.raw.clone(),
            )
        };
        let tags = |s: &ObjStatements| s.tags.iter().map(tag).collect::<Vec<_>>();
        assert_eq!(tags(a), tags(b));
    }

    #[test]
    fn chunks_read_what_the_serial_reader_reads() {
        for seed in 1..=12u64 {
            let text = generated(seed * 7919, 400);
            let serial = read_serially(text.as_bytes()).unwrap();
            for chunk in [1, 5, 17, 64, 500, 1 << 20, usize::MAX] {
                let parallel = read_statements(text.as_bytes(), chunk)
                    .unwrap_or_else(|_| panic!("seed {seed}, chunk {chunk} refused"));
                assert_same(&parallel, &serial);
            }
        }
    }

    #[test]
    fn chunks_end_at_line_ends_outside_continuations() {
        let text = b"v 1 2 3\\\r\n 4\nv 5 \\\n6 7\r\nf 1 2 3\n";
        for chunk in 1..text.len() + 2 {
            let ranges = chunk_ranges(text, chunk);
            assert_eq!(ranges.first().map(|r| r.start), Some(0));
            assert_eq!(ranges.last().map(|r| r.end), Some(text.len()));
            for r in &ranges {
                assert!(r.end == text.len() || !continues(&text[r.start..r.end - 1]));
                assert_eq!(text[r.end - 1], b'\n');
            }
        }
    }

    /// Errors anywhere, late chunks included, are the serial reader's: same line, same words.
    #[test]
    fn errors_are_the_first_in_file_order() {
        let text = generated(99, 600);
        let lines: Vec<&str> = text.split_inclusive('\n').collect();
        let bad = [
            "v 1 2 nope\n",
            "f 1 2\n",
            "f 0 1 2\n",
            "v 1 2 inf\n",
            "f -100000 1 2\n",
            "t crease 2/1/0 0\n",
            "%%%\n",
            "f 1/1 2 3\n",
        ];
        for (k, b) in bad.iter().enumerate() {
            for mut at in [3, lines.len() / 2, lines.len() - 2] {
                // Not where a continuation would join the bad line to the one before.
                while lines[at - 1].trim_end().ends_with('\\') {
                    at += 1;
                }
                let mut broken: String = lines[..at].concat();
                broken.push_str(b);
                broken.push_str(&lines[at..].concat());
                broken.push_str("\nv 1 2 nope\n");
                let expected = read_serially(broken.as_bytes()).err().expect("refused");
                assert!(
                    read_statements(broken.as_bytes(), 37).is_err(),
                    "case {k} at {at}"
                );
                let got = super::super::parse_obj_in_chunks(
                    broken.as_bytes(),
                    &crate::ReadOptions::default(),
                    37,
                )
                .expect_err("refused");
                assert_eq!(got.to_string(), expected.to_string());
                assert!(
                    got.to_string().contains(&format!("line {}", at + 1)),
                    "{got}"
                );
            }
        }
    }

    #[test]
    fn relative_indices_reach_into_earlier_chunks() {
        let mut text = String::new();
        for i in 0..50 {
            text.push_str(&format!("v {i} 0 0\n"));
        }
        for _ in 0..10 {
            text.push_str("f -50 -49 -48\nf -1 -2 -3\n");
        }
        let serial = read_serially(text.as_bytes()).unwrap();
        for chunk in [1, 9, 100] {
            assert_same(
                &read_statements(text.as_bytes(), chunk).ok().unwrap(),
                &serial,
            );
        }
        assert!(read_statements(b"v 0 0 0\nv 1 0 0\nf -1 -2 -3\n", 8).is_err());
    }

    #[test]
    fn invalid_utf8_falls_back_to_the_serial_words() {
        let text = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n# \xff\n";
        let got = super::super::parse_obj_in_chunks(text, &crate::ReadOptions::default(), 4);
        assert!(got.err().unwrap().to_string().contains("line 5"));
    }
}
