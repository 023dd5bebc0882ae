//! One level of the adaptive hierarchy: the faces of uniform level `l` that exist (the
//! children of the refined faces of level `l − 1`), as a topology of their own with the
//! uniform level's tags, rules and exact positions, and every element's uniform index.
//!
//! **Why the positions are exact.** A child of a refined face `f` reads, through its mask,
//! only the faces around `f`'s vertices. The restricted hierarchy guarantees that every face
//! around a refined face's vertices exists at its level (see [`crate::hierarchy`]), so the
//! piece that is refined — every face sharing a vertex with a refined face — gives the
//! children of the refined faces from complete rings, kept in the uniform level's order
//! ([`subd_mesh::cut`]): the same operations as uniform refinement, bit for bit.

use glam::DVec3;
use subd_mesh::Topology;
use subd_schemes::{Options, Refinement, Rule, Scheme};

use crate::AdaptiveError;
use subd_mesh::cut::{self as submesh, NONE};
use subd_schemes::ChildLayout;

/// Where a vertex of a level comes from in the level above.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Origin {
    /// A base vertex.
    Base,
    /// The child of vertex `0` of the level above.
    Vertex(u32),
    /// The child (face point) of face `0` of the level above.
    Face(u32),
    /// The child (edge point) of edge `0` of the level above.
    Edge(u32),
}

/// The parameter domain of a face: its base face, the sub-face of a Catmull-Clark base face
/// that is not a quad (OpenSubdiv's ptex convention), and `(u, v)` at each corner.
pub(crate) const WHOLE_FACE: u16 = u16::MAX;

/// One level of the hierarchy.
#[derive(Debug)]
pub(crate) struct SparseLevel {
    pub topology: Topology,
    pub rules: Vec<Rule>,
    pub points: Vec<DVec3>,
    /// Uniform index of every face, edge and vertex at this level.
    pub face_key: Vec<u64>,
    pub edge_key: Vec<u64>,
    pub vertex_key: Vec<u64>,
    /// Faces around every edge and vertex in the uniform level (to tell complete rings).
    pub edge_full: Vec<u32>,
    pub vertex_full: Vec<u32>,
    pub vertex_origin: Vec<Origin>,
    /// Face of the level above each face is a child of (`NONE` at level 0).
    pub face_parent: Vec<u32>,
    pub base_face: Vec<u32>,
    pub sub_face: Vec<u16>,
    /// `(u, v)` of every face-vertex (NaN for a whole non-quad base face).
    pub corner_params: Vec<[f64; 2]>,
    /// Faces refined at this level.
    pub refined: Vec<bool>,
    /// Index in the next level of each vertex's and edge's child, where it exists.
    pub vertex_child: Vec<u32>,
    pub edge_child: Vec<u32>,
}

impl SparseLevel {
    /// The whole base level, prepared (boundary rules applied to its tags, vertex rules
    /// determined) as uniform refinement prepares it.
    pub(crate) fn base(
        base: &Topology,
        points: &[DVec3],
        scheme: &Scheme,
        options: &Options,
    ) -> Result<SparseLevel, AdaptiveError> {
        if points.len() != base.num_vertices() {
            return Err(AdaptiveError::PointCount {
                given: points.len(),
                vertices: base.num_vertices(),
            });
        }
        let r = Refinement::new(base, scheme.clone(), options, 0)?;
        let rules = r.vertex_rules(0).to_vec();
        let topology = r.into_topology(0);
        let (nv, ne, nf) = (
            topology.num_vertices(),
            topology.num_edges(),
            topology.num_faces(),
        );
        let mut corner_params = Vec::with_capacity(topology.num_face_vertices());
        for f in 0..nf {
            match (scheme, topology.face_size(f)) {
                (Scheme::Loop, _) => corner_params.extend([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
                (_, 4) => {
                    corner_params.extend([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
                }
                (_, n) => corner_params.extend(std::iter::repeat_n([f64::NAN; 2], n)),
            }
        }
        let sub_face = (0..nf)
            .map(|f| {
                if *scheme == Scheme::Loop || topology.face_size(f) == 4 {
                    0
                } else {
                    WHOLE_FACE
                }
            })
            .collect();
        Ok(SparseLevel {
            rules,
            points: points.to_vec(),
            face_key: (0..nf as u64).collect(),
            edge_key: (0..ne as u64).collect(),
            vertex_key: (0..nv as u64).collect(),
            edge_full: (0..ne)
                .map(|e| topology.edge_faces(e).len() as u32)
                .collect(),
            vertex_full: (0..nv)
                .map(|v| topology.vertex_faces(v).len() as u32)
                .collect(),
            vertex_origin: vec![Origin::Base; nv],
            face_parent: vec![NONE; nf],
            base_face: (0..nf as u32).collect(),
            sub_face,
            corner_params,
            refined: vec![false; nf],
            vertex_child: vec![NONE; nv],
            edge_child: vec![NONE; ne],
            topology,
        })
    }

    /// Number of faces.
    pub(crate) fn num_faces(&self) -> usize {
        self.topology.num_faces()
    }

    /// Whether every face around vertex `v` in the uniform level is present.
    pub(crate) fn is_complete(&self, v: usize) -> bool {
        self.topology.vertex_faces(v).len() as u32 == self.vertex_full[v]
    }

    /// The corner parameters of face `f`.
    pub(crate) fn params(&self, f: usize) -> &[[f64; 2]] {
        let o = self.topology.face_offsets();
        &self.corner_params[o[f] as usize..o[f + 1] as usize]
    }

    /// Vertex rules for a cut: the level's, except that a vertex missing faces becomes a
    /// corner. Its own children are never kept; the corner rule only spares the masks (and
    /// the limit classification) a ring that is not the vertex's.
    fn cut_rules(&self, cut: &submesh::SubMesh) -> Vec<Rule> {
        cut.vertices
            .iter()
            .zip(&cut.complete)
            .map(|(&v, &whole)| {
                if whole && self.is_complete(v as usize) {
                    self.rules[v as usize]
                } else {
                    Rule::Corner
                }
            })
            .collect()
    }

    /// Cuts `faces` out of this level with rules and positions, ready to refine.
    pub(crate) fn piece(&self, faces: &[u32]) -> (submesh::SubMesh, Vec<Rule>, Vec<DVec3>) {
        let cut = submesh::cut(&self.topology, faces);
        let rules = self.cut_rules(&cut);
        let points = cut
            .vertices
            .iter()
            .map(|&v| self.points[v as usize])
            .collect();
        (cut, rules, points)
    }

    /// The next level: the children of the refined faces of this one (`self.refined`), which
    /// is `level` of the hierarchy. Records where the children of this level's vertices and
    /// edges went.
    pub(crate) fn refine(
        &mut self,
        level: usize,
        scheme: &Scheme,
        options: &Options,
        uniform: &ChildLayout,
    ) -> Result<SparseLevel, AdaptiveError> {
        let piece_faces = self.refined_piece();
        let (cut, rules, points) = self.piece(&piece_faces);
        let (piece, piece_topology) = Piece::new(cut, piece_faces, *scheme == Scheme::Loop);
        let r = Refinement::from_prepared(piece_topology, rules, scheme.clone(), options, 1)?;
        let child_points = r.refine_points(&points).pop().expect("one level");
        let child_rules = r.vertex_rules(1);
        let kept = self.kept_children(&piece);
        let next = submesh::cut(r.topology(1), &kept.faces);
        // The children's uniform indices are those of this level's elements' children.
        let parent_level = level - 1;
        // Each reads this level and the cuts only: built side by side.
        let this = &*self;
        let ((vertices, (edge_key, edge_full)), (faces, (rules, points))) = rayon::join(
            || {
                rayon::join(
                    || this.child_vertices(&piece, &next, uniform, parent_level),
                    || this.child_edges(&piece, &next, uniform, parent_level),
                )
            },
            || {
                rayon::join(
                    || this.child_faces(&kept, uniform, parent_level, piece.loop_scheme),
                    || {
                        let vs = &next.vertices;
                        let rules: Vec<Rule> =
                            vs.iter().map(|&v| child_rules[v as usize]).collect();
                        let points: Vec<DVec3> =
                            vs.iter().map(|&v| child_points[v as usize]).collect();
                        (rules, points)
                    },
                )
            },
        );
        self.vertex_child = vertices.vertex_child;
        self.edge_child = vertices.edge_child;
        Ok(SparseLevel {
            rules,
            points,
            face_key: faces.face_key,
            edge_key,
            vertex_key: vertices.vertex_key,
            edge_full,
            vertex_full: vertices.vertex_full,
            vertex_origin: vertices.vertex_origin,
            face_parent: faces.face_parent,
            base_face: faces.base_face,
            sub_face: faces.sub_face,
            corner_params: faces.corner_params,
            refined: vec![false; kept.faces.len()],
            vertex_child: vec![NONE; next.vertices.len()],
            edge_child: vec![NONE; next.edges.len()],
            topology: next.topology,
        })
    }

    /// The piece that is refined: every face sharing a vertex with a refined face, in face
    /// order.
    fn refined_piece(&self) -> Vec<u32> {
        let t = &self.topology;
        let nf = t.num_faces();
        let mut touched = vec![false; t.num_vertices()];
        for f in (0..nf).filter(|&f| self.refined[f]) {
            for &v in t.face_vertices(f) {
                touched[v as usize] = true;
            }
        }
        (0..nf as u32)
            .filter(|&f| {
                t.face_vertices(f as usize)
                    .iter()
                    .any(|&v| touched[v as usize])
            })
            .collect()
    }

    /// The kept child faces: children of refined faces, in parent order (indices in the
    /// refined piece's child level), with their parent face and child index.
    fn kept_children(&self, piece: &Piece) -> KeptChildren {
        let mut kept = KeptChildren {
            faces: Vec::new(),
            parent: Vec::new(),
            k: Vec::new(),
        };
        for (pi, &f) in piece.faces.iter().enumerate() {
            if !self.refined[f as usize] {
                continue;
            }
            let children = if piece.loop_scheme {
                4 * pi..4 * pi + 4
            } else {
                piece.face_offsets[pi] as usize..piece.face_offsets[pi + 1] as usize
            };
            for (k, cf) in children.enumerate() {
                kept.faces.push(cf as u32);
                kept.parent.push(f);
                kept.k.push(k);
            }
        }
        kept
    }

    /// The next level's vertices (uniform index, ring size in the uniform level, origin),
    /// and the children of this level's vertices and edges.
    fn child_vertices(
        &self,
        piece: &Piece,
        next: &submesh::SubMesh,
        uniform: &ChildLayout,
        parent_level: usize,
    ) -> ChildVertices {
        let nv = next.vertices.len();
        let mut out = ChildVertices {
            vertex_key: Vec::with_capacity(nv),
            vertex_full: Vec::with_capacity(nv),
            vertex_origin: Vec::with_capacity(nv),
            vertex_child: vec![NONE; self.topology.num_vertices()],
            edge_child: vec![NONE; self.topology.num_edges()],
        };
        for (i, &cv) in next.vertices.iter().enumerate() {
            let cv = cv as usize;
            if cv < piece.num_vertices {
                let v = piece.vertices[cv];
                out.vertex_key.push(self.vertex_key[v as usize]);
                out.vertex_full.push(self.vertex_full[v as usize]);
                out.vertex_origin.push(Origin::Vertex(v));
                out.vertex_child[v as usize] = i as u32;
            } else if cv < piece.edge_point_base {
                let f = piece.faces[cv - piece.num_vertices];
                let key = uniform.face_point(parent_level, self.face_key[f as usize]);
                out.vertex_key.push(key);
                out.vertex_full
                    .push(self.topology.face_size(f as usize) as u32);
                out.vertex_origin.push(Origin::Face(f));
            } else {
                let e = piece.edges[cv - piece.edge_point_base];
                let key = uniform.edge_point(parent_level, self.edge_key[e as usize]);
                out.vertex_key.push(key);
                out.vertex_full
                    .push(uniform.edge_point_faces(self.edge_full[e as usize]));
                out.vertex_origin.push(Origin::Edge(e));
                out.edge_child[e as usize] = i as u32;
            }
        }
        out
    }

    /// The next level's edges (uniform index, faces in the uniform level): interior edges
    /// of a piece face, or halves of a piece edge.
    fn child_edges(
        &self,
        piece: &Piece,
        next: &submesh::SubMesh,
        uniform: &ChildLayout,
        parent_level: usize,
    ) -> (Vec<u64>, Vec<u32>) {
        let mut edge_key = Vec::with_capacity(next.edges.len());
        let mut edge_full = Vec::with_capacity(next.edges.len());
        for &ce in &next.edges {
            let ce = ce as usize;
            if ce < piece.half_base {
                let (pi, j) = if piece.loop_scheme {
                    (ce / 3, ce % 3)
                } else {
                    let pi = piece.face_offsets.partition_point(|&o| o as usize <= ce) - 1;
                    (pi, ce - piece.face_offsets[pi] as usize)
                };
                let f = piece.faces[pi] as usize;
                edge_key.push(uniform.interior_edge(parent_level, self.face_key[f], j));
                edge_full.push(2);
            } else {
                let h = ce - piece.half_base;
                let e = piece.edges[h / 2] as usize;
                edge_key.push(uniform.half_edge(parent_level, self.edge_key[e], (h % 2) as u32));
                edge_full.push(self.edge_full[e]);
            }
        }
        (edge_key, edge_full)
    }

    /// The next level's faces: uniform index, parent, base face and parameter domain.
    fn child_faces(
        &self,
        kept: &KeptChildren,
        uniform: &ChildLayout,
        parent_level: usize,
        loop_scheme: bool,
    ) -> ChildFaces {
        let n = kept.faces.len();
        let mut out = ChildFaces {
            face_key: Vec::with_capacity(n),
            face_parent: Vec::with_capacity(n),
            base_face: Vec::with_capacity(n),
            sub_face: Vec::with_capacity(n),
            corner_params: Vec::with_capacity(4 * n),
        };
        for (&f, &k) in kept.parent.iter().zip(&kept.k) {
            let f = f as usize;
            out.face_key
                .push(uniform.child_face(parent_level, self.face_key[f], k));
            out.face_parent.push(f as u32);
            out.base_face.push(self.base_face[f]);
            let d = self.params(f);
            if loop_scheme {
                out.sub_face.push(0);
                out.corner_params.extend(loop_child_params(d, k));
            } else if self.sub_face[f] == WHOLE_FACE {
                // Sub-face k of a base face that is not a quad: its own unit square.
                out.sub_face.push(k as u16);
                out.corner_params
                    .extend([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
            } else {
                out.sub_face.push(self.sub_face[f]);
                out.corner_params.extend(quad_child_params(d, k));
            }
        }
        out
    }
}

/// The refined piece of a level, and where its refinement puts each kind of child vertex
/// and edge.
struct Piece {
    /// The piece's faces, vertices and edges, as the level's.
    faces: Vec<u32>,
    vertices: Vec<u32>,
    edges: Vec<u32>,
    /// The piece's face offsets (its quad split's children of face `i` start at offset `i`).
    face_offsets: Vec<u32>,
    loop_scheme: bool,
    /// The piece's vertex count: its vertices' children come first.
    num_vertices: usize,
    /// The first edge-point child.
    edge_point_base: usize,
    /// The first child edge that is a half of a piece edge.
    half_base: usize,
}

impl Piece {
    /// The piece cut as `cut` from the level's `faces`; returns its topology apart, to be
    /// refined.
    fn new(cut: submesh::SubMesh, faces: Vec<u32>, loop_scheme: bool) -> (Piece, Topology) {
        let t = cut.topology;
        let (pnv, pnf, pnh) = (t.num_vertices(), t.num_faces(), t.num_face_vertices());
        let piece = Piece {
            faces,
            vertices: cut.vertices,
            edges: cut.edges,
            face_offsets: t.face_offsets().to_vec(),
            loop_scheme,
            num_vertices: pnv,
            edge_point_base: if loop_scheme { pnv } else { pnv + pnf },
            half_base: if loop_scheme { 3 * pnf } else { pnh },
        };
        (piece, t)
    }
}

/// The kept child faces of a refined piece (indices in its child level), each with its
/// parent face in the level and its index among the parent's children.
struct KeptChildren {
    faces: Vec<u32>,
    parent: Vec<u32>,
    k: Vec<usize>,
}

/// The next level's per-vertex arrays, and where this level's vertices and edges went.
struct ChildVertices {
    vertex_key: Vec<u64>,
    vertex_full: Vec<u32>,
    vertex_origin: Vec<Origin>,
    vertex_child: Vec<u32>,
    edge_child: Vec<u32>,
}

/// The next level's per-face arrays.
struct ChildFaces {
    face_key: Vec<u64>,
    face_parent: Vec<u32>,
    base_face: Vec<u32>,
    sub_face: Vec<u16>,
    corner_params: Vec<[f64; 2]>,
}

/// Corner parameters of child `k` of a Loop triangle with corner parameters `d`, in the
/// triangle split's child order.
fn loop_child_params(d: &[[f64; 2]], k: usize) -> [[f64; 2]; 3] {
    let m = |a: usize, b: usize| mid(d[a], d[b]);
    match k {
        0 => [d[0], m(0, 1), m(2, 0)],
        1 => [m(0, 1), d[1], m(1, 2)],
        2 => [m(2, 0), m(1, 2), d[2]],
        _ => [m(1, 2), m(2, 0), m(0, 1)],
    }
}

/// Corner parameters of child `k` of a quad with corner parameters `d`.
fn quad_child_params(d: &[[f64; 2]], k: usize) -> [[f64; 2]; 4] {
    let centre = [
        0.25 * (d[0][0] + d[1][0] + d[2][0] + d[3][0]),
        0.25 * (d[0][1] + d[1][1] + d[2][1] + d[3][1]),
    ];
    // Child k of a quad is (V_k, E_k, F, E_{k-1}) rotated to put V_k at corner k.
    let (prev, next_k) = ((k + 3) % 4, (k + 1) % 4);
    let around = [d[k], mid(d[k], d[next_k]), centre, mid(d[prev], d[k])];
    [0, 1, 2, 3].map(|i| around[(i + 4 - k) % 4])
}

fn mid(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
}
